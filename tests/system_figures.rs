//! Figures of lens systems (`lens fan | spot | distortion --preset …`):
//! a biconvex lens written as a system gives the biconvex figures' numbers;
//! the double Gauss's marginal ray and chief rays against an independent
//! meridional trace (surface by surface, Spencer & Murty's form); the
//! achromat's colour against an N-BK7 singlet; the CLI's refusals.

// `!(x <= tol)` on purpose: it also fails for NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod support;

use glam::DVec3;
use lensview::geometry::{LensSystem, SurfaceSpec};
use lensview::lens_tools::setup::SPOT_WAVELENGTHS_UM;
use lensview::lens_tools::system_bench::{Aim, SystemBench};
use lensview::lens_tools::system_fan::system_fan;
use lensview::lens_tools::system_spot::{system_distortion, system_spot};
use lensview::lens_tools::{Setup, fan, spot_diagram};
use lensview::optics::{Index, WAVELENGTH_D_UM, sagitta};
use lensview::prescription;
use serde_json::Value;
use support::run;

fn preset(name: &str) -> LensSystem {
    let rows = prescription::parse(name, prescription::preset(name).unwrap()).unwrap();
    LensSystem::new(DVec3::ZERO, DVec3::Z, SurfaceSpec::from_rows(&rows, 1.0)).unwrap()
}

fn surface(radius: f64, thickness: f64, n: Index, semi_aperture: f64) -> SurfaceSpec {
    SurfaceSpec {
        radius,
        thickness,
        n,
        semi_aperture,
        stop: false,
    }
}

/// The biconvex lens (d, R1, R2, n) as a two-surface system.
fn biconvex(d: f64, r1: f64, r2: f64, n: Index) -> LensSystem {
    let h = 0.5 * d;
    let t = sagitta(r1, h) + sagitta(r2, h);
    let s = vec![surface(r1, t, n, h), surface(-r2, 0.0, Index::Constant(1.0), h)];
    LensSystem::new(DVec3::ZERO, DVec3::Z, s).unwrap()
}

/// The lenses of the comparison: (d, R1, R2, n, object distance, field °).
fn cases() -> Vec<(f64, f64, f64, Index, Option<f64>, f64)> {
    let cauchy = Index::Cauchy { a: 1.5, b: 0.004 };
    vec![
        (20.0, 50.0, 100.0, Index::Constant(1.5168), None, 0.0),
        (20.0, 50.0, 100.0, Index::Constant(1.5168), None, 5.0),
        (20.0, 50.0, 100.0, Index::Constant(1.5168), Some(300.0), 3.0),
        (2.0, 5.0, 5.0, cauchy, None, 0.0),
        (2.0, 5.0, 5.0, cauchy, None, -4.0),
        (2.0, 1.0, 5.0, Index::Constant(1.7), Some(20.0), 0.0),
    ]
}

/// The biconvex bench and the same lens as a system, aimed at the same
/// pupil (0.9·d/2 in the plane through the lens's centre C).
fn both(c: &(f64, f64, f64, Index, Option<f64>, f64)) -> (Setup, SystemBench) {
    let &(d, r1, r2, n, obj, field) = c;
    let setup = Setup::new(d, r1, r2, n, obj, field).unwrap();
    let aim = Aim {
        z: setup.sag1(),
        radius: 0.9 * 0.5 * d,
    };
    let bench = SystemBench::new(biconvex(d, r1, r2, n), obj, field)
        .unwrap()
        .with_aim(aim);
    (setup, bench)
}

