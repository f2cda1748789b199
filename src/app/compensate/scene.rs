//! The Compensate view's 3-D scene: every target as written (its frame,
//! a mark, the path through them in file order) and as compensated (the
//! frame to command), the move between them drawn as an arrow, enlarged
//! by a round factor said in the caption when it would be too small to
//! see; the selected target (picked there, the largest correction at
//! first) highlighted and its figures said.

use egui::Stroke;
use nalgebra::Isometry3;

use super::job::{CompensationView, flags_text};
use crate::app::AppState;
use crate::app::Forms;
use crate::app::scene::content::axes_lines;
use crate::app::scene::{Line3, Mark, Scene};
use crate::app::widgets::{AFTER, BEFORE, MUTED, WARN};
use crate::engine::tools::scene::{FrameAxes, arrow_scale, bounds, frame_axes};
use crate::engine::uses::compensate::TargetReport;

/// Width the scene starts at beside the view, points.
const SCENE_WIDTH: f32 = 400.0;
/// Smallest scene radius the arrows are scaled against, mm: targets
/// close together still get a visible arrow.
const MIN_RADIUS_MM: f64 = 50.0;

fn position(pose: &Isometry3<f64>) -> [f64; 3] {
    let t = pose.translation.vector;
    [t.x, t.y, t.z]
}

/// The target selected: `selected` when it is one, else the first row
/// (the largest correction).
#[must_use]
pub fn shown_target(rows: &[TargetReport], selected: Option<usize>) -> Option<usize> {
    selected
        .filter(|i| *i < rows.len())
        .or((!rows.is_empty()).then_some(0))
}

/// The scene of `rows` (indices are the rows'), the selected target
/// highlighted, and the factor the moves are drawn enlarged by (1: to
/// scale).
#[must_use]
pub fn compensation_scene(rows: &[TargetReport], selected: Option<usize>) -> (Scene, f64) {
    let wanted: Vec<[f64; 3]> = rows.iter().map(|r| position(&r.wanted)).collect();
    let radius = bounds(&wanted).map_or(MIN_RADIUS_MM, |b| b.1.max(MIN_RADIUS_MM));
    let largest = rows.iter().map(|r| r.correction_mm).fold(0.0, f64::max);
    let scale = arrow_scale(largest, radius);
    let axis = (0.06 * radius).clamp(5.0, 100.0);
    let shown = shown_target(rows, selected);
    let mut scene = Scene::default();
    axes_lines(
        &frame_axes(&Isometry3::identity(), 2.0 * axis),
        2.0,
        &mut scene.lines,
    );
    // The path through the targets as written, in file order.
    let mut order: Vec<usize> = (0..rows.len()).collect();
    order.sort_by_key(|i| rows[*i].line);
    if order.len() > 1 {
        scene.lines.push(Line3 {
            points: order.iter().map(|i| wanted[*i]).collect(),
            stroke: Stroke::new(1.0, MUTED.gamma_multiply(0.6)),
        });
    }
    for (i, r) in rows.iter().enumerate() {
        let is_shown = shown == Some(i);
        let width = if is_shown { 2.5 } else { 1.0 };
        let length = if is_shown { 1.6 * axis } else { axis };
        // As written: the frame, faded.
        let before = frame_axes(&r.wanted, length);
        faded_axes(&before, width, 0.45, &mut scene.lines);
        // As compensated: the frame at the move drawn (enlarged by
        // `scale`), the rotation of the pose to command.
        let moved = r.commanded.translation.vector - r.wanted.translation.vector;
        let drawn = Isometry3::from_parts(
            (r.wanted.translation.vector + scale * moved).into(),
            r.commanded.rotation,
        );
        axes_lines(&frame_axes(&drawn, length), width, &mut scene.lines);
        let end = position(&drawn);
        scene.lines.push(Line3 {
            points: vec![wanted[i], end],
            stroke: Stroke::new(if is_shown { 3.0 } else { 2.0 }, AFTER),
        });
        scene.points.push((end, AFTER));
        let flagged = !r.flags.is_empty();
        scene.marks.push(Mark {
            at: wanted[i],
            index: i,
            label: format!(
                "{} (line {}): moved {:.3} mm, {:.4}°{}",
                r.name,
                r.line,
                r.correction_mm,
                r.correction_deg,
                if flagged { " · flagged" } else { "" }
            ),
            colour: if flagged { WARN } else { BEFORE },
            selected: is_shown,
            crossed: false,
        });
    }
    // Framed on the targets and their moves; the base frame is a zoom
    // out away.
    scene.focus = bounds(wanted.iter().chain(scene.points.iter().map(|p| &p.0)))
        .map(|(c, r)| (c, (1.15 * r).max(0.2 * MIN_RADIUS_MM)));
    (scene, scale)
}

/// The axes of `f` in their colours faded by `alpha`.
fn faded_axes(f: &FrameAxes, width: f32, alpha: f32, out: &mut Vec<Line3>) {
    let mut lines = Vec::new();
    axes_lines(f, width, &mut lines);
    for mut l in lines {
        l.stroke.color = l.stroke.color.gamma_multiply(alpha);
        out.push(l);
    }
}

