//! The covariance of `ml`'s estimate as its users read it back from a
//! result, and the aligned σ a point gets from it: the one home of both,
//! beside the solver that writes the covariance
//! ([`diagnostics`](super::diagnostics), `solver.covariance` in file
//! units: mm, deg). The range prediction ([`range`](super::range)),
//! compensation's per-target σ and measuring's per-point σ use them.
//!
//! **Reading.** [`ParameterCovariance::read`] maps each label (`he_x` …
//! `he_rz`, `alpha1` … `d<n>`) to its unknown in the update vector `ΔY`
//! of [`estimate`](crate::engine::calibrate::solve::estimate) (the inverse
//! of [`unknown_label`]) and keeps the matrix in file units with the
//! factor from file to engine units (rad per deg, 1 for mm) of each row.
//!
//! **Aligned σ.** Sphere data see distances only: part of the parameter
//! uncertainty moves every point of a region alike, a rigid motion that
//! a work frame (taught or measured where the cell works) takes out. To
//! first order a point `p_i` moves by `G_i·δθ`; a small rigid motion
//! `(t, ω)` about `c` moves it by `R_i·(t, ω)`, `R_i = [I | −[p_i − c]×]`
//! ([`twist_rows`]). The rigid motion that best fits the points' motions,
//! `M = (Σ RᵢᵀRᵢ)⁺ Σ RᵢᵀGᵢ` ([`RigidFit`]), is removed from each:
//! `H_i = G_i − R_i·M`, and `σ_i² = tr(H_i·C·H_iᵀ)` ([`aligned_sigma`]).
//! The pseudo-inverse takes out what can be taken out when the points
//! leave a rotation free (all on one line).

use nalgebra::{DMatrix, Matrix3x6, Vector3};

use crate::engine::base::geometry::{skew, twist_rows};
use crate::engine::calibrate::solve::SolverReport;
use crate::engine::calibrate::solve::estimate::{unknown_is_angle, unknown_label};

/// Relative tolerance of the rigid fit's pseudo-inverse (of the largest
/// singular value of `Σ RᵢᵀRᵢ`): far below any real direction, far above
/// rounding.
const RIGID_FIT_TOLERANCE: f64 = 1e-12;

/// Why a result's `solver.covariance` cannot be read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CovarianceError {
    /// A label that is no parameter of the model.
    #[error(
        "solver.covariance names `{label}`, not a parameter of the result's model ({joints} joints)"
    )]
    UnknownLabel {
        /// The label.
        label: String,
        /// The model's joints.
        joints: usize,
    },
    /// The matrix does not match its labels.
    #[error("solver.covariance is not {0} × {0} like its labels")]
    NotSquare(usize),
    /// NaN, infinite or asymmetric entries.
    #[error("solver.covariance is not a finite symmetric matrix")]
    NotSymmetric,
}

/// The covariance of the calibrated parameters as a result gives it
/// (`ml`'s `solver.covariance`), on the unknowns of the update vector
/// `ΔY`.
#[derive(Debug, Clone, PartialEq)]
pub struct ParameterCovariance {
    /// Index of each row in `ΔY` (hand-eye twist first, then the `5·n`
    /// MDH parameters).
    pub unknowns: Vec<usize>,
    /// Engine units (mm or rad) per file unit (mm or deg) of each row.
    pub raw_per_file_unit: Vec<f64>,
    /// The covariance, file units (`mm`, `deg`; entry `(i, j)` in
    /// `unit_i · unit_j`).
    pub matrix: DMatrix<f64>,
}

/// The index in `ΔY` of a covariance label (`he_x` … `he_rz`, `alpha1` …
/// `d<n>`) for a robot of `joints` joints, and whether it is an angle.
#[must_use]
pub fn unknown_of_label(label: &str, joints: usize) -> Option<(usize, bool)> {
    (0..6 + 5 * joints)
        .find(|&u| unknown_label(u) == label)
        .map(|u| (u, unknown_is_angle(u)))
}

/// The a posteriori variance factor of `report` (`ml`'s
/// `solver.variance_factor`, Σ r² / (residuals − unknowns) of the whitened
/// residuals: 1 when the noise model fits), 1 when it has none or it is
/// not a positive number. Every σ a user sees is the covariance as written
/// (a priori, from the noise model) times this factor (a posteriori): the
/// one home of that rule (measuring's per-point σ, compensation's
/// predicted σ, the result view's hand-eye σ, the history's jump test).
#[must_use]
pub fn variance_factor(report: &SolverReport) -> f64 {
    match report {
        SolverReport::Ml(r) => a_posteriori_factor(r.variance_factor),
        _ => 1.0,
    }
}

