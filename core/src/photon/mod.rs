//! The caustic photon map: photons recorded on diffuse surfaces pass by
//! pass, and the irradiance they give at a point — progressive photon
//! mapping with one world-space radius schedule, so that the estimate does
//! not depend on the camera (ARCHITECTURE.md, "Caustics").
//!
//! Pass `k` (from 1) of `N` photons gives the estimate
//! `E_k(x) = Σ Φ_i / (π r_k²)` over its photons within `r_k` of `x`; the map
//! returns the mean of `E_1 … E_K`. The radius shrinks as
//! `r_k = r_0 · k^((α−1)/2)`, held constant over blocks of passes that
//! double (passes 1, 2–3, 4–7, …: level `L` uses `r_0 · (2^L)^((α−1)/2)`);
//! levels whose radii differ little share one grid of cells ([`Group`],
//! each photon weighed `1/(π r²)` of its own pass). With `α < 1` the
//! bias (∝ r²) and the variance (∝ 1/(K·N·r²)) of the mean both go to zero
//! (Hachisuka & Jensen 2009; Knaus & Zwicker 2011).
//!
//! A caustic family (the photons last sent by one object, one way: through
//! it, reflected off it, or out of a lens as a ghost, [`family`]) may
//! gather within `s·r_k`, `s` a power of √2
//! of its own: its photons are kept in a layer of groups of that scale, so
//! the sum above runs over each photon's own family radius. The map's
//! `r_0` and radius (`PhotonMap::radius`) are those of the families not
//! given one.

mod block;
mod cells;
mod family;
mod grid;
mod lanes;
mod radius;

pub use family::family_scales;
pub use lanes::Queries;
pub use radius::initial_radius;

use crate::color::Rgb;
use crate::simd::gmax;
use block::{BLOCK, Block, sum_blocks};
use cells::{CellBits, Key, cell_hash, hash_mix, hash_term, one_block, reach_log2};
use glam::{DVec3, Vec4};
use grid::{Entry, Grid};
use rayon::prelude::*;
use web_time::Instant;

thread_local! {
    /// This thread's queries near photons (where a query costs more than a
    /// clock), and the nanoseconds they took as [`GatherClock`] estimates
    /// them since the last [`take_gather_seconds`].
    static GATHER: std::cell::Cell<(u32, u64)> = const { std::cell::Cell::new((0, 0)) };
}

/// One gather in this many is timed, and counts for as many (a clock
/// costs about a tenth of a gather: timing one in 8 was 2 % of a
/// focal-spot frame, `perf`).
const TIMED_EVERY: u32 = 64;

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
/// along, the power it carries (scene units of light: a pass's photons
/// sum to the power the pass delivers) and its family: the object that
/// last sent it and how (through it, reflected, or out of a lens after
/// reflecting inside: the caustic it belongs to, [`family`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Photon {
    pub p: DVec3,
    pub dir: [f32; 3],
    pub power: [f32; 3],
    pub family: u32,
}

impl Photon {
    pub fn new(p: DVec3, dir: DVec3, power: Rgb) -> Self {
        let f = |v: DVec3| [v.x as f32, v.y as f32, v.z as f32];
        Photon {
            p,
            dir: f(dir),
            power: f(power),
            family: 0,
        }
    }

    /// The photon, of family `family`.
    pub fn with_family(self, family: u32) -> Self {
        Photon { family, ..self }
    }
}

/// Levels of passes whose radii lie within this factor of the group's
/// first share its cells: one lookup per cell for all of them, where a
/// grid per level cost a lookup per cell per level (the lookups were half
/// of a gather, `perf`), for at most `1/GROUP_SHRINK²` more photons tested.
const GROUP_SHRINK: f64 = 0.7;

/// The photons of a group of levels of passes ([`GROUP_SHRINK`]), in
/// cubic cells of side twice the largest radius (a query visits at most 8,
/// and skips those wholly outside its ball), each photon gathered within
/// its own pass's radius. Finer cells test fewer photons but look up more
/// cells, and a lookup costs more than a block of lanes (measured:
/// docs/performance.md).
#[derive(Clone, Debug)]
struct Group {
    radius: f64,
    /// The cells' side: twice the radius.
    cell: f64,
    /// Its reciprocal, for [`Group::key`].
    per_cell: f64,
    lo: DVec3,
    hi: DVec3,
    cells: Grid,
    /// The occupied cells.
    occupied: CellBits,
    /// The blocks of 2×2×2 cells that hold a photon ([`cells`]).
    near: CellBits,
    /// The blocks of 2×2×2 coarse cells ([`COARSE`] cells a side) that
    /// hold a photon: what turns a whole packet away at once
    /// (`lanes::Group::packet_far`).
    coarse: CellBits,
}

