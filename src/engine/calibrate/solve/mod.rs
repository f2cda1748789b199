//! Problem in, steppable solver, result out: the loop of FORMAT.md "The
//! iteration" (paper Fig. 2) around one method's update, the paper's
//! ([`paper`], section 3.2, eq. 17-19) or maximum likelihood ([`ml`]),
//! both linearised by [`estimate`] (eq. 10-16).
//!
//! [`prepare`](fn@prepare) gives the sphere centres (eq. 21) and the initial hand-eye
//! (eq. 6-9); [`run`] computes ε (eq. 20), and while ε is above the
//! threshold and the iteration bound is not reached, asks the method for
//! one update ([`Update`]) and computes ε again. Every ε goes to a progress
//! callback that may cancel; why the loop stopped ([`StopReason`], with
//! the measured ε beside the threshold) is recorded, a cancel being one of
//! the reasons. The [`Calibration`] holds the calibrated model and
//! hand-eye, every centre before and after, the statistics, and the
//! method's typed report ([`SolverReport`]).

pub mod estimate;
pub mod held_out;
pub mod ml;
pub mod paper;
pub mod plausible;
pub mod prepare;
pub mod progress;
pub mod result;

use nalgebra::{Isometry3, Point3, Vector3};

pub use crate::engine::base::records::{LoopRecord, SolverReport};
use crate::engine::base::robot::Robot;
use crate::engine::base::session::{Session, Use, limits};
use crate::engine::calibrate::handeye::HandEyeError;
use crate::engine::calibrate::stripe::StripeError;
use crate::engine::calibrate::validate::{
    BeforeAfter, StationCentres, Stats, Validation, epsilon, validation, within_station_distances,
};
use estimate::{Estimate, Station};
pub use held_out::{HeldOut, HeldOutRecord, HeldOutScheme};
use paper::PaperOptions;
pub use prepare::{Analysis, HandEyeSource, Prepared, PreparedMeasurement, analyse, prepare};
pub use progress::{Control, Phase, Progress};

/// Why a calibration of a loaded session could not run, or failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SolveError {
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
    /// An option is out of range.
    #[error("invalid solver option: {0}")]
    InvalidOption(String),
}

impl SolveError {
    /// True when the cause is the input data or the settings (exit status
    /// 2), false for an internal failure.
    #[must_use]
    pub fn is_input_error(&self) -> bool {
        !matches!(self, Self::NonFinite { .. })
    }
}

/// Identification method.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// The paper's: paired differences, truncated SVD (section 3.2).
    Paper,
    /// Maximum likelihood: station centres as unknowns, noise-model
    /// weighting, identifiable set by pivoted QR, prior, robust loss
    /// ([`ml`]).
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
    pub ml: ml::MlOptions,
    /// Whether to compute the held-out figure after the loop
    /// ([`held_out`]): each identify measurement predicted by a
    /// calibration made without it.
    pub held_out: bool,
}

impl Default for Options {
    /// The defaults of a session file that says nothing of its solver.
    fn default() -> Self {
        Self {
            method: Method::Ml,
            threshold: crate::engine::base::session::DEFAULT_THRESHOLD,
            max_iterations: crate::engine::base::session::DEFAULT_MAX_ITERATIONS,
            paper: PaperOptions::default(),
            ml: ml::MlOptions::default(),
            held_out: true,
        }
    }
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
            ml: ml::MlOptions::default(),
            held_out: true,
        }
    }
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
    /// ε stopped changing (by at most [`LEVELLED_OFF_STOP_MM`] over each
    /// of [`LEVELLED_OFF_UPDATES`] updates) above the threshold: more
    /// updates would not lower it.
    LevelledOff {
        /// Final ε, mm.
        epsilon: f64,
        /// Threshold, mm.
        threshold: f64,
        /// Updates made.
        updates: usize,
        /// |ε change| over the last update, mm.
        last_change: f64,
    },
    /// The caller cancelled the run (the estimate is the one reached so
    /// far, and a method's costly diagnostics are left out, unless the
    /// cancel came in the last phase, [`Phase::Finishing`], after them).
    Cancelled {
        /// ε when cancelled, mm.
        epsilon: f64,
        /// Threshold, mm.
        threshold: f64,
        /// Updates made.
        updates: usize,
    },
}

