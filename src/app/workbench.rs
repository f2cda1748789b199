//! The workbench: owns the state, the forms and the job runner. Each frame
//! it drains the job messages, draws the panels (which push commands) and
//! then applies the commands, starting jobs for anything slow.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use super::commands::Command;
use super::export;
use super::jobs::{JobMessage, Jobs, LoadFailure, RunFailure};
use super::panels;
use super::planner::{self, PlanEvent};
use super::state::{
    AppState, DialogPurpose, ExportKind, Forms, Level, LoadedSession, Notice, PlanExport, Prefs,
    RunState, SolverForm, Source, Tab,
};
use super::view::ResultOrigin;
use super::wizard::ProfilesKind;
use super::work::{self, Opened};
use crate::engine::format::write_atomic;
use crate::engine::history::{self, DriftOptions, HistoryError};
use crate::engine::plan::{self, Controller, Plan};

/// How long to wait for the window's screenshot for a plots PNG: a frame
/// takes milliseconds; a backend that cannot take one never answers.
const SCREENSHOT_TIMEOUT: std::time::Duration = std::time::Duration::from_secs(5);

/// Key of the preferences in eframe's storage (JSON text).
pub const PREFS_KEY: &str = "spherecal.prefs";

/// What the status line says when a file dialog returned nothing.
pub const NO_DIALOG: &str = "no file chosen — or no file dialog is available on this machine (no desktop portal); type the path instead";

/// The workbench application (also driven directly by the UI tests).
pub struct WorkbenchApp {
    state: AppState,
    forms: Forms,
    jobs: Jobs,
    /// Commands queued before the first frame (the start-up file).
    startup: Vec<Command>,
    /// Screen rectangle of the Results view's plots in the last frame.
    plots_rect: Option<egui::Rect>,
    /// Where the awaited screenshot's PNG goes, and since when.
    png_target: Option<(PathBuf, Instant)>,
    /// Whether [`install_fonts`] has run.
    fonts_installed: bool,
}

/// Adds the default monospace font (Hack) as a fallback of the
/// proportional family: egui's default proportional font has no arrows
/// (→) or geometric shapes (▶ ● ○ ■), which the workbench uses.
pub fn install_fonts(ctx: &egui::Context) {
    let mut fonts = egui::FontDefinitions::default();
    if fonts.font_data.contains_key("Hack")
        && let Some(list) = fonts.families.get_mut(&egui::FontFamily::Proportional)
        && !list.iter().any(|f| f == "Hack")
    {
        list.push("Hack".to_string());
    }
    ctx.set_fonts(fonts);
}

impl WorkbenchApp {
    /// A workbench that opens `session` (else the demo) on its first frame
    /// and then `result` for review, with remembered `prefs`.
    #[must_use]
    pub fn new(prefs: Prefs, session: Option<PathBuf>, result: Option<PathBuf>) -> Self {
        let mut forms = Forms::default();
        let export_dir = prefs
            .export_folder
            .clone()
            .or_else(|| prefs.last_folder.clone())
            .or_else(|| std::env::current_dir().ok())
            .unwrap_or_default();
        forms.export_dir = export_dir.display().to_string();
        if let Some(dir) = &prefs.history_folder {
            forms.history.folder = dir.display().to_string();
        }
        let state = AppState {
            prefs,
            pending_result: result,
            ..AppState::default()
        };
        let startup = vec![session.map_or(Command::OpenDemo, Command::OpenPath)];
        Self {
            state,
            forms,
            jobs: Jobs::default(),
            startup,
            plots_rect: None,
            png_target: None,
            fonts_installed: false,
        }
    }

    /// A workbench with the preferences kept in eframe's storage.
    #[must_use]
    pub fn from_storage(
        storage: Option<&dyn eframe::Storage>,
        session: Option<PathBuf>,
        result: Option<PathBuf>,
    ) -> Self {
        let prefs = storage
            .and_then(|s| s.get_string(PREFS_KEY))
            .and_then(|text| serde_json::from_str(&text).ok())
            .unwrap_or_default();
        Self::new(prefs, session, result)
    }

    /// The state, for tests and the shell.
    #[must_use]
    pub fn state(&self) -> &AppState {
        &self.state
    }

    /// The form fields, for tests.
    #[must_use]
    pub fn forms(&self) -> &Forms {
        &self.forms
    }

