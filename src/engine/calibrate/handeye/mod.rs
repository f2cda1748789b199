//! The initial hand-eye `eT_s` (paper section 3.1, eq. 3-9).
//!
//! Every measurement sees one fixed sphere centre `X_b`:
//! `X_b = R0·Rs·X_s + R0·Ts + T0` (eq. 3), with `(R0, T0)` the flange pose
//! from the **nominal** model and `(Rs, Ts)` the hand-eye.
//!
//! - Pure translations (`R0` constant) give `Rs·(X_s1 − X_sk) = R0ᵀ(T0k − T01)`
//!   (eq. 6), solved for a proper rotation by SVD (eq. 7, with the
//!   determinant fixed to +1).
//! - Orientation changes give `(R0j − R0i)·Ts = R0i·Rs·X_si − R0j·Rs·X_sj + T0i − T0j`
//!   (eq. 8), stacked over all pairs `i < j` and solved by least squares (eq. 9).
//!
//! Degenerate sets are detected before solving and reported with the ids.
//!
//! Beyond the paper, [`general`] solves the fixed-sphere constraint for
//! any pose set at once, for cells that publish no pure translations.

pub mod general;

use nalgebra::{DMatrix, DVector, Isometry3, Matrix3, SVD, Translation3, UnitQuaternion, Vector3};

use crate::engine::base::geometry::kabsch_rotation;
use crate::engine::base::numeric::MAX_DECOMPOSITION_SWEEPS;

use crate::engine::base::robot::Robot;

/// The initial hand-eye (paper 3.1) cannot be determined from the data.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HandEyeError {
    /// Fewer translation measurements than eq. 6-7 need.
    #[error(
        "the initial rotation (eq. 6-7) needs at least 3 translation measurements, the session has {found}{}",
        list_ids(ids)
    )]
    TooFewTranslations {
        /// Measurements found.
        found: usize,
        /// Their ids.
        ids: Vec<String>,
    },
    /// Translation displacements do not span a plane.
    #[error("the translation displacements of {} are collinear (second singular value {ratio:.2e} of the first): the rotation about their common direction is undetermined; move the robot in two different directions", ids.join(", "))]
    CollinearTranslations {
        /// Measurement ids involved.
        ids: Vec<String>,
        /// σ2/σ1 of the displacement matrix.
        ratio: f64,
    },
    /// Fewer rotation measurements than eq. 8-9 need.
    #[error(
        "the initial translation (eq. 8-9) needs at least 2 rotation measurements, the session has {found}{}",
        list_ids(ids)
    )]
    TooFewRotations {
        /// Measurements found.
        found: usize,
        /// Their ids.
        ids: Vec<String>,
    },
    /// Orientations do not differ enough (or only about one axis).
    #[error("the orientations of rotation measurements {} do not determine the translation (eq. 8-9): {detail}", ids.join(", "))]
    RotationsTooSimilar {
        /// Measurement ids involved.
        ids: Vec<String>,
        /// What was measured.
        detail: String,
    },
    /// Translation or rotation measurements span more than one station.
    #[error("all {usage} measurements must share one station, found stations {}", stations.join(", "))]
    MixedStations {
        /// "translation" or "rotation".
        usage: &'static str,
        /// The stations found.
        stations: Vec<String>,
    },
    /// Too few sightings for the general hand-eye ([`general`]): it needs
    /// 4 more than the stations it sees.
    #[error(
        "the general initial hand-eye needs at least 4 poses more than stations: {found} poses of {stations} station(s){}",
        list_ids(ids)
    )]
    TooFewPoses {
        /// Sightings given.
        found: usize,
        /// Stations they see.
        stations: usize,
        /// Their ids.
        ids: Vec<String>,
    },
    /// The flange orientations do not determine the hand-eye ([`general`]).
    #[error(
        "the flange orientations span too little to determine the hand-eye (largest difference {span_deg:.1}°): {detail}"
    )]
    OrientationsSpanTooLittle {
        /// Largest angle between two orientations of one station, deg.
        span_deg: f64,
        /// What is undetermined, and what to do.
        detail: String,
    },
    /// The poses or centres give numbers that are not finite (far beyond
    /// any cell's size): no hand-eye can be computed.
    #[error(
        "the translation and rotation measurements give numbers that are not finite: check their poses and centres"
    )]
    NonFinite,
}

