//! What the kernels shade with: the scene and, beside it, the caustic
//! photon map when one has been traced. The map is not part of the scene:
//! it is built from the scene by the render thread (or `render`) and
//! refined from stage to stage, while the scene stays the editor's.

use crate::color::Rgb;
use crate::photon::PhotonMap;
use crate::scene::Scene;

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
}

impl<'a> Lit<'a> {
    /// `scene` lit also by the photons of `caustics`.
    pub fn new(scene: &'a Scene, caustics: Option<&'a PhotonMap>) -> Self {
        Lit {
            scene,
            caustics,
            caustic_weight: 1.0,
            thin: 1,
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
        if i.wrapping_sub(from) % thin == 0 {
            Lit {
                caustic_weight: thin as f64,
                ..self
            }
        } else {
            Lit { caustics: None, ..self }
        }
    }

    /// The irradiance `e` a gather found, as this sample counts it.
    #[inline(always)]
    pub(crate) fn counted(&self, e: Rgb) -> Rgb {
        e * self.caustic_weight
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
