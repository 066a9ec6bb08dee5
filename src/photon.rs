//! The caustic photon map: photons recorded on diffuse surfaces pass by
//! pass, and the irradiance they give at a point — progressive photon
//! mapping with one world-space radius schedule, so that the estimate does
//! not depend on the camera (ARCHITECTURE.md, "Caustics").
//!
//! Pass `k` (from 1) of `N` photons gives the estimate
//! `E_k(x) = Σ Φ_i / (π r_k²)` over its photons within `r_k` of `x`; the map
//! returns the mean of `E_1 … E_K`. The radius shrinks as
//! `r_k = r_0 · k^((α−1)/2)`, held constant over blocks of passes that
//! double (passes 1, 2–3, 4–7, …: level `L` uses `r_0 · (2^L)^((α−1)/2)`),
//! so that each level is one grid of cells of its radius. With `α < 1` the
//! bias (∝ r²) and the variance (∝ 1/(K·N·r²)) of the mean both go to zero
//! (Hachisuka & Jensen 2009; Knaus & Zwicker 2011).

use crate::color::Rgb;
use glam::DVec3;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};
use std::time::Instant;

thread_local! {
    /// This thread's queries near photons (where a query costs more than a
    /// clock), and the nanoseconds they took as [`GatherClock`] estimates
    /// them since the last [`take_gather_seconds`].
    static GATHER: std::cell::Cell<(u32, u64)> = const { std::cell::Cell::new((0, 0)) };
}

/// One gather in this many is timed, and counts for as many (a clock
/// costs about a tenth of a gather).
const TIMED_EVERY: u32 = 8;

/// The clock of one gather: started on one in [`TIMED_EVERY`].
struct GatherClock(Option<Instant>);

impl GatherClock {
    #[inline(always)]
    fn start() -> Self {
        let (count, ns) = GATHER.with(|g| g.get());
        GATHER.with(|g| g.set((count.wrapping_add(1), ns)));
        GatherClock((count % TIMED_EVERY == 0).then(Instant::now))
    }

    #[inline(always)]
    fn stop(self) {
        if let Some(t) = self.0 {
            let spent = t.elapsed().as_nanos() as u64 * TIMED_EVERY as u64;
            GATHER.with(|g| g.set((g.get().0, g.get().1 + spent)));
        }
    }
}

/// The time this thread spent gathering photons since the last call (one
/// gather in [`TIMED_EVERY`] timed): what the viewer shows a frame's
/// caustics cost (run on every thread of the pool and summed).
pub fn take_gather_seconds() -> f64 {
    let (count, ns) = GATHER.with(|g| g.get());
    GATHER.with(|g| g.set((count, 0)));
    ns as f64 * 1e-9
}

/// The exponent of the radius schedule: `r² ∝ k^(α−1)` (SPPM's α).
pub const ALPHA: f64 = 2.0 / 3.0;

/// One photon where it landed: its position, the unit direction it arrived
/// along, and the power it carries (scene units of light: a pass's photons
/// sum to the power the pass delivers).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Photon {
    pub p: DVec3,
    pub dir: [f32; 3],
    pub power: [f32; 3],
}

impl Photon {
    pub fn new(p: DVec3, dir: DVec3, power: Rgb) -> Self {
        let f = |v: DVec3| [v.x as f32, v.y as f32, v.z as f32];
        Photon {
            p,
            dir: f(dir),
            power: f(power),
        }
    }
}

/// A cell's key: its integer coordinates.
type Key = [i64; 3];

/// A cheap hash of a cell's key, for the map and the occupancy bits.
#[inline]
fn cell_hash(k: Key) -> u64 {
    let h = (k[0] as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)
        ^ (k[1] as u64).wrapping_mul(0xc2b2_ae3d_27d4_eb4f)
        ^ (k[2] as u64).wrapping_mul(0x1656_67b1_9e37_79f9);
    h ^ (h >> 29)
}

/// The hasher of [`Cells`]: [`cell_hash`] of the key, whatever else is
/// written (the length of nothing: keys are arrays).
#[derive(Default)]
struct CellHasher(u64);

