//! What one full-resolution 1-spp frame costs on each path, for counting
//! instructions (callgrind) or timing alternately: the `bench --frame-only`
//! frame (`render_into`), the progressive renderer's first sample stage
//! (what the viewer's render thread runs), and that stage followed by the
//! frame the render thread sends (the 8-bit conversion into a new buffer).
//!
//!     cargo build --release --example stage_cost
//!     target/release/examples/stage_cost MODE SCENE WIDTH HEIGHT RUNS
//!
//! MODE: `bench`, `stage`, `send`, `blocks2` (a fresh 2×2 block level,
//! refined at edges, and its picture; `blocks2plain`: not refined;
//! `level2`, `level2plain`: the level alone, as the render thread runs it),
//! `blocks8send` (a fresh 8×8 level and its 8-bit frame) or
//! `warp` (a reprojection after a step): the median time of RUNS runs
//! (after one warm-up); `alt`: `bench` and `stage` frames in turn, both
//! medians; `altblocks`: `blocks2` and `stage` in turn; `altedges`:
//! `blocks2plain`, `blocks2` and `stage` in turn;
//! `hash`: two hashes per stage, of its picture (means, sample counts,
//! 8-bit frame) and of its first hits (recorded for a picture of samples)
//! through the schedule to 16 spp, a camera step (reprojection) and the
//! schedule again (to check that a change keeps every bit). Under callgrind, the difference between two RUNS
//! counts is the cost of that many frames (the scene's setup cancels).

