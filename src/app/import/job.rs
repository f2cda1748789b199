//! The import wizard's job work: the joint log's header, the mapping
//! guessed from it and the first rows mapped; the import itself (the
//! engine's one entry, [`assemble::import_session`], with the request the
//! form's [`ImportChoices`] builds, as `spherecal import`), analysed like
//! an opened file.

use std::time::{Duration, Instant};

use crate::app::error::JobError;
use crate::app::job::Worker;
use crate::app::session::{LoadedSession, Source, analyse};
use crate::engine::assemble::{self, ImportChoices, LogKind};
use crate::engine::calibrate::solve::Control;
use crate::engine::files::import::{ColumnMap, ImportError, ImportStage, PoseCheck};

use super::form::PREVIEW_ROWS;

/// What a preview job answers: the joint log's header (empty when it
/// cannot be read), the mapping guessed from it (when asked), and the
/// mapped rows or why not.
pub type Previewed = (Vec<String>, Option<ColumnMap>, Result<String, JobError>);

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

/// The wizard's preview: the joint log's header, the mapping guessed
/// from it (when `guess`), and the first rows mapped.
pub fn import_preview(mut form: ImportChoices, guess: bool) -> Previewed {
    if form.joints.as_os_str().is_empty() {
        // Nothing to read: the engine's sentence why.
        let why = form
            .joint_spec()
            .map(|_| String::new())
            .map_err(JobError::from);
        return (Vec::new(), None, why);
    }
    let log = form.joints.clone();
    let (header, preview) = assemble::preview_joint_log(&log, PREVIEW_ROWS, |header| {
        if guess {
            form.guess_mapping(header);
        }
        form.joint_spec().map_err(JobError::from)
    });
    (header, guess.then_some(form.columns), preview)
}

/// How often an import job tells the window its progress.
const PROGRESS_EVERY: Duration = Duration::from_millis(100);

/// Runs the import the form chose and analyses the session like an
/// opened file, telling the job its stage (profiles read, side, check,
/// stripe fits) and stopping when it is cancelled.
///
/// # Errors
/// The form is incomplete or the engine's import failed (naming the file,
/// line, column or pose id); [`ImportError::Cancelled`].
pub fn import_session(form: &ImportChoices, job: &Worker) -> Result<Imported, JobError> {
    // Told at most every 0.1 s, and at every stage that is not a profile.
    let mut told: Option<Instant> = None;
    let mut stage = |s: ImportStage| {
        if job.cancelled() {
            return Control::Cancel;
        }
        let profile = matches!(s, ImportStage::Profiles { done, total } if done < total);
        if !profile || told.is_none_or(|t| t.elapsed() >= PROGRESS_EVERY) {
            told = Some(Instant::now());
            let fraction = match s {
                ImportStage::Profiles { done, total } => Some(done as f64 / total.max(1) as f64),
                _ => None,
            };
            job.progress(s.describe(), fraction);
        }
        Control::Continue
    };
    let imported = assemble::import_session(&form.request()?, &mut stage)?;
    if job.cancelled() {
        return Err(ImportError::Cancelled.into());
    }
    job.progress("fitting the stripes", None);
    let session = imported.session;
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
    Ok(Imported {
        loaded: Box::new(analyse(session, Source::Imported(form.log().to_path_buf()))),
        checks: imported.checks,
        notes,
    })
}
