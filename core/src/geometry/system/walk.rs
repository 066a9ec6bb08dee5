//! Rays through a system: the real ray `lens trace` follows (refraction at
//! each cap, reflection under TIR, absorption at rings, edges and the
//! diaphragm) and the Whitted tree the renderer and the photons follow
//! (a Fresnel split at every cap, each branch pruned by its weight). Both
//! take the same step at a cap ([`LensSystem::interface`]).

use super::pieces::{Crossing, Piece};
use super::{LensSystem, MAX_SURFACES};
use crate::geometry::Pruning;
use crate::optics;
use crate::sampling::{mix64, unit_f64};
use glam::DVec3;

/// Reflections a real ray may make before it is reported trapped.
pub const MAX_REFLECTIONS: u32 = 64;

/// How a real ray ends.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayStatus {
    /// It met the system and left it.
    Transmitted,
    /// It met no piece.
    Miss,
    /// A ring, an edge or the stop's diaphragm absorbed it.
    Absorbed,
    /// More than [`MAX_REFLECTIONS`] reflections inside.
    Trapped,
}

impl RayStatus {
    pub fn name(self) -> &'static str {
        match self {
            RayStatus::Transmitted => "transmitted",
            RayStatus::Miss => "miss",
            RayStatus::Absorbed => "absorbed",
            RayStatus::Trapped => "trapped",
        }
    }
}

/// What happened at a piece.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EventKind {
    Refract,
    Reflect,
    Absorb,
}

impl EventKind {
    pub fn name(self) -> &'static str {
        match self {
            EventKind::Refract => "refract",
            EventKind::Reflect => "reflect",
            EventKind::Absorb => "absorb",
        }
    }
}

/// One event of a real ray, in world coordinates: the point and the
/// direction after it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Event {
    pub piece: Piece,
    pub kind: EventKind,
    pub point: DVec3,
    pub dir: DVec3,
}

/// A real ray through a system.
#[derive(Clone, Debug, PartialEq)]
pub struct RealRay {
    pub status: RayStatus,
    pub events: Vec<Event>,
    pub reflections: u32,
    /// Where it left (transmitted rays): the last event's point and
    /// direction, and the piece.
    pub exit: Option<(Piece, DVec3, DVec3)>,
    /// Local point and direction after the last event (for the figures,
    /// which measure in the system's frame).
    pub local: (DVec3, DVec3),
}

/// One ray out of the system's Whitted tree, in world coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SystemBranch {
    pub point: DVec3,
    pub dir: DVec3,
    /// The normal of the piece it leaves, on the side it leaves to.
    pub normal: DVec3,
    /// The share of the light that met the system leaving along it.
    pub weight: f64,
    /// Reflections (partial and total, the first one outside included).
    pub reflections: u32,
}

/// The crossing of a cap for a ray along `u`: the normal facing the ray,
/// the indices it goes from and to, and the refracted direction with its
/// Fresnel reflectance ([`optics::crossing`]).
#[derive(Clone, Copy, Debug)]
pub struct Interface {
    pub nf: DVec3,
    pub n1: f64,
    pub n2: f64,
    pub crossing: optics::Crossing,
}

impl LensSystem {
    /// Every medium's index at `lambda_um`, in order: air before the first
    /// surface, then the medium after each (what [`LensSystem::interface`]
    /// reads; evaluated once a ray, not at each crossing).
    pub fn media(&self, lambda_um: f64) -> [f64; MAX_SURFACES + 1] {
        let mut m = [1.0; MAX_SURFACES + 1];
        for (k, s) in self.surfaces.iter().enumerate() {
            m[k + 1] = s.n.at(lambda_um);
        }
        m
    }

    /// The step at a cap: which way the ray crosses cap `k` at the local
    /// point `x` (the cap's normal points to the side before it), from which
    /// medium into which (`media`: [`LensSystem::media`]).
    #[inline(always)]
    pub fn interface(&self, k: usize, x: DVec3, u: DVec3, media: &[f64]) -> Interface {
        let g = self.cap_normal(k, x);
        let (before, after) = (media[k], media[k + 1]);
        // Along the light (u·g < 0) from before into after.
        let (nf, n1, n2) = if u.dot(g) < 0.0 {
            (g, before, after)
        } else {
            (-g, after, before)
        };
        Interface {
            nf,
            n1,
            n2,
            crossing: optics::crossing(u, nf, n1, n2),
        }
    }

