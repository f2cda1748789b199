//! Compensating targets through the calibration: a pose table or a
//! robot program compensated through the result on show (`spherecal
//! compensate` in the window) on a job thread with progress and Cancel
//! ([`job`]); the compensated file written under a name that follows the
//! targets, refused while the compensation is stale or the targets had
//! errors. The form is [`form`], the view [`ui`], its 3-D scene of the
//! targets before and after [`scene`].

pub mod form;
pub mod job;
pub mod scene;
pub mod ui;

use std::path::{Path, PathBuf};

use super::command::{Command, CompensateCommand};
use super::job::{Job, Slot};
use super::ledger::{Artefact, Reading};
use super::state::Level;
use super::{Core, Write};
use crate::engine::files::program::ReadSpec;
use crate::engine::uses::compensate::JointTargets;
use crate::engine::uses::compensate::{CompensateRequest, TcpSource};
use form::{CompensateForm, TcpChoice};
use job::{CompensationView, compensate_targets, write_compensated};

/// What the view says of a pose-only result without the current tool.
pub const POSE_ONLY_WHAT_TO_DO: &str = "a pose-only result: the sensor was calibrated, the robot's kinematics were not, so there is no model to compensate targets with. Install the calibrated sensor as the controller's tool data (below), or give the tool the controller holds now (Current tool) to rewrite the targets for it";

/// What "Write compensated program" calls the file it writes (status
/// line, list of files written).
pub const WRITTEN_WHAT: &str = "compensated program";

/// The guide's example targets (docs/src/workflows/compensating.md): ten
/// sensor poses along a scan path in the demo's cell, ABB's quaternion
/// order.
pub const EXAMPLE_TARGETS: &str = include_str!("../../../examples/targets.csv");

/// The file name the example targets are written as.
pub const EXAMPLE_TARGETS_NAME: &str = "example-targets.csv";

