//! The orbit view of the Centres view: an orthographic camera drawn with
//! the egui painter that the operator turns by dragging and zooms with
//! the wheel, each centre in its station's marker, the station names
//! that fit without overlapping, the axes, and in the magnified mode a
//! scale bar in µm. A click selects the nearest centre's measurement;
//! hovering one names it.

use egui::{Color32, Pos2, Rect, Sense, Stroke, Vec2};
use egui_plot::MarkerShape;

use super::{Marker, PICK_RADIUS, UM_PER_MM, markers, tooltip};
use crate::app::results::CentreSet;
use crate::app::results::{Camera, CentresForm};
use crate::app::widgets::station_style;

/// The scale bar of the magnified 3D view: a 1-2-5 length of deviation
/// in µm that draws at least [`SCALE_BAR_MIN`] points long when one µm
/// draws `points_per_um`; the length and its points.
#[must_use]
pub fn scale_bar(points_per_um: f64) -> Option<(f64, f32)> {
    if !(points_per_um.is_finite() && points_per_um > 0.0) {
        return None;
    }
    let um = crate::app::widgets::plots::nice_step(f64::from(SCALE_BAR_MIN) / points_per_um, false);
    Some((um, (um * points_per_um) as f32))
}

/// Least length of the scale bar, points.
const SCALE_BAR_MIN: f32 = 60.0;

/// Most station names drawn in the 3D view.
const MAX_LABELS: usize = 60;

/// A station name's width per character at 13 points (an estimate,
/// generous: names are short ids), points.
const LABEL_CHAR_WIDTH: f32 = 8.0;

/// A station name's height, points.
const LABEL_HEIGHT: f32 = 15.0;

/// Least gap between two station names, points.
const LABEL_GAP: f32 = 4.0;

/// The accessible name of the 3D view.
pub const ORBIT_LABEL: &str = "3D view of the sphere centres";

/// The orthographic camera of the orbit view, fitted to the markers.
struct Orbit {
    centre: [f64; 3],
    scale: f64,
    screen_centre: Pos2,
    cy: f64,
    sy: f64,
    cp: f64,
    sp: f64,
}

impl Orbit {
    /// Centre of the markers' bounding box in the middle of `rect`, its
    /// half-diagonal filling 45 % of the shorter side (times the zoom).
    fn fit(markers: &[Marker], cam: &Camera, rect: Rect) -> Self {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for m in markers {
            for k in 0..3 {
                lo[k] = lo[k].min(m.pos[k]);
                hi[k] = hi[k].max(m.pos[k]);
            }
        }
        let centre = [
            f64::midpoint(lo[0], hi[0]),
            f64::midpoint(lo[1], hi[1]),
            f64::midpoint(lo[2], hi[2]),
        ];
        let half = (0..3)
            .map(|k| (hi[k] - lo[k]) / 2.0)
            .map(|d| d * d)
            .sum::<f64>()
            .sqrt()
            .max(1e-6);
        let (sy, cy) = f64::from(cam.yaw).sin_cos();
        let (sp, cp) = f64::from(cam.pitch).sin_cos();
        Self {
            centre,
            scale: f64::from(rect.width().min(rect.height())) * 0.45 / half * f64::from(cam.zoom),
            screen_centre: rect.center(),
            cy,
            sy,
            cp,
            sp,
        }
    }

    /// Screen position and depth of a base-frame point. The view rotates
    /// about z by the yaw, then tilts about the screen x axis by the pitch:
    /// screen right = rotated x, screen up = z·cos(pitch) − depth·sin(pitch).
    fn project(&self, p: [f64; 3]) -> (Pos2, f64) {
        let (x, y, z) = (
            p[0] - self.centre[0],
            p[1] - self.centre[1],
            p[2] - self.centre[2],
        );
        let xr = self.cy * x - self.sy * y;
        let yr = self.sy * x + self.cy * y;
        let up = z * self.cp - yr * self.sp;
        let depth = yr * self.cp + z * self.sp;
        (
            Pos2::new(
                self.screen_centre.x + (xr * self.scale) as f32,
                self.screen_centre.y - (up * self.scale) as f32,
            ),
            depth,
        )
    }
}

/// Where the 3D view in `rect` draws each centre: screen position and
/// measurement index (before and after markers alike). For tests and tools
/// that need to point at a centre.
#[must_use]
pub fn orbit_positions(
    set: &CentreSet,
    form: &CentresForm,
    rect: Rect,
) -> Vec<(Pos2, Option<usize>)> {
    let markers = markers(set, form);
    let view = Orbit::fit(&markers, &form.camera, rect);
    markers
        .iter()
        .map(|m| (view.project(m.pos).0, m.index))
        .collect()
}

