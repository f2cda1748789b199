//! The compensating use case in one entry, [`compensate_file`], that the
//! command line and the workbench both call: the TCP (the calibrated
//! sensor, the flange, or a tool file), the targets read in any layout
//! the program readers know, the model of the result (with the session
//! it was calibrated from, when given) and every target compensated,
//! with the progress of each.

use std::path::PathBuf;

use super::tool::{self, ToolError};
use super::tool_only::{self, CurrentToolError};
use super::{CompensateError, CompensateProgress, Compensation, Model, Options, Tcp};
use crate::engine::base::session::Session;
use crate::engine::calibrate::solve::Control;
use crate::engine::files::format::ResultFile;
use crate::engine::files::program::{self, PoseFile, ProgramError, ReadSpec};

/// The TCP the targets are poses of.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum TcpSource {
    /// The calibrated sensor (the result's hand-eye).
    Sensor,
    /// The flange (no tool).
    Flange,
    /// A tool of the user's: a JSON file with `flange_from_tcp` (4×4, mm).
    ToolFile(PathBuf),
}

/// Everything a compensation needs.
#[derive(Debug, Clone)]
pub struct CompensateRequest {
    /// The result whose calibrated and nominal models compensate.
    pub result: ResultFile,
    /// The session the result was calibrated from, for a result that does
    /// not record the joints of its poses (older results).
    pub session: Option<Session>,
    /// A session that is not the result's is left out with a note,
    /// instead of refused (the workbench's open session).
    pub session_if_it_fits: bool,
    /// The targets file.
    pub targets: PathBuf,
    /// How to read it (layout, convention, columns; detected when not given).
    pub read: ReadSpec,
    /// The TCP.
    pub tcp: TcpSource,
    /// Joint targets and the flag limits.
    pub options: Options,
}

/// A targets file compensated.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// The targets as read.
    pub file: PoseFile,
    /// The model they were compensated with.
    pub model: Model,
    /// Every target, the summary and the compensated text.
    pub compensation: Compensation,
    /// What to know about the run as a whole (a session left out).
    pub notes: Vec<String>,
}

/// Why a targets file could not be compensated, by step.
#[derive(Debug, thiserror::Error)]
pub enum CompensateFileError {
    /// The tool file cannot be read.
    #[error(transparent)]
    Tool(#[from] ToolError),
    /// The current-tool file cannot be read.
    #[error(transparent)]
    CurrentTool(#[from] CurrentToolError),
    /// The targets file cannot be read (naming it and the line).
    #[error(transparent)]
    Targets(#[from] ProgramError),
    /// The result (or the session given with it) gives no model to
    /// compensate with.
    #[error("{0}")]
    Model(CompensateError),
    /// A target cannot be compensated (naming every one), or cancelled.
    #[error("{0}")]
    Compensate(CompensateError),
}

/// Compensates the request's targets (module doc). `progress` hears of
/// each target; [`Control::Cancel`] stops at the next one.
///
/// # Errors
/// [`CompensateFileError`]: the step that failed and why.
pub fn compensate_file(
    request: CompensateRequest,
    progress: &mut dyn FnMut(&CompensateProgress) -> Control,
) -> Result<Outcome, CompensateFileError> {
    let tcp = match &request.tcp {
        TcpSource::Sensor => Tcp::Sensor,
        TcpSource::Flange => Tcp::Flange,
        TcpSource::ToolFile(path) => Tcp::Tool(tool::read_tool(path)?),
    };
    let file = program::read_pose_file(&request.targets, &request.read)?;
    let mut notes = Vec::new();
    let model = match Model::new(&request.result, request.session.as_ref(), tcp.clone()) {
        Err(CompensateError::Session(why)) if request.session_if_it_fits => {
            notes.push(format!("the open session is not used: {why}"));
            Model::new(&request.result, None, tcp)
        }
        other => other,
    }
    .map_err(CompensateFileError::Model)?;
    let compensation = super::compensate(&model, &file, &request.options, progress)
        .map_err(CompensateFileError::Compensate)?;
    Ok(Outcome {
        file,
        model,
        compensation,
        notes,
    })
}

/// A targets file rewritten for the controller's current tool with a
/// pose-only result ([`tool_only`]).
#[derive(Debug, Clone)]
pub struct ToolOnlyOutcome {
    /// The targets as read.
    pub file: PoseFile,
    /// The tool the controller holds now, `flange_from_tcp` (mm).
    pub current_tool: nalgebra::Isometry3<f64>,
    /// Every target and the rewritten text.
    pub compensation: Compensation,
}

/// The targets of `targets` rewritten so that the controller, still with
/// the tool of `current_tool` (a file), puts the result's calibrated
/// sensor where each target says ([`tool_only`]); for a pose-only result.
///
/// # Errors
/// [`CompensateFileError`]: a result that calibrated the kinematics (its
/// targets are compensated through the model instead), a file that
/// cannot be read, a target that is no pose, or cancelled.
pub fn compensate_file_tool_only(
    result: &ResultFile,
    targets: &std::path::Path,
    read: &ReadSpec,
    current_tool: &std::path::Path,
    progress: &mut dyn FnMut(&CompensateProgress) -> Control,
) -> Result<ToolOnlyOutcome, CompensateFileError> {
    if !result.hand_eye_only() {
        return Err(CompensateFileError::Model(CompensateError::Session(
            "--current-tool is for a pose-only result; this result calibrated the robot's kinematics: compensate through its model (--tcp sensor) and set its tool data".to_string(),
        )));
    }
    let file = program::read_pose_file(targets, read)?;
    let convention = file.format.convention().or(read.convention);
    let tool = tool_only::read_current_tool(current_tool, convention)?;
    let compensation = tool_only::compensate_tool_only(&file, &result.hand_eye, &tool, progress)
        .map_err(CompensateFileError::Compensate)?;
    Ok(ToolOnlyOutcome {
        file,
        current_tool: tool,
        compensation,
    })
}
