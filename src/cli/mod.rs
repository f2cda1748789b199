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

pub mod check;
pub mod compensate;
pub mod evaluate;
pub mod export_model;
pub mod history;
pub mod html_report;
pub mod import;
pub mod measure;
pub mod message;
pub mod plan;
pub mod plan_fixed;
pub mod scan_flags;
pub mod simulate;
pub mod simulate_fixed;
pub mod values;

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use clap::{Args, Parser, Subcommand};

pub use message::{MAX_MESSAGE_CHARS, bounded_message, error_line, name_flags, readable_numbers};

use crate::engine::base::records::solver::no_update_warning;
use crate::engine::base::{limits, session};
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
#[command(
    name = "spherecal",
    version,
    about = "Calibrate a robot-mounted laser-stripe sensor against a reference sphere (hand-eye and kinematic errors); plan the poses, measure parts and compensate programs with the calibration, follow a cell's drift",
    long_about = None,
    after_help = "Without a command the workbench opens on the demo session (spherecal gui).\n\
        Exit status: 0 done, 3 a check that fails, 2 bad input or a refused output (one `error:` line), 1 internal failure, 130 interrupted."
)]
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
        use clap::FromArgMatches;
        let matches = command().get_matches_from(args);
        Self::from_arg_matches(&matches).unwrap_or_else(|e| e.exit())
    }
}

/// The command line as the binary parses it (and as `--help` and the
/// guide's reference show it): [`Cli`]'s definitions with every
/// value-taking option accepting negative numbers, and every default
/// shown alike ([`default_paragraph`]).
#[must_use]
pub fn command() -> clap::Command {
    finish(<Cli as clap::CommandFactory>::command())
}

/// `command` with every value-taking option accepting negative numbers
/// and every default shown alike, in every subcommand.
fn finish(command: clap::Command) -> clap::Command {
    command
        .mut_args(|a| {
            let a = default_paragraph(a);
            if a.get_action().takes_values() {
                a.allow_negative_numbers(true)
            } else {
                a
            }
        })
        .mut_subcommands(finish)
}

/// An option whose default depends on the input says so at the end of
/// its help, `… [default: the session's solver.threshold]`; in the long
/// help (`--help`) that bracket is set apart as clap sets apart a fixed
/// default (`[default: 0.15]`), so that every default reads alike.
fn default_paragraph(arg: clap::Arg) -> clap::Arg {
    let Some(help) = arg.get_help().map(ToString::to_string) else {
        return arg;
    };
    // With a list of values (clap puts its own default after it) the
    // bracket stays where it is written.
    if arg.get_long_help().is_some()
        || !help.ends_with(']')
        || !arg.get_possible_values().is_empty()
    {
        return arg;
    }
    match help.rfind(" [default: ") {
        Some(at) => {
            let long = format!("{}\n\n{}", &help[..at], &help[at + 1..]);
            arg.long_help(long)
        }
        None => arg,
    }
}

/// The help of every `-q`/`--quiet`: one meaning on every command that
/// writes files.
pub const QUIET_HELP: &str = "Print nothing but errors (no summary, no progress, no warnings)";

