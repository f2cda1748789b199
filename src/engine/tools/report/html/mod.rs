//! The self-contained HTML report of a calibration: one file with inline
//! CSS and inline SVG figures ([`crate::engine::tools::report::svg`]), no script and no external
//! resource, printable on A4. It shows what the workbench's Results view
//! shows, plus the provenance a report needs:
//!
//! - header: session name and file, SHA-256 of the session file's bytes,
//!   robot, sphere, measurement counts, method, software version, date (UTC);
//! - notes when the result does not match the session;
//! - summary: the validation figures before → after (std, max, rms of the
//!   reference-distance errors; within-station distances), the identify
//!   stations' within-station distances, ε, the stop reason (and a warning
//!   when the paper's loop made ε worse), the held-out figure beside the
//!   fit's own scatter;
//! - for a fixed sensor (FORMAT.md `sensor.mount: "fixed"`), the sensor's
//!   pose in the base frame, the targets on the flange and each validate
//!   pose's prediction error;
//! - settings: every scalar of the result's `solver` block and where the
//!   initial hand-eye came from;
//! - stripe quality: fitted radii, arc spans, cut angles, fit RMS
//!   distribution, trimmed points, warnings (from [`solve::prepare`](fn@crate::engine::calibrate::solve::prepare));
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

mod css;
pub mod figures;
mod fixed;
mod tables;
mod text;

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::time::{SystemTime, UNIX_EPOCH};

use serde_json::{Map, Value};
use sha2::{Digest, Sha256};

use crate::engine::base::session::Session;
use crate::engine::calibrate::solve::ml::MlReport;
use crate::engine::calibrate::solve::{self, HeldOut, Prepared, SolverReport};
use crate::engine::calibrate::validate::BeforeAfter;
use crate::engine::files::format::result::ResultFile;
use crate::engine::tools::report::svg::escape;
use crate::engine::tools::result_view::{
    PairDistance, ResultFigures, Sigma, Tolerance, Verdict, check_result, excluded_measurements,
};
use css::CSS;
use figures::figures;
use tables::{
    hand_eye, identifiability, joint_errors, measurements, outliers, solver_block, validation,
};
use text::{header, notes, settings, stripes, summary};

/// The version written in the report: this crate's.
pub const SOFTWARE_VERSION: &str = env!("CARGO_PKG_VERSION");

/// Colour of the "before" series (nominal model, initial hand-eye); the
/// workbench's.
pub const BEFORE_COLOUR: &str = "#e67828";
/// Colour of the "after" series (calibrated); the workbench's.
pub const AFTER_COLOUR: &str = "#2896e6";
/// Colour of discarded values (dropped singular values).
const BAD_COLOUR: &str = "#e13c3c";

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
    /// them; `None` recomputes them with [`solve::prepare`](fn@crate::engine::calibrate::solve::prepare).
    pub prepared: Option<&'a Prepared>,
    /// File name, time and version.
    pub meta: &'a ReportMeta,
    /// The acceptance tolerance, when the operator set one: the summary
    /// then carries PASS or FAIL.
    pub tolerance: Option<Tolerance>,
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
    fixed::fixed_sensor(&mut h, &ctx);
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
    /// 3-D rms scatter of the identify centres, before and after, mm.
    identify_scatter: (f64, f64),
    excluded: Vec<String>,
    /// The verdict against the tolerance, when one is given.
    verdict: Option<(Verdict, Tolerance)>,
    /// 1σ of the hand-eye as tabled (flange-frame x, y, z; roll, pitch, yaw).
    hand_eye_sigma: Option<[f64; 6]>,
    /// The same a priori (the covariance as written).
    hand_eye_sigma_a_priori: Option<[f64; 6]>,
    /// The held-out figure, when the result has one.
    held_out: Option<HeldOut>,
    /// Warnings about the run (the paper's loop making ε worse).
    warnings: Vec<String>,
}

impl<'a> Ctx<'a> {
    fn new(input: &'a ReportInput<'a>, prepared: Result<&'a Prepared, String>) -> Self {
        let result = input.result;
        let view = ResultFigures::new(result);
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
            identify_scatter: view.identify_scatter,
            excluded: excluded_measurements(input.session, result),
            hand_eye_sigma: view.hand_eye_sigma,
            hand_eye_sigma_a_priori: view.hand_eye_sigma_a_priori,
            held_out: view.held_out,
            warnings: view.warnings,
            verdict: input
                .tolerance
                .map(|t| (Verdict::of(view.headline.as_ref(), &t), t)),
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
