//! Small hand-written SVG plots for the HTML report
//! ([`crate::engine::tools::report::html`]): markers and lines on linear or log axes, with
//! ticks, axis labels (units in the label), a legend, horizontal rules
//! (a threshold, zero) and labelled x bands (stations). No plotting crate:
//! a report needs a few scatter plots, and inline SVG renders in every
//! browser and prints sharp.
//!
//! Everything drawn is in SVG user units (CSS pixels at 100 %); the root
//! has a `viewBox`, so a style sheet may scale it to the page width.

use std::fmt::Write as _;

use crate::engine::base::numeric::step_125_at_least;

/// Room left of the plot area for the y tick labels and the y label, px.
const MARGIN_LEFT: f64 = 64.0;
/// Room right of the plot area, px.
const MARGIN_RIGHT: f64 = 14.0;
/// Room above the plot area for the legend, px.
const MARGIN_TOP: f64 = 28.0;
/// Room below the plot area for the x tick labels and the x label, px.
const MARGIN_BOTTOM: f64 = 42.0;
/// Marker half-size, px.
const MARKER: f64 = 3.0;
/// About this many ticks on an axis.
const TICKS: usize = 6;
/// Grey of the axes, grid, rules and band labels.
pub const MUTED: &str = "#969696";
/// Average width of one character of the 11 px sans-serif labels, px
/// (to decide whether a band label fits).
const CHAR_WIDTH: f64 = 6.5;

/// How the points of a series are marked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Marker {
    /// No marker (a line only).
    None,
    /// A filled square.
    Square,
    /// A filled circle.
    Circle,
    /// An × (for discarded values).
    Cross,
}

/// One data series.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend text.
    pub name: String,
    /// CSS colour, e.g. `#2896e6`.
    pub colour: String,
    /// `[x, y]` in data units. On a log axis, points with `y ≤ 0` are left out.
    pub points: Vec<[f64; 2]>,
    /// Marker shape.
    pub marker: Marker,
    /// Join the points with a line.
    pub line: bool,
}

/// A horizontal line across the plot at `y` (data units).
#[derive(Debug, Clone, PartialEq)]
pub struct Rule {
    /// Height, data units.
    pub y: f64,
    /// CSS colour.
    pub colour: String,
    /// Dashed rather than solid.
    pub dashed: bool,
    /// Legend text; empty for none.
    pub label: String,
}

/// A labelled x interval `[from, to]` (data units): a dotted separator is
/// drawn at each inner boundary and the label at the top of the band.
#[derive(Debug, Clone, PartialEq)]
pub struct Band {
    /// Left end, data units.
    pub from: f64,
    /// Right end, data units.
    pub to: f64,
    /// Label (plain text; escaped on drawing).
    pub label: String,
}

/// A scatter/line plot.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Plot {
    /// Accessible title (the SVG `<title>`).
    pub title: String,
    /// x axis label, with its unit.
    pub x_label: String,
    /// y axis label, with its unit.
    pub y_label: String,
    /// The data.
    pub series: Vec<Series>,
    /// Horizontal rules.
    pub rules: Vec<Rule>,
    /// Labelled x bands.
    pub bands: Vec<Band>,
    /// Logarithmic y axis (base 10).
    pub y_log: bool,
    /// Keep `y = 0` in view (linear axis only).
    pub include_zero: bool,
    /// Ticks on the x axis at integers only.
    pub x_integer: bool,
    /// Width, px.
    pub width: f64,
    /// Height, px.
    pub height: f64,
}

/// A colour scale for a map, `t` in 0..1: green (low) through yellow to
/// red (high), as RGB. The HTML report's and the workbench's range maps
/// both use it.
#[must_use]
pub fn heat_rgb(t: f64) -> [u8; 3] {
    let t = t.clamp(0.0, 1.0);
    let (low, mid, high) = (
        [60.0, 170.0, 90.0],
        [230.0, 200.0, 60.0],
        [225.0, 60.0, 60.0],
    );
    let (a, b, f): ([f64; 3], [f64; 3], f64) = if t < 0.5 {
        (low, mid, t * 2.0)
    } else {
        (mid, high, t * 2.0 - 1.0)
    };
    std::array::from_fn(|k| (a[k] + (b[k] - a[k]) * f).round() as u8)
}