fn list_ids(ids: &[String]) -> String {
    if ids.is_empty() {
        String::new()
    } else {
        format!(" ({})", ids.join(", "))
    }
}

/// Smallest ratio σ₂/σ₁ of the translation-displacement matrix accepted as
/// "not collinear". Displacements of 15-20 mm in different directions give
/// 0.5-1; sensor noise of ~0.02 mm on a 20 mm move is 1e-3. Below 0.05 the
/// rotation about the common direction is set by noise.
pub const MIN_TRANSLATION_SPREAD: f64 = 0.05;

/// Smallest relative rotation (deg) between two rotation measurements for
/// the pair to count. Eq. 8 divides the position noise by `|R0j − R0i|`
/// ≈ 2·sin(angle/2): below 5° a 0.05 mm centre error becomes ~0.6 mm.
pub const MIN_ROTATION_DEG: f64 = 5.0;

/// Smallest accepted σ_min/σ_max of the stacked eq. 8 matrix. Rotations
/// about a single axis leave `Ts` along that axis undetermined (σ_min → 0).
pub const MIN_ROTATION_CONDITION: f64 = 0.02;

/// One sighting of the fixed sphere for the initial hand-eye.
#[derive(Debug, Clone, PartialEq)]
pub struct Sighting {
    /// Measurement id (for messages).
    pub id: String,
    /// Joint readings, deg (empty when `flange` is given).
    pub joints: Vec<f64>,
    /// The flange pose as the controller reported it (a pose-only
    /// measurement), used instead of forward kinematics of `joints`.
    pub flange: Option<Isometry3<f64>>,
    /// Sphere centre in the sensor frame, mm.
    pub centre_in_sensor: Vector3<f64>,
}

impl Sighting {
    /// The flange pose `bT_e`: the given pose, else `robot`'s forward
    /// kinematics of the joint readings.
    #[must_use]
    pub fn base_from_flange(&self, robot: &Robot) -> Isometry3<f64> {
        self.flange
            .unwrap_or_else(|| robot.base_from_flange(&self.joints))
    }
}

/// The initial hand-eye and how well the data determined it.
#[derive(Debug, Clone, PartialEq)]
pub struct InitialHandEye {
    /// `eT_s`: sensor to flange.
    pub flange_from_sensor: Isometry3<f64>,
    /// RMS residual of eq. 6 after the fit, mm.
    pub rotation_residual: f64,
    /// RMS residual of eq. 8 after the fit, mm.
    pub translation_residual: f64,
    /// σ₂/σ₁ of the translation displacements (collinearity measure).
    pub translation_spread: f64,
    /// σ_min/σ_max of the stacked eq. 8 matrix.
    pub rotation_condition: f64,
    /// Largest flange orientation change among the translations, deg
    /// (ideally 0; a taught "pure translation" drifts a little).
    pub translation_orientation_drift_deg: f64,
}

