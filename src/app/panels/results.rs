//! The Results view: the headline figures in large type, the paper's
//! Fig. 5 (within-station centre distances, before and after, per pair)
//! and Fig. 6 (reference-distance errors, before and after, per distance),
//! ε per iteration, the singular values with the truncation line, the
//! hand-eye before and after, the Table 1 view of the joint errors with
//! the non-identifiable ones marked, and the export buttons.

use egui::RichText;
use egui_plot::{HLine, Line, LineStyle, MarkerShape, Plot, PlotPoint, PlotPoints, Points, Text};

use super::plots::{readable, spaced_labels};
use super::side::epsilon_plot_ui;
use super::{AFTER, BAD, BEFORE, GOOD, MUTED, WARN, labelled_field, ratio_text};
use crate::app::commands::{Command, FilesCommand, ViewCommand};
use crate::app::forms::Forms;
use crate::app::state::{AppState, DialogPurpose, ExportKind};
use crate::app::view::{HandEyeView, ResultOrigin, ResultView};
use crate::engine::geometry::{rows_from_isometry, wrap_deg};
use crate::engine::result_view::{PairDistance, Verdict};
use crate::engine::robot::{PARAM_NAMES, PARAMS_PER_JOINT};
use crate::engine::solve::estimate::HAND_EYE_LABELS;

/// Longest solver-block value shown in full (longer ones are cut, the
/// whole value is in the tooltip and the exported JSON).
const SOLVER_ENTRY_CHARS: usize = 300;

/// Singular values with their index.
type Indexed = Vec<(usize, f64)>;

/// Least gap between two of Fig. 5's station names, points.
const STATION_LABEL_GAP: f32 = 10.0;

/// Height of each of the four plots, points.
const PLOT_HEIGHT: f32 = 230.0;

/// The Results view.
pub fn results_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    forms: &mut Forms,
    commands: &mut Vec<Command>,
) {
    let Some(view) = &state.result else {
        ui.add_space(20.0);
        ui.label(RichText::new("No result yet.").size(18.0));
        ui.label("Press ▶ Run in the solver panel on the left, or open a result file (path field or Open…) to review it beside its session.");
        return;
    };
    egui::ScrollArea::vertical()
        .auto_shrink([false, false])
        .show(ui, |ui| {
            origin_ui(ui, view);
            export_ui(ui, state, forms, commands);
            headline_ui(ui, view, forms, commands);
            ui.add_space(4.0);
            plots_ui(ui, view);
            ui.add_space(8.0);
            tables_ui(ui, view);
        });
}

fn origin_ui(ui: &mut egui::Ui, view: &ResultView) {
    let text = match &view.origin {
        ResultOrigin::Run { seconds, excluded } => {
            let left_out = if *excluded > 0 {
                format!(", {excluded} measurement(s) left out")
            } else {
                String::new()
            };
            format!(
                "Run of session \"{}\" in this window ({seconds:.2} s{left_out}), method {}.",
                view.file.session, view.method
            )
        }
        ResultOrigin::Review(path) => format!(
            "Reviewing {} (session \"{}\", method {}): shown as it was computed, the solver was not run.",
            path.display(),
            view.file.session,
            view.method
        ),
    };
    ui.label(RichText::new(text).weak());
    if let Some(stop) = &view.stop_reason {
        ui.label(RichText::new(stop).small());
    }
    for w in &view.shown.warnings {
        ui.label(RichText::new(format!("warning: {w}")).color(WARN));
    }
    for n in &view.notes {
        ui.label(RichText::new(format!("note: {n}")).color(WARN));
    }
}

