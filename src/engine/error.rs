//! One error enum per engine area. Every message says what is wrong and
//! where: the measurement id (and, for file errors, the file path, last).
//! Callers add context once (the CLI prints, the app shows); nothing here
//! prints.

use std::path::PathBuf;

/// A circle fit or sphere-centre computation failed (one stripe).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StripeError {
    /// Fewer points than a circle fit needs.
    #[error("stripe has {found} points, at least {needed} are needed")]
    TooFewPoints {
        /// Points in the stripe.
        found: usize,
        /// Minimum (FORMAT.md: 5).
        needed: usize,
    },
    /// A point is NaN or infinite.
    #[error("stripe point {index} is not finite")]
    NonFinite {
        /// Index of the point.
        index: usize,
    },
    /// The points do not determine a circle (collinear or coincident).
    #[error("stripe points are collinear or coincident: no circle fits them")]
    Degenerate,
    /// After rejecting outliers too few points remain.
    #[error("only {kept} of {total} stripe points remain after outlier rejection")]
    TooManyOutliers {
        /// Points kept.
        kept: usize,
        /// Points in the stripe.
        total: usize,
    },
    /// Fitted radius larger than the sphere beyond the tolerance.
    #[error(
        "fitted stripe radius r = {r:.4} mm exceeds the sphere radius R = {sphere:.4} mm by {excess_pct:.2} % (tolerance 0.5 %)"
    )]
    RadiusTooLarge {
        /// Fitted radius, mm.
        r: f64,
        /// Sphere radius, mm.
        sphere: f64,
        /// `(r − R)/R` in percent.
        excess_pct: f64,
    },
    /// The sphere radius, the side or the fitted circle handed to the
    /// sphere-centre computation is unusable (radius not finite and
    /// positive, side not ±1).
    #[error("invalid sphere-centre input: {detail}")]
    InvalidInput {
        /// What is wrong, with the value.
        detail: String,
    },
}

/// A session or result file could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum FileError {
    /// The file could not be read or written at all.
    #[error("{action} failed: {source} ({path})")]
    Io {
        /// "reading" or "writing".
        action: &'static str,
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The file's content breaks a rule of FORMAT.md.
    #[error("{}{message} ({path})", measurement.as_ref().map(|m| format!("measurement {m}: ")).unwrap_or_default())]
    Invalid {
        /// The file.
        path: PathBuf,
        /// Id of the offending measurement, when the problem is in one.
        measurement: Option<String>,
        /// What is wrong.
        message: String,
    },
}

impl FileError {
    /// The measurement id the error names, if any.
    #[must_use]
    pub fn measurement(&self) -> Option<&str> {
        match self {
            Self::Invalid { measurement, .. } => measurement.as_deref(),
            Self::Io { .. } => None,
        }
    }
}

/// The initial hand-eye (paper 3.1) cannot be determined from the data.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HandEyeError {
    /// Fewer translation measurements than eq. 6-7 need.
    #[error(
        "the initial rotation (eq. 6-7) needs at least 3 translation measurements, the session has {found}{}",
        list_ids(ids)
    )]
    TooFewTranslations {
        /// Measurements found.
        found: usize,
        /// Their ids.
        ids: Vec<String>,
    },
    /// Translation displacements do not span a plane.
    #[error("the translation displacements of {} are collinear (second singular value {ratio:.2e} of the first): the rotation about their common direction is undetermined; move the robot in two different directions", ids.join(", "))]
    CollinearTranslations {
        /// Measurement ids involved.
        ids: Vec<String>,
        /// σ2/σ1 of the displacement matrix.
        ratio: f64,
    },
    /// Fewer rotation measurements than eq. 8-9 need.
    #[error(
        "the initial translation (eq. 8-9) needs at least 2 rotation measurements, the session has {found}{}",
        list_ids(ids)
    )]
    TooFewRotations {
        /// Measurements found.
        found: usize,
        /// Their ids.
        ids: Vec<String>,
    },
    /// Orientations do not differ enough (or only about one axis).
    #[error("the orientations of rotation measurements {} do not determine the translation (eq. 8-9): {detail}", ids.join(", "))]
    RotationsTooSimilar {
        /// Measurement ids involved.
        ids: Vec<String>,
        /// What was measured.
        detail: String,
    },
    /// Translation or rotation measurements span more than one station.
    #[error("all {usage} measurements must share one station, found stations {}", stations.join(", "))]
    MixedStations {
        /// "translation" or "rotation".
        usage: &'static str,
        /// The stations found.
        stations: Vec<String>,
    },
}

fn list_ids(ids: &[String]) -> String {
    if ids.is_empty() {
        String::new()
    } else {
        format!(" ({})", ids.join(", "))
    }
}

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
