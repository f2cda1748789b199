//! Circle fit of a laser stripe, with its quality: Taubin's algebraic
//! start, the geometric fit, outlier trimming and the covariance (the
//! method is in the [stripe module](super)'s docs, steps 1 to 6).

use nalgebra::{Matrix3, Vector3};

use super::StripeError;
use crate::engine::base::numeric::upper_median;

/// Fewest points a stripe may have: the session rule
/// [`MIN_STRIPE_POINTS`](crate::engine::base::session::MIN_STRIPE_POINTS).
pub const MIN_POINTS: usize = crate::engine::base::session::MIN_STRIPE_POINTS;

/// Outlier threshold in robust standard deviations. At 4 σ a Gaussian
/// inlier is rejected with probability 6·10⁻⁵; with the scale's own
/// sampling error, a clean 60-point stripe loses a point about once in 80
/// (simulated), and rejecting such a point moves the fit negligibly. A point
/// displaced 0.3 mm off a 0.02 mm-noise stripe is 15 σ out.
pub const OUTLIER_THRESHOLD_SIGMAS: f64 = 4.0;

/// Lowest outlier threshold, as a fraction of the fitted radius. Residuals of
/// noise-free points are rounding errors (~1e-15 of the radius); a floor well
/// above them and far below any sensor's noise (1e-9 of a 19 mm radius is
/// 2e-8 mm) keeps exact data from being trimmed.
pub const TRIM_FLOOR_REL: f64 = 1e-9;

/// Fewest points for which outliers are trimmed; smaller stripes are fitted
/// whole (a bad point then shows in the RMS). With fewer residuals the MAD
/// is too unsteady: by chance it can be a fraction of the noise, trimming
/// then removes good points and the refit on the survivors confirms the too
/// small scale. In simulation (0.02 mm noise, 110° arcs) about one clean
/// stripe in 10⁴ of 12 to 15 points lost a third of its points that way;
/// none of 10⁶ of 20, 25 or 30 points did.
pub const MIN_POINTS_TO_TRIM: usize = 20;

/// Fewest kept points, as a fraction of the stripe, for the fit to be
/// trusted. The MAD tolerates up to half the points being wrong, but when a
/// third of a stripe lies off the circle the stripe is not one clean arc (a
/// reflection, a second surface, the sphere's edge) and the "outliers" may
/// be the real stripe.
pub const MIN_INLIER_FRACTION: f64 = 2.0 / 3.0;

/// Most fit-and-trim rounds. The kept set settles in two or three rounds on
/// real stripes; the bound only stops a kept set that oscillates.
pub const MAX_TRIM_ROUNDS: usize = 8;

/// 1 / Φ⁻¹(3/4): turns a median absolute deviation into a Gaussian standard
/// deviation.
const MAD_TO_SIGMA: f64 = 1.482_602_218_505_602;

/// Points whose RMS distance from their centroid is below this fraction of
/// the centroid's magnitude are coincident: their differences are rounding.
const COINCIDENT_REL: f64 = 1e-12;

/// Smallest eigenvalue of the normalised scatter matrix (trace 1) below which
/// the points are collinear: a perpendicular spread under 1e-5 of the
/// spread along the line. A 20° arc has about 2e-3.
const COLLINEAR_EIGEN: f64 = 1e-10;

/// Fitted radius above which, in units of the points' RMS spread, the circle
/// is numerically a line (its sagitta over the points is below 1e-6 of their
/// spread).
const MAX_RADIUS_REL: f64 = 1e6;

/// Levenberg-Marquardt: most steps per round (a good start needs 2-5).
const MAX_LM_STEPS: usize = 100;
/// Levenberg-Marquardt: convergence when a step is below this fraction of
/// `1 + r` (normalised units): the solution is then known to ~1e-10 of the
/// radius, far below the 1e-9 mm asked of noise-free fits.
const STEP_TOL: f64 = 1e-10;
/// Levenberg-Marquardt: first damping (relative to the diagonal of `JᵀJ`):
/// small, because Taubin's start is within the noise and Gauss-Newton steps
/// are then accepted at once.
const LAMBDA_START: f64 = 1e-6;
/// Levenberg-Marquardt: damping multiplier after a rejected step.
const LAMBDA_UP: f64 = 10.0;
/// Levenberg-Marquardt: damping multiplier after an accepted step.
const LAMBDA_DOWN: f64 = 0.1;
/// Levenberg-Marquardt: damping floor.
const LAMBDA_MIN: f64 = 1e-12;
/// Levenberg-Marquardt: damping above which no step can lower the cost any
/// more; the round stops there.
const LAMBDA_MAX: f64 = 1e12;
/// Newton steps on Taubin's characteristic polynomial (converges in < 10).
const TAUBIN_NEWTON_STEPS: usize = 50;

