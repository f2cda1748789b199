//! Pose-only sessions (FORMAT.md "Additions to version 1":
//! `measurements[].flange`): the file rules, the round trip, and the
//! hand-eye calibration from flange poses against the simulator's truth.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

use nalgebra::Isometry3;
use spherecal::engine::base::session::Session;
use spherecal::engine::calibrate::solve::{self, Method, Options};
use spherecal::engine::files::format::{self, ResultFile};
use spherecal::engine::tools::simulate::{self, ErrorModel, SimConfig, Truth};

/// A simulated session turned pose-only: each measurement's flange pose is
/// the true robot's (the controller reports where the flange really is),
/// the joints and the robot block are dropped.
fn pose_only(config: &SimConfig) -> (Session, Truth) {
    let (mut session, truth) = simulate::simulate(config).unwrap();
    let robot = truth.true_robot();
    for m in &mut session.measurements {
        m.flange = Some(robot.base_from_flange(&m.joints));
        m.joints.clear();
    }
    session.robot_given = false;
    session.robot = spherecal::engine::base::robot::Robot::new(String::new(), Vec::new());
    session.base_given = false;
    session.flange_given = false;
    (session, truth)
}

fn reload(session: &Session) -> Session {
    let text = format::session_to_json(session);
    format::parse_session(&text, Path::new("pose-only.json")).unwrap()
}

#[test]
fn pose_only_sessions_round_trip_and_leave_the_robot_out() {
    let (session, _) = pose_only(&SimConfig::default());
    let text = format::session_to_json(&session);
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert!(v.get("robot").is_none(), "no robot block is written");
    let m0 = &v["measurements"][0];
    assert!(m0.get("joints").is_none());
    assert_eq!(m0["flange"].as_array().unwrap().len(), 4);
    let loaded = reload(&session);
    assert!(loaded.pose_only());
    assert!(!loaded.robot_given);
    assert_eq!(reload(&loaded), loaded, "load → save → load is stable");
}

#[test]
fn pose_only_rules_name_the_measurement() {
    let (session, _) = pose_only(&SimConfig::default());
    let text = format::session_to_json(&session);
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    // Mixing joints and flange (with a robot, so that joints are allowed).
    let (joints_session, _) = simulate::simulate(&SimConfig::default()).unwrap();
    let full: serde_json::Value =
        serde_json::from_str(&format::session_to_json(&joints_session)).unwrap();
    let mut mixed = v.clone();
    mixed["robot"] = full["robot"].clone();
    let id = mixed["measurements"][3]["id"].as_str().unwrap().to_string();
    let m = mixed["measurements"][3].as_object_mut().unwrap();
    m.remove("flange");
    m.insert("joints".into(), serde_json::json!([0, 0, 0, 0, 0, 0]));
    let err = format::parse_session(&mixed.to_string(), Path::new("mixed.json"))
        .unwrap_err()
        .to_string();
    assert!(err.contains(&id) && err.contains("not both"), "{err}");
    // Both keys in one measurement.
    let mut both = v.clone();
    both["measurements"][0]["joints"] = serde_json::json!([0, 0, 0, 0, 0, 0]);
    let err = format::parse_session(&both.to_string(), Path::new("both.json"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("both `joints` and `flange`"), "{err}");
    // A flange that is not a rotation.
    v["measurements"][1]["flange"][0][0] = serde_json::json!(2.0);
    let err = format::parse_session(&v.to_string(), Path::new("bad.json"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("flange"), "{err}");
    // Joints without a robot.
    let mut no_robot = full.clone();
    no_robot.as_object_mut().unwrap().remove("robot");
    let err = format::parse_session(&no_robot.to_string(), Path::new("norobot.json"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("no `robot`"), "{err}");
}

/// Hand-eye error of a result against the truth: translation mm, rotation deg.
fn hand_eye_error(result: &Isometry3<f64>, truth: &Isometry3<f64>) -> (f64, f64) {
    (
        (result.translation.vector - truth.translation.vector).norm(),
        result.rotation.angle_to(&truth.rotation).to_degrees(),
    )
}

#[test]
fn the_hand_eye_is_exact_from_noise_free_flange_poses() {
    // Every noise source off, stripes at full precision; no stop at a
    // threshold and no prior (which would only pull off the truth).
    let config = SimConfig {
        seed: 11,
        stripe_noise: 0.0,
        joint_noise: 0.0,
        centre_noise: 0.0,
        tracker_noise: 0.0,
        stripe_decimals: 12,
        ..SimConfig::default()
    };
    let (session, truth) = pose_only(&config);
    for method in [Method::Ml, Method::Paper] {
        let mut options = Options {
            method,
            ..Options::from_session(&session)
        };
        options.threshold = 0.0;
        options.ml.prior = false;
        let (_, cal) = solve::calibrate(&session, &options).unwrap();
        let (dt, dr) = hand_eye_error(&cal.hand_eye, &truth.true_hand_eye());
        assert!(dt < 1e-6 && dr < 1e-7, "{method:?}: {dt} mm, {dr} deg");
        assert!(cal.epsilon_after() < 1e-6, "{}", cal.epsilon_after());
        let file = ResultFile::from_calibration(&session, &cal);
        assert!(file.robot.is_none(), "robot: null");
        assert!(file.joint_errors.is_empty());
        let back =
            format::parse_result(&format::result_to_json(&file), Path::new("r.json")).unwrap();
        assert_eq!(back, file);
    }
}

#[test]
fn with_noise_the_hand_eye_error_is_at_the_noise_floor() {
    let config = SimConfig {
        errors: ErrorModel::Table1,
        ..SimConfig::default()
    };
    let (session, truth) = pose_only(&config);
    let (_, cal) = solve::calibrate(&session, &Options::from_session(&session)).unwrap();
    let (dt, dr) = hand_eye_error(&cal.hand_eye, &truth.true_hand_eye());
    // The paper's geometry sees the sphere within a few mm of one sensor
    // point, so the rotation is seen through a short lever (~12 mm): a
    // 0.02 mm stripe noise leaves tenths of a degree (issue 14's point).
    assert!(dt < 0.3 && dr < 0.6, "{dt} mm, {dr} deg");
    // The calibrated within-station scatter against the floor: the true
    // hand-eye on the same noisy data.
    let floor_est = spherecal::engine::calibrate::solve::estimate::Estimate {
        robot: session.solver_robot(),
        flange_from_sensor: truth.true_hand_eye(),
    };
    let (prepared, _) = solve::calibrate(&session, &Options::from_session(&session)).unwrap();
    let stations = prepared.stations(&session, spherecal::engine::base::session::Use::Identify);
    let floor =
        spherecal::engine::calibrate::validate::epsilon(&floor_est.station_centres(&stations));
    let after = cal.epsilon_after();
    // ml weighs by its noise model rather than minimising ε itself, so ε
    // may sit a little above the floor.
    assert!(after <= floor * 1.1, "ε after {after} mm, floor {floor} mm");
}
