//! The scene of a fixed-sensor cell (FORMAT.md `sensor.mount: "fixed"`):
//! the sensor (a tracker, a camera, a scanner) fixed in the base frame at
//! `base_from_sensor`, a mark at every pose's target (a station's point
//! on the flange, carried to the base frame by the flange pose), and at
//! the selected pose the robot, the flange frame, the lever from the
//! flange to the target, the target's sphere, the line of sight from the
//! sensor and what the sensor measured there. Built for the Session view
//! (the nominal model, the initial `base_from_sensor`, the targets as the
//! session puts them) and the Results view (the calibrated ones).

use std::collections::HashMap;

use egui::{Color32, RichText, Stroke};
use nalgebra::{Isometry3, Point3};

use super::content::{LASER, LINK, axes_lines};
use super::{Camera, Line3, Mark, Scene, Sphere3};
use crate::app::widgets::{MUTED, station_style};
use crate::engine::base::robot::Robot;
use crate::engine::files::format::ResultFile;
use crate::engine::tools::scene::{
    FanExtent, frame_axes, laser_fan, link_polyline, stripe_in_base,
};

/// The line of sight.
pub const SIGHT: Color32 = Color32::from_rgb(255, 220, 90);

/// What the sensor reported at a pose, in its own frame.
#[derive(Debug, Clone, PartialEq)]
pub enum Seen {
    /// A point (a tracker's SMR, a fitted sphere centre), mm.
    Point([f64; 3]),
    /// A stripe `[y, z]` in the laser plane, mm, and the fan around it.
    Stripe(Vec<[f64; 2]>, Option<FanExtent>),
}

/// One pose of a fixed-sensor cell.
#[derive(Debug, Clone, PartialEq)]
pub struct CellPose {
    /// What a pick of it gives (a measurement's index).
    pub index: usize,
    /// Its id.
    pub id: String,
    /// The station (the target on the flange) it saw.
    pub station: String,
    /// The flange pose, mm in **B**.
    pub flange: Isometry3<f64>,
    /// The joints, deg, when the robot is drawn.
    pub joints: Option<Vec<f64>>,
    /// What the sensor reported.
    pub seen: Option<Seen>,
    /// Used by the calibration (muted when left out).
    pub used: bool,
}

/// A fixed-sensor cell to draw.
#[derive(Debug, Clone, PartialEq)]
pub struct FixedCell<'a> {
    /// The robot (none for a pose-only session).
    pub robot: Option<&'a Robot>,
    /// `bT_s`, when known.
    pub base_from_sensor: Option<Isometry3<f64>>,
    /// Each station's point in the flange frame, mm, in station order.
    pub targets: Vec<(String, [f64; 3])>,
    /// The poses.
    pub poses: Vec<CellPose>,
    /// The target's radius (an SMR, a ball), mm.
    pub radius: f64,
}

/// The pose shown: `selected` when it is one of the cell's, else the first.
#[must_use]
pub fn shown_pose(cell: &FixedCell<'_>, selected: Option<usize>) -> Option<usize> {
    selected
        .and_then(|s| cell.poses.iter().position(|p| p.index == s))
        .or((!cell.poses.is_empty()).then_some(0))
}

fn at(p: &Point3<f64>) -> [f64; 3] {
    [p.x, p.y, p.z]
}

