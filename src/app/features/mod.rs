//! What the workbench does, one module per feature. Each feature has the
//! handler of its [`Command`]s (checks the forms, starts a job in its
//! [`Slot`]), the handler of its jobs' answers (updates the state, says
//! what happened) and the plain functions its jobs run (engine calls):
//!
//! | feature | commands | job work |
//! |---|---|---|
//! | [`files`] | open, save, the file dialogs | read and fit a session, read a result, save without the left-out measurements |
//! | [`view`] | tab, selection, measurements left out | — |
//! | [`run`] | run, cancel | the calibration |
//! | [`export`] | the Results view's exports | result JSON, CSV, PNG, HTML report, model |
//! | [`import`] | preview, import | the import wizard's engine calls |
//! | [`import_poses`] | scan | a pose file read and paired before import |
//! | [`history`] | scan, drift | scan a library folder |
//! | [`plan`] | plan, cancel, export, simulate | the pose planner and its prediction |
//! | [`compensate`] | compensate, cancel, write | targets and programs through the result on show |
//! | [`measure`] | measure, cancel, export | a scan into a point cloud, its self-validation, PLY/E57/CSV |
//!
//! [`Core`] holds what they share (the state with its job table, the
//! forms) and what every feature does alike: start a job, hand its
//! answer back, write a file, show a file dialog.

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

use std::any::Any;
use std::path::{Path, PathBuf};

use super::commands::Command;
use super::dialog::{self, Ask, NO_DIALOG, Purpose};
use super::error::JobError;
use super::forms::Forms;
use super::job::{Job, Slot, Worker};
use super::ledger::{Artefact, Stamp, WhenStale};
use super::state::{AppState, Confirm, Level, Notice};

/// The state (with the job table) and the forms, with every feature's
/// handlers. The workbench owns one and draws the panels from it.
pub struct Core {
    /// What the workbench knows.
    pub state: AppState,
    /// The fields the widgets edit.
    pub forms: Forms,
}

/// What a write job answers: what was written, of which output, and
/// whether it was (a status line of its own, or why not).
struct WriteAnswer {
    what: String,
    from: Artefact,
    outcome: Result<Option<String>, JobError>,
}

/// A file to write: what it is, the artefact and its stamp, and the
/// command that writes it (asked for again once the operator agrees to
/// replace a file).
struct Write {
    what: String,
    from: Artefact,
    stamp: Stamp,
    again: Command,
}

/// A job's answer as its feature's type.
fn take<T: 'static>(answer: Box<dyn Any + Send>) -> Option<T> {
    answer.downcast::<T>().ok().map(|b| *b)
}

impl Core {
    /// A core with these state and forms and no job in flight.
    #[must_use]
    pub fn new(state: AppState, forms: Forms) -> Self {
        Self { state, forms }
    }

    /// Reads every input into the ledger (each frame, and before each
    /// command, so that a job stamps the inputs as they are); then an
    /// artefact that went stale is cleared or made again, as it says
    /// ([`WhenStale`]).
    pub fn observe(&mut self, ctx: &egui::Context) {
        let readings = crate::app::inputs::readings(&self.state, &self.forms);
        self.state.ledger.observe(readings);
        for a in Artefact::ALL {
            let ledger = &self.state.ledger;
            match a.when_stale() {
                WhenStale::Mark => {}
                WhenStale::Clear => {
                    if ledger.stale(a).is_some() {
                        self.state.ledger.forget(a);
                        self.clear(a);
                    }
                }
                WhenStale::Redo => {
                    let now = ledger.stamp(a);
                    let made = ledger.made(a).is_some_and(|m| m.stamp == now);
                    let making = Slot::of(a)
                        .and_then(|s| self.state.jobs.get(&s))
                        .is_some_and(|j| j.stamp == now);
                    if !(made || making) {
                        self.redo(ctx, a);
                    }
                }
            }
        }
    }

    /// Clears an artefact that went stale (its [`WhenStale::Clear`]).
    fn clear(&mut self, artefact: Artefact) {
        if artefact == Artefact::ImportView {
            let view = &mut self.state.import;
            view.preview = None;
            view.outcome = None;
            view.checks.clear();
        }
    }

    /// Makes an artefact again (its [`WhenStale::Redo`]).
    fn redo(&mut self, ctx: &egui::Context, artefact: Artefact) {
        match artefact {
            Artefact::PoseScan => self.import_scan(ctx),
            Artefact::Drift => self.history_drift(ctx),
            _ => {}
        }
    }

