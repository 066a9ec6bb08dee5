//! An independent reference tracer for a real ray through the thick biconvex
//! lens of DESIGN.md §2, written without any of the crate's code.
//!
//! It works in the *centre form* — the ray `o + t·u` meets the ball of centre
//! `c` and radius `R` where `|o + t·u − c|² = R²` — whereas the code under
//! test uses a vertex form. The solid is the intersection of the two balls, so
//! a ray meets it on `[max of near roots, min of far roots]`. Snell's law is
//! applied in vector form and total internal reflections are followed (and
//! counted) up to [`MAX_REFLECTIONS`].
//!
//! The tracer is generic over the arithmetic: with [`DD`] (double-double, about
//! 32 significant digits) it is the reference; with plain `f64` it is the naive
//! implementation that the stiff tests must be able to tell from a good one.
//! Inputs are `f64` values taken exactly as given (axis and direction are
//! normalised in the working arithmetic).

use std::cmp::Ordering;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// Total internal reflections followed before a ray is reported as trapped.
pub const MAX_REFLECTIONS: u32 = 64;

// ---------------------------------------------------------------------------
// Double-double arithmetic
// ---------------------------------------------------------------------------

/// An unevaluated sum `hi + lo` with `|lo| ≤ ulp(hi)/2`: about 106 bits.
#[derive(Clone, Copy, Debug)]
pub struct DD {
    pub hi: f64,
    pub lo: f64,
}

/// Knuth's TwoSum: `s + e = a + b` exactly.
#[inline]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    let e = (a - (s - bb)) + (b - bb);
    (s, e)
}

/// Dekker's FastTwoSum, valid when `|a| ≥ |b|` (or `a` = 0).
#[inline]
fn quick_two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let e = b - (s - a);
    (s, e)
}

/// TwoProd with a fused multiply-add: `p + e = a·b` exactly.
#[inline]
fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    let e = a.mul_add(b, -p);
    (p, e)
}

impl DD {
    pub const ZERO: DD = DD { hi: 0.0, lo: 0.0 };

    pub fn new(x: f64) -> Self {
        DD { hi: x, lo: 0.0 }
    }

    fn from_pair((hi, lo): (f64, f64)) -> Self {
        let (hi, lo) = quick_two_sum(hi, lo);
        DD { hi, lo }
    }

    pub fn to_f64(self) -> f64 {
        self.hi + self.lo
    }

    /// Square root: the f64 root refined by one Newton step in DD
    /// (`s + (x − s²)/(2s)`), which doubles the 53 correct bits.
    pub fn sqrt(self) -> Self {
        if self.hi <= 0.0 {
            return if self.hi == 0.0 { DD::ZERO } else { DD::new(f64::NAN) };
        }
        let s = DD::new(self.hi.sqrt());
        s + (self - s * s) / (s * DD::new(2.0))
    }
}

impl Add for DD {
    type Output = DD;
    /// The accurate ("IEEE") double-double sum of Hida, Li & Bailey (QD).
    fn add(self, b: DD) -> DD {
        let (s1, s2) = two_sum(self.hi, b.hi);
        let (t1, t2) = two_sum(self.lo, b.lo);
        let (s1, s2) = quick_two_sum(s1, s2 + t1);
        DD::from_pair((s1, s2 + t2))
    }
}

impl Neg for DD {
    type Output = DD;
    fn neg(self) -> DD {
        DD {
            hi: -self.hi,
            lo: -self.lo,
        }
    }
}

impl Sub for DD {
    type Output = DD;
    fn sub(self, b: DD) -> DD {
        self + (-b)
    }
}

impl Mul for DD {
    type Output = DD;
    fn mul(self, b: DD) -> DD {
        let (p, e) = two_prod(self.hi, b.hi);
        let e = e + (self.hi * b.lo + self.lo * b.hi);
        DD::from_pair((p, e))
    }
}

impl Div for DD {
    type Output = DD;
    /// Long division with three f64 quotient digits (QD's accurate division).
    fn div(self, b: DD) -> DD {
        let q1 = self.hi / b.hi;
        let r = self - b * DD::new(q1);
        let q2 = r.hi / b.hi;
        let r = r - b * DD::new(q2);
        let q3 = r.hi / b.hi;
        DD::from_pair((q1, q2)) + DD::new(q3)
    }
}

