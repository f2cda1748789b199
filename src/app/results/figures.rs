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
use crate::engine::calibrate::validate::DistanceRecord;
use crate::engine::tools::result_view::PairDistance;

/// Singular values with their index.
type Indexed = Vec<(usize, f64)>;

/// Least gap between two of Fig. 5's station names, points.
const STATION_LABEL_GAP: f32 = 10.0;

/// The four plots, two by two.
pub(super) fn plots_ui(ui: &mut egui::Ui, view: &ResultView) {
    let (within, distances) = (&view.shown.within, &view.shown.distances);
    ui.columns(2, |cols| {
        let of = view.shown.within_of.as_str();
        let title = format!("Centre distances within {of} stations, per pair (cf. paper Fig. 5)");
        cols[0].label(RichText::new(title).strong());
        key_ui(&mut cols[0]);
        fig5_ui(&mut cols[0], within);
        let title = "Reference-distance errors, measured − reference (cf. paper Fig. 6)";
        cols[1].label(RichText::new(title).strong());
        // No key over an empty plot.
        if !distances.is_empty() {
            key_ui(&mut cols[1]);
        }
        fig6_ui(&mut cols[1], distances);
    });
    // The after series on its own scale: on the before's it is a flat
    // line at zero.
    ui.columns(2, |cols| {
        let title = RichText::new("Fig. 5, after only (its own scale)").strong();
        cols[0].label(title.color(AFTER));
        let after = numbered(within.iter().map(|p| p.after));
        let plot = compare_plot("fig5_after", AFTER_HEIGHT, FIG5_AXES).include_y(0.0);
        plot.show(&mut cols[0], |p| {
            series(p, AFTER_NAME, after, AFTER, MarkerShape::Circle);
        });
        if !distances.is_empty() {
            let title = RichText::new("Fig. 6, after only (its own scale)").strong();
            cols[1].label(title.color(AFTER));
            let after = numbered(distances.iter().map(DistanceRecord::error_after));
            compare_plot("fig6_after", AFTER_HEIGHT, FIG6_AXES).show(&mut cols[1], |p| {
                zero_line(p);
                series(p, AFTER_NAME, after, AFTER, MarkerShape::Circle);
            });
        }
    });
    ui.columns(2, |cols| {
        cols[0].label(RichText::new("ε per iteration (paper eq. 20)").strong());
        let (epsilons, threshold) = (view.epsilons(), view.file.solver.threshold());
        let height = PLOT_HEIGHT;
        epsilon_plot_ui(&mut cols[0], "result_epsilon", &epsilons, threshold, height);
        let title = if view.hand_eye_only.is_some() {
            "Identified: the hand-eye only"
        } else if singular_values(view).is_empty() && !nothing_identified(view) {
            "Identifiable set"
        } else {
            "Singular values of the last update"
        };
        cols[1].label(RichText::new(title).strong());
        singular_ui(&mut cols[1], view);
    });
}

/// The singular values of the paper's last update, descending (none for
/// another method).
fn singular_values(view: &ResultView) -> &[f64] {
    let paper = view.file.solver.paper();
    paper
        .and_then(|p| p.singular_values.as_deref())
        .unwrap_or_default()
}

/// The method neither estimated nor held fixed any parameter (no update
/// was made).
fn nothing_identified(view: &ResultView) -> bool {
    view.file.solver.fixed().is_empty() && view.file.solver.estimated().is_empty()
}

