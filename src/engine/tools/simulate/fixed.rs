//! Simulated cells with a fixed sensor and targets on the tool (FORMAT.md
//! `sensor.mount: "fixed"`, added 2026-11-27): a laser tracker measuring
//! SMRs, a fixed 3-D camera or scanner fitting a sphere the robot
//! carries, or a fixed laser line scanner whose plane cuts that sphere
//! (stripes, fitted by eq. 21 in the sensor's frame), each with its
//! ground truth.
//!
//! The true robot is the nominal one plus the kinematic errors of the
//! [`SimConfig`]'s error model (the flange-mount simulator's
//! [`with_errors`], same seed, same errors). Poses are joint readings drawn
//! around a home configuration and kept when every target faces the
//! sensor within the acceptance cone and lies within the sensor's reach;
//! each kept pose measures every target (several measurements with the
//! same joints, FORMAT.md). The sensor reports each target in its own
//! frame, `bT_s⁻¹ · bT_e(q) · X_e`, with Gaussian noise of the stated σ
//! per sensor axis; a line scanner ([`LinePlane`]) instead reports the
//! stripe of the sphere in its laser plane (the flange simulator's
//! stripes, noise on every point), the first joint turned by Newton's
//! method until the sphere's centre lies at a drawn distance from the
//! plane.

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

use super::config::{SimConfig, SimError};
use super::stripe::stripe;
use super::with_errors;
use crate::engine::base::cell::random::{normal, stream, uniform};
use crate::engine::base::numeric::round_to;
use crate::engine::base::robot::Robot;
use crate::engine::base::session::{Measurement, Mount, Observation, Session, SolverSettings, Use};

/// Random stream of the poses (apart from the flange simulator's streams).
const STREAM_FIXED_POSES: u64 = 11;
/// Random stream of the sensor noise.
const STREAM_FIXED_NOISE: u64 = 12;
/// Random stream of the reported flange poses' error of a pose-only cell
/// ([`SimConfig::pose_only`]), its own so that the poses and the sensor's
/// readings are those of the joint session of the same seed.
const STREAM_FIXED_FLANGE: u64 = 13;
/// Draws per wanted pose before the simulator gives up.
const TRIES_PER_POSE: usize = 400;
/// Decimals of the written sensor coordinates (1 nm: far below any noise,
/// and below the exactness the noise-free tests ask).
const DECIMALS: i32 = 6;
/// Decimals of the written joints (1e-9°, ~2e-8 mm at a metre), as the
/// flange simulator writes them.
const JOINT_DECIMALS: i32 = 9;

/// What stands in the cell and what the robot carries.
#[derive(Debug, Clone, PartialEq)]
pub struct FixedCell {
    /// Name of the session.
    pub name: String,
    /// `bT_s`: the sensor's true pose in the base frame.
    pub base_from_sensor: Isometry3<f64>,
    /// The targets: id and true point in the flange frame, mm.
    pub targets: Vec<(String, Vector3<f64>)>,
    /// The direction (flange frame, unit) the targets face.
    pub target_normal: Vector3<f64>,
    /// Half-angle of the acceptance cone, deg (an SMR's ±30° and more).
    pub cone_deg: f64,
    /// Farthest distance from the sensor a target may be, mm.
    pub reach_mm: f64,
    /// 1σ sensor noise along the sensor's x, y, z, mm.
    pub noise_mm: [f64; 3],
    /// Sphere (or SMR) diameter written to the session, mm.
    pub diameter: f64,
    /// Home joints, deg, and the half-width of the draw about them per joint.
    pub home: Vec<f64>,
    /// See `home`.
    pub spread: Vec<f64>,
    /// Poses measured for identification and held out for validation.
    pub n_identify: usize,
    /// See `n_identify`.
    pub n_validate: usize,
    /// A laser line scanner: stripes of the (one) target sphere in its
    /// laser plane instead of points; `None`: points.
    pub line: Option<LinePlane>,
}

/// A fixed laser line scanner: where the sphere's centre may lie for its
/// plane (`x = 0`) to cut a usable stripe, and the stripe's noise.
#[derive(Debug, Clone, PartialEq)]
pub struct LinePlane {
    /// The centre's distance from the laser plane, sensor `x`, drawn
    /// uniform in this range, mm (within the sphere radius): positive on
    /// side +1, negative on side −1 (the measurements' side).
    pub cut_mm: [f64; 2],
    /// Largest `|y|` of the centre in the sensor frame, mm.
    pub half_width_mm: f64,
    /// The centre's sensor `z` range (the scanner's depth of field), mm.
    pub depth_mm: [f64; 2],
    /// 1σ noise of every stripe point on each coordinate, mm.
    pub point_noise_mm: f64,
}

