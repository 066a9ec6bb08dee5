//! Lens optics end to end: `lens info` against an independent ABCD-matrix
//! computation, `lens trace` through the binary, the renderer's own path
//! through a lens focusing at the back focal distance, and dispersion.

use glam::DVec3;
use lensview::geometry::LensSurface;
use lensview::integrator::transmitted_ray;
use lensview::lens_tools::lens_info;
use lensview::math::Ray;
use lensview::optics::Index;
use lensview::render::{RenderSettings, render};
use lensview::scene::Scene;
use lensview::trace::closest_hit;

/// Paraxial data by ray-transfer (ABCD) matrices — refraction
/// `[[1, 0], [−(n2−n1)/(n2·R), n1/n2]]`, translation `[[1, t], [0, 1]]` —
/// a different route from the thick-lens formulas under test.
fn abcd(d: f64, r1: f64, r2: f64, n: f64) -> (f64, f64, f64) {
    type M = [[f64; 2]; 2];
    let mul = |a: M, b: M| -> M {
        [
            [
                a[0][0] * b[0][0] + a[0][1] * b[1][0],
                a[0][0] * b[0][1] + a[0][1] * b[1][1],
            ],
            [
                a[1][0] * b[0][0] + a[1][1] * b[1][0],
                a[1][0] * b[0][1] + a[1][1] * b[1][1],
            ],
        ]
    };
    let h = d / 2.0;
    // Sagitta by the half-angle form 2R·sin²(θ/2), θ = asin(h/R): another
    // route than the code's h²/(R + √((R−h)(R+h))), and as free of cancellation.
    let sag = |r: f64| {
        let s = (h / r).asin();
        2.0 * r * (s / 2.0).sin().powi(2)
    };
    let t = sag(r1) + sag(r2);
    let refr = |n1: f64, n2: f64, r: f64| -> M { [[1.0, 0.0], [-(n2 - n1) / (n2 * r), n1 / n2]] };
    let m = mul(refr(n, 1.0, -r2), mul([[1.0, t], [0.0, 1.0]], refr(1.0, n, r1)));
    let efl = -1.0 / m[1][0];
    let bfd = -m[0][0] / m[1][0];
    let ffd = -m[1][1] / m[1][0];
    (efl, bfd, ffd)
}

#[test]
fn lens_info_matches_the_abcd_matrices_from_ball_lens_to_nearly_flat() {
    for (d, r1, r2, n) in [
        (2.0, 1.0, 1.0, 1.5), // ball lens
        (2.0, 1.0, 5.0, 1.7), // one hemisphere
        (2.0, 5.0, 5.0, 1.5), // the cubes scene's lens
        (20.0, 50.0, 100.0, 1.5168),
        (1.0, 1e3, 1e4, 1.5),
        (1.0, 1e7, 1e7, 1.5), // nearly flat
        (1e-3, 0.01, 0.02, 4.0),
        (3.0, 1.5000001, 1e5, 1.0001),
    ] {
        let info = lens_info(d, r1, r2, Index::Constant(n), 0.5875618).unwrap();
        let (efl, bfd, ffd) = abcd(d, r1, r2, n);
        for (name, got, want) in [
            ("efl", info.efl.unwrap(), efl),
            ("bfd", info.bfd.unwrap(), bfd),
            ("ffd", info.ffd.unwrap(), ffd),
        ] {
            let rel = ((got - want) / want).abs();
            assert!(
                rel < 1e-12,
                "d={d} r1={r1} r2={r2} n={n}: {name} {got} vs {want} (rel {rel:e})"
            );
        }
        // Thickness is the sum of the sagittas, and principal planes place the focal points.
        assert!((info.thickness - (info.sag1 + info.sag2)).abs() <= 1e-15 * info.thickness);
        let (f, b, h2) = (
            info.efl.unwrap(),
            info.bfd.unwrap(),
            info.principal_rear_from_v2.unwrap(),
        );
        assert!(((b - h2) - f).abs() <= 1e-12 * f.abs());
    }
}

