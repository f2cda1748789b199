//! Poses for a fixed sensor (FORMAT.md `sensor.mount: "fixed"`): joint
//! configurations whose target on the tool lies in a workspace box, faces
//! the sensor within a cone (a tracker's line of sight to an SMR) and is
//! within its reach; identify poses chosen greedily for D-optimality of the
//! fixed-mount identification (the sensitivity of
//! [`crate::engine::calibrate::solve::estimate`] with the target as an
//! unknown), validate poses drawn from the rest.

use std::fmt::Write as _;

use nalgebra::{DMatrix, Isometry3, Matrix3, Point3, Vector3};

use super::PlanError;
use crate::engine::base::cell::random::{stream, uniform};
use crate::engine::base::robot::Preset;
use crate::engine::base::session::{Mount, Use};
use crate::engine::calibrate::handeye::Sighting;
use crate::engine::calibrate::solve::estimate::{Estimate, sensitivity, unknown_scale};

/// Random stream of the candidates.
const STREAM_FIXED_CANDIDATES: u64 = 21;
/// Draws per wanted candidate before giving up.
const TRIES_PER_CANDIDATE: usize = 200;
/// The wrist's joints, drawn again for one arm configuration.
const WRIST_JOINTS: usize = 3;
/// Wrist draws per arm configuration.
const WRIST_DRAWS: usize = 60;
/// How far beyond the box (besides the target's lever) the flange of an
/// arm configuration may be, mm: the wrist's own reach.
const WRIST_MARGIN_MM: f64 = 250.0;
/// Regularisation of the information matrix (per scaled unknown): the
/// exact redundancies of the model stay finite.
const RIDGE: f64 = 1e-6;

/// What a fixed sensor's plan needs.
#[derive(Debug, Clone)]
pub struct FixedPlanRequest {
    /// The robot and its joint limits.
    pub preset: Preset,
    /// Where the sensor stands and looks (`bT_s`, a guess).
    pub base_from_sensor: Isometry3<f64>,
    /// The target on the tool, flange frame, mm, and the way it faces.
    pub target: Vector3<f64>,
    /// See `target`.
    pub target_normal: Vector3<f64>,
    /// Half-angle of the line-of-sight cone, deg.
    pub cone_deg: f64,
    /// Farthest reach of the sensor, mm.
    pub reach_mm: f64,
    /// The workspace box the target must lie in, base frame, mm.
    pub box_min: [f64; 3],
    /// See `box_min`.
    pub box_max: [f64; 3],
    /// Identify and validate poses wanted.
    pub n_identify: usize,
    /// See `n_identify`.
    pub n_validate: usize,
    /// Candidates drawn.
    pub candidates: usize,
    /// Seed of the draw.
    pub seed: u64,
}

/// One planned pose.
#[derive(Debug, Clone, PartialEq)]
pub struct FixedPose {
    /// Pose id (`P1`, …).
    pub id: String,
    /// Identify or validate.
    pub usage: Use,
    /// Joint readings, deg.
    pub joints: Vec<f64>,
}