/// Validation std and max before → after in large type, with the ratio,
/// and the verdict against the acceptance tolerance (editable here).
fn headline_ui(ui: &mut egui::Ui, view: &ResultView, forms: &Forms, commands: &mut Vec<Command>) {
    egui::Frame::group(ui.style()).show(ui, |ui| {
        ui.set_width(ui.available_width());
        match &view.shown.headline {
            Some(h) => {
                ui.label(RichText::new(&h.what).strong());
                let (b, a) = (h.stats.before, h.stats.after);
                ui.horizontal_wrapped(|ui| {
                    big(ui, format!("std {:.3} → {:.3} mm", b.std, a.std));
                    ui.label(RichText::new(ratio_text(b.std, a.std)).size(16.0).color(AFTER));
                    ui.add_space(24.0);
                    big(ui, format!("max {:.3} → {:.3} mm", b.max, a.max));
                    ui.label(RichText::new(ratio_text(b.max, a.max)).size(16.0).color(AFTER));
                });
            }
            None => {
                ui.label(RichText::new("No validate measurements in this session: accuracy is not checked.").color(WARN));
            }
        }
        verdict_ui(ui, view, forms, commands);
        let w = &view.shown.within_stats;
        ui.label(format!(
            "{} stations, centre distances (true value 0): std {:.3} → {:.3} mm, max {:.3} → {:.3} mm · ε {:.4} → {:.4} mm",
            view.shown.within_of.as_str(),
            w.before.std,
            w.after.std,
            w.before.max,
            w.after.max,
            view.file.epsilon_before,
            view.file.epsilon_after
        ));
        let (b, a) = view.shown.identify_scatter;
        ui.label(format!(
            "identify centres about their station's mean (3-D rms): {b:.3} → {a:.3} mm"
        ));
        held_out_ui(ui, view);
    });
}

/// The held-out figure beside the fit's own scatter: each identify centre
/// predicted by a calibration made without it.
fn held_out_ui(ui: &mut egui::Ui, view: &ResultView) {
    let Some(h) = &view.shown.held_out else {
        ui.label(
            RichText::new("held out: not in this result (written before spherecal computed it, or with --no-held-out)")
                .color(MUTED),
        );
        return;
    };
    ui.horizontal_wrapped(|ui| {
        ui.label(RichText::new(format!("held out ({})", h.label())).strong());
        ui.label(
            RichText::new(format!("rms {:.3} mm, max {:.3} mm", h.rms, h.max))
                .size(16.0)
                .strong(),
        )
        .on_hover_text(format!(
            "each identify centre predicted by a calibration made without it, against its station's centre from the other measurements; largest: {}. Refit: {}",
            h.max_measurement, h.refit
        ));
        ui.label(format!(
            "· fit's own scatter rms {:.3} mm, max {:.3} mm ({:.2}× the fit's own)",
            h.fit_rms,
            h.fit_max,
            h.ratio()
        ));
    });
    if !h.undetermined.is_empty() {
        ui.label(
            RichText::new(format!(
                "not predictable without themselves: {}",
                h.undetermined.join(", ")
            ))
            .color(WARN),
        );
    }
}

/// PASS / FAIL in large type against the tolerance, which is edited
/// beside it (remembered for the session's robot).
fn verdict_ui(ui: &mut egui::Ui, view: &ResultView, forms: &Forms, commands: &mut Vec<Command>) {
    let tolerance = forms.tolerance;
    let verdict = Verdict::of(view.shown.headline.as_ref(), &tolerance);
    ui.horizontal_wrapped(|ui| {
        let colour = match verdict {
            Verdict::Pass => GOOD,
            Verdict::Fail(_) => BAD,
            Verdict::NotChecked => MUTED,
        };
        ui.label(
            RichText::new(verdict.word())
                .size(28.0)
                .strong()
                .color(colour),
        )
        .on_hover_text(verdict.describe(&tolerance));
        ui.add_space(12.0);
        let mut edited = tolerance;
        ui.label("tolerance: std ≤");
        let std = ui.add(
            egui::DragValue::new(&mut edited.std_mm)
                .speed(0.005)
                .range(0.001..=100.0)
                .max_decimals(3)
                .suffix(" mm"),
        );
        ui.label("max ≤");
        let max = ui.add(
            egui::DragValue::new(&mut edited.max_mm)
                .speed(0.005)
                .range(0.001..=100.0)
                .max_decimals(3)
                .suffix(" mm"),
        );
        if (std.changed() || max.changed()) && edited != tolerance {
            commands.push(Command::View(ViewCommand::SetTolerance(edited)));
        }
        if let Verdict::Fail(reasons) = &verdict {
            ui.label(RichText::new(reasons.join(", ")).color(BAD));
        }
    });
}

fn big(ui: &mut egui::Ui, text: String) {
    ui.label(RichText::new(text).size(28.0).strong());
}