#[test]
fn a_biconvex_lens_as_a_system_gives_the_biconvex_fan_and_lsa() {
    let (mut worst, mut worst_lsa) = (0.0f64, 0.0f64);
    for c in cases() {
        let (setup, bench) = both(&c);
        let tol = 1e-9 * c.0;
        let a = fan(&setup, 11, None).unwrap();
        let b = system_fan(&bench, 11, None).unwrap();
        assert!(
            (a.image_plane_from_v2 - b.image_plane_from_last_vertex).abs() <= tol,
            "{c:?}"
        );
        for (ra, rb) in a.rays.iter().zip(&b.rays) {
            assert_eq!(ra.ray.status, rb.ray.status, "{c:?}");
            match (ra.ray.image_point, rb.ray.image_point) {
                (Some(pa), Some(pb)) => {
                    worst = worst.max((pa[0] - pb[0]).abs() / c.0);
                    assert!((pa[0] - pb[0]).abs() <= tol, "{c:?}: {pa:?} {pb:?}");
                    assert!((pa[1] + pb[1]).abs() <= tol, "{c:?}: {pa:?} {pb:?}");
                }
                (None, None) => {}
                (pa, pb) => panic!("{c:?}: {pa:?} {pb:?}"),
            }
        }
        assert_eq!(a.lsa.len(), b.lsa.len());
        for (la, lb) in a.lsa.iter().zip(&b.lsa) {
            assert!((la.height - lb.height).abs() <= tol);
            let (Some(fa), Some(fb)) = (la.focus_from_v2, lb.focus_from_last_vertex) else {
                assert_eq!(la.focus_from_v2, lb.focus_from_last_vertex, "{c:?}");
                continue;
            };
            // An axial crossing: the transverse 1e-9·d over the ray's slope.
            let slope = lb.height / fb.abs().max(c.0);
            worst_lsa = worst_lsa.max((fa - fb).abs() * slope / c.0);
            assert!((fa - fb).abs() <= tol / slope, "{c:?}: {fa} {fb}");
            assert!((la.lsa.unwrap() - lb.lsa.unwrap()).abs() <= tol / slope, "{c:?}");
        }
        match (
            a.cardinal.object_marginal_focus_from_v2,
            b.cardinal.marginal_focus_from_last_vertex,
        ) {
            (Some(ma), Some(mb)) => assert!((ma - mb).abs() <= 1e-8 * ma.abs().max(c.0), "{c:?}: {ma} {mb}"),
            (ma, mb) => assert_eq!(ma, mb, "{c:?}"),
        }
    }
    eprintln!("fan: largest |Δx|/d {worst:e}; LSA: largest |Δ focus|·slope/d {worst_lsa:e}");
}

#[test]
fn a_biconvex_lens_as_a_system_gives_the_biconvex_spots() {
    let mut worst = 0.0f64;
    for c in cases() {
        let (setup, bench) = both(&c);
        let tol = 1e-9 * c.0;
        let a = spot_diagram(&setup, None, 6).unwrap();
        let b = system_spot(&bench, None, 6).unwrap();
        for (sa, sb) in a.spots.iter().zip(&b.spots) {
            assert_eq!(sa.line, sb.line);
            assert_eq!(sa.ray_count, sb.ray_count, "{c:?}");
            assert!(sa.ray_count >= 91, "{c:?}");
            let (ca, cb) = (sa.centroid.unwrap(), sb.centroid.unwrap());
            assert!((ca[0] - cb[0]).abs() <= tol && (ca[1] + cb[1]).abs() <= tol, "{c:?}");
            let (qa, qb) = (sa.rms_radius.unwrap(), sb.rms_radius.unwrap());
            assert!((qa - qb).abs() <= tol, "{c:?} {}: {qa} {qb}", sa.line);
            worst = worst.max((qa - qb).abs() / c.0);
        }
    }
    eprintln!("spot: largest |Δ RMS|/d {worst:e}");
}

/// An independent meridional trace through the caps of `sys` (local
/// frame, (x, z)): from the point `p` along the unit `u`, surface by
/// surface up to (not including) surface `to`, at `lambda`. Spencer &
/// Murty's intersection `t = F/(G + √(G² − cF))` and the vector form of
/// Snell's law.
fn meridional(sys: &LensSystem, mut p: [f64; 2], mut u: [f64; 2], to: usize, lambda: f64) -> ([f64; 2], [f64; 2]) {
    for k in 0..to {
        let s = &sys.surfaces[k];
        let n1 = if k == 0 { 1.0 } else { sys.surfaces[k - 1].n.at(lambda) };
        let n2 = s.n.at(lambda);
        if n1 == n2 {
            continue;
        }
        let c = s.curvature();
        let w = p[1] - sys.vertex_z(k);
        let f = c * (p[0] * p[0] + w * w) - 2.0 * w;
        let g = u[1] - c * (p[0] * u[0] + w * u[1]);
        let t = f / (g + (g * g - c * f).sqrt());
        p = [p[0] + t * u[0], p[1] + t * u[1]];
        let w = p[1] - sys.vertex_z(k);
        // The normal (−c·x, 1 − c·w), unit, along the light.
        let (nx, nz) = (-c * p[0], 1.0 - c * w);
        let l = nx.hypot(nz);
        let (nx, nz) = (nx / l, nz / l);
        let cos_i = u[0] * nx + u[1] * nz;
        let mu = n1 / n2;
        let cos_t = (1.0 - mu * mu * (1.0 - cos_i * cos_i)).sqrt();
        let k2 = cos_t - mu * cos_i;
        u = [mu * u[0] + k2 * nx, mu * u[1] + k2 * nz];
    }
    (p, u)
}

