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
use crate::color::Rgb;
use crate::geometry::{Hit, Shape};
use crate::math::Ray;
use crate::scene::Scene;
use glam::DVec3;

/// Rays in a packet.
pub const LANES: usize = 8;

/// One value per lane.
pub type Lanes<T> = [T; LANES];

/// No object (a lane's ray escapes, or the lane is unused).
pub const NO_OBJECT: u32 = u32::MAX;

/// Up to [`LANES`] rays in structure-of-arrays form. Unused lanes are
/// copies of a used lane with an empty interval, so they never hit anything.
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
        Self::with_limits(rays, &[t_max; LANES])
    }

    /// A packet to fill lane by lane in place ([`Packet::set`], then
    /// [`Packet::fill_unused`], which sets every lane not set): no array of
    /// rays to build and copy first. Its lanes mean nothing until then.
    pub const EMPTY: Packet = Packet {
        o: [[0.0; LANES]; 3],
        d: [[0.0; LANES]; 3],
        inv: [[0.0; LANES]; 3],
        t_max: [0.0; LANES],
        len: LANES,
    };

    /// Sets lane `l` to `ray` (unit direction), searched on `(0, t_max)`
    /// (an empty interval when `t_max` is negative).
    #[inline(always)]
    pub fn set(&mut self, l: usize, ray: &Ray, t_max: f64) {
        let inv = ray.dir.recip();
        for k in 0..3 {
            self.o[k][l] = ray.origin[k];
            self.d[k][l] = ray.dir[k];
            self.inv[k][l] = inv[k];
        }
        self.t_max[l] = t_max;
    }

    /// Makes every lane outside the bit mask `live` (not empty) a copy of
    /// its first lane with an empty interval, so that it never hits.
    #[inline(always)]
    pub fn fill_unused(&mut self, live: u32) {
        debug_assert!(live != 0 && live < 1 << LANES);
        let first = live.trailing_zeros() as usize;
        for l in 0..LANES {
            if live >> l & 1 == 0 {
                for k in 0..3 {
                    self.o[k][l] = self.o[k][first];
                    self.d[k][l] = self.d[k][first];
                    self.inv[k][l] = self.inv[k][first];
                }
                self.t_max[l] = -1.0;
            }
        }
        self.len = LANES;
    }

    /// A packet of `rays`, ray `l` searched on `(0, t_max[l])`.
    pub fn with_limits(rays: &[Ray], t_max: &Lanes<f64>) -> Packet {
        assert!(
            !rays.is_empty() && rays.len() <= LANES,
            "a packet holds 1 to {LANES} rays"
        );
        let mut p = Packet::EMPTY;
        for l in 0..LANES {
            match rays.get(l) {
                Some(r) => p.set(l, r, t_max[l]),
                None => p.set(l, &rays[0], -1.0),
            }
        }
        p.len = rays.len();
        p
    }

    /// The camera's primary rays through `(xs[l], ys[l])` for the first `n`
    /// lanes ([`crate::camera::Camera::directions`]).
    #[inline(always)]
    fn camera(cam: &Camera, xs: &Lanes<f64>, ys: &Lanes<f64>, n: usize, width: u32, height: u32) -> Packet {
        let mut p = Packet {
            o: [[0.0; LANES]; 3],
            d: [[0.0; LANES]; 3],
            inv: [[0.0; LANES]; 3],
            t_max: [0.0; LANES],
            len: 0,
        };
        p.set_camera(cam, xs, ys, n, width, height);
        p
    }

    /// Makes this packet [`Packet::camera`]'s, in place (a packet is large
    /// enough that building one and copying it in costs a `memcpy`).
    #[inline(always)]
    fn set_camera(&mut self, cam: &Camera, xs: &Lanes<f64>, ys: &Lanes<f64>, n: usize, width: u32, height: u32) {
        // Unused lanes repeat lane 0's pixel (their interval is empty), so
        // that a tile's frustum can be taken over every lane.
        let (mut xs, mut ys) = (*xs, *ys);
        for l in n..LANES {
            (xs[l], ys[l]) = (xs[0], ys[0]);
        }
        self.d = cam.directions(&xs, &ys, width, height);
        for k in 0..3 {
            self.o[k] = [cam.position[k]; LANES];
            for l in 0..LANES {
                self.inv[k][l] = 1.0 / self.d[k][l];
            }
        }
        self.t_max = [f64::INFINITY; LANES];
        for l in n..LANES {
            self.t_max[l] = -1.0;
        }
        self.len = n;
    }

    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Every lane's direction, structure of arrays.
    #[inline]
    pub fn dirs(&self) -> &[Lanes<f64>; 3] {
        &self.d
    }

    /// Lane `l`'s direction.
    #[inline]
    pub fn dir(&self, l: usize) -> DVec3 {
        DVec3::new(self.d[0][l], self.d[1][l], self.d[2][l])
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
        // `gmax(x, 0)` and `gmin(x, t)` are `f64::max`/`min` for every `x`,
        // NaN included (a NaN gives the other operand), up to the sign of a
        // zero, which no comparison sees; they compile to one instruction.
        let lo = gmax(gmax(gmin(t0x, t1x), gmax(gmin(t0y, t1y), gmin(t0z, t1z))), 0.0);
        let hi = gmin(gmin(gmax(t0x, t1x), gmin(gmax(t0y, t1y), gmax(t0z, t1z))), t_max[l]);
        hit[l] = lo <= hi * (1.0 + 4.0 * f64::EPSILON);
    }
    mask(&hit)
}

