//! What a method reports about a run: the typed form of the result file's
//! `solver` block. A run fills it in directly; the
//! [`format`](crate::engine::files::format) module writes it to a result file and
//! reads it back, and nothing else touches the JSON.

use std::fmt;
use std::str::FromStr;

use serde_json::{Map, Value};

pub use super::loop_record::LoopRecord;
use super::ml::MlReport;

/// A rise of ε over the paper's loop up to this (mm) is rounding, not a
/// worse calibration: a tenth of a micrometre, below any stripe sensor's
/// resolution.
pub const EPSILON_RISE_MM: f64 = 1e-4;

/// The warning when the paper's loop ended with ε above its start (by
/// more than [`EPSILON_RISE_MM`]), naming what to run instead; `pairs` is
/// the pairing the run used (`disjoint`, `all`, or unknown). The result
/// keeps the loop's last update, as FORMAT.md's loop defines it (every
/// update is reported and `epsilon_after` is the last ε): on a one-station
/// pose-only set the best iterate is often the start itself, and handing
/// the initial hand-eye back as "calibrated" would hide that the method
/// failed on this data.
#[must_use]
pub fn epsilon_rise_warning(pairs: Option<&str>, before: f64, after: f64) -> Option<String> {
    // A NaN compares false: no warning.
    let rose = after - before > EPSILON_RISE_MM;
    if !rose {
        return None;
    }
    let (fits, instead) = if pairs == Some(Pairing::All.as_str()) {
        (
            "the differences of every pair",
            "rerun with `--method ml` (maximum likelihood: every measurement once against its station's centre, weighted by its noise; the workbench's Method ml)",
        )
    } else {
        (
            "the differences of its disjoint pairs (1,2), (3,4), …",
            "rerun with `--method ml` (maximum likelihood: every measurement once against its station's centre, weighted by its noise) or `--pairs all` (every pair of a station's measurements); in the workbench, Method ml or Pairs all",
        )
    };
    Some(format!(
        "ε rose from {before:.4} mm to {after:.4} mm: the paper's updates left the identify centres scattering more than the start did (its update fits {fits}, not ε); {instead}"
    ))
}

/// The warning when the loop made no update because ε started at or
/// below the threshold (FORMAT.md "The iteration": one `iterations`
/// entry): nothing was identified, the result is the start. `updates`:
/// updates made; `threshold`: the loop's, when known. One wording for
/// `calibrate`'s console, the workbench's Results, its status line and
/// its step bar.
#[must_use]
pub fn no_update_warning(updates: usize, epsilon: f64, threshold: Option<f64>) -> Option<String> {
    let threshold = threshold.filter(|t| updates == 0 && epsilon <= *t)?;
    Some(format!(
        "no update: ε = {} mm started within the threshold {} mm, so nothing was identified and the result holds the uncalibrated model and initial hand-eye; to refine anyway, run again with threshold 0 (`--threshold 0`; in the workbench, Next's \"Run again with threshold 0\"), which makes updates until ε stops falling (or the most updates are made)",
        crate::engine::base::numeric::approx(epsilon),
        crate::engine::base::numeric::show(threshold)
    ))
}

/// How the measurements of a station are paired into eq. 17 rows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pairing {
    /// The paper's: consecutive disjoint pairs (1,2), (3,4), (5,6) in file
    /// order; an odd last measurement is paired with the first.
    Disjoint,
    /// Every pair `i < j`.
    All,
}

impl Pairing {
    /// The name written in the result's `solver.pairs`.
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Disjoint => "disjoint",
            Self::All => "all",
        }
    }

    /// Parses `disjoint` or `all`.
    #[must_use]
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "disjoint" => Some(Self::Disjoint),
            "all" => Some(Self::All),
            _ => None,
        }
    }

    /// The index pairs for a station of `n` measurements.
    #[must_use]
    pub fn pairs(self, n: usize) -> Vec<(usize, usize)> {
        match self {
            Self::All => (0..n)
                .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
                .collect(),
            Self::Disjoint => {
                let mut out: Vec<(usize, usize)> = (0..n / 2).map(|k| (2 * k, 2 * k + 1)).collect();
                if n % 2 == 1 && n >= 3 {
                    out.push((n - 1, 0));
                }
                out
            }
        }
    }
}

/// The solver block of a result: the paper's method, `ml`, or a method this
/// build does not know (a later version's result, kept as read).
#[derive(Debug, Clone, PartialEq)]
pub enum SolverReport {
    /// The paper's update (section 3.2): paired differences, truncated SVD.
    Paper(Box<PaperReport>),
    /// The maximum-likelihood method.
    Ml(Box<MlReport>),
    /// Another method's block, as read from a file.
    Other {
        /// `solver.method`.
        method: String,
        /// Every other key of the block.
        block: Map<String, Value>,
    },
}

impl SolverReport {
    /// `solver.method`: `paper`, `ml`, or what the file says.
    #[must_use]
    pub fn method(&self) -> &str {
        match self {
            Self::Paper(_) => "paper",
            Self::Ml(_) => "ml",
            Self::Other { method, .. } => method,
        }
    }

