//! `ml`'s noise model and robust loss: the covariance of a measured sphere
//! centre in the base frame (the circle fit's covariance in the sensor
//! frame, rotated, plus the joint noise carried through the kinematics), its
//! whitening, and the Huber and Cauchy losses with their χ(3) scales.

use nalgebra::{Matrix3, SymmetricEigen};

use super::MlOptions;
use crate::engine::base::geometry::twist_rows;
pub use crate::engine::base::records::ml::Loss;
use crate::engine::base::session::Mount;
use crate::engine::calibrate::handeye::Sighting;
use crate::engine::calibrate::solve::estimate::Estimate;
use crate::engine::calibrate::solve::prepare::PreparedMeasurement;

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

/// Probability of the χ(3) quantile used as the default robust-loss scale:
/// at 99 % an inlier is almost never down-weighted, so the loss costs
/// almost no efficiency on clean data.
pub const LOSS_QUANTILE: f64 = 0.99;

/// Probability of the χ(3) quantile above which a measurement is listed as
/// an outlier: one false alarm per thousand clean measurements.
pub const OUTLIER_QUANTILE: f64 = 0.999;

/// The losses' functions, used by the solver only.
impl Loss {
    /// `ρ(s)` for scale `k` (both in σ).
    pub(super) fn rho(self, s: f64, k: f64) -> f64 {
        match self {
            Self::Squared => 0.5 * s * s,
            Self::Huber if s <= k => 0.5 * s * s,
            Self::Huber => k * s - 0.5 * k * k,
            Self::Cauchy => 0.5 * k * k * (s * s / (k * k)).ln_1p(),
        }
    }

    /// IRLS weight `ρ'(s)/s`.
    pub(super) fn weight(self, s: f64, k: f64) -> f64 {
        match self {
            Self::Squared => 1.0,
            Self::Huber if s <= k => 1.0,
            Self::Huber => k / s,
            Self::Cauchy => 1.0 / (1.0 + s * s / (k * k)),
        }
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
pub(super) fn erfc(x: f64) -> f64 {
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
    let Some(eig) = SymmetricEigen::try_new(
        sym,
        f64::EPSILON,
        crate::engine::base::numeric::MAX_DECOMPOSITION_SWEEPS,
    ) else {
        return Matrix3::identity() * floor;
    };
    let values = eig.eigenvalues.map(|v| v.max(floor));
    eig.eigenvectors * Matrix3::from_diagonal(&values) * eig.eigenvectors.transpose()
}

/// The base-frame covariance (mm²) of a sighting's centre under `est`:
/// `R_bs · Σ_sensor · R_bsᵀ + G · σ_q² · Gᵀ`, `G = [I | −[X_b]×] · ∂bT_e/∂q`
/// (per rad), `σ_q` in deg. A sighting with a given flange pose (a
/// pose-only session) has no joint term; the error of the pose the
/// controller reports (the robot's accuracy) enters as `σ_pose² · I`
/// instead.
#[must_use]
pub fn base_covariance(
    est: &Estimate,
    sighting: &Sighting,
    sensor_cov: &Matrix3<f64>,
    joint_sigma_deg: f64,
    pose_sigma_mm: f64,
) -> Matrix3<f64> {
    if let Some(base_from_flange) = sighting.flange {
        let station_from_sensor = est.station_from_sensor(&base_from_flange);
        let r: Matrix3<f64> = station_from_sensor
            .rotation
            .to_rotation_matrix()
            .into_inner();
        return r * sensor_cov * r.transpose() + Matrix3::identity() * pose_sigma_mm.powi(2);
    }
    let (base_from_flange, jq) = est.robot.joint_jacobian(&sighting.joints);
    let station_from_sensor = est.station_from_sensor(&base_from_flange);
    let r: Matrix3<f64> = station_from_sensor
        .rotation
        .to_rotation_matrix()
        .into_inner();
    let g = match est.mount {
        Mount::Flange => {
            let x_b =
                (station_from_sensor * nalgebra::Point3::from(sighting.centre_in_sensor)).coords;
            twist_rows(&x_b) * jq
        }
        // A fixed sensor: the target in the flange frame moves against the
        // flange's base-frame twist (see `estimate`).
        Mount::Fixed => {
            let y =
                (est.flange_from_sensor * nalgebra::Point3::from(sighting.centre_in_sensor)).coords;
            let r_be: Matrix3<f64> = base_from_flange.rotation.to_rotation_matrix().into_inner();
            -(r_be.transpose() * twist_rows(&y)) * jq
        }
    };
    let sq = joint_sigma_deg.to_radians().powi(2);
    r * sensor_cov * r.transpose() + &g * g.transpose() * sq
}

/// Whitening `C⁻¹` of a covariance `Σ = C·Cᵀ`; `None` when not positive definite.
#[must_use]
pub fn whitening(cov: &Matrix3<f64>) -> Option<Matrix3<f64>> {
    let c = cov.cholesky()?;
    c.l().try_inverse()
}

#[cfg(test)]
mod tests {
    use nalgebra::{Matrix3, Vector3};

    use super::*;
    use crate::engine::calibrate::solve::ml::MlOptions;

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
