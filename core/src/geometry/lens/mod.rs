//! The thick biconvex lens: the intersection of two balls (DESIGN.md §2).
//!
//! A lens has centre `C`, unit axis `a`, diameter `d`, radii `r1, r2 ≥ d/2`
//! and an index. Face S1 faces `+a`: its sphere centre is `C − a·√(r1² − (d/2)²)`
//! and its vertex `V1 = C + a·sag1`. Face S2 faces `−a`: centre
//! `C + a·√(r2² − (d/2)²)`, vertex `V2 = C − a·sag2`. The rims meet in the
//! plane through `C`.
//!
//! Each face is handled in *vertex form*: for a cap with vertex `V`, outward
//! vertex normal `m` and radius `r`, the sphere is
//! `f(x) = |x − V|² + 2r·(x − V)·m = 0` (inside the ball when `f < 0`). With
//! `x = p + t·u` this is `t² + 2Bt + C = 0`, `B = (p−V)·u + r·(u·m)`,
//! `C = |p−V|² + 2r·(p−V)·m`. Every term is computed from differences of
//! points near the lens, so a nearly flat face (r = 10⁷·d) loses nothing to
//! cancellation, and the roots come from the stable quadratic. The ray origin
//! is first moved to the point nearest `C`, so a tiny lens far from the
//! origin is solved in its own scale.
//!
//! All of this happens in *lens-local* coordinates, `x − C`. A ray's start
//! is brought there by [`Lens::localize`]: the point of the ray nearest `C`,
//! computed in double-double arithmetic from the direction exactly as given.
//! World coordinates 10⁴ from the origin are spaced 2·10⁻¹² apart; a hit
//! point rounded to them would tilt the normal of a 10⁻³ lens by 10⁻⁹, and
//! so would normalising the direction before finding that point. Local
//! points are added back to `C` only for output. The renderer enters the
//! glass through the same step ([`Lens::entry_of_hit`]): from its world hit
//! point only where world coordinates are fine enough, else from the ray.
//!
//! The solid is convex, so a ray meets it on one interval: entry at the larger
//! of the two near roots, exit at the smaller of the two far roots. Inside the
//! glass only the far roots are used, which needs no epsilon: a ray starting
//! on a face going inward has its near root at ≈0 on that face and the far
//! roots ahead.
//!
//! Files by responsibility: `cap.rs` holds one face and the roots of both
//! faces along a ray, `branches.rs` the Whitted tree of a pass (every ray
//! out, weighted by Fresnel), `dd.rs` the double-double arithmetic of
//! [`Lens::localize`], `fine.rs` a pass with its deviation kept apart
//! ([`Lens::trace_fine`], for foci as n → 1), `trace.rs` the scalar tracer inside the glass
//! ([`Lens::trace`], [`Lens::propagate_inside`]), and `lanes.rs` the same
//! hit test and exit for a packet's lanes at once. The hit test, the tracer
//! and the lanes call the same `#[inline(always)]` steps (`span`,
//! `near_point`, `Lens::pick`, `Lens::exit_step`), so each lane gets the
//! scalar answer bit for bit.

mod branches;
mod cap;
mod dd;
mod fine;
mod lanes;
mod trace;

pub use branches::{Inside, LensBranch, Pruning};
pub use fine::FinePass;
pub(crate) use lanes::LaneExits;
pub use trace::{ExitCrossing, LensEntry, LensPath, LensTraceStatus, MAX_INTERNAL_REFLECTIONS};

use super::{Aabb, Hit, within};
use crate::math::{Ray, domain, max_abs, rescale_pow2};
use crate::optics::{self, Index, ThickLens};
use cap::{Cap, Span, span};
use glam::DVec3;

