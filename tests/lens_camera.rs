//! The lens camera (issue #32), each check against a computation of its
//! own: the thick lens from real rays traced near the axis (not the y–nu
//! module the camera focuses with), the pinhole's projection, and the
//! relative illumination integrated over a plain grid (not the camera's
//! pupil boxes, sampling or weights).

use glam::DVec3;
use lensview::camera::LensCamera;
use lensview::camera::pupil::INTERVALS;
use lensview::optics::WAVELENGTH_D_UM;
use lensview::render::{Image, RenderSettings, render, render_pixel};
use lensview::scene::Scene;

const W: u32 = 120;
const H: u32 = 80;

/// A scene of small white spheres (ambient-lit, no lights; radius 0.004
/// of their distance, about a pixel across) on a grey `background`,
/// seen by a double Gauss at a hundredth of its size.
fn scene(camera: &str, spheres: &[[f64; 3]], background: f64) -> Scene {
    let mut t = format!(
        "[render]\nbackground = [{background}, {background}, {background}]\nshadows = false\n\
         [camera]\nposition = [0, 0, 0]\nlens = {{ preset = \"double-gauss-50mm\", scale = 0.01 }}\n{camera}\n\
         [ambient]\ncolor = [1, 1, 1]\nintensity = 1\n[materials.white]\ncolor = [1, 1, 1]\ndiffuse = 0\n"
    );
    for p in spheres {
        t += &format!(
            "[[objects]]\ntype = \"sphere\"\nposition = [{}, {}, {}]\nradius = {}\nmaterial = \"white\"\n",
            p[0],
            p[1],
            p[2],
            0.004 * p[2].abs()
        );
    }
    Scene::parse("test", &t).unwrap().1
}

fn lens(s: &Scene) -> &LensCamera {
    s.lens.as_deref().expect("a lens camera")
}

/// The brightness-weighted centroid (continuous pixel coordinates) of
/// `img` within `r` pixels of `near`.
fn centroid(img: &Image, near: (f64, f64), r: f64) -> (f64, f64) {
    let (mut sx, mut sy, mut sw) = (0.0, 0.0, 0.0);
    for y in 0..img.height {
        for x in 0..img.width {
            let (cx, cy) = (x as f64 + 0.5, y as f64 + 0.5);
            if (cx - near.0).hypot(cy - near.1) <= r {
                let v = img.get(x, y).y;
                (sx, sy, sw) = (sx + v * cx, sy + v * cy, sw + v);
            }
        }
    }
    assert!(sw > 0.0, "nothing bright near {near:?}");
    (sx / sw, sy / sw)
}

/// A thick lens from two real rays 10⁻³ of the aperture from the axis,
/// one each way, at the d line: (camera-space z of H, of H′, focal length).
fn thick_lens(l: &LensCamera) -> (f64, f64, f64) {
    let sys = &l.system;
    let y0 = 1e-3 * sys.surfaces[0].semi_aperture;
    let far = 10.0 * (sys.length() + sys.radius());
    let cross = |origin: DVec3, dir: DVec3| {
        let r = sys.trace(origin, dir, WAVELENGTH_D_UM);
        let (_, p, d) = r.exit.expect("transmitted");
        // Where the ray out crosses the axis, and where it is at y0.
        (p.z - p.y * d.z / d.y, p.z + (y0 - p.y) * d.z / d.y)
    };
    let (f2, h2) = cross(sys.vertex + DVec3::new(0.0, y0, -far), DVec3::Z);
    let (f1, h1) = cross(sys.vertex + DVec3::new(0.0, y0, far), DVec3::NEG_Z);
    let (front, rear) = (h1 - f1, f2 - h2);
    assert!((front - rear).abs() < 1e-6 * rear, "focal lengths {front} and {rear}");
    (h1, h2, rear)
}

/// The camera-space `z` of the sensor.
fn sensor_z(l: &LensCamera) -> f64 {
    l.system.vertex.z + l.system.length() + l.sensor_distance
}

