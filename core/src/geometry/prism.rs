//! A right prism whose base is an equilateral triangle of side `side` in the
//! xz-plane, extruded `height` along y; the origin is at the centroid of the
//! solid. One vertex of the triangle points toward −z.

use super::polytope::Polytope;
use super::{Aabb, Hit};
use crate::math::Ray;
use glam::DVec3;

#[derive(Clone, Debug, PartialEq)]
pub struct Prism {
    pub side: f64,
    pub height: f64,
    /// Inradius of the triangle, side/(2√3): the offset of its three faces.
    inr: f64,
}

impl Prism {
    pub fn new(side: f64, height: f64) -> Self {
        let inr = side / (2.0 * 3f64.sqrt());
        Prism { side, height, inr }
    }

    /// The five half-spaces, made when used from the numbers kept (each
    /// bit as when they were kept whole, which tripled a prism's size).
    #[inline(always)]
    pub(crate) fn polytope(&self) -> Polytope<5> {
        let c = 3f64.sqrt() / 2.0;
        let (inr, h) = (self.inr, 0.5 * self.height);
        Polytope {
            planes: [
                (DVec3::Z, inr),
                (DVec3::new(-c, 0.0, -0.5), inr),
                (DVec3::new(c, 0.0, -0.5), inr),
                (DVec3::Y, h),
                (DVec3::NEG_Y, h),
            ],
        }
    }

    #[inline]
    pub fn intersect(&self, ray: &Ray, t_min: f64, t_max: f64) -> Option<Hit> {
        self.polytope().intersect(ray, t_min, t_max)
    }

    pub fn normal(&self, part: u8) -> DVec3 {
        self.polytope().normal(part)
    }

    pub fn bounds(&self) -> Aabb {
        // Circumradius side/√3 toward −z; the other two vertices at ±side/2 in x.
        let circ = self.side / 3f64.sqrt();
        let inr = 0.5 * circ;
        Aabb::new(
            DVec3::new(-0.5 * self.side, -0.5 * self.height, -circ),
            DVec3::new(0.5 * self.side, 0.5 * self.height, inr),
        )
    }
}
