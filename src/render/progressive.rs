//! Progressive refinement: a schedule of coarse block levels, then full
//! resolution, then waves of extra samples, rendered in parallel row bands
//! with cancellation checked between bands.
//!
//! Sample `i` of a pixel is fixed: sample 0 is the pixel centre, sample
//! `i ≥ 1` is jittered by `Sampler(seed, pixel, i)`. An image refined to `N`
//! samples is therefore the same whatever the thread count, and the same
//! whether it got there in one wave or many.

use super::{BandMemory, RenderSettings, add_band_samples, sample_packet};
use crate::color::Rgb;
use crate::integrator::PacketScratch;
use crate::scene::Scene;
use crate::simd::LANES;
use crate::trace::TILE;
use rayon::prelude::*;

/// One step of the schedule.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// One sample per `n × n` block, drawn as a flat block.
    Blocks(u32),
    /// Full resolution, accumulated until every pixel has this many samples.
    Samples(u32),
}

impl Stage {
    /// Camera samples this stage takes for a `width × height` image that
    /// already has `have` samples per pixel.
    pub fn cost(&self, width: u32, height: u32, have: u32) -> u64 {
        let (w, h) = (width as u64, height as u64);
        match *self {
            Stage::Blocks(n) => w.div_ceil(n as u64) * h.div_ceil(n as u64),
            Stage::Samples(s) => w * h * s.saturating_sub(have) as u64,
        }
    }

    pub fn label(&self) -> String {
        match *self {
            Stage::Blocks(n) => format!("{n}×{n} blocks"),
            Stage::Samples(s) => format!("{s} spp"),
        }
    }
}

/// The standard schedule: 8×8 → 4×4 → 2×2 blocks, full resolution at 1
/// sample, then 2, 4, 8, … samples per pixel up to `max_spp`.
pub fn schedule(max_spp: u32) -> Vec<Stage> {
    let mut v = vec![Stage::Blocks(8), Stage::Blocks(4), Stage::Blocks(2), Stage::Samples(1)];
    let mut s = 2;
    while s < max_spp {
        v.push(Stage::Samples(s));
        s *= 2;
    }
    if max_spp > 1 {
        v.push(Stage::Samples(max_spp));
    }
    v
}

/// The first stage worth drawing: the finest block level whose predicted
/// time fits `budget_s`, given the measured `seconds_per_sample` (none
/// measured yet: the coarsest).
pub fn first_stage(stages: &[Stage], width: u32, height: u32, seconds_per_sample: Option<f64>, budget_s: f64) -> usize {
    let Some(sps) = seconds_per_sample else { return 0 };
    let mut pick = 0;
    for (i, st) in stages.iter().enumerate() {
        if matches!(st, Stage::Samples(s) if *s > 1) {
            break;
        }
        if st.cost(width, height, 0) as f64 * sps <= budget_s {
            pick = i;
        } else {
            break;
        }
    }
    pick
}

/// The image being refined: a preview for block levels, and the running sum
/// of full-resolution samples.
#[derive(Clone, Debug)]
pub struct Progressive {
    pub width: u32,
    pub height: u32,
    pub seed: u64,
    /// Samples per pixel in `sum` (0 while only block levels were drawn).
    pub spp: u32,
    sum: Vec<Rgb>,
    /// The buffer a sample stage writes before it replaces `sum` (the
    /// previous sums, kept so that no frame allocates or clears one).
    next: Vec<Rgb>,
    preview: Vec<Rgb>,
    /// Block size of the last block stage drawn into `preview`.
    block: usize,
}

/// Rows per band: the unit of parallel work and of cancellation, and the
/// height of a tile of camera packets.
const BAND: usize = TILE;

impl Progressive {
    pub fn new(width: u32, height: u32, seed: u64) -> Self {
        let n = width as usize * height as usize;
        Progressive {
            width,
            height,
            seed,
            spp: 0,
            sum: vec![Rgb::ZERO; n],
            next: vec![Rgb::ZERO; n],
            preview: vec![Rgb::ZERO; n],
            block: 1,
        }
    }

