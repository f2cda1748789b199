//! The HTML report (`engine::html_report`, `spherecal report`) at the level
//! of its text: every section, the session's SHA-256, escaping of every
//! text that comes from a file, no external resource, sessions without
//! validation or without stripes, identifiability marks of both methods,
//! the result-belongs-to-session check, and the command line.
//! `tests/cli/report_browser.rs` renders it in headless Chromium.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::time::{Duration, SystemTime, UNIX_EPOCH};

use crate::support::bin::run;
use serde_json::Value;
use sha2::{Digest, Sha256};
use spherecal::engine::base::robot::PARAM_NAMES;
use spherecal::engine::base::session::{self, Session};
use spherecal::engine::calibrate::solve::estimate::HAND_EYE_LABELS;
use spherecal::engine::calibrate::solve::{self, Method, Options};
use spherecal::engine::files::format::{self, ResultFile};
use spherecal::engine::tools::report::html::{
    self, ReportInput, ReportMeta, format_utc, sha256_hex,
};
use spherecal::engine::tools::result_view::{
    self, ReportError, check_result, excluded_measurements,
};

/// 2023-11-14 22:13:20 UTC.
const WHEN: u64 = 1_700_000_000;

fn when() -> SystemTime {
    UNIX_EPOCH + Duration::from_secs(WHEN)
}

fn sessions_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("sessions")
}

fn demo_value() -> Value {
    serde_json::from_str(spherecal::DEMO_SESSION_JSON).unwrap()
}

/// Session text, parsed session and a result of `method`.
fn calibrated(text: &str, method: Method) -> (Session, ResultFile) {
    let session = format::parse_session(text, Path::new("test.json")).unwrap();
    let mut options = Options::from_session(&session);
    options.method = method;
    let (_, cal) = solve::calibrate(&session, &options).unwrap();
    let result = ResultFile::from_calibration(&session, &cal);
    (session, result)
}

fn render(text: &str, session: &Session, result: &ResultFile) -> String {
    let meta = ReportMeta::new("sessions/test.json", when());
    html::render(&ReportInput {
        session,
        session_bytes: text.as_bytes(),
        result,
        prepared: None,
        meta: &meta,
        tolerance: None,
    })
}

fn demo_report(method: Method) -> (Session, ResultFile, String) {
    let text = spherecal::DEMO_SESSION_JSON;
    let (s, r) = calibrated(text, method);
    let html = render(text, &s, &r);
    (s, r, html)
}

/// Every tag name in the document (`<x` and `</x`).
fn tags(html: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = html;
    while let Some(i) = rest.find('<') {
        rest = &rest[i + 1..];
        let name: String = rest
            .trim_start_matches('/')
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '!')
            .collect();
        out.push(name.to_ascii_lowercase());
    }
    out
}

/// The elements the report is made of; anything else came from a file.
const ALLOWED_TAGS: [&str; 32] = [
    "!doctype",
    "html",
    "head",
    "meta",
    "title",
    "style",
    "body",
    "header",
    "footer",
    "section",
    "h1",
    "h2",
    "h3",
    "small",
    "p",
    "div",
    "span",
    "strong",
    "ul",
    "li",
    "table",
    "tr",
    "th",
    "td",
    "pre",
    "figure",
    "figcaption",
    "svg",
    "rect",
    "line",
    "text",
    "polyline",
];

fn assert_only_report_tags(html: &str) {
    for t in tags(html) {
        assert!(
            ALLOWED_TAGS.contains(&t.as_str()) || t == "path" || t == "circle",
            "unexpected element <{t}> in the report"
        );
    }
}

