//! Seeded, deterministic lens-system cases for `tests/system_exact.rs`:
//! systems (docs/lens-systems.md) in several poses and scales, each with
//! rays given as f64 origin/direction. Rays are made in plain f64 (only the
//! reference traces them) and always start at least `3·(L + ρmax)` from a
//! point of the system's bounding cylinder, so outside every element.

use super::system::{Medium, SurfaceSpec, SystemSpec};

pub const F_LINE_UM: f64 = 0.4861327;
pub const C_LINE_UM: f64 = 0.6562725;

#[derive(Clone, Debug)]
pub struct RaySpec {
    pub id: String,
    pub origin: [f64; 3],
    pub direction: [f64; 3],
    pub wavelength_um: Option<f64>,
}

#[derive(Clone, Debug)]
pub struct Case {
    pub id: String,
    pub system: SystemSpec,
    pub rays: Vec<RaySpec>,
}

/// SplitMix64: a small deterministic generator, independent of the crate.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn f(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.f()
    }
}

type P3 = [f64; 3];

fn add(a: P3, b: P3) -> P3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn mul(a: P3, s: f64) -> P3 {
    [a[0] * s, a[1] * s, a[2] * s]
}
fn dot(a: P3, b: P3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: P3, b: P3) -> P3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn unit(a: P3) -> P3 {
    mul(a, 1.0 / dot(a, a).sqrt())
}

/// The system in f64 for making rays: frame (e1, e2, w = −axis), vertex
/// positions, extent.
pub struct Frame {
    vertex: P3,
    e1: P3,
    e2: P3,
    w: P3,
    z: Vec<f64>,
    zmin: f64,
    zmax: f64,
    rho: f64,
    /// Distance of every ray's origin from its target.
    far: f64,
}

/// `sag` of a surface of signed radius `r` (0 = plane) at height `h`.
pub fn sag(r: f64, h: f64) -> f64 {
    if r == 0.0 {
        return 0.0;
    }
    let c = 1.0 / r;
    c * h * h / (1.0 + (1.0 - c * c * h * h).max(0.0).sqrt())
}

impl Frame {
    pub fn new(s: &SystemSpec) -> Self {
        let w = unit(mul(s.axis, -1.0));
        let helper = if w[0].abs() < 0.6 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        let e1 = unit(cross(w, helper));
        let e2 = cross(w, e1);
        let mut z = Vec::new();
        let mut acc = 0.0;
        for surf in &s.surfaces {
            z.push(acc);
            acc += surf.thickness;
        }
        let ends = s
            .surfaces
            .iter()
            .zip(&z)
            .flat_map(|(f, &zk)| [zk, zk + sag(f.radius, f.semi_aperture)]);
        let zmin = ends.clone().fold(f64::INFINITY, f64::min);
        let zmax = ends.fold(f64::NEG_INFINITY, f64::max);
        let rho = s.surfaces.iter().map(|f| f.semi_aperture).fold(0.0, f64::max);
        Frame {
            vertex: s.vertex,
            e1,
            e2,
            w,
            z,
            zmin,
            zmax,
            rho,
            far: 3.0 * (zmax - zmin + rho),
        }
    }

    /// World point of local `(x, y, z)`.
    pub fn world(&self, x: f64, y: f64, z: f64) -> P3 {
        add(self.vertex, add(mul(self.e1, x), add(mul(self.e2, y), mul(self.w, z))))
    }

    /// World direction of local `(x, y, z)`.
    pub fn dir(&self, x: f64, y: f64, z: f64) -> P3 {
        add(mul(self.e1, x), add(mul(self.e2, y), mul(self.w, z)))
    }

    pub fn vertex_z(&self, k: usize) -> f64 {
        self.z[k]
    }
}

/// A ray towards `target` (local) along the local direction `d`, starting
/// `f.far` before it.
fn toward(f: &Frame, target: P3, d: P3) -> (P3, P3) {
    let d = unit(d);
    let o = [
        target[0] - f.far * d[0],
        target[1] - f.far * d[1],
        target[2] - f.far * d[2],
    ];
    (f.world(o[0], o[1], o[2]), f.dir(d[0], d[1], d[2]))
}

/// A direction tilted by `theta` from the local `±z`, azimuth `psi`.
fn tilted(theta: f64, psi: f64, forward: bool) -> P3 {
    let zc = if forward { theta.cos() } else { -theta.cos() };
    [theta.sin() * psi.cos(), theta.sin() * psi.sin(), zc]
}

