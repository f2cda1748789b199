//! The geometry of the cell as the workbench's 3-D scene draws it, in
//! the robot base frame **B** (mm): the robot's links from the model's
//! forward kinematics, the flange and sensor frames, the laser fan, the
//! stripe where the sensor saw it. Headless and drawn by nobody here:
//! the app projects these points; the tests check them against the
//! model.

use nalgebra::{Isometry3, Point3, Vector3};

use crate::engine::base::robot::Robot;
use crate::engine::base::session::{Observation, Session};
use crate::engine::tools::plan::Plan;

/// A frame drawn as three axes: its origin and the ends of its x, y and
/// z axes, mm in **B**.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameAxes {
    /// The frame's origin.
    pub origin: [f64; 3],
    /// The ends of its x, y and z axes, each `length` from the origin.
    pub ends: [[f64; 3]; 3],
}

/// The axes of `pose` (a frame in **B**), each `length` mm long.
#[must_use]
pub fn frame_axes(pose: &Isometry3<f64>, length: f64) -> FrameAxes {
    let at = |v: Vector3<f64>| point(&(pose * Point3::from(v)));
    FrameAxes {
        origin: at(Vector3::zeros()),
        ends: [
            at(Vector3::x() * length),
            at(Vector3::y() * length),
            at(Vector3::z() * length),
        ],
    }
}

fn point(p: &Point3<f64>) -> [f64; 3] {
    [p.x, p.y, p.z]
}

/// The robot drawn as a polyline: the base frame's origin, the origin of
/// each joint's frame in turn (the MDH chain of
/// [`Robot::base_from_flange`]) and the flange, for joint readings
/// `q_deg`. Its last point is the flange's origin exactly.
#[must_use]
pub fn link_polyline(robot: &Robot, q_deg: &[f64]) -> Vec<[f64; 3]> {
    let mut t = robot.base;
    let mut out = Vec::with_capacity(robot.joints.len() + 2);
    out.push(point(&(t * Point3::origin())));
    for (joint, q) in robot.joints.iter().zip(q_deg) {
        t *= joint.link(*q);
        out.push(point(&(t * Point3::origin())));
    }
    let flange = point(&((t * robot.flange) * Point3::origin()));
    if out.last() != Some(&flange) {
        out.push(flange);
    }
    out
}

/// The part of the laser plane (`x = 0` of the sensor frame) the fan
/// covers: `y` from `y[0]` to `y[1]`, `z` from `z[0]` to `z[1]`, mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FanExtent {
    /// Across the stripe, mm.
    pub y: [f64; 2],
    /// Along the view, mm (distance from the sensor).
    pub z: [f64; 2],
}

/// Margin around what a measurement saw when the fan is drawn from its
/// own points, mm.
const FAN_MARGIN: f64 = 10.0;

/// The fan of measurement `i`: the session's measuring range when it has
/// one; else the extent of the measurement's stripe (or of the sphere
/// around a given centre) with a margin of [`FAN_MARGIN`]; `None` when
/// neither tells (no range and no points).
#[must_use]
pub fn fan_extent(session: &Session, i: usize) -> Option<FanExtent> {
    if let Some(r) = session.sensor_range {
        return Some(FanExtent { y: r.y, z: r.z });
    }
    let m = session.measurements.get(i)?;
    let (lo, hi) = match &m.observation {
        Observation::Stripe(pts) if !pts.is_empty() => pts.iter().fold(
            ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]),
            |(lo, hi), p| {
                (
                    [lo[0].min(p[0]), lo[1].min(p[1])],
                    [hi[0].max(p[0]), hi[1].max(p[1])],
                )
            },
        ),
        Observation::Centre(c) => return Some(fan_around(c, session.sphere_radius())),
        Observation::Stripe(_) => return None,
    };
    Some(FanExtent {
        y: [lo[0] - FAN_MARGIN, hi[0] + FAN_MARGIN],
        z: [(lo[1] - FAN_MARGIN).max(0.0), hi[1] + FAN_MARGIN],
    })
}