#[test]
fn every_section_the_sha256_and_the_headline() {
    let (_, result, html) = demo_report(Method::Ml);
    assert!(html.starts_with("<!DOCTYPE html>"));
    assert!(html.trim_end().ends_with("</html>"));
    for id in [
        "header",
        "sha256",
        "summary",
        "settings",
        "stripes",
        "figures",
        "fig5",
        "fig5-after",
        "fig6-after",
        "fig6",
        "epsilon",
        "identifiability",
        "hand-eye",
        "joints",
        "joint-errors",
        "validation",
        "distances",
        "validate-stations",
        "outliers",
        "excluded",
        "measurements",
        "measurement-table",
        "solver-block",
    ] {
        assert!(html.contains(&format!("id=\"{id}\"")), "no element #{id}");
    }
    // The SHA-256 of the bytes, computed here independently.
    let digest = Sha256::digest(spherecal::DEMO_SESSION_JSON.as_bytes());
    let hex: String = digest.iter().map(|b| format!("{b:02x}")).collect();
    assert_eq!(hex.len(), 64);
    assert_eq!(sha256_hex(spherecal::DEMO_SESSION_JSON.as_bytes()), hex);
    assert!(html.contains(&format!("<span class=\"mono\" id=\"sha256\">{hex}</span>")));
    // Version, date, file, robot.
    assert!(html.contains(&format!("spherecal {}", env!("CARGO_PKG_VERSION"))));
    assert!(html.contains("2023-11-14 22:13:20 UTC"), "date");
    assert!(html.contains("sessions/test.json"));
    assert!(html.contains("ABB IRB 2400/16"));
    // The headline equals the result's validation figures.
    let v = result.validation.as_ref().unwrap();
    let headline = format!("std {:.3} → {:.3} mm", v.before.std, v.after.std);
    assert!(html.contains(&headline), "{headline}");
    assert!(html.contains(&format!("max {:.3} → {:.3} mm", v.before.max, v.after.max)));
    // Every distance is a row of the validation table.
    let table = &html[html.find("id=\"distances\"").unwrap()..];
    let table = &table[..table.find("</table>").unwrap()];
    assert_eq!(table.matches("<tr><td>").count(), v.distances.len());
    // ml: Fig. 5, Fig. 6 and ε are plotted, each SVG with a title, axes
    // labelled with units and a legend of both series; Fig. 5's and 6's
    // after series alone (issue 34); and the map of the predicted error
    // over the region the sphere covered.
    assert_eq!(html.matches("<svg").count(), 6);
    assert!(html.contains("id=\"range-map\""));
    assert!(html.contains("centre distance (mm)") && html.contains("error (mm)"));
    assert!(html.contains("ε (mm, log scale)"));
    assert_eq!(
        html.matches("before (nominal model, initial hand-eye)")
            .count(),
        2
    );
    assert!(html.contains(html::BEFORE_COLOUR) && html.contains(html::AFTER_COLOUR));
    // ml: σ beside the estimates, the fixed set marked.
    assert!(html.contains("id=\"fixed\""));
    assert!(html.contains(" ± "));
    assert!(
        html.contains("title=\"theta1: held fixed"),
        "theta1 is marked"
    );
    // The stripe summary: 124 stripes, the one trimmed point of c52.
    assert!(html.contains("124 of 124 measurements"));
    assert!(html.contains("<strong>c52</strong>"));
    assert_only_report_tags(&html);
    assert!(!html.contains("NaN") && !html.contains("inf<"));
}

#[test]
fn the_report_is_a_function_of_its_input() {
    let text = spherecal::DEMO_SESSION_JSON;
    let (s, r) = calibrated(text, Method::Paper);
    assert_eq!(render(text, &s, &r), render(text, &s, &r));
    // Other bytes, other SHA.
    let other = format!("{text}\n");
    assert_ne!(render(text, &s, &r), render(&other, &s, &r));
}

#[test]
fn a_saved_and_reloaded_result_gives_the_same_report() {
    // The workbench reports a run, the command line a result file: the
    // same figures either way.
    let text = spherecal::DEMO_SESSION_JSON;
    let (s, r) = calibrated(text, Method::Ml);
    let reloaded = format::parse_result(&format::result_to_json(&r), Path::new("r.json")).unwrap();
    assert_eq!(render(text, &s, &r), render(text, &s, &reloaded));
}

