//! Background jobs: every piece of work that may take longer than a frame
//! (reading and fitting a session, the solver, file dialogs, writes) runs
//! on a named thread and reports over one bounded channel, waking the UI
//! with `ctx.request_repaint()`. The frame loop only drains [`JobMessage`]s
//! (egui's http_app, rerun's `background_tasks.rs`).

pub mod measure;

use std::path::PathBuf;
use std::sync::mpsc::{Receiver, SyncSender, TryRecvError, sync_channel};

use crate::engine::calibrate::solve::Progress;
use crate::engine::files::import::PoseCheck;
use crate::engine::tools::history::{Drift, Library};

use super::error::JobError;
use super::forms::ImportForm;
use super::provenance::Stamp;
use super::state::{DialogPurpose, ExportKind, LoadedSession, PlanExport, PlanOutcome};
use super::view::ResultView;
use super::view::compensate::CompensationView;

/// Messages a job may have in flight before it waits for the UI to drain
/// them: far more than a run's ε reports (one per update), so the solver
/// never waits on a UI that keeps up.
pub const CHANNEL_BOUND: usize = 256;

/// Why a run gave no result.
#[derive(Debug)]
pub enum RunFailure {
    /// Cancel was pressed; the solver stopped after this many updates.
    Cancelled(usize),
    /// The session or the solver failed.
    Failed(JobError),
}

/// What a job reports, by the feature that started it.
#[derive(Debug)]
pub enum JobMessage {
    /// Opening and saving files.
    Files(FilesMessage),
    /// The calibration run.
    Run(RunMessage),
    /// The result's exports.
    Export(ExportMessage),
    /// The import wizard.
    Import(ImportMessage),
    /// The library of past results.
    History(HistoryMessage),
    /// The pose planner.
    Plan(PlanMessage),
    /// The Compensate view.
    Compensate(CompensateMessage),
    /// The Measure view.
    Measure(measure::MeasureMessage),
}

/// What the file jobs report.
#[derive(Debug)]
pub enum FilesMessage {
    /// A session file (or the demo) was read and its stripes fitted.
    SessionLoaded(Box<LoadedSession>),
    /// A result file was read for review.
    ResultLoaded {
        /// The file.
        path: PathBuf,
        /// Its view, matched against the session open when it was read.
        view: Box<ResultView>,
    },
    /// A file could not be opened.
    LoadFailed {
        /// The file (or the demo's name).
        what: String,
        /// Why, naming file and measurement.
        error: JobError,
    },
    /// A file dialog closed; `None` when it chose nothing or could not open.
    Dialog {
        /// What it was for.
        purpose: DialogPurpose,
        /// The chosen path.
        path: Option<PathBuf>,
    },
    /// The edited session was written (how many measurements it holds), or
    /// the write was refused.
    Saved {
        /// Target file.
        path: PathBuf,
        /// Measurements written, or why not.
        outcome: Result<usize, JobError>,
    },
}

/// Where a run job is: a phase of the engine's run, or the workbench's
/// own last step (the result file and its views).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RunStage {
    /// The engine's progress report.
    Solver(Progress),
    /// The engine is done: the result file and the views of it are
    /// being built.
    Views,
}

impl RunStage {
    /// What the run is doing, in words that name the phase.
    #[must_use]
    pub fn describe(&self) -> String {
        match self {
            Self::Solver(p) => p.phase.describe(p.updates),
            Self::Views => "the result file and its views".to_string(),
        }
    }

    /// The fraction of the whole run done, phases weighted
    /// ([`Progress::run_fraction`]; the views take the rest of the bar).
    #[must_use]
    pub fn fraction(&self) -> f64 {
        match self {
            Self::Solver(p) => p.run_fraction(),
            Self::Views => crate::engine::calibrate::solve::progress::RUN_END,
        }
    }
}

/// What the solver job reports, each message with the number of its run
/// (a cancelled run's messages are dropped: Cancel always wins).
#[derive(Debug)]
pub enum RunMessage {
    /// The run reached another phase (or the solver computed another ε).
    Progress {
        /// Which run.
        run: u64,
        /// Where it is.
        stage: RunStage,
    },
    /// The run ended.
    Finished {
        /// Which run.
        run: u64,
        /// Its result, or why there is none.
        outcome: Result<Box<ResultView>, RunFailure>,
    },
}

/// What the export jobs report.
#[derive(Debug)]
pub enum ExportMessage {
    /// An export file was written, or why not.
    Written {
        /// What was exported.
        kind: ExportKind,
        /// Target file.
        path: PathBuf,
        /// Success or why not.
        outcome: Result<(), JobError>,
        /// The inputs of what it was written from (for a report: the
        /// result's and the tolerance it judged by).
        stamp: Stamp,
    },
}