/// The ends of a map colour scale's top: 1, 1.2, 1.5, 2, 2.5, 3, 4, 5, 6,
/// 8 times a power of ten (a round number just above the largest cell).
const SCALE_STEPS: [f64; 10] = [1.0, 1.2, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0];

/// The top of a map's colour scale for cells up to `largest` mm: the
/// smallest round number (`SCALE_STEPS`) at or above it; 0 mm is the
/// bottom, 1 mm when `largest` is not a positive number.
#[must_use]
pub fn scale_top(largest: f64) -> f64 {
    if !(largest.is_finite() && largest > 0.0) {
        return 1.0;
    }
    let decade = 10f64.powf(largest.log10().floor());
    SCALE_STEPS
        .iter()
        .chain(std::iter::once(&10.0))
        .map(|m| m * decade)
        .find(|v| *v >= largest * (1.0 - 1e-12))
        .unwrap_or(10.0 * decade)
}

/// The top of the predicted-error map's colour scale (the report's and
/// the workbench's): a round number ([`scale_top`]) at or above the
/// largest value and the verdict's tolerance (std, mm), whichever is
/// larger, so that a cell within the tolerance is never red. A tolerance
/// that is not a finite number is ignored.
#[must_use]
pub fn map_scale(largest: f64, tolerance_mm: f64) -> f64 {
    let tolerance = if tolerance_mm.is_finite() {
        tolerance_mm
    } else {
        0.0
    };
    scale_top(largest.max(tolerance))
}

/// Escapes text for XML: HTML and SVG content and attribute values, the
/// URDF export's attributes (the one XML escape of the crate).
#[must_use]
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            // Control characters (NUL, a line feed inside a name) and the
            // bidirectional overrides (U+202A-U+202E, U+2066-U+2069: text
            // that reads backwards) are shown as their code, not obeyed.
            c if (c.is_control() && c != '\n' && c != '\t')
                || ('\u{202a}'..='\u{202e}').contains(&c)
                || ('\u{2066}'..='\u{2069}').contains(&c) =>
            {
                out.push_str(&format!("[U+{:04X}]", u32::from(c)));
            }
            c => out.push(c),
        }
    }
    out
}

/// "Nice" ticks (steps of 1, 2 or 5 times a power of ten) covering
/// `[lo, hi]`, about `target` of them; `integer` keeps the step at least 1.
#[must_use]
pub fn nice_ticks(lo: f64, hi: f64, target: usize, integer: bool) -> Vec<f64> {
    if !(lo.is_finite() && hi.is_finite()) || hi < lo {
        return Vec::new();
    }
    let span = (hi - lo).max(f64::EPSILON * hi.abs().max(1.0));
    let raw = span / target.max(1) as f64;
    let mut step = step_125_at_least(raw);
    if integer {
        step = step.max(1.0).round();
    }
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    (first..=last).map(|k| k as f64 * step).collect()
}

/// Ticks of a log axis over `[lo, hi]` (log10 units): decades (every
/// k-th one when many show, at most about [`TICKS`]), and 2 and 5 within
/// each decade when fewer than three decades show.
fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let (a, b) = (lo.floor() as i64, hi.ceil() as i64);
    let few = hi - lo < 2.5;
    let every = ((b - a) as f64 / TICKS as f64).ceil().max(1.0) as i64;
    let mut out = Vec::new();
    for e in (a..=b).filter(|e| e.rem_euclid(every) == 0) {
        for m in if few {
            &crate::engine::base::numeric::STEPS_125[..]
        } else {
            &[1.0][..]
        } {
            let t = (m * 10f64.powi(e as i32)).log10();
            if t >= lo - 1e-9 && t <= hi + 1e-9 {
                out.push(t);
            }
        }
    }
    out
}

/// A tick label: `v` with as many decimals as the step needs.
fn tick_label(v: f64, step: f64) -> String {
    let decimals = if step > 0.0 && step < 1.0 {
        (-step.log10().floor()) as usize
    } else {
        0
    };
    let v = if v.abs() < step * 1e-9 { 0.0 } else { v };
    format!("{v:.decimals$}")
}

