//! The Measure view's job work: a scan (the open session, a session
//! file, or a raw scan's pose log and profiles) into a point cloud
//! through the result on show, by the same engine functions `spherecal
//! measure` calls, with the self-validation on its sphere stations; and
//! what the view draws of it, made on the job thread: a decimated copy
//! ([`DRAWN_MAX`] points at most) sorted by σ, the bounds and the σ
//! figures, so that a cloud of millions costs the frame only the points
//! drawn.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use crate::engine::base::session::{Session, Use};
use crate::engine::calibrate::solve::{Control, SolverReport};
pub use crate::engine::calibrate::stripe::segment::grouped as group;
use crate::engine::files::format::{self, ResultFile};
use crate::engine::uses::measure::{
    self, CellModel, Cloud, CloudFormat, CloudPoint, Dropped, JointRange, MeasureError,
    MeasureOptions, ModelChoice, Scan, ScanFiles, SelfValidation, SigmaStats, Stage,
};

use crate::app::error::JobError;

/// Most points the view draws of a cloud (spread evenly over it,
/// [`measure::Cloud::decimated`]): a projection is about 330 × 280
/// screen points, 92,000 pixels; 50,000 points fill it, and three
/// projections of 50,000 small squares draw in a few milliseconds
/// whatever the cloud's size (10 M points stay responsive).
pub const DRAWN_MAX: usize = 50_000;

/// Poses outside the calibrated joint range listed by name at most (as
/// the command lists them).
const LISTED_POSES: usize = 20;

/// The smallest step of the progress bar that is reported (1 %): a
/// scan of 10,000 poses sends 100 messages, not 20,000.
const PROGRESS_STEP: f64 = 0.01;

/// What is measured.
#[derive(Debug, Clone)]
pub enum ScanInput {
    /// A session's stripes (the open one), with the uses to keep (empty:
    /// all) and its name for people.
    Session(Box<Session>, Vec<Use>, String),
    /// A session file, with the uses to keep.
    SessionFile(PathBuf, Vec<Use>),
    /// A raw scan's files.
    Files(Box<ScanFiles>),
}

/// Everything a measuring job needs.
#[derive(Debug, Clone)]
pub struct MeasureRequest {
    /// The scan.
    pub scan: ScanInput,
    /// The result on show.
    pub result: ResultFile,
    /// The result for people and the file header (its file, or "a
    /// workbench run of …").
    pub result_label: String,
    /// The joint range the calibration saw (the open session's).
    pub joint_range: Option<JointRange>,
    /// The workpiece frame file, if any.
    pub frame: Option<PathBuf>,
    /// σ or not, sensor noise (the frame is read by the job).
    pub options: MeasureOptions,
}

/// Whether `result` carries the parameter covariance σ needs (an `ml`
/// result that reached its diagnostics).
#[must_use]
pub fn has_covariance(result: &ResultFile) -> bool {
    matches!(&result.solver, SolverReport::Ml(r) if !r.covariance.labels.is_empty())
}

/// The fraction of the whole job at `stage`'s step `done` of `of`:
/// reading the scan takes the first tenth, placing the poses the next
/// four, σ the next three and a half, the self-validation and the view
/// the rest.
fn fraction(stage: Stage, done: usize, of: usize) -> f64 {
    let f = done as f64 / of.max(1) as f64;
    match stage {
        Stage::Poses => 0.1 + 0.4 * f,
        Stage::Sigma => 0.5 + 0.35 * f,
    }
}

/// The scan a request names, read (a session as it is, a session file,
/// or a raw scan's files), with the label it is shown under.
fn read_scan(scan: ScanInput) -> Result<(Scan, String), MeasureFailure> {
    Ok(match scan {
        ScanInput::Session(session, uses, name) => (Scan::from_session(*session, &uses), name),
        ScanInput::SessionFile(path, uses) => {
            let session = format::load_session(&path)
                .map_err(|e| MeasureFailure::Failed(JobError::from(e)))?;
            (
                Scan::from_session(session, &uses),
                path.display().to_string(),
            )
        }
        ScanInput::Files(files) => {
            let scan = measure::scan_from_files(&files)
                .map_err(|e| MeasureFailure::Failed(JobError::from(e)))?;
            let label = files.log.path().display().to_string();
            (scan, label)
        }
    })
}

