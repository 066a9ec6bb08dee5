//! Whitted radiance: ambient + Lambert diffuse + Phong specular for each
//! light, hard shadows, mirror reflection and Snell refraction with total
//! internal reflection, to a maximum depth.
//!
//! Light through a lens follows the lens's own exact tracer
//! ([`Lens::propagate_inside`]): the same code `lensview lens trace` reports.

use crate::color::Rgb;
use crate::geometry::{Hit, Lens, LensTraceStatus};
use crate::light::{Light, LightSample};
use crate::math::{Ray, surface_offset};
use crate::optics::{self, fresnel_dielectric};
use crate::scene::{Object, Scene};
use glam::DVec3;

/// Below this path weight a branch is not traced further.
const MIN_WEIGHT: f64 = 1e-4;

/// The closest hit: object index and the shape's hit record. Walks the
/// scene's BVH when it has one, else tests every object's box.
#[inline]
pub fn closest_hit(scene: &Scene, ray: &Ray, t_max: f64) -> Option<(usize, Hit)> {
    closest_hit_skip(scene, ray, t_max, usize::MAX)
}

/// [`closest_hit`] without testing object `skip` (one the ray is leaving:
/// see [`Surface::leaving`]).
#[inline]
pub fn closest_hit_skip(scene: &Scene, ray: &Ray, t_max: f64, skip: usize) -> Option<(usize, Hit)> {
    let mut best: Option<(usize, Hit)> = None;
    let mut test = |i: usize, t_max: f64| {
        if i == skip {
            return None;
        }
        let o = &scene.objects[i];
        o.shape.intersect(&o.to_object(ray), 0.0, t_max).map(|h| {
            best = Some((i, h));
            h.t
        })
    };
    match &scene.bvh {
        Some(bvh) => bvh.traverse(ray, t_max, |i, t_max| Ok(test(i as usize, t_max))),
        None => {
            let inv = ray.dir.recip();
            let mut t_max = t_max;
            for (i, o) in scene.objects.iter().enumerate() {
                if o.world_bounds.hit(ray, inv, 0.0, t_max)
                    && let Some(t) = test(i, t_max)
                {
                    t_max = t;
                }
            }
        }
    }
    best
}

/// Light that reaches from `p` to a light `dist` away along `dir`: zero
/// behind an opaque object (the search stops at the first), filtered by each
/// transparent object crossed.
pub fn transmittance(scene: &Scene, p: DVec3, dir: DVec3, dist: f64) -> Rgb {
    transmittance_skip(scene, &Ray { origin: p, dir }, dist, usize::MAX)
}

/// [`transmittance`] along `ray` without testing object `skip`.
pub fn transmittance_skip(scene: &Scene, ray: &Ray, dist: f64, skip: usize) -> Rgb {
    let mut t = Rgb::ONE;
    let mut test = |i: usize| {
        let o = &scene.objects[i];
        if i != skip && o.shape.intersect(&o.to_object(ray), 0.0, dist).is_some() {
            t *= o.material.shadow_transmittance();
        }
        t != Rgb::ZERO
    };
    match &scene.bvh {
        Some(bvh) => bvh.traverse(ray, dist, |i, _| if test(i as usize) { Ok(None) } else { Err(()) }),
        None => {
            let inv = ray.dir.recip();
            for (i, o) in scene.objects.iter().enumerate() {
                if o.world_bounds.hit(ray, inv, 0.0, dist) && !test(i) {
                    break;
                }
            }
        }
    }
    t
}

/// Where a ray leaves a surface: pushed off by a few rounding errors of the
/// point's coordinates, on the side it travels to.
#[inline]
pub fn spawn_ray(p: DVec3, normal: DVec3, dir: DVec3, scale: f64) -> Ray {
    let side = if dir.dot(normal) >= 0.0 { normal } else { -normal };
    Ray {
        origin: p + side * surface_offset(p, scale),
        dir,
    }
}

