//! A sphere of radius `radius` centred on its origin.

use super::{Aabb, Hit};
use crate::math::Ray;
use glam::DVec3;

#[derive(Clone, Debug, PartialEq)]
pub struct Sphere {
    pub radius: f64,
}

impl Sphere {
    pub fn new(radius: f64) -> Self {
        Sphere { radius }
    }

    /// The numerically careful form of Haines et al., "Precision
    /// Improvements for Ray/Sphere Intersection" (Ray Tracing Gems, ch. 7):
    /// move the origin to the point `p` of the ray nearest the centre; then
    /// `t = t₀ ± √((r − |p|)(r + |p|))`, which neither squares the distance
    /// to the camera nor subtracts nearly equal large numbers.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_min: f64, t_max: f64) -> Option<Hit> {
        let t0 = -ray.origin.dot(ray.dir);
        let p = ray.origin + t0 * ray.dir;
        let dist = p.length();
        let disc = (self.radius - dist) * (self.radius + dist);
        if disc < 0.0 {
            return None;
        }
        let s = disc.sqrt();
        let (a, b) = (t0 - s, t0 + s);
        if a > t_min && a < t_max {
            Some(Hit { t: a, part: 0 })
        } else if b > t_min && b < t_max {
            Some(Hit { t: b, part: 0 })
        } else {
            None
        }
    }

    pub fn normal(&self, p: DVec3) -> DVec3 {
        p.normalize()
    }

    pub fn bounds(&self) -> Aabb {
        Aabb::new(DVec3::splat(-self.radius), DVec3::splat(self.radius))
    }

    pub fn contains(&self, p: DVec3) -> bool {
        p.length_squared() <= self.radius * self.radius
    }
}
