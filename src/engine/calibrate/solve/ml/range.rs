//! The predicted error over the sensor's measuring range (beyond the
//! paper): a sphere calibration learns the hand-eye where the sphere was
//! seen, and its rotation error grows with the lever to any other point
//! of the laser plane. From `ml`'s covariance of the estimated parameters
//! this gives, for a grid of points `(0, y, z)` of the laser plane at the
//! session's working poses (its validate poses, else its identify poses),
//! the 1σ of each point's base-frame position (3-D) after the common
//! rigid motion of all of them is taken out (the base frame is not
//! observable from a sphere, and a workpiece frame is aligned anyway):
//! its rms, mean, maximum and where, and the same at the mean sphere
//! position. To first order the error of point `i` is `G_i·δθ`; the best
//! rigid motion `R_i·(t, ω)`, `R_i = [I | −[p_i − c]×]`, is fitted to all
//! of them by least squares and removed: `H_i = G_i − R_i·(RᵀR)⁺RᵀG`,
//! `σ_i² = tr(H_i·C·H_iᵀ)` (the aligned σ of
//! [`covariance`](super::covariance), its one home). The grid covers `sensor.range` when the
//! session has one, else the region the sphere positions covered (and
//! says so).

use nalgebra::{DMatrix, Vector3};

use super::covariance::{RigidFit, aligned_sigma};
use super::problem::Problem;
pub use crate::engine::base::records::ml::{RangeError, VolumeError};
use crate::engine::base::session::{SensorRange, Session, Use};
use crate::engine::calibrate::solve::Prepared;
use crate::engine::calibrate::solve::estimate::{Estimate, PoseSensitivity};

/// Grid points along each side of the range.
pub const RANGE_GRID: usize = 7;

/// Most working poses the prediction is averaged over (an even sample
/// beyond).
pub const RANGE_POSES: usize = 20;

/// Below this fraction of `sensor.range` covered by the sphere positions
/// the report warns.
pub const RANGE_COVERAGE_WARNING: f64 = 0.25;

/// The restricted sensitivity `G` (3 × k, scaled units: column `c` is
/// parameter `estimated[c]` divided by `scale[c]`) of sensor point `g` at
/// a pose, and the point's base-frame position.
fn point_rows(
    est: &Estimate,
    pose: &PoseSensitivity,
    estimated: &[usize],
    scale: &[f64],
    g: Vector3<f64>,
) -> (DMatrix<f64>, Vector3<f64>) {
    let (p, a) = pose.at(est, &g);
    let rows = DMatrix::from_fn(3, estimated.len(), |r, c| a[(r, estimated[c])] / scale[c]);
    (rows, p)
}

/// The grid over a range at a set of poses, with the common rigid motion
/// fitted: `H_i = G_i − R_i·M`, `M = (RᵀR)⁻¹RᵀG` (module doc). One home
/// for the prediction of the result and the planner's criterion.
pub(crate) struct AlignedGrid {
    /// `([y, z], G_i, p_i)`, point-major: each grid point's poses follow
    /// one another.
    points: Vec<([f64; 2], DMatrix<f64>, Vector3<f64>)>,
    /// Poses per grid point.
    poses: usize,
    /// The rigid motion fitted to every point at every pose.
    fit: RigidFit,
}

impl AlignedGrid {
    /// The `RANGE_GRID × RANGE_GRID` grid over `range` at `poses`.
    pub(crate) fn new(
        est: &Estimate,
        poses: &[PoseSensitivity],
        estimated: &[usize],
        scale: &[f64],
        range: &SensorRange,
    ) -> Self {
        let mut points = Vec::with_capacity(RANGE_GRID * RANGE_GRID * poses.len());
        for [y, z] in range.grid(RANGE_GRID) {
            for s in poses {
                let (g, p) = point_rows(est, s, estimated, scale, Vector3::new(0.0, y, z));
                points.push(([y, z], g, p));
            }
        }
        let fit = RigidFit::new(points.iter().map(|(_, g, p)| (p, g)), estimated.len());
        Self {
            points,
            poses: poses.len(),
            fit,
        }
    }