/// The image of a point at distance D lands where the thick lens's image
/// equation puts it (magnification `−s′/s`, turned upright), and the
/// sensor stands in that plane.
#[test]
fn point_images_land_where_the_image_equation_says() {
    let d = 10.0;
    let points = [[0.0, 0.0, -d], [0.6, 0.0, -d], [0.0, -0.45, -d], [-0.5, 0.35, -d]];
    let s = scene("focus_distance = 10\nf_number = 8", &points, 0.0);
    let l = lens(&s);
    let (h1, h2, f) = thick_lens(l);
    let so = h1 + d;
    let si = f * so / (so - f);
    assert!(
        (sensor_z(l) - (h2 + si)).abs() < 1e-6 * si,
        "sensor at z {} but the image at {}",
        sensor_z(l),
        h2 + si
    );
    let m = -si / so;
    let (pw, ph) = l.picture(W, H);
    let img = render(
        &s,
        &RenderSettings {
            width: W,
            height: H,
            spp: 32,
            seed: 1,
        },
        None,
    );
    for p in points {
        let want = ((-m * p[0] / pw + 0.5) * W as f64, (0.5 + m * p[1] / ph) * H as f64);
        let got = centroid(&img, want, 4.0);
        // 0.3 px, and 1 % of the image height for the lens's distortion.
        let tol = 0.3 + 0.01 * (want.0 - 0.5 * W as f64).hypot(want.1 - 0.5 * H as f64);
        assert!(
            (got.0 - want.0).hypot(got.1 - want.1) < tol,
            "point {p:?}: centroid {got:?}, image equation {want:?}"
        );
    }
}

/// Stopped down to a pinhole, the lens camera sees what the pinhole at
/// its position with its equivalent field of view sees: points near and
/// far (the perspective centre is the entrance pupil) in the same places.
#[test]
fn a_tiny_stop_sees_what_the_pinhole_sees() {
    let points = [
        [0.0, 0.0, -10.0],
        [0.5, 0.3, -6.0],
        [-1.2, -0.8, -20.0],
        [0.9, -0.5, -15.0],
    ];
    let s = scene("focus_distance = 10\nf_number = 32", &points, 0.0);
    let pinhole = Scene {
        lens: None,
        ..s.clone()
    };
    assert_eq!(s.camera.fov_y_deg, lens(&s).fov_y_deg());
    let settings = RenderSettings {
        width: W,
        height: H,
        spp: 32,
        seed: 2,
    };
    let (a, b) = (render(&s, &settings, None), render(&pinhole, &settings, None));
    let tan = (0.5 * s.camera.fov_y_deg.to_radians()).tan();
    for p in points {
        // The pinhole's projection, written out.
        let at = (
            (p[0] / -p[2] / (tan * 1.5) + 1.0) * 0.5 * W as f64,
            (1.0 - p[1] / -p[2] / tan) * 0.5 * H as f64,
        );
        let (pin, through) = (centroid(&b, at, 4.0), centroid(&a, at, 4.0));
        assert!((pin.0 - at.0).hypot(pin.1 - at.1) < 0.3, "pinhole {pin:?} vs {at:?}");
        let tol = 0.3 + 0.01 * (at.0 - 0.5 * W as f64).hypot(at.1 - 0.5 * H as f64);
        assert!(
            (through.0 - pin.0).hypot(through.1 - pin.1) < tol,
            "point {p:?}: lens {through:?}, pinhole {pin:?}"
        );
    }
}

/// Every ray from the sensor that passes the lens aims inside its
/// interval's exit-pupil box (a dense grid over a square twice the rear
/// aperture, for several sensor radii), and the boxes waste few samples:
/// more than 40 % of camera rays pass, wide open and stopped down (where
/// pbrt's one search of 1.5 × the rear aperture would find almost none).
#[test]
fn pupil_boxes_hold_every_passing_ray_and_most_rays_pass() {
    for f in [2.8, 16.0] {
        let s = scene(&format!("f_number = {f}"), &[], 1.0);
        let l = lens(&s);
        let share = l.pass_share(W, H);
        assert!(share > 0.4 && share < 0.95, "f/{f}: {share} of rays pass");
        let sys = &l.system;
        let rear_z = sys.vertex.z + sys.length();
        let half = 2.0 * sys.surfaces[sys.len() - 1].semi_aperture;
        let half_diagonal = 0.5 * l.sensor[0].hypot(l.sensor[1]);
        let media = sys.media(WAVELENGTH_D_UM);
        for i in [0, 13, 31, 50, INTERVALS - 1] {
            let r = (i as f64 + 0.5) / INTERVALS as f64 * half_diagonal;
            let b = l.pupil_boxes()[i];
            let film = DVec3::new(r, 0.0, sensor_z(l));
            let n = 160;
            let mut passed = 0;
            for j in 0..n * n {
                let p = DVec3::new(
                    ((j % n) as f64 + 0.5) / n as f64 * 2.0 * half - half,
                    ((j / n) as f64 + 0.5) / n as f64 * 2.0 * half - half,
                    rear_z,
                );
                if sys.pass(film, p - film, &media).is_some() {
                    passed += 1;
                    assert!(
                        p.x >= b.lo[0] && p.x <= b.hi[0] && p.y >= b.lo[1] && p.y <= b.hi[1],
                        "f/{f}, interval {i}: ray through {p} passes outside {b:?}"
                    );
                }
            }
            assert!(i > 0 || passed > 0, "f/{f}: nothing passes at the centre");
        }
    }
}

