//! What the Measure view shows: the measuring job in flight, the cloud
//! on show with its decimated view and figures (made on the job thread,
//! never per frame), and the exports in flight. Changed only by the
//! Measure feature's commands and job messages.

use std::collections::BTreeSet;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use crate::app::error::JobError;
use crate::app::provenance::Stamp;
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

/// The measuring job in flight.
#[derive(Debug, Clone)]
pub struct MeasureJob {
    /// Its number (messages of other jobs are not its own).
    pub id: u64,
    /// Set to stop it at its next pose.
    pub cancel: Arc<AtomicBool>,
    /// When it started.
    pub started: Instant,
    /// What it is doing, in words.
    pub phase: String,
    /// Fraction of the job done, 0…1.
    pub fraction: f64,
    /// The inputs it started from (its cloud's provenance).
    pub stamp: Stamp,
}

/// What a Measure view file dialog is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeasureDialog {
    /// The session file to measure.
    SessionFile,
    /// A raw scan's pose log.
    Log,
    /// A raw scan's profiles folder.
    Profiles,
    /// The workpiece frame file.
    Frame,
    /// A sphere artefact's reference distances CSV.
    References,
    /// Where to export the cloud (a save dialog; writes once chosen).
    Export,
}

/// The Measure view's state.
#[derive(Debug, Default)]
pub struct MeasureView {
    /// The job in flight.
    pub job: Option<MeasureJob>,
    /// Jobs started so far (each job's number).
    pub jobs_started: u64,
    /// Cancelled jobs whose thread has not ended yet: what they send is
    /// dropped.
    pub stopping: BTreeSet<u64>,
    /// The outcome of the job in flight, arrived this frame: shown after
    /// the frame's commands, so that a Cancel clicked in that frame wins.
    pub arrived: Option<(u64, Result<Box<MeasuredCloud>, MeasureFailure>)>,
    /// The cloud on show.
    pub shown: Option<MeasuredCloud>,
    /// The last job's error, until the next job.
    pub failure: Option<String>,
    /// Exports being written.
    pub writing: usize,
    /// A file dialog of the view is open.
    pub dialog: bool,
    /// The last dialog of the view chose nothing (or none is available).
    pub dialog_empty: Option<MeasureDialog>,
}

impl MeasureView {
    /// True while a job, a cancelled job's thread, an export or a dialog
    /// is in flight.
    #[must_use]
    pub fn is_busy(&self) -> bool {
        self.job.is_some()
            || !self.stopping.is_empty()
            || self.arrived.is_some()
            || self.writing > 0
            || self.dialog
    }
}
