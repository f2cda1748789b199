//! The evidence that spreading the sphere over the sensor's range pays
//! (issue 14, `spherecal evaluate --planned-range`): the default IRB 2400
//! cell planned for an 80 × 80 mm range twice, with the spread and
//! without it (the same seed, the sphere at the paper's spot, `ln det`),
//! each plan simulated on true robots with Table 1 and with random
//! kinematic errors (seeds `1..=N`), calibrated with `ml` and scored over
//! the range against the truth ([`range_score`](crate::engine::tools::evaluate::range::range_score)):
//! predicted (from `ml`'s covariance at planning) and realised, against
//! the floor. The poses are touched up on the true robot (Table 1 errors
//! move the cut out of the usable band at some planned joints; an
//! operator jogs until the stripe is seen).

use std::fmt::Write as _;

use crate::engine::base::robot;
use crate::engine::calibrate::solve::Control;
use crate::engine::tools::plan::{self, PlanConfig, PlanError, PredictConfig};
use crate::engine::tools::simulate::{ErrorModel, PlanExecution};

use crate::engine::tools::evaluate::study::STUDY_RANGE;

/// The sphere position of the study's cell (the README's plan example).
pub const STUDY_SPHERE: [f64; 3] = [1050.0, 0.0, 475.0];

/// One row: a plan (with or without the spread) on one error model.
#[derive(Debug, Clone, PartialEq)]
pub struct PlannedRangeRow {
    /// Whether the plan spreads the sphere over the range.
    pub spread: bool,
    /// `table1` or `random`.
    pub errors: &'static str,
    /// `ml`'s predicted rms error over the range at planning, mm.
    pub predicted_rms: f64,
    /// Realised rms model error (calibrated against true model at the same
    /// readings), mean over the seeds, mm: what the prediction estimates.
    pub model_rms: f64,
    /// Realised rms error against the truth, mean over the seeds, mm.
    pub after_rms: f64,
    /// Its floor (the true model on the same readings), mm.
    pub floor_rms: f64,
    /// Mean of `after / floor` over the seeds.
    pub ratio: f64,
    /// Largest error after calibration in any seed, mm.
    pub after_max: f64,
    /// Validation std after / floor (the centre distances), mean.
    pub validation_ratio: f64,
}

/// Runs the study over seeds `1..=seeds`.
///
/// # Errors
/// A plan or a simulated calibration that fails.
pub fn planned_range_study(seeds: u64) -> Result<Vec<PlannedRangeRow>, PlanError> {
    let preset = robot::preset("irb2400")
        .ok_or_else(|| PlanError::InvalidConfig("no irb2400 preset".to_owned()))?;
    let mut rows = Vec::new();
    for spread in [true, false] {
        let config = PlanConfig {
            range: Some(STUDY_RANGE),
            spread,
            ..PlanConfig::for_preset(&preset, STUDY_SPHERE)
        };
        let made = plan::plan(&config, &mut |_| Control::Continue)?;
        let predicted_rms = made
            .stats
            .range_error
            .as_ref()
            .map_or(f64::NAN, |r| r.rms_mm);
        for (errors, model) in [
            ("table1", ErrorModel::Table1),
            ("random", ErrorModel::Random),
        ] {
            let predict = PredictConfig {
                runs: usize::try_from(seeds).unwrap_or(usize::MAX),
                seed: 1,
                errors: model,
                // Table 1 errors move the cut out of the usable band at
                // some planned joints: touched up, as an operator would.
                execution: PlanExecution::TouchUp,
                ..PredictConfig::default()
            };
            let p = plan::predict(&made, &predict, &mut |_, _| Control::Continue)?;
            let Some(r) = p.range else {
                return Err(PlanError::InvalidConfig(
                    "the simulated plan has no range to score".to_owned(),
                ));
            };
            rows.push(PlannedRangeRow {
                spread,
                errors,
                predicted_rms,
                model_rms: r.model_rms,
                after_rms: r.after_rms,
                floor_rms: r.floor_rms,
                ratio: r.ratio_mean,
                after_max: r.after_max,
                validation_ratio: p.ratio_mean,
            });
        }
    }
    Ok(rows)
}

/// The README table (Markdown).
#[must_use]
pub fn planned_range_markdown(rows: &[PlannedRangeRow], seeds: u64) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "| plan | errors ({seeds} seeds) | predicted rms, mm | realised model rms, mm | rms vs truth, mm | floor, mm | after / floor | max, mm | validation std / floor |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|");
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} | {:.4} | {:.4} | {:.4} | {:.4} | {:.2} | {:.3} | {:.2} |",
            if r.spread {
                "sphere spread over the range"
            } else {
                "sphere at one spot"
            },
            r.errors,
            r.predicted_rms,
            r.model_rms,
            r.after_rms,
            r.floor_rms,
            r.ratio,
            r.after_max,
            r.validation_ratio
        );
    }
    s
}

/// The text report.
#[must_use]
pub fn planned_range_text(rows: &[PlannedRangeRow], seeds: u64) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "error over an 80 × 80 mm range, IRB 2400 cell planned at {STUDY_SPHERE:?}, ml, seeds 1..={seeds} (mean)"
    );
    for r in rows {
        let _ = writeln!(
            s,
            "  {:<7} {:<6} predicted {:.4} mm, realised model {:.4} mm; vs truth {:.4} mm (max {:.3}), floor {:.4} mm: {:.2}× floor; validation {:.2}× floor",
            if r.spread { "spread" } else { "spot" },
            r.errors,
            r.predicted_rms,
            r.model_rms,
            r.after_rms,
            r.after_max,
            r.floor_rms,
            r.ratio,
            r.validation_ratio
        );
    }
    s
}
