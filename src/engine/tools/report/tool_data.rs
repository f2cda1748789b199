//! The calibrated hand-eye as tool data (issue 33, `export-model --format
//! tool`): for every result, pose-only ones included, the sensor
//! `flange_from_sensor` in a controller's own syntax
//! ([`Controller::tool_data_with`], the one home of those syntaxes: RAPID
//! `tooldata`, KRL `TOOL_DATA`, FANUC's UTOOL through a position register,
//! UR's `set_tcp`) or for ROS 2 (a `static_transform_publisher` line and a
//! URDF joint of a `sensor` link), with the 1σ of each value the
//! controller takes, propagated from `ml`'s covariance of the hand-eye.

use std::fmt::Write as _;

use nalgebra::{Isometry3, Matrix6, Translation3, UnitQuaternion, Vector3};

use super::model::{urdf_number, urdf_origin};
use crate::engine::base::records::ml::LabelledMatrix;
use crate::engine::base::robot::controller::{Controller, ToolDigits};
use crate::engine::calibrate::solve::estimate::HAND_EYE_LABELS;
use crate::engine::files::format::ResultFile;

/// What the tool data is for (`--controller`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ToolTarget {
    /// A robot controller's tool data.
    Controller(Controller),
    /// ROS 2: a static transform and a URDF joint from the flange frame.
    Ros,
}

/// Name of the tool (RAPID) and of the frame (ROS) written.
pub const TOOL_NAME: &str = "tSensor";

/// The ROS frame of the flange the sensor frame hangs from.
pub const ROS_FLANGE_FRAME: &str = "tool0";

/// The ROS frame of the calibrated sensor.
pub const ROS_SENSOR_FRAME: &str = "sensor";

impl ToolTarget {
    /// Every target, in `--controller`'s order.
    pub const ALL: [Self; 5] = [
        Self::Controller(Controller::Abb),
        Self::Controller(Controller::Kuka),
        Self::Controller(Controller::Fanuc),
        Self::Controller(Controller::Ur),
        Self::Ros,
    ];

    /// The key `--controller` takes: `abb`, `kuka`, `fanuc`, `ur`, `ros`.
    #[must_use]
    pub fn key(self) -> &'static str {
        match self {
            Self::Controller(c) => c.convention().key(),
            Self::Ros => "ros",
        }
    }

    /// The target of a key.
    #[must_use]
    pub fn parse(key: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|t| t.key().eq_ignore_ascii_case(key))
    }

    /// The comment lead of its syntax.
    fn comment(self) -> &'static str {
        match self {
            Self::Controller(Controller::Abb | Controller::Fanuc) => "!",
            Self::Controller(Controller::Kuka) => ";",
            Self::Controller(Controller::Ur) | Self::Ros => "#",
        }
    }

    /// The values the controller takes for a tool, with their names and
    /// units: the convention's (ABB x y z mm and q1..q4; KUKA A B C deg;
    /// FANUC W P R deg; UR m and rad), ROS's x y z (m) and roll pitch yaw
    /// (rad).
    #[must_use]
    pub fn values(self, tool: &Isometry3<f64>) -> Vec<f64> {
        match self {
            Self::Controller(c) => c.convention().values_from_pose(tool),
            Self::Ros => {
                let (t, r) = urdf_origin(tool);
                t.into_iter().chain(r).collect()
            }
        }
    }

    /// Names and units of [`Self::values`].
    #[must_use]
    pub fn labels(self) -> Vec<(&'static str, &'static str)> {
        let mm = |n: [&'static str; 3]| n.map(|x| (x, "mm"));
        match self {
            Self::Controller(Controller::Abb) => {
                let mut v = mm(["x", "y", "z"]).to_vec();
                v.extend([("q1", ""), ("q2", ""), ("q3", ""), ("q4", "")]);
                v
            }
            Self::Controller(Controller::Kuka) => mm(["X", "Y", "Z"])
                .into_iter()
                .chain(["A", "B", "C"].map(|x| (x, "°")))
                .collect(),
            Self::Controller(Controller::Fanuc) => mm(["X", "Y", "Z"])
                .into_iter()
                .chain(["W", "P", "R"].map(|x| (x, "°")))
                .collect(),
            Self::Controller(Controller::Ur) => ["x", "y", "z"]
                .map(|x| (x, "m"))
                .into_iter()
                .chain(["rx", "ry", "rz"].map(|x| (x, "rad")))
                .collect(),
            Self::Ros => ["x", "y", "z"]
                .map(|x| (x, "m"))
                .into_iter()
                .chain(["roll", "pitch", "yaw"].map(|x| (x, "rad")))
                .collect(),
        }
    }

    /// The period of value `k` (an angle wraps), if any, and whether it is
    /// a quaternion component (whose sign goes with the others).
    fn period(self, k: usize) -> Option<f64> {
        match (self, k) {
            (_, 0..=2) | (Self::Controller(Controller::Abb), _) => None,
            (Self::Controller(Controller::Kuka | Controller::Fanuc), _) => Some(360.0),
            _ => Some(std::f64::consts::TAU),
        }
    }
}

