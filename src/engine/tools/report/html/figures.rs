//! The report's figures: the paper's Fig. 5 and 6, ε per update and the
//! singular values, as inline SVG.

use std::fmt::Write as _;

use super::*;
use crate::engine::calibrate::validate::DistanceRecord;
use crate::engine::tools::report::svg::{
    self, Band, Marker, Plot, Rule, Series, escape, map_scale,
};
use crate::engine::tools::result_view::PairDistance;

/// Width of a full-width figure, px (the page is about 930 px wide).
pub const WIDE: f64 = 920.0;

/// Width of a half-width figure, px.
pub const HALF: f64 = 450.0;

/// Height of every figure, px.
pub const FIG_HEIGHT: f64 = 300.0;

pub(super) fn before_after_series(before: Vec<[f64; 2]>, after: Vec<[f64; 2]>) -> Vec<Series> {
    vec![
        Series {
            name: "before (nominal model, initial hand-eye)".into(),
            colour: BEFORE_COLOUR.into(),
            points: before,
            marker: Marker::Square,
            line: true,
        },
        Series {
            name: "after (calibrated)".into(),
            colour: AFTER_COLOUR.into(),
            points: after,
            marker: Marker::Circle,
            line: true,
        },
    ]
}

/// Consecutive runs of equal labels over 1-based positions, as bands.
pub(super) fn bands(labels: impl Iterator<Item = String>) -> Vec<Band> {
    let mut out: Vec<Band> = Vec::new();
    for (k, label) in labels.enumerate() {
        let x = (k + 1) as f64;
        match out.last_mut() {
            Some(b) if b.label == label => b.to = x + 0.5,
            _ => out.push(Band {
                from: x - 0.5,
                to: x + 0.5,
                label,
            }),
        }
    }
    out
}

/// The paper's Fig. 5 as a plot: within-station centre distances per
/// pair (true value 0), before and after, the stations as bands.
#[must_use]
pub fn fig5_plot(within: &[PairDistance], within_of: &str, width: f64) -> Plot {
    let pts = |f: fn(&PairDistance) -> f64| -> Vec<[f64; 2]> {
        within
            .iter()
            .enumerate()
            .map(|(k, p)| [(k + 1) as f64, f(p)])
            .collect()
    };
    Plot {
        title: format!("Centre distances within {within_of} stations, per pair, before and after"),
        x_label: "pair (station by station)".into(),
        y_label: "centre distance (mm)".into(),
        series: before_after_series(pts(|p| p.before), pts(|p| p.after)),
        bands: bands(within.iter().map(|p| p.station.clone())),
        include_zero: true,
        x_integer: true,
        width,
        height: FIG_HEIGHT,
        ..Plot::default()
    }
}

/// The paper's Fig. 6 as a plot: each reference distance's error,
/// measured − reference, before and after, with the zero line.
#[must_use]
pub fn fig6_plot(distances: &[DistanceRecord], width: f64) -> Plot {
    let pts = |f: fn(&DistanceRecord) -> f64| -> Vec<[f64; 2]> {
        distances
            .iter()
            .enumerate()
            .map(|(k, d)| [(k + 1) as f64, f(d)])
            .collect()
    };
    Plot {
        title: "Reference-distance errors, measured − reference, before and after".into(),
        x_label: "reference distance no.".into(),
        y_label: "error (mm)".into(),
        series: before_after_series(
            pts(DistanceRecord::error_before),
            pts(DistanceRecord::error_after),
        ),
        rules: vec![Rule {
            y: 0.0,
            colour: svg::MUTED.into(),
            dashed: false,
            label: String::new(),
        }],
        bands: bands(distances.iter().map(|d| format!("{}→{}", d.from, d.to))),
        include_zero: true,
        x_integer: true,
        width,
        height: FIG_HEIGHT,
        ..Plot::default()
    }
}