/// The subcommands. The first paragraph of each is the summary that
/// `spherecal --help` lists; the rest is shown by `spherecal <command> --help`.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Calibrate a session: identify the hand-eye and the kinematic errors, write the result file
    ///
    /// Runs the whole calibration headless with method `ml` (the default) or
    /// `paper`, prints ε after each update and the validation before and
    /// after, and writes the result (FORMAT.md `spherecal-result`). A
    /// calibration whose identify centres still scatter beyond 10 mm is
    /// refused (nothing written) unless --accept-implausible.
    Calibrate(CalibrateArgs),
    /// Write a simulated session and its truth (for tests, demos and what-if studies)
    ///
    /// Seeded: the same arguments give byte-identical files. The poses are
    /// generated for the --robot preset, or taken from a plan CSV (--plan);
    /// --csv-out also writes the files `spherecal import` reads; --scan
    /// simulates a raw scan of a part instead of a session.
    Simulate(simulate::SimulateArgs),
    /// Open the workbench, optionally on a session file (the default without a command)
    ///
    /// Needs a display (DISPLAY or WAYLAND_DISPLAY); every other command runs
    /// without one.
    Gui(GuiArgs),
    /// Compare the paper's method, `ml` and the noise floor on simulated scenarios (the evidence tables)
    ///
    /// Prints a text report, or with --markdown the tables of the guide's
    /// evidence chapters; --planned-range and --compensation run the other
    /// two studies instead. Writes no file; the progress goes to stderr.
    Evaluate(evaluate::EvaluateArgs),
    /// Write a result's calibration for other software: model JSON, MDH CSV, URDF (yours), UR YAML or tool data
    ExportModel(export_model::ExportModelArgs),
    /// Build a session file from a pose log and what the sensor saw: stripe profiles or sphere centres
    ///
    /// The pose log is a joint log CSV (--joints, with --robot) or a pose
    /// file of any layout (--poses: a table, a JSON list, or a FANUC, ABB
    /// RAPID, KUKA or URScript program; flange poses or joint targets). What
    /// the sensor saw is a folder or a CSV of stripe profiles (--profiles)
    /// or, with --poses, a table of sphere centres (--centres). The session
    /// is in mm and deg; the units of the inputs are set by flags.
    Import(import::ImportArgs),
    /// Plan the poses to teach for a calibration, predict its accuracy, export them for the controller
    ///
    /// From a robot, a rough sphere position and a hand-eye guess: the
    /// translation, rotation, identify and validate poses; --predict N
    /// scores the plan by simulated calibrations; --csv writes the joint
    /// log `spherecal import` reads, --rapid and --program the controller
    /// programs (ABB RAPID, URScript).
    Plan(plan::PlanArgs),
    /// Write a self-contained HTML report of a calibration (figures as inline SVG)
    ///
    /// Calibrates the session first (as `spherecal calibrate`, with
    /// --method), or reports --result as it is after checking that it
    /// belongs to the session; --tolerance adds a PASS or FAIL verdict.
    Report(html_report::ReportArgs),
    /// Measure with the calibrated cell: stripes into a point cloud, each point with its σ
    ///
    /// A session's stripes or a raw scan (a pose log and profiles) into a
    /// point cloud in the base (or a workpiece) frame through a result's
    /// model and hand-eye (PLY, E57 or CSV by the extension of --out); with
    /// a sphere diameter, the sphere self-validation before and after
    /// calibration.
    Measure(measure::MeasureArgs),
    /// Follow a cell's drift: the library of a folder of sessions and results
    ///
    /// Per robot, the hand-eye and the main kinematic deviations over time;
    /// a change between consecutive results beyond k combined σ is flagged.
    /// Prints the tables; --csv also writes every parameter.
    History(history::HistoryArgs),
    /// Compensate robot targets (a pose table or a robot program) through a calibration
    ///
    /// The targets of a pose table or a robot program (RAPID, KUKA KRL,
    /// FANUC .ls, URScript) rewritten so that a controller running the
    /// nominal model drives the TCP onto each target, every other byte
    /// kept; prints the calibrated hand-eye as the controller's tool data
    /// and flags targets outside what the calibration saw.
    Compensate(compensate::CompensateArgs),
    /// Re-check a calibrated cell in five minutes: a short scan of the sphere against the result
    ///
    /// The poses of `plan --check`, run at the robot and imported, predicted
    /// through the result and tested against its covariance and noise model
    /// at the false-alarm rate --alpha: exit 0 when the cell holds its
    /// calibration, 3 when it does not (with what moved).
    Check(check::CheckArgs),
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
        Some(e) => {
            let files = format::written();
            let files = if files.is_empty() {
                String::new()
            } else {
                format!(
                    ", but the files it wrote are whole and kept: {}",
                    files
                        .iter()
                        .map(|p| p.display().to_string())
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            };
            Err(CliError::input(format!(
                "writing to standard output failed: {e}; the command's text is lost{files}"
            )))
        }
        None => Ok(()),
    }
}

/// Time between progress lines of a long command (plan, import): work
/// of the paper's size takes well under this and prints none.
pub const PROGRESS_EVERY: Duration = Duration::from_secs(2);

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
    /// Session file to open [default: the embedded demo session]
    pub session: Option<PathBuf>,
    /// A result file to review beside the session (no solver run).
    #[arg(long)]
    pub result: Option<PathBuf>,
}

/// The sentence of `spherecal gui` (and of `spherecal` alone) where no
/// display is.
pub const NO_DISPLAY: &str = "the workbench needs a display and neither DISPLAY nor WAYLAND_DISPLAY is set: log in to a graphical session, or use the commands that need none (spherecal calibrate, import, plan, measure, compensate, report: see spherecal --help)";

