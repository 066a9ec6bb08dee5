//! The Whitted tree of a pass through the lens: at every crossing of a face
//! from inside, the share `1 − R` (Fresnel) leaves as a ray out and the
//! share `R` is reflected on inside (all of it under total internal
//! reflection). Inside the glass the tree is a chain: each crossing sends
//! one ray out and one on, so the pass is a loop ([`Lens::branches_inside`])
//! that hands each ray out to the caller in order. A branch is dropped
//! when its weight falls to a [`Pruning`]'s bound or the chain reaches its
//! most reflections; what is dropped is returned, so that the weights out
//! and the weight dropped sum to the weight in.
//!
//! The renderer's packets take the first exit from [`Lens::exit_lanes`]
//! and go on from there with [`Lens::reflect_inside`] and
//! [`Lens::branch_chain`]: the very steps of the loop.

use super::trace::MAX_INTERNAL_REFLECTIONS;
use super::{Lens, LensSurface};
use crate::math::renormalize;
use crate::optics;
use glam::DVec3;

/// One ray out of the lens in the tree of a pass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LensBranch {
    /// The face left through.
    pub face: LensSurface,
    /// The exit point, world coordinates.
    pub point: DVec3,
    /// The refracted direction out of the glass (unit).
    pub dir: DVec3,
    /// The face's outward unit normal at the exit point.
    pub normal: DVec3,
    /// The share of the light that entered which leaves along this ray:
    /// the product of the reflectances of the crossings before it (1 for a
    /// total reflection) and of the transmission `1 − R` of its own.
    pub weight: f64,
    /// Reflections inside before this exit, total and partial.
    pub reflections: u32,
}

/// Where a chain of reflections inside stands: the local point `x` on a face
/// (or the entry point), the unit direction `u` on from it, the weight still
/// inside and the reflections so far.
#[derive(Clone, Copy, Debug)]
pub struct Inside {
    pub x: DVec3,
    pub u: DVec3,
    pub weight: f64,
    pub reflections: u32,
}

impl Inside {
    /// The weight that leaves as a ray out at a crossing of reflectance `r`
    /// (not a total reflection).
    #[inline(always)]
    pub fn out_weight(&self, r: f64) -> f64 {
        self.weight * (1.0 - r)
    }

    /// The weight that a crossing of reflectance `r` reflects on inside.
    #[inline(always)]
    pub fn on_weight(&self, r: f64) -> f64 {
        self.weight * r
    }
}

/// When a branch is dropped: a ray out or the light reflected on is kept
/// while `scale · weight > min`, and the chain stops after
/// `max_reflections` reflections inside (at most
/// [`MAX_INTERNAL_REFLECTIONS`]). The renderer's `scale` is the path weight
/// of the ray that entered.
///
/// In a lens system of more than two surfaces (not a singlet or the
/// biconvex lens, whose few ghosts are followed exactly) a ghost, the light reflected a second time or more, kept by
/// `min` but lighter than `roulette`, plays Russian roulette where it is
/// reflected: it is followed with probability `scale · weight / roulette`,
/// carrying the weight `roulette / scale`, so the expected light is the
/// same and the ghosts of many surfaces, whose number grows with the square
/// of the surfaces, cost little (`LensSystem::branches`). 0 turns it off.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pruning {
    pub scale: f64,
    pub min: f64,
    pub max_reflections: u32,
    pub roulette: f64,
}

impl Pruning {
    /// Nothing dropped for its weight; the most reflections followed.
    pub const NONE: Pruning = Pruning {
        scale: 1.0,
        min: 0.0,
        max_reflections: MAX_INTERNAL_REFLECTIONS,
        roulette: 0.0,
    };

    /// Whether a branch of weight `w` is followed.
    #[inline(always)]
    pub fn keeps(&self, w: f64) -> bool {
        self.scale * w > self.min
    }

