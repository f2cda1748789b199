//! The calibration run: the whole engine calibration of the loaded
//! session without the left-out measurements, on a job thread, reporting
//! every ε and stopping at the next one after Cancel; the settings of
//! the next run are the engine's [`Options`], which the solver panel
//! ([`ui`]) edits.

pub mod ui;

use std::collections::BTreeSet;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use crate::engine::calibrate::solve::{
    self, Control, Method, Options, Phase, Progress, StopReason,
};
use crate::engine::files::format::ResultFile;

use super::Core;
use super::command::{RunCommand, Tab};
use super::error::JobError;
use super::job::{Job, Slot};
use super::ledger::{Artefact, Reading, Stamp};
use super::results::{ResultOrigin, ResultView};
use super::session::{LoadedSession, without};
use super::state::{Level, Notice};

/// Why a run gave no result.
#[derive(Debug)]
pub enum RunFailure {
    /// Cancel was pressed; the solver stopped after this many updates.
    Cancelled(usize),
    /// The session or the solver failed.
    Failed(JobError),
}

/// Where a run job is: a phase of the engine's run, or the workbench's
/// own last step (the result file and its views).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RunStage {
    /// The engine's progress report.
    Solver(Progress),
    /// The engine is done: the result file and the views of it are
    /// being built.
    Views,
}

impl RunStage {
    /// What the run is doing, in words that name the phase.
    #[must_use]
    pub fn describe(&self) -> String {
        match self {
            Self::Solver(p) => p.phase.describe(p.updates),
            Self::Views => "the result file and its views".to_string(),
        }
    }

    /// The fraction of the whole run done, phases weighted
    /// ([`Progress::run_fraction`]; the views take the rest of the bar).
    #[must_use]
    pub fn fraction(&self) -> f64 {
        match self {
            Self::Solver(p) => p.run_fraction(),
            Self::Views => crate::engine::calibrate::solve::progress::RUN_END,
        }
    }
}

/// The whole calibration of the loaded session without the `excluded`
/// measurements: the stripes fitted when it was loaded (none is fitted
/// again), the run (reporting every phase and ε, stopping when `cancel`
/// is set or `on_progress` returns false), and the result and its view.
/// The cancel is looked at in every phase, the last one included: after
/// the engine's run, before the result file, before the views.
///
/// # Errors
/// [`RunFailure::Cancelled`] after a cancel, [`RunFailure::Failed`] with
/// the engine's error otherwise.
pub fn calibrate_session(
    loaded: &LoadedSession,
    excluded: &BTreeSet<String>,
    options: &Options,
    cancel: &AtomicBool,
    on_progress: &mut dyn FnMut(RunStage) -> bool,
) -> Result<ResultView, RunFailure> {
    let started = Instant::now();
    let failed = |e: JobError| RunFailure::Failed(e);
    let (kept, indices) = without(&loaded.session, excluded).map_err(|e| failed(e.into()))?;
    let analysis = if excluded.is_empty() {
        loaded.analysis.clone()
    } else {
        loaded.analysis.subset(&kept, &indices)
    };
    let prepared = analysis.prepared(&kept).map_err(|e| failed(e.into()))?;
    let mut updates = 0;
    let cal = solve::run(&kept, &prepared, options, &mut |p| {
        updates = p.updates;
        let delivered = on_progress(RunStage::Solver(*p));
        if cancel.load(Ordering::Relaxed) || !delivered {
            Control::Cancel
        } else {
            Control::Continue
        }
    })
    .map_err(|e| failed(e.into()))?;
    if let StopReason::Cancelled { updates, .. } = cal.stop {
        return Err(RunFailure::Cancelled(updates));
    }
    // Goes on when `ok` and not cancelled.
    let go_on = |ok: bool| {
        let on = ok && !cancel.load(Ordering::Relaxed);
        on.then_some(()).ok_or(RunFailure::Cancelled(updates))
    };
    go_on(true)?;
    go_on(on_progress(RunStage::Views))?;
    let file = ResultFile::from_calibration(&kept, &cal);
    go_on(true)?;
    let origin = ResultOrigin::Run {
        seconds: started.elapsed().as_secs_f64(),
        excluded: loaded.session.measurements.len() - kept.measurements.len(),
    };
    let view = ResultView::new(file, origin, Some(&loaded.session));
    go_on(true).map(|()| view)
}