impl PartialEq for DD {
    fn eq(&self, o: &DD) -> bool {
        self.hi == o.hi && self.lo == o.lo
    }
}

impl PartialOrd for DD {
    fn partial_cmp(&self, o: &DD) -> Option<Ordering> {
        match self.hi.partial_cmp(&o.hi)? {
            Ordering::Equal => self.lo.partial_cmp(&o.lo),
            ord => Some(ord),
        }
    }
}

/// The arithmetic the tracer runs in.
pub trait Real:
    Copy
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    fn of(x: f64) -> Self;
    fn to_f64(self) -> f64;
    fn sqrt(self) -> Self;
}

impl Real for DD {
    fn of(x: f64) -> Self {
        DD::new(x)
    }
    fn to_f64(self) -> f64 {
        DD::to_f64(self)
    }
    fn sqrt(self) -> Self {
        DD::sqrt(self)
    }
}

impl Real for f64 {
    fn of(x: f64) -> Self {
        x
    }
    fn to_f64(self) -> f64 {
        self
    }
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
}

// ---------------------------------------------------------------------------
// Vectors
// ---------------------------------------------------------------------------

#[derive(Clone, Copy, Debug)]
pub struct V3<T>(pub [T; 3]);

impl<T: Real> V3<T> {
    pub fn of(v: [f64; 3]) -> Self {
        V3([T::of(v[0]), T::of(v[1]), T::of(v[2])])
    }
    pub fn to_f64(self) -> [f64; 3] {
        [self.0[0].to_f64(), self.0[1].to_f64(), self.0[2].to_f64()]
    }
    pub fn dot(self, b: Self) -> T {
        self.0[0] * b.0[0] + self.0[1] * b.0[1] + self.0[2] * b.0[2]
    }
    pub fn scale(self, s: T) -> Self {
        V3([self.0[0] * s, self.0[1] * s, self.0[2] * s])
    }
    pub fn length(self) -> T {
        self.dot(self).sqrt()
    }
    pub fn normalize(self) -> Self {
        let l = self.length();
        V3([self.0[0] / l, self.0[1] / l, self.0[2] / l])
    }
}

impl<T: Real> Add for V3<T> {
    type Output = Self;
    fn add(self, b: Self) -> Self {
        V3([self.0[0] + b.0[0], self.0[1] + b.0[1], self.0[2] + b.0[2]])
    }
}

impl<T: Real> Sub for V3<T> {
    type Output = Self;
    fn sub(self, b: Self) -> Self {
        V3([self.0[0] - b.0[0], self.0[1] - b.0[1], self.0[2] - b.0[2]])
    }
}

impl<T: Real> Neg for V3<T> {
    type Output = Self;
    fn neg(self) -> Self {
        V3([-self.0[0], -self.0[1], -self.0[2]])
    }
}

// ---------------------------------------------------------------------------
// The lens and the trace
// ---------------------------------------------------------------------------

/// A lens exactly as given to the code under test (all f64).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LensSpec {
    pub center: [f64; 3],
    pub axis: [f64; 3],
    pub d: f64,
    pub r1: f64,
    pub r2: f64,
    pub n: f64,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Face {
    S1,
    S2,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    Transmitted,
    Miss,
    Trapped,
}

/// A face crossing: face, point, unit direction (inside the glass after an
/// entry, in air after an exit).
#[derive(Clone, Copy, Debug)]
pub struct Crossing<T> {
    pub face: Face,
    pub point: V3<T>,
    pub dir: V3<T>,
}

#[derive(Clone, Debug)]
pub struct Path<T> {
    pub status: Status,
    pub entry: Option<Crossing<T>>,
    pub exit: Option<Crossing<T>>,
    pub reflections: u32,
    /// Smallest `|ρ − d/2|` over every point where the ray met a face (ρ the
    /// distance from the axis): how close the path came to the rim, where the
    /// two faces meet and the face a ray meets is ill-determined.
    pub rim_distance: f64,
    /// Where and in which direction the ray starts inside the glass (after
    /// the entry refraction, or its origin): for a conditioning check.
    pub start: Option<(V3<T>, V3<T>)>,
}

