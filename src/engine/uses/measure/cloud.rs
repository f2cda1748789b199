//! The measured cloud: per pose the transform from the sensor to the
//! output frame and the σ form, and the profile points as the sensor gave
//! them. A point's position and σ are computed when asked (a dozen
//! multiplications), so the cloud holds 16 bytes a point and any view of
//! it (the writers, a decimated preview) costs only the points it shows.

use nalgebra::{Isometry3, Matrix3, Vector3};

use super::scan::{Dropped, Placement};
use super::sigma::SigmaForm;
use crate::engine::base::session::Use;

/// One pose of the cloud.
#[derive(Debug, Clone, PartialEq)]
pub struct CloudPose {
    /// The measurement or pose id.
    pub id: String,
    /// Its sphere station, if any.
    pub station: Option<String>,
    /// Its `use`, if any.
    pub usage: Option<Use>,
    /// Where the robot was.
    pub placement: Placement,
    /// `frame_from_sensor`: the sensor pose in the output frame (the base
    /// frame, or the workpiece frame), mm.
    pub frame_from_sensor: Isometry3<f64>,
    /// `t`, `r₂`, `r₃` of `frame_from_sensor`: a point `(0, y, z)` lands at
    /// `t + y·r₂ + z·r₃`.
    basis: [Vector3<f64>; 3],
    /// The σ form (mm²; [`SigmaForm`]), `None` without σ.
    pub sigma: Option<SigmaForm>,
    /// Profile points `[y, z]`, mm, sensor frame.
    pub points: Vec<[f64; 2]>,
    /// Points dropped while reading.
    pub dropped: Dropped,
}

impl CloudPose {
    /// A pose of the cloud (`sigma` already including any sensor noise).
    #[must_use]
    pub fn new(
        pose: super::scan::ScanPose,
        frame_from_sensor: Isometry3<f64>,
        sigma: Option<SigmaForm>,
    ) -> Self {
        let r: Matrix3<f64> = frame_from_sensor.rotation.to_rotation_matrix().into_inner();
        Self {
            id: pose.id,
            station: pose.station,
            usage: pose.usage,
            placement: pose.placement,
            basis: [
                frame_from_sensor.translation.vector,
                r.column(1).into_owned(),
                r.column(2).into_owned(),
            ],
            frame_from_sensor,
            sigma,
            points: pose.points,
            dropped: pose.dropped,
        }
    }

    /// The output-frame position (mm) of profile point `[y, z]`.
    #[must_use]
    #[inline]
    pub fn position(&self, [y, z]: [f64; 2]) -> [f64; 3] {
        let [t, r2, r3] = &self.basis;
        [
            t.x + y * r2.x + z * r3.x,
            t.y + y * r2.y + z * r3.y,
            t.z + y * r2.z + z * r3.z,
        ]
    }

    /// The 1σ (mm) of profile point `[y, z]`; NaN without σ.
    #[must_use]
    #[inline]
    pub fn sigma_mm(&self, [y, z]: [f64; 2]) -> f64 {
        self.sigma.map_or(f64::NAN, |s| s.sigma(y, z))
    }
}

/// A point of the cloud.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CloudPoint {
    /// Index of its pose in [`Cloud::poses`].
    pub pose: usize,
    /// Position in the output frame, mm.
    pub position: [f64; 3],
    /// 1σ of the position (3-D), mm; NaN without σ.
    pub sigma_mm: f64,
}

/// What frame the cloud is in, for file headers and people.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FrameLabel {
    /// The robot base frame **B**.
    Base,
    /// A workpiece frame given as `base_from_workpiece` in this file.
    Workpiece(String),
}

impl std::fmt::Display for FrameLabel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Base => write!(f, "robot base frame B"),
            Self::Workpiece(file) => write!(f, "workpiece frame of {file} (base_from_workpiece)"),
        }
    }
}

