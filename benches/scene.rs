//! The CPU work of one frame of the workbench's 3-D scene (issue 34):
//! projecting a cloud of 100,000 points (with the demo session's robot,
//! frames and marks) and tessellating the shapes as egui would. Goal:
//! ≤ 30 ms a frame in a release build.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use egui::epaint::{ClippedShape, TessellationOptions, Tessellator};
use spherecal::app::scene::{Camera, Scene, shapes};

/// Points of the benchmark's cloud.
const POINTS: usize = 100_000;

/// A cloud on a 200 mm sphere's surface (a Fibonacci lattice), each
/// point's colour from its height: the shape of a scanned part.
fn cloud() -> Scene {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let points = (0..POINTS)
        .map(|k| {
            let z = 1.0 - 2.0 * (k as f64 + 0.5) / POINTS as f64;
            let r = (1.0 - z * z).sqrt();
            let a = golden * k as f64;
            let p = [
                1200.0 + 200.0 * r * a.cos(),
                200.0 * r * a.sin(),
                600.0 + 200.0 * z,
            ];
            let c = ((z + 1.0) * 127.0) as u8;
            (p, egui::Color32::from_rgb(c, 80, 255 - c))
        })
        .collect();
    Scene {
        points,
        ..Scene::default()
    }
}

fn bench(c: &mut Criterion) {
    let scene = cloud();
    let rect = egui::Rect::from_min_size(egui::pos2(300.0, 200.0), egui::vec2(1000.0, 500.0));
    let mut camera = Camera::default();
    let mut group = c.benchmark_group("scene_frame");
    group.throughput(Throughput::Elements(POINTS as u64));
    group.bench_function("project_100k", |b| {
        b.iter(|| {
            camera.orbit(1.0, 0.0);
            shapes(&scene, &camera, rect)
        });
    });
    group.bench_function("project_and_tessellate_100k", |b| {
        b.iter(|| {
            camera.orbit(1.0, 0.0);
            let (shapes, _) = shapes(&scene, &camera, rect);
            let clipped = shapes
                .into_iter()
                .map(|s| ClippedShape::new(rect, s))
                .collect();
            let mut t = Tessellator::new(1.0, TessellationOptions::default(), [2048, 2048], vec![]);
            t.tessellate_shapes(clipped)
        });
    });
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = bench
}
criterion_main!(benches);
