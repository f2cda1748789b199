//! The report's tables: identifiability, hand-eye, joint errors (the
//! paper's Table 1), validation, outliers, measurements and the solver
//! block.

use std::fmt::Write as _;

use serde_json::Value;

use super::text::{scalar_text, short_number};
use super::*;
use crate::engine::base::geometry::{rows_from_isometry, wrap_deg};
use crate::engine::base::robot::PARAM_NAMES;
use crate::engine::base::session::Observation;
use crate::engine::calibrate::solve::estimate::HAND_EYE_LABELS;
use crate::engine::calibrate::validate::Stats;
use crate::engine::files::format::result::solver_block as solver_map;
use crate::engine::tools::report::svg::escape;
use crate::engine::tools::result_view::{HandEyeView, PairDistance, hand_eye_only_lines};

pub(super) fn list(h: &mut String, id: &str, items: &[String]) {
    let _ = writeln!(h, "<ul id=\"{id}\">");
    for i in items {
        let _ = writeln!(h, "<li>{}</li>", escape(i));
    }
    h.push_str("</ul>\n");
}

pub(super) fn identifiability(h: &mut String, ctx: &Ctx<'_>) {
    section(h, "identifiability", "Identifiability");
    let r = ctx.result();
    if let Some(ml) = &ctx.ml {
        let _ = writeln!(
            h,
            "<p>The <strong>ml</strong> method estimated {} of {} parameters from {} identify measurements at {} stations (pivoted QR, relative tolerance {}); it held {} fixed at their start because centre distances cannot see them:</p>",
            ml.estimated.len(),
            ml.estimated.len() + ml.fixed.len(),
            ml.measurements,
            ml.stations,
            short_number(ml.identifiability.tolerance),
            ml.fixed.len()
        );
        let _ = writeln!(
            h,
            "<p class=\"mono\" id=\"fixed\">fixed: {}</p>",
            escape(&if ml.fixed.is_empty() {
                "none".to_string()
            } else {
                ml.fixed.join(", ")
            })
        );
        if !ml.inseparable.is_empty() {
            h.push_str("<h3>Combinations the data cannot separate</h3>\n");
            let sentences: Vec<String> = ml.inseparable.iter().map(ToString::to_string).collect();
            list(h, "inseparable", &sentences);
        }
        if !ml.strong_correlations.is_empty() {
            h.push_str("<h3>Strongly correlated estimates (|ρ| ≥ 0.95)</h3>\n");
            list(h, "correlations", &ml.strong_correlations);
        }
        h.push_str("<h3>Uncertainty</h3>\n<ul>\n");
        let _ = writeln!(
            h,
            "<li>variance factor {} (≈ 1 when the noise model fits). The ± 1σ of the tables are a posteriori: the covariance as written (a priori, from the noise model) times the variance factor, σ × {}; hover a value for its a priori σ. The file's covariance is as written.</li>",
            num(ml.variance_factor, 3),
            num(
                crate::engine::base::numeric::sigma_of_variance(ml.variance_factor),
                3
            )
        );
        if let Some(v) = &ml.predicted_distance_std_validate {
            let _ = writeln!(
                h,
                "<li>predicted σ of the {} validate distances: mean {} mm, max {} mm; expected validation std {} mm{}</li>",
                v.pairs,
                num(v.mean, 4),
                num(v.max, 4),
                num(v.centred, 4),
                r.validation
                    .as_ref()
                    .filter(|x| !x.distances.is_empty())
                    .map(|x| format!(" (measured: {} mm)", num(x.after.std, 4)))
                    .unwrap_or_default()
            );
        }
        if let Some(v) = &ml.volume_error {
            let _ = writeln!(h, "<li id=\"volume-error\">{}</li>", escape(&v.summary()));
        }
        let p = &ml.predicted_distance_std_identify;
        let _ = writeln!(
            h,
            "<li>predicted σ of distances across the identify volume ({} pose pairs): mean {} mm, max {} mm</li>",
            p.pairs,
            num(p.mean, 4),
            num(p.max, 4)
        );
        if let Some(cv) = &ml.cross_validation {
            let _ = writeln!(
                h,
                "<li>leave-one-station-out cross-validation: within-station distance RMS {} mm over {} station(s)</li>",
                num(cv.rms, 4),
                cv.stations.len()
            );
        }
        if let Some(re) = &ml.range_error {
            let _ = writeln!(
                h,
                "<li id=\"range-error\">{} ({} × {} grid at {} working poses, after the best rigid alignment)</li>",
                escape(&re.summary()),
                re.grid,
                re.grid,
                re.poses
            );
        }
        h.push_str("</ul>\n");
        if let Some(w) = ml.range_error.as_ref().and_then(|re| re.warning.as_ref()) {
            let _ = writeln!(
                h,
                "<p class=\"warn\" id=\"range-warning\">{}</p>",
                escape(w)
            );
        }
        if let Some(re) = &ml.range_error {
            h.push_str(&super::figures::range_map_svg(
                re,
                ctx.input.tolerance.map(|t| t.std_mm),
            ));
        }
        h.push_str("<p class=\"muted\">σ of every estimated parameter: in the hand-eye and joint-error tables below (± values).</p>\n");
    } else {
        let paper = ctx.solver().paper();
        let unknowns = paper.and_then(|p| p.unknowns.as_ref()).map_or(0, Vec::len);
        match paper.and_then(|p| p.kept_directions) {
            Some(k) => {
                let _ = writeln!(
                    h,
                    "<p>The <strong>{}</strong> method kept {k} of {unknowns} SVD directions in its last update (relative tolerance {}); the others are not identifiable from this data and were not moved:</p>",
                    escape(&ctx.method),
                    paper
                        .and_then(|p| p.svd_tolerance)
                        .map_or("?".to_string(), |t| format!("{t:e}"))
                );
            }
            None => {
                let _ = writeln!(
                    h,
                    "<p>Method <strong>{}</strong>: no update was made (ε started below the threshold), so nothing was identified.</p>",
                    escape(&ctx.method)
                );
            }
        }
        let dropped: Vec<String> = paper
            .and_then(|p| p.dropped_directions.as_ref())
            .map(|d| d.iter().map(ToString::to_string).collect())
            .unwrap_or_default();
        if !dropped.is_empty() {
            h.push_str("<h3>Directions the SVD dropped</h3>\n");
            list(h, "dropped", &dropped);
        }
        let fixed = ctx.solver().fixed();
        if !fixed.is_empty() {
            let _ = writeln!(
                h,
                "<p class=\"mono\" id=\"fixed\">fixed: {}</p>",
                escape(&fixed.join(", "))
            );
        }
    }
    let _ = writeln!(
        h,
        "<p>{} parameter(s) are marked † in the tables below: {}.</p>",
        ctx.marks.len(),
        escape(&if ctx.marks.is_empty() {
            "none".to_string()
        } else {
            ctx.marks.keys().cloned().collect::<Vec<_>>().join(", ")
        })
    );
    end_section(h);
}