/// Eq. 6-7: the hand-eye rotation from pure-translation sightings.
///
/// # Errors
/// Fewer than 3 sightings, or displacements that are collinear.
pub fn initial_rotation(
    robot: &Robot,
    translations: &[Sighting],
) -> Result<(UnitQuaternion<f64>, f64, f64, f64), HandEyeError> {
    let ids: Vec<String> = translations.iter().map(|s| s.id.clone()).collect();
    if translations.len() < 3 {
        return Err(HandEyeError::TooFewTranslations {
            found: translations.len(),
            ids,
        });
    }
    let poses: Vec<Isometry3<f64>> = translations
        .iter()
        .map(|s| s.base_from_flange(robot))
        .collect();
    let first = &poses[0];
    let drift = poses
        .iter()
        .map(|p| p.rotation.angle_to(&first.rotation).to_degrees())
        .fold(0.0, f64::max);
    let r0t = first.rotation.inverse();
    let n = translations.len() - 1;
    // A: sensor-frame displacements; B: flange-frame robot displacements.
    let mut a = DMatrix::zeros(3, n);
    let mut b = DMatrix::zeros(3, n);
    for k in 1..translations.len() {
        let ds = translations[0].centre_in_sensor - translations[k].centre_in_sensor;
        let dt = r0t * (poses[k].translation.vector - first.translation.vector);
        a.set_column(k - 1, &ds);
        b.set_column(k - 1, &dt);
    }
    let spread = {
        let sv = SVD::try_new(
            b.clone(),
            false,
            false,
            f64::EPSILON,
            MAX_DECOMPOSITION_SWEEPS,
        )
        .map(|d| d.singular_values)
        .ok_or(HandEyeError::NonFinite)?;
        let mut s: Vec<f64> = sv.iter().copied().collect();
        s.sort_by(|x, y| y.total_cmp(x));
        if s.len() < 2 || s[0] <= 0.0 {
            0.0
        } else {
            s[1] / s[0]
        }
    };
    if spread < MIN_TRANSLATION_SPREAD {
        return Err(HandEyeError::CollinearTranslations { ids, ratio: spread });
    }
    // Eq. 7: Rs = V·Uᵀ with A·Bᵀ = U·S·Vᵀ, reflection removed.
    let m: Matrix3<f64> = (&a * b.transpose()).fixed_view::<3, 3>(0, 0).into_owned();
    let rotation = kabsch_rotation(&m).map_or_else(UnitQuaternion::identity, |r| {
        UnitQuaternion::from_rotation_matrix(&r)
    });
    let residual = {
        let mut sum = 0.0;
        for k in 0..n {
            let ak: Vector3<f64> = a.fixed_view::<3, 1>(0, k).into_owned();
            let bk: Vector3<f64> = b.fixed_view::<3, 1>(0, k).into_owned();
            sum += (rotation * ak - bk).norm_squared();
        }
        (sum / n as f64).sqrt()
    };
    Ok((rotation, residual, spread, drift))
}

/// Eq. 8-9: the hand-eye translation from orientation-changing sightings,
/// given the rotation.
///
/// # Errors
/// Fewer than 2 sightings, or orientations that do not determine `Ts`.
pub fn initial_translation(
    robot: &Robot,
    rotation: &UnitQuaternion<f64>,
    rotations: &[Sighting],
) -> Result<(Vector3<f64>, f64, f64), HandEyeError> {
    let ids: Vec<String> = rotations.iter().map(|s| s.id.clone()).collect();
    if rotations.len() < 2 {
        return Err(HandEyeError::TooFewRotations {
            found: rotations.len(),
            ids,
        });
    }
    let poses: Vec<Isometry3<f64>> = rotations
        .iter()
        .map(|s| s.base_from_flange(robot))
        .collect();
    let rs = rotation.to_rotation_matrix();
    let mut rows_a: Vec<Matrix3<f64>> = Vec::new();
    let mut rows_b: Vec<Vector3<f64>> = Vec::new();
    let mut largest = 0.0_f64;
    for i in 0..rotations.len() {
        for j in i + 1..rotations.len() {
            let angle = poses[i].rotation.angle_to(&poses[j].rotation).to_degrees();
            largest = largest.max(angle);
            if angle < MIN_ROTATION_DEG {
                continue;
            }
            let r0i = poses[i].rotation.to_rotation_matrix();
            let r0j = poses[j].rotation.to_rotation_matrix();
            rows_a.push(r0j.matrix() - r0i.matrix());
            rows_b.push(
                r0i * (rs * rotations[i].centre_in_sensor)
                    - r0j * (rs * rotations[j].centre_in_sensor)
                    + poses[i].translation.vector
                    - poses[j].translation.vector,
            );
        }
    }
    if rows_a.is_empty() {
        return Err(HandEyeError::RotationsTooSimilar {
            ids,
            detail: format!(
                "the largest orientation change between two of them is {largest:.2}°, at least {MIN_ROTATION_DEG}° is needed"
            ),
        });
    }
    let m = rows_a.len();
    let mut a = DMatrix::zeros(3 * m, 3);
    let mut b = DVector::zeros(3 * m);
    for (k, (ak, bk)) in rows_a.iter().zip(&rows_b).enumerate() {
        a.fixed_view_mut::<3, 3>(3 * k, 0).copy_from(ak);
        b.fixed_rows_mut::<3>(3 * k).copy_from(bk);
    }
    let svd = SVD::try_new(
        a.clone(),
        true,
        true,
        f64::EPSILON,
        MAX_DECOMPOSITION_SWEEPS,
    )
    .ok_or(HandEyeError::NonFinite)?;
    let sv = &svd.singular_values;
    let (smax, smin) = (sv.max(), sv.min());
    let condition = if smax > 0.0 { smin / smax } else { 0.0 };
    if condition < MIN_ROTATION_CONDITION {
        return Err(HandEyeError::RotationsTooSimilar {
            ids,
            detail: format!(
                "their rotation axes are (nearly) parallel: σ_min/σ_max = {condition:.3e} < {MIN_ROTATION_CONDITION}; rotate about at least two different axes"
            ),
        });
    }
    let ts = svd
        .solve(&b, 0.0)
        .map_err(|e| HandEyeError::RotationsTooSimilar {
            ids: ids.clone(),
            detail: format!("least squares failed: {e}"),
        })?;
    let ts = Vector3::new(ts[0], ts[1], ts[2]);
    let resid = (&a * DVector::from_column_slice(ts.as_slice()) - &b).norm() / (m as f64).sqrt();
    Ok((ts, resid, condition))
}

