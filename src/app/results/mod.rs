//! The result on show: its view model, built once off the UI thread from
//! the engine's outputs (the [`ResultView`] of a run and of a reviewed
//! file alike, both the typed [`ResultFile`], around the engine's shared
//! [`result_view`](crate::engine::tools::result_view)), the
//! [`CentreSet`] of the Centres view, the views that draw them ([`ui`]
//! with its figures, sets, tables, range map and the way forward after a
//! FAIL; [`centres`]), the exports ([`export`]) and the readings of the
//! result on show and of the tolerance its verdict is judged by.

pub mod centres;
pub mod export;
mod fail;
mod figures;
mod fixed;
pub mod range_map;
mod sets;
mod tables;
pub mod ui;

pub use fail::{MAX_IDENTIFY_STATIONS, more_stations};

use std::path::PathBuf;

use crate::engine::base::session::Session;
use crate::engine::files::format::ResultFile;
use crate::engine::tools::result_view::Tolerance;

use super::AppState;
use super::ledger::Reading;
pub use crate::engine::tools::result_view::{
    CALIBRATION_SET, CentrePoint, CentreSet, ErrorSet, HandEyeView, ResultFigures as Shown,
    Summary, VALIDATION_SET,
};

/// Where a result on show came from.
#[derive(Debug, Clone, PartialEq)]
pub enum ResultOrigin {
    /// A run in this window.
    Run {
        /// Wall time of the run, s.
        seconds: f64,
        /// Measurements left out of the run.
        excluded: usize,
    },
    /// A result file opened for review (no solver run).
    Review(PathBuf),
}

/// Everything the Results, Centres and export views show of one result.
#[derive(Debug, Clone, PartialEq)]
pub struct ResultView {
    /// The result itself (what "Result JSON" exports).
    pub file: ResultFile,
    /// Run or review.
    pub origin: ResultOrigin,
    /// What every reader shows: headline, pairs, hand-eye, marks, σ.
    pub shown: Shown,
    /// Base-frame centres before and after.
    pub centres: CentreSet,
    /// Warnings: e.g. the result names another session.
    pub notes: Vec<String>,
    /// For a result that calibrated the hand-eye only (a pose-only
    /// session): what was and was not identified, and how well.
    pub hand_eye_only: Option<Vec<String>>,
    /// The calibration set's and the validation set's errors.
    pub sets: Vec<ErrorSet>,
}

impl ResultView {
    /// Builds the view of `file`, matched against the loaded `session`
    /// (when there is one) by measurement id.
    #[must_use]
    pub fn new(file: ResultFile, origin: ResultOrigin, session: Option<&Session>) -> Self {
        let mut notes = Vec::new();
        let ids = session.map(crate::engine::tools::result_view::measurement_index);
        let index_of =
            |id: &str| -> Option<usize> { ids.as_ref().and_then(|m| m.get(id).copied()) };
        if let Some(s) = session {
            if s.name != file.session {
                notes.push(format!(
                    "the result was computed from session \"{}\", the open session is \"{}\"",
                    file.session, s.name
                ));
            }
            let missing = file
                .centres
                .iter()
                .filter(|c| index_of(&c.measurement).is_none())
                .count();
            if missing > 0 {
                notes.push(format!(
                    "{missing} of the result's {} measurements are not in the open session",
                    file.centres.len()
                ));
            }
        } else if matches!(origin, ResultOrigin::Review(_)) {
            notes.push("no session is open: the Session and Stripe views are empty".to_string());
        }

        let points: Vec<CentrePoint> = file
            .centres
            .iter()
            .map(|c| CentrePoint {
                id: c.measurement.clone(),
                station: c.station.clone(),
                usage: c.usage.as_str().to_string(),
                index: index_of(&c.measurement),
                before: c.before,
                after: Some(c.after),
            })
            .collect();
        let shown = Shown::new(&file);
        Self {
            origin,
            sets: ErrorSet::all_of(&file.centres, &shown.distances),
            shown,
            centres: CentreSet::new(points),
            notes,
            hand_eye_only: crate::engine::tools::result_view::hand_eye_only_lines(&file, session),
            file,
        }
    }

    /// `solver.method`.
    #[must_use]
    pub fn method(&self) -> &str {
        self.file.solver.method()
    }

    /// ε after 0, 1, … updates, mm.
    #[must_use]
    pub fn epsilons(&self) -> Vec<f64> {
        self.file.iterations.iter().map(|r| r.epsilon).collect()
    }

    /// Where the result came from, in words (the exports' `source`).
    #[must_use]
    pub fn source(&self) -> String {
        match &self.origin {
            ResultOrigin::Review(p) => p.display().to_string(),
            ResultOrigin::Run { .. } => format!("a workbench run of {}", self.file.session),
        }
    }
}

/// Display options of the centres view.
#[derive(Debug, Clone, PartialEq)]
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
    /// The 3-D scene's camera.
    pub camera: crate::app::scene::Camera,
}

impl Default for CentresForm {
    fn default() -> Self {
        Self {
            show_before: true,
            show_after: true,
            relative: true,
            magnify: 50.0,
            camera: crate::app::scene::Camera::default(),
        }
    }
}

/// The acceptance tolerance.
#[must_use]
pub fn tolerance(t: &Tolerance) -> Reading {
    Reading::new(
        vec![
            ("std ≤".into(), format!("{:.3} mm", t.std_mm)),
            ("max ≤".into(), format!("{:.3} mm", t.max_mm)),
        ],
        (t.std_mm.to_bits(), t.max_mm.to_bits()),
    )
}

/// The calibration result on show: which one (the how-many-th shown in
/// this window, where it came from, its method); a new run or a result
/// opened reads otherwise even with the same numbers.
#[must_use]
pub fn calibration(state: &AppState) -> Reading {
    let text = match &state.result {
        None => "none".to_string(),
        Some(r) => match &r.origin {
            ResultOrigin::Run { .. } => {
                format!("run #{} ({})", state.results_shown, r.method())
            }
            ResultOrigin::Review(p) => {
                let name = p.file_name().unwrap_or(p.as_os_str()).to_string_lossy();
                format!("{name} (#{}, {})", state.results_shown, r.method())
            }
        },
    };
    Reading::new(
        vec![("result".into(), text)],
        (state.result.is_some(), state.results_shown),
    )
}
