//! Readable plot axes, shared by every view's plots: ticks at 1-2-5 steps
//! spaced so that each carries its number (egui_plot's default spacer
//! steps by powers of ten, which over a span of 8–20 units leaves one
//! label, "0"), labels with as many decimals as the step needs, whole
//! numbers on counting axes, and band labels (Fig. 5's stations) thinned
//! so that none overlaps the next.

use egui::RichText;
use egui_plot::{AxisHints, GridInput, GridMark, HLine, Line, Plot, PlotPoints, Points};

use super::{AFTER, BEFORE};

/// egui_plot's `grid_spacing.min`, set explicitly: the spacer reads the
/// plot's scale from [`GridInput::base_step_size`], which is this many
/// points' worth of data units.
const GRID_SPACING_MIN: f32 = 8.0;

/// Least distance between two labelled ticks on a y axis, points: more
/// than [`Y_FADE`] and a line of text (about 16 points).
pub const Y_LABEL_GAP: f64 = 26.0;

/// Least distance between two labelled ticks on an x axis, points:
/// more than [`X_FADE`] and a number's width ("150" is about 25 points).
pub const X_LABEL_GAP: f64 = 48.0;

/// Where egui_plot fades y tick labels in, points apart (its default,
/// 20–30, would fade labels [`ticks`] already spaced to fit).
const Y_FADE: (f32, f32) = (16.0, 22.0);

/// Where egui_plot fades x tick labels in, points apart (default 60–80,
/// for long labels; ours are numbers, and egui_plot still drops a label
/// wider than its spacing).
const X_FADE: (f32, f32) = (36.0, 44.0);

/// Least width of a y axis, points: its tick labels ("-10", "0.25") and
/// its rotated title. egui_plot sizes an axis from the last frame's
/// labels, so on a plot's first frame the title sat over the ticks (the
/// Centres views at 3,201 stations); wider labels still widen it.
const Y_AXIS_MIN: f32 = 48.0;

/// Least height of an x axis, points: a line of tick labels and the
/// title below it.
const X_AXIS_MIN: f32 = 38.0;

/// Least distance between two date labels ("2026-01-12"), points.
pub const DATE_LABEL_GAP: f64 = 96.0;

/// The smallest step of 1, 2 or 5 times a power of ten that is at least
/// `least` (data units); at least 1 when `whole`.
#[must_use]
pub fn nice_step(least: f64, whole: bool) -> f64 {
    let step = crate::engine::base::numeric::step_125_at_least(least);
    if whole { step.max(1.0).round() } else { step }
}

/// The ticks over `bounds` (data units) for a plot drawing `units_per_point`
/// data units per screen point: every multiple of one step, the step the
/// least that keeps `gap` points between labels.
#[must_use]
pub fn ticks(bounds: (f64, f64), units_per_point: f64, gap: f64, whole: bool) -> Vec<GridMark> {
    let (lo, hi) = (bounds.0.min(bounds.1), bounds.0.max(bounds.1));
    if !(lo.is_finite() && hi.is_finite() && units_per_point.is_finite()) {
        return Vec::new();
    }
    let step = nice_step(units_per_point * gap, whole);
    let (first, last) = ((lo / step).ceil(), (hi / step).floor());
    if last - first > 1000.0 {
        return Vec::new();
    }
    let mut out = Vec::new();
    let mut k = first;
    while k <= last {
        out.push(GridMark {
            value: k * step,
            step_size: step,
        });
        k += 1.0;
    }
    out
}

/// A tick's label: its value with the decimals its step needs (0.5 → 1,
/// 0.05 → 2, 20 → none), never "-0".
#[must_use]
pub fn tick_label(mark: GridMark) -> String {
    let step = mark.step_size.abs();
    let decimals = if step > 0.0 && step < 1.0 {
        (-step.log10() - 1e-9).ceil().max(0.0) as usize
    } else {
        0
    };
    let v = if mark.value.abs() < step * 1e-6 {
        0.0
    } else {
        mark.value
    };
    format!("{v:.decimals$}")
}

/// The grid spacer of one axis: [`ticks`] at the plot's current scale.
fn spacer(gap: f64, whole: bool) -> impl Fn(GridInput) -> Vec<GridMark> {
    move |input: GridInput| {
        let units_per_point = input.base_step_size / f64::from(GRID_SPACING_MIN);
        ticks(input.bounds, units_per_point, gap, whole)
    }
}