/// A table cell with a value, its σ when known and the † mark.
pub(super) fn marked_cell(ctx: &Ctx<'_>, label: &str, text: String) -> String {
    let sigma = ctx
        .sigma
        .get(label)
        .map(|s| {
            format!(
                " <span class=\"muted\" title=\"a priori ± {}\">± {}</span>",
                num(s.a_priori, 4),
                num(s.std, 4)
            )
        })
        .unwrap_or_default();
    match ctx.marks.get(label) {
        Some(why) => format!(
            "<td class=\"n marked\" title=\"{}\">{} †</td>",
            escape(&format!("{label}: {why}")),
            escape(&text)
        ),
        None => format!("<td class=\"n\">{}{sigma}</td>", escape(&text)),
    }
}

/// A calibrated hand-eye cell (row `k`: x, y, z, roll, pitch, yaw) with
/// its σ in the same frame and unit ([`ResultFigures::hand_eye_sigma`]), and
/// the † mark.
pub(super) fn hand_eye_cell(ctx: &Ctx<'_>, k: usize, text: String) -> String {
    let label = HAND_EYE_LABELS[k];
    if let Some(why) = ctx.marks.get(label) {
        format!(
            "<td class=\"n marked\" title=\"{}\">{} †</td>",
            escape(&format!("{label}: {why}")),
            escape(&text)
        )
    } else {
        let sigma = ctx
            .hand_eye_sigma
            .map(|s| {
                let prior = ctx
                    .hand_eye_sigma_a_priori
                    .map(|p| format!(" title=\"a priori ± {}\"", num(p[k], 4)))
                    .unwrap_or_default();
                format!(" <span class=\"muted\"{prior}>± {}</span>", num(s[k], 4))
            })
            .unwrap_or_default();
        format!("<td class=\"n\">{}{sigma}</td>", escape(&text))
    }
}