/// Cells along each side of a coarse cell of [`Group::coarse`].
const COARSE: i64 = 8;

/// The coarse cell of cell `k`.
#[inline(always)]
pub(super) fn coarse_key(k: Key) -> Key {
    k.map(|c| c.div_euclid(COARSE))
}

/// Bits of a group's set of occupied cells: a clear bit means no photon
/// there, so a query skips the cell's lookup.
const OCCUPANCY_BITS: u32 = 18;

impl Group {
    fn new(radius: f64) -> Self {
        Group {
            radius,
            cell: 2.0 * radius,
            per_cell: 1.0 / (2.0 * radius),
            lo: DVec3::INFINITY,
            hi: DVec3::NEG_INFINITY,
            cells: Grid::default(),
            occupied: CellBits::new(OCCUPANCY_BITS),
            near: CellBits::new(reach_log2(0)),
            coarse: CellBits::new(reach_log2(0)),
        }
    }

    /// The cell of `p`: `⌊p/cell⌋` up to a rounding, as `p` times the
    /// reciprocal (three divisions were a tenth of a gather that finds
    /// nothing, `perf` of focal-spot). Rounded products are monotonic in
    /// `p`, so a query's cells from `x − r` to `x + r` still hold every
    /// photon within `r` of `x`; a photon may lie a rounding of its
    /// coordinates outside its cell's box, far below the `f32` of the
    /// distance test.
    #[inline(always)]
    fn key(&self, p: DVec3) -> Key {
        let c = (p * self.per_cell).floor();
        [c.x as i64, c.y as i64, c.z as i64]
    }

    /// The low corner of cell `k`.
    #[inline(always)]
    fn corner(&self, k: Key) -> DVec3 {
        DVec3::new(k[0] as f64, k[1] as f64, k[2] as f64) * self.cell
    }

    /// Adds passes' photons, pass after pass and each in its order, each
    /// pass gathered within its radius (at most the group's). The cells
    /// are merged once for all of them, with what adding them one by one
    /// gives: a cell's photons in the order added, so the same blocks (a
    /// merge copies every block of the group, so a merge a pass made the
    /// viewer's many passes a stage cost the square of its photons).
    fn add(&mut self, passes: &[(&[Photon], f64)]) {
        let mut entries: Vec<Entry> = Vec::with_capacity(passes.iter().map(|p| p.0.len()).sum());
        for &(photons, radius) in passes {
            let per_area = 1.0 / (std::f64::consts::PI * radius * radius);
            entries.par_extend(photons.par_iter().with_min_len(4096).map(|ph| {
                let key = self.key(ph.p);
                let rel = ph.p - self.corner(key);
                Entry {
                    key,
                    rel: [rel.x as f32, rel.y as f32, rel.z as f32],
                    dir: ph.dir,
                    power: ph.power.map(|c| (c as f64 * per_area) as f32),
                    r2: (radius * radius) as f32,
                }
            }));
        }
        let all = passes.iter().flat_map(|p| p.0.iter());
        for ph in all {
            self.lo = self.lo.min(ph.p);
            self.hi = self.hi.max(ph.p);
        }
        // The cells that held no photon before: the only ones whose bits
        // are not set yet (a bit for each, not for each photon).
        let opened = self.cells.add(&entries);
        for &k in &opened {
            self.occupied.insert(k);
        }
        self.mark_near(&opened);
    }

    /// Adds the blocks holding the newly occupied cells `opened` to
    /// `near` (the other cells' blocks are in it already); when the
    /// group's occupied cells have outgrown its size, makes it anew from
    /// all of them.
    fn mark_near(&mut self, opened: &[Key]) {
        let log2 = reach_log2(self.cells.keys().count());
        if log2 > self.near.log2() {
            (self.near, self.coarse) = (CellBits::new(log2), CellBits::new(log2));
            for k in self.cells.keys() {
                self.near.insert_blocks_of(k);
                self.coarse.insert_blocks_of(coarse_key(k));
            }
            return;
        }
        for &k in opened {
            self.near.insert_blocks_of(k);
            self.coarse.insert_blocks_of(coarse_key(k));
        }
    }

    /// Whether every point of the box `lo ..= hi` lies beyond the
    /// photons' box by more than the radius (along some axis): no query
    /// there finds a photon.
    #[inline(always)]
    fn beyond(&self, lo: DVec3, hi: DVec3) -> bool {
        let r = self.radius;
        (hi + r).cmplt(self.lo).any() || (lo - r).cmpgt(self.hi).any()
    }

