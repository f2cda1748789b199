//! What a run tells its caller while it works: a [`Progress`] report
//! naming the [`Phase`] it is in (setting up, an update of the loop or
//! one of its inner steps, each diagnostic after the loop, the centres
//! and statistics at the end), the fraction of the whole run done with
//! each phase weighted by its usual share of the time
//! ([`Progress::run_fraction`]), and the caller's answer ([`Control`]):
//! go on or cancel. Every phase reports before its work, so a cancel is
//! seen at the start of each of them, the last one included.

use super::held_out::HeldOutScheme;

/// Reported at the start of every phase and after every ε evaluation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Progress {
    /// Updates made so far (0 for the starting ε).
    pub updates: usize,
    /// ε after that many updates, mm (NaN while setting up, before the
    /// first ε).
    pub epsilon: f64,
    /// The iteration bound.
    pub max_iterations: usize,
    /// The threshold, mm.
    pub threshold: f64,
    /// What the run is doing: a new ε of the loop, or a phase before the
    /// loop, inside an update or after the loop.
    pub phase: Phase,
}

/// What a run is doing, for progress reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Before the loop: the method's problem (`ml`: the noise model of
    /// every measurement and the identifiable set).
    Setup,
    /// The loop computed ε after `updates` updates.
    Loop,
    /// Inside update `updates + 1`: the method's inner step `step` (`ml`:
    /// a Levenberg-Marquardt step) was taken.
    Step {
        /// Inner steps taken in this update.
        step: usize,
    },
    /// The held-out figure ([`super::held_out`]): `done` of `of` refits
    /// made (measurements for leave-one-pose-out, folds for k-fold).
    HeldOut {
        /// How the refits are made.
        scheme: HeldOutScheme,
        /// Refits done.
        done: usize,
        /// Refits in all.
        of: usize,
    },
    /// `ml`: the parameter covariance and the leverages.
    Covariance,
    /// `ml`: residuals, outliers and the variance factor.
    Outliers,
    /// `ml`: the predicted σ of the distances.
    Prediction,
    /// `ml`: the predicted error over the sensor's measuring range.
    RangeError,
    /// `ml`: leave-one-station-out refits, `done` of `of` stations.
    CrossValidation {
        /// Stations done.
        done: usize,
        /// Stations in all.
        of: usize,
    },
    /// The last phase: every centre before and after, the within-station
    /// and validation statistics.
    Finishing,
}

/// Where each phase starts on the whole run's progress bar (0 to 1), in
/// run order, measured on a 19,210-measurement `ml` run: setting up and
/// the first ε take ~5 % of the time, the loop ~45 %, the diagnostics
/// before the cross-validation ~15 %, the cross-validation ~30 % (it
/// grows with the stations), the end ~5 %. [`RUN_END`] is left to the
/// caller's own last step (the workbench's views of the result).
const PHASE_START: [(PhaseKind, f64); 9] = [
    (PhaseKind::Setup, 0.0),
    (PhaseKind::Loop, 0.05),
    (PhaseKind::HeldOut, 0.45),
    (PhaseKind::Covariance, 0.50),
    (PhaseKind::Outliers, 0.55),
    (PhaseKind::Prediction, 0.60),
    (PhaseKind::RangeError, 0.63),
    (PhaseKind::CrossValidation, 0.66),
    (PhaseKind::Finishing, 0.94),
];

/// Where the engine's share of the progress bar ends: what is left is
/// the caller's (building its views of the result).
pub const RUN_END: f64 = 0.97;

/// Inner steps of the loop at which its share of the bar is half full:
/// an `ml` run from the nominal model takes 5-10 LM steps in all.
const LOOP_HALF_STEPS: f64 = 8.0;

/// Inner steps counted for one whole update of the loop.
const STEPS_PER_UPDATE: f64 = 4.0;

/// The phases without their counts, for [`PHASE_START`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum PhaseKind {
    Setup,
    Loop,
    HeldOut,
    Covariance,
    Outliers,
    Prediction,
    RangeError,
    CrossValidation,
    Finishing,
}

impl Phase {
    fn kind(self) -> PhaseKind {
        match self {
            Self::Setup => PhaseKind::Setup,
            Self::Loop | Self::Step { .. } => PhaseKind::Loop,
            Self::HeldOut { .. } => PhaseKind::HeldOut,
            Self::Covariance => PhaseKind::Covariance,
            Self::Outliers => PhaseKind::Outliers,
            Self::Prediction => PhaseKind::Prediction,
            Self::RangeError => PhaseKind::RangeError,
            Self::CrossValidation { .. } => PhaseKind::CrossValidation,
            Self::Finishing => PhaseKind::Finishing,
        }
    }

