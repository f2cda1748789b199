//! Tool data in each controller's own syntax: the TCP (for `--tcp sensor`
//! the calibrated hand-eye, `flange_from_sensor`) as the user enters it,
//! so the nominal controller computes the flange pose of a compensated
//! target exactly as the compensation assumed.

use std::fmt::Write as _;
use std::path::Path;

use nalgebra::Isometry3;

use crate::engine::base::robot::controller::FlangeConvention;
use crate::engine::files::format::read_transform;

/// Reads a tool `flange_from_tcp` from a JSON file: a 4×4 matrix (rows,
/// mm), alone or under the key `flange_from_tcp`
/// ([`read_transform`], with its plausibility caps).
///
/// # Errors
/// A message naming the file and what is wrong.
pub fn read_tool(path: &Path) -> Result<Isometry3<f64>, String> {
    read_transform(path, "flange_from_tcp").map_err(|e| format!("tool {}: {e}", path.display()))
}

/// The controllers tool data is written for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Controller {
    /// ABB RAPID `tooldata`.
    Abb,
    /// KUKA `TOOL_DATA[n]` (`$config.dat`).
    Kuka,
    /// FANUC user tool frame `UTOOL[n]`.
    Fanuc,
    /// Universal Robots `set_tcp`.
    Ur,
}

impl Controller {
    /// Every controller, in the order they are listed.
    pub const ALL: [Self; 4] = [Self::Abb, Self::Kuka, Self::Fanuc, Self::Ur];

    /// The controller whose convention is `c`; `None` for a matrix.
    #[must_use]
    pub fn of(c: FlangeConvention) -> Option<Self> {
        match c {
            FlangeConvention::AbbQuaternion => Some(Self::Abb),
            FlangeConvention::KukaAbc => Some(Self::Kuka),
            FlangeConvention::FanucWpr => Some(Self::Fanuc),
            FlangeConvention::UrRotationVector => Some(Self::Ur),
            FlangeConvention::Matrix => None,
        }
    }

    /// For people: "ABB RAPID tooldata".
    #[must_use]
    pub fn describe(self) -> &'static str {
        match self {
            Self::Abb => "ABB RAPID tooldata",
            Self::Kuka => "KUKA TOOL_DATA",
            Self::Fanuc => "FANUC user tool frame (UTOOL)",
            Self::Ur => "Universal Robots TCP",
        }
    }

    /// The tool `flange_from_tcp` (mm) as this controller's tool data,
    /// named `name` where the syntax has a name (RAPID), tool number 1
    /// where it has a number; a few lines with the controller's comments.
    #[must_use]
    pub fn tool_data(self, flange_from_tcp: &Isometry3<f64>, name: &str) -> String {
        let convention = match self {
            Self::Abb => FlangeConvention::AbbQuaternion,
            Self::Kuka => FlangeConvention::KukaAbc,
            Self::Fanuc => FlangeConvention::FanucWpr,
            Self::Ur => FlangeConvention::UrRotationVector,
        };
        let v = convention.values_from_pose(flange_from_tcp);
        let mut s = String::new();
        match self {
            Self::Abb => {
                let _ = writeln!(
                    s,
                    "! TCP of {name} (mm, quaternion w x y z); the load [1,[0,0,1],…] is a placeholder: enter the sensor's mass (kg) and centre of gravity (mm)"
                );
                let _ = writeln!(
                    s,
                    "PERS tooldata {name} := [TRUE,[[{:.4},{:.4},{:.4}],[{:.9},{:.9},{:.9},{:.9}]],[1,[0,0,1],[1,0,0,0],0,0,0]];",
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
                    "TOOL_DATA[1]={{X {:.4},Y {:.4},Z {:.4},A {:.5},B {:.5},C {:.5}}}",
                    v[0], v[1], v[2], v[3], v[4], v[5]
                );
            }
            Self::Fanuc => {
                let _ = writeln!(
                    s,
                    "! TCP of {name}: SETUP > Frames > Tool Frame > Direct Entry, or in a TP program (mm; W, P, R deg):"
                );
                for (k, label) in ["X", "Y", "Z", "W", "P", "R"].iter().enumerate() {
                    let _ = writeln!(s, "PR[1,{}]={:.4} ; ! {label}", k + 1, v[k]);
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
                    "set_tcp(p[{:.7}, {:.7}, {:.7}, {:.7}, {:.7}, {:.7}])",
                    v[0], v[1], v[2], v[3], v[4], v[5]
                );
            }
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::base::geometry::{rot_x, rot_z, trans};

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
}