    /// Whether the light reflected on inside with weight `w`, after
    /// `reflections` reflections before this one, is followed.
    #[inline(always)]
    pub fn keeps_on(&self, w: f64, reflections: u32) -> bool {
        self.keeps(w) && reflections < self.max_reflections.min(MAX_INTERNAL_REFLECTIONS)
    }
}

impl Lens {
    /// Every ray out of the lens for light that has just refracted in at the
    /// world point `x` along the unit `u` (index `n`), in the order the
    /// chain meets them, each handed to `emit`. Returns the weight dropped
    /// (rays out and light inside below the bound, the rest after the most
    /// reflections): with the weights handed out it sums to 1.
    pub fn branches_inside(
        &self,
        x: DVec3,
        u: DVec3,
        n: f64,
        prune: &Pruning,
        emit: &mut impl FnMut(LensBranch),
    ) -> f64 {
        let start = Inside {
            x: x - self.center,
            u,
            weight: 1.0,
            reflections: 0,
        };
        self.branch_chain(start, n, prune, emit)
    }

    /// [`Lens::branches_inside`] from a point of the chain.
    #[inline(always)]
    pub fn branch_chain(&self, mut s: Inside, n: f64, prune: &Pruning, emit: &mut impl FnMut(LensBranch)) -> f64 {
        let mut dropped = 0.0;
        loop {
            let e = self.exit_step(self.caps, s.x, s.u, n);
            if !e.found {
                return dropped + s.weight;
            }
            let c = e.crossing;
            let reflectance = if c.total {
                1.0
            } else {
                let out = s.out_weight(c.reflectance);
                if prune.keeps(out) {
                    emit(LensBranch {
                        face: LensSurface::from_part(e.face as u8),
                        point: self.center + e.y,
                        dir: c.dir,
                        normal: e.normal,
                        weight: out,
                        reflections: s.reflections,
                    });
                } else {
                    dropped += out;
                }
                c.reflectance
            };
            if let Err(lost) = self.reflect_inside(&mut s, e.y, e.normal, reflectance, prune) {
                return dropped + lost;
            }
        }
    }

    /// One ray out of the chain from `s`, drawn as a photon travels it: at
    /// each exit the light leaves with the probability of the crossing's
    /// transmittance or is reflected on (Russian roulette on the Fresnel
    /// split, `draw()` uniform in [0, 1)), keeping its whole weight, so that
    /// each ray of [`Lens::branch_chain`] (none pruned) comes out with the
    /// probability of its weight there, for one exit step a ray instead of
    /// the whole chain. `None` when the light is lost: no exit found, or
    /// reflected more than [`MAX_INTERNAL_REFLECTIONS`] times.
    pub fn walk_chain(&self, mut s: Inside, n: f64, mut draw: impl FnMut() -> f64) -> Option<LensBranch> {
        loop {
            let e = self.exit_step(self.caps, s.x, s.u, n);
            if !e.found {
                return None;
            }
            let c = e.crossing;
            if !c.total && draw() >= c.reflectance {
                return Some(LensBranch {
                    face: LensSurface::from_part(e.face as u8),
                    point: self.center + e.y,
                    dir: c.dir,
                    normal: e.normal,
                    weight: s.weight,
                    reflections: s.reflections,
                });
            }
            let u = s.u;
            Self::reflect_on(&mut s, e.y, 1.0, &Pruning::NONE, || Self::reflected_inside(u, e.normal)).ok()?;
        }
    }

    /// The light of `s` that a crossing at the local point `y` (outward unit
    /// normal `normal`, reflectance `r`) reflects on inside: `s` moves to it,
    /// or, when it is dropped, `Err` with its weight.
    #[inline(always)]
    pub fn reflect_inside(&self, s: &mut Inside, y: DVec3, normal: DVec3, r: f64, prune: &Pruning) -> Result<(), f64> {
        let u = s.u;
        Self::reflect_on(s, y, r, prune, || Self::reflected_inside(u, normal))
    }

