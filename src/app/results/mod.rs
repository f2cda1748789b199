//! The result on show: its view model, built once off the UI thread from
//! the engine's outputs (the [`ResultView`] of a run and of a reviewed
//! file alike, both the typed [`ResultFile`], around the engine's shared
//! [`result_view`](crate::engine::tools::result_view)), the
//! [`CentreSet`] of the Centres view, the views that draw them ([`ui`]
//! with its figures, sets, tables, range map and the way forward after a
//! FAIL; [`centres`]), the exports ([`export`]) and the readings of the
//! result on show and of the tolerance its verdict is judged by.

pub mod centres;
pub mod export;
mod fail;
mod figures;
mod fixed;
pub mod range_map;
mod sets;
mod tables;
pub mod ui;

pub use fail::{MAX_IDENTIFY_STATIONS, more_stations};

use std::collections::HashMap;
use std::path::PathBuf;

use nalgebra::Vector3;
use serde_json::Value;

use crate::engine::base::session::{Session, Use};
use crate::engine::files::format::ResultFile;
use crate::engine::files::format::result::solver_block;
use crate::engine::tools::result_view::{Tolerance, within_pairs};

use super::AppState;
use super::ledger::Reading;
pub use crate::engine::tools::result_view::{HandEyeView, ResultFigures as Shown};

/// Where a result on show came from.
#[derive(Debug, Clone, PartialEq)]
pub enum ResultOrigin {
    /// A run in this window.
    Run {
        /// Wall time of the run, s.
        seconds: f64,
        /// Measurements left out of the run.
        excluded: usize,
    },
    /// A result file opened for review (no solver run).
    Review(PathBuf),
}

/// One sphere centre in the base frame.
#[derive(Debug, Clone, PartialEq)]
pub struct CentrePoint {
    /// Measurement id.
    pub id: String,
    /// Station id.
    pub station: String,
    /// FORMAT.md use spelling.
    pub usage: String,
    /// Index into the loaded session's measurements, when it has this id.
    pub index: Option<usize>,
    /// Centre with the nominal model and initial hand-eye, mm, base frame.
    pub before: [f64; 3],
    /// Centre after calibration, mm, base frame (absent before a run).
    pub after: Option<[f64; 3]>,
}

/// The centres of the centres view, grouped by station.
#[derive(Debug, Clone, PartialEq)]
pub struct CentreSet {
    /// Every centre.
    pub points: Vec<CentrePoint>,
    /// Station ids in order of first appearance.
    pub stations: Vec<String>,
    /// The station of each point (index into `stations`), point order.
    pub station_of: Vec<usize>,
    /// Per station (same order): mean before and mean after (or before), mm.
    pub means: Vec<([f64; 3], [f64; 3])>,
    /// A magnification of the deviations from the station means that
    /// makes the largest one about a quarter of the smallest distance
    /// between stations (1-2-5 steps, 1 to 1000).
    pub suggested_magnify: f32,
    /// The largest distance of a centre from its station's mean (before
    /// or after), mm.
    pub largest_deviation: f64,
    /// Where each station is in `stations`.
    index: HashMap<String, usize>,
}

/// Largest deviation drawn, as a fraction of the closest station spacing.
const DEVIATION_SHARE: f64 = 0.25;

/// The largest 1-2-5 step at or below `x`, within 1..=1000.
fn step_125(x: f64) -> f32 {
    if !(x.is_finite() && x > 1.0) {
        return 1.0;
    }
    crate::engine::base::numeric::step_125_at_most(x.min(1000.0)) as f32
}

