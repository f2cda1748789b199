//! The workbench: an egui desktop app for the whole calibration, from
//! planning the poses to measuring with the calibrated cell. It calls the
//! same engine entries as the command line; nothing here computes a
//! calibration.
//!
//! **One folder a feature**, each with its state and form (`mod.rs`: the
//! handlers of its commands and of its jobs' answers, the readings of its
//! inputs), its views (`ui.rs` and others: `*_ui` functions that read
//! the state, edit the forms and push [`command::Command`]s, never
//! compute) and the work its jobs do (`job.rs`: engine calls):
//! [`session`] (open, save, the Session, Stripe and left-panel views),
//! [`run`](mod@run) (the calibration), [`results`] (the result's views, centres and
//! exports), [`plan`], [`import`], [`history`], [`compensate`],
//! [`measure`].
//!
//! **Shared pieces**, one each: [`job`] (the one job slot type: a named
//! thread, phase and fraction, Cancel, and the rule that a late answer is
//! dropped and the previous result stays), [`ledger`] (the one artefact
//! ledger: what every artefact and every file written of it was made
//! from, stale at once when an input changes, and whether a file may be
//! replaced without asking), [`command`] (what the views ask for),
//! [`dialog`] (the native file dialogs), [`widgets`] (colours, fields,
//! plots), [`scene`] (the 3-D scene of the cell, one widget), [`steps`] (the step bar, read from the ledger), [`state`]
//! (status, notices, preferences), [`error`]. This module ties them:
//! [`AppState`] (what the workbench knows), [`Forms`] (what the widgets
//! edit), and [`Core`], which hands each command and each job's answer to
//! its feature, reads every input into the ledger each frame, and starts,
//! writes and asks alike for every feature; [`workbench`] is the frame
//! loop.
//!
//! Layout of the window, for an operator at 1366×768: the load and solver
//! panel on the left, the Plan, Import, Session, Stripe, Centres, Results,
//! Measure, Compensate and History views in the middle, a status bar at
//! the bottom.

pub mod check;
pub mod command;
pub mod compensate;
pub mod dialog;
pub mod error;
pub mod history;
pub mod import;
pub mod job;
pub mod ledger;
pub mod measure;
pub mod plan;
pub mod results;
pub mod run;
pub mod scene;
pub mod session;
pub mod state;
pub mod steps;
pub mod widgets;
pub mod workbench;

use std::any::Any;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use crate::engine::base::session::Use;
use command::{Command, Tab};
use dialog::{Ask, NO_DIALOG, Purpose};
use error::JobError;
use job::{Job, Jobs, Slot, Worker};
use ledger::{Artefact, Input, Ledger, Reading, Stamp, WhenStale};
use session::{Grouping, LoadedSession, Source, opened_line};
use state::{Confirm, Level, Notice, Prefs, Status};

pub use workbench::WorkbenchApp;

/// The one line printed when the workbench cannot open a window.
pub const NO_DISPLAY_HINT: &str =
    "to calibrate without a display run `spherecal calibrate SESSION --out RESULT`";

/// The window's options: titled, 1366×768 (at least 960×600), files may
/// be dropped on it.
#[must_use]
pub fn native_options() -> eframe::NativeOptions {
    eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("spherecal workbench")
            .with_app_id("spherecal")
            .with_inner_size([1366.0, 768.0])
            .with_min_inner_size([960.0, 600.0])
            .with_drag_and_drop(true),
        ..Default::default()
    }
}

