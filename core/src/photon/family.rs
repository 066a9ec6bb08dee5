//! Caustic families: each photon belongs to the family of the specular
//! event that last sent it (its object, and whether it went through it,
//! was reflected off it, or left a lens after reflecting inside it, a
//! ghost: [`Photon::family`]), and each family big enough to tell
//! gets a starting radius of its own, from its own photons' spacing
//! ([`family_scales`]), where one radius for the whole map was the
//! spacing of its densest families.
//!
//! Why: one scene's caustics differ in scale by orders of magnitude. A
//! convex mirror or a glass ball's surface reflection spreads its photons
//! thinly over a wide area, while a lens gathers its own into a spot: with
//! one radius, set by the median photon (mostly the spot's), the wide
//! caustic is gathered a few photons at a time and shows as speckle; a
//! radius for the wide one's spacing smooths it without blurring the spot.
//! A family's photons are spread by one surface, so their density varies
//! smoothly compared with the mixture's; a photon-by-photon radius from
//! its neighbours (tried in round 28) also widened the thin bright curves
//! of a lens's caustic, where the neighbours are few across the curve.
//!
//! Each family's radius is the map's `r0` times a power of √2 (from 1/2
//! to 4: [`LEAST_HALF_OCTAVES`], [`MOST_HALF_OCTAVES`]); families of the
//! same power share a layer of groups, and the families not listed (too
//! few photons in the first pass to tell their spacing, or new later) are
//! gathered with `r0`'s schedule, as the whole map was before.

use super::Photon;
use super::radius::initial_radius;

/// The fewest photons a family needs in the first pass to get its own
/// radius: four times the neighbours its spacing is measured by (below
/// it, the median distance to the k-th neighbour is mostly the family's
/// extent, not its spacing).
pub const MIN_FAMILY_PHOTONS_PER_NEIGHBOUR: usize = 4;

/// The fewest photons a family needs for a layer of its own, as a share
/// of the first pass's: one in this many (a smaller one joins the nearest
/// layer: [`family_scales`]). A layer costs a walk of its cells for every
/// query near its photons; a family with fewer adds little light for that (the
/// lens's surface reflection in rim-lens, 6 % of the photons, was 6–10 %
/// more time in `render` for no change in the error; optical-bench's
/// ghosts, 1 %, spread 79 times as widely as its direct light, 6–9 % for
/// a caustic error 0.7 % lower: docs/performance.md, round 29).
pub const MIN_FAMILY_SHARE: usize = 8;

/// The smallest radius scale: `2^(LEAST/2)` = 1/2. Down to 1/2 a lens's
/// spot gathered with its own spacing was sharper for its noise
/// (lens-family); a glass ball's spot at 1/4 was noisier than at 1/2
/// (primitives).
pub const LEAST_HALF_OCTAVES: i32 = -2;
/// The largest: `2^(MOST/2)` = 4. A mirror ball's wide reflection (6.9 ×
/// the map's spacing in primitives) lost little error with 8 and cost a
/// tenth more time in `render` than with 4 (round 29).
pub const MOST_HALF_OCTAVES: i32 = 4;

/// `2^(1/4)`, the double nearest it: the bounds between half octaves.
const FOURTH_ROOT_OF_TWO: f64 = 1.189_207_115_002_721;

/// `2^(h/2)`: an exact power of two, times √2 (rounded once) for odd `h`.
/// Products and `powi` of 2 only, no `pow` or `log2` (the same bits on
/// every platform: ARCHITECTURE.md, "Determinism").
pub fn scale_of(h: i32) -> f64 {
    let whole = 2f64.powi(h.div_euclid(2));
    if h.rem_euclid(2) == 1 {
        whole * std::f64::consts::SQRT_2
    } else {
        whole
    }
}