/// The lens in the working arithmetic: unit axis and both sphere centres.
pub struct Geometry<T> {
    pub center: V3<T>,
    pub axis: V3<T>,
    pub half: T,
    pub radius: [T; 2],
    pub sphere_centre: [V3<T>; 2],
    pub n: T,
}

impl<T: Real> Geometry<T> {
    pub fn new(l: &LensSpec) -> Self {
        let center = V3::<T>::of(l.center);
        let axis = V3::<T>::of(l.axis).normalize();
        let half = T::of(l.d) * T::of(0.5);
        let (r1, r2) = (T::of(l.r1), T::of(l.r2));
        // √(R² − (d/2)²): in DD the squares and their difference are exact
        // to ~10⁻³², so R = d/2 gives exactly 0.
        let off1 = (r1 * r1 - half * half).sqrt();
        let off2 = (r2 * r2 - half * half).sqrt();
        Geometry {
            center,
            axis,
            half,
            radius: [r1, r2],
            sphere_centre: [center - axis.scale(off1), center + axis.scale(off2)],
            n: T::of(l.n),
        }
    }

    /// Vertex of S1 (`C + a·sag1`, the point of ball 1 furthest along +a) or
    /// of S2: the sphere centre plus/minus R along the axis.
    pub fn vertex(&self, f: Face) -> V3<T> {
        match f {
            Face::S1 => self.sphere_centre[0] + self.axis.scale(self.radius[0]),
            Face::S2 => self.sphere_centre[1] - self.axis.scale(self.radius[1]),
        }
    }

    /// Both roots (near, far) of `|p + t·u − c|² = R²` for the unit `u`:
    /// `t² + 2bt + cc = 0` with `b = (p − c)·u`, `cc = |p − c|² − R²`.
    pub fn roots(&self, face: usize, p: V3<T>, u: V3<T>) -> Option<(T, T)> {
        let w = p - self.sphere_centre[face];
        let r = self.radius[face];
        let b = w.dot(u);
        let cc = w.dot(w) - r * r;
        let disc = b * b - cc;
        if disc < T::of(0.0) {
            return None;
        }
        let s = disc.sqrt();
        Some((-b - s, -b + s))
    }

    /// Outward unit normal of a face at `x`: `(x − c)/|x − c|`.
    pub fn normal(&self, face: usize, x: V3<T>) -> V3<T> {
        (x - self.sphere_centre[face]).normalize()
    }

    /// `|ρ − d/2|` at `x`, ρ its distance from the axis.
    pub fn rim_distance(&self, x: V3<T>) -> f64 {
        let q = x - self.center;
        let along = q.dot(self.axis);
        let radial = q - self.axis.scale(along);
        (radial.length() - self.half).to_f64().abs()
    }

    /// True when `x` is inside both balls.
    pub fn contains(&self, x: V3<T>) -> bool {
        (0..2).all(|i| {
            let w = x - self.sphere_centre[i];
            w.dot(w) < self.radius[i] * self.radius[i]
        })
    }
}

/// Snell's law in vector form: `u` unit, `nrm` unit facing the incident side,
/// `eta = n_incident / n_transmitted`. `None` under total internal reflection.
pub fn snell<T: Real>(u: V3<T>, nrm: V3<T>, eta: T) -> Option<V3<T>> {
    let one = T::of(1.0);
    let cos_i = -u.dot(nrm);
    let sin2_t = eta * eta * (one - cos_i * cos_i);
    if sin2_t > one {
        return None;
    }
    let cos_t = (one - sin2_t).sqrt();
    Some((u.scale(eta) + nrm.scale(eta * cos_i - cos_t)).normalize())
}

fn face_of(i: usize) -> Face {
    if i == 0 { Face::S1 } else { Face::S2 }
}

