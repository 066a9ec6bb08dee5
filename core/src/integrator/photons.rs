//! Caustic photons: shot from each light toward the glass and mirrors only
//! ([`Targets`]), carried through lenses by the renderer's own exact tracer
//! (one ray out of a lens's chain, drawn by Russian roulette at each exit,
//! `refraction::transmitted_one`; one ray of a lens system's tree, drawn by
//! its weight, [`system_branch`]), through other glass and off mirrors by
//! Russian roulette on the Fresnel split, and recorded where
//! they land on a diffuse surface after at least one specular bounce
//! ([`photon_pass`]). Photons leave their light at the points of scrambled
//! Sobol sequences (one per light, target and colour: [`emission_point`]),
//! every later choice draws from `Sampler(seed, photon, pass)`, and the
//! pass keeps them in photon order, so a pass is the same on any
//! number of threads. Photons fly [`LANES`] at a time, by target: each
//! step finds their rays' closest hits as one packet (the scalar walk's
//! hits, bit for bit), which made a focal-spot pass about a fifth faster
//! than one photon's scalar walk at a time (docs/performance.md, round 18).

use super::emission::{Emitter, Targets, colour_of, emission_point, emit, photons_per_light, strata};
use super::lens_pass::Transmitted;
use super::refraction::transmitted_one;
use super::surface::{spawn_ray, surface};
use super::system_pass::system_rays;
use crate::color::Rgb;
use crate::geometry::{Hit, LensSystem, MAX_INTERNAL_REFLECTIONS, Pruning};
use crate::math::Ray;
use crate::optics;
use crate::photon::Photon;
use crate::sampling::Sampler;
use crate::scene::{Object, Scene};
use crate::simd::LANES;
use crate::trace::{NO_OBJECT, Packet, closest_hits, lane_object};
use rayon::prelude::*;
use std::ops::Range;

/// Photons traced by one task of a pass.
const CHUNK: usize = 1024;

/// How a photon left the object that last sent it ([`family_of`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sent {
    /// Through it: refracted (out of a lens or lens system, straight
    /// through, without reflecting inside).
    Through = 0,
    /// Reflected off it.
    Reflected = 1,
    /// Out of a lens or lens system after reflecting inside it: a ghost,
    /// whose light spreads wide and thin where the direct light is
    /// focused.
    Ghost = 2,
}

impl Sent {
    /// Every way, in the order of their numbers (`Sent::Through as usize`
    /// is its place).
    pub const ALL: [Sent; 3] = [Sent::Through, Sent::Reflected, Sent::Ghost];

    /// The word for it.
    pub fn name(self) -> &'static str {
        match self {
            Sent::Through => "through",
            Sent::Reflected => "reflected",
            Sent::Ghost => "ghost",
        }
    }
}

/// The family of a photon last sent by object `index` ([`Photon::family`],
/// `photon::family`): how it left it, 4 families an object.
fn family_of(index: usize, sent: Sent) -> u32 {
    (index as u32).wrapping_mul(4) | sent as u32
}

/// The object and the way of `family` ([`family_of`]'s inverse); `None`
/// for a family no photon is given.
pub fn family_source(family: u32) -> Option<(usize, Sent)> {
    let sent = *Sent::ALL.get((family % 4) as usize)?;
    Some(((family / 4) as usize, sent))
}

/// One photon in flight, at wavelength `lambda` (µm): the ray it travels,
/// the power it carries, its own random numbers, the object it is leaving
/// (`usize::MAX`: none), the depth used, whether it has been bent or
/// mirrored yet and by what last ([`family_of`]).
struct Flight {
    ray: Ray,
    power: Rgb,
    lambda: f64,
    rng: Sampler,
    skip: usize,
    depth: u32,
    bounced: bool,
    family: u32,
}

impl Flight {
    /// Photon `i` of pass `pass` ([`photon_pass`]), emitted from its
    /// light (of `emitters`, [`Emitter::all`]).
    fn emit(
        scene: &Scene,
        (targets, emitters): (&Targets, &[Emitter]),
        (seed, pass, i): (u64, u32, usize),
        per_light: usize,
    ) -> Flight {
        let rng = Sampler::new(seed, i as u64, pass as u64);
        let (light, j) = (i / per_light, i % per_light);
        let (lambda, tint) = colour_of(scene, j, targets.spheres.len());
        let u = emission_point(strata(scene, targets), per_light, (seed, pass), (light, j));
        let (ray, power) = emit(&emitters[light], targets, j, u);
        Flight {
            ray,
            power: power * tint,
            lambda,
            rng,
            skip: usize::MAX,
            depth: 0,
            bounced: false,
            family: 0,
        }
    }

