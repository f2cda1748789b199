//! `ml`'s least-squares problem: whitened residuals `X_i − c_s` of every
//! identify measurement against its station's unknown centre, the prior
//! rows, and Levenberg-Marquardt over the estimated parameters and all
//! station centres; leave-one-station-out refits by one Gauss-Newton step.

use std::ops::AddAssign;

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

use super::noise::Loss;
use super::report::{CrossStation, CrossValidation};
use crate::engine::handeye::Sighting;
use crate::engine::solve::estimate::{Estimate, sensitivity};

/// Marquardt's starting damping (relative to `diag(JᵀJ)`): small, because
/// the nominal model is close enough for Gauss-Newton steps.
pub(super) const LAMBDA_START: f64 = 1e-4;

/// Damping factor after a rejected step.
pub(super) const LAMBDA_UP: f64 = 10.0;

/// Damping factor after an accepted step.
pub(super) const LAMBDA_DOWN: f64 = 0.3;

/// Smallest damping kept (pure Gauss-Newton below this is no different).
pub(super) const LAMBDA_MIN: f64 = 1e-12;

/// Largest damping tried before the step is declared impossible: the step
/// is then ~1e-10 of the Gauss-Newton step, i.e. at the numerical optimum.
pub(super) const LAMBDA_MAX: f64 = 1e10;

/// Floor of `diag(JᵀJ)` in the damping, relative to its largest entry,
/// so that a column with no data still gets damped.
pub(super) const DIAG_FLOOR_REL: f64 = 1e-12;

/// Converged when an accepted step lowers the cost by less than this
/// fraction: far below what changes any distance (cost ~ number of
/// residuals, so 1e-10 relative is ~1e-8 σ²).
pub(super) const COST_TOL: f64 = 1e-10;

/// Converged when the largest scaled step is below this, mm: a picometre.
pub(super) const STEP_TOL_MM: f64 = 1e-9;

/// One identify measurement as the solver sees it.
#[derive(Debug, Clone)]
pub(super) struct Obs {
    /// Index into the problem's stations.
    pub(super) station: usize,
    /// Joints and sensor-frame centre.
    pub(super) sighting: Sighting,
    /// `C⁻¹` with `Σ = C·Cᵀ` (base frame): whitens a residual.
    pub(super) whiten: Matrix3<f64>,
}

/// The current point of the solve: model, hand-eye and station centres.
#[derive(Debug, Clone)]
pub(super) struct State {
    pub(super) est: Estimate,
    /// Station centres, base frame, mm.
    pub(super) centres: Vec<Vector3<f64>>,
}

/// Which measurement rows a linearisation takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Rows {
    /// Every measurement and the prior.
    All,
    /// Only the measurements of one station (no prior).
    Only(usize),
}

impl Rows {
    pub(super) fn includes(self, station: usize) -> bool {
        match self {
            Self::All => true,
            Self::Only(s) => s == station,
        }
    }
}

/// The linearised problem at a state.
pub(super) struct Linear {
    /// `JᵀWJ` over [estimated parameters (scaled); centres].
    pub(super) h: DMatrix<f64>,
    /// `JᵀW·r`.
    pub(super) g: DVector<f64>,
    /// Robust cost.
    pub(super) cost: f64,
}

/// The prior on the kinematic deviations, in the estimated chart.
pub(super) struct Prior {
    /// Estimated slots that are kinematic parameters.
    pub(super) slots: Vec<usize>,
    /// Their nominal values (rad, mm).
    pub(super) nominal: Vec<f64>,
    /// Whitening of the prior (raw units): `diag(1/σ)`.
    pub(super) whiten: DMatrix<f64>,
}

/// The problem: observations, which unknowns are estimated, weights.
pub(super) struct Problem {
    pub(super) obs: Vec<Obs>,
    /// Identify station ids.
    pub(super) stations: Vec<String>,
    /// Estimated unknowns (indices into ΔY).
    pub(super) estimated: Vec<usize>,
    /// Scale of each estimated unknown (scaled = raw × scale).
    pub(super) scale: Vec<f64>,
    /// The prior, when used.
    pub(super) prior: Option<Prior>,

    /// Number of ΔY unknowns (6 + 5n).
    pub(super) n_unknowns: usize,
    pub(super) loss: Loss,
    pub(super) loss_scale: f64,
}

impl Problem {
    /// Number of solver unknowns (estimated parameters and centres).
    pub(super) fn dim(&self) -> usize {
        self.estimated.len() + 3 * self.stations.len()
    }

