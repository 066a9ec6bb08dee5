//! The shading steps both kernels run, the scalar one ray by ray and the
//! packet one lane by lane, in the same order with the same arithmetic:
//! [`ambient`], each light ([`light_at`], [`add_light`], with
//! [`light_matters`] deciding whether a packet traces its shadow ray)
//! and the rays sent on ([`shade_onward`], [`Secondary`]).

use super::Lit;
use super::lens_pass::Transmitted;
use super::surface::{Surface, spawn_ray};
use crate::color::Rgb;
use crate::geometry::{LensSystem, Pruning};
use crate::light::{Light, LightSample};
use crate::material::Material;
use crate::math::Ray;
use crate::optics;
use crate::scene::Scene;
use glam::DVec3;

/// Below this path weight (of the camera sample's 1) a reflected or
/// refracted ray is not traced further (inside a lens, [`LENS_MIN_WEIGHT`]).
pub const MIN_WEIGHT: f64 = 1e-4;

/// Below this weight (of the camera sample's 1) a ray out of a lens, or the
/// light reflected on inside it, is not followed: at most half an 8-bit
/// level of a pixel whose radiance is at most 1 (adaptive tree depth, Hall &
/// Greenberg 1983). At normal incidence on glass of index 1.5 this keeps
/// the ray through and the first ghost (weight ≈ 0.037) and drops the second
/// (≈ 0.0015).
pub const LENS_MIN_WEIGHT: f64 = 1.0 / 512.0;

/// In a lens system of more than one element, a ghost (light reflected a
/// second time or more) lighter than this plays Russian roulette
/// ([`Pruning`]'s `roulette`): kept with probability `w / GHOST_ROULETTE`
/// at the weight `GHOST_ROULETTE`. Measured on the uncoated double Gauss
/// (11 surfaces; `cargo run --release --example system_ghosts`): a ray
/// sends 9.8 ghosts out, and walking them took half the tree's time; with
/// the roulette 3.4 go out and the tree costs half. They carry 4.0 % of
/// the light against 2.3 % without it: a kept ghost is no longer pruned on
/// its way out, and the ghosts' whole share (weight bound 10⁻⁵) is 4.35 %.
pub const GHOST_ROULETTE: f64 = 1.0 / 64.0;

/// A ray that shading sends on (refracted or reflected), and how its
/// radiance `L` joins the colour: `colour += tint · L · factor`.
#[derive(Clone, Copy, Debug)]
pub struct Secondary {
    pub ray: Ray,
    /// The object the ray leaves ([`Surface::leaving`]), or `usize::MAX`.
    pub skip: usize,
    pub depth: u32,
    /// Path weight after this ray.
    pub weight: f64,
    pub tint: Option<Rgb>,
    pub factor: f64,
}

impl Secondary {
    /// Adds the radiance `l` that came back along the ray.
    #[inline]
    pub fn join(&self, color: &mut Rgb, l: Rgb) {
        join(color, self.tint, self.factor, l);
    }
}

/// How the radiance `l` a secondary ray brought back joins the colour:
/// `colour += tint · l · factor` (without a tint, `l · factor`).
#[inline(always)]
pub(super) fn join(color: &mut Rgb, tint: Option<Rgb>, factor: f64, l: Rgb) {
    *color += match tint {
        Some(t) => t * l * factor,
        None => l * factor,
    };
}

/// The light's sample at the surface when the light is on the side the ray
/// came from (`None` when it lights the other side).
#[inline]
pub fn light_at(s: &Surface, light: &Light) -> Option<LightSample> {
    let ls = light.sample(s.p);
    faces(s.nf, &ls).then_some(ls)
}

/// Whether the light of sample `ls` is on the side of the surface whose
/// normal (on the side the ray came from) is `nf`: [`light_at`]'s test.
#[inline(always)]
pub(super) fn faces(nf: DVec3, ls: &LightSample) -> bool {
    nf.dot(ls.to_light) > 0.0
}

/// `rv` to the power `shininess`: by repeated squaring for a whole
/// exponent (the usual case, within a few ulp of `powf` and several times
/// cheaper), by `powf` otherwise.
#[inline]
fn phong_lobe(rv: f64, shininess: f64) -> f64 {
    if shininess.fract() == 0.0 && shininess <= 4096.0 {
        rv.powi(shininess as i32)
    } else {
        libm::pow(rv, shininess)
    }
}

/// The share of the light a material `m` reflects diffusely: its `diffuse`
/// times its opacity (zero for clear glass).
#[inline(always)]
pub(super) fn diffuse_share<const GLASS: bool>(m: &Material) -> f64 {
    let opacity = if GLASS { 1.0 - m.transparency } else { 1.0 };
    m.diffuse * opacity
}