/// Why a lens description is impossible.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LensError {
    #[error("diameter d must be positive and finite, got {0}")]
    Diameter(f64),
    #[error("radius {name} = {r} is smaller than d/2 = {half}: the sphere cannot span the aperture")]
    Radius { name: &'static str, r: f64, half: f64 },
    #[error("index {0} must be ≥ 1 and finite")]
    Index(f64),
    #[error("axis must be a non-zero finite vector")]
    Axis,
    #[error("centre must be finite")]
    Centre,
    /// Outside the supported domain ([`crate::math::domain`]).
    #[error("{why}")]
    Domain { field: &'static str, why: String },
}

impl LensError {
    /// The key of the lens description at fault: `center`, `axis`, `d`,
    /// `r1`, `r2` or `n`.
    pub fn field(&self) -> &'static str {
        match self {
            LensError::Diameter(_) => "d",
            LensError::Radius { name, .. } => name,
            LensError::Index(_) => "n",
            LensError::Axis => "axis",
            LensError::Centre => "center",
            LensError::Domain { field, .. } => field,
        }
    }
}

/// Which face: S1 faces +axis, S2 faces −axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LensSurface {
    S1,
    S2,
}

impl LensSurface {
    pub fn name(self) -> &'static str {
        match self {
            LensSurface::S1 => "S1",
            LensSurface::S2 => "S2",
        }
    }
    pub(crate) fn from_part(part: u8) -> Self {
        if part == 0 { LensSurface::S1 } else { LensSurface::S2 }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Lens {
    pub center: DVec3,
    pub axis: DVec3,
    pub d: f64,
    pub r1: f64,
    pub r2: f64,
    pub index: Index,
    /// Caps in lens-local coordinates (relative to `center`).
    caps: [Cap; 2],
    /// Both faces are hemispheres of one sphere (a ball lens): the two caps'
    /// roots tie, and a crossing is named by its side of the rim plane.
    one_sphere: bool,
    /// Square of 1.01 × the radius of a sphere about `center` holding the lens.
    reject_radius2: f64,
    /// Square of 10⁴·d: closer origins take [`Lens::localize`]'s fast path.
    fast_radius2: f64,
    /// 10⁴·d when the centre's coordinates are at most that, else −1: a
    /// ray whose origin's coordinates are at most this finds its entry
    /// point well enough in world coordinates ([`Lens::entry_of_hit`]).
    world_exact: f64,
}

impl Lens {
    /// A validated lens inside the supported domain ([`domain`]): centre
    /// coordinates, diameter and radii, and index. `axis` need not be unit.
    pub fn new(center: DVec3, axis: DVec3, d: f64, r1: f64, r2: f64, index: Index) -> Result<Self, LensError> {
        let outside = |field, why: Option<String>| why.map_or(Ok(()), |why| Err(LensError::Domain { field, why }));
        if !center.is_finite() {
            return Err(LensError::Centre);
        }
        for x in center.to_array() {
            outside("center", domain::coordinate(x))?;
        }
        if !(d > 0.0 && d.is_finite()) {
            return Err(LensError::Diameter(d));
        }
        outside("d", domain::length(d, max_abs(center)).map(|w| format!("diameter {w}")))?;
        let half = 0.5 * d;
        for (name, r) in [("r1", r1), ("r2", r2)] {
            if !(r >= half && r.is_finite()) {
                return Err(LensError::Radius { name, r, half });
            }
            if r > domain::MAX_LENGTH {
                let why = format!("radius {name} = {r:e} is above the supported {:e}", domain::MAX_LENGTH);
                return Err(LensError::Domain { field: name, why });
            }
        }
        let check_n = |n: f64| {
            if !(n >= 1.0 && n.is_finite()) {
                Err(LensError::Index(n))
            } else {
                outside("n", domain::index(n))
            }
        };
        match index {
            Index::Constant(n) => check_n(n)?,
            Index::Cauchy { .. } | Index::Glass(_) => {
                // Must be physical over the visible range used for rendering.
                check_n(index.at(0.38))?;
                check_n(index.at(0.78))?;
                check_n(index.nominal())?;
            }
        }
        // Scaled first: [1e200, 0, 1e201] squares to ∞.
        let axis = rescale_pow2(axis);
        let len = axis.length();
        if !(len > 0.0 && len.is_finite()) {
            return Err(LensError::Axis);
        }
        let a = axis / len;
        let sag1 = optics::sagitta(r1, half);
        let sag2 = optics::sagitta(r2, half);
        Ok(Lens {
            center,
            axis: a,
            d,
            r1,
            r2,
            index,
            caps: [
                Cap {
                    vertex: a * sag1,
                    m: a,
                    r: r1,
                    inv_r: 1.0 / r1,
                },
                Cap {
                    vertex: -a * sag2,
                    m: -a,
                    r: r2,
                    inv_r: 1.0 / r2,
                },
            ],
            one_sphere: r1 == half && r2 == half,
            reject_radius2: (1.01 * 1.01) * (half * half + sag1.max(sag2).powi(2)),
            fast_radius2: (1e4 * d) * (1e4 * d),
            world_exact: if max_abs(center) <= 1e4 * d { 1e4 * d } else { -1.0 },
        })
    }

    /// Sphere centre of face S1 or S2 (DESIGN.md §2).
    pub fn sphere_centre(&self, s: LensSurface) -> DVec3 {
        let half = 0.5 * self.d;
        match s {
            LensSurface::S1 => self.center - self.axis * optics::centre_offset(self.r1, half),
            LensSurface::S2 => self.center + self.axis * optics::centre_offset(self.r2, half),
        }
    }

    pub fn vertex(&self, s: LensSurface) -> DVec3 {
        self.center + self.caps[s as usize].vertex
    }

    /// Paraxial data at index `n`.
    pub fn paraxial(&self, n: f64) -> ThickLens {
        ThickLens::new(self.d, self.r1, self.r2, n)
    }

    /// The point of the ray `origin + s·dir` nearest the centre, in lens-local
    /// coordinates, with the unit direction and the distance `t0` from
    /// `origin` to that point. `(origin − C) − ((origin − C)·dir / dir·dir)·dir`
    /// is evaluated in double-double from `dir` as given, so the ray found is
    /// the input ray to well below a rounding of world coordinates.
    ///
    /// When the origin is within 10⁴·d of the centre, plain `f64` is exact
    /// enough — the start point's error, ε·|origin − C| ≤ 2.2·10⁻¹²·d, tilts
    /// the normal by at most 4.4·10⁻¹², far inside the 10⁻⁹ budget — and
    /// this fast path is taken.
    #[inline]
    pub fn localize(&self, origin: DVec3, dir: DVec3) -> (DVec3, DVec3, f64) {
        localize_near(self.center, origin, dir, self.fast_radius2)
    }

    /// Whether a ray from `rel` (relative to the centre, `rel2 = |rel|²`)
    /// whose unit direction has `along = rel·dir` passes well clear of the
    /// lens's bounding sphere: the cheap rejection before the exact start
    /// point (a 1% margin is far above any rounding here).
    #[inline(always)]
    fn clear_of(&self, rel2: f64, along: f64) -> bool {
        rel2 - along * along > self.reject_radius2
    }

    /// The face a local point `x` lies on, given the face the roots chose:
    /// a ball lens names it by the side of the rim plane.
    #[inline(always)]
    fn face(&self, x: DVec3, by_roots: usize) -> usize {
        // Both sides computed, then one picked: a branch here keeps the
        // lane loops from running in SIMD registers.
        let rim_side = if x.dot(self.axis) >= 0.0 { 0 } else { 1 };
        if self.one_sphere { rim_side } else { by_roots }
    }

    /// The crossing a ray from the local point `p` along the unit `u` (its
    /// origin `t0` before `p`) meets on `(t_min, t_max)` over the span `sp`:
    /// whether it meets one, and the hit (not a number to use without).
    /// No branch: lanes run it side by side.
    #[inline(always)]
    fn pick(&self, sp: &Span, p: DVec3, u: DVec3, t0: f64, t_min: f64, t_max: f64) -> (bool, Hit) {
        let (e, x) = (sp.t_in + t0, sp.t_out + t0);
        let (take_e, take_x) = (within(e, t_min, t_max), within(x, t_min, t_max));
        let (ts, face) = if take_e {
            (sp.t_in, sp.face_in)
        } else {
            (sp.t_out, sp.face_out)
        };
        let hit = Hit {
            t: if take_e { e } else { x },
            part: self.face(p + ts * u, face) as u8,
        };
        (sp.real & !(sp.t_in >= sp.t_out) & (take_e | take_x), hit)
    }

    /// Closest crossing of the lens surface in `(t_min, t_max)`; part 0 is S1,
    /// part 1 is S2. `ray.dir` must be unit.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_min: f64, t_max: f64) -> Option<Hit> {
        let rel = ray.origin - self.center;
        if self.clear_of(rel.length_squared(), rel.dot(ray.dir)) {
            return None;
        }
        let (p, u, t0) = self.localize(ray.origin, ray.dir);
        let (met, hit) = self.pick(&span(&self.caps, p, u), p, u, t0, t_min, t_max);
        met.then_some(hit)
    }

    /// Outward unit normal of face `part` at the world point `p`.
    #[inline]
    pub fn normal(&self, p: DVec3, part: u8) -> DVec3 {
        self.caps[part as usize & 1].normal(p - self.center)
    }

    pub fn contains(&self, p: DVec3) -> bool {
        let x = p - self.center;
        self.caps[0].f(x) <= 0.0 && self.caps[1].f(x) <= 0.0
    }

    /// A box around the cylinder of radius d/2 from V2 to V1, which holds
    /// the lens: the box of its end discs, the disc of radius d/2 about each
    /// vertex across the axis (reaching `rim` along each coordinate). The
    /// rim circle and the vertices alone are not enough: a face bulges past
    /// both where the axis is oblique (a ball lens by up to 20% of d).
    pub fn bounds(&self) -> Aabb {
        let a = self.axis;
        // √ per axis (IEEE's, the same bits everywhere; `powf(0.5)` was the
        // platform's `pow`).
        let s = (DVec3::ONE - a * a).max(DVec3::ZERO);
        let rim = 0.5 * self.d * DVec3::new(s.x.sqrt(), s.y.sqrt(), s.z.sqrt());
        let (p, q) = (self.vertex(LensSurface::S1), self.vertex(LensSurface::S2));
        Aabb::new(p.min(q) - rim, p.max(q) + rim)
    }
}

