//! What each feature costs: the scene that uses it rendered with and
//! without it, and the scene that does not use it rendered by the kernel
//! that leaves it out and by the one that has every feature compiled in.

use super::scenes::{FEATURES, feature_variants};
use super::timing::{frame_time, frame_time_with, packet_frame};
use crate::integrator::radiance_packet_unspecialised;
use crate::render::{RenderSettings, render};
use crate::scene::Features;
use crate::scene::file::SceneFile;

/// One feature's bill: the scene that uses it, rendered with and without it,
/// and the scene that does not use it, rendered with the specialised kernel
/// (feature left out) and with the unspecialised one.
#[derive(Clone, Debug, serde::Serialize)]
pub struct FeatureCost {
    pub feature: &'static str,
    pub with_ms: f64,
    pub without_ms: f64,
    pub unused_specialised_ms: f64,
    pub unused_unspecialised_ms: f64,
}

impl FeatureCost {
    /// What carrying the unused feature would cost, as a fraction.
    pub fn unused_overhead(&self) -> f64 {
        self.unused_unspecialised_ms / self.unused_specialised_ms - 1.0
    }
}

/// The scene without `feature` (one of [`FEATURES`]), and the same scene
/// as a renderer that does not leave the feature out would run it: the
/// unspecialised kernel, or for dispersion three wavelengths a sample.
pub fn unused_feature_frame(base: &SceneFile, feature: &str, unspecialised: bool, w: u32, h: u32) -> Option<()> {
    let k = FEATURES.iter().position(|&f| f == feature)?;
    let (_, _, mut without) = feature_variants(base).swap_remove(k);
    if feature == "dispersion" {
        if unspecialised {
            without.features.dispersion = true;
        }
        std::hint::black_box(render(
            &without,
            &RenderSettings {
                width: w,
                height: h,
                spp: 1,
                seed: 0,
            },
            None,
        ));
    } else {
        let kernel = if unspecialised {
            radiance_packet_unspecialised
        } else {
            crate::integrator::radiance_packet
        };
        std::hint::black_box(packet_frame(&without, w, h, kernel));
    }
    Some(())
}

/// Measures every feature on variants of the cubes scene at `w × h`.
pub fn feature_costs(base: &SceneFile, w: u32, h: u32, runs: usize) -> Vec<FeatureCost> {
    let variants = feature_variants(base);
    let mut out = Vec::new();
    for (name, with, without) in variants {
        let with_ms = frame_time(&with, w, h, runs) * 1e3;
        let without_ms = frame_time(&without, w, h, runs) * 1e3;
        // Dispersion is decided per frame (three wavelengths or one), the
        // others inside the kernel; each pair is timed in the same harness.
        let (unused_specialised_ms, unused_unspecialised_ms) = if name == "dispersion" {
            let mut forced = without.clone();
            forced.features = Features {
                dispersion: true,
                ..forced.features
            };
            // Forcing three wavelengths on plain glass gives the same image
            // at three times the work: what not deciding would cost.
            (without_ms, frame_time(&forced, w, h, runs) * 1e3)
        } else {
            // Interleaved, so that drift of the machine hits both alike.
            let mut spec = Vec::new();
            let mut generic = Vec::new();
            for _ in 0..3 {
                spec.push(frame_time_with(&without, w, h, runs, crate::integrator::radiance_packet) * 1e3);
                generic.push(frame_time_with(&without, w, h, runs, radiance_packet_unspecialised) * 1e3);
            }
            spec.sort_by(f64::total_cmp);
            generic.sort_by(f64::total_cmp);
            (spec[1], generic[1])
        };
        out.push(FeatureCost {
            feature: name,
            with_ms,
            without_ms,
            unused_specialised_ms,
            unused_unspecialised_ms,
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::color::Rgb;
    use crate::integrator::{PacketPaths, PacketScratch};
    use crate::scene::Scene;
    use crate::simd::LANES;
    use crate::trace::camera_hits;

    #[test]
    fn unspecialised_kernel_draws_the_same_picture() {
        let (sf, _) = Scene::default_scene();
        let mut no_spec = sf.clone();
        no_spec.materials.values_mut().for_each(|m| m.specular = 0.0);
        no_spec.render.shadows = false;
        no_spec.lenses.clear();
        let s = Scene::build(&no_spec).unwrap();
        assert!(!s.features.specular && !s.features.shadows);
        // Packets of one pixel at the corners and middle, and one of eight
        // across a row: the specialised and unspecialised packet kernels
        // and the scalar `radiance` agree in every lane.
        let wavelength = crate::optics::WAVELENGTH_D_UM;
        let mut packets: Vec<([f64; LANES], f64, usize)> =
            [(10.0, 10.0), (200.0, 200.0), (150.0, 300.0), (390.0, 390.0)]
                .iter()
                .map(|&(x, y)| ([x; LANES], y, 1))
                .collect();
        packets.push((std::array::from_fn(|l| 37.0 * l as f64 + 3.5), 200.5, LANES));
        for (xs, y, n) in packets {
            let (p, hits) = camera_hits(&s, &xs, &[y; LANES], n, 400, 400);
            let paths = PacketPaths::camera(&p, &hits, n);
            let mut scratch = PacketScratch::default();
            let a = crate::integrator::radiance_packet(&(&s).into(), &paths, wavelength, &mut scratch);
            let b = radiance_packet_unspecialised(&(&s).into(), &paths, wavelength, &mut scratch);
            assert_eq!(a, b);
            for l in 0..n {
                let ray = s.camera.ray(xs[l], y, 400, 400);
                assert_eq!(a[l], crate::integrator::radiance(&s, &ray, 0, wavelength), "lane {l}");
                assert!(a[l] != Rgb::ZERO);
            }
        }
    }
}
