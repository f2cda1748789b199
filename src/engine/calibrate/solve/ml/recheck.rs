//! The re-check of a calibrated cell (issue 33): does a short scan of the
//! sphere still agree with the calibration, and if not, what moved.
//!
//! **Model.** Each sighting `i` of the check predicts its sphere centre
//! `x_i = bT_e(q_i; p̂) · eT_s · X_si` through the calibration (its
//! calibrated model and hand-eye `θ̂`). If the cell is unchanged,
//! `x_i = c_s + e_i`, `c_s` the (unknown: it may have been moved) centre
//! of its station, and the stacked errors have the covariance
//!
//! ```text
//! V = diag(Σ_i) + A · C · Aᵀ
//! ```
//!
//! `Σ_i` the noise model of the calibration ([`base_covariance`]: the
//! stripe fit's covariance rotated, plus the joint noise through the
//! kinematics, or the pose σ for flange poses), `A` the sensitivity of the
//! centres to the parameters ([`PoseSensitivity`], eq. 12-16) and `C` the
//! calibration's parameter covariance: the calibration's own error is
//! common to every sighting, so it is not counted as independent noise.
//! Both are scaled by the result's variance factor (at least 1, so that a
//! calibration whose noise was smaller than modelled does not make the
//! check stricter than its model).
//!
//! **Test.** The station centres are fitted by generalised least squares
//! and `T = rᵀ V⁻¹ r` is χ² with `3N − 3S` degrees of freedom when the cell
//! holds. Two tests share the false-alarm rate `α` (Bonferroni, `α/2`
//! each): the omnibus test on `T` (anything that spoils the centres, a
//! loose or dirty sphere included) and the *directed* test on the part
//! of the whitened residual that a change of the cell can make,
//! `T_d = ‖Qᵀ r̃‖²` with `Q` an orthonormal basis of the whitened
//! sensitivity to the hand-eye and the estimated kinematic parameters
//! with the station centres projected out: χ² with `k = rank` degrees of
//! freedom, far fewer than `T`'s, so a change of the cell is seen with
//! a smaller non-centrality. The cell fails when either exceeds its
//! `1 − α/2` quantile. A moved sphere changes only `c_s` and never fails
//! them; a base-like drift (a rigid motion of the whole robot) cannot be
//! told from one at a single station.
//!
//! **What moved.** Each candidate change (the hand-eye's six unknowns
//! together; each kinematic parameter the calibration estimated, alone) is
//! added to the fit; the one whose drop in `T` is most significant (the
//! smallest p-value of the drop, χ² with the columns it adds) is named,
//! with its estimated size and σ, and whether what is left then passes.
//! [`detectable`] gives, before a check is run, the smallest change of
//! each kind the planned poses detect with a given power (non-central χ²).

use nalgebra::{DMatrix, DVector, Matrix3, SymmetricEigen, Vector3};

use super::noise::base_covariance;
use crate::engine::base::geometry::skew;
use crate::engine::base::numeric::MAX_DECOMPOSITION_SWEEPS;
use crate::engine::calibrate::handeye::Sighting;
use crate::engine::calibrate::solve::estimate::{
    Estimate, PoseSensitivity, unknown_is_angle, unknown_label,
};

/// Relative tolerance of the rank of a whitened design (of its largest
/// singular value): columns the check cannot see are below it by orders.
const RANK_TOLERANCE: f64 = 1e-9;

/// Relative tolerance (of the largest singular value) of the directions
/// the directed test counts: a direction weaker than this carries no
/// detectable change and would only add a degree of freedom.
const SEEN_TOLERANCE: f64 = 1e-4;

/// One sighting of the check: its station, the pose and the sensor-frame
/// centre, and that centre's covariance in the sensor frame (mm²).
#[derive(Debug, Clone, PartialEq)]
pub struct CheckPoint {
    /// Station id (the sphere position).
    pub station: String,
    /// The pose and the sensor-frame centre.
    pub sighting: Sighting,
    /// Covariance of the sensor-frame centre, mm².
    pub sensor_cov: Matrix3<f64>,
}

