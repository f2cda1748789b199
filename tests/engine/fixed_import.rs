//! The doors of a fixed sensor (FORMAT.md `sensor.mount: "fixed"`): a
//! pose file beside a tracker's table (a pose-only session, which
//! calibrates `base_from_sensor` and the targets), and a fixed line
//! scanner's stripes of a sphere on the tool (eq. 21 in the fixed
//! sensor's frame), each on seeded simulated cells against the truth:
//! exact without noise, within 1.3 times the floor with noise; and the
//! import's errors, each naming the file, the pose and what is wrong.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use nalgebra::{Isometry3, Point3, Vector3};
use spherecal::engine::assemble::{ImportRequest, PoseLog, import_session};
use spherecal::engine::base::session::{Mount, Observation, Session, Use};
use spherecal::engine::calibrate::solve::{self, Method, Options};
use spherecal::engine::files::format::ResultFile;
use spherecal::engine::files::import::tracker::{
    FixedPoints, FixedPoses, TrackerSpec, read_tracker,
};
use spherecal::engine::files::import::{
    AngleUnit, FlangeConvention, LengthUnit, ProfileFormat, ProfileSource,
};
use spherecal::engine::tools::simulate::{FixedCell, FixedTruth, simulate_fixed};

use super::fixed_mount::{config, rms, score};

/// A pose file (`id,use,x,y,z,q1..q4`: the **true** flange poses, as an
/// exact controller would report them) and the tracker's table
/// (`pose,target,x,y,z`) of a simulated fixed session, in `dir`.
fn pose_file_and_table(session: &Session, truth: &FixedTruth, dir: &Path) -> (PathBuf, PathBuf) {
    let mut poses = String::from("id,use,x,y,z,q1,q2,q3,q4\n");
    let mut points = String::from("pose,target,x,y,z\n");
    let mut last: Option<&[f64]> = None;
    let mut k = 0;
    for m in &session.measurements {
        if last != Some(m.joints.as_slice()) {
            k += 1;
            last = Some(m.joints.as_slice());
            let f = truth.robot.base_from_flange(&m.joints);
            let (t, r) = (f.translation.vector, f.rotation);
            writeln!(
                poses,
                "P{k},{},{},{},{},{},{},{},{}",
                m.usage.as_str(),
                t.x,
                t.y,
                t.z,
                r.w,
                r.i,
                r.j,
                r.k
            )
            .unwrap();
        }
        let Observation::Centre(c) = &m.observation else {
            panic!("a centre")
        };
        writeln!(points, "P{k},{},{},{},{}", m.station, c.x, c.y, c.z).unwrap();
    }
    let (p, q) = (dir.join("poses.csv"), dir.join("points.csv"));
    std::fs::write(&p, poses).unwrap();
    std::fs::write(&q, points).unwrap();
    (p, q)
}

fn pose_spec(poses: &Path, points: &Path, unit: LengthUnit) -> TrackerSpec {
    TrackerSpec {
        poses: FixedPoses::File {
            path: poses.to_path_buf(),
            format: None,
            convention: Some(FlangeConvention::AbbQuaternion),
            pose_columns: None,
        },
        points: FixedPoints::Table {
            path: points.to_path_buf(),
            unit,
        },
        robot: None,
        diameter: 38.1,
        hand_eye: None,
        name: "pose-only tracker".into(),
    }
}

/// Calibrates a pose-only fixed session and returns the result and, per
/// validate measurement, the calibrated prediction error beside the
/// truth's (the true `bT_s` and targets through the same flange pose).
fn score_pose_only(session: &Session, truth: &FixedTruth) -> (ResultFile, Vec<(f64, f64)>) {
    let noise_free = truth.noise_free;
    let mut options = Options {
        method: Method::Ml,
        threshold: 0.0,
        max_iterations: 50,
        ..Options::from_session(session)
    };
    options.ml.prior = !noise_free;
    let (_, cal) = solve::calibrate(session, &options).unwrap();
    let result = ResultFile::from_calibration(session, &cal);
    let pairs = session
        .measurements
        .iter()
        .filter(|m| m.usage == Use::Validate)
        .map(|m| {
            let flange = m.flange.unwrap();
            let Observation::Centre(measured) = &m.observation else {
                panic!("a centre")
            };
            let station = result.stations.iter().find(|s| s.id == m.station).unwrap();
            let x_e = Point3::from(Vector3::from(station.point));
            let predicted = result.hand_eye.inverse_transform_point(&(flange * x_e));
            let truth_point = Point3::from(truth.target(&m.station).unwrap());
            let floor = truth
                .base_from_sensor
                .inverse_transform_point(&(flange * truth_point));
            (
                (predicted.coords - measured).norm(),
                (floor.coords - measured).norm(),
            )
        })
        .collect();
    (result, pairs)
}

fn transform_gap(a: &Isometry3<f64>, b: &Isometry3<f64>) -> (f64, f64) {
    let d = a.inverse() * b;
    (d.translation.vector.norm(), d.rotation.angle().to_degrees())
}

