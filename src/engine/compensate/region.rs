//! The region the calibration saw, and how far a target lies outside it:
//! in joint space, the distance to the nearest identify pose (the
//! session's joints, when given); in the base frame, how far the TCP's
//! working point (for the sensor: where it saw the sphere, the mean
//! sensor-frame identify centre) lies outside the box of the identify
//! sphere positions (the result's `after` centres, always available).

use nalgebra::{Isometry3, Point3, Vector3};

use super::arms::joint_distance;
use crate::engine::format::ResultFile;
use crate::engine::robot::ik::DOF;
use crate::engine::session::Use;

/// The region of one calibration.
#[derive(Debug, Clone)]
pub(super) struct Region {
    /// Identify poses (id, joints deg), when the session was given.
    identify: Vec<(String, [f64; DOF])>,
    /// Box of the identify sphere positions, base frame, mm.
    lo: Vector3<f64>,
    hi: Vector3<f64>,
    /// The working point in the TCP frame, mm.
    working_point: Vector3<f64>,
}

impl Region {
    /// The region of `result`, with the identify poses' joints `identify`
    /// (may be empty) and the TCP frame's working point (mm).
    pub(super) fn new(
        result: &ResultFile,
        identify: Vec<(String, [f64; DOF])>,
        working_point: Vector3<f64>,
    ) -> Self {
        let mut lo = Vector3::repeat(f64::INFINITY);
        let mut hi = Vector3::repeat(f64::NEG_INFINITY);
        for c in result.centres.iter().filter(|c| c.usage == Use::Identify) {
            let p = Vector3::from(c.after);
            lo = lo.inf(&p);
            hi = hi.sup(&p);
        }
        Self {
            identify,
            lo,
            hi,
            working_point,
        }
    }

    pub(super) fn has_joints(&self) -> bool {
        !self.identify.is_empty()
    }

    /// Joint distance (deg) from `q` to the nearest identify pose, when
    /// the session was given.
    pub(super) fn nearest_identify(&self, q: &[f64; DOF]) -> Option<f64> {
        self.identify
            .iter()
            .map(|(_, p)| joint_distance(q, p))
            .min_by(f64::total_cmp)
    }

    /// How far (mm) the working point of a TCP at `base_from_tcp` lies
    /// outside the identify box; 0 inside (and without identify centres).
    pub(super) fn outside(&self, base_from_tcp: &Isometry3<f64>) -> f64 {
        // No identify centre: the box is empty (lo above hi).
        if self.lo.x > self.hi.x || self.lo.x.is_nan() {
            return 0.0;
        }
        let p = (base_from_tcp * Point3::from(self.working_point)).coords;
        let below = (self.lo - p).sup(&Vector3::zeros());
        let above = (p - self.hi).sup(&Vector3::zeros());
        (below + above).norm()
    }
}
