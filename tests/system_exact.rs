//! Lens systems (docs/lens-systems.md, issue #31): `lensview lens trace` on
//! systems against the independent double-double reference of
//! `tests/reference/system.rs`, and the reference's own self-checks.
//!
//! `reference_*` tests check the reference alone (they pass without the
//! crate's side): (a) a biconvex lens written as a 2-surface system against
//! the biconvex reference of `tests/reference/mod.rs`; (b) the same tracer in
//! DD and in f64 on easy rays; (c) a paraxial ray's real axis crossing, EFL
//! and FFD against an independent y–nu trace (which also must give the thick
//! lens formulas of README "The lens"); the glass data; the case sets.
//!
//! `lens_trace_systems_match_reference` writes every case of
//! `reference::system_cases` to JSON, runs the binary's `lens trace` and
//! compares each ray: status, reflection count, every event (surface, piece,
//! kind; point within `1e-9·L`, direction within 1e-9, `L` the first-to-last
//! vertex distance or the largest semi-aperture if larger) and the exit.
//! Excused, only where the crate differs, and counted: a ray whose reference
//! path meets a piece within `1e-10·L` of its border (at most 1 % of the
//! rays), or whose exact path moves by more than a tenth of the tolerance
//! under a nudge of one rounding at the system's scale (ε·L, ε) of its input
//! (chaotic chains of total reflections in the index-4 singlet; at most 2 %).
//!
//! `cargo test --release --test system_exact -- --nocapture` prints the
//! numbers.

#![allow(clippy::neg_cmp_op_on_partial_ord)]

#[path = "system_exact/compare.rs"]
mod compare;
#[allow(dead_code)]
mod reference;

use compare::{Stats, compare_case, ill_conditioned, printed_by, run_lens_trace};
use reference::system::{D_LINE_UM, Medium, paraxial, trace, trace_from};
use reference::system::{Kind, Paraxial, Piece, Status, SurfaceSpec, SysPath, System, SystemSpec};
use reference::system_cases::{self as cases, Case, Frame, RayKind, Rng};
use reference::{DD, LensSpec, Real, V3};

const DIR_TOLERANCE: f64 = 1e-9;
const POS_TOLERANCE: f64 = 1e-9;
const MARGIN_SKIP: f64 = 1e-10;
const SEED: u64 = 31;

fn dd(x: f64) -> DD {
    DD::new(x)
}

/// `|got − want|` in DD.
fn distance(got: [f64; 3], want: V3<DD>) -> f64 {
    (V3::<DD>::of(got) - want).length().to_f64()
}

fn max_abs(v: [f64; 3]) -> f64 {
    v.iter().fold(0.0f64, |m, c| m.max(c.abs()))
}

// ---------------------------------------------------------------------------
// (a) the biconvex lens as a two-surface system
// ---------------------------------------------------------------------------

/// The system of the biconvex lens `l` (README "The lens"): first vertex
/// `C + a·sag1` and thickness `sag1 + sag2`, both in DD.
fn biconvex_system(l: &LensSpec) -> System<DD> {
    let g = reference::Geometry::<DD>::new(l);
    let v1 = g.vertex(reference::Face::S1);
    let t = (v1 - g.vertex(reference::Face::S2)).dot(g.axis);
    let n = Medium::Index(l.n);
    let specs = [
        SurfaceSpec {
            radius: l.r1,
            thickness: 0.0,
            n,
            semi_aperture: l.d / 2.0,
            stop: false,
        },
        SurfaceSpec {
            radius: -l.r2,
            thickness: 0.0,
            n: Medium::AIR,
            semi_aperture: l.d / 2.0,
            stop: false,
        },
    ];
    System::with_pose(v1, V3::of(l.axis), &specs, &[t, dd(0.0)])
}

