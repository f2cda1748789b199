//! Joint identification of hand-eye and kinematic errors, the paper's
//! section 3.2 (eq. 17-19): one linearised update of the unknowns
//! `ΔY = [ΔX; ΔP]` (6 hand-eye errors, `5·n` MDH errors), whose first-order
//! effect on a centre (eq. 10-16) is [`sensitivity`].
//!
//! Two measurements of one station see one point, so for a pair `(i, j)`
//! `X_i − X_j = [R_j·P_j − R_i·P_i,  Q_j·J_j − Q_i·J_i] · ΔY` (eq. 17, with
//! the corrected second block). The pairs are stacked (eq. 18) and solved
//! with a truncated SVD (eq. 19).
//!
//! **Column scaling.** Angle unknowns (rad) are multiplied by
//! [`ANGLE_SCALE_MM`] before the SVD, so that every unknown is in mm of
//! motion at a typical lever (1 mrad at 1 m = 1 mm). Singular values below
//! `svd_tolerance × σ_max` of the scaled matrix are dropped. Unit-norm
//! column scaling is not used: it would inflate the nearly-null columns of
//! the rigid-motion parameters of joint 1 until they fit noise.

use nalgebra::{DMatrix, DVector, Vector3};

use super::{Control, HeldOut, Options, Phase, SolveError, Step, StopReason, Update};
use crate::engine::base::numeric::as_written;
use crate::engine::base::records::solver::{Direction, PaperReport, SolverReport};

use super::estimate::{
    ANGLE_SCALE_MM, Estimate, Station, sensitivity, unknown_label, unknown_scale,
};

/// Default relative SVD tolerance: singular values below this fraction of
/// the largest are dropped. Chosen on simulated paper-like sessions (see
/// README "Accuracy"): low enough to keep the weakly observed hand-eye
/// rotation, high enough to drop the rigid-motion directions of joint 1.
pub const DEFAULT_SVD_TOLERANCE: f64 = 1e-3;

pub use crate::engine::base::records::solver::{EPSILON_RISE_MM, Pairing, epsilon_rise_warning};

/// Settings of the paper's update.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PaperOptions {
    /// Pairing of the measurements of a station.
    pub pairing: Pairing,
    /// Relative SVD tolerance (fraction of σ_max).
    pub svd_tolerance: f64,
}

impl Default for PaperOptions {
    fn default() -> Self {
        Self {
            pairing: Pairing::Disjoint,
            svd_tolerance: DEFAULT_SVD_TOLERANCE,
        }
    }
}

/// What one update saw and did.
#[derive(Debug, Clone, PartialEq)]
pub struct UpdateInfo {
    /// Singular values of the column-scaled `U`, descending.
    pub singular_values: Vec<f64>,
    /// How many were kept (above `svd_tolerance × σ_max`).
    pub kept: usize,
    /// Rows of `U` (3 per pair).
    pub rows: usize,
    /// The update `ΔY` (mm, rad).
    pub delta: Vec<f64>,
    /// The dropped directions, each as its dominant unknowns, e.g.
    /// `+0.71·d6 −0.71·he_z`, strongest first.
    pub dropped: Vec<Direction>,
}

/// Eq. 17-19: builds `U ΔY = V` over all pairs of all stations and solves
/// it with the truncated SVD. Returns the update and what it saw.
///
/// # Errors
/// [`SolveError::NotEnoughData`] when no station yields a pair,
/// [`SolveError::InvalidOption`] for a tolerance outside (0, 1).
pub fn paper_update(
    est: &Estimate,
    stations: &[Station],
    options: &PaperOptions,
) -> Result<UpdateInfo, SolveError> {
    if !(options.svd_tolerance > 0.0 && options.svd_tolerance < 1.0) {
        return Err(SolveError::InvalidOption(format!(
            "svd tolerance must be in (0, 1), got {}",
            options.svd_tolerance
        )));
    }
    let n_unknowns = 6 + est.robot.n_params();
    let mut blocks: Vec<(DMatrix<f64>, Vector3<f64>)> = Vec::new();
    for st in stations {
        let sens: Vec<(Vector3<f64>, DMatrix<f64>)> =
            st.sightings.iter().map(|s| sensitivity(est, s)).collect();
        for (i, j) in options.pairing.pairs(sens.len()) {
            let u = &sens[j].1 - &sens[i].1;
            let v = sens[i].0 - sens[j].0;
            blocks.push((u, v));
        }
    }
    if blocks.is_empty() {
        return Err(SolveError::NotEnoughData {
            detail: format!(
                "{} identify station(s), none with 2 or more measurements",
                stations.len()
            ),
        });
    }
    let rows = 3 * blocks.len();
    let mut u = DMatrix::zeros(rows, n_unknowns);
    let mut v = DVector::zeros(rows);
    for (k, (bu, bv)) in blocks.iter().enumerate() {
        u.view_mut((3 * k, 0), (3, n_unknowns)).copy_from(bu);
        v.fixed_rows_mut::<3>(3 * k).copy_from(bv);
    }
    // Column scaling: unknown_scaled = scale · unknown.
    let scale: Vec<f64> = (0..n_unknowns).map(unknown_scale).collect();
    for (c, s) in scale.iter().enumerate() {
        u.column_mut(c).scale_mut(1.0 / s);
    }
    let (scaled_delta, singular_values, kept, dropped_dirs) =
        truncated_solve(u, &v, options.svd_tolerance);
    let delta: Vec<f64> = scaled_delta
        .iter()
        .zip(&scale)
        .map(|(d, s)| d / s)
        .collect();
    let dropped = dropped_dirs.iter().map(|d| describe_direction(d)).collect();
    Ok(UpdateInfo {
        singular_values,
        kept,
        rows,
        delta,
        dropped,
    })
}

