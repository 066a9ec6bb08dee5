//! Where the window's time goes with caustics (issue #29 item 3): the
//! render thread's refinement of one picture (`progressive::schedule`, the
//! photon passes before each stage as `render::worker` traces them, the
//! adaptive waves thinned as the window thins them), with the scene's
//! caustics and without, twice each in turn. Prints each run's time, the
//! part in photon passes and in sample stages, and the samples cast.
//!
//!   cargo run --release -p lensview-core --example wave_cost -- \
//!       SCENE.toml WIDTH HEIGHT MAX_SPP

use lensview_core::integrator::Lit;
use lensview_core::render::caustics::{Interleaved, stage_work};
use lensview_core::render::progressive::{Progressive, schedule};
use lensview_core::render::thinning::thinning_of;
use lensview_core::scene::Scene;
use std::sync::Arc;
use std::time::Instant;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    if a.len() != 5 {
        eprintln!("usage: wave_cost SCENE.toml WIDTH HEIGHT MAX_SPP");
        std::process::exit(1);
    }
    let (_, mut scene) = Scene::load(std::path::Path::new(&a[1])).expect("a scene");
    let num = |i: usize| a[i].parse::<u32>().expect("a number");
    let (w, h, spp) = (num(2), num(3), num(4));
    let caustics = scene.features.caustics;
    for on in [caustics, false, caustics, false] {
        scene.features.caustics = on;
        let shared = Arc::new(scene.clone());
        let start = Instant::now();
        let mut c = Interleaved::default();
        c.follow(&shared, false);
        let mut p = Progressive::new(w, h, 5);
        let (mut photons, mut stages) = (0.0, 0.0);
        for st in schedule(spp) {
            let thin = thinning_of(&Lit::new(&scene, c.map()), (w, h));
            let work = stage_work(st, (w, h, p.spp), scene.lights.len());
            let t = Instant::now();
            c.refine((work, p.stage_photons(st, thin)), &|| false);
            photons += t.elapsed().as_secs_f64();
            let t = Instant::now();
            assert!(p.run(Lit::new(&scene, c.map()).thinned(thin), st, &|| false));
            stages += t.elapsed().as_secs_f64();
        }
        println!(
            "caustics {}: {:.2} s (photon passes {photons:.2} s, stages {stages:.2} s), {} samples, {} photons",
            if on { "on " } else { "off" },
            start.elapsed().as_secs_f64(),
            p.samples_cast,
            c.map().map_or(0, |m| m.photons())
        );
    }
}
