//! The cell a scan is measured with, taken from a result file: the robot
//! model and the hand-eye (calibrated, or the nominal model and the
//! initial hand-eye), the covariance of the calibrated parameters (`ml`),
//! and the checks that the scan belongs to the result: the same robot,
//! the same joint count, poses within the joint range the calibration
//! saw.

use nalgebra::Isometry3;

use super::MeasureError;
use super::scan::{Placement, Scan};
use crate::engine::base::robot::{PARAM_NAMES, Robot};
use crate::engine::base::session::{Session, Use};
pub use crate::engine::calibrate::solve::ml::covariance::ParameterCovariance;
use crate::engine::files::format::ResultFile;

/// The nominal model of the scan and of the result agree to this (mm and
/// deg per parameter, and in the base and flange matrices): a result file
/// writes its numbers to ~12 significant digits, and the result's nominal
/// is its calibrated model minus the joint errors, so a few 1e-10 differ;
/// a different robot differs by whole millimetres or degrees.
pub const SAME_NOMINAL_TOLERANCE: f64 = 1e-6;

/// Which model of the result places the sensor.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ModelChoice {
    /// The calibrated model and hand-eye (the default).
    #[default]
    Calibrated,
    /// The nominal model and the initial hand-eye: what the cell measured
    /// before calibration.
    Nominal,
}

impl ModelChoice {
    /// `calibrated` or `nominal`.
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Calibrated => "calibrated",
            Self::Nominal => "nominal",
        }
    }
}

/// A robot model and a hand-eye: where the sensor is at a pose.
#[derive(Debug, Clone, PartialEq)]
pub struct CellModel {
    /// The kinematic model; `None` for a pose-only result without a robot.
    pub robot: Option<Robot>,
    /// `eT_s`, sensor to flange (mm).
    pub flange_from_sensor: Isometry3<f64>,
}

impl CellModel {
    /// The result's calibrated or nominal model (see [`ModelChoice`]).
    #[must_use]
    pub fn of_result(result: &ResultFile, choice: ModelChoice) -> Self {
        match choice {
            ModelChoice::Calibrated => Self {
                robot: result.robot.clone(),
                flange_from_sensor: result.hand_eye,
            },
            ModelChoice::Nominal => Self {
                robot: nominal_robot(result),
                flange_from_sensor: result.hand_eye_initial,
            },
        }
    }

    /// `base_from_sensor` at `placement`: `bT_e(q)·eT_s` (FORMAT.md eq. 1-2),
    /// or the given flange pose times `eT_s`. `None` when joint readings
    /// meet a model without a robot.
    #[must_use]
    pub fn base_from_sensor(&self, placement: &Placement) -> Option<Isometry3<f64>> {
        let base_from_flange = match placement {
            Placement::Flange(pose) => *pose,
            Placement::Joints(q) => self.robot.as_ref()?.base_from_flange(q),
        };
        Some(base_from_flange * self.flange_from_sensor)
    }
}

/// The result's nominal robot: the calibrated one minus the joint errors,
/// or for a result that calibrated the hand-eye only (pose-only, no joint
/// errors) its robot as given.
#[must_use]
pub fn nominal_robot(result: &ResultFile) -> Option<Robot> {
    if result.hand_eye_only() {
        result.robot.clone()
    } else {
        result.nominal()
    }
}

/// The result's parameter covariance ([`ParameterCovariance::read`] for
/// the result's model): `Ok(None)` when the result has none (the paper's
/// method, or an `ml` run that stopped before its diagnostics).
///
/// # Errors
/// [`MeasureError::Input`] when the block names a parameter the result's
/// model does not have, or is not square, symmetric and finite.
pub fn covariance_of(result: &ResultFile) -> Result<Option<ParameterCovariance>, MeasureError> {
    let joints = result.robot.as_ref().map_or(0, Robot::dof);
    ParameterCovariance::read(&result.solver, joints)
        .map_err(|e| MeasureError::Input(e.to_string()))
}

