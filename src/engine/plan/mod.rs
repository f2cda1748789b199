//! The pose planner: which robot poses to teach for a calibration, from a
//! robot, a rough sphere position and the sensor's hand-eye guess.
//!
//! # What a plan holds (paper section 4, shared/paper/NOTES.md)
//!
//! - **Stations**, the sphere's places (the paper's sphere sits on a
//!   tripod that is moved between them):
//!   - `P0` at the given sphere position, for the **translation** group
//!     (one flange orientation, the flange moved by `translation_step` mm in
//!     directions spread over the sensor's y-z plane, paper eq. 6-7) and the
//!     **rotation** group (orientations turned 20-45° about different axes,
//!     eq. 8-9);
//!   - **identify** stations `P1..` and **validate** stations `V1..`. By
//!     default ([`StationLayout::Box`]) they are spread in a box centred on
//!     the sphere position: the identify stations on the paper's "3 layers
//!     along X, Y and Z" (a jittered 3 × 3 Latin square of x, y and z
//!     levels; beyond 9, uniform in the box), the validate stations
//!     uniformly in the box with consecutive ones at least a quarter of its
//!     diagonal apart (long laser-tracker distances, paper 4.3). The same
//!     layout as the simulator, from the plan's seed. Or the user lists
//!     them ([`StationLayout::Explicit`]).
//! - **Poses**: at every pose the laser plane cuts the sphere at
//!   `cut_angle` (paper 4.1: about ±40°), i.e. the sphere centre is planned
//!   at sensor `(side · R · sin(cut), y, z)` with `y`, `z` drawn within
//!   `centre_spread` (the paper's ±2, ±3 mm; on the sensor x axis alone the
//!   hand-eye rotation about it would be invisible); identify and validate stations
//!   get both sides, balanced (NOTES.md: one side only is badly
//!   conditioned).
//!
//! # How the poses are chosen
//!
//! 1. **Candidates.** At every station, `candidates` flange orientations are
//!    drawn: approach (flange z) uniform in a cone of `cone_angle` about the
//!    direction from the eye point to the station, uniform roll. For each
//!    orientation and side, every IK branch of the nominal model
//!    ([`Chain::solutions`](crate::engine::robot::ik::Chain::solutions)) within the joint
//!    limits and at least `min_wrist_angle` from the wrist singularity is a
//!    candidate, kept only when the reference forward kinematics puts the
//!    planned sensor-frame centre on the station (to 1e-6 mm).
//! 2. **Identifiable parameters.** The `ml` method's own identifiability
//!    analysis ([`ml::run`] with no update) is run on the whole candidate
//!    pool; the parameters it estimates are the ones the plan is judged on.
//! 3. **Greedy D-optimal selection** of the identify poses: the criterion is
//!    `ln det` of the information matrix of those parameters, Gauss-Newton
//!    of the `ml` method's model (every sighting a residual `X_i − c_s` with
//!    the station centre `c_s` eliminated, whitened with `ml`'s noise model:
//!    joint noise `joint_sigma_deg` and the circle-fit covariance of a
//!    stripe with `stripe_sigma` noise; angles scaled by 1000 mm/rad),
//!    plus `ml`'s prior on the kinematic deviations (σ 0.2°, 0.5 mm) and a
//!    weak one on the hand-eye (σ 10 mm, 10°) so that the early, still
//!    singular steps are ranked (Bayesian D-optimality). Each station's
//!    first pose is its candidate closest to the mean approach; then the
//!    pose with the largest gain (a rank-3 update, by the matrix
//!    determinant lemma) is added until every station is full, each side
//!    at most `ceil(n/2)` per station; then exchange passes swap a chosen
//!    pose for a better one of its station and side (Fedorov exchange)
//!    until none improves. Validate poses are spread instead (farthest
//!    point in flange orientation); the rotation group maximises
//!    `ln det Σ (R_i − R_j)ᵀ(R_i − R_j)` (eq. 8's normal matrix).
//! 4. **Order** for short robot moves: stations in nearest-neighbour order
//!    of their positions (the tripod moves least too), and within a
//!    station's group nearest neighbour then 2-opt on the weighted joint
//!    distance `max_i w_i·|Δq_i|` (the time-like distance of a
//!    synchronised joint move), starting from the previous group's last
//!    pose. Joints whose range exceeds a turn (IRB 2400 axes 4 and 6) take
//!    the equivalent reading (±360°) nearest the previous pose. Station
//!    and measurement ids are given in visit order.
//! 5. **Report**: `ml`'s analysis of the chosen plan (which parameters it
//!    cannot identify and why, the expected validation std from its
//!    covariance), the condition number of the whitened Jacobian, the
//!    criterion against a random selection of the same size from the same
//!    candidates, and the path length. [`predict`] simulates the plan on
//!    randomly perturbed robots and calibrates each run.
//!
//! # Exports
//!
//! [`plan_csv`] writes the joint log layout `spherecal import` reads
//! (`id,station,use,side,j1..jn`, the controller's ABB flange pose
//! `x,y,z,q1..q4` from the nominal model, then the station position and
//! the planned sensor-frame centre, which the import ignores and
//! `spherecal simulate --plan` uses); [`Controller`] renders robot
//! programs (ABB RAPID), one `render` arm per controller.

use std::fmt::Write as _;

use nalgebra::{DMatrix, Isometry3, Matrix3, Point3, Translation3, Unit, UnitQuaternion, Vector3};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

use crate::engine::cell::workspace::{self, Workspace};
use crate::engine::cell::{approach, random, sensor};
use crate::engine::evaluate;
use crate::engine::geometry::wrap_deg;
use crate::engine::handeye::{MIN_TRANSLATION_SPREAD, Sighting};
use crate::engine::robot::ik::{Chain, DOF};
use crate::engine::robot::{JointLimit, Preset, Robot, RobotChoice};
use crate::engine::session::{
    Measurement, Observation, ReferenceDistance, Session, SolverSettings, Use,
};
use crate::engine::simulate::{
    self, ErrorModel, InitialHandEye, PlanExecution, PlanPose, SimConfig,
};
use crate::engine::solve::estimate::{
    ANGLE_SCALE_MM, Estimate, sensitivity, unknown_is_angle, unknown_label,
};
use crate::engine::solve::ml::{self, Inseparable, MlOptions, MlReport};
use crate::engine::solve::{self, Control, HandEyeSource, Method, Options, Prepared};

mod export;
mod order;
mod select;

pub use export::{Controller, RAPID_MODULE, plan_csv, rapid_module, read_plan_csv};
use order::{Metric, order_groups};
use select::{
    Info, StationInfo, criterion, greedy_selection, prior_information, random_selection,
    rotation_criterion, spread_selection,
};

/// Default cut angle, deg: the paper's "about ±40°" (section 4.1), where
/// its distance errors were smallest.
pub const DEFAULT_CUT_ANGLE_DEG: f64 = 40.0;
/// Default orientations drawn per station. Each gives up to 8 IK branches
/// per side on an ABB arm; 24 gives the greedy selection ~100-300
/// candidates per station, far more than the 6 it keeps.
pub const DEFAULT_CANDIDATES: usize = 24;
/// Default half-angle of the cone of approach directions, deg: the
/// simulator's (orientation spread is what identifies the kinematics).
pub const DEFAULT_CONE_DEG: f64 = 45.0;
/// Default smallest `|q5 + theta5|`, deg, away from the wrist singularity.
pub const DEFAULT_MIN_WRIST_DEG: f64 = 10.0;
/// Default flange displacement of the translation group, mm: the middle of
/// the simulator's 15-20 mm.
pub const DEFAULT_TRANSLATION_STEP_MM: f64 = 17.5;
/// Default smallest orientation change of the rotation group, deg.
pub const DEFAULT_ROTATION_MIN_DEG: f64 = 20.0;
/// Default largest orientation change of the rotation group, deg.
pub const DEFAULT_ROTATION_MAX_DEG: f64 = 45.0;
/// Default half-widths (mm) of the planned centres' sensor `y`, `z`: the
/// paper's `±2`, `±3` mm (NOTES.md), as the simulator draws them.
pub const DEFAULT_CENTRE_SPREAD_MM: [f64; 2] = [2.0, 3.0];
/// Default station box (mm) for a robot that is not a preset: a 300 mm
/// cube about the sphere position.
pub const DEFAULT_BOX_MM: [f64; 3] = [300.0; 3];
/// Reference FK must put the planned centre on the station to this, mm
/// (IK converges to 1e-9 mm; this only guards the fast chain).
const FK_CHECK_MM: f64 = 1e-6;
/// Orientation draws tried for the translation group before `P0` is
/// declared out of reach, as a multiple of `candidates`.
const TRANSLATION_TRIES_PER_CANDIDATE: usize = 4;
/// A translation pose must stay within this (deg, every joint) of the
/// previous one: the same IK branch, a pure flange translation.
const TRANSLATION_SAME_BRANCH_DEG: f64 = 20.0;
/// Two rotation poses differ in orientation by at least this (deg), as in
/// the simulator, so eq. 8-9 get distinct rows.
const MIN_ROTATION_SEPARATION_DEG: f64 = 15.0;
/// Stream ids of the plan's seed: stations and candidates; the random
/// baseline selection.
const STREAM_GEOMETRY: u64 = 10;
/// See [`STREAM_GEOMETRY`].
const STREAM_BASELINE: u64 = 11;

