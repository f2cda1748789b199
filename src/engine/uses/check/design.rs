//! How `plan --check` chooses its poses ([`choose_check_design`]): a few
//! layouts of a quick check (one, two or three sphere positions, the
//! default approach cone or a wide one, at most [`MAX_CHECK_POSES`] poses)
//! are planned, each judged by the smallest changes it detects
//! ([`plan_check`]) against the knocks a check must see (a 0.3 mm shift
//! and a 0.1° turn of the sensor, 3σ of each estimated kinematic
//! parameter), and the one that detects the most is kept.
//!
//! Some knocks are below what any check can see: a change is judged
//! against the calibration's own uncertainty, so a turn about the flange
//! axis (along which the sensor looks: its effect is the sensor's small
//! lateral offset times the angle) or a parameter known to a σ the
//! check cannot beat stays undetected whatever the poses (the guide's
//! study gives the figures).

use super::{CheckError, check_design, plan_check};
use crate::engine::calibrate::solve::Control;
use crate::engine::calibrate::solve::ml::recheck::Detectable;
use crate::engine::files::format::ResultFile;
use crate::engine::tools::plan::{self, DEFAULT_CONE_DEG, Plan, PlanConfig, StationLayout};

/// Most poses of a planned check, the import's five included: a few
/// minutes at the robot.
pub const MAX_CHECK_POSES: usize = 30;

/// Most sphere positions of a planned check.
pub const MAX_CHECK_STATIONS: usize = 3;

/// The wide approach cone a check may use, deg: more wrist and arm
/// motion at one sphere position shows the arm's parameters better.
pub const WIDE_CONE_DEG: f64 = 70.0;

/// The time the operator's estimate counts for one pose (move, settle,
/// scan), s.
pub const SECONDS_PER_POSE: f64 = 20.0;

/// The time it counts for moving the sphere to another position, s.
pub const SECONDS_PER_SPHERE_MOVE: f64 = 120.0;

/// The knocks a check is judged on: a shift of the sensor, mm.
pub const TARGET_SHIFT_MM: f64 = 0.3;

/// … a turn of the sensor on its mount, deg.
pub const TARGET_TURN_DEG: f64 = 0.1;

/// … a drift of a kinematic parameter, in σ of the calibration.
pub const TARGET_PARAMETER_SIGMA: f64 = 3.0;

/// A chosen check.
#[derive(Debug, Clone)]
pub struct CheckChoice {
    /// The configuration of the chosen check (plan it again for the poses).
    pub config: PlanConfig,
    /// Its plan.
    pub plan: Plan,
    /// What it detects.
    pub detectable: Detectable,
    /// Sphere positions.
    pub stations: usize,
    /// The operator's time, minutes ([`SECONDS_PER_POSE`],
    /// [`SECONDS_PER_SPHERE_MOVE`]).
    pub minutes: f64,
}

/// The operator's time of a check of `poses` poses at `stations` sphere
/// positions, minutes.
#[must_use]
pub fn check_minutes(poses: usize, stations: usize) -> f64 {
    (poses as f64 * SECONDS_PER_POSE + stations.saturating_sub(1) as f64 * SECONDS_PER_SPHERE_MOVE)
        / 60.0
}

/// The extra sphere positions of a check about `sphere`, inside the
/// station box of the plan (or a 300 mm one).
fn extra_positions(config: &PlanConfig) -> [[f64; 3]; 2] {
    let size = match &config.stations {
        StationLayout::Box { size } => *size,
        StationLayout::Explicit { .. } => plan::DEFAULT_BOX_MM,
    };
    let s = config.design.sphere;
    [
        [
            s[0] - 0.375 * size[0],
            s[1] + 0.5 * size[1],
            s[2] - 0.39 * size[2],
        ],
        [
            s[0] + 0.25 * size[0],
            s[1] - 0.5 * size[1],
            s[2] + 0.5 * size[2],
        ],
    ]
}

/// How far a check is from seeing every target knock: the mean log of
/// detectable size over target (0 when it sees each exactly at target).
fn shortfall(d: &Detectable) -> f64 {
    let mut terms = vec![
        (d.translation_mm / TARGET_SHIFT_MM).ln(),
        (d.rotation_deg / TARGET_TURN_DEG).ln(),
    ];
    let params: Vec<f64> = d
        .parameters
        .iter()
        .filter_map(|(_, _, s)| *s)
        .filter(|s| s.is_finite() && *s > 0.0)
        .map(|s| (s / TARGET_PARAMETER_SIGMA).ln())
        .collect();
    if !params.is_empty() {
        terms.push(params.iter().sum::<f64>() / params.len() as f64);
    }
    terms.iter().sum::<f64>() / terms.len() as f64
}

/// Chooses the check's layout (module doc) and sets `config` to it;
/// `poses`, when given, is the poses per sphere position (else the most
/// that keep the check within [`MAX_CHECK_POSES`]).
///
/// # Errors
/// [`CheckError::Input`] when no layout can be planned (the last
/// planner's error), or what [`plan_check`] refuses.
pub fn choose_check_design(
    config: &mut PlanConfig,
    result: &ResultFile,
    poses: Option<usize>,
) -> Result<CheckChoice, CheckError> {
    let extra = extra_positions(config);
    let fixed = super::CHECK_TRANSLATIONS + super::CHECK_ROTATIONS;
    let mut best: Option<(f64, CheckChoice)> = None;
    let mut last_error = None;
    for stations in 1..=MAX_CHECK_STATIONS {
        let per_station = poses.unwrap_or((MAX_CHECK_POSES - fixed) / stations).max(2);
        for cone in [DEFAULT_CONE_DEG.max(config.cone_angle), WIDE_CONE_DEG] {
            let mut c = config.clone();
            check_design(&mut c, result, per_station);
            let mut identify = vec![c.design.sphere];
            identify.extend(extra.iter().take(stations - 1));
            c.design.n_identify = identify.len();
            c.stations = StationLayout::Explicit {
                identify,
                validate: Vec::new(),
            };
            c.cone_angle = cone;
            let made = match plan::plan(&c, &mut |_| Control::Continue) {
                Ok(p) => p,
                Err(e) => {
                    last_error = Some(e.to_string());
                    continue;
                }
            };
            let d = plan_check(&made, result, c.stripe_sigma, super::DEFAULT_ALPHA)?;
            // A sphere move costs time: a layout with more positions must
            // do clearly better (5 % in size per move).
            let score = shortfall(&d) + 0.05 * (stations - 1) as f64;
            if best.as_ref().is_none_or(|(s, _)| score < *s) {
                let minutes = check_minutes(made.poses.len(), stations);
                best = Some((
                    score,
                    CheckChoice {
                        config: c,
                        plan: made,
                        detectable: d,
                        stations,
                        minutes,
                    },
                ));
            }
        }
    }
    let (_, choice) = best.ok_or_else(|| {
        CheckError::Input(format!(
            "no check could be planned about the sphere: {}",
            last_error.unwrap_or_default()
        ))
    })?;
    *config = choice.config.clone();
    Ok(choice)
}
