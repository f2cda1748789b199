//! Noise terms estimated at the solution (issue 32): the flange poses'
//! isotropic σ of a pose-only session by variance-component estimation.
//!
//! Each residual `r_i = X_i − c_s` (base frame, mm) has the covariance
//! `Σ_i = A_i + σ² I`: `A_i` the part the session states (the stripe fit
//! rotated into the base frame), `σ²` the error of the flange pose the
//! controller reports, unknown. At the solution the quadratic form
//! `Σ rᵢᵀ Σᵢ⁻¹ rᵢ` has expectation equal to the redundancy (the residual
//! coordinates minus the unknowns: 3·N − 3·S − the estimated parameters),
//! and it falls monotonically as `σ²` grows, so the `σ²` that makes them
//! equal is one root, found by bisection. The solver re-solves with that
//! σ and estimates again until σ settles (Helmert's iteration with one
//! component): the same data then give the same σ, variance factor and
//! covariance from any start that reaches the same solution, instead of
//! the scatter at the start deciding them.

use nalgebra::{Matrix3, Vector3};

/// Smallest σ of a reported flange pose's error estimated from the data,
/// mm: a station whose centres agree to the micrometre says nothing finer
/// about a robot's accuracy.
pub const MIN_POSE_SIGMA_MM: f64 = 0.005;

/// Relative change of σ below which the estimate has settled: 0.01 %,
/// far below the 1 % within which starts must agree.
pub const SETTLED: f64 = 1e-4;

/// Most rounds of estimate and re-solve. From the start's scatter σ
/// settles within 3-6 rounds on the simulated and real pose-only cells;
/// the bound only guards against a pathological session.
pub const MAX_ROUNDS: usize = 30;

/// Bisection steps on `ln σ²`: 200 halvings of a bracket of at most ~100
/// natural-log units reach far below f64 resolution.
const BISECTION_STEPS: usize = 200;

/// The quadratic form `Σ rᵢᵀ (Aᵢ + s I)⁻¹ rᵢ`; `None` when a covariance is
/// not positive definite.
fn quadratic_form(residuals: &[(Vector3<f64>, Matrix3<f64>)], s: f64) -> Option<f64> {
    let mut sum = 0.0;
    for (r, a) in residuals {
        let cov = a + Matrix3::identity() * s;
        let chol = cov.cholesky()?;
        sum += r.dot(&chol.solve(r));
    }
    Some(sum)
}

/// The variance-component estimate of the pose σ (mm): the σ for which
/// the residuals' quadratic form under `Aᵢ + σ² I` equals `redundancy`,
/// at least [`MIN_POSE_SIGMA_MM`]. `residuals` pairs each base-frame
/// residual (mm) with its stated covariance `Aᵢ` (mm²). `None` when there
/// is no redundancy or a stated covariance is not positive semi-definite.
#[must_use]
pub fn pose_sigma(residuals: &[(Vector3<f64>, Matrix3<f64>)], redundancy: usize) -> Option<f64> {
    if redundancy == 0 || residuals.is_empty() {
        return None;
    }
    let dof = redundancy as f64;
    let low = MIN_POSE_SIGMA_MM.powi(2);
    if quadratic_form(residuals, low)? <= dof {
        return Some(MIN_POSE_SIGMA_MM);
    }
    // At s = Σ|r|²/dof the form is at most Σ|r|²/s = dof (Aᵢ ⪰ 0).
    let high = residuals.iter().map(|(r, _)| r.norm_squared()).sum::<f64>() / dof;
    if !(high.is_finite() && high > low) {
        return None;
    }
    let (mut lo, mut hi) = (low.ln(), high.ln());
    for _ in 0..BISECTION_STEPS {
        let mid = 0.5 * (lo + hi);
        if quadratic_form(residuals, mid.exp())? > dof {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo < 1e-14 {
            break;
        }
    }
    Some((0.5 * (lo + hi)).exp().sqrt())
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;
    use crate::engine::base::cell::random::{normal, stream};

    #[test]
    fn recovers_a_known_sigma_beside_stated_noise() {
        // 3,000 residuals of σ_pose = 0.1 mm plus a stated 0.03 mm part.
        let mut rng = stream(11, 0);
        let a = Matrix3::identity() * 0.03f64.powi(2);
        let residuals: Vec<_> = (0..3000)
            .map(|_| {
                let r = Vector3::from_fn(|_, _| 0.1 * normal(&mut rng) + 0.03 * normal(&mut rng));
                (r, a)
            })
            .collect();
        let s = pose_sigma(&residuals, 9000).unwrap();
        assert!((s - 0.1).abs() < 0.004, "σ = {s}");
        // The form at the estimate equals the redundancy.
        let q = quadratic_form(&residuals, s * s).unwrap();
        assert!((q - 9000.0).abs() < 1e-6 * 9000.0, "{q}");
    }

    #[test]
    fn stated_noise_that_explains_everything_gives_the_floor() {
        let a = Matrix3::identity() * 1.0;
        let residuals = vec![(Vector3::new(0.1, 0.0, 0.0), a); 10];
        assert_eq!(pose_sigma(&residuals, 30), Some(MIN_POSE_SIGMA_MM));
    }

    #[test]
    fn no_redundancy_is_no_estimate() {
        let residuals = vec![(Vector3::new(1.0, 0.0, 0.0), Matrix3::zeros())];
        assert_eq!(pose_sigma(&residuals, 0), None);
        assert_eq!(pose_sigma(&[], 3), None);
    }
}