/// The caption: what is drawn, the scale of the moves, the selected
/// target's figures.
#[must_use]
pub fn caption(view: &CompensationView, shown: Option<usize>, scale: f64) -> String {
    let moves = if scale > 1.0 {
        format!("the moves drawn ×{scale:.0} (too small to see to scale)")
    } else {
        "the moves drawn to scale".to_string()
    };
    let mut text = format!(
        "{} targets as written (orange, faded frames, the path in file order) and compensated (frames at the blue arrows' ends); {moves}. ",
        view.rows.len()
    );
    if let Some(r) = shown.and_then(|i| view.rows.get(i)) {
        text.push_str(&format!(
            "Selected {} (line {}): {:.3} mm, {:.4}°, joints ≤ {:.3}°{}.",
            r.name,
            r.line,
            r.correction_mm,
            r.correction_deg,
            r.joint_change_deg,
            if r.flags.is_empty() {
                String::new()
            } else {
                format!("; flagged: {}", flags_text(r))
            }
        ));
    }
    text
}

/// The scene beside the Compensate view, when a compensation is on show:
/// a target picked there becomes the selected one; at most `max_width`
/// wide (the view's column keeps the rest).
pub fn scene_panel_ui(ui: &mut egui::Ui, state: &AppState, forms: &mut Forms, max_width: f32) {
    let Some(Ok(view)) = &state.compensate.outcome else {
        return;
    };
    egui::Panel::right("compensate_scene")
        .resizable(true)
        .default_size(SCENE_WIDTH.min(max_width))
        .size_range(260.0..=max_width.max(260.0))
        .show(ui, |ui| {
            let selected = forms.scene.compensate_target;
            let (scene, scale) = compensation_scene(&view.rows, selected);
            let shown = shown_target(&view.rows, selected);
            let text = caption(view, shown, scale);
            if let Some(i) = crate::app::scene::ui::scene_ui(
                ui,
                "compensate",
                &mut forms.scene.compensate,
                &scene,
                &text,
                0.0,
            ) {
                forms.scene.compensate_target = Some(i);
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::base::geometry::{rot_x, trans};
    use crate::engine::files::program::{PoseFile, PoseFormat};
    use crate::engine::uses::compensate::arms::BranchRule;
    use crate::engine::uses::compensate::report::Summary;

    fn row(name: &str, line: usize, at: [f64; 3], moved: [f64; 3]) -> TargetReport {
        let wanted = trans(at[0], at[1], at[2]) * rot_x(0.2);
        let commanded = trans(at[0] + moved[0], at[1] + moved[1], at[2] + moved[2]) * rot_x(0.21);
        TargetReport {
            index: line - 1,
            name: name.into(),
            line,
            joints_target: false,
            written: true,
            nominal_joints: [0.0; 6],
            joints: [0.0; 6],
            branch: BranchRule::First,
            wanted,
            commanded,
            correction_mm: (moved[0].powi(2) + moved[1].powi(2) + moved[2].powi(2)).sqrt(),
            correction_deg: 0.573,
            joint_change_deg: 0.1,
            sigma_mm: None,
            nearest_identify_deg: None,
            outside_mm: 0.0,
            flags: Vec::new(),
            values: Vec::new(),
            config_update: None,
            notes: Vec::new(),
        }
    }

    fn arrows(scene: &Scene) -> Vec<&Line3> {
        scene
            .lines
            .iter()
            .filter(|l| l.stroke.color == AFTER)
            .collect()
    }

    #[test]
    fn the_moves_are_drawn_to_scale_when_they_can_be_seen() {
        let rows = vec![
            row("T2", 5, [1000.0, 0.0, 500.0], [20.0, 0.0, 0.0]),
            row("T1", 4, [1000.0, 400.0, 500.0], [0.0, 15.0, 0.0]),
        ];
        let (scene, scale) = compensation_scene(&rows, None);
        assert_eq!(scale, 1.0);
        assert_eq!(scene.marks.len(), 2);
        assert!(scene.marks[0].selected, "the largest first");
        assert_eq!(scene.marks[1].at, [1000.0, 400.0, 500.0]);
        let a = arrows(&scene);
        assert_eq!(a.len(), 2);
        assert_eq!(
            a[0].points,
            vec![[1000.0, 0.0, 500.0], [1020.0, 0.0, 500.0]]
        );
        // The compensated frame's origin at the arrow's end.
        assert!(scene.points.iter().any(|p| p.0 == [1020.0, 0.0, 500.0]));
        // The path in file order: T1 (line 4) first.
        let path = scene
            .lines
            .iter()
            .find(|l| l.points == vec![[1000.0, 400.0, 500.0], [1000.0, 0.0, 500.0]]);
        assert!(path.is_some());
    }

    #[test]
    fn tiny_moves_are_enlarged_and_the_factor_said() {
        let rows = vec![
            row("P1", 1, [0.0, 0.0, 0.0], [0.02, 0.0, 0.0]),
            row("P2", 2, [500.0, 0.0, 0.0], [0.0, 0.01, 0.0]),
        ];
        let (scene, scale) = compensation_scene(&rows, Some(1));
        assert!(scale > 100.0, "{scale}");
        let a = arrows(&scene);
        let drawn = a[0].points[1][0] - a[0].points[0][0];
        assert!((drawn - 0.02 * scale).abs() < 1e-9, "{drawn}");
        assert!(scene.marks[1].selected && !scene.marks[0].selected);
        let file = PoseFile {
            path: "t.csv".into(),
            format: PoseFormat::Json,
            detected: true,
            targets: Vec::new(),
            order: Vec::new(),
            order_note: String::new(),
            warnings: Vec::new(),
            text: String::new(),
        };
        let view = CompensationView {
            file,
            tcp: String::new(),
            tool_data: Vec::new(),
            rows,
            summary: Summary::default(),
            notes: Vec::new(),
            text: String::new(),
        };
        let text = caption(&view, Some(1), scale);
        assert!(text.contains(&format!("×{scale:.0}")), "{text}");
        assert!(text.contains("Selected P2 (line 2)"), "{text}");
        assert!(caption(&view, None, 1.0).contains("to scale"));
    }
}