/// The after series of Fig. 5 (`errors` false) or Fig. 6 alone, on its
/// own scale: on the before's it is a flat line at zero.
#[must_use]
pub fn after_only_plot(
    title: &str,
    y_label: &str,
    after: Vec<[f64; 2]>,
    errors: bool,
    width: f64,
) -> Plot {
    Plot {
        title: title.to_owned(),
        x_label: if errors {
            "reference distance no.".into()
        } else {
            "pair (station by station)".into()
        },
        y_label: y_label.to_owned(),
        series: vec![Series {
            name: "after (calibrated)".into(),
            colour: AFTER_COLOUR.into(),
            points: after,
            marker: Marker::Circle,
            line: true,
        }],
        rules: if errors {
            vec![Rule {
                y: 0.0,
                colour: svg::MUTED.into(),
                dashed: false,
                label: String::new(),
            }]
        } else {
            Vec::new()
        },
        include_zero: true,
        x_integer: true,
        width,
        height: FIG_HEIGHT,
        ..Plot::default()
    }
}

/// Values numbered from 1, as a plot's points.
fn numbered(values: impl Iterator<Item = f64>) -> Vec<[f64; 2]> {
    values
        .enumerate()
        .map(|(k, v)| [(k + 1) as f64, v])
        .collect()
}

/// ε (mm) after 0, 1, … updates on a log scale, with the threshold.
#[must_use]
pub fn epsilon_plot(epsilons: &[f64], threshold: Option<f64>, width: f64) -> Plot {
    Plot {
        title: "ε per update".into(),
        x_label: "update".into(),
        y_label: "ε (mm, log scale)".into(),
        series: vec![Series {
            name: "ε".into(),
            colour: AFTER_COLOUR.into(),
            points: epsilons
                .iter()
                .enumerate()
                .map(|(k, e)| [k as f64, *e])
                .collect(),
            marker: Marker::Circle,
            line: true,
        }],
        rules: threshold
            .filter(|t| *t > 0.0)
            .map(|t| Rule {
                y: t,
                colour: BEFORE_COLOUR.into(),
                dashed: true,
                label: format!("threshold {t} mm"),
            })
            .into_iter()
            .collect(),
        y_log: true,
        x_integer: true,
        width,
        height: FIG_HEIGHT,
        ..Plot::default()
    }
}

/// The paper's method's singular values (descending) on a log scale:
/// the first `kept` kept, the rest dropped, the truncation line at
/// `svd_tolerance × σ_max`. Zeros are not drawn.
#[must_use]
pub fn singular_plot(values: &[f64], kept: usize, svd_tolerance: Option<f64>, width: f64) -> Plot {
    let smax = values.iter().copied().fold(0.0, f64::max);
    let cut = svd_tolerance.map(|t| t * smax);
    let pts = |keep: bool| -> Vec<[f64; 2]> {
        values
            .iter()
            .enumerate()
            .filter(|(k, v)| (*k < kept) == keep && **v > 0.0)
            .map(|(k, v)| [(k + 1) as f64, *v])
            .collect()
    };
    Plot {
        title: "Singular values of the last update".into(),
        x_label: "index".into(),
        y_label: "singular value (log scale)".into(),
        series: vec![
            Series {
                name: "kept".into(),
                colour: AFTER_COLOUR.into(),
                points: pts(true),
                marker: Marker::Circle,
                line: false,
            },
            Series {
                name: "dropped".into(),
                colour: BAD_COLOUR.into(),
                points: pts(false),
                marker: Marker::Cross,
                line: false,
            },
        ],
        rules: cut
            .map(|c| Rule {
                y: c,
                colour: BEFORE_COLOUR.into(),
                dashed: true,
                label: "truncation".into(),
            })
            .into_iter()
            .collect(),
        y_log: true,
        x_integer: true,
        width,
        height: FIG_HEIGHT,
        ..Plot::default()
    }
}

pub(super) fn figure(h: &mut String, id: &str, svg: &str, caption: &str) {
    let _ = writeln!(
        h,
        "<figure id=\"{id}\">{svg}<figcaption>{}</figcaption></figure>",
        escape(caption)
    );
}