    /// Starts over for a new picture, keeping the buffers when the size is
    /// unchanged (the sums are cleared when the first sample stage runs).
    pub fn reset(&mut self, width: u32, height: u32, seed: u64) {
        if (width, height) != (self.width, self.height) {
            *self = Progressive::new(width, height, seed);
        } else {
            self.seed = seed;
            self.spp = 0;
            self.block = 1;
        }
    }

    /// Renders one stage. Returns `false` (leaving the image as it was
    /// before the stage for sample stages) if `cancelled()` turned true.
    pub fn run(&mut self, scene: &Scene, stage: Stage, cancelled: &(dyn Fn() -> bool + Sync)) -> bool {
        let (w, h) = (self.width as usize, self.height as usize);
        if w == 0 || h == 0 {
            return true;
        }
        match stage {
            Stage::Blocks(n) => {
                let n = n.max(1) as usize;
                self.block = n;
                self.preview.par_chunks_mut(w * n).enumerate().all(|(by, rows)| {
                    if cancelled() {
                        return false;
                    }
                    let y0 = by * n;
                    let rows_here = rows.len() / w;
                    let cy = (y0 + n / 2).min(h - 1);
                    let blocks = w.div_ceil(n);
                    let mut scratch = PacketScratch::default();
                    // Block centres, eight to a packet.
                    for b0 in (0..blocks).step_by(LANES) {
                        let k = (blocks - b0).min(LANES);
                        let xs = std::array::from_fn(|l| ((b0 + l) * n + n / 2).min(w - 1) as f64 + 0.5);
                        let ys = [cy as f64 + 0.5; LANES];
                        let c = sample_packet(scene, &xs, &ys, k, self.width, self.height, &mut scratch);
                        for (l, &c) in c.iter().enumerate().take(k) {
                            let x0 = (b0 + l) * n;
                            for r in 0..rows_here {
                                let row = &mut rows[r * w..(r + 1) * w];
                                row[x0..(x0 + n).min(w)].fill(c);
                            }
                        }
                    }
                    true
                })
            }
            Stage::Samples(target) => {
                let from = self.spp;
                if target <= from {
                    return true;
                }
                let (width, height, seed) = (self.width, self.height, self.seed);
                // The sums are written in place only when the whole stage
                // completes; a cancelled stage must leave them untouched.
                // Sample 0 overwrites what the spare buffer held; a later
                // wave starts each band from a copy of its sums.
                let mut next = std::mem::take(&mut self.next);
                let sum = &self.sum;
                let ok = next.par_chunks_mut(w * BAND).enumerate().all(|(band, rows)| {
                    if cancelled() {
                        return false;
                    }
                    if from > 0 {
                        let start = band * BAND * w;
                        rows.copy_from_slice(&sum[start..start + rows.len()]);
                    }
                    let settings = RenderSettings {
                        width,
                        height,
                        spp: target,
                        seed,
                    };
                    let mut memory = BandMemory::default();
                    for s in from..target {
                        add_band_samples(scene, (band * BAND) as u32, s, s == 0, &settings, &mut memory, rows);
                    }
                    true
                });
                if ok {
                    self.next = std::mem::replace(&mut self.sum, next);
                    self.spp = target;
                } else {
                    self.next = next;
                }
                ok
            }
        }
    }

    /// The current picture: the mean of the samples when there are any,
    /// else the block preview.
    pub fn image(&self) -> super::Image {
        let pixels = if self.spp > 0 {
            let inv = 1.0 / self.spp as f64;
            self.sum.par_iter().map(|c| *c * inv).collect()
        } else {
            self.preview.clone()
        };
        super::Image {
            width: self.width,
            height: self.height,
            pixels,
        }
    }