#[test]
fn the_double_gauss_marginal_ray_crosses_the_axis_where_an_independent_trace_does() {
    let sys = preset("double-gauss-50mm");
    let bench = SystemBench::new(sys.clone(), None, 0.0).unwrap();
    let fan = system_fan(&bench, 3, None).unwrap();
    let n = sys.len();
    for (px, got) in [
        (1.0, fan.cardinal.marginal_focus_from_last_vertex.unwrap()),
        (0.5, fan.lsa[15].focus_from_last_vertex.unwrap()),
    ] {
        let (o, u) = bench.ray(px, 0.0);
        let (p, v) = meridional(&sys, [o.x, o.z], [u.x, u.z], n, WAVELENGTH_D_UM);
        let want = p[1] - p[0] * v[1] / v[0] - sys.length();
        assert!((got - want).abs() <= 1e-9 * want, "px {px}: {got} {want}");
    }
    // The real marginal focus lies behind the paraxial focus: the design's
    // over-corrected zone (LSA +0.17 mm at the rim, −0.06 mm at 0.7).
    let bfd = fan.cardinal.info.bfd.unwrap();
    let marginal = fan.cardinal.marginal_focus_from_last_vertex.unwrap();
    assert!((marginal - bfd - 0.1732).abs() < 1e-3, "{marginal} {bfd}");
    assert!(fan.lsa.iter().all(|l| l.ray.status == "transmitted"));
    // The paraxial limit: LSA ∝ h² at small h.
    let (l1, l2) = (fan.lsa[0].lsa.unwrap(), fan.lsa[1].lsa.unwrap());
    assert!((l2 / l1 - 4.0).abs() < 0.05, "{l1} {l2}");
}

#[test]
fn the_chief_ray_crosses_the_stop_centre() {
    for (name, fields) in [
        ("double-gauss-50mm", &[1.0, 10.0, 20.0][..]),
        ("cooke-triplet-100mm", &[5.0, 15.0]),
        ("fisheye-10mm", &[10.0, 40.0]),
        ("wide-22mm", &[10.0, 30.0]),
    ] {
        let sys = preset(name);
        for &field in fields {
            let bench = SystemBench::new(sys.clone(), None, field).unwrap();
            let stop = bench.paraxial.stop;
            let chief = bench.chief_ray(WAVELENGTH_D_UM).unwrap();
            let a = sys.surfaces[stop].semi_aperture;
            assert!(
                chief.stop_height.abs() <= 1e-9 * a,
                "{name} {field}°: {}",
                chief.stop_height
            );
            // Independently: traced to the stop's plane.
            let (o, u) = (chief.origin, chief.dir);
            let (p, v) = meridional(&sys, [o.x, o.z], [u.x, u.z], stop, WAVELENGTH_D_UM);
            let x = p[0] + (sys.vertex_z(stop) - p[1]) * v[0] / v[1];
            assert!(x.abs() <= 1e-9 * a, "{name} {field}°: {x}");
            // Not the paraxial aim: pupil aberration moves it.
            assert!(chief.px != 0.0);
        }
    }
}

#[test]
fn distortion_vanishes_in_the_small_field_limit_and_grows_as_the_designs_say() {
    let sys = preset("double-gauss-50mm");
    let bench = SystemBench::new(sys, None, 0.0).unwrap();
    let small = system_distortion(&bench, 0.01, 1).unwrap();
    assert!(small.points[0].distortion_percent.unwrap().abs() < 1e-5, "{small:?}");
    let d = system_distortion(&bench, 20.0, 4).unwrap();
    let pct: Vec<f64> = d.points.iter().map(|p| p.distortion_percent.unwrap()).collect();
    // Barrel, growing with the field (≈ −1.07 % at 20°).
    assert!(pct.windows(2).all(|w| w[1] < w[0] && w[0] < 0.0), "{pct:?}");
    assert!((pct[3] + 1.074).abs() < 0.01, "{pct:?}");
    let fisheye = SystemBench::new(preset("fisheye-10mm"), None, 0.0).unwrap();
    let f = system_distortion(&fisheye, 40.0, 1).unwrap();
    assert!(f.points[0].distortion_percent.unwrap() < -10.0, "{f:?}");
}

