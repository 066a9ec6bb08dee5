//! A coarse level's samples drawn at full resolution: each pixel the
//! bilinear blend of the block centres around it, not its block's flat
//! colour. For the same samples the picture is much nearer the converged
//! one (cubes.toml against 16 spp, docs/performance.md round 15: 2×2
//! blocks 44.5 → 48.3 dB at 1280×720), so a fresh coarse level is worth
//! showing where a reprojection would cost more.
//!
//! Block `b` of `n` pixels is sampled at pixel `b·n + n/2` (its centre, or
//! the pixel just past it for even `n`), so along an axis pixel `p` lies
//! at `(p − n/2) / n` in units of blocks from the first block's centre.

use super::edges::Exact;
use super::sparse::Batch;
use crate::color::Rgb;
use crate::integrator::Lit;
use crate::simd::LANES;
use crate::trace::TILE;
use rayon::prelude::*;

/// One camera sample at the centre of each `n × n` block of a `w × h`
/// picture into `coarse` (`⌈w/n⌉ × ⌈h/n⌉`, row-major), in tiles of
/// [`TILE`] packets down as many rows of blocks (as full frames cast them:
/// a packet per row cast alone cost about a third more a sample; through a
/// lens camera [`Batch`] casts a packet at a time); each sample what
/// [`super::sample`] (or [`super::sample_packet`]) gives it. Returns `false`, with some
/// centres left, if `cancelled()` turned true.
pub(crate) fn block_centres(
    scene: &Lit,
    (w, h): (u32, u32),
    n: usize,
    coarse: &mut [Rgb],
    cancelled: &(dyn Fn() -> bool + Sync),
) -> bool {
    let (wu, hu) = (w as usize, h as usize);
    let bw = wu.div_ceil(n);
    let centre = |b: usize, len: usize| (b * n + n / 2).min(len - 1) as f64 + 0.5;
    coarse.par_chunks_mut(bw * TILE).enumerate().all(|(band, centres)| {
        if cancelled() {
            return false;
        }
        let rows = centres.len() / bw;
        let mut sink = |d: u32, c: Rgb, _: &dyn Fn() -> _| centres[d as usize] = c;
        let mut batch = Batch::default();
        for b0 in (0..bw).step_by(LANES) {
            for r in 0..rows {
                let y = centre(band * TILE + r, hu);
                for bx in b0..(b0 + LANES).min(bw) {
                    batch.push(scene, (w, h), (centre(bx, wu), y), (r * bw + bx) as u32, &mut sink);
                }
            }
        }
        batch.flush(scene, (w, h), &mut sink);
        true
    })
}

/// Where pixel `p` lies along an axis of `len` blocks of `n` pixels: the
/// block centres before and after it (clamped to the picture: before the
/// first centre and past the last both are the end one) and the weight of
/// the second.
#[inline]
pub(crate) fn axis(p: usize, n: usize, len: usize) -> (usize, usize, f64) {
    let g = (p as f64 - (n / 2) as f64) / n as f64;
    let g0 = g.floor();
    let last = len.saturating_sub(1) as f64;
    (
        g0.clamp(0.0, last) as usize,
        (g0 + 1.0).clamp(0.0, last) as usize,
        g - g0,
    )
}

/// `a` and `b` blended with weight `f` on `b` (a weight of 0 gives `a`
/// itself, whatever `b` holds).
#[inline(always)]
fn lerp(a: Rgb, b: Rgb, f: f64) -> Rgb {
    if f == 0.0 { a } else { a * (1.0 - f) + b * f }
}

