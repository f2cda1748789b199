//! The calibration where it is used (issue 33), on the real binary: tool
//! data of a pose-only result in each controller's syntax, read back by
//! readers written here from the vendors' grammars; `compensate
//! --current-tool`; the user's URDF written back (read by `urdf-rs`,
//! diffed as XML trees against the source); UR's calibration YAML (read
//! by `serde_norway`, its chain built as ur_description builds it).

// Test helpers may panic: a panic is a test failure with its message.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use crate::support::bin::{self, outcome};
use crate::support::tool_readers::{
    assert_same, pose, read_fanuc_utool, read_krl_tool, read_rapid_tooldata, read_ros, read_ur_tcp,
    rotvec_matrix, rpy_matrix, rx, ry, rz,
};
use std::path::{Path, PathBuf};

use nalgebra::{Isometry3, Vector3};
use rand::{Rng, SeedableRng};
use spherecal::engine::base::robot::{Joint, Robot, ur5e};
use spherecal::engine::files::format::{self, ResultFile};
use spherecal::engine::files::robot_import::robot_from_urdf;

const REAL: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/data/robcalibrator-sphere");
const RESULT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/v1/result.json");
const ABB_URDF: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/robots/abb_irb2400.urdf"
);

fn spherecal(args: &[&str], dir: &Path) -> (i32, String, String) {
    outcome(
        &bin::spherecal()
            .args(args)
            .current_dir(dir)
            .output()
            .unwrap(),
    )
}

fn ok(args: &[&str], dir: &Path) -> String {
    let (code, out, err) = spherecal(args, dir);
    assert_eq!(code, 0, "spherecal {args:?}: {err}");
    out
}

/// The real set's pose-only result (ml, with the hand-eye's covariance).
fn real_result(dir: &Path) -> (PathBuf, ResultFile) {
    ok(
        &[
            "import",
            "--poses",
            &format!("{REAL}/RobPoses.rob"),
            "--pose-convention",
            "fanuc",
            "--profiles",
            REAL,
            "--sphere-diameter",
            "80",
            "--out",
            "real.json",
            "-q",
        ],
        dir,
    );
    ok(
        &["calibrate", "real.json", "--out", "real.result.json", "-q"],
        dir,
    );
    let path = dir.join("real.result.json");
    let result = format::load_result(&path).unwrap();
    assert!(result.hand_eye_only(), "the real set is pose-only");
    (path, result)
}

/// A reader of one syntax.
type Reader = fn(&str) -> Isometry3<f64>;

#[test]
fn tool_data_of_a_pose_only_result_reads_back_in_every_syntax() {
    let dir = tempfile::tempdir().unwrap();
    let (path, result) = real_result(dir.path());
    let path = path.to_str().unwrap();
    let readers: [(&str, Reader); 5] = [
        ("abb", read_rapid_tooldata),
        ("kuka", read_krl_tool),
        ("fanuc", read_fanuc_utool),
        ("ur", read_ur_tcp),
        ("ros", read_ros),
    ];
    for (controller, read) in readers {
        let out = format!("tool.{controller}");
        let printed = ok(
            &[
                "export-model",
                path,
                "--format",
                "tool",
                "--controller",
                controller,
                "-o",
                &out,
            ],
            dir.path(),
        );
        let text = std::fs::read_to_string(dir.path().join(&out)).unwrap();
        assert!(printed.contains(&text), "the tool data is printed too");
        assert!(text.contains("kinematics were not"), "{text}");
        let sigma = text.lines().find(|l| l.contains("1σ:")).unwrap();
        assert_eq!(
            sigma.matches('±').count(),
            if controller == "abb" { 7 } else { 6 },
            "{sigma}"
        );
        let back = read(&text);
        assert_same(&back, &result.hand_eye, 1e-6, 1e-9, controller);
    }
}

