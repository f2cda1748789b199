//! A general initial hand-eye (beyond the paper) for any pose set, when
//! the cell has no group of pure translations (eq. 6-7 need one).
//!
//! Every sighting `i` of station `s` sees one fixed point: with the
//! flange pose `(R_i, p_i)` and the sphere centre `x_i` in the sensor
//! frame,
//!
//! ```text
//! R_i·(R_s·x_i + t_s) + p_i = c_s
//! ```
//!
//! which is linear in the nine entries of `R_s`, in `t_s` and in the
//! station centres `c_s`. The centres are eliminated (each is the mean of
//! its station's sightings, so every station's rows are centred), the 12
//! unknowns solved by least squares (truncated SVD, columns scaled), the
//! 3×3 block taken to the nearest rotation, and the rotation and
//! translation then refined together on the constraint itself
//! (Gauss-Newton with damping, `R_s ← R_s·exp([ω]×)`). `ml` refines the
//! result with everything else.
//!
//! The data determine the hand-eye only when the flange orientations
//! differ about at least two axes: with one orientation the translation
//! cannot be told from the sphere's position, with turns about one axis
//! the translation along it cannot. The covariance of the refined
//! estimate under [`ASSUMED_CENTRE_NOISE_MM`] names such a set
//! ([`HandEyeError::OrientationsSpanTooLittle`]) with its weakest
//! direction, instead of returning a hand-eye set by noise.

use nalgebra::{
    DMatrix, DVector, Isometry3, Matrix3, Matrix6, Rotation3, SVD, SymmetricEigen, Translation3,
    UnitQuaternion, Vector3, Vector6,
};

use super::HandEyeError;
use crate::engine::base::geometry::{polar_rotation, skew};
use crate::engine::base::numeric::MAX_DECOMPOSITION_SWEEPS;

/// Centre noise (mm, per coordinate) under which the conditioning is
/// judged: a line scanner's circle fit gives centres to a few hundredths
/// of a millimetre, robot poses add about a tenth.
pub const ASSUMED_CENTRE_NOISE_MM: f64 = 0.1;

/// Largest 1σ of the hand-eye translation (mm, its weakest direction)
/// under [`ASSUMED_CENTRE_NOISE_MM`] for the set to count as determining
/// it: beyond, the start is set by noise. Orientations turned by 1-2°
/// about a second axis reach it; a set turned about one axis only, or not
/// at all, is far beyond (singular).
pub const MAX_TRANSLATION_SIGMA_MM: f64 = 10.0;

/// Largest 1σ of the hand-eye rotation (deg, weakest axis), as
/// [`MAX_TRANSLATION_SIGMA_MM`]. A single sphere seen near one point of
/// the laser plane determines the rotation only weakly (a rotation error
/// is taken up by the translation there): a few degrees per 0.1 mm of
/// noise is a property of such data, which `ml` reports, not a degenerate
/// set.
pub const MAX_ROTATION_SIGMA_DEG: f64 = 10.0;

/// Gauss-Newton iterations of the refinement (converges in 3-6 from the
/// linear start).
const MAX_ITERATIONS: usize = 60;

/// One sighting for the general hand-eye.
#[derive(Debug, Clone, PartialEq)]
pub struct GeneralSighting {
    /// Measurement id, for messages.
    pub id: String,
    /// Index of its station (0-based, dense).
    pub station: usize,
    /// The flange pose `bT_e` (given, or nominal forward kinematics).
    pub base_from_flange: Isometry3<f64>,
    /// Sphere centre in the sensor frame, mm (with its side).
    pub centre_in_sensor: Vector3<f64>,
}

/// The general initial hand-eye and how well the data determined it.
#[derive(Debug, Clone, PartialEq)]
pub struct GeneralHandEye {
    /// `eT_s`: sensor to flange.
    pub flange_from_sensor: Isometry3<f64>,
    /// Each station's centre in the base frame, mm.
    pub centres_in_base: Vec<Vector3<f64>>,
    /// RMS 3-D distance of the sightings' base-frame centres from their
    /// station's centre, mm.
    pub rms_mm: f64,
    /// Largest angle between two flange orientations of one station, deg.
    pub orientation_span_deg: f64,
    /// 1σ of the translation along its weakest direction under
    /// [`ASSUMED_CENTRE_NOISE_MM`], mm, and that direction (sensor frame).
    pub weakest_translation: (f64, Vector3<f64>),
    /// 1σ of the rotation about its weakest axis under the same noise, deg.
    pub weakest_rotation_deg: f64,
}

