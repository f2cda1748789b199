//! Choosing the poses: the D-optimal criterion of the identify poses
//! (information of the `ml` model with the station centres eliminated,
//! plus `ml`'s prior), its greedy maximisation with exchange passes, the
//! random baseline, the spread of the validate poses and the rotation
//! group's criterion (see the parent module's docs).

use nalgebra::{Cholesky, DMatrix, Dyn, Matrix3};
use rand_chacha::ChaCha8Rng;

use super::{Candidate, Planner, Site, joint_gap, side_quota};
use crate::engine::base::robot::Robot;
use crate::engine::calibrate::solve::estimate::unknown_is_angle;
use crate::engine::calibrate::solve::estimate::unknown_scale;
use crate::engine::calibrate::solve::ml::MlOptions;

/// Weak prior σ of the hand-eye translation in the criterion, mm: only
/// ranks the first, still singular selection steps (`ml` has no hand-eye
/// prior; 10 mm is far wider than any hand-eye guess error).
const HAND_EYE_PRIOR_MM: f64 = 10.0;

/// Weak prior σ of the hand-eye rotation in the criterion, deg.
const HAND_EYE_PRIOR_DEG: f64 = 10.0;

/// Exchange passes after the greedy selection; each pass tries every
/// chosen identify pose against every candidate of its station and side.
/// Two passes catch nearly all of the gain in trials (a third swaps
/// nothing on the presets).
pub(super) const EXCHANGE_PASSES: usize = 3;

/// A swap must raise `ln det` by at least this to count (numerical noise
/// of a ~30 × 30 Cholesky is ~1e-12).
const EXCHANGE_MIN_GAIN: f64 = 1e-9;

/// Ridge added to eq. 8's normal matrix when ranking rotation poses.
const ROTATION_RIDGE: f64 = 1e-6;

/// The prior information (scaled units) of the estimated parameters:
/// `ml`'s prior on the kinematic deviations, a weak one on the hand-eye.
pub(super) fn prior_information(estimated: &[usize]) -> DMatrix<f64> {
    let ml = MlOptions::default();
    let diagonal: Vec<f64> = estimated
        .iter()
        .map(|&k| {
            let sigma = match (k < 6, unknown_is_angle(k)) {
                (true, false) => HAND_EYE_PRIOR_MM,
                (true, true) => HAND_EYE_PRIOR_DEG.to_radians(),
                (false, false) => ml.prior_length,
                (false, true) => ml.prior_angle_deg.to_radians(),
            } * unknown_scale(k);
            1.0 / (sigma * sigma)
        })
        .collect();
    DMatrix::from_diagonal(&nalgebra::DVector::from_vec(diagonal))
}

/// The information one identify candidate carries: its scaled sensitivity
/// to the estimated parameters and the inverse covariance of its
/// base-frame centre.
#[derive(Debug, Clone)]
pub(super) struct Info {
    /// 3 × K.
    pub(super) a: DMatrix<f64>,
    /// Inverse covariance, mm⁻².
    pub(super) w: Matrix3<f64>,
}

/// Accumulated information of one station: `H = Σ AᵀWA`, `B = Σ AᵀW`,
/// `C = Σ W`; the station centre eliminated, `M_s = H − B·C⁻¹·Bᵀ`.
#[derive(Debug, Clone)]
pub(super) struct StationInfo {
    h: DMatrix<f64>,
    b: DMatrix<f64>,
    c: Matrix3<f64>,
    n: usize,
}

impl StationInfo {
    fn new(k: usize) -> Self {
        Self {
            h: DMatrix::zeros(k, k),
            b: DMatrix::zeros(k, 3),
            c: Matrix3::zeros(),
            n: 0,
        }
    }

    pub(super) fn of(infos: &[Info], chosen: &[usize], k: usize) -> Self {
        let mut s = Self::new(k);
        for &i in chosen {
            s.add(&infos[i]);
        }
        s
    }

    fn add(&mut self, info: &Info) {
        let w = dm3(&info.w);
        let atw = info.a.transpose() * &w;
        self.h += &atw * &info.a;
        self.b += atw;
        self.c += info.w;
        self.n += 1;
    }

    /// `M_s`, K × K.
    pub(super) fn schur(&self) -> DMatrix<f64> {
        match self.c.try_inverse() {
            Some(ci) if self.n >= 2 => &self.h - &self.b * dm3(&ci) * self.b.transpose(),
            _ => DMatrix::zeros(self.h.nrows(), self.h.ncols()),
        }
    }

