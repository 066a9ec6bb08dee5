//! Coherent ray packets: eight rays walk the BVH together.
//!
//! Camera rays of neighbouring pixels pass through the same boxes, so a
//! packet pays for one walk and one branch per node instead of eight, and
//! each box test runs over eight lanes at once. The lane loops below are
//! plain `f64` array code that the compiler turns into AVX2 instructions
//! (four `f64` to a register) when the CPU has AVX2 — the function is
//! compiled twice and picked at run time — and into SSE2 otherwise.
//!
//! Every lane computes exactly what the scalar walk
//! ([`crate::integrator::closest_hit`]) computes for its ray, with the same
//! operations in the same order: the box test of [`super::Bvh::traverse`],
//! and for a cuboid without rotation the arithmetic of
//! [`crate::geometry::Cuboid::intersect`]; every other shape (the lens among
//! them) is tested by its own exact scalar code, lane by lane. So a packet
//! gives the scalar answer, bit for bit, except that two objects hit at
//! exactly the same distance may be named in another order.

// Lane loops index several arrays by the lane: the form the vectoriser wants.
#![allow(clippy::needless_range_loop)]

use crate::camera::Camera;
use crate::geometry::{Hit, Shape};
use crate::math::Ray;
use crate::scene::Scene;
use glam::DVec3;

/// Rays in a packet.
pub const LANES: usize = 8;

type Lanes<T> = [T; LANES];

/// No object (a lane's ray escapes, or the lane is unused).
pub const NO_OBJECT: u32 = u32::MAX;

/// Up to [`LANES`] rays in structure-of-arrays form. Unused lanes are
/// copies of lane 0 with an empty interval, so they never hit anything.
#[derive(Clone, Copy, Debug)]
pub struct Packet {
    o: [Lanes<f64>; 3],
    d: [Lanes<f64>; 3],
    inv: [Lanes<f64>; 3],
    t_max: Lanes<f64>,
    len: usize,
}

impl Packet {
    /// A packet of `rays` (1 ..= [`LANES`] of them; directions unit), each
    /// searched on `(0, t_max)`.
    pub fn new(rays: &[Ray], t_max: f64) -> Packet {
        assert!(
            !rays.is_empty() && rays.len() <= LANES,
            "a packet holds 1 to {LANES} rays"
        );
        let mut p = Packet {
            o: [[0.0; LANES]; 3],
            d: [[0.0; LANES]; 3],
            inv: [[0.0; LANES]; 3],
            t_max: [-1.0; LANES],
            len: rays.len(),
        };
        for l in 0..LANES {
            let (r, tm) = match rays.get(l) {
                Some(r) => (r, t_max),
                None => (&rays[0], -1.0),
            };
            let inv = r.dir.recip();
            for k in 0..3 {
                p.o[k][l] = r.origin[k];
                p.d[k][l] = r.dir[k];
                p.inv[k][l] = inv[k];
            }
            p.t_max[l] = tm;
        }
        p
    }

    /// The camera's primary rays through `(xs[l], ys[l])` for the first `n`
    /// lanes ([`crate::camera::Camera::directions`]).
    #[inline(always)]
    fn camera(cam: &Camera, xs: &Lanes<f64>, ys: &Lanes<f64>, n: usize, width: u32, height: u32) -> Packet {
        let d = cam.directions(xs, ys, width, height);
        let mut p = Packet {
            o: [[0.0; LANES]; 3],
            d,
            inv: [[0.0; LANES]; 3],
            t_max: [f64::INFINITY; LANES],
            len: n,
        };
        for k in 0..3 {
            p.o[k] = [cam.position[k]; LANES];
            for l in 0..LANES {
                p.inv[k][l] = 1.0 / d[k][l];
            }
        }
        for l in n..LANES {
            p.t_max[l] = -1.0;
        }
        p
    }

    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Lane `l`'s ray.
    #[inline]
    pub fn ray(&self, l: usize) -> Ray {
        Ray {
            origin: DVec3::new(self.o[0][l], self.o[1][l], self.o[2][l]),
            dir: DVec3::new(self.d[0][l], self.d[1][l], self.d[2][l]),
        }
    }
}

/// The closest hit of each lane: object index ([`NO_OBJECT`] for none),
/// distance and part, as [`crate::integrator::closest_hit`] gives them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PacketHits {
    pub object: Lanes<u32>,
    pub t: Lanes<f64>,
    pub part: Lanes<u8>,
}

impl PacketHits {
    /// Lane `l`'s hit in the form of [`crate::integrator::closest_hit`].
    #[inline]
    pub fn get(&self, l: usize) -> Option<(usize, Hit)> {
        (self.object[l] != NO_OBJECT).then(|| {
            (
                self.object[l] as usize,
                Hit {
                    t: self.t[l],
                    part: self.part[l],
                },
            )
        })
    }
}

