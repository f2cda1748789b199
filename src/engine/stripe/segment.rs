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

use nalgebra::{Matrix3, Vector3};

use super::circle::{CircleFit, fit_circle};
use super::{RADIUS_TOLERANCE, StripeError};
use crate::engine::numeric::upper_median;

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
    #[error("{}", no_circle_message(*.sphere_radius, *.min_radius, *.max_radius, .best))]
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

fn no_circle_message(sphere: f64, min: f64, max: f64, best: &Option<BestCircle>) -> String {
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
fn grouped(n: usize) -> String {
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

/// A circle `(y_c, z_c, r)`, mm.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Circle {
    centre: [f64; 2],
    radius: f64,
}

impl Circle {
    /// The circle through three points; `None` when they are straight within
    /// `min_sagitta` (or coincident).
    fn through(a: [f64; 2], b: [f64; 2], c: [f64; 2], min_sagitta: f64) -> Option<Self> {
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
    fn residual(&self, p: &[f64; 2]) -> f64 {
        let (dx, dy) = (p[0] - self.centre[0], p[1] - self.centre[1]);
        (dx * dx + dy * dy).sqrt() - self.radius
    }

    /// Squared-distance limits of the band `|d − r| ≤ band`.
    fn band_limits(&self, band: f64) -> (f64, f64) {
        let lo = (self.radius - band).max(0.0);
        let hi = self.radius + band;
        (lo * lo, hi * hi)
    }

    fn within(&self, p: &[f64; 2], (lo, hi): (f64, f64)) -> bool {
        let (dx, dy) = (p[0] - self.centre[0], p[1] - self.centre[1]);
        let d2 = dx * dx + dy * dy;
        d2 >= lo && d2 <= hi
    }
}

/// Radii an arc of the sphere may have, mm.
#[derive(Debug, Clone, Copy)]
struct Bounds {
    min: f64,
    max: f64,
}

impl Bounds {
    fn contains(&self, r: f64) -> bool {
        r >= self.min && r <= self.max
    }

    fn contains_loosely(&self, r: f64) -> bool {
        r >= self.min * (1.0 - CANDIDATE_SLACK) && r <= self.max * (1.0 + CANDIDATE_SLACK)
    }
}

/// A piece of consensus: consecutive band points along the profile, each
/// within the gap limit of the one before it in the piece.
#[derive(Debug, Clone, Copy, Default)]
struct Piece {
    /// Band points in the piece.
    count: usize,
    /// Index of its first point in the profile.
    first: usize,
    /// Index of its last point in the profile.
    last: usize,
    /// Band points in the piece that the previous round kept.
    common: usize,
}

/// Splits the band points of a circle, met in profile order, into pieces
/// (method step 1): a point continues the most recently extended of the
/// last [`OPEN_PIECES`] pieces whose last point is within the gap limit,
/// else it starts a new piece. A stray band point elsewhere on the circle
/// (clutter on its far side) thus starts a piece of its own without cutting
/// the arc in two.
struct Pieces {
    pieces: Vec<Piece>,
    /// Ids of the open pieces, most recently extended first.
    open: Vec<usize>,
    max_gap2: f64,
}

impl Pieces {
    fn new(max_gap2: f64) -> Self {
        Self {
            pieces: Vec::new(),
            open: Vec::with_capacity(OPEN_PIECES + 1),
            max_gap2,
        }
    }

    /// Adds band point `i` (`common`: the previous round kept it); returns
    /// the id of its piece.
    fn push(&mut self, points: &[[f64; 2]], i: usize, common: bool) -> usize {
        let p = &points[i];
        let found = self.open.iter().position(|&id| {
            let q = &points[self.pieces[id].last];
            let (dx, dy) = (p[0] - q[0], p[1] - q[1]);
            dx * dx + dy * dy <= self.max_gap2
        });
        let id = if let Some(pos) = found {
            let id = self.open.remove(pos);
            let piece = &mut self.pieces[id];
            piece.count += 1;
            piece.last = i;
            id
        } else {
            self.pieces.push(Piece {
                count: 1,
                first: i,
                last: i,
                common: 0,
            });
            self.open.truncate(OPEN_PIECES - 1);
            self.pieces.len() - 1
        };
        self.pieces[id].common += usize::from(common);
        self.open.insert(0, id);
        id
    }

    /// The piece with the most points the previous round kept, then with the
    /// most points (the first such on a tie); `None` when there is none.
    fn best(&self) -> Option<(usize, Piece)> {
        let mut best: Option<(usize, Piece)> = None;
        for (id, piece) in self.pieces.iter().enumerate() {
            if best.is_none_or(|(_, b)| (piece.common, piece.count) > (b.common, b.count)) {
                best = Some((id, *piece));
            }
        }
        best
    }
}

/// What the search works with.
struct Profile<'a> {
    points: &'a [[f64; 2]],
    /// Squared largest gap between consecutive arc points, mm².
    max_gap2: f64,
}

impl Profile<'_> {
    /// The largest piece of the points within `band` of `circle`, over the
    /// points `step` apart, with the gap limit `max_gap2` (mm²).
    fn score(&self, circle: &Circle, band: f64, step: usize, max_gap2: f64) -> Piece {
        let limits = circle.band_limits(band);
        let mut pieces = Pieces::new(max_gap2);
        for (i, p) in self.points.iter().enumerate().step_by(step) {
            if circle.within(p, limits) {
                pieces.push(self.points, i, false);
            }
        }
        pieces.best().map(|(_, p)| p).unwrap_or_default()
    }

    /// The points within `band` of `circle` in the piece with the most
    /// points of `previous` (a mask over the profile), or, without one or on
    /// a tie, with the most points; ascending.
    fn collect(&self, circle: &Circle, band: f64, previous: Option<&[bool]>) -> Vec<usize> {
        let limits = circle.band_limits(band);
        let mut pieces = Pieces::new(self.max_gap2);
        let mut members: Vec<(usize, usize)> = Vec::new();
        for (i, p) in self.points.iter().enumerate() {
            if circle.within(p, limits) {
                let common = previous.is_some_and(|m| m.get(i).copied().unwrap_or(false));
                members.push((i, pieces.push(self.points, i, common)));
            }
        }
        let Some((best, _)) = pieces.best() else {
            return Vec::new();
        };
        members
            .into_iter()
            .filter(|&(_, id)| id == best)
            .map(|(i, _)| i)
            .collect()
    }
}