#[test]
fn current_tool_rewrites_targets_so_the_calibrated_sensor_reaches_them() {
    let dir = tempfile::tempdir().unwrap();
    let (path, result) = real_result(dir.path());
    let path = path.to_str().unwrap();
    std::fs::write(
        dir.path().join("t.csv"),
        "id,x,y,z,w,p,r\nt1,800,100,400,180,0,90\nt2,850,-50,420,175,5,80\nt3,700,0,380,-170,-3,100\n",
    )
    .unwrap();
    // Without --current-tool: refused (one line on stderr), with the tool
    // data to install (stdout).
    let (code, out, err) = spherecal(
        &[
            "compensate",
            "--result",
            path,
            "--targets",
            "t.csv",
            "--pose-convention",
            "fanuc",
            "--tcp",
            "sensor",
            "-o",
            "out.csv",
        ],
        dir.path(),
    );
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("pose-only"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(out.contains("UTOOL[1]=PR[1]"), "{out}");
    assert!(!dir.path().join("out.csv").exists());
    // The tool the program was taught with, as FANUC values.
    let current = [2.0, -1.5, 250.0, 179.0, 0.5, -90.0];
    std::fs::write(
        dir.path().join("current.txt"),
        format!(
            "! taught with UTOOL 1\n{}\n",
            current.map(|v| v.to_string()).join(",")
        ),
    )
    .unwrap();
    let out = ok(
        &[
            "compensate",
            "--result",
            path,
            "--targets",
            "t.csv",
            "--pose-convention",
            "fanuc",
            "--current-tool",
            "current.txt",
            "-o",
            "out.csv",
        ],
        dir.path(),
    );
    assert!(out.contains("kinematics were not calibrated"), "{out}");
    let c = pose(
        [current[0], current[1], current[2]],
        rz(current[5].to_radians()) * ry(current[4].to_radians()) * rx(current[3].to_radians()),
    );
    let read = |name: &str| -> Vec<Isometry3<f64>> {
        std::fs::read_to_string(dir.path().join(name))
            .unwrap()
            .lines()
            .skip(1)
            .map(|l| {
                let v: Vec<f64> = l.split(',').skip(1).map(|s| s.parse().unwrap()).collect();
                pose(
                    [v[0], v[1], v[2]],
                    rz(v[5].to_radians()) * ry(v[4].to_radians()) * rx(v[3].to_radians()),
                )
            })
            .collect()
    };
    let (wanted, commanded) = (read("t.csv"), read("out.csv"));
    assert_eq!(wanted.len(), 3);
    for (t, p) in wanted.iter().zip(&commanded) {
        // The controller puts the flange at P·C⁻¹, the real sensor at P·C⁻¹·H.
        let sensor = p * c.inverse() * result.hand_eye;
        assert_same(&sensor, t, 1e-6, 1e-9, "sensor on the target");
    }
}

/// A result of `robot` (calibrated) over `nominal`, saved in `dir`.
fn result_of(nominal: &Robot, calibrated: &Robot, dir: &Path, name: &str) -> PathBuf {
    let mut r = format::load_result(Path::new(RESULT)).unwrap();
    r.robot = Some(calibrated.clone());
    r.joint_errors = calibrated.joint_errors(nominal);
    let path = dir.join(name);
    format::save_result(&r, &path).unwrap();
    path
}

fn perturbed(nominal: &Robot, seed: u64, scale: f64) -> Robot {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut r = nominal.clone();
    r.joints = nominal
        .joints
        .iter()
        .map(|j| Joint {
            alpha: j.alpha + scale * rng.random_range(-0.2..0.2),
            a: j.a + scale * rng.random_range(-1.0..1.0),
            beta: j.beta + scale * rng.random_range(-0.2..0.2),
            theta: j.theta + scale * rng.random_range(-0.2..0.2),
            d: j.d + scale * rng.random_range(-1.0..1.0),
        })
        .collect();
    r
}

/// Root → `tip` of a URDF at `q` (deg, moving joints in chain order), as
/// a plain product of `urdf-rs`' joints: origin, then the rotation about
/// the axis.
fn urdf_fk(robot: &urdf_rs::Robot, tip: &str, q: &[f64]) -> Isometry3<f64> {
    let mut chain = Vec::new();
    let mut link = tip.to_string();
    while let Some(j) = robot.joints.iter().find(|j| j.child.link == link) {
        chain.push(j);
        link = j.parent.link.clone();
    }
    chain.reverse();
    let mut t = Isometry3::identity();
    let mut k = 0;
    for j in chain {
        let [x, y, z] = j.origin.xyz.0;
        let [r, p, yw] = j.origin.rpy.0;
        t *= pose([x * 1e3, y * 1e3, z * 1e3], rpy_matrix(r, p, yw));
        if matches!(
            j.joint_type,
            urdf_rs::JointType::Revolute | urdf_rs::JointType::Continuous
        ) {
            let a = Vector3::from(j.axis.xyz.0).normalize();
            t *= pose([0.0; 3], rotvec_matrix(a * q[k].to_radians()));
            k += 1;
        }
    }
    t
}

/// Every node of an XML tree as (path, attributes, text), for a diff.
/// A node of [`tree`]: path, attributes, text.
type XmlNode = (String, Vec<(String, String)>, String);

fn tree(text: &str) -> Vec<XmlNode> {
    let doc = roxmltree::Document::parse(text).unwrap();
    let mut out = Vec::new();
    for n in doc.descendants() {
        let path: Vec<String> = n
            .ancestors()
            .filter(roxmltree::Node::is_element)
            .map(|a| {
                format!(
                    "{}[{}]",
                    a.tag_name().name(),
                    a.attribute("name").unwrap_or("")
                )
            })
            .collect();
        let kind = match n.node_type() {
            roxmltree::NodeType::Comment => "#comment",
            roxmltree::NodeType::Text => "#text",
            _ => "",
        };
        out.push((
            format!("{}{kind}", path.join("<")),
            n.attributes()
                .map(|a| (a.name().to_string(), a.value().to_string()))
                .collect(),
            n.text().unwrap_or("").to_string(),
        ));
    }
    out
}

#[test]
fn the_users_urdf_comes_back_with_only_the_joint_origins_changed() {
    let dir = tempfile::tempdir().unwrap();
    // ROS-I's IRB 2400 with meshes, given inertials and a comment here.
    let mut source = std::fs::read_to_string(ABB_URDF).unwrap();
    for k in 1..=6 {
        let tag = format!("<link name=\"link_{k}\">");
        source = source.replace(
            &tag,
            &format!(
                "{tag}\n    <!-- link {k}'s mass -->\n    <inertial>\n      <origin xyz=\"0.01 0 0.1\" rpy=\"0 0 0\"/>\n      <mass value=\"{}\"/>\n      <inertia ixx=\"0.1\" ixy=\"0\" ixz=\"0\" iyy=\"0.1\" iyz=\"0\" izz=\"0.05\"/>\n    </inertial>",
                30 - 4 * k
            ),
        );
    }
    assert!(source.contains("<mesh") && source.matches("<inertial>").count() == 6);
    let urdf_path = dir.path().join("irb2400.urdf");
    std::fs::write(&urdf_path, &source).unwrap();
    let urdf_arg = urdf_path.to_str().unwrap();
    let nominal = robot_from_urdf(&source, &urdf_path).unwrap().robot;
    let calibrated = perturbed(&nominal, 33, 1.0);
    let result = result_of(&nominal, &calibrated, dir.path(), "abb.result.json");
    let hand_eye = format::load_result(&result).unwrap().hand_eye;
    let out = ok(
        &[
            "export-model",
            result.to_str().unwrap(),
            "--format",
            "urdf",
            "--robot",
            urdf_arg,
            "-o",
            "calibrated.urdf",
        ],
        dir.path(),
    );
    assert!(out.contains("joint origins calibrated"), "{out}");
    let written = std::fs::read_to_string(dir.path().join("calibrated.urdf")).unwrap();
    // The XML trees differ only in the revolute joints' origins and the
    // added comment, sensor link and joint.
    let moving: Vec<String> = urdf_rs::read_from_string(&source)
        .unwrap()
        .joints
        .iter()
        .filter(|j| matches!(j.joint_type, urdf_rs::JointType::Revolute))
        .map(|j| j.name.clone())
        .collect();
    assert_eq!(moving.len(), 6);
    let is_origin_of_moving = |path: &str| {
        moving
            .iter()
            .any(|m| path.starts_with(&format!("origin[]<joint[{m}]<")))
    };
    let (a, b) = (tree(&source), tree(&written));
    let a_kept: Vec<_> = a.iter().filter(|n| !is_origin_of_moving(&n.0)).collect();
    let b_kept: Vec<_> = b
        .iter()
        .filter(|n| !is_origin_of_moving(&n.0))
        .filter(|n| !n.0.contains("[sensor]") && !n.0.contains("[sensor_joint]"))
        .filter(|n| !n.2.contains("Added by spherecal"))
        .collect();
    // Whitespace text nodes around the insertion may differ in count only.
    let strip = |v: Vec<&XmlNode>| {
        v.into_iter()
            .filter(|n| !(n.0.ends_with("#text") && n.2.trim().is_empty()))
            .cloned()
            .collect::<Vec<_>>()
    };
    assert_eq!(
        strip(a_kept),
        strip(b_kept),
        "only the origins and the sensor differ"
    );
    let changed = a
        .iter()
        .filter(|n| is_origin_of_moving(&n.0))
        .zip(b.iter().filter(|n| is_origin_of_moving(&n.0)))
        .filter(|(x, y)| x != y)
        .count();
    assert_eq!(changed, 6, "every revolute joint's origin is calibrated");
    // Outside the origins' numbers and the insertion, the bytes are the source's.
    let prefix = source
        .bytes()
        .zip(written.bytes())
        .take_while(|(x, y)| x == y)
        .count();
    assert!(
        source[..prefix].contains("<robot"),
        "the head is kept byte for byte"
    );
    assert!(written.ends_with(&source[source.rfind("</robot>").unwrap()..]));
    // Forward kinematics of the written file (urdf-rs + a chain product)
    // is the calibrated model at 100 random joint vectors.
    let urdf = urdf_rs::read_from_string(&written).unwrap();
    let tip = robot_from_urdf(&source, &urdf_path).unwrap().tip_link;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    for _ in 0..100 {
        let q: Vec<f64> = (0..6).map(|_| rng.random_range(-170.0..170.0)).collect();
        let want = calibrated.base_from_flange(&q);
        assert_same(&urdf_fk(&urdf, &tip, &q), &want, 1e-6, 1e-9, "tip");
        assert_same(
            &urdf_fk(&urdf, "sensor", &q),
            &(want * hand_eye),
            1e-6,
            1e-9,
            "sensor",
        );
    }
}

#[test]
fn a_urdf_of_another_robot_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let nominal = ur5e().robot;
    let result = result_of(
        &nominal,
        &perturbed(&nominal, 1, 1.0),
        dir.path(),
        "ur.json",
    );
    let (code, _, err) = spherecal(
        &[
            "export-model",
            result.to_str().unwrap(),
            "--format",
            "urdf",
            "--robot",
            ABB_URDF,
            "-o",
            "x.urdf",
        ],
        dir.path(),
    );
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("not the result's nominal robot"), "{err}");
    assert!(!dir.path().join("x.urdf").exists());
}

