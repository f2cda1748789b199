//! `spherecal export-model`: writes the calibrated model of a result file
//! as the FORMAT.md `robot` block (JSON), a CSV table of MDH parameters, a
//! URDF (a fragment of our own, or the user's URDF calibrated), UR's
//! calibration YAML, or the hand-eye as a controller's tool data,
//! atomically. A thin caller of [`crate::engine::tools::report`]'s
//! `model`, `urdf_back`, `ur_calibration` and `tool_data`.

use std::path::PathBuf;

use clap::{Args, ValueEnum};

use super::CliError;
use crate::engine::base::robot::controller::Controller;
use crate::engine::files::format;
use crate::engine::tools::report::model::{self, ModelFormat};
use crate::engine::tools::report::tool_data::{self, ToolTarget};
use crate::engine::tools::report::{ur_calibration, urdf_back};

/// Output format (`--format`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum FormatArg {
    /// The FORMAT.md `robot` block (deg, mm), pasteable into a session.
    Json,
    /// The MDH table with calibrated − nominal, then base, flange and hand-eye (deg, mm).
    Csv,
    /// A URDF with the calibrated joint origins (m, rad): with --robot, that URDF with only its joint origins changed and a sensor link added; without, a chain of our own.
    Urdf,
    /// The calibrated hand-eye as a controller's tool data, with its 1σ (--controller); for every result, pose-only ones too.
    Tool,
    /// Universal Robots' calibration YAML (`kinematics:`, as ur_description and ur_robot_driver read it).
    UrCalibration,
}

impl FormatArg {
    /// How the format is called in messages.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Json => "JSON robot-block",
            Self::Csv => "MDH CSV",
            Self::Urdf => "URDF",
            Self::Tool => "tool-data",
            Self::UrCalibration => "UR calibration",
        }
    }
}

/// `--controller`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ControllerArg {
    /// ABB RAPID `tooldata` (mm, quaternion).
    Abb,
    /// KUKA KRL `TOOL_DATA` (mm, A B C deg).
    Kuka,
    /// FANUC UTOOL values (X Y Z W P R) and a TP line setting them through a position register.
    Fanuc,
    /// Universal Robots TCP (`set_tcp`, m and rotation vector).
    Ur,
    /// ROS 2: a `static_transform_publisher` line and a URDF joint for a `sensor` link.
    Ros,
}

impl ControllerArg {
    /// The engine's target.
    fn target(self) -> ToolTarget {
        match self {
            Self::Abb => ToolTarget::Controller(Controller::Abb),
            Self::Kuka => ToolTarget::Controller(Controller::Kuka),
            Self::Fanuc => ToolTarget::Controller(Controller::Fanuc),
            Self::Ur => ToolTarget::Controller(Controller::Ur),
            Self::Ros => ToolTarget::Ros,
        }
    }
}

/// `spherecal export-model`.
#[derive(Debug, Args)]
pub struct ExportModelArgs {
    /// Result file (FORMAT.md `spherecal-result`).
    pub result: PathBuf,
    /// Output format.
    #[arg(long, value_enum)]
    pub format: FormatArg,
    /// Where to write the model.
    #[arg(long, short)]
    pub out: PathBuf,
    /// For --format tool: the controller whose tool data to write; for --format ur-calibration, `ur` names the robot a UR whatever its name.
    #[arg(long, value_enum)]
    pub controller: Option<ControllerArg>,
    /// For --format urdf: the URDF the session's robot came from, written back with only the calibrated joint origins changed and a `sensor` link added.
    #[arg(long, value_name = "URDF")]
    pub robot: Option<PathBuf>,
    /// For --format urdf --robot: the chain's tip link, when the URDF has several end links (as import's --tip).
    #[arg(long, requires = "robot")]
    pub tip: Option<String>,
    /// `-q`: [`QUIET_HELP`](super::QUIET_HELP).
    #[arg(long, short, help = super::QUIET_HELP)]
    pub quiet: bool,
}

/// Loads the result, exports its model and writes it atomically.
///
/// # Errors
/// [`CliError`] with status 2 when the result file cannot be read or is
/// not a valid result, or the output is refused or cannot be written.
pub fn run(args: &ExportModelArgs) -> Result<(), CliError> {
    let mut inputs = vec![args.result.as_path()];
    if let Some(r) = &args.robot {
        inputs.push(r.as_path());
    }
    CliError::guard_output(&args.out, &inputs)?;
    if args.robot.is_some() && args.format != FormatArg::Urdf {
        return Err(CliError::input(
            "--robot goes with --format urdf (the URDF to write back calibrated)".to_string(),
        ));
    }
    let controller = args.controller;
    match (args.format, controller) {
        (FormatArg::Tool, None) => {
            return Err(CliError::input(
                "--format tool needs --controller abb|kuka|fanuc|ur|ros".to_string(),
            ));
        }
        (FormatArg::UrCalibration, Some(c)) if c != ControllerArg::Ur => {
            return Err(CliError::input(
                "--format ur-calibration is for a UR arm: --controller ur or none".to_string(),
            ));
        }
        (FormatArg::Json | FormatArg::Csv | FormatArg::Urdf, Some(_)) => {
            return Err(CliError::input(
                "--controller goes with --format tool or ur-calibration".to_string(),
            ));
        }
        _ => {}
    }
    let result = format::load_result(&args.result).map_err(|e| CliError::from_file(&e, true))?;
    let source = args.result.display().to_string();
    let fail = |e: &dyn std::fmt::Display| CliError::input(format!("{e} ({source})"));
    let mut notes = Vec::new();
    let text = match (args.format, &args.robot) {
        (FormatArg::Tool, _) => {
            let target = controller.map_or(ToolTarget::Ros, ControllerArg::target);
            tool_data::tool_export(&result, target, &source)
        }
        (FormatArg::UrCalibration, _) => {
            ur_calibration::ur_calibration(&result, &source, controller.is_some())
                .map_err(|e| fail(&e))?
        }
        (FormatArg::Urdf, Some(urdf)) => {
            let text = format::read_text(urdf, format::Cap::URDF)
                .map_err(|e| CliError::input(format!("{}: {e}", urdf.display())))?;
            let done = urdf_back::calibrated_urdf(&result, &text, urdf, args.tip.as_deref())
                .map_err(|e| fail(&e))?;
            notes.push(format!(
                "joint origins calibrated: {}; `sensor` link added under {}",
                done.joints.join(", "),
                done.tip
            ));
            if result.hand_eye_only() {
                notes.push(
                    "a pose-only result: the kinematics were not calibrated, the joint origins are written as they were (to rounding)".to_string(),
                );
            }
            done.text
        }
        (f, _) => {
            let format = match f {
                FormatArg::Json => ModelFormat::Json,
                FormatArg::Csv => ModelFormat::Csv,
                _ => ModelFormat::Urdf,
            };
            model::export(&result, format, &source).map_err(|e| fail(&e))?
        }
    };
    format::write_atomic(&args.out, text.as_bytes()).map_err(|e| CliError::from_file(&e, false))?;
    if args.quiet {
        return Ok(());
    }
    if args.format == FormatArg::Tool {
        say!("{text}");
    }
    for n in &notes {
        sayln!("{n}");
    }
    if args.format == FormatArg::Tool {
        sayln!(
            "wrote the tool data of {} to {}",
            args.result.display(),
            args.out.display()
        );
    } else {
        sayln!(
            "wrote the {} model of {} to {}",
            args.format.name(),
            args.result.display(),
            args.out.display()
        );
    }
    Ok(())
}
