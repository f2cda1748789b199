//! The Compensate view's job work: the targets read, the model of the
//! result on show built and every target compensated by the one engine
//! entry `spherecal compensate` calls too
//! ([`compensate_file`](crate::engine::uses::compensate::compensate_file));
//! the view of it (one row per target, largest correction
//! first, the flags in words, the summary line and the tool data the
//! command line prints) with the compensated text; the file written
//! atomically, never over an input.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use nalgebra::Isometry3;

use crate::engine::base::robot::controller::FlangeConvention;
use crate::engine::calibrate::solve::Control;
use crate::engine::files::format::{refuse_inputs, write_atomic};
use crate::engine::files::program::PoseFile;
use crate::engine::uses::compensate::{
    self, CompensateError, CompensateFileError, CompensateRequest, Compensation, Model,
    TargetFailure, Tcp, report,
};

/// Compensates the request's targets by the one engine entry `spherecal
/// compensate` calls too ([`compensate::compensate_file`]; with
/// `current_tool`, a pose-only result's targets for the controller's
/// current tool, [`compensate::compensate_file_tool_only`]) and makes the
/// view of it; `progress` hears of each target, `cancel` stops at the
/// next one.
///
/// # Errors
/// The message, naming the file (and the target and line): a file that
/// cannot be read, a result without a 6-axis robot, an unreachable
/// target, "cancelled".
pub fn compensate_targets(
    request: CompensateRequest,
    current_tool: Option<PathBuf>,
    cancel: &AtomicBool,
    progress: &mut dyn FnMut(String, f64),
) -> Result<CompensationView, String> {
    let (targets, convention) = (request.targets.clone(), request.read.convention);
    let mut each = |p: &compensate::CompensateProgress| {
        let fraction = p.done as f64 / p.total.max(1) as f64;
        progress(
            format!("target {}: {} of {}", p.target, p.done, p.total),
            fraction,
        );
        if cancel.load(Ordering::Relaxed) {
            Control::Cancel
        } else {
            Control::Continue
        }
    };
    let fail = |e: CompensateFileError| match e {
        CompensateFileError::Model(e) => format!("{e} (the result on show)"),
        CompensateFileError::Compensate(CompensateError::Targets(failed)) if failed.len() > 1 => {
            failures_text(&failed, &targets)
        }
        CompensateFileError::Compensate(e) => format!("{e} ({})", targets.display()),
        e => e.to_string(),
    };
    if let Some(tool) = current_tool {
        let done = compensate::compensate_file_tool_only(
            &request.result,
            &request.targets,
            &request.read,
            &tool,
            &mut each,
        )
        .map_err(fail)?;
        let what = format!(
            "the controller's current tool ({}), moved to the calibrated sensor",
            tool.display()
        );
        return Ok(CompensationView::from_parts(
            done.compensation,
            &done.file,
            what,
            Vec::new(),
        ));
    }
    let done = compensate::compensate_file(request, &mut each).map_err(fail)?;
    let mut view = CompensationView::new(done.compensation, &done.file, &done.model, convention);
    view.notes.extend(done.notes);
    Ok(view)
}

/// Most failed targets the view lists, one a line; the rest are counted.
const MAX_LISTED_FAILURES: usize = 500;

/// Several failed targets for the view: a first line with their count and
/// the file, then one line each (name, line, why).
fn failures_text(failed: &[TargetFailure], targets: &Path) -> String {
    let mut text = format!(
        "{} targets cannot be compensated ({}):",
        failed.len(),
        targets.display()
    );
    for f in failed.iter().take(MAX_LISTED_FAILURES) {
        text.push('\n');
        text.push_str(&f.to_string());
    }
    if failed.len() > MAX_LISTED_FAILURES {
        text.push_str(&format!(
            "\nand {} more",
            failed.len() - MAX_LISTED_FAILURES
        ));
    }
    text
}

/// Writes the compensated text to `path` atomically (all or nothing),
/// refusing to write over the targets or tool file it was made from.
///
/// # Errors
/// The output is an input, or the write failed (the old file, if any,
/// is left as it was).
pub fn write_compensated(
    text: &str,
    path: &Path,
    inputs: &[&Path],
) -> Result<(), crate::app::error::JobError> {
    refuse_inputs(path, inputs)?;
    Ok(write_atomic(path, text.as_bytes())?)
}

