//! The caustic estimate of a scene, refined pass by pass ([`Caustics`]):
//! what the render thread interleaves with camera samples, and what
//! `lensview render` runs before its samples ([`with_caustics`]), in a fixed
//! proportion to them ([`PASSES_PER_SPP`]).
//!
//! The estimate depends on the lights, objects and materials only, never
//! on the camera ([`Caustics::same_light_paths`] decides when it can be
//! kept).

use crate::integrator::{Targets, photon_pass};
use crate::photon::{PhotonMap, SharedMap, initial_radius};
use crate::scene::Scene;
use std::sync::Arc;

/// Photons shot from each light in one pass.
pub const PHOTONS_PER_PASS: usize = 1 << 16;
/// Photon passes `lensview render` runs per sample per pixel.
pub const PASSES_PER_SPP: u32 = 2;
/// The fewest photon passes `lensview render` runs.
pub const MIN_PASSES: u32 = 8;
/// The starting radius holds about this many photons of the first pass.
pub const FIRST_PASS_NEIGHBOURS: usize = 24;
/// The most photons kept: past it no pass is added (the estimate stays).
pub const MAX_PHOTONS: usize = 1 << 22;

/// How a scene's photon passes are shot.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CausticSettings {
    pub photons_per_pass: usize,
    /// The first pass's gather radius; `None`: from the first pass's
    /// photons (the median distance to the [`FIRST_PASS_NEIGHBOURS`]-th
    /// nearest).
    pub initial_radius: Option<f64>,
    pub seed: u64,
}

impl Default for CausticSettings {
    fn default() -> Self {
        CausticSettings {
            photons_per_pass: PHOTONS_PER_PASS,
            initial_radius: None,
            seed: 0,
        }
    }
}

/// A scene's photon map and what is needed to add passes to it.
pub struct Caustics {
    targets: Targets,
    settings: CausticSettings,
    map: Option<Arc<PhotonMap>>,
}

impl Caustics {
    /// `None` when the scene computes no caustics (off, or nothing
    /// specular lit by a light).
    pub fn new(scene: &Scene, settings: CausticSettings) -> Option<Self> {
        let targets = Targets::of(scene);
        (scene.features.caustics && !targets.is_empty() && !scene.lights.is_empty()).then_some(Caustics {
            targets,
            settings,
            map: None,
        })
    }

    /// Whether the caustics of `a` hold for `b`: the same lights, objects
    /// (with their materials) and depth, whatever the cameras.
    pub fn same_light_paths(a: &Scene, b: &Scene) -> bool {
        a.features == b.features && a.max_depth == b.max_depth && a.lights == b.lights && a.objects == b.objects
    }

    /// Passes added so far.
    pub fn passes(&self) -> u32 {
        self.map.as_ref().map_or(0, |m| m.passes())
    }

    /// Photons stored so far.
    pub fn photons(&self) -> usize {
        self.map.as_ref().map_or(0, |m| m.photons())
    }

    /// Whether another pass may be added ([`MAX_PHOTONS`]).
    pub fn can_refine(&self) -> bool {
        self.photons() < MAX_PHOTONS
    }

    /// Shoots one more pass and adds it. The map is changed in place when
    /// no scene holds it any more (drop [`Self::shared`]'s copies first),
    /// else copied.
    pub fn add_pass(&mut self, scene: &Scene) {
        let pass = self.passes() + 1;
        let s = self.settings;
        let photons = photon_pass(scene, &self.targets, pass, s.photons_per_pass, s.seed);
        let map = self.map.get_or_insert_with(|| {
            let floor = 1e-9 * (1.0 + scene.camera.position.length());
            let r0 = s
                .initial_radius
                .or_else(|| initial_radius(&photons, FIRST_PASS_NEIGHBOURS, floor))
                .unwrap_or(1e-3);
            Arc::new(PhotonMap::new(r0))
        });
        Arc::make_mut(map).add_pass(&photons);
    }

    /// The map as a scene holds it (`None` before the first pass).
    pub fn shared(&self) -> Option<SharedMap> {
        self.map.clone().map(SharedMap)
    }
}

/// The photon passes `lensview render` runs for `spp` samples per pixel:
/// [`PASSES_PER_SPP`] per sample, at least [`MIN_PASSES`].
pub fn passes_for_spp(spp: u32) -> u32 {
    spp.saturating_mul(PASSES_PER_SPP).max(MIN_PASSES)
}

/// `scene` with its caustic map after `passes` passes (the scene itself,
/// copied, when it computes no caustics). The same on any thread count.
pub fn with_caustics(scene: &Scene, passes: u32, settings: CausticSettings) -> Scene {
    let mut out = scene.clone();
    if let Some(mut c) = Caustics::new(scene, settings) {
        for _ in 0..passes {
            if !c.can_refine() {
                break;
            }
            c.add_pass(scene);
        }
        out.caustic_map = c.shared();
    }
    out
}