    /// Hands a command to its feature.
    pub fn apply(&mut self, ctx: &egui::Context, command: Command) {
        self.observe(ctx);
        match command {
            Command::Confirm(replace) => self.confirm(ctx, replace),
            Command::Files(c) => self.files(ctx, c),
            Command::Browse(purpose) => self.browse(ctx, purpose),
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

    /// Starts `work` in `slot` with `stamp`; says why when it cannot.
    fn start<T: Send + 'static>(
        &mut self,
        ctx: &egui::Context,
        slot: Slot,
        stamp: Stamp,
        work: impl FnOnce(&Worker) -> T + Send + 'static,
    ) -> bool {
        match self.state.jobs.start(slot, stamp, ctx, work) {
            Ok(()) => true,
            Err(e) => {
                self.state.say(Level::Error, e);
                false
            }
        }
    }

    /// Hands every answer arrived to its feature (the workbench calls
    /// this after the frame's commands: a Cancel in the same frame wins).
    pub fn finish(&mut self, ctx: &egui::Context) {
        for (slot, job, answer) in self.state.jobs.finish() {
            let Some(a) = answer else {
                self.state.say(
                    Level::Error,
                    format!("the {slot:?} job stopped without an answer"),
                );
                continue;
            };
            match slot {
                Slot::Load => take(a).map(|l| self.on_loaded(ctx, l)),
                Slot::Run => take(a).map(|o| self.on_run(&job, o)),
                Slot::Plan => take(a).map(|o| self.on_plan(&job, o)),
                Slot::Simulate => take(a).map(|o| self.on_simulated(ctx, o)),
                Slot::Import => take(a).map(|o| self.on_imported(ctx, &job, o)),
                Slot::ImportPreview => take(a).map(|p| self.on_previewed(ctx, &job, p)),
                Slot::PoseScan => take(a).map(|o| self.on_import_scanned(&job, o)),
                Slot::Library => take(a).map(|o| self.on_scanned(o)),
                Slot::Drift => take(a).map(|o| self.on_drift(&job, o)),
                Slot::Compensate => take(a).map(|o| self.on_compensated(&job, o)),
                Slot::Measure => take(a).map(|o| self.on_measured(&job, o)),
                Slot::Dialog => take(a).map(|(p, path)| self.on_dialog(ctx, p, path)),
                Slot::Write(path) => take(a).map(|w| self.on_written(path, &job, w)),
            };
        }
    }

    /// A native file dialog for `purpose` on a job thread; its answer
    /// goes to the field (or the write) it is for.
    fn browse(&mut self, ctx: &egui::Context, purpose: Purpose) {
        if self.state.jobs.runs(&Slot::Dialog) {
            return;
        }
        let ask = self.ask(purpose);
        if self.start(ctx, Slot::Dialog, Stamp::default(), move |_| {
            (purpose, dialog::show(&ask))
        }) {
            self.state.say(Level::Info, "waiting for the file dialog…");
        }
    }

    /// Where the dialog for `purpose` opens and the name it offers.
    fn ask(&self, purpose: Purpose) -> Ask {
        let prefs = &self.state.prefs;
        let last = prefs.last_folder.clone();
        let import = &self.forms.import;
        let beside_log = || {
            let log = match import.log_kind {
                crate::app::forms::import::LogKind::Joints => &import.joints,
                crate::app::forms::import::LogKind::FlangePoses => &import.poses,
            };
            Path::new(log.trim())
                .parent()
                .map(Path::to_path_buf)
                .filter(|d| !d.as_os_str().is_empty())
                .or_else(|| last.clone())
        };
        let name_of = |field: &str| {
            Path::new(field.trim())
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
        };
        let (folder, file_name) = match purpose {
            Purpose::ExportFolder => (Some(PathBuf::from(self.forms.export_dir.trim())), None),
            Purpose::HistoryFolder => (prefs.history_folder.clone().or(last), None),
            Purpose::ImportProfiles
            | Purpose::ImportReferences
            | Purpose::ImportCentres
            | Purpose::ImportHandEye => (beside_log(), None),
            Purpose::SaveSession => (last, name_of(&self.forms.save_path)),
            Purpose::CompensateOut => (last, self.compensated_file_name()),
            Purpose::MeasureExport => (last, Some(self.cloud_file_name())),
            _ => (last, None),
        };
        Ask {
            purpose,
            folder,
            file_name,
            folder_only: matches!(
                purpose,
                Purpose::ExportFolder | Purpose::HistoryFolder | Purpose::MeasureProfiles
            ) || (purpose == Purpose::ImportProfiles
                && import.profiles_kind == crate::app::forms::ProfilesKind::Folder),
        }
    }

    /// A dialog closed: the chosen path goes to its field (a save dialog
    /// writes at once: it has asked about replacing a file itself).
    fn on_dialog(&mut self, ctx: &egui::Context, purpose: Purpose, path: Option<PathBuf>) {
        self.state.dialog_empty = path.is_none().then_some(purpose);
        let Some(path) = path else {
            self.state.say(Level::Warning, NO_DIALOG);
            return;
        };
        let text = path.display().to_string();
        let f = &mut self.forms;
        match purpose {
            Purpose::Open => self.open_path(ctx, path),
            Purpose::SaveSession => {
                f.save_path = text;
                self.state.ledger.allow(path);
                self.save_session(ctx);
            }
            Purpose::ExportFolder => {
                f.export_dir = text;
                self.state
                    .say(Level::Info, format!("exports go to {}", path.display()));
            }
            Purpose::ImportJoints => {
                f.import.joints = text;
                self.import_preview(ctx, true);
            }
            Purpose::ImportPoses => f.import.poses = text,
            Purpose::ImportProfiles => f.import.profiles = text,
            Purpose::ImportReferences => f.import.references = text,
            Purpose::ImportCentres => f.import.centres = text,
            Purpose::ImportHandEye => f.import.hand_eye_file = text,
            Purpose::HistoryFolder => {
                f.history.folder = text;
                self.history_scan(ctx);
            }
            Purpose::CompensateTargets => {
                f.compensate.targets = text;
                if self.state.result.is_some() {
                    self.observe(ctx);
                    self.compensate_run(ctx);
                }
            }
            Purpose::CompensateTool => f.compensate.tool = text,
            Purpose::CompensateOut => {
                f.compensate.out = text;
                self.state.ledger.allow(path);
                self.compensate_write(ctx);
            }
            Purpose::MeasureSession => f.measure.session_file = text,
            Purpose::MeasureLog => f.measure.log = text,
            Purpose::MeasureProfiles => f.measure.profiles = text,
            Purpose::MeasureFrame => f.measure.frame = text,
            Purpose::MeasureReferences => f.measure.references = text,
            Purpose::MeasureExport => {
                f.measure.out = text;
                self.state.ledger.allow(path);
                self.export_cloud(ctx);
            }
        }
    }

    /// Writes `path` of `write.from` on a job thread (one write a file at
    /// a time): `work` writes it (atomically) and may give a status line
    /// of its own; the file is remembered with the artefact's stamp. A
    /// file that exists and was not written by this window of the same
    /// artefact and inputs is replaced only once the operator says so
    /// ([`Command::Confirm`]); `write.again` is the command that asks
    /// for it again then.
    fn write(
        &mut self,
        ctx: &egui::Context,
        path: PathBuf,
        write: Write,
        work: impl FnOnce(&Path) -> Result<Option<String>, JobError> + Send + 'static,
    ) {
        let Write {
            what,
            from,
            stamp,
            again,
        } = write;
        if let Err(why) = self.state.ledger.may_write(&path, from, &stamp) {
            self.state.say(
                Level::Warning,
                format!("{what} not written yet: {why}; replace it?"),
            );
            self.state.confirm = Some(Confirm { path, why, again });
            return;
        }
        let to = path.clone();
        self.start(ctx, Slot::Write(path), stamp, move |_| WriteAnswer {
            what,
            from,
            outcome: work(&to),
        });
    }

    /// The operator answered the question of [`Core::write`]: the file is
    /// replaced (the write is asked for again), or kept.
    fn confirm(&mut self, ctx: &egui::Context, replace: bool) {
        let Some(c) = self.state.confirm.take() else {
            return;
        };
        if replace {
            self.state.ledger.allow(c.path);
            self.apply(ctx, c.again);
        } else {
            self.state.say(
                Level::Info,
                format!("{} kept: nothing written", c.path.display()),
            );
        }
    }

    /// A write ended: remembered with its output's stamp, or why not.
    fn on_written(&mut self, path: PathBuf, job: &Job, answer: WriteAnswer) {
        let WriteAnswer {
            what,
            from,
            outcome,
        } = answer;
        match outcome {
            Ok(line) => {
                if from == Artefact::Report {
                    let made = format!("report written: {}", path.display());
                    self.state.ledger.record(from, job.stamp.clone(), made);
                }
                self.state
                    .ledger
                    .wrote(&what, path.clone(), from, job.stamp.clone());
                let line = line.unwrap_or_else(|| format!("wrote {what} to {}", path.display()));
                self.state.say(Level::Info, line);
            }
            Err(e) => {
                let status = format!("{what} not written");
                self.refuse(&format!("Could not write {what}"), &status, e.to_string());
                self.state.say(Level::Error, status);
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

    /// Says in the status line that something was not done, and why in a
    /// notice titled `title`.
    fn refuse(&mut self, title: &str, status: &str, why: String) {
        self.state.say(Level::Warning, status);
        self.state.notice = Some(Notice {
            title: title.to_string(),
            body: why,
        });
    }
}
