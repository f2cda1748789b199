//! The five-minute re-check (issue 33) on seeded simulated cells: a cell
//! calibrated by `ml`, re-checked from a `plan --check` plan executed on
//! the true cell, unchanged, with its sphere moved, and knocked (the
//! sensor bumped on its mount, a joint offset changed). The 1,000-trial
//! false-alarm and detection study is an ignored test.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use spherecal::engine::base::robot::{self, Robot};
use spherecal::engine::base::session::Session;
use spherecal::engine::calibrate::solve::ml::recheck::Moved;
use spherecal::engine::calibrate::solve::{self, Method, Options};
use spherecal::engine::files::format::ResultFile;
use spherecal::engine::tools::plan::{Plan, PlanConfig};
use spherecal::engine::tools::simulate::{
    self, ErrorModel, InitialHandEye, PlanExecution, SimConfig, Truth, simulate_plan,
};
use spherecal::engine::uses::check::{
    Checked, DEFAULT_ALPHA, MAX_CHECK_POSES, MAX_CHECK_STATIONS, check_session,
    choose_check_design, plan_check,
};

/// Where the check's sphere is (the IRB 2400's quick-start spot).
const SPHERE: [f64; 3] = [1050.0, 0.0, 475.0];

/// The sphere moved for a check.
const MOVED: [f64; 3] = [1110.0, -90.0, 520.0];

/// A calibrated simulated cell: its truth and its `ml` result.
fn cell(seed: u64) -> (Session, Truth, ResultFile) {
    let config = SimConfig {
        seed,
        ..SimConfig::default()
    };
    let (session, truth) = simulate::simulate(&config).unwrap();
    let mut options = Options::from_session(&session);
    options.method = Method::Ml;
    options.ml.cross_validation = false;
    let (_, cal) = solve::calibrate(&session, &options).unwrap();
    (
        session.clone(),
        truth,
        ResultFile::from_calibration(&session, &cal),
    )
}

/// `plan --check`'s plan for `result` on the IRB 2400.
fn check_plan(result: &ResultFile) -> Plan {
    check_plan_at(result, SPHERE)
}

/// The same with the sphere put elsewhere (the check does not know
/// where the calibration's stations were).
fn check_plan_at(result: &ResultFile, sphere: [f64; 3]) -> Plan {
    let preset = robot::preset("irb2400").unwrap();
    let mut config = PlanConfig::for_preset(&preset, sphere);
    choose_check_design(&mut config, result, None).unwrap().plan
}

/// What changed in the cell since the calibration.
#[derive(Debug, Clone, Copy)]
enum Knock {
    None,
    /// The sensor bumped on its mount: a translation (mm, flange frame).
    Shift([f64; 3]),
    /// The sensor turned on its mount (deg about the flange axes).
    Turn([f64; 3]),
    /// One kinematic parameter changed (index into the 5n MDH list,
    /// deg or mm).
    Parameter(usize, f64),
}

/// The plan executed on the true cell with `knock`, noise of `seed`; the
/// session recorded with the nominal robot, as an import makes it.
fn executed(truth: &Truth, plan: &Plan, knock: Knock, seed: u64) -> Session {
    let mut robot = truth.true_robot();
    let mut hand_eye = truth.true_hand_eye();
    match knock {
        Knock::None => {}
        Knock::Shift(t) => {
            hand_eye = Translation3::new(t[0], t[1], t[2]) * hand_eye;
        }
        Knock::Turn(r) => {
            let rot = UnitQuaternion::from_scaled_axis(Vector3::from(r).map(f64::to_radians));
            hand_eye = Isometry3::from_parts(Translation3::identity(), rot) * hand_eye;
        }
        Knock::Parameter(k, v) => {
            let mut delta = vec![0.0; robot.n_params()];
            delta[k] = if robot::PARAM_IS_ANGLE[k % robot::PARAMS_PER_JOINT] {
                v.to_radians()
            } else {
                v
            };
            robot = robot.perturbed(&delta);
        }
    }
    let config = SimConfig {
        seed,
        errors: ErrorModel::None,
        initial_hand_eye: InitialHandEye::Paper,
        ..SimConfig::default()
    };
    let (mut session, _) = simulate_plan(
        &config,
        &robot,
        &hand_eye,
        &plan.simulation_poses(),
        PlanExecution::AsPlanned,
    )
    .unwrap();
    session.robot = truth.nominal.to_robot();
    session
}