/// Roll, pitch, yaw (deg) and translation (mm) of a hand-eye.
pub(super) fn pose_parts(he: &nalgebra::Isometry3<f64>) -> ([f64; 3], [f64; 3]) {
    let v = HandEyeView::new(he);
    (v.translation, v.rpy_deg)
}

pub(super) fn matrix_text(he: &nalgebra::Isometry3<f64>) -> String {
    rows_from_isometry(he)
        .iter()
        .map(|r| {
            format!(
                "{:>11.6} {:>11.6} {:>11.6} {:>11.4}",
                r[0], r[1], r[2], r[3]
            )
        })
        .collect::<Vec<_>>()
        .join("\n")
}

pub(super) fn hand_eye(h: &mut String, ctx: &Ctx<'_>) {
    let r = ctx.result();
    section(h, "hand-eye", "Hand-eye eT_s (sensor to flange)");
    let (tb, rb) = pose_parts(&r.hand_eye_initial);
    let (ta, ra) = pose_parts(&r.hand_eye);
    h.push_str("<table class=\"keep\">\n");
    head_row(h, &["", "#initial", "#calibrated", "#change"]);
    let names = [
        "x (mm)",
        "y (mm)",
        "z (mm)",
        "roll (deg)",
        "pitch (deg)",
        "yaw (deg)",
    ];
    for (k, name) in names.iter().enumerate() {
        let (b, a, change) = if k < 3 {
            (tb[k], ta[k], ta[k] - tb[k])
        } else {
            let (b, a) = (rb[k - 3], ra[k - 3]);
            // An angle's change the short way round (179° → −179° is +2°).
            (b, a, wrap_deg(a - b))
        };
        let _ = writeln!(
            h,
            "<tr><td>{name}</td><td class=\"n\">{}</td>{}<td class=\"n\">{}</td></tr>",
            num(b, 4),
            hand_eye_cell(ctx, k, num(a, 4)),
            signed(change, 4)
        );
    }
    h.push_str("</table>\n");
    let (b, a) = (&r.hand_eye_initial, &r.hand_eye);
    let _ = writeln!(
        h,
        "<p>The calibration moved the hand-eye by {} mm and turned it by {}°. Roll, pitch, yaw: rotations about x, y, z (R = Rz(yaw)·Ry(pitch)·Rx(roll)).</p>",
        num((a.translation.vector - b.translation.vector).norm(), 4),
        num(b.rotation.angle_to(&a.rotation).to_degrees(), 4)
    );
    let _ = writeln!(
        h,
        "<div class=\"grid2\"><div><h3>initial</h3><pre>{}</pre></div><div><h3>calibrated</h3><pre>{}</pre></div></div>",
        matrix_text(&r.hand_eye_initial),
        matrix_text(&r.hand_eye)
    );
    end_section(h);
}

pub(super) fn joint_errors(h: &mut String, ctx: &Ctx<'_>) {
    if let Some(lines) = hand_eye_only_lines(ctx.result(), Some(ctx.session())) {
        section(h, "joints", "Hand-eye only: no kinematic model");
        for line in lines {
            let class = if line.starts_with("weakly") {
                " class=\"warn\""
            } else {
                ""
            };
            let _ = writeln!(h, "<p{class}>{}</p>", escape(&line));
        }
        end_section(h);
        return;
    }
    section(
        h,
        "joints",
        "Joint errors, calibrated − nominal (cf. paper Table 1)",
    );
    h.push_str("<table class=\"keep\" id=\"joint-errors\">\n");
    head_row(
        h,
        &[
            "joint",
            "#Δα (deg)",
            "#Δa (mm)",
            "#Δβ (deg)",
            "#Δθ (deg)",
            "#Δd (mm)",
        ],
    );
    for (j, e) in ctx.result().joint_errors.iter().enumerate() {
        let _ = write!(h, "<tr><td>{}</td>", j + 1);
        for (p, name) in PARAM_NAMES.iter().enumerate() {
            h.push_str(&marked_cell(
                ctx,
                &format!("{name}{}", j + 1),
                signed(e.get(p), 4),
            ));
        }
        h.push_str("</tr>\n");
    }
    h.push_str("</table>\n");
    let sigma_note = if ctx.sigma.is_empty() {
        ""
    } else {
        " ± is the standard deviation from the ml covariance."
    };
    let _ = writeln!(
        h,
        "<p class=\"muted\">† not identifiable from this data ({} parameter(s)): the method held it fixed or it lies in a direction the SVD dropped, so its value is not a measurement of the robot.{sigma_note}</p>",
        ctx.marks.len()
    );
    end_section(h);
}