/// The calibration a check is made against.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckModel {
    /// The calibrated model and hand-eye.
    pub estimate: Estimate,
    /// The parameter covariance in engine units (mm, rad), on the
    /// unknowns `unknowns` of `ΔY`; empty when the result has none.
    pub covariance: DMatrix<f64>,
    /// The unknowns of `covariance`, indices into `ΔY`.
    pub unknowns: Vec<usize>,
    /// σ of the joint readings, deg.
    pub joint_sigma_deg: f64,
    /// σ of a reported flange pose, mm (pose-only).
    pub pose_sigma_mm: f64,
    /// Scale of every covariance (the variance factor, at least 1).
    pub scale: f64,
}

/// What could move: the hand-eye, or one kinematic parameter.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Moved {
    /// The sensor on its mount (the six hand-eye unknowns).
    HandEye,
    /// One kinematic parameter (its label, e.g. `theta3`).
    Parameter(String),
}

/// A candidate change fitted to the check.
#[derive(Debug, Clone, PartialEq)]
pub struct Explanation {
    /// What moved.
    pub moved: Moved,
    /// Labels of its unknowns (`he_x` … or the parameter).
    pub labels: Vec<String>,
    /// Its estimated change of the cell since the calibration, file
    /// units (mm, deg), one per label: the centres predicted through the
    /// calibration move by `−A·δ` when the cell moved by `δ`.
    pub change: Vec<f64>,
    /// The 1σ of each change, file units.
    pub sigma: Vec<f64>,
    /// p-value of the drop in `T` when it is added.
    pub p_drop: f64,
    /// `T` left with it fitted.
    pub remaining: f64,
    /// Degrees of freedom left.
    pub remaining_dof: usize,
    /// Whether what is left passes the test.
    pub explains: bool,
}

/// The verdict of a check.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckTest {
    /// `T = rᵀ V⁻¹ r`.
    pub statistic: f64,
    /// Its degrees of freedom.
    pub dof: usize,
    /// The false-alarm rate.
    pub alpha: f64,
    /// The `1 − α/2` quantile of χ²(dof).
    pub threshold: f64,
    /// `P(χ² > T)`.
    pub p_value: f64,
    /// The directed statistic `T_d` (module doc).
    pub directed: f64,
    /// Its degrees of freedom (the rank of the changes the check sees).
    pub directed_dof: usize,
    /// The `1 − α/2` quantile of χ²(`directed_dof`).
    pub directed_threshold: f64,
    /// Both tests pass: `T ≤ threshold` and `T_d ≤ directed_threshold`.
    pub holds: bool,
    /// Each station's fitted sphere centre (base frame, mm).
    pub centres: Vec<(String, Vector3<f64>)>,
    /// RMS (3-D) of the predicted centres about their station's fit, mm.
    pub rms_mm: f64,
    /// Candidate changes, the most significant first.
    pub explanations: Vec<Explanation>,
}

/// Why a check cannot be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RecheckError {
    /// Too few sightings for the stations.
    #[error(
        "{points} sightings at {stations} stations leave no degree of freedom to test: at least two sightings at one station are needed"
    )]
    TooFew {
        /// Sightings.
        points: usize,
        /// Stations.
        stations: usize,
    },
    /// The covariance of the centres is not positive definite.
    #[error("the noise model gives the check's centres a covariance that is not positive definite")]
    NotDefinite,
}

/// The rows of a check: predicted centres, their sensitivity to every
/// unknown of `ΔY`, the station design and the whitening.
struct Rows {
    /// Predicted centres, stacked (3N).
    x: DVector<f64>,
    /// Sensitivity, 3N × (6 + 5n).
    a: DMatrix<f64>,
    /// Station indicator, 3N × 3S.
    p: DMatrix<f64>,
    /// Station ids in order.
    stations: Vec<String>,
    /// `L⁻¹` with `V = L·Lᵀ`.
    whiten: DMatrix<f64>,
}

