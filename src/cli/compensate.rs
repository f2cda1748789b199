//! `spherecal compensate`: the targets of a pose table or a robot program
//! compensated through a calibration, written in the same layout with
//! every other byte kept. A thin caller of the one engine entry
//! [`crate::engine::uses::compensate::compensate_file`].

use std::path::PathBuf;

use clap::{Args, ValueEnum};

use super::CliError;
use super::values::{Range, number};
use crate::engine::base::robot::controller::{Controller, FlangeConvention, ToolDigits};
use crate::engine::calibrate::solve::Control;
use crate::engine::files::format;
use crate::engine::files::program::{self, PoseFormat, ReadSpec};
use crate::engine::uses::compensate::{
    self, CompensateError, CompensateFileError, CompensateRequest, JointTargets, Options, Outcome,
    Tcp, TcpSource, report,
};

/// Rows of the target table printed without `--all`.
const TABLE_ROWS: usize = 20;

/// `--joint-targets`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum JointTargetsArg {
    /// The pose the nominal model gives the joints is the pose wanted (offline-programmed targets).
    Compensate,
    /// Leave joint targets as written (taught on the robot).
    Keep,
}

/// `spherecal compensate`.
#[derive(Debug, Args)]
pub struct CompensateArgs {
    /// Result file of the calibration (FORMAT.md `spherecal-result`): its calibrated model, its nominal model (calibrated minus joint errors) and hand-eye.
    #[arg(long)]
    pub result: PathBuf,
    /// The targets: TCP poses in the base frame, as a pose table (`id,x,y,z,…`, a header optional, any separator), a JSON pose list, or a robot program (ABB RAPID module, KUKA .src/.dat, FANUC .ls, URScript).
    #[arg(long)]
    pub targets: PathBuf,
    /// Where to write the compensated targets: the same layout, positions replaced, every other byte kept.
    #[arg(long, short)]
    pub out: PathBuf,
    /// How a pose table or JSON list writes a pose (a robot program's language fixes its own).
    #[arg(long, value_parser = super::scan_flags::convention_parser())]
    pub pose_convention: Option<FlangeConvention>,
    /// Force the targets' layout [default: detected from the content]
    #[arg(long, value_parser = super::scan_flags::pose_format_parser())]
    pub pose_format: Option<PoseFormat>,
    /// The pose columns of a pose table, in the convention's order [default: x,y,z,q1..q4 | a,b,c | w,p,r | rx,ry,rz | m11..m44]; without a header, every column in order, `id` the id and `-` one to skip (e.g. id,x,y,z,w,p,r or x,y,z,w,p,r,-)
    #[arg(long, value_delimiter = ',')]
    pub pose_columns: Vec<String>,
    /// The TCP the targets are poses of: `sensor` (the calibrated hand-eye, printed as tool data to set on the controller), `flange`, or a JSON file with a 4x4 matrix `flange_from_tcp` (rows, mm).
    #[arg(long, default_value = "sensor")]
    pub tcp: String,
    /// For a pose-only result (hand-eye calibrated, kinematics not): the tool data the controller holds now, with which the program was taught (a JSON file with a 4x4 matrix `flange_from_tcp`, rows, mm; or one line of the tool's values in the targets' convention, e.g. x,y,z,w,p,r for FANUC). Each target is rewritten so that the controller, still using this tool, puts the calibrated sensor where the target says.
    #[arg(long, value_name = "FILE")]
    pub current_tool: Option<PathBuf>,
    /// The result's session, for results that do not record the joints of their poses (`pose_joints`: older results): the poses choose the branch of a target without a configuration (the nearest pose's) and flag targets far in joint space from every identify pose.
    #[arg(long)]
    pub session: Option<PathBuf>,
    /// What a joint target (jointtarget, movej joints, E6AXIS, a FANUC position in joints) means.
    #[arg(long, value_enum, default_value = "compensate")]
    pub joint_targets: JointTargetsArg,
    /// Flag a target whose predicted 1σ residual (ml covariance) exceeds this, mm.
    #[arg(long, value_name = "MM", default_value_t = compensate::DEFAULT_SIGMA_TOLERANCE_MM, value_parser = number(Range::positive("mm")))]
    pub sigma_tolerance: f64,
    /// Flag a target farther than this from every identify pose (joint-space norm, deg; when the joints of the poses are known).
    #[arg(long, value_name = "DEG", default_value_t = compensate::DEFAULT_FAR_JOINTS_DEG, value_parser = number(Range::positive("deg")))]
    pub far_joints: f64,
    /// Flag a target whose working point lies farther than this outside the box of the working points at the identify poses (for the sensor: the identify sphere positions), mm.
    #[arg(long, value_name = "MM", default_value_t = compensate::DEFAULT_REGION_MARGIN_MM, value_parser = number(Range::non_negative("mm")))]
    pub region_margin: f64,
    /// Refuse (exit 2, nothing written) when a target is flagged, instead of compensating and listing it.
    #[arg(long)]
    pub strict: bool,
    /// List every target (help text with the table's length).
    #[arg(long, help = format!("List every target, not only the {TABLE_ROWS} largest corrections"))]
    pub all: bool,
    /// `-q`: [`QUIET_HELP`](super::QUIET_HELP).
    #[arg(long, short, help = super::QUIET_HELP)]
    pub quiet: bool,
}