fn export_ui(ui: &mut egui::Ui, state: &AppState, forms: &mut Forms, commands: &mut Vec<Command>) {
    ui.horizontal_wrapped(|ui| {
        labelled_field(
            ui,
            "Export to folder",
            &mut forms.export_dir,
            "/path/to/folder",
            220.0,
        );
        if ui
            .button("Browse…")
            .on_hover_text("choose the folder with the desktop's dialog")
            .clicked()
        {
            commands.push(Command::Files(FilesCommand::Browse(
                DialogPurpose::ExportFolder,
            )));
        }
        ui.separator();
        let hand_eye_only = state
            .result
            .as_ref()
            .is_some_and(|v| v.hand_eye_only.is_some());
        for kind in ExportKind::ALL {
            let model = matches!(
                kind,
                ExportKind::ModelJson | ExportKind::ModelCsv | ExportKind::ModelUrdf
            );
            let enabled = !(model && hand_eye_only);
            if ui
                .add_enabled(enabled, egui::Button::new(kind.label()))
                .on_hover_text(export_hint(kind))
                .on_disabled_hover_text(
                    "a pose-only result calibrated the hand-eye only: there is no kinematic model to export",
                )
                .clicked()
            {
                commands.push(Command::Export(kind));
            }
        }
    });
}

fn export_hint(kind: ExportKind) -> &'static str {
    match kind {
        ExportKind::ResultJson => {
            "the result file of FORMAT.md (what `spherecal calibrate` writes)"
        }
        ExportKind::CentresCsv => {
            "every sphere centre: sensor frame, base frame before and after (mm)"
        }
        ExportKind::DistancesCsv => {
            "reference-distance errors and within-station distances, before and after (mm)"
        }
        ExportKind::PlotsPng => {
            "Fig. 5, Fig. 6, ε and the singular values on one white sheet, whole, for print (2 pixels per point)"
        }
        ExportKind::ReportHtml => {
            "one self-contained HTML file: provenance (SHA-256), settings, stripe quality, figures, hand-eye, joint errors, validation"
        }
        ExportKind::ModelJson => {
            "the calibrated robot as the FORMAT.md robot block (deg, mm), pasteable into a session"
        }
        ExportKind::ModelCsv => {
            "the calibrated MDH table with the deltas, then base, flange and hand-eye matrices (deg, mm)"
        }
        ExportKind::ModelUrdf => {
            "a URDF fragment with the calibrated joint origins and the sensor link (m, rad), for ROS"
        }
    }
}

/// The four plots, two by two.
fn plots_ui(ui: &mut egui::Ui, view: &ResultView) {
    ui.columns(2, |cols| {
        cols[0].label(
            RichText::new(format!(
                "Centre distances within {} stations, per pair (cf. paper Fig. 5)",
                view.shown.within_of.as_str()
            ))
            .strong(),
        );
        key_ui(&mut cols[0]);
        fig5_ui(&mut cols[0], view);
        cols[1].label(
            RichText::new("Reference-distance errors, measured − reference (cf. paper Fig. 6)")
                .strong(),
        );
        key_ui(&mut cols[1]);
        fig6_ui(&mut cols[1], view);
    });
    ui.columns(2, |cols| {
        cols[0].label(RichText::new("ε per iteration (paper eq. 20)").strong());
        epsilon_plot_ui(
            &mut cols[0],
            "result_epsilon",
            &view.epsilons,
            view.threshold,
            PLOT_HEIGHT,
        );
        let title = if view.singular_values.is_empty() && !view.fixed.is_empty() {
            "Identifiable set"
        } else {
            "Singular values of the last update"
        };
        cols[1].label(RichText::new(title).strong());
        singular_ui(&mut cols[1], view);
    });
}

/// The colour key of the before/after plots (their legends would cover
/// the data).
fn key_ui(ui: &mut egui::Ui) {
    super::plot_key(
        ui,
        &[
            ("■ before (nominal model, initial hand-eye)", BEFORE),
            ("● after (calibrated)", AFTER),
        ],
    );
}

fn before_after_series(p: &mut egui_plot::PlotUi<'_>, before: Vec<[f64; 2]>, after: Vec<[f64; 2]>) {
    p.line(
        Line::new("before (nominal)", PlotPoints::from(before.clone()))
            .color(BEFORE)
            .width(1.0),
    );
    p.points(
        Points::new("before (nominal)", PlotPoints::from(before))
            .color(BEFORE)
            .shape(MarkerShape::Square)
            .radius(3.0),
    );
    p.line(
        Line::new("after (calibrated)", PlotPoints::from(after.clone()))
            .color(AFTER)
            .width(1.0),
    );
    p.points(
        Points::new("after (calibrated)", PlotPoints::from(after))
            .color(AFTER)
            .shape(MarkerShape::Circle)
            .radius(3.0),
    );
}

