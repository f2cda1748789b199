//! ml and the paper's method against the size of a session: simulated
//! IRB 2400 sessions from 100 to ~10,000 measurements (6 per identify
//! station). The time per measurement should stay flat: `ml` eliminates
//! the station centres per station (linear in the data).

// A benchmark aborts on data it cannot make: there is nothing to recover.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::time::Duration;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use spherecal::engine::calibrate::solve::{self, Control, Method, Options};
use spherecal::engine::tools::simulate::{self, SimConfig};

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("scaling");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(4));
    group.warm_up_time(Duration::from_millis(500));
    for stations in [15, 50, 150, 500, 1600] {
        let (session, _) = simulate::simulate(&SimConfig {
            n_identify: stations,
            ..SimConfig::default()
        })
        .expect("simulate");
        let prepared = solve::prepare(&session).expect("prepare");
        let n = session.measurements.len();
        group.throughput(Throughput::Elements(n as u64));
        for method in [Method::Ml, Method::Paper] {
            let mut options = Options::from_session(&session);
            options.method = method;
            // Identification only: the held-out figure is timed on its own
            // (benches/calibrate.rs, README "Held-out figure").
            options.held_out = false;
            group.bench_with_input(
                BenchmarkId::new(format!("run {}", method.as_str()), n),
                &options,
                |b, options| {
                    b.iter(|| {
                        solve::run(&session, &prepared, options, &mut |_| Control::Continue)
                            .expect("run")
                    });
                },
            );
        }
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
