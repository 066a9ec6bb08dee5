//! The caustic irradiance at a packet's points at once
//! ([`PhotonMap::irradiance_lanes`]): where the lanes' queries share
//! their cells (the points lie close together next to the cells' side of
//! twice the radius), the cells of all of them are walked once and each
//! photon is tested against every lane's point in one lane loop, instead
//! of each lane walking the cells and testing the photons four at a time.
//! Each lane gets [`PhotonMap::irradiance`]'s bits: the same cells in the
//! same order, the same `f32` arithmetic per photon, and four sums per
//! lane, one for each lane of a [`Block`], added as glam's `element_sum`
//! adds a block's four.

// Lane loops index several arrays by the lane: the form the vectoriser wants.
#![allow(clippy::needless_range_loop)]

use super::block::photon_terms;
use super::cells::{Key, cell_hash, hash_mix, hash_term, one_block};
use super::{AxisCell, BLOCK, Block, GatherClock, Group, PhotonMap, coarse_key};
use crate::color::Rgb;
use crate::simd::{LANES, Lanes, lane, live_lanes, mask};
use glam::DVec3;

/// The most cells along one axis of the lanes' cells together for the
/// walk in lanes: past it the lanes gather one by one.
const MOST_PER_AXIS: usize = 4;

/// The lanes' cells together are walked at once when the lanes' own
/// cells, summed, are at least this many times the cells walked: each
/// photon then costs one lane loop for every lane, where gathering one
/// lane at a time tests four photons at a time for each lane that
/// reaches it (so the walk in lanes wins where most lanes share a cell).
const SHARED_CELLS: usize = 4;

/// A packet's queries: the lanes' points and unit normals as structure
/// of arrays, and which lanes ask (a bit mask).
#[derive(Clone, Copy)]
pub struct Queries<'a> {
    pub x: &'a [Lanes<f64>; 3],
    pub n: &'a [Lanes<f64>; 3],
    pub live: u32,
}

/// Each lane's cells, `from ..= to` on each axis, for the lanes `asks`
/// (elsewhere `from` is above `to`: no cell).
struct Ranges {
    from: [Lanes<i64>; 3],
    to: [Lanes<i64>; 3],
    asks: u32,
}

impl Ranges {
    const NONE: Ranges = Ranges {
        from: [[i64::MAX; LANES]; 3],
        to: [[i64::MIN; LANES]; 3],
        asks: 0,
    };
}

/// A lane's four sums of each colour channel, one for each lane of a
/// [`Block`] (what the one-lane gather's `Vec4` accumulators hold).
type Sums = [[Lanes<f32>; 3]; BLOCK];

/// What the lanes need of one cell coordinate `k` on one axis: the
/// square of each lane's gap to the cell along it, each lane's point from
/// the cell's low corner (as `f32`), the lanes whose own cells hold `k`,
/// and the axis's share of the cell's hash: `AxisCell`'s values, lane by
/// lane.
#[derive(Clone, Copy)]
struct AxisLanes {
    gap2: Lanes<f64>,
    q: Lanes<f32>,
    holds: u32,
    hash: u64,
}

impl AxisLanes {
    const NONE: AxisLanes = AxisLanes {
        gap2: [0.0; LANES],
        q: [0.0; LANES],
        holds: 0,
        hash: 0,
    };
}

impl PhotonMap {
    /// [`PhotonMap::irradiance`] at each lane of `q.live` (zero in the
    /// other lanes), the same bits.
    pub fn irradiance_lanes(&self, q: Queries) -> Lanes<Rgb> {
        estimate_lanes(self, q)
    }
}

