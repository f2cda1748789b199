//! The 3-D scene of the cell: one widget every view that shows the cell
//! uses (Session: the robot at the selected pose, Measure: the cloud in
//! the cell). What is drawn is a [`Scene`] in the robot base frame **B**
//! (mm), built by the views from the engine's geometry
//! ([`crate::engine::tools::scene`]); the widget projects it with a
//! [`Camera`] (orthographic, software) and draws it with egui's painter.
//! Drag to orbit, drag with the right button (or Shift) to pan, scroll to
//! zoom, the buttons for the standard views; a click on a pose's mark
//! picks it.

pub mod content;
pub mod fixed;
pub mod ui;

use egui::{Color32, Pos2, Rect, Shape, Stroke};

/// The camera of each view's scene.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SceneCameras {
    /// The Session view's.
    pub session: Camera,
    /// The Measure view's.
    pub measure: Camera,
    /// The Plan view's.
    pub plan: Camera,
    /// The pose of the plan selected (in the scene and the plan's table).
    pub plan_pose: Option<usize>,
    /// The Compensate view's.
    pub compensate: Camera,
    /// The target selected in the Compensate view's scene (its index in
    /// the compensation's rows).
    pub compensate_target: Option<usize>,
}

/// A polyline of the scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Line3 {
    /// Its points, mm in **B**.
    pub points: Vec<[f64; 3]>,
    /// How it is drawn.
    pub stroke: Stroke,
}

/// A sphere of the scene, drawn as its outline.
#[derive(Debug, Clone, PartialEq)]
pub struct Sphere3 {
    /// Centre, mm in **B**.
    pub centre: [f64; 3],
    /// Radius, mm.
    pub radius: f64,
    /// Outline colour.
    pub colour: Color32,
}

/// A pose's mark: picked with a click, named on hover.
#[derive(Debug, Clone, PartialEq)]
pub struct Mark {
    /// Where, mm in **B**.
    pub at: [f64; 3],
    /// What a click picks (a measurement's or a planned pose's index).
    pub index: usize,
    /// Its name on hover.
    pub label: String,
    /// Its colour.
    pub colour: Color32,
    /// Drawn larger, ringed.
    pub selected: bool,
    /// Drawn crossed (a planned pose the robot cannot reach).
    pub crossed: bool,
}

/// What the scene shows, in **B** (mm).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Scene {
    /// Filled triangles (the laser fan), drawn first.
    pub triangles: Vec<([[f64; 3]; 3], Color32)>,
    /// Spheres (the reference sphere at its stations).
    pub spheres: Vec<Sphere3>,
    /// Points (a cloud, a stripe), each a small square.
    pub points: Vec<([f64; 3], Color32)>,
    /// Polylines (links, frame axes, the fan's edges).
    pub lines: Vec<Line3>,
    /// The pickable marks, drawn last.
    pub marks: Vec<Mark>,
    /// What Fit and the standard views frame (centre, radius, mm): `None`
    /// frames everything.
    pub focus: Option<([f64; 3], f64)>,
}

impl Scene {
    /// The centre and the radius of what is drawn (`None` when empty).
    #[must_use]
    pub fn bounds(&self) -> Option<([f64; 3], f64)> {
        let sphere_tops = self.spheres.iter().flat_map(|s| {
            let c = s.centre;
            [
                [c[0] - s.radius, c[1] - s.radius, c[2] - s.radius],
                [c[0] + s.radius, c[1] + s.radius, c[2] + s.radius],
            ]
        });
        let sphere_tops: Vec<[f64; 3]> = sphere_tops.collect();
        crate::engine::tools::scene::bounds(
            self.lines
                .iter()
                .flat_map(|l| l.points.iter())
                .chain(self.points.iter().map(|p| &p.0))
                .chain(self.marks.iter().map(|m| &m.at))
                .chain(self.triangles.iter().flat_map(|t| t.0.iter()))
                .chain(sphere_tops.iter()),
        )
    }
}

/// A standard view: where the eye is, seen from the scene's centre.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StandardView {
    /// From the front (+x), z up, at an angle from above.
    Iso,
    /// From +x, z up.
    Front,
    /// From −y, z up.
    Side,
    /// From above (+z), x to the right, y up.
    Top,
}

