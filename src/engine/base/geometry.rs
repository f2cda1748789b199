//! Rigid-transform helpers shared by the engine: 4×4 matrices of the file
//! formats to and from [`Isometry3`], the paper's differential-motion
//! vectors (twists), the skew matrix, and Kabsch's best rotation and
//! rigid motion.
//!
//! A twist here is the paper's 6-vector `[Δx, Δy, Δz, δx, δy, δz]`
//! (translation first, mm; then rotation, rad): a point `X` moves by
//! `Δ + δ × X` (paper eq. 13-16).

use nalgebra::{
    Isometry3, Matrix3, Matrix3x6, Matrix4, Rotation3, Translation3, UnitQuaternion, Vector3,
};

/// Tolerance on `RᵀR = I` and `det R = 1` when a 4×4 matrix is read from a
/// file (FORMAT.md: "checked to 1e-6 on load"). Files are written with ~12
/// significant digits, far tighter than this.
pub const ROTATION_TOLERANCE: f64 = 1e-6;

/// Why a 4×4 matrix is not a rigid transform.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MatrixError {
    /// A number is NaN or infinite.
    #[error("contains a non-finite number")]
    NotFinite,
    /// The last row is not `[0, 0, 0, 1]`.
    #[error("last row must be [0, 0, 0, 1], found [{0}, {1}, {2}, {3}]")]
    LastRow(f64, f64, f64, f64),
    /// The 3×3 block is not orthonormal.
    #[error("3x3 block is not orthonormal (|RᵀR − I| = {0:.3e}, tolerance {1:e})")]
    NotOrthonormal(f64, f64),
    /// The 3×3 block is a reflection.
    #[error("3x3 block has determinant {0:.6}, not +1 (a reflection)")]
    Reflection(f64),
}

/// Converts a row-major 4×4 homogeneous matrix (file form) to an isometry,
/// checking the last row and that the 3×3 block is a proper rotation to
/// [`ROTATION_TOLERANCE`]. The rotation is re-orthonormalised.
///
/// # Errors
/// [`MatrixError`] naming the broken property.
pub fn isometry_from_rows(rows: &[[f64; 4]; 4]) -> Result<Isometry3<f64>, MatrixError> {
    isometry_from_rows_within(rows, ROTATION_TOLERANCE).map(|(iso, _)| iso)
}

/// Largest |RᵀR − I| of a 4×4 typed by a person (a hand-eye guess, a
/// workpiece frame, a tool) that is re-orthonormalised rather than
/// refused: a rotation written to 4 decimals is off by up to ~1e-4.
pub const TYPED_ROTATION_TOLERANCE: f64 = 1e-3;

/// [`isometry_from_rows`] with the rotation checked to `tolerance`; also
/// returns how far from orthonormal the 3×3 block was (|RᵀR − I|), which
/// the re-orthonormalisation removed.
///
/// # Errors
/// [`MatrixError`] naming the broken property.
pub fn isometry_from_rows_within(
    rows: &[[f64; 4]; 4],
    tolerance: f64,
) -> Result<(Isometry3<f64>, f64), MatrixError> {
    if rows.iter().flatten().any(|v| !v.is_finite()) {
        return Err(MatrixError::NotFinite);
    }
    let last = rows[3];
    if last[0].abs() > ROTATION_TOLERANCE
        || last[1].abs() > ROTATION_TOLERANCE
        || last[2].abs() > ROTATION_TOLERANCE
        || (last[3] - 1.0).abs() > ROTATION_TOLERANCE
    {
        return Err(MatrixError::LastRow(last[0], last[1], last[2], last[3]));
    }
    let r = Matrix3::from_fn(|i, j| rows[i][j]);
    let off = (r.transpose() * r - Matrix3::identity()).abs().max();
    if off > tolerance {
        return Err(MatrixError::NotOrthonormal(off, tolerance));
    }
    let det = r.determinant();
    if (det - 1.0).abs() > tolerance {
        return Err(MatrixError::Reflection(det));
    }
    let rotation = nearest_rotation(&r);
    Ok((
        Isometry3::from_parts(
            Translation3::new(rows[0][3], rows[1][3], rows[2][3]),
            rotation,
        ),
        off,
    ))
}