pub(super) fn validation(h: &mut String, ctx: &Ctx<'_>) {
    section(h, "validation", "Validation");
    let Some(v) = &ctx.result().validation else {
        h.push_str("<p class=\"warn\">No validate measurements in this session: accuracy is not checked. Add validate stations (and reference distances, e.g. from a laser tracker) to measure it.</p>\n");
        end_section(h);
        return;
    };
    if v.distances.is_empty() {
        h.push_str("<p>No reference distances: only the within-station distances of the validate stations are scored.</p>\n");
    } else {
        h.push_str("<h3>Reference distances (mm)</h3>\n<table class=\"small\" id=\"distances\">\n");
        head_row(
            h,
            &[
                "#",
                "from → to",
                "#pose",
                "#reference",
                "#measured before",
                "#measured after",
                "#error before",
                "#error after",
            ],
        );
        for (k, d) in v.distances.iter().enumerate() {
            let _ = writeln!(
                h,
                "<tr><td>{}</td><td>{} → {}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n b\">{}</td><td class=\"n a\">{}</td></tr>",
                k + 1,
                escape(&d.from),
                escape(&d.to),
                d.pose,
                num(d.reference, 4),
                num(d.before, 4),
                num(d.after, 4),
                signed(d.error_before(), 4),
                signed(d.error_after(), 4)
            );
        }
        for (name, b, a) in [
            ("std", v.before.std, v.after.std),
            ("max |e|", v.before.max, v.after.max),
            ("rms", v.before.rms, v.after.rms),
        ] {
            let _ = writeln!(
                h,
                "<tr><th colspan=\"6\">{name}</th><th class=\"n\">{}</th><th class=\"n\">{}</th></tr>",
                num(b, 4),
                num(a, 4)
            );
        }
        h.push_str("</table>\n");
    }
    // Per validate station.
    let mut stations: Vec<&str> = Vec::new();
    for p in ctx.within.iter().filter(|_| ctx.within_of == "validate") {
        if !stations.contains(&p.station.as_str()) {
            stations.push(&p.station);
        }
    }
    if !stations.is_empty() {
        h.push_str("<h3>Within-station centre distances of the validate stations (mm, true value 0)</h3>\n<table class=\"small\" id=\"validate-stations\">\n");
        head_row(
            h,
            &[
                "station",
                "#pairs",
                "#max before",
                "#max after",
                "#rms before",
                "#rms after",
            ],
        );
        for s in stations {
            let pairs: Vec<&PairDistance> = ctx.within.iter().filter(|p| p.station == s).collect();
            let b = Stats::of(&pairs.iter().map(|p| p.before).collect::<Vec<_>>());
            let a = Stats::of(&pairs.iter().map(|p| p.after).collect::<Vec<_>>());
            let _ = writeln!(
                h,
                "<tr><td>{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td></tr>",
                escape(s),
                pairs.len(),
                num(b.max, 4),
                num(a.max, 4),
                num(b.rms, 4),
                num(a.rms, 4)
            );
        }
        h.push_str("</table>\n");
        let worst = ctx.within.iter().max_by(|a, b| a.after.total_cmp(&b.after));
        if let Some(p) = worst {
            let _ = writeln!(
                h,
                "<p class=\"muted\">Largest within-station distance after calibration: {} mm, {} – {} at station {}.</p>",
                num(p.after, 4),
                escape(&p.ids.0),
                escape(&p.ids.1),
                escape(&p.station)
            );
        }
    }
    end_section(h);
}

