//! The Compensate view's work: the targets of a pose table or a robot
//! program compensated through the result on show, by the engine's
//! [`compensate`](crate::engine::uses::compensate::compensate) as
//! `spherecal compensate` runs it (same reading, same model, same
//! default options), on a job thread with progress and Cancel; and the
//! compensated file written atomically, refused when the compensation is
//! stale or the targets had errors.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use crate::engine::base::robot::controller::FlangeConvention;
use crate::engine::base::session::Session;
use crate::engine::calibrate::solve::Control;
use crate::engine::files::format::{ResultFile, refuse_inputs, write_atomic};
use crate::engine::files::program::{self, ReadSpec};
use crate::engine::uses::compensate::{
    self, CompensateError, Model, Options, TargetFailure, Tcp, tool,
};

use super::{Core, Write};
use crate::app::commands::{Command, CompensateCommand};
use crate::app::forms::compensate::TcpChoice;
use crate::app::job::{Job, Slot};
use crate::app::ledger::Artefact;
use crate::app::state::{Level, Notice};
use crate::app::view::compensate::CompensationView;

/// What "Write compensated program" calls the file it writes (status
/// line, list of files written).
pub const WRITTEN_WHAT: &str = "compensated program";

/// Everything a compensation job needs, taken when it starts.
#[derive(Debug, Clone)]
pub struct CompensateRequest {
    /// The result on show.
    pub result: ResultFile,
    /// The open session, for a result that does not record the joints of
    /// its poses (`pose_joints`, older results): as `--session`.
    pub session: Option<Session>,
    /// The targets file.
    pub targets: PathBuf,
    /// A table's pose convention (`--pose-convention`).
    pub convention: Option<FlangeConvention>,
    /// The TCP (`--tcp`).
    pub tcp: TcpChoice,
    /// The tool file, for [`TcpChoice::ToolFile`].
    pub tool: PathBuf,
    /// Joint targets and the flag limits.
    pub options: Options,
}