/// Relative illumination: on a uniform white background the picture
/// falls toward the corners as the exit pupil's area seen from each
/// sensor point, cos⁴θ-weighted (vignetting and cos⁴ together), within
/// 5 %; integrated here over a plain grid of rays.
#[test]
fn relative_illumination_follows_the_pupil_area() {
    let s = scene("f_number = 2.8", &[], 1.0);
    let l = lens(&s);
    let sys = &l.system;
    let (rear_z, film_z) = (sys.vertex.z + sys.length(), sensor_z(l));
    let z = film_z - rear_z;
    let half = 2.0 * sys.surfaces[sys.len() - 1].semi_aperture;
    let media = sys.media(WAVELENGTH_D_UM);
    let irradiance = |r: f64| {
        let n = 200;
        let film = DVec3::new(r, 0.0, film_z);
        let mut sum = 0.0;
        for j in 0..n * n {
            let p = DVec3::new(
                ((j % n) as f64 + 0.5) / n as f64 * 2.0 * half - half,
                ((j / n) as f64 + 0.5) / n as f64 * 2.0 * half - half,
                rear_z,
            );
            let d = p - film;
            if sys.pass(film, d, &media).is_some() {
                sum += (z / d.length()).powi(4);
            }
        }
        sum
    };
    let (w, h) = (36, 24);
    let (pw, ph) = l.picture(w, h);
    let centre = irradiance(0.0);
    let settings = RenderSettings {
        width: w,
        height: h,
        spp: 2048,
        seed: 3,
    };
    let mut last = f64::INFINITY;
    for k in [0u32, 3, 6, 9, 12, 15, 17] {
        let (px, py) = (18 + k, 12 + (k * 2) / 3);
        let at = ((px as f64 + 0.5) / w as f64 - 0.5, (py as f64 + 0.5) / h as f64 - 0.5);
        let r = (at.0 * pw).hypot(at.1 * ph);
        let want = irradiance(r) / centre;
        let got = render_pixel(&s, px, py, &settings).y;
        assert!(
            (got - want).abs() < 0.05 * want.max(0.05),
            "pixel ({px}, {py}), radius {r}: {got} vs {want}"
        );
        assert!(want < last + 0.01, "relative illumination rises at {r}");
        last = want;
    }
    assert!(last < 0.8, "the corner is as bright as the centre: {last}");
}

