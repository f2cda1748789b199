//! A calibrated model written back onto another description of the same
//! robot (issue 33): a chain of joint origins as a URDF or UR's
//! `kinematics:` file has it (fixed and revolute joints, each revolute one
//! turning about its own `<axis>` after its `<origin>`), with only the
//! revolute joints' origins changed so that the chain's forward
//! kinematics is the calibrated model's.
//!
//! The chain and the nominal model describe one robot: at every joint
//! vector `q` (deg), `W · chain(q) = nominal(q)` for one constant `W`
//! (the model's base frame in the chain's root frame; the identity for a
//! model imported from that URDF). Then each revolute joint's link frame
//! `L_i(q)` sits at a constant offset `E_i` from the model's MDH frame
//! `i`, `W · L_i(q) = P_i(q) · E_i` (both turn about the same axis line).
//! The calibrated chain keeps the offsets: `L'_i = W⁻¹ · P'_i · E_i`, so
//! link geometry (meshes, inertials) moves with its calibrated frame, and
//! a revolute joint's new origin is `(L'_{parent} · fixed)⁻¹ · L'_i` at
//! `q = 0`. The tip keeps its fixed joints, so `W · chain'(q) =
//! calibrated(q)` (the model's flange `F` is not calibrated).

use nalgebra::{Isometry3, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};

use super::kinematics::Robot;

/// Joint vectors at which chain and model are compared.
const CHECKS: usize = 12;

/// Largest translation (mm) between chain and model accepted as the same.
const SAME_MM: f64 = 1e-6;

/// Largest rotation (rad) between chain and model accepted as the same.
const SAME_RAD: f64 = 1e-9;

/// One joint of a chain, root to tip.
#[derive(Debug, Clone, PartialEq)]
pub struct ChainStep {
    /// The joint's name (for messages).
    pub name: String,
    /// Its origin, parent link → child link at zero (mm).
    pub origin: Isometry3<f64>,
    /// The unit axis a revolute joint turns about (child frame); `None`
    /// for a fixed joint.
    pub axis: Option<Vector3<f64>>,
}

/// Why a chain is not the model's robot.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ChainFitError {
    /// Another number of revolute joints.
    #[error("the chain has {chain} revolute joints, the calibrated robot {robot}")]
    JointCount {
        /// Revolute joints of the chain.
        chain: usize,
        /// Joints of the model.
        robot: usize,
    },
    /// The chain's forward kinematics is not the nominal model's.
    #[error(
        "the chain is not the result's nominal robot: its forward kinematics differs by {mm:.4} mm and {deg:.4}° at joints {at:?} (deg); was the session's robot imported from another file?"
    )]
    NotThisRobot {
        /// Translation difference, mm.
        mm: f64,
        /// Rotation difference, deg.
        deg: f64,
        /// Where.
        at: Vec<f64>,
    },
    /// A joint that does not turn about the model's axis.
    #[error(
        "joint {joint} does not turn about the model's joint {index} axis (off by {mm:.6} mm, {deg:.6}°)"
    )]
    JointAxis {
        /// The chain's joint.
        joint: String,
        /// The model's joint, 1-based.
        index: usize,
        /// Distance of its origin from the axis, mm.
        mm: f64,
        /// Angle of its axis to the model's, deg.
        deg: f64,
    },
}

/// The chain's root → tip at `q` (deg).
#[must_use]
pub fn chain_pose(steps: &[ChainStep], q_deg: &[f64]) -> Isometry3<f64> {
    link_poses(steps, q_deg)
        .last()
        .copied()
        .unwrap_or_else(Isometry3::identity)
}

/// Every link's pose (root frame) at `q` (deg), one per step.
fn link_poses(steps: &[ChainStep], q_deg: &[f64]) -> Vec<Isometry3<f64>> {
    let mut pose = Isometry3::identity();
    let mut q = q_deg.iter();
    steps
        .iter()
        .map(|s| {
            pose *= s.origin;
            if let Some(axis) = s.axis {
                let angle = q.next().copied().unwrap_or(0.0).to_radians();
                pose *= UnitQuaternion::from_scaled_axis(axis * angle);
            }
            pose
        })
        .collect()
}

