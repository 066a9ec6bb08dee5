//! Rendering tests with known answers: the inverse-square point light,
//! bit-identical images on any thread count, and a small image regression.

use glam::DVec3;
use lensview::render::{Image, RenderSettings, render, render_pixel};
use lensview::scene::Scene;
use std::path::PathBuf;

const PLANE: &str = r#"
[render]
shadows = true
background = [0, 0, 0]

[camera]
position = [0, 3, 0]
rotation = [-90, 0, 0]
fov = 60

[ambient]
intensity = 0.0

[[lights]]
position = [0.3, 2, 0.2]
intensity = 50

[materials.white]
color = [0.8, 0.6, 0.4]
diffuse = 0.9
specular = 0.0

[[objects]]
type = "cuboid"
position = [0, -0.5, 0]
size = [40, 1, 40]
material = "white"
"#;

#[test]
fn point_light_over_diffuse_plane_follows_inverse_square_cosine_law() {
    let (_, scene) = Scene::parse("plane.toml", PLANE).unwrap();
    let (w, h) = (64, 48);
    let s = RenderSettings {
        width: w,
        height: h,
        spp: 1,
        seed: 0,
    };
    let light = DVec3::new(0.3, 2.0, 0.2);
    let radiant_intensity = 50.0 / (4.0 * std::f64::consts::PI);
    let albedo = DVec3::new(0.8, 0.6, 0.4) * 0.9;
    for (px, py) in [(0, 0), (32, 24), (5, 40), (63, 47), (20, 10)] {
        let got = render_pixel(&scene, px, py, &s);
        // Where the pixel's ray meets the plane y = 0, computed here directly.
        let ray = scene.camera.ray(px as f64 + 0.5, py as f64 + 0.5, w, h);
        let t = -ray.origin.y / ray.dir.y;
        assert!(t > 0.0);
        let p = ray.origin + t * ray.dir;
        let to_light = light - p;
        let r2 = to_light.length_squared();
        let cos = to_light.y / r2.sqrt();
        let expected = albedo * (radiant_intensity * cos / r2);
        // A lit point (so the relative tolerance below is not zero).
        assert!(expected.min_element() > 0.01, "{expected}");
        assert!(
            (got - expected).abs().max_element() < 1e-12 * expected.max_element(),
            "pixel ({px},{py}): {got} vs {expected}"
        );
    }
}

#[test]
fn an_occluder_casts_a_hard_shadow_and_glass_a_light_one() {
    let opaque = format!(
        "{PLANE}\n[[objects]]\ntype = \"sphere\"\nposition = [0.15, 1, 0.1]\nradius = 0.2\nmaterial = \"white\"\n"
    );
    let (_, scene) = Scene::parse("s.toml", &opaque).unwrap();
    // The point on the floor straight under the light, behind the sphere.
    let p = DVec3::new(0.0, 0.0, 0.0);
    let light = DVec3::new(0.3, 2.0, 0.2);
    let dir = (light - p).normalize();
    let t = lensview::trace::transmittance(&scene, p + dir * 1e-9, dir, (light - p).length());
    assert_eq!(t, DVec3::ZERO);
    let glass = opaque
        .replace(
            "material = \"white\"\n\n[[objects]]",
            "material = \"white\"\n\n[materials.glass]\ntransparency = 1\ncolor = [1, 1, 1]\nior = 1.5\n\n[[objects]]",
        )
        .replacen(
            "radius = 0.2\nmaterial = \"white\"",
            "radius = 0.2\nmaterial = \"glass\"",
            1,
        );
    let (_, mut scene) = Scene::parse("g.toml", &glass).unwrap();
    // With caustics (on by default: lit glass) the light through the glass
    // arrives as photons, and the shadow ray stops at it.
    let t = lensview::trace::transmittance(&scene, p + dir * 1e-9, dir, (light - p).length());
    assert_eq!(t, DVec3::ZERO);
    scene.caustics = Some(false);
    scene.compile();
    let t = lensview::trace::transmittance(&scene, p + dir * 1e-9, dir, (light - p).length());
    // Without: two faces at normal incidence, (1 − 0.04)².
    assert!((t - DVec3::splat(0.96 * 0.96)).abs().max_element() < 1e-12, "{t}");
}

