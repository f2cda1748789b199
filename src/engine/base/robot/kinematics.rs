//! The kinematic model of FORMAT.md: modified DH with Hayati's `beta`,
//! forward kinematics (paper eq. 1-2), the Jacobian of the flange pose with
//! respect to all `5·n` parameters (the `J_i` of paper eq. 16) and a
//! numerical inverse kinematics from one start (the multi-branch solver of
//! the simulator and the planner is [`ik`](super::ik)).
//!
//! Link transform of joint `i` (FORMAT.md "Kinematic model"):
//!
//! ```text
//! T_i = Rx(alpha_i) · Tx(a_i) · Ry(beta_i) · Rz(q_i + theta_i) · Tz(d_i)
//! base_from_flange(q) = B · T_1 · … · T_n · F
//! ```
//!
//! [`Joint`] holds the parameters in file units (deg, mm). Inside the
//! engine a *parameter vector* is a flat `[f64]` of length `5·n`, joint by
//! joint, in the order [`PARAM_NAMES`] = alpha, a, beta, theta, d, with
//! angles in **radians** and lengths in mm.

use nalgebra::{DMatrix, DVector, Isometry3, Matrix6xX, Vector3, Vector6};
use serde::{Deserialize, Serialize};

use crate::engine::base::geometry::{rot_x, rot_y, rot_z, trans};

/// Number of kinematic parameters per joint.
pub const PARAMS_PER_JOINT: usize = 5;

/// Parameter names, in parameter-vector order within a joint.
pub const PARAM_NAMES: [&str; PARAMS_PER_JOINT] = ["alpha", "a", "beta", "theta", "d"];

/// Whether each parameter of a joint is an angle (true) or a length.
pub const PARAM_IS_ANGLE: [bool; PARAMS_PER_JOINT] = [true, false, true, true, false];

/// The five MDH parameters of one joint in file units: `alpha`, `beta`,
/// `theta` in degrees, `a`, `d` in millimetres.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Joint {
    /// Twist about the previous x axis (Craig's `alpha_{i-1}`), deg.
    pub alpha: f64,
    /// Length along the previous x axis (Craig's `a_{i-1}`), mm.
    pub a: f64,
    /// Hayati's angle about the y axis for nearly parallel axes, deg.
    pub beta: f64,
    /// Joint zero offset, added to the reading `q_i`, deg.
    pub theta: f64,
    /// Offset along the joint's z axis, mm.
    pub d: f64,
}

impl Joint {
    /// The parameters in internal units (rad, mm), in [`PARAM_NAMES`] order.
    #[must_use]
    pub fn to_internal(&self) -> [f64; PARAMS_PER_JOINT] {
        [
            self.alpha.to_radians(),
            self.a,
            self.beta.to_radians(),
            self.theta.to_radians(),
            self.d,
        ]
    }

    /// A joint from internal units (rad, mm), [`PARAM_NAMES`] order.
    #[must_use]
    pub fn from_internal(p: &[f64]) -> Self {
        Self {
            alpha: p[0].to_degrees(),
            a: p[1],
            beta: p[2].to_degrees(),
            theta: p[3].to_degrees(),
            d: p[4],
        }
    }

    /// The parameter `k` ([`PARAM_NAMES`] order) in file units.
    #[must_use]
    pub fn get(&self, k: usize) -> f64 {
        match k {
            0 => self.alpha,
            1 => self.a,
            2 => self.beta,
            3 => self.theta,
            _ => self.d,
        }
    }

    /// The link transform `T_i` for joint reading `q` (deg).
    #[must_use]
    pub fn link(&self, q_deg: f64) -> Isometry3<f64> {
        rot_x(self.alpha.to_radians())
            * trans(self.a, 0.0, 0.0)
            * rot_y(self.beta.to_radians())
            * rot_z((q_deg + self.theta).to_radians())
            * trans(0.0, 0.0, self.d)
    }

    /// Joint-by-joint difference `self − other`, file units.
    #[must_use]
    pub fn minus(&self, other: &Self) -> Self {
        Self {
            alpha: self.alpha - other.alpha,
            a: self.a - other.a,
            beta: self.beta - other.beta,
            theta: self.theta - other.theta,
            d: self.d - other.d,
        }
    }
}

/// Joint limits in degrees, used by inverse kinematics and the planner.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointLimit {
    /// Lower limit, deg.
    pub min: f64,
    /// Upper limit, deg.
    pub max: f64,
}