/// What the method says about parameters the data cannot tell apart.
fn caveats(view: &ResultView) -> Vec<String> {
    let Some(ml) = view.file.solver.ml() else {
        return Vec::new();
    };
    let inseparable = ml.inseparable.iter().map(ToString::to_string);
    let strong = ml.strong_correlations.iter();
    inseparable
        .chain(strong.map(|c| format!("strongly correlated: {c}")))
        .collect()
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

/// The name of the after series.
const AFTER_NAME: &str = "after (calibrated)";

/// Fig. 5's axis labels.
const FIG5_AXES: (&str, &str) = ("pair (station by station)", "distance (mm)");

/// Fig. 6's axis labels.
const FIG6_AXES: (&str, &str) = ("reference distance no.", "error (mm)");

/// A series drawn as a line through its markers.
fn series(
    p: &mut egui_plot::PlotUi<'_>,
    name: &str,
    points: Vec<[f64; 2]>,
    colour: egui::Color32,
    shape: MarkerShape,
) {
    let line = Line::new(name, PlotPoints::from(points.clone()));
    p.line(line.color(colour).width(1.0));
    let points = Points::new(name, PlotPoints::from(points));
    p.points(points.color(colour).shape(shape).radius(3.0));
}

/// The before (squares) and after (circles) series of `values`
/// (before, after), numbered from 1.
fn before_after_series(p: &mut egui_plot::PlotUi<'_>, values: impl Iterator<Item = (f64, f64)>) {
    let (before, after): (Vec<f64>, Vec<f64>) = values.unzip();
    let before = numbered(before.into_iter());
    series(p, "before (nominal)", before, BEFORE, MarkerShape::Square);
    series(
        p,
        AFTER_NAME,
        numbered(after.into_iter()),
        AFTER,
        MarkerShape::Circle,
    );
}

/// The line at 0 of an error plot.
fn zero_line(p: &mut egui_plot::PlotUi<'_>) {
    p.hline(HLine::new("", 0.0).color(MUTED).width(1.0));
}

/// A plot of Fig. 5 or 6 (or its after-only panel) `height` points tall
/// with its axes.
fn compare_plot<'a>(id: &str, height: f32, (x, y): (&str, &str)) -> Plot<'a> {
    readable(Plot::new(id), true)
        .height(height)
        // The wheel scrolls the page, not the plot (drag still pans).
        .allow_scroll(false)
        .x_axis_label(x.to_owned())
        .y_axis_label(y.to_owned())
}

/// The hover text of a point: `text(its index, its value)` near one.
fn hover<'a>(
    text: impl Fn(usize, f64) -> Option<String> + 'a,
) -> impl Fn(&egui_plot::HoverPosition<'_>) -> Option<String> + 'a {
    move |pos| match pos {
        egui_plot::HoverPosition::NearDataPoint {
            index, position, ..
        } => text(*index, position.y),
        egui_plot::HoverPosition::Elsewhere { .. } => None,
    }
}

fn fig5_ui(ui: &mut egui::Ui, within: &[PairDistance]) {
    let top = within
        .iter()
        .map(|p| p.before.max(p.after))
        .fold(0.0, f64::max);
    let text = |k: usize, y: f64| {
        let p = within.get(k)?;
        Some(format!(
            "{}: {} – {}\n{y:.4} mm",
            p.station, p.ids.0, p.ids.1
        ))
    };
    compare_plot("fig5", PLOT_HEIGHT, FIG5_AXES)
        .include_y(0.0)
        .include_y(top * 1.15)
        .label_formatter(hover(text))
        .show(ui, |p| {
            station_bands_ui(p, within, top * 1.1);
            before_after_series(p, within.iter().map(|w| (w.before, w.after)));
        });
}

/// Height of the after-only panels, points.
const AFTER_HEIGHT: f32 = PLOT_HEIGHT * 0.6;

/// Values numbered from 1 for a plot.
fn numbered(values: impl Iterator<Item = f64>) -> Vec<[f64; 2]> {
    values
        .enumerate()
        .map(|(k, v)| [(k + 1) as f64, v])
        .collect()
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

fn fig6_ui(ui: &mut egui::Ui, distances: &[DistanceRecord]) {
    if distances.is_empty() {
        ui.allocate_ui(egui::vec2(ui.available_width(), PLOT_HEIGHT), |ui| {
            ui.label(RichText::new("No reference distances in this session.").color(MUTED));
        });
        return;
    }
    let text = |k: usize, y: f64| {
        let d = distances.get(k)?;
        let (from, to, pose, reference) = (&d.from, &d.to, &d.pose, d.reference);
        Some(format!(
            "{from} → {to}, pose {pose}: reference {reference:.3} mm\nerror {y:+.4} mm"
        ))
    };
    let errors = distances
        .iter()
        .map(|d| (d.error_before(), d.error_after()));
    compare_plot("fig6", PLOT_HEIGHT, FIG6_AXES)
        .label_formatter(hover(text))
        .show(ui, |p| {
            zero_line(p);
            before_after_series(p, errors);
        });
}

fn singular_ui(ui: &mut egui::Ui, view: &ResultView) {
    let all = singular_values(view);
    let values: Vec<(usize, f64)> = all
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
            } else if nothing_identified(view) {
                let text = "No update was made: ε started below the threshold.";
                ui.label(RichText::new(text).color(MUTED));
            } else {
                identifiable_set_ui(ui, view);
            }
        });
        return;
    }
    let paper = view.file.solver.paper();
    let smax = values.iter().map(|v| v.1).fold(0.0, f64::max);
    let cut = paper.and_then(|p| p.svd_tolerance).map(|t| t * smax);
    let kept = paper.and_then(|p| p.kept_directions);
    let (kept, dropped): (Indexed, Indexed) = values
        .iter()
        .partition(|(k, s)| kept.map_or(cut.is_none_or(|c| *s >= c), |n| *k < n));
    let pts = |v: &[(usize, f64)]| -> Vec<[f64; 2]> {
        v.iter()
            .map(|(k, s)| [(*k + 1) as f64, s.log10()])
            .collect()
    };
    let zeros = all.len() - values.len();
    let mut key = vec![("● kept", AFTER)];
    if !dropped.is_empty() {
        key.push(("× dropped", BAD));
    }
    if cut.is_some() {
        key.push(("- - truncation (tolerance × σ_max)", BEFORE));
    }
    crate::app::widgets::plot_key(ui, &key);
    // Less the key line, and the zeros' note under the plot.
    let height = PLOT_HEIGHT - if zeros > 0 { 36.0 } else { 18.0 };
    crate::app::widgets::plots::readable_log_y(Plot::new("singular"))
        .height(height)
        .x_axis_label("index")
        .y_axis_label("σ (log scale)")
        .show(ui, |p| {
            let kept = Points::new("kept", PlotPoints::from(pts(&kept)));
            p.points(kept.color(AFTER).radius(3.5));
            if !dropped.is_empty() {
                let dropped = Points::new("dropped", PlotPoints::from(pts(&dropped)));
                p.points(dropped.color(BAD).shape(MarkerShape::Cross).radius(5.0));
            }
            if let Some(c) = cut {
                let line = HLine::new("truncation (tolerance × σ_max)", c.log10());
                p.hline(line.color(BEFORE).style(LineStyle::dashed_loose()));
            }
        });
    if zeros > 0 {
        let text = format!("{zeros} singular value(s) are 0 (not drawn on the log scale)");
        ui.label(RichText::new(text).small().weak());
    }
}

