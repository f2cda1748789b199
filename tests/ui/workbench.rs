//! UI tests: egui_kittest drives the real workbench (no display, no GPU).
//! Widgets are found by their labels, clicked, and the app's state and
//! shown text are checked against the engine run headless.

#![cfg(feature = "gui")]
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::path::Path;
use std::time::Duration;

use egui_kittest::Harness;
use egui_kittest::kittest::{NodeT as _, Queryable as _};
use spherecal::app::WorkbenchApp;
use spherecal::app::command::Tab;
use spherecal::app::job::Slot;
use spherecal::engine::calibrate::solve::{Options, calibrate};
use spherecal::engine::files::format::parse_session;
use spherecal::engine::tools::report::model::{self, ModelFormat};

use crate::support::ui as ui_support;
use ui_support::{demo_app, open_path, settle};

/// The text of every label that starts with `prefix`.
fn labels_starting(h: &Harness<'_, WorkbenchApp>, prefix: &str) -> Vec<String> {
    h.query_all_by_label_contains(prefix)
        .filter_map(|n| {
            let a = n.accesskit_node();
            a.value().or_else(|| a.label())
        })
        .filter(|l| l.starts_with(prefix))
        .collect()
}

/// The numbers in `text`, in order (accepts a leading sign and decimals).
fn numbers(text: &str) -> Vec<f64> {
    text.split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-'))
        .filter_map(|t| t.parse::<f64>().ok())
        .collect()
}

#[test]
fn demo_loads_select_run_and_headline_matches_engine() {
    let mut h = demo_app();
    let session = parse_session(
        spherecal::DEMO_SESSION_JSON,
        Path::new(spherecal::DEMO_SESSION_NAME),
    )
    .expect("demo session parses");

    // Select a measurement: the Stripe view's Next button, then an arrow key.
    h.get_by_label("Stripe").click();
    h.run();
    h.get_by_label("Next ▶").click();
    h.run();
    assert_eq!(h.state().state().selected, Some(1));
    h.key_press(egui::Key::ArrowDown);
    h.run();
    assert_eq!(h.state().state().selected, Some(2));
    assert_eq!(h.state().forms().tab, Tab::Stripe);
    let id = &session.measurements[2].id;
    let chooser = h.get_by_label("measurement").accesskit_node().value();
    assert_eq!(
        chooser.as_deref(),
        Some(id.as_str()),
        "the stripe view shows {id}"
    );

    // Run the solver to the end: the operator stays on the Stripe view,
    // the status line says the results are ready and the Results tab is
    // marked until it is opened.
    h.get_by_label("▶ Run").click();
    settle(&mut h);
    assert_eq!(
        h.state().forms().tab,
        Tab::Stripe,
        "a finished run leaves the operator where they are"
    );
    assert!(h.state().state().result_unseen);
    assert!(
        h.query_all_by_label_contains("results ready").count() > 0,
        "the status line says the results are ready"
    );
    h.get_by_label("Results ●").click();
    settle(&mut h);
    assert_eq!(h.state().forms().tab, Tab::Results);
    assert!(!h.state().state().result_unseen);
    assert!(
        h.query_by_label("Results ●").is_none(),
        "the mark goes once the results are seen"
    );

    // The engine's own answer on the same session and settings.
    let (_, cal) =
        calibrate(&session, &Options::from_session(&session)).expect("engine calibrates the demo");
    let v = cal.validation.expect("the demo has validate measurements");

    // Read the after-std from the headline: "std <before> → <after> mm".
    let std_lines = labels_starting(&h, "std ");
    assert_eq!(
        std_lines.len(),
        1,
        "one headline std line, got {std_lines:?}"
    );
    let n = numbers(&std_lines[0]);
    assert_eq!(n.len(), 2, "before and after in {:?}", std_lines[0]);
    assert!(
        (n[0] - v.before.std).abs() < 6e-4,
        "before std {} vs engine {}",
        n[0],
        v.before.std
    );
    assert!(
        (n[1] - v.after.std).abs() < 6e-4,
        "after std {} vs engine {}",
        n[1],
        v.after.std
    );
    let max_lines = labels_starting(&h, "max ");
    let m = numbers(&max_lines[0]);
    assert!(
        (m[1] - v.after.max).abs() < 6e-4,
        "after max {} vs engine {}",
        m[1],
        v.after.max
    );

    // The view model holds exactly the engine's figures.
    let view = h
        .state()
        .state()
        .result
        .as_ref()
        .expect("a result is shown");
    assert_eq!(view.epsilons(), cal.iterations);
    assert!(
        view.shown
            .headline
            .as_ref()
            .is_some_and(|hl| hl.stats.after == v.after)
    );
}

