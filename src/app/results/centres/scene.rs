//! The Centres view's 3-D scene, drawn by the one scene widget
//! ([`crate::app::scene`]): each centre a mark in its station's colour
//! (before faint, after solid), the base frame's axes at the corner of the
//! centres. A click selects the centre's measurement; hovering one names
//! it.

use egui::Pos2;
use nalgebra::{Isometry3, Translation3, UnitQuaternion};

use super::{Marker, markers, tooltip};
use crate::app::results::{CentreSet, CentresForm};
use crate::app::scene::content::axes_lines;
use crate::app::scene::{Mark, Scene};
use crate::app::widgets::station_style;
use crate::engine::tools::scene::frame_axes;

/// The accessible name of the 3-D view (the scene widget's, for its id).
pub const ORBIT_LABEL: &str = "3-D scene of the sphere centres";

/// The scene widget's id of the 3-D view.
pub(super) const ORBIT_ID: &str = "of the sphere centres";

/// How much of its station's colour a before mark keeps.
const BEFORE_FADE: f32 = 0.45;

/// The scene of `markers` (the form's centres, placed as the form says),
/// the measurement `selected` ringed; each mark's index is its centre's in
/// `set.points`.
pub(super) fn centres_scene(set: &CentreSet, markers: &[Marker], selected: Option<usize>) -> Scene {
    let mut scene = Scene::default();
    scene.marks = markers
        .iter()
        .map(|m| {
            let colour = station_style(m.station).colour;
            Mark {
                at: m.pos,
                index: m.point,
                label: tooltip(set, m),
                colour: if m.after {
                    colour
                } else {
                    colour.gamma_multiply(BEFORE_FADE)
                },
                selected: m.index.is_some() && m.index == selected,
                crossed: false,
            }
        })
        .collect();
    // Framed on the centres; the axes at their lowest corner, a fifth of
    // their extent long.
    scene.focus = scene.bounds();
    if let Some((_, radius)) = scene.focus {
        let corner: [f64; 3] = std::array::from_fn(|k| {
            markers
                .iter()
                .map(|m| m.pos[k])
                .fold(f64::INFINITY, f64::min)
        });
        let at = Isometry3::from_parts(
            Translation3::new(corner[0], corner[1], corner[2]),
            UnitQuaternion::identity(),
        );
        axes_lines(&frame_axes(&at, 0.2 * radius), 2.0, &mut scene.lines);
    }
    scene
}

/// Where the 3-D view in `rect` draws each centre: screen position and
/// measurement index (before and after markers alike). For tests and tools
/// that need to point at a centre.
#[must_use]
pub fn orbit_positions(
    set: &CentreSet,
    form: &CentresForm,
    rect: egui::Rect,
) -> Vec<(Pos2, Option<usize>)> {
    let scene = centres_scene(set, &markers(set, form), None);
    let Some(bounds) = scene.focus else {
        return Vec::new();
    };
    let projection = form.camera.projection(rect, bounds);
    scene
        .marks
        .iter()
        .map(|m| (projection.screen(&m.at), set.points[m.index].index))
        .collect()
}
