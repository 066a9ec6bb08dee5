//! The measurements behind `lensview bench`: render time against image size
//! and object count, primary-ray throughput, and what each feature costs a
//! scene that uses it and a scene that does not. Every figure is the median
//! of several timed runs of the real renderer.

use crate::color::Rgb;
use crate::integrator::{PacketKernel, PacketPaths, PacketScratch, radiance_packet_unspecialised};
use crate::render::{Image, RenderSettings, render, render_into};
use crate::scene::file::{ObjectFile, SceneFile, ShapeKind};
use crate::scene::{Features, Scene};
use crate::simd::LANES;
use crate::trace::{CameraTile, Packet, PacketHits, TILE, camera_hits, camera_tile_hits, closest_hit};
use rayon::prelude::*;
use std::time::Instant;

/// Median wall time in seconds of `runs` calls of `f` (after one warm-up).
pub fn median_time(runs: usize, mut f: impl FnMut()) -> f64 {
    f();
    let mut v: Vec<f64> = (0..runs.max(1))
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64()
        })
        .collect();
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Median frame times (seconds, 1 sample per pixel) of several scenes and
/// sizes, timed round-robin: `runs` rounds, each timing every item once
/// (after one warm-up each), so that a slow spell of a shared machine falls
/// on all the points of a sweep alike instead of bending one of them.
pub fn interleaved_frame_times(items: &[(&Scene, u32, u32)], runs: usize) -> Vec<f64> {
    interleaved_frame_samples(items, runs)
        .into_iter()
        .map(|v| v[v.len() / 2])
        .collect()
}

/// Every frame time (seconds, sorted, `runs` of them) of each item, timed
/// round-robin as [`interleaved_frame_times`] times them. Each item renders
/// into an image kept from frame to frame, as the viewer does.
pub fn interleaved_frame_samples(items: &[(&Scene, u32, u32)], runs: usize) -> Vec<Vec<f64>> {
    let frame = |&(scene, width, height): &(&Scene, u32, u32), img: &mut Image| {
        let s = RenderSettings {
            width,
            height,
            spp: 1,
            seed: 0,
        };
        let t = Instant::now();
        render_into(scene, &s, None, img);
        std::hint::black_box(&img.pixels);
        t.elapsed().as_secs_f64()
    };
    let mut images: Vec<Image> = items.iter().map(|&(_, w, h)| Image::new(w, h)).collect();
    for (item, img) in items.iter().zip(&mut images) {
        frame(item, img);
    }
    let mut times = vec![Vec::new(); items.len()];
    for _ in 0..runs.max(1) {
        for (i, item) in items.iter().enumerate() {
            times[i].push(frame(item, &mut images[i]));
        }
    }
    for v in &mut times {
        v.sort_by(f64::total_cmp);
    }
    times
}

/// One full Whitted frame at 1 sample per pixel, into an image kept from
/// frame to frame (as the viewer keeps its frame).
pub fn frame_time(scene: &Scene, width: u32, height: u32, runs: usize) -> f64 {
    let s = RenderSettings {
        width,
        height,
        spp: 1,
        seed: 0,
    };
    let mut img = Image::new(width, height);
    median_time(runs, || {
        render_into(scene, &s, None, &mut img);
        std::hint::black_box(&img.pixels);
    })
}

/// A frame at 1 sample per pixel (pixel centres, camera packets of eight
/// as the renderer casts them) shaded by `kernel`, in a plain parallel loop
/// (no image kept): the harness in which the specialised and unspecialised
/// kernels are compared on equal terms.
pub fn frame_time_with(scene: &Scene, width: u32, height: u32, runs: usize, kernel: PacketKernel) -> f64 {
    median_time(runs, || {
        std::hint::black_box(packet_frame(scene, width, height, kernel));
    })
}

