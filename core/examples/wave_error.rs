//! The window's caustic error against its time (issue #29 item 3): the
//! render thread's refinement of one picture (the stages of
//! `progressive::schedule`, photon passes before each as `render::worker`
//! traces them), with the adaptive waves thinned as the window thins them
//! (`new`) or not thinned (`old`, round 24's window), against a
//! `render` reference; `pfF` is `new` with `F` times the photons of each
//! stage (`pf2`, `pf0.5`). Prints each mode's time (two threads unless
//! RAYON_NUM_THREADS says), photons, samples cast and RMS error over every
//! pixel and over the caustic's pixels (where the reference with caustics
//! exceeds the one without by over 2 % of the largest excess).
//!
//!   cargo run --release -p lensview-core --example wave_error -- \
//!       SCENE.toml WIDTH HEIGHT MAX_SPP REF_SPP old new [pf2 …]

use lensview_core::integrator::Lit;
use lensview_core::render::caustics::{CausticSettings, Interleaved, stage_work, still_map};
use lensview_core::render::progressive::{Progressive, schedule};
use lensview_core::render::thinning::thinning_of;
use lensview_core::render::{Image, RenderSettings, render};
use lensview_core::scene::Scene;
use std::sync::Arc;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    if a.len() < 7 {
        eprintln!("usage: wave_error SCENE.toml WIDTH HEIGHT MAX_SPP REF_SPP old|new …");
        std::process::exit(1);
    }
    let (_, scene) = Scene::load(std::path::Path::new(&a[1])).expect("a scene");
    let num = |i: usize| a[i].parse::<u32>().expect("a number");
    let (w, h, spp, ref_spp) = (num(2), num(3), num(4), num(5));
    let (reference, caustic) = reference(&scene, (w, h), ref_spp);
    eprintln!("reference: {} caustic pixels", caustic.iter().filter(|&&c| c).count());
    let shared = Arc::new(scene.clone());
    for mode in &a[6..] {
        let old = mode == "old";
        let t = std::time::Instant::now();
        let mut c = Interleaved::default();
        c.follow(&shared, false);
        let mut p = Progressive::new(w, h, 5);
        for st in schedule(spp) {
            // Round 24's window: waves neither thinned nor given photons for it.
            let wave = old && p.spp > 0;
            let thin = if wave {
                1
            } else {
                thinning_of(&Lit::new(&scene, c.map()), (w, h))
            };
            let work = stage_work(st, (w, h, p.spp), scene.lights.len());
            c.refine((work, p.stage_photons(st, thin) * photon_factor(mode)), &|| false);
            assert!(p.run(Lit::new(&scene, c.map()).thinned(thin), st, &|| false));
        }
        let secs = t.elapsed().as_secs_f64();
        let (all, hot) = rms(&p.image(), &reference, &caustic);
        let photons = c.map().map_or(0, |m| m.photons());
        println!(
            "{mode}: {secs:.2} s, {photons} photons, {} samples, RMS all {all:.5}, caustic {hot:.5}",
            p.samples_cast
        );
    }
}

/// The reference at `spp` samples and its caustic's pixels.
fn reference(scene: &Scene, (w, h): (u32, u32), spp: u32) -> (Image, Vec<bool>) {
    let s = RenderSettings {
        width: w,
        height: h,
        spp,
        seed: 99,
    };
    // Its own photons too (the window's are seed 0's): with the same seed
    // its first passes would be the window's, and evenly spread photons
    // would look closer to it than they are.
    let photons = CausticSettings {
        seed: 99,
        ..CausticSettings::default()
    };
    let (map, thin) = still_map(scene, (w, h), spp, photons).expect("caustics");
    let with = render(Lit::new(scene, Some(&map)).thinned(thin), &s, None);
    let without = render(Lit::new(scene, None), &s, None);
    let excess: Vec<f64> = with
        .pixels
        .iter()
        .zip(&without.pixels)
        .map(|(a, b)| (*a - *b).max_element())
        .collect();
    let most = excess.iter().copied().fold(0.0, f64::max);
    (with, excess.iter().map(|&e| e > 0.02 * most).collect())
}

/// RMS error over every pixel and over the `caustic` ones.
fn rms(img: &Image, reference: &Image, caustic: &[bool]) -> (f64, f64) {
    let (mut all, mut hot, mut n) = (0.0, 0.0, 0usize);
    for ((x, r), &c) in img.pixels.iter().zip(&reference.pixels).zip(caustic) {
        let d = (*x - *r).length_squared() / 3.0;
        all += d;
        if c {
            hot += d;
            n += 1;
        }
    }
    ((all / img.pixels.len() as f64).sqrt(), (hot / n.max(1) as f64).sqrt())
}

/// The photons a mode `pfF` traces for each the window traces (`F` times
/// as many: the window's photons against its error and time); 1 for
/// `old` and `new`.
fn photon_factor(mode: &str) -> f64 {
    mode.strip_prefix("pf").and_then(|f| f.parse().ok()).unwrap_or(1.0)
}
