//! `ml`'s least-squares problem: whitened residuals `X_i − c_s` of every
//! identify measurement against its station's unknown centre, the prior
//! rows, and Levenberg-Marquardt over the estimated parameters and all
//! station centres; leave-one-station-out and leave-one-pose-out refits by
//! one Gauss-Newton step, and exact leave-one-pose-out refits to test them.

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

use super::noise::Loss;
use crate::engine::base::records::ml::{CrossStation, CrossValidation};
use crate::engine::calibrate::handeye::Sighting;
use crate::engine::calibrate::solve::estimate::{Estimate, sensitivity};
use crate::engine::calibrate::solve::{Control, HeldOutScheme, Phase};

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

/// A cost decrease smaller than this fraction is not progress: the cost
/// is a sum of hundreds to thousands of terms whose rounding reaches
/// 1e-13 of it, and such a step moves no centre by a nanometre. It is not
/// taken.
pub(super) const COST_NOISE_REL: f64 = 1e-12;

/// Converged when the largest scaled step is below this, mm: a picometre.
pub(super) const STEP_TOL_MM: f64 = 1e-9;

/// A measurement whose weighted hat block `w·M_i` has an eigenvalue this
/// close to 1 determines a direction alone (its leverage is 1): the
/// refit without it leaves that direction free and predicts nothing.
/// 1e-9 is far above the rounding of `H⁻¹` and far below any leverage a
/// measurement shares with others (at least 1/m of a station of m).
const UNDETERMINED_LEVERAGE: f64 = 1.0 - 1e-9;

/// The held-out phase reports its progress about this many times (each
/// report may cancel): often enough for Cancel, rarely enough that 10,000
/// measurements do not send 10,000 messages.
const HELD_OUT_REPORTS: usize = 100;

/// One measurement's leave-one-pose-out prediction: the held-out error
/// (`None` when the measurement alone determined a direction) and the
/// fit's own residual, both `|X − c_s|` in mm.
pub(super) type HeldOutPrediction = (Option<f64>, f64);

/// One identify measurement as the solver sees it.
#[derive(Debug, Clone)]
pub(super) struct Obs {
    /// Index into the problem's stations.
    pub(super) station: usize,
    /// Joints and sensor-frame centre.
    pub(super) sighting: Sighting,
    /// `C⁻¹` with `Σ = C·Cᵀ` (base frame): whitens a residual.
    pub(super) whiten: Matrix3<f64>,
    /// The stated covariance of the sensor-frame centre (mm²), kept to
    /// whiten again where the noise is estimated at the solution.
    pub(super) sensor_cov: Matrix3<f64>,
}

/// The current point of the solve: model, hand-eye and station centres.
#[derive(Debug, Clone)]
pub(super) struct State {
    pub(super) est: Estimate,
    /// Station centres, base frame, mm.
    pub(super) centres: Vec<Vector3<f64>>,
}

/// One station's part of the normal equations: the rows of its
/// measurements touch the parameters and its own centre only.
#[derive(Debug, Clone)]
pub(super) struct StationBlock {
    /// Its contribution to the parameter block, `Σ JpᵀwJp` (k × k).
    pub(super) a: DMatrix<f64>,
    /// Its contribution to the parameter gradient (k).
    pub(super) gp: DVector<f64>,
    /// Cross block parameters × centre, `Σ JpᵀwJc` (k × 3).
    pub(super) b: DMatrix<f64>,
    /// Centre block `Σ JcᵀwJc` (3 × 3).
    pub(super) c: Matrix3<f64>,
    /// Centre gradient (3).
    pub(super) gc: Vector3<f64>,
}

/// The linearised problem at a state, arranged for eliminating the
/// station centres (the Schur complement, as bundle adjusters do): a
/// `k × k` parameter block and one small block per station, so that a
/// step, the covariance and the diagnostics cost `O(measurements)` in
/// time and memory instead of the cube of the number of stations.
pub(super) struct Linear {
    /// Parameter block of `JᵀWJ` over all rows (and the prior).
    pub(super) a: DMatrix<f64>,
    /// Parameter gradient `JᵀW·r`.
    pub(super) gp: DVector<f64>,
    /// One per station, in station order.
    pub(super) stations: Vec<StationBlock>,
    /// Robust cost.
    pub(super) cost: f64,
}

impl Linear {
    /// The largest diagonal entry of the whole `JᵀWJ`.
    fn diag_max(&self) -> f64 {
        let params = (0..self.a.nrows())
            .map(|i| self.a[(i, i)])
            .fold(0.0_f64, f64::max);
        self.stations
            .iter()
            .flat_map(|st| (0..3).map(move |i| st.c[(i, i)]))
            .fold(params, f64::max)
    }