/// A serial robot: MDH joints plus fixed base and flange transforms.
#[derive(Debug, Clone, PartialEq)]
pub struct Robot {
    /// Display name, e.g. "ABB IRB 2400/16".
    pub name: String,
    /// The joints, base to flange.
    pub joints: Vec<Joint>,
    /// `B`: fixed transform in front of joint 1 (identity when absent).
    pub base: Isometry3<f64>,
    /// `F`: fixed transform after the last joint (identity when absent).
    pub flange: Isometry3<f64>,
}

impl Robot {
    /// A robot with identity base and flange.
    #[must_use]
    pub fn new(name: impl Into<String>, joints: Vec<Joint>) -> Self {
        Self {
            name: name.into(),
            joints,
            base: Isometry3::identity(),
            flange: Isometry3::identity(),
        }
    }

    /// Number of joints `n`.
    #[must_use]
    pub fn dof(&self) -> usize {
        self.joints.len()
    }

    /// Number of kinematic parameters, `5·n`.
    #[must_use]
    pub fn n_params(&self) -> usize {
        PARAMS_PER_JOINT * self.joints.len()
    }

    /// The parameter vector (rad, mm), joint by joint.
    #[must_use]
    pub fn params(&self) -> Vec<f64> {
        self.joints.iter().flat_map(Joint::to_internal).collect()
    }

    /// A copy with the joint parameters replaced by `params` (rad, mm).
    #[must_use]
    pub fn with_params(&self, params: &[f64]) -> Self {
        let mut out = self.clone();
        for (j, chunk) in out.joints.iter_mut().zip(params.chunks(PARAMS_PER_JOINT)) {
            *j = Joint::from_internal(chunk);
        }
        out
    }

    /// A copy with `delta` (rad, mm) added to the parameter vector.
    #[must_use]
    pub fn perturbed(&self, delta: &[f64]) -> Self {
        let p: Vec<f64> = self
            .params()
            .iter()
            .zip(delta)
            .map(|(p, d)| p + d)
            .collect();
        self.with_params(&p)
    }

    /// Per-joint differences `self − nominal` in file units (paper Table 1).
    #[must_use]
    pub fn joint_errors(&self, nominal: &Self) -> Vec<Joint> {
        self.joints
            .iter()
            .zip(&nominal.joints)
            .map(|(a, b)| a.minus(b))
            .collect()
    }

    /// Label of parameter `k` of the parameter vector, e.g. `"theta3"`.
    #[must_use]
    pub fn param_label(k: usize) -> String {
        format!(
            "{}{}",
            PARAM_NAMES[k % PARAMS_PER_JOINT],
            k / PARAMS_PER_JOINT + 1
        )
    }

    /// Forward kinematics: the flange pose in the base frame, `bT_e(q)`,
    /// for joint readings `q` (deg). `q` must have one entry per joint.
    #[must_use]
    pub fn base_from_flange(&self, q_deg: &[f64]) -> Isometry3<f64> {
        let mut t = self.base;
        for (joint, q) in self.joints.iter().zip(q_deg) {
            t *= joint.link(*q);
        }
        t * self.flange
    }

    /// Forward kinematics and the Jacobian of the flange pose with respect
    /// to the parameter vector (paper eq. 16, `ΔX_i = J_i · ΔP`).
    ///
    /// Column `k` is the twist `[Δ; δ]` (mm and rad, base frame, about the
    /// base origin) produced by a unit change of parameter `k` (per rad for
    /// angles, per mm for lengths): a point `X` fixed to the flange moves by
    /// `Δ + δ × X`.
    #[must_use]
    pub fn flange_jacobian(&self, q_deg: &[f64]) -> (Isometry3<f64>, Matrix6xX<f64>) {
        let mut jac = Matrix6xX::zeros(self.n_params());
        let mut t = self.base;
        for (i, (joint, q)) in self.joints.iter().zip(q_deg).enumerate() {
            let col = i * PARAMS_PER_JOINT;
            // alpha: rotation about x of the previous frame.
            jac.set_column(col, &rotation_twist(&t, &Vector3::x()));
            t *= rot_x(joint.alpha.to_radians());
            // a: translation along that x.
            jac.set_column(col + 1, &translation_twist(&t, &Vector3::x()));
            t *= trans(joint.a, 0.0, 0.0);
            // beta: rotation about the y axis.
            jac.set_column(col + 2, &rotation_twist(&t, &Vector3::y()));
            t *= rot_y(joint.beta.to_radians());
            // theta: rotation about the joint axis z.
            jac.set_column(col + 3, &rotation_twist(&t, &Vector3::z()));
            t *= rot_z((q + joint.theta).to_radians());
            // d: translation along the rotated z.
            jac.set_column(col + 4, &translation_twist(&t, &Vector3::z()));
            t *= trans(0.0, 0.0, joint.d);
        }
        (t * self.flange, jac)
    }

