//! The simulator's poses: sphere centres placed in the sensor frame at the
//! cut angle, and the robot poses of the true model that see them (inverse
//! kinematics on every branch, within the cell's limits), station by
//! station and group by group.

use std::f64::consts::PI;
use std::ops::ControlFlow;

use nalgebra::{Isometry3, Point3, UnitQuaternion, Vector3};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

use super::config::{SideChoice, SimConfig, SimError};
use crate::engine::base::cell::approach::{
    flange_target, mean_approach, random_orientation, turned_orientation,
};
use crate::engine::base::cell::branch;
use crate::engine::base::cell::random::uniform;
use crate::engine::base::cell::workspace::{Workspace, identify_stations, validate_stations};
use crate::engine::base::geometry::wrap_deg;
use crate::engine::base::robot::ik::{Chain, DOF};
use crate::engine::base::robot::{JointLimit, Robot, RobotChoice};
use crate::engine::base::session::Use;

/// Sensor-frame centre y spread (mm): centres are drawn in `±2` mm, as
/// NOTES.md describes the paper's measurements.
pub(super) const CENTRE_Y_SPREAD: f64 = 2.0;
/// Sensor-frame centre z spread (mm): `±3` mm, NOTES.md.
pub(super) const CENTRE_Z_SPREAD: f64 = 3.0;

/// Orientations tried for one pose before the station is declared
/// unreachable. Reachable cones succeed within a few tries; 400 keeps a
/// bad workspace from looping long (each try is at most a few IK runs).
pub(super) const MAX_POSE_ATTEMPTS: usize = 400;

/// Two rotation measurements differ in orientation by at least this much
/// (deg), so eq. 8-9 get distinct rows.
pub(super) const MIN_ROTATION_SEPARATION_DEG: f64 = 15.0;

/// Sides for the measurements of one station: balanced and shuffled for
/// `mixed` (an odd one out takes a random side).
pub(super) fn station_sides(rng: &mut ChaCha8Rng, n: usize, choice: SideChoice) -> Vec<i8> {
    match choice {
        SideChoice::Plus => vec![1; n],
        SideChoice::Minus => vec![-1; n],
        SideChoice::Mixed => {
            let mut sides: Vec<i8> = (0..n).map(|k| if k % 2 == 0 { 1 } else { -1 }).collect();
            if n % 2 == 1 && rng.random::<bool>() {
                sides[n - 1] = -1;
            }
            // Fisher-Yates, drawing explicitly so the stream is stable.
            for i in (1..n).rev() {
                let j = rng.random_range(0..=i);
                sides.swap(i, j);
            }
            sides
        }
    }
}

/// The sphere seen through the reference forward kinematics
/// ([`Robot::base_from_flange`]) must agree with the station to this
/// (mm): a guard on the fast [`Chain`].
pub(super) const IK_CHECK_TOLERANCE: f64 = 1e-7;

/// One planned pose before noise.
#[derive(Debug, Clone)]
pub(super) struct Pose {
    pub(super) station: String,
    pub(super) usage: Use,
    pub(super) side: i8,
    pub(super) joints: [f64; DOF],
    pub(super) centre_in_sensor: Vector3<f64>,
}

/// Places sphere centres in the sensor frame and solves the robot poses
/// that see them, on the true model.
pub(super) struct Planner<'a> {
    pub(super) config: &'a SimConfig,
    pub(super) robot: &'a Robot,
    pub(super) chain: Chain,
    pub(super) limits: Vec<JointLimit>,
    pub(super) choice: RobotChoice,
    pub(super) flange_from_sensor: Isometry3<f64>,
    pub(super) workspace: Workspace,
    /// Nominal theta of joint 5 (deg): the wrist angle is `q5 + theta5`.
    pub(super) wrist_offset: f64,
}

