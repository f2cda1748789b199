//! View models built once, off the UI thread, from engine outputs: the
//! [`ResultView`] of a result (from a run or a reviewed file alike, both go
//! through the FORMAT.md [`ResultFile`]) and the [`CentreSet`] of the
//! centres view. The `*_ui` functions only draw them.

use std::collections::BTreeMap;
use std::path::PathBuf;

use nalgebra::Vector3;
use serde_json::Value;

use crate::engine::format::ResultFile;
use crate::engine::geometry::{isometry_from_rows, rotation_angle_between};
use crate::engine::robot::Joint;
use crate::engine::session::{Session, Use};
use crate::engine::validate::{BeforeAfter, DistanceRecord, Stats, within_station_distances};

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

/// The hand-eye `eT_s` in readable form.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HandEyeView {
    /// The 4×4 matrix (mm), row-major.
    pub rows: [[f64; 4]; 4],
    /// Translation, mm.
    pub translation: [f64; 3],
    /// Roll, pitch, yaw (rotations about x, y, z), deg.
    pub rpy_deg: [f64; 3],
}

impl HandEyeView {
    fn new(rows: &[[f64; 4]; 4]) -> Self {
        let rpy = isometry_from_rows(rows).map_or([0.0; 3], |iso| {
            let (r, p, y) = iso.rotation.euler_angles();
            [r.to_degrees(), p.to_degrees(), y.to_degrees()]
        });
        Self {
            rows: *rows,
            translation: [rows[0][3], rows[1][3], rows[2][3]],
            rpy_deg: rpy,
        }
    }
}

/// One within-station centre distance (true value 0; paper Fig. 5).
#[derive(Debug, Clone, PartialEq)]
pub struct PairDistance {
    /// Station id.
    pub station: String,
    /// Measurement ids of the pair.
    pub ids: (String, String),
    /// Distance with the nominal model and initial hand-eye, mm.
    pub before: f64,
    /// Distance with the calibrated model and hand-eye, mm.
    pub after: f64,
}

/// The headline figures: validation statistics before and after.
#[derive(Debug, Clone, PartialEq)]
pub struct Headline {
    /// What the statistics are of, e.g. "54 reference distances (measured − reference)".
    pub what: String,
    /// Before and after.
    pub stats: BeforeAfter,
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
    /// Per station (same order): mean before and mean after (or before), mm.
    pub means: Vec<([f64; 3], [f64; 3])>,
    /// A magnification of the deviations from the station means that
    /// makes the largest one about a quarter of the smallest distance
    /// between stations (1-2-5 steps, 1 to 1000).
    pub suggested_magnify: f32,
}

/// Largest deviation drawn, as a fraction of the closest station spacing.
const DEVIATION_SHARE: f64 = 0.25;

/// The largest 1-2-5 step at or below `x`, within 1..=1000.
fn step_125(x: f64) -> f32 {
    if !(x.is_finite() && x > 1.0) {
        return 1.0;
    }
    let x = x.min(1000.0);
    let decade = 10f64.powf(x.log10().floor());
    let m = x / decade;
    let step = if m >= 5.0 {
        5.0
    } else if m >= 2.0 {
        2.0
    } else {
        1.0
    };
    (step * decade) as f32
}

impl CentreSet {
    /// Groups `points` by station and computes the station means.
    #[must_use]
    pub fn new(points: Vec<CentrePoint>) -> Self {
        let mut stations: Vec<String> = Vec::new();
        for p in &points {
            if !stations.contains(&p.station) {
                stations.push(p.station.clone());
            }
        }
        let means: Vec<([f64; 3], [f64; 3])> = stations
            .iter()
            .map(|s| {
                let mine: Vec<&CentrePoint> = points.iter().filter(|p| p.station == *s).collect();
                let mean = |f: &dyn Fn(&CentrePoint) -> [f64; 3]| -> [f64; 3] {
                    let sum = mine.iter().fold(Vector3::zeros(), |acc: Vector3<f64>, p| {
                        acc + Vector3::from(f(p))
                    });
                    (sum / mine.len().max(1) as f64).into()
                };
                (mean(&|p| p.before), mean(&|p| p.after.unwrap_or(p.before)))
            })
            .collect();
        let dist = |a: &[f64; 3], b: &[f64; 3]| (Vector3::from(*a) - Vector3::from(*b)).norm();
        let mut spread = 0.0_f64;
        for p in &points {
            let (mb, ma) = means[stations.iter().position(|s| *s == p.station).unwrap_or(0)];
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
            means,
            suggested_magnify,
        }
    }

