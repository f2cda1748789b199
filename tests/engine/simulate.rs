//! The simulator against its own ground truth and against FORMAT.md:
//! determinism, exact geometry without noise, noise of the stated size,
//! the translation/rotation procedure of paper 3.1, every preset's session
//! loading through the strict loader, and the shape of the shared example
//! truth file.

#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

use nalgebra::{Matrix3, Point3, Vector3};
use spherecal::engine::base::cell::sensor;
use spherecal::engine::base::robot::{self, RobotChoice};
use spherecal::engine::base::session::{Observation, Session, Use};
use spherecal::engine::files::format;
use spherecal::engine::tools::simulate::{
    self, ErrorModel, InitialHandEye, SideChoice, SimConfig, Truth,
};

use crate::support::sim::{noise_free, simulate};

/// A small session (fast in debug builds) with the default noise.
fn small(seed: u64, robot: RobotChoice) -> SimConfig {
    SimConfig {
        seed,
        robot,
        n_identify: 3,
        n_validate: 3,
        ..SimConfig::default()
    }
}

fn example_truth_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/v1/example-irb2400.truth.json")
}

fn std_dev(values: &[f64]) -> f64 {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
}

/// `|x|` bounds of a sensor-frame centre: `R · sin(cut ± jitter)`.
fn x_bounds(c: &SimConfig) -> (f64, f64) {
    let r = c.diameter / 2.0;
    (
        r * (c.cut_angle - c.cut_jitter).to_radians().sin(),
        r * (c.cut_angle + c.cut_jitter).to_radians().sin(),
    )
}

#[test]
fn same_seed_same_files_other_seed_other_files() {
    let (s1, t1) = simulate(&small(21, RobotChoice::Irb2400));
    let (s2, t2) = simulate(&small(21, RobotChoice::Irb2400));
    let (s3, t3) = simulate(&small(22, RobotChoice::Irb2400));
    assert_eq!(format::session_to_json(&s1), format::session_to_json(&s2));
    assert_eq!(simulate::truth_to_json(&t1), simulate::truth_to_json(&t2));
    assert_ne!(format::session_to_json(&s1), format::session_to_json(&s3));
    assert_ne!(simulate::truth_to_json(&t1), simulate::truth_to_json(&t3));
}

