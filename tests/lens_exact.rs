//! `Lens::trace` against an independent double-double reference tracer
//! (`tests/reference`), case by stiff case.
//!
//! Tolerance (the spec): positions within `1e-9·d + 64·ε·max|coordinate|` of
//! the reference point, unit directions within 1e-9 (Euclidean), and the
//! status, faces and number of total internal reflections exactly equal.
//!
//! The reference solves the centre form `|o + t·u − c|² = R²` in
//! double-double; the same code in plain `f64` is the *naive* tracer, and the
//! flat-face and tiny-far-lens tests assert that it misses the tolerance, so
//! they are known to test something.
//!
//! Excused, and counted and bounded in every test:
//! - a ray whose path meets a face within `rim_skip` of the rim (`|ρ − d/2|`
//!   tiny, ρ the distance from the axis), where S1 and S2 meet at an edge and
//!   which face is hit is decided by the last bits;
//! - only for a ray on which `Lens::trace` differs from the reference: an
//!   *ill-conditioned* path, one whose exact exit moves by more than
//!   `ILL_CONDITIONED` of the tolerances when its start inside the glass is
//!   nudged by one rounding at the lens's own scale (ε·d, ε). That is decided
//!   on the reference alone (`internal_conditioning`) and concerns long
//!   chains of total internal reflections (at n = 4 they are chaotic: 50
//!   reflections amplify 1e-16 to more than 1e-9). For such a ray the status,
//!   the faces and the reflection count must still be equal unless the nudge
//!   changes them too; only points and directions are not compared.
//!
//! Every test prints what it compared and its worst errors as fractions of
//! the tolerances (`cargo test --release --test lens_exact -- --nocapture`).

// `!(x <= tol)` on purpose, as in the library: it also fails for NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod reference;

use glam::DVec3;
use lensview::geometry::{Lens, LensPath, LensSurface, LensTraceStatus, MAX_INTERNAL_REFLECTIONS};
use lensview::optics::{Index, ThickLens};
use lensview::sampling::Sampler;
use reference::{DD, Face, LensSpec, Path, Status, V3};
use std::f64::consts::{PI, TAU};

const EPS: f64 = f64::EPSILON;

// ---------------------------------------------------------------------------
// Lenses, poses and rays
// ---------------------------------------------------------------------------

/// Where a lens sits: centre, axis (not unit, not along a coordinate axis)
/// and diameter.
#[derive(Clone, Copy, Debug)]
struct Pose {
    center: DVec3,
    axis: DVec3,
    d: f64,
}

const POSES: [Pose; 3] = [
    Pose {
        center: DVec3::new(0.3, -1.7, 2.9),
        axis: DVec3::new(0.36, -0.48, 0.8),
        d: 2.0,
    },
    Pose {
        center: DVec3::new(-12.5, 4.25, 7.0),
        axis: DVec3::new(-1.0, 2.0, 0.5),
        d: 0.37,
    },
    Pose {
        center: DVec3::new(101.0, -3.3, -47.25),
        axis: DVec3::new(0.1, -0.2, -1.0),
        d: 5.0,
    },
];

fn spec(p: Pose, r1: f64, r2: f64, n: f64) -> LensSpec {
    LensSpec {
        center: p.center.to_array(),
        axis: p.axis.to_array(),
        d: p.d,
        r1,
        r2,
        n,
    }
}

fn lens_under_test(s: &LensSpec) -> Lens {
    Lens::new(
        DVec3::from_array(s.center),
        DVec3::from_array(s.axis),
        s.d,
        s.r1,
        s.r2,
        Index::Constant(s.n),
    )
    .expect("valid lens")
}

/// A deterministic stream of uniforms in [0, 1).
struct Rng(Sampler);

impl Rng {
    fn new(seed: u64, stream: u64) -> Self {
        Rng(Sampler::new(seed, stream, 0))
    }
    fn f(&mut self) -> f64 {
        self.0.next_f64()
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.f()
    }
    fn unit_vector(&mut self) -> DVec3 {
        let z = self.range(-1.0, 1.0);
        let phi = self.range(0.0, TAU);
        let s = (1.0 - z * z).max(0.0).sqrt();
        DVec3::new(s * phi.cos(), s * phi.sin(), z)
    }
}

/// Unit axis and two unit vectors across it (f64; only for making rays).
fn frame(s: &LensSpec) -> (DVec3, DVec3, DVec3) {
    let a = DVec3::from_array(s.axis).normalize();
    let e1 = a.any_orthonormal_vector();
    (a, e1, a.cross(e1))
}

/// A ray aimed at a point of the aperture disc (radius `rho_max·d/2`, in the
/// rim plane), tilted up to `max_angle` from `∓axis`, starting `3d` away on
/// the S1 side (`from_s1`) or the S2 side.
fn aperture_ray(s: &LensSpec, rng: &mut Rng, rho_max: f64, max_angle: f64, from_s1: bool) -> (DVec3, DVec3) {
    let (a, e1, e2) = frame(s);
    let c = DVec3::from_array(s.center);
    let rho = rng.f().sqrt() * rho_max * 0.5 * s.d;
    let phi = rng.range(0.0, TAU);
    let target = c + rho * (phi.cos() * e1 + phi.sin() * e2);
    let th = rng.f() * max_angle;
    let psi = rng.range(0.0, TAU);
    let toward = if from_s1 { -a } else { a };
    let dir = th.cos() * toward + th.sin() * (psi.cos() * e1 + psi.sin() * e2);
    (target - 3.0 * s.d * dir, dir)
}

/// A ray from a random point on the sphere of radius `3d` about the centre,
/// aimed at a random point within `0.45·d` of the centre.
fn any_ray(s: &LensSpec, rng: &mut Rng) -> (DVec3, DVec3) {
    let c = DVec3::from_array(s.center);
    let origin = c + 3.0 * s.d * rng.unit_vector();
    let target = c + 0.45 * s.d * rng.f().cbrt() * rng.unit_vector();
    (origin, target - origin)
}

/// A point of face `face` at distance `rho` from the axis (azimuth `phi`),
/// computed in double-double, and the outward normal there.
fn point_on_face(s: &LensSpec, face: Face, rho: f64, phi: f64) -> (V3<DD>, V3<DD>) {
    let g = reference::Geometry::<DD>::new(s);
    let (_, e1, e2) = frame(s);
    // Any unit radial direction will do; normalise it in DD so that the
    // point lies on the sphere to DD precision.
    let radial = V3::<DD>::of((phi.cos() * e1 + phi.sin() * e2).to_array());
    let radial = radial - g.axis.scale(radial.dot(g.axis));
    let radial = radial.normalize();
    let (i, r, sign) = match face {
        Face::S1 => (0, s.r1, 1.0),
        Face::S2 => (1, s.r2, -1.0),
    };
    let rho = DD::new(rho);
    let r = DD::new(r);
    let along = (r * r - rho * rho).sqrt() * DD::new(sign);
    let p = g.sphere_centre[i] + radial.scale(rho) + g.axis.scale(along);
    (p, g.normal(i, p))
}

fn round(v: V3<DD>) -> DVec3 {
    DVec3::from_array(v.to_f64())
}

// ---------------------------------------------------------------------------
// Comparison
// ---------------------------------------------------------------------------

