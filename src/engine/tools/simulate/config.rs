//! Every knob of the simulator ([`SimConfig`]) and its checks.

use serde::{Deserialize, Serialize};

use crate::engine::base::cell::workspace::Workspace;
use crate::engine::base::robot::RobotChoice;
use crate::engine::base::session::{DEFAULT_MAX_ITERATIONS, DEFAULT_THRESHOLD};
use crate::engine::base::session::{MIN_STRIPE_POINTS, SensorRange};

/// σ of the `random` kinematic errors for angles (alpha, beta, theta), deg,
/// at `error_scale = 1`: the size of the paper's Table 1 angle errors
/// (most within ±0.5°, median ~0.08°).
pub const RANDOM_ANGLE_SIGMA_DEG: f64 = 0.1;
/// σ of the `random` kinematic errors for lengths (a, d), mm, at
/// `error_scale = 1`: Table 1's length errors are within ±0.7 mm.
pub const RANDOM_LENGTH_SIGMA_MM: f64 = 0.3;

/// Largest σ of the stripe point noise and of the centre noise, mm: ten
/// times the worst laser-stripe sensor (~1 mm) and a quarter of a small
/// (38 mm) sphere's radius; beyond it a stripe is no longer an arc and
/// the points leave the loader's plausible sensor field.
pub const MAX_SENSOR_NOISE_MM: f64 = 10.0;
/// Largest σ of the joint reading noise, deg: a thousand times an
/// encoder's (~0.003°); beyond it readings stop meaning a pose.
pub const MAX_JOINT_NOISE_DEG: f64 = 3.0;
/// Largest σ of the laser tracker's reference distances, mm (a tracker
/// measures to ~0.01 mm).
pub const MAX_TRACKER_NOISE_MM: f64 = 10.0;
/// Largest `error_scale`: 100 × Table 1 puts angle errors near 50°, far
/// beyond any real robot's deviations from its nominal model.
pub const MAX_ERROR_SCALE: f64 = 100.0;

/// Most stations of a simulated session (identify and validate): 60,000
/// measurements at 6 a station, far beyond any cell's (the workbench's
/// large-session tests simulate 2,000); each one writes files.
pub const MAX_STATIONS: usize = 10_000;
/// Most poses of one group (translations, rotations, or one station's).
pub const MAX_GROUP_POSES: usize = 100;

/// Where the true kinematic model comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ErrorModel {
    /// The paper's Table 1 ([`TABLE1`](crate::engine::base::robot::presets::TABLE1)) times `error_scale`.
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
    /// The paper's initial hand-eye ([`PAPER_INITIAL_HAND_EYE_ROWS`](crate::engine::base::cell::sensor::PAPER_INITIAL_HAND_EYE_ROWS)).
    Paper,
    /// The true hand-eye (a perfect start, for tests).
    Truth,
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
    /// The sensor's measuring range, written as `sensor.range` (issue 14).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub range: Option<SensorRange>,
    /// Spread the sphere over `range`: the identify and validate
    /// measurements see the sphere centre at `(y, z)` uniform in the range
    /// instead of the paper's ±2, ±3 mm (the `P0` hand-eye groups keep the
    /// paper's spot). Needs `range`. Not echoed when off.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub spread: bool,
    /// A pose-only session (FORMAT.md `measurements[].flange`, issue 32):
    /// every measurement reports its flange pose as a controller would,
    /// the true flange position plus Gaussian error of this σ (mm, each
    /// base-frame coordinate; the orientation exact), and carries no
    /// joints and no robot. `None`: joints, as the paper. Not echoed when
    /// off.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pose_only: Option<f64>,
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
            range: None,
            spread: false,
            pose_only: None,
        }
    }
}

