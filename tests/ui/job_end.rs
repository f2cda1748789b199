//! Issue 34, items 2 and 3: Next leads through the whole job (report →
//! Measure → Compensate, optional steps named), the tab row stays put
//! when the bar's lines come and go, the Plan form keeps and says an
//! out-of-range count and commits it on Enter, the map's scale reaches
//! the tolerance, the after-only panels of Fig. 5/6, the Measure export's
//! default written, a refusal box gone once answered. egui_kittest, no
//! display.

#![cfg(feature = "gui")]
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use egui_kittest::Harness;
use egui_kittest::kittest::{NodeT as _, Queryable as _};
use spherecal::app::WorkbenchApp;
use spherecal::app::command::{Command, Tab, ViewCommand};
use spherecal::engine::tools::result_view::Tolerance;

use crate::support::ui as ui_support;
use ui_support::{demo_app, labels_with, settle, step_label};

fn command(h: &mut Harness<'static, WorkbenchApp>, c: Command) {
    let ctx = h.ctx.clone();
    h.state_mut().command(&ctx, c);
    h.run();
}

/// The text of the Next button ("Next: …"), if one is shown.
fn next(h: &Harness<'static, WorkbenchApp>) -> Option<String> {
    labels_with(h, "Next: ").into_iter().next()
}

/// The top of the tab row (the "History" tab, the last one).
fn tabs_top(h: &Harness<'static, WorkbenchApp>) -> f32 {
    h.query_all_by_label("History")
        .map(|n| n.rect().top())
        .fold(f32::INFINITY, f32::min)
}

/// The demo, run and passing a generous tolerance, the export folder a
/// temporary one.
fn passed_demo(dir: &std::path::Path) -> Harness<'static, WorkbenchApp> {
    let mut h = demo_app();
    h.state_mut().forms_mut().export_dir = dir.display().to_string();
    h.get_by_label("Next: ▶ Run the calibration").click();
    settle(&mut h);
    command(
        &mut h,
        Command::View(ViewCommand::SetTolerance(Tolerance {
            std_mm: 5.0,
            max_mm: 10.0,
        })),
    );
    h
}

/// Next goes on after the report to Measure, then names Compensate as
/// the optional step left and leads the demo there with the guide's
/// example targets; "every step is done" only at the end.
#[test]
fn next_leads_from_the_report_to_a_compensated_program() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = passed_demo(dir.path());
    assert!(step_label(&h, "8. Compensated (optional)").starts_with('○'));
    assert_eq!(next(&h).as_deref(), Some("Next: Write the report"));
    h.get_by_label("Next: Write the report").click();
    settle(&mut h);
    // Measured is ○: not done, Next measures.
    assert!(step_label(&h, "7. Measured").starts_with('○'));
    assert!(labels_with(&h, "every step is done").is_empty());
    assert!(labels_with(&h, "every required step is done").is_empty());
    // The demo's stripe warnings first (the first step showing "!"):
    // looked at, the step is done.
    assert!(step_label(&h, "3. Stripes checked").starts_with('!'));
    h.get_by_label("Next: Check the stripes").click();
    h.run();
    assert_eq!(h.state().forms().tab, Tab::Stripe);
    assert!(step_label(&h, "3. Stripes checked").starts_with('●'));
    h.get_by_label("Next: Measure a scan").click();
    h.run();
    assert_eq!(h.state().forms().tab, Tab::Measure);
    h.get_by_label("▶ Measure").click();
    settle(&mut h);
    assert!(step_label(&h, "7. Measured").starts_with('●'));
    // Every required step done: the optional one named, no Next.
    assert_eq!(next(&h), None);
    let said = labels_with(&h, "every required step is done");
    assert_eq!(said.len(), 1, "{said:?}");
    assert!(said[0].contains("8. Compensated"), "{}", said[0]);
    h.get_by_label("or: Compensate targets").click();
    h.run();
    assert_eq!(h.state().forms().tab, Tab::Compensate);
    // The demo is offered the guide's targets: written, compensated.
    h.get_by_label("Use the guide's example targets").click();
    settle(&mut h);
    assert!(
        dir.path().join("example-targets.csv").is_file(),
        "written to the export folder"
    );
    match &h.state().state().compensate.outcome {
        Some(Ok(v)) => assert_eq!(v.rows.len(), 10, "the guide's ten targets"),
        other => panic!("{other:?}"),
    }
    assert!(step_label(&h, "8. Compensated (optional)").starts_with('●'));
    // The re-check is the optional step left: the demo's own session
    // checked against its calibration.
    let said = labels_with(&h, "every required step is done");
    assert!(said[0].contains("9. Re-checked"), "{}", said[0]);
    h.get_by_label("or: Re-check the cell").click();
    h.run();
    assert_eq!(h.state().forms().tab, Tab::Check);
    let demo = concat!(env!("CARGO_MANIFEST_DIR"), "/sessions/demo-irb2400.json");
    h.state_mut().forms_mut().check.session = demo.to_string();
    h.run();
    h.get_by_label("Check").click();
    settle(&mut h);
    assert!(step_label(&h, "9. Re-checked (optional)").starts_with('●'));
    assert!(h.query_by_label("● every step is done").is_some());
    assert_eq!(next(&h), None);
}

