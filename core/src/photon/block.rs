//! A cell's photons as `f32` columns, four to a block ([`Block`]), and the
//! test of a query against them ([`photon_terms`], [`sum_blocks`]): the
//! arithmetic every gather of the map runs, one query at a time or a
//! packet's lanes at once (`lanes.rs`).

use glam::Vec4;

/// Photons a [`Block`] holds: the lanes of one step of the gather loop.
/// Four, not eight: a cell holds a few photons a group (rim-lens: 78
/// photons in 5.3 cells a gather), so eight-lane blocks were a third
/// empty lanes; four cut the gather's instructions 9 % and its time 5 %
/// (docs/performance.md, round 18).
pub(super) const BLOCK: usize = 4;

/// Up to [`BLOCK`] photons of one cell as `f32` columns: positions from the
/// cell's low corner (exact to `f32` of the cell's side, wherever the scene
/// lies), arrival directions, powers over the area of their pass's disc
/// (`Φ/(π r²)`: each photon's share of its pass's estimate) and their
/// pass's squared radius. An unused lane lies at infinity with no power,
/// no direction and no radius, so it is never within reach.
#[derive(Clone, Debug)]
pub(super) struct Block {
    pub(super) p: [Col; 3],
    pub(super) dir: [Col; 3],
    pub(super) power: [Col; 3],
    pub(super) r2: Col,
    pub(super) len: usize,
}

/// A column of a [`Block`]: its lanes as glam's four-lane vector (an SSE
/// register), so that the gather is vector code in every build; left to
/// the vectoriser, loops over plain `f32` lanes came out as lanes shuffled
/// one by one, no faster than scalar code (`perf annotate`).
pub(super) type Col = Vec4;

impl Block {
    pub(super) const EMPTY: Block = Block {
        p: [Vec4::INFINITY; 3],
        dir: [Vec4::ZERO; 3],
        power: [Vec4::ZERO; 3],
        r2: Vec4::ZERO,
        len: 0,
    };

    /// Sets lane `l` of column `c`.
    pub(super) fn set(c: &mut Col, l: usize, v: f32) {
        c[l] = v;
    }
}

/// Adds to `acc`, lane by lane, the power of the photons of `blocks` within
/// their radius of `q` (in the cells' frame) that arrived on the side the
/// normal `n` faces.
#[inline(always)]
pub(super) fn sum_blocks(blocks: &[Block], q: [f32; 3], n: [f32; 3], acc: &mut [Col; 3]) {
    let (q, n) = (q.map(Vec4::splat), n.map(Vec4::splat));
    for b in blocks {
        let (d2, facing) = photon_terms(b.p, q, b.dir, n);
        let near = d2.cmplt(b.r2) & facing.cmplt(Vec4::ZERO);
        // A photon out of reach adds +0, as `0 · power` would (powers are
        // finite and not negative): the same sums, with a mask in place of
        // a product.
        for (a, p) in acc.iter_mut().zip(&b.power) {
            *a += Vec4::select(near, *p, Vec4::ZERO);
        }
    }
}

/// The photon test's arithmetic: the squared distance from the query at
/// `q` to the photon at `p`, and `dir·n` of its arrival direction and the
/// query's normal (negative where it arrived on the side `n` faces), in
/// this order of operations. For the four photons of a block (`Vec4`,
/// [`sum_blocks`]) and for one photon and one lane (`f32`,
/// `lanes::sum_lanes`), so that both give the same bits.
#[inline(always)]
pub(super) fn photon_terms<T>(p: [T; 3], q: [T; 3], dir: [T; 3], n: [T; 3]) -> (T, T)
where
    T: Copy + std::ops::Sub<Output = T> + std::ops::Mul<Output = T> + std::ops::Add<Output = T>,
{
    let d = [p[0] - q[0], p[1] - q[1], p[2] - q[2]];
    let d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    (d2, dir[0] * n[0] + dir[1] * n[1] + dir[2] * n[2])
}
