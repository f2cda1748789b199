//! The pieces the views put in their scenes, in one set of colours:
//! frame axes (x red, y green, z blue), the robot's links, the laser.
//! The views build their scenes themselves (`session::scene`,
//! `measure::scene`) from the engine's geometry
//! ([`crate::engine::tools::scene`]).

use egui::{Color32, Stroke};

use super::Line3;
use crate::engine::tools::scene::FrameAxes;

/// The axes' colours: x red, y green, z blue.
pub const AXIS: [Color32; 3] = [
    Color32::from_rgb(230, 70, 60),
    Color32::from_rgb(80, 190, 80),
    Color32::from_rgb(70, 120, 240),
];
/// The robot's links.
pub const LINK: Color32 = Color32::from_rgb(200, 200, 210);
/// The laser: its fan and its stripe.
pub const LASER: Color32 = Color32::from_rgb(255, 60, 40);

/// The three axes of `f` as lines `width` points wide, added to `out`.
pub fn axes_lines(f: &FrameAxes, width: f32, out: &mut Vec<Line3>) {
    for (end, colour) in f.ends.iter().zip(AXIS) {
        out.push(Line3 {
            points: vec![f.origin, *end],
            stroke: Stroke::new(width, colour),
        });
    }
}
