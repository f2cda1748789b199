//! A simulated session of a measurement plan ([`plan`](crate::engine::tools::plan)'s
//! poses): the poses run on a true robot, as planned or touched up.

use std::collections::HashSet;

use nalgebra::{Isometry3, Point3, Vector3};

use super::config::{InitialHandEye, check, validate_config};
use super::config::{SimConfig, SimError};
use super::poses::{IK_CHECK_TOLERANCE, Pose};
use super::truth::{OrderedMap, TRUTH_FORMAT, TRUTH_VERSION, Truth, TruthRobot};
use super::{STREAM_NOISE, record, reference_distances};
use crate::engine::base::cell::random::stream;
use crate::engine::base::cell::sensor::paper_initial_hand_eye;
use crate::engine::base::geometry::rows_from_isometry;
use crate::engine::base::robot::Robot;
use crate::engine::base::robot::ik::{Chain, DOF};
use crate::engine::base::session::{Session, Use};

/// Smallest cut angle (deg) at which a pose of a plan still counts as
/// seeing the sphere on the true robot: below it the centre is within
/// `R · sin 5°` ≈ 1.7 mm of the laser plane and its side is a guess.
pub(super) const PLAN_MIN_CUT_DEG: f64 = 5.0;
/// Largest usable cut angle (deg): beyond it the stripe circle radius
/// falls under `R · cos 80°` ≈ 3.3 mm and `t = sqrt(R² − r²)` loses all
/// precision (shared/paper/NOTES.md, "The cut angle matters").
pub(super) const PLAN_MAX_CUT_DEG: f64 = 80.0;

/// One commanded pose of a measurement plan (e.g. [`plan`](crate::engine::tools::plan::plan)'s
/// CSV), for [`simulate_plan`].
#[derive(Debug, Clone, PartialEq)]
pub struct PlanPose {
    /// Measurement id, unique in the plan.
    pub id: String,
    /// Station id (the sphere's place).
    pub station: String,
    /// FORMAT.md `use`.
    pub usage: Use,
    /// Planned side of the laser plane, +1 or −1.
    pub side: i8,
    /// Commanded joint readings, deg: the robot goes exactly there.
    pub joints: Vec<f64>,
    /// Where the plan expects the sphere centre in the sensor frame (mm),
    /// under its nominal model and hand-eye guess.
    pub centre_in_sensor: [f64; 3],
}

/// Simulates a plan's poses on a true robot: what a cell records when the
/// controller drives the **nominal** model's joint targets of `poses`.
///
/// - The true robot is `nominal` plus `config`'s kinematic errors (error
///   stream of `config.seed`), the true hand-eye is `flange_from_sensor`.
///   `config.robot`, the workspace and the pose settings are not used.
/// - The robot reaches the commanded joints exactly (they are the actual
///   joints of the truth), or, with [`PlanExecution::TouchUp`], the
///   nearest joints that see the sphere at the planned centre; the
///   readings get `joint_noise`.
/// - Each station's sphere is where the true robot sees the planned
///   sensor-frame centres on average (the mean over the station's poses of
///   `true_fk(q) · flange_from_sensor · centre_in_sensor`): the operator
///   put the sphere where the robot actually looks. Each pose then sees it
///   at its own sensor-frame centre, which differs from the planned one by
///   the true robot's error; that centre must stay within the usable cut
///   ([`SimError::PlanMiss`]).
/// - Stripes (or centres), noise and the reference distances between
///   consecutive validate stations (in order of first appearance) are made
///   as in [`simulate`](crate::engine::tools::simulate::simulate); measurement ids are the plan's.
///
/// # Errors
/// [`SimError::InvalidConfig`] for a bad setting, a robot that is not
/// 6-axis, a malformed pose (side, joint count, duplicate id),
/// [`SimError::PlanMiss`] when a pose does not see the sphere.
pub fn simulate_plan(
    config: &SimConfig,
    nominal: &Robot,
    flange_from_sensor: &Isometry3<f64>,
    poses: &[PlanPose],
    execution: PlanExecution,
) -> Result<(Session, Truth), SimError> {
    let per_station = station_counts(poses);
    let mut echoed = echoed_config(config, poses, &per_station);
    validate_config(&echoed)?;
    check_poses(nominal, poses)?;
    let mut rng_noise = stream(config.seed, STREAM_NOISE);
    let (true_robot, errors) = super::with_errors(config, nominal);
    let base_from_sensor = |q: &[f64]| true_robot.base_from_flange(q) * flange_from_sensor;
    // Each station: the mean of where the true robot sees the planned centres.
    let stations: Vec<(String, Vector3<f64>)> = per_station
        .iter()
        .map(|(id, n)| {
            let sum: Vector3<f64> = poses
                .iter()
                .filter(|p| p.station == *id)
                .map(|p| (base_from_sensor(&p.joints) * Point3::from(p.centre_in_sensor)).coords)
                .sum();
            (id.clone(), sum / *n as f64)
        })
        .collect();
    let simulated = executed_poses(
        config,
        nominal,
        &true_robot,
        flange_from_sensor,
        poses,
        &stations,
        execution,
    )?;
    let default_side = 1;
    let (mut measurements, mut truths) = record(config, &simulated, default_side, &mut rng_noise);
    for ((m, t), p) in measurements.iter_mut().zip(truths.iter_mut()).zip(poses) {
        m.id.clone_from(&p.id);
        t.0.clone_from(&p.id);
    }
    let validate: Vec<(String, Vector3<f64>)> = stations
        .iter()
        .filter(|(id, _)| {
            poses
                .iter()
                .any(|p| p.station == *id && p.usage == Use::Validate)
        })
        .cloned()
        .collect();
    let (reference_distances, true_distances) =
        reference_distances(config, &validate, &mut rng_noise);
    let name = config
        .name
        .clone()
        .unwrap_or_else(|| format!("simulated plan, {}, seed {}", nominal.name, config.seed));
    let hand_eye = match config.initial_hand_eye {
        InitialHandEye::None => None,
        InitialHandEye::Paper => Some(paper_initial_hand_eye()),
        InitialHandEye::Truth => Some(*flange_from_sensor),
    };
    let session = Session {
        reference_distances,
        ..super::simulated_session(&name, nominal, config, default_side, hand_eye, measurements)
    };
    echoed.name = Some(name.clone());
    let truth = Truth {
        format: TRUTH_FORMAT.to_owned(),
        version: TRUTH_VERSION,
        session: name,
        config: echoed,
        robot: TruthRobot::from_robot(&true_robot),
        nominal: TruthRobot::from_robot(nominal),
        joint_errors: errors,
        hand_eye: rows_from_isometry(flange_from_sensor),
        stations: OrderedMap(
            stations
                .iter()
                .map(|(id, p)| (id.clone(), [p.x, p.y, p.z]))
                .collect(),
        ),
        true_distances,
        measurements: OrderedMap(truths),
    };
    Ok((session, truth))
}

