//! The Results view's four plots, two by two: the paper's Fig. 5
//! (within-station centre distances per pair) and Fig. 6
//! (reference-distance errors), before and after, ε per iteration, and
//! the singular values with the truncation line (or `ml`'s identifiable
//! set).

use egui::RichText;
use egui_plot::{HLine, Line, LineStyle, MarkerShape, Plot, PlotPoint, PlotPoints, Points, Text};

use super::ui::PLOT_HEIGHT;
use crate::app::results::ResultView;
use crate::app::widgets::plots::epsilon_plot_ui;
use crate::app::widgets::plots::{readable, spaced_labels};
use crate::app::widgets::{AFTER, BAD, BEFORE, MUTED};
use crate::engine::tools::result_view::PairDistance;

/// Singular values with their index.
type Indexed = Vec<(usize, f64)>;

/// Least gap between two of Fig. 5's station names, points.
const STATION_LABEL_GAP: f32 = 10.0;

/// The four plots, two by two.
pub(super) fn plots_ui(ui: &mut egui::Ui, view: &ResultView) {
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
        // No key over an empty plot.
        if !view.shown.distances.is_empty() {
            key_ui(&mut cols[1]);
        }
        fig6_ui(&mut cols[1], view);
    });
    // The after series on its own scale: on the before's it is a flat
    // line at zero.
    ui.columns(2, |cols| {
        cols[0].label(
            RichText::new("Fig. 5, after only (its own scale)")
                .strong()
                .color(AFTER),
        );
        let within: Vec<[f64; 2]> = after_points(view.shown.within.iter().map(|p| p.after));
        after_only_ui(
            &mut cols[0],
            "fig5_after",
            within,
            ("pair (station by station)", "distance (mm)"),
            true,
        );
        if !view.shown.distances.is_empty() {
            cols[1].label(
                RichText::new("Fig. 6, after only (its own scale)")
                    .strong()
                    .color(AFTER),
            );
            let errors = after_points(
                view.shown
                    .distances
                    .iter()
                    .map(crate::engine::calibrate::validate::DistanceRecord::error_after),
            );
            after_only_ui(
                &mut cols[1],
                "fig6_after",
                errors,
                ("reference distance no.", "error (mm)"),
                false,
            );
        }
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
        let title = if view.hand_eye_only.is_some() {
            "Identified: the hand-eye only"
        } else if view.singular_values.is_empty()
            && !(view.fixed.is_empty() && view.estimated.is_empty())
        {
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
    crate::app::widgets::plot_key(
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

/// Height of the after-only panels, points.
const AFTER_HEIGHT: f32 = PLOT_HEIGHT * 0.6;

/// Values numbered from 1 for a plot.
fn after_points(values: impl Iterator<Item = f64>) -> Vec<[f64; 2]> {
    values
        .enumerate()
        .map(|(k, v)| [(k + 1) as f64, v])
        .collect()
}

/// One after series on its own scale (from 0 for distances, around 0
/// for errors).
fn after_only_ui(
    ui: &mut egui::Ui,
    id: &str,
    after: Vec<[f64; 2]>,
    (x_label, y_label): (&str, &str),
    from_zero: bool,
) {
    let mut plot = readable(Plot::new(id), true)
        .height(AFTER_HEIGHT)
        .allow_scroll(false)
        .x_axis_label(x_label)
        .y_axis_label(y_label);
    if from_zero {
        plot = plot.include_y(0.0);
    }
    plot.show(ui, |p| {
        if !from_zero {
            p.hline(HLine::new("", 0.0).color(MUTED).width(1.0));
        }
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
        let size = egui::vec2(ui.available_width() - TEXT_MARGIN, PLOT_HEIGHT);
        // Left-aligned, not justified to the column, a margin short of its
        // edge: the text ran into the window's right edge.
        let layout = egui::Layout::top_down(egui::Align::Min);
        ui.allocate_ui_with_layout(size, layout, |ui| {
            ui.set_max_width(size.x);
            if view.hand_eye_only.is_some() {
                pose_only_ui(ui, view);
            } else if view.fixed.is_empty() && view.estimated.is_empty() {
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
    crate::app::widgets::plot_key(ui, &key);
    crate::app::widgets::plots::readable_log_y(Plot::new("singular"))
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

/// Room kept between a column's text and its right edge, points.
const TEXT_MARGIN: f32 = 12.0;

/// A pose-only result (flange poses, no joint readings): no kinematic
/// parameter was identified, so there is no identifiable set to list.
fn pose_only_ui(ui: &mut egui::Ui, view: &ResultView) {
    ui.add(
        egui::Label::new(format!(
            "A pose-only result: the session gives flange poses, no joint readings, so method {} identified the hand-eye (sensor on the flange) and the station centres and no kinematic parameter: there is no identifiable set of the model to show. How well the hand-eye is determined: under “Hand-eye only”.",
            view.method
        ))
        .wrap(),
    );
    for c in &view.caveats {
        ui.add(egui::Label::new(RichText::new(c).small()).wrap());
    }
}

/// What a method that chooses its identifiable set (rather than truncating
/// an SVD) estimated and held fixed (the list only when it held some).
fn identifiable_set_ui(ui: &mut egui::Ui, view: &ResultView) {
    let text = if view.fixed.is_empty() {
        format!(
            "Method {} estimated {} parameter(s) and held none fixed.",
            view.method,
            view.estimated.len()
        )
    } else {
        format!(
            "Method {} estimated {} parameter(s) and held {} fixed (not identifiable from centre distances):",
            view.method,
            view.estimated.len(),
            view.fixed.len()
        )
    };
    // Wrapped in its column: the text at the right edge was cut at
    // 1366 × 768.
    ui.add(egui::Label::new(text).wrap());
    egui::ScrollArea::vertical()
        .id_salt("identifiable_set")
        .max_height(PLOT_HEIGHT - 30.0)
        .show(ui, |ui| {
            if !view.fixed.is_empty() {
                ui.add(
                    egui::Label::new(
                        RichText::new(format!("fixed: {}", view.fixed.join(", "))).color(MUTED),
                    )
                    .wrap(),
                );
            }
            for c in &view.caveats {
                ui.add(egui::Label::new(RichText::new(c).small()).wrap());
            }
        });
}
