//! What the workbench knows: the loaded session with its per-measurement
//! fits, the run in progress, the result on show, what each view shows and
//! the messages for the operator ([`AppState`], changed only by commands
//! and job messages). The fields widgets edit are in
//! [`forms`](super::forms).

pub mod measure;

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::engine::base::session::Session;
use crate::engine::calibrate::solve::{Analysis, SolveError};
use crate::engine::calibrate::stripe::{StripeError, StripeResult};
use crate::engine::files::import::{PoseCheck, PosePreview};
use crate::engine::tools::history::{Drift, Library};
use crate::engine::tools::plan::{Plan, PlanError, Prediction};
use crate::engine::tools::result_view::Tolerance;

use super::dialog::Purpose;
use super::forms::{Forms, Grouping};
use super::job::Jobs;
use super::ledger::{Artefact, Ledger};
use super::view::compensate::CompensationView;
use super::view::{CentreSet, ResultView};

/// How many recent files the start list keeps.
pub const RECENT_MAX: usize = 8;

/// Where a session came from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Source {
    /// The demo session embedded in the binary.
    Demo,
    /// A file on disk.
    File(PathBuf),
    /// Built by the import wizard from this joint log; not saved yet.
    Imported(PathBuf),
    /// Simulated from the Plan view's plan; not saved yet.
    Simulated,
}

impl Source {
    /// The file, when there is one.
    #[must_use]
    pub fn path(&self) -> Option<&Path> {
        match self {
            Self::Demo | Self::Imported(_) | Self::Simulated => None,
            Self::File(p) => Some(p),
        }
    }

    /// The folder derived files go to by default: the session file's or
    /// the joint log's.
    #[must_use]
    pub fn folder(&self) -> Option<&Path> {
        match self {
            Self::Demo | Self::Simulated => None,
            Self::File(p) | Self::Imported(p) => p.parent(),
        }
    }

    /// A short name for people: the file name, or the demo's.
    #[must_use]
    pub fn label(&self) -> String {
        match self {
            Self::Demo => format!("{} (embedded demo)", crate::DEMO_SESSION_NAME),
            Self::File(p) => p.display().to_string(),
            Self::Imported(p) => format!("imported from {} (not saved yet)", p.display()),
            Self::Simulated => "simulated from the plan (not saved yet)".to_string(),
        }
    }

    /// The file stem used to name derived files (`<stem>-edited.json`, …).
    #[must_use]
    pub fn stem(&self) -> String {
        let name = match self {
            Self::Demo => Path::new(crate::DEMO_SESSION_NAME),
            Self::Simulated => Path::new("plan-simulated"),
            Self::File(p) | Self::Imported(p) => p.as_path(),
        };
        name.file_stem().map_or_else(
            || "session".to_string(),
            |s| s.to_string_lossy().into_owned(),
        )
    }
}

/// What the load job found out about one measurement (for the session
/// table and the stripe view), borrowed from the session's analysis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Fit<'a> {
    /// The measurement gives its centre directly: nothing to fit.
    GivenCentre,
    /// The stripe's circle fit and sphere centre.
    Stripe(&'a StripeResult),
    /// The stripe could not be fitted.
    Failed(&'a StripeError),
}

impl<'a> Fit<'a> {
    /// The stripe result, when the fit worked.
    #[must_use]
    pub fn stripe(&self) -> Option<&'a StripeResult> {
        match self {
            Self::Stripe(s) => Some(s),
            _ => None,
        }
    }
}

/// A session as the workbench holds it.
#[derive(Debug, Clone)]
pub struct LoadedSession {
    /// The validated session, as loaded (nothing left out).
    pub session: Session,
    /// Where it came from.
    pub source: Source,
    /// The file's bytes as read (for the report's SHA-256); for an
    /// imported session, the FORMAT.md text Save as would write.
    pub bytes: Vec<u8>,
    /// Every stripe fitted once, the initial hand-eye: what a run starts
    /// from.
    pub analysis: Analysis,
    /// Sphere centres in the base frame with the nominal model and the
    /// initial hand-eye, or why they cannot be computed (a failed stripe, a
    /// pose set that does not determine the hand-eye).
    pub before: Result<CentreSet, SolveError>,
}

impl LoadedSession {
    /// What the load job found out about measurement `i`.
    #[must_use]
    pub fn fit(&self, i: usize) -> Fit<'_> {
        match self.analysis.measurements.get(i) {
            Some(Ok(p)) => p.stripe.as_ref().map_or(Fit::GivenCentre, Fit::Stripe),
            Some(Err(e)) => Fit::Failed(e),
            None => Fit::GivenCentre,
        }
    }

    /// Number of stripe points of measurement `i` (`None` for a given centre).
    #[must_use]
    pub fn points(&self, i: usize) -> Option<usize> {
        match &self.session.measurements.get(i)?.observation {
            crate::engine::base::session::Observation::Stripe(p) => Some(p.len()),
            crate::engine::base::session::Observation::Centre(_) => None,
        }
    }

    /// Station ids in order of first appearance (all uses); one pass, so
    /// that a session of 3,000 stations draws in a frame.
    #[must_use]
    pub fn station_ids(&self) -> Vec<String> {
        let mut seen: std::collections::HashSet<&str> = std::collections::HashSet::new();
        let mut out: Vec<String> = Vec::new();
        for m in &self.session.measurements {
            if seen.insert(m.station.as_str()) {
                out.push(m.station.clone());
            }
        }
        out
    }
}

/// How serious a status line is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
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

/// A finished plan.
#[derive(Debug, Clone)]
pub struct PlanOutcome {
    /// The plan.
    pub plan: Box<Plan>,
    /// The predicted accuracy, when asked for, or why it failed.
    pub prediction: Option<Result<Prediction, PlanError>>,
}

