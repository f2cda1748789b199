//! Multi-branch inverse kinematics of 6-axis arms, shared by the simulator
//! ([`simulate`](crate::engine::tools::simulate)) and the pose planner
//! ([`plan`](crate::engine::tools::plan)).
//!
//! [`Chain`] is a [`Robot`] prepared for many IK solves: the same MDH
//! product as [`Robot::base_from_flange`] with each joint's fixed part
//! precomputed, and the 6-column geometric Jacobian of the flange. A solve
//! is damped Gauss-Newton from a start ([`Chain::inverse_kinematics`]);
//! which of the arm's solutions (branches: shoulder front or back, elbow
//! up or down, wrist flipped or not) it finds depends on the start, so
//! [`Chain::search`] walks the starts of every branch:
//!
//! 1. **Arm guesses** `(q1, q2, q3)`, the caller's list (the simulator's
//!    per-preset elbow-up guesses) or [`Chain::arm_guess_grid`] (both
//!    shoulder headings × a 3 × 3 grid of `q2`, `q3` inside the limits).
//! 2. On a **spherical wrist** (wrist axes meet, the ABB arms) the guess is
//!    first moved onto the wrist-centre target by a 3-joint solve
//!    ([`Chain::arm_for_wrist`]), which lands in one of the (up to 4) arm
//!    solutions; guesses that land on an arm already tried are skipped.
//! 3. For each arm the **two wrist solutions** (`q5` of either sign) that
//!    give exactly the target rotation ([`Chain::wrist_starts`], a z-y-z
//!    Euler decomposition) are the starts of the full 6-joint solve.
//!
//! [`Chain::solutions`] collects every distinct solution within joint
//! limits and away from the wrist singularity: up to 8 on an ABB arm.
//!
//! Joint readings are in degrees, lengths in mm, as in the files; the
//! Jacobian is per radian.

use std::ops::ControlFlow;

use nalgebra::{Isometry3, Matrix3, Matrix6, Translation3, UnitQuaternion, Vector3, Vector6};

use super::kinematics::{JointLimit, Robot};
use crate::engine::base::geometry::{rot_x, rot_y, trans, wrap_deg};

/// Joints of the arms this module solves (every preset has 6).
pub const DOF: usize = 6;
/// IK iteration bound: from a family start a reachable target converges in
/// ~6-12 iterations (steps are capped at [`IK_MAX_STEP`]).
const IK_MAX_ITER: usize = 60;
/// After this many iterations a start still more than [`IK_FAR_MM`] or
/// [`IK_FAR_RAD`] off is abandoned: it is heading for a limit or a
/// singularity, and the next start is cheaper than waiting.
const IK_GIVE_UP_ITER: usize = 20;
/// See [`IK_GIVE_UP_ITER`], mm.
const IK_FAR_MM: f64 = 1.0;
/// See [`IK_GIVE_UP_ITER`], rad.
const IK_FAR_RAD: f64 = 0.02;
/// Largest joint step per iteration (rad), to stay in one basin.
const IK_MAX_STEP: f64 = 0.3;
/// Rotation error rows are weighted by this length (mm per rad, ~the
/// sensor stand-off) so position and orientation matter alike.
const IK_ROT_WEIGHT: f64 = 300.0;
/// Convergence: flange position error, mm (ground truth must hold to
/// 1e-6 mm; 1e-9 is ~10⁴ ulp of a 1 m coordinate).
pub const IK_POSITION_TOLERANCE: f64 = 1e-9;
/// Convergence: flange rotation error, rad (1e-11 rad moves the sphere,
/// ~300 mm out, by 3e-9 mm).
pub const IK_ROTATION_TOLERANCE: f64 = 1e-11;
/// Damping of the normal equations (mm²): negligible beside `JᵀJ`
/// (~10⁴-10⁶ mm²) away from singularities, bounded steps near them.
const IK_DAMPING: f64 = 1e-6;
/// Largest deviation (deg) of the wrist twists and betas from the Euler
/// wrist for which [`Chain::wrist_starts`] still gives a useful start.
const EULER_WRIST_TOLERANCE: f64 = 2.0;
/// Two arm solutions closer than this on every joint (deg) are the same.
pub const SAME_ARM_DEG: f64 = 1.0;
/// Two full solutions closer than this on every joint (deg, after
/// wrapping) are the same branch: converged solves agree to ~1e-9°.
const SAME_SOLUTION_DEG: f64 = 1e-3;
/// Largest wrist offset (mm) for which the wrist counts as spherical: the
/// true models' offsets are below 1 mm, the UR5e's are ~100 mm.
const SPHERICAL_WRIST_TOLERANCE: f64 = 5.0;
/// The wrist centre is placed to this (mm) before the full solve: the
/// start only needs to be in the basin, the full solve polishes.
const WRIST_CENTRE_TOLERANCE: f64 = 0.01;
/// Levels of the `q2`, `q3` grid of [`Chain::arm_guess_grid`], as
/// fractions of each joint's usable range: three levels spread over the
/// range reach the elbow-up and elbow-down basins of every preset.
const GRID_LEVELS: [f64; 3] = [1.0 / 6.0, 0.5, 5.0 / 6.0];