/// Each impossible `[camera]` lens is refused in one line naming the
/// file, the line and the key.
#[test]
fn bad_lens_cameras_are_refused_with_file_line_and_key() {
    let base = "[camera]\nposition = [0, 0, 0]\n";
    let lens = "lens = { preset = \"double-gauss-50mm\", scale = 0.01 }\n";
    let cases: &[(String, &str, &str)] = &[
        (
            format!("{base}lens = \"nope\"\n"),
            "t.toml:3:",
            "camera.lens.preset: no preset `nope`",
        ),
        (
            format!("{base}{lens}f_number = 1\n"),
            "t.toml:4:",
            "camera.f_number: f/1 is faster",
        ),
        (
            format!("{base}{lens}focus_distance = 0.1\n"),
            "t.toml:4:",
            "camera.focus_distance: focus distance 0.1 is nearer",
        ),
        (
            format!("{base}{lens}sensor = [0, 24]\n"),
            "t.toml:4:",
            "camera.sensor: sensor 0 × 0.24",
        ),
        (
            format!("{base}f_number = 4\n"),
            "t.toml:3:",
            "camera.f_number: `f_number` needs a `lens`",
        ),
        (
            format!("{base}pinhole = true\n"),
            "t.toml:3:",
            "camera.pinhole: `pinhole` needs a `lens`",
        ),
        (
            format!("{base}{lens}pinhole = \"yes\"\n"),
            "t.toml:4:",
            "camera.pinhole",
        ),
        (
            format!("{base}{lens}focus_distance = 5\nsensor_distance = 0.4\n"),
            "t.toml:5:",
            "camera.sensor_distance: give either",
        ),
        (
            format!("{base}lens = {{ preset = \"double-gauss-50mm\", surfaces = [] }}\n"),
            "t.toml:3:",
            "camera.lens: give exactly one of",
        ),
        (
            format!("{base}lens = {{ surfaces = [{{ radius = 1, semi_aperture = 2 }}] }}\n"),
            "t.toml:3:",
            "camera.lens.surfaces[0].radius: radius 1 is smaller",
        ),
        (
            format!("{base}{lens}sensor_distance = -0.01\n"),
            "t.toml:4:",
            "camera.sensor_distance: puts the sensor",
        ),
        (
            format!("{base}lens = {{ preset = \"double-gauss-50mm\", focus = 3 }}\n"),
            "t.toml:3:",
            "focus",
        ),
    ];
    for (text, at, what) in cases {
        let e = Scene::parse("t.toml", text).map(|_| ()).expect_err(text).to_string();
        assert!(!e.contains('\n'), "{e}");
        assert!(
            e.starts_with(at) && e.contains(what),
            "{text}\n→ {e}\nwant {at} … {what}"
        );
    }
}

/// `render` reports the lens camera and the share of rays passing;
/// `lens system --system SCENE --camera` reads the camera's lens.
#[test]
fn the_command_line_reports_and_reads_the_camera_lens() {
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/camera-dgauss.toml");
    let run = |args: &[&str]| {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_lensview"))
            .args(args)
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr);
        (o.status.code(), text)
    };
    let out = std::env::temp_dir().join(format!("lens-camera-{}.png", std::process::id()));
    let (code, text) = run(&[
        "render",
        scene,
        "-o",
        out.to_str().unwrap(),
        "--width",
        "24",
        "--height",
        "16",
        "--spp",
        "1",
    ]);
    let _ = std::fs::remove_file(&out);
    assert_eq!(code, Some(0), "{text}");
    let share: f64 = text
        .split(" % of camera rays pass")
        .next()
        .and_then(|t| t.rsplit(' ').next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no share in {text}"));
    assert!(share > 40.0 && share < 95.0, "{text}");
    let (code, text) = run(&["lens", "system", "--system", scene, "--camera"]);
    assert_eq!(code, Some(0), "{text}");
    assert!(
        text.lines()
            .any(|l| l.contains("f-number") && l.trim_end().ends_with(" 2.800000000")),
        "{text}"
    );
    // Shown as a pinhole (the viewer's switch), the lens is still read.
    let pinhole = std::env::temp_dir().join(format!("lens-camera-pinhole-{}.toml", std::process::id()));
    let text = std::fs::read_to_string(scene).unwrap();
    std::fs::write(
        &pinhole,
        text.replace("f_number = 2.8", "f_number = 2.8\npinhole = true"),
    )
    .unwrap();
    let (code, text) = run(&["lens", "system", "--system", pinhole.to_str().unwrap(), "--camera"]);
    let _ = std::fs::remove_file(&pinhole);
    assert_eq!(code, Some(0), "{text}");
    assert!(
        text.lines()
            .any(|l| l.contains("f-number") && l.trim_end().ends_with(" 2.800000000")),
        "{text}"
    );
    let cubes = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/cubes.toml");
    let (code, text) = run(&["lens", "system", "--system", cubes, "--camera"]);
    assert_eq!(code, Some(1), "{text}");
    assert!(text.contains("has no lens"), "{text}");
}

