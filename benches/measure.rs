//! `spherecal measure` on the embedded demo session (124 stripes, 7 k
//! points) calibrated by `ml`: points per second of each stage of load →
//! transform → σ → write, and of the whole pipeline to PLY.

// A benchmark aborts on data it cannot load: there is nothing to recover.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use spherecal::engine::calibrate::solve::{self, Control, Options};
use spherecal::engine::files::format::{ResultFile, parse_session};
use spherecal::engine::uses::measure::{
    self, CellModel, MeasureOptions, ModelChoice, Provenance, Scan, write,
};

fn demo() -> spherecal::engine::base::session::Session {
    parse_session(
        spherecal::DEMO_SESSION_JSON,
        Path::new(spherecal::DEMO_SESSION_NAME),
    )
    .expect("the embedded demo session loads")
}

fn bench(c: &mut Criterion) {
    let session = demo();
    let (_, cal) = solve::calibrate(&session, &Options::from_session(&session)).expect("calibrate");
    let result = ResultFile::from_calibration(&session, &cal);
    let options = MeasureOptions {
        sigma: true,
        ..MeasureOptions::default()
    };
    let run = |scan: Scan| {
        measure::measure(scan, &result, &options, None, &mut |_| Control::Continue)
            .expect("measure")
    };
    let points = Scan::from_session(session.clone(), &[]).point_count();
    let provenance = Provenance {
        result: "demo.result.json".into(),
        scan: "demo".into(),
    };
    let mut group = c.benchmark_group("measure_demo");
    group.throughput(Throughput::Elements(points as u64));
    group.bench_function("load (parse and check the session)", |b| b.iter(demo));
    group.bench_function("transform and σ", |b| {
        b.iter_batched(
            || Scan::from_session(session.clone(), &[]),
            run,
            criterion::BatchSize::LargeInput,
        );
    });
    let cloud = run(Scan::from_session(session.clone(), &[])).cloud;
    group.bench_function("write PLY (to memory)", |b| {
        b.iter(|| {
            let mut out = Vec::with_capacity(points * write::ply::VERTEX_BYTES + 4096);
            write::ply::write(&mut out, &cloud, &provenance).expect("ply");
            out
        });
    });
    group.bench_function("write CSV (to memory)", |b| {
        b.iter(|| {
            let mut out = Vec::new();
            write::csv_rows::write(&mut out, &cloud).expect("csv");
            out
        });
    });
    let dir = std::env::temp_dir().join(format!("spherecal-bench-measure-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let e57 = dir.join("cloud.e57");
    group.bench_function("write E57 (file, atomic)", |b| {
        b.iter(|| {
            measure::write_cloud(&cloud, &e57, measure::CloudFormat::E57, &provenance)
                .expect("e57");
        });
    });
    let (nominal, calibrated) = (
        CellModel::of_result(&result, ModelChoice::Nominal),
        CellModel::of_result(&result, ModelChoice::Calibrated),
    );
    group.bench_function(
        "self-validation (validate stations, before and after)",
        |b| {
            b.iter(|| {
                measure::self_validate(
                    &cloud.poses,
                    &nominal,
                    &calibrated,
                    session.sphere_diameter,
                    &session.reference_distances,
                )
            });
        },
    );
    let ply = dir.join("cloud.ply");
    group.bench_function(
        "load → transform → σ → write PLY (file, atomic)",
        |b| {
            b.iter(|| {
                let measured = run(Scan::from_session(demo(), &[]));
                measure::write_cloud(
                    &measured.cloud,
                    &ply,
                    measure::CloudFormat::Ply,
                    &provenance,
                )
                .expect("ply");
            });
        },
    );
    group.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group!(benches, bench);
criterion_main!(benches);