/// Ray kinds a case mixes.
#[derive(Clone, Copy, Debug)]
pub enum RayKind {
    /// Aimed at the first (or last) vertex plane within `frac` of that
    /// surface's aperture, tilted up to `deg` degrees.
    Aimed { front: bool, frac: f64, deg: f64 },
    /// From anywhere around, aimed into the bounding cylinder.
    Any,
    /// From the side, across the axis.
    Side,
    /// At 75–89.5° to the normal of cap `k` at up to 0.95 of its aperture.
    Grazing { k: usize, front: bool },
    /// At 45–80° to the axis through cap `k` at 0.85–0.99 of its aperture.
    SteepRim { k: usize, front: bool },
}

fn make_ray(s: &SystemSpec, f: &Frame, rng: &mut Rng, kind: RayKind) -> (P3, P3) {
    let phi = rng.range(0.0, std::f64::consts::TAU);
    let psi = rng.range(0.0, std::f64::consts::TAU);
    let on_disc = |r: f64, z: f64| [r * phi.cos(), r * phi.sin(), z];
    match kind {
        RayKind::Aimed { front, frac, deg } => {
            let k = if front { 0 } else { s.surfaces.len() - 1 };
            let r = rng.f().sqrt() * frac * s.surfaces[k].semi_aperture;
            let theta = rng.f() * deg.to_radians();
            toward(f, on_disc(r, f.z[k]), tilted(theta, psi, front))
        }
        RayKind::Any | RayKind::Side => {
            let r = rng.f().sqrt() * 1.1 * f.rho;
            let target = on_disc(r, rng.range(f.zmin, f.zmax));
            let theta = match kind {
                RayKind::Side => rng.range(60f64, 120.0).to_radians(),
                _ => rng.range(-1.0, 1.0).acos(),
            };
            toward(f, target, tilted(theta, psi, true))
        }
        RayKind::Grazing { k, front } | RayKind::SteepRim { k, front } => {
            let (lo, hi, t_lo, t_hi) = match kind {
                RayKind::Grazing { .. } => (0.0, 0.95, 75.0, 89.5),
                _ => (0.85, 0.99, 45.0, 80.0),
            };
            let surf = s.surfaces[k];
            let r = rng.range(lo, hi) * surf.semi_aperture;
            let target = on_disc(r, f.z[k] + sag(surf.radius, r));
            // Normal towards the object side (local), from the sphere.
            let n = if surf.radius == 0.0 {
                [0.0, 0.0, -1.0]
            } else {
                let c = [0.0, 0.0, f.z[k] + surf.radius];
                mul(
                    unit([target[0] - c[0], target[1] - c[1], target[2] - c[2]]),
                    surf.radius.signum(),
                )
            };
            let theta = rng.range(t_lo, t_hi).to_radians();
            let d = match kind {
                RayKind::Grazing { .. } => {
                    // About the normal, on the incoming side.
                    let t1 = unit(cross(n, [psi.cos(), psi.sin(), 0.3]));
                    let t2 = cross(n, t1);
                    let s_in = if front { -1.0 } else { 1.0 };
                    let tang = add(mul(t1, psi.cos()), mul(t2, psi.sin()));
                    add(mul(n, s_in * theta.cos()), mul(tang, theta.sin()))
                }
                _ => tilted(theta, psi, front),
            };
            toward(f, target, d)
        }
    }
}

/// `count` rays of each kind in `kinds`, ids `prefix-i`.
pub fn rays(
    s: &SystemSpec,
    rng: &mut Rng,
    kinds: &[RayKind],
    count: usize,
    wavelengths: &[Option<f64>],
) -> Vec<RaySpec> {
    let f = Frame::new(s);
    let mut out = Vec::new();
    for (j, &kind) in kinds.iter().enumerate() {
        for i in 0..count {
            let (origin, direction) = make_ray(s, &f, rng, kind);
            out.push(RaySpec {
                id: format!("k{j}-{i}"),
                origin,
                direction,
                wavelength_um: wavelengths[(i + j) % wavelengths.len()],
            });
        }
    }
    out
}

// ---------------------------------------------------------------------------
// Systems
// ---------------------------------------------------------------------------

fn surf(radius: f64, thickness: f64, n: Medium, semi_aperture: f64) -> SurfaceSpec {
    SurfaceSpec {
        radius,
        thickness,
        n,
        semi_aperture,
        stop: false,
    }
}

const AIR: Medium = Medium::AIR;
const BK7: Medium = Medium::Glass("N-BK7");
const SF5: Medium = Medium::Glass("N-SF5");

pub fn plano_convex(convex_first: bool) -> Vec<SurfaceSpec> {
    if convex_first {
        vec![surf(25.0, 5.0, BK7, 10.0), surf(0.0, 0.0, AIR, 10.0)]
    } else {
        vec![surf(0.0, 5.0, BK7, 10.0), surf(-25.0, 0.0, AIR, 10.0)]
    }
}

pub fn biconcave() -> Vec<SurfaceSpec> {
    let n = Medium::Cauchy(1.5046, 0.0042);
    vec![surf(-20.0, 2.0, n, 8.0), surf(20.0, 0.0, AIR, 8.0)]
}