/// The rendered image of an on-axis point out of focus spreads as the
/// spot diagram (`lens spot`: the d line, a hexapolar fill of the
/// entrance pupil, traced forward from the point) says on the sensor's
/// plane: RMS radius within 5 %, after taking out the sphere's own image
/// (a disc, variance ρ²/2) and the pixel (1/6 px²).
#[test]
fn a_defocused_point_spreads_as_the_spot_diagram_says() {
    use lensview::lens_tools::system_bench::SystemBench;
    use lensview::lens_tools::system_spot::system_spot;
    let (d, r) = (4.0, 0.02);
    let s = {
        // A sphere of radius `r`, not the helper's.
        let t = format!(
            "[render]\nbackground = [0, 0, 0]\nshadows = false\n[camera]\nposition = [0, 0, 0]\n\
             lens = {{ preset = \"double-gauss-50mm\", scale = 0.01 }}\nfocus_distance = 11.4\n\
             [ambient]\ncolor = [1, 1, 1]\nintensity = 1\n[materials.white]\ncolor = [1, 1, 1]\ndiffuse = 0\n\
             [[objects]]\ntype = \"sphere\"\nposition = [0, 0, {}]\nradius = {r}\nmaterial = \"white\"\n",
            -d
        );
        Scene::parse("psf", &t).unwrap().1
    };
    let l = lens(&s);
    let (w, h) = (240u32, 160u32);
    let (_, ph) = l.picture(w, h);
    let unit = ph / h as f64;
    // The spot diagram at the sensor's plane.
    let bench = SystemBench::new(l.system.clone(), Some(d + l.system.vertex.z), 0.0).unwrap();
    let spot = system_spot(&bench, Some(l.sensor_distance), 64).unwrap();
    let want = spot.spots.iter().find(|p| p.line == "d").unwrap().rms_radius.unwrap();
    // The rendered PSF over a window about the centre.
    let settings = RenderSettings {
        width: w,
        height: h,
        spp: 256,
        seed: 4,
    };
    let half = 16;
    let (mut m0, mut mx, mut my, mut mxx) = (0.0, 0.0, 0.0, 0.0);
    for py in h / 2 - half..h / 2 + half {
        for px in w / 2 - half..w / 2 + half {
            let v = render_pixel(&s, px, py, &settings).y;
            let (x, y) = (px as f64 + 0.5, py as f64 + 0.5);
            (m0, mx, my, mxx) = (m0 + v, mx + v * x, my + v * y, mxx + v * (x * x + y * y));
        }
    }
    let (cx, cy) = (mx / m0, my / m0);
    let var = mxx / m0 - cx * cx - cy * cy;
    // The sphere's image: radius |m|·r on the sensor (m at distance d).
    let (h1, _, f) = thick_lens(l);
    let m = f / (h1 + d - f);
    let rho = m * r / unit;
    let got = (var - rho * rho / 2.0 - 1.0 / 6.0).sqrt() * unit;
    assert!(
        want / unit > 3.0,
        "the spot is {} px: too small to measure",
        want / unit
    );

    assert!(
        (got - want).abs() < 0.05 * want,
        "rendered RMS {got}, spot diagram {want} ({} px)",
        want / unit
    );
}

/// The double Gauss at f/`n`, focused at `focus`.
fn double_gauss(n: f64, focus: f64) -> String {
    format!("lens = {{ preset = \"double-gauss-50mm\", scale = 0.01 }}\nfocus_distance = {focus}\nf_number = {n}\n")
}

/// README's N-BK7 biconvex singlet (f/2.7, dispersive), focused at 11.4.
const SINGLET: &str = "lens = { surfaces = [\n\
    { radius = 0.5, thickness = 0.06, n = \"N-BK7\", semi_aperture = 0.09 },\n\
    { radius = -0.5, thickness = 0, semi_aperture = 0.09 },\n] }\n\
    sensor = [0.36, 0.24]\nfocus_distance = 11.4\n";

/// The lens camera of `[camera]` keys `camera` photographing white
/// spheres of radius `r` at the local object points of `fields` (degrees,
/// in the system's meridional plane) at distance `d` from the camera: the
/// scene, and each sphere's camera-space centre.
fn field_scene(camera: &str, d: f64, r: f64, fields: &[f64]) -> (Scene, Vec<DVec3>) {
    use lensview::lens_tools::system_bench::SystemBench;
    let head = format!(
        "[render]\nbackground = [0, 0, 0]\nshadows = false\n[camera]\nposition = [0, 0, 0]\n{camera}\
         [ambient]\ncolor = [1, 1, 1]\nintensity = 1\n[materials.white]\ncolor = [1, 1, 1]\ndiffuse = 0\n"
    );
    let l = Scene::parse("lens", &head).unwrap().1.lens.unwrap();
    let at: Vec<DVec3> = fields
        .iter()
        .map(|&a| {
            let bench = SystemBench::new(l.system.clone(), Some(d + l.system.vertex.z), a).unwrap();
            l.system.world_point(bench.object_point(d + l.system.vertex.z))
        })
        .collect();
    let mut t = head;
    for p in &at {
        t += &format!(
            "[[objects]]\ntype = \"sphere\"\nposition = [{}, {}, {}]\nradius = {r}\nmaterial = \"white\"\n",
            p.x, p.y, p.z
        );
    }
    (Scene::parse("field", &t).unwrap().1, at)
}

