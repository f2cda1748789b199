//! The held-out figure of a calibration: each identify measurement's
//! sphere centre predicted by a calibration made **without** it, against
//! its station's centre estimated from the other measurements. The fit's
//! own scatter (the residuals `|X_i − c_s|` of the measurements it was
//! fitted to) flatters: a real set of one sphere station with every pose
//! `identify` has no other figure, and a model with more freedom always
//! fits its own data better. The held-out error of measurement `i` of
//! station `s` is `|X_i' − c_s'|` (mm, base frame): `X_i'` its centre
//! under the refit's model and hand-eye, `c_s'` the refit's estimate of
//! the station's centre from its other measurements (one left: that one).
//! Its rms (3-D) and max over the measurements stand beside the same
//! statistics of the fit's own residuals over the same measurements.
//!
//! Even with no parameter to fit, the held-out error of a station of `m`
//! sightings exceeds the fit's own by `m/(m − 1)` in rms (the point is no
//! longer part of its own centre's estimate): × 2 for `m = 2`, × 1.07 for
//! `m = 15`. The rest of the gap is what the fitted parameters learned
//! from the point itself.
//!
//! - **`ml`: leave-one-pose-out by one Gauss-Newton step.** Each refit is
//!   one Gauss-Newton step from the full solution on the normal equations
//!   with the measurement's rows removed (a rank-3 downdate of its station
//!   block). By the Sherman-Morrison-Woodbury identity the refit's whitened
//!   residual of the left-out measurement is `(I − w·M_i)⁻¹·(r_i + J_i·δ)`,
//!   with `M_i = J_i·H⁻¹·J_iᵀ` its 3 × 3 hat block, `w` its robust weight
//!   and `δ` the full Newton step (zero at convergence): the PRESS residual
//!   of regression, a few 3 × 3 and `k × 3` products per measurement from
//!   the blocks of `H⁻¹` the covariance already needs, linear in the
//!   measurements. Measured against exact refits (a complete LM solve
//!   without each measurement, [`ml::exact_held_out`](super::ml::exact_held_out)),
//!   see the README's "Held-out figure".
//! - **`paper`: exact refits of the paper's method.** The paper's update is
//!   a truncated SVD of paired differences with no station centres and no
//!   weights; an `ml` step on its result would score `ml`'s refit, not the
//!   paper's. So each refit is the paper's own update (same pairing and SVD
//!   tolerance) made from the same start on the session without the
//!   held-out measurements, as many times as the run made it, and the
//!   station centre is the mean of the other measurements' centres under
//!   it. The count is the run's, not the loop's stop rule again: a refit
//!   that stopped at the threshold after other updates than the run would
//!   score a different procedure, and one that missed the threshold would
//!   make every update the bound allows (on the demo the folds then cost
//!   41 times the run instead of 13). Leave-one-pose-out up to
//!   [`PAPER_LEAVE_ONE_OUT_MAX`] identify measurements, else
//!   [`PAPER_FOLDS`]-fold (measurement `k` of the stations in file order
//!   goes to fold `k mod K`, so that two measurements of a station share
//!   a fold only when it has more than `K`): the cost stays at `K` times
//!   the run's updates, linear in the measurements.

use nalgebra::Vector3;

use super::estimate::{Estimate, Station};
use super::{Control, Phase, Step, Update};
pub use crate::engine::base::records::held_out::{HeldOut, HeldOutRecord, HeldOutScheme};

/// Up to this many identify measurements the paper's held-out figure is
/// leave-one-pose-out: 50 runs of the paper's method on 50 measurements
/// take milliseconds, and the real sets (15-36 poses of one
/// station) get the same scheme as `ml`.
pub const PAPER_LEAVE_ONE_OUT_MAX: usize = 50;

/// Folds of the paper's held-out figure above
/// [`PAPER_LEAVE_ONE_OUT_MAX`]: ten refits on nine tenths of the data each
/// (the figure's sampling error is set by the number of predicted
/// measurements, not of folds), ten times the paper's own run.
pub const PAPER_FOLDS: usize = 10;

/// The fold of each sighting of `stations` (outer: station, inner: its
/// sightings): consecutive over the stations in file order, modulo `folds`.
fn fold_of(stations: &[Station], folds: usize) -> Vec<Vec<usize>> {
    let mut k = 0_usize;
    stations
        .iter()
        .map(|st| {
            st.sightings
                .iter()
                .map(|_| {
                    let f = k % folds;
                    k += 1;
                    f
                })
                .collect()
        })
        .collect()
}

/// The mean of `points`, or `None` for none.
fn mean(points: &[Vector3<f64>]) -> Option<Vector3<f64>> {
    (!points.is_empty()).then(|| points.iter().sum::<Vector3<f64>>() / points.len() as f64)
}