    /// The form fields, for tests that set them directly.
    pub fn forms_mut(&mut self) -> &mut Forms {
        &mut self.forms
    }

    /// True while background work is in flight (or the start-up file has
    /// not been asked for yet).
    #[must_use]
    pub fn is_busy(&self) -> bool {
        !self.startup.is_empty() || self.state.is_busy() || self.state.pending_result.is_some()
    }

    /// Applies a command as if a panel had pushed it (for tests).
    pub fn command(&mut self, ctx: &egui::Context, command: Command) {
        self.apply(ctx, command);
    }

    /// The non-drawing part of a frame: the start-up commands, the job
    /// messages, the screenshot timeout. Also run while the window is
    /// hidden (eframe's `logic`), so that a long run never waits on a full
    /// channel.
    pub fn pump(&mut self, ctx: &egui::Context) {
        for c in std::mem::take(&mut self.startup) {
            self.apply(ctx, c);
        }
        for message in self.jobs.drain() {
            self.on_message(ctx, message);
        }
        self.screenshot_timeout(ctx);
    }

    /// One frame: drain job messages, draw everything, apply the commands.
    pub fn show(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        if !self.fonts_installed {
            // Takes effect at once: nothing has been laid out yet this pass.
            install_fonts(&ctx);
            self.fonts_installed = true;
        }
        self.pump(&ctx);
        let mut commands = Vec::new();
        self.input_commands(&ctx, &mut commands);
        egui::Panel::bottom("status").show(ui, |ui| panels::status::status_ui(ui, &self.state));
        egui::Panel::left("side")
            .resizable(true)
            .default_size(290.0)
            .size_range(240.0..=420.0)
            .show(ui, |ui| {
                panels::side::side_ui(ui, &self.state, &mut self.forms, &mut commands);
            });
        egui::CentralPanel::default().show(ui, |ui| {
            panels::tabs_ui(ui, &self.state, &self.forms, &mut commands);
            ui.separator();
            match self.forms.tab {
                Tab::Session => {
                    panels::session::session_ui(ui, &self.state, &mut self.forms, &mut commands);
                }
                Tab::Stripe => {
                    panels::stripe::stripe_ui(ui, &self.state, &self.forms, &mut commands)
                }
                Tab::Centres => {
                    panels::centres::centres_ui(ui, &self.state, &mut self.forms, &mut commands);
                }
                Tab::Results => {
                    self.plots_rect = panels::results::results_ui(
                        ui,
                        &self.state,
                        &mut self.forms,
                        &mut commands,
                    );
                }
                Tab::Import => {
                    panels::import::import_ui(ui, &self.state, &mut self.forms, &mut commands);
                }
                Tab::Plan => {
                    panels::plan::plan_ui(ui, &self.state, &mut self.forms, &mut commands);
                }
                Tab::History => {
                    panels::history::history_ui(ui, &self.state, &mut self.forms, &mut commands);
                }
            }
        });
        panels::drop_overlay_ui(&ctx);
        for c in commands {
            self.apply(&ctx, c);
        }
    }

    /// Gives up on a window screenshot that never came (a backend that
    /// cannot take one), so that the export stays usable.
    fn screenshot_timeout(&mut self, ctx: &egui::Context) {
        let Some((_, since)) = &self.png_target else {
            return;
        };
        if since.elapsed() >= SCREENSHOT_TIMEOUT {
            self.png_target = None;
            self.state.busy.screenshot = false;
            self.state.say(
                Level::Warning,
                "no screenshot came from the window system: no PNG written",
            );
        } else {
            ctx.request_repaint_after(SCREENSHOT_TIMEOUT);
        }
    }

    /// Dropped files and the arrow keys.
    fn input_commands(&self, ctx: &egui::Context, commands: &mut Vec<Command>) {
        let dropped: Vec<PathBuf> = ctx.input(|i| {
            i.raw
                .dropped_files
                .iter()
                .map(|f| f.path().to_path_buf())
                .collect()
        });
        if let Some(p) = dropped.into_iter().next() {
            commands.push(Command::OpenPath(p));
        }
        let stepping = matches!(self.forms.tab, Tab::Session | Tab::Stripe)
            && ctx.memory(|m| m.focused().is_none());
        if stepping {
            let (down, up) = ctx.input(|i| {
                (
                    i.key_pressed(egui::Key::ArrowDown) || i.key_pressed(egui::Key::ArrowRight),
                    i.key_pressed(egui::Key::ArrowUp) || i.key_pressed(egui::Key::ArrowLeft),
                )
            });
            if down {
                commands.push(Command::Step(1));
            }
            if up {
                commands.push(Command::Step(-1));
            }
        }
    }