impl Planner<'_> {
    fn radius(&self) -> f64 {
        self.config.diameter / 2.0
    }

    /// A sensor-frame centre on `side`: cut angle with jitter, y and z in
    /// [`CENTRE_Y_SPREAD`], [`CENTRE_Z_SPREAD`].
    fn sample_centre(&self, rng: &mut ChaCha8Rng, side: i8) -> Vector3<f64> {
        let x = self.sample_x(rng, side);
        let y = uniform(rng, -CENTRE_Y_SPREAD, CENTRE_Y_SPREAD);
        let z = uniform(rng, -CENTRE_Z_SPREAD, CENTRE_Z_SPREAD);
        Vector3::new(x, y, z)
    }

    /// The centre of an identify or validate measurement: over the range
    /// when the configuration spreads the sphere, else
    /// [`Self::sample_centre`].
    fn station_centre(&self, rng: &mut ChaCha8Rng, side: i8) -> Vector3<f64> {
        match (self.config.spread, self.config.range) {
            (true, Some(r)) => {
                let x = self.sample_x(rng, side);
                Vector3::new(
                    x,
                    uniform(rng, r.y[0], r.y[1]),
                    uniform(rng, r.z[0], r.z[1]),
                )
            }
            _ => self.sample_centre(rng, side),
        }
    }

    fn sample_x(&self, rng: &mut ChaCha8Rng, side: i8) -> f64 {
        let c = self.config;
        let cut = uniform(rng, c.cut_angle - c.cut_jitter, c.cut_angle + c.cut_jitter);
        f64::from(side) * self.radius() * cut.to_radians().sin()
    }

    /// The mean approach at `station` from the workspace's eye point
    /// ([`mean_approach`]).
    fn mean_approach(&self, station: &Vector3<f64>) -> Vector3<f64> {
        mean_approach(station, &Vector3::from(self.workspace.eye))
    }

    /// Arm guesses `(q1, q2, q3)` (deg) for a flange target: the cell's
    /// ([`branch::arm_guesses`]).
    fn arm_guesses(&self, target: &Isometry3<f64>) -> Vec<[f64; 3]> {
        branch::arm_guesses(self.choice, target)
    }

    /// How much a wrist solution is disliked (lower first): the cell's
    /// ([`branch::wrist_dislike`]).
    fn wrist_dislike(&self, q: &[f64; DOF]) -> f64 {
        branch::wrist_dislike(self.choice, q, self.wrist_offset)
    }

    /// Joint angles (deg) that put the sphere at `station` (base) and at
    /// `centre_in_sensor` with the flange rotation `rotation`; `None` when
    /// no start converges within the planning limits and away from the
    /// wrist singularity. `hint` (the solution of a nearby pose with the
    /// same orientation) is tried first, then each arm guess (placed on the
    /// wrist centre when the wrist is spherical) with both wrist solutions,
    /// the preferred one ([`Self::wrist_dislike`]) first. Starts are built
    /// lazily: the first usually succeeds.
    fn solve(
        &self,
        station: &Vector3<f64>,
        rotation: &UnitQuaternion<f64>,
        centre_in_sensor: &Vector3<f64>,
        hint: Option<&[f64; DOF]>,
    ) -> Option<[f64; DOF]> {
        let centre_in_flange = self.flange_from_sensor * Point3::from(*centre_in_sensor);
        let target = flange_target(
            station,
            rotation,
            &self.flange_from_sensor,
            centre_in_sensor,
        );
        let min_wrist = self.config.min_wrist_angle.to_radians().sin();
        // Readings are moved by whole turns into (−180, 180] (the same
        // pose, tidier numbers) before the limits are checked.
        let attempt = |start: &[f64; DOF]| -> Option<[f64; DOF]> {
            let q = self.chain.inverse_kinematics(&target, start)?.map(wrap_deg);
            let in_limits = q
                .iter()
                .zip(&self.limits)
                .all(|(v, l)| *v >= l.min && *v <= l.max);
            let wrist = (q[4] + self.wrist_offset).to_radians().sin().abs();
            // The reference model agrees (guards the fast chain).
            let seen = self.robot.base_from_flange(&q) * centre_in_flange;
            let agrees = (seen.coords - station).norm() < IK_CHECK_TOLERANCE;
            (in_limits && wrist >= min_wrist && agrees).then_some(q)
        };
        if let Some(q) = hint.and_then(attempt) {
            return Some(q);
        }
        let guesses = self.arm_guesses(&target);
        let dislike = |q: &[f64; DOF]| self.wrist_dislike(q);
        self.chain
            .search(&target, &guesses, &dislike, |start| match attempt(start) {
                Some(q) => ControlFlow::Break(q),
                None => ControlFlow::Continue(()),
            })
    }

    /// `n` poses seeing `station` from random orientations in the cone.
    fn station_poses(
        &self,
        rng: &mut ChaCha8Rng,
        id: &str,
        station: &Vector3<f64>,
        usage: Use,
        n: usize,
    ) -> Result<Vec<Pose>, SimError> {
        let mean = self.mean_approach(station);
        let cone = self.config.cone_angle.to_radians();
        let sides = station_sides(rng, n, self.config.side);
        let mut poses: Vec<Pose> = Vec::with_capacity(n);
        for side in sides {
            let mut found = None;
            for _ in 0..MAX_POSE_ATTEMPTS {
                let centre = self.station_centre(rng, side);
                let rotation = random_orientation(rng, &mean, cone);
                if let Some(q) = self.solve(station, &rotation, &centre, None) {
                    found = Some((q, centre));
                    break;
                }
            }
            let (joints, centre_in_sensor) = found.ok_or_else(|| unreachable(id, station))?;
            poses.push(Pose {
                station: id.to_owned(),
                usage,
                side,
                joints,
                centre_in_sensor,
            });
        }
        Ok(poses)
    }

    /// The translation measurements (one orientation, flange moved in
    /// directions spread over the sensor's y-z plane) and the flange
    /// rotation they share.
    fn translation_poses(
        &self,
        rng: &mut ChaCha8Rng,
        id: &str,
        station: &Vector3<f64>,
    ) -> Result<(Vec<Pose>, UnitQuaternion<f64>), SimError> {
        let c = self.config;
        let mean = self.mean_approach(station);
        // The reference orientation stays near the middle of the cone so
        // the rotations about it remain reachable.
        let cone = c.cone_angle.to_radians() / 2.0;
        let n = c.n_translation;
        for _ in 0..MAX_POSE_ATTEMPTS {
            let rotation = random_orientation(rng, &mean, cone);
            let side = station_sides(rng, 1, c.side)[0];
            let first = self.sample_centre(rng, side);
            let phase = 2.0 * PI * rng.random::<f64>();
            // Directions 120° apart for 4 measurements; 90° for 3 so the
            // two displacements are not collinear.
            let step = if n >= 4 {
                2.0 * PI / (n - 1) as f64
            } else {
                PI / 2.0
            };
            let mut centres = vec![first];
            for k in 1..n {
                let rho = uniform(rng, c.translation_min, c.translation_max);
                let angle = phase + step * (k - 1) as f64;
                let x = self.sample_x(rng, side);
                centres.push(Vector3::new(
                    x,
                    first.y + rho * angle.cos(),
                    first.z + rho * angle.sin(),
                ));
            }
            let mut poses = Vec::with_capacity(n);
            let mut hint: Option<[f64; DOF]> = None;
            for centre in centres {
                let Some(q) = self.solve(station, &rotation, &centre, hint.as_ref()) else {
                    break;
                };
                hint = Some(q);
                poses.push(Pose {
                    station: id.to_owned(),
                    usage: Use::Translation,
                    side,
                    joints: q,
                    centre_in_sensor: centre,
                });
            }
            if poses.len() == n {
                return Ok((poses, rotation));
            }
        }
        Err(unreachable(id, station))
    }

    /// The rotation measurements: the reference orientation turned by
    /// `rotation_min..rotation_max` about random axes, each at least
    /// [`MIN_ROTATION_SEPARATION_DEG`] from the others.
    fn rotation_poses(
        &self,
        rng: &mut ChaCha8Rng,
        id: &str,
        station: &Vector3<f64>,
        reference: &UnitQuaternion<f64>,
    ) -> Result<Vec<Pose>, SimError> {
        let c = self.config;
        let sides = station_sides(rng, c.n_rotation, c.side);
        let mut poses: Vec<Pose> = Vec::with_capacity(c.n_rotation);
        let mut rotations: Vec<UnitQuaternion<f64>> = Vec::new();
        for side in sides {
            let mut found = None;
            for _ in 0..MAX_POSE_ATTEMPTS {
                let rotation = turned_orientation(rng, reference, c.rotation_min, c.rotation_max);
                let centre = self.sample_centre(rng, side);
                let distinct = rotations
                    .iter()
                    .all(|r| r.angle_to(&rotation) >= MIN_ROTATION_SEPARATION_DEG.to_radians());
                if !distinct {
                    continue;
                }
                if let Some(q) = self.solve(station, &rotation, &centre, None) {
                    found = Some((q, centre, rotation));
                    break;
                }
            }
            let (joints, centre_in_sensor, rotation) =
                found.ok_or_else(|| unreachable(id, station))?;
            rotations.push(rotation);
            poses.push(Pose {
                station: id.to_owned(),
                usage: Use::Rotation,
                side,
                joints,
                centre_in_sensor,
            });
        }
        Ok(poses)
    }
}