/// The paper's held-out figure: its update (a fresh one from the run's
/// start for each training set, made by `refit_from`) made `updates`
/// times without each fold of the identify `stations` (see the module
/// docs), scored against the fit `fitted`. `None` when `phase` cancelled.
pub(super) fn paper_refits(
    refit_from: &dyn Fn(Vec<Station>) -> Box<dyn Update>,
    fitted: &Estimate,
    updates: usize,
    stations: &[Station],
    phase: &mut dyn FnMut(Phase) -> Control,
) -> Option<HeldOut> {
    let owned: Vec<Station> = stations
        .iter()
        .filter(|s| s.sightings.len() >= 2)
        .cloned()
        .collect();
    let n: usize = owned.iter().map(|s| s.sightings.len()).sum();
    let (scheme, folds) = if n <= PAPER_LEAVE_ONE_OUT_MAX {
        (HeldOutScheme::LeaveOnePoseOut, n)
    } else {
        (HeldOutScheme::KFold, PAPER_FOLDS)
    };
    let fold = fold_of(&owned, folds.max(1));
    // The fit's own residuals: about each station's mean under the fit.
    let fit: Vec<Vec<f64>> = fitted
        .station_centres(&owned)
        .iter()
        .map(|c| {
            let m = mean(c).unwrap_or_else(Vector3::zeros);
            c.iter().map(|x| (x - m).norm()).collect()
        })
        .collect();
    let mut held: Vec<Vec<Option<f64>>> = owned
        .iter()
        .map(|s| vec![None; s.sightings.len()])
        .collect();
    let mut cancel = |done: usize| {
        phase(Phase::HeldOut {
            scheme,
            done,
            of: folds,
        }) == Control::Cancel
    };
    for f in 0..folds {
        // With no update to make, once a fold (the progress is still told).
        if updates == 0 && cancel(f) {
            return None;
        }
        let training: Vec<Station> = owned
            .iter()
            .zip(&fold)
            .map(|(st, fs)| Station {
                id: st.id.clone(),
                sightings: st
                    .sightings
                    .iter()
                    .zip(fs)
                    .filter(|(_, k)| **k != f)
                    .map(|(s, _)| s.clone())
                    .collect(),
            })
            .collect();
        let mut update = refit_from(training.clone());
        let mut failed = false;
        for u in 1..=updates {
            // Before every update: one fold of a large session is a run.
            if cancel(f) {
                return None;
            }
            let mut inner = |_: Phase| Control::Continue;
            // A fold whose rest cannot be calibrated (no pair left)
            // predicts nothing: its measurements stay undetermined.
            if !matches!(update.update(u, &mut inner), Ok(Step::Moved)) {
                failed = true;
                break;
            }
        }
        if failed {
            continue;
        }
        let refit = update.estimate();
        for (s, st) in owned.iter().enumerate() {
            let others: Vec<Vector3<f64>> = training[s]
                .sightings
                .iter()
                .map(|x| refit.centre_in_base(x))
                .collect();
            let Some(centre) = mean(&others) else {
                continue;
            };
            for (i, sighting) in st.sightings.iter().enumerate() {
                if fold[s][i] == f {
                    held[s][i] = Some((refit.centre_in_base(sighting) - centre).norm());
                }
            }
        }
    }
    let mut rows = Vec::new();
    let mut undetermined = Vec::new();
    for (s, st) in owned.iter().enumerate() {
        for (i, sighting) in st.sightings.iter().enumerate() {
            match held[s][i] {
                Some(h) if h.is_finite() => rows.push(HeldOutRecord {
                    measurement: sighting.id.clone(),
                    station: st.id.clone(),
                    held_out: h,
                    fit: fit[s][i],
                }),
                _ => undetermined.push(sighting.id.clone()),
            }
        }
    }
    let refit = format!(
        "the paper's update made {updates} time(s), as in the run, from the same start without the held-out measurements ({}, same pairing and SVD tolerance); the station centre is the mean of its other measurements' centres under that refit",
        scheme.label(folds)
    );
    Some(HeldOut::new(scheme, folds, refit, rows, undetermined))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::calibrate::handeye::Sighting;

    fn station(id: &str, n: usize) -> Station {
        Station {
            id: id.into(),
            sightings: (0..n)
                .map(|i| Sighting {
                    id: format!("{id}{i}"),
                    joints: Vec::new(),
                    flange: None,
                    centre_in_sensor: Vector3::zeros(),
                })
                .collect(),
        }
    }

    #[test]
    fn folds_never_put_two_of_a_small_station_together() {
        let stations = [station("a", 2), station("b", 3), station("c", 12)];
        let fold = fold_of(&stations, 10);
        assert_eq!(fold[0], vec![0, 1]);
        assert_eq!(fold[1], vec![2, 3, 4]);
        // Twelve sightings in ten folds: only there do two share one.
        assert_eq!(fold[2][0], 5);
        assert_eq!(fold[2][5], 0);
        for f in &fold[..2] {
            let mut seen = f.clone();
            seen.dedup();
            assert_eq!(seen.len(), f.len());
        }
    }

    #[test]
    fn the_figure_is_the_rms_and_max_of_its_rows() {
        let row = |m: &str, h: f64, f: f64| HeldOutRecord {
            measurement: m.into(),
            station: "S".into(),
            held_out: h,
            fit: f,
        };
        let h = HeldOut::new(
            HeldOutScheme::LeaveOnePoseOut,
            2,
            String::new(),
            vec![row("a", 3.0, 1.0), row("b", 4.0, 2.0)],
            Vec::new(),
        );
        assert!((h.rms - 12.5_f64.sqrt()).abs() < 1e-12);
        assert_eq!((h.max, h.max_measurement.as_str()), (4.0, "b"));
        assert!((h.fit_rms - 2.5_f64.sqrt()).abs() < 1e-12 && h.fit_max == 2.0);
        let line = h.to_string();
        assert!(
            line.starts_with("held out (leave-one-pose-out): rms 3.536 mm, max 4.000 mm (b); fit's own scatter rms 1.581 mm"),
            "{line}"
        );
        assert_eq!(HeldOutScheme::KFold.label(10), "10-fold");
    }
}