#[test]
fn a_pose_file_beside_a_trackers_table_calibrates_the_tracker_and_the_targets_exactly() {
    let (session, truth) = simulate_fixed(&config(3), &FixedCell::tracker(0.0)).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let (poses, points) = pose_file_and_table(&session, &truth, dir.path());
    // Through the one import entry.
    let imported = import_session(
        &ImportRequest {
            log: PoseLog::Fixed(pose_spec(&poses, &points, LengthUnit::Mm)),
            range: None,
            hand_eye: None,
        },
        &mut |_| solve::Control::Continue,
    )
    .unwrap();
    let pose_only = imported.session;
    assert_eq!(pose_only.mount, Mount::Fixed);
    assert!(!pose_only.robot_given);
    assert_eq!(pose_only.measurements.len(), session.measurements.len());
    assert!(pose_only.measurements.iter().all(|m| m.flange.is_some()));
    assert_eq!(pose_only.with_use(Use::Validate).count(), 36);
    assert!(
        imported.notes.iter().any(|n| n.contains("pose-only")),
        "{:?}",
        imported.notes
    );
    let (result, pairs) = score_pose_only(&pose_only, &truth);
    assert!(result.robot.is_none() && result.joint_errors.is_empty());
    let (mm, deg) = transform_gap(&result.hand_eye, &truth.base_from_sensor);
    assert!(mm < 1e-6 && deg < 1e-8, "bT_s off by {mm} mm, {deg}°");
    for s in &result.stations {
        let gap = (Vector3::from(s.point) - truth.target(&s.id).unwrap()).norm();
        assert!(gap < 1e-6, "{}: {gap} mm", s.id);
        assert_eq!(s.frame, "flange");
    }
    let worst = pairs.iter().map(|p| p.0).fold(0.0, f64::max);
    assert!(worst < 1e-6, "validate prediction {worst} mm without noise");
}

#[test]
fn a_pose_only_tracker_session_with_noise_predicts_near_the_floor() {
    for seed in [5, 6] {
        let (session, truth) = simulate_fixed(&config(seed), &FixedCell::tracker(0.01)).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let (poses, points) = pose_file_and_table(&session, &truth, dir.path());
        let (pose_only, _) = read_tracker(&pose_spec(&poses, &points, LengthUnit::Mm)).unwrap();
        let (result, pairs) = score_pose_only(&pose_only, &truth);
        let (cal, floor): (Vec<f64>, Vec<f64>) = pairs.into_iter().unzip();
        let (cal, floor) = (rms(&cal), rms(&floor));
        let (mm, deg) = transform_gap(&result.hand_eye, &truth.base_from_sensor);
        eprintln!(
            "pose-only tracker seed {seed}: validate rms {cal:.4} mm, floor {floor:.4} mm; bT_s {mm:.4} mm, {deg:.5}° from the truth"
        );
        assert!(floor > 0.005 && floor < 0.03, "floor {floor}");
        assert!(
            cal <= 1.3 * floor,
            "seed {seed}: {cal} mm against {floor} mm"
        );
        assert!(mm < 0.05 && deg < 0.002, "bT_s off by {mm} mm, {deg}°");
    }
}

#[test]
fn the_fixed_doors_errors_name_the_file_the_pose_and_what_is_wrong() {
    let (session, truth) = simulate_fixed(&config(3), &FixedCell::tracker(0.01)).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let (poses, points) = pose_file_and_table(&session, &truth, dir.path());
    let text = std::fs::read_to_string(&points).unwrap();
    let message = |points_text: &str, unit: LengthUnit| {
        let path = dir.path().join("bad.csv");
        std::fs::write(&path, points_text).unwrap();
        read_tracker(&pose_spec(&poses, &path, unit))
            .unwrap_err()
            .to_string()
    };
    // A point of a pose the pose file does not have: the table, its line, the pose.
    let e = message(&format!("{text}P99,SMR1,1,2,3\n"), LengthUnit::Mm);
    let last = text.lines().count() + 1;
    assert!(
        e.contains("bad.csv") && e.contains(&format!("line {last}")) && e.contains("`P99`"),
        "{e}"
    );
    // A pose without a point: the pose file, the pose's line, the pose.
    let without: String = text
        .lines()
        .filter(|l| !l.starts_with("P7,"))
        .map(|l| format!("{l}\n"))
        .collect();
    let e = message(&without, LengthUnit::Mm);
    assert!(
        e.contains("poses.csv") && e.contains("line 8") && e.contains("`P7` has no point"),
        "{e}"
    );
    // Millimetres read as metres: the unit that fits is named.
    let e = message(&text, LengthUnit::M);
    assert!(
        e.contains("bad.csv") && e.contains("not plausible") && e.contains("--centre-unit mm"),
        "{e}"
    );
    // Metres read as millimetres.
    let metres: String = text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i == 0 {
                return format!("{l}\n");
            }
            let f: Vec<&str> = l.split(',').collect();
            let m = |s: &str| s.parse::<f64>().unwrap() / 1000.0;
            format!("{},{},{},{},{}\n", f[0], f[1], m(f[2]), m(f[3]), m(f[4]))
        })
        .collect();
    let e = message(&metres, LengthUnit::Mm);
    assert!(e.contains("--centre-unit m"), "{e}");
    assert!(
        read_tracker(&pose_spec(
            &poses,
            &dir.path().join("bad.csv"),
            LengthUnit::M
        ))
        .is_ok()
    );
    // Joint targets without a robot are refused, naming the file.
    let joints = dir.path().join("joints.csv");
    std::fs::write(&joints, "id,j1,j2,j3,j4,j5,j6\nP1,0,20,10,0,-30,0\n").unwrap();
    let spec = TrackerSpec {
        poses: FixedPoses::Joints {
            path: joints.clone(),
            id_column: "id".into(),
            joint_columns: (1..=6).map(|k| format!("j{k}")).collect(),
            angle_unit: AngleUnit::Deg,
        },
        ..pose_spec(&poses, &points, LengthUnit::Mm)
    };
    let e = read_tracker(&spec).unwrap_err().to_string();
    assert!(e.contains("joints.csv") && e.contains("--robot"), "{e}");
}

