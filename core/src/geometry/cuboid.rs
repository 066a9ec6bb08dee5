//! A box centred on its origin with side lengths `size` along x, y and z:
//! one ray ([`Cuboid::intersect`]) or a packet's lanes at once
//! ([`Cuboid::intersect_lanes`]), both from the same slab step.

// Lane loops index several arrays by the lane: the form the vectoriser wants.
#![allow(clippy::needless_range_loop)]

use super::polytope::Polytope;
use super::{Aabb, Hit, WideHits, crossing_choice};
use crate::math::Ray;
use crate::simd::lane;
use glam::DVec3;

#[derive(Clone, Debug, PartialEq)]
pub struct Cuboid {
    pub size: DVec3,
}

/// The outward normals of a cuboid's faces, in the order of its planes.
const NORMALS: [DVec3; 6] = [DVec3::X, DVec3::NEG_X, DVec3::Y, DVec3::NEG_Y, DVec3::Z, DVec3::NEG_Z];

/// Where one ray crosses a cuboid's slabs ([`slabs`]): distances from the
/// point nearest the centre, and that point's distance `t0` along the ray.
#[derive(Clone, Copy, Debug)]
struct Slabs {
    t0: f64,
    t_in: f64,
    t_out: f64,
    /// The faces entered and left by (see [`Cuboid::intersect`]).
    f_in: u64,
    f_out: u64,
}

/// Kay–Kajiya slabs on the three axes of the box of half sides `h`, for the
/// ray from `o` (object space) along `d` with reciprocal `inv`. As for
/// every polytope the origin is first moved to the point nearest the
/// centre. Written without branches or lookups by index (the faces are
/// picked by selects), so that packet lanes run it side by side; the
/// scalar test is the same arithmetic.
#[inline(always)]
fn slabs(o: DVec3, d: DVec3, inv: DVec3, h: DVec3) -> Slabs {
    let t0 = -o.dot(d);
    let o = o + t0 * d;
    // A zero direction component gives ±∞ here (or NaN exactly on a
    // face plane, which min/max skip): such a slab never limits the ray.
    let a = (-h - o) * inv;
    let b = (h - o) * inv;
    let near = a.min(b);
    let far = a.max(b);
    // Faces are numbered +x, −x, +y, −y, +z, −z: a ray travelling +k
    // enters through −k (2k + 1) and leaves through +k (2k). Axis 2 where
    // its distance beats the larger (smaller) of the first two, else axis
    // 1 where it beats axis 0, else axis 0.
    let in1 = near.y > near.x;
    let in2 = near.z > (if in1 { near.y } else { near.x });
    let out1 = far.y < far.x;
    let out2 = far.z < (if out1 { far.y } else { far.x });
    let pick = |z: bool, y: bool, v: DVec3| {
        if z {
            (v.z, 4u64)
        } else if y {
            (v.y, 2)
        } else {
            (v.x, 0)
        }
    };
    let (d_in, k_in) = pick(in2, in1, d);
    let (d_out, k_out) = pick(out2, out1, d);
    Slabs {
        t0,
        t_in: near.max_element(),
        t_out: far.min_element(),
        f_in: k_in + u64::from(d_in > 0.0),
        f_out: k_out + u64::from(d_out < 0.0),
    }
}

impl Cuboid {
    pub fn new(size: DVec3) -> Self {
        Cuboid { size }
    }