/// The hand-eye block `R_bs · [I | −[X_s]×]` and the centre of a flange-pose
/// sighting (no kinematic columns).
fn flange_rows(est: &Estimate, s: &Sighting, n: usize) -> Option<(Vector3<f64>, DMatrix<f64>)> {
    let base_from_sensor = s.flange? * est.flange_from_sensor;
    let x = (base_from_sensor * nalgebra::Point3::from(s.centre_in_sensor)).coords;
    let r: Matrix3<f64> = base_from_sensor.rotation.to_rotation_matrix().into_inner();
    let mut a = DMatrix::zeros(3, n);
    a.fixed_view_mut::<3, 3>(0, 0).copy_from(&r);
    a.fixed_view_mut::<3, 3>(0, 3)
        .copy_from(&(-(r * skew(&s.centre_in_sensor))));
    Some((x, a))
}

fn rows(model: &CheckModel, points: &[CheckPoint]) -> Result<Rows, RecheckError> {
    let est = &model.estimate;
    let n_unknowns = 6 + est.robot.n_params();
    let mut stations: Vec<String> = Vec::new();
    for p in points {
        if !stations.contains(&p.station) {
            stations.push(p.station.clone());
        }
    }
    let (n, s) = (points.len(), stations.len());
    if 3 * n <= 3 * s {
        return Err(RecheckError::TooFew {
            points: n,
            stations: s,
        });
    }
    let mut x = DVector::zeros(3 * n);
    let mut a = DMatrix::zeros(3 * n, n_unknowns);
    let mut p = DMatrix::zeros(3 * n, 3 * s);
    let mut v = DMatrix::zeros(3 * n, 3 * n);
    for (i, pt) in points.iter().enumerate() {
        let (xi, ai) = flange_rows(est, &pt.sighting, n_unknowns).unwrap_or_else(|| {
            let ps = PoseSensitivity::new(est, &pt.sighting);
            ps.at(est, &pt.sighting.centre_in_sensor)
        });
        x.fixed_rows_mut::<3>(3 * i).copy_from(&xi);
        a.view_mut((3 * i, 0), (3, n_unknowns)).copy_from(&ai);
        let k = stations
            .iter()
            .position(|st| *st == pt.station)
            .unwrap_or(0);
        p.view_mut((3 * i, 3 * k), (3, 3))
            .copy_from(&Matrix3::identity());
        let sigma = base_covariance(
            est,
            &pt.sighting,
            &pt.sensor_cov,
            model.joint_sigma_deg,
            model.pose_sigma_mm,
        );
        v.view_mut((3 * i, 3 * i), (3, 3)).copy_from(&sigma);
    }
    if !model.unknowns.is_empty() {
        let ac = DMatrix::from_fn(3 * n, model.unknowns.len(), |r, c| {
            a[(r, model.unknowns[c])]
        });
        v += &ac * &model.covariance * ac.transpose();
    }
    v *= model.scale.max(1.0);
    let l = v.cholesky().ok_or(RecheckError::NotDefinite)?;
    let whiten = l.l().try_inverse().ok_or(RecheckError::NotDefinite)?;
    Ok(Rows {
        x,
        a,
        p,
        stations,
        whiten,
    })
}

/// A whitened least-squares fit of `z` on the columns of `d`: the
/// residual sum of squares, the rank, the coefficients and their
/// covariance (pseudo-inverse of `dᵀd`).
struct Fit {
    rss: f64,
    rank: usize,
    beta: DVector<f64>,
    cov: DMatrix<f64>,
}

fn fit(z: &DVector<f64>, d: &DMatrix<f64>) -> Fit {
    let m = d.ncols();
    let ntn = d.transpose() * d;
    let Some(eig) = SymmetricEigen::try_new(ntn.clone(), 1e-15, MAX_DECOMPOSITION_SWEEPS) else {
        return Fit {
            rss: z.norm_squared(),
            rank: 0,
            beta: DVector::zeros(m),
            cov: DMatrix::zeros(m, m),
        };
    };
    let top = eig.eigenvalues.amax();
    let mut inv = DMatrix::zeros(m, m);
    let mut rank = 0;
    for k in 0..m {
        let l = eig.eigenvalues[k];
        if l > RANK_TOLERANCE * RANK_TOLERANCE * top.max(f64::MIN_POSITIVE) && l > 0.0 {
            rank += 1;
            let u = eig.eigenvectors.column(k);
            inv += u * u.transpose() / l;
        }
    }
    let beta = &inv * (d.transpose() * z);
    let rss = (z - d * &beta).norm_squared();
    Fit {
        rss,
        rank,
        beta,
        cov: inv,
    }
}