#[test]
fn bad_file_shows_its_error_and_the_app_stays_usable() {
    let mut h = demo_app();
    // The demo with a stripe cut to 3 points: a load error naming the measurement.
    let mut doc: serde_json::Value =
        serde_json::from_str(spherecal::DEMO_SESSION_JSON).expect("demo is JSON");
    let bad_id = doc["measurements"][2]["id"]
        .as_str()
        .expect("id")
        .to_string();
    let points = doc["measurements"][2]["stripe"]["points"]
        .as_array()
        .expect("stripe")
        .clone();
    doc["measurements"][2]["stripe"]["points"] = serde_json::Value::Array(points[..3].to_vec());
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("broken-session.json");
    std::fs::write(&path, serde_json::to_string(&doc).expect("json")).expect("write");

    h.get_by_label("Session or result file").click();
    h.run();
    h.get_by_label("Session or result file")
        .type_text(&path.display().to_string());
    h.run();
    h.get_by_label("Open path").click();
    settle(&mut h);

    let notice = h.state().state().notice.clone().expect("an error is shown");
    assert!(notice.title.contains("broken-session.json"), "{notice:?}");
    assert!(
        notice.body.contains(&bad_id),
        "the message names measurement {bad_id}: {notice:?}"
    );
    assert!(
        h.query_by_label(&notice.body).is_some(),
        "the message is shown in the window"
    );
    // The demo is still open and the app still works.
    assert_eq!(
        h.state()
            .state()
            .loaded
            .as_ref()
            .map(|l| l.session.name.clone()),
        Some(session_name())
    );
    h.get_by_label("Dismiss").click();
    h.run();
    assert!(h.state().state().notice.is_none());
    h.get_by_label("▶ Run").click();
    settle(&mut h);
    assert!(
        h.state().state().result.is_some(),
        "a run still works after the error"
    );
}

fn session_name() -> String {
    parse_session(
        spherecal::DEMO_SESSION_JSON,
        Path::new(spherecal::DEMO_SESSION_NAME),
    )
    .expect("demo parses")
    .name
}

#[test]
fn cancel_stops_a_run() {
    let mut h = demo_app();
    // A run long enough to cancel: ml on a session of 2,470 measurements
    // (400 identify stations), whose every phase (LM steps, covariance,
    // leave-one-station-out over 400 stations) checks the cancel flag.
    // Without a working Cancel the run ends with a result and the test
    // fails.
    let dir = tempfile::tempdir().expect("temp dir");
    let (session, _) = spherecal::engine::tools::simulate::simulate(
        &spherecal::engine::tools::simulate::SimConfig {
            n_identify: 400,
            ..spherecal::engine::tools::simulate::SimConfig::default()
        },
    )
    .expect("simulate");
    let path = dir.path().join("big.json");
    spherecal::engine::files::format::save_session(&session, &path).expect("save");
    open_path(&mut h, path);
    assert_eq!(
        h.state()
            .state()
            .loaded
            .as_ref()
            .map(|l| l.session.measurements.len()),
        Some(session.measurements.len())
    );
    h.get_by_label("▶ Run").click();
    // Let the run get going (the window repaints while it works).
    for _ in 0..10 {
        h.step();
        std::thread::sleep(Duration::from_millis(5));
    }
    assert!(h.state().is_busy(), "the long run is under way");
    h.get_by_label("Cancel").click();
    settle(&mut h);
    let state = h.state().state();
    assert!(state.jobs.get(&Slot::Run).is_none());
    assert!(state.result.is_none(), "a cancelled run shows no result");
    let status = state
        .status
        .as_ref()
        .map(|s| s.text.clone())
        .unwrap_or_default();
    assert!(status.contains("cancelled"), "status: {status}");
}