/// The poses of `req`: identify first, then validate.
///
/// # Errors
/// [`PlanError::InvalidConfig`] for a setting out of range or when too
/// few drawn poses see the target.
pub fn plan_fixed(req: &FixedPlanRequest) -> Result<Vec<FixedPose>, PlanError> {
    let wanted = req.n_identify + req.n_validate;
    if req.n_identify == 0 || req.candidates < wanted || !(0.0..90.0).contains(&req.cone_deg) {
        return Err(PlanError::InvalidConfig(format!(
            "a fixed sensor's plan needs identify poses, at least as many candidates ({}) as poses ({wanted}) and a cone in [0, 90)°",
            req.candidates
        )));
    }
    let robot = &req.preset.robot;
    let mut rng = stream(req.seed, STREAM_FIXED_CANDIDATES);
    let cos_cone = req.cone_deg.to_radians().cos();
    let sensor = req.base_from_sensor.translation.vector;
    let mut candidates: Vec<Vec<f64>> = Vec::with_capacity(req.candidates);
    let mut tries = 0;
    while candidates.len() < req.candidates {
        tries += 1;
        if tries > TRIES_PER_CANDIDATE * req.candidates {
            return Err(PlanError::InvalidConfig(format!(
                "only {} of {} drawn poses put the target in the box, facing the sensor within {}° and within {} mm; widen the box or the cone",
                candidates.len(),
                req.candidates,
                req.cone_deg,
                req.reach_mm
            )));
        }
        let mut q: Vec<f64> = req
            .preset
            .limits
            .iter()
            .map(|l| uniform(&mut rng, l.min.max(-180.0), l.max.min(180.0)))
            .collect();
        // The arm first: the flange near the box (within the target's
        // lever), then the wrist drawn until the target faces the sensor.
        let lever = req.target.norm() + WRIST_MARGIN_MM;
        let wrist = robot.base_from_flange(&q).translation.vector;
        let near = (0..3)
            .all(|k| wrist[k] >= req.box_min[k] - lever && wrist[k] <= req.box_max[k] + lever);
        if !near {
            continue;
        }
        let last = q.len().saturating_sub(WRIST_JOINTS);
        for _ in 0..WRIST_DRAWS {
            for (j, l) in req.preset.limits.iter().enumerate().skip(last) {
                q[j] = uniform(&mut rng, l.min.max(-180.0), l.max.min(180.0));
            }
            let flange = robot.base_from_flange(&q);
            let x = (flange * Point3::from(req.target)).coords;
            let inside = (0..3).all(|k| (req.box_min[k]..=req.box_max[k]).contains(&x[k]));
            let to_sensor = sensor - x;
            let distance = to_sensor.norm();
            let facing = (flange.rotation * req.target_normal).dot(&(to_sensor / distance));
            if inside && distance < req.reach_mm && facing >= cos_cone {
                candidates.push(q);
                break;
            }
        }
    }
    let est = Estimate {
        robot: robot.clone(),
        flange_from_sensor: req.base_from_sensor,
        mount: Mount::Fixed,
    };
    // Each candidate's rows: the scaled sensitivity and −I for the target.
    let rows: Vec<DMatrix<f64>> = candidates
        .iter()
        .map(|q| {
            let seen = req
                .base_from_sensor
                .inverse_transform_point(&(robot.base_from_flange(q) * Point3::from(req.target)));
            let s = Sighting {
                id: String::new(),
                joints: q.clone(),
                flange: None,
                centre_in_sensor: seen.coords,
            };
            let a = sensitivity(&est, &s).1;
            let n = a.ncols();
            DMatrix::from_fn(3, n + 3, |r, c| {
                if c < n {
                    a[(r, c)] / unknown_scale(c)
                } else if r == c - n {
                    -1.0
                } else {
                    0.0
                }
            })
        })
        .collect();
    let n = rows.first().map_or(0, DMatrix::ncols);
    let mut info = DMatrix::<f64>::identity(n, n) * RIDGE;
    let mut chosen: Vec<usize> = Vec::with_capacity(wanted);
    let mut taken = vec![false; candidates.len()];
    for _ in 0..req.n_identify {
        let Some(inverse) = info.clone().try_inverse() else {
            break;
        };
        let mut best: Option<(usize, f64)> = None;
        for (i, j) in rows.iter().enumerate() {
            if taken[i] {
                continue;
            }
            let m: Matrix3<f64> =
                Matrix3::identity() + (j * &inverse * j.transpose()).fixed_view::<3, 3>(0, 0);
            let gain = m.determinant().ln();
            if best.is_none_or(|(_, g)| gain > g) {
                best = Some((i, gain));
            }
        }
        let Some((i, _)) = best else { break };
        taken[i] = true;
        info += rows[i].transpose() * &rows[i];
        chosen.push(i);
    }
    let mut rest: Vec<usize> = (0..candidates.len()).filter(|i| !taken[*i]).collect();
    for _ in 0..req.n_validate {
        if rest.is_empty() {
            break;
        }
        let k = (uniform(&mut rng, 0.0, rest.len() as f64) as usize).min(rest.len() - 1);
        chosen.push(rest.swap_remove(k));
    }
    Ok(chosen
        .into_iter()
        .enumerate()
        .map(|(k, i)| FixedPose {
            id: format!("P{}", k + 1),
            usage: if k < req.n_identify {
                Use::Identify
            } else {
                Use::Validate
            },
            joints: candidates[i]
                .iter()
                .map(|v| (v * 1e6).round() / 1e6)
                .collect(),
        })
        .collect())
}

/// The plan as a joint log (`id,use,j1..jn`, deg): what the robot runs
/// and what `import --mount fixed` reads beside the sensor's points.
#[must_use]
pub fn fixed_plan_csv(poses: &[FixedPose]) -> String {
    let dof = poses.first().map_or(0, |p| p.joints.len());
    let mut out = String::from("id,use");
    for k in 1..=dof {
        let _ = write!(out, ",j{k}");
    }
    out.push('\n');
    for p in poses {
        let _ = write!(out, "{},{}", p.id, p.usage.as_str());
        for q in &p.joints {
            let _ = write!(out, ",{q}");
        }
        out.push('\n');
    }
    out
}