/// The orthographic orbit view. Returns the measurement clicked.
pub(super) fn orbit_ui(
    ui: &mut egui::Ui,
    size: Vec2,
    markers: &[Marker],
    set: &CentreSet,
    cam: &mut Camera,
    selected: Option<usize>,
    magnify: Option<f64>,
) -> Option<usize> {
    let (response, painter) = ui.allocate_painter(size, Sense::click_and_drag());
    response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Canvas, true, ORBIT_LABEL));
    // What the points are and their frame (base for a sensor on the
    // flange, flange for a fixed sensor) is said above the view.
    let response = response.on_hover_text("the centres by station, in the frame named above");
    let rect = response.rect;
    painter.rect_filled(rect, 4.0, ui.visuals().extreme_bg_color);
    if response.dragged() {
        let d = response.drag_delta();
        cam.yaw += d.x * 0.01;
        cam.pitch = (cam.pitch + d.y * 0.01).clamp(-1.55, 1.55);
    }
    if response.hovered() {
        let scroll = ui.input(|i| i.smooth_scroll_delta.y);
        if scroll != 0.0 {
            cam.zoom = (cam.zoom * (scroll * 0.002).exp()).clamp(0.1, 50.0);
        }
    }
    if markers.is_empty() {
        painter.text(
            rect.center(),
            egui::Align2::CENTER_CENTER,
            "nothing to show",
            egui::FontId::proportional(16.0),
            Color32::GRAY,
        );
        return None;
    }
    let view = Orbit::fit(markers, cam, rect);
    let project = |p: [f64; 3]| view.project(p);
    let (cy, sy, cp, sp) = (view.cy, view.sy, view.cp, view.sp);
    let mut drawn: Vec<(Pos2, f64, &Marker)> = markers
        .iter()
        .map(|m| {
            let (p, d) = project(m.pos);
            (p, d, m)
        })
        .collect();
    drawn.sort_by(|a, b| b.1.total_cmp(&a.1));
    let painter = painter.with_clip_rect(rect);
    for (p, _, m) in &drawn {
        let style = station_style(m.station);
        paint_marker(&painter, *p, style.shape, style.colour, m.after);
        if m.index.is_some() && m.index == selected {
            painter.circle_stroke(*p, 8.0, Stroke::new(2.0, ui.visuals().strong_text_color()));
        }
    }
    // Station names where they do not overlap one another (at hundreds
    // of stations a few; hover a centre for its name).
    let mut placed: Vec<Rect> = Vec::new();
    for (k, s) in set.stations.iter().enumerate() {
        if placed.len() >= MAX_LABELS {
            break;
        }
        if let Some((mean, _)) = set.means.get(k) {
            let (p, _) = project(*mean);
            let corner = p + Vec2::new(10.0, -10.0);
            let size = Vec2::new(LABEL_CHAR_WIDTH * s.chars().count() as f32, LABEL_HEIGHT);
            let label = Rect::from_min_size(corner - Vec2::new(0.0, size.y), size);
            if !rect.contains_rect(label)
                || placed.iter().any(|r| r.expand(LABEL_GAP).intersects(label))
            {
                continue;
            }
            placed.push(label);
            painter.text(
                corner,
                egui::Align2::LEFT_BOTTOM,
                s,
                egui::FontId::proportional(13.0),
                station_style(k).colour,
            );
        }
    }
    axes_triad(&painter, rect, cy, sy, cp, sp);
    if let Some(k) = magnify {
        // Drawn mm per true mm of deviation is k; points per drawn mm is the scale.
        scale_bar_ui(
            &painter,
            rect,
            view.scale * k / UM_PER_MM,
            k,
            ui.visuals().text_color(),
        );
    }
    let hit = |pointer: Pos2| -> Option<&Marker> {
        drawn
            .iter()
            .map(|(p, _, m)| (p.distance(pointer), *m))
            .filter(|(d, _)| *d <= PICK_RADIUS)
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(_, m)| m)
    };
    if let Some(pointer) = response.hover_pos()
        && let Some(m) = hit(pointer)
    {
        // On a dark plate: readable over any marker.
        let galley = painter.layout_no_wrap(
            tooltip(set, m),
            egui::FontId::proportional(13.0),
            ui.visuals().strong_text_color(),
        );
        let at = pointer + Vec2::new(12.0, 12.0);
        painter.rect_filled(
            Rect::from_min_size(at, galley.size()).expand(3.0),
            3.0,
            Color32::from_black_alpha(200),
        );
        painter.galley(at, galley, Color32::WHITE);
    }
    if response.clicked() {
        return response
            .interact_pointer_pos()
            .and_then(hit)
            .and_then(|m| m.index);
    }
    None
}