    /// Position of station `s` in [`CentreSet::stations`].
    #[must_use]
    pub fn station_index(&self, s: &str) -> usize {
        self.stations.iter().position(|x| x == s).unwrap_or(0)
    }
}

/// Everything the Results, Centres and export views show of one result.
#[derive(Debug, Clone, PartialEq)]
pub struct ResultView {
    /// The result file itself (what "Result JSON" exports).
    pub file: ResultFile,
    /// Run or review.
    pub origin: ResultOrigin,
    /// `solver.method`.
    pub method: String,
    /// `solver.stop_reason`, when given.
    pub stop_reason: Option<String>,
    /// `solver.threshold`, mm, when given.
    pub threshold: Option<f64>,
    /// ε after 0, 1, … updates, mm.
    pub epsilons: Vec<f64>,
    /// Singular values of the last update, descending.
    pub singular_values: Vec<f64>,
    /// `solver.svd_tolerance` (fraction of σ_max), when given.
    pub svd_tolerance: Option<f64>,
    /// `solver.kept_directions`, when given.
    pub kept: Option<usize>,
    /// `solver.dropped_directions`: the directions the SVD dropped.
    pub dropped: Vec<String>,
    /// `solver.fixed`: parameters a method held fixed.
    pub fixed: Vec<String>,
    /// `solver.estimated`: parameters a method estimated (when it says).
    pub estimated: Vec<String>,
    /// `solver.inseparable` and `solver.strong_correlations`: what the
    /// method says about parameters the data cannot tell apart.
    pub caveats: Vec<String>,
    /// Every entry of the `solver` block as text (values as compact JSON).
    pub solver_entries: Vec<(String, String)>,
    /// Parameter labels (`theta1`, `he_z`, …) not identifiable from this
    /// data, each with why.
    pub marked: BTreeMap<String, String>,
    /// Initial hand-eye.
    pub hand_eye_before: HandEyeView,
    /// Calibrated hand-eye.
    pub hand_eye_after: HandEyeView,
    /// Rotation between the two hand-eyes, deg.
    pub hand_eye_rotation_change_deg: f64,
    /// Calibrated minus nominal, per joint (deg, mm).
    pub joint_errors: Vec<Joint>,
    /// The headline figures, when the result has validation distances.
    pub headline: Option<Headline>,
    /// Within-station distances of the validate stations (or, without
    /// any, of the identify stations), station order then pair order.
    pub within: Vec<PairDistance>,
    /// Which stations `within` is of: "validate" or "identify".
    pub within_of: &'static str,
    /// Statistics of `within`.
    pub within_stats: BeforeAfter,
    /// Reference-distance comparisons (paper Fig. 6).
    pub distances: Vec<DistanceRecord>,
    /// Base-frame centres before and after.
    pub centres: CentreSet,
    /// Warnings: e.g. the result names another session.
    pub notes: Vec<String>,
}

