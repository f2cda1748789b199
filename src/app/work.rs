//! The work the jobs do, as plain functions of engine calls (no egui):
//! open a file, fit its stripes, run the calibration, save the session
//! without the left-out measurements. Each runs on a job thread.

use std::collections::BTreeSet;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use crate::engine::format::FileError;
use crate::engine::format::{
    RESULT_FORMAT, ResultFile, parse_result, parse_session, session_to_json, write_atomic,
};
use crate::engine::import;
use crate::engine::session::{ExcludeError, Session, exclude_measurements};
use crate::engine::solve::estimate::Estimate;
use crate::engine::solve::{self, Control, Options, Progress, SolveError, StopReason};

use super::jobs::{Imported, LoadFailure, RunFailure};
use super::state::{LoadedSession, Source};
use super::view::{CentrePoint, CentreSet, ResultOrigin, ResultView};
use super::wizard::{ImportForm, PREVIEW_ROWS};

/// What a file turned out to be.
#[derive(Debug)]
pub enum Opened {
    /// A session, analysed.
    Session(Box<LoadedSession>),
    /// A result file, checked.
    Result(Box<ResultFile>),
}

/// The embedded demo session, analysed.
///
/// # Errors
/// Only if the embedded text were broken (a build error in practice).
pub fn open_demo() -> Result<LoadedSession, LoadFailure> {
    let name = Path::new(crate::DEMO_SESSION_NAME);
    let session = parse_session(crate::DEMO_SESSION_JSON, name).map_err(|e| LoadFailure {
        what: crate::DEMO_SESSION_NAME.to_string(),
        message: e.to_string(),
    })?;
    let mut loaded = analyse(session, Source::Demo);
    loaded.bytes = crate::DEMO_SESSION_JSON.as_bytes().to_vec();
    Ok(loaded)
}

/// Reads `path` and, by its `format` key, loads it as a result file or
/// as a session (anything else goes to the session loader, whose message
/// then says what is wrong).
///
/// # Errors
/// The file cannot be read or breaks a FORMAT.md rule; the message names
/// the file and, where it applies, the measurement.
pub fn open_path(path: &Path) -> Result<Opened, LoadFailure> {
    let fail = |e: &FileError| LoadFailure {
        what: path.display().to_string(),
        message: e.to_string(),
    };
    let text = std::fs::read_to_string(path).map_err(|source| {
        fail(&FileError::Io {
            action: "reading",
            path: path.to_path_buf(),
            source,
        })
    })?;
    let is_result = serde_json::from_str::<serde_json::Value>(&text)
        .ok()
        .and_then(|v| {
            v.get("format")
                .and_then(|f| f.as_str())
                .map(|f| f == RESULT_FORMAT)
        })
        .unwrap_or(false);
    if is_result {
        let result = parse_result(&text, path).map_err(|e| fail(&e))?;
        Ok(Opened::Result(Box::new(result)))
    } else {
        let session = parse_session(&text, path).map_err(|e| fail(&e))?;
        let mut loaded = analyse(session, Source::File(path.to_path_buf()));
        loaded.bytes = text.into_bytes();
        Ok(Opened::Session(Box::new(loaded)))
    }
}

/// Fits every stripe once (for the table, the stripe view and later runs)
/// and computes the centres before calibration (nominal model, initial
/// hand-eye).
#[must_use]
pub fn analyse(session: Session, source: Source) -> LoadedSession {
    let analysis = solve::analyse(&session);
    let before = analysis
        .clone()
        .prepared(&session)
        .map(|prepared| {
            let start = Estimate {
                robot: session.robot.clone(),
                flange_from_sensor: prepared.hand_eye_initial,
            };
            let points = session
                .measurements
                .iter()
                .enumerate()
                .map(|(i, m)| CentrePoint {
                    id: m.id.clone(),
                    station: m.station.clone(),
                    usage: m.usage.as_str().to_string(),
                    index: Some(i),
                    before: start.centre_in_base(&prepared.sighting(&session, i)).into(),
                    after: None,
                })
                .collect();
            CentreSet::new(points)
        })
        .map_err(|e| e.to_string());
    LoadedSession {
        bytes: session_to_json(&session).into_bytes(),
        session,
        source,
        analysis,
        before,
    }
}