    /// The real ray from the world `origin` along `dir` (any length) at
    /// `lambda_um`: refraction at each cap, reflection under TIR.
    pub fn trace(&self, origin: DVec3, dir: DVec3, lambda_um: f64) -> RealRay {
        let mut events = Vec::new();
        let mut reflections = 0;
        let (status, x, u) = self.walk_real(origin, dir, &self.media(lambda_um), &mut |piece, kind, x, u| {
            reflections += u32::from(kind == EventKind::Reflect);
            events.push(Event {
                piece,
                kind,
                point: self.world_point(x),
                dir: self.world_dir(u),
            });
        });
        let exit = (status == RayStatus::Transmitted)
            .then(|| events.last().map(|e| (e.piece, e.point, e.dir)))
            .flatten();
        RealRay {
            status,
            events,
            reflections,
            exit,
            local: (x, u),
        }
    }

    /// Where the real ray from the world `origin` along `dir` leaves the
    /// system (world point and unit direction), in `media`
    /// ([`LensSystem::media`]), if it crosses the system *in order*: one
    /// refraction at each cap that separates two media, surface after
    /// surface (either way), and nothing else; `None` for any other ray
    /// (stopped, reflected, or out through a gap between elements, where a
    /// camera's barrel would stop it). The walk of [`LensSystem::trace`],
    /// keeping no events (a camera ray a sample).
    pub fn pass(&self, origin: DVec3, dir: DVec3, media: &[f64]) -> Option<(DVec3, DVec3)> {
        let (mut last, mut step, mut count, mut in_order) = (None::<usize>, 0i64, 0, true);
        let (status, x, u) = self.walk_real(origin, dir, media, &mut |piece, kind, _, _| {
            let k = piece.surface;
            let ok;
            (ok, step) = self.order_step(last, step, k);
            in_order &= kind == EventKind::Refract && ok;
            last = Some(k);
            count += 1;
        });
        let whole = count == self.boundary_caps();
        (status == RayStatus::Transmitted && in_order && whole).then(|| (self.world_point(x), self.world_dir(u)))
    }

    /// Whether a pass that crossed cap `last` (`None`: none yet), with
    /// `step` between its last two caps (0: fewer than two), stays in
    /// order crossing cap `k` (a boundary, the same way along the system,
    /// not the same cap again); and the step it keeps then. The rule of
    /// [`LensSystem::pass`] and its lanes.
    #[inline(always)]
    pub(super) fn order_step(&self, last: Option<usize>, step: i64, k: usize) -> (bool, i64) {
        let s = last.map_or(0, |l| k as i64 - l as i64);
        let ok = self.cap_is_boundary(k) && (step == 0 || s.signum() == step.signum()) && (s != 0 || last.is_none());
        (ok, if last.is_some() { s } else { step })
    }

    /// How many caps a pass crosses: those that are boundaries.
    pub(super) fn boundary_caps(&self) -> usize {
        (0..self.len()).filter(|&k| self.cap_is_boundary(k)).count()
    }

    /// The walk of a real ray: each event (the piece, what happened, the
    /// local point and direction after it) handed to `event`; returns how
    /// it ended and the local point and direction after its last event.
    fn walk_real(
        &self,
        origin: DVec3,
        dir: DVec3,
        media: &[f64],
        event: &mut impl FnMut(Piece, EventKind, DVec3, DVec3),
    ) -> (RayStatus, DVec3, DVec3) {
        let (mut x, mut u, t0) = self.localize(origin, dir);
        let mut lo = -t0;
        let mut from = None;
        let (mut reflections, mut events) = (0, 0);
        // Refractions are bounded by the pieces a ray can meet going one
        // way; reflections by MAX_REFLECTIONS.
        let most = MAX_REFLECTIONS as usize + 8 * self.len() + 8;
        while let Some(c) = self.next_crossing(x, u, from, lo, f64::INFINITY) {
            let (kind, next) = self.real_step(&c, u, media);
            // As the lens's tracer counts: MAX_REFLECTIONS are followed,
            // one more makes the ray trapped (not listed).
            if kind == EventKind::Reflect && reflections == MAX_REFLECTIONS {
                return (RayStatus::Trapped, x, u);
            }
            x = c.x;
            u = next;
            lo = 0.0;
            from = Some(c.piece.surface);
            reflections += u32::from(kind == EventKind::Reflect);
            events += 1;
            event(c.piece, kind, x, u);
            if kind == EventKind::Absorb {
                return (RayStatus::Absorbed, x, u);
            }
            if events > most {
                return (RayStatus::Trapped, x, u);
            }
        }
        let status = if events > 0 {
            RayStatus::Transmitted
        } else {
            RayStatus::Miss
        };
        (status, x, u)
    }

    /// What a real ray along `u` does at crossing `c`, and its direction
    /// after.
    fn real_step(&self, c: &Crossing, u: DVec3, media: &[f64]) -> (EventKind, DVec3) {
        if c.piece.is_opaque() {
            return (EventKind::Absorb, u);
        }
        let i = self.interface(c.piece.surface, c.x, u, media);
        if i.crossing.total {
            (EventKind::Reflect, optics::reflect(u, i.nf))
        } else {
            (EventKind::Refract, i.crossing.dir)
        }
    }
}

