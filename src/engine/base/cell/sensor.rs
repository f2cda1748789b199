//! The sensor mount of the paper's cell (section 4.2): its calibrated and
//! initial hand-eye `eT_s` as printed, made rigid. The simulator's truth and
//! the planner's default hand-eye guess.

use nalgebra::{Isometry3, Matrix3};

use crate::engine::base::geometry::rigid_from_rows;
use crate::engine::base::numeric::round_to;

/// The paper's calibrated hand-eye `eT_s` (section 4.2), rows of the 3×4
/// block as printed (rotation to 4 decimals, not quite orthonormal; see
/// [`paper_hand_eye`]). Translation in mm.
pub const PAPER_HAND_EYE_ROWS: [[f64; 4]; 3] = [
    [0.8703, 0.4925, -0.0108, -7.442],
    [0.4921, -0.8702, -0.0227, -1.012],
    [-0.0205, 0.0144, -0.9997, 287.804],
];

/// The paper's *initial* hand-eye (section 4.2, from eq. 7 and 9), rows of
/// the 3×4 block as printed. Written into a session when
/// [`InitialHandEye::Paper`](crate::engine::tools::simulate::InitialHandEye::Paper) is chosen.
pub const PAPER_INITIAL_HAND_EYE_ROWS: [[f64; 4]; 3] = [
    [0.8704, 0.4921, -0.0133, -7.4422],
    [0.4917, -0.8704, -0.0235, -1.012],
    [-0.0231, 0.0139, -0.9996, 287.818],
];

/// Hand-eye matrices are written with this many decimals: 1e-12 keeps the
/// rotation orthonormal to ~1e-12, far inside FORMAT.md's 1e-6 check.
const HAND_EYE_DECIMALS: i32 = 12;

/// Rows of a printed 3×4 hand-eye, re-orthonormalised (nearest rotation)
/// and rounded to [`HAND_EYE_DECIMALS`].
pub(crate) fn orthonormal_rows(printed: &[[f64; 4]; 3]) -> [[f64; 4]; 4] {
    let r = Matrix3::from_fn(|i, j| printed[i][j]);
    let rotation = crate::engine::base::geometry::nearest_rotation(&r).to_rotation_matrix();
    let mut rows = [[0.0, 0.0, 0.0, 1.0]; 4];
    for i in 0..3 {
        for j in 0..3 {
            rows[i][j] = round_to(rotation[(i, j)], HAND_EYE_DECIMALS);
        }
        rows[i][3] = printed[i][3];
    }
    rows
}

/// The true hand-eye as 4×4 rows: the paper's calibrated `eT_s`
/// ([`PAPER_HAND_EYE_ROWS`]) with its rotation replaced by the nearest
/// rotation matrix, rounded to 12 decimals.
#[must_use]
pub fn paper_hand_eye_rows() -> [[f64; 4]; 4] {
    orthonormal_rows(&PAPER_HAND_EYE_ROWS)
}

/// The paper's calibrated hand-eye `flange_from_sensor` (mm), as used for
/// the truth (see [`paper_hand_eye_rows`]).
#[must_use]
pub fn paper_hand_eye() -> Isometry3<f64> {
    rigid_from_rows(&paper_hand_eye_rows())
}

/// The paper's initial hand-eye `flange_from_sensor` (mm), re-orthonormalised
/// like [`paper_hand_eye`].
#[must_use]
pub fn paper_initial_hand_eye() -> Isometry3<f64> {
    rigid_from_rows(&orthonormal_rows(&PAPER_INITIAL_HAND_EYE_ROWS))
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector3;

    use super::*;
    use crate::engine::base::geometry::isometry_from_rows;

    #[test]
    fn paper_hand_eye_is_orthonormal_and_close_to_print() {
        let rows = paper_hand_eye_rows();
        assert!(isometry_from_rows(&rows).is_ok());
        let r = Matrix3::from_fn(|i, j| rows[i][j]);
        assert!((r.transpose() * r - Matrix3::identity()).abs().max() < 1e-11);
        for i in 0..3 {
            for j in 0..4 {
                assert!(
                    (rows[i][j] - PAPER_HAND_EYE_ROWS[i][j]).abs() < 5e-4,
                    "{i},{j}"
                );
            }
        }
        // The independent simulator's truth (shared/examples) orthonormalised
        // the same print to these numbers.
        let example = [0.870272377859, 0.492452900999, -0.01077629963];
        for (a, b) in rows[0].iter().zip(example) {
            assert!((a - b).abs() < 1e-6, "{a} vs {b}");
        }
        let he = paper_hand_eye();
        assert!((he.translation.vector - Vector3::new(-7.442, -1.012, 287.804)).norm() < 1e-12);
        // Sensor z points back toward the flange.
        assert!((he.rotation * Vector3::z()).z < -0.99);
        assert!(isometry_from_rows(&orthonormal_rows(&PAPER_INITIAL_HAND_EYE_ROWS)).is_ok());
    }
}