#[test]
fn left_out_measurements_are_saved_and_a_bad_exclusion_is_refused() {
    let mut h = demo_app();
    let session = parse_session(
        spherecal::DEMO_SESSION_JSON,
        Path::new(spherecal::DEMO_SESSION_NAME),
    )
    .expect("demo parses");
    let dir = tempfile::tempdir().expect("temp dir");
    let target = dir.path().join("demo-edited.json");
    // Show the last measurement's station only, then leave the measurement
    // out by unticking its checkbox.
    let last = session.measurements.last().expect("measurements");
    assert_eq!(last.usage, spherecal::engine::base::session::Use::Validate);
    h.state_mut().forms_mut().filter_station = Some(last.station.clone());
    h.run();
    h.get_by_label(&last.id).click();
    h.run();
    assert!(h.state().state().excluded.contains(&last.id));
    h.state_mut().forms_mut().save_path = target.display().to_string();
    h.get_by_label("Save").click();
    settle(&mut h);
    let saved =
        spherecal::engine::files::format::load_session(&target).expect("the saved file loads");
    assert_eq!(saved.measurements.len(), session.measurements.len() - 1);
    assert!(saved.measurements.iter().all(|m| m.id != last.id));

    // Leaving out every rotation measurement breaks a FORMAT rule: refused.
    let rotation_station = session
        .measurements
        .iter()
        .find(|m| m.usage == spherecal::engine::base::session::Use::Rotation)
        .expect("rotation")
        .station
        .clone();
    let ctx = h.ctx.clone();
    for m in session
        .measurements
        .iter()
        .filter(|m| m.station == rotation_station)
    {
        h.state_mut().command(
            &ctx,
            spherecal::app::command::Command::View(
                spherecal::app::command::ViewCommand::SetIncluded {
                    id: m.id.clone(),
                    included: false,
                },
            ),
        );
    }
    let other = dir.path().join("broken.json");
    h.state_mut().forms_mut().save_path = other.display().to_string();
    h.get_by_label("Save").click();
    settle(&mut h);
    assert!(
        !other.exists(),
        "a session that breaks a rule is not written"
    );
    let notice = h
        .state()
        .state()
        .notice
        .clone()
        .expect("the refusal is shown");
    assert!(notice.body.contains("not valid"), "{notice:?}");
}

#[test]
fn a_result_file_is_reviewed_without_running_the_solver() {
    let mut h = demo_app();
    let session = parse_session(
        spherecal::DEMO_SESSION_JSON,
        Path::new(spherecal::DEMO_SESSION_NAME),
    )
    .expect("demo parses");
    let (_, cal) = calibrate(&session, &Options::from_session(&session)).expect("calibrates");
    let file = spherecal::engine::files::format::ResultFile::from_calibration(&session, &cal);
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("demo-result.json");
    spherecal::engine::files::format::save_result(&file, &path).expect("saves");

    h.get_by_label("Session or result file").click();
    h.run();
    h.get_by_label("Session or result file")
        .type_text(&path.display().to_string());
    h.run();
    h.get_by_label("Open path").click();
    settle(&mut h);
    let view = h
        .state()
        .state()
        .result
        .as_ref()
        .expect("the result is shown");
    assert!(matches!(
        view.origin,
        spherecal::app::results::ResultOrigin::Review(_)
    ));
    assert!(
        view.notes.is_empty(),
        "the result matches the open session: {:?}",
        view.notes
    );
    assert_eq!(h.state().forms().tab, Tab::Results);
    let v = cal.validation.expect("validation");
    let n = numbers(&labels_starting(&h, "std ")[0]);
    assert!((n[1] - v.after.std).abs() < 6e-4);
    assert!(
        h.query_all_by_label_contains("the solver was not run")
            .count()
            > 0,
        "the view says it is a review"
    );
}

