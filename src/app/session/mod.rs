//! The session: where it came from, what its stripes fit to, opening a
//! session or result file (told apart by its `format` key) or the demo,
//! "Save as" without the left-out measurements, and what the Session,
//! Stripe and left panels do with the session on show (selection, the
//! measurements left out, the measuring range). Reading a session fits
//! every stripe once ([`analyse`]): what the tables, the stripe view and
//! every later run use.

pub mod scene;
pub mod stripe;
pub mod ui;

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use crate::engine::base::session::{ExcludeError, SensorRange, Session, exclude_measurements};
use crate::engine::calibrate::solve::{self, Analysis, SolveError, estimate::Estimate};
use crate::engine::calibrate::stripe::{StripeError, StripeResult};
use crate::engine::files::format::{
    Cap, FileError, RESULT_FORMAT, ResultFile, can_write_in, parse_result, parse_session,
    read_text, session_to_json, write_atomic,
};

use super::command::{Command, FilesCommand, Tab, ViewCommand};
use super::error::JobError;
use super::job::Slot;
use super::ledger::{Artefact, Input, Reading, Stamp};
use super::results::{CentrePoint, CentreSet, ResultOrigin, ResultView};
use super::state::{Level, Notice};
use super::{AppState, Core, Write};

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

    /// The folder Save as proposes: the session file's or the joint log's
    /// when a file can be written there, else the current folder, else
    /// the user's home (an import from a read-only folder proposed a file
    /// that could not be written there).
    #[must_use]
    pub fn save_folder(&self) -> PathBuf {
        let folder = match self {
            Self::Demo | Self::Simulated => None,
            Self::File(p) | Self::Imported(p) => p.parent().map(Path::to_path_buf),
        };
        let current = std::env::current_dir().ok();
        let candidates = [folder, current.clone()];
        candidates
            .into_iter()
            .chain([std::env::home_dir()])
            .flatten()
            .find(|d| can_write_in(d))
            .or(current)
            .unwrap_or_default()
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

    /// What is wrong with the stripe in words, its failure or its
    /// warnings; `None` when nothing is.
    #[must_use]
    pub fn problem(&self) -> Option<String> {
        match self {
            Self::Failed(e) => Some(e.to_string()),
            Self::Stripe(s) if !s.warnings.is_empty() => Some(s.warnings.join("; ")),
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
        let mut seen = std::collections::HashSet::new();
        let ms = self.session.measurements.iter();
        let first = ms.filter(|m| seen.insert(m.station.as_str()));
        first.map(|m| m.station.clone()).collect()
    }
}

/// How the session table groups its rows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Grouping {
    /// File order.
    #[default]
    None,
    /// By station, stations in order of first appearance.
    Station,
    /// By use (translation, rotation, identify, validate).
    Use,
}

impl Grouping {
    /// All groupings.
    pub const ALL: [Self; 3] = [Self::None, Self::Station, Self::Use];

    /// Display text.
    #[must_use]
    pub fn label(self) -> &'static str {
        match self {
            Self::None => "file order",
            Self::Station => "station",
            Self::Use => "use",
        }
    }
}

/// What a file turned out to be.
#[derive(Debug)]
pub enum Opened {
    /// A session, analysed.
    Session(Box<LoadedSession>),
    /// A result file, checked.
    Result(Box<ResultFile>),
}

/// The embedded demo session, analysed.
///
/// # Errors
/// Only if the embedded text were broken (a build error in practice).
pub fn open_demo() -> Result<LoadedSession, FileError> {
    let name = Path::new(crate::DEMO_SESSION_NAME);
    let session = parse_session(crate::DEMO_SESSION_JSON, name)?;
    let mut loaded = analyse(session, Source::Demo);
    loaded.bytes = crate::DEMO_SESSION_JSON.as_bytes().to_vec();
    Ok(loaded)
}

/// Reads `path` and, by its `format` key, loads it as a result file or
/// as a session (anything else goes to the session loader, whose message
/// then says what is wrong).
///
/// # Errors
/// The file cannot be read or breaks a FORMAT.md rule; the message names
/// the file and, where it applies, the measurement.
pub fn open_path(path: &Path) -> Result<Opened, FileError> {
    let text = read_text(path, Cap::SESSION).map_err(|source| FileError::Io {
        action: "reading",
        path: path.to_path_buf(),
        source,
    })?;
    let format = |v: serde_json::Value| v.get("format")?.as_str().map(|f| f == RESULT_FORMAT);
    if serde_json::from_str(&text).ok().and_then(format) == Some(true) {
        Ok(Opened::Result(Box::new(parse_result(&text, path)?)))
    } else {
        let session = parse_session(&text, path)?;
        let mut loaded = analyse(session, Source::File(path.to_path_buf()));
        loaded.bytes = text.into_bytes();
        Ok(Opened::Session(Box::new(loaded)))
    }
}