/// The half octave nearest `ratio` (ties up), within the bounds.
fn half_octaves(ratio: f64) -> i32 {
    let mut h = 0;
    while h < MOST_HALF_OCTAVES && ratio >= scale_of(h) * FOURTH_ROOT_OF_TWO {
        h += 1;
    }
    while h > LEAST_HALF_OCTAVES && ratio < scale_of(h - 1) * FOURTH_ROOT_OF_TWO {
        h -= 1;
    }
    h
}

/// The families of a first pass's `photons` that get a radius of their
/// own, in order of family, each with its radius over `r0` in half
/// octaves ([`scale_of`]). A family with at least
/// [`MIN_FAMILY_PHOTONS_PER_NEIGHBOUR`]` · k` photons has its spacing told
/// (the median distance to its `k`-th nearest photon of the family,
/// [`initial_radius`], over `r0`, rounded to half octaves); with one in
/// [`MIN_FAMILY_SHARE`] of the pass's photons too it gets that scale,
/// otherwise the nearest of those scales and the map's (no layer of its
/// own). Those whose scale is the map's are not listed; nor is any of a
/// pass of one family.
pub fn family_scales(photons: &[Photon], k: usize, r0: f64) -> Vec<(u32, i32)> {
    // The photons by family, each family's in their order (a stable sort:
    // one pass over them however many families there are).
    let mut by_family = photons.to_vec();
    by_family.sort_by_key(|p| p.family);
    let families: Vec<&[Photon]> = by_family.chunk_by(|a, b| a.family == b.family).collect();
    if families.len() < 2 || !(r0 > 0.0) {
        return Vec::new();
    }
    // Each family whose spacing can be told: its half octaves, and whether
    // it is big enough for a layer of its own.
    let told: Vec<(u32, i32, bool)> = families
        .into_iter()
        .filter_map(|of| {
            if of.len() < MIN_FAMILY_PHOTONS_PER_NEIGHBOUR * k {
                return None;
            }
            let h = half_octaves(initial_radius(of, k, 0.0)? / r0);
            Some((of[0].family, h, of.len() * MIN_FAMILY_SHARE >= photons.len()))
        })
        .collect();
    // The layers: the map's own and the big families'. A smaller family
    // joins the layer nearest its own scale (the nearer to the map's on a
    // tie), so that it costs no walk of its own.
    let mut layers: Vec<i32> = told.iter().filter(|t| t.2).map(|t| t.1).collect();
    layers.push(0);
    let nearest = |h: i32| {
        let key = |&c: &i32| ((c - h).abs(), c.abs());
        layers.iter().copied().min_by_key(key).unwrap_or(0)
    };
    told.iter()
        .map(|&(f, h, big)| (f, if big { h } else { nearest(h) }))
        .filter(|&(_, h)| h != 0)
        .collect()
}

/// The layers of a map's groups: layer 0 gathers every family not listed
/// with the map's own radii; each other layer, the families listed with
/// its scale.
#[derive(Clone, Debug)]
pub(super) struct Layers {
    /// Each layer's scale on the map's radii (layer 0's is 1).
    pub scales: Vec<f64>,
    /// The families listed, in order, with their layer.
    families: Vec<(u32, usize)>,
}

impl Layers {
    /// The layers of families `listed` ([`family_scales`]: a family and
    /// its half octaves), one for each scale, in order of scale.
    pub fn of(listed: &[(u32, i32)]) -> Self {
        let mut halves: Vec<i32> = listed.iter().map(|&(_, h)| h).filter(|&h| h != 0).collect();
        halves.sort_unstable();
        halves.dedup();
        let layer = |h: i32| halves.binary_search(&h).map_or(0, |i| i + 1);
        let mut families: Vec<(u32, usize)> = listed.iter().map(|&(f, h)| (f, layer(h))).collect();
        families.sort_unstable();
        families.dedup_by_key(|f| f.0);
        let mut scales = vec![1.0];
        scales.extend(halves.iter().map(|&h| scale_of(h)));
        Layers { scales, families }
    }