    /// The unit direction on from a reflection inside, of the unit `u` off a
    /// face of outward unit normal `normal`: [`Lens::reflect_inside`]'s, for a
    /// caller that has computed it beforehand (the packets' lanes).
    #[inline(always)]
    pub fn reflected_inside(u: DVec3, normal: DVec3) -> DVec3 {
        renormalize(optics::reflect(u, normal))
    }

    /// [`Lens::reflect_inside`] with the direction on given by `on` (asked
    /// for only when the light is followed).
    #[inline(always)]
    pub fn reflect_on(
        s: &mut Inside,
        y: DVec3,
        r: f64,
        prune: &Pruning,
        on: impl FnOnce() -> DVec3,
    ) -> Result<(), f64> {
        let w = s.on_weight(r);
        if !prune.keeps_on(w, s.reflections) {
            return Err(w);
        }
        s.weight = w;
        s.reflections += 1;
        s.u = on();
        s.x = y;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::Index;

    /// A total internal reflection carries the whole weight on, and a ray
    /// out is never below its bound.
    #[test]
    fn total_reflections_keep_the_weight_and_the_bound_holds() {
        let l = Lens::new(DVec3::ZERO, DVec3::Z, 2.0, 5.0, 5.0, Index::Constant(4.0)).unwrap();
        let prune = Pruning {
            scale: 0.5,
            min: 1e-3,
            max_reflections: 40,
            roulette: 0.0,
        };
        let mut outs = Vec::new();
        let dropped = l.branches_inside(
            DVec3::ZERO,
            DVec3::new(1.0, 0.0, 0.05).normalize(),
            4.0,
            &prune,
            &mut |b| outs.push(b),
        );
        assert!(!outs.is_empty());
        assert!(outs[0].reflections >= 1, "{outs:?}");
        for b in &outs {
            assert!(prune.keeps(b.weight));
        }
        let sum: f64 = outs.iter().map(|b| b.weight).sum();
        assert!((sum + dropped - 1.0).abs() < 1e-12, "{sum} + {dropped}");
    }

    /// A photon's walk leaves by each ray of the chain as often as the
    /// chain weighs it: with a high index (reflections inside, total
    /// ones among them, before four rays out of weight over 1 %) the share of 200 000 walks out after `k`
    /// reflections inside matches the chain's weight of its rays out after
    /// `k`, within five standard deviations.
    #[test]
    fn a_walk_leaves_by_each_ray_as_often_as_the_chain_weighs_it() {
        let l = Lens::new(DVec3::ZERO, DVec3::Z, 2.0, 1.5, 1.5, Index::Constant(3.5)).unwrap();
        let (x, u) = (DVec3::new(0.3, 0.1, 0.0), DVec3::new(0.4, -0.2, 1.0).normalize());
        let start = Inside {
            x,
            u,
            weight: 1.0,
            reflections: 0,
        };
        let mut want = [0.0; MAX_INTERNAL_REFLECTIONS as usize + 1];
        l.branch_chain(start, 3.5, &Pruning::NONE, &mut |b| {
            want[b.reflections as usize] += b.weight
        });
        assert!(want.iter().filter(|&&w| w > 0.01).count() >= 4, "{want:?}");
        let mut rng = crate::sampling::Sampler::new(5, 6, 7);
        let walks = 200_000;
        let mut got = [0.0; MAX_INTERNAL_REFLECTIONS as usize + 1];
        for _ in 0..walks {
            if let Some(b) = l.walk_chain(start, 3.5, || rng.next_f64()) {
                assert_eq!(b.weight, 1.0);
                got[b.reflections as usize] += 1.0 / walks as f64;
            }
        }
        for (k, (g, w)) in got.iter().zip(&want).enumerate() {
            let sigma = (w * (1.0 - w) / walks as f64).sqrt();
            assert!(
                (g - w).abs() <= 5.0 * sigma + 1e-12,
                "after {k}: {g} vs {w} (σ {sigma})"
            );
        }
    }
}
