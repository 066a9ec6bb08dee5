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

use super::lens_pass::Transmitted;
use super::refraction::transmitted_one;
use super::surface::{spawn_ray, surface};
use super::system_pass::system_rays;
use crate::color::Rgb;
use crate::geometry::{Hit, LensSystem, MAX_INTERNAL_REFLECTIONS, Pruning, Shape};
use crate::light::Light;
use crate::math::{Ray, orthonormal_basis};
use crate::optics::{self, RGB_WAVELENGTHS_UM, WAVELENGTH_D_UM};
use crate::photon::Photon;
use crate::sampling::{Sampler, concentric_disc, mix64, sobol_owen_2d};
use crate::scene::{Object, Scene};
use crate::simd::LANES;
use crate::trace::{NO_OBJECT, Packet, closest_hits, lane_object};
use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::PI;
use std::ops::Range;

/// Photons traced by one task of a pass.
const CHUNK: usize = 1024;

/// The bounding spheres of the objects that can bend or mirror light: the
/// only directions worth a photon (one that meets none of them first lands
/// on a diffuse surface without a specular bounce, which direct light
/// already gives).
#[derive(Clone, Debug)]
pub struct Targets {
    spheres: Vec<(DVec3, f64)>,
    /// Centre and radius of a sphere around every object (where a
    /// directional light's photons start from).
    world: (DVec3, f64),
}

impl Targets {
    pub fn of(scene: &Scene) -> Self {
        let spheres = scene
            .objects
            .iter()
            .filter(|o| o.material.transparency > 0.0 || o.material.reflectivity > 0.0)
            .map(bounding_sphere)
            .collect();
        Targets {
            spheres,
            world: world_sphere(scene),
        }
    }

    /// Every direction from every light (for a directional light, the disc
    /// of the whole scene): uniform emission, what the cones of [`Self::of`]
    /// must agree with (tests/caustic_emission.rs). Empty without objects.
    pub fn everywhere(scene: &Scene) -> Self {
        let (c, r) = world_sphere(scene);
        let reach = scene.lights.iter().fold(r, |r, l| match *l {
            Light::Point { position, .. } => r.max((position - c).length()),
            Light::Directional { .. } => r,
        });
        let spheres = if scene.objects.is_empty() {
            Vec::new()
        } else {
            vec![(c, 1.01 * reach + 1.0)]
        };
        Targets { spheres, world: (c, r) }
    }

    pub fn is_empty(&self) -> bool {
        self.spheres.is_empty()
    }
}

/// Centre and radius of a sphere around every object.
fn world_sphere(scene: &Scene) -> (DVec3, f64) {
    let sphere = |b: &crate::geometry::Aabb| ((b.min + b.max) * 0.5, (b.max - b.min).length() * 0.5);
    scene
        .objects
        .iter()
        .map(|o| o.world_bounds)
        .reduce(|a, b| a.union(&b))
        .map_or((DVec3::ZERO, 0.0), |b| sphere(&b))
}

/// A sphere holding `o`, as tight as its shape allows: a lens lies within
/// `d/2` of its centre (the rims meet in the plane through it, and a cap
/// point at height `z ≤ sag` lies at `√((d/2)² − 2z(R − sag))` from it), a
/// sphere is its own, other shapes are held by the half-diagonal of their
/// own box (the same however the object is turned, unlike its world box).
/// Padded by 10⁻⁹ of its size and place, for rounding.
fn bounding_sphere(o: &Object) -> (DVec3, f64) {
    let world = |p: DVec3| o.world_from_object * p + o.position;
    let (c, r) = match &o.shape {
        Shape::Lens(l) => (world(l.center), 0.5 * l.d),
        Shape::Sphere(s) => (world(DVec3::ZERO), s.radius),
        shape => {
            let b = shape.bounds();
            (world((b.min + b.max) * 0.5), (b.max - b.min).length() * 0.5)
        }
    };
    (c, r + 1e-9 * (r + c.abs().max_element()))
}

/// Half-angle cosine and solid angle of target `(c, r)` seen from `from`
/// (the whole sphere of directions when `from` is inside it).
fn cone(from: DVec3, (c, r): (DVec3, f64)) -> (f64, f64) {
    let d2 = (c - from).length_squared();
    if d2 <= r * r {
        return (-1.0, 4.0 * PI);
    }
    let cos_max = (1.0 - r * r / d2).max(0.0).sqrt();
    (cos_max, 2.0 * PI * (1.0 - cos_max))
}