/// A circle fitted to one stripe, in the laser plane (sensor `x = 0`).
#[derive(Debug, Clone, PartialEq)]
pub struct CircleFit {
    /// Circle centre `(y_c, z_c)`, mm, laser plane (sensor frame).
    pub centre: [f64; 2],
    /// Circle radius `r`, mm.
    pub radius: f64,
    /// Orthogonal-distance RMS over the inlier points, `sqrt(Σ res² / n)`, mm.
    pub rms: f64,
    /// Signed orthogonal residual `|p − c| − r` of every input point, in
    /// input order (outliers too), mm; positive outside the circle.
    pub residuals: Vec<f64>,
    /// Per input point: `true` when it was used in the final fit.
    pub inlier: Vec<bool>,
    /// Angular span of the inlier points seen from the centre, deg
    /// (360° minus the largest angular gap between neighbouring points).
    pub arc_span_deg: f64,
    /// Covariance of `(y_c, z_c, r)`, mm², `σ̂² (JᵀJ)⁻¹` at the final
    /// estimate with `σ̂² = Σ res² / (n_inliers − 3)` over the inliers.
    pub covariance: Matrix3<f64>,
    /// Levenberg-Marquardt steps tried, over all trimming rounds.
    pub iterations: usize,
}

impl CircleFit {
    /// Number of points used in the final fit (inliers).
    #[must_use]
    pub fn used(&self) -> usize {
        self.inlier.iter().filter(|&&k| k).count()
    }

    /// Number of points rejected as outliers.
    #[must_use]
    pub fn rejected(&self) -> usize {
        self.inlier.len() - self.used()
    }

    /// Standard deviation of the radius, mm (from [`CircleFit::covariance`]).
    #[must_use]
    pub fn radius_std(&self) -> f64 {
        crate::engine::base::numeric::sigma_of_variance(self.covariance[(2, 2)])
    }
}

/// Centring and scaling of the stripe points: `local = (p − origin) / scale`.
#[derive(Debug, Clone, Copy)]
struct Frame {
    /// Centroid `(y, z)` of the points, mm.
    origin: [f64; 2],
    /// RMS distance of the points from the centroid, mm.
    scale: f64,
    /// `1 / scale`, 1/mm.
    inv_scale: f64,
}

impl Frame {
    fn local(&self, p: &[f64; 2]) -> (f64, f64) {
        (
            (p[0] - self.origin[0]) * self.inv_scale,
            (p[1] - self.origin[1]) * self.inv_scale,
        )
    }
}

/// Circle parameters `(a, b, r)` in local (normalised) units.
type Params = [f64; 3];

/// The Gauss-Newton normal equations `JᵀJ`, `Jᵀres` and the cost `Σ res²`
/// of the orthogonal residuals over the inliers, for one parameter value.
/// `J` has rows `[−(x − a)/d, −(y − b)/d, −1]`.
#[derive(Debug, Clone, Copy, Default)]
struct Normal {
    xx: f64,
    xy: f64,
    xr: f64,
    yy: f64,
    yr: f64,
    rr: f64,
    gx: f64,
    gy: f64,
    gr: f64,
    cost: f64,
}

impl Normal {
    fn matrix(&self) -> Matrix3<f64> {
        Matrix3::new(
            self.xx, self.xy, self.xr, //
            self.xy, self.yy, self.yr, //
            self.xr, self.yr, self.rr,
        )
    }
}

