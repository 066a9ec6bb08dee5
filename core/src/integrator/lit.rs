//! What the kernels shade with: the scene and, beside it, the caustic
//! photon map when one has been traced. The map is not part of the scene:
//! it is built from the scene by the render thread (or `render`) and
//! refined from stage to stage, while the scene stays the editor's.

use crate::color::Rgb;
use crate::photon::PhotonMap;
use crate::scene::Scene;
use crate::simd::LANES;

/// A scene and its caustic photon map, side by side (two references:
/// copied freely). Dereferences to the scene, so that everything that
/// needs only the scene takes it as before.
#[derive(Clone, Copy)]
pub struct Lit<'a> {
    pub scene: &'a Scene,
    /// The caustic photons shading adds (`kd·C·E`); `None`: no caustics
    /// (the scene computes none, or they are not traced yet).
    pub caustics: Option<&'a PhotonMap>,
    /// What the gathered irradiance counts for: 1, or the camera samples
    /// a gather stands for where the samples are thinned
    /// ([`Lit::for_sample`]). A power of two, so that the sums are the
    /// same bits times it.
    caustic_weight: f64,
    /// One camera sample in how many gathers in a stage of samples
    /// (`render::thinning`): 1, or a power of two.
    thin: u32,
    /// Where a packet's lanes are samples thinned each on its own (an
    /// adaptive wave's, [`Lit::with_lane_weights`]): lane `l`'s weight in
    /// bits `4l .. 4l + 4` as `log₂ w + 1`, 0 for a lane that gathers
    /// nothing. 0 in all: every lane counts as `caustic_weight` says (kept
    /// in four bytes, so that `Lit` stays as small as it was: it is passed
    /// by value all through the kernels).
    lane_weights: u32,
}

impl<'a> Lit<'a> {
    /// `scene` lit also by the photons of `caustics`.
    pub fn new(scene: &'a Scene, caustics: Option<&'a PhotonMap>) -> Self {
        Lit {
            scene,
            caustics,
            caustic_weight: 1.0,
            thin: 1,
            lane_weights: 0,
        }
    }

    /// The same, its samples' gathers thinned by `thin` (a power of two,
    /// `render::thinning::gather_thinning`) wherever the renderers
    /// sample in stages (`render`, the viewer's sample stages).
    pub fn thinned(self, thin: u32) -> Self {
        Lit {
            thin: thin.max(1),
            ..self
        }
    }

    /// One sample in how many gathers ([`Lit::thinned`]; 1 without caustics).
    pub fn thin(&self) -> u32 {
        if self.caustics.is_some() { self.thin } else { 1 }
    }

    /// What camera sample `i` of a stage of samples `from..` gathers when
    /// one sample in `thin` gathers (a power of two dividing the stage's
    /// samples and `from`: `render::thinning::stage_thinning`): samples
    /// `from, from + thin, …` gather, each counting `thin` times (so that
    /// the stage's mean has the caustic's full weight); the others gather
    /// nothing. With `thin` ≤ 1, the same.
    pub fn for_sample(self, i: u32, from: u32, thin: u32) -> Self {
        if thin <= 1 || self.caustics.is_none() {
            return self;
        }
        self.counting(Lit::sample_counts(i, from, thin))
    }

    /// What camera sample `i` of a stage of samples `from..` counts its
    /// gather for where one sample in `thin` gathers ([`Lit::for_sample`]):
    /// `thin` for samples `from, from + thin, …`, 0 for the others, 1
    /// with `thin` ≤ 1.
    pub fn sample_counts(i: u32, from: u32, thin: u32) -> u32 {
        match thin {
            0 | 1 => 1,
            _ if i.wrapping_sub(from) % thin == 0 => thin,
            _ => 0,
        }
    }

    /// The same, its gathers counting `w` times (0: it gathers nothing).
    #[inline(always)]
    fn counting(self, w: u32) -> Self {
        match w {
            0 => Lit { caustics: None, ..self },
            w => Lit {
                caustic_weight: w as f64,
                ..self
            },
        }
    }

    /// The irradiance `e` a gather found, as this sample counts it.
    #[inline(always)]
    pub(crate) fn counted(&self, e: Rgb) -> Rgb {
        debug_assert!(self.lane_weights == 0, "a packet's lanes count through `counted_lane`");
        e * self.caustic_weight
    }

    /// The same for a packet whose lane `l` is camera sample `l` of a
    /// batch, each thinned on its own: what [`Lit::for_sample`] gives
    /// each sample, as `weights` (0 where the sample gathers nothing, else
    /// the samples its gather stands for, a power of two; 1 everywhere is
    /// `self`). For the kernels' lanes ([`Lit::lane`], [`Lit::counted_lane`],
    /// [`Lit::gathers`]); a lane keeps its place through every bounce.
    pub fn with_lane_weights(self, weights: &[u32; LANES]) -> Self {
        if self.caustics.is_none() || weights.iter().all(|&w| w == 1) {
            return self;
        }
        if weights.iter().all(|&w| w == 0) {
            return Lit { caustics: None, ..self };
        }
        debug_assert!(
            weights.iter().all(|w| w.is_power_of_two() && *w < 1 << 14 || *w == 0),
            "{weights:?}"
        );
        let mut lane_weights = 0;
        for (l, &w) in weights.iter().enumerate() {
            let log = if w == 0 { 0 } else { w.trailing_zeros() + 1 };
            lane_weights |= log << (4 * l);
        }
        Lit { lane_weights, ..self }
    }

