//! The library of past results: scan a folder, then the drift of the
//! chosen robot over the ticked results, each on a job thread; the drift
//! is made again whenever the library or the choice changes (a drift
//! asked for again replaces the last, whose answer is dropped). The
//! History view is [`ui`].

pub mod ui;

use std::collections::BTreeSet;
use std::path::PathBuf;

use crate::engine::tools::history::{self, Drift, DriftOptions, HistoryError, Library};

use super::command::HistoryCommand;
use super::error::JobError;
use super::job::{Job, Slot};
use super::ledger::{Artefact, Input, Reading, Stamp};
use super::state::Level;
use super::{AppState, Core, Forms};

/// What a drift job answers: the robot, the library of the ticked
/// results (what the drift's entry indices refer to), and the drift.
type DriftAnswer = (String, Box<Library>, Result<Box<Drift>, JobError>);

/// What the History view shows.
#[derive(Debug, Clone, Default)]
pub struct HistoryView {
    /// The last scan, or why it failed.
    pub library: Option<Result<Library, String>>,
    /// The drift of the chosen robot over the ticked results, or why
    /// there is none; computed from `drift_of`, the library with only the
    /// ticked results.
    pub drift: Option<Result<Drift, String>>,
    /// The library the drift's entry indices refer to (the ticked results).
    pub drift_of: Option<Library>,
    /// Libraries scanned so far (a new scan is another library).
    pub scans: u64,
}

/// The History view's fields.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct HistoryForm {
    /// The library folder.
    pub folder: String,
    /// The robot whose drift is shown.
    pub robot: Option<String>,
    /// Result files left out of the drift (unticked in the table).
    pub unselected: BTreeSet<PathBuf>,
    /// The engine's drift settings (the form edits `k`: flag a change
    /// beyond `k` combined σ).
    pub options: DriftOptions,
}

impl Core {
    /// Handles a [`HistoryCommand`].
    pub(super) fn history(&mut self, ctx: &egui::Context, command: HistoryCommand) {
        match command {
            HistoryCommand::Scan => self.history_scan(ctx),
        }
    }

    /// Starts scanning the form's folder (also after a folder dialog).
    pub(super) fn history_scan(&mut self, ctx: &egui::Context) {
        let text = self.forms.history.folder.trim();
        if text.is_empty() {
            self.state
                .say(Level::Warning, "type or choose the library folder first");
            return;
        }
        if self.state.jobs.runs(&Slot::Library) {
            return;
        }
        let folder = PathBuf::from(text);
        self.state
            .say(Level::Info, format!("scanning {}…", folder.display()));
        self.start(ctx, Slot::Library, Stamp::default(), move |_| {
            let outcome = history::read_library(&folder)
                .map(Box::new)
                .map_err(JobError::from);
            (folder, outcome)
        });
    }

    /// Starts the drift of the chosen robot over the ticked results on a
    /// job thread (a library of hundreds of results takes longer than a
    /// frame); without a library or a robot there is none.
    pub(super) fn history_drift(&mut self, ctx: &egui::Context) {
        let stamp = self.state.ledger.stamp(Artefact::Drift);
        let view = &mut self.state.history;
        let (Some(Ok(library)), Some(robot)) = (&view.library, &self.forms.history.robot) else {
            view.drift = None;
            view.drift_of = None;
            self.state.jobs.cancel(&Slot::Drift);
            self.state.ledger.record(Artefact::Drift, stamp, "no drift");
            return;
        };
        let mut ticked = library.clone();
        ticked.sessions.clear();
        ticked
            .entries
            .retain(|e| !self.forms.history.unselected.contains(&e.path));
        let options = self.forms.history.options.clone();
        let robot = robot.clone();
        self.start(ctx, Slot::Drift, stamp, move |w| {
            w.progress("computing the drift of the ticked results…", None);
            let outcome = history::drift(&ticked, &robot, &options);
            let outcome = outcome.map(Box::new).map_err(JobError::from);
            (robot, Box::new(ticked), outcome)
        });
    }

    /// The drift's answer (the latest request's: an older one was
    /// replaced).
    pub(super) fn on_drift(&mut self, job: &Job, (robot, ticked, outcome): DriftAnswer) {
        let what = format!("the drift of {robot}");
        self.state
            .ledger
            .record(Artefact::Drift, job.stamp.clone(), what);
        let view = &mut self.state.history;
        view.drift = Some(match outcome {
            Ok(d) => Ok(*d),
            Err(JobError::History(HistoryError::UnknownRobot { .. })) => Err(format!(
                "no ticked result of {robot}: tick some in the table"
            )),
            Err(e) => Err(e.to_string()),
        });
        view.drift_of = Some(*ticked);
    }

    /// A scan's answer: the library on show (its drift follows: a new
    /// library makes the last drift stale, and the ledger has it made
    /// again).
    pub(super) fn on_scanned(
        &mut self,
        (folder, outcome): (PathBuf, Result<Box<Library>, JobError>),
    ) {
        self.state.history.scans += 1;
        match outcome {
            Ok(library) => {
                self.state.prefs.history_folder = Some(folder.clone());
                let robots = library.robots();
                let form = &mut self.forms.history;
                if !robots.iter().any(|(n, _)| Some(n) == form.robot.as_ref()) {
                    // The robot with the most results.
                    let most = robots.iter().max_by_key(|(_, n)| *n);
                    form.robot = most.map(|(name, _)| name.clone());
                }
                form.unselected.clear();
                let problems = library.problems.len();
                let (results, sessions) = (library.entries.len(), library.sessions.len());
                let (folder, n) = (folder.display(), robots.len());
                let mut line =
                    format!("{folder}: {results} results of {n} robot(s), {sessions} sessions");
                let mut level = Level::Info;
                if problems > 0 {
                    line.push_str(&format!(", {problems} file(s) could not be used"));
                    level = Level::Warning;
                }
                self.state.say(level, line);
                self.state.history.library = Some(Ok(*library));
            }
            Err(e) => {
                self.state
                    .say(Level::Error, "the library could not be scanned");
                self.state.history.library = Some(Err(e.to_string()));
            }
        }
    }
}

/// The readings of the library (which scan of which folder) and of the
/// choice (the robot, the results left out, `k`).
pub(super) fn readings(state: &AppState, forms: &Forms) -> [(Input, Reading); 2] {
    let f = &forms.history;
    let scans = state.history.scans;
    [
        (
            Input::Library,
            Reading::new(
                vec![("library".into(), format!("{} (scan {scans})", f.folder))],
                scans,
            ),
        ),
        (
            Input::HistoryChoice,
            Reading::new(
                vec![
                    ("robot".into(), f.robot.clone().unwrap_or_default()),
                    ("unticked".into(), f.unselected.len().to_string()),
                    ("k".into(), f.options.k.to_string()),
                ],
                (&f.unselected, f.options.k.to_bits()),
            ),
        ),
    ]
}