/// An orthonormal basis of the whitened changes the check can see: the
/// columns of `d` (whitened sensitivity to the candidates' unknowns) with
/// the station design `dp` projected out; `None` when it sees none.
fn seen_basis(d: &DMatrix<f64>, dp: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let base = fit(&DVector::zeros(dp.nrows()), dp);
    let left = d - dp * (&base.cov * (dp.transpose() * d));
    let svd = left.svd(true, false);
    let u = svd.u?;
    let top = svd.singular_values.amax();
    let keep: Vec<usize> = (0..svd.singular_values.len())
        .filter(|&k| top > 0.0 && svd.singular_values[k] > SEEN_TOLERANCE * top)
        .collect();
    (!keep.is_empty()).then(|| u.select_columns(&keep))
}

/// The columns of every candidate change (hand-eye and the estimated
/// kinematic parameters), indices into `ΔY`.
fn candidate_columns(model: &CheckModel) -> Vec<usize> {
    candidates(model).into_iter().flat_map(|(_, c)| c).collect()
}

/// The candidate changes of a model: the hand-eye, then every kinematic
/// parameter the calibration estimated (columns of `ΔY`).
fn candidates(model: &CheckModel) -> Vec<(Moved, Vec<usize>)> {
    let mut out = vec![(Moved::HandEye, (0..6).collect())];
    for &u in &model.unknowns {
        if u >= 6 {
            out.push((Moved::Parameter(unknown_label(u)), vec![u]));
        }
    }
    out
}

/// File units (mm, deg) per engine unit of unknown `u`.
fn file_unit(u: usize) -> f64 {
    if unknown_is_angle(u) {
        1.0_f64.to_degrees()
    } else {
        1.0
    }
}