/// [`PhotonMap::irradiance_lanes`], compiled into each build.
#[inline(always)]
fn estimate_lanes_impl(map: &PhotonMap, q: Queries) -> Lanes<Rgb> {
    let mut e = [Rgb::ZERO; LANES];
    if map.passes == 0 || q.live == 0 {
        return e;
    }
    // A plain loop, not `array::map`: that was once compiled as three
    // calls out of line (the stores between them 3 % of focal-spot's
    // frame, `perf annotate`).
    let mut n = [[0.0f32; LANES]; 3];
    for c in 0..3 {
        for l in 0..LANES {
            n[c][l] = q.n[c][l] as f32;
        }
    }
    let mut clock = None;
    let (lo, hi) = packet_box(q.x, q.live);
    for g in &map.groups {
        if g.packet_far(lo, hi) {
            continue;
        }
        let cells = g.reach_lanes(q.x, q.live);
        if cells.asks == 0 {
            continue;
        }
        clock.get_or_insert_with(GatherClock::start);
        if !g.gather_lanes(q.x, &n, &cells, &mut e) {
            for l in live_lanes(cells.asks) {
                let (a, b) = (cells.from.map(|c| c[l]), cells.to.map(|c| c[l]));
                e[l] += g.gather(lane(q.x, l), [n[0][l], n[1][l], n[2][l]], (a, b));
            }
        }
    }
    if let Some(c) = clock {
        c.stop();
    }
    e.map(|v| v / map.passes as f64)
}

crate::simd::with_avx2! {
    /// [`estimate_lanes_impl`] in the best build this CPU runs (the same
    /// bits in each: no fused operations).
    fn estimate_lanes / estimate_lanes_avx2 => estimate_lanes_impl(map: &PhotonMap, q: Queries) -> Lanes<Rgb>
}

/// The box of the points `x` of lanes `live` (a lane at NaN left out; an
/// empty box, low corner above high, where none is left), worked out once
/// a packet for every group's [`Group::packet_far`].
#[inline(always)]
fn packet_box(x: &[Lanes<f64>; 3], live: u32) -> (DVec3, DVec3) {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for c in 0..3 {
        for l in live_lanes(live) {
            // A lane at NaN is left out (it finds nothing).
            let v = x[c][l];
            lo[c] = if v < lo[c] { v } else { lo[c] };
            hi[c] = if v > hi[c] { v } else { hi[c] };
        }
    }
    (DVec3::from_array(lo), DVec3::from_array(hi))
}

impl Group {
    /// Whether no lane whose point lies in the box `lo ..= hi`
    /// ([`packet_box`]) can reach a photon of the group,
    /// told for the lanes together: their points' box lies beyond the
    /// photons' box by more than the radius on some axis, or the cells
    /// from its low corner less the radius to its high corner plus the
    /// radius (which hold every lane's cells of [`Group::reach`]: rounded
    /// sums and products are monotonic) lie in one block of 2×2×2 coarse
    /// cells that holds no photon. Where it says so, every lane's walk
    /// would find nothing (zero); one test a packet where the lanes' own
    /// were most of a gather in scenes whose queries mostly find nothing
    /// (focal-spot, cubes; `perf`). Lanes at NaN find nothing either way.
    #[inline(always)]
    fn packet_far(&self, lo: DVec3, hi: DVec3) -> bool {
        if self.beyond(lo, hi) {
            return true;
        }
        let r = self.radius;
        let (a, b) = (coarse_key(self.key(lo - r)), coarse_key(self.key(hi + r)));
        one_block(a, b) && !self.coarse.may_hold(cell_hash(a))
    }

    /// [`Group::reach`] of each lane of `live` at `x`, as lanes: the lanes
    /// within reach whose cells are not empty on any axis, each with its
    /// cells (a lane out of reach, or whose range of cells is empty, finds
    /// nothing: the one-lane gather adds zero there).
    #[inline(always)]
    fn reach_lanes(&self, x: &[Lanes<f64>; 3], live: u32) -> Ranges {
        let mut cells = Ranges::NONE;
        for l in live_lanes(live) {
            if let Some((a, b)) = self.reach(lane(x, l))
                && (0..3).all(|c| a[c] <= b[c])
            {
                for c in 0..3 {
                    (cells.from[c][l], cells.to[c][l]) = (a[c], b[c]);
                }
                cells.asks |= 1 << l;
            }
        }
        cells
    }