/// Refuses a scan with no pose to measure (saying when its measurements
/// give sphere centres instead of profiles).
fn refuse_empty(scan: &Scan, scan_label: &str) -> Result<(), MeasureFailure> {
    if scan.poses.is_empty() {
        return Err(MeasureFailure::Failed(JobError::Missing(format!(
            "nothing to measure: no pose with a profile in {scan_label}{}",
            if scan.skipped.is_empty() {
                String::new()
            } else {
                format!(
                    " (its {} measurements give sphere centres)",
                    scan.skipped.len()
                )
            }
        ))));
    }
    Ok(())
}

/// The points drawn (at most [`DRAWN_MAX`], the largest σ last so that
/// it is drawn on top) and the range of their finite σ (mm).
fn drawn_points(cloud: &Cloud) -> (Vec<CloudPoint>, Option<(f64, f64)>) {
    let mut drawn = cloud.decimated(DRAWN_MAX);
    drawn.sort_by(|a, b| a.sigma_mm.total_cmp(&b.sigma_mm));
    let sigma_range = drawn
        .iter()
        .map(|p| p.sigma_mm)
        .filter(|s| s.is_finite())
        .fold(None, |r: Option<(f64, f64)>, s| {
            Some(r.map_or((s, s), |(lo, hi)| (lo.min(s), hi.max(s))))
        });
    (drawn, sigma_range)
}

/// Why the cloud has no σ (`None` when it has), and what its σ rests on
/// (the covariance as written or scaled, the sensor noise).
fn sigma_words(
    cloud: &Cloud,
    result: &ResultFile,
    options: &MeasureOptions,
) -> (Option<String>, String) {
    let no_sigma = (!cloud.has_sigma()).then(|| {
        if options.sigma {
            "σ is unavailable".to_string()
        } else if has_covariance(result) {
            "no σ (as asked)".to_string()
        } else {
            format!(
                "σ is unavailable: the result (method {}) has no parameter covariance",
                result.solver.method()
            )
        }
    });
    let mut sigma_basis = if options.covariance_as_written {
        "covariance as written".to_string()
    } else {
        format!(
            "covariance × variance factor {:.3}",
            measure::variance_factor(result)
        )
    };
    if options.sensor_noise_mm > 0.0 {
        sigma_basis.push_str(&format!(", sensor noise {} mm", options.sensor_noise_mm));
    }
    (no_sigma, sigma_basis)
}

/// The poses outside the calibrated joint range, in words, at most
/// [`LISTED_POSES`] and a line for the rest.
fn listed_out_of_range(out_of_range: &[measure::OutOfRange]) -> Vec<String> {
    let mut listed: Vec<String> = out_of_range
        .iter()
        .take(LISTED_POSES)
        .map(ToString::to_string)
        .collect();
    if out_of_range.len() > LISTED_POSES {
        listed.push(format!("… and {} more", out_of_range.len() - LISTED_POSES));
    }
    listed
}