#[derive(serde::Deserialize)]
struct UrFile {
    kinematics: UrKinematics,
}
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct UrKinematics {
    shoulder: UrJoint,
    upper_arm: UrJoint,
    forearm: UrJoint,
    wrist_1: UrJoint,
    wrist_2: UrJoint,
    wrist_3: UrJoint,
    hash: String,
}
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct UrJoint {
    x: f64,
    y: f64,
    z: f64,
    roll: f64,
    pitch: f64,
    yaw: f64,
}

/// base_link_inertia (UR's `base`) → tool0 as ur_description's
/// ur_macro.xacro builds it from the kinematics file.
fn ur_fk(k: &UrKinematics, q: &[f64]) -> Isometry3<f64> {
    let half = std::f64::consts::FRAC_PI_2;
    let mut t = Isometry3::identity();
    for (j, q) in [
        &k.shoulder,
        &k.upper_arm,
        &k.forearm,
        &k.wrist_1,
        &k.wrist_2,
        &k.wrist_3,
    ]
    .iter()
    .zip(q)
    {
        t *= pose(
            [j.x * 1e3, j.y * 1e3, j.z * 1e3],
            rpy_matrix(j.roll, j.pitch, j.yaw) * rz(q.to_radians()),
        );
    }
    // wrist_3_link → flange (rpy 0 -pi/2 -pi/2) → tool0 (rpy pi/2 0 pi/2).
    t * pose([0.0; 3], rpy_matrix(0.0, -half, -half)) * pose([0.0; 3], rpy_matrix(half, 0.0, half))
}

