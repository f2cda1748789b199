//! The planning use case in one entry, [`plan_and_predict`], that `spherecal
//! plan` and the workbench's Plan view both call: the poses planned
//! ([`plan`](super::plan)) and, when asked, the plan's accuracy predicted
//! by simulated calibrations ([`predict`](super::predict)), with the
//! progress of both and the plan told as soon as it is made (the command
//! line prints its summary before the prediction runs).

use super::{Plan, PlanConfig, PlanError, PlanStage, PredictConfig, Prediction, plan, predict};
use crate::engine::calibrate::solve::Control;

/// How far a plan is.
#[derive(Debug, Clone, Copy)]
pub enum PlanProgress<'a> {
    /// A stage of the planner.
    Stage(PlanStage),
    /// The plan is made; the prediction (when asked) comes next.
    Planned(&'a Plan),
    /// `done` of `of` simulated calibrations of the prediction.
    Predicting {
        /// Calibrations done.
        done: usize,
        /// Calibrations in all.
        of: usize,
    },
}

/// A plan and its predicted accuracy.
#[derive(Debug, Clone)]
pub struct Planned {
    /// The plan.
    pub plan: Box<Plan>,
    /// The predicted accuracy, when asked for, or why it failed.
    pub prediction: Option<Result<Prediction, PlanError>>,
}

/// Plans `config` and, with `prediction`, predicts the plan's accuracy,
/// telling `progress` each stage; it may cancel. A failed prediction is
/// not an error (the plan comes with the reason), a cancelled one is.
///
/// # Errors
/// The planner's error; [`PlanError::Cancelled`] after a cancel, also
/// during the prediction.
pub fn plan_and_predict(
    config: &PlanConfig,
    prediction: Option<&PredictConfig>,
    progress: &mut dyn FnMut(PlanProgress<'_>) -> Control,
) -> Result<Planned, PlanError> {
    let made = plan(config, &mut |stage| progress(PlanProgress::Stage(stage)))?;
    if progress(PlanProgress::Planned(&made)) == Control::Cancel {
        return Err(PlanError::Cancelled);
    }
    let prediction = prediction.map(|p| {
        predict(&made, p, &mut |done, of| {
            progress(PlanProgress::Predicting { done, of })
        })
    });
    if let Some(Err(PlanError::Cancelled)) = prediction {
        return Err(PlanError::Cancelled);
    }
    Ok(Planned {
        plan: Box::new(made),
        prediction,
    })
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;
    use crate::engine::base::robot;

    /// The paper's cell scaled down so that a debug build plans it fast.
    fn small() -> PlanConfig {
        let mut c = PlanConfig::for_preset(&robot::irb2400(), [1050.0, 0.0, 475.0]);
        c.design.n_identify = 4;
        c.design.identify_poses = 6;
        c.design.n_validate = 4;
        c.design.validate_poses = 4;
        c.design.candidates = 8;
        c
    }

    #[test]
    fn the_plan_is_told_before_its_prediction_and_is_the_planners() {
        let config = small();
        let predict = PredictConfig {
            runs: 1,
            ..PredictConfig::default()
        };
        let mut told = Vec::new();
        let planned = plan_and_predict(&config, Some(&predict), &mut |p| {
            told.push(match p {
                PlanProgress::Stage(_) => 's',
                PlanProgress::Planned(_) => 'p',
                PlanProgress::Predicting { .. } => 'r',
            });
            Control::Continue
        })
        .unwrap();
        let order: String = told.into_iter().collect();
        assert!(order.starts_with('s'), "{order}");
        assert_eq!(order.matches('p').count(), 1, "{order}");
        assert!(
            order.ends_with('r') && order.find('p') < order.find('r'),
            "{order}"
        );
        let alone = plan(&config, &mut |_| Control::Continue).unwrap();
        assert_eq!(
            planned.plan.poses, alone.poses,
            "the same plan as the planner's"
        );
        assert!(matches!(planned.prediction, Some(Ok(ref p)) if p.runs.len() == 1));
    }

    #[test]
    fn a_cancel_while_predicting_is_an_error_and_no_prediction_is_none() {
        let config = small();
        let predict = PredictConfig {
            runs: 2,
            ..PredictConfig::default()
        };
        let cancelled = plan_and_predict(&config, Some(&predict), &mut |p| match p {
            PlanProgress::Predicting { .. } => Control::Cancel,
            _ => Control::Continue,
        });
        assert!(matches!(cancelled, Err(PlanError::Cancelled)));
        let alone = plan_and_predict(&config, None, &mut |_| Control::Continue).unwrap();
        assert!(alone.prediction.is_none());
    }
}
