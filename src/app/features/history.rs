//! The library of past results: scan a folder on a job thread (every
//! result and session file read), then the drift of the chosen robot over
//! the ticked results, computed at once (no file is read, a few hundred
//! numbers are compared).

use std::path::PathBuf;

use crate::engine::history::{self, DriftOptions, HistoryError};

use super::Core;
use crate::app::commands::HistoryCommand;
use crate::app::jobs::{HistoryMessage, JobMessage};
use crate::app::state::Level;

impl Core {
    /// Handles a [`HistoryCommand`].
    pub(super) fn history(&mut self, ctx: &egui::Context, command: HistoryCommand) {
        match command {
            HistoryCommand::Scan => self.history_scan(ctx),
            HistoryCommand::Drift => self.history_drift(),
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
        if self.state.busy.scanning {
            return;
        }
        let folder = PathBuf::from(text);
        self.state
            .say(Level::Info, format!("scanning {}…", folder.display()));
        let started = self.spawn(ctx, "history", move |rep| {
            let outcome = history::scan(&folder).map(Box::new).map_err(Into::into);
            rep.send(JobMessage::History(HistoryMessage::Scanned {
                folder,
                outcome,
            }));
        });
        self.state.busy.scanning = started;
    }

    /// The drift of the chosen robot over the ticked results.
    fn history_drift(&mut self) {
        let view = &mut self.state.history;
        view.drift = None;
        view.drift_of = None;
        let (Some(Ok(library)), Some(robot)) = (&view.library, &self.forms.history.robot) else {
            return;
        };
        let mut ticked = library.clone();
        ticked.sessions.clear();
        ticked
            .entries
            .retain(|e| !self.forms.history.unselected.contains(&e.path));
        let options = DriftOptions {
            k: self.forms.history.k,
            ..DriftOptions::default()
        };
        view.drift = Some(match history::drift(&ticked, robot, &options) {
            Ok(d) => Ok(d),
            Err(HistoryError::UnknownRobot { .. }) => Err(format!(
                "no ticked result of {robot}: tick some in the table"
            )),
            Err(e) => Err(e.to_string()),
        });
        view.drift_of = Some(ticked);
    }

    /// Handles a [`HistoryMessage`].
    pub(super) fn on_history(&mut self, message: HistoryMessage) {
        let HistoryMessage::Scanned { folder, outcome } = message;
        self.state.busy.scanning = false;
        match outcome {
            Ok(library) => {
                self.state.prefs.history_folder = Some(folder.clone());
                let robots = library.robots();
                let keep = self
                    .forms
                    .history
                    .robot
                    .as_ref()
                    .is_some_and(|r| robots.iter().any(|(n, _)| n == r));
                if !keep {
                    // The robot with the most results.
                    self.forms.history.robot = robots
                        .iter()
                        .max_by_key(|(_, n)| *n)
                        .map(|(name, _)| name.clone());
                }
                self.forms.history.unselected.clear();
                let problems = library.problems.len();
                let mut line = format!(
                    "{}: {} results of {} robot(s), {} sessions",
                    folder.display(),
                    library.entries.len(),
                    robots.len(),
                    library.sessions.len()
                );
                if problems > 0 {
                    line.push_str(&format!(", {problems} file(s) could not be used"));
                }
                let level = if problems > 0 {
                    Level::Warning
                } else {
                    Level::Info
                };
                self.state.say(level, line);
                self.state.history.library = Some(Ok(*library));
            }
            Err(e) => {
                self.state
                    .say(Level::Error, "the library could not be scanned");
                self.state.history.library = Some(Err(e.to_string()));
            }
        }
        self.history_drift();
    }
}