    /// Whitened residual of observation `o` at `state`.
    pub(super) fn residual(&self, o: &Obs, state: &State) -> Vector3<f64> {
        o.whiten * (state.est.centre_in_base(&o.sighting) - state.centres[o.station])
    }

    /// Prior residuals `L⁻¹ · (p − p_nominal)` at `state` (empty without a prior).
    pub(super) fn prior_residual(&self, state: &State) -> DVector<f64> {
        let Some(prior) = &self.prior else {
            return DVector::zeros(0);
        };
        let params = state.est.robot.params();
        let dev = DVector::from_iterator(
            prior.slots.len(),
            prior
                .slots
                .iter()
                .zip(&prior.nominal)
                .map(|(&slot, p0)| params[self.estimated[slot] - 6] - p0),
        );
        &prior.whiten * dev
    }

    /// Robust cost at `state`.
    pub(super) fn cost(&self, state: &State) -> f64 {
        let data: f64 = self
            .obs
            .iter()
            .map(|o| {
                self.loss
                    .rho(self.residual(o, state).norm(), self.loss_scale)
            })
            .sum();
        data + 0.5 * self.prior_residual(state).norm_squared()
    }

    /// Whitened, scaled Jacobian of observation `o` with respect to the
    /// estimated parameters (3 × k), and its residual.
    pub(super) fn obs_jacobian(&self, o: &Obs, state: &State) -> (Vector3<f64>, DMatrix<f64>) {
        let (x_b, a) = sensitivity(&state.est, &o.sighting);
        let k = self.estimated.len();
        let mut jp = DMatrix::zeros(3, k);
        for (slot, &u) in self.estimated.iter().enumerate() {
            let col: Vector3<f64> = o.whiten * a.fixed_view::<3, 1>(0, u) / self.scale[slot];
            jp.fixed_view_mut::<3, 1>(0, slot).copy_from(&col);
        }
        (o.whiten * (x_b - state.centres[o.station]), jp)
    }

    /// Gauss-Newton matrix, gradient and cost at `state` (IRLS weights from
    /// the current residuals), over the rows `rows` selects.
    pub(super) fn linearize(&self, state: &State, rows: Rows) -> Linear {
        let k = self.estimated.len();
        let n = self.dim();
        let mut h = DMatrix::zeros(n, n);
        let mut g = DVector::zeros(n);
        let mut cost = 0.0;
        for o in &self.obs {
            if !rows.includes(o.station) {
                continue;
            }
            let (r, jp) = self.obs_jacobian(o, state);
            let s = r.norm();
            cost += self.loss.rho(s, self.loss_scale);
            let w = self.loss.weight(s, self.loss_scale);
            let jc = -o.whiten;
            let c0 = k + 3 * o.station;
            let jpt = jp.transpose();
            {
                let mut hpp = h.view_mut((0, 0), (k, k));
                hpp += &jpt * &jp * w;
            }
            let hpc = &jpt * jc * w;
            h.view_mut((0, c0), (k, 3)).add_assign(&hpc);
            h.view_mut((c0, 0), (3, k)).add_assign(&hpc.transpose());
            let hcc = jc.transpose() * jc * w;
            h.view_mut((c0, c0), (3, 3))
                .add_assign(&DMatrix::from_iterator(3, 3, hcc.iter().copied()));
            let gp = &jpt * DVector::from_iterator(3, r.iter().copied()) * w;
            g.rows_mut(0, k).add_assign(&gp);
            let gc = jc.transpose() * r * w;
            g.fixed_rows_mut::<3>(c0).add_assign(&gc);
        }
        if let (Some(prior), false) = (&self.prior, matches!(rows, Rows::Only(_))) {
            let r = self.prior_residual(state);
            // Jacobian of the prior rows in the scaled slots.
            let mut jp = DMatrix::zeros(r.len(), k);
            for (col, &slot) in prior.slots.iter().enumerate() {
                jp.set_column(slot, &(prior.whiten.column(col) / self.scale[slot]));
            }
            let jpt = jp.transpose();
            let mut hpp = h.view_mut((0, 0), (k, k));
            hpp += &jpt * &jp;
            g.rows_mut(0, k).add_assign(&(&jpt * &r));
            cost += 0.5 * r.norm_squared();
        }
        Linear { h, g, cost }
    }

    /// The state moved by a scaled solver step.
    pub(super) fn apply(&self, state: &State, step: &DVector<f64>) -> State {
        let k = self.estimated.len();
        let mut delta = vec![0.0; self.n_unknowns];
        for (slot, &u) in self.estimated.iter().enumerate() {
            delta[u] = step[slot] / self.scale[slot];
        }
        State {
            est: state.est.updated(&delta),
            centres: state
                .centres
                .iter()
                .enumerate()
                .map(|(s, c)| c + step.fixed_rows::<3>(k + 3 * s))
                .collect(),
        }
    }

