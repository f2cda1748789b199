//! The Session view's 3-D scene: every pose's mark, the robot at the
//! selected pose with its flange and sensor frames, the laser fan and
//! the stripe, the sphere at every station; for a fixed sensor the cell
//! of [`crate::app::scene::fixed`] (the sensor in the base frame, the
//! targets on the flange, the line of sight). Geometry from the engine
//! ([`crate::engine::tools::scene`]); here only what goes in and its
//! colours.

use std::collections::BTreeSet;

use egui::Stroke;
use nalgebra::Isometry3;

use super::LoadedSession;
use crate::app::scene::content::{LASER, LINK, axes_lines};
use crate::app::scene::fixed::{CellPose, FixedCell, Seen, fixed_cell_scene};
use crate::app::scene::{Line3, Mark, Scene, Sphere3};
use crate::app::widgets::{MUTED, station_style};
use crate::engine::base::session::{Mount, Observation};
use crate::engine::tools::scene::{
    fan_extent, frame_axes, laser_fan, link_polyline, stripe_in_base,
};

/// The session's scene: a mark at every pose's flange (coloured by
/// station, muted when left out; frames too for a pose-only session),
/// the base frame, the sphere at every station where the nominal model
/// puts it, and at the `selected` measurement (the first when none) the
/// robot's links, the flange and sensor frames, the laser fan and the
/// stripe.
#[must_use]
pub fn session_scene(
    loaded: &LoadedSession,
    selected: Option<usize>,
    excluded: &BTreeSet<String>,
) -> Scene {
    let session = &loaded.session;
    let robot = &session.robot;
    let pose_only = session.pose_only();
    let hand_eye = initial_hand_eye(loaded);
    if session.mount == Mount::Fixed {
        return fixed_cell_scene(&fixed_cell(loaded, excluded), selected);
    }
    let flanges: Vec<Isometry3<f64>> = (0..session.measurements.len())
        .map(|i| session.base_from_flange(robot, i))
        .collect();
    let reach = flanges
        .iter()
        .map(|f| (f.translation.vector - robot.base.translation.vector).norm())
        .fold(0.0, f64::max);
    let axis = (0.08 * reach).clamp(20.0, 150.0);
    let mut scene = Scene::default();
    let base = if pose_only {
        Isometry3::identity()
    } else {
        robot.base
    };
    axes_lines(&frame_axes(&base, 2.0 * axis), 2.0, &mut scene.lines);
    let centres = loaded.before.as_ref().ok();
    let stations = loaded.station_ids();
    let station_k = |s: &str| {
        centres.map_or_else(
            || stations.iter().position(|x| x == s).unwrap_or(0),
            |c| c.station_index(s),
        )
    };
    if let Some(c) = centres {
        for (k, (before, _)) in c.means.iter().enumerate() {
            scene.spheres.push(Sphere3 {
                centre: *before,
                radius: session.sphere_radius(),
                colour: station_style(k).colour,
            });
        }
    }
    for (i, (m, f)) in session.measurements.iter().zip(&flanges).enumerate() {
        let t = f.translation.vector;
        let used = !excluded.contains(&m.id);
        if pose_only {
            axes_lines(&frame_axes(f, 0.5 * axis), 1.0, &mut scene.lines);
        }
        scene.marks.push(Mark {
            at: [t.x, t.y, t.z],
            index: i,
            label: format!(
                "{} · station {}{}",
                m.id,
                m.station,
                if used { "" } else { " (left out)" }
            ),
            colour: if used {
                station_style(station_k(&m.station)).colour
            } else {
                MUTED
            },
            selected: selected == Some(i),
            crossed: false,
        });
    }
    let Some(i) = selected.or((!session.measurements.is_empty()).then_some(0)) else {
        return scene;
    };
    let m = &session.measurements[i];
    let flange = flanges[i];
    if !pose_only {
        scene.lines.push(Line3 {
            points: link_polyline(robot, &m.joints),
            stroke: Stroke::new(5.0, LINK),
        });
    }
    axes_lines(&frame_axes(&flange, axis), 2.5, &mut scene.lines);
    let Some(hand_eye) = hand_eye else {
        return scene;
    };
    let sensor = flange * hand_eye;
    axes_lines(&frame_axes(&sensor, axis), 2.5, &mut scene.lines);
    // The mount: flange to sensor.
    let (a, b) = (flange.translation.vector, sensor.translation.vector);
    scene.lines.push(Line3 {
        points: vec![[a.x, a.y, a.z], [b.x, b.y, b.z]],
        stroke: Stroke::new(3.0, LINK),
    });
    if let Some(extent) = fan_extent(session, i) {
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
    }
    match &m.observation {
        Observation::Stripe(pts) => {
            for p in stripe_in_base(&sensor, pts) {
                scene.points.push((p, LASER));
            }
        }
        Observation::Centre(c) => {
            let p = sensor * nalgebra::Point3::from(*c);
            scene.points.push(([p.x, p.y, p.z], LASER));
        }
    }
    scene
}

