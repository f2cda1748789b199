//! Whole-calibration benchmarks on the embedded demo session: centres
//! from the stripes plus the initial hand-eye (`prepare`), and the
//! identification loop (`run`) of each method, without and with the
//! held-out figure.

// A benchmark aborts on data it cannot load: there is nothing to recover.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use spherecal::engine::calibrate::solve::{self, Control, Method, Options};
use spherecal::engine::files::format::parse_session;

fn demo() -> spherecal::engine::base::session::Session {
    parse_session(
        spherecal::DEMO_SESSION_JSON,
        Path::new(spherecal::DEMO_SESSION_NAME),
    )
    .expect("the embedded demo session loads")
}

fn bench(c: &mut Criterion) {
    let session = demo();
    let mut group = c.benchmark_group("demo_session");
    group.bench_function("load (parse and check the 237 KB session)", |b| {
        b.iter(demo);
    });
    group.bench_function("prepare (stripe fits + initial hand-eye)", |b| {
        b.iter(|| solve::prepare(&session).expect("prepare"));
    });
    let prepared = solve::prepare(&session).expect("prepare");
    for method in Method::ALL {
        for held_out in [false, true] {
            let mut options = Options::from_session(&session);
            options.method = method;
            options.held_out = held_out;
            let name = if held_out {
                format!(
                    "identify and the held-out figure, method {}",
                    method.as_str()
                )
            } else {
                format!("identify, method {}", method.as_str())
            };
            group.bench_function(name, |b| {
                b.iter(|| {
                    solve::run(&session, &prepared, &options, &mut |_| Control::Continue)
                        .expect("run")
                });
            });
        }
    }
    group.bench_function("whole calibration, default options", |b| {
        b.iter(|| solve::calibrate(&session, &Options::from_session(&session)).expect("calibrate"));
    });
    let (_, cal) = solve::calibrate(&session, &Options::from_session(&session)).expect("calibrate");
    let file = spherecal::engine::files::format::ResultFile::from_calibration(&session, &cal);
    group.bench_function("result file text (write)", |b| {
        b.iter(|| spherecal::engine::files::format::result_to_json(&file));
    });
    group.bench_function(
        "result file text, checked (finite numbers, loads back)",
        |b| {
            b.iter(|| {
                spherecal::engine::files::format::result_text_checked(&file, Path::new("r.json"))
                    .expect("checked")
            });
        },
    );
    let text = spherecal::engine::files::format::result_to_json(&file);
    group.bench_function("result file load", |b| {
        b.iter(|| {
            spherecal::engine::files::format::parse_result(&text, Path::new("r.json"))
                .expect("loads")
        });
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