pub(super) fn unreachable(id: &str, station: &Vector3<f64>) -> SimError {
    SimError::Unreachable(unreachable_after(
        id.to_owned(),
        [station.x, station.y, station.z],
        MAX_POSE_ATTEMPTS,
    ))
}

/// The simulator's refusal of a station (or a scan pose) after
/// `orientations` tried.
pub(super) fn unreachable_after(
    station: String,
    position: [f64; 3],
    orientations: usize,
) -> crate::engine::base::cell::Unreachable {
    crate::engine::base::cell::Unreachable {
        station,
        position,
        orientations,
        why: format!(
            "no pose found in {orientations} orientations; use a smaller workspace or cone"
        ),
    }
}

/// Stations and planned poses (from the geometry stream).
pub(super) struct Plan {
    /// Every station in file order, base frame, mm.
    pub(super) stations: Vec<(String, Vector3<f64>)>,
    /// Every measurement's pose, in session order.
    pub(super) poses: Vec<Pose>,
    /// The validate stations, in order.
    pub(super) validate: Vec<Vector3<f64>>,
}

/// Places the stations and solves every pose: `P0` (translations, then
/// rotations), the identify stations, the validate stations.
pub(super) fn plan(planner: &Planner<'_>, rng: &mut ChaCha8Rng) -> Result<Plan, SimError> {
    let config = planner.config;
    let workspace = &planner.workspace;
    let mut stations: Vec<(String, Vector3<f64>)> = Vec::new();
    let mut poses: Vec<Pose> = Vec::new();
    if config.n_translation + config.n_rotation > 0 {
        let p0 = workspace.centre();
        stations.push(("P0".to_owned(), p0));
        let (translations, reference) = if config.n_translation > 0 {
            planner.translation_poses(rng, "P0", &p0)?
        } else {
            let cone = config.cone_angle.to_radians() / 2.0;
            let mean = planner.mean_approach(&p0);
            (Vec::new(), random_orientation(rng, &mean, cone))
        };
        poses.extend(translations);
        poses.extend(planner.rotation_poses(rng, "P0", &p0, &reference)?);
    }
    let identify = identify_stations(rng, workspace, config.n_identify);
    for (k, p) in identify.iter().enumerate() {
        let id = format!("P{}", k + 1);
        let n = config.poses_per_station;
        poses.extend(planner.station_poses(rng, &id, p, Use::Identify, n)?);
        stations.push((id, *p));
    }
    let validate = validate_stations(rng, workspace, config.n_validate);
    for (k, p) in validate.iter().enumerate() {
        let id = format!("V{}", k + 1);
        let n = config.poses_per_station;
        poses.extend(planner.station_poses(rng, &id, p, Use::Validate, n)?);
        stations.push((id, *p));
    }
    Ok(Plan {
        stations,
        poses,
        validate,
    })
}
