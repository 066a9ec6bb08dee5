//! Criterion benches: per-shape intersection and whole frames of
//! `scenes/cubes.toml`. Inputs are seeded and prepared outside the timed loop.

use criterion::{Criterion, criterion_group, criterion_main};
use glam::DVec3;
use lensview::geometry::{Cuboid, Lens, Prism, Pyramid, Shape, Sphere};
use lensview::math::Ray;
use lensview::optics::Index;
use lensview::render::progressive::{Progressive, Stage};
use lensview::render::{Image, RenderSettings, render_into};
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
        Shape::Lens(Box::new(
            Lens::new(DVec3::ZERO, DVec3::Z, 1.0, 2.0, 2.0, Index::Constant(1.5)).unwrap(),
        )),
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

/// BVH traversal alone: closest box hit over a seeded cloud of boxes.
fn bvh(c: &mut Criterion) {
    use lensview::accel::Bvh;
    use lensview::geometry::Aabb;
    let mut s = Sampler::new(7, 0, 0);
    let mut g = c.benchmark_group("bvh-closest-box-1024-rays");
    for n in [25usize, 2500] {
        let boxes: Vec<Aabb> = (0..n)
            .map(|_| {
                let c = DVec3::new(s.next_f64(), s.next_f64(), s.next_f64()) * 20.0 - 10.0;
                let e = DVec3::splat(0.3 * 25.0f64.sqrt() / (n as f64).sqrt());
                Aabb::new(c - e, c + e)
            })
            .collect();
        let bvh = Bvh::build(&boxes);
        let rays: Vec<Ray> = (0..1024)
            .map(|_| {
                let o = DVec3::new(s.next_f64() - 0.5, s.next_f64() - 0.5, 30.0);
                let t = DVec3::new(s.next_f64(), s.next_f64(), 0.0) * 20.0 - 10.0;
                Ray::new(o, t - o)
            })
            .collect();
        g.bench_function(format!("{n}-boxes"), |b| {
            b.iter(|| {
                let mut hits = 0usize;
                for r in &rays {
                    let inv = r.dir.recip();
                    bvh.traverse(r, f64::INFINITY, |p, t_max| {
                        let bb = &boxes[p as usize];
                        let t0 = (bb.min - r.origin) * inv;
                        let t1 = (bb.max - r.origin) * inv;
                        let lo = t0.min(t1).max_element().max(0.0);
                        let hi = t0.max(t1).min_element().min(t_max);
                        Ok((lo <= hi).then(|| {
                            hits += 1;
                            lo
                        }))
                    });
                }
                hits
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
        // Into a frame kept from iteration to iteration, as the viewer keeps one.
        let mut img = Image::new(w, h);
        g.bench_function(format!("{w}x{h}-1spp"), |b| {
            b.iter(|| render_into(black_box(&scene), &s, None, &mut img))
        });
    }
    // The first progressive level the viewer draws after a change.
    let mut p = Progressive::new(1280, 720, 0);
    g.bench_function("1280x720-first-level-8x8-blocks", |b| {
        b.iter(|| {
            p.reset(1280, 720, 0);
            p.run(black_box(&scene), Stage::Blocks(8), &|| false)
        })
    });
    // Camera rays in tiles of packets (what the renderer casts), in
    // packets of eight walking alone, and one by one.
    g.bench_function("1280x720-primary-rays-closest-hit-tiles", |b| {
        b.iter(|| lensview::bench::primary_rays_per_second(black_box(&scene), 1280, 720, 1, true))
    });
    g.bench_function("1280x720-primary-rays-closest-hit-packets", |b| {
        b.iter(|| lensview::bench::primary_rays_per_second(black_box(&scene), 1280, 720, 1, false))
    });
    g.bench_function("1280x720-primary-rays-closest-hit-one-by-one", |b| {
        b.iter(|| lensview::bench::primary_rays_per_second_scalar(black_box(&scene), 1280, 720, 1))
    });
    g.finish();
}

/// The reprojection's warp alone (splat and look back, no tracing) after
/// a step forward, with its buffers kept from step to step as a flight
/// keeps them.
fn warp(c: &mut Criterion) {
    use lensview::color::Rgb;
    use lensview::render::FirstHit;
    use lensview::render::reproject::{Scratch, Source, warp};
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cubes.toml");
    let (_, scene) = Scene::load(&path).unwrap();
    let mut g = c.benchmark_group("reproject");
    g.sample_size(20);
    for (w, h) in [(640, 360), (1280, 720)] {
        let mut p = Progressive::new(w, h, 0);
        p.run(&scene, Stage::Samples(1), &|| false);
        p.record_first_hits(&scene, &|| false);
        let img = p.image();
        // Running sums of one sample each, as after the first sample stage.
        let ones = vec![1; (w * h) as usize];
        let src = Source {
            camera: &scene.camera,
            size: (w, h),
            colour: &img.pixels,
            count: Some(&ones),
            first: p.first_hits().unwrap(),
        };
        let c0 = &scene.camera;
        let to = lensview::camera::Camera::new(c0.position + c0.forward() * 0.1, c0.rotation_deg, c0.fov_y_deg);
        let n = (w * h) as usize;
        let (mut out, mut first) = (vec![Rgb::ZERO; n], vec![FirstHit::default(); n]);
        let mut scratch = Scratch::default();
        g.bench_function(format!("{w}x{h}-warp-step-forward"), |b| {
            b.iter(|| warp(black_box(&src), &to, (w, h), &mut scratch, &mut out, &mut first))
        });
    }
    g.finish();
}

criterion_group!(benches, shapes, bvh, frames, warp);
criterion_main!(benches);
