//! Issue 34's low rows of the Results view: its own scroll offset (it
//! opened mid-page after the Import view was scrolled), the files written
//! of the last session not listed under the next one's result, and the
//! verdict of a stale result struck out. egui_kittest, no display.

#![cfg(feature = "gui")]
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable as _;
use spherecal::app::WorkbenchApp;
use spherecal::app::command::{Command, FilesCommand, Tab, ViewCommand};

use crate::support::ui::{demo_app, labels_with, settle};

/// Applies `c` and waits for what it started.
fn command(h: &mut Harness<'_, WorkbenchApp>, c: Command) {
    let ctx = h.ctx.clone();
    h.state_mut().command(&ctx, c);
    settle(h);
}

fn run_and_show_results(h: &mut Harness<'_, WorkbenchApp>) {
    h.get_by_label("▶ Run").click();
    settle(h);
    command(h, Command::View(ViewCommand::ShowTab(Tab::Results)));
}

/// Import and Results shared one scroll offset: Results opened mid-page
/// with the verdict off screen. Scrolled Import, Results opens at its top.
#[test]
fn results_open_at_the_top_after_the_import_view_was_scrolled() {
    let mut h = demo_app();
    run_and_show_results(&mut h);
    let top = h.get_by_label("PASS").rect().top();
    command(&mut h, Command::View(ViewCommand::ShowTab(Tab::Import)));
    let middle = egui::pos2(800.0, 500.0);
    for _ in 0..10 {
        h.hover_at(middle);
        h.event(egui::Event::MouseWheel {
            unit: egui::MouseWheelUnit::Point,
            delta: egui::vec2(0.0, -200.0),
            phase: egui::TouchPhase::Move,
            source: egui::MouseWheelSource::Unknown,
            modifiers: egui::Modifiers::NONE,
        });
        h.run();
    }
    command(&mut h, Command::View(ViewCommand::ShowTab(Tab::Results)));
    let now = h.get_by_label("PASS").rect().top();
    assert!(
        (now - top).abs() < 1.0 && now > 0.0 && now < 768.0,
        "the verdict moved from {top} to {now}"
    );
}

/// "written: ! …-report.html (stale)" appeared on the Results of every
/// later, unrelated session. A new session lists only its own files.
#[test]
fn the_files_written_of_the_last_session_are_not_listed_under_the_next() {
    let mut h = demo_app();
    run_and_show_results(&mut h);
    let dir = tempfile::tempdir().expect("temp dir");
    h.state_mut().forms_mut().export_dir = dir.path().display().to_string();
    h.get_by_label("Report HTML").click();
    settle(&mut h);
    assert!(dir.path().join("demo-irb2400-report.html").is_file());
    assert!(
        !labels_with(&h, "demo-irb2400-report.html").is_empty(),
        "the report is listed under its result"
    );
    command(&mut h, Command::Files(FilesCommand::OpenDemo));
    run_and_show_results(&mut h);
    assert!(
        labels_with(&h, "report.html").is_empty(),
        "{:?}",
        labels_with(&h, "report.html")
    );
    assert!(labels_with(&h, "written:").is_empty());
}

/// The big green PASS stayed under a STALE banner. The verdict of a
/// stale result is struck out and says it does not hold; current again,
/// it stands alone.
#[test]
fn the_verdict_of_a_stale_result_says_it_does_not_hold() {
    let mut h = demo_app();
    run_and_show_results(&mut h);
    let stale = spherecal::app::results::ui::STALE_VERDICT;
    assert!(h.query_by_label("PASS").is_some());
    assert!(h.query_by_label(stale).is_none());
    let id = h
        .state()
        .state()
        .loaded
        .as_ref()
        .unwrap()
        .session
        .measurements[0]
        .id
        .clone();
    let leave_out = |included| {
        Command::View(ViewCommand::SetIncluded {
            id: id.clone(),
            included,
        })
    };
    command(&mut h, leave_out(false));
    h.run();
    assert!(
        h.query_by_label("PASS").is_some(),
        "still shown, struck out"
    );
    assert!(h.query_by_label(stale).is_some());
    command(&mut h, leave_out(true));
    h.run();
    assert!(h.query_by_label(stale).is_none());
}