/// Fits every stripe once (for the table, the stripe view and later runs)
/// and computes the centres before calibration (nominal model, initial
/// hand-eye).
#[must_use]
pub fn analyse(session: Session, source: Source) -> LoadedSession {
    let analysis = solve::analyse(&session);
    let before = analysis.clone().prepared(&session).map(|prepared| {
        let start = Estimate {
            robot: session.robot.clone(),
            flange_from_sensor: prepared.hand_eye_initial,
            mount: session.mount,
        };
        let points = session
            .measurements
            .iter()
            .enumerate()
            .map(|(i, m)| CentrePoint {
                id: m.id.clone(),
                station: m.station.clone(),
                usage: m.usage.as_str().to_string(),
                index: Some(i),
                before: start.centre_in_base(&prepared.sighting(&session, i)).into(),
                after: None,
            })
            .collect();
        CentreSet::new(points)
    });
    LoadedSession {
        bytes: session_to_json(&session).into_bytes(),
        session,
        source,
        analysis,
        before,
    }
}

/// The session without the `excluded` measurements, checked against every
/// FORMAT.md rule the removal can break, with the indices (into the
/// loaded session) of the measurements it keeps. The name is kept.
///
/// # Errors
/// Leaving these measurements out breaks a rule: the engine's message.
pub fn without(
    session: &Session,
    excluded: &BTreeSet<String>,
) -> Result<(Session, Vec<usize>), ExcludeError> {
    let ids: Vec<String> = excluded.iter().cloned().collect();
    let kept = if ids.is_empty() {
        session.clone()
    } else {
        exclude_measurements(session, &ids)?
    };
    let indices = session
        .measurements
        .iter()
        .enumerate()
        .filter(|(_, m)| !excluded.contains(&m.id))
        .map(|(i, _)| i)
        .collect();
    Ok((kept, indices))
}

/// Writes the session without the `excluded` measurements to `path`
/// (atomically). Returns how many measurements the file holds.
///
/// # Errors
/// The edited session breaks a rule, or the file cannot be written.
pub fn save_without(
    session: &Session,
    excluded: &BTreeSet<String>,
    path: &Path,
) -> Result<usize, JobError> {
    let (kept, _) = without(session, excluded)?;
    write_atomic(path, session_to_json(&kept).as_bytes())?;
    Ok(kept.measurements.len())
}

/// What a load job answers.
#[derive(Debug)]
pub enum Loaded {
    /// A session, analysed.
    Session(Box<LoadedSession>),
    /// A result file for review, with its view (matched against the
    /// session open when it was read).
    Result(PathBuf, Box<ResultView>),
    /// The file (or the demo's name) could not be opened, and why.
    Failed(String, JobError),
}

impl Core {
    /// Handles a [`FilesCommand`].
    pub(super) fn files(&mut self, ctx: &egui::Context, command: FilesCommand) {
        match command {
            FilesCommand::OpenDemo => {
                self.state.say(Level::Info, "opening the demo session…");
                self.load(
                    ctx,
                    crate::DEMO_SESSION_NAME.to_string(),
                    || match open_demo() {
                        Ok(l) => Loaded::Session(Box::new(l)),
                        Err(e) => Loaded::Failed(crate::DEMO_SESSION_NAME.into(), e.into()),
                    },
                );
            }
            FilesCommand::OpenPath(path) => self.open_path(ctx, path),
            FilesCommand::SaveSession => self.save_session(ctx),
            FilesCommand::ClearRecent => self.state.prefs.recent.clear(),
        }
    }

    /// Reads a file (named `what` for people) on the load job.
    fn load(
        &mut self,
        ctx: &egui::Context,
        what: String,
        work: impl FnOnce() -> Loaded + Send + 'static,
    ) {
        if self.start(ctx, Slot::Load, Stamp::default(), move |_| work())
            && let Some(job) = self.state.jobs.get_mut(&Slot::Load)
        {
            job.phase = format!("opening {what}…");
        }
    }

