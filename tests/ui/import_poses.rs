//! The Import view with pose files as cells write them (issue 19): the
//! layout detected and shown with the reader's warnings, the pairing of
//! every pose with its profile shown before the import (the pose file
//! and another tool's output in the folder skipped), a hand-eye guess
//! asked for with the engine's reason when the poses give none, and the
//! import opening a session of the right size whose run gives the
//! held-out figure (egui_kittest, no display).

#![cfg(feature = "gui")]
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::fmt::Write as _;
use std::path::Path;

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable as _;
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use spherecal::app::WorkbenchApp;
use spherecal::app::command::Tab;
use spherecal::app::import::form::{HandEyeChoice, ObservationKind};
use spherecal::app::job::Slot;
use spherecal::engine::assemble::PosePreview;
use spherecal::engine::base::geometry::{rigid_from_rows, roll_pitch_yaw_deg};
use spherecal::engine::base::session::Observation;
use spherecal::engine::files::import::{FlangeConvention, PoseFormat, SideChoice};
use spherecal::engine::tools::simulate::{self, SimConfig};

use crate::support::pose as pose_support;
use crate::support::ui as ui_support;
use pose_support::{fanuc_ls, headerless_table, station_poses};
use ui_support::{demo_app, labels_with, scroll_to, settle};

/// One stripe a pose: `[y, z]` points in the laser plane, mm.
type Stripes = Vec<Vec<[f64; 2]>>;

/// True flange poses and stripes of one station of a noise-free
/// simulated cell: 4 pure translations and 8 orientation changes.
fn cell() -> (Vec<Isometry3<f64>>, Vec<Vec<[f64; 2]>>) {
    let (poses, stripes, _) = cell_with_centres();
    (poses, stripes)
}

/// As [`cell`], with each pose's true sphere centre in the sensor frame.
fn cell_with_centres() -> (Vec<Isometry3<f64>>, Stripes, Vec<Point3<f64>>) {
    let config = SimConfig {
        seed: 3,
        n_translation: 4,
        n_rotation: 8,
        n_identify: 2,
        n_validate: 0,
        side: simulate::SideChoice::Plus,
        joint_noise: 0.0,
        stripe_noise: 0.0,
        ..SimConfig::default()
    };
    let (session, truth) = simulate::simulate(&config).unwrap();
    let (poses, stripes) = station_poses(&session, &truth, "P0");
    let flange_from_sensor = rigid_from_rows(&truth.hand_eye);
    let station = truth
        .stations
        .iter()
        .find(|(k, _)| *k == "P0")
        .map(|(_, c)| Point3::from(Vector3::from(*c)))
        .unwrap();
    let centres = poses
        .iter()
        .map(|p| (p * flange_from_sensor).inverse() * station)
        .collect();
    (poses, stripes, centres)
}

/// Profiles named as a published folder names them (`7_3C_line.txt`,
/// `x y z` a row, the sensor's x constant), and another tool's output.
fn profile_folder(dir: &Path, stripes: &[Vec<[f64; 2]>]) {
    for (k, s) in stripes.iter().enumerate() {
        let mut t = String::new();
        for [y, z] in s {
            writeln!(t, "0 {y} {z}").unwrap();
        }
        std::fs::write(dir.join(format!("{}_3C_line.txt", k + 1)), t).unwrap();
    }
    std::fs::write(dir.join("calibration.sec"), "{}").unwrap();
}

/// The demo app on the Import view with a pose file chosen.
fn import_view(poses: &Path, profiles: &Path) -> Harness<'static, WorkbenchApp> {
    let mut h = demo_app();
    h.get_by_label("Import").click();
    h.run();
    assert_eq!(h.state().forms().tab, Tab::Import);
    h.get_by_label("a pose file (robot program or pose table)")
        .click();
    h.run();
    {
        let form = &mut h.state_mut().forms_mut().import;
        form.profiles = profiles.display().to_string().into();
    }
    h.get_by_label("Pose file").click();
    h.run();
    h.get_by_label("Pose file")
        .type_text(&poses.display().to_string());
    settle(&mut h);
    h
}

