//! The Measure view's 3-D scene: the cloud's drawn points coloured by
//! σ, the frame's axes, the sensor's path.

use egui::Stroke;
use nalgebra::Isometry3;

use super::job::MeasuredCloud;
use super::ui::sigma_colour;
use crate::app::scene::content::axes_lines;
use crate::app::scene::{Line3, Scene};
use crate::app::widgets::BAD;
use crate::engine::tools::scene::frame_axes;

/// The measured cloud's scene: its drawn points (at most
/// [`crate::app::measure::job::DRAWN_MAX`], spread evenly) coloured by
/// σ on the Measure view's scale, the frame's axes and the sensor's path
/// over the scan.
#[must_use]
pub fn cloud_scene(c: &MeasuredCloud) -> Scene {
    let mut scene = Scene::default();
    scene.points = c
        .drawn
        .iter()
        .map(|p| (p.position, sigma_colour(c, p.sigma_mm)))
        .collect();
    // Framed on the cloud; the base frame's axes and the sensor's path
    // are a zoom out away.
    scene.focus = scene.bounds();
    let radius = scene.focus.map_or(100.0, |b| b.1);
    axes_lines(
        &frame_axes(&Isometry3::identity(), (0.5 * radius).clamp(20.0, 300.0)),
        2.0,
        &mut scene.lines,
    );
    let path: Vec<[f64; 3]> = c
        .cloud()
        .poses
        .iter()
        .map(|p| {
            let t = p.frame_from_sensor.translation.vector;
            [t.x, t.y, t.z]
        })
        .collect();
    // At most a few thousand corners: the path's shape, not its every pose.
    let step = path.len().div_ceil(4000).max(1);
    let path: Vec<[f64; 3]> = path.into_iter().step_by(step).collect();
    if path.len() > 1 {
        scene.lines.push(Line3 {
            points: path,
            stroke: Stroke::new(1.0, BAD.gamma_multiply(0.6)),
        });
    }
    scene
}