/// glam's `DVec3::min` on one component (NaN in `a` or `b` gives `b`).
#[inline(always)]
fn gmin(a: f64, b: f64) -> f64 {
    if a < b { a } else { b }
}

/// glam's `DVec3::max` on one component.
#[inline(always)]
fn gmax(a: f64, b: f64) -> f64 {
    if a > b { a } else { b }
}

/// The BVH box test of every lane, as a bit mask.
#[inline(always)]
fn slab(min: DVec3, max: DVec3, p: &Packet, t_max: &Lanes<f64>) -> u32 {
    let mut hit = [false; LANES];
    for l in 0..LANES {
        let t0x = (min.x - p.o[0][l]) * p.inv[0][l];
        let t0y = (min.y - p.o[1][l]) * p.inv[1][l];
        let t0z = (min.z - p.o[2][l]) * p.inv[2][l];
        let t1x = (max.x - p.o[0][l]) * p.inv[0][l];
        let t1y = (max.y - p.o[1][l]) * p.inv[1][l];
        let t1z = (max.z - p.o[2][l]) * p.inv[2][l];
        let lo = gmax(gmin(t0x, t1x), gmax(gmin(t0y, t1y), gmin(t0z, t1z))).max(0.0);
        let hi = gmin(gmax(t0x, t1x), gmin(gmax(t0y, t1y), gmax(t0z, t1z))).min(t_max[l]);
        hit[l] = lo <= hi * (1.0 + 4.0 * f64::EPSILON);
    }
    mask(&hit)
}

#[inline(always)]
fn mask(b: &Lanes<bool>) -> u32 {
    let mut m = 0;
    for (l, &x) in b.iter().enumerate() {
        m |= (x as u32) << l;
    }
    m
}

/// [`crate::geometry::Cuboid::intersect`] in every lane, for a cuboid of
/// half sides `h` at `position` without rotation; lanes that hit within
/// `(0, best.t)` take the hit as their new best.
#[inline(always)]
fn cuboid(position: DVec3, h: DVec3, object: u32, p: &Packet, best: &mut PacketHits) {
    for l in 0..LANES {
        // `Object::to_object` for a translation.
        let rx = p.o[0][l] - position.x;
        let ry = p.o[1][l] - position.y;
        let rz = p.o[2][l] - position.z;
        let (dx, dy, dz) = (p.d[0][l], p.d[1][l], p.d[2][l]);
        let t0 = -((rx * dx) + (ry * dy) + (rz * dz));
        let ox = rx + t0 * dx;
        let oy = ry + t0 * dy;
        let oz = rz + t0 * dz;
        let (ix, iy, iz) = (p.inv[0][l], p.inv[1][l], p.inv[2][l]);
        let ax = (-h.x - ox) * ix;
        let ay = (-h.y - oy) * iy;
        let az = (-h.z - oz) * iz;
        let bx = (h.x - ox) * ix;
        let by = (h.y - oy) * iy;
        let bz = (h.z - oz) * iz;
        let near = [gmin(ax, bx), gmin(ay, by), gmin(az, bz)];
        let far = [gmax(ax, bx), gmax(ay, by), gmax(az, bz)];
        let t_in = gmax(near[0], gmax(near[1], near[2]));
        let t_out = gmin(far[0], gmin(far[1], far[2]));
        // The face arithmetic of `Cuboid::intersect`.
        let k_in = if near[2] > (if near[1] > near[0] { near[1] } else { near[0] }) {
            2
        } else if near[1] > near[0] {
            1
        } else {
            0
        };
        let k_out = if far[2] < (if far[1] < far[0] { far[1] } else { far[0] }) {
            2
        } else if far[1] < far[0] {
            1
        } else {
            0
        };
        let d = [dx, dy, dz];
        let f_in = 2 * k_in + u8::from(d[k_in as usize] > 0.0);
        let f_out = 2 * k_out + u8::from(d[k_out as usize] < 0.0);
        // `first_crossing` on (0, best).
        let (e, x) = (t_in + t0, t_out + t0);
        let t_max = best.t[l];
        let take_e = !(e > x) && e > 0.0 && e < t_max;
        let take_x = !(e > x) && !take_e && x > 0.0 && x < t_max;
        if take_e {
            best.t[l] = e;
            best.part[l] = f_in;
            best.object[l] = object;
        } else if take_x {
            best.t[l] = x;
            best.part[l] = f_out;
            best.object[l] = object;
        }
    }
}

