//! Everything `ml` reports: the records of the result's `solver` block,
//! as data (the format module writes and reads them), and the command
//! line's summary lines.

use std::fmt::Write as _;

use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

use super::loop_record::LoopRecord;
use crate::engine::calibrate::solve::ml::identifiability::Inseparable;
use crate::engine::calibrate::solve::ml::noise::Loss;
use crate::engine::calibrate::solve::ml::range;

/// What one accepted LM step did (the `iterations` of the solver block).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct IterationRecord {
    /// Robust cost after the step (½ Σ ρ-weighted squared whitened residuals, plus prior).
    pub cost: f64,
    /// Marquardt damping used (relative to `diag(JᵀJ)`).
    pub lm_lambda: f64,
    /// Largest scaled step component, mm (angles × 1000 mm/rad).
    pub step_max_mm: f64,
    /// Relative cost decrease of the step.
    pub relative_decrease: f64,
    /// ε (eq. 20, pooled) after the step, mm.
    pub epsilon: f64,
}

/// A parameter of the solve with its uncertainty.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct ParameterRecord {
    /// Label (`he_x` … `d6`).
    pub parameter: String,
    /// Change from the start (nominal, or the initial hand-eye), file units.
    pub change: f64,
    /// Standard deviation, file units.
    pub std: f64,
    /// `"mm"` or `"deg"`.
    pub unit: String,
}

/// A labelled symmetric matrix (covariance or correlation).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct LabelledMatrix {
    /// Row and column labels.
    pub labels: Vec<String>,
    /// Units of each row (`mm` or `deg`; the entry `(i, j)` is in
    /// `unit_i · unit_j`); empty for correlations.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub units: Vec<String>,
    /// Row-major entries.
    pub matrix: Vec<Vec<f64>>,
}

/// Predicted standard deviations of centre-to-centre distances over a set
/// of pose pairs, mm.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct DistanceStd {
    /// Pose pairs.
    pub pairs: usize,
    /// Mean over the pairs of the total σ (parameters and the two sightings' noise), mm.
    pub mean: f64,
    /// Largest total σ, mm.
    pub max: f64,
    /// RMS of the total σ, mm: the expected RMS error of these distances
    /// (compare with a measured `rms`).
    pub rms: f64,
    /// Expected sample standard deviation of the errors over this set of
    /// pairs, mm: the common part of the parameter error (e.g. a length
    /// scale) removed, as the validation `std` removes the mean error.
    /// Compare with a measured `std`.
    pub centred: f64,
    /// Mean of the part due to the parameter uncertainty alone, mm.
    pub parameter_mean: f64,
    /// Largest parameter part, mm.
    pub parameter_max: f64,
}

/// Leave-one-station-out result of one station.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct CrossStation {
    /// Station id.
    pub station: String,
    /// Pairs of its measurements.
    pub pairs: usize,
    /// RMS of the within-station centre distances predicted by the model
    /// fitted without the station, mm.
    pub rms: f64,
}

/// Leave-one-station-out cross-validation.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct CrossValidation {
    /// Per station.
    pub stations: Vec<CrossStation>,
    /// RMS over all pairs of all stations, mm: an accuracy estimate (the
    /// within-station distance error on unseen stations) with no tracker.
    pub rms: f64,
}

/// A measurement whose residual marks it as an outlier.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct OutlierRecord {
    /// Measurement id.
    pub measurement: String,
    /// Station id.
    pub station: String,
    /// Norm of `X_i − c_s` (base frame), mm.
    pub residual_mm: f64,
    /// Standardised whitened residual norm, σ.
    pub sigma: f64,
    /// Why it is listed.
    pub reason: String,
}

/// The noise model as reported.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct NoiseModel {
    /// σ of the joint readings, deg.
    pub joint_sigma_deg: f64,
    /// σ of each base-frame coordinate from the error of a reported flange
    /// pose, mm (pose-only sessions only; estimated from the data unless
    /// set).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pose_sigma_mm: Option<f64>,
    /// Rounds of variance-component estimation that settled
    /// `pose_sigma_mm` at the solution (issue 32); absent when the σ was
    /// given, and in results written before it was estimated there.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pose_sigma_rounds: Option<usize>,
    /// σ of each coordinate of a given centre, mm.
    pub centre_sigma_mm: f64,
    /// Floor of each principal σ of the sensor-frame covariance, mm.
    pub sensor_sigma_floor_mm: f64,
    /// How residuals are whitened.
    pub whitening: String,
}