impl Core {
    /// Handles a [`RunCommand`].
    pub(super) fn run(&mut self, ctx: &egui::Context, command: RunCommand) {
        match command {
            RunCommand::Start => self.start_run(ctx),
            RunCommand::Cancel => {
                if let Some(run) = self.state.jobs.cancel(&Slot::Run) {
                    let updates = run.series.len().saturating_sub(1);
                    self.state.say(
                        Level::Warning,
                        format!(
                            "run cancelled in \"{}\" after {updates} update(s) ({:.2} s); the result on show is unchanged",
                            run.phase,
                            run.started.elapsed().as_secs_f64()
                        ),
                    );
                }
            }
        }
    }

    fn start_run(&mut self, ctx: &egui::Context) {
        if self.state.jobs.runs(&Slot::Run) {
            return;
        }
        let Some(loaded) = &self.state.loaded else {
            self.state.say(Level::Warning, "open a session first");
            return;
        };
        let options = self.forms.solver;
        let loaded = loaded.clone();
        let excluded = self.state.excluded.clone();
        let stamp = self.state.ledger.stamp(Artefact::Result);
        if self.start(ctx, Slot::Run, stamp, move |w| {
            calibrate_session(&loaded, &excluded, &options, w.flag(), &mut |stage| {
                if let RunStage::Solver(p) = stage
                    && p.phase == Phase::Loop
                {
                    w.point(p.updates, p.epsilon);
                }
                w.progress(stage.describe(), Some(stage.fraction()))
            })
        }) && let Some(job) = self.state.jobs.get_mut(&Slot::Run)
        {
            job.phase = "preparing the run".to_string();
            job.fraction = Some(0.0);
            self.state.say(Level::Info, "running the calibration…");
        }
    }

    /// Shows the outcome of a run (after the frame's commands: a run
    /// cancelled in the frame it arrived in is not shown).
    pub(super) fn on_run(&mut self, run: &Job, outcome: Result<ResultView, RunFailure>) {
        let seconds = run.started.elapsed().as_secs_f64();
        match outcome {
            Ok(mut view) => {
                let stop = view
                    .file
                    .solver
                    .stop_reason()
                    .unwrap_or_default()
                    .to_string();
                // One wall time for the header and the status line.
                if let ResultOrigin::Run { seconds: s, .. } = &mut view.origin {
                    *s = seconds;
                }
                let what = format!("method {}", view.method());
                self.show_result(view, run.stamp.clone(), what);
                // The operator stays where they are; the status line and
                // the Results tab say a result is ready.
                self.state.result_unseen = self.forms.tab != Tab::Results;
                self.state.say(
                    Level::Info,
                    format!("results ready (Results view): calibrated in {seconds:.2} s: {stop}"),
                );
            }
            Err(RunFailure::Cancelled(n)) => self.state.say(
                Level::Warning,
                format!("run cancelled after {n} update(s) ({seconds:.2} s); nothing was changed"),
            ),
            Err(RunFailure::Failed(e)) => {
                self.state.say(Level::Error, "the calibration failed");
                self.state.notice = Some(Notice {
                    title: "The calibration failed".to_string(),
                    body: e.to_string(),
                });
            }
        }
    }
}

impl Core {
    /// Shows `view` as the result, made from `stamp` (`what` in words);
    /// the report of the last one is forgotten.
    pub(super) fn show_result(&mut self, view: ResultView, stamp: Stamp, what: String) {
        self.forms.centres.magnify = view.centres.suggested_magnify;
        self.state.result = Some(view);
        self.state.results_shown += 1;
        self.state.outliers_seen = false;
        self.state.ledger.record(Artefact::Result, stamp, what);
        self.state.ledger.forget(Artefact::Report);
    }
}

/// The solver settings (pairing and SVD tolerance only for the paper's
/// method, which alone uses them).
#[must_use]
pub fn reading(s: &Options) -> Reading {
    let mut fields = vec![
        ("method".into(), s.method.as_str().to_string()),
        ("threshold".into(), format!("{} mm", s.threshold)),
        ("max iterations".into(), s.max_iterations.to_string()),
    ];
    if s.method == Method::Paper {
        fields.push(("pairs".into(), s.paper.pairing.as_str().to_string()));
        fields.push((
            "SVD tolerance".into(),
            format!("{:e}", s.paper.svd_tolerance),
        ));
    }
    Reading::new(fields, ())
}
