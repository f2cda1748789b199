//! What the Measure view shows: the cloud on show with its decimated
//! view and figures (made on the job thread, never per frame). Changed only by the
//! Measure feature's commands and job messages.

use std::sync::Arc;

use crate::app::error::JobError;
use crate::engine::uses::measure::{Cloud, CloudPoint, Dropped, SelfValidation, SigmaStats};

/// A cloud measured in the workbench, with what the view draws of it.
#[derive(Debug, Clone)]
pub struct MeasuredCloud {
    /// The whole cloud (what Export writes), shared with export jobs.
    pub cloud: Arc<Cloud>,
    /// At most [`crate::app::features::measure::DRAWN_MAX`] points spread
    /// evenly over the cloud, sorted by σ (largest drawn last, on top).
    pub drawn: Vec<CloudPoint>,
    /// Points in the cloud.
    pub points: usize,
    /// Poses in the cloud.
    pub poses: usize,
    /// Points dropped while reading (NaN, no-return), all poses.
    pub dropped: Dropped,
    /// Bounding box `(min, max)` of every point, mm, output frame.
    pub bounds: Option<([f64; 3], [f64; 3])>,
    /// σ over every point (rms, median, max), mm; `None` without σ.
    pub sigma: Option<SigmaStats>,
    /// The colour scale's ends, mm: smallest and largest σ of the drawn
    /// points.
    pub sigma_range: Option<(f64, f64)>,
    /// Why there is no σ, when there is none.
    pub no_sigma: Option<String>,
    /// How σ was scaled ("covariance × variance factor 1.031", sensor
    /// noise), for the caption.
    pub sigma_basis: String,
    /// The self-validation on the sphere stations, if the scan saw any.
    pub check: Option<SelfValidation>,
    /// Warnings of the measurement (flange poses, robots).
    pub warnings: Vec<String>,
    /// Poses outside the joint range the calibration saw, in words (the
    /// first few).
    pub out_of_range: Vec<String>,
    /// How many poses are outside that range.
    pub out_of_range_count: usize,
    /// Measurements without a profile (given centres), not in the cloud.
    pub skipped: usize,
    /// How the scan was read (axis map, units).
    pub notes: Vec<String>,
    /// What was measured, for people and the file header.
    pub scan: String,
    /// The result it was measured with, for people and the file header.
    pub result: String,
    /// The output frame, in words.
    pub frame: String,
    /// The model that placed the sensor (`calibrated`).
    pub model: &'static str,
    /// Wall time of the job, s.
    pub seconds: f64,
}

/// Why a measuring job gave no cloud.
#[derive(Debug)]
pub enum MeasureFailure {
    /// Cancel was pressed.
    Cancelled,
    /// The inputs or the engine failed.
    Failed(JobError),
}

/// The Measure view's state.
#[derive(Debug, Default)]
pub struct MeasureView {
    /// The cloud on show.
    pub shown: Option<MeasuredCloud>,
    /// The last job's error, until the next job.
    pub failure: Option<String>,
}
