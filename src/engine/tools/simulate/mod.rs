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

pub mod config;
pub mod fixed;
pub mod from_plan;
pub mod import_files;
mod poses;
pub mod parts;
mod stripe;
pub mod truth;

pub use config::{ErrorModel, InitialHandEye, SideChoice, SimConfig, SimError};
pub use fixed::{FixedCell, FixedTruth, simulate_fixed};
pub use from_plan::{PlanExecution, PlanPose, simulate_plan};
pub use import_files::{ImportFiles, import_files};
pub use parts::{Part, PartKind, ScanConfig, ScanTruth, SimulatedScan, simulate_scan};
pub use truth::{Truth, TruthError, load_truth, parse_truth, truth_to_json};

use nalgebra::Vector3;
use rand_chacha::ChaCha8Rng;

use crate::engine::base::cell::random::{normal, stream};
use crate::engine::base::cell::sensor::{paper_hand_eye_rows, paper_initial_hand_eye};
use crate::engine::base::cell::workspace::{Workspace, planning_limits};
use crate::engine::base::geometry::rigid_from_rows;
use crate::engine::base::numeric::round_to;
use crate::engine::base::robot::ik::Chain;
use crate::engine::base::robot::{self, Joint, table1_errors};
use crate::engine::base::session::{
    Measurement, Observation, ReferenceDistance, Session, SolverSettings, Use,
};
use config::{RANDOM_ANGLE_SIGMA_DEG, RANDOM_LENGTH_SIGMA_MM, validate_config};
use poses::{Planner, Pose, plan};
use stripe::stripe;
use truth::{MeasurementTruth, OrderedMap, TRUTH_FORMAT, TRUTH_VERSION, TrueDistance, TruthRobot};

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

/// Stream ids: geometry, kinematic errors, measurement noise.
const STREAM_GEOMETRY: u64 = 0;
/// See [`STREAM_GEOMETRY`].
const STREAM_ERRORS: u64 = 1;
/// See [`STREAM_GEOMETRY`].
const STREAM_NOISE: u64 = 2;
/// See [`STREAM_GEOMETRY`]: the reported flange poses' error of a
/// pose-only session ([`SimConfig::pose_only`]), its own stream so that
/// the stripes of a pose-only session are those of the joint session of
/// the same seed.
const STREAM_POSES: u64 = 3;

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
            flange: None,
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

/// The true robot of `config` on `nominal`: nominal plus the kinematic
/// errors drawn from the errors stream, and the errors.
pub(crate) fn with_errors(
    config: &SimConfig,
    nominal: &robot::Robot,
) -> (robot::Robot, Vec<Joint>) {
    let mut rng_errors = stream(config.seed, STREAM_ERRORS);
    let errors = kinematic_errors(config, nominal.dof(), &mut rng_errors);
    let mut true_robot = nominal.clone();
    for (joint, e) in true_robot.joints.iter_mut().zip(&errors) {
        joint.alpha += e.alpha;
        joint.a += e.a;
        joint.beta += e.beta;
        joint.theta += e.theta;
        joint.d += e.d;
    }
    (true_robot, errors)
}

/// The preset of `config`'s robot, the true robot and the errors
/// ([`with_errors`]): the same for a session and a scan of the same seed,
/// robot and error model, so that a simulated scan is measured by the
/// calibration of a simulated session.
pub(crate) fn true_cell(
    config: &SimConfig,
) -> Result<(robot::Preset, robot::Robot, Vec<Joint>), SimError> {
    let preset = robot::preset(config.robot.key())
        .ok_or_else(|| SimError::InvalidConfig(format!("unknown robot {}", config.robot.key())))?;
    let (true_robot, errors) = with_errors(config, &preset.robot);
    Ok((preset, true_robot, errors))
}

/// Simulates a session and its ground truth (see the module docs).
///
/// # Errors
/// [`SimError::InvalidConfig`] for a setting out of range,
/// [`SimError::Unreachable`] when a station cannot be seen from the cone.
pub fn simulate(config: &SimConfig) -> Result<(Session, Truth), SimError> {
    validate_config(config)?;
    let (preset, true_robot, errors) = true_cell(config)?;
    let nominal = preset.robot.clone();
    let dof = nominal.dof();
    let workspace = config
        .workspace
        .unwrap_or_else(|| Workspace::for_robot(config.robot));
    let mut rng_geometry = stream(config.seed, STREAM_GEOMETRY);
    let mut rng_noise = stream(config.seed, STREAM_NOISE);
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
    let mut session = Session {
        // The simulator's own robots keep their base and flange unwritten.
        base_given: false,
        flange_given: false,
        reference_distances,
        ..simulated_session(
            &name,
            &nominal,
            config,
            default_side,
            hand_eye,
            measurements,
        )
    };
    if let Some(sigma) = config.pose_only {
        report_flange_poses(&mut session, &true_robot, &plan.poses, sigma, config.seed);
    }
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

/// Turns `session` pose-only ([`SimConfig::pose_only`]): each
/// measurement's flange pose is the true robot's at the pose's actual
/// joints, its position off by N(0, σ²) in each base-frame coordinate (the
/// error a controller's reported pose has); joints and robot are dropped.
/// `poses` are the measurements' poses in order.
fn report_flange_poses(
    session: &mut Session,
    true_robot: &crate::engine::base::robot::Robot,
    poses: &[Pose],
    sigma: f64,
    seed: u64,
) {
    let mut rng = stream(seed, STREAM_POSES);
    for (m, pose) in session.measurements.iter_mut().zip(poses) {
        let mut flange = true_robot.base_from_flange(&pose.joints);
        for k in 0..3 {
            flange.translation.vector[k] += sigma * normal(&mut rng);
        }
        m.flange = Some(flange);
        m.joints.clear();
    }
    session.robot_given = false;
    session.robot = crate::engine::base::robot::Robot::new(String::new(), Vec::new());
}

/// The session of a simulation: the nominal robot, the simulated sensor
/// (its side and range) and solver settings, the hand-eye when the
/// configuration gives one; reference distances added by the caller.
pub(crate) fn simulated_session(
    name: &str,
    nominal: &crate::engine::base::robot::Robot,
    config: &SimConfig,
    default_side: i8,
    hand_eye: Option<nalgebra::Isometry3<f64>>,
    measurements: Vec<Measurement>,
) -> Session {
    Session {
        default_side,
        sensor_given: true,
        sensor_range: config.range,
        hand_eye,
        solver: SolverSettings {
            threshold: config.threshold,
            max_iterations: config.max_iterations,
        },
        solver_given: true,
        ..Session::made(
            name.to_owned(),
            nominal.clone(),
            config.diameter,
            measurements,
        )
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;
    use crate::engine::tools::simulate::config::stripe_point_count;
    use crate::engine::tools::simulate::poses::station_sides;

    #[test]
    fn stripe_point_counts() {
        // r = 14.59 mm, ±55°, 0.5 mm: 28.0 mm of arc, 57 points.
        let r = 19.05 * 40f64.to_radians().cos();
        assert_eq!(stripe_point_count(r, 55.0, 0.5), 57);
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
            Err(SimError::Unreachable(u)) => assert_eq!(u.station, "P1"),
            other => panic!("{other:?}"),
        }
    }
}