/// What one test saw: rays compared, skipped, excused, the worst errors
/// (relative to the tolerances) and the failures.
#[derive(Default)]
struct Stats {
    compared: usize,
    /// Paths that meet a face within `rim_skip` of the rim.
    skipped_rim: usize,
    /// Ill-conditioned paths whose status, faces and reflection count were
    /// compared but not their points and directions.
    ill_conditioned: usize,
    /// Ill-conditioned paths whose status, faces or count themselves change
    /// under a rounding-sized perturbation: nothing compared.
    undetermined: usize,
    /// Worst (error / tolerance) for positions and directions, over the
    /// rays fully compared.
    worst_pos: f64,
    worst_dir: f64,
    max_reflections: u32,
    failures: Vec<String>,
    failed_rays: usize,
    /// Failed rays with a wrong status, face or reflection count.
    failed_structure: usize,
    /// Failed rays per lens.
    failed_lenses: std::collections::BTreeMap<String, usize>,
}

/// A path in plain f64 numbers, from either tracer.
#[derive(Debug, Clone, PartialEq)]
struct Plain {
    status: Status,
    entry: Option<(Face, [f64; 3], [f64; 3])>,
    exit: Option<(Face, [f64; 3], [f64; 3])>,
    reflections: u32,
}

fn face(s: LensSurface) -> Face {
    match s {
        LensSurface::S1 => Face::S1,
        LensSurface::S2 => Face::S2,
    }
}

fn plain_of_lens(p: &LensPath) -> Plain {
    let status = match p.status {
        LensTraceStatus::Transmitted => Status::Transmitted,
        LensTraceStatus::Miss => Status::Miss,
        LensTraceStatus::Trapped => Status::Trapped,
    };
    let c = |c: &Option<(LensSurface, DVec3, DVec3)>| c.map(|(s, x, u)| (face(s), x.to_array(), u.to_array()));
    Plain {
        status,
        entry: c(&p.entry),
        exit: c(&p.exit),
        reflections: p.internal_reflections,
    }
}

fn plain_of<T: reference::Real>(p: &Path<T>) -> Plain {
    let c = |c: &Option<reference::Crossing<T>>| c.map(|c| (c.face, c.point.to_f64(), c.dir.to_f64()));
    Plain {
        status: p.status,
        entry: c(&p.entry),
        exit: c(&p.exit),
        reflections: p.reflections,
    }
}

fn pos_tolerance(d: f64, want: V3<DD>) -> f64 {
    let scale = want.to_f64().iter().fold(0.0f64, |m, c| m.max(c.abs()));
    1e-9 * d + 64.0 * EPS * scale
}

const DIR_TOLERANCE: f64 = 1e-9;

/// `|got − want|` evaluated in double-double.
fn distance(got: [f64; 3], want: V3<DD>) -> f64 {
    (V3::<DD>::of(got) - want).length().to_f64()
}

/// Rays whose path meets a face this close to the rim are skipped.
fn rim_skip(s: &LensSpec) -> f64 {
    let scale = s.center.iter().fold(0.0f64, |m, c| m.max(c.abs()));
    1e-8 * s.d + 1024.0 * EPS * scale
}

/// A path is ill-conditioned when nudging its start inside the glass by one
/// rounding of the lens's own scale (ε·d in position, ε in direction) moves
/// the exact exit by more than this fraction of the tolerances.
const ILL_CONDITIONED: f64 = 1e-3;

/// The differences between `got` and the reference: structural ones
/// (status, faces, reflection count) and numerical ones (points and
/// directions out of tolerance), with the worst error/tolerance ratios.
struct Differences {
    structural: Vec<String>,
    numerical: Vec<String>,
    worst_pos: f64,
    worst_dir: f64,
}

fn differences(s: &LensSpec, got: &Plain, want: &Path<DD>) -> Differences {
    let mut r = Differences {
        structural: Vec::new(),
        numerical: Vec::new(),
        worst_pos: 0.0,
        worst_dir: 0.0,
    };
    if got.status != want.status {
        r.structural
            .push(format!("status: expected {:?}, got {:?}", want.status, got.status));
    }
    if got.reflections != want.reflections {
        r.structural.push(format!(
            "internal reflections: expected {}, got {}",
            want.reflections, got.reflections
        ));
    }
    for (what, g, w) in [("entry", &got.entry, &want.entry), ("exit", &got.exit, &want.exit)] {
        match (g, w) {
            (None, None) => {}
            (Some((gf, gx, gu)), Some(w)) => {
                if *gf != w.face {
                    r.structural
                        .push(format!("{what} face: expected {:?}, got {:?}", w.face, gf));
                }
                let (ex, tx) = (distance(*gx, w.point), pos_tolerance(s.d, w.point));
                let eu = distance(*gu, w.dir);
                r.worst_pos = r.worst_pos.max(ex / tx);
                r.worst_dir = r.worst_dir.max(eu / DIR_TOLERANCE);
                if *gf != w.face || !(ex <= tx) || !(eu <= DIR_TOLERANCE) {
                    r.numerical.push(format!(
                        "{what}: expected {:?} point {:?} dir {:?}; got {:?} point {:?} dir {:?}; \
                         point error {ex:.3e} (tol {tx:.3e}), dir error {eu:.3e} (tol {DIR_TOLERANCE:.0e})",
                        w.face,
                        w.point.to_f64(),
                        w.dir.to_f64(),
                        gf,
                        gx,
                        gu
                    ));
                }
            }
            (g, w) => r.structural.push(format!(
                "{what}: expected {:?}, got {:?}",
                w.map(|w| (w.face, w.point.to_f64(), w.dir.to_f64())),
                g
            )),
        }
    }
    r
}

/// The worst error/tolerance ratio of `got` against the reference, ∞ for a
/// structural difference.
fn worst_ratio(s: &LensSpec, got: &Plain, want: &Path<DD>) -> f64 {
    let d = differences(s, got, want);
    if d.structural.is_empty() {
        d.worst_pos.max(d.worst_dir)
    } else {
        f64::INFINITY
    }
}

/// Conditioning of the path inside the glass: the reference restarted from
/// its first state inside the glass nudged by ε·d (position) or ε
/// (direction) along each coordinate. Returns the largest move of the exit
/// point and direction in units of the tolerances, and whether the status,
/// the exit face or the reflection count changed.
fn internal_conditioning(s: &LensSpec, want: &Path<DD>) -> (f64, bool) {
    let Some((x, v)) = want.start else {
        return (0.0, false);
    };
    let g = reference::Geometry::<DD>::new(s);
    let mut worst = 0.0f64;
    let mut changed = false;
    for k in 0..3 {
        for sign in [-1.0, 1.0] {
            let mut e = [0.0; 3];
            e[k] = sign;
            let e = V3::<DD>::of(e);
            for (x2, v2) in [
                (x + e.scale(DD::new(EPS * s.d)), v),
                (x, (v + e.scale(DD::new(EPS))).normalize()),
            ] {
                let p = reference::inside_path(&g, x2, v2);
                let same_face = match (p.exit, want.exit) {
                    (Some(a), Some(b)) => a.face == b.face,
                    (None, None) => true,
                    _ => false,
                };
                if p.status != want.status || p.reflections != want.reflections || !same_face {
                    changed = true;
                    continue;
                }
                if let (Some(a), Some(b)) = (p.exit, want.exit) {
                    worst = worst
                        .max((a.point - b.point).length().to_f64() / pos_tolerance(s.d, b.point))
                        .max((a.dir - b.dir).length().to_f64() / DIR_TOLERANCE);
                }
            }
        }
    }
    (worst, changed)
}