/// What the Compensate view shows.
#[derive(Debug, Default)]
pub struct CompensateState {
    /// The last compensation, or why there is none (an unreachable
    /// target named, a file that cannot be read).
    pub outcome: Option<Result<CompensationView, String>>,
    /// The output path last derived from the targets: while the output
    /// field holds it, it follows the targets.
    pub derived_out: Option<String>,
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
            CompensateCommand::ExampleTargets => self.example_targets(ctx),
        }
    }

    /// Writes the guide's example targets to the export folder (as
    /// `example-targets.csv`), chooses them (ABB's quaternion order, as
    /// the guide gives them) and compensates them.
    fn example_targets(&mut self, ctx: &egui::Context) {
        let Some(dir) = self.export_folder() else {
            return;
        };
        let path = dir.join(EXAMPLE_TARGETS_NAME);
        if let Err(e) =
            crate::engine::files::format::write_atomic(&path, EXAMPLE_TARGETS.as_bytes())
        {
            let title = "Example targets not written";
            return self.refuse(title, title, e.to_string());
        }
        self.forms.compensate.targets = path.display().to_string();
        self.forms.compensate.convention =
            Some(crate::engine::base::robot::controller::FlangeConvention::AbbQuaternion);
        self.forms.compensate.tcp = TcpChoice::Sensor;
        // The job is stamped with the fields as they are now.
        self.observe(ctx);
        self.compensate_run(ctx);
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
            let again = format!("{why}: run the calibration again, then compensate");
            return self.refuse("Not compensated", &format!("not compensated: {why}"), again);
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
        // A pose-only result moves the targets for the controller's
        // current tool, or says to install the tool data instead.
        let current_tool = result
            .hand_eye_only()
            .then(|| PathBuf::from(form.current_tool.trim()));
        if current_tool
            .as_ref()
            .is_some_and(|t| t.as_os_str().is_empty())
        {
            self.state.say(Level::Warning, POSE_ONLY_WHAT_TO_DO);
            return;
        }
        let session = if result.pose_joints.is_empty() {
            self.state.loaded.as_ref().map(|l| l.session.clone())
        } else {
            None
        };
        let request = CompensateRequest {
            result,
            session,
            // The open session may not be the result's: then it is left
            // out, as the command line without `--session`.
            session_if_it_fits: true,
            targets: PathBuf::from(form.targets.trim()),
            read: ReadSpec {
                convention: form.convention,
                ..ReadSpec::default()
            },
            tcp: match form.tcp {
                TcpChoice::Sensor => TcpSource::Sensor,
                TcpChoice::Flange => TcpSource::Flange,
                TcpChoice::ToolFile => TcpSource::ToolFile(PathBuf::from(form.tool.trim())),
            },
            options: form.options.clone(),
        };
        let stamp = self.state.ledger.stamp(Artefact::Compensation);
        if self.start(ctx, Slot::Compensate, stamp, move |w| {
            compensate_targets(request, current_tool, w).map(Box::new)
        }) && let Some(job) = self.state.jobs.get_mut(&Slot::Compensate)
        {
            job.phase = "reading the targets…".to_string();
            self.state.say(Level::Info, "compensating the targets…");
        }
    }

    /// The compensated text and its stamp when it may be written; `None`
    /// (with the reason in a notice) when it is stale, failed or not made.
    fn compensation_to_write(&mut self) -> Option<(String, PathBuf, crate::app::ledger::Stamp)> {
        let why = match (
            &self.state.compensate.outcome,
            self.state.ledger.check(Artefact::Compensation),
        ) {
            (Some(Ok(v)), Ok(stamp)) => {
                return Some((v.text.clone(), v.targets().to_path_buf(), stamp));
            }
            (Some(Err(e)), _) => format!("the targets had errors, nothing is written: {e}"),
            (None, _) => "compensate the targets first (press Compensate targets)".to_string(),
            (Some(Ok(_)), Err(why)) => format!("{why}: press Compensate targets again"),
        };
        let title = format!("{WRITTEN_WHAT} not written");
        self.refuse(&title, &format!("{title}: {why}"), why);
        None
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
        let form = &self.forms.compensate;
        let tool = (form.tcp == TcpChoice::ToolFile).then(|| PathBuf::from(form.tool.trim()));
        let current = PathBuf::from(form.current_tool.trim());
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
            if !current.as_os_str().is_empty() {
                inputs.push(current.as_path());
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
                let what = view.summary.line();
                self.state
                    .ledger
                    .record(Artefact::Compensation, job.stamp.clone(), what.clone());
                let level = if view.summary.flagged > 0 {
                    Level::Warning
                } else {
                    Level::Info
                };
                self.state.say(level, what);
                // Where the compensated file goes: beside the targets,
                // named after them; the name follows the targets unless
                // the operator typed another.
                let derived = view
                    .targets()
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

/// Size and modification time of a file, when it can be read: a file
/// rewritten in place reads otherwise.
#[must_use]
pub fn file_stamp(path: &str) -> Option<(u64, std::time::SystemTime)> {
    let path = path.trim();
    if path.is_empty() {
        return None;
    }
    let m = std::fs::metadata(path).ok()?;
    Some((m.len(), m.modified().ok()?))
}

/// The Compensate view's targets file and options: the fields it shows,
/// and (unseen) the size and time of the targets and tool files.
#[must_use]
pub fn reading(f: &CompensateForm) -> Reading {
    let tcp = match f.tcp {
        TcpChoice::ToolFile if f.tool.trim().is_empty() => "tool file (none chosen)".to_string(),
        TcpChoice::ToolFile => format!("tool {}", f.tool.trim()),
        other => other.key().to_string(),
    };
    let (targets, o) = (f.targets.trim(), &f.options);
    let joints = match o.joint_targets {
        JointTargets::Compensate => "compensated",
        JointTargets::Keep => "kept",
    };
    let fields = [
        (
            "file",
            if targets.is_empty() { "none" } else { targets }.to_string(),
        ),
        (
            "pose convention",
            CompensateForm::convention_label(f.convention),
        ),
        ("TCP", tcp),
        ("joint targets", joints.to_string()),
        ("σ tolerance", format!("{} mm", o.sigma_tolerance_mm)),
        ("far in joints", format!("{}°", o.far_joints_deg)),
        ("region margin", format!("{} mm", o.region_margin_mm)),
    ];
    let mut fields = Vec::from(fields.map(|(k, v)| (k.to_string(), v)));
    if !f.current_tool.trim().is_empty() {
        fields.push(("current tool".into(), f.current_tool.trim().to_string()));
    }
    let tool = (f.tcp == TcpChoice::ToolFile).then(|| file_stamp(&f.tool));
    let current = file_stamp(&f.current_tool);
    Reading::new(fields, (file_stamp(&f.targets), tool, current))
}