/// The fan around a sphere of `radius` (mm) centred at `centre` (sensor
/// frame): the sphere's extent in the laser plane with a margin of
/// [`FAN_MARGIN`].
#[must_use]
pub fn fan_around(centre: &Vector3<f64>, radius: f64) -> FanExtent {
    let r = radius + FAN_MARGIN;
    FanExtent {
        y: [centre.y - r, centre.y + r],
        z: [(centre.z - r).max(0.0), centre.z + r],
    }
}

/// Joint-limit slack a planned pose may have, deg (rounding).
const LIMIT_SLACK_DEG: f64 = 1e-6;
/// How far the nominal flange at a planned pose's joints may be from the
/// pose's flange, mm.
const FLANGE_SLACK_MM: f64 = 0.01;
/// How far the sphere may be from where the plan says the sensor sees
/// it, mm.
const SIGHT_SLACK_MM: f64 = 1.0;

/// Why planned pose `i` of `plan` cannot be run as planned, in words, or
/// `None` when it can: a joint outside the plan's limits, a flange the
/// plan's robot does not reach at the pose's joints, or the sphere not
/// where the sensor is planned to see it. A plan as the planner makes it
/// has none; a plan read from a file or made for another model may.
#[must_use]
pub fn planned_pose_problem(plan: &Plan, i: usize) -> Option<String> {
    let p = plan.poses.get(i)?;
    if p.joints.len() != plan.robot.joints.len() {
        return Some(format!(
            "{} joints for a {}-joint robot",
            p.joints.len(),
            plan.robot.joints.len()
        ));
    }
    for (k, (q, l)) in p.joints.iter().zip(&plan.limits).enumerate() {
        if *q < l.min - LIMIT_SLACK_DEG || *q > l.max + LIMIT_SLACK_DEG {
            return Some(format!(
                "joint {} at {q:.2}° is outside its limits ({:.1}…{:.1}°)",
                k + 1,
                l.min,
                l.max
            ));
        }
    }
    let flange = plan.robot.base_from_flange(&p.joints);
    let off = (flange.translation.vector - p.base_from_flange.translation.vector).norm();
    if off > FLANGE_SLACK_MM {
        return Some(format!(
            "the robot's flange at these joints is {off:.2} mm from the planned one"
        ));
    }
    let station = plan.station(&p.station)?;
    let seen = (flange * plan.flange_from_sensor).inverse() * Point3::from(station.position);
    let miss = (seen.coords - p.centre_in_sensor).norm();
    if miss > SIGHT_SLACK_MM {
        return Some(format!(
            "the sphere of station {} is {miss:.1} mm from where the sensor should see it",
            p.station
        ));
    }
    None
}

/// The factor a vector of `largest` mm is drawn enlarged by in a scene of
/// `radius` mm so that it can be seen: 1 when it is at least 2 % of the
/// radius, else the 1-2-5 step that draws it nearest 10 % of the radius
/// without passing it.
#[must_use]
pub fn arrow_scale(largest: f64, radius: f64) -> f64 {
    if !(largest.is_finite() && radius.is_finite()) || largest <= 0.0 || largest >= 0.02 * radius {
        return 1.0;
    }
    let want = 0.1 * radius / largest;
    let decade = 10f64.powf(want.log10().floor());
    [5.0, 2.0, 1.0]
        .into_iter()
        .map(|m| m * decade)
        .find(|s| *s <= want)
        .unwrap_or(decade)
        .max(1.0)
}

/// The laser fan of a sensor at `base_from_sensor` over `extent`, in
/// **B**: the sensor's origin, then the far edge's two ends (`y[0]`,
/// `z[1]`) and (`y[1]`, `z[1]`), then the near edge's (`y[1]`, `z[0]`)
/// and (`y[0]`, `z[0]`): a triangle from the origin and the measured
/// band inside it.
#[must_use]
pub fn laser_fan(base_from_sensor: &Isometry3<f64>, extent: &FanExtent) -> [[f64; 3]; 5] {
    let at = |y: f64, z: f64| point(&(base_from_sensor * Point3::new(0.0, y, z)));
    let (y, z) = (extent.y, extent.z);
    [
        at(0.0, 0.0),
        at(y[0], z[1]),
        at(y[1], z[1]),
        at(y[1], z[0]),
        at(y[0], z[0]),
    ]
}