fn check(truth: &Truth, result: &ResultFile, plan: &Plan, knock: Knock, seed: u64) -> Checked {
    let session = executed(truth, plan, knock, seed);
    check_session(&session, result, DEFAULT_ALPHA).unwrap()
}

fn param_index(robot: &Robot, label: &str) -> usize {
    (0..robot.n_params())
        .find(|&k| Robot::param_label(k) == label)
        .unwrap()
}

/// An unchanged cell holds, with the sphere where it was or moved; a
/// knocked one fails and names what moved.
#[test]
fn an_unchanged_cell_holds_and_a_knocked_one_names_what_moved() {
    let (_, truth, result) = cell(1);
    let plan = check_plan(&result);
    let n = plan.poses.len();
    // P0 (translations, rotations) and P1 at the sphere, then one
    // station a further sphere position.
    let stations = plan.stations.len();
    assert!(n <= MAX_CHECK_POSES, "{n}");
    assert!(
        (2..=MAX_CHECK_STATIONS + 1).contains(&stations),
        "{stations}"
    );
    let robot = truth.nominal.to_robot();
    let elsewhere = check_plan_at(&result, MOVED);
    for seed in 10..13 {
        let c = check(&truth, &result, &plan, Knock::None, seed);
        assert!(c.test.holds, "seed {seed}: {:?}", c.test);
        assert_eq!(c.test.dof, 3 * n - 3 * stations);
        let moved = check(&truth, &result, &elsewhere, Knock::None, seed);
        assert!(
            moved.test.holds,
            "moved sphere, seed {seed}: {:?}",
            moved.test
        );
        // The fitted sphere is where the plan put it, to the robot's
        // absolute error (a few mm of base-like error are not calibrated).
        let found = moved.test.centres[0].1;
        assert!((found - Vector3::from(MOVED)).norm() < 10.0, "{found}");
    }
    // The sensor bumped 0.5 mm: fails, the hand-eye named, its size found.
    let c = check(&truth, &result, &plan, Knock::Shift([0.0, 0.5, 0.0]), 20);
    assert!(!c.test.holds, "{:?}", c.test);
    let best = &c.test.explanations[0];
    assert_eq!(best.moved, Moved::HandEye);
    assert!(best.explains, "{best:?}");
    // Its size, in the flange frame: the twist is in the sensor frame.
    let r = result.hand_eye.rotation;
    let found = r * Vector3::new(best.change[0], best.change[1], best.change[2]);
    assert!(
        (found - Vector3::new(0.0, 0.5, 0.0)).norm() < 0.15,
        "{found}"
    );
    // The sensor turned 0.2°.
    let c = check(&truth, &result, &plan, Knock::Turn([0.2, 0.0, 0.0]), 21);
    assert!(!c.test.holds, "{:?}", c.test);
    assert_eq!(c.test.explanations[0].moved, Moved::HandEye);
    // A joint offset changed: theta3 by 0.15°.
    let k = param_index(&robot, "theta3");
    let c = check(&truth, &result, &plan, Knock::Parameter(k, 0.15), 22);
    assert!(!c.test.holds, "{:?}", c.test);
    let best = &c.test.explanations[0];
    assert_eq!(
        best.moved,
        Moved::Parameter("theta3".into()),
        "{:?}",
        c.test.explanations
    );
    assert!(
        (best.change[0] - 0.15).abs() < 3.0 * best.sigma[0] + 0.005,
        "{best:?}"
    );
}

/// `plan --check`'s smallest detectable changes are finite and below the
/// knocks the test above detects.
#[test]
fn the_planned_check_detects_a_fraction_of_a_millimetre() {
    let (_, _, result) = cell(1);
    let plan = check_plan(&result);
    let d = plan_check(
        &plan,
        &result,
        SimConfig::default().stripe_noise,
        DEFAULT_ALPHA,
    )
    .unwrap();
    assert!(d.translation_mm > 0.0 && d.translation_mm < 0.5, "{d:?}");
    assert!(d.rotation_deg > 0.0 && d.rotation_deg < 1.0, "{d:?}");
    // The power the figure promises is there: d4 at its smallest
    // detectable change fails ≥ 80 % of 50 checks (95 % predicted).
    let (_, truth, _) = cell(1);
    let (_, d4, _) = d.parameters.iter().find(|(l, _, _)| l == "d4").unwrap();
    let k = param_index(&truth.nominal.to_robot(), "d4");
    let detected = (0..50)
        .filter(|&s| {
            !check(&truth, &result, &plan, Knock::Parameter(k, *d4), 500 + s)
                .test
                .holds
        })
        .count();
    assert!(detected >= 40, "{detected} of 50");
}