    /// The objective's gain for adding `info`, with `chol` the Cholesky
    /// factor of `M` and `qt` the objective's prepared matrix
    /// ([`Objective::prepare`]). `ΔM = Eᵀ·V·E` with `E = A − C⁻¹Bᵀ` and
    /// `V = (W⁻¹ + C⁻¹)⁻¹` (the new sighting against the station's centre
    /// as the others fix it). `ln det` gains `ln det(V⁻¹ + G) − ln det V⁻¹`
    /// with `G = E·M⁻¹·Eᵀ` (matrix determinant lemma); `tr(Q·M⁻¹)` falls
    /// by `tr((V⁻¹ + G)⁻¹·E·M⁻¹·Q·M⁻¹·Eᵀ)` (Woodbury), with
    /// `E·M⁻¹·Q·M⁻¹·Eᵀ = Fᵀ·Q̃·F`, `F = L⁻¹Eᵀ`, `Q̃ = L⁻¹·Q·L⁻ᵀ`. Zero for a
    /// station with no sighting yet (one sighting only fixes its centre).
    fn gain(&self, info: &Info, chol: &Cholesky<f64, Dyn>, qt: Option<&DMatrix<f64>>) -> f64 {
        let Some(ci) = self.c.try_inverse() else {
            return 0.0;
        };
        let Some(wi) = info.w.try_inverse() else {
            return 0.0;
        };
        let e = &info.a - dm3(&ci) * self.b.transpose();
        // F = L⁻¹·Eᵀ, G = FᵀF = E·M⁻¹·Eᵀ.
        let mut f = e.transpose();
        chol.l_dirty().solve_lower_triangular_mut(&mut f);
        let g = f.transpose() * &f;
        let v_inv = wi + ci;
        let total = v_inv + Matrix3::from_fn(|i, j| g[(i, j)]);
        match qt {
            None => match (total.cholesky(), v_inv.cholesky()) {
                (Some(t), Some(v)) => log_det3(&t) - log_det3(&v),
                _ => 0.0,
            },
            Some(qt) => {
                let fqf = f.transpose() * qt * &f;
                let fqf = Matrix3::from_fn(|i, j| fqf[(i, j)]);
                total.cholesky().map_or(0.0, |t| t.solve(&fqf).trace())
            }
        }
    }
}

/// What the identify selection maximises.
#[derive(Debug, Clone)]
pub(super) enum Objective {
    /// `ln det M`: D-optimal, the parameters as a whole.
    LogDet,
    /// `−tr(Q·M⁻¹)`: minus the mean square predicted point error over the
    /// sensor's range (`Q` from [`AlignedGrid::weight`](crate::engine::calibrate::solve::ml::range)
    /// at the plan's working poses), I-optimal for the range.
    Range(DMatrix<f64>),
}

impl Objective {
    /// The objective at `M = LLᵀ` and its prepared matrix for
    /// [`StationInfo::gain`] (computed once for both).
    fn at(&self, chol: &Cholesky<f64, Dyn>) -> (f64, Option<DMatrix<f64>>) {
        match self.prepare(chol) {
            None => (log_det(chol), None),
            Some(qt) => (-qt.trace(), Some(qt)),
        }
    }

    /// `Q̃ = L⁻¹·Q·L⁻ᵀ` for [`StationInfo::gain`] (`tr Q̃ = tr(Q·M⁻¹)`);
    /// `None` for `ln det`.
    fn prepare(&self, chol: &Cholesky<f64, Dyn>) -> Option<DMatrix<f64>> {
        let Self::Range(q) = self else {
            return None;
        };
        let l = chol.l_dirty();
        let mut x = q.clone();
        l.solve_lower_triangular_mut(&mut x);
        let mut qt = x.transpose();
        l.solve_lower_triangular_mut(&mut qt);
        Some(qt)
    }
}

fn dm3(m: &Matrix3<f64>) -> DMatrix<f64> {
    DMatrix::from_fn(3, 3, |i, j| m[(i, j)])
}

fn log_det3(c: &nalgebra::Cholesky<f64, nalgebra::U3>) -> f64 {
    2.0 * (0..3).map(|i| c.l_dirty()[(i, i)].ln()).sum::<f64>()
}