/// Where the pinhole of the lens's field of view sees `p` (continuous
/// pixels of a `w × h` picture): near where the lens images it.
fn pinhole_pixel(s: &Scene, p: DVec3, (w, h): (u32, u32)) -> (f64, f64) {
    let t = (0.5 * s.camera.fov_y_deg.to_radians()).tan();
    let a = w as f64 / h as f64;
    let (sx, sy) = (p.x / -p.z / (t * a), p.y / -p.z / t);
    ((sx + 1.0) * 0.5 * w as f64, (1.0 - sy) * 0.5 * h as f64)
}

/// The first and second moments of channel `c` (0: C, 1: d, 2: F) of the
/// rendered pixels within `half` pixels of `near`: centroid and variance
/// (px²), the window re-centred once on the centroid.
fn moments(s: &Scene, set: &RenderSettings, near: (f64, f64), half: i64, c: usize) -> ((f64, f64), f64) {
    let mut centre = near;
    let mut out = ((0.0, 0.0), 0.0);
    for _ in 0..2 {
        let (x0, y0) = (centre.0 as i64, centre.1 as i64);
        let (mut m0, mut mx, mut my, mut mxx) = (0.0, 0.0, 0.0, 0.0);
        for py in (y0 - half).max(0)..(y0 + half).min(set.height as i64) {
            for px in (x0 - half).max(0)..(x0 + half).min(set.width as i64) {
                let v = render_pixel(s, px as u32, py as u32, set)[c];
                let (x, y) = (px as f64 + 0.5, py as f64 + 0.5);
                (m0, mx, my, mxx) = (m0 + v, mx + v * x, my + v * y, mxx + v * (x * x + y * y));
            }
        }
        assert!(m0 > 0.0, "nothing bright near {centre:?}");
        centre = (mx / m0, my / m0);
        out = (centre, mxx / m0 - centre.0 * centre.0 - centre.1 * centre.1);
    }
    out
}

/// An off-axis point out of focus through the double Gauss (d line: its
/// prescription has no dispersion), and the C and F lines on and off
/// axis through the N-BK7 singlet (each colour channel is its line's):
/// the rendered PSF's RMS radius within 5 % of the spot diagram's for that
/// field and the sensor's plane, as on axis at the d line.
#[test]
fn off_axis_and_coloured_points_spread_as_the_spot_diagram_says() {
    use lensview::lens_tools::system_bench::SystemBench;
    use lensview::lens_tools::system_spot::system_spot;
    let field = 8.0;
    let (w, h) = (240u32, 160u32);
    let set = RenderSettings {
        width: w,
        height: h,
        spp: 256,
        seed: 4,
    };
    let cases = [
        // (camera, the point's distance and radius, field angle, lines)
        (double_gauss(2.8, 11.4), (4.0, 0.02), field, &["d"][..]),
        (SINGLET.to_string(), (2.5, 0.008), 0.0, &["C", "F"][..]),
        (SINGLET.to_string(), (2.5, 0.008), field, &["C", "d", "F"][..]),
    ];
    for (camera, (d, r), a, lines) in cases {
        let (s, at) = field_scene(&camera, d, r, &[a]);
        let l = lens(&s);
        assert_eq!(l.is_dispersive(), lines.len() > 1);
        let unit = l.picture(w, h).1 / h as f64;
        let bench = SystemBench::new(l.system.clone(), Some(d + l.system.vertex.z), a).unwrap();
        let spot = system_spot(&bench, Some(l.sensor_distance), 64).unwrap();
        let (h1, _, f) = thick_lens(l);
        let rho = f / (h1 + d - f) * r / unit;
        for &line in lines {
            let c = ["C", "d", "F"].iter().position(|&x| x == line).unwrap();
            let want = spot.spots.iter().find(|p| p.line == line).unwrap().rms_radius.unwrap();
            assert!(want / unit > 3.0, "{line} at {a}°: {} px", want / unit);
            let near = pinhole_pixel(&s, at[0], (w, h));
            let (_, var) = moments(&s, &set, near, 20, c);
            let got = (var - rho * rho / 2.0 - 1.0 / 6.0).sqrt() * unit;
            eprintln!("{line} at {a}°: rendered RMS {got:.6}, spot diagram {want:.6}");
            assert!(
                (got - want).abs() < 0.05 * want,
                "{line} at {a}°: rendered RMS {got}, spot diagram {want} ({} px)",
                want / unit
            );
        }
    }
}

