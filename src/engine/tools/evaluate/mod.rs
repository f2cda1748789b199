//! Scoring a model and hand-eye against a simulated ground truth: the
//! validation distance errors measured against the **true** station
//! distances (not the noisy tracker references), and the noise floor, the
//! same errors computed with the true model and hand-eye on the same noisy
//! data. Used by the accuracy tests, the `simulate` summary and the
//! method comparison of the README.

pub mod range;
pub mod study;

use nalgebra::{Isometry3, Point3, Vector3};

use crate::engine::base::robot::Robot;
use crate::engine::base::session::{Session, Use};
use crate::engine::calibrate::solve::Prepared;
use crate::engine::calibrate::validate::Stats;
use crate::engine::tools::simulate::Truth;

/// Validation distance errors `measured − true` (mm) of a model and
/// hand-eye: for each reference distance `from → to` of the session, the
/// k-th validate measurement of `from` against the k-th of `to` (the
/// pairing of FORMAT.md), measured with `robot` and `flange_from_sensor`
/// on the session's (noisy) joints and centres, compared with the distance
/// between the true station centres. Stations missing from the truth are
/// skipped.
#[must_use]
pub fn validation_errors(
    session: &Session,
    prepared: &Prepared,
    truth: &Truth,
    robot: &Robot,
    flange_from_sensor: &Isometry3<f64>,
) -> Vec<f64> {
    let stations = session.stations(Use::Validate);
    let centre = |i: usize| -> Vector3<f64> {
        let m = &session.measurements[i];
        let base_from_sensor = robot.base_from_flange(&m.joints) * flange_from_sensor;
        (base_from_sensor * Point3::from(prepared.measurements[i].centre_in_sensor)).coords
    };
    let find = |id: &str| stations.iter().find(|(s, _)| s == id).map(|(_, idx)| idx);
    let mut out = Vec::new();
    for r in &session.reference_distances {
        let (Some(a), Some(b), Some(ta), Some(tb)) = (
            find(&r.from),
            find(&r.to),
            truth.station(&r.from),
            truth.station(&r.to),
        ) else {
            continue;
        };
        let true_distance = (ta - tb).norm();
        for k in 0..a.len().min(b.len()) {
            out.push((centre(a[k]) - centre(b[k])).norm() - true_distance);
        }
    }
    out
}

/// Before, after and noise floor of the validation distance errors
/// against the truth, mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TruthScore {
    /// Nominal model and initial hand-eye.
    pub before: Stats,
    /// Calibrated model and hand-eye.
    pub after: Stats,
    /// True model and hand-eye on the same data (the noise floor).
    pub floor: Stats,
}

impl TruthScore {
    /// `after.std / floor.std`: 1 is as good as the data allows.
    #[must_use]
    pub fn ratio_to_floor(&self) -> f64 {
        self.after.std / self.floor.std
    }

    /// `before.std / after.std`: the improvement.
    #[must_use]
    pub fn improvement(&self) -> f64 {
        self.before.std / self.after.std
    }
}

/// Scores a calibration against the truth.
#[must_use]
pub fn score(
    session: &Session,
    prepared: &Prepared,
    truth: &Truth,
    calibrated: &Robot,
    hand_eye: &Isometry3<f64>,
) -> TruthScore {
    let stats = |robot: &Robot, he: &Isometry3<f64>| {
        Stats::of(&validation_errors(session, prepared, truth, robot, he))
    };
    TruthScore {
        before: stats(&session.robot, &prepared.hand_eye_initial),
        after: stats(calibrated, hand_eye),
        floor: stats(&truth.true_robot(), &truth.true_hand_eye()),
    }
}

/// The realised measuring error over the working volume: each validate
/// station's sphere measured in the base frame (the mean of its sightings'
/// centres through the model and hand-eye), all of them aligned rigidly to
/// the true station centres (sphere data do not see the base frame), mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VolumeScore {
    /// Calibrated model and hand-eye.
    pub after: range::RangeStats,
    /// True model and hand-eye on the same readings: the repeatability
    /// floor.
    pub floor: range::RangeStats,
    /// Validate stations scored.
    pub stations: usize,
}

impl VolumeScore {
    /// `after.rms / floor.rms`: 1 is as good as the readings allow.
    #[must_use]
    pub fn ratio_to_floor(&self) -> f64 {
        self.after.rms / self.floor.rms
    }
}

/// Scores a calibration over the volume its validate stations span
/// ([`VolumeScore`]); `None` with fewer than 3 validate stations in the
/// truth.
#[must_use]
pub fn volume_score(
    session: &Session,
    prepared: &Prepared,
    truth: &Truth,
    calibrated: &Robot,
    hand_eye: &Isometry3<f64>,
) -> Option<VolumeScore> {
    let stations: Vec<(String, Vec<usize>)> = session
        .stations(Use::Validate)
        .into_iter()
        .filter(|(id, idx)| truth.station(id).is_some() && !idx.is_empty())
        .collect();
    if stations.len() < 3 {
        return None;
    }
    let measured = |robot: &Robot, he: &Isometry3<f64>| -> Vec<Vector3<f64>> {
        stations
            .iter()
            .map(|(_, idx)| {
                idx.iter()
                    .map(|&i| {
                        let m = &session.measurements[i];
                        let t = robot.base_from_flange(&m.joints) * he;
                        (t * Point3::from(prepared.measurements[i].centre_in_sensor)).coords
                    })
                    .sum::<Vector3<f64>>()
                    / idx.len() as f64
            })
            .collect()
    };
    let exact: Vec<Vector3<f64>> = stations
        .iter()
        .filter_map(|(id, _)| truth.station(id))
        .collect();
    Some(VolumeScore {
        after: range::aligned_stats(&measured(calibrated, hand_eye), &exact),
        floor: range::aligned_stats(
            &measured(&truth.true_robot(), &truth.true_hand_eye()),
            &exact,
        ),
        stations: stations.len(),
    })
}