/// What the wizard shows besides its form.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ImportView {
    /// The joint log's header, once read.
    pub header: Vec<String>,
    /// The preview text (mapped rows), or why it failed.
    pub preview: Option<Result<String, String>>,
    /// The flange-pose checks of the last import.
    pub checks: Vec<PoseCheck>,
    /// The last import's outcome in one line, or its error.
    pub outcome: Option<Result<String, String>>,
    /// The pose file's preview (layout, pairing, eq. 6-9 group) of the
    /// latest scan, or why the pose file cannot be read.
    pub pose_preview: Option<Result<PosePreview, String>>,
    /// The last import found no initial hand-eye: why (a guess is needed).
    pub guess_needed: Option<String>,
}

/// What the Plan view shows.
#[derive(Debug, Default)]
pub struct PlanView {
    /// The last plan, or why planning failed (the message).
    pub outcome: Option<Result<PlanOutcome, String>>,
}

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
    pub again: super::commands::Command,
}

/// Everything the workbench shows. Changed only by commands and job
/// messages; the `*_ui` functions read it.
#[derive(Debug, Default)]
pub struct AppState {
    /// The open session, if any.
    pub loaded: Option<LoadedSession>,
    /// Ids of the measurements left out of the solver and of "Save as".
    pub excluded: BTreeSet<String>,
    /// Index of the selected measurement in `loaded.session.measurements`.
    pub selected: Option<usize>,
    /// The background jobs: one a slot, with their progress.
    pub jobs: Jobs,
    /// The result on show (from a run or a reviewed file).
    pub result: Option<ResultView>,
    /// A run finished while another view was on show: the Results tab
    /// is marked until it is opened.
    pub result_unseen: bool,
    /// The status line.
    pub status: Option<Status>,
    /// An error shown until dismissed.
    pub notice: Option<Notice>,
    /// The last file dialog returned nothing (cancelled or unavailable):
    /// what it was for, so that the note shows beside its Browse button.
    pub dialog_empty: Option<Purpose>,
    /// A write waits for the operator: replace a file that exists?
    pub confirm: Option<Confirm>,
    /// What lasts across runs.
    pub prefs: Prefs,
    /// A result file to open once the session given with it has loaded.
    pub pending_result: Option<PathBuf>,
    /// What the import wizard shows (header, preview, flange checks).
    pub import: ImportView,
    /// The scanned library and the drift on show.
    pub history: HistoryView,
    /// The plan on show and the planning job.
    pub plan: PlanView,
    /// What every artefact was made from (whether it is stale) and the
    /// files written of them.
    pub ledger: Ledger,
    /// Sessions opened so far (a new one makes everything of the last
    /// stale, even under the same name).
    pub session_loads: u64,
    /// The operator has been shown the outliers of the result on show
    /// (after a FAIL the next step is then the planner).
    pub outliers_seen: bool,
    /// Results shown so far (a run's or a file's): each new one is
    /// another calibration for what was derived from the last.
    pub results_shown: u64,
    /// The Compensate view's job and its outcome.
    pub compensate: CompensateState,
    /// The Measure view: its job, the cloud on show, its exports.
    pub measure: measure::MeasureView,
}

impl AppState {
    /// Sets the status line.
    pub fn say(&mut self, level: Level, text: impl Into<String>) {
        self.status = Some(Status {
            text: text.into(),
            level,
        });
    }

    /// Where the report of the result on show was written, while it is.
    #[must_use]
    pub fn reported(&self) -> Option<&Path> {
        self.ledger.made(Artefact::Report)?;
        let mut written = self.ledger.written.iter().rev();
        written
            .find(|w| w.from == Artefact::Report)
            .map(|w| w.path.as_path())
    }

    /// True while any background work is in flight.
    #[must_use]
    pub fn is_busy(&self) -> bool {
        self.jobs.is_busy()
    }

    /// Indices of the measurements the session table shows, in its order
    /// (filtered, then grouped).
    #[must_use]
    pub fn visible_rows(&self, forms: &Forms) -> Vec<usize> {
        let Some(loaded) = &self.loaded else {
            return Vec::new();
        };
        let ms = &loaded.session.measurements;
        let needle = forms.search.trim().to_lowercase();
        let problem = |i: usize| {
            loaded
                .analysis
                .measurements
                .get(i)
                .is_some_and(Result::is_err)
                || loaded
                    .analysis
                    .warnings
                    .iter()
                    .any(|(id, _)| *id == ms[i].id)
        };
        let mut rows: Vec<usize> = (0..ms.len())
            .filter(|&i| {
                forms
                    .filter_station
                    .as_ref()
                    .is_none_or(|s| *s == ms[i].station)
                    && forms.filter_use.is_none_or(|u| u == ms[i].usage)
                    && (needle.is_empty()
                        || ms[i].id.to_lowercase().contains(&needle)
                        || ms[i].station.to_lowercase().contains(&needle))
                    && (!forms.filter_problems || problem(i))
            })
            .collect();
        match forms.group {
            Grouping::None => {}
            Grouping::Station => {
                let order: std::collections::HashMap<String, usize> = loaded
                    .station_ids()
                    .into_iter()
                    .enumerate()
                    .map(|(k, s)| (s, k))
                    .collect();
                rows.sort_by_key(|&i| order.get(&ms[i].station).copied());
            }
            Grouping::Use => rows.sort_by_key(|&i| ms[i].usage),
        }
        rows
    }

    /// Number of measurements left out that exist in the loaded session.
    #[must_use]
    pub fn excluded_count(&self) -> usize {
        self.loaded.as_ref().map_or(0, |l| {
            l.session
                .measurements
                .iter()
                .filter(|m| self.excluded.contains(&m.id))
                .count()
        })
    }
}

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
