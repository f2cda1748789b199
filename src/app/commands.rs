//! What the panels ask the workbench to do. A `*_ui` function reads the
//! state, draws, and pushes [`Command`]s; the workbench applies them after
//! the frame's drawing (rerun's `SystemCommand`).

use std::path::PathBuf;

use super::state::{DialogPurpose, ExportKind, PlanExport, Tab};

/// A request from the UI.
#[derive(Debug, Clone, PartialEq)]
pub enum Command {
    /// Open the embedded demo session.
    OpenDemo,
    /// Open a file: a session, or a result to review (told apart by its
    /// `format` key).
    OpenPath(PathBuf),
    /// Show a native file dialog (on a background thread).
    Browse(DialogPurpose),
    /// Switch the central view.
    ShowTab(Tab),
    /// Select a measurement (index into the session's measurements).
    Select(usize),
    /// Select the previous (−1) or next (+1) measurement of the table's order.
    Step(i32),
    /// Select a measurement and show its stripe.
    Inspect(usize),
    /// Use or leave out a measurement (by id).
    SetIncluded {
        /// Measurement id.
        id: String,
        /// True to use it.
        included: bool,
    },
    /// Use or leave out every measurement of a station.
    SetStationIncluded {
        /// Station id.
        station: String,
        /// True to use them.
        included: bool,
    },
    /// Use every measurement again.
    IncludeAll,
    /// Write the session without the left-out measurements to the path
    /// field's file (atomic; asks before overwriting).
    SaveSession,
    /// Start the solver with the form's settings.
    Run,
    /// Ask a running solver to stop.
    Cancel,
    /// Write one export file into the export folder.
    Export(ExportKind),
    /// Close the error notice.
    DismissNotice,
    /// Empty the recent-files list.
    ClearRecent,
    /// Read the joint log's header, guess the mapping and preview the
    /// first rows.
    ImportPreview {
        /// Overwrite the mapping fields with the guesses from the header.
        guess: bool,
    },
    /// Build the session from the import form and open it.
    ImportRun,
    /// Scan the History form's folder.
    HistoryScan,
    /// Recompute the drift after the robot, the ticks or `k` changed.
    HistoryDrift,
    /// Make a plan with the Plan form's settings (and predict it).
    PlanMake,
    /// Stop the planning job.
    PlanCancel,
    /// Write the plan into the export folder.
    PlanExport(PlanExport),
    /// Simulate a session of the plan and open it.
    PlanSimulate,
}
