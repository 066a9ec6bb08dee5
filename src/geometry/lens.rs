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
//! points are added back to `C` only for output.
//!
//! The solid is convex, so a ray meets it on one interval: entry at the larger
//! of the two near roots, exit at the smaller of the two far roots. Inside the
//! glass only the far roots are used, which needs no epsilon: a ray starting
//! on a face going inward has its near root at ≈0 on that face and the far
//! roots ahead.

use super::{Aabb, Hit};
use crate::math::{Ray, solve_half_b_quadratic};
use crate::optics::{self, Index, ThickLens};
use glam::DVec3;

/// Double-double arithmetic (Dekker 1971; Shewchuk 1997): a value `hi + lo`
/// with about 106 significant bits, for the one place that needs it,
/// [`Lens::localize`].
#[derive(Clone, Copy, Debug)]
struct Dd(f64, f64);

impl Dd {
    #[inline]
    fn two_sum(a: f64, b: f64) -> Dd {
        let s = a + b;
        let bb = s - a;
        Dd(s, (a - (s - bb)) + (b - bb))
    }
    #[inline]
    fn two_prod(a: f64, b: f64) -> Dd {
        let p = a * b;
        Dd(p, a.mul_add(b, -p))
    }
    #[inline]
    fn norm(hi: f64, lo: f64) -> Dd {
        let s = hi + lo;
        Dd(s, lo - (s - hi))
    }
    #[inline]
    fn add(self, o: Dd) -> Dd {
        let s = Dd::two_sum(self.0, o.0);
        Dd::norm(s.0, s.1 + self.1 + o.1)
    }
    #[inline]
    fn mul_f(self, b: f64) -> Dd {
        let p = Dd::two_prod(self.0, b);
        Dd::norm(p.0, p.1 + self.1 * b)
    }
    #[inline]
    fn div(self, o: Dd) -> Dd {
        let q1 = self.0 / o.0;
        let r = self.add(o.mul_f(-q1));
        let q2 = r.0 / o.0;
        Dd::norm(q1, q2)
    }
    #[inline]
    fn value(self) -> f64 {
        self.0 + self.1
    }
}

/// The most total internal reflections followed inside the glass before a
/// ray is reported as trapped.
pub const MAX_INTERNAL_REFLECTIONS: u32 = 64;

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

/// Hits of a packet's lanes ([`Lens::intersect_lanes`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct LaneHits<const N: usize> {
    pub t: [f64; N],
    pub part: [u8; N],
    pub hit: [bool; N],
    /// Lanes that the scalar test must take.
    pub slow: [bool; N],
}

/// Exits of a packet's lanes from inside the glass
/// ([`Lens::exit_lanes`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct LaneExits<const N: usize> {
    /// The exit point, world coordinates.
    pub y: [[f64; N]; 3],
    /// The refracted direction out of the glass (unit).
    pub out: [[f64; N]; 3],
    /// The face left through (0: S1, 1: S2).
    pub part: [u64; N],
    /// [`ExitCrossing::normal`] and [`ExitCrossing::reflectance`].
    pub normal: [[f64; N]; 3],
    pub reflectance: [f64; N],
    /// Lanes that leave by refraction at their first exit; the others (a
    /// total internal reflection, or a start outside the glass) need the
    /// scalar [`Lens::propagate_inside`].
    pub ok: [bool; N],
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LensTraceStatus {
    /// The ray entered (or started inside) and left the glass.
    Transmitted,
    /// The ray does not meet the glass.
    Miss,
    /// More than [`MAX_INTERNAL_REFLECTIONS`] total internal reflections.
    Trapped,
}

/// A real ray through the lens.
#[derive(Clone, Debug, PartialEq)]
pub struct LensPath {
    pub status: LensTraceStatus,
    /// Entry face, point, and unit direction inside the glass after the first
    /// refraction; `None` for a miss or a ray that starts inside the glass.
    pub entry: Option<(LensSurface, DVec3, DVec3)>,
    /// Exit face, point, and unit direction in air after the last refraction.
    pub exit: Option<(LensSurface, DVec3, DVec3)>,
    /// The crossing at the exit: `None` without an exit.
    pub exit_crossing: Option<ExitCrossing>,
    pub internal_reflections: u32,
}

