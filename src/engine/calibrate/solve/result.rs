//! A calibration as the result file holds it: the one place the solver's
//! output ([`Calibration`]) becomes the format's [`ResultFile`] (the format
//! itself, layer `files`, knows only the report types of
//! [`crate::engine::base::records`]).

use super::Calibration;
use crate::engine::base::session::{Session, Use};
use crate::engine::files::format::ResultFile;
use crate::engine::files::format::result::{CentreRecord, IterationRecord};
use crate::engine::files::format::stations::stations_of;

impl ResultFile {
    /// The result of a run on `session`.
    #[must_use]
    pub fn from_calibration(session: &Session, cal: &Calibration) -> Self {
        let mut result = Self {
            session: session.name.clone(),
            hand_eye_initial: cal.hand_eye_initial,
            hand_eye: cal.hand_eye,
            robot: if session.pose_only() {
                session.robot_given.then(|| session.robot.clone())
            } else {
                Some(cal.calibrated.clone())
            },
            joint_errors: if session.pose_only() {
                Vec::new()
            } else {
                cal.calibrated.joint_errors(&cal.nominal)
            },
            solver: cal.report.clone(),
            iterations: cal
                .iterations
                .iter()
                .map(|&epsilon| IterationRecord { epsilon })
                .collect(),
            epsilon_before: cal.epsilon_before(),
            epsilon_after: cal.epsilon_after(),
            centres: cal
                .centres
                .iter()
                .map(|c| {
                    let m = &session.measurements[c.index];
                    CentreRecord {
                        measurement: m.id.clone(),
                        station: m.station.clone(),
                        usage: m.usage,
                        sensor: c.sensor.into(),
                        before: c.before.into(),
                        after: c.after.into(),
                    }
                })
                .collect(),
            validation: cal.validation.clone(),
            held_out: cal.held_out.clone(),
            pose_joints: cal
                .centres
                .iter()
                .map(|c| &session.measurements[c.index])
                .filter(|m| {
                    matches!(m.usage, Use::Identify | Use::Validate) && !m.joints.is_empty()
                })
                .map(|m| (m.id.clone(), m.joints.clone()))
                .collect(),
            stations: Vec::new(),
        };
        result.stations = stations_of(&result.centres, session.mount);
        result
    }
}