impl StandardView {
    /// Every standard view, in the order of the buttons.
    pub const ALL: [Self; 4] = [Self::Iso, Self::Front, Self::Side, Self::Top];

    /// The button's text.
    #[must_use]
    pub fn label(self) -> &'static str {
        match self {
            Self::Iso => "Iso",
            Self::Front => "Front",
            Self::Side => "Side",
            Self::Top => "Top",
        }
    }

    /// Yaw and pitch of the eye, rad.
    fn angles(self) -> (f64, f64) {
        let d = f64::to_radians;
        match self {
            Self::Iso => (d(-35.0), d(25.0)),
            Self::Front => (0.0, 0.0),
            Self::Side => (d(-90.0), 0.0),
            Self::Top => (d(-90.0), d(90.0)),
        }
    }
}

/// Radians of orbit per point dragged.
const ORBIT_PER_POINT: f64 = 0.01;
/// Zoom limits (1 fits the scene).
const ZOOM: [f64; 2] = [0.05, 200.0];

/// How a scene is looked at: orthographic, about the scene's centre.
#[derive(Debug, Clone, PartialEq)]
pub struct Camera {
    /// The eye's direction about **B**'s z axis, rad (0: from +x).
    pub yaw: f64,
    /// The eye's elevation, rad (π/2: from above).
    pub pitch: f64,
    /// Screen offset of the scene's centre, points.
    pub pan: [f32; 2],
    /// 1 fits the scene in the view; larger is closer.
    pub zoom: f64,
    /// Where the last frame drew each mark (its index, screen position):
    /// what a click picks from.
    pub drawn_marks: Vec<(usize, Pos2)>,
}

impl Default for Camera {
    fn default() -> Self {
        let mut c = Self {
            yaw: 0.0,
            pitch: 0.0,
            pan: [0.0, 0.0],
            zoom: 1.0,
            drawn_marks: Vec::new(),
        };
        c.set_view(StandardView::Iso);
        c
    }
}

impl Camera {
    /// Looks from a standard view, the whole scene in sight.
    pub fn set_view(&mut self, view: StandardView) {
        (self.yaw, self.pitch) = view.angles();
        self.fit();
    }

    /// The whole scene in sight, the direction kept.
    pub fn fit(&mut self) {
        self.pan = [0.0, 0.0];
        self.zoom = 1.0;
    }

    /// Turns the eye by a drag of `(dx, dy)` points: sideways about z,
    /// up and down in elevation (at most straight above or below).
    pub fn orbit(&mut self, dx: f32, dy: f32) {
        self.yaw -= f64::from(dx) * ORBIT_PER_POINT;
        self.pitch = (self.pitch + f64::from(dy) * ORBIT_PER_POINT)
            .clamp(-std::f64::consts::FRAC_PI_2, std::f64::consts::FRAC_PI_2);
    }

    /// Zooms by `factor` (> 1 closer), within limits.
    pub fn zoom_by(&mut self, factor: f64) {
        if factor.is_finite() && factor > 0.0 {
            self.zoom = (self.zoom * factor).clamp(ZOOM[0], ZOOM[1]);
        }
    }

    /// The projection of a scene of `bounds` into `rect` as seen now.
    #[must_use]
    pub fn projection(&self, rect: Rect, bounds: ([f64; 3], f64)) -> Projection {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        let eye = [cp * cy, cp * sy, sp];
        let right = [-sy, cy, 0.0];
        // up = eye × right
        let up = [
            eye[1] * right[2] - eye[2] * right[1],
            eye[2] * right[0] - eye[0] * right[2],
            eye[0] * right[1] - eye[1] * right[0],
        ];
        let radius = bounds.1.max(1.0);
        let scale = self.zoom * f64::from(rect.width().min(rect.height())) / (2.2 * radius);
        Projection {
            centre: bounds.0,
            right,
            up,
            eye,
            scale,
            origin: rect.center() + egui::vec2(self.pan[0], self.pan[1]),
        }
    }
}

/// A camera's projection for one frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projection {
    centre: [f64; 3],
    right: [f64; 3],
    up: [f64; 3],
    eye: [f64; 3],
    /// Points per millimetre.
    pub scale: f64,
    origin: Pos2,
}