    /// The reduced system `S = A − Σ B·C⁻¹·Bᵀ`, `r = gp − Σ B·C⁻¹·gc`
    /// with Marquardt damping `λ·max(diag, floor)` on both blocks, and
    /// each station's damped `C⁻¹`. `None` when a centre block is singular.
    fn reduced(&self, lambda: f64, floor: f64) -> Option<Reduced> {
        let k = self.a.nrows();
        let mut s = self.a.clone();
        for i in 0..k {
            s[(i, i)] += lambda * self.a[(i, i)].max(floor);
        }
        let mut r = self.gp.clone();
        let mut inverses = Vec::with_capacity(self.stations.len());
        for st in &self.stations {
            let mut c = st.c;
            for i in 0..3 {
                c[(i, i)] += lambda * st.c[(i, i)].max(floor);
            }
            let cinv = c.try_inverse()?;
            let e = &st.b * cinv;
            s -= &e * st.b.transpose();
            r -= &e * st.gc;
            inverses.push(cinv);
        }
        Some((s, r, inverses))
    }

    /// The damped Gauss-Newton step (scaled parameters, then the centres),
    /// or `None` when the damped system is not positive definite.
    pub(super) fn step(&self, lambda: f64, floor: f64) -> Option<DVector<f64>> {
        let k = self.a.nrows();
        let (s, r, inverses) = self.reduced(lambda, floor)?;
        let dp = -s.cholesky()?.solve(&r);
        let mut step = DVector::zeros(k + 3 * self.stations.len());
        step.rows_mut(0, k).copy_from(&dp);
        for (i, (st, cinv)) in self.stations.iter().zip(&inverses).enumerate() {
            let dc = -cinv * (st.gc + st.b.transpose() * &dp);
            step.fixed_rows_mut::<3>(k + 3 * i).copy_from(&dc);
        }
        Some(step)
    }

    /// The blocks of the inverse of the (undamped) `JᵀWJ` that the
    /// diagnostics need: the parameter block `P = S⁻¹` and, per station,
    /// `E = B·C⁻¹` and `C⁻¹`, from which the cross block `−P·E` and the
    /// centre block `C⁻¹ + Eᵀ·P·E` follow. A singular `S` gets its
    /// pseudo-inverse.
    pub(super) fn inverse_blocks(&self) -> InverseBlocks {
        let k = self.a.nrows();
        let Some((s, _, inverses)) = self.reduced(0.0, 0.0) else {
            return InverseBlocks {
                p: DMatrix::zeros(k, k),
                e: vec![DMatrix::zeros(k, 3); self.stations.len()],
                cinv: vec![Matrix3::zeros(); self.stations.len()],
            };
        };
        let p = s
            .clone()
            .cholesky()
            .map(|c| c.inverse())
            .or_else(|| {
                nalgebra::SVD::try_new(
                    s,
                    true,
                    true,
                    f64::EPSILON,
                    crate::engine::base::numeric::MAX_DECOMPOSITION_SWEEPS,
                )?
                .pseudo_inverse(1e-14)
                .ok()
            })
            .unwrap_or_else(|| DMatrix::zeros(k, k));
        let e = self
            .stations
            .iter()
            .zip(&inverses)
            .map(|(st, cinv)| {
                let e = &st.b * cinv;
                DMatrix::from_iterator(k, 3, e.iter().copied())
            })
            .collect();
        InverseBlocks {
            p,
            e,
            cinv: inverses,
        }
    }
}

/// The reduced system: `S`, `r` and each station's (damped) `C⁻¹`.
type Reduced = (DMatrix<f64>, DVector<f64>, Vec<Matrix3<f64>>);

/// Blocks of the inverse of `JᵀWJ` (see [`Linear::inverse_blocks`]).
pub(super) struct InverseBlocks {
    /// Parameter block, `S⁻¹` (scaled units): the parameter covariance.
    pub(super) p: DMatrix<f64>,
    /// Per station `B·C⁻¹` (k × 3).
    pub(super) e: Vec<DMatrix<f64>>,
    /// Per station `C⁻¹`.
    pub(super) cinv: Vec<Matrix3<f64>>,
}

