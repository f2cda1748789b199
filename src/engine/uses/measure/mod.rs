//! Measuring with the calibrated cell (beyond the paper): every profile
//! point of a scan into the robot base frame, or a workpiece frame,
//! through a result's calibrated model and hand-eye, each point with the
//! 1σ of its position, written as PLY, E57 or CSV; and the cell's check
//! of itself with its own scanner.
//!
//! # The transform
//!
//! A profile point `X_s = (0, y, z)` (mm, laser plane of the sensor
//! frame) seen at a pose lands at (FORMAT.md, paper eq. 1-2)
//!
//! ```text
//! X_b = bT_e(q) · eT_s · X_s      bT_e(q) = B · T_1(q_1) · … · T_n(q_n) · F
//! ```
//!
//! with the result's calibrated modified-DH model (Hayati's `β`, the base
//! `B` and flange `F` frames) and hand-eye `eT_s`. A pose given as the
//! controller's flange pose (a pose-only result, or `--poses`) uses that
//! pose for `bT_e`. With a workpiece frame `W = base_from_workpiece` (a
//! 4×4 file, [`load_frame`]) the points are `W⁻¹ · X_b`.
//!
//! # The uncertainty of a point
//!
//! `sigma_mm` is the 1σ of the point's 3-D position (the square root of
//! the trace of its 3 × 3 covariance) propagated from the covariance of
//! the calibrated parameters that `ml` writes (`solver.covariance`: the
//! hand-eye and the identifiable MDH parameters), to first order, scaled
//! by the result's a posteriori variance factor (`solver.variance_factor`,
//! ≈ 1 when `ml`'s noise model fits the data; a cell whose joints or
//! stripes are noisier than the model assumed has a larger one, and its
//! parameters are that much less certain). The
//! base frame itself is **not identifiable from a sphere**: moving the
//! whole cell rigidly moves every sphere centre alike and changes no
//! distance, so no calibration against a sphere knows where the base is
//! to better than the nominal model says, and a measured part is aligned
//! to its drawing anyway. As `ml`'s range prediction does, σ is therefore
//! taken **after the best rigid alignment of the whole cloud** (every
//! point of every pose, weighted alike): it is the error of the cloud's
//! shape, the part that no alignment removes. [`sigma`] holds the
//! algebra; it costs a step per pose and O(1) per point.
//!
//! Not in σ: the scan's own joint-reading noise (the robot's
//! repeatability at each pose) and, unless given (`sensor_noise_mm`, the
//! 1σ of each in-plane coordinate of a profile point, added in
//! quadrature as `2·s²`), the sensor's noise. A result without a
//! covariance (the paper's method) gives no σ.
//!
//! # Parts
//!
//! [`scan`] (what is measured: a session's stripes, or a raw scan's pose
//! log and profiles), [`model`] (the cell from the result; the checks
//! that a scan belongs to it), [`sigma`], [`cloud`] (the measured cloud,
//! its decimated view), [`sphere`] (least-squares sphere fits),
//! [`selfcheck`] (ISO 10360-8-style figures before and after
//! calibration), [`write`] (PLY, E57, CSV); [`entry`] the one entry the
//! command line and the workbench call ([`measure_scan`]).

pub mod cloud;
pub mod entry;
pub mod model;
pub mod scan;
pub mod selfcheck;
pub mod sigma;
pub mod sphere;
pub mod write;

use std::path::Path;

use nalgebra::Isometry3;

pub use cloud::{Cloud, CloudPoint, CloudPose, FrameLabel, SigmaStats};
pub use entry::{LISTED_POSES, MeasureRequest, Outcome, ScanSource, listed, measure_scan};
pub use model::{CellModel, JointRange, ModelChoice, OutOfRange, covariance_of};
pub use scan::{
    Dropped, Placement, Scan, ScanColumns, ScanFiles, ScanLog, ScanPose, scan_from_files,
};
pub use selfcheck::{SelfValidation, self_validate};
pub use sigma::SigmaForm;
pub use write::{CloudFormat, Provenance, write_cloud};

use crate::engine::base::robot::Robot;
use crate::engine::calibrate::solve::Control;
use crate::engine::calibrate::solve::estimate::Estimate;
use crate::engine::files::format::{FileError, ResultFile, read_transform};
use crate::engine::files::import::ImportError;

