//! The measuring use case in one entry, [`measure_scan`], that the
//! command line and the workbench both call: the scan read (a session as
//! it is, a session file, or a raw scan's files) and refused when it has
//! no pose to measure, the workpiece frame read, the scan measured
//! ([`measure`](super::measure)) while the sphere self-validation runs on
//! its own thread beside it, with the progress of every phase.

use std::path::PathBuf;
use std::time::Instant;

use super::{
    CellModel, JointRange, MeasureError, MeasureOptions, MeasureProgress, Measured, ModelChoice,
    Scan, ScanFiles, ScanPose, SelfValidation, Stage, load_frame, measure, scan_from_files,
    selfcheck,
};
use crate::engine::base::session::{Session, Use};
use crate::engine::calibrate::solve::Control;
use crate::engine::files::format::{self, ResultFile};

/// Poses (or measurements) listed by name at most: a scan of thousands
/// of poses would bury the summary.
pub const LISTED_POSES: usize = 20;

/// The first [`LISTED_POSES`] of `items` in words, one an entry, and
/// "… and n more" for the rest.
#[must_use]
pub fn listed<T: std::fmt::Display>(items: &[T]) -> Vec<String> {
    let mut out: Vec<String> = items
        .iter()
        .take(LISTED_POSES)
        .map(ToString::to_string)
        .collect();
    if items.len() > LISTED_POSES {
        out.push(format!("… and {} more", items.len() - LISTED_POSES));
    }
    out
}

/// What is measured.
#[derive(Debug, Clone)]
pub enum ScanSource {
    /// A session's stripes as they are: the measurements of these uses
    /// (empty: all), with the session's name for people.
    Session(Box<Session>, Vec<Use>, String),
    /// A session file's stripes, the measurements of these uses.
    SessionFile(PathBuf, Vec<Use>),
    /// A raw scan's pose log and profiles.
    Files(Box<ScanFiles>),
}

/// Everything a measurement needs.
#[derive(Debug, Clone)]
pub struct MeasureRequest {
    /// What is measured.
    pub scan: ScanSource,
    /// The result whose model and hand-eye place the sensor.
    pub result: ResultFile,
    /// The joint range the calibration saw; `None`: a session's own (a
    /// raw scan's is then not checked).
    pub joint_range: Option<JointRange>,
    /// The workpiece frame file (`base_from_workpiece`), if any.
    pub frame: Option<PathBuf>,
    /// The model, σ, sensor noise (the frame is read from `frame`).
    pub options: MeasureOptions,
}

/// A scan measured, its self-validation, and what was noticed on the way.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// The cloud, its warnings, the poses outside the joint range.
    pub measured: Measured,
    /// The self-validation on the scan's sphere stations, when it saw any.
    pub check: Option<SelfValidation>,
    /// What was measured, for people and the file header.
    pub scan: String,
    /// How the scan was read (axis map, units).
    pub notes: Vec<String>,
    /// Measurements without a profile (given centres): not in the cloud.
    pub skipped: Vec<String>,
    /// Seconds to read the scan and the frame.
    pub read_secs: f64,
    /// Seconds to place the sensor and compute σ.
    pub placed_secs: f64,
    /// Seconds of the self-validation (beside the placing).
    pub checked_secs: f64,
}

impl MeasureProgress {
    /// What the measurement is doing, in words: "the σ of each pose (3 of
    /// 40)".
    #[must_use]
    pub fn describe(&self) -> String {
        let what = match self.stage {
            Stage::Reading => return "reading the scan".to_string(),
            Stage::Poses => "placing the sensor at each pose",
            Stage::Sigma => "the σ of each pose",
            Stage::SelfCheck => return "the self-validation on the sphere stations".to_string(),
        };
        format!("{what} ({} of {})", self.done, self.of)
    }

    /// The fraction of the whole measurement done: reading the scan takes
    /// the first tenth, placing the poses the next four, σ the next three
    /// and a half, the self-validation the rest.
    #[must_use]
    pub fn fraction(&self) -> f64 {
        let f = self.done as f64 / self.of.max(1) as f64;
        match self.stage {
            Stage::Reading => 0.0,
            Stage::Poses => 0.1 + 0.4 * f,
            Stage::Sigma => 0.5 + 0.35 * f,
            Stage::SelfCheck => 0.85,
        }
    }
}

/// The scan a request names, read, and what to call it; a session's own
/// joint range when none is given.
fn read_scan(
    scan: ScanSource,
    joint_range: &mut Option<JointRange>,
) -> Result<(Scan, String), MeasureError> {
    let mut of_session = |s: &Session| {
        if joint_range.is_none() {
            *joint_range = JointRange::of_session(s);
        }
    };
    Ok(match scan {
        ScanSource::Session(session, uses, name) => {
            of_session(&session);
            (Scan::from_session(*session, &uses), name)
        }
        ScanSource::SessionFile(path, uses) => {
            let session = format::load_session(&path)?;
            of_session(&session);
            let label = path.display().to_string();
            (Scan::from_session(session, &uses), label)
        }
        ScanSource::Files(files) => {
            let scan = scan_from_files(&files)?;
            let name = scan.name.clone();
            (scan, name)
        }
    })
}