/// How far the reference exit moves when one input coordinate moves by one
/// ulp (a diagnostic for failure reports).
fn input_sensitivity(s: &LensSpec, origin: DVec3, dir: DVec3, want: &Path<DD>) -> String {
    let Some(w) = want.exit else {
        return "no exit".into();
    };
    let nudge = |v: f64, k: i64| f64::from_bits((v.to_bits() as i64 + k) as u64);
    let (mut dx, mut du) = (0.0f64, 0.0f64);
    let mut changed = false;
    for c in 0..3 {
        for k in [-1, 1] {
            for moved_origin in [true, false] {
                let (mut o, mut u) = (origin.to_array(), dir.to_array());
                if moved_origin {
                    o[c] = nudge(o[c], k);
                } else {
                    u[c] = nudge(u[c], k);
                }
                let p = reference::trace::<DD>(s, o, u);
                match p.exit {
                    Some(e) if e.face == w.face && p.reflections == want.reflections => {
                        dx = dx.max(distance(e.point.to_f64(), w.point) / pos_tolerance(s.d, w.point));
                        du = du.max(distance(e.dir.to_f64(), w.dir) / DIR_TOLERANCE);
                    }
                    _ => changed = true,
                }
            }
        }
    }
    format!(
        "a one-ulp nudge of one input coordinate moves the exact exit point by up to {dx:.3e} and its direction by \
         up to {du:.3e} of the tolerances{}",
        if changed {
            " (and changes the face or the reflection count)"
        } else {
            ""
        }
    )
}

/// Traces one ray with the code under test and the reference and compares.
fn check(s: &LensSpec, lens: &Lens, origin: DVec3, dir: DVec3, stats: &mut Stats) -> Path<DD> {
    let want = reference::trace::<DD>(s, origin.to_array(), dir.to_array());
    if want.rim_distance < rim_skip(s) {
        stats.skipped_rim += 1;
        return want;
    }
    let got = plain_of_lens(&lens.trace(origin, dir, s.n));
    compare(s, origin, dir, &got, &want, stats);
    want
}

/// Compares `got` with the reference path `want` of the ray `origin`,
/// `dir` (not near the rim), excusing only what the exact problem cannot
/// determine, and counts it in `stats`.
fn compare(s: &LensSpec, origin: DVec3, dir: DVec3, got: &Plain, want: &Path<DD>, stats: &mut Stats) {
    let diff = differences(s, got, want);
    let mut problems: Vec<String> = diff.structural.iter().chain(&diff.numerical).cloned().collect();
    let mut note = String::new();
    let mut numbers_count = true;
    if !problems.is_empty() {
        // Excuse only what the exact problem cannot determine: decided on the
        // reference alone, never on how far off `got` is.
        let (cond, changed) = internal_conditioning(s, want);
        if changed {
            stats.undetermined += 1;
            return;
        }
        if cond > ILL_CONDITIONED {
            if diff.structural.is_empty() {
                stats.ill_conditioned += 1;
                return;
            }
            problems = diff.structural.clone();
            numbers_count = false;
        }
        note = format!(
            "\n    reference: {:?}, {} reflections; internal conditioning {cond:.3e}; {}",
            want.status,
            want.reflections,
            input_sensitivity(s, origin, dir, want)
        );
    }
    stats.compared += 1;
    stats.max_reflections = stats.max_reflections.max(want.reflections);
    if numbers_count {
        stats.worst_pos = stats.worst_pos.max(diff.worst_pos);
        stats.worst_dir = stats.worst_dir.max(diff.worst_dir);
    }
    if !problems.is_empty() {
        stats.failed_rays += 1;
        stats.failed_structure += usize::from(!diff.structural.is_empty());
        *stats
            .failed_lenses
            .entry(format!(
                "d {} r1 {} r2 {} n {} centre {:?}",
                s.d, s.r1, s.r2, s.n, s.center
            ))
            .or_default() += 1;
        if stats.failures.len() < 12 {
            stats.failures.push(format!(
                "lens {s:?}\n    ray origin {:?} dir {:?}\n    {}{note}",
                origin.to_array(),
                dir.to_array(),
                problems.join("\n    ")
            ));
        }
    }
}

/// The worst error/tolerance ratio of the naive f64 centre-form tracer.
fn naive_ratio(s: &LensSpec, origin: DVec3, dir: DVec3, want: &Path<DD>) -> f64 {
    let naive = plain_of(&reference::trace::<f64>(s, origin.to_array(), dir.to_array()));
    worst_ratio(s, &naive, want)
}

fn finish(name: &str, stats: &Stats, max_excused_fraction: f64) {
    println!(
        "{name}: {} rays compared ({} failed, {} of them in status, face or count), {} skipped at the rim, {} ill-conditioned (structure only), \
         {} undetermined; worst position error {:.3e} of tolerance, worst direction error {:.3e} of tolerance, \
         most internal reflections {}",
        stats.compared,
        stats.failed_rays,
        stats.failed_structure,
        stats.skipped_rim,
        stats.ill_conditioned,
        stats.undetermined,
        stats.worst_pos,
        stats.worst_dir,
        stats.max_reflections
    );
    assert!(
        stats.failures.is_empty(),
        "{name}: Lens::trace differs from the reference on {} rays; per lens {:#?}; the first ones:\n{}",
        stats.failed_rays,
        stats.failed_lenses,
        stats.failures.join("\n")
    );
    assert!(stats.compared > 0);
    let excused = stats.skipped_rim + stats.ill_conditioned + stats.undetermined;
    let total = (stats.compared + excused) as f64;
    assert!(
        (excused as f64) <= max_excused_fraction * total,
        "{name}: {excused} of {total} rays excused"
    );
}

// ---------------------------------------------------------------------------
// The reference itself
// ---------------------------------------------------------------------------

#[test]
fn double_double_reference_is_accurate() {
    // √2 to 32 digits: 1.4142135623730950488016887242097.
    let r2 = DD::new(2.0).sqrt();
    assert_eq!(r2.hi, std::f64::consts::SQRT_2);
    assert!((r2.lo - (-9.667_293_313_452_913e-17)).abs() < 1e-31, "{r2:?}");
    let e = r2 * r2 - DD::new(2.0);
    assert!(e.to_f64().abs() < 1e-31, "{e:?}");
    // (1/3)·3 − 1 and 1e16 + 1 − 1e16.
    let t = DD::new(1.0) / DD::new(3.0) * DD::new(3.0) - DD::new(1.0);
    assert!(t.to_f64().abs() < 1e-31, "{t:?}");
    assert_eq!((DD::new(1e16) + DD::new(1.0) - DD::new(1e16)).to_f64(), 1.0);
    // The reference ball lens: a ray at height y parallel to the axis meets
    // the ball at depth √(R² − y²) and leaves at the point that Snell's law
    // in the plane gives: the exit point is the entry point turned by
    // π − 2θt about the ball's centre.
    let s = LensSpec {
        center: [0.0; 3],
        axis: [0.0, 0.0, 1.0],
        d: 2.0,
        r1: 1.0,
        r2: 1.0,
        n: 1.5,
    };
    for y in [0.1, 0.5, 0.9] {
        let p = reference::trace::<DD>(&s, [y, 0.0, 5.0], [0.0, 0.0, -1.0]);
        let entry = p.entry.unwrap();
        let exit = p.exit.unwrap();
        assert!((entry.point.to_f64()[2] - (1.0f64 - y * y).sqrt()).abs() < 1e-15);
        let th_t = (y / 1.5f64).asin();
        let th_i = y.asin();
        let turn = PI - 2.0 * th_t;
        let ang = th_i + turn; // polar angle of the exit point, from +z toward +x
        let want = [ang.sin(), 0.0, ang.cos()];
        let got = exit.point.to_f64();
        for k in 0..3 {
            assert!((got[k] - want[k]).abs() < 1e-14, "{got:?} {want:?}");
        }
        assert_eq!(p.reflections, 0);
    }
}

