//! The self-contained HTML report of a calibration: one file with inline
//! CSS and inline SVG figures ([`crate::engine::report::svg`]), no script and no external
//! resource, printable on A4. It shows what the workbench's Results view
//! shows, plus the provenance a report needs:
//!
//! - header: session name and file, SHA-256 of the session file's bytes,
//!   robot, sphere, measurement counts, method, software version, date (UTC);
//! - notes when the result does not match the session;
//! - summary: the validation figures before → after (std, max, rms of the
//!   reference-distance errors; within-station distances), the identify
//!   stations' within-station distances, ε, the stop reason;
//! - settings: every scalar of the result's `solver` block and where the
//!   initial hand-eye came from;
//! - stripe quality: fitted radii, arc spans, cut angles, fit RMS
//!   distribution, trimmed points, warnings (from [`solve::prepare`]);
//! - the paper's Fig. 5 (within-station centre distances, per pair) and
//!   Fig. 6 (reference-distance errors, per distance), before and after;
//! - ε per update, and the singular values of the paper's method;
//! - identifiability: the SVD directions dropped, or the parameters `ml`
//!   held fixed, the combinations it cannot separate, its σ;
//! - hand-eye before and after (translation mm, roll/pitch/yaw deg,
//!   matrices); joint errors in the layout of the paper's Table 1, with the
//!   non-identifiable ones marked;
//! - validation distances, per pair and per station; outliers and
//!   measurements left out of the run; every measurement's fit.
//!
//! [`render`] is a pure function of its [`ReportInput`]: the caller passes
//! the generation time, so the same input gives the same bytes.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::time::{SystemTime, UNIX_EPOCH};

use serde_json::{Map, Value};
use sha2::{Digest, Sha256};

use crate::engine::format::result::{ResultFile, solver_block as solver_map};
use crate::engine::geometry::{rows_from_isometry, wrap_deg};
use crate::engine::report::svg::{self, Band, Marker, Plot, Rule, Series, escape};
use crate::engine::result_view::{
    HandEyeView, PairDistance, ResultView, Sigma, check_result, excluded_measurements,
};
use crate::engine::robot::PARAM_NAMES;
use crate::engine::session::{Observation, Session, Use};
use crate::engine::solve::estimate::HAND_EYE_LABELS;
use crate::engine::solve::ml::MlReport;
use crate::engine::solve::{self, HandEyeSource, Prepared, SolverReport};
use crate::engine::stripe::{HIGH_RMS_MM, StripeResult};
use crate::engine::validate::{BeforeAfter, Stats};

/// The version written in the report: this crate's.
pub const SOFTWARE_VERSION: &str = env!("CARGO_PKG_VERSION");

/// Colour of the "before" series (nominal model, initial hand-eye); the
/// workbench's.
pub const BEFORE_COLOUR: &str = "#e67828";
/// Colour of the "after" series (calibrated); the workbench's.
pub const AFTER_COLOUR: &str = "#2896e6";
/// Colour of discarded values (dropped singular values).
const BAD_COLOUR: &str = "#e13c3c";

/// Width of a full-width figure, px (the page is about 930 px wide).
const WIDE: f64 = 920.0;
/// Width of a half-width figure, px.
const HALF: f64 = 450.0;
/// Height of every figure, px.
const FIG_HEIGHT: f64 = 300.0;

/// Where the report came from and when; the caller's, so that the report
/// is a pure function of its input.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ReportMeta {
    /// The session file as shown (a path, or e.g. `demo-irb2400.json (embedded)`).
    pub session_file: String,
    /// Generation time, shown in UTC to the second.
    pub generated: SystemTime,
    /// Software version shown; [`ReportMeta::new`] puts [`SOFTWARE_VERSION`].
    pub software_version: String,
}

impl ReportMeta {
    /// Metadata with this crate's version.
    #[must_use]
    pub fn new(session_file: impl Into<String>, generated: SystemTime) -> Self {
        Self {
            session_file: session_file.into(),
            generated,
            software_version: SOFTWARE_VERSION.to_string(),
        }
    }
}

