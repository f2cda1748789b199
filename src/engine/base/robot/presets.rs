//! Robot presets: the nominal models of the robots spherecal ships (each
//! with its source), their joint limits, and the paper's Table 1 errors of
//! the IRB 2400. The simulator, the planner, the import and the workbench
//! all take their presets from here.

use serde::{Deserialize, Serialize};

use super::kinematics::{Joint, JointLimit, Robot};

/// A preset by key, for the command line and the files that name one
/// (`--robot irb2400`, the simulator's configuration).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RobotChoice {
    /// ABB IRB 2400/16, the paper's robot.
    #[default]
    Irb2400,
    /// ABB IRB 120.
    Irb120,
    /// Universal Robots UR5e.
    Ur5e,
}

impl RobotChoice {
    /// Every preset.
    pub const ALL: [Self; 3] = [Self::Irb2400, Self::Irb120, Self::Ur5e];

    /// The choice whose [`Self::key`] is `key`.
    #[must_use]
    pub fn from_key(key: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|c| c.key() == key)
    }

    /// The preset key of [`preset`].
    #[must_use]
    pub fn key(self) -> &'static str {
        match self {
            Self::Irb2400 => "irb2400",
            Self::Irb120 => "irb120",
            Self::Ur5e => "ur5e",
        }
    }
}

/// The paper's Table 1 (identified kinematic errors of the IRB 2400), in
/// the table's column order `Δα (deg), Δa (mm), Δd (mm), Δθ (deg), Δβ (deg)`,
/// one row per link. [`table1_errors`] maps it onto [`Joint`].
pub const TABLE1: [[f64; 5]; 6] = [
    [0.1221, 0.0438, 0.0, 1.8962, -0.0399],
    [0.0920, 0.2097, 0.0003, 0.1624, 0.0444],
    [-0.2571, 0.1023, 0.0003, 0.7574, 0.7143],
    [0.4691, 0.3217, 0.0002, 0.0676, 0.0676],
    [0.4309, -0.6921, -0.3061, 0.0805, 0.0805],
    [0.0040, -0.0004, -0.0148, 0.0264, -0.0293],
];

/// The paper's Table 1 as per-joint errors (deg, mm): Table 1's columns
/// `Δα, Δa, Δd, Δθ, Δβ` go to `alpha, a, d, theta, beta`.
#[must_use]
pub fn table1_errors() -> Vec<Joint> {
    TABLE1
        .iter()
        .map(|row| Joint {
            alpha: row[0],
            a: row[1],
            d: row[2],
            theta: row[3],
            beta: row[4],
        })
        .collect()
}

/// A named robot preset: nominal model and joint limits.
#[derive(Debug, Clone)]
pub struct Preset {
    /// Short key used on the command line (`--robot irb2400`).
    pub key: &'static str,
    /// The nominal model.
    pub robot: Robot,
    /// Joint limits, deg.
    pub limits: Vec<JointLimit>,
}

fn joint(alpha: f64, a: f64, beta: f64, theta: f64, d: f64) -> Joint {
    Joint {
        alpha,
        a,
        beta,
        theta,
        d,
    }
}

fn limits(pairs: &[(f64, f64)]) -> Vec<JointLimit> {
    pairs
        .iter()
        .map(|&(min, max)| JointLimit { min, max })
        .collect()
}

/// ABB IRB 2400/16 in the FORMAT.md convention (the paper's robot). Values:
/// FORMAT.md's table, which follows ABB's product specification (615 mm
/// base height, 100 mm shoulder offset, 705 mm lower arm, 135 mm elbow
/// offset, 755 mm upper arm, 85 mm flange). Limits: ABB product
/// specification IRB 2400 (axis 1 ±180°, 2 −100/+110°, 3 −60/+65°,
/// 4 ±200°, 5 ±120°, 6 ±400°).
#[must_use]
pub fn irb2400() -> Preset {
    Preset {
        key: "irb2400",
        robot: Robot::new(
            "ABB IRB 2400/16",
            vec![
                joint(0.0, 0.0, 0.0, 0.0, 615.0),
                joint(-90.0, 100.0, 0.0, -90.0, 0.0),
                joint(0.0, 705.0, 0.0, 0.0, 0.0),
                joint(-90.0, 135.0, 0.0, 0.0, 755.0),
                joint(90.0, 0.0, 0.0, 0.0, 0.0),
                joint(-90.0, 0.0, 0.0, 0.0, 85.0),
            ],
        ),
        limits: limits(&[
            (-180.0, 180.0),
            (-100.0, 110.0),
            (-60.0, 65.0),
            (-200.0, 200.0),
            (-120.0, 120.0),
            (-400.0, 400.0),
        ]),
    }
}

