//! Issue 35 in the Import view: a fixed sensor's cell written by
//! `spherecal simulate --mount fixed` (a tracker's joint log and points
//! table) imported through the form with the fixed mount chosen, the same
//! session as `spherecal import --mount fixed` builds from its flags (one
//! builder of the import's choices, issue 30), calibrated in the window,
//! and Results shows `base_from_sensor`.

#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use egui_kittest::kittest::Queryable as _;
use spherecal::app::command::{Command, Tab, ViewCommand};
use spherecal::app::import::form::ObservationKind;
use spherecal::engine::base::session::Mount;
use spherecal::engine::files::format;
use spherecal::engine::files::import::LengthUnit;

use super::support::bin::run;
use super::support::ui::{demo_app, labels_with, scroll_to, settle};

#[test]
fn a_fixed_sensor_cell_imports_through_the_form_calibrates_and_shows_base_from_sensor() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).display().to_string();
    let (sim, cell) = (p("tracker.json"), p("cell"));
    let args = ["simulate", "--mount", "fixed", "--seed", "4", "--out", &sim];
    let (code, _, err) = run(&[&args[..], &["--csv-out", &cell, "-q"]].concat());
    assert_eq!(code, 0, "{err}");
    let (joints, points) = (p("cell/joints.csv"), p("cell/points.csv"));
    // The command line's session from the same files.
    let cli = p("cli.json");
    let (code, _, err) = run(&[
        "import",
        "--mount",
        "fixed",
        "--joints",
        &joints,
        "--centres",
        &points,
        "--robot",
        "irb2400",
        "--out",
        &cli,
        "-q",
    ]);
    assert_eq!(code, 0, "{err}");

    let mut h = demo_app();
    h.state_mut().forms_mut().tab = Tab::Import;
    h.run();
    h.get_by_label("fixed in the cell, targets on the tool (a tracker, camera or line scanner)")
        .click();
    h.run();
    h.get_by_label("target points (a tracker's or camera's table)")
        .click();
    h.run();
    assert!(h.query_by_label("Points unit").is_some());
    {
        let form = &mut h.state_mut().forms_mut().import;
        assert_eq!(form.mount, Mount::Fixed);
        assert_eq!(form.observations, ObservationKind::Centres);
        assert_eq!(form.centre_unit, LengthUnit::Mm);
        form.joints = joints.into();
        form.centres = points.into();
    }
    h.run();
    h.get_by_label("Import and open").click();
    settle(&mut h);
    let outcome = h.state().state().import.outcome.clone().expect("outcome");
    assert!(outcome.is_ok(), "{outcome:?}");
    let session = &h.state().state().loaded.as_ref().expect("opened").session;
    assert_eq!(session.mount, Mount::Fixed);
    // Form and flags build one request: the same session.
    assert_eq!(*session, format::load_session(cli.as_ref()).unwrap());
    let simulated = format::load_session(sim.as_ref()).unwrap();
    assert_eq!(session.measurements.len(), simulated.measurements.len());

    // Calibrate in the window; Results shows base_from_sensor.
    h.state_mut().forms_mut().tab = Tab::Session;
    h.run();
    h.get_by_label("▶ Run").click();
    settle(&mut h);
    let result = h.state().state().result.as_ref().expect("a result");
    let result = result.file.clone();
    assert_eq!(result.mount(), Mount::Fixed);
    let ctx = h.ctx.clone();
    let show = Command::View(ViewCommand::ShowTab(Tab::Results));
    h.state_mut().command(&ctx, show);
    h.run();
    let column = egui::pos2(700.0, 200.0);
    assert!(scroll_to(&mut h, column, "Base from sensor bT_s"));
    let x = format!("{:.4}", result.hand_eye.translation.vector.x);
    assert!(!labels_with(&h, &x).is_empty(), "base_from_sensor x {x}");
}
