//! The command line: `spherecal calibrate | simulate | measure | gui | …`. A thin caller
//! of the engine; it prints, the engine does not.
//!
//! Exit status (FORMAT.md "Command line contract"): 0 on success, 2 on bad
//! input or a refused or failed output (a device, a folder, a read-only
//! file, an unwritable path, a full standard output) with one `error:`
//! line on stderr naming the file, the measurement and the problem, 1 on
//! an internal failure, 130 when interrupted (Ctrl-C, SIGTERM). Every
//! command writes all of its files or none, each atomically.

/// Prints to stdout with a newline, as `println!`, but a closed stdout (the
/// reader of a pipe went away: `| head`) is not an error: the work is
/// done, the rest of the text is dropped, nothing panics.
macro_rules! sayln {
    () => {
        $crate::cli::write_line(format_args!(""))
    };
    ($($arg:tt)*) => {
        $crate::cli::write_line(format_args!($($arg)*))
    };
}

/// As [`sayln!`] without the newline.
macro_rules! say {
    ($($arg:tt)*) => {
        $crate::cli::write_text(format_args!($($arg)*))
    };
}

pub mod compensate;
pub mod evaluate;
pub mod export_model;
pub mod history;
pub mod html_report;
pub mod import;
pub mod measure;
pub mod plan;
pub mod scan_flags;
pub mod simulate;

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use clap::{Args, Parser, Subcommand};

use crate::engine::base::session;
use crate::engine::calibrate::solve::ml::{Loss, MlOptions};
use crate::engine::calibrate::solve::paper::Pairing;
use crate::engine::calibrate::solve::{
    self, Control, HandEyeSource, Method, Options, SolveError, StopReason, plausible,
};
use crate::engine::files::format;
use crate::engine::files::format::FileError;
use crate::engine::tools::report::summary;

/// spherecal: calibrate a robot-mounted laser-stripe sensor (hand-eye and
/// kinematic errors) against a reference sphere.
#[derive(Debug, Parser)]
#[command(name = "spherecal", version, about, long_about = None)]
pub struct Cli {
    /// What to do; without a command the workbench opens on the demo session.
    #[command(subcommand)]
    pub command: Option<Command>,
}

impl Cli {
    /// Parses the process's arguments; every option that takes a value
    /// also takes a negative number (`--angle -40`, `--range -40,40,…`),
    /// which clap would otherwise read as an unknown flag. Bad arguments
    /// print clap's message and exit with status 2.
    #[must_use]
    pub fn parse_args() -> Self {
        Self::parse_from_args(std::env::args_os())
    }

    /// [`Self::parse_args`] of the given arguments (the first is the
    /// program name).
    #[must_use]
    pub fn parse_from_args<I, T>(args: I) -> Self
    where
        I: IntoIterator<Item = T>,
        T: Into<std::ffi::OsString> + Clone,
    {
        use clap::{CommandFactory, FromArgMatches};
        let matches = negative_numbers(Self::command()).get_matches_from(args);
        Self::from_arg_matches(&matches).unwrap_or_else(|e| e.exit())
    }
}

/// `command` with every value-taking option accepting negative numbers,
/// in every subcommand.
fn negative_numbers(command: clap::Command) -> clap::Command {
    command
        .mut_args(|a| {
            if a.get_action().takes_values() {
                a.allow_negative_numbers(true)
            } else {
                a
            }
        })
        .mut_subcommands(negative_numbers)
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run the whole calibration headless and write the result file.
    Calibrate(CalibrateArgs),
    /// Write a simulated session with a known truth (for tests, demos and what-if studies).
    Simulate(simulate::SimulateArgs),
    /// Open the workbench, optionally on a session file.
    Gui(GuiArgs),
    /// Compare the paper's method, `ml` and the noise floor on simulated scenarios (README evidence).
    Evaluate(evaluate::EvaluateArgs),
    /// Write the calibrated model of a result file as JSON (the session `robot` block), CSV (MDH table) or URDF.
    ExportModel(export_model::ExportModelArgs),
    /// Build a session file from a joint log CSV and stripe profile files (mm, deg in the session; units of the inputs chosen by flags).
    Import(import::ImportArgs),
    /// Plan the poses to teach (translation, rotation, identify and validate groups) for a robot, a rough sphere position and a hand-eye guess; export CSV and the controller program (RAPID, URScript).
    Plan(plan::PlanArgs),
    /// Write a self-contained HTML report (figures as inline SVG): calibrates the session first, or reports `--result` as it is.
    Report(html_report::ReportArgs),
    /// Measure with the calibrated cell: a session's stripes or a raw scan (pose log and profiles) into a point cloud in the base (or a workpiece) frame through a result's model and hand-eye, each point with its σ (PLY, E57 or CSV by extension); the sphere self-validation before and after calibration.
    Measure(measure::MeasureArgs),
    /// Library of a folder of sessions and results: per robot the drift of the hand-eye and kinematic deviations over time, jumps beyond k combined σ flagged.
    History(history::HistoryArgs),
    /// Compensate robot targets through a calibration: a pose table or a robot program (RAPID, KUKA KRL, FANUC .ls, URScript) rewritten so that a controller running the nominal model drives the TCP onto each target; prints the calibrated hand-eye as the controller's tool data.
    Compensate(compensate::CompensateArgs),
}