/// An equiconvex N-BK7 singlet of the achromat's focal length and aperture.
fn singlet(efl: f64) -> LensSystem {
    let glass = Index::Glass(lensview::glass::lookup("N-BK7").unwrap());
    let make = |r: f64| {
        let s = vec![
            surface(r, 5.0, glass, 12.7),
            surface(-r, 0.0, Index::Constant(1.0), 12.7),
        ];
        LensSystem::new(DVec3::ZERO, DVec3::Z, s).unwrap()
    };
    // EFL grows with R: bisect.
    let (mut lo, mut hi) = (60.0, 200.0);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if make(mid).paraxial(WAVELENGTH_D_UM).efl < efl {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    make(0.5 * (lo + hi))
}

#[test]
fn the_achromat_has_less_axial_colour_than_a_singlet() {
    let achromat = preset("achromat-AC254-100-A");
    let efl = achromat.paraxial(WAVELENGTH_D_UM).efl;
    let single = singlet(efl);
    assert!((single.paraxial(WAVELENGTH_D_UM).efl - efl).abs() < 1e-9 * efl);
    // A narrow beam (F/17), where spherical aberration is small and the
    // C and F spots at the d focus are set by the colour.
    let narrow = |sys: &LensSystem| {
        let b = SystemBench::new(sys.clone(), None, 0.0).unwrap();
        let aim = Aim { z: 0.0, radius: 3.0 };
        let spot = system_spot(&b.with_aim(aim), None, 8).unwrap();
        let rms: Vec<f64> = spot.spots.iter().map(|s| s.rms_radius.unwrap()).collect();
        assert!(spot.spots.iter().all(|s| s.ray_count == s.rays.len()));
        rms
    };
    let (a, s) = (narrow(&achromat), narrow(&single));
    eprintln!("F/17 RMS (C, d, F): achromat {a:?}, singlet {s:?}");
    assert_eq!(SPOT_WAVELENGTHS_UM[0].0, "C");
    for i in [0, 2] {
        assert!(a[i] < 0.25 * s[i], "{a:?} {s:?}");
    }
    // Through the CLI at the full aperture: every ray gets there.
    let spec = |sys: &LensSystem| {
        let surfaces: Vec<Value> = (sys.surfaces.iter())
            .map(|f| serde_json::json!({"radius": f.radius, "thickness": f.thickness, "n": "N-BK7", "semi_aperture": f.semi_aperture}))
            .collect();
        serde_json::json!({"vertex": [0, 0, 0], "surfaces": surfaces})
    };
    let mut s = spec(&single);
    s["surfaces"][1]["n"] = 1.into();
    let path = std::env::temp_dir().join(format!("lensview-singlet-{}.json", std::process::id()));
    std::fs::write(&path, s.to_string()).unwrap();
    let rms = |args: &[&str]| -> Vec<f64> {
        let (ok, out, err) = run(args);
        assert!(ok, "{err}");
        let v: Value = serde_json::from_str(&out).unwrap();
        let spots = v["spots"].as_array().unwrap();
        spots.iter().map(|s| s["rms_radius"].as_f64().unwrap()).collect()
    };
    let p = path.display().to_string();
    let sl = rms(&["lens", "spot", "--system", &p, "--json"]);
    let ac = rms(&["lens", "spot", "--preset", "achromat-AC254-100-A", "--json"]);
    std::fs::remove_file(&path).unwrap();
    eprintln!("full aperture RMS (C, d, F): achromat {ac:?}, singlet {sl:?}");
    for i in [0, 2] {
        assert!(ac[i] < 0.2 * sl[i], "{ac:?} {sl:?}");
    }
}

#[test]
fn mixed_or_missing_lens_flags_are_refused_in_one_line() {
    let dat = std::env::temp_dir().join(format!("lensview-fig-{}.dat", std::process::id()));
    std::fs::write(&dat, "50 5 1.5 20\n-50 0 1 20\n").unwrap();
    let dat = dat.display().to_string();
    for (args, names) in [
        (
            vec!["lens", "fan", "--preset", "double-gauss-50mm", "--d", "2", "--json"],
            &["--d", "--preset"][..],
        ),
        (
            vec!["lens", "spot", "--prescription", &dat, "--r1", "5", "--n", "1.5"],
            &["--r1", "--n", "--prescription"],
        ),
        (
            vec![
                "lens",
                "distortion",
                "--preset",
                "double-gauss-50mm",
                "--prescription",
                &dat,
            ],
            &["--preset", "--prescription"],
        ),
        (vec!["lens", "spot", "--d", "2", "--r1", "5", "--r2", "5"], &["--n"]),
        (
            vec![
                "lens", "spot", "--d", "2", "--r1", "5", "--r2", "5", "--n", "1.5", "--scale", "2",
            ],
            &["--scale"],
        ),
        (vec!["lens", "fan", "--preset", "no-such", "--json"], &["--preset"]),
        (
            vec!["lens", "spot", "--preset", "double-gauss-50mm", "--scale", "-1"],
            &["--scale"],
        ),
    ] {
        let (ok, _, err) = run(&args);
        assert!(!ok, "{args:?} accepted");
        assert_eq!(err.trim().lines().count(), 1, "{args:?}: {err}");
        for n in names {
            assert!(err.contains(n), "{args:?}: {err}");
        }
    }
    // A prescription file and its scale are accepted.
    let (ok, out, err) = run(&["lens", "spot", "--prescription", &dat, "--scale", "2"]);
    assert!(ok && out.contains("RMS radius"), "{err}");
    std::fs::remove_file(&dat).unwrap();
}

#[test]
fn the_double_gauss_fan_is_drawn_with_its_elements_stop_and_marks() {
    let out = std::env::temp_dir().join(format!("lensview-dg-{}.svg", std::process::id()));
    let o = out.display().to_string();
    let (ok, stdout, err) = run(&[
        "lens",
        "fan",
        "--preset",
        "double-gauss-50mm",
        "--rays",
        "9",
        "-o",
        &o,
        "--json",
    ]);
    assert!(ok, "{err}");
    let text = std::fs::read_to_string(&out).unwrap();
    std::fs::remove_file(&out).unwrap();
    // Axis, 6 glass cells, the diaphragm's two blades, 9 rays, image plane, H and H′.
    assert_eq!(text.matches("<polyline").count(), 1 + 6 + 2 + 9 + 1 + 2);
    for label in [">stop<", ">F′<", ">H<", ">H′<"] {
        assert!(text.contains(label), "{label}");
    }
    let v: Value = serde_json::from_str(&stdout).unwrap();
    let rays = v["rays"].as_array().unwrap();
    assert!(rays.iter().all(|r| r["status"] == "transmitted"));
    // Every ray ends in the paraxial image plane: last vertex + BFD.
    let bfd = v["cardinal"]["bfd"].as_f64().unwrap();
    for r in rays {
        let path = r["path"].as_array().unwrap();
        let end = path.last().unwrap()[2].as_f64().unwrap();
        assert!((end - 32.04 - bfd).abs() < 1e-9, "{end}");
    }
    assert_eq!(v["lsa"].as_array().unwrap().len(), 32);
}

#[test]
fn aiming_at_the_real_chief_ray_lets_a_fisheye_image_a_wide_field() {
    let count = |extra: &[&str]| -> u64 {
        let mut args = vec![
            "lens",
            "spot",
            "--preset",
            "fisheye-10mm",
            "--field-deg",
            "60",
            "--json",
        ];
        args.extend(extra);
        let (ok, out, err) = run(&args);
        assert!(ok, "{err}");
        let v: Value = serde_json::from_str(&out).unwrap();
        v["spots"][1]["ray_count"].as_u64().unwrap()
    };
    // Through the paraxial pupil every ray is stopped; around the real
    // chief ray most get there.
    assert_eq!(count(&[]), 0);
    assert!(count(&["--aim-chief"]) > 90);
    // Equidistant (f·θ) mapping: the real height at 60° is f·π/3 within 1 %.
    let bench = SystemBench::new(preset("fisheye-10mm"), None, 0.0).unwrap();
    let d = system_distortion(&bench, 60.0, 1).unwrap();
    let h = d.points[0].real_height.unwrap().abs();
    let f_theta = d.efl * std::f64::consts::FRAC_PI_3;
    assert!((h / f_theta - 1.0).abs() < 0.01, "{h} {f_theta}");
    let (ok, _, err) = run(&[
        "lens",
        "spot",
        "--d",
        "2",
        "--r1",
        "5",
        "--r2",
        "5",
        "--n",
        "1.5",
        "--aim-chief",
    ]);
    assert!(
        !ok && err.trim().lines().count() == 1 && err.contains("--aim-chief"),
        "{err}"
    );
}