fn preview(h: &Harness<'_, WorkbenchApp>) -> PosePreview {
    h.state()
        .state()
        .import
        .pose_preview
        .clone()
        .expect("a preview")
        .expect("the pose file reads")
}

/// Where the view's content is (the wheel scrolls it there).
const VIEW: egui::Pos2 = egui::pos2(900.0, 400.0);

/// Clicks Import and open (above the form, always in view) and waits
/// for the import.
fn import_and_open(h: &mut Harness<'_, WorkbenchApp>) {
    h.get_by_label("Import and open").click();
    settle(h);
}

#[test]
fn a_fanuc_program_in_its_profile_folder_is_detected_paired_and_imported() {
    let (poses, stripes) = cell();
    assert_eq!(poses.len(), 12);
    let dir = tempfile::tempdir().unwrap();
    profile_folder(dir.path(), &stripes);
    let ls = dir.path().join("calib.ls");
    std::fs::write(&ls, fanuc_ls(&poses, 1)).unwrap();
    let mut h = import_view(&ls, dir.path());

    // The layout as the engine detects it, the tool warning in orange.
    let p = preview(&h);
    assert_eq!(p.format, PoseFormat::FanucLs);
    assert!(p.detected && !p.joints);
    assert_eq!(p.poses.len(), 12);
    let detected = labels_with(
        &h,
        "FANUC TP program (.ls), detected from its content: 12 poses",
    );
    assert_eq!(detected.len(), 1, "{detected:?}");
    assert!(
        !labels_with(
            &h,
            "warning: positions recorded with user frame UF 0 and tool UT 1"
        )
        .is_empty(),
        "the UT warning is shown"
    );
    // The pairing before the import: natural number order, the pose file
    // and the other tool's output skipped.
    let pairing = p.pairing.clone().expect("paired");
    assert_eq!(pairing.pairs.len(), 12);
    assert_eq!(pairing.pairs[9], (9, "10_3C_line.txt".to_string()));
    assert!(pairing.problem.is_none() && pairing.poses_without.is_empty());
    assert!(scroll_to(&mut h, VIEW, "↔ 2_3C_line.txt"));
    let row = labels_with(&h, "↔ 2_3C_line.txt");
    assert!(row.len() == 1 && row[0].contains("P[2]"), "{row:?}");
    let skipped = labels_with(&h, "skipped: calib.ls");
    assert!(
        skipped.len() == 1
            && skipped[0].contains("calib.ls (the pose file)")
            && skipped[0].contains("calibration.sec"),
        "{skipped:?}"
    );
    // 4 pure translations: eq. 6-9 can start.
    assert_eq!(p.translation_group.clone().unwrap().unwrap().len(), 4);
    assert!(!labels_with(&h, "eq. 6-9 can start: 4 poses").is_empty());

    {
        let form = &mut h.state_mut().forms_mut().import;
        form.sphere_diameter = 38.1;
    }
    import_and_open(&mut h);
    let outcome = h.state().state().import.outcome.clone().expect("outcome");
    let text = outcome.expect("imported");
    let loaded = h.state().state().loaded.as_ref().expect("a session");
    assert!(loaded.session.pose_only());
    assert_eq!(loaded.session.measurements.len(), 12);
    // The side decision and the initial hand-eye, as the CLI prints them.
    assert!(text.contains("side +1 chosen from the data"), "{text}");
    assert!(
        text.contains("initial hand-eye by the paper's eq. 6-9"),
        "{text}"
    );
    assert!(
        text.contains("initial hand-eye in the session: x "),
        "{text}"
    );
    // The run gives the held-out figure beside the fit's own.
    h.get_by_label("▶ Run").click();
    settle(&mut h);
    let result = h.state().state().result.as_ref().expect("a result");
    assert!(result.file.held_out.is_some(), "a held-out figure");
}

