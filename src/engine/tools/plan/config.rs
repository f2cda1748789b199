//! What a plan is asked for: the robot and its limits, the rough sphere
//! position, the hand-eye guess, the counts of stations and poses, the cut
//! angle and the candidate search; with the checks of every setting.

use nalgebra::{Isometry3, Vector3};

use crate::engine::base::cell::sensor;
use crate::engine::base::cell::workspace::{self, Workspace};
use crate::engine::base::numeric::show;
use crate::engine::base::robot::ik::DOF;
use crate::engine::base::robot::{JointLimit, Preset, Robot, RobotChoice};
use crate::engine::base::session::{SensorRange, limits};
use crate::engine::tools::simulate::SimConfig;

use super::*;

/// Most stations of a plan (identify and validate together). The paper
/// uses 9 identify and 10 validate stations; a cell's plan rarely needs
/// more than a few dozen. Planning time grows with the stations (about
/// 20 ms each in a debug build, a few in release), so 500 stay well
/// within a minute; beyond, the request is a typo.
pub const MAX_STATIONS: usize = 500;

/// Most candidate orientations drawn per station (default 24).
pub const MAX_CANDIDATES: usize = 1000;

/// Most candidate orientations of a whole plan (stations × candidates):
/// 500 stations at the default 24. The identifiability analysis and the
/// selection work on every candidate pose (up to 16 a orientation), so
/// this bounds the plan's time and memory.
pub const MAX_ORIENTATIONS: usize = 12_000;

/// Most poses of one group (translations, rotations, or the poses of one
/// identify or validate station): ten times the paper's.
pub const MAX_GROUP_POSES: usize = 100;

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
/// Default half-widths (mm) of the sensor-frame `y`, `z` of the sphere
/// centre at the identify and validate poses: the sphere spread over
/// ±12 mm of the laser plane about the paper's spot (the `P0` groups keep
/// the spot, [`DEFAULT_CENTRE_SPREAD_MM`]). Where in the plane the sphere is
/// seen is information a spot lacks: on simulated cells the volume error
/// over the floor fell from 1.39× to 1.31× (30 cells) with it, and the
/// predicted one by a quarter (docs/src/evidence/volume.md). The stripe
/// then moves up to 12 mm in each direction: a sensor whose field is
/// smaller gives its `--range` (the sphere is then spread over that).
pub const DEFAULT_STATION_SPREAD_MM: [f64; 2] = [12.0, 12.0];
/// The viewing axis (the flange approach) of the working volume's sampled
/// poses: tilted this far from straight down, deg, ...
pub const VOLUME_TILT_DEG: [f64; 2] = [10.0, 40.0];
/// ... toward an azimuth within an arc of this many degrees centred on the
/// horizontal direction from the robot to the place (the sensor on the
/// robot's side of the part, looking out and down), as parts are measured
/// (the check of issue 32).
pub const VOLUME_ARC_DEG: f64 = 200.0;
/// Default half-range of the spin about the viewing axis in the working
/// volume, deg: the flange turned up to ±90° about its approach from a
/// reference roll (its x axis toward the station, away from the robot).
pub const DEFAULT_SPIN_DEG: f64 = 90.0;
/// Sampled poses of the working volume the volume objective averages
/// over (position uniform in the station box, the viewing axis tilted
/// [`VOLUME_TILT_DEG`] from straight down over [`VOLUME_ARC_DEG`], spin in
/// its range, one reachable IK branch each).
pub const VOLUME_SAMPLES: usize = 64;
/// Default station box (mm) for a robot that is not a preset: a 300 mm
/// cube about the sphere position.
pub const DEFAULT_BOX_MM: [f64; 3] = [300.0; 3];

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
    /// Greedy I-optimal with exchange passes for the working volume: the
    /// smallest mean predicted measuring error (`tr(Q·M⁻¹)`, the mean
    /// square of the per-point σ `measure` would report, after the
    /// rigid alignment) over sampled poses of the working volume (the
    /// station box × the approach cone × the spin about the viewing
    /// axis, see the module docs). The default: with the `P0` groups in
    /// the information and the sphere spread over the laser plane it
    /// gives the smallest realised volume error on simulated cells
    /// (docs/src/evidence/volume.md).
    #[default]
    Volume,
    /// Greedy D-optimal with exchange passes (the module docs).
    DOptimal,
    /// A seeded random balanced selection: the baseline.
    Random,
}

