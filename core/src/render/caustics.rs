//! The caustic estimate of a scene, refined pass by pass ([`Caustics`]):
//! what the render thread interleaves with camera samples, and what
//! `lensview render` runs before its samples ([`caustic_map`]): photons
//! in proportion to the camera's work ([`PHOTON_SHARE`]), at most
//! [`PASSES_PER_SPP`] passes per sample.
//!
//! The estimate depends on the lights, objects and materials only, never
//! on the camera: it is kept while the editor's `scene::Change` says the
//! light paths are the same ([`Interleaved::follow`];
//! [`Caustics::same_light_paths`] checks that in debug builds).

use crate::integrator::{Targets, photon_pass, photons_per_light};
use crate::limits::{MAX_SAMPLES, PHOTON_WORK, Work};
use crate::photon::{Photon, PhotonMap, family_scales, initial_radius};
use crate::render::progressive::Stage;
use crate::render::thinning;
use crate::scene::Scene;
use std::sync::Arc;

/// Photons shot from each light in one pass.
pub const PHOTONS_PER_PASS: usize = 1 << 15;
/// The most photon passes `lensview render` runs per sample per pixel.
pub const PASSES_PER_SPP: u32 = 2;
/// The fewest photon passes [`passes_for_spp`] gives.
pub const MIN_PASSES: u32 = 8;
/// The share of the camera's work (`limits::Work`, [`PHOTON_WORK`] camera
/// samples a photon) that photon passes may add: a frame of `n` camera
/// samples affords `PHOTON_SHARE · n / PHOTON_WORK` photons traced
/// ([`photon_allowance`]), in `lensview render` and in the viewer alike.
/// 0.09 since round 27 (0.125 before): evenly spread photons
/// (`integrator::emission::emission_point`) give the caustic pixels a
/// lower error with fewer of them; with 0.0625 optical-bench's error at
/// 16 spp was half again round 26's (docs/performance.md, round 27).
pub const PHOTON_SHARE: f64 = 0.09;
/// The starting radius holds about this many photons of the first pass.
pub const FIRST_PASS_NEIGHBOURS: usize = 24;
/// The most photons kept: past it no pass is added (the estimate stays).
pub const MAX_PHOTONS: usize = 1 << 21;
/// Passes shot together are merged into the map once this many photons
/// have landed (or at the end): a merge copies the map's blocks, so merging
/// each pass cost many passes the square of their photons, and merging
/// them all at once would hold every landed photon twice (up to
/// [`MAX_PHOTONS`], about 180 MB); at most 8 merges fill the map.
pub const MERGE_PHOTONS: usize = 1 << 18;
/// The most photons `lensview render` traces (2^28 ≈ 2.7·10^8, about 2.3
/// minutes at 1.9 M photons/s on 2 cores): its passes are cut to fit, but
/// never below one ([`render_photons`]). Without it a scene whose photons
/// are rarely stored (so [`MAX_PHOTONS`] never stops the passes) traced
/// 2 × spp passes however long they took.
pub const MAX_PHOTONS_TRACED: u64 = 1 << 28;

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
    map: Option<PhotonMap>,
    /// Photons a pass traces (all lights), and traced so far.
    per_pass: u64,
    traced: u64,
}

