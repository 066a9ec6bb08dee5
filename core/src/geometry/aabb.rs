//! Axis-aligned bounding boxes, used to skip objects a ray cannot reach.

use crate::math::Ray;
use crate::simd::{gmax, gmin};
use glam::{DMat3, DVec3};

/// The slack of every box test ([`slab_overlap`]): the exit distance is
/// stretched by four roundings, because rounding of the products may cut a
/// box that a ray just touches.
pub const BOX_PAD: f64 = 1.0 + 4.0 * f64::EPSILON;

/// Whether a ray's span `[lo, hi]` through a box's slabs is not empty, up
/// to [`BOX_PAD`].
#[inline(always)]
pub fn slab_overlap(lo: f64, hi: f64) -> bool {
    lo <= hi * BOX_PAD
}

/// Slab test of the box `[min, max]` for the ray from `o` with reciprocal
/// direction `inv`: whether it meets the box inside `(t_min, t_max)`. The
/// one box test of the crate: [`Aabb::hit`], the BVH's walk, and (lane by
/// lane) the packet walks call it.
///
/// A NaN from 0·∞ (ray in a slab's plane) makes glam's min/max and
/// [`gmin`]/[`gmax`] pick the other operand, so such a ray is
/// conservatively kept. `gmax(x, t_min)` is `f64::max` for every `x`, NaN
/// included, up to the sign of a zero, which no comparison sees.
#[inline(always)]
pub fn slab_hit(min: DVec3, max: DVec3, o: DVec3, inv: DVec3, t_min: f64, t_max: f64) -> bool {
    let t0 = (min - o) * inv;
    let t1 = (max - o) * inv;
    let lo = gmax(t0.min(t1).max_element(), t_min);
    let hi = gmin(t0.max(t1).min_element(), t_max);
    slab_overlap(lo, hi)
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: DVec3,
    pub max: DVec3,
}

impl Aabb {
    pub fn new(min: DVec3, max: DVec3) -> Self {
        Aabb { min, max }
    }

    /// The smallest box holding both.
    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb::new(self.min.min(other.min), self.max.max(other.max))
    }

    /// The box of `rot · p + offset` for every `p` in `self` (Arvo, Graphics
    /// Gems I, "Transforming axis-aligned bounding boxes").
    pub fn transformed(&self, rot: DMat3, offset: DVec3) -> Aabb {
        let c = 0.5 * (self.min + self.max);
        let e = 0.5 * (self.max - self.min);
        let abs = DMat3::from_cols(rot.x_axis.abs(), rot.y_axis.abs(), rot.z_axis.abs());
        let wc = rot * c + offset;
        let we = abs * e;
        Aabb::new(wc - we, wc + we)
    }

    /// Slab test: whether the ray meets the box inside `(t_min, t_max)`.
    #[inline]
    pub fn hit(&self, ray: &Ray, inv_dir: DVec3, t_min: f64, t_max: f64) -> bool {
        slab_hit(self.min, self.max, ray.origin, inv_dir, t_min, t_max)
    }
}