/// A 6-axis [`Robot`] prepared for repeated inverse kinematics: the same
/// MDH product as [`Robot::base_from_flange`], with each joint's fixed part
/// `Rx(alpha)·Tx(a)·Ry(beta)` precomputed, and the geometric Jacobian of
/// the flange (6 columns, not the 30 of the parameter Jacobian).
#[derive(Debug, Clone, PartialEq)]
pub struct Chain {
    base: Isometry3<f64>,
    fixed: [Isometry3<f64>; DOF],
    /// Per joint: zero offset theta (deg) and offset d (mm).
    theta_d: [(f64, f64); DOF],
    flange: Isometry3<f64>,
    /// Whether the wrist is `alpha5 = 90°, alpha6 = −90°` with small betas
    /// (every preset), so [`Self::wrist_starts`] can solve it.
    euler_wrist: bool,
    /// Whether, moreover, the wrist axes nearly meet (`a5`, `d5`, `a6`
    /// small: the ABB arms, not the UR5e), so the wrist centre depends on
    /// joints 1-3 only and [`Self::arm_for_wrist`] can place it.
    spherical_wrist: bool,
}

/// A joint axis in the base frame: direction and a point on it (mm).
type Axis = (Vector3<f64>, Vector3<f64>);

/// `Rz(angle_deg) · Tz(d)`, the moving part of an MDH link.
fn joint_motion(angle_deg: f64, d: f64) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(0.0, 0.0, d),
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), angle_deg.to_radians()),
    )
}

/// Whether every reading of `q` (deg) lies within its limit (inclusive).
#[must_use]
pub fn within_limits(q: &[f64], limits: &[JointLimit]) -> bool {
    q.iter()
        .zip(limits)
        .all(|(v, l)| *v >= l.min && *v <= l.max)
}

impl Chain {
    /// The chain of `robot`; `None` unless it has [`DOF`] joints.
    #[must_use]
    pub fn new(robot: &Robot) -> Option<Self> {
        if robot.dof() != DOF {
            return None;
        }
        let mut fixed = [Isometry3::identity(); DOF];
        let mut theta_d = [(0.0, 0.0); DOF];
        for (i, j) in robot.joints.iter().enumerate() {
            fixed[i] =
                rot_x(j.alpha.to_radians()) * trans(j.a, 0.0, 0.0) * rot_y(j.beta.to_radians());
            theta_d[i] = (j.theta, j.d);
        }
        let j = &robot.joints;
        let euler_wrist = (j[4].alpha - 90.0).abs() < EULER_WRIST_TOLERANCE
            && (j[5].alpha + 90.0).abs() < EULER_WRIST_TOLERANCE
            && j[4].beta.abs() < EULER_WRIST_TOLERANCE
            && j[5].beta.abs() < EULER_WRIST_TOLERANCE;
        let spherical_wrist = euler_wrist
            && j[4].a.abs() < SPHERICAL_WRIST_TOLERANCE
            && j[4].d.abs() < SPHERICAL_WRIST_TOLERANCE
            && j[5].a.abs() < SPHERICAL_WRIST_TOLERANCE;
        Some(Self {
            base: robot.base,
            fixed,
            theta_d,
            flange: robot.flange,
            euler_wrist,
            spherical_wrist,
        })
    }

    /// Whether the wrist axes meet (within 5 mm): the wrist centre then
    /// depends on joints 1-3 only ([`Self::arm_for_wrist`] applies).
    #[must_use]
    pub fn has_spherical_wrist(&self) -> bool {
        self.spherical_wrist
    }

    /// The zero offset `theta` (deg) of joint `i` (0-based) of the chain.
    #[must_use]
    pub fn theta(&self, i: usize) -> f64 {
        self.theta_d[i].0
    }