#[test]
fn no_external_resource_and_no_script() {
    let (_, _, html) = demo_report(Method::Paper);
    let lower = html.to_ascii_lowercase();
    for bad in [
        "http:", "https:", "<script", "<link", "<img", "<iframe", "url(", "@import", "href=",
    ] {
        assert!(!lower.contains(bad), "the report contains {bad}");
    }
    for (i, _) in lower.match_indices("src=") {
        assert!(
            lower[i..].starts_with("src=\"data:"),
            "src= other than data:"
        );
    }
    // Inline CSS with print rules for A4.
    assert!(html.contains("<style>") && html.contains("@page{size:A4"));
}

#[test]
fn text_from_files_is_escaped() {
    let mut v = demo_value();
    v["name"] = Value::from("<script>alert('x')</script> & <b>bold</b>");
    v["robot"]["name"] = Value::from("R<1>");
    let rename = |s: &mut Value| {
        if s.as_str() == Some("V1") {
            *s = Value::from("V<1>&\"");
        }
    };
    for m in v["measurements"].as_array_mut().unwrap() {
        rename(&mut m["station"]);
        if m["id"] == "c1" {
            m["id"] = Value::from("c<i>1");
        }
    }
    for d in v["reference_distances"].as_array_mut().unwrap() {
        rename(&mut d["from"]);
        rename(&mut d["to"]);
    }
    let text = serde_json::to_string_pretty(&v).unwrap();
    let (s, r) = calibrated(&text, Method::Ml);
    let html = render(&text, &s, &r);
    assert!(!html.contains("<script") && !html.contains("<b>") && !html.contains("<i>"));
    assert!(!html.contains("R<1>") && !html.contains("V<1>"));
    assert!(
        html.contains(
            "&lt;script&gt;alert(&#39;x&#39;)&lt;/script&gt; &amp; &lt;b&gt;bold&lt;/b&gt;"
        )
    );
    assert!(html.contains("<title>Calibration report: &lt;script&gt;"));
    assert!(html.contains("R&lt;1&gt;"));
    // In tables and in the SVG band labels of Fig. 5 and Fig. 6.
    assert!(html.contains("V&lt;1&gt;&amp;&quot; → V2"));
    assert!(html.contains(">V&lt;1&gt;&amp;&quot;</text>"));
    assert!(html.contains(">V&lt;1&gt;&amp;&quot;→V2</text>"));
    assert!(html.contains("c&lt;i&gt;1"));
    assert_only_report_tags(&html);
}

#[test]
fn a_session_without_validation_says_so() {
    let mut v = demo_value();
    v["measurements"]
        .as_array_mut()
        .unwrap()
        .retain(|m| m["use"] != "validate");
    v.as_object_mut().unwrap().remove("reference_distances");
    let text = serde_json::to_string_pretty(&v).unwrap();
    let (s, r) = calibrated(&text, Method::Ml);
    assert!(r.validation.is_none());
    let html = render(&text, &s, &r);
    assert!(html.contains("id=\"no-validation\""));
    assert!(html.contains("No validate measurements in this session: accuracy is not checked"));
    assert!(
        html.contains("<p id=\"fig6\" class=\"warn\">The session has no validate measurements")
    );
    assert!(!html.contains("id=\"distances\""));
    // Fig. 5 falls back to the identify stations; ε is still plotted.
    assert!(html.contains("Centre distances within identify stations"));
    // Fig. 5 (and its after series alone), ε and the map of the predicted
    // error over the region the sphere covered (ml; no sensor.range).
    assert_eq!(html.matches("<svg").count(), 4);
    assert!(html.contains("id=\"range-map\""));
    assert_only_report_tags(&html);
}

