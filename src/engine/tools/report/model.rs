//! Export of a calibrated model (issue 5, "Model export"): the result
//! file's robot as the FORMAT.md `robot` block (JSON), as a CSV table of
//! MDH parameters, and as a URDF fragment for ROS users.
//!
//! The URDF chain reproduces [`Robot::base_from_flange`] exactly. URDF
//! rotates a revolute joint about its `<axis>` *after* the joint's
//! `<origin>`, so the MDH link transform
//! `T_i = Rx(alpha_i) · Tx(a_i) · Ry(beta_i) · Rz(q_i + theta_i) · Tz(d_i)`
//! is split at the joint rotation:
//!
//! ```text
//! origin of joint_1     = Rx(alpha_1) · Tx(a_1) · Ry(beta_1) · Rz(theta_1)
//! origin of joint_i     = Tz(d_{i-1}) · Rx(alpha_i) · Tx(a_i) · Ry(beta_i) · Rz(theta_i)
//! origin of flange_joint = Tz(d_n) · F            (fixed)
//! origin of sensor_joint = eT_s (the hand-eye)    (fixed)
//! origin of base_joint   = B  (fixed, world → base_link; only when B ≠ I)
//! ```
//!
//! each revolute joint with `<axis xyz="0 0 1"/>`, so a URDF joint value of
//! zero is the controller's zero (the `theta` offsets are in the origins).
//! URDF is in metres and radians; `rpy` is fixed-axis roll-pitch-yaw,
//! `R = Rz(yaw) · Ry(pitch) · Rx(roll)` (see [`urdf_origin`]).

use std::fmt::Write as _;

use nalgebra::{Isometry3, Rotation3};

use crate::engine::base::geometry::{rot_x, rot_y, rot_z, rows_from_isometry, trans};
use crate::engine::base::robot::{Joint, Robot};
use crate::engine::files::format::ResultFile;
use crate::engine::files::format::result::RobotRecord;
use crate::engine::tools::report::svg::escape;

/// Millimetres per metre: file lengths are mm, URDF lengths are m.
const MM_PER_M: f64 = 1000.0;

/// Below this `cos(pitch)` the rpy split treats the rotation as gimbal
/// locked and puts the whole rotation about z into yaw (roll = 0).
const GIMBAL_LOCK_COS: f64 = 1e-12;

/// Header of the MDH table of [`mdh_csv`]: calibrated values (deg, mm) and
/// calibrated − nominal (`delta_*`, deg, mm).
pub const CSV_HEADER: &str = "joint,alpha_deg,a_mm,beta_deg,theta_deg,d_mm,\
delta_alpha_deg,delta_a_mm,delta_beta_deg,delta_theta_deg,delta_d_mm";

/// Header of the matrix table of [`mdh_csv`]: one row of a row-major 4×4
/// (rotation entries unitless, the fourth column in mm).
pub const CSV_MATRIX_HEADER: &str = "matrix,row,c1,c2,c3,c4";

/// The export formats of `spherecal export-model`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModelFormat {
    /// The FORMAT.md `robot` block (deg, mm), pasteable into a session.
    Json,
    /// The MDH table and the base, flange and hand-eye matrices (deg, mm).
    Csv,
    /// A URDF fragment (m, rad) with the calibrated joint origins.
    Urdf,
}

/// Why a model cannot be exported.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ExportError {
    /// The result calibrated no kinematic model (a pose-only session).
    #[error(
        "the result has no calibrated kinematic model: it is of a pose-only session (flange poses, no joints), so only the hand-eye was calibrated; export it as tool data instead (--format tool --controller abb|kuka|fanuc|ur|ros)"
    )]
    HandEyeOnly,
    /// `joint_errors` does not have one entry per joint.
    #[error("`joint_errors` has {found} entries, the robot has {joints} joints")]
    JointErrorCount {
        /// Entries of `joint_errors`.
        found: usize,
        /// Joints of `robot.joints`.
        joints: usize,
    },
    /// A number of the model is NaN or infinite.
    #[error("{what} is not finite")]
    NotFinite {
        /// Which number.
        what: String,
    },
}

