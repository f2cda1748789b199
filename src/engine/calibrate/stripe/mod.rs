//! A laser stripe to a sphere centre (paper section 4.1, eq. 21): the
//! circle fit of the stripe ([`circle`]), the sphere centre it gives
//! ([`sphere_centre`]) and the warnings about its quality
//! ([`centre_from_stripe`]).
//!
//! # Frames and units
//!
//! The laser plane is the sensor's `x = 0` plane (FORMAT.md "Sensor and
//! stripe"). A stripe is a list of points `[y, z]` in that plane, in mm, in
//! the sensor frame. The stripe on the sphere is an arc of a circle with
//! centre `(0, y_c, z_c)` and radius `r`; with sphere radius `R` the sphere
//! centre in the sensor frame is `(side · t, y_c, z_c)`, `t = sqrt(R² − r²)`
//! (paper eq. 21), `side = ±1`.
//!
//! # Method
//!
//! 1. Checks: at least [`MIN_POINTS`] points, all finite, not coincident and
//!    not collinear ([`StripeError`] otherwise).
//! 2. The points are centred on their centroid and scaled by their RMS
//!    distance from it, so every threshold below is relative and the fit is
//!    the same at any position and scale.
//! 3. Algebraic start: Taubin's fit (G. Taubin, "Estimation of planar curves,
//!    surfaces and nonplanar space curves defined by implicit equations",
//!    IEEE PAMI 13(11), 1991), solved by Newton's method on its characteristic
//!    polynomial as in N. Chernov, *Circular and Linear Regression: Fitting
//!    Circles and Lines by Least Squares*, CRC 2010, `CircleFitByTaubin`.
//!    It is nearly unbiased and starts the geometric fit within the noise.
//! 4. Geometric (orthogonal-distance) fit of `(y_c, z_c, r)` by
//!    Levenberg-Marquardt on the residuals `|p − c| − r` (Chernov & Lesort,
//!    "Least squares fitting of circles", J. Math. Imaging Vision 23, 2005).
//! 5. Outliers (stripes of at least [`MIN_POINTS_TO_TRIM`] points):
//!    iterative trimming. After each fit, every input point whose residual
//!    lies more than [`OUTLIER_THRESHOLD_SIGMAS`] robust standard deviations
//!    from the median residual is set aside and the fit is repeated on the
//!    rest, until the kept set no longer changes (at most
//!    [`MAX_TRIM_ROUNDS`] rounds). The scale is 1.4826 · MAD of all
//!    residuals, from the second round on at least the σ̂ of the previous
//!    fit's inliers (steadier than the MAD once the outliers are out), with a
//!    floor of [`TRIM_FLOOR_REL`] of the radius so that noise-free data is
//!    never trimmed. Fewer than [`MIN_INLIER_FRACTION`] of the points kept is
//!    an error.
//! 6. Covariance of `(y_c, z_c, r)`: `σ̂² (JᵀJ)⁻¹` at the final estimate,
//!    `σ̂² = Σ res² / (n_inliers − 3)`; propagated through eq. 21 for the
//!    sphere centre.
//!
//! A typical stripe (60 points, no outliers) takes one fitting round of two
//! or three Levenberg-Marquardt steps: a few microseconds.

pub mod circle;
pub mod segment;

use nalgebra::{Matrix3, Vector3};

pub use circle::{
    CircleFit, MAX_TRIM_ROUNDS, MIN_INLIER_FRACTION, MIN_POINTS, MIN_POINTS_TO_TRIM,
    OUTLIER_THRESHOLD_SIGMAS, TRIM_FLOOR_REL, fit_circle,
};