pub fn meniscus() -> Vec<SurfaceSpec> {
    vec![surf(15.0, 3.0, Medium::Index(1.6), 7.0), surf(30.0, 0.0, AIR, 7.0)]
}

/// N-BK7/N-SF5 cemented doublet; `stepped` gives the faces different
/// apertures, so that it has rings (one at the cemented surface).
pub fn doublet(stepped: bool) -> Vec<SurfaceSpec> {
    let a = if stepped { [12.7, 12.0, 11.5] } else { [12.7; 3] };
    vec![
        surf(61.9, 6.0, BK7, a[0]),
        surf(-44.3, 2.5, SF5, a[1]),
        surf(-128.9, 0.0, AIR, a[2]),
    ]
}

/// A doublet whose cemented surface is steep (its normal tilts up to 63°):
/// rays entering the N-SF5 from the back near the rim meet it beyond the
/// critical angle (65°) and reflect.
pub fn doublet_steep_cemented() -> Vec<SurfaceSpec> {
    vec![
        surf(40.0, 11.0, BK7, 12.0),
        surf(-13.5, 2.5, SF5, 12.0),
        surf(-60.0, 0.0, AIR, 12.0),
    ]
}

/// A singlet of index 4 (critical angle 14.5°), R 3 and −1.6, aperture 1,
/// edge 0.0011 long: rays reflect inside for long, some more than 64 times
/// (trapped).
pub fn index_4_singlet() -> Vec<SurfaceSpec> {
    vec![surf(3.0, 0.5237, Medium::Index(4.0), 1.0), surf(-1.6, 0.0, AIR, 1.0)]
}

/// A biconvex singlet behind a stop in air: the diaphragm vignettes.
pub fn stopped_singlet() -> Vec<SurfaceSpec> {
    let mut stop = surf(0.0, 5.0, AIR, 4.0);
    stop.stop = true;
    vec![stop, surf(30.0, 4.0, BK7, 8.0), surf(-30.0, 0.0, AIR, 8.0)]
}

/// pbrt's dgauss.50mm.dat (radius, thickness, n, aperture diameter).
pub fn double_gauss() -> Vec<SurfaceSpec> {
    const ROWS: [[f64; 4]; 11] = [
        [29.475, 3.76, 1.67, 25.2],
        [84.83, 0.12, 1.0, 25.2],
        [19.275, 4.025, 1.67, 23.0],
        [40.77, 3.275, 1.699, 23.0],
        [12.75, 5.705, 1.0, 18.0],
        [0.0, 4.5, 0.0, 17.1],
        [-14.495, 1.18, 1.603, 17.0],
        [40.77, 6.065, 1.658, 20.0],
        [-20.385, 0.19, 1.0, 20.0],
        [437.065, 3.22, 1.717, 20.0],
        [-39.73, 0.0, 1.0, 20.0],
    ];
    ROWS.iter()
        .map(|&[r, t, n, d]| SurfaceSpec {
            radius: r,
            thickness: t,
            n: Medium::Index(if n == 0.0 { 1.0 } else { n }),
            semi_aperture: d / 2.0,
            stop: n == 0.0,
        })
        .collect()
}

/// Every length times `k`.
pub fn scaled(s: Vec<SurfaceSpec>, k: f64) -> Vec<SurfaceSpec> {
    s.into_iter()
        .map(|f| SurfaceSpec {
            radius: f.radius * k,
            thickness: f.thickness * k,
            semi_aperture: f.semi_aperture * k,
            ..f
        })
        .collect()
}

/// Poses: (vertex, axis).
pub const NEAR: ([f64; 3], [f64; 3]) = ([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]);
pub const TILTED: ([f64; 3], [f64; 3]) = ([1.25, -3.5, 7.0], [0.36, -0.48, 0.8]);
pub const FAR: ([f64; 3], [f64; 3]) = ([2750.5, -1320.25, 4100.125], [-0.5, 0.45, -0.6]);
pub const FARTHER: ([f64; 3], [f64; 3]) = ([7000.0, -5000.0, 5000.0], [0.1, -0.2, -1.0]);

fn system(pose: ([f64; 3], [f64; 3]), surfaces: Vec<SurfaceSpec>) -> SystemSpec {
    SystemSpec {
        vertex: pose.0,
        axis: pose.1,
        surfaces,
    }
}

const D: Option<f64> = None;
const FRONT: RayKind = RayKind::Aimed {
    front: true,
    frac: 1.05,
    deg: 30.0,
};
const BACK: RayKind = RayKind::Aimed {
    front: false,
    frac: 1.05,
    deg: 30.0,
};

/// A case to make: id, system, kinds of rays (40 each), wavelengths.
type Entry<'a> = (&'a str, SystemSpec, Vec<RayKind>, &'a [Option<f64>]);