fn log_det(chol: &Cholesky<f64, Dyn>) -> f64 {
    let l = chol.l_dirty();
    2.0 * (0..l.nrows()).map(|i| l[(i, i)].ln()).sum::<f64>()
}

/// `ln det(prior + Σ_s M_s)` of a selection `(site, chosen)`.
pub(super) fn criterion(
    prior: &DMatrix<f64>,
    infos: &[Vec<Info>],
    selection: &[(usize, Vec<usize>)],
) -> Option<f64> {
    let k = prior.nrows();
    let mut m = prior.clone();
    for (site, chosen) in selection {
        m += StationInfo::of(&infos[*site], chosen, k).schur();
    }
    m.cholesky().map(|c| log_det(&c))
}

/// The covariance `(prior + Σ_s M_s)⁻¹` (scaled units) of a selection
/// `(site, chosen)`; `None` when singular.
pub(super) fn selection_covariance(
    prior: &DMatrix<f64>,
    infos: &[Vec<Info>],
    selection: &[(usize, Vec<usize>)],
) -> Option<DMatrix<f64>> {
    let k = prior.nrows();
    let mut m = prior.clone();
    for (site, chosen) in selection {
        m += StationInfo::of(&infos[*site], chosen, k).schur();
    }
    m.cholesky().map(|c| c.inverse())
}

/// The predicted measuring error over the working volume: the per-point
/// 1σ (3-D, after the best rigid alignment of the whole volume, as
/// `measure` reports it) of the sphere centre at each sampled pose of the
/// volume, from the planner's covariance of the identify poses (the `ml`
/// model and prior, see the module docs), mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VolumeError {
    /// RMS over the sampled poses.
    pub rms_mm: f64,
    /// Mean.
    pub mean_mm: f64,
    /// Largest.
    pub max_mm: f64,
    /// Sampled poses (reachable places of the volume).
    pub samples: usize,
}

impl VolumeError {
    /// The figures of per-point σ (mm); `None` without any.
    pub(super) fn of(sigmas: &[f64]) -> Option<Self> {
        if sigmas.is_empty() {
            return None;
        }
        let n = sigmas.len() as f64;
        Some(Self {
            rms_mm: (sigmas.iter().map(|s| s * s).sum::<f64>() / n).sqrt(),
            mean_mm: sigmas.iter().sum::<f64>() / n,
            max_mm: sigmas.iter().copied().fold(0.0, f64::max),
            samples: sigmas.len(),
        })
    }
}

/// A seeded random selection of `n` poses per identify station, sides
/// balanced as in the greedy selection.
pub(super) fn random_selection(
    sites: &[Site],
    identify: &[usize],
    n: usize,
    rng: &mut ChaCha8Rng,
) -> Vec<(usize, Vec<usize>)> {
    identify
        .iter()
        .map(|&k| {
            let mut chosen = Vec::with_capacity(n);
            for side in [1_i8, -1] {
                let of_side: Vec<usize> = (0..sites[k].candidates.len())
                    .filter(|&i| sites[k].candidates[i].side == side)
                    .collect();
                let quota = side_quota(n, side).min(of_side.len());
                for j in rand::seq::index::sample(rng, of_side.len(), quota).into_vec() {
                    chosen.push(of_side[j]);
                }
            }
            (k, chosen)
        })
        .collect()
}

