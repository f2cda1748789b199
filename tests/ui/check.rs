//! The Re-check view (issue 33): a simulated IRB 2400 cell calibrated by
//! `ml` is opened with its result; the check poses are planned in the
//! view (`plan --check`) and written as CSV; the plan is then executed
//! on the true cell by the simulator, unchanged and with the sensor
//! knocked 0.5 mm, imported as sessions and checked in the view. The
//! unchanged cell HOLDS and its record parses back; the knocked one
//! FAILS naming the hand-eye; once the result changes (a new run, a
//! measurement left out) the verdict is STALE and its record is refused.
//! egui_kittest, no display.

#![cfg(feature = "gui")]
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::path::{Path, PathBuf};

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable as _;
use nalgebra::{Isometry3, Translation3};
use spherecal::app::WorkbenchApp;
use spherecal::app::command::{CheckCommand, Command, PlanExport, Tab, ViewCommand};
use spherecal::app::ledger::Artefact;
use spherecal::engine::base::session::Session;
use spherecal::engine::calibrate::solve::{self, Method, Options};
use spherecal::engine::files::format::{self, ResultFile};
use spherecal::engine::tools::plan::Plan;
use spherecal::engine::tools::simulate::{
    self, ErrorModel, InitialHandEye, PlanExecution, SimConfig, Truth, simulate_plan,
};

use crate::support::ui as ui_support;
use ui_support::{command, demo_app, labels_with, leave_out_first, open_path, settle, step_label};

/// Where the check's sphere stands (the IRB 2400's quick-start spot).
const SPHERE: [f64; 3] = [1050.0, 0.0, 475.0];

/// A simulated cell calibrated by `ml`: its session and result written to
/// `dir` and opened in the window (the result for review); the truth.
fn calibrated_cell(dir: &Path) -> (Harness<'static, WorkbenchApp>, Truth, PathBuf) {
    let config = SimConfig {
        seed: 1,
        ..SimConfig::default()
    };
    let (session, truth) = simulate::simulate(&config).unwrap();
    let mut options = Options::from_session(&session);
    options.method = Method::Ml;
    options.ml.cross_validation = false;
    let (_, cal) = solve::calibrate(&session, &options).unwrap();
    let result = ResultFile::from_calibration(&session, &cal);
    let session_path = dir.join("cell.json");
    let result_path = dir.join("cell.result.json");
    format::save_session(&session, &session_path).unwrap();
    format::save_result(&result, &result_path).unwrap();
    let mut h = demo_app();
    open_path(&mut h, session_path);
    open_path(&mut h, result_path.clone());
    assert!(h.state().state().result.is_some(), "the result is on show");
    h.state_mut().forms_mut().export_dir = dir.display().to_string();
    (h, truth, result_path)
}

/// `plan`'s poses run on the true cell with the sensor moved by
/// `shift` (mm, flange frame), recorded with the nominal robot as an
/// import makes them, written to `dir/name`.
fn executed(truth: &Truth, plan: &Plan, shift: [f64; 3], dir: &Path, name: &str) -> PathBuf {
    let hand_eye: Isometry3<f64> =
        Translation3::new(shift[0], shift[1], shift[2]) * truth.true_hand_eye();
    let config = SimConfig {
        seed: 7,
        errors: ErrorModel::None,
        initial_hand_eye: InitialHandEye::Paper,
        ..SimConfig::default()
    };
    let (mut session, _): (Session, _) = simulate_plan(
        &config,
        &truth.true_robot(),
        &hand_eye,
        &plan.simulation_poses(),
        PlanExecution::AsPlanned,
    )
    .unwrap();
    session.robot = truth.nominal.to_robot();
    session.name = name.to_string();
    let path = dir.join(name);
    format::save_session(&session, &path).unwrap();
    path
}

/// Sets the check session and presses Check.
fn check(h: &mut Harness<'_, WorkbenchApp>, session: &Path) {
    h.state_mut().forms_mut().check.session = session.display().to_string();
    command(h, Command::Check(CheckCommand::Run));
}

fn verdict(h: &Harness<'_, WorkbenchApp>) -> spherecal::app::check::job::CheckView {
    match &h.state().state().check.outcome {
        Some(Ok(v)) => v.clone(),
        other => panic!("no verdict: {other:?}"),
    }
}

