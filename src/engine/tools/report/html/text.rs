//! The report's text sections: header, notes, summary, settings and the
//! stripe quality.

use std::fmt::Write as _;

use serde_json::Value;

use super::*;
use crate::engine::base::session::Use;
use crate::engine::calibrate::solve::{HandEyeSource, SolverReport};
use crate::engine::calibrate::stripe::{HIGH_RMS_MM, StripeResult};
use crate::engine::calibrate::validate::Stats;
use crate::engine::tools::report::svg::escape;

/// Labels of the solver settings worth a row of their own, by the JSON
/// pointer of the key in a result's `solver` block; those a method does
/// not have are left out.
pub(super) const SETTINGS: [(&str, &str); 17] = [
    ("/method", "method"),
    ("/threshold", "threshold on ε (mm)"),
    ("/max_iterations", "most updates"),
    ("/pairs", "pairing of a station's measurements"),
    ("/svd_tolerance", "SVD tolerance (fraction of σ_max)"),
    ("/column_scaling", "column scaling"),
    (
        "/noise_model/joint_sigma_deg",
        "σ of the joint readings (deg)",
    ),
    ("/noise_model/centre_sigma_mm", "σ of a given centre (mm)"),
    (
        "/noise_model/sensor_sigma_floor_mm",
        "floor of a stripe centre's principal σ (mm)",
    ),
    ("/prior/enabled", "prior on the kinematic deviations"),
    (
        "/prior/angle_sigma_deg",
        "prior σ of angle deviations (deg)",
    ),
    (
        "/prior/length_sigma_mm",
        "prior σ of length deviations (mm)",
    ),
    ("/loss/kind", "robust loss"),
    ("/loss/scale_sigma", "robust loss scale (σ)"),
    (
        "/identifiability/tolerance",
        "rank tolerance (relative pivot)",
    ),
    ("/outlier_limit_sigma", "outlier limit (σ)"),
    ("/stop_reason", "why the loop stopped"),
];

/// The value of setting `pointer` ([`SETTINGS`]) in `report`, as text.
pub(super) fn setting(report: &SolverReport, pointer: &str) -> Option<String> {
    let n = |v: f64| Some(short_number(v));
    let t = |v: &str| Some(v.to_string());
    match (report, pointer) {
        (_, "/method") => t(report.method()),
        (SolverReport::Other { block, .. }, _) => lookup(block, pointer).and_then(scalar_text),
        (SolverReport::Paper(p), _) => match pointer {
            "/threshold" => p.threshold.and_then(n),
            "/max_iterations" => p.max_iterations.and_then(|v| n(v as f64)),
            "/pairs" => p.pairs.as_deref().and_then(t),
            "/svd_tolerance" => p.svd_tolerance.and_then(n),
            "/column_scaling" => p.column_scaling.as_deref().and_then(t),
            "/stop_reason" => p.stop_reason.as_deref().and_then(t),
            _ => None,
        },
        (SolverReport::Ml(m), _) => match pointer {
            "/threshold" => n(m.stop.threshold),
            "/max_iterations" => n(m.stop.max_iterations as f64),
            "/noise_model/joint_sigma_deg" => n(m.noise_model.joint_sigma_deg),
            "/noise_model/centre_sigma_mm" => n(m.noise_model.centre_sigma_mm),
            "/noise_model/sensor_sigma_floor_mm" => n(m.noise_model.sensor_sigma_floor_mm),
            "/prior/enabled" => Some(m.prior.enabled.to_string()),
            "/prior/angle_sigma_deg" => n(m.prior.angle_sigma_deg),
            "/prior/length_sigma_mm" => n(m.prior.length_sigma_mm),
            "/loss/kind" => t(m.loss.kind.as_str()),
            "/loss/scale_sigma" => n(m.loss.scale_sigma),
            "/identifiability/tolerance" => n(m.identifiability.tolerance),
            "/outlier_limit_sigma" => n(m.outlier_limit_sigma),
            "/stop_reason" => t(&m.stop.stop_reason),
            _ => None,
        },
    }
}

