//! Universal Robots' calibration file (issue 33, `export-model --format
//! ur-calibration`): the `kinematics:` YAML that `ur_description` loads
//! (`xacro.load_yaml` in `ur_common.xacro`, the `kinematics_params`
//! argument of `ur_robot_driver`) and its `hash`.
//!
//! ur_description builds the arm as `base_link_inertia` (the controller's
//! `base` frame) → `shoulder_pan_joint` with origin `shoulder` →
//! `shoulder_lift_joint` (`upper_arm`) → `elbow_joint` (`forearm`) →
//! `wrist_1_joint` → `wrist_2_joint` → `wrist_3_joint`, each revolute about
//! its own z after its `<origin xyz="x y z" rpy="roll pitch yaw"/>` (m,
//! rad), then the fixed `wrist_3_link → flange` (rpy `0 −π/2 −π/2`) and
//! `flange → tool0` (rpy `π/2 0 π/2`). Here the nominal model is laid on
//! that chain (the model's base frame is the controller's `base`, its
//! flange `tool0`), and the calibrated origins come from
//! [`calibrated_origins`]: the chain's forward kinematics is the
//! calibrated model's.
//!
//! The `hash` is spherecal's own, `spherecal_` and a digest of the
//! numbers: the driver compares it with the controller's own calibration
//! checksum and warns that they differ, which is expected (module doc of
//! the guide's chapter).

use std::fmt::Write as _;

use nalgebra::{Isometry3, Vector3};
use sha2::{Digest, Sha256};

use super::model::{urdf_number, urdf_origin};
use crate::engine::base::geometry::{rot_x, rot_y, rot_z};
use crate::engine::base::robot::Robot;
use crate::engine::base::robot::chain_origins::{ChainFitError, ChainStep, calibrated_origins};
use crate::engine::files::format::ResultFile;

/// The keys of the six joints, base to tip.
pub const UR_JOINT_KEYS: [&str; 6] = [
    "shoulder",
    "upper_arm",
    "forearm",
    "wrist_1",
    "wrist_2",
    "wrist_3",
];

/// Off-axis distance (mm) and tilt (rad) of the tool flange from axis 6
/// beyond which the model is not a UR arm.
const ON_AXIS: (f64, f64) = (1e-6, 1e-9);

/// Why no UR calibration file can be written.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum UrCalibrationError {
    /// The result has no robot.
    #[error(
        "the result has no robot model (pose-only, no robot given): there are no kinematics to write; export the tool data instead (--format tool --controller ur)"
    )]
    NoRobot,
    /// Not a UR.
    #[error(
        "the robot {0:?} is not a Universal Robots arm (a UR preset, or a robot named `UR…`); name it one with --controller ur"
    )]
    NotUr(String),
    /// Not six joints.
    #[error("the robot has {0} joints, a UR arm 6")]
    NotSixAxis(usize),
    /// The flange is not on axis 6 as UR's `tool0` is.
    #[error(
        "the model's flange is {mm:.6} mm off axis 6 or tilted {deg:.6}° from it: UR's tool0 lies on the axis, so this is not a UR arm's model"
    )]
    FlangeOffAxis {
        /// Off-axis distance, mm.
        mm: f64,
        /// Tilt, deg.
        deg: f64,
    },
    /// The chain did not fit (an internal error).
    #[error(transparent)]
    Chain(#[from] ChainFitError),
}

/// `wrist_3_link → tool0` as ur_description fixes it: `wrist_3_link →
/// flange` (rpy `0 −π/2 −π/2`) then `flange → tool0` (rpy `π/2 0 π/2`).
#[must_use]
pub fn wrist_3_to_tool0() -> Isometry3<f64> {
    use std::f64::consts::FRAC_PI_2;
    let rpy = |r: f64, p: f64, y: f64| rot_z(y) * rot_y(p) * rot_x(r);
    rpy(0.0, -FRAC_PI_2, -FRAC_PI_2) * rpy(FRAC_PI_2, 0.0, FRAC_PI_2)
}