pub(super) fn outliers(h: &mut String, ctx: &Ctx<'_>) {
    section(h, "outliers", "Outliers and excluded measurements");
    if let Some(ml) = &ctx.ml {
        if ml.outliers.is_empty() {
            let _ = writeln!(
                h,
                "<p>No outliers: no identify measurement's standardised residual exceeds {} σ.</p>",
                num(ml.outlier_limit_sigma, 2)
            );
        } else {
            h.push_str("<table class=\"small\" id=\"outlier-table\">\n");
            head_row(
                h,
                &["measurement", "station", "#residual (mm)", "#σ", "reason"],
            );
            for o in &ml.outliers {
                let _ = writeln!(
                    h,
                    "<tr><td>{}</td><td>{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td>{}</td></tr>",
                    escape(&o.measurement),
                    escape(&o.station),
                    num(o.residual_mm, 4),
                    num(o.sigma, 1),
                    escape(&o.reason)
                );
            }
            h.push_str("</table>\n<p class=\"muted\">To rerun without them: <span class=\"mono\">spherecal calibrate SESSION --exclude ID,ID</span>.</p>\n");
        }
    } else {
        let _ = writeln!(
            h,
            "<p>Method {} does not test for outliers.</p>",
            escape(&ctx.method)
        );
    }
    if ctx.excluded.is_empty() {
        h.push_str("<p id=\"excluded\">Every measurement of the session is in the result.</p>\n");
    } else {
        let _ = writeln!(
            h,
            "<p id=\"excluded\">Left out of this run ({} measurement(s) of the session that the result does not hold): <span class=\"mono\">{}</span></p>",
            ctx.excluded.len(),
            escape(&ctx.excluded.join(", "))
        );
    }
    end_section(h);
}

pub(super) fn measurements(h: &mut String, ctx: &Ctx<'_>) {
    section(h, "measurements", "Measurements");
    let s = ctx.session();
    let prepared = ctx.prepared.as_ref().ok();
    h.push_str("<table class=\"small\" id=\"measurement-table\">\n");
    head_row(
        h,
        &[
            "id",
            "station",
            "use",
            "#side",
            "#points (used)",
            "#r (mm)",
            "#fit RMS (µm)",
            "#arc (°)",
            "#cut (°)",
            "in result",
            "warnings",
        ],
    );
    for (i, m) in s.measurements.iter().enumerate() {
        let fit = prepared
            .and_then(|p| p.measurements.get(i))
            .and_then(|p| p.stripe.as_ref());
        let cells = match (&m.observation, fit) {
            (Observation::Stripe(points), Some(f)) => format!(
                "<td class=\"n\">{} ({})</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td>",
                points.len(),
                f.fit.used(),
                num(f.fit.radius, 3),
                num(f.fit.rms * 1e3, 1),
                num(f.fit.arc_span_deg, 1),
                signed(f.sphere.cut_angle_deg, 1)
            ),
            (Observation::Stripe(points), None) => format!(
                "<td class=\"n\">{}</td><td colspan=\"4\" class=\"muted\">not fitted</td>",
                points.len()
            ),
            (Observation::Centre(_), _) => {
                "<td colspan=\"5\" class=\"muted\">centre given</td>".to_string()
            }
        };
        let warnings = fit.map(|f| f.warnings.join("; ")).unwrap_or_default();
        let in_result = if ctx.excluded.contains(&m.id) {
            "<td class=\"marked\">left out</td>"
        } else {
            "<td>yes</td>"
        };
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td class=\"n\">{:+}</td>{cells}{in_result}<td>{}</td></tr>",
            escape(&m.id),
            escape(&m.station),
            m.usage.as_str(),
            m.side,
            escape(&warnings)
        );
    }
    h.push_str("</table>\n");
    end_section(h);
}

pub(super) fn solver_block(h: &mut String, ctx: &Ctx<'_>) {
    section(h, "solver-block", "The result's solver block");
    h.push_str("<table class=\"small\">\n");
    head_row(h, &["key", "value"]);
    let mut omitted = Vec::new();
    let solver = solver_map(ctx.solver());
    let keys = solver
        .get_key_value("method")
        .into_iter()
        .chain(solver.iter().filter(|(k, _)| *k != "method"));
    for (k, v) in keys {
        if let Some(t) = scalar_text(v) {
            let _ = writeln!(
                h,
                "<tr><td class=\"key\">{}</td><td>{}</td></tr>",
                escape(k),
                escape(&t)
            );
        } else if let Value::Object(o) = v {
            for (k2, v2) in o {
                match scalar_text(v2) {
                    Some(t) => {
                        let _ = writeln!(
                            h,
                            "<tr><td class=\"key\">{}.{}</td><td>{}</td></tr>",
                            escape(k),
                            escape(k2),
                            escape(&t)
                        );
                    }
                    None => omitted.push(format!("{k}.{k2}")),
                }
            }
        } else {
            omitted.push(k.clone());
        }
    }
    h.push_str("</table>\n");
    if !omitted.is_empty() {
        let _ = writeln!(
            h,
            "<p class=\"muted\">Lists and matrices, in the result file only or shown above: {}.</p>",
            escape(&omitted.join(", "))
        );
    }
    end_section(h);
}