/// Why [`simulate`](crate::engine::tools::simulate::simulate) could not
/// build a session.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    /// A setting is out of range; the message names it.
    #[error("invalid simulation setting: {0}")]
    InvalidConfig(String),
    /// No orientation in the cone reached a station within the joint
    /// limits and away from the wrist singularity.
    #[error(transparent)]
    Unreachable(#[from] crate::engine::base::cell::Unreachable),
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

pub(super) fn check(ok: bool, message: impl FnOnce() -> String) -> Result<(), SimError> {
    if ok {
        Ok(())
    } else {
        Err(SimError::InvalidConfig(message()))
    }
}

impl SimConfig {
    /// Checks every setting, as [`simulate`](super::simulate) does before
    /// any work (so that a caller can refuse options before writing
    /// anything).
    ///
    /// # Errors
    /// [`SimError::InvalidConfig`] naming the setting and its value.
    pub fn validate(&self) -> Result<(), SimError> {
        validate_config(self)
    }
}

pub(super) fn validate_config(c: &SimConfig) -> Result<(), SimError> {
    check_numbers(c)?;
    if let Some(sigma) = c.pose_only {
        check(
            sigma.is_finite() && (0.0..=MAX_SENSOR_NOISE_MM).contains(&sigma),
            || {
                format!(
                    "pose_only: the flange poses' σ must lie within 0 to {MAX_SENSOR_NOISE_MM} mm, found {sigma} mm"
                )
            },
        )?;
    }
    check_sensor_model(c)?;
    check_motion(c)?;
    check_stripes_and_range(c)
}

/// Every number finite, the noises not negative and plausible, the counts
/// within the session limits, at least one identify station.
fn check_numbers(c: &SimConfig) -> Result<(), SimError> {
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
    for (name, v, limit, unit) in [
        ("stripe_noise", c.stripe_noise, MAX_SENSOR_NOISE_MM, "mm"),
        ("centre_noise", c.centre_noise, MAX_SENSOR_NOISE_MM, "mm"),
        ("joint_noise", c.joint_noise, MAX_JOINT_NOISE_DEG, "deg"),
        ("tracker_noise", c.tracker_noise, MAX_TRACKER_NOISE_MM, "mm"),
        (
            "error_scale",
            c.error_scale,
            MAX_ERROR_SCALE,
            "(times the errors)",
        ),
    ] {
        check(v.abs() <= limit, || {
            format!(
                "{name} {} {unit} is not plausible: at most {limit} (a simulated session must stay one its loader reads)",
                crate::engine::base::numeric::show(v)
            )
        })?;
    }
    for (name, n, limit) in [
        (
            "n_identify + n_validate",
            c.n_identify + c.n_validate,
            MAX_STATIONS,
        ),
        ("poses_per_station", c.poses_per_station, MAX_GROUP_POSES),
        ("n_translation", c.n_translation, MAX_GROUP_POSES),
        ("n_rotation", c.n_rotation, MAX_GROUP_POSES),
    ] {
        check(n <= limit, || {
            format!("{name} is {n}: a simulated session has at most {limit}")
        })?;
    }
    check(c.n_identify >= 1, || {
        "at least one identify station is needed: a session without one cannot be calibrated"
            .to_owned()
    })?;
    Ok(())
}

/// The sensor model: outliers, the sphere's diameter, the stripe sampling,
/// the cut angle and the camera's distance.
fn check_sensor_model(c: &SimConfig) -> Result<(), SimError> {
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
    check(
        c.diameter <= crate::engine::base::limits::SPHERE_DIAMETER_MM,
        || {
            format!(
                "diameter {} mm is not plausible (at most {} mm)",
                crate::engine::base::numeric::show(c.diameter),
                crate::engine::base::limits::SPHERE_DIAMETER_MM
            )
        },
    )?;
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
    Ok(())
}

/// The robot's motion: the approach cone, the wrist, the translation and
/// rotation groups, the poses per station, and the hand-eye groups a
/// session without an initial hand-eye needs.
fn check_motion(c: &SimConfig) -> Result<(), SimError> {
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
    Ok(())
}

/// Enough points on the shortest stripe, the sensor range and its spread,
/// the workspace box.
fn check_stripes_and_range(c: &SimConfig) -> Result<(), SimError> {
    // The shortest stripe: the largest cut angle gives the smallest circle.
    let radius = c.diameter / 2.0;
    let smallest_r = radius * (c.cut_angle + c.cut_jitter).to_radians().cos();
    let points = stripe_point_count(smallest_r, c.arc_half_angle, c.point_spacing);
    check(points >= MIN_STRIPE_POINTS, || {
        format!(
            "stripes would have only {points} points (FORMAT.md needs {MIN_STRIPE_POINTS}); reduce point_spacing or widen arc_half_angle"
        )
    })?;
    if let Some(r) = &c.range {
        let ok = |v: [f64; 2]| v.iter().all(|x| x.is_finite()) && v[0] < v[1];
        check(ok(r.y) && ok(r.z), || {
            format!(
                "range needs finite [min, max] with min < max, found y {:?}, z {:?}",
                r.y, r.z
            )
        })?;
        check(r.z[1] + c.diameter < c.view_z, || {
            format!(
                "range z reaches {} mm: the sphere would touch the camera at view_z {} mm",
                r.z[1], c.view_z
            )
        })?;
    }
    check(!c.spread || c.range.is_some(), || {
        "spread needs a range: the sphere is spread over the sensor's range".to_owned()
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
pub(super) fn stripe_point_count(r: f64, half_angle_deg: f64, spacing: f64) -> usize {
    let arc = 2.0 * half_angle_deg.to_radians() * r;
    // Truncation intended: whole points that fit on the arc.
    let n = (arc / spacing).floor().max(0.0) as usize;
    n + 1
}