/// The model's MDH frames `P_i(q)` after each joint (base frame).
fn mdh_frames(robot: &Robot, q_deg: &[f64]) -> Vec<Isometry3<f64>> {
    let mut t = robot.base;
    robot
        .joints
        .iter()
        .zip(q_deg)
        .map(|(j, q)| {
            t *= j.link(*q);
            t
        })
        .collect()
}

/// The constant `W` with `W · chain(q) = nominal(q)`, checked at a dozen
/// joint vectors.
///
/// # Errors
/// [`ChainFitError`] when the joint counts differ or the two are not one
/// robot.
pub fn chain_in_model(
    steps: &[ChainStep],
    nominal: &Robot,
) -> Result<Isometry3<f64>, ChainFitError> {
    let n = steps.iter().filter(|s| s.axis.is_some()).count();
    if n != nominal.dof() {
        return Err(ChainFitError::JointCount {
            chain: n,
            robot: nominal.dof(),
        });
    }
    let zero = vec![0.0; n];
    let w = nominal.base_from_flange(&zero) * chain_pose(steps, &zero).inverse();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(33);
    for _ in 0..CHECKS {
        let q: Vec<f64> = (0..n).map(|_| rng.random_range(-180.0..180.0)).collect();
        let a = w * chain_pose(steps, &q);
        let b = nominal.base_from_flange(&q);
        let mm = (a.translation.vector - b.translation.vector).norm();
        let rad = a.rotation.angle_to(&b.rotation);
        if mm > SAME_MM.max(1e-12 * b.translation.vector.norm()) || rad > SAME_RAD {
            return Err(ChainFitError::NotThisRobot {
                mm,
                deg: rad.to_degrees(),
                at: q,
            });
        }
    }
    Ok(w)
}

/// The chain's origins with the revolute joints' replaced so that
/// `W · chain'(q) = calibrated(q)` (module doc); fixed joints' origins
/// are returned unchanged.
///
/// # Errors
/// [`ChainFitError`] when the chain is not `nominal`'s robot.
pub fn calibrated_origins(
    steps: &[ChainStep],
    nominal: &Robot,
    calibrated: &Robot,
) -> Result<Vec<Isometry3<f64>>, ChainFitError> {
    let w = chain_in_model(steps, nominal)?;
    let n = nominal.dof();
    let zero = vec![0.0; n];
    let links = link_poses(steps, &zero);
    let nominal_frames = mdh_frames(nominal, &zero);
    let calibrated_frames = mdh_frames(calibrated, &zero);
    let w_inv = w.inverse();
    let mut out = Vec::with_capacity(steps.len());
    let mut parent = Isometry3::identity();
    let mut joint = 0;
    for (step, link) in steps.iter().zip(&links) {
        let Some(axis) = step.axis else {
            out.push(step.origin);
            parent *= step.origin;
            continue;
        };
        let (Some(p), Some(p_cal)) = (nominal_frames.get(joint), calibrated_frames.get(joint))
        else {
            break;
        };
        let e = p.inverse() * w * link;
        let off_axis = e.translation.vector.xy().norm();
        let tilt = (e.rotation * axis).angle(&Vector3::z());
        if off_axis > SAME_MM || tilt > SAME_RAD {
            return Err(ChainFitError::JointAxis {
                joint: step.name.clone(),
                index: joint + 1,
                mm: off_axis,
                deg: tilt.to_degrees(),
            });
        }
        let new_link = w_inv * p_cal * e;
        let origin = parent.inverse() * new_link;
        out.push(origin);
        parent = new_link;
        joint += 1;
    }
    Ok(out)
}
