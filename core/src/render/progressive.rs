//! Progressive refinement: a schedule of coarse block levels, then full
//! resolution, then waves of extra samples, rendered in parallel row bands
//! with cancellation checked between bands.
//!
//! Sample `i` of a pixel is fixed: sample 0 is the pixel centre, sample
//! `i ≥ 1` lies at [`crate::sampling::pixel_offset`] of the pattern, keyed by (seed, pixel,
//! `i`). With [`Sampling::adaptive`] a wave refines only the pixels that
//! need it ([`Adaptive`]); a pixel's mean is over its own samples. An
//! image refined to `N` samples is the same whatever the thread count, and
//! (uniform waves) the same whether it got there in one wave or many.

use super::adaptive::{Sums, SumsMut, copy_squares};
use super::edges::{self, EDGE_BLOCK, EDGE_CONTRAST, EDGE_SHARE, Exact};
use super::thinning::{lit_for_sample, photon_factor, sample_stage, stage_thinning, wave_photon_factor};
use super::upsample::{block_centres, upsample};
use super::{Adaptive, BandMemory, FirstHit, RenderSettings, add_band_samples, band_first_hits};
use crate::color::{Rgb, Srgb8, Tone};
use crate::integrator::Lit;
use crate::sampling::Pattern;
use crate::scene::Scene;
use crate::trace::TILE;
use rayon::prelude::*;

/// How a [`Progressive`] places its samples.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sampling {
    pub pattern: Pattern,
    /// `None`: every wave samples every pixel.
    pub adaptive: Option<Adaptive>,
}

impl Default for Sampling {
    /// R2 points, adaptive waves: what the viewer and `converge` use.
    fn default() -> Sampling {
        Sampling {
            pattern: Pattern::R2,
            adaptive: Some(Adaptive::default()),
        }
    }
}

impl Sampling {
    /// Every pixel gets every sample (a direct `render`'s points).
    pub const UNIFORM: Sampling = Sampling {
        pattern: Pattern::R2,
        adaptive: None,
    };
}

/// One step of the schedule.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// One sample per `n × n` block, at its centre; every pixel drawn as
    /// the bilinear blend of the centres around it (`upsample`), but in
    /// the blocks at edges, whose own pixels are cast ([`super::edges`]).
    Blocks(u32),
    /// Full resolution, accumulated until every pixel has this many samples.
    Samples(u32),
    /// The previous picture moved into a new view, the rest traced
    /// ([`Progressive::reproject`]).
    Reprojected,
}

impl Stage {
    /// Camera samples this stage takes for a `width × height` image that
    /// already has `have` samples per pixel (a block level: at most, its
    /// edges refined to the cap of [`EDGE_SHARE`] where it is refined).
    pub fn cost(&self, width: u32, height: u32, have: u32) -> u64 {
        let (w, h) = (width as u64, height as u64);
        match *self {
            Stage::Blocks(n) => {
                let centres = w.div_ceil(n as u64) * h.div_ceil(n as u64);
                let n = n as usize;
                let share = if n <= EDGE_BLOCK { EDGE_SHARE } else { 0.0 };
                centres + (edges::cap(centres as usize, n, share) * (n * n).saturating_sub(1)) as u64
            }
            Stage::Samples(s) => w * h * s.saturating_sub(have) as u64,
            Stage::Reprojected => 0,
        }
    }