    /// Starts a job, or reports why it could not start.
    fn spawn(
        &mut self,
        ctx: &egui::Context,
        name: &str,
        work: impl FnOnce(&super::jobs::Reporter) + Send + 'static,
    ) -> bool {
        match self.jobs.spawn(name, ctx, work) {
            Ok(()) => true,
            Err(e) => {
                self.state.say(Level::Error, e);
                false
            }
        }
    }

    fn apply(&mut self, ctx: &egui::Context, command: Command) {
        match command {
            Command::OpenDemo => {
                self.state.say(Level::Info, "opening the demo session…");
                let started = self.spawn(ctx, "load", |rep| {
                    rep.send(match work::open_demo() {
                        Ok(l) => JobMessage::SessionLoaded(Box::new(l)),
                        Err(e) => JobMessage::LoadFailed(e),
                    });
                });
                if started {
                    self.state.busy.loading += 1;
                }
            }
            Command::OpenPath(path) => self.open_path(ctx, path),
            Command::Browse(purpose) => self.browse(ctx, purpose),
            Command::ShowTab(tab) => self.forms.tab = tab,
            Command::Select(i) => self.state.selected = Some(i),
            Command::Inspect(i) => {
                self.state.selected = Some(i);
                self.forms.tab = Tab::Stripe;
            }
            Command::Step(delta) => self.step(delta),
            Command::SetIncluded { id, included } => {
                if included {
                    self.state.excluded.remove(&id);
                } else {
                    self.state.excluded.insert(id);
                }
                self.say_excluded();
            }
            Command::SetStationIncluded { station, included } => {
                if let Some(l) = &self.state.loaded {
                    for m in l
                        .session
                        .measurements
                        .iter()
                        .filter(|m| m.station == station)
                    {
                        if included {
                            self.state.excluded.remove(&m.id);
                        } else {
                            self.state.excluded.insert(m.id.clone());
                        }
                    }
                }
                self.say_excluded();
            }
            Command::IncludeAll => {
                self.state.excluded.clear();
                self.say_excluded();
            }
            Command::SaveSession => self.save_session(ctx, false),
            Command::Run => self.run(ctx),
            Command::Cancel => {
                if let Some(run) = &mut self.state.run {
                    run.cancel.store(true, Ordering::Relaxed);
                    run.cancelling = true;
                    self.state.say(Level::Info, "cancelling the run…");
                }
            }
            Command::Export(kind) => self.export(ctx, kind),
            Command::DismissNotice => self.state.notice = None,
            Command::ClearRecent => self.state.prefs.recent.clear(),
            Command::ImportPreview { guess } => self.import_preview(ctx, guess),
            Command::ImportRun => self.import_run(ctx),
            Command::HistoryScan => self.history_scan(ctx),
            Command::HistoryDrift => self.history_drift(),
            Command::PlanMake => self.plan_make(ctx),
            Command::PlanCancel => {
                if let Some(c) = &self.state.plan.cancel {
                    c.store(true, Ordering::Relaxed);
                    self.state.plan.progress = Some("cancelling…".to_string());
                }
            }
            Command::PlanExport(kind) => self.plan_export(ctx, kind),
            Command::PlanSimulate => self.plan_simulate(ctx),
        }
    }

    fn plan_make(&mut self, ctx: &egui::Context) {
        if self.state.plan.cancel.is_some() {
            return;
        }
        let session_hand_eye = self
            .state
            .result
            .as_ref()
            .map(|v| v.file.hand_eye)
            .or_else(|| self.state.loaded.as_ref().and_then(|l| l.session.hand_eye));
        let config = match self.forms.plan.config(session_hand_eye) {
            Ok(c) => c,
            Err(e) => {
                self.state.plan.outcome = Some(Err(e.clone()));
                self.state.say(Level::Warning, e);
                return;
            }
        };
        let runs = self.forms.plan.request.predict_runs;
        let cancel = Arc::new(AtomicBool::new(false));
        let flag = Arc::clone(&cancel);
        let started = self.spawn(ctx, "plan", move |rep| {
            let outcome = planner::make_plan(&config, runs, &flag, &mut |event| {
                rep.send(JobMessage::Plan(event));
            });
            rep.send(JobMessage::Plan(PlanEvent::Finished(outcome)));
        });
        if started {
            self.state.plan.cancel = Some(cancel);
            self.state.plan.progress = Some("planning…".to_string());
            self.state.say(Level::Info, "planning the poses…");
        }
    }

