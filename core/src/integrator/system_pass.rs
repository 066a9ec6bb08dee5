//! The pass through a lens system ([`system_rays`]): its Whitted tree,
//! each ray out spawned where it leaves the system.

use super::lens_pass::Transmitted;
use super::surface::spawn_ray;
use crate::geometry::{LensSystem, Pruning};
use crate::math::Ray;
use crate::scene::Object;

/// Every ray out of the lens system `sys` (object `obj`) for the ray `ray`
/// that meets it, at `lambda_um`: its Whitted tree
/// ([`LensSystem::branches`], the reflection where it enters included),
/// pruned by `prune`, each ray out handed to `emit` as it leaves the system
/// for good.
#[inline]
pub fn system_rays(
    obj: &Object,
    sys: &LensSystem,
    ray: &Ray,
    lambda_um: f64,
    prune: &Pruning,
    mut emit: impl FnMut(Transmitted),
) {
    sys.branches(ray.origin, ray.dir, lambda_um, prune, &mut |b| {
        emit(Transmitted {
            ray: spawn_ray(b.point, b.normal, b.dir, obj.scale),
            bounces: 2 + b.reflections,
            factor: b.weight,
        })
    });
}
