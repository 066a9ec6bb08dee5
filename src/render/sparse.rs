//! Camera samples at scattered points of the image (the pixels an adaptive
//! wave refines, the holes a reprojection leaves), gathered eight to a
//! packet and up to [`TILE`] packets to a tile, so they are cast exactly as
//! [`super::add_band_samples`] casts whole rows: every sample gets what
//! [`super::sample`] gives it, bit for bit, however the points are grouped.

use super::{BandMemory, shade_camera_packet};
use crate::color::Rgb;
use crate::scene::Scene;
use crate::simd::LANES;
use crate::simd::Lanes;
use crate::trace::{NO_OBJECT, Packet, PacketHits, TILE, camera_tile_hits};

/// What the ray through a pixel's centre met first, kept for reprojection.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FirstHit {
    /// The hit point less the camera position (for [`Seen::Sky`], the
    /// ray's unit direction: a point at infinity).
    pub offset: [f32; 3],
    pub seen: Seen,
}

/// Whether a pixel's colour may be moved to another view.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Seen {
    /// Nothing known (a block preview, a pixel filled from a coarse level).
    #[default]
    Unknown,
    /// A surface whose colour does not depend on the view's position
    /// (Phong highlights aside).
    Surface,
    /// The background.
    Sky,
    /// Glass or a mirror: what it shows moves differently from the surface.
    Specular,
}

impl FirstHit {
    /// Lane `l` of a camera packet and its closest hits.
    #[inline]
    pub(crate) fn of(scene: &Scene, p: &Packet, hits: &PacketHits, l: usize) -> FirstHit {
        FirstHit::at(scene, p.dirs(), hits, l)
    }

    /// [`FirstHit::of`] for lanes `0 .. out.len()` of a camera packet (the
    /// first sample stage records one per pixel, in the pass that shades
    /// them).
    #[inline]
    pub(crate) fn lanes(scene: &Scene, p: &Packet, hits: &PacketHits, out: &mut [FirstHit]) {
        let d = p.dirs();
        for (l, f) in out.iter_mut().enumerate() {
            *f = FirstHit::at(scene, d, hits, l);
        }
    }

    /// Lane `l`: the direction (a point at infinity) when it met nothing,
    /// else the direction times the hit's distance, and what was met. The
    /// directions stay in lanes (no ray is built per pixel).
    #[inline(always)]
    fn at(scene: &Scene, d: &[Lanes<f64>; 3], hits: &PacketHits, l: usize) -> FirstHit {
        let (t, seen) = match hits.object[l] {
            NO_OBJECT => (1.0, Seen::Sky),
            o => {
                let m = &scene.objects[o as usize].material;
                let specular = m.transparency > 0.0 || m.reflectivity > 0.0;
                (hits.t[l], if specular { Seen::Specular } else { Seen::Surface })
            }
        };
        // `x * 1.0` is `x`: a sky pixel's offset is its direction's bits.
        FirstHit {
            offset: [(d[0][l] * t) as f32, (d[1][l] * t) as f32, (d[2][l] * t) as f32],
            seen,
        }
    }
}

/// Points waiting to be cast, and where their results go.
pub(crate) struct Batch {
    xs: [[f64; LANES]; TILE],
    ys: [[f64; LANES]; TILE],
    dst: [[u32; LANES]; TILE],
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
    pub fn push(&mut self, scene: &Scene, (w, h): (u32, u32), (x, y): (f64, f64), dst: u32, sink: &mut impl Sink) {
        self.xs[self.rows][self.lane] = x;
        self.ys[self.rows][self.lane] = y;
        self.dst[self.rows][self.lane] = dst;
        self.lane += 1;
        if self.lane == LANES {
            self.lane = 0;
            self.rows += 1;
            if self.rows == TILE {
                self.flush(scene, (w, h), sink);
            }
        }
    }

    /// Casts every point pushed so far.
    pub fn flush(&mut self, scene: &Scene, (w, h): (u32, u32), sink: &mut impl Sink) {
        let packets = self.rows + usize::from(self.lane > 0);
        if packets == 0 {
            return;
        }
        let mut n = [LANES; TILE];
        if self.lane > 0 {
            n[self.rows] = self.lane;
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
            shade_camera_packet(scene, p, hits, len, &mut self.memory.scratch, &mut self.shaded);
            for l in 0..len {
                sink(self.dst[r][l], self.shaded[l], &|| FirstHit::of(scene, p, hits, l));
            }
        }
        (self.rows, self.lane) = (0, 0);
    }
}