fn fig5_ui(ui: &mut egui::Ui, view: &ResultView) {
    let before: Vec<[f64; 2]> = view
        .shown
        .within
        .iter()
        .enumerate()
        .map(|(k, p)| [(k + 1) as f64, p.before])
        .collect();
    let after: Vec<[f64; 2]> = view
        .shown
        .within
        .iter()
        .enumerate()
        .map(|(k, p)| [(k + 1) as f64, p.after])
        .collect();
    let top = view
        .shown
        .within
        .iter()
        .map(|p| p.before.max(p.after))
        .fold(0.0, f64::max);
    let within = &view.shown.within;
    readable(Plot::new("fig5"), true)
        .height(PLOT_HEIGHT)
        // The wheel scrolls the page, not the plot (drag still pans).
        .allow_scroll(false)
        .x_axis_label("pair (station by station)")
        .y_axis_label("distance (mm)")
        .include_y(0.0)
        .include_y(top * 1.15)
        .label_formatter(move |pos| match pos {
            egui_plot::HoverPosition::NearDataPoint {
                index, position, ..
            } => within.get(*index).map(|p| {
                format!(
                    "{}: {} – {}\n{:.4} mm",
                    p.station, p.ids.0, p.ids.1, position.y
                )
            }),
            egui_plot::HoverPosition::Elsewhere { .. } => None,
        })
        .show(ui, |p| {
            station_bands_ui(p, within, top * 1.1);
            before_after_series(p, before, after);
        });
}

/// Fig. 5's stations: a dotted line between two (under the names), and each one's name
/// above its pairs where it does not overlap its neighbour's (at 60
/// stations every few; hover a point for its station).
fn station_bands_ui(p: &mut egui_plot::PlotUi<'_>, within: &[PairDistance], y: f64) {
    // (first pair, one past the last) of each station, 0-based.
    let mut runs: Vec<(usize, usize)> = Vec::new();
    for (k, pair) in within.iter().enumerate() {
        match runs.last_mut() {
            Some(r) if within[r.0].station == pair.station => r.1 = k + 1,
            _ => runs.push((k, k + 1)),
        }
    }
    let x_of = |run: &(usize, usize)| (run.0 + run.1 + 1) as f64 / 2.0;
    let centres: Vec<f32> = runs
        .iter()
        .map(|r| p.screen_from_plot(PlotPoint::new(x_of(r), y)).x)
        .collect();
    let font = egui::TextStyle::Small.resolve(&p.ctx().global_style());
    let widths: Vec<f32> = runs
        .iter()
        .map(|r| {
            p.ctx().fonts_mut(|f| {
                f.layout_no_wrap(within[r.0].station.clone(), font.clone(), MUTED)
                    .size()
                    .x
            })
        })
        .collect();
    for k in spaced_labels(&centres, &widths, STATION_LABEL_GAP) {
        let r = &runs[k];
        p.text(
            Text::new("", PlotPoint::new(x_of(r), y), within[r.0].station.as_str()).color(MUTED),
        );
    }
    // The separators stop under the names, which stay clear to read.
    let below_names = y * 0.93;
    for r in runs.iter().skip(1) {
        let x = r.0 as f64 + 0.5;
        p.line(
            Line::new("", PlotPoints::from(vec![[x, 0.0], [x, below_names]]))
                .color(MUTED)
                .width(1.0)
                .allow_hover(false)
                .style(LineStyle::dotted_dense()),
        );
    }
}

