//! The pass through a lens system ([`system_rays`]): its Whitted tree,
//! each ray out spawned where it leaves the system; and the trees of the
//! lanes of a packet that enter the same system, walked together
//! beforehand ([`system_trees`]) and handed out lane by lane ([`Replay`]).

use super::PacketPaths;
use super::lens_pass::Transmitted;
use super::scalar::Alone;
use super::shade::{Refraction, into_system};
use super::surface::{Surface, spawn_ray};
use crate::geometry::{LaneTrees, LensSystem, Pruning, SystemBranch};
use crate::math::Ray;
use crate::scene::{Object, Scene};
use crate::simd::{LANES, Lanes, set_lane};
use glam::DVec3;

/// Every ray out of the lens system `sys` (object `obj`) for the ray `ray`
/// that meets it, at `lambda_um`: its Whitted tree
/// ([`LensSystem::branches`], the reflection where it enters included),
/// pruned by `prune`, each ray out handed to `emit` as it leaves the system
/// for good.
#[inline]
pub fn system_rays(
    obj: &Object,
    sys: &LensSystem,
    ray: &Ray,
    lambda_um: f64,
    prune: &Pruning,
    mut emit: impl FnMut(Transmitted),
) {
    sys.branches(ray.origin, ray.dir, lambda_um, prune, &mut |b| emit(carried(obj, b)));
}

/// The ray that carries on from the ray out `b` of the system `obj`.
#[inline(always)]
fn carried(obj: &Object, b: SystemBranch) -> Transmitted {
    Transmitted {
        ray: spawn_ray(b.point, b.normal, b.dir, obj.scale),
        bounces: 2 + b.reflections,
        factor: b.weight,
    }
}

/// Fewer lanes than this entering one system walk their trees one by one.
const MIN_TREES: u32 = 2;

/// The trees [`system_trees`] walked: the lanes (`lanes`) whose surface is
/// the entry into the system of object `object`, each with the pruning
/// `shade_onward` gives its tree, and their rays out.
pub(super) struct SystemTrees {
    lanes: u32,
    object: usize,
    prune: Lanes<Pruning>,
    trees: LaneTrees,
}

impl Default for SystemTrees {
    fn default() -> Self {
        SystemTrees {
            lanes: 0,
            object: 0,
            prune: [Pruning::NONE; LANES],
            trees: LaneTrees::default(),
        }
    }
}

impl SystemTrees {
    /// Lane `l`'s [`Refraction`] for the ray `ray`: its tree where one was
    /// walked.
    #[inline(always)]
    pub(super) fn lane(&self, l: usize, ray: Ray) -> Replay<'_> {
        Replay {
            alone: Alone(ray),
            tree: (self.lanes >> l & 1 != 0).then(|| (self.object, &self.prune[l], &self.trees.out[l][..])),
        }
    }
}

/// Walks together the trees of the lanes of a packet whose surface is a
/// lens system's (the first such system; lanes on another take the scalar
/// path) and whose light `shade_onward` follows into it, each pruned as
/// `shade_onward` prunes it (both ask [`into_system`];
/// [`LensSystem::branches_lanes`]), into `out`;
/// none where the system's trees do not pay in lanes
/// ([`LensSystem::trees_in_lanes`]).
#[inline(always)]
pub(super) fn system_trees(
    scene: &Scene,
    paths: &PacketPaths,
    surfaces: &[Option<Surface>; LANES],
    lambda_um: f64,
    out: &mut SystemTrees,
) {
    out.lanes = 0;
    let mut which: Option<(usize, &LensSystem)> = None;
    let (mut origin, mut dir) = ([[0.0; LANES]; 3], [[0.0; LANES]; 3]);
    for (l, s) in surfaces.iter().enumerate() {
        let Some(s) = s else { continue };
        let Some((sys, prune)) = into_system(scene, s, paths.depth[l], paths.weight[l]) else {
            continue;
        };
        match which {
            Some((i, _)) if i != s.index => continue,
            // The first system's trees walk one by one: no lane is gathered.
            None if !sys.trees_in_lanes() => return,
            _ => {}
        }
        which.get_or_insert((s.index, sys));
        out.lanes |= 1 << l;
        out.prune[l] = prune;
        let ray = paths.rays.ray(l);
        set_lane(&mut origin, l, ray.origin);
        set_lane(&mut dir, l, ray.dir);
    }
    let Some((object, sys)) = which else { return };
    if out.lanes.count_ones() < MIN_TREES {
        out.lanes = 0;
        return;
    }
    out.object = object;
    let live = std::array::from_fn(|l| out.lanes >> l & 1 != 0);
    sys.branches_lanes(&origin, &dir, live, lambda_um, &out.prune, &mut out.trees);
}

/// A packet lane's [`Refraction`]: [`Alone`]'s, but for the rays out of a
/// system whose tree [`system_trees`] walked with the same pruning.
pub(super) struct Replay<'a> {
    alone: Alone,
    tree: Option<(usize, &'a Pruning, &'a [SystemBranch])>,
}

impl Refraction for Replay<'_> {
    #[inline(always)]
    fn fresnel(&self, dir: DVec3, nf: DVec3, n1: f64, n2: f64) -> f64 {
        self.alone.fresnel(dir, nf, n1, n2)
    }

    #[inline(always)]
    fn transmit(&self, s: &Surface, ior: f64, prune: &Pruning, emit: impl FnMut(Transmitted)) {
        self.alone.transmit(s, ior, prune, emit);
    }

    #[inline(always)]
    fn through_system(
        &self,
        s: &Surface,
        sys: &LensSystem,
        lambda_um: f64,
        prune: &Pruning,
        mut emit: impl FnMut(Transmitted),
    ) {
        match self.tree {
            Some((object, p, rays)) if object == s.index && p == prune => {
                for &b in rays {
                    emit(carried(s.object, b));
                }
            }
            _ => self.alone.through_system(s, sys, lambda_um, prune, emit),
        }
    }
}