/// Opens the workbench window on `session` (default: the embedded demo
/// session) and, when given, `result` for review beside it, with the
/// preferences kept in eframe's storage. Blocks until the window closes.
///
/// # Errors
/// A window that could not be created: one line pointing to `spherecal
/// calibrate`.
pub fn run(session: Option<PathBuf>, result: Option<PathBuf>) -> Result<(), String> {
    eframe::run_native(
        "spherecal",
        native_options(),
        Box::new(move |cc| {
            Ok(Box::new(WorkbenchApp::from_storage(
                cc.storage, session, result,
            )))
        }),
    )
    .map_err(|e| format!("could not open the workbench window ({e}); {NO_DISPLAY_HINT}"))
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
    pub result: Option<results::ResultView>,
    /// A run finished while another view was on show: the Results tab
    /// is marked until it is opened (and Next shows the verdict before
    /// offering the report).
    pub result_unseen: bool,
    /// The run under way was started by Next: Results (the verdict)
    /// opens when it ends.
    pub run_by_next: bool,
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
    pub import: import::ImportView,
    /// The scanned library and the drift on show.
    pub history: history::HistoryView,
    /// The plan on show and the planning job.
    pub plan: plan::PlanView,
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
    pub compensate: compensate::CompensateState,
    /// The Measure view: its job, the cloud on show, its exports.
    pub measure: measure::MeasureView,
    /// The Re-check view: the check's plan and verdict.
    pub check: check::CheckState,
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

/// Fields the widgets edit in place: text fields, filters, settings of
/// the next run, view options.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Forms {
    /// The current tab.
    pub tab: Tab,
    /// The path field of the load panel.
    pub open_path: String,
    /// Where "Save as" writes the edited session.
    pub save_path: String,
    /// The export folder.
    pub export_dir: String,
    /// Session table: only this station.
    pub filter_station: Option<String>,
    /// Session table: only this use.
    pub filter_use: Option<Use>,
    /// Session table grouping.
    pub group: Grouping,
    /// Session table: only measurements with a stripe warning or failure.
    pub filter_problems: bool,
    /// Session table: only ids (or stations) containing this text.
    pub search: String,
    /// The measuring range being edited in the Session view, `[y0, y1,
    /// z0, z1]` mm; `None`: the session's (or the default) on show.
    pub range_edit: Option<[f64; 4]>,
    /// Settings of the next run.
    pub solver: crate::engine::calibrate::solve::Options,
    /// Centres view options.
    pub centres: results::CentresForm,
    /// The import wizard's fields.
    pub import: import::form::ImportChoices,
    /// The History view's fields.
    pub history: history::HistoryForm,
    /// The Plan view's fields.
    pub plan: plan::form::PlanForm,
    /// The acceptance tolerance the headline's PASS/FAIL and the report
    /// use (remembered per robot in the preferences).
    pub tolerance: crate::engine::tools::result_view::Tolerance,
    /// Scroll the Results view to its "after a FAIL" box once (set by
    /// Next's "Look at the outliers").
    pub focus_after_fail: bool,
    /// The Compensate view's fields.
    pub compensate: compensate::form::CompensateForm,
    /// The Measure view's fields.
    pub measure: measure::MeasureForm,
    /// How the 3-D scenes are looked at, one camera a view.
    pub scene: scene::SceneCameras,
    /// The Re-check view's fields.
    pub check: check::CheckForm,
    /// The URDF the robot came from, for "URDF back" (Results' exports).
    pub urdf_source: String,
}

/// The state (with the job table) and the forms, with every feature's
/// handlers. The workbench owns one and draws the panels from it.
pub struct Core {
    /// What the workbench knows.
    pub state: AppState,
    /// The fields the widgets edit.
    pub forms: Forms,
}

/// What a write job answers: what was written, of which output, and
/// whether it was (a status line of its own, or why not).
struct WriteAnswer {
    what: String,
    from: Artefact,
    outcome: Result<Option<String>, JobError>,
}

/// A file to write: what it is, the artefact and its stamp, and the
/// command that writes it (asked for again once the operator agrees to
/// replace a file).
struct Write {
    what: String,
    from: Artefact,
    stamp: Stamp,
    again: Command,
}

/// A job's answer as its feature's type.
fn take<T: 'static>(answer: Box<dyn Any + Send>) -> Option<T> {
    answer.downcast::<T>().ok().map(|b| *b)
}

impl Core {
    /// A core with these state and forms and no job in flight.
    #[must_use]
    pub fn new(state: AppState, forms: Forms) -> Self {
        Self { state, forms }
    }

    /// Reads every input into the ledger (each frame, and before each
    /// command, so that a job stamps the inputs as they are); then an
    /// artefact that went stale is cleared or made again, as it says
    /// ([`WhenStale`]).
    pub fn observe(&mut self, ctx: &egui::Context) {
        let readings = self.readings();
        self.state.ledger.observe(readings);
        for a in Artefact::ALL {
            let ledger = &self.state.ledger;
            match a.when_stale() {
                WhenStale::Mark => {}
                WhenStale::Clear => {
                    if ledger.stale(a).is_some() {
                        self.state.ledger.forget(a);
                        self.clear(a);
                    }
                }
                WhenStale::Redo => {
                    let now = ledger.stamp(a);
                    let made = ledger.made(a).is_some_and(|m| m.stamp == now);
                    let making = Slot::of(a)
                        .and_then(|s| self.state.jobs.get(&s))
                        .is_some_and(|j| j.stamp == now);
                    if !(made || making) {
                        self.redo(ctx, a);
                    }
                }
            }
        }
        // A refusal because something was stale goes once nothing is.
        let stale_refusal = self
            .state
            .notice
            .as_ref()
            .is_some_and(|n| n.body.contains("stale"));
        if stale_refusal
            && Artefact::ALL
                .iter()
                .all(|a| self.state.ledger.stale(*a).is_none())
        {
            self.state.notice = None;
        }
    }

