//! The acceptance shape of the real tracker cells (issue 35): a small
//! 6-axis robot (an IRB 120-sized arm of its own MDH table, 0.58 m
//! reach) with a laser tracker, seven sets of 70 calibration poses each
//! with its own 10 validation poses, written as FORMAT sessions with
//! `sensor.mount: "fixed"` as a user would, calibrated with `spherecal
//! calibrate S --out R`, and scored from the written result's `hand_eye`
//! (`base_from_sensor`), `robot` and `stations` exactly as an outside
//! scorer would: this file's own forward kinematics from FORMAT.md's MDH
//! convention, not the engine's. Goal: each set's validation error within
//! 1.3 times the floor (the true model on the same noisy points).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use nalgebra::{Matrix4, Vector3, Vector4};
use serde_json::{Value, json};

use crate::support::bin::run;

/// The nominal arm: `alpha a beta theta d` a joint (deg, mm).
const NOMINAL: [[f64; 5]; 6] = [
    [0.0, 0.0, 0.0, 0.0, 290.0],
    [-90.0, 0.0, 0.0, -90.0, 0.0],
    [0.0, 270.0, 0.0, 0.0, 0.0],
    [-90.0, 70.0, 0.0, 0.0, 302.0],
    [90.0, 0.0, 0.0, 0.0, 0.0],
    [-90.0, 0.0, 0.0, 0.0, 72.0],
];
/// The tracker's noise, mm, on each coordinate.
const TRACKER_NOISE: f64 = 0.01;

/// splitmix64: this file's own random numbers.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
    fn normal(&mut self) -> f64 {
        let (u, v) = (self.next().max(1e-300), self.next());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
}

fn rx(deg: f64) -> Matrix4<f64> {
    let (s, c) = deg.to_radians().sin_cos();
    Matrix4::new(
        1.0, 0.0, 0.0, 0.0, 0.0, c, -s, 0.0, 0.0, s, c, 0.0, 0.0, 0.0, 0.0, 1.0,
    )
}
fn ry(deg: f64) -> Matrix4<f64> {
    let (s, c) = deg.to_radians().sin_cos();
    Matrix4::new(
        c, 0.0, s, 0.0, 0.0, 1.0, 0.0, 0.0, -s, 0.0, c, 0.0, 0.0, 0.0, 0.0, 1.0,
    )
}
fn rz(deg: f64) -> Matrix4<f64> {
    let (s, c) = deg.to_radians().sin_cos();
    Matrix4::new(
        c, -s, 0.0, 0.0, s, c, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
    )
}
fn shift(x: f64, y: f64, z: f64) -> Matrix4<f64> {
    Matrix4::new(
        1.0, 0.0, 0.0, x, 0.0, 1.0, 0.0, y, 0.0, 0.0, 1.0, z, 0.0, 0.0, 0.0, 1.0,
    )
}

/// FORMAT.md: `bT_e(q) = B · Π Rx(alpha)·Tx(a)·Ry(beta)·Rz(q+theta)·Tz(d) · F`.
fn flange(
    joints: &[[f64; 5]],
    base: &Matrix4<f64>,
    tool: &Matrix4<f64>,
    q: &[f64],
) -> Matrix4<f64> {
    let mut t = *base;
    for (p, qi) in joints.iter().zip(q) {
        t = t * rx(p[0]) * shift(p[1], 0.0, 0.0) * ry(p[2]) * rz(qi + p[3]) * shift(0.0, 0.0, p[4]);
    }
    t * tool
}

/// The point `x_e` on the flange seen from a sensor at `base_from_sensor`.
fn seen(
    joints: &[[f64; 5]],
    base: &Matrix4<f64>,
    tool: &Matrix4<f64>,
    base_from_sensor: &Matrix4<f64>,
    q: &[f64],
    x_e: &Vector3<f64>,
) -> Vector3<f64> {
    let x_b = flange(joints, base, tool, q) * Vector4::new(x_e.x, x_e.y, x_e.z, 1.0);
    let x_s = base_from_sensor.try_inverse().unwrap() * x_b;
    Vector3::new(x_s.x, x_s.y, x_s.z)
}

