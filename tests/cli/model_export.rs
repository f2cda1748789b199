//! `spherecal export-model` on the real binary: the URDF's joint origins
//! reproduce `Robot::base_from_flange`, the CSV reads back to the joints,
//! the JSON loads as a session's robot, and bad input exits 2 with no
//! output file.

// Test helpers may panic: a panic is a test failure with its message.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::process::Command;

use nalgebra::{Isometry3, Rotation3, Translation3, UnitQuaternion};
use spherecal::engine::base::geometry::rows_from_isometry;
use spherecal::engine::base::robot::Robot;
use spherecal::engine::files::format::{self, ResultFile};
use spherecal::engine::tools::report::model::{self, CSV_HEADER};

const RESULT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/v1/result.json");
const BASE_SESSION: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/base.json");

fn fixture() -> ResultFile {
    format::load_result(Path::new(RESULT)).unwrap()
}

/// Runs `export-model` and returns (status, stderr).
fn export(result: &Path, format: &str, out: &Path) -> (i32, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_spherecal"))
        .arg("export-model")
        .arg(result)
        .args(["--format", format, "--out"])
        .arg(out)
        .output()
        .unwrap();
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

fn export_ok(result: &Path, format: &str, dir: &Path) -> String {
    let out = dir.join(format!("model.{format}"));
    let (status, stderr) = export(result, format, &out);
    assert_eq!(status, 0, "{stderr}");
    std::fs::read_to_string(out).unwrap()
}

/// The value of attribute `name` in a tag's text.
fn attr<'a>(tag: &'a str, name: &str) -> &'a str {
    let key = format!("{name}=\"");
    let start = tag.find(&key).unwrap() + key.len();
    let len = tag[start..].find('"').unwrap();
    &tag[start..start + len]
}

fn numbers(text: &str) -> Vec<f64> {
    text.split_whitespace()
        .map(|v| v.parse().unwrap())
        .collect()
}

/// One `<joint>` of the URDF: name, type, parent, child, origin (mm).
struct UrdfJoint {
    name: String,
    kind: String,
    parent: String,
    child: String,
    origin: Isometry3<f64>,
}

/// A tiny parser of the `<joint>` elements: origin xyz (m → mm) and rpy
/// with `R = Rz(yaw) · Ry(pitch) · Rx(roll)`, built here from elementary
/// rotations (independent of the exporter's convention).
fn urdf_joints(text: &str) -> Vec<UrdfJoint> {
    let mut joints = Vec::new();
    let mut rest = text;
    while let Some(start) = rest.find("<joint ") {
        let end = start + rest[start..].find("</joint>").unwrap();
        let body = &rest[start..end];
        let head = &body[..body.find('>').unwrap()];
        let tag = |t: &str| {
            let s = body.find(&format!("<{t} ")).unwrap();
            &body[s..s + body[s..].find("/>").unwrap()]
        };
        let origin = tag("origin");
        let xyz = numbers(attr(origin, "xyz"));
        let rpy = numbers(attr(origin, "rpy"));
        let rotation = Rotation3::from_axis_angle(&nalgebra::Vector3::z_axis(), rpy[2])
            * Rotation3::from_axis_angle(&nalgebra::Vector3::y_axis(), rpy[1])
            * Rotation3::from_axis_angle(&nalgebra::Vector3::x_axis(), rpy[0]);
        if attr(head, "type") == "revolute" {
            assert_eq!(numbers(attr(tag("axis"), "xyz")), vec![0.0, 0.0, 1.0]);
        }
        joints.push(UrdfJoint {
            name: attr(head, "name").to_string(),
            kind: attr(head, "type").to_string(),
            parent: attr(tag("parent"), "link").to_string(),
            child: attr(tag("child"), "link").to_string(),
            origin: Isometry3::from_parts(
                Translation3::new(xyz[0] * 1e3, xyz[1] * 1e3, xyz[2] * 1e3),
                UnitQuaternion::from_rotation_matrix(&rotation),
            ),
        });
        rest = &rest[end..];
    }
    joints
}

