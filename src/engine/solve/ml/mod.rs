//! The `ml` method: a maximum-likelihood identification that goes beyond
//! the paper's section 3.2 while keeping its measurement model.
//!
//! **Model (paper eq. 1, 10).** Every identify measurement `i` of station
//! `s` sees the sphere at `X_i = bT_e(q_i; p) · eT_s · X_si`; the station
//! centre `c_s` (base frame) is an unknown like the hand-eye (6, a twist in
//! the sensor frame as in [`identify`](crate::engine::solve::paper)) and the kinematic
//! errors (`5·n`). The residual of a measurement is `e_i = X_i − c_s`, so
//! every measurement is used once, with no pairing (eq. 17-18 difference
//! pairs instead; their noise is correlated and the disjoint pairing of the
//! paper throws information away).
//!
//! **Noise model (weighting).** The covariance of `X_i` is
//! `Σ_i = R_bs · Σ_sensor · R_bsᵀ + G_i · σ_q² · G_iᵀ`, with `Σ_sensor` the
//! circle-fit covariance of the stripe's sphere centre (eq. 21; for given
//! centres `centre_sigma² · I`), floored at `sensor_sigma_floor`, and
//! `G_i = [I | −[X_i]×] · ∂(bT_e)/∂q` the joint-noise Jacobian (the `Q_i`
//! of eq. 16 applied to the joint columns). Each residual is whitened with
//! the inverse Cholesky factor of `Σ_i`, computed **once**, from the
//! initial model and hand-eye (the parameters move the frames by a fraction
//! of a degree, which changes `Σ_i` by far less than its own uncertainty).
//!
//! **Solver.** Levenberg-Marquardt on the stacked whitened residuals, with
//! the unknowns scaled so that every one is in mm of motion (angles ×
//! [`ANGLE_SCALE_MM`], as in the paper's update) and Marquardt damping
//! `λ · diag(JᵀJ)`. The normal equations (parameters and all station
//! centres, ≤ 36 + 3·S unknowns) are solved densely by Cholesky. One
//! update of the loop of FORMAT.md "The iteration" is a complete LM solve
//! (its steps are listed in the result with their ε): stopping LM part-way
//! because ε fell below the paper's threshold leaves the estimate short of
//! the optimum (2.9 instead of 1.4 times the noise floor over 8 paper-like
//! seeds, measured without the prior),
//! so the threshold is checked between solves, never inside one.
//!
//! **Identifiable set.** Distances between points are all that sphere data
//! constrain (shared/paper/NOTES.md), so the station centres absorb any
//! rigid motion. The whitened Jacobian of the 6 + 5n parameters, with the
//! centre columns projected out station by station and columns scaled as
//! above, goes through a QR factorisation with column pivoting; a
//! parameter whose pivot is below `rank_tolerance × |R_11|` is fixed at its
//! start (nominal for kinematic parameters, the initial hand-eye for the
//! hand-eye). The Jacobian is taken where every station's sightings meet
//! at one point, so that exact redundancies are exactly null. Among
//! exactly dependent columns the pivoting fixes the members the standard
//! minimal model leaves out (Hayati's `beta` on non-parallel axes, `d`
//! before a parallel axis, the last joint's `theta` and `d`). Each fixed
//! parameter is then regressed on the estimated ones to name the
//! combination that cannot be separated (e.g. `d6 ~ he_z`). On the IRB
//! 2400 this keeps 24 of 36 parameters.
//!
//! **Prior.** Rows `(p_k − p_k,nominal) / σ_k` for the estimated
//! kinematic parameters (σ 0.2° and 0.5 mm by default), so weakly observed
//! directions stay near nominal. On by default: over 20 simulated seeds it
//! brought the validation std from 1.43 to 1.23 times the noise floor on
//! paper-like sessions and left random-error sessions unchanged (1.30 and
//! 1.28). The weakest direction left is the global length scale (`a3`,
//! `d4`, `he_z` together), which sphere data see only through the ±12 mm
//! sensor-frame offsets of the centres.
//!
//! **Robust loss.** Huber or Cauchy on the norm of each whitened 3-vector
//! residual, applied by iteratively reweighted least squares inside LM
//! (the cost that LM compares is the robust one). Measurements whose
//! standardised residual exceeds the 99.9 % point of χ(3) are reported as
//! outliers; [`exclude_measurements`] removes them for a rerun.
//!
//! **Uncertainty.** The parameter covariance is the parameter block of the
//! inverse of the final Gauss-Newton matrix; it predicts the standard
//! deviation of any centre-to-centre distance, both as an RMS error and
//! as the expected std over a set of distances (the common part removed,
//! as the validation std removes it). Leave-one-station-out
//! cross-validation estimates accuracy without a laser tracker.

use std::collections::HashSet;
use std::fmt::Write as _;
use std::ops::AddAssign;

use nalgebra::{DMatrix, DVector, Matrix3, Matrix3x6, SymmetricEigen, Vector3};
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

use super::{CalibrationError, IdentifyError};
use crate::engine::geometry::skew;
use crate::engine::handeye::Sighting;
use crate::engine::session::{Session, Use};
use crate::engine::solve::estimate::{
    ANGLE_SCALE_MM, Estimate, sensitivity, unknown_is_angle, unknown_label,
};
use crate::engine::solve::{
    Calibration, Control, Options, Prepared, PreparedMeasurement, Progress, StopReason,
};
use crate::engine::validate::epsilon;

/// Default σ of the joint readings, deg: the repeatability-level noise of
/// an industrial arm's encoders (the simulator's default is 0.003°).
pub const DEFAULT_JOINT_SIGMA_DEG: f64 = 0.003;
/// Default σ of each coordinate of a sphere centre given directly in the
/// session (no stripe to fit), mm: about what a sphere-fitting sensor
/// specifies (the paper's sensor: 0.025 mm accuracy on points).
pub const DEFAULT_CENTRE_SIGMA_MM: f64 = 0.01;
/// Default floor on each principal σ of a stripe-fit centre covariance,
/// mm: the fit's covariance comes from its own residuals and collapses on
/// noise-free or coarsely rounded stripes; 2 µm is below any real sensor.
pub const DEFAULT_SENSOR_SIGMA_FLOOR_MM: f64 = 0.002;
/// Default prior σ of the kinematic angle deviations, deg: the paper's
/// Table 1 angles are mostly within a few tenths of a degree.
pub const DEFAULT_PRIOR_ANGLE_DEG: f64 = 0.2;
/// Default prior σ of the kinematic length deviations, mm: Table 1's
/// lengths are within ±0.7 mm.
pub const DEFAULT_PRIOR_LENGTH_MM: f64 = 0.5;
/// Default relative pivot tolerance of the identifiability QR: exact
/// redundancies of the model (rigid motions, `d6 ~ he_z`) leave pivots of
/// ~1e-12 |R_11|, the weakest real direction on the IRB 2400 (hand-eye
/// rotation) ~1e-3; 1e-7 separates them with margin on both sides.
pub const DEFAULT_RANK_TOLERANCE: f64 = 1e-7;
/// Probability of the χ(3) quantile used as the default robust-loss scale:
/// at 99 % an inlier is almost never down-weighted, so the loss costs
/// almost no efficiency on clean data.
pub const LOSS_QUANTILE: f64 = 0.99;
/// Probability of the χ(3) quantile above which a measurement is listed as
/// an outlier: one false alarm per thousand clean measurements.
pub const OUTLIER_QUANTILE: f64 = 0.999;
/// Correlations at least this large (absolute) are listed by name: beyond
/// 0.95 two parameters are nearly interchangeable for this data.
pub const STRONG_CORRELATION: f64 = 0.95;

