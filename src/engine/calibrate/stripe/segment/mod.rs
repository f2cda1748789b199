//! The sphere's arc in a raw sensor profile: which of the ~2,500 points of
//! one laser line lie on the sphere, before the circle fit of the
//! [stripe module](super).
//!
//! A raw profile holds everything the laser line touched, in sensor order
//! along the line: the sphere's arc, but also the stand, the table, edges
//! and reflections. [`fit_circle`] assumes the points are (mostly) the arc;
//! [`find_arc`] finds the arc first.
//!
//! # Method
//!
//! A consensus search over candidate circles, RANSAC-like (M. A. Fischler
//! and R. C. Bolles, "Random sample consensus: a paradigm for model fitting
//! with applications to image analysis and automated cartography", Comm. ACM
//! 24(6), 1981), with deterministic sampling and two constraints a sphere
//! imposes: the radius, and the arc being one stretch of the line.
//!
//! 1. **Contiguity.** The pitch is the median distance between neighbouring
//!    profile points. The points near a circle, taken in profile order, form
//!    pieces: a point continues a piece when it lies within
//!    [`MAX_GAP_PITCHES`] pitches of the piece's last point (checked against
//!    the [`OPEN_PIECES`] most recently extended pieces), else it starts one.
//!    So a dropout or a reflection on the arc up to that long is bridged,
//!    while a stray point elsewhere on the circle (clutter on its far side)
//!    neither joins the arc nor cuts it in two.
//! 2. **Candidates.** Circles through point triples `(i, i + s/2, i + s)`
//!    spread along the ordered profile at [`SPAN_LEVELS`] spans: `s = n − 1`
//!    (the whole profile: the best circle when it is all arc), then halved
//!    at each level, with starts every `s/2`, down to `n/64`: 247 triples for
//!    a profile of 2,500 points. No random numbers: the same profile
//!    always gives the same arc. The widest triple that fits inside the arc
//!    gives a circle within a few noise σ of it. A triple whose middle point
//!    lies less than [`MIN_SAGITTA_MM`] from the chord of the outer two is
//!    straight within the noise and gives no candidate.
//! 3. **Radius bound.** A plane cuts a sphere of radius `R` in a circle of
//!    radius `r ≤ R`; a fit may exceed `R` by [`RADIUS_TOLERANCE`] (0.5 %).
//!    Cut angles beyond [`MAX_CUT_ANGLE_DEG`] are not searched
//!    (`r ≥ R · cos 80° ≈ 0.17 R`). A three-point circle is only an
//!    estimate, so candidates are kept within [`CANDIDATE_SLACK`] of these
//!    bounds; the refined circle must meet them exactly.
//! 4. **Score.** Each candidate is scored on an evenly spread subsample of
//!    at most [`SCORE_POINTS`] points: the number of points within
//!    [`SEARCH_BAND_MM`] of the circle in its largest piece (step 1).
//!    Counting the piece, not all points near the circle, keeps scattered
//!    background that happens to touch a circle from adding up.
//! 5. **Refinement**, from the best-scoring candidate: the points within the
//!    band of the current circle are split into pieces; the piece with the
//!    most points (from the second round: the most points in common with the
//!    previous round's) is the arc. Its orthogonal-distance circle
//!    (Gauss-Newton from the current circle; no trimming, the band has left
//!    the outliers out; Chernov & Lesort, "Least squares fitting of
//!    circles", J. Math. Imaging Vision 23, 2005) gives the next circle and
//!    band, and the points are re-collected, until the arc no longer changes
//!    (at most [`MAX_REFINE_ROUNDS`] rounds; on the test profiles one or two
//!    fits and a confirming collection). The arc is then fitted once with
//!    [`fit_circle`] (Taubin start, Levenberg-Marquardt, its own 4 σ
//!    outlier trimming): that is the circle reported.
//! 6. **The band** is data-driven. The first collection uses the search
//!    band [`SEARCH_BAND_MM`], which must hold a three-point circle's error;
//!    then it is [`BAND_SIGMAS`] robust standard deviations of the residuals
//!    of the current fit over the arc (1.4826 · MAD about their median, so
//!    a few background points in the arc do not widen it), clamped to
//!    [`BAND_FLOOR_MM`]..[`BAND_CAP_MM`]. At 5 σ a Gaussian point falls
//!    outside once in 1.7 million, and the band is a little wider than the
//!    fit's 4 σ trimming
//!    ([`OUTLIER_THRESHOLD_SIGMAS`](super::OUTLIER_THRESHOLD_SIGMAS)), so that on a clean
//!    stripe the arc holds every point the plain circle fit keeps. The floor
//!    keeps near noise-free data from being cut to rounding; the cap keeps a
//!    noisy fit from swallowing the background. The real SR7140 profiles
//!    (σ ≈ 0.011 mm) get a band of about 0.05 mm.
//! 7. **Acceptance.** The refined circle must lie within the radius bound
//!    and its fit must use at least [`MIN_ARC_POINTS`] points over at least
//!    [`MIN_ARC_SPAN_DEG`]. When it does not, the next best candidate on a
//!    different part of the profile is refined (at most [`MAX_ATTEMPTS`]
//!    attempts); the first accepted arc is the answer. A profile with no
//!    accepted arc gets the error of the best-scoring attempt.
//!
//! The consensus points are the arc (method step 5); the circle fit of them
//! is [`Arc::fit`], exactly what [`centre_from_stripe`](super::centre_from_stripe)
//! computes from [`Arc::points`].
//!
//! A background surface that crosses the circle right next to the arc
//! (within the gap limit) adds the few points at the crossing to the arc;
//! they lie on the circle within the band and do not bias it. A sphere on
//! a table or stand never shows that (the cut circle lies above them).
//!
//! For a 2,500-point profile: 247 triples, the candidates among them scored
//! on the subsample, a few Gauss-Newton fits and one [`fit_circle`]; well
//! under a millisecond in all, most of it the final [`fit_circle`], which
//! on a real 2,500-point arc may take several trimming rounds
//! (`benches/segment.rs`).
//!
//! # Input
//!
//! `points` are `[y, z]` in the laser plane (sensor `x = 0`), mm, in sensor
//! order along the line. They must be finite: remove non-finite points
//! first (a non-finite point is never on a circle, so it is dropped, but it
//! spoils the pitch estimate if there are many).

