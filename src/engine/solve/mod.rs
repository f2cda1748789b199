//! The whole calibration of a session (paper Fig. 2): sphere centres from
//! the stripes (eq. 21), the initial hand-eye (eq. 6-9), then the loop of
//! FORMAT.md "The iteration" around an identification update, then the
//! before/after statistics. The command line and the workbench both call
//! [`prepare`] and [`run`]; `run` reports every ε through a callback that
//! can cancel.

pub mod estimate;
pub mod ml;
pub mod paper;

use nalgebra::{Isometry3, Matrix3, Point3, Vector3};
use serde_json::{Map, Value, json};

use crate::engine::handeye::HandEyeError;
use crate::engine::handeye::{InitialHandEye, Sighting, initial_hand_eye};
use crate::engine::robot::Robot;
use crate::engine::session::{Observation, Session, Use};
use crate::engine::solve::estimate::{Estimate, Station, unknown_label};
use crate::engine::solve::paper::{Pairing, PaperOptions, UpdateInfo, paper_update};
use crate::engine::stripe::StripeError;
use crate::engine::stripe::{StripeResult, centre_from_stripe};
use crate::engine::validate::{
    BeforeAfter, StationCentres, Stats, Validation, epsilon, validation, within_station_distances,
};

/// The identification (paper 3.2 or the ML method) cannot run or failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IdentifyError {
    /// No identify station has two measurements.
    #[error(
        "identification needs at least one identify station with 2 or more measurements; {detail}"
    )]
    NotEnoughData {
        /// What was found.
        detail: String,
    },
    /// A number became non-finite during the solve.
    #[error("the solver produced a non-finite value at iteration {iteration}")]
    NonFinite {
        /// Update number.
        iteration: usize,
    },
    /// The user cancelled the run.
    #[error("cancelled by the user after {iterations} update(s)")]
    Cancelled {
        /// Updates made before the cancel.
        iterations: usize,
    },
    /// An option is out of range.
    #[error("invalid solver option: {0}")]
    InvalidOption(String),
}

/// Anything that stops a calibration of a loaded session.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CalibrationError {
    /// One stripe could not give a sphere centre.
    #[error("measurement {id}: {source}")]
    Stripe {
        /// Measurement id.
        id: String,
        /// The stripe problem.
        source: StripeError,
    },
    /// The initial hand-eye could not be determined.
    #[error(transparent)]
    HandEye(#[from] HandEyeError),
    /// The identification could not run.
    #[error(transparent)]
    Identify(#[from] IdentifyError),
}

impl CalibrationError {
    /// True when the cause is the input data (exit status 2), false for an
    /// internal failure or a cancel.
    #[must_use]
    pub fn is_input_error(&self) -> bool {
        match self {
            Self::Stripe { .. } | Self::HandEye(_) => true,
            Self::Identify(e) => matches!(
                e,
                IdentifyError::NotEnoughData { .. } | IdentifyError::InvalidOption(_)
            ),
        }
    }
}

/// Identification method.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// The paper's: paired differences, truncated SVD (section 3.2).
    Paper,
    /// Maximum likelihood: station centres as unknowns, noise-model
    /// weighting, identifiable set by pivoted QR, prior, robust loss
    /// ([`crate::engine::solve::ml`]).
    Ml,
}

impl Method {
    /// The name written in the result's `solver.method`.
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Paper => "paper",
            Self::Ml => "ml",
        }
    }

    /// Parses a method name.
    #[must_use]
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "paper" => Some(Self::Paper),
            "ml" => Some(Self::Ml),
            _ => None,
        }
    }

    /// Every method, the default first.
    pub const ALL: [Self; 2] = [Self::Ml, Self::Paper];
}

/// Everything that steers a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Identification method.
    pub method: Method,
    /// Stop when ε ≤ this, mm.
    pub threshold: f64,
    /// Most updates.
    pub max_iterations: usize,
    /// Settings of the paper's update.
    pub paper: PaperOptions,
    /// Settings of the `ml` method.
    pub ml: crate::engine::solve::ml::MlOptions,
}