/// Refuses to open the workbench where there is no display to open it
/// on (Linux and the BSDs: neither `DISPLAY` nor `WAYLAND_DISPLAY` set),
/// with status 2 and [`NO_DISPLAY`].
///
/// # Errors
/// No display.
pub fn check_display() -> Result<(), CliError> {
    if cfg!(any(target_os = "macos", target_os = "windows")) {
        return Ok(());
    }
    let set = |key: &str| std::env::var_os(key).is_some_and(|v| !v.is_empty());
    if set("DISPLAY") || set("WAYLAND_DISPLAY") {
        Ok(())
    } else {
        Err(CliError::input(NO_DISPLAY))
    }
}

/// `spherecal calibrate`.
#[derive(Debug, Args)]
pub struct CalibrateArgs {
    /// Session file (FORMAT.md `spherecal-session`).
    pub session: PathBuf,
    /// Where to write the result file (FORMAT.md `spherecal-result`).
    #[arg(long, short)]
    pub out: PathBuf,
    /// Identification method: `ml` (maximum likelihood: nearer the noise floor in every simulated scenario) or `paper` (the paper's section 3.2, the baseline).
    #[arg(long, default_value = "ml", value_parser = method_parser())]
    pub method: Method,
    /// Leave these measurements out (comma-separated ids), e.g. the outliers `ml` listed.
    #[arg(long, value_delimiter = ',')]
    pub exclude: Vec<String>,
    /// Stop when ε falls to this, mm [default: the session's `solver.threshold`]
    #[arg(long, value_name = "MM", value_parser = values::number(values::Range::non_negative("mm").at_most(limits::THRESHOLD_MM)))]
    pub threshold: Option<f64>,
    /// Most updates [default: the session's `solver.max_iterations`]
    #[arg(long, value_name = "N", value_parser = values::count(0, MAX_ITERATIONS))]
    pub max_iterations: Option<usize>,
    /// Relative SVD tolerance of the paper's method (fraction of the largest singular value).
    #[arg(long, default_value_t = crate::engine::calibrate::solve::paper::DEFAULT_SVD_TOLERANCE, value_parser = values::number(values::Range::fraction_open()))]
    pub svd_tolerance: f64,
    /// Pairing of a station's measurements in the paper's method: `disjoint` (the paper's (1,2),(3,4),(5,6)) or `all`.
    #[arg(long, default_value = "disjoint", value_parser = values::Keywords::plain(["disjoint", "all"], Pairing::parse))]
    pub pairs: Pairing,
    /// Write the result even when the identify centres still scatter beyond 10 mm after calibration (a failed calibration: wrong pose convention, joint unit, robot model or side), e.g. to study it.
    #[arg(long)]
    pub accept_implausible: bool,
    /// Skip the held-out figure (each identify measurement's centre predicted by a calibration made without it; ml: one Gauss-Newton step per measurement, paper: its loop rerun without each, 10-fold above 50 measurements).
    #[arg(long)]
    pub no_held_out: bool,
    /// `-q`: [`QUIET_HELP`].
    #[arg(long, short, help = QUIET_HELP)]
    pub quiet: bool,
    /// Settings of the `ml` method (last: their own heading in the help).
    #[command(flatten)]
    pub ml: MlArgs,
}

/// Most updates `--max-iterations` takes: the engine's plausibility limit.
#[allow(
    clippy::cast_possible_truncation,
    clippy::cast_sign_loss,
    reason = "a whole, positive number far below usize::MAX"
)]
const MAX_ITERATIONS: usize = limits::MAX_ITERATIONS as usize;

