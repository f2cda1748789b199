//! The left panel: load a session or result (path field, native dialog,
//! demo, recent files, the error of a file that did not load) and the
//! solver (settings, Run, Cancel, live ε).

use egui::{RichText, Vec2};
use egui_plot::{HLine, Line, Plot, PlotPoints, Points};

use crate::engine::calibrate::solve::Method;
use crate::engine::calibrate::solve::paper::Pairing;

use super::{AFTER, BAD, BEFORE, labelled_field};
use crate::app::commands::{Command, FilesCommand, RunCommand, ViewCommand};
use crate::app::dialog::{NO_DIALOG, Purpose};
use crate::app::forms::Forms;
use crate::app::job::Slot;
use crate::app::ledger::Artefact;
use crate::app::state::AppState;

/// The whole left panel.
pub fn side_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    forms: &mut Forms,
    commands: &mut Vec<Command>,
) {
    egui::ScrollArea::vertical()
        .auto_shrink([false, false])
        .show(ui, |ui| {
            ui.add_space(4.0);
            load_ui(ui, state, forms, commands);
            ui.separator();
            solver_ui(ui, state, forms, commands);
            // What comes and goes sits below the solver, so that Run and
            // the ε plot stay where they are (and on screen at 1366×768).
            notice_ui(ui, state, commands);
            recent_ui(ui, state, commands);
        });
}

/// Height of the side panel's ε plot, points.
const SIDE_EPSILON_HEIGHT: f32 = 150.0;

/// Loading: the current session (three lines whatever it is, so that
/// nothing below moves), the path field with Open… and the demo.
pub fn load_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    forms: &mut Forms,
    commands: &mut Vec<Command>,
) {
    ui.heading("Session");
    let line = |ui: &mut egui::Ui, text: RichText| ui.add(egui::Label::new(text).truncate());
    // Whole, wrapped: a cut path or count hides what is open.
    let whole = |ui: &mut egui::Ui, text: RichText| ui.add(egui::Label::new(text).wrap());
    if let Some(l) = &state.loaded {
        name_ui(ui, &l.session.name);
        whole(ui, RichText::new(l.source.label()).small().weak());
        let n = l.session.measurements.len();
        let stations = l.station_ids().len();
        let text = format!(
            "{n} measurements, {stations} station{}, sphere Ø {} mm{}",
            if stations == 1 { "" } else { "s" },
            l.session.sphere_diameter,
            if l.session.pose_only() {
                " · pose-only (flange poses)"
            } else {
                ""
            }
        );
        whole(ui, RichText::new(text).small());
    } else {
        match state.jobs.get(&Slot::Load) {
            Some(job) => name_ui(ui, &job.phase),
            None => name_ui(ui, "no session open"),
        }
        line(ui, RichText::new(" ").small());
        line(ui, RichText::new(" ").small());
    }
    ui.add_space(4.0);
    let width = ui.available_width();
    let field = ui
        .vertical(|ui| {
            labelled_field(
                ui,
                "Session or result file",
                &mut forms.open_path,
                "/path/to/session.json",
                width,
            )
        })
        .inner;
    let entered = field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
    ui.horizontal(|ui| {
        if ui
            .button("Open path")
            .on_hover_text("open the file typed above")
            .clicked()
            || entered
        {
            commands.push(Command::Files(FilesCommand::OpenPath(
                forms.open_path.trim().into(),
            )));
        }
        let dialog = ui
            .add_enabled(!state.jobs.runs(&Slot::Dialog), egui::Button::new("Open…"))
            .on_hover_text("choose a file with the desktop's file dialog");
        if dialog.clicked() {
            commands.push(Command::Browse(Purpose::Open));
        }
        if ui
            .button("Demo")
            .on_hover_text("the demo session built into the program")
            .clicked()
        {
            commands.push(Command::Files(FilesCommand::OpenDemo));
        }
    });
    // One line either way: the dialog's note replaces the drop hint.
    let hint = if state.dialog_empty == Some(Purpose::Open) {
        NO_DIALOG
    } else {
        "or drop a file onto the window"
    };
    line(ui, RichText::new(hint).small().weak()).on_hover_text(hint);
}

