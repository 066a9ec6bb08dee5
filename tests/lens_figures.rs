//! `lensview lens spot | fan | distortion` against independent computations:
//! every listed ray re-traced by the double-double reference tracer
//! (`tests/reference`), the spot statistics recomputed from the listed
//! crossings, and the paraxial planes and heights from a paraxial y–nu ray
//! trace (not the thick-lens formulas the code uses).
//!
//! Tolerance: an image-plane crossing within 1e-9·d of the reference's
//! (transverse); an axial crossing (LSA) within 1e-9·d divided by the exit
//! ray's slope, i.e. the same transverse 1e-9·d at the focus.

// `!(x <= tol)` on purpose: it also fails for NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

// Shared with tests/lens_exact.rs, which uses all of it.
#[allow(dead_code)]
mod reference;

mod support;

use reference::{DD, Face, LensSpec, Path, Status, V3};
use serde_json::Value;
use support::run;

/// Lenses from a ball lens to nearly flat, n from 1.0001 to 4, with a
/// dispersive glass: (d, r1, r2, n as given to --n).
const LENSES: &[(f64, f64, f64, &str)] = &[
    (2.0, 1.0, 1.0, "1.5"), // ball lens
    (2.0, 1.0, 5.0, "1.7"), // one hemisphere
    (2.0, 5.0, 5.0, "1.5,0.004"),
    (20.0, 50.0, 100.0, "1.5168"),
    (1.0, 1e3, 1e4, "1.5"),
    (1.0, 1e5, 1e5, "1.5"),
    (1.0, 1e7, 1e7, "1.5"), // nearly flat
    (1e-3, 0.01, 0.02, "4"),
    (3.0, 1.5000001, 1e5, "1.0001"),
];

fn json(cmd: &str, d: f64, r1: f64, r2: f64, n: &str, extra: &[&str]) -> Value {
    let mut args: Vec<String> = ["lens", cmd, "--d", &d.to_string(), "--r1", &r1.to_string()]
        .iter()
        .map(|s| s.to_string())
        .collect();
    args.extend(["--r2", &r2.to_string(), "--n", n, "--json"].map(String::from));
    args.extend(extra.iter().map(|s| s.to_string()));
    let (ok, out, err) = run(&args);
    assert!(ok, "{args:?}: {err}");
    serde_json::from_str(&out).expect("JSON on stdout")
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("a number: {v}"))
}

fn arr3(v: &Value) -> [f64; 3] {
    [f(&v[0]), f(&v[1]), f(&v[2])]
}

fn spec(d: f64, r1: f64, r2: f64, n: f64) -> LensSpec {
    LensSpec {
        center: [0.0; 3],
        axis: [0.0, 0.0, 1.0],
        d,
        r1,
        r2,
        n,
    }
}

/// The reference path of a listed ray at index `n`.
fn retrace(s: &LensSpec, ray: &Value) -> Path<DD> {
    reference::trace::<DD>(s, arr3(&ray["origin"]), arr3(&ray["direction"]))
}

/// The exit of a path through S2 toward −z, in DD.
fn exit_s2(p: &Path<DD>) -> Option<(V3<DD>, V3<DD>)> {
    let e = p.exit.as_ref()?;
    (p.status == Status::Transmitted && e.face == Face::S2 && e.dir.0[2].to_f64() < 0.0).then_some((e.point, e.dir))
}

/// Where the reference ray crosses the plane z = `plane_z` (x, y).
fn plane_crossing(p: &Path<DD>, plane_z: f64) -> Option<[f64; 2]> {
    let (x, u) = exit_s2(p)?;
    let t = (DD::new(plane_z) - x.0[2]) / u.0[2];
    Some([(x.0[0] + u.0[0] * t).to_f64(), (x.0[1] + u.0[1] * t).to_f64()])
}

