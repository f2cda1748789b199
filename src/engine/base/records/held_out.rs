//! The result's `held_out` block: each identify measurement predicted by a
//! calibration made without it, the figure over them and how the refits
//! were made (computed by `calibrate::solve::held_out`).

use std::fmt;

use serde::{Deserialize, Serialize};

use super::validation::Stats;

/// How the refits of a held-out figure were made.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum HeldOutScheme {
    /// One refit per identify measurement, without it.
    #[default]
    LeaveOnePoseOut,
    /// `K` refits, each without one fold of the measurements.
    KFold,
}

impl HeldOutScheme {
    /// In words, with the number of refits: `leave-one-pose-out` or `10-fold`.
    #[must_use]
    pub fn label(self, folds: usize) -> String {
        match self {
            Self::LeaveOnePoseOut => "leave-one-pose-out".to_string(),
            Self::KFold => format!("{folds}-fold"),
        }
    }

    /// What one refit leaves out: `measurements` or `folds`.
    #[must_use]
    pub fn unit(self) -> &'static str {
        match self {
            Self::LeaveOnePoseOut => "measurements",
            Self::KFold => "folds",
        }
    }
}

/// One identify measurement's held-out prediction.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HeldOutRecord {
    /// Measurement id.
    pub measurement: String,
    /// Station id.
    pub station: String,
    /// `|X_i' − c_s'|` under the calibration made without it, mm (base frame).
    pub held_out: f64,
    /// `|X_i − c_s|` under the calibration itself, mm (base frame).
    pub fit: f64,
}

/// The held-out figure: the result file's top-level `held_out` key.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HeldOut {
    /// `leave_one_pose_out` or `k_fold`.
    pub scheme: HeldOutScheme,
    /// Refits made: one per measurement, or one per fold.
    pub folds: usize,
    /// How each refit was made, in words.
    pub refit: String,
    /// RMS of the held-out errors (3-D), mm.
    pub rms: f64,
    /// Largest held-out error, mm.
    pub max: f64,
    /// The measurement with the largest held-out error.
    pub max_measurement: String,
    /// RMS of the fit's own residuals over the same measurements, mm.
    pub fit_rms: f64,
    /// Largest of the fit's own residuals, mm.
    pub fit_max: f64,
    /// Measurements whose refit left a direction undetermined (the
    /// measurement alone determined it): no prediction.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub undetermined: Vec<String>,
    /// Every predicted measurement, in station order.
    pub measurements: Vec<HeldOutRecord>,
}

impl HeldOut {
    /// The figure of the predictions `rows`.
    #[must_use]
    pub fn new(
        scheme: HeldOutScheme,
        folds: usize,
        refit: String,
        measurements: Vec<HeldOutRecord>,
        undetermined: Vec<String>,
    ) -> Self {
        let held: Vec<f64> = measurements.iter().map(|r| r.held_out).collect();
        let fit: Vec<f64> = measurements.iter().map(|r| r.fit).collect();
        let (held, fit) = (Stats::of(&held), Stats::of(&fit));
        let max_measurement = measurements
            .iter()
            .max_by(|a, b| a.held_out.total_cmp(&b.held_out))
            .map(|r| r.measurement.clone())
            .unwrap_or_default();
        Self {
            scheme,
            folds,
            refit,
            rms: held.rms,
            max: held.max,
            max_measurement,
            fit_rms: fit.rms,
            fit_max: fit.max,
            undetermined,
            measurements,
        }
    }

    /// `leave-one-pose-out` or `10-fold`.
    #[must_use]
    pub fn label(&self) -> String {
        self.scheme.label(self.folds)
    }

    /// Held-out rms over the fit's own (1 when both are 0).
    #[must_use]
    pub fn ratio(&self) -> f64 {
        if self.fit_rms > 0.0 {
            self.rms / self.fit_rms
        } else {
            1.0
        }
    }
}

impl fmt::Display for HeldOut {
    /// One line: `held out (leave-one-pose-out): rms 0.310 mm, max 0.620
    /// mm (p5); fit's own scatter rms 0.240 mm, max 0.560 mm`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "held out ({}): rms {:.3} mm, max {:.3} mm",
            self.label(),
            self.rms,
            self.max
        )?;
        if !self.max_measurement.is_empty() {
            write!(f, " ({})", self.max_measurement)?;
        }
        write!(
            f,
            "; fit's own scatter rms {:.3} mm, max {:.3} mm",
            self.fit_rms, self.fit_max
        )?;
        if !self.undetermined.is_empty() {
            write!(
                f,
                "; {} measurement(s) not predictable without themselves: {}",
                self.undetermined.len(),
                self.undetermined.join(", ")
            )?;
        }
        Ok(())
    }
}
