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
//!    ([`Chain::solutions`](crate::engine::base::robot::ik::Chain::solutions)) within the joint
//!    limits and at least `min_wrist_angle` from the wrist singularity is a
//!    candidate, kept only when the reference forward kinematics puts the
//!    planned sensor-frame centre on the station (to 1e-6 mm).
//! 2. **Identifiable parameters.** The `ml` method's own identifiability
//!    analysis ([`solve::run`](crate::engine::calibrate::solve::run) with no update) is run on the whole candidate
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
//!    The default objective ([`Selection::Volume`]) is I-optimal instead:
//!    the same greedy additions and exchanges minimise `tr(Q·M⁻¹)`, the
//!    mean square predicted σ of a sphere centre (after the rigid
//!    alignment) over poses sampled in the working volume
//!    ([`VOLUME_SAMPLES`]: the station box × the viewing axis tilted
//!    [`VOLUME_TILT_DEG`] from straight down over [`VOLUME_ARC_DEG`] ×
//!    the spin). In both, the information of the `P0` groups (one station)
//!    is part of the prior, and identify and validate candidates see the
//!    sphere within [`DEFAULT_STATION_SPREAD_MM`] of the laser plane's
//!    centre (`PlanConfig::station_spread`; over the range with a spread).
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
//!    randomly perturbed robots and calibrates each run; [`entry`] is the
//!    one entry of both that the command line and the workbench call.
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

use nalgebra::{Isometry3, Vector3};
use rand_chacha::ChaCha8Rng;

use crate::engine::base::cell::random;
use crate::engine::base::robot::ik::{Chain, DOF};
use crate::engine::base::robot::{JointLimit, Robot};
use crate::engine::base::session::{SensorRange, Use};
use crate::engine::calibrate::solve::ml::range::RangeError;
use crate::engine::calibrate::solve::ml::{Inseparable, SETUP_CHECK};
use crate::engine::calibrate::solve::{Control, SolveError};
use crate::engine::tools::simulate::{PlanPose, SimError};

mod candidates;
mod config;
pub mod entry;
mod export;
pub mod fixed;
mod order;
mod predict;
pub mod range_study;
mod request;
mod select;

pub use crate::engine::base::robot::controller::Controller;
pub use candidates::stripe_centre_covariance;
use candidates::{
    Candidate, Group, Planner, STREAM_BASELINE, STREAM_GEOMETRY, STREAM_VOLUME, Site, joint_gap,
    provisional_id, side_quota, unknown_indices,
};
pub use config::{
    DEFAULT_BOX_MM, DEFAULT_CANDIDATES, DEFAULT_CENTRE_SPREAD_MM, DEFAULT_CONE_DEG,
    DEFAULT_CUT_ANGLE_DEG, DEFAULT_MIN_WRIST_DEG, DEFAULT_ROTATION_MAX_DEG,
    DEFAULT_ROTATION_MIN_DEG, DEFAULT_SPIN_DEG, DEFAULT_STATION_SPREAD_MM,
    DEFAULT_TRANSLATION_STEP_MM, MAX_CANDIDATES, MAX_GROUP_POSES, MAX_ORIENTATIONS, MAX_STATIONS,
    PlanConfig, PlanDesign, Selection, StationLayout, VOLUME_ARC_DEG, VOLUME_SAMPLES,
    VOLUME_TILT_DEG, defaults,
};
pub use entry::{PlanProgress, Planned, plan_and_predict};
pub use export::{
    PROGRAMS, RAPID_MODULE, other_maker_warning, parse_program, plan_csv, program_controller,
    rapid_module, read_plan_csv, render_program, ur_script,
};
use order::{Metric, order_groups};
pub use predict::{
    MAX_PREDICT_RUNS, PredictConfig, Prediction, RangePrediction, RunScore, VolumePrediction,
    predict, simulated_true_hand_eye,
};
pub use request::{PlanRequest, RequestError, read_hand_eye, read_stations};
pub use select::VolumeError;
use select::{
    Info, Objective, criterion, greedy_selection, prior_information, random_selection,
    selection_covariance, spread_selection,
};