fn cubes() -> Scene {
    Scene::load(&PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/cubes.toml"))
        .unwrap()
        .1
}

#[test]
fn image_is_bit_identical_on_one_and_two_threads() {
    let scene = cubes();
    let s = RenderSettings {
        width: 96,
        height: 72,
        spp: 3,
        seed: 7,
    };
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| render(&scene, &s, None))
    };
    let a = run(1);
    let b = run(2);
    let c = run(3);
    assert!(
        a.pixels
            .iter()
            .zip(&b.pixels)
            .all(|(x, y)| x.to_array().map(f64::to_bits) == y.to_array().map(f64::to_bits))
    );
    assert_eq!(a, c);
}

/// Compares against `tests/golden/cubes-80x60.png`; `LENSVIEW_BLESS=1`
/// rewrites the stored image instead.
#[test]
fn cubes_image_matches_the_stored_reference() {
    let scene = cubes();
    let img = render(
        &scene,
        &RenderSettings {
            width: 80,
            height: 60,
            spp: 2,
            seed: 0,
        },
        None,
    );
    let golden = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/golden/cubes-80x60.png");
    if std::env::var_os("LENSVIEW_BLESS").is_some() {
        img.write_png(&golden).unwrap();
        return;
    }
    let reference = Image::read_png(&golden).expect("stored reference image (regenerate with LENSVIEW_BLESS=1)");
    assert_eq!((reference.width, reference.height), (img.width, img.height));
    let ours = img.to_srgb8();
    let theirs = reference.to_srgb8();
    let diffs: Vec<i32> = ours
        .iter()
        .zip(&theirs)
        .map(|(a, b)| (*a as i32 - *b as i32).abs())
        .collect();
    let mean = diffs.iter().sum::<i32>() as f64 / diffs.len() as f64;
    let max = *diffs.iter().max().unwrap();
    // Rounding differences between machines stay within a level or two.
    assert!(
        mean < 0.5 && max <= 3,
        "image differs from reference: mean {mean:.3}, max {max}"
    );
}

/// A tiny tracer written from the README alone, for `scenes/cubes.toml`:
/// axis-aligned boxes, one point light (E = Φ·cos θ/4πr²), ambient,
/// Lambert and Phong, hard shadows. It knows nothing of the lens, so it is
/// only asked about rays that pass well clear of it.
struct Reference {
    eye: DVec3,
    pitch: f64,
    tan_half: f64,
    boxes: Vec<(DVec3, DVec3, [f64; 3], f64, f64)>,
    light: DVec3,
    power: f64,
    ambient: f64,
    background: DVec3,
    lens: DVec3,
}