#[test]
fn the_check_view_holds_on_an_unchanged_cell_flags_a_knock_and_goes_stale() {
    let dir = tempfile::tempdir().unwrap();
    let (mut h, truth, _) = calibrated_cell(dir.path());
    command(&mut h, Command::View(ViewCommand::ShowTab(Tab::Check)));
    assert!(step_label(&h, "9. Re-checked (optional)").starts_with('○'));
    // 1. Plan the check about the sphere; write its CSV.
    h.state_mut().forms_mut().check.sphere = Some(SPHERE);
    command(&mut h, Command::Check(CheckCommand::Plan));
    let planned = match &h.state().state().check.plan {
        Some(Ok(p)) => p.clone(),
        other => panic!("no check planned: {other:?}"),
    };
    assert!(
        planned.plan.poses.len() <= 30,
        "{}",
        planned.plan.poses.len()
    );
    assert!(
        planned
            .lines
            .iter()
            .any(|l| l.contains("the sensor knocked")),
        "{:?}",
        planned.lines
    );
    command(
        &mut h,
        Command::Check(CheckCommand::Export(PlanExport::Csv)),
    );
    let csv = dir.path().join("check-irb2400.csv");
    let text = std::fs::read_to_string(&csv).expect("the check's CSV");
    assert_eq!(
        text,
        spherecal::engine::tools::plan::plan_csv(&planned.plan)
    );

    // 2. The unchanged cell holds; its record is written and parses back.
    let unchanged = executed(
        &truth,
        &planned.plan,
        [0.0; 3],
        dir.path(),
        "unchanged.json",
    );
    check(&mut h, &unchanged);
    let v = verdict(&h);
    assert!(v.checked.test.holds, "{:?}", v.lines);
    assert!(!labels_with(&h, "HOLDS").is_empty());
    assert!(step_label(&h, "9. Re-checked (optional)").starts_with('●'));
    command(&mut h, Command::Check(CheckCommand::Record));
    let record = format::check_record_path(&unchanged);
    let text = std::fs::read_to_string(&record).expect("the record");
    let parsed = format::parse_check_record(&text, &record).unwrap();
    assert!(parsed.holds);
    assert_eq!(parsed.sightings, v.checked.sightings);
    assert!(parsed.result_file.ends_with("cell.result.json"));

    // 3. The sensor knocked 0.5 mm: FAILS, the hand-eye named.
    let knocked = executed(
        &truth,
        &planned.plan,
        [0.0, 0.5, 0.0],
        dir.path(),
        "knocked.json",
    );
    check(&mut h, &knocked);
    let v = verdict(&h);
    assert!(!v.checked.test.holds, "{:?}", v.lines);
    assert!(v.moved[0].contains("the hand-eye"), "{:?}", v.moved);
    assert!(!labels_with(&h, "FAILS").is_empty());
    assert!(
        v.lines.iter().any(|l| l.starts_with("  sphere at")),
        "the fitted sphere positions: {:?}",
        v.lines
    );

    // 4. The result changes (a new run of the same session): the verdict
    // and the check's plan are STALE, the record and the plan's files
    // refused.
    h.get_by_label("▶ Run").click();
    settle(&mut h);
    assert!(h.state().state().ledger.stale(Artefact::Result).is_none());
    command(&mut h, Command::View(ViewCommand::ShowTab(Tab::Check)));
    assert!(h.state().state().ledger.stale(Artefact::Check).is_some());
    assert!(
        h.state()
            .state()
            .ledger
            .stale(Artefact::CheckPlan)
            .is_some()
    );
    assert!(!labels_with(&h, "FAILS (stale)").is_empty());
    assert!(step_label(&h, "9. Re-checked (optional)").starts_with('!'));
    command(&mut h, Command::Check(CheckCommand::Record));
    assert!(
        !format::check_record_path(&knocked).exists(),
        "a stale verdict is not written"
    );
    let notice = h.state().state().notice.clone().expect("a refusal");
    assert!(notice.body.contains("stale"), "{}", notice.body);
    std::fs::remove_file(&csv).unwrap();
    command(
        &mut h,
        Command::Check(CheckCommand::Export(PlanExport::Csv)),
    );
    assert!(!csv.exists(), "a stale check plan is not written");
    // Checked again: current.
    command(&mut h, Command::Check(CheckCommand::Run));
    assert!(h.state().state().ledger.stale(Artefact::Check).is_none());
    // A measurement left out: the result and the verdict are stale, and
    // no check is made against a stale result.
    leave_out_first(&mut h);
    assert!(h.state().state().ledger.stale(Artefact::Check).is_some());
    command(&mut h, Command::Check(CheckCommand::Run));
    assert!(h.state().state().ledger.stale(Artefact::Check).is_some());
    let notice = h.state().state().notice.clone().expect("a refusal");
    assert_eq!(notice.title, "Not checked");
}