#[test]
fn reference_self_check_biconvex_as_two_surfaces() {
    let lenses = [
        ([0.3, -1.7, 2.9], [0.36, -0.48, 0.8], 2.0, 5.0, 5.0, 1.5),
        ([-12.5, 4.25, 7.0], [-1.0, 2.0, 0.5], 0.37, 0.3, 0.5, 2.4),
        ([101.0, -3.3, -47.25], [0.1, -0.2, -1.0], 5.0, 2.6, 40.0, 1.7),
        ([7000.0, -5000.0, 5000.0], [-0.5, 0.45, -0.6], 1e-3, 1e-3, 7e-4, 1.5),
    ];
    let mut rng = Rng::new(SEED);
    let (mut compared, mut reflections) = (0, 0);
    // Worst exit point (over d) and direction: rays without and with total
    // internal reflections (whose chains amplify the last bits).
    let (mut worst, mut worst_tir) = ([0.0f64; 2], [0.0f64; 2]);
    for (center, axis, d, r1, r2, n) in lenses {
        let l = LensSpec {
            center,
            axis,
            d,
            r1,
            r2,
            n,
        };
        let sys = biconvex_system(&l);
        for _ in 0..400 {
            // From a sphere of radius 3d about the centre, aimed within 0.45d.
            let (o, dir) = any_ray(center, d, &mut rng);
            let want = reference::trace::<DD>(&l, o, dir);
            if want.rim_distance < 1e-6 * d {
                continue;
            }
            let got = trace(&sys, o, dir, D_LINE_UM);
            let status = match want.status {
                reference::Status::Transmitted => Status::Transmitted,
                reference::Status::Miss => Status::Miss,
                reference::Status::Trapped => Status::Trapped,
            };
            assert_eq!(got.status, status, "status, lens {l:?}, ray {o:?} {dir:?}");
            assert_eq!(got.reflections, want.reflections, "reflections, ray {o:?} {dir:?}");
            if let (Some(g), Some(w)) = (got.exit(), want.exit) {
                let w_ = if got.reflections == 0 {
                    &mut worst
                } else {
                    &mut worst_tir
                };
                w_[0] = w_[0].max((g.point - w.point).length().to_f64() / d);
                w_[1] = w_[1].max((g.dir - w.dir).length().to_f64());
            }
            compared += 1;
            reflections += got.reflections;
        }
    }
    println!(
        "biconvex as a system: {compared} rays ({reflections} reflections); worst exit point and direction \
         {:.2e}·d, {:.2e} without reflections, {:.2e}·d, {:.2e} with",
        worst[0], worst[1], worst_tir[0], worst_tir[1]
    );
    assert!(compared > 1200 && reflections > 50);
    // DD carries ~1e-32 of the coordinates: 1e-25 of the 1e-3 lens at 1e4.
    assert!(worst[0] < 1e-24 && worst[1] < 1e-23, "{worst:?}");
    assert!(worst_tir[0] < 1e-20 && worst_tir[1] < 1e-20, "{worst_tir:?}");
}

fn any_ray(center: [f64; 3], d: f64, rng: &mut Rng) -> ([f64; 3], [f64; 3]) {
    let mut unit = || {
        let z = rng.range(-1.0, 1.0);
        let phi = rng.range(0.0, std::f64::consts::TAU);
        let s = (1.0 - z * z).sqrt();
        [s * phi.cos(), s * phi.sin(), z]
    };
    let (a, b) = (unit(), unit());
    let k = 0.45 * d * rng.f().cbrt();
    let o: Vec<f64> = (0..3).map(|i| center[i] + 3.0 * d * a[i]).collect();
    let t: Vec<f64> = (0..3).map(|i| center[i] + k * b[i]).collect();
    ([o[0], o[1], o[2]], [t[0] - o[0], t[1] - o[1], t[2] - o[2]])
}

// ---------------------------------------------------------------------------
// (b) DD against f64
// ---------------------------------------------------------------------------

/// The structure of a path: (surface, piece, kind) per event.
fn structure<T: Real>(p: &SysPath<T>) -> Vec<(usize, Piece, Kind)> {
    p.events.iter().map(|e| (e.surface, e.piece, e.kind)).collect()
}

