//! Everything `ml` reports: the records of the result's `solver` block,
//! as data (the format module writes and reads them), and the command
//! line's summary lines.

use std::fmt::{self, Write as _};

use serde::{Deserialize, Deserializer, Serialize, Serializer};
use serde_json::{Map, Value};

use super::loop_record::LoopRecord;

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
    /// covered), from the covariance (`calibrate::solve::ml::range`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub range_error: Option<RangeError>,
    /// Predicted measuring error over the session's volume (a posteriori),
    /// with 2 or more stations ([`VolumeError`]); absent in
    /// results written before 2026-11-28.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub volume_error: Option<VolumeError>,
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

/// Robust loss on the norm `s` of a whitened 3-vector residual.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Loss {
    /// Plain least squares, `ρ(s) = s²/2`.
    Squared,
    /// Huber: quadratic up to `k`, linear beyond (the default).
    #[default]
    Huber,
    /// Cauchy: `ρ(s) = k²/2 · ln(1 + s²/k²)`, redescending.
    Cauchy,
}

impl Loss {
    /// The name used on the command line and in the result.
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Squared => "squared",
            Self::Huber => "huber",
            Self::Cauchy => "cauchy",
        }
    }

    /// Parses a loss name.
    #[must_use]
    pub fn parse(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|l| l.as_str() == s)
    }

    /// Every loss.
    pub const ALL: [Self; 3] = [Self::Squared, Self::Huber, Self::Cauchy];
}

/// Whether a parameter label names an angle (deg in files): the hand-eye
/// rotation and every joint's alpha, beta and theta.
fn label_is_angle(label: &str) -> bool {
    label.starts_with("he_r")
        || label.starts_with("alpha")
        || label.starts_with("beta")
        || label.starts_with("theta")
}

/// A parameter change of one file unit as text, by label.
fn label_unit(label: &str) -> &'static str {
    if label_is_angle(label) { "°" } else { " mm" }
}

/// An estimated parameter that undoes part of a fixed one's effect.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Partner {
    /// Its label (`he_z`, `theta3`, …).
    pub parameter: String,
    /// Its change (file units: mm or deg) that undoes one file unit of the
    /// fixed parameter.
    pub undo: f64,
}

/// A parameter `ml` held fixed, and why: what the data cannot separate it
/// from. Written in the result file as one sentence each, e.g.
/// `d6 ~ he_z: d6 +1 mm is undone by he_z +1.000 mm`.
#[derive(Debug, Clone, PartialEq)]
pub enum Inseparable {
    /// Parameters that move no centre distance at all: a rigid motion of
    /// the base frame, absorbed by the station centres.
    NoEffect(Vec<String>),
    /// A fixed parameter whose combination could not be computed.
    Unresolved(String),
    /// A fixed parameter whose effect estimated parameters undo.
    Combination {
        /// The fixed parameter.
        fixed: String,
        /// The estimated parameters that undo it, largest share first.
        partners: Vec<Partner>,
        /// The share of its effect they undo, %, when not all of it.
        explained_pct: Option<f64>,
    },
    /// A sentence this build cannot read (a later version's wording).
    Text(String),
}

/// End of the "no effect" sentence.
const NO_EFFECT_TEXT: &str = ": no effect on any centre distance (a rigid motion of the base frame, absorbed by the station centres)";
/// End of the "unresolved" sentence.
const UNRESOLVED_TEXT: &str = ": fixed (no estimated combination computed)";

impl Inseparable {
    /// The fixed parameters it names.
    #[must_use]
    pub fn fixed(&self) -> Vec<&str> {
        match self {
            Self::NoEffect(list) => list.iter().map(String::as_str).collect(),
            Self::Unresolved(f) | Self::Combination { fixed: f, .. } => vec![f.as_str()],
            Self::Text(t) => text_head(t).0,
        }
    }

    /// The estimated parameters that carry the fixed ones' effect (empty
    /// when they move no distance at all).
    #[must_use]
    pub fn partners(&self) -> Vec<&str> {
        match self {
            Self::Combination { partners, .. } => {
                partners.iter().map(|p| p.parameter.as_str()).collect()
            }
            Self::Text(t) => text_head(t).1,
            _ => Vec::new(),
        }
    }

    fn parse(text: &str) -> Option<Self> {
        if let Some(list) = text.strip_suffix(NO_EFFECT_TEXT) {
            return Some(Self::NoEffect(
                list.split(", ").map(str::to_string).collect(),
            ));
        }
        if let Some(f) = text.strip_suffix(UNRESOLVED_TEXT) {
            return Some(Self::Unresolved(f.to_string()));
        }
        let (head, rest) = text.split_once(": ")?;
        let (fixed, _) = head.split_once(" ~ ")?;
        let (undo, explained_pct) = match rest.rsplit_once(" (to ") {
            Some((u, tail)) => (
                u,
                Some(tail.strip_suffix(" % of its effect)")?.parse().ok()?),
            ),
            None => (rest, None),
        };
        let (_, parts) = undo.split_once(" is undone by ")?;
        let partners = parts
            .split(", ")
            .map(|part| {
                let (parameter, value) = part.split_once(' ')?;
                let number = value
                    .strip_suffix(label_unit(parameter))
                    .or_else(|| value.strip_suffix('°'))?;
                Some(Partner {
                    parameter: parameter.to_string(),
                    undo: number.parse().ok()?,
                })
            })
            .collect::<Option<Vec<_>>>()?;
        Some(Self::Combination {
            fixed: fixed.to_string(),
            partners,
            explained_pct,
        })
    }
}

