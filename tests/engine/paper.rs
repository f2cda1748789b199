//! The paper's method end to end against simulated ground truth: the
//! estimators must recover the truth exactly without noise and come within
//! a stated factor of the noise floor with it.

// Test helpers may panic: a panic is a test failure with its message.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use spherecal::engine::base::robot::Robot;
use spherecal::engine::base::session::{Session, Use};
use spherecal::engine::calibrate::solve::{self, Prepared};
use spherecal::engine::tools::evaluate;
use spherecal::engine::tools::simulate::{SimConfig, Truth};

use crate::support::sim::{self, paper_options, simulate};

/// Noise-free: every noise source off and stripes written at full precision.
/// The paper's method (`paper_options`) is these tests' baseline; the `ml`
/// method, the default, has its own in `tests/engine/ml.rs`.
fn noise_free(seed: u64) -> SimConfig {
    SimConfig {
        cut_jitter: 3.0,
        stripe_decimals: 12,
        ..sim::noise_free(seed)
    }
}

fn run(session: &Session, threshold: f64, max_iterations: usize) -> (Prepared, solve::Calibration) {
    let mut options = paper_options(session);
    options.threshold = threshold;
    options.max_iterations = max_iterations;
    solve::calibrate(session, &options).expect("calibration")
}

/// True distances between validate stations against those the calibrated
/// model measures, every k-th pose pair.
fn max_distance_error(
    session: &Session,
    prepared: &Prepared,
    truth: &Truth,
    robot: &Robot,
    he: &nalgebra::Isometry3<f64>,
) -> f64 {
    evaluate::validation_errors(session, prepared, truth, robot, he)
        .iter()
        .fold(0.0_f64, |m, e| m.max(e.abs()))
}

#[test]
fn noise_free_stripe_session_is_recovered_exactly() {
    let (session, truth) = simulate(&noise_free(11));
    let (prepared, cal) = run(&session, 0.0, 30);
    // The noise-free sphere centres are exact.
    for (m, p) in session.measurements.iter().zip(&prepared.measurements) {
        let t = truth.measurement(&m.id).unwrap();
        let d = (p.centre_in_sensor - nalgebra::Vector3::from(t.sensor_centre)).norm();
        assert!(d < 1e-6, "{}: sensor centre off by {d}", m.id);
    }
    assert!(
        cal.epsilon_after() < 1e-6,
        "ε after = {}",
        cal.epsilon_after()
    );
    let err = max_distance_error(&session, &prepared, &truth, &cal.calibrated, &cal.hand_eye);
    assert!(err < 1e-6, "validation distances off by {err} mm");
    // Before calibration the nominal model is far off.
    let before = max_distance_error(
        &session,
        &prepared,
        &truth,
        &session.robot,
        &prepared.hand_eye_initial,
    );
    assert!(before > 0.3, "{before}");
}

#[test]
fn noise_free_initial_hand_eye_from_true_model_is_exact() {
    // With the nominal model replaced by the truth, eq. 6-9 see exact flange
    // poses, so the initial hand-eye equals the true one.
    let (mut session, truth) = simulate(&noise_free(12));
    session.robot = truth.true_robot();
    let prepared = solve::prepare(&session).unwrap();
    let he = prepared.hand_eye_initial;
    let t = truth.true_hand_eye();
    assert!(he.rotation.angle_to(&t.rotation) < 1e-9);
    assert!((he.translation.vector - t.translation.vector).norm() < 1e-6);
}

#[test]
fn noise_free_centres_session_is_recovered_exactly() {
    let config = SimConfig {
        centres: true,
        ..noise_free(13)
    };
    let (session, truth) = simulate(&config);
    let (prepared, cal) = run(&session, 0.0, 30);
    let err = max_distance_error(&session, &prepared, &truth, &cal.calibrated, &cal.hand_eye);
    assert!(err < 1e-6, "validation distances off by {err} mm");
}

#[test]
fn noisy_sessions_reach_near_the_noise_floor() {
    // Five seeds of the paper-like session (joint noise 0.003°, stripe
    // noise 0.02 mm): the calibrated validation std must be within 3× the
    // floor and at least 10× better than before.
    let mut ratios = Vec::new();
    for seed in 1..=5 {
        let (session, truth) = simulate(&SimConfig {
            seed,
            ..SimConfig::default()
        });
        let (prepared, cal) = run(
            &session,
            session.solver.threshold,
            session.solver.max_iterations,
        );
        let score = evaluate::score(&session, &prepared, &truth, &cal.calibrated, &cal.hand_eye);
        eprintln!(
            "seed {seed}: before {:.4} after {:.4} floor {:.4} (ratio {:.2}, improvement {:.1}x)",
            score.before.std,
            score.after.std,
            score.floor.std,
            score.ratio_to_floor(),
            score.improvement()
        );
        assert!(score.ratio_to_floor() < 3.0, "seed {seed}: {score:?}");
        assert!(score.improvement() > 10.0, "seed {seed}: {score:?}");
        ratios.push(score.ratio_to_floor());
    }
    let mean = ratios.iter().sum::<f64>() / ratios.len() as f64;
    assert!(mean < 2.5, "mean ratio to floor {mean}");
}

