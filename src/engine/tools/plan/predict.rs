//! The predicted accuracy of a plan: the plan's poses simulated on
//! randomly perturbed robots and calibrated with `ml`, scored against the
//! truth.

use nalgebra::Isometry3;

use crate::engine::base::cell::sensor;
use crate::engine::base::session::Use;
use crate::engine::calibrate::solve::{self, Control, Options};
use crate::engine::tools::evaluate;
use crate::engine::tools::evaluate::range::{RangeScore, range_score};
use crate::engine::tools::simulate::{self, ErrorModel, InitialHandEye, PlanExecution, SimConfig};

use super::config::check;
use super::*;

/// Most simulated calibrations of a prediction (`--predict-runs`, the
/// Plan view): a few seconds each at most, and the spread of the
/// prediction settles long before.
pub const MAX_PREDICT_RUNS: usize = 1000;

/// How [`predict`] simulates the plan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PredictConfig {
    /// Simulated calibrations.
    pub runs: usize,
    /// Seed of the first run; run `k` uses `seed + k`.
    pub seed: u64,
    /// Kinematic errors of the true robots.
    pub errors: ErrorModel,
    /// Multiplies them.
    pub error_scale: f64,
    /// σ of the joint reading noise, deg.
    pub joint_noise: f64,
    /// σ of the stripe point noise, mm.
    pub stripe_noise: f64,
    /// σ of the laser-tracker reference distances, mm.
    pub tracker_noise: f64,
    /// Whether the poses run as planned or are touched up.
    pub execution: PlanExecution,
}

impl Default for PredictConfig {
    /// 5 runs of random kinematic errors (σ 0.1°, 0.3 mm) with the
    /// simulator's default noise.
    fn default() -> Self {
        let sim = SimConfig::default();
        Self {
            runs: 5,
            seed: 1,
            errors: ErrorModel::Random,
            error_scale: 1.0,
            joint_noise: sim.joint_noise,
            stripe_noise: sim.stripe_noise,
            tracker_noise: sim.tracker_noise,
            execution: PlanExecution::AsPlanned,
        }
    }
}

/// The score of one simulated calibration of a plan (validation std of
/// the distances against the true station distances, mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunScore {
    /// Seed of the run.
    pub seed: u64,
    /// Nominal model, initial hand-eye.
    pub before_std: f64,
    /// Calibrated (`ml`).
    pub after_std: f64,
    /// True model and hand-eye on the same data: the noise floor.
    pub floor_std: f64,
    /// The error over the plan's range (before, after, floor), when the
    /// plan has one.
    pub range: Option<RangeScore>,
    /// The realised error over the volume of the validate stations
    /// (after, floor), with 3 or more of them.
    pub volume: Option<evaluate::VolumeScore>,
}

/// The realised measuring error over the volume, over the runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VolumePrediction {
    /// Mean rms error after calibration, mm.
    pub after_rms: f64,
    /// Mean rms floor, mm.
    pub floor_rms: f64,
    /// Mean of `after / floor`.
    pub ratio_mean: f64,
    /// Largest `after / floor` of any run.
    pub ratio_max: f64,
}

/// The realised error over the plan's range, mean over the runs, mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RangePrediction {
    /// Mean rms error after calibration.
    pub after_rms: f64,
    /// Largest error after calibration in any run.
    pub after_max: f64,
    /// Mean rms floor (the true model on the same readings).
    pub floor_rms: f64,
    /// Mean of `after / floor`.
    pub ratio_mean: f64,
    /// Mean rms model error alone (what `ml`'s range prediction
    /// estimates).
    pub model_rms: f64,
}

/// The predicted accuracy of a plan.
#[derive(Debug, Clone, PartialEq)]
pub struct Prediction {
    /// Every run.
    pub runs: Vec<RunScore>,
    /// Mean validation std after calibration, mm.
    pub after_mean: f64,
    /// Sample std of it over the runs, mm (0 for one run).
    pub after_spread: f64,
    /// Mean noise floor, mm.
    pub floor_mean: f64,
    /// Mean of `after / floor` over the runs.
    pub ratio_mean: f64,
    /// Mean validation std before calibration, mm.
    pub before_mean: f64,
    /// The error over the plan's range, when it has one.
    pub range: Option<RangePrediction>,
    /// The error over the volume of the validate stations.
    pub volume: Option<VolumePrediction>,
}

/// The true hand-eye of a simulated run: the plan's guess moved by the
/// paper's own guess error (initial → calibrated hand-eye, section 4.2),
/// so that the default guess gives the paper's calibrated hand-eye.
#[must_use]
pub fn simulated_true_hand_eye(guess: &Isometry3<f64>) -> Isometry3<f64> {
    guess * sensor::paper_initial_hand_eye().inverse() * sensor::paper_hand_eye()
}

