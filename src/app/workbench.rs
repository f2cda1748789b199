//! The frame loop: owns the [`Core`] (state with its job table, forms).
//! Each frame it takes the jobs' reports, draws the left panel, the step
//! bar, the tabs and the view on show (which push commands), hands the
//! commands to their features, and only then shows the answers that
//! arrived in the frame (so that Cancel, clicked while a job's answer was
//! on its way, always wins).

use std::path::PathBuf;

use super::AppState;
use super::Core;
use super::Forms;
use super::command::Tab;
use super::command::{Command, FilesCommand, ViewCommand};
use super::state::Prefs;
use super::{check, compensate, history, import, steps};
use super::{measure, plan, results, run, session, widgets};

/// Key of the preferences in eframe's storage (JSON text).
pub const PREFS_KEY: &str = "spherecal.prefs";

/// What drives the window instead of an operator (a screenshot
/// scenario): it sees each frame's input first and the core after each
/// frame.
pub trait Driver {
    /// Adds to the input of the next frame (the pointer, the wheel).
    fn raw_input(&mut self, raw: &mut egui::RawInput);
    /// Acts after the frame: commands, form edits, checks, a picture.
    fn frame(&mut self, ctx: &egui::Context, core: &mut Core);
}

/// The workbench application (also driven directly by the UI tests).
pub struct WorkbenchApp {
    core: Core,
    /// Commands queued before the first frame (the start-up file).
    startup: Vec<Command>,
    /// Whether [`install_fonts`] has run.
    fonts_installed: bool,
    /// What drives the window instead of an operator (a screenshot
    /// scenario), if anything.
    driver: Option<Box<dyn Driver>>,
}