/// The row-major 4×4 homogeneous matrix of an isometry (file form).
#[must_use]
pub fn rows_from_isometry(iso: &Isometry3<f64>) -> [[f64; 4]; 4] {
    let m: Matrix4<f64> = iso.to_homogeneous();
    let mut rows = [[0.0; 4]; 4];
    for (i, row) in rows.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = m[(i, j)];
        }
    }
    rows[3] = [0.0, 0.0, 0.0, 1.0];
    rows
}

/// The skew-symmetric matrix `[v]×` with `[v]× w = v × w`.
#[must_use]
pub fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// `[I | −[x]×]` (3 × 6): the first-order motion `Δ + δ × x` of the
/// point `x` under a small twist `[Δ; δ]` (module doc): the paper's `Q_i`
/// (eq. 16), and the rows of the rigid motion an aligned σ takes out.
#[must_use]
pub fn twist_rows(x: &Vector3<f64>) -> Matrix3x6<f64> {
    let mut q = Matrix3x6::zeros();
    q.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&Matrix3::identity());
    q.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-skew(x)));
    q
}

/// The rigid motion `exp(twist)`: rotation by the rotation vector
/// `[δx, δy, δz]` (rad) and translation `[Δx, Δy, Δz]` (mm), composed as
/// translation after rotation. To first order it moves `X` by `Δ + δ × X`.
#[must_use]
pub fn isometry_from_twist(twist: &[f64; 6]) -> Isometry3<f64> {
    let rotation = UnitQuaternion::from_scaled_axis(Vector3::new(twist[3], twist[4], twist[5]));
    Isometry3::from_parts(Translation3::new(twist[0], twist[1], twist[2]), rotation)
}

/// Rotation about the x axis by `angle` (rad).
#[must_use]
pub fn rot_x(angle: f64) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::identity(),
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_axis_angle(
            &Vector3::x_axis(),
            angle,
        )),
    )
}

/// Rotation about the y axis by `angle` (rad).
#[must_use]
pub fn rot_y(angle: f64) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::identity(),
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_axis_angle(
            &Vector3::y_axis(),
            angle,
        )),
    )
}

/// Rotation about the z axis by `angle` (rad).
#[must_use]
pub fn rot_z(angle: f64) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::identity(),
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_axis_angle(
            &Vector3::z_axis(),
            angle,
        )),
    )
}

/// Translation by `(x, y, z)` mm.
#[must_use]
pub fn trans(x: f64, y: f64, z: f64) -> Isometry3<f64> {
    Isometry3::translation(x, y, z)
}

/// The angle (rad) of the relative rotation between two isometries.
#[must_use]
pub fn rotation_angle_between(a: &Isometry3<f64>, b: &Isometry3<f64>) -> f64 {
    a.rotation.angle_to(&b.rotation)
}

/// `v` (deg) moved by whole turns into (−180, 180].
#[must_use]
pub fn wrap_deg(v: f64) -> f64 {
    let w = v - 360.0 * (v / 360.0).round();
    if w <= -180.0 { w + 360.0 } else { w }
}

/// A rigid transform from 4×4 rows, taking the nearest rotation of the 3×3
/// block. For rows that pass [`isometry_from_rows`] the result is identical
/// to it (same conversion); it never fails, so accessors need no `Result`.
#[must_use]
pub fn rigid_from_rows(rows: &[[f64; 4]; 4]) -> Isometry3<f64> {
    let r = Matrix3::from_fn(|i, j| rows[i][j]);
    Isometry3::from_parts(
        Translation3::new(rows[0][3], rows[1][3], rows[2][3]),
        nearest_rotation(&r),
    )
}

/// The rotation nearest `m` (Müller et al.'s iteration, nalgebra's
/// `from_matrix`), its iterations bounded by
/// [`MAX_DECOMPOSITION_SWEEPS`](crate::engine::base::numeric::MAX_DECOMPOSITION_SWEEPS):
/// nalgebra's own loops until convergence, which a NaN or an overflowed
/// matrix never reaches (an import with a centre of 1e308 ran without end).
#[must_use]
pub fn nearest_rotation(m: &Matrix3<f64>) -> UnitQuaternion<f64> {
    UnitQuaternion::from_matrix_eps(
        m,
        f64::EPSILON,
        crate::engine::base::numeric::MAX_DECOMPOSITION_SWEEPS,
        UnitQuaternion::identity(),
    )
}