/// Marquardt's starting damping (relative to `diag(JᵀJ)`): small, because
/// the nominal model is close enough for Gauss-Newton steps.
const LAMBDA_START: f64 = 1e-4;
/// Damping factor after a rejected step.
const LAMBDA_UP: f64 = 10.0;
/// Damping factor after an accepted step.
const LAMBDA_DOWN: f64 = 0.3;
/// Smallest damping kept (pure Gauss-Newton below this is no different).
const LAMBDA_MIN: f64 = 1e-12;
/// Largest damping tried before the step is declared impossible: the step
/// is then ~1e-10 of the Gauss-Newton step, i.e. at the numerical optimum.
const LAMBDA_MAX: f64 = 1e10;
/// Floor of `diag(JᵀJ)` in the damping, relative to its largest entry,
/// so that a column with no data still gets damped.
const DIAG_FLOOR_REL: f64 = 1e-12;
/// Converged when an accepted step lowers the cost by less than this
/// fraction: far below what changes any distance (cost ~ number of
/// residuals, so 1e-10 relative is ~1e-8 σ²).
const COST_TOL: f64 = 1e-10;
/// Converged when the largest scaled step is below this, mm: a picometre.
const STEP_TOL_MM: f64 = 1e-9;
/// LM steps in one update of the loop. From the nominal model LM takes
/// 5-10 steps; 100 only guards against a pathological session.
const MAX_LM_STEPS: usize = 100;
/// Columns of the identifiability QR whose norms agree to this relative
/// amount are a tie; the lower index (hand-eye first, then base to flange)
/// is kept.
const PIVOT_TIE_REL: f64 = 1e-6;
/// Weight of a "conventionally redundant" parameter's column in the pivot
/// choice (see [`pivot_preference`]). Exact redundancies tie the columns
/// of a group; the weight makes the QR fix this member, without moving
/// any real direction below the rank tolerance (the weakest real pivot,
/// ~6e-3, stays ~1e4 × above it).
const REDUNDANT_WEIGHT: f64 = 1e-3;
/// `|sin(alpha)|` below this counts as parallel consecutive axes (Hayati's
/// `beta` is the right parameter there, `d` of the previous joint is not).
const PARALLEL_SIN: f64 = 0.1;
/// A fixed parameter's column shorter than this fraction of `|R_11|` moves
/// no distance at all (a rigid motion); otherwise it is named with the
/// estimated parameters that compensate it.
const NO_EFFECT_REL: f64 = 1e-9;
/// A compensating parameter is named when its share (scaled, mm of motion)
/// is at least this fraction of the largest share.
const SHOWN_SHARE: f64 = 0.1;

/// Robust loss on the norm `s` of a whitened 3-vector residual.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Loss {
    /// Plain least squares, `ρ(s) = s²/2`.
    Squared,
    /// Huber: quadratic up to `k`, linear beyond.
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

    /// `ρ(s)` for scale `k` (both in σ).
    fn rho(self, s: f64, k: f64) -> f64 {
        match self {
            Self::Squared => 0.5 * s * s,
            Self::Huber if s <= k => 0.5 * s * s,
            Self::Huber => k * s - 0.5 * k * k,
            Self::Cauchy => 0.5 * k * k * (s * s / (k * k)).ln_1p(),
        }
    }

    /// IRLS weight `ρ'(s)/s`.
    fn weight(self, s: f64, k: f64) -> f64 {
        match self {
            Self::Squared => 1.0,
            Self::Huber if s <= k => 1.0,
            Self::Huber => k / s,
            Self::Cauchy => 1.0 / (1.0 + s * s / (k * k)),
        }
    }
}

/// Settings of the `ml` method.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MlOptions {
    /// σ of every joint reading, deg.
    pub joint_sigma_deg: f64,
    /// σ of each coordinate of a centre given in the session, mm (sensor frame).
    pub centre_sigma: f64,
    /// Floor on each principal σ of a sensor-frame centre covariance, mm.
    pub sensor_sigma_floor: f64,
    /// Whether the prior on kinematic deviations is used.
    pub prior: bool,
    /// Prior σ of the angle deviations (alpha, beta, theta), deg.
    pub prior_angle_deg: f64,
    /// Prior σ of the length deviations (a, d), mm.
    pub prior_length: f64,
    /// Robust loss.
    pub loss: Loss,
    /// Scale `k` of the robust loss, in σ of the whitened residual norm.
    pub loss_scale: f64,
    /// Relative pivot tolerance of the identifiability QR.
    pub rank_tolerance: f64,
    /// Whether to run leave-one-station-out cross-validation after the solve.
    pub cross_validation: bool,
}

impl Default for MlOptions {
    fn default() -> Self {
        Self {
            joint_sigma_deg: DEFAULT_JOINT_SIGMA_DEG,
            centre_sigma: DEFAULT_CENTRE_SIGMA_MM,
            sensor_sigma_floor: DEFAULT_SENSOR_SIGMA_FLOOR_MM,
            prior: true,
            prior_angle_deg: DEFAULT_PRIOR_ANGLE_DEG,
            prior_length: DEFAULT_PRIOR_LENGTH_MM,
            loss: Loss::Huber,
            loss_scale: chi3_quantile(LOSS_QUANTILE),
            rank_tolerance: DEFAULT_RANK_TOLERANCE,
            cross_validation: true,
        }
    }
}

impl MlOptions {
    /// Checks every setting.
    ///
    /// # Errors
    /// [`IdentifyError::InvalidOption`] naming the setting and its value.
    pub fn validate(&self) -> Result<(), IdentifyError> {
        let check = |name: &str, v: f64, zero_ok: bool| {
            if v.is_finite() && (v > 0.0 || (zero_ok && v == 0.0)) {
                Ok(())
            } else {
                Err(IdentifyError::InvalidOption(format!(
                    "{name} must be a {} number, got {v}",
                    if zero_ok { "non-negative" } else { "positive" }
                )))
            }
        };
        check("ml joint sigma (deg)", self.joint_sigma_deg, true)?;
        check("ml centre sigma (mm)", self.centre_sigma, false)?;
        check("ml sensor sigma floor (mm)", self.sensor_sigma_floor, false)?;
        check("ml prior angle sigma (deg)", self.prior_angle_deg, false)?;
        check("ml prior length sigma (mm)", self.prior_length, false)?;
        check("ml loss scale (σ)", self.loss_scale, false)?;
        if !(self.rank_tolerance > 0.0 && self.rank_tolerance < 1.0) {
            return Err(IdentifyError::InvalidOption(format!(
                "ml rank tolerance must be in (0, 1), got {}",
                self.rank_tolerance
            )));
        }
        Ok(())
    }
}

