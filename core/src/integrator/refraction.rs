//! Refraction at a hit: the rays that carry on ([`transmitted_rays`]: for
//! the renderer, every ray out of a lens's Whitted tree), the one ray a
//! photon takes ([`transmitted_one`]: one ray out of the lens's chain,
//! drawn at each exit) and the principal ray ([`transmitted_ray`]), from
//! one refraction in ([`refracted_in`]).

use super::lens_pass::{Transmitted, out_of};
use super::surface::spawn_ray;
use crate::geometry::{Inside, Lens, Pruning};
use crate::math::Ray;
use crate::optics;
use crate::scene::Object;
use glam::DVec3;

/// Refraction at the hit point `p` of `obj` (normal `nf` facing the
/// incoming `ray`, index `ior`): each ray that carries on, handed to
/// `emit`. A ray entering a lens gives every ray out of the lens's Whitted
/// tree ([`Lens::branch_chain`], pruned by `prune`) from its entry in
/// lens-local coordinates ([`Lens::entry_of_hit`]: `lens trace`'s where `p`
/// is too coarse); other solids give the ray inside. Nothing under total
/// internal reflection.
///
/// The sink's type is known to the compiler, so that the kernels' sinks
/// are compiled in rather than called through a pointer (any closure, or
/// `&mut dyn FnMut`, fits).
#[inline(always)]
#[allow(clippy::too_many_arguments)] // one hit's data, the bound and the sink
pub fn transmitted_rays(
    obj: &Object,
    p: DVec3,
    nf: DVec3,
    entering: bool,
    ray: &Ray,
    ior: f64,
    prune: &Pruning,
    mut emit: impl FnMut(Transmitted),
) {
    match refracted_in(obj, p, nf, entering, ray, ior) {
        Some(Refracted::Lens(lens, start)) => {
            lens.branch_chain(start, ior, prune, &mut |b| emit(out_of(lens, &b)));
        }
        Some(Refracted::On(t)) => emit(t),
        None => {}
    }
}

/// Where the light refracted at a hit goes: into a lens (its chain starts
/// from the light just inside), or on as one ray (any other glass).
enum Refracted<'a> {
    Lens(&'a Lens, Inside),
    On(Transmitted),
}

/// The refraction at a hit of [`transmitted_rays`]: `None` when the light
/// is totally reflected.
#[inline(always)]
fn refracted_in<'a>(
    obj: &'a Object,
    p: DVec3,
    nf: DVec3,
    entering: bool,
    ray: &Ray,
    ior: f64,
) -> Option<Refracted<'a>> {
    let (n1, n2) = if entering { (1.0, ior) } else { (ior, 1.0) };
    let lens = obj.lens().filter(|_| entering);
    let entry = lens.map(|l| l.entry_of_hit(ray, p, nf));
    let (dir, normal) = entry.map_or((ray.dir, nf), |e| (e.dir, e.normal));
    let t = optics::refract(dir, normal, n1, n2)?;
    Some(match (lens, entry) {
        (Some(lens), Some(e)) => Refracted::Lens(
            lens,
            Inside {
                x: e.local,
                u: t,
                weight: 1.0,
                reflections: 0,
            },
        ),
        _ => Refracted::On(Transmitted {
            ray: spawn_ray(p, nf, t, obj.scale),
            bounces: 1,
            factor: 1.0,
        }),
    })
}

/// One ray out of the refraction at a hit, as a photon travels: through a
/// lens, one ray of its chain drawn by its weight ([`Lens::walk_chain`],
/// `draw()` uniform in [0, 1)), carrying the factor 1; through other glass
/// the one ray on. `None` when the light is totally reflected or lost.
pub fn transmitted_one(
    obj: &Object,
    p: DVec3,
    nf: DVec3,
    entering: bool,
    ray: &Ray,
    ior: f64,
    draw: impl FnMut() -> f64,
) -> Option<Transmitted> {
    match refracted_in(obj, p, nf, entering, ray, ior)? {
        Refracted::Lens(lens, start) => lens.walk_chain(start, ior, draw).map(|b| out_of(lens, &b)),
        Refracted::On(t) => Some(t),
    }
}

/// The first ray that carries on from [`transmitted_rays`], nothing
/// pruned: for a lens, its principal ray out (what `lens trace` reports).
pub fn transmitted_ray(obj: &Object, p: DVec3, nf: DVec3, entering: bool, ray: &Ray, ior: f64) -> Option<Transmitted> {
    let mut first = None;
    transmitted_rays(obj, p, nf, entering, ray, ior, &Pruning::NONE, &mut |t| {
        first.get_or_insert(t);
    });
    first
}
