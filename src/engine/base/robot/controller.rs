//! The robot controllers spherecal reads and writes for ([`Controller`],
//! the one list of them: the planner's program export, compensation's
//! tool data and programs, the pose readers) and how each writes a pose
//! ([`FlangeConvention`]: ABB's quaternion, KUKA's A B C, FANUC's W P R,
//! UR's rotation vector in metres, or a plain 4×4 matrix). One encoding
//! per controller, for every reader and writer of controller poses: the
//! import's flange-pose check and pose-only logs, joint logs, compensated
//! targets, tool data. An ABB quaternion is written with `w ≥ 0`.

use std::fmt::Write as _;

use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};

use crate::engine::base::geometry::{MatrixError, isometry_from_rows, rows_from_isometry};

/// Largest accepted deviation of an ABB quaternion's norm from 1.
const QUATERNION_NORM_TOLERANCE: f64 = 1e-3;

/// A robot controller, by maker: its pose convention, the language and
/// file of its programs, its tool data.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Controller {
    /// ABB IRC5 / OmniCore: RAPID, quaternion poses.
    Abb,
    /// KUKA KR C4: KRL, A B C angles.
    Kuka,
    /// FANUC R-30iB: TP programs (`.ls`), W P R angles.
    Fanuc,
    /// Universal Robots (CB3, e-Series): URScript, rotation vectors in m.
    Ur,
}

impl Controller {
    /// Every controller, in the order they are listed.
    pub const ALL: [Self; 4] = [Self::Abb, Self::Kuka, Self::Fanuc, Self::Ur];

