//! Camera rays: packets of primary rays ([`camera_hits`]) and tiles of
//! [`TILE`] such packets that walk the BVH once for all
//! ([`camera_tile_hits`]): the tile's frustum (`Frustum`) lists the
//! leaves any of its rays may reach, and each packet tests only those.

// Lane loops index several arrays by the lane: the form the vectoriser wants.
#![allow(clippy::needless_range_loop)]

use super::NO_OBJECT;
use super::packet::{Closest, Packet, PacketHits, Visitor, closest_hits_impl, slab};
use crate::accel::{Bvh, Node, Walker};
use crate::camera::Camera;
use crate::geometry::slab_overlap;
use crate::scene::Scene;
use crate::simd::{LANES, Lanes, gmax, gmin, with_avx2};
use glam::DVec3;

impl Packet {
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
        // plain lane loops. `v · 0` is NaN where a reciprocal is infinite
        // or NaN (NaN would slip through the comparisons), and zero
        // elsewhere: summed per lane and each sum compared with zero, not
        // added up in order, so that the sums stay vector registers (an
        // ordered sum of all 24 kept them as numbers one by one: the
        // frustum was a sixth of a tile's walk, `perf`).
        let mut lo = [[f64::INFINITY; LANES]; 3];
        let mut hi = [[f64::NEG_INFINITY; LANES]; 3];
        let mut bad = [[0.0; LANES]; 3];
        for p in packets {
            for k in 0..3 {
                for l in 0..LANES {
                    let v = p.inv[k][l];
                    lo[k][l] = gmin(lo[k][l], v);
                    hi[k][l] = gmax(hi[k][l], v);
                    bad[k][l] += v * 0.0;
                }
            }
        }
        if !bad.iter().flatten().all(|b| *b == 0.0) {
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
        slab_overlap(lo, hi)
    }
}

/// The leaves (node indices) the frustum reaches, in the order the packet
/// walk visits them, or `None` past [`TILE_LEAVES`].
#[inline(always)]
fn tile_leaves(bvh: &Bvh, f: &Frustum, out: &mut [u32; TILE_LEAVES]) -> Option<usize> {
    struct List<'a> {
        f: &'a Frustum,
        out: &'a mut [u32; TILE_LEAVES],
        n: usize,
        full: bool,
    }
    impl Walker for List<'_> {
        #[inline(always)]
        fn enters(&mut self, node: &Node) -> bool {
            self.f.reaches(node.min, node.max)
        }
        #[inline(always)]
        fn leaf(&mut self, index: usize, _: &Node) -> bool {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Sampler;
    use crate::trace::packet::tests::scenes;

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
}