/// A plot whose x and y axes carry readable numbers: labelled ticks
/// [`X_LABEL_GAP`] and [`Y_LABEL_GAP`] apart, whole numbers on the x
/// axis when `whole_x` (counts: pair, distance no., update). Call it
/// first: it replaces the axes, whose labels are set after.
#[must_use]
pub fn readable(plot: Plot<'_>, whole_x: bool) -> Plot<'_> {
    readable_y(plot)
        .custom_x_axes(vec![
            AxisHints::new_x()
                .label_spacing(egui::Rangef::new(X_FADE.0, X_FADE.1))
                .min_thickness(X_AXIS_MIN),
        ])
        .x_grid_spacer(spacer(X_LABEL_GAP, whole_x))
        .x_axis_formatter(|mark, _| tick_label(mark))
}

/// A plot whose y axis carries readable numbers (the x axis is the
/// caller's, e.g. dates or a log scale).
#[must_use]
pub fn readable_y(plot: Plot<'_>) -> Plot<'_> {
    plot.grid_spacing(egui::Rangef::new(GRID_SPACING_MIN, 300.0))
        .custom_y_axes(vec![
            AxisHints::new_y()
                .label_spacing(egui::Rangef::new(Y_FADE.0, Y_FADE.1))
                .min_thickness(Y_AXIS_MIN),
        ])
        .y_grid_spacer(spacer(Y_LABEL_GAP, false))
        .y_axis_formatter(|mark, _| tick_label(mark))
}

/// Mantissas tried, finest last, when whole decades leave fewer than two
/// labels on a log axis.
const LOG_MANTISSAS: [&[f64]; 2] = [
    &crate::engine::base::numeric::STEPS_125,
    &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0],
];

/// The ticks of a `log10` axis over `bounds` (log units) drawn at
/// `units_per_point` log units per point, each label `gap` points from
/// the next: whole decades (1, 2 or 5 apart) when two or more fit, else
/// 1-2-5 or 1…9 times a decade, else round values spaced evenly (a span
/// within one decade, e.g. ε from 0.37 to 0.36 mm, still carries at
/// least two numbers).
#[must_use]
pub fn log_ticks(bounds: (f64, f64), units_per_point: f64, gap: f64) -> Vec<GridMark> {
    if !(bounds.0.is_finite() && bounds.1.is_finite() && units_per_point.is_finite()) {
        return Vec::new();
    }
    let (lo, hi) = (bounds.0.min(bounds.1), bounds.0.max(bounds.1));
    if hi - lo >= 1000.0 {
        return Vec::new();
    }
    let decades = ticks((lo, hi), units_per_point, gap, true);
    if decades.len() >= 2 {
        return decades;
    }
    let least = units_per_point * gap;
    // Kept greedily from the bottom, each `least` above the last.
    let spaced = |values: Vec<f64>| -> Vec<f64> {
        let mut kept: Vec<f64> = Vec::new();
        for v in values {
            if kept.last().is_none_or(|last| v - last >= least) {
                kept.push(v);
            }
        }
        kept
    };
    let marks = |kept: Vec<f64>| -> Vec<GridMark> {
        let step = kept
            .windows(2)
            .map(|w| w[1] - w[0])
            .fold(f64::INFINITY, f64::min);
        let step = if step.is_finite() { step } else { least };
        kept.into_iter()
            .map(|value| GridMark {
                value,
                step_size: step,
            })
            .collect()
    };
    for mantissas in LOG_MANTISSAS {
        let mut values = Vec::new();
        let mut d = lo.floor();
        while d <= hi.ceil() {
            for m in mantissas {
                let v = d + m.log10();
                if v >= lo && v <= hi {
                    values.push(v);
                }
            }
            d += 1.0;
        }
        let kept = spaced(values);
        if kept.len() >= 2 {
            return marks(kept);
        }
    }
    // Within one decade: round values of the quantity itself.
    let (a, b) = (10f64.powf(lo), 10f64.powf(hi));
    let labels = ((hi - lo) / least).floor().max(1.0);
    let step = nice_step((b - a) / labels, false);
    let mut values = Vec::new();
    let mut k = (a / step).ceil();
    while k * step <= b && values.len() < 100 {
        values.push((k * step).log10());
        k += 1.0;
    }
    marks(spaced(values))
}

/// A plot whose y axis is `log10` of the values, labelled by
/// [`log_ticks`] with the value itself ([`super::log_tick`]).
#[must_use]
pub fn readable_log_y(plot: Plot<'_>) -> Plot<'_> {
    plot.grid_spacing(egui::Rangef::new(GRID_SPACING_MIN, 300.0))
        .custom_y_axes(vec![
            AxisHints::new_y()
                .label_spacing(egui::Rangef::new(Y_FADE.0, Y_FADE.1))
                .min_thickness(Y_AXIS_MIN),
        ])
        .y_grid_spacer(|input: GridInput| {
            let units_per_point = input.base_step_size / f64::from(GRID_SPACING_MIN);
            log_ticks(input.bounds, units_per_point, Y_LABEL_GAP)
        })
        .y_axis_formatter(|mark, _| super::log_tick(mark.value))
}

/// A plot whose x axis counts positions `0, 1, …` labelled by `labels`
/// (e.g. dates), thinned to every k-th so that each label fits in `gap`
/// points.
#[must_use]
pub fn labelled_x(plot: Plot<'_>, labels: Vec<String>, gap: f64) -> Plot<'_> {
    plot.grid_spacing(egui::Rangef::new(GRID_SPACING_MIN, 300.0))
        .x_grid_spacer(spacer(gap, true))
        .x_axis_formatter(move |mark, _| {
            let i = mark.value.round();
            if (mark.value - i).abs() < 1e-6 && i >= 0.0 {
                labels.get(i as usize).cloned().unwrap_or_default()
            } else {
                String::new()
            }
        })
}

/// Which of the band labels centred at `centres` (screen points, left to
/// right) with widths `widths` (points) to draw so that no two overlap:
/// greedily from the left, a label is kept when it starts `gap` points
/// after the last kept one ends.
#[must_use]
pub fn spaced_labels(centres: &[f32], widths: &[f32], gap: f32) -> Vec<usize> {
    let mut kept = Vec::new();
    let mut end = f32::NEG_INFINITY;
    for (k, (c, w)) in centres.iter().zip(widths).enumerate() {
        if c - w / 2.0 >= end + gap {
            kept.push(k);
            end = c + w / 2.0;
        }
    }
    kept
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
    // Within a decade, room above and below the data: the threshold's
    // name is written above its line, and at the top of the range (a
    // pose-only run stopping at once under it) it was cut by the frame.
    let decades = if hi - lo >= WHOLE_DECADES_FROM {
        vec![lo.floor(), hi.ceil()]
    } else {
        let pad = (0.25 * (hi - lo)).max(0.02);
        vec![lo - pad, hi + pad]
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
        // Update 1 too: with a single point (a run without update) x = 0
        // sat mid-plot and the threshold's name, written from it to the
        // right, ran past the frame.
        .include_x(0.0)
        .include_x(1.0)
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

#[cfg(test)]
mod tests {
    use super::*;

    fn labels(bounds: (f64, f64), points: f64, gap: f64, whole: bool) -> Vec<String> {
        ticks(bounds, (bounds.1 - bounds.0) / points, gap, whole)
            .into_iter()
            .map(tick_label)
            .collect()
    }

    #[test]
    fn steps_are_one_two_five() {
        assert_eq!(nice_step(0.7, false), 1.0);
        assert_eq!(nice_step(1.3, false), 2.0);
        assert_eq!(nice_step(3.0, false), 5.0);
        assert_eq!(nice_step(6.0, false), 10.0);
        assert_eq!(nice_step(0.013, false), 0.02);
        assert_eq!(nice_step(0.3, true), 1.0);
        assert_eq!(nice_step(f64::NAN, false), 1.0);
    }

    /// The case: Fig. 6 of 12 distances, errors within −3…5 mm
    /// on a 180-point plot, showed the single label "0". Now every
    /// labelled tick has its own number, at least four of them.
    #[test]
    fn a_small_span_carries_several_numbers() {
        let l = labels((-3.2, 5.4), 180.0, Y_LABEL_GAP, false);
        assert_eq!(l, ["-2", "0", "2", "4"]);
        // History's hand-eye roll: 179.02…179.11 deg over 120 points.
        let l = labels((179.02, 179.11), 120.0, Y_LABEL_GAP, false);
        assert!(l.len() >= 3, "{l:?}");
        assert!(
            l.iter().all(|s| s.starts_with("179.") && s.len() == 6),
            "{l:?}"
        );
        let distinct: std::collections::BTreeSet<_> = l.iter().collect();
        assert_eq!(distinct.len(), l.len(), "{l:?}");
        // A sub-millimetre Fig. 6 after calibration.
        let l = labels((-0.21, 0.18), 180.0, Y_LABEL_GAP, false);
        assert_eq!(l, ["-0.2", "-0.1", "0.0", "0.1"]);
    }

    #[test]
    fn counting_axes_are_whole_and_spaced() {
        // 12 reference distances across 450 points: every 2nd.
        let l = labels((0.5, 12.5), 450.0, X_LABEL_GAP, true);
        assert_eq!(l, ["2", "4", "6", "8", "10", "12"]);
        // Two updates in 300 points: 0, 1, 2 and no 0.5.
        assert_eq!(
            labels((-0.1, 2.1), 300.0, X_LABEL_GAP, true),
            ["0", "1", "2"]
        );
        // 240 pairs: whole steps of 20 or more.
        let t = ticks((0.0, 240.0), 240.0 / 500.0, X_LABEL_GAP, true);
        assert!(t[1].value - t[0].value >= 20.0);
    }

    #[test]
    fn no_minus_zero_and_no_runaway() {
        assert_eq!(
            tick_label(GridMark {
                value: -1e-17,
                step_size: 0.1
            }),
            "0.0"
        );
        assert!(ticks((0.0, 1e9), 1e-9, 30.0, false).is_empty());
        assert!(ticks((f64::NAN, 1.0), 0.1, 30.0, false).is_empty());
    }

    fn log_labels(bounds: (f64, f64), points: f64) -> Vec<String> {
        log_ticks(bounds, (bounds.1 - bounds.0) / points, Y_LABEL_GAP)
            .into_iter()
            .map(|m| crate::app::widgets::log_tick(m.value))
            .collect()
    }

    /// The issue: ε of the real set (0.37 → 0.36 mm) had no number on
    /// its axis, and the demo's 0.1 none; every log axis now carries two
    /// or more, spaced.
    #[test]
    fn a_log_axis_within_a_decade_carries_numbers() {
        // 0.355…0.375 mm over 110 points.
        let l = log_labels((0.355_f64.log10(), 0.375_f64.log10()), 110.0);
        assert!(l.len() >= 2, "{l:?}");
        assert!(l.iter().all(|s| s.starts_with("0.3")), "{l:?}");
        let distinct: std::collections::BTreeSet<_> = l.iter().collect();
        assert_eq!(distinct.len(), l.len(), "{l:?}");
        // The demo: ε from 6.3 to 0.08 mm over 110 points: 0.1 and 1.
        let l = log_labels((0.08_f64.log10(), 6.3_f64.log10()), 110.0);
        assert!(
            l.contains(&"0.1".to_string()) && l.contains(&"1".to_string()),
            "{l:?}"
        );
        // Many decades: whole decades, spaced.
        let t = log_ticks((-9.0, 1.0), 10.0 / 110.0, Y_LABEL_GAP);
        assert!(
            t.len() >= 2 && t.iter().all(|m| m.value.fract() == 0.0),
            "{t:?}"
        );
        for w in t.windows(2) {
            assert!((w[1].value - w[0].value) / (10.0 / 110.0) >= Y_LABEL_GAP - 1e-9);
        }
        assert!(log_ticks((f64::NAN, 1.0), 0.1, 26.0).is_empty());
    }

    /// Fig. 5 of 60 stations on a 500-point plot: 8 points a station;
    /// the labels kept do not overlap and are spread over the plot.
    #[test]
    fn band_labels_do_not_overlap() {
        let centres: Vec<f32> = (0..60).map(|k| 4.0 + 8.0 * k as f32).collect();
        let widths = vec![24.0; 60];
        let kept = spaced_labels(&centres, &widths, 6.0);
        assert!(kept.len() >= 10 && kept.len() < 60, "{kept:?}");
        for w in kept.windows(2) {
            let (a, b) = (w[0], w[1]);
            assert!(centres[b] - widths[b] / 2.0 >= centres[a] + widths[a] / 2.0 + 6.0);
        }
        // Room for all: all kept.
        let centres: Vec<f32> = (0..5).map(|k| 50.0 * k as f32).collect();
        assert_eq!(spaced_labels(&centres, &[20.0; 5], 6.0).len(), 5);
    }
}