// ---------------------------------------------------------------------------
// The stiff cases
// ---------------------------------------------------------------------------

#[test]
fn nearly_flat_faces() {
    let mut stats = Stats::default();
    let mut naive_worst = [0.0f64; 2];
    let mut naive_failed = [0usize; 2];
    for (k, factor) in [1e6, 1e7].into_iter().enumerate() {
        for (pi, pose) in POSES.iter().enumerate() {
            let s = spec(*pose, factor * pose.d, factor * pose.d * 1.3, 1.5);
            let lens = lens_under_test(&s);
            let mut rng = Rng::new(11, (k * 10 + pi) as u64);
            for i in 0..300 {
                let (o, u) = aperture_ray(&s, &mut rng, 0.99, 0.7, i % 3 != 0);
                let want = check(&s, &lens, o, u, &mut stats);
                let r = naive_ratio(&s, o, u, &want);
                naive_worst[k] = naive_worst[k].max(r);
                naive_failed[k] += usize::from(r > 1.0);
            }
        }
    }
    println!(
        "nearly_flat_faces: naive f64 worst error/tolerance: R = 1e6·d {:.3e}, R = 1e7·d {:.3e} \
         ({} of 900 rays out of tolerance; ∞ = wrong status or face)",
        naive_worst[0], naive_worst[1], naive_failed[1]
    );
    assert!(naive_worst[1] > 1.0, "the naive tracer should fail at R = 1e7·d");
    finish("nearly_flat_faces", &stats, 0.01);

    // Convergence to the thin lens and to the plane. Near-axis rays parallel
    // to the axis at height y leave deviated by y/EFL; an oblique ray is
    // deviated by O(d/R) and displaced as by a plate of the local thickness.
    let pose = POSES[0];
    let (a, e1, e2) = frame(&spec(pose, 1.0, 1.0, 1.5));
    let n = 1.5;
    let mut prev_oblique_dev = f64::INFINITY;
    let mut prev_ref = f64::INFINITY;
    for factor in [1e4, 1e5, 1e6, 1e7] {
        let r = factor * pose.d;
        let s = spec(pose, r, r, n);
        let lens = lens_under_test(&s);
        let efl = ThickLens::new(pose.d, r, r, n).efl;
        // |deviation·EFL/y − 1| for Lens::trace and for the reference (whose
        // deviation is taken in double-double, against the exact axis).
        let (mut worst_code, mut worst_ref) = (0.0f64, 0.0f64);
        let g = reference::Geometry::<DD>::new(&s);
        for (j, frac) in [0.01, 0.1, 0.5].into_iter().enumerate() {
            let y = frac * 0.5 * pose.d;
            let phi = 0.7 + j as f64;
            let o = pose.center + 2.0 * pose.d * a + y * (phi.cos() * e1 + phi.sin() * e2);
            let u = -a;
            // Spherical aberration and the sine/tangent difference are
            // O((y/R)²); rounding a unit direction is a few ε of deviation.
            let aberration = 100.0 * (y / r).powi(2);
            let (_, _, out) = lens.trace(o, u, n).exit.expect("transmitted");
            let dev = out.cross(u).length().atan2(out.dot(u));
            let err = (dev * efl / y - 1.0).abs();
            assert!(
                err <= aberration + 16.0 * EPS * efl / y,
                "Lens::trace: R = {factor:e}·d, y = {y}: {err:e}"
            );
            worst_code = worst_code.max(err);
            let p = reference::trace::<DD>(&s, o.to_array(), u.to_array());
            let out = p.exit.expect("transmitted").dir;
            let u_dd = V3::<DD>::of(u.to_array()).normalize();
            let cross = V3([
                out.0[1] * u_dd.0[2] - out.0[2] * u_dd.0[1],
                out.0[2] * u_dd.0[0] - out.0[0] * u_dd.0[2],
                out.0[0] * u_dd.0[1] - out.0[1] * u_dd.0[0],
            ]);
            let dev = cross.length().to_f64().atan2(out.dot(u_dd).to_f64());
            let q = V3::<DD>::of(o.to_array()) - g.center;
            let height = (q - g.axis.scale(q.dot(g.axis))).length().to_f64();
            let err = (dev * efl / height - 1.0).abs();
            assert!(
                err <= aberration + 1e-13,
                "reference: R = {factor:e}·d, y = {y}: {err:e}"
            );
            worst_ref = worst_ref.max(err);
        }
        // The oblique ray: 30° to the axis through the point at 0.5·d/2.
        let th: f64 = 30f64.to_radians();
        let u = -th.cos() * a + th.sin() * e1;
        let target = pose.center + 0.25 * pose.d * e2;
        let o = target - 2.0 * pose.d * u;
        let p = lens.trace(o, u, n);
        let (_, x_in, _) = p.entry.unwrap();
        let (_, x_out, u_out) = p.exit.unwrap();
        let dev = u_out.cross(u).length();
        // Plate of the local axial thickness (h² − ρ²)·(1/R) (both faces
        // together, to first order in 1/R) at ρ = d/4: lateral displacement
        // T·sin(θ − θ')/cos θ'.
        let h = 0.5 * pose.d;
        let rho = 0.25 * pose.d;
        let t_local = (h * h - rho * rho) / r;
        let th_t = (th.sin() / n).asin();
        let plate = t_local * (th - th_t).sin() / th_t.cos();
        let step = x_out - x_in;
        let lateral = (step - u * step.dot(u)).length();
        println!(
            "nearly_flat_faces: R = {factor:e}·d: |deviation·EFL/y − 1| ≤ {worst_code:.2e} (reference {worst_ref:.2e}); \
             oblique ray deviated {dev:.3e} rad, displaced {lateral:.4e} (plate {plate:.4e})"
        );
        assert!(dev < 2.0 * pose.d / r, "deviation {dev} at R = {r}");
        assert!(dev < prev_oblique_dev / 5.0);
        // The exact deviation converges to the paraxial one as 1/R².
        assert!(
            worst_ref <= (prev_ref / 50.0).max(1e-14),
            "{worst_ref:e} after {prev_ref:e}"
        );
        prev_ref = worst_ref;
        prev_oblique_dev = dev;
        assert!(
            (lateral / plate - 1.0).abs() < 1e-3,
            "plate displacement {lateral} vs {plate}"
        );
    }
}