/// A circle fit or sphere-centre computation failed (one stripe).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StripeError {
    /// Fewer points than a circle fit needs.
    #[error("stripe has {found} points, at least {needed} are needed")]
    TooFewPoints {
        /// Points in the stripe.
        found: usize,
        /// Minimum (FORMAT.md: 5).
        needed: usize,
    },
    /// A point is NaN or infinite.
    #[error("stripe point {index} is not finite")]
    NonFinite {
        /// Index of the point.
        index: usize,
    },
    /// The points do not determine a circle (collinear or coincident).
    #[error("stripe points are collinear or coincident: no circle fits them")]
    Degenerate,
    /// After rejecting outliers too few points remain.
    #[error("only {kept} of {total} stripe points remain after outlier rejection")]
    TooManyOutliers {
        /// Points kept.
        kept: usize,
        /// Points in the stripe.
        total: usize,
    },
    /// Fitted radius larger than the sphere beyond the tolerance.
    #[error(
        "fitted stripe radius r = {r:.4} mm exceeds the sphere radius R = {sphere:.4} mm by {excess_pct:.2} % (tolerance 0.5 %)"
    )]
    RadiusTooLarge {
        /// Fitted radius, mm.
        r: f64,
        /// Sphere radius, mm.
        sphere: f64,
        /// `(r − R)/R` in percent.
        excess_pct: f64,
    },
    /// The whole profile is not one clean arc and no arc of the sphere was
    /// found in it (the segmentation's message).
    #[error("no arc of the sphere in the profile: {fit}; searching the raw profile: {search}")]
    NoArc {
        /// Why the whole-profile fit was not used.
        fit: String,
        /// Why the arc search found none.
        search: String,
    },
    /// The sphere radius, the side or the fitted circle handed to the
    /// sphere-centre computation is unusable (radius not finite and
    /// positive, side not ±1).
    #[error("invalid sphere-centre input: {detail}")]
    InvalidInput {
        /// What is wrong, with the value.
        detail: String,
    },
}

/// How far the fitted stripe radius `r` may exceed the sphere radius `R`, as
/// a fraction of `R` (FORMAT.md: 0.5 %). Within it the centre is taken on the
/// laser plane; beyond it the fit is an error
/// ([`StripeError::RadiusTooLarge`]).
pub const RADIUS_TOLERANCE: f64 = 0.005;

/// Shortest arc (inlier span seen from the centre, deg) that is not reported
/// as short. Below about 60° the centre and radius of a circle fit become
/// strongly correlated and their errors grow as the inverse square of the
/// span.
pub const SHORT_ARC_DEG: f64 = 60.0;

/// Smallest |cut angle| (deg) that is not reported. Near the sphere's equator
/// (`r → R`) the offset `t = sqrt(R² − r²)` has `dt/dr = −r/t`, which blows
/// up: at 15° a radius error is amplified 3.7 times.
pub const CUT_ANGLE_MIN_DEG: f64 = 15.0;

/// Largest |cut angle| (deg) that is not reported. Near the pole the stripe
/// circle is small (`r = R cos 70° ≈ 0.34 R`) and its centre poorly fixed by
/// a short, strongly curved stripe. The paper's best is about ±40°.
pub const CUT_ANGLE_MAX_DEG: f64 = 70.0;

/// Orthogonal-distance RMS (mm) above which the fit is reported as poor:
/// four times the 0.025 mm accuracy of the paper's sensor (section 4).
pub const HIGH_RMS_MM: f64 = 0.1;

/// The sphere centre given by one stripe circle (paper eq. 21).
#[derive(Debug, Clone, PartialEq)]
pub struct SphereCentre {
    /// Sphere centre `(side · t, y_c, z_c)`, mm, sensor frame.
    pub centre_in_sensor: Vector3<f64>,
    /// Offset of the centre from the laser plane, `t = sqrt(R² − r²)`, mm
    /// (≥ 0; 0 when [`SphereCentre::on_plane`]).
    pub offset: f64,
    /// `r / R`, the stripe radius over the sphere radius (dimensionless).
    pub r_over_r: f64,
    /// Cut angle `side · asin(t / R)`, deg: the angle between the laser plane
    /// and the plane through the sphere centre. About ±40° is the paper's
    /// sweet spot.
    pub cut_angle_deg: f64,
    /// `true` when `r` was above `R` (within [`RADIUS_TOLERANCE`]) and the
    /// centre was therefore taken on the plane (`x = 0`).
    pub on_plane: bool,
    /// Covariance of [`SphereCentre::centre_in_sensor`], mm², sensor frame:
    /// the fit covariance of `(y_c, z_c, r)` propagated through eq. 21 with
    /// `dt/dr = −r/t`. The `x` variance is capped at
    /// [`on_plane_x_variance`]`(R)`, and equals it when the centre is on the
    /// plane (`t = 0`, where the linearisation fails) with no correlation to
    /// `y`, `z`.
    pub covariance: Matrix3<f64>,
}

