//! The Plan view's job work: the engine's pose planner
//! ([`crate::engine::tools::plan::plan`]) and its predicted accuracy
//! ([`crate::engine::tools::plan::predict`]) as `spherecal plan` runs
//! them, with progress and cancel; and a simulated session of a plan, to
//! try the whole workflow without a robot.

use crate::engine::base::robot::RobotChoice;
use crate::engine::base::session::Session;
use crate::engine::calibrate::solve::Control;
use crate::engine::tools::plan::{
    self, Plan, PlanConfig, PlanError, PlanProgress, PlanStage, Planned, PredictConfig,
    RequestError,
};
use crate::engine::tools::simulate::{self, PlanExecution, SimConfig};

use crate::app::error::JobError;
use crate::app::job::Worker;

/// Reports `phase` and `fraction` to `w`, and [`Control::Cancel`] once
/// the job should stop (cancelled, or the workbench gone): the job-slot
/// glue of the Plan, Compensate and Re-check jobs (it could be a method
/// of the shared job slot's worker).
pub fn report(w: &Worker, phase: impl Into<String>, fraction: Option<f64>) -> Control {
    if w.progress(phase, fraction) {
        Control::Continue
    } else {
        Control::Cancel
    }
}

/// Plans and predicts ([`plan::plan_and_predict`], as `spherecal plan`),
/// reporting each stage in words to `w`; Cancel stops at the next stage
/// or prediction run.
///
/// # Errors
/// The planner's error ([`PlanError::Cancelled`] after a cancel, also
/// during the prediction). A failed prediction is not an error: the plan
/// comes with the reason.
pub fn make_plan(config: &PlanConfig, runs: usize, w: &Worker) -> Result<Planned, PlanError> {
    // The candidates take most of the planning; a prediction, when
    // asked for, the second half of the bar.
    let share = if runs > 0 { 0.5 } else { 1.0 };
    let predict = (runs > 0).then(|| PredictConfig {
        runs,
        ..PredictConfig::default()
    });
    plan::plan_and_predict(config, predict.as_ref(), &mut |progress| match progress {
        PlanProgress::Stage(stage) => {
            let done = match stage {
                PlanStage::Candidates { done, of } => 0.6 * done as f64 / of.max(1) as f64,
                PlanStage::Analysis { done, of } => 0.6 + 0.3 * done as f64 / of.max(1) as f64,
                _ => 0.9,
            };
            report(w, stage_text(stage), Some(share * done))
        }
        PlanProgress::Planned(_) if w.cancelled() => Control::Cancel,
        PlanProgress::Planned(_) => Control::Continue,
        PlanProgress::Predicting { done, of } => report(
            w,
            format!("predicting the accuracy: {done} of {of} simulated calibrations"),
            Some(0.5 + 0.5 * done as f64 / of.max(1) as f64),
        ),
    })
}

/// A planner stage in words.
#[must_use]
pub fn stage_text(stage: PlanStage) -> String {
    match stage {
        PlanStage::Candidates { done, of } => {
            format!("solving candidate poses: station {done} of {of}")
        }
        PlanStage::Analysis { done, of } => format!(
            "identifiability of the candidate pool: {:.0} %",
            100.0 * done as f64 / of.max(1) as f64
        ),
        PlanStage::Selection => "choosing the identify poses…".to_string(),
        PlanStage::Ordering => "ordering for short moves…".to_string(),
        PlanStage::Comparison => "the plan without the spread, for comparison…".to_string(),
    }
}

/// A simulated session of `plan` (the simulator's default kinematic errors,
/// the true hand-eye of the prediction), each pose touched up on the true
/// robot as in the paper's teach mode, to try the workflow without a
/// robot.
///
/// # Errors
/// An unknown preset, or the simulator's error (a pose that would not see
/// the sphere on the true robot).
pub fn simulate_plan(plan: &Plan, robot: &str, seed: u64) -> Result<Session, JobError> {
    let robot_choice = RobotChoice::from_key(robot)
        .ok_or_else(|| RequestError::UnknownPreset(robot.to_owned()))?;
    let config = SimConfig {
        robot: robot_choice,
        seed,
        name: Some(format!("simulated from a plan ({robot}, seed {seed})")),
        range: plan.range,
        ..SimConfig::default()
    };
    let truth_hand_eye = plan::simulated_true_hand_eye(&plan.flange_from_sensor);
    let (session, _truth) = simulate::simulate_plan(
        &config,
        &plan.robot,
        &truth_hand_eye,
        &plan.simulation_poses(),
        PlanExecution::TouchUp,
    )?;
    Ok(session)
}
