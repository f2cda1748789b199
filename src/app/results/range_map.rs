//! The predicted error over the sensor's measuring range as a map, on an
//! absolute colour scale from 0 mm with its colour bar in mm: a spread of
//! a micrometre draws as one colour, not green to red, and the caption
//! says what the cells are (each point's 1σ, rms over the working poses)
//! beside the summary's maximum (the largest at any one pose).

use egui::RichText;
use egui_plot::{Line, MarkerShape, Plot, PlotPoints, Points, Polygon};

use super::ui::PLOT_HEIGHT;
use crate::app::widgets::MUTED;
use crate::app::widgets::plots::{nice_step, readable, tick_label};
use crate::engine::calibrate::solve::ml::range::RangeError;

/// Width of the colour bar, points.
const BAR_WIDTH: f32 = 16.0;

/// Bands the colour bar is drawn in.
const BAR_BANDS: usize = 48;

/// Labelled ticks on the colour bar, at most.
const BAR_TICKS: f64 = 5.0;

pub use crate::engine::tools::report::svg::{map_scale, scale_top};

/// The engine's map colour at `sigma` on the scale 0 … `top` mm
/// ([`heat_rgb`](crate::engine::tools::report::svg::heat_rgb): green at 0, red
/// at the top).
#[must_use]
pub fn cell_colour(sigma: f64, top: f64) -> egui::Color32 {
    let [r, g, b] = crate::engine::tools::report::svg::heat_rgb(sigma / top.max(f64::MIN_POSITIVE));
    egui::Color32::from_rgb(r, g, b)
}

/// The colour bar's hover text: its scale in words.
#[must_use]
pub fn colour_bar_label(top: f64) -> String {
    format!("colour scale: 0 mm (green) to {} mm (red)", scale_text(top))
}

/// The top of the scale as the caption and the bar give it ("0.12").
#[must_use]
pub fn scale_text(top: f64) -> String {
    bar_tick(top, top)
}

fn bar_tick(value: f64, top: f64) -> String {
    tick_label(egui_plot::GridMark {
        value,
        step_size: nice_step(top / BAR_TICKS, false),
    })
}

/// The predicted error over the range as a map: one cell per grid point
/// coloured by its σ on the absolute scale, the colour bar beside it, the
/// region the sphere positions covered outlined, the largest σ at one
/// pose marked.
///
/// The scale runs from 0 to the tolerance (`tolerance_mm`, the verdict's
/// std) or the largest value, whichever is larger ([`map_scale`]): a cell
/// within the tolerance is never red. The tolerance and the largest σ at
/// one pose are marked on the bar.
pub(super) fn range_map_ui(ui: &mut egui::Ui, r: &RangeError, tolerance_mm: f64) {
    if r.map.is_empty() || r.grid < 2 {
        return;
    }
    let (lo, hi) = r
        .map
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p[2]), b.max(p[2]))
        });
    let top = map_scale(hi.max(r.max_mm), tolerance_mm);
    let half_y = (r.y[1] - r.y[0]) / (r.grid - 1) as f64 / 2.0;
    let half_z = (r.z[1] - r.z[0]) / (r.grid - 1) as f64 / 2.0;
    ui.label(
        RichText::new(format!(
            "Each cell: the point's predicted 1σ, rms over the {} working poses: {lo:.3} to {hi:.3} mm. \
             The summary's max ({:.3} mm, ×) is the largest at any one pose. \
             Colours from 0 mm (green) to {} mm (red), the tolerance {} mm (std) marked on the bar; the white outline is where the sphere was seen.",
            r.poses,
            r.max_mm,
            scale_text(top),
            crate::engine::base::numeric::show(tolerance_mm)
        ))
        .color(MUTED),
    );
    ui.horizontal(|ui| {
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
                    let colour = cell_colour(c[2], top);
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
                        format!("largest σ at one pose {:.3} mm", r.max_mm),
                        PlotPoints::from(vec![r.max_at]),
                    )
                    .shape(MarkerShape::Cross)
                    .radius(6.0)
                    .color(egui::Color32::WHITE),
                );
            });
        colour_bar_ui(ui, top, &[("tolerance", tolerance_mm), ("max", r.max_mm)]);
    });
}

