//! [`LensSystem::pass`] for [`LANES`] rays at once: the lens camera's
//! sensor rays, which all cross the same surfaces in the same order.
//!
//! The lanes walk in lockstep: at each step every live lane looks for its
//! nearest crossing, the faces taken in the walk's order (one loop over
//! the faces for the lanes walking toward `+z`, one for those toward
//! `−z`), each lane starting where the scalar walk starts
//! ([`Face::skipped`](super::pieces)) and stopping where it stops; at a
//! face each lane takes the scalar walk's own step
//! ([`LensSystem::face_step`]), and at a cap the scalar
//! [`LensSystem::interface`]. So every lane performs the scalar pass's
//! operations in its order and gives its bits (`tests/system_lanes.rs`).
//! A lane drops out, with the scalar pass's `None`, at the first event
//! that makes its pass out of order (a reflection, an absorption, a cap
//! met twice or against the direction); it is done, with the ray out,
//! where nothing is ahead. The lane loops (`for l in 0..LANES` over
//! arrays) are built for AVX2 and AVX-512 ([`with_avx2!`]).

// Lane loops index several arrays by the lane: the form the vectoriser wants.
#![allow(clippy::needless_range_loop)]

use super::LensSystem;
use super::pieces::{Nearest, Piece, PieceKind};
use crate::simd::{LANES, Lanes, lane, mask, set_lane, with_avx2};
use glam::DVec3;

/// What [`LensSystem::pass`] gives one ray: the world point and direction
/// where it leaves the system, or `None`.
pub type Passed = Option<(DVec3, DVec3)>;

/// No surface (a lane's `from` or `last` before its first crossing).
pub(super) const NONE: usize = usize::MAX;

/// The lanes' walk: local point and direction, the start of the stretch
/// to search, and what [`LensSystem::pass`] keeps to judge the order.
pub(super) struct Walk {
    pub x: [Lanes<f64>; 3],
    pub u: [Lanes<f64>; 3],
    pub lo: Lanes<f64>,
    /// The cap a lane starts on (its own root is not a crossing).
    pub from: Lanes<usize>,
    /// The step between the last two caps (its sign is the direction).
    step: Lanes<i64>,
    /// Crossings so far.
    count: Lanes<usize>,
    pub live: Lanes<bool>,
}

impl Walk {
    /// No lane walking yet.
    pub fn new() -> Walk {
        Walk {
            x: [[0.0; LANES]; 3],
            u: [[0.0; LANES]; 3],
            lo: [0.0; LANES],
            from: [NONE; LANES],
            step: [0; LANES],
            count: [0; LANES],
            live: [false; LANES],
        }
    }
}

/// Each lane's nearest crossing ([`Nearest`]'s fields, as lanes).
pub(super) struct Found {
    t: Lanes<f64>,
    surface: Lanes<usize>,
    kind: Lanes<PieceKind>,
    x: [Lanes<f64>; 3],
}

impl Found {
    /// Lane `l`'s [`Nearest`], its search starting at `t_lo`.
    #[inline(always)]
    pub fn near(&self, l: usize, t_lo: f64) -> Nearest {
        Nearest {
            t: self.t[l],
            piece: Piece {
                surface: self.surface[l],
                kind: self.kind[l],
            },
            x: lane(&self.x, l),
            t_lo,
        }
    }

    #[inline(always)]
    fn set(&mut self, l: usize, near: &Nearest) {
        self.t[l] = near.t;
        self.surface[l] = near.piece.surface;
        self.kind[l] = near.piece.kind;
        set_lane(&mut self.x, l, near.x);
    }
}

with_avx2! {
    /// [`LensSystem::pass`] of the rays `origin[l] + t·dir[l]` of the lanes
    /// `l` with `live[l]` (others: `None`), in `media`; lane for lane, the
    /// same bits.
    pub fn pass_lanes / pass_lanes_avx2 => pass_lanes_impl(
        system: &LensSystem,
        origin: &[Lanes<f64>; 3],
        dir: &[Lanes<f64>; 3],
        live: Lanes<bool>,
        media: &[f64]
    ) -> Lanes<Passed>
}

#[inline(always)]
fn pass_lanes_impl(
    system: &LensSystem,
    origin: &[Lanes<f64>; 3],
    dir: &[Lanes<f64>; 3],
    live: Lanes<bool>,
    media: &[f64],
) -> Lanes<Passed> {
    let mut w = Walk { live, ..Walk::new() };
    for l in 0..LANES {
        let (x, u, t0) = system.localize(lane(origin, l), lane(dir, l));
        set_lane(&mut w.x, l, x);
        set_lane(&mut w.u, l, u);
        w.lo[l] = -t0;
    }
    let boundaries = system.boundary_caps();
    let mut out = [None; LANES];
    while mask(&w.live) != 0 {
        let found = system.lane_crossings(&w);
        system.lane_events(&mut w, &found, boundaries, &mut out);
        system.lane_refractions(&mut w, &found, media);
    }
    out
}

impl LensSystem {
    /// [`pass_lanes`] as a method.
    #[inline]
    pub fn pass_lanes(
        &self,
        origin: &[Lanes<f64>; 3],
        dir: &[Lanes<f64>; 3],
        live: Lanes<bool>,
        media: &[f64],
    ) -> Lanes<Passed> {
        pass_lanes(self, origin, dir, live, media)
    }