    /// Flange pose `base_from_flange` and geometric Jacobian for readings
    /// `q` (deg): column `i` is `[z_i × (p − o_i); z_i]` (mm/rad of the
    /// flange origin `p`, rad/rad), base frame.
    #[must_use]
    pub fn pose_and_jacobian(&self, q: &[f64; DOF]) -> (Isometry3<f64>, Matrix6<f64>) {
        let mut t = self.base;
        let mut axes = [(Vector3::zeros(), Vector3::zeros()); DOF];
        for i in 0..DOF {
            t *= self.fixed[i];
            axes[i] = (t.rotation * Vector3::z(), t.translation.vector);
            let (theta, d) = self.theta_d[i];
            t *= joint_motion(q[i] + theta, d);
        }
        let pose = t * self.flange;
        let p = pose.translation.vector;
        let mut jac = Matrix6::zeros();
        for (i, (z, o)) in axes.iter().enumerate() {
            let v = z.cross(&(p - o));
            jac.fixed_view_mut::<3, 1>(0, i).copy_from(&v);
            jac.fixed_view_mut::<3, 1>(3, i).copy_from(z);
        }
        (pose, jac)
    }

    /// The wrist centre target for a flange target `base_from_flange`: the
    /// origin of the frame before the last joint's `Tz(d6)`, with the
    /// flange transform removed (on a spherical wrist it depends on joints
    /// 1-3 only). Base frame, mm.
    #[must_use]
    pub fn wrist_centre_target(&self, target: &Isometry3<f64>) -> Vector3<f64> {
        let d6 = self.theta_d[DOF - 1].1;
        (target * self.flange.inverse() * trans(0.0, 0.0, -d6))
            .translation
            .vector
    }

    /// The wrist centre (base frame, mm) for arm joints `arm` (deg).
    fn wrist_centre(&self, arm: &[f64; 3]) -> (Vector3<f64>, [Axis; 3]) {
        let mut t = self.base;
        let mut axes = [(Vector3::zeros(), Vector3::zeros()); 3];
        for i in 0..3 {
            t *= self.fixed[i];
            axes[i] = (t.rotation * Vector3::z(), t.translation.vector);
            let (theta, d) = self.theta_d[i];
            t *= joint_motion(arm[i] + theta, d);
        }
        let d4 = self.theta_d[3].1;
        (
            (t * self.fixed[3] * trans(0.0, 0.0, d4)).translation.vector,
            axes,
        )
    }

    /// Joints 1-3 (deg) that put the spherical wrist's centre at `centre`
    /// (base frame, mm), by damped Gauss-Newton from `arm`; `None` when out
    /// of reach.
    #[must_use]
    pub fn arm_for_wrist(&self, arm: [f64; 3], centre: &Vector3<f64>) -> Option<[f64; 3]> {
        let mut q = arm;
        for _ in 0..IK_MAX_ITER {
            let (w, axes) = self.wrist_centre(&q);
            let err = centre - w;
            if err.norm() < WRIST_CENTRE_TOLERANCE {
                return Some(q);
            }
            let jac = Matrix3::from_columns(&axes.map(|(z, o)| z.cross(&(w - o))));
            let normal = jac.transpose() * jac + Matrix3::identity() * IK_DAMPING;
            let step = normal.cholesky()?.solve(&(jac.transpose() * err));
            let largest = step.amax();
            let scale = if largest > IK_MAX_STEP {
                IK_MAX_STEP / largest
            } else {
                1.0
            };
            for (qi, s) in q.iter_mut().zip(step.iter()) {
                *qi += (s * scale).to_degrees();
            }
        }
        None
    }

