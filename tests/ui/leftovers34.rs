//! Issue 34's last rows, as an operator meets them at 1366×768: Run in
//! one place whatever the session, the left panel's error box whole on
//! screen, the path field naming the open session only, a pose-only
//! result said for what it is, the identifiable set inside the window.

#![cfg(feature = "gui")]
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable as _;
use spherecal::app::WorkbenchApp;
use spherecal::app::command::{Command, FilesCommand, Tab, ViewCommand};
use spherecal::engine::calibrate::solve::Method;
use spherecal::engine::tools::simulate::SimConfig;

use crate::support::ui as ui_support;
use ui_support::{demo_app, open_path, scroll_to, settle, simulated};

/// The window's height in the tests, points.
const HEIGHT: f32 = 768.0;

fn command(h: &mut Harness<'_, WorkbenchApp>, c: Command) {
    let ctx = h.ctx.clone();
    h.state_mut().command(&ctx, c);
}

fn run_top(h: &Harness<'_, WorkbenchApp>) -> f32 {
    h.get_by_label("▶ Run").rect().top()
}

/// A small simulated session (seeded) with `name`, pose-only or not.
fn small(name: &str, pose_only: bool) -> SimConfig {
    SimConfig {
        seed: 34,
        n_validate: 3,
        name: Some(name.to_string()),
        pose_only: pose_only.then_some(0.0),
        ..SimConfig::default()
    }
}

/// The issue: the Run button sat at 368, 382 or 410 px as the session's
/// name, its source (a long path) or its counts wrapped. Now it stays in
/// one place for the demo, a long name in a deep folder, and a pose-only
/// session (its counts line is longer), and with no session at all.
#[test]
fn the_run_button_stays_in_one_place() {
    let mut h = demo_app();
    let at = run_top(&h);
    let dir = tempfile::tempdir().expect("temp dir");
    let deep = dir
        .path()
        .join("a-rather-long-folder-name-for-the-cell-of-line-3")
        .join("calibration-sessions-of-the-second-week");
    std::fs::create_dir_all(&deep).expect("folders");
    let long = "cell 3 of line 7, the second sphere stand, after the gripper change, measured by the night shift";
    let cases = [
        simulated(
            &deep,
            "a-long-file-name-for-this-session.json",
            &small(long, false),
        ),
        simulated(dir.path(), "p.json", &small("p", true)),
        simulated(dir.path(), "s.json", &small("s", false)),
    ];
    for path in cases {
        open_path(&mut h, path.clone());
        assert!(h.state().state().loaded.is_some(), "{}", path.display());
        let y = run_top(&h);
        assert!(
            (y - at).abs() < 0.5,
            "Run at {y} for {}, at {at} for the demo",
            path.display()
        );
    }
    let loaded = h.state().state().loaded.as_ref().expect("a session");
    assert!(!loaded.session.pose_only());
}

/// The issue: the path field still named the previous file while the
/// demo (or another session without a file) was open. It names the open
/// session's file, and nothing when that has none.
#[test]
fn the_path_field_names_the_open_session_only() {
    let mut h = demo_app();
    let dir = tempfile::tempdir().expect("temp dir");
    let path = simulated(dir.path(), "s.json", &small("s", false));
    open_path(&mut h, path.clone());
    assert_eq!(h.state().forms().open_path, path.display().to_string());
    command(&mut h, Command::Files(FilesCommand::OpenDemo));
    settle(&mut h);
    assert!(h.state().state().loaded.is_some());
    assert_eq!(
        h.state().forms().open_path,
        "",
        "the demo is open: the field names no file"
    );
    // A file that does not open keeps what was typed, to correct it.
    let missing = dir.path().join("missing.json");
    open_path(&mut h, missing.clone());
    assert_eq!(h.state().forms().open_path, missing.display().to_string());
}

/// The issue: the left panel's error box was cut off at 768 px. A long
/// error (a deep path that does not exist) is wrapped inside the panel,
/// scrolled into sight, its Dismiss button on screen, and Dismiss works.
#[test]
fn the_error_box_is_whole_on_screen() {
    let mut h = demo_app();
    let dir = tempfile::tempdir().expect("temp dir");
    let missing = dir
        .path()
        .join("a-folder-with-a-long-name-that-does-not-exist")
        .join("nor-does-this-one")
        .join("session-of-the-night-shift.json");
    open_path(&mut h, missing);
    assert!(h.state().state().notice.is_some(), "a notice");
    for _ in 0..4 {
        h.run();
    }
    let run = h.get_by_label("▶ Run").rect();
    let title = h.get_by_label_contains("Could not open").rect();
    assert!(
        title.right() <= run.left() + 290.0,
        "the title wraps in the panel: {title:?}"
    );
    let dismiss = h.get_by_label("Dismiss").rect();
    assert!(
        dismiss.bottom() <= HEIGHT - 20.0 && dismiss.top() >= 0.0,
        "Dismiss on screen, above the status line: {dismiss:?}"
    );
    h.get_by_label("Dismiss").click();
    h.run();
    assert!(h.state().state().notice.is_none());
}