/// Every pixel of `out` (`w` wide, rows of `n`-pixel blocks) from the
/// block centres `coarse` (`bw × bh`, row-major), each pixel `per` items
/// of `out` that `put` writes from the blended colour: first down the
/// column between the two rows of centres around the pixel's row, then
/// along the row (the four weights are separable, so this is the bilinear
/// blend, rounded in that order).
/// The pixels of the blocks in `exact` (a level refined at its edges:
/// [`super::edges`]) are its pixels instead.
/// Written straight into a frame's 8-bit pixels, a preview costs no
/// full-size linear copy (at 1280×720 that copy doubled the time from a
/// change to the first 8×8 frame).
pub fn upsample<T: Send>(
    (coarse, exact): (&[Rgb], Option<Exact>),
    (bw, bh): (usize, usize),
    n: usize,
    (w, per): (usize, usize),
    out: &mut [T],
    put: impl Fn(Rgb, &mut [T]) + Sync,
) {
    if w == 0 || per == 0 || bw == 0 || bh == 0 {
        return;
    }
    let cols: Vec<(usize, usize, f64)> = (0..w).map(|x| axis(x, n, bw)).collect();
    out.par_chunks_mut(w * per).enumerate().for_each_init(
        || Vec::with_capacity(bw),
        |line: &mut Vec<Rgb>, (y, row)| {
            let (y0, y1, fy) = axis(y, n, bh);
            let (r0, r1) = (&coarse[y0 * bw..(y0 + 1) * bw], &coarse[y1 * bw..(y1 + 1) * bw]);
            line.clear();
            line.extend(r0.iter().zip(r1).map(|(&a, &b)| lerp(a, b, fy)));
            for (o, &(x0, x1, fx)) in row.chunks_exact_mut(per).zip(&cols) {
                put(lerp(line[x0], line[x1], fx), o);
            }
            if let Some(e) = exact {
                // The refined blocks of this row of blocks.
                let first = (y / n * bw) as u32;
                let lo = e.blocks.partition_point(|&b| b < first);
                let hi = e.blocks.partition_point(|&b| b < first + bw as u32);
                let px = &e.pixels[y * w..(y + 1) * w];
                for &b in &e.blocks[lo..hi] {
                    let xs = (b - first) as usize * n..((b - first) as usize * n + n).min(w);
                    for (o, &c) in row[xs.start * per..xs.end * per].chunks_exact_mut(per).zip(&px[xs]) {
                        put(c, o);
                    }
                }
            }
        },
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Pixels are placed between the centres as the block levels sample
    /// them; the ends clamp to the end centres.
    #[test]
    fn pixels_lie_between_the_centres_around_them() {
        // 4-pixel blocks, 3 of them: centres at pixels 2, 6, 10.
        assert_eq!(axis(2, 4, 3), (0, 1, 0.0));
        assert_eq!(axis(4, 4, 3), (0, 1, 0.5));
        assert_eq!(axis(9, 4, 3), (1, 2, 0.75));
        assert_eq!(axis(10, 4, 3), (2, 2, 0.0));
        assert_eq!(axis(11, 4, 3), (2, 2, 0.25));
        // Before the first centre both are the first.
        assert_eq!(axis(0, 4, 3), (0, 0, 0.5));
        // Odd blocks: centre at the middle pixel.
        assert_eq!(axis(1, 3, 2), (0, 1, 0.0));
        assert_eq!(axis(3, 3, 2), (0, 1, 2.0 / 3.0));
    }

    /// Every pixel is the bilinear blend of the four centres around it;
    /// a centre's own pixel is its colour exactly, even beside a colour a
    /// blend would turn into NaN.
    #[test]
    fn each_pixel_is_the_bilinear_blend_of_the_centres_around_it() {
        let (bw, bh, n) = (3, 2, 4);
        let (w, h) = (11, 7);
        let coarse: Vec<Rgb> = (0..bw * bh)
            .map(|i| Rgb::new(i as f64, (i * i) as f64, 1.0 / (1.0 + i as f64)))
            .collect();
        let mut out = vec![Rgb::ZERO; w * h];
        upsample((&coarse, None), (bw, bh), n, (w, 1), &mut out, |c, o| o[0] = c);
        for y in 0..h {
            for x in 0..w {
                let (x0, x1, fx) = axis(x, n, bw);
                let (y0, y1, fy) = axis(y, n, bh);
                let c = |bx: usize, by: usize| coarse[by * bw + bx];
                let want = (c(x0, y0) * (1.0 - fx) + c(x1, y0) * fx) * (1.0 - fy)
                    + (c(x0, y1) * (1.0 - fx) + c(x1, y1) * fx) * fy;
                assert!((out[y * w + x] - want).abs().max_element() < 1e-12, "({x}, {y})");
            }
        }
        assert_eq!(out[2 * w + 6], coarse[1]);
        assert_eq!(out[6 * w + 10], coarse[5]);
        let mut inf = coarse.clone();
        inf[1] = Rgb::splat(f64::INFINITY);
        upsample((&inf, None), (bw, bh), n, (w, 1), &mut out, |c, o| o[0] = c);
        assert_eq!(out[2 * w + 2], coarse[0]);
    }
}
