//! The calibration run: the whole engine calibration of the loaded
//! session without the left-out measurements, on a job thread, reporting
//! every ε and stopping at the next one after Cancel.

use std::collections::BTreeSet;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use crate::engine::calibrate::solve::{self, Control, Options, Phase, StopReason};
use crate::engine::files::format::ResultFile;

use super::Core;
use super::files::without;
use crate::app::commands::RunCommand;
use crate::app::error::JobError;
use crate::app::forms::Tab;
use crate::app::jobs::{JobMessage, RunFailure, RunMessage, RunStage};
use crate::app::provenance::Output;
use crate::app::state::{Level, LoadedSession, Notice, RunState};
use crate::app::view::{ResultOrigin, ResultView};

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
    let (kept, indices) =
        without(&loaded.session, excluded).map_err(|e| RunFailure::Failed(JobError::from(e)))?;
    let analysis = if excluded.is_empty() {
        loaded.analysis.clone()
    } else {
        loaded.analysis.subset(&kept, &indices)
    };
    let prepared = analysis
        .prepared(&kept)
        .map_err(|e| RunFailure::Failed(JobError::from(e)))?;
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
    .map_err(|e| RunFailure::Failed(JobError::from(e)))?;
    if let StopReason::Cancelled { updates, .. } = cal.stop {
        return Err(RunFailure::Cancelled(updates));
    }
    let stopped = |cancel: &AtomicBool| cancel.load(Ordering::Relaxed);
    if stopped(cancel) || !on_progress(RunStage::Views) || stopped(cancel) {
        return Err(RunFailure::Cancelled(updates));
    }
    let file = ResultFile::from_calibration(&kept, &cal);
    if stopped(cancel) {
        return Err(RunFailure::Cancelled(updates));
    }
    let origin = ResultOrigin::Run {
        seconds: started.elapsed().as_secs_f64(),
        excluded: loaded.session.measurements.len() - kept.measurements.len(),
    };
    let view = ResultView::new(file, origin, Some(&loaded.session));
    if stopped(cancel) {
        return Err(RunFailure::Cancelled(updates));
    }
    Ok(view)
}

impl Core {
    /// Handles a [`RunCommand`].
    pub(super) fn run(&mut self, ctx: &egui::Context, command: RunCommand) {
        match command {
            RunCommand::Start => self.start_run(ctx),
            RunCommand::Cancel => {
                if let Some(run) = self.stop_run() {
                    let updates = run.epsilons.len().saturating_sub(1);
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

    /// Stops the run in flight, if any, and forgets it at once: Cancel
    /// always wins. Its thread stops at the start of its next phase;
    /// whatever it still sends is dropped, a result included, so the
    /// result on show stays.
    pub(super) fn stop_run(&mut self) -> Option<RunState> {
        let run = self.state.run.take()?;
        run.cancel.store(true, Ordering::Relaxed);
        if self.arrived.as_ref().is_some_and(|(id, _)| *id == run.id) {
            // Its thread has ended: what it sent is dropped.
            self.arrived = None;
        } else {
            self.state.stopping.insert(run.id);
        }
        Some(run)
    }

    fn start_run(&mut self, ctx: &egui::Context) {
        if self.state.run.is_some() {
            return;
        }
        let Some(loaded) = &self.state.loaded else {
            self.state.say(Level::Warning, "open a session first");
            return;
        };
        let options = self.forms.solver.options(&loaded.session);
        let loaded = loaded.clone();
        let excluded = self.state.excluded.clone();
        let cancel = Arc::new(AtomicBool::new(false));
        let flag = Arc::clone(&cancel);
        let n_excluded = self.state.excluded_count();
        let stamp = self.state.provenance.stamp(Output::Result);
        self.state.runs_started += 1;
        let id = self.state.runs_started;
        let started = self.spawn(ctx, "solver", move |rep| {
            let outcome = calibrate_session(&loaded, &excluded, &options, &flag, &mut |stage| {
                rep.send(JobMessage::Run(RunMessage::Progress { run: id, stage }))
            });
            rep.send(JobMessage::Run(RunMessage::Finished {
                run: id,
                outcome: outcome.map(Box::new),
            }));
        });
        if started {
            self.state.run = Some(RunState {
                id,
                epsilons: Vec::new(),
                threshold: options.threshold,
                max_iterations: options.max_iterations,
                cancel,
                started: Instant::now(),
                excluded: n_excluded,
                phase: "preparing the run".to_string(),
                fraction: 0.0,
                stamp,
            });
            self.state.say(Level::Info, "running the calibration…");
        }
    }

    /// Shows the outcome of the run that arrived this frame, unless the
    /// run was cancelled in the frame (the workbench calls this after the
    /// frame's commands).
    pub fn finish_run(&mut self) {
        let Some((id, outcome)) = self.arrived.take() else {
            return;
        };
        let Some(run) = self.state.run.take_if(|r| r.id == id) else {
            return;
        };
        let seconds = run.started.elapsed().as_secs_f64();
        match outcome {
            Ok(mut view) => {
                let stop = view.stop_reason.clone().unwrap_or_default();
                // One wall time for the header and the status line.
                if let ResultOrigin::Run { seconds: s, .. } = &mut view.origin {
                    *s = seconds;
                }
                self.forms.centres.magnify = view.centres.suggested_magnify;
                self.state.result = Some(*view);
                self.state.results_shown += 1;
                self.state.reported = None;
                self.state.outliers_seen = false;
                self.state.provenance.record(Output::Result, run.stamp);
                self.state.provenance.forget(Output::Report);
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

    /// Handles a [`RunMessage`].
    pub(super) fn on_run(&mut self, message: RunMessage) {
        match message {
            RunMessage::Progress { run: id, stage } => {
                if let Some(run) = self.state.run.as_mut().filter(|r| r.id == id) {
                    if let RunStage::Solver(p) = stage
                        && p.phase == Phase::Loop
                    {
                        run.epsilons.truncate(p.updates);
                        run.epsilons.push(p.epsilon);
                    }
                    run.phase = stage.describe();
                    run.fraction = run.fraction.max(stage.fraction());
                }
            }
            RunMessage::Finished { run: id, outcome } => {
                // A cancelled run (or one whose session was replaced) has
                // ended: what it sends is not shown.
                if self.state.stopping.remove(&id) {
                    return;
                }
                if self.state.run.as_ref().is_some_and(|r| r.id == id) {
                    self.arrived = Some((id, outcome));
                }
            }
        }
    }
}