/// A measurement could not be made.
#[derive(Debug, thiserror::Error)]
pub enum MeasureError {
    /// The inputs do not fit together or break a rule (a scan from another
    /// robot, a result without covariance, a frame that is not rigid).
    #[error("{0}")]
    Input(String),
    /// A raw scan's file could not be read.
    #[error(transparent)]
    Import(#[from] ImportError),
    /// A session, result or output file could not be read or written.
    #[error(transparent)]
    File(#[from] FileError),
    /// The progress callback cancelled.
    #[error("the measurement was cancelled")]
    Cancelled,
}

/// How to measure.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MeasureOptions {
    /// Which of the result's models places the sensor.
    pub model: ModelChoice,
    /// The workpiece frame `base_from_workpiece` and what to call it;
    /// `None`: the base frame.
    pub frame: Option<(Isometry3<f64>, String)>,
    /// Compute σ from the result's covariance (refused when it has none).
    pub sigma: bool,
    /// The sensor's own noise: 1σ of each in-plane coordinate of a profile
    /// point, mm (0: not added).
    pub sensor_noise_mm: f64,
    /// Use `solver.covariance` as written; by default it is scaled by the
    /// result's variance factor (module doc).
    pub covariance_as_written: bool,
}

impl MeasureOptions {
    /// What σ rests on, in words: "covariance × variance factor 1.031"
    /// (or "as written"), and the sensor noise when it is added.
    #[must_use]
    pub fn sigma_basis(&self, result: &ResultFile) -> String {
        let mut basis = if self.covariance_as_written {
            "covariance as written".to_string()
        } else {
            format!(
                "covariance × variance factor {:.3}",
                variance_factor(result)
            )
        };
        if self.sensor_noise_mm > 0.0 {
            let noise = crate::engine::base::numeric::show(self.sensor_noise_mm);
            basis.push_str(&format!(", sensor noise {noise} mm"));
        }
        basis
    }
}

/// What a measurement is doing, for a progress display.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// Reading the scan ([`measure_scan`]).
    Reading,
    /// Placing the sensor at each pose.
    Poses,
    /// The σ of each pose (two passes over the poses).
    Sigma,
    /// Waiting for the self-validation ([`measure_scan`]).
    SelfCheck,
}

/// How far a measurement is: `done` of `of` steps of `stage`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MeasureProgress {
    /// The stage.
    pub stage: Stage,
    /// Steps done.
    pub done: usize,
    /// Steps in the stage.
    pub of: usize,
}

/// A measured cloud and what was noticed on the way.
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    /// The cloud (shared: the workbench keeps it on show while an export
    /// job writes it).
    pub cloud: std::sync::Arc<Cloud>,
    /// Warnings (e.g. only the hand-eye applies to flange poses).
    pub warnings: Vec<String>,
    /// Scan poses outside the joint range the calibration saw.
    pub out_of_range: Vec<OutOfRange>,
}

/// The result's a posteriori variance factor (`ml`'s `variance_factor`,
/// Σ r² / (residuals − unknowns) of the whitened residuals: 1 when the
/// noise model fits), 1 when it has none or it is not a positive number.
#[must_use]
pub fn variance_factor(result: &ResultFile) -> f64 {
    crate::engine::calibrate::solve::ml::covariance::variance_factor(&result.solver)
}

/// Reads a workpiece frame: a JSON 4×4 matrix (four rows of four numbers,
/// FORMAT.md's matrices), `base_from_workpiece`, bare or under that key
/// ([`read_transform`], with its plausibility caps).
///
/// # Errors
/// [`MeasureError::Input`] naming the file: unreadable, not JSON, not
/// 4×4, not a rigid transform (orthonormal with determinant +1 to 1e-6,
/// last row `0 0 0 1`), or a translation beyond the plausibility limit.
pub fn load_frame(path: &Path) -> Result<Isometry3<f64>, MeasureError> {
    read_transform(path, "base_from_workpiece")
        .map_err(|e| MeasureError::Input(format!("the workpiece frame: {e} ({})", path.display())))
}