mod geometry;
mod pieces;
mod refine;

use self::geometry::{Bounds, Circle, geometric_fit, pitch, robust_sigma, span_deg, triples};
use self::pieces::{Piece, Profile};
use self::refine::{Attempt, Failure, Refined, refine};

use nalgebra::Matrix3;

use super::circle::{CircleFit, fit_circle};
use super::{RADIUS_TOLERANCE, StripeError};
use crate::engine::base::numeric::upper_median;

/// Fewest points an accepted arc keeps (and fewest points a profile must
/// have). Below about 20 points the circle fit no longer trims outliers
/// ([`MIN_POINTS_TO_TRIM`](super::MIN_POINTS_TO_TRIM)).
pub const MIN_ARC_POINTS: usize = 20;

/// Smallest span of an accepted arc, deg (seen from its centre). The
/// radius error of a circle fit grows as the inverse square of the span: at
/// 20° a stretch of a larger circle, or of a line, can pass for an arc of
/// the sphere. Arcs below [`SHORT_ARC_DEG`](super::SHORT_ARC_DEG) are
/// accepted but warned about by the sphere-centre step.
pub const MIN_ARC_SPAN_DEG: f64 = 20.0;

/// Largest cut angle searched, deg: arcs of radius below `R · cos 80°`
/// (0.17 `R`) are not taken for the sphere. Beyond
/// [`CUT_ANGLE_MAX_DEG`](super::CUT_ANGLE_MAX_DEG) (70°) the centre is
/// already poorly fixed; a still smaller circle is more likely an edge or a
/// bump than the sphere.
pub const MAX_CUT_ANGLE_DEG: f64 = 80.0;

/// Half-width of the band around a candidate circle in which points count
/// for its score, mm. It must hold a three-point circle's error plus the
/// noise of a usable sensor (σ up to about 0.03 mm); it is the crate's
/// poor-fit RMS ([`HIGH_RMS_MM`](super::HIGH_RMS_MM)).
pub const SEARCH_BAND_MM: f64 = 0.1;