/// A log tick label: `10^t` written out (0.01, 0.2, 5, 100), or as
/// `1e-6` beyond 0.001 and 10000.
fn log_tick_label(t: f64) -> String {
    let v = 10f64.powf(t);
    if !(-3.5..4.5).contains(&t) {
        return format!("1e{}", t.round());
    }
    let decimals = if v < 1.0 {
        (-(v.log10().floor())) as usize
    } else {
        0
    };
    format!("{v:.decimals$}")
}

/// The range `[lo, hi]` of `values`, padded by 5 % (or to a unit span
/// when all are equal).
fn padded(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold(None, |acc: Option<(f64, f64)>, v| match acc {
            None => Some((v, v)),
            Some((a, b)) => Some((a.min(v), b.max(v))),
        })?;
    if hi - lo <= f64::EPSILON * hi.abs().max(1.0) {
        return Some((lo - 0.5, hi + 0.5));
    }
    let pad = 0.05 * (hi - lo);
    Some((lo - pad, hi + pad))
}

/// The plot area (SVG px) and the data ranges it shows (x, and y in the
/// plotted scale: `log10` on a log axis).
struct Frame {
    left: f64,
    right: f64,
    top: f64,
    bottom: f64,
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
    y_log: bool,
}

impl Frame {
    /// The plot area of `plot` and the padded ranges of its data (with
    /// zero when asked, room above for band labels).
    fn of(plot: &Plot) -> Self {
        let (w, h) = (plot.width, plot.height);
        let to_y = |v: f64| plotted_y(plot.y_log, v);
        let xs = plot
            .series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p[0]))
            .chain(plot.bands.iter().flat_map(|b| [b.from, b.to]));
        let ys = plot
            .series
            .iter()
            .flat_map(|s| s.points.iter().filter_map(|p| to_y(p[1])))
            .chain(plot.rules.iter().filter_map(|r| to_y(r.y)))
            .chain((plot.include_zero && !plot.y_log).then_some(0.0));
        let (x0, x1) = padded(xs).unwrap_or((0.0, 1.0));
        let (mut y0, mut y1) = padded(ys).unwrap_or((0.0, 1.0));
        if plot.include_zero && !plot.y_log && y0 > -1e-12 {
            y0 = 0.0;
        }
        if !plot.bands.is_empty() {
            // Room for the band labels above the data.
            y1 += 0.08 * (y1 - y0);
        }
        Self {
            left: MARGIN_LEFT,
            right: w - MARGIN_RIGHT,
            top: MARGIN_TOP,
            bottom: h - MARGIN_BOTTOM,
            x0,
            x1,
            y0,
            y1,
            y_log: plot.y_log,
        }
    }

    /// A data value on the plotted y scale; `None` for a non-positive
    /// value on a log axis.
    fn to_y(&self, v: f64) -> Option<f64> {
        plotted_y(self.y_log, v)
    }

    /// SVG x (px) of the data x.
    fn px(&self, x: f64) -> f64 {
        self.left + (x - self.x0) / (self.x1 - self.x0) * (self.right - self.left)
    }

    /// SVG y (px) of the plotted y.
    fn py(&self, y: f64) -> f64 {
        self.bottom - (y - self.y0) / (self.y1 - self.y0) * (self.bottom - self.top)
    }
}

/// A data value on the plotted y scale (`log10` on a log axis, where a
/// non-positive value has none).
fn plotted_y(y_log: bool, v: f64) -> Option<f64> {
    if y_log {
        (v > 0.0).then(|| v.log10())
    } else {
        Some(v)
    }
}

/// The plot as an `<svg>` element (no XML prolog, no namespace needed
/// inside HTML).
#[must_use]
pub fn render(plot: &Plot) -> String {
    let (w, h) = (plot.width, plot.height);
    let f = Frame::of(plot);
    let mut s = String::new();
    let _ = write!(
        s,
        r#"<svg class="plot" viewBox="0 0 {w:.0} {h:.0}" width="{w:.0}" height="{h:.0}" role="img" font-family="sans-serif" font-size="11"><title>{}</title>"#,
        escape(&plot.title)
    );
    write_axes(&mut s, plot, &f);
    write_bands(&mut s, plot, &f);
    // Rules, then the data.
    write_rules(&mut s, plot, &f);
    for series in &plot.series {
        write_series(&mut s, series, &f);
    }
    write_legend(&mut s, plot, &f);
    s.push_str("</svg>");
    s
}