/// Tests `points` against `model` at false-alarm rate `alpha` (module doc).
///
/// # Errors
/// [`RecheckError`]: no degree of freedom, or a covariance that is not
/// positive definite.
pub fn recheck(
    model: &CheckModel,
    points: &[CheckPoint],
    alpha: f64,
) -> Result<CheckTest, RecheckError> {
    let r = rows(model, points)?;
    let z = &r.whiten * &r.x;
    let dp = &r.whiten * &r.p;
    let base = fit(&z, &dp);
    let rows_n = z.len();
    let dof = rows_n.saturating_sub(base.rank).max(1);
    let threshold = chi2_quantile(1.0 - 0.5 * alpha, dof as f64);
    let statistic = base.rss;
    let cols = candidate_columns(model);
    let seen = &r.whiten * DMatrix::from_fn(r.a.nrows(), cols.len(), |i, j| r.a[(i, cols[j])]);
    let residual_w = &z - &dp * &base.beta;
    let (directed, directed_dof) = match seen_basis(&seen, &dp) {
        Some(q) => ((q.transpose() * &residual_w).norm_squared(), q.ncols()),
        None => (0.0, 0),
    };
    let directed_threshold = if directed_dof > 0 {
        chi2_quantile(1.0 - 0.5 * alpha, directed_dof as f64)
    } else {
        f64::INFINITY
    };
    let centres: Vec<(String, Vector3<f64>)> = r
        .stations
        .iter()
        .enumerate()
        .map(|(k, id)| {
            (
                id.clone(),
                Vector3::new(base.beta[3 * k], base.beta[3 * k + 1], base.beta[3 * k + 2]),
            )
        })
        .collect();
    let residual = &r.x - &r.p * &base.beta;
    let rms_mm = (residual.norm_squared() / points.len().max(1) as f64).sqrt();
    let mut explanations = Vec::new();
    for (moved, cols) in candidates(model) {
        let e = DMatrix::from_fn(r.a.nrows(), cols.len(), |i, j| r.a[(i, cols[j])]);
        let mut d = DMatrix::zeros(rows_n, dp.ncols() + cols.len());
        d.columns_mut(0, dp.ncols()).copy_from(&dp);
        d.columns_mut(dp.ncols(), cols.len())
            .copy_from(&(&r.whiten * e));
        let f = fit(&z, &d);
        let added = f.rank.saturating_sub(base.rank);
        if added == 0 {
            continue;
        }
        let remaining_dof = rows_n.saturating_sub(f.rank).max(1);
        let drop = (statistic - f.rss).max(0.0);
        let off = dp.ncols();
        explanations.push(Explanation {
            moved,
            labels: cols.iter().map(|&u| unknown_label(u)).collect(),
            change: cols
                .iter()
                .enumerate()
                .map(|(j, &u)| -f.beta[off + j] * file_unit(u))
                .collect(),
            sigma: cols
                .iter()
                .enumerate()
                .map(|(j, &u)| {
                    crate::engine::base::numeric::sigma_of_variance(f.cov[(off + j, off + j)])
                        * file_unit(u)
                })
                .collect(),
            p_drop: chi2_sf(drop, added as f64),
            remaining: f.rss,
            remaining_dof,
            explains: f.rss <= chi2_quantile(1.0 - 0.5 * alpha, remaining_dof as f64),
        });
    }
    // Best first: what is left the most like noise, as a z-score of χ²
    // (`(T − k)/√(2k)`: comparable across the degrees of freedom left,
    // and finite where the p-values underflow).
    let left = |e: &Explanation| {
        let k = e.remaining_dof as f64;
        (e.remaining - k) / (2.0 * k).sqrt()
    };
    explanations.sort_by(|a, b| left(a).total_cmp(&left(b)));
    Ok(CheckTest {
        statistic,
        dof,
        alpha,
        threshold,
        p_value: chi2_sf(statistic, dof as f64),
        directed,
        directed_dof,
        directed_threshold,
        holds: statistic <= threshold && directed <= directed_threshold,
        centres,
        rms_mm,
        explanations,
    })
}

/// The smallest changes a check of `points` detects with probability
/// `power` at false-alarm rate `alpha`.
#[derive(Debug, Clone, PartialEq)]
pub struct Detectable {
    /// A knock of the sensor on its mount: a translation in its worst
    /// direction, mm.
    pub translation_mm: f64,
    /// A turn of the sensor about the flange origin (its mount), about
    /// the worst axis, deg.
    pub rotation_deg: f64,
    /// Each estimated kinematic parameter: label, change (mm or deg), and
    /// that change in σ of the calibration's covariance (`None` without).
    pub parameters: Vec<(String, f64, Option<f64>)>,
    /// Degrees of freedom of the directed test the sizes are quoted for
    /// (the omnibus test only adds to the power).
    pub dof: usize,
}