impl CentreSet {
    /// Groups `points` by station and computes the station means (one
    /// pass: 20,000 centres of 3,000 stations take milliseconds).
    #[must_use]
    pub fn new(points: Vec<CentrePoint>) -> Self {
        let mut stations: Vec<String> = Vec::new();
        let mut index: HashMap<String, usize> = HashMap::new();
        let mut station_of = Vec::with_capacity(points.len());
        for p in &points {
            let k = *index.entry(p.station.clone()).or_insert_with(|| {
                stations.push(p.station.clone());
                stations.len() - 1
            });
            station_of.push(k);
        }
        let mut sums = vec![(Vector3::zeros(), Vector3::zeros(), 0.0_f64); stations.len()];
        for (p, &k) in points.iter().zip(&station_of) {
            let (b, a, n) = &mut sums[k];
            *b += Vector3::from(p.before);
            *a += Vector3::from(p.after.unwrap_or(p.before));
            *n += 1.0;
        }
        let means: Vec<([f64; 3], [f64; 3])> = sums
            .iter()
            .map(|(b, a, n)| ((b / n.max(1.0)).into(), (a / n.max(1.0)).into()))
            .collect();
        let dist = |a: &[f64; 3], b: &[f64; 3]| (Vector3::from(*a) - Vector3::from(*b)).norm();
        let mut spread = 0.0_f64;
        for (p, &k) in points.iter().zip(&station_of) {
            let (mb, ma) = means[k];
            spread = spread.max(dist(&p.before, &mb));
            if let Some(a) = &p.after {
                spread = spread.max(dist(a, &ma));
            }
        }
        let mut separation = f64::INFINITY;
        for (i, a) in means.iter().enumerate() {
            for b in &means[i + 1..] {
                separation = separation.min(dist(&a.0, &b.0));
            }
        }
        let suggested_magnify = if spread > 0.0 && separation.is_finite() {
            step_125(DEVIATION_SHARE * separation / spread)
        } else {
            1.0
        };
        Self {
            points,
            stations,
            station_of,
            means,
            suggested_magnify,
            largest_deviation: spread,
            index,
        }
    }

    /// Position of station `s` in [`CentreSet::stations`] (0 when absent).
    #[must_use]
    pub fn station_index(&self, s: &str) -> usize {
        self.index.get(s).copied().unwrap_or(0)
    }
}

/// Mean, standard deviation and largest absolute value of a set of
/// errors, mm.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Summary {
    /// How many errors.
    pub n: usize,
    /// Mean (signed), mm.
    pub mean: f64,
    /// Sample standard deviation (divisor n − 1; 0 below two), mm.
    pub std: f64,
    /// Largest absolute error, mm.
    pub max: f64,
}

impl Summary {
    /// The summary of `errors` (zeros when empty).
    #[must_use]
    pub fn of(errors: &[f64]) -> Self {
        let n = errors.len();
        if n == 0 {
            return Self::default();
        }
        let stats = crate::engine::calibrate::validate::Stats::of(errors);
        Self {
            n,
            mean: errors.iter().sum::<f64>() / n as f64,
            std: stats.std,
            max: stats.max,
        }
    }
}

/// The name of the calibration set (the identify stations).
pub const CALIBRATION_SET: &str = "calibration (identify)";
/// The name of the validation set (the validate stations).
pub const VALIDATION_SET: &str = "validation (validate)";

/// One set of a result's errors, before and after calibration, mm: the
/// calibration set (identify stations) or the validation set (validate
/// stations, reference distances), for the table that sets them side by
/// side.
#[derive(Debug, Clone, PartialEq)]
pub struct ErrorSet {
    /// "calibration (identify)" or "validation (validate)".
    pub set: &'static str,
    /// What the errors are, e.g. "within-station distances, 9 stations".
    pub what: String,
    /// Whether the errors are within-station distances (true value 0,
    /// comparable between the sets) rather than signed reference errors.
    pub within: bool,
    /// Errors with the nominal model and initial hand-eye, mm.
    pub before: Vec<f64>,
    /// Errors after calibration, mm.
    pub after: Vec<f64>,
}

impl ErrorSet {
    /// The within-station distances of the stations of `usage`.
    fn within(file: &ResultFile, usage: Use, set: &'static str) -> Option<Self> {
        let pairs = within_pairs(&file.centres, usage);
        if pairs.is_empty() {
            return None;
        }
        let stations = pairs
            .iter()
            .map(|p| p.station.as_str())
            .collect::<std::collections::HashSet<_>>()
            .len();
        Some(Self {
            set,
            what: format!("within-station distances, {stations} stations"),
            within: true,
            before: pairs.iter().map(|p| p.before).collect(),
            after: pairs.iter().map(|p| p.after).collect(),
        })
    }

