//! Issue 34's rows in the Measure and Compensate views, at 1366×768: the
//! Compensate column beside its scene shows every control whole; the
//! empty Measure view says what it will show (a 3-D scene and three
//! projections) and, opened by Next, what to do first, with ▶ Measure
//! focused. egui_kittest, no display.

#![cfg(feature = "gui")]
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use egui_kittest::Harness;
use egui_kittest::kittest::{NodeT as _, Queryable as _};
use spherecal::app::WorkbenchApp;
use spherecal::app::command::{Command, Tab, ViewCommand};
use spherecal::engine::tools::result_view::Tolerance;

use crate::support::ui::{command, demo_app, labels_with, settle};

/// The demo calibrated in the window, passing a generous tolerance, the
/// export folder `dir`.
fn calibrated_demo(dir: &std::path::Path) -> Harness<'static, WorkbenchApp> {
    let mut h = demo_app();
    h.state_mut().forms_mut().export_dir = dir.display().to_string();
    h.get_by_label("Next: ▶ Run the calibration").click();
    settle(&mut h);
    let tolerance = Tolerance {
        std_mm: 5.0,
        max_mm: 10.0,
    };
    command(&mut h, Command::View(ViewCommand::SetTolerance(tolerance)));
    h.run();
    h
}

/// The issue: at 1366×768 the scene cut "Open targets…", "kept as
/// written", "Write compensated program…" and the summary line. Each is
/// whole, left of the scene, inside the window.
#[test]
fn the_compensate_column_is_whole_beside_its_scene() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = calibrated_demo(dir.path());
    command(&mut h, Command::View(ViewCommand::ShowTab(Tab::Compensate)));
    h.run();
    h.get_by_label("Use the guide's example targets").click();
    settle(&mut h);
    let summary = match &h.state().state().compensate.outcome {
        Some(Ok(v)) => v.summary.line(),
        other => panic!("not compensated: {other:?}"),
    };
    for _ in 0..3 {
        h.run();
    }
    let scene = h.get_by_label_contains("targets as written (orange").rect();
    assert!(
        scene.left() > 600.0,
        "the scene beside the column: {scene:?}"
    );
    let labels = [
        "Open targets…",
        "kept as written (taught on the robot)",
        "Write compensated program…",
        summary.as_str(),
    ];
    for label in labels {
        // The view's own (the status bar repeats the summary at the bottom).
        let rects: Vec<egui::Rect> = h
            .query_all_by_label(label)
            .map(|n| n.rect())
            .filter(|r| r.bottom() < 768.0 - 30.0)
            .collect();
        assert!(!rects.is_empty(), "{label:?} is shown");
        for r in rects {
            assert!(r.left() >= 0.0 && r.right() <= 1366.0, "{label:?}: {r:?}");
            assert!(
                r.right() <= scene.left(),
                "{label:?} ends left of the scene ({}): {r:?}",
                scene.left()
            );
        }
    }
}

/// The empty Measure view says what it shows (a 3-D scene now, and the
/// projections), and without a result that the calibration comes first.
#[test]
fn the_empty_measure_view_says_what_is_true() {
    let mut h = demo_app();
    command(&mut h, Command::View(ViewCommand::ShowTab(Tab::Measure)));
    h.run();
    assert!(labels_with(&h, "drawn in three projections").is_empty());
    let about = labels_with(&h, "The cloud is shown in the cell in 3-D");
    assert_eq!(about.len(), 1, "{about:?}");
    assert!(about[0].contains("three projections"), "{}", about[0]);
    let todo = labels_with(&h, "To do: run the calibration");
    assert_eq!(todo.len(), 1, "{todo:?}");
}

/// The issue: "Next: Measure a scan" showed the Measure view and nothing
/// in it said what to do. Opened by Next, the view says it at its top,
/// on screen, and ▶ Measure has the keyboard focus.
#[test]
fn next_to_measure_says_what_to_do() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = calibrated_demo(dir.path());
    h.get_by_label("Next: Write the report").click();
    settle(&mut h);
    h.get_by_label("Next: Check the stripes").click();
    h.run();
    h.get_by_label("Next: Measure a scan").click();
    h.run();
    assert_eq!(h.state().forms().tab, Tab::Measure);
    let todo = h.get_by_label_contains("To do: press ▶ Measure to measure the open session");
    let r = todo.rect();
    assert!(
        r.top() >= 0.0 && r.bottom() <= 768.0 && r.right() <= 1366.0,
        "{r:?}"
    );
    assert!(
        h.get_by_label("▶ Measure").accesskit_node().is_focused(),
        "▶ Measure has the focus"
    );
    // Measured: the box is gone.
    h.get_by_label("▶ Measure").click();
    settle(&mut h);
    assert!(h.state().state().measure.shown.is_some());
    assert!(labels_with(&h, "To do: ").is_empty());
}