/// The smallest detectable changes (module doc): for a change `δ` along
/// columns `E`, the test's non-centrality is `δᵀ Ẽᵀ(I − Π)Ẽ δ` with `Ẽ`
/// whitened and `Π` the projection on the station centres; `δ` is
/// detectable when the non-central χ² exceeds the threshold with
/// probability `power`.
///
/// # Errors
/// As [`recheck`].
pub fn detectable(
    model: &CheckModel,
    points: &[CheckPoint],
    alpha: f64,
    power: f64,
) -> Result<Detectable, RecheckError> {
    let r = rows(model, points)?;
    let dp = &r.whiten * &r.p;
    let rows_n = dp.nrows();
    let base = fit(&DVector::zeros(rows_n), &dp);
    // The directed test's (module doc): every change considered here lies
    // in its span, so its non-centrality is the whole of the change's.
    let cols = candidate_columns(model);
    let seen = &r.whiten * DMatrix::from_fn(r.a.nrows(), cols.len(), |i, j| r.a[(i, cols[j])]);
    let dof = seen_basis(&seen, &dp).map_or(0, |q| q.ncols()).max(1);
    let threshold = chi2_quantile(1.0 - 0.5 * alpha, dof as f64);
    let lambda = required_noncentrality(threshold, dof as f64, power);
    // (I − Π)·Ẽ for every column of ΔY.
    let e = &r.whiten * &r.a;
    let proj = &dp * (&base.cov * (dp.transpose() * &e));
    let left = e - proj;
    let m = left.transpose() * &left;
    // A knock of the sensor on its mount, in the flange frame: a
    // translation `t_f` is the twist `(Rᵀ·t_f, 0)`, a rotation `ω_f` about
    // the flange origin is `(Rᵀ·(ω_f × t), Rᵀ·ω_f)` (`R`, `t` of `eT_s`).
    let he = &model.estimate.flange_from_sensor;
    let rt: Matrix3<f64> = he.rotation.to_rotation_matrix().into_inner().transpose();
    let mut shift = DMatrix::zeros(6, 3);
    shift.fixed_view_mut::<3, 3>(0, 0).copy_from(&rt);
    let mut turn = DMatrix::zeros(6, 3);
    turn.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&(-(rt * skew(&he.translation.vector))));
    turn.fixed_view_mut::<3, 3>(3, 0).copy_from(&rt);
    let m_he = m.view((0, 0), (6, 6)).into_owned();
    let worst = |map: &DMatrix<f64>| {
        let block = map.transpose() * &m_he * map;
        let smallest = block.symmetric_eigenvalues().min();
        if smallest > 0.0 {
            (lambda / smallest).sqrt()
        } else {
            f64::INFINITY
        }
    };
    let sigma_of = |u: usize| {
        model
            .unknowns
            .iter()
            .position(|&k| k == u)
            .map(|i| crate::engine::base::numeric::sigma_of_variance(model.covariance[(i, i)]))
    };
    let parameters = model
        .unknowns
        .iter()
        .filter(|&&u| u >= 6)
        .map(|&u| {
            let info = m[(u, u)];
            let size = if info > 0.0 {
                (lambda / info).sqrt()
            } else {
                f64::INFINITY
            };
            let in_sigma = sigma_of(u).filter(|s| *s > 0.0).map(|s| size / s);
            (unknown_label(u), size * file_unit(u), in_sigma)
        })
        .collect();
    Ok(Detectable {
        translation_mm: worst(&shift),
        rotation_deg: worst(&turn).to_degrees(),
        parameters,
        dof,
    })
}