use lensview::render::edges::EDGE_SHARE;
use lensview::render::progressive::{Progressive, Stage};
use lensview::render::{Image, RenderSettings, render_into};
use lensview::scene::Scene;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let [_, mode, scene, w, h, runs] = &args[..] else {
        eprintln!(
            "usage: stage_cost bench|stage|send|blocks2|blocks2plain|level2|level2plain|blocks8send|warp|alt|altblocks|altedges|hash SCENE WIDTH HEIGHT RUNS"
        );
        std::process::exit(2);
    };
    let number = |s: &str| -> u32 {
        s.parse().unwrap_or_else(|_| {
            eprintln!("not a number: {s}");
            std::process::exit(2)
        })
    };
    let (w, h, runs) = (number(w), number(h), number(runs));
    let scene = match Scene::load(std::path::Path::new(scene)) {
        Ok((_, s)) => s,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1)
        }
    };
    if mode == "hash" {
        return hash_schedule(&scene, w, h);
    }
    if mode == "warp" {
        return time_warp(&scene, w, h, runs);
    }
    let mut img = Image::new(w, h);
    let mut prog = Progressive::new(w, h, 0);
    let mut frame = |mode: &str| match mode {
        "bench" => {
            let s = RenderSettings {
                width: w,
                height: h,
                spp: 1,
                seed: 0,
            };
            render_into(&scene, &s, None, &mut img);
            std::hint::black_box(&img.pixels);
        }
        "blocks2" | "blocks2plain" | "level2" | "level2plain" => {
            prog.reset(w, h, 0);
            prog.edge_share = if mode.ends_with("plain") { 0.0 } else { EDGE_SHARE };
            prog.run(&scene, Stage::Blocks(2), &|| false);
            if mode.starts_with("blocks") {
                std::hint::black_box(prog.image());
            }
        }
        "blocks8send" => {
            prog.reset(w, h, 0);
            prog.run(&scene, Stage::Blocks(8), &|| false);
            let mut rgba = Vec::new();
            prog.write_rgba8(&mut rgba, Default::default());
            std::hint::black_box(rgba);
        }
        "stage" | "send" => {
            prog.reset(w, h, 0);
            prog.run(&scene, Stage::Samples(1), &|| false);
            if mode == "send" {
                let mut rgba = Vec::new();
                prog.write_rgba8(&mut rgba, Default::default());
                std::hint::black_box(rgba);
            }
        }
        _ => {
            eprintln!("unknown mode {mode}");
            std::process::exit(2)
        }
    };
    if mode == "altedges" {
        let mut t = [Vec::new(), Vec::new(), Vec::new()];
        for _ in 0..=runs {
            for (m, v) in ["blocks2plain", "blocks2", "stage"].into_iter().zip(&mut t) {
                let t0 = Instant::now();
                frame(m);
                v.push(t0.elapsed().as_secs_f64() * 1e3);
            }
        }
        let [p, e, st] = t.map(|mut v| {
            v.remove(0);
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        });
        println!(
            "{w}x{h}: blocks2plain {p:.2} ms ({:.1} %), blocks2 {e:.2} ms ({:.1} %), stage {st:.2} ms (medians of {runs})",
            100.0 * p / st,
            100.0 * e / st
        );
        return;
    }
    if mode == "alt" || mode == "altblocks" {
        let first = if mode == "alt" { "bench" } else { "blocks2" };
        let (mut b, mut st) = (Vec::new(), Vec::new());
        for _ in 0..=runs {
            for (m, v) in [(first, &mut b), ("stage", &mut st)] {
                let t = Instant::now();
                frame(m);
                v.push(t.elapsed().as_secs_f64() * 1e3);
            }
        }
        let med = |v: &mut Vec<f64>| {
            v.remove(0);
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        let (mb, ms) = (med(&mut b), med(&mut st));
        println!(
            "{w}x{h}: {first} {mb:.2} ms, stage {ms:.2} ms (medians of {runs}): {first}/stage {:.1} %",
            100.0 * mb / ms
        );
        return;
    }
    frame(mode);
    let mut times: Vec<f64> = (0..runs)
        .map(|_| {
            let t = Instant::now();
            frame(mode);
            t.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    times.sort_by(f64::total_cmp);
    if let Some(m) = times.get(times.len() / 2) {
        println!("{mode} {w}x{h}: median {m:.2} ms of {runs}");
    }
}

fn hash_schedule(scene: &Scene, w: u32, h: u32) {
    use lensview::render::progressive::schedule;
    use std::hash::{DefaultHasher, Hash, Hasher};
    let mut prog = Progressive::new(w, h, 0);
    let moved = stepped(scene);
    // Two hashes: the picture (means, counts, 8-bit frame) and the first
    // hits (recorded where a picture of samples has none yet; block
    // previews have none).
    let print = |prog: &mut Progressive, scene: &Scene, label: &str| {
        let mut hs = DefaultHasher::new();
        for p in &prog.image().pixels {
            [p.x, p.y, p.z].map(f64::to_bits).hash(&mut hs);
        }
        prog.counts().hash(&mut hs);
        let mut rgba = Vec::new();
        prog.write_rgba8(&mut rgba, Default::default());
        rgba.hash(&mut hs);
        let mut hf = DefaultHasher::new();
        if prog.spp > 0 {
            prog.record_first_hits(scene, &|| false);
        }
        prog.first_hits().hash(&mut hf);
        println!("{label}: {:016x} {:016x}", hs.finish(), hf.finish());
    };
    for st in schedule(16) {
        prog.run(scene, st, &|| false);
        print(&mut prog, scene, &st.label());
    }
    prog.reproject(&moved, scene, |_| 2);
    print(&mut prog, &moved, "reprojected");
    for st in schedule(16).into_iter().filter(|s| matches!(s, Stage::Samples(_))) {
        prog.run(&moved, st, &|| false);
        print(&mut prog, &moved, &format!("moved {}", st.label()));
    }
}

/// `warp`: the median time of a reprojection (warp and holes at 2×2) of a
/// 1-spp picture after W held for 1/30 s.
fn time_warp(scene: &Scene, w: u32, h: u32, runs: u32) {
    let moved = stepped(scene);
    let mut prog = Progressive::new(w, h, 0);
    let mut runs: Vec<[f64; 4]> = (0..=runs)
        .map(|_| {
            prog.reset(w, h, 0);
            prog.run(scene, Stage::Samples(1), &|| false);
            let t = Instant::now();
            prog.reproject(&moved, scene, |_| 2);
            let r = prog.reprojection;
            [t.elapsed().as_secs_f64(), r.first_hits_s, r.warp_s, r.fill_s].map(|s| s * 1e3)
        })
        .collect();
    runs.remove(0);
    let median = |i: usize| {
        let mut v: Vec<f64> = runs.iter().map(|r| r[i]).collect();
        v.sort_by(f64::total_cmp);
        v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
    };
    println!(
        "warp {w}x{h}: median {:.2} ms of {} (first hits {:.2}, splat and look back {:.2}, holes traced at 2x2 {:.2}; {} holes)",
        median(0),
        runs.len(),
        median(1),
        median(2),
        median(3),
        prog.reprojection.holes
    );
}

/// `scene` after W held for 1/30 s at the default flight speed (0.1 forward).
fn stepped(scene: &Scene) -> Scene {
    let mut moved = scene.clone();
    let c = &scene.camera;
    moved.camera = lensview::camera::Camera::new(c.position + c.forward() * 0.1, c.rotation_deg, c.fov_y_deg);
    moved
}