/// A station seen from flange orientations turned about one axis only
/// (no two poses share an orientation): neither eq. 6-9 nor the general
/// solution gives a hand-eye. The true flange poses, the stripes and the
/// true hand-eye.
fn turned_about_one_axis() -> (Vec<Isometry3<f64>>, Stripes, Isometry3<f64>) {
    const RADIUS: f64 = 38.1 / 2.0;
    let flange_from_sensor = Isometry3::from_parts(
        Translation3::new(12.0, -30.0, 140.0),
        UnitQuaternion::from_euler_angles(0.05, -0.1, 0.3),
    );
    let sphere = Point3::new(900.0, 150.0, 400.0);
    let down = UnitQuaternion::from_euler_angles(std::f64::consts::PI, 0.0, 0.0);
    let (mut poses, mut stripes) = (Vec::new(), Vec::new());
    for k in 0..8 {
        let kf = f64::from(k);
        let turn = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), (kf * 6.0).to_radians());
        let rotation = turn * down;
        // The centre in the sensor frame, on side +1 of the laser plane.
        let centre = Vector3::new(6.0, -15.0 + 4.0 * kf, 180.0 + 3.0 * kf);
        let in_flange = flange_from_sensor * Point3::from(centre);
        let position = sphere.coords - rotation * in_flange.coords;
        poses.push(Isometry3::from_parts(
            Translation3::from(position),
            rotation,
        ));
        let rho = (RADIUS * RADIUS - centre.x * centre.x).sqrt();
        stripes.push(
            (0..60)
                .map(|i| {
                    let a = std::f64::consts::PI * (1.2 + 0.6 * f64::from(i) / 59.0);
                    [centre.y + rho * a.cos(), centre.z + rho * a.sin()]
                })
                .collect(),
        );
    }
    (poses, stripes, flange_from_sensor)
}

#[test]
fn a_set_without_pure_translations_asks_for_a_guess_with_the_reason() {
    let (poses, stripes, truth) = turned_about_one_axis();
    let dir = tempfile::tempdir().unwrap();
    profile_folder(dir.path(), &stripes);
    let table = dir.path().join("robpose.txt");
    std::fs::write(&table, headerless_table(&poses)).unwrap();
    let mut h = import_view(&table, dir.path());
    {
        let form = &mut h.state_mut().forms_mut().import;
        form.pose_convention = Some(FlangeConvention::FanucWpr);
        form.side = SideChoice::Plus;
    }
    settle(&mut h);
    // Before the import: no group of one orientation, said with why.
    let why = preview(&h).translation_group.unwrap().unwrap_err();
    assert!(why.contains("has 1 poses and 7 others"), "{why}");
    assert!(!labels_with(&h, "No pure-translation group: no group of one orientation").is_empty());

    import_and_open(&mut h);
    let error = h
        .state()
        .state()
        .import
        .outcome
        .clone()
        .expect("outcome")
        .expect_err("no hand-eye without a guess");
    assert!(error.contains("no initial hand-eye"), "{error}");
    let needed = h
        .state()
        .state()
        .import
        .guess_needed
        .clone()
        .expect("a guess asked for");
    assert!(needed.contains("eq. 6-9 need"), "{needed}");
    assert!(
        labels_with(&h, "A hand-eye guess is needed").len() == 2,
        "the view asks for the guess"
    );

    // The guess, typed as 6 numbers (a few mm and degrees off the truth).
    h.get_by_label("a guess: numbers").scroll_to_me();
    h.run();
    h.get_by_label("a guess: numbers").click();
    h.run();
    {
        let t = truth.translation.vector;
        let [roll, pitch, yaw] = roll_pitch_yaw_deg(&truth.rotation);
        let form = &mut h.state_mut().forms_mut().import;
        assert_eq!(form.hand_eye, HandEyeChoice::Numbers);
        form.hand_eye_numbers = [
            t.x + 2.0,
            t.y - 1.0,
            t.z + 3.0,
            roll + 1.0,
            pitch,
            yaw - 1.0,
        ];
    }
    assert!(
        !labels_with(&h, "hand-eye yaw").is_empty(),
        "the fields are shown"
    );
    import_and_open(&mut h);
    let text = h
        .state()
        .state()
        .import
        .outcome
        .clone()
        .expect("outcome")
        .expect("imported with the guess");
    assert!(text.contains("initial hand-eye: the guess given"), "{text}");
    assert!(h.state().state().import.guess_needed.is_none());
    let session = &h
        .state()
        .state()
        .loaded
        .as_ref()
        .expect("a session")
        .session;
    assert_eq!(session.measurements.len(), 8);
    let start = session.hand_eye.expect("the guess is the start");
    assert!(
        (start.translation.vector - truth.translation.vector - Vector3::new(2.0, -1.0, 3.0)).norm()
            < 1e-9
    );

    // Or from a file, as `--hand-eye FILE` takes it (a 4×4, rows, mm).
    let file = dir.path().join("hand_eye.json");
    let rows: Vec<Vec<f64>> = (0..4)
        .map(|r| (0..4).map(|c| truth.to_homogeneous()[(r, c)]).collect())
        .collect();
    std::fs::write(&file, format!("{{\"hand_eye\": {rows:?}}}")).unwrap();
    {
        let form = &mut h.state_mut().forms_mut().import;
        form.hand_eye = HandEyeChoice::File;
        form.hand_eye_file = file.display().to_string().into();
    }
    h.state_mut().forms_mut().tab = Tab::Import;
    settle(&mut h);
    import_and_open(&mut h);
    let session = &h
        .state()
        .state()
        .loaded
        .as_ref()
        .expect("a session")
        .session;
    let start = session.hand_eye.expect("the file's guess is the start");
    assert!((start.translation.vector - truth.translation.vector).norm() < 1e-9);
    assert!(start.rotation.angle_to(&truth.rotation) < 1e-9);
}