const _: () = assert!(LANES == 8, "`mask` packs eight lanes");

/// The lanes whose bit is set in `mask`, lowest first.
#[inline(always)]
pub(crate) fn live_lanes(mask: u32) -> LiveLanes {
    LiveLanes(mask)
}

/// [`live_lanes`]: the bits left to visit.
pub(crate) struct LiveLanes(u32);

impl Iterator for LiveLanes {
    type Item = usize;

    #[inline(always)]
    fn next(&mut self) -> Option<usize> {
        if self.0 == 0 {
            return None;
        }
        let l = self.0.trailing_zeros() as usize;
        self.0 &= self.0 - 1;
        Some(l)
    }
}

/// Bit `l` set where `b[l]`: the eight flags as bytes of one word, gathered
/// into its top byte by one multiplication (each byte's bit lands 7 places
/// apart from the next; no two products meet in the top byte).
#[inline(always)]
fn mask(b: &Lanes<bool>) -> u32 {
    let word = u64::from_le_bytes(b.map(u8::from));
    (word.wrapping_mul(0x0102_0408_1020_4080) >> 56) as u32
}

/// Hits of one object in a packet's lanes.
#[derive(Clone, Copy, Debug)]
struct ObjectHits {
    /// Lanes that hit within `(0, t_max)`.
    /// 1 where hit, else 0.
    hit: Lanes<u64>,
    t: Lanes<f64>,
    /// In 64-bit lanes, the width of the distances, so that the loops that
    /// pick among them stay in SIMD registers.
    part: Lanes<u64>,
}

/// [`crate::geometry::Cuboid::intersect`] in every lane, for a cuboid of
/// half sides `h` at `position` without rotation, on `(0, t_max[l])`.
#[inline(always)]
fn cuboid(position: DVec3, h: DVec3, p: &Packet, t_max: &Lanes<f64>) -> ObjectHits {
    // Flags and faces in 64-bit lanes, the width of the distances, so that
    // the loop is one SIMD loop; narrowed after it.
    let mut hit_w = [0u64; LANES];
    let mut out_t = [0.0; LANES];
    let mut part_w = [0u64; LANES];
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
        // The face arithmetic of `Cuboid::intersect`, as selects (no
        // branch, no lookup by index, so that the loop stays in SIMD lanes):
        // axis 2 where its distance beats the larger (smaller) of the first
        // two, else axis 1 where it beats axis 0, else axis 0.
        let in1 = near[1] > near[0];
        let in2 = near[2] > (if in1 { near[1] } else { near[0] });
        let out1 = far[1] < far[0];
        let out2 = far[2] < (if out1 { far[1] } else { far[0] });
        let d_in = if in2 {
            dz
        } else if in1 {
            dy
        } else {
            dx
        };
        let d_out = if out2 {
            dz
        } else if out1 {
            dy
        } else {
            dx
        };
        let k_in: u64 = if in2 {
            4
        } else if in1 {
            2
        } else {
            0
        };
        let k_out: u64 = if out2 {
            4
        } else if out1 {
            2
        } else {
            0
        };
        let f_in = k_in + u64::from(d_in > 0.0);
        let f_out = k_out + u64::from(d_out < 0.0);
        // `first_crossing` on (0, t_max).
        let (e, x) = (t_in + t0, t_out + t0);
        let ordered = !(e > x);
        let take_e = ordered & (e > 0.0) & (e < t_max[l]);
        let take_x = ordered & (x > 0.0) & (x < t_max[l]);
        hit_w[l] = u64::from(take_e | take_x);
        out_t[l] = if take_e { e } else { x };
        part_w[l] = if take_e { f_in } else { f_out };
    }
    ObjectHits {
        hit: hit_w,
        t: out_t,
        part: part_w,
    }
}