/// Upper-tail quantile of the χ distribution with 3 degrees of freedom
/// (the norm of a whitened 3-vector residual): the `s` with
/// `P(|r| ≤ s) = p`, for `0 < p < 1`. Computed by bisection on the closed
/// form `P(χ²₃ ≤ x) = erf(√(x/2)) − √(2x/π)·e^(−x/2)`.
#[must_use]
pub fn chi3_quantile(p: f64) -> f64 {
    /// Bisection steps: the bracket [0, 100] shrinks below 1e-13.
    const STEPS: usize = 60;
    let cdf = |x: f64| -> f64 {
        let s = (x / 2.0).sqrt();
        (1.0 - erfc(s)) - (2.0 * x / std::f64::consts::PI).sqrt() * (-x / 2.0).exp()
    };
    let (mut lo, mut hi) = (0.0_f64, 100.0_f64);
    for _ in 0..STEPS {
        let mid = 0.5 * (lo + hi);
        if cdf(mid) < p {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (0.5 * (lo + hi)).sqrt()
}

/// Complementary error function (Numerical Recipes' Chebyshev fit,
/// fractional error below 1.2e-7 everywhere).
fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let poly = -z * z - 1.265_512_23
        + t * (1.000_023_68
            + t * (0.374_091_96
                + t * (0.096_784_18
                    + t * (-0.186_288_06
                        + t * (0.278_868_07
                            + t * (-1.135_203_98
                                + t * (1.488_515_87 + t * (-0.822_152_23 + t * 0.170_872_77))))))));
    let r = t * poly.exp();
    if x >= 0.0 { r } else { 2.0 - r }
}

/// The sensor-frame covariance (mm²) of a prepared measurement's centre:
/// the circle-fit covariance for a stripe, `centre_sigma² · I` for a given
/// centre; every principal σ raised to at least `sensor_sigma_floor`.
#[must_use]
pub fn sensor_covariance(m: &PreparedMeasurement, options: &MlOptions) -> Matrix3<f64> {
    let base = m
        .covariance
        .filter(|c| c.iter().all(|v| v.is_finite()))
        .unwrap_or_else(|| Matrix3::identity() * options.centre_sigma.powi(2));
    let floor = options.sensor_sigma_floor.powi(2);
    let sym = (base + base.transpose()) * 0.5;
    let eig = SymmetricEigen::new(sym);
    let values = eig.eigenvalues.map(|v| v.max(floor));
    eig.eigenvectors * Matrix3::from_diagonal(&values) * eig.eigenvectors.transpose()
}

/// The base-frame covariance (mm²) of a sighting's centre under `est`:
/// `R_bs · Σ_sensor · R_bsᵀ + G · σ_q² · Gᵀ`, `G = [I | −[X_b]×] · ∂bT_e/∂q`
/// (per rad), `σ_q` in deg.
#[must_use]
pub fn base_covariance(
    est: &Estimate,
    sighting: &Sighting,
    sensor_cov: &Matrix3<f64>,
    joint_sigma_deg: f64,
) -> Matrix3<f64> {
    let (base_from_flange, jq) = est.robot.joint_jacobian(&sighting.joints);
    let base_from_sensor = base_from_flange * est.flange_from_sensor;
    let x_b = (base_from_sensor * nalgebra::Point3::from(sighting.centre_in_sensor)).coords;
    let r: Matrix3<f64> = base_from_sensor.rotation.to_rotation_matrix().into_inner();
    let mut q = Matrix3x6::zeros();
    q.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&Matrix3::identity());
    q.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-skew(&x_b)));
    let g = q * jq;
    let sq = joint_sigma_deg.to_radians().powi(2);
    r * sensor_cov * r.transpose() + &g * g.transpose() * sq
}

/// Why [`exclude_measurements`] refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ExcludeError {
    /// An id names no measurement of the session.
    #[error("cannot exclude measurement {0}: the session has no measurement with that id")]
    UnknownId(String),
    /// An identify station would keep fewer than 2 measurements.
    #[error(
        "excluding {} leaves identify station {station} with {remaining} measurement(s); an identify station needs at least 2",
        excluded.join(", ")
    )]
    StationTooSmall {
        /// The station.
        station: String,
        /// Measurements it would keep.
        remaining: usize,
        /// The excluded ids of that station.
        excluded: Vec<String>,
    },
    /// A validate station named by a reference distance would be empty.
    #[error(
        "excluding {} leaves validate station {station} with no measurement, but reference distance {from} → {to} names it",
        excluded.join(", ")
    )]
    ReferencedStationEmpty {
        /// The station.
        station: String,
        /// The excluded ids of that station.
        excluded: Vec<String>,
        /// The reference distance's `from`.
        from: String,
        /// The reference distance's `to`.
        to: String,
    },
}

/// The session without the measurements `ids` (exclude-and-rerun),
/// re-checking the FORMAT.md rules the removal can break: every identify
/// station keeps at least 2 measurements, and every validate station a
/// reference distance names keeps at least one. Translation and rotation
/// counts are checked when the initial hand-eye is computed.
///
/// # Errors
/// [`ExcludeError`] naming the unknown id or the station.
pub fn exclude_measurements(session: &Session, ids: &[String]) -> Result<Session, ExcludeError> {
    let known: HashSet<&str> = session.measurements.iter().map(|m| m.id.as_str()).collect();
    if let Some(bad) = ids.iter().find(|id| !known.contains(id.as_str())) {
        return Err(ExcludeError::UnknownId(bad.clone()));
    }
    let drop: HashSet<&str> = ids.iter().map(String::as_str).collect();
    let mut out = session.clone();
    out.measurements.retain(|m| !drop.contains(m.id.as_str()));
    let excluded_of = |station: &str, usage: Use| -> Vec<String> {
        session
            .measurements
            .iter()
            .filter(|m| m.station == station && m.usage == usage && drop.contains(m.id.as_str()))
            .map(|m| m.id.clone())
            .collect()
    };
    for (station, _) in session.stations(Use::Identify) {
        let remaining = out
            .measurements
            .iter()
            .filter(|m| m.usage == Use::Identify && m.station == station)
            .count();
        if remaining < 2 {
            let excluded = excluded_of(&station, Use::Identify);
            if !excluded.is_empty() {
                return Err(ExcludeError::StationTooSmall {
                    station,
                    remaining,
                    excluded,
                });
            }
        }
    }
    for r in &session.reference_distances {
        for station in [&r.from, &r.to] {
            let left = out
                .measurements
                .iter()
                .any(|m| m.usage == Use::Validate && &m.station == station);
            if !left {
                return Err(ExcludeError::ReferencedStationEmpty {
                    station: station.clone(),
                    excluded: excluded_of(station, Use::Validate),
                    from: r.from.clone(),
                    to: r.to.clone(),
                });
            }
        }
    }
    Ok(out)
}

/// One identify measurement as the solver sees it.
#[derive(Debug, Clone)]
struct Obs {
    /// Index into the problem's stations.
    station: usize,
    /// Joints and sensor-frame centre.
    sighting: Sighting,
    /// `C⁻¹` with `Σ = C·Cᵀ` (base frame): whitens a residual.
    whiten: Matrix3<f64>,
}

/// The current point of the solve: model, hand-eye and station centres.
#[derive(Debug, Clone)]
struct State {
    est: Estimate,
    /// Station centres, base frame, mm.
    centres: Vec<Vector3<f64>>,
}

/// Which measurement rows a linearisation takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Rows {
    /// Every measurement and the prior.
    All,
    /// Only the measurements of one station (no prior).
    Only(usize),
}

impl Rows {
    fn includes(self, station: usize) -> bool {
        match self {
            Self::All => true,
            Self::Only(s) => s == station,
        }
    }
}

/// The linearised problem at a state.
struct Linear {
    /// `JᵀWJ` over [estimated parameters (scaled); centres].
    h: DMatrix<f64>,
    /// `JᵀW·r`.
    g: DVector<f64>,
    /// Robust cost.
    cost: f64,
}

/// The identifiability analysis of the parameters.
#[derive(Debug, Clone, PartialEq)]
struct Identifiability {
    /// Estimated unknowns (indices into ΔY), ascending.
    estimated: Vec<usize>,
    /// Fixed unknowns, ascending.
    fixed: Vec<usize>,
    /// Pivot order with `|R_kk| / |R_11|`.
    pivots: Vec<(usize, f64)>,
    /// Named combinations that cannot be separated.
    inseparable: Vec<String>,
}