/// Everything a report is made of.
#[derive(Debug, Clone, Copy)]
pub struct ReportInput<'a> {
    /// The session the result was computed from.
    pub session: &'a Session,
    /// The session file's bytes exactly as read (for the SHA-256).
    pub session_bytes: &'a [u8],
    /// The result to report.
    pub result: &'a ResultFile,
    /// The session's stripe fits and initial hand-eye, when the caller has
    /// them; `None` recomputes them with [`solve::prepare`].
    pub prepared: Option<&'a Prepared>,
    /// File name, time and version.
    pub meta: &'a ReportMeta,
}

/// The SHA-256 of `bytes`, 64 lowercase hex digits.
#[must_use]
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .fold(String::with_capacity(64), |mut s, b| {
            let _ = write!(s, "{b:02x}");
            s
        })
}

/// `t` as `YYYY-MM-DD hh:mm:ss UTC` (RFC 3339 to the second, by
/// `humantime`); a time before 1970 or after 9999 is `unknown date`.
#[must_use]
pub fn format_utc(t: SystemTime) -> String {
    // humantime formats years 1970..=9999 (it panics outside them).
    const YEAR_10000: u64 = 253_402_300_800;
    match t.duration_since(UNIX_EPOCH) {
        Ok(d) if d.as_secs() < YEAR_10000 => {
            let s = humantime::format_rfc3339_seconds(t).to_string();
            format!("{} UTC", s.trim_end_matches('Z').replacen('T', " ", 1))
        }
        _ => "unknown date".to_string(),
    }
}

/// The value at a JSON pointer (`/loss/kind`) of a JSON object.
fn lookup<'v>(block: &'v Map<String, Value>, pointer: &str) -> Option<&'v Value> {
    let path = pointer.trim_start_matches('/');
    match path.split_once('/') {
        Some((head, rest)) => block.get(head)?.pointer(&format!("/{rest}")),
        None => block.get(path),
    }
}

/// The report as one HTML document.
#[must_use]
pub fn render(input: &ReportInput<'_>) -> String {
    let computed;
    let prepared: Result<&Prepared, String> = match input.prepared {
        Some(p) => Ok(p),
        None => match solve::prepare(input.session) {
            Ok(p) => {
                computed = p;
                Ok(&computed)
            }
            Err(e) => Err(e.to_string()),
        },
    };
    let ctx = Ctx::new(input, prepared);
    let mut h = String::with_capacity(256 * 1024);
    let title = format!("Calibration report: {}", input.session.name);
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<meta name=\"generator\" content=\"spherecal {}\">\n<title>{}</title>\n<style>{CSS}</style>\n</head>\n<body>\n",
        escape(&input.meta.software_version),
        escape(&title)
    );
    header(&mut h, &ctx);
    notes(&mut h, &ctx);
    summary(&mut h, &ctx);
    settings(&mut h, &ctx);
    stripes(&mut h, &ctx);
    figures(&mut h, &ctx);
    identifiability(&mut h, &ctx);
    hand_eye(&mut h, &ctx);
    joint_errors(&mut h, &ctx);
    validation(&mut h, &ctx);
    outliers(&mut h, &ctx);
    measurements(&mut h, &ctx);
    solver_block(&mut h, &ctx);
    let _ = write!(
        h,
        "<footer><p>spherecal {} · {} · session SHA-256 <span class=\"mono\">{}</span></p></footer>\n</body>\n</html>\n",
        escape(&input.meta.software_version),
        escape(&format_utc(input.meta.generated)),
        ctx.sha
    );
    h
}

