//! The acceptance check of issue 32, as a bench (`#[ignore]`): exactly
//!
//! ```text
//! spherecal plan --sphere 1050,0,475 --identify-stations 20 --csv P.csv
//! ```
//!
//! (IRB 2400 preset, every other option at its default), its translation,
//! rotation and identify rows executed at their commanded joints on
//! hidden true robots, calibrated with `spherecal calibrate`, measured
//! with `spherecal measure` and scored over the working volume against
//! the repeatability floor. Run with
//!
//! ```text
//! cargo test --test cli -- --ignored --nocapture volume_check::
//! ```
//!
//! `VOLUME_CHECK_SEEDS` (`101-105` by default) chooses the cells and
//! `VOLUME_CHECK_PLAN` adds plan options (e.g. `--selection d-optimal`) to
//! compare against the default.
//!
//! What the bench does, cell by cell (none of it shares a random stream
//! with the planner or the simulator):
//!
//! - **The true robot**: the preset's nominal model with every joint's
//!   α, β, θ off by N(0, 0.2°) and a, d by N(0, 0.3 mm); the true hand-eye
//!   is the plan's guess moved by the paper's guess error
//!   ([`simulated_true_hand_eye`]).
//! - **The plan's rows** run at their commanded joints. Each station's
//!   sphere sits where the station's first row sees the planned centre on
//!   the true robot (an operator centres the stripe on the first pose);
//!   every row then sees it where the true robot puts it. A row whose
//!   centre leaves the usable cut (5-80°, the planned side) misses the
//!   sphere and is left out: it counts against the plan.
//! - **20 validate stations** uniform in the preset's box about the
//!   sphere, 6 poses each: the viewing axis (the flange approach) tilted
//!   10-40° from straight down toward an azimuth within ±100° of the
//!   horizontal direction from the robot to the station (a 200° arc on the
//!   robot's side, the sensor facing out), spun ±90° about it from the
//!   reference roll, the sphere at the paper's cut (40 ± 3°, sides
//!   balanced) within ±2, ±3 mm of the plane's centre; joints from the
//!   true robot's IK (unreachable draws drawn again).
//! - **Scans**: every stripe the arc of the cut circle facing the camera
//!   (±50°, a point every 0.4 mm) with N(0, 0.025 mm) noise on each
//!   coordinate; joint readings with N(0, 0.003°).
//! - **Scoring**: the validate stripes measured by `spherecal measure`
//!   through the calibrated result; each station's sphere fitted (known
//!   diameter, from the station's free fit: a calibrated base frame sits
//!   up to ~16 mm off the true one, too far for the true centre to start
//!   it, see [`Start`]) to its points in the base frame; the 20 centres aligned
//!   rigidly to the true ones; the rms of what is left. The floor is the
//!   same with the true model and hand-eye on the same readings.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