fn normal_equations(points: &[[f64; 2]], frame: &Frame, inlier: &[bool], p: &Params) -> Normal {
    let mut acc = Normal::default();
    for (q, _) in points.iter().zip(inlier).filter(|(_, k)| **k) {
        let (x, y) = frame.local(q);
        let dx = x - p[0];
        let dy = y - p[1];
        let d = (dx * dx + dy * dy).sqrt();
        let res = d - p[2];
        // At the centre itself the direction is undefined; such a point
        // still constrains r.
        let (jx, jy) = if d > 0.0 {
            (-dx / d, -dy / d)
        } else {
            (0.0, 0.0)
        };
        acc.xx += jx * jx;
        acc.xy += jx * jy;
        acc.xr -= jx;
        acc.yy += jy * jy;
        acc.yr -= jy;
        acc.rr += 1.0;
        acc.gx += jx * res;
        acc.gy += jy * res;
        acc.gr -= res;
        acc.cost += res * res;
    }
    acc
}

/// Levenberg-Marquardt on the inliers from `params`; returns the steps tried
/// and the normal equations at the final `params`.
fn refine(
    points: &[[f64; 2]],
    frame: &Frame,
    inlier: &[bool],
    params: &mut Params,
) -> (usize, Normal) {
    let mut current = normal_equations(points, frame, inlier, params);
    let mut lambda = LAMBDA_START;
    let mut steps = 0;
    while steps < MAX_LM_STEPS && lambda <= LAMBDA_MAX {
        steps += 1;
        let mut a = current.matrix();
        for i in 0..3 {
            // Marquardt's scaling; the identity term keeps a zero diagonal
            // (all points at the centre) solvable.
            a[(i, i)] += lambda * (a[(i, i)] + 1e-12);
        }
        let g = Vector3::new(current.gx, current.gy, current.gr);
        let Some(delta) = a.cholesky().map(|c| -c.solve(&g)) else {
            lambda *= LAMBDA_UP;
            continue;
        };
        if !delta.iter().all(|v| v.is_finite()) {
            lambda *= LAMBDA_UP;
            continue;
        }
        let small = delta.norm() <= STEP_TOL * (1.0 + params[2].abs());
        let trial = [
            params[0] + delta[0],
            params[1] + delta[1],
            params[2] + delta[2],
        ];
        let candidate = normal_equations(points, frame, inlier, &trial);
        if candidate.cost.is_finite() && candidate.cost <= current.cost {
            *params = trial;
            current = candidate;
            lambda = (lambda * LAMBDA_DOWN).max(LAMBDA_MIN);
        } else {
            lambda *= LAMBDA_UP;
        }
        if small {
            break;
        }
    }
    (steps, current)
}

/// Taubin's algebraic circle fit of the inliers (Chernov's
/// `CircleFitByTaubin`, Newton's method on the characteristic polynomial).
/// `None` when the moments give no finite circle.
fn taubin(points: &[[f64; 2]], frame: &Frame, inlier: &[bool]) -> Option<Params> {
    let mut count = 0.0;
    let (mut mx, mut my) = (0.0, 0.0);
    for (q, _) in points.iter().zip(inlier).filter(|(_, k)| **k) {
        let (x, y) = frame.local(q);
        mx += x;
        my += y;
        count += 1.0;
    }
    mx /= count;
    my /= count;
    let (mut sxx, mut syy, mut sxy, mut sxz, mut syz, mut szz) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for (q, _) in points.iter().zip(inlier).filter(|(_, k)| **k) {
        let (x, y) = frame.local(q);
        let (xi, yi) = (x - mx, y - my);
        let zi = xi * xi + yi * yi;
        sxx += xi * xi;
        syy += yi * yi;
        sxy += xi * yi;
        sxz += xi * zi;
        syz += yi * zi;
        szz += zi * zi;
    }
    let (mxx, myy, mxy, mxz, myz, mzz) = (
        sxx / count,
        syy / count,
        sxy / count,
        sxz / count,
        syz / count,
        szz / count,
    );
    let mz = mxx + myy;
    let cov_xy = mxx * myy - mxy * mxy;
    let var_z = mzz - mz * mz;
    let a3 = 4.0 * mz;
    let a2 = -3.0 * mz * mz - mzz;
    let a1 = var_z * mz + 4.0 * cov_xy * mz - mxz * mxz - myz * myz;
    let a0 = mxz * (mxz * myy - myz * mxy) + myz * (myz * mxx - mxz * mxy) - var_z * cov_xy;
    let (a22, a33) = (a2 + a2, a3 + a3 + a3);

    // Newton from x = 0 towards the smallest non-negative root.
    let mut x = 0.0_f64;
    let mut y = a0;
    for _ in 0..TAUBIN_NEWTON_STEPS {
        let dy = a1 + x * (a22 + x * a33);
        let x_new = x - y / dy;
        if !x_new.is_finite() || x_new == x {
            break;
        }
        let y_new = a0 + x_new * (a1 + x_new * (a2 + x_new * a3));
        if y_new.abs() >= y.abs() {
            break;
        }
        x = x_new;
        y = y_new;
    }
    let x = x.max(0.0);
    let det = x * x - x * mz + cov_xy;
    let cx = (mxz * (myy - x) - myz * mxy) / det / 2.0;
    let cy = (myz * (mxx - x) - mxz * mxy) / det / 2.0;
    let r = (cx * cx + cy * cy + mz).sqrt();
    let params = [cx + mx, cy + my, r];
    params.iter().all(|v| v.is_finite()).then_some(params)
}

