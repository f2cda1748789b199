//! Seeded ground-truth sessions for tests, demos and what-if studies.
//!
//! [`simulate`] builds a [`Session`] as a real cell would record it, and the
//! [`Truth`] it was made from: the true kinematic model (nominal plus
//! errors, paper Table 1 by default), the true hand-eye (the paper's
//! calibrated one, section 4.2), every sphere station in the base frame,
//! the actual joint angles and the exact sensor-frame centres.
//!
//! # Geometry (shared/paper/NOTES.md, "Geometry of the paper's setup")
//!
//! - The sensor origin sits ~288 mm out along the flange z axis with the
//!   sensor z axis pointing back toward the flange, so the sphere is seen
//!   near the sensor origin: sensor-frame centres
//!   `(side · R · sin(cut), ±2, ±3)` mm with the cut angle ~40° (± a few
//!   degrees of jitter) on both sides of the laser plane.
//! - A stripe is the arc of the cut circle (centre `(y, z)` of the sensor
//!   centre, radius `sqrt(R² − x²)`) that faces a camera at sensor
//!   `(0, 0, view_z)`, `arc_half_angle` either side, one point every
//!   `point_spacing` mm of arc, Gaussian noise on both coordinates, rounded.
//! - Stations lie in a per-robot [`Workspace`] box: the translation and
//!   rotation station `P0` at its centre, the identify stations `P1..` on a
//!   3×3 Latin square of x, y and z levels (the paper's "3 layers along X,
//!   Y, Z"; beyond 9 stations uniformly in the box), the validate stations
//!   `V1..` uniformly in the box.
//! - Every pose is reached by inverse kinematics on the **true** model
//!   within the joint limits and away from the wrist singularity. Its
//!   approach direction (flange z) is drawn uniformly in a cone of
//!   `cone_angle` around the direction from the workspace's eye point to
//!   the station, with a uniform rotation about the approach axis; this
//!   orientation spread is what makes the kinematic errors identifiable.
//! - Translation measurements (paper 3.1) keep one orientation and move
//!   the flange by 15-20 mm in directions 120° apart in the sensor's y-z
//!   plane; rotation measurements turn that orientation by 20-45° about
//!   random axes.
//!
//! # Randomness
//!
//! One seed drives three independent ChaCha8 streams: geometry (stations,
//! poses), kinematic errors, and measurement noise. Changing a noise level
//! therefore leaves every pose unchanged, and the same configuration always
//! gives byte-identical files.

use std::collections::HashSet;
use std::f64::consts::PI;
use std::fmt;
use std::marker::PhantomData;
use std::ops::ControlFlow;
use std::path::Path;

use nalgebra::{
    Isometry3, Matrix3, Point3, Rotation3, Translation3, Unit, UnitQuaternion, Vector3,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use serde::de::{MapAccess, Visitor};
use serde::ser::SerializeMap;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::error::FileError;
use super::geometry::{MatrixError, isometry_from_rows, rows_from_isometry};
use super::ik::{Chain, DOF, wrap_deg};
use super::kinematics::{self, Joint, JointLimit, Robot};
use super::model::{
    DEFAULT_MAX_ITERATIONS, DEFAULT_THRESHOLD, Measurement, Observation, ReferenceDistance,
    Session, SolverSettings, Use,
};

/// `"format"` of a truth file.
pub const TRUTH_FORMAT: &str = "spherecal-truth";
/// `"version"` of the truth files this module writes and reads.
pub const TRUTH_VERSION: u32 = 1;

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

/// The paper's calibrated hand-eye `eT_s` (section 4.2), rows of the 3×4
/// block as printed (rotation to 4 decimals, not quite orthonormal; see
/// [`paper_hand_eye`]). Translation in mm.
pub const PAPER_HAND_EYE_ROWS: [[f64; 4]; 3] = [
    [0.8703, 0.4925, -0.0108, -7.442],
    [0.4921, -0.8702, -0.0227, -1.012],
    [-0.0205, 0.0144, -0.9997, 287.804],
];

/// The paper's *initial* hand-eye (section 4.2, from eq. 7 and 9), rows of
/// the 3×4 block as printed. Written into a session when
/// [`InitialHandEye::Paper`] is chosen.
pub const PAPER_INITIAL_HAND_EYE_ROWS: [[f64; 4]; 3] = [
    [0.8704, 0.4921, -0.0133, -7.4422],
    [0.4917, -0.8704, -0.0235, -1.012],
    [-0.0231, 0.0139, -0.9996, 287.818],
];

/// σ of the `random` kinematic errors for angles (alpha, beta, theta), deg,
/// at `error_scale = 1`: the size of the paper's Table 1 angle errors
/// (most within ±0.5°, median ~0.08°).
pub const RANDOM_ANGLE_SIGMA_DEG: f64 = 0.1;
/// σ of the `random` kinematic errors for lengths (a, d), mm, at
/// `error_scale = 1`: Table 1's length errors are within ±0.7 mm.
pub const RANDOM_LENGTH_SIGMA_MM: f64 = 0.3;

/// Kinematic errors are rounded to this many decimals (0.1 µm, 1e-4°),
/// as printed in Table 1, so the truth file states them exactly.
const ERROR_DECIMALS: i32 = 4;
/// Recorded joint readings are rounded to this many decimals: 1e-9° moves
/// a point 1.5 m from the axis by 3e-8 mm, so a noise-free session stays
/// exact to well under 1e-6 mm (the engine's exactness tests) while the
/// file stays readable.
const JOINT_DECIMALS: i32 = 9;
/// Reference distances are rounded to this many decimals, for the same
/// reason (1e-9 mm, far below a laser tracker's resolution).
const DISTANCE_DECIMALS: i32 = 9;
/// Hand-eye matrices are written with this many decimals: 1e-12 keeps the
/// rotation orthonormal to ~1e-12, far inside FORMAT.md's 1e-6 check.
const HAND_EYE_DECIMALS: i32 = 12;
/// Sensor-frame centre y spread (mm): centres are drawn in `±2` mm, as
/// NOTES.md describes the paper's measurements.
const CENTRE_Y_SPREAD: f64 = 2.0;
/// Sensor-frame centre z spread (mm): `±3` mm, NOTES.md.
const CENTRE_Z_SPREAD: f64 = 3.0;
/// FORMAT.md: a stripe needs at least 5 points.
const MIN_STRIPE_POINTS: usize = 5;
/// Orientations tried for one pose before the station is declared
/// unreachable. Reachable cones succeed within a few tries; 400 keeps a
/// bad workspace from looping long (each try is at most a few IK runs).
const MAX_POSE_ATTEMPTS: usize = 400;
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
/// Two rotation measurements differ in orientation by at least this much
/// (deg), so eq. 8-9 get distinct rows.
const MIN_ROTATION_SEPARATION_DEG: f64 = 15.0;

/// Robot preset to simulate (FORMAT robot blocks from
/// [`kinematics::preset`]).
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

    /// The preset key of [`kinematics::preset`].
    #[must_use]
    pub fn key(self) -> &'static str {
        match self {
            Self::Irb2400 => "irb2400",
            Self::Irb120 => "irb120",
            Self::Ur5e => "ur5e",
        }
    }
}

/// Where the true kinematic model comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ErrorModel {
    /// The paper's Table 1 ([`TABLE1`]) times `error_scale`.
    #[default]
    Table1,
    /// Independent Gaussian errors: σ = [`RANDOM_ANGLE_SIGMA_DEG`]·scale for
    /// alpha, beta, theta and [`RANDOM_LENGTH_SIGMA_MM`]·scale for a, d, on
    /// every joint (d1 and theta1 too, although sphere data cannot see them).
    Random,
    /// The true model is the nominal one.
    None,
}

/// On which side of the laser plane the sphere centres lie.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SideChoice {
    /// Both sides, balanced within each station (NOTES.md: one side only is
    /// badly conditioned).
    #[default]
    Mixed,
    /// Every centre at sensor `x > 0`.
    Plus,
    /// Every centre at sensor `x < 0`.
    Minus,
}

