//! Each point's 1σ from the covariance of the calibrated parameters, O(1)
//! per point after a step per pose.
//!
//! A profile point `(0, y, z)` enters the model linearly: at a pose with
//! `base_from_sensor = (R, t)` it lands at `X = t + y·r₂ + z·r₃` (`r₂`,
//! `r₃` the columns of `R`), and its sensitivity to the parameter update
//! (hand-eye twist and MDH errors, [`PoseSensitivity`]) is affine in
//! `(y, z)` too: `G(y, z) = G₀ + y·G₁ + z·G₂` (3 × k, restricted to the
//! `k` parameters the covariance `C` covers, in file units).
//!
//! The base frame is not identifiable from a sphere (a rigid motion of
//! the whole cell leaves every distance unchanged), and a part is aligned
//! to its drawing once anyway; so, as `ml`'s range prediction does, the
//! best rigid motion of the whole cloud is taken out: with `Rᵢ = [I |
//! −[Xᵢ − c]×]` a point's motion under a small rigid motion `(τ, ω)` about
//! the centroid `c`, fitted to all points by least squares, `M =
//! (Σ RᵢᵀRᵢ)⁺ Σ RᵢᵀGᵢ` and `Hᵢ = Gᵢ − Rᵢ·M` (the aligned σ of
//! [`covariance`](crate::engine::calibrate::solve::ml::covariance), whose
//! rows and fit this uses). The set is **every point of
//! the measured cloud** (every pose, every point, each weighted alike, as
//! a user aligns a measured part once). `Rᵢ` is affine in `(y, z)` as
//! well, so the sums need only the moments `Σ1, Σy, Σz, Σy², Σyz, Σz²`
//! of each pose's points, and `H(y, z) = H₀ + y·H₁ + z·H₂` stays affine.
//!
//! With `C = L·Lᵀ` and `Kₐ = Hₐ·L`, `σ²(y, z) = tr(H·C·Hᵀ)` is a quadratic
//! form in `(1, y, z)` whose six coefficients `⟨Kₐ, K_b⟩` are computed
//! once per pose ([`SigmaForm`]): the same σ as the point form, evaluated
//! in O(1) a point (a test checks them against each other).

use nalgebra::{DMatrix, Isometry3, Matrix3, Matrix3x6, Matrix6, SymmetricEigen, Vector3};

use super::scan::Placement;
use crate::engine::base::geometry::twist_rows;
use crate::engine::base::numeric::MAX_DECOMPOSITION_SWEEPS;
use crate::engine::calibrate::solve::Control;
use crate::engine::calibrate::solve::estimate::{Estimate, PoseSensitivity};
use crate::engine::calibrate::solve::ml::covariance::{
    ParameterCovariance, rigid_fit, rotation_rows,
};

/// The variance of a point's position at one pose as a quadratic form in
/// its profile coordinates: `σ²(y, z) = c₀ + c₁·y + c₂·z + c₃·y² +
/// c₄·y·z + c₅·z²` (mm², `y`, `z` in mm).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SigmaForm(pub [f64; 6]);

impl SigmaForm {
    /// `σ²` (mm²) of the point `(0, y, z)`, never below 0.
    #[must_use]
    pub fn variance(&self, y: f64, z: f64) -> f64 {
        let c = &self.0;
        (c[0] + y * (c[1] + c[3] * y + c[4] * z) + z * (c[2] + c[5] * z)).max(0.0)
    }

    /// `σ` (mm) of the point `(0, y, z)`.
    #[must_use]
    pub fn sigma(&self, y: f64, z: f64) -> f64 {
        crate::engine::base::numeric::sigma_of_variance(self.variance(y, z))
    }

    /// The same form with `v` (mm²) added to every point.
    #[must_use]
    pub fn plus(mut self, v: f64) -> Self {
        self.0[0] += v;
        self
    }
}

/// Sums over one pose's points of `u·uᵀ`, `u = (1, y, z)`: the moments
/// the alignment needs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Moments(pub Matrix3<f64>);

