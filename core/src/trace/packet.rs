//! Coherent ray packets: eight rays walk the BVH together.
//!
//! Rays of neighbouring pixels pass through the same boxes, so a packet
//! pays for one walk and one branch per node instead of eight, and each
//! box test runs over eight lanes at once ([`crate::simd`]: the walks are
//! compiled twice, for AVX2 and SSE2, and picked at run time).
//!
//! Every lane computes exactly what the scalar walk
//! ([`super::closest_hit`]) computes for its ray, with the same operations
//! in the same order: the box test ([`crate::geometry::slab_hit`]), and
//! for a cuboid without rotation and for the lens their lane tests
//! ([`crate::geometry::Cuboid::intersect_lanes`], `Lens::intersect_lanes`),
//! which share their arithmetic with the scalar tests; every other shape is
//! tested by its own scalar code, lane by lane. So a packet gives the
//! scalar answer, bit for bit, except that two objects hit at exactly the
//! same distance may be named in another order.

// Lane loops index several arrays by the lane: the form the vectoriser wants.
#![allow(clippy::needless_range_loop)]

use super::NO_OBJECT;
use crate::accel::{Node, Walker};
use crate::color::Rgb;
use crate::geometry::{Hit, Shape, WideHits, slab_hit};
use crate::math::Ray;
use crate::scene::Scene;
use crate::simd::{LANES, Lanes, lane, live_lanes, mask, with_avx2};
use glam::DVec3;

/// Up to [`LANES`] rays in structure-of-arrays form. Unused lanes are
/// copies of a used lane with an empty interval, so they never hit anything.
#[derive(Clone, Copy, Debug)]
pub struct Packet {
    pub(super) o: [Lanes<f64>; 3],
    pub(super) d: [Lanes<f64>; 3],
    pub(super) inv: [Lanes<f64>; 3],
    pub(super) t_max: Lanes<f64>,
    pub(super) len: usize,
}

impl Packet {
    /// A packet of `rays` (1 ..= [`LANES`] of them; directions unit), each
    /// searched on `(0, t_max)`.
    pub fn new(rays: &[Ray], t_max: f64) -> Packet {
        Self::with_limits(rays, &[t_max; LANES])
    }

    /// A packet to fill lane by lane in place ([`Packet::set`], then
    /// [`Packet::fill_unused`], which sets every lane not set and every
    /// lane's inverse direction): no array of
    /// rays to build and copy first. Its lanes mean nothing until then.
    pub const EMPTY: Packet = Packet {
        o: [[0.0; LANES]; 3],
        d: [[0.0; LANES]; 3],
        inv: [[0.0; LANES]; 3],
        t_max: [0.0; LANES],
        len: LANES,
    };

    /// Sets lane `l` to `ray` (unit direction), searched on `(0, t_max)`
    /// (an empty interval when `t_max` is negative); its inverse direction
    /// is computed by [`Packet::fill_unused`].
    #[inline(always)]
    pub fn set(&mut self, l: usize, ray: &Ray, t_max: f64) {
        for k in 0..3 {
            self.o[k][l] = ray.origin[k];
            self.d[k][l] = ray.dir[k];
        }
        self.t_max[l] = t_max;
    }

    /// Every lane's inverse direction from its direction, all lanes at once
    /// (what `DVec3::recip` gives lane by lane): computed only for the packets
    /// that are traced ([`Packet::fill_unused`]), not per ray as it is set, so
    /// that the rays gathered and then traced one by one or found to leave
    /// the scene pay no division.
    #[inline(always)]
    fn invert(&mut self) {
        for k in 0..3 {
            for l in 0..LANES {
                self.inv[k][l] = 1.0 / self.d[k][l];
            }
        }
    }

