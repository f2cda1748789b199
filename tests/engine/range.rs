//! The predicted error over the sensor's range (issue 14) against the
//! realised one on simulated IRB 2400 cells: the 3-D error of points of
//! the laser plane, on a grid over `sensor.range`, at the validation
//! poses, between the calibrated and the true model (the same joint
//! readings), after the best rigid alignment (the base frame is not
//! observable). The prediction comes from `ml`'s covariance alone; a
//! wrong covariance fails this test.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use nalgebra::{Isometry3, Point3};
use spherecal::engine::base::geometry::kabsch;
use spherecal::engine::base::session::{SensorRange, Session, Use};
use spherecal::engine::calibrate::solve::ml::range::{RANGE_GRID, RANGE_POSES};
use spherecal::engine::calibrate::solve::{self, Calibration, Options};
use spherecal::engine::files::format;
use spherecal::engine::tools::simulate::{self, SimConfig, Truth};

const RANGE: SensorRange = SensorRange {
    y: [-40.0, 40.0],
    z: [-40.0, 40.0],
};

fn calibrated(seed: u64) -> (Session, Truth, Calibration) {
    let (mut session, truth) = simulate::simulate(&SimConfig {
        seed,
        ..SimConfig::default()
    })
    .unwrap();
    session.sensor_range = Some(RANGE);
    let mut options = Options::from_session(&session);
    options.ml.cross_validation = false;
    let (_, cal) = solve::calibrate(&session, &options).unwrap();
    (session, truth, cal)
}

/// RMS over the grid and the validation poses of the error after the
/// best rigid alignment (Kabsch), mm.
fn realised_rms(session: &Session, truth: &Truth, cal: &Calibration) -> f64 {
    let working: Vec<usize> = (0..session.measurements.len())
        .filter(|&i| session.measurements[i].usage == Use::Validate)
        .collect();
    let stride = working.len().div_ceil(RANGE_POSES).max(1);
    let true_robot = truth.true_robot();
    let true_he = truth.true_hand_eye();
    let mut cal_pts = Vec::new();
    let mut true_pts = Vec::new();
    for &i in working.iter().step_by(stride) {
        let q = &session.measurements[i].joints;
        let bc: Isometry3<f64> = cal.calibrated.base_from_flange(q) * cal.hand_eye;
        let bt: Isometry3<f64> = true_robot.base_from_flange(q) * true_he;
        for [y, z] in RANGE.grid(RANGE_GRID) {
            let g = Point3::new(0.0, y, z);
            cal_pts.push((bc * g).coords);
            true_pts.push((bt * g).coords);
        }
    }
    let n = cal_pts.len() as f64;
    let fit = kabsch(&cal_pts, &true_pts).unwrap();
    let sum_sq: f64 = cal_pts
        .iter()
        .zip(&true_pts)
        .map(|(c, t)| ((fit * Point3::from(*c)).coords - t).norm_squared())
        .sum();
    (sum_sq / n).sqrt()
}

#[test]
fn the_predicted_range_error_agrees_with_the_realised_one() {
    let mut predicted_sq = 0.0;
    let mut realised_sq = 0.0;
    let seeds = [1_u64, 2, 3, 4, 5];
    for seed in seeds {
        let (session, truth, cal) = calibrated(seed);
        let ml = cal.report.ml().expect("ml");
        let range = ml.range_error.as_ref().expect("a range prediction");
        assert_eq!(range.region, "sensor.range");
        assert_eq!((range.y, range.z), (RANGE.y, RANGE.z));
        // The paper-like cell sees the sphere at one spot: warned.
        assert!(range.coverage < 0.05, "{}", range.coverage);
        assert!(range.warning.is_some());
        assert!(range.max_mm > range.at_sphere_mm);
        let realised = realised_rms(&session, &truth, &cal);
        eprintln!(
            "seed {seed}: predicted rms {:.4} mm, realised {realised:.4} mm",
            range.rms_mm
        );
        predicted_sq += range.rms_mm.powi(2);
        realised_sq += realised.powi(2);
    }
    let ratio = (realised_sq / predicted_sq).sqrt();
    eprintln!(
        "realised / predicted over {} seeds: {ratio:.3}",
        seeds.len()
    );
    assert!(
        (0.8..=1.2).contains(&ratio),
        "realised / predicted range error {ratio:.3} (within 20 % expected)"
    );
}