    /// IK starts for an arm guess `(q1, q2, q3)` (deg): the two wrist
    /// solutions (`q5` of either sign) that give exactly the target
    /// rotation for that arm. The wrist of every preset is
    /// `Rz(q4') · Rx(90°) · Rz(q5') · Rx(−90°) · Rz(q6') = Rz(q4') · Ry(−q5') · Rz(q6')`
    /// (primes: plus `theta`), a z-y-z Euler decomposition; a robot without
    /// that wrist gets the arm guess with a zero wrist.
    #[must_use]
    pub fn wrist_starts(&self, arm: [f64; 3], target: &Isometry3<f64>) -> [[f64; DOF]; 2] {
        let (t4, t5, t6) = (self.theta_d[3].0, self.theta_d[4].0, self.theta_d[5].0);
        if !self.euler_wrist {
            return [[arm[0], arm[1], arm[2], 0.0, 0.0, 0.0]; 2];
        }
        let mut t = self.base;
        for (i, q) in arm.iter().enumerate() {
            let (theta, d) = self.theta_d[i];
            t *= self.fixed[i] * joint_motion(*q + theta, d);
        }
        t *= self.fixed[3];
        let m = (t.rotation.inverse() * target.rotation * self.flange.rotation.inverse())
            .to_rotation_matrix();
        let b = m[(0, 2)].hypot(m[(1, 2)]).atan2(m[(2, 2)]).to_degrees();
        let a = m[(1, 2)].atan2(m[(0, 2)]).to_degrees();
        let c = m[(2, 1)].atan2(-m[(2, 0)]).to_degrees();
        [
            [arm[0], arm[1], arm[2], a - t4, -b - t5, c - t6],
            [
                arm[0],
                arm[1],
                arm[2],
                a + 180.0 - t4,
                b - t5,
                c + 180.0 - t6,
            ],
        ]
    }

    /// Damped Gauss-Newton from `start` (deg) to the flange pose `target`
    /// (`base_from_flange`, mm), converged to [`IK_POSITION_TOLERANCE`] and
    /// [`IK_ROTATION_TOLERANCE`]; `None` when it does not converge. Limits
    /// are the caller's check; the readings are not wrapped.
    #[must_use]
    pub fn inverse_kinematics(
        &self,
        target: &Isometry3<f64>,
        start: &[f64; DOF],
    ) -> Option<[f64; DOF]> {
        let mut q = *start;
        for iter in 0..IK_MAX_ITER {
            let (pose, jac) = self.pose_and_jacobian(&q);
            let dp = target.translation.vector - pose.translation.vector;
            let dr = (target.rotation * pose.rotation.inverse()).scaled_axis();
            if dp.norm() < IK_POSITION_TOLERANCE && dr.norm() < IK_ROTATION_TOLERANCE {
                return Some(q);
            }
            if iter >= IK_GIVE_UP_ITER && (dp.norm() > IK_FAR_MM || dr.norm() > IK_FAR_RAD) {
                return None;
            }
            let mut a = jac;
            for r in 3..6 {
                a.row_mut(r).scale_mut(IK_ROT_WEIGHT);
            }
            let e = Vector6::new(
                dp.x,
                dp.y,
                dp.z,
                dr.x * IK_ROT_WEIGHT,
                dr.y * IK_ROT_WEIGHT,
                dr.z * IK_ROT_WEIGHT,
            );
            let normal = a.transpose() * a + Matrix6::identity() * IK_DAMPING;
            let step = normal.cholesky()?.solve(&(a.transpose() * e));
            let largest = step.amax();
            let scale = if largest > IK_MAX_STEP {
                IK_MAX_STEP / largest
            } else {
                1.0
            };
            for (qi, s) in q.iter_mut().zip(step.iter()) {
                *qi += (s * scale).to_degrees();
            }
        }
        None
    }

    /// Walks the IK starts of every branch for the flange pose `target`, in
    /// the order of the module docs, and hands each to `visit` until it
    /// breaks: for each arm guess (placed on the wrist-centre target first
    /// when the wrist is spherical, skipped when it lands on an arm already
    /// tried), the two [`Self::wrist_starts`], the one with the lower
    /// `wrist_dislike` first. Returns what `visit` broke with, or `None`
    /// when every start was visited. Starts are built lazily, so a caller
    /// that breaks on its first success pays for one branch.
    pub fn search<T>(
        &self,
        target: &Isometry3<f64>,
        guesses: &[[f64; 3]],
        wrist_dislike: &dyn Fn(&[f64; DOF]) -> f64,
        mut visit: impl FnMut(&[f64; DOF]) -> ControlFlow<T>,
    ) -> Option<T> {
        let centre = self.wrist_centre_target(target);
        let mut arms_tried: Vec<[f64; 3]> = Vec::new();
        for guess in guesses {
            let arm = if self.spherical_wrist {
                match self.arm_for_wrist(*guess, &centre) {
                    Some(arm) => arm,
                    None => continue,
                }
            } else {
                *guess
            };
            // Different guesses often reach the same arm solution.
            let seen_before = arms_tried.iter().any(|t| {
                t.iter()
                    .zip(&arm)
                    .all(|(a, b)| wrap_deg(a - b).abs() < SAME_ARM_DEG)
            });
            if seen_before {
                continue;
            }
            arms_tried.push(arm);
            let mut wrists = self.wrist_starts(arm, target);
            if wrist_dislike(&wrists[1]) < wrist_dislike(&wrists[0]) {
                wrists.swap(0, 1);
            }
            for start in &wrists {
                if let ControlFlow::Break(found) = visit(start) {
                    return Some(found);
                }
            }
        }
        None
    }

