//! The Centres view: sphere centres in the base frame by station, before
//! and after calibration, in a 3D view the operator can orbit (an
//! orthographic camera drawn with the egui painter) and in the three plane
//! projections. Clicking a centre selects its measurement.

use egui::{Color32, Pos2, Rect, RichText, Sense, Stroke, Vec2};
use egui_plot::{MarkerShape, Plot, PlotPoints, Points};

use super::plots::readable;
use super::station_style;
use crate::app::commands::{Command, ViewCommand};
use crate::app::forms::{Camera, CentresForm, Forms};
use crate::app::state::AppState;
use crate::app::view::{CentrePoint, CentreSet};

/// A click selects the nearest centre within this many points of the pointer.
const PICK_RADIUS: f32 = 10.0;

/// The key of the before markers (hollow, in the station's colour).
pub const BEFORE_KEY: &str = "○ before (nominal): hollow";
/// The key of the after markers (filled, in the station's colour).
pub const AFTER_KEY: &str = "● after (calibrated): filled";

/// The key of station number `k` named `name`: its shape and name, e.g.
/// "◆ V5" (shown in its colour).
#[must_use]
pub fn station_key(k: usize, name: &str) -> String {
    // A no-break space: a wrapped row never parts a shape from its name.
    format!("{}\u{a0}{name}", station_style(k).glyph)
}

/// One drawn marker: where, which measurement, before or after.
struct Marker {
    pos: [f64; 3],
    index: Option<usize>,
    station: usize,
    after: bool,
}

/// The Centres view.
pub fn centres_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    forms: &mut Forms,
    commands: &mut Vec<Command>,
) {
    let set = match (&state.result, &state.loaded) {
        (Some(r), _) => &r.centres,
        (None, Some(l)) => match &l.before {
            Ok(set) => set,
            Err(e) => {
                ui.label(RichText::new(format!("No centres: {e}")).color(super::BAD));
                return;
            }
        },
        (None, None) => {
            ui.label("No session open.");
            return;
        }
    };
    let has_after = set.points.iter().any(|p| p.after.is_some());
    options_ui(ui, &mut forms.centres, has_after, set);
    let markers = markers(set, &forms.centres);
    let flat = projection_markers(set, &forms.centres);
    let relative = forms.centres.relative;
    let magnify = forms
        .centres
        .relative
        .then_some(f64::from(forms.centres.magnify));
    let selected = state.selected;
    let size = ui.available_size();
    ui.horizontal(|ui| {
        let w3d = (size.x * 0.55).max(200.0);
        ui.vertical(|ui| {
            ui.set_width(w3d);
            ui.label(
                RichText::new("3D (drag to orbit, scroll to zoom, click to select)")
                    .small()
                    .weak(),
            );
            let h = (size.y - 24.0).max(150.0);
            if let Some(i) = orbit_ui(
                ui,
                Vec2::new(w3d, h),
                &markers,
                set,
                &mut forms.centres.camera,
                selected,
                magnify,
            ) {
                commands.push(Command::View(ViewCommand::Select(i)));
            }
        });
        ui.vertical(|ui| {
            let h = ((size.y - 3.0 * 22.0) / 3.0).max(100.0);
            for (k, (a, b, name)) in [
                (0, 1, "top view: x–y"),
                (0, 2, "side view: x–z"),
                (1, 2, "front view: y–z"),
            ]
            .into_iter()
            .enumerate()
            {
                let name = if relative {
                    format!("{name}, deviations from each station's mean (all stations about 0)")
                } else {
                    name.to_string()
                };
                ui.label(RichText::new(name).small().weak());
                if let Some(i) = projection_ui(ui, k, (a, b), (h, relative), &flat, set, selected) {
                    commands.push(Command::View(ViewCommand::Select(i)));
                }
            }
        });
    });
}

fn options_ui(ui: &mut egui::Ui, f: &mut CentresForm, has_after: bool, set: &CentreSet) {
    ui.horizontal_wrapped(|ui| {
        // Both are drawn in their station's colour: the cue is the fill.
        ui.checkbox(&mut f.show_before, BEFORE_KEY)
            .on_hover_text("nominal model, initial hand-eye: hollow markers");
        ui.add_enabled_ui(has_after, |ui| {
            ui.checkbox(&mut f.show_after, AFTER_KEY)
                .on_hover_text("calibrated: filled markers")
                .on_disabled_hover_text("run the solver first");
        });
        ui.checkbox(
            &mut f.relative,
            "deviations from the station mean, magnified",
        )
        .on_hover_text(
            "each centre is drawn at its station's mean plus its deviation times the factor",
        );
        ui.add_enabled_ui(f.relative, |ui| {
            let l = ui.label("×");
            ui.add(
                egui::DragValue::new(&mut f.magnify)
                    .range(1.0..=2000.0)
                    .speed(1.0),
            )
            .labelled_by(l.id);
        });
        if ui.button("Reset view").clicked() {
            f.camera = Camera::default();
        }
        ui.separator();
        for (k, s) in set.stations.iter().enumerate() {
            let style = station_style(k);
            ui.label(RichText::new(station_key(k, s)).color(style.colour));
        }
    });
}