impl InverseBlocks {
    /// `J·H⁻¹·Jᵀ` for one measurement's rows `J = [jp | jc]` (3 × k
    /// parameters, 3 × 3 on its station's centre): its hat matrix.
    pub(super) fn hat(&self, jp: &DMatrix<f64>, jc: &Matrix3<f64>, station: usize) -> Matrix3<f64> {
        let e = &self.e[station];
        let p_e = &self.p * e;
        // Parameter block, cross terms through −P·E, centre block.
        let pp = jp * &self.p * jp.transpose();
        let cross = jp * &p_e * jc.transpose();
        let centre = self.cinv[station] + e.transpose() * &p_e;
        let cc = jc * centre * jc.transpose();
        let pp = Matrix3::from_iterator(pp.iter().copied());
        let cross = Matrix3::from_iterator(cross.iter().copied());
        pp - cross - cross.transpose() + cc
    }
}

/// The prior on the kinematic deviations, in the estimated chart.
#[derive(Clone)]
pub(super) struct Prior {
    /// Estimated slots that are kinematic parameters.
    pub(super) slots: Vec<usize>,
    /// Their nominal values (rad, mm).
    pub(super) nominal: Vec<f64>,
    /// Whitening of the prior (raw units): `diag(1/σ)`.
    pub(super) whiten: DMatrix<f64>,
}