/// The prior on the kinematic deviations, in the estimated chart.
struct Prior {
    /// Estimated slots that are kinematic parameters.
    slots: Vec<usize>,
    /// Their nominal values (rad, mm).
    nominal: Vec<f64>,
    /// Whitening of the prior (raw units): `diag(1/σ)`.
    whiten: DMatrix<f64>,
}

/// The problem: observations, which unknowns are estimated, weights.
struct Problem {
    obs: Vec<Obs>,
    /// Identify station ids.
    stations: Vec<String>,
    /// Estimated unknowns (indices into ΔY).
    estimated: Vec<usize>,
    /// Scale of each estimated unknown (scaled = raw × scale).
    scale: Vec<f64>,
    /// The prior, when used.
    prior: Option<Prior>,

    /// Number of ΔY unknowns (6 + 5n).
    n_unknowns: usize,
    loss: Loss,
    loss_scale: f64,
}

/// Scale of ΔY unknown `k`: angles in mm of motion at 1 m.
fn unknown_scale(k: usize) -> f64 {
    if unknown_is_angle(k) {
        ANGLE_SCALE_MM
    } else {
        1.0
    }
}

/// Whitening `C⁻¹` of a covariance `Σ = C·Cᵀ`; `None` when not positive definite.
fn whitening(cov: &Matrix3<f64>) -> Option<Matrix3<f64>> {
    let c = cov.cholesky()?;
    c.l().try_inverse()
}

impl Problem {
    /// Number of solver unknowns (estimated parameters and centres).
    fn dim(&self) -> usize {
        self.estimated.len() + 3 * self.stations.len()
    }

    /// Whitened residual of observation `o` at `state`.
    fn residual(&self, o: &Obs, state: &State) -> Vector3<f64> {
        o.whiten * (state.est.centre_in_base(&o.sighting) - state.centres[o.station])
    }

    /// Prior residuals `L⁻¹ · (p − p_nominal)` at `state` (empty without a prior).
    fn prior_residual(&self, state: &State) -> DVector<f64> {
        let Some(prior) = &self.prior else {
            return DVector::zeros(0);
        };
        let params = state.est.robot.params();
        let dev = DVector::from_iterator(
            prior.slots.len(),
            prior
                .slots
                .iter()
                .zip(&prior.nominal)
                .map(|(&slot, p0)| params[self.estimated[slot] - 6] - p0),
        );
        &prior.whiten * dev
    }

    /// Robust cost at `state`.
    fn cost(&self, state: &State) -> f64 {
        let data: f64 = self
            .obs
            .iter()
            .map(|o| {
                self.loss
                    .rho(self.residual(o, state).norm(), self.loss_scale)
            })
            .sum();
        data + 0.5 * self.prior_residual(state).norm_squared()
    }

    /// Whitened, scaled Jacobian of observation `o` with respect to the
    /// estimated parameters (3 × k), and its residual.
    fn obs_jacobian(&self, o: &Obs, state: &State) -> (Vector3<f64>, DMatrix<f64>) {
        let (x_b, a) = sensitivity(&state.est, &o.sighting);
        let k = self.estimated.len();
        let mut jp = DMatrix::zeros(3, k);
        for (slot, &u) in self.estimated.iter().enumerate() {
            let col: Vector3<f64> = o.whiten * a.fixed_view::<3, 1>(0, u) / self.scale[slot];
            jp.fixed_view_mut::<3, 1>(0, slot).copy_from(&col);
        }
        (o.whiten * (x_b - state.centres[o.station]), jp)
    }

    /// Gauss-Newton matrix, gradient and cost at `state` (IRLS weights from
    /// the current residuals), over the rows `rows` selects.
    fn linearize(&self, state: &State, rows: Rows) -> Linear {
        let k = self.estimated.len();
        let n = self.dim();
        let mut h = DMatrix::zeros(n, n);
        let mut g = DVector::zeros(n);
        let mut cost = 0.0;
        for o in &self.obs {
            if !rows.includes(o.station) {
                continue;
            }
            let (r, jp) = self.obs_jacobian(o, state);
            let s = r.norm();
            cost += self.loss.rho(s, self.loss_scale);
            let w = self.loss.weight(s, self.loss_scale);
            let jc = -o.whiten;
            let c0 = k + 3 * o.station;
            let jpt = jp.transpose();
            {
                let mut hpp = h.view_mut((0, 0), (k, k));
                hpp += &jpt * &jp * w;
            }
            let hpc = &jpt * jc * w;
            h.view_mut((0, c0), (k, 3)).add_assign(&hpc);
            h.view_mut((c0, 0), (3, k)).add_assign(&hpc.transpose());
            let hcc = jc.transpose() * jc * w;
            h.view_mut((c0, c0), (3, 3))
                .add_assign(&DMatrix::from_iterator(3, 3, hcc.iter().copied()));
            let gp = &jpt * DVector::from_iterator(3, r.iter().copied()) * w;
            g.rows_mut(0, k).add_assign(&gp);
            let gc = jc.transpose() * r * w;
            g.fixed_rows_mut::<3>(c0).add_assign(&gc);
        }
        if let (Some(prior), false) = (&self.prior, matches!(rows, Rows::Only(_))) {
            let r = self.prior_residual(state);
            // Jacobian of the prior rows in the scaled slots.
            let mut jp = DMatrix::zeros(r.len(), k);
            for (col, &slot) in prior.slots.iter().enumerate() {
                jp.set_column(slot, &(prior.whiten.column(col) / self.scale[slot]));
            }
            let jpt = jp.transpose();
            let mut hpp = h.view_mut((0, 0), (k, k));
            hpp += &jpt * &jp;
            g.rows_mut(0, k).add_assign(&(&jpt * &r));
            cost += 0.5 * r.norm_squared();
        }
        Linear { h, g, cost }
    }

    /// The state moved by a scaled solver step.
    fn apply(&self, state: &State, step: &DVector<f64>) -> State {
        let k = self.estimated.len();
        let mut delta = vec![0.0; self.n_unknowns];
        for (slot, &u) in self.estimated.iter().enumerate() {
            delta[u] = step[slot] / self.scale[slot];
        }
        State {
            est: state.est.updated(&delta),
            centres: state
                .centres
                .iter()
                .enumerate()
                .map(|(s, c)| c + step.fixed_rows::<3>(k + 3 * s))
                .collect(),
        }
    }

    /// One Levenberg-Marquardt step from `state`: retries with more
    /// damping until the cost falls. `None` when no damping lowers it
    /// (the state is at the optimum to numerical precision).
    fn lm_step(&self, state: &State, lambda: &mut f64) -> Option<LmStep> {
        let lin = self.linearize(state, Rows::All);
        let n = self.dim();
        let dmax = (0..n).map(|i| lin.h[(i, i)]).fold(0.0_f64, f64::max);
        let floor = (dmax * DIAG_FLOOR_REL).max(f64::MIN_POSITIVE);
        while *lambda <= LAMBDA_MAX {
            let mut a = lin.h.clone();
            for i in 0..n {
                a[(i, i)] += *lambda * lin.h[(i, i)].max(floor);
            }
            if let Some(chol) = a.cholesky() {
                let step = -chol.solve(&lin.g);
                if step.iter().all(|v| v.is_finite()) {
                    let trial = self.apply(state, &step);
                    let cost = self.cost(&trial);
                    if cost.is_finite() && cost < lin.cost {
                        let used = *lambda;
                        *lambda = (*lambda * LAMBDA_DOWN).max(LAMBDA_MIN);
                        return Some(LmStep {
                            state: trial,
                            cost_before: lin.cost,
                            cost_after: cost,
                            step_max: step.amax(),
                            lambda: used,
                        });
                    }
                }
            }
            *lambda *= LAMBDA_UP;
        }
        None
    }