/// A branch of the tree still inside (or between the elements of) the
/// system.
#[derive(Clone, Copy, Debug)]
pub(super) struct Live {
    pub x: DVec3,
    pub u: DVec3,
    weight: f64,
    reflections: u32,
    pub from: Option<usize>,
    /// Crossings so far (the tree's bound on refractions).
    steps: u32,
}

impl Live {
    /// Where its search for the next crossing starts: the root's at the
    /// world ray's origin (`−t0` along the local ray), a branch's at its
    /// own start.
    #[inline(always)]
    pub fn lo(&self, t0: f64) -> f64 {
        if self.steps == 0 { -t0 } else { 0.0 }
    }
}

/// A ray's tree under way: the branches still to walk, its pruning, the
/// seed of its ghosts' roulette and where its world origin lies along the
/// local ray (`−t0`).
pub(super) struct Tree<'a> {
    pub pending: Pending<'a>,
    prune: Pruning,
    seed: u64,
    pub t0: f64,
}

/// Branches held at once; a tree that would hold more drops its lightest.
pub(super) const STACK: usize = 32;

/// The branches of a tree still to walk, and the weight dropped so far.
pub(super) struct Pending<'a> {
    /// `None` past `len`: only a branch's slot is written when it is
    /// pushed (filling 32 slots with copies of the root each tree cost 5 %
    /// of a singlet's frame).
    stack: &'a mut [Option<Live>; STACK],
    len: usize,
    pub dropped: f64,
}

impl Pending<'_> {
    /// The branch [`Pending::pop`] would give.
    #[inline(always)]
    pub fn peek(&self) -> Option<&Live> {
        self.len.checked_sub(1).and_then(|k| self.stack[k].as_ref())
    }

    #[inline(always)]
    pub fn pop(&mut self) -> Option<Live> {
        self.len = self.len.checked_sub(1)?;
        self.stack[self.len]
    }

    /// Keeps `child` of a branch with `parent` reflections to walk: unless
    /// pruned (its weight dropped), lost at a ghost's roulette, or beyond
    /// the stack (dropped).
    #[inline(always)]
    fn push(&mut self, child: Live, parent: u32, prune: &Pruning, seed: u64) {
        let born = child.reflections > parent;
        let kept = if born {
            prune.keeps_on(child.weight, parent)
        } else {
            prune.keeps(child.weight)
        };
        if !kept {
            self.dropped += child.weight;
            return;
        }
        let Some(child) = (if born {
            roulette(prune, child, seed)
        } else {
            Some(child)
        }) else {
            return;
        };
        if self.len < STACK {
            self.stack[self.len] = Some(child);
            self.len += 1;
        } else {
            self.dropped += child.weight;
        }
    }
}

impl LensSystem {
    /// Every ray out of the system for light arriving from outside along
    /// the world ray `origin + t·dir` (unit `dir`), at `lambda_um`: the
    /// Whitted tree with a Fresnel split at every cap (the reflection at
    /// the first one included), each branch pruned by `prune`, rings,
    /// edges and the diaphragm absorbing; ghosts play `prune`'s roulette,
    /// decided by a hash of the ray and the branch, so the same ray gives
    /// the same tree. Each ray out is handed to `emit` in a fixed order.
    /// Returns the weight dropped by pruning (a ghost lost at the roulette
    /// is not counted: the survivors carry its light in expectation).
    pub fn branches(
        &self,
        origin: DVec3,
        dir: DVec3,
        lambda_um: f64,
        prune: &Pruning,
        emit: &mut impl FnMut(SystemBranch),
    ) -> f64 {
        let media = self.media(lambda_um);
        // On the stack where it stays (moving 32 branches cost 3 % of a frame).
        let mut stack = [None; STACK];
        let mut tree = self.tree(origin, dir, prune, &mut stack);
        let most = self.most_steps();
        while let Some(b) = tree.pending.pop() {
            let c = self.next_crossing(b.x, b.u, b.from, b.lo(tree.t0), f64::INFINITY);
            self.tree_step(&mut tree, &b, c, &media, most, emit);
        }
        tree.pending.dropped
    }

