//! Robot import from URDF and DH tables (`engine::files::robot_import::{urdf, dh_table}`):
//! the imported model's forward kinematics against an independent model of
//! the same file (the URDF chain composed directly, the standard DH
//! product written out) and against spherecal's presets, over hundreds of
//! seeded random joint vectors within the limits; and the errors for files
//! the model cannot hold.
//!
//! Run with `--nocapture` to see the largest errors measured.

// Helpers outside `#[test]` functions read fixtures: a panic is a failure.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use spherecal::engine::base::robot::{JointLimit, Robot, irb2400, ur5e};
use spherecal::engine::files::import::{load_dh_csv, load_urdf};
use spherecal::engine::files::robot_import::{
    DhConvention, RobotImportError, UrdfOptions, robot_from_dh_csv, robot_from_urdf,
    robot_from_urdf_with,
};

/// Position agreement required, mm.
const POS_TOL: f64 = 1e-9;
/// Rotation agreement required, rad.
const ROT_TOL: f64 = 1e-12;
/// Random joint vectors per comparison.
const SAMPLES: usize = 256;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/robots")
        .join(name)
}

fn deg(v: f64) -> f64 {
    v.to_radians()
}

fn rot(axis: Vector3<f64>, angle: f64) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::identity(),
        UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_normalize(axis), angle),
    )
}

fn tx(x: f64) -> Isometry3<f64> {
    Isometry3::translation(x, 0.0, 0.0)
}

fn tz(z: f64) -> Isometry3<f64> {
    Isometry3::translation(0.0, 0.0, z)
}

/// Position (mm) and rotation (rad) gap of two poses. The rotation angle is
/// `2·asin(|v|)` of the relative quaternion's vector part, which stays
/// accurate for tiny angles (unlike `acos` of its scalar part).
fn gap(a: &Isometry3<f64>, b: &Isometry3<f64>) -> (f64, f64) {
    let pos = (a.translation.vector - b.translation.vector).norm();
    let rel = a.rotation.inverse() * b.rotation;
    let angle = 2.0 * rel.quaternion().imag().norm().min(1.0).asin();
    (pos, angle)
}

/// Seeded joint vectors (deg) uniform within `limits`; infinite bounds
/// become ±360°.
fn random_qs(limits: &[JointLimit], n: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            limits
                .iter()
                .map(|l| rng.random_range(l.min.max(-360.0)..=l.max.min(360.0)))
                .collect()
        })
        .collect()
}

/// The largest gaps of `a(q)` against `b(q)` over `qs`, asserted below the
/// tolerances; printed with `label`.
fn compare(
    label: &str,
    qs: &[Vec<f64>],
    a: impl Fn(&[f64]) -> Isometry3<f64>,
    b: impl Fn(&[f64]) -> Isometry3<f64>,
) -> (f64, f64) {
    let (mut max_pos, mut max_rot) = (0.0_f64, 0.0_f64);
    for q in qs {
        let (pos, angle) = gap(&a(q), &b(q));
        assert!(
            pos < POS_TOL && angle < ROT_TOL,
            "{label}: q = {q:?}: position gap {pos:e} mm, rotation gap {angle:e} rad"
        );
        max_pos = max_pos.max(pos);
        max_rot = max_rot.max(angle);
    }
    println!(
        "{label}: {} poses, max position gap {max_pos:.3e} mm, max rotation gap {max_rot:.3e} rad",
        qs.len()
    );
    (max_pos, max_rot)
}