/// The defaults of a plan, the command line's, the Plan view's and
/// [`PlanDesign::new`]'s: the paper's experiment (section 4), as the
/// simulator's defaults.
pub mod defaults {
    /// Sphere diameter, mm: the paper's 38.1 mm sphere.
    pub const DIAMETER_MM: f64 = 38.1;
    /// Translation poses at P0: one more than eq. 6-7's minimum of 3.
    pub const TRANSLATIONS: usize = 4;
    /// Rotation poses at P0, as the paper's experiment.
    pub const ROTATIONS: usize = 6;
    /// Identify stations: the paper's 3 × 3 layers.
    pub const IDENTIFY_STATIONS: usize = 9;
    /// Poses per identify station, as the paper's.
    pub const IDENTIFY_POSES: usize = 6;
    /// Validate stations: the paper's 54 distances are 9 pairs × 6 poses.
    pub const VALIDATE_STATIONS: usize = 10;
    /// Poses per validate station.
    pub const VALIDATE_POSES: usize = 6;
    /// Seed of every random choice.
    pub const SEED: u64 = 1;
}

/// What a plan is made of, the same whether a person asks for it
/// ([`super::PlanRequest`]) or the planner works from it
/// ([`PlanConfig`]): the sphere, how many stations and poses of each
/// group, the cut of the laser plane and how the identify poses are
/// searched and chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanDesign {
    /// Rough sphere position (station `P0`), base frame, mm.
    pub sphere: [f64; 3],
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
}

impl PlanDesign {
    /// The paper-like design ([`defaults`]) about a sphere at `sphere`:
    /// 4 translations, 6 rotations, 9 identify and 10 validate stations of
    /// 6 poses, a 38.1 mm sphere cut at 40°, 24 candidate orientations per
    /// station, the volume selection, seed 1.
    #[must_use]
    pub fn new(sphere: [f64; 3]) -> Self {
        Self {
            sphere,
            diameter: defaults::DIAMETER_MM,
            n_translation: defaults::TRANSLATIONS,
            n_rotation: defaults::ROTATIONS,
            n_identify: defaults::IDENTIFY_STATIONS,
            identify_poses: defaults::IDENTIFY_POSES,
            n_validate: defaults::VALIDATE_STATIONS,
            validate_poses: defaults::VALIDATE_POSES,
            cut_angle: DEFAULT_CUT_ANGLE_DEG,
            candidates: DEFAULT_CANDIDATES,
            selection: Selection::Volume,
            seed: defaults::SEED,
        }
    }
}