    /// The tree of the world ray `origin + t·dir` with its root on `stack`:
    /// the system's pruning ([`LensSystem::tree_pruning`]) and the ray's
    /// hash for the ghosts' roulette.
    #[inline(always)]
    pub(super) fn tree<'a>(
        &self,
        origin: DVec3,
        dir: DVec3,
        prune: &Pruning,
        stack: &'a mut [Option<Live>; STACK],
    ) -> Tree<'a> {
        let (x, u, t0) = self.localize(origin, dir);
        stack[0] = Some(Live {
            x,
            u,
            weight: 1.0,
            reflections: 0,
            from: None,
            steps: 0,
        });
        let prune = self.tree_pruning(prune);
        // Only a roulette needs the ray's hash.
        let seed = if prune.roulette > 0.0 { ray_hash(origin, dir) } else { 0 };
        Tree {
            pending: Pending {
                stack,
                len: 1,
                dropped: 0.0,
            },
            prune,
            seed,
            t0,
        }
    }

    /// A tree with nothing to walk, on `stack` (a lane of
    /// [`super::tree_lanes`] with no ray).
    #[inline(always)]
    pub(super) fn idle_tree<'a>(stack: &'a mut [Option<Live>; STACK]) -> Tree<'a> {
        Tree {
            pending: Pending {
                stack,
                len: 0,
                dropped: 0.0,
            },
            prune: Pruning::NONE,
            seed: 0,
            t0: 0.0,
        }
    }

    /// The crossings a branch may make before it is dropped.
    #[inline(always)]
    pub(super) fn most_steps(&self) -> u32 {
        8 * self.len() as u32 + 8
    }

    /// The tree's step for the branch `b` whose nearest crossing is `c`:
    /// out of the system where nothing is ahead (handed to `emit`),
    /// stopped at an opaque piece, dropped past `most` crossings, else
    /// split at the cap into its refraction and reflection (pushed to
    /// walk, the refraction first). The scalar tree and the lanes'
    /// ([`super::tree_lanes`]) take it.
    #[inline(always)]
    pub(super) fn tree_step(
        &self,
        tree: &mut Tree,
        b: &Live,
        c: Option<Crossing>,
        media: &[f64],
        most: u32,
        emit: &mut impl FnMut(SystemBranch),
    ) {
        let Some(c) = c else {
            if b.steps > 0 {
                emit(self.leaving(b));
            }
            return;
        };
        if c.piece.is_opaque() {
            return;
        }
        if b.steps > most {
            tree.pending.dropped += b.weight;
            return;
        }
        let i = self.interface(c.piece.surface, c.x, b.u, media);
        let r = if i.crossing.total { 1.0 } else { i.crossing.reflectance };
        let next = |u, weight, reflections| Live {
            x: c.x,
            u,
            weight,
            reflections,
            from: Some(c.piece.surface),
            steps: b.steps + 1,
        };
        let children = [
            (!i.crossing.total).then(|| next(i.crossing.dir, b.weight * (1.0 - r), b.reflections)),
            Some(next(optics::reflect(b.u, i.nf), b.weight * r, b.reflections + 1)),
        ];
        // Pushed reflection first, so the refraction is walked first.
        for child in children.into_iter().rev().flatten() {
            tree.pending.push(child, b.reflections, &tree.prune, tree.seed);
        }
    }

    /// `prune` for this system's tree: a singlet's tree is the biconvex
    /// lens's, followed exactly (its ghosts are few), so it plays no
    /// roulette; the ghosts between elements grow as the square.
    fn tree_pruning(&self, prune: &Pruning) -> Pruning {
        let elements = (0..self.len()).filter(|&k| self.cap_is_boundary(k)).count() > 2;
        Pruning {
            roulette: if elements { prune.roulette } else { 0.0 },
            ..*prune
        }
    }

    /// The ray out for a branch with nothing ahead.
    fn leaving(&self, b: &Live) -> SystemBranch {
        let k = b.from.unwrap_or(0);
        let g = self.cap_normal(k, b.x);
        let side = if g.dot(b.u) >= 0.0 { g } else { -g };
        SystemBranch {
            point: self.world_point(b.x),
            dir: self.world_dir(b.u),
            normal: self.world_dir(side),
            weight: b.weight,
            reflections: b.reflections,
        }
    }
}

/// A ghost's Russian roulette ([`Pruning`]'s `roulette`), played once where
/// it is reflected: `child` as it is (not a ghost, or heavy enough), at the
/// roulette's weight, or lost.
#[inline]
fn roulette(prune: &Pruning, mut child: Live, seed: u64) -> Option<Live> {
    let w = prune.scale * child.weight;
    if child.reflections < 2 || !(w < prune.roulette) {
        return Some(child);
    }
    let u = unit_f64(mix(seed, child.x, child.u));
    if u * prune.roulette < w {
        child.weight = prune.roulette / prune.scale;
        Some(child)
    } else {
        None
    }
}

/// A hash of a ray (its origin's and direction's bits).
fn ray_hash(origin: DVec3, dir: DVec3) -> u64 {
    mix(0x243f_6a88_85a3_08d3, origin, dir)
}

/// `seed` mixed with the bits of `x` and `u` ([`mix64`] steps).
fn mix(seed: u64, x: DVec3, u: DVec3) -> u64 {
    [x.x, x.y, x.z, u.x, u.y, u.z].iter().fold(seed, |h, v| {
        mix64((h ^ v.to_bits()).wrapping_add(0x9e37_79b9_7f4a_7c15))
    })
}