#[test]
fn hemispherical_faces() {
    let mut stats = Stats::default();
    for (pi, pose) in POSES.iter().enumerate() {
        let h = 0.5 * pose.d;
        let shapes = [
            (h, 3.0 * pose.d),                    // one exact hemisphere
            (2.0 * pose.d, h),                    // the other face a hemisphere
            (h * (1.0 + 1e-4), h * (1.0 + 1e-4)), // almost a ball
            (h, h),                               // a ball lens
        ];
        for (k, (r1, r2)) in shapes.into_iter().enumerate() {
            let s = spec(*pose, r1, r2, 1.5);
            let lens = lens_under_test(&s);
            let mut rng = Rng::new(12, (pi * 10 + k) as u64);
            for i in 0..400 {
                let (o, u) = match i % 3 {
                    0 => aperture_ray(&s, &mut rng, 1.0, 0.5, true),
                    1 => aperture_ray(&s, &mut rng, 1.0, 0.5, false),
                    _ => any_ray(&s, &mut rng),
                };
                check(&s, &lens, o, u, &mut stats);
            }
        }
    }
    finish("hemispherical_faces", &stats, 0.01);
}

#[test]
fn tiny_lens_far_from_origin() {
    let mut stats = Stats::default();
    let mut naive_worst = 0.0f64;
    let mut naive_failed = 0;
    let center = DVec3::new(7000.0, -5000.0, 5000.0);
    let d = 1e-3;
    for (k, (axis, r1, r2, n)) in [
        (DVec3::new(-0.6, 0.7, -0.4), 1.2e-3, 3e-3, 1.5),
        (DVec3::new(0.8, -0.3, 0.45), 0.7e-3, 0.9e-3, 1.7),
        (DVec3::new(-0.5, 0.45, -0.6), 5e-4, 5e-4, 1.5), // a tiny ball lens
        (DVec3::new(-0.7, 0.5, -0.5), 0.1, 0.1, 1.5),    // a tiny nearly flat lens
    ]
    .into_iter()
    .enumerate()
    {
        let s = spec(Pose { center, axis, d }, r1, r2, n);
        let lens = lens_under_test(&s);
        let (_, e1, e2) = frame(&s);
        let mut rng = Rng::new(13, k as u64);
        for _ in 0..500 {
            let rho = rng.f().sqrt() * 0.98 * 0.5 * d;
            let phi = rng.range(0.0, TAU);
            let target = center + rho * (phi.cos() * e1 + phi.sin() * e2);
            let (o, u) = (DVec3::ZERO, target);
            let want = check(&s, &lens, o, u, &mut stats);
            assert_eq!(want.status, Status::Transmitted);
            let r = naive_ratio(&s, o, u, &want);
            naive_worst = naive_worst.max(r);
            naive_failed += usize::from(r > 1.0);
        }
    }
    println!(
        "tiny_lens_far_from_origin: naive f64 worst error/tolerance {naive_worst:.3e} ({naive_failed} of 2000 rays \
         out of tolerance; ∞ = wrong status or face)"
    );
    assert!(
        naive_worst > 1.0,
        "the naive tracer should fail for a tiny lens far away"
    );
    finish("tiny_lens_far_from_origin", &stats, 0.01);
}

#[test]
fn grazing_80_degree_incidence() {
    let mut stats = Stats::default();
    let incidence: f64 = 80f64.to_radians();
    for (pi, pose) in POSES.iter().enumerate() {
        for (k, (r1, r2, n)) in [(2.5, 1.5, 1.5), (0.8, 4.0, 1.7), (50.0, 0.6, 1.5)]
            .into_iter()
            .enumerate()
        {
            let s = spec(*pose, r1 * pose.d, r2 * pose.d, n);
            let lens = lens_under_test(&s);
            let mut rng = Rng::new(14, (pi * 10 + k) as u64);
            for _ in 0..300 {
                let rho = rng.f().sqrt() * 0.9 * 0.5 * pose.d;
                let (p, nrm) = point_on_face(&s, Face::S1, rho, rng.range(0.0, TAU));
                // A unit tangent at a random azimuth about the normal.
                let w = V3::<DD>::of(rng.unit_vector().to_array());
                let tangent = (w - nrm.scale(w.dot(nrm))).normalize();
                let u = nrm.scale(DD::new(-incidence.cos())) + tangent.scale(DD::new(incidence.sin()));
                let o = p - u.scale(DD::new(2.0 * pose.d));
                let (o, u) = (round(o), round(u));
                let want = check(&s, &lens, o, u, &mut stats);
                // The rounded ray still meets S1 at 80° to the normal.
                let e = want.entry.expect("enters");
                assert_eq!(e.face, Face::S1);
                let g = reference::Geometry::<DD>::new(&s);
                let n_at = g.normal(0, e.point);
                let cos = -V3::<DD>::of(u.to_array()).normalize().dot(n_at).to_f64();
                assert!((cos.acos() - incidence).abs() < 1e-9);
            }
        }
    }
    finish("grazing_80_degree_incidence", &stats, 0.0);
}

#[test]
fn rays_near_the_rim() {
    let mut stats = Stats::default();
    for (pi, pose) in POSES.iter().enumerate() {
        let h = 0.5 * pose.d;
        for (r1, r2, n) in [
            (2.5 * pose.d, 1.5 * pose.d, 1.5),
            (1.2 * h, 4.0 * pose.d, 1.6),
            (h, h, 1.5),
        ] {
            let s = spec(*pose, r1, r2, n);
            let lens = lens_under_test(&s);
            let (a, e1, e2) = frame(&s);
            for frac in [0.99, 0.999999] {
                for k in 0..48 {
                    let phi = (k as f64 + 0.137 * pi as f64) * TAU / 48.0;
                    let radial = frac * h * (phi.cos() * e1 + phi.sin() * e2);
                    for side in [1.0, -1.0] {
                        let o = pose.center + side * 2.0 * pose.d * a + radial;
                        check(&s, &lens, o, -side * a, &mut stats);
                    }
                }
            }
        }
    }
    finish("rays_near_the_rim", &stats, 0.0);
}

#[test]
fn rays_on_the_axis() {
    let mut stats = Stats::default();
    let aligned = Pose {
        center: DVec3::new(1.0, 2.0, 3.0),
        axis: DVec3::Z,
        d: 2.0,
    };
    let poses = [POSES[0], POSES[1], POSES[2], aligned];
    for (pi, pose) in poses.iter().enumerate() {
        for (r1, r2, n) in [(2.5, 1.5, 1.5), (0.5, 3.0, 1.7), (1e7, 1e7, 1.5), (0.5, 0.5, 4.0)] {
            let s = spec(*pose, r1 * pose.d, r2 * pose.d, n);
            let lens = lens_under_test(&s);
            let g = reference::Geometry::<DD>::new(&s);
            let a = DVec3::from_array(s.axis).normalize();
            for dist in [1.5, 3.0, 10.0, 1000.0] {
                for side in [1.0, -1.0] {
                    let o = pose.center + side * dist * pose.d * a;
                    let u = -side * a;
                    let want = check(&s, &lens, o, u, &mut stats);
                    let got = lens.trace(o, u, n);
                    assert_eq!(got.internal_reflections, 0);
                    let (f_in, f_out) = if side > 0.0 {
                        (Face::S1, Face::S2)
                    } else {
                        (Face::S2, Face::S1)
                    };
                    let (_, x_in, u_in) = got.entry.expect("enters");
                    let (_, x_out, u_out) = got.exit.expect("leaves");
                    // Exact vertex points and an undeviated ray.
                    for (x, f) in [(x_in, f_in), (x_out, f_out)] {
                        let v = g.vertex(f);
                        assert!(distance(x.to_array(), v) <= pos_tolerance(pose.d, v), "{x} vs {v:?}");
                    }
                    // Undeviated, up to the tilt that rounding the origin off
                    // the axis (≤ ulp(1000·d)) gives through faces of radius ≥ d/2.
                    assert!(
                        (u_in - u).length() < 1e-12 && (u_out - u).length() < 1e-12,
                        "{u_in} {u_out} {u}"
                    );
                    assert_eq!(want.reflections, 0);
                    if pi == 3 {
                        // On the z axis every transverse coordinate is exact.
                        for x in [x_in, x_out] {
                            assert_eq!((x.x, x.y), (1.0, 2.0));
                        }
                        for w in [u_in, u_out] {
                            assert_eq!((w.x, w.y), (0.0, 0.0));
                        }
                    }
                }
            }
        }
    }
    finish("rays_on_the_axis", &stats, 0.0);
}