#[test]
fn noise_free_session_matches_its_truth_exactly() {
    let config = noise_free(3);
    let (session, truth) = simulate(&config);
    let robot = truth.true_robot();
    let hand_eye = truth.true_hand_eye();
    let radius = config.diameter / 2.0;
    let (x_min, x_max) = x_bounds(&config);
    let mut sides = HashSet::new();
    assert_eq!(session.measurements.len(), truth.measurements.len());
    for m in &session.measurements {
        let t = truth
            .measurement(&m.id)
            .expect("truth of every measurement");
        assert_eq!(
            (t.station.as_str(), t.usage, t.side),
            (m.station.as_str(), m.usage, m.side)
        );
        let station = truth.station(&m.station).expect("station");
        let c = Vector3::from(t.sensor_centre);
        // Paper eq. 1: the true chain maps the true centre onto the station.
        let seen = robot.base_from_flange(&t.joints_actual) * hand_eye * Point3::from(c);
        assert!(
            (seen.coords - station).norm() < 1e-6,
            "{}: {}",
            m.id,
            (seen.coords - station).norm()
        );
        // Without noise the readings are the actual joints (9 decimals).
        for (a, b) in m.joints.iter().zip(&t.joints_actual) {
            assert!((a - b).abs() <= 5.1e-10, "{}: {a} vs {b}", m.id);
        }
        let recorded = robot.base_from_flange(&m.joints) * hand_eye * Point3::from(c);
        assert!((recorded.coords - station).norm() < 1e-6, "{}", m.id);
        // The cut angle and the side.
        assert!(
            c.x.abs() >= x_min - 1e-12 && c.x.abs() <= x_max + 1e-12,
            "{}: x = {}",
            m.id,
            c.x
        );
        assert_eq!(c.x.signum() as i8, m.side, "{}", m.id);
        sides.insert(m.side);
        assert!(
            c.y.abs() <= 2.0 + 1e-12 && c.z.abs() <= 3.0 + 1e-12 || m.usage == Use::Translation
        );
        // The stripe is the arc of the cut circle facing the camera (+z).
        let Observation::Stripe(points) = &m.observation else {
            panic!("{}: expected a stripe", m.id);
        };
        let r = (radius * radius - c.x * c.x).sqrt();
        assert!(points.len() >= 50, "{}: {} points", m.id, points.len());
        for p in points {
            let d = ((p[0] - c.y).powi(2) + (p[1] - c.z).powi(2)).sqrt() - r;
            assert!(
                d.abs() < 1e-4,
                "{}: point {p:?} off the circle by {d}",
                m.id
            );
        }
        let mean_z = points.iter().map(|p| p[1]).sum::<f64>() / points.len() as f64;
        assert!(mean_z > c.z + 0.5 * r, "{}: arc does not face +z", m.id);
        // Consecutive points ~0.5 mm apart.
        let gap =
            ((points[1][0] - points[0][0]).powi(2) + (points[1][1] - points[0][1]).powi(2)).sqrt();
        assert!((gap - 0.5).abs() < 1e-3, "{}: spacing {gap}", m.id);
    }
    assert_eq!(sides, HashSet::from([1, -1]), "mixed gives both sides");
    // Reference distances are the true ones without tracker noise.
    assert_eq!(session.reference_distances.len(), 9);
    for (r, t) in session
        .reference_distances
        .iter()
        .zip(&truth.true_distances)
    {
        assert_eq!((&r.from, &r.to), (&t.from, &t.to));
        let stations = (truth.station(&r.from).unwrap() - truth.station(&r.to).unwrap()).norm();
        assert!((t.distance - stations).abs() < 1e-9);
        assert!((r.distance - t.distance).abs() <= 5.1e-10);
    }
    // The true model is nominal plus Table 1.
    let nominal = truth.nominal_robot();
    assert_eq!(nominal.joints, session.robot.joints);
    for ((t, n), e) in robot
        .joints
        .iter()
        .zip(&nominal.joints)
        .zip(&truth.joint_errors)
    {
        assert!((t.alpha - n.alpha - e.alpha).abs() < 1e-12 && (t.d - n.d - e.d).abs() < 1e-12);
    }
    assert_eq!(truth.joint_errors, robot::table1_errors());
}

#[test]
fn default_noise_has_the_stated_size() {
    let config = SimConfig::default();
    let (session, truth) = simulate(&config);
    let mut joint_diffs = Vec::new();
    let mut residuals = Vec::new();
    let radius = config.diameter / 2.0;
    for m in &session.measurements {
        let t = truth.measurement(&m.id).unwrap();
        joint_diffs.extend(m.joints.iter().zip(&t.joints_actual).map(|(a, b)| a - b));
        let c = Vector3::from(t.sensor_centre);
        let r = (radius * radius - c.x * c.x).sqrt();
        if let Observation::Stripe(points) = &m.observation {
            residuals.extend(
                points
                    .iter()
                    .map(|p| ((p[0] - c.y).powi(2) + (p[1] - c.z).powi(2)).sqrt() - r),
            );
        }
    }
    let joint_std = std_dev(&joint_diffs);
    assert!(
        (joint_std / config.joint_noise - 1.0).abs() < 0.3,
        "joint noise std {joint_std}"
    );
    let stripe_std = std_dev(&residuals);
    assert!(
        (stripe_std / config.stripe_noise - 1.0).abs() < 0.3,
        "stripe residual std {stripe_std}"
    );
    // 54 identify and 60 validate measurements, as in the paper.
    assert_eq!(session.with_use(Use::Identify).count(), 54);
    assert_eq!(session.with_use(Use::Validate).count(), 60);
    assert_eq!(session.with_use(Use::Translation).count(), 4);
    assert_eq!(session.with_use(Use::Rotation).count(), 6);
    assert!(session.hand_eye.is_none());
    // The reference distances carry tracker noise of ~0.01 mm.
    for (r, t) in session
        .reference_distances
        .iter()
        .zip(&truth.true_distances)
    {
        assert!(
            (r.distance - t.distance).abs() < 0.06,
            "{} → {}",
            r.from,
            r.to
        );
        assert!(
            t.distance > 100.0,
            "stations {} and {} too close",
            r.from,
            r.to
        );
    }
}