/// What emission from one light toward the targets needs of the light and
/// the targets alone, worked out once a pass ([`Emitter::all`]) instead of
/// once a photon: each target's cone (square roots, divisions), the basis
/// about its axis and its term of the density sum (a directional light's
/// basis too). The same operations on the same values, so the same bits; a
/// pass's photons 3 % faster in focal-spot, 7 % in primitives (whose two
/// lights aim at three targets; docs/performance.md, round 26).
enum Emitter {
    /// A point light: the light and, for each target, its [`Cone`].
    Point {
        position: DVec3,
        power: (Rgb, f64),
        cones: Vec<Cone>,
    },
    /// A directional light: the light, the basis across its beam and the
    /// photons it aims at each target.
    Directional {
        direction: DVec3,
        power: (Rgb, f64),
        basis: (DVec3, DVec3),
        share: f64,
    },
}

/// A target as a point light at `from` sees it: the cosine of its cone's
/// half-angle (−1: the whole sphere), the unit vector toward its centre,
/// the basis about that axis (the cone's directions are drawn in), and
/// the photons per steradian its share of a light's photons gives inside
/// its cone.
struct Cone {
    cos_max: f64,
    toward: DVec3,
    axis: DVec3,
    basis: (DVec3, DVec3),
    per_sr: f64,
}

impl Emitter {
    /// Each light's emitter for `t`, in the scene's order of lights, where
    /// each light shoots `per_light` photons (a whole share for every
    /// target, [`photons_per_light`]).
    fn all(scene: &Scene, t: &Targets, per_light: usize) -> Vec<Emitter> {
        let share = (per_light / t.spheres.len().max(1)) as f64;
        let cone_of = |position: DVec3, s: (DVec3, f64)| {
            let (cos_max, omega) = cone(position, s);
            let axis = (s.0 - position).try_normalize().unwrap_or(DVec3::Z);
            Cone {
                cos_max,
                toward: (s.0 - position).normalize(),
                axis,
                basis: orthonormal_basis(axis),
                per_sr: share / omega,
            }
        };
        let emitter = |light: &Light| match *light {
            Light::Point {
                position,
                color,
                intensity,
            } => Emitter::Point {
                position,
                power: (color, intensity),
                cones: t.spheres.iter().map(|&s| cone_of(position, s)).collect(),
            },
            Light::Directional {
                direction,
                color,
                intensity,
            } => Emitter::Directional {
                direction,
                power: (color, intensity),
                basis: orthonormal_basis(direction),
                share,
            },
        };
        scene.lights.iter().map(emitter).collect()
    }
}

/// A photon's first ray and the power it carries: photon `i` of the light
/// whose [`Emitter`] is `e` aims at target `i mod T`, at the point of its
/// cone (disc for a directional light) that `u` in [0, 1)² maps to
/// area for area ([`concentric_disc`]; evenly spread `u`, evenly spread
/// rays); its power is the light's over the number of photons and the
/// density of the mixture of all targets' cones (discs) at the ray drawn,
/// so that the photons of a pass deliver the light's power exactly in
/// expectation.
fn emit(e: &Emitter, t: &Targets, i: usize, u: (f64, f64)) -> (Ray, Rgb) {
    let n_t = t.spheres.len();
    let aim = t.spheres[i % n_t];
    let (r, (cos_phi, sin_phi)) = concentric_disc(u);
    match *e {
        Emitter::Point {
            position,
            power: (color, intensity),
            ref cones,
        } => {
            let c = &cones[i % n_t];
            // The cap's area above a cosine is 2π(1 − cos): a disc's r²
            // spread over 1 − cos_max, area for area.
            let one_less = r * r * (1.0 - c.cos_max);
            let cos = 1.0 - one_less;
            let sin = (one_less * (2.0 - one_less)).max(0.0).sqrt();
            let (a, b) = c.basis;
            let dir = (c.axis * cos + (a * cos_phi + b * sin_phi) * sin.copysign(r)).normalize();
            // Photons per steradian along `dir`, summed over the targets.
            let density: f64 = cones
                .iter()
                .map(|s| {
                    let inside = s.cos_max <= -1.0 || dir.dot(s.toward) >= s.cos_max;
                    if inside { s.per_sr } else { 0.0 }
                })
                .sum();
            let power = color * (intensity / (4.0 * PI) / density.max(f64::MIN_POSITIVE));
            (Ray { origin: position, dir }, power)
        }
        Emitter::Directional {
            direction,
            power: (color, intensity),
            basis: (a, b),
            share,
        } => {
            let q = aim.0 + (a * cos_phi + b * sin_phi) * (r * aim.1);
            let back = (q - t.world.0).dot(direction).max(0.0) + t.world.1 + 1.0;
            let origin = q - direction * back;
            // Photons per unit area across the beam, summed over the discs.
            let density: f64 = t
                .spheres
                .iter()
                .map(|&(c, r)| {
                    let off = (q - c) - direction * (q - c).dot(direction);
                    if off.length_squared() <= r * r {
                        share / (PI * r * r)
                    } else {
                        0.0
                    }
                })
                .sum();
            let power = color * (intensity / density.max(f64::MIN_POSITIVE));
            (Ray { origin, dir: direction }, power)
        }
    }
}

