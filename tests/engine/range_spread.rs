//! Spreading the sphere over the sensor's range (issue 14): the simulator
//! and the planner put the sphere anywhere in `sensor.range`, the error
//! over the range is scored against the truth and its floor, and a plan
//! with the spread reaches the floor where the paper's one spot does not.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use crate::support::bin::run;
use spherecal::engine::base::robot;
use spherecal::engine::base::session::{SensorRange, Use};
use spherecal::engine::calibrate::solve::{self, Control, Options};
use spherecal::engine::tools::evaluate::range::range_score;
use spherecal::engine::tools::evaluate::study::{STUDY_RANGE, run_scenario, select};
use spherecal::engine::tools::plan::range_study::planned_range_study;
use spherecal::engine::tools::plan::{self, PlanConfig, PlanStage};
use spherecal::engine::tools::simulate::{self, SimConfig, SimError};

const RANGE: SensorRange = SensorRange {
    y: [-40.0, 40.0],
    z: [-30.0, 30.0],
};

fn extent(values: impl Iterator<Item = f64>) -> [f64; 2] {
    values.fold([f64::INFINITY, f64::NEG_INFINITY], |e, v| {
        [e[0].min(v), e[1].max(v)]
    })
}

#[test]
fn the_simulator_spreads_the_sphere_over_the_range() {
    let config = SimConfig {
        range: Some(RANGE),
        spread: true,
        ..SimConfig::default()
    };
    let (session, truth) = simulate::simulate(&config).unwrap();
    assert_eq!(session.sensor_range, Some(RANGE));
    let centres = |usage: Use| -> Vec<[f64; 3]> {
        truth
            .measurements
            .iter()
            .filter(|(_, m)| m.usage == usage)
            .map(|(_, m)| m.sensor_centre)
            .collect()
    };
    for usage in [Use::Identify, Use::Validate] {
        let c = centres(usage);
        assert!(c.iter().all(|p| RANGE.contains(p[1], p[2])), "{usage:?}");
        let (y, z) = (
            extent(c.iter().map(|p| p[1])),
            extent(c.iter().map(|p| p[2])),
        );
        // 54 or 60 uniform draws cover most of each side.
        assert!(y[1] - y[0] > 0.8 * 80.0, "{usage:?} y {y:?}");
        assert!(z[1] - z[0] > 0.8 * 60.0, "{usage:?} z {z:?}");
    }
    // The hand-eye rotations at P0 keep the paper's spot.
    assert!(
        centres(Use::Rotation)
            .iter()
            .all(|p| p[1].abs() <= 2.0 && p[2].abs() <= 3.0)
    );
    // Without the spread the sphere stays at the spot.
    let (_, spot) = simulate::simulate(&SimConfig {
        range: Some(RANGE),
        ..SimConfig::default()
    })
    .unwrap();
    assert!(
        spot.measurements
            .iter()
            .all(|(_, m)| m.usage == Use::Translation
                || (m.sensor_centre[1].abs() <= 2.0 && m.sensor_centre[2].abs() <= 3.0))
    );
    let e = simulate::simulate(&SimConfig {
        spread: true,
        ..SimConfig::default()
    })
    .unwrap_err();
    assert!(
        matches!(&e, SimError::InvalidConfig(m) if m.contains("spread needs a range")),
        "{e}"
    );
}

#[test]
fn the_range_score_holds_a_model_to_the_truth_and_its_floor() {
    let config = SimConfig {
        range: Some(RANGE),
        ..SimConfig::default()
    };
    let (session, truth) = simulate::simulate(&config).unwrap();
    let prepared = solve::prepare(&session).unwrap();
    let true_robot = truth.true_robot();
    let true_he = truth.true_hand_eye();
    let exact = range_score(
        &session,
        &truth,
        &prepared.hand_eye_initial,
        &true_robot,
        &true_he,
        None,
    )
    .unwrap();
    // The true model is at the floor, with no model error.
    assert_eq!(exact.after, exact.floor);
    assert!(exact.model.rms < 1e-9, "{:?}", exact.model);
    // The floor is the joint noise seen at the points: 0.003° at about a
    // metre and a half of arm, tenths of a millimetre at most.
    assert!((0.03..0.3).contains(&exact.floor.rms), "{:?}", exact.floor);
    // The nominal model is far off.
    assert!(exact.before.rms > 5.0 * exact.floor.rms, "{exact:?}");
    // Noise-free readings: the floor is zero (up to the joints' written
    // decimals).
    let (quiet, quiet_truth) = simulate::simulate(&SimConfig {
        joint_noise: 0.0,
        ..config
    })
    .unwrap();
    let q = range_score(
        &quiet,
        &quiet_truth,
        &prepared.hand_eye_initial,
        &true_robot,
        &true_he,
        None,
    )
    .unwrap();
    assert!(q.floor.rms < 1e-6, "{:?}", q.floor);
    // No range in the session and none given: no score.
    let mut bare = session.clone();
    bare.sensor_range = None;
    assert!(range_score(&bare, &truth, &true_he, &true_robot, &true_he, None).is_none());
}