impl Moments {
    /// The moments of `points` (`[y, z]`, mm).
    #[must_use]
    pub fn of(points: &[[f64; 2]]) -> Self {
        let (mut n, mut sy, mut sz, mut syy, mut syz, mut szz) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        for &[y, z] in points {
            n += 1.0;
            sy += y;
            sz += z;
            syy += y * y;
            syz += y * z;
            szz += z * z;
        }
        Self(Matrix3::new(n, sy, sz, sy, syy, syz, sz, syz, szz))
    }
}

/// One pose as the σ step needs it.
pub(super) struct SigmaPose<'a> {
    /// Where the robot was.
    pub placement: &'a Placement,
    /// `base_from_sensor` under the model whose covariance is used.
    pub base_from_sensor: Isometry3<f64>,
    /// Moments of its points.
    pub moments: Moments,
}

/// `G₀, G₁, G₂` of a pose (3 × k each, file units; module doc).
fn pose_rows(
    est: &Estimate,
    cov: &ParameterCovariance,
    placement: &Placement,
) -> [DMatrix<f64>; 3] {
    let pose = match placement {
        Placement::Joints(q) => PoseSensitivity::at_pose(est, q, None),
        Placement::Flange(flange) => PoseSensitivity::at_pose(est, &[], Some(flange)),
    };
    let (_, a0) = pose.at(est, &Vector3::zeros());
    let (_, ay) = pose.at(est, &Vector3::y());
    let (_, az) = pose.at(est, &Vector3::z());
    let k = cov.unknowns.len();
    let restrict = |a: &DMatrix<f64>, minus: Option<&DMatrix<f64>>| {
        DMatrix::from_fn(3, k, |r, c| {
            let u = cov.unknowns[c];
            let v = a[(r, u)] - minus.map_or(0.0, |m| m[(r, u)]);
            v * cov.raw_per_file_unit[c]
        })
    };
    [
        restrict(&a0, None),
        restrict(&ay, Some(&a0)),
        restrict(&az, Some(&a0)),
    ]
}

/// `R₀, R₁, R₂` of a pose about the centroid `c` (module doc): the
/// rigid rows of the sensor origin, and the rotation rows of the offsets
/// along the sensor's `y` and `z` axes.
fn pose_rigid_rows(base_from_sensor: &Isometry3<f64>, c: &Vector3<f64>) -> [Matrix3x6<f64>; 3] {
    let r = base_from_sensor.rotation.to_rotation_matrix().into_inner();
    let t = base_from_sensor.translation.vector;
    [
        twist_rows(&(t - c)),
        rotation_rows(&r.column(1).into_owned()),
        rotation_rows(&r.column(2).into_owned()),
    ]
}

/// A square root `L` of a symmetric positive semi-definite `C` (`C =
/// L·Lᵀ`), by its eigen decomposition (negative eigenvalues of rounding
/// are taken as 0).
fn square_root(c: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let eig = SymmetricEigen::try_new(c.clone(), f64::EPSILON, MAX_DECOMPOSITION_SWEEPS)?;
    let mut l = eig.eigenvectors;
    for (j, value) in eig.eigenvalues.iter().enumerate() {
        l.column_mut(j)
            .scale_mut(crate::engine::base::numeric::sigma_of_variance(*value));
    }
    Some(l)
}