/// Largest angle (deg) between two orientations of the same station (all
/// pairs up to 400 sightings a station, against the first beyond).
fn orientation_span(sightings: &[GeneralSighting], stations: usize) -> f64 {
    let mut span: f64 = 0.0;
    for s in 0..stations {
        let members: Vec<&UnitQuaternion<f64>> = sightings
            .iter()
            .filter(|g| g.station == s)
            .map(|g| &g.base_from_flange.rotation)
            .collect();
        let all_pairs = members.len() <= 400;
        for (i, a) in members.iter().enumerate() {
            let others = if all_pairs {
                &members[i + 1..]
            } else {
                &members[..1]
            };
            for b in others {
                span = span.max(a.angle_to(b).to_degrees());
            }
        }
    }
    span
}

/// Rows of one sighting centred by its station's mean: `(A_i, b_i)`.
fn centred<const N: usize>(
    sightings: &[GeneralSighting],
    stations: usize,
    rows: impl Fn(&GeneralSighting) -> ([[f64; N]; 3], [f64; 3]),
) -> (DMatrix<f64>, DVector<f64>) {
    let n = sightings.len();
    let mut a = DMatrix::zeros(3 * n, N);
    let mut b = DVector::zeros(3 * n);
    let mut mean_a = vec![[[0.0; N]; 3]; stations];
    let mut mean_b = vec![[0.0; 3]; stations];
    let mut count = vec![0.0; stations];
    let all: Vec<([[f64; N]; 3], [f64; 3])> = sightings.iter().map(&rows).collect();
    for (g, (ra, rb)) in sightings.iter().zip(&all) {
        count[g.station] += 1.0;
        for k in 0..3 {
            for c in 0..N {
                mean_a[g.station][k][c] += ra[k][c];
            }
            mean_b[g.station][k] += rb[k];
        }
    }
    for (i, (g, (ra, rb))) in sightings.iter().zip(&all).enumerate() {
        let m = count[g.station];
        for k in 0..3 {
            for c in 0..N {
                a[(3 * i + k, c)] = ra[k][c] - mean_a[g.station][k][c] / m;
            }
            b[3 * i + k] = rb[k] - mean_b[g.station][k] / m;
        }
    }
    (a, b)
}

/// The linear least-squares estimate of `(M, t_s)` (12 unknowns) with
/// the station centres eliminated; `None` when the system is empty.
fn linear(sightings: &[GeneralSighting], stations: usize) -> Option<(Matrix3<f64>, Vector3<f64>)> {
    let (mut a, b) = centred::<12>(sightings, stations, |g| {
        let r = g.base_from_flange.rotation.to_rotation_matrix();
        let r = r.matrix();
        let x = g.centre_in_sensor;
        let p = g.base_from_flange.translation.vector;
        let mut rows = [[0.0; 12]; 3];
        for (k, row) in rows.iter_mut().enumerate() {
            for j in 0..3 {
                for l in 0..3 {
                    row[3 * j + l] = r[(k, j)] * x[l];
                }
                row[9 + j] = r[(k, j)];
            }
        }
        (rows, [-p.x, -p.y, -p.z])
    });
    let scales: Vec<f64> = (0..12)
        .map(|c| a.column(c).norm())
        .map(|n| if n > 0.0 { n } else { 1.0 })
        .collect();
    for (c, s) in scales.iter().enumerate() {
        a.column_mut(c).scale_mut(1.0 / s);
    }
    let svd = SVD::try_new(a, true, true, f64::EPSILON, MAX_DECOMPOSITION_SWEEPS)?;
    let largest = svd.singular_values.max();
    let x = svd.solve(&b, largest * 1e-9).ok()?;
    let v: Vec<f64> = x.iter().zip(&scales).map(|(x, s)| x / s).collect();
    if v.iter().any(|x| !x.is_finite()) {
        return None;
    }
    let m = Matrix3::new(v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8]);
    Some((m, Vector3::new(v[9], v[10], v[11])))
}

