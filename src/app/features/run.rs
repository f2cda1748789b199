//! The calibration run: the whole engine calibration of the loaded
//! session without the left-out measurements, on a job thread, reporting
//! every ε and stopping at the next one after Cancel.

use std::collections::BTreeSet;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use crate::engine::format::ResultFile;
use crate::engine::solve::{self, Control, Options, Phase, Progress, StopReason};

use super::Core;
use super::files::without;
use crate::app::commands::RunCommand;
use crate::app::error::JobError;
use crate::app::forms::Tab;
use crate::app::jobs::{JobMessage, RunFailure, RunMessage};
use crate::app::state::{Level, LoadedSession, Notice, RunState};
use crate::app::view::{ResultOrigin, ResultView};

/// The whole calibration of the loaded session without the `excluded`
/// measurements: the stripes fitted when it was loaded (none is fitted
/// again), the run (reporting every ε, stopping when `cancel` is set or
/// `on_progress` returns false), and the result and its view.
///
/// # Errors
/// [`RunFailure::Cancelled`] after a cancel, [`RunFailure::Failed`] with
/// the engine's error otherwise.
pub fn calibrate_session(
    loaded: &LoadedSession,
    excluded: &BTreeSet<String>,
    options: &Options,
    cancel: &AtomicBool,
    on_progress: &mut dyn FnMut(&Progress) -> bool,
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
    let cal = solve::run(&kept, &prepared, options, &mut |p| {
        let delivered = on_progress(p);
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
    let file = ResultFile::from_calibration(&kept, &cal);
    let origin = ResultOrigin::Run {
        seconds: started.elapsed().as_secs_f64(),
        excluded: loaded.session.measurements.len() - kept.measurements.len(),
    };
    Ok(ResultView::new(file, origin, Some(&loaded.session)))
}

impl Core {
    /// Handles a [`RunCommand`].
    pub(super) fn run(&mut self, ctx: &egui::Context, command: RunCommand) {
        match command {
            RunCommand::Start => self.start_run(ctx),
            RunCommand::Cancel => {
                if let Some(run) = &mut self.state.run {
                    run.cancel.store(true, Ordering::Relaxed);
                    run.cancelling = true;
                    self.state.say(Level::Info, "cancelling the run…");
                }
            }
        }
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
        let started = self.spawn(ctx, "solver", move |rep| {
            let outcome = calibrate_session(&loaded, &excluded, &options, &flag, &mut |p| {
                rep.send(JobMessage::Run(RunMessage::Progress(*p)))
            });
            rep.send(JobMessage::Run(RunMessage::Finished(outcome.map(Box::new))));
        });
        if started {
            self.state.run = Some(RunState {
                epsilons: Vec::new(),
                threshold: options.threshold,
                max_iterations: options.max_iterations,
                cancel,
                cancelling: false,
                started: Instant::now(),
                excluded: n_excluded,
                phase: None,
            });
            self.state.say(Level::Info, "running the calibration…");
        }
    }

    /// Handles a [`RunMessage`].
    pub(super) fn on_run(&mut self, message: RunMessage) {
        match message {
            RunMessage::Progress(p) => {
                if let Some(run) = &mut self.state.run {
                    if p.phase == Phase::Loop {
                        run.epsilons.truncate(p.updates);
                        run.epsilons.push(p.epsilon);
                        run.phase = None;
                    } else {
                        run.phase = Some((p.phase.describe(p.updates), p.phase.fraction()));
                    }
                }
            }
            RunMessage::Finished(outcome) => {
                // A run whose session was replaced meanwhile is forgotten.
                let Some(run) = self.state.run.take() else {
                    return;
                };
                match outcome {
                    Ok(view) => {
                        let stop = view.stop_reason.clone().unwrap_or_default();
                        let seconds = run.started.elapsed().as_secs_f64();
                        self.forms.centres.magnify = view.centres.suggested_magnify;
                        self.state.result = Some(*view);
                        self.state.reported = None;
                        // The operator stays where they are; the status
                        // line and the Results tab say a result is ready.
                        self.state.result_unseen = self.forms.tab != Tab::Results;
                        self.state.say(
                            Level::Info,
                            format!(
                                "results ready (Results view): calibrated in {seconds:.2} s: {stop}"
                            ),
                        );
                    }
                    Err(RunFailure::Cancelled(n)) => self.state.say(
                        Level::Warning,
                        format!("run cancelled after {n} update(s); nothing was changed"),
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
    }
}
