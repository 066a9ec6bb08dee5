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
        let a = (-h - o) * inv;
        let b = (h - o) * inv;
        let near = a.min(b);
        let far = a.max(b);
        // Entering face on each axis: the −face when the ray travels +.
        let (mut t_in, mut f_in) = (f64::NEG_INFINITY, 0u8);
        let (mut t_out, mut f_out) = (f64::INFINITY, 0u8);
        for k in 0..3 {
            let d = ray.dir[k];
            if d == 0.0 {
                if o[k].abs() > h[k] {
                    return None;
                }
                continue;
            }
            let (enter_face, exit_face) = if d > 0.0 {
                (2 * k as u8 + 1, 2 * k as u8)
            } else {
                (2 * k as u8, 2 * k as u8 + 1)
            };
            if near[k] > t_in {
                t_in = near[k];
                f_in = enter_face;
            }
            if far[k] < t_out {
                t_out = far[k];
                f_out = exit_face;
            }
        }
        if t_in > t_out {
            return None;
        }
        let (t_in, t_out) = (t_in + t0, t_out + t0);
        if t_in > t_min && t_in < t_max {
            Some(Hit { t: t_in, part: f_in })
        } else if t_out > t_min && t_out < t_max {
            Some(Hit { t: t_out, part: f_out })
        } else {
            None
        }
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
