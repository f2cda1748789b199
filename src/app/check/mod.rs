//! The five-minute re-check (`spherecal plan --check` and `spherecal
//! check` in the window): the check poses planned for the result on show
//! about a sphere position and written as the Plan view writes a plan
//! (CSV, the controller's program); a check session tested against the
//! result on a job thread with progress and Cancel, by the one engine
//! entry the command line calls too
//! ([`check_file`](crate::engine::uses::check::check_file)); the verdict
//! (HOLDS/FAILS, both tests, what moved, the fitted sphere positions) and
//! its record `X.check.json` that `history` lists. Both are made from
//! the result (the ledger's [`Artefact::CheckPlan`] and
//! [`Artefact::Check`]): stale when it, the sphere or the check session
//! changes, and then never written. The view is [`ui`], the work [`job`].

pub mod job;
pub mod ui;

use std::path::PathBuf;

use super::command::{CheckCommand, Command, PlanExport};
use super::job::{Job, Slot};
use super::ledger::{Artefact, Reading, Stamp};
use super::state::Level;
use super::{Core, Forms, Write};
use crate::engine::files::format::{ResultFile, check_record_path};
use crate::engine::uses::check::DEFAULT_ALPHA;
use job::{CheckPlanView, CheckView};

/// What the record is called in the status line and the files written.
pub const RECORD_WHAT: &str = "check record";

/// The Re-check view's fields.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckForm {
    /// Where the sphere is for the check (mm, base frame); `None`: the
    /// Plan form's sphere.
    pub sphere: Option<[f64; 3]>,
    /// The check's scan, imported as a session file.
    pub session: String,
    /// The false-alarm rate.
    pub alpha: f64,
}

impl Default for CheckForm {
    fn default() -> Self {
        Self {
            sphere: None,
            session: String::new(),
            alpha: DEFAULT_ALPHA,
        }
    }
}

impl CheckForm {
    /// The sphere of the check: the form's, else the Plan form's.
    #[must_use]
    pub fn sphere_of(&self, forms: &Forms) -> [f64; 3] {
        self.sphere.unwrap_or(forms.plan.request.design.sphere)
    }
}

/// What the Re-check view shows.
#[derive(Debug, Default)]
pub struct CheckState {
    /// The check poses planned, or why there are none.
    pub plan: Option<Result<CheckPlanView, String>>,
    /// The last check's verdict, or why there is none.
    pub outcome: Option<Result<CheckView, String>>,
}

/// The check's sphere position (the robot is the Plan form's).
#[must_use]
pub fn form_reading(forms: &Forms) -> Reading {
    let s = forms.check.sphere_of(forms);
    let fields = vec![(
        "sphere".to_string(),
        format!("{:.1}, {:.1}, {:.1} mm", s[0], s[1], s[2]),
    )];
    Reading::new(fields, s.map(f64::to_bits))
}

/// The check session (its path, and unseen its size and time) and α.
#[must_use]
pub fn session_reading(form: &CheckForm) -> Reading {
    let path = form.session.trim();
    let fields = vec![
        (
            "file".to_string(),
            if path.is_empty() { "none" } else { path }.to_string(),
        ),
        ("α".to_string(), form.alpha.to_string()),
    ];
    Reading::new(fields, super::compensate::file_stamp(path))
}

impl Core {
    /// Handles a [`CheckCommand`].
    pub(super) fn check(&mut self, ctx: &egui::Context, command: CheckCommand) {
        match command {
            CheckCommand::Plan => self.check_plan(ctx),
            CheckCommand::Cancel => {
                let planning = self.state.jobs.cancel(&Slot::CheckPlan).is_some();
                if self.state.jobs.cancel(&Slot::Check).is_some() || planning {
                    self.state
                        .say(Level::Warning, "cancelled: what is on show did not change");
                }
            }
            CheckCommand::Export(kind) => self.check_export(ctx, kind),
            CheckCommand::Run => self.check_run(ctx),
            CheckCommand::Record => self.check_write_record(ctx),
        }
    }

    /// The result on show when it is current; `None` (said why, under
    /// the title `what`) else.
    fn result_to_check(&mut self, what: &str) -> Option<ResultFile> {
        let Some(view) = &self.state.result else {
            self.state.say(
                Level::Warning,
                format!("{what}: run the calibration or open a result first"),
            );
            return None;
        };
        let file = view.file.clone();
        match self.state.ledger.check(Artefact::Result) {
            Ok(_) => Some(file),
            Err(why) => {
                self.refuse(what, what, format!("{why}: run the calibration again"));
                None
            }
        }
    }

    fn check_plan(&mut self, ctx: &egui::Context) {
        if self.state.jobs.runs(&Slot::CheckPlan) {
            return;
        }
        let Some(result) = self.result_to_check("Check not planned") else {
            return;
        };
        let mut config = match self.forms.plan.config(None) {
            Ok(c) => c,
            Err(e) => {
                self.state.check.plan = Some(Err(e.clone()));
                self.state.say(Level::Warning, e);
                return;
            }
        };
        config.design.sphere = self.forms.check.sphere_of(&self.forms);
        let robot = self.forms.plan.robot.clone();
        let stamp = self.state.ledger.stamp(Artefact::CheckPlan);
        if self.start(ctx, Slot::CheckPlan, stamp, move |w| {
            w.progress("planning one to three sphere positions…", None);
            job::plan_check_poses(config, &result, robot)
        }) {
            self.state.say(Level::Info, "planning the check…");
        }
    }