/// A 4×4 of FORMAT.md (4 rows of 4), or identity when absent.
fn matrix(v: Option<&Value>) -> Matrix4<f64> {
    let Some(rows) = v.and_then(Value::as_array) else {
        return Matrix4::identity();
    };
    Matrix4::from_fn(|i, j| rows[i][j].as_f64().unwrap())
}

/// The true cell: the arm with its errors, the tracker's pose, the SMR.
struct Cell {
    truth: Vec<[f64; 5]>,
    base_from_sensor: Matrix4<f64>,
    smr: Vector3<f64>,
}

fn cell() -> Cell {
    let mut rng = Rng(35);
    let truth = NOMINAL
        .iter()
        .map(|p| {
            [
                p[0] + 0.013 * rng.normal(),
                p[1] + 0.06 * rng.normal(),
                p[2] + 0.013 * rng.normal(),
                p[3] + 0.013 * rng.normal(),
                p[4] + 0.06 * rng.normal(),
            ]
        })
        .collect();
    // A tracker 1.6 m in front of the arm, a little to the side, looking back at it.
    let position = Vector3::new(1600.0, 250.0, 450.0);
    let z = (Vector3::new(350.0, 0.0, 500.0) - position).normalize();
    let x = Vector3::z().cross(&z).normalize();
    let y = z.cross(&x);
    let mut base_from_sensor = Matrix4::identity();
    for k in 0..3 {
        base_from_sensor[(k, 0)] = x[k];
        base_from_sensor[(k, 1)] = y[k];
        base_from_sensor[(k, 2)] = z[k];
        base_from_sensor[(k, 3)] = position[k];
    }
    Cell {
        truth,
        base_from_sensor,
        smr: Vector3::new(15.0, -10.0, 65.0),
    }
}

/// One set: 70 identify and 10 validate poses where the SMR faces the
/// tracker within 55°, each measured with the tracker's noise.
fn set(cell: &Cell, seed: u64) -> Vec<(Vec<f64>, &'static str, Vector3<f64>)> {
    let mut rng = Rng(1000 + seed);
    let (id, base) = (Matrix4::identity(), Matrix4::identity());
    let tracker = cell.base_from_sensor.column(3).xyz();
    let mut poses = Vec::new();
    while poses.len() < 80 {
        let q = vec![
            rng.uniform(-40.0, 40.0),
            rng.uniform(-30.0, 40.0),
            rng.uniform(-40.0, 30.0),
            rng.uniform(-90.0, 90.0),
            rng.uniform(-70.0, 70.0),
            rng.uniform(-120.0, 120.0),
        ];
        let f = flange(&cell.truth, &base, &id, &q);
        let normal = f.fixed_view::<3, 1>(0, 2).into_owned();
        let smr = (f * cell.smr.push(1.0)).xyz();
        if (q[4]).abs() < 10.0
            || normal.dot(&(tracker - smr).normalize()) < 55f64.to_radians().cos()
        {
            continue;
        }
        let x_s = seen(
            &cell.truth,
            &base,
            &id,
            &cell.base_from_sensor,
            &q,
            &cell.smr,
        );
        let measured = x_s + Vector3::from_fn(|_, _| TRACKER_NOISE * rng.normal());
        let usage = if poses.len() < 70 {
            "identify"
        } else {
            "validate"
        };
        poses.push((q, usage, measured));
    }
    poses
}

