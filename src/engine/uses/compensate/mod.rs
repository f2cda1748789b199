//! Target compensation: driving the robot where it is meant to go. A
//! controller runs its nominal kinematics; a calibration helps the robot
//! itself only when its targets are corrected (RoboDK calls it filtering
//! a program). For each target, the TCP pose wanted in the base frame:
//!
//! 1. the **nominal solution** `q_n` on the branch the target means
//!    ([`arms`]: its written configuration, else the branch of the
//!    nearest pose the calibration saw, else the one a cell teaches);
//! 2. the **calibrated solution** `q_c`: the joints the calibrated model
//!    needs for the pose, `FK_cal(q_c)·tool = target`, by Newton from
//!    `q_n` (same branch);
//! 3. the **pose to command**: `FK_nom(q_c)·tool`. The nominal controller
//!    (with `tool` as its tool data) solves that pose back to exactly
//!    `q_c`, so the real robot, which the calibrated model describes,
//!    puts its TCP on the target.
//!
//! The TCP (`tool`, `flange_from_tcp`) is the calibrated sensor (the
//! result's hand-eye, printed as each controller's tool data by
//! [`tool`]), the flange, or a tool the user gives. A **joint target**
//! (`jointtarget`, `movej([…])`, `E6AXIS`, a FANUC position in joints)
//! is read as an offline-programmed target: the pose the nominal model
//! says those joints reach, `FK_nom(q_w)·tool`, is the pose wanted, and
//! the joints written are those the calibrated model needs for it
//! (Newton from `q_w`). A joint target taught on the robot already is
//! where the robot went, and is left as written with
//! [`JointTargets::Keep`].
//!
//! **Configuration.** The written configuration (RAPID `cf`, KUKA `S`/`T`,
//! FANUC `CONFIG`) is kept; when the calibrated solution lies across one
//! of its boundaries (a joint quadrant or turn, a sign) from the nominal
//! one, it is updated and the target carries a note ([`config`]).
//!
//! **Per target** ([`TargetReport`]): the correction (how far the pose to
//! command is from the target, mm and deg), the predicted 1σ residual
//! from `ml`'s covariance ([`uncertainty`]), and flags when the target
//! lies outside what the calibration saw ([`Flag`]): joints far from every
//! identify pose, the TCP's working point outside the box of the working
//! points at the identify poses (for the sensor, the identify sphere
//! positions), or σ above a tolerance. Flagged targets are compensated
//! and written like the others (the calibrated model is still the best
//! estimate there, and the correction is still most of the error) and
//! are listed; the command line's `--strict` refuses them. An unreachable
//! target is an error naming it, and then nothing is written.
//!
//! **The base frame.** Sphere data see distances only: the calibrated
//! model's base frame is the nominal one (joint 1's parameters are not
//! identified), so compensated targets are exact up to the one rigid
//! motion between the nominal and the real base frame, which a workpiece
//! frame (taught or measured) takes out anyway.
//!
//! **Where the calibration saw the robot**: the joints of its identify
//! and validate poses, which result files record (`pose_joints`), or the
//! session's for older results. Without them the branch is the one a
//! cell teaches, σ is not aligned and the joint-space flag is not raised.
//!
//! [`compensate`] runs over every target with a progress callback that
//! may cancel (a workbench job); [`compensate_file`] ([`entry`]) is the
//! one entry the command line and the workbench call (the TCP, the
//! targets read, the model, the compensation); [`study`] is the
//! validation in simulation of the README.

pub mod arms;
pub mod config;
pub mod entry;
mod region;
pub mod report;
pub mod study;
mod target;
pub mod tool;
pub mod tool_only;
pub mod uncertainty;

use nalgebra::{Isometry3, Vector3};

use self::arms::{Arms, BranchRule};
use self::region::Region;
use self::uncertainty::Predictor;
use crate::engine::base::robot::Robot;
use crate::engine::base::robot::ik::DOF;
use crate::engine::base::session::{Session, Use};
use crate::engine::calibrate::solve::Control;
use crate::engine::calibrate::solve::ml::covariance::ParameterCovariance;
use crate::engine::files::format::ResultFile;
use crate::engine::files::program::{PoseFile, RewriteError};