#[test]
fn nearly_invisible_glass() {
    let mut stats = Stats::default();
    for (pi, pose) in POSES.iter().enumerate() {
        let h = 0.5 * pose.d;
        for (k, (r1, r2)) in [
            (2.5 * pose.d, 1.5 * pose.d),
            (h, 3.0 * pose.d),
            (1e3 * pose.d, 1e3 * pose.d),
        ]
        .into_iter()
        .enumerate()
        {
            let s = spec(*pose, r1, r2, 1.0001);
            let lens = lens_under_test(&s);
            let mut rng = Rng::new(15, (pi * 10 + k) as u64);
            for i in 0..400 {
                let (o, u) = if i % 2 == 0 {
                    aperture_ray(&s, &mut rng, 0.99, 1.0, i % 4 == 0)
                } else {
                    any_ray(&s, &mut rng)
                };
                let want = check(&s, &lens, o, u, &mut stats);
                if let Some(exit) = want.exit {
                    // Glass of index 1.0001 barely bends the ray.
                    let dev = distance(u.normalize().to_array(), exit.dir);
                    assert!(dev < 1e-2, "deviation {dev}");
                }
            }
        }
    }
    finish("nearly_invisible_glass", &stats, 0.01);
}

#[test]
fn strong_tir_index_4() {
    let mut stats = Stats::default();
    let mut counts = [0usize; 3]; // ≥ 2 reflections, ≥ 5 reflections, trapped
    for (pi, pose) in POSES.iter().enumerate() {
        for (k, (r1, r2)) in [(2.5, 2.5), (1.5, 0.8), (0.6, 5.0)].into_iter().enumerate() {
            let s = spec(*pose, r1 * pose.d, r2 * pose.d, 4.0);
            let lens = lens_under_test(&s);
            let (a, e1, e2) = frame(&s);
            let mut rng = Rng::new(16, (pi * 10 + k) as u64);
            for i in 0..400 {
                let (o, u) = if i % 2 == 0 {
                    aperture_ray(&s, &mut rng, 0.99, 1.3, i % 4 == 0)
                } else {
                    // From near the centre, nearly across the axis: trapped by
                    // several total internal reflections.
                    let o = pose.center
                        + 0.3 * pose.d * rng.f() * (rng.range(-1.0, 1.0) * e1 + rng.range(-1.0, 1.0) * e2)
                        + 0.01 * pose.d * rng.range(-1.0, 1.0) * a;
                    let th = rng.range(0.0, 0.5);
                    let phi = rng.range(0.0, TAU);
                    (o, th.sin() * a + th.cos() * (phi.cos() * e1 + phi.sin() * e2))
                };
                let undetermined = stats.undetermined;
                let want = check(&s, &lens, o, u, &mut stats);
                counts[0] += usize::from(want.reflections >= 2);
                counts[1] += usize::from(want.reflections >= 5);
                if want.status == Status::Trapped && stats.undetermined == undetermined {
                    // Trapped: stopped after the most reflections followed,
                    // with no exit, exactly as the reference.
                    let got = lens.trace(o, u, 4.0);
                    assert_eq!(got.status, LensTraceStatus::Trapped, "{o} {u}");
                    assert_eq!(got.internal_reflections, MAX_INTERNAL_REFLECTIONS);
                    assert_eq!(want.reflections, MAX_INTERNAL_REFLECTIONS);
                    assert!(got.exit.is_none() && want.exit.is_none());
                    counts[2] += 1;
                }
            }
        }
    }
    println!(
        "strong_tir_index_4: {} rays with ≥ 2 reflections, {} with ≥ 5, {} trapped in both tracers",
        counts[0], counts[1], counts[2]
    );
    // Long chains, and trapped rays that the tracer reports as trapped.
    assert!(counts[0] >= 50 && counts[1] >= 10 && counts[2] >= 50, "{counts:?}");
    finish("strong_tir_index_4", &stats, 0.02);
}

#[test]
fn ray_starting_inside_glass() {
    let mut stats = Stats::default();
    for (pi, pose) in POSES.iter().enumerate() {
        let h = 0.5 * pose.d;
        for (k, (r1, r2, n)) in [
            (2.5 * pose.d, 1.5 * pose.d, 1.5),
            (h, 3.0 * pose.d, 1.7),
            (h, h, 1.5),
            (1e6 * pose.d, 1e6 * pose.d, 1.5),
        ]
        .into_iter()
        .enumerate()
        {
            let s = spec(*pose, r1, r2, n);
            let lens = lens_under_test(&s);
            let g = reference::Geometry::<DD>::new(&s);
            let (a, e1, e2) = frame(&s);
            let t = ThickLens::new(pose.d, r1, r2, n);
            let mut rng = Rng::new(17, (pi * 10 + k) as u64);
            let mut n_rays = 0;
            while n_rays < 300 {
                let rho = rng.f().sqrt() * h;
                let phi = rng.range(0.0, TAU);
                let z = rng.range(-t.sag2, t.sag1);
                let o = pose.center + rho * (phi.cos() * e1 + phi.sin() * e2) + z * a;
                if !g.contains(V3::<DD>::of(o.to_array())) {
                    continue;
                }
                n_rays += 1;
                let u = rng.unit_vector();
                let want = check(&s, &lens, o, u, &mut stats);
                assert!(want.entry.is_none());
            }
        }
    }
    finish("ray_starting_inside_glass", &stats, 0.01);
}