/// The URDF's own forward kinematics, independent of the importer: from
/// the root down to `tip`, each joint's `<origin>` (xyz in m → mm, rotation
/// `Rz(yaw)·Ry(pitch)·Rx(roll)`) followed, for a moving joint, by the
/// rotation by its reading about its `<axis>`.
fn urdf_fk(urdf: &urdf_rs::Robot, tip: &str, q_deg: &[f64]) -> Isometry3<f64> {
    let mut chain = Vec::new();
    let mut link = tip;
    while let Some(joint) = urdf.joints.iter().find(|j| j.child.link == link) {
        chain.push(joint);
        link = &joint.parent.link;
    }
    chain.reverse();
    let mut pose = Isometry3::identity();
    let mut q = q_deg.iter();
    for joint in chain {
        let [x, y, z] = joint.origin.xyz.0;
        let [roll, pitch, yaw] = joint.origin.rpy.0;
        pose = pose
            * Isometry3::translation(x * 1000.0, y * 1000.0, z * 1000.0)
            * rot(Vector3::z(), yaw)
            * rot(Vector3::y(), pitch)
            * rot(Vector3::x(), roll);
        if joint.joint_type != urdf_rs::JointType::Fixed {
            let [ax, ay, az] = joint.axis.xyz.0;
            let angle = q.next().copied().unwrap_or(0.0).to_radians();
            pose *= rot(Vector3::new(ax, ay, az), angle);
        }
    }
    pose
}

fn read_urdf(path: &Path) -> urdf_rs::Robot {
    urdf_rs::read_file(path).unwrap()
}

fn assert_limits(limits: &[JointLimit], expected: &[JointLimit]) {
    assert_eq!(limits.len(), expected.len());
    for (l, e) in limits.iter().zip(expected) {
        assert!(
            (l.min - e.min).abs() < 1e-9 && (l.max - e.max).abs() < 1e-9,
            "{l:?} vs {e:?}"
        );
    }
}

// ---------------------------------------------------------------- URDF

#[test]
fn urdf_irb2400_matches_its_own_chain() {
    let path = data("abb_irb2400.urdf");
    // Default tip: `base` hangs off the root by a fixed joint only, so
    // `tool0` is the only end reached through moving joints.
    let imported = load_urdf(&path, &UrdfOptions::default()).unwrap();
    assert_eq!(imported.root_link, "base_link");
    assert_eq!(imported.tip_link, "tool0");
    assert_eq!(
        imported.joint_names,
        [
            "joint_1", "joint_2", "joint_3", "joint_4", "joint_5", "joint_6"
        ]
    );
    assert_eq!(imported.robot.name, "abb_irb2400");
    let urdf = read_urdf(&path);
    let qs = random_qs(&imported.limits, SAMPLES, 1);
    compare(
        "IRB 2400 URDF vs its chain",
        &qs,
        |q| imported.robot.base_from_flange(q),
        |q| urdf_fk(&urdf, "tool0", q),
    );
}

#[test]
fn urdf_irb2400_is_the_preset() {
    let imported = load_urdf(&data("abb_irb2400.urdf"), &UrdfOptions::default()).unwrap();
    let preset = irb2400();
    assert_limits(&imported.limits, &preset.limits);
    // Same parameters as the preset, joint for joint, except theta6: at the
    // zero pose the preset's flange has x up, ROS-I's tool0 (rpy 0 π/2 0 on
    // link_6) has x down, so the URDF's flange is the preset's turned 180°
    // about z.
    let robot = &imported.robot;
    for (i, (j, p)) in robot.joints.iter().zip(&preset.robot.joints).enumerate() {
        let theta = if i == 5 { p.theta + 180.0 } else { p.theta };
        let expected = [p.alpha, p.a, p.beta, theta, p.d];
        let got = [j.alpha, j.a, j.beta, j.theta, j.d];
        for (g, e) in got.iter().zip(expected) {
            assert!(
                (g - e).abs() < 1e-9,
                "joint {}: {got:?} vs {expected:?}",
                i + 1
            );
        }
    }
    let (base_gap, _) = gap(&robot.base, &Isometry3::identity());
    let (flange_gap, flange_rot) = gap(&robot.flange, &Isometry3::identity());
    assert!(base_gap < 1e-12 && flange_gap < 1e-9 && flange_rot < 1e-12);
    // Fixed transforms between the two: base none, flange Rz(180°).
    let flange_fix = rot(Vector3::z(), deg(180.0));
    let qs = random_qs(&preset.limits, SAMPLES, 2);
    compare(
        "IRB 2400 URDF vs preset · Rz(180°)",
        &qs,
        |q| robot.base_from_flange(q),
        |q| preset.robot.base_from_flange(q) * flange_fix,
    );
}