/// Reads everything, compensates, writes the file atomically, prints the
/// tool data, the targets, the flagged ones and the summary.
///
/// # Errors
/// [`CliError`] with status 2 for bad input (an unreadable or invalid
/// file, an unreachable target, a flagged one with `--strict`), 1 when
/// the output cannot be written. Nothing is written on any error.
pub fn run(args: &CompensateArgs) -> Result<(), CliError> {
    let mut inputs = vec![args.result.as_path(), args.targets.as_path()];
    if let Some(s) = &args.session {
        inputs.push(s.as_path());
    }
    if !matches!(args.tcp.as_str(), "sensor" | "flange") {
        inputs.push(std::path::Path::new(&args.tcp));
    }
    if let Some(t) = &args.current_tool {
        inputs.push(t.as_path());
    }
    CliError::guard_output(&args.out, &inputs)?;
    let result = format::load_result(&args.result).map_err(|e| CliError::from_file(&e, true))?;
    if let Some(current) = &args.current_tool {
        return run_tool_only(args, &result, current);
    }
    if result.hand_eye_only() {
        // The tool data to install goes to standard output (what the user
        // copies), the refusal to standard error on one line.
        let file = program::read_pose_file(&args.targets, &read_spec(args)).ok();
        let controllers = file.as_ref().map_or_else(
            || Controller::ALL.to_vec(),
            |f| report::tool_controllers(f, args.pose_convention),
        );
        for c in controllers {
            sayln!("{}:", c.tool_data_kind());
            sayln!(
                "{}",
                c.tool_data_with(&result.hand_eye, report::TOOL_NAME, ToolDigits::Full)
                    .trim_end()
            );
        }
        return Err(CliError::input(format!(
            "{} ({})",
            CompensateError::PoseOnly,
            args.result.display()
        )));
    }
    let session = match &args.session {
        Some(p) => Some(format::load_session(p).map_err(|e| CliError::from_file(&e, true))?),
        None => None,
    };
    let tcp = match args.tcp.as_str() {
        "sensor" => TcpSource::Sensor,
        "flange" => TcpSource::Flange,
        path => TcpSource::ToolFile(PathBuf::from(path)),
    };
    let request = CompensateRequest {
        result,
        session,
        session_if_it_fits: false,
        targets: args.targets.clone(),
        read: read_spec(args),
        tcp,
        options: Options {
            joint_targets: match args.joint_targets {
                JointTargetsArg::Compensate => JointTargets::Compensate,
                JointTargetsArg::Keep => JointTargets::Keep,
            },
            sigma_tolerance_mm: args.sigma_tolerance,
            far_joints_deg: args.far_joints,
            region_margin_mm: args.region_margin,
        },
    };
    let targets = args.targets.display();
    let Outcome {
        file,
        model,
        compensation: done,
        ..
    } = compensate::compensate_file(request, &mut |_| Control::Continue).map_err(|e| match e {
        CompensateFileError::Tool(e) => CliError::input(e),
        CompensateFileError::CurrentTool(e) => CliError::input(e.to_string()),
        CompensateFileError::Targets(e) => CliError::input(e.to_string()),
        CompensateFileError::Model(e) => CliError::input(format!(
            "{e} ({})",
            args.session.as_ref().unwrap_or(&args.result).display()
        )),
        CompensateFileError::Compensate(
            e @ (CompensateError::Rewrite(_) | CompensateError::Cancelled),
        ) => CliError::internal(format!("{e} ({targets})")),
        CompensateFileError::Compensate(e) => CliError::input(format!("{e} ({targets})")),
    })?;
    if args.strict && done.summary.flagged > 0 {
        return Err(CliError::input(format!(
            "{} target(s) lie outside what the calibration saw (--strict), nothing written: {} ({})",
            done.summary.flagged,
            report::flagged(&done.targets).trim().replace('\n', "; "),
            args.targets.display()
        )));
    }
    format::write_atomic(&args.out, done.text.as_bytes())
        .map_err(|e| CliError::from_file(&e, false))?;
    if args.quiet {
        return Ok(());
    }
    sayln!("{}", report::file_line(&file));
    for w in &file.warnings {
        sayln!("  warning: {w}");
    }
    sayln!("TCP: {}", model.tcp.describe());
    if model.tcp == Tcp::Sensor {
        for (kind, text) in report::tool_data(&file, args.pose_convention, &model.tool) {
            sayln!("tool data to set on the controller ({kind}):");
            for line in text.lines() {
                sayln!("  {line}");
            }
        }
    }
    say!(
        "{}",
        report::table(&done.targets, (!args.all).then_some(TABLE_ROWS))
    );
    let flagged = report::flagged(&done.targets);
    if !flagged.is_empty() {
        sayln!("flagged (compensated and written; --strict refuses them):");
        say!("{flagged}");
    }
    for t in done.targets.iter().filter(|t| !t.notes.is_empty()) {
        for n in &t.notes {
            sayln!("  note: {} (line {}): {n}", t.name, t.line);
        }
    }
    for n in &done.notes {
        sayln!("note: {n}");
    }
    sayln!("{}", done.summary.line());
    sayln!("wrote {}", args.out.display());
    Ok(())
}

