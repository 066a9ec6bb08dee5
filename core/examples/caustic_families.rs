//! The caustic families of a scene's first photon pass (`photon::family`):
//! for each, the object that last sent its photons and how (through,
//! reflected, ghost), its share of the photons and of their power, its
//! own spacing (the median distance to the 24th neighbour among its
//! photons) against the map's, and which families the map gathers with a
//! radius of their own.
//!
//!     cargo run --release -p lensview-core --example caustic_families -- scenes/primitives.toml

use lensview_core::integrator::{Targets, family_source, photon_pass};
use lensview_core::photon::{Photon, family_scales, initial_radius};
use lensview_core::render::caustics::{FIRST_PASS_NEIGHBOURS, PHOTONS_PER_PASS};
use lensview_core::scene::Scene;

fn main() {
    let Some(path) = std::env::args().nth(1) else {
        eprintln!("usage: caustic_families SCENE.toml");
        std::process::exit(2);
    };
    let scene = match Scene::load(std::path::Path::new(&path)) {
        Ok((_, s)) => s,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(1);
        }
    };
    let photons = photon_pass(&scene, &Targets::of(&scene), 1, PHOTONS_PER_PASS, 0);
    let k = FIRST_PASS_NEIGHBOURS;
    let Some(r0) = initial_radius(&photons, k, 0.0) else {
        println!("{path}: {} photons landed in the first pass: no map", photons.len());
        return;
    };
    let power = |v: &[Photon]| {
        v.iter()
            .map(|p| p.power.iter().map(|&c| c as f64).sum::<f64>())
            .sum::<f64>()
    };
    let (n, all) = (photons.len() as f64, power(&photons));
    println!("{path}: {} photons in the first pass, r0 {r0:.5}", photons.len());
    let mut families: Vec<u32> = photons.iter().map(|p| p.family).collect();
    families.sort_unstable();
    families.dedup();
    for f in families {
        let of: Vec<Photon> = photons.iter().filter(|p| p.family == f).copied().collect();
        let own = initial_radius(&of, k, 0.0).map_or("-".to_string(), |r| format!("{:.2} r0", r / r0));
        println!(
            "  {}: {:.1} % of the photons, {:.1} % of the power, spacing {own}",
            named(&scene, f),
            100.0 * of.len() as f64 / n,
            100.0 * power(&of) / all
        );
    }
    let listed = family_scales(&photons, k, r0);
    let named: Vec<String> = listed
        .iter()
        .map(|&(f, h)| format!("{} at 2^({h}/2) r0", named(&scene, f)))
        .collect();
    println!(
        "  own radii: {}",
        if named.is_empty() {
            "none".to_string()
        } else {
            named.join(", ")
        }
    );
}

/// A family as its object's name and the way its photons left it.
fn named(scene: &Scene, family: u32) -> String {
    match family_source(family) {
        Some((i, sent)) => {
            let name = scene.objects.get(i).map_or("?", |o| o.name.as_str());
            format!("{name} ({})", sent.name())
        }
        None => format!("family {family}"),
    }
}