    /// Whether the photon still travels: `max_depth` is not used up.
    fn flies(&self, scene: &Scene) -> bool {
        self.depth < scene.max_depth.max(1)
    }

    /// The photon meets `hit` (its ray's closest hit, the object it leaves
    /// skipped; `None`: it leaves the scene): it is recorded if the surface
    /// is diffuse and the photon has been bent or mirrored, then goes on by
    /// reflection or refraction with their Fresnel shares (Russian
    /// roulette). Returns whether it goes on (not gone, absorbed or out of
    /// depth).
    ///
    /// `branches` is scratch room for the rays out of a lens system (kept
    /// from photon to photon, so that a photon through one allocates
    /// nothing).
    fn land(
        &mut self,
        scene: &Scene,
        hit: Option<(usize, Hit)>,
        out: &mut Vec<Photon>,
        branches: &mut Vec<Transmitted>,
    ) -> bool {
        let Some((i, h)) = hit else {
            return false;
        };
        let ray = self.ray;
        let s = surface(scene, &ray, i, h);
        let m = &s.object.material;
        if self.bounced && m.diffuse * (1.0 - m.transparency) > 0.0 {
            out.push(Photon::new(s.p, ray.dir, self.power).with_family(self.family));
        }
        let ior = s.object.ior().at(self.lambda);
        let system = s.object.system();
        // A system's tree holds every reflection at its surfaces.
        let f = if m.transparency > 0.0 && system.is_none() {
            let (n1, n2) = if s.entering { (1.0, ior) } else { (ior, 1.0) };
            optics::fresnel_at(ray.dir, s.nf, n1, n2)
        } else {
            0.0
        };
        let (kr, kt) = (m.reflectivity + m.transparency * f, m.transparency * (1.0 - f));
        let total = kr + kt;
        let go_on = total.min(1.0);
        let u = self.rng.next_f64();
        if !(u < go_on) {
            return false;
        }
        self.power *= total / go_on;
        if u < go_on * kr / total {
            let r = optics::reflect(ray.dir, s.nf);
            self.ray = spawn_ray(s.p, s.nf, r, s.object.scale);
            self.skip = s.leaving(r);
            self.depth += 1;
            self.family = family_of(s.index, Sent::Reflected);
        } else {
            let rng = &mut self.rng;
            let tr = match system {
                Some(sys) => system_branch(s.object, sys, &ray, self.lambda, rng.next_f64(), branches),
                None => transmitted_one(s.object, s.p, s.nf, s.entering, &ray, ior, || rng.next_f64()),
            };
            let Some(tr) = tr else {
                return false;
            };
            self.power *= m.color * tr.factor;
            self.skip = if s.outward(tr.ray.dir) || s.object.lens().is_some() || system.is_some() {
                s.index
            } else {
                usize::MAX
            };
            self.ray = tr.ray;
            self.depth += tr.bounces;
            // A lens's way out counts its surfaces and reflections inside
            // (`Transmitted::bounces`: 2 straight through), a solid's
            // refraction 1.
            let ghost = tr.bounces > 2;
            self.family = family_of(s.index, if ghost { Sent::Ghost } else { Sent::Through });
        }
        self.bounced = true;
        self.flies(scene)
    }
}

/// Follows up to [`LANES`] photons together until each has left the
/// scene, been absorbed or used up `max_depth`: each step finds the closest
/// hits of the rays still in flight as one packet (`trace::closest_hits`,
/// the scalar walk's hits bit for bit), then lands each photon on its own
/// ([`Flight::land`]). Appends the photons flight `l` records to
/// `kept[l]`, in order.
fn trace_photons(
    scene: &Scene,
    flights: &mut [Flight],
    kept: &mut [Vec<Photon>; LANES],
    branches: &mut Vec<Transmitted>,
) {
    let mut live: u32 = 0;
    for (l, f) in flights.iter().enumerate() {
        live |= u32::from(f.flies(scene)) << l;
    }
    let mut packet = Packet::EMPTY;
    while live != 0 {
        let mut skip = [NO_OBJECT; LANES];
        for (l, f) in flights.iter().enumerate().filter(|(l, _)| live >> l & 1 == 1) {
            packet.set(l, &f.ray, f64::INFINITY);
            skip[l] = lane_object(f.skip);
        }
        packet.fill_unused(live);
        let hits = closest_hits(scene, &packet, &skip);
        let flying = live;
        for (l, f) in flights.iter_mut().enumerate().filter(|(l, _)| flying >> l & 1 == 1) {
            if !f.land(scene, hits.get(l), &mut kept[l], branches) {
                live &= !(1 << l);
            }
        }
    }
}