/// Measures the request's scan (module doc). `progress` hears of every
/// phase and step; [`Control::Cancel`] ends the measurement with
/// [`MeasureError::Cancelled`].
///
/// # Errors
/// A file that cannot be read (naming it), a scan with no pose with a
/// profile, a frame that is not rigid, a scan of another robot, σ asked of
/// a result without covariance ([`MeasureError`]); cancelled.
pub fn measure_scan(
    request: MeasureRequest,
    progress: &mut dyn FnMut(&MeasureProgress) -> Control,
) -> Result<Outcome, MeasureError> {
    let started = Instant::now();
    let MeasureRequest {
        scan,
        result,
        mut joint_range,
        frame,
        mut options,
    } = request;
    if result.mount() == crate::engine::base::session::Mount::Fixed {
        return Err(MeasureError::Input(
            "the result is of a fixed sensor (sensor.mount \"fixed\"): measuring parts needs a sensor on the flange, whose hand-eye places each profile".into(),
        ));
    }
    let step = |stage| MeasureProgress {
        stage,
        done: 0,
        of: 1,
    };
    if progress(&step(Stage::Reading)) == Control::Cancel {
        return Err(MeasureError::Cancelled);
    }
    if let Some(path) = &frame {
        options.frame = Some((load_frame(path)?, path.display().to_string()));
    }
    let (scan, label) = read_scan(scan, &mut joint_range)?;
    if scan.poses.is_empty() {
        let centres = if scan.skipped.is_empty() {
            String::new()
        } else {
            let n = scan.skipped.len();
            format!(" (the {n} measurements give sphere centres)")
        };
        return Err(MeasureError::Input(format!(
            "nothing to measure: no pose with a profile{centres} ({label})"
        )));
    }
    let read_secs = started.elapsed().as_secs_f64();
    let sphere = scan.sphere_diameter;
    let references = scan.reference_distances.clone();
    let checked: Vec<ScanPose> = match sphere {
        Some(_) => scan
            .poses
            .iter()
            .filter(|p| selfcheck::checks(*p))
            .cloned()
            .collect(),
        None => Vec::new(),
    };
    let (notes, skipped) = (scan.notes.clone(), scan.skipped.clone());
    let (nominal, calibrated) = (
        CellModel::of_result(&result, ModelChoice::Nominal),
        CellModel::of_result(&result, ModelChoice::Calibrated),
    );
    let self_validation = || {
        let t = Instant::now();
        let check = sphere
            .and_then(|d| super::self_validate(&checked, &nominal, &calibrated, d, &references));
        (check, t.elapsed().as_secs_f64())
    };
    let (measured, placed_secs, (check, checked_secs)) = std::thread::scope(|s| {
        let worker = std::thread::Builder::new()
            .name("self-validation".into())
            .spawn_scoped(s, self_validation);
        let t = Instant::now();
        let measured = measure(scan, &result, &options, joint_range.as_ref(), progress);
        let placed = t.elapsed().as_secs_f64();
        if measured.is_ok() {
            progress(&step(Stage::SelfCheck));
        }
        // A self-validation that panicked gives no check, not a failure.
        let check = match worker {
            Ok(handle) => handle.join().unwrap_or((None, 0.0)),
            Err(_) => self_validation(),
        };
        (measured, placed, check)
    });
    Ok(Outcome {
        measured: measured?,
        check,
        scan: label,
        notes,
        skipped,
        read_secs,
        placed_secs,
        checked_secs,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The progress bar only moves forward through the phases.
    #[test]
    fn the_fraction_grows_through_the_stages() {
        let at = |stage, done, of| MeasureProgress { stage, done, of }.fraction();
        assert!(at(Stage::Reading, 0, 1).abs() < 1e-12);
        assert!((at(Stage::Poses, 0, 10) - 0.1).abs() < 1e-12);
        assert!((at(Stage::Poses, 10, 10) - 0.5).abs() < 1e-12);
        assert!((at(Stage::Sigma, 10, 10) - 0.85).abs() < 1e-12);
        assert!(at(Stage::Sigma, 0, 0) >= 0.5);
        assert!((at(Stage::SelfCheck, 0, 1) - 0.85).abs() < 1e-12);
    }

    /// Twenty names, then a count of the rest.
    #[test]
    fn a_long_list_is_cut_with_a_count() {
        let ids: Vec<usize> = (0..23).collect();
        let l = listed(&ids);
        assert_eq!(l.len(), LISTED_POSES + 1);
        assert_eq!(l[19], "19");
        assert_eq!(l[20], "… and 3 more");
        assert_eq!(listed(&ids[..2]), ["0", "1"]);
    }
}
