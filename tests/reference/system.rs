//! An independent reference tracer for a real ray through a *lens system*
//! (docs/lens-systems.md), written without any of the crate's code.
//!
//! Formulation (deliberately not the crate's vertex form): every spherical
//! surface is the sphere `|p − C_k|² = R_k²` in world coordinates, centre
//! `C_k = V + (z_k + R_k)·w` on the axis (`w = −a`, the direction of the
//! light), solved as `t² + 2bt + cc = 0` (`b = (p − C)·u`, `cc = |p − C|² −
//! R²`); the cap is the branch on the vertex's side of the centre,
//! `(x − C)·w·R < 0`, within `r ≤ a_k`. Planes (plane surfaces, rings, the
//! stop's diaphragm) are `z = const` along `w`, edges the cylinders `r = ρ`.
//! On the sphere a ray leaves, the other root is `−2b` exactly. Refraction
//! is vector Snell ([`super::snell`]); the side a ray comes from is the sign
//! of `u·m`, `m = (x − C)/R` the unit normal towards the object side.
//!
//! Generic over [`Real`]: with [`super::DD`] it is the reference, with `f64`
//! the naive tracer.

use super::{MAX_REFLECTIONS, Real, V3, snell};

/// The helium d line (µm), the default wavelength.
pub const D_LINE_UM: f64 = 0.5875618;

/// A medium: a number, Cauchy `A + B/λ²` (λ in µm) or a catalogue glass
/// (Sellmeier, SCHOTT's coefficients).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Medium {
    Index(f64),
    Cauchy(f64, f64),
    Glass(&'static str),
}

/// SCHOTT Sellmeier coefficients `(B1..3, C1..3)` (C in µm²).
pub fn sellmeier(name: &str) -> ([f64; 3], [f64; 3]) {
    match name {
        "N-BK7" => (
            [1.03961212, 0.231792344, 1.01046945],
            [0.00600069867, 0.0200179144, 103.560653],
        ),
        "N-SF5" => (
            [1.52481889, 0.187085527, 1.42729015],
            [0.011254756, 0.0588995392, 129.141675],
        ),
        _ => panic!("no Sellmeier coefficients for glass {name:?} in the reference"),
    }
}

impl Medium {
    pub const AIR: Medium = Medium::Index(1.0);

    /// Air: the index exactly 1 at every wavelength.
    pub fn is_air(&self) -> bool {
        matches!(*self, Medium::Index(n) if n == 1.0) || matches!(*self, Medium::Cauchy(a, b) if a == 1.0 && b == 0.0)
    }

    pub fn index<T: Real>(&self, lambda_um: f64) -> T {
        let l2 = T::of(lambda_um) * T::of(lambda_um);
        match *self {
            Medium::Index(n) => T::of(n),
            Medium::Cauchy(a, b) => T::of(a) + T::of(b) / l2,
            Medium::Glass(name) => {
                let (b, c) = sellmeier(name);
                let mut n2 = T::of(1.0);
                for (bi, ci) in b.iter().zip(c) {
                    n2 = n2 + T::of(*bi) * l2 / (l2 - T::of(ci));
                }
                n2.sqrt()
            }
        }
    }

    /// As the crate's input writes it.
    pub fn to_json(self) -> serde_json::Value {
        match self {
            Medium::Index(n) => serde_json::json!(n),
            Medium::Cauchy(a, b) => serde_json::json!({ "cauchy": [a, b] }),
            Medium::Glass(name) => serde_json::json!(name),
        }
    }
}

/// One surface exactly as given to the code under test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceSpec {
    /// Signed radius; 0 is a plane.
    pub radius: f64,
    pub thickness: f64,
    /// The medium after the surface.
    pub n: Medium,
    pub semi_aperture: f64,
    pub stop: bool,
}

/// A system exactly as given to the code under test (all f64).
#[derive(Clone, Debug, PartialEq)]
pub struct SystemSpec {
    pub vertex: [f64; 3],
    pub axis: [f64; 3],
    pub surfaces: Vec<SurfaceSpec>,
}

impl SystemSpec {
    /// The length the tolerances scale with: first to last vertex, or the
    /// largest semi-aperture if larger.
    pub fn length(&self) -> f64 {
        let n = self.surfaces.len();
        let axial: f64 = self.surfaces[..n - 1].iter().map(|s| s.thickness).sum();
        self.surfaces.iter().map(|s| s.semi_aperture).fold(axial, f64::max)
    }

    /// The medium before surface `k`.
    pub fn before(&self, k: usize) -> Medium {
        if k == 0 { Medium::AIR } else { self.surfaces[k - 1].n }
    }