/// The problem: observations, which unknowns are estimated, weights.
#[derive(Clone)]
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
    #[allow(
        clippy::unused_self,
        reason = "a residual of this problem, beside its Jacobian, which needs the problem"
    )]
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

    /// Gauss-Newton blocks, gradient and cost at `state` (IRLS weights
    /// from the current residuals).
    pub(super) fn linearize(&self, state: &State) -> Linear {
        let k = self.estimated.len();
        let mut stations: Vec<StationBlock> = (0..self.stations.len())
            .map(|_| StationBlock {
                a: DMatrix::zeros(k, k),
                gp: DVector::zeros(k),
                b: DMatrix::zeros(k, 3),
                c: Matrix3::zeros(),
                gc: Vector3::zeros(),
            })
            .collect();
        let mut cost = 0.0;
        for o in &self.obs {
            let (r, jp) = self.obs_jacobian(o, state);
            let s = r.norm();
            cost += self.loss.rho(s, self.loss_scale);
            let w = self.loss.weight(s, self.loss_scale);
            let jc = -o.whiten;
            let st = &mut stations[o.station];
            let jpt = jp.transpose();
            st.a += &jpt * &jp * w;
            let jc_dyn = DMatrix::from_iterator(3, 3, jc.iter().copied());
            st.b += &jpt * jc_dyn * w;
            st.c += jc.transpose() * jc * w;
            st.gp += &jpt * DVector::from_iterator(3, r.iter().copied()) * w;
            st.gc += jc.transpose() * r * w;
        }
        let mut a = DMatrix::zeros(k, k);
        let mut gp = DVector::zeros(k);
        for st in &stations {
            a += &st.a;
            gp += &st.gp;
        }
        if let Some(prior) = &self.prior {
            let r = self.prior_residual(state);
            // Jacobian of the prior rows in the scaled slots.
            let mut jp = DMatrix::zeros(r.len(), k);
            for (col, &slot) in prior.slots.iter().enumerate() {
                jp.set_column(slot, &(prior.whiten.column(col) / self.scale[slot]));
            }
            let jpt = jp.transpose();
            a += &jpt * &jp;
            gp += &jpt * &r;
            cost += 0.5 * r.norm_squared();
        }
        Linear {
            a,
            gp,
            stations,
            cost,
        }
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
        let lin = self.linearize(state);
        let floor = (lin.diag_max() * DIAG_FLOOR_REL).max(f64::MIN_POSITIVE);
        while *lambda <= LAMBDA_MAX {
            if let Some(step) = lin.step(*lambda, floor)
                && step.iter().all(|v| v.is_finite())
            {
                let trial = self.apply(state, &step);
                let cost = self.cost(&trial);
                if cost.is_finite() && cost < lin.cost * (1.0 - COST_NOISE_REL) {
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
            *lambda *= LAMBDA_UP;
        }
        None
    }

    /// Leave-one-pose-out at the solution `state`, each refit one
    /// Gauss-Newton step with the measurement's rows removed (see
    /// [`held_out`](crate::engine::calibrate::solve::held_out)): by the
    /// Sherman-Morrison-Woodbury identity the refit's whitened residual of
    /// measurement `i` is `(I − w·M_i)⁻¹·(r_i + J_i·δ)`, `M_i` its hat
    /// block from the blocks of `H⁻¹`, `w` its robust weight, `δ` the full
    /// Newton step (zero at convergence). The residual is `X_i − c_s`, so
    /// its norm unwhitened is the distance from the left-out centre to the
    /// refit's station centre. The robust weights stay those of the
    /// solution, as in LM's steps and the covariance; an exact refit
    /// weighs again (on the real RobCalibrator set, with one outlier beyond
    /// the Huber corner, that moved one pose's figure by 0.01 mm and the
    /// rms by 0.4 %). One entry per observation; `None` when `phase`
    /// cancelled.
    pub(super) fn held_out(
        &self,
        state: &State,
        phase: &mut dyn FnMut(Phase) -> Control,
    ) -> Option<Vec<HeldOutPrediction>> {
        let k = self.estimated.len();
        let lin = self.linearize(state);
        let inverse = lin.inverse_blocks();
        let step = lin
            .step(0.0, 0.0)
            .filter(|s| s.iter().all(|v| v.is_finite()))
            .unwrap_or_else(|| DVector::zeros(self.dim()));
        let dp = step.rows(0, k);
        let of = self.obs.len();
        let stride = (of / HELD_OUT_REPORTS).max(1);
        let mut out = Vec::with_capacity(of);
        for (i, o) in self.obs.iter().enumerate() {
            if i % stride == 0
                && phase(Phase::HeldOut {
                    scheme: HeldOutScheme::LeaveOnePoseOut,
                    done: i,
                    of,
                }) == Control::Cancel
            {
                return None;
            }
            let (r, jp) = self.obs_jacobian(o, state);
            let unwhiten = o.whiten.try_inverse().unwrap_or_else(Matrix3::zeros);
            let fit = (state.est.centre_in_base(&o.sighting) - state.centres[o.station]).norm();
            let w = self.loss.weight(r.norm(), self.loss_scale);
            let jc = -o.whiten;
            let wm = inverse.hat(&jp, &jc, o.station) * w;
            let moved = r
                + Vector3::from_iterator((&jp * dp).iter().copied())
                + jc * step.fixed_rows::<3>(k + 3 * o.station);
            let leverage = wm.symmetric_eigenvalues().max();
            let held = if leverage < UNDETERMINED_LEVERAGE {
                (Matrix3::identity() - wm)
                    .try_inverse()
                    .map(|a| (unwhiten * a * moved).norm())
                    .filter(|h| h.is_finite())
            } else {
                None
            };
            out.push((held, fit));
        }
        Some(out)
    }

    /// The problem without observation `i` (its station keeps its index,
    /// with one measurement fewer).
    pub(super) fn without(&self, i: usize) -> Self {
        let mut p = self.clone();
        p.obs.remove(i);
        p
    }

    /// Levenberg-Marquardt from `state` until it converges or no step
    /// lowers the cost (at most `max_steps` steps).
    pub(super) fn solve_from(&self, state: &State, max_steps: usize) -> State {
        let mut state = state.clone();
        let mut lambda = LAMBDA_START;
        for _ in 0..max_steps {
            let Some(step) = self.lm_step(&state, &mut lambda) else {
                break;
            };
            let done = step.converged();
            state = step.state;
            if done {
                break;
            }
        }
        state
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
    pub(super) fn cross_validate(
        &self,
        state: &State,
        phase: &mut dyn FnMut(Phase) -> Control,
    ) -> Option<CrossValidation> {
        let k = self.estimated.len();
        let full = self.linearize(state);
        // The reduced system of all stations; leaving station `s` out
        // removes its rows from the parameter block and its centre term
        // from the complement (its centre is then free and irrelevant).
        let reduced = full.reduced(0.0, 0.0);
        let mut rows = Vec::new();
        let (mut sum, mut count) = (0.0, 0_usize);
        let of = self.stations.len();
        // Each station's measurements, grouped once.
        let mut members: Vec<Vec<&Obs>> = vec![Vec::new(); of];
        for o in &self.obs {
            members[o.station].push(o);
        }
        for (s, id) in self.stations.iter().enumerate() {
            if phase(Phase::CrossValidation { done: s, of }) == Control::Cancel {
                return None;
            }
            let refit = reduced.as_ref().and_then(|(sfull, rfull, inverses)| {
                let st = &full.stations[s];
                let e = &st.b * inverses[s];
                let h = sfull - &st.a + &e * st.b.transpose();
                let g = rfull - &st.gp + &e * st.gc;
                let dp = -h.cholesky()?.solve(&g);
                let mut step = DVector::zeros(k + 3 * self.stations.len());
                step.rows_mut(0, k).copy_from(&dp);
                Some(self.apply(state, &step))
            });
            let refit = refit.as_ref().unwrap_or(state);
            let centres: Vec<Vector3<f64>> = members[s]
                .iter()
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
        Some(CrossValidation {
            stations: rows,
            rms: if count > 0 {
                (sum / count as f64).sqrt()
            } else {
                0.0
            },
        })
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