    /// How many layers.
    pub fn len(&self) -> usize {
        self.scales.len()
    }

    /// The layer of `family`.
    pub fn of_family(&self, family: u32) -> usize {
        self.families
            .binary_search_by_key(&family, |f| f.0)
            .map_or(0, |i| self.families[i].1)
    }

    /// `photons` by layer, each layer's in their order.
    pub fn split(&self, photons: &[Photon]) -> Vec<Vec<Photon>> {
        let mut parts = vec![Vec::new(); self.len()];
        for p in photons {
            parts[self.of_family(p.family)].push(*p);
        }
        parts
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn half_octaves_are_the_nearest_power_of_the_square_root_of_two() {
        assert_eq!(scale_of(0), 1.0);
        assert_eq!(scale_of(-4), 0.25);
        assert_eq!(scale_of(6), 8.0);
        assert_eq!(scale_of(-1), std::f64::consts::FRAC_1_SQRT_2);
        assert_eq!(scale_of(3), 2.0 * std::f64::consts::SQRT_2);
        for h in LEAST_HALF_OCTAVES..=MOST_HALF_OCTAVES {
            let s = scale_of(h);
            assert_eq!(half_octaves(s), h);
            assert_eq!(half_octaves(s * 1.18), h, "just below the upper bound");
            assert_eq!(half_octaves(s / 1.18), h, "just above the lower bound");
        }
        assert_eq!(half_octaves(1e-9), LEAST_HALF_OCTAVES);
        assert_eq!(half_octaves(1e9), MOST_HALF_OCTAVES);
        assert_eq!(half_octaves(f64::NAN), 0);
    }

    /// Photons of family `f` on a square grid of spacing `d` from `at`.
    fn lattice(f: u32, at: DVec3, d: f64, side: usize) -> Vec<Photon> {
        (0..side * side)
            .map(|i| {
                let p = at + DVec3::new((i % side) as f64, (i / side) as f64, 0.0) * d;
                Photon::new(p, -DVec3::Z, DVec3::ONE).with_family(f)
            })
            .collect()
    }

    /// A dense family, a sparse one four times as widely spaced, and one
    /// too small to tell: the sparse one is listed two octaves up from a
    /// map radius of the dense one's spacing, the others not at all.
    #[test]
    fn a_sparse_family_gets_a_wider_radius() {
        let dense = lattice(7, DVec3::ZERO, 0.01, 40);
        let sparse = lattice(3, DVec3::new(5.0, 0.0, 0.0), 0.04, 20);
        let few = lattice(9, DVec3::new(-5.0, 0.0, 0.0), 0.5, 4);
        // Two families too small for a layer of their own: one spaced 3
        // times as widely as the dense one joins the sparse one's layer,
        // one spaced 1.2 times stays in the map's.
        let wide = lattice(10, DVec3::new(10.0, 0.0, 0.0), 0.03, 15);
        let near = lattice(11, DVec3::new(20.0, 0.0, 0.0), 0.012, 12);
        let all: Vec<Photon> = [dense.clone(), sparse, few, wide, near].concat();
        let r0 = initial_radius(&dense, 24, 0.0).unwrap();
        assert_eq!(family_scales(&all, 24, r0), vec![(3, 4), (10, 4)]);
        assert!(family_scales(&dense, 24, r0).is_empty(), "one family: none");
        let layers = Layers::of(&[(3, 4), (5, -2), (8, 4)]);
        assert_eq!(layers.scales, vec![1.0, 0.5, 4.0]);
        assert_eq!([3, 5, 8, 7].map(|f| layers.of_family(f)), [2, 1, 2, 0]);
        let parts = layers.split(&all);
        assert_eq!(
            parts.iter().map(Vec::len).collect::<Vec<_>>(),
            vec![1600 + 16 + 225 + 144, 0, 400]
        );
    }
}