    fn current_plan(&mut self) -> Option<Plan> {
        match &self.state.plan.outcome {
            Some(Ok(o)) => Some((*o.plan).clone()),
            _ => {
                self.state.say(Level::Warning, "make a plan first");
                None
            }
        }
    }

    fn plan_export(&mut self, ctx: &egui::Context, kind: PlanExport) {
        let Some(plan) = self.current_plan() else {
            return;
        };
        let dir = PathBuf::from(self.forms.export_dir.trim());
        if !dir.is_dir() {
            self.state.notice = Some(Notice {
                title: "Nothing exported".to_string(),
                body: format!("the export folder {} does not exist", dir.display()),
            });
            return;
        }
        self.state.prefs.export_folder = Some(dir.clone());
        let path = dir.join(kind.file_name(&self.forms.plan.robot));
        let started = self.spawn(ctx, "export", move |rep| {
            let text = match kind {
                PlanExport::Csv => plan::plan_csv(&plan),
                PlanExport::Rapid => Controller::AbbRapid.render(&plan),
            };
            let outcome = write_atomic(&path, text.as_bytes()).map_err(|e| e.to_string());
            rep.send(JobMessage::PlanWritten {
                kind,
                path,
                outcome,
            });
        });
        if started {
            self.state.plan.writing += 1;
        }
    }

    fn plan_simulate(&mut self, ctx: &egui::Context) {
        let Some(plan) = self.current_plan() else {
            return;
        };
        let robot = self.forms.plan.robot.clone();
        let seed = self.forms.plan.request.seed;
        let started = self.spawn(ctx, "simulate", move |rep| {
            let outcome = planner::simulate_plan(&plan, &robot, seed)
                .map(|session| Box::new(work::analyse(session, Source::Simulated)));
            rep.send(JobMessage::PlanSimulated(outcome));
        });
        if started {
            self.state.plan.writing += 1;
            self.state
                .say(Level::Info, "simulating a session of the plan…");
        }
    }