/// Smallest distance of a triple's middle point from the chord of its outer
/// points, mm: below it the three points are straight within the noise
/// (twice the search band) and give no candidate. A circle of radius 40 mm
/// reaches it over an 8 mm chord.
pub const MIN_SAGITTA_MM: f64 = 2.0 * SEARCH_BAND_MM;

/// Half-width of the refinement band in robust standard deviations of the
/// fit residuals.
pub const BAND_SIGMAS: f64 = 5.0;

/// Narrowest refinement band, mm: keeps near noise-free data (σ → 0) from
/// losing points to rounding.
pub const BAND_FLOOR_MM: f64 = 0.02;

/// Widest refinement band, mm: a fit with a robust σ above 0.04 mm does not
/// widen the band further (twice [`HIGH_RMS_MM`](super::HIGH_RMS_MM)).
pub const BAND_CAP_MM: f64 = 0.2;

/// Largest gap between consecutive arc points along the profile, in point
/// pitches (the median distance between neighbours): 3 mm at 0.03 mm
/// pitch. Larger gaps split the consensus; the largest piece is kept.
pub const MAX_GAP_PITCHES: f64 = 100.0;

/// Pieces of consensus a band point may continue: the most recently
/// extended ones (method step 1).
pub const OPEN_PIECES: usize = 8;

/// Candidate circles are searched with radii up to this fraction beyond the
/// radius bound, both ways: a three-point circle is only an estimate.
pub const CANDIDATE_SLACK: f64 = 0.05;

/// Most points a candidate is scored on (an evenly spread subsample).
pub const SCORE_POINTS: usize = 512;

/// Span levels of the candidate triples (each half the previous).
pub const SPAN_LEVELS: usize = 7;

/// Most collect-and-refit rounds of one refinement.
pub const MAX_REFINE_ROUNDS: usize = 12;

/// Most candidates refined before giving up.
pub const MAX_ATTEMPTS: usize = 4;

/// 1 / Φ⁻¹(3/4): a median absolute deviation to a Gaussian σ.
const MAD_TO_SIGMA: f64 = 1.482_602_218_505_602;

/// Shortest triple span, in points.
const MIN_TRIPLE_SPAN: usize = 4;

/// Most Gauss-Newton steps of a refinement round's circle fit (from a
/// circle within the band, two to four are needed).
const GAUSS_NEWTON_STEPS: usize = 20;

/// Step halvings tried before a Gauss-Newton step counts as stalled.
const HALVINGS: usize = 4;

/// The sphere's arc found in a raw profile.
#[derive(Debug, Clone, PartialEq)]
pub struct Arc {
    /// Indices into the profile of the arc's points, ascending: the points
    /// within the final band around the circle along one contiguous piece of
    /// the profile.
    pub kept: Vec<usize>,
    /// Circle centre `(y_c, z_c)`, mm, laser plane.
    pub centre: [f64; 2],
    /// Circle radius `r`, mm.
    pub radius: f64,
    /// Orthogonal-distance RMS of the circle fit over the points it used,
    /// mm.
    pub rms: f64,
    /// Angular span of the points the circle fit used, seen from the centre,
    /// deg.
    pub span_deg: f64,
    /// Points in the profile.
    pub total: usize,
    /// Points not kept (`total − kept.len()`): [`Arc::off_arc`] plus
    /// [`Arc::outliers`].
    pub dropped: usize,
    /// Dropped points before the first or after the last kept point along
    /// the profile: the background.
    pub off_arc: usize,
    /// Dropped points between the first and the last kept point: off the
    /// circle (spikes, reflections, clutter).
    pub outliers: usize,
    /// Half-width of the final band around the circle, mm: [`BAND_SIGMAS`]
    /// · [`Arc::sigma`], clamped to [`BAND_FLOOR_MM`]..[`BAND_CAP_MM`].
    pub band: f64,
    /// Robust standard deviation (1.4826 · MAD) of the kept points'
    /// residuals from the last refinement circle, mm.
    pub sigma: f64,
    /// Point pitch: median distance between neighbouring profile points, mm.
    pub pitch: f64,
    /// Candidate circles scored (triples within the loosened radius bound).
    pub candidates: usize,
    /// Candidates refined, including the accepted one.
    pub attempts: usize,
    /// Collect-and-refit rounds of the accepted refinement, the last one
    /// the collection that confirmed the arc.
    pub rounds: usize,
    /// The circle fit ([`fit_circle`]) of the kept points, in the order of
    /// `kept` (its residuals and inlier flags are per kept point). It is what
    /// [`centre_from_stripe`](super::centre_from_stripe) of
    /// [`Arc::points`] computes; hand it to
    /// [`sphere_centre`](super::sphere_centre). Its outlier trimming may set
    /// a few kept points aside ([`CircleFit::rejected`]): the band
    /// ([`BAND_SIGMAS`]) is a little wider than the fit's threshold.
    pub fit: CircleFit,
}