    /// Leave-one-station-out cross-validation at the solution `state`.
    /// Each refit without station `s` is one Gauss-Newton step from the
    /// full solution with the station's rows removed,
    /// `δ = −(H − H_s)⁻¹ · (g − g_s)`: dropping one station of many moves
    /// the parameters by a fraction of their σ, well inside the linear
    /// regime, so one step is the refit to second order (and costs one
    /// factorisation instead of a whole LM run per station). The model
    /// refitted without `s` then predicts the within-station distances
    /// of `s`, whose true value is zero.
    fn cross_validate(&self, state: &State) -> CrossValidation {
        let k = self.estimated.len();
        let full = self.linearize(state, Rows::All);
        let mut rows = Vec::new();
        let (mut sum, mut count) = (0.0, 0_usize);
        for (s, id) in self.stations.iter().enumerate() {
            let own = self.linearize(state, Rows::Only(s));
            let mut h = &full.h - &own.h;
            let mut g = &full.g - &own.g;
            // The left-out station has no rows: pin its centre.
            let c0 = k + 3 * s;
            for d in 0..3 {
                h[(c0 + d, c0 + d)] = 1.0;
                g[c0 + d] = 0.0;
            }
            let refit = match h.cholesky() {
                Some(chol) => self.apply(state, &(-chol.solve(&g))),
                None => state.clone(),
            };
            let centres: Vec<Vector3<f64>> = self
                .obs
                .iter()
                .filter(|o| o.station == s)
                .map(|o| refit.est.centre_in_base(&o.sighting))
                .collect();
            let (mut ss, mut n) = (0.0, 0_usize);
            for i in 0..centres.len() {
                for j in i + 1..centres.len() {
                    ss += (centres[i] - centres[j]).norm_squared();
                    n += 1;
                }
            }
            sum += ss;
            count += n;
            rows.push(CrossStation {
                station: id.clone(),
                pairs: n,
                rms: if n > 0 { (ss / n as f64).sqrt() } else { 0.0 },
            });
        }
        CrossValidation {
            stations: rows,
            rms: if count > 0 {
                (sum / count as f64).sqrt()
            } else {
                0.0
            },
        }
    }
}

/// An accepted LM step.
struct LmStep {
    state: State,
    cost_before: f64,
    cost_after: f64,
    /// Largest scaled component, mm.
    step_max: f64,
    /// Damping that produced it.
    lambda: f64,
}

impl LmStep {
    fn relative_decrease(&self) -> f64 {
        (self.cost_before - self.cost_after) / self.cost_before.max(f64::MIN_POSITIVE)
    }

    fn converged(&self) -> bool {
        self.relative_decrease() < COST_TOL || self.step_max < STEP_TOL_MM
    }
}

/// The sensitivity of [`sensitivity`] for a sighting whose sensor-frame
/// centre is moved to where `point` (base frame, mm) appears in its pose:
/// the Jacobian of a model that fits the station exactly. At a start far
/// from the truth a station's sightings scatter by millimetres, which makes
/// a rigid motion of the base look weakly visible (it rotates the
/// residuals without changing the cost); at the station's point it is
/// exactly null, as it is for distances, and every exact redundancy of
/// the model (`theta6` with the hand-eye, say) stays exact.
fn sensitivity_at(est: &Estimate, s: &Sighting, point: &Vector3<f64>) -> DMatrix<f64> {
    let base_from_sensor = est.robot.base_from_flange(&s.joints) * est.flange_from_sensor;
    let moved = Sighting {
        id: s.id.clone(),
        joints: s.joints.clone(),
        centre_in_sensor: base_from_sensor
            .inverse_transform_point(&nalgebra::Point3::from(*point))
            .coords,
    };
    sensitivity(est, &moved).1
}

/// Pivot weight of ΔY unknown `u` for the nominal `robot`: 1, or
/// [`REDUNDANT_WEIGHT`] for the parameters that the standard minimal
/// model leaves out, so that within an exactly dependent group these are
/// the ones fixed: Hayati's `beta_i` where axis `i` is not parallel to
/// axis `i−1`, `d_{i−1}` where it is (the position along a parallel axis
/// is arbitrary), and the last joint's `theta_n` and `d_n` (the hand-eye
/// duplicates them). Fixing the conventional member keeps the estimated
/// values close to the physical deviations, which is what a prior on them
/// assumes; a different member would have to absorb e.g. a 0.76° `theta3`
/// as `beta4` and 1.8 mm of `d4`.
fn pivot_preference(robot: &crate::engine::robot::Robot, u: usize) -> f64 {
    if u < 6 {
        return 1.0;
    }
    let k = u - 6;
    let (joint, which) = (
        k / crate::engine::robot::PARAMS_PER_JOINT,
        k % crate::engine::robot::PARAMS_PER_JOINT,
    );
    let n = robot.joints.len();
    let parallel_to_previous =
        |j: usize| j > 0 && robot.joints[j].alpha.to_radians().sin().abs() < PARALLEL_SIN;
    let redundant = match which {
        // beta
        2 => joint > 0 && !parallel_to_previous(joint),
        // theta
        3 => joint + 1 == n,
        // d
        4 => joint + 1 == n || (joint + 1 < n && parallel_to_previous(joint + 1)),
        _ => false,
    };
    if redundant { REDUNDANT_WEIGHT } else { 1.0 }
}

/// QR with column pivoting of the projected, scaled, whitened Jacobian of
/// all `6 + 5n` parameters (modified Gram-Schmidt, re-orthogonalised), and
/// the naming of the fixed parameters.
fn identifiability(obs: &[Obs], n_stations: usize, est: &Estimate, tol: f64) -> Identifiability {
    let n_unknowns = 6 + est.robot.n_params();
    // Projected Jacobian, station by station.
    let mut blocks: Vec<DMatrix<f64>> = Vec::new();
    for s in 0..n_stations {
        let mine: Vec<&Obs> = obs.iter().filter(|o| o.station == s).collect();
        if mine.is_empty() {
            continue;
        }
        let rows = 3 * mine.len();
        let mut jp = DMatrix::zeros(rows, n_unknowns);
        let mut jc = DMatrix::zeros(rows, 3);
        let point = mine
            .iter()
            .map(|o| est.centre_in_base(&o.sighting))
            .sum::<Vector3<f64>>()
            / mine.len() as f64;
        for (i, o) in mine.iter().enumerate() {
            let a = sensitivity_at(est, &o.sighting, &point);
            for u in 0..n_unknowns {
                let col: Vector3<f64> = o.whiten * a.fixed_view::<3, 1>(0, u) / unknown_scale(u);
                jp.fixed_view_mut::<3, 1>(3 * i, u).copy_from(&col);
            }
            jc.view_mut((3 * i, 0), (3, 3)).copy_from(&(-o.whiten));
        }
        let ctc = jc.transpose() * &jc;
        let Some(inv) = ctc.try_inverse() else {
            continue;
        };
        let projected = &jp - &jc * (inv * (jc.transpose() * &jp));
        blocks.push(projected);
    }
    let rows: usize = blocks.iter().map(DMatrix::nrows).sum();
    let mut j = DMatrix::zeros(rows.max(1), n_unknowns);
    let mut r0 = 0;
    for b in &blocks {
        j.view_mut((r0, 0), (b.nrows(), n_unknowns)).copy_from(b);
        r0 += b.nrows();
    }
    // Pivoted modified Gram-Schmidt on the preference-weighted columns.
    let mut work: Vec<DVector<f64>> = (0..n_unknowns)
        .map(|u| j.column(u) * pivot_preference(&est.robot, u))
        .collect();
    let mut remaining: Vec<usize> = (0..n_unknowns).collect();
    let mut pivots = Vec::with_capacity(n_unknowns);
    let mut r11 = 0.0_f64;
    while !remaining.is_empty() {
        let best = remaining
            .iter()
            .map(|&u| work[u].norm())
            .fold(0.0_f64, f64::max);
        let pos = remaining
            .iter()
            .position(|&u| work[u].norm() >= best * (1.0 - PIVOT_TIE_REL))
            .unwrap_or(0);
        let u = remaining.remove(pos);
        let r = work[u].norm();
        // The unweighted pivot decides the rank.
        let r_plain = r / pivot_preference(&est.robot, u);
        if pivots.is_empty() {
            r11 = r_plain;
        }
        pivots.push((u, if r11 > 0.0 { r_plain / r11 } else { 0.0 }));
        if r > 0.0 {
            let q = &work[u] / r;
            for _ in 0..2 {
                for &v in &remaining {
                    let c = q.dot(&work[v]);
                    work[v] -= &q * c;
                }
            }
        }
    }
    let mut estimated: Vec<usize> = pivots.iter().filter(|p| p.1 >= tol).map(|p| p.0).collect();
    let mut fixed: Vec<usize> = pivots.iter().filter(|p| p.1 < tol).map(|p| p.0).collect();
    estimated.sort_unstable();
    fixed.sort_unstable();
    let inseparable = name_inseparable(&j, &estimated, &fixed, r11);
    Identifiability {
        estimated,
        fixed,
        pivots,
        inseparable,
    }
}

