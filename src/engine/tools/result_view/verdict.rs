//! The verdict on a result: PASS or FAIL of its validation statistics
//! against the operator's acceptance tolerance (validation std and max,
//! mm). One rule for the workbench's headline and the HTML report.

use serde::{Deserialize, Serialize};

use super::Headline;

/// An acceptance tolerance on the validation after calibration, mm.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Tolerance {
    /// Largest accepted standard deviation of the validation errors, mm.
    pub std_mm: f64,
    /// Largest accepted absolute validation error, mm.
    pub max_mm: f64,
}

impl Default for Tolerance {
    /// 0.2 mm std and 0.5 mm max: a little above what the paper's cell
    /// reaches (std 0.173 mm); set it to the job's own figures.
    fn default() -> Self {
        Self {
            std_mm: 0.2,
            max_mm: 0.5,
        }
    }
}

/// A tolerance that cannot be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ToleranceError {
    /// Not two parts.
    #[error("`{0}`: give STD,MAX in mm, e.g. 0.2,0.5")]
    NotTwo(String),
    /// A part that is not a positive number.
    #[error("`{0}` is not a positive number of mm")]
    NotPositive(String),
}

/// The message, for the edges that show errors as text (the command
/// line's value parser).
impl From<ToleranceError> for String {
    fn from(e: ToleranceError) -> Self {
        e.to_string()
    }
}

impl Tolerance {
    /// Parses `STD,MAX` (mm), e.g. `0.2,0.5`.
    ///
    /// # Errors
    /// [`ToleranceError`]: not two positive finite numbers separated by a
    /// comma.
    pub fn parse(s: &str) -> Result<Self, ToleranceError> {
        let parts: Vec<&str> = s.split(',').map(str::trim).collect();
        let [std, max] = parts.as_slice() else {
            return Err(ToleranceError::NotTwo(s.to_string()));
        };
        let value = |t: &str| -> Result<f64, ToleranceError> {
            t.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite() && *v > 0.0)
                .ok_or_else(|| ToleranceError::NotPositive(t.to_string()))
        };
        Ok(Self {
            std_mm: value(std)?,
            max_mm: value(max)?,
        })
    }

    /// Whether both limits are positive and finite.
    #[must_use]
    pub fn is_valid(&self) -> bool {
        [self.std_mm, self.max_mm]
            .iter()
            .all(|v| v.is_finite() && *v > 0.0)
    }
}

/// The verdict on a result.
#[derive(Debug, Clone, PartialEq)]
pub enum Verdict {
    /// Both figures within the tolerance.
    Pass,
    /// A figure beyond the tolerance; the reasons in words.
    Fail(Vec<String>),
    /// The result has no validation to judge (no validate measurements).
    NotChecked,
}

impl Verdict {
    /// The verdict of the headline's after-calibration figures.
    #[must_use]
    pub fn of(headline: Option<&Headline>, tolerance: &Tolerance) -> Self {
        let Some(h) = headline else {
            return Self::NotChecked;
        };
        let after = h.stats.after;
        let mut reasons = Vec::new();
        // NaN is never within.
        let within = |value: f64, limit: f64| value <= limit;
        if !within(after.std, tolerance.std_mm) {
            reasons.push(format!(
                "std {:.3} mm > {:.3} mm",
                after.std, tolerance.std_mm
            ));
        }
        if !within(after.max, tolerance.max_mm) {
            reasons.push(format!(
                "max {:.3} mm > {:.3} mm",
                after.max, tolerance.max_mm
            ));
        }
        if reasons.is_empty() {
            Self::Pass
        } else {
            Self::Fail(reasons)
        }
    }

    /// `PASS`, `FAIL` or `NOT CHECKED`.
    #[must_use]
    pub fn word(&self) -> &'static str {
        match self {
            Self::Pass => "PASS",
            Self::Fail(_) => "FAIL",
            Self::NotChecked => "NOT CHECKED",
        }
    }

    /// One line: the word, the tolerance and why.
    #[must_use]
    pub fn describe(&self, tolerance: &Tolerance) -> String {
        let limits = format!(
            "tolerance std ≤ {:.3} mm, max ≤ {:.3} mm",
            tolerance.std_mm, tolerance.max_mm
        );
        match self {
            Self::Pass => format!("PASS: validation within the {limits}"),
            Self::Fail(r) => format!("FAIL: {} ({limits})", r.join(", ")),
            Self::NotChecked => "NOT CHECKED: the session has no validate measurements".to_string(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::calibrate::validate::{BeforeAfter, Stats};

    fn headline(std: f64, max: f64) -> Headline {
        Headline {
            what: "validation".into(),
            stats: BeforeAfter {
                before: Stats {
                    max: 9.0,
                    std: 5.0,
                    rms: 5.0,
                },
                after: Stats { max, std, rms: std },
            },
        }
    }

    #[test]
    fn pass_and_fail_follow_the_tolerance() {
        let t = Tolerance::default();
        assert_eq!(Verdict::of(Some(&headline(0.17, 0.4)), &t), Verdict::Pass);
        let v = Verdict::of(Some(&headline(0.25, 0.4)), &t);
        assert_eq!(v.word(), "FAIL");
        assert!(v.describe(&t).contains("std 0.250 mm > 0.200 mm"));
        let v = Verdict::of(Some(&headline(0.1, 0.6)), &t);
        assert!(v.describe(&t).contains("max 0.600 mm > 0.500 mm"));
        assert_eq!(Verdict::of(None, &t), Verdict::NotChecked);
        // At the limit passes; NaN fails.
        assert_eq!(Verdict::of(Some(&headline(0.2, 0.5)), &t), Verdict::Pass);
        assert_eq!(
            Verdict::of(Some(&headline(f64::NAN, 0.1)), &t).word(),
            "FAIL"
        );
    }

    #[test]
    fn tolerances_parse() {
        assert_eq!(
            Tolerance::parse("0.1, 0.3").unwrap(),
            Tolerance {
                std_mm: 0.1,
                max_mm: 0.3
            }
        );
        assert!(Tolerance::parse("0.1").is_err());
        assert!(Tolerance::parse("0,1").is_err());
        assert!(Tolerance::parse("x,1").is_err());
    }
}