fn markers(set: &CentreSet, f: &CentresForm) -> Vec<Marker> {
    let mut out = Vec::new();
    let place = |p: [f64; 3], own_mean: [f64; 3], anchor: [f64; 3]| -> [f64; 3] {
        if f.relative {
            let k = f64::from(f.magnify);
            [
                anchor[0] + k * (p[0] - own_mean[0]),
                anchor[1] + k * (p[1] - own_mean[1]),
                anchor[2] + k * (p[2] - own_mean[2]),
            ]
        } else {
            p
        }
    };
    for p in &set.points {
        let s = set.station_index(&p.station);
        let (mean_before, mean_after) = set.means.get(s).copied().unwrap_or(([0.0; 3], [0.0; 3]));
        if f.show_before {
            out.push(Marker {
                pos: place(p.before, mean_before, mean_before),
                index: p.index,
                station: s,
                after: false,
            });
        }
        if f.show_after
            && let Some(a) = p.after
        {
            out.push(Marker {
                pos: place(a, mean_after, mean_before),
                index: p.index,
                station: s,
                after: true,
            });
        }
    }
    out
}

/// Micrometres in a millimetre.
const UM_PER_MM: f64 = 1000.0;

/// What the plane projections draw: in relative mode each centre's
/// deviation from its station's mean in µm (before from the mean before,
/// after from the mean after; every station about one origin, so the
/// axes carry true deviations, not magnified millimetres), else the
/// centres in mm.
fn projection_markers(set: &CentreSet, f: &CentresForm) -> Vec<Marker> {
    if !f.relative {
        return markers(set, f);
    }
    let dev = |p: [f64; 3], mean: [f64; 3]| -> [f64; 3] {
        std::array::from_fn(|k| (p[k] - mean[k]) * UM_PER_MM)
    };
    let mut out = Vec::new();
    for p in &set.points {
        let s = set.station_index(&p.station);
        let (mean_before, mean_after) = set.means.get(s).copied().unwrap_or(([0.0; 3], [0.0; 3]));
        if f.show_before {
            out.push(Marker {
                pos: dev(p.before, mean_before),
                index: p.index,
                station: s,
                after: false,
            });
        }
        if f.show_after
            && let Some(a) = p.after
        {
            out.push(Marker {
                pos: dev(a, mean_after),
                index: p.index,
                station: s,
                after: true,
            });
        }
    }
    out
}

/// The label of projection axis `k` (0 x, 1 y, 2 z): position in mm, or
/// in relative mode the deviation from the station mean in µm (the
/// caption above each projection says of what; the label must fit the
/// plot's height).
#[must_use]
pub fn projection_axis_label(k: usize, relative: bool) -> String {
    let name = ["x", "y", "z"].get(k).copied().unwrap_or("?");
    if relative {
        format!("Δ{name} (µm)")
    } else {
        format!("{name} (mm)")
    }
}

/// Where the plane projections draw each centre (x, y, z in the units of
/// [`projection_axis_label`]) and its measurement index.
#[must_use]
pub fn projection_points(set: &CentreSet, form: &CentresForm) -> Vec<([f64; 3], Option<usize>)> {
    projection_markers(set, form)
        .into_iter()
        .map(|m| (m.pos, m.index))
        .collect()
}

/// The scale bar of the magnified 3D view: a 1-2-5 length of deviation
/// in µm that draws at least [`SCALE_BAR_MIN`] points long when one µm
/// draws `points_per_um`; the length and its points.
#[must_use]
pub fn scale_bar(points_per_um: f64) -> Option<(f64, f32)> {
    if !(points_per_um.is_finite() && points_per_um > 0.0) {
        return None;
    }
    let um = super::plots::nice_step(f64::from(SCALE_BAR_MIN) / points_per_um, false);
    Some((um, (um * points_per_um) as f32))
}