/// Where the identify and validate stations are.
#[derive(Debug, Clone, PartialEq)]
pub enum StationLayout {
    /// Spread (from the seed) in a box of this size (mm, along the base
    /// axes) centred on the sphere position; see the module docs.
    Box {
        /// Full edge lengths, mm.
        size: [f64; 3],
    },
    /// Explicit positions (base frame, mm); `n_identify` and `n_validate`
    /// are then their counts.
    Explicit {
        /// Identify stations, in order.
        identify: Vec<[f64; 3]>,
        /// Validate stations, in order.
        validate: Vec<[f64; 3]>,
    },
}

/// How the identify poses are chosen from the candidates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Selection {
    /// Greedy D-optimal with exchange passes (the module docs).
    #[default]
    DOptimal,
    /// A seeded random balanced selection: the baseline.
    Random,
}

/// Everything the planner needs. [`PlanConfig::for_preset`] and
/// [`PlanConfig::new`] fill the defaults.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanConfig {
    /// The nominal model the controller uses (6 joints).
    pub robot: Robot,
    /// Joint limits, deg, one per joint.
    pub limits: Vec<JointLimit>,
    /// Rough sphere position (station `P0`), base frame, mm.
    pub sphere: [f64; 3],
    /// The hand-eye guess `flange_from_sensor` (mm).
    pub flange_from_sensor: Isometry3<f64>,
    /// Sphere diameter, mm.
    pub diameter: f64,
    /// Translation poses at `P0` (0, or at least 3).
    pub n_translation: usize,
    /// Rotation poses at `P0` (0, or at least 2).
    pub n_rotation: usize,
    /// Identify stations (ignored for an explicit layout).
    pub n_identify: usize,
    /// Poses per identify station.
    pub identify_poses: usize,
    /// Validate stations (ignored for an explicit layout).
    pub n_validate: usize,
    /// Poses per validate station.
    pub validate_poses: usize,
    /// Cut angle, deg: the sphere centre at sensor `x = ±R·sin(cut)`.
    pub cut_angle: f64,
    /// Orientations drawn per station.
    pub candidates: usize,
    /// How identify poses are chosen.
    pub selection: Selection,
    /// Seed of every random choice: the same configuration gives the same plan.
    pub seed: u64,
    /// Identify and validate stations.
    pub stations: StationLayout,
    /// Eye point (base frame, mm): approach directions centre on
    /// `station − eye`. `None`: above the robot base at the sphere's
    /// height plus its horizontal distance from the base (a 45° look down
    /// and outward).
    pub eye: Option<[f64; 3]>,
    /// Half-angle of the approach cone, deg.
    pub cone_angle: f64,
    /// Smallest `|q5 + theta5|`, deg.
    pub min_wrist_angle: f64,
    /// Flange displacement of the translation group, mm.
    pub translation_step: f64,
    /// Smallest orientation change of the rotation group, deg.
    pub rotation_min: f64,
    /// Largest orientation change of the rotation group, deg.
    pub rotation_max: f64,
    /// Weights of the joint distance `max_i w_i·|Δq_i|` used for ordering
    /// (e.g. the inverse joint speeds); one per joint.
    pub joint_weights: Vec<f64>,
    /// σ of the joint readings in the criterion's noise model, deg.
    pub joint_sigma_deg: f64,
    /// σ of the stripe points in the criterion's noise model, mm.
    pub stripe_sigma: f64,
    /// Half-widths (mm) of the sensor-frame `y` and `z` of the planned
    /// centres, drawn per candidate: the paper's centres sit at `±2`, `±3`
    /// mm (NOTES.md). All at `y = z = 0` (on the sensor x axis) would hide
    /// the hand-eye rotation about that axis.
    pub centre_spread: [f64; 2],
}

impl PlanConfig {
    /// Defaults for any robot: the paper-like counts (4 translations, 6
    /// rotations, 9 identify and 10 validate stations of 6 poses), the
    /// paper's initial hand-eye, a 38.1 mm sphere, a 300 mm station box.
    #[must_use]
    pub fn new(robot: Robot, limits: Vec<JointLimit>, sphere: [f64; 3]) -> Self {
        let sim = SimConfig::default();
        let dof = robot.dof();
        Self {
            robot,
            limits,
            sphere,
            flange_from_sensor: sensor::paper_initial_hand_eye(),
            diameter: sim.diameter,
            n_translation: sim.n_translation,
            n_rotation: sim.n_rotation,
            n_identify: sim.n_identify,
            identify_poses: sim.poses_per_station,
            n_validate: sim.n_validate,
            validate_poses: sim.poses_per_station,
            cut_angle: DEFAULT_CUT_ANGLE_DEG,
            candidates: DEFAULT_CANDIDATES,
            selection: Selection::DOptimal,
            seed: 1,
            stations: StationLayout::Box {
                size: DEFAULT_BOX_MM,
            },
            eye: None,
            cone_angle: DEFAULT_CONE_DEG,
            min_wrist_angle: DEFAULT_MIN_WRIST_DEG,
            translation_step: DEFAULT_TRANSLATION_STEP_MM,
            rotation_min: DEFAULT_ROTATION_MIN_DEG,
            rotation_max: DEFAULT_ROTATION_MAX_DEG,
            joint_weights: vec![1.0; dof],
            joint_sigma_deg: sim.joint_noise,
            stripe_sigma: sim.stripe_noise,
            centre_spread: DEFAULT_CENTRE_SPREAD_MM,
        }
    }

    /// Defaults for a preset: [`Self::new`] with the limits a cell plans
    /// within ([`workspace::cell_limits`]) and the simulator's station box
    /// size for that robot ([`Workspace::for_robot`], e.g. 400 × 600 ×
    /// 450 mm for the IRB 2400).
    #[must_use]
    pub fn for_preset(preset: &Preset, sphere: [f64; 3]) -> Self {
        let mut config = Self::new(
            preset.robot.clone(),
            workspace::cell_limits(preset.key, &preset.limits),
            sphere,
        );
        let choice = RobotChoice::from_key(preset.key);
        if let Some(choice) = choice {
            let w = Workspace::for_robot(choice);
            config.stations = StationLayout::Box {
                size: [0, 1, 2].map(|i| w.max[i] - w.min[i]),
            };
        }
        config
    }

    /// The eye point (base frame, mm); see [`Self::eye`].
    #[must_use]
    pub fn eye_point(&self) -> Vector3<f64> {
        if let Some(e) = self.eye {
            return Vector3::from(e);
        }
        let b = self.robot.base.translation.vector;
        let s = Vector3::from(self.sphere);
        let horizontal = (s.x - b.x).hypot(s.y - b.y);
        Vector3::new(b.x, b.y, s.z + horizontal)
    }