    /// The cells a query at `x` visits (from `x − r` to `x + r`), or
    /// `None` where no photon of the group lies within reach: `x` is
    /// beyond the photons' box by more than the radius, or the query's
    /// cells form one block of 2×2×2 cells (or less) and no photon lies in
    /// that block (`near`). Where it is `None` the walk of the cells would
    /// find no photon, so the sums are the walk's (zero).
    #[inline(always)]
    fn reach(&self, x: DVec3) -> Option<(Key, Key)> {
        if self.beyond(x, x) {
            return None;
        }
        let r = self.radius;
        let (a, b) = (self.key(x - r), self.key(x + r));
        if one_block(a, b) && !self.near.may_hold(cell_hash(a)) {
            return None;
        }
        Some((a, b))
    }

    /// The sum over the photons within their pass's radius of `x` that
    /// arrived on the side `n` faces of `Φ/(π r²)`. The cells from
    /// `x − r` to `x + r` are visited `i`, then `j`, then `k` rising;
    /// what a cell's test and lookup need of each of its coordinates
    /// ([`AxisCell`]) is worked out once per coordinate, not per cell.
    #[inline(always)]
    fn gather(&self, x: DVec3, n: [f32; 3], (a, b): (Key, Key)) -> Rgb {
        if (0..3).any(|c| a[c] > b[c]) {
            return Rgb::ZERO;
        }
        let r2 = self.radius * self.radius;
        let mut acc = [Vec4::ZERO; 3];
        let axis = |c: usize, k: i64| AxisCell::new(c, k, x[c], self.cell);
        let mut i = a[0];
        loop {
            let ci = axis(0, i);
            let mut j = a[1];
            loop {
                let cj = axis(1, j);
                let (gap_ij, hash_ij) = (ci.gap2 + cj.gap2, ci.hash ^ cj.hash);
                let mut k = a[2];
                loop {
                    let ck = axis(2, k);
                    // Skipped where the cell's nearest point to `x` is beyond
                    // the radius, or the cell holds no photon.
                    let far = gap_ij + ck.gap2 >= r2;
                    let h = hash_mix(hash_ij ^ ck.hash);
                    if !far
                        && self.occupied.may_hold(h)
                        && let Some(v) = self.cells.get([i, j, k], h)
                    {
                        sum_blocks(v, [ci.q, cj.q, ck.q], n, &mut acc);
                    }
                    if k >= b[2] {
                        break;
                    }
                    k += 1;
                }
                if j >= b[1] {
                    break;
                }
                j += 1;
            }
            if i >= b[0] {
                break;
            }
            i += 1;
        }
        let [e0, e1, e2] = acc.map(|a| a.element_sum() as f64);
        Rgb::new(e0, e1, e2)
    }
}

/// What a query at `x` needs of a cell's coordinate `k` on one axis: the
/// square of the gap from `x` to the cell along it (zero inside), that
/// axis's share of the cell's hash ([`hash_term`]) and `x` from the cell's
/// low corner, as a [`Block`] holds positions. Each is the arithmetic the
/// whole cell's would do on that axis (`corner = k·cell`, the gap
/// `max(corner − x, x − corner − cell, 0)`, its square summed over the
/// axes in order), so the sums and tests are the same bits.
struct AxisCell {
    gap2: f64,
    hash: u64,
    q: f32,
}

impl AxisCell {
    #[inline(always)]
    fn new(c: usize, k: i64, x: f64, cell: f64) -> AxisCell {
        let (gap2, q) = Self::gap2_and_q(k as f64 * cell, x, cell);
        AxisCell {
            gap2,
            hash: hash_term(c, k),
            q,
        }
    }

    /// The square of the gap from `x` to the cell whose low corner is at
    /// `corner` along one axis, and `x` from that corner as `f32`.
    #[inline(always)]
    fn gap2_and_q(corner: f64, x: f64, cell: f64) -> (f64, f32) {
        let gap = gmax(gmax(corner - x, x - corner - cell), 0.0);
        (gap * gap, (x - corner) as f32)
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
    /// Every layer's groups ([`family`]), in the order made.
    groups: Vec<Group>,
    /// The layers of families, each with its own scale on the radii.
    layers: family::Layers,
    /// Each layer's latest group (an index into `groups`).
    latest: Vec<Option<usize>>,
    /// Where some of the first pass's photons landed: every
    /// [`SPREAD_EVERY`]-th, up to [`SPREAD_MOST`] ([`PhotonMap::spread`]).
    spread: Vec<DVec3>,
}

/// One photon in this many is kept in [`PhotonMap::spread`].
const SPREAD_EVERY: usize = 16;
/// The most photons [`PhotonMap::spread`] keeps.
const SPREAD_MOST: usize = 4096;

impl PhotonMap {
    /// An empty map whose first pass gathers within `r0`, whatever the
    /// photons' families.
    pub fn new(r0: f64) -> Self {
        Self::with_families(r0, &[])
    }