/// Which initial hand-eye, if any, the session file carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum InitialHandEye {
    /// None: the engine computes it from the translation and rotation
    /// measurements (paper 3.1).
    #[default]
    None,
    /// The paper's initial hand-eye ([`PAPER_INITIAL_HAND_EYE_ROWS`]).
    Paper,
    /// The true hand-eye (a perfect start, for tests).
    Truth,
}

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

    fn centre(&self) -> Vector3<f64> {
        self.lerp([0.5; 3])
    }

    fn diagonal(&self) -> f64 {
        (Vector3::from(self.max) - Vector3::from(self.min)).norm()
    }
}

/// Every knob of the simulator. `Default` is the paper-like demo: the IRB
/// 2400 with Table 1 errors, 9 identify stations and 10 validate stations
/// of 6 poses, 4 translations and 6 rotations, joint noise 0.003°, stripe
/// noise 0.02 mm, both sides of the laser plane. Echoed as `config` in the
/// truth file; missing keys take the defaults and unknown keys are ignored
/// when a truth file is read (so other simulators' truth files load).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SimConfig {
    /// Seed of every random choice; same configuration ⇒ same files.
    pub seed: u64,
    /// Session name; `None` gives "simulated <robot>, seed <seed>".
    #[serde(skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Robot preset.
    pub robot: RobotChoice,
    /// Kinematic error model of the true robot.
    pub errors: ErrorModel,
    /// Multiplies the kinematic errors (`table1` and `random`).
    pub error_scale: f64,
    /// Initial hand-eye written into the session.
    pub initial_hand_eye: InitialHandEye,
    /// Number of identify stations (`P1..`).
    pub n_identify: usize,
    /// Number of validate stations (`V1..`).
    pub n_validate: usize,
    /// Measurements per identify or validate station.
    pub poses_per_station: usize,
    /// Translation measurements at `P0` (paper: 4).
    pub n_translation: usize,
    /// Rotation measurements at `P0` (paper: 6).
    pub n_rotation: usize,
    /// σ of the joint reading noise, deg (recorded = actual + noise).
    pub joint_noise: f64,
    /// σ of the stripe point noise on each coordinate, mm.
    pub stripe_noise: f64,
    /// Fraction of stripe points made outliers, 0..1.
    pub outlier_fraction: f64,
    /// Smallest outlier displacement (along the circle's normal), mm.
    pub outlier_min: f64,
    /// Largest outlier displacement, mm.
    pub outlier_max: f64,
    /// Stripe point spacing along the arc, mm.
    pub point_spacing: f64,
    /// Half-angle of the visible stripe arc, deg.
    pub arc_half_angle: f64,
    /// Sensor z (mm) of the camera the visible arc faces.
    pub view_z: f64,
    /// The cut angle: the sphere centre lies at sensor-frame
    /// `|x| = R · sin(cut)`, deg (paper 4.1: about ±40°).
    pub cut_angle: f64,
    /// Uniform jitter of the cut angle, ± deg.
    pub cut_jitter: f64,
    /// Write sphere centres instead of stripes.
    pub centres: bool,
    /// σ of the centre noise on each coordinate (centres mode), mm.
    pub centre_noise: f64,
    /// Sides of the laser plane.
    pub side: SideChoice,
    /// σ of the laser-tracker reference distances, mm.
    pub tracker_noise: f64,
    /// Sphere diameter, mm (paper: 38.1).
    pub diameter: f64,
    /// Solver threshold written into the session, mm.
    pub threshold: f64,
    /// Solver iteration bound written into the session.
    pub max_iterations: usize,
    /// Decimals of the written stripe points and centres.
    pub stripe_decimals: i32,
    /// Half-angle of the cone of approach directions, deg. Default 45°:
    /// the orientation spread is what identifies the kinematic errors (with
    /// the paper's method, 9 stations, validation error over the noise
    /// floor fell from ~2.7× at 25° to ~2.0× at 45° and ~1.5× at 60° in
    /// 8-seed trials).
    pub cone_angle: f64,
    /// Smallest `|q5|` (deg) away from the wrist singularity.
    pub min_wrist_angle: f64,
    /// Flange displacement of the translation measurements, smallest, mm.
    pub translation_min: f64,
    /// Flange displacement of the translation measurements, largest, mm.
    pub translation_max: f64,
    /// Orientation change of the rotation measurements, smallest, deg.
    pub rotation_min: f64,
    /// Orientation change of the rotation measurements, largest, deg.
    pub rotation_max: f64,
    /// Station box and eye point; `None` is [`Workspace::for_robot`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub workspace: Option<Workspace>,
}

impl Default for SimConfig {
    fn default() -> Self {
        Self {
            seed: 1,
            name: None,
            robot: RobotChoice::Irb2400,
            errors: ErrorModel::Table1,
            error_scale: 1.0,
            initial_hand_eye: InitialHandEye::None,
            n_identify: 9,
            n_validate: 10,
            poses_per_station: 6,
            n_translation: 4,
            n_rotation: 6,
            joint_noise: 0.003,
            stripe_noise: 0.02,
            outlier_fraction: 0.0,
            outlier_min: 0.3,
            outlier_max: 3.0,
            point_spacing: 0.5,
            arc_half_angle: 55.0,
            view_z: 150.0,
            cut_angle: 40.0,
            cut_jitter: 3.0,
            centres: false,
            centre_noise: 0.01,
            side: SideChoice::Mixed,
            tracker_noise: 0.01,
            diameter: 38.1,
            threshold: DEFAULT_THRESHOLD,
            max_iterations: DEFAULT_MAX_ITERATIONS,
            stripe_decimals: 4,
            cone_angle: 45.0,
            min_wrist_angle: 10.0,
            translation_min: 15.0,
            translation_max: 20.0,
            rotation_min: 20.0,
            rotation_max: 45.0,
            workspace: None,
        }
    }
}

/// Why [`simulate`] could not build a session.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    /// A setting is out of range; the message names it.
    #[error("invalid simulation setting: {0}")]
    InvalidConfig(String),
    /// No orientation in the cone reached a station within the joint
    /// limits and away from the wrist singularity.
    #[error(
        "station {station} at [{:.1}, {:.1}, {:.1}] mm (base) is out of reach: no pose found in {attempts} orientations; use a smaller workspace or cone",
        position[0], position[1], position[2]
    )]
    Unreachable {
        /// Station id.
        station: String,
        /// Station centre, base frame, mm.
        position: [f64; 3],
        /// Orientations tried.
        attempts: usize,
    },
    /// A pose of a plan does not see the sphere on the true robot: the
    /// sphere centre falls outside the usable cut of the laser plane.
    #[error(
        "pose {id}: on the true robot the sphere centre lies at sensor x = {x:.2} mm, outside the usable cut on side {side:+} ({lo:.2} to {hi:.2} mm from the laser plane); the true robot or hand-eye is too far from the plan's nominal ones: touch the poses up (--touch-up), use smaller errors (--errors random, --error-scale), or the plan's robot and hand-eye"
    )]
    PlanMiss {
        /// Measurement id.
        id: String,
        /// Sensor-frame x of the sphere centre, mm.
        x: f64,
        /// The planned side, +1 or −1.
        side: i8,
        /// Smallest usable `|x|`, mm.
        lo: f64,
        /// Largest usable `|x|`, mm.
        hi: f64,
    },
}

/// Why a truth file could not be read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TruthError {
    /// Not valid JSON or not the truth file's shape.
    #[error("not a valid truth file: {0}")]
    Syntax(String),
    /// `format` is not `spherecal-truth`.
    #[error("\"format\" is {0:?}, expected \"{TRUTH_FORMAT}\"")]
    Format(String),
    /// `version` is not one this build reads.
    #[error("truth file version {0} is not supported (this build reads version {TRUTH_VERSION})")]
    Version(u32),
    /// A 4×4 matrix is not a rigid transform.
    #[error("{what}: {source}")]
    Matrix {
        /// Which matrix.
        what: String,
        /// What is wrong with it.
        source: MatrixError,
    },
    /// Parts of the file disagree (joint counts, unknown station ids).
    #[error("{0}")]
    Inconsistent(String),
}

/// A map written as a JSON object whose keys keep their insertion order
/// (stations and measurements in file order). Duplicate keys are an error
/// on reading.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct OrderedMap<V>(pub Vec<(String, V)>);

