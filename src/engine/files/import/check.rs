//! The optional flange-pose check of a joint log: the controller's flange
//! pose of every row against the nominal model's forward kinematics of its
//! joints, flagged beyond a tolerance with a hint at the likely cause
//! (joints in the wrong unit, two joint columns swapped, wrong robot or
//! base frame).

use nalgebra::Isometry3;

use super::{AngleUnit, FlangeConvention};
use crate::engine::base::robot::Robot;

/// Default position tolerance of the flange-pose check, mm: a few mm, far
/// above the nominal model's errors (< 1 mm) and far below the effect of a
/// unit or joint-order mistake (tens to hundreds of mm).
pub const DEFAULT_POSITION_TOLERANCE_MM: f64 = 3.0;
/// Default rotation tolerance of the flange-pose check, deg.
pub const DEFAULT_ROTATION_TOLERANCE_DEG: f64 = 0.5;

/// The optional flange-pose check.
#[derive(Debug, Clone, PartialEq)]
pub struct FlangeCheck {
    /// How the controller writes the pose.
    pub convention: FlangeConvention,
    /// The pose columns of the joint log, in the convention's order.
    pub columns: Vec<String>,
    /// Largest accepted position mismatch, mm.
    pub tolerance_mm: f64,
    /// Largest accepted rotation mismatch, deg.
    pub tolerance_deg: f64,
}

impl FlangeCheck {
    /// A check with the convention's default columns and tolerances.
    #[must_use]
    pub fn new(convention: FlangeConvention) -> Self {
        Self {
            convention,
            columns: convention.default_columns(),
            tolerance_mm: DEFAULT_POSITION_TOLERANCE_MM,
            tolerance_deg: DEFAULT_ROTATION_TOLERANCE_DEG,
        }
    }
}

/// The flange-pose check of one pose.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseCheck {
    /// Measurement id.
    pub id: String,
    /// Distance between the controller's and the nominal FK flange
    /// position, mm.
    pub position_error_mm: f64,
    /// Angle between the two flange orientations, deg.
    pub rotation_error_deg: f64,
    /// Whether either error is above its tolerance.
    pub flagged: bool,
    /// The likely cause when flagged, else empty.
    pub hint: String,
}

/// Position (mm) and rotation (deg) mismatch of FK at `q_deg` and `pose`.
fn mismatch(robot: &Robot, q_deg: &[f64], pose: &Isometry3<f64>) -> (f64, f64) {
    let fk = robot.base_from_flange(q_deg);
    (
        (fk.translation.vector - pose.translation.vector).norm(),
        fk.rotation.angle_to(&pose.rotation).to_degrees(),
    )
}

pub(super) fn check_pose(
    robot: &Robot,
    f: &FlangeCheck,
    unit: AngleUnit,
    id: &str,
    raw: &[f64],
    pose: &Isometry3<f64>,
) -> PoseCheck {
    let within = |(p, r): (f64, f64)| p <= f.tolerance_mm && r <= f.tolerance_deg;
    let q: Vec<f64> = raw.iter().map(|&v| unit.to_deg(v)).collect();
    let (position_error_mm, rotation_error_deg) = mismatch(robot, &q, pose);
    let flagged = !within((position_error_mm, rotation_error_deg));
    let mut hint = String::new();
    if flagged {
        let (other, other_q): (AngleUnit, Vec<f64>) = match unit {
            AngleUnit::Deg => (AngleUnit::Rad, raw.iter().map(|v| v.to_degrees()).collect()),
            AngleUnit::Rad => (AngleUnit::Deg, raw.to_vec()),
        };
        if within(mismatch(robot, &other_q, pose)) {
            hint = format!(
                "joints look like {}: reading them as {} brings FK within tolerance (--joint-unit {})",
                other.as_str(),
                other.as_str(),
                other.as_str()
            );
        } else {
            'swap: for i in 0..q.len() {
                for j in i + 1..q.len() {
                    let mut s = q.clone();
                    s.swap(i, j);
                    if within(mismatch(robot, &s, pose)) {
                        hint = format!(
                            "joint columns {} and {} look swapped: swapping them brings FK within tolerance",
                            i + 1,
                            j + 1
                        );
                        break 'swap;
                    }
                }
            }
        }
        if hint.is_empty() {
            hint = "wrong robot model or base frame?".into();
        }
    }
    PoseCheck {
        id: id.to_string(),
        position_error_mm,
        rotation_error_deg,
        flagged,
        hint,
    }
}