pub use self::entry::{
    CompensateFileError, CompensateRequest, Outcome, TcpSource, ToolOnlyOutcome, compensate_file,
    compensate_file_tool_only,
};
pub use self::report::Summary;

/// Default tolerance of the predicted σ (mm): a target whose predicted
/// residual exceeds it is flagged. Measured with [`study`] over seeds 1-6
/// (paper-like cells): targets within ±3° of the validate poses had σ up
/// to 0.20 mm; random targets over the arm's range with σ below 0.25 mm
/// all reached within 0.25 mm, and those above it within 1.5 σ.
pub const DEFAULT_SIGMA_TOLERANCE_MM: f64 = 0.25;

/// Default largest joint-space distance (deg, norm over the six joints,
/// each wrapped) from the nearest identify pose before a target is
/// flagged. Identify poses are sparse in joint space: over seeds 1-6 of
/// [`study`], targets within ±3° of the validate poses, compensated to
/// 0.1 mm, lay up to 84° from the nearest identify pose; the predicted σ
/// is the sharper criterion, this one catches other arm configurations.
pub const DEFAULT_FAR_JOINTS_DEG: f64 = 90.0;

/// Default margin (mm) around the box of the working points at the
/// identify poses (for the sensor: the identify sphere positions): a TCP
/// working point farther out than this is flagged. The identify
/// stations of a paper-like cell span ~320 × 480 × 360 mm; targets near
/// its validate poses came up to 142 mm outside that box (seeds 1-6 of
/// [`study`]), random targets over the arm's range mostly hundreds.
pub const DEFAULT_REGION_MARGIN_MM: f64 = 200.0;

/// A session's joints give back the result's base-frame centres (through
/// the calibrated model and hand-eye) to the rounding of the files, far
/// below this (mm); another session's do not, by millimetres at least.
const SAME_SESSION_MM: f64 = 1e-3;

/// The tool point (TCP) the targets are poses of.
#[derive(Debug, Clone, PartialEq)]
pub enum Tcp {
    /// The calibrated sensor: the result's hand-eye `flange_from_sensor`.
    Sensor,
    /// The flange (no tool).
    Flange,
    /// A tool of the user's, `flange_from_tcp` (mm).
    Tool(Isometry3<f64>),
}

impl Tcp {
    /// For people.
    #[must_use]
    pub fn describe(&self) -> &'static str {
        match self {
            Self::Sensor => "the calibrated sensor (the result's hand-eye)",
            Self::Flange => "the flange",
            Self::Tool(_) => "the tool given",
        }
    }
}

/// What to do with joint targets.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum JointTargets {
    /// The pose the nominal model gives those joints is the pose wanted
    /// (offline-programmed targets).
    #[default]
    Compensate,
    /// Leave them as written (taught on the robot).
    Keep,
}

/// How to compensate.
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    /// What joint targets mean.
    pub joint_targets: JointTargets,
    /// Flag a target whose predicted σ exceeds this, mm.
    pub sigma_tolerance_mm: f64,
    /// Flag a target farther than this from every identify pose, deg.
    pub far_joints_deg: f64,
    /// Flag a target whose working point is farther than this outside the
    /// box of the working points at the identify poses, mm.
    pub region_margin_mm: f64,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            joint_targets: JointTargets::Compensate,
            sigma_tolerance_mm: DEFAULT_SIGMA_TOLERANCE_MM,
            far_joints_deg: DEFAULT_FAR_JOINTS_DEG,
            region_margin_mm: DEFAULT_REGION_MARGIN_MM,
        }
    }
}

/// A target that cannot be compensated: its name, line and why.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("target {name} (line {line}): {message}")]
pub struct TargetFailure {
    /// The target's name.
    pub name: String,
    /// Its 1-based line.
    pub line: usize,
    /// What is wrong.
    pub message: String,
}

/// Most failed targets one message names; the rest are counted (the
/// message stays one readable line).
pub const MAX_NAMED_FAILURES: usize = 8;

