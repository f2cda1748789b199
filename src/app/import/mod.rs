//! The import wizard: a pose log (a joint log CSV, or a pose file in any
//! layout the engine reads) and stripe profiles or the sensor's centres,
//! or a fixed sensor's points or profiles, into a session, as `spherecal
//! import` does. The form ([`form`]: the engine's import choices), the
//! pose file read and paired before the import (made again whenever what
//! it reads changes), the joint log's preview and guessed mapping, the
//! import with progress and Cancel ([`job`]); the Import view ([`ui`],
//! [`poses_ui`]).

pub mod form;
pub mod job;
pub mod poses_ui;
pub mod ui;

use crate::engine::assemble;
use crate::engine::assemble::PosePreview;
use crate::engine::files::import::{ImportError, PoseCheck};

use super::command::{ImportCommand, Tab};
use super::error::JobError;
use super::job::{Job, Slot};
use super::ledger::{Artefact, Reading};
use super::state::Level;
use super::{Core, Forms};
use job::{Imported, Previewed, import_preview, import_session};

/// What the wizard shows besides its form.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ImportView {
    /// The joint log's header, once read.
    pub header: Vec<String>,
    /// The preview text (mapped rows), or why it failed.
    pub preview: Option<Result<String, String>>,
    /// The flange-pose checks of the last import.
    pub checks: Vec<PoseCheck>,
    /// The last import's outcome in one line, or its error.
    pub outcome: Option<Result<String, String>>,
    /// The pose file's preview (layout, pairing, eq. 6-9 group) of the
    /// latest scan, or why the pose file cannot be read.
    pub pose_preview: Option<Result<PosePreview, String>>,
    /// The last import found no initial hand-eye: why (a guess is needed).
    pub guess_needed: Option<String>,
}

impl Core {
    /// Handles an [`ImportCommand`].
    pub(super) fn import(&mut self, ctx: &egui::Context, command: ImportCommand) {
        match command {
            ImportCommand::Preview { guess } => self.import_preview(ctx, guess),
            ImportCommand::Run => self.import_run(ctx),
            ImportCommand::Cancel => {
                if self.state.jobs.cancel(&Slot::Import).is_some() {
                    self.state.say(
                        Level::Warning,
                        "import cancelled: nothing was opened, what is open stays",
                    );
                }
            }
            ImportCommand::Scan => self.import_scan(ctx),
        }
    }

    /// Starts a preview job (also after the joint log was chosen in a
    /// dialog).
    pub(super) fn import_preview(&mut self, ctx: &egui::Context, guess: bool) {
        let form = self.forms.import.clone();
        let stamp = self.state.ledger.stamp(Artefact::ImportView);
        self.start(ctx, Slot::ImportPreview, stamp, move |_| {
            import_preview(form, guess)
        });
    }

    /// The preview's answer: the header, the guessed mapping, the rows.
    pub(super) fn on_previewed(
        &mut self,
        ctx: &egui::Context,
        job: &Job,
        (header, guessed, preview): Previewed,
    ) {
        let mut stamp = job.stamp.clone();
        if let Some(columns) = guessed {
            self.forms.import.columns = columns;
            // Previewed with the mapping guessed: made from the form as
            // it reads now.
            self.observe(ctx);
            stamp = self.state.ledger.stamp(Artefact::ImportView);
        }
        let what = "the import preview";
        self.state.ledger.record(Artefact::ImportView, stamp, what);
        self.state.import.header = header;
        match &preview {
            Ok(_) => self
                .state
                .say(Level::Info, "preview of the mapped rows below"),
            Err(e) => self.state.say(Level::Warning, format!("preview: {e}")),
        }
        self.state.import.preview = Some(preview.map_err(|e| e.to_string()));
    }

    /// Starts the import (the form's choices are checked by the engine
    /// on the job: a missing file is the import's failure, said).
    fn import_run(&mut self, ctx: &egui::Context) {
        let form = self.forms.import.clone();
        let stamp = self.state.ledger.stamp(Artefact::ImportView);
        self.state.say(Level::Info, "importing…");
        self.start(ctx, Slot::Import, stamp, move |w| import_session(&form, w));
    }

