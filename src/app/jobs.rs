//! Background jobs: every piece of work that may take longer than a frame
//! (reading and fitting a session, the solver, file dialogs, writes) runs
//! on a named thread and reports over one bounded channel, waking the UI
//! with `ctx.request_repaint()`. The frame loop only drains [`JobMessage`]s
//! (egui's http_app, rerun's `background_tasks.rs`).

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::mpsc::{Receiver, SyncSender, TryRecvError, sync_channel};

use crate::engine::history::Library;
use crate::engine::import::PoseCheck;
use crate::engine::solve::Progress;

use super::planner::PlanEvent;
use super::state::{DialogPurpose, ExportKind, LoadedSession, PlanExport};
use super::view::ResultView;
use super::wizard::ImportForm;

/// Messages a job may have in flight before it waits for the UI to drain
/// them: far more than a run's ε reports (one per update), so the solver
/// never waits on a UI that keeps up.
pub const CHANNEL_BOUND: usize = 256;

/// Why a run gave no result.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum RunFailure {
    /// Cancel was pressed; the solver stopped after this many updates.
    Cancelled(usize),
    /// The session or the solver failed: the engine's message.
    Failed(String),
}

/// What a job reports.
#[derive(Debug)]
pub enum JobMessage {
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
    LoadFailed(LoadFailure),
    /// The solver computed another ε.
    Progress(Progress),
    /// The run ended.
    RunFinished(Result<Box<ResultView>, RunFailure>),
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
        outcome: Result<usize, String>,
    },
    /// The window's pixels for a plots PNG arrived.
    Screenshot(Arc<egui::ColorImage>),
    /// The import wizard's joint log was read: its header and the preview.
    ImportPreviewed {
        /// The header, empty when it could not be read.
        header: Vec<String>,
        /// The form with the mapping guessed from the header, when asked.
        guessed: Option<Box<ImportForm>>,
        /// The mapped rows, or the engine's message.
        preview: Result<String, String>,
    },
    /// The import wizard built a session, or why not.
    Imported(Result<Imported, String>),
    /// The planning job's progress or result.
    Plan(PlanEvent),
    /// A plan file was written, or why not.
    PlanWritten {
        /// What was written.
        kind: PlanExport,
        /// Target file.
        path: PathBuf,
        /// Success or the error message.
        outcome: Result<(), String>,
    },
    /// A session simulated from the plan, or why not.
    PlanSimulated(Result<Box<LoadedSession>, String>),
    /// A library folder was scanned, or why not.
    Scanned {
        /// The folder.
        folder: PathBuf,
        /// The library or the engine's message.
        outcome: Result<Box<Library>, String>,
    },
    /// An export file was written, or why not.
    Exported {
        /// What was exported.
        kind: ExportKind,
        /// Target file.
        path: PathBuf,
        /// Success or the error message.
        outcome: Result<(), String>,
    },
}

/// The outcome of an import job.
#[derive(Debug)]
pub struct Imported {
    /// The session, analysed like an opened file.
    pub loaded: Box<LoadedSession>,
    /// The flange-pose checks (empty without a check).
    pub checks: Vec<PoseCheck>,
}

/// A file that could not be opened: which, and the engine's message.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LoadFailure {
    /// The file (or the demo's name).
    pub what: String,
    /// The message, naming file and measurement.
    pub message: String,
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
    /// A reporter for `ctx`, e.g. for a screenshot callback.
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
    /// The thread could not be started (the message says so).
    pub fn spawn(
        &self,
        name: &str,
        ctx: &egui::Context,
        work: impl FnOnce(&Reporter) + Send + 'static,
    ) -> Result<(), String> {
        let reporter = self.reporter(ctx);
        std::thread::Builder::new()
            .name(format!("spherecal-{name}"))
            .spawn(move || work(&reporter))
            .map(|_| ())
            .map_err(|e| format!("could not start the {name} thread: {e}"))
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