    /// One Levenberg-Marquardt step from `state`: retries with more
    /// damping until the cost falls. `None` when no damping lowers it
    /// (the state is at the optimum to numerical precision).
    pub(super) fn lm_step(&self, state: &State, lambda: &mut f64) -> Option<LmStep> {
        let lin = self.linearize(state, Rows::All);
        let n = self.dim();
        let dmax = (0..n).map(|i| lin.h[(i, i)]).fold(0.0_f64, f64::max);
        let floor = (dmax * DIAG_FLOOR_REL).max(f64::MIN_POSITIVE);
        while *lambda <= LAMBDA_MAX {
            let mut a = lin.h.clone();
            for i in 0..n {
                a[(i, i)] += *lambda * lin.h[(i, i)].max(floor);
            }
            if let Some(chol) = a.cholesky() {
                let step = -chol.solve(&lin.g);
                if step.iter().all(|v| v.is_finite()) {
                    let trial = self.apply(state, &step);
                    let cost = self.cost(&trial);
                    if cost.is_finite() && cost < lin.cost {
                        let used = *lambda;
                        *lambda = (*lambda * LAMBDA_DOWN).max(LAMBDA_MIN);
                        return Some(LmStep {
                            state: trial,
                            cost_before: lin.cost,
                            cost_after: cost,
                            step_max: step.amax(),
                            lambda: used,
                        });
                    }
                }
            }
            *lambda *= LAMBDA_UP;
        }
        None
    }

    /// Leave-one-station-out cross-validation at the solution `state`.
    /// Each refit without station `s` is one Gauss-Newton step from the
    /// full solution with the station's rows removed,
    /// `δ = −(H − H_s)⁻¹ · (g − g_s)`: dropping one station of many moves
    /// the parameters by a fraction of their σ, well inside the linear
    /// regime, so one step is the refit to second order (and costs one
    /// factorisation instead of a whole LM run per station). The model
    /// refitted without `s` then predicts the within-station distances
    /// of `s`, whose true value is zero.
    pub(super) fn cross_validate(&self, state: &State) -> CrossValidation {
        let k = self.estimated.len();
        let full = self.linearize(state, Rows::All);
        let mut rows = Vec::new();
        let (mut sum, mut count) = (0.0, 0_usize);
        for (s, id) in self.stations.iter().enumerate() {
            let own = self.linearize(state, Rows::Only(s));
            let mut h = &full.h - &own.h;
            let mut g = &full.g - &own.g;
            // The left-out station has no rows: pin its centre.
            let c0 = k + 3 * s;
            for d in 0..3 {
                h[(c0 + d, c0 + d)] = 1.0;
                g[c0 + d] = 0.0;
            }
            let refit = match h.cholesky() {
                Some(chol) => self.apply(state, &(-chol.solve(&g))),
                None => state.clone(),
            };
            let centres: Vec<Vector3<f64>> = self
                .obs
                .iter()
                .filter(|o| o.station == s)
                .map(|o| refit.est.centre_in_base(&o.sighting))
                .collect();
            let (mut ss, mut n) = (0.0, 0_usize);
            for i in 0..centres.len() {
                for j in i + 1..centres.len() {
                    ss += (centres[i] - centres[j]).norm_squared();
                    n += 1;
                }
            }
            sum += ss;
            count += n;
            rows.push(CrossStation {
                station: id.clone(),
                pairs: n,
                rms: if n > 0 { (ss / n as f64).sqrt() } else { 0.0 },
            });
        }
        CrossValidation {
            stations: rows,
            rms: if count > 0 {
                (sum / count as f64).sqrt()
            } else {
                0.0
            },
        }
    }
}

/// An accepted LM step.
pub(super) struct LmStep {
    pub(super) state: State,
    pub(super) cost_before: f64,
    pub(super) cost_after: f64,
    /// Largest scaled component, mm.
    pub(super) step_max: f64,
    /// Damping that produced it.
    pub(super) lambda: f64,
}

impl LmStep {
    pub(super) fn relative_decrease(&self) -> f64 {
        (self.cost_before - self.cost_after) / self.cost_before.max(f64::MIN_POSITIVE)
    }

    pub(super) fn converged(&self) -> bool {
        self.relative_decrease() < COST_TOL || self.step_max < STEP_TOL_MM
    }
}
