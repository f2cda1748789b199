//! Why a job of the workbench failed, with the engine's error as its
//! source. The workbench shows the message (naming the file and the
//! measurement) in the status line or a notice; nothing is lost to a
//! string on the way.

use std::path::PathBuf;

use crate::engine::base::session::ExcludeError;
use crate::engine::calibrate::solve::SolveError;
use crate::engine::files::format::FileError;
use crate::engine::files::import::ImportError;
use crate::engine::tools::history::HistoryError;
use crate::engine::tools::plan::{PlanError, RequestError};
use crate::engine::tools::report::model::ExportError;
use crate::engine::tools::result_view::ReportError;
use crate::engine::tools::simulate::SimError;

/// A failed job.
#[derive(Debug, thiserror::Error)]
pub enum JobError {
    /// A file could not be read, written or loaded.
    #[error(transparent)]
    File(#[from] FileError),
    /// The calibration could not run.
    #[error(transparent)]
    Solve(#[from] SolveError),
    /// Leaving the chosen measurements out breaks a session rule.
    #[error("the session without the left-out measurements is not valid: {0}")]
    Excluded(#[from] ExcludeError),
    /// The import failed.
    #[error(transparent)]
    Import(#[from] ImportError),
    /// The history library could not be scanned, or no drift computed.
    #[error(transparent)]
    History(#[from] HistoryError),
    /// The planner failed.
    #[error(transparent)]
    Plan(#[from] PlanError),
    /// The plan request is not complete.
    #[error(transparent)]
    Request(#[from] RequestError),
    /// A session could not be simulated from the plan.
    #[error(transparent)]
    Simulate(#[from] SimError),
    /// The result does not belong to the open session.
    #[error("the report was not written: {0}")]
    Report(#[from] ReportError),
    /// The calibrated model cannot be exported.
    #[error("the model cannot be exported: {0}")]
    Model(#[from] ExportError),
    /// The plots' PNG could not be made.
    #[error("{0}")]
    Png(String),
    /// A job that needs a file dialog, a screenshot or a session found
    /// none: what is missing.
    #[error("{0}")]
    Missing(String),
    /// A file exists where a folder is needed, or the like.
    #[error("{what} ({})", path.display())]
    Path {
        /// What is wrong.
        what: String,
        /// The path.
        path: PathBuf,
    },
    /// A scan could not be measured.
    #[error(transparent)]
    Measure(#[from] crate::engine::uses::measure::MeasureError),
}