impl FixedCell {
    /// A laser tracker 2.4 m in front of an IRB 2400, three SMRs on the
    /// tool, `noise` mm on each coordinate.
    #[must_use]
    pub fn tracker(noise: f64) -> Self {
        Self {
            name: "tracker cell".into(),
            base_from_sensor: sensor_at(Vector3::new(2600.0, 300.0, 900.0)),
            targets: vec![
                ("SMR1".into(), Vector3::new(40.0, 0.0, 110.0)),
                ("SMR2".into(), Vector3::new(-30.0, 45.0, 120.0)),
                ("SMR3".into(), Vector3::new(-20.0, -50.0, 100.0)),
            ],
            target_normal: Vector3::z(),
            cone_deg: 60.0,
            reach_mm: 4000.0,
            noise_mm: [noise; 3],
            diameter: 38.1,
            home: vec![0.0, 20.0, 10.0, 0.0, -30.0, 0.0],
            spread: vec![35.0, 25.0, 25.0, 60.0, 40.0, 60.0],
            n_identify: 60,
            n_validate: 12,
            line: None,
        }
    }

    /// A fixed 3-D scanner 1.4 m in front of the robot, one sphere on the
    /// tool; `noise` mm across the view, three times that in depth.
    #[must_use]
    pub fn scanner(noise: f64) -> Self {
        Self {
            name: "fixed scanner cell".into(),
            base_from_sensor: sensor_at(Vector3::new(1900.0, -200.0, 1100.0)),
            targets: vec![("BALL".into(), Vector3::new(0.0, 30.0, 150.0))],
            target_normal: Vector3::z(),
            cone_deg: 85.0,
            reach_mm: 1800.0,
            noise_mm: [noise, noise, 3.0 * noise],
            diameter: 25.0,
            ..Self::tracker(noise)
        }
    }

    /// A fixed laser line scanner (a profile sensor with a 300 mm deep
    /// field at 300-600 mm) in front of an IRB 2400's tool, one 25 mm
    /// sphere on the tool cut by its vertical laser plane; `noise` mm on
    /// every stripe point.
    #[must_use]
    pub fn line_scanner(noise: f64) -> Self {
        let target = Vector3::new(0.0, 20.0, 140.0);
        let home = vec![0.0, 20.0, 10.0, 0.0, -30.0, 0.0];
        let nominal = crate::engine::base::robot::irb2400().robot;
        let at_home = (nominal.base_from_flange(&home) * Point3::from(target)).coords;
        Self {
            name: "fixed line scanner cell".into(),
            base_from_sensor: line_scanner_at(&at_home, 450.0),
            targets: vec![("BALL".into(), target)],
            target_normal: Vector3::z(),
            cone_deg: 80.0,
            reach_mm: 1000.0,
            noise_mm: [0.0; 3],
            diameter: 25.0,
            home,
            spread: vec![8.0, 15.0, 15.0, 50.0, 35.0, 60.0],
            n_identify: 60,
            n_validate: 12,
            line: Some(LinePlane {
                cut_mm: [5.0, 10.0],
                half_width_mm: 120.0,
                depth_mm: [300.0, 600.0],
                point_noise_mm: noise,
            }),
        }
    }
}

/// A line scanner `standoff` mm out from `aim` (base frame; outward from
/// the base axis and up), looking at it along its `z`, its laser plane
/// (`x = 0`) vertical through the base axis' radial direction, so that
/// the first joint moves a point across the plane.
fn line_scanner_at(aim: &Vector3<f64>, standoff: f64) -> Isometry3<f64> {
    let outward = Vector3::new(aim.x, aim.y, 0.0).normalize();
    let from = (outward + Vector3::z() * 0.6).normalize();
    let position = aim + from * standoff;
    // z toward the aim; x horizontal, along the first joint's motion.
    let z = -from;
    let x = Vector3::z().cross(&outward).normalize();
    let y = z.cross(&x);
    let rotation = UnitQuaternion::from_rotation_matrix(
        &nalgebra::Rotation3::from_matrix_unchecked(nalgebra::Matrix3::from_columns(&[x, y, z])),
    );
    Isometry3::from_parts(Translation3::from(position), rotation)
}

