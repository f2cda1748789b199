//! The Measure view's feature: a scan (the open session, a session file,
//! or a raw scan's pose log and profiles) into a point cloud through the
//! result on show, on a job thread with progress and Cancel, by the same
//! engine functions `spherecal measure` calls ([`measure::measure`],
//! [`measure::scan_from_files`], [`measure::self_validate`],
//! [`measure::write_cloud`]). The job also makes what the view draws: a
//! decimated copy of the cloud ([`DRAWN_MAX`] points at most) sorted by
//! σ, the bounds and the σ figures, so that a cloud of millions costs
//! the frame only the points drawn.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use crate::engine::base::session::{Session, Use};
use crate::engine::calibrate::solve::{Control, SolverReport};
pub use crate::engine::calibrate::stripe::segment::grouped as group;
use crate::engine::files::format::{self, ResultFile, refuse_inputs};
use crate::engine::uses::measure::{
    self, CellModel, Cloud, CloudFormat, CloudPoint, JointRange, MeasureError, MeasureOptions,
    ModelChoice, Scan, ScanFiles, Stage,
};

use super::{Core, Write};
use crate::app::commands::{Command, MeasureCommand};
use crate::app::error::JobError;
use crate::app::forms::measure::ScanChoice;
use crate::app::job::{Job, Slot};
use crate::app::ledger::Artefact;
use crate::app::state::measure::{MeasureFailure, MeasuredCloud};
use crate::app::state::{Level, Notice};
use crate::app::view::ResultOrigin;

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

impl Core {
    /// Handles a [`MeasureCommand`].
    pub(super) fn measure(&mut self, ctx: &egui::Context, command: MeasureCommand) {
        match command {
            MeasureCommand::Start => self.start_measure(ctx),
            MeasureCommand::Cancel => {
                if let Some(job) = self.state.jobs.cancel(&Slot::Measure) {
                    self.state.say(
                        Level::Warning,
                        format!(
                            "measuring cancelled in \"{}\" ({:.2} s); the cloud on show is unchanged",
                            job.phase,
                            job.started.elapsed().as_secs_f64()
                        ),
                    );
                }
            }
            MeasureCommand::Export => self.export_cloud(ctx),
        }
    }

    /// The job's request from the form and the result on show, or why
    /// there is none.
    fn measure_request(&self) -> Result<MeasureRequest, String> {
        let Some(view) = &self.state.result else {
            return Err("no result on show: run the calibration or open a result first".into());
        };
        self.state
            .ledger
            .check(Artefact::Result)
            .map_err(|why| format!("{why}: run the calibration again, then measure"))?;
        let form = &self.forms.measure;
        let sigma = !form.no_sigma;
        if sigma && !has_covariance(&view.file) {
            return Err(format!(
                "σ is unavailable: the result (method {}) has no parameter covariance; tick \"no σ\" to measure without it (as --no-sigma), or calibrate with method ml",
                view.file.solver.method()
            ));
        }
        if !(form.sensor_noise_mm.is_finite() && form.sensor_noise_mm >= 0.0) {
            return Err("the sensor noise must be a finite number ≥ 0 mm".into());
        }
        let loaded = self.state.loaded.as_ref();
        let scan = match form.choice {
            ScanChoice::OpenSession => {
                let Some(l) = loaded else {
                    return Err("no session open to measure".into());
                };
                ScanInput::Session(
                    Box::new(l.session.clone()),
                    form.uses(),
                    format!("\"{}\" ({})", l.session.name, l.source.label()),
                )
            }
            ScanChoice::SessionFile => {
                let path = form.session_file.trim();
                if path.is_empty() {
                    return Err("type or choose the session file to measure".into());
                }
                ScanInput::SessionFile(PathBuf::from(path), form.uses())
            }
            ScanChoice::RawScan => {
                let dof = view
                    .file
                    .robot
                    .as_ref()
                    .map_or(0, crate::engine::base::robot::kinematics::Robot::dof);
                ScanInput::Files(Box::new(form.scan_files(dof)?))
            }
        };
        let result_label = match &view.origin {
            ResultOrigin::Review(p) => p.display().to_string(),
            ResultOrigin::Run { .. } => format!(
                "a workbench run (method {}) of \"{}\"",
                view.method, view.file.session
            ),
        };
        Ok(MeasureRequest {
            scan,
            result: view.file.clone(),
            result_label,
            joint_range: loaded.and_then(|l| JointRange::of_session(&l.session)),
            frame: form.frame_path(),
            options: MeasureOptions {
                model: ModelChoice::Calibrated,
                frame: None,
                sigma,
                sensor_noise_mm: form.sensor_noise_mm,
                covariance_as_written: false,
            },
        })
    }