/// A parameter change of one file unit (1 mm or 1°) as text.
fn file_unit(k: usize) -> &'static str {
    if unknown_is_angle(k) { "°" } else { " mm" }
}

/// Raw units (rad or mm) per file unit.
fn raw_per_file_unit(k: usize) -> f64 {
    if unknown_is_angle(k) {
        1.0_f64.to_radians()
    } else {
        1.0
    }
}

/// Names each fixed parameter's combination: the estimated parameters that
/// undo its effect on the distances (least squares on the projected
/// columns), in file units; parameters with no effect at all are grouped.
fn name_inseparable(
    j: &DMatrix<f64>,
    estimated: &[usize],
    fixed: &[usize],
    r11: f64,
) -> Vec<String> {
    let mut out = Vec::new();
    let mut no_effect = Vec::new();
    let mut je = DMatrix::zeros(j.nrows(), estimated.len());
    for (slot, &u) in estimated.iter().enumerate() {
        je.set_column(slot, &j.column(u));
    }
    let svd = je.clone().svd(true, true);
    for &f in fixed {
        let col = j.column(f).into_owned();
        if col.norm() <= NO_EFFECT_REL * r11 {
            no_effect.push(unknown_label(f));
            continue;
        }
        let Ok(c) = svd.solve(&col, 1e-12 * r11) else {
            out.push(format!(
                "{}: fixed (no estimated combination computed)",
                unknown_label(f)
            ));
            continue;
        };
        let unexplained = (&col - &je * &c).norm() / col.norm();

        // Scaled null direction: z_f = 1, z_k = −c_k. One file unit of f.
        let zf = raw_per_file_unit(f) * unknown_scale(f);
        let biggest = c.amax();
        let mut parts: Vec<(usize, f64)> = estimated
            .iter()
            .zip(c.iter())
            .filter(|(_, ck)| ck.abs() >= SHOWN_SHARE * biggest)
            .map(|(&u, &ck)| (u, ck))
            .collect();
        parts.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()));
        let names: Vec<String> = parts.iter().map(|(u, _)| unknown_label(*u)).collect();
        let undo: Vec<String> = parts
            .iter()
            .map(|&(u, ck)| {
                let raw = -ck * zf / unknown_scale(u);
                format!(
                    "{} {:+.3}{}",
                    unknown_label(u),
                    raw / raw_per_file_unit(u),
                    file_unit(u)
                )
            })
            .collect();
        let mut text = format!(
            "{} ~ {}: {} +1{} is undone by {}",
            unknown_label(f),
            names.join(", "),
            unknown_label(f),
            file_unit(f),
            undo.join(", ")
        );
        if unexplained > 1e-3 {
            let _ = write!(
                text,
                " (to {:.1} % of its effect)",
                100.0 * (1.0 - unexplained)
            );
        }
        out.push(text);
    }
    if !no_effect.is_empty() {
        out.insert(
            0,
            format!(
                "{}: no effect on any centre distance (a rigid motion of the base frame, absorbed by the station centres)",
                                no_effect.join(", ")
            ),
        );
    }
    out
}

/// Prior σ (raw units: rad, mm) of ΔY unknown `u` (kinematic only).
fn prior_sigma(u: usize, options: &MlOptions) -> f64 {
    if unknown_is_angle(u) {
        options.prior_angle_deg.to_radians()
    } else {
        options.prior_length
    }
}

/// The prior on the estimated kinematic parameters: independent, σ by
/// type, centred on nominal. Because the pivoting keeps the parameters of
/// the standard minimal model ([`pivot_preference`]), these are the
/// deviations a prior speaks about. (Mapping a prior on all `5n`
/// parameters into this chart through the compensating combinations was
/// tried and did worse on the Table 1 sessions, 1.33 against 1.23 times
/// the noise floor over 20 seeds, and no better on random errors.)
fn chart_prior(ident: &Identifiability, nominal: &[f64], options: &MlOptions) -> Option<Prior> {
    if !options.prior {
        return None;
    }
    let slots: Vec<usize> = (0..ident.estimated.len())
        .filter(|&s| ident.estimated[s] >= 6)
        .collect();
    if slots.is_empty() {
        return None;
    }
    let inverse_sigma = DVector::from_iterator(
        slots.len(),
        slots
            .iter()
            .map(|&slot| 1.0 / prior_sigma(ident.estimated[slot], options)),
    );
    let whiten = DMatrix::from_diagonal(&inverse_sigma);
    Some(Prior {
        nominal: slots
            .iter()
            .map(|&slot| nominal[ident.estimated[slot] - 6])
            .collect(),
        slots,
        whiten,
    })
}

/// The solver: problem, state, damping. One [`MlSolver::update`] is one
/// update of the FORMAT.md loop.
struct MlSolver {
    problem: Problem,
    ident: Identifiability,
    state: State,
    lambda: f64,
    history: Vec<IterationRecord>,
}

/// What one accepted LM step did (the `iterations` of the solver block).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
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

/// Outcome of one update.
enum StepOutcome {
    /// A step was taken; `true` when LM has converged with it.
    Taken(bool),
    /// No step lowers the cost: converged before this update.
    Stuck,
}

