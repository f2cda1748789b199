//! The `ml` method against simulated ground truth: exact without noise,
//! near the noise floor with it and never clearly worse than the paper's
//! method; the identifiability report names the known redundancies of the
//! IRB 2400; outliers are listed and excluding them restores accuracy;
//! the predicted uncertainty matches what the truth shows.

// The helpers below are test code too: a panic is a test failure with a
// message (clippy.toml allows this only inside `#[test]` functions).
#![allow(clippy::expect_used)]

use spherecal::engine::base::session::{self, ExcludeError};
use spherecal::engine::base::session::{Observation, Session, Use};
use spherecal::engine::calibrate::solve::estimate::Estimate;
use spherecal::engine::calibrate::solve::ml::{Loss, MlReport, MlUpdate};
use spherecal::engine::calibrate::solve::{
    self, Calibration, Control, Method, Options, Prepared, Step, Update,
};
use spherecal::engine::files::format::result::solver_block;
use spherecal::engine::files::format::{self, ResultFile};
use spherecal::engine::tools::evaluate::study as evaluate;
use spherecal::engine::tools::evaluate::{TruthScore, score, validation_errors};
use spherecal::engine::tools::simulate::{SimConfig, Truth};

use crate::support::sim::{self, paper_options, simulate};

fn ml_options(session: &Session) -> Options {
    sim::options(session, Method::Ml)
}

fn run(session: &Session, options: &Options) -> (Prepared, Calibration) {
    solve::calibrate(session, options).expect("calibration")
}

fn report(cal: &Calibration) -> MlReport {
    cal.report.ml().expect("an ml report").clone()
}

fn truth_score(
    session: &Session,
    prepared: &Prepared,
    truth: &Truth,
    cal: &Calibration,
) -> TruthScore {
    score(session, prepared, truth, &cal.calibrated, &cal.hand_eye)
}

#[test]
fn noise_free_session_is_recovered_exactly() {
    // Every noise source off, stripes at full precision. Recorded joints
    // are rounded to 1e-9° by the simulator (~3e-8 mm at the arm's
    // reach), so 1e-6 mm is a real test of exactness. The prior is off:
    // with no noise it would only pull the estimate off the truth.
    let (session, truth) = simulate(&SimConfig {
        seed: 11,
        joint_noise: 0.0,
        stripe_noise: 0.0,
        centre_noise: 0.0,
        tracker_noise: 0.0,
        stripe_decimals: 12,
        ..SimConfig::default()
    });
    let mut options = ml_options(&session);
    options.threshold = 0.0;
    options.ml.prior = false;
    let (prepared, cal) = run(&session, &options);
    let errors = validation_errors(&session, &prepared, &truth, &cal.calibrated, &cal.hand_eye);
    let worst = errors.iter().fold(0.0_f64, |m, e| m.max(e.abs()));
    assert!(worst < 1e-6, "validation distances off by {worst} mm");
    assert!(
        cal.epsilon_after() < 1e-6,
        "ε after = {}",
        cal.epsilon_after()
    );
    let before = validation_errors(
        &session,
        &prepared,
        &truth,
        &session.robot,
        &prepared.hand_eye_initial,
    );
    assert!(
        before.iter().any(|e| e.abs() > 0.3),
        "the nominal model should be far off"
    );
    assert_eq!(cal.stop.code(), "converged", "{}", cal.stop.describe());
}