/// Radiance arriving along `ray` at wavelength `lambda_um` (used only by
/// dispersive glass), `depth` bounces deep.
///
/// The kernel is chosen once per call from the scene's [`Features`]: each
/// combination is its own monomorphised function, so a scene pays nothing for
/// what it does not use — no shadow rays, no refraction or mirror branch, no
/// specular term — not even a test per hit.
///
/// [`Features`]: crate::scene::Features
pub fn radiance(scene: &Scene, ray: &Ray, depth: u32, lambda_um: f64) -> Rgb {
    let f = scene.features;
    with_features!(f, kernel, (scene, ray, usize::MAX, depth, lambda_um, 1.0))
}

/// [`radiance`] of a camera ray whose closest hit is already known (from a
/// packet, [`crate::accel::packet`]), with the transmittance of its shadow
/// rays as `visibility(light, surface, sample)` gives it: the same value,
/// without walking the scene again.
pub fn radiance_from_hit(
    scene: &Scene,
    ray: &Ray,
    hit: Option<&Surface>,
    lambda_um: f64,
    visibility: &mut impl FnMut(usize, &Surface, &LightSample) -> Rgb,
) -> Rgb {
    let f = scene.features;
    with_features!(f, shade, (scene, ray, hit, 0, lambda_um, 1.0, visibility))
}

/// The kernel with every feature compiled in, deciding per hit from the
/// materials and settings (the same picture): what a renderer that does not
/// specialise would run. For benchmarks of the savings.
pub fn radiance_unspecialised(scene: &Scene, ray: &Ray, depth: u32, lambda_um: f64) -> Rgb {
    kernel::<true, true, true, true>(scene, ray, usize::MAX, depth, lambda_um, 1.0)
}

/// Calls `$f::<SHADOWS, GLASS, MIRROR, SPECULAR>$args` with the const
/// parameters read from a `Features` value.
macro_rules! with_features {
    ($feat:expr, $f:ident, $args:tt) => {
        with_features!(@ $f, $args, [], [$feat.shadows, $feat.glass, $feat.mirror, $feat.specular])
    };
    (@ $f:ident, $args:tt, [$($acc:tt)*], []) => { $f::<$($acc)*> $args };
    (@ $f:ident, $args:tt, [$($acc:tt)*], [$b:expr $(, $rest:expr)*]) => {
        if $b {
            with_features!(@ $f, $args, [$($acc)* true,], [$($rest),*])
        } else {
            with_features!(@ $f, $args, [$($acc)* false,], [$($rest),*])
        }
    };
}
use with_features;

fn kernel<const SHADOWS: bool, const GLASS: bool, const MIRROR: bool, const SPECULAR: bool>(
    scene: &Scene,
    ray: &Ray,
    skip: usize,
    depth: u32,
    lambda_um: f64,
    weight: f64,
) -> Rgb {
    let hit = closest_hit_skip(scene, ray, f64::INFINITY, skip);
    let hit = hit.map(|(i, h)| surface(scene, ray, i, h));
    shade::<SHADOWS, GLASS, MIRROR, SPECULAR>(scene, ray, hit.as_ref(), depth, lambda_um, weight, &mut |_, s, ls| {
        let (sr, dist) = shadow_ray(s, ls);
        transmittance_skip(scene, &sr, dist, s.leaving(ls.to_light))
    })
}

/// A hit with what shading needs of it.
#[derive(Clone, Copy, Debug)]
pub struct Surface<'a> {
    pub index: usize,
    pub object: &'a Object,
    pub p: DVec3,
    /// Outward unit normal.
    pub n: DVec3,
    /// The normal on the side the ray came from.
    pub nf: DVec3,
    /// Whether the ray arrived from outside the solid.
    pub entering: bool,
}

