//! Approach directions and flange orientations: a direction uniform in a
//! cone about a mean, and the flange rotation whose z axis (the approach)
//! is that direction with a given roll.

use std::f64::consts::PI;

use nalgebra::{Rotation3, UnitQuaternion, Vector3};
use rand_chacha::ChaCha8Rng;

use rand::Rng;

/// A unit vector uniformly distributed (by solid angle) within `cone` rad
/// of `axis`.
pub fn direction_in_cone(rng: &mut ChaCha8Rng, axis: &Vector3<f64>, cone: f64) -> Vector3<f64> {
    let cos_t = 1.0 - rng.random::<f64>() * (1.0 - cone.cos());
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let phi = 2.0 * PI * rng.random::<f64>();
    let (e1, e2) = perpendiculars(axis);
    (axis * cos_t + (e1 * phi.cos() + e2 * phi.sin()) * sin_t).normalize()
}

/// Two unit vectors completing `axis` (unit) to a right-handed basis.
fn perpendiculars(axis: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let helper = if axis.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let e1 = (helper - axis * helper.dot(axis)).normalize();
    let e2 = axis.cross(&e1);
    (e1, e2)
}

/// The rotation whose z axis is `approach` (unit), turned by `roll` rad
/// about it.
#[must_use]
pub fn rotation_from_approach(approach: &Vector3<f64>, roll: f64) -> UnitQuaternion<f64> {
    let (e1, e2) = perpendiculars(approach);
    let x = e1 * roll.cos() + e2 * roll.sin();
    let y = approach.cross(&x);
    UnitQuaternion::from_rotation_matrix(&Rotation3::from_basis_unchecked(&[x, y, *approach]))
}

/// A random flange orientation: approach in the cone, uniform roll.
pub fn random_orientation(
    rng: &mut ChaCha8Rng,
    mean: &Vector3<f64>,
    cone: f64,
) -> UnitQuaternion<f64> {
    let approach = direction_in_cone(rng, mean, cone);
    let roll = 2.0 * PI * rng.random::<f64>();
    rotation_from_approach(&approach, roll)
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector3;

    use super::*;
    use crate::engine::base::cell::random::stream;

    #[test]
    fn cone_directions_stay_in_the_cone() {
        let mut rng = stream(3, 0);
        let axis = Vector3::new(1.0, 0.0, -1.0).normalize();
        for _ in 0..200 {
            let d = direction_in_cone(&mut rng, &axis, 40f64.to_radians());
            assert!((d.norm() - 1.0).abs() < 1e-12);
            assert!(d.dot(&axis).acos().to_degrees() <= 40.0 + 1e-9);
            let r = rotation_from_approach(&d, 1.0);
            assert!((r * Vector3::z() - d).norm() < 1e-12);
        }
    }
}