impl ResultView {
    /// Builds the view of `file`, matched against the loaded `session`
    /// (when there is one) by measurement id.
    #[must_use]
    pub fn new(file: ResultFile, origin: ResultOrigin, session: Option<&Session>) -> Self {
        let solver = &file.solver;
        let text = |k: &str| solver.get(k).and_then(Value::as_str).map(str::to_string);
        let number = |k: &str| solver.get(k).and_then(Value::as_f64);
        let numbers = |k: &str| -> Vec<f64> {
            solver
                .get(k)
                .and_then(Value::as_array)
                .map(|a| a.iter().filter_map(Value::as_f64).collect())
                .unwrap_or_default()
        };
        let texts = |k: &str| -> Vec<String> {
            solver
                .get(k)
                .and_then(Value::as_array)
                .map(|a| {
                    a.iter()
                        .filter_map(|v| v.as_str().map(str::to_string))
                        .collect()
                })
                .unwrap_or_default()
        };
        let dropped = texts("dropped_directions");
        let fixed = texts("fixed");
        let marked = crate::engine::report::html::identifiability_marks(solver);
        let estimated = texts("estimated");
        let mut caveats = texts("inseparable");
        caveats.extend(
            texts("strong_correlations")
                .into_iter()
                .map(|c| format!("strongly correlated: {c}")),
        );
        let solver_entries = solver
            .iter()
            .map(|(k, v)| {
                let text = match v {
                    Value::String(t) => t.clone(),
                    other => other.to_string(),
                };
                (k.clone(), text)
            })
            .collect();

        let mut notes = Vec::new();
        let index_of = |id: &str| -> Option<usize> {
            session.and_then(|s| s.measurements.iter().position(|m| m.id == id))
        };
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
                usage: c.usage.clone(),
                index: index_of(&c.measurement),
                before: c.before,
                after: Some(c.after),
            })
            .collect();
        let (within, within_of) = {
            let validate = within_pairs(&points, Use::Validate);
            if validate.is_empty() {
                (within_pairs(&points, Use::Identify), "identify")
            } else {
                (validate, "validate")
            }
        };
        let within_stats = BeforeAfter {
            before: Stats::of(&within.iter().map(|p| p.before).collect::<Vec<_>>()),
            after: Stats::of(&within.iter().map(|p| p.after).collect::<Vec<_>>()),
        };
        let distances = file
            .validation
            .as_ref()
            .map(|v| v.distances.clone())
            .unwrap_or_default();
        let headline = match &file.validation {
            Some(v) if !v.distances.is_empty() => Some(Headline {
                what: format!(
                    "validation: {} reference distances (measured − reference)",
                    v.distances.len()
                ),
                stats: BeforeAfter {
                    before: v.before,
                    after: v.after,
                },
            }),
            Some(v) => Some(Headline {
                what: "validation: within-station centre distances".to_string(),
                stats: v.within_station,
            }),
            None => None,
        };
        let hand_eye_rotation_change_deg = match (
            isometry_from_rows(&file.hand_eye_initial),
            isometry_from_rows(&file.hand_eye),
        ) {
            (Ok(a), Ok(b)) => rotation_angle_between(&a, &b).to_degrees(),
            _ => 0.0,
        };
        Self {
            origin,
            method: text("method").unwrap_or_else(|| "?".to_string()),
            stop_reason: text("stop_reason"),
            threshold: number("threshold"),
            epsilons: file.iterations.iter().map(|r| r.epsilon).collect(),
            singular_values: numbers("singular_values"),
            svd_tolerance: number("svd_tolerance"),
            kept: solver
                .get("kept_directions")
                .and_then(Value::as_u64)
                .and_then(|k| usize::try_from(k).ok()),
            dropped,
            fixed,
            estimated,
            caveats,
            solver_entries,
            marked,
            hand_eye_before: HandEyeView::new(&file.hand_eye_initial),
            hand_eye_after: HandEyeView::new(&file.hand_eye),
            hand_eye_rotation_change_deg,
            joint_errors: file.joint_errors.clone(),
            headline,
            within,
            within_of,
            within_stats,
            distances,
            centres: CentreSet::new(points),
            notes,
            file,
        }
    }

    /// Whether parameter `label` (e.g. `theta2`) is marked not identifiable.
    #[must_use]
    pub fn is_marked(&self, label: &str) -> bool {
        self.marked.contains_key(label)
    }
}

/// Pairwise centre distances within each station of `usage`, in the
/// engine's order (station, then `i < j`), computed by the engine's
/// [`within_station_distances`].
fn within_pairs(points: &[CentrePoint], usage: Use) -> Vec<PairDistance> {
    let mut stations: Vec<(String, Vec<&CentrePoint>)> = Vec::new();
    for p in points.iter().filter(|p| p.usage == usage.as_str()) {
        if let Some(s) = stations.iter_mut().find(|(s, _)| *s == p.station) {
            s.1.push(p);
        } else {
            stations.push((p.station.clone(), vec![p]));
        }
    }
    let centres = |f: &dyn Fn(&CentrePoint) -> [f64; 3]| -> Vec<Vec<Vector3<f64>>> {
        stations
            .iter()
            .map(|(_, ps)| ps.iter().map(|p| Vector3::from(f(p))).collect())
            .collect()
    };
    let before = within_station_distances(&centres(&|p| p.before));
    let after = within_station_distances(&centres(&|p| p.after.unwrap_or(p.before)));
    let mut labels = Vec::new();
    for (station, ps) in &stations {
        for i in 0..ps.len() {
            for j in i + 1..ps.len() {
                labels.push((station.clone(), (ps[i].id.clone(), ps[j].id.clone())));
            }
        }
    }
    labels
        .into_iter()
        .zip(before.into_iter().zip(after))
        .map(|((station, ids), (before, after))| PairDistance {
            station,
            ids,
            before,
            after,
        })
        .collect()
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