/// How a path crosses the exit face, beyond the point and direction of
/// [`LensPath::exit`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExitCrossing {
    /// The face's outward unit normal at the exit point.
    pub normal: DVec3,
    /// The Fresnel reflectance of the crossing from glass into air
    /// ([`optics::fresnel_at`], from the cosines of the refraction itself):
    /// the share of the light that stays inside.
    pub reflectance: f64,
}

/// One face in vertex form.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Cap {
    vertex: DVec3,
    /// Outward normal at the vertex (±axis).
    m: DVec3,
    r: f64,
    /// `1/r`: the normal scales by it rather than dividing three times.
    inv_r: f64,
}

impl Cap {
    /// Both roots `(near, far)` for the unit direction `u` from `p`.
    #[inline]
    fn roots(&self, p: DVec3, u: DVec3) -> Option<(f64, f64)> {
        let q = p - self.vertex;
        let b = q.dot(u) + self.r * u.dot(self.m);
        let c = q.length_squared() + 2.0 * self.r * q.dot(self.m);
        solve_half_b_quadratic(b, c)
    }

    /// Outward unit normal at `x` on the sphere: `(x − centre)/r`, written as
    /// `m + (x − V)/r` to avoid the large `x − centre` of a flat face.
    #[inline]
    fn normal(&self, x: DVec3) -> DVec3 {
        (self.m + (x - self.vertex) * self.inv_r).normalize()
    }

    fn f(&self, x: DVec3) -> f64 {
        let q = x - self.vertex;
        q.length_squared() + 2.0 * self.r * q.dot(self.m)
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
}

impl Lens {
    /// A validated lens. `axis` need not be unit.
    pub fn new(center: DVec3, axis: DVec3, d: f64, r1: f64, r2: f64, index: Index) -> Result<Self, LensError> {
        if !center.is_finite() {
            return Err(LensError::Centre);
        }
        if !(d > 0.0 && d.is_finite()) {
            return Err(LensError::Diameter(d));
        }
        let half = 0.5 * d;
        for (name, r) in [("r1", r1), ("r2", r2)] {
            if !(r >= half && r.is_finite()) {
                return Err(LensError::Radius { name, r, half });
            }
        }
        let check_n = |n: f64| {
            if n >= 1.0 && n.is_finite() {
                Ok(())
            } else {
                Err(LensError::Index(n))
            }
        };
        match index {
            Index::Constant(n) => check_n(n)?,
            Index::Cauchy { .. } => {
                // Must be physical over the visible range used for rendering.
                check_n(index.at(0.38))?;
                check_n(index.at(0.78))?;
                check_n(index.nominal())?;
            }
        }
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
        let rel = origin - self.center;
        if rel.length_squared() <= self.fast_radius2 {
            let vv = dir.length_squared();
            let k = rel.dot(dir) / vv;
            let len = vv.sqrt();
            return (rel - k * dir, dir / len, -k * len);
        }
        let o = [origin.x, origin.y, origin.z];
        let c = [self.center.x, self.center.y, self.center.z];
        let v = [dir.x, dir.y, dir.z];
        let rel = [0, 1, 2].map(|i| Dd::two_sum(o[i], -c[i]));
        let mut dot = Dd(0.0, 0.0);
        let mut vv = Dd(0.0, 0.0);
        for i in 0..3 {
            dot = dot.add(rel[i].mul_f(v[i]));
            vv = vv.add(Dd::two_prod(v[i], v[i]));
        }
        let k = dot.div(vv);
        let p = [0, 1, 2].map(|i| rel[i].add(k.mul_f(-v[i])).value());
        let len = vv.value().sqrt();
        (DVec3::from(p), dir / len, -k.value() * len)
    }

    /// Roots of both faces from the local point `p` along the unit `u`.
    #[inline]
    fn local_roots(&self, p: DVec3, u: DVec3) -> Option<[(f64, f64); 2]> {
        Some([self.caps[0].roots(p, u)?, self.caps[1].roots(p, u)?])
    }

