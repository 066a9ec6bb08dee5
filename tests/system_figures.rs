//! Figures of lens systems (`lens fan | spot | distortion --preset …`).

use glam::DVec3;
use lensview::geometry::{LensSystem, SurfaceSpec};
use lensview::lens_tools::system_bench::SystemBench;
use lensview::optics::{Index, WAVELENGTH_D_UM};
use lensview::prescription;

fn preset(name: &str) -> LensSystem {
    let rows = prescription::parse(name, prescription::preset(name).unwrap()).unwrap();
    let surfaces = rows
        .iter()
        .map(|r| SurfaceSpec {
            radius: r.radius,
            thickness: r.thickness,
            n: r.n,
            semi_aperture: 0.5 * r.aperture_diameter,
            stop: r.stop,
        })
        .collect();
    LensSystem::new(DVec3::ZERO, DVec3::Z, surfaces).unwrap()
}

#[test]
fn probe() {
    for (name, _) in prescription::PRESETS {
        let b = SystemBench::new(preset(name), None, 0.0).unwrap();
        let z = b.system.vertex_z(b.paraxial.stop);
        let a = b.system.surfaces[b.paraxial.stop].semi_aperture;
        for px in [0.5, 0.9, 0.99, 1.0] {
            let (o, _, ray) = b.trace(px, 0.0, WAVELENGTH_D_UM);
            let h = b.plane_crossing(o, &ray, z).map(|p| p.x / a);
            eprintln!("{name} px {px}: stop height / a = {h:?} {:?}", ray.status);
        }
    }
    let _ = Index::Constant(1.0);
}