impl<V> OrderedMap<V> {
    /// The value under `key`, if any.
    #[must_use]
    pub fn get(&self, key: &str) -> Option<&V> {
        self.0.iter().find(|(k, _)| k == key).map(|(_, v)| v)
    }

    /// Entries in order.
    pub fn iter(&self) -> impl Iterator<Item = (&str, &V)> {
        self.0.iter().map(|(k, v)| (k.as_str(), v))
    }

    /// Number of entries.
    #[must_use]
    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// True when there are no entries.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

impl<V: Serialize> Serialize for OrderedMap<V> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut map = serializer.serialize_map(Some(self.0.len()))?;
        for (k, v) in &self.0 {
            map.serialize_entry(k, v)?;
        }
        map.end()
    }
}

impl<'de, V: Deserialize<'de>> Deserialize<'de> for OrderedMap<V> {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct MapVisitor<V>(PhantomData<V>);
        impl<'de, V: Deserialize<'de>> Visitor<'de> for MapVisitor<V> {
            type Value = OrderedMap<V>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("an object")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut access: A) -> Result<Self::Value, A::Error> {
                let mut entries: Vec<(String, V)> = Vec::new();
                let mut seen = HashSet::new();
                while let Some((k, v)) = access.next_entry::<String, V>()? {
                    if !seen.insert(k.clone()) {
                        return Err(serde::de::Error::custom(format!("key {k:?} given twice")));
                    }
                    entries.push((k, v));
                }
                Ok(OrderedMap(entries))
            }
        }
        deserializer.deserialize_map(MapVisitor(PhantomData))
    }
}

/// `Use` as its FORMAT.md spelling.
mod use_serde {
    use super::Use;
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(usage: &Use, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(usage.as_str())
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Use, D::Error> {
        let s = String::deserialize(deserializer)?;
        Use::parse(&s).ok_or_else(|| {
            serde::de::Error::custom(format!(
                "unknown use {s:?} (expected translation, rotation, identify or validate)"
            ))
        })
    }
}

/// A robot block in a truth file: FORMAT.md's session `robot` shape
/// (joints in deg and mm; `base`, `flange` 4×4 rows when not identity).
/// `name` is optional here so other simulators' truth files load.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TruthRobot {
    /// Display name.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// MDH joints, base to flange, file units.
    pub joints: Vec<Joint>,
    /// `B`, row-major 4×4; absent means identity.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base: Option<[[f64; 4]; 4]>,
    /// `F`, row-major 4×4; absent means identity.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub flange: Option<[[f64; 4]; 4]>,
}

impl TruthRobot {
    fn from_robot(robot: &Robot) -> Self {
        let rows =
            |iso: &Isometry3<f64>| (*iso != Isometry3::identity()).then(|| rows_from_isometry(iso));
        Self {
            name: Some(robot.name.clone()),
            joints: robot.joints.clone(),
            base: rows(&robot.base),
            flange: rows(&robot.flange),
        }
    }

    /// The robot this block describes (name "unnamed robot" when absent).
    #[must_use]
    pub fn to_robot(&self) -> Robot {
        let mut robot = Robot::new(
            self.name
                .clone()
                .unwrap_or_else(|| "unnamed robot".to_owned()),
            self.joints.clone(),
        );
        if let Some(rows) = &self.base {
            robot.base = rigid_from_rows(rows);
        }
        if let Some(rows) = &self.flange {
            robot.flange = rigid_from_rows(rows);
        }
        robot
    }
}

/// Ground truth of one measurement.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeasurementTruth {
    /// Station id.
    pub station: String,
    /// FORMAT.md `use`.
    #[serde(rename = "use", with = "use_serde")]
    pub usage: Use,
    /// Joint angles the robot actually had, deg (the session's `joints` are
    /// these plus reading noise).
    pub joints_actual: Vec<f64>,
    /// The true sphere centre in the sensor frame, mm.
    pub sensor_centre: [f64; 3],
    /// Side of the laser plane, +1 or −1.
    pub side: i8,
}

/// A true distance between two validate stations (before tracker noise).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrueDistance {
    /// Station id.
    pub from: String,
    /// Station id.
    pub to: String,
    /// Distance between the station centres, mm.
    pub distance: f64,
}

/// The ground truth of a simulated session (`"format": "spherecal-truth"`,
/// version 1), the shape of shared/examples/*.truth.json.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Truth {
    /// Always [`TRUTH_FORMAT`].
    pub format: String,
    /// Always [`TRUTH_VERSION`].
    pub version: u32,
    /// Name of the session this is the truth of.
    pub session: String,
    /// The configuration that produced it (name and workspace resolved).
    pub config: SimConfig,
    /// The true kinematic model (nominal + `joint_errors`).
    pub robot: TruthRobot,
    /// The nominal model written into the session.
    pub nominal: TruthRobot,
    /// True minus nominal, per joint, deg and mm (paper Table 1 layout).
    pub joint_errors: Vec<Joint>,
    /// The true hand-eye `eT_s` (sensor to flange), row-major 4×4, mm.
    pub hand_eye: [[f64; 4]; 4],
    /// Sphere centre of every station, base frame, mm, in file order.
    pub stations: OrderedMap<[f64; 3]>,
    /// True distances of the session's `reference_distances`, same order.
    pub true_distances: Vec<TrueDistance>,
    /// Per measurement id, in session order.
    pub measurements: OrderedMap<MeasurementTruth>,
}

impl Truth {
    /// The true kinematic model.
    #[must_use]
    pub fn true_robot(&self) -> Robot {
        self.robot.to_robot()
    }

    /// The nominal kinematic model.
    #[must_use]
    pub fn nominal_robot(&self) -> Robot {
        self.nominal.to_robot()
    }

    /// The true hand-eye `flange_from_sensor` (mm).
    #[must_use]
    pub fn true_hand_eye(&self) -> Isometry3<f64> {
        rigid_from_rows(&self.hand_eye)
    }

    /// Sphere centre of station `id`, base frame, mm.
    #[must_use]
    pub fn station(&self, id: &str) -> Option<Vector3<f64>> {
        self.stations.get(id).map(|p| Vector3::from(*p))
    }

    /// Ground truth of measurement `id`.
    #[must_use]
    pub fn measurement(&self, id: &str) -> Option<&MeasurementTruth> {
        self.measurements.get(id)
    }
}

/// A rigid transform from 4×4 rows, taking the nearest rotation of the 3×3
/// block. For rows that pass [`isometry_from_rows`] the result is identical
/// to it (same conversion); it never fails, so accessors need no `Result`.
pub(crate) fn rigid_from_rows(rows: &[[f64; 4]; 4]) -> Isometry3<f64> {
    let r = Matrix3::from_fn(|i, j| rows[i][j]);
    Isometry3::from_parts(
        Translation3::new(rows[0][3], rows[1][3], rows[2][3]),
        UnitQuaternion::from_matrix(&r),
    )
}

pub(crate) fn round_to(value: f64, decimals: i32) -> f64 {
    let scale = 10f64.powi(decimals);
    (value * scale).round() / scale
}

/// Rows of a printed 3×4 hand-eye, re-orthonormalised (nearest rotation)
/// and rounded to [`HAND_EYE_DECIMALS`].
fn orthonormal_rows(printed: &[[f64; 4]; 3]) -> [[f64; 4]; 4] {
    let r = Matrix3::from_fn(|i, j| printed[i][j]);
    let rotation = UnitQuaternion::from_matrix(&r).to_rotation_matrix();
    let mut rows = [[0.0, 0.0, 0.0, 1.0]; 4];
    for i in 0..3 {
        for j in 0..3 {
            rows[i][j] = round_to(rotation[(i, j)], HAND_EYE_DECIMALS);
        }
        rows[i][3] = printed[i][3];
    }
    rows
}

/// The true hand-eye as 4×4 rows: the paper's calibrated `eT_s`
/// ([`PAPER_HAND_EYE_ROWS`]) with its rotation replaced by the nearest
/// rotation matrix, rounded to 12 decimals.
#[must_use]
pub fn paper_hand_eye_rows() -> [[f64; 4]; 4] {
    orthonormal_rows(&PAPER_HAND_EYE_ROWS)
}