    /// The face a local point `x` lies on, given the face the roots chose.
    #[inline]
    fn face(&self, x: DVec3, by_roots: usize) -> usize {
        if self.one_sphere {
            if x.dot(self.axis) >= 0.0 { 0 } else { 1 }
        } else {
            by_roots
        }
    }

    /// Closest crossing of the lens surface in `(t_min, t_max)`; part 0 is S1,
    /// part 1 is S2. `ray.dir` must be unit.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_min: f64, t_max: f64) -> Option<Hit> {
        // A cheap rejection first: rays that pass well clear of the lens's
        // bounding sphere (a 1% margin is far above any rounding here) do
        // not need the exact start point.
        let rel = ray.origin - self.center;
        let along = rel.dot(ray.dir);
        let miss2 = rel.length_squared() - along * along;
        if miss2 > self.reject_radius2 {
            return None;
        }
        let (p, u, t0) = self.localize(ray.origin, ray.dir);
        let [(n1, f1), (n2, f2)] = self.local_roots(p, u)?;
        let (t_in, p_in) = if n1 >= n2 { (n1, 0) } else { (n2, 1) };
        let (t_out, p_out) = if f1 <= f2 { (f1, 0) } else { (f2, 1) };
        if t_in >= t_out {
            return None;
        }
        if t_in + t0 > t_min && t_in + t0 < t_max {
            let part = self.face(p + t_in * u, p_in) as u8;
            Some(Hit { t: t_in + t0, part })
        } else if t_out + t0 > t_min && t_out + t0 < t_max {
            let part = self.face(p + t_out * u, p_out) as u8;
            Some(Hit { t: t_out + t0, part })
        } else {
            None
        }
    }

