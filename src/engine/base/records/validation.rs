//! The result's `validation` block (FORMAT.md) and the statistics of an
//! error list: what the paper's figures of merit (eq. 20, Fig. 5 and 6,
//! computed by `calibrate::validate`) are written as.

use serde::{Deserialize, Serialize};

/// FORMAT.md statistics of a list of errors `e`: `max |e|`, the sample
/// standard deviation (divisor `n − 1`) and `sqrt(mean e²)`. All mm.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stats {
    /// Largest absolute error, mm.
    pub max: f64,
    /// Sample standard deviation (divisor n − 1), mm; 0 for fewer than 2.
    pub std: f64,
    /// Root mean square, mm.
    pub rms: f64,
}

impl Stats {
    /// Statistics of `errors` (mm). Zeros for an empty list.
    #[must_use]
    pub fn of(errors: &[f64]) -> Self {
        let n = errors.len();
        if n == 0 {
            return Self::default();
        }
        let nf = n as f64;
        let mean = errors.iter().sum::<f64>() / nf;
        let max = errors.iter().fold(0.0_f64, |m, e| m.max(e.abs()));
        let rms = (errors.iter().map(|e| e * e).sum::<f64>() / nf).sqrt();
        let std = if n < 2 {
            0.0
        } else {
            (errors.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (nf - 1.0)).sqrt()
        };
        Self { max, std, rms }
    }
}

/// One reference distance compared with the measurement (FORMAT.md
/// `validation.distances`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DistanceRecord {
    /// Station id.
    pub from: String,
    /// Station id.
    pub to: String,
    /// `k`: the k-th validate measurement of each station (0-based, file order).
    pub pose: usize,
    /// Reference (tracker) distance, mm.
    pub reference: f64,
    /// Measured distance with the nominal model and initial hand-eye, mm.
    pub before: f64,
    /// Measured distance with the calibrated model and hand-eye, mm.
    pub after: f64,
}

impl DistanceRecord {
    /// `before − reference`, mm.
    #[must_use]
    pub fn error_before(&self) -> f64 {
        self.before - self.reference
    }

    /// `after − reference`, mm.
    #[must_use]
    pub fn error_after(&self) -> f64 {
        self.after - self.reference
    }
}

/// Before/after statistics of one kind of error.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BeforeAfter {
    /// With the nominal model and initial hand-eye.
    pub before: Stats,
    /// With the calibrated model and hand-eye.
    pub after: Stats,
}

/// FORMAT.md `validation` block.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Validation {
    /// Reference-distance comparisons (paper Fig. 6).
    pub distances: Vec<DistanceRecord>,
    /// Statistics of `measured − reference`, before.
    pub before: Stats,
    /// Statistics of `measured − reference`, after.
    pub after: Stats,
    /// Statistics of all pairwise distances within each validate station
    /// (true value zero; paper Fig. 5).
    pub within_station: BeforeAfter,
}
