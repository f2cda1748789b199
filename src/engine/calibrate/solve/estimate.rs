//! The unknowns of the identification and their first-order effect
//! (paper eq. 10-16): the estimate (kinematic model and hand-eye), the
//! update vector `ΔY = [ΔX; ΔP]` (a hand-eye twist in the sensor frame,
//! `eT_s ← eT_s · exp(ΔX)`, then the `5·n` MDH errors) with its labels, and
//! the sensitivity of a measured centre to `ΔY`:
//!
//! ```text
//! ΔX_i = R(bT_s,i) · P_i · ΔX + Q_i · J_i · ΔP          (eq. 12-16)
//! P_i = [I | −[X_si]×]    (eq. 14; the rotation is that of bT_s = bT_e·eT_s,
//!                           the corrected eq. 13 of NOTES.md)
//! Q_i = [I | −[X_bi]×]    (eq. 16; J_i from Robot::flange_jacobian)
//! ```
//!
//! The paper's update ([`paper`](super::paper)) and `ml` ([`ml`](super::ml))
//! both linearise with these.
//!
//! One constraint serves both mounts (FORMAT.md `sensor.mount`): a point
//! fixed in one frame, seen from another, the kinematic chain between.
//! With the sensor on the flange the point is the sphere centre in the
//! base frame, `X = bT_e(q)·eT_s·X_s`; with a fixed sensor it is the
//! target on the flange, `X = bT_e(q)⁻¹·bT_s·X_s`, and the transform
//! estimated beside the model is `bT_s`. With `T = bT_e`, `H = bT_s`,
//! `Y = H·X_s` (base frame) and a base-frame twist `ξ = J_i·ΔP` of the
//! flange, the fixed mount's sensitivity is
//!
//! ```text
//! ΔX_i = R(T⁻¹·H) · P_i · ΔX − R(T)ᵀ · [I | −[Y]×] · J_i · ΔP
//! ```

use nalgebra::{DMatrix, Isometry3, Matrix3, Point3, Vector3};

use crate::engine::base::geometry::{isometry_from_twist, skew, twist_rows};
use crate::engine::base::robot::{PARAM_IS_ANGLE, PARAMS_PER_JOINT, Robot};
use crate::engine::base::session::Mount;
use crate::engine::calibrate::handeye::Sighting;

/// Lever (mm per rad) applied to angle unknowns before the SVD: the arm's
/// reach is ~1 m, so 1 mrad of a kinematic angle moves the tool ~1 mm.
pub const ANGLE_SCALE_MM: f64 = 1000.0;

/// Labels of the six hand-eye unknowns (sensor frame; mm, rad).
pub const HAND_EYE_LABELS: [&str; 6] = ["he_x", "he_y", "he_z", "he_rx", "he_ry", "he_rz"];

/// One identify station: every sighting saw the same fixed point.
#[derive(Debug, Clone, PartialEq)]
pub struct Station {
    /// Station id.
    pub id: String,
    /// Its sightings in file order.
    pub sightings: Vec<Sighting>,
}

/// The current estimate: kinematic model and hand-eye.
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate {
    /// Kinematic model.
    pub robot: Robot,
    /// The hand-eye: `eT_s` for a sensor on the flange; for a fixed
    /// sensor ([`Mount::Fixed`]) `bT_s`, the sensor's pose in the base
    /// frame.
    pub flange_from_sensor: Isometry3<f64>,
    /// Where the sensor stands; says what the hand-eye and the stations are.
    pub mount: Mount,
}

impl Estimate {
    /// The transform from the sensor frame to the frame a station's point
    /// is fixed in, at the flange pose `base_from_flange`: `bT_e·eT_s`
    /// (base frame) for a sensor on the flange, `bT_e⁻¹·bT_s` (flange
    /// frame) for a fixed sensor.
    #[must_use]
    pub fn station_from_sensor(&self, base_from_flange: &Isometry3<f64>) -> Isometry3<f64> {
        match self.mount {
            Mount::Flange => base_from_flange * self.flange_from_sensor,
            Mount::Fixed => base_from_flange.inverse() * self.flange_from_sensor,
        }
    }

    /// One sighting's point in its station's frame (eq. 10), mm: the
    /// sphere centre in the base frame for a sensor on the flange, the
    /// target in the flange frame for a fixed sensor.
    #[must_use]
    pub fn centre_in_base(&self, s: &Sighting) -> Vector3<f64> {
        let station_from_sensor = self.station_from_sensor(&s.base_from_flange(&self.robot));
        (station_from_sensor * Point3::from(s.centre_in_sensor)).coords
    }

    /// Base-frame centres of every station, grouped as `stations`.
    #[must_use]
    pub fn station_centres(&self, stations: &[Station]) -> Vec<Vec<Vector3<f64>>> {
        stations
            .iter()
            .map(|st| {
                st.sightings
                    .iter()
                    .map(|s| self.centre_in_base(s))
                    .collect()
            })
            .collect()
    }

    /// A copy with the update `ΔY = [ΔX; ΔP]` applied (mm, rad; unscaled).
    #[must_use]
    pub fn updated(&self, delta: &[f64]) -> Self {
        let twist = [delta[0], delta[1], delta[2], delta[3], delta[4], delta[5]];
        Self {
            robot: self.robot.perturbed(&delta[6..]),
            flange_from_sensor: self.flange_from_sensor * isometry_from_twist(&twist),
            mount: self.mount,
        }
    }
}

/// Label of unknown `k` of `ΔY` (`he_x`…, then `alpha1`, `a1`, …).
#[must_use]
pub fn unknown_label(k: usize) -> String {
    if k < 6 {
        HAND_EYE_LABELS[k].to_string()
    } else {
        Robot::param_label(k - 6)
    }
}