    /// Every input as it reads now, from each feature's readings.
    fn readings(&self) -> Vec<(Input, Reading)> {
        let (state, forms) = (&self.state, &self.forms);
        let mut out = vec![
            (Input::Session, session::reading(state)),
            (Input::LeftOut, session::left_out(&state.excluded)),
            (Input::Solver, run::reading(&forms.solver)),
            (
                Input::PlanForm,
                plan::reading(&forms.plan, plan::plan_hand_eye(state)),
            ),
            (Input::Tolerance, results::tolerance(&forms.tolerance)),
            (Input::Calibration, results::calibration(state)),
            (Input::Targets, compensate::reading(&forms.compensate)),
            (Input::MeasureForm, measure::reading(&forms.measure)),
            (Input::CheckForm, check::form_reading(forms)),
            (Input::CheckSession, check::session_reading(&forms.check)),
        ];
        out.extend(import::readings(forms));
        out.extend(history::readings(state, forms));
        out
    }

    /// Clears an artefact's view: one that went stale (its
    /// [`WhenStale::Clear`]), or one made from the previous session.
    fn clear(&mut self, artefact: Artefact) {
        let state = &mut self.state;
        match artefact {
            Artefact::ImportView => {
                state.import.preview = None;
                state.import.outcome = None;
                state.import.checks.clear();
            }
            Artefact::Cloud => state.measure = measure::MeasureView::default(),
            Artefact::Compensation => state.compensate.outcome = None,
            Artefact::CheckPlan => state.check.plan = None,
            Artefact::Check => state.check.outcome = None,
            _ => {}
        }
    }

    /// Makes an artefact again (its [`WhenStale::Redo`]).
    fn redo(&mut self, ctx: &egui::Context, artefact: Artefact) {
        match artefact {
            Artefact::PoseScan => self.import_scan(ctx),
            Artefact::Drift => self.history_drift(ctx),
            _ => {}
        }
    }

    /// Hands a command to its feature.
    pub fn apply(&mut self, ctx: &egui::Context, command: Command) {
        self.observe(ctx);
        match command {
            Command::Confirm(replace) => self.confirm(ctx, replace),
            Command::Files(c) => self.files(ctx, c),
            Command::Browse(purpose) => self.browse(ctx, purpose),
            Command::View(c) => self.view(c),
            Command::Run(c) => self.run(ctx, c),
            Command::Export(kind) => self.export(ctx, kind),
            Command::Import(c) => self.import(ctx, c),
            Command::History(c) => self.history(ctx, c),
            Command::Plan(c) => self.plan(ctx, c),
            Command::Compensate(c) => self.compensate(ctx, c),
            Command::Measure(c) => self.measure(ctx, c),
            Command::Check(c) => self.check(ctx, c),
            Command::UseExport(kind) => self.use_export(ctx, kind),
            Command::RunWith(options) => {
                self.forms.solver = *options;
                self.observe(ctx);
                self.run(ctx, command::RunCommand::Start);
            }
            Command::Next(c) => {
                let idle = !self.state.jobs.runs(&Slot::Run);
                self.apply(ctx, *c);
                self.state.run_by_next |= idle && self.state.jobs.runs(&Slot::Run);
            }
        }
    }

    /// A run ended: when Next started it, Results (the verdict) opens;
    /// a result made without any update says so in the status line.
    fn after_run(&mut self, shown_before: u64) {
        let by_next = std::mem::take(&mut self.state.run_by_next);
        if self.state.results_shown == shown_before {
            return;
        }
        if by_next {
            self.view(command::ViewCommand::ShowTab(Tab::Results));
        }
        let warning = self
            .state
            .result
            .as_ref()
            .and_then(|r| r.file.no_update_warning());
        if let Some(w) = warning {
            self.state.say(Level::Warning, format!("calibrated: {w}"));
        }
    }

