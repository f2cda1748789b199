//! The region the calibration saw, and how far a target lies outside it:
//! in joint space, the distance to the nearest identify pose (the joints
//! the result records, or the session's); in the base frame, how far the
//! TCP's working point (for the sensor: where it saw the sphere, the mean
//! sensor-frame identify centre; else the TCP origin) lies outside the
//! box of the working points at the identify poses (for the sensor
//! without joints: the identify sphere positions, the result's `after`
//! centres).

use nalgebra::{Isometry3, Point3, Vector3};

use super::arms::joint_distance;
use crate::engine::base::robot::ik::DOF;

/// The region of one calibration.
#[derive(Debug, Clone)]
pub(super) struct Region {
    /// Identify poses (id, joints deg), when the session was given.
    identify: Vec<(String, [f64; DOF])>,
    /// Box of the working points at the identify poses, base frame, mm.
    lo: Vector3<f64>,
    hi: Vector3<f64>,
    /// The working point in the TCP frame, mm.
    working_point: Vector3<f64>,
}

impl Region {
    /// The region of the identify poses `identify` (joints deg, may be
    /// empty), the working points `seen` there (base frame, mm; their box)
    /// and the TCP frame's working point (mm).
    pub(super) fn new(
        identify: Vec<(String, [f64; DOF])>,
        seen: &[Vector3<f64>],
        working_point: Vector3<f64>,
    ) -> Self {
        let mut lo = Vector3::repeat(f64::INFINITY);
        let mut hi = Vector3::repeat(f64::NEG_INFINITY);
        for p in seen {
            lo = lo.inf(p);
            hi = hi.sup(p);
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
    /// outside the box; 0 inside (and without a box).
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