/// Greedy D-optimal selection with exchange passes (module docs).
pub(super) fn greedy_selection(
    planner: &Planner<'_>,
    sites: &[Site],
    identify: &[usize],
    infos: &[Vec<Info>],
    prior: &DMatrix<f64>,
    objective: &Objective,
    stop: &mut dyn FnMut() -> bool,
) -> Option<Vec<(usize, Vec<usize>)>> {
    let n = planner.config.design.identify_poses;
    let k = prior.nrows();
    let mut chosen: Vec<Vec<usize>> = identify
        .iter()
        .map(|&s| planner.first_pose(&sites[s]).into_iter().collect())
        .collect();
    let mut stations: Vec<StationInfo> = identify
        .iter()
        .zip(&chosen)
        .map(|(&s, c)| StationInfo::of(&infos[s], c, k))
        .collect();
    let mut m = prior.clone();
    for st in &stations {
        m += st.schur();
    }
    // Greedy additions.
    let mut greedy = Greedy {
        sites,
        identify,
        infos,
        n,
    };
    let went_on = match objective {
        Objective::LogDet => greedy.lazy(&mut chosen, &mut stations, &mut m, stop),
        Objective::Range(_) => greedy.full(&mut chosen, &mut stations, &mut m, objective, stop),
    };
    if !went_on {
        return None;
    }
    // Exchange passes: swap a chosen pose for a better one of its side.
    for _ in 0..EXCHANGE_PASSES {
        let mut swapped = false;
        for (slot, &s) in identify.iter().enumerate() {
            if stop() {
                return None;
            }
            for pos in 0..chosen[slot].len() {
                let Some((current, _)) = m.clone().cholesky().map(|c| objective.at(&c)) else {
                    continue;
                };
                let removed = chosen[slot][pos];
                let mut rest = chosen[slot].clone();
                rest.remove(pos);
                let without = StationInfo::of(&infos[s], &rest, k);
                let without_schur = without.schur();
                let m_without = &m - stations[slot].schur() + &without_schur;
                let Some(chol) = m_without.clone().cholesky() else {
                    continue;
                };
                let (base, qt) = objective.at(&chol);
                let side = sites[s].candidates[removed].side;
                let mut best: Option<(f64, usize)> = None;
                for (cand, info) in infos[s].iter().enumerate() {
                    if sites[s].candidates[cand].side != side || chosen[slot].contains(&cand) {
                        continue;
                    }
                    let value = base + without.gain(info, &chol, qt.as_ref());
                    if best.is_none_or(|(b, _)| value > b) {
                        best = Some((value, cand));
                    }
                }
                if let Some((value, cand)) = best
                    && value > current + EXCHANGE_MIN_GAIN
                {
                    let mut updated = without;
                    updated.add(&infos[s][cand]);
                    m = m_without - without_schur + updated.schur();
                    chosen[slot][pos] = cand;
                    stations[slot] = updated;
                    swapped = true;
                }
            }
        }
        if !swapped {
            break;
        }
    }
    Some(identify.iter().copied().zip(chosen).collect())
}

/// The greedy additions of [`greedy_selection`]: until every station is
/// full, the pose with the largest gain of the objective is added.
struct Greedy<'p> {
    sites: &'p [Site],
    identify: &'p [usize],
    infos: &'p [Vec<Info>],
    /// Poses per identify station.
    n: usize,
}

