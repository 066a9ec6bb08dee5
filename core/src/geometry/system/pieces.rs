//! The pieces of a system's boundary (docs/lens-systems.md): optical caps,
//! opaque rings (the stop's diaphragm among them) and opaque edge
//! cylinders, and the nearest crossing of any of them along a ray.

use super::{LensSystem, sag};
use glam::DVec3;

/// What a piece of the boundary is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PieceKind {
    /// The spherical (or plane) face of surface `k` within its aperture.
    Cap,
    /// The flat annulus of surface `k` beyond its aperture, or the stop's
    /// diaphragm: opaque.
    Ring,
    /// The cylindrical edge of the element after surface `k`: opaque.
    Edge,
}

/// One piece: its kind and surface (for an edge, the surface before the
/// element).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Piece {
    pub surface: usize,
    pub kind: PieceKind,
}

impl Piece {
    /// The part number a [`crate::geometry::Hit`] carries: `3·k + kind`.
    pub fn part(self) -> u8 {
        let kind = match self.kind {
            PieceKind::Cap => 0,
            PieceKind::Ring => 1,
            PieceKind::Edge => 2,
        };
        (3 * self.surface + kind) as u8
    }

    pub fn from_part(part: u8) -> Piece {
        let kind = match part % 3 {
            0 => PieceKind::Cap,
            1 => PieceKind::Ring,
            _ => PieceKind::Edge,
        };
        Piece {
            surface: usize::from(part / 3),
            kind,
        }
    }

    /// Whether the piece absorbs what meets it.
    pub fn is_opaque(self) -> bool {
        self.kind != PieceKind::Cap
    }
}

/// A crossing of the boundary: at `t` along the ray, on `piece`, at the
/// local point `x`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Crossing {
    pub t: f64,
    pub piece: Piece,
    pub x: DVec3,
}

/// The two roots of `a·t² + 2b·t + c = 0` (NaN where there is none), the
/// larger-magnitude one from `q = −(b + sign(b)·√(b² − ac))` and the other
/// as `c/q`, so neither cancels.
#[inline(always)]
fn roots(a: f64, b: f64, c: f64) -> [f64; 2] {
    let disc = b * b - a * c;
    if !(disc >= 0.0) {
        return [f64::NAN; 2];
    }
    let q = -(b + disc.sqrt().copysign(b));
    [c / q, q / a]
}

/// The nearest crossing found so far on `(t_lo, t_hi)`: `t` starts at
/// `t_hi` (none found), so that a crossing is taken where `t_lo < t < t`
/// (a lane's search keeps one a lane, [`super::lanes`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct Nearest {
    pub t: f64,
    pub piece: Piece,
    pub x: DVec3,
    pub t_lo: f64,
}

impl Nearest {
    /// None found yet on `(t_lo, t_hi)`.
    #[inline(always)]
    pub fn new(t_lo: f64, t_hi: f64) -> Nearest {
        Nearest {
            t: t_hi,
            piece: Piece {
                surface: 0,
                kind: PieceKind::Cap,
            },
            x: DVec3::ZERO,
            t_lo,
        }
    }

    /// Whether a crossing was taken (every one taken lies below `t_hi`).
    #[inline(always)]
    pub fn found(&self, t_hi: f64) -> bool {
        self.t < t_hi
    }

    /// The crossing taken, if any (below `t_hi`).
    #[inline(always)]
    pub fn crossing(&self, t_hi: f64) -> Option<Crossing> {
        self.found(t_hi).then_some(Crossing {
            t: self.t,
            piece: self.piece,
            x: self.x,
        })
    }

    /// Takes the crossing at `t` if it is one (`ok`) and the nearest so far.
    #[inline(always)]
    fn take(&mut self, ok: bool, t: f64, piece: Piece, x: DVec3) {
        if ok && t > self.t_lo && t < self.t {
            (self.t, self.piece, self.x) = (t, piece, x);
        }
    }
}

/// What [`LensSystem::next_crossing`] reads of one surface, side by side
/// (it read eight arrays, each with its bounds check, and computed each
/// ring plane's sag, a square root, at every test).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct Face {
    /// Vertex `z_k`, curvature `c_k`, semi-aperture.
    z: f64,
    c: f64,
    a: f64,
    /// The plane of the ring: the sag at the aperture.
    ring_z: f64,
    /// The ring's (or diaphragm's) outer radius; no ring unless above `a`.
    ring_outer: f64,
    /// The rim radius of the cell after the surface (0: air, no edge),
    /// and the planes of its two rings, this surface's then the next's.
    rim: f64,
    edge: (f64, f64),
    /// The extent along the axis of the cap and ring, in order.
    span: (f64, f64),
    /// The least `z` of any piece of this surface and after (caps, rings,
    /// edges), and the greatest of any of it and before: a ray walking
    /// toward `+z` whose stretch ahead ends before the first (toward
    /// `−z`: after the second) meets none of them.
    reach: (f64, f64),
    /// Whether the cap separates two media.
    boundary: bool,
}

