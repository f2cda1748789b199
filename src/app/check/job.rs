//! The Re-check view's job work: the check poses planned by the engine's
//! `plan --check` entry
//! ([`choose_check_design`](crate::engine::uses::check::choose_check_design)),
//! a check session tested by the one entry `spherecal check` calls
//! ([`check_file`](crate::engine::uses::check::check_file)), the record
//! written by its writer; the views of them in the engine's words.

use std::path::{Path, PathBuf};

use crate::app::error::JobError;
use crate::app::job::Worker;
use crate::engine::base::session::Session;
use crate::engine::files::format::ResultFile;
use crate::engine::tools::plan::{Controller, Plan, PlanConfig, program_controller};
use crate::engine::uses::check::{self, CheckRequest, CheckSource, Checked, choose_check_design};

/// A check planned for the result on show.
#[derive(Debug, Clone)]
pub struct CheckPlanView {
    /// The poses (3 translations, 2 rotations, then the check's own).
    pub plan: Plan,
    /// What it detects and the operator's time, in the command line's words.
    pub lines: Vec<String>,
    /// The robot's key (the Plan form's), for the file names.
    pub robot: String,
    /// The controller whose program the Plan view writes for this robot.
    pub controller: Option<Controller>,
}

/// Plans the check poses for `result` about `config`'s sphere (module
/// doc).
///
/// # Errors
/// Why no check can be planned, in words.
pub fn plan_check_poses(
    mut config: PlanConfig,
    result: &ResultFile,
    robot: String,
) -> Result<CheckPlanView, String> {
    let choice = choose_check_design(&mut config, result, None).map_err(|e| e.to_string())?;
    let lines = check::detectable_lines(&choice.plan, choice.stations, &choice.detectable);
    let controller = program_controller(&choice.plan.robot.name);
    Ok(CheckPlanView {
        plan: choice.plan,
        lines,
        robot,
        controller,
    })
}

/// A check session tested against a result.
#[derive(Debug, Clone)]
pub struct CheckView {
    /// The check session's file.
    pub session_path: PathBuf,
    /// The session as read.
    pub session: Session,
    /// The result it was checked against.
    pub result: ResultFile,
    /// The false-alarm rate.
    pub alpha: f64,
    /// The test and the candidate changes.
    pub checked: Checked,
    /// The verdict in the command line's words (both tests, the sphere
    /// positions).
    pub lines: Vec<String>,
    /// What moved, when it fails.
    pub moved: Vec<String>,
}

impl CheckView {
    /// The verdict in a line: HOLDS or FAILS, with the statistic.
    #[must_use]
    pub fn headline(&self) -> String {
        let t = &self.checked.test;
        if t.holds {
            format!(
                "HOLDS: the cell still holds its calibration (T {:.2} ≤ {:.2}, T_d {:.2} ≤ {:.2}, α {})",
                t.statistic, t.threshold, t.directed, t.directed_threshold, self.alpha
            )
        } else {
            format!(
                "FAILS: the cell no longer holds its calibration (T {:.2} / {:.2}, T_d {:.2} / {:.2}, α {}): re-calibrate",
                t.statistic, t.threshold, t.directed, t.directed_threshold, self.alpha
            )
        }
    }
}

/// Tests the session file `path` against `result` at `alpha` by the
/// engine's entry, reporting its steps to `w` (Cancel stops it).
///
/// # Errors
/// The engine's message: a file that cannot be read, a check of another
/// cell, a result without `ml`'s covariance, cancelled.
pub fn check_session_file(
    path: PathBuf,
    result: ResultFile,
    alpha: f64,
    w: &Worker,
) -> Result<CheckView, String> {
    let request = CheckRequest {
        scan: CheckSource::SessionFile(path.clone()),
        result: result.clone(),
        alpha,
    };
    let (session, checked) = check::check_file(request, &mut |what, done| {
        crate::app::plan::job::report(w, what, Some(done))
    })
    .map_err(|e| e.to_string())?;
    let lines = check::verdict_lines(&checked, alpha);
    let moved = if checked.test.holds {
        Vec::new()
    } else {
        check::moved_words(&checked)
    };
    Ok(CheckView {
        session_path: path,
        session,
        result,
        alpha,
        checked,
        lines,
        moved,
    })
}

/// Writes the record of `view` to `path` by the engine's writer
/// (atomic); `result` is how the record names the result.
///
/// # Errors
/// The file cannot be written (naming it).
pub fn write_check_record(view: &CheckView, result: &Path, path: &Path) -> Result<(), JobError> {
    Ok(check::write_record(
        path,
        &view.checked,
        &view.session,
        &view.result,
        (&view.session_path, result),
    )?)
}
