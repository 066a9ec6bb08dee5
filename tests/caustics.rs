//! Caustics by progressive photon mapping (issue 20, item 2): the focal
//! spot of a point light on a lens's axis, on a diffuse screen before the
//! focus, against an independent count of rays through the lens; the
//! estimate's thread-count determinism; the `[render] caustics` key.

use glam::DVec3;
use lensview::geometry::{LensSurface, LensTraceStatus};
use lensview::integrator::Lit;
use lensview::optics::{ThickLens, WAVELENGTH_D_UM, fresnel_at};
use lensview::render::caustics::{CausticSettings, caustic_map};
use lensview::render::{RenderSettings, render};
use lensview::sampling::Sampler;
use lensview::scene::Scene;
use std::f64::consts::PI;

// The lens: asymmetric, its strongly curved face toward the light for
// plenty of spherical aberration. Axis +z, centre at the origin, so S1 faces
// +z: the light, on the axis at −z, enters through S2 (radius R_IN) and
// leaves through S1 (radius R_OUT).
const D: f64 = 3.2;
const R_IN: f64 = 3.0;
const R_OUT: f64 = 9.0;
const N: f64 = 1.62;
const LIGHT_Z: f64 = -11.0;
const POWER: f64 = 300.0;

/// The scene: the light, the lens, and a diffuse screen (its front face at
/// `screen_z`) facing them, with `caustics` as written.
fn scene_text(screen_z: f64, caustics: &str) -> String {
    format!(
        r#"
[render]
max_depth = 8
{caustics}

[camera]
position = [6, 0, 0]
look_at = [0, 0, 3]

[[lights]]
type = "point"
position = [0, 0, {LIGHT_Z}]
intensity = {POWER}

[[lenses]]
center = [0, 0, 0]
axis = [0, 0, 1]
d = {D}
r1 = {R_OUT}
r2 = {R_IN}
n = {N}

[materials.screen]
color = [1, 1, 1]
diffuse = 1.0

[[objects]]
name = "screen"
type = "cuboid"
position = [0, 0, {z}]
size = [40, 40, 0.2]
material = "screen"
"#,
        z = screen_z + 0.1
    )
}

fn scene(screen_z: f64, caustics: &str) -> Scene {
    Scene::parse("caustics.toml", &scene_text(screen_z, caustics))
        .unwrap()
        .1
}

/// The screen's distance: 70 % of the way from the lens's back vertex to
/// the paraxial image of the light, well before every focus.
fn screen_z() -> f64 {
    let s = scene(100.0, "");
    let lens = s.objects.iter().find_map(|o| o.lens()).unwrap();
    // The lens as the light meets it: entry face first.
    let p = ThickLens::new(D, R_IN, R_OUT, N);
    let (v_in, v_out) = (lens.vertex(LensSurface::S2).z, lens.vertex(LensSurface::S1).z);
    assert!(v_in < v_out);
    // Object distance from the front principal plane H, image distance
    // from the rear one H' (both positive along the light).
    let so = v_in + p.h1 - LIGHT_Z;
    let si = 1.0 / (1.0 / p.efl - 1.0 / so);
    v_out + 0.7 * (p.h2 + si)
}