    /// Makes every lane outside the bit mask `live` (not empty) a copy of
    /// its first lane with an empty interval, so that it never hits, and
    /// computes every lane's inverse direction: the packet is ready to trace.
    #[inline(always)]
    pub fn fill_unused(&mut self, live: u32) {
        debug_assert!(live != 0 && live < 1 << LANES);
        let first = live.trailing_zeros() as usize;
        for l in 0..LANES {
            if live >> l & 1 == 0 {
                for k in 0..3 {
                    self.o[k][l] = self.o[k][first];
                    self.d[k][l] = self.d[k][first];
                }
                self.t_max[l] = -1.0;
            }
        }
        self.invert();
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
        p.invert();
        p.len = rays.len();
        p
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

    /// Lane `l`'s inverse direction (`DVec3::recip` of its direction), once
    /// [`Packet::fill_unused`] has computed every lane's.
    #[inline]
    pub fn inv_dir(&self, l: usize) -> DVec3 {
        DVec3::new(self.inv[0][l], self.inv[1][l], self.inv[2][l])
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
/// distance and part, as [`super::closest_hit`] gives them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PacketHits {
    pub object: Lanes<u32>,
    pub t: Lanes<f64>,
    pub part: Lanes<u8>,
}

impl PacketHits {
    /// Lane `l`'s hit in the form of [`super::closest_hit`].
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

/// Hits of one object in a packet's lanes.
type ObjectHits = WideHits<LANES>;

/// The BVH box test of every lane, as a bit mask.
#[inline(always)]
pub(crate) fn slab(min: DVec3, max: DVec3, p: &Packet, t_max: &Lanes<f64>) -> u32 {
    let mut hit = [false; LANES];
    for l in 0..LANES {
        hit[l] = slab_hit(min, max, lane(&p.o, l), lane(&p.inv, l), 0.0, t_max[l]);
    }
    mask(&hit)
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
        Shape::Cuboid(c) if o.translation_only => {
            drop_skipped(c.intersect_lanes(o.position, &p.o, &p.d, &p.inv, t_max))
        }
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
/// `visitor` tests object `i` in the lanes whose rays reach its box
/// (`lanes`, a bit mask), never in the lanes of `skipped` (those whose
/// `skip[l]` is `i`), and may shorten `t_max` (a closer hit; −1 ends a
/// lane). The walk ends when every lane has ended. `SKIP` and `ANY` switch
/// off the skip test and the check for ended lanes where no lane skips or
/// ends.
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
    let Some(bvh) = &scene.bvh else {
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
        return;
    };
    // Children in the order of the first lane's direction: the rays of a
    // packet travel nearly alike.
    let neg = [p.inv[0][0] < 0.0, p.inv[1][0] < 0.0, p.inv[2][0] < 0.0];
    bvh.walk(
        neg,
        &mut PacketWalk {
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

/// [`walk`] through the BVH: what it does at each node.
struct PacketWalk<'a, V, S, A> {
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

impl<V: Visitor, S: Fn(u32) -> u32, A: Fn(&Lanes<f64>) -> bool> Walker for PacketWalk<'_, V, S, A> {
    #[inline(always)]
    fn enters(&mut self, node: &Node) -> bool {
        self.m = slab(node.min, node.max, self.p, self.t_max);
        self.m != 0
    }

    #[inline(always)]
    fn leaf(&mut self, _: usize, node: &Node) -> bool {
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

/// What a walk does with the objects it reaches (a trait rather than a
/// closure, so that it is compiled inside the AVX2 build).
pub(super) trait Visitor {
    /// Tests object `i` (see [`walk`]).
    fn visit(&mut self, scene: &Scene, p: &Packet, i: u32, lanes: u32, skipped: u32, t_max: &mut Lanes<f64>);
}

/// Closest hits: every hit shortens its lane.
pub(super) struct Closest {
    part: Lanes<u64>,
    object: Lanes<u64>,
}

impl Closest {
    #[inline(always)]
    pub(super) fn new() -> Closest {
        Closest {
            part: [0; LANES],
            object: [u64::from(NO_OBJECT); LANES],
        }
    }

    /// The hits found in packet `p`, narrowed to [`PacketHits`]; lanes
    /// past its length report none.
    #[inline(always)]
    pub(super) fn hits(&self, p: &Packet, t_max: &Lanes<f64>) -> PacketHits {
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
            let filter = scene.shadow_filter(i as usize);
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
pub(super) fn closest_hits_impl<const SKIP: bool>(scene: &Scene, p: &Packet, skip: &Lanes<u32>) -> PacketHits {
    let mut c = Closest::new();
    let mut t_max = p.t_max;
    walk::<SKIP, false>(scene, p, skip, &mut t_max, &mut c);
    c.hits(p, &t_max)
}

#[inline(always)]
fn closest_hits_skip_impl(scene: &Scene, p: &Packet, skip: &Lanes<u32>) -> PacketHits {
    closest_hits_impl::<true>(scene, p, skip)
}

/// [`super::transmittance_skip`] in every lane: the light
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

/// The portable (SSE2) build of [`closest_hits`], for tests on any CPU.
pub fn closest_hits_portable(scene: &Scene, p: &Packet, skip: &Lanes<u32>) -> PacketHits {
    closest_hits_impl::<true>(scene, p, skip)
}

/// The portable build of [`transmittances`].
pub fn transmittances_portable(scene: &Scene, p: &Packet, skip: &Lanes<u32>) -> Lanes<Rgb> {
    transmittances_impl(scene, p, skip)
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::sampling::Sampler;
    use crate::simd::LANES;
    use crate::trace::closest_hit;

    /// The scenes the packet and tile tests run on.
    pub(in crate::trace) fn scenes() -> Vec<(&'static str, Scene)> {
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
                parse("primitives", include_str!("../../../scenes/primitives.toml")),
            ),
            (
                "optical bench",
                parse("optical bench", include_str!("../../../scenes/optical-bench.toml")),
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

    /// Shadow-like rays (random segments, some lanes skipping an object,
    /// some unused) give the scalar transmittance, and closest hits with
    /// skips give the scalar `closest_hit_skip`.
    fn check_skips(
        shadow: fn(&Scene, &Packet, &Lanes<u32>) -> Lanes<Rgb>,
        closest: fn(&Scene, &Packet, &Lanes<u32>) -> PacketHits,
    ) {
        use crate::trace::{closest_hit_skip, transmittance_skip};
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