/// Robust standard deviation (1.4826 · MAD about the median) of `values`;
/// 0 when empty. Reorders `values`.
fn robust_sigma(values: &mut [f64]) -> f64 {
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
fn pitch(points: &[[f64; 2]]) -> f64 {
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
fn triples(n: usize) -> Vec<[usize; 3]> {
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
fn span_deg(points: &[[f64; 2]], indices: &[usize], centre: [f64; 2]) -> f64 {
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

/// Why one refinement did not give an arc.
enum Failure {
    /// The refined circle is outside the radius bound.
    Radius { radius: f64, points: usize },
    /// Too few points or too short a span.
    Small {
        points: usize,
        span_deg: f64,
        radius: f64,
    },
    /// The circle fit failed.
    Fit { points: usize, source: StripeError },
}

/// One refinement's outcome with the profile indices it covered.
struct Attempt {
    result: Result<Refined, Failure>,
    first: usize,
    last: usize,
}

/// An accepted refinement.
struct Refined {
    kept: Vec<usize>,
    fit: CircleFit,
    band: f64,
    sigma: f64,
    rounds: usize,
}

/// `JᵀJ`, `Jᵀres` and `Σ res²` of the orthogonal residuals `|p − c| − r`
/// of the points `indices` for the circle `(c, r)`.
fn normal_equations(
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
    #[allow(clippy::cast_precision_loss)] // point counts are far below 2^52
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
fn geometric_fit(points: &[[f64; 2]], indices: &[usize], start: Circle) -> Option<Circle> {
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

/// Collect-and-refit from a candidate circle (method steps 5 to 7).
/// `seed_piece` is the candidate's scored piece (the range reported when
/// nothing is collected).
fn refine(profile: &Profile<'_>, seed: Circle, bounds: Bounds, seed_piece: Piece) -> Attempt {
    let mut circle = seed;
    let mut band = SEARCH_BAND_MM;
    let mut sigma = 0.0;
    let mut mask = vec![false; profile.points.len()];
    let mut kept: Vec<usize> = Vec::new();
    let mut fitted = false;
    let mut rounds = 0;
    let mut residuals = Vec::new();
    let range = |run: &[usize]| match (run.first(), run.last()) {
        (Some(&first), Some(&last)) => (first, last),
        _ => (seed_piece.first, seed_piece.last),
    };
    let fail = |result, (first, last)| Attempt {
        result: Err(result),
        first,
        last,
    };
    while rounds < MAX_REFINE_ROUNDS {
        let run = profile.collect(&circle, band, fitted.then_some(mask.as_slice()));
        rounds += 1;
        if fitted && run == kept {
            break;
        }
        if run.len() < MIN_ARC_POINTS {
            return fail(
                Failure::Small {
                    points: run.len(),
                    span_deg: span_deg(profile.points, &run, circle.centre),
                    radius: circle.radius,
                },
                range(&run),
            );
        }
        let Some(next) = geometric_fit(profile.points, &run, circle) else {
            return fail(
                Failure::Fit {
                    points: run.len(),
                    source: StripeError::Degenerate,
                },
                range(&run),
            );
        };
        residuals.clear();
        residuals.extend(run.iter().map(|&i| next.residual(&profile.points[i])));
        sigma = robust_sigma(&mut residuals);
        band = (BAND_SIGMAS * sigma).clamp(BAND_FLOOR_MM, BAND_CAP_MM);
        circle = next;
        for &i in &kept {
            mask[i] = false;
        }
        for &i in &run {
            mask[i] = true;
        }
        kept = run;
        fitted = true;
    }
    let covered = range(&kept);
    if !fitted {
        // The first round fits unless it returns: not reached.
        return fail(
            Failure::Small {
                points: 0,
                span_deg: 0.0,
                radius: circle.radius,
            },
            covered,
        );
    }
    let points: Vec<[f64; 2]> = kept.iter().map(|&i| profile.points[i]).collect();
    let fit = match fit_circle(&points) {
        Ok(fit) => fit,
        Err(source) => {
            return fail(
                Failure::Fit {
                    points: kept.len(),
                    source,
                },
                covered,
            );
        }
    };
    let result = if !bounds.contains(fit.radius) {
        Err(Failure::Radius {
            radius: fit.radius,
            points: kept.len(),
        })
    } else if fit.used() < MIN_ARC_POINTS || fit.arc_span_deg < MIN_ARC_SPAN_DEG {
        Err(Failure::Small {
            points: fit.used(),
            span_deg: fit.arc_span_deg,
            radius: fit.radius,
        })
    } else {
        Ok(Refined {
            kept,
            fit,
            band,
            sigma,
            rounds,
        })
    };
    Attempt {
        result,
        first: covered.0,
        last: covered.1,
    }
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
    #[allow(clippy::cast_precision_loss)] // point counts are far below 2^52
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
