//! Shop-floor workflow benchmarks: a default IRB 2400 pose plan (candidates,
//! identifiability, D-optimal selection, ordering; no prediction), one
//! simulated calibration of that plan as the prediction runs it, the HTML
//! report of the demo session, and a scan plus drift of the example
//! history library (`sessions/history`).

// A benchmark aborts on data it cannot load: there is nothing to recover.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;
use std::time::{Duration, UNIX_EPOCH};

use criterion::{Criterion, criterion_group, criterion_main};
use spherecal::engine::base::robot;
use spherecal::engine::calibrate::solve::{self, Control, Options};
use spherecal::engine::files::format::ResultFile;
use spherecal::engine::files::format::parse_session;
use spherecal::engine::tools::history::{self, DriftOptions};
use spherecal::engine::tools::plan::{self, PlanConfig, PredictConfig};
use spherecal::engine::tools::report::html::{self, ReportInput, ReportMeta};

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("workflow");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(10));

    let config = PlanConfig::for_preset(&robot::irb2400(), [1050.0, 0.0, 475.0]);
    group.bench_function("plan, default IRB 2400 (124 poses)", |b| {
        b.iter(|| plan::plan(&config, &mut |_| Control::Continue).expect("plan"));
    });
    let made = plan::plan(&config, &mut |_| Control::Continue).expect("plan");
    let one = PredictConfig {
        runs: 1,
        ..PredictConfig::default()
    };
    group.bench_function("predict, one simulated calibration of the plan", |b| {
        b.iter(|| plan::predict(&made, &one, &mut |_, _| Control::Continue).expect("predict"));
    });

    let session = parse_session(
        spherecal::DEMO_SESSION_JSON,
        Path::new(spherecal::DEMO_SESSION_NAME),
    )
    .expect("the embedded demo session loads");
    let (prepared, cal) =
        solve::calibrate(&session, &Options::from_session(&session)).expect("the demo calibrates");
    let result = ResultFile::from_calibration(&session, &cal);
    let meta = ReportMeta::new("demo", UNIX_EPOCH + Duration::from_hours(498648));
    group.bench_function("HTML report of the demo (render)", |b| {
        b.iter(|| {
            html::render(&ReportInput {
                session: &session,
                session_bytes: spherecal::DEMO_SESSION_JSON.as_bytes(),
                result: &result,
                prepared: Some(&prepared),
                meta: &meta,
                tolerance: None,
            })
        });
    });

    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("sessions/history");
    group.bench_function("history: scan sessions/history and drift", |b| {
        b.iter(|| {
            let library = history::read_library(&folder).expect("scan");
            let robot = library.robots()[0].0.clone();
            history::drift(&library, &robot, &DriftOptions::default()).expect("drift")
        });
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
