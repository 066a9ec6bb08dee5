//! Adaptive sample waves: after every pixel has its centre sample, a wave
//! refines only the pixels that still need it — those that differ from a
//! neighbour by more than a contrast threshold (Whitted 1980: an edge, a
//! silhouette, the lens rim, a colour fringe) or whose mean still has a
//! large estimated error (the standard error from the samples' variance).
//! A pixel left out keeps its samples; later waves look at it again.
//!
//! The decision reads only the picture before the wave, and a pixel's
//! samples are its fixed samples `count ..` in order, so an adaptive image
//! is the same on any number of threads.

use super::sparse::{Batch, FirstHit};
use super::thinning::{observations, sample_stage, sample_weight, stage_thinning};
use super::{LensBatch, RenderSettings};
use crate::color::Rgb;
use crate::integrator::Lit;
use crate::sampling::{Pattern, pixel_offset};
use crate::simd::LANES;
use crate::trace::TILE;
use rayon::prelude::*;

/// When a pixel is refined further (values in linear light, channels
/// clamped to [0, 1], the units of the error `converge` measures).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Adaptive {
    /// A pixel whose mean differs from one of its eight neighbours' by more
    /// than this in some channel is refined.
    pub contrast: f64,
    /// A pixel with two samples or more whose mean's standard error exceeds
    /// this in some channel is refined.
    pub error: f64,
}

impl Default for Adaptive {
    /// Measured on `scenes/cubes.toml` (docs/performance.md, issue #21).
    fn default() -> Adaptive {
        Adaptive {
            contrast: 0.004,
            error: 0.002,
        }
    }
}

/// The running sums of a picture: per pixel the sum of its samples, the sum
/// of their squares and their count.
pub(super) struct Sums<'a> {
    pub sum: &'a [Rgb],
    /// `None` while every pixel has one sample: each square is then the
    /// square of the sum ([`square`]), left for the wave that reads it to
    /// compute, so that the first sample stage writes no squares.
    pub sq: Option<&'a [[f32; 3]]>,
    pub count: &'a [u32],
}

/// The square of one sample, as the sums of squares hold it.
#[inline]
pub(super) fn square(c: Rgb) -> [f32; 3] {
    (c * c).as_vec3().to_array()
}

/// Copies the squares of `sq` into `dst`, or with `None` (one sample per
/// pixel) writes the squares of the sums `sum` (as long as `dst`).
pub(super) fn copy_squares(dst: &mut [[f32; 3]], sq: Option<&[[f32; 3]]>, sum: &[Rgb]) {
    match sq {
        Some(sq) => dst.copy_from_slice(sq),
        None => {
            for (q, c) in dst.iter_mut().zip(sum) {
                *q = square(*c);
            }
        }
    }
}

/// The means a wave compares, clamped to [0, 1], as `f32` (computed once
/// per wave, not once per neighbour).
type Means = [[f32; 3]];

/// The same, writable: the rows of one band.
pub(super) struct SumsMut<'a> {
    pub sum: &'a mut [Rgb],
    pub sq: &'a mut [[f32; 3]],
    pub count: &'a mut [u32],
}

impl Sums<'_> {
    /// Copies the sums of the pixels from `start` on into a band's `sum`,
    /// `sq` and `count` (as long as each other).
    fn copy_band(&self, start: usize, (sum, sq, count): (&mut [Rgb], &mut [[f32; 3]], &mut [u32])) {
        let end = start + sum.len();
        sum.copy_from_slice(&self.sum[start..end]);
        copy_squares(sq, self.sq.map(|q| &q[start..end]), &self.sum[start..end]);
        count.copy_from_slice(&self.count[start..end]);
    }

    /// Every pixel's mean, clamped, into `out`.
    fn means(&self, out: &mut Vec<[f32; 3]>) {
        out.resize(self.sum.len(), [0.0; 3]);
        const CHUNK: usize = 4096;
        out.par_chunks_mut(CHUNK)
            .zip(self.sum.par_chunks(CHUNK).zip(self.count.par_chunks(CHUNK)))
            .for_each(|(o, (s, n))| {
                for ((o, s), n) in o.iter_mut().zip(s).zip(n) {
                    *o = (*s / (*n).max(1) as f64)
                        .clamp(Rgb::ZERO, Rgb::ONE)
                        .as_vec3()
                        .to_array();
                }
            });
    }
}

