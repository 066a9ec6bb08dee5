//! Camera samples at scattered points of the image (the pixels an adaptive
//! wave refines, the holes a reprojection leaves), gathered eight to a
//! packet and up to [`TILE`] packets to a tile, so they are cast exactly as
//! [`super::add_band_samples`] casts whole rows: every sample gets what
//! [`super::sample`] gives it, bit for bit, however the points are grouped
//! (through a lens camera, what [`sample_packet`] gives it).

use super::{BandMemory, sample_packet, shade_camera_packet};
use crate::color::Rgb;
use crate::integrator::Lit;
use crate::scene::Scene;
use crate::simd::LANES;
use crate::simd::Lanes;
use crate::trace::{NO_OBJECT, Packet, PacketHits, TILE, camera_tile_hits};
use glam::DVec3;

/// What the ray through a pixel's centre met first, kept for reprojection:
/// what it was ([`Seen`]) and, for a point, its depth along the camera's
/// axis (the point is the centre ray's direction scaled to depth 1 times
/// it; for the background, the direction alone). Packed in four bytes, the
/// depth's `f32` bits (positive) with the class in the two low bits (at
/// sixteen bytes, the point itself, the traffic cost about a tenth of a
/// first sample stage when that stage wrote them).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct FirstHit(u32);

impl Default for FirstHit {
    fn default() -> Self {
        FirstHit::UNKNOWN
    }
}

/// Whether a pixel's colour may be moved to another view (the values are
/// [`FirstHit`]'s two low bits).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Seen {
    /// Nothing known (a block preview, a pixel filled from a coarse level).
    #[default]
    Unknown = 3,
    /// A surface whose colour does not depend on the view's position
    /// (Phong highlights aside).
    Surface = 0,
    /// The background.
    Sky = 1,
    /// Glass or a mirror: what it shows moves differently from the surface.
    Specular = 2,
}

impl FirstHit {
    /// Nothing known.
    pub const UNKNOWN: FirstHit = FirstHit(Seen::Unknown as u32);

    /// `seen` at depth `depth` along the view's axis (positive; the two
    /// lowest bits of its `f32` are dropped, a relative change below
    /// 5e-7; not kept for [`Seen::Sky`] and [`Seen::Unknown`]).
    #[inline(always)]
    pub fn new(seen: Seen, depth: f32) -> FirstHit {
        let bits = match seen {
            Seen::Surface | Seen::Specular => depth.to_bits() & !3,
            Seen::Sky | Seen::Unknown => 0,
        };
        FirstHit(bits | seen as u32)
    }

    /// What the centre ray met.
    #[inline(always)]
    pub fn seen(self) -> Seen {
        match self.0 & 3 {
            0 => Seen::Surface,
            1 => Seen::Sky,
            2 => Seen::Specular,
            _ => Seen::Unknown,
        }
    }

    /// The point's depth along the view's axis (0 for the background and
    /// for nothing known).
    #[inline(always)]
    pub fn depth(self) -> f32 {
        f32::from_bits(self.0 & !3)
    }

    /// Lane `l` of a camera packet and its closest hits.
    #[inline]
    pub(crate) fn of(scene: &Scene, p: &Packet, hits: &PacketHits, l: usize) -> FirstHit {
        FirstHit::at(scene, scene.camera.forward(), p.dirs(), hits, l)
    }

    /// [`FirstHit::of`] for lanes `0 .. out.len()` of a camera packet (what
    /// [`super::band_first_hits`] records, the rays cast but not shaded).
    #[inline]
    pub(crate) fn lanes(scene: &Scene, p: &Packet, hits: &PacketHits, out: &mut [FirstHit]) {
        let (axis, d) = (scene.camera.forward(), p.dirs());
        for (l, f) in out.iter_mut().enumerate() {
            *f = FirstHit::at(scene, axis, d, hits, l);
        }
    }

    /// Lane `l` (of unit directions `d`; `axis`, the camera's): the
    /// background when it met nothing, else what it met and the depth of
    /// the hit along `axis`. The directions stay in lanes (no ray is built
    /// per pixel).
    #[inline(always)]
    fn at(scene: &Scene, axis: DVec3, d: &[Lanes<f64>; 3], hits: &PacketHits, l: usize) -> FirstHit {
        match hits.object[l] {
            NO_OBJECT => FirstHit::new(Seen::Sky, 0.0),
            o => {
                let m = &scene.objects[o as usize].material;
                let specular = m.transparency > 0.0 || m.reflectivity > 0.0;
                let cos = d[0][l] * axis.x + d[1][l] * axis.y + d[2][l] * axis.z;
                let seen = if specular { Seen::Specular } else { Seen::Surface };
                FirstHit::new(seen, (hits.t[l] * cos) as f32)
            }
        }
    }
}

