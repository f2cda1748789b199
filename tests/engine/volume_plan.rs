//! The plan for the working volume (issue 32): `plan --volume` chooses
//! the identify poses for the mean predicted measuring error over the
//! working volume (I-optimal), every plan prints it, and `plan --predict` scores the realised error over the
//! volume of the validate stations against the repeatability floor.
//!
//! The study (`#[ignore]`, the guide's evidence chapter
//! docs/src/evidence/volume.md):
//!
//! ```text
//! cargo test --release --test engine -- --ignored --nocapture volume_plan::volume_study
//! ```

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::time::Instant;

use spherecal::engine::base::robot;
use spherecal::engine::calibrate::solve::Control;
use spherecal::engine::tools::plan::{self, Plan, PlanConfig, PredictConfig, Selection};

const SPHERE: [f64; 3] = [1050.0, 0.0, 475.0];

fn config(stations: usize, poses: usize, selection: Selection, seed: u64) -> PlanConfig {
    let mut c = PlanConfig::for_preset(&robot::irb2400(), SPHERE);
    c.design.n_identify = stations;
    c.design.identify_poses = poses;
    c.design.selection = selection;
    c.design.seed = seed;
    c
}

fn make(c: &PlanConfig) -> Plan {
    plan::plan(c, &mut |_| Control::Continue).unwrap()
}

/// The volume objective (the default) predicts a smaller error
/// over the working volume than the D-optimal and the random choice from
/// the same candidates; the three are scored on the same sampled volume.
#[test]
fn the_volume_plan_is_chosen_for_the_working_volume() {
    assert_eq!(
        PlanConfig::for_preset(&robot::irb2400(), SPHERE)
            .design
            .selection,
        Selection::Volume
    );
    let mut c = config(6, 6, Selection::Volume, 3);
    c.design.n_validate = 4;
    c.design.candidates = 12;
    let volume = make(&c);
    let d = make(&PlanConfig {
        design: plan::PlanDesign {
            selection: Selection::DOptimal,
            ..c.design
        },
        ..c.clone()
    });
    let v = volume.stats.volume_error.unwrap();
    let r = volume.stats.volume_error_random.unwrap();
    let dv = d.stats.volume_error.unwrap();
    assert_eq!(v.samples, dv.samples);
    assert!(
        v.samples >= plan::VOLUME_SAMPLES / 2,
        "{} samples",
        v.samples
    );
    assert!(v.rms_mm < dv.rms_mm, "volume {v:?} vs D-optimal {dv:?}");
    assert!(v.rms_mm < r.rms_mm, "volume {v:?} vs random {r:?}");
    // The D-optimal plan is the best by ln det.
    assert!(d.stats.log_det >= volume.stats.log_det - 1e-9);
    let summary = plan::summary(&volume);
    assert!(summary.contains("predicted measuring error over the working volume"));
    assert!(summary.contains("the same stations with poses at random"));
}

/// The realised volume error of `predict`: against the floor of the same
/// readings, and the prediction of the planner within a factor of 2 of
/// the realised model part.
#[test]
fn predict_scores_the_error_over_the_volume() {
    let mut c = config(6, 6, Selection::Volume, 2);
    c.design.n_validate = 5;
    c.design.candidates = 12;
    let p = make(&c);
    let predicted = p.stats.volume_error.unwrap();
    let pr = plan::predict(
        &p,
        &PredictConfig {
            runs: 3,
            ..PredictConfig::default()
        },
        &mut |_, _| Control::Continue,
    )
    .unwrap();
    let v = pr.volume.unwrap();
    for run in &pr.runs {
        let s = run.volume.unwrap();
        assert_eq!(s.stations, 5);
        assert!(s.floor.rms > 0.0 && s.after.rms > 0.0);
        assert!(s.ratio_to_floor() <= v.ratio_max + 1e-12);
    }
    assert!(v.ratio_mean >= 0.9, "{v:?}");
    // The model part of the realised error (after² − floor², one station
    // mean of a few sightings) against the planner's predicted σ.
    let model = (v.after_rms.powi(2) - v.floor_rms.powi(2)).max(0.0).sqrt();
    assert!(
        model < 2.0 * predicted.rms_mm && model > predicted.rms_mm / 4.0,
        "realised model part {model:.4} mm, predicted {:.4} mm",
        predicted.rms_mm
    );
}