/// 1σ of each of `target`'s values of the hand-eye, from the covariance
/// of the perturbation `eT_s·exp(ΔX)` (sensor frame, `he_x … he_rz`, mm
/// and deg), by central differences. `None` when a hand-eye direction is
/// not in the covariance (held fixed) or the result has none.
#[must_use]
pub fn value_sigmas(
    target: ToolTarget,
    hand_eye: &Isometry3<f64>,
    covariance: &LabelledMatrix,
) -> Option<Vec<f64>> {
    let index: Vec<usize> = HAND_EYE_LABELS
        .iter()
        .map(|l| covariance.labels.iter().position(|x| x == l))
        .collect::<Option<_>>()?;
    let mut c = Matrix6::<f64>::zeros();
    for (a, &i) in index.iter().enumerate() {
        for (b, &j) in index.iter().enumerate() {
            c[(a, b)] = *covariance.matrix.get(i)?.get(j)?;
        }
    }
    let base = target.values(hand_eye);
    let moved = |k: usize, h: f64| {
        let mut t = Vector3::zeros();
        let mut w = Vector3::zeros();
        if k < 3 {
            t[k] = h;
        } else {
            w[k - 3] = h.to_radians();
        }
        let pert =
            Isometry3::from_parts(Translation3::from(t), UnitQuaternion::from_scaled_axis(w));
        let mut v = target.values(&(hand_eye * pert));
        if matches!(target, ToolTarget::Controller(Controller::Abb)) {
            let dot: f64 = (3..7).map(|i| v[i] * base[i]).sum();
            if dot < 0.0 {
                for x in &mut v[3..7] {
                    *x = -*x;
                }
            }
        }
        for (i, x) in v.iter_mut().enumerate() {
            if let Some(p) = target.period(i) {
                *x = base[i] + (*x - base[i] - p * ((*x - base[i]) / p).round());
            }
        }
        v
    };
    let h = 1e-5;
    let n = base.len();
    let mut jac = nalgebra::DMatrix::<f64>::zeros(n, 6);
    for k in 0..6 {
        let (p, m) = (moved(k, h), moved(k, -h));
        for i in 0..n {
            jac[(i, k)] = (p[i] - m[i]) / (2.0 * h);
        }
    }
    let c = nalgebra::DMatrix::from_iterator(6, 6, c.iter().copied());
    let f = &jac * c * jac.transpose();
    let out: Vec<f64> = (0..n)
        .map(|i| crate::engine::base::numeric::sigma_of_variance(f[(i, i)]))
        .collect();
    out.iter().all(|v| v.is_finite()).then_some(out)
}

/// The result's calibrated hand-eye as `target`'s tool data: a comment
/// naming the result (`source`) and what was calibrated, the 1σ of every
/// value (or why there is none), then the syntax with enough decimals to
/// read back within 1e-7 mm and 1e-11 rad.
#[must_use]
pub fn tool_export(result: &ResultFile, target: ToolTarget, source: &str) -> String {
    let c = target.comment();
    let tool = result.hand_eye;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{c} Calibrated sensor (hand-eye, flange → sensor) of {source}, session {:?}, by spherecal {}.",
        result.session,
        env!("CARGO_PKG_VERSION")
    );
    if result.hand_eye_only() {
        let _ = writeln!(
            s,
            "{c} A pose-only result: the hand-eye was calibrated, the robot's kinematics were not."
        );
    }
    let labels = target.labels();
    match result
        .solver
        .ml()
        .and_then(|ml| value_sigmas(target, &tool, &ml.covariance))
    {
        Some(sig) => {
            let parts: Vec<String> = labels
                .iter()
                .zip(&sig)
                .map(|((name, unit), v)| match *unit {
                    "" => format!("{name} ±{v:.6}"),
                    "m" => format!("{name} ±{v:.7} m"),
                    "rad" => format!("{name} ±{v:.6} rad"),
                    "°" => format!("{name} ±{v:.4}°"),
                    u => format!("{name} ±{v:.4} {u}"),
                })
                .collect();
            let _ = writeln!(s, "{c} 1σ: {}", parts.join(", "));
        }
        None => {
            let _ = writeln!(
                s,
                "{c} 1σ: not known (the result has no covariance of the hand-eye: the paper's method, or a direction held fixed)"
            );
        }
    }
    match target {
        ToolTarget::Controller(ctrl) => {
            s.push_str(&ctrl.tool_data_with(&tool, TOOL_NAME, ToolDigits::Full));
        }
        ToolTarget::Ros => {
            let v: Vec<String> = target.values(&tool).into_iter().map(urdf_number).collect();
            let _ = writeln!(
                s,
                "# ROS 2: the sensor frame as a static transform from the flange frame ({ROS_FLANGE_FRAME}, the frame the calibration's flange poses are of):"
            );
            let _ = writeln!(
                s,
                "ros2 run tf2_ros static_transform_publisher --x {} --y {} --z {} --roll {} --pitch {} --yaw {} --frame-id {ROS_FLANGE_FRAME} --child-frame-id {ROS_SENSOR_FRAME}",
                v[0], v[1], v[2], v[3], v[4], v[5]
            );
            let _ = writeln!(s, "# or in the robot's URDF:");
            s.push_str(&sensor_urdf(&tool, ROS_FLANGE_FRAME, "  "));
        }
    }
    s
}