/// A sensor at `position` (base frame) looking along its `z` at the
/// robot's workspace (toward the base's `−x`), its `y` down.
fn sensor_at(position: Vector3<f64>) -> Isometry3<f64> {
    let look = (Vector3::new(1100.0, 0.0, 800.0) - position).normalize();
    let rotation = UnitQuaternion::face_towards(&look, &-Vector3::z());
    Isometry3::from_parts(Translation3::from(position), rotation)
}

/// The truth of a fixed-sensor simulation.
#[derive(Debug, Clone, PartialEq)]
pub struct FixedTruth {
    /// The true robot.
    pub robot: Robot,
    /// The true `bT_s`.
    pub base_from_sensor: Isometry3<f64>,
    /// The true targets on the flange, by station id.
    pub targets: Vec<(String, Vector3<f64>)>,
    /// Whether the sensor had no noise.
    pub noise_free: bool,
}

impl FixedTruth {
    /// A target's true point, flange frame.
    #[must_use]
    pub fn target(&self, id: &str) -> Option<Vector3<f64>> {
        self.targets.iter().find(|(t, _)| t == id).map(|(_, p)| *p)
    }

    /// The error of predicting what the sensor measured at joints `q` for
    /// `station` with the true model, mm: the noise floor of one
    /// measurement.
    #[must_use]
    pub fn prediction_error(&self, q: &[f64], station: &str, measured: &Vector3<f64>) -> f64 {
        let Some(x_e) = self.target(station) else {
            return f64::NAN;
        };
        let predicted = self
            .base_from_sensor
            .inverse_transform_point(&(self.robot.base_from_flange(q) * Point3::from(x_e)));
        (predicted.coords - measured).norm()
    }
}

/// Turns the first joint of `q` (within `limits`) until the sphere's
/// centre lies `x` mm from the line scanner's plane (Newton's method on
/// the true robot), and says whether it then lies in the window.
fn onto_the_plane(
    robot: &Robot,
    cell: &FixedCell,
    line: &LinePlane,
    q: &mut [f64],
    x: f64,
    limits: (f64, f64),
) -> bool {
    let Some((_, target)) = cell.targets.first() else {
        return false;
    };
    let at = |q: &[f64]| {
        cell.base_from_sensor
            .inverse_transform_point(&(robot.base_from_flange(q) * Point3::from(*target)))
            .coords
    };
    let h = 1e-4;
    for _ in 0..20 {
        let f = at(q).x - x;
        if f.abs() < 1e-9 {
            break;
        }
        let mut qh = q.to_vec();
        qh[0] += h;
        let slope = (at(&qh).x - at(q).x) / h;
        if slope.abs() < 1e-6 {
            return false;
        }
        q[0] = (q[0] - f / slope).clamp(limits.0, limits.1);
    }
    let c = at(q);
    (c.x - x).abs() < 1e-6
        && c.y.abs() <= line.half_width_mm
        && (line.depth_mm[0]..=line.depth_mm[1]).contains(&c.z)
}