/// The plan's stations in order of first appearance, with their pose
/// counts.
fn station_counts(poses: &[PlanPose]) -> Vec<(String, usize)> {
    let mut per_station: Vec<(String, usize)> = Vec::new();
    for p in poses {
        match per_station.iter_mut().find(|(s, _)| *s == p.station) {
            Some((_, n)) => *n += 1,
            None => per_station.push((p.station.clone(), 1)),
        }
    }
    per_station
}

/// The configuration the truth file echoes: the plan's counts of poses
/// and stations, no workspace.
fn echoed_config(
    config: &SimConfig,
    poses: &[PlanPose],
    per_station: &[(String, usize)],
) -> SimConfig {
    let count = |usage: Use| poses.iter().filter(|p| p.usage == usage).count();
    let smallest_station = poses
        .iter()
        .filter(|p| matches!(p.usage, Use::Identify | Use::Validate))
        .filter_map(|p| per_station.iter().find(|(s, _)| *s == p.station))
        .map(|(_, n)| *n)
        .min()
        .unwrap_or(2);
    SimConfig {
        n_translation: count(Use::Translation),
        n_rotation: count(Use::Rotation),
        n_identify: count_stations(poses, Use::Identify),
        n_validate: count_stations(poses, Use::Validate),
        poses_per_station: smallest_station,
        workspace: None,
        ..config.clone()
    }
}

/// Checks the robot (6-axis) and every pose: a unique id, one finite
/// value per joint, a side of ±1, a finite planned centre.
fn check_poses(nominal: &Robot, poses: &[PlanPose]) -> Result<(), SimError> {
    let dof = nominal.dof();
    check(dof == DOF, || {
        format!(
            "the simulator drives 6-axis arms, {} has {dof} joints",
            nominal.name
        )
    })?;
    check(!poses.is_empty(), || "the plan has no poses".to_owned())?;
    let mut ids = HashSet::new();
    for p in poses {
        check(ids.insert(p.id.as_str()), || {
            format!("pose id {} is given twice", p.id)
        })?;
        check(p.joints.len() == dof, || {
            format!(
                "pose {}: {} joint values, the robot has {dof}",
                p.id,
                p.joints.len()
            )
        })?;
        check(p.joints.iter().all(|v| v.is_finite()), || {
            format!("pose {}: a joint value is not finite", p.id)
        })?;
        check(p.side == 1 || p.side == -1, || {
            format!("pose {}: side must be +1 or -1, found {}", p.id, p.side)
        })?;
        check(p.centre_in_sensor.iter().all(|v| v.is_finite()), || {
            format!("pose {}: the planned centre is not finite", p.id)
        })?;
    }
    Ok(())
}