    /// The phase's name, without counts: "the loop", "covariance and
    /// leverages", …
    #[must_use]
    pub fn name(&self) -> &'static str {
        match self {
            Self::Setup => "setting up the problem",
            Self::Loop | Self::Step { .. } => "the identification loop",
            Self::HeldOut { .. } => "held-out figure",
            Self::Covariance => "covariance and leverages",
            Self::Outliers => "outliers and variance factor",
            Self::Prediction => "predicted distance σ",
            Self::RangeError => "predicted error over the range",
            Self::CrossValidation { .. } => "leave-one-station-out",
            Self::Finishing => "centres and statistics",
        }
    }

    /// In words, with the count done where there is one.
    #[must_use]
    pub fn describe(&self, updates: usize) -> String {
        match *self {
            Self::Loop => format!("update {updates}"),
            Self::Step { step } => format!("update {}: solver step {step}", updates + 1),
            Self::CrossValidation { done, of } => {
                format!("leave-one-station-out: {done} of {of} stations")
            }
            Self::HeldOut { scheme, done, of } => format!(
                "held out ({}): {done} of {of} {}",
                scheme.label(of),
                scheme.unit()
            ),
            _ => self.name().to_string(),
        }
    }

    /// The fraction of the phase done, when it has one.
    #[must_use]
    pub fn fraction(&self) -> Option<f64> {
        match *self {
            Self::CrossValidation { done, of } | Self::HeldOut { done, of, .. } if of > 0 => {
                Some(done as f64 / of as f64)
            }
            _ => None,
        }
    }
}

impl Progress {
    /// The fraction of the whole run done (0 to [`RUN_END`]): the start
    /// of the phase on the bar ([`PHASE_START`]) plus the part of its
    /// share done: the stations of the cross-validation, or in the loop
    /// the inner steps taken (`k / (k + 8)`, never full: how many an
    /// update takes is not known in advance). It grows from phase to
    /// phase; inside the loop an update may take more inner steps than
    /// are counted for it, so a caller showing a bar keeps the largest
    /// fraction seen.
    #[must_use]
    pub fn run_fraction(&self) -> f64 {
        let kind = self.phase.kind();
        let at = PHASE_START
            .iter()
            .position(|(k, _)| *k == kind)
            .unwrap_or(0);
        let start = PHASE_START[at].1;
        let end = PHASE_START.get(at + 1).map_or(RUN_END, |(_, s)| *s);
        let within = match self.phase {
            Phase::Loop | Phase::Step { .. } => {
                let step = match self.phase {
                    Phase::Step { step } => step as f64,
                    _ => 0.0,
                };
                let k = self.updates as f64 * STEPS_PER_UPDATE + step;
                k / (k + LOOP_HALF_STEPS)
            }
            other => other.fraction().unwrap_or(0.0),
        };
        start + (end - start) * within.clamp(0.0, 1.0)
    }
}

/// What the progress callback asks for (one type for every job, in
/// `base`): [`Control::Cancel`] ends the run with
/// [`StopReason::Cancelled`](super::StopReason::Cancelled).
pub use crate::engine::base::control::Control;

#[cfg(test)]
mod tests {
    use super::*;

    fn at(updates: usize, phase: Phase) -> f64 {
        Progress {
            updates,
            epsilon: 0.1,
            max_iterations: 50,
            threshold: 0.01,
            phase,
        }
        .run_fraction()
    }

    /// The bar only moves forward through a run, phase by phase, and
    /// stays below the caller's share.
    #[test]
    fn the_run_fraction_grows_through_the_phases() {
        let run = [
            at(0, Phase::Setup),
            at(0, Phase::Loop),
            at(0, Phase::Step { step: 1 }),
            at(0, Phase::Step { step: 3 }),
            at(1, Phase::Loop),
            at(1, Phase::Step { step: 3 }),
            at(2, Phase::Loop),
            at(2, Phase::Covariance),
            at(2, Phase::Outliers),
            at(2, Phase::Prediction),
            at(2, Phase::RangeError),
            at(2, Phase::CrossValidation { done: 0, of: 3000 }),
            at(
                2,
                Phase::CrossValidation {
                    done: 2999,
                    of: 3000,
                },
            ),
            at(2, Phase::Finishing),
        ];
        for w in run.windows(2) {
            assert!(w[1] >= w[0], "{run:?}");
        }
        assert!((run[0] - 0.0).abs() < 1e-12);
        assert!(run[13] < RUN_END && run[13] > 0.9, "{run:?}");
        // Every later phase starts above any point of the loop.
        assert!(at(40, Phase::Step { step: 99 }) < at(0, Phase::Covariance));
        // Half the loop's share after 8 inner steps.
        assert!((at(2, Phase::Loop) - (0.05 + 0.40 * 0.5)).abs() < 1e-12);
    }

    #[test]
    fn every_phase_has_a_name() {
        for p in [
            Phase::Setup,
            Phase::Covariance,
            Phase::Outliers,
            Phase::Prediction,
            Phase::RangeError,
            Phase::Finishing,
        ] {
            assert_eq!(p.describe(3), p.name());
        }
        assert_eq!(
            Phase::CrossValidation { done: 2, of: 9 }.describe(0),
            "leave-one-station-out: 2 of 9 stations"
        );
    }
}