#[test]
fn ur_calibration_file_builds_the_calibrated_ur5e() {
    let dir = tempfile::tempdir().unwrap();
    let nominal = ur5e().robot;
    // The nominal file is UR's own default_kinematics.yaml for the UR5e
    // (Universal_Robots_ROS2_Description, config/ur5e), to its 2e-11 m.
    let path = result_of(&nominal, &nominal, dir.path(), "nominal.json");
    ok(
        &[
            "export-model",
            path.to_str().unwrap(),
            "--format",
            "ur-calibration",
            "-o",
            "nominal.yaml",
        ],
        dir.path(),
    );
    let text = std::fs::read_to_string(dir.path().join("nominal.yaml")).unwrap();
    let file: UrFile = serde_norway::from_str(&text).unwrap();
    let published = "kinematics:
  shoulder: {x: 0, y: 0, z: 0.1625, roll: 0, pitch: 0, yaw: 0}
  upper_arm: {x: 0, y: 0, z: 0, roll: 1.570796327, pitch: 0, yaw: 0}
  forearm: {x: -0.425, y: 0, z: 0, roll: 0, pitch: 0, yaw: 0}
  wrist_1: {x: -0.3922, y: 0, z: 0.1333, roll: 0, pitch: 0, yaw: 0}
  wrist_2: {x: 0, y: -0.0997, z: -2.044881182297852e-11, roll: 1.570796327, pitch: 0, yaw: 0}
  wrist_3: {x: 0, y: 0.09959999999999999, z: -2.042830148012698e-11, roll: 1.570796326589793, pitch: 3.141592653589793, yaw: 3.141592653589793}
  hash: calib_12788084448423163542
";
    let ur: UrFile = serde_norway::from_str(published).unwrap();
    let joints = |k: &UrKinematics| {
        [
            &k.shoulder,
            &k.upper_arm,
            &k.forearm,
            &k.wrist_1,
            &k.wrist_2,
            &k.wrist_3,
        ]
        .map(|j| {
            pose(
                [j.x * 1e3, j.y * 1e3, j.z * 1e3],
                rpy_matrix(j.roll, j.pitch, j.yaw),
            )
        })
    };
    for (a, b) in joints(&file.kinematics)
        .iter()
        .zip(joints(&ur.kinematics).iter())
    {
        assert_same(a, b, 1e-6, 1e-9, "nominal origin vs UR's file");
    }
    assert!(file.kinematics.hash.starts_with("spherecal_"));
    // A calibrated UR5e: its file's chain is the calibrated model.
    let calibrated = perturbed(&nominal, 5, 0.5);
    let path = result_of(&nominal, &calibrated, dir.path(), "cal.json");
    ok(
        &[
            "export-model",
            path.to_str().unwrap(),
            "--format",
            "ur-calibration",
            "-o",
            "cal.yaml",
        ],
        dir.path(),
    );
    let text = std::fs::read_to_string(dir.path().join("cal.yaml")).unwrap();
    let file: UrFile = serde_norway::from_str(&text).unwrap();
    assert_ne!(file.kinematics.hash, ur.kinematics.hash);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    for _ in 0..100 {
        let q: Vec<f64> = (0..6).map(|_| rng.random_range(-360.0..360.0)).collect();
        assert_same(
            &ur_fk(&file.kinematics, &q),
            &calibrated.base_from_flange(&q),
            1e-6,
            1e-9,
            "UR chain vs calibrated model",
        );
    }
    // Not a UR: refused unless named one.
    let abb = robot_from_urdf(
        &std::fs::read_to_string(ABB_URDF).unwrap(),
        Path::new(ABB_URDF),
    )
    .unwrap()
    .robot;
    let path = result_of(&abb, &abb, dir.path(), "abb.json");
    let (code, _, err) = spherecal(
        &[
            "export-model",
            path.to_str().unwrap(),
            "--format",
            "ur-calibration",
            "-o",
            "abb.yaml",
        ],
        dir.path(),
    );
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("not a Universal Robots arm"), "{err}");
}