/// Paraxial y–nu trace (light to the right, heights up, slopes up
/// positive) of a ray meeting S1's vertex plane at height `y` with slope
/// `u` in air: its height at S2's vertex plane and slope after S2.
/// Sagittas by the half-angle form 2R·sin²(θ/2).
fn ynu(d: f64, r1: f64, r2: f64, n: f64, y: f64, u: f64) -> (f64, f64) {
    let t = sag(d, r1) + sag(d, r2);
    // n'u' = nu − y·(n' − n)/R, with R1 = +r1, R2 = −r2.
    let u1 = (u - y * (n - 1.0) / r1) / n;
    let y2 = y + t * u1;
    let u2 = n * u1 - y2 * (1.0 - n) / (-r2);
    (y2, u2)
}

/// Sagitta of a face of radius `r` over d/2, by the half-angle form.
fn sag(d: f64, r: f64) -> f64 {
    2.0 * r * ((d / 2.0 / r).asin() / 2.0).sin().powi(2)
}

#[test]
fn spot_rays_match_the_double_double_reference() {
    let mut worst = 0.0f64;
    let mut checked = 0;
    for &(d, r1, r2, n) in LENSES {
        for extra in [
            &[][..],
            &["--field-deg", "7.5"],
            &["--object-distance", "40", "--field-deg", "-3"],
        ] {
            let mut extra: Vec<&str> = extra.to_vec();
            extra.extend(["--rings", "5"]);
            let ip = (1.3 * d).to_string();
            // A ball lens at n ≥ 2 or a near object can put the paraxial image inside: give a plane.
            if n == "4" || extra.contains(&"--object-distance") {
                extra.extend(["--image-plane", &ip]);
            }
            let v = json("spot", d, r1, r2, n, &extra);
            let plane_z = f(&v["image_plane_z"]);
            assert_eq!(v["sampling"], "hexapolar");
            for sp in v["spots"].as_array().unwrap() {
                let s = spec(d, r1, r2, f(&sp["n"]));
                let rays = sp["rays"].as_array().unwrap();
                assert_eq!(rays.len(), 1 + 3 * 5 * 6, "hexapolar, 5 rings");
                let mut hits = Vec::new();
                for ray in rays {
                    let want = plane_crossing(&retrace(&s, ray), plane_z);
                    let got = ray["image_point"].as_array().map(|p| [f(&p[0]), f(&p[1]), f(&p[2])]);
                    match (got, want) {
                        (Some(g), Some(w)) => {
                            let e = (g[0] - w[0]).hypot(g[1] - w[1]);
                            assert!(
                                e <= 1e-9 * d,
                                "lens {d} {r1} {r2} {n} {extra:?} ray {ray}: {g:?} vs {w:?}"
                            );
                            assert_eq!(g[2], plane_z);
                            worst = worst.max(e / d);
                            hits.push([g[0], g[1]]);
                            checked += 1;
                        }
                        (None, None) => {}
                        (g, w) => panic!("lens {d} {r1} {r2} {n} {extra:?} ray {ray}: {g:?} vs reference {w:?}"),
                    }
                }
                // RMS radius about the centroid, recomputed from the listed crossings.
                assert_eq!(f(&sp["ray_count"]) as usize, hits.len());
                if hits.is_empty() {
                    continue;
                }
                let k = hits.len() as f64;
                let cx = hits.iter().map(|p| p[0]).sum::<f64>() / k;
                let cy = hits.iter().map(|p| p[1]).sum::<f64>() / k;
                let rms = (hits
                    .iter()
                    .map(|p| (p[0] - cx).powi(2) + (p[1] - cy).powi(2))
                    .sum::<f64>()
                    / k)
                    .sqrt();
                let tol = 1e-12 * (rms + 1e-3 * d);
                assert!(
                    (f(&sp["rms_radius"]) - rms).abs() <= tol,
                    "{} vs {rms}",
                    sp["rms_radius"]
                );
                assert!((f(&sp["centroid"][0]) - cx).abs() <= tol && (f(&sp["centroid"][1]) - cy).abs() <= tol);
            }
        }
    }
    eprintln!("{checked} spot rays; worst crossing error {worst:e}·d");
    assert!(checked > 5000);
}

