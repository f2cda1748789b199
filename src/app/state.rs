//! What the workbench says and keeps beside its views: the status line
//! and its level, the error notice until dismissed, the question before
//! a file is replaced, and the preferences kept between runs (eframe's
//! storage).

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::engine::tools::result_view::Tolerance;

/// How many recent files the start list keeps.
pub const RECENT_MAX: usize = 8;

/// How serious a status line is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Level {
    /// Plain information.
    Info,
    /// Something to look at.
    Warning,
    /// Something failed.
    Error,
}

/// The line in the status bar.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Status {
    /// What happened.
    pub text: String,
    /// How serious.
    pub level: Level,
}

/// An error shown in the window until dismissed (a file that did not
/// load, a save that was refused).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Notice {
    /// One line: what failed, e.g. "Could not open session.json".
    pub title: String,
    /// The engine's message, naming file and measurement.
    pub body: String,
}

/// What lasts across runs of the program (eframe storage).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Prefs {
    /// Recently opened session and result files, newest first.
    pub recent: Vec<PathBuf>,
    /// The folder of the last file opened or saved.
    pub last_folder: Option<PathBuf>,
    /// The last export folder.
    pub export_folder: Option<PathBuf>,
    /// The last library folder of the History view.
    pub history_folder: Option<PathBuf>,
    /// The acceptance tolerance last set for each robot (by name).
    pub tolerances: std::collections::BTreeMap<String, Tolerance>,
    /// The first-start "what to do" on the demo was dismissed.
    pub intro_dismissed: bool,
}

impl Prefs {
    /// Puts `path` first in the recent list (once), trimmed to [`RECENT_MAX`].
    pub fn remember(&mut self, path: &Path) {
        self.recent.retain(|p| p != path);
        self.recent.insert(0, path.to_path_buf());
        self.recent.truncate(RECENT_MAX);
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            self.last_folder = Some(dir.to_path_buf());
        }
    }
}

/// A write that waits for the operator: the file exists and was not
/// written by this window of the same artefact from the same inputs.
#[derive(Debug, Clone, PartialEq)]
pub struct Confirm {
    /// The file.
    pub path: PathBuf,
    /// Why the operator is asked, in words.
    pub why: String,
    /// The command that writes it, asked for again once agreed.
    pub again: super::command::Command,
}