    pub fn label(&self) -> String {
        match *self {
            Stage::Blocks(n) => format!("{n}×{n} blocks"),
            Stage::Samples(s) => format!("{s} spp"),
            Stage::Reprojected => "reprojected".into(),
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

/// Where the last reprojection's time went ([`Progressive::reproject`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ReprojectTimes {
    /// Recording the old picture's first hits (0 when it had them).
    pub first_hits_s: f64,
    /// Steps 1 and 2: the splat and the look back.
    pub warp_s: f64,
    /// Of `warp_s`, step 1 (the splat).
    pub splat_s: f64,
    /// Step 3: tracing what was left.
    pub fill_s: f64,
    /// Pixels left to step 3, and the block size they were traced at.
    pub holes: usize,
    pub level: u32,
}

/// The image being refined: a preview for block levels, and the running
/// sums of full-resolution samples.
#[derive(Debug)]
pub struct Progressive {
    pub width: u32,
    pub height: u32,
    pub seed: u64,
    /// The most samples any pixel has (0 while only block levels were
    /// drawn); every pixel has this many unless waves are adaptive.
    pub spp: u32,
    pub sampling: Sampling,
    /// Camera samples cast since the last reset, block levels included.
    pub samples_cast: u64,
    /// The share of a block level's samples that refining its edges may
    /// add ([`edges::cap`]; 0: none refined), for levels of blocks up to
    /// [`EDGE_BLOCK`] pixels.
    pub edge_share: f64,
    sum: Vec<Rgb>,
    /// Per pixel: the sum of its samples' squares, and their count.
    sq: Vec<[f32; 3]>,
    /// `sq` is not written: every pixel has its one sample and its square
    /// is the square of its sum (after the first sample stage alone, which
    /// thus writes no squares; the next wave computes them as it copies).
    sq_of_sum: bool,
    count: Vec<u32>,
    /// The buffers a sample stage writes before they replace `sum`, `sq`
    /// and `count` (the previous ones, kept so that no frame allocates).
    next: Vec<Rgb>,
    next_sq: Vec<[f32; 3]>,
    next_count: Vec<u32>,
    /// Working memory of adaptive waves (clamped means) and of
    /// reprojection (the nearest splat per pixel).
    means: Vec<[f32; 3]>,
    splat: super::reproject::Scratch,
    /// What each pixel's centre ray met (written by a reprojection, or
    /// by [`Self::record_first_hits`]), and the buffer a reprojection
    /// writes.
    first: Vec<FirstHit>,
    next_first: Vec<FirstHit>,
    /// `first` belongs to the picture held. A sample stage does not write
    /// first hits (in the first stage, every move's cost, they cost a
    /// few percent against a plain frame): the render thread records them
    /// when it has nothing else to do, or the next reprojection does.
    first_ok: bool,
    /// The preview holds a reprojected picture (with `first`), which may
    /// itself be reprojected.
    reprojected: bool,
    /// The picture while it is not the samples' means; after a block
    /// level, the pixels of its blocks refined at edges.
    preview: Vec<Rgb>,
    /// Block size of the last block stage drawn into `preview`.
    block: usize,
    /// That stage's block centres, row-major (kept for the next), and the
    /// blocks it refined (ascending).
    coarse: Vec<Rgb>,
    edges: Vec<u32>,
    /// Where the last reprojection's time went.
    pub reprojection: ReprojectTimes,
}

/// A block level's centres and the pixels of its blocks refined at edges.
type Centres<'a> = (&'a [Rgb], Option<Exact<'a>>);

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
            sampling: Sampling::default(),
            samples_cast: 0,
            edge_share: EDGE_SHARE,
            sum: vec![Rgb::ZERO; n],
            sq: vec![[0.0; 3]; n],
            sq_of_sum: false,
            count: vec![0; n],
            next: vec![Rgb::ZERO; n],
            next_sq: vec![[0.0; 3]; n],
            next_count: vec![0; n],
            first: vec![FirstHit::default(); n],
            next_first: vec![FirstHit::default(); n],
            first_ok: false,
            reprojected: false,
            means: Vec::new(),
            splat: Default::default(),
            preview: vec![Rgb::ZERO; n],
            block: 1,
            coarse: Vec::new(),
            edges: Vec::new(),
            reprojection: ReprojectTimes::default(),
        }
    }

    /// [`Progressive::new`] with another way of placing samples.
    pub fn with_sampling(mut self, sampling: Sampling) -> Self {
        self.sampling = sampling;
        self
    }

    /// Starts over for a new picture, keeping the buffers when the size is
    /// unchanged (the sums are cleared when the first sample stage runs).
    pub fn reset(&mut self, width: u32, height: u32, seed: u64) {
        if (width, height) != (self.width, self.height) {
            let (sampling, edge_share) = (self.sampling, self.edge_share);
            // The old buffers are freed before the new ones are allocated.
            *self = Progressive::new(0, 0, seed);
            *self = Progressive::new(width, height, seed).with_sampling(sampling);
            self.edge_share = edge_share;
        } else {
            self.seed = seed;
            self.spp = 0;
            self.block = 1;
            self.samples_cast = 0;
            self.reprojected = false;
            self.first_ok = false;
        }
    }

    /// Moves the current picture, seen from `from`, into `scene`'s view
    /// (the same size; the scene the same but for its camera:
    /// [`super::reproject::same_but_camera`]) and starts a new picture
    /// with it: the frame of [`Stage::Reprojected`]. What cannot be moved
    /// is traced at the block size `level(pixels left)` picks (1: each
    /// pixel's centre). Returns `false`, changing nothing, when there is no
    /// picture to move (nothing refined yet, or only block levels), or when
    /// either view is a lens camera's: the warp and its first hits assume a
    /// pinhole (one centre ray a pixel from one point), and a lens camera's
    /// pixel gathers rays from the whole pupil, blurred by the focus.
    pub fn reproject<'a>(&mut self, scene: impl Into<Lit<'a>>, from: &Scene, level: impl Fn(usize) -> u32) -> bool {
        let lit = scene.into();
        let scene = &lit;
        use super::reproject::{Source, fill, warp};
        let n = self.width as usize * self.height as usize;
        let pinholes = from.lens.is_none() && scene.lens.is_none();
        if !(self.spp > 0 || self.reprojected) || n == 0 || !pinholes {
            return false;
        }
        let t0 = web_time::Instant::now();
        self.record_first_hits(from, &|| false);
        let t1 = web_time::Instant::now();
        let size = (self.width, self.height);
        // The source colours: the means of the samples, or the preview.
        let (colour, count) = if self.spp > 0 {
            (&self.sum, Some(&self.count[..]))
        } else {
            (&self.preview, None)
        };
        let src = Source {
            camera: &from.camera,
            size,
            colour,
            count,
            first: &self.first,
        };
        let holes = warp(
            &src,
            &scene.camera,
            size,
            &mut self.splat,
            &mut self.next,
            &mut self.next_first,
        );
        let (t2, level) = (web_time::Instant::now(), level(holes));
        let cast = fill(scene, size, level, &mut self.next, &mut self.next_first);
        self.reprojection = ReprojectTimes {
            first_hits_s: (t1 - t0).as_secs_f64(),
            warp_s: (t2 - t1).as_secs_f64(),
            splat_s: self.splat.splat_s,
            fill_s: t2.elapsed().as_secs_f64(),
            holes,
            level,
        };
        std::mem::swap(&mut self.preview, &mut self.next);
        std::mem::swap(&mut self.first, &mut self.next_first);
        (self.spp, self.block, self.reprojected, self.samples_cast) = (0, 1, true, cast);
        self.first_ok = true;
        true
    }

    /// Takes a picture refined elsewhere as the one held, for the next
    /// [`Self::reproject`] to move: pixel `i` becomes `over(i)` where that
    /// is `Some` (linear colour), else keeps what this picture shows. For
    /// a front end that adds its samples outside this type (the web page's
    /// band steps, whose finished picture is `render`'s). Returns `false`,
    /// changing nothing, if a pixel left to this picture shows only a
    /// block preview (nothing at full resolution to move).
    pub fn hold(&mut self, over: impl Fn(usize) -> Option<Rgb> + Sync) -> bool {
        let blocks = self.spp == 0 && (self.block > 1 || !self.reprojected);
        let (spp, preview, sum, count) = (self.spp, &self.preview, &self.sum, &self.count);
        // Into the scratch buffer (the old picture is read meanwhile), which
        // then becomes the preview; a refusal leaves only scratch written.
        let whole = self.next.par_iter_mut().enumerate().all(|(i, out)| {
            let own = || match spp {
                0 => preview[i],
                _ => mean(sum[i], count[i]),
            };
            match over(i).or_else(|| (!blocks).then(own)) {
                Some(c) => *out = c,
                None => return false,
            }
            true
        });
        if !whole {
            return false;
        }
        std::mem::swap(&mut self.preview, &mut self.next);
        (self.spp, self.block, self.reprojected) = (0, 1, true);
        true
    }

    /// What each pixel's centre ray met (row-major; see [`FirstHit`]), once
    /// recorded for the picture held ([`Self::record_first_hits`]).
    pub fn first_hits(&self) -> Option<&[FirstHit]> {
        self.first_ok.then_some(&self.first[..])
    }

    /// Records what each pixel's centre ray meets in `scene` (the scene of
    /// the picture held), unless recorded: sample 0's camera rays, not
    /// shaded (about a sixth of a frame's time). Returns `false`, leaving
    /// them unrecorded, if `cancelled()` turned true.
    pub fn record_first_hits(&mut self, scene: &Scene, cancelled: &(dyn Fn() -> bool + Sync)) -> bool {
        let w = self.width as usize;
        if self.first_ok || w == 0 {
            return true;
        }
        let settings = RenderSettings {
            width: self.width,
            height: self.height,
            spp: 1,
            seed: self.seed,
        };
        self.first_ok = self.first.par_chunks_mut(w * BAND).enumerate().all(|(band, first)| {
            if cancelled() {
                return false;
            }
            let mut memory = BandMemory::default();
            band_first_hits(scene, (band * BAND) as u32, &settings, &mut memory, first);
            true
        });
        self.first_ok
    }

    /// The share of the picture's pixels seen through glass or in a mirror,
    /// or not known (a reprojection traces them all), once its first hits
    /// are recorded.
    pub fn specular_share(&self) -> Option<f64> {
        use super::Seen::{Specular, Unknown};
        let first = self.first_hits()?;
        let n = first.iter().filter(|f| matches!(f.seen(), Specular | Unknown)).count();
        Some(n as f64 / first.len().max(1) as f64)
    }

    /// Samples each pixel holds (row-major).
    pub fn counts(&self) -> &[u32] {
        &self.count
    }

    /// Renders one stage. Returns `false` (leaving the image as it was
    /// before the stage for sample stages) if `cancelled()` turned true.
    pub fn run<'a>(&mut self, scene: impl Into<Lit<'a>>, stage: Stage, cancelled: &(dyn Fn() -> bool + Sync)) -> bool {
        let lit = scene.into();
        let scene = &lit;
        let (w, h) = (self.width as usize, self.height as usize);
        if w == 0 || h == 0 {
            return true;
        }
        match stage {
            Stage::Blocks(n) => {
                let n = n.max(1) as usize;
                self.block = n;
                (self.reprojected, self.first_ok) = (false, false);
                let (bw, bh) = (w.div_ceil(n), h.div_ceil(n));
                self.samples_cast += (bw * bh) as u64;
                self.edges.clear();
                let mut coarse = std::mem::take(&mut self.coarse);
                coarse.resize(bw * bh, Rgb::ZERO);
                // Only the block centres (and the pixels at edges): the
                // pixels are blended from them when they are read
                // ([`Self::image`], [`Self::write_rgba8`]).
                let done = block_centres(scene, (self.width, self.height), n, &mut coarse, cancelled);
                self.coarse = coarse;
                done && self.refine_edges(scene, n, cancelled)
            }
            Stage::Samples(target) => self.run_samples(scene, target, cancelled),
            Stage::Reprojected => true,
        }
    }

    /// The block level just cast refined at its edges ([`super::edges`]):
    /// the pixels of the blocks chosen cast into `preview`. Returns
    /// `false`, refining none, if `cancelled()` turned true.
    fn refine_edges(&mut self, scene: &Lit, n: usize, cancelled: &(dyn Fn() -> bool + Sync)) -> bool {
        let (w, h) = (self.width as usize, self.height as usize);
        let grid = (w.div_ceil(n), h.div_ceil(n));
        let share = if n <= EDGE_BLOCK { self.edge_share } else { 0.0 };
        let cap = edges::cap(self.coarse.len(), n, share);
        let blocks = edges::edge_blocks(&self.coarse, grid, n, EDGE_CONTRAST, cap);
        let size = (self.width, self.height);
        match edges::cast_blocks(scene, size, n, (&blocks, &self.coarse), &mut self.preview, cancelled) {
            Some(cast) => {
                self.samples_cast += cast;
                self.edges = blocks;
                true
            }
            None => false,
        }
    }

    /// How many blocks the last block level refined at its edges (0 once
    /// samples or a reprojection replaced it).
    pub fn edge_blocks(&self) -> usize {
        self.blocks()
            .map_or(0, |((_, e), _, _)| e.map_or(0, |e| e.blocks.len()))
    }

    /// One sample in how many gathers caustic photons, at most, in
    /// `stage` from this picture for a frame thinned by `thin`
    /// (`Lit::thinned`): a stage of samples thins as `render` does (its
    /// top doubling stage's `thinning::stage_thinning`), an adaptive wave
    /// sample by sample the same (`thinning::sample_weight`; its choice
    /// reads the variance of groups, `render::adaptive`); block levels and
    /// reprojections never.
    pub fn stage_thinning(&self, stage: Stage, thin: u32) -> u32 {
        match stage {
            Stage::Samples(target) if target > self.spp => {
                let (from, to) = sample_stage(target - 1, target);
                stage_thinning(thin, from, to)
            }
            _ => 1,
        }
    }

    /// The photons `stage` from this picture traces for each its camera
    /// work affords unthinned, in a frame thinned by `thin`
    /// ([`Progressive::stage_thinning`]): `thinning::photon_factor`, or for
    /// an adaptive wave `thinning::wave_photon_factor`.
    pub fn stage_photons(&self, stage: Stage, thin: u32) -> f64 {
        let q = self.stage_thinning(stage, thin);
        if self.spp > 0 && self.sampling.adaptive.is_some() {
            wave_photon_factor(q)
        } else {
            photon_factor(q)
        }
    }

    /// A sample stage to `target` samples: the whole picture, or (adaptive,
    /// after the first sample) a wave over the pixels that need it. The
    /// sums are replaced only when the whole stage completes; a cancelled
    /// stage leaves them untouched.
    fn run_samples(&mut self, scene: &Lit, target: u32, cancelled: &(dyn Fn() -> bool + Sync)) -> bool {
        let from = self.spp;
        if target <= from {
            return true;
        }
        let (w, h) = (self.width as usize, self.height as usize);
        let mut next = std::mem::take(&mut self.next);
        let mut next_sq = std::mem::take(&mut self.next_sq);
        let mut next_count = std::mem::take(&mut self.next_count);
        let cast = match self.sampling.adaptive {
            Some(a) if from > 0 => {
                let old = Sums {
                    sum: &self.sum,
                    sq: (!self.sq_of_sum).then_some(&self.sq[..]),
                    count: &self.count,
                };
                let new = SumsMut {
                    sum: &mut next,
                    sq: &mut next_sq,
                    count: &mut next_count,
                };
                let key = (w, h, self.seed, self.sampling.pattern);
                a.wave(scene, key, target, (&old, new), &mut self.means, cancelled)
            }
            _ => self.every_pixel(
                scene,
                from,
                target,
                (&mut next, &mut next_sq, &mut next_count),
                cancelled,
            ),
        };
        let ok = cast.is_some();
        if ok {
            std::mem::swap(&mut self.sum, &mut next);
            std::mem::swap(&mut self.sq, &mut next_sq);
            std::mem::swap(&mut self.count, &mut next_count);
            if from == 0 {
                // A new picture: its first hits are recorded apart.
                self.first_ok = false;
            }
            self.spp = target;
            self.sq_of_sum = from == 0 && target == 1;
            self.reprojected = false;
            self.samples_cast += cast.unwrap_or(0);
        }
        (self.next, self.next_sq, self.next_count) = (next, next_sq, next_count);
        ok
    }

    /// Samples `from .. target` of every pixel into `next` (sample 0
    /// overwrites what it held; a later wave starts each band from a copy
    /// of the sums). Sample 0, when more samples follow, starts the sums of
    /// squares (a stage of one sample leaves them to the next wave:
    /// [`Progressive::sq_of_sum`]); later samples of this path leave those
    /// as they were (only adaptive waves read them). No first hits are
    /// written ([`Progressive::record_first_hits`]). Returns the samples
    /// cast, or `None` if cancelled.
    fn every_pixel(
        &mut self,
        scene: &Lit,
        from: u32,
        target: u32,
        (next, next_sq, next_count): (&mut [Rgb], &mut [[f32; 3]], &mut [u32]),
        cancelled: &(dyn Fn() -> bool + Sync),
    ) -> Option<u64> {
        let w = self.width as usize;
        let settings = RenderSettings {
            width: self.width,
            height: self.height,
            spp: target,
            seed: self.seed,
        };
        let (sum, pattern) = (&self.sum, self.sampling.pattern);
        let sq = (!self.sq_of_sum).then_some(&self.sq[..]);
        let bands = next.par_chunks_mut(w * BAND).zip(next_sq.par_chunks_mut(w * BAND));
        let ok = bands
            .zip(next_count.par_chunks_mut(w * BAND))
            .enumerate()
            .all(|(band, ((rows, sq_rows), counts))| {
                if cancelled() {
                    return false;
                }
                let start = band * BAND * w;
                if from > 0 {
                    let end = start + rows.len();
                    rows.copy_from_slice(&sum[start..end]);
                    copy_squares(sq_rows, sq.map(|q| &q[start..end]), &sum[start..end]);
                }
                let mut memory = BandMemory::default();
                let y0 = (band * BAND) as u32;
                for s in from..target {
                    // Thinned gathers as `render` thins them (`thinning`).
                    let lit = lit_for_sample(scene, s, target);
                    add_band_samples(&lit, y0, (s, pattern), &settings, &mut memory, rows);
                    if s == 0 && target > 1 {
                        copy_squares(sq_rows, None, rows);
                    }
                }
                counts.fill(target);
                true
            });
        ok.then(|| (target - from) as u64 * (w * self.height as usize) as u64)
    }

    /// The last block level's centres and pixels refined, their grid and
    /// the block size, while it is the picture (no samples, nothing
    /// reprojected since).
    fn blocks(&self) -> Option<(Centres<'_>, (usize, usize), usize)> {
        let (w, h, n) = (self.width as usize, self.height as usize, self.block);
        let exact = (!self.edges.is_empty()).then_some(Exact {
            blocks: &self.edges,
            pixels: &self.preview,
        });
        (self.spp == 0 && n > 1).then(|| ((&self.coarse[..], exact), (w.div_ceil(n), h.div_ceil(n)), n))
    }

    /// The current picture: the mean of the samples when there are any,
    /// else the block preview.
    pub fn image(&self) -> super::Image {
        let pixels = if self.spp > 0 {
            self.sum
                .par_iter()
                .zip(&self.count)
                .map(|(c, &n)| mean(*c, n))
                .collect()
        } else if let Some((coarse, size, n)) = self.blocks() {
            let mut pixels = vec![Rgb::ZERO; self.preview.len()];
            upsample(coarse, size, n, (self.width as usize, 1), &mut pixels, |c, o| o[0] = c);
            pixels
        } else {
            self.preview.clone()
        };
        super::Image {
            width: self.width,
            height: self.height,
            pixels,
        }
    }

    /// The current picture as 8-bit sRGB RGBA (for a framebuffer) after
    /// `tone`, written into `out` (resized as needed).
    pub fn write_rgba8(&self, out: &mut Vec<u8>, tone: Tone) {
        let n = self.width as usize * self.height as usize;
        out.resize(n * 4, 255);
        let srgb = Toned::new(tone);
        // Chunks of pixels, not single pixels, per parallel task: at a
        // million tiny tasks rayon's splitting costs more than the work.
        const CHUNK: usize = 4096;
        if let Some((coarse, size, n)) = self.blocks() {
            let put = |c, o: &mut [u8]| o.copy_from_slice(&srgb.rgba(c));
            return upsample(coarse, size, n, (self.width as usize, 4), out, put);
        }
        if self.spp == 0 {
            return out
                .par_chunks_mut(4 * CHUNK)
                .zip(self.preview.par_chunks(CHUNK))
                .for_each(|(o, cs)| {
                    for (o, c) in o.chunks_exact_mut(4).zip(cs) {
                        o.copy_from_slice(&srgb.rgba(*c));
                    }
                });
        }
        out.par_chunks_mut(4 * CHUNK)
            .zip(self.sum.par_chunks(CHUNK))
            .zip(self.count.par_chunks(CHUNK))
            .for_each(|((o, cs), ns)| {
                for ((o, c), &n) in o.chunks_exact_mut(4).zip(cs).zip(ns) {
                    o.copy_from_slice(&srgb.rgba(mean(*c, n)));
                }
            });
    }
}

/// The sRGB table after a tone: the table alone for the identity (the
/// frames of today's default, bit for bit).
#[derive(Clone, Copy)]
struct Toned {
    srgb: Srgb8,
    tone: Option<Tone>,
}

impl Toned {
    fn new(tone: Tone) -> Toned {
        Toned {
            srgb: Srgb8::table(),
            tone: (!tone.is_identity()).then_some(tone),
        }
    }

    #[inline]
    fn rgba(self, c: Rgb) -> [u8; 4] {
        match self.tone {
            None => self.srgb.rgba(c),
            Some(t) => self.srgb.rgba(t.apply(c)),
        }
    }
}

/// The mean of `n` samples summing to `sum` (the product with `1/n`, as
/// every frame has always been computed).
#[inline]
pub(super) fn mean(sum: Rgb, n: u32) -> Rgb {
    sum * (1.0 / n.max(1) as f64)
}

#[cfg(test)]
mod tests;