/// The prior as reported.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct PriorRecord {
    /// Whether it was used.
    pub enabled: bool,
    /// σ of angle deviations, deg.
    pub angle_sigma_deg: f64,
    /// σ of length deviations, mm.
    pub length_sigma_mm: f64,
}

/// The robust loss as reported.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct LossRecord {
    /// `squared`, `huber` or `cauchy`.
    pub kind: Loss,
    /// Scale `k`, σ of the whitened residual norm.
    pub scale_sigma: f64,
}

/// One pivot of the identifiability QR.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct PivotRecord {
    /// Parameter label.
    pub parameter: String,
    /// `|R_kk| / |R_11|`.
    pub relative: f64,
}

/// The identifiability analysis as reported.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct IdentifiabilityRecord {
    /// The method, in words.
    pub method: String,
    /// Relative pivot tolerance.
    pub tolerance: f64,
    /// Pivots in order.
    pub pivots: Vec<PivotRecord>,
}

/// Everything the `ml` method reports: the result file's `solver` block.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct MlReport {
    /// Noise model.
    pub noise_model: NoiseModel,
    /// Prior.
    pub prior: PriorRecord,
    /// Robust loss.
    pub loss: LossRecord,
    /// Solver, in words.
    pub solver: String,
    /// The loop: threshold, bound, why it stopped.
    #[serde(flatten)]
    pub stop: LoopRecord,
    /// Identify measurements used.
    pub measurements: usize,
    /// Identify stations (each with an unknown centre).
    pub stations: usize,
    /// Rank analysis.
    pub identifiability: IdentifiabilityRecord,
    /// Estimated parameters.
    pub estimated: Vec<String>,
    /// Parameters fixed at their start.
    pub fixed: Vec<String>,
    /// Combinations the data cannot separate (written one sentence each).
    pub inseparable: Vec<Inseparable>,
    /// Estimated parameters with their change and σ.
    pub parameters: Vec<ParameterRecord>,
    /// Covariance of the estimated parameters (file units).
    pub covariance: LabelledMatrix,
    /// Correlation of the estimated parameters.
    pub correlation: LabelledMatrix,
    /// Pairs with |correlation| ≥ 0.95, e.g. `"he_rx / beta6: -0.98"`.
    pub strong_correlations: Vec<String>,
    /// Σ r² / (residuals − unknowns) of the whitened residuals: ≈ 1 when
    /// the noise model is right; the covariance is not rescaled by it.
    pub variance_factor: f64,
    /// Predicted σ of distances over the validate pose pairs (FORMAT.md
    /// pairing), when the session has them.
    pub predicted_distance_std_validate: Option<DistanceStd>,
    /// Predicted σ of distances between the k-th poses of every two
    /// identify stations (the measured volume).
    pub predicted_distance_std_identify: DistanceStd,
    /// Leave-one-station-out cross-validation, when enabled.
    pub cross_validation: Option<CrossValidation>,
    /// Predicted error over the sensor's range (or the region the sphere
    /// covered), from the covariance ([`super::range`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub range_error: Option<range::RangeError>,
    /// Predicted measuring error over the session's volume (a posteriori),
    /// with 2 or more stations ([`super::range::VolumeError`]); absent in
    /// results written before 2026-11-28.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub volume_error: Option<range::VolumeError>,
    /// Outlier limit, σ of the standardised residual norm.
    pub outlier_limit_sigma: f64,
    /// Measurements beyond the limit.
    pub outliers: Vec<OutlierRecord>,
    /// Accepted LM steps.
    pub iterations: Vec<IterationRecord>,
    /// Keys of the block this build does not know, kept as read.
    #[serde(flatten)]
    pub extra: Map<String, Value>,
}

/// Largest |entry| of a parameter covariance read back, in file units
/// (mm², mm·deg, deg²): a σ of 10,000 km is no calibration (a weakly
/// identified parameter's σ stays far below it).
const MAX_COVARIANCE: f64 = 1e20;

