//! Timing harnesses: the median of timed runs, frames timed round-robin,
//! and primary rays and frames cast as the renderer casts them (tiles of
//! camera packets) but outside it, so kernels and walks compare on equal
//! terms.

use crate::color::Rgb;
use crate::integrator::{PacketKernel, PacketPaths, PacketScratch};
use crate::render::{Image, RenderSettings, render_into};
use crate::scene::Scene;
use crate::simd::LANES;
use crate::trace::{CameraTile, Packet, PacketHits, TILE, camera_hits, camera_tile_hits, closest_hit};
use rayon::prelude::*;
use web_time::Instant;

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
                    &scene.into(),
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
/// ([`crate::trace`]). With `tiles` off, each packet walks the BVH
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