    /// An empty map whose first pass gathers the families `listed` (each
    /// with its radius over `r0` in half octaves: [`family_scales`])
    /// within `r0` times their scale, and every other family within `r0`.
    pub fn with_families(r0: f64, listed: &[(u32, i32)]) -> Self {
        let layers = family::Layers::of(listed);
        PhotonMap {
            r0,
            passes: 0,
            photons: 0,
            groups: Vec::new(),
            latest: vec![None; layers.len()],
            layers,
            spread: Vec::new(),
        }
    }

    /// The gather radius of pass `k` (from 1): `r_0 · (2^L)^((α−1)/2)`
    /// for the level `L = ⌊log₂ k⌋` the pass belongs to
    /// (`radius::of_pass`: the same bits on every platform).
    pub fn radius_of_pass(r0: f64, k: u32) -> f64 {
        radius::of_pass(r0, k)
    }

    /// Adds one pass's photons (in their order: the sums are the same
    /// whatever produced them).
    pub fn add_pass(&mut self, photons: &[Photon]) {
        self.add_passes(&[photons]);
    }

    /// Adds passes' photons, in order: the map [`PhotonMap::add_pass`]
    /// gives one pass after the other, with each group's cells merged once.
    pub fn add_passes(&mut self, passes: &[&[Photon]]) {
        // Each pass's photons by layer, where there are layers to split.
        let split: Vec<Vec<Vec<Photon>>> = if self.layers.len() > 1 {
            passes.par_iter().map(|p| self.layers.split(p)).collect()
        } else {
            Vec::new()
        };
        let mut pending: Vec<Vec<(&[Photon], f64)>> = vec![Vec::new(); self.layers.len()];
        for (i, &photons) in passes.iter().enumerate() {
            self.passes += 1;
            let base = self.radius();
            for (l, pending) in pending.iter_mut().enumerate() {
                let part = split.get(i).map_or(photons, |parts| &parts[l]);
                let r = base * self.layers.scales[l];
                if self.latest[l].is_none_or(|g| r < GROUP_SHRINK * self.groups[g].radius) {
                    self.add_to_latest(l, pending);
                    self.groups.push(Group::new(r));
                    self.latest[l] = Some(self.groups.len() - 1);
                }
                pending.push((part, r));
            }
            if self.passes == 1 {
                let kept = photons.iter().step_by(SPREAD_EVERY).take(SPREAD_MOST);
                self.spread.extend(kept.map(|ph| ph.p));
            }
            self.photons += photons.len();
        }
        for (l, pending) in pending.iter_mut().enumerate() {
            self.add_to_latest(l, pending);
        }
    }

    /// Adds the `pending` passes to layer `l`'s latest group, and forgets
    /// them.
    fn add_to_latest(&mut self, l: usize, pending: &mut Vec<(&[Photon], f64)>) {
        if let Some(g) = self.latest[l]
            && !pending.is_empty()
        {
            self.groups[g].add(pending);
        }
        pending.clear();
    }

    /// Passes added so far.
    pub fn passes(&self) -> u32 {
        self.passes
    }

    /// Photons stored so far (those that landed after a specular bounce).
    pub fn photons(&self) -> usize {
        self.photons
    }

    /// Where some of the photons landed, for telling how the camera sees
    /// them (`render::thinning`): photon `n` of the first pass's for every
    /// `n` a multiple of 16, up to 4096 of them (the same whatever passes
    /// follow).
    pub fn spread(&self) -> &[DVec3] {
        &self.spread
    }

    /// The first pass's radius (`r0`; a family's own is a scale times it).
    pub fn first_radius(&self) -> f64 {
        self.r0
    }

    /// The radius the latest pass gathers with (`r0` before any pass),
    /// where its family has no scale of its own ([`family`]).
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
    if map.passes == 0 {
        return Rgb::ZERO;
    }
    let n = [n.x as f32, n.y as f32, n.z as f32];
    let (mut e, mut clock) = (Rgb::ZERO, None);
    for g in &map.groups {
        // A group out of reach adds zero: nothing to add.
        if let Some(cells) = g.reach(x) {
            if clock.is_none() {
                clock = Some(GatherClock::start());
            }
            e += g.gather(x, n, cells);
        }
    }
    if let Some(c) = clock {
        c.stop();
    }
    e / map.passes as f64
}

crate::simd::with_avx2! {
    /// [`estimate_impl`] in the best build this CPU runs (the same bits in
    /// each: no fused operations).
    fn estimate / estimate_avx2 => estimate_impl(map: &PhotonMap, x: DVec3, n: DVec3) -> Rgb
}

#[cfg(test)]
mod tests;