impl Options {
    /// Defaults, with threshold and iteration bound from the session file.
    /// The method is `ml`: over five simulated scenarios it comes nearer the
    /// noise floor than the paper's method in every one (README, Evidence).
    #[must_use]
    pub fn from_session(session: &Session) -> Self {
        Self {
            method: Method::Ml,
            threshold: session.solver.threshold,
            max_iterations: session.solver.max_iterations,
            paper: PaperOptions::default(),
            ml: crate::engine::solve::ml::MlOptions::default(),
        }
    }
}

/// A measurement's sphere centre in the sensor frame, ready for the solver.
#[derive(Debug, Clone, PartialEq)]
pub struct PreparedMeasurement {
    /// Index into `session.measurements`.
    pub index: usize,
    /// Sphere centre in the sensor frame, mm.
    pub centre_in_sensor: Vector3<f64>,
    /// Its covariance, mm² (from the circle fit; `None` for given centres).
    pub covariance: Option<Matrix3<f64>>,
    /// Circle fit and quality, for stripe measurements.
    pub stripe: Option<StripeResult>,
}

/// Where the initial hand-eye came from.
#[derive(Debug, Clone, PartialEq)]
pub enum HandEyeSource {
    /// The session's `hand_eye`.
    File,
    /// Computed by eq. 6-9, with its diagnostics.
    Computed(InitialHandEye),
}

/// A session with every centre computed and the initial hand-eye known.
#[derive(Debug, Clone, PartialEq)]
pub struct Prepared {
    /// One per session measurement, same order.
    pub measurements: Vec<PreparedMeasurement>,
    /// `eT_s` before identification.
    pub hand_eye_initial: Isometry3<f64>,
    /// Where it came from.
    pub hand_eye_source: HandEyeSource,
    /// Warnings `(measurement id, text)` from the stripe fits.
    pub warnings: Vec<(String, String)>,
}

impl Prepared {
    /// Sightings of the measurements with this use, grouped by station in
    /// order of first appearance.
    #[must_use]
    pub fn stations(&self, session: &Session, usage: Use) -> Vec<Station> {
        session
            .stations(usage)
            .into_iter()
            .map(|(id, idx)| Station {
                id,
                sightings: idx.iter().map(|&i| self.sighting(session, i)).collect(),
            })
            .collect()
    }

    /// The sighting of measurement `i`.
    #[must_use]
    pub fn sighting(&self, session: &Session, i: usize) -> Sighting {
        let m = &session.measurements[i];
        Sighting {
            id: m.id.clone(),
            joints: m.joints.clone(),
            centre_in_sensor: self.measurements[i].centre_in_sensor,
        }
    }
}

/// Sphere centres of every measurement (eq. 21) and the initial hand-eye
/// (the file's, else eq. 6-9 on the nominal model).
///
/// # Errors
/// A stripe that cannot be fitted (naming the measurement) or a pose set
/// that does not determine the hand-eye.
pub fn prepare(session: &Session) -> Result<Prepared, CalibrationError> {
    let radius = session.sphere_radius();
    let mut measurements = Vec::with_capacity(session.measurements.len());
    let mut warnings = Vec::new();
    for (index, m) in session.measurements.iter().enumerate() {
        let prepared = match &m.observation {
            Observation::Centre(c) => PreparedMeasurement {
                index,
                centre_in_sensor: *c,
                covariance: None,
                stripe: None,
            },
            Observation::Stripe(points) => {
                let fit = centre_from_stripe(points, radius, m.side).map_err(|source| {
                    CalibrationError::Stripe {
                        id: m.id.clone(),
                        source,
                    }
                })?;
                warnings.extend(fit.warnings.iter().map(|w| (m.id.clone(), w.clone())));
                PreparedMeasurement {
                    index,
                    centre_in_sensor: fit.sphere.centre_in_sensor,
                    covariance: Some(fit.sphere.covariance),
                    stripe: Some(fit),
                }
            }
        };
        measurements.push(prepared);
    }
    let mut out = Prepared {
        measurements,
        hand_eye_initial: Isometry3::identity(),
        hand_eye_source: HandEyeSource::File,
        warnings,
    };
    if let Some(he) = session.hand_eye {
        out.hand_eye_initial = he;
    } else {
        let sightings = |usage| -> Vec<Sighting> {
            session
                .measurements
                .iter()
                .enumerate()
                .filter(|(_, m)| m.usage == usage)
                .map(|(i, _)| out.sighting(session, i))
                .collect()
        };
        let initial = initial_hand_eye(
            &session.robot,
            &sightings(Use::Translation),
            &sightings(Use::Rotation),
        )?;
        out.hand_eye_initial = initial.flange_from_sensor;
        out.hand_eye_source = HandEyeSource::Computed(initial);
    }
    Ok(out)
}