/// The σ form of every pose (module doc), after the best rigid alignment
/// of all their points. `progress(done, of)` is asked after each pose of
/// each of the two passes (`of` = twice the poses); `None` when it
/// cancelled, or when the covariance has no square root (not symmetric
/// positive semi-definite to rounding).
pub(super) fn sigma_forms(
    est: &Estimate,
    cov: &ParameterCovariance,
    poses: &[SigmaPose<'_>],
    progress: &mut dyn FnMut(usize, usize) -> Control,
) -> Option<Vec<SigmaForm>> {
    let total = 2 * poses.len();
    let k = cov.unknowns.len();
    // The centroid of all points: Σ over poses of n·t + Σy·r₂ + Σz·r₃.
    let mut sum = Vector3::zeros();
    let mut count = 0.0;
    for p in poses {
        let m = &p.moments.0;
        let r = p
            .base_from_sensor
            .rotation
            .to_rotation_matrix()
            .into_inner();
        let t = p.base_from_sensor.translation.vector;
        sum += t * m[(0, 0)] + r.column(1) * m[(0, 1)] + r.column(2) * m[(0, 2)];
        count += m[(0, 0)];
    }
    let centroid = if count > 0.0 { sum / count } else { sum };
    // Pass 1: Σ RᵀR and Σ RᵀG from each pose's moments; each pose's G
    // kept for pass 2 (9·k numbers a pose).
    let mut rtr = Matrix6::zeros();
    let mut rtg = DMatrix::zeros(6, k);
    let mut rows = Vec::with_capacity(poses.len());
    for (i, p) in poses.iter().enumerate() {
        let g = pose_rows(est, cov, p.placement);
        let r = pose_rigid_rows(&p.base_from_sensor, &centroid);
        let m = &p.moments.0;
        for b in 0..3 {
            let mut w = nalgebra::Matrix6x3::zeros();
            for (a, ra) in r.iter().enumerate() {
                w += ra.transpose() * m[(a, b)];
            }
            rtr += w * r[b];
            rtg += w * &g[b];
        }
        rows.push(g);
        if progress(i + 1, total) == Control::Cancel {
            return None;
        }
    }
    // A degenerate cloud (one line of points) leaves a rotation free: the
    // pseudo-inverse takes out what can be taken out.
    let rtr = DMatrix::from_fn(6, 6, |i, j| rtr[(i, j)]);
    let l = square_root(&cov.matrix)?;
    let ml = rigid_fit(&rtr, rtg) * &l;
    // Pass 2: Kₐ = Gₐ·L − Rₐ·(M·L), and the six inner products.
    let mut forms = Vec::with_capacity(poses.len());
    for (i, (p, g)) in poses.iter().zip(&rows).enumerate() {
        let r = pose_rigid_rows(&p.base_from_sensor, &centroid);
        let kk: Vec<DMatrix<f64>> = (0..3)
            .map(|a| &g[a] * &l - DMatrix::from_fn(3, 6, |x, y| r[a][(x, y)]) * &ml)
            .collect();
        let dot = |a: usize, b: usize| kk[a].dot(&kk[b]);
        forms.push(SigmaForm([
            dot(0, 0),
            2.0 * dot(0, 1),
            2.0 * dot(0, 2),
            dot(1, 1),
            2.0 * dot(1, 2),
            dot(2, 2),
        ]));
        if progress(poses.len() + i + 1, total) == Control::Cancel {
            return None;
        }
    }
    Some(forms)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::engine::base::geometry::{isometry_from_twist, skew};
    use crate::engine::calibrate::handeye::Sighting;
    use nalgebra::Point3;

    /// The O(1) form equals the direct `tr(H·C·Hᵀ)` of each point, with
    /// `H` from the per-point sensitivity and an explicitly fitted rigid
    /// motion over all points.
    #[test]
    fn forms_match_the_direct_computation() {
        let robot = crate::engine::base::robot::irb2400().robot;
        let est = Estimate {
            robot,
            flange_from_sensor: isometry_from_twist(&[-7.4, -1.0, 287.8, 3.1, 0.02, 0.5]),
            mount: crate::engine::base::session::Mount::Flange,
        };
        // A covariance on the hand-eye and a few kinematic parameters.
        let unknowns = vec![0, 1, 2, 3, 4, 5, 6 + 7, 6 + 13, 6 + 18, 6 + 24];
        let k = unknowns.len();
        let a = DMatrix::from_fn(k, k, |i, j| ((i * 7 + j * 3) % 5) as f64 * 0.01 - 0.02);
        let matrix = &a * a.transpose() + DMatrix::identity(k, k) * 1e-4;
        let raw_per_file_unit = unknowns
            .iter()
            .map(|&u| {
                if crate::engine::calibrate::solve::estimate::unknown_is_angle(u) {
                    1.0_f64.to_radians()
                } else {
                    1.0
                }
            })
            .collect();
        let cov = ParameterCovariance {
            unknowns: unknowns.clone(),
            raw_per_file_unit,
            matrix: matrix.clone(),
        };
        let placements = [
            Placement::Joints(vec![12.5, 20.1, -3.4, 40.0, 35.2, -10.0]),
            Placement::Joints(vec![-20.0, 5.0, 10.0, -30.0, 60.0, 45.0]),
            Placement::Joints(vec![30.0, -10.0, 25.0, 10.0, -45.0, 90.0]),
        ];
        let points: Vec<Vec<[f64; 2]>> = vec![
            vec![[-10.0, 2.0], [0.0, -5.0], [15.0, 8.0]],
            vec![[30.0, 30.0], [-30.0, -20.0]],
            vec![[1.0, 1.0], [2.0, -3.0], [5.0, 5.0], [-40.0, 10.0]],
        ];
        let poses: Vec<SigmaPose> = placements
            .iter()
            .zip(&points)
            .map(|(pl, pts)| {
                let Placement::Joints(q) = pl else {
                    unreachable!()
                };
                SigmaPose {
                    placement: pl,
                    base_from_sensor: est.robot.base_from_flange(q) * est.flange_from_sensor,
                    moments: Moments::of(pts),
                }
            })
            .collect();
        let forms = sigma_forms(&est, &cov, &poses, &mut |_, _| Control::Continue).unwrap();
        // Direct: per point G (3 × k) and X, the rigid fit, H, tr(H C Hᵀ).
        let mut rows: Vec<(DMatrix<f64>, Vector3<f64>)> = Vec::new();
        for (pl, pts) in placements.iter().zip(&points) {
            let Placement::Joints(q) = pl else {
                unreachable!()
            };
            let s = Sighting {
                id: String::new(),
                joints: q.clone(),
                flange: None,
                centre_in_sensor: Vector3::zeros(),
            };
            let ps = PoseSensitivity::new(&est, &s);
            for &[y, z] in pts {
                let (x, a) = ps.at(&est, &Vector3::new(0.0, y, z));
                let g =
                    DMatrix::from_fn(3, k, |r, c| a[(r, unknowns[c])] * cov.raw_per_file_unit[c]);
                rows.push((g, x));
            }
        }
        let c = rows.iter().map(|(_, x)| x).sum::<Vector3<f64>>() / rows.len() as f64;
        let rigid = |x: &Vector3<f64>| {
            let mut r = DMatrix::zeros(3, 6);
            r.view_mut((0, 0), (3, 3)).copy_from(&Matrix3::identity());
            r.view_mut((0, 3), (3, 3)).copy_from(&(-skew(&(x - c))));
            r
        };
        let mut rtr = DMatrix::zeros(6, 6);
        let mut rtg = DMatrix::zeros(6, k);
        for (g, x) in &rows {
            let r = rigid(x);
            rtr += r.transpose() * &r;
            rtg += r.transpose() * g;
        }
        let m = rtr.try_inverse().unwrap() * rtg;
        let mut i = 0;
        for (form, pts) in forms.iter().zip(&points) {
            for &[y, z] in pts {
                let (g, x) = &rows[i];
                let h = g - rigid(x) * &m;
                let direct = (&h * &matrix * h.transpose()).trace();
                let fast = form.variance(y, z);
                assert!(
                    (direct - fast).abs() < 1e-9 * direct.max(1e-6),
                    "point {i}: {direct} vs {fast}"
                );
                i += 1;
            }
        }
        // The points themselves: X = t + y·r₂ + z·r₃ is the model.
        let t = poses[0].base_from_sensor;
        let x = (t * Point3::new(0.0, -10.0, 2.0)).coords;
        assert!((x - rows[0].1).norm() < 1e-9);
    }
}