/// The poses as executed by the true robot (the `nominal` one with its
/// errors; `stations`: where it sees
/// the sphere, base frame, mm): the planned joints, or touched up to the
/// planned centre; each seeing the sphere within the usable cut.
fn executed_poses(
    config: &SimConfig,
    nominal: &Robot,
    true_robot: &Robot,
    flange_from_sensor: &Isometry3<f64>,
    poses: &[PlanPose],
    stations: &[(String, Vector3<f64>)],
    execution: PlanExecution,
) -> Result<Vec<Pose>, SimError> {
    let base_from_sensor = |q: &[f64]| true_robot.base_from_flange(q) * flange_from_sensor;
    let radius = config.diameter / 2.0;
    let (lo, hi) = (
        radius * PLAN_MIN_CUT_DEG.to_radians().sin(),
        radius * PLAN_MAX_CUT_DEG.to_radians().sin(),
    );
    let chain = Chain::new(true_robot)
        .ok_or_else(|| SimError::InvalidConfig(format!("{} is not a 6-axis arm", nominal.name)))?;
    let mut simulated = Vec::with_capacity(poses.len());
    for p in poses {
        let station = stations
            .iter()
            .find(|(id, _)| *id == p.station)
            .map_or_else(Vector3::zeros, |(_, c)| *c);
        let mut joints = [0.0; DOF];
        joints.copy_from_slice(&p.joints);
        if execution == PlanExecution::TouchUp {
            let planned = Vector3::from(p.centre_in_sensor);
            joints = touch_up(&chain, flange_from_sensor, &joints, &planned, &station)
                .filter(|q| {
                    let seen = base_from_sensor(q) * Point3::from(planned);
                    (seen.coords - station).norm() < IK_CHECK_TOLERANCE
                })
                .ok_or_else(|| {
                    SimError::InvalidConfig(format!(
                        "pose {}: the touch-up found no joints that see the sphere at the planned centre",
                        p.id
                    ))
                })?;
        }
        let centre = base_from_sensor(&joints)
            .inverse_transform_point(&Point3::from(station))
            .coords;
        let x = centre.x * f64::from(p.side);
        if !(lo..=hi).contains(&x) {
            return Err(SimError::PlanMiss {
                id: p.id.clone(),
                x: centre.x,
                side: p.side,
                lo,
                hi,
            });
        }
        simulated.push(Pose {
            station: p.station.clone(),
            usage: p.usage,
            side: p.side,
            joints,
            centre_in_sensor: centre,
        });
    }
    Ok(simulated)
}

/// How the cell executes a plan in [`simulate_plan`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PlanExecution {
    /// The robot goes to the plan's joints exactly (a program of joint
    /// targets run as written); each pose sees the sphere wherever the
    /// true robot's error puts it, within the usable cut or
    /// [`SimError::PlanMiss`].
    #[default]
    AsPlanned,
    /// Each pose is touched up, as when teaching (the paper's teach mode):
    /// the smallest joint change (least squares in joint space) that puts
    /// the sphere at the planned sensor-frame centre on the true robot.
    /// The recorded joints are the touched-up ones.
    TouchUp,
}

/// Touch-up iteration bound: from the plan's joints the correction is a
/// fraction of a degree and Gauss-Newton converges in 3-5 steps.
pub(super) const TOUCH_UP_MAX_ITER: usize = 30;
/// Touch-up convergence, mm (as the IK's position tolerance).
pub(super) const TOUCH_UP_TOLERANCE_MM: f64 = 1e-9;

/// The joints nearest `start` (deg, least-norm Gauss-Newton steps) at
/// which `chain` sees `station` (base, mm) at `centre` (sensor, mm).
pub(super) fn touch_up(
    chain: &Chain,
    flange_from_sensor: &Isometry3<f64>,
    start: &[f64; DOF],
    centre: &Vector3<f64>,
    station: &Vector3<f64>,
) -> Option<[f64; DOF]> {
    let in_flange = (flange_from_sensor * Point3::from(*centre)).coords;
    let mut q = *start;
    for _ in 0..TOUCH_UP_MAX_ITER {
        let (pose, jac) = chain.pose_and_jacobian(&q);
        let point = (pose * Point3::from(in_flange)).coords;
        let r = point - station;
        if r.norm() < TOUCH_UP_TOLERANCE_MM {
            return Some(q);
        }
        // Velocity of the point: v + ω × (point − flange origin).
        let lever = point - pose.translation.vector;
        let jp = nalgebra::Matrix3x6::from_fn(|i, j| {
            let w = Vector3::new(jac[(3, j)], jac[(4, j)], jac[(5, j)]);
            jac[(i, j)] + w.cross(&lever)[i]
        });
        let step = jp.transpose() * (jp * jp.transpose()).try_inverse()? * (-r);
        for (qi, s) in q.iter_mut().zip(step.iter()) {
            *qi += s.to_degrees();
        }
    }
    None
}

/// Number of distinct stations with measurements of `usage`.
pub(super) fn count_stations(poses: &[PlanPose], usage: Use) -> usize {
    let mut seen: Vec<&str> = Vec::new();
    for p in poses.iter().filter(|p| p.usage == usage) {
        if !seen.contains(&p.station.as_str()) {
            seen.push(&p.station);
        }
    }
    seen.len()
}