impl Face {
    /// Whether a ray starting at `z = start` and walking toward `+z`
    /// (`forward`) or `−z` has every piece of this surface (and of those
    /// before it, in its direction) behind it.
    #[inline(always)]
    pub(super) fn skipped(&self, start: f64, forward: bool) -> bool {
        if forward {
            self.reach.1 < start
        } else {
            self.reach.0 > start
        }
    }

    /// The extent along the axis of the edge after the surface.
    #[inline(always)]
    fn edge_span(&self) -> (f64, f64) {
        let (z0, z1) = self.edge;
        (z0.min(z1), z0.max(z1))
    }

    /// The extent of the surface's pieces (the edge after it included).
    fn extent(&self) -> (f64, f64) {
        let (mut lo, mut hi) = self.span;
        if self.rim > 0.0 {
            let (e0, e1) = self.edge_span();
            (lo, hi) = (lo.min(e0), hi.max(e1));
        }
        (lo, hi)
    }
}

/// Whether a ray from `p` along `u` covers, over `t` in `(t_lo, bound)`,
/// some `z` of the extent `(lo, hi)`. Without branches (`&`, `|` and
/// selects), so that the lanes' loop over it is vectorised.
#[inline(always)]
fn covers(p: DVec3, u: DVec3, t_lo: f64, bound: f64, (lo, hi): (f64, f64)) -> bool {
    let flat = (p.z >= lo) & (p.z <= hi);
    let (a, b) = (p.z + t_lo * u.z, p.z + bound * u.z);
    let (a, b) = if a <= b { (a, b) } else { (b, a) };
    let through = !((hi < a) | (lo > b));
    if u.z == 0.0 { flat } else { through }
}