    /// [`Lens::intersect`] on `(0, t_max[l])` for every lane `l` of a packet
    /// (origins `o`, unit directions `d`, structure of arrays), written
    /// without branches so that the lanes run in SIMD registers. Each lane
    /// performs exactly the operations of the scalar test, so it gives the
    /// same hit, bit for bit. Lanes whose origin lies beyond the fast radius
    /// need the double-double start point: they are flagged `slow` and left
    /// for the scalar test.
    #[inline(always)]
    pub(crate) fn intersect_lanes<const N: usize>(
        &self,
        o: &[[f64; N]; 3],
        d: &[[f64; N]; 3],
        t_max: &[f64; N],
    ) -> LaneHits<N> {
        let mut out = LaneHits {
            t: [0.0; N],
            part: [0; N],
            hit: [false; N],
            slow: [false; N],
        };
        let c = self.center;
        let axis = self.axis;
        // The cheap rejection of `intersect` first: a packet whose rays all
        // pass clear of the lens (its box is larger than it) stops here.
        let mut any_near = false;
        for l in 0..N {
            let (rx, ry, rz) = (o[0][l] - c.x, o[1][l] - c.y, o[2][l] - c.z);
            let along = (rx * d[0][l]) + (ry * d[1][l]) + (rz * d[2][l]);
            let rel2 = (rx * rx) + (ry * ry) + (rz * rz);
            any_near |= !(rel2 - along * along > self.reject_radius2);
        }
        if !any_near {
            return out;
        }
        for l in 0..N {
            let (dx, dy, dz) = (d[0][l], d[1][l], d[2][l]);
            let (rx, ry, rz) = (o[0][l] - c.x, o[1][l] - c.y, o[2][l] - c.z);
            let along = (rx * dx) + (ry * dy) + (rz * dz);
            let rel2 = (rx * rx) + (ry * ry) + (rz * rz);
            let miss2 = rel2 - along * along;
            let near = !(miss2 > self.reject_radius2);
            let fast = rel2 <= self.fast_radius2;
            // `localize`, fast path.
            let vv = (dx * dx) + (dy * dy) + (dz * dz);
            let k = along / vv;
            let len = vv.sqrt();
            let (px, py, pz) = (rx - k * dx, ry - k * dy, rz - k * dz);
            let (ux, uy, uz) = (dx / len, dy / len, dz / len);
            let t0 = -k * len;
            // `local_roots`: both caps.
            let mut ok = true;
            let mut roots = [(0.0, 0.0); 2];
            for (cap, root) in self.caps.iter().zip(roots.iter_mut()) {
                let (qx, qy, qz) = (px - cap.vertex.x, py - cap.vertex.y, pz - cap.vertex.z);
                let (m, r) = (cap.m, cap.r);
                let b = ((qx * ux) + (qy * uy) + (qz * uz)) + r * ((ux * m.x) + (uy * m.y) + (uz * m.z));
                let cc = ((qx * qx) + (qy * qy) + (qz * qz)) + 2.0 * r * ((qx * m.x) + (qy * m.y) + (qz * m.z));
                // `solve_half_b_quadratic`.
                let disc = b * b - cc;
                ok &= disc >= 0.0;
                let s = disc.sqrt();
                let q = if b >= 0.0 { -(b + s) } else { -(b - s) };
                let r2 = cc / q;
                let pair = if q <= r2 { (q, r2) } else { (r2, q) };
                *root = if q == 0.0 { (0.0, 0.0) } else { pair };
            }
            let [(n1, f1), (n2, f2)] = roots;
            let (t_in, p_in) = if n1 >= n2 { (n1, 0u8) } else { (n2, 1u8) };
            let (t_out, p_out) = if f1 <= f2 { (f1, 0u8) } else { (f2, 1u8) };
            let (e, x) = (t_in + t0, t_out + t0);
            let take_e = e > 0.0 && e < t_max[l];
            let take_x = x > 0.0 && x < t_max[l];
            let (ts, ps) = if take_e { (t_in, p_in) } else { (t_out, p_out) };
            // `face`: a ball lens names the face by the side of the rim plane.
            let (hx, hy, hz) = (px + ts * ux, py + ts * uy, pz + ts * uz);
            let rim_side = if (hx * axis.x) + (hy * axis.y) + (hz * axis.z) >= 0.0 {
                0
            } else {
                1
            };
            out.part[l] = if self.one_sphere { rim_side } else { ps };
            out.t[l] = if take_e { e } else { x };
            out.hit[l] = near && fast && ok && !(t_in >= t_out) && (take_e || take_x);
            out.slow[l] = near && !fast;
        }
        out
    }