pub(super) fn figures(h: &mut String, ctx: &Ctx<'_>) {
    let r = ctx.result();
    section(h, "figures", "Before and after (cf. paper Fig. 5 and 6)");
    // Fig. 5.
    if ctx.within.is_empty() {
        h.push_str(
            "<p id=\"fig5\">No station has two measurements: no within-station distances.</p>\n",
        );
    } else {
        let plot = fig5_plot(&ctx.within, ctx.within_of, WIDE);
        let stations = bands(ctx.within.iter().map(|p| p.station.clone())).len();
        figure(
            h,
            "fig5",
            &svg::render(&plot),
            &format!(
                "Fig. 5 (after the paper's): distances between the sphere centres of the {} pairs of measurements within each of the {stations} {} station(s); the sphere did not move, so the true value is 0 mm.",
                ctx.within.len(),
                ctx.within_of
            ),
        );
    }
    // Fig. 6.
    let distances = r
        .validation
        .as_ref()
        .map(|v| v.distances.as_slice())
        .unwrap_or_default();
    if distances.is_empty() {
        let why = if r.validation.is_some() {
            "The session has no reference distances"
        } else {
            "The session has no validate measurements"
        };
        let _ = writeln!(
            h,
            "<p id=\"fig6\" class=\"warn\">{why}: no Fig. 6 (reference-distance errors).</p>"
        );
    } else {
        let plot = fig6_plot(distances, WIDE);
        figure(
            h,
            "fig6",
            &svg::render(&plot),
            &format!(
                "Fig. 6 (after the paper's): error of each of the {} distances between validate centres against its reference distance (e.g. a laser tracker's), measured − reference.",
                distances.len()
            ),
        );
    }
    // The after series alone, each on its own scale.
    let fig6_after = (!distances.is_empty()).then(|| {
        after_only_plot(
            "Fig. 6, after only (its own scale)",
            "error (mm)",
            numbered(distances.iter().map(DistanceRecord::error_after)),
            true,
            HALF,
        )
    });
    if !ctx.within.is_empty() || fig6_after.is_some() {
        h.push_str("<div class=\"grid2\">\n");
        if !ctx.within.is_empty() {
            let plot = after_only_plot(
                "Fig. 5, after only (its own scale)",
                "centre distance (mm)",
                numbered(ctx.within.iter().map(|p| p.after)),
                false,
                HALF,
            );
            figure(
                h,
                "fig5-after",
                &svg::render(&plot),
                "Fig. 5's calibrated distances alone, on their own scale (on the before's they lie flat at zero).",
            );
        }
        if let Some(plot) = fig6_after {
            figure(
                h,
                "fig6-after",
                &svg::render(&plot),
                "Fig. 6's calibrated errors alone, on their own scale.",
            );
        }
        h.push_str("</div>\n");
    }
    // ε, and the singular values of the paper's method.
    h.push_str("<div class=\"grid2\">\n");
    let eps: Vec<f64> = r.iterations.iter().map(|i| i.epsilon).collect();
    let plot = epsilon_plot(&eps, ctx.solver().threshold(), HALF);
    figure(
        h,
        "epsilon",
        &svg::render(&plot),
        &format!(
            "ε (paper eq. 20, pooled over the identify stations) after each update: {} → {} mm.",
            num(r.epsilon_before, 4),
            num(r.epsilon_after, 4)
        ),
    );
    singular_values(h, ctx);
    h.push_str("</div>\n");
    end_section(h);
}

pub(super) fn singular_values(h: &mut String, ctx: &Ctx<'_>) {
    let paper = ctx.solver().paper();
    let values: Vec<f64> = paper
        .and_then(|p| p.singular_values.clone())
        .unwrap_or_default();
    if values.is_empty() {
        let what = if ctx.ml.is_some() {
            "The ml method has no SVD truncation: its identifiable set is listed under Identifiability."
        } else {
            "No singular values in the result (no update was made)."
        };
        let _ = writeln!(
            h,
            "<figure id=\"singular\"><p class=\"muted\">{what}</p></figure>"
        );
        return;
    }
    let kept = paper
        .and_then(|p| p.kept_directions)
        .unwrap_or(values.len());
    let zeros = values.iter().filter(|v| **v <= 0.0).count();
    let plot = singular_plot(&values, kept, paper.and_then(|p| p.svd_tolerance), HALF);
    let zero_note = if zeros > 0 {
        format!(" {zeros} singular value(s) are 0 and not drawn.")
    } else {
        String::new()
    };
    figure(
        h,
        "singular",
        &svg::render(&plot),
        &format!(
            "Singular values of the paper's method's last update (scaled): kept {kept} of {}, truncated below tolerance × σ_max.{zero_note}",
            values.len()
        ),
    );
}

/// [`heat_rgb`] as `#rrggbb`.
fn heat_hex(t: f64) -> String {
    let [r, g, b] = crate::engine::tools::report::svg::heat_rgb(t);
    format!("#{r:02x}{g:02x}{b:02x}")
}