/// The session's name in two lines of room whatever its length (wrapped,
/// cut with … beyond two lines, whole on hover).
fn name_ui(ui: &mut egui::Ui, name: &str) {
    let style = egui::TextStyle::Body;
    let width = ui.available_width();
    let height = 2.0 * ui.text_style_height(&style);
    let mut job = egui::text::LayoutJob::single_section(
        name.to_string(),
        egui::TextFormat {
            font_id: style.resolve(ui.style()),
            color: ui.visuals().strong_text_color(),
            ..Default::default()
        },
    );
    job.wrap = egui::text::TextWrapping {
        max_width: width,
        max_rows: 2,
        break_anywhere: false,
        overflow_character: Some('…'),
    };
    let rect = egui::Rect::from_min_size(ui.cursor().min, egui::vec2(width, height));
    let used = ui
        .scope_builder(egui::UiBuilder::new().max_rect(rect), |ui| {
            ui.add(egui::Label::new(job)).on_hover_text(name);
        })
        .response
        .rect
        .height();
    if used < height {
        ui.add_space(height - used);
    }
}

/// The error of the last thing that failed (a file that did not open, an
/// export not written), until dismissed.
pub fn notice_ui(ui: &mut egui::Ui, state: &AppState, commands: &mut Vec<Command>) {
    if let Some(notice) = &state.notice {
        ui.add_space(6.0);
        egui::Frame::group(ui.style())
            .stroke(egui::Stroke::new(1.5, BAD))
            .show(ui, |ui| {
                ui.label(RichText::new(&notice.title).strong().color(BAD));
                ui.label(&notice.body);
                if ui.button("Dismiss").clicked() {
                    commands.push(Command::View(ViewCommand::DismissNotice));
                }
            });
    }
}

/// The recent files, newest first.
pub fn recent_ui(ui: &mut egui::Ui, state: &AppState, commands: &mut Vec<Command>) {
    if !state.prefs.recent.is_empty() {
        ui.add_space(4.0);
        egui::CollapsingHeader::new("Recent files")
            .default_open(true)
            .show(ui, |ui| {
                for p in &state.prefs.recent {
                    let name = p.file_name().map_or_else(
                        || p.display().to_string(),
                        |n| n.to_string_lossy().into_owned(),
                    );
                    if ui
                        .add(egui::Button::new(name).truncate())
                        .on_hover_text(p.display().to_string())
                        .clicked()
                    {
                        commands.push(Command::Files(FilesCommand::OpenPath(p.clone())));
                    }
                }
                if ui.small_button("Clear list").clicked() {
                    commands.push(Command::Files(FilesCommand::ClearRecent));
                }
            });
    }
}

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
        let run = ui.add_enabled(
            can_run,
            egui::Button::new(RichText::new("▶ Run").size(18.0).strong())
                .min_size(Vec2::new(110.0, 32.0)),
        );
        if run
            .on_hover_text("calibrate the session with these settings")
            .clicked()
        {
            commands.push(Command::Run(RunCommand::Start));
        }
        let cancel = ui.add_enabled(
            running,
            egui::Button::new(RichText::new("Cancel").size(16.0)).min_size(Vec2::new(80.0, 32.0)),
        );
        if cancel
            .on_hover_text("stop the run now: the result on show stays")
            .clicked()
        {
            commands.push(Command::Run(RunCommand::Cancel));
        }
    });
    if let Some(l) = &state.loaded
        && let Err(e) = &l.before
    {
        ui.label(
            RichText::new(format!(
                "the whole session cannot be prepared: {e}; leave out what fails"
            ))
            .color(BAD)
            .small(),
        );
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
            let text = {
                match run.series.last() {
                    Some(eps) if run.phase.starts_with("update") && !run.phase.contains(':') => {
                        let most = forms.solver.max_iterations;
                        format!("{} of ≤ {most}: ε = {eps:.4} mm", run.phase)
                    }
                    _ => run.phase.clone(),
                }
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
            Some(s) => ui
                .label(
                    RichText::new("ε of the result on show (stale)")
                        .small()
                        .color(super::WARN),
                )
                .on_hover_text(s.to_string()),
            None => ui.label(RichText::new("ε of the result on show").small().weak()),
        };
        epsilon_plot_ui(
            ui,
            "last_epsilon",
            &result.epsilons,
            result.threshold,
            SIDE_EPSILON_HEIGHT,
        );
        if let Some(stop) = &result.stop_reason {
            ui.label(RichText::new(stop).small());
        }
    }
}

