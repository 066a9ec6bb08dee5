//! A square pyramid: base of side `base` in the plane y = −height/2, apex at
//! (0, height/2, 0). The origin is the centre of its bounding box.

use super::polytope::Polytope;
use super::{Aabb, Hit};
use crate::math::Ray;
use glam::DVec3;

#[derive(Clone, Debug, PartialEq)]
pub struct Pyramid {
    pub base: f64,
    pub height: f64,
    poly: Polytope<5>,
}

impl Pyramid {
    pub fn new(base: f64, height: f64) -> Self {
        let apex = DVec3::new(0.0, 0.5 * height, 0.0);
        // A side plane contains the apex and a base edge at distance base/2
        // along `e`; in the (e, y) plane its normal is (height, base/2).
        let side = |e: DVec3| {
            let n = (height * e + 0.5 * base * DVec3::Y).normalize();
            (n, n.dot(apex))
        };
        Pyramid {
            base,
            height,
            poly: Polytope {
                planes: [
                    (DVec3::NEG_Y, 0.5 * height),
                    side(DVec3::X),
                    side(DVec3::NEG_X),
                    side(DVec3::Z),
                    side(DVec3::NEG_Z),
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
        let h = DVec3::new(0.5 * self.base, 0.5 * self.height, 0.5 * self.base);
        Aabb::new(-h, h)
    }

    pub(crate) fn polytope(&self) -> &Polytope<5> {
        &self.poly
    }
}