    /// Every set of `file`: calibration, validation within-station, and
    /// validation reference distances, those it has.
    #[must_use]
    pub fn all_of(file: &ResultFile, shown: &Shown) -> Vec<Self> {
        let mut out: Vec<Self> = [
            Self::within(file, Use::Identify, CALIBRATION_SET),
            Self::within(file, Use::Validate, VALIDATION_SET),
        ]
        .into_iter()
        .flatten()
        .collect();
        if !shown.distances.is_empty() {
            out.push(Self {
                set: VALIDATION_SET,
                what: "reference distances, measured − reference".to_string(),
                within: false,
                before: shown
                    .distances
                    .iter()
                    .map(super::super::engine::calibrate::validate::DistanceRecord::error_before)
                    .collect(),
                after: shown
                    .distances
                    .iter()
                    .map(super::super::engine::calibrate::validate::DistanceRecord::error_after)
                    .collect(),
            });
        }
        out
    }
}

/// Everything the Results, Centres and export views show of one result.
#[derive(Debug, Clone, PartialEq)]
pub struct ResultView {
    /// The result itself (what "Result JSON" exports).
    pub file: ResultFile,
    /// Run or review.
    pub origin: ResultOrigin,
    /// What every reader shows: headline, pairs, hand-eye, marks, σ.
    pub shown: Shown,
    /// `solver.method`.
    pub method: String,
    /// Why the loop stopped, when the method says.
    pub stop_reason: Option<String>,
    /// The threshold on ε, mm, when the method says.
    pub threshold: Option<f64>,
    /// ε after 0, 1, … updates, mm.
    pub epsilons: Vec<f64>,
    /// Singular values of the last update, descending (paper's method).
    pub singular_values: Vec<f64>,
    /// SVD tolerance (fraction of σ_max), when given.
    pub svd_tolerance: Option<f64>,
    /// SVD directions kept, when given.
    pub kept: Option<usize>,
    /// The directions the SVD dropped.
    pub dropped: Vec<String>,
    /// Parameters a method held fixed.
    pub fixed: Vec<String>,
    /// Parameters a method estimated (when it says).
    pub estimated: Vec<String>,
    /// What the method says about parameters the data cannot tell apart.
    pub caveats: Vec<String>,
    /// Every entry of the `solver` block as written (values as compact JSON).
    pub solver_entries: Vec<(String, String)>,
    /// Base-frame centres before and after.
    pub centres: CentreSet,
    /// Warnings: e.g. the result names another session.
    pub notes: Vec<String>,
    /// For a result that calibrated the hand-eye only (a pose-only
    /// session): what was and was not identified, and how well.
    pub hand_eye_only: Option<Vec<String>>,
    /// The calibration set's and the validation set's errors.
    pub sets: Vec<ErrorSet>,
}

impl ResultView {
    /// Builds the view of `file`, matched against the loaded `session`
    /// (when there is one) by measurement id.
    #[must_use]
    pub fn new(file: ResultFile, origin: ResultOrigin, session: Option<&Session>) -> Self {
        let solver = &file.solver;
        let paper = solver.paper();
        let mut caveats: Vec<String> = solver
            .ml()
            .map(|m| m.inseparable.iter().map(ToString::to_string).collect())
            .unwrap_or_default();
        caveats.extend(
            solver
                .ml()
                .iter()
                .flat_map(|m| &m.strong_correlations)
                .map(|c| format!("strongly correlated: {c}")),
        );
        let solver_entries = solver_block(solver)
            .into_iter()
            .map(|(k, v)| {
                let text = match v {
                    Value::String(t) => t,
                    other => other.to_string(),
                };
                (k, text)
            })
            .collect();

        let mut notes = Vec::new();
        let ids = session.map(crate::engine::tools::result_view::measurement_index);
        let index_of =
            |id: &str| -> Option<usize> { ids.as_ref().and_then(|m| m.get(id).copied()) };
        if let Some(s) = session {
            if s.name != file.session {
                notes.push(format!(
                    "the result was computed from session \"{}\", the open session is \"{}\"",
                    file.session, s.name
                ));
            }
            let missing = file
                .centres
                .iter()
                .filter(|c| index_of(&c.measurement).is_none())
                .count();
            if missing > 0 {
                notes.push(format!(
                    "{missing} of the result's {} measurements are not in the open session",
                    file.centres.len()
                ));
            }
        } else if matches!(origin, ResultOrigin::Review(_)) {
            notes.push("no session is open: the Session and Stripe views are empty".to_string());
        }

        let points: Vec<CentrePoint> = file
            .centres
            .iter()
            .map(|c| CentrePoint {
                id: c.measurement.clone(),
                station: c.station.clone(),
                usage: c.usage.as_str().to_string(),
                index: index_of(&c.measurement),
                before: c.before,
                after: Some(c.after),
            })
            .collect();
        let shown = Shown::new(&file);
        Self {
            origin,
            sets: ErrorSet::all_of(&file, &shown),
            shown,
            method: solver.method().to_string(),
            stop_reason: solver.stop_reason().map(str::to_string),
            threshold: solver.threshold(),
            epsilons: file.iterations.iter().map(|r| r.epsilon).collect(),
            singular_values: paper
                .and_then(|p| p.singular_values.clone())
                .unwrap_or_default(),
            svd_tolerance: paper.and_then(|p| p.svd_tolerance),
            kept: paper.and_then(|p| p.kept_directions),
            dropped: paper
                .and_then(|p| p.dropped_directions.as_ref())
                .map(|d| d.iter().map(ToString::to_string).collect())
                .unwrap_or_default(),
            fixed: solver.fixed().to_vec(),
            estimated: solver.estimated().to_vec(),
            caveats,
            solver_entries,
            centres: CentreSet::new(points),
            notes,
            hand_eye_only: crate::engine::tools::result_view::hand_eye_only_lines(&file, session),
            file,
        }
    }
}

