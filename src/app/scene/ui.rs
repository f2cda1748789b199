//! The scene widget: the standard views' buttons, the canvas (drag to
//! orbit, right-drag or Shift-drag to pan, scroll to zoom, click a mark
//! to pick it, hover to name it) and a caption under it.

use egui::{Color32, RichText, Sense};

use super::{Camera, Scene, StandardView, nearest_mark, shapes};
use crate::app::widgets::MUTED;

/// How near a click must be to a mark to pick it, points.
const PICK_RADIUS: f32 = 10.0;
/// Zoom per point scrolled.
const ZOOM_PER_POINT: f64 = 1.0 / 200.0;
/// The canvas's background.
const BACKGROUND: Color32 = Color32::from_rgb(24, 26, 30);

/// The scene `scene` in a canvas `height` points tall (0: the height
/// left, less the caption's), as `camera` looks at
/// it, with `caption` under it; the index of the mark a click picked.
pub fn scene_ui(
    ui: &mut egui::Ui,
    id: &str,
    camera: &mut Camera,
    scene: &Scene,
    caption: &str,
    height: f32,
) -> Option<usize> {
    let room = if height > 0.0 {
        Room::Canvas(height)
    } else {
        Room::Fill
    };
    scene_in(ui, id, camera, scene, caption, room)
}

/// [`scene_ui`] with its buttons, canvas and caption together `total`
/// points tall, whatever the buttons' and the caption's rows take at this
/// width (the Centres view's caption ran off the bottom when its rows
/// wrapped).
pub fn scene_ui_within(
    ui: &mut egui::Ui,
    id: &str,
    camera: &mut Camera,
    scene: &Scene,
    caption: &str,
    total: f32,
) -> Option<usize> {
    scene_in(ui, id, camera, scene, caption, Room::Total(total))
}

/// The height a scene is given.
#[derive(Debug, Clone, Copy)]
enum Room {
    /// The canvas this tall.
    Canvas(f32),
    /// The height left, less the caption's.
    Fill,
    /// Buttons, canvas and caption together this tall.
    Total(f32),
}

fn scene_in(
    ui: &mut egui::Ui,
    id: &str,
    camera: &mut Camera,
    scene: &Scene,
    caption: &str,
    room: Room,
) -> Option<usize> {
    let top = ui.cursor().min.y;
    ui.horizontal_wrapped(|ui| {
        ui.label(RichText::new("3-D").strong());
        for v in StandardView::ALL {
            if ui
                .small_button(v.label())
                .on_hover_text(format!(
                    "look from the {} view, the whole scene in sight",
                    v.label()
                ))
                .clicked()
            {
                camera.set_view(v);
            }
        }
        if ui
            .small_button("Fit")
            .on_hover_text("the whole scene in sight")
            .clicked()
        {
            camera.fit();
        }
        if ui.small_button("+").on_hover_text("zoom in").clicked() {
            camera.zoom_by(1.25);
        }
        if ui.small_button("−").on_hover_text("zoom out").clicked() {
            camera.zoom_by(0.8);
        }
        ui.label(
            RichText::new("drag: orbit · right-drag: pan · scroll: zoom · click a pose: select")
                .small()
                .color(MUTED),
        );
    });
    // The caption's own height at this width (a four-line caption was
    // cut at the bottom of a view that kept room for three).
    let caption_height = if caption.is_empty() {
        0.0
    } else {
        let font = egui::TextStyle::Small.resolve(ui.style());
        let galley = ui
            .painter()
            .layout(caption.to_string(), font, MUTED, ui.available_width());
        galley.size().y + 2.0 * ui.spacing().item_spacing.y
    };
    let height = match room {
        Room::Canvas(h) => h,
        Room::Fill => (ui.available_height() - caption_height).max(120.0),
        Room::Total(t) => {
            let buttons = ui.cursor().min.y - top;
            (t - buttons - caption_height).max(120.0)
        }
    };
    let size = egui::vec2(ui.available_width().max(120.0), height);
    let (rect, response) = ui.allocate_exact_size(size, Sense::click_and_drag());
    let response = response.on_hover_cursor(egui::CursorIcon::Grab);
    response.widget_info(|| {
        egui::WidgetInfo::labeled(egui::Role::Canvas, true, format!("3-D scene {id}"))
    });
    let shift = ui.input(|i| i.modifiers.shift);
    let delta = response.drag_delta();
    if response.dragged_by(egui::PointerButton::Secondary)
        || response.dragged_by(egui::PointerButton::Middle)
        || (response.dragged_by(egui::PointerButton::Primary) && shift)
    {
        camera.pan[0] += delta.x;
        camera.pan[1] += delta.y;
    } else if response.dragged_by(egui::PointerButton::Primary) {
        camera.orbit(delta.x, delta.y);
    }
    if response.hovered() {
        let (scroll, pinch) = ui.input(|i| (i.smooth_scroll_delta.y, i.zoom_delta()));
        if scroll != 0.0 || pinch != 1.0 {
            camera.zoom_by((f64::from(scroll) * ZOOM_PER_POINT).exp() * f64::from(pinch));
            // The scene takes the wheel: the page under it does not scroll.
            ui.input_mut(|i| i.smooth_scroll_delta = egui::Vec2::ZERO);
        }
    }
    let (shapes, drawn) = shapes(scene, camera, rect);
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 4.0, BACKGROUND);
    painter.extend(shapes);
    let mut picked = None;
    if let Some(at) = response.interact_pointer_pos().or(response.hover_pos())
        && let Some(k) = nearest_mark(&drawn, at, PICK_RADIUS)
    {
        if response.clicked() {
            picked = Some(k);
        }
        if let (Some(m), Some((_, p))) = (
            scene.marks.iter().find(|m| m.index == k),
            drawn.iter().find(|d| d.0 == k),
        ) {
            name_at(&painter, rect, *p, &m.label);
        }
    }
    if scene.marks.is_empty() && scene.points.is_empty() && scene.lines.is_empty() {
        painter.text(
            rect.center(),
            egui::Align2::CENTER_CENTER,
            "nothing to show",
            egui::FontId::proportional(14.0),
            MUTED,
        );
    }
    camera.drawn_marks = drawn;
    if !caption.is_empty() {
        ui.label(RichText::new(caption).small());
    }
    picked
}

/// A mark's name beside it, kept inside the canvas.
fn name_at(painter: &egui::Painter, rect: egui::Rect, at: egui::Pos2, text: &str) {
    // Wrapped to the canvas: a name wider than a narrow view was cut at
    // its edge.
    let galley = painter.layout(
        text.to_string(),
        egui::FontId::proportional(13.0),
        Color32::WHITE,
        (rect.width() - 8.0).max(40.0),
    );
    let size = galley.size() + egui::vec2(8.0, 4.0);
    let mut min = at + egui::vec2(10.0, -size.y - 4.0);
    min.x = min.x.min(rect.right() - size.x).max(rect.left());
    min.y = min.y.max(rect.top()).min(rect.bottom() - size.y);
    let frame = egui::Rect::from_min_size(min, size);
    painter.rect_filled(frame, 3.0, Color32::from_black_alpha(200));
    painter.galley(min + egui::vec2(4.0, 2.0), galley, Color32::WHITE);
}