/// The issue: a pose-only ml result was headed "Singular values of the
/// last update" and listed "held 0 fixed (…):" with nothing after it. It
/// is headed for what it is, says no kinematic parameter was identified,
/// and lists no empty set.
#[test]
fn a_pose_only_result_says_what_it_is() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = simulated(dir.path(), "p.json", &small("pose-only cell", true));
    let mut h = demo_app();
    open_path(&mut h, path);
    assert!(
        h.state()
            .state()
            .loaded
            .as_ref()
            .unwrap()
            .session
            .pose_only()
    );
    h.state_mut().forms_mut().solver.method = Method::Ml;
    h.get_by_label("▶ Run").click();
    settle(&mut h);
    let view = h.state().state().result.as_ref().expect("a result");
    assert!(view.hand_eye_only.is_some(), "a hand-eye-only result");
    command(&mut h, Command::View(ViewCommand::ShowTab(Tab::Results)));
    h.run();
    let centre = egui::pos2(800.0, 500.0);
    assert!(
        scroll_to(&mut h, centre, "Identified: the hand-eye only"),
        "the heading says what was identified"
    );
    assert!(
        h.query_all_by_label_contains("A pose-only result")
            .next()
            .is_some(),
        "what a pose-only result is, said"
    );
    assert!(
        h.query_all_by_label_contains("no kinematic parameter")
            .next()
            .is_some()
    );
    for gone in ["Singular values of the last update", "held 0 fixed"] {
        assert!(
            h.query_all_by_label_contains(gone).next().is_none(),
            "{gone:?} is not shown"
        );
    }
}

/// The issue: the identifiable set's text ran to the window's right edge
/// (cut at 1366 px). Every line of it ends inside the window with room.
#[test]
fn the_identifiable_set_stays_inside_the_window() {
    let mut h = demo_app();
    h.state_mut().forms_mut().solver.method = Method::Ml;
    h.get_by_label("▶ Run").click();
    settle(&mut h);
    command(&mut h, Command::View(ViewCommand::ShowTab(Tab::Results)));
    h.run();
    assert!(scroll_to(
        &mut h,
        egui::pos2(800.0, 500.0),
        "Identifiable set"
    ));
    for _ in 0..3 {
        h.run();
    }
    let lines: Vec<egui::Rect> = ["Method ml estimated", "fixed: "]
        .iter()
        .flat_map(|t| h.query_all_by_label_contains(t).map(|n| n.rect()))
        .collect();
    assert!(!lines.is_empty(), "the set is listed");
    for r in lines {
        assert!(r.right() <= 1366.0 - 8.0, "inside the window: {r:?}");
    }
}

/// The operator review: the Results view scrolled down to the
/// identifiable set, then a run of another session: its Results opened
/// at the same offset, the verdict off screen. Each new result opens at
/// the top.
#[test]
fn a_new_result_opens_at_its_verdict() {
    let mut h = demo_app();
    h.get_by_label("▶ Run").click();
    settle(&mut h);
    command(&mut h, Command::View(ViewCommand::ShowTab(Tab::Results)));
    h.run();
    // The export row, just above the verdict, whatever the verdict says.
    let top = |h: &Harness<'_, WorkbenchApp>| h.get_by_label("Report HTML").rect().top();
    let first = top(&h);
    assert!(
        (80.0..HEIGHT).contains(&first),
        "the verdict on show: {first}"
    );
    // Down the page with the wheel, as the operator does.
    for _ in 0..4 {
        h.hover_at(egui::pos2(800.0, 500.0));
        h.event(egui::Event::MouseWheel {
            unit: egui::MouseWheelUnit::Point,
            delta: egui::vec2(0.0, -200.0),
            phase: egui::TouchPhase::Move,
            source: egui::MouseWheelSource::Unknown,
            modifiers: egui::Modifiers::NONE,
        });
        h.run();
    }
    for _ in 0..10 {
        h.run();
    }
    assert!(top(&h) < 80.0, "scrolled past the verdict: {}", top(&h));
    let dir = tempfile::tempdir().expect("temp dir");
    open_path(&mut h, simulated(dir.path(), "s.json", &small("s", false)));
    h.get_by_label("▶ Run").click();
    settle(&mut h);
    command(&mut h, Command::View(ViewCommand::ShowTab(Tab::Results)));
    h.run();
    let again = top(&h);
    assert!(
        (80.0..HEIGHT).contains(&again),
        "the new result opens at its verdict: {again}"
    );
}

/// The operator review: step 3's "Check the stripes" opened the Stripe
/// view on the selected measurement (t1, no warning) and marked the step
/// done, the demo's warned stripe never shown. The view names the flagged
/// stripes; a click shows one.
#[test]
fn the_stripe_view_names_the_flagged_stripes() {
    let mut h = demo_app();
    command(&mut h, Command::View(ViewCommand::ShowTab(Tab::Stripe)));
    h.run();
    let loaded = h.state().state().loaded.as_ref().expect("the demo");
    let flagged: Vec<(usize, String)> = (0..loaded.session.measurements.len())
        .filter(|&k| {
            loaded
                .fit(k)
                .stripe()
                .is_none_or(|s| !s.warnings.is_empty())
        })
        .map(|k| (k, loaded.session.measurements[k].id.clone()))
        .collect();
    assert_eq!(
        flagged.len(),
        1,
        "the demo has one warned stripe: {flagged:?}"
    );
    let (k, id) = flagged[0].clone();
    assert_ne!(h.state().state().selected, Some(k));
    assert!(
        h.query_all_by_label_contains("1 with warnings or failures")
            .next()
            .is_some()
    );
    h.get_by_label(&id).click();
    h.run();
    assert_eq!(h.state().state().selected, Some(k), "{id} is shown");
}
