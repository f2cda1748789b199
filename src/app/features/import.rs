//! The import wizard's work: read the joint log's header, guess the
//! column mapping, preview the mapped rows, and build the session with
//! the engine's [`import::import`] (as `spherecal import`), analysed like
//! an opened file.

use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use crate::engine::calibrate::solve::Control;
use crate::engine::files::import::{self, ImportError, ImportStage};

use super::Core;
use super::files::analyse;
use crate::app::commands::ImportCommand;
use crate::app::error::JobError;
use crate::app::forms::import::{LogKind, PREVIEW_ROWS};
use crate::app::forms::{ImportForm, Tab};
use crate::app::jobs::{ImportMessage, Imported, JobMessage};
use crate::app::state::{Level, Source};

/// The wizard's preview: the joint log's header (empty when it cannot be
/// read), the form with the mapping guessed from it (when `guess`), and
/// the first rows mapped.
pub fn import_preview(
    mut form: ImportForm,
    guess: bool,
) -> (
    Vec<String>,
    Option<Box<ImportForm>>,
    Result<String, JobError>,
) {
    if form.joints.trim().is_empty() {
        return (
            Vec::new(),
            None,
            Err(JobError::ImportForm(
                "choose the joint log CSV first".into(),
            )),
        );
    }
    let header = match import::header(Path::new(form.joints.trim())) {
        Ok(h) => h,
        Err(e) => return (Vec::new(), None, Err(e.into())),
    };
    if guess {
        form.guess_mapping(&header);
    }
    let preview = form
        .spec()
        .map_err(JobError::ImportForm)
        .and_then(|spec| Ok(import::preview(&spec, PREVIEW_ROWS)?));
    (header, guess.then(|| Box::new(form)), preview)
}

/// How often an import job tells the window its progress.
const PROGRESS_EVERY: Duration = Duration::from_millis(100);

/// Runs the import of the wizard's form (a joint log or a flange-pose
/// log) and analyses the session like an opened file, telling `progress`
/// its stage (profiles read, side, check, stripe fits) and stopping when
/// `cancel` is set.
///
/// # Errors
/// The form is incomplete or the engine's import failed (naming the file,
/// line, column or pose id); [`ImportError::Cancelled`].
pub fn import_session(
    form: &ImportForm,
    cancel: &AtomicBool,
    progress: &mut dyn FnMut(String),
) -> Result<Imported, JobError> {
    // Told at most every 0.1 s, and at every stage that is not a profile.
    let mut told: Option<Instant> = None;
    let mut stage = |s: ImportStage| {
        if cancel.load(Ordering::Relaxed) {
            return Control::Cancel;
        }
        let profile = matches!(s, ImportStage::Profiles { done, total } if done < total);
        if !profile || told.is_none_or(|t| t.elapsed() >= PROGRESS_EVERY) {
            told = Some(Instant::now());
            progress(s.describe());
        }
        Control::Continue
    };
    let (imported, log) = match form.log_kind {
        LogKind::Joints => {
            let spec = form.spec().map_err(JobError::ImportForm)?;
            (import::import_with(&spec, &mut stage)?, spec.joint_log)
        }
        LogKind::FlangePoses => {
            let mut spec = form.pose_spec().map_err(JobError::ImportForm)?;
            if spec.hand_eye.is_none() {
                spec.hand_eye = form.hand_eye_guess().map_err(JobError::ImportForm)?;
            }
            (import::import_poses_with(&spec, &mut stage)?, spec.poses)
        }
    };
    if cancel.load(Ordering::Relaxed) {
        return Err(ImportError::Cancelled.into());
    }
    progress("fitting the stripes".to_string());
    let mut session = imported.session;
    let mut notes = imported.notes;
    if form.log_kind == LogKind::FlangePoses
        && let Some(he) = &session.hand_eye
    {
        let t = he.translation.vector;
        let [roll, pitch, yaw] = crate::engine::base::geometry::roll_pitch_yaw_deg(&he.rotation);
        notes.push(format!(
            "initial hand-eye in the session: x {:.3}, y {:.3}, z {:.3} mm; roll {roll:.3}, pitch {pitch:.3}, yaw {yaw:.3} deg",
            t.x, t.y, t.z
        ));
    }
    if let Some(v) = form.range {
        session.sensor_range = Some(
            crate::app::panels::range_of(&v)
                .map_err(|why| JobError::ImportForm(format!("measuring range: {why}")))?,
        );
    }
    Ok(Imported {
        loaded: Box::new(analyse(session, Source::Imported(log))),
        checks: imported.checks,
        notes,
    })
}

impl Core {
    /// Handles an [`ImportCommand`].
    pub(super) fn import(&mut self, ctx: &egui::Context, command: ImportCommand) {
        match command {
            ImportCommand::Preview { guess } => self.import_preview(ctx, guess),
            ImportCommand::Run => self.import_run(ctx),
            ImportCommand::Cancel => self.import_cancel(),
            ImportCommand::Scan => self.import_scan(ctx),
            ImportCommand::Edited => {
                let view = &mut self.state.import;
                view.preview = None;
                view.outcome = None;
                view.checks.clear();
            }
        }
    }

