//! Circles of the arc search: candidates through point triples, the
//! radius bounds, and the Gauss-Newton circle fit of a set of points.

use nalgebra::{Matrix3, Vector3};

use super::{
    CANDIDATE_SLACK, GAUSS_NEWTON_STEPS, HALVINGS, MAD_TO_SIGMA, MIN_TRIPLE_SPAN, SPAN_LEVELS,
    upper_median,
};

/// A circle `(y_c, z_c, r)`, mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Circle {
    pub(super) centre: [f64; 2],
    pub(super) radius: f64,
}

impl Circle {
    /// The circle through three points; `None` when they are straight within
    /// `min_sagitta` (or coincident).
    pub(super) fn through(a: [f64; 2], b: [f64; 2], c: [f64; 2], min_sagitta: f64) -> Option<Self> {
        // Relative to `a`, for precision far from the origin.
        let (bx, by) = (b[0] - a[0], b[1] - a[1]);
        let (cx, cy) = (c[0] - a[0], c[1] - a[1]);
        let chord = cx.hypot(cy);
        let cross = bx * cy - by * cx;
        // |cross| / chord: distance of b from the line a-c.
        if !(chord > 0.0 && cross.abs() >= min_sagitta * chord) {
            return None;
        }
        let d = 2.0 * cross;
        let (b2, c2) = (bx * bx + by * by, cx * cx + cy * cy);
        let ux = (cy * b2 - by * c2) / d;
        let uy = (bx * c2 - cx * b2) / d;
        let circle = Self {
            centre: [a[0] + ux, a[1] + uy],
            radius: ux.hypot(uy),
        };
        (circle.centre.iter().all(|v| v.is_finite()) && circle.radius.is_finite()).then_some(circle)
    }

    /// Signed orthogonal distance `|p − c| − r`, mm.
    pub(super) fn residual(&self, p: &[f64; 2]) -> f64 {
        let (dx, dy) = (p[0] - self.centre[0], p[1] - self.centre[1]);
        (dx * dx + dy * dy).sqrt() - self.radius
    }

    /// Squared-distance limits of the band `|d − r| ≤ band`.
    pub(super) fn band_limits(&self, band: f64) -> (f64, f64) {
        let lo = (self.radius - band).max(0.0);
        let hi = self.radius + band;
        (lo * lo, hi * hi)
    }

    pub(super) fn within(&self, p: &[f64; 2], (lo, hi): (f64, f64)) -> bool {
        let (dx, dy) = (p[0] - self.centre[0], p[1] - self.centre[1]);
        let d2 = dx * dx + dy * dy;
        d2 >= lo && d2 <= hi
    }
}

/// Radii an arc of the sphere may have, mm.
#[derive(Debug, Clone, Copy)]
pub(super) struct Bounds {
    pub(super) min: f64,
    pub(super) max: f64,
}

impl Bounds {
    pub(super) fn contains(&self, r: f64) -> bool {
        r >= self.min && r <= self.max
    }

    pub(super) fn contains_loosely(&self, r: f64) -> bool {
        r >= self.min * (1.0 - CANDIDATE_SLACK) && r <= self.max * (1.0 + CANDIDATE_SLACK)
    }
}

/// Robust standard deviation (1.4826 · MAD about the median) of `values`;
/// 0 when empty. Reorders `values`.
pub(super) fn robust_sigma(values: &mut [f64]) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    let med = upper_median(values);
    for v in values.iter_mut() {
        *v = (*v - med).abs();
    }
    MAD_TO_SIGMA * upper_median(values)
}

/// Median distance between neighbouring points, mm.
pub(super) fn pitch(points: &[[f64; 2]]) -> f64 {
    let mut steps: Vec<f64> = points
        .windows(2)
        .map(|w| {
            let (dx, dy) = (w[1][0] - w[0][0], w[1][1] - w[0][1]);
            (dx * dx + dy * dy).sqrt()
        })
        .collect();
    if steps.is_empty() {
        return 0.0;
    }
    upper_median(&mut steps)
}

/// The triples `(i, i + s/2, i + s)`: `s = n − 1`, halved at each of
/// [`SPAN_LEVELS`] levels down to [`MIN_TRIPLE_SPAN`], starts every `s/2`.
pub(super) fn triples(n: usize) -> Vec<[usize; 3]> {
    let mut out = Vec::new();
    let mut span = n.saturating_sub(1);
    for _ in 0..SPAN_LEVELS {
        if span < MIN_TRIPLE_SPAN {
            break;
        }
        let stride = (span / 2).max(1);
        let mut i = 0;
        while i + span < n {
            out.push([i, i + span / 2, i + span]);
            i += stride;
        }
        span /= 2;
    }
    out
}