const DISPERSIVE: &[Option<f64>] = &[D, Some(F_LINE_UM), Some(C_LINE_UM), Some(0.45)];
const D_ONLY: &[Option<f64>] = &[D];

fn g(k: usize, front: bool) -> RayKind {
    RayKind::Grazing { k, front }
}

fn steep(k: usize, front: bool) -> RayKind {
    RayKind::SteepRim { k, front }
}

/// Singlets and doublets near the origin.
fn simple_entries() -> Vec<Entry<'static>> {
    vec![
        (
            "plano-convex",
            system(TILTED, plano_convex(true)),
            vec![FRONT, BACK, RayKind::Any, g(0, true), g(1, false)],
            DISPERSIVE,
        ),
        (
            "convex-plano",
            system(NEAR, plano_convex(false)),
            vec![FRONT, BACK, RayKind::Any, g(0, true), g(1, false)],
            D_ONLY,
        ),
        (
            "biconcave",
            system(TILTED, biconcave()),
            vec![
                FRONT,
                BACK,
                RayKind::Side,
                RayKind::Any,
                g(0, true),
                steep(0, true),
                steep(1, false),
            ],
            DISPERSIVE,
        ),
        (
            "meniscus",
            system(NEAR, meniscus()),
            vec![FRONT, BACK, RayKind::Any, g(0, true), steep(1, false)],
            D_ONLY,
        ),
        (
            "doublet",
            system(TILTED, doublet(false)),
            vec![FRONT, BACK, RayKind::Any, steep(0, true), steep(2, false), g(2, false)],
            DISPERSIVE,
        ),
        (
            "doublet-steep-cemented",
            system(TILTED, doublet_steep_cemented()),
            vec![FRONT, BACK, RayKind::Any, steep(2, false), g(2, false)],
            DISPERSIVE,
        ),
        (
            "doublet-stepped",
            system(NEAR, doublet(true)),
            vec![
                FRONT,
                BACK,
                RayKind::Side,
                RayKind::Any,
                steep(0, true),
                steep(2, false),
            ],
            D_ONLY,
        ),
        (
            "index-4-singlet",
            system(TILTED, index_4_singlet()),
            vec![
                FRONT,
                RayKind::Any,
                RayKind::Any,
                RayKind::Any,
                g(0, true),
                steep(1, false),
                steep(1, false),
            ],
            D_ONLY,
        ),
    ]
}

/// Stops, the double-Gauss, index 4, scaled and far systems.
fn compound_entries() -> Vec<Entry<'static>> {
    vec![
        (
            "stopped-singlet",
            system(TILTED, stopped_singlet()),
            vec![FRONT, BACK, RayKind::Any, RayKind::Side],
            D_ONLY,
        ),
        (
            "double-gauss",
            system(NEAR, double_gauss()),
            vec![FRONT, BACK, RayKind::Any, RayKind::Side, g(0, true)],
            D_ONLY,
        ),
        (
            "double-gauss-far",
            system(FAR, double_gauss()),
            vec![FRONT, BACK, RayKind::Any],
            D_ONLY,
        ),
        (
            "tiny-doublet-far",
            system(FAR, scaled(doublet(true), 1e-3)),
            vec![FRONT, BACK, RayKind::Any, steep(2, false)],
            D_ONLY,
        ),
        (
            "tiny-double-gauss",
            system(TILTED, scaled(double_gauss(), 1e-3)),
            vec![FRONT, BACK, RayKind::Any],
            D_ONLY,
        ),
        (
            "large-double-gauss",
            system(TILTED, scaled(double_gauss(), 1e3)),
            vec![FRONT, BACK, RayKind::Any],
            D_ONLY,
        ),
        (
            "large-doublet-farther",
            system(FARTHER, scaled(doublet(false), 1e3)),
            vec![FRONT, RayKind::Any, steep(2, false)],
            D_ONLY,
        ),
        (
            "meniscus-farther",
            system(FARTHER, meniscus()),
            vec![FRONT, BACK, RayKind::Any, g(0, true)],
            D_ONLY,
        ),
        (
            "tiny-biconcave-farther",
            system(FARTHER, scaled(biconcave(), 1e-3)),
            vec![FRONT, RayKind::Side, g(0, true)],
            DISPERSIVE,
        ),
    ]
}

/// Every case, from `seed`.
pub fn cases(seed: u64) -> Vec<Case> {
    let mut rng = Rng::new(seed);
    let mut list = simple_entries();
    list.extend(compound_entries());
    list.into_iter()
        .map(|(id, system, kinds, waves)| {
            let rays = rays(&system, &mut rng, &kinds, 40, waves);
            Case {
                id: id.to_string(),
                system,
                rays,
            }
        })
        .collect()
}