/// One row of the study: mean and worst `after / floor` of the volume
/// error over the seeds, the predicted and realised rms, the time.
fn study_row(name: &str, configs: &[PlanConfig], runs: usize) {
    let (mut ratios, mut predicted, mut realised, mut ms) = (vec![], vec![], vec![], 0.0);
    for c in configs {
        let t = Instant::now();
        let p = make(c);
        ms += t.elapsed().as_secs_f64() * 1e3;
        let pr = plan::predict(
            &p,
            &PredictConfig {
                runs,
                seed: 100 * c.design.seed,
                ..PredictConfig::default()
            },
            &mut |_, _| Control::Continue,
        )
        .unwrap();
        for r in &pr.runs {
            ratios.push(r.volume.unwrap().ratio_to_floor());
        }
        let v = pr.volume.unwrap();
        predicted.push(p.stats.volume_error.map_or(f64::NAN, |e| e.rms_mm));
        realised.push((v.after_rms.powi(2) - v.floor_rms.powi(2)).max(0.0).sqrt());
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    println!(
        "| {name} | {:.2} | {:.2} | {:.4} | {:.4} | {:.2} | {:.0} |",
        mean(&ratios),
        ratios.iter().copied().fold(0.0, f64::max),
        mean(&predicted),
        mean(&realised),
        mean(&realised) / mean(&predicted),
        ms / configs.len() as f64
    );
}

/// The study table of docs/src/evidence/volume.md: 9, 15, 20, 30 identify
/// stations of 6 poses; the paper's layout (9 stations, as many
/// measurements, poses at random), random, D-optimal and the volume plan;
/// plan seeds 1..=5, each scored on 4 simulated cells.
#[test]
#[ignore = "study: minutes; the guide's evidence chapter"]
fn volume_study() {
    let seeds = 1..=5_u64;
    let runs = 4;
    println!(
        "| plan | volume error / floor, mean | worst | predicted σ rms, mm | realised model part rms, mm | realised / predicted | plan time, ms |"
    );
    println!("|---|---|---|---|---|---|---|");
    // `VOLUME_STUDY_STATIONS=9,15` runs part of the table.
    let counts: Vec<usize> = std::env::var("VOLUME_STUDY_STATIONS").map_or_else(
        |_| vec![9, 15, 20, 30],
        |v| v.split(',').map(|s| s.trim().parse().unwrap()).collect(),
    );
    for stations in counts {
        let paper: Vec<PlanConfig> = seeds
            .clone()
            .map(|s| config(9, (stations * 6).div_ceil(9), Selection::Random, s))
            .collect();
        study_row(&format!("{stations} × 6: paper layout"), &paper, runs);
        for (name, selection) in [
            ("random", Selection::Random),
            ("D-optimal", Selection::DOptimal),
            ("volume (the default)", Selection::Volume),
        ] {
            let configs: Vec<PlanConfig> = seeds
                .clone()
                .map(|s| config(stations, 6, selection, s))
                .collect();
            study_row(&format!("{stations} × 6: {name}"), &configs, runs);
        }
    }
}

/// `calibrate`'s predicted measuring error over the session's volume: at
/// every identify and validate pose, a posteriori, beside the realised
/// volume error of the same calibration against the truth; a result
/// written before it loads without it.
#[test]
fn calibrate_predicts_the_error_over_the_session_volume() {
    use spherecal::engine::base::session::Use;
    use spherecal::engine::calibrate::solve::{self, Options};
    use spherecal::engine::tools::evaluate;
    use spherecal::engine::tools::simulate::{self, SimConfig};

    let (session, truth) = simulate::simulate(&SimConfig::default()).unwrap();
    let prepared = solve::prepare(&session).unwrap();
    let mut options = Options::from_session(&session);
    options.held_out = false;
    let cal = solve::run(&session, &prepared, &options, &mut |_| Control::Continue).unwrap();
    let ml = cal.report.ml().unwrap();
    let v = ml.volume_error.as_ref().unwrap();
    let working = session
        .measurements
        .iter()
        .filter(|m| matches!(m.usage, Use::Identify | Use::Validate))
        .count();
    assert_eq!(v.poses, working);
    assert_eq!(v.stations, 19);
    assert!(v.rms_mm > 0.0 && v.rms_mm <= v.max_mm, "{v:?}");
    assert!(
        (0..3).all(|k| v.box_mm[k][1] - v.box_mm[k][0] > 100.0),
        "{v:?}"
    );
    assert!(
        ml.summary()
            .contains("predicted measuring error over the session's volume")
    );
    // The realised model part of the validate spheres (station means of
    // 6 sightings, where much of a single sighting's parameter error
    // averages out) stays below the predicted σ of a single sighting.
    let s = evaluate::volume_score(&session, &prepared, &truth, &cal.calibrated, &cal.hand_eye)
        .unwrap();
    let model = (s.after.rms.powi(2) - s.floor.rms.powi(2)).max(0.0).sqrt();
    assert!(
        model < v.rms_mm && s.after.rms > s.floor.rms,
        "realised {model:.4} mm, predicted {:.4} mm",
        v.rms_mm
    );
    // A result written before 2026-11-28 has none and still loads.
    let old = spherecal::engine::files::format::load_result(std::path::Path::new(
        "tests/data/v1/result.json",
    ))
    .unwrap();
    assert!(old.solver.ml().is_none_or(|m| m.volume_error.is_none()));
}