/// The paper's calibrated hand-eye `flange_from_sensor` (mm), as used for
/// the truth (see [`paper_hand_eye_rows`]).
#[must_use]
pub fn paper_hand_eye() -> Isometry3<f64> {
    rigid_from_rows(&paper_hand_eye_rows())
}

/// The paper's initial hand-eye `flange_from_sensor` (mm), re-orthonormalised
/// like [`paper_hand_eye`].
#[must_use]
pub fn paper_initial_hand_eye() -> Isometry3<f64> {
    rigid_from_rows(&orthonormal_rows(&PAPER_INITIAL_HAND_EYE_ROWS))
}

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

/// Serialises a truth file: pretty JSON (one-space indent, like the
/// shared example), keys in struct order, trailing newline.
#[must_use]
pub fn truth_to_json(truth: &Truth) -> String {
    let mut out = Vec::new();
    let formatter = serde_json::ser::PrettyFormatter::with_indent(b" ");
    let mut ser = serde_json::Serializer::with_formatter(&mut out, formatter);
    // Serialising plain structs of strings and finite numbers to memory
    // cannot fail; keep whatever was written if it somehow does.
    let _ = truth.serialize(&mut ser);
    let mut text = String::from_utf8_lossy(&out).into_owned();
    text.push('\n');
    text
}

/// Parses a truth file and checks it: format and version, rigid 4×4
/// matrices, matching joint counts, measurements naming known stations.
///
/// # Errors
/// [`TruthError`] naming what is wrong.
pub fn parse_truth(text: &str) -> Result<Truth, TruthError> {
    let truth: Truth = serde_json::from_str(text).map_err(|e| TruthError::Syntax(e.to_string()))?;
    if truth.format != TRUTH_FORMAT {
        return Err(TruthError::Format(truth.format));
    }
    if truth.version != TRUTH_VERSION {
        return Err(TruthError::Version(truth.version));
    }
    let matrix = |what: &str, rows: &[[f64; 4]; 4]| {
        isometry_from_rows(rows)
            .map(|_| ())
            .map_err(|source| TruthError::Matrix {
                what: what.to_owned(),
                source,
            })
    };
    matrix("hand_eye", &truth.hand_eye)?;
    for (label, block) in [("robot", &truth.robot), ("nominal", &truth.nominal)] {
        if let Some(rows) = &block.base {
            matrix(&format!("{label}.base"), rows)?;
        }
        if let Some(rows) = &block.flange {
            matrix(&format!("{label}.flange"), rows)?;
        }
    }
    let n = truth.robot.joints.len();
    if truth.nominal.joints.len() != n || truth.joint_errors.len() != n {
        return Err(TruthError::Inconsistent(format!(
            "robot has {n} joints, nominal {} and joint_errors {}",
            truth.nominal.joints.len(),
            truth.joint_errors.len()
        )));
    }
    for (id, m) in truth.measurements.iter() {
        if m.joints_actual.len() != n {
            return Err(TruthError::Inconsistent(format!(
                "measurement {id}: joints_actual has {} values, the robot has {n} joints",
                m.joints_actual.len()
            )));
        }
        if truth.stations.get(&m.station).is_none() {
            return Err(TruthError::Inconsistent(format!(
                "measurement {id}: station {} is not in \"stations\"",
                m.station
            )));
        }
        if m.side != 1 && m.side != -1 {
            return Err(TruthError::Inconsistent(format!(
                "measurement {id}: side must be 1 or -1, found {}",
                m.side
            )));
        }
    }
    Ok(truth)
}

/// Reads and parses a truth file.
///
/// # Errors
/// [`FileError::Io`] when it cannot be read, [`FileError::Invalid`] with
/// the [`TruthError`] message otherwise.
pub fn load_truth(path: &Path) -> Result<Truth, FileError> {
    let text = std::fs::read_to_string(path).map_err(|source| FileError::Io {
        action: "reading",
        path: path.to_path_buf(),
        source,
    })?;
    parse_truth(&text).map_err(|e| FileError::Invalid {
        path: path.to_path_buf(),
        measurement: None,
        message: e.to_string(),
    })
}

/// One ChaCha8 stream of the seed (see "Randomness" in the module docs).
pub(crate) fn stream(seed: u64, id: u64) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(id);
    rng
}

/// Stream ids: geometry, kinematic errors, measurement noise.
const STREAM_GEOMETRY: u64 = 0;
/// See [`STREAM_GEOMETRY`].
const STREAM_ERRORS: u64 = 1;
/// See [`STREAM_GEOMETRY`].
const STREAM_NOISE: u64 = 2;

/// Uniform in `[lo, hi)`; never panics and always draws one number.
pub(crate) fn uniform(rng: &mut ChaCha8Rng, lo: f64, hi: f64) -> f64 {
    lo + (hi - lo) * rng.random::<f64>()
}

fn normal(rng: &mut ChaCha8Rng) -> f64 {
    rng.sample(StandardNormal)
}

fn check(ok: bool, message: impl FnOnce() -> String) -> Result<(), SimError> {
    if ok {
        Ok(())
    } else {
        Err(SimError::InvalidConfig(message()))
    }
}

fn validate_config(c: &SimConfig) -> Result<(), SimError> {
    let reals = [
        ("error_scale", c.error_scale),
        ("joint_noise", c.joint_noise),
        ("stripe_noise", c.stripe_noise),
        ("outlier_fraction", c.outlier_fraction),
        ("outlier_min", c.outlier_min),
        ("outlier_max", c.outlier_max),
        ("point_spacing", c.point_spacing),
        ("arc_half_angle", c.arc_half_angle),
        ("view_z", c.view_z),
        ("cut_angle", c.cut_angle),
        ("cut_jitter", c.cut_jitter),
        ("centre_noise", c.centre_noise),
        ("tracker_noise", c.tracker_noise),
        ("diameter", c.diameter),
        ("threshold", c.threshold),
        ("cone_angle", c.cone_angle),
        ("min_wrist_angle", c.min_wrist_angle),
        ("translation_min", c.translation_min),
        ("translation_max", c.translation_max),
        ("rotation_min", c.rotation_min),
        ("rotation_max", c.rotation_max),
    ];
    for (name, v) in reals {
        check(v.is_finite(), || {
            format!("{name} must be a finite number, found {v}")
        })?;
    }
    for (name, v) in [
        ("joint_noise", c.joint_noise),
        ("stripe_noise", c.stripe_noise),
        ("centre_noise", c.centre_noise),
        ("tracker_noise", c.tracker_noise),
        ("threshold", c.threshold),
        ("cut_jitter", c.cut_jitter),
        ("outlier_min", c.outlier_min),
    ] {
        check(v >= 0.0, || {
            format!("{name} must not be negative, found {v}")
        })?;
    }
    check((0.0..=1.0).contains(&c.outlier_fraction), || {
        format!(
            "outlier_fraction must be within 0..1, found {}",
            c.outlier_fraction
        )
    })?;
    check(c.outlier_min <= c.outlier_max, || {
        format!(
            "outlier_min ({} mm) must not exceed outlier_max ({} mm)",
            c.outlier_min, c.outlier_max
        )
    })?;
    check(c.diameter > 0.0, || {
        format!("diameter must be positive, found {} mm", c.diameter)
    })?;
    check(c.point_spacing > 0.0, || {
        format!(
            "point_spacing must be positive, found {} mm",
            c.point_spacing
        )
    })?;
    check(c.arc_half_angle > 0.0 && c.arc_half_angle <= 90.0, || {
        format!(
            "arc_half_angle must be within (0, 90] deg, found {}",
            c.arc_half_angle
        )
    })?;
    check(
        c.cut_angle - c.cut_jitter > 0.0 && c.cut_angle + c.cut_jitter < 90.0,
        || {
            format!(
                "cut_angle ± cut_jitter must stay within (0, 90) deg, found {} ± {}",
                c.cut_angle, c.cut_jitter
            )
        },
    )?;
    check(c.view_z > c.diameter, || {
        format!(
            "view_z ({} mm) must put the camera outside the sphere (above the diameter, {} mm)",
            c.view_z, c.diameter
        )
    })?;
    check((0..=12).contains(&c.stripe_decimals), || {
        format!(
            "stripe_decimals must be within 0..=12, found {}",
            c.stripe_decimals
        )
    })?;
    check((0.0..=90.0).contains(&c.cone_angle), || {
        format!(
            "cone_angle must be within 0..90 deg, found {}",
            c.cone_angle
        )
    })?;
    check((0.0..90.0).contains(&c.min_wrist_angle), || {
        format!(
            "min_wrist_angle must be within 0..90 deg, found {}",
            c.min_wrist_angle
        )
    })?;
    check(
        0.0 <= c.translation_min && c.translation_min <= c.translation_max,
        || {
            format!(
                "translations need 0 ≤ translation_min ≤ translation_max, found {} and {} mm",
                c.translation_min, c.translation_max
            )
        },
    )?;
    check(c.n_translation < 2 || c.translation_max > 0.0, || {
        "translation_max must be positive to move the robot".to_owned()
    })?;
    check(
        0.0 < c.rotation_min && c.rotation_min <= c.rotation_max && c.rotation_max <= 180.0,
        || {
            format!(
                "rotations need 0 < rotation_min ≤ rotation_max ≤ 180, found {} and {} deg",
                c.rotation_min, c.rotation_max
            )
        },
    )?;
    check(
        c.poses_per_station >= 2 || c.n_identify + c.n_validate == 0,
        || {
            format!(
                "poses_per_station must be at least 2 (FORMAT.md), found {}",
                c.poses_per_station
            )
        },
    )?;
    if c.initial_hand_eye == InitialHandEye::None {
        check(c.n_translation >= 3, || {
            format!(
                "without an initial hand-eye the session needs at least 3 translation measurements, found {}",
                c.n_translation
            )
        })?;
        check(c.n_rotation >= 2, || {
            format!(
                "without an initial hand-eye the session needs at least 2 rotation measurements, found {}",
                c.n_rotation
            )
        })?;
    }
    // The shortest stripe: the largest cut angle gives the smallest circle.
    let radius = c.diameter / 2.0;
    let smallest_r = radius * (c.cut_angle + c.cut_jitter).to_radians().cos();
    let points = stripe_point_count(smallest_r, c.arc_half_angle, c.point_spacing);
    check(points >= MIN_STRIPE_POINTS, || {
        format!(
            "stripes would have only {points} points (FORMAT.md needs {MIN_STRIPE_POINTS}); reduce point_spacing or widen arc_half_angle"
        )
    })?;
    if let Some(w) = &c.workspace {
        let finite = w
            .min
            .iter()
            .chain(&w.max)
            .chain(&w.eye)
            .all(|v| v.is_finite());
        check(finite && (0..3).all(|i| w.min[i] <= w.max[i]), || {
            "workspace needs finite numbers and min ≤ max on every axis".to_owned()
        })?;
    }
    Ok(())
}