    /// The maker: "ABB", "KUKA", "FANUC", "Universal Robots".
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Abb => "ABB",
            Self::Kuka => "KUKA",
            Self::Fanuc => "FANUC",
            Self::Ur => "Universal Robots",
        }
    }

    /// How it writes a pose.
    #[must_use]
    pub fn convention(self) -> FlangeConvention {
        match self {
            Self::Abb => FlangeConvention::AbbQuaternion,
            Self::Kuka => FlangeConvention::KukaAbc,
            Self::Fanuc => FlangeConvention::FanucWpr,
            Self::Ur => FlangeConvention::UrRotationVector,
        }
    }

    /// The controller whose convention is `c`; `None` for a matrix.
    #[must_use]
    pub fn of(c: FlangeConvention) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.convention() == c)
    }

    /// The key of its program language, as `--pose-format` and
    /// `plan --program` take it: `rapid`, `krl`, `fanuc-ls`, `urscript`.
    #[must_use]
    pub fn key(self) -> &'static str {
        match self {
            Self::Abb => "rapid",
            Self::Kuka => "krl",
            Self::Fanuc => "fanuc-ls",
            Self::Ur => "urscript",
        }
    }

    /// The controller of a program language's [`Self::key`].
    #[must_use]
    pub fn parse(key: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|c| c.key() == key)
    }

    /// The usual extension of its program files.
    #[must_use]
    pub fn extension(self) -> &'static str {
        match self {
            Self::Abb => "mod",
            Self::Kuka => "src",
            Self::Fanuc => "ls",
            Self::Ur => "script",
        }
    }

    /// What its program is, for a button or a message: "RAPID module".
    #[must_use]
    pub fn label(self) -> &'static str {
        match self {
            Self::Abb => "RAPID module",
            Self::Kuka => "KRL program",
            Self::Fanuc => "TP program",
            Self::Ur => "URScript program",
        }
    }

    /// The controller of a robot, by its model name (`ABB …` or `IRB …`,
    /// `KUKA …`, `FANUC …`, `Universal Robots …` or `UR…`).
    #[must_use]
    pub fn for_robot(name: &str) -> Option<Self> {
        let n = name.to_ascii_lowercase();
        if n.starts_with("abb") || n.contains("irb") {
            Some(Self::Abb)
        } else if n.starts_with("kuka") {
            Some(Self::Kuka)
        } else if n.starts_with("fanuc") {
            Some(Self::Fanuc)
        } else if n.starts_with("universal robots") || n.starts_with("ur") {
            Some(Self::Ur)
        } else {
            None
        }
    }

    /// What its tool data is, for people: "ABB RAPID tooldata".
    #[must_use]
    pub fn tool_data_kind(self) -> &'static str {
        match self {
            Self::Abb => "ABB RAPID tooldata",
            Self::Kuka => "KUKA TOOL_DATA",
            Self::Fanuc => "FANUC user tool frame (UTOOL)",
            Self::Ur => "Universal Robots TCP",
        }
    }

    /// The tool `flange_from_tcp` (mm) as this controller's tool data,
    /// named `name` where the syntax has a name (RAPID), tool number 1
    /// where it has a number; a few lines with the controller's comments,
    /// with the decimals a pendant shows ([`ToolDigits::Display`]).
    #[must_use]
    pub fn tool_data(self, flange_from_tcp: &Isometry3<f64>, name: &str) -> String {
        self.tool_data_with(flange_from_tcp, name, ToolDigits::Display)
    }

    /// [`Self::tool_data`] with the decimals `digits` asks for:
    /// [`ToolDigits::Full`] reads back to the tool within 1e-7 mm and
    /// 1e-11 rad (the export of `export-model --format tool`).
    #[must_use]
    pub fn tool_data_with(
        self,
        flange_from_tcp: &Isometry3<f64>,
        name: &str,
        digits: ToolDigits,
    ) -> String {
        let v = self.convention().values_from_pose(flange_from_tcp);
        let full = digits == ToolDigits::Full;
        // Decimals of mm, deg, a quaternion, m and rad.
        let (mm, deg, quat, m, rad) = if full {
            (7, 9, 12, 10, 12)
        } else {
            (4, 5, 9, 7, 7)
        };
        let mut s = String::new();
        match self {
            Self::Abb => {
                let _ = writeln!(
                    s,
                    "! TCP of {name} (mm, quaternion w x y z); the load [1,[0,0,1],…] is a placeholder: enter the sensor's mass (kg) and centre of gravity (mm)"
                );
                let _ = writeln!(
                    s,
                    "PERS tooldata {name} := [TRUE,[[{:.mm$},{:.mm$},{:.mm$}],[{:.quat$},{:.quat$},{:.quat$},{:.quat$}]],[1,[0,0,1],[1,0,0,0],0,0,0]];",
                    v[0], v[1], v[2], v[3], v[4], v[5], v[6]
                );
            }
            Self::Kuka => {
                let _ = writeln!(
                    s,
                    "; TCP of {name} (mm; A, B, C deg), in $config.dat or the numeric tool input"
                );
                let _ = writeln!(
                    s,
                    "TOOL_DATA[1]={{X {:.mm$},Y {:.mm$},Z {:.mm$},A {:.deg$},B {:.deg$},C {:.deg$}}}",
                    v[0], v[1], v[2], v[3], v[4], v[5]
                );
            }
            Self::Fanuc => {
                if full {
                    let _ = writeln!(
                        s,
                        "! UTOOL of {name}, as entered on SETUP > Frames > Tool Frame > Direct Entry (mm; W, P, R deg):"
                    );
                    for (k, label) in ["X", "Y", "Z", "W", "P", "R"].iter().enumerate() {
                        let d = if k < 3 { mm } else { deg };
                        let _ = writeln!(s, "!   {label}: {:.d$}", v[k]);
                    }
                    let _ = writeln!(s, "! or in a TP program, through position register 1:");
                } else {
                    let _ = writeln!(
                        s,
                        "! TCP of {name}: SETUP > Frames > Tool Frame > Direct Entry, or in a TP program (mm; W, P, R deg):"
                    );
                }
                for (k, label) in ["X", "Y", "Z", "W", "P", "R"].iter().enumerate() {
                    let d = if k < 3 {
                        mm
                    } else if full {
                        deg
                    } else {
                        4
                    };
                    let _ = writeln!(s, "PR[1,{}]={:.d$} ; ! {label}", k + 1, v[k]);
                }
                let _ = writeln!(s, "UTOOL[1]=PR[1] ;");
            }
            Self::Ur => {
                let _ = writeln!(
                    s,
                    "# TCP of {name} (m; rotation vector rad): Installation > TCP, or in URScript:"
                );
                let _ = writeln!(
                    s,
                    "set_tcp(p[{:.m$}, {:.m$}, {:.m$}, {:.rad$}, {:.rad$}, {:.rad$}])",
                    v[0], v[1], v[2], v[3], v[4], v[5]
                );
            }
        }
        s
    }
}

