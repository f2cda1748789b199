//! UI tests of the measuring range in the workbench (issue 14): set in the
//! Session view (kept with the session, used by the next run and by the
//! planner), and the Plan view spreading the sphere over it beside the
//! plan without the spread. egui_kittest, no display.

#![cfg(feature = "gui")]
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use egui_kittest::kittest::Queryable as _;
use spherecal::app::command::Tab;
use spherecal::engine::base::session::SensorRange;

use crate::support::ui as ui_support;
use ui_support::{demo_app, settle, small_plan};

const DEFAULT: SensorRange = SensorRange {
    y: [-40.0, 40.0],
    z: [-40.0, 40.0],
};

#[test]
fn the_session_view_sets_the_measuring_range_for_the_next_run() {
    let mut h = demo_app();
    h.state_mut().forms_mut().tab = Tab::Session;
    h.run();
    let range = |h: &egui_kittest::Harness<'_, spherecal::app::WorkbenchApp>| {
        h.state()
            .state()
            .loaded
            .as_ref()
            .and_then(|l| l.session.sensor_range)
    };
    assert_eq!(range(&h), None);
    assert!(
        h.query_all_by_label_contains("not set: the error is predicted only where")
            .count()
            > 0
    );
    h.get_by_label("Set range").click();
    h.run();
    assert_eq!(range(&h), Some(DEFAULT));
    assert!(h.query_all_by_label_contains("set: y -40…40").count() > 0);
    // The planner follows it.
    assert_eq!(h.state().forms().plan.request.range, Some(DEFAULT));
    assert!(h.state().forms().plan.request.spread);
    // The next run predicts the error over it.
    h.get_by_label("▶ Run").click();
    settle(&mut h);
    let predicted = h
        .state()
        .state()
        .result
        .as_ref()
        .and_then(|r| r.file.solver.ml())
        .and_then(|m| m.range_error.clone())
        .expect("a range prediction");
    assert_eq!(predicted.region, "sensor.range");
    assert_eq!((predicted.y, predicted.z), (DEFAULT.y, DEFAULT.z));
    // Cleared, it is gone from the session.
    h.state_mut().forms_mut().tab = Tab::Session;
    h.run();
    h.get_by_label("Clear").click();
    h.run();
    assert_eq!(range(&h), None);
    // A range with from > to cannot be set, and says why.
    h.state_mut().forms_mut().range_edit = Some([10.0, -10.0, -5.0, 5.0]);
    h.run();
    assert!(
        h.query_all_by_label_contains("each side needs from < to")
            .count()
            > 0
    );
    h.get_by_label("Set range").click();
    h.run();
    assert_eq!(range(&h), None);
}

#[test]
fn the_plan_view_spreads_the_sphere_over_the_range() {
    let mut h = demo_app();
    h.get_by_label("Plan").click();
    h.run();
    h.get_by_label("plan for the measuring range").click();
    h.run();
    {
        let f = &h.state().forms().plan;
        assert_eq!(f.request.range, Some(DEFAULT));
        assert!(f.request.spread);
    }
    small_plan(&mut h, 4, 3);
    h.get_by_label("Make plan").click();
    settle(&mut h);
    assert!(
        h.query_all_by_label_contains("predicted error over the range")
            .count()
            > 0
    );
    assert!(
        h.query_all_by_label_contains("the same without the spread")
            .count()
            > 0
    );
    let plan = h
        .state()
        .state()
        .plan
        .outcome
        .as_ref()
        .and_then(|o| o.as_ref().ok())
        .map(|o| o.plan.clone())
        .expect("a plan");
    let spread = plan.stats.range_error.expect("predicted").rms_mm;
    let unspread = plan.stats.range_error_unspread.expect("compared").rms_mm;
    assert!(spread < unspread, "{spread} vs {unspread}");
}

/// The import wizard writes the measuring range into the session it opens.
#[test]
fn the_import_wizard_sets_the_measuring_range() {
    let mut h = demo_app();
    let dir = tempfile::tempdir().expect("temp dir");
    let (session, _) = spherecal::engine::tools::simulate::simulate(
        &spherecal::engine::tools::simulate::SimConfig::default(),
    )
    .expect("simulate");
    let files = spherecal::engine::tools::simulate::import_files(&session).expect("import files");
    std::fs::write(dir.path().join("joints.csv"), &files.joints_csv).unwrap();
    std::fs::create_dir_all(dir.path().join("profiles")).unwrap();
    for (id, text) in &files.profiles {
        std::fs::write(dir.path().join("profiles").join(format!("{id}.csv")), text).unwrap();
    }
    {
        let form = &mut h.state_mut().forms_mut().import;
        form.joints = dir.path().join("joints.csv").display().to_string().into();
        form.profiles = dir.path().join("profiles").display().to_string().into();
    }
    h.get_by_label("Import").click();
    h.run();
    h.get_by_label("measuring range known (sensor.range)")
        .click();
    h.run();
    assert_eq!(
        h.state().forms().import.range,
        Some([-40.0, 40.0, -40.0, 40.0])
    );
    // The button is below the fold at 768 px once the range fields show:
    // the command it sends.
    let ctx = h.ctx.clone();
    h.state_mut().command(
        &ctx,
        spherecal::app::command::Command::Import(spherecal::app::command::ImportCommand::Run),
    );
    settle(&mut h);
    let outcome = h.state().state().import.outcome.clone().expect("outcome");
    assert!(outcome.is_ok(), "{outcome:?}");
    let opened = h
        .state()
        .state()
        .loaded
        .as_ref()
        .and_then(|l| l.session.sensor_range);
    assert_eq!(opened, Some(DEFAULT));
    assert_eq!(h.state().forms().plan.request.range, Some(DEFAULT));
}