    /// Adds to `e` each lane's sum (as [`Group::gather`] gives it) over the
    /// lanes' cells (`cells`, from [`Group::reach`]) walked together, and
    /// says so; or adds nothing and says `false` where the lanes share too
    /// few of their cells for that to pay ([`SHARED_CELLS`],
    /// [`MOST_PER_AXIS`]).
    #[inline(always)]
    fn gather_lanes(&self, x: &[Lanes<f64>; 3], n: &[Lanes<f32>; 3], cells: &Ranges, e: &mut Lanes<Rgb>) -> bool {
        let (mut lo, mut hi) = ([i64::MAX; 3], [i64::MIN; 3]);
        let mut own = 0u64;
        for l in live_lanes(cells.asks) {
            let mut v = 1u64;
            for c in 0..3 {
                lo[c] = lo[c].min(cells.from[c][l]);
                hi[c] = hi[c].max(cells.to[c][l]);
                v = v.saturating_mul(cells.to[c][l].abs_diff(cells.from[c][l]).saturating_add(1));
            }
            own = own.saturating_add(v);
        }
        let mut dims = [0usize; 3];
        for c in 0..3 {
            match usize::try_from(hi[c].abs_diff(lo[c]).saturating_add(1)) {
                Ok(d) if d <= MOST_PER_AXIS => dims[c] = d,
                _ => return false,
            }
        }
        if own < (SHARED_CELLS * dims.iter().product::<usize>()) as u64 {
            return false;
        }
        let mut axes = [[AxisLanes::NONE; MOST_PER_AXIS]; 3];
        for c in 0..3 {
            for d in 0..dims[c] {
                axes[c][d] = self.axis_lanes(c, lo[c] + d as i64, &x[c], cells);
            }
        }
        let mut sums: Sums = [[[0.0; LANES]; 3]; BLOCK];
        let axes = [&axes[0][..dims[0]], &axes[1][..dims[1]], &axes[2][..dims[2]]];
        self.walk_lanes(axes, lo, n, &mut sums);
        for l in live_lanes(cells.asks) {
            let total = |c: usize| ((sums[0][c][l] + sums[1][c][l]) + (sums[2][c][l] + sums[3][c][l])) as f64;
            e[l] += Rgb::new(total(0), total(1), total(2));
        }
        true
    }

    /// [`AxisLanes`] of coordinate `k` on axis `c`, for lanes at `x` (on
    /// that axis) whose cells are `cells`.
    #[inline(always)]
    fn axis_lanes(&self, c: usize, k: i64, x: &Lanes<f64>, cells: &Ranges) -> AxisLanes {
        let corner = k as f64 * self.cell;
        let mut a = AxisLanes {
            gap2: [0.0; LANES],
            q: [0.0; LANES],
            holds: 0,
            hash: hash_term(c, k),
        };
        let mut holds = [false; LANES];
        for l in 0..LANES {
            (a.gap2[l], a.q[l]) = AxisCell::gap2_and_q(corner, x[l], self.cell);
            holds[l] = cells.from[c][l] <= k && k <= cells.to[c][l];
        }
        a.holds = mask(&holds) & cells.asks;
        a
    }