fn fig6_ui(ui: &mut egui::Ui, view: &ResultView) {
    if view.shown.distances.is_empty() {
        ui.allocate_ui(egui::vec2(ui.available_width(), PLOT_HEIGHT), |ui| {
            ui.label(RichText::new("No reference distances in this session.").color(MUTED));
        });
        return;
    }
    let before: Vec<[f64; 2]> = view
        .shown
        .distances
        .iter()
        .enumerate()
        .map(|(k, d)| [(k + 1) as f64, d.error_before()])
        .collect();
    let after: Vec<[f64; 2]> = view
        .shown
        .distances
        .iter()
        .enumerate()
        .map(|(k, d)| [(k + 1) as f64, d.error_after()])
        .collect();
    let distances = &view.shown.distances;
    readable(Plot::new("fig6"), true)
        .height(PLOT_HEIGHT)
        // The wheel scrolls the page, not the plot (drag still pans).
        .allow_scroll(false)
        .x_axis_label("reference distance no.")
        .y_axis_label("error (mm)")
        .label_formatter(move |pos| match pos {
            egui_plot::HoverPosition::NearDataPoint {
                index, position, ..
            } => distances.get(*index).map(|d| {
                format!(
                    "{} → {}, pose {}: reference {:.3} mm\nerror {:+.4} mm",
                    d.from, d.to, d.pose, d.reference, position.y
                )
            }),
            egui_plot::HoverPosition::Elsewhere { .. } => None,
        })
        .show(ui, |p| {
            p.hline(HLine::new("", 0.0).color(MUTED).width(1.0));
            before_after_series(p, before, after);
        });
}

fn singular_ui(ui: &mut egui::Ui, view: &ResultView) {
    let values: Vec<(usize, f64)> = view
        .singular_values
        .iter()
        .copied()
        .enumerate()
        .filter(|(_, s)| *s > 0.0)
        .collect();
    if values.is_empty() {
        ui.allocate_ui(egui::vec2(ui.available_width(), PLOT_HEIGHT), |ui| {
            if view.fixed.is_empty() && view.estimated.is_empty() {
                ui.label(
                    RichText::new("No update was made: ε started below the threshold.")
                        .color(MUTED),
                );
            } else {
                identifiable_set_ui(ui, view);
            }
        });
        return;
    }
    let smax = values.iter().map(|v| v.1).fold(0.0, f64::max);
    let cut = view.svd_tolerance.map(|t| t * smax);
    let (kept, dropped): (Indexed, Indexed) = values
        .iter()
        .partition(|(k, s)| view.kept.map_or(cut.is_none_or(|c| *s >= c), |n| *k < n));
    let pts = |v: &[(usize, f64)]| -> Vec<[f64; 2]> {
        v.iter()
            .map(|(k, s)| [(*k + 1) as f64, s.log10()])
            .collect()
    };
    let zeros = view.singular_values.len() - values.len();
    let mut key = vec![("● kept", AFTER)];
    if !dropped.is_empty() {
        key.push(("× dropped", BAD));
    }
    if cut.is_some() {
        key.push(("- - truncation (tolerance × σ_max)", BEFORE));
    }
    super::plot_key(ui, &key);
    super::plots::readable_log_y(Plot::new("singular"))
        // Less the key line, and the zeros' note under the plot.
        .height(if zeros > 0 {
            PLOT_HEIGHT - 36.0
        } else {
            PLOT_HEIGHT - 18.0
        })
        .x_axis_label("index")
        .y_axis_label("σ (log scale)")
        .show(ui, |p| {
            p.points(
                Points::new("kept", PlotPoints::from(pts(&kept)))
                    .color(AFTER)
                    .radius(3.5),
            );
            if !dropped.is_empty() {
                p.points(
                    Points::new("dropped", PlotPoints::from(pts(&dropped)))
                        .color(BAD)
                        .shape(MarkerShape::Cross)
                        .radius(5.0),
                );
            }
            if let Some(c) = cut {
                p.hline(
                    HLine::new("truncation (tolerance × σ_max)", c.log10())
                        .color(BEFORE)
                        .style(LineStyle::dashed_loose()),
                );
            }
        });
    if zeros > 0 {
        ui.label(
            RichText::new(format!(
                "{zeros} singular value(s) are 0 (not drawn on the log scale)"
            ))
            .small()
            .weak(),
        );
    }
}

/// What a method that chooses its identifiable set (rather than truncating
/// an SVD) estimated and held fixed.
fn identifiable_set_ui(ui: &mut egui::Ui, view: &ResultView) {
    ui.label(format!(
        "Method {} estimated {} parameter(s) and held {} fixed (not identifiable from centre distances):",
        view.method,
        view.estimated.len(),
        view.fixed.len()
    ));
    egui::ScrollArea::vertical()
        .id_salt("identifiable_set")
        .max_height(PLOT_HEIGHT - 30.0)
        .show(ui, |ui| {
            ui.label(RichText::new(format!("fixed: {}", view.fixed.join(", "))).color(MUTED));
            for c in &view.caveats {
                ui.label(RichText::new(c).small());
            }
        });
}

