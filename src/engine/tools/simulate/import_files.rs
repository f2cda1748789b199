//! The files a real cell would hand to `spherecal import` for a simulated
//! session: the joint log and one stripe profile per pose.

use crate::engine::base::cell::joint_log;
use crate::engine::base::session::{Observation, Session};

use super::config::SimError;

/// The inputs of `spherecal import` for a simulated stripe session, as a
/// real cell would leave them (see [`import_files`]).
#[derive(Debug, Clone, PartialEq)]
pub struct ImportFiles {
    /// The joint log: `id,station,use,side,j1..jn,x,y,z,q1,q2,q3,q4`.
    pub joints_csv: String,
    /// One stripe profile per measurement: `(id, "y,z" CSV text)`, mm.
    pub profiles: Vec<(String, String)>,
    /// `from,to,distance` (mm) of the reference distances; `None` when the
    /// session has none.
    pub references_csv: Option<String>,
}

/// The import inputs of a session with stripes: the joint log with the
/// flange pose the controller reports (ABB `x,y,z` in mm and the unit
/// quaternion `q1..q4` = w, x, y, z), computed by the **nominal** forward
/// kinematics of the recorded joints, as a real controller computes it;
/// a `y,z` profile per measurement; the reference distances. Numbers are
/// written with enough decimals to round-trip the session (joints 1e-9°,
/// profile points as in the session).
///
/// # Errors
/// [`SimError::InvalidConfig`] when a measurement is a centre (the import
/// reads stripes only).
pub fn import_files(session: &Session) -> Result<ImportFiles, SimError> {
    use std::fmt::Write as _;
    let mut rows = Vec::with_capacity(session.measurements.len());
    let mut profiles = Vec::with_capacity(session.measurements.len());
    for m in &session.measurements {
        let Observation::Stripe(points) = &m.observation else {
            return Err(SimError::InvalidConfig(format!(
                "measurement {} is a sphere centre; the import reads stripe profiles (simulate without --centres)",
                m.id
            )));
        };
        rows.push(joint_log::Row {
            id: &m.id,
            station: &m.station,
            usage: m.usage,
            side: m.side,
            joints: &m.joints,
            flange: session.robot.base_from_flange(&m.joints),
            extra: Vec::new(),
        });
        let mut text = String::from("y,z\n");
        for [y, z] in points {
            let _ = writeln!(text, "{y},{z}");
        }
        profiles.push((m.id.clone(), text));
    }
    let joints_csv = joint_log::write(&[], session.robot.dof(), &[], &rows);
    let references_csv = (!session.reference_distances.is_empty()).then(|| {
        let mut text = String::from("from,to,distance\n");
        for r in &session.reference_distances {
            let _ = writeln!(text, "{},{},{}", r.from, r.to, r.distance);
        }
        text
    });
    Ok(ImportFiles {
        joints_csv,
        profiles,
        references_csv,
    })
}