/// A fixed-sensor session of `cell` on `config`'s robot and error model
/// (seeded by `config.seed`), with its truth. The session gives no
/// `hand_eye`: the engine's linear start finds `bT_s`.
///
/// # Errors
/// [`SimError::InvalidConfig`] for an unknown robot or home of the wrong
/// length, [`SimError::Unreachable`]-like configuration errors when too few
/// poses see every target.
pub fn simulate_fixed(
    config: &SimConfig,
    cell: &FixedCell,
) -> Result<(Session, FixedTruth), SimError> {
    let preset = crate::engine::base::robot::preset(config.robot.key())
        .ok_or_else(|| SimError::InvalidConfig(format!("unknown robot {}", config.robot.key())))?;
    let nominal = preset.robot.clone();
    let (true_robot, _) = with_errors(config, &nominal);
    let dof = nominal.dof();
    if cell.home.len() != dof || cell.spread.len() != dof {
        return Err(SimError::InvalidConfig(format!(
            "the fixed cell's home and spread need {dof} joints each"
        )));
    }
    let mut rng = stream(config.seed, STREAM_FIXED_POSES);
    let mut noise = stream(config.seed, STREAM_FIXED_NOISE);
    let mut flange_noise = stream(config.seed, STREAM_FIXED_FLANGE);
    let side: i8 = match &cell.line {
        Some(line) if line.cut_mm[1] < 0.0 => -1,
        _ => 1,
    };
    let wanted = cell.n_identify + cell.n_validate;
    let cos_cone = cell.cone_deg.to_radians().cos();
    let mut measurements = Vec::new();
    let mut poses = 0;
    let mut tries = 0;
    while poses < wanted {
        tries += 1;
        if tries > TRIES_PER_POSE * wanted {
            return Err(SimError::InvalidConfig(format!(
                "only {poses} of {wanted} drawn poses saw every target within the {}° cone and {} mm",
                cell.cone_deg, cell.reach_mm
            )));
        }
        let mut q: Vec<f64> = (0..dof)
            .map(|j| {
                let (lo, hi) = (preset.limits[j].min, preset.limits[j].max);
                uniform(
                    &mut rng,
                    cell.home[j] - cell.spread[j],
                    cell.home[j] + cell.spread[j],
                )
                .clamp(lo, hi)
            })
            .collect();
        if let Some(line) = &cell.line {
            let x = uniform(&mut rng, line.cut_mm[0], line.cut_mm[1]);
            let limits = (preset.limits[0].min, preset.limits[0].max);
            if !onto_the_plane(&true_robot, cell, line, &mut q, x, limits) {
                continue;
            }
        }
        let flange = true_robot.base_from_flange(&q);
        let sensor_pos = cell.base_from_sensor.translation.vector;
        let normal_b = flange.rotation * cell.target_normal;
        let seen = cell.targets.iter().all(|(_, x_e)| {
            let x_b = (flange * Point3::from(*x_e)).coords;
            let to_sensor = sensor_pos - x_b;
            let distance = to_sensor.norm();
            distance < cell.reach_mm && normal_b.dot(&(to_sensor / distance)) >= cos_cone
        });
        if !seen {
            continue;
        }
        let usage = if poses < cell.n_identify {
            Use::Identify
        } else {
            Use::Validate
        };
        let q_written: Vec<f64> = q.iter().map(|v| round_to(*v, JOINT_DECIMALS)).collect();
        // A pose-only cell reports the pose's true flange pose, its
        // position off by N(0, σ²) in each base coordinate (one error a
        // pose, shared by its targets), as the flange mount's pose-only
        // sessions do.
        let reported = config.pose_only.map(|sigma| {
            let mut f = true_robot.base_from_flange(&q_written);
            for k in 0..3 {
                f.translation.vector[k] += sigma * normal(&mut flange_noise);
            }
            f
        });
        for (id, x_e) in &cell.targets {
            let flange = true_robot.base_from_flange(&q_written);
            let x_s = cell
                .base_from_sensor
                .inverse_transform_point(&(flange * Point3::from(*x_e)))
                .coords;
            let observation = match &cell.line {
                Some(line) => {
                    let c = SimConfig {
                        diameter: cell.diameter,
                        stripe_noise: line.point_noise_mm,
                        outlier_fraction: 0.0,
                        // The camera beside the laser, at the sensor's origin.
                        view_z: 0.0,
                        stripe_decimals: DECIMALS,
                        ..config.clone()
                    };
                    Observation::Stripe(stripe(&c, &mut noise, &x_s))
                }
                None => Observation::Centre(Vector3::from_fn(|k, _| {
                    round_to(x_s[k] + cell.noise_mm[k] * normal(&mut noise), DECIMALS)
                })),
            };
            measurements.push(Measurement {
                id: format!("p{}-{id}", poses + 1),
                station: id.clone(),
                usage,
                side_given: None,
                side,
                joints: if reported.is_some() {
                    Vec::new()
                } else {
                    q_written.clone()
                },
                flange: reported,
                observation,
            });
        }
        poses += 1;
    }
    let pose_only = config.pose_only.is_some();
    let session = Session {
        mount: Mount::Fixed,
        sensor_given: true,
        default_side: side,
        robot_given: !pose_only,
        solver: SolverSettings {
            threshold: config.threshold,
            max_iterations: config.max_iterations,
        },
        solver_given: true,
        ..Session::made(
            cell.name.clone(),
            if pose_only {
                Robot::new(String::new(), Vec::new())
            } else {
                nominal
            },
            cell.diameter,
            measurements,
        )
    };
    let truth = FixedTruth {
        robot: true_robot,
        base_from_sensor: cell.base_from_sensor,
        targets: cell.targets.clone(),
        noise_free: cell.noise_mm.iter().all(|s| *s == 0.0)
            && cell.line.as_ref().is_none_or(|l| l.point_noise_mm == 0.0)
            && config.pose_only.is_none_or(|s| s == 0.0),
    };
    Ok((session, truth))
}
