//! The Plan view's work: the engine's pose planner
//! ([`crate::engine::tools::plan::plan`]) and its predicted accuracy
//! ([`crate::engine::tools::plan::predict`]), as `spherecal plan` runs them, with
//! progress and cancel; the plan's files; and a simulated session of a
//! plan, to try the whole workflow without a robot.

use std::path::PathBuf;
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
use super::Write;
use super::files::analyse;
use crate::app::commands::PlanExport;
use crate::app::commands::{Command, PlanCommand};
use crate::app::error::JobError;
use crate::app::forms::Tab;
use crate::app::inputs::plan_hand_eye;
use crate::app::job::{Job, Slot};
use crate::app::ledger::{Artefact, Stamp};
use crate::app::state::{Level, LoadedSession, Notice, PlanOutcome, Source};

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
    report: &mut dyn FnMut(String, Option<f64>),
) -> Result<PlanOutcome, PlanError> {
    let control = || {
        if cancel.load(Ordering::Relaxed) {
            Control::Cancel
        } else {
            Control::Continue
        }
    };
    // The candidates take most of the planning; a prediction, when
    // asked for, the second half of the bar.
    let share = if runs > 0 { 0.5 } else { 1.0 };
    let plan = plan::plan(config, &mut |stage| {
        let done = match stage {
            PlanStage::Candidates { done, of } => 0.8 * done as f64 / of.max(1) as f64,
            _ => 0.9,
        };
        report(stage_text(stage), Some(share * done));
        control()
    })?;
    let prediction = (runs > 0).then(|| {
        let predict = PredictConfig {
            runs,
            ..PredictConfig::default()
        };
        plan::predict(&plan, &predict, &mut |done, of| {
            report(
                format!("predicting the accuracy: {done} of {of} simulated calibrations"),
                Some(0.5 + 0.5 * done as f64 / of.max(1) as f64),
            );
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
                if self.state.jobs.cancel(&Slot::Plan).is_some() {
                    self.state
                        .say(Level::Warning, "planning cancelled: no plan was made");
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
        if self.state.jobs.runs(&Slot::Plan) {
            return;
        }
        let session_hand_eye = plan_hand_eye(&self.state);
        let config = match self.forms.plan.config(session_hand_eye) {
            Ok(c) => c,
            Err(e) => {
                self.state.plan.outcome = Some(Err(e.clone()));
                self.state.ledger.forget(Artefact::Plan);
                self.state.say(Level::Warning, e);
                return;
            }
        };
        let runs = self.forms.plan.request.predict_runs;
        let stamp = self.state.ledger.stamp(Artefact::Plan);
        if self.start(ctx, Slot::Plan, stamp, move |w| {
            make_plan(&config, runs, w.flag(), &mut |text, fraction| {
                w.progress(text, fraction);
            })
            .map_err(JobError::from)
        }) {
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
        if let Err(why) = self.state.ledger.check(Artefact::Plan) {
            self.state
                .say(Level::Warning, format!("{what} refused: {why}"));
            self.state.notice = Some(Notice {
                title: format!("{what} refused"),
                body: format!("{why}: press Make plan again"),
            });
            return None;
        }
        let stamp = self.state.ledger.check(Artefact::Plan).ok()?;
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
        let write = Write {
            what: kind.label().to_string(),
            from: Artefact::Plan,
            stamp,
            again: Command::Plan(PlanCommand::Export(kind)),
        };
        self.write(ctx, path, write, move |path| {
            let text = match kind {
                PlanExport::Csv => plan::plan_csv(&plan),
                PlanExport::Program(c) => plan::render_program(c, &plan)?,
            };
            write_atomic(path, text.as_bytes())?;
            Ok(None)
        });
    }

    fn plan_simulate(&mut self, ctx: &egui::Context) {
        let Some((plan, _)) = self.current_plan("Simulate and open") else {
            return;
        };
        let robot = self.forms.plan.robot.clone();
        let seed = self.forms.plan.request.design.seed;
        if self.start(ctx, Slot::Simulate, Stamp::default(), move |_| {
            simulate_plan(&plan, &robot, seed)
                .map(|session| Box::new(analyse(session, Source::Simulated)))
        }) {
            self.state
                .say(Level::Info, "simulating a session of the plan…");
        }
    }

    /// The planner's answer: the plan on show (recorded with the inputs
    /// it started from), or why there is none.
    pub(super) fn on_plan(&mut self, job: &Job, outcome: Result<PlanOutcome, JobError>) {
        match &outcome {
            Ok(o) => {
                let what = format!(
                    "{} poses planned for {}",
                    o.plan.poses.len(),
                    self.forms.plan.robot
                );
                self.state
                    .ledger
                    .record(Artefact::Plan, job.stamp.clone(), what);
            }
            Err(_) => self.state.ledger.forget(Artefact::Plan),
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

    /// A session simulated from the plan: opened, or why not.
    pub(super) fn on_simulated(
        &mut self,
        ctx: &egui::Context,
        outcome: Result<Box<LoadedSession>, JobError>,
    ) {
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