/// The hand-eye the scene draws: the initial one of the analysis, else
/// the session's.
fn initial_hand_eye(loaded: &LoadedSession) -> Option<Isometry3<f64>> {
    loaded
        .analysis
        .hand_eye
        .as_ref()
        .ok()
        .map(|(h, _)| *h)
        .or(loaded.session.hand_eye)
}

/// A fixed-sensor session's cell: the nominal robot (none for a
/// pose-only session), the initial `base_from_sensor`, each target where
/// the session puts it (its station's mean point in the flange frame),
/// every pose with what the sensor reported.
#[must_use]
pub fn fixed_cell<'a>(loaded: &'a LoadedSession, excluded: &BTreeSet<String>) -> FixedCell<'a> {
    let session = &loaded.session;
    let pose_only = session.pose_only();
    let targets = loaded.before.as_ref().map_or_else(
        |_| Vec::new(),
        |c| {
            c.stations
                .iter()
                .cloned()
                .zip(c.means.iter().map(|m| m.0))
                .collect()
        },
    );
    let poses = session
        .measurements
        .iter()
        .enumerate()
        .map(|(i, m)| CellPose {
            index: i,
            id: m.id.clone(),
            station: m.station.clone(),
            flange: session.base_from_flange(&session.robot, i),
            joints: (!pose_only).then(|| m.joints.clone()),
            seen: Some(match &m.observation {
                Observation::Centre(c) => Seen::Point([c.x, c.y, c.z]),
                Observation::Stripe(p) => Seen::Stripe(p.clone(), fan_extent(session, i)),
            }),
            used: !excluded.contains(&m.id),
        })
        .collect();
    FixedCell {
        robot: (!pose_only).then_some(&session.robot),
        base_from_sensor: initial_hand_eye(loaded),
        targets,
        poses,
        radius: session.sphere_radius(),
    }
}