/// Traces the ray `origin + t·dir` (dir need not be unit) through the lens.
pub fn trace<T: Real>(lens: &LensSpec, origin: [f64; 3], dir: [f64; 3]) -> Path<T> {
    let g = Geometry::<T>::new(lens);
    let o = V3::<T>::of(origin);
    let u = V3::<T>::of(dir).normalize();
    let miss = Path {
        status: Status::Miss,
        entry: None,
        exit: None,
        reflections: 0,
        rim_distance: f64::INFINITY,
        start: None,
    };
    let (Some((near1, far1)), Some((near2, far2))) = (g.roots(0, o, u), g.roots(1, o, u)) else {
        return miss;
    };
    let (t_in, i_in) = if near1 > near2 {
        (near1, 0)
    } else if near2 > near1 {
        (near2, 1)
    } else {
        // Coinciding spheres (a ball lens): the half the point lies in.
        let x = o + u.scale(near1);
        (near1, if (x - g.center).dot(g.axis) >= T::of(0.0) { 0 } else { 1 })
    };
    let t_out = if far1 <= far2 { far1 } else { far2 };
    // "On a face" means within 1e-10·d of it (the contract of `Lens::trace`).
    let tol = T::of(1e-10 * lens.d);
    if t_in >= t_out || t_out <= tol {
        return Path {
            rim_distance: if t_in >= t_out {
                f64::INFINITY
            } else {
                g.rim_distance(o + u.scale(t_out))
            },
            ..miss
        };
    }
    if t_in >= -tol {
        let x = if t_in > T::of(0.0) { o + u.scale(t_in) } else { o };
        let nrm = g.normal(i_in, x);
        let inside = snell(u, nrm, T::of(1.0) / g.n).expect("no total reflection from air into glass");
        let mut path = inside_path(&g, x, inside);
        path.rim_distance = path.rim_distance.min(g.rim_distance(x));
        path.entry = Some(Crossing {
            face: face_of(i_in),
            point: x,
            dir: inside,
        });
        path
    } else {
        inside_path(&g, o, u)
    }
}

/// From `x` inside (or on) the glass in the unit direction `v`, until the ray
/// leaves or is trapped.
pub fn inside_path<T: Real>(g: &Geometry<T>, mut x: V3<T>, mut v: V3<T>) -> Path<T> {
    let start = Some((x, v));
    let mut reflections = 0;
    let mut rim = f64::INFINITY;
    loop {
        let (Some((_, f1)), Some((_, f2))) = (g.roots(0, x, v), g.roots(1, x, v)) else {
            return Path {
                status: Status::Miss,
                entry: None,
                exit: None,
                reflections,
                rim_distance: rim,
                start,
            };
        };
        let (t, i) = if f1 < f2 {
            (f1, 0)
        } else if f2 < f1 {
            (f2, 1)
        } else {
            // The spheres coincide (a ball lens, R1 = R2 = d/2): the face is
            // the half the point lies in, S1 on the +a side of the rim plane.
            let y = x + v.scale(f1);
            (f1, if (y - g.center).dot(g.axis) >= T::of(0.0) { 0 } else { 1 })
        };
        let y = x + v.scale(t);
        rim = rim.min(g.rim_distance(y));
        let nrm = g.normal(i, y);
        match snell(v, -nrm, g.n) {
            Some(out) => {
                return Path {
                    status: Status::Transmitted,
                    entry: None,
                    exit: Some(Crossing {
                        face: face_of(i),
                        point: y,
                        dir: out,
                    }),
                    reflections,
                    rim_distance: rim,
                    start,
                };
            }
            None => {
                if reflections >= MAX_REFLECTIONS {
                    return Path {
                        status: Status::Trapped,
                        entry: None,
                        exit: None,
                        reflections,
                        rim_distance: rim,
                        start,
                    };
                }
                reflections += 1;
                v = (v - nrm.scale(T::of(2.0) * v.dot(nrm))).normalize();
                x = y;
            }
        }
    }
}

// ---------------------------------------------------------------------------
// Lens systems (docs/lens-systems.md)
// ---------------------------------------------------------------------------

#[allow(dead_code)]
pub mod system;
#[allow(dead_code)]
pub mod system_cases;