/// Object `i`'s hits on `(0, t_max[l])`, each by the arithmetic of its
/// scalar test: in the lanes of `lanes` (a bit mask) and, where a SIMD
/// test is cheaper than picking lanes, in others too (a hit is a hit; the
/// mask only says which rays reach the object's box). Lanes in `skip`
/// never hit.
#[inline(always)]
fn test_object(scene: &Scene, i: u32, lanes: u32, skip: u32, p: &Packet, t_max: &Lanes<f64>) -> ObjectHits {
    let o = &scene.objects[i as usize];
    let drop_skipped = |mut h: ObjectHits| {
        if skip != 0 {
            for l in 0..LANES {
                h.hit[l] &= u64::from(skip >> l & 1 == 0);
            }
        }
        h
    };
    match &o.shape {
        Shape::Cuboid(c) if o.translation_only => drop_skipped(cuboid(o.position, 0.5 * c.size, p, t_max)),
        Shape::Lens(lens) if o.identity => {
            let h = lens.intersect_lanes(&p.o, &p.d, t_max);
            let mut out = ObjectHits {
                hit: h.hit.map(u64::from),
                t: h.t,
                part: h.part.map(u64::from),
            };
            // Origins far from the lens need the scalar test's exact start.
            for l in live_lanes(lanes & mask(&h.slow)) {
                if let Some(h) = lens.intersect(&p.ray(l), 0.0, t_max[l]) {
                    out.hit[l] = 1;
                    out.t[l] = h.t;
                    out.part[l] = u64::from(h.part);
                }
            }
            drop_skipped(out)
        }
        shape => {
            let mut out = ObjectHits {
                hit: [0; LANES],
                t: [0.0; LANES],
                part: [0; LANES],
            };
            for l in live_lanes(lanes) {
                if let Some(h) = shape.intersect(&o.to_object(&p.ray(l)), 0.0, t_max[l]) {
                    out.hit[l] = 1;
                    out.t[l] = h.t;
                    out.part[l] = u64::from(h.part);
                }
            }
            out
        }
    }
}

/// Walks the scene (its BVH, or every object's box) with the packet:
/// `visit(i, lanes, skipped, t_max)` tests object `i` in the lanes whose
/// rays reach its box (`lanes`, a bit mask), never in the lanes of
/// `skipped` (those whose `skip[l]` is `i`), and may shorten `t_max` (a
/// closer hit; −1 ends a lane). The walk ends when every lane
/// has ended. `SKIP` and `ANY` switch off the skip test and the check
/// for ended lanes where no lane skips or ends.
#[inline(always)]
fn walk<const SKIP: bool, const ANY: bool>(
    scene: &Scene,
    p: &Packet,
    skip: &Lanes<u32>,
    t_max: &mut Lanes<f64>,
    visitor: &mut impl Visitor,
) {
    let skipped = |i: u32| {
        if !SKIP {
            return 0;
        }
        let mut b = [false; LANES];
        for l in 0..LANES {
            b[l] = skip[l] == i;
        }
        mask(&b)
    };
    let alive = |t_max: &Lanes<f64>| {
        if !ANY {
            return true;
        }
        let mut b = [false; LANES];
        for l in 0..LANES {
            b[l] = t_max[l] >= 0.0;
        }
        mask(&b) != 0
    };
    match &scene.bvh {
        None => {
            for (i, o) in scene.objects.iter().enumerate() {
                let sk = skipped(i as u32);
                let m = slab(o.world_bounds.min, o.world_bounds.max, p, t_max) & !sk;
                if m != 0 {
                    visitor.visit(scene, p, i as u32, m, sk, t_max);
                    if !alive(t_max) {
                        return;
                    }
                }
            }
        }
        Some(bvh) => {
            struct Lanes8<'a, V, S, A> {
                scene: &'a Scene,
                prims: &'a [u32],
                p: &'a Packet,
                t_max: &'a mut Lanes<f64>,
                visitor: &'a mut V,
                skipped: S,
                alive: A,
                /// The lanes that reach the node just entered.
                m: u32,
            }
            impl<V: Visitor, S: Fn(u32) -> u32, A: Fn(&Lanes<f64>) -> bool> super::Walker for Lanes8<'_, V, S, A> {
                #[inline(always)]
                fn enters(&mut self, node: &super::Node) -> bool {
                    self.m = slab(node.min, node.max, self.p, self.t_max);
                    self.m != 0
                }
                #[inline(always)]
                fn leaf(&mut self, _: usize, node: &super::Node) -> bool {
                    for &o in node.prims(self.prims) {
                        let sk = (self.skipped)(o);
                        let lanes = self.m & !sk;
                        if lanes != 0 {
                            self.visitor.visit(self.scene, self.p, o, lanes, sk, self.t_max);
                        }
                    }
                    (self.alive)(self.t_max)
                }
            }
            // Children in the order of the first lane's direction: the rays
            // of a packet travel nearly alike.
            let neg = [p.inv[0][0] < 0.0, p.inv[1][0] < 0.0, p.inv[2][0] < 0.0];
            bvh.walk(
                neg,
                &mut Lanes8 {
                    scene,
                    prims: &bvh.prims,
                    p,
                    t_max,
                    visitor,
                    skipped,
                    alive,
                    m: 0,
                },
            );
        }
    }
}

