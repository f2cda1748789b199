//! The re-check of a pose-only cell (issue 33): a result calibrated from
//! flange poses (the hand-eye alone) re-checked with a pose-only check
//! session (flange poses the controller reports): an unchanged cell
//! holds, a sensor moved on its mount fails and the hand-eye is named;
//! and the check's record round-trips through its file and `history`.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use spherecal::engine::base::session::Session;
use spherecal::engine::calibrate::solve::ml::recheck::Moved;
use spherecal::engine::calibrate::solve::{self, Method, Options};
use spherecal::engine::files::format::{self, ResultFile};
use spherecal::engine::tools::history;
use spherecal::engine::tools::simulate::{self, SimConfig};
use spherecal::engine::uses::check::{DEFAULT_ALPHA, check_record, check_session};

/// A simulated session turned pose-only: the flange poses the true robot
/// reaches (the controller's report), no joints, no robot; `knock` is the
/// sensor's move on its mount since the calibration (flange frame): the
/// sensor saw the sphere from `F·K·H`, the controller still reports `F`,
/// so the poses the check gets are `F·K` for the data of `F`.
fn pose_only(seed: u64, knock: Isometry3<f64>, keep: usize) -> Session {
    let config = SimConfig {
        seed,
        ..SimConfig::default()
    };
    let (mut session, truth) = simulate::simulate(&config).unwrap();
    let robot = truth.true_robot();
    for m in &mut session.measurements {
        m.flange = Some(robot.base_from_flange(&m.joints) * knock.inverse());
        m.joints.clear();
    }
    session.measurements.truncate(keep);
    session.robot_given = false;
    session.robot = spherecal::engine::base::robot::Robot::new(String::new(), Vec::new());
    session.base_given = false;
    session.flange_given = false;
    session
}

fn calibrated() -> ResultFile {
    let session = pose_only(1, Isometry3::identity(), usize::MAX);
    let mut options = Options::from_session(&session);
    options.method = Method::Ml;
    options.ml.cross_validation = false;
    let (_, cal) = solve::calibrate(&session, &options).unwrap();
    ResultFile::from_calibration(&session, &cal)
}

/// 30 sightings of another day's scan (other noise): the size of a
/// quick check.
const CHECK_POSES: usize = 30;

#[test]
fn a_pose_only_cell_holds_unchanged_and_fails_when_the_sensor_moved() {
    let result = calibrated();
    assert!(result.hand_eye_only());
    let mut held = 0;
    for seed in 20..30 {
        let check = pose_only(seed, Isometry3::identity(), CHECK_POSES);
        let c = check_session(&check, &result, DEFAULT_ALPHA).unwrap();
        assert!(c.hand_eye_only);
        assert!(
            c.test
                .explanations
                .iter()
                .all(|e| e.moved == Moved::HandEye)
        );
        held += usize::from(c.test.holds);
    }
    // α = 0.1 %: ten unchanged checks hold (one false alarm would be a
    // 1 % event).
    assert_eq!(held, 10);
    // The sensor moved 0.5 mm along the flange's y, and turned 0.3° about x.
    for knock in [
        Isometry3::from_parts(Translation3::new(0.0, 0.5, 0.0), UnitQuaternion::identity()),
        Isometry3::from_parts(
            Translation3::identity(),
            UnitQuaternion::from_scaled_axis(Vector3::x() * 0.3_f64.to_radians()),
        ),
    ] {
        let check = pose_only(40, knock, CHECK_POSES);
        let c = check_session(&check, &result, DEFAULT_ALPHA).unwrap();
        assert!(!c.test.holds, "{knock:?}: {:?}", c.test);
        let best = &c.test.explanations[0];
        assert_eq!(best.moved, Moved::HandEye);
        assert!(best.explains, "{best:?}");
    }
    // The shift's size, in the flange frame, from the hand-eye's change
    // (a twist in the sensor frame).
    let knock = Isometry3::from_parts(Translation3::new(0.0, 0.5, 0.0), UnitQuaternion::identity());
    let c = check_session(&pose_only(41, knock, CHECK_POSES), &result, DEFAULT_ALPHA).unwrap();
    let best = &c.test.explanations[0];
    let found =
        result.hand_eye.rotation * Vector3::new(best.change[0], best.change[1], best.change[2]);
    assert!(
        (found - Vector3::new(0.0, 0.5, 0.0)).norm() < 0.15,
        "{found}"
    );
}

/// The record `spherecal check` writes: read back equal, and `history`
/// lists it with its verdict, date and what moved, beside the result.
#[test]
fn the_check_record_is_listed_by_history() {
    let dir = tempfile::tempdir().unwrap();
    let result = calibrated();
    let result_path = dir.path().join("cell 2026-11-20.result.json");
    format::save_result(&result, &result_path).unwrap();
    let knock = Isometry3::from_parts(Translation3::new(0.5, 0.0, 0.0), UnitQuaternion::identity());
    for (name, knock) in [
        ("check-ok", Isometry3::identity()),
        ("check-knocked", knock),
    ] {
        let session = pose_only(50, knock, CHECK_POSES);
        let checked = check_session(&session, &result, DEFAULT_ALPHA).unwrap();
        let session_path = dir.path().join(format!("{name}.json"));
        let record = check_record(
            &checked,
            &session,
            &result,
            (&session_path, &result_path),
            std::time::SystemTime::now(),
        );
        let path = format::check_record_path(&session_path);
        assert_eq!(path, dir.path().join(format!("{name}.check.json")));
        format::save_check_record(&path, &record).unwrap();
        assert_eq!(format::load_check_record(&path).unwrap(), record);
        assert_eq!(record.holds, checked.test.holds);
        assert_eq!(record.moved.is_some(), !checked.test.holds);
    }
    let library = history::read_library(dir.path()).unwrap();
    assert_eq!(library.entries.len(), 1);
    assert!(library.problems.is_empty(), "{:?}", library.problems);
    assert_eq!(library.checks.len(), 2);
    let ok = library
        .checks
        .iter()
        .find(|c| c.path.ends_with("check-ok.check.json"))
        .unwrap();
    assert!(ok.record.holds && ok.record.moved.is_none());
    assert!(ok.date.has_time && ok.date.year >= 2026, "{}", ok.date);
    let bad = library
        .checks
        .iter()
        .find(|c| c.path.ends_with("check-knocked.check.json"))
        .unwrap();
    assert!(!bad.record.holds);
    assert!(
        bad.record.moved.as_deref().unwrap().contains("hand-eye"),
        "{:?}",
        bad.record.moved
    );
    assert_eq!(bad.record.result_session, result.session);
    // A record that is not one: a problem of the library, named.
    std::fs::write(
        dir.path().join("broken.check.json"),
        r#"{"format": "spherecal-check", "version": 1}"#,
    )
    .unwrap();
    let library = history::read_library(dir.path()).unwrap();
    assert_eq!(library.checks.len(), 2);
    assert!(
        library
            .problems
            .iter()
            .any(|p| p.path.ends_with("broken.check.json") && p.message.contains("missing field")),
        "{:?}",
        library.problems
    );
}
