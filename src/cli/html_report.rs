//! `spherecal report`: the self-contained HTML report of a calibration
//! ([`crate::engine::tools::report::html`]). The module is `html_report` because
//! `cli` already imports the engine's result-file module as `report`.
//! Without `--result` the session is calibrated first, as `spherecal
//! calibrate` does with its defaults (the session's threshold and iteration
//! bound); with `--result` that result is reported as it is, after checking
//! that it belongs to the session.

use std::path::PathBuf;
use std::time::{Instant, SystemTime};

use clap::Args;

use super::{CliError, QUIET_HELP};
use crate::engine::calibrate::solve::{self, Control, Method, Options};
use crate::engine::files::format::{self, FileError};
use crate::engine::tools::report::html::{self, ReportInput, ReportMeta};
use crate::engine::tools::result_view;

/// `spherecal report`.
#[derive(Debug, Args)]
pub struct ReportArgs {
    /// Session file (FORMAT.md `spherecal-session`); its SHA-256 is in the report.
    pub session: PathBuf,
    /// A result file of this session to report as it is (no solver run); without it the session is calibrated first.
    #[arg(long)]
    pub result: Option<PathBuf>,
    /// Where to write the HTML report (one file: inline CSS and SVG, no script, no external resource).
    #[arg(long, short)]
    pub out: PathBuf,
    /// Method of the calibration run when no `--result` is given.
    #[arg(long, default_value = "ml", value_parser = super::method_parser())]
    pub method: Method,
    /// Acceptance tolerance on the validation after calibration, `STD,MAX` in mm (e.g. `0.2,0.5`): the report then says PASS or FAIL.
    #[arg(long, value_name = "STD,MAX", value_parser = parse_tolerance)]
    pub tolerance: Option<result_view::Tolerance>,
    /// Without --result: report the calibration even when its identify centres still scatter beyond 10 mm (a failed calibration), as `calibrate --accept-implausible`.
    #[arg(long)]
    pub accept_implausible: bool,
    /// `-q`: [`QUIET_HELP`](super::QUIET_HELP).
    #[arg(long, short, help = QUIET_HELP)]
    pub quiet: bool,
}

/// Largest `--tolerance` figure, mm: a validation error of a metre
/// accepts any calibration, so a larger one is a slip of the keyboard.
pub const MAX_TOLERANCE_MM: f64 = 1000.0;

/// `--tolerance STD,MAX`: two positive numbers of mm, at most
/// [`MAX_TOLERANCE_MM`].
fn parse_tolerance(s: &str) -> Result<result_view::Tolerance, String> {
    let t = result_view::Tolerance::parse(s)?;
    if t.std_mm > MAX_TOLERANCE_MM || t.max_mm > MAX_TOLERANCE_MM {
        return Err(format!(
            "`{s}`: a tolerance of more than {} mm accepts any calibration; give STD,MAX in mm, e.g. 0.2,0.5",
            crate::engine::base::numeric::show(MAX_TOLERANCE_MM)
        ));
    }
    Ok(t)
}

/// Loads the session (and result), calibrates when needed, renders the
/// report and writes it atomically.
///
/// # Errors
/// [`CliError`] with status 2 for bad input (unreadable or invalid files,
/// a result of another session, a session that cannot be calibrated, an
/// output that is refused or cannot be written).
pub fn run(args: &ReportArgs) -> Result<(), CliError> {
    let mut inputs = vec![args.session.as_path()];
    inputs.extend(args.result.as_deref());
    CliError::guard_output(&args.out, &inputs)?;
    let started = Instant::now();
    let bytes = format::read_bytes(&args.session, format::Cap::SESSION).map_err(|source| {
        CliError::from_file(
            &FileError::Io {
                action: "reading",
                path: args.session.clone(),
                source,
            },
            true,
        )
    })?;
    let text = std::str::from_utf8(&bytes).map_err(|e| {
        CliError::input(format!(
            "the file is not UTF-8 text ({e}) ({})",
            args.session.display()
        ))
    })?;
    let session =
        format::parse_session(text, &args.session).map_err(|e| CliError::from_file(&e, true))?;
    let prepared =
        solve::prepare(&session).map_err(|e| CliError::from_calibration(&e, &args.session))?;
    let result = if let Some(path) = &args.result {
        let result = format::load_result(path).map_err(|e| CliError::from_file(&e, true))?;
        result_view::check_result(&session, &result, Some(&prepared)).map_err(|e| {
            CliError::input(format!(
                "{} does not belong to {}: {e}",
                path.display(),
                args.session.display()
            ))
        })?;
        result
    } else {
        let mut options = Options::from_session(&session);
        options.method = args.method;
        let cal = solve::run(&session, &prepared, &options, &mut |_| Control::Continue)
            .map_err(|e| CliError::from_calibration(&e, &args.session))?;
        super::check_plausible(
            &session,
            &cal,
            (args.accept_implausible, args.quiet),
            &args.session,
        )?;
        format::ResultFile::from_calibration(&session, &cal)
    };
    let meta = ReportMeta::new(args.session.display().to_string(), SystemTime::now());
    let rendering = Instant::now();
    let html = html::render(&ReportInput {
        session: &session,
        session_bytes: &bytes,
        result: &result,
        prepared: Some(&prepared),
        meta: &meta,
        tolerance: args.tolerance,
    });
    let render_ms = rendering.elapsed().as_secs_f64() * 1e3;
    format::write_atomic(&args.out, html.as_bytes()).map_err(|e| CliError::from_file(&e, false))?;
    if !args.quiet {
        if let Some(t) = &args.tolerance {
            let view = result_view::ResultFigures::new(&result);
            sayln!(
                "{}",
                result_view::Verdict::of(view.headline.as_ref(), t).describe(t)
            );
        }
        let how = match &args.result {
            Some(_) => "the given result".to_string(),
            None => format!("a run of method {}", args.method.as_str()),
        };
        sayln!(
            "wrote {} ({:.0} KB, {how}; {:.0} ms in all, {render_ms:.1} ms of it rendering)",
            args.out.display(),
            html.len() as f64 / 1024.0,
            started.elapsed().as_secs_f64() * 1e3
        );
    }
    Ok(())
}