impl MlSolver {
    fn new(
        session: &Session,
        prepared: &Prepared,
        start: &Estimate,
        options: &MlOptions,
    ) -> Result<Self, IdentifyError> {
        options.validate()?;
        let groups = session.stations(Use::Identify);
        let groups: Vec<(String, Vec<usize>)> = groups
            .into_iter()
            .filter(|(_, idx)| idx.len() >= 2)
            .collect();
        let mut obs = Vec::new();
        for (s, (_, idx)) in groups.iter().enumerate() {
            for &i in idx {
                let sighting = prepared.sighting(session, i);
                let cov = base_covariance(
                    start,
                    &sighting,
                    &sensor_covariance(&prepared.measurements[i], options),
                    options.joint_sigma_deg,
                );
                let whiten = whitening(&cov).ok_or_else(|| {
                    IdentifyError::InvalidOption(format!(
                        "measurement {}: the noise model gives a covariance that is not positive definite",
                        sighting.id
                    ))
                })?;
                obs.push(Obs {
                    station: s,
                    sighting,
                    whiten,
                });
            }
        }
        if obs.is_empty() {
            return Err(IdentifyError::NotEnoughData {
                detail: "no identify station has 2 or more measurements".into(),
            });
        }
        let stations: Vec<String> = groups.into_iter().map(|(id, _)| id).collect();
        let ident = identifiability(&obs, stations.len(), start, options.rank_tolerance);
        let n_unknowns = 6 + start.robot.n_params();
        let scale = ident.estimated.iter().map(|&u| unknown_scale(u)).collect();
        let prior = chart_prior(&ident, &session.robot.params(), options);
        let problem = Problem {
            obs,
            stations,
            estimated: ident.estimated.clone(),
            scale,
            prior,
            n_unknowns,
            loss: options.loss,
            loss_scale: options.loss_scale,
        };
        // Station centres start at the mean of their sightings.
        let mut sums = vec![(Vector3::zeros(), 0.0); problem.stations.len()];
        for o in &problem.obs {
            sums[o.station].0 += start.centre_in_base(&o.sighting);
            sums[o.station].1 += 1.0;
        }
        let centres = sums.iter().map(|(s, n)| s / *n).collect();
        Ok(Self {
            problem,
            ident,
            state: State {
                est: start.clone(),
                centres,
            },
            lambda: LAMBDA_START,
            history: Vec::new(),
        })
    }

    /// One update: LM steps until LM converges or [`MAX_LM_STEPS`] steps
    /// were taken. `epsilon` scores a state for the history.
    fn update(&mut self, epsilon: &dyn Fn(&Estimate) -> f64) -> StepOutcome {
        let mut taken = 0;
        while taken < MAX_LM_STEPS {
            let Some(step) = self.problem.lm_step(&self.state, &mut self.lambda) else {
                return if taken == 0 {
                    StepOutcome::Stuck
                } else {
                    StepOutcome::Taken(true)
                };
            };
            taken += 1;
            let done = step.converged();
            self.history.push(IterationRecord {
                cost: step.cost_after,
                lm_lambda: step.lambda,
                step_max_mm: step.step_max,
                relative_decrease: step.relative_decrease(),
                epsilon: epsilon(&step.state.est),
            });
            self.state = step.state;
            if done {
                return StepOutcome::Taken(true);
            }
        }
        StepOutcome::Taken(false)
    }
}

/// Runs the `ml` method inside the loop of FORMAT.md "The iteration":
/// ε before any update; while ε > threshold, fewer than `max_iterations`
/// updates were made and LM has not converged, one update (a complete LM
/// solve) and ε again. `progress` sees every ε and may cancel. Called by
/// [`solve::run`](crate::engine::solve::run) for [`Method::Ml`](crate::engine::solve::Method::Ml).
///
/// # Errors
/// A bad option, too little data, a non-finite step or a cancel.
pub fn run(
    session: &Session,
    prepared: &Prepared,
    options: &Options,
    progress: &mut dyn FnMut(&Progress) -> Control,
) -> Result<Calibration, CalibrationError> {
    let start = Estimate {
        robot: session.robot.clone(),
        flange_from_sensor: prepared.hand_eye_initial,
    };
    let mut solver = MlSolver::new(session, prepared, &start, &options.ml)?;
    let stations = prepared.stations(session, Use::Identify);
    let eps_of = |est: &Estimate| epsilon(&est.station_centres(&stations));
    let mut eps = eps_of(&solver.state.est);
    let mut iterations = vec![eps];
    let report = |updates: usize, epsilon: f64| Progress {
        updates,
        epsilon,
        max_iterations: options.max_iterations,
        threshold: options.threshold,
    };
    if progress(&report(0, eps)) == Control::Cancel {
        return Err(IdentifyError::Cancelled { iterations: 0 }.into());
    }
    let mut lm_converged = false;
    while eps > options.threshold && iterations.len() - 1 < options.max_iterations && !lm_converged
    {
        let updates = iterations.len();
        match solver.update(&eps_of) {
            StepOutcome::Stuck => {
                lm_converged = true;
                continue;
            }
            StepOutcome::Taken(done) => lm_converged = done,
        }
        eps = eps_of(&solver.state.est);
        if !eps.is_finite() {
            return Err(IdentifyError::NonFinite { iteration: updates }.into());
        }
        iterations.push(eps);
        if progress(&report(updates, eps)) == Control::Cancel {
            return Err(IdentifyError::Cancelled {
                iterations: updates,
            }
            .into());
        }
    }
    let updates = iterations.len() - 1;
    let n = iterations.len();
    let last_change = if n >= 2 {
        (iterations[n - 1] - iterations[n - 2]).abs()
    } else {
        f64::INFINITY
    };
    let stop = if eps <= options.threshold {
        StopReason::Converged {
            epsilon: eps,
            threshold: options.threshold,
            updates,
        }
    } else if lm_converged {
        StopReason::SolverConverged {
            epsilon: eps,
            threshold: options.threshold,
            updates,
            relative_change: solver.history.last().map_or(0.0, |h| h.relative_decrease),
        }
    } else {
        StopReason::IterationLimit {
            epsilon: eps,
            threshold: options.threshold,
            updates,
            last_change,
        }
    };
    let report = diagnostics(session, prepared, options, &solver, &stop);
    let est = solver.state.est.clone();
    let mut cal = crate::engine::solve::finish(
        session, prepared, options, &start, est, iterations, stop, None,
    );
    cal.solver = report.to_solver_block();
    Ok(cal)
}

/// A parameter of the solve with its uncertainty.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
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
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
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
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
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
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CrossValidation {
    /// Per station.
    pub stations: Vec<CrossStation>,
    /// RMS over all pairs of all stations, mm: an accuracy estimate (the
    /// within-station distance error on unseen stations) with no tracker.
    pub rms: f64,
}

/// A measurement whose residual marks it as an outlier.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
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
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NoiseModel {
    /// σ of the joint readings, deg.
    pub joint_sigma_deg: f64,
    /// σ of each coordinate of a given centre, mm.
    pub centre_sigma_mm: f64,
    /// Floor of each principal σ of the sensor-frame covariance, mm.
    pub sensor_sigma_floor_mm: f64,
    /// How residuals are whitened.
    pub whitening: String,
}

/// The prior as reported.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PriorRecord {
    /// Whether it was used.
    pub enabled: bool,
    /// σ of angle deviations, deg.
    pub angle_sigma_deg: f64,
    /// σ of length deviations, mm.
    pub length_sigma_mm: f64,
}

/// The robust loss as reported.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LossRecord {
    /// `squared`, `huber` or `cauchy`.
    pub kind: Loss,
    /// Scale `k`, σ of the whitened residual norm.
    pub scale_sigma: f64,
}

/// One pivot of the identifiability QR.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PivotRecord {
    /// Parameter label.
    pub parameter: String,
    /// `|R_kk| / |R_11|`.
    pub relative: f64,
}

/// The identifiability analysis as reported.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IdentifiabilityRecord {
    /// The method, in words.
    pub method: String,
    /// Relative pivot tolerance.
    pub tolerance: f64,
    /// Pivots in order.
    pub pivots: Vec<PivotRecord>,
}

