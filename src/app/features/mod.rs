//! What the workbench does, one module per feature. Each feature has the
//! handler of its [`Command`]s (checks the forms, starts a job), the
//! handler of its jobs' [`JobMessage`]s (updates the state, says what
//! happened) and the plain functions its jobs run (engine calls; the
//! plots PNG reads egui's built-in fonts):
//!
//! | feature | commands | job work |
//! |---|---|---|
//! | [`files`] | open, browse, save | read and fit a session, read a result, save without the left-out measurements |
//! | [`view`] | tab, selection, measurements left out | — |
//! | [`run`] | run, cancel | the calibration |
//! | [`export`] | the Results view's exports | result JSON, CSV, PNG, HTML report, model |
//! | [`import`] | preview, import | the import wizard's engine calls |
//! | [`import_poses`] | scan | a pose file read and paired before import |
//! | [`history`] | scan, drift | scan a library folder |
//! | [`plan`] | plan, cancel, export, simulate | the pose planner and its prediction |
//! | [`compensate`] | compensate, cancel, write | targets and programs through the result on show |
//! | [`measure`] | measure, cancel, export, browse | a scan into a point cloud, its self-validation, PLY/E57/CSV |
//!
//! [`Core`] holds what they share: the state, the forms and the job runner.

pub mod compensate;
pub mod export;
pub mod files;
pub mod history;
pub mod import;
pub mod measure;
pub mod import_poses;
pub mod plan;
pub mod run;
pub mod view;

use std::path::{Path, PathBuf};

use super::commands::Command;
use super::error::JobError;
use super::forms::Forms;
use super::jobs::{JobMessage, Jobs, Reporter, RunFailure};
use super::state::{AppState, Level, Notice};
use super::view::ResultView;

/// The state, the forms and the job runner, with every feature's
/// handlers. The workbench owns one and draws the panels from it.
pub struct Core {
    /// What the workbench knows.
    pub state: AppState,
    /// The fields the widgets edit.
    pub forms: Forms,
    /// The job runner.
    pub jobs: Jobs,
    /// The outcome of the run in flight, arrived this frame: shown by
    /// [`Core::finish_run`] once the frame's commands are applied, so that
    /// a Cancel clicked in the frame it arrives in still wins.
    arrived: Option<(u64, Result<Box<ResultView>, RunFailure>)>,
}

impl Core {
    /// A core with these state and forms and no job in flight.
    #[must_use]
    pub fn new(state: AppState, forms: Forms) -> Self {
        Self {
            state,
            forms,
            jobs: Jobs::default(),
            arrived: None,
        }
    }

    /// Reads every input into the provenance (each frame, and before each
    /// command, so that a job stamps the inputs as they are).
    pub fn observe(&mut self) {
        let readings = crate::app::inputs::readings(&self.state, &self.forms);
        self.state.provenance.observe(readings);
    }

    /// Hands a command to its feature.
    pub fn apply(&mut self, ctx: &egui::Context, command: Command) {
        self.observe();
        match command {
            Command::Files(c) => self.files(ctx, c),
            Command::View(c) => self.view(c),
            Command::Run(c) => self.run(ctx, c),
            Command::Export(kind) => self.export(ctx, kind),
            Command::Import(c) => self.import(ctx, c),
            Command::History(c) => self.history(ctx, c),
            Command::Plan(c) => self.plan(ctx, c),
            Command::Compensate(c) => self.compensate(ctx, c),
            Command::Measure(c) => self.measure(ctx, c),
        }
    }

    /// Hands a job's message to its feature.
    pub fn on_message(&mut self, ctx: &egui::Context, message: JobMessage) {
        match message {
            JobMessage::Files(m) => self.on_files(ctx, m),
            JobMessage::Run(m) => self.on_run(m),
            JobMessage::Export(m) => self.on_export(m),
            JobMessage::Import(m) => self.on_import(ctx, m),
            JobMessage::History(m) => self.on_history(ctx, m),
            JobMessage::Plan(m) => self.on_plan(ctx, m),
            JobMessage::Compensate(m) => self.on_compensate(m),
            JobMessage::Measure(m) => self.on_measure(ctx, m),
        }
    }

    /// Starts a job, or says why it could not start.
    fn spawn(
        &mut self,
        ctx: &egui::Context,
        name: &str,
        work: impl FnOnce(&Reporter) + Send + 'static,
    ) -> bool {
        match self.jobs.spawn(name, ctx, work) {
            Ok(()) => true,
            Err(e) => {
                self.state.say(
                    Level::Error,
                    format!("could not start the {name} job (no thread: {e})"),
                );
                false
            }
        }
    }

    /// The export folder of the form, remembered; `None` (with a notice)
    /// when it does not exist.
    fn export_folder(&mut self) -> Option<PathBuf> {
        let dir = PathBuf::from(self.forms.export_dir.trim());
        if !dir.is_dir() {
            self.state.notice = Some(Notice {
                title: "Nothing exported".to_string(),
                body: format!("the export folder {} does not exist", dir.display()),
            });
            return None;
        }
        self.state.prefs.export_folder = Some(dir.clone());
        Some(dir)
    }

    /// The status line for a written file, or the notice of why not.
    fn say_written(&mut self, what: &str, path: &Path, outcome: Result<(), JobError>) {
        match outcome {
            Ok(()) => self
                .state
                .say(Level::Info, format!("wrote {what} to {}", path.display())),
            Err(e) => {
                self.state.say(Level::Error, format!("{what} not written"));
                self.state.notice = Some(Notice {
                    title: format!("Could not write {what}"),
                    body: e.to_string(),
                });
            }
        }
    }
}