/// How many decimals tool data is written with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ToolDigits {
    /// What a pendant shows: 4 decimals of mm (0.1 µm), 5 of deg.
    Display,
    /// Enough to read back to the tool within 1e-7 mm and 1e-11 rad.
    Full,
}

/// Why a controller's values are no pose.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PoseValuesError {
    /// Another count of values than the convention has.
    #[error("{given} values given, the convention needs {needed}")]
    Count {
        /// Values given.
        given: usize,
        /// Values of the convention.
        needed: usize,
    },
    /// An ABB quaternion that is not of unit norm.
    #[error("quaternion norm {0:.6} is not 1")]
    QuaternionNorm(f64),
    /// NaN or infinite.
    #[error("a value is not a finite number")]
    NotFinite,
    /// A matrix that is not a rigid transform.
    #[error(transparent)]
    Matrix(#[from] MatrixError),
}

/// How a controller writes the flange pose.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FlangeConvention {
    /// ABB: x, y, z (mm), q1..q4 = w, x, y, z of a unit quaternion.
    AbbQuaternion,
    /// KUKA: x, y, z (mm), A, B, C (deg), `R = Rz(A)·Ry(B)·Rx(C)`.
    KukaAbc,
    /// Fanuc: x, y, z (mm), W, P, R (deg), `R = Rz(R)·Ry(P)·Rx(W)`.
    FanucWpr,
    /// Universal Robots: x, y, z (m), rx, ry, rz (rad) rotation vector.
    UrRotationVector,
    /// A 4×4 homogeneous matrix, 16 numbers row-major (mm), last row
    /// `0 0 0 1`, its 3×3 block a rotation (checked to 1e-6).
    Matrix,
}

impl FlangeConvention {
    /// Every convention, in the order the workbench lists them.
    pub const ALL: [Self; 5] = [
        Self::AbbQuaternion,
        Self::KukaAbc,
        Self::FanucWpr,
        Self::UrRotationVector,
        Self::Matrix,
    ];

    /// The name [`Self::parse`] reads (`abb`, `kuka`, `fanuc`, `ur`, `matrix`).
    #[must_use]
    pub fn key(self) -> &'static str {
        match self {
            Self::AbbQuaternion => "abb",
            Self::KukaAbc => "kuka",
            Self::FanucWpr => "fanuc",
            Self::UrRotationVector => "ur",
            Self::Matrix => "matrix",
        }
    }

    /// What the values are, for people: "FANUC x, y, z (mm), W, P, R (deg)".
    #[must_use]
    pub fn describe(self) -> &'static str {
        match self {
            Self::AbbQuaternion => "ABB x, y, z (mm), q1..q4 (unit quaternion w, x, y, z)",
            Self::KukaAbc => "KUKA x, y, z (mm), A, B, C (deg), R = Rz(A)·Ry(B)·Rx(C)",
            Self::FanucWpr => "FANUC x, y, z (mm), W, P, R (deg), R = Rz(R)·Ry(P)·Rx(W)",
            Self::UrRotationVector => "UR x, y, z (m), rx, ry, rz (rotation vector, rad)",
            Self::Matrix => "a 4×4 matrix, 16 numbers row-major (mm)",
        }
    }
}

impl FlangeConvention {
    /// Number of columns a pose takes (7 for ABB, 16 for a matrix, 6
    /// otherwise).
    #[must_use]
    pub fn n_columns(self) -> usize {
        match self {
            Self::AbbQuaternion => 7,
            Self::Matrix => 16,
            _ => 6,
        }
    }

    /// Default column names.
    #[must_use]
    pub fn default_columns(self) -> Vec<String> {
        let names: &[&str] = match self {
            Self::AbbQuaternion => &["x", "y", "z", "q1", "q2", "q3", "q4"],
            Self::KukaAbc => &["x", "y", "z", "a", "b", "c"],
            Self::FanucWpr => &["x", "y", "z", "w", "p", "r"],
            Self::UrRotationVector => &["x", "y", "z", "rx", "ry", "rz"],
            Self::Matrix => &[
                "m11", "m12", "m13", "m14", "m21", "m22", "m23", "m24", "m31", "m32", "m33", "m34",
                "m41", "m42", "m43", "m44",
            ],
        };
        names.iter().map(|s| (*s).to_string()).collect()
    }