/// The parameters a sentence of another wording names before its colon:
/// `fixed, … ~ partner, …: …` or `fixed, …: …`.
fn text_head(text: &str) -> (Vec<&str>, Vec<&str>) {
    let head = text.split_once(':').map_or(text, |(h, _)| h);
    match head.split_once(" ~ ") {
        Some((f, p)) => (names(f), names(p)),
        None => (names(head), Vec::new()),
    }
}

/// The comma-separated names of a list, blanks dropped.
fn names(list: &str) -> Vec<&str> {
    list.split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .collect()
}

impl fmt::Display for Inseparable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NoEffect(list) => write!(f, "{}{NO_EFFECT_TEXT}", list.join(", ")),
            Self::Unresolved(p) => write!(f, "{p}{UNRESOLVED_TEXT}"),
            Self::Text(t) => f.write_str(t),
            Self::Combination {
                fixed,
                partners,
                explained_pct,
            } => {
                let names: Vec<&str> = partners.iter().map(|p| p.parameter.as_str()).collect();
                let undo: Vec<String> = partners
                    .iter()
                    .map(|p| format!("{} {:+.3}{}", p.parameter, p.undo, label_unit(&p.parameter)))
                    .collect();
                write!(
                    f,
                    "{fixed} ~ {}: {fixed} +1{} is undone by {}",
                    names.join(", "),
                    label_unit(fixed),
                    undo.join(", ")
                )?;
                if let Some(pct) = explained_pct {
                    write!(f, " (to {pct:.1} % of its effect)")?;
                }
                Ok(())
            }
        }
    }
}

impl Serialize for Inseparable {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl<'de> Deserialize<'de> for Inseparable {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let text = String::deserialize(d)?;
        Ok(Self::parse(&text).unwrap_or(Self::Text(text)))
    }
}

/// The predicted error over the range (result file: `solver.range_error`).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct RangeError {
    /// What the grid covers: `sensor.range`, or `sphere positions` when
    /// the session gives no range.
    pub region: String,
    /// The grid's `[min, max]` along the line, mm (sensor frame).
    pub y: [f64; 2],
    /// The grid's `[min, max]` in depth, mm.
    pub z: [f64; 2],
    /// Grid points per side.
    pub grid: usize,
    /// Working poses the figures are over.
    pub poses: usize,
    /// RMS over grid points and poses of the 3-D 1σ, mm.
    pub rms_mm: f64,
    /// Mean of the 3-D 1σ, mm.
    pub mean_mm: f64,
    /// Largest 3-D 1σ (at any pose), mm.
    pub max_mm: f64,
    /// Where the largest is, `[y, z]` mm.
    pub max_at: [f64; 2],
    /// RMS 3-D 1σ at the mean sphere position, mm.
    pub at_sphere_mm: f64,
    /// `[min, max]` of the measured sphere positions along the line, mm.
    pub sphere_y: [f64; 2],
    /// `[min, max]` of the measured sphere positions in depth, mm.
    pub sphere_z: [f64; 2],
    /// Fraction of the range's area inside the sphere positions' extent
    /// (1 when the region is the sphere positions).
    pub coverage: f64,
    /// The map: `[y, z, σ]` (mm) of every grid point, σ the rms over the
    /// working poses.
    pub map: Vec<[f64; 3]>,
    /// Set when the sphere covered less than `calibrate::solve::ml::range::RANGE_COVERAGE_WARNING`
    /// of the range.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub warning: Option<String>,
}

impl RangeError {
    /// One line for people.
    #[must_use]
    pub fn summary(&self) -> String {
        let what = if self.region == "sensor.range" {
            format!(
                "over sensor.range (y {:.0}…{:.0}, z {:.0}…{:.0} mm)",
                self.y[0], self.y[1], self.z[0], self.z[1]
            )
        } else {
            format!(
                "over the region the sphere covered (y {:.1}…{:.1}, z {:.1}…{:.1} mm; no sensor.range in the session)",
                self.y[0], self.y[1], self.z[0], self.z[1]
            )
        };
        format!(
            "predicted point error {what}: rms {:.3} mm, max {:.3} mm at (y {:.0}, z {:.0}); {:.3} mm at the sphere",
            self.rms_mm, self.max_mm, self.max_at[0], self.max_at[1], self.at_sphere_mm
        )
    }
}

/// The predicted measuring error over the session's volume (result file:
/// `solver.volume_error`): the 1σ a measured sphere centre gets
/// (`measure`'s per-point σ: 3-D, after the best rigid alignment of all
/// of them, the covariance times the variance factor) at every identify
/// and validate pose of the session, i.e. over the box its stations span
/// and the orientations it used.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct VolumeError {
    /// Poses the figures are over.
    pub poses: usize,
    /// Stations they are at.
    pub stations: usize,
    /// RMS of the 1σ, mm.
    pub rms_mm: f64,
    /// Largest 1σ, mm.
    pub max_mm: f64,
    /// The box the stations span (base frame, mm): `[min, max]` of x, y, z
    /// of the measured centres.
    pub box_mm: [[f64; 2]; 3],
}

impl VolumeError {
    /// One line for people.
    #[must_use]
    pub fn summary(&self) -> String {
        let e = |k: usize| self.box_mm[k][1] - self.box_mm[k][0];
        format!(
            "predicted measuring error over the session's volume (a sphere centre's σ after the rigid alignment, a posteriori, at its {} poses at {} stations, a {:.0} × {:.0} × {:.0} mm box): rms {:.4} mm, max {:.4} mm",
            self.poses,
            self.stations,
            e(0),
            e(1),
            e(2),
            self.rms_mm,
            self.max_mm
        )
    }
}