    /// Walks the cells of `axes` (from `lo`), `i`, then `j`, then `k`
    /// rising, and adds each photon in a cell to the sums of the lanes
    /// whose own cells hold it and which it does not lie wholly beyond
    /// (the one-lane walk's cells, in its order).
    #[inline(always)]
    fn walk_lanes(&self, axes: [&[AxisLanes]; 3], lo: Key, n: &[Lanes<f32>; 3], sums: &mut Sums) {
        let r2 = self.radius * self.radius;
        for (di, ci) in axes[0].iter().enumerate() {
            for (dj, cj) in axes[1].iter().enumerate() {
                let holds_ij = ci.holds & cj.holds;
                if holds_ij == 0 {
                    continue;
                }
                let mut gap_ij = [0.0; LANES];
                for l in 0..LANES {
                    gap_ij[l] = ci.gap2[l] + cj.gap2[l];
                }
                let hash_ij = ci.hash ^ cj.hash;
                for (dk, ck) in axes[2].iter().enumerate() {
                    let mut near = [false; LANES];
                    for l in 0..LANES {
                        near[l] = !(gap_ij[l] + ck.gap2[l] >= r2);
                    }
                    let live = holds_ij & ck.holds & mask(&near);
                    if live == 0 {
                        continue;
                    }
                    let key = [lo[0] + di as i64, lo[1] + dj as i64, lo[2] + dk as i64];
                    let h = hash_mix(hash_ij ^ ck.hash);
                    if self.occupied.may_hold(h)
                        && let Some(blocks) = self.cells.get(key, h)
                    {
                        sum_lanes(blocks, [&ci.q, &cj.q, &ck.q], n, live, sums);
                    }
                }
            }
        }
    }
}