/// Variance (mm²) given to the sensor-`x` coordinate of a sphere centre
/// taken on the laser plane: the square of the offset
/// `R · sqrt(1 − (1 − tol)²) ≈ 0.1 R` that a radius [`RADIUS_TOLERANCE`]
/// below `R` would give. Since a radius up to that tolerance above `R` is
/// accepted, the true offset is unknown to about that much. It also caps the
/// linearised variance near the equator, where `dt/dr` is unbounded.
#[must_use]
pub fn on_plane_x_variance(sphere_radius: f64) -> f64 {
    let tol = RADIUS_TOLERANCE;
    sphere_radius * sphere_radius * (2.0 * tol - tol * tol)
}

/// The sphere centre in the sensor frame from a stripe circle (paper
/// eq. 21): `(side · sqrt(R² − r²), y_c, z_c)`, mm.
///
/// `sphere_radius` is `R` (mm, half the diameter); `side` is +1 when the
/// centre lies at sensor `x > 0`, −1 at `x < 0`. A radius above `R` by at
/// most [`RADIUS_TOLERANCE`]` · R` puts the centre on the plane
/// ([`SphereCentre::on_plane`]).
///
/// # Errors
/// - [`StripeError::RadiusTooLarge`]: `r > R (1 + RADIUS_TOLERANCE)`;
/// - [`StripeError::InvalidInput`]: `R` not finite and positive, `side` not
///   ±1, or a fit with a non-finite or non-positive radius or centre.
pub fn sphere_centre(
    fit: &CircleFit,
    sphere_radius: f64,
    side: i8,
) -> Result<SphereCentre, StripeError> {
    if !(sphere_radius.is_finite() && sphere_radius > 0.0) {
        return Err(StripeError::InvalidInput {
            detail: format!("sphere radius {sphere_radius} mm is not a positive number"),
        });
    }
    if side != 1 && side != -1 {
        return Err(StripeError::InvalidInput {
            detail: format!("side {side} is neither +1 nor -1"),
        });
    }
    let r = fit.radius;
    if !(r.is_finite() && r > 0.0 && fit.centre.iter().all(|v| v.is_finite())) {
        return Err(StripeError::InvalidInput {
            detail: format!(
                "circle with centre ({}, {}) mm and radius {r} mm",
                fit.centre[0], fit.centre[1]
            ),
        });
    }
    let big_r = sphere_radius;
    let excess = (r - big_r) / big_r;
    if excess > RADIUS_TOLERANCE {
        return Err(StripeError::RadiusTooLarge {
            r,
            sphere: big_r,
            excess_pct: 100.0 * excess,
        });
    }
    let sign = f64::from(side);
    let on_plane = r > big_r;
    // (R − r)(R + r) keeps precision when r is close to R.
    let offset = if on_plane {
        0.0
    } else {
        ((big_r - r) * (big_r + r)).sqrt()
    };
    let cut_angle_deg = sign * (offset / big_r).min(1.0).asin().to_degrees();

    let cap = on_plane_x_variance(big_r);
    let c = &fit.covariance;
    // d(centre)/d(y_c, z_c, r): x depends on r only, y and z are y_c and z_c.
    let dx_dr = if offset > 0.0 {
        -sign * r / offset
    } else {
        f64::INFINITY
    };
    let linear_var_x = dx_dr * dx_dr * c[(2, 2)];
    let mut covariance = Matrix3::zeros();
    covariance[(1, 1)] = c[(0, 0)];
    covariance[(1, 2)] = c[(0, 1)];
    covariance[(2, 1)] = c[(1, 0)];
    covariance[(2, 2)] = c[(1, 1)];
    if linear_var_x.is_finite() && linear_var_x <= cap {
        covariance[(0, 0)] = linear_var_x;
        covariance[(0, 1)] = dx_dr * c[(2, 0)];
        covariance[(1, 0)] = covariance[(0, 1)];
        covariance[(0, 2)] = dx_dr * c[(2, 1)];
        covariance[(2, 0)] = covariance[(0, 2)];
    } else if linear_var_x.is_finite() && offset > 0.0 {
        // Scale the x row so that its variance is the cap, keeping the
        // correlations (the matrix stays positive semi-definite).
        let k = dx_dr * (cap / linear_var_x).sqrt();
        covariance[(0, 0)] = cap;
        covariance[(0, 1)] = k * c[(2, 0)];
        covariance[(1, 0)] = covariance[(0, 1)];
        covariance[(0, 2)] = k * c[(2, 1)];
        covariance[(2, 0)] = covariance[(0, 2)];
    } else {
        covariance[(0, 0)] = cap;
    }

    Ok(SphereCentre {
        centre_in_sensor: Vector3::new(sign * offset, fit.centre[0], fit.centre[1]),
        offset,
        r_over_r: r / big_r,
        cut_angle_deg,
        on_plane,
        covariance,
    })
}