/// Below this change of ε (mm) over one update the loop is said to have
/// levelled off: 1 µm is far below any stripe sensor's resolution.
pub const LEVELLED_OFF_MM: f64 = 1e-3;

/// The loop stops when ε changed by at most this (mm) over each of the
/// last [`LEVELLED_OFF_UPDATES`] updates: a picometre, where only rounding
/// moves it.
pub const LEVELLED_OFF_STOP_MM: f64 = 1e-9;

/// Updates in a row with ε levelled off before the loop stops.
pub const LEVELLED_OFF_UPDATES: usize = 2;

impl StopReason {
    /// A sentence for people.
    #[must_use]
    pub fn describe(&self) -> String {
        match *self {
            // Nothing converged when no update was made: the start was
            // already within the threshold (no_update_warning says more).
            Self::Converged {
                epsilon,
                threshold,
                updates: 0,
            } => format!(
                "no update: ε = {epsilon:.4} mm was within the threshold {threshold:.4} mm at the start"
            ),
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
            Self::LevelledOff {
                epsilon,
                threshold,
                updates,
                last_change,
            } => format!(
                "ε levelled off: it changed by {last_change:.1e} mm over the last update; stopped after {updates} update(s) with ε = {epsilon:.4} mm above the threshold {threshold:.4} mm, which is below what the noise of this data allows"
            ),
            Self::Cancelled {
                epsilon,
                threshold,
                updates,
            } => format!(
                "cancelled by the user after {updates} update(s): ε = {epsilon:.4} mm (threshold {threshold:.4} mm)"
            ),
        }
    }

    /// Whether the caller cancelled the run.
    #[must_use]
    pub fn is_cancelled(&self) -> bool {
        matches!(self, Self::Cancelled { .. })
    }

    /// The same stop, cancelled (a cancel during a method's diagnostics).
    #[must_use]
    pub fn cancelled(&self) -> Self {
        let (epsilon, threshold, updates) = match *self {
            Self::Converged {
                epsilon,
                threshold,
                updates,
            }
            | Self::IterationLimit {
                epsilon,
                threshold,
                updates,
                ..
            }
            | Self::SolverConverged {
                epsilon,
                threshold,
                updates,
                ..
            }
            | Self::LevelledOff {
                epsilon,
                threshold,
                updates,
                ..
            }
            | Self::Cancelled {
                epsilon,
                threshold,
                updates,
            } => (epsilon, threshold, updates),
        };
        Self::Cancelled {
            epsilon,
            threshold,
            updates,
        }
    }

    /// The loop's record for the result's `solver` block.
    #[must_use]
    pub fn record(&self, options: &Options) -> LoopRecord {
        LoopRecord {
            threshold: options.threshold,
            max_iterations: options.max_iterations,
            stop: self.code().to_string(),
            stop_reason: self.describe(),
        }
    }

    /// Short machine name for the result file.
    #[must_use]
    pub fn code(&self) -> &'static str {
        match self {
            Self::Converged { .. } => "threshold",
            Self::IterationLimit { .. } => "max_iterations",
            Self::SolverConverged { .. } => "converged",
            Self::LevelledOff { .. } => "levelled_off",
            Self::Cancelled { .. } => "cancelled",
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
    /// The method's report (the result file's `solver` block).
    pub report: SolverReport,
    /// Every measurement's centre, session order.
    pub centres: Vec<CentreRow>,
    /// Within-station distance statistics of the identify stations.
    pub identify_within: BeforeAfter,
    /// Validation block, when the session has validate measurements.
    pub validation: Option<Validation>,
    /// Each identify measurement predicted by a calibration made without
    /// it ([`held_out`]); `None` when not asked for ([`Options::held_out`]).
    pub held_out: Option<HeldOut>,
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

/// What one update of a method did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Step {
    /// The estimate moved; the method would go on.
    Moved,
    /// The estimate moved and the method has converged with it (`ml`: LM
    /// stopped on a negligible cost decrease).
    Converged {
        /// Relative cost decrease of the last step.
        relative_change: f64,
    },
    /// No step is possible any more: converged before this update; the
    /// estimate did not move.
    Stuck {
        /// Relative cost decrease of the last step taken (0 if none).
        relative_change: f64,
    },
    /// The caller cancelled inside the update (the estimate is the last
    /// accepted one).
    Cancelled,
}

/// A method inside the loop: its estimate, one update, and its report
/// once the loop has stopped.
pub trait Update {
    /// The model and hand-eye now.
    fn estimate(&self) -> &Estimate;