/// The frame, the grid with its tick labels, and the axis labels.
fn write_axes(s: &mut String, plot: &Plot, f: &Frame) {
    let (left, right, top, bottom) = (f.left, f.right, f.top, f.bottom);
    let _ = write!(
        s,
        r#"<rect x="{left:.1}" y="{top:.1}" width="{:.1}" height="{:.1}" fill="none" stroke="{MUTED}"/>"#,
        right - left,
        bottom - top
    );
    let x_ticks = nice_ticks(f.x0, f.x1, TICKS + 2, plot.x_integer);
    let x_step = x_ticks
        .get(1)
        .zip(x_ticks.first())
        .map_or(1.0, |(b, a)| b - a);
    for t in &x_ticks {
        let x = f.px(*t);
        let _ = write!(
            s,
            r#"<line x1="{x:.1}" y1="{bottom:.1}" x2="{x:.1}" y2="{:.1}" stroke="{MUTED}"/><text x="{x:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
            bottom + 4.0,
            bottom + 16.0,
            tick_label(*t, x_step)
        );
    }
    let (y_ticks, y_step) = if plot.y_log {
        (log_ticks(f.y0, f.y1), 0.0)
    } else {
        let t = nice_ticks(f.y0, f.y1, TICKS, false);
        let step = t.get(1).zip(t.first()).map_or(1.0, |(b, a)| b - a);
        (t, step)
    };
    for t in &y_ticks {
        let y = f.py(*t);
        let label = if plot.y_log {
            log_tick_label(*t)
        } else {
            tick_label(*t, y_step)
        };
        let _ = write!(
            s,
            r##"<line x1="{left:.1}" y1="{y:.1}" x2="{right:.1}" y2="{y:.1}" stroke="#e4e4e4"/><text x="{:.1}" y="{:.1}" text-anchor="end">{label}</text>"##,
            left - 5.0,
            y + 4.0
        );
    }
    let _ = write!(
        s,
        r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">{}</text><text transform="translate(14 {:.1}) rotate(-90)" text-anchor="middle">{}</text>"#,
        f64::midpoint(left, right),
        plot.height - 6.0,
        escape(&plot.x_label),
        f64::midpoint(top, bottom),
        escape(&plot.y_label)
    );
}

/// The bands' separators and, where they fit, their labels.
fn write_bands(s: &mut String, plot: &Plot, f: &Frame) {
    let (top, bottom) = (f.top, f.bottom);
    for (k, b) in plot.bands.iter().enumerate() {
        if k > 0 {
            let x = f.px(b.from);
            let _ = write!(
                s,
                r#"<line x1="{x:.1}" y1="{top:.1}" x2="{x:.1}" y2="{bottom:.1}" stroke="{MUTED}" stroke-dasharray="2 2"/>"#
            );
        }
        let width = f.px(b.to) - f.px(b.from);
        if width >= CHAR_WIDTH * b.label.chars().count() as f64 {
            let _ = write!(
                s,
                r#"<text x="{:.1}" y="{:.1}" text-anchor="middle" fill="{MUTED}">{}</text>"#,
                f.px(f64::midpoint(b.from, b.to)),
                top + 13.0,
                escape(&b.label)
            );
        }
    }
}

/// The horizontal rules across the plot area.
fn write_rules(s: &mut String, plot: &Plot, f: &Frame) {
    let (left, right) = (f.left, f.right);
    for r in &plot.rules {
        if let Some(v) = f.to_y(r.y) {
            let y = f.py(v);
            let dash = if r.dashed {
                r#" stroke-dasharray="6 4""#
            } else {
                ""
            };
            let _ = write!(
                s,
                r#"<line x1="{left:.1}" y1="{y:.1}" x2="{right:.1}" y2="{y:.1}" stroke="{}" stroke-width="1.2"{dash}/>"#,
                escape(&r.colour)
            );
        }
    }
}