/// Points waiting to be cast, and where their results go.
pub(crate) struct Batch {
    xs: [[f64; LANES]; TILE],
    ys: [[f64; LANES]; TILE],
    dst: [[u32; LANES]; TILE],
    /// What each point's gather counts for (`Lit::with_lane_weights`: 0
    /// for none, 1 unless thinned), read only where `weighted`.
    weights: [[u32; LANES]; TILE],
    /// Whether a point pushed since the last cast counts other than once.
    weighted: bool,
    /// Points in the packet being filled (packet `rows`).
    lane: usize,
    /// Full packets before it.
    rows: usize,
    memory: BandMemory,
    shaded: [Rgb; LANES],
}

impl Default for Batch {
    fn default() -> Batch {
        Batch {
            xs: [[0.0; LANES]; TILE],
            ys: [[0.0; LANES]; TILE],
            dst: [[0; LANES]; TILE],
            weights: [[1; LANES]; TILE],
            weighted: false,
            lane: 0,
            rows: 0,
            memory: BandMemory::default(),
            shaded: [Rgb::ZERO; LANES],
        }
    }
}

/// Where a batch's results go: `sink(dst, colour, first hit)`, called in
/// the order the points were pushed.
pub(crate) trait Sink: FnMut(u32, Rgb, &dyn Fn() -> FirstHit) {}
impl<F: FnMut(u32, Rgb, &dyn Fn() -> FirstHit)> Sink for F {}

impl Batch {
    /// Adds the camera sample at continuous position `(x, y)` whose result
    /// goes to `dst`; casts the tile when it is full.
    #[inline]
    pub fn push(&mut self, scene: &Lit, size: (u32, u32), at: (f64, f64), dst: u32, sink: &mut impl Sink) {
        self.push_weighted(scene, size, (at, 1), dst, sink);
    }

    /// [`Batch::push`] of a camera sample whose gather counts `weight`
    /// times (0: it gathers nothing; `Lit::for_sample`'s thinning, sample
    /// by sample).
    #[inline(always)]
    pub fn push_weighted(
        &mut self,
        scene: &Lit,
        (w, h): (u32, u32),
        ((x, y), weight): ((f64, f64), u32),
        dst: u32,
        sink: &mut impl Sink,
    ) {
        self.xs[self.rows][self.lane] = x;
        self.ys[self.rows][self.lane] = y;
        self.dst[self.rows][self.lane] = dst;
        self.weights[self.rows][self.lane] = weight;
        self.weighted |= weight != 1;
        self.lane += 1;
        if self.lane == LANES {
            self.lane = 0;
            self.rows += 1;
            if self.rows == TILE {
                self.flush(scene, (w, h), sink);
            }
        }
    }

    /// Casts every point pushed so far: through a pinhole a tile at a
    /// time; through a lens camera, whose rays start apart, a packet at a
    /// time ([`sample_packet`], each at its pixel's first pupil point; no
    /// first hits, which assume a pinhole).
    pub fn flush(&mut self, scene: &Lit, (w, h): (u32, u32), sink: &mut impl Sink) {
        let packets = self.rows + usize::from(self.lane > 0);
        if packets == 0 {
            return;
        }
        let mut n = [LANES; TILE];
        if self.lane > 0 {
            n[self.rows] = self.lane;
        }
        (self.rows, self.lane) = (0, 0);
        let weighted = std::mem::take(&mut self.weighted);
        if scene.lens.is_some() {
            // A lens camera's gathers are never thinned (`thinning`).
            debug_assert!((0..packets).all(|r| self.weights[r][..n[r]].iter().all(|&w| w == 1)));
            for (r, &len) in n.iter().enumerate().take(packets) {
                let (xs, ys) = (&self.xs[r], &self.ys[r]);
                self.shaded = sample_packet(scene, xs, ys, len, w, h, &mut self.memory.scratch);
                for l in 0..len {
                    sink(self.dst[r][l], self.shaded[l], &|| FirstHit::UNKNOWN);
                }
            }
            return;
        }
        let tile = &mut self.memory.tile;
        camera_tile_hits(
            scene,
            &self.xs[..packets],
            &self.ys[..packets],
            &n[..packets],
            w,
            h,
            tile,
        );
        for (r, &len) in n.iter().enumerate().take(packets) {
            let (p, hits) = (&tile.packets[r], &tile.hits[r]);
            // Unused lanes count as 1: they shade nothing.
            let lit = if weighted {
                scene.with_lane_weights(&std::array::from_fn(|l| if l < len { self.weights[r][l] } else { 1 }))
            } else {
                *scene
            };
            shade_camera_packet(&lit, p, hits, len, &mut self.memory.scratch, &mut self.shaded);
            for l in 0..len {
                sink(self.dst[r][l], self.shaded[l], &|| FirstHit::of(scene, p, hits, l));
            }
        }
    }
}
