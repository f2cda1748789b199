//! A fixed sensor and targets on the tool (FORMAT.md `sensor.mount:
//! "fixed"`, added 2026-11-27): the file rules and round trip, and the
//! calibration of simulated tracker and scanner cells against their truth
//! (exact without noise; with noise, the validate poses' prediction error
//! against the floor of the true model on the same data).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

use spherecal::engine::base::session::{Mount, Session, Use};
use spherecal::engine::calibrate::solve::{self, Method, Options};
use spherecal::engine::files::format::stations::prediction_errors;
use spherecal::engine::files::format::{self, ResultFile};
use spherecal::engine::files::import::tracker::{
    FixedPoints, FixedPoses, TrackerSpec, read_tracker,
};
use spherecal::engine::files::import::{AngleUnit, LengthUnit};
use spherecal::engine::tools::simulate::{FixedCell, FixedTruth, SimConfig, simulate_fixed};

pub(crate) fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

/// Calibrates `session` with `method` and returns the result and, per
/// validate measurement, the calibrated prediction error beside the true
/// model's (the floor).
pub(crate) fn score(
    session: &Session,
    truth: &FixedTruth,
    method: Method,
) -> (ResultFile, Vec<(f64, f64)>) {
    let noise_free = truth.noise_free;
    let mut options = Options {
        method,
        // To the solver's own convergence, not the paper's 0.15 mm stop.
        threshold: 0.0,
        max_iterations: 50,
        ..Options::from_session(session)
    };
    // Without noise the prior would only pull the estimate off the truth.
    options.ml.prior = !noise_free;
    let (prepared, cal) = solve::calibrate(session, &options).unwrap();
    let result = ResultFile::from_calibration(session, &cal);
    let predicted = prediction_errors(&result.centres, &result.stations);
    let pairs = predicted
        .iter()
        .map(|p| {
            let i = session
                .measurements
                .iter()
                .position(|m| m.id == p.measurement)
                .unwrap();
            let m = &session.measurements[i];
            let measured = prepared.measurements[i].centre_in_sensor;
            (
                p.error,
                truth.prediction_error(&m.joints, &m.station, &measured),
            )
        })
        .collect();
    (result, pairs)
}

pub(crate) fn config(seed: u64) -> SimConfig {
    SimConfig {
        seed,
        ..SimConfig::default()
    }
}

#[test]
fn a_fixed_session_round_trips_and_needs_no_translation_or_rotation_group() {
    let (session, _) = simulate_fixed(&config(1), &FixedCell::tracker(0.01)).unwrap();
    assert_eq!(session.mount, Mount::Fixed);
    assert!(session.hand_eye.is_none());
    assert_eq!(session.with_use(Use::Translation).count(), 0);
    let text = format::session_to_json(&session);
    assert!(text.contains("\"mount\": \"fixed\""), "{text}");
    let back = format::parse_session(&text, Path::new("fixed.json")).unwrap();
    assert_eq!(back, session);
    // A mount that is neither is refused, naming the key.
    let bad = text.replace("\"mount\": \"fixed\"", "\"mount\": \"ceiling\"");
    let e = format::parse_session(&bad, Path::new("fixed.json")).unwrap_err();
    assert!(e.to_string().contains("sensor.mount"), "{e}");
    // The same measurements on the flange mount need the groups.
    let flange = Session {
        mount: Mount::Flange,
        ..session
    };
    assert!(flange.check_rules().is_err());
}

#[test]
fn a_tracker_cell_without_noise_is_recovered_exactly() {
    let (session, truth) = simulate_fixed(&config(3), &FixedCell::tracker(0.0)).unwrap();
    for method in [Method::Ml, Method::Paper] {
        let (result, pairs) = score(&session, &truth, method);
        assert_eq!(result.mount(), Mount::Fixed);
        assert_eq!(result.stations.len(), 3);
        assert!(result.stations.iter().all(|s| s.frame == "flange"));
        let worst = pairs.iter().map(|p| p.0).fold(0.0, f64::max);
        let tolerance = if method == Method::Ml { 1e-6 } else { 1e-3 };
        assert!(
            worst < tolerance,
            "{method:?}: validate prediction error {worst} mm without noise"
        );
        // The result reads back equal, its stations and mount with it.
        let text = format::result_to_json(&result);
        let back = format::parse_result(&text, Path::new("r.json")).unwrap();
        assert_eq!(back, result);
        assert_eq!(back.mount(), Mount::Fixed);
    }
}

