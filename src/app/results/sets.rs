//! The calibration set against the validation set, as a table of mean,
//! std and max before → after (mm), with a histogram of the errors after
//! calibration: the within-station centre distances of the identify
//! stations (what the solver fitted) beside those of the validate
//! stations (held out). A validation clearly worse than the calibration
//! set points at too few stations or stations that do not cover where
//! the robot is used, rather than at noise.

use egui::RichText;
use egui_plot::{Bar, BarChart, Plot};

use crate::app::results::{CALIBRATION_SET, ErrorSet, ResultView, Summary};
use crate::app::widgets::plots::{nice_step, readable};
use crate::app::widgets::{AFTER, BEFORE, MUTED, plot_key, table};

/// Width of the histogram beside the table, points.
const HISTOGRAM_WIDTH: f32 = 300.0;

/// Height of the histogram, points.
const HISTOGRAM_HEIGHT: f32 = 170.0;

/// About this many bins over the largest error after calibration.
const HISTOGRAM_BINS: f64 = 14.0;

/// The title of the table (its accessible name).
pub const SETS_TITLE: &str = "Calibration set vs validation set";

/// Colour of the calibration set in the histogram.
const CALIBRATION: egui::Color32 = AFTER;
/// Colour of the validation set in the histogram.
const VALIDATION: egui::Color32 = BEFORE;

/// The table and the histogram, side by side.
pub(super) fn sets_ui(ui: &mut egui::Ui, view: &ResultView) {
    if view.sets.is_empty() {
        return;
    }
    ui.label(RichText::new(SETS_TITLE).strong());
    let width = ui.available_width();
    let table = (width - HISTOGRAM_WIDTH - 16.0).max(300.0);
    ui.horizontal_top(|ui| {
        ui.allocate_ui_with_layout(
            egui::vec2(table, 0.0),
            egui::Layout::top_down(egui::Align::Min),
            |ui| table_ui(ui, &view.sets),
        );
        ui.add_space(12.0);
        ui.vertical(|ui| histogram_ui(ui, &view.sets));
    });
}

fn table_ui(ui: &mut egui::Ui, sets: &[ErrorSet]) {
    ui.spacing_mut().item_spacing = egui::vec2(10.0, 4.0);
    let header = ["set", "errors", "n", "mean", "std", "max"];
    table(ui, "sets_table", &header, |ui| {
        for s in sets {
            let (b, a) = (Summary::of(&s.before), Summary::of(&s.after));
            ui.label(s.set);
            ui.add(egui::Label::new(&s.what).extend());
            ui.label(a.n.to_string());
            for (b, a) in [(b.mean, a.mean), (b.std, a.std), (b.max, a.max)] {
                ui.label(format!("{b:.3} → {a:.3}"));
            }
            ui.end_row();
        }
    });
    ui.add(
        egui::Label::new(
            RichText::new(
                "mm, before → after calibration. The calibration set is what the solver fitted, the validation set was held out; their within-station distances (true value 0) compare.",
            )
            .small()
            .color(MUTED),
        )
        .wrap(),
    );
}

/// The key entry of `set` in the histogram and its colour.
fn key(set: &ErrorSet) -> (&'static str, egui::Color32) {
    if set.set == CALIBRATION_SET {
        ("■ calibration", CALIBRATION)
    } else {
        ("■ validation", VALIDATION)
    }
}

/// The share (%) of `values` in each of `bins` bins of `width` from 0.
#[must_use]
pub fn histogram(values: &[f64], width: f64, bins: usize) -> Vec<f64> {
    let mut counts = vec![0.0; bins];
    if values.is_empty() || width.is_nan() || width <= 0.0 || bins == 0 {
        return counts;
    }
    for v in values {
        let k = ((v.abs() / width).floor() as usize).min(bins - 1);
        counts[k] += 1.0;
    }
    let n = values.len() as f64;
    counts.iter().map(|c| 100.0 * c / n).collect()
}

/// The within-station distances after calibration of each set, as the
/// share of the set in each bin (sets of different sizes compare).
fn histogram_ui(ui: &mut egui::Ui, sets: &[ErrorSet]) {
    let within: Vec<&ErrorSet> = sets.iter().filter(|s| s.within).collect();
    let largest = within
        .iter()
        .flat_map(|s| s.after.iter())
        .fold(0.0_f64, |m, v| m.max(v.abs()));
    if within.is_empty() || largest <= 0.0 {
        return;
    }
    let width = nice_step(largest / HISTOGRAM_BINS, false);
    let bins = ((largest / width).floor() as usize + 1).max(1);
    let entries: Vec<_> = within.iter().map(|s| key(s)).collect();
    plot_key(ui, &entries);
    readable(Plot::new("sets_histogram"), false)
        .height(HISTOGRAM_HEIGHT)
        .allow_scroll(false)
        .allow_drag(false)
        .include_y(0.0)
        .include_x(0.0)
        .width(HISTOGRAM_WIDTH)
        .x_axis_label("distance after calibration (mm)")
        .y_axis_label("share (%)")
        .show(ui, |p| {
            let n = within.len() as f64;
            for (k, s) in within.iter().enumerate() {
                let colour = key(s).1;
                // Side by side within each bin.
                let bar_width = width / n;
                let bars: Vec<Bar> = histogram(&s.after, width, bins)
                    .into_iter()
                    .enumerate()
                    .map(|(b, share)| {
                        Bar::new(b as f64 * width + bar_width * (k as f64 + 0.5), share)
                            .width(bar_width * 0.9)
                    })
                    .collect();
                p.bar_chart(BarChart::new(s.set, bars).color(colour));
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_histogram_is_a_share_of_each_set() {
        let h = histogram(&[0.01, 0.02, 0.02, 0.06, 5.0], 0.05, 3);
        assert_eq!(h, vec![60.0, 20.0, 20.0]);
        assert!((h.iter().sum::<f64>() - 100.0).abs() < 1e-9);
        assert_eq!(histogram(&[], 0.1, 2), vec![0.0, 0.0]);
    }
}