/// The Session view's caption under the scene for measurement `shown`.
#[must_use]
pub fn session_caption(
    loaded: &LoadedSession,
    shown: usize,
    excluded: &BTreeSet<String>,
) -> String {
    if loaded.session.mount == Mount::Fixed {
        let cell = fixed_cell(loaded, excluded);
        return crate::app::scene::fixed::caption(
            &cell,
            crate::app::scene::fixed::shown_pose(&cell, Some(shown)),
            false,
        );
    }
    loaded
        .session
        .measurements
        .get(shown)
        .map_or_else(String::new, |m| {
            let what = if loaded.session.pose_only() {
                "pose-only: the flange poses as frames"
            } else {
                "the robot from the nominal model"
            };
            format!(
                "{} (station {}): {what}, flange and sensor frames (x red, y green, z blue), the laser fan and stripe; the sphere at every station where the nominal model puts it",
                m.id, m.station
            )
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::session::{Source, analyse, open_demo};

    /// Lines as wide as the robot's links.
    fn links(scene: &Scene) -> Vec<&Line3> {
        scene
            .lines
            .iter()
            .filter(|l| l.stroke.width == 5.0)
            .collect()
    }

    #[test]
    fn the_session_scene_has_every_pose_and_the_selected_robot() {
        let loaded = open_demo().expect("demo");
        let n = loaded.session.measurements.len();
        let scene = session_scene(&loaded, Some(7), &BTreeSet::new());
        assert_eq!(scene.marks.len(), n);
        assert_eq!(scene.marks.iter().filter(|m| m.selected).count(), 1);
        assert!(scene.marks[7].selected);
        // The robot at pose 7 reaches that pose's flange mark.
        let robot = links(&scene);
        assert_eq!(robot.len(), 1);
        assert_eq!(robot[0].points.last(), Some(&scene.marks[7].at));
        // A sphere a station, the stripe's points among the points.
        let stations = loaded.station_ids().len();
        assert_eq!(scene.spheres.len(), stations);
        let stripe = match &loaded.session.measurements[7].observation {
            Observation::Stripe(p) => p.len(),
            Observation::Centre(_) => 1,
        };
        assert_eq!(scene.points.len(), stripe);
        assert_eq!(scene.triangles.len(), 1, "the laser fan");
        // The stripe lies on its station's sphere (nominal model): within
        // a few mm of the sphere's surface.
        let m = &loaded.session.measurements[7];
        let k = loaded
            .before
            .as_ref()
            .expect("centres")
            .station_index(&m.station);
        let c = scene.spheres[k].centre;
        let r = loaded.session.sphere_radius();
        for (p, _) in &scene.points {
            let d = ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2) + (p[2] - c[2]).powi(2)).sqrt();
            assert!((d - r).abs() < 5.0, "{d} vs {r}");
        }
        // A left-out pose is muted.
        let left = BTreeSet::from([loaded.session.measurements[3].id.clone()]);
        let scene = session_scene(&loaded, None, &left);
        assert_eq!(scene.marks[3].colour, MUTED);
        assert!(scene.marks[3].label.ends_with("(left out)"));
    }

    #[test]
    fn a_pose_only_session_shows_frames_and_no_robot() {
        let demo = open_demo().expect("demo");
        let mut session = demo.session.clone();
        for m in &mut session.measurements {
            m.flange = Some(session.robot.base_from_flange(&m.joints));
        }
        assert!(session.pose_only());
        let loaded = analyse(session, Source::Demo);
        let scene = session_scene(&loaded, Some(2), &BTreeSet::new());
        assert!(links(&scene).is_empty(), "no robot drawn without a model");
        let n = loaded.session.measurements.len();
        assert_eq!(scene.marks.len(), n);
        // Three axes a pose, the base's, the flange's and the sensor's.
        let axes = scene.lines.iter().filter(|l| l.points.len() == 2).count();
        assert!(axes >= 3 * n + 9, "{axes} axes for {n} poses");
        assert_eq!(scene.spheres.len(), loaded.station_ids().len());
        assert_eq!(scene.triangles.len(), 1);
    }

    #[test]
    fn a_fixed_sensor_session_shows_the_tracker_and_the_targets_on_the_flange() {
        use crate::engine::tools::simulate::SimConfig;
        use crate::engine::tools::simulate::fixed::{FixedCell, simulate_fixed};
        let cell = FixedCell::tracker(0.0);
        let (session, _) = simulate_fixed(&SimConfig::default(), &cell).expect("simulate");
        let loaded = analyse(session, Source::Simulated);
        let n = loaded.session.measurements.len();
        let scene = session_scene(&loaded, Some(4), &BTreeSet::new());
        assert_eq!(scene.marks.len(), n, "a mark at every pose's target");
        assert!(scene.marks[4].selected);
        // The sensor stands where the initial base_from_sensor (the
        // engine's linear start, nominal model) puts it: the tracker's
        // place within a few per cent of its distance (the nominal model's
        // errors are taken up by it).
        let sensor = scene.spheres[0].centre;
        let start = initial_hand_eye(&loaded)
            .expect("a start")
            .translation
            .vector;
        assert_eq!(sensor, [start.x, start.y, start.z]);
        let truth = cell.base_from_sensor.translation.vector;
        let off = (start - truth).norm();
        assert!(
            off < 0.05 * truth.norm(),
            "the sensor {off:.1} mm from the truth"
        );
        // What the tracker measured at pose 4, carried to the base frame,
        // lies at that pose's target (the nominal model: a few mm).
        let measured = scene.points[0].0;
        let target = scene.marks[4].at;
        let d = (0..3)
            .map(|k| (measured[k] - target[k]).powi(2))
            .sum::<f64>()
            .sqrt();
        assert!(d < 5.0, "{d:.2} mm");
        // The line of sight from the sensor to it.
        let sight = scene
            .lines
            .iter()
            .filter(|l| l.stroke.color == crate::app::scene::fixed::SIGHT)
            .count();
        assert_eq!(sight, 1);
        assert!(session_caption(&loaded, 4, &BTreeSet::new()).starts_with("Fixed sensor"));
        // Not the flange mount's sensor on the flange: no laser fan.
        assert!(scene.triangles.is_empty());
    }
}