/// A `sensor` link and the fixed `sensor_joint` hanging it from `parent`
/// at the hand-eye, each line led by `indent`.
#[must_use]
pub fn sensor_urdf(hand_eye: &Isometry3<f64>, parent: &str, indent: &str) -> String {
    let (t, r) = urdf_origin(hand_eye);
    let [x, y, z] = t.map(urdf_number);
    let [roll, pitch, yaw] = r.map(urdf_number);
    let mut s = String::new();
    let _ = writeln!(s, "{indent}<link name=\"{ROS_SENSOR_FRAME}\"/>");
    let _ = writeln!(
        s,
        "{indent}<joint name=\"{ROS_SENSOR_FRAME}_joint\" type=\"fixed\">"
    );
    let _ = writeln!(s, "{indent}  <parent link=\"{parent}\"/>");
    let _ = writeln!(s, "{indent}  <child link=\"{ROS_SENSOR_FRAME}\"/>");
    let _ = writeln!(
        s,
        "{indent}  <origin xyz=\"{x} {y} {z}\" rpy=\"{roll} {pitch} {yaw}\"/>"
    );
    let _ = writeln!(s, "{indent}</joint>");
    s
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::engine::base::geometry::{rot_x, rot_y, rot_z, trans};
    use crate::engine::tools::result_view::hand_eye_sigma;

    fn covariance() -> LabelledMatrix {
        let sd = [0.1, 0.2, 0.3, 0.01, 0.02, 0.03];
        LabelledMatrix {
            labels: HAND_EYE_LABELS.iter().map(|s| (*s).to_string()).collect(),
            units: Vec::new(),
            matrix: (0..6)
                .map(|i| {
                    (0..6)
                        .map(|j| {
                            let rho = if i == j { 1.0 } else { 0.3 };
                            rho * sd[i] * sd[j]
                        })
                        .collect()
                })
                .collect(),
        }
    }

    #[test]
    fn fanuc_sigmas_are_the_results_roll_pitch_yaw_sigmas() {
        // FANUC's W P R are the fixed-axis roll, pitch, yaw the result view
        // propagates by its own route (a Jacobian of the rotation matrix).
        let he = trans(-7.4, -1.0, 287.8) * rot_z(0.5) * rot_y(0.3) * rot_x(3.0);
        let c = covariance();
        let fanuc = value_sigmas(ToolTarget::Controller(Controller::Fanuc), &he, &c).unwrap();
        let view = hand_eye_sigma(&he, &c).unwrap();
        for (a, b) in fanuc.iter().zip(view) {
            assert!((a - b).abs() < 1e-6 * b.max(1.0), "{fanuc:?} vs {view:?}");
        }
        // KUKA's A B C are the same angles in the other order; UR's and
        // ROS's translations are the same σ in metres.
        let kuka = value_sigmas(ToolTarget::Controller(Controller::Kuka), &he, &c).unwrap();
        assert!((kuka[3] - view[5]).abs() < 1e-6 && (kuka[5] - view[3]).abs() < 1e-6);
        let ros = value_sigmas(ToolTarget::Ros, &he, &c).unwrap();
        assert!((ros[0] * 1000.0 - view[0]).abs() < 1e-9);
        assert!((ros[4].to_degrees() - view[4]).abs() < 1e-6);
        // A direction held fixed: no σ.
        let mut partial = c;
        partial.labels[2] = "d1".into();
        assert!(value_sigmas(ToolTarget::Ros, &he, &partial).is_none());
    }
}