#[test]
fn a_tracker_cell_with_noise_predicts_validate_poses_near_the_floor() {
    for seed in [5, 6] {
        let (session, truth) = simulate_fixed(&config(seed), &FixedCell::tracker(0.01)).unwrap();
        let (result, pairs) = score(&session, &truth, Method::Ml);
        let (cal, floor): (Vec<f64>, Vec<f64>) = pairs.into_iter().unzip();
        let (cal, floor) = (rms(&cal), rms(&floor));
        eprintln!(
            "tracker seed {seed}: validate rms {cal:.4} mm, floor {floor:.4} mm, ε after {:.4} mm",
            result.epsilon_after
        );
        assert!(floor > 0.005 && floor < 0.03, "floor {floor}");
        assert!(
            cal <= 1.3 * floor,
            "seed {seed}: {cal} mm against the floor {floor} mm"
        );
    }
}

#[test]
fn a_fixed_scanner_and_one_sphere_on_the_tool_is_calibrated_to_its_floor() {
    let (exact, truth) = simulate_fixed(&config(7), &FixedCell::scanner(0.0)).unwrap();
    let (_, pairs) = score(&exact, &truth, Method::Ml);
    let worst = pairs.iter().map(|p| p.0).fold(0.0, f64::max);
    assert!(worst < 1e-6, "scanner without noise: {worst} mm");
    let (noisy, truth) = simulate_fixed(&config(7), &FixedCell::scanner(0.02)).unwrap();
    let (result, pairs) = score(&noisy, &truth, Method::Ml);
    let (cal, floor): (Vec<f64>, Vec<f64>) = pairs.into_iter().unzip();
    let (cal, floor) = (rms(&cal), rms(&floor));
    eprintln!("scanner: validate rms {cal:.4} mm, floor {floor:.4} mm");
    assert_eq!(result.stations.len(), 1);
    assert!(cal <= 1.3 * floor, "{cal} mm against the floor {floor} mm");
}

#[test]
fn the_first_joint_is_fixed_for_the_sensor_pose_and_the_last_for_the_targets() {
    let (session, _) = simulate_fixed(&config(3), &FixedCell::tracker(0.01)).unwrap();
    let (_, cal) = solve::calibrate(&session, &Options::from_session(&session)).unwrap();
    let result = ResultFile::from_calibration(&session, &cal);
    let block = format::solver_block(&result.solver);
    let fixed: Vec<String> = serde_json::from_value(block["fixed"].clone()).unwrap();
    eprintln!("fixed: {fixed:?}");
    for p in ["alpha1", "a1", "theta1", "d1", "theta6", "d6"] {
        assert!(fixed.iter().any(|f| f == p), "{p} not fixed: {fixed:?}");
    }
    for p in ["he_x", "he_rz", "a2", "theta3"] {
        assert!(!fixed.iter().any(|f| f == p), "{p} fixed: {fixed:?}");
    }
}

fn tracker_spec(points: &Path, unit: LengthUnit) -> TrackerSpec {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    TrackerSpec {
        poses: FixedPoses::Joints {
            path: root.join("examples/tracker/joints.csv"),
            id_column: "id".into(),
            joint_columns: (1..=6).map(|k| format!("j{k}")).collect(),
            angle_unit: AngleUnit::Deg,
        },
        points: FixedPoints::Table {
            path: points.to_path_buf(),
            unit,
        },
        robot: Some(spherecal::engine::base::robot::irb2400().robot),
        diameter: 38.1,
        hand_eye: None,
        name: "tracker".into(),
    }
}

