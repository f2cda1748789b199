//! The fields the widgets edit in place ([`Forms`]): text fields, filters,
//! the settings of the next run, view options, and the forms of the
//! import wizard, the History view and the Plan view. Nothing here runs a
//! job; the features read these when a command comes.

pub mod compensate;
pub mod import;
pub mod measure;
pub mod plan;

use std::collections::BTreeSet;
use std::path::PathBuf;

use crate::engine::base::session::{Session, Use};
use crate::engine::calibrate::solve::paper::{DEFAULT_SVD_TOLERANCE, Pairing, PaperOptions};
use crate::engine::calibrate::solve::{Method, Options};
use crate::engine::tools::history::DEFAULT_K;
pub use compensate::CompensateForm;
pub use import::{ImportForm, ProfilesKind};
pub use plan::PlanForm;

/// The solver settings as the form edits them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverForm {
    /// Identification method.
    pub method: Method,
    /// Pairing of a station's measurements (paper's method).
    pub pairing: Pairing,
    /// Stop when ε ≤ this, mm.
    pub threshold: f64,
    /// Most updates.
    pub max_iterations: usize,
    /// Relative SVD truncation tolerance (fraction of σ_max).
    pub svd_tolerance: f64,
}

impl Default for SolverForm {
    fn default() -> Self {
        Self {
            method: Method::ALL[0],
            pairing: Pairing::Disjoint,
            threshold: crate::engine::base::session::DEFAULT_THRESHOLD,
            max_iterations: crate::engine::base::session::DEFAULT_MAX_ITERATIONS,
            svd_tolerance: DEFAULT_SVD_TOLERANCE,
        }
    }
}

impl SolverForm {
    /// The session's settings (threshold and iteration bound from its file).
    #[must_use]
    pub fn from_session(session: &Session) -> Self {
        let o = Options::from_session(session);
        Self {
            method: o.method,
            pairing: o.paper.pairing,
            threshold: o.threshold,
            max_iterations: o.max_iterations,
            svd_tolerance: o.paper.svd_tolerance,
        }
    }

    /// The engine options these settings stand for.
    #[must_use]
    pub fn options(&self, session: &Session) -> Options {
        let mut o = Options::from_session(session);
        o.method = self.method;
        o.threshold = self.threshold;
        o.max_iterations = self.max_iterations;
        o.paper = PaperOptions {
            pairing: self.pairing,
            svd_tolerance: self.svd_tolerance,
        };
        o
    }
}

/// The central views.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tab {
    /// The measurement table.
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
}

impl Tab {
    /// All tabs, in the order of the job: plan the poses, bring the data
    /// in, check the stripes and centres, calibrate and validate, measure
    /// with the calibrated cell, compensate the robot's targets, follow the
    /// cell over time.
    pub const ALL: [Self; 9] = [
        Self::Plan,
        Self::Import,
        Self::Session,
        Self::Stripe,
        Self::Centres,
        Self::Results,
        Self::Measure,
        Self::Compensate,
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
        }
    }
}

/// How the session table groups its rows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Grouping {
    /// File order.
    None,
    /// By station, stations in order of first appearance.
    Station,
    /// By use (translation, rotation, identify, validate).
    Use,
}

impl Grouping {
    /// All groupings.
    pub const ALL: [Self; 3] = [Self::None, Self::Station, Self::Use];

    /// Display text.
    #[must_use]
    pub fn label(self) -> &'static str {
        match self {
            Self::None => "file order",
            Self::Station => "station",
            Self::Use => "use",
        }
    }
}

/// The camera of the 3D centres view (orthographic, orbiting the centres).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Rotation about the base z axis, rad.
    pub yaw: f32,
    /// Elevation above the base xy plane, rad.
    pub pitch: f32,
    /// Zoom factor (1 = fit all).
    pub zoom: f32,
}

impl Default for Camera {
    fn default() -> Self {
        Self {
            yaw: -0.6,
            pitch: 0.5,
            zoom: 1.0,
        }
    }
}