/// The simulated evidence (`spherecal evaluate --scenario range-…`): the
/// sphere spread over the range brings ml's error over it much nearer the
/// floor than the paper's one spot.
#[test]
fn spreading_the_simulated_sphere_lowers_the_range_error() {
    let seeds = 3;
    let spot = run_scenario(&select("range-spot").unwrap()[0], seeds).unwrap();
    let spread = run_scenario(&select("range-spread").unwrap()[0], seeds).unwrap();
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let (spot_ratio, spread_ratio) = (mean(&spot.ml.range_ratio), mean(&spread.ml.range_ratio));
    eprintln!("ml over the range / floor: spot {spot_ratio:.2}, spread {spread_ratio:.2}");
    assert_eq!(spot.ml.range_ratio.len(), 3);
    assert!(spot_ratio > 1.6, "{spot_ratio}");
    assert!(spread_ratio < 1.4, "{spread_ratio}");
    assert!(spread_ratio < 0.75 * spot_ratio);
    assert!(spot.range_floor.iter().all(|f| *f > 0.0));
}

/// The planner spreads the identify and validate poses over the range,
/// keeps the hand-eye groups at the spot, predicts the error over the
/// range and compares it with the plan without the spread.
#[test]
fn the_planner_spreads_the_sphere_and_compares() {
    let preset = robot::preset("irb2400").unwrap();
    let config = PlanConfig {
        range: Some(STUDY_RANGE),
        spread: true,
        ..PlanConfig::for_preset(&preset, [1050.0, 0.0, 475.0])
    };
    let mut stages = Vec::new();
    let made = plan::plan(&config, &mut |s| {
        stages.push(s);
        Control::Continue
    })
    .unwrap();
    assert!(stages.contains(&PlanStage::Comparison));
    for usage in [Use::Identify, Use::Validate] {
        let poses: Vec<_> = made.poses.iter().filter(|p| p.usage == usage).collect();
        assert!(
            poses
                .iter()
                .all(|p| STUDY_RANGE.contains(p.centre_in_sensor.y, p.centre_in_sensor.z))
        );
        let y = extent(poses.iter().map(|p| p.centre_in_sensor.y));
        let z = extent(poses.iter().map(|p| p.centre_in_sensor.z));
        assert!(
            y[1] - y[0] > 60.0 && z[1] - z[0] > 60.0,
            "{usage:?} {y:?} {z:?}"
        );
    }
    assert!(
        made.poses
            .iter()
            .filter(|p| matches!(p.usage, Use::Translation | Use::Rotation))
            .all(|p| p.centre_in_sensor.y.abs() <= 30.0)
    );
    let spread = made.stats.range_error.as_ref().unwrap();
    let unspread = made.stats.range_error_unspread.as_ref().unwrap();
    assert_eq!(spread.region, "sensor.range");
    assert!(
        // Without the spread the sphere is still seen within ±12 mm of
        // the plane's centre (the plan's default, issue 32), not at the
        // paper's ±2, ±3 mm spot: the spread still lowers it by a third.
        unspread.rms_mm > 1.5 * spread.rms_mm,
        "{} vs {}",
        unspread.rms_mm,
        spread.rms_mm
    );
    let text = plan::summary(&made);
    assert!(
        text.contains("predicted point error over the range"),
        "{text}"
    );
    assert!(text.contains("without the spread: rms"), "{text}");
    // Spreading needs a range.
    let bad = PlanConfig {
        range: None,
        ..config
    };
    let e = plan::plan(&bad, &mut |_| Control::Continue).unwrap_err();
    assert!(e.to_string().contains("needs the sensor's range"), "{e}");
}