#[test]
fn spherical_aberration_of_a_positive_lens_is_negative_and_grows_with_height() {
    let info = lens_info(2.0, 5.0, 5.0, Index::Constant(1.5), 0.5875618).unwrap();
    let sa = info.spherical_aberration.unwrap();
    assert!(sa < 0.0 && sa > -0.5, "{sa}");
    let lens = lensview::geometry::Lens::new(DVec3::ZERO, DVec3::Z, 2.0, 5.0, 5.0, Index::Constant(1.5)).unwrap();
    let small = lensview::lens_tools::real_focus(&lens, 0.01, 1.5).unwrap() - info.bfd.unwrap();
    assert!(small.abs() < 1e-3 * sa.abs(), "paraxial ray focus error {small}");
    // Third-order: LSA ∝ h², so at 0.45 it is about a quarter of that at 0.9.
    let half = lensview::lens_tools::real_focus(&lens, 0.45, 1.5).unwrap() - info.bfd.unwrap();
    assert!((half / sa - 0.25).abs() < 0.05, "{half} vs {sa}");
}

#[test]
fn axial_colour_of_crown_glass() {
    let info = lens_info(2.0, 5.0, 5.0, Index::Cauchy { a: 1.5046, b: 0.0042 }, 0.5875618).unwrap();
    let c = info.axial_colour.unwrap();
    // Blue is bent more and focuses closer: BFD(F) < BFD(C), by about f/V (V ≈ 64).
    assert!(
        c < 0.0 && (c.abs() - info.efl.unwrap() / 64.0).abs() < 0.3 * info.efl.unwrap() / 64.0,
        "{c}"
    );
    assert!(
        lens_info(2.0, 5.0, 5.0, Index::Constant(1.5), 0.5875618)
            .unwrap()
            .axial_colour
            .is_none()
    );
}

const LENS_SCENE: &str = r#"
[camera]
position = [0, 0, 10]
look_at = [0, 0, 0]
fov = 30

[[lights]]
position = [0, 5, 10]
intensity = 400

[[lenses]]
center = [0.5, -0.25, 1]
axis = [0.1, 0.2, 1]
d = 2
r1 = 5
r2 = 3
n = 1.5
"#;

#[test]
fn the_renderers_path_through_a_lens_focuses_at_the_back_focal_distance() {
    let (_, scene) = Scene::parse("lens.toml", LENS_SCENE).unwrap();
    let lens = scene.objects[0].lens().unwrap().clone();
    let px = lens.paraxial(1.5);
    let (u, v) = lensview::math::orthonormal_basis(lens.axis);
    let v2 = lens.vertex(LensSurface::S2);
    for h in [1e-3, 2e-3, 4e-3, 0.05, 0.1] {
        for az in [0.0f64, 1.0, 2.5, 4.0] {
            let offset = (u * az.cos() + v * az.sin()) * h;
            // A collimated beam along −axis, as from a camera far up the axis.
            let ray = Ray::new(lens.center + lens.axis * 3.0 + offset, -lens.axis);
            let (i, hit) = closest_hit(&scene, &ray, f64::INFINITY).unwrap();
            let obj = &scene.objects[i];
            let p = ray.at(hit.t);
            let n = obj.world_normal(p, hit.part);
            let out = transmitted_ray(obj, p, n, true, &ray, 1.5).unwrap();
            // Where the exit ray crosses the axis: closest approach to the axis line.
            let o = out.ray.origin - v2;
            let w = out.ray.dir;
            let radial = o - lens.axis * o.dot(lens.axis);
            let radial_dir = w - lens.axis * w.dot(lens.axis);
            let t = -radial.dot(radial_dir) / radial_dir.length_squared();
            let cross = o + w * t;
            let miss = (cross - lens.axis * cross.dot(lens.axis)).length();
            let bfd = -cross.dot(lens.axis);
            // Within the paraxial limit: spherical aberration grows as h².
            let tol = 1e-9 + 40.0 * h * h;
            assert!((bfd - px.bfd).abs() < tol, "h={h}: {bfd} vs {}", px.bfd);
            assert!(miss < 1e-9, "exit ray is skew to the axis by {miss}");
        }
    }
}