    /// Parses `ABB`, `KUKA`, `FANUC`, `UR` or `matrix` (also `4x4`), any case.
    #[must_use]
    pub fn parse(s: &str) -> Option<Self> {
        match s.to_ascii_lowercase().as_str() {
            "abb" => Some(Self::AbbQuaternion),
            "kuka" => Some(Self::KukaAbc),
            "fanuc" => Some(Self::FanucWpr),
            "ur" => Some(Self::UrRotationVector),
            "matrix" | "4x4" => Some(Self::Matrix),
            _ => None,
        }
    }

    /// The flange pose `bT_e` (mm) from the controller's values, or what
    /// is wrong with them.
    ///
    /// # Errors
    /// [`PoseValuesError`]: the count is wrong, an ABB quaternion is not
    /// unit, a value is not finite, a matrix is not rigid.
    pub fn pose_from_values(self, v: &[f64]) -> Result<Isometry3<f64>, PoseValuesError> {
        if v.len() != self.n_columns() {
            return Err(PoseValuesError::Count {
                given: v.len(),
                needed: self.n_columns(),
            });
        }
        let (t, r) = match self {
            Self::AbbQuaternion => {
                let q = Quaternion::new(v[3], v[4], v[5], v[6]);
                if (q.norm() - 1.0).abs() > QUATERNION_NORM_TOLERANCE {
                    return Err(PoseValuesError::QuaternionNorm(q.norm()));
                }
                (
                    Vector3::new(v[0], v[1], v[2]),
                    UnitQuaternion::from_quaternion(q),
                )
            }
            Self::KukaAbc => (
                Vector3::new(v[0], v[1], v[2]),
                UnitQuaternion::from_euler_angles(
                    v[5].to_radians(),
                    v[4].to_radians(),
                    v[3].to_radians(),
                ),
            ),
            Self::FanucWpr => (
                Vector3::new(v[0], v[1], v[2]),
                UnitQuaternion::from_euler_angles(
                    v[3].to_radians(),
                    v[4].to_radians(),
                    v[5].to_radians(),
                ),
            ),
            Self::UrRotationVector => (
                Vector3::new(v[0], v[1], v[2]) * 1000.0,
                UnitQuaternion::from_scaled_axis(Vector3::new(v[3], v[4], v[5])),
            ),
            Self::Matrix => {
                let mut rows = [[0.0; 4]; 4];
                for (k, x) in v.iter().enumerate() {
                    rows[k / 4][k % 4] = *x;
                }
                return Ok(isometry_from_rows(&rows)?);
            }
        };
        if v.iter().any(|x| !x.is_finite()) {
            return Err(PoseValuesError::NotFinite);
        }
        Ok(Isometry3::from_parts(Translation3::from(t), r))
    }

