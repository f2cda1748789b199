//! What the Measure view's jobs report: progress and the cloud of a
//! measuring job (by its number: a cancelled job's messages are
//! dropped), an export written, a file dialog closed.

use std::path::PathBuf;

use crate::app::error::JobError;
use crate::app::provenance::Stamp;
use crate::app::state::measure::{MeasureDialog, MeasureFailure, MeasuredCloud};
use crate::engine::uses::measure::CloudFormat;

/// What the Measure jobs report.
#[derive(Debug)]
pub enum MeasureMessage {
    /// The job reached another phase or pose.
    Progress {
        /// Which job.
        job: u64,
        /// What it is doing, in words.
        phase: String,
        /// Fraction of the job done, 0…1.
        fraction: f64,
    },
    /// The job ended.
    Finished {
        /// Which job.
        job: u64,
        /// The cloud, or why there is none.
        outcome: Result<Box<MeasuredCloud>, MeasureFailure>,
    },
    /// A cloud file was written, or why not.
    Written {
        /// Target file.
        path: PathBuf,
        /// Its format.
        format: CloudFormat,
        /// Success or why not.
        outcome: Result<(), JobError>,
        /// The inputs of the cloud it was written from.
        stamp: Stamp,
    },
    /// A file dialog of the view closed; `None` when it chose nothing or
    /// could not open.
    Dialog {
        /// What it was for.
        purpose: MeasureDialog,
        /// The chosen path.
        path: Option<PathBuf>,
    },
}