#[test]
fn a_joint_without_origin_or_rpy_gets_them_written() {
    let dir = tempfile::tempdir().unwrap();
    // URDF defaults: no <origin> is the identity, no rpy is 0 0 0.
    let source = std::fs::read_to_string(ABB_URDF)
        .unwrap()
        .replacen(
            "<joint name=\"joint_1\" type=\"revolute\">\n    <origin xyz=\"0 0 0\" rpy=\"0 0 0\"/>",
            "<joint name=\"joint_1\" type=\"revolute\">",
            1,
        )
        .replacen(
            "<origin xyz=\"0 0 0.705\" rpy=\"0 0 0\"/>",
            "<origin xyz=\"0 0 0.705\"/>",
            1,
        );
    assert!(!source.contains("0.705\" rpy"));
    let urdf_path = dir.path().join("bare.urdf");
    std::fs::write(&urdf_path, &source).unwrap();
    let nominal = robot_from_urdf(&source, &urdf_path).unwrap().robot;
    let calibrated = perturbed(&nominal, 8, 1.0);
    let result = result_of(&nominal, &calibrated, dir.path(), "bare.result.json");
    ok(
        &[
            "export-model",
            result.to_str().unwrap(),
            "--format",
            "urdf",
            "--robot",
            urdf_path.to_str().unwrap(),
            "-o",
            "bare.calibrated.urdf",
            "-q",
        ],
        dir.path(),
    );
    let written = std::fs::read_to_string(dir.path().join("bare.calibrated.urdf")).unwrap();
    let urdf = urdf_rs::read_from_string(&written).unwrap();
    for name in ["joint_1", "joint_3"] {
        let j = urdf.joints.iter().find(|j| j.name == name).unwrap();
        assert!(
            j.origin.rpy.0 != [0.0; 3],
            "{name} has its calibrated rotation"
        );
    }
    let tip = robot_from_urdf(&source, &urdf_path).unwrap().tip_link;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
    for _ in 0..20 {
        let q: Vec<f64> = (0..6).map(|_| rng.random_range(-170.0..170.0)).collect();
        assert_same(
            &urdf_fk(&urdf, &tip, &q),
            &calibrated.base_from_flange(&q),
            1e-6,
            1e-9,
            "tip",
        );
    }
}