#[test]
fn dispersive_glass_renders_colour_fringes_and_plain_glass_does_not() {
    // A grey world (black and white stripes) seen through the lens.
    let mut grey = String::from(
        r#"
[render]
background = [0.1, 0.1, 0.1]

[camera]
position = [0, 0, 6]
look_at = [0, 0, 0]
fov = 30

[ambient]
intensity = 1.0

[materials.white]
color = [0.9, 0.9, 0.9]
diffuse = 0.0
ambient = 1

[[objects]]
type = "cuboid"
position = [0, 0, -3]
size = [0.3, 8, 0.1]
material = "white"

[[objects]]
type = "cuboid"
position = [0.8, 0, -3]
size = [0.3, 8, 0.1]
material = "white"

[[lenses]]
center = [0.3, 0, 2]
axis = [0, 0, 1]
d = 2.5
r1 = 2
r2 = 2
"#,
    );
    let plain = format!("{grey}n = 1.5\n");
    grey.push_str("n = { cauchy = [1.6, 0.04] }\n");
    let s = RenderSettings {
        width: 80,
        height: 60,
        spp: 1,
        seed: 0,
    };
    let spread = |text: &str| {
        let (_, scene) = Scene::parse("d.toml", text).unwrap();
        let img = render(&scene, &s, None);
        img.pixels.iter().map(|c| (c.x - c.z).abs()).fold(0.0, f64::max)
    };
    assert!(spread(&plain) < 1e-12, "plain glass coloured a grey scene");
    assert!(spread(&grey) > 0.2, "no colour fringes from dispersive glass");
}

#[test]
fn lens_info_at_n_1_reports_no_power_and_agrees_with_lens_trace() {
    let info = lens_info(2.0, 5.0, 3.0, Index::Constant(1.0), 0.5875618).unwrap();
    assert_eq!(
        (
            info.efl,
            info.bfd,
            info.ffd,
            info.principal_front_from_v1,
            info.principal_rear_from_v2
        ),
        (None, None, None, None, None)
    );
    assert_eq!(info.no_power, Some(lensview::lens_tools::NO_POWER));
    // The paraxial data themselves (the viewer's readout): ∞, not NaN.
    let t = lensview::optics::ThickLens::new(2.0, 5.0, 3.0, 1.0);
    assert!(!t.has_power() && [t.efl, t.bfd, t.ffd] == [f64::INFINITY; 3], "{t:?}");
    assert_eq!((info.marginal_focus_from_v2, info.spherical_aberration), (None, None));
    let json = serde_json::to_value(&info).unwrap();
    assert!(json["efl"].is_null() && json["bfd"].is_null() && json["no_power"].as_str().unwrap().contains("infinite"));
    let text = info.to_string();
    assert!(
        text.lines()
            .any(|l| l.contains("effective focal length") && l.trim_end().ends_with('∞'))
            && !text.contains("NaN"),
        "{text}"
    );
    // A lens with power has no `no_power` key.
    let info = lens_info(2.0, 5.0, 3.0, Index::Constant(1.5), 0.5875618).unwrap();
    assert!(serde_json::to_value(&info).unwrap().get("no_power").is_none());
    // lens trace agrees: at n = 1 the ray leaves undeviated.
    let lens = lensview::geometry::Lens::new(DVec3::ZERO, DVec3::Z, 2.0, 5.0, 3.0, Index::Constant(1.0)).unwrap();
    let u = DVec3::new(0.1, 0.05, -1.0).normalize();
    let p = lens.trace(DVec3::new(0.3, 0.0, 5.0), u, 1.0);
    assert!((p.exit.unwrap().2 - u).length() < 1e-15, "{p:?}");
}

#[test]
fn plano_like_lenses_at_the_largest_radius() {
    // R1 = 1e9 (the largest radius in the domain): a plano-convex lens whose
    // paraxial data match the ABCD matrices and whose rays get through.
    for (d, r1, r2) in [(20.0, 1e9, 50.0), (1e-3, 1e9, 2e-3), (2.0, 1e9, 1e9)] {
        let info = lens_info(d, r1, r2, Index::Constant(1.5), 0.5875618).unwrap();
        let (efl, bfd, _) = abcd(d, r1, r2, 1.5);
        let rel = |got: Option<f64>, want: f64| ((got.unwrap() - want) / want).abs();
        assert!(rel(info.efl, efl) < 1e-12 && rel(info.bfd, bfd) < 1e-12, "{info:?}");
        assert!(info.marginal_focus_from_v2.is_some(), "{info:?}");
        let lens = lensview::geometry::Lens::new(DVec3::ZERO, DVec3::Z, d, r1, r2, Index::Constant(1.5)).unwrap();
        let p = lens.trace(DVec3::new(0.25 * d, 0.0, d), DVec3::NEG_Z, 1.5);
        assert_eq!(p.status, lensview::geometry::LensTraceStatus::Transmitted, "{p:?}");
    }
}