impl Adaptive {
    /// Whether pixel `(x, y)` of a `w × h` picture is refined by a wave to
    /// `target` samples (`means`: [`Sums::means`]).
    ///
    /// Where the caustic gathers are thinned by `thin` the squares are
    /// those of groups ([`GroupSquares`]): the variance is that of the
    /// groups' means, and the standard error divides it by the number of
    /// groups ([`observations`]), not of samples. The groups are counted
    /// at the frame's thinning now: where an earlier wave thinned more
    /// (the radius shrinks as passes are added), a pixel counts a few
    /// more groups than it had, a slightly smaller error.
    fn wants(
        &self,
        s: &Sums,
        means: &Means,
        (w, h, thin): (usize, usize, u32),
        (x, y): (usize, usize),
        target: u32,
    ) -> bool {
        let i = y * w + x;
        let n = s.count[i];
        if n >= target {
            return false;
        }
        if n >= 2 {
            let nf = n as f64;
            let mf = observations(thin, n) as f64;
            debug_assert!(s.sq.is_some(), "squares of sums stand for one sample only");
            let q = s.sq.map_or_else(|| square(s.sum[i]), |sq| sq[i]);
            let sq = Rgb::new(q[0] as f64, q[1] as f64, q[2] as f64);
            let mean = s.sum[i] / nf;
            let var = ((sq / nf - mean * mean) * (mf / (mf - 1.0))).max(Rgb::ZERO);
            if (var / mf).max_element() > self.error * self.error {
                return true;
            }
        }
        let m = means[i];
        let t = self.contrast as f32;
        for y2 in y.saturating_sub(1)..(y + 2).min(h) {
            for q in &means[y2 * w + x.saturating_sub(1)..y2 * w + (x + 2).min(w)] {
                if (q[0] - m[0]).abs() > t || (q[1] - m[1]).abs() > t || (q[2] - m[2]).abs() > t {
                    return true;
                }
            }
        }
        false
    }

    /// One wave: every pixel [`Self::wants`] gets its samples `count ..
    /// target`, cast in tiles of the pixels of each 8 × [`TILE`] block.
    /// `old` is the picture before the wave; `new` (same size) receives
    /// the picture after it. Returns the samples cast, or `None` when
    /// `cancelled()` turned true (then `new` is partly written).
    pub(super) fn wave(
        &self,
        scene: &Lit,
        (w, h, seed, pattern): (usize, usize, u64, Pattern),
        target: u32,
        (old, new): (&Sums, SumsMut),
        means: &mut Vec<[f32; 3]>,
        cancelled: &(dyn Fn() -> bool + Sync),
    ) -> Option<u64> {
        old.means(means);
        let means = &means[..];
        // One sample in how many gathers, stage by stage (1 with a lens
        // camera or without caustics: `thinning`).
        let thin = scene.thin();
        let band = w * TILE;
        let size = (w as u32, h as u32);
        let settings = RenderSettings {
            width: size.0,
            height: size.1,
            spp: target,
            seed,
        };
        let bands = new.sum.par_chunks_mut(band).zip(new.sq.par_chunks_mut(band));
        bands
            .zip(new.count.par_chunks_mut(band))
            .enumerate()
            .map(|(b, ((sum, sq), count))| {
                if cancelled() {
                    return None;
                }
                old.copy_band(b * band, (sum, sq, count));
                let mut groups = GroupSquares::new(thin, target);
                // A pixel's samples come in the order pushed, one after the
                // other (`Batch`, `LensBatch`): its groups whole.
                let mut sink = |dst: u32, c: Rgb, _: &dyn Fn() -> FirstHit| {
                    let d = dst as usize;
                    sum[d] += c;
                    groups.add(&mut sq[d], count[d], c);
                    count[d] += 1;
                };
                let mut batch = Batch::default();
                let mut lens_batch = LensBatch::default();
                let mut cast = 0u64;
                let y0 = b * TILE;
                let rows = (h - y0).min(TILE);
                for x0 in (0..w).step_by(LANES) {
                    for y in y0..y0 + rows {
                        for x in x0..(x0 + LANES).min(w) {
                            if !self.wants(old, means, (w, h, thin), (x, y), target) {
                                continue;
                            }
                            let pixel = (y * w + x) as u64;
                            let dst = ((y - y0) * w + x) as u32;
                            for i in old.count[pixel as usize]..target {
                                if let Some(lens) = &scene.lens {
                                    // A lens camera's samples, eight at a
                                    // time, as the whole-picture stages
                                    // cast them (the same bits).
                                    let at = ((x as u32, y as u32), i, pattern);
                                    let mut to = |d: u32, c: Rgb| sink(d, c, &|| FirstHit::UNKNOWN);
                                    lens_batch.push(scene, lens, at, &settings, dst, &mut to);
                                } else {
                                    let (jx, jy) = pixel_offset(pattern, seed, pixel, i);
                                    let weight = if thin > 1 { sample_weight(thin, i, target).0 } else { 1 };
                                    let at = ((x as f64 + jx, y as f64 + jy), weight);
                                    batch.push_weighted(scene, size, at, dst, &mut sink);
                                }
                                cast += 1;
                            }
                        }
                    }
                }
                batch.flush(scene, size, &mut sink);
                if let Some(lens) = &scene.lens {
                    lens_batch.flush(scene, lens, size, &mut |d, c| sink(d, c, &|| FirstHit::UNKNOWN));
                }
                Some(cast)
            })
            .try_reduce(|| 0, |a, b| Some(a + b))
    }
}

