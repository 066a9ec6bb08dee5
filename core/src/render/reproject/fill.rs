//! Step 3 of a reprojection: the pixels [`super::warp`] left are traced,
//! each at its centre or, to save time, once per block of a coarser level
//! with the holes between block centres interpolated.

use crate::color::Rgb;
use crate::integrator::Lit;
use crate::render::sparse::{Batch, FirstHit, Seen};
use crate::render::upsample::axis;
use crate::simd::LANES;
use crate::trace::TILE;
use rayon::prelude::*;

/// Traces the pixels [`super::warp`] left ([`Seen::Unknown`]): at their
/// centres when `block` is 1 (they get their first hits too), else one
/// sample at the centre of each `block × block` block holding some (the
/// point a block level samples), from which they are interpolated.
/// Returns the samples cast.
pub fn fill<'a>(
    scene: impl Into<Lit<'a>>,
    (w, h): (u32, u32),
    block: u32,
    out: &mut [Rgb],
    first: &mut [FirstHit],
) -> u64 {
    let lit = scene.into();
    let scene = &lit;
    if block <= 1 {
        return pixels(scene, (w, h), out, first);
    }
    let n = block as usize;
    let (wu, hu) = (w as usize, h as usize);
    let (bw, bh) = (wu.div_ceil(n), hu.div_ceil(n));
    let mut coarse = vec![None; bw * bh];
    let first = &*first;
    let cast = coarse
        .par_chunks_mut(bw)
        .enumerate()
        .map(|(by, coarse)| {
            let rows = &first[by * n * wu..((by + 1) * n).min(hu) * wu];
            let is_hole = |bx: usize| {
                rows.chunks(wu).any(|r| {
                    r[bx * n..((bx + 1) * n).min(wu)]
                        .iter()
                        .any(|f| f.seen() == Seen::Unknown)
                })
            };
            let mut sink = |bx: u32, c: Rgb, _: &dyn Fn() -> FirstHit| coarse[bx as usize] = Some(c);
            let mut batch = Batch::default();
            let y = (by * n + n / 2).min(hu - 1) as f64 + 0.5;
            let mut cast = 0;
            for bx in (0..bw).filter(|&bx| is_hole(bx)) {
                let x = (bx * n + n / 2).min(wu - 1) as f64 + 0.5;
                batch.push(scene, (w, h), (x, y), bx as u32, &mut sink);
                cast += 1;
            }
            batch.flush(scene, (w, h), &mut sink);
            cast
        })
        .sum();
    out.par_chunks_mut(wu)
        .zip(first.par_chunks(wu))
        .enumerate()
        .for_each(|(y, (row, first))| {
            for (x, (o, f)) in row.iter_mut().zip(first).enumerate() {
                if f.seen() == Seen::Unknown {
                    *o = interpolate(&coarse, (bw, bh), n, (x, y));
                }
            }
        });
    cast
}

/// Bilinear between the traced block centres around pixel `(x, y)` (its
/// own block's is always one of them), placed as [`axis`] places them.
fn interpolate(coarse: &[Option<Rgb>], (bw, bh): (usize, usize), n: usize, (x, y): (usize, usize)) -> Rgb {
    let (x0, x1, fx) = axis(x, n, bw);
    let (y0, y1, fy) = axis(y, n, bh);
    let (mut sum, mut weight) = (Rgb::ZERO, 0.0);
    for (by, wy) in [(y0, 1.0 - fy), (y1, fy)] {
        for (bx, wx) in [(x0, 1.0 - fx), (x1, fx)] {
            if let Some(c) = coarse[by * bw + bx] {
                sum += c * (wx * wy);
                weight += wx * wy;
            }
        }
    }
    if weight > 0.0 {
        sum / weight
    } else {
        coarse[(y / n) * bw + x / n].unwrap_or(Rgb::ZERO)
    }
}

/// [`fill`] at each hole's centre, in bands of [`TILE`] rows.
fn pixels(scene: &Lit, (w, h): (u32, u32), out: &mut [Rgb], first: &mut [FirstHit]) -> u64 {
    let wu = w as usize;
    out.par_chunks_mut(wu * TILE)
        .zip(first.par_chunks_mut(wu * TILE))
        .enumerate()
        .map(|(band, (rows, first))| {
            let rows_here = rows.len() / wu;
            // By columns of a packet's width, as the tiles go.
            let per_column =
                |x0: usize| (0..rows_here).flat_map(move |r| (x0..(x0 + LANES).min(wu)).map(move |x| r * wu + x));
            let dst: Vec<u32> = (0..wu)
                .step_by(LANES)
                .flat_map(per_column)
                .filter(|&i| first[i].seen() == Seen::Unknown)
                .map(|i| i as u32)
                .collect();
            let mut sink = |d: u32, c: Rgb, f: &dyn Fn() -> FirstHit| (rows[d as usize], first[d as usize]) = (c, f());
            let mut batch = Batch::default();
            for &d in &dst {
                let (x, y) = (d as usize % wu, band * TILE + d as usize / wu);
                batch.push(scene, (w, h), (x as f64 + 0.5, y as f64 + 0.5), d, &mut sink);
            }
            batch.flush(scene, (w, h), &mut sink);
            dst.len() as u64
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A hole between traced block centres gets their bilinear blend; a
    /// missing centre (a block without holes) is left out of the weights;
    /// at a centre, that centre's colour.
    #[test]
    fn holes_between_block_centres_are_interpolated() {
        let (a, b, c) = (Rgb::splat(0.2), Rgb::splat(0.6), Rgb::splat(1.0));
        // 2 × 2 blocks of 4 pixels: centres at pixels 2 and 6.
        let coarse = [Some(a), Some(b), Some(c), None];
        let at = |x, y| interpolate(&coarse, (2, 2), 4, (x, y));
        assert_eq!(at(2, 2), a);
        assert_eq!(at(6, 2), b);
        assert!((at(4, 2) - (a + b) * 0.5).abs().max_element() < 1e-12);
        // Between all four, the missing one weighs nothing.
        assert!((at(4, 4) - (a + b + c) / 3.0).abs().max_element() < 1e-12);
    }
}