/// The whole initial hand-eye of section 3.1: rotation from the
/// translations (eq. 6-7), then translation from the rotations (eq. 8-9).
///
/// # Errors
/// See [`initial_rotation`] and [`initial_translation`].
pub fn initial_hand_eye(
    robot: &Robot,
    translations: &[Sighting],
    rotations: &[Sighting],
) -> Result<InitialHandEye, HandEyeError> {
    let (rotation, rotation_residual, translation_spread, drift) =
        initial_rotation(robot, translations)?;
    let (t, translation_residual, rotation_condition) =
        initial_translation(robot, &rotation, rotations)?;
    Ok(InitialHandEye {
        flange_from_sensor: Isometry3::from_parts(Translation3::from(t), rotation),
        rotation_residual,
        translation_residual,
        translation_spread,
        rotation_condition,
        translation_orientation_drift_deg: drift,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::base::geometry::isometry_from_twist;
    use crate::engine::base::robot::irb2400;

    /// Sightings of `station` from flange poses (exact, no noise).
    fn sight(
        robot: &Robot,
        he: &Isometry3<f64>,
        station: &Vector3<f64>,
        q: &[f64],
        id: &str,
    ) -> Sighting {
        let base_from_sensor = robot.base_from_flange(q) * he;
        let c = base_from_sensor.inverse() * nalgebra::Point3::from(*station);
        Sighting {
            id: id.into(),
            joints: q.to_vec(),
            flange: None,
            centre_in_sensor: c.coords,
        }
    }

    #[test]
    fn exact_on_noise_free_data() {
        let preset = irb2400();
        let robot = preset.robot;
        let he = isometry_from_twist(&[-7.4, -1.0, 287.8, 0.02, -0.03, 0.5])
            * crate::engine::base::geometry::rot_x(std::f64::consts::PI);
        let q0 = [0.0, 20.0, 20.0, 0.0, 45.0, 0.0];
        let flange0 = robot.base_from_flange(&q0);
        let station = (flange0 * he * nalgebra::Point3::new(12.0, 1.0, -2.0)).coords;
        // Translations: same flange orientation, moved 20 mm three ways.
        let mut trans = Vec::new();
        for (k, d) in [
            [0.0, 0.0, 0.0],
            [20.0, 0.0, 0.0],
            [0.0, 20.0, 0.0],
            [0.0, 0.0, 15.0],
        ]
        .iter()
        .enumerate()
        {
            let target = Isometry3::from_parts(
                Translation3::from(flange0.translation.vector + Vector3::from(*d)),
                flange0.rotation,
            );
            let q = robot
                .inverse_kinematics(&target, &q0, Some(&preset.limits))
                .unwrap();
            trans.push(sight(&robot, &he, &station, &q, &format!("t{k}")));
        }
        let rots: Vec<Sighting> = [
            [0.0, 20.0, 20.0, 0.0, 45.0, 0.0],
            [5.0, 25.0, 15.0, 20.0, 40.0, 30.0],
            [-5.0, 18.0, 22.0, -25.0, 50.0, -40.0],
            [3.0, 22.0, 19.0, 10.0, 30.0, 90.0],
        ]
        .iter()
        .enumerate()
        .map(|(k, q)| {
            // Each orientation must keep the sphere in view: place the
            // flange so that the station is at the same sensor point.
            let flange = robot.base_from_flange(q);
            let wanted = flange.rotation * (he.rotation * Vector3::new(-12.0, 0.5, 1.0));
            let t = station - wanted - flange.rotation * he.translation.vector;
            let target = Isometry3::from_parts(Translation3::from(t), flange.rotation);
            let q = robot
                .inverse_kinematics(&target, q, Some(&preset.limits))
                .unwrap();
            sight(&robot, &he, &station, &q, &format!("r{k}"))
        })
        .collect();
        let est = initial_hand_eye(&robot, &trans, &rots).unwrap();
        let e = est.flange_from_sensor;
        assert!(
            e.rotation.angle_to(&he.rotation) < 1e-9,
            "{}",
            e.rotation.angle_to(&he.rotation)
        );
        assert!((e.translation.vector - he.translation.vector).norm() < 1e-6);
        assert!(est.rotation_residual < 1e-9 && est.translation_residual < 1e-6);
        assert!(est.translation_orientation_drift_deg < 1e-6);
    }

    #[test]
    fn collinear_translations_are_reported() {
        let robot = irb2400().robot;
        let q = [0.0, 20.0, 20.0, 0.0, 45.0, 0.0];
        let s = |id: &str, c: [f64; 3]| Sighting {
            id: id.into(),
            joints: q.to_vec(),
            flange: None,
            centre_in_sensor: Vector3::from(c),
        };
        // Same joints: zero robot displacement → no spread.
        let err = initial_rotation(
            &robot,
            &[
                s("a", [0.0; 3]),
                s("b", [1.0, 0.0, 0.0]),
                s("c", [2.0, 0.0, 0.0]),
            ],
        )
        .unwrap_err();
        let msg = err.to_string();
        assert!(
            matches!(err, HandEyeError::CollinearTranslations { .. }),
            "{msg}"
        );
        assert!(msg.contains("a, b, c"), "{msg}");
        let err =
            initial_rotation(&robot, &[s("a", [0.0; 3]), s("b", [1.0, 0.0, 0.0])]).unwrap_err();
        assert!(matches!(
            err,
            HandEyeError::TooFewTranslations { found: 2, .. }
        ));
    }

    #[test]
    fn similar_rotations_are_reported() {
        let robot = irb2400().robot;
        let s = |id: &str, q: [f64; 6]| Sighting {
            id: id.into(),
            joints: q.to_vec(),
            flange: None,
            centre_in_sensor: Vector3::zeros(),
        };
        let err = initial_translation(
            &robot,
            &UnitQuaternion::identity(),
            &[
                s("r1", [0.0, 20.0, 20.0, 0.0, 45.0, 0.0]),
                s("r2", [0.0, 20.0, 20.0, 0.0, 45.0, 2.0]),
            ],
        )
        .unwrap_err();
        assert!(err.to_string().contains("r1, r2"), "{err}");
        // Rotations about joint 6 only: one axis → Ts along it undetermined.
        let err = initial_translation(
            &robot,
            &UnitQuaternion::identity(),
            &[
                s("r1", [0.0, 20.0, 20.0, 0.0, 45.0, 0.0]),
                s("r2", [0.0, 20.0, 20.0, 0.0, 45.0, 40.0]),
                s("r3", [0.0, 20.0, 20.0, 0.0, 45.0, 80.0]),
            ],
        )
        .unwrap_err();
        assert!(err.to_string().contains("parallel"), "{err}");
    }
}