impl Greedy<'_> {
    /// Whether candidate `cand` may join the station in `slot`: not
    /// chosen yet, its side's quota not full, the station not full.
    fn eligible(&self, slot: usize, chosen: &[usize], cand: usize) -> bool {
        let site = &self.sites[self.identify[slot]];
        let side = site.candidates[cand].side;
        let used = chosen
            .iter()
            .filter(|&&i| site.candidates[i].side == side)
            .count();
        chosen.len() < self.n && !chosen.contains(&cand) && used < side_quota(self.n, side)
    }

    /// Adds candidate `cand` to the station in `slot`, updating `M`.
    fn add(
        &self,
        slot: usize,
        cand: usize,
        chosen: &mut [Vec<usize>],
        stations: &mut [StationInfo],
        m: &mut DMatrix<f64>,
    ) {
        let s = self.identify[slot];
        *m -= stations[slot].schur();
        stations[slot].add(&self.infos[s][cand]);
        *m += stations[slot].schur();
        chosen[slot].push(cand);
    }

    /// Every step evaluates every eligible candidate (any objective).
    fn full(
        &mut self,
        chosen: &mut [Vec<usize>],
        stations: &mut [StationInfo],
        m: &mut DMatrix<f64>,
        objective: &Objective,
        stop: &mut dyn FnMut() -> bool,
    ) -> bool {
        while let Some(chol) = m.clone().cholesky() {
            if stop() {
                return false;
            }
            let qt = objective.prepare(&chol);
            let mut best: Option<(f64, usize, usize)> = None;
            for (slot, &s) in self.identify.iter().enumerate() {
                for (cand, info) in self.infos[s].iter().enumerate() {
                    if !self.eligible(slot, &chosen[slot], cand) {
                        continue;
                    }
                    let g = stations[slot].gain(info, &chol, qt.as_ref());
                    if best.is_none_or(|(b, _, _)| g > b) {
                        best = Some((g, slot, cand));
                    }
                }
            }
            let Some((_, slot, cand)) = best else {
                break;
            };
            self.add(slot, cand, chosen, stations, m);
        }
        true
    }

    /// The same additions for `ln det`, lazily (Minoux's accelerated
    /// greedy): adding a pose to one station only adds information to
    /// `M`, so the gain of every other station's candidate can only fall
    /// (`E·M⁻¹·Eᵀ` shrinks as `M` grows); a gain computed at an earlier
    /// step is an upper bound. The candidate with the largest bound is
    /// re-evaluated; when its fresh gain is still the largest it is the
    /// step's best, as a full evaluation would find (up to rounding and
    /// exact ties). Only the changed station's candidates are evaluated
    /// afresh each step, so the work grows with the candidates, not with
    /// their square (200 stations: 20 s before, well under 1 s of
    /// selection now).
    fn lazy(
        &mut self,
        chosen: &mut [Vec<usize>],
        stations: &mut [StationInfo],
        m: &mut DMatrix<f64>,
        stop: &mut dyn FnMut() -> bool,
    ) -> bool {
        use std::collections::BinaryHeap;
        let Some(mut chol) = m.clone().cholesky() else {
            return true;
        };
        let mut step = 0_usize;
        // (bound, slot, cand, step of the bound), largest bound first,
        // ties to the lowest slot and candidate (as the full evaluation).
        let mut heap: BinaryHeap<Entry> = BinaryHeap::new();
        for (slot, &s) in self.identify.iter().enumerate() {
            for (cand, info) in self.infos[s].iter().enumerate() {
                if self.eligible(slot, &chosen[slot], cand) {
                    let gain = stations[slot].gain(info, &chol, None);
                    heap.push(Entry::new(gain, slot, cand, step));
                }
            }
        }
        // The step at which each station last changed: older entries of
        // it are dropped (its candidates are re-pushed fresh).
        let mut changed: Vec<usize> = vec![0; self.identify.len()];
        while let Some(top) = heap.pop() {
            let (slot, cand) = (top.slot, top.cand);
            if top.step < changed[slot] || !self.eligible(slot, &chosen[slot], cand) {
                continue;
            }
            if top.step != step {
                let info = &self.infos[self.identify[slot]][cand];
                let gain = stations[slot].gain(info, &chol, None);
                heap.push(Entry::new(gain, slot, cand, step));
                continue;
            }
            self.add(slot, cand, chosen, stations, m);
            step += 1;
            changed[slot] = step;
            if stop() {
                return false;
            }
            let Some(c) = m.clone().cholesky() else {
                return true;
            };
            chol = c;
            let s = self.identify[slot];
            for (k, info) in self.infos[s].iter().enumerate() {
                if self.eligible(slot, &chosen[slot], k) {
                    let gain = stations[slot].gain(info, &chol, None);
                    heap.push(Entry::new(gain, slot, k, step));
                }
            }
        }
        true
    }
}

/// A candidate in the lazy greedy's queue.
#[derive(Debug, Clone, Copy)]
struct Entry {
    /// Its gain at `step` (an upper bound later).
    gain: f64,
    slot: usize,
    cand: usize,
    step: usize,
}

impl Entry {
    fn new(gain: f64, slot: usize, cand: usize, step: usize) -> Self {
        Self {
            gain,
            slot,
            cand,
            step,
        }
    }
}

impl PartialEq for Entry {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == std::cmp::Ordering::Equal
    }
}

impl Eq for Entry {}

impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Entry {
    /// Larger gain first; on a tie the lower slot, then the lower
    /// candidate, then the fresher bound.
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.gain
            .total_cmp(&other.gain)
            .then(other.slot.cmp(&self.slot))
            .then(other.cand.cmp(&self.cand))
            .then(self.step.cmp(&other.step))
    }
}