impl Hasher for CellHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ b as u64).wrapping_mul(0x0100_0000_01b3);
        }
    }
    fn write_u64(&mut self, v: u64) {
        self.take(v);
    }
}

/// A cell key hashed whole (not element by element).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct CellKey(Key);

impl std::hash::Hash for CellKey {
    fn hash<H: Hasher>(&self, state: &mut H) {
        state.write_u64(cell_hash(self.0));
    }
}

impl CellHasher {
    fn take(&mut self, v: u64) {
        self.0 = v;
    }
}

type Cells = HashMap<CellKey, Vec<Block>, BuildHasherDefault<CellHasher>>;

/// Bits of a level's occupancy filter: a cell whose bit is clear holds no
/// photon, so most queries away from caustics cost a few bit tests.
const OCCUPANCY_BITS: u32 = 18;

/// Which cells of side `cell` hold a photon, as bits indexed by a hash of
/// the cell (no false "empty": a clear bit means no photon there).
#[derive(Clone, Debug)]
struct Occupancy {
    cell: f64,
    bits: Vec<u64>,
}

impl Occupancy {
    fn new(cell: f64) -> Self {
        Occupancy {
            cell,
            bits: vec![0; 1 << (OCCUPANCY_BITS - 6)],
        }
    }

    #[inline(always)]
    fn key(&self, p: DVec3) -> Key {
        let c = (p / self.cell).floor();
        [c.x as i64, c.y as i64, c.z as i64]
    }

    /// The word and bit of cell `k`.
    #[inline]
    fn bit(k: Key) -> (usize, u64) {
        let b = (cell_hash(k) >> (64 - OCCUPANCY_BITS)) as usize;
        (b >> 6, 1u64 << (b & 63))
    }

    fn mark(&mut self, k: Key) {
        let (w, b) = Self::bit(k);
        self.bits[w] |= b;
    }

    #[inline(always)]
    fn may_hold(&self, k: Key) -> bool {
        let (w, b) = Self::bit(k);
        self.bits[w] & b != 0
    }

    /// Whether any cell within `r` of `x` may hold a photon.
    #[inline(always)]
    fn near(&self, x: DVec3, r: f64) -> bool {
        let (a, b) = (self.key(x - r), self.key(x + r));
        // Loops, not nested `any`: its closures were not inlined into the
        // ISA builds (6 % of a cubes frame, `perf`).
        for i in a[0]..=b[0] {
            for j in a[1]..=b[1] {
                for k in a[2]..=b[2] {
                    if self.may_hold([i, j, k]) {
                        return true;
                    }
                }
            }
        }
        false
    }
}

/// Photons a [`Block`] holds: the lanes of one step of the gather loop.
const BLOCK: usize = 8;

/// Up to [`BLOCK`] photons of one cell as `f32` columns: positions from the
/// cell's low corner (exact to `f32` of the cell's side, wherever the scene
/// lies), arrival directions and powers. An unused lane lies at infinity
/// with no power and no direction, so it is never within the radius.
#[derive(Clone, Debug)]
struct Block {
    p: [[f32; BLOCK]; 3],
    dir: [[f32; BLOCK]; 3],
    power: [[f32; BLOCK]; 3],
    len: usize,
}

impl Block {
    const EMPTY: Block = Block {
        p: [[f32::INFINITY; BLOCK]; 3],
        dir: [[0.0; BLOCK]; 3],
        power: [[0.0; BLOCK]; 3],
        len: 0,
    };
}

/// A gather's query in a cell's frame: the point from the cell's corner,
/// the normal, the squared radius.
#[derive(Clone, Copy)]
struct Query {
    q: [f32; 3],
    n: [f32; 3],
    r2: f32,
}

