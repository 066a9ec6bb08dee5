//! A lens *system*: surfaces along one axis, in the order the light meets
//! them (docs/lens-systems.md is the model, word for word).
//!
//! Each surface has a signed radius (optical convention, 0 = plane), the
//! axial thickness to the next, the medium after it and a clear
//! semi-aperture; one plane in air may be the stop. A *cell* is the space
//! between two surfaces; one filled with glass is an element, a solid of
//! revolution bounded by its two faces (spherical out to their apertures,
//! flat from there to its rim) and a cylindrical edge. Light passes the
//! surfaces travelling along `−axis`: the first surface faces `+axis`, as
//! the biconvex lens's S1 does.
//!
//! Everything is computed in the system's local frame (`z` along the light
//! from the first vertex), where each surface is in vertex form
//! `c(x² + y² + (z − z_k)²) − 2(z − z_k) = 0`: a plane is `c = 0`, a nearly
//! flat face loses nothing to cancellation. A ray is brought there from the
//! point on it nearest the first vertex, found in double-double arithmetic
//! far from the origin ([`crate::geometry::localize_near`]).
//!
//! Files: `pieces.rs` the boundary pieces and the nearest crossing,
//! `walk.rs` the real ray (`lens trace`) and the Whitted tree of a pass
//! (every ray out, Fresnel-weighted), `lanes.rs` the walk of `pass` for
//! eight rays at once (the lens camera's), `tree_lanes.rs` the tree for
//! eight scene rays at once (the packet kernel's), `paraxial.rs` the y–nu trace.

mod lanes;
mod paraxial;
mod pieces;
mod tree_lanes;
mod walk;

pub use lanes::Passed;
pub use paraxial::{Paraxial, Pupil};
pub use pieces::{Piece, PieceKind};
pub use tree_lanes::LaneTrees;
pub use walk::{Event, EventKind, RayStatus, RealRay, SystemBranch};

use super::{Aabb, Hit};
use crate::math::{Ray, domain, max_abs, rescale_pow2};
use crate::optics::Index;
use glam::DVec3;

/// Surfaces a system may have: part numbers are `3·k + kind` in a `u8`.
pub const MAX_SURFACES: usize = 64;

/// One surface as the user gives it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceSpec {
    /// Signed radius of curvature; 0 (or infinite) for a plane.
    pub radius: f64,
    /// Axial distance to the next surface (ignored on the last).
    pub thickness: f64,
    /// The medium after the surface; `Index::Constant(1.0)` is air.
    pub n: Index,
    /// Clear semi-diameter.
    pub semi_aperture: f64,
    /// The aperture stop (a plane with air on both sides).
    pub stop: bool,
}

impl SurfaceSpec {
    /// The surfaces of a prescription's rows (its aperture column a
    /// diameter), every length times `scale`.
    pub fn from_rows(rows: &[crate::prescription::PrescriptionRow], scale: f64) -> Vec<SurfaceSpec> {
        rows.iter()
            .map(|r| SurfaceSpec {
                radius: r.radius * scale,
                thickness: r.thickness * scale,
                n: r.n,
                semi_aperture: 0.5 * r.aperture_diameter * scale,
                stop: r.stop,
            })
            .collect()
    }

    /// The curvature `1/R`, 0 for a plane.
    pub fn curvature(&self) -> f64 {
        if self.radius == 0.0 || self.radius.is_infinite() {
            0.0
        } else {
            1.0 / self.radius
        }
    }
}

/// Why a system description is impossible: the surface (0-based, `None`
/// for the whole system) and its field.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct SystemError {
    pub surface: Option<usize>,
    pub field: &'static str,
    pub message: String,
}

fn err<T>(surface: Option<usize>, field: &'static str, message: String) -> Result<T, SystemError> {
    Err(SystemError {
        surface,
        field,
        message,
    })
}

/// Whether a medium is air (index exactly 1, no dispersion).
pub fn is_air(n: &Index) -> bool {
    matches!(n, Index::Constant(v) if *v == 1.0)
}

/// The sag `c r²/(1 + √(1 − c²r²))` of a surface of curvature `c` at
/// radius `r` (`c·r ≤ 1`).
#[inline(always)]
pub fn sag(c: f64, r: f64) -> f64 {
    let cr = c * r;
    c * r * r / (1.0 + ((1.0 - cr) * (1.0 + cr)).max(0.0).sqrt())
}