    /// The exit from inside the glass: the nearer of the two far roots, from
    /// the local point `x` (inside or on the surface) along the unit `u`.
    #[inline]
    fn exit_local(&self, x: DVec3, u: DVec3) -> Option<(f64, usize)> {
        let [(_, f1), (_, f2)] = self.local_roots(x, u)?;
        let (t, part) = if f1 <= f2 { (f1, 0) } else { (f2, 1) };
        (t >= 0.0).then(|| (t, self.face(x + t * u, part)))
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

    /// A box around the cylinder of radius d/2 from V2 to V1.
    pub fn bounds(&self) -> Aabb {
        let a = self.axis;
        let rim = 0.5 * self.d * (DVec3::ONE - a * a).max(DVec3::ZERO).powf(0.5);
        let (p, q) = (self.vertex(LensSurface::S1), self.vertex(LensSurface::S2));
        let lo = (self.center - rim).min(p).min(q);
        let hi = (self.center + rim).max(p).max(q);
        Aabb::new(lo, hi)
    }

    /// Traces a real ray through the lens in air at index `n`: refraction by
    /// Snell's law at entry, total internal reflections inside (counted, at
    /// most [`MAX_INTERNAL_REFLECTIONS`]), refraction at exit. A ray whose
    /// origin lies inside the glass starts there without an entry; one whose
    /// origin lies on a face (within 1e-10·d) and points inward enters there.
    pub fn trace(&self, origin: DVec3, dir: DVec3, n: f64) -> LensPath {
        let miss = LensPath {
            status: LensTraceStatus::Miss,
            entry: None,
            exit: None,
            exit_crossing: None,
            internal_reflections: 0,
        };
        let (p, u, t0) = self.localize(origin, dir);
        let Some([(n1, f1), (n2, f2)]) = self.local_roots(p, u) else {
            return miss;
        };
        let (t_in, s_in) = if n1 >= n2 { (n1, 0) } else { (n2, 1) };
        let t_out = f1.min(f2);
        let tol = 1e-10 * self.d;
        // Distances from the ray's origin.
        let (o_in, o_out) = (t_in + t0, t_out + t0);
        if t_in >= t_out || o_out <= tol {
            return miss;
        }
        let mut path = if o_in >= -tol {
            // Enters through a face (at the origin itself if it lies on one).
            let x = if o_in > 0.0 { p + t_in * u } else { p - t0 * u };
            let s = self.face(x, s_in);
            let normal = self.caps[s].normal(x);
            // From air into glass (n ≥ 1) there is no total reflection.
            let Some(inside) = optics::refract(u, normal, 1.0, n) else {
                return miss;
            };
            let mut path = self.propagate_local(x, inside, n);
            path.entry = Some((LensSurface::from_part(s as u8), x, inside));
            path
        } else {
            // Starts inside the glass: from the origin, in local coordinates.
            self.propagate_local(p - t0 * u, u, n)
        };
        // Back to world coordinates for the caller.
        let world = |e: Option<(LensSurface, DVec3, DVec3)>| e.map(|(s, x, d)| (s, self.center + x, d));
        path.entry = world(path.entry);
        path.exit = world(path.exit);
        path
    }

    /// Follows a ray inside the glass from the world point `x` in the unit
    /// direction `u` until it leaves (the renderer calls this after its own
    /// entry refraction). Points in the result are in world coordinates.
    pub fn propagate_inside(&self, x: DVec3, u: DVec3, n: f64) -> LensPath {
        let mut path = self.propagate_local(x - self.center, u, n);
        path.exit = path.exit.map(|(s, y, d)| (s, self.center + y, d));
        path
    }

    /// [`Lens::propagate_inside`] for `N` rays at once, for rays that leave
    /// at their first exit: lane `l` starts at the world point `x[l]` inside
    /// (or on) the glass along the unit `u[l]`. A lane flagged `ok` gets
    /// exactly the scalar exit (the same operations in the same order,
    /// without branches, so that the lanes share SIMD registers); the others
    /// are left to the scalar code.
    #[inline(always)]
    pub(crate) fn exit_lanes<const N: usize>(&self, x: &[[f64; N]; 3], u: &[[f64; N]; 3], n: f64) -> LaneExits<N> {
        let mut out = LaneExits {
            y: [[0.0; N]; 3],
            out: [[0.0; N]; 3],
            part: [0; N],
            normal: [[0.0; N]; 3],
            reflectance: [0.0; N],
            ok: [false; N],
        };
        let [c0, c1] = self.caps;
        for l in 0..N {
            let x = DVec3::new(x[0][l], x[1][l], x[2][l]) - self.center;
            let u = DVec3::new(u[0][l], u[1][l], u[2][l]);
            // `exit_local`: the far roots of both faces (`Cap::roots`,
            // `solve_half_b_quadratic`).
            let mut real = true;
            let mut far = [0.0; 2];
            for (cap, far) in [c0, c1].iter().zip(far.iter_mut()) {
                let q = x - cap.vertex;
                let b = q.dot(u) + cap.r * u.dot(cap.m);
                let c = q.length_squared() + 2.0 * cap.r * q.dot(cap.m);
                let disc = b * b - c;
                real &= disc >= 0.0;
                let s = disc.sqrt();
                let q = if b >= 0.0 { -(b + s) } else { -(b - s) };
                let r2 = c / q;
                *far = if q == 0.0 {
                    0.0
                } else if q <= r2 {
                    r2
                } else {
                    q
                };
            }
            let (t, by_roots) = if far[0] <= far[1] { (far[0], 0) } else { (far[1], 1) };
            let y = x + t * u;
            // `face`.
            let s = if self.one_sphere {
                if y.dot(self.axis) >= 0.0 { 0 } else { 1 }
            } else {
                by_roots
            };
            let cap = if s == 0 { c0 } else { c1 };
            let normal = (cap.m + (y - cap.vertex) * cap.inv_r).normalize();
            // `propagate_local`'s crossing out, inside to air.
            let c = optics::crossing(u, -normal, n, 1.0);
            out.reflectance[l] = c.reflectance;
            let yw = self.center + y;
            for k in 0..3 {
                out.y[k][l] = yw[k];
                out.out[k][l] = c.dir[k];
                out.normal[k][l] = normal[k];
            }
            out.part[l] = s;
            out.ok[l] = real & (t >= 0.0) & !c.total;
        }
        out
    }

    /// [`Lens::propagate_inside`] in local coordinates.
    fn propagate_local(&self, mut x: DVec3, mut u: DVec3, n: f64) -> LensPath {
        let mut reflections = 0;
        loop {
            let Some((t, s)) = self.exit_local(x, u) else {
                return LensPath {
                    status: LensTraceStatus::Miss,
                    entry: None,
                    exit: None,
                    exit_crossing: None,
                    internal_reflections: reflections,
                };
            };
            let y = x + t * u;
            let normal = self.caps[s].normal(y);
            // Inside, the face's outward normal points away from the incident
            // side, so Snell's law takes −normal.
            let c = optics::crossing(u, -normal, n, 1.0);
            if !c.total {
                return LensPath {
                    status: LensTraceStatus::Transmitted,
                    entry: None,
                    exit: Some((LensSurface::from_part(s as u8), y, c.dir)),
                    exit_crossing: Some(ExitCrossing {
                        normal,
                        reflectance: c.reflectance,
                    }),
                    internal_reflections: reflections,
                };
            }
            if reflections >= MAX_INTERNAL_REFLECTIONS {
                return LensPath {
                    status: LensTraceStatus::Trapped,
                    entry: None,
                    exit: None,
                    exit_crossing: None,
                    internal_reflections: reflections,
                };
            }
            reflections += 1;
            u = optics::reflect(u, normal).normalize();
            x = y;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn lens(d: f64, r1: f64, r2: f64, n: f64) -> Lens {
        Lens::new(DVec3::ZERO, DVec3::Z, d, r1, r2, Index::Constant(n)).unwrap()
    }

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

    #[test]
    fn axial_ray_passes_undeviated() {
        let l = lens(20.0, 50.0, 50.0, 1.5);
        let p = l.trace(DVec3::new(0.0, 0.0, 30.0), DVec3::NEG_Z, 1.5);
        assert_eq!(p.status, LensTraceStatus::Transmitted);
        let (s, x, u) = p.entry.unwrap();
        assert_eq!(s, LensSurface::S1);
        assert_relative_eq!(x.z, optics::sagitta(50.0, 10.0), epsilon = 1e-15);
        assert_eq!(u, DVec3::NEG_Z);
        let (s, x, u) = p.exit.unwrap();
        assert_eq!(s, LensSurface::S2);
        assert_relative_eq!(x.z, -optics::sagitta(50.0, 10.0), epsilon = 1e-15);
        assert_eq!(u, DVec3::NEG_Z);
    }

    #[test]
    fn paraxial_ray_focuses_near_back_focal_distance() {
        let l = lens(20.0, 50.0, 50.0, 1.5);
        let px = l.paraxial(1.5);
        let h = 1e-4;
        let p = l.trace(DVec3::new(h, 0.0, 30.0), DVec3::NEG_Z, 1.5);
        let (_, x, u) = p.exit.unwrap();
        // Where the exiting ray crosses the axis, measured from V2.
        let t = -x.x / u.x;
        let z = x.z + t * u.z;
        let bfd = l.vertex(LensSurface::S2).z - z;
        assert_relative_eq!(bfd, px.bfd, max_relative = 1e-7);
    }

    #[test]
    fn misses_and_rays_from_inside() {
        let l = lens(2.0, 5.0, 5.0, 1.5);
        assert_eq!(
            l.trace(DVec3::new(1.01, 0.0, 5.0), DVec3::NEG_Z, 1.5).status,
            LensTraceStatus::Miss
        );
        assert_eq!(
            l.trace(DVec3::new(0.0, 0.0, -5.0), DVec3::NEG_Z, 1.5).status,
            LensTraceStatus::Miss
        );
        // From the centre toward S1 (not toward the rim, where the faces meet).
        let p = l.trace(DVec3::ZERO, DVec3::new(0.3, 0.0, 1.0), 1.5);
        assert!(p.entry.is_none());
        assert_eq!(p.exit.unwrap().0, LensSurface::S1);
        assert_eq!(p.status, LensTraceStatus::Transmitted);
    }

    #[test]
    fn ball_lens_traps_nothing_and_index_four_reflects() {
        // A ball lens: both faces hemispheres.
        let ball = lens(2.0, 1.0, 1.0, 1.5);
        let p = ball.trace(DVec3::new(0.5, 0.0, 5.0), DVec3::NEG_Z, 1.5);
        assert_eq!(p.status, LensTraceStatus::Transmitted);
        assert_eq!(p.internal_reflections, 0);
        let (_, x, _) = p.exit.unwrap();
        assert_relative_eq!(x.length(), 1.0, epsilon = 1e-15);
        // A ray inside a ball is never trapped by TIR (the chord angle is
        // preserved), but inside a thin lens at n = 4 a ray is.
        let l = lens(2.0, 5.0, 5.0, 4.0);
        let p = l.trace(DVec3::ZERO, DVec3::new(1.0, 0.0, 0.05), 4.0);
        assert!(p.internal_reflections >= 1, "{p:?}");
    }

    /// Lenses for the lane tests: the benchmark scene's, a ball, a
    /// meniscus-like pair of radii, a nearly flat one and a tiny one far
    /// from the origin.
    fn lane_test_lenses() -> Vec<Lens> {
        [
            Lens::new(
                DVec3::new(0.0, 4.3, 6.9),
                DVec3::new(0.0, 0.48, 0.88),
                2.0,
                5.0,
                5.0,
                Index::Constant(1.5),
            ),
            Lens::new(DVec3::ZERO, DVec3::Z, 2.0, 1.0, 1.0, Index::Constant(1.5)),
            Lens::new(DVec3::ONE, DVec3::X, 2.0, 1.0, 3.0, Index::Constant(1.5)),
            Lens::new(DVec3::ZERO, DVec3::Y, 2.0, 2e6, 2e7, Index::Constant(1.5)),
            Lens::new(DVec3::splat(1e4), DVec3::ONE, 1e-3, 0.7e-3, 5e-3, Index::Constant(1.5)),
        ]
        .into_iter()
        .map(|l| l.unwrap())
        .collect()
    }

    /// The lane exits are the scalar `propagate_inside` exits to the bit,
    /// for rays refracted in at real entry points (thick, ball, meniscus-
    /// like, nearly flat and tiny far-off lenses), and every lane that
    /// reflects inside is left to the scalar code.
    #[test]
    fn lane_exits_are_the_scalar_exits_bit_for_bit() {
        use crate::sampling::Sampler;
        let mut s = Sampler::new(5, 0, 0);
        let (mut exact, mut scalar) = (0, 0);
        for (c, l) in lane_test_lenses().into_iter().enumerate() {
            let n = 1.5;
            for _ in 0..3000 {
                let mut x = [[0.0; 8]; 3];
                let mut u = [[0.0; 8]; 3];
                for lane in 0..8 {
                    // A ray from outside toward the lens, refracted in where
                    // it enters.
                    let org = l.center + (DVec3::new(s.next_f64(), s.next_f64(), s.next_f64()) - 0.5) * 6.0 * l.d;
                    let aim = l.center + (DVec3::new(s.next_f64(), s.next_f64(), s.next_f64()) - 0.5) * l.d;
                    let ray = Ray::new(org, aim - org);
                    let (p, dir) = match l.intersect(&ray, 0.0, f64::INFINITY) {
                        Some(h) => {
                            let p = ray.at(h.t);
                            let nrm = l.normal(p, h.part);
                            let nf = if ray.dir.dot(nrm) < 0.0 { nrm } else { -nrm };
                            (p, optics::refract(ray.dir, nf, 1.0, n).unwrap_or(ray.dir))
                        }
                        // A start inside the glass in a random direction.
                        None => (l.center, ray.dir),
                    };
                    for k in 0..3 {
                        x[k][lane] = p[k];
                        u[k][lane] = dir[k];
                    }
                }
                let got = l.exit_lanes(&x, &u, n);
                for lane in 0..8 {
                    let p = DVec3::new(x[0][lane], x[1][lane], x[2][lane]);
                    let dir = DVec3::new(u[0][lane], u[1][lane], u[2][lane]);
                    let want = l.propagate_inside(p, dir, n);
                    if !got.ok[lane] {
                        scalar += 1;
                        assert!(
                            want.internal_reflections > 0 || want.status != LensTraceStatus::Transmitted,
                            "case {c}: a plain pass left to the scalar code"
                        );
                        continue;
                    }
                    exact += 1;
                    let y = DVec3::new(got.y[0][lane], got.y[1][lane], got.y[2][lane]);
                    let out = DVec3::new(got.out[0][lane], got.out[1][lane], got.out[2][lane]);
                    let part = LensSurface::from_part(got.part[lane] as u8);
                    assert_eq!(want.status, LensTraceStatus::Transmitted, "case {c}");
                    assert_eq!(want.internal_reflections, 0, "case {c}");
                    assert_eq!(want.exit, Some((part, y, out)), "case {c}");
                    let crossing = ExitCrossing {
                        normal: DVec3::new(got.normal[0][lane], got.normal[1][lane], got.normal[2][lane]),
                        reflectance: got.reflectance[lane],
                    };
                    assert_eq!(want.exit_crossing, Some(crossing), "case {c}");
                }
            }
        }
        assert!(
            exact > 50_000 && scalar > 500,
            "{exact} exact lanes, {scalar} left to the scalar code"
        );
    }

    #[test]
    fn lanes_give_the_scalar_hit_bit_for_bit() {
        use crate::sampling::Sampler;
        let mut s = Sampler::new(11, 0, 0);
        for (c, l) in lane_test_lenses().into_iter().enumerate() {
            let mut hits = 0;
            for k in 0..4000 {
                let mut o = [[0.0; 8]; 3];
                let mut d = [[0.0; 8]; 3];
                let mut t_max = [f64::INFINITY; 8];
                for lane in 0..8 {
                    // Origins near the lens (some inside it), on the far side,
                    // and far away for the slow lanes.
                    let spread = [0.2, 3.0, 1e5][(k + lane) % 3] * l.d;
                    let org = l.center + (DVec3::new(s.next_f64(), s.next_f64(), s.next_f64()) - 0.5) * spread;
                    let aim = l.center + (DVec3::new(s.next_f64(), s.next_f64(), s.next_f64()) - 0.5) * l.d;
                    let dir = (aim - org).normalize();
                    if lane == 7 {
                        t_max[lane] = s.next_f64() * spread;
                    }
                    for i in 0..3 {
                        o[i][lane] = org[i];
                        d[i][lane] = dir[i];
                    }
                }
                let got = l.intersect_lanes(&o, &d, &t_max);
                for lane in 0..8 {
                    let ray = Ray {
                        origin: DVec3::new(o[0][lane], o[1][lane], o[2][lane]),
                        dir: DVec3::new(d[0][lane], d[1][lane], d[2][lane]),
                    };
                    let want = l.intersect(&ray, 0.0, t_max[lane]);
                    if got.slow[lane] {
                        assert!((ray.origin - l.center).length_squared() > l.fast_radius2, "case {c}");
                        continue;
                    }
                    let have = got.hit[lane].then_some(Hit {
                        t: got.t[lane],
                        part: got.part[lane],
                    });
                    assert_eq!(have, want, "case {c}, packet {k}, lane {lane}: {ray:?}");
                    hits += usize::from(want.is_some());
                }
            }
            assert!(hits > 2000, "case {c}: only {hits} hits");
        }
    }
}