/// One series: its line (when drawn) and its markers.
fn write_series(s: &mut String, series: &Series, f: &Frame) {
    let pts: Vec<(f64, f64)> = series
        .points
        .iter()
        .filter_map(|p| f.to_y(p[1]).map(|y| (f.px(p[0]), f.py(y))))
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .collect();
    let colour = escape(&series.colour);
    if series.line && pts.len() > 1 {
        let mut line = String::new();
        for (x, y) in &pts {
            let _ = write!(line, "{x:.1},{y:.1} ");
        }
        let _ = write!(
            s,
            r#"<polyline points="{}" fill="none" stroke="{colour}" stroke-width="1.2"/>"#,
            line.trim_end()
        );
    }
    let d = marker_path(series.marker, &pts);
    if !d.is_empty() {
        let paint = if series.marker == Marker::Cross {
            format!(r#"fill="none" stroke="{colour}" stroke-width="1.5""#)
        } else {
            format!(r#"fill="{colour}""#)
        };
        let _ = write!(s, r#"<path d="{d}" {paint}/>"#);
    }
}

/// The SVG path data of `marker` at each of `pts` (px); empty for none.
fn marker_path(marker: Marker, pts: &[(f64, f64)]) -> String {
    let mut d = String::new();
    let m = MARKER;
    for (x, y) in pts {
        let _ = match marker {
            Marker::None => Ok(()),
            Marker::Square => write!(
                d,
                "M{:.1} {:.1}h{:.0}v{:.0}h-{:.0}z",
                x - m,
                y - m,
                2.0 * m,
                2.0 * m,
                2.0 * m
            ),
            Marker::Circle => write!(
                d,
                "M{:.1} {y:.1}a{m} {m} 0 1 0 {:.0} 0a{m} {m} 0 1 0 -{:.0} 0z",
                x - m,
                2.0 * m,
                2.0 * m
            ),
            Marker::Cross => write!(
                d,
                "M{:.1} {:.1}l{:.0} {:.0}m0 -{:.0}l-{:.0} {:.0}",
                x - m,
                y - m,
                2.0 * m,
                2.0 * m,
                2.0 * m,
                2.0 * m,
                2.0 * m
            ),
        };
    }
    d
}

/// The legend, in a row above the plot area: the named series, then the
/// labelled rules.
fn write_legend(s: &mut String, plot: &Plot, f: &Frame) {
    let mut x = f.left;
    let entries = plot
        .series
        .iter()
        .filter(|s| !s.name.is_empty())
        .map(|s| (&s.name, &s.colour, Some(s.marker), false))
        .chain(
            plot.rules
                .iter()
                .filter(|r| !r.label.is_empty())
                .map(|r| (&r.label, &r.colour, None, r.dashed)),
        );
    for (name, colour, marker, dashed) in entries {
        let colour = escape(colour);
        let y = f.top - 10.0;
        match marker {
            Some(Marker::Circle) => {
                let _ = write!(
                    s,
                    r#"<circle cx="{:.1}" cy="{y:.1}" r="{MARKER}" fill="{colour}"/>"#,
                    x + 8.0
                );
            }
            Some(Marker::Square) => {
                let _ = write!(
                    s,
                    r#"<rect x="{:.1}" y="{:.1}" width="6" height="6" fill="{colour}"/>"#,
                    x + 5.0,
                    y - 3.0
                );
            }
            Some(Marker::Cross) => {
                let _ = write!(
                    s,
                    r#"<path d="M{:.1} {:.1}l6 6m0 -6l-6 6" fill="none" stroke="{colour}" stroke-width="1.5"/>"#,
                    x + 5.0,
                    y - 3.0
                );
            }
            _ => {
                let dash = if dashed {
                    r#" stroke-dasharray="4 3""#
                } else {
                    ""
                };
                let _ = write!(
                    s,
                    r#"<line x1="{x:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="{colour}" stroke-width="2"{dash}/>"#,
                    x + 16.0
                );
            }
        }
        let _ = write!(
            s,
            r#"<text x="{:.1}" y="{:.1}">{}</text>"#,
            x + 20.0,
            y + 4.0,
            escape(name)
        );
        x += 20.0 + CHAR_WIDTH * name.chars().count() as f64 + 18.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_session_name_with_nul_or_a_bidi_override_is_shown_not_obeyed() {
        assert_eq!(escape("a<b>&\"'"), "a&lt;b&gt;&amp;&quot;&#39;");
        assert_eq!(escape("cell\u{0}1"), "cell[U+0000]1");
        assert_eq!(escape("abc\u{202e}fed"), "abc[U+202E]fed");
        assert_eq!(escape("x\u{2066}y"), "x[U+2066]y");
        assert_eq!(escape("two\nlines\tkept"), "two\nlines\tkept");
    }

    #[test]
    fn ticks_are_nice_and_cover_the_range() {
        let labels: Vec<String> = nice_ticks(0.0, 1.0, 5, false)
            .into_iter()
            .map(|t| tick_label(t, 0.2))
            .collect();
        assert_eq!(labels, ["0.0", "0.2", "0.4", "0.6", "0.8", "1.0"]);
        let t = nice_ticks(0.3, 151.0, 8, true);
        assert_eq!(t.first(), Some(&20.0));
        assert!(t.windows(2).all(|w| (w[1] - w[0] - 20.0).abs() < 1e-9));
        assert_eq!(nice_ticks(1.0, 3.0, 8, true), vec![1.0, 2.0, 3.0]);
        assert!(nice_ticks(f64::NAN, 1.0, 5, false).is_empty());
    }

    #[test]
    fn log_ticks_and_labels() {
        // 0.1 mm .. 10 mm: two decades, so 1-2-5 ticks.
        let t: Vec<String> = log_ticks(-1.0, 1.0)
            .into_iter()
            .map(log_tick_label)
            .collect();
        assert_eq!(t, vec!["0.1", "0.2", "0.5", "1", "2", "5", "10"]);
        // 1e-16 .. 10: every fourth decade, written as powers.
        let t: Vec<String> = log_ticks(-16.2, 1.1)
            .into_iter()
            .map(log_tick_label)
            .collect();
        assert_eq!(t, vec!["1e-16", "1e-12", "1e-8", "1e-4", "1"]);
        assert_eq!(tick_label(0.30000000000000004, 0.1), "0.3");
        assert_eq!(tick_label(-1e-17, 0.1), "0.0");
    }

    #[test]
    fn renders_escaped_series_rules_and_bands() {
        let plot = Plot {
            title: "a <b>".into(),
            x_label: "pair".into(),
            y_label: "distance (mm)".into(),
            series: vec![Series {
                name: "after & done".into(),
                colour: "#2896e6".into(),
                points: vec![[1.0, 0.5], [2.0, 0.25], [3.0, -1.0]],
                marker: Marker::Circle,
                line: true,
            }],
            rules: vec![Rule {
                y: 0.3,
                colour: "#e67828".into(),
                dashed: true,
                label: "threshold".into(),
            }],
            bands: vec![
                Band {
                    from: 0.5,
                    to: 2.5,
                    label: "P<1>".into(),
                },
                Band {
                    from: 2.5,
                    to: 3.5,
                    label: "P2".into(),
                },
            ],
            y_log: true,
            include_zero: false,
            x_integer: true,
            width: 600.0,
            height: 300.0,
        };
        let svg = render(&plot);
        assert!(svg.starts_with("<svg") && svg.ends_with("</svg>"));
        assert!(svg.contains("<title>a &lt;b&gt;</title>"));
        assert!(svg.contains("after &amp; done") && svg.contains("P&lt;1&gt;"));
        assert!(!svg.contains("<b>") && !svg.contains("P<1>"));
        // The negative point is left out on the log axis: two circles.
        assert_eq!(svg.matches("a3 3 0 1 0 6 0a").count(), 2);
        assert!(svg.contains("<polyline") && svg.contains("stroke-dasharray=\"6 4\""));
        assert!(!svg.contains("NaN") && !svg.contains("inf"));
    }
}
