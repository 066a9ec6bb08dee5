//! A hit with what shading needs of it ([`Surface`]), and the one place
//! rays leave a surface ([`spawn_ray`], [`shadow_ray`]): pushed off by a
//! few rounding errors of the point's coordinates, on the side they travel
//! to.

use crate::geometry::Hit;
use crate::light::LightSample;
use crate::math::{Ray, surface_offset};
use crate::scene::{Object, Scene};
use glam::DVec3;

/// A hit with what shading needs of it.
#[derive(Clone, Copy, Debug)]
pub struct Surface<'a> {
    pub index: usize,
    pub object: &'a Object,
    pub p: DVec3,
    /// The unit normal on the side the ray came from: the outward normal
    /// when `entering`, else its opposite.
    pub nf: DVec3,
    /// Whether the ray arrived from outside the solid.
    pub entering: bool,
}

impl Surface<'_> {
    /// Whether `dir` points out of the solid: `dir · n > 0` for the outward
    /// normal `n`, evaluated as `±(dir · nf)` (negation is exact, so this is
    /// the same test to the bit).
    #[inline(always)]
    pub fn outward(&self, dir: DVec3) -> bool {
        outward(self.entering, self.nf, dir)
    }

    /// The object a ray leaving this point along `dir` cannot meet again,
    /// or `usize::MAX`. Every shape is convex, so a ray that starts on the
    /// surface and heads outward never returns to it: its test is skipped
    /// (it could only find the point itself, which the start offset is
    /// there to avoid).
    #[inline]
    pub fn leaving(&self, dir: DVec3) -> usize {
        if self.outward(dir) { self.index } else { usize::MAX }
    }
}

/// [`Surface::outward`] for a surface of normal `nf` reached from outside
/// (`entering`) or inside.
#[inline(always)]
pub(super) fn outward(entering: bool, nf: DVec3, dir: DVec3) -> bool {
    let d = dir.dot(nf);
    if entering { d > 0.0 } else { d < 0.0 }
}

/// The shading data of hit `hit` of object `index` along `ray`.
#[inline(always)]
pub fn surface<'a>(scene: &'a Scene, ray: &Ray, index: usize, hit: Hit) -> Surface<'a> {
    let object = &scene.objects[index];
    let p = ray.at(hit.t);
    let n = object.world_normal(p, hit.part);
    let entering = ray.dir.dot(n) < 0.0;
    Surface {
        index,
        object,
        p,
        nf: if entering { n } else { -n },
        entering,
    }
}

/// Where a ray leaves a surface: pushed off by a few rounding errors of the
/// point's coordinates, on the side it travels to.
#[inline]
pub fn spawn_ray(p: DVec3, normal: DVec3, dir: DVec3, scale: f64) -> Ray {
    spawn_ray_by(p, normal, dir, surface_offset(p, scale))
}

/// [`spawn_ray`] with the offset given.
#[inline(always)]
fn spawn_ray_by(p: DVec3, normal: DVec3, dir: DVec3, offset: f64) -> Ray {
    let side = if dir.dot(normal) >= 0.0 { normal } else { -normal };
    Ray {
        origin: p + side * offset,
        dir,
    }
}

/// The shadow ray from the surface toward a light, and the distance to the
/// light along it.
#[inline]
pub fn shadow_ray(s: &Surface, ls: &LightSample) -> (Ray, f64) {
    shadow_ray_from(s.p, s.nf, s.object.scale, ls)
}

/// [`shadow_ray`] from the point `p` with normal `nf` (on the side the ray
/// came from) of an object of scale `scale`.
#[inline(always)]
pub(super) fn shadow_ray_from(p: DVec3, nf: DVec3, scale: f64, ls: &LightSample) -> (Ray, f64) {
    let offset = surface_offset(p, scale);
    let sr = spawn_ray_by(p, nf, ls.to_light, offset);
    // The origin is `offset` from the surface along a unit normal.
    let dist = if ls.distance.is_finite() {
        (ls.distance - offset).max(0.0)
    } else {
        f64::INFINITY
    };
    (sr, dist)
}