/// Rates over `trials` checks of `cells` calibrated cells for each
/// condition of the issue; printed for the guide.
fn study(cells: u64, trials: u64) -> Vec<(String, f64)> {
    let mut rows: Vec<(String, usize, usize)> = Vec::new();
    let mut count = |name: &str, failed: bool| {
        if let Some(r) = rows.iter_mut().find(|r| r.0 == name) {
            r.1 += usize::from(failed);
            r.2 += 1;
        } else {
            rows.push((name.to_owned(), usize::from(failed), 1));
        }
    };
    for c in 1..=cells {
        let (_, truth, result) = cell(c);
        let plan = check_plan(&result);
        let elsewhere = check_plan_at(&result, MOVED);
        let robot = truth.nominal.to_robot();
        let cov = spherecal::engine::uses::check::model_of(&result, &robot).unwrap();
        let sigma_of = |label: &str| {
            let k = param_index(&robot, label);
            let i = cov.unknowns.iter().position(|&u| u == k + 6).unwrap();
            let s = cov.covariance[(i, i)].sqrt();
            if robot::PARAM_IS_ANGLE[k % robot::PARAMS_PER_JOINT] {
                s.to_degrees()
            } else {
                s
            }
        };
        let printed = plan_check(
            &plan,
            &result,
            SimConfig::default().stripe_noise,
            DEFAULT_ALPHA,
        )
        .unwrap();
        println!(
            "cell {c}: {} poses at {} sphere position(s); plan --check prints {:.3} mm, {:.3}°, {}",
            plan.poses.len(),
            plan.stations.len() - 1,
            printed.translation_mm,
            printed.rotation_deg,
            printed
                .parameters
                .iter()
                .filter(|(l, _, _)| ["theta2", "theta3", "d4"].contains(&l.as_str()))
                .map(|(l, v, s)| format!("{l} {v:.4} ({:.1}σ)", s.unwrap_or(f64::NAN)))
                .collect::<Vec<_>>()
                .join(", ")
        );
        for t in 0..trials / cells {
            let seed = 1000 * c + t;
            count(
                "sphere moved",
                !check(&truth, &result, &elsewhere, Knock::None, seed)
                    .test
                    .holds,
            );
            let mut run = |name: &str, knock: Knock| {
                let failed = !check(&truth, &result, &plan, knock, seed).test.holds;
                count(name, failed);
            };
            run("unchanged", Knock::None);
            for (axis, v) in [
                ("x", [0.3, 0.0, 0.0]),
                ("y", [0.0, 0.3, 0.0]),
                ("z", [0.0, 0.0, 0.3]),
            ] {
                run(&format!("hand-eye 0.3 mm along {axis}"), Knock::Shift(v));
            }
            for (axis, v) in [
                ("x", [0.1, 0.0, 0.0]),
                ("y", [0.0, 0.1, 0.0]),
                ("z", [0.0, 0.0, 0.1]),
            ] {
                run(&format!("hand-eye 0.1° about {axis}"), Knock::Turn(v));
            }
            for label in ["theta2", "theta3", "d4"] {
                let k = param_index(&robot, label);
                run(
                    &format!("{label} 3σ"),
                    Knock::Parameter(k, 3.0 * sigma_of(label)),
                );
                // At the size plan --check prints (95 % predicted).
                let (_, size, _) = printed
                    .parameters
                    .iter()
                    .find(|(l, _, _)| l == label)
                    .unwrap();
                run(
                    &format!("{label} at the printed size (95 % predicted)"),
                    Knock::Parameter(k, *size),
                );
            }
        }
    }
    rows.into_iter()
        .map(|(n, f, t)| (n, f as f64 / t as f64))
        .collect()
}

/// The 1,000-trial study of the issue: false alarms of an unchanged cell
/// and of a moved sphere, detection of each knock.
/// The study at 50 trials, as CI runs it.
#[test]
fn fifty_trial_study() {
    let rows = study(1, 50);
    for (name, rate) in &rows {
        println!("{name}: {:.1} % of checks fail", 100.0 * rate);
    }
}

#[test]
#[ignore = "a study of 1,000 trials a condition (minutes); figures for the guide"]
fn thousand_trial_study() {
    let rows = study(10, 1000);
    for (name, rate) in &rows {
        println!("{name}: {:.1} % of checks fail", 100.0 * rate);
    }
    for (name, rate) in &rows {
        if name == "unchanged" || name.starts_with("sphere") {
            assert!(*rate <= 0.005, "{name}: {rate}");
        }
    }
}