/// The predicted error over the range as an inline SVG map: one cell per
/// grid point coloured by its σ on an absolute scale from 0 mm to the
/// verdict's tolerance (std, `tolerance_mm`) or the largest value,
/// whichever is larger ([`map_scale`], the workbench's scale), the
/// colour bar beside it with the tolerance and the largest σ marked, the
/// sphere positions outlined, the largest σ marked, the range's limits
/// on the axes.
pub(super) fn range_map_svg(
    re: &crate::engine::calibrate::solve::ml::range::RangeError,
    tolerance_mm: Option<f64>,
) -> String {
    use std::fmt::Write as _;
    if re.map.is_empty() || re.grid < 2 {
        return String::new();
    }
    let (size, pad) = (280.0_f64, 46.0_f64);
    let (lo, hi) = re
        .map
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p[2]), b.max(p[2]))
        });
    let top = map_scale(hi.max(re.max_mm), tolerance_mm.unwrap_or(f64::NAN));
    let cells = re.grid as f64;
    let (y0, y1, z0, z1) = (re.y[0], re.y[1], re.z[0], re.z[1]);
    let half_y = (y1 - y0) / (cells - 1.0) / 2.0;
    let half_z = (z1 - z0) / (cells - 1.0) / 2.0;
    let (ya, yb, za, zb) = (y0 - half_y, y1 + half_y, z0 - half_z, z1 + half_z);
    let px = |y: f64| pad + (y - ya) / (yb - ya) * size;
    // Depth up.
    let pz = |z: f64| 10.0 + (zb - z) / (zb - za) * size;
    let mut svg = String::new();
    let _ = write!(
        svg,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\" role=\"img\" aria-label=\"predicted error over the range\">",
        w = size + pad + MAP_BAR_ROOM,
        h = size + 56.0
    );
    for c in &re.map {
        let _ = write!(
            svg,
            "<rect x=\"{:.1}\" y=\"{:.1}\" width=\"{:.1}\" height=\"{:.1}\" fill=\"{}\"><title>y {:.1}, z {:.1} mm: σ {:.3} mm</title></rect>",
            px(c[0] - half_y),
            pz(c[1] + half_z),
            px(c[0] + half_y) - px(c[0] - half_y),
            pz(c[1] - half_z) - pz(c[1] + half_z),
            heat_hex(c[2] / top),
            c[0],
            c[1],
            c[2]
        );
    }
    let _ = write!(
        svg,
        "<rect x=\"{:.1}\" y=\"{:.1}\" width=\"{:.1}\" height=\"{:.1}\" fill=\"none\" stroke=\"#fff\" stroke-width=\"2\"/>",
        px(re.sphere_y[0]),
        pz(re.sphere_z[1]),
        (px(re.sphere_y[1]) - px(re.sphere_y[0])).max(2.0),
        (pz(re.sphere_z[0]) - pz(re.sphere_z[1])).max(2.0)
    );
    let (mx, mz) = (px(re.max_at[0]), pz(re.max_at[1]));
    let _ = write!(
        svg,
        "<path d=\"M{:.1} {:.1}L{:.1} {:.1}M{:.1} {:.1}L{:.1} {:.1}\" stroke=\"#fff\" stroke-width=\"2\"/>",
        mx - 5.0,
        mz - 5.0,
        mx + 5.0,
        mz + 5.0,
        mx - 5.0,
        mz + 5.0,
        mx + 5.0,
        mz - 5.0
    );
    let axis_y = size + 10.0;
    for (y, anchor) in [(y0, "start"), (y1, "end")] {
        let _ = write!(
            svg,
            "<text x=\"{:.1}\" y=\"{:.1}\" font-size=\"12\" text-anchor=\"{anchor}\">{y:.0}</text>",
            px(y),
            axis_y + 16.0
        );
    }
    let _ = write!(
        svg,
        "<text x=\"{:.1}\" y=\"{:.1}\" font-size=\"12\" text-anchor=\"middle\">y (mm, along the laser line)</text>",
        pad + size / 2.0,
        axis_y + 34.0
    );
    for (z, dy) in [(z1, 12.0), (z0, 0.0)] {
        let _ = write!(
            svg,
            "<text x=\"{:.1}\" y=\"{:.1}\" font-size=\"12\" text-anchor=\"end\">{z:.0}</text>",
            pad - 4.0,
            pz(z) + dy
        );
    }
    let _ = write!(
        svg,
        "<text x=\"12\" y=\"{:.1}\" font-size=\"12\" text-anchor=\"middle\" transform=\"rotate(-90 12 {:.1})\">z (mm, depth)</text>",
        10.0 + size / 2.0,
        10.0 + size / 2.0
    );
    let mut marks = Vec::new();
    if let Some(t) = tolerance_mm.filter(|t| t.is_finite() && *t >= 0.0) {
        marks.push(("tolerance", t));
    }
    marks.push(("max", re.max_mm));
    colour_bar_svg(
        &mut svg,
        pad + size + 14.0,
        (10.0, 10.0 + size),
        top,
        &marks,
    );
    svg.push_str("</svg>");
    let tolerance = tolerance_mm.map_or_else(String::new, |t| {
        format!(", the tolerance {} mm (std) marked on the bar", short(t))
    });
    format!(
        "<figure id=\"range-map\">{svg}<figcaption>Predicted 1σ over the range (rms over {} working poses): {lo:.3} to {hi:.3} mm; the summary's max {:.3} mm (×) is the largest at any one pose. Colours from 0 mm (green) to {} mm (red){tolerance}; white outline: where the sphere was seen.</figcaption></figure>\n",
        re.poses,
        re.max_mm,
        short(top)
    )
}