#[test]
fn urdf_ur5e_matches_its_own_chain() {
    let path = data("ur5e.urdf");
    let options = UrdfOptions {
        tip: Some("tool0".into()),
        joints: Some(6),
    };
    let imported = load_urdf(&path, &options).unwrap();
    assert_eq!(imported.root_link, "world");
    assert_eq!(imported.tip_link, "tool0");
    assert_eq!(imported.joint_names[0], "shoulder_pan_joint");
    assert_eq!(imported.joint_names[5], "wrist_3_joint");
    assert!(imported.robot.joints.iter().all(|j| j.beta == 0.0));
    let urdf = read_urdf(&path);
    let qs = random_qs(&imported.limits, SAMPLES, 3);
    compare(
        "UR5e URDF vs its chain",
        &qs,
        |q| imported.robot.base_from_flange(q),
        |q| urdf_fk(&urdf, "tool0", q),
    );
    // The other ROS-I end frames are reachable as tips too.
    for tip in ["flange", "ft_frame", "wrist_3_link"] {
        let other = load_urdf(&path, &UrdfOptions::with_tip(tip)).unwrap();
        compare(
            &format!("UR5e URDF to {tip} vs its chain"),
            &qs[..32],
            |q| other.robot.base_from_flange(q),
            |q| urdf_fk(&urdf, tip, q),
        );
    }
}

#[test]
fn urdf_ur5e_is_the_preset() {
    let imported = load_urdf(&data("ur5e.urdf"), &UrdfOptions::with_tip("tool0")).unwrap();
    let preset = ur5e();
    assert_limits(&imported.limits, &preset.limits);
    // ROS's base_link is the controller's base turned 180° about z
    // (base_link → base_link_inertia in the URDF); tool0 is the DH flange
    // frame of UR's table, so no flange fix.
    let base_fix = rot(Vector3::z(), deg(180.0));
    let qs = random_qs(&preset.limits, SAMPLES, 4);
    compare(
        "UR5e URDF vs Rz(180°) · preset",
        &qs,
        |q| imported.robot.base_from_flange(q),
        |q| base_fix * preset.robot.base_from_flange(q),
    );
}

#[test]
fn urdf_zero_pose_frames_are_simple() {
    // Frame 0 sits on axis 1 below the root origin, so the base transform
    // of both files is a pure rotation about z; tool0 sits at the flange
    // centre with z along the last axis, so the flange transform is the
    // identity.
    let irb = load_urdf(&data("abb_irb2400.urdf"), &UrdfOptions::default()).unwrap();
    let ur = load_urdf(&data("ur5e.urdf"), &UrdfOptions::with_tip("tool0")).unwrap();
    for robot in [&irb.robot, &ur.robot] {
        println!("{}:", robot.name);
        for j in &robot.joints {
            println!(
                "  alpha {:8.3} a {:8.3} beta {:6.3} theta {:8.3} d {:8.3}",
                j.alpha, j.a, j.beta, j.theta, j.d
            );
        }
        let (base_pos, _) = gap(&robot.base, &Isometry3::identity());
        let base_z = robot.base.rotation * Vector3::z();
        assert!(base_pos < 1e-12 && (base_z - Vector3::z()).norm() < 1e-12);
        let (pos, angle) = gap(&robot.flange, &Isometry3::identity());
        assert!(pos < 1e-9 && angle < 1e-12, "{}: {pos} {angle}", robot.name);
    }
}