/// Room kept between a column's text and its right edge, points.
const TEXT_MARGIN: f32 = 12.0;

/// `text` wrapped in its column.
fn wrapped(ui: &mut egui::Ui, text: impl Into<egui::WidgetText>) {
    ui.add(egui::Label::new(text).wrap());
}

/// A pose-only result (flange poses, no joint readings): no kinematic
/// parameter was identified, so there is no identifiable set to list.
fn pose_only_ui(ui: &mut egui::Ui, view: &ResultView) {
    wrapped(
        ui,
        format!(
            "A pose-only result: the session gives flange poses, no joint readings, so method {} identified the hand-eye (sensor on the flange) and the station centres and no kinematic parameter: there is no identifiable set of the model to show. How well the hand-eye is determined: under “Hand-eye only”.",
            view.method()
        ),
    );
    for c in caveats(view) {
        wrapped(ui, RichText::new(c).small());
    }
}

/// What a method that chooses its identifiable set (rather than truncating
/// an SVD) estimated and held fixed (the list only when it held some).
fn identifiable_set_ui(ui: &mut egui::Ui, view: &ResultView) {
    let (method, solver) = (view.method(), &view.file.solver);
    let (estimated, fixed) = (solver.estimated().len(), solver.fixed());
    let text = if fixed.is_empty() {
        format!("Method {method} estimated {estimated} parameter(s) and held none fixed.")
    } else {
        format!(
            "Method {method} estimated {estimated} parameter(s) and held {} fixed (not identifiable from centre distances):",
            fixed.len()
        )
    };
    // Wrapped in its column: the text at the right edge was cut at
    // 1366 × 768.
    wrapped(ui, text);
    egui::ScrollArea::vertical()
        .id_salt("identifiable_set")
        .max_height(PLOT_HEIGHT - 30.0)
        .show(ui, |ui| {
            if !fixed.is_empty() {
                wrapped(
                    ui,
                    RichText::new(format!("fixed: {}", fixed.join(", "))).color(MUTED),
                );
            }
            for c in caveats(view) {
                wrapped(ui, RichText::new(c).small());
            }
        });
}