/// Calls `f(packet, hits, n)` for the camera packets of the band of rows
/// from `TILE · band`: pixel centres cast in tiles of eight pixels by the
/// band's rows ([`TILE`] of them), a packet to each row (`n` pixels in the last column), as
/// the renderer casts them ([`camera_tile_hits`]). With `tiles` off, each
/// packet walks the BVH alone ([`camera_hits`]).
fn centre_packets(
    scene: &Scene,
    width: u32,
    height: u32,
    band: u32,
    tiles: bool,
    mut f: impl FnMut(&Packet, &PacketHits, usize),
) {
    let y0 = band * TILE as u32;
    let rows = ((height - y0) as usize).min(TILE);
    let ys: [[f64; LANES]; TILE] = std::array::from_fn(|r| [(y0 as usize + r) as f64 + 0.5; LANES]);
    let mut tile = CameraTile::default();
    for x0 in (0..width).step_by(LANES) {
        let n = ((width - x0) as usize).min(LANES);
        let xs = [std::array::from_fn(|l| (x0 as usize + l) as f64 + 0.5); TILE];
        if tiles {
            camera_tile_hits(
                scene,
                &xs[..rows],
                &ys[..rows],
                &[n; TILE][..rows],
                width,
                height,
                &mut tile,
            );
            for r in 0..rows {
                f(&tile.packets[r], &tile.hits[r], n);
            }
        } else {
            for r in 0..rows {
                let (p, hits) = camera_hits(scene, &xs[r], &ys[r], n, width, height);
                f(&p, &hits, n);
            }
        }
    }
}

/// One frame at pixel centres through `kernel`, in tiles of camera
/// packets, in parallel bands of rows; returns the sum of its pixels.
pub fn packet_frame(scene: &Scene, width: u32, height: u32, kernel: PacketKernel) -> Rgb {
    (0..height.div_ceil(TILE as u32))
        .into_par_iter()
        .map(|band| {
            let mut acc = Rgb::ZERO;
            let mut scratch = PacketScratch::default();
            centre_packets(scene, width, height, band, true, |p, hits, n| {
                let c = kernel(
                    scene,
                    &PacketPaths::camera(p, hits, n),
                    crate::optics::WAVELENGTH_D_UM,
                    &mut scratch,
                );
                acc += c.iter().sum::<Rgb>();
            });
            acc
        })
        .sum()
}

/// Closest-hit primary rays per second (pixel centres, no shading), cast
/// the way the renderer casts them: tiles of 8 × [`TILE`] pixels whose frustum
/// walks the BVH once, each row of a tile a packet of eight rays
/// ([`crate::trace::packet`]). With `tiles` off, each packet walks the BVH
/// on its own.
pub fn primary_rays_per_second(scene: &Scene, width: u32, height: u32, runs: usize, tiles: bool) -> f64 {
    let t = median_time(runs, || {
        let hits: usize = (0..height.div_ceil(TILE as u32))
            .into_par_iter()
            .map(|band| {
                let mut count = 0;
                centre_packets(scene, width, height, band, tiles, |_, hits, n| {
                    count += (0..n).filter(|&l| hits.get(l).is_some()).count();
                });
                count
            })
            .sum();
        std::hint::black_box(hits);
    });
    (width as f64 * height as f64) / t
}

/// The same rays one at a time through the scalar walk
/// ([`crate::trace::closest_hit`]): what the packets are measured
/// against.
pub fn primary_rays_per_second_scalar(scene: &Scene, width: u32, height: u32, runs: usize) -> f64 {
    let t = median_time(runs, || {
        let hits: usize = (0..height)
            .into_par_iter()
            .map(|y| {
                (0..width)
                    .filter(|&x| {
                        let ray = scene.camera.ray(x as f64 + 0.5, y as f64 + 0.5, width, height);
                        closest_hit(scene, &ray, f64::INFINITY).is_some()
                    })
                    .count()
            })
            .sum();
        std::hint::black_box(hits);
    });
    (width as f64 * height as f64) / t
}

fn is_cube(o: &ObjectFile) -> bool {
    o.name.as_deref().is_some_and(|n| n.starts_with("cube"))
}

/// The cubes scene with only its first `n` cubes (ground and lens kept).
pub fn cubes_subset(base: &SceneFile, n: usize) -> Scene {
    let mut sf = base.clone();
    let mut kept = 0;
    sf.objects.retain(|o| {
        if !is_cube(o) {
            return true;
        }
        kept += 1;
        kept <= n
    });
    Scene::build(&sf).expect("subset of a valid scene") // ok: a subset of a valid scene is valid
}

/// The cubes scene with its 5×5 grid replaced by `side × side` cubes over
/// the same area (−3.2 … 3.2), each scaled so the gaps keep their ratio.
pub fn cubes_grid(base: &SceneFile, side: usize) -> Scene {
    let mut sf = base.clone();
    let template = sf.objects.iter().find(|o| is_cube(o)).cloned();
    let materials: Vec<Option<String>> = sf
        .objects
        .iter()
        .filter(|o| is_cube(o))
        .map(|o| o.material.clone())
        .collect();
    sf.objects.retain(|o| !is_cube(o));
    if let Some(t) = template {
        let spacing = if side > 1 { 6.4 / (side - 1) as f64 } else { 1.6 };
        let size = 0.625 * spacing;
        for i in 0..side * side {
            let (ix, iz) = (i % side, i / side);
            let (x, z) = if side > 1 {
                (-3.2 + ix as f64 * spacing, -3.2 + iz as f64 * spacing)
            } else {
                (0.0, 0.0)
            };
            sf.objects.push(ObjectFile {
                kind: ShapeKind::Cuboid,
                name: Some(format!("cube {}", i + 1)),
                position: [x, 0.5 * size, z],
                size: Some([size; 3]),
                material: materials[i % materials.len().max(1)].clone(),
                ..t.clone()
            });
        }
    }
    Scene::build(&sf).expect("grid of a valid scene") // ok: the same objects at other sizes
}

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