/// The factor a covariance is scaled by for a variance factor `v`: `v`
/// itself when it is a positive number, else 1.
#[must_use]
pub fn a_posteriori_factor(v: f64) -> f64 {
    if v.is_finite() && v > 0.0 { v } else { 1.0 }
}

impl ParameterCovariance {
    /// [`Self::read`] scaled by [`variance_factor`]: the a posteriori
    /// covariance every σ downstream uses.
    ///
    /// # Errors
    /// As [`Self::read`].
    pub fn read_a_posteriori(
        report: &SolverReport,
        joints: usize,
    ) -> Result<Option<Self>, CovarianceError> {
        let factor = variance_factor(report);
        Ok(Self::read(report, joints)?.map(|mut c| {
            c.matrix *= factor;
            c
        }))
    }

    /// The covariance of `report` for a model of `joints` joints:
    /// `Ok(None)` when it has none (the paper's method, or an `ml` run
    /// that stopped before its diagnostics).
    ///
    /// # Errors
    /// [`CovarianceError`]: a label the model does not have, a matrix not
    /// square like its labels, or not finite and symmetric.
    pub fn read(report: &SolverReport, joints: usize) -> Result<Option<Self>, CovarianceError> {
        let SolverReport::Ml(ml) = report else {
            return Ok(None);
        };
        let c = &ml.covariance;
        if c.labels.is_empty() {
            return Ok(None);
        }
        let k = c.labels.len();
        let mut unknowns = Vec::with_capacity(k);
        let mut raw_per_file_unit = Vec::with_capacity(k);
        for label in &c.labels {
            let (u, angle) =
                unknown_of_label(label, joints).ok_or_else(|| CovarianceError::UnknownLabel {
                    label: label.clone(),
                    joints,
                })?;
            unknowns.push(u);
            raw_per_file_unit.push(if angle { 1.0_f64.to_radians() } else { 1.0 });
        }
        if c.matrix.len() != k || c.matrix.iter().any(|row| row.len() != k) {
            return Err(CovarianceError::NotSquare(k));
        }
        let matrix = DMatrix::from_fn(k, k, |i, j| c.matrix[i][j]);
        let scale = matrix.amax().max(f64::MIN_POSITIVE);
        let asymmetric = (&matrix - matrix.transpose()).amax() > 1e-9 * scale;
        if matrix.iter().any(|v| !v.is_finite()) || asymmetric {
            return Err(CovarianceError::NotSymmetric);
        }
        Ok(Some(Self {
            unknowns,
            raw_per_file_unit,
            matrix,
        }))
    }

    /// The covariance in engine units (rad, mm): entry `(i, j)` times the
    /// rows' factors.
    #[must_use]
    pub fn in_engine_units(&self) -> DMatrix<f64> {
        let k = self.unknowns.len();
        let f = &self.raw_per_file_unit;
        DMatrix::from_fn(k, k, |i, j| self.matrix[(i, j)] * f[i] * f[j])
    }
}

/// `[0 | −[v]×]`: the motion `ω × v` of the offset `v` under a small
/// rotation `ω`, as a function of `(t, ω)` (the part of [`twist_rows`]
/// that grows with the point's offset).
#[must_use]
pub fn rotation_rows(v: &Vector3<f64>) -> Matrix3x6<f64> {
    let mut r = Matrix3x6::zeros();
    r.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-skew(v)));
    r
}

/// `R = [I | −[d]×]` ([`twist_rows`]): the motion `t + ω × d` of a point
/// at `d` from the centre of a small rigid motion `(t, ω)`, as a dynamic
/// matrix to stand beside a `G` (3 × k).
fn rigid_rows_dyn(d: &Vector3<f64>) -> DMatrix<f64> {
    let r = twist_rows(d);
    DMatrix::from_fn(3, 6, |i, j| r[(i, j)])
}

