//! The import wizard's work: read the joint log's header, guess the
//! column mapping, preview the mapped rows, and build the session with
//! the engine's [`import::import`] (as `spherecal import`), analysed like
//! an opened file.

use std::path::Path;
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
use crate::app::job::{Job, Slot};
use crate::app::ledger::Artefact;
use crate::app::state::{Level, LoadedSession, Source};

/// What a preview job answers: the joint log's header (empty when it
/// cannot be read), the form with the guessed mapping (when asked), and
/// the mapped rows or why not.
pub type Previewed = (
    Vec<String>,
    Option<Box<ImportForm>>,
    Result<String, JobError>,
);

/// The outcome of an import job.
#[derive(Debug)]
pub struct Imported {
    /// The session, analysed like an opened file.
    pub loaded: Box<LoadedSession>,
    /// The flange-pose checks (empty without a check).
    pub checks: Vec<crate::engine::files::import::PoseCheck>,
    /// What the import decided, in words (axis map, side, initial
    /// hand-eye).
    pub notes: Vec<String>,
}

/// The wizard's preview: the joint log's header (empty when it cannot be
/// read), the form with the mapping guessed from it (when `guess`), and
/// the first rows mapped.
pub fn import_preview(mut form: ImportForm, guess: bool) -> Previewed {
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
    progress: &mut dyn FnMut(String, Option<f64>),
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
            let fraction = match s {
                ImportStage::Profiles { done, total } => Some(done as f64 / total.max(1) as f64),
                _ => None,
            };
            progress(s.describe(), fraction);
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
    progress("fitting the stripes".to_string(), None);
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
        if let Some(form) = guessed {
            let f = &mut self.forms.import;
            f.id_column = form.id_column;
            f.station_column = form.station_column;
            f.use_column = form.use_column;
            f.side_column = form.side_column;
            f.joint_columns = form.joint_columns;
            // Previewed with the mapping guessed: made from the form as
            // it reads now.
            self.observe(ctx);
            stamp = self.state.ledger.stamp(Artefact::ImportView);
        }
        self.state
            .ledger
            .record(Artefact::ImportView, stamp, "the import preview");
        self.state.import.header = header;
        match &preview {
            Ok(_) => self
                .state
                .say(Level::Info, "preview of the mapped rows below"),
            Err(e) => self.state.say(Level::Warning, format!("preview: {e}")),
        }
        self.state.import.preview = Some(preview.map_err(|e| e.to_string()));
    }

    fn import_run(&mut self, ctx: &egui::Context) {
        let form = self.forms.import.clone();
        let ready = match form.log_kind {
            LogKind::Joints => form.spec().map(|_| ()),
            LogKind::FlangePoses => form.pose_spec().map(|_| ()),
        };
        let stamp = self.state.ledger.stamp(Artefact::ImportView);
        if let Err(e) = ready {
            self.state.import.outcome = Some(Err(e.clone()));
            self.state
                .ledger
                .record(Artefact::ImportView, stamp, "why not");
            self.state.say(Level::Warning, e);
            return;
        }
        self.state.say(Level::Info, "importing…");
        self.start(ctx, Slot::Import, stamp, move |w| {
            import_session(&form, w.flag(), &mut |text, fraction| {
                w.progress(text, fraction);
            })
        });
    }

    /// Shows an import's outcome: the session opened, or why not.
    pub(super) fn on_imported(
        &mut self,
        ctx: &egui::Context,
        job: &Job,
        outcome: Result<Imported, JobError>,
    ) {
        let what = "the import's outcome";
        self.state
            .ledger
            .record(Artefact::ImportView, job.stamp.clone(), what);
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