    /// The geometric Jacobian of the flange pose with respect to the joint
    /// readings: `6 × n`, twist per **radian** of each joint (the `theta`
    /// columns of [`Self::flange_jacobian`]).
    #[must_use]
    pub fn joint_jacobian(&self, q_deg: &[f64]) -> (Isometry3<f64>, Matrix6xX<f64>) {
        let (pose, full) = self.flange_jacobian(q_deg);
        let mut jac = Matrix6xX::zeros(self.dof());
        for i in 0..self.dof() {
            jac.set_column(i, &full.column(i * PARAMS_PER_JOINT + 3));
        }
        (pose, jac)
    }

    /// Numerical inverse kinematics: joint readings (deg) that put the flange
    /// at `target`, by damped Gauss-Newton from `q_start` (deg). Returns
    /// `None` when it does not converge to 1e-9 mm / 1e-11 rad or leaves
    /// `limits` (when given). Which of the arm's several solutions is found
    /// depends on `q_start`.
    #[must_use]
    pub fn inverse_kinematics(
        &self,
        target: &Isometry3<f64>,
        q_start: &[f64],
        limits: Option<&[JointLimit]>,
    ) -> Option<Vec<f64>> {
        /// Iteration bound; convergence from a start within ~30° takes ~6-10.
        const MAX_ITER: usize = 100;
        /// Largest joint step (rad) per iteration, to stay in one basin.
        const MAX_STEP: f64 = 0.3;
        let n = self.dof();
        let mut q: Vec<f64> = q_start.to_vec();
        for _ in 0..MAX_ITER {
            let (pose, jac) = self.joint_jacobian(&q);
            let err = pose_error(&pose, target);
            if err.fixed_rows::<3>(0).norm() < 1e-9 && err.fixed_rows::<3>(3).norm() < 1e-11 {
                let outside = limits
                    .is_some_and(|lim| q.iter().zip(lim).any(|(v, l)| *v < l.min || *v > l.max));
                return if outside { None } else { Some(q) };
            }
            // Weight rotation rows by a length so both parts matter.
            const ROT_WEIGHT: f64 = 1000.0;
            let mut a = DMatrix::from_iterator(6, n, jac.iter().copied());
            let mut b = DVector::from_iterator(6, err.iter().copied());
            for r in 3..6 {
                a.row_mut(r).scale_mut(ROT_WEIGHT);
                b[r] *= ROT_WEIGHT;
            }
            let ata = a.transpose() * &a + DMatrix::identity(n, n) * 1e-9;
            let atb = a.transpose() * b;
            let step = ata.cholesky()?.solve(&atb);
            let max = step.amax();
            let scale = if max > MAX_STEP { MAX_STEP / max } else { 1.0 };
            for (qi, s) in q.iter_mut().zip(step.iter()) {
                *qi += (s * scale).to_degrees();
            }
        }
        None
    }
}

/// The twist `[Δ; δ]` taking `pose` to `target` to first order (base
/// frame): `δ` is the rotation vector of `target·pose⁻¹`, `Δ` the
/// translation difference corrected for the rotation about the base origin.
#[must_use]
pub fn pose_error(pose: &Isometry3<f64>, target: &Isometry3<f64>) -> Vector6<f64> {
    let rot = (target.rotation * pose.rotation.inverse()).scaled_axis();
    let dp = target.translation.vector - pose.translation.vector;
    // A point at p moves by Δ + δ × p, so Δ = dp − δ × p.
    let delta = dp - rot.cross(&pose.translation.vector);
    Vector6::new(delta.x, delta.y, delta.z, rot.x, rot.y, rot.z)
}

/// Twist of a unit rotation about `axis_local` (frame `frame`) through the
/// frame's origin: `δ = u`, `Δ = o × u`.
fn rotation_twist(frame: &Isometry3<f64>, axis_local: &Vector3<f64>) -> Vector6<f64> {
    let u = frame.rotation * axis_local;
    let o = frame.translation.vector;
    let delta = o.cross(&u);
    Vector6::new(delta.x, delta.y, delta.z, u.x, u.y, u.z)
}