impl Projection {
    /// Where `p` (mm in **B**) is drawn.
    #[must_use]
    pub fn screen(&self, p: &[f64; 3]) -> Pos2 {
        let d = [
            p[0] - self.centre[0],
            p[1] - self.centre[1],
            p[2] - self.centre[2],
        ];
        let dot = |a: &[f64; 3]| a[0] * d[0] + a[1] * d[1] + a[2] * d[2];
        Pos2::new(
            self.origin.x + (self.scale * dot(&self.right)) as f32,
            self.origin.y - (self.scale * dot(&self.up)) as f32,
        )
    }

    /// How near `p` is to the eye (larger is nearer), mm.
    #[must_use]
    pub fn depth(&self, p: &[f64; 3]) -> f64 {
        (0..3).map(|k| self.eye[k] * (p[k] - self.centre[k])).sum()
    }
}

/// Side of a drawn point, screen points.
pub const POINT_SIZE: f32 = 2.0;
/// Radius of a mark, points (a selected one is larger).
const MARK_RADIUS: f32 = 4.0;

/// The frame's shapes of `scene` seen by `camera` in `rect`, and where
/// each mark was drawn: the CPU work of projecting (tessellating them is
/// egui's). Points go into one mesh of small squares; what falls outside
/// `rect` is left out.
#[must_use]
pub fn shapes(scene: &Scene, camera: &Camera, rect: Rect) -> (Vec<Shape>, Vec<(usize, Pos2)>) {
    let Some(bounds) = scene.focus.or_else(|| scene.bounds()) else {
        return (Vec::new(), Vec::new());
    };
    let proj = camera.projection(rect, bounds);
    let mut out = Vec::new();
    if !scene.triangles.is_empty() {
        let mut mesh = egui::Mesh::default();
        for (t, colour) in &scene.triangles {
            let base = mesh.vertices.len() as u32;
            for p in t {
                mesh.colored_vertex(proj.screen(p), *colour);
            }
            mesh.add_triangle(base, base + 1, base + 2);
        }
        out.push(Shape::mesh(mesh));
    }
    for s in &scene.spheres {
        let c = proj.screen(&s.centre);
        let r = (s.radius * proj.scale) as f32;
        out.push(Shape::circle_filled(c, r, s.colour.gamma_multiply(0.15)));
        out.push(Shape::circle_stroke(c, r, Stroke::new(1.5, s.colour)));
    }
    if !scene.points.is_empty() {
        let mut mesh = egui::Mesh::default();
        mesh.reserve_vertices(4 * scene.points.len());
        mesh.reserve_triangles(2 * scene.points.len());
        let size = egui::vec2(POINT_SIZE, POINT_SIZE);
        for (p, colour) in &scene.points {
            let at = proj.screen(p);
            if rect.contains(at) {
                mesh.add_colored_rect(Rect::from_center_size(at, size), *colour);
            }
        }
        out.push(Shape::mesh(mesh));
    }
    for l in &scene.lines {
        let pts: Vec<Pos2> = l.points.iter().map(|p| proj.screen(p)).collect();
        out.push(Shape::line(pts, l.stroke));
    }
    // Marks far from the eye first, so that the nearest is on top.
    let mut order: Vec<(f64, &Mark)> = scene.marks.iter().map(|m| (proj.depth(&m.at), m)).collect();
    order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.selected.cmp(&b.1.selected)));
    let mut drawn = Vec::with_capacity(order.len());
    for (_, m) in order {
        let at = proj.screen(&m.at);
        if !rect.contains(at) {
            continue;
        }
        let r = if m.selected {
            MARK_RADIUS + 2.5
        } else {
            MARK_RADIUS
        };
        out.push(Shape::circle_filled(at, r, m.colour));
        if m.selected {
            out.push(Shape::circle_stroke(
                at,
                r + 2.5,
                Stroke::new(2.0, Color32::WHITE),
            ));
        }
        if m.crossed {
            let d = r + 2.0;
            let stroke = Stroke::new(2.0, crate::app::widgets::BAD);
            out.push(Shape::line_segment(
                [at + egui::vec2(-d, -d), at + egui::vec2(d, d)],
                stroke,
            ));
            out.push(Shape::line_segment(
                [at + egui::vec2(-d, d), at + egui::vec2(d, -d)],
                stroke,
            ));
        }
        drawn.push((m.index, at));
    }
    (out, drawn)
}