/// Everything the `ml` method reports: the result file's `solver` block.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MlReport {
    /// Always `"ml"`.
    pub method: String,
    /// Noise model.
    pub noise_model: NoiseModel,
    /// Prior.
    pub prior: PriorRecord,
    /// Robust loss.
    pub loss: LossRecord,
    /// Solver, in words.
    pub solver: String,
    /// Threshold of the loop, mm.
    pub threshold: f64,
    /// Iteration bound of the loop.
    pub max_iterations: usize,
    /// Stop code (`threshold`, `converged`, `max_iterations`).
    pub stop: String,
    /// Stop reason in words.
    pub stop_reason: String,
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
    /// Combinations the data cannot separate, one sentence each.
    pub inseparable: Vec<String>,
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
    /// Outlier limit, σ of the standardised residual norm.
    pub outlier_limit_sigma: f64,
    /// Measurements beyond the limit.
    pub outliers: Vec<OutlierRecord>,
    /// Accepted LM steps.
    pub iterations: Vec<IterationRecord>,
}

impl MlReport {
    /// As the result file's `solver` block.
    #[must_use]
    pub fn to_solver_block(&self) -> Map<String, Value> {
        match serde_json::to_value(self) {
            Ok(Value::Object(m)) => m,
            _ => Map::new(),
        }
    }

    /// Reads the report back from a result's `solver` block (for the
    /// workbench); `None` when the block is not an `ml` one.
    #[must_use]
    pub fn from_solver_block(block: &Map<String, Value>) -> Option<Self> {
        if block.get("method").and_then(Value::as_str) != Some("ml") {
            return None;
        }
        serde_json::from_value(Value::Object(block.clone())).ok()
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
        let _ = writeln!(
            s,
            "  predicted σ of distances across the identify volume: mean {:.4} mm, max {:.4} mm (parameters alone: mean {:.4} mm)",
            p.mean, p.max, p.parameter_mean
        );
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

/// Column `u` of `A` restricted and scaled to the estimated slots.
fn restricted(a: &DMatrix<f64>, problem: &Problem) -> DVector<f64> {
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
type NoisySighting = (Sighting, Matrix3<f64>);

/// Predicted σ of the distances between pairs of sightings.
fn distance_std(
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

/// Covariance, correlation, predicted distances, cross-validation and
/// outliers at the final state.
fn diagnostics(
    session: &Session,
    prepared: &Prepared,
    options: &Options,
    solver: &MlSolver,
    stop: &StopReason,
) -> MlReport {
    let problem = &solver.problem;
    let state = &solver.state;
    let mo = &options.ml;
    let k = problem.estimated.len();
    let lin = problem.linearize(state, Rows::All);
    let full_inv = lin
        .h
        .clone()
        .cholesky()
        .map(|c| c.inverse())
        .or_else(|| lin.h.clone().pseudo_inverse(1e-14).ok())
        .unwrap_or_else(|| DMatrix::zeros(lin.h.nrows(), lin.h.ncols()));
    let cov_scaled = full_inv.view((0, 0), (k, k)).into_owned();
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
    let std: Vec<f64> = (0..k).map(|i| cov_file[i][i].max(0.0).sqrt()).collect();
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
    // Changes from the start, file units.
    let start_params = session.robot.params();
    let params = state.est.robot.params();
    let he_change = prepared.hand_eye_initial.inverse() * state.est.flange_from_sensor;
    let he_t = he_change.translation.vector;
    let he_r = he_change.rotation.scaled_axis();
    let parameters = problem
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
        .collect();
    // Residual statistics, leverage and outliers.
    let limit = chi3_quantile(OUTLIER_QUANTILE);
    let mut chi2 = 0.0;
    let mut outliers = Vec::new();
    for o in &problem.obs {
        let (r, jp) = problem.obs_jacobian(o, state);
        chi2 += r.norm_squared();
        // Leverage: tr(J_i H⁻¹ J_iᵀ)/3 with J_i = [jp | −C⁻¹].
        let c0 = k + 3 * o.station;
        let mut ji = DMatrix::zeros(3, problem.dim());
        ji.view_mut((0, 0), (3, k)).copy_from(&jp);
        ji.view_mut((0, c0), (3, 3))
            .copy_from(&DMatrix::from_iterator(3, 3, (-o.whiten).iter().copied()));
        let hat = &ji * &full_inv * ji.transpose();
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
    // Predicted distance σ.
    let noisy = |i: usize| -> NoisySighting {
        let s = prepared.sighting(session, i);
        let cov = base_covariance(
            &state.est,
            &s,
            &sensor_covariance(&prepared.measurements[i], mo),
            mo.joint_sigma_deg,
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
    let mut ipairs = Vec::new();
    for (ia, (_, a)) in identify.iter().enumerate() {
        for (_, b) in identify.iter().skip(ia + 1) {
            for kk in 0..a.len().min(b.len()) {
                ipairs.push((noisy(a[kk]), noisy(b[kk])));
            }
        }
    }
    let predicted_validate =
        (!vpairs.is_empty()).then(|| distance_std(problem, &state.est, &cov_scaled, &vpairs));
    let predicted_identify = distance_std(problem, &state.est, &cov_scaled, &ipairs);
    // Leave-one-station-out.
    let cross_validation =
        (mo.cross_validation && problem.stations.len() >= 2).then(|| problem.cross_validate(state));
    let ident = &solver.ident;
    MlReport {
        method: "ml".into(),
        noise_model: NoiseModel {
            joint_sigma_deg: mo.joint_sigma_deg,
            centre_sigma_mm: mo.centre_sigma,
            sensor_sigma_floor_mm: mo.sensor_sigma_floor,
            whitening: "each centre residual (base frame) multiplied by the inverse Cholesky factor of R_bs·Σ_sensor·R_bsᵀ + G·σ_q²·Gᵀ, computed once from the initial model and hand-eye".into(),
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
        threshold: options.threshold,
        max_iterations: options.max_iterations,
        stop: stop.code().into(),
        stop_reason: stop.describe(),
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
        estimated: labels.clone(),
        fixed: ident.fixed.iter().map(|&u| unknown_label(u)).collect(),
        inseparable: ident.inseparable.clone(),
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
        outlier_limit_sigma: limit,
        outliers,
        iterations: solver.history.clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chi3_quantiles_match_tables() {
        // χ²(3) table: 7.815 (95 %), 11.345 (99 %), 16.266 (99.9 %).
        assert!((chi3_quantile(0.95).powi(2) - 7.815).abs() < 2e-3);
        assert!((chi3_quantile(0.99).powi(2) - 11.345).abs() < 2e-3);
        assert!((chi3_quantile(0.999).powi(2) - 16.266).abs() < 2e-3);
    }

    #[test]
    fn erfc_known_values() {
        assert!((erfc(0.0) - 1.0).abs() < 1e-7);
        assert!((erfc(1.0) - 0.157_299_207).abs() < 1e-7);
        assert!((erfc(-1.0) - 1.842_700_793).abs() < 1e-7);
    }

    #[test]
    fn losses_are_consistent() {
        for loss in Loss::ALL {
            let k = 2.0;
            for s in [0.1, 1.0, 3.0, 10.0] {
                // ρ'(s) = s · w(s): central difference.
                let h = 1e-6;
                let d = (loss.rho(s + h, k) - loss.rho(s - h, k)) / (2.0 * h);
                assert!((d - s * loss.weight(s, k)).abs() < 1e-6, "{loss:?} at {s}");
            }
            assert_eq!(Loss::parse(loss.as_str()), Some(loss));
        }
    }

    #[test]
    fn sensor_covariance_is_floored() {
        let m = PreparedMeasurement {
            index: 0,
            centre_in_sensor: Vector3::zeros(),
            covariance: Some(Matrix3::zeros()),
            stripe: None,
        };
        let o = MlOptions::default();
        let c = sensor_covariance(&m, &o);
        assert!((c - Matrix3::identity() * o.sensor_sigma_floor.powi(2)).norm() < 1e-18);
    }
}