#[test]
fn a_headerless_whitespace_table_needs_its_convention_then_imports() {
    let (poses, stripes) = cell();
    let dir = tempfile::tempdir().unwrap();
    profile_folder(dir.path(), &stripes);
    let table = dir.path().join("robot.txt");
    std::fs::write(&table, headerless_table(&poses)).unwrap();
    let mut h = import_view(&table, dir.path());
    // A table does not say how it writes a pose: the engine's message.
    let error = h
        .state()
        .state()
        .import
        .pose_preview
        .clone()
        .expect("a preview")
        .expect_err("no convention");
    assert!(
        error.contains("a pose table needs its convention"),
        "{error}"
    );
    assert!(!labels_with(&h, "The pose file cannot be read").is_empty());
    h.state_mut().forms_mut().import.pose_convention = Some(FlangeConvention::FanucWpr);
    settle(&mut h);
    let p = preview(&h);
    assert_eq!(p.format, PoseFormat::Table);
    assert!(
        !labels_with(
            &h,
            "pose table, detected from its content: 12 poses in the order written"
        )
        .is_empty()
    );
    assert_eq!(p.pairing.clone().unwrap().pairs.len(), 12);
    // Forcing another layout is the engine's --pose-format.
    h.state_mut().forms_mut().import.pose_format = Some(PoseFormat::Rapid);
    settle(&mut h);
    let forced = h.state().state().import.pose_preview.clone().unwrap();
    assert!(forced.is_err(), "a table read as RAPID has no robtarget");
    h.state_mut().forms_mut().import.pose_format = None;
    settle(&mut h);
    import_and_open(&mut h);
    let loaded = h.state().state().loaded.as_ref().expect("a session");
    assert_eq!(loaded.session.measurements.len(), 12);
    let first = loaded.session.measurements[0].flange.unwrap();
    assert!((first.translation.vector - poses[0].translation.vector).norm() < 1e-6);
}