/// The independent count: rays from the light spread uniformly over the
/// cone of the lens's rim, traced by the library's exact `Lens::trace`,
/// weighted by the Fresnel transmission of their two crossings, and binned
/// by where they meet the screen. Returns (Φ/4π × Ω × mean transmission,
/// the hit radii with their weights).
fn reference(screen_z: f64, rays: usize) -> (f64, Vec<(f64, f64)>) {
    let s = scene(screen_z, "");
    let lens = s.objects.iter().find_map(|o| o.lens()).unwrap();
    let light = DVec3::new(0.0, 0.0, LIGHT_Z);
    let rim_z = lens.vertex(LensSurface::S2).z + ThickLens::new(D, R_IN, R_OUT, N).sag1;
    let cos_max = (rim_z - LIGHT_Z) / ((rim_z - LIGHT_Z).powi(2) + (0.5 * D).powi(2)).sqrt();
    let omega = 2.0 * PI * (1.0 - cos_max);
    let mut hits = Vec::with_capacity(rays);
    let mut sum = 0.0;
    for i in 0..rays {
        let mut rng = Sampler::new(99, i as u64, 7);
        let (u, v) = rng.next_2d();
        let cos = 1.0 - u * (1.0 - cos_max);
        let sin = (1.0 - cos * cos).sqrt();
        let dir = DVec3::new(sin * (2.0 * PI * v).cos(), sin * (2.0 * PI * v).sin(), cos);
        let path = lens.trace(light, dir, N);
        if path.status != LensTraceStatus::Transmitted || path.internal_reflections > 0 {
            continue;
        }
        let (s1, x1, inside) = path.entry.unwrap();
        let n1 = lens.normal(x1, s1 as u8);
        let (_, x2, out) = path.exit.unwrap();
        let t_in = 1.0 - fresnel_at(dir, n1, 1.0, N);
        let t_out = 1.0 - fresnel_at(inside, -path.exit_crossing.unwrap().normal, N, 1.0);
        let w = t_in * t_out;
        let t = (screen_z - x2.z) / out.z;
        let hit = x2 + out * t;
        hits.push((hit.truncate().length(), w));
        sum += w;
    }
    (POWER / (4.0 * PI) * omega * sum / rays as f64, hits)
}

/// Radii holding `fractions` of the power in `(radius, weight)` pairs.
fn radii(mut v: Vec<(f64, f64)>, fractions: &[f64]) -> Vec<f64> {
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
    let total: f64 = v.iter().map(|p| p.1).sum();
    fractions
        .iter()
        .map(|&f| {
            let mut acc = 0.0;
            v.iter()
                .find(|p| {
                    acc += p.1;
                    acc >= f * total
                })
                .unwrap()
                .0
        })
        .collect()
}

#[test]
fn the_focal_spot_has_the_power_and_profile_of_a_ray_count() {
    let z = screen_z();
    let (expected, ref_hits) = reference(z, 2_000_000);
    let ref_radii = radii(ref_hits.clone(), &[0.5, 0.8, 0.95]);
    let spot = ref_hits.iter().map(|h| h.0).fold(0.0, f64::max);
    // The ring of spherical aberration: the rim's rays fold inward, so the
    // densest 5 % of the area lies at the spot's edge.
    let settings = CausticSettings {
        photons_per_pass: 125_000,
        initial_radius: Some(0.01 * spot),
        seed: 3,
    };
    let map = caustic_map(&scene(z, "caustics = true"), 24, settings).expect("a photon map");
    assert!(map.radius() < 0.007 * spot, "{} vs spot {spot}", map.radius());
    // The estimate on the screen, integrated over a grid of cells.
    let cells = 500;
    let h = 2.4 * spot / cells as f64;
    let mut est = Vec::new();
    for i in 0..cells {
        for j in 0..cells {
            let x = -1.2 * spot + (i as f64 + 0.5) * h;
            let y = -1.2 * spot + (j as f64 + 0.5) * h;
            let e = map.irradiance(DVec3::new(x, y, z), -DVec3::Z).x;
            est.push((x.hypot(y), e * h * h));
        }
    }
    let power: f64 = est.iter().map(|p| p.1).sum();
    assert!(
        (power / expected - 1.0).abs() < 0.05,
        "spot power {power} vs Φ/4π·Ω·T = {expected}"
    );
    let got = radii(est, &[0.5, 0.8, 0.95]);
    for (g, r) in got.iter().zip(&ref_radii) {
        assert!((g / r - 1.0).abs() < 0.08, "radii {got:?} vs ray count {ref_radii:?}");
    }
    // The ring is there and resolved: the irradiance just inside the edge
    // is several times that at mid-radius.
    let at = |r: f64| map.irradiance(DVec3::new(r, 0.0, z), -DVec3::Z).x;
    let edge = (0..40)
        .map(|k| at(spot * (0.90 + 0.0025 * k as f64)))
        .fold(0.0, f64::max);
    assert!(edge > 3.0 * at(0.5 * spot), "edge {edge} vs middle {}", at(0.5 * spot));
    eprintln!(
        "power {power:.4} expected {expected:.4}; radii {got:?} ref {ref_radii:?}; r {}",
        map.radius()
    );
}