/// The mark drawn nearest `at` within `radius` points: its index.
#[must_use]
pub fn nearest_mark(drawn: &[(usize, Pos2)], at: Pos2, radius: f32) -> Option<usize> {
    drawn
        .iter()
        .map(|(i, p)| (*i, p.distance(at)))
        .filter(|(_, d)| *d <= radius)
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(i, _)| i)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rect() -> Rect {
        Rect::from_min_size(Pos2::ZERO, egui::vec2(400.0, 300.0))
    }

    #[test]
    fn the_standard_views_look_where_they_say() {
        let bounds = ([0.0; 3], 100.0);
        let mut cam = Camera::default();
        cam.set_view(StandardView::Front);
        let p = cam.projection(rect(), bounds);
        let c = p.screen(&[0.0; 3]);
        assert_eq!(c, rect().center());
        // From the front (+x): +y to the right, +z up, +x toward the eye.
        assert!(p.screen(&[0.0, 10.0, 0.0]).x > c.x);
        assert!(p.screen(&[0.0, 0.0, 10.0]).y < c.y);
        assert!((p.screen(&[10.0, 0.0, 0.0]) - c).length() < 1e-3);
        assert!(p.depth(&[10.0, 0.0, 0.0]) > 0.0);
        cam.set_view(StandardView::Top);
        let p = cam.projection(rect(), bounds);
        assert!(p.screen(&[10.0, 0.0, 0.0]).x > c.x + 1.0);
        assert!(p.screen(&[0.0, 10.0, 0.0]).y < c.y - 1.0);
        cam.set_view(StandardView::Side);
        let p = cam.projection(rect(), bounds);
        assert!(p.screen(&[10.0, 0.0, 0.0]).x > c.x + 1.0);
        assert!(p.depth(&[0.0, -10.0, 0.0]) > 0.0);
    }

    #[test]
    fn fit_shows_the_whole_scene_and_zoom_and_pan_move_it() {
        let bounds = ([500.0, 0.0, 800.0], 1000.0);
        let mut cam = Camera::default();
        let corner = [1500.0, 1000.0, 1800.0];
        for v in StandardView::ALL {
            cam.set_view(v);
            let p = cam.projection(rect(), bounds);
            assert!(rect().contains(p.screen(&corner)), "{v:?}");
        }
        let before = cam.projection(rect(), bounds).screen(&corner);
        cam.zoom_by(2.0);
        let after = cam.projection(rect(), bounds).screen(&corner);
        let c = rect().center();
        assert!(((after - c).length() - 2.0 * (before - c).length()).abs() < 0.01);
        cam.pan = [10.0, -5.0];
        assert_eq!(
            cam.projection(rect(), bounds).screen(&bounds.0),
            c + egui::vec2(10.0, -5.0)
        );
        cam.zoom_by(1e9);
        assert_eq!(cam.zoom, ZOOM[1]);
    }

    #[test]
    fn orbit_turns_the_view_and_stops_overhead() {
        let mut cam = Camera::default();
        let (yaw, pitch) = (cam.yaw, cam.pitch);
        cam.orbit(50.0, 0.0);
        assert!((cam.yaw - (yaw - 0.5)).abs() < 1e-12);
        assert_eq!(cam.pitch, pitch);
        cam.orbit(0.0, 1e6);
        assert_eq!(cam.pitch, std::f64::consts::FRAC_PI_2);
    }

    #[test]
    fn marks_are_picked_nearest_first_within_reach() {
        let scene = Scene {
            marks: (0..3)
                .map(|k| Mark {
                    at: [0.0, 100.0 * f64::from(k), 0.0],
                    index: k as usize,
                    label: format!("m{k}"),
                    colour: Color32::RED,
                    selected: k == 1,
                    crossed: false,
                })
                .collect(),
            ..Scene::default()
        };
        let mut cam = Camera::default();
        cam.set_view(StandardView::Front);
        let (shapes, drawn) = shapes(&scene, &cam, rect());
        assert_eq!(drawn.len(), 3);
        assert!(!shapes.is_empty());
        let at = drawn.iter().find(|d| d.0 == 2).expect("mark 2").1;
        assert_eq!(
            nearest_mark(&drawn, at + egui::vec2(3.0, 0.0), 8.0),
            Some(2)
        );
        assert_eq!(nearest_mark(&drawn, at + egui::vec2(30.0, 30.0), 8.0), None);
    }
}