    /// Checks every setting.
    ///
    /// # Errors
    /// [`PlanError::InvalidConfig`] naming the setting and its value.
    pub fn validate(&self) -> Result<(), PlanError> {
        let dof = self.robot.dof();
        check(dof == DOF, || {
            format!(
                "the planner solves 6-axis arms, {} has {dof} joints",
                self.robot.name
            )
        })?;
        check(self.limits.len() == dof, || {
            format!(
                "{} joint limits given, the robot has {dof} joints",
                self.limits.len()
            )
        })?;
        check(
            self.limits
                .iter()
                .all(|l| l.min.is_finite() && l.max.is_finite() && l.min < l.max),
            || "every joint limit needs finite min < max".to_owned(),
        )?;
        check(self.joint_weights.len() == dof, || {
            format!(
                "{} joint weights given, the robot has {dof} joints",
                self.joint_weights.len()
            )
        })?;
        check(
            self.joint_weights.iter().all(|w| w.is_finite() && *w > 0.0),
            || "joint weights must be positive numbers".to_owned(),
        )?;
        let reals = [
            ("diameter", self.diameter),
            ("cut angle", self.cut_angle),
            ("cone angle", self.cone_angle),
            ("min wrist angle", self.min_wrist_angle),
            ("translation step", self.translation_step),
            ("rotation min", self.rotation_min),
            ("rotation max", self.rotation_max),
            ("joint sigma", self.joint_sigma_deg),
            ("stripe sigma", self.stripe_sigma),
        ];
        for (name, v) in reals {
            check(v.is_finite(), || {
                format!("{name} must be a finite number, found {v}")
            })?;
        }
        check(
            self.centre_spread
                .iter()
                .all(|v| v.is_finite() && *v >= 0.0),
            || "the centre spread needs two finite, non-negative half-widths (mm)".to_owned(),
        )?;
        check(self.sphere.iter().all(|v| v.is_finite()), || {
            "the sphere position must be three finite numbers (mm)".to_owned()
        })?;
        check(self.diameter > 0.0, || {
            format!(
                "the sphere diameter must be positive, found {} mm",
                self.diameter
            )
        })?;
        check(self.cut_angle > 5.0 && self.cut_angle < 80.0, || {
            format!(
                "the cut angle must be within (5, 80) deg, found {}",
                self.cut_angle
            )
        })?;
        check((0.0..=90.0).contains(&self.cone_angle), || {
            format!(
                "the cone angle must be within 0..90 deg, found {}",
                self.cone_angle
            )
        })?;
        check((0.0..90.0).contains(&self.min_wrist_angle), || {
            format!(
                "the min wrist angle must be within 0..90 deg, found {}",
                self.min_wrist_angle
            )
        })?;
        check(
            0.0 < self.rotation_min
                && self.rotation_min <= self.rotation_max
                && self.rotation_max <= 180.0,
            || {
                format!(
                    "rotations need 0 < rotation min ≤ rotation max ≤ 180 deg, found {} and {}",
                    self.rotation_min, self.rotation_max
                )
            },
        )?;
        check(
            self.joint_sigma_deg >= 0.0 && self.stripe_sigma > 0.0,
            || "the noise model needs joint sigma ≥ 0 and stripe sigma > 0".to_owned(),
        )?;
        check(self.candidates >= 1, || {
            "at least one candidate orientation per station is needed".to_owned()
        })?;
        check(self.n_rotation != 1, || {
            "the rotation group needs at least 2 poses (eq. 8 uses pairs), or none".to_owned()
        })?;
        check(self.n_identify_stations() >= 1, || {
            "at least one identify station is needed".to_owned()
        })?;
        check(self.identify_poses >= 2, || {
            format!(
                "an identify station needs at least 2 poses (FORMAT.md), found {}",
                self.identify_poses
            )
        })?;
        check(
            self.n_validate_stations() == 0 || self.validate_poses >= 1,
            || "validate stations need at least 1 pose".to_owned(),
        )?;
        match &self.stations {
            StationLayout::Box { size } => {
                check(size.iter().all(|v| v.is_finite() && *v >= 0.0), || {
                    "the station box needs three finite, non-negative sizes (mm)".to_owned()
                })?;
            }
            StationLayout::Explicit { identify, validate } => {
                check(
                    identify
                        .iter()
                        .chain(validate)
                        .flatten()
                        .all(|v| v.is_finite()),
                    || "station positions must be finite numbers (mm)".to_owned(),
                )?;
            }
        }
        Ok(())
    }

    fn n_identify_stations(&self) -> usize {
        match &self.stations {
            StationLayout::Box { .. } => self.n_identify,
            StationLayout::Explicit { identify, .. } => identify.len(),
        }
    }

    fn n_validate_stations(&self) -> usize {
        match &self.stations {
            StationLayout::Box { .. } => self.n_validate,
            StationLayout::Explicit { validate, .. } => validate.len(),
        }
    }

    fn radius(&self) -> f64 {
        self.diameter / 2.0
    }

    /// The planned sensor-frame centre on `side`.
    fn centre(&self, side: i8) -> Vector3<f64> {
        Vector3::new(
            f64::from(side) * self.radius() * self.cut_angle.to_radians().sin(),
            0.0,
            0.0,
        )
    }
}

fn check(ok: bool, message: impl FnOnce() -> String) -> Result<(), PlanError> {
    if ok {
        Ok(())
    } else {
        Err(PlanError::InvalidConfig(message()))
    }
}

/// Why a plan (or its prediction) could not be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanError {
    /// A setting is out of range; the message names it.
    #[error("invalid plan setting: {0}")]
    InvalidConfig(String),
    /// No candidate pose sees the station.
    #[error(
        "station {station} at [{:.1}, {:.1}, {:.1}] mm (base) is out of reach: none of {orientations} flange orientations (approach within {cone:.0}° of the look from the eye point) sees it with the laser plane at ±{cut:.0}° within the joint limits and {min_wrist:.0}° from the wrist singularity; move the sphere (or the station box) toward the robot, or widen the cone",
        position[0], position[1], position[2]
    )]
    Unreachable {
        /// Station id.
        station: String,
        /// Its position, base frame, mm.
        position: [f64; 3],
        /// Orientations tried.
        orientations: usize,
        /// Cone half-angle, deg.
        cone: f64,
        /// Cut angle, deg.
        cut: f64,
        /// Smallest wrist angle, deg.
        min_wrist: f64,
    },
    /// A station has too few reachable candidate poses on one side.
    #[error(
        "station {station} at [{:.1}, {:.1}, {:.1}] mm (base): only {found} reachable pose(s) see the sphere on side {side:+} of the laser plane, {needed} needed; draw more candidates, ask for fewer poses, or move the station toward the middle of the robot's reach",
        position[0], position[1], position[2]
    )]
    TooFewPoses {
        /// Station id.
        station: String,
        /// Its position, base frame, mm.
        position: [f64; 3],
        /// The side, +1 or −1.
        side: i8,
        /// Distinct reachable candidates on that side.
        found: usize,
        /// Poses the plan needs on that side.
        needed: usize,
    },
    /// The translation group cannot determine the hand-eye rotation.
    #[error(
        "the translation group is collinear: {detail}; eq. 6-7 need displacements in at least two directions (3 or more translations, a non-zero step)"
    )]
    CollinearTranslations {
        /// What was found.
        detail: String,
    },
    /// The run was cancelled through the progress callback.
    #[error("planning cancelled")]
    Cancelled,
    /// A simulated run of [`predict`] failed.
    #[error("prediction run {run} (seed {seed}): {message}")]
    Prediction {
        /// Run index, 1-based.
        run: usize,
        /// Its seed.
        seed: u64,
        /// What failed.
        message: String,
    },
    /// The `ml` analysis of the candidates or the plan failed.
    #[error("identifiability analysis failed: {0}")]
    Analysis(String),
    /// A plan CSV could not be read.
    #[error("line {line}: {message}")]
    Csv {
        /// 1-based line.
        line: usize,
        /// What is wrong.
        message: String,
    },
}

/// What a station is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StationRole {
    /// `P0`: the translation and rotation groups (initial hand-eye).
    HandEye,
    /// Identification.
    Identify,
    /// Validation (held out).
    Validate,
}

/// A planned station.
#[derive(Debug, Clone, PartialEq)]
pub struct PlannedStation {
    /// Station id (`P0`, `P1..`, `V1..`, in visit order).
    pub id: String,
    /// What it is for.
    pub role: StationRole,
    /// Where to put the sphere, base frame, mm.
    pub position: Vector3<f64>,
    /// Reachable candidate poses found there.
    pub candidates: usize,
}

/// A planned pose, in visit order.
#[derive(Debug, Clone, PartialEq)]
pub struct PlannedPose {
    /// Measurement id (`t1..`, `r1..`, `c1..`, `v1..`, in visit order).
    pub id: String,
    /// Station id.
    pub station: String,
    /// FORMAT.md `use`.
    pub usage: Use,
    /// Side of the laser plane, +1 or −1.
    pub side: i8,
    /// Joint targets, deg.
    pub joints: Vec<f64>,
    /// The flange pose of the nominal model at `joints` (what the
    /// controller reports), base frame, mm.
    pub base_from_flange: Isometry3<f64>,
    /// Where the sphere centre is planned in the sensor frame, mm.
    pub centre_in_sensor: Vector3<f64>,
}