/// The caustics of a render are the same bits on one and on three threads.
#[test]
fn caustics_are_the_same_on_any_thread_count() {
    let s = scene(screen_z(), "");
    assert!(s.features.caustics, "on by default with a lit lens");
    let settings = CausticSettings {
        photons_per_pass: 20_000,
        initial_radius: None,
        seed: 5,
    };
    let rs = RenderSettings {
        width: 40,
        height: 30,
        spp: 2,
        seed: 0,
    };
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let map = caustic_map(&s, 5, settings).unwrap();
            let probe: Vec<u64> = (0..200)
                .map(|i| {
                    let p = DVec3::new(i as f64 * 0.01, 0.003 * i as f64, screen_z());
                    map.irradiance(p, -DVec3::Z).x.to_bits()
                })
                .collect();
            (map.photons(), probe, render(Lit::new(&s, Some(&map)), &rs, None).pixels)
        })
    };
    let (a, b) = (run(1), run(3));
    assert!(a.0 > 10_000, "{} photons", a.0);
    assert!(a.1.iter().any(|&e| e != 0), "the probes see no caustic");
    assert_eq!(a.0, b.0);
    assert_eq!(a.1, b.1);
    assert!(a.2 == b.2, "images differ between 1 and 3 threads");
}

/// On by default exactly when glass or a mirror is lit; the key overrides;
/// with caustics on a shadow ray stops at glass, off it is filtered.
#[test]
fn the_caustics_key_and_the_shadow_switch() {
    let z = screen_z();
    let on = scene(z, "");
    let off = scene(z, "caustics = false");
    assert!(on.features.caustics && !off.features.caustics);
    let lens = on.objects.iter().position(|o| o.lens().is_some()).unwrap();
    assert_eq!(on.shadow_filter(lens), glam::DVec3::ZERO);
    assert!(off.shadow_filter(lens).x > 0.8);
    let screen = on.objects.iter().position(|o| o.lens().is_none()).unwrap();
    assert_eq!(off.shadow_filter(screen), glam::DVec3::ZERO);
    // Without glass or mirror there is nothing to compute, key or not.
    let text = scene_text(z, "caustics = true");
    let start = text.find("[[lenses]]").unwrap();
    let end = text.find("[materials.screen]").unwrap();
    let plain = format!("{}{}", &text[..start], &text[end..]);
    let s = Scene::parse("plain.toml", &plain).unwrap().1;
    assert!(!s.features.caustics);
    assert!(caustic_map(&s, 3, CausticSettings::default()).is_none());
}

/// A bad value is refused in one line naming the file, the line and the key.
#[test]
fn bad_values_of_the_key_are_refused_with_their_line() {
    for bad in [
        "caustics = 1",
        "caustics = \"yes\"",
        "caustics = [true]",
        "caustics = 0.5",
    ] {
        let text = scene_text(2.0, bad);
        let err = Scene::parse("bad.toml", &text).unwrap_err().to_string();
        let line = text.lines().position(|l| l == bad).unwrap() + 1;
        assert!(err.starts_with(&format!("bad.toml:{line}")), "{bad}: {err}");
        assert!(err.contains("caustics"), "{bad}: {err}");
        assert_eq!(err.lines().count(), 1, "{bad}: {err}");
    }
}

/// The photons' light enters the shading as `kd·C·E`: a render of the
/// screen where the map says E, less the same render without the map, is
/// kd·C·E (here kd = 1, C = 1).
#[test]
fn the_caustic_enters_the_shading_as_kd_c_e() {
    let z = screen_z();
    let s = scene(z, "");
    let map = caustic_map(&s, 4, CausticSettings::default()).unwrap();
    let ray = lensview::math::Ray {
        origin: DVec3::new(0.05, 0.02, z - 1.0),
        dir: DVec3::Z,
    };
    let with = lensview::integrator::radiance(Lit::new(&s, Some(&map)), &ray, 0, WAVELENGTH_D_UM);
    let without = lensview::integrator::radiance(&s, &ray, 0, WAVELENGTH_D_UM);
    let e = map.irradiance(DVec3::new(0.05, 0.02, z), -DVec3::Z);
    assert!(e.x > 0.0);
    assert!(
        ((with - without) - e).abs().max_element() < 1e-9 * e.x,
        "{with} {without} {e}"
    );
}