/// Refuses a finished calibration whose identify centres scatter beyond
/// any sensor and robot ([`plausible::check_calibration`]), unless
/// `accept` (then it is a warning on stderr, unless `quiet`).
///
/// # Errors
/// Status 2 naming the scatter and the likely causes, and the flag that
/// writes the result anyway.
pub fn check_plausible(
    session: &session::Session,
    cal: &solve::Calibration,
    (accept, quiet): (bool, bool),
    path: &Path,
) -> Result<(), CliError> {
    match plausible::check_calibration(session, cal) {
        Ok(()) => Ok(()),
        Err(e) if accept => {
            if !quiet {
                eprintln!("warning: {e} (written anyway: --accept-implausible)");
            }
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
#[command(next_help_heading = "Options of the ml method")]
pub struct MlArgs {
    /// σ of the joint readings, deg.
    #[arg(long, value_name = "DEG", default_value_t = MlOptions::default().joint_sigma_deg, value_parser = values::number(values::Range::non_negative("deg")))]
    pub joint_sigma: f64,
    /// σ of a centre given in the session, mm.
    #[arg(long, value_name = "MM", default_value_t = MlOptions::default().centre_sigma, value_parser = values::number(values::Range::positive("mm")))]
    pub centre_sigma: f64,
    /// Floor of each principal σ of a stripe centre's covariance, mm.
    #[arg(long, value_name = "MM", default_value_t = MlOptions::default().sensor_sigma_floor, value_parser = values::number(values::Range::positive("mm")))]
    pub sensor_sigma_floor: f64,
    /// No prior on the kinematic deviations.
    #[arg(long)]
    pub no_prior: bool,
    /// Prior σ of angle deviations, deg.
    #[arg(long, value_name = "DEG", default_value_t = MlOptions::default().prior_angle_deg, value_parser = values::number(values::Range::positive("deg")))]
    pub prior_angle: f64,
    /// Prior σ of length deviations, mm.
    #[arg(long, value_name = "MM", default_value_t = MlOptions::default().prior_length, value_parser = values::number(values::Range::positive("mm")))]
    pub prior_length: f64,
    /// Robust loss.
    #[arg(long, default_value = MlOptions::default().loss.as_str(), value_parser = values::Keywords::plain(Loss::ALL.map(Loss::as_str), Loss::parse))]
    pub loss: Loss,
    /// Robust loss scale (help text with the engine's default).
    #[arg(
        long,
        value_name = "SIGMA",
        value_parser = values::number(values::Range::positive("σ")),
        help = format!(
            "Robust loss scale, σ of the whitened residual norm [default: {}, the 99 % point of χ(3)]",
            crate::engine::base::numeric::approx(MlOptions::default().loss_scale)
        )
    )]
    pub loss_scale: Option<f64>,
    /// Relative pivot tolerance of the identifiability QR.
    #[arg(long, default_value = crate::engine::base::numeric::show(MlOptions::default().rank_tolerance), value_parser = values::number(values::Range::fraction_open()))]
    pub rank_tolerance: f64,
    /// Skip the leave-one-station-out cross-validation.
    #[arg(long)]
    pub no_cross_validation: bool,
    /// Pose-only sessions: σ of each base-frame coordinate from the error of the flange poses the controller reports (the robot's accuracy), mm [default: estimated from the data at the solution (variance-component estimation)]
    #[arg(long, value_name = "MM", value_parser = values::number(values::Range::positive("mm")))]
    pub pose_sigma: Option<f64>,
}

impl MlArgs {
    /// The options these flags give, the rest at their defaults.
    #[must_use]
    pub fn options(&self) -> MlOptions {
        let d = MlOptions::default();
        MlOptions {
            joint_sigma_deg: self.joint_sigma,
            centre_sigma: self.centre_sigma,
            sensor_sigma_floor: self.sensor_sigma_floor,
            prior: d.prior && !self.no_prior,
            prior_angle_deg: self.prior_angle,
            prior_length: self.prior_length,
            loss: self.loss,
            loss_scale: self.loss_scale.unwrap_or(d.loss_scale),
            rank_tolerance: self.rank_tolerance,
            cross_validation: d.cross_validation && !self.no_cross_validation,
            pose_sigma: self.pose_sigma.or(d.pose_sigma),
        }
    }
}

/// A `--hand-eye` file (a JSON 4x4, or a session or result file's
/// `hand_eye`), read by the engine's one transform reader (capped, held
/// to the session rules), its errors led by the flag.
///
/// # Errors
/// Status 2: the file cannot be read, or its transform is not plausible.
pub fn hand_eye_file(path: &Path) -> Result<nalgebra::Isometry3<f64>, CliError> {
    use crate::engine::tools::plan::RequestError;
    let (hand_eye, note) =
        crate::engine::tools::plan::read_hand_eye(path).map_err(|e| match e {
            RequestError::File { message, .. } => {
                let message = message.strip_prefix("hand_eye: ").unwrap_or(&message);
                CliError::input(format!("--hand-eye: {message} ({})", path.display()))
            }
            other => CliError::input(other.to_string()),
        })?;
    if let Some(note) = note {
        let note = note.strip_prefix("hand_eye: ").unwrap_or(&note);
        sayln!("note: --hand-eye: {note} ({})", path.display());
    }
    Ok(hand_eye)
}

/// The robot presets' keys, for the help of every `--robot`:
/// `irb2400, irb120, ur5e`.
#[must_use]
pub fn preset_keys() -> String {
    crate::engine::base::robot::RobotChoice::ALL
        .map(crate::engine::base::robot::RobotChoice::key)
        .join(", ")
}

/// `--method`: the engine's methods, the default first.
fn method_parser() -> values::Keywords<Method> {
    values::Keywords::plain(Method::ALL.map(Method::as_str), Method::parse)
}

/// `--dh`: a DH table's convention.
fn dh_parser() -> values::Keywords<crate::engine::files::robot_import::DhConvention> {
    values::Keywords::new(
        vec![
            (
                "standard",
                Some("Denavit-Hartenberg: Rz(theta)·Tz(d)·Tx(a)·Rx(alpha) per row"),
            ),
            (
                "modified",
                Some(
                    "Craig's modified DH (with Hayati's optional beta), the model's own: Rx(alpha)·Tx(a)·Ry(beta)·Rz(theta)·Tz(d) per row",
                ),
            ),
        ],
        parse_dh,
    )
}

/// `standard` or `modified` (a DH table's convention).
fn parse_dh(s: &str) -> Option<crate::engine::files::robot_import::DhConvention> {
    match s.to_ascii_lowercase().as_str() {
        "standard" | "dh" => Some(crate::engine::files::robot_import::DhConvention::Standard),
        "modified" | "mdh" => Some(crate::engine::files::robot_import::DhConvention::Modified),
        _ => None,
    }
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
            HandEyeSource::Linear(g) => sayln!(
                "initial base-from-sensor (linear, from every identify measurement): points scatter {:.4} mm rms",
                g.rms_mm
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
        updates,
    } = cal.stop
        && let Some(w) = no_update_warning(updates, epsilon, Some(threshold))
        && !quiet
    {
        // Said plainly: a threshold at or above the starting ε calibrates
        // nothing.
        eprintln!("warning: {w}");
    }
    check_plausible(
        &session,
        &cal,
        (args.accept_implausible, quiet),
        &args.session,
    )?;
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

    /// The defaults `--help` shows for the ml method are the engine's.
    #[test]
    fn ml_defaults_are_the_engines() {
        let args: CalibrateArgs = parse_flags(&["calibrate", "s.json", "-o", "r.json"]);
        assert_eq!(args.ml.options(), MlOptions::default());
        assert_eq!(
            args.svd_tolerance,
            crate::engine::calibrate::solve::paper::DEFAULT_SVD_TOLERANCE
        );
        assert_eq!(args.method, Method::Ml);
        let args: CalibrateArgs = parse_flags(&[
            "calibrate",
            "s.json",
            "-o",
            "r.json",
            "--rank-tolerance",
            "1e-9",
            "--loss",
            "cauchy",
            "--loss-scale",
            "2.5",
        ]);
        let o = args.ml.options();
        assert_eq!(
            (o.rank_tolerance, o.loss, o.loss_scale),
            (1e-9, Loss::Cauchy, 2.5)
        );
    }

    /// Issue 31: `1e308` was printed as 309 digits.
    #[test]
    fn long_numbers_are_shown_in_scientific_notation() {
        let long = format!("{}", 1e308_f64);
        assert_eq!(long.len(), 309);
        assert_eq!(
            readable_numbers(&format!("tolerance must be in (0, 1), got {long}")),
            "tolerance must be in (0, 1), got 1e308"
        );
        assert_eq!(
            readable_numbers(&format!("found -{long} mm")),
            "found -1e308 mm"
        );
        let tiny = format!("{}", 1e-300_f64);
        assert_eq!(readable_numbers(&format!("got {tiny}.")), "got 1e-300.");
        // Everyday numbers, ids and numbers inside words are kept.
        let kept = "pose p123456789012345678901 at 1050.25 mm, line 12: 0.001 (file_2026.csv)";
        assert_eq!(readable_numbers(kept), kept);
        assert_eq!(
            readable_numbers("1234567890123456789x"),
            "1234567890123456789x"
        );
    }

    #[test]
    fn engine_names_become_flags() {
        let names = [
            (
                "n_identify + n_validate",
                "--identify-stations + --validate-stations",
            ),
            ("stripe_noise", "--stripe-noise"),
        ];
        assert_eq!(
            name_flags("stripe_noise 100 mm is not plausible", &names),
            "--stripe-noise 100 mm is not plausible"
        );
        assert_eq!(
            name_flags("n_identify + n_validate is 600: at most 500", &names),
            "--identify-stations + --validate-stations is 600: at most 500"
        );
        assert_eq!(
            name_flags("max_stripe_noise and stripe_noise_x stay", &names),
            "max_stripe_noise and stripe_noise_x stay"
        );
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
