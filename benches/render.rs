//! Criterion benches: per-shape intersection and whole frames of
//! `scenes/cubes.toml`. Inputs are seeded and prepared outside the timed loop.

use criterion::{Criterion, criterion_group, criterion_main};
use glam::DVec3;
use lensview::geometry::{Cuboid, Lens, Prism, Pyramid, Shape, Sphere};
use lensview::math::Ray;
use lensview::optics::Index;
use lensview::render::{RenderSettings, render};
use lensview::sampling::Sampler;
use lensview::scene::Scene;
use std::hint::black_box;

fn rays(n: usize) -> Vec<Ray> {
    let mut s = Sampler::new(42, 0, 0);
    (0..n)
        .map(|_| {
            let o = DVec3::new(s.next_f64() - 0.5, s.next_f64() - 0.5, 4.0);
            let target = DVec3::new(s.next_f64() - 0.5, s.next_f64() - 0.5, 0.0) * 1.5;
            Ray::new(o, target - o)
        })
        .collect()
}

fn shapes(c: &mut Criterion) {
    let rays = rays(1024);
    let shapes = [
        Shape::Sphere(Sphere::new(0.5)),
        Shape::Cuboid(Cuboid::new(DVec3::ONE)),
        Shape::Prism(Prism::new(1.0, 1.0)),
        Shape::Pyramid(Pyramid::new(1.0, 1.0)),
        Shape::Lens(Lens::new(DVec3::ZERO, DVec3::Z, 1.0, 2.0, 2.0, Index::Constant(1.5)).unwrap()),
    ];
    let mut g = c.benchmark_group("intersect-1024-rays");
    for s in &shapes {
        g.bench_function(s.kind_name(), |b| {
            b.iter(|| {
                rays.iter()
                    .filter(|r| black_box(s).intersect(r, 0.0, f64::INFINITY).is_some())
                    .count()
            })
        });
    }
    g.finish();
}

fn frames(c: &mut Criterion) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cubes.toml");
    let (_, scene) = Scene::load(&path).unwrap();
    let mut g = c.benchmark_group("cubes-frame");
    g.sample_size(10);
    for (w, h) in [(400, 400), (1280, 720)] {
        let s = RenderSettings {
            width: w,
            height: h,
            spp: 1,
            seed: 0,
        };
        g.bench_function(format!("{w}x{h}-1spp"), |b| {
            b.iter(|| render(black_box(&scene), &s, None))
        });
    }
    g.finish();
}

criterion_group!(benches, shapes, frames);
criterion_main!(benches);