#[test]
fn reference_self_check_dd_agrees_with_f64() {
    let (mut compared, mut worst_pos, mut worst_dir) = (0, 0.0f64, 0.0f64);
    let mut rng = Rng::new(SEED + 1);
    for case in cases::cases(SEED).iter().filter(|c| !c.id.contains("far")) {
        let spec = &case.system;
        let easy = [
            RayKind::Aimed {
                front: true,
                frac: 0.9,
                deg: 20.0,
            },
            RayKind::Aimed {
                front: false,
                frac: 0.9,
                deg: 20.0,
            },
        ];
        let (sd, sf) = (System::<DD>::new(spec), System::<f64>::new(spec));
        for ray in cases::rays(spec, &mut rng, &easy, 50, &[None]) {
            let want = trace(&sd, ray.origin, ray.direction, D_LINE_UM);
            if want.margin < 1e-6 {
                continue;
            }
            let got = trace(&sf, ray.origin, ray.direction, D_LINE_UM);
            assert_eq!(structure(&got), structure(&want), "{} {}", case.id, ray.id);
            for (g, w) in got.events.iter().zip(&want.events) {
                worst_pos = worst_pos.max(distance(g.point.to_f64(), w.point) / spec.length());
                worst_dir = worst_dir.max(distance(g.dir.to_f64(), w.dir));
            }
            compared += 1;
        }
    }
    println!("DD against f64: {compared} easy rays, worst point {worst_pos:.2e}·L, direction {worst_dir:.2e}");
    assert!(compared >= 900);
    assert!(worst_pos < 1e-12 && worst_dir < 1e-12, "{worst_pos:e} {worst_dir:e}");
}

// ---------------------------------------------------------------------------
// (c) paraxial
// ---------------------------------------------------------------------------

/// A ray parallel to the axis at height `h` (local x), from the front or
/// the back; returns (EFL, the axis crossing's distance after the last
/// vertex (front) or before the first (back)) from the real trace.
fn real_paraxial(spec: &SystemSpec, h: f64, front: bool) -> (f64, f64) {
    let sys = System::<DD>::new(spec);
    let f = Frame::new(spec);
    let far = dd(5.0 * spec.length());
    let last = sys.surfaces[spec.surfaces.len() - 1].z;
    // Start and direction in DD: an f64 origin 1e4 from the world origin
    // would carry a rounding of the height's size.
    let e1 = V3::<DD>::of(f.dir(1.0, 0.0, 0.0));
    let e = (e1 - sys.w.scale(e1.dot(sys.w))).normalize();
    let (z0, u) = if front { (-far, sys.w) } else { (last + far, -sys.w) };
    let o = sys.vertex + sys.w.scale(z0) + e.scale(dd(h));
    let path = trace_from(&sys, o, u, D_LINE_UM);
    let exit = path
        .exit()
        .unwrap_or_else(|| panic!("paraxial ray not transmitted: {:?}", path.status));
    let (z, tr) = sys.local(exit.point);
    let (along, across) = (exit.dir.dot(sys.w), exit.dir.dot(e));
    let z_cross = z - tr.dot(e) / across * along;
    // EFL = −y₁/u′ with u′ = across/along measured along the light.
    let efl = -dd(h) * along / across;
    let (efl, cross) = if front { (efl, z_cross - last) } else { (-efl, -z_cross) };
    (efl.to_f64(), cross.to_f64())
}

fn paraxial_systems() -> Vec<(&'static str, SystemSpec)> {
    let near = |s| SystemSpec {
        vertex: cases::NEAR.0,
        axis: cases::NEAR.1,
        surfaces: s,
    };
    let far = |s| SystemSpec {
        vertex: cases::FAR.0,
        axis: cases::FAR.1,
        surfaces: s,
    };
    vec![
        ("plano-convex", near(cases::plano_convex(true))),
        ("convex-plano", near(cases::plano_convex(false))),
        ("biconcave", near(cases::biconcave())),
        ("meniscus", near(cases::meniscus())),
        ("doublet", near(cases::doublet(false))),
        ("stopped-singlet", near(cases::stopped_singlet())),
        ("double-gauss", near(cases::double_gauss())),
        ("tiny-doublet-far", far(cases::scaled(cases::doublet(true), 1e-3))),
        ("large-double-gauss-far", far(cases::scaled(cases::double_gauss(), 1e3))),
    ]
}

