//! Background jobs: one slot type for every piece of work that may take
//! longer than a frame (rerun's `background_tasks.rs`: a keyed map of
//! promises). A job runs on a thread named `spherecal-<slot>`, reports its
//! phase and fraction over one bounded channel and wakes the UI with
//! `ctx.request_repaint()`; its answer is a value of its feature's own
//! type. One job a [`Slot`]: a new one replaces the last, and a job that
//! was cancelled or replaced is forgotten at once, so that whatever it
//! still sends, its answer included, is dropped and the previous result
//! stays. An answer that arrives is held until [`Jobs::finish`], which
//! the workbench calls after the frame's commands: a Cancel clicked in
//! the frame it arrives in still wins.

use std::any::Any;
use std::collections::{BTreeMap, BTreeSet};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
use std::time::Instant;

use super::ledger::{Artefact, Stamp};

/// Messages a job may have in flight before it waits for the UI: far
/// more than a run's ε reports, so a job never waits on a UI that keeps up.
pub const CHANNEL_BOUND: usize = 256;

/// Where a job runs: one job a slot.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub enum Slot {
    /// Reading a session or result file (or the demo).
    Load,
    /// The calibration run.
    Run,
    /// The pose planner.
    Plan,
    /// A session simulated from the plan.
    Simulate,
    /// The import wizard's import.
    Import,
    /// The joint log's header and preview.
    ImportPreview,
    /// The pose file read and paired before the import.
    PoseScan,
    /// A library folder scanned.
    Library,
    /// The drift over the ticked results.
    Drift,
    /// Targets compensated.
    Compensate,
    /// A scan measured into a cloud.
    Measure,
    /// A native file dialog.
    Dialog,
    /// The check poses planned for the result on show.
    CheckPlan,
    /// A check session tested against the result on show.
    Check,
    /// A file written (one write a file at a time).
    Write(PathBuf),
}

impl Slot {
    /// The slot of the job that makes `artefact`, when a job makes it.
    #[must_use]
    pub fn of(artefact: Artefact) -> Option<Self> {
        match artefact {
            Artefact::Plan => Some(Self::Plan),
            Artefact::Result => Some(Self::Run),
            Artefact::Compensation => Some(Self::Compensate),
            Artefact::Cloud => Some(Self::Measure),
            Artefact::PoseScan => Some(Self::PoseScan),
            Artefact::Drift => Some(Self::Drift),
            Artefact::CheckPlan => Some(Self::CheckPlan),
            Artefact::Check => Some(Self::Check),
            Artefact::ImportView => Some(Self::ImportPreview),
            Artefact::Report | Artefact::EditedSession => None,
        }
    }
}

/// A job in its slot: what the views show of it and what its answer
/// needs.
#[derive(Debug, Clone)]
pub struct Job {
    /// Its number; messages of other jobs are not its own.
    pub id: u64,
    /// Set to ask it to stop at its next check.
    pub cancel: Arc<AtomicBool>,
    /// When it started.
    pub started: Instant,
    /// What it is doing, naming its phase.
    pub phase: String,
    /// Fraction done, 0…1 (never goes back); `None` when unknown.
    pub fraction: Option<f64>,
    /// A series it reports as it goes (a run's ε after each update, mm).
    pub series: Vec<f64>,
    /// The readings of the inputs it started from (its artefact's stamp).
    pub stamp: Stamp,
}

#[derive(Debug)]
enum Report {
    Progress(String, Option<f64>),
    Point(usize, f64),
    Done(Box<dyn Any + Send>),
    Lost,
}

#[derive(Debug)]
struct Message {
    id: u64,
    report: Report,
}

/// What a job's thread holds: its reporting end.
pub struct Worker {
    id: u64,
    tx: SyncSender<Message>,
    ctx: egui::Context,
    cancel: Arc<AtomicBool>,
}

impl Worker {
    fn send(&self, report: Report) -> bool {
        let ok = self
            .tx
            .send(Message {
                id: self.id,
                report,
            })
            .is_ok();
        self.ctx.request_repaint();
        ok
    }

    /// Reports the phase and the fraction done. False when the job should
    /// stop (cancelled, or the workbench is gone).
    pub fn progress(&self, phase: impl Into<String>, fraction: Option<f64>) -> bool {
        self.send(Report::Progress(phase.into(), fraction)) && !self.cancelled()
    }

    /// Reports the `index`-th value of the job's series (the later ones
    /// are dropped).
    pub fn point(&self, index: usize, value: f64) {
        self.send(Report::Point(index, value));
    }

    /// Whether Cancel was pressed (or the job replaced).
    #[must_use]
    pub fn cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }

    /// The cancel flag, for engine calls that look at it themselves.
    #[must_use]
    pub fn flag(&self) -> &AtomicBool {
        &self.cancel
    }
}