    fn history_scan(&mut self, ctx: &egui::Context) {
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
            let outcome = history::scan(&folder)
                .map(Box::new)
                .map_err(|e| e.to_string());
            rep.send(JobMessage::Scanned { folder, outcome });
        });
        self.state.busy.scanning = started;
    }

    /// The drift of the chosen robot over the ticked results (fast: no
    /// file is read, a few hundred numbers are compared).
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

    fn import_preview(&mut self, ctx: &egui::Context, guess: bool) {
        let form = self.forms.import.clone();
        let started = self.spawn(ctx, "import", move |rep| {
            let (header, guessed, preview) = work::import_preview(form, guess);
            rep.send(JobMessage::ImportPreviewed {
                header,
                guessed,
                preview,
            });
        });
        if started {
            self.state.busy.importing += 1;
        }
    }

    fn import_run(&mut self, ctx: &egui::Context) {
        let form = self.forms.import.clone();
        if let Err(e) = form.spec() {
            self.state.import.outcome = Some(Err(e.clone()));
            self.state.say(Level::Warning, e);
            return;
        }
        self.state.say(Level::Info, "importing…");
        let started = self.spawn(ctx, "import", move |rep| {
            rep.send(JobMessage::Imported(work::import_session(&form)));
        });
        if started {
            self.state.busy.importing += 1;
        }
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

    fn open_path(&mut self, ctx: &egui::Context, path: PathBuf) {
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
        let started = self.spawn(ctx, "load", move |rep| {
            rep.send(match work::open_path(&path) {
                Ok(Opened::Session(l)) => JobMessage::SessionLoaded(l),
                Ok(Opened::Result(file)) => {
                    let view = super::view::ResultView::new(
                        *file,
                        ResultOrigin::Review(path.clone()),
                        session.as_ref(),
                    );
                    JobMessage::ResultLoaded {
                        path,
                        view: Box::new(view),
                    }
                }
                Err(e) => JobMessage::LoadFailed(e),
            });
        });
        if started {
            self.state.busy.loading += 1;
        }
    }

    fn browse(&mut self, ctx: &egui::Context, purpose: DialogPurpose) {
        if self.state.busy.dialog {
            return;
        }
        let folder = match purpose {
            DialogPurpose::ExportFolder => Some(PathBuf::from(self.forms.export_dir.trim())),
            DialogPurpose::HistoryFolder => self
                .state
                .prefs
                .history_folder
                .clone()
                .or_else(|| self.state.prefs.last_folder.clone()),
            DialogPurpose::ImportProfiles | DialogPurpose::ImportReferences => {
                Path::new(self.forms.import.joints.trim())
                    .parent()
                    .map(Path::to_path_buf)
                    .filter(|d| !d.as_os_str().is_empty())
                    .or_else(|| self.state.prefs.last_folder.clone())
            }
            _ => self.state.prefs.last_folder.clone(),
        };
        let profiles_folder = self.forms.import.profiles_kind == ProfilesKind::Folder;
        let file_name = Path::new(self.forms.save_path.trim())
            .file_name()
            .map(|n| n.to_string_lossy().into_owned());
        let started = self.spawn(ctx, "file-dialog", move |rep| {
            let mut dialog = rfd::FileDialog::new();
            if let Some(dir) = folder.filter(|d| d.is_dir()) {
                dialog = dialog.set_directory(dir);
            }
            let path = match purpose {
                DialogPurpose::Open => dialog
                    .add_filter("spherecal session or result", &["json"])
                    .pick_file(),
                DialogPurpose::SaveSession => {
                    let dialog = dialog.add_filter("spherecal session", &["json"]);
                    match file_name {
                        Some(n) => dialog.set_file_name(n),
                        None => dialog,
                    }
                    .save_file()
                }
                DialogPurpose::ExportFolder | DialogPurpose::HistoryFolder => dialog.pick_folder(),
                DialogPurpose::ImportJoints | DialogPurpose::ImportReferences => {
                    dialog.add_filter("CSV", &["csv", "txt"]).pick_file()
                }
                DialogPurpose::ImportProfiles if profiles_folder => dialog.pick_folder(),
                DialogPurpose::ImportProfiles => {
                    dialog.add_filter("CSV", &["csv", "txt"]).pick_file()
                }
            };
            rep.send(JobMessage::Dialog { purpose, path });
        });
        self.state.busy.dialog = started;
        if started {
            self.state.say(Level::Info, "waiting for the file dialog…");
        }
    }

    fn step(&mut self, delta: i32) {
        let rows = self.state.visible_rows(&self.forms);
        if rows.is_empty() {
            return;
        }
        let pos = self
            .state
            .selected
            .and_then(|s| rows.iter().position(|&r| r == s));
        let next = match pos {
            None => 0,
            Some(p) => {
                let last = rows.len() - 1;
                if delta < 0 {
                    p.saturating_sub(delta.unsigned_abs() as usize)
                } else {
                    (p + delta.unsigned_abs() as usize).min(last)
                }
            }
        };
        self.state.selected = Some(rows[next]);
    }

    fn save_session(&mut self, ctx: &egui::Context, confirmed: bool) {
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
        let confirmed = confirmed || self.state.confirm_overwrite.as_ref() == Some(&path);
        if path.exists() && !confirmed {
            let opened = loaded.source.path() == Some(path.as_path());
            self.state.say(
                Level::Warning,
                format!(
                    "{} exists{}: press Save again to replace it",
                    path.display(),
                    if opened {
                        " (it is the opened session file)"
                    } else {
                        ""
                    }
                ),
            );
            self.state.confirm_overwrite = Some(path);
            return;
        }
        self.state.confirm_overwrite = None;
        let session = loaded.session.clone();
        let excluded = self.state.excluded.clone();
        let started = self.spawn(ctx, "save", move |rep| {
            let outcome = work::save_without(&session, &excluded, &path);
            rep.send(JobMessage::Saved { path, outcome });
        });
        self.state.busy.saving = started;
    }

    fn run(&mut self, ctx: &egui::Context) {
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
            let outcome = work::calibrate_session(&loaded, &excluded, &options, &flag, &mut |p| {
                rep.send(JobMessage::Progress(*p))
            });
            rep.send(JobMessage::RunFinished(outcome.map(Box::new)));
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
            });
            self.state.say(Level::Info, "running the calibration…");
        }
    }

    fn export(&mut self, ctx: &egui::Context, kind: ExportKind) {
        let Some(view) = &self.state.result else {
            self.state.say(
                Level::Warning,
                "nothing to export: run the solver or open a result first",
            );
            return;
        };
        let dir = PathBuf::from(self.forms.export_dir.trim());
        if !dir.is_dir() {
            self.state.notice = Some(Notice {
                title: "Nothing exported".to_string(),
                body: format!("the export folder {} does not exist", dir.display()),
            });
            return;
        }
        self.state.prefs.export_folder = Some(dir.clone());
        let stem = match &self.state.loaded {
            Some(l) => l.source.stem(),
            None => "result".to_string(),
        };
        let path = dir.join(kind.file_name(&stem));
        if kind == ExportKind::PlotsPng {
            if self.state.busy.screenshot {
                return;
            }
            self.forms.tab = Tab::Results;
            self.png_target = Some((path, Instant::now()));
            self.state.busy.screenshot = true;
            let rep = self.jobs.reporter(ctx);
            ctx.request_screenshot(move |image| {
                rep.send(JobMessage::Screenshot(image));
            });
            self.state
                .say(Level::Info, "taking a screenshot of the plots…");
            return;
        }
        let view = view.clone();
        if kind == ExportKind::ReportHtml {
            let Some(loaded) = &self.state.loaded else {
                self.state
                    .say(Level::Warning, "a report needs the session: open it first");
                return;
            };
            let loaded = loaded.clone();
            let started = self.spawn(ctx, "export", move |rep| {
                let outcome = export::write_report(&view, &loaded, &path);
                rep.send(JobMessage::Exported {
                    kind,
                    path,
                    outcome,
                });
            });
            if started {
                self.state.busy.exporting += 1;
            }
            return;
        }
        let started = self.spawn(ctx, "export", move |rep| {
            let outcome = export::write_text(kind, &view, &path);
            rep.send(JobMessage::Exported {
                kind,
                path,
                outcome,
            });
        });
        if started {
            self.state.busy.exporting += 1;
        }
    }

    fn on_message(&mut self, ctx: &egui::Context, message: JobMessage) {
        match message {
            JobMessage::SessionLoaded(loaded) => self.on_session(ctx, *loaded),
            JobMessage::ResultLoaded { path, view } => {
                self.state.busy.loading = self.state.busy.loading.saturating_sub(1);
                self.state.prefs.remember(&path);
                let notes = view.notes.join("; ");
                self.forms.centres.magnify = view.centres.suggested_magnify;
                self.state.result = Some(*view);
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
            JobMessage::LoadFailed(LoadFailure { what, message }) => {
                self.state.busy.loading = self.state.busy.loading.saturating_sub(1);
                self.state
                    .say(Level::Error, format!("could not open {what}"));
                self.state.notice = Some(Notice {
                    title: format!("Could not open {what}"),
                    body: message,
                });
                if let Some(p) = self.state.pending_result.take() {
                    self.open_path(ctx, p);
                }
            }
            JobMessage::Progress(p) => {
                if let Some(run) = &mut self.state.run {
                    run.epsilons.truncate(p.updates);
                    run.epsilons.push(p.epsilon);
                }
            }
            JobMessage::RunFinished(outcome) => {
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
                        self.forms.tab = Tab::Results;
                        self.state
                            .say(Level::Info, format!("calibrated in {seconds:.2} s: {stop}"));
                    }
                    Err(RunFailure::Cancelled(n)) => self.state.say(
                        Level::Warning,
                        format!("run cancelled after {n} update(s); nothing was changed"),
                    ),
                    Err(RunFailure::Failed(message)) => {
                        self.state.say(Level::Error, "the calibration failed");
                        self.state.notice = Some(Notice {
                            title: "The calibration failed".to_string(),
                            body: message,
                        });
                    }
                }
            }
            JobMessage::Dialog { purpose, path } => {
                self.state.busy.dialog = false;
                self.state.dialog_empty = path.is_none();
                let Some(path) = path else {
                    self.state.say(Level::Warning, NO_DIALOG);
                    return;
                };
                match purpose {
                    DialogPurpose::Open => self.open_path(ctx, path),
                    DialogPurpose::SaveSession => {
                        self.forms.save_path = path.display().to_string();
                        // The dialog has asked about replacing a file already.
                        self.save_session(ctx, true);
                    }
                    DialogPurpose::ExportFolder => {
                        self.forms.export_dir = path.display().to_string();
                        self.state
                            .say(Level::Info, format!("exports go to {}", path.display()));
                    }
                    DialogPurpose::ImportJoints => {
                        self.forms.import.joints = path.display().to_string();
                        self.import_preview(ctx, true);
                    }
                    DialogPurpose::ImportProfiles => {
                        self.forms.import.profiles = path.display().to_string();
                    }
                    DialogPurpose::ImportReferences => {
                        self.forms.import.references = path.display().to_string();
                    }
                    DialogPurpose::HistoryFolder => {
                        self.forms.history.folder = path.display().to_string();
                        self.history_scan(ctx);
                    }
                }
            }
            JobMessage::Saved { path, outcome } => {
                self.state.busy.saving = false;
                match outcome {
                    Ok(n) => {
                        self.state.prefs.remember(&path);
                        self.state.say(
                            Level::Info,
                            format!(
                                "saved {n} measurements to {} (atomic write)",
                                path.display()
                            ),
                        );
                    }
                    Err(message) => {
                        self.state.say(Level::Error, "the session was not saved");
                        self.state.notice = Some(Notice {
                            title: format!("Could not save {}", path.display()),
                            body: message,
                        });
                    }
                }
            }
            JobMessage::Screenshot(image) => self.on_screenshot(ctx, &image),
            JobMessage::ImportPreviewed {
                header,
                guessed,
                preview,
            } => {
                self.state.busy.importing = self.state.busy.importing.saturating_sub(1);
                if let Some(form) = guessed {
                    let f = &mut self.forms.import;
                    f.id_column = form.id_column;
                    f.station_column = form.station_column;
                    f.use_column = form.use_column;
                    f.side_column = form.side_column;
                    f.joint_columns = form.joint_columns;
                }
                self.state.import.header = header;
                match &preview {
                    Ok(_) => self
                        .state
                        .say(Level::Info, "preview of the mapped rows below"),
                    Err(e) => self.state.say(Level::Warning, format!("preview: {e}")),
                }
                self.state.import.preview = Some(preview);
            }
            JobMessage::Plan(PlanEvent::Progress(text)) => {
                if self.state.plan.cancel.is_some() {
                    self.state.plan.progress = Some(text);
                }
            }
            JobMessage::Plan(PlanEvent::Finished(outcome)) => {
                self.state.plan.cancel = None;
                self.state.plan.progress = None;
                match &outcome {
                    Ok(o) => {
                        let line = match &o.prediction {
                            Some(Ok(p)) => format!(
                                "planned {} poses; predicted validation std after {:.3} ± {:.3} mm",
                                o.plan.poses.len(),
                                p.after_mean,
                                p.after_spread
                            ),
                            Some(Err(e)) => {
                                format!("planned {} poses; no prediction: {e}", o.plan.poses.len())
                            }
                            None => format!("planned {} poses", o.plan.poses.len()),
                        };
                        self.state.say(Level::Info, line);
                    }
                    Err(e) => self.state.say(Level::Warning, format!("no plan: {e}")),
                }
                self.state.plan.outcome = Some(outcome);
            }
            JobMessage::PlanWritten {
                kind,
                path,
                outcome,
            } => {
                self.state.plan.writing = self.state.plan.writing.saturating_sub(1);
                self.say_written(kind.label(), &path, outcome);
            }
            JobMessage::PlanSimulated(outcome) => {
                self.state.plan.writing = self.state.plan.writing.saturating_sub(1);
                match outcome {
                    Ok(loaded) => {
                        self.on_session(ctx, *loaded);
                        self.state.say(
                            Level::Info,
                            "opened a session simulated from the plan (not saved yet): press Run to calibrate it",
                        );
                    }
                    Err(message) => {
                        self.state
                            .say(Level::Error, "the plan could not be simulated");
                        self.state.notice = Some(Notice {
                            title: "Could not simulate the plan".to_string(),
                            body: message,
                        });
                    }
                }
            }
            JobMessage::Scanned { folder, outcome } => {
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
                    Err(message) => {
                        self.state
                            .say(Level::Error, "the library could not be scanned");
                        self.state.history.library = Some(Err(message));
                    }
                }
                self.history_drift();
            }
            JobMessage::Imported(outcome) => {
                self.state.busy.importing = self.state.busy.importing.saturating_sub(1);
                match outcome {
                    Ok(imported) => {
                        let flagged = imported.checks.iter().filter(|c| c.flagged).count();
                        let n = imported.loaded.session.measurements.len();
                        let refs = imported.loaded.session.reference_distances.len();
                        let mut line =
                            format!("imported {n} measurements and {refs} reference distances");
                        if !imported.checks.is_empty() {
                            line.push_str(&format!(
                                "; flange poses: {} checked, {flagged} flagged",
                                imported.checks.len()
                            ));
                        }
                        self.state.import.checks = imported.checks;
                        self.state.import.outcome = Some(Ok(line.clone()));
                        self.on_session(ctx, *imported.loaded);
                        self.forms.tab = if flagged > 0 {
                            Tab::Import
                        } else {
                            Tab::Session
                        };
                        let level = if flagged > 0 {
                            Level::Warning
                        } else {
                            Level::Info
                        };
                        self.state.say(
                            level,
                            format!("{line}: not saved yet, use Save as… on the Session view"),
                        );
                    }
                    Err(message) => {
                        self.state.say(Level::Error, "the import failed");
                        self.state.import.checks.clear();
                        self.state.import.outcome = Some(Err(message));
                    }
                }
            }
            JobMessage::Exported {
                kind,
                path,
                outcome,
            } => {
                self.state.busy.exporting = self.state.busy.exporting.saturating_sub(1);
                self.say_written(kind.label(), &path, outcome);
            }
        }
    }

    /// The status line for a written file, or the notice of why not.
    fn say_written(&mut self, what: &str, path: &Path, outcome: Result<(), String>) {
        match outcome {
            Ok(()) => self
                .state
                .say(Level::Info, format!("wrote {what} to {}", path.display())),
            Err(message) => {
                self.state.say(Level::Error, format!("{what} not written"));
                self.state.notice = Some(Notice {
                    title: format!("Could not write {what}"),
                    body: message,
                });
            }
        }
    }

    fn on_session(&mut self, ctx: &egui::Context, loaded: LoadedSession) {
        self.state.busy.loading = self.state.busy.loading.saturating_sub(1);
        if let Some(run) = self.state.run.take() {
            // The run was of the previous session: stop it, forget it.
            run.cancel.store(true, Ordering::Relaxed);
        }
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
        self.forms.filter_station = None;
        self.forms.filter_use = None;
        if self.forms.tab == Tab::Results {
            self.forms.tab = Tab::Session;
        }
        self.state.excluded.clear();
        self.state.confirm_overwrite = None;
        self.state.selected = (!loaded.session.measurements.is_empty()).then_some(0);
        self.state.result = None;
        self.state.notice = None;
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
        self.state.say(level, text);
        if let Ok(set) = &loaded.before {
            self.forms.centres.magnify = set.suggested_magnify;
        }
        self.state.loaded = Some(loaded);
        if let Some(p) = self.state.pending_result.take() {
            self.open_path(ctx, p);
        }
    }

    fn on_screenshot(&mut self, ctx: &egui::Context, image: &Arc<egui::ColorImage>) {
        self.state.busy.screenshot = false;
        let (Some((path, _)), Some(rect)) = (self.png_target.take(), self.plots_rect) else {
            self.state.say(
                Level::Warning,
                "the plots were not on screen: no PNG written",
            );
            return;
        };
        let ppp = ctx.pixels_per_point();
        let px = |v: f32| (v * ppp).round().max(0.0) as usize;
        let crop = [
            px(rect.min.x),
            px(rect.min.y),
            px(rect.width()),
            px(rect.height()),
        ];
        let image = Arc::clone(image);
        let started = self.spawn(ctx, "export", move |rep| {
            let outcome = export::write_png(&image, crop, &path);
            rep.send(JobMessage::Exported {
                kind: ExportKind::PlotsPng,
                path,
                outcome,
            });
        });
        if started {
            self.state.busy.exporting += 1;
        }
    }
}

impl eframe::App for WorkbenchApp {
    fn logic(&mut self, ctx: &egui::Context, _frame: &mut eframe::Frame) {
        self.pump(ctx);
    }

    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        self.show(ui);
    }

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        if let Ok(text) = serde_json::to_string(&self.state.prefs) {
            storage.set_string(PREFS_KEY, text);
        }
    }
}