#[test]
fn epsilon_series_follows_the_loop_of_format_md() {
    let (session, _) = simulate(&SimConfig {
        seed: 3,
        ..SimConfig::default()
    });
    // A threshold above the starting ε: one entry, no update.
    let prepared = solve::prepare(&session).unwrap();
    let mut options = paper_options(&session);
    options.threshold = 1000.0;
    let cal = solve::run(&session, &prepared, &options, &mut |_| {
        solve::Control::Continue
    })
    .unwrap();
    assert_eq!(cal.iterations.len(), 1);
    assert!(
        cal.report
            .paper()
            .is_some_and(|p| p.kept_directions.is_none())
    );
    // Threshold 0 with a bound of 4: exactly 4 updates, 5 entries.
    options.threshold = 0.0;
    options.max_iterations = 4;
    let mut seen = Vec::new();
    let cal = solve::run(&session, &prepared, &options, &mut |p| {
        if p.phase == solve::Phase::Loop {
            seen.push((p.updates, p.epsilon));
        }
        solve::Control::Continue
    })
    .unwrap();
    assert_eq!(cal.iterations.len(), 5);
    assert_eq!(seen.len(), 5);
    assert_eq!(seen[4].0, 4);
    assert!((seen[4].1 - cal.epsilon_after()).abs() < 1e-15);
    assert!(cal.epsilon_after() < cal.epsilon_before());
    assert!(matches!(
        cal.stop,
        solve::StopReason::IterationLimit { updates: 4, .. }
    ));
}

#[test]
fn cancel_stops_the_loop() {
    let (session, _) = simulate(&SimConfig::default());
    let prepared = solve::prepare(&session).unwrap();
    let mut options = paper_options(&session);
    options.threshold = 0.0;
    // A cancel is a stop reason (not an error): the run ends with the
    // estimate reached so far.
    let cal = solve::run(&session, &prepared, &options, &mut |p| {
        if p.updates >= 2 {
            solve::Control::Cancel
        } else {
            solve::Control::Continue
        }
    })
    .unwrap();
    let err = cal.stop.describe();
    assert!(err.contains("cancelled"), "{err}");
    assert_eq!(cal.iterations.len(), 3);
}

#[test]
fn too_little_identify_data_is_explained() {
    let (mut session, _) = simulate(&SimConfig::default());
    session.measurements.retain(|m| m.usage != Use::Identify);
    let err = solve::calibrate(&session, &paper_options(&session)).unwrap_err();
    assert!(err.to_string().contains("identify station"), "{err}");
}

#[test]
fn the_paper_loop_stops_when_epsilon_has_levelled_off() {
    // Threshold 0 and a bound of 100,000: the loop must stop once ε no
    // longer moves, not run every update.
    let (session, _) = simulate(&SimConfig::default());
    let prepared = solve::prepare(&session).unwrap();
    let mut options = paper_options(&session);
    options.threshold = 0.0;
    options.max_iterations = 100_000;
    let cal = solve::run(&session, &prepared, &options, &mut |_| {
        solve::Control::Continue
    })
    .unwrap();
    assert_eq!(cal.stop.code(), "levelled_off", "{}", cal.stop.describe());
    assert!(
        cal.iterations.len() < 200,
        "{} updates",
        cal.iterations.len()
    );
}

/// A session broken in code and the same session written and read:
/// the typed rules and the loader say the same (one home for each
/// rule), the loader adding only the position.
#[test]
fn typed_rules_and_the_loader_agree() {
    let (base, _) = spherecal::engine::tools::simulate::simulate(
        &spherecal::engine::tools::simulate::SimConfig {
            n_identify: 2,
            n_validate: 2,
            ..spherecal::engine::tools::simulate::SimConfig::default()
        },
    )
    .unwrap();
    assert_eq!(base.validate(), Ok(()));
    type Break = Box<dyn Fn(&mut spherecal::engine::base::session::Session)>;
    let breaks: Vec<(&str, Break)> = vec![
        (
            "few points",
            Box::new(|s: &mut spherecal::engine::base::session::Session| {
                s.measurements[3].observation =
                    spherecal::engine::base::session::Observation::Stripe(vec![[0.0, 1.0]; 3]);
            }),
        ),
        (
            "duplicate id",
            Box::new(|s: &mut spherecal::engine::base::session::Session| {
                s.measurements[4].id = s.measurements[2].id.clone();
            }),
        ),
        (
            "joint count",
            Box::new(|s: &mut spherecal::engine::base::session::Session| {
                s.measurements[5].joints.pop();
            }),
        ),
        (
            "implausible joint",
            Box::new(|s: &mut spherecal::engine::base::session::Session| {
                s.measurements[5].joints[2] = 1e9;
            }),
        ),
        (
            "diameter",
            Box::new(|s: &mut spherecal::engine::base::session::Session| {
                s.sphere_diameter = 5000.0;
            }),
        ),
        (
            "reference",
            Box::new(|s: &mut spherecal::engine::base::session::Session| {
                s.reference_distances[0].from = "P1".to_string();
            }),
        ),
        (
            "robot",
            Box::new(|s: &mut spherecal::engine::base::session::Session| {
                s.robot.joints[1].a = 1e12;
            }),
        ),
    ];
    for (what, broken) in breaks {
        let mut s = base.clone();
        broken(&mut s);
        let typed = s.validate().expect_err(what);
        let loaded = spherecal::engine::files::format::parse_session(
            &spherecal::engine::files::format::session_to_json(&s),
            std::path::Path::new("t.json"),
        )
        .expect_err(what)
        .to_string();
        assert!(
            loaded.contains(&typed.message),
            "{what}: typed `{}` vs loader `{loaded}`",
            typed.message
        );
    }
}
