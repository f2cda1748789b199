//! The pose planner: the Plan form ([`form`]), Make plan with progress
//! and Cancel ([`job`]), the plan on show and its files (the joint-log
//! CSV and the controller's program), and a session simulated from it;
//! the Plan view ([`ui`]) with its 3-D scene of the poses ([`scene`]).

pub mod form;
pub mod job;
pub mod scene;
pub mod ui;

use std::path::PathBuf;

use nalgebra::Isometry3;

use crate::engine::base::session::Use;
use crate::engine::files::format::write_atomic;
use crate::engine::tools::plan::{self, Plan, PlanError, Planned, Selection};

use super::command::{Command, PlanCommand, PlanExport, Tab};
use super::error::JobError;
use super::job::{Job, Slot};
use super::ledger::{Artefact, Reading, Stamp};
use super::results::more_stations;
use super::session::{LoadedSession, Source, analyse, range_text};
use super::state::{Level, Notice};
use super::{AppState, Core, Write};
use form::PlanForm;
use job::{make_plan, simulate_plan};

/// What the Plan view shows.
#[derive(Debug, Default)]
pub struct PlanView {
    /// The last plan, or why planning failed (the message).
    pub outcome: Option<Result<Planned, String>>,
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
            make_plan(&config, runs, w).map_err(JobError::from)
        }) {
            self.state.say(Level::Info, "planning the poses…");
        }
    }

    /// The plan on show and its stamp, when it is current; otherwise
    /// `None`, and the operator is told why nothing is written (a stale
    /// plan is never written as another robot's program).
    fn current_plan(&mut self, what: &str) -> Option<(Plan, Stamp)> {
        let Some(Ok(o)) = &self.state.plan.outcome else {
            self.state.say(Level::Warning, "make a plan first");
            return None;
        };
        let plan = (*o.plan).clone();
        match self.state.ledger.check(Artefact::Plan) {
            Ok(stamp) => Some((plan, stamp)),
            Err(why) => {
                let (title, status) = (format!("{what} refused"), format!("{what} refused: {why}"));
                self.refuse(&title, &status, format!("{why}: press Make plan again"));
                None
            }
        }
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
        self.write(ctx, path, write, move |path| write_plan(kind, &plan, path));
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
    pub(super) fn on_plan(&mut self, job: &Job, outcome: Result<Planned, JobError>) {
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

/// Writes `plan` to `path` (atomically) as `kind`: the joint-log CSV or
/// the controller's program (the Plan and Re-check views' exports).
///
/// # Errors
/// The program cannot be rendered, or the file cannot be written.
pub fn write_plan(
    kind: PlanExport,
    plan: &Plan,
    path: &std::path::Path,
) -> Result<Option<String>, JobError> {
    let text = match kind {
        PlanExport::Csv => plan::plan_csv(plan),
        PlanExport::Program(c) => plan::render_program(c, plan)?,
    };
    write_atomic(path, text.as_bytes())?;
    Ok(None)
}

/// The hand-eye guess "from the open calibration": the result's on show,
/// else the open session's.
#[must_use]
pub fn plan_hand_eye(state: &AppState) -> Option<Isometry3<f64>> {
    state
        .result
        .as_ref()
        .map(|v| v.file.hand_eye)
        .or_else(|| state.loaded.as_ref().and_then(|l| l.session.hand_eye))
}

/// The Plan form: every field it shows, the hand-eye guess, and (unseen)
/// the whole request.
#[must_use]
pub fn reading(f: &PlanForm, session_hand_eye: Option<Isometry3<f64>>) -> Reading {
    let r = &f.request;
    let hand_eye = match (f.hand_eye_from_session, session_hand_eye) {
        (false, _) => "the paper's initial one".to_string(),
        (true, None) => "from the open calibration (none open)".to_string(),
        (true, Some(h)) => {
            let t = h.translation.vector;
            format!(
                "from the open calibration ({:.3}, {:.3}, {:.3} mm)",
                t.x, t.y, t.z
            )
        }
    };
    let (d, sphere) = (&r.design, r.design.sphere);
    let fields = [
        ("robot", f.robot.clone()),
        (
            "sphere",
            format!("({}, {}, {}) mm", sphere[0], sphere[1], sphere[2]),
        ),
        ("translations", d.n_translation.to_string()),
        ("rotations", d.n_rotation.to_string()),
        ("identify stations", d.n_identify.to_string()),
        ("poses per identify station", d.identify_poses.to_string()),
        ("validate stations", d.n_validate.to_string()),
        ("poses per validate station", d.validate_poses.to_string()),
        ("candidates", d.candidates.to_string()),
        ("prediction runs", r.predict_runs.to_string()),
        ("cut angle", format!("{}°", d.cut_angle)),
        ("seed", d.seed.to_string()),
        ("objective", objective_text(d.selection).into()),
        ("range", range_text(r.range.as_ref())),
        ("spread", r.spread.to_string()),
        ("hand-eye guess", hand_eye),
    ];
    let fields = Vec::from(fields.map(|(k, v)| (k.to_string(), v)));
    // Fields the view does not show (cone, box, …) still count.
    let unseen = format!("{r:?}");
    Reading::new(fields, unseen)
}

/// The plan's objective in words (the form's and the settings' reading).
#[must_use]
pub fn objective_text(selection: Selection) -> &'static str {
    match selection {
        Selection::Volume => "working volume (I-optimal)",
        Selection::DOptimal => "D-optimal",
        Selection::Random => "random",
    }
}
