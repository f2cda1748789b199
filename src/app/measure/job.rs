//! The Measure view's job work: a scan (the open session, a session
//! file, or a raw scan's pose log and profiles) into a point cloud
//! through the result on show, by the one engine entry `spherecal
//! measure` calls too ([`measure::measure_scan`], with the
//! self-validation on its sphere stations); and what the view draws of
//! it, made on the job thread: a decimated copy
//! ([`DRAWN_MAX`] points at most) sorted by σ, the bounds and the σ
//! figures, so that a cloud of millions costs the frame only the points
//! drawn.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use crate::engine::calibrate::solve::{Control, SolverReport};
pub use crate::engine::calibrate::stripe::segment::grouped as group;
use crate::engine::files::format::ResultFile;
use crate::engine::uses::measure::{
    self, Cloud, CloudFormat, CloudPoint, Dropped, MeasureError, MeasureOptions, MeasureRequest,
    Outcome, SelfValidation, SigmaStats,
};

use crate::app::error::JobError;

/// Most points the view draws of a cloud (spread evenly over it,
/// [`measure::Cloud::decimated`]): a projection is about 330 × 280
/// screen points, 92,000 pixels; 50,000 points fill it, and three
/// projections of 50,000 small squares draw in a few milliseconds
/// whatever the cloud's size (10 M points stay responsive).
pub const DRAWN_MAX: usize = 50_000;

/// The smallest step of the progress bar that is reported (1 %): a
/// scan of 10,000 poses sends 100 messages, not 20,000.
const PROGRESS_STEP: f64 = 0.01;

/// Whether `result` carries the parameter covariance σ needs (an `ml`
/// result that reached its diagnostics).
#[must_use]
pub fn has_covariance(result: &ResultFile) -> bool {
    matches!(&result.solver, SolverReport::Ml(r) if !r.covariance.labels.is_empty())
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

/// Measures `request` by the engine's [`measure::measure_scan`] (what
/// `spherecal measure` calls) and makes the view of the cloud;
/// `result_label` names the result for people and the file header.
/// `progress` gets each phase in words and the fraction done (false: the
/// workbench is gone); `cancel` is looked at after every pose and
/// between the phases.
///
/// # Errors
/// [`MeasureFailure::Cancelled`] after a cancel, [`MeasureFailure::Failed`]
/// with the engine's error (naming the file, pose or parameter) otherwise.
pub fn measure_cloud(
    request: MeasureRequest,
    result_label: String,
    cancel: &AtomicBool,
    progress: &mut dyn FnMut(&str, f64) -> bool,
) -> Result<MeasuredCloud, MeasureFailure> {
    let started = Instant::now();
    let cancelled = || cancel.load(Ordering::Relaxed);
    let (result, options) = (request.result.clone(), request.options.clone());
    let mut last = -1.0;
    let done = measure::measure_scan(request, &mut |p| {
        let f = p.fraction();
        let mut alive = true;
        if f - last >= PROGRESS_STEP || p.done == p.of {
            last = f;
            alive = progress(&p.describe(), f);
        }
        if cancelled() || !alive {
            Control::Cancel
        } else {
            Control::Continue
        }
    })
    .map_err(|e| match e {
        MeasureError::Cancelled => MeasureFailure::Cancelled,
        e => MeasureFailure::Failed(JobError::from(e)),
    })?;
    if cancelled() {
        return Err(MeasureFailure::Cancelled);
    }
    progress("the view of the cloud (decimated, σ colours)", 0.95);
    let Outcome {
        measured,
        check,
        scan,
        notes,
        skipped,
        ..
    } = done;
    let cloud = measured.cloud;
    let (drawn, sigma_range) = drawn_points(&cloud);
    let (no_sigma, sigma_basis) = sigma_words(&cloud, &result, &options);
    if cancelled() {
        return Err(MeasureFailure::Cancelled);
    }
    Ok(MeasuredCloud {
        out_of_range_count: measured.out_of_range.len(),
        out_of_range: measure::listed(&measured.out_of_range),
        points: cloud.len(),
        poses: cloud.poses.len(),
        dropped: cloud.dropped(),
        bounds: cloud.bounds(),
        sigma: cloud.sigma_stats(),
        sigma_range,
        no_sigma,
        sigma_basis,
        check,
        warnings: measured.warnings,
        skipped: skipped.len(),
        notes,
        scan,
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