    /// One IK solve from `start` (see [`Self::inverse_kinematics`]), with
    /// the readings moved by whole turns into (−180, 180] and accepted only
    /// within `limits` and with `|sin(q5 + theta5)| ≥ sin(min_wrist_deg)`
    /// (away from the wrist singularity, where `q4` and `q6` are one
    /// direction).
    #[must_use]
    pub fn solve_from(
        &self,
        target: &Isometry3<f64>,
        start: &[f64; DOF],
        limits: &[JointLimit],
        min_wrist_deg: f64,
    ) -> Option<[f64; DOF]> {
        let q = self.inverse_kinematics(target, start)?.map(wrap_deg);
        let wrist = (q[4] + self.theta(4)).to_radians().sin().abs();
        (within_limits(&q, limits) && wrist >= min_wrist_deg.to_radians().sin()).then_some(q)
    }

    /// Every distinct solution (branch) for the flange pose `target` found
    /// from the starts of `guesses` ([`Self::search`]), each accepted by
    /// [`Self::solve_from`]; in search order, duplicates removed.
    #[must_use]
    pub fn solutions(
        &self,
        target: &Isometry3<f64>,
        guesses: &[[f64; 3]],
        limits: &[JointLimit],
        min_wrist_deg: f64,
    ) -> Vec<[f64; DOF]> {
        let mut found: Vec<[f64; DOF]> = Vec::new();
        let no_preference = |_: &[f64; DOF]| 0.0;
        let _: Option<()> = self.search(target, guesses, &no_preference, |start| {
            if let Some(q) = self.solve_from(target, start, limits, min_wrist_deg) {
                let duplicate = found.iter().any(|f| {
                    f.iter()
                        .zip(&q)
                        .all(|(a, b)| wrap_deg(a - b).abs() < SAME_SOLUTION_DEG)
                });
                if !duplicate {
                    found.push(q);
                }
            }
            ControlFlow::Continue(())
        });
        found
    }