/// Points on an arc of radius `r` (mm), half-angle `half_angle_deg`, one
/// every `spacing` mm.
pub(crate) fn stripe_point_count(r: f64, half_angle_deg: f64, spacing: f64) -> usize {
    let arc = 2.0 * half_angle_deg.to_radians() * r;
    // Truncation intended: whole points that fit on the arc.
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let n = (arc / spacing).floor().max(0.0) as usize;
    n + 1
}

fn kinematic_errors(c: &SimConfig, dof: usize, rng: &mut ChaCha8Rng) -> Vec<Joint> {
    let scale = |v: f64| round_to(v * c.error_scale, ERROR_DECIMALS);
    match c.errors {
        ErrorModel::None => vec![Joint::default(); dof],
        ErrorModel::Table1 => {
            let mut table = table1_errors();
            table.resize(dof, Joint::default());
            table
                .iter()
                .map(|j| Joint {
                    alpha: scale(j.alpha),
                    a: scale(j.a),
                    beta: scale(j.beta),
                    theta: scale(j.theta),
                    d: scale(j.d),
                })
                .collect()
        }
        ErrorModel::Random => (0..dof)
            .map(|_| {
                let mut draw = |sigma: f64| scale(sigma * normal(rng));
                Joint {
                    alpha: draw(RANDOM_ANGLE_SIGMA_DEG),
                    a: draw(RANDOM_LENGTH_SIGMA_MM),
                    beta: draw(RANDOM_ANGLE_SIGMA_DEG),
                    theta: draw(RANDOM_ANGLE_SIGMA_DEG),
                    d: draw(RANDOM_LENGTH_SIGMA_MM),
                }
            })
            .collect(),
    }
}

/// A unit vector uniformly distributed (by solid angle) within `cone` rad
/// of `axis`.
pub(crate) fn direction_in_cone(
    rng: &mut ChaCha8Rng,
    axis: &Vector3<f64>,
    cone: f64,
) -> Vector3<f64> {
    let cos_t = 1.0 - rng.random::<f64>() * (1.0 - cone.cos());
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let phi = 2.0 * PI * rng.random::<f64>();
    let (e1, e2) = perpendiculars(axis);
    (axis * cos_t + (e1 * phi.cos() + e2 * phi.sin()) * sin_t).normalize()
}

/// Two unit vectors completing `axis` (unit) to a right-handed basis.
fn perpendiculars(axis: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let helper = if axis.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let e1 = (helper - axis * helper.dot(axis)).normalize();
    let e2 = axis.cross(&e1);
    (e1, e2)
}

/// The rotation whose z axis is `approach` (unit), turned by `roll` rad
/// about it.
pub(crate) fn rotation_from_approach(approach: &Vector3<f64>, roll: f64) -> UnitQuaternion<f64> {
    let (e1, e2) = perpendiculars(approach);
    let x = e1 * roll.cos() + e2 * roll.sin();
    let y = approach.cross(&x);
    UnitQuaternion::from_rotation_matrix(&Rotation3::from_basis_unchecked(&[x, y, *approach]))
}

/// A random flange orientation: approach in the cone, uniform roll.
pub(crate) fn random_orientation(
    rng: &mut ChaCha8Rng,
    mean: &Vector3<f64>,
    cone: f64,
) -> UnitQuaternion<f64> {
    let approach = direction_in_cone(rng, mean, cone);
    let roll = 2.0 * PI * rng.random::<f64>();
    rotation_from_approach(&approach, roll)
}