#[test]
fn reference_self_check_paraxial_focus() {
    for (name, spec) in paraxial_systems() {
        let p: Paraxial<DD> = paraxial(&spec, D_LINE_UM).expect("power");
        let h = 1e-6 * spec.surfaces[0].semi_aperture;
        let (efl_f, bfd) = real_paraxial(&spec, h, true);
        let (efl_b, ffd) = real_paraxial(&spec, h, false);
        let f = p.efl.to_f64();
        println!(
            "{name}: EFL {f:.9} BFD {:.9} FFD {:.9} H {:.9} H' {:.9}; real at 1e-6·a: EFL {efl_f:.9} / {efl_b:.9}, \
             BFD {bfd:.9}, FFD {ffd:.9}",
            p.bfd.to_f64(),
            p.ffd.to_f64(),
            p.h.to_f64(),
            p.h_rear.to_f64()
        );
        let close = |a: f64, b: DD| (a - b.to_f64()).abs() <= 1e-9 * f.abs();
        assert!(close(efl_f, p.efl) && close(efl_b, p.efl), "{name}: EFL");
        assert!(close(bfd, p.bfd), "{name}: BFD {bfd} against {}", p.bfd.to_f64());
        assert!(close(ffd, p.ffd), "{name}: FFD {ffd} against {}", p.ffd.to_f64());
        assert!((p.efl - p.ffd - p.h).to_f64().abs() < 1e-25 * f.abs(), "{name}: H");
    }
    // pbrt's double-Gauss is "scaled to 50 mm".
    let (_, dg) = &paraxial_systems()[6];
    let efl = paraxial::<f64>(dg, D_LINE_UM).expect("power").efl;
    assert!((efl - 50.0).abs() < 1.5, "double-Gauss EFL {efl}");
}

#[test]
fn reference_self_check_paraxial_matches_thick_lens_formulas() {
    // README "The lens": R1s = +R1, R2s = −R2 (Hecht §6.1).
    for (d, r1, r2, n) in [(2.0, 5.0, 5.0, 1.5), (20.0, 50.0, 100.0, 1.5168), (2.0, 1.0, 5.0, 1.5)] {
        let half = 0.5 * d;
        let sag = |r: f64| half * half / (r + ((r - half) * (r + half)).sqrt());
        let t = sag(r1) + sag(r2);
        let spec = SystemSpec {
            vertex: [0.0; 3],
            axis: [0.0, 0.0, 1.0],
            surfaces: vec![
                SurfaceSpec {
                    radius: r1,
                    thickness: t,
                    n: Medium::Index(n),
                    semi_aperture: half,
                    stop: false,
                },
                SurfaceSpec {
                    radius: -r2,
                    thickness: 0.0,
                    n: Medium::AIR,
                    semi_aperture: half,
                    stop: false,
                },
            ],
        };
        let p = paraxial::<DD>(&spec, D_LINE_UM).expect("power");
        let (n, r1s, r2s, t) = (dd(n), dd(r1), dd(-r2), dd(t));
        let one = dd(1.0);
        let f = one / ((n - one) * (one / r1s - one / r2s + (n - one) * t / (n * r1s * r2s)));
        let h1 = -f * (n - one) * t / (n * r2s);
        let h2 = -f * (n - one) * t / (n * r1s);
        for (got, want, what) in [
            (p.efl, f, "EFL"),
            (p.h, h1, "H"),
            (p.h_rear, h2, "H'"),
            (p.bfd, f + h2, "BFD"),
            (p.ffd, f - h1, "FFD"),
        ] {
            let err = (got - want).to_f64().abs() / f.to_f64();
            assert!(
                err < 1e-28,
                "d {d} R {r1} {r2}: {what} {} against {}",
                got.to_f64(),
                want.to_f64()
            );
        }
    }
}

#[test]
fn reference_self_check_sellmeier_glass() {
    // SCHOTT data sheets: nd and the Abbe number vd = (nd − 1)/(nF − nC).
    for (name, nd, vd) in [("N-BK7", 1.51680, 64.17), ("N-SF5", 1.67271, 32.25)] {
        let g = Medium::Glass(name);
        let n = |l: f64| g.index::<DD>(l).to_f64();
        let got = n(D_LINE_UM);
        assert!((got - nd).abs() < 1e-5, "{name}: nd {got}");
        let v = (got - 1.0) / (n(cases::F_LINE_UM) - n(cases::C_LINE_UM));
        assert!((v - vd).abs() < 0.05, "{name}: vd {v}");
        assert!((g.index::<f64>(D_LINE_UM) - got).abs() < 1e-15);
    }
}

// ---------------------------------------------------------------------------
// The case sets
// ---------------------------------------------------------------------------

/// Per case: rays by status, events by piece, TIRs at a cemented surface,
/// far-branch roots passed over.
#[derive(Default, Debug)]
struct Census {
    status: [usize; 4],
    pieces: [usize; 4],
    reflections: u32,
    cemented_tir: usize,
    far_branch: u32,
    near_border: usize,
    ill_conditioned: usize,
}

