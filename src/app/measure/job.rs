//! The Measure view's job work: a scan (the open session, a session
//! file, or a raw scan's pose log and profiles) into a point cloud
//! through the result on show, by the one engine entry `spherecal
//! measure` calls too ([`measure::measure_scan`], with the
//! self-validation on its sphere stations); and what the view draws of
//! it, made on the job thread: a decimated copy
//! ([`DRAWN_MAX`] points at most) sorted by σ, the bounds and the σ
//! figures, so that a cloud of millions costs the frame only the points
//! drawn.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use crate::engine::calibrate::solve::{Control, SolverReport};
pub use crate::engine::calibrate::stripe::segment::grouped as group;
use crate::engine::files::format::ResultFile;
use crate::engine::uses::measure::{
    self, Cloud, CloudPoint, MeasureError, MeasureRequest, Outcome, SigmaStats,
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

/// Why a measuring job gave no cloud.
#[derive(Debug)]
pub enum MeasureFailure {
    /// Cancel was pressed.
    Cancelled,
    /// The inputs or the engine failed.
    Failed(JobError),
}

/// A cloud measured in the workbench: the engine's outcome as it came,
/// and what the view draws of it (made once: a median of millions is
/// not a frame's work).
#[derive(Debug, Clone)]
pub struct MeasuredCloud {
    /// The engine's outcome: the cloud (shared with export jobs), its
    /// warnings, the self-validation, what was measured.
    pub outcome: Outcome,
    /// At most [`DRAWN_MAX`] points spread evenly over the cloud, sorted
    /// by σ (largest drawn last, on top).
    pub drawn: Vec<CloudPoint>,
    /// The colour scale's ends, mm: smallest and largest finite σ drawn.
    pub sigma_range: Option<(f64, f64)>,
    /// σ over every point (rms, median, max), mm; `None` without σ.
    pub sigma: Option<SigmaStats>,
    /// Bounding box `(min, max)` of every point, mm, output frame.
    pub bounds: Option<([f64; 3], [f64; 3])>,
    /// Why there is no σ, when there is none.
    pub no_sigma: Option<String>,
    /// What σ rests on (the covariance's scale, the sensor noise).
    pub sigma_basis: String,
    /// The result it was measured with, for people and the file header.
    pub result: String,
    /// Wall time of the job, s.
    pub seconds: f64,
}

impl MeasuredCloud {
    /// The whole cloud.
    #[must_use]
    pub fn cloud(&self) -> &Cloud {
        &self.outcome.measured.cloud
    }
}

/// Measures `request` by the engine's [`measure::measure_scan`] (what
/// `spherecal measure` calls) and makes the view of the cloud;
/// `result_label` names the result for people and the file header.
/// `progress` gets each phase in words and the fraction done (false: the
/// workbench is gone); `cancel` is looked at after every pose and
/// between the phases.
///
/// # Errors
/// [`MeasureFailure::Cancelled`] after a cancel, [`MeasureFailure::Failed`] with
/// the engine's error (naming the file, pose or parameter) otherwise.
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
    let outcome = measure::measure_scan(request, &mut |p| {
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
    let cloud = &outcome.measured.cloud;
    let mut drawn = cloud.decimated(DRAWN_MAX);
    drawn.sort_by(|a, b| a.sigma_mm.total_cmp(&b.sigma_mm));
    let finite = drawn.iter().map(|p| p.sigma_mm).filter(|s| s.is_finite());
    let sigma_range = finite.fold(None, |r: Option<(f64, f64)>, s| {
        Some(r.map_or((s, s), |(lo, hi)| (lo.min(s), hi.max(s))))
    });
    let no_sigma = (!cloud.has_sigma()).then(|| match (options.sigma, has_covariance(&result)) {
        (true, _) => "σ is unavailable".to_string(),
        (false, true) => "no σ (as asked)".to_string(),
        (false, false) => format!(
            "σ is unavailable: the result (method {}) has no parameter covariance",
            result.solver.method()
        ),
    });
    let (sigma, bounds) = (cloud.sigma_stats(), cloud.bounds());
    if cancelled() {
        return Err(MeasureFailure::Cancelled);
    }
    Ok(MeasuredCloud {
        drawn,
        sigma_range,
        sigma,
        bounds,
        no_sigma,
        sigma_basis: options.sigma_basis(&result),
        result: result_label,
        seconds: started.elapsed().as_secs_f64(),
        outcome,
    })
}