impl LensSystem {
    /// The name of a piece as `lens trace` prints it.
    pub fn piece_name(&self, piece: Piece) -> &'static str {
        match piece.kind {
            PieceKind::Cap => "cap",
            PieceKind::Ring if self.surfaces[piece.surface].stop => "stop",
            PieceKind::Ring => "ring",
            PieceKind::Edge => "edge",
        }
    }

    /// Whether cap `k` separates two media (a stop's opening or a dummy
    /// surface in one medium is not a boundary).
    #[inline(always)]
    pub fn cap_is_boundary(&self, k: usize) -> bool {
        self.faces[k].boundary
    }

    /// The nearest crossing with `t` in `(t_lo, t_hi)` of the ray from the
    /// local point `p` along the unit `u`. `from` is the cap the ray starts
    /// on: its root at the start is not a crossing (of its two roots, the
    /// one nearer 0 is left out; a plane has only that one).
    pub fn next_crossing(&self, p: DVec3, u: DVec3, from: Option<usize>, t_lo: f64, t_hi: f64) -> Option<Crossing> {
        let mut best = Nearest::new(t_lo, t_hi);
        let faces = &self.faces[..];
        // Surfaces are walked in the ray's direction along z. Those whose
        // every piece lies behind the start are skipped at once: each would
        // fail the stretch test below (reach is monotone in k, so they are
        // a run at the start of the walk). A reflected ray restarting in
        // the middle of a double Gauss tested all eleven.
        let start = p.z + t_lo * u.z;
        let forward = u.z >= 0.0;
        let skip = if forward {
            faces.iter().take_while(|f| f.skipped(start, true)).count()
        } else {
            faces.iter().rev().take_while(|f| f.skipped(start, false)).count()
        };
        for i in skip..faces.len() {
            let k = if forward { i } else { faces.len() - 1 - i };
            if Self::face_step(k, &faces[k], (p, u), from, t_hi, &mut best) {
                break;
            }
        }
        best.crossing(t_hi)
    }

    /// [`LensSystem::next_crossing`]'s step at face `k` (`f`) of the walk,
    /// for the ray `(p, u)` and the crossing found so far, `best`: tests
    /// its cap and ring and the edge after it where
    /// [`LensSystem::face_gates`] would open them; true where the walk
    /// stops.
    #[inline(always)]
    fn face_step(
        k: usize,
        f: &Face,
        (p, u): (DVec3, DVec3),
        from: Option<usize>,
        t_hi: f64,
        best: &mut Nearest,
    ) -> bool {
        // The branches of [`LensSystem::face_gates`]: the scalar walk
        // computes what they open only (the lanes compute every gate).
        if Self::stops_at(f, (p, u), t_hi, best) {
            return true;
        }
        let bound = best.t;
        if covers(p, u, best.t_lo, bound, f.span) {
            Self::cap_and_ring(k, f, (p, u), from == Some(k), true, best);
        }
        if f.rim > 0.0 && covers(p, u, best.t_lo, bound, f.edge_span()) {
            Self::edge(k, f, (p, u), true, best);
        }
        false
    }

    /// What the walk does at face `f` for the ray `(p, u)` at this face of
    /// its walk (`on`) with the crossing found so far `best`: whether it
    /// goes on ([`LensSystem::stops_at`]), tests the cap and ring, and
    /// tests the edge after it. A piece is tested only where the stretch
    /// of `z` the ray covers on `(t_lo, best)` reaches its span (exact:
    /// each piece lies within its span; up to a crossing, `best.t` is
    /// `t_hi`). The scalar walk and the lanes' ([`super::lanes`]) ask it.
    #[inline(always)]
    pub(super) fn face_gates(
        f: &Face,
        (p, u): (DVec3, DVec3),
        on: bool,
        t_hi: f64,
        best: &Nearest,
    ) -> (bool, bool, bool) {
        // `&` and `|` rather than `&&` and `||`: no branches (the lanes'
        // loop is vectorised); the values are the same.
        let go = on & !Self::stops_at(f, (p, u), t_hi, best);
        let bound = best.t;
        let cap = go & covers(p, u, best.t_lo, bound, f.span);
        let edge = go & (f.rim > 0.0) & covers(p, u, best.t_lo, bound, f.edge_span());
        (go, cap, edge)
    }

    /// Whether the walk stops at face `f`: a crossing is found (below
    /// `t_hi`) and every piece still to test lies beyond it, so none can
    /// be nearer. Not asked before a crossing is found: up to `t_hi` none
    /// is taken anyway, and a singlet's ray met its first surface without
    /// one (the test cost 4 % of its walk).
    #[inline(always)]
    fn stops_at(f: &Face, (p, u): (DVec3, DVec3), t_hi: f64, best: &Nearest) -> bool {
        let far = p.z + best.t * u.z;
        best.found(t_hi) & (((u.z > 0.0) & (f.reach.0 > far)) | ((u.z < 0.0) & (f.reach.1 < far)))
    }

    /// [`LensSystem::next_crossing`]'s test of cap `k` (face `f`) and its
    /// ring; `starts_here`: the ray starts on this cap; nothing is taken
    /// unless `gate`.
    #[inline(always)]
    pub(super) fn cap_and_ring(
        k: usize,
        f: &Face,
        (p, u): (DVec3, DVec3),
        starts_here: bool,
        gate: bool,
        best: &mut Nearest,
    ) {
        if f.boundary {
            let mut ts = Self::cap_roots(f, p, u);
            // The root at the start is the smaller in magnitude.
            let second = !(ts[1].abs() >= ts[0].abs());
            if starts_here && second {
                ts[1] = f64::NAN;
            }
            if starts_here && !second {
                ts[0] = f64::NAN;
            }
            for t in ts {
                let x = p + t * u;
                let piece = Piece {
                    surface: k,
                    kind: PieceKind::Cap,
                };
                best.take(gate && Self::on_cap(f, x), t, piece, x);
            }
        }
        if f.ring_outer > f.a {
            let t = (f.ring_z - p.z) / u.z;
            let x = p + t * u;
            let r2 = x.x * x.x + x.y * x.y;
            let (a, o) = (f.a, f.ring_outer);
            let piece = Piece {
                surface: k,
                kind: PieceKind::Ring,
            };
            best.take(
                gate && r2 > a * a && r2 <= o * o,
                t,
                piece,
                DVec3::new(x.x, x.y, f.ring_z),
            );
        }
    }

    /// [`LensSystem::next_crossing`]'s test of the edge after surface `k`;
    /// nothing is taken unless `gate`.
    #[inline(always)]
    pub(super) fn edge(k: usize, f: &Face, (p, u): (DVec3, DVec3), gate: bool, best: &mut Nearest) {
        let (z0, z1) = f.edge;
        for t in Self::edge_roots(f.rim, p, u) {
            let x = p + t * u;
            let piece = Piece {
                surface: k,
                kind: PieceKind::Edge,
            };
            best.take(gate && x.z >= z0 && x.z <= z1, t, piece, x);
        }
    }

    /// Each surface's [`Face`]: what the walk reads, the reach included.
    pub(super) fn faces_of_pieces(&self) -> Vec<Face> {
        let n = self.len();
        let mut faces: Vec<Face> = (0..n)
            .map(|k| {
                let (z, rz) = (self.z[k], self.ring_z(k));
                Face {
                    z,
                    c: self.c[k],
                    a: self.surfaces[k].semi_aperture,
                    ring_z: rz,
                    ring_outer: self.ring_outer[k],
                    rim: self.rim[k],
                    edge: if k + 1 < n { (rz, self.ring_z(k + 1)) } else { (rz, rz) },
                    span: (z.min(rz), z.max(rz)),
                    reach: (f64::INFINITY, f64::NEG_INFINITY),
                    boundary: self.before(k) != self.surfaces[k].n,
                }
            })
            .collect();
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for k in (0..n).rev() {
            lo = lo.min(faces[k].extent().0);
            faces[k].reach.0 = lo;
        }
        for f in faces.iter_mut() {
            hi = hi.max(f.extent().1);
            f.reach.1 = hi;
        }
        faces
    }

    /// The roots along `p + t·u` of the sphere of face `f` in vertex form,
    /// `c(x² + y² + (z − z_k)²) − 2(z − z_k) = 0`: `A = c·|u|²`,
    /// `B = c·(q·u) − u_z`, `C = c·|q|² − 2q_z` with `q = p − z_k·ẑ`.
    /// A plane (`c = 0`) has the one root `C/(−2B)`.
    #[inline(always)]
    fn cap_roots(f: &Face, p: DVec3, u: DVec3) -> [f64; 2] {
        let c = f.c;
        let q = DVec3::new(p.x, p.y, p.z - f.z);
        roots(
            c * u.length_squared(),
            c * q.dot(u) - u.z,
            c * q.length_squared() - 2.0 * q.z,
        )
    }

    /// Whether the local point `x` of face `f`'s sphere lies on its cap:
    /// within the aperture, on the vertex's branch (`c·(z − z_k) < 1`).
    #[inline(always)]
    fn on_cap(f: &Face, x: DVec3) -> bool {
        let a = f.a;
        x.x * x.x + x.y * x.y <= a * a && f.c * (x.z - f.z) < 1.0
    }

    /// The plane of surface `k`'s ring: its sag at the aperture.
    #[inline(always)]
    pub(super) fn ring_z(&self, k: usize) -> f64 {
        self.z[k] + sag(self.c[k], self.surfaces[k].semi_aperture)
    }

    /// The roots along `p + t·u` of the cylinder `x² + y² = ρ²`.
    #[inline(always)]
    fn edge_roots(rho: f64, p: DVec3, u: DVec3) -> [f64; 2] {
        let a = u.x * u.x + u.y * u.y;
        let c = (p.x - rho) * (p.x + rho) + p.y * p.y;
        roots(a, p.x * u.x + p.y * u.y, c)
    }

    /// The unit normal of cap `k` at the local point `x`, pointing to the
    /// side before the surface: `(c·x, c·y, c·(z − z_k) − 1)`, of length 1
    /// on the sphere (normalised for rounding).
    #[inline(always)]
    pub fn cap_normal(&self, k: usize, x: DVec3) -> DVec3 {
        let c = self.c[k];
        DVec3::new(c * x.x, c * x.y, c * (x.z - self.z[k]) - 1.0).normalize()
    }

    /// The normal (local) at `x` on `piece` pointing out of the solid: to
    /// the air side of a cap or ring, away from the axis on an edge.
    pub fn outward_normal(&self, piece: Piece, x: DVec3) -> DVec3 {
        let k = piece.surface;
        let glass_before = !super::is_air(&self.before(k));
        match piece.kind {
            PieceKind::Cap => {
                let g = self.cap_normal(k, x);
                if glass_before { -g } else { g }
            }
            PieceKind::Ring => {
                if glass_before && k > 0 && self.rim[k] == 0.0 {
                    DVec3::Z
                } else {
                    -DVec3::Z
                }
            }
            PieceKind::Edge => DVec3::new(x.x, x.y, 0.0).normalize_or(DVec3::X),
        }
    }
}
