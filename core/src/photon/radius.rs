//! The map's starting radius from its first pass ([`initial_radius`]),
//! and how it shrinks pass by pass ([`of_pass`]).

use super::{ALPHA, Photon};
use glam::DVec3;
use rayon::prelude::*;

/// A starting radius for a map from its first pass's photons: the median,
/// over up to 256 photons spread through the pass, of the distance to the
/// `k`-th nearest other photon (at least `floor`). `None` without photons.
pub fn initial_radius(photons: &[Photon], k: usize, floor: f64) -> Option<f64> {
    if photons.len() < 2 {
        return None;
    }
    let k = k.clamp(1, photons.len() - 1);
    let step = photons.len().div_ceil(256);
    let from: Vec<DVec3> = photons.iter().step_by(step).map(|a| a.p).collect();
    let mut by_x: Vec<DVec3> = photons.iter().map(|a| a.p).collect();
    by_x.sort_unstable_by(|a, b| a.x.total_cmp(&b.x));
    // The photon itself is at distance 0: the k-th other is the (k+1)-th.
    let mut radii: Vec<f64> = from.par_iter().map(|&a| kth_smallest(&by_x, a, k).sqrt()).collect();
    let mid = radii.len() / 2;
    radii.select_nth_unstable_by(mid, f64::total_cmp);
    Some(radii[mid].max(floor))
}

/// The gather radius of pass `k` (from 1): `r_0 · (2^L)^((α−1)/2)` for
/// the level `L = ⌊log₂ k⌋` the pass belongs to: with α = 2/3,
/// `2^(−L/6)`, as `2^(−(L mod 6)/6)` (a correctly rounded constant) times
/// `2^(−⌊L/6⌋)` (exact). Not the platform's `pow`, whose last bit differs
/// between glibc and wasm32's `libm` (`examples/libm_differ`): the same
/// radii, so the same photon map, on every platform.
pub fn of_pass(r0: f64, k: u32) -> f64 {
    const _: () = assert!(ALPHA == 2.0 / 3.0, "SIXTH_ROOTS hold 2^(-s/6): (alpha - 1)/2 = -1/6");
    /// `2^(−s/6)` for `s` in 0..6, each the double nearest the true value.
    const SIXTH_ROOTS: [f64; 6] = [
        1.0,
        0.8908987181403393,
        0.7937005259840998,
        std::f64::consts::FRAC_1_SQRT_2,
        0.6299605249474366,
        0.5612310241546865,
    ];
    let level = 31 - k.max(1).leading_zeros();
    r0 * SIXTH_ROOTS[(level % 6) as usize] * 0.5f64.powi((level / 6) as i32)
}

/// The `k`-th smallest (from 0) squared distance from `a` to the points
/// `by_x` (in order of `x`): the `k + 1` smallest kept in order while
/// scanning out from `a.x` both ways, each way stopped where the gap in `x`
/// alone reaches the last kept (a squared distance is never below its
/// `x` term's square, rounding included), so that only the points in a
/// slab around `a` are looked at. The same value as a scan of all (a
/// scan of every point for each of 256 cost 2 % of a focal-spot frame).
fn kth_smallest(by_x: &[DVec3], a: DVec3, k: usize) -> f64 {
    let mut best = vec![f64::INFINITY; k + 1];
    let (below, above) = by_x.split_at(by_x.partition_point(|b| b.x < a.x));
    scan_out(a, above.iter(), &mut best);
    scan_out(a, below.iter().rev(), &mut best);
    best[k]
}

/// Keeps in `best` the smallest squared distances from `a` to `points`,
/// taken in order of their distance in `x` from `a`, until that alone
/// reaches the last kept.
fn scan_out<'a>(a: DVec3, points: impl Iterator<Item = &'a DVec3>, best: &mut [f64]) {
    for &b in points {
        let d = a - b;
        if d.x * d.x >= best[best.len() - 1] {
            break;
        }
        keep_smallest(best, d.length_squared());
    }
}

/// Puts `d` in `best` (in order) when it is below its last, which drops out.
fn keep_smallest(best: &mut [f64], d: f64) {
    let mut i = best.len() - 1;
    if d < best[i] {
        while i > 0 && best[i - 1] > d {
            best[i] = best[i - 1];
            i -= 1;
        }
        best[i] = d;
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::photon;
    use super::*;

    /// Every level's radius within a few units in the last place of the
    /// platform's `pow` (whose exponent (α − 1)/2 is −1/6 rounded, off by
    /// 2.8e-17: at level L that moves the true value by about L·2e-17 of
    /// itself), and within one of 2^(−s/6) for the levels below 6.
    #[test]
    fn the_radius_schedule_is_the_power_it_stands_for() {
        let ulps = |a: f64, b: f64| (a.to_bits() as i64 - b.to_bits() as i64).unsigned_abs();
        for level in 0..31u32 {
            let got = of_pass(1.0, 1 << level);
            let pow = ((1u64 << level) as f64).powf((ALPHA - 1.0) / 2.0);
            assert!(ulps(got, pow) <= 4, "level {level}: {got} against {pow}");
            if level < 6 {
                let exact = 2f64.powf(-(level as f64) / 6.0);
                assert!(ulps(got, exact) <= 1, "level {level}: {got} against {exact}");
            }
            assert_eq!(of_pass(1.0, (1 << level) + (1 << level) / 2), got, "one radius a level");
        }
    }

    /// The slab scan gives the k-th smallest distance a scan of every point
    /// gives, bit for bit, in clouds flat, round and with ties in `x`.
    #[test]
    fn the_slab_scan_is_a_full_scan() {
        let mut rng = crate::sampling::Sampler::new(3, 1, 4);
        for (cloud, flat) in [(0, 0.0), (1, 1.0), (2, 1e-3)] {
            let mut pts: Vec<DVec3> = (0..500)
                .map(|i| {
                    let (u, v) = rng.next_2d();
                    let x = if cloud == 2 { (i % 7) as f64 } else { 10.0 * u };
                    DVec3::new(x, 10.0 * v, flat * rng.next_f64())
                })
                .collect();
            let queries: Vec<DVec3> = pts.iter().step_by(37).copied().collect();
            pts.sort_unstable_by(|a, b| a.x.total_cmp(&b.x));
            for &a in &queries {
                for k in [1, 4, 24] {
                    let mut all: Vec<f64> = pts.iter().map(|&b| (a - b).length_squared()).collect();
                    all.sort_unstable_by(f64::total_cmp);
                    assert_eq!(kth_smallest(&pts, a, k).to_bits(), all[k].to_bits(), "{a} k {k}");
                }
            }
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