/// Reads the targets, builds the model of the result and compensates
/// every target, as `spherecal compensate` with the request's options; `progress` hears of each target,
/// `cancel` stops at the next one.
///
/// # Errors
/// The message, naming the file (and the target and line): a file that
/// cannot be read, a result without a 6-axis robot, an unreachable
/// target, "cancelled".
pub fn compensate_targets(
    request: &CompensateRequest,
    cancel: &AtomicBool,
    progress: &mut dyn FnMut(String, f64),
) -> Result<CompensationView, String> {
    let tcp = match request.tcp {
        TcpChoice::Sensor => Tcp::Sensor,
        TcpChoice::Flange => Tcp::Flange,
        TcpChoice::ToolFile => Tcp::Tool(tool::read_tool(&request.tool)?),
    };
    let spec = ReadSpec {
        format: None,
        convention: request.convention,
        columns: None,
    };
    let file = program::read_pose_file(&request.targets, &spec).map_err(|e| e.to_string())?;
    let mut notes = Vec::new();
    let model = match Model::new(&request.result, request.session.as_ref(), tcp.clone()) {
        // The open session is not the result's: go on without it, as the
        // command line without `--session`.
        Err(CompensateError::Session(why)) => {
            notes.push(format!("the open session is not used: {why}"));
            Model::new(&request.result, None, tcp)
        }
        other => other,
    }
    .map_err(|e| format!("{e} (the result on show)"))?;
    let done = compensate::compensate(&model, &file, &request.options, &mut |p| {
        progress(
            format!("target {}: {} of {}", p.target, p.done, p.total),
            p.done as f64 / p.total.max(1) as f64,
        );
        if cancel.load(Ordering::Relaxed) {
            Control::Cancel
        } else {
            Control::Continue
        }
    })
    .map_err(|e| match e {
        CompensateError::Targets(failed) if failed.len() > 1 => {
            failures_text(&failed, &request.targets)
        }
        e => format!("{e} ({})", request.targets.display()),
    })?;
    let mut view = CompensationView::new(done, &file, &model, request.convention);
    view.notes.extend(notes);
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

impl Core {
    /// Handles a [`CompensateCommand`].
    pub(super) fn compensate(&mut self, ctx: &egui::Context, command: CompensateCommand) {
        match command {
            CompensateCommand::Run => self.compensate_run(ctx),
            CompensateCommand::Cancel => {
                if self.state.jobs.cancel(&Slot::Compensate).is_some() {
                    self.state.say(
                        Level::Warning,
                        "compensation cancelled: what is on show did not change",
                    );
                }
            }
            CompensateCommand::Write => self.compensate_write(ctx),
        }
    }

    pub(super) fn compensate_run(&mut self, ctx: &egui::Context) {
        if self.state.jobs.runs(&Slot::Compensate) {
            return;
        }
        let Some(view) = &self.state.result else {
            self.state.say(
                Level::Warning,
                "nothing to compensate with: run the calibration or open a result first",
            );
            return;
        };
        // Targets are never compensated through a result that is out of
        // date.
        if let Err(why) = self.state.ledger.check(Artefact::Result) {
            self.state
                .say(Level::Warning, format!("not compensated: {why}"));
            self.state.notice = Some(Notice {
                title: "Not compensated".to_string(),
                body: format!("{why}: run the calibration again, then compensate"),
            });
            return;
        }
        let form = &self.forms.compensate;
        if form.targets.trim().is_empty() {
            self.state.say(
                Level::Warning,
                "choose a targets file first (a pose table or a robot program)",
            );
            return;
        }
        let result = view.file.clone();
        let session = if result.pose_joints.is_empty() {
            self.state.loaded.as_ref().map(|l| l.session.clone())
        } else {
            None
        };
        let request = CompensateRequest {
            result,
            session,
            targets: PathBuf::from(form.targets.trim()),
            convention: form.convention,
            tcp: form.tcp,
            tool: PathBuf::from(form.tool.trim()),
            options: form.options.clone(),
        };
        let stamp = self.state.ledger.stamp(Artefact::Compensation);
        if self.start(ctx, Slot::Compensate, stamp, move |w| {
            compensate_targets(&request, w.flag(), &mut |text, fraction| {
                w.progress(text, Some(fraction));
            })
            .map(Box::new)
        }) && let Some(job) = self.state.jobs.get_mut(&Slot::Compensate)
        {
            job.phase = "reading the targets…".to_string();
            self.state.say(Level::Info, "compensating the targets…");
        }
    }

    /// The compensated text and its stamp when it may be written; `None`
    /// (with the reason in a notice) when it is stale, failed or not made.
    fn compensation_to_write(&mut self) -> Option<(String, PathBuf, crate::app::ledger::Stamp)> {
        let refuse = |state: &mut crate::app::state::AppState, why: String| {
            state.say(Level::Warning, format!("{WRITTEN_WHAT} not written: {why}"));
            state.notice = Some(Notice {
                title: format!("{WRITTEN_WHAT} not written"),
                body: why,
            });
        };
        let (text, targets) = match &self.state.compensate.outcome {
            Some(Ok(v)) => (v.text.clone(), v.targets.clone()),
            Some(Err(e)) => {
                let why = format!("the targets had errors, nothing is written: {e}");
                refuse(&mut self.state, why);
                return None;
            }
            None => {
                refuse(
                    &mut self.state,
                    "compensate the targets first (press Compensate targets)".to_string(),
                );
                return None;
            }
        };
        match self.state.ledger.check(Artefact::Compensation) {
            Ok(stamp) => Some((text, targets, stamp)),
            Err(why) => {
                refuse(
                    &mut self.state,
                    format!("{why}: press Compensate targets again"),
                );
                None
            }
        }
    }

    pub(super) fn compensate_write(&mut self, ctx: &egui::Context) {
        let Some((text, targets, stamp)) = self.compensation_to_write() else {
            return;
        };
        let out = self.forms.compensate.out.trim().to_string();
        if out.is_empty() {
            self.state.say(
                Level::Warning,
                "type where to write the compensated file, or press Write compensated program…",
            );
            return;
        }
        let path = PathBuf::from(out);
        let tool = (self.forms.compensate.tcp == TcpChoice::ToolFile)
            .then(|| PathBuf::from(self.forms.compensate.tool.trim()));
        let write = Write {
            what: WRITTEN_WHAT.to_string(),
            from: Artefact::Compensation,
            stamp,
            again: Command::Compensate(CompensateCommand::Write),
        };
        self.write(ctx, path, write, move |path| {
            let mut inputs: Vec<&Path> = vec![targets.as_path()];
            if let Some(t) = &tool {
                inputs.push(t.as_path());
            }
            write_compensated(&text, path, &inputs).map(|()| None)
        });
    }

    /// The file name the save dialog offers: the output field's, else
    /// `<targets stem>-compensated.<ext>`.
    pub(super) fn compensated_file_name(&self) -> Option<String> {
        Path::new(self.forms.compensate.out.trim())
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .or_else(|| match &self.state.compensate.outcome {
                Some(Ok(v)) => Some(v.default_file_name()),
                _ => None,
            })
    }

    /// The compensation's answer: on show (recorded with the inputs it
    /// started from), or why there is none.
    pub(super) fn on_compensated(
        &mut self,
        job: &Job,
        outcome: Result<Box<CompensationView>, String>,
    ) {
        match outcome {
            Ok(view) => {
                let what = view.summary.clone();
                self.state
                    .ledger
                    .record(Artefact::Compensation, job.stamp.clone(), what);
                let level = if view.flagged > 0 {
                    Level::Warning
                } else {
                    Level::Info
                };
                self.state.say(level, view.summary.clone());
                // Where the compensated file goes: beside the targets,
                // named after them; the name follows the targets unless
                // the operator typed another.
                let derived = view
                    .targets
                    .with_file_name(view.default_file_name())
                    .display()
                    .to_string();
                let c = &mut self.state.compensate;
                let out = &mut self.forms.compensate.out;
                if out.trim().is_empty() || c.derived_out.as_deref() == Some(out.trim()) {
                    out.clone_from(&derived);
                }
                c.derived_out = Some(derived);
                self.state.compensate.outcome = Some(Ok(*view));
            }
            Err(e) => {
                self.state.ledger.forget(Artefact::Compensation);
                // Several failed targets: their count in the status line,
                // the list in the view.
                let first = e.lines().next().unwrap_or_default();
                self.state
                    .say(Level::Error, format!("not compensated: {first}"));
                self.state.compensate.outcome = Some(Err(e));
            }
        }
    }
}