    /// Shows an import's outcome: the session opened, or why not.
    pub(super) fn on_imported(
        &mut self,
        ctx: &egui::Context,
        job: &Job,
        outcome: Result<Imported, JobError>,
    ) {
        let (stamp, what) = (job.stamp.clone(), "the import's outcome");
        self.state.ledger.record(Artefact::ImportView, stamp, what);
        match outcome {
            Ok(imported) => {
                let (checks, s) = (&imported.checks, &imported.loaded.session);
                let flagged = checks.iter().filter(|c| c.flagged).count();
                let (n, refs) = (s.measurements.len(), s.reference_distances.len());
                let mut line = format!("imported {n} measurements and {refs} reference distances");
                if !checks.is_empty() {
                    let checked = checks.len();
                    line += &format!("; flange poses: {checked} checked, {flagged} flagged");
                }
                let outcome = [&[line.clone()], &imported.notes[..]].concat().join("\n");
                self.state.import.checks = imported.checks;
                self.state.import.outcome = Some(Ok(outcome));
                self.state.import.guess_needed = None;
                self.on_session(ctx, *imported.loaded);
                let (tab, level) = if flagged > 0 {
                    (Tab::Import, Level::Warning)
                } else {
                    (Tab::Session, Level::Info)
                };
                self.forms.tab = tab;
                self.state.say(
                    level,
                    format!("{line}: not saved yet, use Save as… on the Session view"),
                );
            }
            Err(e) => {
                self.state.say(Level::Error, "the import failed");
                self.state.import.guess_needed = match &e {
                    JobError::Import(ImportError::NoInitialHandEye { message, .. }) => {
                        Some(message.clone())
                    }
                    _ => None,
                };
                self.state.import.checks.clear();
                self.state.import.outcome = Some(Err(e.to_string()));
            }
        }
    }
}

impl Core {
    /// Starts a scan of the form's pose file (or forgets the last one
    /// when there is nothing to scan).
    pub(super) fn import_scan(&mut self, ctx: &egui::Context) {
        let stamp = self.state.ledger.stamp(Artefact::PoseScan);
        let view = &mut self.state.import;
        let form = &self.forms.import;
        let spec = match (form.pose_spec(false), form.pose_scan_key()) {
            (Ok(spec), Some(_)) => spec,
            (spec, _) => {
                // Nothing to read: why, or nothing at all.
                view.pose_preview = match spec {
                    Err(why) if !form.poses.as_os_str().is_empty() => Some(Err(why.to_string())),
                    _ => None,
                };
                self.state.jobs.cancel(&Slot::PoseScan);
                self.state
                    .ledger
                    .record(Artefact::PoseScan, stamp, "nothing");
                return;
            }
        };
        self.start(ctx, Slot::PoseScan, stamp, move |_| {
            assemble::preview_pose_import(&spec)
                .map(Box::new)
                .map_err(JobError::from)
        });
    }

    /// The latest scan's answer.
    pub(super) fn on_import_scanned(
        &mut self,
        job: &Job,
        outcome: Result<Box<PosePreview>, JobError>,
    ) {
        let (stamp, what) = (job.stamp.clone(), "the pose file's preview");
        self.state.ledger.record(Artefact::PoseScan, stamp, what);
        self.state.import.pose_preview = Some(outcome.map(|p| *p).map_err(|e| e.to_string()));
    }
}

/// The readings of the import form (all of it) and of what the pose
/// file's preview reads of it.
pub(super) fn readings(forms: &Forms) -> [(super::ledger::Input, Reading); 2] {
    use super::ledger::Input;
    [
        (
            Input::ImportForm,
            Reading::new(Vec::new(), format!("{:?}", forms.import)),
        ),
        (
            Input::PoseFile,
            Reading::new(Vec::new(), format!("{:?}", forms.import.pose_scan_key())),
        ),
    ]
}