/// The stripe points `[y, z]` of the laser plane (sensor frame) in
/// **B**.
#[must_use]
pub fn stripe_in_base(base_from_sensor: &Isometry3<f64>, points: &[[f64; 2]]) -> Vec<[f64; 3]> {
    points
        .iter()
        .map(|p| point(&(base_from_sensor * Point3::new(0.0, p[0], p[1]))))
        .collect()
}

/// The centre and the radius of the smallest axis-aligned box around
/// `points` (half its diagonal), mm; `None` without a finite point.
#[must_use]
pub fn bounds<'a>(points: impl IntoIterator<Item = &'a [f64; 3]>) -> Option<([f64; 3], f64)> {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    let mut any = false;
    for p in points {
        if p.iter().all(|v| v.is_finite()) {
            any = true;
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
    }
    any.then(|| {
        let centre = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
        let half = Vector3::new(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]).norm() / 2.0;
        (centre, half)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::base::geometry::{rot_x, trans};
    use crate::engine::base::robot::presets;
    use crate::engine::base::session::SensorRange;

    fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
        Vector3::new(a[0] - b[0], a[1] - b[1], a[2] - b[2]).norm()
    }

    #[test]
    fn the_polyline_ends_at_the_flange_of_the_forward_kinematics() {
        let robot = presets::irb2400().robot;
        for q in [[0.0; 6], [10.0, -35.0, 20.0, 45.0, -60.0, 90.0]] {
            let line = link_polyline(&robot, &q);
            let flange = robot.base_from_flange(&q);
            let end = *line.last().expect("points");
            let f = flange.translation.vector;
            assert!(dist(end, [f.x, f.y, f.z]) < 1e-9, "{end:?} vs {f:?}");
            assert_eq!(line[0], {
                let b = robot.base.translation.vector;
                [b.x, b.y, b.z]
            });
            // One point a joint between them at most.
            assert!(line.len() <= robot.joints.len() + 2);
            // The chain is as long as the links are: no point far off.
            let reach: f64 = line.windows(2).map(|w| dist(w[0], w[1])).sum();
            assert!(reach < 5000.0 && reach > 500.0, "{reach}");
        }
    }

    #[test]
    fn a_polyline_moves_with_a_joint() {
        let robot = presets::irb2400().robot;
        let a = link_polyline(&robot, &[0.0; 6]);
        let b = link_polyline(&robot, &[30.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        // Joint 1 turns everything beyond it about the base's z: heights stay.
        for (p, q) in a.iter().zip(&b) {
            assert!((p[2] - q[2]).abs() < 1e-9);
        }
        assert!(dist(*a.last().expect("a"), *b.last().expect("b")) > 10.0);
    }

    #[test]
    fn frame_axes_follow_the_pose() {
        let pose = trans(100.0, 0.0, 50.0) * rot_x(std::f64::consts::FRAC_PI_2);
        let f = frame_axes(&pose, 10.0);
        assert_eq!(f.origin, [100.0, 0.0, 50.0]);
        let near = |a: [f64; 3], b: [f64; 3]| assert!(dist(a, b) < 1e-9, "{a:?} vs {b:?}");
        near(f.ends[0], [110.0, 0.0, 50.0]);
        // x-rotation by 90°: y goes to z, z to −y.
        near(f.ends[1], [100.0, 0.0, 60.0]);
        near(f.ends[2], [100.0, -10.0, 50.0]);
    }

    #[test]
    fn the_fan_lies_in_the_laser_plane_and_holds_the_stripe() {
        let sensor = trans(10.0, 20.0, 30.0) * rot_x(0.3);
        let stripe = [[-5.0, 300.0], [0.0, 310.0], [5.0, 300.0]];
        let mut session = crate::engine::files::format::parse_session(
            crate::DEMO_SESSION_JSON,
            std::path::Path::new("demo.json"),
        )
        .expect("demo");
        session.sensor_range = None;
        session.measurements[0].observation = Observation::Stripe(stripe.to_vec());
        let e = fan_extent(&session, 0).expect("extent");
        assert_eq!(e.y, [-15.0, 15.0]);
        assert_eq!(e.z, [290.0, 320.0]);
        let fan = laser_fan(&sensor, &e);
        let inv = sensor.inverse();
        for p in fan {
            let s = inv * Point3::new(p[0], p[1], p[2]);
            assert!(s.x.abs() < 1e-9, "off the plane: {s:?}");
        }
        assert_eq!(fan[0], [10.0, 20.0, 30.0]);
        for p in stripe_in_base(&sensor, &stripe) {
            let s = inv * Point3::new(p[0], p[1], p[2]);
            assert!(s.x.abs() < 1e-9 && s.y >= e.y[0] && s.y <= e.y[1]);
            assert!(s.z >= e.z[0] && s.z <= e.z[1]);
        }
        // The session's range wins over the points.
        session.sensor_range = Some(SensorRange {
            y: [-40.0, 40.0],
            z: [250.0, 350.0],
        });
        let r = fan_extent(&session, 0).expect("range");
        assert_eq!((r.y, r.z), ([-40.0, 40.0], [250.0, 350.0]));
    }

    #[test]
    fn the_planner_s_poses_have_no_problem_and_a_broken_one_is_named() {
        let preset = presets::irb2400();
        let mut config =
            crate::engine::tools::plan::PlanConfig::for_preset(&preset, [1050.0, 0.0, 475.0]);
        config.design.n_identify = 3;
        config.design.n_validate = 2;
        config.design.identify_poses = 4;
        config.design.validate_poses = 3;
        let plan = crate::engine::tools::plan::plan(&config, &mut |_| {
            crate::engine::calibrate::solve::Control::Continue
        })
        .expect("plan");
        for i in 0..plan.poses.len() {
            assert_eq!(planned_pose_problem(&plan, i), None, "pose {i}");
        }
        assert_eq!(planned_pose_problem(&plan, plan.poses.len()), None);
        let mut broken = plan.clone();
        broken.poses[1].joints[2] = broken.limits[2].max + 5.0;
        let why = planned_pose_problem(&broken, 1).expect("outside");
        assert!(why.starts_with("joint 3 at"), "{why}");
        let mut broken = plan.clone();
        let k = broken
            .stations
            .iter()
            .position(|s| s.id == broken.poses[2].station)
            .expect("station");
        broken.stations[k].position.x += 30.0;
        let why = planned_pose_problem(&broken, 2).expect("not seen");
        assert!(why.contains("30.0 mm from where the sensor"), "{why}");
        let mut broken = plan;
        broken.robot.joints[1].a += 5.0;
        let why = planned_pose_problem(&broken, 0).expect("other robot");
        assert!(why.contains("from the planned one"), "{why}");
    }

    #[test]
    fn a_tiny_arrow_is_enlarged_by_a_round_factor_said() {
        assert_eq!(arrow_scale(30.0, 1000.0), 1.0);
        assert_eq!(arrow_scale(20.0, 1000.0), 1.0);
        // 0.2 mm in 1000 mm: 100 mm wanted, ×500 draws it 100 mm.
        assert_eq!(arrow_scale(0.2, 1000.0), 500.0);
        // 0.3 mm: ×333 wanted, ×200 the step below.
        assert_eq!(arrow_scale(0.3, 1000.0), 200.0);
        assert_eq!(arrow_scale(15.0, 1000.0), 5.0);
        for (l, r) in [(0.013, 800.0), (1.7, 2000.0), (0.9, 50.0)] {
            let s = arrow_scale(l, r);
            assert!(s * l <= 0.1 * r + 1e-9 && s * l >= 0.02 * r, "{l} {r} {s}");
        }
        assert_eq!(arrow_scale(0.0, 1000.0), 1.0);
        assert_eq!(arrow_scale(f64::NAN, 1000.0), 1.0);
    }

    #[test]
    fn bounds_skip_what_is_not_finite() {
        let pts = [[0.0, 0.0, 0.0], [2.0, 2.0, 1.0], [f64::NAN, 0.0, 0.0]];
        let (c, r) = bounds(&pts).expect("bounds");
        assert_eq!(c, [1.0, 1.0, 0.5]);
        assert!((r - 1.5).abs() < 1e-12);
        assert!(bounds(&[[f64::NAN; 3]]).is_none());
    }
}