#[test]
fn translations_keep_orientation_and_rotations_differ() {
    let (session, truth) = simulate(&small(8, RobotChoice::Irb2400));
    let robot = truth.true_robot();
    let pose = |id: &str| robot.base_from_flange(&truth.measurement(id).unwrap().joints_actual);
    let translations: Vec<_> = session
        .with_use(Use::Translation)
        .map(|m| pose(&m.id))
        .collect();
    assert_eq!(translations.len(), 4);
    for t in &translations[1..] {
        assert!(t.rotation.angle_to(&translations[0].rotation) < 1e-9);
        let moved = (t.translation.vector - translations[0].translation.vector).norm();
        assert!((14.0..=22.0).contains(&moved), "flange moved {moved} mm");
    }
    // Displacements span a plane: the second singular value is not small.
    let d = Matrix3::from_columns(
        &translations[1..4]
            .iter()
            .map(|t| t.translation.vector - translations[0].translation.vector)
            .collect::<Vec<_>>(),
    );
    let sv = d.singular_values();
    let mut sv: Vec<f64> = sv.iter().copied().collect();
    sv.sort_by(|a, b| b.total_cmp(a));
    assert!(
        sv[1] / sv[0] > 0.3,
        "displacements nearly collinear: {sv:?}"
    );
    let rotations: Vec<_> = session
        .with_use(Use::Rotation)
        .map(|m| pose(&m.id))
        .collect();
    assert_eq!(rotations.len(), 6);
    for (i, a) in rotations.iter().enumerate() {
        let from_reference = a.rotation.angle_to(&translations[0].rotation).to_degrees();
        assert!(
            (19.9..=45.1).contains(&from_reference),
            "rotation {i}: {from_reference}°"
        );
        for b in &rotations[i + 1..] {
            assert!(a.rotation.angle_to(&b.rotation).to_degrees() > 10.0);
        }
    }
    // All of them see one station, P0.
    let stations: HashSet<_> = session
        .measurements
        .iter()
        .filter(|m| matches!(m.usage, Use::Translation | Use::Rotation))
        .map(|m| m.station.as_str())
        .collect();
    assert_eq!(stations, HashSet::from(["P0"]));
}

#[test]
fn identify_stations_vary_orientation_strongly() {
    let (session, truth) = simulate(&small(9, RobotChoice::Irb2400));
    let robot = truth.true_robot();
    for (id, indices) in session.stations(Use::Identify) {
        let approaches: Vec<Vector3<f64>> = indices
            .iter()
            .map(|&i| {
                let t = truth.measurement(&session.measurements[i].id).unwrap();
                robot.base_from_flange(&t.joints_actual).rotation * Vector3::z()
            })
            .collect();
        let widest = approaches
            .iter()
            .flat_map(|a| approaches.iter().map(move |b| a.angle(b).to_degrees()))
            .fold(0.0_f64, f64::max);
        assert!(widest > 20.0, "{id}: approach directions within {widest}°");
        // Joint 5 stays away from the wrist singularity.
        for &i in &indices {
            let q5 = truth
                .measurement(&session.measurements[i].id)
                .unwrap()
                .joints_actual[4];
            assert!(q5.abs() >= 10.0 - 1e-9, "{id}: q5 = {q5}");
        }
    }
}