/// The first error writing to stdout other than a closed pipe (a full
/// disk, `/dev/full`), reported by [`stdout_result`] when the command ends.
static STDOUT_ERROR: std::sync::Mutex<Option<std::io::Error>> = std::sync::Mutex::new(None);

/// Remembers a failed write to stdout, unless the reader went away (a
/// closed pipe is the reader's choice, not a lost output).
fn note_stdout(result: std::io::Result<()>) {
    if let Err(e) = result
        && e.kind() != std::io::ErrorKind::BrokenPipe
        && let Ok(mut first) = STDOUT_ERROR.lock()
        && first.is_none()
    {
        *first = Some(e);
    }
}

/// Writes `args` and a newline to stdout, ignoring a closed pipe (any
/// other failure is reported by [`stdout_result`]).
pub fn write_line(args: std::fmt::Arguments<'_>) {
    use std::io::Write as _;
    let mut out = std::io::stdout().lock();
    note_stdout(out.write_fmt(args).and_then(|()| out.write_all(b"\n")));
}

/// Writes `args` to stdout, ignoring a closed pipe (any other failure is
/// reported by [`stdout_result`]).
pub fn write_text(args: std::fmt::Arguments<'_>) {
    use std::io::Write as _;
    note_stdout(std::io::stdout().lock().write_fmt(args));
}

/// Flushes stdout and reports the first failed write of the command's
/// text (`spherecal history … > /dev/full`): the output is lost, so the
/// command fails (status 2). A closed pipe is not a failure.
///
/// # Errors
/// [`CliError`] with status 2 naming the write error.
pub fn stdout_result() -> Result<(), CliError> {
    use std::io::Write as _;
    note_stdout(std::io::stdout().lock().flush());
    let first = STDOUT_ERROR.lock().ok().and_then(|mut e| e.take());
    match first {
        Some(e) => Err(CliError::input(format!(
            "writing to standard output failed: {e}; the command's text is lost"
        ))),
        None => Ok(()),
    }
}

/// Longest error message printed whole, characters: far beyond any
/// message of spherecal's own; only one that echoes a hostile input (a
/// line of a gigabyte) is longer.
pub const MAX_MESSAGE_CHARS: usize = 2000;

/// Time between progress lines of a long command (plan, import): work
/// of the paper's size takes well under this and prints none.
pub const PROGRESS_EVERY: Duration = Duration::from_secs(2);

/// `message` cut in the middle to at most [`MAX_MESSAGE_CHARS`]: the
/// start (what is wrong) and the end (the file) are kept, the middle is
/// replaced by how many characters were left out.
#[must_use]
pub fn bounded_message(message: &str) -> String {
    let n = message.chars().count();
    if n <= MAX_MESSAGE_CHARS {
        return message.to_owned();
    }
    let keep = MAX_MESSAGE_CHARS / 2;
    let head: String = message.chars().take(keep).collect();
    let tail: String = message.chars().skip(n - keep).collect();
    format!("{head}… ({} characters left out) …{tail}", n - 2 * keep)
}