/// The FORMAT session of a set, as a user writes it.
fn session(name: &str, poses: &[(Vec<f64>, &str, Vector3<f64>)]) -> String {
    let joints: Vec<Value> = NOMINAL
        .iter()
        .map(|p| json!({"alpha": p[0], "a": p[1], "beta": p[2], "theta": p[3], "d": p[4]}))
        .collect();
    let measurements: Vec<Value> = poses
        .iter()
        .enumerate()
        .map(|(k, (q, usage, c))| {
            json!({"id": format!("p{}", k + 1), "station": "SMR", "use": usage,
                   "joints": q, "centre": [c.x, c.y, c.z]})
        })
        .collect();
    serde_json::to_string_pretty(&json!({
        "format": "spherecal-session",
        "version": 1,
        "name": name,
        "robot": {"name": "small arm (0.58 m reach)", "joints": joints},
        "sphere": {"diameter": 38.1},
        "sensor": {"mount": "fixed"},
        "measurements": measurements,
    }))
    .unwrap()
}

fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

#[test]
fn seven_tracker_sets_on_a_small_arm_are_scored_from_the_result_within_the_floor() {
    let cell = cell();
    let dir = tempfile::tempdir().unwrap();
    let identity = Matrix4::identity();
    for seed in 1..=7 {
        let poses = set(&cell, seed);
        let s = dir.path().join(format!("set{seed}.json"));
        let r = dir.path().join(format!("set{seed}.result.json"));
        std::fs::write(&s, session(&format!("tracker set {seed}"), &poses)).unwrap();
        let (code, out, err) = run(&[
            "calibrate".as_ref(),
            s.as_os_str(),
            "--out".as_ref(),
            r.as_os_str(),
        ]);
        assert_eq!(code, 0, "{out}\n{err}");
        // The outside scorer: the result's hand_eye (base_from_sensor),
        // robot (MDH, base, flange) and stations (the SMR on the flange).
        let result: Value = serde_json::from_str(&std::fs::read_to_string(&r).unwrap()).unwrap();
        let base_from_sensor = matrix(result.get("hand_eye"));
        let robot = &result["robot"];
        let joints: Vec<[f64; 5]> = robot["joints"]
            .as_array()
            .unwrap()
            .iter()
            .map(|j| ["alpha", "a", "beta", "theta", "d"].map(|k| j[k].as_f64().unwrap()))
            .collect();
        let (base, tool) = (matrix(robot.get("base")), matrix(robot.get("flange")));
        let stations = result["stations"].as_array().unwrap();
        assert_eq!(stations.len(), 1);
        assert_eq!(stations[0]["id"], "SMR");
        assert_eq!(stations[0]["frame"], "flange");
        let smr = Vector3::from_fn(|k, _| stations[0]["point"][k].as_f64().unwrap());
        let (mut calibrated, mut floor, mut nominal) = (Vec::new(), Vec::new(), Vec::new());
        let nominal_joints: Vec<[f64; 5]> = NOMINAL.to_vec();
        let initial = matrix(result.get("hand_eye_initial"));
        for (q, usage, measured) in &poses {
            if *usage != "validate" {
                continue;
            }
            let predicted = seen(&joints, &base, &tool, &base_from_sensor, q, &smr);
            calibrated.push((predicted - measured).norm());
            let truth = seen(
                &cell.truth,
                &identity,
                &identity,
                &cell.base_from_sensor,
                q,
                &cell.smr,
            );
            floor.push((truth - measured).norm());
            let before = seen(&nominal_joints, &identity, &identity, &initial, q, &smr);
            nominal.push((before - measured).norm());
        }
        let (cal, floor, nominal) = (rms(&calibrated), rms(&floor), rms(&nominal));
        eprintln!(
            "set {seed}: validation {cal:.4} mm (floor {floor:.4} mm, {:.2}x); nominal model {nominal:.3} mm",
            cal / floor
        );
        assert!(floor > 0.008 && floor < 0.03, "set {seed}: floor {floor}");
        assert!(
            cal <= 1.3 * floor,
            "set {seed}: validation {cal} mm against the floor {floor} mm"
        );
    }
}
