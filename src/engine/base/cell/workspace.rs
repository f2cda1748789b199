//! The cell's workspace: the box the sphere stations stand in, with the eye
//! point the approach directions centre on, per preset; the station layouts
//! (the paper's "3 layers along X, Y, Z" for identification, spread stations
//! for validation); the joint limits a cell plans within.

use nalgebra::Vector3;
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::random::uniform;
use crate::engine::base::robot::{JointLimit, RobotChoice};

/// The box (base frame, mm) the sphere stations are placed in, and the eye
/// point (base frame, mm) whose direction to a station is the mean
/// approach direction (flange z) there.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Workspace {
    /// Lower corner `[x, y, z]`, mm, base frame.
    pub min: [f64; 3],
    /// Upper corner `[x, y, z]`, mm, base frame.
    pub max: [f64; 3],
    /// Eye point `[x, y, z]`, mm, base frame: approach directions centre on
    /// `station − eye`.
    pub eye: [f64; 3],
}

impl Workspace {
    /// The default workspace of a preset, chosen so that every station can
    /// be seen from a cone of 40° about the mean direction with the paper's
    /// 288 mm sensor stand-off (see the module docs).
    #[must_use]
    pub fn for_robot(robot: RobotChoice) -> Self {
        match robot {
            // The paper's cell: a 400 × 600 × 450 mm box in front of the
            // robot, below the shoulder (615 mm); the sensor looks down and
            // outward.
            RobotChoice::Irb2400 => Self {
                min: [850.0, -300.0, 250.0],
                max: [1250.0, 300.0, 700.0],
                eye: [0.0, 0.0, 1400.0],
            },
            // A 140 × 300 × 150 mm box for the 580 mm-reach arm: the 288 mm
            // sensor stand-off is half its reach, so stations sit low and
            // close.
            RobotChoice::Irb120 => Self {
                min: [330.0, -150.0, 50.0],
                max: [470.0, 150.0, 200.0],
                eye: [0.0, 0.0, 800.0],
            },
            // The UR5e's arm points along −x at q1 = 0: a 250 × 500 × 250 mm
            // box on that side, 0-250 mm above the base plate.
            RobotChoice::Ur5e => Self {
                min: [-650.0, -250.0, 0.0],
                max: [-400.0, 250.0, 250.0],
                eye: [0.0, 0.0, 1100.0],
            },
        }
    }

    pub(crate) fn lerp(&self, f: [f64; 3]) -> Vector3<f64> {
        Vector3::from_fn(|i, _| self.min[i] + f[i] * (self.max[i] - self.min[i]))
    }

    pub(crate) fn centre(&self) -> Vector3<f64> {
        self.lerp([0.5; 3])
    }

    pub(crate) fn diagonal(&self) -> f64 {
        (Vector3::from(self.max) - Vector3::from(self.min)).norm()
    }
}

/// Tries for a validate station that is at least [`MIN_STATION_SEPARATION`]
/// of the workspace diagonal from its predecessor.
const MAX_STATION_ATTEMPTS: usize = 100;

/// Consecutive validate stations are at least this fraction of the
/// workspace diagonal apart, so reference distances are long (the paper's
/// tracker distances are hundreds of mm).
const MIN_STATION_SEPARATION: f64 = 0.25;

/// The three levels of the Latin-square identify stations on each axis, as
/// fractions of the box extent: spread over the box, with room for the
/// jitter inside it.
const IDENTIFY_LEVELS: [f64; 3] = [0.1, 0.5, 0.9];

/// Jitter of the Latin-square identify stations about their level, as a
/// fraction of the box extent (levels are 0.4 apart, so layers stay
/// distinct).
const LEVEL_JITTER: f64 = 0.08;

/// The preset's joint limits, narrowed where a preset allows
/// configurations no cell would use: the UR5e (±360° everywhere) keeps its
/// upper arm above the horizontal and leaning toward the work (`q2` in
/// −150..−10, the base stands on a table) and its elbow up and bent (`q3`
/// in 10..160, away from the stretched-arm singularity at 0 and from
/// folding onto itself).
pub(crate) fn planning_limits(choice: RobotChoice, limits: &[JointLimit]) -> Vec<JointLimit> {
    cell_limits(choice.key(), limits)
}

/// The joint limits a cell would plan within for the preset `key`: the
/// preset's `limits`, with the UR5e narrowed as the simulator narrows it
/// (upper arm above the horizontal, elbow up and bent); other robots keep
/// `limits` unchanged.
#[must_use]
pub fn cell_limits(key: &str, limits: &[JointLimit]) -> Vec<JointLimit> {
    let mut out = limits.to_vec();
    if key == RobotChoice::Ur5e.key() && out.len() >= 3 {
        out[1] = JointLimit {
            min: -150.0,
            max: -10.0,
        };
        out[2] = JointLimit {
            min: 10.0,
            max: 160.0,
        };
    }
    out
}

/// Identify stations: a 3×3 Latin square of x, y, z levels (jittered),
/// then uniform in the box.
pub fn identify_stations(rng: &mut ChaCha8Rng, w: &Workspace, n: usize) -> Vec<Vector3<f64>> {
    (0..n)
        .map(|k| {
            if k < 9 {
                let (ix, iy) = (k / 3, k % 3);
                let iz = (ix + iy) % 3;
                let f = [ix, iy, iz].map(|i| {
                    let level = IDENTIFY_LEVELS[i];
                    (level + uniform(rng, -LEVEL_JITTER, LEVEL_JITTER)).clamp(0.0, 1.0)
                });
                w.lerp(f)
            } else {
                w.lerp([(); 3].map(|()| rng.random::<f64>()))
            }
        })
        .collect()
}

/// Validate stations: uniform in the box, each far enough from the one
/// before (long reference distances).
pub fn validate_stations(rng: &mut ChaCha8Rng, w: &Workspace, n: usize) -> Vec<Vector3<f64>> {
    let min_gap = MIN_STATION_SEPARATION * w.diagonal();
    let mut out: Vec<Vector3<f64>> = Vec::with_capacity(n);
    for _ in 0..n {
        let mut p = w.lerp([(); 3].map(|()| rng.random::<f64>()));
        for _ in 0..MAX_STATION_ATTEMPTS {
            if out.last().is_none_or(|prev| (p - prev).norm() >= min_gap) {
                break;
            }
            p = w.lerp([(); 3].map(|()| rng.random::<f64>()));
        }
        out.push(p);
    }
    out
}