pub(super) fn header(h: &mut String, ctx: &Ctx<'_>) {
    let s = ctx.session();
    let _ = write!(
        h,
        "<header id=\"header\">\n<h1>Calibration report<small>{}</small></h1>\n<table class=\"meta\">\n",
        escape(&s.name)
    );
    meta_row(h, "Session", &escape(&s.name));
    meta_row(h, "Session file", &escape(&ctx.input.meta.session_file));
    meta_row(
        h,
        "SHA-256 of the file",
        &format!("<span class=\"mono\" id=\"sha256\">{}</span>", ctx.sha),
    );
    let robot = if s.pose_only() {
        "none: a pose-only session (the controller's flange poses, no joint readings)".to_string()
    } else {
        format!(
            "{} ({} joints, nominal model of the session)",
            escape(&s.robot.name),
            s.robot.dof()
        )
    };
    meta_row(h, "Robot", &robot);
    meta_row(
        h,
        "Sphere",
        &format!("diameter {} mm", num(s.sphere_diameter, 3)),
    );
    let counts: Vec<String> = Use::ALL
        .iter()
        .map(|u| {
            let n = s.with_use(*u).count();
            let stations = s.stations(*u).len();
            format!("{n} {} ({stations} station(s))", u.as_str())
        })
        .collect();
    meta_row(
        h,
        "Measurements",
        &format!("{}: {}", s.measurements.len(), escape(&counts.join(", "))),
    );
    meta_row(
        h,
        "Reference distances",
        &s.reference_distances.len().to_string(),
    );
    meta_row(h, "Method", &escape(&ctx.method));
    meta_row(
        h,
        "Software",
        &format!("spherecal {}", escape(&ctx.input.meta.software_version)),
    );
    meta_row(
        h,
        "Generated",
        &escape(&format_utc(ctx.input.meta.generated)),
    );
    h.push_str("</table>\n</header>\n");
}

pub(super) fn notes(h: &mut String, ctx: &Ctx<'_>) {
    let mut notes = Vec::new();
    if let Err(e) = check_result(
        ctx.session(),
        ctx.result(),
        ctx.prepared.as_ref().ok().copied(),
    ) {
        notes.push(format!(
            "The result may not belong to this session: {e}. Figures below are the result's."
        ));
    }
    if let Err(e) = &ctx.prepared {
        notes.push(format!(
            "The session's stripe fits could not be recomputed: {e}."
        ));
    }
    for n in notes {
        let _ = writeln!(h, "<p class=\"warn\">{}</p>", escape(&n));
    }
}

/// A row of the before/after table of statistics.
pub(super) fn stats_rows(h: &mut String, what: &str, b: &Stats, a: &Stats) {
    for (name, vb, va) in [
        ("std", b.std, a.std),
        ("max", b.max, a.max),
        ("rms", b.rms, a.rms),
    ] {
        let _ = writeln!(
            h,
            "<tr><td>{} — {name}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td></tr>",
            escape(what),
            num(vb, 4),
            num(va, 4),
            escape(&ratio(vb, va))
        );
    }
}