/// What a walk does with the objects it reaches (a trait rather than a
/// closure, so that it is compiled inside the AVX2 build).
trait Visitor {
    /// Tests object `i` (see [`walk`]).
    fn visit(&mut self, scene: &Scene, p: &Packet, i: u32, lanes: u32, skipped: u32, t_max: &mut Lanes<f64>);
}

/// Closest hits: every hit shortens its lane.
struct Closest {
    part: Lanes<u64>,
    object: Lanes<u64>,
}

impl Closest {
    #[inline(always)]
    fn new() -> Closest {
        Closest {
            part: [0; LANES],
            object: [u64::from(NO_OBJECT); LANES],
        }
    }

    /// The hits found in packet `p`, narrowed to [`PacketHits`]; lanes
    /// past its length report none.
    #[inline(always)]
    fn hits(&self, p: &Packet, t_max: &Lanes<f64>) -> PacketHits {
        let mut h = PacketHits {
            object: self.object.map(|o| o as u32),
            t: *t_max,
            part: self.part.map(|p| p as u8),
        };
        for l in p.len..LANES {
            h.object[l] = NO_OBJECT;
        }
        h
    }
}

impl Visitor for Closest {
    #[inline(always)]
    fn visit(&mut self, scene: &Scene, p: &Packet, i: u32, lanes: u32, skipped: u32, t_max: &mut Lanes<f64>) {
        let h = test_object(scene, i, lanes, skipped, p, t_max);
        for l in 0..LANES {
            let hit = h.hit[l] != 0;
            t_max[l] = if hit { h.t[l] } else { t_max[l] };
            self.part[l] = if hit { h.part[l] } else { self.part[l] };
            self.object[l] = if hit { u64::from(i) } else { self.object[l] };
        }
    }
}

/// Shadow rays: every hit filters its lane's light, an opaque one ends it.
struct Shadow {
    light: Lanes<Rgb>,
}

impl Visitor for Shadow {
    #[inline(always)]
    fn visit(&mut self, scene: &Scene, p: &Packet, i: u32, lanes: u32, skipped: u32, t_max: &mut Lanes<f64>) {
        let h = test_object(scene, i, lanes, skipped, p, t_max);
        if h.hit.contains(&1) {
            let filter = scene.objects[i as usize].material.shadow_transmittance();
            for l in 0..LANES {
                if h.hit[l] != 0 {
                    self.light[l] *= filter;
                    if self.light[l] == Rgb::ZERO {
                        t_max[l] = -1.0;
                    }
                }
            }
        }
    }
}

#[inline(always)]
fn closest_hits_impl<const SKIP: bool>(scene: &Scene, p: &Packet, skip: &Lanes<u32>) -> PacketHits {
    let mut c = Closest::new();
    let mut t_max = p.t_max;
    walk::<SKIP, false>(scene, p, skip, &mut t_max, &mut c);
    c.hits(p, &t_max)
}

#[inline(always)]
fn closest_hits_skip_impl(scene: &Scene, p: &Packet, skip: &Lanes<u32>) -> PacketHits {
    closest_hits_impl::<true>(scene, p, skip)
}

/// [`crate::integrator::transmittance_skip`] in every lane: the light
/// reaching along each ray over `(0, t_max)`, zero once an opaque object is
/// met. (With several transparent objects on one ray the filters may be
/// multiplied in another order than the scalar walk's.)
#[inline(always)]
fn transmittances_impl(scene: &Scene, p: &Packet, skip: &Lanes<u32>) -> Lanes<Rgb> {
    let mut v = Shadow {
        light: [Rgb::ONE; LANES],
    };
    let mut t_max = p.t_max;
    walk::<true, true>(scene, p, skip, &mut t_max, &mut v);
    v.light
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
    let h = closest_hits_impl::<false>(scene, &p, &[NO_OBJECT; LANES]);
    (p, h)
}

/// Rows of camera packets in a tile ([`camera_tile_hits`]): a tile is
/// [`LANES`] pixels wide and this many tall. Sixteen rows took 8% fewer
/// instructions than eight for the primary rays of `cubes.toml` (callgrind).
pub const TILE: usize = 16;