    /// Kay–Kajiya slabs on the three axes ([`slabs`]; the planes are the
    /// polytope's, in the order +x, −x, +y, −y, +z, −z, so `part` names the
    /// same face).
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_min: f64, t_max: f64) -> Option<Hit> {
        let s = slabs(ray.origin, ray.dir, ray.dir.recip(), 0.5 * self.size);
        super::first_crossing(
            (s.t_in + s.t0, s.f_in as u8),
            (s.t_out + s.t0, s.f_out as u8),
            t_min,
            t_max,
        )
    }

    /// [`Cuboid::intersect`] on `(0, t_max[l])` in every lane `l` of a
    /// packet (world origins `o`, unit directions `d` and their reciprocals
    /// `inv`, structure of arrays), for this cuboid placed at `position`
    /// without rotation: each lane does the scalar test's arithmetic and
    /// gets its hit bit for bit.
    #[inline(always)]
    pub(crate) fn intersect_lanes<const N: usize>(
        &self,
        position: DVec3,
        o: &[[f64; N]; 3],
        d: &[[f64; N]; 3],
        inv: &[[f64; N]; 3],
        t_max: &[f64; N],
    ) -> WideHits<N> {
        let h = 0.5 * self.size;
        let mut out = WideHits {
            hit: [0; N],
            t: [0.0; N],
            part: [0; N],
        };
        for l in 0..N {
            // `Object::to_object` for a translation.
            let s = slabs(lane(o, l) - position, lane(d, l), lane(inv, l), h);
            let (e, x) = (s.t_in + s.t0, s.t_out + s.t0);
            let (take_e, take_x) = crossing_choice(e, x, 0.0, t_max[l]);
            out.hit[l] = u64::from(take_e | take_x);
            out.t[l] = if take_e { e } else { x };
            out.part[l] = if take_e { s.f_in } else { s.f_out };
        }
        out
    }

    pub fn normal(&self, part: u8) -> DVec3 {
        NORMALS[part as usize]
    }

    pub fn bounds(&self) -> Aabb {
        Aabb::new(-0.5 * self.size, 0.5 * self.size)
    }

    /// The six half-spaces, made when asked (only `contains` asks): kept,
    /// they would triple a cuboid's size.
    pub(crate) fn polytope(&self) -> Polytope<6> {
        let h = 0.5 * self.size;
        let offsets = [h.x, h.x, h.y, h.y, h.z, h.z];
        Polytope {
            planes: std::array::from_fn(|i| (NORMALS[i], offsets[i])),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Sampler;
    use crate::simd::{LANES, set_lane};

    /// Every lane of `intersect_lanes` is `intersect` of its ray moved into
    /// object space, bit for bit: rays from outside, from inside, along an
    /// axis (infinite reciprocals), with short intervals.
    #[test]
    fn lanes_give_the_scalar_hit_bit_for_bit() {
        let mut s = Sampler::new(17, 0, 0);
        let mut v = |scale: f64| (DVec3::new(s.next_f64(), s.next_f64(), s.next_f64()) - 0.5) * scale;
        let (mut hits, mut misses) = (0, 0);
        for k in 0..3000 {
            let cube = Cuboid::new(DVec3::new(1.0, 2.0, 0.5) + v(1.0).abs());
            let position = v(10.0);
            let (mut o, mut d, mut inv) = ([[0.0; LANES]; 3], [[0.0; LANES]; 3], [[0.0; LANES]; 3]);
            let mut t_max = [f64::INFINITY; LANES];
            let mut rays = [Ray::new(DVec3::ZERO, DVec3::X); LANES];
            for l in 0..LANES {
                let origin = position + v([0.5, 4.0, 30.0][(k + l) % 3]);
                let mut dir = position + v(2.0) - origin;
                if l == 5 {
                    dir[k % 3] = 0.0;
                }
                rays[l] = Ray::new(origin, dir);
                if l == 6 {
                    t_max[l] = v(20.0).x.abs();
                }
                set_lane(&mut o, l, rays[l].origin);
                set_lane(&mut d, l, rays[l].dir);
                set_lane(&mut inv, l, rays[l].dir.recip());
            }
            let got = cube.intersect_lanes(position, &o, &d, &inv, &t_max);
            for (l, ray) in rays.iter().enumerate() {
                let local = Ray {
                    origin: ray.origin - position,
                    dir: ray.dir,
                };
                let want = cube.intersect(&local, 0.0, t_max[l]);
                let have = (got.hit[l] != 0).then(|| Hit {
                    t: got.t[l],
                    part: got.part[l] as u8,
                });
                assert_eq!(have, want, "packet {k} lane {l}: {ray:?}");
                if want.is_some() {
                    hits += 1;
                } else {
                    misses += 1;
                }
            }
        }
        assert!(hits > 5000 && misses > 2000, "{hits} hits, {misses} misses");
    }
}