/// FORMAT.md's session rules, checked directly (the loader checks them too,
/// below).
fn check_format_rules(session: &Session, truth: &Truth) {
    let ids: HashSet<_> = session.measurements.iter().map(|m| m.id.as_str()).collect();
    assert_eq!(ids.len(), session.measurements.len(), "ids unique");
    let mut per_station: HashMap<(&str, Use), usize> = HashMap::new();
    for m in &session.measurements {
        assert_eq!(m.joints.len(), session.robot.dof(), "{}", m.id);
        assert!(m.joints.iter().all(|q| q.is_finite()));
        assert!(m.side == 1 || m.side == -1);
        *per_station
            .entry((m.station.as_str(), m.usage))
            .or_default() += 1;
        match &m.observation {
            Observation::Stripe(points) => {
                assert!(points.len() >= 5, "{}", m.id);
                let c = truth.measurement(&m.id).unwrap().sensor_centre;
                let r = (session.sphere_radius().powi(2) - c[0] * c[0]).sqrt();
                assert!(r < session.sphere_radius() * 1.005);
            }
            Observation::Centre(c) => assert!(c.iter().all(|v| v.is_finite())),
        }
    }
    for ((station, usage), n) in &per_station {
        if *usage == Use::Identify {
            assert!(*n >= 2, "identify station {station} has {n} measurements");
        }
    }
    let validate: HashSet<_> = session
        .with_use(Use::Validate)
        .map(|m| m.station.as_str())
        .collect();
    for r in &session.reference_distances {
        assert!(validate.contains(r.from.as_str()) && validate.contains(r.to.as_str()));
    }
    if session.hand_eye.is_none() {
        assert!(session.with_use(Use::Translation).count() >= 3);
        assert!(session.with_use(Use::Rotation).count() >= 2);
    }
}

#[test]
fn every_preset_and_mode_passes_format_rules_and_loads() {
    let configs = [
        small(31, RobotChoice::Irb2400),
        small(32, RobotChoice::Irb120),
        small(33, RobotChoice::Ur5e),
        SimConfig {
            centres: true,
            ..small(34, RobotChoice::Irb2400)
        },
        SimConfig {
            side: SideChoice::Minus,
            errors: ErrorModel::Random,
            ..small(35, RobotChoice::Ur5e)
        },
        SimConfig {
            side: SideChoice::Plus,
            initial_hand_eye: InitialHandEye::Paper,
            outlier_fraction: 0.05,
            ..small(36, RobotChoice::Irb120)
        },
    ];
    for config in configs {
        let (session, truth) = simulate(&config);
        check_format_rules(&session, &truth);
        match config.side {
            SideChoice::Plus => assert!(session.measurements.iter().all(|m| m.side == 1)),
            SideChoice::Minus => assert!(session.measurements.iter().all(|m| m.side == -1)),
            SideChoice::Mixed => {}
        }
        assert_eq!(
            session.hand_eye.is_some(),
            config.initial_hand_eye != InitialHandEye::None
        );
        // The strict loader accepts the written file and reads back the
        // same measurements.
        let text = format::session_to_json(&session);
        let loaded = format::parse_session(&text, Path::new("simulated.json"))
            .unwrap_or_else(|e| panic!("{:?}: {e}", config.robot));
        assert_eq!(
            loaded.measurements, session.measurements,
            "{:?}",
            config.robot
        );
        assert_eq!(loaded.reference_distances, session.reference_distances);
        assert_eq!(loaded.robot.joints, session.robot.joints);
        assert_eq!(loaded.name, session.name);
        // The truth file round-trips exactly.
        let back = simulate::parse_truth(&simulate::truth_to_json(&truth)).unwrap();
        assert_eq!(back, truth);
    }
}