/// Tells the workbench when a job's thread ends without an answer (a
/// panic), so that its slot does not stay busy.
struct Guard(Option<Worker>);

impl Drop for Guard {
    fn drop(&mut self) {
        if let Some(w) = self.0.take() {
            w.send(Report::Lost);
        }
    }
}

/// An answer held for [`Jobs::finish`]; `None`: the thread ended without one.
type Answer = (u64, Option<Box<dyn Any + Send>>);

/// An answer handed back: its slot, its job, the answer.
pub type Finished = (Slot, Job, Option<Box<dyn Any + Send>>);

/// The job table: the slots, the answers arrived, one channel.
#[derive(Debug)]
pub struct Jobs {
    running: BTreeMap<Slot, Job>,
    /// Cancelled or replaced jobs whose thread has not ended: what they
    /// send is dropped (the workbench is busy until they end).
    stopping: BTreeSet<u64>,
    arrived: Vec<Answer>,
    started: u64,
    tx: SyncSender<Message>,
    rx: Receiver<Message>,
}

impl Default for Jobs {
    fn default() -> Self {
        let (tx, rx) = sync_channel(CHANNEL_BOUND);
        Self {
            running: BTreeMap::new(),
            stopping: BTreeSet::new(),
            arrived: Vec::new(),
            started: 0,
            tx,
            rx,
        }
    }
}