#[test]
fn the_papers_method_marks_the_dropped_directions() {
    let (_, result, html) = demo_report(Method::Paper);
    assert!(html.contains("<strong>paper</strong> method kept"));
    assert!(html.contains("id=\"dropped\""));
    // Fig. 5, Fig. 6 (each with its after series alone), ε and the
    // singular values with the truncation line.
    assert_eq!(html.matches("<svg").count(), 6);
    assert!(html.contains("truncation"));
    let marks = result_view::identifiability_marks(&result.solver);
    assert!(!marks.is_empty() && marks.contains_key("theta1"));
    // Every mark of a joint or hand-eye parameter is a marked cell.
    let mut labels: Vec<String> = HAND_EYE_LABELS
        .iter()
        .map(std::string::ToString::to_string)
        .collect();
    for j in 1..=6 {
        labels.extend(PARAM_NAMES.iter().map(|p| format!("{p}{j}")));
    }
    assert!(marks.keys().all(|k| labels.contains(k)), "{marks:?}");
    let marked = html.matches("class=\"n marked\" title=").count();
    assert_eq!(marked, marks.len(), "{marks:?}");
    assert!(!html.contains(" ± "), "the paper's method has no σ");
}

#[test]
fn a_centre_session_has_no_stripe_fits() {
    let path = sessions_dir().join("centres-irb2400.json");
    let text = std::fs::read_to_string(path).unwrap();
    let (s, r) = calibrated(&text, Method::Ml);
    let html = render(&text, &s, &r);
    assert!(html.contains("No stripes: all 124 measurements give the sphere centre directly"));
    assert!(html.contains("centre given"));
}

#[test]
fn a_result_must_belong_to_its_session() {
    let text = spherecal::DEMO_SESSION_JSON;
    let (demo, result) = calibrated(text, Method::Paper);
    let prepared = solve::prepare(&demo).unwrap();
    assert_eq!(check_result(&demo, &result, Some(&prepared)), Ok(()));
    // Another session.
    let ur5e_text = std::fs::read_to_string(sessions_dir().join("ur5e.json")).unwrap();
    let ur5e = format::parse_session(&ur5e_text, Path::new("ur5e.json")).unwrap();
    assert!(matches!(
        check_result(&ur5e, &result, None),
        Err(ReportError::OtherSession { .. })
    ));
    // Same name, a measurement moved to another station.
    let mut other = result.clone();
    other.centres[20].station = "P9".into();
    assert!(matches!(
        check_result(&demo, &other, None),
        Err(ReportError::Differs {
            what: "station",
            ..
        })
    ));
    // Same name and ids, other stripe data.
    let mut other = result.clone();
    other.centres[30].sensor[1] += 1e-3;
    let e = check_result(&demo, &other, Some(&prepared)).unwrap_err();
    assert!(matches!(e, ReportError::OtherData { .. }), "{e}");
    assert!(e.to_string().contains(&other.centres[30].measurement));
    // An unknown id.
    let mut other = result.clone();
    other.centres[0].measurement = "nope".into();
    assert!(matches!(
        check_result(&demo, &other, None),
        Err(ReportError::UnknownMeasurement { .. })
    ));
    // The report of a mismatched result says so at the top.
    let html = render(text, &demo, &other);
    assert!(html.contains("The result may not belong to this session"));
}

#[test]
fn measurements_left_out_are_listed() {
    let text = spherecal::DEMO_SESSION_JSON;
    let demo = format::parse_session(text, Path::new("demo.json")).unwrap();
    let fewer =
        session::exclude_measurements(&demo, &["c5".to_string(), "v7".to_string()]).unwrap();
    let (_, cal) = solve::calibrate(&fewer, &Options::from_session(&fewer)).unwrap();
    let result = ResultFile::from_calibration(&fewer, &cal);
    // Reported against the full session: the ids are its own.
    assert_eq!(check_result(&demo, &result, None), Ok(()));
    assert_eq!(excluded_measurements(&demo, &result), ["c5", "v7"]);
    let html = render(text, &demo, &result);
    assert!(html.contains("Left out of this run (2 measurement(s)"));
    assert_eq!(
        html.matches("<td class=\"marked\">left out</td>").count(),
        2
    );
}

#[test]
fn dates_are_utc_to_the_second() {
    assert_eq!(format_utc(when()), "2023-11-14 22:13:20 UTC");
    assert_eq!(format_utc(UNIX_EPOCH), "1970-01-01 00:00:00 UTC");
    assert_eq!(
        format_utc(UNIX_EPOCH + Duration::from_millis(1_999)),
        "1970-01-01 00:00:01 UTC"
    );
    assert_eq!(
        format_utc(UNIX_EPOCH - Duration::from_secs(1)),
        "unknown date"
    );
}