/// How good the plan is.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanStats {
    /// Reachable candidate poses, all stations.
    pub candidates: usize,
    /// Parameters the plan identifies (`ml`'s analysis of the plan).
    pub estimated: Vec<String>,
    /// Parameters it cannot identify (fixed at their start).
    pub fixed: Vec<String>,
    /// `ml`'s sentences naming each combination that cannot be separated.
    pub inseparable: Vec<Inseparable>,
    /// The criterion of the identify poses: `ln det` of the information
    /// matrix (prior included, angles scaled by 1000 mm/rad, mm⁻²).
    pub log_det: f64,
    /// The same criterion for a seeded random balanced selection of the
    /// same size from the same candidates.
    pub log_det_random: f64,
    /// Condition number of the whitened, scaled Jacobian of the estimated
    /// parameters (data alone, station centres eliminated).
    pub condition: f64,
    /// `ml`'s expected validation std after calibration, mm (parameter
    /// covariance and noise, common part removed), when the plan has
    /// validate stations.
    pub predicted_validation_std: Option<f64>,
    /// Path of the poses in selection order (groups as generated), deg of
    /// weighted joint distance.
    pub path_unordered_deg: f64,
    /// Path in plan order, deg.
    pub path_deg: f64,
}

/// A measurement plan.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// The nominal model.
    pub robot: Robot,
    /// The joint limits planned within, deg.
    pub limits: Vec<JointLimit>,
    /// The hand-eye guess used.
    pub flange_from_sensor: Isometry3<f64>,
    /// Sphere diameter, mm.
    pub diameter: f64,
    /// Cut angle, deg.
    pub cut_angle: f64,
    /// The stations, in visit order.
    pub stations: Vec<PlannedStation>,
    /// The poses, in visit order.
    pub poses: Vec<PlannedPose>,
    /// Quality figures.
    pub stats: PlanStats,
}

impl Plan {
    /// Number of poses of `usage`.
    #[must_use]
    pub fn count(&self, usage: Use) -> usize {
        self.poses.iter().filter(|p| p.usage == usage).count()
    }

    /// The station `id`.
    #[must_use]
    pub fn station(&self, id: &str) -> Option<&PlannedStation> {
        self.stations.iter().find(|s| s.id == id)
    }

    /// The poses as [`simulate::simulate_plan`] takes them.
    #[must_use]
    pub fn simulation_poses(&self) -> Vec<PlanPose> {
        self.poses
            .iter()
            .map(|p| PlanPose {
                id: p.id.clone(),
                station: p.station.clone(),
                usage: p.usage,
                side: p.side,
                joints: p.joints.clone(),
                centre_in_sensor: [
                    p.centre_in_sensor.x,
                    p.centre_in_sensor.y,
                    p.centre_in_sensor.z,
                ],
            })
            .collect()
    }
}

/// Where [`plan`] is, for a progress display.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlanStage {
    /// Candidate poses of station `done` of `of` solved.
    Candidates {
        /// Stations done.
        done: usize,
        /// Stations in all.
        of: usize,
    },
    /// The `ml` identifiability analysis of the candidate pool.
    Analysis,
    /// Greedy selection and exchange passes.
    Selection,
    /// Ordering and the analysis of the chosen plan.
    Ordering,
}

/// One candidate pose.
#[derive(Debug, Clone)]
struct Candidate {
    joints: [f64; DOF],
    side: i8,
    centre: Vector3<f64>,
    rotation: UnitQuaternion<f64>,
}

/// A station while planning.
#[derive(Debug, Clone)]
struct Site {
    role: StationRole,
    position: Vector3<f64>,
    candidates: Vec<Candidate>,
    /// Indices of the chosen candidates, in selection order.
    chosen: Vec<usize>,
}

/// One pose of a group to order: joints, with its candidate.
#[derive(Debug, Clone)]
struct Group {
    usage: Use,
    /// Index into the sites.
    site: usize,
    poses: Vec<Candidate>,
}

/// Makes a plan (see the module docs). `progress` sees each stage and may
/// cancel.
///
/// # Errors
/// [`PlanError`]: a bad setting, an unreachable station, too few reachable
/// poses, a collinear translation group, a cancel, or a failed analysis.
pub fn plan(
    config: &PlanConfig,
    progress: &mut dyn FnMut(PlanStage) -> Control,
) -> Result<Plan, PlanError> {
    config.validate()?;
    if (1..3).contains(&config.n_translation) {
        return Err(PlanError::CollinearTranslations {
            detail: format!(
                "{} translation pose(s) give {} displacement(s)",
                config.n_translation,
                config.n_translation - 1
            ),
        });
    }
    if config.n_translation >= 3 && config.translation_step <= 0.0 {
        return Err(PlanError::CollinearTranslations {
            detail: format!("the translation step is {} mm", config.translation_step),
        });
    }
    let chain = Chain::new(&config.robot).ok_or_else(|| {
        PlanError::InvalidConfig(format!(
            "the planner solves 6-axis arms, {} has {} joints",
            config.robot.name,
            config.robot.dof()
        ))
    })?;
    let planner = Planner { config, chain };
    let mut rng = stream(config.seed, STREAM_GEOMETRY);
    let mut sites = planner.sites(&mut rng);
    let mut cancel = |stage| {
        if progress(stage) == Control::Cancel {
            Err(PlanError::Cancelled)
        } else {
            Ok(())
        }
    };

    // Hand-eye groups at P0.
    let mut groups: Vec<Group> = Vec::new();
    let hand_eye = config.n_translation + config.n_rotation > 0;
    let total = sites.len() + usize::from(hand_eye);
    let mut done = 0;
    if hand_eye {
        let p0 = Vector3::from(config.sphere);
        let (translations, reference) = planner.translation_group(&mut rng, &p0)?;
        let rotations = planner.rotation_group(&mut rng, &p0, &reference)?;
        sites.insert(
            0,
            Site {
                role: StationRole::HandEye,
                position: p0,
                candidates: translations.iter().chain(&rotations).cloned().collect(),
                chosen: Vec::new(),
            },
        );
        groups.push(Group {
            usage: Use::Translation,
            site: 0,
            poses: translations,
        });
        groups.push(Group {
            usage: Use::Rotation,
            site: 0,
            poses: rotations,
        });
        done += 1;
        cancel(PlanStage::Candidates { done, of: total })?;
    }
    let first_station = usize::from(hand_eye);
    for k in first_station..sites.len() {
        let id = provisional_id(&sites, k);
        sites[k].candidates = planner.station_candidates(&mut rng, &sites[k].position, &id)?;
        let needed = match sites[k].role {
            StationRole::Identify => config.identify_poses,
            _ => config.validate_poses,
        };
        for side in [1_i8, -1] {
            let found = sites[k]
                .candidates
                .iter()
                .filter(|c| c.side == side)
                .count();
            let need = side_quota(needed, side);
            if found < need {
                let p = sites[k].position;
                return Err(PlanError::TooFewPoses {
                    station: id.clone(),
                    position: [p.x, p.y, p.z],
                    side,
                    found,
                    needed: need,
                });
            }
        }
        done += 1;
        cancel(PlanStage::Candidates { done, of: total })?;
    }

    // The identifiable parameters of the candidate pool, by ml.
    cancel(PlanStage::Analysis)?;
    let pool = planner.pool_report(&sites)?;
    let estimated = unknown_indices(&config.robot, &pool.estimated);
    let infos: Vec<Vec<Info>> = sites
        .iter()
        .map(|s| {
            if s.role == StationRole::Identify {
                s.candidates
                    .iter()
                    .map(|c| planner.info(c, &estimated))
                    .collect()
            } else {
                Vec::new()
            }
        })
        .collect();
    let prior = prior_information(&estimated);

    // Selection.
    cancel(PlanStage::Selection)?;
    let identify_sites: Vec<usize> = (0..sites.len())
        .filter(|&k| sites[k].role == StationRole::Identify)
        .collect();
    let mut baseline_rng = stream(config.seed, STREAM_BASELINE);
    let random = random_selection(
        &sites,
        &identify_sites,
        config.identify_poses,
        &mut baseline_rng,
    );
    let log_det_random = criterion(&prior, &infos, &random).unwrap_or(f64::NEG_INFINITY);
    let chosen = match config.selection {
        Selection::DOptimal => greedy_selection(&planner, &sites, &identify_sites, &infos, &prior),
        Selection::Random => random,
    };
    for (k, c) in chosen {
        sites[k].chosen = c;
    }
    let log_det = criterion(
        &prior,
        &infos,
        &sites
            .iter()
            .enumerate()
            .filter(|(_, s)| s.role == StationRole::Identify)
            .map(|(k, s)| (k, s.chosen.clone()))
            .collect::<Vec<_>>(),
    )
    .unwrap_or(f64::NEG_INFINITY);
    for site in &mut sites {
        if site.role == StationRole::Validate {
            site.chosen = spread_selection(&planner, site, config.validate_poses);
        }
    }

    // Ordering.
    cancel(PlanStage::Ordering)?;
    for (k, s) in sites.iter().enumerate() {
        if s.role == StationRole::HandEye {
            continue;
        }
        groups.push(Group {
            usage: if s.role == StationRole::Identify {
                Use::Identify
            } else {
                Use::Validate
            },
            site: k,
            poses: s.chosen.iter().map(|&i| s.candidates[i].clone()).collect(),
        });
    }
    let metric = Metric {
        weights: &config.joint_weights,
        limits: &config.limits,
    };
    let unordered: Vec<[f64; DOF]> = groups
        .iter()
        .flat_map(|g| g.poses.iter().map(|c| c.joints))
        .collect();
    let path_unordered_deg = metric.path(&metric.unwrap_path(&unordered));
    let ordered_groups = order_groups(&sites, groups, &metric);
    let sequence: Vec<[f64; DOF]> = ordered_groups
        .iter()
        .flat_map(|g| g.poses.iter().map(|c| c.joints))
        .collect();
    let realized = metric.unwrap_path(&sequence);
    let path_deg = metric.path(&realized);

    // Ids in visit order.
    let mut station_ids: Vec<Option<String>> = vec![None; sites.len()];
    let (mut n_identify, mut n_validate) = (0, 0);
    let mut stations = Vec::new();
    for g in &ordered_groups {
        if station_ids[g.site].is_some() {
            continue;
        }
        let site = &sites[g.site];
        let id = match site.role {
            StationRole::HandEye => "P0".to_owned(),
            StationRole::Identify => {
                n_identify += 1;
                format!("P{n_identify}")
            }
            StationRole::Validate => {
                n_validate += 1;
                format!("V{n_validate}")
            }
        };
        station_ids[g.site] = Some(id.clone());
        stations.push(PlannedStation {
            id,
            role: site.role,
            position: site.position,
            candidates: site.candidates.len(),
        });
    }
    let mut counters = [0usize; 4];
    let mut poses = Vec::with_capacity(realized.len());
    let mut joints_iter = realized.iter();
    for g in &ordered_groups {
        let station = station_ids[g.site].clone().unwrap_or_default();
        for c in &g.poses {
            let joints = joints_iter.next().map_or(c.joints.to_vec(), |q| q.to_vec());
            let (prefix, slot) = match g.usage {
                Use::Translation => ("t", 0),
                Use::Rotation => ("r", 1),
                Use::Identify => ("c", 2),
                Use::Validate => ("v", 3),
            };
            counters[slot] += 1;
            poses.push(PlannedPose {
                id: format!("{prefix}{}", counters[slot]),
                station: station.clone(),
                usage: g.usage,
                side: c.side,
                base_from_flange: config.robot.base_from_flange(&joints),
                joints,
                centre_in_sensor: c.centre,
            });
        }
    }
    let mut plan = Plan {
        robot: config.robot.clone(),
        limits: config.limits.clone(),
        flange_from_sensor: config.flange_from_sensor,
        diameter: config.diameter,
        cut_angle: config.cut_angle,
        stations,
        poses,
        stats: PlanStats {
            candidates: sites.iter().map(|s| s.candidates.len()).sum(),
            estimated: Vec::new(),
            fixed: Vec::new(),
            inseparable: Vec::new(),
            log_det,
            log_det_random,
            condition: f64::NAN,
            predicted_validation_std: None,
            path_unordered_deg,
            path_deg,
        },
    };
    let report = planner.plan_report(&plan)?;
    let plan_estimated = unknown_indices(&config.robot, &report.estimated);
    plan.stats.condition = planner.condition(&plan, &plan_estimated);
    plan.stats.estimated = report.estimated;
    plan.stats.fixed = report.fixed;
    plan.stats.inseparable = report.inseparable;
    plan.stats.predicted_validation_std = report.predicted_distance_std_validate.map(|d| d.centred);
    Ok(plan)
}