/// `ln Γ(x)`, x > 0 (Lanczos, g = 7, nine terms: 1e-15 relative).
fn ln_gamma(x: f64) -> f64 {
    const G: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = G[0];
    let t = x + 7.5;
    for (i, g) in G.iter().enumerate().skip(1) {
        a += g / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// The regularised lower incomplete gamma `P(a, x)` (series below
/// `a + 1`, Lentz's continued fraction above; Numerical Recipes 6.2).
fn gamma_p(a: f64, x: f64) -> f64 {
    const STEPS: usize = 500;
    const EPS: f64 = 1e-15;
    if x <= 0.0 {
        return 0.0;
    }
    let front = (-x + a * x.ln() - ln_gamma(a)).exp();
    if x < a + 1.0 {
        let (mut term, mut sum, mut ap) = (1.0 / a, 1.0 / a, a);
        for _ in 0..STEPS {
            ap += 1.0;
            term *= x / ap;
            sum += term;
            if term.abs() < sum.abs() * EPS {
                break;
            }
        }
        return (sum * front).clamp(0.0, 1.0);
    }
    let tiny = 1e-300;
    let mut b = x + 1.0 - a;
    let mut c = 1.0 / tiny;
    let mut d = 1.0 / b;
    let mut h = d;
    for i in 1..=STEPS {
        let an = -(i as f64) * (i as f64 - a);
        b += 2.0;
        d = an * d + b;
        if d.abs() < tiny {
            d = tiny;
        }
        c = b + an / c;
        if c.abs() < tiny {
            c = tiny;
        }
        d = 1.0 / d;
        let step = d * c;
        h *= step;
        if (step - 1.0).abs() < EPS {
            break;
        }
    }
    (1.0 - front * h).clamp(0.0, 1.0)
}

/// `P(χ²_k ≤ x)`.
#[must_use]
pub fn chi2_cdf(x: f64, k: f64) -> f64 {
    gamma_p(0.5 * k, 0.5 * x)
}

/// `P(χ²_k > x)`.
#[must_use]
pub fn chi2_sf(x: f64, k: f64) -> f64 {
    1.0 - chi2_cdf(x, k)
}

/// The `p` quantile of χ²(k), by bisection on [`chi2_cdf`].
#[must_use]
pub fn chi2_quantile(p: f64, k: f64) -> f64 {
    const STEPS: usize = 200;
    let (mut lo, mut hi) = (0.0_f64, k + 10.0 * k.sqrt() + 100.0);
    while chi2_cdf(hi, k) < p && hi < 1e9 {
        hi *= 2.0;
    }
    for _ in 0..STEPS {
        let mid = 0.5 * (lo + hi);
        if chi2_cdf(mid, k) < p {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo < 1e-12 * hi.max(1.0) {
            break;
        }
    }
    0.5 * (lo + hi)
}

/// `P(χ'²_k(λ) > x)`: the non-central χ² as a Poisson mixture of central
/// ones, summed until the Poisson weights left are below 1e-12.
#[must_use]
pub fn noncentral_chi2_sf(x: f64, k: f64, lambda: f64) -> f64 {
    let half = 0.5 * lambda;
    let terms = (half + 12.0 * half.sqrt() + 50.0).ceil() as usize;
    let mut total = 0.0;
    let mut weight_sum = 0.0;
    for j in 0..terms {
        let jf = j as f64;
        let w = (-half + jf * half.max(f64::MIN_POSITIVE).ln() - ln_gamma(jf + 1.0)).exp();
        let w = if half == 0.0 {
            if j == 0 { 1.0 } else { 0.0 }
        } else {
            w
        };
        weight_sum += w;
        total += w * chi2_sf(x, k + 2.0 * jf);
        if 1.0 - weight_sum < 1e-12 && jf > half {
            break;
        }
    }
    total.clamp(0.0, 1.0)
}

/// The non-centrality at which a χ²(k) test with threshold `x` rejects
/// with probability `power`.
#[must_use]
pub fn required_noncentrality(x: f64, k: f64, power: f64) -> f64 {
    const STEPS: usize = 100;
    let (mut lo, mut hi) = (0.0_f64, 10.0_f64);
    while noncentral_chi2_sf(x, k, hi) < power && hi < 1e8 {
        hi *= 2.0;
    }
    for _ in 0..STEPS {
        let mid = 0.5 * (lo + hi);
        if noncentral_chi2_sf(x, k, mid) < power {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Quantiles from the χ² table.
    #[test]
    fn chi2_quantiles_match_tables() {
        for (p, k, q) in [
            (0.95, 1.0, 3.841),
            (0.999, 1.0, 10.828),
            (0.999, 3.0, 16.266),
            (0.999, 10.0, 29.588),
            (0.999, 27.0, 55.476),
            (0.99, 60.0, 88.379),
        ] {
            assert!((chi2_quantile(p, k) - q).abs() < 2e-3, "{p} {k}");
        }
    }

    /// λ = 0 is the central χ²; a known power value (k = 1: the
    /// two-sided normal test, λ = (1.96 + 1.645)² for 95 % at 5 %).
    #[test]
    fn noncentral_reduces_and_matches_the_normal_case() {
        assert!((noncentral_chi2_sf(5.0, 3.0, 0.0) - chi2_sf(5.0, 3.0)).abs() < 1e-12);
        let lambda = required_noncentrality(3.841_458_8, 1.0, 0.95);
        assert!(
            (lambda - (1.959_964 + 1.644_854_f64).powi(2)).abs() < 0.01,
            "{lambda}"
        );
    }
}