impl Reference {
    fn new() -> Reference {
        let text =
            std::fs::read_to_string(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/cubes.toml")).unwrap();
        let t: toml::Table = text.parse().unwrap();
        let v3 = |v: &toml::Value| -> DVec3 {
            let a = v.as_array().unwrap();
            let f = |i: usize| a[i].as_float().or(a[i].as_integer().map(|i| i as f64)).unwrap();
            DVec3::new(f(0), f(1), f(2))
        };
        let num = |v: &toml::Value| v.as_float().or(v.as_integer().map(|i| i as f64)).unwrap();
        let cam = &t["camera"];
        let mats = t["materials"].as_table().unwrap();
        let boxes = t["objects"]
            .as_array()
            .unwrap()
            .iter()
            .map(|o| {
                assert_eq!(o["type"].as_str(), Some("cuboid"));
                assert!(o.get("rotation").is_none());
                let (c, half) = (v3(&o["position"]), 0.5 * v3(&o["size"]));
                let m = &mats[o["material"].as_str().unwrap()];
                let shin = m.get("shininess").map_or(32.0, num);
                (
                    c - half,
                    c + half,
                    v3(&m["color"]).to_array(),
                    num(&m["specular"]),
                    shin,
                )
            })
            .collect();
        let light = &t["lights"].as_array().unwrap()[0];
        Reference {
            eye: v3(&cam["position"]),
            pitch: v3(&cam["rotation"]).x.to_radians(),
            tan_half: (0.5 * num(&cam["fov"])).to_radians().tan(),
            boxes,
            light: v3(&light["position"]),
            power: num(&light["intensity"]),
            ambient: num(&t["ambient"]["intensity"]),
            background: v3(&t["render"]["background"]),
            lens: v3(&t["lenses"].as_array().unwrap()[0]["center"]),
        }
    }

    /// The camera ray through (x, y) in pixels: pitch about x, vertical fov.
    fn ray(&self, x: f64, y: f64, w: u32, h: u32) -> DVec3 {
        let u = (2.0 * x / w as f64 - 1.0) * self.tan_half * w as f64 / h as f64;
        let v = (1.0 - 2.0 * y / h as f64) * self.tan_half;
        let (s, c) = self.pitch.sin_cos();
        DVec3::new(u, v * c + s, v * s - c).normalize()
    }

    /// Nearest box hit after `t > 1e-9`: (t, box index, outward normal).
    fn hit(&self, o: DVec3, d: DVec3) -> Option<(f64, usize, DVec3)> {
        let mut best: Option<(f64, usize, DVec3)> = None;
        for (i, &(lo, hi, ..)) in self.boxes.iter().enumerate() {
            let (t0, t1) = ((lo - o) / d, (hi - o) / d);
            let (near, far) = (t0.min(t1), t0.max(t1));
            let t = near.max_element();
            if t > 1e-9 && t <= far.min_element() && best.is_none_or(|b| t < b.0) {
                let axis = (0..3).find(|&k| near[k] == t).unwrap();
                let mut n = DVec3::ZERO;
                n[axis] = -d[axis].signum();
                best = Some((t, i, n));
            }
        }
        best
    }

    /// Whether the segment from `o` along unit `d` comes within `r` of the lens.
    fn near_lens(&self, o: DVec3, d: DVec3, len: f64, r: f64) -> bool {
        let t = (self.lens - o).dot(d).clamp(0.0, len);
        (o + t * d - self.lens).length() < r
    }

    /// Linear radiance along the camera ray `d`, or `None` if the lens may
    /// be involved (in view or shadowing the point).
    fn radiance(&self, d: DVec3) -> Option<(DVec3, Option<usize>)> {
        if self.near_lens(self.eye, d, 1e9, 1.5) {
            return None;
        }
        let Some((t, i, n)) = self.hit(self.eye, d) else {
            return Some((self.background, None));
        };
        let p = self.eye + t * d;
        let (_, _, color, ks, shin) = self.boxes[i];
        let c = DVec3::from(color);
        let mut out = c * self.ambient;
        let to_l = self.light - p;
        let dist = to_l.length();
        let l = to_l / dist;
        if self.near_lens(p, l, dist, 1.5) {
            return None;
        }
        let cos = n.dot(l);
        let blocked = self.hit(p + n * 1e-9, l).is_some_and(|(s, ..)| s < dist);
        if cos > 0.0 && !blocked {
            let e = self.power / (4.0 * std::f64::consts::PI * dist * dist);
            let r = 2.0 * cos * n - l;
            out += e * (0.9 * c * cos + DVec3::splat(ks * r.dot(-d).max(0.0).powf(shin)));
        }
        Some((out, Some(i)))
    }
}

fn srgb8(v: f64) -> i32 {
    let v = v.clamp(0.0, 1.0);
    let s = if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0).round() as i32
}

