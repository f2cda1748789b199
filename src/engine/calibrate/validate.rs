//! The paper's figures of merit: ε (eq. 20, pooled over stations as
//! FORMAT.md defines it), the statistics of an error list, the reference
//! (laser-tracker) distance errors of section 4.3 / Fig. 6 and the
//! within-station centre distances of Fig. 5.

pub use crate::engine::base::records::validation::{
    BeforeAfter, DistanceRecord, Stats, Validation,
};
use crate::engine::base::session::ReferenceDistance;
use nalgebra::Vector3;

/// The scatter of the centres about their station's mean: the RMS of
/// the 3-D deviations `|X_i − mean_s|` over every centre of every station
/// with at least two, mm (0 without any). For one station it is what a
/// hand-eye-only calibration is judged by.
#[must_use]
pub fn scatter_rms(stations: &[Vec<Vector3<f64>>]) -> f64 {
    let mut sum = 0.0;
    let mut n = 0usize;
    for centres in stations.iter().filter(|c| c.len() >= 2) {
        let mean = centres.iter().sum::<Vector3<f64>>() / centres.len() as f64;
        sum += centres
            .iter()
            .map(|c| (c - mean).norm_squared())
            .sum::<f64>();
        n += centres.len();
    }
    if n == 0 { 0.0 } else { (sum / n as f64).sqrt() }
}

/// Paper eq. 20 pooled over stations (FORMAT.md "The iteration"): over all
/// stations and all pairs `i < j` within a station, with `N` pairs,
/// `ε = sqrt(Σ |X_i − X_j|² / (N − 1))`, mm.
///
/// `stations` holds the base-frame centres of each station. With a single
/// pair (`N = 1`) the divisor `N − 1` would be zero; the divisor is then 1
/// (ε is the one distance), and with no pair ε is 0.
#[must_use]
pub fn epsilon(stations: &[Vec<Vector3<f64>>]) -> f64 {
    let mut sum = 0.0;
    let mut pairs = 0_usize;
    for centres in stations {
        for i in 0..centres.len() {
            for j in i + 1..centres.len() {
                sum += (centres[i] - centres[j]).norm_squared();
                pairs += 1;
            }
        }
    }
    if pairs == 0 {
        return 0.0;
    }
    (sum / (pairs.saturating_sub(1).max(1)) as f64).sqrt()
}

/// Every pairwise distance between centres of one station (true value 0),
/// all stations pooled, in station order then `i < j`, mm (paper Fig. 5).
#[must_use]
pub fn within_station_distances(stations: &[Vec<Vector3<f64>>]) -> Vec<f64> {
    let mut out = Vec::new();
    for centres in stations {
        for i in 0..centres.len() {
            for j in i + 1..centres.len() {
                out.push((centres[i] - centres[j]).norm());
            }
        }
    }
    out
}

/// Base-frame centres of one validate station, before and after.
#[derive(Debug, Clone, PartialEq)]
pub struct StationCentres {
    /// Station id.
    pub station: String,
    /// Centres with the nominal model and initial hand-eye, file order, mm.
    pub before: Vec<Vector3<f64>>,
    /// Centres with the calibrated model and hand-eye, file order, mm.
    pub after: Vec<Vector3<f64>>,
}

/// FORMAT.md `validation.distances`: for each reference distance
/// `from → to`, the k-th centre of station `from` against the k-th of `to`
/// for `k` up to the shorter station (the paper's 54 distances for 10
/// stations × 6 poses). References naming an unknown station are skipped
/// (the loader rejects them).
#[must_use]
pub fn reference_distances(
    references: &[ReferenceDistance],
    stations: &[StationCentres],
) -> Vec<DistanceRecord> {
    let find = |id: &str| stations.iter().find(|s| s.station == id);
    let mut out = Vec::new();
    for r in references {
        let (Some(a), Some(b)) = (find(&r.from), find(&r.to)) else {
            continue;
        };
        let n = a.before.len().min(b.before.len());
        for k in 0..n {
            out.push(DistanceRecord {
                from: r.from.clone(),
                to: r.to.clone(),
                pose: k,
                reference: r.distance,
                before: (a.before[k] - b.before[k]).norm(),
                after: (a.after[k] - b.after[k]).norm(),
            });
        }
    }
    out
}

/// The validation block from the validate stations' centres.
#[must_use]
pub fn validation(references: &[ReferenceDistance], stations: &[StationCentres]) -> Validation {
    let distances = reference_distances(references, stations);
    let before: Vec<f64> = distances.iter().map(DistanceRecord::error_before).collect();
    let after: Vec<f64> = distances.iter().map(DistanceRecord::error_after).collect();
    let within_before: Vec<Vec<Vector3<f64>>> = stations.iter().map(|s| s.before.clone()).collect();
    let within_after: Vec<Vec<Vector3<f64>>> = stations.iter().map(|s| s.after.clone()).collect();
    Validation {
        before: Stats::of(&before),
        after: Stats::of(&after),
        within_station: BeforeAfter {
            before: Stats::of(&within_station_distances(&within_before)),
            after: Stats::of(&within_station_distances(&within_after)),
        },
        distances,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stats_by_hand() {
        let s = Stats::of(&[1.0, -2.0, 3.0]);
        assert!((s.max - 3.0).abs() < 1e-15);
        // mean 2/3; deviations 1/3, −8/3, 7/3 → Σ² = 114/9; /2 → 57/9.
        assert!((s.std - (57.0_f64 / 9.0).sqrt()).abs() < 1e-12);
        assert!((s.rms - (14.0_f64 / 3.0).sqrt()).abs() < 1e-12);
        assert_eq!(Stats::of(&[]), Stats::default());
        assert_eq!(Stats::of(&[2.0]).std, 0.0);
    }

    #[test]
    fn epsilon_by_hand() {
        // Station A: three points on a line 1 mm apart → pairs 1, 1, 2 (Σ² = 6).
        // Station B: two points 3 mm apart (Σ² = 9). N = 4 → ε = sqrt(15/3).
        let a = vec![Vector3::zeros(), Vector3::x(), Vector3::x() * 2.0];
        let b = vec![Vector3::zeros(), Vector3::y() * 3.0];
        assert!((epsilon(&[a, b]) - 5.0_f64.sqrt()).abs() < 1e-12);
        assert_eq!(epsilon(&[vec![Vector3::zeros()]]), 0.0);
        assert!((epsilon(&[vec![Vector3::zeros(), Vector3::x() * 2.0]]) - 2.0).abs() < 1e-12);
    }

    #[test]
    fn reference_distances_pair_kth_poses() {
        let st = |id: &str, xs: &[f64]| StationCentres {
            station: id.into(),
            before: xs.iter().map(|x| Vector3::new(*x, 0.0, 0.0)).collect(),
            after: xs
                .iter()
                .map(|x| Vector3::new(*x + 0.5, 0.0, 0.0))
                .collect(),
        };
        let stations = vec![st("V1", &[0.0, 0.1, 0.2]), st("V2", &[100.0, 100.0])];
        let refs = vec![ReferenceDistance {
            from: "V1".into(),
            to: "V2".into(),
            distance: 100.0,
        }];
        let v = validation(&refs, &stations);
        assert_eq!(v.distances.len(), 2);
        assert_eq!(v.distances[1].pose, 1);
        assert!((v.distances[1].before - 99.9).abs() < 1e-12);
        assert!((v.before.max - 0.1).abs() < 1e-12);
        // Within V1: 0.1, 0.2, 0.1; V2: 0.
        assert!((v.within_station.before.max - 0.2).abs() < 1e-12);
    }
}