/// Tests object `i` against the lanes in `lanes` (a bit mask).
#[inline(always)]
fn test_object(scene: &Scene, i: u32, lanes: u32, p: &Packet, best: &mut PacketHits) {
    let o = &scene.objects[i as usize];
    match &o.shape {
        Shape::Cuboid(c) if o.translation_only => cuboid(o.position, 0.5 * c.size, i, p, best),
        Shape::Lens(lens) if o.identity => {
            let h = lens.intersect_lanes(&p.o, &p.d, &best.t);
            for l in 0..LANES {
                if lanes >> l & 1 != 0 && h.hit[l] {
                    best.t[l] = h.t[l];
                    best.part[l] = h.part[l];
                    best.object[l] = i;
                }
            }
            let mut slow = lanes & mask(&h.slow);
            while slow != 0 {
                let l = slow.trailing_zeros() as usize;
                slow &= slow - 1;
                if let Some(h) = lens.intersect(&p.ray(l), 0.0, best.t[l]) {
                    best.t[l] = h.t;
                    best.part[l] = h.part;
                    best.object[l] = i;
                }
            }
        }
        shape => {
            let mut m = lanes;
            while m != 0 {
                let l = m.trailing_zeros() as usize;
                m &= m - 1;
                if let Some(h) = shape.intersect(&o.to_object(&p.ray(l)), 0.0, best.t[l]) {
                    best.t[l] = h.t;
                    best.part[l] = h.part;
                    best.object[l] = i;
                }
            }
        }
    }
}

#[inline(always)]
fn closest_hits_impl(scene: &Scene, p: &Packet) -> PacketHits {
    let mut best = PacketHits {
        object: [NO_OBJECT; LANES],
        t: p.t_max,
        part: [0; LANES],
    };
    match &scene.bvh {
        None => {
            for (i, o) in scene.objects.iter().enumerate() {
                let m = slab(o.world_bounds.min, o.world_bounds.max, p, &best.t);
                if m != 0 {
                    test_object(scene, i as u32, m, p, &mut best);
                }
            }
        }
        Some(bvh) => {
            if bvh.nodes.is_empty() {
                return best;
            }
            // Children in the order of the first lane's direction: the rays
            // of a packet travel nearly alike.
            let neg = [p.inv[0][0] < 0.0, p.inv[1][0] < 0.0, p.inv[2][0] < 0.0];
            let mut stack = [0u32; 64];
            let mut sp = 0usize;
            let mut i = 0usize;
            loop {
                let node = &bvh.nodes[i];
                let m = slab(node.min, node.max, p, &best.t);
                if m != 0 {
                    if node.count > 0 {
                        for &o in &bvh.prims[node.first as usize..(node.first + node.count) as usize] {
                            test_object(scene, o, m, p, &mut best);
                        }
                    } else {
                        let (near, far) = if neg[node.axis as usize] {
                            (node.first as usize, i + 1)
                        } else {
                            (i + 1, node.first as usize)
                        };
                        if sp < stack.len() {
                            stack[sp] = far as u32;
                            sp += 1;
                        }
                        // (A tree deeper than the stack is walked without its
                        // far children; `Bvh::build` never makes one.)
                        i = near;
                        continue;
                    }
                }
                if sp == 0 {
                    break;
                }
                sp -= 1;
                i = stack[sp] as usize;
            }
        }
    }
    // Unused lanes report no hit.
    for l in p.len..LANES {
        best.object[l] = NO_OBJECT;
    }
    best
}

/// [`closest_hits_impl`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn closest_hits_avx2(scene: &Scene, p: &Packet) -> PacketHits {
    closest_hits_impl(scene, p)
}

/// Whether this CPU runs the AVX2 build of the packet code.
pub fn uses_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// The closest hit of every ray of the packet (lanes past its length report
/// none).
pub fn closest_hits(scene: &Scene, p: &Packet) -> PacketHits {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: `closest_hits_avx2` only differs from the portable build in
        // being compiled with AVX2 instructions, and the line above has just
        // checked that this CPU has them. Calling a `target_feature` function
        // needs `unsafe` in Rust; nothing else here is unchecked.
        return unsafe { closest_hits_avx2(scene, p) };
    }
    closest_hits_impl(scene, p)
}