/// The failed targets in one line: the one alone, or their count and the
/// first [`MAX_NAMED_FAILURES`].
fn failures_text(failures: &[TargetFailure]) -> String {
    if let [one] = failures {
        return one.to_string();
    }
    let mut text = format!("{} targets cannot be compensated: ", failures.len());
    let named: Vec<String> = failures
        .iter()
        .take(MAX_NAMED_FAILURES)
        .map(ToString::to_string)
        .collect();
    text.push_str(&named.join("; "));
    if failures.len() > MAX_NAMED_FAILURES {
        text.push_str(&format!(
            "; and {} more",
            failures.len() - MAX_NAMED_FAILURES
        ));
    }
    text
}

/// Why compensation failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CompensateError {
    /// The result calibrated no kinematic model (pose-only).
    #[error(
        "the result is pose-only: the sensor (hand-eye) was calibrated, the robot's kinematics were not, so there is no model to compensate targets with; install the calibrated sensor as the controller's tool data instead (`spherecal export-model RESULT --format tool --controller …`), or give --current-tool FILE (the tool the program was taught with) to rewrite the targets for the tool the controller holds now"
    )]
    PoseOnly,
    /// Not a 6-axis arm.
    #[error("the robot has {0} joints; target compensation solves 6-axis arms")]
    NotSixAxis(usize),
    /// The sensor of a fixed-sensor result asked for as the tool: it
    /// stands in the cell, not on the flange.
    #[error(
        "the result is of a fixed sensor (its hand_eye is base_from_sensor, the sensor's pose in the cell, not a tool on the flange): compensate for the flange or a tool file instead of the sensor"
    )]
    FixedSensor,
    /// The session given is not the result's.
    #[error("{0}")]
    Session(String),
    /// Targets that cannot be compensated (out of reach, a bad value):
    /// every one, in the order the robot goes to them, so a program is
    /// mended in one pass.
    #[error("{}", failures_text(.0))]
    Targets(Vec<TargetFailure>),
    /// The file could not be rewritten (an internal error).
    #[error("the targets could not be rewritten: {0}")]
    Rewrite(#[from] RewriteError),
    /// The caller cancelled.
    #[error("cancelled")]
    Cancelled,
}

/// A reason a target lies outside what the calibration saw.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Flag {
    /// Its joints are this far (deg) from every identify pose (limit).
    FarInJoints(f64, f64),
    /// Its working point is this far (mm) outside the identify box (limit).
    OutsideRegion(f64, f64),
    /// Its predicted σ (mm) exceeds the tolerance (mm).
    Uncertain(f64, f64),
}

impl Flag {
    /// For people: "42.3° from every identify pose (limit 40°)".
    #[must_use]
    pub fn describe(&self) -> String {
        match self {
            Self::FarInJoints(d, l) => {
                format!("joints {d:.1}° from every identify pose (limit {l}°)")
            }
            Self::OutsideRegion(d, l) => format!(
                "working point {d:.0} mm outside the box of the identify poses' working points (margin {l} mm)"
            ),
            Self::Uncertain(s, l) => format!("predicted σ {s:.3} mm above {l} mm"),
        }
    }
}

/// One compensated target.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetReport {
    /// Index into the file's targets.
    pub index: usize,
    /// Its name (`P[3]`, `p10`, a table's id).
    pub name: String,
    /// 1-based line.
    pub line: usize,
    /// A joint target.
    pub joints_target: bool,
    /// Compensated and written (false: a joint target kept).
    pub written: bool,
    /// The nominal solution of the pose wanted, deg.
    pub nominal_joints: [f64; DOF],
    /// The calibrated solution: the joints the robot is driven to, deg.
    pub joints: [f64; DOF],
    /// How the branch was chosen.
    pub branch: BranchRule,
    /// The TCP pose wanted, base frame, mm.
    pub wanted: Isometry3<f64>,
    /// The TCP pose to command (nominal model at `joints`, with the tool).
    pub commanded: Isometry3<f64>,
    /// `|commanded − wanted|` of the TCP position, mm.
    pub correction_mm: f64,
    /// Rotation from wanted to commanded, deg.
    pub correction_deg: f64,
    /// Largest joint change `|q_c − q_n|`, deg.
    pub joint_change_deg: f64,
    /// Predicted 1σ of the TCP position after compensation, mm (`ml`).
    pub sigma_mm: Option<f64>,
    /// Joint distance to the nearest identify pose, deg (when their joints are known).
    pub nearest_identify_deg: Option<f64>,
    /// How far the working point lies outside the identify box, mm (0 inside).
    pub outside_mm: f64,
    /// Why it is outside what the calibration saw.
    pub flags: Vec<Flag>,
    /// The numbers written, file units, one per span.
    pub values: Vec<f64>,
    /// The configuration written instead of the old one, when updated.
    pub config_update: Option<(String, String)>,
    /// What to know about this target (a configuration kept or updated).
    pub notes: Vec<String>,
}

