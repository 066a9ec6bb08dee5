//! A block level refined at its edges. The bilinear blend of the block
//! centres ([`super::upsample`]) smears an edge over the blocks between
//! centres that disagree; there the block's own pixels are cast at full
//! resolution, each at its centre (sample 0, what the first sample stage
//! gives the pixel, bit for bit; through a lens camera, at seed 0's pupil
//! point, as the centres are: [`super::sample_packet`]), and drawn as
//! they are.
//!
//! A block is refined when its contrast passes [`EDGE_CONTRAST`]: the
//! squared length of the range, per channel, of the centres its pixels
//! are blended from, clamped to [0, 1] as the error is measured. Of
//! those, the highest at most [`cap`], so that a scene of edges
//! everywhere adds no more than a fixed share of the level's samples.
//! The choice depends on the centres alone: the same on any number of
//! threads. On cubes.toml against 16 spp (docs/performance.md, round 16)
//! 2×2 blocks at 640×360 go from 44.9 to 46.7 dB refining 1.2 % of them.

use super::sparse::Batch;
use crate::color::Rgb;
use crate::integrator::Lit;
use crate::trace::TILE;
use rayon::prelude::*;

/// Block levels refined: blocks of up to this many pixels a side. A
/// coarser level is the first picture only where time is shortest, and
/// a refined block of it costs `n² − 1` samples (4×4 at 640×360: +1.2 dB
/// for half again the level's time).
pub const EDGE_BLOCK: usize = 2;

/// The share of a block level's samples that its refinement may add. At
/// 2×2 blocks 0.12 of the centres: 4 % of the blocks, 3 % of the pixels,
/// so that the level stays near a third of a 1-spp frame on any scene
/// (where edges are everywhere, a sample at one costs a frame's average).
pub const EDGE_SHARE: f64 = 0.12;

/// Contrast over which a block is refined (a range of 0.17 in one
/// channel, 0.1 in each). At 0.02 cubes.toml at 640×360 refines 1.8 % of
/// the blocks for 47.3 dB, but the level then takes about 0.36 of a 1-spp
/// frame (a sample at an edge costs 3–4 times a frame's average).
pub const EDGE_CONTRAST: f32 = 0.03;

/// The most blocks refined of `blocks` blocks of `n × n` pixels: each
/// casts `n² − 1` samples (its centre is cast), together at most `share`
/// of `blocks`.
pub fn cap(blocks: usize, n: usize, share: f64) -> usize {
    if n < 2 || share <= 0.0 {
        return 0;
    }
    (blocks as f64 * share / (n * n - 1) as f64) as usize
}

/// The blocks' own pixels, for the blocks refined: `blocks` (indices into
/// the grid of centres, ascending), whose pixels in `pixels` (the
/// picture's size, row-major) are drawn instead of the blend.
#[derive(Clone, Copy)]
pub struct Exact<'a> {
    pub blocks: &'a [u32],
    pub pixels: &'a [Rgb],
}