    /// Arm guesses `(q1, q2, q3)` (deg) that reach every branch of a flange
    /// target on any 6-axis arm: joint 1 turned toward the target's wrist
    /// centre and turned away from it (shoulder front and back), each with
    /// a 3 × 3 grid of `q2`, `q3` spread over their limits (clamped to
    /// ±180°). The heading of the arm at `q1 = 0` is measured on the chain
    /// (the ABB arms point along +x, the UR5e along −x).
    #[must_use]
    pub fn arm_guess_grid(&self, target: &Isometry3<f64>, limits: &[JointLimit]) -> Vec<[f64; 3]> {
        let (w0, _) = self.wrist_centre(&[0.0; 3]);
        let origin = self.base.translation.vector;
        let heading0 = (w0.y - origin.y).atan2(w0.x - origin.x).to_degrees();
        let w = self.wrist_centre_target(target);
        let heading = (w.y - origin.y).atan2(w.x - origin.x).to_degrees();
        let level = |k: usize, f: f64| -> f64 {
            let (lo, hi) = limits
                .get(k)
                .map_or((-180.0, 180.0), |l| (l.min.max(-180.0), l.max.min(180.0)));
            lo + f * (hi - lo)
        };
        let mut out = Vec::with_capacity(2 * GRID_LEVELS.len() * GRID_LEVELS.len());
        for turn in [0.0, 180.0] {
            let q1 = wrap_deg(heading - heading0 + turn);
            for f2 in GRID_LEVELS {
                for f3 in GRID_LEVELS {
                    out.push([q1, level(1, f2), level(2, f3)]);
                }
            }
        }
        out
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;
    use crate::engine::base::robot::presets as kinematics;

    fn perturbed_irb2400() -> Robot {
        let mut robot = kinematics::irb2400().robot;
        for (j, e) in robot
            .joints
            .iter_mut()
            .zip(crate::engine::base::robot::table1_errors())
        {
            j.alpha += e.alpha;
            j.a += e.a;
            j.beta += e.beta;
            j.theta += e.theta;
            j.d += e.d;
        }
        robot
    }

    #[test]
    fn wrap_and_limits() {
        assert_eq!(wrap_deg(190.0), -170.0);
        assert_eq!(wrap_deg(-180.0), 180.0);
        assert_eq!(wrap_deg(540.0), 180.0);
        assert!((wrap_deg(-725.0) - -5.0).abs() < 1e-12);
        let limits = kinematics::irb2400().limits;
        assert!(within_limits(&[0.0; 6], &limits));
        assert!(!within_limits(&[0.0, 0.0, 70.0, 0.0, 0.0, 0.0], &limits));
    }

    #[test]
    fn chain_matches_reference_kinematics() {
        let robot = perturbed_irb2400();
        let chain = Chain::new(&robot).unwrap();
        assert!(chain.has_spherical_wrist());
        let q = [12.5, 20.1, -3.4, 40.0, 35.2, -10.0];
        let (pose, jac) = chain.pose_and_jacobian(&q);
        let reference = robot.base_from_flange(&q);
        assert!((pose.translation.vector - reference.translation.vector).norm() < 1e-9);
        assert!(pose.rotation.angle_to(&reference.rotation) < 1e-12);
        // Jacobian columns against central differences (per rad).
        let h = 1e-6_f64;
        for i in 0..DOF {
            let mut qp = q;
            qp[i] += h.to_degrees();
            let mut qm = q;
            qm[i] -= h.to_degrees();
            let (pp, _) = chain.pose_and_jacobian(&qp);
            let (pm, _) = chain.pose_and_jacobian(&qm);
            let v = (pp.translation.vector - pm.translation.vector) / (2.0 * h);
            let col = jac.column(i);
            assert!(
                (v - Vector3::new(col[0], col[1], col[2])).norm() < 1e-4,
                "joint {i}"
            );
        }
        // IK from a wrist start returns the pose.
        let target = reference;
        let arm = chain
            .arm_for_wrist([10.0, 15.0, 0.0], &chain.wrist_centre_target(&target))
            .unwrap();
        let solved = chain
            .wrist_starts(arm, &target)
            .iter()
            .find_map(|s| chain.inverse_kinematics(&target, s))
            .unwrap();
        let back = robot.base_from_flange(&solved);
        assert!((back.translation.vector - target.translation.vector).norm() < 1e-8);
    }

    #[test]
    fn every_branch_reaches_the_target() {
        for preset in kinematics::presets() {
            let robot = preset.robot.clone();
            let chain = Chain::new(&robot).unwrap();
            let q = [20.0, -60.0, 70.0, 30.0, -40.0, 15.0];
            let q = if preset.key == "ur5e" {
                q
            } else {
                [20.0, 30.0, 10.0, 30.0, 50.0, 15.0]
            };
            let target = robot.base_from_flange(&q);
            let guesses = chain.arm_guess_grid(&target, &preset.limits);
            let all = chain.solutions(&target, &guesses, &preset.limits, 1.0);
            assert!(all.len() >= 2, "{}: {} branches", preset.key, all.len());
            // The pose it was made from is among them.
            assert!(
                all.iter()
                    .any(|s| s.iter().zip(&q).all(|(a, b)| wrap_deg(a - b).abs() < 1e-6)),
                "{}: {all:?}",
                preset.key
            );
            for s in &all {
                assert!(within_limits(s, &preset.limits));
                let back = robot.base_from_flange(s);
                assert!(
                    (back.translation.vector - target.translation.vector).norm() < 1e-8,
                    "{}",
                    preset.key
                );
                assert!(back.rotation.angle_to(&target.rotation) < 1e-10);
            }
            // Distinct branches differ by more than rounding.
            for (i, a) in all.iter().enumerate() {
                for b in &all[i + 1..] {
                    assert!(a.iter().zip(b).any(|(x, y)| wrap_deg(x - y).abs() > 1e-3));
                }
            }
        }
    }

    #[test]
    fn search_stops_at_the_first_break() {
        let preset = kinematics::irb2400();
        let chain = Chain::new(&preset.robot).unwrap();
        let target = preset
            .robot
            .base_from_flange(&[0.0, 20.0, 10.0, 0.0, 40.0, 0.0]);
        let guesses = chain.arm_guess_grid(&target, &preset.limits);
        let mut visits = 0;
        let first = chain.search(&target, &guesses, &|_| 0.0, |s| {
            visits += 1;
            match chain.solve_from(&target, s, &preset.limits, 5.0) {
                Some(q) => ControlFlow::Break(q),
                None => ControlFlow::Continue(()),
            }
        });
        assert!(first.is_some());
        assert!(visits <= 2 * guesses.len());
    }
}
