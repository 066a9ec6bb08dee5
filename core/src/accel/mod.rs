//! Acceleration: a bounding volume hierarchy over a scene's objects, built
//! with the surface area heuristic (binned, as in Wald, "On fast
//! construction of SAH-based bounding volume hierarchies", 2007) and
//! flattened into an array in depth-first order, so that a node's left child
//! follows it and traversal walks memory forward.
//!
//! The tree is built over boxes and walked through [`Walker`]: it knows no
//! scene, shape or camera. The queries that walk it with rays of a scene,
//! one ray or a packet or a tile's frustum, live in [`crate::trace`].

use crate::geometry::{Aabb, slab_hit};
use crate::math::Ray;
use glam::DVec3;

/// One node: 64 bytes, a cache line. For an inner node `first` is the
/// index of the right child (the left child is the next node) and `count`
/// is 0; for a leaf, `first` indexes `Bvh::prims` and `count > 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct Node {
    pub min: DVec3,
    pub max: DVec3,
    pub first: u32,
    pub count: u32,
    /// Split axis of an inner node: children are visited nearer-first along it.
    pub axis: u32,
}

#[derive(Clone, Debug, PartialEq, Default)]
pub struct Bvh {
    pub nodes: Vec<Node>,
    /// Object indices, leaves own contiguous runs.
    pub prims: Vec<u32>,
}

const BINS: usize = 12;
const MAX_LEAF: usize = 4;
/// Cost of a box test relative to a primitive test in the SAH.
const TRAVERSAL_COST: f64 = 0.5;

fn area(min: DVec3, max: DVec3) -> f64 {
    let e = (max - min).max(DVec3::ZERO);
    2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
}

/// The SAH bin (of [`BINS`] over the centroid range from `lo`, `scale`
/// bins a unit) of the centroid coordinate `c`.
#[inline]
fn bin(c: f64, lo: f64, scale: f64) -> usize {
    (((c - lo) * scale) as usize).min(BINS - 1)
}

/// The cheapest split of `prims` by the binned SAH over the centroid range
/// `cmin .. cmin + extent`, on every axis: `(cost, axis, split bin)`, the
/// objects of bins below the split going left; an infinite cost when no
/// axis splits them (all centroids coincide).
fn best_split(prims: &[u32], bounds: &[Aabb], centroids: &[DVec3], cmin: DVec3, extent: DVec3) -> (f64, usize, usize) {
    let mut best = (f64::INFINITY, 0usize, 0usize);
    for axis in 0..3 {
        if extent[axis] <= 0.0 {
            continue;
        }
        let mut bin_min = [DVec3::INFINITY; BINS];
        let mut bin_max = [DVec3::NEG_INFINITY; BINS];
        let mut bin_n = [0usize; BINS];
        let scale = BINS as f64 / extent[axis];
        for &p in prims {
            let b = bin(centroids[p as usize][axis], cmin[axis], scale);
            bin_n[b] += 1;
            bin_min[b] = bin_min[b].min(bounds[p as usize].min);
            bin_max[b] = bin_max[b].max(bounds[p as usize].max);
        }
        // Sweep from the right to get each split's right-side area.
        let mut right_area = [0.0; BINS];
        let (mut rmin, mut rmax, mut rn) = (DVec3::INFINITY, DVec3::NEG_INFINITY, 0);
        let mut right_n = [0usize; BINS];
        for b in (1..BINS).rev() {
            rmin = rmin.min(bin_min[b]);
            rmax = rmax.max(bin_max[b]);
            rn += bin_n[b];
            right_area[b] = area(rmin, rmax);
            right_n[b] = rn;
        }
        let (mut lmin, mut lmax, mut ln) = (DVec3::INFINITY, DVec3::NEG_INFINITY, 0);
        for b in 1..BINS {
            lmin = lmin.min(bin_min[b - 1]);
            lmax = lmax.max(bin_max[b - 1]);
            ln += bin_n[b - 1];
            if ln == 0 || right_n[b] == 0 {
                continue;
            }
            let cost = ln as f64 * area(lmin, lmax) + right_n[b] as f64 * right_area[b];
            if cost < best.0 {
                best = (cost, axis, b);
            }
        }
    }
    best
}

