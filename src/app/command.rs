//! What the views ask the workbench to do, by feature. A `*_ui` function
//! reads the state, draws, and pushes [`Command`]s; the workbench hands
//! each to its feature's handler after the frame's drawing (rerun's
//! `SystemCommand`).

use std::path::PathBuf;

use super::dialog::Purpose;
use crate::engine::tools::plan::Controller;

/// A request from the UI, by the feature that handles it.
#[derive(Debug, Clone, PartialEq)]
pub enum Command {
    /// Opening and saving files.
    Files(FilesCommand),
    /// Show a native file dialog (on a job thread) for a path field.
    Browse(Purpose),
    /// The answer to "replace this file?": replace it (the write is
    /// asked for again), or keep it.
    Confirm(bool),
    /// The session on show: views, selection, measurements left out.
    View(ViewCommand),
    /// The calibration run.
    Run(RunCommand),
    /// Write one export file of the result into the export folder.
    Export(ExportKind),
    /// The import wizard.
    Import(ImportCommand),
    /// The library of past results.
    History(HistoryCommand),
    /// The pose planner.
    Plan(PlanCommand),
    /// The Compensate view.
    Compensate(CompensateCommand),
    /// The Measure view.
    Measure(MeasureCommand),
    /// The Re-check view.
    Check(CheckCommand),
    /// A file for the controller or the planner from the result on show
    /// (tool data, the robot's URDF back, UR's calibration).
    UseExport(UseExport),
    /// Run the calibration with these settings (the solver panel's are
    /// set to them first): "Run again with threshold 0".
    RunWith(Box<crate::engine::calibrate::solve::Options>),
    /// A command given by the step bar's Next: a run it starts opens
    /// Results (the verdict) when it ends.
    Next(Box<Command>),
}

/// The Re-check view.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CheckCommand {
    /// Plan the check poses for the result on show (`plan --check`).
    Plan,
    /// Stop the job in flight (planning or checking).
    Cancel,
    /// Write the check's plan into the export folder.
    Export(PlanExport),
    /// Test the check session against the result on show.
    Run,
    /// Write the check's record (`X.check.json` beside the session).
    Record,
}

/// Opening and saving files.
#[derive(Debug, Clone, PartialEq)]
pub enum FilesCommand {
    /// Open the embedded demo session.
    OpenDemo,
    /// Open a file: a session, or a result to review (told apart by its
    /// `format` key).
    OpenPath(PathBuf),
    /// Write the session without the left-out measurements to the path
    /// field's file (atomic; asks before overwriting).
    SaveSession,
    /// Empty the recent-files list.
    ClearRecent,
}

/// The session on show.
#[derive(Debug, Clone, PartialEq)]
pub enum ViewCommand {
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
    /// Close the error notice.
    DismissNotice,
    /// Close the first-start "what to do" (remembered).
    DismissIntro,
    /// Set or clear the open session's measuring range (`sensor.range`);
    /// kept with the session when it is saved, used by the next run.
    SetSensorRange(Option<crate::engine::base::session::SensorRange>),
    /// Set the acceptance tolerance (remembered for the session's robot).
    SetTolerance(crate::engine::tools::result_view::Tolerance),
    /// After a FAIL: show the measurements the solver flagged as
    /// outliers (Results view, its "after a FAIL" box).
    ShowOutliers,
}

/// The calibration run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RunCommand {
    /// Start the solver with the form's settings.
    Start,
    /// Ask a running solver to stop.
    Cancel,
}

/// The import wizard.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImportCommand {
    /// Read the joint log's header, guess the mapping and preview the
    /// first rows.
    Preview {
        /// Overwrite the mapping fields with the guesses from the header.
        guess: bool,
    },
    /// Build the session from the import form and open it.
    Run,
    /// Stop the import in flight; nothing is opened.
    Cancel,
    /// Read the pose file and pair it with the profiles or centres (the
    /// preview shown before Import).
    Scan,
}

/// The library of past results.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HistoryCommand {
    /// Scan the History form's folder (its drift follows).
    Scan,
}

/// The pose planner.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlanCommand {
    /// Make a plan with the Plan form's settings (and predict it).
    Make,
    /// Stop the planning job.
    Cancel,
    /// Write the plan into the export folder.
    Export(PlanExport),
    /// Simulate a session of the plan and open it.
    Simulate,
    /// After a FAIL: open the Plan view set for the open session's robot
    /// with more identify stations than the session has.
    MoreStations,
}

/// The Compensate view.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CompensateCommand {
    /// Compensate the form's targets file through the result on show.
    Run,
    /// Stop the compensation job (what it sends later is dropped).
    Cancel,
    /// Write the compensated file to the form's output path (refused when
    /// the compensation is stale or the targets had errors).
    Write,
    /// The guide's example targets (`examples/targets.csv`, for the demo's
    /// cell) written to the export folder, chosen, and compensated.
    ExampleTargets,
}

/// The Measure view.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeasureCommand {
    /// Measure the form's scan with the result on show (a job).
    Start,
    /// Stop the measuring job; the cloud on show stays.
    Cancel,
    /// Write the cloud on show to the form's export path (format by its
    /// extension).
    Export,
}

/// What the Plan view writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlanExport {
    /// The plan as the joint-log CSV `spherecal import` reads.
    Csv,
    /// The robot controller's program (RAPID for ABB, URScript for UR).
    Program(Controller),
}