/// ABB IRB 120-3/0.6 in the same layout as the IRB 2400. Values: ABB
/// product specification IRB 120 (290 mm base height, 270 mm lower arm,
/// 70 mm elbow offset, 302 mm upper arm, 72 mm flange; no shoulder
/// offset). Limits from the same document (axis 1 ±165°, 2 ±110°,
/// 3 −110/+70°, 4 ±160°, 5 ±120°, 6 ±400°).
#[must_use]
pub fn irb120() -> Preset {
    Preset {
        key: "irb120",
        robot: Robot::new(
            "ABB IRB 120-3/0.6",
            vec![
                joint(0.0, 0.0, 0.0, 0.0, 290.0),
                joint(-90.0, 0.0, 0.0, -90.0, 0.0),
                joint(0.0, 270.0, 0.0, 0.0, 0.0),
                joint(-90.0, 70.0, 0.0, 0.0, 302.0),
                joint(90.0, 0.0, 0.0, 0.0, 0.0),
                joint(-90.0, 0.0, 0.0, 0.0, 72.0),
            ],
        ),
        limits: limits(&[
            (-165.0, 165.0),
            (-110.0, 110.0),
            (-110.0, 70.0),
            (-160.0, 160.0),
            (-120.0, 120.0),
            (-400.0, 400.0),
        ]),
    }
}

/// Universal Robots UR5e. Values: Universal Robots' published standard-DH
/// table ("DH parameters for calculations of kinematics and dynamics":
/// d1 = 162.5, a2 = −425, a3 = −392.2, d4 = 133.3, d5 = 99.7, d6 = 99.6 mm,
/// alpha1 = 90°, alpha4 = 90°, alpha5 = −90°), converted to this modified
/// convention: standard `(a_i, alpha_i)` become the `(a, alpha)` of joint
/// `i+1`; `a_6 = alpha_6 = 0`, so the flange transform is the identity.
/// Limits ±360° on every joint (UR e-Series user manual).
#[must_use]
pub fn ur5e() -> Preset {
    Preset {
        key: "ur5e",
        robot: Robot::new(
            "Universal Robots UR5e",
            vec![
                joint(0.0, 0.0, 0.0, 0.0, 162.5),
                joint(90.0, 0.0, 0.0, 0.0, 0.0),
                joint(0.0, -425.0, 0.0, 0.0, 0.0),
                joint(0.0, -392.2, 0.0, 0.0, 133.3),
                joint(90.0, 0.0, 0.0, 0.0, 99.7),
                joint(-90.0, 0.0, 0.0, 0.0, 99.6),
            ],
        ),
        limits: limits(&[(-360.0, 360.0); 6]),
    }
}

/// Every preset, the paper's robot first.
#[must_use]
pub fn presets() -> Vec<Preset> {
    vec![irb2400(), irb120(), ur5e()]
}

/// The preset with this key (`irb2400`, `irb120`, `ur5e`).
#[must_use]
pub fn preset(key: &str) -> Option<Preset> {
    presets().into_iter().find(|p| p.key == key)
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector3;

    use super::*;

    #[test]
    fn irb2400_zero_pose() {
        let robot = irb2400().robot;
        let pose = robot.base_from_flange(&[0.0; 6]);
        let p = pose.translation.vector;
        assert!((p - Vector3::new(940.0, 0.0, 1455.0)).norm() < 1e-9, "{p}");
        // Flange z along base +x, as in ABB's tool0 at the calibration pose.
        let z = pose.rotation * Vector3::z();
        assert!((z - Vector3::x()).norm() < 1e-12, "{z}");
    }

    #[test]
    fn irb120_zero_pose() {
        let p = irb120()
            .robot
            .base_from_flange(&[0.0; 6])
            .translation
            .vector;
        assert!((p - Vector3::new(374.0, 0.0, 630.0)).norm() < 1e-9, "{p}");
    }

    #[test]
    fn ur5e_zero_pose() {
        // UR zero pose: arm stretched along −x; tool at (−817.2, −232.9, 62.8)
        // per the standard-DH chain (x = a2 + a3, y = −(d4 + d6), z = d1 − d5).
        let p = ur5e().robot.base_from_flange(&[0.0; 6]).translation.vector;
        assert!(
            (p - Vector3::new(-817.2, -232.9, 62.8)).norm() < 1e-9,
            "{p}"
        );
    }

    #[test]
    fn irb2400_joint2_rotates_arm_forward() {
        // +q2 leans the lower arm forward: the wrist moves along +x, down.
        let robot = irb2400().robot;
        let p = robot
            .base_from_flange(&[0.0, 10.0, 0.0, 0.0, 0.0, 0.0])
            .translation
            .vector;
        assert!(p.x > 940.0 && p.z < 1455.0, "{p}");
    }

    #[test]
    fn table1_maps_columns_onto_joints() {
        let e = table1_errors();
        assert_eq!(e.len(), 6);
        let j1 = e[0];
        assert_eq!(
            (j1.alpha, j1.a, j1.beta, j1.theta, j1.d),
            (0.1221, 0.0438, -0.0399, 1.8962, 0.0)
        );
        let j5 = e[4];
        assert_eq!(
            (j5.alpha, j5.a, j5.beta, j5.theta, j5.d),
            (0.4309, -0.6921, 0.0805, 0.0805, -0.3061)
        );
    }
}
