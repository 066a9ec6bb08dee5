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

    #[inline]
    pub fn intersect(&self, ray: &Ray, t_min: f64, t_max: f64) -> Option<Hit> {
        self.poly.intersect(ray, t_min, t_max)
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
