//! Issue 34's flow rows: a result the loop made no update to is not shown
//! as a calibration (the step bar, Results, the status line, and the one
//! click that refines it anyway); a run Next started opens Results, and
//! Next offers the report only once the verdict was seen; opening another
//! session clears what was made of the previous one, and says so.

#![cfg(feature = "gui")]
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable as _;
use spherecal::app::WorkbenchApp;
use spherecal::app::command::{Command, Tab, ViewCommand};
use spherecal::engine::calibrate::solve::Method;
use spherecal::engine::tools::simulate::SimConfig;

use crate::support::ui::{
    command, demo_app, labels_with, open_path, settle, simulated, status, step_label,
};

/// The Next button's label, if any.
fn next(h: &Harness<'_, WorkbenchApp>) -> Option<String> {
    labels_with(h, "Next: ").into_iter().next()
}

/// The issue: an `ml` run on a pose-only session whose ε (0.107 mm)
/// started within the threshold (0.15 mm) made no update, yet steps 4 and
/// 5 showed done. Now step 4 says so ("!"), 5 is to do, Results and the
/// status line give the figures, and Next's "Run again with threshold 0"
/// refines it.
#[test]
fn a_start_within_the_threshold_is_not_a_calibration() {
    let dir = tempfile::tempdir().expect("temp dir");
    let config = SimConfig {
        pose_only: Some(0.02),
        ..SimConfig::default()
    };
    let path = simulated(dir.path(), "pose-only.json", &config);
    let mut h = demo_app();
    open_path(&mut h, path);
    h.state_mut().forms_mut().solver.method = Method::Ml;
    h.run();
    h.get_by_label("Next: ▶ Run the calibration").click();
    settle(&mut h);
    let view = h.state().state().result.as_ref().expect("a result");
    assert_eq!(view.file.iterations.len(), 1, "no update");
    assert_eq!(h.state().forms().tab, Tab::Results, "the verdict on show");
    let calibrated = step_label(&h, "4. Calibrated");
    assert!(calibrated.starts_with('!'), "{calibrated}");
    let validated = step_label(&h, "5. Validated");
    assert!(validated.starts_with('○'), "{validated}");
    let said = "no update: ε = 0.1068 mm started within the threshold 0.15 mm";
    assert!(status(&h).contains(said), "{}", status(&h));
    assert!(!labels_with(&h, said).is_empty(), "Results says it");
    assert_eq!(
        next(&h).as_deref(),
        Some("Next: Run again with threshold 0")
    );
    assert!(!labels_with(&h, "or: write the report anyway").is_empty());

    h.get_by_label("Next: Run again with threshold 0").click();
    settle(&mut h);
    assert_eq!(h.state().forms().solver.threshold, 0.0);
    let view = h.state().state().result.as_ref().expect("a result");
    assert!(view.file.iterations.len() > 1, "updated");
    assert!(view.file.epsilon_after < view.file.epsilon_before);
    assert_ne!(view.file.hand_eye, view.file.hand_eye_initial);
    assert!(step_label(&h, "4. Calibrated").starts_with('●'));
    assert!(
        labels_with(&h, "no update").is_empty(),
        "nothing left to say"
    );
}

/// The issue: after Next ran the calibration the window stayed on Session
/// and Next offered the report before the verdict was seen.
#[test]
fn the_verdict_is_seen_before_the_report() {
    let mut h = demo_app();
    h.get_by_label("Next: ▶ Run the calibration").click();
    settle(&mut h);
    assert_eq!(h.state().forms().tab, Tab::Results, "Next's run shows it");
    assert_eq!(next(&h).as_deref(), Some("Next: Write the report"));
    // A run started elsewhere (Run on the left): the operator stays, and
    // Next shows the verdict first.
    command(&mut h, Command::View(ViewCommand::ShowTab(Tab::Session)));
    h.get_by_label("▶ Run").click();
    settle(&mut h);
    assert_eq!(h.state().forms().tab, Tab::Session);
    assert_eq!(next(&h).as_deref(), Some("Next: See the verdict"));
    h.get_by_label("Next: See the verdict").click();
    h.run();
    assert_eq!(h.state().forms().tab, Tab::Results);
    assert_eq!(next(&h).as_deref(), Some("Next: Write the report"));
}

/// The issue: opening another session kept the previous result's cloud
/// and compensation (marked stale). They are cleared, and the status line
/// says what went, naming what was never written.
#[test]
fn another_session_clears_what_was_made_of_the_last() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut h = demo_app();
    h.state_mut().forms_mut().export_dir = dir.path().display().to_string();
    h.get_by_label("Next: ▶ Run the calibration").click();
    settle(&mut h);
    command(&mut h, Command::View(ViewCommand::ShowTab(Tab::Measure)));
    h.get_by_label("▶ Measure").click();
    settle(&mut h);
    assert!(h.state().state().measure.shown.is_some(), "a cloud");
    command(&mut h, Command::View(ViewCommand::ShowTab(Tab::Compensate)));
    h.get_by_label("Use the guide's example targets").click();
    settle(&mut h);
    assert!(
        h.state().state().compensate.outcome.is_some(),
        "compensated"
    );

    let config = SimConfig {
        n_validate: 3,
        ..SimConfig::default()
    };
    open_path(&mut h, simulated(dir.path(), "other.json", &config));
    let state = h.state().state();
    assert!(state.measure.shown.is_none(), "the cloud went");
    assert!(state.compensate.outcome.is_none(), "the compensation went");
    assert!(state.result.is_none());
    let said = status(&h);
    assert!(
        said.contains(
            "cleared what was made of the previous session: the compensation (never written), the cloud (never written)"
        ),
        "{said}"
    );
    assert!(step_label(&h, "7. Measured").starts_with('○'));
    assert!(step_label(&h, "8. Compensated (optional)").starts_with('○'));
}
