//! Compensation with a pose-only result (issue 33, `compensate
//! --current-tool`): the kinematics were not calibrated, only the sensor
//! (the hand-eye `H`, flange → sensor). The controller still holds the
//! tool `C` the program was taught with; a target `T` is where the
//! sensor is meant to be. The controller puts the flange at `P · C⁻¹` for
//! a commanded pose `P`, the real sensor then at `P · C⁻¹ · H`, so the
//! pose to command is `P = T · H⁻¹ · C`: the target moved by the
//! difference between the calibrated sensor and the current tool, in the
//! same layout with every other byte kept. A joint target does not
//! depend on the tool and is kept as written.
//!
//! The current tool is read from a JSON file (`flange_from_tcp`, 4×4 mm,
//! as `--tcp` reads) or from a text with the tool's values in the
//! targets' convention (`x, y, z, w, p, r` for FANUC), the numbers of its
//! one line that is not a comment.

use std::path::{Path, PathBuf};

use nalgebra::Isometry3;

use super::arms::BranchRule;
use super::report::Summary;
use super::target::{nearest, written_numbers};
use super::{CompensateError, CompensateProgress, Compensation, TargetFailure, TargetReport};
use crate::engine::base::robot::controller::FlangeConvention;
use crate::engine::base::robot::ik::DOF;
use crate::engine::calibrate::solve::Control;
use crate::engine::files::format::{Cap, read_text};
use crate::engine::files::program::{PoseFile, TargetValue};

/// The note every tool-only compensation carries.
pub const TOOL_ONLY_NOTE: &str = "a pose-only result: the robot's kinematics were not calibrated; each target is moved by the difference between the calibrated sensor and the current tool only, so that the controller, still using its current tool, puts the calibrated sensor where the target says";

/// A current-tool file that gives no tool.
#[derive(Debug, thiserror::Error)]
#[error("current tool {}: {message}", path.display())]
pub struct CurrentToolError {
    /// The file.
    pub path: PathBuf,
    /// What is wrong.
    pub message: String,
}

/// Reads the tool the controller holds now (module doc). `convention`:
/// the targets' pose convention, for a text of values.
///
/// # Errors
/// [`CurrentToolError`] naming the file and what is wrong.
pub fn read_current_tool(
    path: &Path,
    convention: Option<FlangeConvention>,
) -> Result<Isometry3<f64>, CurrentToolError> {
    let fail = |message: String| CurrentToolError {
        path: path.to_path_buf(),
        message,
    };
    let text = read_text(path, Cap::SESSION).map_err(|e| fail(e.to_string()))?;
    if text.trim_start().starts_with(['{', '[']) {
        return super::tool::read_tool(path).map_err(|e| fail(e.source.to_string()));
    }
    let convention = convention.ok_or_else(|| {
        fail("a text of tool values needs the targets' pose convention (a robot program's language, or --pose-convention)".to_string())
    })?;
    let lines: Vec<&str> = text
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with(['!', '#', ';', '/']))
        .collect();
    let [line] = lines.as_slice() else {
        return Err(fail(format!(
            "{} lines of values, one is needed: the tool's {}",
            lines.len(),
            convention.describe()
        )));
    };
    let values = line
        .split(|c: char| c == ',' || c.is_whitespace())
        .filter(|s| !s.is_empty())
        .map(|s| {
            s.parse::<f64>()
                .map_err(|_| fail(format!("`{s}` is not a number")))
        })
        .collect::<Result<Vec<f64>, _>>()?;
    convention
        .pose_from_values(&values)
        .map_err(|e| fail(format!("{e} ({})", convention.describe())))
}

/// Every target of `file` as the controller, still with `current_tool`,
/// must be told to put the sensor `hand_eye` on it (module doc).
///
/// # Errors
/// A target whose values are no pose, a rewrite that fails, or the caller
/// cancelled.
pub fn compensate_tool_only(
    file: &PoseFile,
    hand_eye: &Isometry3<f64>,
    current_tool: &Isometry3<f64>,
    progress: &mut dyn FnMut(&CompensateProgress) -> Control,
) -> Result<Compensation, CompensateError> {
    let shift = hand_eye.inverse() * current_tool;
    let total = file.order.len();
    let mut targets = Vec::with_capacity(total);
    let mut failed = Vec::new();
    for (done, &index) in file.order.iter().enumerate() {
        let t = &file.targets[index];
        let mut report = TargetReport {
            index,
            name: t.name.clone(),
            line: t.line,
            joints_target: false,
            written: true,
            nominal_joints: [0.0; DOF],
            joints: [0.0; DOF],
            branch: BranchRule::First,
            wanted: Isometry3::identity(),
            commanded: Isometry3::identity(),
            correction_mm: 0.0,
            correction_deg: 0.0,
            joint_change_deg: 0.0,
            sigma_mm: None,
            nearest_identify_deg: None,
            outside_mm: 0.0,
            flags: Vec::new(),
            values: Vec::new(),
            config_update: None,
            notes: Vec::new(),
        };
        match &t.value {
            TargetValue::Pose { values, convention } => match convention.pose_from_values(values) {
                Ok(wanted) => {
                    let commanded = wanted * shift;
                    report.wanted = wanted;
                    report.commanded = commanded;
                    report.correction_mm =
                        (commanded.translation.vector - wanted.translation.vector).norm();
                    report.correction_deg =
                        commanded.rotation.angle_to(&wanted.rotation).to_degrees();
                    report.values = nearest(
                        *convention,
                        &convention.values_from_pose(&commanded),
                        values,
                    );
                    targets.push(report);
                }
                Err(e) => failed.push(TargetFailure {
                    name: t.name.clone(),
                    line: t.line,
                    message: e.to_string(),
                }),
            },
            TargetValue::Joints { .. } => {
                report.joints_target = true;
                report.written = false;
                report.notes.push(
                    "a joint target does not depend on the tool: kept as written".to_string(),
                );
                targets.push(report);
            }
        }
        if progress(&CompensateProgress {
            done: done + 1,
            total,
            target: t.name.clone(),
        }) == Control::Cancel
        {
            return Err(CompensateError::Cancelled);
        }
    }
    if !failed.is_empty() {
        return Err(CompensateError::Targets(failed));
    }
    let edits: Vec<(usize, Vec<String>)> = targets
        .iter()
        .filter(|t| t.written)
        .map(|t| (t.index, written_numbers(file, t)))
        .collect();
    let text = file.rewritten(&edits).map_err(CompensateError::Rewrite)?;
    let mut notes = vec![TOOL_ONLY_NOTE.to_string()];
    if file.order.len() < file.targets.len() {
        notes.push(format!(
            "{} of {} positions are never moved to and are left as written",
            file.targets.len() - file.order.len(),
            file.targets.len()
        ));
    }
    let summary = Summary::of(&targets);
    Ok(Compensation {
        text,
        targets,
        summary,
        notes,
    })
}