    /// Lane `l`'s weight as [`Lit::lane_weights`] holds it.
    #[inline(always)]
    fn lane_log(&self, l: usize) -> u32 {
        (self.lane_weights >> (4 * l)) & 15
    }

    /// What lane `l` of a packet shades with, alone (the scalar kernel's
    /// `Lit` for it: [`Lit::for_sample`]'s for its sample).
    #[inline(always)]
    pub(crate) fn lane(self, l: usize) -> Self {
        if self.lane_weights == 0 {
            return self;
        }
        let w = match self.lane_log(l) {
            0 => 0,
            log => 1 << (log - 1),
        };
        Lit {
            lane_weights: 0,
            ..self
        }
        .counting(w)
    }

    /// Whether lane `l` of a packet gathers caustic photons at all (given
    /// that the map is there).
    #[inline(always)]
    pub(crate) fn gathers(&self, l: usize) -> bool {
        self.lane_weights == 0 || self.lane_log(l) != 0
    }

    /// [`Lit::counted`] for lane `l` of a packet ([`Lit::lane`]'s).
    #[inline(always)]
    pub(crate) fn counted_lane(&self, e: Rgb, l: usize) -> Rgb {
        self.lane(l).counted(e)
    }
}

/// A scene without caustic photons.
impl<'a> From<&'a Scene> for Lit<'a> {
    fn from(scene: &'a Scene) -> Self {
        Lit::new(scene, None)
    }
}

impl std::ops::Deref for Lit<'_> {
    type Target = Scene;
    fn deref(&self) -> &Scene {
        self.scene
    }
}

impl<'a> From<&Lit<'a>> for Lit<'a> {
    fn from(lit: &Lit<'a>) -> Self {
        *lit
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::{PacketPaths, PacketScratch, radiance, radiance_packet};
    use crate::optics::WAVELENGTH_D_UM;
    use crate::simd::Lanes;
    use crate::trace::camera_hits;

    /// A packet whose lanes are samples thinned each on its own
    /// ([`Lit::with_lane_weights`]) gives each lane the scalar kernel's
    /// radiance for that sample's own thinning ([`Lit::for_sample`]) bit
    /// for bit: lanes that gather nothing, and that count once, twice or
    /// four times, through every bounce (rim-lens: camera rays through the
    /// lens, reflections and packets too small to stay packets).
    #[test]
    fn lanes_thinned_each_on_its_own_are_their_samples() {
        let text = include_str!("../../../scenes/rim-lens.toml");
        let scene = Scene::parse("rim-lens", text).unwrap().1;
        let map = crate::render::caustics::caustic_map(&scene, 3, Default::default());
        let lit = Lit::new(&scene, map.as_ref());
        // The scalar kernel's `Lit` for a sample counting `w` times (0:
        // one in two, not the one that gathers).
        let alone = |w: u32| {
            if w == 0 {
                lit.for_sample(1, 0, 2)
            } else {
                lit.for_sample(0, 0, w)
            }
        };
        let (w, h) = (64u32, 36u32);
        let mut scratch = PacketScratch::default();
        let (mut differ, mut nothing) = (0, 0);
        for y in 0..h {
            for x0 in (0..w).step_by(LANES) {
                let xs: Lanes<f64> = std::array::from_fn(|l| (x0 as usize + l) as f64 + 0.5);
                let ys = [y as f64 + 0.5; LANES];
                let weights: [u32; LANES] =
                    std::array::from_fn(|l| [0, 1, 2, 4][(l + y as usize + x0 as usize / 8) % 4]);
                let (p, hits) = camera_hits(&scene, &xs, &ys, LANES, w, h);
                let paths = PacketPaths::camera(&p, &hits, LANES);
                let got = radiance_packet(&lit.with_lane_weights(&weights), &paths, WAVELENGTH_D_UM, &mut scratch);
                for l in 0..LANES {
                    let want = radiance(alone(weights[l]), &p.ray(l), 0, WAVELENGTH_D_UM);
                    assert_eq!(got[l], want, "pixel {}, {y}, weight {}", x0 as usize + l, weights[l]);
                    let plain = radiance(lit, &p.ray(l), 0, WAVELENGTH_D_UM);
                    differ += usize::from(weights[l] > 1 && want != plain);
                    nothing += usize::from(weights[l] == 0 && want != plain);
                }
            }
        }
        assert!(
            differ > 20 && nothing > 20,
            "{differ} weighted, {nothing} unlit lanes show it"
        );
    }

    /// Weights of 1 everywhere are the plain `Lit`'s; without a map, any.
    #[test]
    fn weights_of_one_change_nothing() {
        let scene = Scene::default_scene().1;
        let lit = Lit::new(&scene, None).with_lane_weights(&[0, 4, 1, 2, 0, 0, 1, 1]);
        assert_eq!(lit.lane_weights, 0);
        let map = crate::render::caustics::caustic_map(&scene, 1, Default::default());
        let lit = Lit::new(&scene, map.as_ref());
        assert_eq!(lit.with_lane_weights(&[1; LANES]).lane_weights, 0);
        assert!(lit.with_lane_weights(&[0; LANES]).caustics.is_none());
        let some = lit.with_lane_weights(&[0, 4, 1, 2, 0, 0, 1, 1]);
        assert!(!some.gathers(0) && some.gathers(1) && some.gathers(2));
        assert_eq!(some.lane(1).caustic_weight, 4.0);
        assert_eq!(some.lane(3).caustic_weight, 2.0);
        assert!(some.lane(4).caustics.is_none());
    }
}
