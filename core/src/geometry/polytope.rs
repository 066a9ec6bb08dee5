//! Convex polytopes as intersections of half-spaces `n·x ≤ h`: the shared
//! intersection code of the cuboid, the prism and the pyramid.

use super::Hit;
use crate::math::Ray;
use glam::DVec3;

/// At most 6 planes (the cuboid), each an outward unit normal and offset.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Polytope<const N: usize> {
    pub planes: [(DVec3, f64); N],
}

impl<const N: usize> Polytope<N> {
    /// Kay–Kajiya slabs generalised to half-spaces (Haines, "Fast ray–convex
    /// polyhedron intersection", Graphics Gems II). The ray origin is first
    /// moved to the point of the ray nearest the shape's centre (the origin of
    /// shape space) so that `h − n·o` is computed from numbers of the shape's
    /// size, not the camera's distance.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_min: f64, t_max: f64) -> Option<Hit> {
        let t0 = -ray.origin.dot(ray.dir);
        let o = ray.origin + t0 * ray.dir;
        let mut t_in = f64::NEG_INFINITY;
        let mut t_out = f64::INFINITY;
        let (mut f_in, mut f_out) = (0u8, 0u8);
        for (i, &(n, h)) in self.planes.iter().enumerate() {
            let denom = n.dot(ray.dir);
            let dist = h - n.dot(o);
            if denom == 0.0 {
                if dist < 0.0 {
                    return None;
                }
                continue;
            }
            let t = dist / denom;
            if denom < 0.0 {
                if t > t_in {
                    t_in = t;
                    f_in = i as u8;
                }
            } else if t < t_out {
                t_out = t;
                f_out = i as u8;
            }
        }
        super::first_crossing((t_in + t0, f_in), (t_out + t0, f_out), t_min, t_max)
    }

    pub fn normal(&self, part: u8) -> DVec3 {
        self.planes[part as usize].0
    }

    pub fn contains(&self, p: DVec3) -> bool {
        self.planes.iter().all(|&(n, h)| n.dot(p) <= h)
    }
}