/// How far [`compensate`] is: told after each target.
#[derive(Debug, Clone, PartialEq)]
pub struct CompensateProgress {
    /// Targets done.
    pub done: usize,
    /// Targets in all.
    pub total: usize,
    /// The target just done.
    pub target: String,
}

/// The compensated file.
#[derive(Debug, Clone, PartialEq)]
pub struct Compensation {
    /// The file's text with the positions (and updated configurations)
    /// replaced, every other byte kept.
    pub text: String,
    /// Per target, in the order the robot goes to them.
    pub targets: Vec<TargetReport>,
    /// Targets, largest correction, flagged.
    pub summary: Summary,
    /// What to know about the run as a whole.
    pub notes: Vec<String>,
}

/// What compensation needs of a calibration: the nominal and calibrated
/// arms, the TCP, the covariance and the region the calibration saw.
#[derive(Debug, Clone)]
pub struct Model {
    /// The two arms.
    pub arms: Arms,
    /// The TCP.
    pub tcp: Tcp,
    /// `flange_from_tcp` (mm).
    pub tool: Isometry3<f64>,
    predictor: Option<Predictor>,
    region: Region,
    /// What to know (a session that differs from the result, no covariance).
    pub notes: Vec<String>,
}

impl Model {
    /// The model of a result. The joints of the poses the calibration saw
    /// (for the branch choice and the joint-space flag) are the result's
    /// own record (`pose_joints`), else those of `session` (the result's
    /// session, for results written before the record).
    ///
    /// # Errors
    /// A result without a robot, not a 6-axis arm, or a session that is
    /// not the result's (none of the result's identify measurements in it).
    pub fn new(
        result: &ResultFile,
        session: Option<&Session>,
        tcp: Tcp,
    ) -> Result<Self, CompensateError> {
        let (Some(calibrated), Some(nominal)) = (result.robot.clone(), result.nominal()) else {
            return Err(CompensateError::PoseOnly);
        };
        if result.hand_eye_only() {
            return Err(CompensateError::PoseOnly);
        }
        if calibrated.dof() != DOF {
            return Err(CompensateError::NotSixAxis(calibrated.dof()));
        }
        if result.mount() == crate::engine::base::session::Mount::Fixed && tcp == Tcp::Sensor {
            return Err(CompensateError::FixedSensor);
        }
        let mut notes = Vec::new();
        // Where the calibration saw the robot: the result's own record of
        // the joints, else the session's.
        let mut joints: Vec<(String, [f64; DOF])> = result
            .pose_joints
            .iter()
            .filter_map(|(id, q)| Some((id.clone(), <[f64; DOF]>::try_from(q.as_slice()).ok()?)))
            .collect();
        if let Some(s) = session {
            let from_session = session_joints(result, s, &calibrated, &nominal, &mut notes)?;
            if joints.is_empty() {
                joints = from_session;
            }
        }
        let usage = |id: &str| {
            result
                .centres
                .iter()
                .find(|c| c.measurement == id)
                .map(|c| c.usage)
        };
        let poses: Vec<(String, [f64; DOF])> = joints
            .iter()
            .filter(|(id, _)| matches!(usage(id), Some(Use::Identify | Use::Validate)))
            .cloned()
            .collect();
        let identify: Vec<(String, [f64; DOF])> = joints
            .into_iter()
            .filter(|(id, _)| usage(id) == Some(Use::Identify))
            .collect();
        let pose_joints: Vec<[f64; DOF]> = poses.iter().map(|(_, q)| *q).collect();
        let arms = Arms::new(nominal, calibrated.clone(), poses)
            .ok_or(CompensateError::NotSixAxis(calibrated.dof()))?;
        let tool = match &tcp {
            Tcp::Sensor => result.hand_eye,
            Tcp::Flange => Isometry3::identity(),
            Tcp::Tool(t) => *t,
        };
        // A malformed covariance is as none: no σ, said below. A
        // posteriori: scaled by the result's variance factor, as
        // measuring's per-point σ.
        let covariance = ParameterCovariance::read_a_posteriori(&result.solver, DOF)
            .ok()
            .flatten();
        let predictor = covariance.as_ref().map(|c| {
            Predictor::new(
                c,
                calibrated.clone(),
                tool,
                tcp == Tcp::Sensor,
                &pose_joints,
            )
        });
        match &predictor {
            None => notes.push(format!(
                "the result's method ({}) reports no covariance: no predicted σ per target",
                result.solver.method()
            )),
            Some(p) if !p.aligned() => notes.push(
                "σ is not aligned (no poses of the calibration known): it includes the rigid motion of the whole region that a work frame takes out".to_string(),
            ),
            Some(_) => {}
        }
        let working_point = working_point(result, &tcp);
        // The box of the working points the calibration saw: at the
        // identify poses when their joints are known, else (for the
        // sensor) the identify sphere positions themselves.
        let seen = seen_points(
            result,
            &tcp,
            &identify,
            &calibrated,
            &tool,
            &working_point,
            &mut notes,
        );
        let region = Region::new(identify, &seen, working_point);
        Ok(Self {
            arms,
            tcp,
            tool,
            predictor,
            region,
            notes,
        })
    }