/// Validate poses: farthest point in flange orientation, sides balanced,
/// from the candidate closest to the mean approach.
pub(super) fn spread_selection(planner: &Planner<'_>, site: &Site, n: usize) -> Vec<usize> {
    let mut chosen: Vec<usize> = planner.first_pose(site).into_iter().collect();
    while chosen.len() < n {
        let mut best: Option<(f64, usize)> = None;
        for (i, c) in site.candidates.iter().enumerate() {
            let used = chosen
                .iter()
                .filter(|&&j| site.candidates[j].side == c.side)
                .count();
            if chosen.contains(&i) || used >= side_quota(n, c.side) {
                continue;
            }
            let nearest = chosen
                .iter()
                .map(|&j| {
                    let other = &site.candidates[j];
                    // Same orientation on another branch still differs in joints.
                    other.rotation.angle_to(&c.rotation)
                        + joint_gap(&other.joints, &c.joints).to_radians() * 1e-3
                })
                .fold(f64::INFINITY, f64::min);
            if best.is_none_or(|(b, _)| nearest > b) {
                best = Some((nearest, i));
            }
        }
        match best {
            Some((_, i)) => chosen.push(i),
            None => break,
        }
    }
    chosen
}

/// `ln det(N + ε·I)` of eq. 8's normal matrix `N = Σ_{i<j} (R_i − R_j)ᵀ(R_i − R_j)`
/// over the flange rotations of `set` (nominal model).
pub(super) fn rotation_criterion(robot: &Robot, set: &[&Candidate]) -> f64 {
    let rotations: Vec<Matrix3<f64>> = set
        .iter()
        .map(|c| {
            robot
                .base_from_flange(&c.joints)
                .rotation
                .to_rotation_matrix()
                .into_inner()
        })
        .collect();
    let mut n = Matrix3::identity() * ROTATION_RIDGE;
    for i in 0..rotations.len() {
        for j in i + 1..rotations.len() {
            let d = rotations[i] - rotations[j];
            n += d.transpose() * d;
        }
    }
    n.determinant().max(f64::MIN_POSITIVE).ln()
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::engine::tools::plan::StationRole;
    use nalgebra::{UnitQuaternion, Vector3};
    use rand::{Rng as _, SeedableRng as _};

    /// The lazy greedy chooses what the full evaluation chooses (issue
    /// 23: the full one made 200 stations take 20 s), on a synthetic
    /// problem of random sensitivities.
    #[test]
    fn the_lazy_greedy_chooses_as_the_full_one() {
        let mut rng = ChaCha8Rng::seed_from_u64(23);
        let (k, n_stations, n_candidates, n) = (9, 14, 30, 6);
        let candidate = |side: i8| Candidate {
            joints: [0.0; 6],
            side,
            centre: Vector3::zeros(),
            rotation: UnitQuaternion::identity(),
        };
        let sites: Vec<Site> = (0..n_stations)
            .map(|_| Site {
                role: StationRole::Identify,
                position: Vector3::zeros(),
                candidates: (0..n_candidates)
                    .map(|c| candidate(if c % 2 == 0 { 1 } else { -1 }))
                    .collect(),
                chosen: Vec::new(),
            })
            .collect();
        let infos: Vec<Vec<Info>> = (0..n_stations)
            .map(|_| {
                (0..n_candidates)
                    .map(|_| Info {
                        a: DMatrix::from_fn(3, k, |_, _| rng.random_range(-1.0..1.0)),
                        w: Matrix3::from_diagonal(&Vector3::new(
                            rng.random_range(0.5..2.0),
                            rng.random_range(0.5..2.0),
                            rng.random_range(0.5..2.0),
                        )),
                    })
                    .collect()
            })
            .collect();
        let identify: Vec<usize> = (0..n_stations).collect();
        let prior = DMatrix::identity(k, k) * 1e-3;
        let start = || {
            let chosen: Vec<Vec<usize>> = (0..n_stations).map(|_| vec![0]).collect();
            let stations: Vec<StationInfo> = chosen
                .iter()
                .zip(&infos)
                .map(|(c, i)| StationInfo::of(i, c, k))
                .collect();
            let mut m = prior.clone();
            for st in &stations {
                m += st.schur();
            }
            (chosen, stations, m)
        };
        let mut greedy = Greedy {
            sites: &sites,
            identify: &identify,
            infos: &infos,
            n,
        };
        let (mut full, mut st_full, mut m_full) = start();
        greedy.full(
            &mut full,
            &mut st_full,
            &mut m_full,
            &Objective::LogDet,
            &mut || false,
        );
        let (mut lazy, mut st_lazy, mut m_lazy) = start();
        greedy.lazy(&mut lazy, &mut st_lazy, &mut m_lazy, &mut || false);
        assert!(full.iter().all(|c| c.len() == n));
        assert_eq!(full, lazy);
    }
}