/// The session without the `excluded` measurements, checked against every
/// FORMAT.md rule the removal can break, with the indices (into the
/// loaded session) of the measurements it keeps. The name is kept.
///
/// # Errors
/// Leaving these measurements out breaks a rule: the engine's message.
pub fn without(
    session: &Session,
    excluded: &BTreeSet<String>,
) -> Result<(Session, Vec<usize>), ExcludeError> {
    let ids: Vec<String> = excluded.iter().cloned().collect();
    let kept = if ids.is_empty() {
        session.clone()
    } else {
        exclude_measurements(session, &ids)?
    };
    let indices = session
        .measurements
        .iter()
        .enumerate()
        .filter(|(_, m)| !excluded.contains(&m.id))
        .map(|(i, _)| i)
        .collect();
    Ok((kept, indices))
}

/// Writes the session without the `excluded` measurements to `path`
/// (atomically). Returns how many measurements the file holds.
///
/// # Errors
/// The edited session breaks a rule, or the file cannot be written.
pub fn save_without(
    session: &Session,
    excluded: &BTreeSet<String>,
    path: &Path,
) -> Result<usize, String> {
    let (kept, _) = without(session, excluded).map_err(|e| {
        format!("not saved: the session without the left-out measurements is not valid: {e}")
    })?;
    write_atomic(path, session_to_json(&kept).as_bytes()).map_err(|e| e.to_string())?;
    Ok(kept.measurements.len())
}

/// The whole calibration of the loaded session without the `excluded`
/// measurements: the stripes fitted when it was loaded (none is fitted
/// again), the run (reporting every ε, stopping when `cancel` is set),
/// and the result and its view.
///
/// # Errors
/// [`RunFailure::Cancelled`] after a cancel, [`RunFailure::Failed`] with
/// the engine's message otherwise.
pub fn calibrate_session(
    loaded: &LoadedSession,
    excluded: &BTreeSet<String>,
    options: &Options,
    cancel: &AtomicBool,
    on_progress: &mut dyn FnMut(&Progress) -> bool,
) -> Result<ResultView, RunFailure> {
    let started = Instant::now();
    let (kept, indices) = without(&loaded.session, excluded).map_err(|e| {
        RunFailure::Failed(format!(
            "the session without the left-out measurements is not valid: {e}"
        ))
    })?;
    let analysis = if excluded.is_empty() {
        loaded.analysis.clone()
    } else {
        loaded.analysis.subset(&kept, &indices)
    };
    let failed = |e: SolveError| RunFailure::Failed(e.to_string());
    let prepared = analysis.prepared(&kept).map_err(failed)?;
    let cal = solve::run(&kept, &prepared, options, &mut |p| {
        let delivered = on_progress(p);
        if cancel.load(Ordering::Relaxed) || !delivered {
            Control::Cancel
        } else {
            Control::Continue
        }
    })
    .map_err(failed)?;
    if let StopReason::Cancelled { updates, .. } = cal.stop {
        return Err(RunFailure::Cancelled(updates));
    }
    let file = ResultFile::from_calibration(&kept, &cal);
    let origin = ResultOrigin::Run {
        seconds: started.elapsed().as_secs_f64(),
        excluded: loaded.session.measurements.len() - kept.measurements.len(),
    };
    Ok(ResultView::new(file, origin, Some(&loaded.session)))
}

/// The import wizard's preview: the joint log's header, the form with the
/// mapping guessed from it (when `guess`), and the first rows mapped.
pub fn import_preview(
    mut form: ImportForm,
    guess: bool,
) -> (Vec<String>, Option<Box<ImportForm>>, Result<String, String>) {
    if form.joints.trim().is_empty() {
        return (
            Vec::new(),
            None,
            Err("choose the joint log CSV first".into()),
        );
    }
    let header = match import::header(Path::new(form.joints.trim())) {
        Ok(h) => h,
        Err(e) => return (Vec::new(), None, Err(e.to_string())),
    };
    if guess {
        form.guess_mapping(&header);
    }
    let preview = form
        .spec()
        .and_then(|spec| import::preview(&spec, PREVIEW_ROWS).map_err(|e| e.to_string()));
    (header, guess.then(|| Box::new(form)), preview)
}

/// Runs the import of the wizard's form and analyses the session like an
/// opened file.
///
/// # Errors
/// The form is incomplete or the engine's import failed: its message,
/// naming the file, line, column or pose id.
pub fn import_session(form: &ImportForm) -> Result<Imported, String> {
    let spec = form.spec()?;
    let (session, checks) = import::import(&spec).map_err(|e| e.to_string())?;
    Ok(Imported {
        loaded: Box::new(analyse(session, Source::Imported(spec.joint_log))),
        checks,
    })
}