/// A station marker at `p`: its shape, filled (after) or hollow (before).
fn paint_marker(
    painter: &egui::Painter,
    p: Pos2,
    shape: MarkerShape,
    colour: Color32,
    filled: bool,
) {
    let r = if filled { 4.0 } else { 4.5 };
    let corners: Vec<Pos2> = match shape {
        MarkerShape::Square => vec![
            p + Vec2::new(-r, -r),
            p + Vec2::new(r, -r),
            p + Vec2::new(r, r),
            p + Vec2::new(-r, r),
        ],
        MarkerShape::Diamond => {
            let d = r * 1.35;
            vec![
                p + Vec2::new(0.0, -d),
                p + Vec2::new(d, 0.0),
                p + Vec2::new(0.0, d),
                p + Vec2::new(-d, 0.0),
            ]
        }
        MarkerShape::Right => vec![
            p + Vec2::new(-r, -r * 1.15),
            p + Vec2::new(r * 1.3, 0.0),
            p + Vec2::new(-r, r * 1.15),
        ],
        _ => {
            if filled {
                painter.circle_filled(p, r, colour);
            } else {
                painter.circle_stroke(p, r, Stroke::new(1.5, colour));
            }
            return;
        }
    };
    if filled {
        painter.add(egui::Shape::convex_polygon(corners, colour, Stroke::NONE));
    } else {
        painter.add(egui::Shape::closed_line(corners, Stroke::new(1.5, colour)));
    }
}

/// The deviation scale of the magnified 3D view, lower right: a bar of a
/// 1-2-5 number of µm and its length in words.
fn scale_bar_ui(
    painter: &egui::Painter,
    rect: Rect,
    points_per_um: f64,
    magnify: f64,
    colour: Color32,
) {
    let Some((um, length)) = scale_bar(points_per_um) else {
        return;
    };
    let right = rect.right_bottom() + Vec2::new(-20.0, -24.0);
    let left = right - Vec2::new(length, 0.0);
    let stroke = Stroke::new(2.0, colour);
    painter.line_segment([left, right], stroke);
    for end in [left, right] {
        painter.line_segment(
            [end - Vec2::new(0.0, 5.0), end + Vec2::new(0.0, 5.0)],
            stroke,
        );
    }
    painter.text(
        right - Vec2::new(0.0, 8.0),
        egui::Align2::RIGHT_BOTTOM,
        format!("{} deviation (×{magnify:.0})", length_text(um)),
        egui::FontId::proportional(13.0),
        colour,
    );
}

/// A 1-2-5 length given in µm as text: µm below a millimetre, else mm.
#[must_use]
pub fn length_text(um: f64) -> String {
    let text = |v: f64| {
        crate::app::widgets::plots::tick_label(egui_plot::GridMark {
            value: v,
            step_size: v,
        })
    };
    if um >= UM_PER_MM {
        format!("{} mm", text(um / UM_PER_MM))
    } else {
        format!("{} µm", text(um))
    }
}

/// x (red), y (green), z (blue) in the lower left corner.
fn axes_triad(painter: &egui::Painter, rect: Rect, cy: f64, sy: f64, cp: f64, sp: f64) {
    let origin = rect.left_bottom() + Vec2::new(40.0, -40.0);
    let axes = [
        ([1.0, 0.0, 0.0], Color32::from_rgb(220, 60, 60), "x"),
        ([0.0, 1.0, 0.0], Color32::from_rgb(60, 180, 60), "y"),
        ([0.0, 0.0, 1.0], Color32::from_rgb(70, 110, 230), "z"),
    ];
    for (v, colour, name) in axes {
        let xr = cy * v[0] - sy * v[1];
        let yr = sy * v[0] + cy * v[1];
        let up = v[2] * cp - yr * sp;
        let tip = origin + Vec2::new((xr * 28.0) as f32, -(up * 28.0) as f32);
        painter.line_segment([origin, tip], Stroke::new(2.0, colour));
        painter.text(
            tip,
            egui::Align2::CENTER_CENTER,
            name,
            egui::FontId::proportional(12.0),
            colour,
        );
    }
}