fn tables_ui(ui: &mut egui::Ui, view: &ResultView) {
    // One above the other: with ± 1σ the joint table needs the width.
    hand_eye_ui(ui, view);
    ui.add_space(8.0);
    match &view.hand_eye_only {
        Some(lines) => hand_eye_only_ui(ui, lines),
        None => joint_errors_ui(ui, view),
    }
    if !view.dropped.is_empty() {
        ui.add_space(6.0);
        egui::CollapsingHeader::new(format!(
            "Directions the SVD dropped ({})",
            view.dropped.len()
        ))
        .show(ui, |ui| {
            for d in &view.dropped {
                ui.monospace(d);
            }
        });
    }
    ml_tables_ui(ui, view);
    egui::CollapsingHeader::new("Details: the solver block as written in the result file").show(
        ui,
        |ui| {
            egui::Grid::new("solver_entries")
                .striped(true)
                .num_columns(2)
                .show(ui, |ui| {
                    for (k, v) in &view.solver_entries {
                        ui.monospace(k);
                        let short: String = v.chars().take(SOLVER_ENTRY_CHARS).collect();
                        let shown = if short.len() < v.len() {
                            format!("{short}…")
                        } else {
                            short
                        };
                        ui.add(egui::Label::new(shown).wrap()).on_hover_text(v);
                        ui.end_row();
                    }
                });
        },
    );
}

fn marked_cell(ui: &mut egui::Ui, view: &ResultView, label: &str, text: String) {
    if let Some(why) = view.shown.marked.get(label) {
        ui.label(RichText::new(format!("{text} †")).color(MUTED))
            .on_hover_text(format!("{label} is not identifiable from this data: {why}"));
    } else {
        ui.label(text);
    }
}

fn hand_eye_ui(ui: &mut egui::Ui, view: &ResultView) {
    ui.label(RichText::new("Hand-eye eT_s (sensor to flange)").strong());
    let (b, a): (&HandEyeView, &HandEyeView) =
        (&view.shown.hand_eye_before, &view.shown.hand_eye_after);
    let sigma = view.shown.hand_eye_sigma;
    egui::Grid::new("hand_eye")
        .striped(true)
        .num_columns(5)
        .show(ui, |ui| {
            for t in ["", "initial", "calibrated", "± 1σ", "change"] {
                ui.strong(t);
            }
            ui.end_row();
            let rows: [(&str, f64, f64, &str); 6] = [
                (
                    "x (mm)",
                    b.translation[0],
                    a.translation[0],
                    HAND_EYE_LABELS[0],
                ),
                (
                    "y (mm)",
                    b.translation[1],
                    a.translation[1],
                    HAND_EYE_LABELS[1],
                ),
                (
                    "z (mm)",
                    b.translation[2],
                    a.translation[2],
                    HAND_EYE_LABELS[2],
                ),
                ("roll (deg)", b.rpy_deg[0], a.rpy_deg[0], HAND_EYE_LABELS[3]),
                (
                    "pitch (deg)",
                    b.rpy_deg[1],
                    a.rpy_deg[1],
                    HAND_EYE_LABELS[4],
                ),
                ("yaw (deg)", b.rpy_deg[2], a.rpy_deg[2], HAND_EYE_LABELS[5]),
            ];
            for (k, (name, before, after, label)) in rows.into_iter().enumerate() {
                ui.label(name);
                ui.label(format!("{before:.4}"));
                marked_cell(ui, view, label, format!("{after:.4}"));
                match sigma {
                    Some(s) if !view.shown.marked.contains_key(label) => {
                        ui.label(RichText::new(format!("± {:.4}", s[k])).color(MUTED))
                    }
                    _ => ui.label(RichText::new("–").color(MUTED)),
                }
                .on_hover_text(
                    "1σ from ml's covariance, in the row's frame and unit (flange-frame x, y, z; roll, pitch, yaw)",
                );
                let change = if k < 3 {
                    after - before
                } else {
                    wrap_deg(after - before)
                };
                ui.label(format!("{change:+.4}"));
                ui.end_row();
            }
        });
    ui.label(
        RichText::new(format!(
            "rotation changed by {:.4}°",
            view.shown.hand_eye_rotation_change_deg
        ))
        .small(),
    );
    egui::CollapsingHeader::new("matrices").show(ui, |ui| {
        for (title, m) in [
            ("initial", &view.file.hand_eye_initial),
            ("calibrated", &view.file.hand_eye),
        ] {
            ui.label(title);
            for r in rows_from_isometry(m) {
                ui.monospace(format!(
                    "{:>10.5} {:>10.5} {:>10.5} {:>10.3}",
                    r[0], r[1], r[2], r[3]
                ));
            }
        }
    });
}