#[test]
fn a_trackers_table_in_metres_with_named_columns_and_repeats_imports_averaged() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let named = root.join("examples/tracker/points-m.csv");
    let (session, notes) = read_tracker(&tracker_spec(&named, LengthUnit::M)).unwrap();
    assert_eq!(session.mount, Mount::Fixed);
    assert_eq!(session.measurements.len(), 24);
    assert_eq!(session.with_use(Use::Validate).count(), 6);
    assert!(
        notes.iter().any(|n| n.contains("averaged at 24")),
        "{notes:?}"
    );
    // The same points one a row, in mm, in another order: the same session.
    let dir = tempfile::tempdir().unwrap();
    let rows = dir.path().join("rows.csv");
    let mut text = String::from("pose,target,x,y,z\n");
    for m in session.measurements.iter().rev() {
        let spherecal::engine::base::session::Observation::Centre(c) = &m.observation else {
            panic!("a centre")
        };
        let pose = m.id.split('-').next().unwrap();
        text += &format!("{pose},{},{},{},{}\n", m.station, c.x, c.y, c.z);
    }
    std::fs::write(&rows, text).unwrap();
    let (again, _) = read_tracker(&tracker_spec(&rows, LengthUnit::Mm)).unwrap();
    assert_eq!(again.measurements.len(), 24);
    // Poses in the log's order, targets in the table's order within one.
    let key = |s: &Session| {
        let mut v: Vec<(String, String, Vec<f64>)> = s
            .measurements
            .iter()
            .map(|m| (m.id.clone(), m.station.clone(), m.joints.clone()))
            .collect();
        v.sort_by(|a, b| a.0.cmp(&b.0));
        v
    };
    assert_eq!(key(&again), key(&session));
    assert_eq!(again.measurements[0].id, "P1-SMR3");
    // A pose the joint log does not have is named with its line.
    std::fs::write(&rows, "pose,x,y,z\nP1,1,2,3\nP99,1,2,3\n").unwrap();
    let e = read_tracker(&tracker_spec(&rows, LengthUnit::Mm)).unwrap_err();
    assert!(
        e.to_string().contains("line 3") && e.to_string().contains("P99"),
        "{e}"
    );
}

#[test]
fn a_fixed_plan_puts_the_target_in_the_box_facing_the_sensor() {
    use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
    use spherecal::engine::tools::plan::fixed::{FixedPlanRequest, fixed_plan_csv, plan_fixed};
    let position = Vector3::new(2600.0, 300.0, 900.0);
    let centre = Vector3::new(1100.0, 0.0, 700.0);
    let req = FixedPlanRequest {
        preset: spherecal::engine::base::robot::irb2400(),
        base_from_sensor: Isometry3::from_parts(
            Translation3::from(position),
            UnitQuaternion::face_towards(&(centre - position), &Vector3::z()),
        ),
        target: Vector3::new(0.0, 0.0, 100.0),
        target_normal: Vector3::z(),
        cone_deg: 45.0,
        reach_mm: 5000.0,
        box_min: [800.0, -300.0, 400.0],
        box_max: [1400.0, 300.0, 1000.0],
        n_identify: 30,
        n_validate: 8,
        candidates: 600,
        seed: 3,
    };
    let poses = plan_fixed(&req).unwrap();
    assert_eq!(poses.len(), 38);
    assert_eq!(poses.iter().filter(|p| p.usage == Use::Validate).count(), 8);
    for p in &poses {
        let flange = req.preset.robot.base_from_flange(&p.joints);
        let x = (flange * Point3::from(req.target)).coords;
        assert!((0..3).all(|k| x[k] >= req.box_min[k] - 1e-3 && x[k] <= req.box_max[k] + 1e-3));
        let to_sensor = (position - x).normalize();
        let facing = (flange.rotation * Vector3::z()).dot(&to_sensor);
        assert!(facing >= 45f64.to_radians().cos() - 1e-6, "{}", p.id);
    }
    assert_eq!(plan_fixed(&req).unwrap(), poses, "seeded");
    let csv = fixed_plan_csv(&poses);
    assert!(
        csv.starts_with("id,use,j1,j2,j3,j4,j5,j6\nP1,identify,"),
        "{csv}"
    );
}

#[test]
fn compensation_takes_a_fixed_sensors_model_but_not_its_sensor_as_a_tool() {
    use spherecal::engine::uses::compensate::{CompensateError, Model, Tcp};
    let (session, _) = simulate_fixed(&config(3), &FixedCell::tracker(0.01)).unwrap();
    let (_, cal) = solve::calibrate(&session, &Options::from_session(&session)).unwrap();
    let result = ResultFile::from_calibration(&session, &cal);
    assert!(matches!(
        Model::new(&result, Some(&session), Tcp::Sensor),
        Err(CompensateError::FixedSensor)
    ));
    let flange = Model::new(&result, Some(&session), Tcp::Flange);
    assert!(flange.is_ok(), "{:?}", flange.err());
}
