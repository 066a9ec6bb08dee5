//! [`LensSystem::branches`] for [`LANES`] rays at once: the scene rays of
//! a packet that enter the same system (the packet kernel's).
//!
//! Each lane walks its own tree, in lockstep with the others: at each step
//! every lane with a branch left pops its next one, the lanes look for
//! their nearest crossings together ([`LensSystem::lane_crossings`], the
//! lens camera's search: the scalar search's steps, lane for lane), and
//! each lane then takes the scalar tree's own step there
//! ([`LensSystem::tree_step`]). So every lane's rays out are the scalar
//! tree's, bit for bit and in its order (`tests/system_lanes.rs`).

use super::lanes::{NONE, Walk};
use super::walk::{Live, STACK, Tree};
use super::{LensSystem, SystemBranch};
use crate::geometry::Pruning;
use crate::simd::{LANES, Lanes, lane, mask, set_lane, with_avx2};

/// Working memory of [`LensSystem::branches_lanes`], kept between calls:
/// each lane's stack of branches, and its rays out.
pub struct LaneTrees {
    stacks: Box<Lanes<[Option<Live>; STACK]>>,
    /// Lane `l`'s rays out of its tree, in [`LensSystem::branches`]'s order.
    pub out: Lanes<Vec<SystemBranch>>,
}

impl Default for LaneTrees {
    fn default() -> Self {
        LaneTrees {
            stacks: Box::new([[None; STACK]; LANES]),
            out: Default::default(),
        }
    }
}

with_avx2! {
    /// [`LensSystem::branches`] of the rays `origin[l] + t·dir[l]` of the
    /// lanes `l` with `live[l]`, each pruned by its `prune[l]`: lane `l`'s
    /// rays out into `trees.out[l]` (emptied first), and the weight each
    /// dropped.
    fn branches_lanes / branches_lanes_avx2 => branches_lanes_impl(
        system: &LensSystem,
        origin: &[Lanes<f64>; 3],
        dir: &[Lanes<f64>; 3],
        live: Lanes<bool>,
        lambda_um: f64,
        prune: &Lanes<Pruning>,
        trees: &mut LaneTrees
    ) -> Lanes<f64>
}

#[inline(always)]
fn branches_lanes_impl(
    system: &LensSystem,
    origin: &[Lanes<f64>; 3],
    dir: &[Lanes<f64>; 3],
    live: Lanes<bool>,
    lambda_um: f64,
    prune: &Lanes<Pruning>,
    trees: &mut LaneTrees,
) -> Lanes<f64> {
    let media = system.media(lambda_um);
    let most = system.most_steps();
    let LaneTrees { stacks, out } = trees;
    let mut l = 0;
    let mut tree: Lanes<Tree> = stacks.each_mut().map(|stack| {
        let t = if live[l] {
            system.tree(lane(origin, l), lane(dir, l), &prune[l], stack)
        } else {
            LensSystem::idle_tree(stack)
        };
        l += 1;
        t
    });
    for o in out.iter_mut() {
        o.clear();
    }
    let mut walk = Walk::new();
    loop {
        // The lanes whose next branch walks the way most do take a step;
        // the others wait (a lane's tree is its own: its order holds).
        let top: Lanes<Option<bool>> = std::array::from_fn(|l| tree[l].pending.peek().map(|b| b.u.z >= 0.0));
        let ahead = top.iter().filter(|&&t| t == Some(true)).count();
        let behind = top.iter().filter(|&&t| t == Some(false)).count();
        let way = ahead >= behind;
        let popped: Lanes<Option<Live>> = std::array::from_fn(|l| {
            if top[l] == Some(way) {
                tree[l].pending.pop()
            } else {
                None
            }
        });
        for (l, b) in popped.iter().enumerate() {
            walk.live[l] = b.is_some();
            if let Some(b) = b {
                set_lane(&mut walk.x, l, b.x);
                set_lane(&mut walk.u, l, b.u);
                walk.lo[l] = b.lo(tree[l].t0);
                walk.from[l] = b.from.unwrap_or(NONE);
            }
        }
        if mask(&walk.live) == 0 {
            break;
        }
        let found = system.lane_crossings(&walk);
        for (l, b) in popped.iter().enumerate() {
            let Some(b) = b else { continue };
            let c = found.near(l, 0.0).crossing(f64::INFINITY);
            system.tree_step(&mut tree[l], b, c, &media, most, &mut |ray| out[l].push(ray));
        }
    }
    tree.map(|t| t.pending.dropped)
}

/// The most caps that separate two media a system may have for its trees
/// to be walked in lanes: beyond, the trees of neighbouring rays part
/// ways (their ghosts' roulettes differ) and the lockstep costs more than
/// it saves (docs/performance.md, round 13: the singlet and the achromat
/// 12–16 % faster, the Cooke triplet's six even, the double Gauss's ten
/// 20–25 % slower).
const LANE_CAPS: usize = 4;

impl LensSystem {
    /// Whether [`LensSystem::branches_lanes`] pays for this system's trees
    /// (few surfaces: [`LANE_CAPS`]).
    pub fn trees_in_lanes(&self) -> bool {
        self.boundary_caps() <= LANE_CAPS
    }

    /// [`branches_lanes`] as a method: [`LensSystem::branches`] for the
    /// live lanes, each lane's rays out into `trees.out`.
    #[inline]
    pub fn branches_lanes(
        &self,
        origin: &[Lanes<f64>; 3],
        dir: &[Lanes<f64>; 3],
        live: Lanes<bool>,
        lambda_um: f64,
        prune: &Lanes<Pruning>,
        trees: &mut LaneTrees,
    ) -> Lanes<f64> {
        branches_lanes(self, origin, dir, live, lambda_um, prune, trees)
    }
}