/// [`Lens::localize`]'s fast path: the point of the ray from `rel`
/// (relative to the centre) along `dir` (`along = rel·dir`) nearest the
/// centre, the unit direction, and the distance `t0` to that point.
#[inline(always)]
fn near_point(rel: DVec3, along: f64, dir: DVec3) -> (DVec3, DVec3, f64) {
    let vv = dir.length_squared();
    let k = along / vv;
    let len = vv.sqrt();
    (rel - k * dir, dir / len, -k * len)
}

/// The point of the ray `origin + s·dir` nearest `center`, relative to
/// `center`, with the unit direction and the `s` of that point along it:
/// [`Lens::localize`] for any solid placed by a point (the lens, a lens
/// system). Within `fast_radius2` of `center` in plain `f64`; farther, in
/// double-double arithmetic from the direction exactly as given.
#[inline]
pub(crate) fn localize_near(center: DVec3, origin: DVec3, dir: DVec3, fast_radius2: f64) -> (DVec3, DVec3, f64) {
    let rel = origin - center;
    if rel.length_squared() <= fast_radius2 {
        return near_point(rel, rel.dot(dir), dir);
    }
    let o = [origin.x, origin.y, origin.z];
    let c = [center.x, center.y, center.z];
    let v = [dir.x, dir.y, dir.z];
    let rel = [0, 1, 2].map(|i| dd::Dd::two_sum(o[i], -c[i]));
    let mut dot = dd::Dd(0.0, 0.0);
    let mut vv = dd::Dd(0.0, 0.0);
    for i in 0..3 {
        dot = dot.add(rel[i].mul_f(v[i]));
        vv = vv.add(dd::Dd::two_prod(v[i], v[i]));
    }
    let k = dot.div(vv);
    let p = [0, 1, 2].map(|i| rel[i].add(k.mul_f(-v[i])).value());
    let len = vv.value().sqrt();
    (DVec3::from(p), dir / len, -k.value() * len)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn rejects_impossible_lenses() {
        assert!(matches!(
            Lens::new(DVec3::ZERO, DVec3::Z, 2.0, 0.99, 5.0, Index::Constant(1.5)),
            Err(LensError::Radius { name: "r1", .. })
        ));
        assert!(Lens::new(DVec3::ZERO, DVec3::Z, 0.0, 5.0, 5.0, Index::Constant(1.5)).is_err());
        assert!(Lens::new(DVec3::ZERO, DVec3::Z, 2.0, 5.0, 5.0, Index::Constant(0.9)).is_err());
        assert!(Lens::new(DVec3::ZERO, DVec3::ZERO, 2.0, 5.0, 5.0, Index::Constant(1.5)).is_err());
        assert!(Lens::new(DVec3::ZERO, DVec3::Z, f64::NAN, 5.0, 5.0, Index::Constant(1.5)).is_err());
        assert!(Lens::new(DVec3::ZERO, DVec3::Z, 2.0, f64::INFINITY, 5.0, Index::Constant(1.5)).is_err());
    }

    /// Every point of both faces lies in the box, for oblique lenses of
    /// every shape: a ball, a strongly curved one (`scenes/rim-lens.toml`),
    /// an ordinary and a meniscus-like one.
    #[test]
    fn the_box_holds_both_faces() {
        let axis = DVec3::new(0.5, 0.2, 0.77);
        for (d, r1, r2) in [(2.0, 1.0, 1.0), (2.4, 1.45, 1.45), (2.0, 5.0, 3.0), (2.0, 1.0, 30.0)] {
            let l = Lens::new(DVec3::new(0.0, 0.2, 2.2), axis, d, r1, r2, Index::Constant(1.5)).unwrap();
            let b = l.bounds();
            let (u, v) = crate::math::orthonormal_basis(l.axis);
            for i in 0..=40 {
                let rho = 0.5 * d * f64::from(i) / 40.0;
                for k in 0..64 {
                    let phi = std::f64::consts::TAU * f64::from(k) / 64.0;
                    let radial = rho * (u * phi.cos() + v * phi.sin());
                    for (s, r, side) in [(LensSurface::S1, r1, 1.0), (LensSurface::S2, r2, -1.0)] {
                        let x = l.sphere_centre(s) + radial + side * (r * r - rho * rho).max(0.0).sqrt() * l.axis;
                        let slack = DVec3::splat(1e-12);
                        assert!(
                            x.cmpge(b.min - slack).all() && x.cmple(b.max + slack).all(),
                            "d {d} r {r1} {r2}: {x} outside {b:?}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn geometry_follows_the_contract() {
        let l = Lens::new(
            DVec3::new(1.0, 2.0, 3.0),
            DVec3::new(0.0, 0.0, 2.0),
            2.0,
            5.0,
            3.0,
            Index::Constant(1.5),
        )
        .unwrap();
        let h1 = (25.0f64 - 1.0).sqrt();
        let h2 = (9.0f64 - 1.0).sqrt();
        assert!((l.sphere_centre(LensSurface::S1) - DVec3::new(1.0, 2.0, 3.0 - h1)).length() < 1e-14);
        assert!((l.sphere_centre(LensSurface::S2) - DVec3::new(1.0, 2.0, 3.0 + h2)).length() < 1e-14);
        assert_relative_eq!(l.vertex(LensSurface::S1).z, 3.0 + 5.0 - h1, epsilon = 1e-14);
        assert_relative_eq!(l.vertex(LensSurface::S2).z, 3.0 - (3.0 - h2), epsilon = 1e-14);
        // The rim circle in the plane through C lies on both spheres.
        let rim = DVec3::new(2.0, 2.0, 3.0);
        assert_relative_eq!((rim - l.sphere_centre(LensSurface::S1)).length(), 5.0, epsilon = 1e-14);
        assert_relative_eq!((rim - l.sphere_centre(LensSurface::S2)).length(), 3.0, epsilon = 1e-14);
    }
}
