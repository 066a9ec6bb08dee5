//! A box centred on its origin with side lengths `size` along x, y and z.

use super::polytope::Polytope;
use super::{Aabb, Hit};
use crate::math::Ray;
use glam::DVec3;

#[derive(Clone, Debug, PartialEq)]
pub struct Cuboid {
    pub size: DVec3,
    poly: Polytope<6>,
}

impl Cuboid {
    pub fn new(size: DVec3) -> Self {
        let h = 0.5 * size;
        Cuboid {
            size,
            poly: Polytope {
                planes: [
                    (DVec3::X, h.x),
                    (DVec3::NEG_X, h.x),
                    (DVec3::Y, h.y),
                    (DVec3::NEG_Y, h.y),
                    (DVec3::Z, h.z),
                    (DVec3::NEG_Z, h.z),
                ],
            },
        }
    }

    /// Kay–Kajiya slabs on the three axes (the planes are the polytope's, in
    /// the order +x, −x, +y, −y, +z, −z, so `part` names the same face).
    /// As for every polytope the origin is first moved to the point nearest
    /// the centre.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_min: f64, t_max: f64) -> Option<Hit> {
        let t0 = -ray.origin.dot(ray.dir);
        let o = ray.origin + t0 * ray.dir;
        let h = 0.5 * self.size;
        let inv = ray.dir.recip();
        // A zero direction component gives ±∞ here (or NaN exactly on a
        // face plane, which min/max skip): such a slab never limits the ray.
        let a = (-h - o) * inv;
        let b = (h - o) * inv;
        let near = a.min(b);
        let far = a.max(b);
        let t_in = near.max_element();
        let t_out = far.min_element();
        // Faces are numbered +x, −x, +y, −y, +z, −z: a ray travelling +k
        // enters through −k (2k + 1) and leaves through +k (2k).
        let arg = |v: DVec3, pick_max: bool| -> usize {
            let better = |x: f64, y: f64| if pick_max { x > y } else { x < y };
            let mut k = 0;
            if better(v.y, v[k]) {
                k = 1;
            }
            if better(v.z, v[k]) {
                k = 2;
            }
            k
        };
        let k_in = arg(near, true);
        let k_out = arg(far, false);
        let f_in = (2 * k_in + usize::from(ray.dir[k_in] > 0.0)) as u8;
        let f_out = (2 * k_out + usize::from(ray.dir[k_out] < 0.0)) as u8;
        super::first_crossing((t_in + t0, f_in), (t_out + t0, f_out), t_min, t_max)
    }

    pub fn normal(&self, part: u8) -> DVec3 {
        self.poly.normal(part)
    }

    pub fn bounds(&self) -> Aabb {
        Aabb::new(-0.5 * self.size, 0.5 * self.size)
    }

    pub(crate) fn polytope(&self) -> &Polytope<6> {
        &self.poly
    }
}
