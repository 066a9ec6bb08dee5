//! The kernel for one ray: its closest hit, then [`shade`], which follows
//! the refracted and reflected rays at once by calling the kernel again.
//! The packet kernel (`packet.rs`) runs the same steps over the lanes of a
//! packet.

use super::Lit;
use super::lens_pass::Transmitted;
use super::refraction::transmitted_rays;
use super::shade::{Refraction, Secondary, Tracer, add_light, ambient, light_at, shade_onward};
use super::surface::{Surface, shadow_ray, surface};
use super::system_pass::system_rays;
use crate::color::Rgb;
use crate::geometry::{LensSystem, Pruning};
use crate::light::LightSample;
use crate::math::Ray;
use crate::optics::fresnel_at;

use crate::trace::{closest_hit_skip, transmittance_skip};
use glam::DVec3;

pub(super) fn kernel<const SHADOWS: bool, const GLASS: bool, const MIRROR: bool, const SPECULAR: bool>(
    scene: Lit,
    ray: &Ray,
    skip: usize,
    depth: u32,
    lambda_um: f64,
    weight: f64,
) -> Rgb {
    let hit = closest_hit_skip(scene.scene, ray, f64::INFINITY, skip);
    let hit = hit.map(|(i, h)| surface(scene.scene, ray, i, h));
    shade::<SHADOWS, GLASS, MIRROR, SPECULAR>(scene, ray, hit.as_ref(), depth, lambda_um, weight)
}

/// Light `j`'s sample at the surface and, with shadows, the transmittance
/// of the shadow ray toward it, traced alone (one without shadows).
#[inline]
fn lit_by<const SHADOWS: bool>(scene: Lit, j: usize, s: &Surface) -> Option<(LightSample, Rgb)> {
    let ls = light_at(s, &scene.lights[j])?;
    if !(SHADOWS && scene.shadows) {
        return Some((ls, Rgb::ONE));
    }
    let (sr, dist) = shadow_ray(s, &ls);
    Some((ls, transmittance_skip(scene.scene, &sr, dist, s.leaving(ls.to_light))))
}

/// The radiance along `ray` given its closest hit, one ray alone: light
/// by light with a shadow ray each, then the refracted and reflected rays
/// traced at once. `packet_kernel` (`packet.rs`) runs the same three steps over a
/// packet.
#[inline(always)]
fn shade<const SHADOWS: bool, const GLASS: bool, const MIRROR: bool, const SPECULAR: bool>(
    scene: Lit,
    ray: &Ray,
    hit: Option<&Surface>,
    depth: u32,
    lambda_um: f64,
    weight: f64,
) -> Rgb {
    let Some(s) = hit else {
        return scene.background;
    };
    let mut color = ambient::<GLASS>(scene, s);
    for j in 0..scene.lights.len() {
        if let Some((ls, visible)) = lit_by::<SHADOWS>(scene, j, s) {
            add_light::<SHADOWS, GLASS, SPECULAR>(scene.scene, s, ray.dir, &ls, visible, &mut color);
        }
    }
    if GLASS || MIRROR {
        shade_onward::<GLASS, MIRROR>(
            scene.scene,
            ray.dir,
            s,
            depth,
            lambda_um,
            weight,
            &Alone(*ray),
            &mut AtOnce::<SHADOWS, GLASS, MIRROR, SPECULAR> { scene, lambda_um },
            &mut color,
        );
    }
    color
}

/// One ray's [`Refraction`]: each crossing computed at its surface, for a
/// ray held (a lens entry far from the world origin starts from its origin).
pub(super) struct Alone(pub(super) Ray);

impl Refraction for Alone {
    #[inline(always)]
    fn fresnel(&self, dir: DVec3, nf: DVec3, n1: f64, n2: f64) -> f64 {
        fresnel_at(dir, nf, n1, n2)
    }

    #[inline(always)]
    fn transmit(&self, s: &Surface, ior: f64, prune: &Pruning, emit: impl FnMut(Transmitted)) {
        transmitted_rays(s.object, s.p, s.nf, s.entering, &self.0, ior, prune, emit);
    }

    #[inline(always)]
    fn through_system(
        &self,
        s: &Surface,
        sys: &LensSystem,
        lambda_um: f64,
        prune: &Pruning,
        emit: impl FnMut(Transmitted),
    ) {
        system_rays(s.object, sys, &self.0, lambda_um, prune, emit);
    }
}

/// One ray's [`Tracer`]: each ray sent on traced at once by the kernel.
struct AtOnce<'a, const SHADOWS: bool, const GLASS: bool, const MIRROR: bool, const SPECULAR: bool> {
    scene: Lit<'a>,
    lambda_um: f64,
}

impl<const SHADOWS: bool, const GLASS: bool, const MIRROR: bool, const SPECULAR: bool> Tracer
    for AtOnce<'_, SHADOWS, GLASS, MIRROR, SPECULAR>
{
    #[inline(always)]
    fn trace(&mut self, sec: Secondary, color: &mut Rgb) {
        let back = kernel::<SHADOWS, GLASS, MIRROR, SPECULAR>(
            self.scene,
            &sec.ray,
            sec.skip,
            sec.depth,
            self.lambda_um,
            sec.weight,
        );
        sec.join(color, back);
    }
}