/// The photons of photons `range` of a pass, in photon order. Photon `i`
/// aims at target `i mod T`, so the photons fly [`LANES`] at a time by
/// target (photons `r, r + T, …`: one packet's rays start together and
/// head the same way), each landing tagged with its photon, and the
/// landings are put back in photon order at the end (a stable sort: one
/// photon's stay in its order).
fn chunk_photons(
    scene: &Scene,
    aim: (&Targets, &[Emitter]),
    (seed, pass): (u64, u32),
    per_light: usize,
    range: Range<usize>,
) -> Vec<Photon> {
    let t = aim.0.spheres.len().max(1);
    let mut landed: Vec<(usize, Photon)> = Vec::new();
    let (mut kept, mut branches): ([Vec<Photon>; LANES], _) = (Default::default(), Vec::new());
    let mut flights: Vec<Flight> = Vec::with_capacity(LANES);
    let mut fly = |ids: &[usize], landed: &mut Vec<(usize, Photon)>| {
        flights.clear();
        flights.extend(
            ids.iter()
                .map(|&i| Flight::emit(scene, aim, (seed, pass, i), per_light)),
        );
        trace_photons(scene, &mut flights, &mut kept, &mut branches);
        for (&i, k) in ids.iter().zip(kept.iter_mut()) {
            landed.extend(k.drain(..).map(|p| (i, p)));
        }
    };
    let mut ids = Vec::with_capacity(LANES);
    for r in 0..t {
        let first = range.start + (r + t - range.start % t) % t;
        for i in (first..range.end).step_by(t) {
            ids.push(i);
            if ids.len() == LANES {
                fly(&ids, &mut landed);
                ids.clear();
            }
        }
    }
    if !ids.is_empty() {
        fly(&ids, &mut landed);
    }
    // Already in order where the photons aim at one target.
    if !landed.is_sorted_by_key(|&(i, _)| i) {
        landed.sort_by_key(|&(i, _)| i);
    }
    landed.into_iter().map(|(_, p)| p).collect()
}

/// One ray out of a lens system, for a photon: one ray of its tree
/// ([`system_rays`]), drawn by weight; its factor the tree's total weight
/// (what the rings, edges and diaphragm absorb is lost).
fn system_branch(
    obj: &Object,
    sys: &LensSystem,
    ray: &Ray,
    lambda: f64,
    u: f64,
    out: &mut Vec<Transmitted>,
) -> Option<Transmitted> {
    let prune = Pruning {
        scale: 1.0,
        min: PHOTON_BRANCH_MIN,
        max_reflections: MAX_INTERNAL_REFLECTIONS,
        roulette: super::shade::GHOST_ROULETTE,
    };
    out.clear();
    system_rays(obj, sys, ray, lambda, &prune, |t| out.push(t));
    pick_branch(out, u)
}

/// Branches lighter than this, relative to the photon, are not followed
/// through a lens system (the light they carry is dropped: at most this
/// fraction).
const PHOTON_BRANCH_MIN: f64 = 1e-4;

/// One of the rays `out`, drawn by its factor with `u` in [0, 1); its
/// factor set to their sum.
fn pick_branch(out: &[Transmitted], u: f64) -> Option<Transmitted> {
    let total: f64 = out.iter().map(|t| t.factor).sum();
    let mut left = u * total;
    let pick = out.iter().position(|t| {
        left -= t.factor;
        left < 0.0
    });
    let mut tr = *out.get(pick.unwrap_or(out.len().saturating_sub(1)))?;
    tr.factor = total;
    Some(tr)
}