/// The features [`feature_variants`] measures, by the names the command
/// line takes.
pub const FEATURES: [&str; 5] = ["shadows", "glass", "mirror", "specular", "dispersion"];

/// For each feature of [`FEATURES`]: its label, the cubes scene using it and
/// the same scene without it.
pub fn feature_variants(base: &SceneFile) -> Vec<(&'static str, Scene, Scene)> {
    let build = |f: &dyn Fn(&mut SceneFile)| {
        let mut sf = base.clone();
        f(&mut sf);
        Scene::build(&sf).expect("variant of a valid scene") // ok: the variants only switch valid settings
    };
    let no_lens = |sf: &mut SceneFile| sf.lenses.clear();
    let no_spec = |sf: &mut SceneFile| sf.materials.values_mut().for_each(|m| m.specular = 0.0);
    let mirror = |sf: &mut SceneFile| {
        if let Some(m) = sf.materials.get_mut("ground") {
            m.reflectivity = 0.5;
        }
    };
    let dispersive = |sf: &mut SceneFile| {
        if let Some(l) = sf.lenses.first_mut() {
            l.n = crate::scene::file::IndexFile::Cauchy([1.4846, 0.0042]);
        }
    };
    vec![
        ("shadows", build(&|_| {}), build(&|sf| sf.render.shadows = false)),
        ("glass (the lens)", build(&|_| {}), build(&no_lens)),
        // Glass reflects too: the mirror path is unused only without the lens.
        (
            "mirror",
            build(&|sf| {
                no_lens(sf);
                mirror(sf)
            }),
            build(&no_lens),
        ),
        // The lens glass has a highlight of its own: measured without it.
        (
            "specular",
            build(&no_lens),
            build(&|sf| {
                no_lens(sf);
                no_spec(sf)
            }),
        ),
        ("dispersion", build(&dispersive), build(&|_| {})),
    ]
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

    #[test]
    fn variants_have_the_objects_asked_for() {
        let (sf, _) = Scene::default_scene();
        let s = cubes_subset(&sf, 7);
        assert_eq!(s.objects.iter().filter(|o| o.name.starts_with("cube")).count(), 7);
        let g = cubes_grid(&sf, 10);
        assert_eq!(g.objects.iter().filter(|o| o.name.starts_with("cube")).count(), 100);
        assert!(g.bvh.is_some());
        let g5 = cubes_grid(&sf, 5);
        let orig = Scene::default_scene().1;
        // A 5×5 grid is the original layout.
        let pos = |s: &Scene| {
            s.objects
                .iter()
                .filter(|o| o.name.starts_with("cube"))
                .map(|o| o.position)
                .collect::<Vec<_>>()
        };
        for (a, b) in pos(&g5).iter().zip(pos(&orig)) {
            assert!((*a - b).length() < 1e-12);
        }
    }

    #[test]
    fn each_variant_pair_differs_in_its_feature_only_being_used() {
        let (sf, _) = Scene::default_scene();
        for ((label, with, without), name) in feature_variants(&sf).into_iter().zip(FEATURES) {
            let pick = |f: Features| match name {
                "shadows" => f.shadows,
                "glass" => f.glass,
                "mirror" => f.mirror,
                "specular" => f.specular,
                _ => f.dispersion,
            };
            assert!(pick(with.features) && !pick(without.features), "{label}");
        }
    }

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
            let a = crate::integrator::radiance_packet(&s, &paths, wavelength, &mut scratch);
            let b = radiance_packet_unspecialised(&s, &paths, wavelength, &mut scratch);
            assert_eq!(a, b);
            for l in 0..n {
                let ray = s.camera.ray(xs[l], y, 400, 400);
                assert_eq!(a[l], crate::integrator::radiance(&s, &ray, 0, wavelength), "lane {l}");
                assert!(a[l] != Rgb::ZERO);
            }
        }
    }
}