    /// The current picture as 8-bit sRGB RGBA (for a framebuffer), written
    /// into `out` (resized as needed).
    pub fn write_rgba8(&self, out: &mut Vec<u8>) {
        let n = self.width as usize * self.height as usize;
        out.resize(n * 4, 255);
        if self.spp == 0 && self.block > 1 {
            return self.write_blocks_rgba8(out);
        }
        let inv = if self.spp > 0 { 1.0 / self.spp as f64 } else { 1.0 };
        let src = if self.spp > 0 { &self.sum } else { &self.preview };
        // Chunks of pixels, not single pixels, per parallel task: at a
        // million tiny tasks rayon's splitting costs more than the work.
        const CHUNK: usize = 4096;
        out.par_chunks_mut(4 * CHUNK)
            .zip(src.par_chunks(CHUNK))
            .for_each(|(o, cs)| {
                for (o, c) in o.chunks_exact_mut(4).zip(cs) {
                    let c = *c * inv;
                    o[0] = crate::color::to_srgb8_fast(c.x);
                    o[1] = crate::color::to_srgb8_fast(c.y);
                    o[2] = crate::color::to_srgb8_fast(c.z);
                    o[3] = 255;
                }
            });
    }
}

impl Progressive {
    /// [`Progressive::write_rgba8`] for a block preview: one conversion per
    /// block, then whole rows copied (the first frame after an input should
    /// not spend its budget converting 64 equal pixels 64 times).
    fn write_blocks_rgba8(&self, out: &mut [u8]) {
        let (w, n) = (self.width as usize, self.block);
        out.par_chunks_mut(4 * w * n)
            .zip(self.preview.par_chunks(w * n))
            .for_each(|(o, src)| {
                let row0 = &mut o[..4 * w];
                for bx in 0..w.div_ceil(n) {
                    let c = src[bx * n];
                    let px = [
                        crate::color::to_srgb8_fast(c.x),
                        crate::color::to_srgb8_fast(c.y),
                        crate::color::to_srgb8_fast(c.z),
                        255,
                    ];
                    for x in bx * n..((bx + 1) * n).min(w) {
                        row0[4 * x..4 * x + 4].copy_from_slice(&px);
                    }
                }
                let (first, rest) = o.split_at_mut(4 * w);
                for row in rest.chunks_exact_mut(4 * w) {
                    row.copy_from_slice(first);
                }
            });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::{RenderSettings, render};

    fn scene() -> Scene {
        Scene::default_scene().1
    }

    #[test]
    fn schedule_goes_coarse_to_fine_and_stops_at_the_cap() {
        assert_eq!(
            schedule(16),
            vec![
                Stage::Blocks(8),
                Stage::Blocks(4),
                Stage::Blocks(2),
                Stage::Samples(1),
                Stage::Samples(2),
                Stage::Samples(4),
                Stage::Samples(8),
                Stage::Samples(16)
            ]
        );
        assert_eq!(*schedule(1).last().unwrap(), Stage::Samples(1));
        assert_eq!(*schedule(48).last().unwrap(), Stage::Samples(48));
    }

    #[test]
    fn first_stage_fits_the_budget() {
        let st = schedule(64);
        assert_eq!(first_stage(&st, 1280, 720, None, 0.016), 0);
        // 10 µs a sample: 8×8 blocks (14 400 samples) take 0.144 s: still the coarsest.
        assert_eq!(first_stage(&st, 1280, 720, Some(1e-5), 0.016), 0);
        // 50 ns a sample: 2×2 (230 400 samples) takes 11.5 ms; full res 46 ms.
        assert_eq!(first_stage(&st, 1280, 720, Some(5e-8), 0.016), 2);
        assert_eq!(first_stage(&st, 1280, 720, Some(1e-9), 0.016), 3);
    }

    #[test]
    fn refinement_converges_to_the_same_image_as_a_direct_render() {
        let s = scene();
        let mut p = Progressive::new(40, 30, 3);
        for st in schedule(4) {
            assert!(p.run(&s, st, &|| false));
        }
        assert_eq!(p.spp, 4);
        let direct = render(
            &s,
            &RenderSettings {
                width: 40,
                height: 30,
                spp: 1,
                seed: 3,
            },
            None,
        );
        let mut one = Progressive::new(40, 30, 3);
        one.run(&s, Stage::Samples(1), &|| false);
        // Sample 0 is the pixel centre, as in a 1-spp render.
        assert_eq!(one.image(), direct);
        // After a reset the kept buffers hold old sums; they never leak in.
        one.run(&s, Stage::Samples(3), &|| false);
        one.reset(40, 30, 3);
        one.run(&s, Stage::Samples(1), &|| false);
        assert_eq!(one.image(), direct);
        // Four samples in waves equal four samples at once.
        let mut once = Progressive::new(40, 30, 3);
        once.run(&s, Stage::Samples(4), &|| false);
        assert_eq!(once.image(), p.image());
    }

    #[test]
    fn cancellation_stops_a_stage_and_keeps_the_previous_image() {
        let s = scene();
        let mut p = Progressive::new(64, 16 * BAND as u32, 0);
        p.run(&s, Stage::Samples(1), &|| false);
        let before = p.image();
        let calls = std::sync::atomic::AtomicUsize::new(0);
        let ok = p.run(&s, Stage::Samples(8), &|| {
            calls.fetch_add(1, std::sync::atomic::Ordering::Relaxed) >= 2
        });
        assert!(!ok);
        assert_eq!(p.spp, 1);
        assert_eq!(p.image(), before);
        // Bands after the cancellation were skipped, not rendered: of the
        // 16 bands, the two that saw no cancellation and the few already
        // started beside the third asked.
        assert!(calls.load(std::sync::atomic::Ordering::Relaxed) <= 8);
    }

    #[test]
    fn the_schedule_gives_the_same_bits_on_one_two_and_three_threads() {
        let s = Scene::load(&std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/primitives.toml"))
            .unwrap()
            .1;
        // Taller than one band per thread, and not a whole number of bands.
        let run = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| {
                    let mut p = Progressive::new(45, 7 * BAND as u32 + 3, 11);
                    let mut frames = Vec::new();
                    for st in schedule(6) {
                        assert!(p.run(&s, st, &|| false));
                        let mut rgba = Vec::new();
                        p.write_rgba8(&mut rgba);
                        frames.push((p.image(), rgba));
                    }
                    frames
                })
        };
        let bits = |frames: &[(crate::render::Image, Vec<u8>)]| -> Vec<(Vec<u64>, Vec<u8>)> {
            frames
                .iter()
                .map(|(img, rgba)| {
                    (
                        img.pixels.iter().flat_map(|c| c.to_array().map(f64::to_bits)).collect(),
                        rgba.clone(),
                    )
                })
                .collect()
        };
        let one = bits(&run(1));
        assert_eq!(one.len(), schedule(6).len());
        // Every stage changed the picture (the comparison is not of blanks).
        assert!(one.windows(2).all(|w| w[0].0 != w[1].0));
        assert_eq!(one, bits(&run(2)));
        assert_eq!(one, bits(&run(3)));
    }

    #[test]
    fn block_preview_fills_every_pixel() {
        let s = scene();
        let mut p = Progressive::new(37, 23, 0);
        assert!(p.run(&s, Stage::Blocks(8), &|| false));
        let img = p.image();
        // Blocks are flat, and the last partial block is filled too.
        assert_eq!(img.get(0, 0), img.get(7, 7));
        assert_ne!(img.get(36, 22), Rgb::ZERO);
        let mut rgba = Vec::new();
        p.write_rgba8(&mut rgba);
        assert_eq!(rgba.len(), 37 * 23 * 4);
        // The per-block conversion gives the same bytes as per pixel.
        let per_pixel: Vec<u8> = img
            .pixels
            .iter()
            .flat_map(|c| {
                [
                    crate::color::to_srgb8_fast(c.x),
                    crate::color::to_srgb8_fast(c.y),
                    crate::color::to_srgb8_fast(c.z),
                    255,
                ]
            })
            .collect();
        assert_eq!(rgba, per_pixel);
    }
}