fn census(case: &Case) -> Census {
    let sys = System::<DD>::new(&case.system);
    let mut c = Census::default();
    for ray in &case.rays {
        let o = V3::<DD>::of(ray.origin);
        assert!(!sys.inside_glass(o), "{} {}: origin inside glass", case.id, ray.id);
        let p = trace_from(
            &sys,
            o,
            V3::of(ray.direction).normalize(),
            ray.wavelength_um.unwrap_or(D_LINE_UM),
        );
        c.status[p.status as usize] += 1;
        for e in &p.events {
            c.pieces[e.piece as usize] += 1;
            let s = &case.system.surfaces;
            let cemented = e.surface > 0 && !s[e.surface - 1].n.is_air() && !s[e.surface].n.is_air();
            c.cemented_tir += usize::from(cemented && e.kind == Kind::Reflect);
        }
        c.reflections += p.reflections;
        c.far_branch += p.far_branch_roots;
        c.near_border += usize::from(p.margin < MARGIN_SKIP);
        let tol = POS_TOLERANCE * case.system.length();
        let lambda = ray.wavelength_um.unwrap_or(D_LINE_UM);
        c.ill_conditioned += usize::from(ill_conditioned(&sys, ray.origin, ray.direction, lambda, &p, tol));
    }
    c
}

#[test]
fn reference_self_check_cases_cover_what_they_claim() {
    let all = cases::cases(SEED);
    let again = cases::cases(SEED);
    assert_eq!(all.len(), again.len());
    for (a, b) in all.iter().zip(&again) {
        assert!(
            a.rays
                .iter()
                .zip(&b.rays)
                .all(|(x, y)| x.origin == y.origin && x.direction == y.direction)
        );
    }
    let mut total = Census::default();
    for case in &all {
        let c = census(case);
        println!("{:24} {:4} rays {c:?}", case.id, case.rays.len());
        let has = |i: usize| c.status[i] > 0;
        assert!(has(Status::Transmitted as usize), "{}", case.id);
        let stuck = if case.id.starts_with("index-4") {
            Status::Trapped
        } else {
            Status::Absorbed
        };
        assert!(has(stuck as usize), "{}: none {}", case.id, stuck.name());
        if case.id == "doublet-steep-cemented" {
            assert!(c.cemented_tir > 0, "{}: no TIR at the cemented surface", case.id);
        }
        if case.id.contains("biconcave") {
            assert!(c.far_branch > 0, "{}: no far-branch root", case.id);
        }
        if case.id.contains("stopped") || case.id.contains("gauss") {
            assert!(
                c.pieces[Piece::Stop as usize] > 0,
                "{}: nothing vignetted by the stop",
                case.id
            );
        }
        for i in 0..4 {
            total.status[i] += c.status[i];
            total.pieces[i] += c.pieces[i];
        }
        total.near_border += c.near_border;
        total.ill_conditioned += c.ill_conditioned;
        total.reflections += c.reflections;
        total.cemented_tir += c.cemented_tir;
        total.far_branch += c.far_branch;
    }
    println!("all: {total:?}");
    // Every status and piece occurs; few rays are excusable.
    assert!(total.status.iter().all(|&n| n > 0) && total.pieces.iter().all(|&n| n > 0));
    let rays: usize = all.iter().map(|c| c.rays.len()).sum();
    assert!(
        total.near_border * 100 <= rays && total.ill_conditioned * 50 <= rays,
        "{total:?}"
    );
}

// ---------------------------------------------------------------------------
// The crate: `lens trace` on systems
// ---------------------------------------------------------------------------