    /// Starts `work` in `slot` with `stamp`; says why when it cannot.
    fn start<T: Send + 'static>(
        &mut self,
        ctx: &egui::Context,
        slot: Slot,
        stamp: Stamp,
        work: impl FnOnce(&Worker) -> T + Send + 'static,
    ) -> bool {
        match self.state.jobs.start(slot, stamp, ctx, work) {
            Ok(()) => true,
            Err(e) => {
                self.state.say(Level::Error, e);
                false
            }
        }
    }

    /// Hands every answer arrived to its feature (the workbench calls
    /// this after the frame's commands: a Cancel in the same frame wins).
    pub fn finish(&mut self, ctx: &egui::Context) {
        for (slot, job, answer) in self.state.jobs.finish() {
            let Some(a) = answer else {
                self.state.say(
                    Level::Error,
                    format!("the {slot:?} job stopped without an answer"),
                );
                continue;
            };
            match slot {
                Slot::Load => take(a).map(|l| self.on_loaded(ctx, l)),
                Slot::Run => take(a).map(|o| {
                    let shown = self.state.results_shown;
                    self.on_run(&job, o);
                    self.after_run(shown);
                }),
                Slot::Plan => take(a).map(|o| self.on_plan(&job, o)),
                Slot::Simulate => take(a).map(|o| self.on_simulated(ctx, o)),
                Slot::Import => take(a).map(|o| self.on_imported(ctx, &job, o)),
                Slot::ImportPreview => take(a).map(|p| self.on_previewed(ctx, &job, p)),
                Slot::PoseScan => take(a).map(|o| self.on_import_scanned(&job, o)),
                Slot::Library => take(a).map(|o| self.on_scanned(o)),
                Slot::Drift => take(a).map(|o| self.on_drift(&job, o)),
                Slot::Compensate => take(a).map(|o| self.on_compensated(&job, o)),
                Slot::Measure => take(a).map(|o| self.on_measured(&job, o)),
                Slot::CheckPlan => take(a).map(|o| self.on_check_planned(&job, o)),
                Slot::Check => take(a).map(|o| self.on_checked(&job, o)),
                Slot::Dialog => take(a).map(|(p, path)| self.on_dialog(ctx, p, path)),
                Slot::Write(path) => take(a).map(|w| self.on_written(path, &job, w)),
            };
        }
    }

    /// A native file dialog for `purpose` on a job thread; its answer
    /// goes to the field (or the write) it is for.
    fn browse(&mut self, ctx: &egui::Context, purpose: Purpose) {
        if self.state.jobs.runs(&Slot::Dialog) {
            return;
        }
        let ask = self.ask(purpose);
        if self.start(ctx, Slot::Dialog, Stamp::default(), move |_| {
            (purpose, dialog::show(&ask))
        }) {
            self.state.say(Level::Info, "waiting for the file dialog…");
        }
    }

    /// Where the dialog for `purpose` opens and the name it offers.
    fn ask(&self, purpose: Purpose) -> Ask {
        let prefs = &self.state.prefs;
        let last = prefs.last_folder.clone();
        let import = &self.forms.import;
        let beside_log = || {
            import
                .log()
                .parent()
                .map(Path::to_path_buf)
                .filter(|d| !d.as_os_str().is_empty())
                .or_else(|| last.clone())
        };
        let name_of = |field: &str| {
            Path::new(field.trim())
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
        };
        let (folder, file_name) = match purpose {
            Purpose::ExportFolder => (Some(PathBuf::from(self.forms.export_dir.trim())), None),
            Purpose::HistoryFolder => (prefs.history_folder.clone().or(last), None),
            Purpose::ImportProfiles
            | Purpose::ImportReferences
            | Purpose::ImportCentres
            | Purpose::ImportHandEye => (beside_log(), None),
            Purpose::SaveSession => (last, name_of(&self.forms.save_path)),
            Purpose::CompensateOut => (last, self.compensated_file_name()),
            Purpose::MeasureExport => (last, Some(self.cloud_file_name())),
            _ => (last, None),
        };
        Ask {
            purpose,
            folder,
            file_name,
            folder_only: matches!(
                purpose,
                Purpose::ExportFolder | Purpose::HistoryFolder | Purpose::MeasureProfiles
            ) || (purpose == Purpose::ImportProfiles
                && import.profiles_kind == import::form::ProfilesKind::Folder),
        }
    }

    /// A dialog closed: the chosen path goes to its field (a save dialog
    /// writes at once: it has asked about replacing a file itself).
    fn on_dialog(&mut self, ctx: &egui::Context, purpose: Purpose, path: Option<PathBuf>) {
        self.state.dialog_empty = path.is_none().then_some(purpose);
        let Some(path) = path else {
            self.state.say(Level::Warning, NO_DIALOG);
            return;
        };
        let text = path.display().to_string();
        let f = &mut self.forms;
        match purpose {
            Purpose::Open => self.open_path(ctx, path),
            Purpose::SaveSession => {
                f.save_path = text;
                self.state.ledger.allow(path);
                self.save_session(ctx);
            }
            Purpose::ExportFolder => {
                f.export_dir = text;
                self.state
                    .say(Level::Info, format!("exports go to {}", path.display()));
            }
            Purpose::ImportJoints => {
                f.import.joints = path;
                self.import_preview(ctx, true);
            }
            Purpose::ImportPoses => f.import.poses = path,
            Purpose::ImportProfiles => f.import.profiles = path,
            Purpose::ImportReferences => f.import.references = path,
            Purpose::ImportCentres => f.import.centres = path,
            Purpose::ImportHandEye => f.import.hand_eye_file = path,
            Purpose::HistoryFolder => {
                f.history.folder = text;
                self.history_scan(ctx);
            }
            Purpose::CompensateTargets => {
                f.compensate.targets = text;
                if self.state.result.is_some() {
                    self.observe(ctx);
                    self.compensate_run(ctx);
                }
            }
            Purpose::CompensateTool => f.compensate.tool = text,
            Purpose::CompensateOut => {
                f.compensate.out = text;
                self.state.ledger.allow(path);
                self.compensate_write(ctx);
            }
            Purpose::MeasureSession => f.measure.session_file = text,
            Purpose::MeasureLog => f.measure.log = text,
            Purpose::MeasureProfiles => f.measure.profiles = text,
            Purpose::MeasureFrame => f.measure.frame = text,
            Purpose::MeasureReferences => f.measure.references = text,
            Purpose::CheckSession => f.check.session = text,
            Purpose::CompensateCurrentTool => f.compensate.current_tool = text,
            Purpose::UrdfSource => f.urdf_source = text,
            Purpose::MeasureExport => {
                f.measure.out = text;
                self.state.ledger.allow(path);
                self.export_cloud(ctx);
            }
        }
    }

    /// Writes `path` of `write.from` on a job thread (one write a file at
    /// a time): `work` writes it (atomically) and may give a status line
    /// of its own; the file is remembered with the artefact's stamp. A
    /// file that exists and was not written by this window of the same
    /// artefact and inputs is replaced only once the operator says so
    /// ([`Command::Confirm`]); `write.again` is the command that asks
    /// for it again then.
    fn write(
        &mut self,
        ctx: &egui::Context,
        path: PathBuf,
        write: Write,
        work: impl FnOnce(&Path) -> Result<Option<String>, JobError> + Send + 'static,
    ) {
        let Write {
            what,
            from,
            stamp,
            again,
        } = write;
        if let Err(why) = self.state.ledger.may_write(&path, from, &stamp) {
            self.state.say(
                Level::Warning,
                format!("{what} not written yet: {why}; replace it?"),
            );
            self.state.confirm = Some(Confirm { path, why, again });
            return;
        }
        let to = path.clone();
        self.start(ctx, Slot::Write(path), stamp, move |_| WriteAnswer {
            what,
            from,
            outcome: work(&to),
        });
    }

    /// The operator answered the question of [`Core::write`]: the file is
    /// replaced (the write is asked for again), or kept.
    fn confirm(&mut self, ctx: &egui::Context, replace: bool) {
        let Some(c) = self.state.confirm.take() else {
            return;
        };
        if replace {
            self.state.ledger.allow(c.path);
            self.apply(ctx, c.again);
        } else {
            self.state.say(
                Level::Info,
                format!("{} kept: nothing written", c.path.display()),
            );
        }
    }

    /// A write ended: remembered with its output's stamp, or why not.
    fn on_written(&mut self, path: PathBuf, job: &Job, answer: WriteAnswer) {
        let WriteAnswer {
            what,
            from,
            outcome,
        } = answer;
        match outcome {
            Ok(line) => {
                if from == Artefact::Report {
                    let made = format!("report written: {}", path.display());
                    self.state.ledger.record(from, job.stamp.clone(), made);
                }
                self.state
                    .ledger
                    .wrote(&what, path.clone(), from, job.stamp.clone());
                let line = line.unwrap_or_else(|| format!("wrote {what} to {}", path.display()));
                self.state.say(Level::Info, line);
                // A refusal to write is answered by this write.
                if self.state.notice.as_ref().is_some_and(|n| {
                    n.title.ends_with("not written") || n.title.starts_with("Could not write")
                }) {
                    self.state.notice = None;
                }
            }
            Err(e) => {
                let status = format!("{what} not written");
                self.refuse(&format!("Could not write {what}"), &status, e.to_string());
                self.state.say(Level::Error, status);
            }
        }
    }

    /// The export folder of the form, remembered; `None` (with a notice)
    /// when it does not exist.
    fn export_folder(&mut self) -> Option<PathBuf> {
        let dir = PathBuf::from(self.forms.export_dir.trim());
        if !dir.is_dir() {
            self.state.notice = Some(Notice {
                title: "Nothing exported".to_string(),
                body: format!("the export folder {} does not exist", dir.display()),
            });
            return None;
        }
        self.state.prefs.export_folder = Some(dir.clone());
        Some(dir)
    }

    /// Says in the status line that something was not done, and why in a
    /// notice titled `title`.
    fn refuse(&mut self, title: &str, status: &str, why: String) {
        self.state.say(Level::Warning, status);
        self.state.notice = Some(Notice {
            title: title.to_string(),
            body: why,
        });
    }

    /// Shows a session that was opened, imported or simulated: resets the
    /// forms and the selection, says what was found, and opens the result
    /// waiting for it.
    pub(super) fn on_session(&mut self, ctx: &egui::Context, loaded: LoadedSession) {
        // A run of the previous session: stopped and forgotten (and the
        // jobs of what was made of its result, below).
        self.state.jobs.cancel(&Slot::Run);
        match loaded.source.path() {
            Some(p) => {
                self.state.prefs.remember(p);
                self.forms.open_path = p.display().to_string();
            }
            // The demo, an import or a simulation: the field shows no
            // file rather than the previous one.
            None => self.forms.open_path.clear(),
        }
        let dir = loaded.source.save_folder();
        let file_name = match loaded.source {
            Source::Imported(_) => format!("{}.json", loaded.source.stem()),
            _ => format!("{}-edited.json", loaded.source.stem()),
        };
        self.forms.save_path = dir.join(file_name).display().to_string();
        self.forms.solver = crate::engine::calibrate::solve::Options::from_session(&loaded.session);
        // The Plan view follows the open session's robot (a preset of the
        // same name), so a plan and its program are for that robot.
        if let Some(p) = crate::engine::base::robot::presets::presets()
            .into_iter()
            .find(|p| p.robot.name == loaded.session.robot.name)
            && self.forms.plan.robot != p.key
        {
            self.forms.plan.robot = p.key.to_string();
            self.forms.plan.request.design.sphere = plan::form::default_sphere(p.key);
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
        // What was made of the last session's result goes with it, the
        // result and report aside (forgotten, not said); what was never
        // written is said.
        let mut cleared = Vec::new();
        for a in Artefact::ALL.into_iter().filter(|a| a.upstream().is_some()) {
            let ledger = &self.state.ledger;
            if let Some(made) = ledger.made(a).filter(|_| a != Artefact::Report) {
                let saved = ledger
                    .written
                    .iter()
                    .any(|w| w.from == a && w.stamp == made.stamp);
                cleared.push(format!(
                    "{}{}",
                    a.name(),
                    if saved { "" } else { " (never written)" }
                ));
            }
            if let Some(slot) = Slot::of(a) {
                self.state.jobs.cancel(&slot);
            }
            self.state.ledger.forget(a);
            self.clear(a);
        }
        self.state.ledger.forget(Artefact::Result);
        // The files written of the last session are not this one's.
        self.state.ledger.forget_written_of(Input::Session);
        let (mut level, mut text) = opened_line(&loaded);
        if !cleared.is_empty() {
            level = Level::Warning.max(level);
            text = format!(
                "{text}; cleared what was made of the previous session: {}",
                cleared.join(", ")
            );
        }
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