#[test]
fn ray_origin_on_a_face() {
    // Not the tiny lens far away: there 1e-10·d is below the spacing of f64
    // coordinates, so a rounded point of a face is not "on" it by the contract.
    let mut stats = Stats::default();
    for (pi, pose) in POSES.iter().enumerate() {
        let h = 0.5 * pose.d;
        for (k, (r1, r2, n)) in [
            (2.5 * pose.d, 1.5 * pose.d, 1.5),
            (h, 3.0 * pose.d, 1.7),
            (1e6 * pose.d, h, 1.5),
        ]
        .into_iter()
        .enumerate()
        {
            let s = spec(*pose, r1, r2, n);
            let lens = lens_under_test(&s);
            let mut rng = Rng::new(18, (pi * 10 + k) as u64);
            for i in 0..300 {
                let f = if i % 2 == 0 { Face::S1 } else { Face::S2 };
                let rho = rng.f().sqrt() * 0.95 * h;
                let (p, nrm) = point_on_face(&s, f, rho, rng.range(0.0, TAU));
                // Inward, up to 85° from the inward normal.
                let (_, t1, t2) = {
                    let n = round(nrm);
                    let e1 = n.any_orthonormal_vector();
                    (n, e1, n.cross(e1))
                };
                let th = rng.f() * 85f64.to_radians();
                let phi = rng.range(0.0, TAU);
                let u = -th.cos() * round(nrm) + th.sin() * (phi.cos() * t1 + phi.sin() * t2);
                let o = round(p);
                let want = check(&s, &lens, o, u, &mut stats);
                let e = want.entry.expect("enters at its origin");
                assert_eq!(e.face, f);
                assert!(distance(o.to_array(), e.point) <= 1e-10 * pose.d);
            }
        }
    }
    finish("ray_origin_on_a_face", &stats, 0.01);
}

/// Rays that start a few diameters from a lens of d = 1e-3 centred at
/// each of `centers` (four shapes each): on the axis, parallel to it at
/// 0.5 h and 0.99 h, at 80° to the normal of S1, and skew rays (neither
/// meridional nor parallel), handed to `visit` with the lens, the kind
/// (0 ..= 4) and the ray.
fn rays_near_tiny_lenses(centers: &[DVec3], visit: &mut impl FnMut(&LensSpec, usize, DVec3, DVec3)) {
    let d = 1e-3;
    let h = 0.5 * d;
    let shapes = [
        (DVec3::new(-0.6, 0.7, -0.4), 1.2e-3, 3e-3, 1.5),
        (DVec3::new(0.8, -0.3, 0.45), 0.7e-3, 0.9e-3, 1.7),
        (DVec3::new(-0.5, 0.45, -0.6), h, h, 1.5),
        (DVec3::new(-0.7, 0.5, -0.5), 0.1, 0.1, 1.5),
    ];
    for (ci, &center) in centers.iter().enumerate() {
        for (k, (axis, r1, r2, n)) in shapes.into_iter().enumerate() {
            let s = spec(Pose { center, axis, d }, r1, r2, n);
            let (a, e1, e2) = frame(&s);
            let mut rng = Rng::new(19, (ci * 10 + k) as u64);
            for i in 0..400 {
                let dist = [1.5, 3.0, 7.0][i % 3] * d;
                let side = if i % 2 == 0 { 1.0 } else { -1.0 };
                let phi = rng.range(0.0, TAU);
                let radial = phi.cos() * e1 + phi.sin() * e2;
                let kind = (i / 2) % 5;
                let (o, u) = match kind {
                    // On the axis, and parallel to it at 0.5 h and 0.99 h.
                    0..=2 => {
                        let rho = [0.0, 0.5, 0.99][kind] * h;
                        (center + side * dist * a + rho * radial, -side * a)
                    }
                    // 80° to the normal of S1 at a random point of it.
                    3 => {
                        let (p, nrm) = point_on_face(&s, Face::S1, rng.f().sqrt() * 0.9 * h, phi);
                        let w = V3::<DD>::of(rng.unit_vector().to_array());
                        let tangent = (w - nrm.scale(w.dot(nrm))).normalize();
                        let th = 80f64.to_radians();
                        let u = nrm.scale(DD::new(-th.cos())) + tangent.scale(DD::new(th.sin()));
                        (round(p - u.scale(DD::new(dist))), round(u))
                    }
                    // Skew: offset across the axis, tilted about another line.
                    _ => {
                        let off = rng.f().sqrt() * 0.9 * h * radial;
                        let across = radial.cross(a);
                        let tilt = rng.range(0.05, 0.6);
                        let u = (-side * a + tilt * across).normalize();
                        (center + off - dist * u, u)
                    }
                };
                visit(&s, kind, o, u);
            }
        }
    }
}

/// Centres ~1e4 from the world origin, where world coordinates are spaced
/// ~2e-12 apart (2e-9 of a lens of d = 1e-3).
const FAR_CENTRES: [DVec3; 2] = [DVec3::new(7000.0, -5000.0, 5000.0), DVec3::new(-9999.5, 3.25, 8000.125)];

#[test]
fn rays_starting_near_a_tiny_far_lens() {
    let mut stats = Stats::default();
    let mut kinds = [0usize; 5];
    rays_near_tiny_lenses(&FAR_CENTRES, &mut |s, kind, o, u| {
        kinds[kind] += 1;
        let want = check(s, &lens_under_test(s), o, u, &mut stats);
        if kind < 3 {
            assert_eq!(want.status, Status::Transmitted, "kind {kind}");
        }
    });
    println!("rays_starting_near_a_tiny_far_lens: rays per kind {kinds:?}");
    finish("rays_starting_near_a_tiny_far_lens", &stats, 0.01);
}

/// The renderer's own pass into the lens (`integrator::surface` of the
/// closest hit, then `integrator::transmitted_ray`, what the scalar kernel
/// and a packet's scalar lanes call) for the rays of
/// `rays_starting_near_a_tiny_far_lens`, and for the same lenses at the
/// origin: its first ray out, with the renderer's push off the exit face
/// taken back off, against the reference exit (point and direction, same
/// tolerances). The face it leaves by is not an output of the pass: its
/// point stands for it. From the rounded world hit point alone (main before
/// this test) the far lenses' exits were off by several 1e-9.
#[test]
fn the_renderers_pass_near_a_tiny_far_lens() {
    use lensview::integrator::{spawn_ray, surface, transmitted_ray};
    use lensview::math::Ray;
    use lensview::scene::Scene;
    use lensview::trace::closest_hit;
    let mut stats = Stats::default();
    let centres = [FAR_CENTRES[0], FAR_CENTRES[1], DVec3::new(0.3, -0.2, 0.5)];
    let scene_of = |s: &LensSpec| {
        let v = |a: [f64; 3]| format!("[{:?}, {:?}, {:?}]", a[0], a[1], a[2]);
        let text = format!(
            "[camera]\nposition = [0, 0, 10]\nlook_at = [0, 0, 0]\n\n[[lenses]]\ncenter = {}\naxis = {}\n\
             d = {:?}\nr1 = {:?}\nr2 = {:?}\nn = {:?}\n",
            v(s.center),
            v(s.axis),
            s.d,
            s.r1,
            s.r2,
            s.n
        );
        Scene::parse("tiny.toml", &text).expect("a valid scene").1
    };
    let mut current: Option<(LensSpec, Scene)> = None;
    rays_near_tiny_lenses(&centres, &mut |s, _, o, u| {
        if current.as_ref().is_none_or(|(c, _)| c != s) {
            current = Some((*s, scene_of(s)));
        }
        let scene = &current.as_ref().expect("just set").1;
        let ray = Ray::new(o, u);
        let want = reference::trace::<DD>(s, o.to_array(), ray.dir.to_array());
        if want.rim_distance < rim_skip(s) {
            stats.skipped_rim += 1;
            return;
        }
        let out = closest_hit(scene, &ray, f64::INFINITY)
            .map(|(i, hit)| surface(scene, &ray, i, hit))
            .filter(|srf| srf.entering)
            .and_then(|srf| transmitted_ray(srf.object, srf.p, srf.nf, true, &ray, s.n));
        let got = match (out, &want.exit) {
            (Some(t), Some(w)) => {
                let x = round(w.point);
                let i = if w.face == Face::S1 { 0 } else { 1 };
                let normal = round(reference::Geometry::<DD>::new(s).normal(i, w.point));
                let push = spawn_ray(x, normal, t.ray.dir, s.d).origin - x;
                Plain {
                    status: Status::Transmitted,
                    entry: None,
                    exit: Some((w.face, (t.ray.origin - push).to_array(), t.ray.dir.to_array())),
                    reflections: t.bounces - 2,
                }
            }
            (out, _) => Plain {
                status: if out.is_some() {
                    Status::Transmitted
                } else {
                    Status::Miss
                },
                entry: None,
                exit: None,
                reflections: 0,
            },
        };
        let want = Path { entry: None, ..want };
        compare(s, o, ray.dir, &got, &want, &mut stats);
    });
    finish("the_renderers_pass_near_a_tiny_far_lens", &stats, 0.01);
}