const CSS: &str = "
:root{--before:#e67828;--after:#2896e6;--muted:#777}
*{-webkit-print-color-adjust:exact;print-color-adjust:exact;box-sizing:border-box}
body{font:14px/1.45 system-ui,-apple-system,'Segoe UI',Roboto,'DejaVu Sans',Arial,sans-serif;color:#1d1d1d;max-width:960px;margin:24px auto;padding:0 16px;background:#fff}
h1{font-size:24px;margin:0 0 2px}
h1 small{display:block;font-size:16px;font-weight:normal;color:#444}
h2{font-size:18px;border-bottom:1px solid #ccc;padding-bottom:3px;margin:28px 0 8px}
h3{font-size:15px;margin:16px 0 6px}
table{border-collapse:collapse;margin:6px 0 10px}
th,td{padding:2px 8px;border-bottom:1px solid #e4e4e4;text-align:left;vertical-align:top}
th{font-weight:600;background:#f4f4f4}
td.n,th.n{text-align:right;font-variant-numeric:tabular-nums;white-space:nowrap}
table.meta th{background:none;width:11em}
table.small{font-size:12px}
.mono{font-family:ui-monospace,'DejaVu Sans Mono',Menlo,Consolas,monospace;font-size:12px;word-break:break-all}
td.key{font-family:ui-monospace,'DejaVu Sans Mono',Menlo,Consolas,monospace;white-space:nowrap}
pre{font-size:12px;margin:4px 0;background:#f7f7f7;padding:6px 8px;overflow-x:auto}
.headline{border:1px solid #ccc;border-radius:6px;padding:10px 14px;margin:8px 0}
.big{display:inline-block;font-size:26px;font-weight:600;margin-right:28px;white-space:nowrap}
.ratio{color:#1f6fae;font-size:16px;font-weight:normal;margin-left:4px}
.warn{background:#fff4e0;border-left:4px solid #e6aa28;padding:6px 10px;margin:8px 0}
.muted,.marked{color:var(--muted)}
.b{color:#b85a15}.a{color:#1f6fae}
figure{margin:12px 0}
figcaption{font-size:13px;color:#444;margin-top:2px}
svg.plot{max-width:100%;height:auto;display:block}
.grid2{display:grid;grid-template-columns:1fr 1fr;gap:14px}
ul{margin:4px 0 8px;padding-left:22px}
footer{margin-top:32px;border-top:1px solid #ccc;font-size:12px;color:#555}
@page{size:A4;margin:14mm 12mm}
@media print{
body{max-width:none;margin:0;padding:0;font-size:10.5px}
h2{break-after:avoid;margin-top:18px}
figure,.headline,table.keep,tr{break-inside:avoid}
.big{font-size:20px}
pre,.mono{font-size:10px}
}
";

/// Labels of the solver settings worth a row of their own, by the JSON
/// pointer of the key in a result's `solver` block; those a method does
/// not have are left out.
const SETTINGS: [(&str, &str); 17] = [
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
fn setting(report: &SolverReport, pointer: &str) -> Option<String> {
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

/// What every section reads, computed once.
struct Ctx<'a> {
    input: &'a ReportInput<'a>,
    prepared: Result<&'a Prepared, String>,
    sha: String,
    method: String,
    ml: Option<&'a MlReport>,
    marks: BTreeMap<String, String>,
    /// σ of each `ml` parameter, by label.
    sigma: BTreeMap<String, Sigma>,
    /// Within-station pairs (Fig. 5) and which stations they are of.
    within: Vec<PairDistance>,
    within_of: &'static str,
    identify_within: BeforeAfter,
    excluded: Vec<String>,
}

impl<'a> Ctx<'a> {
    fn new(input: &'a ReportInput<'a>, prepared: Result<&'a Prepared, String>) -> Self {
        let result = input.result;
        let view = ResultView::new(result);
        Self {
            input,
            prepared,
            sha: sha256_hex(input.session_bytes),
            method: result.solver.method().to_string(),
            ml: result.solver.ml(),
            marks: view.marked,
            sigma: view.sigma,
            within: view.within,
            within_of: view.within_of.as_str(),
            identify_within: view.identify_within,
            excluded: excluded_measurements(input.session, result),
        }
    }

    fn result(&self) -> &ResultFile {
        self.input.result
    }

    fn session(&self) -> &Session {
        self.input.session
    }

    fn solver(&self) -> &SolverReport {
        &self.result().solver
    }
}

/// `v` with `d` decimals; `–` when not finite.
fn num(v: f64, d: usize) -> String {
    if v.is_finite() {
        format!("{v:.d$}")
    } else {
        "–".to_string()
    }
}

/// `v` with a sign and `d` decimals.
fn signed(v: f64, d: usize) -> String {
    if v.is_finite() {
        format!("{v:+.d$}")
    } else {
        "–".to_string()
    }
}

/// "76.0× lower" (or higher), empty when not defined.
fn ratio(before: f64, after: f64) -> String {
    if before > 0.0 && after > 0.0 {
        let r = before / after;
        if r >= 1.0 {
            format!("{r:.1}× lower")
        } else {
            format!("{:.1}× higher", 1.0 / r)
        }
    } else {
        String::new()
    }
}

fn section(h: &mut String, id: &str, title: &str) {
    let _ = write!(h, "<section id=\"{id}\">\n<h2>{}</h2>\n", escape(title));
}

fn end_section(h: &mut String) {
    h.push_str("</section>\n");
}

/// A `<th>` row of `th` headers; those starting with `#` are numeric
/// (right-aligned), the `#` dropped.
fn head_row(h: &mut String, cells: &[&str]) {
    h.push_str("<tr>");
    for c in cells {
        match c.strip_prefix('#') {
            Some(c) => {
                let _ = write!(h, "<th class=\"n\">{}</th>", escape(c));
            }
            None => {
                let _ = write!(h, "<th>{}</th>", escape(c));
            }
        }
    }
    h.push_str("</tr>\n");
}

/// A metadata row: the header and already escaped HTML.
fn meta_row(h: &mut String, key: &str, html: &str) {
    let _ = writeln!(h, "<tr><th>{}</th><td>{html}</td></tr>", escape(key));
}

fn header(h: &mut String, ctx: &Ctx<'_>) {
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
    meta_row(
        h,
        "Robot",
        &format!(
            "{} ({} joints, nominal model of the session)",
            escape(&s.robot.name),
            s.robot.dof()
        ),
    );
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

fn notes(h: &mut String, ctx: &Ctx<'_>) {
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
fn stats_rows(h: &mut String, what: &str, b: &Stats, a: &Stats) {
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

fn summary(h: &mut String, ctx: &Ctx<'_>) {
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
    match &headline {
        Some((what, b, a)) => {
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
        }
        None => h.push_str(
            "<p class=\"warn\" id=\"no-validation\">No validate measurements in this session: accuracy is not checked (no Fig. 6, no validation table).</p>\n",
        ),
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

/// `v` to 6 significant digits, without trailing zeros (1e-7 stays 1e-7).
fn short_number(v: f64) -> String {
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
fn scalar_text(v: &Value) -> Option<String> {
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

fn settings(h: &mut String, ctx: &Ctx<'_>) {
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
        },
        Err(_) => {
            h.push_str("<p>Initial hand-eye: unknown (the session could not be prepared).</p>\n")
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
fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let k = ((q * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len());
    sorted[k - 1]
}

/// `min – max` of an iterator, with `d` decimals.
fn range_text(values: impl Iterator<Item = f64>, d: usize) -> String {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    if lo.is_finite() {
        format!("{} – {}", num(lo, d), num(hi, d))
    } else {
        "–".to_string()
    }
}

fn stripes(h: &mut String, ctx: &Ctx<'_>) {
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
        .map(|(id, _)| *id)
        .unwrap_or("");
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

fn before_after_series(before: Vec<[f64; 2]>, after: Vec<[f64; 2]>) -> Vec<Series> {
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
fn bands(labels: impl Iterator<Item = String>) -> Vec<Band> {
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

fn figure(h: &mut String, id: &str, svg: &str, caption: &str) {
    let _ = writeln!(
        h,
        "<figure id=\"{id}\">{svg}<figcaption>{}</figcaption></figure>",
        escape(caption)
    );
}

fn figures(h: &mut String, ctx: &Ctx<'_>) {
    let r = ctx.result();
    section(h, "figures", "Before and after (cf. paper Fig. 5 and 6)");
    // Fig. 5.
    if ctx.within.is_empty() {
        h.push_str(
            "<p id=\"fig5\">No station has two measurements: no within-station distances.</p>\n",
        );
    } else {
        let pts = |f: fn(&PairDistance) -> f64| -> Vec<[f64; 2]> {
            ctx.within
                .iter()
                .enumerate()
                .map(|(k, p)| [(k + 1) as f64, f(p)])
                .collect()
        };
        let plot = Plot {
            title: format!(
                "Centre distances within {} stations, per pair, before and after",
                ctx.within_of
            ),
            x_label: "pair (station by station)".into(),
            y_label: "centre distance (mm)".into(),
            series: before_after_series(pts(|p| p.before), pts(|p| p.after)),
            bands: bands(ctx.within.iter().map(|p| p.station.clone())),
            include_zero: true,
            x_integer: true,
            width: WIDE,
            height: FIG_HEIGHT,
            ..Plot::default()
        };
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
        let pts = |f: fn(&crate::engine::validate::DistanceRecord) -> f64| -> Vec<[f64; 2]> {
            distances
                .iter()
                .enumerate()
                .map(|(k, d)| [(k + 1) as f64, f(d)])
                .collect()
        };
        let plot = Plot {
            title: "Reference-distance errors, measured − reference, before and after".into(),
            x_label: "distance (reference pair, pose by pose)".into(),
            y_label: "error (mm)".into(),
            series: before_after_series(
                pts(crate::engine::validate::DistanceRecord::error_before),
                pts(crate::engine::validate::DistanceRecord::error_after),
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
            width: WIDE,
            height: FIG_HEIGHT,
            ..Plot::default()
        };
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
    // ε, and the singular values of the paper's method.
    h.push_str("<div class=\"grid2\">\n");
    let eps: Vec<[f64; 2]> = r
        .iterations
        .iter()
        .enumerate()
        .map(|(k, i)| [k as f64, i.epsilon])
        .collect();
    let threshold = ctx.solver().threshold();
    let plot = Plot {
        title: "ε per update".into(),
        x_label: "update".into(),
        y_label: "ε (mm, log scale)".into(),
        series: vec![Series {
            name: "ε".into(),
            colour: AFTER_COLOUR.into(),
            points: eps,
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
        width: HALF,
        height: FIG_HEIGHT,
        ..Plot::default()
    };
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

fn singular_values(h: &mut String, ctx: &Ctx<'_>) {
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
    let smax = values.iter().copied().fold(0.0, f64::max);
    let kept = paper
        .and_then(|p| p.kept_directions)
        .unwrap_or(values.len());
    let cut = paper.and_then(|p| p.svd_tolerance).map(|t| t * smax);
    let pts = |keep: bool| -> Vec<[f64; 2]> {
        values
            .iter()
            .enumerate()
            .filter(|(k, v)| (*k < kept) == keep && **v > 0.0)
            .map(|(k, v)| [(k + 1) as f64, *v])
            .collect()
    };
    let zeros = values.iter().filter(|v| **v <= 0.0).count();
    let plot = Plot {
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
        width: HALF,
        height: FIG_HEIGHT,
        ..Plot::default()
    };
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

fn list(h: &mut String, id: &str, items: &[String]) {
    let _ = writeln!(h, "<ul id=\"{id}\">");
    for i in items {
        let _ = writeln!(h, "<li>{}</li>", escape(i));
    }
    h.push_str("</ul>\n");
}

fn identifiability(h: &mut String, ctx: &Ctx<'_>) {
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
            "<li>variance factor {} (≈ 1 when the noise model fits; the covariance is not rescaled by it)</li>",
            num(ml.variance_factor, 3)
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
        h.push_str("</ul>\n<p class=\"muted\">σ of every estimated parameter: in the hand-eye and joint-error tables below (± values).</p>\n");
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
fn marked_cell(ctx: &Ctx<'_>, label: &str, text: String) -> String {
    let sigma = ctx
        .sigma
        .get(label)
        .map(|s| format!(" <span class=\"muted\">± {}</span>", num(s.std, 4)))
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

/// Roll, pitch, yaw (deg) and translation (mm) of a hand-eye.
fn pose_parts(he: &nalgebra::Isometry3<f64>) -> ([f64; 3], [f64; 3]) {
    let v = HandEyeView::new(he);
    (v.translation, v.rpy_deg)
}

fn matrix_text(he: &nalgebra::Isometry3<f64>) -> String {
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

fn hand_eye(h: &mut String, ctx: &Ctx<'_>) {
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
            marked_cell(ctx, HAND_EYE_LABELS[k], num(a, 4)),
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

fn joint_errors(h: &mut String, ctx: &Ctx<'_>) {
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

fn validation(h: &mut String, ctx: &Ctx<'_>) {
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

fn outliers(h: &mut String, ctx: &Ctx<'_>) {
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

fn measurements(h: &mut String, ctx: &Ctx<'_>) {
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

fn solver_block(h: &mut String, ctx: &Ctx<'_>) {
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