impl Bvh {
    /// Builds over `bounds` (one box per object).
    pub fn build(bounds: &[Aabb]) -> Bvh {
        let mut bvh = Bvh {
            nodes: Vec::with_capacity(2 * bounds.len()),
            prims: (0..bounds.len() as u32).collect(),
        };
        if bounds.is_empty() {
            return bvh;
        }
        let centroids: Vec<DVec3> = bounds.iter().map(|b| 0.5 * (b.min + b.max)).collect();
        bvh.build_node(bounds, &centroids, 0, bounds.len());
        bvh
    }

    fn build_node(&mut self, bounds: &[Aabb], centroids: &[DVec3], start: usize, end: usize) -> usize {
        let idx = self.nodes.len();
        let (mut min, mut max) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        let (mut cmin, mut cmax) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for &p in &self.prims[start..end] {
            let b = &bounds[p as usize];
            min = min.min(b.min);
            max = max.max(b.max);
            cmin = cmin.min(centroids[p as usize]);
            cmax = cmax.max(centroids[p as usize]);
        }
        self.nodes.push(Node {
            min,
            max,
            first: start as u32,
            count: (end - start) as u32,
            axis: 0,
        });
        let n = end - start;
        if n <= 1 {
            return idx;
        }
        let extent = cmax - cmin;
        let best = best_split(&self.prims[start..end], bounds, centroids, cmin, extent);
        let leaf_cost = n as f64;
        let split_cost = TRAVERSAL_COST + best.0 / area(min, max).max(f64::MIN_POSITIVE);
        if best.0.is_infinite() || (n <= MAX_LEAF && split_cost >= leaf_cost) {
            // All centroids coincide, or a leaf is cheaper: stay a leaf,
            // unless it is too big, then split in the middle of the list.
            if n <= MAX_LEAF || best.0.is_infinite() && n <= 2 * MAX_LEAF {
                return idx;
            }
        }
        let mid = if best.0.is_finite() {
            let (axis, split) = (best.1, best.2);
            let scale = BINS as f64 / extent[axis];
            let slice = &mut self.prims[start..end];
            let mut i = 0;
            for j in 0..slice.len() {
                if bin(centroids[slice[j] as usize][axis], cmin[axis], scale) < split {
                    slice.swap(i, j);
                    i += 1;
                }
            }
            self.nodes[idx].axis = axis as u32;
            start + i
        } else {
            start + n / 2
        };
        self.build_node(bounds, centroids, start, mid);
        let right = self.build_node(bounds, centroids, mid, end);
        let node = &mut self.nodes[idx];
        node.first = right as u32;
        node.count = 0;
        idx
    }

    /// Visits leaves that the ray may hit within `(0, t_max)`, nearer
    /// children first. `visit(object, t_max)` tests one object and returns a
    /// new, smaller `t_max` if it hit; returning `Err(())` stops the walk
    /// (an any-hit query found what it wanted).
    #[inline]
    pub fn traverse(&self, ray: &Ray, t_max: f64, visit: impl FnMut(u32, f64) -> Result<Option<f64>, ()>) {
        let inv = ray.dir.recip();
        let neg = [inv.x < 0.0, inv.y < 0.0, inv.z < 0.0];
        struct OneRay<'a, F> {
            prims: &'a [u32],
            origin: DVec3,
            inv: DVec3,
            t_max: f64,
            visit: F,
        }
        impl<F: FnMut(u32, f64) -> Result<Option<f64>, ()>> Walker for OneRay<'_, F> {
            #[inline(always)]
            fn enters(&mut self, node: &Node) -> bool {
                slab(node, self.origin, self.inv, self.t_max)
            }
            #[inline(always)]
            fn leaf(&mut self, _: usize, node: &Node) -> bool {
                for &p in node.prims(self.prims) {
                    match (self.visit)(p, self.t_max) {
                        Ok(Some(t)) => self.t_max = t,
                        Ok(None) => {}
                        Err(()) => return false,
                    }
                }
                true
            }
        }
        self.walk(
            neg,
            &mut OneRay {
                prims: &self.prims,
                origin: ray.origin,
                inv,
                t_max,
                visit,
            },
        );
    }

    /// The depth-first walk every query shares (one ray, a packet, a tile's
    /// frustum): from the root, into each node `walker` enters, the nearer
    /// child first for directions of signs `neg`, handing it each leaf it
    /// enters, until the tree is done or `leaf` returns `false`.
    #[inline(always)]
    pub(crate) fn walk(&self, neg: [bool; 3], walker: &mut impl Walker) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack = Stack::new();
        let mut i = 0usize;
        loop {
            let node = &self.nodes[i];
            if walker.enters(node) {
                if node.count > 0 {
                    if !walker.leaf(i, node) {
                        return;
                    }
                } else {
                    let (near, far) = node.near_far(i, neg);
                    stack.push(far);
                    i = near;
                    continue;
                }
            }
            match stack.pop() {
                Some(next) => i = next,
                None => return,
            }
        }
    }
}