#[test]
fn directions_of_any_magnitude_name_the_same_ray() {
    let lens = lensview::geometry::Lens::new(DVec3::ZERO, DVec3::Z, 2.0, 5.0, 5.0, Index::Constant(1.5)).unwrap();
    let o = DVec3::new(-0.5, 0.0, 3.0);
    let want = lens.trace(o, DVec3::new(0.1, 0.0, -1.0), 1.5);
    assert_eq!(want.status, lensview::geometry::LensTraceStatus::Transmitted);
    let w = want.exit.unwrap().2;
    for dir in [
        [1e200, 0.0, -1e201],
        [1e-200, 0.0, -1e-199],
        [1e300, 0.0, -1e301],
        [1e-290, 0.0, -1e-289],
    ] {
        let p = lens.trace(o, DVec3::from(dir), 1.5);
        assert_eq!(p.status, want.status, "{dir:?}");
        assert!((p.exit.unwrap().2 - w).length() < 1e-14, "{dir:?}: {p:?}");
    }
}

/// Issue 33.4: `lens info --object-distance` gives the paraxial image of a
/// magnifier (the default scene's lens with the object inside F): virtual,
/// on the object's side, upright and enlarged; outside F, real and
/// inverted. Checked against Newton's form (x·x′ = f², each from its focal
/// point) and the lens's own F, F′.
#[test]
fn lens_info_gives_a_magnifiers_virtual_image_and_a_real_one() {
    let info = lens_info(2.0, 5.0, 5.0, Index::Constant(1.5), 0.5875618).unwrap();
    let (f, ffd, bfd) = (info.efl.unwrap(), info.ffd.unwrap(), info.bfd.unwrap());
    for (dist, virtual_image) in [(3.5, true), (20.0, false), (1.0, true)] {
        let im = info.clone().with_object(dist).image.unwrap().paraxial.unwrap();
        assert_eq!(im.is_virtual, virtual_image, "at {dist}");
        // Newton: the object `x` before F, the image `x′` after F′.
        let (x, x_image) = (dist - ffd, im.from_last_vertex - bfd);
        assert!(
            (x * x_image - f * f).abs() < 1e-9 * f * f,
            "at {dist}: {x}·{x_image} ≠ {f}²"
        );
        // m = −f/x: upright and enlarged inside F, inverted outside.
        assert!((im.magnification + f / x).abs() < 1e-12, "{im:?}");
        if virtual_image {
            assert!(im.magnification > 1.0 && im.from_last_vertex < 0.0, "{im:?}");
        } else {
            assert!(im.magnification < 0.0 && im.from_last_vertex > 0.0, "{im:?}");
        }
    }
    // At F the image is at infinity.
    let at_f = info.clone().with_object(ffd).image.unwrap();
    assert!(
        at_f.paraxial.is_none_or(|p| p.from_last_vertex.abs() > 1e12),
        "{at_f:?}"
    );
    let text = info.with_object(3.5).to_string();
    assert!(text.contains("virtual image") && text.contains("(upright)"), "{text}");
}

/// Issue 33.4: the distortion of a magnifier (the default scene's lens, the
/// object 3.5 before V1, inside F) is measured in its virtual image plane,
/// where `lens info` puts it, with the chief rays extended backwards:
/// upright heights, a distortion that vanishes toward the axis, and the
/// same numbers from the command line (which refused it before).
#[test]
fn a_magnifiers_distortion_is_taken_in_its_virtual_image() {
    use lensview::lens_tools::{Setup, distortion};
    let s = Setup::new(2.0, 5.0, 5.0, Index::Constant(1.5), Some(3.5), 0.0).unwrap();
    let d = distortion(&s, 20.0, 40).unwrap();
    let info = lens_info(2.0, 5.0, 5.0, Index::Constant(1.5), 0.5875618).unwrap();
    let im = info.with_object(3.5).image.unwrap().paraxial.unwrap();
    assert!(d.virtual_image && im.is_virtual);
    assert_eq!(
        (d.image_plane_from_v2, d.magnification),
        (im.from_last_vertex, Some(im.magnification))
    );
    let first = &d.points[0];
    assert!(first.distortion_percent.unwrap().abs() < 1e-3, "{first:?}");
    for p in &d.points {
        let real = p.real_height.unwrap();
        assert!(real > 0.0 && p.paraxial_height > 0.0, "not upright: {p:?}");
    }
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_lensview"))
        .args(["lens", "distortion", "--d", "2", "--r1", "5", "--r2", "5", "--n", "1.5"])
        .args(["--object-distance", "3.5", "--max-field-deg", "20", "--steps", "40"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("virtual image") && text.contains("extended backwards"),
        "{text}"
    );
}