/// Predicted calibrated accuracy of a plan: `runs` simulations of its
/// poses ([`simulate::simulate_plan`]) on true robots with seeded random
/// kinematic errors and the true hand-eye of [`simulated_true_hand_eye`],
/// each calibrated with the default method (`ml`, leave-one-station-out
/// cross-validation skipped: it does not change the estimate) and scored
/// against the true station distances ([`evaluate::score`]). `progress`
/// sees `(runs done, runs)` and may cancel.
///
/// # Errors
/// [`PlanError::InvalidConfig`] without 2 validate stations or runs,
/// [`PlanError::Prediction`] when a run fails, [`PlanError::Cancelled`].
pub fn predict(
    plan: &Plan,
    config: &PredictConfig,
    progress: &mut dyn FnMut(usize, usize) -> Control,
) -> Result<Prediction, PlanError> {
    let validate = plan
        .stations
        .iter()
        .filter(|s| s.role == StationRole::Validate)
        .count();
    check(validate >= 2, || {
        format!(
            "the prediction scores distances between validate stations: the plan has {validate}, at least 2 are needed"
        )
    })?;
    check(config.runs >= 1, || {
        "the prediction needs at least one run".to_owned()
    })?;
    let poses = plan.simulation_poses();
    let truth_hand_eye = simulated_true_hand_eye(&plan.flange_from_sensor);
    let hand_eye_groups = plan.count(Use::Translation) > 0;
    let mut runs = Vec::with_capacity(config.runs);
    for k in 0..config.runs {
        let seed = config.seed + k as u64;
        let fail = |failure: PredictionFailure| PlanError::Prediction {
            run: k + 1,
            seed,
            failure,
        };
        let sim = SimConfig {
            seed,
            errors: config.errors,
            error_scale: config.error_scale,
            joint_noise: config.joint_noise,
            stripe_noise: config.stripe_noise,
            tracker_noise: config.tracker_noise,
            diameter: plan.diameter,
            range: plan.range,
            initial_hand_eye: if hand_eye_groups {
                InitialHandEye::None
            } else {
                InitialHandEye::Paper
            },
            ..SimConfig::default()
        };
        let (mut session, truth) =
            simulate::simulate_plan(&sim, &plan.robot, &truth_hand_eye, &poses, config.execution)
                .map_err(|e| fail(e.into()))?;
        if !hand_eye_groups {
            session.hand_eye = Some(plan.flange_from_sensor);
        }
        let mut options = Options::from_session(&session);
        options.ml.cross_validation = false;
        options.held_out = false;
        let prepared = solve::prepare(&session).map_err(|e| fail(e.into()))?;
        // A cancel is looked at inside each run too (its ε and phases):
        // `progress` hears the runs done so far again.
        let mut cancelled = false;
        let cal = solve::run(&session, &prepared, &options, &mut |_| {
            cancelled = progress(k, config.runs) == Control::Cancel;
            if cancelled {
                Control::Cancel
            } else {
                Control::Continue
            }
        })
        .map_err(|e| fail(e.into()))?;
        if cancelled {
            return Err(PlanError::Cancelled);
        }
        let score = evaluate::score(&session, &prepared, &truth, &cal.calibrated, &cal.hand_eye);
        let range = range_score(
            &session,
            &truth,
            &prepared.hand_eye_initial,
            &cal.calibrated,
            &cal.hand_eye,
            None,
        );
        let volume =
            evaluate::volume_score(&session, &prepared, &truth, &cal.calibrated, &cal.hand_eye);
        runs.push(RunScore {
            volume,
            seed,
            before_std: score.before.std,
            after_std: score.after.std,
            floor_std: score.floor.std,
            range,
        });
        if progress(k + 1, config.runs) == Control::Cancel {
            return Err(PlanError::Cancelled);
        }
    }
    let n = runs.len() as f64;
    let mean = |f: &dyn Fn(&RunScore) -> f64| runs.iter().map(f).sum::<f64>() / n;
    let after_mean = mean(&|r| r.after_std);
    let after_spread = if runs.len() >= 2 {
        (runs
            .iter()
            .map(|r| (r.after_std - after_mean).powi(2))
            .sum::<f64>()
            / (n - 1.0))
            .sqrt()
    } else {
        0.0
    };
    let ranges: Vec<RangeScore> = runs.iter().filter_map(|r| r.range).collect();
    let range = (!ranges.is_empty()).then(|| {
        let m = ranges.len() as f64;
        let avg = |f: &dyn Fn(&RangeScore) -> f64| ranges.iter().map(f).sum::<f64>() / m;
        RangePrediction {
            after_rms: avg(&|r| r.after.rms),
            after_max: ranges.iter().map(|r| r.after.max).fold(0.0, f64::max),
            floor_rms: avg(&|r| r.floor.rms),
            ratio_mean: avg(&|r| r.ratio_to_floor()),
            model_rms: avg(&|r| r.model.rms),
        }
    });
    let volumes: Vec<evaluate::VolumeScore> = runs.iter().filter_map(|r| r.volume).collect();
    let volume = (!volumes.is_empty()).then(|| {
        let m = volumes.len() as f64;
        let avg =
            |f: &dyn Fn(&evaluate::VolumeScore) -> f64| volumes.iter().map(f).sum::<f64>() / m;
        VolumePrediction {
            after_rms: avg(&|v| v.after.rms),
            floor_rms: avg(&|v| v.floor.rms),
            ratio_mean: avg(&evaluate::VolumeScore::ratio_to_floor),
            ratio_max: volumes
                .iter()
                .map(evaluate::VolumeScore::ratio_to_floor)
                .fold(0.0, f64::max),
        }
    });
    Ok(Prediction {
        volume,
        range,
        after_mean,
        after_spread,
        floor_mean: mean(&|r| r.floor_std),
        ratio_mean: mean(&|r| r.after_std / r.floor_std),
        before_mean: mean(&|r| r.before_std),
        runs,
    })
}