/// Refuses, before any work, outputs that could not be written (a
/// device, a folder, a read-only file, a missing folder, two outputs that
/// are one file), with status 2.
///
/// # Errors
/// The refusal, naming the output.
pub fn check_outputs(paths: &[&Path], folders: format::Folders) -> Result<(), CliError> {
    format::check_outputs(paths, folders).map_err(|e| CliError::from_file(&e, false))
}

/// Writes a command's files as one transaction: all of them or none
/// ([`format::write_all_atomic`]).
///
/// # Errors
/// Status 2 naming the file that could not be written (nothing is
/// written), 130 when interrupted.
pub fn write_outputs(files: &[(&Path, &[u8])], folders: format::Folders) -> Result<(), CliError> {
    format::write_all_atomic(files, folders).map_err(|e| CliError::from_file(&e, false))
}

/// `spherecal gui`.
#[derive(Debug, Args)]
pub struct GuiArgs {
    /// Session file to open (default: the embedded demo session).
    pub session: Option<PathBuf>,
    /// A result file to review beside the session (no solver run).
    #[arg(long)]
    pub result: Option<PathBuf>,
}

/// `spherecal calibrate`.
#[derive(Debug, Args)]
pub struct CalibrateArgs {
    /// Session file (FORMAT.md `spherecal-session`).
    pub session: PathBuf,
    /// Where to write the result file (FORMAT.md `spherecal-result`).
    #[arg(long, short)]
    pub out: PathBuf,
    /// Identification method: `ml` (maximum likelihood, the default: nearer the noise floor in every simulated scenario) or `paper` (the paper's section 3.2, the baseline).
    #[arg(long, default_value = "ml", value_parser = parse_method)]
    pub method: Method,
    /// Leave these measurements out (comma-separated ids), e.g. the outliers `ml` listed.
    #[arg(long, value_delimiter = ',')]
    pub exclude: Vec<String>,
    /// Settings of the `ml` method.
    #[command(flatten)]
    pub ml: MlArgs,
    /// Stop when ε falls to this (mm); default: the session's `solver.threshold` (0.15).
    #[arg(long)]
    pub threshold: Option<f64>,
    /// Most updates; default: the session's `solver.max_iterations` (20).
    #[arg(long)]
    pub max_iterations: Option<usize>,
    /// Relative SVD tolerance of the paper's method (fraction of the largest singular value).
    #[arg(long, default_value_t = crate::engine::calibrate::solve::paper::DEFAULT_SVD_TOLERANCE)]
    pub svd_tolerance: f64,
    /// Pairing of a station's measurements: `disjoint` (the paper's (1,2),(3,4),(5,6)) or `all`.
    #[arg(long, default_value = "disjoint", value_parser = parse_pairing)]
    pub pairs: Pairing,
    /// Write the result even when the identify centres still scatter beyond 10 mm after calibration (a failed calibration: wrong pose convention, joint unit, robot model or side), e.g. to study it.
    #[arg(long)]
    pub accept_implausible: bool,
    /// Skip the held-out figure (each identify measurement's centre predicted by a calibration made without it; ml: one Gauss-Newton step per measurement, paper: its loop rerun without each, 10-fold above 50 measurements).
    #[arg(long)]
    pub no_held_out: bool,
    /// Print nothing but errors.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Refuses a finished calibration whose identify centres scatter beyond
/// any sensor and robot ([`plausible::check_calibration`]), unless
/// `accept` (then it is a warning on stderr).
///
/// # Errors
/// Status 2 naming the scatter and the likely causes, and the flag that
/// writes the result anyway.
pub fn check_plausible(
    session: &session::Session,
    cal: &solve::Calibration,
    accept: bool,
    path: &Path,
) -> Result<(), CliError> {
    match plausible::check_calibration(session, cal) {
        Ok(()) => Ok(()),
        Err(e) if accept => {
            eprintln!("warning: {e} (written anyway: --accept-implausible)");
            Ok(())
        }
        Err(e) => Err(CliError::input(format!(
            "{e}; nothing is written (--accept-implausible writes it anyway) ({})",
            path.display()
        ))),
    }
}

/// Settings of the `ml` method (defaults: [`MlOptions::default`]).
#[derive(Debug, Args)]
pub struct MlArgs {
    /// ml: σ of the joint readings, deg (default 0.003).
    #[arg(long)]
    pub joint_sigma: Option<f64>,
    /// ml: σ of a centre given in the session, mm (default 0.01).
    #[arg(long)]
    pub centre_sigma: Option<f64>,
    /// ml: floor of each principal σ of a stripe centre's covariance, mm (default 0.002).
    #[arg(long)]
    pub sensor_sigma_floor: Option<f64>,
    /// ml: no prior on the kinematic deviations.
    #[arg(long)]
    pub no_prior: bool,
    /// ml: prior σ of angle deviations, deg (default 0.2).
    #[arg(long)]
    pub prior_angle: Option<f64>,
    /// ml: prior σ of length deviations, mm (default 0.5).
    #[arg(long)]
    pub prior_length: Option<f64>,
    /// ml: robust loss, `squared`, `huber` or `cauchy` (default huber).
    #[arg(long, value_parser = parse_loss)]
    pub loss: Option<Loss>,
    /// ml: robust loss scale, σ of the whitened residual norm (default 3.37, the 99 % point of χ(3)).
    #[arg(long)]
    pub loss_scale: Option<f64>,
    /// ml: relative pivot tolerance of the identifiability QR (default 1e-7).
    #[arg(long)]
    pub rank_tolerance: Option<f64>,
    /// ml: skip the leave-one-station-out cross-validation.
    #[arg(long)]
    pub no_cross_validation: bool,
    /// ml, pose-only sessions: σ of each base-frame coordinate from the error of the flange poses the controller reports (the robot's accuracy), mm (default: estimated from the scatter of the station centres at the start).
    #[arg(long)]
    pub pose_sigma: Option<f64>,
}

impl MlArgs {
    /// The options these flags give, the rest at their defaults.
    #[must_use]
    pub fn options(&self) -> MlOptions {
        let d = MlOptions::default();
        MlOptions {
            joint_sigma_deg: self.joint_sigma.unwrap_or(d.joint_sigma_deg),
            centre_sigma: self.centre_sigma.unwrap_or(d.centre_sigma),
            sensor_sigma_floor: self.sensor_sigma_floor.unwrap_or(d.sensor_sigma_floor),
            prior: d.prior && !self.no_prior,
            prior_angle_deg: self.prior_angle.unwrap_or(d.prior_angle_deg),
            prior_length: self.prior_length.unwrap_or(d.prior_length),
            loss: self.loss.unwrap_or(d.loss),
            loss_scale: self.loss_scale.unwrap_or(d.loss_scale),
            rank_tolerance: self.rank_tolerance.unwrap_or(d.rank_tolerance),
            cross_validation: d.cross_validation && !self.no_cross_validation,
            pose_sigma: self.pose_sigma.or(d.pose_sigma),
        }
    }
}

/// `standard` or `modified` (a DH table's convention).
fn parse_dh(s: &str) -> Result<crate::engine::base::robot::DhConvention, String> {
    match s.to_ascii_lowercase().as_str() {
        "standard" | "dh" => Ok(crate::engine::base::robot::DhConvention::Standard),
        "modified" | "mdh" => Ok(crate::engine::base::robot::DhConvention::Modified),
        _ => Err(format!(
            "unknown DH convention `{s}`, expected standard or modified"
        )),
    }
}

fn parse_loss(s: &str) -> Result<Loss, String> {
    Loss::parse(s)
        .ok_or_else(|| format!("unknown loss `{s}`, expected `squared`, `huber` or `cauchy`"))
}

/// Parses `--range Y0,Y1,Z0,Z1` (mm, sensor frame) into a `sensor.range`.
///
/// # Errors
/// Not four finite numbers with `Y0 < Y1` and `Z0 < Z1`.
pub fn parse_range(s: &str) -> Result<crate::engine::base::session::SensorRange, String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|t| t.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("`{s}`: give Y0,Y1,Z0,Z1 in mm, e.g. -40,40,-40,40"))?;
    let [y0, y1, z0, z1] = v.as_slice() else {
        return Err(format!("`{s}`: give four numbers Y0,Y1,Z0,Z1 in mm"));
    };
    if !(v.iter().all(|x| x.is_finite()) && y0 < y1 && z0 < z1) {
        return Err(format!("`{s}`: need Y0 < Y1 and Z0 < Z1 (mm)"));
    }
    Ok(crate::engine::base::session::SensorRange {
        y: [*y0, *y1],
        z: [*z0, *z1],
    })
}