/// The model of `result` in `format`, as the text of the file to write.
/// `source` names the result file in the URDF's comment.
///
/// # Errors
/// [`ExportError`] when the result's model is unusable (a loaded result
/// has been checked already).
pub fn export(
    result: &ResultFile,
    format: ModelFormat,
    source: &str,
) -> Result<String, ExportError> {
    let robot = check(result)?;
    Ok(match format {
        ModelFormat::Json => robot_json(robot),
        ModelFormat::Csv => mdh_csv(result, robot),
        ModelFormat::Urdf => urdf(result, robot, source),
    })
}

/// Checks what the exporters rely on: finite joints, one joint error per
/// joint.
fn check(result: &ResultFile) -> Result<&Robot, ExportError> {
    let robot = match &result.robot {
        Some(r) if !result.hand_eye_only() => r,
        _ => return Err(ExportError::HandEyeOnly),
    };
    let joints = robot.joints.len();
    if result.joint_errors.len() != joints {
        return Err(ExportError::JointErrorCount {
            found: result.joint_errors.len(),
            joints,
        });
    }
    for (i, (j, e)) in robot.joints.iter().zip(&result.joint_errors).enumerate() {
        for (k, v) in joint_values(j).iter().chain(&joint_values(e)).enumerate() {
            if !v.is_finite() {
                let what = if k < 5 {
                    "robot.joints"
                } else {
                    "joint_errors"
                };
                return Err(ExportError::NotFinite {
                    what: format!(
                        "{what}[{i}].{}",
                        crate::engine::base::robot::PARAM_NAMES[k % 5]
                    ),
                });
            }
        }
    }
    Ok(robot)
}

fn joint_values(j: &Joint) -> [f64; 5] {
    [j.alpha, j.a, j.beta, j.theta, j.d]
}

/// The result's calibrated model as exactly the FORMAT.md `robot` block
/// (`name`, `joints` in deg and mm, `base` and `flange` as row-major 4×4
/// in mm), pretty-printed with a trailing newline. Numbers are written so
/// that they read back to the same `f64`.
#[must_use]
fn robot_json(robot: &Robot) -> String {
    let mut text = serde_json::to_string_pretty(&RobotRecord::from_robot(robot))
        .unwrap_or_else(|e| format!("serialisation failed: {e}"));
    text.push('\n');
    text
}

/// The result's model as CSV, two tables separated by one empty line:
///
/// 1. [`CSV_HEADER`], then one row per joint (`joint` = 1..n): the
///    calibrated `alpha, a, beta, theta, d` (deg, mm) and the result's
///    `joint_errors`, calibrated − nominal (deg, mm);
/// 2. [`CSV_MATRIX_HEADER`], then four rows (`row` = 1..4) each of the
///    row-major 4×4 matrices `base` (B), `flange` (F) and `hand_eye`
///    (`eT_s`, sensor to flange); the fourth column is in mm.
///
/// Numbers use Rust's shortest round-trip form, so they read back to the
/// same `f64`.
#[must_use]
fn mdh_csv(result: &ResultFile, robot: &Robot) -> String {
    let mut out = String::new();
    out.push_str(CSV_HEADER);
    out.push('\n');
    for (i, (j, e)) in robot.joints.iter().zip(&result.joint_errors).enumerate() {
        let _ = write!(out, "{}", i + 1);
        for v in joint_values(j).iter().chain(&joint_values(e)) {
            let _ = write!(out, ",{v}");
        }
        out.push('\n');
    }
    out.push('\n');
    out.push_str(CSV_MATRIX_HEADER);
    out.push('\n');
    for (name, m) in [
        ("base", &robot.base),
        ("flange", &robot.flange),
        ("hand_eye", &result.hand_eye),
    ] {
        for (r, row) in rows_from_isometry(m).iter().enumerate() {
            let _ = writeln!(
                out,
                "{name},{},{},{},{},{}",
                r + 1,
                row[0],
                row[1],
                row[2],
                row[3]
            );
        }
    }
    out
}

