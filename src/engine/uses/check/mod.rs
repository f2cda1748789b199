//! The five-minute re-check (issue 33): does the cell still hold its
//! calibration? At most 30 poses at one to three sphere positions about a
//! rough one, planned by `plan --check` ([`choose_check_design`]: the
//! layout that detects the most, [`plan_check`]), imported like any session, are
//! predicted through the result's calibrated model and hand-eye and
//! tested against the result's covariance and noise model
//! ([`recheck`](crate::engine::calibrate::solve::ml::recheck): a χ² test
//! at false-alarm rate α, the sphere's position fitted since it may have
//! been moved). When the cell does not hold, the candidate change that
//! explains most is named: the hand-eye (the sensor knocked on its
//! mount) or one of the kinematic parameters the check's poses can see
//! (e.g. `theta2`, `theta3`, `d4`). A rigid drift of the whole robot
//! (its base) moves every centre alike and cannot be told from a moved
//! sphere at one station.
//!
//! A pose-only result (flange poses, hand-eye only) is checked from a
//! pose list: the hand-eye alone, the controller's flange poses taken as
//! they are with the result's pose σ.
//!
//! [`entry`] is the one entry the command line and the workbench call
//! ([`check_file`]).

pub mod design;
pub mod entry;

use nalgebra::Isometry3;

pub use design::{
    CheckChoice, MAX_CHECK_POSES, MAX_CHECK_STATIONS, check_minutes, choose_check_design,
};
pub use entry::{
    CheckRequest, CheckSource, check_file, check_record, detectable_lines, verdict_lines,
    write_record,
};

use crate::engine::base::robot::Robot;
use crate::engine::base::session::Mount;
use crate::engine::base::session::Session;
use crate::engine::calibrate::handeye::Sighting;
use crate::engine::calibrate::solve::SolverReport;
use crate::engine::calibrate::solve::analyse;
use crate::engine::calibrate::solve::estimate::Estimate;
use crate::engine::calibrate::solve::ml::MlOptions;
use crate::engine::calibrate::solve::ml::covariance::ParameterCovariance;
use crate::engine::calibrate::solve::ml::noise::sensor_covariance;
use crate::engine::calibrate::solve::ml::recheck::{
    CheckModel, CheckPoint, CheckTest, Detectable, Moved, RecheckError, detectable, recheck,
};
use crate::engine::files::format::{FileError, ResultFile};
use crate::engine::tools::plan::{Plan, PlanConfig, StationLayout, stripe_centre_covariance};
use crate::engine::uses::measure::variance_factor;

/// The default false-alarm rate: one false alarm in a thousand checks of
/// an unchanged cell.
pub const DEFAULT_ALPHA: f64 = 0.001;

/// The power `plan --check` quotes its smallest detectable changes at.
pub const DETECTION_POWER: f64 = 0.95;

/// Translation poses of a planned check: the fewest eq. 6-7 takes.
pub const CHECK_TRANSLATIONS: usize = 3;

/// Rotation poses of a planned check: the fewest eq. 8-9 takes.
pub const CHECK_ROTATIONS: usize = 2;