impl Jobs {
    /// Runs `work` in `slot` (replacing the job there) on a thread named
    /// `spherecal-<slot>`; `stamp` is what its answer is made from.
    ///
    /// # Errors
    /// The thread could not be started (the message says so).
    pub fn start<T: Send + 'static>(
        &mut self,
        slot: Slot,
        stamp: Stamp,
        ctx: &egui::Context,
        work: impl FnOnce(&Worker) -> T + Send + 'static,
    ) -> Result<(), String> {
        let name = match &slot {
            Slot::Write(_) => "write".to_string(),
            other => format!("{other:?}").to_lowercase(),
        };
        self.cancel(&slot);
        self.started += 1;
        let id = self.started;
        let cancel = Arc::new(AtomicBool::new(false));
        let worker = Worker {
            id,
            tx: self.tx.clone(),
            ctx: ctx.clone(),
            cancel: Arc::clone(&cancel),
        };
        std::thread::Builder::new()
            .name(format!("spherecal-{name}"))
            .spawn(move || {
                let mut guard = Guard(Some(worker));
                let answer = guard.0.as_ref().map(work);
                if let (Some(w), Some(a)) = (guard.0.take(), answer) {
                    w.send(Report::Done(Box::new(a)));
                }
            })
            .map_err(|e| format!("could not start the {name} job (no thread: {e})"))?;
        self.running.insert(
            slot,
            Job {
                id,
                cancel,
                started: Instant::now(),
                phase: "starting".to_string(),
                fraction: None,
                series: Vec::new(),
                stamp,
            },
        );
        Ok(())
    }

    /// The job in `slot`, if one runs there.
    #[must_use]
    pub fn get(&self, slot: &Slot) -> Option<&Job> {
        self.running.get(slot)
    }

    /// The job in `slot`, to set what it shows before it reports.
    pub fn get_mut(&mut self, slot: &Slot) -> Option<&mut Job> {
        self.running.get_mut(slot)
    }

    /// Whether a job runs in `slot`.
    #[must_use]
    pub fn runs(&self, slot: &Slot) -> bool {
        self.running.contains_key(slot)
    }

    /// Whether a file is being written.
    #[must_use]
    pub fn writing(&self) -> bool {
        self.running.keys().any(|s| matches!(s, Slot::Write(_)))
    }

    /// Stops the job in `slot` and forgets it at once: whatever it still
    /// sends is dropped.
    pub fn cancel(&mut self, slot: &Slot) -> Option<Job> {
        let job = self.running.remove(slot)?;
        job.cancel.store(true, Ordering::Relaxed);
        let before = self.arrived.len();
        self.arrived.retain(|(id, _)| *id != job.id);
        if self.arrived.len() == before {
            self.stopping.insert(job.id);
        }
        Some(job)
    }

    /// Takes every message waiting now (never blocks): progress goes to
    /// its job, an answer is held for [`Jobs::finish`], anything of a job
    /// no longer in its slot is dropped.
    pub fn drain(&mut self) {
        while let Ok(Message { id, report }) = self.rx.try_recv() {
            let job = self.running.values_mut().find(|j| j.id == id);
            let answer = match (report, job) {
                (Report::Done(a), _) => Some(a),
                (Report::Lost, _) => None,
                (Report::Progress(phase, f), Some(job)) => {
                    job.phase = phase;
                    job.fraction = f.map(|f| job.fraction.map_or(f, |g| g.max(f)));
                    continue;
                }
                (Report::Point(k, v), Some(job)) => {
                    job.series.truncate(k);
                    job.series.push(v);
                    continue;
                }
                (Report::Progress(..) | Report::Point(..), None) => continue,
            };
            if !self.stopping.remove(&id) && self.running.values().any(|j| j.id == id) {
                self.arrived.push((id, answer));
            }
        }
    }

    /// The answers arrived and not cancelled since, with their jobs, out
    /// of their slots. `None`: the thread ended without one.
    pub fn finish(&mut self) -> Vec<Finished> {
        let arrived = std::mem::take(&mut self.arrived);
        let mut out = Vec::new();
        for (id, answer) in arrived {
            let slot = self.running.iter().find(|(_, j)| j.id == id);
            let Some(slot) = slot.map(|(s, _)| s.clone()) else {
                continue;
            };
            out.extend(self.running.remove(&slot).map(|job| (slot, job, answer)));
        }
        out
    }

    /// True while a job runs, a stopped one's thread has not ended, or an
    /// answer waits to be shown.
    #[must_use]
    pub fn is_busy(&self) -> bool {
        !(self.running.is_empty() && self.stopping.is_empty() && self.arrived.is_empty())
    }

    /// Jobs started so far (a driver waits until it stops changing).
    #[must_use]
    pub fn started(&self) -> u64 {
        self.started
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Waits until every job's thread has answered (or been dropped).
    fn settle(jobs: &mut Jobs) -> Vec<Finished> {
        let mut out = Vec::new();
        for _ in 0..1000 {
            jobs.drain();
            out.extend(jobs.finish());
            if !jobs.is_busy() {
                return out;
            }
            std::thread::sleep(std::time::Duration::from_millis(2));
        }
        panic!("the jobs did not end");
    }

    /// An answer comes back with its job (phase, fraction, series); a
    /// job replaced in its slot, or cancelled, is forgotten at once and
    /// its late answer dropped.
    #[test]
    fn a_late_answer_is_dropped_and_the_latest_job_answers() {
        let ctx = egui::Context::default();
        let mut jobs = Jobs::default();
        let (go, wait) = std::sync::mpsc::channel::<()>();
        jobs.start(Slot::Plan, Stamp::default(), &ctx, move |w| {
            wait.recv().ok();
            w.point(0, 2.5);
            w.progress("second half", Some(0.5));
            1_u32
        })
        .unwrap();
        // Replaced before it answers: its answer is dropped.
        jobs.start(Slot::Plan, Stamp::default(), &ctx, |_| 2_u32)
            .unwrap();
        go.send(()).unwrap();
        let done = settle(&mut jobs);
        assert_eq!(done.len(), 1);
        let (slot, job, answer) = &done[0];
        assert_eq!(*slot, Slot::Plan);
        assert_eq!(job.id, 2);
        let answer = answer.as_ref().and_then(|a| a.downcast_ref::<u32>());
        assert_eq!(answer, Some(&2));
        // Cancelled: nothing comes back, and the job saw the flag.
        let (go, wait) = std::sync::mpsc::channel::<()>();
        jobs.start(Slot::Run, Stamp::default(), &ctx, move |w| {
            wait.recv().ok();
            w.progress("after the cancel", Some(1.0))
        })
        .unwrap();
        let cancelled = jobs.cancel(&Slot::Run).expect("running");
        assert!(cancelled.cancel.load(Ordering::Relaxed));
        assert!(jobs.is_busy(), "until its thread ends");
        go.send(()).unwrap();
        assert!(settle(&mut jobs).is_empty());
        assert!(jobs.get(&Slot::Run).is_none());
    }

    /// Progress reaches the job in its slot and never goes back; a series
    /// point replaces what followed it.
    #[test]
    fn progress_reaches_the_job_and_never_goes_back() {
        let ctx = egui::Context::default();
        let mut jobs = Jobs::default();
        let (go, wait) = std::sync::mpsc::channel::<()>();
        jobs.start(Slot::Measure, Stamp::default(), &ctx, move |w| {
            w.progress("a", Some(0.6));
            w.progress("b", Some(0.4));
            w.point(0, 1.0);
            w.point(1, 0.5);
            w.point(1, 0.25);
            wait.recv().ok();
        })
        .unwrap();
        let job = loop {
            jobs.drain();
            let job = jobs.get(&Slot::Measure).expect("running");
            if job.series.len() == 2 && job.series[1] == 0.25 {
                break job.clone();
            }
            std::thread::sleep(std::time::Duration::from_millis(2));
        };
        assert_eq!(job.phase, "b");
        assert_eq!(job.fraction, Some(0.6));
        assert_eq!(job.series, [1.0, 0.25]);
        go.send(()).unwrap();
        assert_eq!(settle(&mut jobs).len(), 1);
    }
}