/// The power, lane by lane then lanes in order, of the photons of `blocks`
/// within the radius of the query that arrived on the side its normal
/// faces: one branch-free loop over the columns.
#[inline(always)]
fn sum_blocks_impl(blocks: &[Block], at: Query) -> [f32; 3] {
    let Query { q, n, r2 } = at;
    let mut acc = [[0.0f32; BLOCK]; 3];
    for b in blocks {
        for l in 0..BLOCK {
            let d = [b.p[0][l] - q[0], b.p[1][l] - q[1], b.p[2][l] - q[2]];
            let d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            let facing = b.dir[0][l] * n[0] + b.dir[1][l] * n[1] + b.dir[2][l] * n[2];
            let w = if d2 < r2 && facing < 0.0 { 1.0 } else { 0.0 };
            for (a, c) in acc.iter_mut().zip(&b.power) {
                a[l] += w * c[l];
            }
        }
    }
    acc.map(|a| a.iter().sum())
}

/// The photons of one level of passes, all gathered with one radius, in
/// cubic cells of side twice the radius (a query visits at most 8, and
/// skips those wholly outside its ball). Finer cells test fewer photons
/// but look up more cells, and a lookup (a cache miss, mostly) costs more
/// than a block of lanes (measured: docs/performance.md).
#[derive(Clone, Debug)]
struct Level {
    radius: f64,
    lo: DVec3,
    hi: DVec3,
    cells: Cells,
    occupied: Occupancy,
}

impl Level {
    fn new(radius: f64) -> Self {
        Level {
            radius,
            lo: DVec3::INFINITY,
            hi: DVec3::NEG_INFINITY,
            cells: Cells::default(),
            occupied: Occupancy::new(2.0 * radius),
        }
    }

    #[inline(always)]
    fn key(&self, p: DVec3) -> Key {
        self.occupied.key(p)
    }

    /// The low corner of cell `k`.
    #[inline(always)]
    fn corner(&self, k: Key) -> DVec3 {
        DVec3::new(k[0] as f64, k[1] as f64, k[2] as f64) * self.occupied.cell
    }

    fn insert(&mut self, ph: Photon) {
        self.lo = self.lo.min(ph.p);
        self.hi = self.hi.max(ph.p);
        let k = self.key(ph.p);
        self.occupied.mark(k);
        let rel = ph.p - self.corner(k);
        let blocks = self.cells.entry(CellKey(k)).or_default();
        if blocks.last().is_none_or(|b| b.len == BLOCK) {
            blocks.push(Block::EMPTY);
        }
        // ok: a block was pushed above when there was none with room.
        let b = blocks.last_mut().expect("a block with room");
        let l = b.len;
        for (c, v) in [rel.x as f32, rel.y as f32, rel.z as f32].into_iter().enumerate() {
            b.p[c][l] = v;
            b.dir[c][l] = ph.dir[c];
            b.power[c][l] = ph.power[c];
        }
        b.len += 1;
    }

    /// The power of the photons within the radius of `x` that arrived on
    /// the side `n` faces.
    #[inline(always)]
    fn gather(&self, x: DVec3, n: DVec3) -> Rgb {
        let r = self.radius;
        if (x + r).cmplt(self.lo).any() || (x - r).cmpgt(self.hi).any() {
            return Rgb::ZERO;
        }
        let (a, b) = (self.key(x - r), self.key(x + r));
        let (r2, cell) = (r * r, self.occupied.cell);
        let n = [n.x as f32, n.y as f32, n.z as f32];
        let mut sum = Rgb::ZERO;
        for i in a[0]..=b[0] {
            for j in a[1]..=b[1] {
                for k in a[2]..=b[2] {
                    let key = [i, j, k];
                    let corner = self.corner(key);
                    // The cell's nearest point to `x` is beyond the radius.
                    let gap = (corner - x).max(x - corner - cell).max(DVec3::ZERO);
                    if gap.length_squared() >= r2 || !self.occupied.may_hold(key) {
                        continue;
                    }
                    let Some(v) = self.cells.get(&CellKey(key)) else {
                        continue;
                    };
                    let q = x - corner;
                    let at = Query {
                        q: [q.x as f32, q.y as f32, q.z as f32],
                        n,
                        r2: r2 as f32,
                    };
                    let s = sum_blocks_impl(v, at);
                    sum += Rgb::new(s[0] as f64, s[1] as f64, s[2] as f64);
                }
            }
        }
        sum
    }
}