/// Display options of the centres view.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CentresForm {
    /// Draw the centres before calibration.
    pub show_before: bool,
    /// Draw the centres after calibration.
    pub show_after: bool,
    /// Draw each centre's deviation from its station mean magnified by
    /// `magnify`, placed at the station mean.
    pub relative: bool,
    /// Magnification of the deviations in relative mode.
    pub magnify: f32,
    /// The orbit camera.
    pub camera: Camera,
}

impl Default for CentresForm {
    fn default() -> Self {
        Self {
            show_before: true,
            show_after: true,
            relative: true,
            magnify: 50.0,
            camera: Camera::default(),
        }
    }
}

/// Fields the widgets edit in place: text fields, filters, settings of
/// the next run, view options.
#[derive(Debug, Clone, PartialEq)]
pub struct Forms {
    /// The current tab.
    pub tab: Tab,
    /// The path field of the load panel.
    pub open_path: String,
    /// Where "Save as" writes the edited session.
    pub save_path: String,
    /// The export folder.
    pub export_dir: String,
    /// Session table: only this station.
    pub filter_station: Option<String>,
    /// Session table: only this use.
    pub filter_use: Option<Use>,
    /// Session table grouping.
    pub group: Grouping,
    /// Session table: only measurements with a stripe warning or failure.
    pub filter_problems: bool,
    /// Session table: only ids (or stations) containing this text.
    pub search: String,
    /// The measuring range being edited in the Session view, `[y0, y1,
    /// z0, z1]` mm; `None`: the session's (or the default) on show.
    pub range_edit: Option<[f64; 4]>,
    /// Settings of the next run.
    pub solver: SolverForm,
    /// Centres view options.
    pub centres: CentresForm,
    /// The import wizard's fields.
    pub import: ImportForm,
    /// The History view's fields.
    pub history: HistoryForm,
    /// The Plan view's fields.
    pub plan: PlanForm,
    /// The acceptance tolerance the headline's PASS/FAIL and the report
    /// use (remembered per robot in the preferences).
    pub tolerance: crate::engine::tools::result_view::Tolerance,
    /// Scroll the Results view to its "after a FAIL" box once (set by
    /// Next's "Look at the outliers").
    pub focus_after_fail: bool,
    /// The Compensate view's fields.
    pub compensate: CompensateForm,
    /// The Measure view's fields.
    pub measure: measure::MeasureForm,
}

impl Default for Forms {
    fn default() -> Self {
        Self {
            tab: Tab::Session,
            open_path: String::new(),
            save_path: String::new(),
            export_dir: String::new(),
            filter_station: None,
            filter_use: None,
            group: Grouping::None,
            filter_problems: false,
            search: String::new(),
            range_edit: None,
            solver: SolverForm::default(),
            centres: CentresForm::default(),
            import: ImportForm::default(),
            history: HistoryForm::default(),
            plan: PlanForm::default(),
            tolerance: crate::engine::tools::result_view::Tolerance::default(),
            focus_after_fail: false,
            compensate: CompensateForm::default(),
            measure: measure::MeasureForm::default(),
        }
    }
}

/// The History view's fields.
#[derive(Debug, Clone, PartialEq)]
pub struct HistoryForm {
    /// The library folder.
    pub folder: String,
    /// The robot whose drift is shown.
    pub robot: Option<String>,
    /// Result files left out of the drift (unticked in the table).
    pub unselected: BTreeSet<PathBuf>,
    /// Flag a change beyond `k` combined σ.
    pub k: f64,
}

impl Default for HistoryForm {
    fn default() -> Self {
        Self {
            folder: String::new(),
            robot: None,
            unselected: BTreeSet::new(),
            k: DEFAULT_K,
        }
    }
}

/// The sensor's no-return value as a form field holds it (profile file
/// units): `None` when the field is empty.
///
/// # Errors
/// The message to show when the text is not a finite number.
pub(crate) fn no_return(text: &str) -> Result<Option<f64>, String> {
    match text.trim() {
        "" => Ok(None),
        text => text
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .map(Some)
            .ok_or_else(|| format!("the no-return value `{text}` is not a number")),
    }
}