/// Adds to `sums`, for each lane of `live`, the power of the photons of
/// `blocks` within their radius of the lane's point `q` (in the cells'
/// frame) that arrived on the side the lane's normal `n` faces: photon
/// `s` of a block into the lane's sum `s`, with `sum_blocks`'s arithmetic
/// (`photon_terms`).
#[inline(always)]
fn sum_lanes(blocks: &[Block], q: [&Lanes<f32>; 3], n: &[Lanes<f32>; 3], live: u32, sums: &mut Sums) {
    let live: Lanes<bool> = std::array::from_fn(|l| live >> l & 1 != 0);
    for b in blocks {
        for s in 0..BLOCK {
            let p = [b.p[0][s], b.p[1][s], b.p[2][s]];
            let dir = [b.dir[0][s], b.dir[1][s], b.dir[2][s]];
            let power = [b.power[0][s], b.power[1][s], b.power[2][s]];
            let r2 = b.r2[s];
            let sum = &mut sums[s];
            for l in 0..LANES {
                let (at, normal) = ([q[0][l], q[1][l], q[2][l]], [n[0][l], n[1][l], n[2][l]]);
                let (d2, facing) = photon_terms(p, at, dir, normal);
                let near = live[l] & (d2 < r2) & (facing < 0.0);
                for c in 0..3 {
                    sum[c][l] += if near { power[c] } else { 0.0 };
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::photon::Photon;
    use crate::sampling::Sampler;
    use glam::DVec3;

    /// A packet's irradiance is each lane's own, bit for bit: lanes close
    /// together (one walk for all), spread over many cells (one by one)
    /// and in between, on photons of several passes and groups, with
    /// normals both ways, dead lanes and lanes in empty space.
    #[test]
    fn lanes_give_each_lanes_irradiance_bit_for_bit() {
        let mut rng = Sampler::new(11, 2, 5);
        let mut m = PhotonMap::new(0.05);
        for _ in 0..20 {
            let pass: Vec<Photon> = (0..1000)
                .map(|_| {
                    let (u, v) = rng.next_2d();
                    let w = rng.next_f64();
                    let dir = if w < 0.7 { -DVec3::Z } else { DVec3::new(0.6, 0.0, 0.8) };
                    let p = DVec3::new(u - 0.5, v - 0.5, 0.02 * (w - 0.5));
                    Photon::new(p, dir, glam::DVec3::new(1e-3, 2e-3, 5e-4))
                })
                .collect();
            m.add_pass(&pass);
        }
        assert!(m.groups.len() >= 2);
        let (mut walked, mut found) = (0, 0);
        for spread in [1e-4, 0.01, 0.04, 0.1, 0.5, 3.0] {
            for t in 0..40 {
                let (u, v) = rng.next_2d();
                let centre = DVec3::new(u - 0.5, v - 0.5, 0.0);
                let (mut x, mut nv) = ([[0.0; LANES]; 3], [[0.0; LANES]; 3]);
                let live = if t % 5 == 0 { 0b1011_0110 } else { 0xff };
                for l in 0..LANES {
                    let (a, b) = rng.next_2d();
                    let p = centre + DVec3::new(a - 0.5, b - 0.5, 0.01 * (a - b)) * spread;
                    let nz = if (l + t) % 4 == 0 { -1.0 } else { 1.0 };
                    let n = DVec3::new(0.1 * a, -0.1 * b, nz).normalize();
                    for c in 0..3 {
                        (x[c][l], nv[c][l]) = (p[c], n[c]);
                    }
                }
                let q = Queries { x: &x, n: &nv, live };
                let got = m.irradiance_lanes(q);
                for l in 0..LANES {
                    let want = if live >> l & 1 != 0 {
                        m.irradiance(lane(&x, l), lane(&nv, l))
                    } else {
                        Rgb::ZERO
                    };
                    let bits = |c: Rgb| [c.x.to_bits(), c.y.to_bits(), c.z.to_bits()];
                    assert_eq!(bits(got[l]), bits(want), "spread {spread}, query {t}, lane {l}");
                    found += usize::from(want.x > 0.0);
                }
                let n = q.n.map(|c| c.map(|v| v as f32));
                let cells = m.groups[0].reach_lanes(q.x, q.live);
                walked += usize::from(m.groups[0].gather_lanes(q.x, &n, &cells, &mut [Rgb::ZERO; LANES]));
            }
        }
        assert!(found > 500, "{found} lanes find photons");
        assert!((60..200).contains(&walked), "{walked} of 240 packets walked in lanes");
    }

    /// The irradiance of a packet of 8 live lanes at `x` (normals `nv`),
    /// having checked that each lane's is its own, bit for bit.
    fn all_lanes_are_each_lanes(m: &PhotonMap, x: &[Lanes<f64>; 3], nv: &[Lanes<f64>; 3]) -> Lanes<Rgb> {
        let got = m.irradiance_lanes(Queries { x, n: nv, live: 0xff });
        for l in 0..LANES {
            let want = m.irradiance(lane(x, l), lane(nv, l));
            let bits = |c: Rgb| [c.x.to_bits(), c.y.to_bits(), c.z.to_bits()];
            assert_eq!(bits(got[l]), bits(want), "lane {l} at {}", lane(x, l));
        }
        got
    }

    /// With families gathered within radii of their own (layers of groups
    /// at four scales), each lane still gets its own irradiance, bit for
    /// bit.
    #[test]
    fn lanes_give_each_lanes_irradiance_with_families() {
        let mut rng = Sampler::new(12, 3, 1);
        let mut m = PhotonMap::with_families(0.04, &[(1, 2), (2, -2), (5, 3)]);
        for _ in 0..6 {
            let pass: Vec<Photon> = (0..3000)
                .map(|i| {
                    let (u, v) = rng.next_2d();
                    let p = DVec3::new(u - 0.5, v - 0.5, 0.0);
                    Photon::new(p, -DVec3::Z, DVec3::new(1e-3, 2e-3, 5e-4)).with_family(i % 7)
                })
                .collect();
            m.add_pass(&pass);
        }
        let mut found = 0;
        for spread in [1e-3, 0.02, 0.1, 0.6] {
            for _ in 0..40 {
                let (u, v) = rng.next_2d();
                let (mut x, nv) = ([[0.0; LANES]; 3], [0.0, 0.0, 1.0].map(|c| [c; LANES]));
                for l in 0..LANES {
                    let (a, b) = rng.next_2d();
                    let p = DVec3::new(u - 0.5 + spread * (a - 0.5), v - 0.5 + spread * (b - 0.5), 0.0);
                    for c in 0..3 {
                        x[c][l] = p[c];
                    }
                }
                let got = all_lanes_are_each_lanes(&m, &x, &nv);
                found += got.iter().filter(|e| e.x > 0.0).count();
            }
        }
        assert!(found > 1000, "{found} lanes find photons");
    }

    /// A packet is turned away at once only where every lane finds
    /// nothing, and most packets in empty space are: sparse photons in a
    /// box, packets of lanes close together (one cell, several, many),
    /// inside and outside the photons' box, some with lanes at NaN.
    #[test]
    fn a_packet_is_turned_away_only_where_no_lane_finds_a_photon() {
        let mut rng = Sampler::new(3, 1, 4);
        let mut point = |scale: f64| {
            let (u, v) = rng.next_2d();
            let (w, _) = rng.next_2d();
            DVec3::new(u - 0.5, v - 0.5, w - 0.5) * scale
        };
        let pass: Vec<Photon> = (0..80)
            .map(|_| Photon::new(point(10.0), -DVec3::Z, DVec3::ONE))
            .collect();
        let mut m = PhotonMap::new(0.05);
        m.add_pass(&pass);
        let g = &m.groups[0];
        let (mut empty, mut turned_away) = (0, 0);
        for t in 0..3000 {
            // Half the packets about a photon, half anywhere.
            let centre = if t % 2 == 0 {
                point(12.0)
            } else {
                pass[t % 80].p + point(0.1)
            };
            let spread = [1e-3, 0.05, 0.3, 2.0][t % 4];
            let (mut x, nv) = ([[0.0; LANES]; 3], [0.0, 0.0, 1.0].map(|v| [v; LANES]));
            for l in 0..LANES {
                let p = centre + point(spread);
                for c in 0..3 {
                    x[c][l] = if t % 7 == 0 && l == 3 { f64::NAN } else { p[c] };
                }
            }
            let live = if t % 5 == 0 { 0b0110_1101 } else { 0xff };
            let e = m.irradiance_lanes(Queries { x: &x, n: &nv, live });
            let nothing = (0..LANES).all(|l| e[l] == Rgb::ZERO);
            let (lo, hi) = packet_box(&x, live);
            let far = g.packet_far(lo, hi);
            assert!(!far || nothing, "packet {t} turned away with photons in reach");
            empty += usize::from(nothing);
            turned_away += usize::from(far);
        }
        assert!(empty < 2900, "{empty} of 3000 packets find nothing");
        assert!(
            turned_away * 10 > empty * 3,
            "{turned_away} of {empty} empty packets turned away"
        );
    }

    /// Lanes far apart at the ends of the keys' range (cells saturated at
    /// both ends of `i64`), photons there too, and a lane at zero: the
    /// lanes still give each lane's own irradiance, bit for bit.
    #[test]
    fn lanes_at_the_ends_of_the_key_range_give_each_lanes_irradiance() {
        let far = 1e300;
        let spots = [DVec3::new(far, 0.0, 0.0), DVec3::new(-far, 0.0, 0.0), DVec3::ZERO];
        let pass: Vec<Photon> = spots
            .iter()
            .flat_map(|&c| (0..5).map(move |i| Photon::new(c + DVec3::X * (0.01 * i as f64), -DVec3::Z, DVec3::ONE)))
            .collect();
        let mut m = PhotonMap::new(0.1);
        m.add_pass(&pass);
        let (mut x, mut nv) = ([[0.0; LANES]; 3], [[0.0; LANES]; 3]);
        for l in 0..LANES {
            let p = spots[l % 3] + DVec3::new(0.003 * l as f64, 0.001, 0.0);
            for c in 0..3 {
                (x[c][l], nv[c][l]) = (p[c], DVec3::Z[c]);
            }
        }
        let got = all_lanes_are_each_lanes(&m, &x, &nv);
        assert!(got[2].x > 0.0, "the photons at zero are found");
    }
}