/// A URDF of random joints: origins, rotations and axes drawn at random,
/// with some joints made to share or intersect the previous axis, or be
/// nearly parallel to it, and fixed joints in between.
fn random_urdf(seed: u64) -> String {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut joints = String::new();
    let mut links = String::from("<link name=\"l0\"/>");
    let mut prev_axis = [0.0, 0.0, 1.0];
    let mut link = 0;
    for i in 0..7 {
        let mut xyz: [f64; 3] = std::array::from_fn(|_| rng.random_range(-0.5..0.5));
        let mut rpy: [f64; 3] = std::array::from_fn(|_| rng.random_range(-3.0..3.0));
        let mut axis: [f64; 3] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
        match rng.random_range(0..5) {
            // Parallel to the previous axis (same direction, no rotation).
            0 => {
                rpy = [0.0; 3];
                axis = prev_axis;
            }
            // Nearly parallel: a tilt of 1e-4 rad.
            1 => {
                rpy = [1e-4, 0.0, 0.0];
                axis = prev_axis;
            }
            // Intersecting the previous axis at the joint origin.
            2 => xyz = [0.0; 3],
            // Opposite direction on a parallel axis.
            3 => {
                rpy = [0.0; 3];
                axis = prev_axis.map(|v| -v);
            }
            _ => {}
        }
        if i == 6 {
            // A tool frame past the last joint, hung off a fixed joint.
            rpy = [0.0, std::f64::consts::FRAC_PI_2, 0.0];
        }
        let kind = if i == 6 {
            "fixed"
        } else if i == 3 {
            "continuous"
        } else {
            "revolute"
        };
        let (parent, child) = (link, link + 1);
        link += 1;
        links.push_str(&format!("<link name=\"l{child}\"/>"));
        joints.push_str(&format!(
            "<joint name=\"j{i}\" type=\"{kind}\"><parent link=\"l{parent}\"/>\
             <child link=\"l{child}\"/><origin xyz=\"{} {} {}\" rpy=\"{} {} {}\"/>\
             <axis xyz=\"{} {} {}\"/><limit lower=\"-3\" upper=\"3\" effort=\"1\" velocity=\"1\"/></joint>",
            xyz[0], xyz[1], xyz[2], rpy[0], rpy[1], rpy[2], axis[0], axis[1], axis[2]
        ));
        if kind != "fixed" {
            prev_axis = axis;
        }
        if i == 2 {
            // A fixed joint between moving ones.
            let (p, c) = (link, link + 1);
            link += 1;
            links.push_str(&format!("<link name=\"l{c}\"/>"));
            joints.push_str(&format!(
                "<joint name=\"fixed{i}\" type=\"fixed\"><parent link=\"l{p}\"/>\
                 <child link=\"l{c}\"/><origin xyz=\"0.1 0.2 0.3\" rpy=\"0.4 0.5 0.6\"/></joint>"
            ));
            prev_axis = [0.0, 0.0, 1.0]; // the fixed rotation breaks parallelism
        }
    }
    format!("<robot name=\"random{seed}\">{links}{joints}</robot>")
}

#[test]
fn urdf_random_chains_match_their_own_chain() {
    let (mut max_pos, mut max_rot) = (0.0_f64, 0.0_f64);
    let mut betas = 0;
    for seed in 0..40 {
        let text = random_urdf(seed);
        let imported = robot_from_urdf(&text, Path::new("random.urdf")).unwrap();
        assert_eq!(imported.robot.dof(), 6);
        assert!(imported.limits[3].max.is_infinite(), "continuous joint");
        betas += imported
            .robot
            .joints
            .iter()
            .filter(|j| j.beta != 0.0)
            .count();
        let urdf = urdf_rs::read_from_string(&text).unwrap();
        let limits = [JointLimit {
            min: -180.0,
            max: 180.0,
        }; 6];
        let qs = random_qs(&limits, 64, 100 + seed);
        let (pos, angle) = compare(
            &format!("random URDF {seed}"),
            &qs,
            |q| imported.robot.base_from_flange(q),
            |q| urdf_fk(&urdf, &imported.tip_link, q),
        );
        max_pos = max_pos.max(pos);
        max_rot = max_rot.max(angle);
    }
    println!("random URDFs: max position gap {max_pos:.3e} mm, max rotation gap {max_rot:.3e} rad");
    assert!(betas > 0, "the nearly parallel joints use beta");
}