/// Roll, pitch and yaw (deg) of a rotation, the one convention of the
/// crate (see the crate's "Conventions"): fixed-axis x-y-z,
/// `R = Rz(yaw) · Ry(pitch) · Rx(roll)`, pitch in [−90°, 90°].
#[must_use]
pub fn roll_pitch_yaw_deg(rotation: &UnitQuaternion<f64>) -> [f64; 3] {
    let (r, p, y) = rotation.euler_angles();
    [r.to_degrees(), p.to_degrees(), y.to_degrees()]
}

/// The rotation of roll, pitch and yaw (deg), [`roll_pitch_yaw_deg`]'s
/// convention.
#[must_use]
pub fn rotation_from_rpy_deg(rpy_deg: [f64; 3]) -> UnitQuaternion<f64> {
    let [r, p, y] = rpy_deg.map(f64::to_radians);
    UnitQuaternion::from_euler_angles(r, p, y)
}

/// The rotation nearest `m` by its SVD `m = U·S·Vᵀ` (the polar
/// decomposition, determinant forced to +1): `U·diag(1, 1, ±1)·Vᵀ`. The
/// one SVD of Kabsch's problem in the crate: [`kabsch_rotation`] and the
/// general hand-eye's start use it. `None` for a matrix that is not
/// finite or a failed SVD.
#[must_use]
pub fn polar_rotation(m: &Matrix3<f64>) -> Option<Matrix3<f64>> {
    if m.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let svd = nalgebra::linalg::SVD::try_new(
        *m,
        true,
        true,
        f64::EPSILON,
        crate::engine::base::numeric::MAX_DECOMPOSITION_SWEEPS,
    )?;
    let (u, v_t) = (svd.u?, svd.v_t?);
    let d = (u * v_t).determinant().signum();
    let fix = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, d));
    Some(u * fix * v_t)
}

/// The proper rotation `R` minimising `Σ |R·a_k − b_k|²` given the
/// cross-covariance `m = Σ a_k·b_kᵀ` (Kabsch; the paper's eq. 7 with the
/// determinant forced to +1): `R = V·diag(1, 1, det(V·Uᵀ))·Uᵀ` from the
/// SVD `m = U·S·Vᵀ`, the transpose of [`polar_rotation`]`(m)`, taken to
/// the nearest rotation (Müller et al.'s iteration, bounded as in
/// [`nearest_rotation`]) so that rounding leaves no scale. `None` for a
/// failed SVD or a matrix that is not finite. The one Kabsch of the
/// crate: the initial hand-eye (eq. 7) and [`kabsch`] call it.
#[must_use]
pub fn kabsch_rotation(m: &Matrix3<f64>) -> Option<Rotation3<f64>> {
    let r = polar_rotation(m)?.transpose();
    Some(Rotation3::from_matrix_eps(
        &r,
        f64::EPSILON,
        crate::engine::base::numeric::MAX_DECOMPOSITION_SWEEPS,
        Rotation3::identity(),
    ))
}

