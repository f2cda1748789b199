//! Opening and saving files: the demo session, a session or result file
//! (told apart by its `format` key), the native file dialogs, and "Save
//! as" of the session without the left-out measurements. Reading a
//! session fits every stripe once ([`analyse`]): what the tables, the
//! stripe view and every later run use.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use crate::engine::base::session::{ExcludeError, Session, exclude_measurements};
use crate::engine::calibrate::solve::{self, estimate::Estimate};
use crate::engine::files::format::{
    Cap, FileError, RESULT_FORMAT, ResultFile, parse_result, parse_session, read_text,
    session_to_json, write_atomic,
};

use super::Core;
use super::Write;
use crate::app::commands::{Command, FilesCommand};
use crate::app::error::JobError;
use crate::app::forms::{SolverForm, Tab};
use crate::app::job::Slot;
use crate::app::ledger::{Artefact, Input, Stamp};
use crate::app::state::{Level, LoadedSession, Notice, Source};
use crate::app::view::{CentrePoint, CentreSet, ResultOrigin, ResultView};

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
    let is_result = serde_json::from_str::<serde_json::Value>(&text)
        .ok()
        .and_then(|v| {
            v.get("format")
                .and_then(|f| f.as_str())
                .map(|f| f == RESULT_FORMAT)
        })
        .unwrap_or(false);
    if is_result {
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
                let view_method = view.method.clone();
                self.forms.centres.magnify = view.centres.suggested_magnify;
                self.state.result = Some(*view);
                self.state.results_shown += 1;
                self.state.result_unseen = false;
                self.state.outliers_seen = false;
                // Made elsewhere: not with this window's solver settings.
                let stamp = self
                    .state
                    .ledger
                    .stamp(Artefact::Result)
                    .without(Input::Solver);
                let what = format!("method {view_method} (reviewed)");
                self.state.ledger.record(Artefact::Result, stamp, what);
                self.state.ledger.forget(Artefact::Report);
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

    /// Shows a session that was opened, imported or simulated: resets the
    /// forms and the selection, says what was found, and opens the result
    /// waiting for it.
    pub(super) fn on_session(&mut self, ctx: &egui::Context, loaded: LoadedSession) {
        // A run of the previous session: stopped and forgotten.
        self.state.jobs.cancel(&Slot::Run);
        if let Some(p) = loaded.source.path() {
            self.state.prefs.remember(p);
            self.forms.open_path = p.display().to_string();
        }
        let dir = loaded
            .source
            .folder()
            .map(Path::to_path_buf)
            .or_else(|| std::env::current_dir().ok())
            .unwrap_or_default();
        let file_name = match loaded.source {
            Source::Imported(_) => format!("{}.json", loaded.source.stem()),
            _ => format!("{}-edited.json", loaded.source.stem()),
        };
        self.forms.save_path = dir.join(file_name).display().to_string();
        self.forms.solver = SolverForm::from_session(&loaded.session);
        // The Plan view follows the open session's robot (a preset of the
        // same name), so a plan and its program are for that robot.
        if let Some(p) = crate::engine::base::robot::presets::presets()
            .into_iter()
            .find(|p| p.robot.name == loaded.session.robot.name)
            && self.forms.plan.robot != p.key
        {
            self.forms.plan.robot = p.key.to_string();
            self.forms.plan.request.design.sphere = crate::app::forms::plan::default_sphere(p.key);
        }
        // A session that knows its measuring range plans for it.
        self.forms.range_edit = None;
        if loaded.session.sensor_range.is_some() {
            self.forms.plan.request.range = loaded.session.sensor_range;
            self.forms.plan.request.spread = true;
        }
        self.forms.tolerance = self
            .state
            .prefs
            .tolerances
            .get(&loaded.session.robot.name)
            .copied()
            .unwrap_or_default();
        self.forms.filter_station = None;
        self.forms.filter_use = None;
        if self.forms.tab == Tab::Results {
            self.forms.tab = Tab::Session;
        }
        self.state.excluded.clear();
        self.state.confirm = None;
        self.state.selected = (!loaded.session.measurements.is_empty()).then_some(0);
        self.state.result = None;
        self.state.result_unseen = false;
        self.state.notice = None;
        self.state.session_loads += 1;
        self.state.ledger.forget(Artefact::Result);
        self.state.ledger.forget(Artefact::Report);
        let (level, text) = opened_line(&loaded);
        self.state.say(level, text);
        if let Ok(set) = &loaded.before {
            self.forms.centres.magnify = set.suggested_magnify;
        }
        self.state.loaded = Some(loaded);
        if let Some(p) = self.state.pending_result.take() {
            self.open_path(ctx, p);
        }
    }
}

/// The status line for an opened session: how many measurements, how
/// many stripes warned or failed, and why the solver cannot run.
fn opened_line(loaded: &LoadedSession) -> (Level, String) {
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