/// Reported after every ε evaluation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Progress {
    /// Updates made so far (0 for the starting ε).
    pub updates: usize,
    /// ε after that many updates, mm.
    pub epsilon: f64,
    /// The iteration bound.
    pub max_iterations: usize,
    /// The threshold, mm.
    pub threshold: f64,
}

/// What the progress callback asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Control {
    /// Go on.
    Continue,
    /// Stop now; `run` returns [`IdentifyError::Cancelled`].
    Cancel,
}

/// Why the loop stopped, with the measured value beside the threshold.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StopReason {
    /// ε ≤ threshold.
    Converged {
        /// Final ε, mm.
        epsilon: f64,
        /// Threshold, mm.
        threshold: f64,
        /// Updates made.
        updates: usize,
    },
    /// The iteration bound was reached with ε above the threshold.
    IterationLimit {
        /// Final ε, mm.
        epsilon: f64,
        /// Threshold, mm.
        threshold: f64,
        /// Updates made (= the bound).
        updates: usize,
        /// |ε change| over the last update, mm: small means ε has levelled
        /// off at the noise of the data, not that more updates would help.
        last_change: f64,
    },
    /// The solver itself converged with ε above the threshold (`ml`: an
    /// LM step lowered the cost by a negligible amount, or none could).
    SolverConverged {
        /// Final ε, mm.
        epsilon: f64,
        /// Threshold, mm.
        threshold: f64,
        /// Updates made.
        updates: usize,
        /// Relative cost decrease of the last step (0 when none was possible).
        relative_change: f64,
    },
}

/// Below this change of ε (mm) over one update the loop is said to have
/// levelled off: 1 µm is far below any stripe sensor's resolution.
pub const LEVELLED_OFF_MM: f64 = 1e-3;

impl StopReason {
    /// A sentence for people.
    #[must_use]
    pub fn describe(&self) -> String {
        match *self {
            Self::Converged {
                epsilon,
                threshold,
                updates,
            } => format!(
                "converged: ε = {epsilon:.4} mm ≤ threshold {threshold:.4} mm after {updates} update(s)"
            ),
            Self::IterationLimit {
                epsilon,
                threshold,
                updates,
                last_change,
            } => {
                let why = if last_change < LEVELLED_OFF_MM {
                    format!(
                        "ε levelled off (last change {last_change:.2e} mm): the threshold is below what the noise of this data allows (robot repeatability and sensor noise set a floor under ε)"
                    )
                } else {
                    format!("ε was still changing by {last_change:.4} mm per update")
                };
                format!(
                    "stopped on the iteration bound: ε = {epsilon:.4} mm > threshold {threshold:.4} mm after {updates} update(s); {why}"
                )
            }
            Self::SolverConverged {
                epsilon,
                threshold,
                updates,
                relative_change,
            } => format!(
                "converged: the maximum-likelihood solve reached its optimum (last relative cost change {relative_change:.1e}) after {updates} update(s); ε = {epsilon:.4} mm is above the threshold {threshold:.4} mm, which is below what the noise of this data allows"
            ),
        }
    }

    /// Short machine name for the result file.
    #[must_use]
    pub fn code(&self) -> &'static str {
        match self {
            Self::Converged { .. } => "threshold",
            Self::IterationLimit { .. } => "max_iterations",
            Self::SolverConverged { .. } => "converged",
        }
    }
}

/// One measurement's sphere centre in the base frame, before and after.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CentreRow {
    /// Index into `session.measurements`.
    pub index: usize,
    /// Sensor frame, mm.
    pub sensor: Vector3<f64>,
    /// Base frame, nominal model and initial hand-eye, mm.
    pub before: Vector3<f64>,
    /// Base frame, calibrated model and hand-eye, mm.
    pub after: Vector3<f64>,
}