#[derive(Clone, Debug, PartialEq)]
pub struct LensSystem {
    /// Vertex of the first surface (world).
    pub vertex: DVec3,
    /// Unit axis; the first surface faces it, light travels along `−axis`.
    pub axis: DVec3,
    pub surfaces: Vec<SurfaceSpec>,
    /// World from local: columns `ex, ey, ez` with `ez = −axis`.
    frame: [DVec3; 3],
    /// Each surface's vertex `z_k` and curvature `c_k`.
    z: Vec<f64>,
    c: Vec<f64>,
    /// Each cell's rim radius (0 for air cells); cell `k` follows surface `k`.
    rim: Vec<f64>,
    /// Each surface's ring (or diaphragm) outer radius: no ring where it is
    /// not above the semi-aperture.
    ring_outer: Vec<f64>,
    /// What the nearest-crossing test reads of each surface, side by side
    /// ([`pieces::Face`]): its extent, its reach, the ring planes.
    faces: Vec<pieces::Face>,
    /// The largest radius of the system (apertures and rims).
    radius: f64,
    /// Square of 1.01 × the radius of a ball about `mid` holding the system.
    reject_radius2: f64,
    /// Centre of that ball, world (the middle of the axial length).
    mid: DVec3,
    /// Square of 10⁴ × the system's size: closer origins are localised in f64.
    fast_radius2: f64,
}

impl LensSystem {
    /// Checks a description (docs/lens-systems.md, "Validation") and
    /// builds the system.
    pub fn new(vertex: DVec3, axis: DVec3, surfaces: Vec<SurfaceSpec>) -> Result<Self, SystemError> {
        if !vertex.is_finite() {
            return err(None, "vertex", "vertex must be finite".into());
        }
        if let Some(why) = vertex.to_array().into_iter().find_map(domain::coordinate) {
            return err(None, "vertex", why);
        }
        let a = rescale_pow2(axis);
        let len = a.length();
        if !(len > 0.0 && len.is_finite()) {
            return err(None, "axis", "axis must be a non-zero finite vector".into());
        }
        let axis = a / len;
        check_surfaces(&surfaces, max_abs(vertex))?;
        let mut z = Vec::with_capacity(surfaces.len());
        let mut at = 0.0;
        for s in &surfaces {
            z.push(at);
            at += s.thickness;
        }
        let c: Vec<f64> = surfaces.iter().map(SurfaceSpec::curvature).collect();
        let rim = (0..surfaces.len())
            .map(|k| match surfaces.get(k + 1) {
                Some(next) if !is_air(&surfaces[k].n) => surfaces[k].semi_aperture.max(next.semi_aperture),
                _ => 0.0,
            })
            .collect::<Vec<f64>>();
        let radius = (surfaces.iter().map(|s| s.semi_aperture))
            .chain(rim.iter().copied())
            .fold(0.0, f64::max);
        let ring_outer = (0..surfaces.len())
            .map(|k| {
                if surfaces[k].stop {
                    radius
                } else {
                    let before = if k > 0 { rim[k - 1] } else { 0.0 };
                    before.max(rim[k])
                }
            })
            .collect();
        let ez = -axis;
        let (ex, ey) = ez.any_orthonormal_pair();
        let length = *z.last().unwrap_or(&0.0);
        let mid = vertex - axis * (0.5 * length);
        // Sags reach at most the radius from the vertex planes.
        let half = libm::hypot(0.5 * length + radius, radius);
        let size = length.max(radius);
        let sys = LensSystem {
            vertex,
            axis,
            surfaces,
            frame: [ex, ey, ez],
            z,
            c,
            rim,
            ring_outer,
            faces: Vec::new(),
            radius,
            reject_radius2: (1.01 * half).powi(2),
            mid,
            fast_radius2: (1e4 * size).powi(2),
        };
        sys.check_edges()?;
        let mut sys = sys;
        sys.faces = sys.faces_of_pieces();
        Ok(sys)
    }

    /// Number of surfaces.
    pub fn len(&self) -> usize {
        self.surfaces.len()
    }

    pub fn is_empty(&self) -> bool {
        self.surfaces.is_empty()
    }

    /// Axial length, first vertex to last.
    pub fn length(&self) -> f64 {
        *self.z.last().unwrap_or(&0.0)
    }

    /// The largest radius (apertures and rims).
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// Vertex `z` of surface `k` along the light from the first vertex.
    pub fn vertex_z(&self, k: usize) -> f64 {
        self.z[k]
    }

    /// The medium before surface `k` (air before the first).
    pub fn before(&self, k: usize) -> Index {
        if k == 0 {
            Index::Constant(1.0)
        } else {
            self.surfaces[k - 1].n
        }
    }

