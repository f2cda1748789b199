//! `ml`'s diagnostics at the solution: parameter covariance and
//! correlation, the predicted σ of centre distances, leave-one-station-out
//! cross-validation, the variance factor and the outliers.

use nalgebra::{DMatrix, DVector, Matrix3};

use super::MlUpdate;
use super::identifiability::raw_per_file_unit;
use super::noise::{OUTLIER_QUANTILE, base_covariance, chi3_quantile, sensor_covariance};
use super::problem::{InverseBlocks, Problem, State};
use crate::engine::base::records::ml::{
    DistanceStd, IdentifiabilityRecord, LabelledMatrix, LossRecord, MlReport, NoiseModel,
    OutlierRecord, ParameterRecord, PivotRecord, PriorRecord,
};
use crate::engine::base::session::Use;
use crate::engine::calibrate::handeye::Sighting;
use crate::engine::calibrate::solve::estimate::{
    ANGLE_SCALE_MM, Estimate, sensitivity, unknown_is_angle, unknown_label,
};
use crate::engine::calibrate::solve::{Control, Phase, StopReason};

/// Correlations at least this large (absolute) are listed by name: beyond
/// 0.95 two parameters are nearly interchangeable for this data.
pub const STRONG_CORRELATION: f64 = 0.95;

/// Most station pairs the predicted σ of distances across the identify
/// volume is averaged over; beyond it an even sample of the pairs (every
/// pair of up to 46 stations counts).
pub const MAX_STATION_PAIRS: usize = 1000;

/// Column `u` of `A` restricted and scaled to the estimated slots.
pub(super) fn restricted(a: &DMatrix<f64>, problem: &Problem) -> DVector<f64> {
    // Row vector of a 1×K gradient → k entries.
    DVector::from_iterator(
        problem.estimated.len(),
        problem
            .estimated
            .iter()
            .zip(&problem.scale)
            .map(|(&u, s)| a[(0, u)] / s),
    )
}

/// A sighting with its base-frame centre covariance (mm²).
pub(super) type NoisySighting = (Sighting, Matrix3<f64>);

/// Predicted σ of the distances between pairs of sightings.
pub(super) fn distance_std(
    problem: &Problem,
    est: &Estimate,
    cov: &DMatrix<f64>,
    pairs: &[(NoisySighting, NoisySighting)],
) -> DistanceStd {
    let mut out = DistanceStd {
        pairs: pairs.len(),
        ..DistanceStd::default()
    };
    if pairs.is_empty() {
        return out;
    }
    let mut sum_sq = 0.0;
    let mut grads: Vec<DVector<f64>> = Vec::with_capacity(pairs.len());
    let mut noise = 0.0;
    for ((sa, ca), (sb, cb)) in pairs {
        let (xa, aa) = sensitivity(est, sa);
        let (xb, ab) = sensitivity(est, sb);
        let d = xa - xb;
        let norm = d.norm();
        if norm <= 0.0 {
            continue;
        }
        let u = d / norm;
        let grad = DMatrix::from_row_slice(1, 3, u.as_slice()) * (aa - ab);
        let g = restricted(&grad, problem);
        let var_p = (g.transpose() * cov * &g)[(0, 0)].max(0.0);
        let var_n = (u.transpose() * (ca + cb) * u)[(0, 0)].max(0.0);
        noise += var_n;
        grads.push(g);
        let total = (var_p + var_n).sqrt();
        out.mean += total;
        out.max = out.max.max(total);
        sum_sq += total * total;
        out.parameter_mean += var_p.sqrt();
        out.parameter_max = out.parameter_max.max(var_p.sqrt());
    }
    let n = pairs.len() as f64;
    out.mean /= n;
    out.parameter_mean /= n;
    out.rms = (sum_sq / n).sqrt();
    // E[s²] = (tr(P·G·C·Gᵀ) + (1 − 1/m)·Σ v_k) / (m − 1), P = I − 11ᵀ/m,
    // the pairs' noise taken as independent.
    let m = grads.len();
    if m >= 2 {
        let mf = m as f64;
        let mean_grad = grads
            .iter()
            .fold(DVector::zeros(cov.nrows()), |acc, g| acc + g)
            / mf;
        let spread: f64 = grads
            .iter()
            .map(|g| {
                let c = g - &mean_grad;
                (c.transpose() * cov * &c)[(0, 0)]
            })
            .sum();
        out.centred = ((spread.max(0.0) + (1.0 - 1.0 / mf) * noise) / (mf - 1.0)).sqrt();
    }
    out
}