/// Room right of the map for its colour bar and labels, px.
const MAP_BAR_ROOM: f64 = 170.0;

/// Width of the map's colour bar, px.
const MAP_BAR_WIDTH: f64 = 14.0;

/// Bands the map's colour bar is drawn in.
const MAP_BAR_BANDS: usize = 48;

/// A number as the map's bar and caption give it: at most four
/// significant decimals, no trailing zeros (0.12, 0.2, 0.1125).
fn short(v: f64) -> String {
    let text = format!("{v:.4}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    if text.is_empty() || text == "-" {
        "0".to_string()
    } else {
        text.to_string()
    }
}

/// The map's colour bar at `x`, from `y.1` (0 mm) up to `y.0` (`top`
/// mm): labelled round values in mm on its right, and each of `marks`
/// (name, mm) as a dark line across it with its name and value.
fn colour_bar_svg(svg: &mut String, x: f64, y: (f64, f64), top: f64, marks: &[(&str, f64)]) {
    let (y_top, y_bottom) = y;
    let y_of = |v: f64| y_bottom - (v / top).clamp(0.0, 1.0) * (y_bottom - y_top);
    for k in 0..MAP_BAR_BANDS {
        let (a, b) = (
            top * k as f64 / MAP_BAR_BANDS as f64,
            top * (k + 1) as f64 / MAP_BAR_BANDS as f64,
        );
        let _ = write!(
            svg,
            "<rect x=\"{x:.1}\" y=\"{:.2}\" width=\"{MAP_BAR_WIDTH:.1}\" height=\"{:.2}\" fill=\"{}\"/>",
            y_of(b),
            y_of(a) - y_of(b) + 0.3,
            heat_hex(f64::midpoint(a, b) / top)
        );
    }
    let _ = write!(
        svg,
        "<rect id=\"range-map-scale\" data-top=\"{}\" x=\"{x:.1}\" y=\"{y_top:.1}\" width=\"{MAP_BAR_WIDTH:.1}\" height=\"{:.1}\" fill=\"none\" stroke=\"#444\"><title>colour scale: 0 mm (green) to {} mm (red)</title></rect>",
        short(top),
        y_bottom - y_top,
        short(top)
    );
    let ticks = crate::engine::tools::report::svg::nice_ticks(0.0, top, 4, false);
    let step = ticks.get(1).map_or(top, |t| t - ticks[0]);
    let mut values = ticks;
    if values.last().is_some_and(|last| top - last > step * 0.3) {
        values.push(top);
    }
    for v in values {
        let _ = write!(
            svg,
            "<text class=\"tick\" x=\"{:.1}\" y=\"{:.1}\" font-size=\"11\" dominant-baseline=\"middle\">{} mm</text>",
            x + MAP_BAR_WIDTH + 4.0,
            y_of(v),
            short(v)
        );
    }
    let mut placed: Vec<f64> = Vec::new();
    for (name, v) in marks {
        if !(v.is_finite() && *v >= 0.0) {
            continue;
        }
        let at = y_of(*v);
        // Two marks close together: the second one's words below.
        let dy = if placed.iter().any(|p| (p - at).abs() < 12.0) {
            12.0
        } else {
            0.0
        };
        placed.push(at);
        let _ = write!(
            svg,
            "<line class=\"mark\" x1=\"{:.1}\" y1=\"{at:.1}\" x2=\"{:.1}\" y2=\"{at:.1}\" stroke=\"#000\" stroke-width=\"2\"/><text class=\"mark\" x=\"{:.1}\" y=\"{:.1}\" font-size=\"11\" dominant-baseline=\"middle\">{name} {}</text>",
            x - 2.0,
            x + MAP_BAR_WIDTH + 2.0,
            x + MAP_BAR_WIDTH + 54.0,
            at + dy,
            short(*v)
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::calibrate::solve::ml::range::RangeError;

    /// A 3 × 3 map of σ from 0.100 to 0.112 mm (the passing cell).
    fn map() -> RangeError {
        let mut map = Vec::new();
        for (k, (y, z)) in [-20.0, 0.0, 20.0]
            .iter()
            .flat_map(|y| [-10.0, 0.0, 10.0].map(move |z| (*y, z)))
            .enumerate()
        {
            map.push([y, z, 0.100 + 0.0015 * k as f64]);
        }
        RangeError {
            y: [-20.0, 20.0],
            z: [-10.0, 10.0],
            grid: 3,
            poses: 12,
            max_mm: 0.150,
            max_at: [20.0, 10.0],
            sphere_y: [-5.0, 5.0],
            sphere_z: [-2.0, 2.0],
            map,
            ..RangeError::default()
        }
    }

    fn fills(svg: &str) -> Vec<String> {
        svg.split("<rect ")
            .filter(|r| r.contains("<title>y "))
            .filter_map(|r| r.split("fill=\"").nth(1))
            .filter_map(|r| r.split('"').next())
            .map(str::to_string)
            .collect()
    }

    /// Issue 34: the report's map ran from the smallest to the largest
    /// cell, so cells of 0.100-0.112 mm passing a 0.2 mm tolerance were
    /// green to solid red. Now the scale is the workbench's: 0 to the
    /// tolerance (or the largest value), the tolerance and the maximum
    /// marked on the bar, and the caption says so.
    #[test]
    fn the_reports_map_runs_from_zero_to_the_tolerance() {
        let svg = range_map_svg(&map(), Some(0.2));
        assert!(svg.contains("data-top=\"0.2\""), "{svg}");
        assert!(svg.contains(">tolerance 0.2</text>"), "{svg}");
        assert!(svg.contains(">max 0.15</text>"), "{svg}");
        assert!(svg.contains(">0 mm</text>") && svg.contains(">0.2 mm</text>"));
        assert!(svg.contains("Colours from 0 mm (green) to 0.2 mm (red), the tolerance 0.2 mm (std) marked on the bar"));
        let cells = fills(&svg);
        assert_eq!(cells.len(), 9);
        // 0.100 to 0.112 mm on 0 … 0.2 mm: at most half-way (yellow),
        // never the red end; the largest cell is the workbench's colour.
        let red = heat_hex(1.0);
        assert!(cells.iter().all(|c| *c != red), "{cells:?}");
        assert_eq!(cells[8], heat_hex(0.112 / 0.2));
        assert_eq!(cells[0], heat_hex(0.5));
    }

    /// Beyond the tolerance the largest value sets the top (a round
    /// number at or above it); without a tolerance only the maximum is
    /// marked.
    #[test]
    fn the_largest_value_sets_the_top_beyond_the_tolerance() {
        let mut re = map();
        re.max_mm = 0.7;
        let svg = range_map_svg(&re, Some(0.5));
        assert!(svg.contains("data-top=\"0.8\""), "{svg}");
        assert!(svg.contains(">tolerance 0.5</text>") && svg.contains(">max 0.7</text>"));
        let svg = range_map_svg(&map(), None);
        assert!(svg.contains("data-top=\"0.15\""), "{svg}");
        assert!(!svg.contains("tolerance"), "{svg}");
        assert!(svg.contains(">max 0.15</text>"));
        assert!(svg.contains("to 0.15 mm (red); white outline"));
    }
}