impl Arc {
    /// The kept points of `profile` (the profile `find_arc` was given), in
    /// order.
    #[must_use]
    pub fn points(&self, profile: &[[f64; 2]]) -> Vec<[f64; 2]> {
        self.kept
            .iter()
            .filter_map(|&i| profile.get(i).copied())
            .collect()
    }

    /// Covariance of `(y_c, z_c, r)`, mm² (that of [`Arc::fit`]).
    #[must_use]
    pub fn covariance(&self) -> Matrix3<f64> {
        self.fit.covariance
    }

    /// One line for a user report, e.g. "kept 812 of 2,514 points; 1,702
    /// dropped: 1,690 off the arc, 12 outliers along it; r = 38.1234 mm,
    /// rms 0.0112 mm over 104.2°" (and, when the circle fit set kept points
    /// aside, "; the circle fit set 2 of them aside").
    #[must_use]
    pub fn summary(&self) -> String {
        let mut line = format!(
            "kept {} of {} points; {} dropped: {} off the arc, {} outliers along it; r = {:.4} mm, rms {:.4} mm over {:.1}°",
            grouped(self.kept.len()),
            grouped(self.total),
            grouped(self.dropped),
            grouped(self.off_arc),
            grouped(self.outliers),
            self.radius,
            self.rms,
            self.span_deg
        );
        let trimmed = self.fit.rejected();
        if trimmed > 0 {
            line.push_str(&format!(
                "; the circle fit set {} of them aside",
                grouped(trimmed)
            ));
        }
        line
    }
}

/// No arc of the sphere in a profile.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SegmentError {
    /// The profile has too few points for an arc.
    #[error("profile has {found} points, an arc needs at least {needed}")]
    TooFewPoints {
        /// Points in the profile.
        found: usize,
        /// [`MIN_ARC_POINTS`].
        needed: usize,
    },
    /// The sphere radius is not a positive number.
    #[error("sphere radius {sphere_radius} mm is not a positive number")]
    InvalidRadius {
        /// The radius given, mm.
        sphere_radius: f64,
    },
    /// No circle of the profile has a radius a sphere of radius `R` can
    /// produce.
    #[error("{}", no_circle_message(*.sphere_radius, *.min_radius, *.max_radius, .best.as_ref()))]
    NoCircle {
        /// Sphere radius `R`, mm.
        sphere_radius: f64,
        /// Smallest radius searched, `R · cos(MAX_CUT_ANGLE_DEG)`, mm.
        min_radius: f64,
        /// Largest radius accepted, `R · (1 + RADIUS_TOLERANCE)`, mm.
        max_radius: f64,
        /// The circle with the largest consensus, if the profile has any
        /// curved stretch; `None` when it is straight within the noise.
        best: Option<BestCircle>,
    },
    /// The best arc within the radius bound has too few points or too short
    /// a span.
    #[error(
        "no arc of a sphere of radius {sphere_radius} mm: the best arc has {points} points over {span_deg:.1}° (r = {radius:.3} mm); at least {MIN_ARC_POINTS} points over {MIN_ARC_SPAN_DEG:.0}° are needed"
    )]
    TooSmall {
        /// Sphere radius `R`, mm.
        sphere_radius: f64,
        /// Points kept on the best arc.
        points: usize,
        /// Its span, deg.
        span_deg: f64,
        /// Its radius, mm.
        radius: f64,
    },
    /// The circle fit of the best consensus failed.
    #[error("the circle fit of the best arc ({points} points) failed: {source}")]
    Fit {
        /// Points handed to the fit.
        points: usize,
        /// The fit's error.
        source: StripeError,
    },
}

