//! Benchmark of the stripe circle fit: one 60-point arc over 110° with
//! 0.02 mm noise at the paper's 40° cut of a 38.1 mm sphere (a typical
//! stripe of the demo calibration), reported in points per second.

#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use spherecal::engine::calibrate::stripe::{centre_from_stripe, fit_circle};

/// Points in the benchmarked stripe.
const POINTS: usize = 60;

fn stripe() -> Vec<[f64; 2]> {
    let radius = 19.05 * 40f64.to_radians().cos();
    let centre = [2.3, -3.1];
    let noise = Normal::new(0.0, 0.02).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    (0..POINTS)
        .map(|i| {
            let t = (35.0 + 110.0 * i as f64 / (POINTS - 1) as f64).to_radians();
            let r = radius + noise.sample(&mut rng);
            [centre[0] + r * t.cos(), centre[1] + r * t.sin()]
        })
        .collect()
}

fn bench_fit(c: &mut Criterion) {
    let points = stripe();
    let mut group = c.benchmark_group("stripe");
    group.throughput(Throughput::Elements(POINTS as u64));
    group.bench_function("fit_circle_60", |b| {
        b.iter(|| fit_circle(black_box(&points)));
    });
    group.bench_function("centre_from_stripe_60", |b| {
        b.iter(|| centre_from_stripe(black_box(&points), black_box(19.05), 1));
    });
    group.finish();
}

criterion_group!(benches, bench_fit);
criterion_main!(benches);
