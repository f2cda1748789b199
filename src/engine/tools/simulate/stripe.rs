//! Synthetic stripes: the arc of the laser plane's cut through the sphere
//! that the camera sees, with noise, outliers and rounding.

use nalgebra::Vector3;
use rand::Rng;
use rand_chacha::ChaCha8Rng;

use super::config::{SimConfig, stripe_point_count};
use crate::engine::base::cell::random::{normal, uniform};
use crate::engine::base::numeric::round_to;

/// The stripe of a sensor-frame centre: the arc of the cut circle facing
/// the camera at `(0, 0, view_z)`, noise on both coordinates, outliers
/// moved along the circle normal, rounded.
pub(super) fn stripe(c: &SimConfig, rng: &mut ChaCha8Rng, centre: &Vector3<f64>) -> Vec<[f64; 2]> {
    let radius = c.diameter / 2.0;
    let r = (radius * radius - centre.x * centre.x).max(0.0).sqrt();
    let (yc, zc) = (centre.y, centre.z);
    // Angle from the +z axis toward +y of the camera seen from the circle centre.
    let facing = (-yc).atan2(c.view_z - zc);
    let n = stripe_point_count(r, c.arc_half_angle, c.point_spacing);
    let step = c.point_spacing / r;
    let first = facing + step * (n - 1) as f64 / 2.0;
    let mut points: Vec<(f64, f64, f64)> = (0..n)
        .map(|k| {
            let phi = first - step * k as f64;
            let y = yc + r * phi.sin() + c.stripe_noise * normal(rng);
            let z = zc + r * phi.cos() + c.stripe_noise * normal(rng);
            (y, z, phi)
        })
        .collect();
    // Rounding to nearest intended: a count of points.
    let n_outliers = (c.outlier_fraction * n as f64).round() as usize;
    if n_outliers > 0 {
        for index in rand::seq::index::sample(rng, n, n_outliers.min(n)).into_vec() {
            let magnitude = uniform(rng, c.outlier_min, c.outlier_max);
            let sign = if rng.random::<bool>() { 1.0 } else { -1.0 };
            let (y, z, phi) = &mut points[index];
            *y += sign * magnitude * phi.sin();
            *z += sign * magnitude * phi.cos();
        }
    }
    points
        .iter()
        .map(|(y, z, _)| {
            [
                round_to(*y, c.stripe_decimals),
                round_to(*z, c.stripe_decimals),
            ]
        })
        .collect()
}
