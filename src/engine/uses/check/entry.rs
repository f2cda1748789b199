//! The re-check in one entry, [`check_file`], that the command line and
//! the workbench both call: the check session read (a session as it is,
//! or a session file) and checked against a result ([`check_session`]),
//! with its progress and a way to stop; the verdict in words
//! ([`verdict_lines`]); the check's record ([`check_record`]) that
//! `history` lists; and what a planned check detects, in words
//! ([`detectable_lines`]).

use std::path::PathBuf;

use super::{CheckError, Checked, check_session, moved_words};
use crate::engine::base::session::Session;
use crate::engine::calibrate::solve::Control;
use crate::engine::calibrate::solve::ml::recheck::Detectable;
use crate::engine::files::format::{self, CheckCentre, CheckRecord, ResultFile};
use crate::engine::tools::history::Timestamp;
use crate::engine::tools::plan::Plan;

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
/// with the verdict. `progress` hears of each step (what, fraction done);
/// [`Control::Cancel`] stops before the next.
///
/// # Errors
/// A session that cannot be read (naming the file), what
/// [`check_session`] refuses, or [`CheckError::Cancelled`].
pub fn check_file(
    request: CheckRequest,
    progress: &mut dyn FnMut(&str, f64) -> Control,
) -> Result<(Session, Checked), CheckError> {
    let mut step = |what: &str, done: f64| match progress(what, done) {
        Control::Cancel => Err(CheckError::Cancelled),
        Control::Continue => Ok(()),
    };
    step("reading the check's session", 0.0)?;
    let session = match request.scan {
        CheckSource::Session(s) => *s,
        CheckSource::SessionFile(path) => format::load_session(&path)?,
    };
    step(
        &format!(
            "fitting {} stripes and testing them against the calibration",
            session.measurements.len()
        ),
        0.3,
    )?;
    let checked = check_session(&session, &request.result, request.alpha)?;
    step("checked", 1.0)?;
    Ok((session, checked))
}

/// The verdict's lines at false-alarm rate `alpha`: what was predicted
/// through what, each fitted sphere position, both tests' statistics, and
/// what a check cannot see.
#[must_use]
pub fn verdict_lines(checked: &Checked, alpha: f64) -> Vec<String> {
    let t = &checked.test;
    let mut out = Vec::new();
    let what = if checked.hand_eye_only {
        "the hand-eye (flange poses)"
    } else {
        "the calibrated model and hand-eye"
    };
    out.push(format!(
        "{} sightings at {} station(s) predicted through {what}: {:.4} mm rms about the fitted sphere",
        checked.sightings,
        t.centres.len(),
        t.rms_mm
    ));
    for (id, c) in &t.centres {
        out.push(format!(
            "  sphere at {id}: {:.3}, {:.3}, {:.3} mm (fitted: it may have been moved)",
            c.x, c.y, c.z
        ));
    }
    out.push(format!(
        "test: T = {:.2} on {} degrees of freedom, threshold {:.2}; directed T_d = {:.2} on {}, threshold {:.2}; at a false-alarm rate α = {} ({:.2} %, α/2 each); p = {:.3e}",
        t.statistic,
        t.dof,
        t.threshold,
        t.directed,
        t.directed_dof,
        t.directed_threshold,
        alpha,
        100.0 * alpha,
        t.p_value
    ));
    out.push(
        "  a drift of the whole robot's base moves every centre alike: it cannot be told from a moved sphere (each position's sphere is fitted), and is not tested".into(),
    );
    out
}

/// Writes the record of a check ([`check_record`], dated now) to `path`
/// atomically; `files` are the check's session and the result as named
/// in the record.
///
/// # Errors
/// The file cannot be written (naming it).
pub fn write_record(
    path: &std::path::Path,
    checked: &Checked,
    session: &Session,
    result: &ResultFile,
    files: (&std::path::Path, &std::path::Path),
) -> Result<(), format::FileError> {
    let record = check_record(
        checked,
        session,
        result,
        files,
        std::time::SystemTime::now(),
    );
    format::save_check_record(path, &record)
}

/// What a planned check of `plan` (at `positions` sphere positions)
/// detects, `d` from [`plan_check`](super::plan_check): the operator's
/// time, the smallest knock of the sensor, the robot parameters best
/// seen, and what it cannot see.
#[must_use]
pub fn detectable_lines(plan: &Plan, positions: usize, d: &Detectable) -> Vec<String> {
    let mut out = vec![
        format!(
            "re-check: {} poses at {} sphere position(s), about {:.0} minutes at the robot ({:.0} s a pose, {:.0} s a sphere move)",
            plan.poses.len(),
            positions,
            super::check_minutes(plan.poses.len(), positions),
            super::design::SECONDS_PER_POSE,
            super::design::SECONDS_PER_SPHERE_MOVE
        ),
        format!(
            "re-check: detects with {:.0} % power at a false-alarm rate of {} % ({} degrees of freedom): the sensor knocked {:.3} mm in its worst direction, or turned {:.3}° about its mount's worst axis",
            100.0 * super::DETECTION_POWER,
            100.0 * super::DEFAULT_ALPHA,
            d.dof,
            d.translation_mm,
            d.rotation_deg
        ),
    ];
    let mut seen: Vec<(String, f64, f64)> = d
        .parameters
        .iter()
        .filter_map(|(l, v, s)| s.map(|s| (l.clone(), *v, s)))
        .collect();
    seen.sort_by(|a, b| a.2.total_cmp(&b.2));
    let listed: Vec<String> = seen
        .iter()
        .take(4)
        .map(|(l, v, s)| {
            let unit = if l.starts_with('a') && !l.starts_with("alpha") || l.starts_with('d') {
                "mm"
            } else {
                "°"
            };
            format!("{l} {v:.3} {unit} ({s:.1}σ)")
        })
        .collect();
    if !listed.is_empty() {
        out.push(format!(
            "robot parameters best seen from here (change detected, in σ of the calibration): {}",
            listed.join(", ")
        ));
    }
    out.push(
        "a drift of the robot's base cannot be told from a moved sphere (each position's sphere is fitted)".into(),
    );
    out
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