/// Measures `scan` with `result` (module doc): checks that the scan
/// belongs to the result ([`model::check_scan`]), lists the poses outside
/// `joint_range`, places the sensor at every pose, and computes each
/// pose's σ form. `progress` is asked after each pose of each stage;
/// [`Control::Cancel`] ends the measurement with
/// [`MeasureError::Cancelled`].
///
/// # Errors
/// [`MeasureError::Input`] for a scan that is not the result's robot's,
/// σ asked of a result without covariance (or of the nominal model), a
/// covariance that is not positive semi-definite; [`MeasureError::Cancelled`].
pub fn measure(
    scan: Scan,
    result: &ResultFile,
    options: &MeasureOptions,
    joint_range: Option<&JointRange>,
    progress: &mut dyn FnMut(&MeasureProgress) -> Control,
) -> Result<Measured, MeasureError> {
    let warnings = model::check_scan(&scan, result)?;
    let out_of_range = joint_range.map(|r| r.outside(&scan)).unwrap_or_default();
    let cell = CellModel::of_result(result, options.model);
    let covariance = if options.sigma {
        if options.model == ModelChoice::Nominal {
            return Err(MeasureError::Input(
                "σ is the calibrated model's; the nominal model has none (measure it without σ)"
                    .into(),
            ));
        }
        let mut cov = covariance_of(result)?.ok_or_else(|| {
            MeasureError::Input(format!(
                "the result (method {}) has no parameter covariance, so no point σ: calibrate with --method ml, or measure without σ (--no-sigma)",
                result.solver.method()
            ))
        })?;
        if !options.covariance_as_written {
            cov.matrix *= variance_factor(result);
        }
        Some(cov)
    } else {
        None
    };
    let workpiece_from_base = options
        .frame
        .as_ref()
        .map_or_else(Isometry3::identity, |(w, _)| w.inverse());
    let n = scan.poses.len();
    let mut base_from_sensor = Vec::with_capacity(n);
    for (i, pose) in scan.poses.iter().enumerate() {
        let t = cell.base_from_sensor(&pose.placement).ok_or_else(|| {
            MeasureError::Input(format!(
                "pose {}: joint readings, but the result has no robot model",
                pose.id
            ))
        })?;
        base_from_sensor.push(t);
        let step = MeasureProgress {
            stage: Stage::Poses,
            done: i + 1,
            of: n,
        };
        if progress(&step) == Control::Cancel {
            return Err(MeasureError::Cancelled);
        }
    }
    let forms: Vec<Option<SigmaForm>> = match &covariance {
        None => vec![None; n],
        Some(cov) => {
            let est = Estimate {
                robot: cell
                    .robot
                    .clone()
                    .unwrap_or_else(|| Robot::new(result.robot_name(), Vec::new())),
                flange_from_sensor: cell.flange_from_sensor,
                mount: crate::engine::base::session::Mount::Flange,
            };
            let inputs: Vec<sigma::SigmaPose> = scan
                .poses
                .iter()
                .zip(&base_from_sensor)
                .map(|(p, t)| sigma::SigmaPose {
                    placement: &p.placement,
                    base_from_sensor: *t,
                    moments: sigma::Moments::of(&p.points),
                })
                .collect();
            let mut cancelled = false;
            let forms = sigma::sigma_forms(&est, cov, &inputs, &mut |done, of| {
                let c = progress(&MeasureProgress {
                    stage: Stage::Sigma,
                    done,
                    of,
                });
                cancelled |= c == Control::Cancel;
                c
            });
            match forms {
                Some(f) => {
                    let noise = 2.0 * options.sensor_noise_mm * options.sensor_noise_mm;
                    f.into_iter().map(|s| Some(s.plus(noise))).collect()
                }
                None if cancelled => return Err(MeasureError::Cancelled),
                None => {
                    return Err(MeasureError::Input(
                        "solver.covariance is not positive semi-definite: no σ can be computed from it".into(),
                    ));
                }
            }
        }
    };
    let poses = scan
        .poses
        .into_iter()
        .zip(base_from_sensor)
        .zip(forms)
        .map(|((pose, t), form)| CloudPose::new(pose, workpiece_from_base * t, form))
        .collect();
    Ok(Measured {
        cloud: std::sync::Arc::new(Cloud {
            poses,
            frame: options
                .frame
                .as_ref()
                .map_or(FrameLabel::Base, |(_, label)| {
                    FrameLabel::Workpiece(label.clone())
                }),
            model: options.model.as_str(),
        }),
        warnings,
        out_of_range,
    })
}
