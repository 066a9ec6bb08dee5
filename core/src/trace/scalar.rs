//! Scene queries for one ray: the closest hit ([`closest_hit`]), the
//! light that reaches along a shadow ray ([`transmittance`]), each also
//! without the object a ray is leaving (`*_skip`). Each walks the scene's
//! BVH when it has one, else tests every object's box; their packet twins
//! are in [`super::packet`].

use crate::color::Rgb;
use crate::geometry::Hit;
use crate::math::Ray;
use crate::scene::{Object, Scene};
use glam::DVec3;

/// The closest hit: object index and the shape's hit record. Walks the
/// scene's BVH when it has one, else tests every object's box.
#[inline]
pub fn closest_hit(scene: &Scene, ray: &Ray, t_max: f64) -> Option<(usize, Hit)> {
    closest_hit_skip(scene, ray, t_max, usize::MAX)
}

/// [`closest_hit`] without testing object `skip` (one the ray is leaving:
/// see `integrator::Surface::leaving`).
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
            t *= scene.shadow_filter(i);
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

/// The shading point data of the closest hit, for tools and tests.
pub fn hit_point<'a>(scene: &'a Scene, ray: &Ray) -> Option<(&'a Object, DVec3, DVec3)> {
    let (i, h) = closest_hit(scene, ray, f64::INFINITY)?;
    let o = &scene.objects[i];
    let p = ray.at(h.t);
    Some((o, p, o.world_normal(p, h.part)))
}