/// Adds the default monospace font (Hack) as a fallback of the
/// proportional family: egui's default proportional font has no arrows
/// (→) or geometric shapes (▶ ● ○ ■), which the workbench uses; and sets
/// the text sizes (secondary text 12 px).
pub fn install_fonts(ctx: &egui::Context) {
    let mut fonts = egui::FontDefinitions::default();
    if fonts.font_data.contains_key("Hack")
        && let Some(list) = fonts.families.get_mut(&egui::FontFamily::Proportional)
        && !list.iter().any(|f| f == "Hack")
    {
        list.push("Hack".to_string());
    }
    ctx.set_fonts(fonts);
    // Secondary text at least 12 px (egui's small style is 9 px), body
    // and buttons 14 px: readable on a shop-floor screen.
    ctx.all_styles_mut(|style| {
        use egui::{FontFamily, FontId, TextStyle};
        for (text, size) in [
            (TextStyle::Small, 12.0),
            (TextStyle::Body, 14.0),
            (TextStyle::Button, 14.0),
        ] {
            let font = FontId::new(size, FontFamily::Proportional);
            style.text_styles.insert(text, font);
        }
    });
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
        let open = session.map_or(FilesCommand::OpenDemo, FilesCommand::OpenPath);
        Self {
            core: Core::new(state, forms),
            startup: vec![Command::Files(open)],
            fonts_installed: false,
            driver: None,
        }
    }

    /// The workbench driven by `driver` (nothing stored).
    #[must_use]
    pub fn with_driver(mut self, driver: impl Driver + 'static) -> Self {
        self.driver = Some(Box::new(driver));
        self
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
        &self.core.state
    }

    /// The form fields, for tests.
    #[must_use]
    pub fn forms(&self) -> &Forms {
        &self.core.forms
    }

    /// The form fields, for tests that set them directly.
    pub fn forms_mut(&mut self) -> &mut Forms {
        &mut self.core.forms
    }

    /// True while background work is in flight (or the start-up file has
    /// not been asked for yet).
    #[must_use]
    pub fn is_busy(&self) -> bool {
        let state = &self.core.state;
        !self.startup.is_empty() || state.is_busy() || state.pending_result.is_some()
    }

    /// Applies a command as if a panel had pushed it (for tests).
    pub fn command(&mut self, ctx: &egui::Context, command: Command) {
        self.core.apply(ctx, command);
    }

    /// The non-drawing part of a frame: the start-up commands, the job
    /// reports (answers wait for [`Core::finish`]). Also run while the window is
    /// hidden (eframe's `logic`), so that a long run never waits on a full
    /// channel.
    pub fn pump(&mut self, ctx: &egui::Context) {
        for c in std::mem::take(&mut self.startup) {
            self.core.apply(ctx, c);
        }
        self.core.state.jobs.drain();
        self.core.observe(ctx);
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
        input_commands(&ctx, &self.core.forms, &mut commands);
        let Core { state, forms, .. } = &mut self.core;
        egui::Panel::bottom("status").show(ui, |ui| widgets::status_ui(ui, state));
        egui::Panel::left("side")
            .resizable(true)
            .default_size(290.0)
            .size_range(240.0..=420.0)
            .show(ui, |ui| {
                let scroll = egui::ScrollArea::vertical().auto_shrink([false, false]);
                scroll.show(ui, |ui| {
                    ui.add_space(4.0);
                    session::ui::load_ui(ui, state, forms, &mut commands);
                    ui.separator();
                    run::ui::solver_ui(ui, state, forms, &mut commands);
                    // What comes and goes sits below the solver, so that Run
                    // and the ε plot stay where they are (and on screen at
                    // 1366×768).
                    session::ui::notice_ui(ui, state, &mut commands);
                    session::ui::recent_ui(ui, state, &mut commands);
                });
            });
        egui::CentralPanel::default().show(ui, |ui| {
            steps::steps_ui(ui, state, forms, &mut commands);
            widgets::tabs_ui(ui, state, forms, &mut commands);
            ui.separator();
            match forms.tab {
                Tab::Session => session::ui::session_ui(ui, state, forms, &mut commands),
                Tab::Stripe => session::stripe::stripe_ui(ui, state, forms, &mut commands),
                Tab::Centres => results::centres::centres_ui(ui, state, forms, &mut commands),
                Tab::Results => results::ui::results_ui(ui, state, forms, &mut commands),
                Tab::Import => import::ui::import_ui(ui, state, forms, &mut commands),
                Tab::Plan => plan::ui::plan_ui(ui, state, forms, &mut commands),
                Tab::History => history::ui::history_ui(ui, state, forms, &mut commands),
                Tab::Compensate => {
                    compensate::ui::compensate_ui(ui, state, forms, &mut commands);
                }
                Tab::Measure => measure::ui::measure_ui(ui, state, forms, &mut commands),
                Tab::Check => check::ui::check_ui(ui, state, forms, &mut commands),
            }
        });
        widgets::drop_overlay_ui(&ctx);
        widgets::confirm_ui(&ctx, state, &mut commands);
        for c in commands {
            self.core.apply(&ctx, c);
        }
        // Answers are shown after the frame's commands: a Cancel clicked
        // in the frame an answer arrived in wins.
        self.core.finish(&ctx);
        // Fields edited this frame mark what they feed stale at once.
        self.core.observe(&ctx);
        if let Some(director) = &mut self.driver {
            director.frame(&ctx, &mut self.core);
        }
    }
}

/// Dropped files and the arrow keys, as commands.
fn input_commands(ctx: &egui::Context, forms: &Forms, commands: &mut Vec<Command>) {
    let dropped: Vec<PathBuf> = ctx.input(|i| {
        i.raw
            .dropped_files
            .iter()
            .map(|f| f.path().to_path_buf())
            .collect()
    });
    if let Some(p) = dropped.into_iter().next() {
        commands.push(Command::Files(FilesCommand::OpenPath(p)));
    }
    let stepping =
        matches!(forms.tab, Tab::Session | Tab::Stripe) && ctx.memory(|m| m.focused().is_none());
    if stepping {
        let (down, up) = ctx.input(|i| {
            (
                i.key_pressed(egui::Key::ArrowDown) || i.key_pressed(egui::Key::ArrowRight),
                i.key_pressed(egui::Key::ArrowUp) || i.key_pressed(egui::Key::ArrowLeft),
            )
        });
        if down {
            commands.push(Command::View(ViewCommand::Step(1)));
        }
        if up {
            commands.push(Command::View(ViewCommand::Step(-1)));
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

    fn raw_input_hook(&mut self, _ctx: &egui::Context, raw_input: &mut egui::RawInput) {
        if let Some(director) = &mut self.driver {
            director.raw_input(raw_input);
        }
    }

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        if self.driver.is_some() {
            return;
        }
        if let Ok(text) = serde_json::to_string(&self.core.state.prefs) {
            storage.set_string(PREFS_KEY, text);
        }
    }
}