/// The pose of `link` in the URDF's root frame for joint values `q` (deg),
/// walking the parent links; also returns the root link's name.
fn urdf_pose(joints: &[UrdfJoint], link: &str, q_deg: &[f64]) -> (Isometry3<f64>, String) {
    let mut pose = Isometry3::identity();
    let mut current = link.to_string();
    while let Some(j) = joints.iter().find(|j| j.child == current) {
        let mut t = j.origin;
        if j.kind == "revolute" {
            let i: usize = j.name.strip_prefix("joint_").unwrap().parse().unwrap();
            t *= Isometry3::rotation(nalgebra::Vector3::z() * q_deg[i - 1].to_radians());
        } else {
            assert_eq!(j.kind, "fixed");
        }
        pose = t * pose;
        current.clone_from(&j.parent);
    }
    (pose, current)
}

fn assert_close(a: &Isometry3<f64>, b: &Isometry3<f64>, what: &str) {
    let dt = (a.translation.vector - b.translation.vector).norm();
    let dr = a.rotation.angle_to(&b.rotation);
    // 1e-9 m = 1e-6 mm.
    assert!(
        dt < 1e-6 && dr < 1e-9,
        "{what}: |Δt| = {dt:e} mm, |Δr| = {dr:e} rad"
    );
}

/// A result near every gimbal lock of the rpy split: the fixture's model
/// with joint 2 exactly at alpha = theta = −90° (pitch exactly −90°) and a
/// hand-eye and flange that are also locked or nearly so.
fn locked_result() -> ResultFile {
    let mut r = fixture();
    r.robot.as_mut().unwrap().joints[1].alpha = -90.0;
    r.robot.as_mut().unwrap().joints[1].theta = -90.0;
    r.robot.as_mut().unwrap().joints[1].beta = 0.0;
    r.robot.as_mut().unwrap().joints[3].theta = 90.0 + 1e-7;
    r.robot.as_mut().unwrap().flange = spherecal::engine::base::geometry::isometry_from_rows(&[
        [0.0, 0.0, 1.0, 1.5],
        [0.0, 1.0, 0.0, -2.0],
        [-1.0, 0.0, 0.0, 12.5],
        [0.0, 0.0, 0.0, 1.0],
    ])
    .unwrap();
    r
}

fn check_urdf(result: &ResultFile, path: &Path, dir: &Path) {
    let text = export_ok(path, "urdf", dir);
    assert!(text.contains("Generated by spherecal"), "{text}");
    assert!(text.contains("<robot name=\"ABB IRB 2400/16\">"), "{text}");
    let joints = urdf_joints(&text);
    let robot: Robot = result.robot.clone().unwrap();
    assert_eq!(joints.iter().filter(|j| j.kind == "revolute").count(), 6);
    for q in [
        [0.0; 6],
        [10.0, -20.0, 30.0, -40.0, 50.0, -60.0],
        [170.0, 85.0, -120.0, 300.0, -115.0, 359.0],
        [-0.5, 90.0, -90.0, 180.0, 90.0, -180.0],
    ] {
        let (flange, root) = urdf_pose(&joints, "flange", &q);
        assert_eq!(root, "world");
        assert_close(
            &flange,
            &robot.base_from_flange(&q),
            &format!("flange at {q:?}"),
        );
        let (sensor, _) = urdf_pose(&joints, "sensor", &q);
        let hand_eye = result.hand_eye;
        assert_close(&sensor, &(robot.base_from_flange(&q) * hand_eye), "sensor");
    }
}

#[test]
fn urdf_chain_reproduces_forward_kinematics() {
    let dir = tempfile::tempdir().unwrap();
    check_urdf(&fixture(), Path::new(RESULT), dir.path());
    let locked = locked_result();
    let path = dir.path().join("locked.json");
    format::save_result(&locked, &path).unwrap();
    check_urdf(&locked, &path, dir.path());
}

#[test]
fn urdf_origin_is_exact_at_and_near_gimbal_lock() {
    for (roll, pitch, yaw) in [
        (0.3, std::f64::consts::FRAC_PI_2, -1.2),
        (0.3, -std::f64::consts::FRAC_PI_2, 2.0),
        (-2.0, std::f64::consts::FRAC_PI_2 - 1e-9, 0.7),
        (1.0, -std::f64::consts::FRAC_PI_2 + 1e-13, 3.0),
        (0.1, 0.2, 0.3),
    ] {
        let r = Rotation3::from_euler_angles(roll, pitch, yaw);
        let iso = Isometry3::from_parts(
            Translation3::new(1.0, 2.0, 3.0),
            UnitQuaternion::from_rotation_matrix(&r),
        );
        let (xyz, rpy) = model::urdf_origin(&iso);
        assert_eq!(xyz, [0.001, 0.002, 0.003]);
        let back = Rotation3::from_euler_angles(rpy[0], rpy[1], rpy[2]);
        let err = (back.matrix() - r.matrix()).abs().max();
        assert!(err < 1e-12, "{roll} {pitch} {yaw}: {rpy:?}, error {err:e}");
    }
}

