//! The solver panel on the left: the settings of the next run, Run and
//! Cancel, the run's phase and fraction and its live ε, or the ε of the
//! result on show.

use egui::{RichText, Vec2};

use crate::app::command::{Command, RunCommand};
use crate::app::job::Slot;
use crate::app::ledger::Artefact;
use crate::app::widgets::{BAD, WARN, choice, form_grid, labelled_drag, plots::epsilon_plot_ui};
use crate::app::{AppState, Forms};
use crate::engine::calibrate::solve::Method;
use crate::engine::calibrate::solve::paper::Pairing;

/// Height of the side panel's ε plot, points.
const SIDE_EPSILON_HEIGHT: f32 = 150.0;

/// The solver: settings, Run and Cancel, progress and the live ε plot.
pub fn solver_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    forms: &mut Forms,
    commands: &mut Vec<Command>,
) {
    ui.heading("Solver");
    let run = state.jobs.get(&Slot::Run);
    let running = run.is_some();
    ui.add_enabled_ui(!running, |ui| settings_ui(ui, forms));
    ui.add_space(6.0);
    // A session whose stripes do not all fit can still run once the
    // failing measurements are left out: the run reports what fails.
    let can_run = !running && state.loaded.is_some();
    ui.horizontal(|ui| {
        let text = RichText::new("▶ Run").size(18.0).strong();
        let run = egui::Button::new(text).min_size(Vec2::new(110.0, 32.0));
        let hover = "calibrate the session with these settings";
        if ui.add_enabled(can_run, run).on_hover_text(hover).clicked() {
            commands.push(Command::Run(RunCommand::Start));
        }
        let text = RichText::new("Cancel").size(16.0);
        let cancel = egui::Button::new(text).min_size(Vec2::new(80.0, 32.0));
        let hover = "stop the run now: the result on show stays";
        if ui
            .add_enabled(running, cancel)
            .on_hover_text(hover)
            .clicked()
        {
            commands.push(Command::Run(RunCommand::Cancel));
        }
    });
    if let Some(l) = &state.loaded
        && let Err(e) = &l.before
    {
        let why = format!("the whole session cannot be prepared: {e}; leave out what fails");
        ui.label(RichText::new(why).color(BAD).small());
    }
    let excluded = state.excluded_count();
    if excluded > 0 && !running {
        ui.label(RichText::new(format!("{excluded} measurement(s) will be left out")).small());
    }
    if let Some(run) = run {
        // Always the phase by name and the whole run's fraction: the bar
        // never sits still without saying what the run is doing.
        ui.horizontal(|ui| {
            ui.spinner();
            let text = match run.series.last() {
                Some(eps) if run.phase.starts_with("update") && !run.phase.contains(':') => {
                    let most = forms.solver.max_iterations;
                    format!("{} of ≤ {most}: ε = {eps:.4} mm", run.phase)
                }
                _ => run.phase.clone(),
            };
            ui.add(egui::Label::new(text).wrap());
        });
        let fraction = run.fraction.unwrap_or_default() as f32;
        ui.add(egui::ProgressBar::new(fraction).show_percentage());
        epsilon_plot_ui(
            ui,
            "live_epsilon",
            &run.series,
            Some(forms.solver.threshold),
            SIDE_EPSILON_HEIGHT,
        );
    } else if let Some(result) = &state.result {
        match state.ledger.stale(Artefact::Result) {
            Some(s) => {
                let text = RichText::new("ε of the result on show (stale)").small();
                ui.label(text.color(WARN)).on_hover_text(s.to_string())
            }
            None => ui.label(RichText::new("ε of the result on show").small().weak()),
        };
        epsilon_plot_ui(
            ui,
            "last_epsilon",
            &result.epsilons(),
            result.file.solver.threshold(),
            SIDE_EPSILON_HEIGHT,
        );
        if let Some(stop) = result.file.solver.stop_reason() {
            ui.label(RichText::new(stop).small());
        }
    }
}

/// Method, pairing, threshold, iteration bound, SVD tolerance.
fn settings_ui(ui: &mut egui::Ui, forms: &mut Forms) {
    let s = &mut forms.solver;
    form_grid(ui, "solver_settings", 2, |ui| {
        let methods = Method::ALL.map(|m| (m, m.as_str().to_string()));
        choice(ui, "Method", "method", &mut s.method, methods)
            .on_hover_text("identification method");
        ui.end_row();
        let paper = s.method == Method::Paper;
        ui.label("Pairs");
        ui.add_enabled_ui(paper, |ui| {
            let pairings = [Pairing::Disjoint, Pairing::All].map(|p| (p, p.as_str().to_string()));
            choice(ui, "", "pairing", &mut s.paper.pairing, pairings)
                .on_hover_text("pairs of a station's measurements: disjoint (1,2),(3,4),… as in the paper, or all")
                .on_disabled_hover_text("used by the paper's method only");
        });
        ui.end_row();
        let threshold = egui::DragValue::new(&mut s.threshold).range(0.0..=10.0);
        let threshold = threshold.speed(0.001).max_decimals(4).suffix(" mm");
        labelled_drag(ui, "Threshold", threshold).on_hover_text("stop when ε falls to this");
        ui.end_row();
        let most = egui::DragValue::new(&mut s.max_iterations).range(1..=500);
        labelled_drag(ui, "Max iterations", most.speed(0.2));
        ui.end_row();
        let l = ui.label("SVD tolerance");
        ui.add_enabled(
            paper,
            egui::DragValue::new(&mut s.paper.svd_tolerance)
                .range(1e-12..=0.5)
                .speed(1e-5)
                .custom_formatter(|v, _| format!("{v:.1e}"))
                .custom_parser(|t| t.trim().parse::<f64>().ok()),
        )
        .labelled_by(l.id)
        .on_hover_text(
            "singular values below this fraction of the largest are dropped (truncated SVD)",
        )
        .on_disabled_hover_text("used by the paper's method only");
        ui.end_row();
    });
}
