//! The Plan view's form: the robot preset, where the hand-eye guess comes
//! from, and the engine's [`PlanRequest`] (as `spherecal plan` takes it).
//! The planning job is [`super::job`].

use nalgebra::Isometry3;

use crate::engine::base::cell::workspace::Workspace;
use crate::engine::base::robot::RobotChoice;
use crate::engine::files::import::RobotSource;
use crate::engine::tools::plan::{PlanConfig, PlanRequest};

/// The Plan view's fields: the robot preset and where the hand-eye guess
/// comes from, and the rest of the request as the command line has it.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanForm {
    /// Robot preset key.
    pub robot: String,
    /// Take the hand-eye guess from the open session (when it has one)
    /// instead of the paper's initial hand-eye.
    pub hand_eye_from_session: bool,
    /// The plan asked for (its robot and hand-eye are set from the fields
    /// above when it is made).
    pub request: PlanRequest,
}

impl Default for PlanForm {
    fn default() -> Self {
        let key = RobotChoice::Irb2400.key();
        Self {
            robot: key.to_string(),
            hand_eye_from_session: false,
            request: PlanRequest::new(RobotSource::Preset(key.to_string()), default_sphere(key)),
        }
    }
}

/// A sphere position every preset reaches from both sides: the centre of
/// its simulator workspace (base frame, mm).
#[must_use]
pub fn default_sphere(key: &str) -> [f64; 3] {
    RobotChoice::from_key(key).map_or([1000.0, 0.0, 500.0], |c| {
        let w = Workspace::for_robot(c);
        [0, 1, 2].map(|i| f64::midpoint(w.min[i], w.max[i]))
    })
}

impl PlanForm {
    /// The engine's configuration; `session_hand_eye` is the open
    /// session's initial hand-eye, if any.
    ///
    /// # Errors
    /// An unknown preset, or the session hand-eye asked for but absent.
    pub fn config(&self, session_hand_eye: Option<Isometry3<f64>>) -> Result<PlanConfig, String> {
        let mut request = self.request.clone();
        request.robot = RobotSource::Preset(self.robot.clone());
        request.hand_eye = if self.hand_eye_from_session {
            Some(session_hand_eye.ok_or(
                "no hand-eye in the result on show or the open session: untick \"hand-eye guess from the open calibration\" to use the paper's initial one",
            )?)
        } else {
            None
        };
        request.config().map_err(|e| e.to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_match_the_cli_and_the_preset_workspace() {
        let f = PlanForm::default();
        assert_eq!(f.request.design.sphere, [1050.0, 0.0, 475.0]);
        let c = f.config(None).unwrap();
        assert_eq!(c.design.n_identify, 9);
        assert_eq!(c.design.seed, 1);
        assert!(f.config(Some(Isometry3::identity())).is_ok());
        let g = PlanForm {
            hand_eye_from_session: true,
            ..PlanForm::default()
        };
        assert!(g.config(None).unwrap_err().contains("no hand-eye"));
        let h = PlanForm {
            robot: "kr16".into(),
            ..PlanForm::default()
        };
        assert!(h.config(None).unwrap_err().contains("kr16"));
    }
}