/// A grid of points in focus (f/11: the centroid is the chief ray's
/// landing) along one row of the picture: how far each lands from the
/// centre, against the paraxial height (magnification from real near-axis
/// rays, times the point's lateral offset), is the distortion `lens
/// distortion` gives for the camera's lens at that field and distance.
#[test]
fn a_photographed_grid_shows_the_lens_distortion() {
    use lensview::lens_tools::system_bench::SystemBench;
    use lensview::lens_tools::system_spot::system_distortion;
    let (d, fields) = (6.0, [6.0, 12.0, 18.0]);
    let (s, at) = field_scene(&double_gauss(11.0, d), d, 0.01, &fields);
    let l = lens(&s);
    let (w, h) = (360u32, 240u32);
    let unit = l.picture(w, h).1 / h as f64;
    let bench = SystemBench::new(l.system.clone(), Some(d + l.system.vertex.z), 0.0).unwrap();
    let table = system_distortion(&bench, 18.0, 3).unwrap();
    let (h1, _, f) = thick_lens(l);
    let m = f / (h1 + d - f);
    let set = RenderSettings {
        width: w,
        height: h,
        spp: 64,
        seed: 2,
    };
    let mut largest: f64 = 0.0;
    for (k, (&a, p)) in fields.iter().zip(&at).enumerate() {
        let ((cx, cy), _) = moments(&s, &set, pinhole_pixel(&s, *p, (w, h)), 8, 1);
        let real = (cx - w as f64 / 2.0).hypot(cy - h as f64 / 2.0) * unit;
        let paraxial = m * p.x.hypot(p.y);
        let got = 100.0 * (real - paraxial) / paraxial;
        let row = &table.points[k];
        assert!((row.field_deg - a).abs() < 1e-9);
        let want = row.distortion_percent.unwrap();
        eprintln!("{a}°: rendered distortion {got:.4} %, lens distortion {want:.4} %");
        largest = largest.max(want.abs());
        assert!(
            (got - want).abs() < 0.1,
            "{a}°: rendered distortion {got:.3} %, lens distortion {want:.3} %"
        );
    }
    assert!(
        largest > 0.2,
        "the lens barely distorts ({largest:.3} %): nothing is checked"
    );
}

/// A click picks with the ray the lens camera sends out for the pixel's
/// centre through the middle of its pupil box (`viewer/pick.rs`): over the
/// picture those rays point where the pinhole of the same framing looks,
/// within the lens's distortion (about 1 % at the corner) and the pupil
/// box's offset from the chief ray: within 1° everywhere, upright.
#[test]
fn the_pick_ray_through_the_lens_looks_where_the_picture_shows() {
    let s = scene("focus_distance = 10\nf_number = 2.8", &[], 0.0);
    let l = lens(&s);
    let (w, h) = (320u32, 240u32);
    let mut worst = 0.0f64;
    for j in 0..9 {
        for i in 0..9 {
            let at = ((i as f64 + 0.5) / 9.0 * w as f64, (j as f64 + 0.5) / 9.0 * h as f64);
            let (ray, _) = l
                .ray(&s.camera, at, (w, h), (0.5, 0.5), 1)
                .expect("the middle of the pupil passes");
            let pin = s.camera.ray(at.0, at.1, w, h);
            let angle = ray
                .dir
                .normalize()
                .dot(pin.dir.normalize())
                .clamp(-1.0, 1.0)
                .acos()
                .to_degrees();
            worst = worst.max(angle);
        }
    }
    assert!(worst < 1.0, "a pick ray is {worst}° off the pinhole's");
}