/// The blocks to refine among the centres `coarse` (`bw × bh`, row-major),
/// ascending: those whose contrast passes `threshold`, the `cap` highest
/// if more (ties: the first).
pub fn edge_blocks(coarse: &[Rgb], (bw, bh): (usize, usize), n: usize, threshold: f32, cap: usize) -> Vec<u32> {
    if cap == 0 || bw == 0 {
        return Vec::new();
    }
    // The centres a block's pixels are blended from ([`super::upsample::axis`]):
    // before and at its own, and after it for blocks over 2 pixels.
    let after = usize::from(n > 2);
    let scratch = || Scan::new(bw);
    let mut found: Vec<(f32, u32)> = (0..bh)
        .into_par_iter()
        .map_init(scratch, |scan, by| {
            let contrast = scan.contrast(coarse, (bw, bh), by, after);
            let passed = contrast.iter().enumerate().filter(|&(_, &k)| k > threshold);
            passed.map(|(bx, &k)| (k, (by * bw + bx) as u32)).collect::<Vec<_>>()
        })
        .flatten_iter()
        .collect();
    if found.len() > cap {
        found.select_nth_unstable_by(cap - 1, |a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        found.truncate(cap);
    }
    let mut blocks: Vec<u32> = found.into_iter().map(|(_, b)| b).collect();
    blocks.sort_unstable();
    blocks
}

/// The working rows of [`edge_blocks`]'s scan of one row of blocks.
struct Scan {
    lo: [Vec<f32>; 3],
    hi: [Vec<f32>; 3],
    row: [Vec<f32>; 3],
    t: Vec<f32>,
    contrast: Vec<f32>,
}

impl Scan {
    fn new(bw: usize) -> Self {
        let v = || vec![0f32; bw];
        Scan {
            lo: [v(), v(), v()],
            hi: [v(), v(), v()],
            row: [v(), v(), v()],
            t: v(),
            contrast: v(),
        }
    }

    /// The contrast of each block of row `by` of a `bw × bh` grid of
    /// centres: the range, per channel, of each column's centres (each
    /// row's channels first made contiguous `f32`, so that the ranges run
    /// in lanes), then of the neighbouring columns' (`after`: the next
    /// row's and column's too).
    fn contrast(&mut self, coarse: &[Rgb], (bw, bh): (usize, usize), by: usize, after: usize) -> &[f32] {
        let Scan {
            lo,
            hi,
            row,
            t,
            contrast,
        } = self;
        lo.iter_mut().for_each(|v| v.fill(1.0));
        hi.iter_mut().for_each(|v| v.fill(0.0));
        for y in by.saturating_sub(1)..(by + 1 + after).min(bh) {
            for (x, c) in coarse[y * bw..(y + 1) * bw].iter().enumerate() {
                for ch in 0..3 {
                    row[ch][x] = c[ch].clamp(0.0, 1.0) as f32;
                }
            }
            for ch in 0..3 {
                for ((l, h), &v) in lo[ch].iter_mut().zip(hi[ch].iter_mut()).zip(&row[ch]) {
                    (*l, *h) = (least(*l, v), most(*h, v));
                }
            }
        }
        contrast.fill(0.0);
        for ch in 0..3 {
            widen(&mut lo[ch], t, least, after);
            widen(&mut hi[ch], t, most, after);
            for ((k, l), h) in contrast.iter_mut().zip(lo[ch].iter()).zip(hi[ch].iter()) {
                *k += (h - l) * (h - l);
            }
        }
        contrast
    }
}

/// The smaller of two values: a plain compare, which vectorises (a NaN
/// centre, `clamp`'s NaN, passes as it falls).
#[inline(always)]
fn least(a: f32, b: f32) -> f32 {
    if b < a { b } else { a }
}

/// The larger of two values ([`least`]).
#[inline(always)]
fn most(a: f32, b: f32) -> f32 {
    if b > a { b } else { a }
}

/// Each of `v` combined by `f` with the one before it (and, with `after`,
/// the one after it); `t` is scratch of the same length.
#[inline]
fn widen(v: &mut [f32], t: &mut [f32], f: fn(f32, f32) -> f32, after: usize) {
    let len = v.len();
    t.copy_from_slice(v);
    for (a, &b) in v[1..].iter_mut().zip(&t[..len - 1]) {
        *a = f(*a, b);
    }
    if after > 0 {
        for (a, &b) in v[..len - 1].iter_mut().zip(&t[1..]) {
            *a = f(*a, b);
        }
    }
}

/// Every pixel of the `n × n` blocks `blocks` (ascending) of a `w × h`
/// picture into `exact` (its size, row-major), each at its centre: the
/// block's centre pixel is its centre `coarse[b]` (cast there already),
/// the others are cast as [`super::upsample::block_centres`] casts the
/// centres. Returns the samples cast, or `None` if `cancelled()` turned
/// true (some pixels left).
pub fn cast_blocks(
    scene: &Lit,
    (w, h): (u32, u32),
    n: usize,
    (blocks, coarse): (&[u32], &[Rgb]),
    exact: &mut [Rgb],
    cancelled: &(dyn Fn() -> bool + Sync),
) -> Option<u64> {
    let (wu, hu) = (w as usize, h as usize);
    if wu == 0 || blocks.is_empty() {
        return Some(0);
    }
    let bw = wu.div_ceil(n);
    let centre = |b: usize, len: usize| (b * n + n / 2).min(len - 1);
    // Rows of blocks a task: about a tile of pixel rows.
    let rows = (TILE / n).max(1);
    exact
        .par_chunks_mut(wu * n * rows)
        .enumerate()
        .map(|(task, px)| {
            if cancelled() {
                return None;
            }
            let first = task * rows * bw;
            let lo = blocks.partition_point(|&b| (b as usize) < first);
            let hi = blocks.partition_point(|&b| (b as usize) < first + rows * bw);
            let y0 = task * rows * n;
            let mut points = Vec::with_capacity((hi - lo) * n * n);
            for &b in &blocks[lo..hi] {
                let (bx, by) = (b as usize % bw, b as usize / bw);
                let c = (centre(bx, wu), centre(by, hu));
                for y in by * n..((by + 1) * n).min(hu) {
                    for x in bx * n..((bx + 1) * n).min(wu) {
                        let i = (y - y0) * wu + x;
                        if (x, y) == c {
                            px[i] = coarse[b as usize];
                        } else {
                            points.push(i as u32);
                        }
                    }
                }
            }
            cast(scene, (w, h), y0, &points, px);
            Some(points.len() as u64)
        })
        .sum()
}

/// Each pixel `points[k]` of `px` (rows from `y0` of a `w × h` picture)
/// at its centre.
fn cast(scene: &Lit, (w, h): (u32, u32), y0: usize, points: &[u32], px: &mut [Rgb]) {
    let wu = w as usize;
    let at = |i: u32| ((i as usize % wu) as f64 + 0.5, (y0 + i as usize / wu) as f64 + 0.5);
    let mut sink = |d: u32, c: Rgb, _: &dyn Fn() -> _| px[d as usize] = c;
    let mut batch = Batch::default();
    for &i in points {
        batch.push(scene, (w, h), at(i), i, &mut sink);
    }
    batch.flush(scene, (w, h), &mut sink);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A grid of centres, black but for the white ones.
    fn grid((bw, bh): (usize, usize), white: impl Fn(usize, usize) -> bool) -> Vec<Rgb> {
        (0..bw * bh)
            .map(|i| if white(i % bw, i / bw) { Rgb::ONE } else { Rgb::ZERO })
            .collect()
    }

    /// One white centre: the blocks blended from it pass, the rest not
    /// (2×2 blocks: its own and those after it; larger blocks: the 3 × 3
    /// around it); values past 1 count as 1.
    #[test]
    fn an_edge_is_where_the_centres_blended_disagree() {
        let (bw, bh) = (6, 5);
        let mut g = grid((bw, bh), |x, y| (x, y) == (2, 2));
        assert_eq!(edge_blocks(&g, (bw, bh), 2, 0.5, 100), [14, 15, 20, 21]);
        assert_eq!(
            edge_blocks(&g, (bw, bh), 4, 0.5, 100),
            [7, 8, 9, 13, 14, 15, 19, 20, 21]
        );
        // Contrast 3, a range of 1 in each channel, however bright.
        g[14] = Rgb::splat(50.0);
        assert_eq!(edge_blocks(&g, (bw, bh), 2, 2.999, 100).len(), 4);
        assert_eq!(edge_blocks(&g, (bw, bh), 2, 3.0, 100), Vec::<u32>::new());
        assert_eq!(edge_blocks(&g, (bw, bh), 2, 0.5, 0), Vec::<u32>::new());
        // A flat picture, however bright: none.
        assert!(edge_blocks(&vec![Rgb::splat(7.0); 30], (bw, bh), 2, 0.0, 100).is_empty());
    }

    /// A picture of edges everywhere (a checkerboard of centres) refines
    /// exactly the cap, the highest contrast first, ties by position.
    #[test]
    fn edges_everywhere_refine_no_more_than_the_cap() {
        let (bw, bh) = (75, 40);
        let g = grid((bw, bh), |x, y| (x + y) % 2 == 0);
        let k = cap(bw * bh, 2, EDGE_SHARE);
        assert_eq!(k, 120, "4 % of 3000 blocks");
        let picked = edge_blocks(&g, (bw, bh), 2, EDGE_CONTRAST, k);
        // Block 0 is blended from its centre alone.
        assert_eq!(picked, (1..=120).collect::<Vec<u32>>());
        // Lower contrast in the first rows: those blocks come last.
        let mut g = g;
        for c in &mut g[..bw * 3] {
            *c *= 0.5;
        }
        let picked = edge_blocks(&g, (bw, bh), 2, EDGE_CONTRAST, k);
        let from = 3 * bw as u32 + 1;
        assert_eq!(picked, (from..from + 120).collect::<Vec<u32>>());
        assert_eq!(cap(1000, 1, 1.0), 0);
        assert_eq!(cap(1000, 4, 0.0), 0);
        assert_eq!(cap(1500, 4, 0.5), 50);
    }
}
