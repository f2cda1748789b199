//! The result's `stations` block (FORMAT.md, added 2026-11-27): every
//! station's calibrated point and the frame it is fixed in, `"base"` for
//! a sensor on the flange (the sphere centre), `"flange"` for a fixed
//! sensor (a target on the tool).
//!
//! A station's point is the mean of its identify measurements' `after`
//! points (of all its measurements when it has no identify one): the
//! held-out check of a fixed sensor predicts each validate measurement
//! from it ([`prediction_errors`]).

use std::collections::HashMap;

use serde::{Deserialize, Serialize};

use super::result::CentreRecord;
use crate::engine::base::session::{Mount, Use};

/// One entry of the result's `stations`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StationRecord {
    /// Station id.
    pub id: String,
    /// Its calibrated point, mm, in `frame`.
    pub point: [f64; 3],
    /// `"base"` or `"flange"`.
    pub frame: String,
}

/// Per station: the sum and count of its identify points, then of the others.
type Sums = ([f64; 3], usize, [f64; 3], usize);

/// The `stations` block of a run's `centres` on a session with `mount`,
/// stations in order of first appearance.
#[must_use]
pub fn stations_of(centres: &[CentreRecord], mount: Mount) -> Vec<StationRecord> {
    let mut order: Vec<&str> = Vec::new();
    let mut sums: HashMap<&str, Sums> = HashMap::new();
    for c in centres {
        let entry = sums.entry(c.station.as_str()).or_insert_with(|| {
            order.push(c.station.as_str());
            ([0.0; 3], 0, [0.0; 3], 0)
        });
        let (sum, n) = if c.usage == Use::Identify {
            (&mut entry.0, &mut entry.1)
        } else {
            (&mut entry.2, &mut entry.3)
        };
        for (s, a) in sum.iter_mut().zip(c.after) {
            *s += a;
        }
        *n += 1;
    }
    order
        .into_iter()
        .filter_map(|id| {
            let (si, ni, so, no) = sums.get(id)?;
            let (sum, n) = if *ni > 0 { (si, *ni) } else { (so, *no) };
            Some(StationRecord {
                id: id.to_string(),
                point: sum.map(|v| v / n as f64),
                frame: mount.station_frame().to_string(),
            })
        })
        .collect()
}

/// The mount a result was made with: `Fixed` when its stations are fixed
/// in the flange frame, else `Flange` (results written before the block
/// existed are all of a sensor on the flange).
#[must_use]
pub fn mount_of(stations: &[StationRecord]) -> Mount {
    if stations
        .iter()
        .any(|s| s.frame == Mount::Fixed.station_frame())
    {
        Mount::Fixed
    } else {
        Mount::Flange
    }
}

/// One validate measurement's predicted point against the measured one.
#[derive(Debug, Clone, PartialEq)]
pub struct Prediction {
    /// Measurement id.
    pub measurement: String,
    /// Station id.
    pub station: String,
    /// `|predicted − measured|`, mm: the same in the sensor frame as in the
    /// station's frame (the two differ by a rigid motion).
    pub error: f64,
}

/// Each `validate` measurement's predicted point against the measured one
/// (FORMAT.md 2026-11-27, the held-out check of a fixed sensor): the
/// station's calibrated point, seen through the calibrated model and
/// `base_from_sensor`, against what the sensor measured. A validate
/// measurement whose station has no point is left out.
#[must_use]
pub fn prediction_errors(centres: &[CentreRecord], stations: &[StationRecord]) -> Vec<Prediction> {
    let points: HashMap<&str, &[f64; 3]> =
        stations.iter().map(|s| (s.id.as_str(), &s.point)).collect();
    centres
        .iter()
        .filter(|c| c.usage == Use::Validate)
        .filter_map(|c| {
            let p = points.get(c.station.as_str())?;
            let error = (0..3)
                .map(|k| (c.after[k] - p[k]).powi(2))
                .sum::<f64>()
                .sqrt();
            Some(Prediction {
                measurement: c.measurement.clone(),
                station: c.station.clone(),
                error,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn centre(id: &str, station: &str, usage: Use, after: [f64; 3]) -> CentreRecord {
        CentreRecord {
            measurement: id.into(),
            station: station.into(),
            usage,
            sensor: [0.0; 3],
            before: [0.0; 3],
            after,
        }
    }

    #[test]
    fn a_station_is_its_identify_mean_and_validate_poses_are_scored_against_it() {
        let centres = [
            centre("a", "T1", Use::Identify, [1.0, 0.0, 0.0]),
            centre("b", "T1", Use::Identify, [3.0, 0.0, 0.0]),
            centre("v", "T1", Use::Validate, [2.0, 4.0, 0.0]),
            centre("w", "T2", Use::Validate, [0.0, 0.0, 5.0]),
        ];
        let st = stations_of(&centres, Mount::Fixed);
        assert_eq!(st.len(), 2);
        assert_eq!(st[0].point, [2.0, 0.0, 0.0]);
        assert_eq!(st[0].frame, "flange");
        assert_eq!(st[1].point, [0.0, 0.0, 5.0]);
        assert_eq!(mount_of(&st), Mount::Fixed);
        assert_eq!(
            mount_of(&stations_of(&centres, Mount::Flange)),
            Mount::Flange
        );
        let p = prediction_errors(&centres, &st);
        assert_eq!(p.len(), 2);
        assert!((p[0].error - 4.0).abs() < 1e-12);
        assert!(p[1].error.abs() < 1e-12);
    }
}
