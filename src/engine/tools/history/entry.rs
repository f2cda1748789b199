//! One result's parameters as history compares them: the hand-eye as
//! translation and roll/pitch/yaw with σ carried through the rotation's
//! Jacobians, the kinematic deviations with σ, and what the method held
//! fixed or could not separate.

use std::collections::{HashMap, HashSet};
use std::path::PathBuf;

use nalgebra::{Matrix3, UnitQuaternion, Vector3};

use super::{
    COUPLING_REL, Combination, DateSource, Entry, HandEye, PRIOR_HELD_FRACTION, PairedBy,
    ParamValue, RPY_STEP_DEG, Status, Timestamp, Unit, hand_eye_names,
};
use crate::engine::base::geometry::wrap_deg;
use crate::engine::base::robot::{Joint, PARAM_IS_ANGLE, PARAMS_PER_JOINT, Robot};
use crate::engine::calibrate::solve::SolverReport;
use crate::engine::calibrate::solve::estimate::HAND_EYE_LABELS;
use crate::engine::files::format::ResultFile;

/// What a result's method says about its parameters.
#[derive(Debug, Default)]
pub(super) struct SolverInfo {
    estimated: Vec<String>,
    fixed: Vec<String>,
    combinations: Vec<Combination>,
    covariance: Option<(Vec<String>, Vec<Vec<f64>>)>,
    stds: HashMap<String, f64>,
    /// Prior σ (angle deg, length mm) when the prior was on.
    prior: Option<(f64, f64)>,
    variance_factor: Option<f64>,
    kept_directions: Option<usize>,
}

pub(super) fn solver_info(report: &SolverReport) -> SolverInfo {
    match report {
        SolverReport::Ml(r) => {
            let c = &r.covariance;
            let square = c.matrix.len() == c.labels.len()
                && c.matrix.iter().all(|row| row.len() == c.labels.len());
            SolverInfo {
                estimated: r.estimated.clone(),
                fixed: r.fixed.clone(),
                combinations: r
                    .inseparable
                    .iter()
                    .map(|i| Combination {
                        fixed: i.fixed().into_iter().map(str::to_string).collect(),
                        partners: i.partners().into_iter().map(str::to_string).collect(),
                        text: i.to_string(),
                    })
                    .collect(),
                covariance: square.then(|| (c.labels.clone(), c.matrix.clone())),
                stds: r
                    .parameters
                    .iter()
                    .map(|p| (p.parameter.clone(), p.std))
                    .collect(),
                prior: r
                    .prior
                    .enabled
                    .then_some((r.prior.angle_sigma_deg, r.prior.length_sigma_mm)),
                variance_factor: Some(r.variance_factor),
                kept_directions: None,
            }
        }
        SolverReport::Paper(p) => SolverInfo {
            kept_directions: p.kept_directions,
            ..SolverInfo::default()
        },
        SolverReport::Other { .. } => SolverInfo::default(),
    }
}

/// The hand-eye twist labels a hand-eye value depends on (its block).
pub(super) fn twist_block(index: usize) -> &'static [&'static str] {
    if index < 3 {
        &HAND_EYE_LABELS[..3]
    } else {
        &HAND_EYE_LABELS[3..]
    }
}

pub(super) fn roll_pitch_yaw_deg(q: &UnitQuaternion<f64>) -> Vector3<f64> {
    Vector3::from(crate::engine::base::geometry::roll_pitch_yaw_deg(q))
}

/// Jacobians of the hand-eye translation (mm / mm) and roll-pitch-yaw
/// (deg / deg) with respect to the right twist `eT_s · exp(Δ)`.
pub(super) fn hand_eye_jacobians(rotation: &UnitQuaternion<f64>) -> (Matrix3<f64>, Matrix3<f64>) {
    let jt = rotation.to_rotation_matrix().into_inner();
    let mut jr = Matrix3::zeros();
    for i in 0..3 {
        let mut axis = Vector3::zeros();
        axis[i] = RPY_STEP_DEG.to_radians();
        let plus = roll_pitch_yaw_deg(&(rotation * UnitQuaternion::from_scaled_axis(axis)));
        let minus = roll_pitch_yaw_deg(&(rotation * UnitQuaternion::from_scaled_axis(-axis)));
        for r in 0..3 {
            jr[(r, i)] = wrap_deg(plus[r] - minus[r]) / (2.0 * RPY_STEP_DEG);
        }
    }
    (jt, jr)
}

/// The twist labels ([`HAND_EYE_LABELS`]) hand-eye value `index` depends
/// on (see [`COUPLING_REL`]).
pub(super) fn coupled_twist(rotation: &UnitQuaternion<f64>, index: usize) -> Vec<&'static str> {
    let (jt, jr) = hand_eye_jacobians(rotation);
    let (jac, row) = if index < 3 {
        (jt, index)
    } else {
        (jr, index - 3)
    };
    let biggest = (0..3).map(|c| jac[(row, c)].abs()).fold(0.0, f64::max);
    let block = twist_block(index);
    (0..3)
        .filter(|&c| jac[(row, c)].abs() >= COUPLING_REL * biggest)
        .map(|c| block[c])
        .collect()
}

/// The nominal and calibrated joints of a result (none for a hand-eye
/// only result): the calibrated model minus its errors is the nominal.
fn model_joints(result: &ResultFile) -> (Vec<Joint>, Vec<Joint>) {
    let calibrated: Vec<Joint> = match &result.robot {
        Some(r) if !result.hand_eye_only() => r.joints.clone(),
        _ => Vec::new(),
    };
    let nominal: Vec<Joint> = calibrated
        .iter()
        .zip(&result.joint_errors)
        .map(|(c, e)| c.minus(e))
        .collect();
    (nominal, calibrated)
}