/// `tests/golden/cubes-80x60.png`.
fn stored_golden() -> Image {
    Image::read_png(&PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/golden/cubes-80x60.png")).unwrap()
}

/// The stored golden image (2 samples a pixel: the centre and the first
/// point of `Pattern::R2`) re-derived pixel by pixel by the independent
/// tracer above, edges included: wherever both samples' rays pass clear of
/// the lens, the mean of the independent tracer's two samples at the same
/// points must be the stored pixel to two levels. Only where a sample
/// grazes an edge may the two tracers disagree.
#[test]
fn the_stored_reference_is_two_independent_samples_a_pixel() {
    use lensview::sampling::{Pattern, pixel_offset};
    let (golden, r) = (stored_golden(), Reference::new());
    let (w, h) = (golden.width, golden.height);
    let stored = golden.to_srgb8();
    let (mut compared, mut edges, mut off) = (0, 0, Vec::new());
    for py in 0..h {
        for px in 0..w {
            let pixel = (py * w + px) as u64;
            let at = |(dx, dy): (f64, f64)| r.radiance(r.ray(px as f64 + dx, py as f64 + dy, w, h));
            let (Some((a, oa)), Some((b, ob))) = (at((0.5, 0.5)), at(pixel_offset(Pattern::R2, 0, pixel, 1))) else {
                continue;
            };
            let want = (a + b) * 0.5;
            let want = [srgb8(want.x), srgb8(want.y), srgb8(want.z)];
            let i = 3 * (py * w + px) as usize;
            compared += 1;
            edges += usize::from(oa != ob);
            if (0..3).any(|k| (stored[i + k] as i32 - want[k]).abs() > 2) {
                off.push((px, py, &stored[i..i + 3], want));
            }
        }
    }
    // Most of the picture, edges between objects among it, nearly all equal.
    assert!(compared > 1000 && edges >= 5, "{compared} pixels, {edges} on edges");
    assert!(
        off.len() * 200 <= compared,
        "{} of {compared} differ: {:?}",
        off.len(),
        &off[..off.len().min(8)]
    );
}

/// The stored golden image is checked against the independent tracer above
/// wherever a pixel is flat (its corners and centre see the same box with
/// the same colour to a level), so the reference is not only the code's own
/// past output.
#[test]
fn the_stored_reference_agrees_with_an_independent_tracer() {
    let (golden, r) = (stored_golden(), Reference::new());
    let (w, h) = (golden.width, golden.height);
    let srgb = |c: DVec3| [srgb8(c.x), srgb8(c.y), srgb8(c.z)];
    let stored = golden.to_srgb8();
    let mut checked = std::collections::BTreeMap::new();
    for py in 0..h {
        for px in 0..w {
            let at = |dx: f64, dy: f64| r.radiance(r.ray(px as f64 + dx, py as f64 + dy, w, h));
            let corners = [(0.5, 0.5), (0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)].map(|(x, y)| at(x, y));
            let Some((centre, what)) = corners[0] else { continue };
            let flat = corners.iter().all(|c| {
                c.is_some_and(|(v, o)| o == what && srgb(v).iter().zip(srgb(centre)).all(|(a, b)| (a - b).abs() <= 1))
            });
            if !flat {
                continue;
            }
            let i = 3 * (py * w + px) as usize;
            let want = srgb(centre);
            for k in 0..3 {
                let d = (stored[i + k] as i32 - want[k]).abs();
                assert!(
                    d <= 2,
                    "pixel ({px},{py}): stored {:?}, independent {want:?}",
                    &stored[i..i + 3]
                );
            }
            *checked.entry(what).or_insert(0) += 1;
        }
    }
    // Background, the ground and cubes (those not behind the lens) were all
    // compared.
    let n: usize = checked.values().sum();
    assert!(
        n > 500 && checked.len() >= 4 && checked.contains_key(&None) && checked.contains_key(&Some(0)),
        "{checked:?}"
    );
}