/// One photon in flight, at wavelength `lambda` (µm): the ray it travels,
/// the power it carries, its own random numbers, the object it is leaving
/// (`usize::MAX`: none), the depth used and whether it has been bent or
/// mirrored yet.
struct Flight {
    ray: Ray,
    power: Rgb,
    lambda: f64,
    rng: Sampler,
    skip: usize,
    depth: u32,
    bounced: bool,
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
            out.push(Photon::new(s.p, ray.dir, self.power));
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

/// The wavelength photon `i` of a light is traced at and the factor on its
/// power: without dispersive glass the d line and all channels; with it,
/// one channel alone at that channel's wavelength (the camera's,
/// [`RGB_WAVELENGTHS_UM`]), three times as strong, channel `(i / t) mod 3`
/// for `t` targets (each target's photons cycle through the channels).
fn colour_of(scene: &Scene, i: usize, t: usize) -> (f64, Rgb) {
    if !scene.features.dispersion {
        return (WAVELENGTH_D_UM, Rgb::ONE);
    }
    let c = (i / t) % 3;
    let mut w = Rgb::ZERO;
    w[c] = 3.0;
    (RGB_WAVELENGTHS_UM[c], w)
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

/// The point in [0, 1)² that photon `j` of light `light` in pass `pass`
/// (from 1) is emitted at ([`emit`]), where each light shoots `per_light`
/// photons in `groups` groups ([`strata`]: photon `j` is of group
/// `j mod groups`). Each group's photons, pass after pass, are one
/// scrambled Sobol sequence ([`sobol_owen_2d`], keyed by the seed, the light
/// and the group): pass `p`'s are its points `(p − 1)·n` to `p·n − 1`
/// for `n` a pass, so that a pass's photons and all passes' together
/// spread evenly (a caustic's photon counts vary far less than with
/// independent points), and each photon alone is uniform. Indices wrap at
/// 2^32, past [`MAX_PHOTONS_TRACED`](crate::render::caustics::MAX_PHOTONS_TRACED).
fn emission_point(groups: usize, per_light: usize, (seed, pass): (u64, u32), (light, j): (usize, usize)) -> (f64, f64) {
    let (group, k) = (j % groups, j / groups);
    let n = (per_light / groups) as u64;
    let index = u64::from(pass.max(1) - 1) * n + k as u64;
    let key = mix64(seed ^ mix64((light as u64) << 32 | group as u64));
    sobol_owen_2d(index as u32, key)
}

/// The groups a light's photons fall in, by target and colour channel:
/// photon `j` aims at target `j mod T` and, with dispersive glass, carries
/// channel `(j / T) mod 3` ([`colour_of`]), so `j mod 3T` (`j mod T`
/// without dispersion) is its group.
fn strata(scene: &Scene, targets: &Targets) -> usize {
    let t = targets.spheres.len().max(1);
    if scene.features.dispersion { 3 * t } else { t }
}

/// The photons [`photon_pass`] shoots from each light when asked for
/// `per_light`: rounded up to a whole share for every target (and colour
/// channel, with dispersion), so at least one a target.
pub fn photons_per_light(scene: &Scene, targets: &Targets, per_light: usize) -> usize {
    let share = strata(scene, targets);
    per_light.max(1).div_ceil(share) * share
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A group's emission points, mapped onto the disc, fill 64 cells of
    /// equal area (8 rings by 8 sectors) far more evenly than independent
    /// points: one pass, and two passes together (the second continues
    /// the first's sequence). Squared deviations from the mean count,
    /// summed, against their expectation for independent points (the
    /// number of points); groups and lights get different points.
    #[test]
    fn emission_points_spread_evenly_pass_by_pass() {
        let (groups, per_light) = (3, 3 * 1024);
        let cell = |(x, y): (f64, f64)| {
            let ring = ((x * x + y * y) * 8.0).min(7.0) as usize;
            let sector = ((y.atan2(x) / std::f64::consts::TAU + 0.5) * 8.0).min(7.0) as usize;
            ring * 8 + sector
        };
        let spread = |points: &[(f64, f64)]| {
            let mut counts = [0.0f64; 64];
            points.iter().for_each(|&u| {
                let (r, (c, s)) = concentric_disc(u);
                counts[cell((r * c, r * s))] += 1.0
            });
            let mean = points.len() as f64 / 64.0;
            counts.iter().map(|c| (c - mean).powi(2)).sum::<f64>() / points.len() as f64
        };
        for (light, group) in [(0, 0), (0, 2), (1, 1)] {
            let pass = |p: u32| -> Vec<(f64, f64)> {
                (0..1024)
                    .map(|k| emission_point(groups, per_light, (9, p), (light, k * groups + group)))
                    .collect()
            };
            let (one, two) = (pass(1), pass(2));
            let both: Vec<_> = one.iter().chain(&two).copied().collect();
            for (what, pts) in [("pass 1", &one), ("pass 2", &two), ("both", &both)] {
                assert!(
                    spread(pts) < 0.2,
                    "{what}: {} of the independent points' 1",
                    spread(pts)
                );
            }
            assert_ne!(one[5], two[5]);
        }
        let mut rng = Sampler::new(1, 2, 3);
        let uniform: Vec<_> = (0..2048).map(|_| rng.next_2d()).collect();
        assert!(spread(&uniform) > 0.5, "{}", spread(&uniform));
        let first = |light, group| emission_point(groups, per_light, (9, 1), (light, group));
        assert_ne!(first(0, 0), first(0, 1));
        assert_ne!(first(0, 0), first(1, 0));
    }

    /// Every point of a tilted lens, a turned cuboid and a sphere lies in
    /// its target sphere, and some lie near its surface (the sphere is not
    /// loose): for the lens about half the solid angle of the sphere
    /// around its world box.
    #[test]
    fn target_spheres_hold_their_objects_tightly() {
        let text = r#"
[camera]
position = [0, 0, 10]
[[lights]]
type = "point"
position = [5, 10, 6]
intensity = 100
[[lenses]]
center = [0.3, 4.3, 6.9]
axis = [0, 0.48, 0.88]
d = 2
r1 = 5
r2 = 2.5
n = 1.5
[materials.glass]
transparency = 1.0
[[objects]]
type = "cuboid"
position = [3, 1, -2]
rotation = [20, 35, 10]
size = [1, 2, 0.5]
material = "glass"
[[objects]]
type = "sphere"
position = [-3, 1, 0]
radius = 0.7
material = "glass"
"#;
        let scene = Scene::parse("t.toml", text).unwrap().1;
        let t = Targets::of(&scene);
        assert_eq!(t.spheres.len(), 3);
        for (o, &(c, r)) in scene.objects.iter().zip(&t.spheres) {
            let b = o.world_bounds;
            let mut far: f64 = 0.0;
            let n = 60;
            for i in 0..=n {
                for j in 0..=n {
                    for k in 0..=n {
                        let f = DVec3::new(i as f64, j as f64, k as f64) / n as f64;
                        let p = b.min + (b.max - b.min) * f;
                        if o.shape.contains(o.object_from_world() * (p - o.position)) {
                            far = far.max((p - c).length());
                        }
                    }
                }
            }
            assert!(far <= r && far > 0.9 * r, "{}: farthest {far} vs {r}", o.name);
        }
        let i = scene.objects.iter().position(|o| o.lens().is_some()).unwrap();
        let b = scene.objects[i].world_bounds;
        let loose = (b.max - b.min).length() * 0.5;
        assert!(t.spheres[i].1 < 0.75 * loose, "{} vs {loose}", t.spheres[i].1);
    }

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
}