pub(super) fn summary(h: &mut String, ctx: &Ctx<'_>) {
    let r = ctx.result();
    section(h, "summary", "Summary: before → after");
    h.push_str("<div class=\"headline\">\n");
    let headline = match &r.validation {
        Some(v) if !v.distances.is_empty() => Some((
            format!(
                "Validation: {} reference distances, measured − reference",
                v.distances.len()
            ),
            v.before,
            v.after,
        )),
        Some(v) => Some((
            "Validation: within-station centre distances (no reference distances)".to_string(),
            v.within_station.before,
            v.within_station.after,
        )),
        None => None,
    };
    if let Some((what, b, a)) = &headline {
        let _ = writeln!(h, "<p><strong>{}</strong></p>\n<p>", escape(what));
        for (name, vb, va) in [("std", b.std, a.std), ("max", b.max, a.max)] {
            let _ = write!(
                h,
                "<span class=\"big\">{name} {} → {} mm<span class=\"ratio\">{}</span></span>",
                num(vb, 3),
                num(va, 3),
                escape(&ratio(vb, va))
            );
        }
        h.push_str("</p>\n");
    } else {
        h.push_str(
            "<p class=\"warn\" id=\"no-validation\">No validate measurements in this session: accuracy is not checked (no Fig. 6, no validation table).</p>\n",
        );
        let (b, a) = ctx.identify_scatter;
        let _ = writeln!(
            h,
            "<p>Identify centres about their station's mean (3-D rms): <span class=\"big\">{} → {} mm</span></p>",
            num(b, 3),
            num(a, 3)
        );
    }
    if let Some((verdict, tolerance)) = &ctx.verdict {
        let class = match verdict {
            Verdict::Pass => "pass",
            Verdict::Fail(_) => "fail",
            Verdict::NotChecked => "unchecked",
        };
        let _ = writeln!(
            h,
            "<p class=\"verdict {class}\" id=\"verdict\">{}</p>",
            escape(&verdict.describe(tolerance))
        );
    }
    let _ = writeln!(
        h,
        "<p>ε (paper eq. 20) {} → {} mm after {} update(s).{}</p>",
        num(r.epsilon_before, 4),
        num(r.epsilon_after, 4),
        r.iterations.len().saturating_sub(1),
        ctx.solver()
            .stop_reason()
            .map(|s| format!(" Stop: {}.", escape(s)))
            .unwrap_or_default()
    );
    for w in &ctx.warnings {
        let _ = writeln!(
            h,
            "<p class=\"warn\" id=\"epsilon-warning\">Warning: {}</p>",
            escape(w)
        );
    }
    held_out(h, ctx);
    h.push_str("</div>\n<table class=\"keep\">\n");
    head_row(h, &["figure (mm)", "#before", "#after", "#change"]);
    if let Some(v) = &r.validation {
        if !v.distances.is_empty() {
            stats_rows(h, "reference-distance errors", &v.before, &v.after);
        }
        stats_rows(
            h,
            "validate stations, within-station distances",
            &v.within_station.before,
            &v.within_station.after,
        );
    }
    let w = &ctx.identify_within;
    stats_rows(
        h,
        "identify stations, within-station distances",
        &w.before,
        &w.after,
    );
    let _ = writeln!(
        h,
        "<tr><td>ε</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td></tr>",
        num(r.epsilon_before, 4),
        num(r.epsilon_after, 4),
        escape(&ratio(r.epsilon_before, r.epsilon_after))
    );
    h.push_str("</table>\n<p class=\"muted\">Before: nominal model and initial hand-eye. After: calibrated model and hand-eye. Within-station distances have the true value 0. Statistics as in FORMAT.md: std with divisor n − 1, max of |e|, rms.</p>\n");
    end_section(h);
}

/// The held-out figure beside the fit's own scatter, or why there is none.
fn held_out(h: &mut String, ctx: &Ctx<'_>) {
    let Some(ho) = &ctx.held_out else {
        h.push_str("<p class=\"muted\" id=\"held-out\">No held-out figure in this result (written before spherecal computed one, or with --no-held-out).</p>\n");
        return;
    };
    let _ = writeln!(
        h,
        "<p id=\"held-out\">Held out ({}), each identify centre predicted without itself: <span class=\"big\">rms {} mm</span>, max {} mm{}; the fit's own scatter: rms {} mm, max {} mm ({}× the fit's own rms over {} measurements).</p>",
        escape(&ho.label()),
        num(ho.rms, 3),
        num(ho.max, 3),
        if ho.max_measurement.is_empty() {
            String::new()
        } else {
            format!(" ({})", escape(&ho.max_measurement))
        },
        num(ho.fit_rms, 3),
        num(ho.fit_max, 3),
        num(ho.ratio(), 2),
        ho.measurements.len()
    );
    if !ho.undetermined.is_empty() {
        let _ = writeln!(
            h,
            "<p class=\"warn\">Not predictable without themselves (each alone determined a direction): {}</p>",
            escape(&ho.undetermined.join(", "))
        );
    }
    let _ = writeln!(
        h,
        "<p class=\"muted\">Held out: the distance from a measurement's centre, under a calibration made without it, to its station's centre as that calibration estimates it from the station's other measurements. The fit's own scatter flatters: the fit has seen each point. Refit: {}.</p>",
        escape(&ho.refit)
    );
}