/// Robust centre (median) and outlier threshold (local units) of the
/// residuals of all points: a point is kept when its residual is within the
/// threshold of the median. The scale is the larger of 1.4826 · MAD and
/// `sigma` (0 for none).
fn trim_threshold(
    residuals: &[f64],
    scratch: &mut Vec<f64>,
    radius: f64,
    sigma: f64,
) -> (f64, f64) {
    scratch.clear();
    scratch.extend_from_slice(residuals);
    let med = upper_median(scratch);
    for v in scratch.iter_mut() {
        *v = (*v - med).abs();
    }
    let scale = (MAD_TO_SIGMA * upper_median(scratch)).max(sigma);
    let threshold = (OUTLIER_THRESHOLD_SIGMAS * scale).max(TRIM_FLOOR_REL * radius.abs().max(1.0));
    (med, threshold)
}

/// Span (rad) of the inlier points seen from `(a, b)`: 2π minus the largest
/// angular gap between neighbours.
fn arc_span(
    points: &[[f64; 2]],
    frame: &Frame,
    inlier: &[bool],
    p: &Params,
    scratch: &mut Vec<f64>,
) -> f64 {
    scratch.clear();
    for (q, _) in points.iter().zip(inlier).filter(|(_, k)| **k) {
        let (x, y) = frame.local(q);
        scratch.push((y - p[1]).atan2(x - p[0]));
    }
    scratch.sort_unstable_by(f64::total_cmp);
    let (Some(&first), Some(&last)) = (scratch.first(), scratch.last()) else {
        return 0.0;
    };
    let mut max_gap = first + std::f64::consts::TAU - last;
    for w in scratch.windows(2) {
        max_gap = max_gap.max(w[1] - w[0]);
    }
    (std::f64::consts::TAU - max_gap).max(0.0)
}

/// Checks the input and builds the normalising frame.
fn check_points(points: &[[f64; 2]]) -> Result<Frame, StripeError> {
    if points.len() < MIN_POINTS {
        return Err(StripeError::TooFewPoints {
            found: points.len(),
            needed: MIN_POINTS,
        });
    }
    if let Some(index) = points
        .iter()
        .position(|p| !(p[0].is_finite() && p[1].is_finite()))
    {
        return Err(StripeError::NonFinite { index });
    }
    let count = points.len() as f64;
    let (sy, sz) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), p| (a + p[0], b + p[1]));
    let origin = [sy / count, sz / count];
    let (mut syy, mut szz, mut syz) = (0.0, 0.0, 0.0);
    for p in points {
        let (dy, dz) = (p[0] - origin[0], p[1] - origin[1]);
        syy += dy * dy;
        szz += dz * dz;
        syz += dy * dz;
    }
    let scale = ((syy + szz) / count).sqrt();
    let magnitude = origin[0].abs().max(origin[1].abs());
    // Non-finite here means coordinates so large that their squares overflow.
    if !origin.iter().all(|v| v.is_finite())
        || !scale.is_finite()
        || scale <= COINCIDENT_REL * magnitude
        || scale == 0.0
    {
        return Err(StripeError::Degenerate);
    }
    // Eigenvalues of the scatter matrix normalised to trace 1.
    let trace = syy + szz;
    let (nyy, nzz, nyz) = (syy / trace, szz / trace, syz / trace);
    let half_gap = (0.25 * (nyy - nzz).powi(2) + nyz * nyz).sqrt();
    let largest = 0.5 + half_gap;
    let smallest = (nyy * nzz - nyz * nyz) / largest;
    if smallest.is_nan() || smallest <= COLLINEAR_EIGEN {
        return Err(StripeError::Degenerate);
    }
    Ok(Frame {
        origin,
        scale,
        inv_scale: 1.0 / scale,
    })
}