/// What failed in one simulated calibration of a prediction.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PredictionFailure {
    /// The plan's poses could not be simulated on the true robot.
    #[error(transparent)]
    Simulate(#[from] SimError),
    /// The calibration of the simulated session failed.
    #[error(transparent)]
    Solve(#[from] SolveError),
}

/// Why a plan (or its prediction) could not be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanError {
    /// A setting is out of range; the message names it.
    #[error("invalid plan setting: {0}")]
    InvalidConfig(String),
    /// No candidate pose sees the station.
    #[error(transparent)]
    Unreachable(#[from] crate::engine::base::cell::Unreachable),
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
    #[error("prediction run {run} (seed {seed}): {failure}")]
    Prediction {
        /// Run index, 1-based.
        run: usize,
        /// Its seed.
        seed: u64,
        /// What failed: the simulation or the calibration.
        #[source]
        failure: PredictionFailure,
    },
    /// The `ml` analysis of the candidates or the plan failed.
    #[error("identifiability analysis failed: {0}")]
    Analysis(#[source] SolveError),
    /// A plan CSV could not be read.
    #[error("line {line}: {message}")]
    Csv {
        /// 1-based line.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// No program export for this controller.
    #[error(
        "no program export for {} controllers (a {} is not written yet): use the plan CSV",
        .0.name(),
        .0.label()
    )]
    NoProgram(Controller),
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
    /// `ml`'s predicted error over the sensor's range at the plan's
    /// validate poses (with a range).
    pub range_error: Option<RangeError>,
    /// The same for the plan made without the spread (same seed, the
    /// sphere at the paper's spot, `ln det`), when this one spreads: what
    /// the spread gains.
    pub range_error_unspread: Option<RangeError>,
    /// The predicted measuring error over the working volume of the chosen
    /// identify poses ([`VolumeError`]).
    pub volume_error: Option<VolumeError>,
    /// The same for the random selection of the same size at the same
    /// stations (the paper's practice: poses not chosen for a criterion).
    pub volume_error_random: Option<VolumeError>,
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
    /// The sensor's measuring range planned for, if any.
    pub range: Option<SensorRange>,
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

    /// The poses as [`simulate::simulate_plan`](crate::engine::tools::simulate::simulate_plan) takes them.
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
    /// The `ml` identifiability analysis of the candidate pool: `done`
    /// of about `of` steps (the analysis's looks at the cancel: every
    /// [`ml::SETUP_CHECK`](crate::engine::calibrate::solve::ml::SETUP_CHECK)
    /// candidates twice, one a pivot), then one a station's information.
    Analysis {
        /// Steps done.
        done: usize,
        /// Steps in all (an estimate; `done` stays below it).
        of: usize,
    },
    /// Greedy selection and exchange passes.
    Selection,
    /// Ordering and the analysis of the chosen plan.
    Ordering,
    /// The plan without the spread, for comparison.
    Comparison,
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
    let chain = checked_chain(config)?;
    let planner = Planner { config, chain };
    let mut rng = random::stream(config.design.seed, STREAM_GEOMETRY);
    let mut sites = planner.sites(&mut rng);
    let mut cancel = |stage| {
        if progress(stage) == Control::Cancel {
            Err(PlanError::Cancelled)
        } else {
            Ok(())
        }
    };
    let groups = gather_candidates(&planner, &mut rng, &mut sites, &mut cancel)?;
    let chosen = choose_poses(&planner, &mut sites, &mut cancel)?;
    cancel(PlanStage::Ordering)?;
    let mut plan = ordered_plan(config, &sites, groups);
    plan.stats.log_det = chosen.log_det;
    plan.stats.log_det_random = chosen.log_det_random;
    plan.stats.volume_error = chosen.volume;
    plan.stats.volume_error_random = chosen.volume_random;
    analyse_plan(&planner, &mut plan)?;
    if config.spread {
        // The comparison: the same cell planned without the spread.
        let unspread = PlanConfig {
            spread: false,
            ..config.clone()
        };
        // Best effort: a comparison that cannot be planned (the spot's
        // candidates fewer than needed) leaves the figure out, not the plan.
        match self::plan(&unspread, &mut |_| progress(PlanStage::Comparison)) {
            Ok(other) => plan.stats.range_error_unspread = other.stats.range_error,
            Err(PlanError::Cancelled) => return Err(PlanError::Cancelled),
            Err(_) => {}
        }
    }
    Ok(plan)
}

/// Checks the configuration (its settings, then a translation group that
/// would be collinear) and builds the fast IK chain of its robot.
fn checked_chain(config: &PlanConfig) -> Result<Chain, PlanError> {
    config.validate()?;
    if (1..3).contains(&config.design.n_translation) {
        return Err(PlanError::CollinearTranslations {
            detail: format!(
                "{} translation pose(s) give {} displacement(s)",
                config.design.n_translation,
                config.design.n_translation - 1
            ),
        });
    }
    if config.design.n_translation >= 3 && config.translation_step <= 0.0 {
        return Err(PlanError::CollinearTranslations {
            detail: format!("the translation step is {} mm", config.translation_step),
        });
    }
    Chain::new(&config.robot).ok_or_else(|| {
        PlanError::InvalidConfig(format!(
            "the planner solves 6-axis arms, {} has {} joints",
            config.robot.name,
            config.robot.dof()
        ))
    })
}

/// Draws the candidates: the hand-eye groups at `P0` (inserted as the
/// first site, returned as the first groups) and every station's pool,
/// each checked for enough poses on both sides; reports each station.
fn gather_candidates(
    planner: &Planner<'_>,
    rng: &mut ChaCha8Rng,
    sites: &mut Vec<Site>,
    cancel: &mut dyn FnMut(PlanStage) -> Result<(), PlanError>,
) -> Result<Vec<Group>, PlanError> {
    let config = planner.config;
    let mut groups: Vec<Group> = Vec::new();
    let hand_eye = config.design.n_translation + config.design.n_rotation > 0;
    let total = sites.len() + usize::from(hand_eye);
    let mut done = 0;
    if hand_eye {
        let p0 = Vector3::from(config.design.sphere);
        let (translations, reference) = planner.translation_group(rng, &p0)?;
        let rotations = planner.rotation_group(rng, &p0, &reference)?;
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
        let id = provisional_id(sites, k);
        sites[k].candidates = planner.station_candidates(rng, &sites[k].position, &id)?;
        let needed = match sites[k].role {
            StationRole::Identify => config.design.identify_poses,
            _ => config.design.validate_poses,
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
    Ok(groups)
}

/// What [`choose_poses`] found: `ln det` and the predicted volume error
/// of the chosen identify poses and of the random baseline of the same
/// size.
struct Chosen {
    log_det: f64,
    log_det_random: f64,
    volume: Option<VolumeError>,
    volume_random: Option<VolumeError>,
}

/// The analysis of the candidate pool (the identifiable parameters, by
/// ml) and the selection: the validate poses spread, the identify poses
/// for the working volume (I-optimal), D-optimal or random.
fn choose_poses(
    planner: &Planner<'_>,
    sites: &mut [Site],
    cancel: &mut dyn FnMut(PlanStage) -> Result<(), PlanError>,
) -> Result<Chosen, PlanError> {
    let config = planner.config;
    let pool: usize = sites
        .iter()
        .filter(|s| s.role == StationRole::Identify)
        .map(|s| s.candidates.len())
        .sum();
    let of = analysis_steps(pool, config.robot.n_params()) + sites.len();
    let mut done = 0;
    cancel(PlanStage::Analysis { done, of })?;
    let labels = planner.pool_estimated(sites, &mut || {
        done = (done + 1).min(of - sites.len() - 1);
        match cancel(PlanStage::Analysis { done, of }) {
            Ok(()) => Control::Continue,
            Err(_) => Control::Cancel,
        }
    })?;
    let estimated = unknown_indices(&config.robot, &labels);
    let mut infos: Vec<Vec<Info>> = Vec::with_capacity(sites.len());
    for (done, s) in (of - sites.len() + 1..).zip(sites.iter()) {
        cancel(PlanStage::Analysis { done, of })?;
        infos.push(if s.role == StationRole::Identify {
            s.candidates
                .iter()
                .map(|c| planner.info(c, &estimated))
                .collect()
        } else {
            Vec::new()
        });
    }
    // The hand-eye groups at P0 are calibration data too (one station,
    // its centre eliminated): their information is in the prior the
    // identify poses add to, so that these are not spent on what P0
    // already gives.
    let mut prior = prior_information(&estimated);
    for s in sites.iter().filter(|s| s.role == StationRole::HandEye) {
        let infos: Vec<Info> = s
            .candidates
            .iter()
            .map(|c| planner.info(c, &estimated))
            .collect();
        let all: Vec<usize> = (0..infos.len()).collect();
        prior += select::StationInfo::of(&infos, &all, estimated.len()).schur();
    }

    cancel(PlanStage::Selection)?;
    let identify_sites: Vec<usize> = (0..sites.len())
        .filter(|&k| sites[k].role == StationRole::Identify)
        .collect();
    let mut baseline_rng = random::stream(config.design.seed, STREAM_BASELINE);
    let random = random_selection(
        sites,
        &identify_sites,
        config.design.identify_poses,
        &mut baseline_rng,
    );
    let log_det_random = criterion(&prior, &infos, &random).unwrap_or(f64::NEG_INFINITY);
    // The validate poses first: they are the working poses the range
    // criterion is judged at.
    for site in sites.iter_mut() {
        if site.role == StationRole::Validate {
            site.chosen = spread_selection(planner, site, config.design.validate_poses);
        }
    }
    // The working volume: sampled poses and their aligned grid.
    let mut volume_rng = random::stream(config.design.seed, STREAM_VOLUME);
    let samples = planner.volume_samples(&mut volume_rng);
    let volume = (!samples.is_empty()).then(|| planner.volume_grid(&samples, &estimated));
    let volume_error = |selection: &[(usize, Vec<usize>)]| {
        let grid = volume.as_ref()?;
        let cov = selection_covariance(&prior, &infos, selection)?;
        VolumeError::of(&grid.sigmas(&cov))
    };
    let volume_random = volume_error(&random);
    let objective = match (config.spread, config.range, &volume) {
        (true, Some(range), _) => Objective::Range(planner.range_weight(sites, &estimated, &range)),
        (_, _, Some(grid)) if config.design.selection == Selection::Volume => {
            Objective::Range(grid.weight())
        }
        _ => Objective::LogDet,
    };
    let chosen = match config.design.selection {
        Selection::Volume | Selection::DOptimal => {
            let mut stop = || cancel(PlanStage::Selection).is_err();
            greedy_selection(
                planner,
                sites,
                &identify_sites,
                &infos,
                &prior,
                &objective,
                &mut stop,
            )
            .ok_or(PlanError::Cancelled)?
        }
        Selection::Random => random,
    };
    for (k, c) in chosen {
        sites[k].chosen = c;
    }
    let selection: Vec<(usize, Vec<usize>)> = sites
        .iter()
        .enumerate()
        .filter(|(_, s)| s.role == StationRole::Identify)
        .map(|(k, s)| (k, s.chosen.clone()))
        .collect();
    let log_det = criterion(&prior, &infos, &selection).unwrap_or(f64::NEG_INFINITY);
    Ok(Chosen {
        log_det,
        log_det_random,
        volume: volume_error(&selection),
        volume_random,
    })
}

/// About how many times the identifiability analysis of `pool`
/// candidates of a robot of `n_params` looks at the cancel: every
/// [`SETUP_CHECK`] candidates while whitening and again while building
/// the Jacobian, once a pivot of the `6 + n_params` unknowns.
fn analysis_steps(pool: usize, n_params: usize) -> usize {
    2 * pool.div_ceil(SETUP_CHECK) + 6 + n_params + 1
}

/// The chosen poses in visit order: the groups (the hand-eye ones, then
/// one a station) ordered for a short joint path, the stations and poses
/// numbered in that order. The statistics hold the path lengths; the rest
/// of them is filled by the caller.
fn ordered_plan(config: &PlanConfig, sites: &[Site], mut groups: Vec<Group>) -> Plan {
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
    let ordered_groups = order_groups(sites, groups, &metric);
    let sequence: Vec<[f64; DOF]> = ordered_groups
        .iter()
        .flat_map(|g| g.poses.iter().map(|c| c.joints))
        .collect();
    let realized = metric.unwrap_path(&sequence);
    let path_deg = metric.path(&realized);
    let (station_ids, stations) = numbered_stations(sites, &ordered_groups);
    let poses = numbered_poses(config, &ordered_groups, &station_ids, &realized);
    Plan {
        robot: config.robot.clone(),
        limits: config.limits.clone(),
        flange_from_sensor: config.flange_from_sensor,
        diameter: config.design.diameter,
        cut_angle: config.design.cut_angle,
        range: config.range,
        stations,
        poses,
        stats: PlanStats {
            candidates: sites.iter().map(|s| s.candidates.len()).sum(),
            estimated: Vec::new(),
            fixed: Vec::new(),
            inseparable: Vec::new(),
            log_det: f64::NAN,
            log_det_random: f64::NAN,
            condition: f64::NAN,
            predicted_validation_std: None,
            path_unordered_deg,
            path_deg,
            range_error: None,
            range_error_unspread: None,
            volume_error: None,
            volume_error_random: None,
        },
    }
}

/// Station ids in visit order (`P0`, `P1`.., `V1`..): the id of each site
/// (by site index) and the planned stations in that order.
fn numbered_stations(
    sites: &[Site],
    ordered_groups: &[Group],
) -> (Vec<Option<String>>, Vec<PlannedStation>) {
    let mut station_ids: Vec<Option<String>> = vec![None; sites.len()];
    let (mut n_identify, mut n_validate) = (0, 0);
    let mut stations = Vec::new();
    for g in ordered_groups {
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
    (station_ids, stations)
}

/// The planned poses in visit order, numbered per use (`t1`.., `r1`..,
/// `c1`.., `v1`..), with the joints of the realized (unwrapped) path and
/// their flange poses on the nominal model.
fn numbered_poses(
    config: &PlanConfig,
    ordered_groups: &[Group],
    station_ids: &[Option<String>],
    realized: &[[f64; DOF]],
) -> Vec<PlannedPose> {
    let mut counters = [0usize; 4];
    let mut poses = Vec::with_capacity(realized.len());
    let mut joints_iter = realized.iter();
    for g in ordered_groups {
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
    poses
}

/// The `ml` analysis of the chosen plan into its statistics: what it
/// identifies, the condition number, the predicted validation std and
/// the error over the range.
fn analyse_plan(planner: &Planner<'_>, plan: &mut Plan) -> Result<(), PlanError> {
    let report = planner.plan_report(plan)?;
    let plan_estimated = unknown_indices(&planner.config.robot, &report.estimated);
    plan.stats.condition = planner.condition(plan, &plan_estimated);
    plan.stats.estimated = report.estimated;
    plan.stats.fixed = report.fixed;
    plan.stats.inseparable = report.inseparable;
    plan.stats.predicted_validation_std = report.predicted_distance_std_validate.map(|d| d.centred);
    plan.stats.range_error = report.range_error;
    Ok(())
}

impl Plan {
    /// The plan's poses in one line, as the command line and the
    /// workbench show it: poses of each use, stations of each role.
    #[must_use]
    pub fn pose_counts(&self) -> String {
        let stations = |role| self.stations.iter().filter(|s| s.role == role).count();
        format!(
            "{} poses: {} translation, {} rotation at P0; {} identify at {} stations; {} validate at {} stations",
            self.poses.len(),
            self.count(Use::Translation),
            self.count(Use::Rotation),
            self.count(Use::Identify),
            stations(StationRole::Identify),
            self.count(Use::Validate),
            stations(StationRole::Validate)
        )
    }
}

/// A few lines for people (the command line's summary).
#[must_use]
pub fn summary(plan: &Plan) -> String {
    let mut s = String::new();
    let st = &plan.stats;
    let _ = writeln!(s, "plan for {}: {}", plan.robot.name, plan.pose_counts());
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
    if let Some(r) = st
        .range_error
        .as_ref()
        .filter(|r| r.region != "sensor.range")
    {
        let _ = writeln!(
            s,
            "  predicted point error where the sphere is seen (y {:.0}…{:.0}, z {:.0}…{:.0} mm, ml covariance): rms {:.4} mm; give --range for the sensor's measuring range",
            r.y[0], r.y[1], r.z[0], r.z[1], r.rms_mm
        );
    }
    if let Some(r) = st
        .range_error
        .as_ref()
        .filter(|r| r.region == "sensor.range")
    {
        let _ = writeln!(
            s,
            "  predicted point error over the range (y {:.0}…{:.0}, z {:.0}…{:.0} mm, ml covariance): rms {:.4} mm, max {:.4} mm",
            r.y[0], r.y[1], r.z[0], r.z[1], r.rms_mm, r.max_mm
        );
        match &st.range_error_unspread {
            Some(u) => {
                let _ = writeln!(
                    s,
                    "    the sphere spread over the range; without the spread: rms {:.4} mm, max {:.4} mm ({:.2}× the rms)",
                    u.rms_mm,
                    u.max_mm,
                    u.rms_mm / r.rms_mm
                );
            }
            None if r.coverage
                < crate::engine::calibrate::solve::ml::range::RANGE_COVERAGE_WARNING =>
            {
                let _ = writeln!(
                    s,
                    "    the sphere at one spot ({:.0} % of the range): spread it over the range for less error away from it",
                    r.coverage * 100.0
                );
            }
            None => {
                let _ = writeln!(
                    s,
                    "    the sphere seen over {:.0} % of the range",
                    r.coverage * 100.0
                );
            }
        }
    }
    if let Some(v) = &st.volume_error {
        let _ = writeln!(
            s,
            "  predicted measuring error over the working volume (σ of a sphere centre after the rigid alignment, {} sampled poses: station box × viewing axis 10-40° from straight down × spin): rms {:.4} mm, max {:.4} mm",
            v.samples, v.rms_mm, v.max_mm
        );
        if let Some(r) = &st.volume_error_random {
            let _ = writeln!(
                s,
                "    the same stations with poses at random (the paper's practice), same number of measurements: rms {:.4} mm, max {:.4} mm ({:.2}× the rms)",
                r.rms_mm,
                r.max_mm,
                r.rms_mm / v.rms_mm
            );
        }
    }
    let _ = writeln!(
        s,
        "  path: {:.0} deg of weighted joint moves ({:.0} deg before ordering)",
        st.path_deg, st.path_unordered_deg
    );
    s
}