/// Truncated-SVD least squares (eq. 19): `x = E · S⁺ · Fᵀ · v`, keeping
/// singular values ≥ `tol · σ_max`. Also returns the singular values
/// (descending, padded with zeros to the column count), the number kept
/// and the dropped right singular vectors.
fn truncated_solve(
    u: DMatrix<f64>,
    v: &DVector<f64>,
    tol: f64,
) -> (Vec<f64>, Vec<f64>, usize, Vec<Vec<f64>>) {
    let ncols = u.ncols();
    // Thin SVD of a tall matrix: min(rows, cols) singular values.
    let Some(svd) = nalgebra::SVD::try_new(
        u,
        true,
        true,
        f64::EPSILON,
        crate::engine::base::numeric::MAX_DECOMPOSITION_SWEEPS,
    ) else {
        return (vec![0.0; ncols], vec![0.0; ncols], 0, Vec::new());
    };
    let (Some(left), Some(right_t)) = (svd.u, svd.v_t) else {
        return (vec![0.0; ncols], vec![0.0; ncols], 0, Vec::new());
    };
    let sv = svd.singular_values;
    let mut order: Vec<usize> = (0..sv.len()).collect();
    order.sort_by(|a, b| sv[*b].total_cmp(&sv[*a]));
    let smax = order.first().map_or(0.0, |&k| sv[k]);
    let mut x = DVector::zeros(ncols);
    let mut kept = 0;
    let mut dropped = Vec::new();
    for &k in &order {
        let row = right_t.row(k);
        if smax > 0.0 && sv[k] >= tol * smax {
            let coef = left.column(k).dot(v) / sv[k];
            x += row.transpose() * coef;
            kept += 1;
        } else {
            dropped.push(row.iter().copied().collect());
        }
    }
    // Directions beyond the rank of a short matrix are dropped too: the
    // thin SVD has no vector for them; they are the complement.
    let mut values: Vec<f64> = order.iter().map(|&k| sv[k]).collect();
    values.resize(ncols, 0.0);
    (x.iter().copied().collect(), values, kept, dropped)
}

/// A direction of `ΔY` (scaled space) as its dominant unknowns.
fn describe_direction(d: &[f64]) -> Direction {
    /// Components smaller than this are left out of the description.
    const SHOWN: f64 = 0.2;
    let mut parts: Vec<(usize, f64)> = d
        .iter()
        .copied()
        .enumerate()
        .filter(|(_, c)| c.abs() >= SHOWN)
        .collect();
    parts.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()));
    // Make the largest component positive so the sign is canonical.
    let sign = parts.first().map_or(1.0, |p| p.1.signum());
    Direction {
        terms: parts
            .iter()
            .map(|(k, c)| (as_written(c * sign, 2), unknown_label(*k)))
            .collect(),
    }
}

/// The paper's update inside the loop: one [`paper_update`] per update.
pub struct PaperUpdate {
    /// Where the loop started (the held-out refits start there too).
    start: Estimate,
    est: Estimate,
    stations: Vec<Station>,
    options: Options,
    last: Option<UpdateInfo>,
    /// Updates made.
    updates: usize,
}

impl PaperUpdate {
    /// The update from the start `est` over the identify `stations`.
    #[must_use]
    pub fn new(est: Estimate, stations: Vec<Station>, options: &Options) -> Self {
        Self {
            start: est.clone(),
            est,
            stations,
            options: *options,
            last: None,
            updates: 0,
        }
    }
}