    /// The predicted 1σ (mm) of the TCP position at joints `q` after
    /// compensation, a posteriori (the result's covariance times its
    /// variance factor); `None` without a covariance.
    #[must_use]
    pub fn predicted_sigma(&self, q: &[f64; DOF]) -> Option<f64> {
        self.predictor.as_ref().map(|p| p.sigma(q))
    }

    /// Whether the joints of the identify poses are known (recorded in the
    /// result or from the session): the joint-space check is then made.
    #[must_use]
    pub fn has_identify_joints(&self) -> bool {
        self.region.has_joints()
    }
}

/// The joints of the result's measurements in `s` (the session given
/// with the result), checked to be the result's session: they must give
/// back the result's base-frame centres. Notes a session robot that
/// differs from the result's nominal model.
fn session_joints(
    result: &ResultFile,
    s: &Session,
    calibrated: &Robot,
    nominal: &Robot,
    notes: &mut Vec<String>,
) -> Result<Vec<(String, [f64; DOF])>, CompensateError> {
    let from_session: Vec<(String, [f64; DOF])> = result
        .centres
        .iter()
        .filter_map(|c| {
            let m = s.measurements.iter().find(|m| m.id == c.measurement)?;
            Some((
                c.measurement.clone(),
                <[f64; DOF]>::try_from(m.joints.as_slice()).ok()?,
            ))
        })
        .collect();
    // The session's joints, the calibrated model and hand-eye must
    // give back the result's own centres (base frame; the flange frame for
    // a fixed sensor).
    let est = crate::engine::calibrate::solve::estimate::Estimate {
        robot: calibrated.clone(),
        flange_from_sensor: result.hand_eye,
        mount: result.mount(),
    };
    let worst = from_session
        .iter()
        .filter_map(|(id, q)| {
            let c = result.centres.iter().find(|c| c.measurement == *id)?;
            let seen = est.station_from_sensor(&calibrated.base_from_flange(q))
                * nalgebra::Point3::from(Vector3::from(c.sensor));
            Some((seen.coords - Vector3::from(c.after)).norm())
        })
        .fold(0.0, f64::max);
    if from_session.is_empty() || worst > SAME_SESSION_MM {
        return Err(CompensateError::Session(format!(
            "the session {:?} {}: it is not the session the result was calibrated from",
            s.name,
            if from_session.is_empty() {
                "has none of the result's measurements with joints".to_string()
            } else {
                format!(
                    "does not give back the result's centres (its joints put one {worst:.3} mm away)"
                )
            }
        )));
    }
    let same = s.robot.joints.len() == nominal.joints.len()
        && s.robot
            .joints
            .iter()
            .zip(&nominal.joints)
            .all(|(a, b)| (0..5).all(|k| (a.get(k) - b.get(k)).abs() < 1e-6));
    if !same {
        notes.push(
            "the session's robot differs from the result's nominal model (calibrated minus joint errors): the result's is used".to_string(),
        );
    }
    Ok(from_session)
}