    /// Whether some medium's index depends on the wavelength.
    pub fn is_dispersive(&self) -> bool {
        self.surfaces.iter().any(|s| s.n.is_dispersive())
    }

    /// The first glass of the system (for the material shading reads).
    pub fn first_glass(&self) -> Index {
        let glass = self.surfaces.iter().map(|s| s.n).filter(|n| !is_air(n));
        let mut first = None;
        for n in glass {
            first.get_or_insert(n);
            if n.is_dispersive() {
                return n;
            }
        }
        first.unwrap_or(Index::Constant(1.0))
    }

    /// World point of a local one.
    #[inline(always)]
    pub fn world_point(&self, x: DVec3) -> DVec3 {
        self.vertex + self.world_dir(x)
    }

    /// World direction of a local one.
    #[inline(always)]
    pub fn world_dir(&self, u: DVec3) -> DVec3 {
        let [ex, ey, ez] = self.frame;
        ex * u.x + ey * u.y + ez * u.z
    }

    /// Local direction of a world one.
    #[inline(always)]
    pub fn local_dir(&self, u: DVec3) -> DVec3 {
        let [ex, ey, ez] = self.frame;
        DVec3::new(ex.dot(u), ey.dot(u), ez.dot(u))
    }

    /// A world ray in local coordinates: the point on it nearest the first
    /// vertex, its unit direction, and the `t` of that point along the
    /// given (unit) direction.
    #[inline]
    pub fn localize(&self, origin: DVec3, dir: DVec3) -> (DVec3, DVec3, f64) {
        let (rel, u, t0) = super::localize_near(self.vertex, origin, dir, self.fast_radius2);
        (self.local_dir(rel), self.local_dir(u), t0)
    }

    /// Bounds in world space (the shape's own space: a system is placed
    /// by its vertex and axis).
    pub fn bounds(&self) -> Aabb {
        let r = self.radius;
        let len = self.length();
        // The faces lie within r of their vertex planes.
        let mut lo = DVec3::INFINITY;
        let mut hi = DVec3::NEG_INFINITY;
        for z in [-r, len + r] {
            for (x, y) in [(-r, -r), (-r, r), (r, -r), (r, r)] {
                let p = self.world_point(DVec3::new(x, y, z));
                (lo, hi) = (lo.min(p), hi.max(p));
            }
        }
        Aabb::new(lo, hi)
    }

    /// Whether a world point lies inside a glass element.
    pub fn contains(&self, p: DVec3) -> bool {
        let x = self.local_dir(p - self.vertex);
        self.cell_at(x).is_some()
    }

    /// The glass cell holding the local point `x`, if any.
    pub fn cell_at(&self, x: DVec3) -> Option<usize> {
        let r = libm::hypot(x.x, x.y);
        (0..self.len())
            .find(|&k| self.rim[k] > 0.0 && r <= self.rim[k] && x.z >= self.front(k, r) && x.z <= self.back(k, r))
    }

    /// Front profile of cell `k` at radius `r`: surface `k`, flat beyond
    /// its aperture.
    pub fn front(&self, k: usize, r: f64) -> f64 {
        self.z[k] + sag(self.c[k], r.min(self.surfaces[k].semi_aperture))
    }

    /// Back profile of cell `k`: surface `k + 1`, flat beyond its aperture.
    pub fn back(&self, k: usize, r: f64) -> f64 {
        self.front(k + 1, r)
    }

    /// Closest crossing of the system's boundary in `(t_min, t_max)` for a
    /// world ray from outside; the part is the piece ([`Piece::part`]).
    pub fn intersect(&self, ray: &Ray, t_min: f64, t_max: f64) -> Option<Hit> {
        // The cheap rejection: a ray well clear of the ball holding it.
        let rel = ray.origin - self.mid;
        let along = rel.dot(ray.dir);
        if rel.length_squared() - along * along > self.reject_radius2 {
            return None;
        }
        let (p, u, t0) = self.localize(ray.origin, ray.dir);
        let c = self.next_crossing(p, u, None, t_min - t0, t_max - t0)?;
        Some(Hit {
            t: c.t + t0,
            part: c.piece.part(),
        })
    }

    /// Outward unit normal (world) at the world point `p` of part `part`.
    pub fn normal(&self, p: DVec3, part: u8) -> DVec3 {
        let x = self.local_dir(p - self.vertex);
        let piece = Piece::from_part(part);
        self.world_dir(self.outward_normal(piece, x))
    }
}