/// Everything one stripe gives: the circle, the sphere centre and the
/// quality warnings.
#[derive(Debug, Clone, PartialEq)]
pub struct StripeResult {
    /// The circle fit in the laser plane. Its `residuals` and `inlier`
    /// cover every point of the stripe; after a segmentation a point off
    /// the arc is not an inlier (see `segment`).
    pub fit: CircleFit,
    /// The sphere centre in the sensor frame.
    pub sphere: SphereCentre,
    /// Human-readable quality warnings with numbers and units; empty when
    /// the stripe is good.
    pub warnings: Vec<String>,
    /// The arc found in a raw profile, when the whole stripe was not one
    /// clean arc ([`segment::find_arc`]).
    pub segment: Option<ArcSegment>,
}

/// The sphere's arc in a raw profile: which points it kept, and in words.
#[derive(Debug, Clone, PartialEq)]
pub struct ArcSegment {
    /// One per stripe point: on the arc (kept) or dropped.
    pub on_arc: Vec<bool>,
    /// "kept 2,419 of 2,439 points; 20 dropped: …".
    pub summary: String,
}

/// Whether the whole-stripe fit is one clean circle: fitted to noise
/// level. Otherwise the stripe is taken as a raw profile and searched for
/// the sphere's arc. (A clean circle larger than the sphere stays an error
/// of its radius.)
fn clean_arc(fit: &CircleFit) -> bool {
    fit.rms <= HIGH_RMS_MM
}

/// The circle of the stripe: the whole-stripe fit when it is a clean arc
/// (every clean stripe, as before), else the arc found in the raw profile,
/// its fit spread back over every point (residuals to the circle, points
/// off the arc not inliers).
fn stripe_circle(
    points: &[[f64; 2]],
    sphere_radius: f64,
) -> Result<(CircleFit, Option<ArcSegment>), StripeError> {
    let whole = fit_circle(points);
    if whole.as_ref().is_ok_and(clean_arc) {
        return whole.map(|fit| (fit, None));
    }
    if points.len() < segment::MIN_ARC_POINTS {
        return whole.map(|fit| (fit, None));
    }
    match segment::find_arc(points, sphere_radius) {
        Ok(arc) => {
            let mut fit = arc.fit.clone();
            let mut on_arc = vec![false; points.len()];
            let mut inlier = vec![false; points.len()];
            for (k, &i) in arc.kept.iter().enumerate() {
                on_arc[i] = true;
                inlier[i] = fit.inlier.get(k).copied().unwrap_or(true);
            }
            fit.residuals = points
                .iter()
                .map(|p| (p[0] - fit.centre[0]).hypot(p[1] - fit.centre[1]) - fit.radius)
                .collect();
            fit.inlier = inlier;
            Ok((
                fit,
                Some(ArcSegment {
                    on_arc,
                    summary: arc.summary(),
                }),
            ))
        }
        // A whole-stripe fit with a high RMS is still a fit: keep it (its
        // warnings say so) rather than fail.
        Err(search) => match whole {
            Ok(fit) if fit.radius <= sphere_radius * (1.0 + RADIUS_TOLERANCE) => Ok((fit, None)),
            Ok(fit) => Err(StripeError::NoArc {
                fit: format!(
                    "the whole stripe fits a circle of r = {:.3} mm, larger than the sphere (R = {sphere_radius:.3} mm)",
                    fit.radius
                ),
                search: search.to_string(),
            }),
            Err(e) => Err(StripeError::NoArc {
                fit: e.to_string(),
                search: search.to_string(),
            }),
        },
    }
}

