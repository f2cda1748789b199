//! Least-squares sphere fits of base-frame points: the size, form and
//! position figures of an ISO 10360-8-style check are read from them.
//!
//! - [`fit_sphere`]: centre and radius free. The algebraic fit
//!   (`|x|² + a·x + b = 0` linear in `a`, `b`, on centred points) starts a
//!   Gauss-Newton solve of the geometric residuals `|xᵢ − c| − r`, the
//!   orthogonal distances that the form error is the range of.
//! - [`fit_sphere_radius`]: radius fixed (the artefact's calibrated
//!   size), centre free, Gauss-Newton from a given start: one stripe (an
//!   arc) fixes a centre only with the radius known, and only on the side
//!   the start lies.

use nalgebra::{Matrix3, Matrix4, Vector3, Vector4};

/// Most Gauss-Newton steps: a fit of a sphere's points converges in a
/// handful; points far from any sphere (a station seen through the
/// nominal model) converge linearly, and 50 steps leave them far below
/// the figures' 0.1 µm.
const MAX_STEPS: usize = 50;

/// A step shorter than this times the radius ends the solve (the
/// coordinates are mm; 1e-10 of a 20 mm radius is 2e-9 mm, and the
/// convergence is quadratic on exact data: the next step would be ~1e-18).
const STEP_TOLERANCE: f64 = 1e-10;

/// A step that is not at most this fraction of the one before, once the
/// solve has taken [`SETTLE_STEPS`], ends it: the steps have reached the
/// rounding of the sums (points far from a sphere, e.g. a station seen
/// through the nominal model, converge slowly to a fit no better than a
/// few steps give).
const STALL_RATIO: f64 = 0.9;

/// Steps taken before [`STALL_RATIO`] is looked at.
const SETTLE_STEPS: usize = 3;

/// A fitted sphere, mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphereFit {
    /// Centre.
    pub centre: Vector3<f64>,
    /// Radius.
    pub radius: f64,
    /// RMS of the radial residuals `|xᵢ − c| − r`.
    pub rms: f64,
    /// Smallest radial residual (most negative: inside).
    pub min_residual: f64,
    /// Largest radial residual.
    pub max_residual: f64,
    /// Points fitted.
    pub points: usize,
}

impl SphereFit {
    /// The form error: the range of the radial residuals, mm.
    #[must_use]
    pub fn form(&self) -> f64 {
        self.max_residual - self.min_residual
    }

    fn of(points: &[Vector3<f64>], centre: Vector3<f64>, radius: f64) -> Option<Self> {
        let (mut sum, mut lo, mut hi) = (0.0, f64::INFINITY, f64::NEG_INFINITY);
        for p in points {
            let e = (p - centre).norm() - radius;
            sum += e * e;
            lo = lo.min(e);
            hi = hi.max(e);
        }
        let fit = Self {
            centre,
            radius,
            rms: (sum / points.len().max(1) as f64).sqrt(),
            min_residual: lo,
            max_residual: hi,
            points: points.len(),
        };
        (centre.iter().all(|v| v.is_finite()) && radius.is_finite() && fit.rms.is_finite())
            .then_some(fit)
    }
}

/// The sphere through `points` in least squares, centre and radius free;
/// `None` for fewer than 4 points or points that fix no sphere (all on a
/// plane or a line).
#[must_use]
pub fn fit_sphere(points: &[Vector3<f64>]) -> Option<SphereFit> {
    if points.len() < 4 {
        return None;
    }
    let n = points.len() as f64;
    let mean = points.iter().sum::<Vector3<f64>>() / n;
    // Algebraic start: 2·c·d + e = |d|² for d = x − mean, e = r² − |c|².
    let mut ata = Matrix4::zeros();
    let mut atb = Vector4::zeros();
    for p in points {
        let d = p - mean;
        let row = Vector4::new(2.0 * d.x, 2.0 * d.y, 2.0 * d.z, 1.0);
        ata += row * row.transpose();
        atb += row * d.norm_squared();
    }
    let sol = ata.try_inverse()? * atb;
    let c0 = Vector3::new(sol[0], sol[1], sol[2]);
    let r2 = sol[3] + c0.norm_squared();
    if r2 <= 0.0 || !r2.is_finite() {
        return None;
    }
    // Gauss-Newton on f = |d − c| − r, unknowns (c, r) about the mean.
    let (mut c, mut r) = (c0, r2.sqrt());
    let mut last = f64::INFINITY;
    for iteration in 0..MAX_STEPS {
        let mut jtj = Matrix4::zeros();
        let mut jtf = Vector4::zeros();
        for p in points {
            let v = p - mean - c;
            let dist = v.norm();
            if dist == 0.0 {
                continue;
            }
            let u = v / dist;
            let row = Vector4::new(-u.x, -u.y, -u.z, -1.0);
            let f = dist - r;
            jtj += row * row.transpose();
            jtf += row * f;
        }
        let step = -(jtj.try_inverse()? * jtf);
        c += Vector3::new(step[0], step[1], step[2]);
        r += step[3];
        let size = step.norm();
        if size <= STEP_TOLERANCE * r.abs().max(1.0)
            || (iteration >= SETTLE_STEPS && size > STALL_RATIO * last)
        {
            break;
        }
        last = size;
    }
    SphereFit::of(points, c + mean, r.abs())
}

