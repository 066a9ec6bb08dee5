//! Where caustic photons start: the targets worth a photon ([`Targets`]:
//! the bounding spheres of whatever bends or mirrors light), each light's
//! emitter toward them, worked out once a pass ([`Emitter`]), and each
//! photon's first ray, power and wavelength. Photons leave their light at
//! evenly spread points: each light's photons aimed at one target (and
//! colour channel) are one scrambled Sobol sequence, continued pass after
//! pass ([`emission_point`]), mapped onto the target's cone or disc area
//! for area ([`emit`]). Tracing them on is `photons.rs`'s.

use crate::color::Rgb;
use crate::geometry::Shape;
use crate::light::Light;
use crate::math::{Ray, orthonormal_basis};
use crate::optics::{RGB_WAVELENGTHS_UM, WAVELENGTH_D_UM};
use crate::sampling::{concentric_disc, mix64, sobol_owen_2d};
use crate::scene::{Object, Scene};
use glam::DVec3;
use std::f64::consts::PI;

/// The bounding spheres of the objects that can bend or mirror light: the
/// only directions worth a photon (one that meets none of them first lands
/// on a diffuse surface without a specular bounce, which direct light
/// already gives).
#[derive(Clone, Debug)]
pub struct Targets {
    pub(super) spheres: Vec<(DVec3, f64)>,
    /// Centre and radius of a sphere around every object (where a
    /// directional light's photons start from).
    pub(super) world: (DVec3, f64),
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
pub(super) enum Emitter {
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
/// half-angle (−1: the whole sphere), the unit vector toward its centre
/// (the cone's axis; +z where the light is at the centre, a whole sphere
/// whose axis only orients its basis), the basis about that axis (the
/// cone's directions are drawn in), and the photons per steradian its
/// share of a light's photons gives inside its cone.
pub(super) struct Cone {
    cos_max: f64,
    axis: DVec3,
    basis: (DVec3, DVec3),
    per_sr: f64,
}

impl Emitter {
    /// Each light's emitter for `t`, in the scene's order of lights, where
    /// each light shoots `per_light` photons (a whole share for every
    /// target, [`photons_per_light`]).
    pub(super) fn all(scene: &Scene, t: &Targets, per_light: usize) -> Vec<Emitter> {
        let share = (per_light / t.spheres.len().max(1)) as f64;
        let cone_of = |position: DVec3, s: (DVec3, f64)| {
            let (cos_max, omega) = cone(position, s);
            let axis = (s.0 - position).try_normalize().unwrap_or(DVec3::Z);
            Cone {
                cos_max,
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
pub(super) fn emit(e: &Emitter, t: &Targets, i: usize, u: (f64, f64)) -> (Ray, Rgb) {
    let n_t = t.spheres.len();
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
                    let inside = s.cos_max <= -1.0 || dir.dot(s.axis) >= s.cos_max;
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
            let aim = t.spheres[i % n_t];
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

/// The wavelength photon `i` of a light is traced at and the factor on its
/// power: without dispersive glass the d line and all channels; with it,
/// one channel alone at that channel's wavelength (the camera's,
/// [`RGB_WAVELENGTHS_UM`]), three times as strong, channel `(i / t) mod 3`
/// for `t` targets (each target's photons cycle through the channels).
pub(super) fn colour_of(scene: &Scene, i: usize, t: usize) -> (f64, Rgb) {
    if !scene.features.dispersion {
        return (WAVELENGTH_D_UM, Rgb::ONE);
    }
    let c = (i / t) % 3;
    let mut w = Rgb::ZERO;
    w[c] = 3.0;
    (RGB_WAVELENGTHS_UM[c], w)
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
pub(super) fn emission_point(
    groups: usize,
    per_light: usize,
    (seed, pass): (u64, u32),
    (light, j): (usize, usize),
) -> (f64, f64) {
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
pub(super) fn strata(scene: &Scene, targets: &Targets) -> usize {
    let t = targets.spheres.len().max(1);
    if scene.features.dispersion { 3 * t } else { t }
}

/// The photons [`photon_pass`](super::photon_pass) shoots from each light when asked for
/// `per_light`: rounded up to a whole share for every target (and colour
/// channel, with dispersion), so at least one a target.
pub fn photons_per_light(scene: &Scene, targets: &Targets, per_light: usize) -> usize {
    let share = strata(scene, targets);
    per_light.max(1).div_ceil(share) * share
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Sampler;

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
}