    fn start_measure(&mut self, ctx: &egui::Context) {
        if self.state.jobs.runs(&Slot::Measure) {
            return;
        }
        let request = match self.measure_request() {
            Ok(r) => r,
            Err(why) => {
                self.state.say(Level::Warning, "nothing measured");
                self.state.measure.failure = Some(why);
                return;
            }
        };
        let stamp = self.state.ledger.stamp(Artefact::Cloud);
        if self.start(ctx, Slot::Measure, stamp, move |w| {
            measure_scan(request, w.flag(), &mut |phase, fraction| {
                w.progress(phase, Some(fraction))
            })
            .map(Box::new)
        }) {
            self.state.measure.failure = None;
            self.state.say(Level::Info, "measuring the scan…");
        }
    }

    /// Shows the cloud of a measuring job (after the frame's commands: a
    /// job cancelled in the frame it arrived in is not shown).
    pub(super) fn on_measured(
        &mut self,
        job: &Job,
        outcome: Result<Box<MeasuredCloud>, MeasureFailure>,
    ) {
        let m = &mut self.state.measure;
        match outcome {
            Ok(cloud) => {
                let text = format!(
                    "measured {} points of {} poses in {:.2} s (Measure view)",
                    group(cloud.points),
                    group(cloud.poses),
                    cloud.seconds
                );
                let what = format!("{} points measured of {}", group(cloud.points), cloud.scan);
                m.shown = Some(*cloud);
                self.state
                    .ledger
                    .record(Artefact::Cloud, job.stamp.clone(), what);
                self.state.say(Level::Info, text);
            }
            Err(MeasureFailure::Cancelled) => self.state.say(
                Level::Warning,
                "measuring cancelled; the cloud on show is unchanged",
            ),
            Err(MeasureFailure::Failed(e)) => {
                m.failure = Some(e.to_string());
                self.state
                    .say(Level::Error, "the scan could not be measured");
                self.state.notice = Some(Notice {
                    title: "The scan could not be measured".to_string(),
                    body: e.to_string(),
                });
            }
        }
    }

    /// Every input file of the cloud on show and of the form, to refuse
    /// an export over one of them.
    fn measure_inputs(&self) -> Vec<PathBuf> {
        let form = &self.forms.measure;
        let mut out: Vec<PathBuf> = [
            form.session_file.trim(),
            form.log.trim(),
            form.profiles.trim(),
            form.frame.trim(),
            form.references.trim(),
        ]
        .iter()
        .filter(|s| !s.is_empty())
        .map(PathBuf::from)
        .collect();
        if let Some(p) = self.state.loaded.as_ref().and_then(|l| l.source.path()) {
            out.push(p.to_path_buf());
        }
        if let Some(ResultOrigin::Review(p)) = self.state.result.as_ref().map(|v| &v.origin) {
            out.push(p.clone());
        }
        out
    }

    /// Writes the cloud on show to the form's path, refused when it is
    /// stale or the path is not a cloud file.
    pub(super) fn export_cloud(&mut self, ctx: &egui::Context) {
        let refuse = |core: &mut Self, why: String| {
            core.refuse("Cloud not written", "cloud not written", why);
        };
        let Some(shown) = &self.state.measure.shown else {
            refuse(self, "no cloud to write: measure a scan first".into());
            return;
        };
        // A stale cloud is never written as if it were current.
        let stamp = match self.state.ledger.check(Artefact::Cloud) {
            Ok(stamp) => stamp,
            Err(why) => {
                refuse(self, format!("{why}: measure again, then export"));
                return;
            }
        };
        let text = self.forms.measure.out.trim();
        if text.is_empty() {
            refuse(
                self,
                "type where to write the cloud (.ply, .e57 or .csv), or press Save as…".into(),
            );
            return;
        }
        let path = PathBuf::from(text);
        let Some(format) = CloudFormat::of_path(&path) else {
            refuse(
                self,
                format!(
                    "{}: the extension chooses the format: .ply, .e57 or .csv",
                    path.display()
                ),
            );
            return;
        };
        let inputs = self.measure_inputs();
        let refs: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
        if let Err(e) = refuse_inputs(&path, &refs) {
            refuse(self, e.to_string());
            return;
        }
        let cloud = Arc::clone(&shown.cloud);
        let provenance = measure::Provenance {
            result: shown.result.clone(),
            scan: shown.scan.clone(),
        };
        let write = Write {
            what: format_label(format).to_string(),
            from: Artefact::Cloud,
            stamp,
            again: Command::Measure(MeasureCommand::Export),
        };
        self.state.say(
            Level::Info,
            format!("writing the {}…", format_label(format)),
        );
        self.write(ctx, path, write, move |path| {
            measure::write_cloud(&cloud, path, format, &provenance)?;
            Ok(None)
        });
    }

    /// The name the export's save dialog offers: the export field's, else
    /// `<session stem>-cloud.ply`.
    pub(super) fn cloud_file_name(&self) -> String {
        Path::new(self.forms.measure.out.trim())
            .file_name()
            .map_or_else(
                || {
                    let stem = self
                        .state
                        .loaded
                        .as_ref()
                        .map_or_else(|| "scan".to_string(), |l| l.source.stem());
                    format!("{stem}-cloud.ply")
                },
                |n| n.to_string_lossy().into_owned(),
            )
    }
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
