//! The cell checks itself with its own scanner (no tracker): the sphere
//! seen at several places (a session's validate stations, or a sphere
//! artefact scanned from many poses at several places) is measured
//! through a model into the base frame and fitted, as an ISO 10360-8-style
//! check of a scanning probe does:
//!
//! - **size error**: the fitted diameter (centre and radius free, all the
//!   station's stripes) minus the sphere's calibrated diameter;
//! - **form error**: the range of the radial residuals of that fit;
//! - **position spread**: each pose's sphere centre (its stripe alone,
//!   fitted with the known radius) against the station's fitted centre,
//!   rms and largest;
//! - **spacing error**: distances between the fitted centres of two
//!   stations against the reference distances, when there are some
//!   (else the distances between consecutive stations are listed).
//!
//! Both the nominal model with the initial hand-eye ("before") and the
//! calibrated ones ("after") are scored, on the same points.

use std::collections::HashMap;

use nalgebra::{Point3, Vector3};

use super::cloud::CloudPose;
use super::model::CellModel;
use super::scan::{Placement, ScanPose};
use super::sphere::{SphereFit, fit_sphere, fit_sphere_radius};
use crate::engine::base::session::{ReferenceDistance, Use};

/// A pose that may have seen a sphere station: a scan's pose or a
/// cloud's (the self-validation runs on either, e.g. beside the
/// measurement on another thread).
pub trait Sighted {
    /// Its station, if any.
    fn station(&self) -> Option<&str>;
    /// Its `use`, if any.
    fn usage(&self) -> Option<Use>;
    /// Where the robot was.
    fn placement(&self) -> &Placement;
    /// Its profile points `[y, z]`, mm, sensor frame.
    fn points(&self) -> &[[f64; 2]];
}

impl Sighted for ScanPose {
    fn station(&self) -> Option<&str> {
        self.station.as_deref()
    }
    fn usage(&self) -> Option<Use> {
        self.usage
    }
    fn placement(&self) -> &Placement {
        &self.placement
    }
    fn points(&self) -> &[[f64; 2]] {
        &self.points
    }
}

impl Sighted for CloudPose {
    fn station(&self) -> Option<&str> {
        self.station.as_deref()
    }
    fn usage(&self) -> Option<Use> {
        self.usage
    }
    fn placement(&self) -> &Placement {
        &self.placement
    }
    fn points(&self) -> &[[f64; 2]] {
        &self.points
    }
}

/// Whether the self-validation looks at `pose`: it saw a station and is
/// used `validate` (or has no use: a raw scan).
#[must_use]
pub fn checks(pose: &impl Sighted) -> bool {
    pose.station().is_some() && matches!(pose.usage(), Some(Use::Validate) | None)
}

/// One station's sphere under one model, base frame, mm.
#[derive(Debug, Clone, PartialEq)]
pub struct StationCheck {
    /// Station id.
    pub station: String,
    /// Poses that saw it.
    pub poses: usize,
    /// The fit of all its points (centre and radius free).
    pub fit: SphereFit,
    /// Fitted diameter minus the sphere's diameter.
    pub size_error: f64,
    /// Each pose's centre (radius fixed) in pose order.
    pub pose_centres: Vec<Vector3<f64>>,
    /// RMS distance of the pose centres from the fitted centre.
    pub spread_rms: f64,
    /// Largest distance of a pose centre from the fitted centre.
    pub spread_max: f64,
}

/// A distance between two stations' fitted centres, mm.
#[derive(Debug, Clone, PartialEq)]
pub struct Spacing {
    /// Station id.
    pub from: String,
    /// Station id.
    pub to: String,
    /// Measured distance.
    pub measured: f64,
    /// The reference distance, when the input has one.
    pub reference: Option<f64>,
}

/// Every station under one model, with summary figures (mm).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ModelCheck {
    /// Stations in order of first appearance.
    pub stations: Vec<StationCheck>,
    /// Distances between stations.
    pub spacings: Vec<Spacing>,
}

/// RMS and largest absolute value.
fn rms_max(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut sum, mut n, mut max) = (0.0, 0usize, 0.0_f64);
    for v in values {
        sum += v * v;
        n += 1;
        max = max.max(v.abs());
    }
    ((sum / n.max(1) as f64).sqrt(), max)
}

impl ModelCheck {
    /// RMS and largest |size error|.
    #[must_use]
    pub fn size(&self) -> (f64, f64) {
        rms_max(self.stations.iter().map(|s| s.size_error))
    }

    /// RMS and largest form error.
    #[must_use]
    pub fn form(&self) -> (f64, f64) {
        rms_max(self.stations.iter().map(|s| s.fit.form()))
    }

    /// RMS over all pose centres of their distance from their station's
    /// centre, and the largest.
    #[must_use]
    pub fn spread(&self) -> (f64, f64) {
        let mut sum = 0.0;
        let mut n = 0usize;
        for s in &self.stations {
            sum += s.spread_rms * s.spread_rms * s.pose_centres.len() as f64;
            n += s.pose_centres.len();
        }
        let max = self
            .stations
            .iter()
            .map(|s| s.spread_max)
            .fold(0.0, f64::max);
        ((sum / n.max(1) as f64).sqrt(), max)
    }

    /// RMS and largest |measured − reference| over the spacings with a
    /// reference; `None` without any.
    #[must_use]
    pub fn spacing_error(&self) -> Option<(f64, f64)> {
        let errors: Vec<f64> = self
            .spacings
            .iter()
            .filter_map(|s| Some(s.measured - s.reference?))
            .collect();
        (!errors.is_empty()).then(|| rms_max(errors.into_iter()))
    }
}