/// A circle found in a profile that is not an arc of the sphere (in
/// [`SegmentError::NoCircle`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BestCircle {
    /// Its radius, mm.
    pub radius: f64,
    /// Points on it: within its band along one contiguous piece of the
    /// profile.
    pub points: usize,
}

fn no_circle_message(sphere: f64, min: f64, max: f64, best: Option<&BestCircle>) -> String {
    match best {
        Some(b) => format!(
            "no arc of a sphere of radius {sphere} mm: the best circle has r = {:.3} mm ({} points on it), outside {min:.3}..{max:.3} mm",
            b.radius,
            grouped(b.points)
        ),
        None => format!(
            "no arc of a sphere of radius {sphere} mm: the profile has no curved stretch (every triple of points spread along it is straight within {MIN_SAGITTA_MM} mm)"
        ),
    }
}

/// A count with thousands separators: 2514 → "2,514".
#[must_use]
pub fn grouped(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::with_capacity(digits.len() + digits.len() / 3);
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// Finds the arc of a sphere of radius `sphere_radius` (mm) in a raw
/// profile: the points of one contiguous stretch of the profile that lie on
/// one circle of radius `R · cos 80° ≤ r ≤ R · (1 + RADIUS_TOLERANCE)`, by
/// consensus over candidate circles and refinement (see the module
/// documentation for the method and its thresholds).
///
/// `points` are `[y, z]` in the laser plane, mm, in sensor order along the
/// line, all finite. The same input always gives the same result.
///
/// # Errors
/// - [`SegmentError::TooFewPoints`]: fewer than [`MIN_ARC_POINTS`] points;
/// - [`SegmentError::InvalidRadius`]: `sphere_radius` not finite and
///   positive;
/// - [`SegmentError::NoCircle`]: no circle within the radius bound (the
///   message names the best circle found, or says the profile is straight);
/// - [`SegmentError::TooSmall`]: the best arc within the bound has fewer
///   than [`MIN_ARC_POINTS`] points or spans less than [`MIN_ARC_SPAN_DEG`];
/// - [`SegmentError::Fit`]: the circle fit of the best consensus failed.
pub fn find_arc(points: &[[f64; 2]], sphere_radius: f64) -> Result<Arc, SegmentError> {
    if !(sphere_radius.is_finite() && sphere_radius > 0.0) {
        return Err(SegmentError::InvalidRadius { sphere_radius });
    }
    let n = points.len();
    if n < MIN_ARC_POINTS {
        return Err(SegmentError::TooFewPoints {
            found: n,
            needed: MIN_ARC_POINTS,
        });
    }
    let bounds = Bounds {
        min: sphere_radius * MAX_CUT_ANGLE_DEG.to_radians().cos(),
        max: sphere_radius * (1.0 + RADIUS_TOLERANCE),
    };
    let pitch = pitch(points);
    let max_gap = MAX_GAP_PITCHES * pitch;
    let profile = Profile {
        points,
        max_gap2: max_gap * max_gap,
    };

    // Candidates (steps 2 and 3).
    let mut inside = Vec::new();
    let mut outside = Vec::new();
    for [a, b, c] in triples(n) {
        if let Some(circle) = Circle::through(points[a], points[b], points[c], MIN_SAGITTA_MM) {
            if bounds.contains_loosely(circle.radius) {
                inside.push(circle);
            } else {
                outside.push(circle);
            }
        }
    }

    // Scores on the subsample (step 4).
    let step = n.div_ceil(SCORE_POINTS).max(1);
    let score_gap = max_gap.max(2.0 * step as f64 * pitch);
    let score_gap2 = score_gap * score_gap;
    let mut scored: Vec<(Piece, Circle)> = inside
        .iter()
        .map(|c| (profile.score(c, SEARCH_BAND_MM, step, score_gap2), *c))
        .collect();
    // Stable: equal scores keep the triple order.
    scored.sort_by_key(|(piece, _)| std::cmp::Reverse(piece.count));

    // Refinement of the best candidates on distinct parts of the profile
    // (steps 5 to 7).
    let mut failed: Vec<Attempt> = Vec::new();
    for (score, circle) in &scored {
        if failed.len() >= MAX_ATTEMPTS || score.count == 0 {
            break;
        }
        // A candidate on a part of the profile a failed attempt already
        // covered (more than half its piece) is the same structure again.
        let width = score.last - score.first + 1;
        let covered = failed.iter().any(|a| {
            let (lo, hi) = (score.first.max(a.first), score.last.min(a.last));
            hi >= lo && 2 * (hi - lo + 1) > width
        });
        if covered {
            continue;
        }
        let attempt = refine(&profile, *circle, bounds, *score);
        match attempt.result {
            Ok(refined) => {
                return Ok(arc_from(refined, n, pitch, inside.len(), failed.len() + 1));
            }
            Err(_) => failed.push(attempt),
        }
    }

    // No arc: say why, from the most prominent attempt.
    if let Some(Err(failure)) = failed.into_iter().next().map(|a| a.result) {
        return Err(match failure {
            Failure::Radius { radius, points } => SegmentError::NoCircle {
                sphere_radius,
                min_radius: bounds.min,
                max_radius: bounds.max,
                best: Some(BestCircle { radius, points }),
            },
            Failure::Small {
                points,
                span_deg,
                radius,
            } => SegmentError::TooSmall {
                sphere_radius,
                points,
                span_deg,
                radius,
            },
            Failure::Fit { points, source } => SegmentError::Fit { points, source },
        });
    }
    // No candidate within the bound: the best circle outside it (scored on
    // the subsample, its points counted on the whole profile).
    let best = outside
        .iter()
        .map(|c| (profile.score(c, SEARCH_BAND_MM, step, score_gap2), *c))
        .max_by_key(|(s, _)| s.count)
        .map(|(_, c)| BestCircle {
            radius: c.radius,
            points: profile.score(&c, SEARCH_BAND_MM, 1, profile.max_gap2).count,
        });
    Err(SegmentError::NoCircle {
        sphere_radius,
        min_radius: bounds.min,
        max_radius: bounds.max,
        best,
    })
}

/// The [`Arc`] of an accepted refinement.
fn arc_from(refined: Refined, total: usize, pitch: f64, candidates: usize, attempts: usize) -> Arc {
    let kept = refined.kept;
    let within = match (kept.first(), kept.last()) {
        (Some(&first), Some(&last)) => last - first + 1,
        _ => 0,
    };
    let dropped = total - kept.len();
    let outliers = within - kept.len();
    Arc {
        centre: refined.fit.centre,
        radius: refined.fit.radius,
        rms: refined.fit.rms,
        span_deg: refined.fit.arc_span_deg,
        total,
        dropped,
        off_arc: dropped - outliers,
        outliers,
        band: refined.band,
        sigma: refined.sigma,
        pitch,
        candidates,
        attempts,
        rounds: refined.rounds,
        kept,
        fit: refined.fit,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grouped_counts() {
        assert_eq!(grouped(0), "0");
        assert_eq!(grouped(999), "999");
        assert_eq!(grouped(2514), "2,514");
        assert_eq!(grouped(1_234_567), "1,234,567");
    }

    #[test]
    fn circle_through_three_points() {
        let c = Circle::through([5.0, 0.0], [0.0, 5.0], [-5.0, 0.0], 0.1).unwrap();
        assert!((c.centre[0]).abs() < 1e-12 && (c.centre[1]).abs() < 1e-12);
        assert!((c.radius - 5.0).abs() < 1e-12);
        assert!(Circle::through([0.0, 0.0], [1.0, 0.05], [2.0, 0.0], 0.1).is_none());
        assert!(Circle::through([1.0, 1.0], [1.0, 1.0], [1.0, 1.0], 0.1).is_none());
    }

    #[test]
    fn triples_cover_the_profile() {
        let t = triples(2500);
        assert_eq!(t[0], [0, 1249, 2499]);
        assert!(t.iter().all(|[a, b, c]| a < b && b < c && *c < 2500));
        assert!(t.len() < 260, "{}", t.len());
        assert_eq!(triples(3).len(), 0);
    }
}