/// `v` to 6 significant digits, without trailing zeros (1e-7 stays 1e-7).
pub(super) fn short_number(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return v.to_string();
    }
    let trim = |t: String| -> String {
        if t.contains('.') {
            t.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            t
        }
    };
    let magnitude = v.abs().log10().floor();
    if (-3.0..6.0).contains(&magnitude) {
        let decimals = (5.0 - magnitude).max(0.0) as usize;
        trim(format!("{v:.decimals$}"))
    } else {
        let t = format!("{v:.5e}");
        match t.split_once('e') {
            Some((m, e)) => format!("{}e{e}", trim(m.to_string())),
            None => t,
        }
    }
}

/// Scalars of a JSON value as text; `None` for big arrays and objects.
pub(super) fn scalar_text(v: &Value) -> Option<String> {
    /// Longest array of scalars shown inline.
    const MAX_INLINE: usize = 8;
    match v {
        Value::String(s) => Some(s.clone()),
        Value::Number(n) => Some(n.as_f64().map_or_else(|| n.to_string(), short_number)),
        Value::Bool(b) => Some(b.to_string()),
        Value::Null => Some("null".to_string()),
        Value::Array(a)
            if a.len() <= MAX_INLINE && a.iter().all(|x| !x.is_array() && !x.is_object()) =>
        {
            Some(
                a.iter()
                    .filter_map(scalar_text)
                    .collect::<Vec<_>>()
                    .join(", "),
            )
        }
        _ => None,
    }
}

pub(super) fn settings(h: &mut String, ctx: &Ctx<'_>) {
    section(h, "settings", "Settings");
    let s = ctx.session();
    let _ = writeln!(
        h,
        "<p>Session solver settings: threshold {} mm, at most {} update(s){}.</p>",
        num(s.solver.threshold, 4),
        s.solver.max_iterations,
        if s.solver_given {
            ""
        } else {
            " (defaults: the session has no solver block)"
        }
    );
    match &ctx.prepared {
        Ok(p) => match &p.hand_eye_source {
            HandEyeSource::File => {
                h.push_str("<p>Initial hand-eye: from the session file.</p>\n");
            }
            HandEyeSource::Computed(i) => {
                let _ = writeln!(
                    h,
                    "<p>Initial hand-eye: computed from the translation and rotation measurements (paper eq. 6-9); rotation residual {} mm, translation residual {} mm.</p>",
                    num(i.rotation_residual, 4),
                    num(i.translation_residual, 4)
                );
            }
            HandEyeSource::Linear(g) => {
                let _ = writeln!(
                    h,
                    "<p>Initial base-from-sensor (a fixed sensor): linear in the unknowns from every identify measurement; the targets scatter {} mm rms about their points.</p>",
                    num(g.rms_mm, 4)
                );
            }
        },
        Err(_) => {
            h.push_str("<p>Initial hand-eye: unknown (the session could not be prepared).</p>\n");
        }
    }
    h.push_str("<table class=\"keep\" id=\"settings-table\">\n");
    head_row(h, &["setting", "value"]);
    for (path, label) in SETTINGS {
        if let Some(t) = setting(ctx.solver(), path) {
            let _ = writeln!(
                h,
                "<tr><td>{}</td><td>{}</td></tr>",
                escape(label),
                escape(&t)
            );
        }
    }
    if let Some(ml) = &ctx.ml {
        let _ = writeln!(
            h,
            "<tr><td>leave-one-station-out cross-validation</td><td>{}</td></tr>",
            if ml.cross_validation.is_some() {
                "on"
            } else {
                "off"
            }
        );
    }
    h.push_str("</table>\n<p class=\"muted\">Every scalar of the result's solver block is listed at the end of the report.</p>\n");
    end_section(h);
}

/// The value at fraction `q` of sorted `v` (nearest rank).
pub(super) fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let k = ((q * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len());
    sorted[k - 1]
}

/// `min – max` of an iterator, with `d` decimals.
pub(super) fn range_text(values: impl Iterator<Item = f64>, d: usize) -> String {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    if lo.is_finite() {
        format!("{} – {}", num(lo, d), num(hi, d))
    } else {
        "–".to_string()
    }
}