/// The rotation whose y and z columns are nearest those of `m`, its x
/// column their cross product: for a set whose centres barely move off
/// the laser plane the x column of `m` is the weakly seen one.
fn rotation_from_plane_columns(m: &Matrix3<f64>) -> Option<Matrix3<f64>> {
    let y = m.column(1).into_owned();
    let z = m.column(2).into_owned();
    let x = y.cross(&z);
    if x.norm() < 1e-12 {
        return None;
    }
    polar_rotation(&Matrix3::from_columns(&[
        x.normalize() * (0.5 * (y.norm() + z.norm())),
        y,
        z,
    ]))
}

/// Centred residuals and Jacobian (6 columns: ω, t) at `(r_s, t_s)`.
fn linearise(
    sightings: &[GeneralSighting],
    stations: usize,
    r_s: &Matrix3<f64>,
    t_s: &Vector3<f64>,
) -> (DMatrix<f64>, DVector<f64>) {
    let (j, b) = centred::<6>(sightings, stations, |g| {
        let r = *g.base_from_flange.rotation.to_rotation_matrix().matrix();
        let x = g.centre_in_sensor;
        let p = g.base_from_flange.translation.vector;
        let d_omega = -r * r_s * skew(&x);
        let value = r * (r_s * x + t_s) + p;
        let mut rows = [[0.0; 6]; 3];
        for (k, row) in rows.iter_mut().enumerate() {
            for c in 0..3 {
                row[c] = d_omega[(k, c)];
                row[3 + c] = r[(k, c)];
            }
        }
        // Residual `value`, written as the "rhs" slot: centred the same way.
        (rows, [value.x, value.y, value.z])
    });
    (j, b)
}

/// Damped Gauss-Newton from `(r_s, t_s)`; returns the refined pair and
/// its residual sum of squares.
fn refine(
    sightings: &[GeneralSighting],
    stations: usize,
    mut r_s: Matrix3<f64>,
    mut t_s: Vector3<f64>,
) -> (Matrix3<f64>, Vector3<f64>, f64) {
    let (mut j, mut r) = linearise(sightings, stations, &r_s, &t_s);
    let mut cost = r.norm_squared();
    let mut lambda = 1e-6;
    for _ in 0..MAX_ITERATIONS {
        let jtj: Matrix6<f64> = (j.transpose() * &j).fixed_view::<6, 6>(0, 0).into_owned();
        let jtr: Vector6<f64> = (j.transpose() * &r).fixed_rows::<6>(0).into_owned();
        let mut improved = false;
        for _ in 0..12 {
            let mut damped = jtj;
            for k in 0..6 {
                damped[(k, k)] += lambda * jtj[(k, k)].max(1e-12);
            }
            let Some(chol) = damped.cholesky() else {
                lambda *= 10.0;
                continue;
            };
            let step = -chol.solve(&jtr);
            let omega = Vector3::new(step[0], step[1], step[2]);
            let r_new = r_s * Rotation3::new(omega).matrix();
            let t_new = t_s + Vector3::new(step[3], step[4], step[5]);
            let (j_new, res_new) = linearise(sightings, stations, &r_new, &t_new);
            let c = res_new.norm_squared();
            if c.is_finite() && c <= cost {
                let done = cost - c <= 1e-15 * cost.max(1e-30) || step.norm() < 1e-13;
                r_s = r_new;
                t_s = t_new;
                j = j_new;
                r = res_new;
                cost = c;
                lambda = (lambda * 0.1).max(1e-12);
                improved = !done;
                break;
            }
            lambda *= 10.0;
        }
        if !improved {
            break;
        }
    }
    (r_s, t_s, cost)
}

/// Why a set does not determine the hand-eye, from its orientation span.
fn why(span_deg: f64) -> String {
    if span_deg < 1.0 {
        "the flange orientations are all the same: the hand-eye translation cannot be told from the sphere's position".to_string()
    } else {
        "the flange orientations turn about one axis only, or too little: the hand-eye translation along it cannot be told from the sphere's position".to_string()
    }
}