/// What the method did and how it was set, without the diagnostics: the
/// whole report of a cancelled run.
pub(super) fn settings(solver: &MlUpdate<'_>, stop: &StopReason) -> MlReport {
    let mo = &solver.options.ml;
    let problem = &solver.problem;
    let ident = &solver.ident;
    MlReport {
        noise_model: NoiseModel {
            joint_sigma_deg: mo.joint_sigma_deg,
            pose_sigma_mm: mo.pose_sigma,
            pose_sigma_rounds: solver.noise_rounds,
            centre_sigma_mm: mo.centre_sigma,
            sensor_sigma_floor_mm: mo.sensor_sigma_floor,
            whitening: "each centre residual (base frame) multiplied by the inverse Cholesky factor of R_bs·Σ_sensor·R_bsᵀ + G·σ_q²·Gᵀ (for a given flange pose: + σ_pose²·I instead of the joint term), computed from the initial model and hand-eye; where σ_pose is estimated, again at the solution with the σ_pose estimated there, until it settles".into(),
        },
        prior: PriorRecord {
            enabled: mo.prior,
            angle_sigma_deg: mo.prior_angle_deg,
            length_sigma_mm: mo.prior_length,
        },
        loss: LossRecord {
            kind: mo.loss,
            scale_sigma: mo.loss_scale,
        },
        solver: format!(
            "Levenberg-Marquardt (Marquardt damping λ·diag(JᵀJ)), unknowns scaled to mm (angles × {ANGLE_SCALE_MM} mm/rad), station centres as unknowns, dense Cholesky; one update of the loop is a complete LM solve"
        ),
        stop: stop.record(&solver.options),
        measurements: problem.obs.len(),
        stations: problem.stations.len(),
        identifiability: IdentifiabilityRecord {
            method: "QR with column pivoting of the whitened Jacobian of the 6 + 5n parameters, station-centre columns projected out, angles × 1000 mm/rad; pivots below tolerance × |R_11| are fixed at their start".into(),
            tolerance: mo.rank_tolerance,
            pivots: ident
                .pivots
                .iter()
                .map(|&(u, rel)| PivotRecord {
                    parameter: unknown_label(u),
                    relative: rel,
                })
                .collect(),
        },
        estimated: problem.estimated.iter().map(|&u| unknown_label(u)).collect(),
        fixed: ident.fixed.iter().map(|&u| unknown_label(u)).collect(),
        inseparable: ident.inseparable.clone(),
        outlier_limit_sigma: chi3_quantile(OUTLIER_QUANTILE),
        iterations: solver.history.clone(),
        ..MlReport::default()
    }
}

/// The report of a run that stopped for `stop`: the settings, and unless
/// it was cancelled the covariance, correlation, predicted distances,
/// cross-validation and outliers at the final state.
pub(super) fn report(
    solver: &MlUpdate<'_>,
    stop: &StopReason,
    phase: &mut dyn FnMut(Phase) -> Control,
) -> (MlReport, bool) {
    let base = settings(solver, stop);
    if stop.is_cancelled() {
        return (base, false);
    }
    let cancelled = |solver: &MlUpdate<'_>| (settings(solver, &stop.cancelled()), true);
    if phase(Phase::Covariance) == Control::Cancel {
        return cancelled(solver);
    }
    let (session, prepared) = (solver.session, solver.prepared);
    let problem = &solver.problem;
    let state = &solver.state;
    let mo = &solver.options.ml;
    let lin = problem.linearize(state);
    let inverse = lin.inverse_blocks();
    let cov_scaled = inverse.p.clone();
    let FileCovariance {
        labels,
        units,
        matrix: cov_file,
        std,
        corr,
        strong,
    } = file_covariance(problem, &cov_scaled);
    let parameters = parameter_changes(solver, &labels, &units, &std);
    // Residual statistics, leverage and outliers.
    if phase(Phase::Outliers) == Control::Cancel {
        return cancelled(solver);
    }
    let limit = chi3_quantile(OUTLIER_QUANTILE);
    let (outliers, variance_factor) = outliers_and_variance(problem, state, &inverse);
    // Predicted distance σ.
    if phase(Phase::Prediction) == Control::Cancel {
        return cancelled(solver);
    }
    let (predicted_validate, predicted_identify) = predicted_distances(solver, &cov_scaled);
    if phase(Phase::RangeError) == Control::Cancel {
        return cancelled(solver);
    }
    // The range is a laser plane on the flange, and the volume error a
    // sphere seen by it; a fixed sensor has neither.
    let flange = session.mount == crate::engine::base::session::Mount::Flange;
    let range_error = flange
        .then(|| super::range::range_error(session, prepared, problem, &state.est, &cov_scaled))
        .flatten();
    // A posteriori, as `measure` reports a point's σ.
    let factor = super::covariance::a_posteriori_factor(variance_factor);
    let volume_error = flange
        .then(|| {
            super::range::volume_error(
                session,
                prepared,
                problem,
                &state.est,
                &(&cov_scaled * factor),
            )
        })
        .flatten();
    // Leave-one-station-out.
    let cross_validation = if mo.cross_validation && problem.stations.len() >= 2 {
        match problem.cross_validate(state, phase) {
            Some(cv) => Some(cv),
            None => return cancelled(solver),
        }
    } else {
        None
    };
    let report = MlReport {
        parameters,
        covariance: LabelledMatrix {
            labels: labels.clone(),
            units,
            matrix: cov_file,
        },
        correlation: LabelledMatrix {
            labels,
            units: Vec::new(),
            matrix: corr,
        },
        strong_correlations: strong,
        variance_factor,
        predicted_distance_std_validate: predicted_validate,
        predicted_distance_std_identify: predicted_identify,
        cross_validation,
        range_error,
        volume_error,
        outlier_limit_sigma: limit,
        outliers,
        ..base
    };
    (report, false)
}