impl Surface<'_> {
    /// The object a ray leaving this point along `dir` cannot meet again,
    /// or `usize::MAX`. Every shape is convex, so a ray that starts on the
    /// surface and heads outward never returns to it: its test is skipped
    /// (it could only find the point itself, which the start offset is
    /// there to avoid).
    #[inline]
    pub fn leaving(&self, dir: DVec3) -> usize {
        if dir.dot(self.n) > 0.0 { self.index } else { usize::MAX }
    }
}

/// The shading data of hit `hit` of object `index` along `ray`.
#[inline]
pub fn surface<'a>(scene: &'a Scene, ray: &Ray, index: usize, hit: Hit) -> Surface<'a> {
    let object = &scene.objects[index];
    let p = ray.at(hit.t);
    let n = object.world_normal(p, hit.part);
    let entering = ray.dir.dot(n) < 0.0;
    Surface {
        index,
        object,
        p,
        n,
        nf: if entering { n } else { -n },
        entering,
    }
}

/// The light's sample at the surface when the light is on the side the ray
/// came from (`None` when it lights the other side).
#[inline]
pub fn light_at(s: &Surface, light: &Light) -> Option<LightSample> {
    let ls = light.sample(s.p);
    (s.nf.dot(ls.to_light) > 0.0).then_some(ls)
}

/// The shadow ray from the surface toward a light, and the distance to the
/// light along it.
#[inline]
pub fn shadow_ray(s: &Surface, ls: &LightSample) -> (Ray, f64) {
    let sr = spawn_ray(s.p, s.nf, ls.to_light, s.object.scale);
    let dist = if ls.distance.is_finite() {
        (ls.distance - (sr.origin - s.p).length()).max(0.0)
    } else {
        f64::INFINITY
    };
    (sr, dist)
}

/// The radiance along `ray` given its closest hit. `visibility(j, s, ls)`
/// is the transmittance of the shadow ray toward light `j` (asked only when
/// shadows are on and the light faces the surface): the scalar kernel walks
/// the scene for it, a packet has it ready.
#[inline(always)]
fn shade<const SHADOWS: bool, const GLASS: bool, const MIRROR: bool, const SPECULAR: bool>(
    scene: &Scene,
    ray: &Ray,
    hit: Option<&Surface>,
    depth: u32,
    lambda_um: f64,
    weight: f64,
    visibility: &mut impl FnMut(usize, &Surface, &LightSample) -> Rgb,
) -> Rgb {
    let Some(s) = hit else {
        return scene.background;
    };
    let (obj, p, nf, entering) = (s.object, s.p, s.nf, s.entering);
    let m = &obj.material;
    let scale = obj.scale;
    let view = -ray.dir;

    let mut color = Rgb::ZERO;
    let opacity = if GLASS { 1.0 - m.transparency } else { 1.0 };

    // Local Phong shading.
    color += m.color * scene.ambient * (m.ambient * opacity);
    for (j, light) in scene.lights.iter().enumerate() {
        let Some(ls) = light_at(s, light) else {
            continue;
        };
        let cos = nf.dot(ls.to_light);
        let mut e = ls.irradiance;
        if SHADOWS && scene.shadows {
            e *= visibility(j, s, &ls);
            if e == Rgb::ZERO {
                continue;
            }
        }
        color += m.color * e * (m.diffuse * opacity * cos);
        if SPECULAR && m.specular > 0.0 {
            let r = optics::reflect(-ls.to_light, nf);
            let rv = r.dot(view);
            if rv > 0.0 {
                color += e * (m.specular * rv.powf(m.shininess));
            }
        }
    }

    if !(GLASS || MIRROR) || depth >= scene.max_depth {
        return color;
    }

    let mut kr = if MIRROR { m.reflectivity } else { 0.0 };
    if GLASS && m.transparency > 0.0 {
        let ior = m.ior.at(lambda_um);
        let (n1, n2) = if entering { (1.0, ior) } else { (ior, 1.0) };
        let f = fresnel_dielectric(nf.dot(view), n1, n2);
        kr += m.transparency * f;
        let kt = m.transparency * (1.0 - f);
        if kt * weight > MIN_WEIGHT
            && let Some(tr) = transmitted_ray(obj, p, nf, entering, ray.dir, ior)
            && depth + tr.bounces <= scene.max_depth
        {
            let w = kt * tr.factor;
            // Out of a lens, or out of a solid: the ray has left the object.
            let skip = if tr.ray.dir.dot(s.n) > 0.0 || obj.lens().is_some() {
                s.index
            } else {
                usize::MAX
            };
            color += m.color
                * kernel::<SHADOWS, GLASS, MIRROR, SPECULAR>(
                    scene,
                    &tr.ray,
                    skip,
                    depth + tr.bounces,
                    lambda_um,
                    weight * w,
                )
                * w;
        }
    }
    if kr * weight > MIN_WEIGHT {
        let r = optics::reflect(ray.dir, nf);
        color += kernel::<SHADOWS, GLASS, MIRROR, SPECULAR>(
            scene,
            &spawn_ray(p, nf, r, scale),
            s.leaving(r),
            depth + 1,
            lambda_um,
            weight * kr,
        ) * kr;
    }
    color
}

