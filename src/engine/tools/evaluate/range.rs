//! Scoring the error over the sensor's measuring range against a
//! simulated ground truth (issue 14): the 3-D error of points `(0, y, z)`
//! of the laser plane on a grid over `sensor.range`, at every validate
//! pose, between where a model puts them (at the session's **recorded**
//! joint readings) and where they truly are (the true model at the
//! **actual** joints), after the best rigid alignment of all of them (the
//! base frame is not observable from a sphere; a workpiece frame is
//! aligned anyway). The floor is the same error of the true model and
//! hand-eye on the recorded readings: the joint-reading noise alone. A
//! calibration at the floor is as good over the range as the readings
//! allow.

use nalgebra::{Isometry3, Point3, Vector3};

use crate::engine::base::geometry::kabsch;
use crate::engine::base::robot::Robot;
use crate::engine::base::session::{SensorRange, Session, Use};
use crate::engine::tools::simulate::Truth;

/// Grid points along each side of the range (finer than `ml`'s
/// prediction grid: this is the measurement the prediction is held to).
pub const RANGE_SCORE_GRID: usize = 9;

/// RMS and largest 3-D error over the grid and the validate poses, mm.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RangeStats {
    /// Root mean square of the 3-D error, mm.
    pub rms: f64,
    /// Largest 3-D error, mm.
    pub max: f64,
}

/// Before, after and floor of the error over the range, mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RangeScore {
    /// The range scored.
    pub range: SensorRange,
    /// Nominal model, initial hand-eye.
    pub before: RangeStats,
    /// Calibrated model and hand-eye.
    pub after: RangeStats,
    /// True model and hand-eye on the recorded readings.
    pub floor: RangeStats,
    /// Only the model error: the calibrated against the true model at the
    /// same (recorded) readings. What `ml`'s range prediction estimates.
    pub model: RangeStats,
}

impl RangeScore {
    /// `after.rms / floor.rms`: 1 is as good as the readings allow.
    #[must_use]
    pub fn ratio_to_floor(&self) -> f64 {
        self.after.rms / self.floor.rms
    }
}

/// The grid points of `range`, sensor frame.
fn grid(range: &SensorRange) -> Vec<Point3<f64>> {
    range
        .grid(RANGE_SCORE_GRID)
        .into_iter()
        .map(|[y, z]| Point3::new(0.0, y, z))
        .collect()
}

/// The aligned 3-D errors of `model` (points of a model, one per grid point
/// and pose) against `truth` (the same points, truly), mm.
pub(crate) fn aligned_stats(model: &[Vector3<f64>], truth: &[Vector3<f64>]) -> RangeStats {
    let Some(fit) = kabsch(model, truth) else {
        return RangeStats::default();
    };
    let errors: Vec<f64> = model
        .iter()
        .zip(truth)
        .map(|(m, t)| ((fit * Point3::from(*m)).coords - t).norm())
        .collect();
    let n = errors.len().max(1) as f64;
    RangeStats {
        rms: (errors.iter().map(|e| e * e).sum::<f64>() / n).sqrt(),
        max: errors.iter().copied().fold(0.0, f64::max),
    }
}

/// Scores a calibration over `range` (default: the session's
/// `sensor.range`) against the truth; `None` without a range, validate
/// poses or their truth.
#[must_use]
pub fn range_score(
    session: &Session,
    truth: &Truth,
    initial_hand_eye: &Isometry3<f64>,
    calibrated: &Robot,
    hand_eye: &Isometry3<f64>,
    range: Option<SensorRange>,
) -> Option<RangeScore> {
    let range = range.or(session.sensor_range)?;
    let points = grid(&range);
    let true_robot = truth.true_robot();
    let true_he = truth.true_hand_eye();
    let mut poses: Vec<(&[f64], Vec<f64>)> = Vec::new();
    for m in session.with_use(Use::Validate) {
        let actual = truth.measurements.get(&m.id)?;
        poses.push((&m.joints, actual.joints_actual.clone()));
    }
    if poses.is_empty() {
        return None;
    }
    let place = |robot: &Robot, he: &Isometry3<f64>, q: &[f64]| -> Vec<Vector3<f64>> {
        let t = robot.base_from_flange(q) * he;
        points.iter().map(|g| (t * g).coords).collect()
    };
    let (mut exact, mut before, mut after, mut floor) = (vec![], vec![], vec![], vec![]);
    for (recorded, actual) in &poses {
        exact.extend(place(&true_robot, &true_he, actual));
        before.extend(place(&session.robot, initial_hand_eye, recorded));
        after.extend(place(calibrated, hand_eye, recorded));
        floor.extend(place(&true_robot, &true_he, recorded));
    }
    Some(RangeScore {
        range,
        before: aligned_stats(&before, &exact),
        after: aligned_stats(&after, &exact),
        floor: aligned_stats(&floor, &exact),
        model: aligned_stats(&after, &floor),
    })
}
