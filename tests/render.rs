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
    let (_, scene) = Scene::parse("g.toml", &glass).unwrap();
    let t = lensview::trace::transmittance(&scene, p + dir * 1e-9, dir, (light - p).length());
    // Two faces at normal incidence: (1 − 0.04)².
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