/// The ray that carries on after refraction at a hit.
#[derive(Clone, Copy, Debug)]
pub struct Transmitted {
    /// The continuing ray: inside the glass for ordinary solids, already out
    /// of the exit face for a lens.
    pub ray: Ray,
    /// Depth it used: 1 for a refraction, 1 + internal reflections + 1 for a
    /// pass through a lens.
    pub bounces: u32,
    /// Extra transmission factor (the Fresnel loss at a lens's exit face).
    pub factor: f64,
}

/// Refraction at the hit point `p` of `obj` (normal `nf` facing the incoming
/// ray of direction `dir`, index `ior`). A ray entering a lens is carried
/// through it by the lens's exact tracer ([`Lens::propagate_inside`], the
/// code behind `lensview lens trace`); other solids return the ray inside.
/// `None` under total internal reflection, or when the lens traps the ray.
pub fn transmitted_ray(obj: &Object, p: DVec3, nf: DVec3, entering: bool, dir: DVec3, ior: f64) -> Option<Transmitted> {
    let (n1, n2) = if entering { (1.0, ior) } else { (ior, 1.0) };
    let t = optics::refract(dir, nf, n1, n2)?;
    match obj.lens() {
        Some(lens) if entering => through_lens(lens, p, t, ior),
        _ => Some(Transmitted {
            ray: spawn_ray(p, nf, t, obj.scale),
            bounces: 1,
            factor: 1.0,
        }),
    }
}

/// Follows a ray that has just refracted into `lens` at `p` to its exit.
fn through_lens(lens: &Lens, p: DVec3, inside: DVec3, ior: f64) -> Option<Transmitted> {
    let path = lens.propagate_inside(p, inside, ior);
    match (path.status, path.exit) {
        (LensTraceStatus::Transmitted, Some((s, y, out))) => {
            let n = lens.surface_normal(y, s);
            // Fresnel loss at the exit face, at the inside angle of incidence.
            let cos_out = out.dot(n).abs();
            let cos_in = (1.0 - (1.0 - cos_out * cos_out) / (ior * ior)).max(0.0).sqrt();
            Some(Transmitted {
                ray: spawn_ray(y, n, out, lens.d),
                bounces: 2 + path.internal_reflections,
                factor: 1.0 - fresnel_dielectric(cos_in, ior, 1.0),
            })
        }
        _ => None,
    }
}

/// The shading point data of the closest hit, for tools and tests.
pub fn hit_point<'a>(scene: &'a Scene, ray: &Ray) -> Option<(&'a Object, DVec3, DVec3)> {
    let (i, h) = closest_hit(scene, ray, f64::INFINITY)?;
    let o = &scene.objects[i];
    let p = ray.at(h.t);
    Some((o, p, o.world_normal(p, h.part)))
}