    pub(super) fn open_path(&mut self, ctx: &egui::Context, path: PathBuf) {
        if path.as_os_str().is_empty() {
            self.state.say(
                Level::Warning,
                "type the path of a session or result file first",
            );
            return;
        }
        self.forms.open_path = path.display().to_string();
        self.state
            .say(Level::Info, format!("opening {}…", path.display()));
        let session = self.state.loaded.as_ref().map(|l| l.session.clone());
        self.load(ctx, path.display().to_string(), move || {
            match open_path(&path) {
                Ok(Opened::Session(l)) => Loaded::Session(l),
                Ok(Opened::Result(file)) => {
                    let origin = ResultOrigin::Review(path.clone());
                    let view = ResultView::new(*file, origin, session.as_ref());
                    Loaded::Result(path, Box::new(view))
                }
                Err(e) => Loaded::Failed(path.display().to_string(), e.into()),
            }
        });
    }

    pub(super) fn save_session(&mut self, ctx: &egui::Context) {
        let Some(loaded) = &self.state.loaded else {
            self.state.say(Level::Warning, "no session to save");
            return;
        };
        let text = self.forms.save_path.trim();
        if text.is_empty() {
            self.state
                .say(Level::Warning, "type where to save the session first");
            return;
        }
        let path = PathBuf::from(text);
        let session = loaded.session.clone();
        let excluded = self.state.excluded.clone();
        let write = Write {
            what: "the session".to_string(),
            from: Artefact::EditedSession,
            stamp: self.state.ledger.stamp(Artefact::EditedSession),
            again: Command::Files(FilesCommand::SaveSession),
        };
        self.write(ctx, path, write, move |path| {
            let n = save_without(&session, &excluded, path)?;
            Ok(Some(format!(
                "saved {n} measurements to {} (atomic write)",
                path.display()
            )))
        });
    }

    /// A load job's answer: the session or result shown, or why not.
    pub(super) fn on_loaded(&mut self, ctx: &egui::Context, loaded: Loaded) {
        match loaded {
            Loaded::Session(l) => self.on_session(ctx, *l),
            Loaded::Result(path, view) => {
                self.state.prefs.remember(&path);
                let notes = view.notes.join("; ");
                // Made elsewhere: not with this window's solver settings.
                let stamp = self.state.ledger.stamp(Artefact::Result);
                let what = format!("method {} (reviewed)", view.method());
                self.show_result(*view, stamp.without(Input::Solver), what);
                self.state.result_unseen = false;
                self.forms.tab = Tab::Results;
                if notes.is_empty() {
                    self.state.say(
                        Level::Info,
                        format!(
                            "reviewing {} as it was computed (the solver was not run)",
                            path.display()
                        ),
                    );
                } else {
                    self.state.say(
                        Level::Warning,
                        format!("reviewing {}: {notes}", path.display()),
                    );
                }
            }
            Loaded::Failed(what, error) => {
                self.state
                    .say(Level::Error, format!("could not open {what}"));
                self.state.notice = Some(Notice {
                    title: format!("Could not open {what}"),
                    body: error.to_string(),
                });
                if let Some(p) = self.state.pending_result.take() {
                    self.open_path(ctx, p);
                }
            }
        }
    }
}

/// The status line for an opened session: how many measurements, how
/// many stripes warned or failed, and why the solver cannot run.
pub(super) fn opened_line(loaded: &LoadedSession) -> (Level, String) {
    let failed = loaded.analysis.failures().count();
    let warned = loaded
        .analysis
        .measurements
        .iter()
        .filter(|m| {
            m.as_ref()
                .is_ok_and(|p| p.stripe.as_ref().is_some_and(|s| !s.warnings.is_empty()))
        })
        .count();
    let mut text = format!(
        "opened {}: {} measurements",
        loaded.session.name,
        loaded.session.measurements.len()
    );
    let mut level = Level::Info;
    if warned > 0 {
        text.push_str(&format!(", {warned} with stripe warnings"));
    }
    if failed > 0 {
        text.push_str(&format!(", {failed} stripe(s) could not be fitted"));
        level = Level::Warning;
    }
    if let Err(e) = &loaded.before {
        text.push_str(&format!("; the solver cannot run: {e}"));
        level = Level::Warning;
    }
    (level, text)
}