fn parse_method(s: &str) -> Result<Method, String> {
    Method::parse(s).ok_or_else(|| {
        let names: Vec<&str> = Method::ALL.iter().map(|m| m.as_str()).collect();
        format!(
            "unknown method `{s}`, expected one of: {}",
            names.join(", ")
        )
    })
}

fn parse_pairing(s: &str) -> Result<Pairing, String> {
    Pairing::parse(s).ok_or_else(|| format!("unknown pairing `{s}`, expected `disjoint` or `all`"))
}

/// A failure of a command, with its exit status.
#[derive(Debug)]
pub struct CliError {
    /// 2 for bad input or a refused output, 1 for an internal failure,
    /// 130 when interrupted.
    pub status: i32,
    /// One line, without the `error: ` prefix.
    pub message: String,
}

impl CliError {
    /// Bad input (exit 2).
    #[must_use]
    pub fn input(message: impl Into<String>) -> Self {
        Self {
            status: 2,
            message: message.into(),
        }
    }

    /// Internal failure (exit 1).
    #[must_use]
    pub fn internal(message: impl Into<String>) -> Self {
        Self {
            status: 1,
            message: message.into(),
        }
    }

    /// Interrupted (Ctrl-C or SIGTERM, exit 130).
    #[must_use]
    pub fn interrupted(message: impl Into<String>) -> Self {
        Self {
            status: 130,
            message: message.into(),
        }
    }

