//! The Compensate view's job work: the targets read, the model of the
//! result on show built and every target compensated by the one engine
//! entry `spherecal compensate` calls too
//! ([`compensate_file`](crate::engine::uses::compensate::compensate_file));
//! the view of it (one row per target, largest correction
//! first, the flags in words, the summary line and the tool data the
//! command line prints) with the compensated text; the file written
//! atomically, never over an input.

use std::path::{Path, PathBuf};

use crate::app::job::Worker;
use crate::app::plan::job::report;
use crate::engine::base::robot::controller::FlangeConvention;
use crate::engine::files::format::{refuse_inputs, write_atomic};
use crate::engine::files::program::PoseFile;
use crate::engine::uses::compensate::{
    self, CompensateError, CompensateFileError, CompensateRequest, Compensation, Model,
    TargetFailure, TargetReport, Tcp, report, report::Summary,
};

/// Compensates the request's targets by the one engine entry `spherecal
/// compensate` calls too ([`compensate::compensate_file`]; with
/// `current_tool`, a pose-only result's targets for the controller's
/// current tool, [`compensate::compensate_file_tool_only`]) and makes the
/// view of it; `w` hears of each target, Cancel stops at the next one.
///
/// # Errors
/// The message, naming the file (and the target and line): a file that
/// cannot be read, a result without a 6-axis robot, an unreachable
/// target, "cancelled".
pub fn compensate_targets(
    request: CompensateRequest,
    current_tool: Option<PathBuf>,
    w: &Worker,
) -> Result<CompensationView, String> {
    let (targets, convention) = (request.targets.clone(), request.read.convention);
    let mut each = |p: &compensate::CompensateProgress| {
        let fraction = p.done as f64 / p.total.max(1) as f64;
        let text = format!("target {}: {} of {}", p.target, p.done, p.total);
        report(w, text, Some(fraction))
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
            done.file,
            what,
            Vec::new(),
        ));
    }
    let done = compensate::compensate_file(request, &mut each).map_err(fail)?;
    let mut view = CompensationView::new(done.compensation, done.file, &done.model, convention);
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

/// Why a target is flagged, in words (empty: not flagged).
#[must_use]
pub fn flags_text(target: &TargetReport) -> String {
    let why: Vec<String> = target
        .flags
        .iter()
        .map(compensate::Flag::describe)
        .collect();
    why.join("; ")
}

/// A compensation as the view shows it: the engine's reports as they
/// came, the targets largest correction first.
#[derive(Debug, Clone, PartialEq)]
pub struct CompensationView {
    /// The targets as read (path, layout, warnings).
    pub file: PoseFile,
    /// The TCP, for people.
    pub tcp: String,
    /// The tool data to set on the controller, per controller
    /// (description, text), when the TCP is the calibrated sensor.
    pub tool_data: Vec<(String, String)>,
    /// Every target, largest position correction first (as the command
    /// line's table).
    pub rows: Vec<TargetReport>,
    /// The command line's summary (targets, largest correction, flagged).
    pub summary: Summary,
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
        file: PoseFile,
        model: &Model,
        convention: Option<FlangeConvention>,
    ) -> Self {
        let tool_data = if model.tcp == Tcp::Sensor {
            report::tool_data(&file, convention, &model.tool)
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
        file: PoseFile,
        tcp: String,
        tool_data: Vec<(String, String)>,
    ) -> Self {
        let rows = report::largest_first(&done.targets).into_iter().cloned();
        Self {
            rows: rows.collect(),
            file,
            tcp,
            tool_data,
            summary: done.summary,
            notes: done.notes,
            text: done.text,
        }
    }

    /// The targets file.
    #[must_use]
    pub fn targets(&self) -> &Path {
        &self.file.path
    }

    /// The default name of the compensated file: `<stem>-compensated`
    /// with the targets file's extension.
    #[must_use]
    pub fn default_file_name(&self) -> String {
        let stem = self.targets().file_stem().map_or_else(
            || "targets".to_string(),
            |s| s.to_string_lossy().into_owned(),
        );
        match self.targets().extension() {
            Some(e) => format!("{stem}-compensated.{}", e.to_string_lossy()),
            None => format!("{stem}-compensated"),
        }
    }
}