/// Twist of a unit translation along `axis_local` of `frame`.
fn translation_twist(frame: &Isometry3<f64>, axis_local: &Vector3<f64>) -> Vector6<f64> {
    let u = frame.rotation * axis_local;
    Vector6::new(u.x, u.y, u.z, 0.0, 0.0, 0.0)
}

#[cfg(test)]
mod tests {
    use super::super::presets::{irb2400, ur5e};
    use super::*;

    fn finite_difference_check(robot: &Robot, q: &[f64]) {
        let (pose, jac) = robot.flange_jacobian(q);
        let p0 = robot.params();
        let point = Vector3::new(12.0, -30.0, 250.0); // a point on the tool
        let x0 = pose * nalgebra::Point3::from(point);
        let h = 1e-6;
        for k in 0..robot.n_params() {
            let mut p = p0.clone();
            p[k] += h;
            let xp = robot.with_params(&p).base_from_flange(q) * nalgebra::Point3::from(point);
            p[k] -= 2.0 * h;
            let xm = robot.with_params(&p).base_from_flange(q) * nalgebra::Point3::from(point);
            let numeric = (xp - xm) / (2.0 * h);
            let col = jac.column(k);
            let delta = Vector3::new(col[0], col[1], col[2]);
            let rot = Vector3::new(col[3], col[4], col[5]);
            let analytic = delta + rot.cross(&x0.coords);
            assert!(
                (numeric - analytic).norm() < 1e-5 * (1.0 + analytic.norm()),
                "param {}: numeric {numeric} analytic {analytic}",
                Robot::param_label(k)
            );
        }
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let mut robot = irb2400().robot;
        // Non-zero beta and offsets so every column is exercised.
        robot.joints[2].beta = 0.7;
        robot.joints[4].a = -0.7;
        robot.base = crate::engine::base::geometry::isometry_from_twist(&[
            5.0, -3.0, 2.0, 0.01, 0.02, -0.03,
        ]);
        robot.flange =
            crate::engine::base::geometry::isometry_from_twist(&[1.0, 2.0, 3.0, 0.1, 0.0, 0.2]);
        for q in [
            [0.0; 6],
            [12.5, 20.1, -3.4, 40.0, 35.2, -10.0],
            [-30.0, 45.0, 20.0, -120.0, -60.0, 170.0],
        ] {
            finite_difference_check(&robot, &q);
        }
        finite_difference_check(&ur5e().robot, &[10.0, -80.0, 70.0, -30.0, 45.0, 5.0]);
    }

    #[test]
    fn perturbed_fk_is_first_order_in_jacobian() {
        let robot = irb2400().robot;
        let q = [12.5, 20.1, -3.4, 40.0, 35.2, -10.0];
        let (pose, jac) = robot.flange_jacobian(&q);
        let dp: Vec<f64> = (0..robot.n_params())
            .map(|k| if PARAM_IS_ANGLE[k % 5] { 1e-4 } else { 0.05 } * ((k * 7 % 5) as f64 - 2.0))
            .collect();
        let twist = jac * nalgebra::DVector::from_vec(dp.clone());
        let point = nalgebra::Point3::new(0.0, 0.0, 290.0);
        let x0 = pose * point;
        let predicted = x0.coords
            + Vector3::new(twist[0], twist[1], twist[2])
            + Vector3::new(twist[3], twist[4], twist[5]).cross(&x0.coords);
        let actual = robot.perturbed(&dp).base_from_flange(&q) * point;
        // Second-order remainder: |dp|² × lever ~ (1e-4)² × 1e3 mm scale.
        assert!(
            (actual.coords - predicted).norm() < 2e-3,
            "{}",
            (actual.coords - predicted).norm()
        );
    }

    #[test]
    fn inverse_kinematics_round_trip() {
        let preset = irb2400();
        let robot = preset.robot;
        let q = [12.5, 20.1, -3.4, 40.0, 35.2, -10.0];
        let target = robot.base_from_flange(&q);
        let start = [0.0, 10.0, 10.0, 20.0, 40.0, 0.0];
        let sol = robot
            .inverse_kinematics(&target, &start, Some(&preset.limits))
            .unwrap();
        let pose = robot.base_from_flange(&sol);
        assert!((pose.translation.vector - target.translation.vector).norm() < 1e-8);
        assert!(pose.rotation.angle_to(&target.rotation) < 1e-10);
    }
}