    /// Starts a preview job (also after the joint log was chosen in a
    /// dialog).
    pub(super) fn import_preview(&mut self, ctx: &egui::Context, guess: bool) {
        let form = self.forms.import.clone();
        let started = self.spawn(ctx, "import", move |rep| {
            let (header, guessed, preview) = import_preview(form, guess);
            rep.send(JobMessage::Import(ImportMessage::Previewed {
                header,
                guessed,
                preview,
            }));
        });
        if started {
            self.state.busy.importing += 1;
        }
    }

    fn import_run(&mut self, ctx: &egui::Context) {
        let form = self.forms.import.clone();
        let ready = match form.log_kind {
            LogKind::Joints => form.spec().map(|_| ()),
            LogKind::FlangePoses => form.pose_spec().map(|_| ()),
        };
        if let Err(e) = ready {
            self.state.import.outcome = Some(Err(e.clone()));
            self.state.say(Level::Warning, e);
            return;
        }
        self.state.say(Level::Info, "importing…");
        let job = self.state.import_job.job + 1;
        let cancel = Arc::new(AtomicBool::new(false));
        let flag = Arc::clone(&cancel);
        let started = self.spawn(ctx, "import", move |rep| {
            let outcome = import_session(&form, &flag, &mut |text| {
                rep.send(JobMessage::Import(ImportMessage::Progress { job, text }));
            });
            rep.send(JobMessage::Import(ImportMessage::Imported { job, outcome }));
        });
        if started {
            let run = &mut self.state.import_job;
            run.job = job;
            run.cancel = Some(cancel);
            run.progress = Some("starting".to_string());
        }
    }

    /// Stops the import in flight: its answer, if it comes, is dropped and
    /// what is open stays.
    fn import_cancel(&mut self) {
        let run = &mut self.state.import_job;
        if let Some(c) = run.cancel.take() {
            c.store(true, Ordering::Relaxed);
            run.progress = None;
            self.state.say(
                Level::Warning,
                "import cancelled: nothing was opened, what is open stays",
            );
        }
    }

    /// Handles an [`ImportMessage`].
    pub(super) fn on_import(&mut self, ctx: &egui::Context, message: ImportMessage) {
        match message {
            ImportMessage::Progress { job, text } => {
                let run = &mut self.state.import_job;
                if run.job == job && run.cancel.is_some() {
                    run.progress = Some(text);
                }
            }
            ImportMessage::Imported { job, outcome } => {
                let run = &mut self.state.import_job;
                // A cancelled job's answer is not shown.
                if run.job != job || run.cancel.is_none() {
                    return;
                }
                run.cancel = None;
                run.progress = None;
                self.on_imported(ctx, outcome);
            }
            ImportMessage::Scanned {
                generation,
                outcome,
            } => {
                self.state.busy.importing = self.state.busy.importing.saturating_sub(1);
                self.on_import_scanned(generation, outcome);
            }
            ImportMessage::Previewed {
                header,
                guessed,
                preview,
            } => {
                self.state.busy.importing = self.state.busy.importing.saturating_sub(1);
                if let Some(form) = guessed {
                    let f = &mut self.forms.import;
                    f.id_column = form.id_column;
                    f.station_column = form.station_column;
                    f.use_column = form.use_column;
                    f.side_column = form.side_column;
                    f.joint_columns = form.joint_columns;
                }
                self.state.import.header = header;
                match &preview {
                    Ok(_) => self
                        .state
                        .say(Level::Info, "preview of the mapped rows below"),
                    Err(e) => self.state.say(Level::Warning, format!("preview: {e}")),
                }
                self.state.import.preview = Some(preview.map_err(|e| e.to_string()));
            }
        }
    }

    /// Shows an import's outcome: the session opened, or why not.
    fn on_imported(&mut self, ctx: &egui::Context, outcome: Result<Imported, JobError>) {
        match outcome {
            Ok(imported) => {
                let flagged = imported.checks.iter().filter(|c| c.flagged).count();
                let n = imported.loaded.session.measurements.len();
                let refs = imported.loaded.session.reference_distances.len();
                let mut line = format!("imported {n} measurements and {refs} reference distances");
                if !imported.checks.is_empty() {
                    line.push_str(&format!(
                        "; flange poses: {} checked, {flagged} flagged",
                        imported.checks.len()
                    ));
                }
                let mut outcome = line.clone();
                for note in &imported.notes {
                    outcome.push_str(&format!("\n{note}"));
                }
                self.state.import.checks = imported.checks;
                self.state.import.outcome = Some(Ok(outcome));
                self.state.import.guess_needed = None;
                self.on_session(ctx, *imported.loaded);
                self.forms.tab = if flagged > 0 {
                    Tab::Import
                } else {
                    Tab::Session
                };
                let level = if flagged > 0 {
                    Level::Warning
                } else {
                    Level::Info
                };
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