/// The covariance of the estimated parameters in file units (mm, deg)
/// with what a reader needs of it.
struct FileCovariance {
    /// The parameters' labels.
    labels: Vec<String>,
    /// Their units (`mm` or `deg`).
    units: Vec<String>,
    /// The covariance, file units.
    matrix: Vec<Vec<f64>>,
    /// The standard deviations, file units.
    std: Vec<f64>,
    /// The correlations.
    corr: Vec<Vec<f64>>,
    /// The pairs correlated at least [`STRONG_CORRELATION`], as text.
    strong: Vec<String>,
}

/// The covariance `cov_scaled` (scaled unknowns) of `problem` in file
/// units, with its standard deviations and correlations.
fn file_covariance(problem: &Problem, cov_scaled: &DMatrix<f64>) -> FileCovariance {
    let k = problem.estimated.len();
    // File units: scaled → raw (÷ scale) → deg for angles.
    let to_file: Vec<f64> = problem
        .estimated
        .iter()
        .zip(&problem.scale)
        .map(|(&u, s)| {
            if unknown_is_angle(u) {
                1.0_f64.to_degrees() / s
            } else {
                1.0 / s
            }
        })
        .collect();
    let labels: Vec<String> = problem
        .estimated
        .iter()
        .map(|&u| unknown_label(u))
        .collect();
    let units: Vec<String> = problem
        .estimated
        .iter()
        .map(|&u| {
            if unknown_is_angle(u) {
                "deg".into()
            } else {
                "mm".into()
            }
        })
        .collect();
    let cov_file: Vec<Vec<f64>> = (0..k)
        .map(|i| {
            (0..k)
                .map(|j| cov_scaled[(i, j)] * to_file[i] * to_file[j])
                .collect()
        })
        .collect();
    let std: Vec<f64> = (0..k)
        .map(|i| crate::engine::base::numeric::sigma_of_variance(cov_file[i][i]))
        .collect();
    let corr: Vec<Vec<f64>> = (0..k)
        .map(|i| {
            (0..k)
                .map(|j| {
                    let d = std[i] * std[j];
                    if d > 0.0 { cov_file[i][j] / d } else { 0.0 }
                })
                .collect()
        })
        .collect();
    let mut strong = Vec::new();
    for i in 0..k {
        for j in i + 1..k {
            if corr[i][j].abs() >= STRONG_CORRELATION {
                strong.push(format!("{} / {}: {:+.3}", labels[i], labels[j], corr[i][j]));
            }
        }
    }
    FileCovariance {
        labels,
        units,
        matrix: cov_file,
        std,
        corr,
        strong,
    }
}

/// The change of each estimated parameter from the start (file units),
/// with its standard deviation.
fn parameter_changes(
    solver: &MlUpdate<'_>,
    labels: &[String],
    units: &[String],
    std: &[f64],
) -> Vec<ParameterRecord> {
    let (session, prepared) = (solver.session, solver.prepared);
    let problem = &solver.problem;
    let state = &solver.state;
    // Changes from the start, file units.
    let start_params = session.robot.params();
    let params = state.est.robot.params();
    let he_change = prepared.hand_eye_initial.inverse() * state.est.flange_from_sensor;
    let he_t = he_change.translation.vector;
    let he_r = he_change.rotation.scaled_axis();
    problem
        .estimated
        .iter()
        .enumerate()
        .map(|(slot, &u)| {
            let raw = if u < 3 {
                he_t[u]
            } else if u < 6 {
                he_r[u - 3]
            } else {
                params[u - 6] - start_params[u - 6]
            };
            ParameterRecord {
                parameter: labels[slot].clone(),
                change: raw / raw_per_file_unit(u),
                std: std[slot],
                unit: units[slot].clone(),
            }
        })
        .collect()
}