impl Update for PaperUpdate {
    fn estimate(&self) -> &Estimate {
        &self.est
    }

    fn update(
        &mut self,
        update: usize,
        _phase: &mut dyn FnMut(Phase) -> Control,
    ) -> Result<Step, SolveError> {
        let info = paper_update(&self.est, &self.stations, &self.options.paper)?;
        if info.delta.iter().any(|d| !d.is_finite()) {
            return Err(SolveError::NonFinite { iteration: update });
        }
        self.est = self.est.updated(&info.delta);
        self.last = Some(info);
        self.updates += 1;
        Ok(Step::Moved)
    }

    /// Exact refits of the paper's own loop ([`held_out`](super::held_out)).
    fn held_out(&self, phase: &mut dyn FnMut(Phase) -> Control) -> Option<HeldOut> {
        let refit_from = |training: Vec<Station>| -> Box<dyn Update> {
            Box::new(PaperUpdate::new(
                self.start.clone(),
                training,
                &self.options,
            ))
        };
        super::held_out::paper_refits(&refit_from, &self.est, self.updates, &self.stations, phase)
    }

    fn report(
        self: Box<Self>,
        stop: &StopReason,
        _phase: &mut dyn FnMut(Phase) -> Control,
    ) -> (SolverReport, bool) {
        let o = &self.options;
        let record = stop.record(o);
        let last = self.last;
        let report = SolverReport::Paper(Box::new(PaperReport {
            pairs: Some(o.paper.pairing.as_str().to_string()),
            svd_tolerance: Some(o.paper.svd_tolerance),
            column_scaling: Some(format!(
                "angle unknowns × {ANGLE_SCALE_MM} mm/rad before the SVD"
            )),
            threshold: Some(record.threshold),
            max_iterations: Some(record.max_iterations),
            stop: Some(record.stop),
            stop_reason: Some(record.stop_reason),
            kept_directions: last.as_ref().map(|i| i.kept),
            equations: last.as_ref().map(|i| i.rows),
            unknowns: last
                .as_ref()
                .map(|i| (0..i.delta.len()).map(unknown_label).collect()),
            singular_values: last.as_ref().map(|i| i.singular_values.clone()),
            dropped_directions: last.map(|i| i.dropped),
            extra: serde_json::Map::new(),
        }));
        (report, false)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rise_of_epsilon_is_a_warning_naming_the_other_methods() {
        let w = epsilon_rise_warning(Some("disjoint"), 0.3699, 0.3757).unwrap();
        assert!(w.contains("ε rose from 0.3699 mm to 0.3757 mm"), "{w}");
        assert!(
            w.contains("`--method ml`") && w.contains("`--pairs all`"),
            "{w}"
        );
        let w = epsilon_rise_warning(Some("all"), 0.3, 0.4).unwrap();
        assert!(
            w.contains("`--method ml`") && !w.contains("--pairs all"),
            "{w}"
        );
        // A fall, no change, and a rise within rounding: no warning.
        assert!(epsilon_rise_warning(None, 0.37, 0.35).is_none());
        assert!(epsilon_rise_warning(None, 0.37, 0.37).is_none());
        assert!(epsilon_rise_warning(None, 0.37, 0.37 + 0.5 * EPSILON_RISE_MM).is_none());
        assert!(epsilon_rise_warning(None, 0.37, f64::NAN).is_none());
        assert!(epsilon_rise_warning(None, 0.37, 0.37 + 2.0 * EPSILON_RISE_MM).is_some());
    }

    #[test]
    fn pairings() {
        assert_eq!(Pairing::Disjoint.pairs(6), vec![(0, 1), (2, 3), (4, 5)]);
        assert_eq!(Pairing::Disjoint.pairs(5), vec![(0, 1), (2, 3), (4, 0)]);
        assert_eq!(Pairing::Disjoint.pairs(2), vec![(0, 1)]);
        assert_eq!(Pairing::All.pairs(4).len(), 6);
    }

    #[test]
    fn truncated_solve_drops_null_direction() {
        // Two identical columns: the difference direction is null.
        let u = DMatrix::from_row_slice(3, 2, &[1.0, 1.0, 2.0, 2.0, 0.0, 0.0]);
        let v = DVector::from_row_slice(&[2.0, 4.0, 0.0]);
        let (x, sv, kept, dropped) = truncated_solve(u, &v, 1e-6);
        assert_eq!(kept, 1);
        assert_eq!(dropped.len(), 1);
        assert!(sv[1].abs() < 1e-12);
        // Minimum-norm solution splits equally.
        assert!((x[0] - 1.0).abs() < 1e-12 && (x[1] - 1.0).abs() < 1e-12);
    }
}
