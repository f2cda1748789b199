//! The joint log: the CSV a controller hands over for a calibration, one
//! row per pose — `id,station,use,side,j1..jn` (deg), then the flange pose
//! the controller reports (`x,y,z,q1..q4`: ABB's mm and unit quaternion
//! w, x, y, z), then any further columns. The planner writes it for the
//! cell to teach, the simulator writes it as a cell would record it, and
//! the import and the simulator read it back ([`Table`](crate::engine::files::table::Table)):
//! one reader and one writer.

use std::fmt::Write as _;

use nalgebra::Isometry3;

use crate::engine::base::robot::controller::FlangeConvention;
use crate::engine::base::session::Use;

/// One row of a joint log to write.
#[derive(Debug, Clone, PartialEq)]
pub struct Row<'a> {
    /// Measurement id.
    pub id: &'a str,
    /// Station id.
    pub station: &'a str,
    /// What the pose is for.
    pub usage: Use,
    /// Side of the laser plane the sphere centre is planned on (+1 or −1).
    pub side: i8,
    /// Joint readings, deg.
    pub joints: &'a [f64],
    /// The flange pose the controller reports (base frame, mm).
    pub flange: Isometry3<f64>,
    /// Further columns, already formatted.
    pub extra: Vec<String>,
}

/// A joint reading to 1e-9° without trailing zeros (a reading already
/// rounded to 9 decimals prints as it reads).
fn joint_text(q: f64) -> String {
    let s = format!("{q:.9}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" || s.is_empty() {
        format!("{q}")
    } else {
        s.to_string()
    }
}

/// A joint log: `#` comment lines, the header
/// `id,station,use,side,j1..jn,x,y,z,q1,q2,q3,q4` plus `extra_header`, and
/// one line per row (joints to 1e-9°, the flange position to 1e-6 mm, the
/// quaternion to 12 decimals, `w ≥ 0`: ABB's encoding,
/// [`FlangeConvention::values_from_pose`]).
#[must_use]
pub fn write(comments: &[String], n_joints: usize, extra_header: &[&str], rows: &[Row]) -> String {
    let mut out = String::new();
    for c in comments {
        let _ = writeln!(out, "# {c}");
    }
    out.push_str("id,station,use,side");
    for k in 1..=n_joints {
        let _ = write!(out, ",j{k}");
    }
    out.push_str(",x,y,z,q1,q2,q3,q4");
    for h in extra_header {
        let _ = write!(out, ",{h}");
    }
    out.push('\n');
    for r in rows {
        let _ = write!(
            out,
            "{},{},{},{}",
            r.id,
            r.station,
            r.usage.as_str(),
            r.side
        );
        for &q in r.joints {
            let _ = write!(out, ",{}", joint_text(q));
        }
        let f = FlangeConvention::AbbQuaternion.values_from_pose(&r.flange);
        let _ = write!(
            out,
            ",{:.6},{:.6},{:.6},{:.12},{:.12},{:.12},{:.12}",
            f[0], f[1], f[2], f[3], f[4], f[5], f[6]
        );
        for e in &r.extra {
            let _ = write!(out, ",{e}");
        }
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn joint_text_is_shortest_for_rounded_readings() {
        for q in [20.5, -0.0, 0.0, 90.0, 4.576_573_352, -27.320_271_412, 1e-9] {
            assert_eq!(joint_text(q).parse::<f64>().ok(), Some(q), "{q}");
            assert_eq!(joint_text(q), format!("{q}"), "{q}");
        }
        assert_eq!(joint_text(12.345_678_901_234), "12.345678901");
    }
}