/// The rigid fit `M = (Σ RᵢᵀRᵢ)⁺ Σ RᵢᵀGᵢ` (6 × k) from its two sums
/// (module doc).
#[must_use]
pub fn rigid_fit(rtr: &DMatrix<f64>, rtg: DMatrix<f64>) -> DMatrix<f64> {
    // Only a negative tolerance makes the pseudo-inverse fail.
    let pinv = rtr
        .clone()
        .pseudo_inverse(RIGID_FIT_TOLERANCE * rtr.norm().max(1e-300))
        .unwrap_or_else(|_| DMatrix::zeros(6, 6));
    pinv * rtg
}

/// The best rigid motion of a set of points, fitted to their motions
/// `G_i` (module doc), and the aligned motion `H` of any point.
#[derive(Debug, Clone)]
pub struct RigidFit {
    /// The centroid `c` of the points the fit is over (base frame, mm).
    centroid: Vector3<f64>,
    /// `M`, 6 × k.
    m: DMatrix<f64>,
}

impl RigidFit {
    /// The fit over `points`, `(p_i, G_i)` (base frame mm; 3 × k, every
    /// `G_i` the same `k` columns).
    #[must_use]
    pub fn new<'a>(
        points: impl Iterator<Item = (&'a Vector3<f64>, &'a DMatrix<f64>)> + Clone,
        k: usize,
    ) -> Self {
        let n = points.clone().count();
        let centroid = points.clone().map(|(p, _)| p).sum::<Vector3<f64>>() / n.max(1) as f64;
        let mut rtr = DMatrix::zeros(6, 6);
        let mut rtg = DMatrix::zeros(6, k);
        for (p, g) in points {
            let r = rigid_rows_dyn(&(p - centroid));
            rtr += r.transpose() * &r;
            rtg += r.transpose() * g;
        }
        Self {
            centroid,
            m: rigid_fit(&rtr, rtg),
        }
    }

    /// `k`, the parameters the motions are in.
    #[must_use]
    pub fn columns(&self) -> usize {
        self.m.ncols()
    }

    /// `H = G − R(p)·M` of a point with motion `g` at base position `p`.
    #[must_use]
    pub fn aligned(&self, g: &DMatrix<f64>, p: &Vector3<f64>) -> DMatrix<f64> {
        g - rigid_rows_dyn(&(p - self.centroid)) * &self.m
    }
}

/// `σ = √tr(H·C·Hᵀ)` (mm) of a point's motion `h` under the covariance
/// `cov` of the parameters `h`'s columns are in (never below 0).
#[must_use]
pub fn aligned_sigma(h: &DMatrix<f64>, cov: &DMatrix<f64>) -> f64 {
    crate::engine::base::numeric::sigma_of_variance((h * cov * h.transpose()).trace())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_map_to_the_update_vector() {
        assert_eq!(unknown_of_label("he_x", 6), Some((0, false)));
        assert_eq!(unknown_of_label("he_rz", 6), Some((5, true)));
        assert_eq!(unknown_of_label("alpha1", 6), Some((6, true)));
        assert_eq!(unknown_of_label("a1", 6), Some((7, false)));
        assert_eq!(unknown_of_label("d6", 6), Some((6 + 29, false)));
        assert_eq!(unknown_of_label("theta3", 6), Some((6 + 10 + 3, true)));
        assert_eq!(unknown_of_label("d7", 6), None);
        assert_eq!(unknown_of_label("x1", 6), None);
    }

    /// A rigid motion of the points is taken out whole: points that all
    /// move by one rigid motion have an aligned σ of 0.
    #[test]
    fn a_common_rigid_motion_is_taken_out() {
        let points: Vec<Vector3<f64>> = [
            [100.0, 0.0, 0.0],
            [0.0, 200.0, 10.0],
            [-50.0, 30.0, 300.0],
            [10.0, -80.0, 20.0],
        ]
        .iter()
        .map(|p| Vector3::from(*p))
        .collect();
        // Two parameters: a translation along x, a rotation about z.
        let g: Vec<DMatrix<f64>> = points
            .iter()
            .map(|p| {
                let mut g = DMatrix::zeros(3, 2);
                g[(0, 0)] = 1.0;
                g.set_column(1, &Vector3::z().cross(p));
                g
            })
            .collect();
        let fit = RigidFit::new(points.iter().zip(&g), 2);
        let cov = DMatrix::identity(2, 2);
        for (p, g) in points.iter().zip(&g) {
            assert!(aligned_sigma(&fit.aligned(g, p), &cov) < 1e-9);
            assert!(aligned_sigma(g, &cov) > 1.0);
        }
    }
}
