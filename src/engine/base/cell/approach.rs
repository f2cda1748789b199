//! Approach directions and flange orientations: a direction uniform in a
//! cone about a mean, and the flange rotation whose z axis (the approach)
//! is that direction with a given roll; the mean approach from an eye
//! point, a random turn of a reference orientation, and the flange pose
//! that puts the sphere where the sensor should see it (shared by the
//! simulator and the planner).

use std::f64::consts::PI;

use nalgebra::{Isometry3, Point3, Rotation3, Translation3, Unit, UnitQuaternion, Vector3};
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

/// The mean approach direction (base frame, unit) at `station` looked at
/// from `eye` (both base frame, mm): from the eye to the station; straight
/// down (`−z`) when the two coincide.
#[must_use]
pub fn mean_approach(station: &Vector3<f64>, eye: &Vector3<f64>) -> Vector3<f64> {
    let d = station - eye;
    if d.norm() > 0.0 {
        d.normalize()
    } else {
        -Vector3::z()
    }
}

/// `reference` turned by an angle uniform in `min_deg..max_deg` (deg) about
/// a uniformly random axis; draws the axis first, then the angle (the
/// seeded streams of the simulator and the planner depend on that order).
pub fn turned_orientation(
    rng: &mut ChaCha8Rng,
    reference: &UnitQuaternion<f64>,
    min_deg: f64,
    max_deg: f64,
) -> UnitQuaternion<f64> {
    let axis = Unit::new_normalize(direction_in_cone(rng, &Vector3::z(), PI));
    let angle = super::random::uniform(rng, min_deg, max_deg).to_radians();
    reference * UnitQuaternion::from_axis_angle(&axis, angle)
}

/// The flange pose `base_from_flange` (mm) with flange rotation `rotation`
/// that puts the sphere centre at `station` (base frame, mm) and at
/// `centre_in_sensor` (sensor frame, mm) through the hand-eye
/// `flange_from_sensor`.
#[must_use]
pub fn flange_target(
    station: &Vector3<f64>,
    rotation: &UnitQuaternion<f64>,
    flange_from_sensor: &Isometry3<f64>,
    centre_in_sensor: &Vector3<f64>,
) -> Isometry3<f64> {
    let centre_in_flange = flange_from_sensor * Point3::from(*centre_in_sensor);
    let position = station - rotation * centre_in_flange.coords;
    Isometry3::from_parts(Translation3::from(position), *rotation)
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