/// What a walk of the tree ([`Bvh::walk`]) does at the nodes it reaches (a
/// trait rather than closures, so that the packet code's uses compile
/// inside its AVX2 build).
pub(crate) trait Walker {
    /// Whether the walk goes into `node` (its box may matter).
    fn enters(&mut self, node: &Node) -> bool;
    /// Handles the leaf `node` (at `index`) the walk went into; `false`
    /// ends the walk.
    fn leaf(&mut self, index: usize, node: &Node) -> bool;
}

impl Node {
    /// A leaf's objects, out of [`Bvh::prims`].
    #[inline(always)]
    pub(crate) fn prims<'a>(&self, prims: &'a [u32]) -> &'a [u32] {
        &prims[self.first as usize..(self.first + self.count) as usize]
    }

    /// An inner node's children, nearer first along its split axis for a
    /// ray whose direction has the signs `neg` (`i` is this node's index).
    #[inline(always)]
    pub(crate) fn near_far(&self, i: usize, neg: [bool; 3]) -> (usize, usize) {
        if neg[self.axis as usize] {
            (self.first as usize, i + 1)
        } else {
            (i + 1, self.first as usize)
        }
    }
}

/// The traversal stack of node indices: 64 on the stack frame, which a
/// balanced tree never outgrows, then a vector that a degenerate tree (one
/// object a level) spills into, so that no subtree is ever left out.
pub(crate) struct Stack {
    items: [u32; 64],
    len: usize,
    spill: Vec<u32>,
}

impl Stack {
    #[inline(always)]
    pub(crate) fn new() -> Stack {
        Stack {
            items: [0; 64],
            len: 0,
            spill: Vec::new(),
        }
    }

    #[inline(always)]
    pub(crate) fn push(&mut self, i: usize) {
        if self.len < self.items.len() {
            self.items[self.len] = i as u32;
            self.len += 1;
        } else {
            self.spill.push(i as u32);
        }
    }

    #[inline(always)]
    pub(crate) fn pop(&mut self) -> Option<usize> {
        if let Some(i) = self.spill.pop() {
            return Some(i as usize);
        }
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        Some(self.items[self.len] as usize)
    }
}

