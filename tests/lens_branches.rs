//! The Whitted tree inside a lens conserves energy: before pruning, the
//! weights of all the rays out of a lens ([`Lens::branches_inside`], the
//! enumeration the renderer and `lens trace --branches` use) and the light
//! still inside when the chain stops sum to 1 within 1e-9, for rays across
//! the whole aperture, near-critical crossings and total internal
//! reflections included.

use glam::DVec3;
use lensview::geometry::{Lens, LensBranch, Pruning};
use lensview::optics::Index;
use lensview::sampling::Sampler;

/// Lenses: the benchmark lens, a steep one of index 3 (many total
/// reflections), a ball, a nearly flat thin one, a meniscus-like pair.
fn lenses() -> Vec<(Lens, f64)> {
    [
        (2.0, 5.0, 5.0, 1.5),
        (2.0, 1.05, 8.0, 3.0),
        (2.0, 1.0, 1.0, 1.5),
        (2.0, 400.0, 400.0, 1.5),
        (2.0, 1.0, 3.0, 1.9),
    ]
    .into_iter()
    .map(|(d, r1, r2, n)| {
        (
            Lens::new(DVec3::ZERO, DVec3::Z, d, r1, r2, Index::Constant(n)).unwrap(),
            n,
        )
    })
    .collect()
}

/// What one ray's tree gave: the sum of the weights out, the weight left
/// inside, and whether a crossing was near-critical (R > 0.5 but not total)
/// or total.
struct Tree {
    sum: f64,
    left: f64,
    near_critical: bool,
    total: bool,
}

fn tree(lens: &Lens, x: DVec3, u: DVec3, n: f64) -> Tree {
    let mut outs: Vec<LensBranch> = Vec::new();
    let prune = Pruning {
        min: 0.0,
        ..Pruning::NONE
    };
    let left = lens.branches_inside(x, u, n, &prune, &mut |b| outs.push(b));
    // Each ray out after the first: the weight that reached its crossing is
    // what the one before reflected on (times any total reflections, 1).
    let mut near_critical = false;
    let mut inside = 1.0;
    for b in &outs {
        let t = b.weight / inside;
        near_critical |= t < 0.5 && t > 0.0;
        inside -= b.weight;
        inside = inside.max(f64::MIN_POSITIVE);
    }
    let total = outs.first().is_some_and(|b| b.reflections > 0)
        || outs.windows(2).any(|w| w[1].reflections > w[0].reflections + 1);
    Tree {
        sum: outs.iter().map(|b| b.weight).sum(),
        left,
        near_critical,
        total,
    }
}

#[test]
fn weights_out_of_a_lens_sum_to_one_before_pruning() {
    let mut s = Sampler::new(17, 0, 0);
    let (mut rays, mut near, mut total, mut all_out) = (0, 0, 0, 0);
    for (c, (lens, n)) in lenses().into_iter().enumerate() {
        let r = lens.d / 2.0;
        for k in 0..4000 {
            // From outside, across the whole aperture (to 0.9999 of the
            // radius), tilted up to 85°; or from inside in any direction.
            let (x, u) = if k % 4 != 3 {
                let h = r * (1.0 - 1e-4) * (k % 100) as f64 / 99.0;
                let phi = s.next_f64() * std::f64::consts::TAU;
                let tilt = 85f64.to_radians() * s.next_f64();
                let aim = DVec3::new(h * phi.cos(), h * phi.sin(), 0.0);
                let dir = DVec3::new(
                    tilt.sin() * (phi + 1.0).cos(),
                    tilt.sin() * (phi + 1.0).sin(),
                    -tilt.cos(),
                );
                let p = lens.trace(aim - dir * 4.0 * lens.d, dir, n);
                let Some((_, x, inside)) = p.entry else { continue };
                (x, inside)
            } else {
                let v = DVec3::new(s.next_f64(), s.next_f64(), s.next_f64()) * 2.0 - 1.0;
                (DVec3::new(0.3 * r * v.x, 0.3 * r * v.y, 0.0), (v + 0.01).normalize())
            };
            let t = tree(&lens, x, u, n);
            assert!(
                (t.sum + t.left - 1.0).abs() < 1e-9,
                "case {c}, ray {k}: out {} + inside {} != 1",
                t.sum,
                t.left
            );
            rays += 1;
            near += usize::from(t.near_critical);
            total += usize::from(t.total);
            // Unless the light stays in (the chain's 64 reflections), the
            // rays out carry all of it.
            if t.left < 1e-12 {
                assert!((t.sum - 1.0).abs() < 1e-9, "case {c}, ray {k}: {}", t.sum);
                all_out += 1;
            }
        }
    }
    assert!(
        rays > 15_000 && near > 200 && total > 200 && all_out > 10_000,
        "{rays} rays, {near} near-critical, {total} with total reflections, {all_out} wholly out"
    );
}

/// A bound drops light but never creates any: what is listed and what is
/// dropped still sum to 1, and every branch listed is above the bound.
#[test]
fn pruned_trees_account_for_what_they_drop() {
    let mut s = Sampler::new(3, 0, 0);
    for (lens, n) in lenses() {
        for k in 0..500 {
            let h = lens.d / 2.0 * 0.999 * (k as f64 / 499.0);
            let dir = DVec3::new(0.3 * s.next_f64(), 0.0, -1.0).normalize();
            let p = lens.trace(DVec3::new(h, 0.0, 0.0) - dir * 4.0 * lens.d, dir, n);
            let Some((_, x, inside)) = p.entry else { continue };
            let prune = Pruning {
                scale: 0.8,
                min: 1.0 / 512.0,
                max_reflections: 4,
                roulette: 0.0,
            };
            let mut outs = Vec::new();
            let dropped = lens.branches_inside(x, inside, n, &prune, &mut |b| outs.push(b));
            let sum: f64 = outs.iter().map(|b| b.weight).sum();
            assert!((sum + dropped - 1.0).abs() < 1e-12);
            assert!(outs.iter().all(|b| 0.8 * b.weight > 1.0 / 512.0 && b.reflections <= 4));
        }
    }
}