#[test]
fn exports_are_written_to_the_chosen_folder() {
    let mut h = demo_app();
    h.get_by_label("▶ Run").click();
    settle(&mut h);
    h.get_by_label("Results ●").click();
    settle(&mut h);
    let dir = tempfile::tempdir().expect("temp dir");
    h.state_mut().forms_mut().export_dir = dir.path().display().to_string();
    for button in [
        "Result JSON",
        "Centres CSV",
        "Distances CSV",
        "Model JSON",
        "Model CSV",
        "Model URDF",
        "Report HTML",
    ] {
        h.get_by_label(button).click();
        settle(&mut h);
    }
    let stem = "demo-irb2400";
    let result = spherecal::engine::files::format::load_result(
        &dir.path().join(format!("{stem}-result.json")),
    )
    .expect("the exported result loads");
    let shown = h.state().state().result.as_ref().expect("result");
    assert_eq!(result, shown.file, "the export is the result on show");
    let centres =
        std::fs::read_to_string(dir.path().join(format!("{stem}-centres.csv"))).expect("centres");
    assert_eq!(centres.lines().count(), 1 + shown.file.centres.len());
    let distances = std::fs::read_to_string(dir.path().join(format!("{stem}-distances.csv")))
        .expect("distances");
    assert_eq!(
        distances.lines().count(),
        1 + shown.shown.distances.len() + shown.shown.within.len()
    );
    for (ext, format) in [
        ("json", ModelFormat::Json),
        ("csv", ModelFormat::Csv),
        ("urdf", ModelFormat::Urdf),
    ] {
        let written = std::fs::read_to_string(dir.path().join(format!("{stem}-model.{ext}")))
            .expect("model file");
        let source = format!("a workbench run of {}", shown.file.session);
        let expected = model::export(&shown.file, format, &source).expect("exports");
        assert_eq!(written, expected, "the {ext} model is the engine's export");
    }
    let report =
        std::fs::read_to_string(dir.path().join(format!("{stem}-report.html"))).expect("report");
    let sha =
        spherecal::engine::tools::report::html::sha256_hex(spherecal::DEMO_SESSION_JSON.as_bytes());
    assert!(report.starts_with("<!DOCTYPE html>"));
    assert!(
        report.contains(&sha),
        "the report carries the session's SHA-256"
    );
    assert!(report.contains(&shown.file.session));
    assert!(
        report.matches("<svg").count() >= 3,
        "figures are inline SVG"
    );
    assert_eq!(
        h.state().state().prefs.export_folder.as_deref(),
        Some(dir.path()),
        "the folder is remembered"
    );
}

#[test]
fn clicking_a_centre_in_the_3d_view_selects_its_measurement() {
    let mut h = demo_app();
    h.get_by_label("Centres").click();
    h.run();
    let rect = h
        .get_by_label(spherecal::app::results::centres::ORBIT_LABEL)
        .rect();
    let positions = {
        let app = h.state();
        let set = app
            .state()
            .loaded
            .as_ref()
            .and_then(|l| l.before.as_ref().ok())
            .expect("centres before calibration");
        spherecal::app::results::centres::orbit_positions(set, &app.forms().centres, rect)
    };
    // A centre well inside the view that no other centre covers: a click on
    // it picks the nearest marker, itself.
    let (pos, index) = positions
        .iter()
        .filter(|(p, i)| i.is_some() && rect.shrink(20.0).contains(*p))
        .find(|(p, i)| {
            positions
                .iter()
                .all(|(q, j)| j == i || p.distance(*q) > 2.0)
        })
        .copied()
        .expect("an isolated centre");
    let index = index.expect("measurement index");
    assert_ne!(h.state().state().selected, Some(index));
    for pressed in [true, false] {
        h.event(egui::Event::PointerButton {
            pos,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: egui::Modifiers::NONE,
        });
    }
    h.run();
    assert_eq!(h.state().state().selected, Some(index));
}