/// One target of the table.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetRow {
    /// Its name (`P[3]`, `p10`, a table's id).
    pub name: String,
    /// Its 1-based line in the targets file.
    pub line: usize,
    /// TCP position correction `|commanded − wanted|`, mm.
    pub correction_mm: f64,
    /// Rotation correction, deg.
    pub correction_deg: f64,
    /// Largest joint change between the nominal and the calibrated
    /// solution, deg.
    pub joint_change_deg: f64,
    /// Predicted 1σ residual of the TCP position after compensation, mm
    /// (`ml` results only).
    pub sigma_mm: Option<f64>,
    /// Joint-space distance to the nearest identify pose, deg (when the
    /// joints of the poses are known).
    pub nearest_identify_deg: Option<f64>,
    /// Why it lies outside what the calibration saw, in words (empty:
    /// inside).
    pub flags: Vec<String>,
    /// A joint target left as written.
    pub kept: bool,
    /// What to know about it (a configuration kept or updated).
    pub notes: Vec<String>,
    /// The TCP pose wanted, base frame, mm.
    pub wanted: Isometry3<f64>,
    /// The TCP pose to command, base frame, mm.
    pub commanded: Isometry3<f64>,
}

/// A compensation as the view shows it.
#[derive(Debug, Clone, PartialEq)]
pub struct CompensationView {
    /// The targets file.
    pub targets: PathBuf,
    /// What the file is and how it was read: "pose table T.csv: in file
    /// order (layout detected)".
    pub file_line: String,
    /// The reader's warnings.
    pub warnings: Vec<String>,
    /// The TCP, for people.
    pub tcp: String,
    /// The tool data to set on the controller, per controller
    /// (description, text), when the TCP is the calibrated sensor.
    pub tool_data: Vec<(String, String)>,
    /// Every target, largest position correction first.
    pub rows: Vec<TargetRow>,
    /// The command line's summary line (targets, largest correction,
    /// flagged).
    pub summary: String,
    /// Targets flagged outside what the calibration saw.
    pub flagged: usize,
    /// What to know about the run as a whole.
    pub notes: Vec<String>,
    /// The compensated file: positions rewritten, every other byte kept.
    pub text: String,
}

impl CompensationView {
    /// The view of `done`, the compensation of `file` through `model`;
    /// `convention` is the one given for a table (it picks the
    /// controller whose tool data is shown; all four without one).
    #[must_use]
    pub fn new(
        done: Compensation,
        file: &PoseFile,
        model: &Model,
        convention: Option<FlangeConvention>,
    ) -> Self {
        let tool_data = if model.tcp == Tcp::Sensor {
            report::tool_data(file, convention, &model.tool)
                .into_iter()
                .map(|(kind, text)| (kind.to_string(), text))
                .collect()
        } else {
            Vec::new()
        };
        Self::from_parts(done, file, model.tcp.describe().to_string(), tool_data)
    }

    /// The view of `done`, the compensation of `file` for the TCP `tcp`
    /// (in words), with the tool data to set (controller, text).
    #[must_use]
    pub fn from_parts(
        done: Compensation,
        file: &PoseFile,
        tcp: String,
        tool_data: Vec<(String, String)>,
    ) -> Self {
        let file_line = report::file_line(file);
        // Largest first, as the command line's table.
        let rows = report::largest_first(&done.targets)
            .into_iter()
            .map(|t| TargetRow {
                name: t.name.clone(),
                line: t.line,
                correction_mm: t.correction_mm,
                correction_deg: t.correction_deg,
                joint_change_deg: t.joint_change_deg,
                sigma_mm: t.sigma_mm,
                nearest_identify_deg: t.nearest_identify_deg,
                flags: t
                    .flags
                    .iter()
                    .map(crate::engine::uses::compensate::Flag::describe)
                    .collect(),
                kept: !t.written,
                notes: t.notes.clone(),
                wanted: t.wanted,
                commanded: t.commanded,
            })
            .collect();
        Self {
            targets: file.path.clone(),
            file_line,
            warnings: file.warnings.clone(),
            tcp,
            tool_data,
            rows,
            summary: done.summary.line(),
            flagged: done.summary.flagged,
            notes: done.notes,
            text: done.text,
        }
    }

    /// The default name of the compensated file: `<stem>-compensated`
    /// with the targets file's extension.
    #[must_use]
    pub fn default_file_name(&self) -> String {
        let stem = self.targets.file_stem().map_or_else(
            || "targets".to_string(),
            |s| s.to_string_lossy().into_owned(),
        );
        match self.targets.extension() {
            Some(e) => format!("{stem}-compensated.{}", e.to_string_lossy()),
            None => format!("{stem}-compensated"),
        }
    }
}
