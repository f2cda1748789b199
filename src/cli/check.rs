//! `spherecal check`: the five-minute re-check. A short scan of the
//! sphere (planned by `plan --check`, imported like any session) tested
//! against a result's covariance and noise model: the verdict at the
//! false-alarm rate α, exit 0 when the cell still holds its calibration
//! and 3 when it does not, with what moved. A thin caller of
//! [`crate::engine::uses::check`].

use std::path::PathBuf;

use clap::Args;

use super::values::{Range, number};
use super::{CliError, QUIET_HELP};
use crate::engine::calibrate::solve::Control;
use crate::engine::files::format;
use crate::engine::uses::check::{self, CheckError, CheckRequest, CheckSource, DEFAULT_ALPHA};

/// The exit status of a check that fails: the cell no longer holds its
/// calibration (not an error of the input).
pub const CHECK_FAILED_STATUS: i32 = 3;

/// `spherecal check`.
#[derive(Debug, Args)]
pub struct CheckArgs {
    /// The check's session: the poses of `plan --check` run at the robot, imported like any session.
    pub session: PathBuf,
    /// The result the cell was calibrated to (an `ml` result: its covariance and noise model).
    #[arg(long)]
    pub result: PathBuf,
    /// The false-alarm rate: the share of checks of an unchanged cell that fail.
    #[arg(long, default_value_t = DEFAULT_ALPHA, value_parser = number(Range::positive("").at_most(0.2)))]
    pub alpha: f64,
    /// Where the check's record goes (`history` lists it) [default: X.check.json beside the session X.json].
    #[arg(long, value_name = "FILE", conflicts_with = "no_record")]
    pub record: Option<PathBuf>,
    /// Write no record of the check.
    #[arg(long)]
    pub no_record: bool,
    /// `-q`: [`QUIET_HELP`](super::QUIET_HELP).
    #[arg(long, short, help = QUIET_HELP)]
    pub quiet: bool,
}

fn error(e: &CheckError) -> CliError {
    CliError::input(e.to_string())
}

/// Runs `spherecal check`.
///
/// # Errors
/// [`CliError`] with status 2 for a file that cannot be read or a check
/// of another cell, and status [`CHECK_FAILED_STATUS`] when the cell no
/// longer holds its calibration.
pub fn run(args: &CheckArgs) -> Result<(), CliError> {
    let result = format::load_result(&args.result).map_err(|e| CliError::input(e.to_string()))?;
    let record_path = (!args.no_record).then(|| {
        args.record
            .clone()
            .unwrap_or_else(|| format::check_record_path(&args.session))
    });
    if let Some(path) = &record_path {
        CliError::guard_output(path, &[args.session.as_path(), args.result.as_path()])?;
    }
    let (session, checked) = check::check_file(
        CheckRequest {
            scan: CheckSource::SessionFile(args.session.clone()),
            result: result.clone(),
            alpha: args.alpha,
        },
        &mut |_, _| Control::Continue,
    )
    .map_err(|e| error(&e))?;
    if !args.quiet {
        for note in &checked.notes {
            sayln!("note: {note}");
        }
        for s in &checked.skipped {
            sayln!("warning: left out: {s}");
        }
        for line in check::verdict_lines(&checked, args.alpha) {
            sayln!("{line}");
        }
    }
    if let Some(path) = &record_path {
        check::write_record(
            path,
            &checked,
            &session,
            &result,
            (&args.session, &args.result),
        )
        .map_err(|e| CliError::from_file(&e, false))?;
        if !args.quiet {
            sayln!("wrote the check's record {}", path.display());
        }
    }
    if checked.test.holds {
        if !args.quiet {
            sayln!("HOLDS: the cell still holds its calibration");
        }
        return Ok(());
    }
    let moved = check::moved_words(&checked);
    if !args.quiet {
        for line in &moved {
            sayln!("  {line}");
        }
    }
    Err(CliError {
        status: CHECK_FAILED_STATUS,
        message: format!(
            "the cell no longer holds its calibration (T {:.2} > {:.2}); {}: re-calibrate",
            checked.test.statistic,
            checked.test.threshold,
            moved.first().map_or("", String::as_str)
        ),
    })
}