/// Everything the planner needs. [`PlanConfig::for_preset`] and
/// [`PlanConfig::new`] fill the defaults.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanConfig {
    /// The nominal model the controller uses (6 joints).
    pub robot: Robot,
    /// Joint limits, deg, one per joint.
    pub limits: Vec<JointLimit>,
    /// The sphere, the counts of stations and poses, the cut and the
    /// candidate search: as the request asked.
    pub design: PlanDesign,
    /// The hand-eye guess `flange_from_sensor` (mm).
    pub flange_from_sensor: Isometry3<f64>,
    /// Identify and validate stations.
    pub stations: StationLayout,
    /// Eye point (base frame, mm): approach directions centre on
    /// `station − eye`. `None`: above the robot base at the sphere's
    /// height plus its horizontal distance from the base (a 45° look down
    /// and outward).
    pub eye: Option<[f64; 3]>,
    /// Half-angle of the approach cone, deg.
    pub cone_angle: f64,
    /// Half-range of the spin about the viewing axis in the working
    /// volume, deg ([`DEFAULT_SPIN_DEG`]).
    pub spin_deg: f64,
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
    /// Half-widths (mm) of the sensor-frame `y` and `z` of the planned
    /// centres at the identify and validate stations (without a spread
    /// over `range`): [`DEFAULT_STATION_SPREAD_MM`].
    pub station_spread: [f64; 2],
    /// The sensor's measuring range (`sensor.range`, issue 14): the plan's
    /// analysis predicts the error over it.
    pub range: Option<SensorRange>,
    /// Spread the sphere over `range`: identify and validate candidates
    /// see the centre anywhere in the range (instead of `centre_spread`)
    /// and the identify poses are chosen for the smallest predicted error
    /// over the range (`tr(Q·M⁻¹)`, see `select`) instead of `ln det`.
    /// Needs `range`.
    pub spread: bool,
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
            design: PlanDesign::new(sphere),
            flange_from_sensor: sensor::paper_initial_hand_eye(),
            stations: StationLayout::Box {
                size: DEFAULT_BOX_MM,
            },
            eye: None,
            cone_angle: DEFAULT_CONE_DEG,
            spin_deg: DEFAULT_SPIN_DEG,
            min_wrist_angle: DEFAULT_MIN_WRIST_DEG,
            translation_step: DEFAULT_TRANSLATION_STEP_MM,
            rotation_min: DEFAULT_ROTATION_MIN_DEG,
            rotation_max: DEFAULT_ROTATION_MAX_DEG,
            joint_weights: vec![1.0; dof],
            joint_sigma_deg: sim.joint_noise,
            stripe_sigma: sim.stripe_noise,
            centre_spread: DEFAULT_CENTRE_SPREAD_MM,
            station_spread: DEFAULT_STATION_SPREAD_MM,
            range: None,
            spread: false,
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
        let s = Vector3::from(self.design.sphere);
        let horizontal = (s.x - b.x).hypot(s.y - b.y);
        Vector3::new(b.x, b.y, s.z + horizontal)
    }

    /// Checks every setting.
    ///
    /// # Errors
    /// [`PlanError::InvalidConfig`] naming the setting and its value.
    pub fn validate(&self) -> Result<(), PlanError> {
        self.check_robot()?;
        self.check_lengths()?;
        self.check_angles()?;
        self.check_counts()?;
        self.check_stations()
    }

    /// The robot: a 6-axis arm with a limit and a positive weight per joint.
    fn check_robot(&self) -> Result<(), PlanError> {
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
        Ok(())
    }

    /// Every real setting finite; the centre spread, the sensor range and its
    /// spread; the sphere and the stations within the session file's
    /// plausibility limits.
    fn check_lengths(&self) -> Result<(), PlanError> {
        let reals = [
            ("diameter", self.design.diameter),
            ("cut angle", self.design.cut_angle),
            ("cone angle", self.cone_angle),
            ("spin", self.spin_deg),
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
        check(
            self.station_spread
                .iter()
                .all(|v| v.is_finite() && *v >= 0.0),
            || "the station spread needs two finite, non-negative half-widths (mm)".to_owned(),
        )?;
        if let Some(r) = &self.range {
            let ok = |v: [f64; 2]| v.iter().all(|x| x.is_finite()) && v[0] < v[1];
            check(ok(r.y) && ok(r.z), || {
                format!(
                    "the sensor range needs finite [min, max] with min < max, found y {:?}, z {:?} mm",
                    r.y, r.z
                )
            })?;
        }
        check(!self.spread || self.range.is_some(), || {
            "spreading the sphere needs the sensor's range (--range)".to_owned()
        })?;
        check(self.design.sphere.iter().all(|v| v.is_finite()), || {
            "the sphere position must be three finite numbers (mm)".to_owned()
        })?;
        check(self.design.diameter > 0.0, || {
            format!(
                "the sphere diameter must be positive, found {} mm",
                self.design.diameter
            )
        })?;
        // The session file's plausibility limits: a plan's numbers end up
        // in sessions and messages.
        check(self.design.diameter <= limits::SPHERE_DIAMETER_MM, || {
            format!(
                "the sphere diameter {} mm is not plausible (at most {} mm)",
                show(self.design.diameter),
                limits::SPHERE_DIAMETER_MM
            )
        })?;
        let far = |v: &[f64]| v.iter().any(|x| x.abs() > limits::LENGTH_MM);
        check(!far(&self.design.sphere), || {
            format!(
                "the sphere position [{}, {}, {}] mm is not plausible (at most {} mm from the base)",
                show(self.design.sphere[0]),
                show(self.design.sphere[1]),
                show(self.design.sphere[2]),
                limits::LENGTH_MM
            )
        })?;
        let box_far = match &self.stations {
            StationLayout::Box { size } => far(size),
            StationLayout::Explicit { identify, validate } => {
                identify.iter().chain(validate).any(|p| far(p))
            }
        };
        check(!box_far && !far(&[self.translation_step]), || {
            format!(
                "station positions, the station box and the translation step must stay within {} mm",
                limits::LENGTH_MM
            )
        })?;
        Ok(())
    }

    /// The cut, cone, wrist and rotation angles, the noise model, at least
    /// one candidate orientation.
    fn check_angles(&self) -> Result<(), PlanError> {
        check(
            self.design.cut_angle > 5.0 && self.design.cut_angle < 80.0,
            || {
                format!(
                    "the cut angle must be within (5, 80) deg, found {}",
                    self.design.cut_angle
                )
            },
        )?;
        check((0.0..=90.0).contains(&self.cone_angle), || {
            format!(
                "the cone angle must be within 0..90 deg, found {}",
                self.cone_angle
            )
        })?;
        check((0.0..=180.0).contains(&self.spin_deg), || {
            format!(
                "the spin must be within 0..180 deg, found {}",
                self.spin_deg
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
        check(self.design.candidates >= 1, || {
            "at least one candidate orientation per station is needed".to_owned()
        })?;
        Ok(())
    }

    /// The counts of stations, candidates and poses: within the plan's limits
    /// and enough for each group.
    fn check_counts(&self) -> Result<(), PlanError> {
        let stations = self.n_identify_stations() + self.n_validate_stations();
        check(stations <= MAX_STATIONS, || {
            format!(
                "{stations} stations asked for ({} identify, {} validate): a plan has at most {MAX_STATIONS}",
                self.n_identify_stations(),
                self.n_validate_stations()
            )
        })?;
        check(self.design.candidates <= MAX_CANDIDATES, || {
            format!(
                "{} candidate orientations per station asked for: at most {MAX_CANDIDATES}",
                self.design.candidates
            )
        })?;
        check(
            stations.saturating_mul(self.design.candidates) <= MAX_ORIENTATIONS,
            || {
                format!(
                    "{stations} stations × {} candidates = {} orientations to solve: a plan has at most {MAX_ORIENTATIONS}; ask for fewer stations or candidates",
                    self.design.candidates,
                    stations.saturating_mul(self.design.candidates)
                )
            },
        )?;
        for (name, n) in [
            ("translation poses", self.design.n_translation),
            ("rotation poses", self.design.n_rotation),
            ("identify poses per station", self.design.identify_poses),
            ("validate poses per station", self.design.validate_poses),
        ] {
            check(n <= MAX_GROUP_POSES, || {
                format!("{n} {name} asked for: at most {MAX_GROUP_POSES}")
            })?;
        }
        check(self.design.n_rotation != 1, || {
            "the rotation group needs at least 2 poses (eq. 8 uses pairs), or none".to_owned()
        })?;
        check(self.n_identify_stations() >= 1, || {
            "at least one identify station is needed".to_owned()
        })?;
        check(self.design.identify_poses >= 2, || {
            format!(
                "an identify station needs at least 2 poses (FORMAT.md), found {}",
                self.design.identify_poses
            )
        })?;
        check(
            self.n_validate_stations() == 0 || self.design.validate_poses >= 1,
            || "validate stations need at least 1 pose".to_owned(),
        )?;
        Ok(())
    }

    /// The station box or the explicit station positions: finite (mm).
    fn check_stations(&self) -> Result<(), PlanError> {
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

    pub(super) fn n_identify_stations(&self) -> usize {
        match &self.stations {
            StationLayout::Box { .. } => self.design.n_identify,
            StationLayout::Explicit { identify, .. } => identify.len(),
        }
    }

    pub(super) fn n_validate_stations(&self) -> usize {
        match &self.stations {
            StationLayout::Box { .. } => self.design.n_validate,
            StationLayout::Explicit { validate, .. } => validate.len(),
        }
    }

    pub(super) fn radius(&self) -> f64 {
        self.design.diameter / 2.0
    }

    /// The planned sensor-frame centre on `side`.
    pub(super) fn centre(&self, side: i8) -> Vector3<f64> {
        Vector3::new(
            f64::from(side) * self.radius() * self.design.cut_angle.to_radians().sin(),
            0.0,
            0.0,
        )
    }
}

pub(super) fn check(ok: bool, message: impl FnOnce() -> String) -> Result<(), PlanError> {
    if ok {
        Ok(())
    } else {
        Err(PlanError::InvalidConfig(message()))
    }
}