#[test]
fn pupil_rays_are_hexapolar_and_aimed_at_the_rim_plane() {
    let (d, r1, r2) = (2.0, 5.0, 5.0);
    let v = json("spot", d, r1, r2, "1.5", &["--rings", "3", "--field-deg", "12"]);
    let rays = v["spots"][0]["rays"].as_array().unwrap();
    let mut k = 0;
    for ring in 0..=3u32 {
        let m = if ring == 0 { 1 } else { 6 * ring };
        for j in 0..m {
            let a = std::f64::consts::TAU * j as f64 / m as f64;
            let want = [ring as f64 / 3.0 * a.cos(), ring as f64 / 3.0 * a.sin()];
            let ray = &rays[k];
            let p = [f(&ray["pupil"][0]), f(&ray["pupil"][1])];
            assert!(
                (p[0] - want[0]).abs() < 1e-15 && (p[1] - want[1]).abs() < 1e-15,
                "{p:?} vs {want:?}"
            );
            // The incoming line meets the plane z = 0 at 0.9·d/2·pupil, at 12° to the axis.
            let (o, u) = (arr3(&ray["origin"]), arr3(&ray["direction"]));
            let t = -o[2] / u[2];
            let aim = [o[0] + t * u[0], o[1] + t * u[1]];
            assert!((aim[0] - 0.9 * p[0]).abs() < 1e-14 && (aim[1] - 0.9 * p[1]).abs() < 1e-14);
            assert!(((-u[2]).acos().to_degrees() - 12.0).abs() < 1e-12);
            k += 1;
        }
    }
    assert_eq!(k, rays.len());
}

#[test]
fn default_image_plane_is_the_paraxial_focus() {
    for &(d, r1, r2, n) in LENSES.iter().filter(|l| l.3 != "4") {
        let nd: f64 = n.split(',').next().unwrap().parse().unwrap();
        let nd = if n.contains(',') {
            nd + 0.004 / 0.5875618f64.powi(2)
        } else {
            nd
        };
        let (y2, u2) = ynu(d, r1, r2, nd, 1.0, 0.0);
        let bfd = -y2 / u2;
        let v = json("spot", d, r1, r2, n, &["--rings", "1"]);
        let got = f(&v["image_plane_from_v2"]);
        assert!(
            (got - bfd).abs() <= 1e-11 * bfd.abs(),
            "{d} {r1} {r2} {n}: {got} vs {bfd}"
        );
    }
}

#[test]
fn lsa_curve_matches_the_reference() {
    let mut checked = 0;
    for &(d, r1, r2, n) in LENSES.iter().filter(|l| l.3 != "4") {
        let v = json("fan", d, r1, r2, n, &[]);
        let nd = f(&v["n"]);
        let s = spec(d, r1, r2, nd);
        let (y2, u2) = ynu(d, r1, r2, nd, 1.0, 0.0);
        let bfd = -y2 / u2;
        let s2 = f(&v["cardinal"]["sag2"]);
        let lsa = v["lsa"].as_array().unwrap();
        for p in lsa {
            let Some((x, u)) = exit_s2(&retrace(&s, &p["ray"])) else {
                assert!(p["focus_from_v2"].is_null());
                continue;
            };
            // Where the exit line meets x = 0, from V2 = (0, 0, −sag2).
            let z = x.0[2] - x.0[0] * u.0[2] / u.0[0];
            let want = (DD::new(-s2) - z).to_f64();
            let slope = (u.0[0] / u.0[2]).to_f64().abs();
            let got = f(&p["focus_from_v2"]);
            assert!(
                (got - want).abs() <= 1e-9 * d / slope,
                "{d} {r1} {r2} {n} h {}: {got} vs {want}",
                p["height"]
            );
            let l = f(&p["lsa"]);
            assert!(
                (l - (got - bfd)).abs() <= 1e-10 * bfd.abs() + 1e-9 * d / slope,
                "{l} vs {}",
                got - bfd
            );
            checked += 1;
        }
        // Spherical aberration grows as h²: the curve at a quarter of the
        // pupil is about a sixteenth of the curve at the edge.
        if let (Some(q), Some(e)) = (lsa[7]["lsa"].as_f64(), lsa[31]["lsa"].as_f64())
            && e.abs() > 1e-6 * d
        {
            let ratio = q / e;
            assert!(ratio > 0.04 && ratio < 0.09, "{d} {r1} {r2} {n}: {q} / {e}");
        }
    }
    assert!(checked > 150);
}