// ------------------------------------------------------------ DH tables

/// The standard DH product `Π Rz(q_i + theta_i)·Tz(d_i)·Tx(a_i)·Rx(alpha_i)`
/// of rows `[theta (deg), d (mm), a (mm), alpha (deg)]`.
fn standard_dh_fk(rows: &[[f64; 4]], q_deg: &[f64]) -> Isometry3<f64> {
    rows.iter()
        .zip(q_deg)
        .fold(Isometry3::identity(), |t, (r, q)| {
            t * rot(Vector3::z(), deg(q + r[0]))
                * tz(r[1])
                * tx(r[2])
                * rot(Vector3::x(), deg(r[3]))
        })
}

/// The rows of `ur5e_dh.csv` read without the importer:
/// `[theta, d, a, alpha]` in deg and mm.
fn ur5e_standard_rows() -> Vec<[f64; 4]> {
    let text = std::fs::read_to_string(data("ur5e_dh.csv")).unwrap();
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("joint"))
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|c| c.trim().parse().unwrap()).collect();
            // joint, theta_rad, a_m, d_m, alpha_rad
            [
                v[1].to_degrees(),
                v[3] * 1000.0,
                v[2] * 1000.0,
                v[4].to_degrees(),
            ]
        })
        .collect()
}

#[test]
fn dh_ur5e_standard_matches_the_standard_product() {
    let robot = load_dh_csv(&data("ur5e_dh.csv"), DhConvention::Standard).unwrap();
    assert_eq!(robot.name, "ur5e_dh");
    let rows = ur5e_standard_rows();
    assert_eq!(rows.len(), 6);
    let qs = random_qs(&ur5e().limits, SAMPLES, 5);
    compare(
        "UR5e standard DH CSV vs standard DH product",
        &qs,
        |q| robot.base_from_flange(q),
        |q| standard_dh_fk(&rows, q),
    );
}