/// The id a station will probably get (for messages before ordering).
fn provisional_id(sites: &[Site], k: usize) -> String {
    let role = sites[k].role;
    let n = sites[..=k].iter().filter(|s| s.role == role).count();
    match role {
        StationRole::HandEye => "P0".to_owned(),
        StationRole::Identify => format!("P{n}"),
        StationRole::Validate => format!("V{n}"),
    }
}

/// Poses on `side` of a station of `n`: `ceil(n/2)` on +1, the rest on −1.
fn side_quota(n: usize, side: i8) -> usize {
    if side > 0 { n.div_ceil(2) } else { n / 2 }
}

fn stream(seed: u64, id: u64) -> ChaCha8Rng {
    use rand::SeedableRng;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(id);
    rng
}

/// Indices into ΔY (`he_x`…, then the kinematic parameters) of `labels`.
fn unknown_indices(robot: &Robot, labels: &[String]) -> Vec<usize> {
    (0..6 + robot.n_params())
        .filter(|&k| labels.iter().any(|l| *l == unknown_label(k)))
        .collect()
}

/// Scale of ΔY unknown `k`: angles in mm of motion at 1 m (as `ml`).
fn unknown_scale(k: usize) -> f64 {
    if unknown_is_angle(k) {
        ANGLE_SCALE_MM
    } else {
        1.0
    }
}

fn joint_gap(a: &[f64; DOF], b: &[f64; DOF]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| wrap_deg(x - y).abs())
        .fold(0.0, f64::max)
}

/// The planner's geometry: candidates and groups on the nominal model.
struct Planner<'a> {
    config: &'a PlanConfig,
    chain: Chain,
}