/// Every pass's photons so far and the estimate they give
/// ([`PhotonMap::irradiance`]). Adding a pass never changes what earlier
/// passes contribute, and the result depends only on the passes' photons
/// in order: not on threads or on any camera.
#[derive(Clone, Debug)]
pub struct PhotonMap {
    r0: f64,
    passes: u32,
    photons: usize,
    levels: Vec<Level>,
    /// Every photon's cell at the first (largest) radius: a query with
    /// nothing near skips all levels at once.
    coarse: Occupancy,
}

impl PhotonMap {
    /// An empty map whose first pass gathers within `r0`.
    pub fn new(r0: f64) -> Self {
        PhotonMap {
            r0,
            passes: 0,
            photons: 0,
            levels: Vec::new(),
            coarse: Occupancy::new(2.0 * r0),
        }
    }

    /// The gather radius of pass `k` (from 1): `r_0 · (2^L)^((α−1)/2)`
    /// for the level `L = ⌊log₂ k⌋` the pass belongs to.
    pub fn radius_of_pass(r0: f64, k: u32) -> f64 {
        let level = 31 - k.max(1).leading_zeros();
        r0 * ((1u64 << level) as f64).powf((ALPHA - 1.0) / 2.0)
    }

    /// Adds one pass's photons (in their order: the sums are the same
    /// whatever produced them).
    pub fn add_pass(&mut self, photons: &[Photon]) {
        self.passes += 1;
        let level = (31 - self.passes.leading_zeros()) as usize;
        while self.levels.len() <= level {
            let k = 1u32 << self.levels.len();
            self.levels.push(Level::new(Self::radius_of_pass(self.r0, k)));
        }
        for &ph in photons {
            self.levels[level].insert(ph);
            let k = self.coarse.key(ph.p);
            self.coarse.mark(k);
        }
        self.photons += photons.len();
    }

    /// Passes added so far.
    pub fn passes(&self) -> u32 {
        self.passes
    }

    /// Photons stored so far (those that landed after a specular bounce).
    pub fn photons(&self) -> usize {
        self.photons
    }

    /// The radius the latest pass gathers with (`r0` before any pass).
    pub fn radius(&self) -> f64 {
        Self::radius_of_pass(self.r0, self.passes)
    }

    /// The caustic irradiance at `x` on the side of the surface whose unit
    /// normal (toward the viewer) is `n`: the mean over the passes of each
    /// pass's density estimate. Zero before the first pass.
    pub fn irradiance(&self, x: DVec3, n: DVec3) -> Rgb {
        estimate(self, x, n)
    }
}

/// [`PhotonMap::irradiance`], compiled into each build.
#[inline(always)]
fn estimate_impl(map: &PhotonMap, x: DVec3, n: DVec3) -> Rgb {
    if map.passes == 0 || map.photons == 0 || !map.coarse.near(x, map.r0) {
        return Rgb::ZERO;
    }
    let clock = GatherClock::start();
    let mut e = Rgb::ZERO;
    for l in &map.levels {
        let s = l.gather(x, n);
        if s != Rgb::ZERO {
            e += s / (std::f64::consts::PI * l.radius * l.radius);
        }
    }
    clock.stop();
    e / map.passes as f64
}

crate::simd::with_avx2! {
    /// [`estimate_impl`] in the best build this CPU runs (the same bits in
    /// each: no fused operations).
    fn estimate / estimate_avx2 => estimate_impl(map: &PhotonMap, x: DVec3, n: DVec3) -> Rgb
}