// ---------------------------------------------------------------------------
// The command line
// ---------------------------------------------------------------------------

fn files_in(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn cli_report_calibrates_or_reports_a_given_result() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let session = d.join("demo.json");
    std::fs::write(&session, spherecal::DEMO_SESSION_JSON).unwrap();
    let out = d.join("report.html");
    // Without --result: calibrated with the default method (ml).
    let (status, stdout, stderr) = run(&[
        "report".as_ref(),
        session.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    assert_eq!(status, 0, "{stderr}");
    assert!(stdout.contains("a run of method ml"), "{stdout}");
    let html = std::fs::read_to_string(&out).unwrap();
    assert!(html.starts_with("<!DOCTYPE html>") && html.contains("<strong>ml</strong> method"));
    assert!(html.contains(&sha256_hex(spherecal::DEMO_SESSION_JSON.as_bytes())));
    assert_eq!(
        files_in(d),
        ["demo.json", "report.html"],
        "no temporary file left"
    );
    // With --result (of the paper's method): reported as it is, not rerun
    // (a run would use ml).
    let result = d.join("paper.json");
    let (status, _, stderr) = run(&[
        "calibrate".as_ref(),
        session.as_os_str(),
        "--method".as_ref(),
        "paper".as_ref(),
        "-q".as_ref(),
        "--out".as_ref(),
        result.as_os_str(),
    ]);
    assert_eq!(status, 0, "{stderr}");
    let (status, stdout, stderr) = run(&[
        "report".as_ref(),
        session.as_os_str(),
        "--result".as_ref(),
        result.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    assert_eq!(status, 0, "{stderr}");
    assert!(stdout.contains("the given result"), "{stdout}");
    let html = std::fs::read_to_string(&out).unwrap();
    assert!(html.contains("<strong>paper</strong> method kept"));
    let loaded = format::load_result(&result).unwrap();
    let v = loaded.validation.unwrap();
    assert!(html.contains(&format!("std {:.3} → {:.3} mm", v.before.std, v.after.std)));
}

#[test]
fn cli_report_rejects_bad_input_with_one_error_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let demo = d.join("demo.json");
    std::fs::write(&demo, spherecal::DEMO_SESSION_JSON).unwrap();
    let ur5e = sessions_dir().join("ur5e.json");
    let result = d.join("ur5e.result.json");
    let (status, _, stderr) = run(&[
        "calibrate".as_ref(),
        ur5e.as_os_str(),
        "-q".as_ref(),
        "--out".as_ref(),
        result.as_os_str(),
    ]);
    assert_eq!(status, 0, "{stderr}");
    let out = d.join("report.html");
    let bad_json = d.join("bad.json");
    std::fs::write(&bad_json, "{ \"format\": \"spherecal-session\", ").unwrap();
    let missing = d.join("missing.json");
    let cases: Vec<(Vec<&std::ffi::OsStr>, &str)> = vec![
        (
            vec![demo.as_os_str(), "--result".as_ref(), result.as_os_str()],
            "does not belong to",
        ),
        (vec![missing.as_os_str()], "missing.json"),
        (vec![bad_json.as_os_str()], "bad.json"),
        (
            vec![demo.as_os_str(), "--result".as_ref(), demo.as_os_str()],
            "demo.json",
        ),
    ];
    for (args, needle) in cases {
        let mut all: Vec<&std::ffi::OsStr> = vec!["report".as_ref()];
        all.extend(args);
        all.extend(["-o".as_ref(), out.as_os_str()]);
        let (status, _, stderr) = run(&all);
        assert_eq!(status, 2, "{all:?}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(
            stderr.starts_with("error: ") && stderr.contains(needle),
            "{stderr}"
        );
        assert!(!out.exists(), "no report on bad input");
    }
}