#[test]
fn outliers_are_displaced_by_the_stated_amount() {
    let config = SimConfig {
        outlier_fraction: 0.1,
        stripe_noise: 0.0,
        ..small(41, RobotChoice::Irb2400)
    };
    let (session, truth) = simulate(&config);
    let radius = config.diameter / 2.0;
    let (mut far, mut total) = (0usize, 0usize);
    for m in &session.measurements {
        let c = truth.measurement(&m.id).unwrap().sensor_centre;
        let r = (radius * radius - c[0] * c[0]).sqrt();
        let Observation::Stripe(points) = &m.observation else {
            continue;
        };
        for p in points {
            let d = (((p[0] - c[1]).powi(2) + (p[1] - c[2]).powi(2)).sqrt() - r).abs();
            assert!(
                d < 1e-4 || (0.3 - 1e-4..=3.0 + 1e-4).contains(&d),
                "{}: {d}",
                m.id
            );
            far += usize::from(d > 0.1);
            total += 1;
        }
    }
    let fraction = far as f64 / total as f64;
    assert!((fraction - 0.1).abs() < 0.02, "outlier fraction {fraction}");
}

#[test]
fn truth_file_has_the_shape_of_the_shared_example() {
    let text = std::fs::read_to_string(example_truth_path()).unwrap();
    let example: serde_json::Value = serde_json::from_str(&text).unwrap();
    let (_, truth) = simulate(&small(51, RobotChoice::Irb2400));
    let ours: serde_json::Value = serde_json::from_str(&simulate::truth_to_json(&truth)).unwrap();
    let keys =
        |v: &serde_json::Value| -> Vec<String> { v.as_object().unwrap().keys().cloned().collect() };
    assert_eq!(keys(&ours), keys(&example), "top-level keys");
    let first = |v: &serde_json::Value| {
        v["measurements"]
            .as_object()
            .unwrap()
            .values()
            .next()
            .unwrap()
            .clone()
    };
    let mut a = keys(&first(&ours));
    let mut b = keys(&first(&example));
    a.sort();
    b.sort();
    assert_eq!(a, b, "measurement keys");
    // Every config key of the example that this simulator also has keeps its
    // meaning: same value type.
    for (k, v) in example["config"].as_object().unwrap() {
        if let Some(ours) = ours["config"].get(k) {
            assert_eq!(ours.is_number(), v.is_number(), "config.{k}");
        }
    }
}

#[test]
fn shared_example_truth_loads_and_agrees_with_our_conventions() {
    let truth = simulate::load_truth(&example_truth_path()).unwrap();
    assert_eq!(truth.config.errors, ErrorModel::Table1);
    assert_eq!(truth.joint_errors, robot::table1_errors());
    let robot = truth.true_robot();
    let hand_eye = truth.true_hand_eye();
    let ours = sensor::paper_hand_eye();
    assert!(
        (hand_eye.to_homogeneous() - ours.to_homogeneous())
            .abs()
            .max()
            < 1e-9
    );
    // The independent simulator's joints and centres reproduce its stations
    // under FORMAT.md's MDH product: the conventions agree.
    for (id, m) in truth.measurements.iter() {
        let station = truth.station(&m.station).unwrap();
        let seen = robot.base_from_flange(&m.joints_actual)
            * hand_eye
            * Point3::from(Vector3::from(m.sensor_centre));
        assert!(
            (seen.coords - station).norm() < 1e-6,
            "{id}: {}",
            (seen.coords - station).norm()
        );
    }
}

#[test]
fn load_truth_names_the_file_on_error() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.truth.json");
    std::fs::write(&path, r#"{"format": "spherecal-session", "version": 1}"#).unwrap();
    let err = simulate::load_truth(&path).unwrap_err().to_string();
    assert!(err.contains("bad.truth.json"), "{err}");
    let (_, truth) = simulate(&small(52, RobotChoice::Irb120));
    let wrong = simulate::truth_to_json(&truth).replace("\"version\": 1", "\"version\": 2");
    assert!(matches!(
        simulate::parse_truth(&wrong),
        Err(simulate::TruthError::Version(2))
    ));
}