/// True when the local circle parameters are a usable circle.
fn plausible(p: &Params) -> bool {
    p.iter().all(|v| v.is_finite()) && p[2] > 0.0 && p[2] < MAX_RADIUS_REL
}

/// Fits a circle to a stripe: Taubin's algebraic fit refined by a robust
/// orthogonal-distance Levenberg-Marquardt fit with outlier trimming (see the
/// module documentation).
///
/// `points` are `[y, z]` in the laser plane (sensor `x = 0`), mm. The result's
/// centre, radius and residuals are in mm in the same plane.
///
/// # Errors
/// - [`StripeError::TooFewPoints`]: fewer than [`MIN_POINTS`] points;
/// - [`StripeError::NonFinite`]: a coordinate is NaN or infinite (the first
///   such point is named);
/// - [`StripeError::Degenerate`]: the points are coincident or collinear, or
///   the best circle is numerically a line (radius above 10⁶ times the
///   points' spread), or coordinates so large that the computation overflows;
/// - [`StripeError::TooManyOutliers`]: trimming keeps fewer than
///   [`MIN_POINTS`] points or fewer than [`MIN_INLIER_FRACTION`] of them.
pub fn fit_circle(points: &[[f64; 2]]) -> Result<CircleFit, StripeError> {
    let frame = check_points(points)?;
    let total = points.len();
    let mut inlier = vec![true; total];
    let mut params = taubin(points, &frame, &inlier).ok_or(StripeError::Degenerate)?;
    if !plausible(&params) {
        return Err(StripeError::Degenerate);
    }

    let mut residuals = vec![0.0; total];
    let mut scratch = Vec::with_capacity(total);
    let mut iterations = 0;
    let mut rounds = 0;
    let mut used = total;
    let normal = loop {
        let (steps, normal) = refine(points, &frame, &inlier, &mut params);
        iterations += steps;
        rounds += 1;
        if !plausible(&params) {
            return Err(StripeError::Degenerate);
        }
        for (res, q) in residuals.iter_mut().zip(points) {
            let (x, y) = frame.local(q);
            let (dx, dy) = (x - params[0], y - params[1]);
            *res = (dx * dx + dy * dy).sqrt() - params[2];
        }
        if rounds >= MAX_TRIM_ROUNDS || total < MIN_POINTS_TO_TRIM {
            break normal;
        }
        // From the second round on, the outliers are out of the fit and its
        // own σ̂ is a steadier scale than the MAD; it only ever raises the
        // threshold, so that a low MAD does not trim good points.
        let sigma = if rounds > 1 {
            (normal.cost / (used - 3) as f64).sqrt()
        } else {
            0.0
        };
        let (centre, threshold) = trim_threshold(&residuals, &mut scratch, params[2], sigma);
        let mut changed = false;
        used = 0;
        for (keep, res) in inlier.iter_mut().zip(&residuals) {
            let k = (res - centre).abs() <= threshold;
            changed |= k != *keep;
            used += usize::from(k);
            *keep = k;
        }
        if !changed {
            break normal;
        }
        if used < MIN_POINTS {
            return Err(StripeError::TooManyOutliers { kept: used, total });
        }
    };
    if (used as f64) < MIN_INLIER_FRACTION * total as f64 {
        return Err(StripeError::TooManyOutliers { kept: used, total });
    }

    let (used_f, dof) = (used as f64, (used - 3) as f64);
    let scale = frame.scale;
    let inverse = normal
        .matrix()
        .cholesky()
        .map(|c| c.inverse())
        .ok_or(StripeError::Degenerate)?;
    let sigma2 = normal.cost / dof;
    let covariance = inverse * (sigma2 * scale * scale);
    let span = arc_span(points, &frame, &inlier, &params, &mut scratch);
    for r in &mut residuals {
        *r *= scale;
    }
    Ok(CircleFit {
        centre: [
            frame.origin[0] + scale * params[0],
            frame.origin[1] + scale * params[1],
        ],
        radius: scale * params[2],
        rms: scale * (normal.cost / used_f).sqrt(),
        residuals,
        inlier,
        arc_span_deg: span.to_degrees(),
        covariance,
        iterations,
    })
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    fn arc(
        centre: [f64; 2],
        radius: f64,
        start_deg: f64,
        span_deg: f64,
        n: usize,
    ) -> Vec<[f64; 2]> {
        (0..n)
            .map(|i| {
                let t = (start_deg + span_deg * i as f64 / (n - 1) as f64).to_radians();
                [centre[0] + radius * t.cos(), centre[1] + radius * t.sin()]
            })
            .collect()
    }

    #[test]
    fn taubin_start_is_exact_on_exact_points() {
        let pts = arc([3.0, -7.0], 12.0, 10.0, 80.0, 20);
        let frame = check_points(&pts).unwrap();
        let p = taubin(&pts, &frame, &[true; 20]).unwrap();
        let centre = [
            frame.origin[0] + frame.scale * p[0],
            frame.origin[1] + frame.scale * p[1],
        ];
        assert!((centre[0] - 3.0).abs() < 1e-9, "{centre:?}");
        assert!((centre[1] + 7.0).abs() < 1e-9, "{centre:?}");
        assert!((frame.scale * p[2] - 12.0).abs() < 1e-9);
    }

    #[test]
    fn median_and_threshold_floor() {
        let mut v = [5.0, 1.0, 3.0, 2.0, 4.0];
        assert_eq!(upper_median(&mut v), 3.0);
        let mut scratch = Vec::new();
        // Exact residuals: the floor applies.
        let (m, t) = trim_threshold(&[0.0; 10], &mut scratch, 2.0, 0.0);
        assert_eq!((m, t), (0.0, TRIM_FLOOR_REL * 2.0));
        // Residuals ±1 around 0: MAD = 1.
        let res = [1.0, -1.0, 1.0, -1.0, 0.0, 1.0, -1.0];
        let (_, t) = trim_threshold(&res, &mut scratch, 2.0, 0.0);
        assert!((t - OUTLIER_THRESHOLD_SIGMAS * MAD_TO_SIGMA).abs() < 1e-12);
    }

    #[test]
    fn arc_span_of_quarter_and_full_circle() {
        let pts = arc([1.0, 2.0], 5.0, 170.0, 90.0, 7);
        let frame = check_points(&pts).unwrap();
        let p = [
            (1.0 - frame.origin[0]) / frame.scale,
            (2.0 - frame.origin[1]) / frame.scale,
            5.0 / frame.scale,
        ];
        let mut s = Vec::new();
        let span = arc_span(&pts, &frame, &[true; 7], &p, &mut s).to_degrees();
        assert!((span - 90.0).abs() < 1e-9, "{span}");
        // 12 points evenly around the whole circle: 330° between first and last.
        let full: Vec<_> = (0..12)
            .map(|i| {
                let t = (30.0 * f64::from(i)).to_radians();
                [1.0 + 5.0 * t.cos(), 2.0 + 5.0 * t.sin()]
            })
            .collect();
        let frame = check_points(&full).unwrap();
        let p = [
            (1.0 - frame.origin[0]) / frame.scale,
            (2.0 - frame.origin[1]) / frame.scale,
            5.0 / frame.scale,
        ];
        let span = arc_span(&full, &frame, &[true; 12], &p, &mut s).to_degrees();
        assert!((span - 330.0).abs() < 1e-9, "{span}");
    }

    #[test]
    fn collinear_and_coincident_are_degenerate() {
        let line: Vec<_> = (0..10)
            .map(|i| [1.0 + f64::from(i), 2.0 - 0.5 * f64::from(i)])
            .collect();
        assert_eq!(fit_circle(&line), Err(StripeError::Degenerate));
        let same = vec![[4.2, -1.3]; 8];
        assert_eq!(fit_circle(&same), Err(StripeError::Degenerate));
    }
}