#[test]
fn sensor_range_round_trips_and_bad_ranges_are_refused() {
    let (mut session, _) = simulate::simulate(&SimConfig::default()).unwrap();
    session.sensor_range = Some(RANGE);
    let text = format::session_to_json(&session);
    assert!(text.contains("\"range\": {"));
    let back = format::parse_session(&text, std::path::Path::new("r.json")).unwrap();
    assert_eq!(back.sensor_range, Some(RANGE));
    for (bad, expect) in [
        (
            r#"{"y": [40.0, -40.0], "z": [-40.0, 40.0]}"#,
            "sensor.range.y must be [min, max] with min < max",
        ),
        (
            r#"{"y": [-40.0, 40.0], "z": [0.0, 1e6]}"#,
            "sensor.range.z = 1000000 mm is not plausible",
        ),
        (r#"{"y": [-40.0, 40.0]}"#, "missing key `z`"),
        (
            r#"{"y": [-40.0, 40.0], "z": [0, 1], "x": [0, 1]}"#,
            "unknown key `x`",
        ),
    ] {
        let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
        v["sensor"]["range"] = serde_json::from_str(bad).unwrap();
        let edited = serde_json::to_string_pretty(&v).unwrap();
        let e = format::parse_session(&edited, std::path::Path::new("r.json"))
            .unwrap_err()
            .to_string();
        assert!(e.contains(expect), "{bad}: {e}");
    }
}

/// `simulate --range` writes `sensor.range`; `calibrate` prints the
/// predicted range error and the warning; the HTML report carries both.
#[test]
fn the_command_line_reports_the_range_error() {
    let dir = tempfile::tempdir().unwrap();
    let s = dir.path().join("s.json");
    let run = |args: &[&str]| {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_spherecal"))
            .args(args)
            .output()
            .unwrap();
        (
            o.status.code(),
            String::from_utf8_lossy(&o.stdout).into_owned(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    let (code, _, err) = run(&[
        "simulate",
        "--out",
        s.to_str().unwrap(),
        "--range",
        "-40,40,-30,30",
    ]);
    assert_eq!(code, Some(0), "{err}");
    let session = format::load_session(&s).unwrap();
    assert_eq!(
        session.sensor_range,
        Some(SensorRange {
            y: [-40.0, 40.0],
            z: [-30.0, 30.0]
        })
    );
    let r = dir.path().join("r.json");
    let (code, out, err) = run(&[
        "calibrate",
        s.to_str().unwrap(),
        "--out",
        r.to_str().unwrap(),
    ]);
    assert_eq!(code, Some(0), "{err}");
    assert!(
        out.contains("predicted point error over sensor.range (y -40…40, z -30…30 mm)"),
        "{out}"
    );
    assert!(out.contains("warning: the sphere positions"), "{out}");
    let result = format::load_result(&r).unwrap();
    let range = result
        .solver
        .ml()
        .and_then(|m| m.range_error.clone())
        .expect("in the result");
    assert!(range.rms_mm > range.at_sphere_mm);
    let html = dir.path().join("r.html");
    let (code, _, err) = run(&[
        "report",
        s.to_str().unwrap(),
        "--result",
        r.to_str().unwrap(),
        "-o",
        html.to_str().unwrap(),
    ]);
    assert_eq!(code, Some(0), "{err}");
    let page = std::fs::read_to_string(&html).unwrap();
    assert!(page.contains("id=\"range-error\""));
    assert!(page.contains("id=\"range-warning\""));
    assert!(page.contains("id=\"range-map\"><svg"));
    assert_eq!(
        page.matches("<title>y ").count(),
        range.map.len(),
        "one cell per grid point"
    );
    let (code, _, err) = run(&[
        "simulate",
        "--out",
        s.to_str().unwrap(),
        "--range",
        "40,-40,0,1",
    ]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("Y0 < Y1"), "{err}");
}