/// The camera of the 3D centres view (orthographic, orbiting the centres).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Rotation about the base z axis, rad.
    pub yaw: f32,
    /// Elevation above the base xy plane, rad.
    pub pitch: f32,
    /// Zoom factor (1 = fit all).
    pub zoom: f32,
}

impl Default for Camera {
    fn default() -> Self {
        Self {
            yaw: -0.6,
            pitch: 0.5,
            zoom: 1.0,
        }
    }
}

/// Display options of the centres view.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CentresForm {
    /// Draw the centres before calibration.
    pub show_before: bool,
    /// Draw the centres after calibration.
    pub show_after: bool,
    /// Draw each centre's deviation from its station mean magnified by
    /// `magnify`, placed at the station mean.
    pub relative: bool,
    /// Magnification of the deviations in relative mode.
    pub magnify: f32,
    /// The orbit camera.
    pub camera: Camera,
}

impl Default for CentresForm {
    fn default() -> Self {
        Self {
            show_before: true,
            show_after: true,
            relative: true,
            magnify: 50.0,
            camera: Camera::default(),
        }
    }
}

/// The acceptance tolerance.
#[must_use]
pub fn tolerance(t: &Tolerance) -> Reading {
    Reading::new(
        vec![
            ("std ≤".into(), format!("{:.3} mm", t.std_mm)),
            ("max ≤".into(), format!("{:.3} mm", t.max_mm)),
        ],
        (t.std_mm.to_bits(), t.max_mm.to_bits()),
    )
}

/// The calibration result on show: which one (the how-many-th shown in
/// this window, where it came from, its method); a new run or a result
/// opened reads otherwise even with the same numbers.
#[must_use]
pub fn calibration(state: &AppState) -> Reading {
    let text = match &state.result {
        None => "none".to_string(),
        Some(r) => match &r.origin {
            ResultOrigin::Run { .. } => {
                format!("run #{} ({})", state.results_shown, r.method)
            }
            ResultOrigin::Review(p) => format!(
                "{} (#{}, {})",
                p.file_name().map_or_else(
                    || p.display().to_string(),
                    |n| n.to_string_lossy().into_owned()
                ),
                state.results_shown,
                r.method
            ),
        },
    };
    Reading::new(
        vec![("result".into(), text)],
        (state.result.is_some(), state.results_shown),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn magnification_steps() {
        assert!((step_125(0.3) - 1.0).abs() < 1e-6);
        assert!((step_125(7.9) - 5.0).abs() < 1e-6);
        assert!((step_125(23.0) - 20.0).abs() < 1e-6);
        assert!((step_125(1e9) - 1000.0).abs() < 1e-3);
    }
}
