//! The Plan view's work: the engine's pose planner
//! ([`crate::engine::tools::plan::plan`]) and its predicted accuracy
//! ([`crate::engine::tools::plan::predict`]), as `spherecal plan` runs them, with
//! progress and cancel; the plan's files; and a simulated session of a
//! plan, to try the whole workflow without a robot.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use crate::engine::base::robot::RobotChoice;
use crate::engine::base::session::{Session, Use};
use crate::engine::calibrate::solve::Control;
use crate::engine::files::format::write_atomic;
use crate::engine::tools::plan::{
    self, Plan, PlanConfig, PlanError, PlanStage, PredictConfig, RequestError,
};
use crate::engine::tools::simulate::{self, PlanExecution, SimConfig};

use super::Core;
use super::files::analyse;
use crate::app::commands::PlanCommand;
use crate::app::error::JobError;
use crate::app::forms::Tab;
use crate::app::inputs::plan_hand_eye;
use crate::app::jobs::{JobMessage, PlanMessage};
use crate::app::provenance::{Output, Stamp};
use crate::app::state::{Level, Notice, PlanExport, PlanOutcome, Source};

/// Plans and predicts, reporting each stage in words; `cancel` stops at
/// the next stage or prediction run.
///
/// # Errors
/// The planner's error ([`PlanError::Cancelled`] after a cancel, also
/// during the prediction). A failed prediction is not an error: the plan
/// comes with the reason.
pub fn make_plan(
    config: &PlanConfig,
    runs: usize,
    cancel: &AtomicBool,
    report: &mut dyn FnMut(String),
) -> Result<PlanOutcome, PlanError> {
    let control = || {
        if cancel.load(Ordering::Relaxed) {
            Control::Cancel
        } else {
            Control::Continue
        }
    };
    let plan = plan::plan(config, &mut |stage| {
        report(stage_text(stage));
        control()
    })?;
    let prediction = (runs > 0).then(|| {
        let predict = PredictConfig {
            runs,
            ..PredictConfig::default()
        };
        plan::predict(&plan, &predict, &mut |done, of| {
            report(format!(
                "predicting the accuracy: {done} of {of} simulated calibrations"
            ));
            control()
        })
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

/// Most identify stations the Plan form offers.
pub const MAX_IDENTIFY_STATIONS: usize = 30;

/// How many identify stations to plan after a FAIL with `have`: half as
/// many again, at least three more (more stations determine the
/// parameters better: README, Evidence), at most
/// [`MAX_IDENTIFY_STATIONS`] unless the session already had more.
#[must_use]
pub fn more_stations(have: usize) -> usize {
    let want = (have + have.div_ceil(2)).max(have + 3);
    want.min(MAX_IDENTIFY_STATIONS.max(have))
}

/// The planner's error in the Plan view's words.
fn plan_error_text(e: &JobError) -> String {
    match e {
        JobError::Plan(PlanError::Cancelled) => "cancelled: no plan was made".to_string(),
        other => other.to_string(),
    }
}

impl Core {
    /// Handles a [`PlanCommand`].
    pub(super) fn plan(&mut self, ctx: &egui::Context, command: PlanCommand) {
        match command {
            PlanCommand::Make => self.plan_make(ctx),
            PlanCommand::Cancel => {
                if let Some(c) = &self.state.plan.cancel {
                    c.store(true, Ordering::Relaxed);
                    self.state.plan.progress = Some("cancelling…".to_string());
                }
            }
            PlanCommand::Export(kind) => self.plan_export(ctx, kind),
            PlanCommand::Simulate => self.plan_simulate(ctx),
            PlanCommand::MoreStations => self.more_stations(),
        }
    }

    /// After a FAIL: the Plan view, set for the open session's robot with
    /// more identify stations than the session has ([`more_stations`]).
    fn more_stations(&mut self) {
        self.forms.tab = Tab::Plan;
        let Some(loaded) = &self.state.loaded else {
            return;
        };
        let have = loaded.session.stations(Use::Identify).len();
        let want = more_stations(have);
        self.forms.plan.request.design.n_identify = want;
        self.state.say(
            Level::Info,
            format!(
                "the Plan form asks for {want} identify stations (the session has {have}): press Make plan, then measure the new poses"
            ),
        );
    }

    fn plan_make(&mut self, ctx: &egui::Context) {
        if self.state.plan.cancel.is_some() {
            return;
        }
        let session_hand_eye = plan_hand_eye(&self.state);
        let config = match self.forms.plan.config(session_hand_eye) {
            Ok(c) => c,
            Err(e) => {
                self.state.plan.outcome = Some(Err(e.clone()));
                self.state.provenance.forget(Output::Plan);
                self.state.say(Level::Warning, e);
                return;
            }
        };
        let runs = self.forms.plan.request.predict_runs;
        let cancel = Arc::new(AtomicBool::new(false));
        let flag = Arc::clone(&cancel);
        let started = self.spawn(ctx, "plan", move |rep| {
            let outcome = make_plan(&config, runs, &flag, &mut |text| {
                rep.send(JobMessage::Plan(PlanMessage::Progress(text)));
            });
            rep.send(JobMessage::Plan(PlanMessage::Finished(
                outcome.map_err(Into::into),
            )));
        });
        if started {
            self.state.plan.cancel = Some(cancel);
            self.state.plan.pending = Some(self.state.provenance.stamp(Output::Plan));
            self.state.plan.progress = Some("planning…".to_string());
            self.state.say(Level::Info, "planning the poses…");
        }
    }

    /// The plan on show and its stamp, when it is current; otherwise
    /// `None`, and the operator is told why nothing is written (a stale
    /// plan is never written as another robot's program).
    fn current_plan(&mut self, what: &str) -> Option<(Plan, Stamp)> {
        let plan = if let Some(Ok(o)) = &self.state.plan.outcome {
            (*o.plan).clone()
        } else {
            self.state.say(Level::Warning, "make a plan first");
            return None;
        };
        if let Err(why) = self.state.provenance.check(Output::Plan) {
            self.state
                .say(Level::Warning, format!("{what} refused: {why}"));
            self.state.notice = Some(Notice {
                title: format!("{what} refused"),
                body: format!("{why}: press Make plan again"),
            });
            return None;
        }
        let stamp = self.state.provenance.made(Output::Plan).cloned()?;
        Some((plan, stamp))
    }

    fn plan_export(&mut self, ctx: &egui::Context, kind: PlanExport) {
        let Some((plan, stamp)) = self.current_plan(kind.label()) else {
            return;
        };
        let Some(dir) = self.export_folder() else {
            return;
        };
        let path: PathBuf = dir.join(kind.file_name(&self.forms.plan.robot));
        let started = self.spawn(ctx, "export", move |rep| {
            let text = match kind {
                PlanExport::Csv => plan::plan_csv(&plan),
                PlanExport::Program(c) => c.render(&plan),
            };
            let outcome = write_atomic(&path, text.as_bytes()).map_err(Into::into);
            rep.send(JobMessage::Plan(PlanMessage::Written {
                kind,
                path,
                outcome,
                stamp,
            }));
        });
        if started {
            self.state.plan.writing += 1;
        }
    }

    fn plan_simulate(&mut self, ctx: &egui::Context) {
        let Some((plan, _)) = self.current_plan("Simulate and open") else {
            return;
        };
        let robot = self.forms.plan.robot.clone();
        let seed = self.forms.plan.request.design.seed;
        let started = self.spawn(ctx, "simulate", move |rep| {
            let outcome = simulate_plan(&plan, &robot, seed)
                .map(|session| Box::new(analyse(session, Source::Simulated)));
            rep.send(JobMessage::Plan(PlanMessage::Simulated(outcome)));
        });
        if started {
            self.state.plan.writing += 1;
            self.state
                .say(Level::Info, "simulating a session of the plan…");
        }
    }

    /// Handles a [`PlanMessage`].
    pub(super) fn on_plan(&mut self, ctx: &egui::Context, message: PlanMessage) {
        match message {
            PlanMessage::Progress(text) => {
                if self.state.plan.cancel.is_some() {
                    self.state.plan.progress = Some(text);
                }
            }
            PlanMessage::Finished(outcome) => {
                self.state.plan.cancel = None;
                self.state.plan.progress = None;
                let stamp = self.state.plan.pending.take().unwrap_or_default();
                if outcome.is_ok() {
                    self.state.provenance.record(Output::Plan, stamp);
                } else {
                    self.state.provenance.forget(Output::Plan);
                }
                match &outcome {
                    Ok(o) => {
                        let line = match &o.prediction {
                            Some(Ok(p)) => format!(
                                "planned {} poses; predicted validation std after {:.3} ± {:.3} mm",
                                o.plan.poses.len(),
                                p.after_mean,
                                p.after_spread
                            ),
                            Some(Err(e)) => {
                                format!("planned {} poses; no prediction: {e}", o.plan.poses.len())
                            }
                            None => format!("planned {} poses", o.plan.poses.len()),
                        };
                        self.state.say(Level::Info, line);
                    }
                    Err(e) => self
                        .state
                        .say(Level::Warning, format!("no plan: {}", plan_error_text(e))),
                }
                self.state.plan.outcome = Some(outcome.map_err(|e| plan_error_text(&e)));
            }
            PlanMessage::Written {
                kind,
                path,
                outcome,
                stamp,
            } => {
                self.state.plan.writing = self.state.plan.writing.saturating_sub(1);
                if outcome.is_ok() {
                    self.state
                        .provenance
                        .wrote(kind.label(), path.clone(), Output::Plan, stamp);
                }
                self.say_written(kind.label(), &path, outcome);
            }
            PlanMessage::Simulated(outcome) => {
                self.state.plan.writing = self.state.plan.writing.saturating_sub(1);
                match outcome {
                    Ok(loaded) => {
                        self.on_session(ctx, *loaded);
                        self.state.say(
                            Level::Info,
                            "opened a session simulated from the plan (not saved yet): press Run to calibrate it",
                        );
                    }
                    Err(e) => {
                        self.state
                            .say(Level::Error, "the plan could not be simulated");
                        self.state.notice = Some(Notice {
                            title: "Could not simulate the plan".to_string(),
                            body: e.to_string(),
                        });
                    }
                }
            }
        }
    }
}