/// A check could not be made.
#[derive(Debug, thiserror::Error)]
pub enum CheckError {
    /// The inputs do not fit together (a check from another robot, a
    /// result without covariance).
    #[error("{0}")]
    Input(String),
    /// The test cannot be computed.
    #[error(transparent)]
    Recheck(#[from] RecheckError),
    /// A session or result file could not be read.
    #[error(transparent)]
    File(#[from] FileError),
    /// Stopped on request (the workbench's Cancel).
    #[error("the check was cancelled")]
    Cancelled,
}

/// A session checked against a result.
#[derive(Debug, Clone)]
pub struct Checked {
    /// The test and the candidate changes.
    pub test: CheckTest,
    /// Sightings used.
    pub sightings: usize,
    /// Measurements left out (their stripe gave no centre), with why.
    pub skipped: Vec<String>,
    /// Whether only the hand-eye was checked (flange poses).
    pub hand_eye_only: bool,
    /// What was noticed on the way.
    pub notes: Vec<String>,
}

/// The model a check is made against: the result's calibrated model and
/// hand-eye, its covariance in engine units, its noise model; `robot` is
/// used for a result without one (pose-only; its columns are then unused).
///
/// # Errors
/// [`CheckError::Input`] for a result without `ml`'s covariance and noise
/// model, or a covariance that does not fit the result's model.
pub fn model_of(result: &ResultFile, robot: &Robot) -> Result<CheckModel, CheckError> {
    let SolverReport::Ml(ml) = &result.solver else {
        return Err(CheckError::Input(format!(
            "the result (method {}) has no parameter covariance and noise model: a check needs an `ml` result (calibrate with --method ml)",
            result.solver.method()
        )));
    };
    let model_robot = result.robot.clone().unwrap_or_else(|| robot.clone());
    let cov = ParameterCovariance::read(&result.solver, model_robot.dof())
        .map_err(|e| CheckError::Input(e.to_string()))?
        .ok_or_else(|| {
            CheckError::Input(
                "the result has no parameter covariance (its ml run stopped before its diagnostics): calibrate again".into(),
            )
        })?;
    if result.mount() != Mount::Flange {
        return Err(CheckError::Input(
            "the result is of a fixed sensor: the re-check is of a sensor on the flange (calibrate the fixed cell again with a short session instead)".into(),
        ));
    }
    let noise = &ml.noise_model;
    Ok(CheckModel {
        estimate: Estimate {
            robot: model_robot,
            flange_from_sensor: result.hand_eye,
            mount: Mount::Flange,
        },
        covariance: cov.in_engine_units(),
        unknowns: cov.unknowns,
        joint_sigma_deg: noise.joint_sigma_deg,
        pose_sigma_mm: noise.pose_sigma_mm.unwrap_or(0.0),
        scale: variance_factor(result),
    })
}

/// Keeps the hand-eye's part of the model's covariance: flange poses see
/// the hand-eye only, so no kinematic parameter is a candidate.
fn hand_eye_part(model: &mut CheckModel) {
    let keep: Vec<usize> = (0..model.unknowns.len())
        .filter(|&i| model.unknowns[i] < 6)
        .collect();
    model.covariance = model.covariance.select_rows(&keep).select_columns(&keep);
    model.unknowns = keep.iter().map(|&i| model.unknowns[i]).collect();
}

/// The noise settings of the result's `ml` run that the sensor-frame
/// covariance of a centre needs.
fn ml_options(result: &ResultFile) -> MlOptions {
    let mut o = MlOptions::default();
    if let SolverReport::Ml(ml) = &result.solver {
        o.centre_sigma = ml.noise_model.centre_sigma_mm;
        o.sensor_sigma_floor = ml.noise_model.sensor_sigma_floor_mm;
    }
    o
}

/// Refuses a check session that is not of the result's cell; returns
/// whether it gives flange poses (the hand-eye alone is checked) and
/// notes.
fn belongs(session: &Session, result: &ResultFile) -> Result<(bool, Vec<String>), CheckError> {
    let mut notes = Vec::new();
    let flange = session.measurements.iter().all(|m| m.flange.is_some());
    let joints = session.measurements.iter().find(|m| m.flange.is_none());
    if let Some(m) = joints {
        let Some(robot) = result.robot.as_ref().filter(|_| !result.hand_eye_only()) else {
            return Err(CheckError::Input(format!(
                "measurement {}: the check gives joint readings, but the result calibrated only the hand-eye from flange poses: check it from a pose list (import --poses)",
                m.id
            )));
        };
        if session.robot.dof() != robot.dof() || session.robot.name != robot.name {
            return Err(CheckError::Input(format!(
                "the check's robot {:?} ({} joints) is not the result's {:?} ({} joints): a check of another cell",
                session.robot.name,
                session.robot.dof(),
                robot.name,
                robot.dof()
            )));
        }
    } else if flange && !result.hand_eye_only() {
        notes.push(
            "the check gives flange poses: only the hand-eye is checked, not the calibrated kinematics".into(),
        );
    }
    Ok((flange, notes))
}

/// The check's sightings: every measurement whose stripe gives a centre
/// (the others listed as skipped).
fn points_of(session: &Session, result: &ResultFile) -> (Vec<CheckPoint>, Vec<String>) {
    let options = ml_options(result);
    let analysis = analyse(session);
    let mut points = Vec::new();
    let mut skipped = Vec::new();
    for (m, outcome) in session.measurements.iter().zip(&analysis.measurements) {
        match outcome {
            Ok(pm) => points.push(CheckPoint {
                station: m.station.clone(),
                sighting: Sighting {
                    id: m.id.clone(),
                    joints: m.joints.clone(),
                    flange: m.flange,
                    centre_in_sensor: pm.centre_in_sensor,
                },
                sensor_cov: sensor_covariance(pm, &options),
            }),
            Err(e) => skipped.push(format!("{}: {e}", m.id)),
        }
    }
    (points, skipped)
}

/// Checks `session` against `result` at false-alarm rate `alpha` (module
/// doc).
///
/// # Errors
/// [`CheckError`]: a session of another cell, a result without `ml`'s
/// covariance, too few sightings.
pub fn check_session(
    session: &Session,
    result: &ResultFile,
    alpha: f64,
) -> Result<Checked, CheckError> {
    if !(alpha > 0.0 && alpha < 0.5) {
        return Err(CheckError::Input(format!(
            "the false-alarm rate {alpha} is not between 0 and 0.5"
        )));
    }
    let (hand_eye_only, notes) = belongs(session, result)?;
    let mut model = model_of(result, &session.robot)?;
    if hand_eye_only {
        hand_eye_part(&mut model);
    }
    let (points, skipped) = points_of(session, result);
    let sightings = points.len();
    let test = recheck(&model, &points, alpha)?;
    Ok(Checked {
        test,
        sightings,
        skipped,
        hand_eye_only,
        notes,
    })
}

/// What moved, in words: the best explanation of a failed check.
#[must_use]
pub fn moved_words(checked: &Checked) -> Vec<String> {
    let mut out = Vec::new();
    let Some(best) = checked.test.explanations.first() else {
        out.push("no change of the hand-eye or of a parameter the check can see explains it: look for a loose sphere, a dirty or damaged sphere, or a base-like drift".into());
        return out;
    };
    let what = match &best.moved {
        Moved::HandEye => "the hand-eye (the sensor on its mount)".to_string(),
        Moved::Parameter(p) => format!("the robot's {p}"),
    };
    let sizes: Vec<String> = best
        .labels
        .iter()
        .zip(best.change.iter().zip(&best.sigma))
        .map(|(l, (c, s))| {
            let unit = if l.starts_with("he_r") || is_angle_label(l) {
                "°"
            } else {
                " mm"
            };
            format!("{l} {c:+.4}{unit} ± {s:.4}")
        })
        .collect();
    let left = if best.explains {
        "it explains the check (what is left passes)"
    } else {
        "what is left still fails: more than one thing moved, or something the check cannot name"
    };
    out.push(format!("what moved: {what}: {}; {left}", sizes.join(", ")));
    if let Some(next) = checked.test.explanations.get(1) {
        let name = match &next.moved {
            Moved::HandEye => "the hand-eye".to_string(),
            Moved::Parameter(p) => p.clone(),
        };
        out.push(format!(
            "next candidate: {name} (what is left with it: T {:.1} on {} degrees of freedom, against {:.1} on {})",
            next.remaining, next.remaining_dof, best.remaining, best.remaining_dof
        ));
    }
    out
}

fn is_angle_label(label: &str) -> bool {
    ["alpha", "beta", "theta"]
        .iter()
        .any(|p| label.starts_with(p))
}

/// The smallest changes a check of `plan`'s poses detects with
/// [`DETECTION_POWER`] at `alpha` against `result`: the planned centres
/// with the stripe covariance of `stripe_sigma` (mm) on the points.
///
/// # Errors
/// As [`check_session`].
pub fn plan_check(
    plan: &Plan,
    result: &ResultFile,
    stripe_sigma: f64,
    alpha: f64,
) -> Result<Detectable, CheckError> {
    let mut model = model_of(result, &plan.robot)?;
    let flange = result.hand_eye_only();
    if flange {
        hand_eye_part(&mut model);
    }
    let options = ml_options(result);
    let floor = options.sensor_sigma_floor.powi(2);
    let points: Vec<CheckPoint> = plan
        .poses
        .iter()
        .map(|p| {
            let cov =
                stripe_centre_covariance(0.5 * plan.diameter, plan.cut_angle, p.side, stripe_sigma)
                    + nalgebra::Matrix3::identity() * floor;
            let flange_pose: Option<Isometry3<f64>> = flange.then_some(p.base_from_flange);
            CheckPoint {
                station: p.station.clone(),
                sighting: Sighting {
                    id: p.id.clone(),
                    joints: if flange { Vec::new() } else { p.joints.clone() },
                    flange: flange_pose,
                    centre_in_sensor: p.centre_in_sensor,
                },
                sensor_cov: cov,
            }
        })
        .collect();
    Ok(detectable(&model, &points, alpha, DETECTION_POWER)?)
}

/// Turns a plan's configuration into a check's: `poses` poses at the one
/// sphere position, after the fewest translation and rotation poses an
/// import needs there (no validate group), planned
/// about the result's calibrated model and hand-eye, chosen D-optimally (the most
/// information, so the most power, for the parameters the check sees).
pub fn check_design(config: &mut PlanConfig, result: &ResultFile, poses: usize) {
    let d = &mut config.design;
    // The smallest translation and rotation groups at the sphere: the
    // check imports like any session, its initial hand-eye from them
    // (eq. 6-9); they are sightings of the sphere like the others.
    d.n_translation = CHECK_TRANSLATIONS;
    d.n_rotation = CHECK_ROTATIONS;
    d.n_identify = 1;
    d.identify_poses = poses;
    d.n_validate = 0;
    config.stations = StationLayout::Explicit {
        identify: vec![config.design.sphere],
        validate: Vec::new(),
    };
    config.flange_from_sensor = result.hand_eye;
    // The joint targets solved on the calibrated model, so that the real
    // robot puts the sphere where the plan expects it (the cut).
    if let Some(robot) = result.robot.as_ref().filter(|_| !result.hand_eye_only())
        && robot.dof() == config.robot.dof()
    {
        config.robot = robot.clone();
    }
}