/// The working point in the TCP frame (mm): the mean identify centre
/// (sensor frame) for the sensor, else the TCP's origin.
fn working_point(result: &ResultFile, tcp: &Tcp) -> Vector3<f64> {
    match tcp {
        Tcp::Sensor => {
            let sensor: Vec<Vector3<f64>> = result
                .centres
                .iter()
                .filter(|c| c.usage == Use::Identify)
                .map(|c| Vector3::from(c.sensor))
                .collect();
            sensor.iter().sum::<Vector3<f64>>() / sensor.len().max(1) as f64
        }
        _ => Vector3::zeros(),
    }
}

/// The working points the calibration saw (base frame, mm): at the
/// identify poses when their joints are known, else (for the sensor) the
/// identify sphere positions themselves; none otherwise, with a note.
fn seen_points(
    result: &ResultFile,
    tcp: &Tcp,
    identify: &[(String, [f64; DOF])],
    calibrated: &Robot,
    tool: &Isometry3<f64>,
    working_point: &Vector3<f64>,
    notes: &mut Vec<String>,
) -> Vec<Vector3<f64>> {
    if identify.is_empty() {
        if *tcp == Tcp::Sensor {
            result
                .centres
                .iter()
                .filter(|c| c.usage == Use::Identify)
                .map(|c| Vector3::from(c.after))
                .collect()
        } else {
            notes.push(
            "the region is not checked in the base frame: without the joints of the calibration's poses, where a TCP other than the sensor was is not known".to_string(),
        );
            Vec::new()
        }
    } else {
        identify
            .iter()
            .map(|(_, q)| {
                (calibrated.base_from_flange(q) * tool * nalgebra::Point3::from(*working_point))
                    .coords
            })
            .collect()
    }
}

/// Compensates every target of `file` that the robot goes to (in that
/// order; all of them when the file has no motion instructions), calling
/// `progress` after each; it may cancel.
///
/// # Errors
/// The targets that cannot be compensated (unreachable, a bad value; all
/// of them, after every target was tried), [`CompensateError::Cancelled`],
/// or a rewrite that fails.
pub fn compensate(
    model: &Model,
    file: &PoseFile,
    options: &Options,
    progress: &mut dyn FnMut(&CompensateProgress) -> Control,
) -> Result<Compensation, CompensateError> {
    let total = file.order.len();
    let mut targets = Vec::with_capacity(total);
    let mut failed = Vec::new();
    for (done, &index) in file.order.iter().enumerate() {
        let name = match target::compensate_target(model, file, index, options) {
            Ok(report) => {
                let name = report.name.clone();
                targets.push(report);
                name
            }
            Err(failure) => {
                let name = failure.name.clone();
                failed.push(failure);
                name
            }
        };
        if progress(&CompensateProgress {
            done: done + 1,
            total,
            target: name,
        }) == Control::Cancel
        {
            return Err(CompensateError::Cancelled);
        }
    }
    if !failed.is_empty() {
        return Err(CompensateError::Targets(failed));
    }
    let edits: Vec<(usize, Vec<String>)> = targets
        .iter()
        .filter(|t| t.written)
        .map(|t| (t.index, target::written_numbers(file, t)))
        .collect();
    let configs: Vec<(usize, String)> = targets
        .iter()
        .filter_map(|t| {
            t.config_update
                .as_ref()
                .map(|(_, new)| (t.index, new.clone()))
        })
        .collect();
    let text = file
        .rewritten_with_config(&edits, &configs)
        .map_err(CompensateError::Rewrite)?;
    let mut notes = model.notes.clone();
    if !model.has_identify_joints() {
        notes.push(
            "the result records no joints of its poses (written before spherecal recorded them, or pose-only) and no session was given (--session): the branch is the one a cell teaches, the joints are not checked against the identify poses, and the working point is checked against the box of the identify sphere positions (for the sensor)".to_string(),
        );
    }
    if file.order.len() < file.targets.len() {
        notes.push(format!(
            "{} of {} positions are never moved to and are left as written",
            file.targets.len() - file.order.len(),
            file.targets.len()
        ));
    }
    let summary = Summary::of(&targets);
    Ok(Compensation {
        text,
        targets,
        summary,
        notes,
    })
}