pub(super) fn stripes(h: &mut String, ctx: &Ctx<'_>) {
    section(h, "stripes", "Stripe quality");
    let p = match &ctx.prepared {
        Ok(p) => p,
        Err(e) => {
            let _ = writeln!(
                h,
                "<p class=\"warn\">Stripe fits unavailable: {}.</p>",
                escape(e)
            );
            end_section(h);
            return;
        }
    };
    let s = ctx.session();
    let fits: Vec<(&str, &StripeResult)> = p
        .measurements
        .iter()
        .filter_map(|m| {
            m.stripe
                .as_ref()
                .map(|f| (s.measurements[m.index].id.as_str(), f))
        })
        .collect();
    let given = s.measurements.len() - fits.len();
    if fits.is_empty() {
        let _ = writeln!(
            h,
            "<p>No stripes: all {given} measurements give the sphere centre directly (a sensor that fits spheres itself), so there are no circle fits to judge.</p>"
        );
        end_section(h);
        return;
    }
    let mut rms: Vec<f64> = fits.iter().map(|(_, f)| f.fit.rms).collect();
    rms.sort_by(f64::total_cmp);
    let worst = fits
        .iter()
        .max_by(|a, b| a.1.fit.rms.total_cmp(&b.1.fit.rms))
        .map_or("", |(id, _)| *id);
    let rejected: usize = fits.iter().map(|(_, f)| f.fit.rejected()).sum();
    let trimmed = fits.iter().filter(|(_, f)| f.fit.rejected() > 0).count();
    let total: usize = fits.iter().map(|(_, f)| f.fit.inlier.len()).sum();
    let high = rms.iter().filter(|r| **r > HIGH_RMS_MM).count();
    let on_plane = fits.iter().filter(|(_, f)| f.sphere.on_plane).count();
    h.push_str("<table class=\"keep\">\n");
    let row = |h: &mut String, k: &str, v: String| {
        let _ = writeln!(h, "<tr><th>{}</th><td>{}</td></tr>", escape(k), escape(&v));
    };
    row(
        h,
        "stripes fitted",
        format!(
            "{} of {} measurements ({given} give a centre directly)",
            fits.len(),
            s.measurements.len()
        ),
    );
    row(
        h,
        "points per stripe",
        format!(
            "{} ({total} in all)",
            range_text(fits.iter().map(|(_, f)| f.fit.inlier.len() as f64), 0)
        ),
    );
    row(
        h,
        "fitted circle radius r",
        format!(
            "{} mm (r/R {}; sphere R = {} mm)",
            range_text(fits.iter().map(|(_, f)| f.fit.radius), 3),
            range_text(fits.iter().map(|(_, f)| f.sphere.r_over_r), 3),
            num(s.sphere_radius(), 3)
        ),
    );
    row(
        h,
        "fit RMS (orthogonal residuals)",
        format!(
            "min {} µm, median {} µm, 90th percentile {} µm, max {} µm ({worst}); {high} above {} µm",
            num(quantile(&rms, 0.0) * 1e3, 1),
            num(quantile(&rms, 0.5) * 1e3, 1),
            num(quantile(&rms, 0.9) * 1e3, 1),
            num(quantile(&rms, 1.0) * 1e3, 1),
            num(HIGH_RMS_MM * 1e3, 0)
        ),
    );
    row(
        h,
        "arc span",
        format!(
            "{} °",
            range_text(fits.iter().map(|(_, f)| f.fit.arc_span_deg), 1)
        ),
    );
    row(
        h,
        "cut angle |side · asin(t/R)|",
        format!(
            "{} ° (about 40° is the paper's)",
            range_text(fits.iter().map(|(_, f)| f.sphere.cut_angle_deg.abs()), 1)
        ),
    );
    row(
        h,
        "trimmed outlier points",
        format!("{rejected} of {total} points, in {trimmed} stripe(s)"),
    );
    row(
        h,
        "centre taken on the laser plane (r > R within tolerance)",
        on_plane.to_string(),
    );
    row(h, "warnings", p.warnings.len().to_string());
    h.push_str("</table>\n");
    if !p.warnings.is_empty() {
        h.push_str("<ul id=\"stripe-warnings\">\n");
        for (id, w) in &p.warnings {
            let _ = writeln!(h, "<li><strong>{}</strong>: {}</li>", escape(id), escape(w));
        }
        h.push_str("</ul>\n");
    }
    end_section(h);
}