#[test]
fn distortion_against_paraxial_heights_and_the_reference_chief_ray() {
    for &(d, r1, r2, n) in LENSES.iter().filter(|l| l.3 != "4" && !l.3.contains(',')) {
        let nd: f64 = n.parse().unwrap();
        let efl = -1.0 / ynu(d, r1, r2, nd, 1.0, 0.0).1;
        for dist in [None, Some(3.0 * efl)] {
            let mut extra = vec!["--max-field-deg", "30", "--steps", "6"];
            let ds = dist.map(|x: f64| x.to_string()).unwrap_or_default();
            if dist.is_some() {
                extra.extend(["--object-distance", &ds]);
            }
            let v = json("distortion", d, r1, r2, n, &extra);
            // The paraxial image plane and magnification by y–nu traces.
            let (plane, m) = match dist {
                None => {
                    let (y2, u2) = ynu(d, r1, r2, nd, 1.0, 0.0);
                    (-y2 / u2, None)
                }
                Some(dd) => {
                    // From the axial object point at slope 1: height D at V1.
                    let (y2, u2) = ynu(d, r1, r2, nd, dd, 1.0);
                    (-y2 / u2, Some(1.0 / u2))
                }
            };
            let got_plane = f(&v["image_plane_from_v2"]);
            assert!(
                (got_plane - plane).abs() <= 1e-10 * plane.abs(),
                "{got_plane} vs {plane}"
            );
            let s = spec(d, r1, r2, nd);
            let plane_z = -sag(d, r2) - got_plane;
            for p in v["points"].as_array().unwrap() {
                let a = f(&p["field_deg"]).to_radians();
                let par = match (dist, m) {
                    (Some(dd), Some(m)) => m * (dd + sag(d, r1)) * a.tan(),
                    _ => -efl * a.tan(),
                };
                let got = f(&p["paraxial_height"]);
                assert!(
                    (got - par).abs() <= 1e-10 * par.abs(),
                    "{d} {r1} {r2} {n}: {got} vs {par}"
                );
                let want = plane_crossing(&retrace(&s, &p["chief_ray"]), plane_z).expect("chief ray through");
                let real = f(&p["real_height"]);
                assert!(
                    (real - want[0]).abs() <= 1e-9 * d + 1e-12 * want[0].abs(),
                    "{real} vs {want:?}"
                );
                let pct = f(&p["distortion_percent"]);
                assert!((pct - 100.0 * (real - got) / got).abs() <= 1e-9 * pct.abs().max(1.0));
            }
        }
    }
}

#[test]
fn distortion_vanishes_in_the_small_field_limit() {
    for &(d, r1, r2, n) in LENSES.iter().filter(|l| l.3 != "4" && !l.3.contains(',')) {
        let v = json("distortion", d, r1, r2, n, &["--max-field-deg", "0.02", "--steps", "2"]);
        let p = v["points"].as_array().unwrap();
        let (d1, d2) = (f(&p[0]["distortion_percent"]), f(&p[1]["distortion_percent"]));
        // Third order: D ∝ A² (twice the angle, four times the distortion) and tiny.
        assert!(d2.abs() < 1e-4, "{d} {r1} {r2} {n}: {d2}%");
        if d2.abs() > 1e-9 {
            assert!((d2 / d1 - 4.0).abs() < 0.05, "{d} {r1} {r2} {n}: {d1}, {d2}");
        }
    }
}