/// Leaves a tile's frustum may reach before the tile falls back to one walk
/// per packet.
const TILE_LEAVES: usize = 48;

/// The packets of a tile and their closest hits; the first `len` are used.
#[derive(Clone, Copy, Debug)]
pub struct CameraTile {
    pub packets: [Packet; TILE],
    pub hits: [PacketHits; TILE],
    pub len: usize,
}

/// What every ray of a tile shares: the origin and, per axis, the sign and
/// the range of the reciprocal direction.
struct Frustum {
    o: DVec3,
    inv_lo: [f64; 3],
    inv_hi: [f64; 3],
    neg: [bool; 3],
}

impl Frustum {
    /// The frustum of camera packets (all from one origin, unused lanes
    /// repeating lane 0), or `None` when some axis changes sign or meets an
    /// infinite or NaN reciprocal.
    #[inline(always)]
    fn of(packets: &[Packet]) -> Option<Frustum> {
        // Over all lanes (a camera packet's unused lanes repeat lane 0), as
        // plain lane loops. The sum is not finite if any reciprocal is
        // infinite or NaN (NaN would slip through the comparisons).
        let mut lo = [[f64::INFINITY; LANES]; 3];
        let mut hi = [[f64::NEG_INFINITY; LANES]; 3];
        let mut sum = [[0.0; LANES]; 3];
        for p in packets {
            for k in 0..3 {
                for l in 0..LANES {
                    let v = p.inv[k][l];
                    lo[k][l] = gmin(lo[k][l], v);
                    hi[k][l] = gmax(hi[k][l], v);
                    sum[k][l] += v;
                }
            }
        }
        if !sum.iter().flatten().sum::<f64>().is_finite() {
            return None;
        }
        let mut inv_lo = [0.0; 3];
        let mut inv_hi = [0.0; 3];
        let mut neg = [false; 3];
        for k in 0..3 {
            let (lo, hi) = (
                lo[k].into_iter().fold(f64::INFINITY, gmin),
                hi[k].into_iter().fold(f64::NEG_INFINITY, gmax),
            );
            if !(lo.is_finite() && hi.is_finite() && (lo > 0.0 || hi < 0.0)) {
                return None;
            }
            (inv_lo[k], inv_hi[k]) = (lo, hi);
            neg[k] = hi < 0.0;
        }
        let p = &packets[0];
        Some(Frustum {
            o: DVec3::new(p.o[0][0], p.o[1][0], p.o[2][0]),
            inv_lo,
            inv_hi,
            neg,
        })
    }

    /// Whether some ray of the tile may pass [`slab`] for the box: the
    /// box test in interval arithmetic. For one face `b − o` is the same
    /// number in every lane and a rounded product is monotonic in the
    /// other factor, so each lane's entry and exit distances lie between
    /// the products with the two ends of the reciprocal's range: if any
    /// lane passes, this passes.
    #[inline(always)]
    fn reaches(&self, min: DVec3, max: DVec3) -> bool {
        let mut near = [0.0; 3];
        let mut far = [0.0; 3];
        for k in 0..3 {
            let (b0, b1) = (min[k] - self.o[k], max[k] - self.o[k]);
            let (a, b, c, d) = (
                b0 * self.inv_lo[k],
                b0 * self.inv_hi[k],
                b1 * self.inv_lo[k],
                b1 * self.inv_hi[k],
            );
            near[k] = gmin(gmin(a, b), gmin(c, d));
            far[k] = gmax(gmax(a, b), gmax(c, d));
        }
        let lo = gmax(gmax(near[0], gmax(near[1], near[2])), 0.0);
        let hi = gmin(far[0], gmin(far[1], far[2]));
        lo <= hi * (1.0 + 4.0 * f64::EPSILON)
    }
}

/// The leaves (node indices) the frustum reaches, in the order the packet
/// walk visits them, or `None` past [`TILE_LEAVES`].
#[inline(always)]
fn tile_leaves(bvh: &super::Bvh, f: &Frustum, out: &mut [u32; TILE_LEAVES]) -> Option<usize> {
    struct List<'a> {
        f: &'a Frustum,
        out: &'a mut [u32; TILE_LEAVES],
        n: usize,
        full: bool,
    }
    impl super::Walker for List<'_> {
        #[inline(always)]
        fn enters(&mut self, node: &super::Node) -> bool {
            self.f.reaches(node.min, node.max)
        }
        #[inline(always)]
        fn leaf(&mut self, index: usize, _: &super::Node) -> bool {
            if self.n == TILE_LEAVES {
                self.full = true;
                return false;
            }
            self.out[self.n] = index as u32;
            self.n += 1;
            true
        }
    }
    let mut list = List {
        f,
        out,
        n: 0,
        full: false,
    };
    bvh.walk(f.neg, &mut list);
    (!list.full).then_some(list.n)
}