#[inline]
fn slab(n: &Node, o: DVec3, inv: DVec3, t_max: f64) -> bool {
    slab_hit(n.min, n.max, o, inv, 0.0, t_max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Sampler;

    fn boxes(n: usize, seed: u64) -> Vec<Aabb> {
        let mut s = Sampler::new(seed, 0, 0);
        (0..n)
            .map(|_| {
                let c = DVec3::new(s.next_f64(), s.next_f64(), s.next_f64()) * 20.0 - 10.0;
                let e = DVec3::new(s.next_f64(), s.next_f64(), s.next_f64()) * 0.8 + 0.05;
                Aabb::new(c - e, c + e)
            })
            .collect()
    }

    fn brute(bounds: &[Aabb], ray: &Ray) -> Option<(u32, f64)> {
        let inv = ray.dir.recip();
        let mut best: Option<(u32, f64)> = None;
        for (i, b) in bounds.iter().enumerate() {
            let t0 = (b.min - ray.origin) * inv;
            let t1 = (b.max - ray.origin) * inv;
            let lo = t0.min(t1).max_element().max(0.0);
            let hi = t0.max(t1).min_element();
            if lo <= hi && best.is_none_or(|(_, t)| lo < t) {
                best = Some((i as u32, lo));
            }
        }
        best
    }

    #[test]
    fn every_object_is_in_exactly_one_leaf_and_boxes_nest() {
        for n in [1, 2, 3, 7, 25, 100, 2500] {
            let b = boxes(n, n as u64);
            let bvh = Bvh::build(&b);
            let mut seen = vec![0; n];
            for node in &bvh.nodes {
                if node.count > 0 {
                    for &p in node.prims(&bvh.prims) {
                        seen[p as usize] += 1;
                        assert!(node.min.cmple(b[p as usize].min).all() && node.max.cmpge(b[p as usize].max).all());
                    }
                    assert!(node.count as usize <= 2 * MAX_LEAF);
                }
            }
            assert!(seen.iter().all(|&k| k == 1), "n = {n}");
        }
    }

    #[test]
    fn closest_box_hit_matches_brute_force() {
        let b = boxes(500, 9);
        let bvh = Bvh::build(&b);
        let mut s = Sampler::new(3, 0, 0);
        for _ in 0..2000 {
            let o = DVec3::new(s.next_f64(), s.next_f64(), s.next_f64()) * 40.0 - 20.0;
            let d = DVec3::new(s.next_f64() - 0.5, s.next_f64() - 0.5, s.next_f64() - 0.5);
            let ray = Ray::new(o, d);
            let inv = ray.dir.recip();
            let mut best: Option<(u32, f64)> = None;
            bvh.traverse(&ray, f64::INFINITY, |p, t_max| {
                let bb = &b[p as usize];
                let t0 = (bb.min - ray.origin) * inv;
                let t1 = (bb.max - ray.origin) * inv;
                let lo = t0.min(t1).max_element().max(0.0);
                let hi = t0.max(t1).min_element().min(t_max);
                if lo <= hi && lo < t_max {
                    best = Some((p, lo));
                    return Ok(Some(lo));
                }
                Ok(None)
            });
            let want = brute(&b, &ray);
            assert_eq!(best.map(|x| x.1), want.map(|x| x.1), "ray {o} {d}");
        }
    }

    /// Boxes at 20⁻ᵏ put all but one centroid in the first of the 12 bins
    /// at every level, so the SAH peels one object a level: a tree far deeper
    /// than the 64-entry stack, which must still be walked whole.
    #[test]
    fn a_degenerate_tree_deeper_than_the_stack_is_walked_whole() {
        let b: Vec<Aabb> = (0..100)
            .map(|k| {
                let x = 0.05f64.powi(k);
                Aabb::new(DVec3::new(x, -1.0, -1.0), DVec3::new(x + 0.01 * x, 1.0, 1.0))
            })
            .collect();
        let bvh = Bvh::build(&b);
        fn depth(bvh: &Bvh, i: usize) -> usize {
            let n = &bvh.nodes[i];
            if n.count > 0 {
                1
            } else {
                1 + depth(bvh, i + 1).max(depth(bvh, n.first as usize))
            }
        }
        assert!(depth(&bvh, 0) > 64, "depth {}", depth(&bvh, 0));
        // Along +x every box is in the way, and the walk goes down the deep
        // side first, leaving one far child on the stack a level.
        let ray = Ray::new(DVec3::new(-1e9, 0.0, 0.0), DVec3::X);
        let mut seen = vec![false; b.len()];
        bvh.traverse(&ray, f64::INFINITY, |p, _| {
            seen[p as usize] = true;
            Ok(None)
        });
        assert!(
            seen.iter().all(|&s| s),
            "{} of {} boxes visited",
            seen.iter().filter(|&&s| s).count(),
            b.len()
        );
    }

    #[test]
    fn any_hit_stops_early() {
        let b = boxes(1000, 4);
        let bvh = Bvh::build(&b);
        // A ray along x that meets at least three boxes, so a walk that went
        // on after the first visit would visit more.
        let hits = |ray: &Ray| (0..b.len()).filter(|&i| brute(&b[i..=i], ray).is_some()).count();
        let ray = (0..400)
            .map(|k| {
                Ray::new(
                    DVec3::new(-30.0, (k / 20) as f64 - 10.0, (k % 20) as f64 - 10.0),
                    DVec3::X,
                )
            })
            .find(|r| hits(r) >= 3)
            .unwrap();
        let mut all = 0;
        bvh.traverse(&ray, f64::INFINITY, |_, _| {
            all += 1;
            Ok(None)
        });
        let hit = hits(&ray);
        assert!(all >= hit, "{hit} boxes hit, {all} visited");
        let mut visits = 0;
        bvh.traverse(&ray, f64::INFINITY, |_, _| {
            visits += 1;
            Err(())
        });
        assert_eq!(visits, 1);
    }
}