#[test]
fn bad_values_get_one_line_errors_naming_the_flag() {
    let base = ["lens", "spot", "--d", "2", "--r1", "5", "--r2", "5"];
    for (extra, flag) in [
        (&["--n", "1.5", "--image-plane", "-1"][..], "--image-plane"),
        (&["--n", "1.5", "--image-plane", "0"], "--image-plane"),
        (&["--n", "1.5", "--field-deg", "90"], "--field-deg"),
        (&["--n", "1.5", "--field-deg", "-95"], "--field-deg"),
        (&["--n", "1.5", "--field-deg", "nan"], "--field-deg"),
        (&["--n", "0.9"], "--n"),
        (&["--n", "1.5", "--rings", "0"], "--rings"),
        (&["--n", "1.5", "--rings", "100000"], "--rings"),
        (&["--n", "1.5", "--object-distance", "-4"], "--object-distance"),
        (&["--n", "1"], "--image-plane"),
        // An object inside F is a magnifier, measured in its virtual image.
        (
            &["--n", "1.5", "--object-distance", "1", "--image-plane", "-3"],
            "--image-plane",
        ),
        (&["--n", "1.5", "--fields", "0,95"], "--fields"),
        (&["--n", "1.5", "--fields", "0,x"], "--fields"),
        (&["--n", "1.5", "-o", "spot.gif"], ".png or .svg"),
    ] {
        let mut args: Vec<String> = base.iter().map(|s| s.to_string()).collect();
        args.extend(extra.iter().map(|s| s.to_string()));
        let (ok, _, err) = run(&args);
        assert!(!ok, "{args:?} accepted");
        assert_eq!(err.trim().lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(flag), "{args:?}: {err}");
    }
    let args = "lens distortion --d 2 --r1 5 --r2 5 --n 1.5 --max-field-deg 90";
    let (ok, _, err) = run(&args.split(' ').map(String::from).collect::<Vec<_>>());
    assert!(!ok && err.contains("--max-field-deg"), "{err}");
}