/// The outcome of a run.
#[derive(Debug, Clone, PartialEq)]
pub struct Calibration {
    /// Options used.
    pub options: Options,
    /// Nominal model (the session's).
    pub nominal: Robot,
    /// Calibrated model.
    pub calibrated: Robot,
    /// `eT_s` before identification.
    pub hand_eye_initial: Isometry3<f64>,
    /// `eT_s` calibrated.
    pub hand_eye: Isometry3<f64>,
    /// ε after 0, 1, … updates, mm.
    pub iterations: Vec<f64>,
    /// Why the loop stopped.
    pub stop: StopReason,
    /// The last update's SVD (None when no update was made).
    pub last_update: Option<UpdateInfo>,
    /// The result file's `solver` block.
    pub solver: Map<String, Value>,
    /// Every measurement's centre, session order.
    pub centres: Vec<CentreRow>,
    /// Within-station distance statistics of the identify stations.
    pub identify_within: BeforeAfter,
    /// Validation block, when the session has validate measurements.
    pub validation: Option<Validation>,
}

impl Calibration {
    /// ε before identification, mm.
    #[must_use]
    pub fn epsilon_before(&self) -> f64 {
        self.iterations.first().copied().unwrap_or(0.0)
    }

    /// ε after identification, mm.
    #[must_use]
    pub fn epsilon_after(&self) -> f64 {
        self.iterations.last().copied().unwrap_or(0.0)
    }
}

/// Runs the identification loop (FORMAT.md "The iteration"): compute ε;
/// while ε > threshold and fewer than `max_iterations` updates were made,
/// update and compute ε again. `progress` is called with every ε; returning
/// [`Control::Cancel`] stops the run.
///
/// # Errors
/// Too little identify data, a bad option, a non-finite update, or a cancel.
pub fn run(
    session: &Session,
    prepared: &Prepared,
    options: &Options,
    progress: &mut dyn FnMut(&Progress) -> Control,
) -> Result<Calibration, CalibrationError> {
    if !(options.threshold >= 0.0 && options.threshold.is_finite()) {
        return Err(IdentifyError::InvalidOption(format!(
            "threshold must be a non-negative number of mm, got {}",
            options.threshold
        ))
        .into());
    }
    let stations = prepared.stations(session, Use::Identify);
    let usable = stations.iter().filter(|s| s.sightings.len() >= 2).count();
    if usable == 0 {
        return Err(IdentifyError::NotEnoughData {
            detail: format!(
                "the session has {} identify station(s) and none has 2 measurements",
                stations.len()
            ),
        }
        .into());
    }
    if options.method == Method::Ml {
        return crate::engine::solve::ml::run(session, prepared, options, progress);
    }
    let start = Estimate {
        robot: session.robot.clone(),
        flange_from_sensor: prepared.hand_eye_initial,
    };
    let mut est = start.clone();
    let mut eps = epsilon(&est.station_centres(&stations));
    let mut iterations = vec![eps];
    let mut last_update = None;
    let report = |updates: usize, epsilon: f64| Progress {
        updates,
        epsilon,
        max_iterations: options.max_iterations,
        threshold: options.threshold,
    };
    if progress(&report(0, eps)) == Control::Cancel {
        return Err(IdentifyError::Cancelled { iterations: 0 }.into());
    }
    while eps > options.threshold && iterations.len() - 1 < options.max_iterations {
        let updates = iterations.len();
        let info = match options.method {
            Method::Paper | Method::Ml => paper_update(&est, &stations, &options.paper)?,
        };
        if info.delta.iter().any(|d| !d.is_finite()) {
            return Err(IdentifyError::NonFinite { iteration: updates }.into());
        }
        est = est.updated(&info.delta);
        eps = epsilon(&est.station_centres(&stations));
        if !eps.is_finite() {
            return Err(IdentifyError::NonFinite { iteration: updates }.into());
        }
        iterations.push(eps);
        last_update = Some(info);
        if progress(&report(updates, eps)) == Control::Cancel {
            return Err(IdentifyError::Cancelled {
                iterations: updates,
            }
            .into());
        }
    }
    let updates = iterations.len() - 1;
    let stop = if eps <= options.threshold {
        StopReason::Converged {
            epsilon: eps,
            threshold: options.threshold,
            updates,
        }
    } else {
        let n = iterations.len();
        let last_change = if n >= 2 {
            (iterations[n - 1] - iterations[n - 2]).abs()
        } else {
            f64::INFINITY
        };
        StopReason::IterationLimit {
            epsilon: eps,
            threshold: options.threshold,
            updates,
            last_change,
        }
    };
    Ok(finish(
        session,
        prepared,
        options,
        &start,
        est,
        iterations,
        stop,
        last_update,
    ))
}