/// The URDF `<origin>` of a transform given in mm: `xyz` in metres and
/// `rpy` (rad), fixed-axis roll-pitch-yaw with
/// `R = Rz(yaw) · Ry(pitch) · Rx(roll)` (nalgebra's
/// [`Rotation3::from_euler_angles`] convention).
///
/// Not [`Rotation3::euler_angles`]: its `asin` loses half the digits near
/// pitch = ±90°, where MDH origins often are (`alpha = −90°` with
/// `theta = −90°`). Here pitch comes from `atan2`, and yaw is taken from
/// the rotation left after roll and pitch, so the angles reproduce `R` to
/// rounding even at and near gimbal lock.
#[must_use]
pub fn urdf_origin(iso: &Isometry3<f64>) -> ([f64; 3], [f64; 3]) {
    let t = iso.translation.vector / MM_PER_M;
    let r = iso.rotation.to_rotation_matrix();
    let m = r.matrix();
    let cos_pitch = m[(0, 0)].hypot(m[(1, 0)]);
    let pitch = (-m[(2, 0)]).atan2(cos_pitch);
    let roll = if cos_pitch < GIMBAL_LOCK_COS {
        0.0
    } else {
        m[(2, 1)].atan2(m[(2, 2)])
    };
    let rest = r
        * Rotation3::from_euler_angles(-roll, 0.0, 0.0)
        * Rotation3::from_euler_angles(0.0, -pitch, 0.0);
    let rm = rest.matrix();
    let yaw = rm[(1, 0)].atan2(rm[(0, 0)]);
    ([t.x, t.y, t.z], [roll, pitch, yaw])
}

/// A length (m) or angle (rad) as the URDF and YAML exports write it:
/// Rust's shortest text that reads back to the same `f64`, in plain
/// decimals (no exponent, which YAML 1.1 readers such as xacro's take for
/// a string); below 1e-15 (1e-12 mm, rounding of a composed transform)
/// it is `0`, never `-0`.
#[must_use]
pub fn urdf_number(v: f64) -> String {
    if v.abs() < 1e-15 {
        "0".to_string()
    } else {
        format!("{v}")
    }
}

/// The fixed part of joint `joint`'s link transform before its rotation,
/// `Rx(alpha) · Tx(a) · Ry(beta) · Rz(theta)` (mm).
fn mdh_origin(joint: &Joint) -> Isometry3<f64> {
    rot_x(joint.alpha.to_radians())
        * trans(joint.a, 0.0, 0.0)
        * rot_y(joint.beta.to_radians())
        * rot_z(joint.theta.to_radians())
}

/// The URDF joint origins of a robot (mm, not yet converted), in chain
/// order: one per revolute joint (see the module doc), then the flange's.
#[must_use]
pub fn urdf_joint_origins(robot: &Robot) -> Vec<Isometry3<f64>> {
    let mut origins = Vec::with_capacity(robot.joints.len() + 1);
    let mut carried_d = 0.0;
    for joint in &robot.joints {
        origins.push(trans(0.0, 0.0, carried_d) * mdh_origin(joint));
        carried_d = joint.d;
    }
    origins.push(trans(0.0, 0.0, carried_d) * robot.flange);
    origins
}

/// Makes text safe inside an XML comment (no `--`, no trailing `-`).
fn xml_comment(text: &str) -> String {
    let mut out = text.replace("--", "- -").replace("--", "- -");
    if out.ends_with('-') {
        out.push(' ');
    }
    out
}

/// Writes one `<origin>` element.
fn push_origin(out: &mut String, iso: &Isometry3<f64>) {
    let ([x, y, z], [roll, pitch, yaw]) = urdf_origin(iso);
    let _ = writeln!(
        out,
        "    <origin xyz=\"{x} {y} {z}\" rpy=\"{roll} {pitch} {yaw}\"/>"
    );
}