/// Fits the stripe's circle, computes the sphere centre (eq. 21) and lists
/// quality warnings: rejected outlier points, a short arc (below
/// [`SHORT_ARC_DEG`]), a high RMS (above [`HIGH_RMS_MM`]), a radius above
/// `R` within tolerance (centre taken on the plane), and a cut angle outside
/// [`CUT_ANGLE_MIN_DEG`]..[`CUT_ANGLE_MAX_DEG`].
///
/// `points` are `[y, z]` in the laser plane, mm; `sphere_radius` is `R`, mm;
/// `side` is ±1 (see [`sphere_centre`]).
///
/// # Errors
/// Those of [`fit_circle`] and [`sphere_centre`].
pub fn centre_from_stripe(
    points: &[[f64; 2]],
    sphere_radius: f64,
    side: i8,
) -> Result<StripeResult, StripeError> {
    let (fit, segment) = stripe_circle(points, sphere_radius)?;
    let sphere = sphere_centre(&fit, sphere_radius, side)?;
    let mut warnings = Vec::new();
    let rejected = fit.rejected();
    if let Some(seg) = &segment {
        warnings.push(format!("raw profile, the sphere's arc: {}", seg.summary));
    } else if rejected > 0 {
        let worst = fit
            .residuals
            .iter()
            .zip(&fit.inlier)
            .filter(|(_, k)| !**k)
            .map(|(r, _)| r.abs())
            .fold(0.0, f64::max);
        warnings.push(format!(
            "{rejected} of {} stripe points rejected as outliers (largest residual {worst:.3} mm)",
            fit.inlier.len()
        ));
    }
    if fit.arc_span_deg < SHORT_ARC_DEG {
        warnings.push(format!(
            "short arc: the stripe spans {:.1}° of its circle (below {SHORT_ARC_DEG:.0}°); centre and radius are weakly determined (σ(r) = {:.4} mm)",
            fit.arc_span_deg,
            fit.radius_std()
        ));
    }
    if fit.rms > HIGH_RMS_MM {
        warnings.push(format!(
            "high circle-fit RMS: {:.3} mm over {} points (above {HIGH_RMS_MM:.3} mm)",
            fit.rms,
            fit.used()
        ));
    }
    if sphere.on_plane {
        warnings.push(format!(
            "stripe radius r = {:.4} mm exceeds the sphere radius R = {sphere_radius:.4} mm by {:.3} % (within the {:.1} % tolerance): sphere centre taken on the laser plane (x = 0)",
            fit.radius,
            100.0 * (sphere.r_over_r - 1.0),
            100.0 * RADIUS_TOLERANCE
        ));
    } else {
        let cut = sphere.cut_angle_deg.abs();
        if cut < CUT_ANGLE_MIN_DEG {
            warnings.push(format!(
                "cut angle {:.1}° is below {CUT_ANGLE_MIN_DEG:.0}°: the laser plane is near the sphere's equator (r/R = {:.4}) and the centre's distance from it, t = {:.3} mm, is sensitive to r (dt/dr = {:.1}); about ±40° is best",
                sphere.cut_angle_deg,
                sphere.r_over_r,
                sphere.offset,
                -fit.radius / sphere.offset.max(f64::MIN_POSITIVE)
            ));
        } else if cut > CUT_ANGLE_MAX_DEG {
            warnings.push(format!(
                "cut angle {:.1}° is above {CUT_ANGLE_MAX_DEG:.0}°: the laser plane is near the sphere's pole and the stripe circle is small (r = {:.3} mm); about ±40° is best",
                sphere.cut_angle_deg, fit.radius
            ));
        }
    }
    Ok(StripeResult {
        fit,
        sphere,
        warnings,
        segment,
    })
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn on_plane_variance_is_offset_at_tolerance() {
        let r_big = 19.05;
        let t = (r_big * r_big - (r_big * (1.0 - RADIUS_TOLERANCE)).powi(2)).sqrt();
        assert!((on_plane_x_variance(r_big) - t * t).abs() < 1e-12);
    }
}