/// The self-validation: before and after calibration.
#[derive(Debug, Clone, PartialEq)]
pub struct SelfValidation {
    /// The sphere's diameter, mm.
    pub diameter: f64,
    /// Nominal model, initial hand-eye.
    pub before: ModelCheck,
    /// Calibrated model and hand-eye.
    pub after: ModelCheck,
}

/// The poses of `poses` the self-validation looks at ([`checks`]), by
/// station in order of first appearance.
fn stations<P: Sighted>(poses: &[P]) -> Vec<(String, Vec<&P>)> {
    let mut order: Vec<(String, Vec<&P>)> = Vec::new();
    let mut index: HashMap<String, usize> = HashMap::new();
    for p in poses {
        let Some(station) = p.station().filter(|_| checks(p)) else {
            continue;
        };
        let slot = *index.entry(station.to_string()).or_insert_with(|| {
            order.push((station.to_string(), Vec::new()));
            order.len() - 1
        });
        order[slot].1.push(p);
    }
    order
}

/// One model's check of the stations (module doc).
fn check<P: Sighted>(
    stations: &[(String, Vec<&P>)],
    model: &CellModel,
    diameter: f64,
    references: &[ReferenceDistance],
) -> ModelCheck {
    let radius = diameter / 2.0;
    let mut out = ModelCheck::default();
    for (station, poses) in stations {
        let per_pose: Vec<Vec<Vector3<f64>>> = poses
            .iter()
            .filter_map(|p| {
                let t = model.base_from_sensor(p.placement())?;
                Some(
                    p.points()
                        .iter()
                        .map(|&[y, z]| (t * Point3::new(0.0, y, z)).coords)
                        .collect(),
                )
            })
            .collect();
        let all: Vec<Vector3<f64>> = per_pose.iter().flatten().copied().collect();
        let Some(fit) = fit_sphere(&all) else {
            continue;
        };
        let pose_centres: Vec<Vector3<f64>> = per_pose
            .iter()
            .filter_map(|pts| fit_sphere_radius(pts, radius, &fit.centre).map(|f| f.centre))
            .collect();
        let (spread_rms, spread_max) =
            rms_max(pose_centres.iter().map(|c| (c - fit.centre).norm()));
        out.stations.push(StationCheck {
            station: station.clone(),
            poses: poses.len(),
            size_error: 2.0 * fit.radius - diameter,
            fit,
            pose_centres,
            spread_rms,
            spread_max,
        });
    }
    let centre = |id: &str| {
        out.stations
            .iter()
            .find(|s| s.station == id)
            .map(|s| s.fit.centre)
    };
    let mut spacings = Vec::new();
    for r in references {
        if let (Some(a), Some(b)) = (centre(&r.from), centre(&r.to)) {
            spacings.push(Spacing {
                from: r.from.clone(),
                to: r.to.clone(),
                measured: (a - b).norm(),
                reference: Some(r.distance),
            });
        }
    }
    if spacings.is_empty() {
        for pair in out.stations.windows(2) {
            spacings.push(Spacing {
                from: pair[0].station.clone(),
                to: pair[1].station.clone(),
                measured: (pair[0].fit.centre - pair[1].fit.centre).norm(),
                reference: None,
            });
        }
    }
    out.spacings = spacings;
    out
}

/// The self-validation of the sphere stations among `poses` (module doc)
/// under `before` and `after`; `None` when no station has a sphere fit.
#[must_use]
pub fn self_validate<P: Sighted>(
    poses: &[P],
    before: &CellModel,
    after: &CellModel,
    diameter: f64,
    references: &[ReferenceDistance],
) -> Option<SelfValidation> {
    let stations = stations(poses);
    let after_check = check(&stations, after, diameter, references);
    if after_check.stations.is_empty() {
        return None;
    }
    Some(SelfValidation {
        diameter,
        before: check(&stations, before, diameter, references),
        after: after_check,
    })
}

impl SelfValidation {
    /// A few lines for people: the figures before and after.
    #[must_use]
    pub fn summary(&self) -> String {
        use std::fmt::Write as _;
        let mut s = String::new();
        let _ = writeln!(
            s,
            "self-validation: the {} mm sphere at {} station(s), base frame (ISO 10360-8-style; rms / max, mm):",
            self.diameter,
            self.after.stations.len()
        );
        let _ = writeln!(s, "  {:<38} {:>17} {:>17}", "", "before", "after");
        let row = |s: &mut String, what: &str, b: (f64, f64), a: (f64, f64)| {
            let _ = writeln!(
                s,
                "  {what:<38} {:>8.4} / {:<6.4} {:>8.4} / {:<6.4}",
                b.0, b.1, a.0, a.1
            );
        };
        row(
            &mut s,
            "size error (diameter)",
            self.before.size(),
            self.after.size(),
        );
        row(
            &mut s,
            "form error (range of radial residuals)",
            self.before.form(),
            self.after.form(),
        );
        row(
            &mut s,
            "position spread (each pose's centre)",
            self.before.spread(),
            self.after.spread(),
        );
        if let (Some(b), Some(a)) = (self.before.spacing_error(), self.after.spacing_error()) {
            let n = self
                .after
                .spacings
                .iter()
                .filter(|x| x.reference.is_some())
                .count();
            row(
                &mut s,
                &format!("spacing error ({n} reference distances)"),
                b,
                a,
            );
        } else if !self.after.spacings.is_empty() {
            let _ = writeln!(
                s,
                "  distances between consecutive spheres (no reference): {}",
                self.after
                    .spacings
                    .iter()
                    .map(|x| format!("{}–{} {:.4}", x.from, x.to, x.measured))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
        s
    }
}