impl Core {
    /// Handles a [`ViewCommand`].
    pub(super) fn view(&mut self, command: ViewCommand) {
        match command {
            ViewCommand::ShowTab(tab) => {
                self.forms.tab = tab;
                if tab == Tab::Results {
                    self.state.result_unseen = false;
                }
            }
            ViewCommand::Select(i) => self.state.selected = Some(i),
            ViewCommand::Inspect(i) => {
                self.state.selected = Some(i);
                self.forms.tab = Tab::Stripe;
            }
            ViewCommand::Step(delta) => self.step(delta),
            ViewCommand::SetIncluded { id, included } => self.include([id], included),
            ViewCommand::SetStationIncluded { station, included } => {
                let ms = self
                    .state
                    .loaded
                    .iter()
                    .flat_map(|l| &l.session.measurements);
                let ids: Vec<String> = ms
                    .filter(|m| m.station == station)
                    .map(|m| m.id.clone())
                    .collect();
                self.include(ids, included);
            }
            ViewCommand::IncludeAll => {
                self.state.excluded.clear();
                self.say_excluded();
            }
            ViewCommand::ShowOutliers => {
                self.forms.tab = Tab::Results;
                self.forms.focus_after_fail = true;
                self.state.result_unseen = false;
                self.state.outliers_seen = true;
            }
            ViewCommand::DismissNotice => self.state.notice = None,
            ViewCommand::DismissIntro => self.state.prefs.intro_dismissed = true,
            ViewCommand::SetSensorRange(range) => {
                if let Some(loaded) = &mut self.state.loaded {
                    loaded.session.sensor_range = range;
                    self.forms.range_edit = None;
                    if range.is_some() {
                        // The planner spreads the sphere over a range it is given.
                        self.forms.plan.request.range = range;
                        self.forms.plan.request.spread = true;
                    }
                }
            }
            ViewCommand::SetTolerance(t) => {
                if t.is_valid() {
                    self.forms.tolerance = t;
                    if let Some(loaded) = &self.state.loaded {
                        self.state
                            .prefs
                            .tolerances
                            .insert(loaded.session.robot.name.clone(), t);
                    }
                }
            }
        }
    }

    /// Selects the measurement `delta` rows away in the table's order
    /// (clamped to the first and last row).
    fn step(&mut self, delta: i32) {
        let rows = self.state.visible_rows(&self.forms);
        if rows.is_empty() {
            return;
        }
        let pos = self
            .state
            .selected
            .and_then(|s| rows.iter().position(|&r| r == s));
        let last = rows.len() - 1;
        let next = pos.map_or(0, |p| p.saturating_add_signed(delta as isize).min(last));
        self.state.selected = Some(rows[next]);
    }

    /// Uses the measurements `ids` in the next run, or leaves them out.
    fn include(&mut self, ids: impl IntoIterator<Item = String>, included: bool) {
        for id in ids {
            if included {
                self.state.excluded.remove(&id);
            } else {
                self.state.excluded.insert(id);
            }
        }
        self.say_excluded();
    }

    fn say_excluded(&mut self) {
        let n = self.state.excluded_count();
        if n == 0 {
            self.state.say(Level::Info, "every measurement is used");
        } else {
            self.state.say(
                Level::Info,
                format!("{n} measurement(s) left out: the next run skips them; Save as… keeps the choice"),
            );
        }
    }
}

/// A measuring range in words.
pub(super) fn range_text(r: Option<&SensorRange>) -> String {
    r.map_or_else(
        || "none".to_string(),
        |r| format!("y {}…{}, z {}…{} mm", r.y[0], r.y[1], r.z[0], r.z[1]),
    )
}

/// The open session: its name, its measuring range, and (unseen) which
/// load of a session it is.
pub(super) fn reading(state: &AppState) -> Reading {
    match &state.loaded {
        Some(l) => Reading::new(
            vec![
                ("session".into(), format!("\"{}\"", l.session.name)),
                (
                    "measuring range".into(),
                    range_text(l.session.sensor_range.as_ref()),
                ),
            ],
            state.session_loads,
        ),
        None => Reading::new(vec![("session".into(), "none".into())], 0_u64),
    }
}

/// Left-out ids named in a reading; more are counted.
const IDS_SHOWN: usize = 3;

/// The measurements left out: how many, the first few ids.
#[must_use]
pub fn left_out(excluded: &BTreeSet<String>) -> Reading {
    let mut ids: Vec<&str> = excluded
        .iter()
        .take(IDS_SHOWN)
        .map(String::as_str)
        .collect();
    if excluded.len() > IDS_SHOWN {
        ids.push("…");
    }
    let text = if excluded.is_empty() {
        "none".to_string()
    } else {
        format!("{} ({})", excluded.len(), ids.join(", "))
    };
    Reading::new(vec![("left out".into(), text)], excluded)
}