/// The acceptance: the IRB 2400 cell planned with the spread,
/// simulated (Table 1 and random errors, 5 seeds each) and calibrated with
/// ml, is within 1.2× the floor over the 80 × 80 mm range; planned without
/// the spread it is worse, predicted and realised; the prediction of the
/// spread plan agrees with the realised model error within 20 %.
#[test]
fn a_spread_plan_is_within_1_2_times_the_floor_over_the_range() {
    let rows = planned_range_study(5).unwrap();
    for r in &rows {
        eprintln!("{r:?}");
    }
    assert_eq!(rows.len(), 4);
    for errors in ["table1", "random"] {
        let spread = rows
            .iter()
            .find(|r| r.spread && r.errors == errors)
            .unwrap();
        let spot = rows
            .iter()
            .find(|r| !r.spread && r.errors == errors)
            .unwrap();
        assert!(spread.ratio <= 1.2, "{errors}: {spread:?}");
        assert!(spot.ratio > spread.ratio + 0.2, "{errors}: {spot:?}");
        // The spot is the default ±12 mm about the plane's centre.
        assert!(spot.predicted_rms > 1.5 * spread.predicted_rms);
        assert!(spot.after_max > spread.after_max);
        let agreement = spread.model_rms / spread.predicted_rms;
        assert!((0.8..=1.2).contains(&agreement), "{errors}: {agreement}");
    }
}

/// The calibrated cell of a spread simulation: `ml` with the range.
#[test]
fn ml_on_a_spread_session_reports_full_coverage() {
    let (session, _) = simulate::simulate(&SimConfig {
        range: Some(RANGE),
        spread: true,
        ..SimConfig::default()
    })
    .unwrap();
    let mut options = Options::from_session(&session);
    options.ml.cross_validation = false;
    let (_, cal) = solve::calibrate(&session, &options).unwrap();
    let range = cal.report.ml().unwrap().range_error.clone().unwrap();
    assert!(range.coverage > 0.6, "{}", range.coverage);
    assert!(range.warning.is_none());
    // Seen everywhere, the error is nearly even over the range.
    assert!(range.max_mm < 2.0 * range.at_sphere_mm, "{range:?}");
}

/// `simulate --spread`, `plan --range [--no-spread]`, `evaluate` with the
/// range scenarios, from the command line.
#[test]
fn the_command_line_spreads_plans_and_scores_the_range() {
    let dir = tempfile::tempdir().unwrap();
    let s = dir.path().join("s.json");
    let (code, _, err) = run(&["simulate", "--out", s.to_str().unwrap(), "--spread"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--range"), "{err}");
    let (code, _, err) = run(&[
        "simulate",
        "--out",
        s.to_str().unwrap(),
        "--range",
        "-40,40,-30,30",
        "--spread",
    ]);
    assert_eq!(code, 0, "{err}");
    let truth =
        simulate::parse_truth(&std::fs::read_to_string(dir.path().join("s.truth.json")).unwrap())
            .unwrap();
    assert!(truth.config.spread);
    assert_eq!(truth.config.range, Some(RANGE));
    let spread_y = extent(
        truth
            .measurements
            .iter()
            .filter(|(_, m)| m.usage == Use::Identify)
            .map(|(_, m)| m.sensor_centre[1]),
    );
    assert!(spread_y[1] - spread_y[0] > 50.0, "{spread_y:?}");

    // A small cell for the command line: 4 identify, 3 validate stations.
    let plan = |extra: &[&str]| {
        let mut args = vec![
            "plan",
            "--sphere",
            "1050,0,475",
            "--range",
            "-40,40,-40,40",
            "--identify-stations",
            "4",
            "--validate-stations",
            "3",
            "--candidates",
            "10",
        ];
        args.extend_from_slice(extra);
        run(&args)
    };
    let (code, out, err) = plan(&["--predict", "2"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("predicted point error over the range (y -40…40, z -40…40 mm"),
        "{out}"
    );
    assert!(out.contains("without the spread: rms"), "{out}");
    assert!(out.contains("error over the range (9 × 9 grid"), "{out}");
    let (code, out, err) = plan(&["--no-spread", "--predict", "0"]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("the sphere at one spot"), "{out}");
    let (code, _, err) = run(&["plan", "--sphere", "1050,0,475", "--no-spread"]);
    assert_eq!(code, 2, "{err}");

    let (code, out, err) = run(&["evaluate", "--scenario", "range-spread", "--seeds", "1"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("error over the range (rms over a 9 × 9 grid"),
        "{out}"
    );
}