/// The squares a wave adds to a pixel's sums (its samples in order): each
/// sample's square, or where its stage's gathers are thinned by `q`
/// (`thinning::sample_weight`), each group of `q` samples' (one gathering
/// for all, `q` times) as `q` samples at the group's mean (`S²/q` for the
/// group's sum `S`). A thinned sample alone is its light with `q` times the
/// caustic's or none: the squares of groups leave out that spread, which
/// no sample of the picture's mean has (its groups' means estimate it),
/// so a wave refines a pixel for its noise, not for its thinning.
struct GroupSquares {
    thin: u32,
    target: u32,
    /// The sum of the group's samples so far.
    group: Rgb,
}

impl GroupSquares {
    /// For a wave to `target` samples thinned by `thin`.
    fn new(thin: u32, target: u32) -> Self {
        GroupSquares {
            thin,
            target,
            group: Rgb::ZERO,
        }
    }

    /// Adds sample `i` of a pixel, of colour `c`, to its squares `sq`.
    #[inline(always)]
    fn add(&mut self, sq: &mut [f32; 3], i: u32, c: Rgb) {
        let (from, q) = if self.thin > 1 {
            let (from, to) = sample_stage(i, self.target);
            (from, stage_thinning(self.thin, from, to))
        } else {
            (0, 1)
        };
        let c2 = if q <= 1 {
            (c * c).as_vec3()
        } else {
            debug_assert!((i - from) % q != 0 || self.group == Rgb::ZERO, "a group left open");
            self.group += c;
            if (i - from + 1) % q != 0 {
                return;
            }
            let g = std::mem::replace(&mut self.group, Rgb::ZERO);
            (g * g / q as f64).as_vec3()
        };
        *sq = [sq[0] + c2.x, sq[1] + c2.y, sq[2] + c2.z];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A pixel of constant light whose stages from 4 samples on gather
    /// one sample in 4, counting 4 times (`thinning::sample_weight`): each
    /// sample's square would give it a large variance, which is the
    /// thinning's alone (as the waves read it before they thinned); the
    /// squares of groups give none, so a wave leaves it.
    #[test]
    fn groups_square_away_the_thinning() {
        let (d, caustic) = (Rgb::splat(0.3), Rgb::new(0.2, 0.1, 0.05));
        let a = Adaptive::default();
        let target = 64;
        let wants = |thin: u32, grouped: bool| {
            let mut g = GroupSquares::new(if grouped { thin } else { 1 }, target);
            let (mut sum, mut sq) = (Rgb::ZERO, [0.0f32; 3]);
            for i in 0..16 {
                let (w, _) = sample_weight(thin, i, target);
                let c = d + caustic * w as f64;
                sum += c;
                g.add(&mut sq, i, c);
            }
            assert_eq!(g.group, Rgb::ZERO, "whole groups");
            let sums = Sums {
                sum: &[sum],
                sq: Some(&[sq]),
                count: &[16],
            };
            let mean = (sum / 16.0).as_vec3().to_array();
            let off = (sum / 16.0 - (d + caustic)).abs().max_element();
            assert!(off < 1e-12, "the thinned mean is the caustic's: {sum}");
            let read = if grouped { thin } else { 1 };
            a.wants(&sums, &[mean], (1, 1, read), (0, 0), target)
        };
        assert!(!wants(1, true), "unthinned: no variance");
        assert!(!wants(4, true), "groups: no variance");
        assert!(wants(4, false), "each sample's square: the thinning's spread");
    }
}
