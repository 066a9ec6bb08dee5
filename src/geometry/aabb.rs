//! Axis-aligned bounding boxes, used to skip objects a ray cannot reach.

use crate::math::Ray;
use glam::{DMat3, DVec3};

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
        let t0 = (self.min - ray.origin) * inv_dir;
        let t1 = (self.max - ray.origin) * inv_dir;
        let lo = t0.min(t1).max_element().max(t_min);
        let hi = t0.max(t1).min_element().min(t_max);
        // A NaN from 0·∞ (ray in a slab's plane) makes max/min pick the other
        // operand, so such a ray is conservatively kept.
        lo <= hi * (1.0 + 4.0 * f64::EPSILON)
    }
}