#[allow(
    clippy::unnecessary_wraps,
    reason = "the same shape as the walk's other readers, which can fail"
)]
pub(super) fn build_entry(
    path: PathBuf,
    result: &ResultFile,
    session_path: Option<PathBuf>,
    paired_by: Option<PairedBy>,
    date: Timestamp,
    date_source: DateSource,
    notes: Vec<String>,
) -> Result<Entry, String> {
    let he_iso = result.hand_eye;
    let hand_eye = HandEye::new(&result.hand_eye);
    let hand_eye_initial = HandEye::new(&result.hand_eye_initial);
    let method = result.solver.method().to_string();
    let info = solver_info(&result.solver);
    let sigma_scale = info.variance_factor.map_or(1.0, |v| v.max(1.0).sqrt());
    let estimated: HashSet<&str> = info.estimated.iter().map(String::as_str).collect();
    let fixed: HashSet<&str> = info.fixed.iter().map(String::as_str).collect();
    let status_of = |label: &str| {
        if estimated.contains(label) {
            Status::Estimated
        } else if fixed.contains(label) {
            Status::Fixed
        } else {
            Status::Unknown
        }
    };
    let cov = |a: &str, b: &str| -> Option<f64> {
        let (labels, m) = info.covariance.as_ref()?;
        let i = labels.iter().position(|l| l == a)?;
        let j = labels.iter().position(|l| l == b)?;
        Some(m[i][j])
    };
    let std_of = |label: &str| -> Option<f64> {
        info.stds
            .get(label)
            .copied()
            .or_else(|| cov(label, label).map(crate::engine::base::numeric::sigma_of_variance))
            .filter(|s| s.is_finite())
    };

    let mut params = Vec::with_capacity(6 + PARAMS_PER_JOINT * result.joint_errors.len());
    // Hand-eye: the twist covariance carried through the Jacobians.
    let (jt, jr) = hand_eye_jacobians(&he_iso.rotation);
    let has_cov = info.covariance.is_some();
    for (i, name) in hand_eye_names(result.mount()).iter().enumerate() {
        let block = twist_block(i);
        let (jac, row) = if i < 3 { (&jt, i) } else { (&jr, i - 3) };
        let statuses: Vec<Status> = coupled_twist(&he_iso.rotation, i)
            .into_iter()
            .map(status_of)
            .collect();
        let status = if statuses.iter().all(|s| *s == Status::Estimated) {
            Status::Estimated
        } else if statuses.contains(&Status::Fixed) {
            Status::Fixed
        } else {
            Status::Unknown
        };
        let sigma = (has_cov && status == Status::Estimated).then(|| {
            // A fixed twist component has no variance; its entries are 0.
            let mut var = 0.0;
            for a in 0..3 {
                for b in 0..3 {
                    var += jac[(row, a)] * jac[(row, b)] * cov(block[a], block[b]).unwrap_or(0.0);
                }
            }
            crate::engine::base::numeric::sigma_of_variance(var) * sigma_scale
        });
        let value = if i < 3 {
            hand_eye.translation[i]
        } else {
            hand_eye.rpy_deg[i - 3]
        };
        params.push(ParamValue {
            name: (*name).to_string(),
            unit: if i < 3 { Unit::Mm } else { Unit::Deg },
            value,
            sigma: sigma.filter(|s| s.is_finite()),
            status,
            prior_held: false,
        });
    }
    for (k, err) in result
        .joint_errors
        .iter()
        .flat_map(|j| (0..PARAMS_PER_JOINT).map(move |p| j.get(p)))
        .enumerate()
    {
        let label = Robot::param_label(k);
        let is_angle = PARAM_IS_ANGLE[k % PARAMS_PER_JOINT];
        let status = status_of(&label);
        let sigma = (status != Status::Fixed)
            .then(|| std_of(&label))
            .flatten()
            .map(|s| s * sigma_scale);
        let prior_held = match (info.prior, sigma) {
            (Some((angle, length)), Some(s)) => {
                let prior = if is_angle { angle } else { length };
                prior > 0.0 && s / sigma_scale >= PRIOR_HELD_FRACTION * prior
            }
            _ => false,
        };
        params.push(ParamValue {
            name: label,
            unit: if is_angle { Unit::Deg } else { Unit::Mm },
            value: err,
            sigma,
            status,
            prior_held,
        });
    }
    let (nominal, calibrated) = model_joints(result);
    let validation = result.validation.as_ref();
    Ok(Entry {
        path,
        session_path,
        paired_by,
        date,
        date_source,
        robot: result.robot_name().to_string(),
        session: result.session.clone(),
        method,
        epsilon_before: result.epsilon_before,
        epsilon_after: result.epsilon_after,
        validation_before: validation.map(|v| v.before),
        validation_after: validation.map(|v| v.after),
        within_station_before: validation.map(|v| v.within_station.before),
        within_station_after: validation.map(|v| v.within_station.after),
        mount: result.mount(),
        hand_eye,
        hand_eye_initial,
        nominal,
        calibrated,
        joint_errors: result.joint_errors.clone(),
        params,
        estimated: info.estimated,
        fixed: info.fixed,
        combinations: info.combinations,
        kept_directions: info.kept_directions,
        variance_factor: info.variance_factor,
        sigma_scale,
        notes,
    })
}