/// Writes a fixed joint.
fn push_fixed(out: &mut String, name: &str, parent: &str, child: &str, origin: &Isometry3<f64>) {
    let _ = writeln!(out, "  <joint name=\"{name}\" type=\"fixed\">");
    let _ = writeln!(out, "    <parent link=\"{parent}\"/>");
    let _ = writeln!(out, "    <child link=\"{child}\"/>");
    push_origin(out, origin);
    out.push_str("  </joint>\n");
}

/// The result's calibrated model as a URDF fragment (m, rad): links
/// `world` (only when the base `B` is not the identity), `base_link`,
/// `link_1` … `link_n`, `flange` and `sensor`; revolute joints `joint_1`
/// … `joint_n` about z; fixed joints `base_joint` (world → base_link, `B`),
/// `flange_joint` (link_n → flange, `Tz(d_n) · F`) and `sensor_joint`
/// (flange → sensor, the calibrated hand-eye `eT_s`). Composing the
/// origins with a rotation `q_i` (rad) about z after each revolute
/// joint's origin gives [`Robot::base_from_flange`] (see the module doc).
/// `source` names the result file in the leading comment. The links carry
/// no geometry or inertia, and the joint limits are not part of the
/// calibration: the fragment says to take them from the vendor's URDF.
///
fn urdf(result: &ResultFile, robot: &Robot, source: &str) -> String {
    let hand_eye = result.hand_eye;
    let n = robot.joints.len();
    let mut out = String::new();
    out.push_str("<?xml version=\"1.0\"?>\n");
    let _ = writeln!(
        out,
        "<!-- Generated by spherecal {} from result {} (session {:?}).\n     \
         Calibrated MDH model in metres and radians. A joint value of zero is the\n     \
         controller's zero: the theta offsets are in the joint origins.\n     \
         Joint limits, effort and velocity are not calibrated: take them from the\n     \
         vendor's description; the limits below only span one turn each way. -->",
        env!("CARGO_PKG_VERSION"),
        xml_comment(source),
        xml_comment(&result.session),
    );
    let _ = writeln!(out, "<robot name=\"{}\">", escape(&robot.name));
    let has_base = robot.base != Isometry3::identity();
    if has_base {
        out.push_str("  <link name=\"world\"/>\n");
    }
    out.push_str("  <link name=\"base_link\"/>\n");
    for i in 1..=n {
        let _ = writeln!(out, "  <link name=\"link_{i}\"/>");
    }
    out.push_str("  <link name=\"flange\"/>\n  <link name=\"sensor\"/>\n");
    if has_base {
        push_fixed(&mut out, "base_joint", "world", "base_link", &robot.base);
    }
    let origins = urdf_joint_origins(robot);
    let mut parent = "base_link".to_string();
    for (i, origin) in origins.iter().take(n).enumerate() {
        let child = format!("link_{}", i + 1);
        let _ = writeln!(out, "  <joint name=\"joint_{}\" type=\"revolute\">", i + 1);
        let _ = writeln!(out, "    <parent link=\"{parent}\"/>");
        let _ = writeln!(out, "    <child link=\"{child}\"/>");
        push_origin(&mut out, origin);
        out.push_str("    <axis xyz=\"0 0 1\"/>\n");
        let _ = writeln!(
            out,
            "    <limit lower=\"{}\" upper=\"{}\" effort=\"0\" velocity=\"0\"/>",
            -std::f64::consts::TAU,
            std::f64::consts::TAU
        );
        out.push_str("  </joint>\n");
        parent = child;
    }
    if let Some(flange) = origins.last() {
        push_fixed(&mut out, "flange_joint", &parent, "flange", flange);
    }
    push_fixed(&mut out, "sensor_joint", "flange", "sensor", &hand_eye);
    out.push_str("</robot>\n");
    out
}