/// The sphere of radius `radius` through `points` in least squares, its
/// centre found by Gauss-Newton from `start`; `None` for fewer than 3
/// points or a singular step.
#[must_use]
pub fn fit_sphere_radius(
    points: &[Vector3<f64>],
    radius: f64,
    start: &Vector3<f64>,
) -> Option<SphereFit> {
    if points.len() < 3 {
        return None;
    }
    let mut c = *start;
    let mut last = f64::INFINITY;
    for iteration in 0..MAX_STEPS {
        let mut jtj = Matrix3::zeros();
        let mut jtf = Vector3::zeros();
        for p in points {
            let v = p - c;
            let dist = v.norm();
            if dist == 0.0 {
                continue;
            }
            let u = -v / dist;
            jtj += u * u.transpose();
            jtf += u * (dist - radius);
        }
        let step = -(jtj.try_inverse()? * jtf);
        c += step;
        let size = step.norm();
        if size <= STEP_TOLERANCE * radius.max(1.0)
            || (iteration >= SETTLE_STEPS && size > STALL_RATIO * last)
        {
            break;
        }
        last = size;
    }
    SphereFit::of(points, c, radius)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    /// Points on the sphere `(c, r)` over a cap of polar angle up to
    /// `cap` (rad) around `axis`, or on three arcs.
    fn cap(c: Vector3<f64>, r: f64, cap: f64, n: usize) -> Vec<Vector3<f64>> {
        (0..n)
            .map(|i| {
                let t = i as f64 / n as f64;
                let polar = cap * (0.1 + 0.9 * t);
                let azimuth = 2.399_963 * i as f64; // golden angle
                c + r * Vector3::new(
                    polar.sin() * azimuth.cos(),
                    polar.sin() * azimuth.sin(),
                    polar.cos(),
                )
            })
            .collect()
    }

    #[test]
    fn exact_spheres_fit_exactly() {
        for (c, r, cap_angle) in [
            (Vector3::new(1020.4, -3.1, 411.0), 19.05, 1.0),
            (Vector3::new(-500.0, 800.0, 1200.0), 12.7, 0.6),
            (Vector3::new(0.0, 0.0, 0.0), 250.0, 3.0),
        ] {
            let pts = cap(c, r, cap_angle, 200);
            let fit = fit_sphere(&pts).unwrap();
            assert!((fit.centre - c).norm() < 1e-9, "{:?} vs {c:?}", fit.centre);
            assert!((fit.radius - r).abs() < 1e-9, "{} vs {r}", fit.radius);
            assert!(fit.form() < 1e-9 && fit.rms < 1e-9);
            let fixed = fit_sphere_radius(&pts, r, &(c + Vector3::new(1.0, -2.0, 0.5))).unwrap();
            assert!((fixed.centre - c).norm() < 1e-9);
        }
    }

    #[test]
    fn one_arc_with_the_radius_known_fixes_the_centre() {
        // A stripe: an arc of the circle cut by the plane x = 12 of a
        // sphere of radius 19.05 about c.
        let c = Vector3::new(500.0, 200.0, 300.0);
        let (r, x): (f64, f64) = (19.05, 12.0);
        let rho = (r * r - x * x).sqrt();
        let pts: Vec<Vector3<f64>> = (0..40)
            .map(|i| {
                let phi = -1.0 + 2.0 * f64::from(i) / 39.0;
                c + Vector3::new(-x, rho * phi.sin(), rho * phi.cos())
            })
            .collect();
        let fit = fit_sphere_radius(&pts, r, &(c + Vector3::new(2.0, 1.0, -1.0))).unwrap();
        assert!((fit.centre - c).norm() < 1e-9, "{:?}", fit.centre - c);
        // Free radius: one arc does not fix a sphere (a family fits it).
        assert!(fit_sphere(&pts).is_none_or(|f| f.rms < 1e-6));
    }

    #[test]
    fn noise_and_form_are_reported() {
        let c = Vector3::new(10.0, 20.0, 30.0);
        let mut pts = cap(c, 20.0, 1.2, 400);
        // A bump of +0.05 mm on one point, -0.03 on another.
        pts[100] = c + (pts[100] - c) * (20.05 / 20.0);
        pts[200] = c + (pts[200] - c) * (19.97 / 20.0);
        let fit = fit_sphere(&pts).unwrap();
        assert!((fit.form() - 0.08).abs() < 2e-3, "{}", fit.form());
        assert!((fit.radius - 20.0).abs() < 1e-3);
        assert!(fit_sphere(&pts[..3]).is_none());
        // Points on a plane fix no sphere.
        let flat: Vec<Vector3<f64>> = (0..30)
            .map(|i| Vector3::new(f64::from(i % 6), f64::from(i / 6), 0.0))
            .collect();
        assert!(fit_sphere(&flat).is_none_or(|f| f.radius > 1e6));
    }
}