/// Statistics of the points' σ, mm.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SigmaStats {
    /// Root mean square.
    pub rms: f64,
    /// Median (the upper of the two middle values for an even count).
    pub median: f64,
    /// Largest.
    pub max: f64,
}

/// The measured cloud.
#[derive(Debug, Clone, PartialEq)]
pub struct Cloud {
    /// The poses in scan order, each with its points.
    pub poses: Vec<CloudPose>,
    /// The output frame.
    pub frame: FrameLabel,
    /// Which model of the result placed the sensor (`calibrated`, `nominal`).
    pub model: &'static str,
}

impl Cloud {
    /// Points in all poses.
    #[must_use]
    pub fn len(&self) -> usize {
        self.poses.iter().map(|p| p.points.len()).sum()
    }

    /// True without points.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.poses.iter().all(|p| p.points.is_empty())
    }

    /// Whether the points carry σ.
    #[must_use]
    pub fn has_sigma(&self) -> bool {
        self.poses.iter().any(|p| p.sigma.is_some())
    }

    /// Every point, pose by pose in order.
    pub fn points(&self) -> impl Iterator<Item = CloudPoint> + '_ {
        self.poses.iter().enumerate().flat_map(|(i, pose)| {
            pose.points.iter().map(move |&p| CloudPoint {
                pose: i,
                position: pose.position(p),
                sigma_mm: pose.sigma_mm(p),
            })
        })
    }

    /// `min(max_points, n)` points spread evenly over the cloud's `n`
    /// (point `⌊k·n / max_points⌋` for `k = 0, 1, …`, in order): a view of a
    /// cloud of millions for drawing. Costs the points returned (and a step
    /// per pose), not the cloud.
    #[must_use]
    pub fn decimated(&self, max_points: usize) -> Vec<CloudPoint> {
        let n = self.len();
        let take = max_points.min(n);
        let mut out = Vec::with_capacity(take);
        // Index of the k-th point taken.
        let at = |k: usize| {
            usize::try_from(k as u128 * n as u128 / take.max(1) as u128).unwrap_or(usize::MAX)
        };
        let mut k = 0usize;
        let mut start = 0usize;
        for (i, pose) in self.poses.iter().enumerate() {
            let end = start + pose.points.len();
            while k < take && at(k) < end {
                let p = pose.points[at(k) - start];
                out.push(CloudPoint {
                    pose: i,
                    position: pose.position(p),
                    sigma_mm: pose.sigma_mm(p),
                });
                k += 1;
            }
            start = end;
        }
        out
    }

    /// The bounding box `(min, max)` of the points, mm; `None` without
    /// points.
    #[must_use]
    pub fn bounds(&self) -> Option<([f64; 3], [f64; 3])> {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in self.points() {
            for k in 0..3 {
                lo[k] = lo[k].min(p.position[k]);
                hi[k] = hi[k].max(p.position[k]);
            }
        }
        (!self.is_empty()).then_some((lo, hi))
    }

    /// RMS, median and largest σ; `None` without σ or points.
    #[must_use]
    pub fn sigma_stats(&self) -> Option<SigmaStats> {
        if !self.has_sigma() || self.is_empty() {
            return None;
        }
        let mut all: Vec<f64> = self.points().map(|p| p.sigma_mm).collect();
        let n = all.len() as f64;
        let rms = (all.iter().map(|s| s * s).sum::<f64>() / n).sqrt();
        let max = all.iter().copied().fold(0.0, f64::max);
        let median = crate::engine::base::numeric::upper_median(&mut all);
        Some(SigmaStats { rms, median, max })
    }

    /// Points dropped while reading, all poses.
    #[must_use]
    pub fn dropped(&self) -> Dropped {
        self.poses.iter().fold(Dropped::default(), |a, p| Dropped {
            non_finite: a.non_finite + p.dropped.non_finite,
            no_return: a.no_return + p.dropped.no_return,
        })
    }
}