impl Planner<'_> {
    /// The identify and validate stations (not yet `P0`).
    fn sites(&self, rng: &mut ChaCha8Rng) -> Vec<Site> {
        let c = self.config;
        let (identify, validate): (Vec<Vector3<f64>>, Vec<Vector3<f64>>) = match &c.stations {
            StationLayout::Box { size } => {
                let centre = Vector3::from(c.sphere);
                let half = Vector3::from(*size) / 2.0;
                let eye = self.config.eye_point();
                let w = Workspace {
                    min: (centre - half).into(),
                    max: (centre + half).into(),
                    eye: eye.into(),
                };
                (
                    workspace::identify_stations(rng, &w, c.n_identify),
                    workspace::validate_stations(rng, &w, c.n_validate),
                )
            }
            StationLayout::Explicit { identify, validate } => (
                identify.iter().map(|p| Vector3::from(*p)).collect(),
                validate.iter().map(|p| Vector3::from(*p)).collect(),
            ),
        };
        let site = |role, position| Site {
            role,
            position,
            candidates: Vec::new(),
            chosen: Vec::new(),
        };
        identify
            .into_iter()
            .map(|p| site(StationRole::Identify, p))
            .chain(validate.into_iter().map(|p| site(StationRole::Validate, p)))
            .collect()
    }

    fn mean_approach(&self, station: &Vector3<f64>) -> Vector3<f64> {
        let d = station - self.config.eye_point();
        if d.norm() > 0.0 {
            d.normalize()
        } else {
            -Vector3::z()
        }
    }

    /// The flange pose that puts the sphere at `station` and at `centre`
    /// in the sensor frame, with flange rotation `rotation`.
    fn target(
        &self,
        station: &Vector3<f64>,
        rotation: &UnitQuaternion<f64>,
        centre: &Vector3<f64>,
    ) -> Isometry3<f64> {
        let centre_in_flange = self.config.flange_from_sensor * Point3::from(*centre);
        let position = station - rotation * centre_in_flange.coords;
        Isometry3::from_parts(Translation3::from(position), *rotation)
    }

    /// Whether the reference FK at `q` sees the station at `centre`.
    fn sees(&self, q: &[f64; DOF], station: &Vector3<f64>, centre: &Vector3<f64>) -> bool {
        let seen = self.config.robot.base_from_flange(q)
            * self.config.flange_from_sensor
            * Point3::from(*centre);
        (seen.coords - station).norm() < FK_CHECK_MM
    }

    /// Every IK branch of every drawn orientation and side at a station.
    fn station_candidates(
        &self,
        rng: &mut ChaCha8Rng,
        station: &Vector3<f64>,
        id: &str,
    ) -> Result<Vec<Candidate>, PlanError> {
        let c = self.config;
        let mean = self.mean_approach(station);
        let cone = c.cone_angle.to_radians();
        let mut out = Vec::new();
        for _ in 0..c.candidates {
            let rotation = approach::random_orientation(rng, &mean, cone);
            for side in [1_i8, -1] {
                let offset = self.offset(rng);
                out.extend(self.candidates_at(
                    station,
                    &rotation,
                    &(c.centre(side) + offset),
                    side,
                ));
            }
        }
        if out.is_empty() {
            return Err(self.unreachable(id, station, c.candidates));
        }
        Ok(out)
    }

    /// A sensor-frame `(0, y, z)` offset of the planned centre, uniform in
    /// `±centre_spread`.
    fn offset(&self, rng: &mut ChaCha8Rng) -> Vector3<f64> {
        let [y, z] = self.config.centre_spread;
        Vector3::new(
            0.0,
            random::uniform(rng, -y, y),
            random::uniform(rng, -z, z),
        )
    }

    /// Every IK branch that sees `station` at `centre` (sensor frame) with
    /// the flange rotation `rotation`.
    fn candidates_at(
        &self,
        station: &Vector3<f64>,
        rotation: &UnitQuaternion<f64>,
        centre: &Vector3<f64>,
        side: i8,
    ) -> Vec<Candidate> {
        let c = self.config;
        let centre = *centre;
        let target = self.target(station, rotation, &centre);
        let guesses = self.chain.arm_guess_grid(&target, &c.limits);
        self.chain
            .solutions(&target, &guesses, &c.limits, c.min_wrist_angle)
            .into_iter()
            .filter(|q| self.sees(q, station, &centre))
            .map(|joints| Candidate {
                joints,
                side,
                centre,
                rotation: *rotation,
            })
            .collect()
    }

    fn unreachable(&self, id: &str, station: &Vector3<f64>, orientations: usize) -> PlanError {
        PlanError::Unreachable {
            station: id.to_owned(),
            position: [station.x, station.y, station.z],
            orientations,
            cone: self.config.cone_angle,
            cut: self.config.cut_angle,
            min_wrist: self.config.min_wrist_angle,
        }
    }

    /// The translation group at `P0` (side +1, one orientation, one IK
    /// branch) and its flange rotation. Empty (with a reference
    /// orientation) when no translations are asked for.
    fn translation_group(
        &self,
        rng: &mut ChaCha8Rng,
        p0: &Vector3<f64>,
    ) -> Result<(Vec<Candidate>, UnitQuaternion<f64>), PlanError> {
        let c = self.config;
        let mean = self.mean_approach(p0);
        // Near the middle of the cone, so the rotations about it stay reachable.
        let cone = c.cone_angle.to_radians() / 2.0;
        let n = c.n_translation;
        let tries = c.candidates * TRANSLATION_TRIES_PER_CANDIDATE;
        for _ in 0..tries {
            let rotation = approach::random_orientation(rng, &mean, cone);
            let phase = std::f64::consts::TAU * rng.random::<f64>();
            if n == 0 {
                // Only a reference orientation for the rotation group: one
                // that reaches P0.
                if !self
                    .candidates_at(p0, &rotation, &c.centre(1), 1)
                    .is_empty()
                {
                    return Ok((Vec::new(), rotation));
                }
                continue;
            }
            // Directions 120° apart for 4 translations (the simulator's).
            #[allow(clippy::cast_precision_loss)]
            let step = std::f64::consts::TAU / (n - 1) as f64;
            let first = c.centre(1);
            let centres: Vec<Vector3<f64>> = (0..n)
                .map(|k| {
                    if k == 0 {
                        first
                    } else {
                        #[allow(clippy::cast_precision_loss)]
                        let angle = phase + step * (k - 1) as f64;
                        first
                            + Vector3::new(
                                0.0,
                                c.translation_step * angle.cos(),
                                c.translation_step * angle.sin(),
                            )
                    }
                })
                .collect();
            for start in self.candidates_at(p0, &rotation, &first, 1) {
                let mut poses = vec![start.clone()];
                let mut previous = start.joints;
                for centre in &centres[1..] {
                    let target = self.target(p0, &rotation, centre);
                    let Some(q) =
                        self.chain
                            .solve_from(&target, &previous, &c.limits, c.min_wrist_angle)
                    else {
                        break;
                    };
                    if joint_gap(&q, &previous) > TRANSLATION_SAME_BRANCH_DEG
                        || !self.sees(&q, p0, centre)
                    {
                        break;
                    }
                    previous = q;
                    poses.push(Candidate {
                        joints: q,
                        side: 1,
                        centre: *centre,
                        rotation,
                    });
                }
                if poses.len() == n {
                    check_translations(&self.config.robot, &poses)?;
                    return Ok((poses, rotation));
                }
            }
        }
        Err(self.unreachable("P0", p0, tries))
    }

    /// The rotation group at `P0`: candidates turned `rotation_min..max`
    /// about random axes from `reference`, sides alternating; greedy on
    /// `ln det` of eq. 8's normal matrix, pairs at least 15° apart.
    fn rotation_group(
        &self,
        rng: &mut ChaCha8Rng,
        p0: &Vector3<f64>,
        reference: &UnitQuaternion<f64>,
    ) -> Result<Vec<Candidate>, PlanError> {
        let c = self.config;
        let n = c.n_rotation;
        if n == 0 {
            return Ok(Vec::new());
        }
        let draws = c.candidates.max(n) * 2;
        let mut pool: Vec<Candidate> = Vec::new();
        for k in 0..draws {
            let axis = Unit::new_normalize(approach::direction_in_cone(
                rng,
                &Vector3::z(),
                std::f64::consts::PI,
            ));
            let angle = random::uniform(rng, c.rotation_min, c.rotation_max).to_radians();
            let rotation = reference * UnitQuaternion::from_axis_angle(&axis, angle);
            let side = if k % 2 == 0 { 1 } else { -1 };
            // One branch per orientation: the eq. 8 rows depend on the
            // orientation only.
            let centre = c.centre(side) + self.offset(rng);
            if let Some(first) = self
                .candidates_at(p0, &rotation, &centre, side)
                .into_iter()
                .next()
            {
                pool.push(first);
            }
        }
        let mut chosen: Vec<usize> = Vec::new();
        while chosen.len() < n {
            let mut best: Option<(f64, usize)> = None;
            for (i, cand) in pool.iter().enumerate() {
                let distinct = chosen.iter().all(|&j| {
                    pool[j].rotation.angle_to(&cand.rotation)
                        >= MIN_ROTATION_SEPARATION_DEG.to_radians()
                });
                let used = chosen
                    .iter()
                    .filter(|&&j| pool[j].side == cand.side)
                    .count();
                if chosen.contains(&i) || !distinct || used >= side_quota(n, cand.side) {
                    continue;
                }
                let mut set: Vec<&Candidate> = chosen.iter().map(|&j| &pool[j]).collect();
                set.push(cand);
                let value = rotation_criterion(&self.config.robot, &set);
                if best.is_none_or(|(b, _)| value > b) {
                    best = Some((value, i));
                }
            }
            match best {
                Some((_, i)) => chosen.push(i),
                None => {
                    // The side still short of its quota.
                    let plus = chosen.iter().filter(|&&j| pool[j].side == 1).count();
                    let side: i8 = if plus < side_quota(n, 1) { 1 } else { -1 };
                    let found = chosen.iter().filter(|&&j| pool[j].side == side).count();
                    return Err(PlanError::TooFewPoses {
                        station: "P0".to_owned(),
                        position: [p0.x, p0.y, p0.z],
                        side,
                        found,
                        needed: side_quota(n, side),
                    });
                }
            }
        }
        Ok(chosen.into_iter().map(|i| pool[i].clone()).collect())
    }

    /// An identify or validate station's first pose: the candidate on side
    /// +1 whose approach is closest to the mean approach.
    fn first_pose(&self, site: &Site) -> Option<usize> {
        let mean = self.mean_approach(&site.position);
        site.candidates
            .iter()
            .enumerate()
            .filter(|(_, c)| c.side == 1)
            .map(|(i, c)| (i, (c.rotation * Vector3::z()).dot(&mean)))
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(i, _)| i)
    }

    /// The estimate the criterion linearises about: nominal model, guess.
    fn estimate(&self) -> Estimate {
        Estimate {
            robot: self.config.robot.clone(),
            flange_from_sensor: self.config.flange_from_sensor,
        }
    }

    fn sighting(id: &str, c: &Candidate) -> Sighting {
        Sighting {
            id: id.to_owned(),
            joints: c.joints.to_vec(),
            centre_in_sensor: c.centre,
        }
    }

    /// The sensor-frame covariance of a planned centre on `side`.
    fn sensor_covariance(&self, side: i8) -> Matrix3<f64> {
        stripe_centre_covariance(
            self.config.radius(),
            self.config.cut_angle,
            side,
            self.config.stripe_sigma,
        )
    }

    fn info(&self, c: &Candidate, estimated: &[usize]) -> Info {
        let est = self.estimate();
        let s = Self::sighting("candidate", c);
        let (_, full) = sensitivity(&est, &s);
        let a = DMatrix::from_fn(3, estimated.len(), |i, j| {
            full[(i, estimated[j])] / unknown_scale(estimated[j])
        });
        let cov = ml::noise::base_covariance(
            &est,
            &s,
            &self.sensor_covariance(c.side),
            self.config.joint_sigma_deg,
        );
        let w = cov.try_inverse().unwrap_or_else(Matrix3::zeros);
        Info { a, w }
    }

    /// A session and its prepared centres for `ml`'s analysis: the given
    /// poses at their stations, reference distances between consecutive
    /// validate stations, the planned centres with the stripe covariance.
    fn analysis_input(
        &self,
        poses: &[(String, Use, Candidate)],
        validate: &[(String, Vector3<f64>)],
    ) -> (Session, Prepared) {
        let c = self.config;
        let mut measurements = Vec::with_capacity(poses.len());
        let mut prepared = Vec::with_capacity(poses.len());
        for (index, (station, usage, cand)) in poses.iter().enumerate() {
            measurements.push(Measurement {
                id: format!("m{}", index + 1),
                station: station.clone(),
                usage: *usage,
                side_given: Some(cand.side),
                side: cand.side,
                joints: cand.joints.to_vec(),
                observation: Observation::Centre(cand.centre),
            });
            prepared.push(solve::PreparedMeasurement {
                index,
                centre_in_sensor: cand.centre,
                covariance: Some(self.sensor_covariance(cand.side)),
                stripe: None,
            });
        }
        let reference_distances = validate
            .windows(2)
            .map(|w| ReferenceDistance {
                from: w[0].0.clone(),
                to: w[1].0.clone(),
                distance: (w[1].1 - w[0].1).norm(),
            })
            .collect();
        let session = Session {
            name: "plan".to_owned(),
            name_given: true,
            robot: c.robot.clone(),
            base_given: false,
            flange_given: false,
            sphere_diameter: c.diameter,
            default_side: 1,
            sensor_given: false,
            hand_eye: Some(c.flange_from_sensor),
            solver: SolverSettings::default(),
            solver_given: false,
            reference_distances,
            measurements,
        };
        let prepared = Prepared {
            measurements: prepared,
            hand_eye_initial: c.flange_from_sensor,
            hand_eye_source: HandEyeSource::File,
            warnings: Vec::new(),
        };
        (session, prepared)
    }

    /// `ml`'s analysis (no update: the nominal model fits the planned
    /// centres exactly) of a session.
    fn analyse(&self, session: &Session, prepared: &Prepared) -> Result<MlReport, PlanError> {
        let options = Options {
            method: Method::Ml,
            threshold: 0.0,
            max_iterations: 0,
            paper: Default::default(),
            ml: MlOptions {
                joint_sigma_deg: self.config.joint_sigma_deg,
                cross_validation: false,
                ..MlOptions::default()
            },
        };
        ml::analyse(session, prepared, &options).map_err(|e| PlanError::Analysis(e.to_string()))
    }

    /// `ml`'s analysis of every identify candidate.
    fn pool_report(&self, sites: &[Site]) -> Result<MlReport, PlanError> {
        let poses: Vec<(String, Use, Candidate)> = sites
            .iter()
            .enumerate()
            .filter(|(_, s)| s.role == StationRole::Identify)
            .flat_map(|(k, s)| {
                s.candidates
                    .iter()
                    .map(move |c| (format!("S{k}"), Use::Identify, c.clone()))
            })
            .collect();
        let (session, prepared) = self.analysis_input(&poses, &[]);
        self.analyse(&session, &prepared)
    }

    /// `ml`'s analysis of the plan's identify and validate poses.
    fn plan_report(&self, plan: &Plan) -> Result<MlReport, PlanError> {
        let poses: Vec<(String, Use, Candidate)> = plan
            .poses
            .iter()
            .filter(|p| matches!(p.usage, Use::Identify | Use::Validate))
            .map(|p| (p.station.clone(), p.usage, pose_candidate(p)))
            .collect();
        let validate: Vec<(String, Vector3<f64>)> = plan
            .stations
            .iter()
            .filter(|s| s.role == StationRole::Validate)
            .map(|s| (s.id.clone(), s.position))
            .collect();
        let (session, prepared) = self.analysis_input(&poses, &validate);
        self.analyse(&session, &prepared)
    }

    /// Condition number of the whitened, scaled Jacobian of `estimated`
    /// over the plan's identify poses (station centres eliminated).
    fn condition(&self, plan: &Plan, estimated: &[usize]) -> f64 {
        let k = estimated.len();
        let mut m = DMatrix::zeros(k, k);
        for s in plan
            .stations
            .iter()
            .filter(|s| s.role == StationRole::Identify)
        {
            let infos: Vec<Info> = plan
                .poses
                .iter()
                .filter(|p| p.station == s.id && p.usage == Use::Identify)
                .map(|p| self.info(&pose_candidate(p), estimated))
                .collect();
            let all: Vec<usize> = (0..infos.len()).collect();
            m += StationInfo::of(&infos, &all, k).schur();
        }
        let eig = nalgebra::SymmetricEigen::new(m).eigenvalues;
        let max = eig.iter().copied().fold(0.0_f64, f64::max);
        let min = eig.iter().copied().fold(f64::INFINITY, f64::min);
        if min > 0.0 {
            (max / min).sqrt()
        } else {
            f64::INFINITY
        }
    }
}

