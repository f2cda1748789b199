//! The Plan view's form and the work its job does: the engine's pose
//! planner ([`crate::engine::plan::plan`]) and its predicted accuracy
//! ([`crate::engine::plan::predict`]), as `spherecal plan` runs them, with
//! progress and cancel; and a simulated session of a plan, to try the
//! whole workflow without a robot.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use nalgebra::Isometry3;

use crate::engine::cell::workspace::Workspace;
use crate::engine::plan::{
    self, DEFAULT_CANDIDATES, DEFAULT_CUT_ANGLE_DEG, Plan, PlanConfig, PlanError, PlanStage,
    PredictConfig, Prediction,
};
use crate::engine::robot;
use crate::engine::robot::RobotChoice;
use crate::engine::session::Session;
use crate::engine::simulate::{self, PlanExecution, SimConfig};
use crate::engine::solve::Control;

/// The Plan view's fields.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanForm {
    /// Robot preset key.
    pub robot: String,
    /// Rough sphere position, base frame, mm.
    pub sphere: [f64; 3],
    /// Take the hand-eye guess from the open session (when it has one)
    /// instead of the paper's initial hand-eye.
    pub hand_eye_from_session: bool,
    /// Translation poses at P0.
    pub n_translation: usize,
    /// Rotation poses at P0.
    pub n_rotation: usize,
    /// Identify stations.
    pub n_identify: usize,
    /// Poses per identify station.
    pub identify_poses: usize,
    /// Validate stations.
    pub n_validate: usize,
    /// Poses per validate station.
    pub validate_poses: usize,
    /// Cut angle of the laser plane, deg.
    pub cut_angle: f64,
    /// Orientation candidates per station.
    pub candidates: usize,
    /// Seed of the plan (and of the simulated session).
    pub seed: u64,
    /// Simulated calibrations for the predicted accuracy (0: none).
    pub predict_runs: usize,
}

impl Default for PlanForm {
    fn default() -> Self {
        let predict = PredictConfig::default();
        Self {
            robot: RobotChoice::Irb2400.key().to_string(),
            sphere: default_sphere(RobotChoice::Irb2400.key()),
            hand_eye_from_session: false,
            n_translation: 4,
            n_rotation: 6,
            n_identify: 9,
            identify_poses: 6,
            n_validate: 10,
            validate_poses: 6,
            cut_angle: DEFAULT_CUT_ANGLE_DEG,
            candidates: DEFAULT_CANDIDATES,
            seed: 1,
            predict_runs: predict.runs,
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
        let preset = robot::preset(&self.robot)
            .ok_or_else(|| format!("unknown robot preset `{}`", self.robot))?;
        let mut c = PlanConfig::for_preset(&preset, self.sphere);
        if self.hand_eye_from_session {
            c.flange_from_sensor = session_hand_eye.ok_or(
                "no hand-eye in the result on show or the open session: untick \"hand-eye guess from the open calibration\" to use the paper's initial one",
            )?;
        }
        c.n_translation = self.n_translation;
        c.n_rotation = self.n_rotation;
        c.n_identify = self.n_identify;
        c.identify_poses = self.identify_poses;
        c.n_validate = self.n_validate;
        c.validate_poses = self.validate_poses;
        c.cut_angle = self.cut_angle;
        c.candidates = self.candidates;
        c.seed = self.seed;
        Ok(c)
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
        assert_eq!(f.sphere, [1050.0, 0.0, 475.0]);
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