    pub fn to_json(&self) -> serde_json::Value {
        let surfaces: Vec<serde_json::Value> = self
            .surfaces
            .iter()
            .map(|s| {
                serde_json::json!({
                    "radius": s.radius, "thickness": s.thickness, "n": s.n.to_json(),
                    "semi_aperture": s.semi_aperture, "stop": s.stop,
                })
            })
            .collect();
        serde_json::json!({ "vertex": self.vertex, "axis": self.axis, "surfaces": surfaces })
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Piece {
    Cap,
    Ring,
    Edge,
    Stop,
}

impl Piece {
    pub fn name(self) -> &'static str {
        match self {
            Piece::Cap => "cap",
            Piece::Ring => "ring",
            Piece::Edge => "edge",
            Piece::Stop => "stop",
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Refract,
    Reflect,
    Absorb,
}

impl Kind {
    pub fn name(self) -> &'static str {
        match self {
            Kind::Refract => "refract",
            Kind::Reflect => "reflect",
            Kind::Absorb => "absorb",
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    Transmitted,
    Miss,
    Absorbed,
    Trapped,
}

impl Status {
    pub fn name(self) -> &'static str {
        match self {
            Status::Transmitted => "transmitted",
            Status::Miss => "miss",
            Status::Absorbed => "absorbed",
            Status::Trapped => "trapped",
        }
    }
}

/// A piece met: surface, piece, what happened, the point and the direction
/// after it (the incoming one for an absorption).
#[derive(Clone, Copy, Debug)]
pub struct Event<T> {
    pub surface: usize,
    pub piece: Piece,
    pub kind: Kind,
    pub point: V3<T>,
    pub dir: V3<T>,
}

#[derive(Clone, Debug)]
pub struct SysPath<T> {
    pub status: Status,
    pub events: Vec<Event<T>>,
    pub reflections: u32,
    /// Smallest distance, over the events, from the point met to a border of
    /// its piece (cap rim, ring radii, edge ends), over the system length:
    /// where which piece is met is decided by the last bits.
    pub margin: f64,
    /// Roots on a sphere's far branch (within its aperture radius) that were
    /// passed over: these rays test the branch choice.
    pub far_branch_roots: u32,
}

impl<T: Real> SysPath<T> {
    /// The last refraction of a transmitted ray.
    pub fn exit(&self) -> Option<&Event<T>> {
        (self.status == Status::Transmitted)
            .then(|| self.events.last())
            .flatten()
    }
}

/// A surface in the working arithmetic.
#[derive(Clone, Copy, Debug)]
pub struct Surf<T> {
    pub radius: T,
    pub plane: bool,
    /// Vertex position along the light from the first vertex.
    pub z: T,
    pub a: T,
    pub stop: bool,
    pub medium: Medium,
}

/// The system in the working arithmetic: first vertex, unit light direction
/// `w = −axis`, the surfaces.
#[derive(Clone, Debug)]
pub struct System<T> {
    pub vertex: V3<T>,
    pub w: V3<T>,
    pub surfaces: Vec<Surf<T>>,
}

/// A boundary piece, ready to intersect.
#[derive(Clone, Copy, Debug)]
enum Shape<T> {
    Cap {
        k: usize,
    },
    Annulus {
        k: usize,
        piece: Piece,
        z: T,
        inner: T,
        outer: T,
    },
    Cylinder {
        k: usize,
        rho: T,
        z0: T,
        z1: T,
    },
}

fn sign<T: Real>(x: T) -> T {
    T::of(if x < T::of(0.0) { -1.0 } else { 1.0 })
}

fn min<T: Real>(a: T, b: T) -> T {
    if a < b { a } else { b }
}

fn max<T: Real>(a: T, b: T) -> T {
    if a > b { a } else { b }
}

impl<T: Real> System<T> {
    pub fn new(spec: &SystemSpec) -> Self {
        let t: Vec<T> = spec.surfaces.iter().map(|s| T::of(s.thickness)).collect();
        Self::with_pose(V3::of(spec.vertex), V3::of(spec.axis), &spec.surfaces, &t)
    }

    /// From a first vertex and thicknesses already in `T` (for the check
    /// against the biconvex reference, whose vertex is `C + a·sag1` in DD).
    pub fn with_pose(vertex: V3<T>, axis: V3<T>, specs: &[SurfaceSpec], thickness: &[T]) -> Self {
        let mut z = T::of(0.0);
        let mut surfaces = Vec::new();
        for (s, t) in specs.iter().zip(thickness) {
            surfaces.push(Surf {
                radius: T::of(s.radius),
                plane: s.radius == 0.0 || s.radius.is_infinite(),
                z,
                a: T::of(s.semi_aperture),
                stop: s.stop,
                medium: s.n,
            });
            z = z + *t;
        }
        System {
            vertex,
            w: -axis.normalize(),
            surfaces,
        }
    }

    pub fn centre(&self, k: usize) -> V3<T> {
        let s = &self.surfaces[k];
        self.vertex + self.w.scale(s.z + s.radius)
    }

    /// `z` along the light from the first vertex, and the transverse part.
    pub fn local(&self, x: V3<T>) -> (T, V3<T>) {
        let q = x - self.vertex;
        let z = q.dot(self.w);
        (z, q - self.w.scale(z))
    }

    fn medium_before(&self, k: usize) -> Medium {
        if k == 0 {
            Medium::AIR
        } else {
            self.surfaces[k - 1].medium
        }
    }

    /// Sag of surface `k` at radius `r ≤ |R|`: `R − sign(R)·√(R² − r²)`,
    /// written as `sign(R)·r²/(|R| + √((|R| − r)(|R| + r)))`.
    pub fn sag(&self, k: usize, r: T) -> T {
        let s = &self.surfaces[k];
        if s.plane {
            return T::of(0.0);
        }
        let big = s.radius * sign(s.radius);
        sign(s.radius) * r * r / (big + ((big - r) * (big + r)).sqrt())
    }

    /// Rim radius of cell `k` if it is glass.
    pub fn rim(&self, k: usize) -> Option<T> {
        let s = &self.surfaces;
        (k + 1 < s.len() && !s[k].medium.is_air()).then(|| max(s[k].a, s[k + 1].a))
    }

    fn ring_outer(&self, k: usize) -> Option<T> {
        if self.surfaces[k].stop {
            let mut m = T::of(0.0);
            for s in &self.surfaces {
                m = max(m, s.a);
            }
            return Some(m);
        }
        let before = if k > 0 { self.rim(k - 1) } else { None };
        match (before, self.rim(k)) {
            (Some(a), Some(b)) => Some(max(a, b)),
            (a, b) => a.or(b),
        }
    }

    /// Every piece of the boundary at wavelength `lambda_um`.
    fn pieces(&self, lambda_um: f64) -> Vec<Shape<T>> {
        let mut out = Vec::new();
        for (k, s) in self.surfaces.iter().enumerate() {
            let before = self.medium_before(k).index::<T>(lambda_um);
            let after = s.medium.index::<T>(lambda_um);
            if before != after {
                out.push(Shape::Cap { k });
            }
            if let Some(outer) = self.ring_outer(k).filter(|&o| o > s.a) {
                let piece = if s.stop { Piece::Stop } else { Piece::Ring };
                let z = s.z + self.sag(k, s.a);
                out.push(Shape::Annulus {
                    k,
                    piece,
                    z,
                    inner: s.a,
                    outer,
                });
            }
            if let Some(rho) = self.rim(k) {
                let z0 = s.z + self.sag(k, s.a);
                let z1 = self.surfaces[k + 1].z + self.sag(k + 1, self.surfaces[k + 1].a);
                out.push(Shape::Cylinder { k, rho, z0, z1 });
            }
        }
        out
    }

    /// True when `x` is inside (or on) a glass element.
    pub fn inside_glass(&self, x: V3<T>) -> bool {
        let (z, tr) = self.local(x);
        let r = tr.length();
        (0..self.surfaces.len()).any(|k| {
            self.rim(k).is_some_and(|rho| {
                let (f, b) = (&self.surfaces[k], &self.surfaces[k + 1]);
                let front = f.z + self.sag(k, min(r, f.a));
                let back = b.z + self.sag(k + 1, min(r, b.a));
                r <= rho && front <= z && z <= back
            })
        })
    }

    /// The unit normal of cap `k` at `x` towards the object side.
    fn cap_normal(&self, k: usize, x: V3<T>) -> V3<T> {
        let s = &self.surfaces[k];
        if s.plane {
            -self.w
        } else {
            (x - self.centre(k)).normalize().scale(sign(s.radius))
        }
    }
}

/// Where `p + t·u` meets the plane `z = zp` (local), for `t > 0`.
fn plane_t<T: Real>(sys: &System<T>, p: V3<T>, u: V3<T>, zp: T) -> Option<T> {
    let (z, _) = sys.local(p);
    let along = u.dot(sys.w);
    if along == T::of(0.0) {
        return None;
    }
    let t = (zp - z) / along;
    (t > T::of(0.0)).then_some(t)
}

/// The nearest crossing of `shape` ahead (`t > 0`); `on` is the surface
/// whose cap the ray starts from, whose root at the start is no crossing.
/// Counts passed-over far-branch roots in `far`.
fn hit<T: Real>(sys: &System<T>, shape: &Shape<T>, p: V3<T>, u: V3<T>, on: Option<usize>, far: &mut u32) -> Option<T> {
    let zero = T::of(0.0);
    let in_radius = |x: V3<T>, lo: Option<T>, hi: T| {
        let tr = sys.local(x).1;
        let r2 = tr.dot(tr);
        r2 <= hi * hi && lo.is_none_or(|lo| r2 > lo * lo)
    };
    match *shape {
        Shape::Cap { k } => {
            let s = &sys.surfaces[k];
            if s.plane {
                if on == Some(k) {
                    return None;
                }
                return plane_t(sys, p, u, s.z).filter(|&t| in_radius(p + u.scale(t), None, s.a));
            }
            let c = sys.centre(k);
            let b = (p - c).dot(u);
            let roots = if on == Some(k) {
                [-(b + b), -(b + b)]
            } else {
                let cc = (p - c).dot(p - c) - s.radius * s.radius;
                let disc = b * b - cc;
                if disc < zero {
                    return None;
                }
                let q = -(b + sign(b) * disc.sqrt());
                if q == zero {
                    return None;
                }
                let (t1, t2) = (q, cc / q);
                if t1 < t2 { [t1, t2] } else { [t2, t1] }
            };
            for t in roots.into_iter().filter(|&t| t > zero) {
                let x = p + u.scale(t);
                if in_radius(x, None, s.a) {
                    if (x - c).dot(sys.w) * s.radius < zero {
                        return Some(t);
                    }
                    *far += 1;
                }
            }
            None
        }
        Shape::Annulus { k, z, inner, outer, .. } => {
            if on == Some(k) && sys.surfaces[k].plane {
                return None;
            }
            plane_t(sys, p, u, z).filter(|&t| in_radius(p + u.scale(t), Some(inner), outer))
        }
        Shape::Cylinder { rho, z0, z1, .. } => {
            let (_, pt) = sys.local(p);
            let ut = u - sys.w.scale(u.dot(sys.w));
            let (a, b, c) = (ut.dot(ut), pt.dot(ut), pt.dot(pt) - rho * rho);
            let disc = b * b - a * c;
            if a == zero || disc < zero {
                return None;
            }
            let s = disc.sqrt();
            [(-b - s) / a, (-b + s) / a].into_iter().find(|&t| {
                let z = sys.local(p + u.scale(t)).0;
                t > zero && z0 <= z && z <= z1
            })
        }
    }
}

/// Distance from `x` on `shape` to the nearest border of the piece.
fn border_distance<T: Real>(sys: &System<T>, shape: &Shape<T>, x: V3<T>) -> f64 {
    let (z, tr) = sys.local(x);
    let r = tr.length();
    let d = match *shape {
        Shape::Cap { k } => (r - sys.surfaces[k].a).to_f64().abs(),
        Shape::Annulus { inner, outer, .. } => min(r - inner, outer - r).to_f64(),
        Shape::Cylinder { z0, z1, .. } => min(z - z0, z1 - z).to_f64(),
    };
    d.abs()
}

/// Traces the ray `origin + t·dir` (dir need not be unit) at `lambda_um`.
pub fn trace<T: Real>(sys: &System<T>, origin: [f64; 3], dir: [f64; 3], lambda_um: f64) -> SysPath<T> {
    trace_from(sys, V3::of(origin), V3::of(dir).normalize(), lambda_um)
}

/// Traces from `p` (in air, outside every element) in the unit direction `u`.
pub fn trace_from<T: Real>(sys: &System<T>, mut p: V3<T>, mut u: V3<T>, lambda_um: f64) -> SysPath<T> {
    let pieces = sys.pieces(lambda_um);
    let scale = {
        let (first, last) = (sys.surfaces[0].z, sys.surfaces[sys.surfaces.len() - 1].z);
        let mut m = (last - first).to_f64().abs();
        for s in &sys.surfaces {
            m = m.max(s.a.to_f64());
        }
        m
    };
    let mut path = SysPath {
        status: Status::Miss,
        events: Vec::new(),
        reflections: 0,
        margin: f64::INFINITY,
        far_branch_roots: 0,
    };
    let mut on = None;
    loop {
        let mut best: Option<(T, &Shape<T>)> = None;
        for shape in &pieces {
            if let Some(t) = hit(sys, shape, p, u, on, &mut path.far_branch_roots) {
                if best.is_none_or(|(bt, _)| t < bt) {
                    best = Some((t, shape));
                }
            }
        }
        let Some((t, shape)) = best else {
            if !path.events.is_empty() {
                path.status = Status::Transmitted;
            }
            return path;
        };
        let x = p + u.scale(t);
        path.margin = path.margin.min(border_distance(sys, shape, x) / scale);
        let (k, piece) = match *shape {
            Shape::Cap { k } => (k, Piece::Cap),
            Shape::Annulus { k, piece, .. } => (k, piece),
            Shape::Cylinder { k, .. } => (k, Piece::Edge),
        };
        if piece != Piece::Cap {
            path.events.push(Event {
                surface: k,
                piece,
                kind: Kind::Absorb,
                point: x,
                dir: u,
            });
            path.status = Status::Absorbed;
            return path;
        }
        let m = sys.cap_normal(k, x);
        let n_before = sys.medium_before(k).index::<T>(lambda_um);
        let n_after = sys.surfaces[k].medium.index::<T>(lambda_um);
        let (n1, n2, nrm) = if u.dot(m) < T::of(0.0) {
            (n_before, n_after, m)
        } else {
            (n_after, n_before, -m)
        };
        let (kind, v) = match snell(u, nrm, n1 / n2) {
            Some(v) => (Kind::Refract, v),
            None => {
                if path.reflections >= MAX_REFLECTIONS {
                    path.status = Status::Trapped;
                    return path;
                }
                path.reflections += 1;
                (Kind::Reflect, (u - nrm.scale(T::of(2.0) * u.dot(nrm))).normalize())
            }
        };
        path.events.push(Event {
            surface: k,
            piece,
            kind,
            point: x,
            dir: v,
        });
        (p, u, on) = (x, v, Some(k));
    }
}

// ---------------------------------------------------------------------------
// Paraxial (y–nu) trace
// ---------------------------------------------------------------------------

/// Paraxial data, lengths along the light: `h` the front principal plane
/// from V1, `h_rear` the rear one from the last vertex, `ffd` the front
/// focus *before* V1, `bfd` the back focus after the last vertex. `None`
/// (all) for a system without power.
#[derive(Clone, Copy, Debug)]
pub struct Paraxial<T> {
    pub efl: T,
    pub bfd: T,
    pub ffd: T,
    pub h: T,
    pub h_rear: T,
}

/// `(c_k, n_k after, t_k after)` per surface; the medium before the first
/// is air.
fn ynu_back_focus<T: Real>(surfaces: &[(T, T, T)]) -> Option<(T, T)> {
    let (mut y, mut nu, mut n) = (T::of(1.0), T::of(0.0), T::of(1.0));
    for (i, &(c, n2, t)) in surfaces.iter().enumerate() {
        // n'u' = nu − y(n' − n)c
        nu = nu - y * (n2 - n) * c;
        n = n2;
        if i + 1 < surfaces.len() {
            y = y + t * nu / n;
        }
    }
    let u = nu / n;
    if u == T::of(0.0) {
        return None;
    }
    // EFL = −y₁/u′ (y₁ = 1), BFD = −y_last/u′.
    Some((-T::of(1.0) / u, -y / u))
}

pub fn paraxial<T: Real>(spec: &SystemSpec, lambda_um: f64) -> Option<Paraxial<T>> {
    let s = &spec.surfaces;
    let curv = |r: f64| {
        if r == 0.0 || r.is_infinite() {
            T::of(0.0)
        } else {
            T::of(1.0) / T::of(r)
        }
    };
    let forward: Vec<(T, T, T)> = s
        .iter()
        .map(|x| (curv(x.radius), x.n.index::<T>(lambda_um), T::of(x.thickness)))
        .collect();
    // Reversed: surface N−1−j, curvature negated, the medium after it the
    // one before the original, the gap after it the original's gap before.
    let n = s.len();
    let backward: Vec<(T, T, T)> = (0..n)
        .map(|j| {
            let k = n - 1 - j;
            let gap = if k > 0 { T::of(s[k - 1].thickness) } else { T::of(0.0) };
            (-curv(s[k].radius), spec.before(k).index::<T>(lambda_um), gap)
        })
        .collect();
    let (efl, bfd) = ynu_back_focus(&forward)?;
    let (_, ffd) = ynu_back_focus(&backward)?;
    Some(Paraxial {
        efl,
        bfd,
        ffd,
        h: efl - ffd,
        h_rear: bfd - efl,
    })
}
