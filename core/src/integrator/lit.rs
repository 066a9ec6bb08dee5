//! What the kernels shade with: the scene and, beside it, the caustic
//! photon map when one has been traced. The map is not part of the scene:
//! it is built from the scene by the render thread (or `render`) and
//! refined from stage to stage, while the scene stays the editor's.

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
}

impl<'a> Lit<'a> {
    /// `scene` lit also by the photons of `caustics`.
    pub fn new(scene: &'a Scene, caustics: Option<&'a PhotonMap>) -> Self {
        Lit { scene, caustics }
    }
}

/// A scene without caustic photons.
impl<'a> From<&'a Scene> for Lit<'a> {
    fn from(scene: &'a Scene) -> Self {
        Lit { scene, caustics: None }
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
