//! The lane functions' builds (SSE2, AVX2, AVX-512: `simd::Isa`) give the
//! same picture bit for bit, on every shipped scene, in one process per
//! build switch (this file is its own test binary: forcing a build is
//! global). Builds this CPU lacks are skipped, and said so.

use lensview::render::progressive::{Progressive, Stage};
use lensview::render::{Image, RenderSettings, render_into};
use lensview::scene::Scene;
use lensview::simd::{Isa, force_isa};

fn picture(scene: &Scene) -> (Vec<u64>, Vec<u8>) {
    let s = RenderSettings {
        width: 72,
        height: 48,
        spp: 2,
        seed: 7,
    };
    let mut img = Image::new(s.width, s.height);
    render_into(scene, &s, None, &mut img);
    let bits = img.pixels.iter().flat_map(|p| p.to_array().map(f64::to_bits)).collect();
    // The progressive path too (camera tiles, adaptive waves).
    let mut prog = Progressive::new(s.width, s.height, 3);
    assert!(prog.run(scene, Stage::Samples(2), &|| false));
    let mut rgba = Vec::new();
    prog.write_rgba8(&mut rgba, Default::default());
    (bits, rgba)
}

#[test]
fn every_build_gives_the_same_bits() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    names.sort();
    assert!(names.len() >= 4, "{names:?}");
    let builds: Vec<Isa> = [Isa::Portable, Isa::Avx2, Isa::Avx512]
        .into_iter()
        .filter(|&i| force_isa(Some(i)))
        .collect();
    eprintln!("builds this CPU runs: {builds:?} (best {:?})", Isa::detected());
    for path in &names {
        let scene = Scene::load(path).unwrap().1;
        let pictures: Vec<_> = builds
            .iter()
            .map(|&i| {
                assert!(force_isa(Some(i)));
                picture(&scene)
            })
            .collect();
        for (i, p) in builds.iter().zip(&pictures).skip(1) {
            assert!(
                *p == pictures[0],
                "{}: {:?} differs from {:?}",
                path.display(),
                i,
                builds[0]
            );
        }
    }
    assert!(force_isa(None));
}
