//! One face of the lens in vertex form, and the roots of both faces along
//! a ray: the quadratic solve that the lens's hit test, its scalar tracer
//! and their lane forms all call (see the module docs of [`super`]).

use crate::math::{half_b_discriminant, half_b_roots, renormalize};
use glam::DVec3;

/// One face in vertex form.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Cap {
    pub(super) vertex: DVec3,
    /// Outward normal at the vertex (±axis).
    pub(super) m: DVec3,
    pub(super) r: f64,
    /// `1/r`: the normal scales by it rather than dividing three times.
    pub(super) inv_r: f64,
}

impl Cap {
    /// `f(x) = |x − V|² + 2r·(x − V)·m`: negative inside the ball.
    #[inline(always)]
    pub(super) fn f(&self, x: DVec3) -> f64 {
        let q = x - self.vertex;
        q.length_squared() + 2.0 * self.r * q.dot(self.m)
    }

    /// Both roots `(near, far)` of `f(p + t·u) = 0` for the unit direction
    /// `u` from `p`, and whether they are real (if not, the roots are not
    /// numbers to use). No branch: lanes run it side by side.
    #[inline(always)]
    pub(super) fn roots(&self, p: DVec3, u: DVec3) -> (bool, (f64, f64)) {
        let q = p - self.vertex;
        let b = q.dot(u) + self.r * u.dot(self.m);
        let c = self.f(p);
        let disc = half_b_discriminant(b, c);
        (disc >= 0.0, half_b_roots(b, c, disc))
    }

    /// Outward unit normal at `x` on the sphere: `(x − centre)/r`, written as
    /// `m + (x − V)/r` to avoid the large `x − centre` of a flat face.
    #[inline(always)]
    pub(super) fn normal(&self, x: DVec3) -> DVec3 {
        renormalize(self.m + (x - self.vertex) * self.inv_r)
    }
}

/// Where a ray from a local point crosses the solid ([`span`]): the solid
/// is convex, so on one interval, entered at the larger of the two near
/// roots and left at the smaller of the two far roots.
#[derive(Clone, Copy, Debug)]
pub(super) struct Span {
    /// Both faces' roots are real (else the ray misses, and nothing else
    /// here is a number to use).
    pub(super) real: bool,
    pub(super) t_in: f64,
    /// The face whose root gave `t_in` (0: S1, 1: S2).
    pub(super) face_in: usize,
    pub(super) t_out: f64,
    pub(super) face_out: usize,
}

/// The roots of both caps from the local point `p` along the unit `u`.
#[inline(always)]
pub(super) fn span(caps: &[Cap; 2], p: DVec3, u: DVec3) -> Span {
    let (real1, (n1, f1)) = caps[0].roots(p, u);
    let (real2, (n2, f2)) = caps[1].roots(p, u);
    let (t_in, face_in) = if n1 >= n2 { (n1, 0) } else { (n2, 1) };
    let (t_out, face_out) = if f1 <= f2 { (f1, 0) } else { (f2, 1) };
    Span {
        real: real1 & real2,
        t_in,
        face_in,
        t_out,
        face_out,
    }
}
