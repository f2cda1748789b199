//! The Plan view's form and the work its job does: the engine's pose
//! planner ([`crate::engine::plan::plan`]) and its predicted accuracy
//! ([`crate::engine::plan::predict`]), as `spherecal plan` runs them, with
//! progress and cancel; and a simulated session of a plan, to try the
//! whole workflow without a robot.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use nalgebra::Isometry3;

use crate::engine::cell::workspace::Workspace;
use crate::engine::import::RobotSource;
use crate::engine::plan::{
    self, Plan, PlanConfig, PlanError, PlanRequest, PlanStage, PredictConfig, Prediction,
};
use crate::engine::robot::RobotChoice;
use crate::engine::session::Session;
use crate::engine::simulate::{self, PlanExecution, SimConfig};
use crate::engine::solve::Control;

/// The Plan view's fields: the robot preset and where the hand-eye guess
/// comes from, and the rest of the request as the command line has it.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanForm {
    /// Robot preset key.
    pub robot: String,
    /// Take the hand-eye guess from the open session (when it has one)
    /// instead of the paper's initial hand-eye.
    pub hand_eye_from_session: bool,
    /// The plan asked for (its robot and hand-eye are set from the fields
    /// above when it is made).
    pub request: PlanRequest,
}

impl Default for PlanForm {
    fn default() -> Self {
        let key = RobotChoice::Irb2400.key();
        Self {
            robot: key.to_string(),
            hand_eye_from_session: false,
            request: PlanRequest::new(RobotSource::Preset(key.to_string()), default_sphere(key)),
        }
    }
}

/// A sphere position every preset reaches from both sides: the centre of
/// its simulator workspace (base frame, mm).
#[must_use]
pub fn default_sphere(key: &str) -> [f64; 3] {
    RobotChoice::from_key(key).map_or([1000.0, 0.0, 500.0], |c| {
        let w = Workspace::for_robot(c);
        [0, 1, 2].map(|i| (w.min[i] + w.max[i]) / 2.0)
    })
}

impl PlanForm {
    /// The engine's configuration; `session_hand_eye` is the open
    /// session's initial hand-eye, if any.
    ///
    /// # Errors
    /// An unknown preset, or the session hand-eye asked for but absent.
    pub fn config(&self, session_hand_eye: Option<Isometry3<f64>>) -> Result<PlanConfig, String> {
        let mut request = self.request.clone();
        request.robot = RobotSource::Preset(self.robot.clone());
        request.hand_eye = if self.hand_eye_from_session {
            Some(session_hand_eye.ok_or(
                "no hand-eye in the result on show or the open session: untick \"hand-eye guess from the open calibration\" to use the paper's initial one",
            )?)
        } else {
            None
        };
        request.config().map_err(|e| e.to_string())
    }
}

/// What the planning job reports.
#[derive(Debug)]
pub enum PlanEvent {
    /// A stage of the planner, or a finished prediction run, in words.
    Progress(String),
    /// The plan, and its prediction when one was asked for.
    Finished(Result<PlanOutcome, String>),
}

/// A finished plan.
#[derive(Debug, Clone)]
pub struct PlanOutcome {
    /// The plan.
    pub plan: Box<Plan>,
    /// The predicted accuracy, when asked for, or why it failed.
    pub prediction: Option<Result<Prediction, String>>,
}

/// Plans and predicts, reporting each stage; `cancel` stops at the next.
pub fn make_plan(
    config: &PlanConfig,
    runs: usize,
    cancel: &Arc<AtomicBool>,
    report: &mut dyn FnMut(PlanEvent),
) -> Result<PlanOutcome, String> {
    let control = |cancel: &AtomicBool| {
        if cancel.load(Ordering::Relaxed) {
            Control::Cancel
        } else {
            Control::Continue
        }
    };
    let plan = plan::plan(config, &mut |stage| {
        report(PlanEvent::Progress(stage_text(stage)));
        control(cancel)
    })
    .map_err(|e| plan_error(&e))?;
    let prediction = (runs > 0).then(|| {
        let predict = PredictConfig {
            runs,
            ..PredictConfig::default()
        };
        plan::predict(&plan, &predict, &mut |done, of| {
            report(PlanEvent::Progress(format!(
                "predicting the accuracy: {done} of {of} simulated calibrations"
            )));
            control(cancel)
        })
        .map_err(|e| plan_error(&e))
    });
    if let Some(Err(e)) = &prediction
        && cancel.load(Ordering::Relaxed)
    {
        return Err(e.clone());
    }
    Ok(PlanOutcome {
        plan: Box::new(plan),
        prediction,
    })
}

fn plan_error(e: &PlanError) -> String {
    match e {
        PlanError::Cancelled => "cancelled: no plan was made".to_string(),
        other => other.to_string(),
    }
}

/// A planner stage in words.
#[must_use]
pub fn stage_text(stage: PlanStage) -> String {
    match stage {
        PlanStage::Candidates { done, of } => {
            format!("solving candidate poses: station {done} of {of}")
        }
        PlanStage::Analysis => "identifiability of the candidate pool…".to_string(),
        PlanStage::Selection => "D-optimal selection…".to_string(),
        PlanStage::Ordering => "ordering for short moves…".to_string(),
    }
}

/// A simulated session of `plan` (the simulator's default kinematic errors,
/// the true hand-eye of the prediction), each pose touched up on the true
/// robot as in the paper's teach mode, to try the workflow without a
/// robot.
///
/// # Errors
/// The engine's message (a pose that would not see the sphere on the true
/// robot, an unknown preset).
pub fn simulate_plan(plan: &Plan, robot: &str, seed: u64) -> Result<Session, String> {
    let robot_choice =
        RobotChoice::from_key(robot).ok_or_else(|| format!("unknown robot preset `{robot}`"))?;
    let config = SimConfig {
        robot: robot_choice,
        seed,
        name: Some(format!("simulated from a plan ({robot}, seed {seed})")),
        ..SimConfig::default()
    };
    let truth_hand_eye = plan::simulated_true_hand_eye(&plan.flange_from_sensor);
    simulate::simulate_plan(
        &config,
        &plan.robot,
        &truth_hand_eye,
        &plan.simulation_poses(),
        PlanExecution::TouchUp,
    )
    .map(|(session, _truth)| session)
    .map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_match_the_cli_and_the_preset_workspace() {
        let f = PlanForm::default();
        assert_eq!(f.request.sphere, [1050.0, 0.0, 475.0]);
        let c = f.config(None).unwrap();
        assert_eq!(c.n_identify, 9);
        assert_eq!(c.seed, 1);
        assert!(f.config(Some(Isometry3::identity())).is_ok());
        let g = PlanForm {
            hand_eye_from_session: true,
            ..PlanForm::default()
        };
        assert!(g.config(None).unwrap_err().contains("no hand-eye"));
        let h = PlanForm {
            robot: "kr16".into(),
            ..PlanForm::default()
        };
        assert!(h.config(None).unwrap_err().contains("kr16"));
    }
}