#[inline(always)]
fn camera_tile_hits_impl(
    scene: &Scene,
    xs: &[Lanes<f64>],
    ys: &[Lanes<f64>],
    n: &[usize],
    width: u32,
    height: u32,
    tile: &mut CameraTile,
) {
    let len = n.len();
    assert!(
        (1..=TILE).contains(&len) && xs.len() == len && ys.len() == len,
        "a tile holds 1 to {TILE} packets"
    );
    tile.len = len;
    for r in 0..len {
        tile.packets[r].set_camera(&scene.camera, &xs[r], &ys[r], n[r], width, height);
    }
    let mut leaves = [0u32; TILE_LEAVES];
    let list = match (&scene.bvh, Frustum::of(&tile.packets[..len])) {
        (Some(bvh), Some(f)) if !bvh.nodes.is_empty() => tile_leaves(bvh, &f, &mut leaves).map(|n| (bvh, n)),
        _ => None,
    };
    let Some((bvh, count)) = list else {
        for r in 0..len {
            tile.hits[r] = closest_hits_impl::<false>(scene, &tile.packets[r], &[NO_OBJECT; LANES]);
        }
        return;
    };
    for r in 0..len {
        let p = &tile.packets[r];
        let mut c = Closest::new();
        let mut t_max = p.t_max;
        for &i in &leaves[..count] {
            let node = &bvh.nodes[i as usize];
            let m = slab(node.min, node.max, p, &t_max);
            if m != 0 {
                for &o in node.prims(&bvh.prims) {
                    c.visit(scene, p, o, m, 0, &mut t_max);
                }
            }
        }
        tile.hits[r] = c.hits(p, &t_max);
    }
}

impl Default for CameraTile {
    fn default() -> CameraTile {
        let p = Packet {
            o: [[0.0; LANES]; 3],
            d: [[0.0; LANES]; 3],
            inv: [[0.0; LANES]; 3],
            t_max: [-1.0; LANES],
            len: 0,
        };
        CameraTile {
            packets: [p; TILE],
            hits: [PacketHits {
                object: [NO_OBJECT; LANES],
                t: [0.0; LANES],
                part: [0; LANES],
            }; TILE],
            len: 0,
        }
    }
}