/// A pose-only result: no joint table; what was calibrated and how well.
fn hand_eye_only_ui(ui: &mut egui::Ui, lines: &[String]) {
    ui.label(RichText::new("Hand-eye only: no kinematic model").strong());
    for (k, line) in lines.iter().enumerate() {
        let text = RichText::new(line);
        ui.label(if line.starts_with("weakly") {
            text.color(WARN)
        } else if k == 0 {
            text
        } else {
            text.color(MUTED)
        });
    }
}

fn joint_errors_ui(ui: &mut egui::Ui, view: &ResultView) {
    ui.label(RichText::new("Joint errors, calibrated − nominal (cf. paper Table 1)").strong());
    const HEADER: [&str; PARAMS_PER_JOINT + 1] = [
        "joint",
        "Δα (deg)",
        "Δa (mm)",
        "Δβ (deg)",
        "Δθ (deg)",
        "Δd (mm)",
    ];
    egui::Grid::new("joint_errors")
        .striped(true)
        .num_columns(HEADER.len())
        .show(ui, |ui| {
            for h in HEADER {
                ui.strong(h);
            }
            ui.end_row();
            for (j, e) in view.file.joint_errors.iter().enumerate() {
                ui.label(format!("{}", j + 1));
                for (p, name) in PARAM_NAMES.iter().enumerate() {
                    let label = format!("{name}{}", j + 1);
                    let text = match view.shown.sigma.get(&label) {
                        Some(s) => format!("{:+.4} ± {:.4}", e.get(p), s.std),
                        None => format!("{:+.4}", e.get(p)),
                    };
                    marked_cell(ui, view, &label, text);
                }
                ui.end_row();
            }
        });
    if !view.shown.marked.is_empty() {
        ui.label(
            RichText::new(format!(
                "± 1σ from ml's covariance. † not identifiable from this data ({} parameter(s)): they lie in a direction the SVD dropped (or the method held them fixed), so the value is not a measurement of the robot. Hover a value for the direction.",
                view.shown.marked.len()
            ))
            .small()
            .color(MUTED),
        );
    }
}

/// `ml`'s diagnostics as tables: outliers, leave-one-station-out and the
/// strong correlations (each collapsible, open when it has something to
/// say).
fn ml_tables_ui(ui: &mut egui::Ui, view: &ResultView) {
    let Some(ml) = view.file.solver.ml() else {
        return;
    };
    ui.add_space(6.0);
    if let Some(r) = &ml.range_error {
        ui.label(r.summary()).on_hover_text(format!(
            "1σ of points of the laser plane on a {} × {} grid at {} working poses, from ml's covariance, after the best rigid alignment",
            r.grid, r.grid, r.poses
        ));
        if let Some(w) = &r.warning {
            ui.label(RichText::new(format!("warning: {w}")).color(WARN));
        }
        range_map_ui(ui, r);
    }
    egui::CollapsingHeader::new(format!(
        "Outliers ({}; limit {:.1} σ)",
        ml.outliers.len(),
        ml.outlier_limit_sigma
    ))
    .default_open(!ml.outliers.is_empty())
    .show(ui, |ui| {
        if ml.outliers.is_empty() {
            ui.label("No identify measurement's standardised residual exceeds the limit.");
            return;
        }
        egui::Grid::new("outliers").striped(true).show(ui, |ui| {
            for h in ["measurement", "station", "residual (mm)", "σ", "reason"] {
                ui.strong(h);
            }
            ui.end_row();
            for o in &ml.outliers {
                ui.label(&o.measurement);
                ui.label(&o.station);
                ui.label(format!("{:.4}", o.residual_mm));
                ui.label(format!("{:.1}", o.sigma));
                ui.label(&o.reason);
                ui.end_row();
            }
        });
    });
    if let Some(cv) = &ml.cross_validation {
        egui::CollapsingHeader::new(format!(
            "Leave-one-station-out: rms {:.4} mm over {} stations",
            cv.rms,
            cv.stations.len()
        ))
        .show(ui, |ui| {
            ui.label(
                RichText::new(
                    "Each station's within-station centre distances predicted by the model fitted without it: an accuracy estimate without a tracker.",
                )
                .color(MUTED),
            );
            let mut rows: Vec<_> = cv.stations.iter().collect();
            rows.sort_by(|a, b| b.rms.total_cmp(&a.rms));
            egui::Grid::new("loso").striped(true).show(ui, |ui| {
                for h in ["station", "pairs", "rms (mm)"] {
                    ui.strong(h);
                }
                ui.end_row();
                for s in rows {
                    ui.label(&s.station);
                    ui.label(s.pairs.to_string());
                    ui.label(format!("{:.4}", s.rms));
                    ui.end_row();
                }
            });
        });
    }
    egui::CollapsingHeader::new(format!(
        "Strong correlations ({}, |r| ≥ 0.95)",
        ml.strong_correlations.len()
    ))
    .show(ui, |ui| {
        if ml.strong_correlations.is_empty() {
            ui.label("No two estimated parameters correlate by 0.95 or more.");
        }
        for c in &ml.strong_correlations {
            ui.label(c);
        }
    });
}