    /// The `ml` report, when the method is `ml`.
    #[must_use]
    pub fn ml(&self) -> Option<&MlReport> {
        match self {
            Self::Ml(r) => Some(r),
            _ => None,
        }
    }

    /// The paper's report, when the method is the paper's.
    #[must_use]
    pub fn paper(&self) -> Option<&PaperReport> {
        match self {
            Self::Paper(r) => Some(r),
            _ => None,
        }
    }

    /// The threshold on ε of the loop, mm, when the block says.
    #[must_use]
    pub fn threshold(&self) -> Option<f64> {
        match self {
            Self::Paper(r) => r.threshold,
            Self::Ml(r) => Some(r.stop.threshold),
            Self::Other { .. } => None,
        }
    }

    /// Why the loop stopped, in words, when the block says.
    #[must_use]
    pub fn stop_reason(&self) -> Option<&str> {
        match self {
            Self::Paper(r) => r.stop_reason.as_deref(),
            Self::Ml(r) => Some(&r.stop.stop_reason),
            Self::Other { .. } => None,
        }
    }

    /// The warning a method gives about the ε of its loop, from `before`
    /// to `after` (mm): the paper's method when ε rose
    /// ([`epsilon_rise_warning`](epsilon_rise_warning)).
    #[must_use]
    pub fn epsilon_warning(&self, before: f64, after: f64) -> Option<String> {
        match self {
            Self::Paper(p) => epsilon_rise_warning(p.pairs.as_deref(), before, after),
            Self::Ml(_) | Self::Other { .. } => None,
        }
    }

    /// Parameters the method held fixed at their start (`ml`'s fixed set;
    /// empty for a method that does not fix parameters).
    #[must_use]
    pub fn fixed(&self) -> &[String] {
        match self {
            Self::Ml(r) => &r.fixed,
            _ => &[],
        }
    }

    /// Parameters the method estimated (`ml`'s identifiable set; empty when
    /// the method does not say).
    #[must_use]
    pub fn estimated(&self) -> &[String] {
        match self {
            Self::Ml(r) => &r.estimated,
            _ => &[],
        }
    }
}

/// The paper's method as reported. Every key is optional: a run fills
/// them all in, a file written by another implementation may hold fewer,
/// and [`format`](crate::engine::files::format) writes back only those present
/// (keys it does not know, or of another type, stay in `extra`).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PaperReport {
    /// Pairing of a station's measurements (`disjoint` or `all`).
    pub pairs: Option<String>,
    /// Relative SVD tolerance (fraction of σ_max).
    pub svd_tolerance: Option<f64>,
    /// How the unknowns were scaled before the SVD, in words.
    pub column_scaling: Option<String>,
    /// Threshold on ε, mm.
    pub threshold: Option<f64>,
    /// Most updates.
    pub max_iterations: Option<usize>,
    /// Stop code.
    pub stop: Option<String>,
    /// Why the loop stopped, in words.
    pub stop_reason: Option<String>,
    /// Singular values the last update's SVD kept.
    pub kept_directions: Option<usize>,
    /// Rows of the last update's `U` (3 per pair).
    pub equations: Option<usize>,
    /// Singular values of the column-scaled `U`, descending.
    pub singular_values: Option<Vec<f64>>,
    /// The directions the truncation dropped.
    pub dropped_directions: Option<Vec<Direction>>,
    /// Labels of the unknowns, `ΔY` order.
    pub unknowns: Option<Vec<String>>,
    /// Keys of the block this build does not read, kept as they were.
    pub extra: Map<String, Value>,
}

/// A direction of `ΔY` (scaled space) by its dominant unknowns, strongest
/// first, coefficients as written (two decimals): `+0.71·d6 -0.71·he_z`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Direction {
    /// `(coefficient, label)`, the largest coefficient positive.
    pub terms: Vec<(f64, String)>,
}

impl fmt::Display for Direction {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (k, (c, label)) in self.terms.iter().enumerate() {
            if k > 0 {
                f.write_str(" ")?;
            }
            write!(f, "{c:+.2}·{label}")?;
        }
        Ok(())
    }
}

impl FromStr for Direction {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let mut terms = Vec::new();
        for term in s.split_whitespace() {
            let (c, label) = term
                .split_once('·')
                .ok_or_else(|| format!("`{term}` is not `coefficient·label`"))?;
            let c: f64 = c
                .replace('−', "-")
                .parse()
                .map_err(|_| format!("`{c}` is not a number"))?;
            terms.push((c, label.to_string()));
        }
        Ok(Self { terms })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn directions_read_back_as_written() {
        let d = Direction {
            terms: vec![(0.7049, "d6".into()), (-0.7093, "he_z".into())],
        };
        assert_eq!(d.to_string(), "+0.70·d6 -0.71·he_z");
        let back: Direction = d.to_string().parse().unwrap();
        assert_eq!(back.to_string(), d.to_string());
        assert_eq!(back.terms[1], (-0.71, "he_z".to_string()));
        assert!("0.5".parse::<Direction>().is_err());
    }
}
