//! The closed set of shapes, dispatched by `match`.
//!
//! A shape is geometry only, in its own object space (the lens, which is
//! defined by its centre and axis, lives in world space so that its exactness
//! does not depend on a matrix). Intersection is two-phase: [`Shape::intersect`]
//! returns the distance and which part was hit, and [`Shape::normal`] computes
//! surface data only for the closest hit.

mod aabb;
mod cuboid;
mod lens;
mod polytope;
mod prism;
mod pyramid;
mod sphere;
mod system;

pub use aabb::{Aabb, BOX_PAD, slab_hit, slab_overlap};
pub use cuboid::Cuboid;
pub(crate) use lens::LaneExits;
pub(crate) use lens::localize_near;
pub use lens::{
    ExitCrossing, FinePass, Inside, Lens, LensBranch, LensEntry, LensError, LensPath, LensSurface, LensTraceStatus,
    MAX_INTERNAL_REFLECTIONS, Pruning,
};
pub use prism::Prism;
pub use pyramid::Pyramid;
pub use sphere::Sphere;
pub use system::{
    Event, EventKind, LaneTrees, LensSystem, Paraxial, Passed, Piece, PieceKind, Pupil, RayStatus, RealRay,
    SurfaceSpec, SystemBranch, SystemError, is_air,
};

use crate::math::Ray;
use glam::DVec3;

/// The result of the cheap intersection phase: distance along the ray and an
/// index naming the face or cap that was hit (its meaning is per shape).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f64,
    pub part: u8,
}

/// Whether `t` lies in the open interval `(t_min, t_max)`.
#[inline(always)]
pub(crate) fn within(t: f64, t_min: f64, t_max: f64) -> bool {
    (t > t_min) & (t < t_max)
}

/// Which end of the span from `entry` to `exit` a ray meets on
/// `(t_min, t_max)`: `(entry, exit)` flags, both false for an empty span
/// (`entry > exit`). Written without branches, so that lane code can run
/// it side by side; [`first_crossing`] is its scalar form.
#[inline(always)]
pub(crate) fn crossing_choice(entry: f64, exit: f64, t_min: f64, t_max: f64) -> (bool, bool) {
    let ordered = !(entry > exit);
    (
        ordered & within(entry, t_min, t_max),
        ordered & within(exit, t_min, t_max),
    )
}

/// The hit of a convex solid met on the interval from entry `(t, part)` to
/// exit: the entry when it lies in `(t_min, t_max)`, else the exit (the ray
/// starts inside), else none. An empty interval (`entry > exit`) is a miss.
#[inline]
pub(crate) fn first_crossing(entry: (f64, u8), exit: (f64, u8), t_min: f64, t_max: f64) -> Option<Hit> {
    let (take_entry, take_exit) = crossing_choice(entry.0, exit.0, t_min, t_max);
    let (t, part) = if take_entry {
        entry
    } else if take_exit {
        exit
    } else {
        return None;
    };
    Some(Hit { t, part })
}

/// Hits of one object in `N` lanes (by [`Cuboid::intersect_lanes`]), flags
/// and faces in 64-bit lanes, the width of the distances, so that the
/// loops that pick among them stay in SIMD registers.
#[derive(Clone, Copy, Debug)]
pub(crate) struct WideHits<const N: usize> {
    /// 1 where the lane's ray hits within its interval, else 0.
    pub hit: [u64; N],
    pub t: [f64; N],
    pub part: [u64; N],
}

#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    Sphere(Sphere),
    Cuboid(Cuboid),
    Prism(Prism),
    Pyramid(Pyramid),
    /// Boxed: a lens is five times the size of the other shapes, and every
    /// object would pay for it (tests/memory.rs).
    Lens(Box<Lens>),
    /// A lens system: surfaces along one axis (`system/`).
    System(Box<LensSystem>),
}

impl Shape {
    /// The closest intersection with `t` in the open interval `(t_min, t_max)`.
    /// `ray.dir` must be unit length.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_min: f64, t_max: f64) -> Option<Hit> {
        match self {
            Shape::Sphere(s) => s.intersect(ray, t_min, t_max),
            Shape::Cuboid(s) => s.intersect(ray, t_min, t_max),
            Shape::Prism(s) => s.intersect(ray, t_min, t_max),
            Shape::Pyramid(s) => s.intersect(ray, t_min, t_max),
            Shape::Lens(s) => s.intersect(ray, t_min, t_max),
            Shape::System(s) => s.intersect(ray, t_min, t_max),
        }
    }

    /// Outward unit normal at a point `p` of part `part`.
    #[inline(always)]
    pub fn normal(&self, p: DVec3, part: u8) -> DVec3 {
        match self {
            Shape::Sphere(s) => s.normal(p),
            Shape::Cuboid(s) => s.normal(part),
            Shape::Prism(s) => s.normal(part),
            Shape::Pyramid(s) => s.normal(part),
            Shape::Lens(s) => s.normal(p, part),
            Shape::System(s) => s.normal(p, part),
        }
    }

    /// The number of faces of a shape bounded by planes only (its normal
    /// depends on the face, not the point), `None` for curved shapes.
    pub fn flat_faces(&self) -> Option<usize> {
        match self {
            Shape::Cuboid(_) => Some(6),
            Shape::Prism(_) | Shape::Pyramid(_) => Some(5),
            Shape::Sphere(_) | Shape::Lens(_) | Shape::System(_) => None,
        }
    }

    /// Bounds in the shape's own space.
    pub fn bounds(&self) -> Aabb {
        match self {
            Shape::Sphere(s) => s.bounds(),
            Shape::Cuboid(s) => s.bounds(),
            Shape::Prism(s) => s.bounds(),
            Shape::Pyramid(s) => s.bounds(),
            Shape::Lens(s) => s.bounds(),
            Shape::System(s) => s.bounds(),
        }
    }

    /// A characteristic size, used to scale the offset of spawned rays.
    pub fn scale(&self) -> f64 {
        let b = self.bounds();
        (b.max - b.min).max_element()
    }

    /// Whether `p` (shape space) lies inside the solid.
    pub fn contains(&self, p: DVec3) -> bool {
        match self {
            Shape::Sphere(s) => s.contains(p),
            Shape::Cuboid(s) => s.polytope().contains(p),
            Shape::Prism(s) => s.polytope().contains(p),
            Shape::Pyramid(s) => s.polytope().contains(p),
            Shape::Lens(s) => s.contains(p),
            Shape::System(s) => s.contains(p),
        }
    }

    pub fn kind_name(&self) -> &'static str {
        match self {
            Shape::Sphere(_) => "sphere",
            Shape::Cuboid(_) => "cuboid",
            Shape::Prism(_) => "prism",
            Shape::Pyramid(_) => "pyramid",
            Shape::Lens(_) => "lens",
            Shape::System(_) => "lens system",
        }
    }
}