/// The cell's scene, measurement `selected` (the first when none) shown.
#[must_use]
pub fn fixed_cell_scene(cell: &FixedCell<'_>, selected: Option<usize>) -> Scene {
    let mut scene = Scene::default();
    let base = cell.robot.map_or_else(Isometry3::identity, |r| r.base);
    let sensor = cell.base_from_sensor;
    let reach = cell
        .poses
        .iter()
        .map(|p| (p.flange.translation.vector - base.translation.vector).norm())
        .chain(sensor.map(|s| (s.translation.vector - base.translation.vector).norm()))
        .fold(0.0, f64::max);
    let axis = (0.08 * reach).clamp(20.0, 150.0);
    axes_lines(&frame_axes(&base, 2.0 * axis), 2.0, &mut scene.lines);
    if let Some(s) = sensor {
        axes_lines(&frame_axes(&s, 1.5 * axis), 3.0, &mut scene.lines);
        scene.spheres.push(Sphere3 {
            centre: at(&(s * Point3::origin())),
            radius: 0.25 * axis,
            colour: SIGHT,
        });
    }
    let target: HashMap<&str, (usize, [f64; 3])> = cell
        .targets
        .iter()
        .enumerate()
        .map(|(k, (id, p))| (id.as_str(), (k, *p)))
        .collect();
    let in_base = |p: &CellPose| {
        target
            .get(p.station.as_str())
            .map(|(k, t)| (*k, at(&(p.flange * Point3::new(t[0], t[1], t[2])))))
    };
    let shown = shown_pose(cell, selected);
    for (j, p) in cell.poses.iter().enumerate() {
        let Some((k, t)) = in_base(p) else {
            continue;
        };
        scene.marks.push(Mark {
            at: t,
            index: p.index,
            label: format!(
                "{} · target {}{}",
                p.id,
                p.station,
                if p.used { "" } else { " (left out)" }
            ),
            colour: if p.used {
                station_style(k).colour
            } else {
                MUTED
            },
            selected: shown == Some(j),
            crossed: false,
        });
    }
    let Some(p) = shown.map(|j| &cell.poses[j]) else {
        return scene;
    };
    if let (Some(robot), Some(q)) = (cell.robot, &p.joints) {
        scene.lines.push(Line3 {
            points: link_polyline(robot, q),
            stroke: Stroke::new(5.0, LINK),
        });
    }
    axes_lines(&frame_axes(&p.flange, axis), 2.5, &mut scene.lines);
    let target_at = in_base(p).map(|(k, t)| {
        let f = at(&(p.flange * Point3::origin()));
        // The lever from the flange to the target, and the target.
        scene.lines.push(Line3 {
            points: vec![f, t],
            stroke: Stroke::new(3.0, LINK),
        });
        if cell.radius > 0.0 {
            scene.spheres.push(Sphere3 {
                centre: t,
                radius: cell.radius,
                colour: station_style(k).colour,
            });
        }
        t
    });
    let Some(s) = sensor else {
        return scene;
    };
    let origin = at(&(s * Point3::origin()));
    match &p.seen {
        Some(Seen::Point(c)) => {
            let m = at(&(s * Point3::new(c[0], c[1], c[2])));
            scene.lines.push(Line3 {
                points: vec![origin, m],
                stroke: Stroke::new(1.5, SIGHT),
            });
            scene.points.push((m, LASER));
        }
        Some(Seen::Stripe(pts, fan)) => {
            if let Some(e) = fan {
                let fan = laser_fan(&s, e);
                scene
                    .triangles
                    .push(([fan[0], fan[1], fan[2]], LASER.gamma_multiply(0.18)));
                scene.lines.push(Line3 {
                    points: vec![fan[1], fan[2], fan[3], fan[4], fan[1]],
                    stroke: Stroke::new(1.0, LASER),
                });
            }
            for q in stripe_in_base(&s, pts) {
                scene.points.push((q, LASER));
            }
            if let Some(t) = target_at {
                scene.lines.push(Line3 {
                    points: vec![origin, t],
                    stroke: Stroke::new(1.5, SIGHT),
                });
            }
        }
        None => {
            if let Some(t) = target_at {
                scene.lines.push(Line3 {
                    points: vec![origin, t],
                    stroke: Stroke::new(1.5, SIGHT),
                });
            }
        }
    }
    scene
}

/// What the fixed cell's scene shows, in words, for pose `shown`.
#[must_use]
pub fn caption(cell: &FixedCell<'_>, shown: Option<usize>, calibrated: bool) -> String {
    let model = if calibrated {
        "calibrated base_from_sensor and model"
    } else {
        "initial base_from_sensor, the nominal model"
    };
    let mut text = format!(
        "Fixed sensor (yellow ball) at the {model}; a dot at every pose's target on the flange. "
    );
    if let Some(p) = shown.and_then(|j| cell.poses.get(j)) {
        text.push_str(&format!(
            "{} (target {}): {}the lever to the target, the line of sight, the measured point (red).",
            p.id,
            p.station,
            if cell.robot.is_some() && p.joints.is_some() {
                "the robot, "
            } else {
                ""
            }
        ));
    }
    if cell.base_from_sensor.is_none() {
        text.push_str(" base_from_sensor is not known: the sensor is not drawn.");
    }
    text
}

/// The cell of a fixed-sensor result: the calibrated robot at the joints
/// of each pose the result records (`pose_joints`), the calibrated
/// targets (`stations`) and `base_from_sensor`, each pose's measured
/// point (`centres[].sensor`); `radius` of the target, mm (0: the target
/// is drawn as its mark only).
#[must_use]
pub fn result_cell(file: &ResultFile, radius: f64) -> FixedCell<'_> {
    let joints: HashMap<&str, &Vec<f64>> = file
        .pose_joints
        .iter()
        .map(|(id, q)| (id.as_str(), q))
        .collect();
    let poses = match &file.robot {
        Some(robot) => file
            .centres
            .iter()
            .enumerate()
            .filter_map(|(i, c)| {
                let q = joints.get(c.measurement.as_str())?;
                Some(CellPose {
                    index: i,
                    id: c.measurement.clone(),
                    station: c.station.clone(),
                    flange: robot.base_from_flange(q),
                    joints: Some((*q).clone()),
                    seen: Some(Seen::Point(c.sensor)),
                    used: true,
                })
            })
            .collect(),
        None => Vec::new(),
    };
    FixedCell {
        robot: file.robot.as_ref(),
        base_from_sensor: Some(file.hand_eye),
        targets: file
            .stations
            .iter()
            .map(|s| (s.id.clone(), s.point))
            .collect(),
        poses,
        radius,
    }
}