/// How the targets are read.
fn read_spec(args: &CompensateArgs) -> ReadSpec {
    ReadSpec {
        format: args.pose_format,
        convention: args.pose_convention,
        columns: (!args.pose_columns.is_empty()).then(|| args.pose_columns.clone()),
    }
}

/// `--current-tool`: a pose-only result's targets rewritten for the tool
/// the controller holds now.
fn run_tool_only(
    args: &CompensateArgs,
    result: &format::ResultFile,
    current: &std::path::Path,
) -> Result<(), CliError> {
    let targets = args.targets.display();
    let done = compensate::compensate_file_tool_only(
        result,
        &args.targets,
        &read_spec(args),
        current,
        &mut |_| Control::Continue,
    )
    .map_err(|e| match e {
        CompensateFileError::Compensate(
            e @ (CompensateError::Rewrite(_) | CompensateError::Cancelled),
        ) => CliError::internal(format!("{e} ({targets})")),
        CompensateFileError::Targets(e) => CliError::input(e.to_string()),
        e => CliError::input(format!("{e} ({targets})")),
    })?;
    format::write_atomic(&args.out, done.compensation.text.as_bytes())
        .map_err(|e| CliError::from_file(&e, false))?;
    if args.quiet {
        return Ok(());
    }
    sayln!("{}", report::file_line(&done.file));
    for w in &done.file.warnings {
        sayln!("  warning: {w}");
    }
    sayln!(
        "TCP: the calibrated sensor, reached through the current tool of {}",
        current.display()
    );
    say!(
        "{}",
        report::table(
            &done.compensation.targets,
            (!args.all).then_some(TABLE_ROWS)
        )
    );
    for t in done
        .compensation
        .targets
        .iter()
        .filter(|t| !t.notes.is_empty())
    {
        for n in &t.notes {
            sayln!("  note: {} (line {}): {n}", t.name, t.line);
        }
    }
    for n in &done.compensation.notes {
        sayln!("note: {n}");
    }
    sayln!("{}", done.compensation.summary.line());
    sayln!("wrote {}", args.out.display());
    Ok(())
}