/// The same table as a European spreadsheet saves it (semicolons,
/// decimal commas) is the same robot.
#[test]
fn a_dh_table_with_decimal_commas_is_the_same_robot() {
    let dotted = std::fs::read_to_string(data("ur5e_dh.csv")).unwrap();
    let european: String = dotted
        .lines()
        .map(|l| {
            if l.starts_with('#') {
                l.to_string()
            } else {
                l.replace(',', ";").replace('.', ",")
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("ur5e_dh.csv");
    std::fs::write(&path, european).unwrap();
    let a = load_dh_csv(&data("ur5e_dh.csv"), DhConvention::Standard).unwrap();
    let b = load_dh_csv(&path, DhConvention::Standard).unwrap();
    assert_eq!(a, b);
}

#[test]
fn dh_ur5e_standard_is_the_preset() {
    let robot = load_dh_csv(&data("ur5e_dh.csv"), DhConvention::Standard).unwrap();
    let preset = ur5e();
    for (j, p) in robot.joints.iter().zip(&preset.robot.joints) {
        let got = [j.alpha, j.a, j.beta, j.theta, j.d];
        let expected = [p.alpha, p.a, p.beta, p.theta, p.d];
        for (g, e) in got.iter().zip(expected) {
            assert!((g - e).abs() < 1e-9, "{got:?} vs {expected:?}");
        }
    }
    let qs = random_qs(&preset.limits, SAMPLES, 6);
    compare(
        "UR5e standard DH CSV vs preset",
        &qs,
        |q| robot.base_from_flange(q),
        |q| preset.robot.base_from_flange(q),
    );
}

#[test]
fn dh_irb2400_modified_is_the_preset() {
    let robot = load_dh_csv(&data("abb_irb2400_mdh.csv"), DhConvention::Modified).unwrap();
    let preset = irb2400();
    assert_eq!(robot.joints, preset.robot.joints);
    assert_eq!(robot.base, Isometry3::identity());
    assert_eq!(robot.flange, Isometry3::identity());
    let qs = random_qs(&preset.limits, SAMPLES, 7);
    compare(
        "IRB 2400 modified DH CSV vs preset",
        &qs,
        |q| robot.base_from_flange(q),
        |q| preset.robot.base_from_flange(q),
    );
}

#[test]
fn dh_standard_of_the_irb2400_urdf_chain() {
    // A standard table with a non-zero last row: its Tx(a6)·Rx(alpha6)
    // must land in the flange transform.
    let text = "a,alpha,d,theta\n100,-90,615,0\n705,0,0,-90\n135,-90,0,0\n0,90,755,0\n0,-90,0,0\n25,30,85,0\n";
    let robot = robot_from_dh_csv(text, Path::new("std.csv"), DhConvention::Standard).unwrap();
    let rows: Vec<[f64; 4]> = vec![
        [0.0, 615.0, 100.0, -90.0],
        [-90.0, 0.0, 705.0, 0.0],
        [0.0, 0.0, 135.0, -90.0],
        [0.0, 755.0, 0.0, 90.0],
        [0.0, 0.0, 0.0, -90.0],
        [0.0, 85.0, 25.0, 30.0],
    ];
    let qs = random_qs(&irb2400().limits, SAMPLES, 8);
    compare(
        "standard DH with a last-row offset vs standard DH product",
        &qs,
        |q| robot.base_from_flange(q),
        |q| standard_dh_fk(&rows, q),
    );
}

#[test]
fn dh_csv_units_bom_comments_and_labels() {
    let text = "\u{feff}# a comment before the header\n\
                Joint, A_M, ALPHA_rad, D_mm, Theta_Deg, beta_rad\n\
                \n\
                # a comment between rows\n\
                j1, 0, 0, 615, 0, 0\n\
                j2, 0.1, -1.5707963267948966, 0, -90, 0.001\n";
    let robot = robot_from_dh_csv(text, Path::new("u.csv"), DhConvention::Modified).unwrap();
    assert_eq!(robot.dof(), 2);
    let j2 = robot.joints[1];
    assert!((j2.a - 100.0).abs() < 1e-12);
    assert!((j2.alpha + 90.0).abs() < 1e-12);
    assert!((j2.beta - 0.001_f64.to_degrees()).abs() < 1e-12);
    assert_eq!(j2.theta, -90.0);
    assert_eq!(robot.joints[0].d, 615.0);
    // Line numbers count comments and blank lines: the bad cell is line 6.
    let bad = text.replace("j2, 0.1", "j2, x0.1");
    let err = robot_from_dh_csv(&bad, Path::new("u.csv"), DhConvention::Modified).unwrap_err();
    assert!(
        matches!(err, RobotImportError::DhLine { line: 6, .. }),
        "{err}"
    );
}

// ---------------------------------------------------------------- errors

fn message(err: &RobotImportError) -> String {
    let text = err.to_string();
    println!("error: {text}");
    text
}

/// A two-joint URDF with the second joint of type `kind`.
fn two_joint_urdf(kind: &str) -> String {
    format!(
        r#"<robot name="r">
  <link name="base"/><link name="l1"/><link name="l2"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="slide" type="{kind}"><parent link="l1"/><child link="l2"/>
    <origin xyz="0 0 0.3"/><axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>"#
    )
}

#[test]
fn urdf_prismatic_joint_is_an_error() {
    let err =
        robot_from_urdf(&two_joint_urdf("prismatic"), Path::new("cell/slider.urdf")).unwrap_err();
    let text = message(&err);
    assert!(matches!(&err, RobotImportError::UrdfJoint { joint, .. } if joint == "slide"));
    assert!(text.contains("cell/slider.urdf") && text.contains("`slide`"));
    assert!(text.contains("prismatic"));
    let err = robot_from_urdf(&two_joint_urdf("floating"), Path::new("f.urdf")).unwrap_err();
    assert!(message(&err).contains("floating"));
}

#[test]
fn urdf_branched_tree_without_tip_is_an_error() {
    let text = r#"<robot name="two_arms">
  <link name="torso"/><link name="left"/><link name="right"/>
  <link name="left_tool"/><link name="right_tool"/>
  <joint name="jl" type="revolute"><parent link="torso"/><child link="left"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="jr" type="revolute"><parent link="torso"/><child link="right"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="tl" type="fixed"><parent link="left"/><child link="left_tool"/></joint>
  <joint name="tr" type="fixed"><parent link="right"/><child link="right_tool"/></joint>
</robot>"#;
    let err = robot_from_urdf(text, Path::new("two_arms.urdf")).unwrap_err();
    let msg = message(&err);
    assert!(matches!(err, RobotImportError::UrdfTree { .. }));
    assert!(
        msg.contains("two_arms.urdf")
            && msg.contains("`left_tool`")
            && msg.contains("`right_tool`")
    );
    // Naming a tip picks one arm.
    let left = robot_from_urdf_with(
        text,
        Path::new("two_arms.urdf"),
        &UrdfOptions::with_tip("left_tool"),
    )
    .unwrap();
    assert_eq!(left.joint_names, ["jl"]);
    // The UR5e file has tool0 and ft_frame past the wrist: no default tip.
    let err = load_urdf(&data("ur5e.urdf"), &UrdfOptions::default()).unwrap_err();
    let msg = message(&err);
    assert!(msg.contains("ur5e.urdf") && msg.contains("`ft_frame`") && msg.contains("`tool0`"));
}

#[test]
fn urdf_chain_errors_name_file_and_culprit() {
    let path = data("abb_irb2400.urdf");
    let err = load_urdf(&path, &UrdfOptions::with_tip("tool1")).unwrap_err();
    assert!(message(&err).contains("no link named `tool1`"));
    let options = UrdfOptions {
        tip: None,
        joints: Some(7),
    };
    let err = load_urdf(&path, &options).unwrap_err();
    let msg = message(&err);
    assert!(matches!(
        err,
        RobotImportError::JointCount {
            found: 6,
            expected: Some(7),
            ..
        }
    ));
    assert!(msg.contains("abb_irb2400.urdf") && msg.contains("joint_6"));
    // A tip above every moving joint leaves no joint.
    let err = load_urdf(&path, &UrdfOptions::with_tip("base")).unwrap_err();
    assert!(message(&err).contains("(none), expected at least 1"));
    assert!(
        matches!(err, RobotImportError::JointCount { found: 0, .. }),
        "{err}"
    );
    let err = load_urdf(
        Path::new("/nonexistent/robot.urdf"),
        &UrdfOptions::default(),
    )
    .unwrap_err();
    assert!(matches!(err, RobotImportError::Io { .. }) && message(&err).contains("robot.urdf"));
    let err = robot_from_urdf("<robot name=\"x\"><link", Path::new("broken.urdf")).unwrap_err();
    assert!(
        matches!(err, RobotImportError::UrdfSyntax { .. }) && message(&err).contains("broken.urdf")
    );
    let no_limits = two_joint_urdf("revolute").replace(
        "<limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/></joint>\n</robot>",
        "</joint>\n</robot>",
    );
    let err = robot_from_urdf(&no_limits, Path::new("n.urdf")).unwrap_err();
    assert!(
        matches!(&err, RobotImportError::UrdfJoint { joint, .. } if joint == "slide"),
        "{err}"
    );
    let zero_axis =
        two_joint_urdf("revolute").replace("<axis xyz=\"1 0 0\"/>", "<axis xyz=\"0 0 0\"/>");
    let err = robot_from_urdf(&zero_axis, Path::new("z.urdf")).unwrap_err();
    assert!(message(&err).contains("no direction"));
}

#[test]
fn dh_row_with_three_numbers_is_an_error() {
    let text = "# robot\na,alpha,d,theta\n0,0,615,0\n100,-90,0\n";
    let err = robot_from_dh_csv(text, Path::new("short.csv"), DhConvention::Modified).unwrap_err();
    let msg = message(&err);
    assert!(matches!(err, RobotImportError::DhLine { line: 4, .. }));
    assert!(
        msg.contains("short.csv, line 4") && msg.contains("3 fields"),
        "{msg}"
    );
}

#[test]
fn dh_non_numeric_cell_is_an_error() {
    let text = "a,alpha,d,theta\n0,0,615,0\n100,-90,zero,0\n";
    let err =
        robot_from_dh_csv(text, Path::new("dir/bad.csv"), DhConvention::Standard).unwrap_err();
    let msg = message(&err);
    assert!(msg.contains("dir/bad.csv, line 3") && msg.contains("`d`") && msg.contains("`zero`"));
    let text = "a,alpha,d,theta\n0,0,inf,0\n";
    let err = robot_from_dh_csv(text, Path::new("inf.csv"), DhConvention::Standard).unwrap_err();
    assert!(message(&err).contains("inf.csv, line 2"));
}

#[test]
fn dh_empty_file_is_an_error() {
    for text in ["", "\u{feff}", "# only a comment\n\n"] {
        let err =
            robot_from_dh_csv(text, Path::new("empty.csv"), DhConvention::Modified).unwrap_err();
        let msg = message(&err);
        assert!(matches!(err, RobotImportError::DhTable { .. }));
        assert!(msg.contains("empty.csv") && msg.contains("empty"));
    }
    let err = robot_from_dh_csv(
        "a,alpha,d,theta\n",
        Path::new("h.csv"),
        DhConvention::Modified,
    )
    .unwrap_err();
    assert!(message(&err).contains("no joint rows"));
}

#[test]
fn dh_header_errors() {
    let cases = [
        (
            "a,alpha,d,theta,offset\n0,0,0,0,0\n",
            DhConvention::Modified,
            "unknown column `offset`",
        ),
        (
            "a,alpha,d\n0,0,0\n",
            DhConvention::Modified,
            "lacks the column(s) theta",
        ),
        (
            "a,a_m,alpha,d,theta\n0,0,0,0,0\n",
            DhConvention::Modified,
            "given twice",
        ),
        (
            "a,alpha,d,theta,beta\n0,0,0,0,0\n",
            DhConvention::Standard,
            "modified convention",
        ),
        (
            "a_rad,alpha,d,theta\n0,0,0,0\n",
            DhConvention::Standard,
            "unknown column `a_rad`",
        ),
    ];
    for (text, convention, expected) in cases {
        let err = robot_from_dh_csv(text, Path::new("h.csv"), convention).unwrap_err();
        let msg = message(&err);
        assert!(
            msg.contains("h.csv, line 1") && msg.contains(expected),
            "{msg}"
        );
    }
}

#[test]
fn robot_new_has_identity_transforms() {
    // The modified import leaves base and flange to the caller.
    let robot: Robot = robot_from_dh_csv(
        "a,alpha,d,theta\n0,0,1,0\n",
        Path::new("one.csv"),
        DhConvention::Modified,
    )
    .unwrap();
    assert_eq!(robot.dof(), 1);
    assert_eq!(robot.name, "one");
}