/// Span (deg) of the points `indices` seen from `centre`: 360° minus the
/// largest angular gap between neighbours; 0 for fewer than two points.
pub(super) fn span_deg(points: &[[f64; 2]], indices: &[usize], centre: [f64; 2]) -> f64 {
    if indices.len() < 2 {
        return 0.0;
    }
    let mut angles: Vec<f64> = indices
        .iter()
        .map(|&i| (points[i][1] - centre[1]).atan2(points[i][0] - centre[0]))
        .collect();
    angles.sort_unstable_by(f64::total_cmp);
    let wrap = angles.first().copied().unwrap_or(0.0) + std::f64::consts::TAU
        - angles.last().copied().unwrap_or(0.0);
    let largest = angles.windows(2).map(|w| w[1] - w[0]).fold(wrap, f64::max);
    (std::f64::consts::TAU - largest).max(0.0).to_degrees()
}

/// `JᵀJ`, `Jᵀres` and `Σ res²` of the orthogonal residuals `|p − c| − r`
/// of the points `indices` for the circle `(c, r)`.
pub(super) fn normal_equations(
    points: &[[f64; 2]],
    indices: &[usize],
    circle: &Circle,
) -> (Matrix3<f64>, Vector3<f64>, f64) {
    let [a, b] = circle.centre;
    let (mut xx, mut xy, mut xr, mut yy, mut yr) = (0.0, 0.0, 0.0, 0.0, 0.0);
    let (mut gx, mut gy, mut gr, mut cost) = (0.0, 0.0, 0.0, 0.0);
    for &i in indices {
        let (dx, dy) = (points[i][0] - a, points[i][1] - b);
        let d = (dx * dx + dy * dy).sqrt();
        let res = d - circle.radius;
        // Rows [−dx/d, −dy/d, −1]; at the centre itself only r is constrained.
        let (jx, jy) = if d > 0.0 {
            let inv = 1.0 / d;
            (-dx * inv, -dy * inv)
        } else {
            (0.0, 0.0)
        };
        xx += jx * jx;
        xy += jx * jy;
        xr -= jx;
        yy += jy * jy;
        yr -= jy;
        gx += jx * res;
        gy += jy * res;
        gr -= res;
        cost += res * res;
    }
    let rr = indices.len() as f64;
    (
        Matrix3::new(xx, xy, xr, xy, yy, yr, xr, yr, rr),
        Vector3::new(gx, gy, gr),
        cost,
    )
}

/// The orthogonal-distance least-squares circle of the points `indices`,
/// by Gauss-Newton with step halving from `start` (a circle within the band
/// of them); no trimming: the band has left the outliers out. `None` when
/// the normal equations are singular or the result is not finite.
pub(super) fn geometric_fit(
    points: &[[f64; 2]],
    indices: &[usize],
    start: Circle,
) -> Option<Circle> {
    let mut circle = start;
    let (mut jtj, mut jtr, mut cost) = normal_equations(points, indices, &circle);
    for _ in 0..GAUSS_NEWTON_STEPS {
        let delta = -jtj.cholesky()?.solve(&jtr);
        let mut scale = 1.0;
        let mut accepted = None;
        for _ in 0..HALVINGS {
            let trial = Circle {
                centre: [
                    circle.centre[0] + scale * delta[0],
                    circle.centre[1] + scale * delta[1],
                ],
                radius: circle.radius + scale * delta[2],
            };
            let next = normal_equations(points, indices, &trial);
            if next.2 <= cost {
                accepted = Some((trial, next));
                break;
            }
            scale *= 0.5;
        }
        // No step lowers the cost: the minimum is reached.
        let Some((trial, next)) = accepted else {
            break;
        };
        let decrease = cost - next.2;
        circle = trial;
        (jtj, jtr, cost) = next;
        // Converged when the cost stalls (relative decrease below 1e-9: the
        // circle is then known to far below the noise).
        if decrease <= 1e-9 * cost {
            break;
        }
    }
    (circle.centre.iter().all(|v| v.is_finite())
        && circle.radius.is_finite()
        && circle.radius > 0.0)
        .then_some(circle)
}
