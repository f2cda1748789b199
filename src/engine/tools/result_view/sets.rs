//! The sets a result's readers draw: the sphere centres grouped by
//! station with each station's mean and the magnification that makes
//! their deviations visible ([`CentreSet`], the workbench's Centres view
//! and its Session view before a run), and the calibration and validation
//! sets of errors before and after calibration with their summaries
//! ([`ErrorSet`], [`Summary`]).

use std::collections::{HashMap, HashSet};

use nalgebra::Vector3;

use super::within_pairs;
use crate::engine::base::numeric::step_125_at_most;
use crate::engine::base::session::Use;
use crate::engine::calibrate::validate::{DistanceRecord, Stats};
use crate::engine::files::format::result::CentreRecord;

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
    step_125_at_most(x.min(1000.0)) as f32
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
        let stats = Stats::of(errors);
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
    fn within(centres: &[CentreRecord], usage: Use, set: &'static str) -> Option<Self> {
        let pairs = within_pairs(centres, usage);
        if pairs.is_empty() {
            return None;
        }
        let stations = pairs
            .iter()
            .map(|p| p.station.as_str())
            .collect::<HashSet<_>>()
            .len();
        Some(Self {
            set,
            what: format!("within-station distances, {stations} stations"),
            within: true,
            before: pairs.iter().map(|p| p.before).collect(),
            after: pairs.iter().map(|p| p.after).collect(),
        })
    }

    /// Every set of a result's `centres` and reference `distances`:
    /// calibration, validation within-station, and validation reference
    /// distances, those it has.
    #[must_use]
    pub fn all_of(centres: &[CentreRecord], distances: &[DistanceRecord]) -> Vec<Self> {
        let mut out: Vec<Self> = [
            Self::within(centres, Use::Identify, CALIBRATION_SET),
            Self::within(centres, Use::Validate, VALIDATION_SET),
        ]
        .into_iter()
        .flatten()
        .collect();
        if !distances.is_empty() {
            out.push(Self {
                set: VALIDATION_SET,
                what: "reference distances, measured − reference".to_string(),
                within: false,
                before: distances.iter().map(DistanceRecord::error_before).collect(),
                after: distances.iter().map(DistanceRecord::error_after).collect(),
            });
        }
        out
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn magnification_steps() {
        assert!((step_125(0.3) - 1.0).abs() < 1e-6);
        assert!((step_125(7.9) - 5.0).abs() < 1e-6);
        assert!((step_125(23.0) - 20.0).abs() < 1e-6);
        assert!((step_125(1e9) - 1000.0).abs() < 1e-3);
    }

    fn centre(
        id: &str,
        station: &str,
        usage: Use,
        before: [f64; 3],
        after: [f64; 3],
    ) -> CentreRecord {
        CentreRecord {
            measurement: id.into(),
            station: station.into(),
            usage,
            sensor: [0.0; 3],
            before,
            after,
        }
    }

    #[test]
    fn centres_are_grouped_by_station_with_their_means_and_a_magnification() {
        let point =
            |id: &str, station: &str, before: [f64; 3], after: Option<[f64; 3]>| CentrePoint {
                id: id.into(),
                station: station.into(),
                usage: "identify".into(),
                index: None,
                before,
                after,
            };
        let set = CentreSet::new(vec![
            point("a", "P1", [0.0, 0.0, 0.0], Some([0.0, 0.0, 0.0])),
            point("b", "P2", [1000.0, 0.0, 0.0], None),
            point("c", "P1", [0.2, 0.0, 0.0], Some([0.02, 0.0, 0.0])),
        ]);
        assert_eq!(set.stations, ["P1", "P2"]);
        assert_eq!(set.station_of, [0, 1, 0]);
        assert_eq!(set.station_index("P2"), 1);
        assert_eq!(set.station_index("none"), 0);
        // P1's mean before (0.1, 0, 0), after (0.01, 0, 0); P2 has no
        // after: its before stands in.
        assert!((set.means[0].0[0] - 0.1).abs() < 1e-12);
        assert!((set.means[0].1[0] - 0.01).abs() < 1e-12);
        assert_eq!(set.means[1].1, [1000.0, 0.0, 0.0]);
        // Largest deviation 0.1 mm; stations 999.9 mm apart: a quarter of
        // that is 2500 × the deviation, capped at 1000.
        assert!((set.largest_deviation - 0.1).abs() < 1e-12);
        assert!((set.suggested_magnify - 1000.0).abs() < 1e-3);
    }

    #[test]
    fn error_sets_are_the_within_station_distances_and_the_reference_errors() {
        let centres = [
            centre("a", "P1", Use::Identify, [0.0; 3], [0.0; 3]),
            centre("b", "P1", Use::Identify, [0.3, 0.0, 0.0], [0.0, 0.04, 0.0]),
            centre("c", "V1", Use::Validate, [0.0; 3], [0.0; 3]),
            centre("d", "V1", Use::Validate, [0.0, 0.0, 0.5], [0.0, 0.0, 0.1]),
            centre("e", "V2", Use::Validate, [9.0; 3], [9.0; 3]),
        ];
        let distance = DistanceRecord {
            from: "V1".into(),
            to: "V2".into(),
            pose: 0,
            reference: 100.0,
            before: 100.5,
            after: 99.9,
        };
        let sets = ErrorSet::all_of(&centres, std::slice::from_ref(&distance));
        assert_eq!(sets.len(), 3);
        assert_eq!(sets[0].set, CALIBRATION_SET);
        assert_eq!(sets[0].what, "within-station distances, 1 stations");
        assert!((sets[0].before[0] - 0.3).abs() < 1e-12);
        assert!((sets[0].after[0] - 0.04).abs() < 1e-12);
        assert_eq!(sets[1].set, VALIDATION_SET);
        assert!(sets[1].within && !sets[2].within);
        assert!((sets[2].before[0] - 0.5).abs() < 1e-9);
        assert!((sets[2].after[0] + 0.1).abs() < 1e-9);
        assert!(
            ErrorSet::all_of(&centres[..1], &[]).is_empty(),
            "one centre: no pair"
        );
        let s = Summary::of(&[1.0, -3.0]);
        assert_eq!((s.n, s.mean, s.max), (2, -1.0, 3.0));
        assert!((s.std - 8.0_f64.sqrt()).abs() < 1e-12);
        assert_eq!(Summary::of(&[]), Summary::default());
    }
}