    /// Makes update number `update` (1, 2, …), telling `phase` of each
    /// inner step; a [`Control::Cancel`] from it ends the update at once
    /// with [`Step::Cancelled`].
    ///
    /// # Errors
    /// A bad option, or a non-finite step.
    fn update(
        &mut self,
        update: usize,
        phase: &mut dyn FnMut(Phase) -> Control,
    ) -> Result<Step, SolveError>;

    /// The held-out figure at the estimate the loop ended with: each
    /// identify measurement's centre predicted by a calibration made
    /// without it ([`held_out`]), telling `phase` of the refits; `None`
    /// when `phase` cancelled.
    fn held_out(&self, phase: &mut dyn FnMut(Phase) -> Control) -> Option<HeldOut>;

    /// The method's report on the run that stopped for `stop` (a method
    /// leaves out its costly diagnostics after a cancel), telling `phase`
    /// of each diagnostic; the flag is true when `phase` cancelled them
    /// (the report then holds the settings only).
    fn report(
        self: Box<Self>,
        stop: &StopReason,
        phase: &mut dyn FnMut(Phase) -> Control,
    ) -> (SolverReport, bool);
}

/// Runs the identification loop (FORMAT.md "The iteration"): compute ε;
/// while ε > threshold and fewer than `max_iterations` updates were made
/// (and the method has not converged), update and compute ε again.
/// `progress` is called with every ε; returning [`Control::Cancel`] ends
/// the run with [`StopReason::Cancelled`].
///
/// # Errors
/// Too little identify data, a bad option, or a non-finite update.
pub fn run(
    session: &Session,
    prepared: &Prepared,
    options: &Options,
    progress: &mut dyn FnMut(&Progress) -> Control,
) -> Result<Calibration, SolveError> {
    if !(options.threshold >= 0.0 && options.threshold.is_finite()) {
        return Err(SolveError::InvalidOption(format!(
            "threshold must be a non-negative number of mm, got {}",
            crate::engine::base::numeric::show(options.threshold)
        )));
    }
    if options.threshold > limits::THRESHOLD_MM {
        return Err(SolveError::InvalidOption(format!(
            "threshold {} mm is not plausible: ε of a calibration is a few mm at most, so no update would be made; give at most {} mm",
            crate::engine::base::numeric::show(options.threshold),
            limits::THRESHOLD_MM
        )));
    }
    if options.max_iterations as f64 > limits::MAX_ITERATIONS {
        return Err(SolveError::InvalidOption(format!(
            "max_iterations {} is not plausible: give at most {}",
            options.max_iterations,
            limits::MAX_ITERATIONS
        )));
    }
    let stations = prepared.stations(session, Use::Identify);
    let usable = stations.iter().filter(|s| s.sightings.len() >= 2).count();
    if usable == 0 {
        return Err(SolveError::NotEnoughData {
            detail: format!(
                "the session has {} identify station(s) and none has 2 measurements",
                stations.len()
            ),
        });
    }
    let start = Estimate {
        robot: session.solver_robot(),
        flange_from_sensor: prepared.hand_eye_initial,
        mount: session.mount,
    };
    let report = |updates: usize, epsilon: f64, phase: Phase| Progress {
        updates,
        epsilon,
        max_iterations: options.max_iterations,
        threshold: options.threshold,
        phase,
    };
    // The paper's update sets up at once; `ml` looks at the cancel while
    // it builds its problem.
    let cancelled_early = progress(&report(0, f64::NAN, Phase::Setup)) == Control::Cancel;
    let mut method: Box<dyn Update> = match options.method {
        Method::Paper => Box::new(paper::PaperUpdate::new(
            start.clone(),
            stations.clone(),
            options,
        )),
        Method::Ml if cancelled_early => {
            return Ok(cancelled_in_setup(
                session, prepared, options, &start, &stations,
            ));
        }
        Method::Ml => {
            let mut setup = |phase: Phase| progress(&report(0, f64::NAN, phase));
            match ml::MlUpdate::new(
                session,
                prepared,
                &start,
                stations.clone(),
                options,
                &mut setup,
            )? {
                Some(m) => Box::new(m),
                None => {
                    return Ok(cancelled_in_setup(
                        session, prepared, options, &start, &stations,
                    ));
                }
            }
        }
    };
    let looped = iterate(
        method.as_mut(),
        &stations,
        options,
        cancelled_early,
        progress,
    )?;
    let mut stop = looped.stop(options);
    let (updates, eps) = (looped.iterations.len() - 1, stop_epsilon(&stop));
    let est = method.estimate().clone();
    let mut after = |phase: Phase| progress(&report(updates, eps, phase));
    let mut held_out = None;
    if options.held_out && !stop.is_cancelled() {
        match method.held_out(&mut after) {
            Some(h) => held_out = Some(h),
            None => stop = stop.cancelled(),
        }
    }
    let (report, cancelled_late) = method.report(&stop, &mut after);
    if cancelled_late || (!stop.is_cancelled() && after(Phase::Finishing) == Control::Cancel) {
        stop = stop.cancelled();
    }
    let mut cal = finish(
        session,
        prepared,
        options,
        &start,
        est,
        looped.iterations,
        stop,
        report,
    );
    cal.held_out = held_out;
    Ok(cal)
}

/// The final ε a stop reason records, mm.
fn stop_epsilon(stop: &StopReason) -> f64 {
    match *stop {
        StopReason::Converged { epsilon, .. }
        | StopReason::IterationLimit { epsilon, .. }
        | StopReason::SolverConverged { epsilon, .. }
        | StopReason::LevelledOff { epsilon, .. }
        | StopReason::Cancelled { epsilon, .. } => epsilon,
    }
}

/// What the loop did: every ε and how it ended.
struct Looped {
    /// ε after 0, 1, … updates, mm.
    iterations: Vec<f64>,
    /// The caller cancelled.
    cancelled: bool,
    /// The method converged (its last relative cost change).
    converged: Option<f64>,
    /// Updates in a row over which ε did not change.
    levelled: usize,
}

impl Looped {
    /// Why the loop stopped.
    fn stop(&self, options: &Options) -> StopReason {
        let n = self.iterations.len();
        let updates = n - 1;
        let eps = self.iterations[n - 1];
        let threshold = options.threshold;
        let last_change = if n >= 2 {
            (self.iterations[n - 1] - self.iterations[n - 2]).abs()
        } else {
            f64::INFINITY
        };
        if self.cancelled {
            StopReason::Cancelled {
                epsilon: eps,
                threshold,
                updates,
            }
        } else if eps <= threshold {
            StopReason::Converged {
                epsilon: eps,
                threshold,
                updates,
            }
        } else if let Some(relative_change) = self.converged {
            StopReason::SolverConverged {
                epsilon: eps,
                threshold,
                updates,
                relative_change,
            }
        } else if self.levelled >= LEVELLED_OFF_UPDATES {
            StopReason::LevelledOff {
                epsilon: eps,
                threshold,
                updates,
                last_change,
            }
        } else {
            StopReason::IterationLimit {
                epsilon: eps,
                threshold,
                updates,
                last_change,
            }
        }
    }
}

/// The loop of FORMAT.md "The iteration" around `method` over the
/// identify `stations`: compute ε; while ε > threshold, fewer than
/// `max_iterations` updates were made, the method has not converged and ε
/// has not levelled off, update and compute ε again. `progress` hears of
/// every ε and every inner step, and may cancel (`cancelled`: it did
/// already, while the method was set up).
///
/// # Errors
/// As the method's update, or a non-finite ε.
fn iterate(
    method: &mut dyn Update,
    stations: &[Station],
    options: &Options,
    cancelled: bool,
    progress: &mut dyn FnMut(&Progress) -> Control,
) -> Result<Looped, SolveError> {
    let eps_of = |est: &Estimate| epsilon(&est.station_centres(stations));
    let mut eps = eps_of(method.estimate());
    let mut iterations = vec![eps];
    let report = |updates: usize, epsilon: f64, phase: Phase| Progress {
        updates,
        epsilon,
        max_iterations: options.max_iterations,
        threshold: options.threshold,
        phase,
    };
    let mut cancelled = cancelled || progress(&report(0, eps, Phase::Loop)) == Control::Cancel;
    let mut converged = None;
    let mut levelled = 0_usize;
    while !cancelled
        && converged.is_none()
        && levelled < LEVELLED_OFF_UPDATES
        && eps > options.threshold
        && iterations.len() - 1 < options.max_iterations
    {
        let updates = iterations.len();
        let (done, now) = (updates - 1, eps);
        let mut inner = |phase: Phase| progress(&report(done, now, phase));
        match method.update(updates, &mut inner)? {
            Step::Moved => {}
            Step::Converged { relative_change } => converged = Some(relative_change),
            Step::Stuck { relative_change } => {
                converged = Some(relative_change);
                continue;
            }
            Step::Cancelled => {
                cancelled = true;
                continue;
            }
        }
        let previous = eps;
        eps = eps_of(method.estimate());
        if !eps.is_finite() {
            return Err(SolveError::NonFinite { iteration: updates });
        }
        iterations.push(eps);
        levelled = if (eps - previous).abs() <= LEVELLED_OFF_STOP_MM {
            levelled + 1
        } else {
            0
        };
        cancelled = progress(&report(updates, eps, Phase::Loop)) == Control::Cancel;
    }
    Ok(Looped {
        iterations,
        cancelled,
        converged,
        levelled,
    })
}

/// The run cancelled before its method was set up: the start, ε of the
/// start, and a report of the settings only.
fn cancelled_in_setup(
    session: &Session,
    prepared: &Prepared,
    options: &Options,
    start: &Estimate,
    stations: &[estimate::Station],
) -> Calibration {
    let eps = epsilon(&start.station_centres(stations));
    let stop = StopReason::Cancelled {
        epsilon: eps,
        threshold: options.threshold,
        updates: 0,
    };
    let report = SolverReport::Ml(Box::new(ml::MlReport {
        stop: stop.record(options),
        ..ml::MlReport::default()
    }));
    finish(
        session,
        prepared,
        options,
        start,
        start.clone(),
        vec![eps],
        stop,
        report,
    )
}

/// The centres and statistics of a finished run.
#[allow(clippy::too_many_arguments)]
fn finish(
    session: &Session,
    prepared: &Prepared,
    options: &Options,
    start: &Estimate,
    est: Estimate,
    iterations: Vec<f64>,
    stop: StopReason,
    report: SolverReport,
) -> Calibration {
    let centre = |e: &Estimate, i: usize| -> Vector3<f64> {
        let station_from_sensor = e.station_from_sensor(&session.base_from_flange(&e.robot, i));
        (station_from_sensor * Point3::from(prepared.measurements[i].centre_in_sensor)).coords
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
    Calibration {
        options: *options,
        nominal: session.solver_robot(),
        calibrated: est.robot,
        hand_eye_initial: start.flange_from_sensor,
        hand_eye: est.flange_from_sensor,
        iterations,
        stop,
        report,
        centres,
        identify_within,
        validation,
        held_out: None,
    }
}

/// `prepare` then `run` with no progress reporting.
///
/// # Errors
/// As [`prepare`](fn@prepare) and [`run`].
pub fn calibrate(
    session: &Session,
    options: &Options,
) -> Result<(Prepared, Calibration), SolveError> {
    let prepared = prepare(session)?;
    let cal = run(session, &prepared, options, &mut |_| Control::Continue)?;
    Ok((prepared, cal))
}