/// The per-surface checks that need no profile.
fn check_surfaces(s: &[SurfaceSpec], distance: f64) -> Result<(), SystemError> {
    if s.is_empty() {
        return err(None, "surfaces", "a lens system needs at least one surface".into());
    }
    if s.len() > MAX_SURFACES {
        return err(
            None,
            "surfaces",
            format!("{} surfaces: at most {MAX_SURFACES}", s.len()),
        );
    }
    let length = |k, field, what: &str, v: f64| match domain::length(v, distance) {
        Some(why) => err(Some(k), field, format!("{what} {why}")),
        None => Ok(()),
    };
    for (k, f) in s.iter().enumerate() {
        let a = f.semi_aperture;
        if !(a > 0.0 && a.is_finite()) {
            return err(
                Some(k),
                "semi_aperture",
                format!("semi-aperture {a} must be positive and finite"),
            );
        }
        length(k, "semi_aperture", "semi-aperture", a)?;
        if f.radius.is_nan() {
            return err(Some(k), "radius", "radius must be a number (0 for a plane)".into());
        }
        if f.curvature() != 0.0 {
            length(k, "radius", "radius", f.radius.abs())?;
            if f.radius.abs() < a {
                return err(
                    Some(k),
                    "radius",
                    format!(
                        "radius {} is smaller than the semi-aperture {a}: the sphere cannot span it",
                        f.radius
                    ),
                );
            }
        }
        if k + 1 < s.len() && !(f.thickness >= 0.0 && f.thickness <= domain::MAX_LENGTH) {
            return err(
                Some(k),
                "thickness",
                format!("thickness {} must be in [0, {:e}]", f.thickness, domain::MAX_LENGTH),
            );
        }
        check_index(k, &f.n)?;
        if f.stop && (f.curvature() != 0.0 || !is_air(&f.n) || (k > 0 && !is_air(&s[k - 1].n))) {
            return err(
                Some(k),
                "stop",
                "the stop must be a plane surface with air on both sides".into(),
            );
        }
    }
    if !is_air(&s[s.len() - 1].n) {
        return err(
            Some(s.len() - 1),
            "n",
            "the medium after the last surface must be air (n = 1)".into(),
        );
    }
    if s.iter().filter(|f| f.stop).count() > 1 {
        return err(None, "stop", "at most one surface is the stop".into());
    }
    Ok(())
}

/// The index of a medium: at least 1 and within the domain over the
/// visible range the renderer uses.
fn check_index(k: usize, n: &Index) -> Result<(), SystemError> {
    for lambda in [0.38, crate::optics::WAVELENGTH_D_UM, 0.78] {
        let v = n.at(lambda);
        if !(v >= 1.0 && v.is_finite()) {
            return err(Some(k), "n", format!("index {v} at {lambda} µm must be ≥ 1 and finite"));
        }
        if let Some(why) = domain::index(v) {
            return err(Some(k), "n", why);
        }
    }
    Ok(())
}

impl LensSystem {
    /// Edge thickness of every element and the gap between neighbours:
    /// the profiles must not cross. Between breakpoints (apertures, rims)
    /// each profile is a sag or a constant, and the difference of two is
    /// monotone (`s'(r) = c·r/√(1 − c²r²)` grows with `c`), so checking at
    /// the breakpoints is exact.
    fn check_edges(&self) -> Result<(), SystemError> {
        let n = self.len();
        for k in 0..n.saturating_sub(1) {
            let (a0, a1) = (self.surfaces[k].semi_aperture, self.surfaces[k + 1].semi_aperture);
            // The radius over which both profiles matter.
            let reach = if self.rim[k] > 0.0 {
                self.rim[k]
            } else {
                // An air gap: the faces (rings and the stop's diaphragm
                // included) meet only where both reach.
                self.ring_outer[k].max(a0).min(self.ring_outer[k + 1].max(a1))
            };
            for r in [0.0, a0, a1, reach] {
                if r > reach {
                    continue;
                }
                let (b, f) = (self.back(k, r), self.front(k, r));
                let gap = b - f;
                // A knife edge (a biconvex lens's rims meeting) may round
                // either way: a few rounding errors of the profiles.
                if gap < -8.0 * f64::EPSILON * (b.abs() + f.abs()) {
                    let what = if self.rim[k] > 0.0 { "edge thickness" } else { "air gap" };
                    return err(
                        Some(k),
                        "thickness",
                        format!(
                            "{what} {gap:.6e} at radius {r} between surfaces {k} and {}: the faces cross",
                            k + 1
                        ),
                    );
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests;