/// Refuses a scan that does not belong to the result: joint readings
/// with a result that has no kinematic model, a joint count other than
/// the result's robot's, or a nominal robot (name, joints, base, flange)
/// other than the result's. Returns warnings for what is allowed but
/// worth saying (flange poses with a result that calibrated the
/// kinematics: only the hand-eye applies).
///
/// # Errors
/// [`MeasureError::Input`] naming the pose or the robots.
pub fn check_scan(scan: &Scan, result: &ResultFile) -> Result<Vec<String>, MeasureError> {
    let mut warnings = Vec::new();
    let joints_pose = scan
        .poses
        .iter()
        .find(|p| matches!(p.placement, Placement::Joints(_)));
    if let Some(pose) = joints_pose {
        let Some(robot) = result.robot.as_ref().filter(|_| !result.hand_eye_only()) else {
            return Err(MeasureError::Input(format!(
                "pose {}: the scan gives joint readings, but the result calibrated only the hand-eye from flange poses (pose-only) and has no calibrated kinematic model; measure with the controller's flange poses (--poses)",
                pose.id
            )));
        };
        for p in &scan.poses {
            if let Placement::Joints(q) = &p.placement
                && q.len() != robot.dof()
            {
                return Err(MeasureError::Input(format!(
                    "pose {}: {} joint readings, the result's robot {:?} has {} joints: a scan from another robot",
                    p.id,
                    q.len(),
                    robot.name,
                    robot.dof()
                )));
            }
        }
    } else if !scan.poses.is_empty() && !result.hand_eye_only() {
        warnings.push(
            "the scan gives the controller's flange poses: only the calibrated hand-eye applies, not the calibrated kinematic model".to_string(),
        );
    }
    if let (Some(scan_robot), Some(nominal)) = (&scan.robot, nominal_robot(result)) {
        if let Some(why) = different_robot(scan_robot, &nominal) {
            return Err(MeasureError::Input(format!(
                "the scan's robot {:?} is not the result's {:?}: {why}; measure with the result of this robot's calibration",
                scan_robot.name, nominal.name
            )));
        }
    } else if let (Some(scan_robot), None) = (&scan.robot, &result.robot)
        && !scan_robot.joints.is_empty()
        && joints_pose.is_some()
    {
        return Err(MeasureError::Input(format!(
            "the scan's robot {:?} is not in the result (a pose-only result without a robot)",
            scan_robot.name
        )));
    }
    Ok(warnings)
}

/// Why two nominal models are not the same robot, if they are not.
fn different_robot(a: &Robot, b: &Robot) -> Option<String> {
    if a.name != b.name {
        return Some(format!("the names differ ({:?}, {:?})", a.name, b.name));
    }
    if a.dof() != b.dof() {
        return Some(format!("{} joints against {}", a.dof(), b.dof()));
    }
    for (i, (ja, jb)) in a.joints.iter().zip(&b.joints).enumerate() {
        for (p, name) in PARAM_NAMES.iter().enumerate() {
            let (va, vb) = (ja.get(p), jb.get(p));
            if (va - vb).abs() > SAME_NOMINAL_TOLERANCE {
                return Some(format!("nominal {name}{} is {va} against {vb}", i + 1));
            }
        }
    }
    let same = |x: &Isometry3<f64>, y: &Isometry3<f64>| {
        (x.to_homogeneous() - y.to_homogeneous()).amax() <= SAME_NOMINAL_TOLERANCE
    };
    if !same(&a.base, &b.base) {
        return Some("the base frames differ".into());
    }
    if !same(&a.flange, &b.flange) {
        return Some("the flange frames differ".into());
    }
    None
}

/// The range of each joint (deg) over the poses a calibration identified
/// from: a scan pose outside it is measured where the model was not
/// checked.
#[derive(Debug, Clone, PartialEq)]
pub struct JointRange {
    /// Smallest reading of each joint, deg.
    pub min: Vec<f64>,
    /// Largest reading of each joint, deg.
    pub max: Vec<f64>,
}

/// A scan pose with a joint outside the calibrated range.
#[derive(Debug, Clone, PartialEq)]
pub struct OutOfRange {
    /// The pose id.
    pub id: String,
    /// The joint, 1-based.
    pub joint: usize,
    /// Its reading, deg.
    pub reading: f64,
    /// The range the calibration saw, deg.
    pub range: [f64; 2],
}

impl std::fmt::Display for OutOfRange {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "pose {}: joint {} at {:.3}° is outside {:.3}…{:.3}° that the calibration saw",
            self.id, self.joint, self.reading, self.range[0], self.range[1]
        )
    }
}

impl JointRange {
    /// The range of the `identify` poses of `session` (what the
    /// identification saw); `None` for a pose-only session or one
    /// without identify poses.
    #[must_use]
    pub fn of_session(session: &Session) -> Option<Self> {
        let mut readings = session
            .measurements
            .iter()
            .filter(|m| m.usage == Use::Identify && m.flange.is_none())
            .map(|m| &m.joints);
        let first = readings.next()?;
        let mut range = Self {
            min: first.clone(),
            max: first.clone(),
        };
        for q in readings {
            for (k, v) in q.iter().enumerate().take(range.min.len()) {
                range.min[k] = range.min[k].min(*v);
                range.max[k] = range.max[k].max(*v);
            }
        }
        Some(range)
    }

    /// Every pose of `scan` with a joint outside the range (each pose once,
    /// at its joint furthest out), in scan order.
    #[must_use]
    pub fn outside(&self, scan: &Scan) -> Vec<OutOfRange> {
        let mut out = Vec::new();
        for p in &scan.poses {
            let Placement::Joints(q) = &p.placement else {
                continue;
            };
            let worst = q
                .iter()
                .enumerate()
                .take(self.min.len())
                .map(|(k, v)| (k, *v, (self.min[k] - v).max(v - self.max[k])))
                .filter(|(_, _, beyond)| *beyond > 0.0)
                .max_by(|a, b| a.2.total_cmp(&b.2));
            if let Some((k, v, _)) = worst {
                out.push(OutOfRange {
                    id: p.id.clone(),
                    joint: k + 1,
                    reading: v,
                    range: [self.min[k], self.max[k]],
                });
            }
        }
        out
    }
}