/// Compiles each `*_impl` function a second time with AVX2 enabled, and
/// defines the public function that picks the build at run time.
macro_rules! with_avx2 {
    ($(#[$doc:meta])* $vis:vis fn $name:ident / $avx2:ident => $imp:ident ($($arg:ident: $ty:ty),*) -> $ret:ty) => {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2")]
        fn $avx2($($arg: $ty),*) -> $ret {
            $imp($($arg),*)
        }

        $(#[$doc])*
        $vis fn $name($($arg: $ty),*) -> $ret {
            #[cfg(target_arch = "x86_64")]
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: the AVX2 build differs from the portable one only
                // in being compiled with AVX2 instructions, and the line
                // above has just checked that this CPU has them. Calling a
                // `target_feature` function needs `unsafe` in Rust; nothing
                // else here is unchecked.
                return unsafe { $avx2($($arg),*) };
            }
            $imp($($arg),*)
        }
    };
}

pub(crate) use with_avx2;

with_avx2! {
    /// The closest hit of every ray of the packet (lanes past its length
    /// report none); lane `l` never meets object `skip[l]` ([`NO_OBJECT`]
    /// for none).
    pub fn closest_hits / closest_hits_avx2 => closest_hits_skip_impl(scene: &Scene, p: &Packet, skip: &Lanes<u32>) -> PacketHits
}

with_avx2! {
    /// The light reaching along every ray of the packet, each to its
    /// `t_max` (lane `l` never meets object `skip[l]`).
    pub fn transmittances / transmittances_avx2 => transmittances_impl(scene: &Scene, p: &Packet, skip: &Lanes<u32>) -> Lanes<Rgb>
}

with_avx2! {
    /// The primary rays of a `width × height` image through the continuous
    /// pixel positions `(xs[l], ys[l])`, `l < n` (1 ..= [`LANES`]), and
    /// their closest hits: the rays are exactly [`Camera::ray`]'s.
    pub fn camera_hits / camera_hits_avx2 => camera_hits_impl(
        scene: &Scene,
        xs: &Lanes<f64>,
        ys: &Lanes<f64>,
        n: usize,
        width: u32,
        height: u32
    ) -> (Packet, PacketHits)
}

with_avx2! {
    /// The primary rays of up to [`TILE`] packets (packet `r` through
    /// `(xs[r][l], ys[r][l])`, `l < n[r]`), as [`camera_hits`] gives them,
    /// found with one walk of the tile's frustum: the BVH leaves it reaches
    /// are listed once, and each packet tests only those. Fills `tile`.
    pub fn camera_tile_hits / camera_tile_hits_avx2 => camera_tile_hits_impl(
        scene: &Scene,
        xs: &[Lanes<f64>],
        ys: &[Lanes<f64>],
        n: &[usize],
        width: u32,
        height: u32,
        tile: &mut CameraTile
    ) -> ()
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

/// The portable (SSE2) build of [`closest_hits`], for tests on any CPU.
pub fn closest_hits_portable(scene: &Scene, p: &Packet, skip: &Lanes<u32>) -> PacketHits {
    closest_hits_impl::<true>(scene, p, skip)
}

/// The portable build of [`transmittances`].
pub fn transmittances_portable(scene: &Scene, p: &Packet, skip: &Lanes<u32>) -> Lanes<Rgb> {
    transmittances_impl(scene, p, skip)
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
    fn check(hits: fn(&Scene, &Packet, &Lanes<u32>) -> PacketHits) {
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
                let got = hits(&scene, &Packet::new(&rays, f64::INFINITY), &[NO_OBJECT; LANES]);
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

    /// Tiles give every packet exactly what walking the packet alone gives
    /// it: whole and partial tiles, jittered rays, cameras that look along
    /// an axis (a reciprocal changes sign or is infinite inside a tile, so
    /// the tile falls back), from inside the scene, and a scene whose
    /// tiles reach more leaves than a tile lists.
    type TileHits = fn(&Scene, &[Lanes<f64>], &[Lanes<f64>], &[usize], u32, u32, &mut CameraTile);

    fn check_tiles(tile_hits: TileHits) {
        let mut cases = scenes();
        let (sf, _) = Scene::default_scene();
        for (name, pos, rot) in [
            ("straight down", [0.0, 8.0, 0.0], [-90.0, 0.0, 0.0]),
            ("along −z", [0.0, 0.5, 9.0], [0.0, 0.0, 0.0]),
            ("inside, rolled", [0.3, 0.6, 0.2], [-10.0, 33.0, 20.0]),
        ] {
            let mut f = sf.clone();
            f.camera.position = pos;
            f.camera.rotation = Some(rot);
            f.camera.look_at = None;
            cases.push((name, Scene::build(&f).unwrap()));
        }
        let (mut tiled, mut fell_back, mut compared) = (0, 0, 0);
        for (name, scene) in &cases {
            let (w, h) = (101, 75);
            let mut s = Sampler::new(11, 2, 0);
            let mut tile = CameraTile::default();
            for y0 in (0..h).step_by(TILE) {
                let rows = (h - y0).min(TILE);
                for x0 in (0..w).step_by(LANES) {
                    let n = (w - x0).min(LANES);
                    let jitter = (x0 / LANES) % 2 == 1;
                    let mut xs = [[0.0; LANES]; TILE];
                    let mut ys = [[0.0; LANES]; TILE];
                    for r in 0..rows {
                        for l in 0..n {
                            let (jx, jy) = if jitter { s.next_2d() } else { (0.5, 0.5) };
                            xs[r][l] = (x0 + l) as f64 + jx;
                            ys[r][l] = (y0 + r) as f64 + jy;
                        }
                    }
                    let ns = [n; TILE];
                    tile_hits(
                        scene,
                        &xs[..rows],
                        &ys[..rows],
                        &ns[..rows],
                        w as u32,
                        h as u32,
                        &mut tile,
                    );
                    assert_eq!(tile.len, rows);
                    let frustum = Frustum::of(&tile.packets[..rows]).is_some();
                    if frustum && scene.bvh.is_some() {
                        tiled += 1;
                    } else {
                        fell_back += 1;
                    }
                    for r in 0..rows {
                        let (p, want) = camera_hits(scene, &xs[r], &ys[r], n, w as u32, h as u32);
                        assert_eq!(tile.packets[r].d, p.d, "{name}: tile ({x0}, {y0}) row {r}");
                        for l in 0..LANES {
                            assert_eq!(
                                tile.hits[r].get(l),
                                want.get(l),
                                "{name}: tile ({x0}, {y0}) row {r} lane {l}"
                            );
                            compared += usize::from(l < n && want.get(l).is_some());
                        }
                    }
                }
            }
        }
        assert!(
            tiled > 200 && fell_back > 20 && compared > 40_000,
            "{tiled} tiled, {fell_back} fell back, {compared} hits"
        );
    }

    #[test]
    fn tiles_give_each_packet_its_own_hits() {
        check_tiles(camera_tile_hits);
    }

    #[test]
    fn portable_tiles_give_each_packet_its_own_hits() {
        check_tiles(camera_tile_hits_impl);
    }

    #[test]
    fn a_tile_that_reaches_more_leaves_than_it_lists_falls_back() {
        let (sf, _) = Scene::default_scene();
        let scene = crate::bench::cubes_grid(&sf, 50);
        let bvh = scene.bvh.as_ref().unwrap();
        // The right half of the view in one tile: every leaf in sight.
        let xs = [std::array::from_fn(|l| 205.0 + l as f64 * 27.0); TILE];
        let ys: [Lanes<f64>; TILE] = std::array::from_fn(|r| [r as f64 * 57.0; LANES]);
        let mut tile = CameraTile::default();
        camera_tile_hits(&scene, &xs, &ys, &[LANES; TILE], 400, 400, &mut tile);
        let f = Frustum::of(&tile.packets).unwrap();
        assert!(tile_leaves(bvh, &f, &mut [0; TILE_LEAVES]).is_none());
        for r in 0..TILE {
            let (_, want) = camera_hits(&scene, &xs[r], &ys[r], LANES, 400, 400);
            assert_eq!(tile.hits[r], want);
        }
    }

    #[test]
    fn mask_sets_bit_l_for_lane_l() {
        for m in 0u32..256 {
            let b: Lanes<bool> = std::array::from_fn(|l| m >> l & 1 != 0);
            assert_eq!(mask(&b), m);
        }
    }

    /// Shadow-like rays (random segments, some lanes skipping an object,
    /// some unused) give the scalar transmittance, and closest hits with
    /// skips give the scalar `closest_hit_skip`.
    fn check_skips(
        shadow: fn(&Scene, &Packet, &Lanes<u32>) -> Lanes<Rgb>,
        closest: fn(&Scene, &Packet, &Lanes<u32>) -> PacketHits,
    ) {
        use crate::integrator::{closest_hit_skip, transmittance_skip};
        for (name, scene) in scenes() {
            let mut s = Sampler::new(3, 1, 0);
            let (mut blocked, mut open) = (0, 0);
            for k in 0..1500 {
                let mut rays = [Ray {
                    origin: DVec3::ZERO,
                    dir: DVec3::X,
                }; LANES];
                let mut t_max = [-1.0; LANES];
                let mut skip = [NO_OBJECT; LANES];
                for l in 0..LANES {
                    let o =
                        DVec3::new(s.next_f64(), s.next_f64() * 0.6, s.next_f64()) * 12.0 - DVec3::new(6.0, 0.5, 6.0);
                    let to =
                        DVec3::new(5.0, 10.0, 6.0) + (DVec3::new(s.next_f64(), s.next_f64(), s.next_f64()) - 0.5) * 4.0;
                    rays[l] = Ray::new(o, to - o);
                    if (k + l) % 5 != 0 {
                        t_max[l] = (to - o).length();
                    }
                    if (k + l) % 3 == 0 {
                        skip[l] = (s.next_f64() * scene.objects.len() as f64) as u32;
                    }
                }
                let p = Packet::with_limits(&rays, &t_max);
                let got = shadow(&scene, &p, &skip);
                let hits = closest(&scene, &p, &skip);
                for l in 0..LANES {
                    if t_max[l] < 0.0 {
                        assert_eq!(got[l], Rgb::ONE);
                        assert!(hits.get(l).is_none());
                        continue;
                    }
                    let sk = if skip[l] == NO_OBJECT {
                        usize::MAX
                    } else {
                        skip[l] as usize
                    };
                    let want = transmittance_skip(&scene, &rays[l], t_max[l], sk);
                    assert!(
                        (got[l] - want).abs().max_element() <= 1e-15,
                        "{name}: packet {k} lane {l}"
                    );
                    if want == Rgb::ONE {
                        open += 1;
                    } else {
                        blocked += 1;
                    }
                    let want = closest_hit_skip(&scene, &rays[l], t_max[l], sk);
                    assert_eq!(
                        want.map(|h| h.1.t),
                        hits.get(l).map(|h| h.1.t),
                        "{name}: packet {k} lane {l}"
                    );
                }
            }
            assert!(blocked > 500 && open > 500, "{name}: {blocked} blocked, {open} open");
        }
    }

    #[test]
    fn shadow_packets_give_the_scalar_transmittance() {
        check_skips(transmittances, closest_hits);
    }

    #[test]
    fn portable_shadow_packets_give_the_scalar_transmittance() {
        check_skips(transmittances_portable, closest_hits_portable);
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