#[test]
fn centres_the_sensor_reported_are_chosen_instead_of_profiles() {
    let (poses, _, centres) = cell_with_centres();
    let dir = tempfile::tempdir().unwrap();
    let ls = dir.path().join("calib.ls");
    std::fs::write(&ls, fanuc_ls(&poses, 1)).unwrap();
    let table = dir.path().join("centres.txt");
    let mut t = String::new();
    for c in &centres {
        writeln!(t, "{:.9} {:.9} {:.9}", c.x, c.y, c.z).unwrap();
    }
    std::fs::write(&table, t).unwrap();
    let mut h = import_view(&ls, Path::new(""));
    h.get_by_label("sphere centres (its own sphere fit)")
        .click();
    settle(&mut h);
    assert_eq!(
        h.state().forms().import.observations,
        ObservationKind::Centres
    );
    assert!(
        h.query_by_label("Stripe profiles").is_none(),
        "centres instead of profiles"
    );
    h.get_by_label("Centres file").click();
    settle(&mut h);
    h.get_by_label("Centres file")
        .type_text(&table.display().to_string());
    settle(&mut h);
    let pairing = preview(&h).pairing.expect("paired");
    assert_eq!(pairing.pairs.len(), 12);
    assert_eq!(pairing.pairs[0], (0, "centre at line 1".to_string()));
    assert!(
        pairing
            .how
            .contains("sphere centres of centres.txt in order")
    );
    import_and_open(&mut h);
    let loaded = h.state().state().loaded.as_ref().expect("a session");
    assert_eq!(loaded.session.measurements.len(), 12);
    for (m, c) in loaded.session.measurements.iter().zip(&centres) {
        let Observation::Centre(x) = &m.observation else {
            panic!("{}: a centre measurement", m.id)
        };
        assert!((x - c.coords).norm() < 1e-6);
    }
}

/// A long import (1,200 profiles) shows its stage beside a Cancel
/// button; Cancel stops it, nothing is opened, the demo stays, and the
/// job's late answer is dropped.
#[test]
fn a_long_import_shows_its_progress_and_cancel_keeps_what_is_open() {
    let (poses, stripes) = cell();
    let n = 1200;
    let poses: Vec<Isometry3<f64>> = (0..n).map(|k| poses[k % poses.len()]).collect();
    let stripes: Stripes = (0..n).map(|k| stripes[k % stripes.len()].clone()).collect();
    let dir = tempfile::tempdir().unwrap();
    profile_folder(dir.path(), &stripes);
    let table = dir.path().join("robpose.txt");
    std::fs::write(&table, headerless_table(&poses)).unwrap();
    let mut h = import_view(&table, dir.path());
    h.state_mut().forms_mut().import.pose_convention = Some(FlangeConvention::FanucWpr);
    settle(&mut h);
    let demo = |h: &Harness<'_, WorkbenchApp>| {
        let loaded = h.state().state().loaded.as_ref().expect("a session");
        (
            loaded.session.name.clone(),
            loaded.session.measurements.len(),
        )
    };
    let before = demo(&h);

    h.get_by_label("Import and open").click();
    h.step();
    h.step();
    assert!(
        h.state().state().jobs.get(&Slot::Import).is_some(),
        "{} {:?}",
        ui_support::status(&h),
        h.state().state().import.outcome
    );
    // The stage in words while it runs.
    let mut seen = Vec::new();
    for _ in 0..400 {
        seen = labels_with(&h, "reading profiles: ");
        if !seen.is_empty() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
        h.step();
    }
    assert!(
        seen.len() == 1 && seen[0].ends_with(&format!(" of {n}")),
        "{seen:?}"
    );
    h.get_by_label("Cancel import").click();
    h.step();
    assert!(h.state().state().jobs.get(&Slot::Import).is_none());
    assert!(
        ui_support::status(&h).contains("import cancelled"),
        "{}",
        ui_support::status(&h)
    );
    // Whatever the job still sends is dropped.
    for _ in 0..60 {
        std::thread::sleep(std::time::Duration::from_millis(10));
        h.step();
    }
    settle(&mut h);
    assert_eq!(demo(&h), before);
    assert!(h.state().state().import.outcome.is_none());
    assert!(labels_with(&h, "reading profiles: ").is_empty());
}