impl Caustics {
    /// `None` when the scene computes no caustics (off, or nothing
    /// specular lit by a light).
    pub fn new(scene: &Scene, settings: CausticSettings) -> Option<Self> {
        let targets = Targets::of(scene);
        let on = scene.features.caustics && !targets.is_empty() && !scene.lights.is_empty();
        on.then(|| {
            let per_light = photons_per_light(scene, &targets, settings.photons_per_pass);
            Caustics {
                per_pass: (per_light as u64).saturating_mul(scene.lights.len() as u64).max(1),
                targets,
                settings,
                map: None,
                traced: 0,
            }
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

    /// Whether another pass may be added: fewer than [`MAX_PHOTONS`]
    /// stored, and room for its photons under [`MAX_PHOTONS_TRACED`] (the
    /// first pass always: the viewer's cap and `render`'s are the same).
    pub fn can_refine(&self) -> bool {
        self.room_for_pass(self.photons())
    }

    /// [`Caustics::can_refine`] with `stored` photons landed so far (those
    /// of passes shot and not yet merged included).
    fn room_for_pass(&self, stored: usize) -> bool {
        stored < MAX_PHOTONS && (self.traced == 0 || self.traced + self.per_pass <= MAX_PHOTONS_TRACED)
    }

    /// Photons one pass traces, all lights together.
    pub fn photons_per_pass(&self) -> u64 {
        self.per_pass
    }

    /// Shoots one more pass and adds it (in place).
    pub fn add_pass(&mut self, scene: &Scene) {
        self.add_passes(scene, |n| n == 0);
    }

    /// Shoots passes while the caps allow another ([`Caustics::can_refine`],
    /// counting the passes shot so far) and `more(n)` says so (`n`: passes
    /// shot by this call so far; asked before each), and adds them to the
    /// map together, [`MERGE_PHOTONS`] photons or more at a time
    /// (`PhotonMap::add_passes`: the map adding them one by one gives,
    /// each group's cells merged once a batch). Returns how many.
    pub fn add_passes(&mut self, scene: &Scene, mut more: impl FnMut(usize) -> bool) -> usize {
        let s = self.settings;
        let (mut batch, mut shot): (Vec<Vec<Photon>>, usize) = (Vec::new(), 0);
        let mut stored = self.photons();
        while self.room_for_pass(stored) && more(shot) {
            let pass = self.passes() + batch.len() as u32 + 1;
            let photons = photon_pass(scene, &self.targets, pass, s.photons_per_pass, s.seed);
            stored += photons.len();
            self.traced += self.per_pass;
            batch.push(photons);
            shot += 1;
            if batch.iter().map(Vec::len).sum::<usize>() >= MERGE_PHOTONS {
                self.merge(scene, &mut batch);
            }
        }
        self.merge(scene, &mut batch);
        shot
    }

    /// Adds the passes of `batch` to the map (making it from the first
    /// pass's photons if there is none yet) and empties it.
    fn merge(&mut self, scene: &Scene, batch: &mut Vec<Vec<Photon>>) {
        let Some(first) = batch.first() else {
            return;
        };
        let s = self.settings;
        let map = self.map.get_or_insert_with(|| {
            let floor = 1e-9 * (1.0 + scene.camera.position.length());
            if let Some(r0) = s.initial_radius {
                return PhotonMap::new(r0);
            }
            let r0 = initial_radius(first, FIRST_PASS_NEIGHBOURS, floor).unwrap_or(1e-3);
            PhotonMap::with_families(r0, &family_scales(first, FIRST_PASS_NEIGHBOURS, r0))
        });
        let passes: Vec<&[Photon]> = batch.iter().map(Vec::as_slice).collect();
        map.add_passes(&passes);
        batch.clear();
    }

    /// The map, for the kernels to shade with beside the scene
    /// (`integrator::Lit`; `None` before the first pass).
    pub fn map(&self) -> Option<&PhotonMap> {
        self.map.as_ref()
    }

    /// The map, kept (`None` before the first pass).
    pub fn into_map(self) -> Option<PhotonMap> {
        self.map
    }
}

/// The most photon passes `lensview render` runs for `spp` samples per
/// pixel: [`PASSES_PER_SPP`] per sample, at least [`MIN_PASSES`].
pub fn passes_for_spp(spp: u32) -> u32 {
    spp.saturating_mul(PASSES_PER_SPP).max(MIN_PASSES)
}

/// The photons that `camera_work` camera samples of work (`Work::total`)
/// afford: [`PHOTON_SHARE`] of it, at [`PHOTON_WORK`] a photon.
pub fn photon_allowance(camera_work: f64) -> f64 {
    PHOTON_SHARE * camera_work / PHOTON_WORK
}

/// The camera's work of `width`×`height` pixels at `spp` samples each,
/// shading `lights` lights (`limits::Work::total`).
pub fn camera_work((width, height): (u32, u32), spp: u32, lights: usize) -> f64 {
    Work::samples(width, height, spp as u64, 1).with_lights(lights).total()
}

/// The camera's work of `stage` on a `width`×`height` picture that has
/// `have` samples per pixel, shading `lights` lights: a sample stage's
/// ([`Stage::cost`]); none for a block preview or a reprojection, which
/// add no photon pass.
pub fn stage_work(stage: Stage, (width, height, have): (u32, u32, u32), lights: usize) -> f64 {
    match stage {
        Stage::Samples(n) => camera_work((width, height), n.saturating_sub(have), lights),
        Stage::Blocks(_) | Stage::Reprojected => 0.0,
    }
}

/// The photon passes `lensview render` runs for `spp` samples per pixel
/// of `width`×`height` pixels of `scene`, and the photons they trace at
/// most (for the work budget, `limits::Work`; fewer when the map fills up
/// and the passes stop early): the passes of whole photons the camera's
/// work affords ([`photon_allowance`]), at most [`passes_for_spp`], cut to
/// [`MAX_PHOTONS_TRACED`] photons, never below one pass. `(0, 0.0)` when
/// the scene computes no caustics.
pub fn render_photons(scene: &Scene, (width, height): (u32, u32), spp: u32, settings: CausticSettings) -> (u32, f64) {
    Caustics::new(scene, settings).map_or((0, 0.0), |c| {
        let per_pass = c.per_pass;
        let work = camera_work((width, height), spp, scene.lights.len());
        let afford = (photon_allowance(work) / per_pass as f64) as u32;
        let fit = u32::try_from(MAX_PHOTONS_TRACED / per_pass).unwrap_or(u32::MAX);
        let passes = afford.min(passes_for_spp(spp)).min(fit).max(1);
        (passes, passes as f64 * per_pass as f64)
    })
}

/// `scene`'s caustic map after `passes` passes (`None` when it computes no
/// caustics), to render with beside it (`integrator::Lit`). The same on
/// any thread count.
pub fn caustic_map(scene: &Scene, passes: u32, settings: CausticSettings) -> Option<PhotonMap> {
    let mut c = Caustics::new(scene, settings)?;
    c.add_passes(scene, |n| n < passes as usize);
    c.into_map()
}

/// The photon map of a still (`lensview render`, a film's frame, the web
/// page's picture) of `width`×`height` pixels at `spp` samples, and the
/// thinning of its gathers (for `Lit::thinned`): [`render_photons`]'s
/// passes, then, where the still's gathers are thinned
/// ([`thinning::gather_thinning`] of those passes, at their radius),
/// [`thinning::THINNED_PHOTONS`] times as many in all, as far as the caps
/// allow and where their work fits `limits::MAX_SAMPLES` (`None` when the
/// scene computes no caustics). The same on any thread count.
pub fn still_map(scene: &Scene, size: (u32, u32), spp: u32, settings: CausticSettings) -> Option<(PhotonMap, u32)> {
    let (passes, _) = render_photons(scene, size, spp, settings);
    let mut c = Caustics::new(scene, settings)?;
    c.add_passes(scene, |n| n < passes as usize);
    let thin = c.map().map_or(1, |m| still_thinning(scene, m, passes, size));
    // The extra photons only where their work fits the limit too (that
    // of the passes alone was checked before, `limits::check_total`).
    let work = |passes: u32| {
        let photons = passes as f64 * c.photons_per_pass() as f64;
        let samples = Work::samples(size.0, size.1, spp as u64, 1).with_lights(scene.lights.len());
        samples.with_photons(photons).total() <= MAX_SAMPLES as f64
    };
    let more = thinned_passes(passes, thin) - passes;
    let more = if work(passes + more) { more } else { 0 };
    c.add_passes(scene, |n| n < more as usize);
    Some((c.into_map()?, thin))
}

/// [`thinning::gather_thinning`] of a still of `size` pixels whose
/// map `map` traced `passes` before any for thinning ([`still_map`]): at
/// those passes' radius (the same whatever the map has added since).
pub fn still_thinning(scene: &Scene, map: &PhotonMap, passes: u32, size: (u32, u32)) -> u32 {
    let radius = PhotonMap::radius_of_pass(map.first_radius(), passes);
    thinning::gather_thinning(scene, map, radius, size)
}

/// The passes [`still_map`] traces for [`render_photons`]'s `passes` where
/// the still's gathers are thinned by `thin`.
pub fn thinned_passes(passes: u32, thin: u32) -> u32 {
    let more = (passes as f64 * thinning::photon_factor(thin)).ceil();
    (more as u32).max(passes)
}

/// The caustics the render thread keeps from job to job: one photon map
/// for as long as the lights, objects and materials stay the same (camera
/// moves keep it), refined before each stage by the passes its camera
/// work affords ([`photon_allowance`]; the first pass at once, so that
/// caustics show from the first frame), up to [`MAX_PHOTONS`] stored or
/// [`MAX_PHOTONS_TRACED`] traced.
#[derive(Default)]
pub struct Interleaved {
    scene: Option<Arc<Scene>>,
    caustics: Option<Caustics>,
    /// Photons the camera's work so far affords and no pass has traced
    /// (negative after the first pass, which is traced on credit).
    credit: f64,
    /// The latest stage's photon-pass and gather times, seconds (the
    /// photon passes before the stage, zero for a stage without any).
    times: (f64, f64),
}

impl Interleaved {
    /// Takes the scene of a new job: the estimate is kept when the editor
    /// says the light paths are the same (`keeps`: only the camera, the
    /// shading or the image changed since the scene followed before), else
    /// started again.
    pub fn follow(&mut self, scene: &Arc<Scene>, keeps: bool) {
        let same = keeps && self.scene.is_some();
        debug_assert!(
            !same
                || self
                    .scene
                    .as_ref()
                    .is_some_and(|s| Caustics::same_light_paths(s, scene))
        );
        if !same {
            self.caustics = Caustics::new(scene, CausticSettings::default());
            self.credit = 0.0;
        }
        self.scene = Some(scene.clone());
    }

    /// Adds the passes due before a stage of `camera_work` camera samples
    /// of work (`limits::Work::total`; none for a block preview, which
    /// adds no pass), `factor` times the photons that affords (more where
    /// its gathers are thinned: `Progressive::stage_photons`), stopping
    /// early when `cancelled` says so or the map is full. The first pass
    /// is traced on credit.
    pub fn refine(&mut self, (camera_work, factor): (f64, f64), cancelled: &dyn Fn() -> bool) {
        let (Some(c), Some(scene)) = (&mut self.caustics, &self.scene) else {
            return;
        };
        let start = web_time::Instant::now();
        self.credit += photon_allowance(camera_work) * factor;
        let per_pass = c.photons_per_pass() as f64;
        let first = c.passes() == 0 && camera_work > 0.0;
        let credit = &mut self.credit;
        // The passes due, shot one by one (a cancel stops them between
        // two), added at once.
        c.add_passes(scene, |n| {
            let due = (first && n == 0 || *credit >= per_pass) && !cancelled();
            if due {
                *credit -= per_pass;
            }
            due
        });
        self.times.0 = start.elapsed().as_secs_f64();
    }

    /// Starts (`false`) or stops (`true`) counting a stage's gathering:
    /// the time the pool's threads spent in [`PhotonMap::irradiance`] in
    /// between, summed over them and divided by their number, so that on a
    /// stage that keeps them all busy it compares with the stage's time.
    pub fn gather_clock(&mut self, stop: bool) {
        let spent: f64 = rayon::broadcast(|_| crate::photon::take_gather_seconds())
            .into_iter()
            .sum();
        if stop {
            self.times.1 = spent / rayon::current_num_threads() as f64;
        }
    }

    /// The photon map to shade with beside the job's scene (`None` before
    /// the first pass, or when the scene computes no caustics).
    pub fn map(&self) -> Option<&PhotonMap> {
        self.caustics.as_ref().and_then(Caustics::map)
    }

    /// Passes and photons of the current map (zero without one).
    pub fn counts(&self) -> (u32, usize) {
        self.caustics.as_ref().map_or((0, 0), |c| (c.passes(), c.photons()))
    }

    /// What a frame reports of the caustics: the counts, and the latest
    /// stage's photon-pass and gather times.
    pub fn stats(&self) -> CausticStats {
        let (passes, photons) = self.counts();
        CausticStats {
            passes,
            photons,
            photon_ms: self.times.0 * 1e3,
            gather_ms: self.times.1 * 1e3,
        }
    }
}

/// A frame's caustics: the map's passes and photons so far, and where its
/// stage's caustic time went (zero without caustics).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CausticStats {
    pub passes: u32,
    pub photons: usize,
    /// Photon passes traced before the stage.
    pub photon_ms: f64,
    /// Gathering photons while the stage shaded (all threads together).
    pub gather_ms: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn focal_spot() -> Scene {
        let text = include_str!("../../../scenes/focal-spot.toml");
        Scene::parse("focal-spot.toml", text).unwrap().1
    }

    /// The camera work that affords `passes` passes of `scene`'s photons.
    fn work_for(scene: &Scene, passes: f64) -> f64 {
        let per_pass = Caustics::new(scene, CausticSettings::default())
            .unwrap()
            .photons_per_pass();
        passes * per_pass as f64 * PHOTON_WORK / PHOTON_SHARE
    }

    /// Passes shot together and merged in batches of [`MERGE_PHOTONS`]
    /// give the map that adding them one by one gives, bit for bit.
    #[test]
    fn passes_merged_together_give_the_map_of_one_by_one() {
        let scene = focal_spot();
        let mut one = Caustics::new(&scene, CausticSettings::default()).unwrap();
        for _ in 0..12 {
            one.add_pass(&scene);
        }
        let together = caustic_map(&scene, 12, CausticSettings::default()).unwrap();
        let one = one.into_map().unwrap();
        assert_eq!((together.passes(), together.photons()), (one.passes(), one.photons()));
        assert!(
            one.photons() > MERGE_PHOTONS,
            "{} photons: one merge only",
            one.photons()
        );
        let mut lit = 0;
        for i in 0..400 {
            let p = glam::DVec3::new(0.01 * (i % 20) as f64 - 0.1, 0.0, 0.01 * (i / 20) as f64 - 0.1);
            let (a, b) = (
                one.irradiance(p, glam::DVec3::Y),
                together.irradiance(p, glam::DVec3::Y),
            );
            assert_eq!(a.x.to_bits(), b.x.to_bits(), "{p}");
            lit += usize::from(a.x > 0.0);
        }
        assert!(lit > 100, "{lit} probes lit");
    }

    /// A camera move keeps the estimate; a light move starts it again.
    #[test]
    fn the_estimate_survives_camera_moves_only() {
        let base = focal_spot();
        let mut it = Interleaved::default();
        it.follow(&Arc::new(base.clone()), false);
        it.refine((work_for(&base, 0.5), 1.0), &|| false);
        let (passes, photons) = it.counts();
        assert_eq!(passes, 1, "the first pass at once");
        assert!(photons > 1000, "{photons}");
        let mut moved = base.clone();
        moved.camera.position.x += 1.0;
        let job = Arc::new(moved.clone());
        it.follow(&job, true);
        assert_eq!(it.counts(), (passes, photons));
        let map = it.map().expect("a map after a pass");
        assert_eq!((map.passes(), map.photons()), (passes, photons));
        let mut lit = base.clone();
        if let crate::light::Light::Point { position, .. } = &mut lit.lights[0] {
            position.x += 0.5;
        }
        let lit = Arc::new(lit);
        it.follow(&lit, false);
        assert_eq!(it.counts(), (0, 0));
        assert!(it.map().is_none(), "no map before the new light's first pass");
        // Cancelled: no pass.
        it.refine((work_for(&base, 4.0), 1.0), &|| true);
        assert_eq!(it.counts(), (0, 0));
    }

    /// Issue 29.3: a stage's passes are those its camera work affords
    /// ([`PHOTON_SHARE`]), the first on credit, the rest carried over.
    #[test]
    fn viewer_passes_follow_the_camera_work() {
        let base = focal_spot();
        let mut it = Interleaved::default();
        it.follow(&Arc::new(base.clone()), false);
        let mut passes = Vec::new();
        it.refine((0.0, 1.0), &|| false);
        assert_eq!(it.counts().0, 0, "a block preview traces no pass");
        for owed in [0.5, 1.2, 2.1, 0.8] {
            it.refine((work_for(&base, owed), 1.0), &|| false);
            passes.push(it.counts().0);
        }
        // 1 on credit (−0.5 left); 0.7: none; 2.8: two more; 1.6: one.
        assert_eq!(passes, [1, 1, 3, 4]);
    }

    /// Issue 30: the viewer's passes stop at [`MAX_PHOTONS_TRACED`] traced
    /// as `render`'s do (the first pass always runs).
    #[test]
    fn the_viewers_passes_are_capped_by_photons_traced() {
        let scene = focal_spot();
        let mut c = Caustics::new(&scene, CausticSettings::default()).unwrap();
        c.traced = MAX_PHOTONS_TRACED - c.per_pass;
        assert!(c.can_refine(), "room for one more pass");
        c.traced += 1;
        assert!(!c.can_refine(), "no room for a whole pass");
        c.traced = 0;
        assert!(c.can_refine());
    }

    /// Passes for a headless render: at most in proportion to the samples.
    #[test]
    fn headless_passes_follow_the_samples() {
        assert_eq!(passes_for_spp(1), MIN_PASSES);
        assert_eq!(passes_for_spp(64), 64 * PASSES_PER_SPP);
        let map = caustic_map(&focal_spot(), 3, CausticSettings::default());
        assert_eq!(map.expect("a photon map").passes(), 3);
    }

    /// Issue 30.2: the photons a render traces are capped (passes cut to
    /// [`MAX_PHOTONS_TRACED`], at least one), and counted.
    #[test]
    fn headless_photons_are_capped_and_counted() {
        let scene = focal_spot();
        let settings = CausticSettings::default();
        let per_light = photons_per_light(&scene, &Targets::of(&scene), PHOTONS_PER_PASS);
        let per_pass = (per_light * scene.lights.len()) as f64;
        // Issue 29.3: the photons the camera's work affords, whole passes.
        let afford = (PHOTON_SHARE * (640.0 * 360.0 * 16.0) / PHOTON_WORK / per_pass) as u32;
        assert!(afford >= 1);
        assert_eq!(
            render_photons(&scene, (640, 360), 16, settings),
            (afford, afford as f64 * per_pass)
        );
        // Tiny: one pass; huge: at most PASSES_PER_SPP a sample.
        assert_eq!(render_photons(&scene, (16, 16), 1, settings), (1, per_pass));
        assert_eq!(render_photons(&scene, (4096, 4096), 4, settings), (8, 8.0 * per_pass));
        let most = (MAX_PHOTONS_TRACED / per_pass as u64) as u32;
        assert_eq!(
            render_photons(&scene, (4096, 4096), 65536, settings),
            (most, most as f64 * per_pass)
        );
        assert!(most as f64 * per_pass <= MAX_PHOTONS_TRACED as f64);
        // So many lights that one pass is over the cap: still one pass.
        let mut many = scene.clone();
        let light = many.lights[0].clone();
        many.lights.resize(10_000, light);
        assert_eq!(
            render_photons(&many, (640, 360), 1, settings),
            (1, 1e4 * per_light as f64)
        );
        let mut off = scene;
        off.features.caustics = false;
        assert_eq!(render_photons(&off, (640, 360), 64, settings), (0, 0.0));
    }
}