#[inline(always)]
fn camera_hits_impl(
    scene: &Scene,
    xs: &Lanes<f64>,
    ys: &Lanes<f64>,
    n: usize,
    width: u32,
    height: u32,
) -> (Packet, PacketHits) {
    let p = Packet::camera(&scene.camera, xs, ys, n, width, height);
    let h = closest_hits_impl(scene, &p);
    (p, h)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn camera_hits_avx2(
    scene: &Scene,
    xs: &Lanes<f64>,
    ys: &Lanes<f64>,
    n: usize,
    width: u32,
    height: u32,
) -> (Packet, PacketHits) {
    camera_hits_impl(scene, xs, ys, n, width, height)
}

/// The primary rays of a `width × height` image through the continuous
/// pixel positions `(xs[l], ys[l])`, `l < n` (1 ..= [`LANES`]), and their
/// closest hits: the rays are exactly [`Camera::ray`]'s.
pub fn camera_hits(
    scene: &Scene,
    xs: &Lanes<f64>,
    ys: &Lanes<f64>,
    n: usize,
    width: u32,
    height: u32,
) -> (Packet, PacketHits) {
    assert!((1..=LANES).contains(&n), "a packet holds 1 to {LANES} rays");
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: as in `closest_hits`: the AVX2 build of the same code,
        // called only after checking that the CPU has AVX2.
        return unsafe { camera_hits_avx2(scene, xs, ys, n, width, height) };
    }
    camera_hits_impl(scene, xs, ys, n, width, height)
}

/// The portable (SSE2) build, for tests and benchmarks on any CPU.
pub fn closest_hits_portable(scene: &Scene, p: &Packet) -> PacketHits {
    closest_hits_impl(scene, p)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::closest_hit;
    use crate::sampling::Sampler;

    fn scenes() -> Vec<(&'static str, Scene)> {
        let (sf, cubes) = Scene::default_scene();
        let parse = |name, text| Scene::parse(name, text).unwrap().1;
        let mut rotated = sf.clone();
        for (k, o) in rotated.objects.iter_mut().enumerate() {
            if k % 3 == 0 {
                o.rotation = [10.0 * k as f64, 5.0, 0.0];
            }
        }
        vec![
            ("cubes", cubes),
            ("cubes 40×40", crate::bench::cubes_grid(&sf, 40)),
            ("cubes 2", crate::bench::cubes_subset(&sf, 2)),
            ("cubes rotated", Scene::build(&rotated).unwrap()),
            (
                "primitives",
                parse("primitives", include_str!("../../scenes/primitives.toml")),
            ),
            (
                "optical bench",
                parse("optical bench", include_str!("../../scenes/optical-bench.toml")),
            ),
        ]
    }

    /// Packets of camera rays (coherent) and of random rays from random
    /// points (incoherent) give the scalar walk's hit in every lane.
    fn check(hits: fn(&Scene, &Packet) -> PacketHits) {
        for (name, scene) in scenes() {
            let mut s = Sampler::new(7, 0, 0);
            let mut compared = 0;
            for k in 0..1500 {
                let n = 1 + k % LANES;
                let rays: Vec<Ray> = (0..n)
                    .map(|l| {
                        if k % 2 == 0 {
                            let (x, y) = (s.next_f64() * 200.0, s.next_f64() * 150.0);
                            let _ = l;
                            scene.camera.ray(x, y, 200, 150)
                        } else {
                            let o = DVec3::new(s.next_f64(), s.next_f64(), s.next_f64()) * 16.0 - 8.0;
                            let d = DVec3::new(s.next_f64(), s.next_f64(), s.next_f64()) - 0.5;
                            Ray::new(o, d)
                        }
                    })
                    .collect();
                let got = hits(&scene, &Packet::new(&rays, f64::INFINITY));
                for (l, r) in rays.iter().enumerate() {
                    let want = closest_hit(&scene, r, f64::INFINITY);
                    let have = got.get(l);
                    match (want, have) {
                        (Some((wi, wh)), Some((hi, hh))) => {
                            assert_eq!(wh.t, hh.t, "{name}: ray {k} lane {l}");
                            if wi != hi {
                                // An exact tie: both objects are hit at that distance.
                                let o = &scene.objects[wi];
                                let t = scene.objects[hi].shape.intersect(
                                    &scene.objects[hi].to_object(r),
                                    0.0,
                                    f64::INFINITY,
                                );
                                assert_eq!(t.map(|h| h.t), Some(wh.t), "{name}: {} vs {}", o.name, hi);
                            } else {
                                assert_eq!(wh.part, hh.part, "{name}: ray {k} lane {l}");
                            }
                        }
                        (w, h) => assert_eq!(w.is_some(), h.is_some(), "{name}: ray {k} lane {l}"),
                    }
                    compared += usize::from(want.is_some());
                }
                for l in n..LANES {
                    assert!(got.get(l).is_none());
                }
            }
            assert!(compared > 1000, "{name}: only {compared} hits compared");
        }
    }

    #[test]
    fn packets_give_the_scalar_hits() {
        check(closest_hits);
    }

    #[test]
    fn the_portable_build_gives_the_scalar_hits() {
        check(closest_hits_portable);
    }
}
