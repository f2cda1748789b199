//! The import wizard's job work: the joint log's header, the mapping
//! guessed from it and the first rows mapped; the import itself (the
//! engine's [`import_with`](crate::engine::files::import::import_with) or [`assemble::import_poses_with`], as
//! `spherecal import`), analysed like an opened file.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use crate::engine::assemble;
use crate::engine::assemble::{ImportRequest, PoseLog};
use crate::engine::calibrate::solve::Control;
use crate::engine::files::import::{ImportError, ImportStage};

use super::form::{ImportForm, LogKind, PREVIEW_ROWS};
use crate::app::error::JobError;
use crate::app::session::{LoadedSession, Source, analyse};

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
        let why = JobError::ImportForm("choose the joint log CSV first".into());
        return (Vec::new(), None, Err(why));
    }
    let joint_log = PathBuf::from(form.joints.trim());
    let (header, preview) = assemble::preview_joint_log(&joint_log, PREVIEW_ROWS, |header| {
        if guess {
            form.guess_mapping(header);
        }
        form.spec().map_err(JobError::ImportForm)
    });
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
    let (log, path) = match form.log_kind {
        LogKind::Joints => {
            let spec = form.spec().map_err(JobError::ImportForm)?;
            let path = spec.joint_log.clone();
            (PoseLog::Joints(spec), path)
        }
        LogKind::FlangePoses => {
            let mut spec = form.pose_spec().map_err(JobError::ImportForm)?;
            if spec.hand_eye.is_none() {
                spec.hand_eye = form.hand_eye_guess().map_err(JobError::ImportForm)?;
            }
            let path = spec.poses.clone();
            (PoseLog::Poses(spec), path)
        }
    };
    let range = form
        .range
        .map(|v| crate::app::widgets::range_of(&v))
        .transpose()
        .map_err(|why| JobError::ImportForm(format!("measuring range: {why}")))?;
    let imported = assemble::import_session(&ImportRequest { log, range }, &mut stage)?;
    if cancel.load(Ordering::Relaxed) {
        return Err(ImportError::Cancelled.into());
    }
    progress("fitting the stripes".to_string(), None);
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
        loaded: Box::new(analyse(session, Source::Imported(path))),
        checks: imported.checks,
        notes,
    })
}