/// Writes the demo session's poses as a KUKA-style joint log (`Pose`,
/// `Sphere`, `Use`, `Side`, `A1`..`A6`) and one profile CSV per pose.
pub(super) fn write_import_files(dir: &Path) -> spherecal::engine::base::session::Session {
    use std::fmt::Write as _;
    let session = parse_session(
        spherecal::DEMO_SESSION_JSON,
        Path::new(spherecal::DEMO_SESSION_NAME),
    )
    .expect("demo parses");
    let profiles = dir.join("profiles");
    std::fs::create_dir_all(&profiles).expect("profiles folder");
    let mut log = String::from("Pose,Sphere,Use,Side,A1,A2,A3,A4,A5,A6\n");
    for m in &session.measurements {
        write!(
            log,
            "{},{},{},{}",
            m.id,
            m.station,
            m.usage.as_str(),
            m.side
        )
        .unwrap();
        for q in &m.joints {
            write!(log, ",{q}").unwrap();
        }
        log.push('\n');
        let spherecal::engine::base::session::Observation::Stripe(points) = &m.observation else {
            panic!("the demo has stripes");
        };
        let mut p = String::from("y,z\n");
        for [y, z] in points {
            writeln!(p, "{y},{z}").unwrap();
        }
        std::fs::write(profiles.join(format!("{}.csv", m.id)), p).expect("profile");
    }
    std::fs::write(dir.join("joints.csv"), log).expect("log");
    let mut refs = String::from("from,to,distance\n");
    for r in &session.reference_distances {
        writeln!(refs, "{},{},{}", r.from, r.to, r.distance).unwrap();
    }
    std::fs::write(dir.join("references.csv"), refs).expect("references");
    session
}

fn type_into(h: &mut Harness<'_, WorkbenchApp>, label: &str, text: &str) {
    h.get_by_label(label).click();
    h.run();
    h.get_by_label(label).type_text(text);
    h.run();
}

#[test]
fn the_import_wizard_guesses_the_mapping_previews_and_opens_the_session() {
    let mut h = demo_app();
    let dir = tempfile::tempdir().expect("temp dir");
    let original = write_import_files(dir.path());
    h.get_by_label("Import").click();
    h.run();
    assert_eq!(h.state().forms().tab, Tab::Import);
    let joints = dir.path().join("joints.csv");
    type_into(&mut h, "Joint log CSV", &joints.display().to_string());
    let profiles = dir.path().join("profiles");
    type_into(&mut h, "Stripe profiles", &profiles.display().to_string());
    let refs = dir.path().join("references.csv");
    type_into(
        &mut h,
        "Reference distances CSV",
        &refs.display().to_string(),
    );

    // The default mapping (id, station, j1…) does not fit this header.
    h.get_by_label("Preview").click();
    settle(&mut h);
    let preview = h.state().state().import.preview.clone().expect("preview");
    assert!(
        preview
            .as_ref()
            .is_err_and(|e| e.contains("no column `id`")),
        "{preview:?}"
    );
    assert!(
        h.query_all_by_label_contains("not in the header").count() > 0,
        "the unmatched columns are named"
    );

    h.get_by_label("Guess mapping").click();
    settle(&mut h);
    let form = &h.state().forms().import;
    assert_eq!(form.columns.id, "Pose");
    assert_eq!(form.columns.side.as_deref().unwrap_or_default(), "Side");
    assert_eq!(form.columns.joints[5], "A6");
    let preview = h.state().state().import.preview.clone().expect("preview");
    let text = preview.expect("the preview works with the guessed mapping");
    let first = &original.measurements[0];
    assert!(text.contains(&first.id), "{text}");
    assert!(
        h.query_all_by_label_contains(&format!("{:.4}", first.joints[1]))
            .count()
            > 0,
        "the preview shows joint 2 of the first pose"
    );
    // Issue 13: editing the form clears the now stale preview.
    h.get_by_label("no-return value").click();
    h.run();
    h.get_by_label("no-return value").type_text("-999");
    h.run();
    assert!(
        h.state().state().import.preview.is_none(),
        "an edit clears the old preview"
    );
    h.get_by_label("Preview").click();
    settle(&mut h);
    assert!(h.state().state().import.preview.is_some());

    h.get_by_label("Import and open").click();
    settle(&mut h);
    let loaded = h.state().state().loaded.as_ref().expect("a session");
    assert!(matches!(
        loaded.source,
        spherecal::app::session::Source::Imported(_)
    ));
    assert_eq!(
        loaded.session.measurements.len(),
        original.measurements.len()
    );
    assert_eq!(
        loaded.session.reference_distances,
        original.reference_distances
    );
    for (a, b) in loaded
        .session
        .measurements
        .iter()
        .zip(&original.measurements)
    {
        assert_eq!((&a.id, &a.station, a.side), (&b.id, &b.station, b.side));
        assert_eq!(a.joints, b.joints);
    }
    assert_eq!(h.state().forms().tab, Tab::Session);
    assert!(
        h.state().forms().save_path.ends_with("joints.json"),
        "Save as proposes a session beside the joint log: {}",
        h.state().forms().save_path
    );
}

