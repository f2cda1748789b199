//! Benchmark of the arc search in a raw profile (`find_arc`): a synthetic
//! 2,500-point profile at 0.03 mm pitch (a stand, the arc of a 40 mm sphere
//! cut at r = 30 mm, a table with a bump, 2 % clutter, 0.02 mm noise), and
//! the real 2,529-point profile `p1.yml` of
//! `data/robcalibrator-sphere` when it is there (with the plain
//! circle fit of it for comparison: most of `find_arc`'s time on it).

#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use spherecal::engine::calibrate::stripe::fit_circle;
use spherecal::engine::calibrate::stripe::segment::find_arc;

const R: f64 = 40.0;
const PITCH: f64 = 0.03;
const POINTS: usize = 2500;

/// Upper half of a circle at `y`.
fn cap(centre: [f64; 2], radius: f64, y: f64) -> f64 {
    let dy = y - centre[0];
    centre[1] + (radius * radius - dy * dy).max(0.0).sqrt()
}

fn profile() -> Vec<[f64; 2]> {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let noise = Normal::new(0.0, 0.02).unwrap();
    let (centre, r) = ([0.0, -30.0], 30.0);
    let half = r * 55f64.to_radians().sin();
    let start = -(POINTS as f64) * PITCH / 2.0;
    (0..POINTS)
        .map(|i| {
            let y = start + i as f64 * PITCH;
            let z = if y < -half - 1.0 {
                // The stand: a circle of 1.8 R below the sphere.
                cap([-half - 10.0, -30.0 - r - 2.0 - 1.8 * R], 1.8 * R, y)
            } else if y <= half {
                cap(centre, r, y)
            } else if (y - half - 8.0).abs() < 3.0 {
                // A bump on the table.
                cap([half + 8.0, -30.0 - r - 14.0], 0.4 * R, y).max(-30.0 - r - 5.0)
            } else {
                -30.0 - r - 5.0 + 0.02 * (y - half)
            };
            let z = if rng.random::<f64>() < 0.02 {
                rng.random_range(-80.0..10.0)
            } else {
                z
            };
            [y, z + noise.sample(&mut rng)]
        })
        .collect()
}

/// The flat `scan_line` list of the real profile `p1.yml` as `[x, z]`.
fn real_profile() -> Option<Vec<[f64; 2]>> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/data/robcalibrator-sphere/p1.yml"
    );
    let text = std::fs::read_to_string(path).ok()?;
    let rest = &text[text.find("scan_line:")?..];
    let list = &rest[rest.find('[')? + 1..rest.find(']')?];
    let values: Vec<f64> = list
        .split(',')
        .map(str::trim)
        .filter(|v| !v.is_empty())
        .map(|v| v.parse().unwrap())
        .collect();
    Some(values.chunks_exact(3).map(|c| [c[0], c[2]]).collect())
}

/// The fastest of `runs` calls, µs: robust to other load on the machine.
fn fastest<T>(runs: usize, mut f: impl FnMut() -> T) -> f64 {
    (0..runs)
        .map(|_| {
            let t = std::time::Instant::now();
            black_box(f());
            t.elapsed().as_secs_f64() * 1e6
        })
        .fold(f64::INFINITY, f64::min)
}

fn bench_find_arc(c: &mut Criterion) {
    let points = profile();
    let real = real_profile();
    // Criterion's mean suffers from other load on a shared machine; the
    // fastest call does not.
    println!(
        "synthetic: {}; fastest of 300 calls {:.0} µs",
        find_arc(&points, R).unwrap().summary(),
        fastest(300, || find_arc(black_box(&points), R))
    );
    match &real {
        Some(real) => println!(
            "p1.yml: {}; fastest of 300 calls {:.0} µs (fit_circle alone {:.0} µs)",
            find_arc(real, R).unwrap().summary(),
            fastest(300, || find_arc(black_box(real), R)),
            fastest(300, || fit_circle(black_box(real)))
        ),
        None => println!("p1.yml not found: real-profile benchmark skipped"),
    }
    let mut group = c.benchmark_group("segment");
    group.throughput(Throughput::Elements(points.len() as u64));
    group.bench_function("find_arc_synthetic_2500", |b| {
        b.iter(|| find_arc(black_box(&points), black_box(R)));
    });
    if let Some(real) = &real {
        group.throughput(Throughput::Elements(real.len() as u64));
        group.bench_function("find_arc_real_p1", |b| {
            b.iter(|| find_arc(black_box(real), black_box(R)));
        });
        group.bench_function("fit_circle_real_p1", |b| {
            b.iter(|| fit_circle(black_box(real)));
        });
    }
    group.finish();
}

criterion_group!(benches, bench_find_arc);
criterion_main!(benches);