/// Least length of the scale bar, points.
const SCALE_BAR_MIN: f32 = 60.0;

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
            (lo[0] + hi[0]) / 2.0,
            (lo[1] + hi[1]) / 2.0,
            (lo[2] + hi[2]) / 2.0,
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
fn orbit_ui(
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
    let response = response.on_hover_text("sphere centres in the robot base frame");
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
    for (k, s) in set.stations.iter().enumerate() {
        if let Some((mean, _)) = set.means.get(k) {
            let (p, _) = project(*mean);
            painter.text(
                p + Vec2::new(10.0, -10.0),
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
        let label = tooltip(set, m);
        painter.text(
            pointer + Vec2::new(12.0, 12.0),
            egui::Align2::LEFT_TOP,
            label,
            egui::FontId::proportional(13.0),
            ui.visuals().strong_text_color(),
        );
    }
    if response.clicked() {
        return response
            .interact_pointer_pos()
            .and_then(hit)
            .and_then(|m| m.index);
    }
    None
}

fn tooltip(set: &CentreSet, m: &Marker) -> String {
    let p: Option<&CentrePoint> = m
        .index
        .and_then(|i| set.points.iter().find(|p| p.index == Some(i)));
    let id = p.map_or("?", |p| p.id.as_str());
    let station = set.stations.get(m.station).map_or("?", String::as_str);
    format!(
        "{id} ({station}, {})",
        if m.after { "after" } else { "before" }
    )
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
        super::plots::tick_label(egui_plot::GridMark {
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

/// One plane projection. Returns the measurement clicked.
fn projection_ui(
    ui: &mut egui::Ui,
    k: usize,
    (a, b): (usize, usize),
    (height, relative): (f32, bool),
    markers: &[Marker],
    set: &CentreSet,
    selected: Option<usize>,
) -> Option<usize> {
    let response = readable(Plot::new(("projection", k)), false)
        .data_aspect(1.0)
        .height(height)
        .x_axis_label(projection_axis_label(a, relative))
        .y_axis_label(projection_axis_label(b, relative))
        .show(ui, |p| {
            for (s, name) in set.stations.iter().enumerate() {
                let style = station_style(s);
                for after in [false, true] {
                    let pts: Vec<[f64; 2]> = markers
                        .iter()
                        .filter(|m| m.station == s && m.after == after)
                        .map(|m| [m.pos[a], m.pos[b]])
                        .collect();
                    if pts.is_empty() {
                        continue;
                    }
                    p.points(
                        Points::new(name.clone(), PlotPoints::from(pts))
                            .color(style.colour)
                            .filled(after)
                            .shape(style.shape)
                            .radius(if after { 3.5 } else { 4.0 }),
                    );
                }
            }
            if let Some(sel) = selected {
                let pts: Vec<[f64; 2]> = markers
                    .iter()
                    .filter(|m| m.index == Some(sel))
                    .map(|m| [m.pos[a], m.pos[b]])
                    .collect();
                p.points(
                    Points::new("", PlotPoints::from(pts))
                        .shape(MarkerShape::Circle)
                        .filled(false)
                        .radius(8.0)
                        .color(p.ctx().global_style().visuals.strong_text_color()),
                );
            }
            let clicked = p.response().clicked();
            let pointer = p.response().interact_pointer_pos();
            match (clicked, pointer) {
                (true, Some(pointer)) => markers
                    .iter()
                    .map(|m| {
                        let s = p.screen_from_plot(egui_plot::PlotPoint::new(m.pos[a], m.pos[b]));
                        (s.distance(pointer), m.index)
                    })
                    .filter(|(d, _)| *d <= PICK_RADIUS)
                    .min_by(|x, y| x.0.total_cmp(&y.0))
                    .and_then(|(_, i)| i),
                _ => None,
            }
        });
    response.inner
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(id: &str, station: &str, before: [f64; 3], after: [f64; 3]) -> CentrePoint {
        CentrePoint {
            id: id.into(),
            station: station.into(),
            usage: "identify".into(),
            index: None,
            before,
            after: Some(after),
        }
    }

    /// The issue: at ×250 the magnified projections showed ±2000 "mm".
    /// Now they show each centre's true deviation in µm.
    #[test]
    fn magnified_projections_are_in_micrometres() {
        let set = CentreSet::new(vec![
            point("a", "P0", [1000.0, 0.0, 500.0], [1000.0, 0.0, 500.0]),
            point("b", "P0", [1000.02, 0.0, 500.0], [1000.002, 0.0, 500.0]),
            point("c", "P1", [0.0, 800.0, 300.0], [0.0, 800.0, 300.0]),
            point("d", "P1", [0.0, 800.0, 300.04], [0.0, 800.0, 300.0]),
        ]);
        let form = CentresForm {
            magnify: 250.0,
            ..CentresForm::default()
        };
        assert!(form.relative);
        let pts = projection_points(&set, &form);
        let largest = pts
            .iter()
            .flat_map(|(p, _)| p.iter())
            .fold(0.0_f64, |m, v| m.max(v.abs()));
        // b's deviation before: 0.01 mm from P0's mean = 10 µm; d's 20 µm.
        assert!((largest - 20.0).abs() < 1e-6, "{largest}");
        assert!((pts[2].0[0] - 10.0).abs() < 1e-6, "{:?}", pts[2]);
        assert!((pts[3].0[0] - 1.0).abs() < 1e-6, "after: {:?}", pts[3]);
        assert_eq!(projection_axis_label(0, true), "Δx (µm)");
        assert_eq!(projection_axis_label(2, false), "z (mm)");
        // Not magnified: positions in mm.
        let plain = CentresForm {
            relative: false,
            ..form
        };
        assert_eq!(projection_points(&set, &plain)[0].0, [1000.0, 0.0, 500.0]);
    }

    #[test]
    fn scale_bar_is_a_round_number_of_micrometres() {
        // ×250 at 0.5 points per drawn mm: 0.125 points per µm; 60 points
        // need 480 µm, so 500 µm, 62.5 points.
        let (um, points) = scale_bar(0.125).unwrap();
        assert_eq!(um, 500.0);
        assert!((points - 62.5).abs() < 1e-3);
        assert!(scale_bar(0.0).is_none());
        assert_eq!(length_text(um), "500 µm");
        assert_eq!(length_text(20_000.0), "20 mm");
        assert_eq!(station_key(12, "V3"), "■\u{a0}V3");
    }
}