#[test]
fn a_failed_import_names_the_pose_and_keeps_the_open_session() {
    let mut h = demo_app();
    let dir = tempfile::tempdir().expect("temp dir");
    let original = write_import_files(dir.path());
    let gone = &original.measurements[3].id;
    std::fs::remove_file(dir.path().join("profiles").join(format!("{gone}.csv"))).expect("remove");
    let before = session_name();
    {
        let form = &mut h.state_mut().forms_mut().import;
        form.joints = dir.path().join("joints.csv").display().to_string().into();
        form.profiles = dir.path().join("profiles").display().to_string().into();
    }
    h.get_by_label("Import").click();
    h.run();
    h.get_by_label("Guess mapping").click();
    settle(&mut h);
    h.get_by_label("Import and open").click();
    settle(&mut h);
    let outcome = h.state().state().import.outcome.clone().expect("outcome");
    let message = outcome.expect_err("the import fails");
    assert!(message.contains(&format!("pose {gone}")), "{message}");
    assert!(
        h.query_all_by_label_contains(&format!("pose {gone}"))
            .count()
            > 0,
        "the message is on screen"
    );
    let name = &h
        .state()
        .state()
        .loaded
        .as_ref()
        .expect("session")
        .session
        .name;
    assert_eq!(*name, before, "the open session is kept");
}

#[test]
fn the_history_view_scans_the_example_library_and_flags_its_jumps() {
    let mut h = demo_app();
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("sessions/history");
    h.get_by_label("History").click();
    h.run();
    type_into(&mut h, "Library folder", &folder.display().to_string());
    h.get_by_label("Scan").click();
    settle(&mut h);
    let view = &h.state().state().history;
    let library = view
        .library
        .as_ref()
        .expect("scanned")
        .as_ref()
        .expect("the library loads");
    assert_eq!(library.entries.len(), 5);
    assert!(library.problems.is_empty(), "{:?}", library.problems);
    let drift = view
        .drift
        .as_ref()
        .expect("a drift")
        .as_ref()
        .expect("the drift of the one robot");
    let mut jumped: Vec<&str> = drift.jumps().map(|j| j.parameter.as_str()).collect();
    jumped.sort_unstable();
    assert_eq!(jumped, ["hand_eye.x", "hand_eye.y", "theta3"]);
    assert!(
        h.query_all_by_label_contains("3 jump(s) flagged").count() > 0,
        "the jumps are announced"
    );
    // Untick the last calibration: the theta3 jump (2026-05-11) goes.
    let last = library.entries.last().expect("entries").path.clone();
    let name = last
        .file_name()
        .expect("name")
        .to_string_lossy()
        .into_owned();
    h.get_by_label(&name).click();
    settle(&mut h); // the drift is recomputed on a job thread
    assert!(h.state().forms().history.unselected.contains(&last));
    let drift = h
        .state()
        .state()
        .history
        .drift
        .clone()
        .expect("drift")
        .expect("ok");
    let mut jumped: Vec<String> = drift.jumps().map(|j| j.parameter.clone()).collect();
    jumped.sort_unstable();
    assert_eq!(jumped, ["hand_eye.x", "hand_eye.y"]);
    assert_eq!(drift.entries.len(), 4);
}

#[test]
fn a_missing_library_folder_is_reported() {
    let mut h = demo_app();
    h.get_by_label("History").click();
    h.run();
    type_into(&mut h, "Library folder", "/no/such/folder");
    h.get_by_label("Scan").click();
    settle(&mut h);
    let outcome = h.state().state().history.library.as_ref().expect("scanned");
    let message = outcome.as_ref().expect_err("fails");
    assert!(message.contains("/no/such/folder"), "{message}");
    assert!(h.query_all_by_label_contains("Could not scan").count() > 0);
}