/// What the import jobs report.
#[derive(Debug)]
pub enum ImportMessage {
    /// The joint log was read: its header and the preview.
    Previewed {
        /// The header, empty when it could not be read.
        header: Vec<String>,
        /// The form with the mapping guessed from the header, when asked.
        guessed: Option<Box<ImportForm>>,
        /// The mapped rows, or why not.
        preview: Result<String, JobError>,
    },
    /// How far the import job is, in words.
    Progress {
        /// Which job.
        job: u64,
        /// Its stage.
        text: String,
    },
    /// The import built a session, or why not.
    Imported {
        /// Which job (a cancelled one's answer is dropped).
        job: u64,
        /// The session, or why not.
        outcome: Result<Imported, JobError>,
    },
    /// The pose file was read and paired (no profile read), or why not.
    Scanned {
        /// Which scan (an older one's answer is dropped).
        generation: u64,
        /// The preview, or why the pose file cannot be read.
        outcome: Result<Box<crate::engine::files::import::PosePreview>, JobError>,
    },
}

/// The outcome of an import job.
#[derive(Debug)]
pub struct Imported {
    /// The session, analysed like an opened file.
    pub loaded: Box<LoadedSession>,
    /// The flange-pose checks (empty without a check).
    pub checks: Vec<PoseCheck>,
    /// What the import decided, in words (axis map, side, initial
    /// hand-eye).
    pub notes: Vec<String>,
}

/// What the history jobs report.
#[derive(Debug)]
pub enum HistoryMessage {
    /// A library folder was scanned, or why not.
    Scanned {
        /// The folder.
        folder: PathBuf,
        /// The library.
        outcome: Result<Box<Library>, JobError>,
    },
    /// The drift of the chosen robot over the ticked results, or why
    /// there is none.
    Drift {
        /// Which request this answers (only the latest is shown).
        generation: u64,
        /// The robot.
        robot: String,
        /// The library with only the ticked results (what the drift's
        /// entry indices refer to).
        ticked: Box<Library>,
        /// The drift.
        outcome: Result<Box<Drift>, JobError>,
    },
}

/// What the planning jobs report.
#[derive(Debug)]
pub enum PlanMessage {
    /// A stage of the planner, or a finished prediction run, in words.
    Progress(String),
    /// The plan, and its prediction when one was asked for.
    Finished(Result<PlanOutcome, JobError>),
    /// A plan file was written, or why not.
    Written {
        /// What was written.
        kind: PlanExport,
        /// Target file.
        path: PathBuf,
        /// Success or why not.
        outcome: Result<(), JobError>,
        /// The inputs of the plan it was written from.
        stamp: Stamp,
    },
    /// A session simulated from the plan, or why not.
    Simulated(Result<Box<LoadedSession>, JobError>),
}

/// What the Compensate view's jobs report, each with the number of its
/// job (a cancelled job's messages are dropped).
#[derive(Debug)]
pub enum CompensateMessage {
    /// Another target is done, in words.
    Progress {
        /// Which job.
        job: u64,
        /// "target P[7]: 12 of 40".
        text: String,
    },
    /// The compensation, or why there is none (naming the target or the
    /// file).
    Finished {
        /// Which job.
        job: u64,
        /// The view of it, or the message.
        outcome: Result<Box<CompensationView>, String>,
    },
    /// The compensated file was written, or why not.
    Written {
        /// Target file.
        path: PathBuf,
        /// Success or why not.
        outcome: Result<(), JobError>,
        /// The inputs of the compensation it was written from.
        stamp: Stamp,
    },
}

/// The sending end handed to a job.
#[derive(Clone)]
pub struct Reporter {
    tx: SyncSender<JobMessage>,
    ctx: egui::Context,
}

impl Reporter {
    /// Sends a message and wakes the UI. Returns false when the workbench
    /// is gone (the job should stop).
    #[allow(
        clippy::must_use_candidate,
        reason = "a job that has nothing more to do after its last message ignores the answer"
    )]
    pub fn send(&self, message: JobMessage) -> bool {
        let ok = self.tx.send(message).is_ok();
        self.ctx.request_repaint();
        ok
    }
}

/// The job runner: one channel, many named threads.
pub struct Jobs {
    tx: SyncSender<JobMessage>,
    rx: Receiver<JobMessage>,
}

impl Default for Jobs {
    fn default() -> Self {
        let (tx, rx) = sync_channel(CHANNEL_BOUND);
        Self { tx, rx }
    }
}

impl Jobs {
    /// A reporter for `ctx`.
    #[must_use]
    pub fn reporter(&self, ctx: &egui::Context) -> Reporter {
        Reporter {
            tx: self.tx.clone(),
            ctx: ctx.clone(),
        }
    }

    /// Runs `work` on a new thread named `spherecal-<name>`.
    ///
    /// # Errors
    /// The thread could not be started.
    pub fn spawn(
        &self,
        name: &str,
        ctx: &egui::Context,
        work: impl FnOnce(&Reporter) + Send + 'static,
    ) -> std::io::Result<()> {
        let reporter = self.reporter(ctx);
        std::thread::Builder::new()
            .name(format!("spherecal-{name}"))
            .spawn(move || work(&reporter))
            .map(|_| ())
    }

    /// Every message waiting now, oldest first (never blocks).
    #[must_use]
    pub fn drain(&self) -> Vec<JobMessage> {
        let mut out = Vec::new();
        loop {
            match self.rx.try_recv() {
                Ok(m) => out.push(m),
                Err(TryRecvError::Empty | TryRecvError::Disconnected) => return out,
            }
        }
    }
}
