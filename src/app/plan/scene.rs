//! The Plan view's 3-D scene and its table of poses: every planned pose's
//! flange mark coloured by station (crossed when it cannot be run as
//! planned), the sphere at every station, and at the selected pose the
//! robot, the flange and sensor frames and the laser fan. A pose picked in
//! the scene is selected in the table (opened and scrolled to it), a row
//! clicked in the table is the pose the scene shows.

use egui::{RichText, Stroke};

use crate::app::Forms;
use crate::app::scene::content::{LASER, LINK, axes_lines};
use crate::app::scene::{Line3, Mark, Scene, Sphere3};
use crate::app::widgets::{BAD, MUTED, coloured, station_style, table};
use crate::engine::tools::plan::Plan;
use crate::engine::tools::scene::{
    fan_around, frame_axes, laser_fan, link_polyline, planned_pose_problem,
};

/// Height of the scene, points.
const SCENE_HEIGHT: f32 = 340.0;

/// The pose the scene shows: the selected one when it is in the plan,
/// else the first.
#[must_use]
pub fn shown_pose(plan: &Plan, selected: Option<usize>) -> Option<usize> {
    selected
        .filter(|i| *i < plan.poses.len())
        .or((!plan.poses.is_empty()).then_some(0))
}

/// The plan's scene with pose `selected` (the first when none) shown:
/// the base frame, the sphere at every station, a mark at every pose's
/// flange (by station, crossed with why when it cannot be run), and at
/// the shown pose the robot's links, the flange and sensor frames, the
/// mount and the laser fan; the number of crossed poses.
#[must_use]
pub fn plan_scene(plan: &Plan, selected: Option<usize>) -> (Scene, usize) {
    let robot = &plan.robot;
    let reach = plan
        .poses
        .iter()
        .map(|p| (p.base_from_flange.translation.vector - robot.base.translation.vector).norm())
        .fold(0.0, f64::max);
    let axis = (0.08 * reach).clamp(20.0, 150.0);
    let mut scene = Scene::default();
    axes_lines(&frame_axes(&robot.base, 2.0 * axis), 2.0, &mut scene.lines);
    let station_k = |id: &str| plan.stations.iter().position(|s| s.id == id).unwrap_or(0);
    for (k, s) in plan.stations.iter().enumerate() {
        scene.spheres.push(Sphere3 {
            centre: [s.position.x, s.position.y, s.position.z],
            radius: 0.5 * plan.diameter,
            colour: station_style(k).colour,
        });
    }
    let shown = shown_pose(plan, selected);
    let mut crossed = 0;
    for (i, p) in plan.poses.iter().enumerate() {
        let t = p.base_from_flange.translation.vector;
        let problem = planned_pose_problem(plan, i);
        crossed += usize::from(problem.is_some());
        scene.marks.push(Mark {
            at: [t.x, t.y, t.z],
            index: i,
            label: format!(
                "{} · station {} · {}{}",
                p.id,
                p.station,
                p.usage.as_str(),
                problem
                    .as_ref()
                    .map_or_else(String::new, |w| format!(" · ✗ {w}"))
            ),
            colour: station_style(station_k(&p.station)).colour,
            selected: shown == Some(i),
            crossed: problem.is_some(),
        });
    }
    let Some(i) = shown else {
        return (scene, crossed);
    };
    let p = &plan.poses[i];
    scene.lines.push(Line3 {
        points: link_polyline(robot, &p.joints),
        stroke: Stroke::new(5.0, LINK),
    });
    let flange = p.base_from_flange;
    let sensor = flange * plan.flange_from_sensor;
    axes_lines(&frame_axes(&flange, axis), 2.5, &mut scene.lines);
    axes_lines(&frame_axes(&sensor, axis), 2.5, &mut scene.lines);
    let (a, b) = (flange.translation.vector, sensor.translation.vector);
    scene.lines.push(Line3 {
        points: vec![[a.x, a.y, a.z], [b.x, b.y, b.z]],
        stroke: Stroke::new(3.0, LINK),
    });
    let extent = plan.range.map_or_else(
        || fan_around(&p.centre_in_sensor, 0.5 * plan.diameter),
        |r| crate::engine::tools::scene::FanExtent { y: r.y, z: r.z },
    );
    let fan = laser_fan(&sensor, &extent);
    scene
        .triangles
        .push(([fan[0], fan[1], fan[2]], LASER.gamma_multiply(0.18)));
    scene.lines.push(Line3 {
        points: vec![fan[1], fan[0], fan[2]],
        stroke: Stroke::new(1.0, LASER.gamma_multiply(0.7)),
    });
    scene.lines.push(Line3 {
        points: vec![fan[1], fan[2], fan[3], fan[4], fan[1]],
        stroke: Stroke::new(1.0, LASER),
    });
    (scene, crossed)
}