/// A line scanner's session written as its files (joint log and one
/// `y,z` profile a pose) and imported through the one entry.
fn line_scanner_import(session: &Session, dir: &Path) -> Session {
    let mut joints = String::from("id,use,j1,j2,j3,j4,j5,j6\n");
    std::fs::create_dir_all(dir.join("profiles")).unwrap();
    for (k, m) in session.measurements.iter().enumerate() {
        let q: Vec<String> = m.joints.iter().map(f64::to_string).collect();
        writeln!(joints, "P{},{},{}", k + 1, m.usage.as_str(), q.join(",")).unwrap();
        let Observation::Stripe(points) = &m.observation else {
            panic!("a stripe")
        };
        let mut text = String::from("y,z\n");
        for [y, z] in points {
            writeln!(text, "{y},{z}").unwrap();
        }
        std::fs::write(dir.join("profiles").join(format!("P{}.csv", k + 1)), text).unwrap();
    }
    std::fs::write(dir.join("joints.csv"), joints).unwrap();
    let spec = TrackerSpec {
        poses: FixedPoses::Joints {
            path: dir.join("joints.csv"),
            id_column: "id".into(),
            joint_columns: (1..=6).map(|k| format!("j{k}")).collect(),
            angle_unit: AngleUnit::Deg,
        },
        points: FixedPoints::Profiles {
            source: ProfileSource::Folder(dir.join("profiles")),
            format: ProfileFormat::default(),
            side: Some(1),
        },
        robot: Some(spherecal::engine::base::robot::irb2400().robot),
        diameter: session.sphere_diameter,
        hand_eye: None,
        name: "line scanner".into(),
    };
    import_session(
        &ImportRequest {
            log: PoseLog::Fixed(spec),
            range: None,
            hand_eye: None,
        },
        &mut |_| solve::Control::Continue,
    )
    .unwrap()
    .session
}

#[test]
fn a_fixed_line_scanners_stripes_are_fitted_in_its_frame_exactly_without_noise() {
    let (session, truth) = simulate_fixed(&config(7), &FixedCell::line_scanner(0.0)).unwrap();
    assert!(
        session
            .measurements
            .iter()
            .all(|m| matches!(m.observation, Observation::Stripe(_)))
    );
    let (result, pairs) = score(&session, &truth, Method::Ml);
    assert_eq!(result.stations.len(), 1);
    let worst = pairs.iter().map(|p| p.0).fold(0.0, f64::max);
    assert!(worst < 1e-5, "line scanner without noise: {worst} mm");
    // The same stripes through the import's files calibrate the same.
    let dir = tempfile::tempdir().unwrap();
    let imported = line_scanner_import(&session, dir.path());
    assert_eq!(imported.mount, Mount::Fixed);
    assert_eq!(imported.measurements.len(), session.measurements.len());
    let (again, _) = score(
        &Session {
            name: session.name.clone(),
            solver: session.solver,
            solver_given: session.solver_given,
            ..imported
        },
        &truth,
        Method::Ml,
    );
    let gap =
        (Vector3::from(again.stations[0].point) - Vector3::from(result.stations[0].point)).norm();
    assert!(gap < 1e-9, "imported: the sphere moved {gap} mm");
}

#[test]
fn a_fixed_line_scanner_with_noise_predicts_validate_poses_near_the_floor() {
    for seed in [7, 8, 9] {
        let (session, truth) =
            simulate_fixed(&config(seed), &FixedCell::line_scanner(0.02)).unwrap();
        let (_, pairs) = score(&session, &truth, Method::Ml);
        let (cal, floor): (Vec<f64>, Vec<f64>) = pairs.into_iter().unzip();
        let (cal, floor) = (rms(&cal), rms(&floor));
        eprintln!("line scanner seed {seed}: validate rms {cal:.4} mm, floor {floor:.4} mm");
        assert!(floor > 0.002 && floor < 0.1, "floor {floor}");
        assert!(
            cal <= 1.3 * floor,
            "seed {seed}: {cal} mm against {floor} mm"
        );
    }
}
