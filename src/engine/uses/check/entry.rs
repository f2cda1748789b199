//! The re-check in one entry, [`check_file`], that the command line
//! calls: the check session read (a session as it is, or a session
//! file) and checked against a result ([`check_session`]); and the
//! check's record ([`check_record`]) that `history` lists.

use std::path::PathBuf;

use super::{CheckError, Checked, check_session, moved_words};
use crate::engine::base::session::Session;
use crate::engine::files::format::{self, CheckCentre, CheckRecord, ResultFile};
use crate::engine::tools::history::Timestamp;

/// The check's scan.
#[derive(Debug, Clone)]
pub enum CheckSource {
    /// A session as it is.
    Session(Box<Session>),
    /// A session file.
    SessionFile(PathBuf),
}

/// Everything a check needs.
#[derive(Debug, Clone)]
pub struct CheckRequest {
    /// The check's scan.
    pub scan: CheckSource,
    /// The result it is checked against.
    pub result: ResultFile,
    /// The false-alarm rate.
    pub alpha: f64,
}

/// Reads the request's session and checks it (module doc); the session
/// with the verdict.
///
/// # Errors
/// A session that cannot be read (naming the file), or what
/// [`check_session`] refuses.
pub fn check_file(request: CheckRequest) -> Result<(Session, Checked), CheckError> {
    let session = match request.scan {
        CheckSource::Session(s) => *s,
        CheckSource::SessionFile(path) => format::load_session(&path)?,
    };
    let checked = check_session(&session, &request.result, request.alpha)?;
    Ok((session, checked))
}

/// The record of a check (formats.md, `spherecal-check`), dated `now`.
#[must_use]
pub fn check_record(
    checked: &Checked,
    session: &Session,
    result: &ResultFile,
    files: (&std::path::Path, &std::path::Path),
    now: std::time::SystemTime,
) -> CheckRecord {
    let t = &checked.test;
    let date = Timestamp::from_system_time(now).map_or_else(String::new, |d| {
        format!(
            "{:04}-{:02}-{:02}T{:02}:{:02}:{:02}Z",
            d.year, d.month, d.day, d.hour, d.minute, d.second
        )
    });
    CheckRecord {
        format: format::CHECK_FORMAT.into(),
        version: format::FORMAT_VERSION,
        date,
        robot: result.robot_name().to_string(),
        session: session.name.clone(),
        session_file: files.0.display().to_string(),
        result_file: files.1.display().to_string(),
        result_session: result.session.clone(),
        alpha: t.alpha,
        holds: t.holds,
        hand_eye_only: checked.hand_eye_only,
        sightings: checked.sightings,
        statistic: t.statistic,
        dof: t.dof,
        threshold: t.threshold,
        directed: t.directed,
        directed_dof: t.directed_dof,
        directed_threshold: t
            .directed_threshold
            .is_finite()
            .then_some(t.directed_threshold),
        rms_mm: t.rms_mm,
        moved: (!t.holds).then(|| moved_words(checked).join("; ")),
        centres: t
            .centres
            .iter()
            .map(|(id, c)| CheckCentre {
                station: id.clone(),
                centre: [c.x, c.y, c.z],
            })
            .collect(),
    }
}