    /// From a file error: a file that cannot be read, or an output that is
    /// refused or cannot be written, is the user's to fix (status 2, one
    /// code for every command); a write stopped by Ctrl-C is 130.
    #[must_use]
    pub fn from_file(e: &FileError, reading: bool) -> Self {
        let message = e.to_string();
        match e {
            FileError::Io { source, .. }
                if !reading && source.kind() == std::io::ErrorKind::Interrupted =>
            {
                Self::interrupted(message)
            }
            FileError::Invalid { .. } | FileError::Io { .. } => Self::input(message),
        }
    }

    /// Refuses, before any work, an output that is one of the command's
    /// inputs (the same file: it would be destroyed) or that could not be
    /// written ([`check_outputs`]: a device, a folder, a read-only file, a
    /// missing folder), with status 2.
    ///
    /// # Errors
    /// The refusal, naming the output (and the input it is).
    pub fn guard_output(output: &Path, inputs: &[&Path]) -> Result<(), Self> {
        format::refuse_inputs(output, inputs).map_err(|e| Self::input(e.to_string()))?;
        check_outputs(&[output], format::Folders::Existing)
    }

    /// From a calibration error of the session at `path`.
    #[must_use]
    pub fn from_calibration(e: &SolveError, path: &Path) -> Self {
        let message = format!("{e} ({})", path.display());
        if e.is_input_error() {
            Self::input(message)
        } else {
            Self::internal(message)
        }
    }
}