/// Sides for the measurements of one station: balanced and shuffled for
/// `mixed` (an odd one out takes a random side).
fn station_sides(rng: &mut ChaCha8Rng, n: usize, choice: SideChoice) -> Vec<i8> {
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
const IK_CHECK_TOLERANCE: f64 = 1e-7;

/// One planned pose before noise.
#[derive(Debug, Clone)]
struct Pose {
    station: String,
    usage: Use,
    side: i8,
    joints: [f64; DOF],
    centre_in_sensor: Vector3<f64>,
}

/// Places sphere centres in the sensor frame and solves the robot poses
/// that see them, on the true model.
struct Planner<'a> {
    config: &'a SimConfig,
    robot: &'a Robot,
    chain: Chain,
    limits: Vec<JointLimit>,
    choice: RobotChoice,
    flange_from_sensor: Isometry3<f64>,
    workspace: Workspace,
    /// Nominal theta of joint 5 (deg): the wrist angle is `q5 + theta5`.
    wrist_offset: f64,
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

    fn sample_x(&self, rng: &mut ChaCha8Rng, side: i8) -> f64 {
        let c = self.config;
        let cut = uniform(rng, c.cut_angle - c.cut_jitter, c.cut_angle + c.cut_jitter);
        f64::from(side) * self.radius() * cut.to_radians().sin()
    }

    fn mean_approach(&self, station: &Vector3<f64>) -> Vector3<f64> {
        let d = station - Vector3::from(self.workspace.eye);
        if d.norm() > 0.0 {
            d.normalize()
        } else {
            -Vector3::z()
        }
    }

    /// Arm guesses `(q1, q2, q3)` (deg) for a flange target: per-preset
    /// elbow-up configurations, joint 1 turned toward the target.
    fn arm_guesses(&self, target: &Isometry3<f64>) -> Vec<[f64; 3]> {
        let p = target.translation.vector;
        let heading = p.y.atan2(p.x).to_degrees();
        // The ABB arms point along +x at q1 = 0, the UR5e along −x.
        let (q1_offset, arms): (f64, &[[f64; 2]]) = match self.choice {
            RobotChoice::Irb2400 | RobotChoice::Irb120 => {
                (0.0, &[[20.0, 20.0], [40.0, 0.0], [0.0, 45.0], [50.0, 30.0]])
            }
            RobotChoice::Ur5e => (
                180.0,
                &[
                    [-90.0, 90.0],
                    [-50.0, 100.0],
                    [-120.0, 110.0],
                    [-60.0, 140.0],
                ],
            ),
        };
        let q1 = wrap_deg(heading + q1_offset);
        arms.iter().map(|a| [q1, a[0], a[1]]).collect()
    }

    /// How much a wrist solution is disliked (lower first): the wrist a
    /// cell would teach. ABB wrists: the least forearm roll `|q4|` (less
    /// cable wind-up); the UR5e: its tool-down configuration, `q5 < 0`.
    fn wrist_dislike(&self, q: &[f64; DOF]) -> f64 {
        match self.choice {
            RobotChoice::Irb2400 | RobotChoice::Irb120 => wrap_deg(q[3]).abs(),
            RobotChoice::Ur5e => (q[4] + self.wrist_offset).signum(),
        }
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
        let position = station - rotation * centre_in_flange.coords;
        let target = Isometry3::from_parts(Translation3::from(position), *rotation);
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
                let centre = self.sample_centre(rng, side);
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
                let axis = Unit::new_normalize(direction_in_cone(rng, &Vector3::z(), PI));
                let angle = uniform(rng, c.rotation_min, c.rotation_max).to_radians();
                let rotation = reference * UnitQuaternion::from_axis_angle(&axis, angle);
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

/// The preset's joint limits, narrowed where a preset allows
/// configurations no cell would use: the UR5e (±360° everywhere) keeps its
/// upper arm above the horizontal and leaning toward the work (`q2` in
/// −150..−10, the base stands on a table) and its elbow up and bent (`q3`
/// in 10..160, away from the stretched-arm singularity at 0 and from
/// folding onto itself).
fn planning_limits(choice: RobotChoice, limits: &[JointLimit]) -> Vec<JointLimit> {
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

fn unreachable(id: &str, station: &Vector3<f64>) -> SimError {
    SimError::Unreachable {
        station: id.to_owned(),
        position: [station.x, station.y, station.z],
        attempts: MAX_POSE_ATTEMPTS,
    }
}

/// Identify stations: a 3×3 Latin square of x, y, z levels (jittered),
/// then uniform in the box.
pub(crate) fn identify_stations(
    rng: &mut ChaCha8Rng,
    w: &Workspace,
    n: usize,
) -> Vec<Vector3<f64>> {
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
pub(crate) fn validate_stations(
    rng: &mut ChaCha8Rng,
    w: &Workspace,
    n: usize,
) -> Vec<Vector3<f64>> {
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

/// The stripe of a sensor-frame centre: the arc of the cut circle facing
/// the camera at `(0, 0, view_z)`, noise on both coordinates, outliers
/// moved along the circle normal, rounded.
fn stripe(c: &SimConfig, rng: &mut ChaCha8Rng, centre: &Vector3<f64>) -> Vec<[f64; 2]> {
    let radius = c.diameter / 2.0;
    let r = (radius * radius - centre.x * centre.x).max(0.0).sqrt();
    let (yc, zc) = (centre.y, centre.z);
    // Angle from the +z axis toward +y of the camera seen from the circle centre.
    let facing = (-yc).atan2(c.view_z - zc);
    let n = stripe_point_count(r, c.arc_half_angle, c.point_spacing);
    let step = c.point_spacing / r;
    let first = facing + step * (n - 1) as f64 / 2.0;
    let mut points: Vec<(f64, f64, f64)> = (0..n)
        .map(|k| {
            let phi = first - step * k as f64;
            let y = yc + r * phi.sin() + c.stripe_noise * normal(rng);
            let z = zc + r * phi.cos() + c.stripe_noise * normal(rng);
            (y, z, phi)
        })
        .collect();
    // Rounding to nearest intended: a count of points.
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let n_outliers = (c.outlier_fraction * n as f64).round() as usize;
    if n_outliers > 0 {
        for index in rand::seq::index::sample(rng, n, n_outliers.min(n)).into_vec() {
            let magnitude = uniform(rng, c.outlier_min, c.outlier_max);
            let sign = if rng.random::<bool>() { 1.0 } else { -1.0 };
            let (y, z, phi) = &mut points[index];
            *y += sign * magnitude * phi.sin();
            *z += sign * magnitude * phi.cos();
        }
    }
    points
        .iter()
        .map(|(y, z, _)| {
            [
                round_to(*y, c.stripe_decimals),
                round_to(*z, c.stripe_decimals),
            ]
        })
        .collect()
}

/// Stations and planned poses (from the geometry stream).
struct Plan {
    /// Every station in file order, base frame, mm.
    stations: Vec<(String, Vector3<f64>)>,
    /// Every measurement's pose, in session order.
    poses: Vec<Pose>,
    /// The validate stations, in order.
    validate: Vec<Vector3<f64>>,
}

/// Places the stations and solves every pose: `P0` (translations, then
/// rotations), the identify stations, the validate stations.
fn plan(planner: &Planner<'_>, rng: &mut ChaCha8Rng) -> Result<Plan, SimError> {
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

/// What the cell records for each pose (noise from the noise stream):
/// joint readings, and the stripe or the centre; with the truth of each.
fn record(
    config: &SimConfig,
    poses: &[Pose],
    default_side: i8,
    rng: &mut ChaCha8Rng,
) -> (Vec<Measurement>, Vec<(String, MeasurementTruth)>) {
    let mut counters = [0usize; 4];
    let mut measurements = Vec::with_capacity(poses.len());
    let mut truths = Vec::with_capacity(poses.len());
    for pose in poses {
        let (prefix, slot) = match pose.usage {
            Use::Translation => ("t", 0),
            Use::Rotation => ("r", 1),
            Use::Identify => ("c", 2),
            Use::Validate => ("v", 3),
        };
        counters[slot] += 1;
        let id = format!("{prefix}{}", counters[slot]);
        let joints: Vec<f64> = pose
            .joints
            .iter()
            .map(|q| round_to(q + config.joint_noise * normal(rng), JOINT_DECIMALS))
            .collect();
        let c = pose.centre_in_sensor;
        let observation = if config.centres {
            Observation::Centre(c.map(|v| {
                round_to(
                    v + config.centre_noise * normal(rng),
                    config.stripe_decimals,
                )
            }))
        } else {
            Observation::Stripe(stripe(config, rng, &c))
        };
        measurements.push(Measurement {
            id: id.clone(),
            station: pose.station.clone(),
            usage: pose.usage,
            side_given: (pose.side != default_side).then_some(pose.side),
            side: pose.side,
            joints,
            observation,
        });
        truths.push((
            id,
            MeasurementTruth {
                station: pose.station.clone(),
                usage: pose.usage,
                joints_actual: pose.joints.to_vec(),
                sensor_centre: [c.x, c.y, c.z],
                side: pose.side,
            },
        ));
    }
    (measurements, truths)
}

/// Tracker distances between consecutive validate stations (`V1 → V2`,
/// `V2 → V3`, …, in the order given): true distance plus tracker noise,
/// and the true ones.
fn reference_distances(
    config: &SimConfig,
    validate: &[(String, Vector3<f64>)],
    rng: &mut ChaCha8Rng,
) -> (Vec<ReferenceDistance>, Vec<TrueDistance>) {
    let mut reference = Vec::new();
    let mut truth = Vec::new();
    for pair in validate.windows(2) {
        let [(from, a), (to, b)] = pair else {
            continue;
        };
        let (from, to) = (from.clone(), to.clone());
        let distance = (b - a).norm();
        let measured = distance + config.tracker_noise * normal(rng);
        reference.push(ReferenceDistance {
            from: from.clone(),
            to: to.clone(),
            distance: round_to(measured, DISTANCE_DECIMALS),
        });
        truth.push(TrueDistance { from, to, distance });
    }
    (reference, truth)
}

/// Simulates a session and its ground truth (see the module docs).
///
/// # Errors
/// [`SimError::InvalidConfig`] for a setting out of range,
/// [`SimError::Unreachable`] when a station cannot be seen from the cone.
pub fn simulate(config: &SimConfig) -> Result<(Session, Truth), SimError> {
    validate_config(config)?;
    let preset = kinematics::preset(config.robot.key())
        .ok_or_else(|| SimError::InvalidConfig(format!("unknown robot {}", config.robot.key())))?;
    let nominal = preset.robot;
    let dof = nominal.dof();
    let workspace = config
        .workspace
        .unwrap_or_else(|| Workspace::for_robot(config.robot));
    let mut rng_geometry = stream(config.seed, STREAM_GEOMETRY);
    let mut rng_errors = stream(config.seed, STREAM_ERRORS);
    let mut rng_noise = stream(config.seed, STREAM_NOISE);

    let errors = kinematic_errors(config, dof, &mut rng_errors);
    let mut true_robot = nominal.clone();
    for (joint, e) in true_robot.joints.iter_mut().zip(&errors) {
        joint.alpha += e.alpha;
        joint.a += e.a;
        joint.beta += e.beta;
        joint.theta += e.theta;
        joint.d += e.d;
    }
    let hand_eye_rows = paper_hand_eye_rows();
    let flange_from_sensor = rigid_from_rows(&hand_eye_rows);

    let chain = Chain::new(&true_robot).ok_or_else(|| {
        SimError::InvalidConfig(format!(
            "the simulator plans for 6-axis arms, {} has {dof}",
            nominal.name
        ))
    })?;
    let planner = Planner {
        config,
        robot: &true_robot,
        chain,
        limits: planning_limits(config.robot, &preset.limits),
        choice: config.robot,
        flange_from_sensor,
        workspace,
        wrist_offset: nominal.joints.get(4).map_or(0.0, |j| j.theta),
    };

    let plan = plan(&planner, &mut rng_geometry)?;
    let default_side: i8 = if config.side == SideChoice::Minus {
        -1
    } else {
        1
    };
    let (measurements, truths) = record(config, &plan.poses, default_side, &mut rng_noise);
    let validate: Vec<(String, Vector3<f64>)> = plan
        .validate
        .iter()
        .enumerate()
        .map(|(k, p)| (format!("V{}", k + 1), *p))
        .collect();
    let (reference_distances, true_distances) =
        reference_distances(config, &validate, &mut rng_noise);

    let name = config
        .name
        .clone()
        .unwrap_or_else(|| format!("simulated {}, seed {}", nominal.name, config.seed));
    let hand_eye = match config.initial_hand_eye {
        InitialHandEye::None => None,
        InitialHandEye::Paper => Some(paper_initial_hand_eye()),
        InitialHandEye::Truth => Some(flange_from_sensor),
    };
    let session = Session {
        name: name.clone(),
        name_given: true,
        robot: nominal.clone(),
        base_given: false,
        flange_given: false,
        sphere_diameter: config.diameter,
        default_side,
        sensor_given: true,
        hand_eye,
        solver: SolverSettings {
            threshold: config.threshold,
            max_iterations: config.max_iterations,
        },
        solver_given: true,
        reference_distances,
        measurements,
    };
    let mut echoed = config.clone();
    echoed.name = Some(name.clone());
    echoed.workspace = Some(workspace);
    let truth = Truth {
        format: TRUTH_FORMAT.to_owned(),
        version: TRUTH_VERSION,
        session: name,
        config: echoed,
        robot: TruthRobot::from_robot(&true_robot),
        nominal: TruthRobot::from_robot(&nominal),
        joint_errors: errors,
        hand_eye: hand_eye_rows,
        stations: OrderedMap(
            plan.stations
                .iter()
                .map(|(id, p)| (id.clone(), [p.x, p.y, p.z]))
                .collect(),
        ),
        true_distances,
        measurements: OrderedMap(truths),
    };
    Ok((session, truth))
}

/// Smallest cut angle (deg) at which a pose of a plan still counts as
/// seeing the sphere on the true robot: below it the centre is within
/// `R · sin 5°` ≈ 1.7 mm of the laser plane and its side is a guess.
const PLAN_MIN_CUT_DEG: f64 = 5.0;
/// Largest usable cut angle (deg): beyond it the stripe circle radius
/// falls under `R · cos 80°` ≈ 3.3 mm and `t = sqrt(R² − r²)` loses all
/// precision (shared/paper/NOTES.md, "The cut angle matters").
const PLAN_MAX_CUT_DEG: f64 = 80.0;

/// One commanded pose of a measurement plan (e.g. [`plan`](super::plan)'s
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
///   as in [`simulate`]; measurement ids are the plan's.
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
    let count = |usage: Use| poses.iter().filter(|p| p.usage == usage).count();
    let mut per_station: Vec<(String, usize)> = Vec::new();
    for p in poses {
        match per_station.iter_mut().find(|(s, _)| *s == p.station) {
            Some((_, n)) => *n += 1,
            None => per_station.push((p.station.clone(), 1)),
        }
    }
    let smallest_station = poses
        .iter()
        .filter(|p| matches!(p.usage, Use::Identify | Use::Validate))
        .filter_map(|p| per_station.iter().find(|(s, _)| *s == p.station))
        .map(|(_, n)| *n)
        .min()
        .unwrap_or(2);
    let mut echoed = SimConfig {
        n_translation: count(Use::Translation),
        n_rotation: count(Use::Rotation),
        n_identify: count_stations(poses, Use::Identify),
        n_validate: count_stations(poses, Use::Validate),
        poses_per_station: smallest_station,
        workspace: None,
        ..config.clone()
    };
    validate_config(&echoed)?;
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
    let mut rng_errors = stream(config.seed, STREAM_ERRORS);
    let mut rng_noise = stream(config.seed, STREAM_NOISE);
    let errors = kinematic_errors(config, dof, &mut rng_errors);
    let mut true_robot = nominal.clone();
    for (joint, e) in true_robot.joints.iter_mut().zip(&errors) {
        joint.alpha += e.alpha;
        joint.a += e.a;
        joint.beta += e.beta;
        joint.theta += e.theta;
        joint.d += e.d;
    }
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
    let radius = config.diameter / 2.0;
    let (lo, hi) = (
        radius * PLAN_MIN_CUT_DEG.to_radians().sin(),
        radius * PLAN_MAX_CUT_DEG.to_radians().sin(),
    );
    let chain = Chain::new(&true_robot)
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
        name: name.clone(),
        name_given: true,
        robot: nominal.clone(),
        base_given: nominal.base != Isometry3::identity(),
        flange_given: nominal.flange != Isometry3::identity(),
        sphere_diameter: config.diameter,
        default_side,
        sensor_given: true,
        hand_eye,
        solver: SolverSettings {
            threshold: config.threshold,
            max_iterations: config.max_iterations,
        },
        solver_given: true,
        reference_distances,
        measurements,
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
const TOUCH_UP_MAX_ITER: usize = 30;
/// Touch-up convergence, mm (as the IK's position tolerance).
const TOUCH_UP_TOLERANCE_MM: f64 = 1e-9;

/// The joints nearest `start` (deg, least-norm Gauss-Newton steps) at
/// which `chain` sees `station` (base, mm) at `centre` (sensor, mm).
fn touch_up(
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
fn count_stations(poses: &[PlanPose], usage: Use) -> usize {
    let mut seen: Vec<&str> = Vec::new();
    for p in poses.iter().filter(|p| p.usage == usage) {
        if !seen.contains(&p.station.as_str()) {
            seen.push(&p.station);
        }
    }
    seen.len()
}

/// The inputs of `spherecal import` for a simulated stripe session, as a
/// real cell would leave them (see [`import_files`]).
#[derive(Debug, Clone, PartialEq)]
pub struct ImportFiles {
    /// The joint log: `id,station,use,side,j1..jn,x,y,z,q1,q2,q3,q4`.
    pub joints_csv: String,
    /// One stripe profile per measurement: `(id, "y,z" CSV text)`, mm.
    pub profiles: Vec<(String, String)>,
    /// `from,to,distance` (mm) of the reference distances; `None` when the
    /// session has none.
    pub references_csv: Option<String>,
}

/// The import inputs of a session with stripes: the joint log with the
/// flange pose the controller reports (ABB `x,y,z` in mm and the unit
/// quaternion `q1..q4` = w, x, y, z), computed by the **nominal** forward
/// kinematics of the recorded joints, as a real controller computes it;
/// a `y,z` profile per measurement; the reference distances. Numbers are
/// written with enough decimals to round-trip the session (joints 1e-9°,
/// profile points as in the session).
///
/// # Errors
/// [`SimError::InvalidConfig`] when a measurement is a centre (the import
/// reads stripes only).
pub fn import_files(session: &Session) -> Result<ImportFiles, SimError> {
    use std::fmt::Write as _;
    let n = session.robot.dof();
    let mut joints_csv = String::from("id,station,use,side");
    for k in 1..=n {
        let _ = write!(joints_csv, ",j{k}");
    }
    joints_csv.push_str(",x,y,z,q1,q2,q3,q4\n");
    let mut profiles = Vec::with_capacity(session.measurements.len());
    for m in &session.measurements {
        let Observation::Stripe(points) = &m.observation else {
            return Err(SimError::InvalidConfig(format!(
                "measurement {} is a sphere centre; the import reads stripe profiles (simulate without --centres)",
                m.id
            )));
        };
        let _ = write!(
            joints_csv,
            "{},{},{},{}",
            m.id,
            m.station,
            m.usage.as_str(),
            m.side
        );
        for q in &m.joints {
            let _ = write!(joints_csv, ",{q}");
        }
        let pose = session.robot.base_from_flange(&m.joints);
        let t = pose.translation.vector;
        let r = pose.rotation;
        let _ = writeln!(
            joints_csv,
            ",{:.6},{:.6},{:.6},{:.12},{:.12},{:.12},{:.12}",
            t.x, t.y, t.z, r.w, r.i, r.j, r.k
        );
        let mut text = String::from("y,z\n");
        for [y, z] in points {
            let _ = writeln!(text, "{y},{z}");
        }
        profiles.push((m.id.clone(), text));
    }
    let references_csv = (!session.reference_distances.is_empty()).then(|| {
        let mut text = String::from("from,to,distance\n");
        for r in &session.reference_distances {
            let _ = writeln!(text, "{},{},{}", r.from, r.to, r.distance);
        }
        text
    });
    Ok(ImportFiles {
        joints_csv,
        profiles,
        references_csv,
    })
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;

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

    #[test]
    fn paper_hand_eye_is_orthonormal_and_close_to_print() {
        let rows = paper_hand_eye_rows();
        assert!(isometry_from_rows(&rows).is_ok());
        let r = Matrix3::from_fn(|i, j| rows[i][j]);
        assert!((r.transpose() * r - Matrix3::identity()).abs().max() < 1e-11);
        for i in 0..3 {
            for j in 0..4 {
                assert!(
                    (rows[i][j] - PAPER_HAND_EYE_ROWS[i][j]).abs() < 5e-4,
                    "{i},{j}"
                );
            }
        }
        // The independent simulator's truth (shared/examples) orthonormalised
        // the same print to these numbers.
        let example = [0.870272377859, 0.492452900999, -0.01077629963];
        for (a, b) in rows[0].iter().zip(example) {
            assert!((a - b).abs() < 1e-6, "{a} vs {b}");
        }
        let he = paper_hand_eye();
        assert!((he.translation.vector - Vector3::new(-7.442, -1.012, 287.804)).norm() < 1e-12);
        // Sensor z points back toward the flange.
        assert!((he.rotation * Vector3::z()).z < -0.99);
        assert!(isometry_from_rows(&orthonormal_rows(&PAPER_INITIAL_HAND_EYE_ROWS)).is_ok());
    }

    #[test]
    fn wrap_and_counts() {
        assert_eq!(wrap_deg(190.0), -170.0);
        assert_eq!(wrap_deg(-180.0), 180.0);
        assert_eq!(wrap_deg(540.0), 180.0);
        assert!((wrap_deg(-725.0) - -5.0).abs() < 1e-12);
        // r = 14.59 mm, ±55°, 0.5 mm: 28.0 mm of arc, 57 points.
        let r = 19.05 * 40f64.to_radians().cos();
        assert_eq!(stripe_point_count(r, 55.0, 0.5), 57);
    }

    #[test]
    fn cone_directions_stay_in_the_cone() {
        let mut rng = stream(3, 0);
        let axis = Vector3::new(1.0, 0.0, -1.0).normalize();
        for _ in 0..200 {
            let d = direction_in_cone(&mut rng, &axis, 40f64.to_radians());
            assert!((d.norm() - 1.0).abs() < 1e-12);
            assert!(d.dot(&axis).acos().to_degrees() <= 40.0 + 1e-9);
            let r = rotation_from_approach(&d, 1.0);
            assert!((r * Vector3::z() - d).norm() < 1e-12);
        }
    }

    #[test]
    fn mixed_sides_are_balanced() {
        let mut rng = stream(5, 0);
        for n in [2, 5, 6] {
            let s = station_sides(&mut rng, n, SideChoice::Mixed);
            let plus = s.iter().filter(|v| **v == 1).count();
            assert!(plus == n / 2 || plus == n.div_ceil(2), "{s:?}");
        }
    }

    #[test]
    fn ordered_map_keeps_order_and_rejects_duplicates() {
        let map = OrderedMap(vec![("b".to_owned(), 1), ("a".to_owned(), 2)]);
        let text = serde_json::to_string(&map).unwrap();
        assert_eq!(text, r#"{"b":1,"a":2}"#);
        let back: OrderedMap<i32> = serde_json::from_str(&text).unwrap();
        assert_eq!(back, map);
        assert!(serde_json::from_str::<OrderedMap<i32>>(r#"{"a":1,"a":2}"#).is_err());
    }

    #[test]
    fn bad_settings_are_rejected() {
        let bad = [
            SimConfig {
                joint_noise: -1.0,
                ..SimConfig::default()
            },
            SimConfig {
                stripe_noise: f64::NAN,
                ..SimConfig::default()
            },
            SimConfig {
                outlier_fraction: 1.5,
                ..SimConfig::default()
            },
            SimConfig {
                cut_angle: 88.0,
                ..SimConfig::default()
            },
            SimConfig {
                poses_per_station: 1,
                ..SimConfig::default()
            },
            SimConfig {
                n_translation: 2,
                ..SimConfig::default()
            },
            SimConfig {
                point_spacing: 20.0,
                ..SimConfig::default()
            },
            SimConfig {
                diameter: 0.0,
                ..SimConfig::default()
            },
        ];
        for c in bad {
            assert!(
                matches!(simulate(&c), Err(SimError::InvalidConfig(_))),
                "{c:?}"
            );
        }
        // With an initial hand-eye, no translations or rotations are needed.
        let c = SimConfig {
            n_translation: 0,
            n_rotation: 0,
            n_identify: 1,
            n_validate: 0,
            initial_hand_eye: InitialHandEye::Truth,
            ..SimConfig::default()
        };
        let (s, t) = simulate(&c).unwrap();
        assert_eq!(s.measurements.len(), 6);
        assert!(s.hand_eye.is_some());
        assert!(t.station("P0").is_none());
    }

    #[test]
    fn unreachable_workspace_is_reported() {
        let c = SimConfig {
            n_translation: 0,
            n_rotation: 0,
            n_identify: 1,
            n_validate: 0,
            initial_hand_eye: InitialHandEye::Paper,
            workspace: Some(Workspace {
                min: [5000.0, 0.0, 0.0],
                max: [5000.0, 0.0, 0.0],
                eye: [0.0, 0.0, 1000.0],
            }),
            ..SimConfig::default()
        };
        match simulate(&c) {
            Err(SimError::Unreachable { station, .. }) => assert_eq!(station, "P1"),
            other => panic!("{other:?}"),
        }
    }
}