/// The outliers at the final state (residual beyond the χ(3) limit once
/// its leverage is accounted for), worst first, and the variance factor
/// `χ² / dof`.
fn outliers_and_variance(
    problem: &Problem,
    state: &State,
    inverse: &InverseBlocks,
) -> (Vec<OutlierRecord>, f64) {
    let limit = chi3_quantile(OUTLIER_QUANTILE);
    let mut chi2 = 0.0;
    let mut outliers = Vec::new();
    for o in &problem.obs {
        let (r, jp) = problem.obs_jacobian(o, state);
        chi2 += r.norm_squared();
        // Leverage: tr(J_i H⁻¹ J_iᵀ)/3 with J_i = [jp | −C⁻¹], from the
        // blocks of H⁻¹ (the station centres eliminated).
        let hat = inverse.hat(&jp, &(-o.whiten), o.station);
        let lev = (hat.trace() / 3.0).clamp(0.0, 0.99);
        let sigma = r.norm() / (1.0 - lev).sqrt();
        if sigma > limit {
            let e = state.est.centre_in_base(&o.sighting) - state.centres[o.station];
            outliers.push(OutlierRecord {
                measurement: o.sighting.id.clone(),
                station: problem.stations[o.station].clone(),
                residual_mm: e.norm(),
                sigma,
                reason: format!(
                    "residual {:.3} mm = {:.1} σ, beyond the χ(3) {:.1} % limit of {:.2} σ",
                    e.norm(),
                    sigma,
                    OUTLIER_QUANTILE * 100.0,
                    limit
                ),
            });
        }
    }
    outliers.sort_by(|a, b| b.sigma.total_cmp(&a.sigma));
    let dof = (3 * problem.obs.len()).saturating_sub(problem.dim()).max(1);
    let variance_factor = chi2 / dof as f64;
    (outliers, variance_factor)
}

/// The predicted σ of the validate distances (`None` without reference
/// distances) and of the identify station pairs.
fn predicted_distances(
    solver: &MlUpdate<'_>,
    cov_scaled: &DMatrix<f64>,
) -> (Option<DistanceStd>, DistanceStd) {
    let (session, prepared) = (solver.session, solver.prepared);
    let problem = &solver.problem;
    let state = &solver.state;
    let mo = &solver.options.ml;
    let noisy = |i: usize| -> NoisySighting {
        let s = prepared.sighting(session, i);
        let cov = base_covariance(
            &state.est,
            &s,
            &sensor_covariance(&prepared.measurements[i], mo),
            mo.joint_sigma_deg,
            mo.pose_sigma.unwrap_or(0.0),
        );
        (s, cov)
    };
    let validate = session.stations(Use::Validate);
    let find = |id: &str| validate.iter().find(|(s, _)| s == id).map(|(_, idx)| idx);
    let mut vpairs = Vec::new();
    for r in &session.reference_distances {
        if let (Some(a), Some(b)) = (find(&r.from), find(&r.to)) {
            for kk in 0..a.len().min(b.len()) {
                vpairs.push((noisy(a[kk]), noisy(b[kk])));
            }
        }
    }
    let identify = session.stations(Use::Identify);
    let station_pairs = identify.len() * identify.len().saturating_sub(1) / 2;
    // Every pair of stations up to MAX_STATION_PAIRS, else an even sample
    // of them: the count grows as the square of the stations.
    let stride = station_pairs.div_ceil(MAX_STATION_PAIRS).max(1);
    let mut ipairs = Vec::new();
    let mut nth = 0_usize;
    for (ia, (_, a)) in identify.iter().enumerate() {
        for (_, b) in identify.iter().skip(ia + 1) {
            nth += 1;
            if !(nth - 1).is_multiple_of(stride) {
                continue;
            }
            for kk in 0..a.len().min(b.len()) {
                ipairs.push((noisy(a[kk]), noisy(b[kk])));
            }
        }
    }
    let predicted_validate =
        (!vpairs.is_empty()).then(|| distance_std(problem, &state.est, cov_scaled, &vpairs));
    let predicted_identify = distance_std(problem, &state.est, cov_scaled, &ipairs);
    (predicted_validate, predicted_identify)
}