/// `spherecal calibrate`: load, calibrate, write the result atomically,
/// print a summary.
///
/// # Errors
/// [`CliError`] with status 2 for bad input, 1 for internal failures.
pub fn calibrate_command(args: &CalibrateArgs) -> Result<(), CliError> {
    let started = Instant::now();
    CliError::guard_output(&args.out, &[&args.session])?;
    let session = format::load_session(&args.session).map_err(|e| CliError::from_file(&e, true))?;
    let session = if args.exclude.is_empty() {
        session
    } else {
        session::exclude_measurements(&session, &args.exclude)
            .map_err(|e| CliError::input(format!("{e} ({})", args.session.display())))?
    };
    let mut options = Options::from_session(&session);
    options.ml = args.ml.options();
    options.method = args.method;
    if let Some(t) = args.threshold {
        options.threshold = t;
    }
    if let Some(n) = args.max_iterations {
        options.max_iterations = n;
    }
    options.paper.svd_tolerance = args.svd_tolerance;
    options.paper.pairing = args.pairs;
    options.held_out = !args.no_held_out;
    let prepared =
        solve::prepare(&session).map_err(|e| CliError::from_calibration(&e, &args.session))?;
    let quiet = args.quiet;
    let mut on_progress = |p: &solve::Progress| {
        if !quiet && p.phase == solve::Phase::Loop {
            sayln!("  ε after {:>2} update(s): {:.4} mm", p.updates, p.epsilon);
        }
        Control::Continue
    };
    if !quiet {
        sayln!(
            "session {:?}: {} measurements",
            session.name,
            session.measurements.len()
        );
        for (id, w) in &prepared.warnings {
            sayln!("  warning: measurement {id}: {w}");
        }
        match &prepared.hand_eye_source {
            HandEyeSource::File => sayln!("initial hand-eye: from the session file"),
            HandEyeSource::Computed(h) => sayln!(
                "initial hand-eye (eq. 6-9): rotation residual {:.4} mm, translation residual {:.4} mm",
                h.rotation_residual,
                h.translation_residual
            ),
        }
        sayln!(
            "identification: method {}, threshold {} mm, at most {} update(s)",
            options.method.as_str(),
            crate::engine::base::numeric::show(options.threshold),
            options.max_iterations
        );
    }
    let cal = solve::run(&session, &prepared, &options, &mut on_progress)
        .map_err(|e| CliError::from_calibration(&e, &args.session))?;
    if let StopReason::Converged {
        epsilon,
        threshold,
        updates: 0,
    } = cal.stop
    {
        // Said plainly: a threshold at or above the starting ε calibrates
        // nothing.
        eprintln!(
            "warning: ε = {} mm is already within the threshold {} mm before any update: nothing was identified, the result holds the uncalibrated model and initial hand-eye",
            crate::engine::base::numeric::approx(epsilon),
            crate::engine::base::numeric::show(threshold)
        );
    }
    check_plausible(&session, &cal, args.accept_implausible, &args.session)?;
    let result = format::ResultFile::from_calibration(&session, &cal);
    format::save_result(&result, &args.out).map_err(|e| CliError::from_file(&e, false))?;
    if !quiet {
        say!("{}", summary::summary(&session, &cal));
        sayln!(
            "wrote {} ({:.0} ms)",
            args.out.display(),
            started.elapsed().as_secs_f64() * 1e3
        );
    }
    Ok(())
}

/// A command's flags parsed from `argv` (its first word the command's
/// name), as the commands' tests read them; panics on bad flags (tests only).
#[cfg(test)]
#[allow(clippy::unwrap_used)]
pub(crate) fn parse_flags<A: clap::Args>(argv: &[&str]) -> A {
    use clap::Parser;

    #[derive(Debug, Parser)]
    struct Wrapper<A: clap::Args> {
        #[command(flatten)]
        args: A,
    }

    Wrapper::<A>::try_parse_from(argv).unwrap().args
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 23: a write stopped by a late Ctrl-C ended with status 1
    /// ("No such file or directory"); it is an interruption (130), and
    /// every other refused or failed output is status 2.
    #[test]
    fn file_errors_have_one_status_each() {
        let io = |kind: std::io::ErrorKind| FileError::Io {
            action: "writing",
            path: PathBuf::from("r.json"),
            source: std::io::Error::new(kind, "x"),
        };
        let interrupted = io(std::io::ErrorKind::Interrupted);
        assert_eq!(CliError::from_file(&interrupted, false).status, 130);
        for kind in [
            std::io::ErrorKind::PermissionDenied,
            std::io::ErrorKind::NotFound,
            std::io::ErrorKind::InvalidInput,
        ] {
            assert_eq!(CliError::from_file(&io(kind), false).status, 2);
            assert_eq!(CliError::from_file(&io(kind), true).status, 2);
        }
    }

    #[test]
    fn long_messages_keep_their_start_and_end() {
        let long = format!("start {} end (file.csv)", "x".repeat(10_000));
        let short = bounded_message(&long);
        assert!(
            short.chars().count() < MAX_MESSAGE_CHARS + 60,
            "{}",
            short.len()
        );
        assert!(short.starts_with("start ") && short.ends_with("end (file.csv)"));
        assert!(short.contains("characters left out"));
        assert_eq!(bounded_message("short"), "short");
    }
}
