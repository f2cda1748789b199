//! Issue 34: the planner reports a fraction inside its long stages (the
//! identifiability of the candidate pool, the selection) and stops soon
//! after a cancel.

#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::time::Instant;

use spherecal::engine::calibrate::solve::Control;
use spherecal::engine::files::import::RobotSource;
use spherecal::engine::tools::plan::{self, PlanRequest, PlanStage};

fn request(n_identify: usize) -> PlanRequest {
    let mut r = PlanRequest::new(RobotSource::Preset("irb2400".into()), [1050.0, 0.0, 475.0]);
    r.design.n_identify = n_identify;
    r
}

/// The time between the planner's progress calls, by stage (release
/// figures for the report).
#[test]
#[ignore = "timing study: cargo test --release --test engine plan_progress -- --ignored --nocapture"]
fn stage_times() {
    for n in [9, 30, 120] {
        let config = request(n).config().unwrap();
        let start = Instant::now();
        let mut last = start;
        let mut worst = (0.0_f64, String::new());
        plan::plan(&config, &mut |stage| {
            let now = Instant::now();
            let gap = (now - last).as_secs_f64();
            if gap > worst.0 {
                worst = (gap, format!("{stage:?}"));
            }
            last = now;
            Control::Continue
        })
        .unwrap();
        println!(
            "{n} identify stations: {:.2} s in all, longest gap {:.3} s before {}",
            start.elapsed().as_secs_f64(),
            worst.0,
            worst.1
        );
    }
}

/// The identifiability analysis of the pool reports a growing fraction,
/// many times, below 1; a cancel inside it ends the plan as cancelled.
#[test]
fn the_analysis_reports_a_fraction_and_stops_on_cancel() {
    let config = request(9).config().unwrap();
    let mut seen = Vec::new();
    plan::plan(&config, &mut |stage| {
        if let PlanStage::Analysis { done, of } = stage {
            seen.push((done, of));
        }
        Control::Continue
    })
    .unwrap();
    assert!(seen.len() >= 20, "{} analysis steps", seen.len());
    assert!(seen.windows(2).all(|w| w[1].0 > w[0].0 && w[1].1 == w[0].1));
    let (last, of) = *seen.last().unwrap();
    assert!(last <= of && last + 2 >= of, "{last} of {of}");
    // A cancel at the fifth step of the analysis: cancelled, no later stage.
    let mut after = Vec::new();
    let mut steps = 0;
    let got = plan::plan(&config, &mut |stage| {
        if matches!(stage, PlanStage::Analysis { .. }) {
            steps += 1;
        }
        after.push(stage);
        if steps >= 5 {
            Control::Cancel
        } else {
            Control::Continue
        }
    });
    assert!(matches!(got, Err(plan::PlanError::Cancelled)), "{got:?}");
    assert!(matches!(after.last(), Some(PlanStage::Analysis { .. })));
}

/// Cancel latency: a plan (and its prediction) cancelled at moments
/// spread over its run; the longest time from the cancel to the return.
#[test]
#[ignore = "timing study: cargo test --test engine plan_progress -- --ignored --nocapture"]
fn cancel_latency() {
    use std::sync::Arc;
    use std::sync::atomic::{AtomicBool, Ordering};
    for n in [30, 120] {
        let req = request(n);
        let config = req.config().unwrap();
        let predict = plan::PredictConfig {
            runs: 5,
            ..plan::PredictConfig::default()
        };
        let start = Instant::now();
        plan::plan_and_predict(&config, Some(&predict), &mut |_| Control::Continue).unwrap();
        let whole = start.elapsed().as_secs_f64();
        let mut worst = 0.0_f64;
        for k in 1..20 {
            let at = whole * f64::from(k) / 20.0;
            let flag = Arc::new(AtomicBool::new(false));
            let config = config.clone();
            let f = Arc::clone(&flag);
            let job = std::thread::Builder::new()
                .name("plan".into())
                .spawn(move || {
                    let r = plan::plan_and_predict(&config, Some(&predict), &mut |_| {
                        if f.load(Ordering::Relaxed) {
                            Control::Cancel
                        } else {
                            Control::Continue
                        }
                    });
                    (r.is_err(), Instant::now())
                })
                .unwrap();
            std::thread::sleep(std::time::Duration::from_secs_f64(at));
            let set = Instant::now();
            flag.store(true, Ordering::Relaxed);
            let (cancelled, ended) = job.join().unwrap();
            if cancelled {
                worst = worst.max(ended.saturating_duration_since(set).as_secs_f64());
            }
        }
        println!(
            "{n} identify stations (5 predicted runs): {whole:.2} s whole, cancel within {worst:.3} s at worst (19 cancels)"
        );
    }
}