/// The photons of pass `pass` (from 1): `per_light` photons from each light
/// (rounded up to a multiple of the number of targets, times three with
/// dispersive glass, so that targets and channels get equal shares) toward
/// the targets, those that land after a specular bounce, in photon order.
/// Empty when the scene has no light or nothing specular.
pub fn photon_pass(scene: &Scene, targets: &Targets, pass: u32, per_light: usize, seed: u64) -> Vec<Photon> {
    if targets.is_empty() || scene.lights.is_empty() {
        return Vec::new();
    }
    let per_light = photons_per_light(scene, targets, per_light);
    let total = per_light * scene.lights.len();
    let emitters = Emitter::all(scene, targets, per_light);
    let chunks: Vec<Vec<Photon>> = (0..total.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            chunk_photons(
                scene,
                (targets, &emitters),
                (seed, pass),
                per_light,
                c * CHUNK..((c + 1) * CHUNK).min(total),
            )
        })
        .collect();
    chunks.concat()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A pass traced in packets ([`photon_pass`]) gives the photons that
    /// following each photon alone with the scalar walk gives, in the same
    /// order: through a biconvex lens, a lens system with dispersion, a
    /// glass ball and mirrors, and the lens seen edge-on.
    #[test]
    fn photons_in_packets_are_the_photons_one_by_one() {
        use crate::trace::closest_hit_skip;
        let parse = |name, text| Scene::parse(name, text).unwrap().1;
        let scenes = [
            parse("focal-spot", include_str!("../../../scenes/focal-spot.toml")),
            parse("lens-family", include_str!("../../../scenes/lens-family.toml")),
            parse("primitives", include_str!("../../../scenes/primitives.toml")),
            parse("rim-lens", include_str!("../../../scenes/rim-lens.toml")),
        ];
        for scene in &scenes {
            let targets = Targets::of(scene);
            let per_light = photons_per_light(scene, &targets, 2000);
            let emitters = Emitter::all(scene, &targets, per_light);
            let got = photon_pass(scene, &targets, 3, 2000, 7);
            let (mut want, mut branches) = (Vec::new(), Vec::new());
            for i in 0..per_light * scene.lights.len() {
                let mut f = Flight::emit(scene, (&targets, &emitters), (7, 3, i), per_light);
                let mut flies = f.flies(scene);
                while flies {
                    let hit = closest_hit_skip(scene, &f.ray, f64::INFINITY, f.skip);
                    flies = f.land(scene, hit, &mut want, &mut branches);
                }
            }
            assert!(want.len() > 500, "{} photons", want.len());
            assert!(got == want, "{} against {} photons", got.len(), want.len());
        }
    }

    /// Each photon's family names the object that last sent it: from where
    /// it landed, back along the way it came, that object is the first
    /// hit. Direct light, reflections and ghosts all show: through and off
    /// the lens in rim-lens, and inside it; through the glass ball and off
    /// the mirror ball in primitives.
    #[test]
    fn a_photons_family_is_the_object_it_came_from() {
        use crate::trace::closest_hit_skip;
        use glam::DVec3;
        let parse = |name, text| Scene::parse(name, text).unwrap().1;
        for sent in Sent::ALL {
            assert_eq!(Sent::ALL[sent as usize], sent);
            assert_eq!(family_source(family_of(7, sent)), Some((7, sent)));
        }
        assert_eq!(family_source(3), None);
        let cases = [
            (parse("rim-lens", include_str!("../../../scenes/rim-lens.toml")), 3),
            (parse("primitives", include_str!("../../../scenes/primitives.toml")), 2),
        ];
        for (scene, kinds) in &cases {
            let targets = Targets::of(scene);
            let photons = photon_pass(scene, &targets, 1, 20_000, 3);
            let mut agree = 0;
            let mut seen: Vec<(usize, Sent)> = Vec::new();
            for ph in &photons {
                let dir = DVec3::from_array(ph.dir.map(f64::from)).normalize();
                let back = Ray {
                    origin: ph.p - dir * 1e-6 * (1.0 + ph.p.length()),
                    dir: -dir,
                };
                let from = closest_hit_skip(scene, &back, f64::INFINITY, usize::MAX).map(|h| h.0);
                let (object, kind) = family_source(ph.family).expect("a family photons are given");
                agree += usize::from(from == Some(object));
                if !seen.contains(&(object, kind)) {
                    seen.push((object, kind));
                }
            }
            let n = photons.len();
            assert!(
                agree * 100 >= n * 99,
                "{agree} of {n} photons came from their family's object"
            );
            let kinds_seen = Sent::ALL.iter().filter(|k| seen.iter().any(|s| s.1 == **k)).count();
            assert!(kinds_seen >= *kinds, "families {seen:?}");
            assert!(
                seen.iter().all(|s| scene.objects[s.0].material.transparency > 0.0
                    || scene.objects[s.0].material.reflectivity > 0.0
                    || scene.objects[s.0].lens().is_some()),
                "{seen:?}"
            );
        }
    }
}