/// The general initial hand-eye of `sightings` (with `stations` distinct
/// station indices `0..stations`).
///
/// # Errors
/// Too few sightings beyond one a station, numbers that are not finite,
/// or orientations that span too little to determine it (naming the span
/// and the weakest direction).
pub fn general_hand_eye(
    sightings: &[GeneralSighting],
    stations: usize,
) -> Result<GeneralHandEye, HandEyeError> {
    let ids: Vec<String> = sightings.iter().map(|s| s.id.clone()).collect();
    if sightings.len() < stations + 4 {
        return Err(HandEyeError::TooFewPoses {
            found: sightings.len(),
            stations,
            ids,
        });
    }
    if sightings.iter().any(|g| {
        !(g.centre_in_sensor.iter().all(|v| v.is_finite())
            && g.base_from_flange
                .translation
                .vector
                .iter()
                .all(|v| v.is_finite()))
    }) {
        return Err(HandEyeError::NonFinite);
    }
    let span = orientation_span(sightings, stations);
    let degenerate = |detail: String| HandEyeError::OrientationsSpanTooLittle {
        span_deg: span,
        detail,
    };
    let (m, t) = linear(sightings, stations)
        .ok_or_else(|| degenerate("the least-squares system could not be solved".to_string()))?;
    let mut best: Option<(Matrix3<f64>, Vector3<f64>, f64)> = None;
    for start in [polar_rotation(&m), rotation_from_plane_columns(&m)]
        .into_iter()
        .flatten()
    {
        let refined = refine(sightings, stations, start, t);
        if best.as_ref().is_none_or(|b| refined.2 < b.2) {
            best = Some(refined);
        }
    }
    let (r_s, t_s, cost) =
        best.ok_or_else(|| degenerate("no rotation fits the linear estimate".to_string()))?;
    // Conditioning under the assumed noise.
    let (j, _) = linearise(sightings, stations, &r_s, &t_s);
    let jtj: Matrix6<f64> = (j.transpose() * &j).fixed_view::<6, 6>(0, 0).into_owned();
    let covariance = jtj
        .try_inverse()
        .filter(|c| c.iter().all(|v| v.is_finite()))
        .ok_or_else(|| degenerate(why(span)))?;
    let noise2 = ASSUMED_CENTRE_NOISE_MM * ASSUMED_CENTRE_NOISE_MM;
    let c_tt: Matrix3<f64> = covariance.fixed_view::<3, 3>(3, 3).into_owned() * noise2;
    let c_ww: Matrix3<f64> = covariance.fixed_view::<3, 3>(0, 0).into_owned() * noise2;
    let eig_t = SymmetricEigen::try_new(c_tt, f64::EPSILON, MAX_DECOMPOSITION_SWEEPS)
        .ok_or(HandEyeError::NonFinite)?;
    let k = eig_t.eigenvalues.imax();
    let sigma_t = crate::engine::base::numeric::sigma_of_variance(eig_t.eigenvalues[k]);
    let direction_base = eig_t.eigenvectors.column(k).into_owned();
    let sigma_w = SymmetricEigen::try_new(c_ww, f64::EPSILON, MAX_DECOMPOSITION_SWEEPS)
        .ok_or(HandEyeError::NonFinite)?
        .eigenvalues
        .max()
        .max(0.0)
        .sqrt()
        .to_degrees();
    // t_s is in the flange frame; name the direction in the sensor frame.
    let direction = (r_s.transpose() * direction_base).normalize();
    if !(sigma_t <= MAX_TRANSLATION_SIGMA_MM && sigma_w <= MAX_ROTATION_SIGMA_DEG) {
        return Err(degenerate(format!(
            "{}; with {ASSUMED_CENTRE_NOISE_MM} mm of centre noise the hand-eye translation would be known to ±{} mm along ({:.2}, {:.2}, {:.2}) in the sensor frame and its rotation to ±{}° (limits {MAX_TRANSLATION_SIGMA_MM} mm, {MAX_ROTATION_SIGMA_DEG}°); turn the flange further, about at least two different axes",
            why(span),
            crate::engine::base::numeric::approx(sigma_t),
            direction.x,
            direction.y,
            direction.z,
            crate::engine::base::numeric::approx(sigma_w)
        )));
    }
    let rotation = crate::engine::base::geometry::nearest_rotation(&r_s);
    let flange_from_sensor = Isometry3::from_parts(Translation3::from(t_s), rotation);
    let mut sums = vec![Vector3::zeros(); stations];
    let mut counts = vec![0.0; stations];
    for g in sightings {
        let x =
            g.base_from_flange * flange_from_sensor * nalgebra::Point3::from(g.centre_in_sensor);
        sums[g.station] += x.coords;
        counts[g.station] += 1.0;
    }
    let centres_in_base = sums
        .iter()
        .zip(&counts)
        .map(|(s, c)| if *c > 0.0 { s / *c } else { *s })
        .collect();
    let rms_mm = (cost / sightings.len() as f64).sqrt();
    Ok(GeneralHandEye {
        flange_from_sensor,
        centres_in_base,
        rms_mm,
        orientation_span_deg: span,
        weakest_translation: (sigma_t, direction),
        weakest_rotation_deg: sigma_w,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::base::geometry::isometry_from_twist;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn hand_eye() -> Isometry3<f64> {
        isometry_from_twist(&[-7.4, -1.0, 287.8, 0.02, -0.03, 0.5])
            * crate::engine::base::geometry::rot_x(std::f64::consts::PI)
    }

    /// Sightings of one sphere at `centre` from flange orientations turned
    /// up to `span_deg` about random axes, each pose placed so the sphere
    /// lies near `(±10, y, z)` in the sensor frame.
    fn sightings(n: usize, span_deg: f64, noise: f64, seed: u64) -> Vec<GeneralSighting> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let he = hand_eye();
        let centre = Vector3::new(1000.0, 50.0, 400.0);
        let base = UnitQuaternion::from_euler_angles(std::f64::consts::PI, 0.0, 0.3);
        (0..n)
            .map(|i| {
                let axis = Vector3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                );
                let angle = (span_deg / 2.0).to_radians() * rng.random_range(-1.0..1.0);
                let rotation = UnitQuaternion::from_scaled_axis(axis.normalize() * angle) * base;
                let x_s = Vector3::new(
                    if i % 2 == 0 { 12.0 } else { -9.0 } + rng.random_range(-3.0..3.0),
                    rng.random_range(-10.0..10.0),
                    rng.random_range(-10.0..10.0),
                );
                // Place the flange so that the sensor sees the centre at x_s.
                let sensor_rotation = rotation * he.rotation;
                let sensor_origin = centre - sensor_rotation * x_s;
                let flange_origin = sensor_origin - rotation * he.translation.vector;
                let pose = Isometry3::from_parts(Translation3::from(flange_origin), rotation);
                let jitter = Vector3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                ) * noise;
                GeneralSighting {
                    id: format!("p{i}"),
                    station: 0,
                    base_from_flange: pose,
                    centre_in_sensor: x_s + jitter,
                }
            })
            .collect()
    }

    #[test]
    fn exact_without_noise() {
        let g = general_hand_eye(&sightings(8, 40.0, 0.0, 1), 1).unwrap();
        let he = hand_eye();
        assert!((g.flange_from_sensor.translation.vector - he.translation.vector).norm() < 1e-6);
        assert!(g.flange_from_sensor.rotation.angle_to(&he.rotation) < 1e-9);
        assert!(g.rms_mm < 1e-6);
        assert!((g.centres_in_base[0] - Vector3::new(1000.0, 50.0, 400.0)).norm() < 1e-6);
    }

    #[test]
    fn close_with_noise_and_refused_when_degenerate() {
        for seed in 1..=5 {
            let g = general_hand_eye(&sightings(8, 30.0, 0.05, seed), 1).unwrap();
            let he = hand_eye();
            let dt = (g.flange_from_sensor.translation.vector - he.translation.vector).norm();
            let dr = g
                .flange_from_sensor
                .rotation
                .angle_to(&he.rotation)
                .to_degrees();
            assert!(dt < 1.0 && dr < 0.5, "seed {seed}: {dt} mm, {dr}°");
        }
        let flat = sightings(8, 0.0, 0.0, 2);
        let e = general_hand_eye(&flat, 1).unwrap_err().to_string();
        assert!(e.contains("all the same"), "{e}");
        let e = general_hand_eye(&sightings(3, 30.0, 0.0, 2), 1)
            .unwrap_err()
            .to_string();
        assert!(e.contains('3'), "{e}");
    }
}