impl PlanExport {
    /// The button text.
    #[must_use]
    pub fn label(self) -> &'static str {
        match self {
            Self::Csv => "Plan CSV",
            Self::Program(c) => c.label(),
        }
    }

    /// The file name for a robot key.
    #[must_use]
    pub fn file_name(self, robot: &str) -> String {
        match self {
            Self::Csv => format!("plan-{robot}.csv"),
            Self::Program(c) => format!("plan-{robot}.{}", c.extension()),
        }
    }
}

/// Things to export from the Results view.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExportKind {
    /// The FORMAT.md result file.
    ResultJson,
    /// Every sphere centre, before and after, CSV.
    CentresCsv,
    /// Reference-distance and within-station distance errors, CSV.
    DistancesCsv,
    /// The Results view's plots as an image.
    PlotsPng,
    /// The calibrated model as the FORMAT.md `robot` block (deg, mm).
    ModelJson,
    /// The calibrated MDH table and matrices, CSV (deg, mm).
    ModelCsv,
    /// A URDF fragment with the calibrated joint origins (m, rad).
    ModelUrdf,
    /// The self-contained HTML report (inline SVG figures).
    ReportHtml,
}

impl ExportKind {
    /// All kinds, in the order of the export buttons.
    pub const ALL: [Self; 8] = [
        Self::ReportHtml,
        Self::ResultJson,
        Self::CentresCsv,
        Self::DistancesCsv,
        Self::PlotsPng,
        Self::ModelJson,
        Self::ModelCsv,
        Self::ModelUrdf,
    ];

    /// The button text and the file name's suffix.
    fn words(self) -> (&'static str, &'static str) {
        match self {
            Self::ResultJson => ("Result JSON", "result.json"),
            Self::CentresCsv => ("Centres CSV", "centres.csv"),
            Self::DistancesCsv => ("Distances CSV", "distances.csv"),
            Self::PlotsPng => ("Plots PNG", "plots.png"),
            Self::ModelJson => ("Model JSON", "model.json"),
            Self::ModelCsv => ("Model CSV", "model.csv"),
            Self::ModelUrdf => ("Model URDF", "model.urdf"),
            Self::ReportHtml => ("Report HTML", "report.html"),
        }
    }

    /// The button text.
    #[must_use]
    pub fn label(self) -> &'static str {
        self.words().0
    }

    /// The file name for a session stem.
    #[must_use]
    pub fn file_name(self, stem: &str) -> String {
        format!("{stem}-{}", self.words().1)
    }
}

/// A file of the result on show for the controller or the planner
/// (`spherecal export-model --format tool|urdf --robot|ur-calibration`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UseExport {
    /// The calibrated hand-eye as a controller's tool data (or ROS 2's).
    Tool(crate::engine::tools::report::tool_data::ToolTarget),
    /// The URDF the robot came from, with the calibrated joint origins
    /// and a `sensor` link.
    UrdfBack,
    /// Universal Robots' calibration YAML.
    UrCalibration,
}

impl UseExport {
    /// The button text.
    #[must_use]
    pub fn label(self) -> String {
        match self {
            Self::Tool(t) => format!("Tool data {}", t.key().to_uppercase()),
            Self::UrdfBack => "URDF back".to_string(),
            Self::UrCalibration => "UR calibration".to_string(),
        }
    }

    /// The file name for a session stem.
    #[must_use]
    pub fn file_name(self, stem: &str) -> String {
        match self {
            Self::Tool(t) => format!("{stem}-tool-{}.txt", t.key()),
            Self::UrdfBack => format!("{stem}-calibrated.urdf"),
            Self::UrCalibration => format!("{stem}-ur_calibration.yaml"),
        }
    }
}

/// The central views.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Tab {
    /// The measurement table.
    #[default]
    Session,
    /// One stripe and its circle.
    Stripe,
    /// Sphere centres in the base frame.
    Centres,
    /// Plots and tables of a result.
    Results,
    /// The import wizard: joint log and profiles to a session.
    Import,
    /// The library of past results and the drift of one robot.
    History,
    /// The pose planner.
    Plan,
    /// Targets and programs compensated through the result on show.
    Compensate,
    /// Scans measured with the calibrated cell: the point cloud.
    Measure,
    /// The five-minute re-check of a calibrated cell.
    Check,
}

impl Tab {
    /// All tabs, in the order of the job: plan the poses, bring the data
    /// in, check the stripes and centres, calibrate and validate, measure
    /// with the calibrated cell, compensate the robot's targets, follow the
    /// cell over time.
    pub const ALL: [Self; 10] = [
        Self::Plan,
        Self::Import,
        Self::Session,
        Self::Stripe,
        Self::Centres,
        Self::Results,
        Self::Measure,
        Self::Compensate,
        Self::Check,
        Self::History,
    ];

    /// The tab's title.
    #[must_use]
    pub fn label(self) -> &'static str {
        match self {
            Self::Session => "Session",
            Self::Stripe => "Stripe",
            Self::Centres => "Centres",
            Self::Results => "Results",
            Self::Import => "Import",
            Self::History => "History",
            Self::Plan => "Plan",
            Self::Compensate => "Compensate",
            Self::Measure => "Measure",
            Self::Check => "Re-check",
        }
    }
}