#[test]
fn lens_trace_systems_match_reference() {
    let all = cases::cases(SEED);
    let printed = run_lens_trace(&all);
    let printed_cases = printed["cases"].as_array().map(Vec::as_slice).unwrap_or(&[]);
    let mut stats = Stats::default();
    for case in &all {
        match printed_cases
            .iter()
            .find(|c| c["id"].as_str() == Some(case.id.as_str()))
        {
            Some(p) => compare_case(case, p, &mut stats),
            None => stats.failures.push(format!("case {} not printed", case.id)),
        }
    }
    let rays: usize = all.iter().map(|c| c.rays.len()).sum();
    println!(
        "lens trace on systems: {} of {rays} rays compared; excused {} near a border, {} ill-conditioned; worst \
         point {:.3} and direction {:.3} of the tolerances; {} failed",
        stats.compared,
        stats.near_border,
        stats.ill_conditioned,
        stats.worst_pos,
        stats.worst_dir,
        stats.failures.len()
    );
    let shown: Vec<&String> = stats.failures.iter().take(20).collect();
    assert!(
        stats.failures.is_empty(),
        "{} rays differ from the reference: {shown:#?}",
        stats.failures.len()
    );
    assert!(
        stats.near_border * 100 <= rays && stats.ill_conditioned * 50 <= rays,
        "too many rays excused (at most 1 % near a border, 2 % ill-conditioned)"
    );
}

// ---------------------------------------------------------------------------
// The crate: paraxial data of systems
// ---------------------------------------------------------------------------

/// The crate's paraxial data of a system (EFL, BFD, FFD, H from V1, H' from
/// the last vertex; lengths along the light, FFD before V1), as
/// `lens system --json` prints them.
fn crate_paraxial(spec: &SystemSpec) -> Result<Paraxial<f64>, String> {
    let dir = tempfile::tempdir().map_err(|e| e.to_string())?;
    let path = dir.path().join("system.json");
    std::fs::write(&path, spec.to_json().to_string()).map_err(|e| e.to_string())?;
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_lensview"))
        .args(["lens", "system", "--json", "--system"])
        .arg(&path)
        .output()
        .map_err(|e| e.to_string())?;
    if !out.status.success() {
        return Err(String::from_utf8_lossy(&out.stderr).into_owned());
    }
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).map_err(|e| e.to_string())?;
    let f = |k: &str| v[k].as_f64().ok_or(format!("no `{k}` in {v}"));
    Ok(Paraxial {
        efl: f("efl")?,
        bfd: f("bfd")?,
        ffd: f("ffd")?,
        h: f("front_principal")?,
        h_rear: f("rear_principal")?,
    })
}

#[test]
fn lens_system_paraxial_data_match_the_reference() {
    for (name, spec) in paraxial_systems() {
        let want = paraxial::<DD>(&spec, D_LINE_UM).expect("power");
        let got = crate_paraxial(&spec).unwrap_or_else(|e| panic!("{name}: {e}"));
        let f = want.efl.to_f64().abs();
        for (what, g, w) in [
            ("EFL", got.efl, want.efl),
            ("BFD", got.bfd, want.bfd),
            ("FFD", got.ffd, want.ffd),
            ("H", got.h, want.h),
            ("H'", got.h_rear, want.h_rear),
        ] {
            assert!(
                (g - w.to_f64()).abs() <= 1e-12 * f,
                "{name}: {what} {g}, reference {}",
                w.to_f64()
            );
        }
    }
}

#[test]
fn reference_self_check_comparison_of_printed_rays() {
    // The comparison accepts the reference's own output rounded to f64, and
    // tells the naive f64 tracer from it on the tiny and far systems.
    let all = cases::cases(SEED);
    for (name, printed, must_pass) in [
        ("DD", printed_by::<DD>(&all), true),
        ("f64", printed_by::<f64>(&all), false),
    ] {
        let mut stats = Stats::default();
        let mut failed_cases = std::collections::BTreeSet::new();
        for (case, p) in all.iter().zip(printed["cases"].as_array().expect("cases")) {
            let before = stats.failures.len();
            compare_case(case, p, &mut stats);
            if stats.failures.len() > before {
                failed_cases.insert(case.id.clone());
            }
        }
        println!(
            "{name} tracer as `lens trace`: {} rays, {} failed (cases {failed_cases:?}), worst passing point {:.2e} \
             and direction {:.2e} of the tolerances",
            stats.compared,
            stats.failures.len(),
            stats.worst_pos,
            stats.worst_dir
        );
        if must_pass {
            assert!(
                stats.failures.is_empty(),
                "{:#?}",
                &stats.failures[..stats.failures.len().min(5)]
            );
            // Only the rounding of the printed numbers (≤ 4ε·|x| of slack).
            assert!(stats.worst_pos < 0.1 && stats.worst_dir < 1e-3);
        } else {
            assert!(
                failed_cases.iter().any(|c| c.contains("tiny") && c.contains("far")),
                "{failed_cases:?}"
            );
        }
    }
}