#[test]
fn csv_reads_back_to_the_joints() {
    let dir = tempfile::tempdir().unwrap();
    let result = fixture();
    let text = export_ok(Path::new(RESULT), "csv", dir.path());
    let mut tables = text.split("\n\n");
    let mdh: Vec<&str> = tables.next().unwrap().lines().collect();
    assert_eq!(mdh[0], CSV_HEADER);
    assert_eq!(mdh.len(), 1 + result.robot.as_ref().unwrap().joints.len());
    for (i, line) in mdh[1..].iter().enumerate() {
        let v: Vec<f64> = line.split(',').map(|s| s.parse().unwrap()).collect();
        let (j, e) = (
            &result.robot.as_ref().unwrap().joints[i],
            &result.joint_errors[i],
        );
        assert_eq!(v[0], (i + 1) as f64);
        assert_eq!(v[1..6], [j.alpha, j.a, j.beta, j.theta, j.d], "row {line}");
        assert_eq!(v[6..11], [e.alpha, e.a, e.beta, e.theta, e.d], "row {line}");
    }
    let matrices: Vec<&str> = tables.next().unwrap().lines().collect();
    assert_eq!(matrices[0], model::CSV_MATRIX_HEADER);
    assert_eq!(matrices.len(), 13);
    for (k, (name, m)) in [
        (
            "base",
            rows_from_isometry(&result.robot.as_ref().unwrap().base),
        ),
        (
            "flange",
            rows_from_isometry(&result.robot.as_ref().unwrap().flange),
        ),
        ("hand_eye", rows_from_isometry(&result.hand_eye)),
    ]
    .iter()
    .enumerate()
    {
        for r in 0..4 {
            let cells: Vec<&str> = matrices[1 + 4 * k + r].split(',').collect();
            assert_eq!(cells[0], *name);
            assert_eq!(cells[1], (r + 1).to_string());
            let v: Vec<f64> = cells[2..].iter().map(|s| s.parse().unwrap()).collect();
            assert_eq!(v, m[r]);
        }
    }
}

#[test]
fn json_is_a_session_robot_block() {
    let dir = tempfile::tempdir().unwrap();
    let result = fixture();
    let block = export_ok(Path::new(RESULT), "json", dir.path());
    let block: serde_json::Value = serde_json::from_str(&block).unwrap();
    let keys: Vec<&String> = block.as_object().unwrap().keys().collect();
    assert_eq!(keys.len(), 4, "{keys:?}");
    let mut s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(BASE_SESSION).unwrap()).unwrap();
    s["robot"] = block;
    let text = serde_json::to_string(&s).unwrap();
    let loaded = format::parse_session(&text, Path::new("embedded.json")).unwrap();
    let expected = result.robot.clone().unwrap();
    assert_eq!(loaded.robot.name, expected.name);
    assert_eq!(loaded.robot.joints, expected.joints);
    assert_close(&loaded.robot.base, &expected.base, "base");
    assert_close(&loaded.robot.flange, &expected.flange, "flange");
}

fn assert_bad_input(input: &Path, dir: &Path) {
    for format in ["json", "csv", "urdf"] {
        let out: PathBuf = dir.join(format!("out.{format}"));
        let (status, stderr) = export(input, format, &out);
        assert_eq!(status, 2, "{stderr}");
        assert!(stderr.starts_with("error:"), "{stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        let name = input.file_name().unwrap().to_string_lossy();
        assert!(stderr.contains(name.as_ref()), "{stderr}");
        assert!(!out.exists(), "partial output {}", out.display());
    }
    let left: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .filter(|n| n.to_string_lossy().starts_with("out"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
}

#[test]
fn missing_file_exits_2() {
    let dir = tempfile::tempdir().unwrap();
    assert_bad_input(&dir.path().join("no-such-result.json"), dir.path());
}

#[test]
fn a_session_is_not_a_result() {
    let dir = tempfile::tempdir().unwrap();
    let session_path = dir.path().join("a-session.json");
    std::fs::copy(BASE_SESSION, &session_path).unwrap();
    assert_bad_input(&session_path, dir.path());
}