#[test]
fn lens_trace_json_near_a_tiny_far_lens() {
    // `lens trace` reads its rays from JSON. An origin written with more
    // digits than an f64 holds (as from an arbitrary-precision oracle) must
    // become the nearest f64: one ulp off at ~1e4 (1.8e-12 = 1.8e-9·d) tilts
    // the exit of a 1e-3 lens by several 1e-9. Each origin here is a point
    // a few diameters from the lens, written with 30 significant digits.
    let mut stats = Stats::default();
    let d = 1e-3;
    let center = DVec3::new(7000.0, -5000.0, 5000.0);
    let s = spec(
        Pose {
            center,
            axis: DVec3::new(-0.5, 0.45, -0.6),
            d,
        },
        0.5 * d,
        0.5 * d,
        1.5,
    );
    let lens = lens_under_test(&s);
    let (a, e1, e2) = frame(&s);
    let mut rng = Rng::new(20, 0);
    let mut rays = Vec::new();
    let mut origins = Vec::new();
    for i in 0..300 {
        let phi = rng.range(0.0, TAU);
        let rho = [0.0, 0.5, 0.99, rng.f().sqrt()][i % 4] * 0.5 * d;
        let o = center + 3.0 * d * a + rho * (phi.cos() * e1 + phi.sin() * e2);
        // Extra digits below the f64's: a decimal between neighbouring f64s.
        let text: Vec<String> = o
            .to_array()
            .iter()
            .map(|c| format!("{c:.12}{:014}", (rng.f() * 1e14) as u64))
            .collect();
        origins.push(
            text.iter()
                .map(|t| t.parse::<f64>().expect("a number"))
                .collect::<Vec<_>>(),
        );
        let dir = (-a).to_array();
        rays.push(format!(
            r#"{{"origin": [{}], "direction": [{}, {}, {}]}}"#,
            text.join(", "),
            dir[0],
            dir[1],
            dir[2]
        ));
    }
    let json = format!(
        r#"{{"cases": [{{"lens": {{"center": [{}, {}, {}], "axis": [{}, {}, {}], "d": {}, "R1": {}, "R2": {}, "n": {}}}, "rays": [{}]}}]}}"#,
        s.center[0],
        s.center[1],
        s.center[2],
        s.axis[0],
        s.axis[1],
        s.axis[2],
        s.d,
        s.r1,
        s.r2,
        s.n,
        rays.join(", ")
    );
    let input: lensview::lens_tools::TraceInput = serde_json::from_str(&json).expect("valid input");
    let out = lensview::lens_tools::trace_cases(&input).expect("traced");
    for ((ray, got), o) in input.cases[0]
        .rays
        .iter()
        .zip(out.cases[0].rays.iter().filter_map(|r| r.lens()))
        .zip(&origins)
    {
        // Read as the nearest f64, as Rust's own parser does.
        assert_eq!(ray.origin.as_slice(), o.as_slice(), "origin misread");
        let want = check(
            &s,
            &lens,
            DVec3::from_slice(o),
            DVec3::from_array(ray.direction),
            &mut stats,
        );
        // What `lens trace` printed, against the reference from that origin.
        let (g, w) = (got.exit_direction.expect("leaves"), want.exit.expect("leaves"));
        assert!(
            distance(g, w.dir) <= DIR_TOLERANCE,
            "exit direction {g:?}, reference {:?}",
            w.dir.to_f64()
        );
    }
    finish("lens_trace_json_near_a_tiny_far_lens", &stats, 0.01);
}

#[test]
fn lenses_at_the_edges_of_the_supported_domain() {
    // The corners of `lensview::math::domain`: coordinates ±1e9, lengths
    // 1e-9 and 1e9 (a plano-like face of radius 1e9), the smallest diameter
    // allowed at a distance (1e-7 of it), and indices 1 and 10.
    let mut stats = Stats::default();
    // (centre, axis, [d, r1, r2, n]).
    let cases = [
        ([1e9, -1e9, 1e9], [0.3, -0.4, 0.8], [100.0, 60.0, 1e9, 10.0]),
        ([-1e9, 5.0, 3e8], [-1.0, 0.2, 0.1], [100.0, 1e9, 1e9, 1.5]),
        ([0.01, 0.0, -0.005], [0.1, 1.0, 0.3], [1e-9, 0.6e-9, 2e-9, 1.0]),
        ([0.01, 0.0, -0.005], [0.1, 1.0, 0.3], [1e-9, 0.5e-9, 0.5e-9, 10.0]),
        ([0.0; 3], [0.0, 0.6, -0.8], [1e9, 1e9, 0.5e9, 1.7]),
    ];
    for (k, (center, axis, [d, r1, r2, n])) in cases.into_iter().enumerate() {
        let (center, axis) = (DVec3::from(center), DVec3::from(axis));
        let s = spec(Pose { center, axis, d }, r1, r2, n);
        let lens = lens_under_test(&s);
        let mut rng = Rng::new(21, k as u64);
        for i in 0..300 {
            let (o, u) = match i % 3 {
                2 => any_ray(&s, &mut rng),
                side => aperture_ray(&s, &mut rng, 0.99, 0.6, side == 0),
            };
            check(&s, &lens, o, u, &mut stats);
        }
    }
    finish("lenses_at_the_edges_of_the_supported_domain", &stats, 0.02);
    // Just outside, a refusal naming the field.
    let refused = |c: DVec3, d: f64, r: f64, n: f64| {
        Lens::new(c, DVec3::Z, d, r, r, Index::Constant(n))
            .map(|_| ())
            .unwrap_err()
            .field()
    };
    assert_eq!(refused(DVec3::new(0.0, 1.0000001e9, 0.0), 1e3, 1e3, 1.5), "center");
    assert_eq!(refused(DVec3::new(0.0, 1e9, 0.0), 99.0, 1e3, 1.5), "d");
    assert_eq!(refused(DVec3::ZERO, 0.9e-9, 1.0, 1.5), "d");
    assert_eq!(refused(DVec3::ZERO, 1.1e9, 1.1e9, 1.5), "d");
    assert_eq!(refused(DVec3::ZERO, 1.0, 1.0000001e9, 1.5), "r1");
    assert_eq!(refused(DVec3::ZERO, 1.0, 1.0, 10.000001), "n");
    assert_eq!(refused(DVec3::ZERO, 1.0, 1.0, 1e78), "n");
}