fn pose_candidate(p: &PlannedPose) -> Candidate {
    let mut joints = [0.0; DOF];
    for (j, v) in joints.iter_mut().zip(&p.joints) {
        *j = *v;
    }
    Candidate {
        joints,
        side: p.side,
        centre: p.centre_in_sensor,
        rotation: p.base_from_flange.rotation,
    }
}

/// The collinearity check of eq. 6-7 on the planned translations.
fn check_translations(robot: &Robot, poses: &[Candidate]) -> Result<(), PlanError> {
    let p: Vec<Vector3<f64>> = poses
        .iter()
        .map(|c| robot.base_from_flange(&c.joints).translation.vector)
        .collect();
    let d = DMatrix::from_fn(3, p.len() - 1, |i, k| p[k + 1][i] - p[0][i]);
    let sv = d.singular_values();
    let (s1, s2) = (sv[0], if sv.len() > 1 { sv[1] } else { 0.0 });
    if s1 <= 0.0 || s2 / s1 < MIN_TRANSLATION_SPREAD {
        return Err(PlanError::CollinearTranslations {
            detail: format!(
                "the flange displacements have σ₂/σ₁ = {:.3} (at least {MIN_TRANSLATION_SPREAD} needed)",
                if s1 > 0.0 { s2 / s1 } else { 0.0 }
            ),
        });
    }
    Ok(())
}

/// Covariance (mm², sensor frame) of the sphere centre of a stripe whose
/// laser plane cuts a sphere of `radius` at `cut_deg`, with `sigma` (mm)
/// noise on the points: the circle fit's `(y_c, z_c, r)` covariance
/// `σ²·(JᵀJ)⁻¹` for the points the simulator draws (the arc facing the
/// camera, 0.5 mm apart over ±55°), carried to `x = side·sqrt(R² − r²)`
/// (eq. 21: `∂x/∂r = −side·r/t`).
#[must_use]
pub fn stripe_centre_covariance(radius: f64, cut_deg: f64, side: i8, sigma: f64) -> Matrix3<f64> {
    let sim = SimConfig::default();
    let r = radius * cut_deg.to_radians().cos();
    let t = radius * cut_deg.to_radians().sin();
    let half = sim.arc_half_angle.to_radians();
    let arc = 2.0 * half * r;
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let n = ((arc / sim.point_spacing).floor().max(0.0) as usize + 1).max(3);
    let mut jtj = Matrix3::zeros();
    for k in 0..n {
        #[allow(clippy::cast_precision_loss)]
        let phi = -half + 2.0 * half * k as f64 / (n - 1) as f64;
        // Residual of a point along the circle normal: ∂/∂(y_c, z_c, r).
        let row = Vector3::new(-phi.sin(), -phi.cos(), -1.0);
        jtj += row * row.transpose();
    }
    let fit = jtj.try_inverse().unwrap_or_else(Matrix3::zeros) * sigma * sigma;
    // (x, y, z) from (y_c, z_c, r).
    let dx_dr = -f64::from(side) * r / t;
    let jac = Matrix3::new(0.0, 0.0, dx_dr, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0);
    jac * fit * jac.transpose()
}