/// Whether the light of sample `ls` can change what shading adds at a
/// surface of normal `nf` (on the side the ray came from) for a ray along
/// `dir`: a diffuse term (`kd`, the [`diffuse_share`]: zero for clear glass)
/// or a specular one (`ks`, left out where `r·v` is at most the object's
/// [`crate::scene::Object::lobe_cos_min`], below which the lobe is under
/// [`crate::material::LOBE_FLOOR`] of its peak). Where neither is, the shadow
/// ray would not change a bit of the pixel, and a packet does not trace it
/// (the scalar kernel still does: the tests compare the two paths bit for
/// bit). The expressions are [`add_light`]'s own, on plain values
/// (`[kd, ks, lobe_cos_min]`) so that a packet runs it as a lane loop.
#[inline(always)]
pub(super) fn light_matters<const SPECULAR: bool>(
    [kd, ks, lobe_cos_min]: [f64; 3],
    nf: DVec3,
    ls: &LightSample,
    dir: DVec3,
) -> bool {
    let cos = nf.dot(ls.to_light);
    if kd * cos != 0.0 || !ls.irradiance.is_finite() {
        return true;
    }
    SPECULAR && ks > 0.0 && lobe_cos(nf, ls, dir) > lobe_cos_min
}

/// The ambient term at the surface, and the caustic photons' light there
/// when the scene has a photon map: where local shading starts.
#[inline(always)]
pub(super) fn ambient<const GLASS: bool>(scene: Lit, s: &Surface) -> Rgb {
    let m = &s.object.material;
    let mut color = ambient_light::<GLASS>(scene, m);
    let kd = diffuse_share::<GLASS>(m);
    if let Some(map) = scene.caustics
        && gathers_caustics(kd)
    {
        color += caustic_term(m.color, scene.counted(map.irradiance(s.p, s.nf)), kd);
    }
    color
}

/// Whether [`ambient`] gathers the caustic photons' light at a surface
/// whose [`diffuse_share`] is `kd`: not where it would be multiplied by
/// zero (clear glass).
#[inline(always)]
pub(super) fn gathers_caustics(kd: f64) -> bool {
    kd > 0.0
}

/// The caustic irradiance `e` lit like a light's on a surface of colour
/// `color` and [`diffuse_share`] `kd`: `kd·C·E`, in this order of
/// operations (the scalar and packet kernels both add it).
#[inline(always)]
pub(super) fn caustic_term(color: Rgb, e: Rgb, kd: f64) -> Rgb {
    color * e * kd
}

/// [`ambient`]'s first term, the ambient light on material `m`: all of
/// it where the scene has no caustic photons.
#[inline(always)]
pub(super) fn ambient_light<const GLASS: bool>(scene: Lit, m: &Material) -> Rgb {
    let opacity = if GLASS { 1.0 - m.transparency } else { 1.0 };
    let mut color = Rgb::ZERO;
    color += m.color * scene.ambient * (m.ambient * opacity);
    color
}

/// Whether shading at a surface of material `m` reads more of it than
/// its [`ambient_light`]: the scene has lights or caustic photons, or
/// [`shade_onward`] may send a ray on from it (glass, or a mirror whose
/// share of any weight can pass [`followed`]).
#[inline(always)]
pub(super) fn reads_surface<const GLASS: bool, const MIRROR: bool>(scene: Lit, m: &Material) -> bool {
    !scene.lights.is_empty()
        || scene.caustics.is_some()
        || (GLASS && m.transparency > 0.0)
        || (MIRROR && m.reflectivity != 0.0)
}

/// Adds the Lambert and Phong terms of one light's sample `ls` at the
/// surface, for a ray along `dir`, dimmed by the transmittance `visible` of
/// its shadow ray (ignored without shadows).
#[inline(always)]
pub(super) fn add_light<const SHADOWS: bool, const GLASS: bool, const SPECULAR: bool>(
    scene: &Scene,
    s: &Surface,
    dir: DVec3,
    ls: &LightSample,
    visible: Rgb,
    color: &mut Rgb,
) {
    let m = &s.object.material;
    let (e, arrives) = arriving(SHADOWS && scene.shadows, ls, visible);
    if !arrives {
        return;
    }
    *color += lambert(m.color, e, diffuse_share::<GLASS>(m), s.nf, ls);
    if SPECULAR && m.specular > 0.0 {
        let rv = lobe_cos(s.nf, ls, dir);
        if rv > s.object.lobe_cos_min {
            *color += phong(e, m.specular, rv, m.shininess);
        }
    }
}