/// The colour bar: 0 mm at the bottom, `top` at the top, labelled at
/// round steps in mm, and each of `marks` (name, mm) as a line across it
/// with its name and value.
fn colour_bar_ui(ui: &mut egui::Ui, top: f64, marks: &[(&str, f64)]) {
    let label_width = 150.0;
    let (rect, response) = ui.allocate_exact_size(
        egui::vec2(BAR_WIDTH + label_width, PLOT_HEIGHT),
        egui::Sense::hover(),
    );
    response.on_hover_text(colour_bar_label(top));
    let painter = ui.painter_at(rect);
    // Room for the top and bottom labels.
    let bar = egui::Rect::from_min_max(
        rect.min + egui::vec2(0.0, 8.0),
        egui::pos2(rect.min.x + BAR_WIDTH, rect.max.y - 8.0),
    );
    let y_of = |v: f64| bar.bottom() - (v / top) as f32 * bar.height();
    for k in 0..BAR_BANDS {
        let (a, b) = (
            top * k as f64 / BAR_BANDS as f64,
            top * (k + 1) as f64 / BAR_BANDS as f64,
        );
        let band = egui::Rect::from_x_y_ranges(bar.x_range(), y_of(b)..=y_of(a));
        painter.rect_filled(band, 0.0, cell_colour(f64::midpoint(a, b), top));
    }
    let text = ui.visuals().text_color();
    painter.rect_stroke(
        bar,
        0.0,
        egui::Stroke::new(1.0, text),
        egui::StrokeKind::Inside,
    );
    let step = nice_step(top / BAR_TICKS, false);
    let mut values = Vec::new();
    let mut v = 0.0;
    while v <= top * (1.0 + 1e-9) {
        values.push(v);
        v += step;
    }
    // The top is always labelled (0.12 on steps of 0.05).
    if values.last().is_some_and(|last| top - last > step * 0.3) {
        values.push(top);
    }
    let mark_colour = if ui.visuals().dark_mode {
        egui::Color32::WHITE
    } else {
        egui::Color32::BLACK
    };
    let mut marked: Vec<f32> = Vec::new();
    for (name, v) in marks {
        if !(v.is_finite() && *v >= 0.0 && *v <= top * (1.0 + 1e-9)) {
            continue;
        }
        let y = y_of(*v);
        painter.line_segment(
            [
                egui::pos2(bar.left() - 2.0, y),
                // Across the bar only: a line to the tick labels struck
                // their numbers through.
                egui::pos2(bar.right() + 2.0, y),
            ],
            egui::Stroke::new(2.0, mark_colour),
        );
        // Two marks close together: the second one's words below.
        let dy = if marked.iter().any(|m| (m - y).abs() < 12.0) {
            12.0
        } else {
            0.0
        };
        marked.push(y);
        painter.text(
            egui::pos2(bar.right() + 62.0, y + dy),
            egui::Align2::LEFT_CENTER,
            format!("{name} {v:.3}"),
            egui::FontId::proportional(12.0),
            text,
        );
    }
    for v in values {
        let y = y_of(v);
        painter.line_segment(
            [egui::pos2(bar.right(), y), egui::pos2(bar.right() + 4.0, y)],
            egui::Stroke::new(1.0, text),
        );
        painter.text(
            egui::pos2(bar.right() + 6.0, y),
            egui::Align2::LEFT_CENTER,
            format!("{} mm", bar_tick(v, top)),
            egui::FontId::proportional(12.0),
            text,
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The issue: cells of 0.112-0.113 mm were drawn green to red. On the
    /// absolute scale (0 to 0.12 mm) they are one colour.
    #[test]
    fn a_micrometre_of_spread_is_one_colour() {
        let top = scale_top(0.113);
        assert!((top - 0.12).abs() < 1e-12, "{top}");
        let (a, b) = (cell_colour(0.112, top), cell_colour(0.113, top));
        let diff = a
            .to_array()
            .iter()
            .zip(b.to_array())
            .map(|(x, y)| (i32::from(*x) - i32::from(y)).abs())
            .max()
            .unwrap_or(0);
        assert!(diff <= 6, "{a:?} vs {b:?}");
        // 0 mm is green, the top red.
        assert_eq!(cell_colour(0.0, top), egui::Color32::from_rgb(60, 170, 90));
        assert_eq!(cell_colour(top, top), egui::Color32::from_rgb(225, 60, 60));
        assert_eq!(scale_top(0.246), 0.25);
        assert_eq!(scale_top(1.0), 1.0);
        assert_eq!(scale_top(0.0), 1.0);
        assert_eq!(
            colour_bar_label(0.12),
            "colour scale: 0 mm (green) to 0.12 mm (red)"
        );
    }

    /// Issue 34: cells of 0.112 mm passing a 0.5 mm tolerance are green,
    /// not red: the scale runs to the tolerance when it is larger.
    #[test]
    fn the_scale_reaches_the_tolerance() {
        let top = map_scale(0.150, 0.5);
        assert!((top - 0.5).abs() < 1e-12, "{top}");
        let c = cell_colour(0.112, top).to_array();
        assert!(c[1] > c[0], "a passing cell is green-ish: {c:?}");
        // Beyond the tolerance, the largest value sets it.
        assert!((map_scale(0.7, 0.5) - 0.8).abs() < 1e-12);
        assert!((map_scale(0.113, f64::NAN) - 0.12).abs() < 1e-12);
    }
}