    /// The planner's answer: on show, recorded with what it was made from.
    pub(super) fn on_check_planned(&mut self, job: &Job, outcome: Result<CheckPlanView, String>) {
        match &outcome {
            Ok(p) => {
                let what = format!("{} check poses planned", p.plan.poses.len());
                self.state
                    .say(Level::Info, format!("{what}: {}", p.lines[0]));
                self.state
                    .ledger
                    .record(Artefact::CheckPlan, job.stamp.clone(), what);
            }
            Err(e) => {
                self.state.ledger.forget(Artefact::CheckPlan);
                self.state
                    .say(Level::Error, format!("check not planned: {e}"));
            }
        }
        self.state.check.plan = Some(outcome);
    }

    /// Writes the check's plan as the Plan view writes a plan: refused
    /// while it is stale.
    fn check_export(&mut self, ctx: &egui::Context, kind: PlanExport) {
        let Some(Ok(view)) = &self.state.check.plan else {
            self.state.say(Level::Warning, "plan the check first");
            return;
        };
        let (made, robot) = (view.plan.clone(), view.robot.clone());
        let stamp = match self.state.ledger.check(Artefact::CheckPlan) {
            Ok(s) => s,
            Err(why) => {
                let title = format!("{} refused", kind.label());
                self.refuse(&title, &title, format!("{why}: plan the check again"));
                return;
            }
        };
        let Some(dir) = self.export_folder() else {
            return;
        };
        // The plan's name with `check-` for `plan-`: check-irb2400.csv.
        let name = kind.file_name(&robot).replacen("plan-", "check-", 1);
        let path = dir.join(name);
        let write = Write {
            what: format!("check {}", kind.label()),
            from: Artefact::CheckPlan,
            stamp,
            again: Command::Check(CheckCommand::Export(kind)),
        };
        self.write(ctx, path, write, move |path| {
            super::plan::write_plan(kind, &made, path)
        });
    }

    fn check_run(&mut self, ctx: &egui::Context) {
        if self.state.jobs.runs(&Slot::Check) {
            return;
        }
        let Some(result) = self.result_to_check("Not checked") else {
            return;
        };
        let path = PathBuf::from(self.forms.check.session.trim());
        if path.as_os_str().is_empty() {
            self.state.say(
                Level::Warning,
                "choose the check session first (the check's scan, imported)",
            );
            return;
        }
        let alpha = self.forms.check.alpha;
        let stamp = self.state.ledger.stamp(Artefact::Check);
        if self.start(ctx, Slot::Check, stamp, move |w| {
            job::check_session_file(path, result, alpha, w)
        }) {
            self.state.say(Level::Info, "checking the cell…");
        }
    }

    /// The check's answer: the verdict on show, recorded with what it
    /// was made from, or why there is none.
    pub(super) fn on_checked(&mut self, job: &Job, outcome: Result<CheckView, String>) {
        match &outcome {
            Ok(v) => {
                let what = v.headline();
                let level = if v.checked.test.holds {
                    Level::Info
                } else {
                    Level::Warning
                };
                self.state.say(level, what.clone());
                self.state
                    .ledger
                    .record(Artefact::Check, job.stamp.clone(), what);
            }
            Err(e) => {
                self.state.ledger.forget(Artefact::Check);
                self.state.say(Level::Error, format!("not checked: {e}"));
            }
        }
        self.state.check.outcome = Some(outcome);
    }

    /// Writes the check's record beside its session (`X.check.json`),
    /// refused while the verdict is stale.
    fn check_write_record(&mut self, ctx: &egui::Context) {
        let Some(Ok(view)) = &self.state.check.outcome else {
            self.state.say(Level::Warning, "check the cell first");
            return;
        };
        let view = view.clone();
        let stamp: Stamp = match self.state.ledger.check(Artefact::Check) {
            Ok(s) => s,
            Err(why) => {
                let title = format!("{RECORD_WHAT} not written");
                let why = format!("{why}: a stale verdict is not written as current; check again");
                self.refuse(&title, &title, why);
                return;
            }
        };
        let result = match self.state.result.as_ref().map(|r| &r.origin) {
            Some(super::results::ResultOrigin::Review(p)) => p.clone(),
            _ => PathBuf::from(format!("a workbench run of {}", view.result.session)),
        };
        let path = check_record_path(&view.session_path);
        let write = Write {
            what: RECORD_WHAT.to_string(),
            from: Artefact::Check,
            stamp,
            again: Command::Check(CheckCommand::Record),
        };
        self.write(ctx, path, write, move |path| {
            job::write_check_record(&view, &result, path)?;
            Ok(Some(format!(
                "wrote the check's record {} (history lists it)",
                path.display()
            )))
        });
    }
}