use nalgebra::{Isometry3, Point3, Rotation3, Unit, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use spherecal::engine::base::geometry::kabsch;
use spherecal::engine::base::robot::ik::Chain;
use spherecal::engine::base::robot::{self, JointLimit, Robot};
use spherecal::engine::base::session::{Measurement, Observation, Session, Use};
use spherecal::engine::files::format;
use spherecal::engine::tools::plan::{
    PlanConfig, StationLayout, read_plan_csv, simulated_true_hand_eye,
};
use spherecal::engine::tools::simulate::PlanPose;
use spherecal::engine::uses::measure::sphere::{fit_sphere, fit_sphere_radius};

use crate::support::bin::run;

const SPHERE: [f64; 3] = [1050.0, 0.0, 475.0];
const DIAMETER: f64 = 38.1;
const ANGLE_SIGMA_DEG: f64 = 0.2;
const LENGTH_SIGMA_MM: f64 = 0.3;
const JOINT_NOISE_DEG: f64 = 0.003;
const STRIPE_NOISE_MM: f64 = 0.025;
const ARC_HALF_DEG: f64 = 50.0;
const POINT_SPACING_MM: f64 = 0.4;
const VIEW_Z_MM: f64 = 150.0;
const VALIDATE_STATIONS: usize = 20;
const VALIDATE_POSES: usize = 6;
const MIN_CUT_DEG: f64 = 5.0;
const MAX_CUT_DEG: f64 = 80.0;

fn normal(rng: &mut ChaCha8Rng) -> f64 {
    let u1: f64 = rng.random::<f64>().max(1e-300);
    let u2: f64 = rng.random();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

fn true_robot(nominal: &Robot, rng: &mut ChaCha8Rng) -> Robot {
    let mut r = nominal.clone();
    for j in &mut r.joints {
        j.alpha += ANGLE_SIGMA_DEG * normal(rng);
        j.beta += ANGLE_SIGMA_DEG * normal(rng);
        j.theta += ANGLE_SIGMA_DEG * normal(rng);
        j.a += LENGTH_SIGMA_MM * normal(rng);
        j.d += LENGTH_SIGMA_MM * normal(rng);
    }
    r
}

/// The stripe of a sensor-frame centre (the arc facing the camera).
fn stripe(rng: &mut ChaCha8Rng, c: &Vector3<f64>) -> Vec<[f64; 2]> {
    let radius = DIAMETER / 2.0;
    let r = (radius * radius - c.x * c.x).max(0.0).sqrt();
    let facing = (-c.y).atan2(VIEW_Z_MM - c.z);
    let half = ARC_HALF_DEG.to_radians();
    let n = ((2.0 * half * r / POINT_SPACING_MM).floor() as usize + 1).max(3);
    (0..n)
        .map(|k| {
            let phi = facing - half + 2.0 * half * k as f64 / (n - 1) as f64;
            [
                c.y + r * phi.sin() + STRIPE_NOISE_MM * normal(rng),
                c.z + r * phi.cos() + STRIPE_NOISE_MM * normal(rng),
            ]
        })
        .collect()
}

fn usable(c: &Vector3<f64>, side: i8) -> bool {
    let radius = DIAMETER / 2.0;
    let x = c.x * f64::from(side);
    (radius * MIN_CUT_DEG.to_radians().sin()..=radius * MAX_CUT_DEG.to_radians().sin()).contains(&x)
}

/// One pose as executed: station, use, side, true joints, sensor centre.
struct Row {
    id: String,
    station: String,
    usage: Use,
    side: i8,
    joints: Vec<f64>,
    centre: Vector3<f64>,
}

/// The plan's rows on the true robot: the sphere where each station's
/// first row sees it; rows that miss it dropped (and counted).
fn plan_rows(rows: &[PlanPose], truth: &Robot, hand_eye: &Isometry3<f64>) -> (Vec<Row>, usize) {
    let see = |q: &[f64]| truth.base_from_flange(q) * hand_eye;
    let mut stations: Vec<(String, Vector3<f64>)> = Vec::new();
    let (mut out, mut missed) = (Vec::new(), 0);
    for p in rows.iter().filter(|p| p.usage != Use::Validate) {
        if !stations.iter().any(|(s, _)| *s == p.station) {
            let at = see(&p.joints) * Point3::from(Vector3::from(p.centre_in_sensor));
            stations.push((p.station.clone(), at.coords));
        }
        let station = stations.iter().find(|(s, _)| *s == p.station).unwrap().1;
        let centre = see(&p.joints)
            .inverse_transform_point(&Point3::from(station))
            .coords;
        if !usable(&centre, p.side) {
            missed += 1;
            continue;
        }
        out.push(Row {
            id: p.id.clone(),
            station: p.station.clone(),
            usage: p.usage,
            side: p.side,
            joints: p.joints.clone(),
            centre,
        });
    }
    (out, missed)
}

/// Our validate stations and poses on the true robot.
fn validate_rows(
    rng: &mut ChaCha8Rng,
    truth: &Robot,
    hand_eye: &Isometry3<f64>,
    limits: &[JointLimit],
    lo: &Vector3<f64>,
    hi: &Vector3<f64>,
) -> (Vec<Row>, Vec<(String, Vector3<f64>)>) {
    let chain = Chain::new(truth).unwrap();
    let base = truth.base.translation.vector;
    let radius = DIAMETER / 2.0;
    let (mut rows, mut stations) = (Vec::new(), Vec::new());
    let mut k = 0;
    while stations.len() < VALIDATE_STATIONS {
        let place = Vector3::from_fn(|i, _| rng.random_range(lo[i]..hi[i]));
        let id = format!("V{}", stations.len() + 1);
        let out = {
            let d = place - base;
            Vector3::new(d.x, d.y, 0.0).normalize()
        };
        let out_azimuth = out.y.atan2(out.x);
        let mut found = Vec::new();
        for _ in 0..400 {
            if found.len() == VALIDATE_POSES {
                break;
            }
            let side: i8 = if found.len() % 2 == 0 { 1 } else { -1 };
            let tilt = rng.random_range(10.0_f64..40.0).to_radians();
            let azimuth = out_azimuth + rng.random_range(-100.0_f64..100.0).to_radians();
            let approach = Vector3::new(
                tilt.sin() * azimuth.cos(),
                tilt.sin() * azimuth.sin(),
                -tilt.cos(),
            );
            let reference = out - approach * out.dot(&approach);
            let x0 = reference.normalize();
            let spin = rng.random_range(-90.0_f64..90.0).to_radians();
            let x = UnitQuaternion::from_axis_angle(&Unit::new_normalize(approach), spin) * x0;
            let y = approach.cross(&x);
            let flange_rotation =
                UnitQuaternion::from_rotation_matrix(&Rotation3::from_basis_unchecked(&[
                    x, y, approach,
                ]));
            let cut = rng.random_range(37.0_f64..43.0).to_radians();
            let centre = Vector3::new(
                f64::from(side) * radius * cut.sin(),
                rng.random_range(-2.0..2.0),
                rng.random_range(-3.0..3.0),
            );
            // The flange pose that sees `place` at `centre`.
            let sensor_rotation = flange_rotation * hand_eye.rotation;
            let sensor_origin = place - sensor_rotation * centre;
            let base_from_sensor = Isometry3::from_parts(sensor_origin.into(), sensor_rotation);
            let target = base_from_sensor * hand_eye.inverse();
            let guesses = chain.arm_guess_grid(&target, limits);
            let Some(q) = chain
                .solutions(&target, &guesses, limits, 10.0)
                .into_iter()
                .next()
            else {
                continue;
            };
            let seen = (truth.base_from_flange(&q) * hand_eye)
                .inverse_transform_point(&Point3::from(place))
                .coords;
            if (seen - centre).norm() > 1e-6 {
                continue;
            }
            found.push((side, q.to_vec(), seen));
        }
        k += 1;
        if found.len() < VALIDATE_POSES {
            assert!(k < 200, "validate stations out of reach");
            continue;
        }
        for (n, (side, joints, centre)) in found.into_iter().enumerate() {
            rows.push(Row {
                id: format!("w{}_{}", stations.len() + 1, n + 1),
                station: id.clone(),
                usage: Use::Validate,
                side,
                joints,
                centre,
            });
        }
        stations.push((id, place));
    }
    (rows, stations)
}

/// Rms of what is left after the best rigid alignment of `a` onto `b`.
fn aligned_rms(a: &[Vector3<f64>], b: &[Vector3<f64>]) -> f64 {
    let t = kabsch(a, b).unwrap();
    let s: f64 = a
        .iter()
        .zip(b)
        .map(|(p, q)| (t * Point3::from(*p) - Point3::from(*q)).norm_squared())
        .sum();
    (s / a.len() as f64).sqrt()
}

/// Where a station's known-diameter fit starts.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Start {
    /// The station's own free-radius fit (as `measure`'s self-check
    /// starts it): the bench's scoring.
    FreeFit,
    /// The station's true centre: the bench's scoring before the fix, kept
    /// for the regression test. It is no start for a calibrated model's
    /// points: the calibrated base frame sits a rigid motion (10-16 mm in
    /// cell 18) off the true one, which the score aligns away, and from
    /// there the fit can land in a wrong minimum (cell 18, rescoring 17,
    /// station V7: 2.9 mm rms, the cell scored at 68×).
    Truth,
}

/// Each validate station's sphere centre fitted to `points` (id → base
/// points), in the order of `stations`: the known diameter, from the
/// station's free fit.
fn fitted(
    stations: &[(String, Vector3<f64>)],
    rows: &[Row],
    points: &BTreeMap<String, Vec<Vector3<f64>>>,
) -> Vec<Vector3<f64>> {
    fitted_from(stations, rows, points, Start::FreeFit)
}

/// [`fitted`] from `start`. A fit whose residuals are far over the
/// stripes' noise (a wrong minimum) stops the bench rather than score.
fn fitted_from(
    stations: &[(String, Vector3<f64>)],
    rows: &[Row],
    points: &BTreeMap<String, Vec<Vector3<f64>>>,
    start: Start,
) -> Vec<Vector3<f64>> {
    stations
        .iter()
        .map(|(id, truth)| {
            let pts: Vec<Vector3<f64>> = rows
                .iter()
                .filter(|r| r.station == *id)
                .flat_map(|r| points[&r.id].iter().copied())
                .collect();
            let from = match start {
                Start::FreeFit => fit_sphere(&pts).unwrap().centre,
                Start::Truth => *truth,
            };
            let f = fit_sphere_radius(&pts, DIAMETER / 2.0, &from).unwrap();
            assert!(
                start == Start::Truth || f.rms < 20.0 * STRIPE_NOISE_MM,
                "station {id}: the sphere fit's rms is {:.3} mm over {} points (a wrong minimum?)",
                f.rms,
                pts.len()
            );
            f.centre
        })
        .collect()
}

/// The score of one cell: (after, floor) rms mm, rows missed, seconds,
/// and its anatomy.
struct Cell {
    after: f64,
    floor: f64,
    missed: usize,
    rows: usize,
    seconds: f64,
    /// The calibration's own error over the validate poses, noise-free:
    /// each validate pose's true sensor-frame centre carried to the base
    /// frame by the calibrated model, averaged by station, aligned
    /// rigidly to the truth, rms (mm).
    param: f64,
    /// What the result predicts for it (`volume_error.rms_mm`).
    predicted: f64,
    /// Largest |measure − own mapping| over the validate points (mm): 0
    /// when the rescoring below maps as `measure` does.
    mapping_check: f64,
    truth: Robot,
    hand_eye: Isometry3<f64>,
    calibrated: (Robot, Isometry3<f64>),
}

/// The calibration's noise-free error at `rows` (validate) over
/// `stations`: see [`Cell::param`].
fn param_error(
    stations: &[(String, Vector3<f64>)],
    rows: &[Row],
    robot: &Robot,
    hand_eye: &Isometry3<f64>,
) -> f64 {
    let mapped: Vec<Vector3<f64>> = stations
        .iter()
        .map(|(id, _)| {
            let own: Vec<Vector3<f64>> = rows
                .iter()
                .filter(|r| r.station == *id)
                .map(|r| {
                    (robot.base_from_flange(&r.joints) * hand_eye * Point3::from(r.centre)).coords
                })
                .collect();
            own.iter().sum::<Vector3<f64>>() / own.len() as f64
        })
        .collect();
    let exact: Vec<Vector3<f64>> = stations.iter().map(|(_, p)| *p).collect();
    aligned_rms(&mapped, &exact)
}

/// The predicted volume error (`volume_error.rms_mm`) of a result file.
fn predicted_volume_error(text: &str) -> f64 {
    let v: serde_json::Value = serde_json::from_str(text).unwrap();
    v["solver"]["volume_error"]["rms_mm"]
        .as_f64()
        .unwrap_or(f64::NAN)
}

/// A fresh validate set for a calibrated cell, scored in-process (the
/// calibrated model maps as `measure` does: [`Cell::mapping_check`]):
/// (after, floor, param) mm.
fn rescore(c: &Cell, rng: &mut ChaCha8Rng) -> (f64, f64, f64) {
    rescore_from(c, rng, Start::FreeFit)
}

/// [`rescore`] with the stations' fits from `start`.
fn rescore_from(c: &Cell, rng: &mut ChaCha8Rng, start: Start) -> (f64, f64, f64) {
    let preset = robot::preset("irb2400").unwrap();
    let config = PlanConfig::for_preset(&preset, SPHERE);
    let StationLayout::Box { size } = config.stations else {
        unreachable!()
    };
    let centre = Vector3::from(SPHERE);
    let half = Vector3::from(size) / 2.0;
    let (rows, stations) = validate_rows(
        rng,
        &c.truth,
        &c.hand_eye,
        &config.limits,
        &(centre - half),
        &(centre + half),
    );
    let readings: Vec<(Vec<f64>, Vec<[f64; 2]>)> = rows
        .iter()
        .map(|r| {
            let q = r
                .joints
                .iter()
                .map(|q| q + JOINT_NOISE_DEG * normal(rng))
                .collect();
            (q, stripe(rng, &r.centre))
        })
        .collect();
    let points_of = |robot: &Robot, he: &Isometry3<f64>| -> BTreeMap<String, Vec<Vector3<f64>>> {
        rows.iter()
            .zip(&readings)
            .map(|(r, (q, s))| {
                let t = robot.base_from_flange(q) * he;
                let pts = s
                    .iter()
                    .map(|p| (t * Point3::new(0.0, p[0], p[1])).coords)
                    .collect();
                (r.id.clone(), pts)
            })
            .collect()
    };
    let exact: Vec<Vector3<f64>> = stations.iter().map(|(_, p)| *p).collect();
    let floor = aligned_rms(
        &fitted_from(&stations, &rows, &points_of(&c.truth, &c.hand_eye), start),
        &exact,
    );
    let after = aligned_rms(
        &fitted_from(
            &stations,
            &rows,
            &points_of(&c.calibrated.0, &c.calibrated.1),
            start,
        ),
        &exact,
    );
    let param = param_error(&stations, &rows, &c.calibrated.0, &c.calibrated.1);
    (after, floor, param)
}

fn cell(dir: &Path, plan: &[PlanPose], seed: u64) -> Cell {
    cell_rep(dir, plan, seed, 0)
}

/// Cell `seed` with its readings' noise drawn afresh for `rep` > 0 (the
/// same true robot, plan rows and validate poses).
fn cell_rep(dir: &Path, plan: &[PlanPose], seed: u64, rep: u64) -> Cell {
    let preset = robot::preset("irb2400").unwrap();
    let config = PlanConfig::for_preset(&preset, SPHERE);
    let StationLayout::Box { size } = config.stations else {
        unreachable!()
    };
    let centre = Vector3::from(SPHERE);
    let half = Vector3::from(size) / 2.0;
    let mut rng = ChaCha8Rng::seed_from_u64(0x5EED_0032_0000 + seed);
    let truth = true_robot(&preset.robot, &mut rng);
    let hand_eye = simulated_true_hand_eye(&config.flange_from_sensor);
    let (mut rows, missed) = plan_rows(plan, &truth, &hand_eye);
    let planned = plan.iter().filter(|p| p.usage != Use::Validate).count();
    let (validate, v_stations) = validate_rows(
        &mut rng,
        &truth,
        &hand_eye,
        &config.limits,
        &(centre - half),
        &(centre + half),
    );
    let validate_only: Vec<Row> = validate
        .iter()
        .map(|r| Row {
            id: r.id.clone(),
            station: r.station.clone(),
            usage: r.usage,
            side: r.side,
            joints: r.joints.clone(),
            centre: r.centre,
        })
        .collect();
    rows.extend(validate);
    if rep > 0 {
        rng = ChaCha8Rng::seed_from_u64(0x5EED_0032_1000_0000 + 1000 * seed + rep);
    }
    let measurements: Vec<Measurement> = rows
        .iter()
        .map(|r| Measurement {
            id: r.id.clone(),
            station: r.station.clone(),
            usage: r.usage,
            side_given: (r.side != 1).then_some(r.side),
            side: r.side,
            joints: r
                .joints
                .iter()
                .map(|q| q + JOINT_NOISE_DEG * normal(&mut rng))
                .collect(),
            flange: None,
            observation: Observation::Stripe(stripe(&mut rng, &r.centre)),
        })
        .collect();
    // The floor: the true model on the same readings.
    let points_of = |robot: &Robot, he: &Isometry3<f64>| -> BTreeMap<String, Vec<Vector3<f64>>> {
        measurements
            .iter()
            .filter(|m| m.usage == Use::Validate)
            .map(|m| {
                let t = robot.base_from_flange(&m.joints) * he;
                let Observation::Stripe(s) = &m.observation else {
                    unreachable!()
                };
                let pts = s
                    .iter()
                    .map(|p| (t * Point3::new(0.0, p[0], p[1])).coords)
                    .collect();
                (m.id.clone(), pts)
            })
            .collect()
    };
    let exact: Vec<Vector3<f64>> = v_stations.iter().map(|(_, p)| *p).collect();
    let floor = aligned_rms(
        &fitted(&v_stations, &rows, &points_of(&truth, &hand_eye)),
        &exact,
    );
    let session = Session::made(
        format!("volume check, cell {seed}"),
        preset.robot.clone(),
        DIAMETER,
        measurements.clone(),
    );
    let (s, r, v) = (
        dir.join(format!("cell{seed}.json")),
        dir.join(format!("cell{seed}.result.json")),
        dir.join(format!("cell{seed}.validate.csv")),
    );
    format::save_session(&session, &s).unwrap();
    let t = Instant::now();
    let extra = std::env::var("VOLUME_CHECK_CALIBRATE").unwrap_or_default();
    let mut args: Vec<&std::ffi::OsStr> = vec![
        "calibrate".as_ref(),
        s.as_os_str(),
        "--out".as_ref(),
        r.as_os_str(),
        "-q".as_ref(),
    ];
    args.extend(extra.split_whitespace().map(std::ffi::OsStr::new));
    let (code, out, err) = run(&args);
    let seconds = t.elapsed().as_secs_f64();
    assert_eq!(code, 0, "calibrate: {out}{err}");
    let (code, out, err) = run(&[
        "measure".as_ref(),
        s.as_os_str(),
        "--result".as_ref(),
        r.as_os_str(),
        "--use".as_ref(),
        "validate".as_ref(),
        "--out".as_ref(),
        v.as_os_str(),
    ]);
    assert_eq!(code, 0, "measure: {out}{err}");
    let mut measured: BTreeMap<String, Vec<Vector3<f64>>> = BTreeMap::new();
    let mut reader = csv::Reader::from_path(&v).unwrap();
    for rec in reader.records() {
        let rec = rec.unwrap();
        let f = |k: usize| rec[k].parse::<f64>().unwrap();
        measured
            .entry(rec[0].to_string())
            .or_default()
            .push(Vector3::new(f(1), f(2), f(3)));
    }
    let after = aligned_rms(&fitted(&v_stations, &rows, &measured), &exact);
    let text = std::fs::read_to_string(&r).unwrap();
    let result = format::load_result(&r).unwrap();
    let calibrated = (result.robot.clone().unwrap(), result.hand_eye);
    let predicted = predicted_volume_error(&text);
    let own = points_of(&calibrated.0, &calibrated.1);
    let mapping_check = measured
        .iter()
        .flat_map(|(id, pts)| pts.iter().zip(&own[id]).map(|(a, b)| (a - b).norm()))
        .fold(0.0, f64::max);
    Cell {
        after,
        floor,
        missed,
        rows: planned,
        seconds,
        param: param_error(&v_stations, &validate_only, &calibrated.0, &calibrated.1),
        predicted,
        mapping_check,
        truth,
        hand_eye,
        calibrated,
    }
}

fn seeds() -> Vec<u64> {
    let spec = std::env::var("VOLUME_CHECK_SEEDS").unwrap_or_else(|_| "101-105".to_owned());
    spec.split(',')
        .flat_map(|part| match part.split_once('-') {
            Some((a, b)) => {
                (a.trim().parse::<u64>().unwrap()..=b.trim().parse().unwrap()).collect()
            }
            None => vec![part.trim().parse::<u64>().unwrap()],
        })
        .collect()
}

/// The check's plan, made by the command line as the issue states it
/// (`VOLUME_CHECK_PLAN` adds options), in a scratch folder of its own.
struct CheckPlan {
    dir: std::path::PathBuf,
    poses: Vec<PlanPose>,
    console: String,
    seconds: f64,
    extra: String,
}

fn check_plan(name: &str) -> CheckPlan {
    let dir = std::env::temp_dir().join(format!("spherecal-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let csv = dir.join("P.csv");
    let extra = std::env::var("VOLUME_CHECK_PLAN").unwrap_or_default();
    let mut args: Vec<String> = [
        "plan",
        "--sphere",
        "1050,0,475",
        "--identify-stations",
        "20",
        "--csv",
    ]
    .iter()
    .map(|s| (*s).to_owned())
    .collect();
    args.push(csv.display().to_string());
    args.extend(extra.split_whitespace().map(str::to_owned));
    let t = Instant::now();
    let (code, out, err) = run(&args);
    let seconds = t.elapsed().as_secs_f64();
    assert_eq!(code, 0, "plan: {out}{err}");
    let poses = read_plan_csv(&std::fs::read_to_string(&csv).unwrap()).unwrap();
    CheckPlan {
        dir,
        poses,
        console: out,
        seconds,
        extra,
    }
}

/// The check: the plan made by the command line, scored on the cells.
#[test]
#[ignore = "bench: the acceptance check of issue 32, a minute a cell"]
fn issue_32_check() {
    let CheckPlan {
        dir,
        poses: plan,
        console,
        seconds: plan_seconds,
        extra,
    } = check_plan("volume-check");
    println!("{}", console.trim_end());
    println!(
        "plan {} ({plan_seconds:.1} s, this build)",
        if extra.is_empty() {
            "(default)"
        } else {
            &extra
        }
    );
    println!(
        "| cell | after, mm | floor, mm | after / floor | rows missed | calibrate, s | parameters' part, mm | predicted, mm |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    let mut ratios = Vec::new();
    for seed in seeds() {
        let c = cell(&dir, &plan, seed);
        let ratio = c.after / c.floor;
        ratios.push(ratio);
        println!(
            "| {seed} | {:.4} | {:.4} | {ratio:.2} | {} of {} | {:.1} | {:.4} | {:.4} |",
            c.after, c.floor, c.missed, c.rows, c.seconds, c.param, c.predicted
        );
    }
    let mean = ratios.iter().sum::<f64>() / ratios.len() as f64;
    let worst = ratios.iter().copied().fold(0.0, f64::max);
    println!(
        "volume error / floor over {} cells: mean {mean:.2}, worst {worst:.2} (goal: mean ≤ 1.35, worst ≤ 1.6)",
        ratios.len()
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The rows of the check's plan that miss the sphere on the cells' true
/// robots, by use, without calibrating (seconds, not minutes): the
/// robustness of a plan to the true robot's error.
#[test]
#[ignore = "bench: rows missed by the check's plan on the cells' true robots"]
fn rows_missed() {
    let CheckPlan {
        dir, poses: plan, ..
    } = check_plan("rows-missed");
    let preset = robot::preset("irb2400").unwrap();
    let config = PlanConfig::for_preset(&preset, SPHERE);
    let hand_eye = simulated_true_hand_eye(&config.flange_from_sensor);
    let mut total = BTreeMap::<String, usize>::new();
    let mut counts = Vec::new();
    for seed in seeds() {
        let mut rng = ChaCha8Rng::seed_from_u64(0x5EED_0032_0000 + seed);
        let truth = true_robot(&preset.robot, &mut rng);
        let (rows, missed) = plan_rows(&plan, &truth, &hand_eye);
        let kept: std::collections::BTreeSet<&str> = rows.iter().map(|r| r.id.as_str()).collect();
        let mut by = BTreeMap::<String, usize>::new();
        for p in plan.iter().filter(|p| p.usage != Use::Validate) {
            if !kept.contains(p.id.as_str()) {
                *by.entry(format!("{:?}", p.usage)).or_default() += 1;
                *total.entry(format!("{:?}", p.usage)).or_default() += 1;
            }
        }
        counts.push(missed);
        println!("cell {seed}: {missed} missed {by:?}");
    }
    println!(
        "rows missed over {} cells: total {}, worst {}, by use {total:?}",
        counts.len(),
        counts.iter().sum::<usize>(),
        counts.iter().max().unwrap_or(&0)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// What makes a bad cell bad: each cell of `VOLUME_CHECK_SEEDS` as the
/// check scores it, then (a) the same calibration scored on
/// `VOLUME_ANATOMY_RESCORES` fresh validate sets (the score's own noise:
/// the calibration fixed, the validate stations and noise drawn again)
/// and (b) calibrated again from `VOLUME_ANATOMY_REPS` fresh draws of the
/// readings' noise (the same true robot and rows: is the cell bad
/// through its robot or through its noise?). Each row: the ratio, the
/// parameters' part of the error (noise-free, see [`Cell::param`])
/// against what the result predicts; last, a summary over them all.
/// `VOLUME_CHECK_CALIBRATE` adds options to `calibrate`.
#[test]
#[ignore = "bench: the anatomy of the check's cells"]
fn anatomy() {
    let CheckPlan {
        dir, poses: plan, ..
    } = check_plan("volume-anatomy");
    let env = |k: &str, d: u64| {
        std::env::var(k)
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(d)
    };
    let (reps, rescores) = (
        env("VOLUME_ANATOMY_REPS", 3),
        env("VOLUME_ANATOMY_RESCORES", 20),
    );
    println!(
        "| cell | noise | after / floor | floor, mm | parameters' part, mm | predicted, mm | part / predicted | rescored: ratio median [10 %, 90 %] worst, parameters' part mean |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    let (mut ratios, mut parts, mut shares) = (Vec::new(), Vec::new(), Vec::new());
    for seed in seeds() {
        for rep in 0..=reps {
            let c = cell_rep(&dir, &plan, seed, rep);
            let rescored = if rep == 0 && rescores > 0 {
                let mut rng = ChaCha8Rng::seed_from_u64(0x5EED_0032_2000_0000 + seed);
                let s: Vec<(f64, f64, f64)> =
                    (0..rescores).map(|_| rescore(&c, &mut rng)).collect();
                let mut r: Vec<f64> = s.iter().map(|(a, f, _)| a / f).collect();
                r.sort_by(f64::total_cmp);
                let at = |f: f64| r[((r.len() - 1) as f64 * f).round() as usize];
                format!(
                    "{:.2} [{:.2}, {:.2}] worst {:.2}, {:.4} (mapping check {:.1e} mm)",
                    at(0.5),
                    at(0.1),
                    at(0.9),
                    at(1.0),
                    s.iter().map(|x| x.2).sum::<f64>() / s.len() as f64,
                    c.mapping_check
                )
            } else {
                String::new()
            };
            println!(
                "| {seed} | {rep} | {:.2} | {:.4} | {:.4} | {:.4} | {:.2} | {rescored} |",
                c.after / c.floor,
                c.floor,
                c.param,
                c.predicted,
                c.param / c.predicted,
            );
            ratios.push(c.after / c.floor);
            parts.push(c.param);
            shares.push(c.param / c.predicted);
        }
    }
    let n = ratios.len() as f64;
    ratios.sort_by(f64::total_cmp);
    println!(
        "{} calibrations: after / floor mean {:.3}, 90th percentile {:.2}, worst {:.2}, over 1.6: {}; parameters' part mean {:.4} mm, rms {:.4} mm; part / predicted mean {:.2}",
        ratios.len(),
        ratios.iter().sum::<f64>() / n,
        ratios[((n - 1.0) * 0.9).round() as usize],
        ratios[ratios.len() - 1],
        ratios.iter().filter(|r| **r > 1.6).count(),
        parts.iter().sum::<f64>() / n,
        (parts.iter().map(|p| p * p).sum::<f64>() / n).sqrt(),
        shares.iter().sum::<f64>() / n
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The rescorings of [`anatomy`] one by one (the same draws): each
/// cell of `VOLUME_CHECK_SEEDS` calibrated and scored on
/// `VOLUME_ANATOMY_RESCORES` fresh validate sets, each set's ratio, rms
/// and parameters' part printed, to find one set (`VOLUME_CHECK_SEEDS=18
/// VOLUME_ANATOMY_RESCORES=20`: set 17 is the one that scored 68× before
/// the stations' fits started from their free fits).
#[test]
#[ignore = "bench: the anatomy's rescorings one by one"]
fn rescorings() {
    let CheckPlan {
        dir, poses: plan, ..
    } = check_plan("volume-rescorings");
    let n: u64 = std::env::var("VOLUME_ANATOMY_RESCORES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(20);
    for seed in seeds() {
        let c = cell(&dir, &plan, seed);
        println!("cell {seed}: after / floor {:.2}", c.after / c.floor);
        let mut rng = ChaCha8Rng::seed_from_u64(0x5EED_0032_2000_0000 + seed);
        for k in 0..n {
            let (a, f, p) = rescore(&c, &mut rng);
            println!(
                "  set {k}: after / floor {:.2}, after {a:.4} mm, floor {f:.4} mm, parameters' part {p:.4} mm",
                a / f
            );
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A cell whose "calibrated" model is the true one with its base frame
/// moved by `offset` (what the rigid alignment of the score takes away).
fn moved_base_cell(seed: u64, offset: &Isometry3<f64>) -> Cell {
    let preset = robot::preset("irb2400").unwrap();
    let config = PlanConfig::for_preset(&preset, SPHERE);
    let mut rng = ChaCha8Rng::seed_from_u64(0x5EED_0032_0000 + seed);
    let truth = true_robot(&preset.robot, &mut rng);
    let hand_eye = simulated_true_hand_eye(&config.flange_from_sensor);
    let mut moved = truth.clone();
    moved.base = offset * truth.base;
    Cell {
        after: 0.0,
        floor: 0.0,
        missed: 0,
        rows: 0,
        seconds: 0.0,
        param: 0.0,
        predicted: 0.0,
        mapping_check: 0.0,
        truth,
        hand_eye,
        calibrated: (moved, hand_eye),
    }
}

/// The score's own fit, regression (cell 18's rescoring 17 scored 68×):
/// a "calibrated" model that is the true one with its base frame moved
/// 16 mm (a calibrated base frame sits 10-16 mm off the true one; the
/// score's rigid alignment takes it away) must score the floor exactly.
/// From the true centres (the bench's start before) one station's fit
/// lands in a wrong minimum and the set scores 75×; from each station's
/// free fit, 1.000000.
#[test]
fn a_moved_base_frame_scores_the_floor() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let dir = Vector3::new(normal(&mut rng), normal(&mut rng), normal(&mut rng)).normalize() * 16.0;
    let c = moved_base_cell(7, &Isometry3::translation(dir.x, dir.y, dir.z));
    let ratio = |start| {
        let (after, floor, part) = rescore_from(&c, &mut ChaCha8Rng::seed_from_u64(1007), start);
        assert!(
            part < 1e-9,
            "the moved model maps the truth: part {part} mm"
        );
        after / floor
    };
    let (before, now) = (ratio(Start::Truth), ratio(Start::FreeFit));
    assert!(
        before > 10.0,
        "from the true centres: {before:.2}× (the trap not met: choose another seed)"
    );
    assert!((now - 1.0).abs() < 1e-6, "from the free fits: {now:.8}×");
}