/// The scene of the plan on show, with its caption; a pose picked there
/// becomes the selected one (and its row is shown in the table).
pub fn plan_scene_ui(ui: &mut egui::Ui, forms: &mut Forms, plan: &Plan, stale: bool) {
    ui.label(RichText::new("The planned poses in the cell (3-D)").strong());
    let selected = forms.scene.plan_pose;
    let (scene, crossed) = plan_scene(plan, selected);
    let shown = shown_pose(plan, selected);
    let mut caption = shown.map_or_else(String::new, |i| {
        let p = &plan.poses[i];
        format!(
            "{} (station {}, {}, side {:+}): the robot from the nominal model, flange and sensor frames (x red, y green, z blue), the laser fan; a mark at every pose's flange, coloured by station; the sphere at every station. ",
            p.id,
            p.station,
            p.usage.as_str(),
            p.side
        )
    });
    caption.push_str(&if crossed == 0 {
        format!("All {} poses run as planned.", plan.poses.len())
    } else {
        format!(
            "✗ {crossed} of {} poses cannot be run as planned (crossed; the reason on hover).",
            plan.poses.len()
        )
    });
    if stale {
        caption.push_str(" STALE: the poses of the plan as it was made.");
    }
    if let Some(i) = crate::app::scene::ui::scene_ui(
        ui,
        "plan",
        &mut forms.scene.plan,
        &scene,
        &caption,
        SCENE_HEIGHT,
    ) {
        forms.scene.plan_pose = Some(i);
        // The table opens on the row picked.
        ui.data_mut(|d| d.insert_temp(scroll_id(), i));
    }
    if crossed > 0 {
        let text =
            format!("{crossed} planned poses cannot be run as planned: press Make plan again");
        coloured(ui, BAD, text);
    }
}

/// Where the row to scroll to once is kept (egui's memory).
fn scroll_id() -> egui::Id {
    egui::Id::unique("plan_pose_scroll_to")
}

/// The poses in plan order, one row each; a click selects a pose (the
/// scene shows it), the selected row is highlighted, and the row a pick
/// in the scene chose is scrolled to once.
pub fn poses_table_ui(ui: &mut egui::Ui, forms: &mut Forms, plan: &Plan) {
    let selected = shown_pose(plan, forms.scene.plan_pose);
    let scroll_to: Option<usize> = ui.data(|d| d.get_temp(scroll_id()));
    egui::CollapsingHeader::new(format!("the {} poses in plan order", plan.poses.len()))
        .id_salt("plan_poses")
        .open(scroll_to.map(|_| true))
        .show(ui, |ui| {
            let scroll = egui::ScrollArea::vertical().id_salt("plan_pose_table");
            scroll.max_height(260.0).show(ui, |ui| {
                let headers = ["id", "station", "use", "side", "joints (deg)"];
                table(ui, "plan_pose_grid", &headers, |ui| {
                    for (i, p) in plan.poses.iter().enumerate() {
                        let row = ui.selectable_label(selected == Some(i), &p.id);
                        if row.clicked() {
                            forms.scene.plan_pose = Some(i);
                        }
                        if scroll_to == Some(i) {
                            // Just into sight (the scene above stays in
                            // view as far as it can), once the row is
                            // laid out.
                            row.scroll_to_me(None);
                            ui.data_mut(|d| d.remove::<usize>(scroll_id()));
                        }
                        ui.label(&p.station);
                        ui.label(p.usage.as_str());
                        ui.label(format!("{:+}", p.side));
                        let joints: Vec<String> =
                            p.joints.iter().map(|q| format!("{q:8.3}")).collect();
                        ui.label(RichText::new(joints.join(" ")).monospace());
                        ui.end_row();
                    }
                });
            });
        });
    if plan.poses.is_empty() {
        ui.label(RichText::new("no poses").color(MUTED));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::base::robot::presets;
    use crate::engine::calibrate::solve::Control;
    use crate::engine::tools::plan::{PlanConfig, plan};

    fn small_plan() -> Plan {
        let mut config = PlanConfig::for_preset(&presets::irb2400(), [1050.0, 0.0, 475.0]);
        config.design.n_identify = 3;
        config.design.n_validate = 2;
        config.design.identify_poses = 4;
        config.design.validate_poses = 3;
        plan(&config, &mut |_| Control::Continue).expect("plan")
    }

    #[test]
    fn the_plan_scene_has_every_pose_the_stations_and_the_selected_robot() {
        let plan = small_plan();
        let n = plan.poses.len();
        let (scene, crossed) = plan_scene(&plan, Some(5));
        assert_eq!(crossed, 0);
        assert_eq!(scene.marks.len(), n);
        assert!(scene.marks.iter().all(|m| !m.crossed));
        assert_eq!(scene.marks.iter().filter(|m| m.selected).count(), 1);
        assert!(scene.marks[5].selected);
        assert_eq!(scene.spheres.len(), plan.stations.len());
        // The robot at pose 5 reaches its flange mark.
        let links: Vec<&Line3> = scene
            .lines
            .iter()
            .filter(|l| l.stroke.width == 5.0)
            .collect();
        assert_eq!(links.len(), 1);
        let end = links[0].points.last().expect("end");
        let d = (0..3)
            .map(|k| (end[k] - scene.marks[5].at[k]).powi(2))
            .sum::<f64>();
        assert!(d.sqrt() < 1e-6, "{end:?} vs {:?}", scene.marks[5].at);
        // The fan holds the station's sphere: its far edge beyond it.
        assert_eq!(scene.triangles.len(), 1);
        // A selection beyond the plan shows the first pose.
        let (scene, _) = plan_scene(&plan, Some(n + 3));
        assert!(scene.marks[0].selected);
    }

    #[test]
    fn a_pose_that_cannot_be_run_is_crossed_and_named() {
        let mut plan = small_plan();
        plan.poses[2].joints[0] = plan.limits[0].max + 10.0;
        let (scene, crossed) = plan_scene(&plan, None);
        assert_eq!(crossed, 1);
        assert!(scene.marks[2].crossed);
        assert!(
            scene.marks[2].label.contains("✗ joint 1 at"),
            "{}",
            scene.marks[2].label
        );
        assert_eq!(scene.marks.iter().filter(|m| m.crossed).count(), 1);
    }
}