/// The nominal model laid on ur_description's chain: six revolute steps
/// about z, link `i` at the MDH frame `i` (`T_i(0)` as origin, as UR's own
/// file has it: `shoulder.z` is `d_1`), the base folded into the first,
/// the flange into the last so that the fixed [`wrist_3_to_tool0`]
/// follows, then that fixed step.
///
/// # Errors
/// [`UrCalibrationError`] when the model has not six joints or its flange
/// is not on axis 6.
pub fn ur_chain(nominal: &Robot) -> Result<Vec<ChainStep>, UrCalibrationError> {
    if nominal.dof() != UR_JOINT_KEYS.len() {
        return Err(UrCalibrationError::NotSixAxis(nominal.dof()));
    }
    // UR's links sit at the MDH frames (d_i in joint i's origin): link i
    // is `P_{i-1} · T_i(0)`, turning about its z.
    let mut origins: Vec<Isometry3<f64>> = nominal.joints.iter().map(|j| j.link(0.0)).collect();
    let wrist = wrist_3_to_tool0();
    // wrist_3_link = frame 6 · (F · wrist⁻¹): that must turn about z.
    let fold = nominal.flange * wrist.inverse();
    let mm = fold.translation.vector.xy().norm();
    let tilt = (fold.rotation * Vector3::z()).angle(&Vector3::z());
    if mm > ON_AXIS.0 || tilt > ON_AXIS.1 {
        return Err(UrCalibrationError::FlangeOffAxis {
            mm,
            deg: tilt.to_degrees(),
        });
    }
    if let Some(first) = origins.first_mut() {
        *first = nominal.base * *first;
    }
    if let Some(last) = origins.last_mut() {
        *last *= fold;
    }
    let mut steps: Vec<ChainStep> = origins
        .into_iter()
        .zip(UR_JOINT_KEYS)
        .map(|(origin, key)| ChainStep {
            name: key.to_string(),
            origin,
            axis: Some(Vector3::z()),
        })
        .collect();
    steps.push(ChainStep {
        name: "wrist_3_link-tool0".to_string(),
        origin: wrist,
        axis: None,
    });
    Ok(steps)
}

/// Whether the result's robot is a UR: named `Universal Robots …` or
/// `UR…` (the presets are), or said to be one (`--controller ur`).
#[must_use]
pub fn is_ur(robot: &Robot) -> bool {
    crate::engine::base::robot::controller::Controller::for_robot(&robot.name)
        == Some(crate::engine::base::robot::controller::Controller::Ur)
}

/// The calibration YAML of `result`'s calibrated UR arm. `named_ur`: the
/// user said the robot is a UR (`--controller ur`) whatever its name.
///
/// # Errors
/// [`UrCalibrationError`]: no robot, not a UR, not its shape.
pub fn ur_calibration(
    result: &ResultFile,
    source: &str,
    named_ur: bool,
) -> Result<String, UrCalibrationError> {
    let (Some(calibrated), Some(nominal)) = (result.robot.as_ref(), result.nominal()) else {
        return Err(UrCalibrationError::NoRobot);
    };
    if !named_ur && !is_ur(calibrated) {
        return Err(UrCalibrationError::NotUr(calibrated.name.clone()));
    }
    let steps = ur_chain(&nominal)?;
    let origins = calibrated_origins(&steps, &nominal, calibrated)?;
    let mut body = String::new();
    for (key, origin) in UR_JOINT_KEYS.iter().zip(&origins) {
        let ([x, y, z], [roll, pitch, yaw]) = urdf_origin(origin);
        let _ = writeln!(body, "  {key}:");
        for (name, v) in [
            ("x", x),
            ("y", y),
            ("z", z),
            ("roll", roll),
            ("pitch", pitch),
            ("yaw", yaw),
        ] {
            let _ = writeln!(body, "    {name}: {}", urdf_number(v));
        }
    }
    let digest = Sha256::digest(body.as_bytes());
    let hash: String = digest.iter().take(8).map(|b| format!("{b:02x}")).collect();
    let mut out = String::new();
    let _ = writeln!(
        out,
        "# Calibrated kinematics of {:?} for ur_description / ur_robot_driver (kinematics_params),",
        calibrated.name
    );
    let _ = writeln!(
        out,
        "# from {source} (session {:?}) by spherecal {}. Metres and radians.",
        result.session,
        env!("CARGO_PKG_VERSION")
    );
    let _ = writeln!(
        out,
        "# The hash is spherecal's: the driver reports that it differs from the controller's calibration checksum (expected)."
    );
    out.push_str("kinematics:\n");
    out.push_str(&body);
    let _ = writeln!(out, "  hash: spherecal_{hash}");
    Ok(out)
}