/// The engine's map colour scale ([`heat_rgb`](crate::engine::report::svg::heat_rgb)).
fn heat(t: f64) -> egui::Color32 {
    let [r, g, b] = crate::engine::report::svg::heat_rgb(t);
    egui::Color32::from_rgb(r, g, b)
}

/// The predicted error over the range as a map: one cell per grid point
/// coloured by its σ (green low, red high), the region the sphere
/// positions covered outlined, the largest σ marked.
fn range_map_ui(ui: &mut egui::Ui, r: &crate::engine::solve::ml::range::RangeError) {
    use egui_plot::Polygon;
    if r.map.is_empty() || r.grid < 2 {
        return;
    }
    let (lo, hi) = r
        .map
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p[2]), b.max(p[2]))
        });
    let span = (hi - lo).max(1e-12);
    let half_y = (r.y[1] - r.y[0]) / (r.grid - 1) as f64 / 2.0;
    let half_z = (r.z[1] - r.z[0]) / (r.grid - 1) as f64 / 2.0;
    ui.label(
        RichText::new(format!(
            "Predicted 1σ over the range: {lo:.3} mm (green) to {hi:.3} mm (red); the white outline is where the sphere was seen"
        ))
        .color(MUTED),
    );
    readable(Plot::new("range_map"), false)
        .height(PLOT_HEIGHT)
        .width(PLOT_HEIGHT * 1.3)
        .data_aspect(1.0)
        .x_axis_label("y (mm, along the laser line)")
        .y_axis_label("z (mm, depth)")
        .allow_drag(false)
        .allow_scroll(false)
        .show(ui, |p| {
            for c in &r.map {
                let (y, z) = (c[0], c[1]);
                let cell = vec![
                    [y - half_y, z - half_z],
                    [y + half_y, z - half_z],
                    [y + half_y, z + half_z],
                    [y - half_y, z + half_z],
                ];
                let colour = heat((c[2] - lo) / span);
                p.polygon(
                    Polygon::new(format!("σ {:.3} mm", c[2]), PlotPoints::from(cell))
                        .fill_color(colour)
                        .stroke(egui::Stroke::new(0.5, colour)),
                );
            }
            let (y0, y1, z0, z1) = (r.sphere_y[0], r.sphere_y[1], r.sphere_z[0], r.sphere_z[1]);
            p.line(
                Line::new(
                    "sphere positions",
                    PlotPoints::from(vec![[y0, z0], [y1, z0], [y1, z1], [y0, z1], [y0, z0]]),
                )
                .color(egui::Color32::WHITE)
                .width(2.0),
            );
            p.points(
                Points::new(
                    format!("largest σ {:.3} mm", r.max_mm),
                    PlotPoints::from(vec![r.max_at]),
                )
                .shape(MarkerShape::Cross)
                .radius(6.0)
                .color(egui::Color32::WHITE),
            );
        });
}