    /// The controller's values for a flange pose `bT_e` (mm): the inverse
    /// of [`Self::pose_from_values`], the one encoding of each controller's
    /// poses (an ABB quaternion with `w ≥ 0`, as the controller reports
    /// it).
    #[must_use]
    pub fn values_from_pose(self, pose: &Isometry3<f64>) -> Vec<f64> {
        let t = pose.translation.vector;
        let r = pose.rotation;
        match self {
            Self::AbbQuaternion => {
                let q = r.into_inner();
                let q = if q.w < 0.0 { -q } else { q };
                vec![t.x, t.y, t.z, q.w, q.i, q.j, q.k]
            }
            Self::KukaAbc => {
                let (roll, pitch, yaw) = r.euler_angles();
                vec![
                    t.x,
                    t.y,
                    t.z,
                    yaw.to_degrees(),
                    pitch.to_degrees(),
                    roll.to_degrees(),
                ]
            }
            Self::FanucWpr => {
                let (roll, pitch, yaw) = r.euler_angles();
                vec![
                    t.x,
                    t.y,
                    t.z,
                    roll.to_degrees(),
                    pitch.to_degrees(),
                    yaw.to_degrees(),
                ]
            }
            Self::UrRotationVector => {
                let s = r.scaled_axis();
                vec![t.x / 1000.0, t.y / 1000.0, t.z / 1000.0, s.x, s.y, s.z]
            }
            Self::Matrix => rows_from_isometry(pose).iter().flatten().copied().collect(),
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn tool_data_reads_back() {
        let tool = trans(-7.4, -1.0, 287.8) * rot_z(0.5) * rot_x(3.0);
        let abb = Controller::Abb.tool_data(&tool, "tSensor");
        assert!(
            abb.contains("PERS tooldata tSensor := [TRUE,[[-7.4000,-1.0000,287.8000],"),
            "{abb}"
        );
        let kuka = Controller::Kuka.tool_data(&tool, "sensor");
        let line = kuka.lines().nth(1).unwrap();
        let numbers: Vec<f64> = line
            .trim_start_matches("TOOL_DATA[1]={")
            .trim_end_matches('}')
            .split(',')
            .map(|f| f.split_whitespace().nth(1).unwrap().parse().unwrap())
            .collect();
        let back = FlangeConvention::KukaAbc
            .pose_from_values(&numbers)
            .unwrap();
        assert!((back.translation.vector - tool.translation.vector).norm() < 1e-4);
        assert!(back.rotation.angle_to(&tool.rotation) < 1e-6);
        let fanuc = Controller::Fanuc.tool_data(&tool, "sensor");
        assert!(
            fanuc.contains("PR[1,3]=287.8000") && fanuc.contains("UTOOL[1]=PR[1]"),
            "{fanuc}"
        );
        let ur = Controller::Ur.tool_data(&tool, "sensor");
        assert!(
            ur.contains("set_tcp(p[-0.0074000, -0.0010000, 0.2878000,"),
            "{ur}"
        );
    }
    use crate::engine::base::geometry::{rot_x, rot_y, rot_z, trans};

    #[test]
    fn every_convention_round_trips() {
        let pose = trans(-195.8, 1363.3, 524.8) * rot_z(0.4) * rot_y(-0.3) * rot_x(2.9);
        for c in FlangeConvention::ALL {
            let v = c.values_from_pose(&pose);
            assert_eq!(v.len(), c.n_columns(), "{c:?}");
            let back = c.pose_from_values(&v).unwrap();
            assert!(
                (back.translation.vector - pose.translation.vector).norm() < 1e-9,
                "{c:?}"
            );
            assert!(back.rotation.angle_to(&pose.rotation) < 1e-12, "{c:?}");
            assert_eq!(FlangeConvention::parse(c.key()), Some(c));
        }
    }

    #[test]
    fn fanuc_wpr_is_rz_ry_rx() {
        // RobCalibrator's first pose: R = Rz(r)·Ry(p)·Rx(w).
        let (w, p, r) = (-179.924_f64, 0.889_f64, 179.635_f64);
        let pose = FlangeConvention::FanucWpr
            .pose_from_values(&[-195.8, 1363.305, 524.812, w, p, r])
            .unwrap();
        let expected = rot_z(r.to_radians()) * rot_y(p.to_radians()) * rot_x(w.to_radians());
        assert!(pose.rotation.angle_to(&expected.rotation) < 1e-12);
        assert!((pose.translation.vector.x + 195.8).abs() < 1e-12);
    }

    #[test]
    fn bad_values_are_named() {
        let e = FlangeConvention::FanucWpr
            .pose_from_values(&[1.0, 2.0, 3.0, 4.0, 5.0])
            .unwrap_err()
            .to_string();
        assert!(e.contains("5 values"), "{e}");
        let mut m = vec![0.0; 16];
        m[0] = 2.0;
        assert!(FlangeConvention::Matrix.pose_from_values(&m).is_err());
        let nan = FlangeConvention::KukaAbc
            .pose_from_values(&[1.0, 2.0, f64::NAN, 0.0, 0.0, 0.0])
            .unwrap_err()
            .to_string();
        assert!(nan.contains("finite"), "{nan}");
    }
}