#[test]
fn noisy_sessions_reach_near_the_floor_and_beat_the_paper() {
    // Five paper-like seeds (Table 1 errors, 9 stations, joint noise
    // 0.003°, stripe noise 0.02 mm).
    let mut ratios = Vec::new();
    let mut paper_ratios = Vec::new();
    for seed in 1..=5 {
        let (session, truth) = simulate(&SimConfig {
            seed,
            ..SimConfig::default()
        });
        let (prepared, paper) = run(&session, &paper_options(&session));
        let (_, ml) = run(&session, &ml_options(&session));
        let p = truth_score(&session, &prepared, &truth, &paper);
        let m = truth_score(&session, &prepared, &truth, &ml);
        eprintln!(
            "seed {seed}: floor {:.4}, paper {:.4} ({:.2}), ml {:.4} ({:.2})",
            m.floor.std,
            p.after.std,
            p.ratio_to_floor(),
            m.after.std,
            m.ratio_to_floor()
        );
        // Never worse than the paper by more than a small margin: the
        // validation std of 54 distances itself scatters by ~10 %.
        assert!(
            m.after.std < 1.1 * p.after.std,
            "seed {seed}: ml {m:?} paper {p:?}"
        );
        assert!(m.improvement() > 10.0, "seed {seed}: {m:?}");
        ratios.push(m.ratio_to_floor());
        paper_ratios.push(p.ratio_to_floor());
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    assert!(
        mean(&ratios) <= 1.3,
        "ml mean ratio to floor {}",
        mean(&ratios)
    );
    assert!(mean(&ratios) < mean(&paper_ratios));
}

#[test]
fn identifiability_names_the_redundancies_of_the_irb2400() {
    let (session, _) = simulate(&SimConfig::default());
    let (_, cal) = run(&session, &ml_options(&session));
    let r = report(&cal);
    // NOTES.md: joint 1 is a rigid motion of everything; d6 and theta6
    // overlap the hand-eye; d2, d3 lie on parallel axes; Hayati's beta is
    // redundant wherever consecutive axes are not parallel.
    for fixed in [
        "alpha1", "a1", "beta1", "theta1", "d1", "d2", "beta2", "beta4", "beta5", "beta6",
        "theta6", "d6",
    ] {
        assert!(
            r.fixed.iter().any(|f| f == fixed),
            "{fixed} not fixed: {:?}",
            r.fixed
        );
    }
    assert_eq!(r.estimated.len(), 24, "{:?}", r.estimated);
    assert_eq!(r.estimated.len() + r.fixed.len(), 36);
    let has = |needle: &str| {
        r.inseparable
            .iter()
            .any(|s| s.to_string().starts_with(needle))
    };
    assert!(
        has("alpha1, a1, beta1, theta1, d1: no effect"),
        "{:#?}",
        r.inseparable
    );
    assert!(has("d6 ~ he_z"), "{:#?}", r.inseparable);
    assert!(has("theta6 ~ he_rz"), "{:#?}", r.inseparable);
    assert!(has("d2 ~ d3"), "{:#?}", r.inseparable);
    // A clean gap between what is kept and what is fixed.
    let kept_min = r.identifiability.pivots[..24]
        .iter()
        .map(|p| p.relative)
        .fold(1.0, f64::min);
    let fixed_max = r.identifiability.pivots[24..]
        .iter()
        .map(|p| p.relative)
        .fold(0.0, f64::max);
    assert!(
        kept_min > 1e-4 && fixed_max < 1e-12,
        "{kept_min} {fixed_max}"
    );
    // The covariance covers exactly the estimated parameters.
    assert_eq!(r.covariance.labels, r.estimated);
    assert_eq!(r.covariance.matrix.len(), 24);
    for (i, row) in r.correlation.matrix.iter().enumerate() {
        assert!((row[i] - 1.0).abs() < 1e-9);
        assert!(row.iter().all(|c| c.abs() <= 1.0 + 1e-9));
    }
}

#[test]
fn an_outlier_is_listed_and_excluding_it_restores_accuracy() {
    // A centres session, so a single measurement's centre can be spoiled.
    let config = SimConfig {
        seed: 4,
        centres: true,
        ..SimConfig::default()
    };
    let (clean, truth) = simulate(&config);
    let (prepared, cal) = run(&clean, &ml_options(&clean));
    let clean_std = truth_score(&clean, &prepared, &truth, &cal).after.std;
    assert!(
        report(&cal).outliers.is_empty(),
        "{:?}",
        report(&cal).outliers
    );

    let mut spoiled = clean.clone();
    let bad = spoiled
        .measurements
        .iter()
        .position(|m| m.usage == Use::Identify && m.station == "P5")
        .expect("station P5");
    let bad_id = spoiled.measurements[bad].id.clone();
    if let Observation::Centre(c) = &mut spoiled.measurements[bad].observation {
        c.x += 2.0;
    }
    let mut paper = paper_options(&spoiled);
    paper.threshold = 0.0;
    let (prepared, paper) = run(&spoiled, &paper);
    let (_, cal) = run(&spoiled, &ml_options(&spoiled));
    let r = report(&cal);
    assert_eq!(r.outliers.len(), 1, "{:?}", r.outliers);
    let o = &r.outliers[0];
    assert_eq!(o.measurement, bad_id);
    assert!(
        o.sigma > r.outlier_limit_sigma && o.residual_mm > 1.0,
        "{o:?}"
    );
    assert!(
        o.reason.contains("mm") && o.reason.contains("σ"),
        "{}",
        o.reason
    );
    eprintln!("outlier {}: {}", o.measurement, o.reason);
    let spoiled_std = truth_score(&spoiled, &prepared, &truth, &cal).after.std;
    let paper_std = truth_score(&spoiled, &prepared, &truth, &paper).after.std;
    eprintln!("clean {clean_std:.4}, with outlier: ml {spoiled_std:.4}, paper {paper_std:.4}");
    // The paper's method has no defence against it.
    assert!(paper_std > 1.5 * clean_std, "{paper_std} vs {clean_std}");

    let rerun =
        session::exclude_measurements(&spoiled, std::slice::from_ref(&bad_id)).expect("exclude");
    assert_eq!(rerun.measurements.len(), spoiled.measurements.len() - 1);
    let (prepared, cal) = run(&rerun, &ml_options(&rerun));
    let rerun_std = truth_score(&rerun, &prepared, &truth, &cal).after.std;
    eprintln!("after excluding {bad_id}: {rerun_std:.4}");
    assert!(report(&cal).outliers.is_empty());
    assert!(
        rerun_std < 1.1 * clean_std,
        "{rerun_std} vs clean {clean_std}"
    );
}

#[test]
fn excluding_checks_the_format_rules() {
    let (session, _) = simulate(&SimConfig::default());
    let err = session::exclude_measurements(&session, &["nope".into()]).unwrap_err();
    assert_eq!(err, ExcludeError::UnknownId("nope".into()));
    let p1: Vec<String> = session
        .measurements
        .iter()
        .filter(|m| m.usage == Use::Identify && m.station == "P1")
        .map(|m| m.id.clone())
        .collect();
    let err = session::exclude_measurements(&session, &p1[1..]).unwrap_err();
    assert!(
        matches!(&err, ExcludeError::StationTooSmall { station, remaining: 1, .. } if station == "P1")
    );
    assert!(err.to_string().contains("identify station P1"), "{err}");
    assert!(session::exclude_measurements(&session, &p1[2..]).is_ok());
    let v1: Vec<String> = session
        .measurements
        .iter()
        .filter(|m| m.usage == Use::Validate && m.station == "V1")
        .map(|m| m.id.clone())
        .collect();
    let err = session::exclude_measurements(&session, &v1).unwrap_err();
    assert!(err.to_string().contains("validate station V1"), "{err}");
}

#[test]
fn predicted_uncertainty_matches_the_truth() {
    let (mut predicted, mut measured) = (0.0, 0.0);
    let (mut cv, mut within) = (0.0, 0.0);
    for seed in 1..=5 {
        let (session, truth) = simulate(&SimConfig {
            seed,
            ..SimConfig::default()
        });
        let (prepared, cal) = run(&session, &ml_options(&session));
        let r = report(&cal);
        let s = truth_score(&session, &prepared, &truth, &cal);
        let p = r.predicted_distance_std_validate.expect("validate pairs");
        eprintln!(
            "seed {seed}: validation std {:.4} (predicted {:.4}), rms {:.4} (predicted {:.4}); cross-validation {:.4}, within-station {:.4}",
            s.after.std,
            p.centred,
            s.after.rms,
            p.rms,
            r.cross_validation.as_ref().map_or(0.0, |c| c.rms),
            cal.validation
                .as_ref()
                .map_or(0.0, |v| v.within_station.after.rms)
        );
        assert!(p.centred > 0.0 && p.rms >= p.centred && p.max >= p.mean);
        predicted += p.centred;
        measured += s.after.std;
        cv += r.cross_validation.as_ref().expect("cross-validation").rms;
        within += cal
            .validation
            .as_ref()
            .expect("validation")
            .within_station
            .after
            .rms;
        assert!(
            r.variance_factor > 0.5 && r.variance_factor < 2.0,
            "{}",
            r.variance_factor
        );
    }
    let ratio = predicted / measured;
    assert!(
        (0.5..2.0).contains(&ratio),
        "predicted/measured validation std {ratio}"
    );
    let ratio = cv / within;
    assert!(
        (0.5..2.0).contains(&ratio),
        "cross-validation/within-station {ratio}"
    );
}

#[test]
fn the_loop_of_format_md_holds_for_ml() {
    let (session, _) = simulate(&SimConfig {
        seed: 3,
        ..SimConfig::default()
    });
    let prepared = solve::prepare(&session).expect("prepare");
    let mut options = ml_options(&session);
    // A threshold above the starting ε: one entry, no update.
    options.threshold = 1000.0;
    let cal = solve::run(&session, &prepared, &options, &mut |_| Control::Continue).expect("run");
    assert_eq!(cal.iterations.len(), 1);
    assert_eq!(cal.stop.code(), "threshold");
    // Threshold 0: one update (a complete LM solve), then LM has converged.
    options.threshold = 0.0;
    let mut seen = Vec::new();
    let cal = solve::run(&session, &prepared, &options, &mut |p| {
        if p.phase == solve::Phase::Loop {
            seen.push((p.updates, p.epsilon));
        }
        Control::Continue
    })
    .expect("run");
    assert_eq!(cal.iterations.len(), 2);
    assert_eq!(seen.len(), 2);
    assert!((seen[1].1 - cal.epsilon_after()).abs() < 1e-15);
    assert_eq!(cal.stop.code(), "converged");
    let r = report(&cal);
    assert!(r.iterations.len() >= 3, "LM steps {:?}", r.iterations);
    assert!((r.iterations.last().map_or(0.0, |i| i.epsilon) - cal.epsilon_after()).abs() < 1e-12);
    // No update allowed: the start is reported, with its diagnostics.
    options.max_iterations = 0;
    let cal = solve::run(&session, &prepared, &options, &mut |_| Control::Continue).expect("run");
    assert_eq!(cal.iterations.len(), 1);
    assert_eq!(cal.stop.code(), "max_iterations");
    // Cancel: a stop reason, with the start reported and no diagnostics.
    options.max_iterations = 20;
    let cal = solve::run(&session, &prepared, &options, &mut |_| Control::Cancel).expect("run");
    let err = cal.stop.describe();
    assert!(err.contains("cancelled"), "{err}");
    assert_eq!(cal.iterations.len(), 1);
    assert!(report(&cal).parameters.is_empty());
    // Bad options are input errors.
    options.ml.joint_sigma_deg = -1.0;
    let err = solve::run(&session, &prepared, &options, &mut |_| Control::Continue).unwrap_err();
    assert!(
        err.is_input_error() && err.to_string().contains("joint sigma"),
        "{err}"
    );
}

#[test]
fn ml_result_block_round_trips_and_is_named() {
    let (session, _) = simulate(&SimConfig::default());
    let (_, cal) = run(&session, &ml_options(&session));
    let block = solver_block(&cal.report);
    assert_eq!(block["method"], "ml");
    for key in [
        "noise_model",
        "prior",
        "loss",
        "estimated",
        "fixed",
        "inseparable",
        "covariance",
        "correlation",
        "predicted_distance_std_validate",
        "predicted_distance_std_identify",
        "cross_validation",
        "outliers",
        "iterations",
        "stop_reason",
    ] {
        assert!(block.contains_key(key), "solver block lacks {key}");
    }
    let r = report(&cal);
    let file = ResultFile::from_calibration(&session, &cal);
    let back = format::parse_result(
        &format::result_to_json(&file),
        std::path::Path::new("r.json"),
    )
    .unwrap();
    assert_eq!(back.solver.ml(), Some(&r));
}

#[test]
fn evaluate_smoke_two_seeds() {
    // The README evidence command, 2 seeds of every scenario.
    let scenarios = evaluate::select("all").expect("scenarios");
    assert_eq!(scenarios.len(), 8);
    let mut results = Vec::new();
    for s in &scenarios {
        let r = evaluate::run_scenario(s, 2).expect("scenario");
        assert_eq!(r.ml.std.len(), 2);
        for (m, f) in r.ml.std.iter().zip(&r.floor) {
            assert!(m.is_finite() && *m < 2.0 * f, "{}: ml {m} floor {f}", s.key);
        }
        results.push(r);
    }
    let table = evaluate::markdown(&results, 2);
    assert_eq!(table.lines().count(), 2 + 8, "{table}");
    assert!(evaluate::select("nope").is_err());
}

/// A reference weighted least-squares fit: `ml`'s problem started at the
/// TRUE model and hand-eye (so the whitening and every fixed parameter are
/// exact), with no prior and no robust loss, LM run to its optimum.
fn reference_fit(session: &Session, prepared: &Prepared, truth: &Truth) -> TruthScore {
    let start = Estimate {
        robot: truth.true_robot(),
        flange_from_sensor: truth.true_hand_eye(),
        mount: session.mount,
    };
    let mut options = ml_options(session);
    options.ml.prior = false;
    options.ml.loss = Loss::Squared;
    let stations = prepared.stations(session, Use::Identify);
    let mut update = MlUpdate::new(session, prepared, &start, stations, &options, &mut |_| {
        Control::Continue
    })
    .expect("reference problem")
    .expect("not cancelled");
    for n in 1..=options.max_iterations {
        if update.update(n, &mut |_| Control::Continue).expect("LM") != Step::Moved {
            break;
        }
    }
    let est = update.estimate();
    score(
        session,
        prepared,
        truth,
        &est.robot,
        &est.flange_from_sensor,
    )
}

#[test]
fn many_stations_stay_at_the_efficient_level_and_nine_do_not_lose() {
    // Issue 14, part 6. At 30 stations the validation std of `ml` is
    // 1.11x the floor (mean of seeds 1..=5; 1.23 worst), at 9 stations
    // 1.21x. The rest is not lost by the solver: the reference weighted
    // least-squares fit from the truth (exact whitening, no prior, no
    // robust loss) is no closer to the floor (1.16x at 30 stations);
    // the parameter uncertainty the data leave, mostly the global length
    // scale, is what remains, and the prior is what takes `ml` below the
    // reference. The goal of 1.03x is therefore not asserted; these bounds
    // guard what was measured (README, "Efficiency at many stations").
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let scenario = |key: &str| evaluate::select(key).expect("scenario")[0];
    let (many_stations, paper_like) = (scenario("stations-30"), scenario("paper-like"));
    let many = evaluate::run_scenario(&many_stations, 5).expect("stations-30");
    let nine = evaluate::run_scenario(&paper_like, 5).expect("paper-like");
    let (many_ml, nine_ml) = (mean(&many.ml.ratio), mean(&nine.ml.ratio));
    eprintln!("ml / floor: 30 stations {many_ml:.3}, 9 stations {nine_ml:.3}");
    assert!(many_ml <= 1.12, "30 stations: ml / floor {many_ml}");
    assert!(nine_ml <= 1.21, "9 stations: ml / floor {nine_ml}");
    assert!(many_ml < mean(&many.paper.ratio) && nine_ml < mean(&nine.paper.ratio));
    let mut reference = Vec::new();
    for seed in 1..=5 {
        let (session, truth) = simulate(&(many_stations.config)(seed));
        let prepared = solve::prepare(&session).expect("prepare");
        reference.push(reference_fit(&session, &prepared, &truth).ratio_to_floor());
    }
    let reference = mean(&reference);
    eprintln!("reference weighted LS from the truth, 30 stations: {reference:.3}");
    assert!(
        reference > 1.1 && many_ml <= reference,
        "reference {reference}, ml {many_ml}"
    );
}

#[test]
fn a_cancel_in_the_diagnostics_ends_the_run_as_cancelled() {
    let (session, _) = simulate(&SimConfig::default());
    let prepared = solve::prepare(&session).expect("prepare");
    let options = ml_options(&session);
    let mut phases = Vec::new();
    let cal = solve::run(&session, &prepared, &options, &mut |p| {
        phases.push(p.phase);
        if matches!(p.phase, solve::Phase::CrossValidation { done: 3, .. }) {
            Control::Cancel
        } else {
            Control::Continue
        }
    })
    .expect("run");
    assert!(cal.stop.is_cancelled(), "{}", cal.stop.describe());
    let report = cal.report.ml().expect("ml");
    assert!(report.cross_validation.is_none() && report.parameters.is_empty());
    // Every phase reported itself before the cancel.
    assert!(phases.contains(&solve::Phase::Covariance));
    assert!(phases.contains(&solve::Phase::Prediction));
    assert!(
        phases
            .iter()
            .any(|p| matches!(p, solve::Phase::Step { .. }))
    );
}

/// Issue 22: every phase of a run looks at the cancel when it starts, the
/// last one included: a cancel at the first report of any phase ends the
/// run as cancelled at once, with no report after it (the app's Cancel
/// then never waits for a phase to finish).
#[test]
fn every_phase_of_a_run_polls_the_cancel() {
    use solve::Phase;
    let (session, _) = simulate(&SimConfig::default());
    let prepared = solve::prepare(&session).expect("prepare");
    let options = ml_options(&session);
    let kind = |p: &Phase| -> u8 {
        match p {
            Phase::Setup => 0,
            Phase::Loop => 1,
            Phase::Step { .. } => 2,
            Phase::Covariance => 3,
            Phase::Outliers => 4,
            Phase::Prediction => 5,
            Phase::RangeError => 6,
            Phase::CrossValidation { .. } => 7,
            Phase::Finishing => 8,
            Phase::HeldOut { .. } => 9,
        }
    };
    for target in 0..=9 {
        let mut cancelled = false;
        let mut after = Vec::new();
        let cal = solve::run(&session, &prepared, &options, &mut |p| {
            if cancelled {
                after.push(p.phase);
                Control::Continue
            } else if kind(&p.phase) == target {
                cancelled = true;
                Control::Cancel
            } else {
                Control::Continue
            }
        })
        .expect("run");
        assert!(cancelled, "phase {target} was never reported");
        assert!(
            cal.stop.is_cancelled(),
            "phase {target}: {}",
            cal.stop.describe()
        );
        assert!(
            after.is_empty(),
            "phase {target}: reports after the cancel: {after:?}"
        );
    }
}
