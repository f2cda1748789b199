//! The plots of a result on one sheet, for print: a title, the headline,
//! the paper's Fig. 5 and 6 (full width), ε per update and the singular
//! values (side by side), each with its heading, drawn by the report's
//! [`svg`] plots on a white page. The workbench's "Plots PNG" rasterises
//! it; nothing here depends on a window, so the sheet is whole whatever
//! part of the Results view is on screen.

use std::fmt::Write as _;

use super::html::figures::{HALF, WIDE, epsilon_plot, fig5_plot, fig6_plot, singular_plot};
use super::svg::{self, escape};
use crate::engine::calibrate::validate::DistanceRecord;
use crate::engine::tools::result_view::PairDistance;

/// White space around the sheet's content, px.
pub const SHEET_MARGIN: f64 = 24.0;
/// Room for a figure's heading above it, px.
const HEADING: f64 = 26.0;
/// Gap between two figures side by side, px.
const GUTTER: f64 = WIDE - 2.0 * HALF;
/// Height of a line under the title, px.
const LINE: f64 = 20.0;
/// Height of a line of text where a figure has no data, px.
const NOTE: f64 = 30.0;

/// What the sheet shows of a result.
#[derive(Debug, Clone, Copy)]
pub struct SheetInput<'a> {
    /// First line, e.g. the session and the method.
    pub title: &'a str,
    /// Lines under the title, e.g. the validation std and max before and
    /// after (plain text; keep each under about 130 characters).
    pub lines: &'a [String],
    /// Within-station centre distances (Fig. 5).
    pub within: &'a [PairDistance],
    /// Which stations `within` is of ("validate", "identify").
    pub within_of: &'a str,
    /// Reference-distance errors (Fig. 6).
    pub distances: &'a [DistanceRecord],
    /// ε after 0, 1, … updates, mm.
    pub epsilons: &'a [f64],
    /// The threshold on ε, mm.
    pub threshold: Option<f64>,
    /// Singular values of the last update (paper's method), descending.
    pub singular_values: &'a [f64],
    /// Directions kept (the rest were dropped).
    pub kept: Option<usize>,
    /// SVD tolerance, a fraction of σ_max.
    pub svd_tolerance: Option<f64>,
}

/// A whole SVG document and its size, px.
#[derive(Debug, Clone, PartialEq)]
pub struct Sheet {
    /// The document (with its namespace), white background.
    pub svg: String,
    /// Width, px.
    pub width: f64,
    /// Height, px.
    pub height: f64,
}

/// Lays the figures of `input` out on one white sheet.
#[must_use]
pub fn plots_sheet(input: &SheetInput<'_>) -> Sheet {
    let width = WIDE + 2.0 * SHEET_MARGIN;
    let mut body = String::new();
    let mut y = SHEET_MARGIN;
    let _ = write!(
        body,
        r#"<text x="{SHEET_MARGIN}" y="{:.1}" font-size="16" font-weight="bold">{}</text>"#,
        y + 14.0,
        escape(input.title)
    );
    y += 24.0;
    for line in input.lines {
        let _ = write!(
            body,
            r#"<text x="{SHEET_MARGIN}" y="{:.1}" font-size="13">{}</text>"#,
            y + 12.0,
            escape(line)
        );
        y += LINE;
    }
    y += 8.0;
    let place = |body: &mut String, x: f64, y: f64, heading: &str, plot: Option<svg::Plot>| {
        let _ = write!(
            body,
            r#"<text x="{x:.1}" y="{:.1}" font-size="13" font-weight="bold">{}</text>"#,
            y + 16.0,
            escape(heading)
        );
        match plot {
            Some(p) => {
                let _ = write!(
                    body,
                    r#"<g transform="translate({x:.1} {:.1})">{}</g>"#,
                    y + HEADING,
                    svg::render(&p)
                );
                HEADING + p.height
            }
            None => HEADING + NOTE,
        }
    };
    let fig5 = (!input.within.is_empty()).then(|| fig5_plot(input.within, input.within_of, WIDE));
    let heading = if fig5.is_some() {
        format!(
            "Centre distances within {} stations, per pair (cf. paper Fig. 5)",
            input.within_of
        )
    } else {
        "Fig. 5: no station has two measurements".to_string()
    };
    y += place(&mut body, SHEET_MARGIN, y, &heading, fig5) + 12.0;
    let fig6 = (!input.distances.is_empty()).then(|| fig6_plot(input.distances, WIDE));
    let heading = if fig6.is_some() {
        "Reference-distance errors, measured − reference (cf. paper Fig. 6)"
    } else {
        "Fig. 6: no reference distances in this session"
    };
    y += place(&mut body, SHEET_MARGIN, y, heading, fig6) + 12.0;
    let eps = place(
        &mut body,
        SHEET_MARGIN,
        y,
        "ε per update (paper eq. 20)",
        Some(epsilon_plot(input.epsilons, input.threshold, HALF)),
    );
    let singular = if input.singular_values.iter().any(|v| *v > 0.0) {
        place(
            &mut body,
            SHEET_MARGIN + HALF + GUTTER,
            y,
            "Singular values of the last update",
            Some(singular_plot(
                input.singular_values,
                input.kept.unwrap_or(input.singular_values.len()),
                input.svd_tolerance,
                HALF,
            )),
        )
    } else {
        0.0
    };
    y += eps.max(singular) + SHEET_MARGIN;
    let height = y.ceil();
    let mut s = String::with_capacity(body.len() + 400);
    let _ = write!(
        s,
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0}" height="{height:.0}" viewBox="0 0 {width:.0} {height:.0}" font-family="sans-serif" fill="#000"><rect width="{width:.0}" height="{height:.0}" fill="#fff"/>"##
    );
    s.push_str(&body);
    s.push_str("</svg>");
    Sheet {
        svg: s,
        width,
        height,
    }
}

#[cfg(test)]
mod tests {
    use super::super::html::figures::FIG_HEIGHT;
    use super::*;

    #[test]
    fn the_sheet_is_white_whole_and_escaped() {
        let within: Vec<PairDistance> = (0..6)
            .map(|k| PairDistance {
                station: format!("V{}", k / 2),
                ids: (format!("m{k}a"), format!("m{k}b")),
                before: 1.0 + f64::from(k),
                after: 0.05,
            })
            .collect();
        let sheet = plots_sheet(&SheetInput {
            title: "cell <3>",
            lines: &["std 6.3 mm before, 0.08 mm after".to_string()],
            within: &within,
            within_of: "validate",
            distances: &[],
            epsilons: &[9.8, 0.14],
            threshold: Some(0.15),
            singular_values: &[],
            kept: None,
            svd_tolerance: None,
        });
        assert!(
            sheet
                .svg
                .starts_with("<svg xmlns=\"http://www.w3.org/2000/svg\"")
        );
        assert!(sheet.svg.contains(r##"fill="#fff""##));
        assert!(sheet.svg.contains("cell &lt;3&gt;"));
        assert!(sheet.svg.contains("no reference distances"));
        // Title, headline, Fig. 5 (+ heading), Fig. 6's note, ε (+ heading).
        let expected = 2.0 * SHEET_MARGIN
            + 24.0
            + LINE
            + 8.0
            + (HEADING + FIG_HEIGHT + 12.0)
            + (HEADING + NOTE + 12.0)
            + (HEADING + FIG_HEIGHT);
        assert!(
            (sheet.height - expected.ceil()).abs() < 1e-9,
            "{}",
            sheet.height
        );
        assert_eq!(sheet.svg.matches("<svg").count(), 3);
    }
}