/// The light of sample `ls` that arrives, dimmed by the transmittance
/// `visible` of its shadow ray when `shadows`, and whether any does
/// ([`add_light`] adds nothing where none does).
#[inline(always)]
pub(super) fn arriving(shadows: bool, ls: &LightSample, visible: Rgb) -> (Rgb, bool) {
    let mut e = ls.irradiance;
    if shadows {
        e *= visible;
        if e == Rgb::ZERO {
            return (e, false);
        }
    }
    (e, true)
}

/// The Lambert term of the light `e` arriving from sample `ls` at a
/// surface of colour `color`, diffuse share `kd` ([`diffuse_share`]) and
/// normal `nf`.
#[inline(always)]
pub(super) fn lambert(color: Rgb, e: Rgb, kd: f64, nf: DVec3, ls: &LightSample) -> Rgb {
    let cos = nf.dot(ls.to_light);
    color * e * (kd * cos)
}

/// `r·v`: the cosine between the light of sample `ls` mirrored in the
/// normal `nf` and the way back along `dir`, which the Phong lobe is of.
#[inline(always)]
pub(super) fn lobe_cos(nf: DVec3, ls: &LightSample, dir: DVec3) -> f64 {
    optics::reflect(-ls.to_light, nf).dot(-dir)
}

/// The Phong term of the light `e` for a specular coefficient `ks` and
/// lobe cosine `rv` ([`lobe_cos`]).
#[inline(always)]
pub(super) fn phong(e: Rgb, ks: f64, rv: f64, shininess: f64) -> Rgb {
    e * (ks * phong_lobe(rv, shininess))
}

/// How a kernel refracts at a surface for [`shade_onward`]: the scalar one
/// computes each crossing; a packet traces the first exits from a lens of
/// all its lanes together beforehand, the entry's reflectance with them.
/// Traits rather than closures ([`Refraction`], [`Tracer`]), so that each
/// kernel's steps are compiled into `shade_onward`.
pub(super) trait Refraction {
    /// [`optics::fresnel_at`]`(dir, nf, n1, n2)` at the surface for this ray.
    fn fresnel(&self, dir: DVec3, nf: DVec3, n1: f64, n2: f64) -> f64;
    /// [`super::transmitted_rays`] at the surface `s` for this ray (index
    /// `ior`): each ray that carries on, out of a lens every branch of its
    /// tree pruned by `prune`, handed to `emit` in order.
    fn transmit(&self, s: &Surface, ior: f64, prune: &Pruning, emit: impl FnMut(Transmitted));
    /// [`super::lens_pass::system_rays`] for this ray into the lens system
    /// of the surface `s`.
    fn through_system(
        &self,
        s: &Surface,
        sys: &LensSystem,
        lambda_um: f64,
        prune: &Pruning,
        emit: impl FnMut(Transmitted),
    );
}

/// How a kernel follows the rays [`shade_onward`] sends on: the scalar one
/// traces each at once, a packet gathers them to trace as packets after
/// the local shading of every lane (the additions come in the same order
/// either way).
pub(super) trait Tracer {
    /// Follows `sec` and adds what it brings to `color`.
    fn trace(&mut self, sec: Secondary, color: &mut Rgb);
}

/// The refracted and reflected rays at the surface for a ray along `dir`,
/// `depth` bounces deep with path weight `weight`, handed to `tracer`;
/// `refraction` gives the Fresnel reflectance and the rays that carry on
/// through the glass.
#[inline(always)]
#[allow(clippy::too_many_arguments)] // the ray's state at the surface, and the kernel's two steps
pub(super) fn shade_onward<const GLASS: bool, const MIRROR: bool>(
    scene: &Scene,
    dir: DVec3,
    s: &Surface,
    depth: u32,
    lambda_um: f64,
    weight: f64,
    refraction: &impl Refraction,
    tracer: &mut impl Tracer,
    color: &mut Rgb,
) {
    if depth >= scene.max_depth {
        return;
    }
    let m = &s.object.material;
    let mut kr = if MIRROR { m.reflectivity } else { 0.0 };
    if GLASS && m.transparency > 0.0 && s.object.system().is_some() {
        // A system's tree holds every reflection at its surfaces.
        if let Some((sys, prune)) = into_system(scene, s, depth, weight) {
            let kt = m.transparency;
            refraction.through_system(s, sys, lambda_um, &prune, |tr| {
                if let Some(sec) = refracted(scene, s, depth, weight, kt, tr) {
                    tracer.trace(sec, color);
                }
            });
        }
    } else if GLASS && m.transparency > 0.0 {
        let ior = s.object.ior().at(lambda_um);
        let (n1, n2) = if s.entering { (1.0, ior) } else { (ior, 1.0) };
        let (r, kt) = glass_shares::<MIRROR>(m, refraction.fresnel(dir, s.nf, n1, n2));
        kr = r;
        if followed(kt, weight) {
            let prune = lens_pruning(scene, depth, weight, kt);
            refraction.transmit(s, ior, &prune, |tr| {
                if let Some(sec) = refracted(scene, s, depth, weight, kt, tr) {
                    tracer.trace(sec, color);
                }
            });
        }
    }
    if followed(kr, weight) {
        tracer.trace(reflected(s, dir, depth, weight, kr), color);
    }
}