    /// The aligned grid of single sensor points, one at each pose:
    /// `points[i] = (pose, sensor-frame point)` (the planner's working
    /// volume: a sphere centre seen at each sampled pose). The rigid
    /// motion fitted to all of them is taken out, as over a range.
    pub(crate) fn at_points(
        est: &Estimate,
        points: &[(PoseSensitivity, Vector3<f64>)],
        estimated: &[usize],
        scale: &[f64],
    ) -> Self {
        let points: Vec<([f64; 2], DMatrix<f64>, Vector3<f64>)> = points
            .iter()
            .map(|(pose, x)| {
                let (g, p) = point_rows(est, pose, estimated, scale, *x);
                ([x.y, x.z], g, p)
            })
            .collect();
        let fit = RigidFit::new(points.iter().map(|(_, g, p)| (p, g)), estimated.len());
        Self {
            points,
            poses: 1,
            fit,
        }
    }

    /// The aligned 1σ (mm) of every point under the covariance `cov` of
    /// the (scaled) estimated parameters.
    pub(crate) fn sigmas(&self, cov: &DMatrix<f64>) -> Vec<f64> {
        self.points
            .iter()
            .map(|(_, g, p)| aligned_sigma(&self.aligned(g, p), cov))
            .collect()
    }

    /// `H` of a point with sensitivity `g` at base position `p`.
    fn aligned(&self, g: &DMatrix<f64>, p: &Vector3<f64>) -> DMatrix<f64> {
        self.fit.aligned(g, p)
    }

    /// `Q = Σ H_iᵀH_i / n` (k × k): `tr(Q·C)` is the mean square predicted
    /// error over the grid for a covariance `C` of the (scaled) estimated
    /// parameters: the planner's criterion.
    pub(crate) fn weight(&self) -> DMatrix<f64> {
        let k = self.fit.columns();
        let mut q = DMatrix::zeros(k, k);
        for (_, g, p) in &self.points {
            let h = self.aligned(g, p);
            q += h.transpose() * &h;
        }
        q / self.points.len().max(1) as f64
    }
}

/// The prediction (see the module doc); `None` without working poses.
pub(super) fn range_error(
    session: &Session,
    prepared: &Prepared,
    problem: &Problem,
    est: &Estimate,
    cov: &DMatrix<f64>,
) -> Option<RangeError> {
    let pick = |usage: Use| -> Vec<usize> {
        (0..session.measurements.len())
            .filter(|&i| session.measurements[i].usage == usage)
            .collect()
    };
    let identify = pick(Use::Identify);
    let validate = pick(Use::Validate);
    let working = if validate.is_empty() {
        &identify
    } else {
        &validate
    };
    if working.is_empty() || identify.is_empty() {
        return None;
    }
    let stride = working.len().div_ceil(RANGE_POSES).max(1);
    let poses: Vec<PoseSensitivity> = working
        .iter()
        .step_by(stride)
        .map(|&i| PoseSensitivity::new(est, &prepared.sighting(session, i)))
        .collect();
    // Where the sphere was seen (identify centres, sensor frame).
    let centres: Vec<Vector3<f64>> = identify
        .iter()
        .map(|&i| prepared.measurements[i].centre_in_sensor)
        .collect();
    let extent = |k: usize| {
        centres
            .iter()
            .fold([f64::INFINITY, f64::NEG_INFINITY], |e, c| {
                [e[0].min(c[k]), e[1].max(c[k])]
            })
    };
    let (sphere_y, sphere_z) = (extent(1), extent(2));
    let mean = centres.iter().sum::<Vector3<f64>>() / centres.len() as f64;
    let (region, range, coverage) = match session.sensor_range {
        Some(r) => {
            let overlap = |a: [f64; 2], b: [f64; 2]| (a[1].min(b[1]) - a[0].max(b[0])).max(0.0);
            let covered = overlap(sphere_y, r.y) * overlap(sphere_z, r.z);
            ("sensor.range".to_string(), r, covered / r.area())
        }
        None => (
            "sphere positions".to_string(),
            SensorRange {
                y: sphere_y,
                z: sphere_z,
            },
            1.0,
        ),
    };
    let grid = AlignedGrid::new(est, &poses, &problem.estimated, &problem.scale, &range);
    let (mut sum_sq, mut sum, mut max, mut max_at) = (0.0, 0.0, 0.0_f64, [0.0; 2]);
    let mut map: Vec<[f64; 3]> = Vec::with_capacity(RANGE_GRID * RANGE_GRID);
    for chunk in grid.points.chunks(grid.poses.max(1)) {
        let mut point_sq = 0.0;
        for (yz, g, p) in chunk {
            let sigma = aligned_sigma(&grid.aligned(g, p), cov);
            sum_sq += sigma * sigma;
            point_sq += sigma * sigma;
            sum += sigma;
            if sigma > max {
                max = sigma;
                max_at = *yz;
            }
        }
        if let Some((yz, _, _)) = chunk.first() {
            map.push([yz[0], yz[1], (point_sq / chunk.len() as f64).sqrt()]);
        }
    }
    let sphere_sq: f64 = poses
        .iter()
        .map(|s| {
            let centre = Vector3::new(0.0, mean.y, mean.z);
            let (g, p) = point_rows(est, s, &problem.estimated, &problem.scale, centre);
            aligned_sigma(&grid.aligned(&g, &p), cov).powi(2)
        })
        .sum();
    let nf = grid.points.len().max(1) as f64;
    let at_sphere_mm = (sphere_sq / poses.len() as f64).sqrt();
    let warning = (coverage < RANGE_COVERAGE_WARNING).then(|| {
        format!(
            "the sphere positions (y {:.1}…{:.1}, z {:.1}…{:.1} mm) cover {:.0} % of sensor.range: the predicted error grows from {:.3} mm at the sphere to {:.3} mm at (y {:.0}, z {:.0}); spread the sphere over the range",
            sphere_y[0],
            sphere_y[1],
            sphere_z[0],
            sphere_z[1],
            coverage * 100.0,
            at_sphere_mm,
            max,
            max_at[0],
            max_at[1]
        )
    });
    Some(RangeError {
        region,
        y: range.y,
        z: range.z,
        grid: RANGE_GRID,
        poses: poses.len(),
        rms_mm: (sum_sq / nf).sqrt(),
        mean_mm: sum / nf,
        max_mm: max,
        max_at,
        at_sphere_mm,
        sphere_y,
        sphere_z,
        coverage,
        map,
        warning,
    })
}