/// "Every step is done" never shows while a step shows "!": a stale
/// report (the tolerance changed) is written again first.
#[test]
fn a_step_showing_a_mark_is_never_done() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = passed_demo(dir.path());
    h.get_by_label("Next: Write the report").click();
    settle(&mut h);
    h.get_by_label("Next: Check the stripes").click();
    h.run();
    h.get_by_label("Next: Measure a scan").click();
    h.run();
    h.get_by_label("▶ Measure").click();
    settle(&mut h);
    assert!(!labels_with(&h, "every required step is done").is_empty());
    let top = tabs_top(&h);
    // The tolerance changes: the report is stale ("!"), Next writes it
    // again, and the tab row has not moved for the "! stale" line.
    command(
        &mut h,
        Command::View(ViewCommand::SetTolerance(Tolerance {
            std_mm: 4.0,
            max_mm: 10.0,
        })),
    );
    assert!(step_label(&h, "6. Reported").starts_with('!'));
    assert!(!labels_with(&h, "! stale:").is_empty(), "the stale line");
    assert!(
        labels_with(&h, "step is done").is_empty(),
        "not done while \"!\": {:?}",
        labels_with(&h, "step is done")
    );
    assert_eq!(next(&h).as_deref(), Some("Next: Write the report again"));
    assert_eq!(tabs_top(&h), top, "the tabs stay put");
}

/// The tab row does not move when "or: write the report (FAIL)" and the
/// stale line come and go.
#[test]
fn the_tab_row_stays_put() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = passed_demo(dir.path());
    let top = tabs_top(&h);
    assert!(top.is_finite());
    // A FAIL: "or:" buttons appear beside Next.
    command(
        &mut h,
        Command::View(ViewCommand::SetTolerance(Tolerance {
            std_mm: 0.0001,
            max_mm: 0.0001,
        })),
    );
    assert!(!labels_with(&h, "or: write the report (FAIL)").is_empty());
    assert_eq!(tabs_top(&h), top);
    // A left-out measurement: the result and its steps are stale.
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
    command(
        &mut h,
        Command::View(ViewCommand::SetIncluded {
            id: id.clone(),
            included: false,
        }),
    );
    assert!(!labels_with(&h, "! stale:").is_empty());
    assert_eq!(tabs_top(&h), top);
    // Writing the stale result is refused in a red box; with the
    // measurement back, nothing is stale and the box goes.
    command(
        &mut h,
        Command::Export(spherecal::app::command::ExportKind::ResultJson),
    );
    settle(&mut h);
    let refused = h.state().state().notice.clone().expect("a refusal");
    assert!(refused.body.contains("stale"), "{refused:?}");
    command(
        &mut h,
        Command::View(ViewCommand::SetIncluded { id, included: true }),
    );
    assert!(labels_with(&h, "! stale:").is_empty());
    assert_eq!(h.state().state().notice, None, "the stale box went");
    assert_eq!(tabs_top(&h), top);
}

/// The Plan form: 300 identify stations are kept (the CLI plans them),
/// 600 are kept and said (the engine's bound), never clamped; a typed
/// value counts on Enter, not per keystroke.
#[test]
fn the_plan_form_keeps_and_says_an_out_of_range_count() {
    let mut h = demo_app();
    command(&mut h, Command::View(ViewCommand::ShowTab(Tab::Plan)));
    let before = h.state().forms().plan.request.design.n_identify;
    h.get_by_label("Identify stations").focus();
    h.run();
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    h.get_by_label("Identify stations").type_text("300");
    h.run();
    assert_eq!(
        h.state().forms().plan.request.design.n_identify,
        before,
        "not committed while typing"
    );
    h.key_press(egui::Key::Enter);
    h.run();
    assert_eq!(h.state().forms().plan.request.design.n_identify, 300);
    assert!(labels_with(&h, "not plannable as set").is_empty());
    // Beyond the engine's bound: kept, said, Make plan disabled.
    h.state_mut().forms_mut().plan.request.design.n_identify = 600;
    h.run();
    assert_eq!(h.state().forms().plan.request.design.n_identify, 600);
    let said = labels_with(&h, "not plannable as set");
    assert_eq!(said.len(), 1, "{said:?}");
    assert!(said[0].contains("at most 500"), "{}", said[0]);
    assert!(h.get_by_label("Make plan").accesskit_node().is_disabled());
}

/// The Results view draws Fig. 5's and Fig. 6's after series alone, and
/// the Measure export writes the default its field shows.
#[test]
fn after_panels_and_the_cloud_default() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = passed_demo(dir.path());
    command(&mut h, Command::View(ViewCommand::ShowTab(Tab::Results)));
    assert!(ui_support::scroll_to(
        &mut h,
        egui::pos2(900.0, 500.0),
        "Fig. 6, after only"
    ));
    assert!(!labels_with(&h, "Fig. 5, after only").is_empty());
    // Measure, then Write with the field empty: the default is written.
    command(&mut h, Command::View(ViewCommand::ShowTab(Tab::Measure)));
    h.get_by_label("▶ Measure").click();
    settle(&mut h);
    assert!(h.state().forms().measure.out.is_empty());
    h.get_by_label("Write cloud").click();
    settle(&mut h);
    let name = spherecal::app::measure::default_cloud_name(h.state().state());
    assert!(dir.path().join(&name).is_file(), "{name} written");
    assert!(h.state().state().notice.is_none(), "no refusal box");
}