/// The lens system whose surface `s` is, and the pruning of its tree, where
/// shading follows the light into it (for a ray `depth` bounces deep with
/// path weight `weight`: transparent, within `max_depth`, its transmitted
/// share [`followed`]); `None` otherwise. [`shade_onward`] and the packet
/// kernel's trees walked beforehand (`system_pass::system_trees`) ask it.
#[inline(always)]
pub(super) fn into_system<'a>(
    scene: &Scene,
    s: &Surface<'a>,
    depth: u32,
    weight: f64,
) -> Option<(&'a LensSystem, Pruning)> {
    let kt = s.object.material.transparency;
    let sys = s.object.system()?;
    (kt > 0.0 && depth < scene.max_depth && followed(kt, weight)).then(|| (sys, lens_pruning(scene, depth, weight, kt)))
}

/// The shares of the light that glass of material `m` reflects (`kr`,
/// with a mirror's reflectivity) and transmits (`kt`) where the Fresnel
/// reflectance is `f`.
#[inline(always)]
pub(super) fn glass_shares<const MIRROR: bool>(m: &Material, f: f64) -> (f64, f64) {
    let kr = if MIRROR { m.reflectivity } else { 0.0 };
    (kr + m.transparency * f, m.transparency * (1.0 - f))
}

/// Whether a ray that carries the share `k` of a path of weight `weight`
/// is followed ([`MIN_WEIGHT`]).
#[inline(always)]
pub(super) fn followed(k: f64, weight: f64) -> bool {
    k * weight > MIN_WEIGHT
}

/// When a branch out of a lens is dropped, for light entering it `depth`
/// bounces deep with path weight `weight` of which the share `kt` goes in:
/// a ray out of a lens uses 2 + its reflections inside.
#[inline(always)]
pub(super) fn lens_pruning(scene: &Scene, depth: u32, weight: f64, kt: f64) -> Pruning {
    Pruning {
        scale: weight * kt,
        min: LENS_MIN_WEIGHT,
        max_reflections: scene.max_depth.saturating_sub(depth + 2),
        roulette: GHOST_ROULETTE,
    }
}

/// The ray `tr` that carries on through the surface `s` (transmitted share
/// `kt`) as shading sends it on; `None` past the scene's `max_depth`
/// ([`within_depth`], then [`carried_on`]).
#[inline(always)]
pub(super) fn refracted(
    scene: &Scene,
    s: &Surface,
    depth: u32,
    weight: f64,
    kt: f64,
    tr: Transmitted,
) -> Option<Secondary> {
    within_depth(scene, depth, tr.bounces).then(|| carried_on(s, depth, weight, kt, tr))
}

/// Whether a ray that uses `bounces` more than `depth` stays within the
/// scene's `max_depth`.
#[inline(always)]
pub(super) fn within_depth(scene: &Scene, depth: u32, bounces: u32) -> bool {
    depth + bounces <= scene.max_depth
}

/// [`refracted`] for a ray within the depth.
#[inline(always)]
pub(super) fn carried_on(s: &Surface, depth: u32, weight: f64, kt: f64, tr: Transmitted) -> Secondary {
    let w = kt * tr.factor;
    // Out of a lens, or out of a solid: the ray has left the object.
    let skip = if s.object.lens().is_some() || s.object.system().is_some() || s.outward(tr.ray.dir) {
        s.index
    } else {
        usize::MAX
    };
    Secondary {
        ray: tr.ray,
        skip,
        depth: depth + tr.bounces,
        weight: weight * w,
        tint: Some(s.object.material.color),
        factor: w,
    }
}

/// The mirror ray at the surface `s` for a ray along `dir` (reflected share
/// `kr`) as shading sends it on.
#[inline(always)]
pub(super) fn reflected(s: &Surface, dir: DVec3, depth: u32, weight: f64, kr: f64) -> Secondary {
    let r = optics::reflect(dir, s.nf);
    Secondary {
        ray: spawn_ray(s.p, s.nf, r, s.object.scale),
        skip: s.leaving(r),
        depth: depth + 1,
        weight: weight * kr,
        tint: None,
        factor: kr,
    }
}