/// The rigid motion `T` that best maps `from` onto `to` in least squares
/// (Kabsch: centroids, then [`kabsch_rotation`] of the cross-covariance,
/// reflection excluded). `None` for fewer than 3 pairs, unequal lengths or
/// a failed SVD.
#[must_use]
pub fn kabsch(from: &[Vector3<f64>], to: &[Vector3<f64>]) -> Option<Isometry3<f64>> {
    if from.len() != to.len() || from.len() < 3 {
        return None;
    }
    let n = from.len() as f64;
    let cf = from.iter().sum::<Vector3<f64>>() / n;
    let ct = to.iter().sum::<Vector3<f64>>() / n;
    let mut h = Matrix3::zeros();
    for (f, t) in from.iter().zip(to) {
        h += (f - cf) * (t - ct).transpose();
    }
    let r = kabsch_rotation(&h)?;
    let t = ct - r * cf;
    Some(Isometry3::from_parts(
        Translation3::from(t),
        UnitQuaternion::from_rotation_matrix(&r),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 31: nalgebra's nearest rotation loops until convergence, which
    /// a matrix of NaN or 1e308 never reaches (an import hung on it).
    #[test]
    fn the_nearest_rotation_of_a_matrix_beyond_reason_ends() {
        for bad in [f64::NAN, 1e308, f64::INFINITY] {
            let m = Matrix3::new(bad, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);
            let started = std::time::Instant::now();
            let _ = nearest_rotation(&m);
            let kabsch = kabsch_rotation(&m);
            assert!(bad.is_finite() || kabsch.is_none());
            assert!(started.elapsed().as_secs_f64() < 5.0, "{bad}");
        }
        let r = UnitQuaternion::from_euler_angles(0.1, -0.2, 0.3);
        let m = r.to_rotation_matrix().into_inner() * 1.000_001;
        assert!(nearest_rotation(&m).angle_to(&r) < 1e-9);
    }

    #[test]
    fn kabsch_recovers_a_rigid_motion() {
        let motion = isometry_from_twist(&[10.0, -5.0, 2.0, 0.3, -0.1, 0.7]);
        let from: Vec<Vector3<f64>> = [
            [0.0, 0.0, 0.0],
            [100.0, 0.0, 0.0],
            [0.0, 50.0, 0.0],
            [0.0, 0.0, 30.0],
            [20.0, -40.0, 10.0],
        ]
        .iter()
        .map(|p| Vector3::from(*p))
        .collect();
        let to: Vec<Vector3<f64>> = from
            .iter()
            .map(|p| (motion * nalgebra::Point3::from(*p)).coords)
            .collect();
        let found = kabsch(&from, &to).unwrap();
        assert!(
            (found.to_homogeneous() - motion.to_homogeneous())
                .abs()
                .max()
                < 1e-9
        );
        assert!(kabsch(&from[..2], &to[..2]).is_none());
    }

    #[test]
    fn rows_round_trip() {
        let iso = isometry_from_twist(&[1.0, -2.0, 3.0, 0.1, -0.2, 0.3]);
        let rows = rows_from_isometry(&iso);
        let back = isometry_from_rows(&rows).unwrap();
        assert!((back.to_homogeneous() - iso.to_homogeneous()).abs().max() < 1e-12);
    }

    #[test]
    fn rejects_reflection_and_skew() {
        let mut rows = rows_from_isometry(&Isometry3::identity());
        rows[0][0] = -1.0;
        assert!(matches!(
            isometry_from_rows(&rows),
            Err(MatrixError::Reflection(_))
        ));
        let mut rows = rows_from_isometry(&Isometry3::identity());
        rows[0][1] = 0.01;
        assert!(matches!(
            isometry_from_rows(&rows),
            Err(MatrixError::NotOrthonormal(..))
        ));
        let mut rows = rows_from_isometry(&Isometry3::identity());
        rows[3][0] = 1.0;
        assert!(matches!(
            isometry_from_rows(&rows),
            Err(MatrixError::LastRow(..))
        ));
    }

    #[test]
    fn skew_is_cross_product() {
        let v = Vector3::new(1.0, 2.0, 3.0);
        let w = Vector3::new(-0.5, 4.0, 0.25);
        assert!((skew(&v) * w - v.cross(&w)).norm() < 1e-14);
    }

    #[test]
    fn wraps_to_half_open_turn() {
        assert_eq!(wrap_deg(190.0), -170.0);
        assert_eq!(wrap_deg(-180.0), 180.0);
        assert_eq!(wrap_deg(540.0), 180.0);
        assert!((wrap_deg(-725.0) - -5.0).abs() < 1e-12);
    }

    #[test]
    fn angle_changes_wrap_across_180() {
        assert!((wrap_deg(358.9) - (-1.1)).abs() < 1e-9);
        assert!((wrap_deg(-359.0) - 1.0).abs() < 1e-9);
        assert!((wrap_deg(0.25) - 0.25).abs() < 1e-12);
        assert_eq!(wrap_deg(180.0), 180.0);
        assert_eq!(wrap_deg(-180.0), 180.0);
    }
}