/// The centres, statistics and solver block of a finished run.
#[allow(clippy::too_many_arguments)]
pub(crate) fn finish(
    session: &Session,
    prepared: &Prepared,
    options: &Options,
    start: &Estimate,
    est: Estimate,
    iterations: Vec<f64>,
    stop: StopReason,
    last_update: Option<UpdateInfo>,
) -> Calibration {
    let centre = |e: &Estimate, i: usize| -> Vector3<f64> {
        let m = &session.measurements[i];
        let base_from_sensor = e.robot.base_from_flange(&m.joints) * e.flange_from_sensor;
        (base_from_sensor * Point3::from(prepared.measurements[i].centre_in_sensor)).coords
    };
    let centres: Vec<CentreRow> = (0..session.measurements.len())
        .map(|i| CentreRow {
            index: i,
            sensor: prepared.measurements[i].centre_in_sensor,
            before: centre(start, i),
            after: centre(&est, i),
        })
        .collect();
    let grouped = |usage: Use| -> Vec<StationCentres> {
        session
            .stations(usage)
            .into_iter()
            .map(|(station, idx)| StationCentres {
                station,
                before: idx.iter().map(|&i| centres[i].before).collect(),
                after: idx.iter().map(|&i| centres[i].after).collect(),
            })
            .collect()
    };
    let identify = grouped(Use::Identify);
    let identify_within = BeforeAfter {
        before: Stats::of(&within_station_distances(
            &identify
                .iter()
                .map(|s| s.before.clone())
                .collect::<Vec<_>>(),
        )),
        after: Stats::of(&within_station_distances(
            &identify.iter().map(|s| s.after.clone()).collect::<Vec<_>>(),
        )),
    };
    let validate = grouped(Use::Validate);
    let validation = if validate.is_empty() {
        None
    } else {
        Some(validation(&session.reference_distances, &validate))
    };
    let solver = solver_block(options, &stop, last_update.as_ref());
    Calibration {
        options: *options,
        nominal: session.robot.clone(),
        calibrated: est.robot,
        hand_eye_initial: start.flange_from_sensor,
        hand_eye: est.flange_from_sensor,
        iterations,
        stop,
        last_update,
        solver,
        centres,
        identify_within,
        validation,
    }
}

/// The result file's `solver` block for the paper's method.
fn solver_block(
    options: &Options,
    stop: &StopReason,
    last: Option<&UpdateInfo>,
) -> Map<String, Value> {
    let mut m = Map::new();
    m.insert("method".into(), json!(options.method.as_str()));
    m.insert("pairs".into(), json!(options.paper.pairing.as_str()));
    m.insert("svd_tolerance".into(), json!(options.paper.svd_tolerance));
    m.insert(
        "column_scaling".into(),
        json!(format!(
            "angle unknowns × {} mm/rad before the SVD",
            crate::engine::solve::estimate::ANGLE_SCALE_MM
        )),
    );
    m.insert("threshold".into(), json!(options.threshold));
    m.insert("max_iterations".into(), json!(options.max_iterations));
    m.insert("stop".into(), json!(stop.code()));
    m.insert("stop_reason".into(), json!(stop.describe()));
    if let Some(info) = last {
        m.insert("kept_directions".into(), json!(info.kept));
        m.insert("equations".into(), json!(info.rows));
        m.insert("singular_values".into(), json!(info.singular_values));
        m.insert("dropped_directions".into(), json!(info.dropped));
        m.insert(
            "unknowns".into(),
            json!((0..info.delta.len()).map(unknown_label).collect::<Vec<_>>()),
        );
    }
    m
}

/// `prepare` then `run` with no progress reporting.
///
/// # Errors
/// As [`prepare`] and [`run`].
pub fn calibrate(
    session: &Session,
    options: &Options,
) -> Result<(Prepared, Calibration), CalibrationError> {
    let prepared = prepare(session)?;
    let cal = run(session, &prepared, options, &mut |_| Control::Continue)?;
    Ok((prepared, cal))
}

/// Sets the pairing by name (for callers parsing options).
#[must_use]
pub fn pairing_from_name(name: &str) -> Option<Pairing> {
    Pairing::parse(name)
}