/// How [`predict`] simulates the plan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PredictConfig {
    /// Simulated calibrations.
    pub runs: usize,
    /// Seed of the first run; run `k` uses `seed + k`.
    pub seed: u64,
    /// Kinematic errors of the true robots.
    pub errors: ErrorModel,
    /// Multiplies them.
    pub error_scale: f64,
    /// σ of the joint reading noise, deg.
    pub joint_noise: f64,
    /// σ of the stripe point noise, mm.
    pub stripe_noise: f64,
    /// σ of the laser-tracker reference distances, mm.
    pub tracker_noise: f64,
    /// Whether the poses run as planned or are touched up.
    pub execution: PlanExecution,
}

impl Default for PredictConfig {
    /// 5 runs of random kinematic errors (σ 0.1°, 0.3 mm) with the
    /// simulator's default noise.
    fn default() -> Self {
        let sim = SimConfig::default();
        Self {
            runs: 5,
            seed: 1,
            errors: ErrorModel::Random,
            error_scale: 1.0,
            joint_noise: sim.joint_noise,
            stripe_noise: sim.stripe_noise,
            tracker_noise: sim.tracker_noise,
            execution: PlanExecution::AsPlanned,
        }
    }
}

/// The score of one simulated calibration of a plan (validation std of
/// the distances against the true station distances, mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunScore {
    /// Seed of the run.
    pub seed: u64,
    /// Nominal model, initial hand-eye.
    pub before_std: f64,
    /// Calibrated (`ml`).
    pub after_std: f64,
    /// True model and hand-eye on the same data: the noise floor.
    pub floor_std: f64,
}

/// The predicted accuracy of a plan.
#[derive(Debug, Clone, PartialEq)]
pub struct Prediction {
    /// Every run.
    pub runs: Vec<RunScore>,
    /// Mean validation std after calibration, mm.
    pub after_mean: f64,
    /// Sample std of it over the runs, mm (0 for one run).
    pub after_spread: f64,
    /// Mean noise floor, mm.
    pub floor_mean: f64,
    /// Mean of `after / floor` over the runs.
    pub ratio_mean: f64,
    /// Mean validation std before calibration, mm.
    pub before_mean: f64,
}

/// The true hand-eye of a simulated run: the plan's guess moved by the
/// paper's own guess error (initial → calibrated hand-eye, section 4.2),
/// so that the default guess gives the paper's calibrated hand-eye.
#[must_use]
pub fn simulated_true_hand_eye(guess: &Isometry3<f64>) -> Isometry3<f64> {
    guess * sensor::paper_initial_hand_eye().inverse() * sensor::paper_hand_eye()
}

/// Predicted calibrated accuracy of a plan: `runs` simulations of its
/// poses ([`simulate::simulate_plan`]) on true robots with seeded random
/// kinematic errors and the true hand-eye of [`simulated_true_hand_eye`],
/// each calibrated with the default method (`ml`, leave-one-station-out
/// cross-validation skipped: it does not change the estimate) and scored
/// against the true station distances ([`evaluate::score`]). `progress`
/// sees `(runs done, runs)` and may cancel.
///
/// # Errors
/// [`PlanError::InvalidConfig`] without 2 validate stations or runs,
/// [`PlanError::Prediction`] when a run fails, [`PlanError::Cancelled`].
pub fn predict(
    plan: &Plan,
    config: &PredictConfig,
    progress: &mut dyn FnMut(usize, usize) -> Control,
) -> Result<Prediction, PlanError> {
    let validate = plan
        .stations
        .iter()
        .filter(|s| s.role == StationRole::Validate)
        .count();
    check(validate >= 2, || {
        format!(
            "the prediction scores distances between validate stations: the plan has {validate}, at least 2 are needed"
        )
    })?;
    check(config.runs >= 1, || {
        "the prediction needs at least one run".to_owned()
    })?;
    let poses = plan.simulation_poses();
    let truth_hand_eye = simulated_true_hand_eye(&plan.flange_from_sensor);
    let hand_eye_groups = plan.count(Use::Translation) > 0;
    let mut runs = Vec::with_capacity(config.runs);
    for k in 0..config.runs {
        let seed = config.seed + k as u64;
        let fail = |message: String| PlanError::Prediction {
            run: k + 1,
            seed,
            message,
        };
        let sim = SimConfig {
            seed,
            errors: config.errors,
            error_scale: config.error_scale,
            joint_noise: config.joint_noise,
            stripe_noise: config.stripe_noise,
            tracker_noise: config.tracker_noise,
            diameter: plan.diameter,
            initial_hand_eye: if hand_eye_groups {
                InitialHandEye::None
            } else {
                InitialHandEye::Paper
            },
            ..SimConfig::default()
        };
        let (mut session, truth) =
            simulate::simulate_plan(&sim, &plan.robot, &truth_hand_eye, &poses, config.execution)
                .map_err(|e| fail(e.to_string()))?;
        if !hand_eye_groups {
            session.hand_eye = Some(plan.flange_from_sensor);
        }
        let mut options = Options::from_session(&session);
        options.ml.cross_validation = false;
        let prepared = solve::prepare(&session).map_err(|e| fail(e.to_string()))?;
        let cal = solve::run(&session, &prepared, &options, &mut |_| Control::Continue)
            .map_err(|e| fail(e.to_string()))?;
        let score = evaluate::score(&session, &prepared, &truth, &cal.calibrated, &cal.hand_eye);
        runs.push(RunScore {
            seed,
            before_std: score.before.std,
            after_std: score.after.std,
            floor_std: score.floor.std,
        });
        if progress(k + 1, config.runs) == Control::Cancel {
            return Err(PlanError::Cancelled);
        }
    }
    #[allow(clippy::cast_precision_loss)]
    let n = runs.len() as f64;
    let mean = |f: &dyn Fn(&RunScore) -> f64| runs.iter().map(f).sum::<f64>() / n;
    let after_mean = mean(&|r| r.after_std);
    let after_spread = if runs.len() >= 2 {
        (runs
            .iter()
            .map(|r| (r.after_std - after_mean).powi(2))
            .sum::<f64>()
            / (n - 1.0))
            .sqrt()
    } else {
        0.0
    };
    Ok(Prediction {
        after_mean,
        after_spread,
        floor_mean: mean(&|r| r.floor_std),
        ratio_mean: mean(&|r| r.after_std / r.floor_std),
        before_mean: mean(&|r| r.before_std),
        runs,
    })
}

/// A few lines for people (the command line's summary).
#[must_use]
pub fn summary(plan: &Plan) -> String {
    let mut s = String::new();
    let st = &plan.stats;
    let stations = |role| plan.stations.iter().filter(|s| s.role == role).count();
    let _ = writeln!(
        s,
        "plan for {}: {} poses: {} translation, {} rotation at P0; {} identify at {} stations; {} validate at {} stations",
        plan.robot.name,
        plan.poses.len(),
        plan.count(Use::Translation),
        plan.count(Use::Rotation),
        plan.count(Use::Identify),
        stations(StationRole::Identify),
        plan.count(Use::Validate),
        stations(StationRole::Validate)
    );
    let _ = writeln!(
        s,
        "  reachable candidates: {} (IK branches within limits, laser plane at ±{}°)",
        st.candidates, plan.cut_angle
    );
    let _ = writeln!(
        s,
        "  identification: ln det {:.2} (random selection of the same size: {:.2}, gain {:.2}), condition number {:.3e}",
        st.log_det,
        st.log_det_random,
        st.log_det - st.log_det_random,
        st.condition
    );
    let _ = writeln!(
        s,
        "  identifies {} of {} parameters; cannot identify: {}",
        st.estimated.len(),
        st.estimated.len() + st.fixed.len(),
        if st.fixed.is_empty() {
            "none".to_owned()
        } else {
            st.fixed.join(", ")
        }
    );
    for c in &st.inseparable {
        let _ = writeln!(s, "    {c}");
    }
    if let Some(v) = st.predicted_validation_std {
        let _ = writeln!(
            s,
            "  expected validation std after calibration (ml covariance): {v:.4} mm"
        );
    }
    let _ = writeln!(
        s,
        "  path: {:.0} deg of weighted joint moves ({:.0} deg before ordering)",
        st.path_deg, st.path_unordered_deg
    );
    s
}