/// Height of the Results view's scene, points.
const RESULTS_HEIGHT: f32 = 360.0;

/// The Results view's scene of a fixed-sensor result; its camera and the
/// pose picked are kept in egui's memory (the Results view's forms are
/// not touched).
pub fn results_scene_ui(ui: &mut egui::Ui, file: &ResultFile) {
    let cell = result_cell(file, 0.0);
    ui.add_space(8.0);
    ui.label(RichText::new("The cell (3-D): the sensor, the targets at every pose").strong());
    if cell.poses.is_empty() {
        ui.label(
            RichText::new(
                "The result records no joints of its poses (pose-only, or written before pose_joints): only the sensor and the base frame are drawn.",
            )
            .color(MUTED),
        );
    }
    let id = egui::Id::unique("results_fixed_scene");
    let (mut camera, selected) = ui.data_mut(|d| {
        d.get_temp::<(Camera, Option<usize>)>(id)
            .unwrap_or_default()
    });
    let scene = fixed_cell_scene(&cell, selected);
    let text = caption(&cell, shown_pose(&cell, selected), true);
    let picked = super::ui::scene_ui(ui, "results", &mut camera, &scene, &text, RESULTS_HEIGHT);
    let selected = picked.or(selected);
    ui.data_mut(|d| d.insert_temp(id, (camera, selected)));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::base::geometry::{rot_x, trans};
    use crate::engine::base::robot::presets;

    #[test]
    fn the_targets_ride_on_the_flange_and_the_sensor_stands_still() {
        let robot = presets::irb2400().robot;
        let sensor = trans(2500.0, 0.0, 800.0) * rot_x(0.4);
        let q = [[0.0; 6], [10.0, -20.0, 15.0, 30.0, -40.0, 60.0]];
        let lever = [0.0, 50.0, 120.0];
        let poses: Vec<CellPose> = q
            .iter()
            .enumerate()
            .map(|(i, q)| {
                let flange = robot.base_from_flange(q);
                let t = sensor.inverse() * (flange * Point3::new(lever[0], lever[1], lever[2]));
                CellPose {
                    index: i,
                    id: format!("f{i}"),
                    station: "T1".into(),
                    flange,
                    joints: Some(q.to_vec()),
                    seen: Some(Seen::Point([t.x, t.y, t.z])),
                    used: true,
                }
            })
            .collect();
        let cell = FixedCell {
            robot: Some(&robot),
            base_from_sensor: Some(sensor),
            targets: vec![("T1".into(), lever)],
            poses,
            radius: 6.35,
        };
        let scene = fixed_cell_scene(&cell, Some(1));
        assert_eq!(scene.marks.len(), 2);
        assert!(scene.marks[1].selected);
        // The measured point (exact data) is where the target is.
        let m = scene.points[0].0;
        let t = scene.marks[1].at;
        let d = (0..3).map(|k| (m[k] - t[k]).powi(2)).sum::<f64>().sqrt();
        assert!(d < 1e-9, "{d}");
        // The line of sight runs from the sensor's origin to it.
        let sight: Vec<&Line3> = scene
            .lines
            .iter()
            .filter(|l| l.stroke.color == SIGHT)
            .collect();
        assert_eq!(sight.len(), 1);
        assert_eq!(sight[0].points[0], [2500.0, 0.0, 800.0]);
        // The robot at pose 1 ends at its flange; the sensor is a sphere
        // at its origin, the target another.
        let links: Vec<&Line3> = scene
            .lines
            .iter()
            .filter(|l| l.stroke.width == 5.0)
            .collect();
        assert_eq!(links.len(), 1);
        let f = cell.poses[1].flange.translation.vector;
        let end = links[0].points.last().expect("end");
        assert!((end[0] - f.x).abs() + (end[1] - f.y).abs() + (end[2] - f.z).abs() < 1e-9);
        assert_eq!(scene.spheres.len(), 2);
        assert_eq!(scene.spheres[0].centre, [2500.0, 0.0, 800.0]);
        assert!(caption(&cell, Some(1), false).contains("f1 (target T1): the robot"));
        // Without base_from_sensor: no sensor, no sight, said.
        let blind = FixedCell {
            base_from_sensor: None,
            ..cell
        };
        let scene = fixed_cell_scene(&blind, Some(0));
        assert!(scene.lines.iter().all(|l| l.stroke.color != SIGHT));
        assert!(caption(&blind, Some(0), false).contains("not known"));
    }
}