impl MlReport {
    /// What makes this block, read back from a result file, no
    /// calibration's: a variance factor that is negative or not finite
    /// (0 is a fit without residuals: a noise-free simulation), a
    /// covariance with a label twice, an entry beyond [`MAX_COVARIANCE`]
    /// or not finite, a negative variance, or a covariance beyond its
    /// variances (`|c_ij| > √(c_ii·c_jj)`: not positive semi-definite).
    /// `None` when it is plausible.
    #[must_use]
    pub fn implausible(&self) -> Option<String> {
        let v = self.variance_factor;
        if !(v.is_finite() && v >= 0.0) {
            return Some(format!(
                "`solver.variance_factor` = {v} is not plausible: Σ r² / degrees of freedom is a number of at least 0"
            ));
        }
        let c = &self.covariance;
        for (i, l) in c.labels.iter().enumerate() {
            if let Some(j) = c.labels[..i].iter().position(|x| x == l) {
                return Some(format!(
                    "`solver.covariance` has the label `{l}` twice (rows {j} and {i})"
                ));
            }
        }
        let n = c.labels.len();
        if c.matrix.len() != n || c.matrix.iter().any(|r| r.len() != n) {
            return Some(format!(
                "`solver.covariance` is not {n}×{n}, as its {n} labels say"
            ));
        }
        for i in 0..n {
            for j in 0..n {
                let x = c.matrix[i][j];
                let key = format!("`solver.covariance` ({}, {})", c.labels[i], c.labels[j]);
                if !(x.is_finite() && x.abs() <= MAX_COVARIANCE) {
                    return Some(format!(
                        "{key} = {x:e} is not plausible (at most {MAX_COVARIANCE:e})"
                    ));
                }
                let (a, b) = (c.matrix[i][i], c.matrix[j][j]);
                if i == j && x < 0.0 {
                    return Some(format!("{key} = {x:e}: a variance is not negative"));
                }
                if x.abs() > (a * b).max(0.0).sqrt() * (1.0 + 1e-6) + 1e-12 {
                    return Some(format!(
                        "{key} = {x:e} exceeds √(variance·variance) = {:e}: the covariance is not positive semi-definite",
                        (a * b).max(0.0).sqrt()
                    ));
                }
            }
        }
        None
    }

    /// A few lines for people (the command line's summary).
    #[must_use]
    pub fn summary(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "ml: {} measurements, {} station centres; estimated {} of {} parameters, fixed: {}",
            self.measurements,
            self.stations,
            self.estimated.len(),
            self.estimated.len() + self.fixed.len(),
            if self.fixed.is_empty() {
                "none".into()
            } else {
                self.fixed.join(", ")
            }
        );
        for c in &self.inseparable {
            let _ = writeln!(s, "  cannot separate: {c}");
        }
        if let Some(pose) = self.noise_model.pose_sigma_mm {
            let how = match self.noise_model.pose_sigma_rounds {
                Some(n) => format!(
                    "estimated at the solution (variance-component estimation, {n} round{})",
                    if n == 1 { "" } else { "s" }
                ),
                None => "given (--pose-sigma), or in a result written before 2026-11-27 estimated at the start".to_string(),
            };
            let _ = writeln!(
                s,
                "  flange pose σ {pose:.4} mm each base coordinate, {how}"
            );
        }
        let _ = writeln!(
            s,
            "  variance factor {:.3} (≈ 1 when the noise model fits)",
            self.variance_factor
        );
        if let Some(v) = &self.predicted_distance_std_validate {
            let _ = writeln!(
                s,
                "  predicted σ of validate distances: mean {:.4} mm, max {:.4} mm (parameters alone: mean {:.4} mm); expected validation std {:.4} mm (common part removed)",
                v.mean, v.max, v.parameter_mean, v.centred
            );
        }
        let p = &self.predicted_distance_std_identify;
        // With one station there is no distance across the volume.
        if self.stations > 1 {
            let _ = writeln!(
                s,
                "  predicted σ of distances across the identify volume: mean {:.4} mm, max {:.4} mm (parameters alone: mean {:.4} mm)",
                p.mean, p.max, p.parameter_mean
            );
        }
        if let Some(cv) = &self.cross_validation {
            let worst = cv.stations.iter().max_by(|a, b| a.rms.total_cmp(&b.rms));
            let _ = writeln!(
                s,
                "  leave-one-station-out: within-station distance RMS {:.4} mm{}",
                cv.rms,
                worst
                    .map(|w| format!(" (worst {} {:.4} mm)", w.station, w.rms))
                    .unwrap_or_default()
            );
        }
        if let Some(v) = &self.volume_error {
            let _ = writeln!(s, "  {}", v.summary());
        }
        if let Some(r) = &self.range_error {
            let _ = writeln!(s, "  {}", r.summary());
            if let Some(w) = &r.warning {
                let _ = writeln!(s, "  warning: {w}");
            }
        }
        if self.outliers.is_empty() {
            let _ = writeln!(s, "  no outliers beyond {:.2} σ", self.outlier_limit_sigma);
        }
        for o in &self.outliers {
            let _ = writeln!(
                s,
                "  outlier {} (station {}): {}",
                o.measurement, o.station, o.reason
            );
        }
        s
    }
}