/// Method, pairing, threshold, iteration bound, SVD tolerance.
fn settings_ui(ui: &mut egui::Ui, forms: &mut Forms) {
    let s = &mut forms.solver;
    egui::Grid::new("solver_settings")
        .num_columns(2)
        .spacing([8.0, 6.0])
        .show(ui, |ui| {
            ui.label("Method");
            egui::ComboBox::from_id_salt("method")
                .selected_text(s.method.as_str())
                .show_ui(ui, |ui| {
                    for m in Method::ALL {
                        ui.selectable_value(&mut s.method, m, m.as_str());
                    }
                })
                .response
                .on_hover_text("identification method");
            ui.end_row();
            let paper = s.method == Method::Paper;
            ui.label("Pairs");
            ui.add_enabled_ui(paper, |ui| {
                egui::ComboBox::from_id_salt("pairing")
                    .selected_text(s.pairing.as_str())
                    .show_ui(ui, |ui| {
                        for p in [Pairing::Disjoint, Pairing::All] {
                            ui.selectable_value(&mut s.pairing, p, p.as_str());
                        }
                    })
                    .response
                    .on_hover_text("pairs of a station's measurements: disjoint (1,2),(3,4),… as in the paper, or all")
                    .on_disabled_hover_text("used by the paper's method only");
            });
            ui.end_row();
            let l = ui.label("Threshold");
            ui.add(
                egui::DragValue::new(&mut s.threshold)
                    .range(0.0..=10.0)
                    .speed(0.001)
                    .max_decimals(4)
                    .suffix(" mm"),
            )
            .labelled_by(l.id)
            .on_hover_text("stop when ε falls to this");
            ui.end_row();
            let l = ui.label("Max iterations");
            ui.add(egui::DragValue::new(&mut s.max_iterations).range(1..=500).speed(0.2))
                .labelled_by(l.id);
            ui.end_row();
            let l = ui.label("SVD tolerance");
            ui.add_enabled(
                paper,
                egui::DragValue::new(&mut s.svd_tolerance)
                    .range(1e-12..=0.5)
                    .speed(1e-5)
                    .custom_formatter(|v, _| format!("{v:.1e}"))
                    .custom_parser(|t| t.trim().parse::<f64>().ok()),
            )
            .labelled_by(l.id)
            .on_hover_text("singular values below this fraction of the largest are dropped (truncated SVD)")
            .on_disabled_hover_text("used by the paper's method only");
            ui.end_row();
        });
}

/// From this span (decades) on, the ε axis reaches the whole decades
/// around the data.
const WHOLE_DECADES_FROM: f64 = 0.7;

/// ε is drawn on a log scale; values below this (mm) are drawn at it.
const EPSILON_FLOOR_MM: f64 = 1e-9;

/// ε per update on a log scale (it falls by orders of magnitude), with
/// the threshold.
pub fn epsilon_plot_ui(
    ui: &mut egui::Ui,
    id: &str,
    epsilons: &[f64],
    threshold: Option<f64>,
    height: f32,
) {
    let log = |v: f64| v.max(EPSILON_FLOOR_MM).log10();
    let pts: Vec<[f64; 2]> = epsilons
        .iter()
        .enumerate()
        .map(|(k, e)| [k as f64, log(*e)])
        .collect();
    // Over a decade or more the axis reaches the whole decades around the
    // data, so that each carries its number (the demo's 0.1); within one
    // the data fill it, labelled by round values (0.36, 0.37).
    let (lo, hi) = pts
        .iter()
        .map(|p| p[1])
        .chain(threshold.map(log))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    let decades = if hi - lo >= WHOLE_DECADES_FROM {
        vec![lo.floor(), hi.ceil()]
    } else {
        Vec::new()
    };
    let mut plot = super::plots::readable_log_y(Plot::new(id));
    for d in decades {
        plot = plot.include_y(d);
    }
    plot.height(height)
        .x_axis_label("update")
        .y_axis_label("ε (mm, log)")
        // Updates are whole numbers: no tick at 0.5.
        .x_axis_formatter(|mark, _| {
            if (mark.value - mark.value.round()).abs() < 1e-9 && mark.value >= 0.0 {
                format!("{}", mark.value.round())
            } else {
                String::new()
            }
        })
        .label_formatter(|pos| match pos {
            egui_plot::HoverPosition::NearDataPoint { position, .. } => Some(format!(
                "update {}: ε = {:.4} mm",
                position.x.round(),
                10f64.powf(position.y)
            )),
            egui_plot::HoverPosition::Elsewhere { .. } => None,
        })
        .include_x(0.0)
        .allow_scroll(false)
        .show(ui, |p| {
            p.line(
                Line::new("", PlotPoints::from(pts.clone()))
                    .color(AFTER)
                    .width(2.0),
            );
            p.points(
                Points::new("ε", PlotPoints::from(pts))
                    .color(AFTER)
                    .radius(3.0),
            );
            if let Some(t) = threshold {
                p.hline(HLine::new("threshold", log(t)).color(BEFORE));
                p.text(
                    egui_plot::Text::new(
                        "threshold label",
                        egui_plot::PlotPoint::new(0.0, log(t)),
                        RichText::new(format!("threshold {t:.3} mm")).color(BEFORE),
                    )
                    .anchor(egui::Align2::LEFT_BOTTOM),
                );
            }
        });
}