/// Measures `request` (module doc): reads the scan, measures it, runs
/// the self-validation on its sphere stations, and makes the view of the
/// cloud. `progress` gets each phase in words and the fraction done
/// (false: the workbench is gone); `cancel` is looked at after every
/// pose and between the phases.
///
/// # Errors
/// [`MeasureFailure::Cancelled`] after a cancel, [`MeasureFailure::Failed`]
/// with the engine's error (naming the file, pose or parameter) otherwise.
pub fn measure_scan(
    request: MeasureRequest,
    cancel: &AtomicBool,
    progress: &mut dyn FnMut(&str, f64) -> bool,
) -> Result<MeasuredCloud, MeasureFailure> {
    let started = Instant::now();
    let failed = |e: MeasureError| match e {
        MeasureError::Cancelled => MeasureFailure::Cancelled,
        e => MeasureFailure::Failed(JobError::from(e)),
    };
    let stopped = |cancel: &AtomicBool| {
        if cancel.load(Ordering::Relaxed) {
            Err(MeasureFailure::Cancelled)
        } else {
            Ok(())
        }
    };
    progress("reading the scan", 0.0);
    let MeasureRequest {
        scan,
        result,
        result_label,
        joint_range,
        frame,
        mut options,
    } = request;
    let (scan, scan_label) = read_scan(scan)?;
    stopped(cancel)?;
    refuse_empty(&scan, &scan_label)?;
    if let Some(path) = &frame {
        let w = measure::load_frame(path).map_err(failed)?;
        options.frame = Some((w, path.display().to_string()));
    }
    let sphere = scan.sphere_diameter;
    let references = scan.reference_distances.clone();
    let (notes, skipped) = (scan.notes.clone(), scan.skipped.len());
    let mut last = 0.0;
    let measured = measure::measure(scan, &result, &options, joint_range.as_ref(), &mut |p| {
        let f = fraction(p.stage, p.done, p.of);
        let mut alive = true;
        if f - last >= PROGRESS_STEP || p.done == p.of {
            last = f;
            let what = match p.stage {
                Stage::Poses => "placing the sensor at each pose",
                Stage::Sigma => "the σ of each pose",
            };
            alive = progress(&format!("{what} ({} of {})", p.done, p.of), f);
        }
        if cancel.load(Ordering::Relaxed) || !alive {
            Control::Cancel
        } else {
            Control::Continue
        }
    })
    .map_err(failed)?;
    stopped(cancel)?;
    progress("the self-validation on the sphere stations", 0.85);
    let check = sphere.and_then(|d| {
        measure::self_validate(
            &measured.cloud.poses,
            &CellModel::of_result(&result, ModelChoice::Nominal),
            &CellModel::of_result(&result, ModelChoice::Calibrated),
            d,
            &references,
        )
    });
    stopped(cancel)?;
    progress("the view of the cloud (decimated, σ colours)", 0.95);
    let cloud = measured.cloud;
    let (drawn, sigma_range) = drawn_points(&cloud);
    let sigma = cloud.sigma_stats();
    let (no_sigma, sigma_basis) = sigma_words(&cloud, &result, &options);
    let out_of_range = listed_out_of_range(&measured.out_of_range);
    let out_of_range_count = measured.out_of_range.len();
    stopped(cancel)?;
    Ok(MeasuredCloud {
        out_of_range_count,
        points: cloud.len(),
        poses: cloud.poses.len(),
        dropped: cloud.dropped(),
        bounds: cloud.bounds(),
        sigma,
        sigma_range,
        no_sigma,
        sigma_basis,
        check,
        warnings: measured.warnings,
        out_of_range,
        skipped,
        notes,
        scan: scan_label,
        result: result_label,
        frame: cloud.frame.to_string(),
        model: cloud.model,
        seconds: started.elapsed().as_secs_f64(),
        drawn,
        cloud: Arc::new(cloud),
    })
}

/// The file format's name for people.
#[must_use]
pub fn format_label(format: CloudFormat) -> &'static str {
    match format {
        CloudFormat::Ply => "PLY cloud",
        CloudFormat::E57 => "E57 cloud",
        CloudFormat::Csv => "CSV cloud",
    }
}

/// A cloud measured in the workbench, with what the view draws of it.
#[derive(Debug, Clone)]
pub struct MeasuredCloud {
    /// The whole cloud (what Export writes), shared with export jobs.
    pub cloud: Arc<Cloud>,
    /// At most [`crate::app::measure::job::DRAWN_MAX`] points spread
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The progress bar only moves forward through the phases.
    #[test]
    fn the_fraction_grows_through_the_stages() {
        assert!((fraction(Stage::Poses, 0, 10) - 0.1).abs() < 1e-12);
        assert!((fraction(Stage::Poses, 10, 10) - 0.5).abs() < 1e-12);
        assert!((fraction(Stage::Sigma, 10, 10) - 0.85).abs() < 1e-12);
        assert!(fraction(Stage::Sigma, 0, 0) >= 0.5);
    }
}