/// Whether unknown `k` of `ΔY` is an angle (rad).
#[must_use]
pub fn unknown_is_angle(k: usize) -> bool {
    if k < 6 {
        k >= 3
    } else {
        PARAM_IS_ANGLE[(k - 6) % PARAMS_PER_JOINT]
    }
}

/// Scale of `ΔY` unknown `k` in a solve: angles in mm of motion at
/// [`ANGLE_SCALE_MM`] mm, lengths as they are (scaled = raw × scale).
#[must_use]
pub fn unknown_scale(k: usize) -> f64 {
    if unknown_is_angle(k) {
        ANGLE_SCALE_MM
    } else {
        1.0
    }
}

/// The 3 × (6 + 5n) sensitivity `A_i` of one sighting's base-frame centre
/// to `ΔY` (the bracket of eq. 17 for one measurement), and the centre.
#[must_use]
pub fn sensitivity(est: &Estimate, s: &Sighting) -> (Vector3<f64>, DMatrix<f64>) {
    PoseSensitivity::new(est, s).at(est, &s.centre_in_sensor)
}

/// The part of [`sensitivity`] that depends on the pose only (the flange
/// pose and its Jacobian `J_i`), to evaluate many sensor points at one
/// pose.
#[derive(Debug, Clone)]
pub struct PoseSensitivity {
    base_from_flange: Isometry3<f64>,
    jac: nalgebra::Matrix6xX<f64>,
}

impl PoseSensitivity {
    /// The pose of sighting `s` under `est`.
    #[must_use]
    pub fn new(est: &Estimate, s: &Sighting) -> Self {
        Self::at_pose(est, &s.joints, s.flange.as_ref())
    }

    /// The pose of the joint readings `joints` (deg) under `est`, or the
    /// given flange pose `flange` (`base_from_flange`, mm; the kinematic
    /// parameters then have no effect): a pose without a sighting, as a
    /// compensated target or a measured profile has.
    #[must_use]
    pub fn at_pose(est: &Estimate, joints: &[f64], flange: Option<&Isometry3<f64>>) -> Self {
        let (base_from_flange, jac) = match flange {
            // A given flange pose does not depend on the kinematic parameters.
            Some(pose) => (*pose, nalgebra::Matrix6xX::zeros(est.robot.n_params())),
            None => est.robot.flange_jacobian(joints),
        };
        Self {
            base_from_flange,
            jac,
        }
    }

    /// `A_i` and the position of sensor point `x_s` at this pose in the
    /// station frame (the base frame for a sensor on the flange, the
    /// flange frame for a fixed sensor).
    #[must_use]
    pub fn at(&self, est: &Estimate, x_s: &Vector3<f64>) -> (Vector3<f64>, DMatrix<f64>) {
        let station_from_sensor = est.station_from_sensor(&self.base_from_flange);
        let x = (station_from_sensor * Point3::from(*x_s)).coords;
        let r: Matrix3<f64> = station_from_sensor
            .rotation
            .to_rotation_matrix()
            .into_inner();
        let n = 6 + self.jac.ncols();
        let mut a = DMatrix::zeros(3, n);
        // Hand-eye block: R · [I | −[X_s]×]   (eq. 13-14)
        a.fixed_view_mut::<3, 3>(0, 0).copy_from(&r);
        a.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&(-(r * skew(x_s))));
        let qj = match est.mount {
            // Kinematic block: Q_i · J_i = [I | −[X_b]×] · J_i   (eq. 15-16)
            Mount::Flange => twist_rows(&x) * &self.jac,
            // The flange moves by the base-frame twist J_i·ΔP; the point
            // seen in the base frame, Y, moves the other way in the
            // flange frame: −R(bT_e)ᵀ · [I | −[Y]×] · J_i.
            Mount::Fixed => {
                let y = (est.flange_from_sensor * Point3::from(*x_s)).coords;
                let r_be: Matrix3<f64> = self
                    .base_from_flange
                    .rotation
                    .to_rotation_matrix()
                    .into_inner();
                -(r_be.transpose() * twist_rows(&y)) * &self.jac
            }
        };
        a.view_mut((0, 6), (3, n - 6)).copy_from(&qj);
        (x, a)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sensitivity_matches_finite_differences() {
        for mount in [Mount::Flange, Mount::Fixed] {
            check_sensitivity(mount);
        }
    }

    fn check_sensitivity(mount: Mount) {
        let robot = crate::engine::base::robot::irb2400().robot;
        let est = Estimate {
            robot,
            flange_from_sensor: isometry_from_twist(&[-7.4, -1.0, 287.8, 3.1, 0.02, 0.5]),
            mount,
        };
        let s = Sighting {
            id: "x".into(),
            joints: vec![12.5, 20.1, -3.4, 40.0, 35.2, -10.0],
            flange: None,
            centre_in_sensor: Vector3::new(12.2, -1.3, 2.4),
        };
        let (x0, a) = sensitivity(&est, &s);
        let n = a.ncols();
        for k in 0..n {
            let h = 1e-6;
            let mut d = vec![0.0; n];
            d[k] = h;
            let xp = est.updated(&d).centre_in_base(&s);
            d[k] = -h;
            let xm = est.updated(&d).centre_in_base(&s);
            let numeric = (xp - xm) / (2.0 * h);
            let analytic = a.column(k);
            let err = (numeric - analytic).norm();
            assert!(
                err < 1e-5 * (1.0 + analytic.norm()),
                "{}: {err}",
                unknown_label(k)
            );
        }
        assert!((x0 - est.centre_in_base(&s)).norm() < 1e-12);
    }
}