#[test]
fn fan_is_drawn_as_svg_and_png() {
    let dir = std::env::temp_dir().join(format!("lensview-fan-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for ext in ["svg", "png"] {
        let out = dir.join(format!("fan.{ext}"));
        let args = [
            "lens", "fan", "--d", "2", "--r1", "5", "--r2", "5", "--n", "1.5", "--rays", "9", "-o",
        ];
        let mut args: Vec<String> = args.iter().map(|s| s.to_string()).collect();
        args.push(out.display().to_string());
        let (ok, _, err) = run(&args);
        assert!(ok, "{err}");
        let bytes = std::fs::read(&out).unwrap();
        if ext == "svg" {
            let text = String::from_utf8(bytes).unwrap();
            // Axis, lens, 9 rays, image plane, H and H′.
            assert_eq!(text.matches("<polyline").count(), 1 + 1 + 9 + 1 + 2);
            for label in [">F<", ">F′<", ">H<", ">H′<", ">V1<", ">V2<", ">M<"] {
                assert!(text.contains(label), "{label}");
            }
        } else {
            assert_eq!(&bytes[1..4], b"PNG");
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Where the reference path's exit line meets the axis, from V2 = (0, 0,
/// −sag2), in DD; `None` unless it leaves through S2.
fn reference_focus(p: &Path<DD>, sag2: f64) -> Option<DD> {
    let (x, u) = exit_s2(p)?;
    let z = x.0[2] - x.0[0] * u.0[2] / u.0[0];
    Some(DD::new(-sag2) - z)
}

/// The real marginal focus and the LSA as n → 1 (issue 30.5): the ray
/// bends by about n − 1, so a turn computed as the difference of two unit
/// vectors keeps only ε/(n − 1) of its digits (2·10⁻³ of the focus at
/// n − 1 = 1e-13). `lens info` and `lens fan` against the double-double
/// reference over n − 1 = 1e-1 … 1e-13, from infinity and from a near
/// object (a virtual image: the focus is the backward extension's). The
/// LSA is a difference of two numbers of the focus's size, so its error is
/// measured against the focus; and, relative to itself, for the edge ray of
/// a lens whose LSA is 1.6 % of its focus.
#[test]
fn marginal_focus_and_lsa_keep_their_precision_as_n_goes_to_1() {
    let lenses = [
        (2.0, 5.0, 5.0),
        (2.0, 1.0, 5.0),
        (2.0, 1.0, 1.0),
        (20.0, 50.0, 100.0),
        (1.0, 1e3, 1e4),
        (3.0, 1.5000001, 1e5),
    ];
    let rel = |got: f64, want: DD, of: DD| ((DD::new(got) - want) / of).to_f64().abs();
    let mut worst = [0.0f64; 3];
    for k in 1..=13 {
        let n = 1.0 + 10f64.powi(-k);
        // Focus, LSA (against the focus), the edge LSA of the first lens.
        let mut w = [0.0f64; 3];
        for &(d, r1, r2) in &lenses {
            let s = spec(d, r1, r2, n);
            let (y2, u2) = ynu(d, r1, r2, n, 1.0, 0.0);
            let bfd = DD::new(-y2) / DD::new(u2);
            let info = json("info", d, r1, r2, &n.to_string(), &[]);
            let (sag1, sag2) = (f(&info["sag1"]), f(&info["sag2"]));
            let h = 0.9 * 0.5 * d;
            let p = reference::trace::<DD>(&s, [h, 0.0, sag1 + d], [0.0, 0.0, -1.0]);
            let want = reference_focus(&p, sag2).expect("the marginal ray leaves through S2");
            w[0] = w[0].max(rel(f(&info["marginal_focus_from_v2"]), want, want));
            w[1] = w[1].max(rel(f(&info["spherical_aberration"]), want - bfd, want));
            if r1 == 5.0 {
                w[2] = rel(f(&info["spherical_aberration"]), want - bfd, want - bfd);
            }
            let fan = json("fan", d, r1, r2, &n.to_string(), &["--rays", "1"]);
            for pt in fan["lsa"].as_array().unwrap() {
                let want = reference_focus(&retrace(&s, &pt["ray"]), sag2).unwrap();
                w[0] = w[0].max(rel(f(&pt["focus_from_v2"]), want, want));
                w[1] = w[1].max(rel(f(&pt["lsa"]), want - bfd, want));
            }
            let dist = (10.0 * d).to_string();
            let ip = (1.3 * d).to_string();
            let extra = ["--rays", "1", "--object-distance", &dist, "--image-plane", &ip];
            let near = json("fan", d, r1, r2, &n.to_string(), &extra);
            let edge = &near["lsa"][31]["ray"];
            let want = reference_focus(&retrace(&s, edge), sag2).unwrap();
            let got = f(&near["cardinal"]["object_marginal_focus_from_v2"]);
            w[0] = w[0].max(rel(got, want, want));
        }
        eprintln!(
            "n − 1 = 1e-{k}: worst relative error of the focus {:.1e}, LSA error / focus {:.1e}; \
             edge LSA of d 2, R 5, 5: relative error {:.1e}",
            w[0], w[1], w[2]
        );
        for (a, b) in worst.iter_mut().zip(w) {
            *a = a.max(b);
        }
    }
    assert!(worst[0] <= 1e-14, "focus {:e}", worst[0]);
    assert!(worst[1] <= 5e-14, "LSA {:e}", worst[1]);
    assert!(worst[2] <= 1e-12, "edge LSA {:e}", worst[2]);
}

/// A magnifier (object inside F): fan and spot measure in its virtual
/// image, before V2, where the rays' backward extensions meet. The plane
/// against a paraxial y–nu trace from the object point; every fan ray's
/// image point against the reference ray's exit line extended backwards.
#[test]
fn a_magnifier_is_measured_in_its_virtual_image() {
    let (d, r1, r2, n, dist) = (2.0, 5.0, 5.0, 1.5, 3.5);
    // From the axial object point: height u·(dist) at S1's vertex plane.
    let u = 1e-6;
    let (y2, u2) = ynu(d, r1, r2, n, u * dist, u);
    let virtual_plane = -y2 / u2;
    assert!(virtual_plane < -10.0, "{virtual_plane}");
    let spot = json("spot", d, r1, r2, "1.5", &["--object-distance", "3.5", "--rings", "3"]);
    let got = f(&spot["image_plane_from_v2"]);
    assert!(
        (got - virtual_plane).abs() <= 1e-8 * virtual_plane.abs(),
        "{got} vs {virtual_plane}"
    );
    assert_eq!(spot["virtual_image"], Value::Bool(true));
    let fan = json(
        "fan",
        d,
        r1,
        r2,
        "1.5",
        &["--object-distance", "3.5", "--field-deg", "4"],
    );
    assert_eq!(f(&fan["image_plane_from_v2"]), got);
    let s = spec(d, r1, r2, n);
    let plane_z = -sag(d, r2) - got;
    let mut checked = 0;
    for ray in fan["rays"].as_array().unwrap() {
        let reference = retrace(&s, ray);
        let (x, _) = exit_s2(&reference).expect("every fan ray leaves through S2");
        let want = plane_crossing(&reference, plane_z).unwrap();
        let p = arr3(&ray["image_point"]);
        assert!(
            (p[0] - want[0]).abs() <= 1e-9 * d && (p[1] - want[1]).abs() <= 1e-9 * d,
            "{p:?} vs {want:?}"
        );
        // Behind the exit point, against the light: a backward extension.
        assert!(p[2] > x.0[2].to_f64(), "{p:?}");
        checked += 1;
    }
    assert_eq!(checked, 7);
}

/// `spot -o` and `distortion -o` draw charts (PNG, SVG) with titled axes;
/// `--fields` gives a spot diagram per field angle; the fan of a magnifier
/// draws its rays' backward extensions dashed.
#[test]
fn spot_and_distortion_are_drawn_and_magnifier_rays_dashed() {
    let dir = std::env::temp_dir().join(format!("lensview-charts-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let lens = ["lens", "?", "--d", "2", "--r1", "5", "--r2", "5", "--n", "1.5,0.004"];
    let go = |cmd: &str, extra: &[&str]| {
        let mut args: Vec<String> = lens.iter().map(|s| s.to_string()).collect();
        args[1] = cmd.into();
        args.extend(extra.iter().map(|s| s.to_string()));
        let (ok, out, err) = run(&args);
        assert!(ok, "{args:?}: {err}");
        out
    };
    for ext in ["png", "svg"] {
        let spot = dir.join(format!("spot.{ext}"));
        let dist = dir.join(format!("dist.{ext}"));
        go("spot", &["--fields", "0,10,-20", "-o", spot.to_str().unwrap()]);
        go("distortion", &["-o", dist.to_str().unwrap()]);
        for (path, titles) in [
            (&spot, &["field 10°", "x − centroid (units)"][..]),
            (&dist, &["field angle (°)", "distortion (%)"]),
        ] {
            let bytes = std::fs::read(path).unwrap();
            if ext == "png" {
                assert_eq!(&bytes[1..4], b"PNG");
            } else {
                let text = String::from_utf8(bytes).unwrap();
                for t in titles {
                    assert!(text.contains(t), "{}: no {t}", path.display());
                }
            }
        }
    }
    let many: Value = serde_json::from_str(&go("spot", &["--fields", "0,5", "--json"])).unwrap();
    let fields: Vec<f64> = many.as_array().unwrap().iter().map(|d| f(&d["field_deg"])).collect();
    assert_eq!(fields, [0.0, 5.0]);
    let text = go("spot", &["--fields", "0,5,10"]);
    assert_eq!(text.matches("spot diagram:").count(), 3, "{text}");
    let fan = dir.join("magnifier.svg");
    go(
        "fan",
        &["--object-distance", "3.5", "--rays", "9", "-o", fan.to_str().unwrap()],
    );
    let svg = std::fs::read_to_string(&fan).unwrap();
    assert_eq!(
        svg.matches("stroke-dasharray").count(),
        9,
        "one dashed extension per ray"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