/// A starting radius for a map from its first pass's photons: the median,
/// over up to 256 photons spread through the pass, of the distance to the
/// `k`-th nearest other photon (at least `floor`). `None` without photons.
pub fn initial_radius(photons: &[Photon], k: usize, floor: f64) -> Option<f64> {
    if photons.len() < 2 {
        return None;
    }
    let k = k.clamp(1, photons.len() - 1);
    let step = photons.len().div_ceil(256);
    let mut radii: Vec<f64> = photons
        .iter()
        .step_by(step)
        .map(|a| {
            let mut d: Vec<f64> = photons.iter().map(|b| (a.p - b.p).length_squared()).collect();
            // d[0] is the photon itself (distance 0): the k-th other is d[k].
            d.select_nth_unstable_by(k, f64::total_cmp);
            d[k].sqrt()
        })
        .collect();
    let mid = radii.len() / 2;
    radii.select_nth_unstable_by(mid, f64::total_cmp);
    Some(radii[mid].max(floor))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn photon(x: f64, y: f64, power: f64) -> Photon {
        Photon::new(DVec3::new(x, y, 0.0), -DVec3::Z, Rgb::splat(power))
    }

    /// One photon of power 1 at the origin: within the radius the estimate
    /// is 1/(πr²) on the side it arrived on, zero outside or behind.
    #[test]
    fn one_photon_gives_its_power_over_the_disc() {
        let mut m = PhotonMap::new(0.5);
        m.add_pass(&[photon(0.0, 0.0, 1.0)]);
        let e = m.irradiance(DVec3::new(0.3, 0.2, 0.0), DVec3::Z);
        assert!((e.x - 1.0 / (std::f64::consts::PI * 0.25)).abs() < 1e-12, "{e}");
        assert_eq!(m.irradiance(DVec3::new(0.5, 0.1, 0.0), DVec3::Z), Rgb::ZERO);
        assert_eq!(m.irradiance(DVec3::ZERO, -DVec3::Z), Rgb::ZERO);
    }

    /// The radius shrinks by level as `(2^L)^((α−1)/2)`, and the estimate is
    /// the mean over passes: a second pass with nothing near halves it.
    #[test]
    fn radius_schedule_and_mean_over_passes() {
        assert_eq!(PhotonMap::radius_of_pass(1.0, 1), 1.0);
        let r2 = PhotonMap::radius_of_pass(1.0, 2);
        assert!((r2 - 2f64.powf(-1.0 / 6.0)).abs() < 1e-15);
        assert_eq!(PhotonMap::radius_of_pass(1.0, 3), r2);
        assert!(PhotonMap::radius_of_pass(1.0, 4) < r2);
        let mut m = PhotonMap::new(0.5);
        m.add_pass(&[photon(0.0, 0.0, 1.0)]);
        let e1 = m.irradiance(DVec3::ZERO, DVec3::Z);
        m.add_pass(&[photon(5.0, 0.0, 1.0)]);
        assert_eq!(m.irradiance(DVec3::ZERO, DVec3::Z), e1 / 2.0);
        assert_eq!(m.passes(), 2);
        assert_eq!(m.photons(), 2);
    }

    /// Photons across cell boundaries are all found: a uniform grid of
    /// photons gives its density everywhere inside.
    #[test]
    fn a_uniform_field_gives_its_density() {
        let mut v = Vec::new();
        let h = 0.01;
        for i in -200..200 {
            for j in -200..200 {
                v.push(photon((i as f64 + 0.5) * h, (j as f64 + 0.5) * h, h * h));
            }
        }
        let mut m = PhotonMap::new(0.1);
        m.add_pass(&v);
        for x in [DVec3::ZERO, DVec3::new(0.7, -0.33, 0.0), DVec3::new(-1.2, 1.1, 0.0)] {
            let e = m.irradiance(x, DVec3::Z).x;
            assert!((e - 1.0).abs() < 0.03, "{x}: {e}");
        }
    }

    #[test]
    fn initial_radius_is_the_median_kth_neighbour_distance() {
        let v: Vec<Photon> = (0..100).map(|i| photon(i as f64, 0.0, 1.0)).collect();
        assert_eq!(initial_radius(&v, 2, 0.0), Some(1.0));
        assert_eq!(initial_radius(&v, 4, 0.0), Some(2.0));
        assert_eq!(initial_radius(&v[..1], 4, 0.0), None);
    }
}