#[test]
fn a_plan_is_made_exported_simulated_and_calibrated() {
    use spherecal::app::session::Source;
    use spherecal::engine::tools::plan;
    let mut h = demo_app();
    h.get_by_label("Plan").click();
    h.run();
    assert_eq!(h.state().forms().tab, Tab::Plan);
    {
        let f = &mut h.state_mut().forms_mut().plan;
        f.request.design.n_identify = 3;
        f.request.design.identify_poses = 4;
        f.request.design.n_validate = 2;
        f.request.design.validate_poses = 3;
        f.request.design.candidates = 8;
        f.request.predict_runs = 1;
    }
    h.get_by_label("Make plan").click();
    settle(&mut h);
    let outcome = h
        .state()
        .state()
        .plan
        .outcome
        .clone()
        .expect("planned")
        .expect("a plan");
    let n = outcome.plan.poses.len();
    assert_eq!(n, 4 + 6 + 3 * 4 + 2 * 3);
    let prediction = outcome.prediction.expect("asked for").expect("predicted");
    assert!(prediction.after_mean > 0.0 && prediction.after_mean < prediction.before_mean);
    assert!(
        h.query_all_by_label_contains("Predicted validation std after")
            .count()
            > 0
    );

    let dir = tempfile::tempdir().expect("temp dir");
    h.state_mut().forms_mut().export_dir = dir.path().display().to_string();
    h.get_by_label("Plan CSV").click();
    settle(&mut h);
    h.get_by_label("RAPID module").click();
    settle(&mut h);
    let csv = std::fs::read_to_string(dir.path().join("plan-irb2400.csv")).expect("csv");
    let poses = plan::read_plan_csv(&csv).expect("the CSV reads back");
    assert_eq!(poses.len(), n);
    let rapid = std::fs::read_to_string(dir.path().join("plan-irb2400.mod")).expect("rapid");
    assert!(rapid.contains("MODULE"), "{rapid}");
    assert!(
        rapid.matches("jointtarget").count() >= n,
        "one jointtarget per pose"
    );

    h.get_by_label("Simulate and open").click();
    settle(&mut h);
    let notice = h.state().state().notice.clone();
    assert!(notice.is_none(), "{notice:?}");
    let loaded = h.state().state().loaded.as_ref().expect("a session");
    assert_eq!(loaded.source, Source::Simulated);
    assert_eq!(loaded.session.measurements.len(), n);
    h.get_by_label("▶ Run").click();
    settle(&mut h);
    let result = h.state().state().result.as_ref().expect("calibrated");
    assert!(result.file.epsilon_after < result.file.epsilon_before);
}

/// The real data set in the repository (`data/robcalibrator-sphere`, see
/// tests/engine/realdata.rs); missing, the test fails.
fn realdata() -> std::path::PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/robcalibrator-sphere");
    assert!(
        dir.join("RobPoses.rob").is_file(),
        "the real data set is missing: {}",
        dir.display()
    );
    dir
}

#[test]
fn the_wizard_imports_flange_poses_and_the_run_calibrates_the_hand_eye_only() {
    let dir = realdata();
    let mut h = demo_app();
    h.get_by_label("Import").click();
    h.run();
    {
        let form = &mut h.state_mut().forms_mut().import;
        form.log_kind = spherecal::app::import::form::LogKind::FlangePoses;
        form.poses = dir.join("RobPoses.rob").display().to_string().into();
        form.profiles = dir.display().to_string().into();
        form.pose_convention = Some(spherecal::engine::files::import::FlangeConvention::FanucWpr);
        form.sphere_diameter = 80.0;
    }
    settle(&mut h);
    assert!(
        h.query_all_by_label_contains("Pose file").count() > 0,
        "the pose-log fields are shown"
    );
    h.get_by_label("Import and open").click();
    settle(&mut h);
    let loaded = h.state().state().loaded.as_ref().expect("a session");
    assert!(loaded.session.pose_only());
    assert_eq!(loaded.session.measurements.len(), 15);
    let outcome = h.state().state().import.outcome.clone().expect("outcome");
    let text = outcome.expect("imported");
    assert!(text.contains("side +1 chosen"), "{text}");
    assert!(text.contains("axis map -y,x,z"), "{text}");
    h.get_by_label("▶ Run").click();
    settle(&mut h);
    h.get_by_label("Results ●").click();
    settle(&mut h);
    let view = h.state().state().result.as_ref().expect("a result");
    assert!(view.hand_eye_only.is_some());
    assert!(
        h.query_all_by_label_contains("no kinematic parameter was identified")
            .count()
            > 0,
        "the Results view says what was calibrated"
    );
}
