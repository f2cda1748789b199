//! One attempt of the arc search: from a candidate circle, collect the
//! points of the largest piece within the band, refit, and repeat until
//! the set stops changing.

use super::{
    BAND_CAP_MM, BAND_FLOOR_MM, BAND_SIGMAS, Bounds, Circle, CircleFit, MAX_REFINE_ROUNDS,
    MIN_ARC_POINTS, MIN_ARC_SPAN_DEG, Piece, Profile, SEARCH_BAND_MM, StripeError, fit_circle,
    geometric_fit, robust_sigma, span_deg,
};

/// Why one refinement did not give an arc.
pub(super) enum Failure {
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
pub(super) struct Attempt {
    pub(super) result: Result<Refined, Failure>,
    pub(super) first: usize,
    pub(super) last: usize,
}

/// An accepted refinement.
pub(super) struct Refined {
    pub(super) kept: Vec<usize>,
    pub(super) fit: CircleFit,
    pub(super) band: f64,
    pub(super) sigma: f64,
    pub(super) rounds: usize,
}

/// Collect-and-refit from a candidate circle (method steps 5 to 7).
/// `seed_piece` is the candidate's scored piece (the range reported when
/// nothing is collected).
pub(super) fn refine(
    profile: &Profile<'_>,
    seed: Circle,
    bounds: Bounds,
    seed_piece: Piece,
) -> Attempt {
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