#[test]
fn simulating_its_own_poses_as_a_plan_reproduces_a_session() {
    // The poses of a simulated session, run as a plan on the same true
    // robot (same seed: same kinematic errors and noise stream), give the
    // same recordings: simulate_plan and simulate share one model of the cell.
    let config = small(61, RobotChoice::Irb2400);
    let (session, truth) = simulate(&config);
    let poses: Vec<simulate::PlanPose> = session
        .measurements
        .iter()
        .map(|m| {
            let t = truth.measurement(&m.id).unwrap();
            simulate::PlanPose {
                id: m.id.clone(),
                station: m.station.clone(),
                usage: m.usage,
                side: m.side,
                joints: t.joints_actual.clone(),
                centre_in_sensor: t.sensor_centre,
            }
        })
        .collect();
    let (again, again_truth) = simulate::simulate_plan(
        &config,
        &truth.nominal_robot(),
        &truth.true_hand_eye(),
        &poses,
        simulate::PlanExecution::AsPlanned,
    )
    .unwrap();
    assert_eq!(again.measurements.len(), session.measurements.len());
    for (a, b) in again.measurements.iter().zip(&session.measurements) {
        assert_eq!(
            (&a.id, &a.station, a.usage, a.side),
            (&b.id, &b.station, b.usage, b.side)
        );
        assert_eq!(a.joints, b.joints, "{}", a.id);
        let (Observation::Stripe(pa), Observation::Stripe(pb)) = (&a.observation, &b.observation)
        else {
            panic!("{}: stripes expected", a.id);
        };
        assert_eq!(pa.len(), pb.len(), "{}", a.id);
        for (p, q) in pa.iter().zip(pb) {
            // Rounded to 1e-4 mm: a centre that moved by 1e-12 mm can
            // round the other way.
            assert!((p[0] - q[0]).abs() <= 1.0001e-4 && (p[1] - q[1]).abs() <= 1.0001e-4);
        }
    }
    for (id, p) in truth.stations.iter() {
        let q = again_truth.station(id).unwrap();
        assert!((Vector3::from(*p) - q).norm() < 1e-9, "{id}");
    }
    assert_eq!(
        again.reference_distances.len(),
        session.reference_distances.len()
    );
    for (a, b) in again
        .reference_distances
        .iter()
        .zip(&session.reference_distances)
    {
        assert_eq!((&a.from, &a.to), (&b.from, &b.to));
        assert!((a.distance - b.distance).abs() < 1e-8);
    }
    // The import inputs: a joint log with the nominal ABB flange pose.
    let files = simulate::import_files(&again).unwrap();
    let mut lines = files.joints_csv.lines();
    assert_eq!(
        lines.next(),
        Some("id,station,use,side,j1,j2,j3,j4,j5,j6,x,y,z,q1,q2,q3,q4")
    );
    assert_eq!(lines.count(), again.measurements.len());
    assert_eq!(files.profiles.len(), again.measurements.len());
    assert!(files.profiles[0].1.starts_with("y,z\n"));
    let refs = files.references_csv.unwrap();
    assert!(refs.starts_with("from,to,distance\n"));
    // A centres session has no stripes to write.
    let (centres, _) = simulate(&SimConfig {
        centres: true,
        ..small(62, RobotChoice::Irb2400)
    });
    assert!(simulate::import_files(&centres).is_err());
}

/// The example sessions in `sessions/` (and their truth files) are what
/// `simulate` writes today from the configuration each truth file echoes:
/// byte for byte, so that a change of the simulator (or of the session
/// writer) that would change them is seen.
#[test]
fn example_sessions_are_regenerated_byte_for_byte() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("sessions");
    for stem in ["demo-irb2400", "centres-irb2400", "ur5e"] {
        let session_text = std::fs::read_to_string(dir.join(format!("{stem}.json"))).unwrap();
        let truth_text = std::fs::read_to_string(dir.join(format!("{stem}.truth.json"))).unwrap();
        let truth = simulate::parse_truth(&truth_text).unwrap();
        let (session, again) = simulate(&truth.config);
        assert_eq!(
            format::session_to_json(&session),
            session_text,
            "{stem}.json"
        );
        assert_eq!(
            simulate::truth_to_json(&again),
            truth_text,
            "{stem}.truth.json"
        );
    }
}