    /// Each live lane's nearest crossing ([`LensSystem::next_crossing`]
    /// with `t_hi` infinite): the lanes walking toward `+z`, then those
    /// toward `−z`, each group over the faces in its order.
    #[inline(always)]
    pub(super) fn lane_crossings(&self, w: &Walk) -> Found {
        let none = Nearest::new(0.0, f64::INFINITY);
        let mut found = Found {
            t: [none.t; LANES],
            surface: [none.piece.surface; LANES],
            kind: [none.piece.kind; LANES],
            x: [[0.0; LANES]; 3],
        };
        let forward: Lanes<bool> = std::array::from_fn(|l| w.live[l] && w.u[2][l] >= 0.0);
        let backward: Lanes<bool> = std::array::from_fn(|l| w.live[l] && !(w.u[2][l] >= 0.0));
        if mask(&forward) != 0 {
            self.lane_search::<true>(w, forward, &mut found);
        }
        if mask(&backward) != 0 {
            self.lane_search::<false>(w, backward, &mut found);
        }
        found
    }

    /// [`LensSystem::next_crossing`]'s walk over the faces for the lanes
    /// of `group`, all walking toward `+z` (`FORWARD`) or `−z`: a lane
    /// starts at the first face it does not skip and takes
    /// [`LensSystem::face_gates`] and the tests they open (the scalar step) at each until it stops.
    #[inline(always)]
    fn lane_search<const FORWARD: bool>(&self, w: &Walk, group: Lanes<bool>, found: &mut Found) {
        let faces = &self.faces[..];
        let start: Lanes<f64> = std::array::from_fn(|l| w.x[2][l] + w.lo[l] * w.u[2][l]);
        let (mut started, mut walking) = ([false; LANES], group);
        for i in 0..faces.len() {
            if mask(&walking) == 0 {
                break;
            }
            let k = if FORWARD { i } else { faces.len() - 1 - i };
            let f = &faces[k];
            let (mut cap, mut edge) = ([false; LANES], [false; LANES]);
            for l in 0..LANES {
                started[l] |= !f.skipped(start[l], FORWARD);
                let near = found.near(l, w.lo[l]);
                let ray = (lane(&w.x, l), lane(&w.u, l));
                let go;
                (go, cap[l], edge[l]) = Self::face_gates(f, ray, walking[l] & started[l], f64::INFINITY, &near);
                walking[l] = go | (walking[l] & !started[l]);
            }
            // Each test made for every lane where one lane needs it; only
            // the lanes whose gate is open take what it finds.
            if mask(&cap) != 0 {
                for l in 0..LANES {
                    let mut near = found.near(l, w.lo[l]);
                    let ray = (lane(&w.x, l), lane(&w.u, l));
                    Self::cap_and_ring(k, f, ray, w.from[l] == k, cap[l], &mut near);
                    found.set(l, &near);
                }
            }
            if mask(&edge) != 0 {
                for l in 0..LANES {
                    let mut near = found.near(l, w.lo[l]);
                    Self::edge(k, f, (lane(&w.x, l), lane(&w.u, l)), edge[l], &mut near);
                    found.set(l, &near);
                }
            }
        }
    }

    /// The events of the lanes' crossings as [`LensSystem::pass`] judges
    /// them: a lane with nothing ahead is done (its ray out where it
    /// crossed every cap that is a boundary, in order); one that meets an
    /// opaque piece, or a cap out of order, drops out (`None`).
    #[inline(always)]
    fn lane_events(&self, w: &mut Walk, found: &Found, boundaries: usize, out: &mut Lanes<Passed>) {
        for l in 0..LANES {
            if !w.live[l] {
                continue;
            }
            let near = found.near(l, 0.0);
            if !near.found(f64::INFINITY) {
                w.live[l] = false;
                if w.count[l] > 0 && w.count[l] == boundaries {
                    let (x, u) = (lane(&w.x, l), lane(&w.u, l));
                    out[l] = Some((self.world_point(x), self.world_dir(u)));
                }
                continue;
            }
            let last = (w.from[l] != NONE).then_some(w.from[l]);
            let ok;
            (ok, w.step[l]) = self.order_step(last, w.step[l], near.piece.surface);
            w.live[l] = !near.piece.is_opaque() && ok;
        }
    }

    /// The refraction of each live lane at its cap ([`LensSystem::interface`],
    /// the scalar step); a lane reflected there (TIR) drops out. One loop
    /// with the surface shared when every live lane meets the same.
    #[inline(always)]
    fn lane_refractions(&self, w: &mut Walk, found: &Found, media: &[f64]) {
        let k0 = found.surface[w.live.iter().position(|&b| b).unwrap_or(0)];
        let shared = (0..LANES).all(|l| !w.live[l] || found.surface[l] == k0);
        if shared {
            self.refract_lanes(w, found, media, |_| k0);
        } else {
            self.refract_lanes(w, found, media, |l| found.surface[l]);
        }
    }

    #[inline(always)]
    fn refract_lanes(&self, w: &mut Walk, found: &Found, media: &[f64], surface: impl Fn(usize) -> usize) {
        for l in 0..LANES {
            let x = lane(&found.x, l);
            let i = self.interface(surface(l), x, lane(&w.u, l), media);
            if w.live[l] {
                w.live[l] = !i.crossing.total;
                set_lane(&mut w.x, l, x);
                set_lane(&mut w.u, l, i.crossing.dir);
                w.lo[l] = 0.0;
                w.from[l] = found.surface[l];
                w.count[l] += 1;
            }
        }
    }
}