/// Most poses the volume error is taken over (an even sample beyond).
pub const VOLUME_POSES: usize = 400;

/// The prediction over the session's volume ([`VolumeError`]) with the
/// covariance `cov` (scaled units, a posteriori); `None` with fewer than
/// 2 stations (one station's volume is the sensor's range there:
/// [`range_error`]).
pub(super) fn volume_error(
    session: &Session,
    prepared: &Prepared,
    problem: &Problem,
    est: &Estimate,
    cov: &DMatrix<f64>,
) -> Option<VolumeError> {
    let working: Vec<usize> = (0..session.measurements.len())
        .filter(|&i| matches!(session.measurements[i].usage, Use::Identify | Use::Validate))
        .collect();
    let stations: std::collections::HashSet<&str> = working
        .iter()
        .map(|&i| session.measurements[i].station.as_str())
        .collect();
    if stations.len() < 2 {
        return None;
    }
    let stride = working.len().div_ceil(VOLUME_POSES).max(1);
    let points: Vec<(PoseSensitivity, Vector3<f64>)> = working
        .iter()
        .step_by(stride)
        .map(|&i| {
            (
                PoseSensitivity::new(est, &prepared.sighting(session, i)),
                prepared.measurements[i].centre_in_sensor,
            )
        })
        .collect();
    let grid = AlignedGrid::at_points(est, &points, &problem.estimated, &problem.scale);
    let sigmas = grid.sigmas(cov);
    let n = sigmas.len().max(1) as f64;
    let mut box_mm = [[f64::INFINITY, f64::NEG_INFINITY]; 3];
    for (_, _, p) in &grid.points {
        for k in 0..3 {
            box_mm[k] = [box_mm[k][0].min(p[k]), box_mm[k][1].max(p[k])];
        }
    }
    Some(VolumeError {
        poses: sigmas.len(),
        stations: stations.len(),
        rms_mm: (sigmas.iter().map(|s| s * s).sum::<f64>() / n).sqrt(),
        max_mm: sigmas.iter().copied().fold(0.0, f64::max),
        box_mm,
    })
}
