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
    /// The side plane toward +x: its normal (across, up, 0) and offset; the
    /// other three sides are it turned by quarter turns.
    across: f64,
    up: f64,
    offset: f64,
}

/// A side plane of the pyramid `base`×`height`: it contains the apex and a
/// base edge at distance base/2 along `e`; in the (e, y) plane its normal
/// is (height, base/2).
fn side_plane(base: f64, height: f64, e: DVec3) -> (DVec3, f64) {
    let apex = DVec3::new(0.0, 0.5 * height, 0.0);
    let n = (height * e + 0.5 * base * DVec3::Y).normalize();
    (n, n.dot(apex))
}

impl Pyramid {
    pub fn new(base: f64, height: f64) -> Self {
        let (n, offset) = side_plane(base, height, DVec3::X);
        Pyramid {
            base,
            height,
            across: n.x,
            up: n.y,
            offset,
        }
    }

    /// The five half-spaces, made when used from the numbers kept; each
    /// bit is what [`side_plane`] gives for its side (the test below), the
    /// four sides differing only in signs and the order of their terms.
    #[inline(always)]
    pub(crate) fn polytope(&self) -> Polytope<5> {
        let (a, u, h) = (self.across, self.up, self.offset);
        Polytope {
            planes: [
                (DVec3::NEG_Y, 0.5 * self.height),
                (DVec3::new(a, u, 0.0), h),
                (DVec3::new(-a, u, 0.0), h),
                (DVec3::new(0.0, u, a), h),
                (DVec3::new(0.0, u, -a), h),
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
        let h = DVec3::new(0.5 * self.base, 0.5 * self.height, 0.5 * self.base);
        Aabb::new(-h, h)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The planes made from the three numbers kept are, bit for bit, the
    /// planes [`side_plane`] builds for each side, over sizes from tiny to
    /// huge and flat to tall.
    #[test]
    fn kept_numbers_give_each_side_plane_exactly() {
        let sizes = [1e-9, 3e-4, 0.1, 0.7, 1.0, 1.3, 2.0, 17.25, 1e3, 4.5e7, 1e12];
        for &base in &sizes {
            for &height in &sizes {
                let p = Pyramid::new(base, height).polytope();
                assert_eq!(p.planes[0], (DVec3::NEG_Y, 0.5 * height));
                for (i, e) in [DVec3::X, DVec3::NEG_X, DVec3::Z, DVec3::NEG_Z].into_iter().enumerate() {
                    let (n, h) = side_plane(base, height, e);
                    let (m, k) = p.planes[i + 1];
                    assert_eq!(
                        (m.to_array().map(f64::to_bits), k.to_bits()),
                        (n.to_array().map(f64::to_bits), h.to_bits()),
                        "base {base} height {height} side {i}"
                    );
                }
            }
        }
    }
}
