//! The Whitted tree of a lens system for a grid of rays across its
//! aperture: rays out a camera ray, the light they carry by number of
//! reflections, the weight dropped, and the time a ray, with and without
//! the ghosts' Russian roulette (`Pruning::roulette`), rounds alternating.
//!
//!     cargo run --release --example system_ghosts [PRESET] [MIN_WEIGHT]
//!
//! PRESET defaults to double-gauss-50mm, MIN_WEIGHT to the renderer's 1/512.

use glam::DVec3;
use lensview::geometry::{LensSystem, Pruning, SurfaceSpec};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let name = args.get(1).map_or("double-gauss-50mm", String::as_str);
    let min = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1.0 / 512.0);
    let text = lensview::prescription::preset(name).expect("a preset's name");
    let rows = lensview::prescription::parse(name, text).expect("a preset parses");
    let sys = LensSystem::new(DVec3::ZERO, DVec3::Z, SurfaceSpec::from_rows(&rows, 0.08)).expect("a preset builds");
    let (r, m) = (sys.radius(), 100);
    let dir = DVec3::new(0.01, 0.02, 1.0).normalize();
    println!("{name}, {} surfaces, {m}×{m} rays, min weight {min:.3e}", sys.len());
    for round in 0..3 {
        for roulette in [0.0, lensview::integrator::GHOST_ROULETTE] {
            let prune = Pruning {
                scale: 1.0,
                min,
                max_reflections: 6,
                roulette,
            };
            let (mut by, mut count, mut dropped) = ([0.0f64; 4], [0usize; 4], 0.0);
            let t = Instant::now();
            for i in 0..m {
                for j in 0..m {
                    let at = |k: usize| (k as f64 / (m - 1) as f64 - 0.5) * r;
                    let o = DVec3::new(at(i), at(j), -10.0);
                    dropped += sys.branches(o, dir, 0.5876, &prune, &mut |b| {
                        let k = b.reflections.min(3) as usize;
                        by[k] += b.weight;
                        count[k] += 1;
                    });
                }
            }
            let rays = (m * m) as f64;
            let us = t.elapsed().as_secs_f64() * 1e6 / rays;
            let out: Vec<String> = (0..4)
                .map(|k| format!("{k}: {:.4} in {:.2}", by[k] / rays, count[k] as f64 / rays))
                .collect();
            println!(
                "round {round} roulette {roulette:.4}: {us:6.1} µs a ray; light out by reflections (3 = 3 or more) {}; dropped {:.4}",
                out.join(", "),
                dropped / rays
            );
        }
    }
}
