//! Caustic photons leave each light only toward the glass and mirrors
//! (`integrator::Targets`: the cones of their bounding spheres, or for a
//! directional light the discs they project, overlaps weighted by the
//! mixture's density). Against photons sent uniformly in every direction
//! (`Targets::everywhere`), the power they deliver to each region agrees
//! within the noise — the estimate is unbiased and in the same units — for
//! a small fraction of the photons.

use glam::DVec3;
use lensview::integrator::{Targets, photon_pass};
use lensview::scene::Scene;

/// The power `passes` passes of `per_light` photons deliver to each of
/// `regions` regions (`region` says which a landing point is in), as a
/// mean over the passes and its standard error (`√Σ X²` over the photons'
/// contributions X, over the passes).
fn tally(
    scene: &Scene,
    targets: &Targets,
    per_light: usize,
    passes: u32,
    regions: usize,
    region: &dyn Fn(DVec3) -> Option<usize>,
) -> Vec<(f64, f64)> {
    let (mut sum, mut sq) = (vec![0.0; regions], vec![0.0; regions]);
    for pass in 1..=passes {
        for ph in photon_pass(scene, targets, pass, per_light, 11) {
            if let Some(r) = region(ph.p) {
                let x = ph.power[1] as f64;
                sum[r] += x;
                sq[r] += x * x;
            }
        }
    }
    let k = passes as f64;
    sum.iter().zip(&sq).map(|(s, q)| (s / k, q.sqrt() / k)).collect()
}

/// Cones (`n_cone` photons a light a pass) against uniform emission
/// (`n_uniform`): every region agrees within 4.5 standard errors; the
/// regions named in `lit` hold a clear caustic (over 10 standard errors),
/// and there the cones' variance per photon shot is at least `gain` times
/// smaller.
fn cones_agree_with_uniform(
    scene: &Scene,
    (n_cone, n_uniform): (usize, usize),
    regions: usize,
    region: &dyn Fn(DVec3) -> Option<usize>,
    lit: &[usize],
    gain: f64,
) {
    let cones = tally(scene, &Targets::of(scene), n_cone, 4, regions, region);
    let uniform = tally(scene, &Targets::everywhere(scene), n_uniform, 2, regions, region);
    eprintln!("cones {cones:?}\nuniform {uniform:?}");
    for (r, (&(a, sa), &(b, sb))) in cones.iter().zip(&uniform).enumerate() {
        let se = sa.hypot(sb);
        assert!(
            (a - b).abs() <= 4.5 * se,
            "region {r}: cones {a} ± {sa}, uniform {b} ± {sb}"
        );
    }
    for &r in lit {
        let ((a, sa), (b, sb)) = (cones[r], uniform[r]);
        assert!(a > 10.0 * sa && b > 10.0 * sb, "region {r}: {a} ± {sa}, {b} ± {sb}");
        // Variance × photons shot (4 and 2 passes).
        let cost_cones = sa * sa * (4 * n_cone) as f64;
        let cost_uniform = sb * sb * (2 * n_uniform) as f64;
        assert!(
            cost_uniform > gain * cost_cones,
            "region {r}: variance per photon, uniform {cost_uniform} vs cones {cost_cones}"
        );
    }
}

#[test]
fn focal_spot_cones_deliver_the_uniform_power() {
    let text = include_str!("../scenes/focal-spot.toml");
    let scene = Scene::parse("focal-spot.toml", text).unwrap().1;
    // On the floor: the spot, the ring around it, the rest.
    let region = |p: DVec3| {
        (p.y.abs() < 1e-3).then(|| match p.x.hypot(p.z) {
            r if r < 0.4 => 0,
            r if r < 1.5 => 1,
            _ => 2,
        })
    };
    cones_agree_with_uniform(&scene, (40_000, 1_500_000), 3, &region, &[0], 100.0);
}

/// A mirror turned toward a wall, a glass ball partly in front of it as
/// the point light sees it (their cones overlap), a glass block off to the
/// side, lit by a point light and by a directional one.
const MIRROR_AND_GLASS: &str = r#"
[render]
max_depth = 8

[camera]
position = [0, 4, 12]
look_at = [0, 1, 0]

[[lights]]
type = "point"
position = [0, 6, 0]
intensity = 100

[[lights]]
type = "directional"
direction = [0.3, -1, 0.2]
intensity = 2

[materials.matte]
diffuse = 0.9

[materials.mirror]
diffuse = 0.0
reflectivity = 1.0

[materials.glass]
diffuse = 0.0
transparency = 1.0
ior = 1.5

[[objects]]
name = "floor"
type = "cuboid"
position = [0, -0.1, 0]
size = [12, 0.2, 12]
material = "matte"

[[objects]]
name = "wall"
type = "cuboid"
position = [6, 3, 0]
size = [0.2, 6, 12]
material = "matte"

[[objects]]
name = "mirror"
type = "cuboid"
position = [3, 2, 0]
rotation = [0, 0, -30]
size = [3, 0.2, 3]
material = "mirror"

[[objects]]
name = "ball"
type = "sphere"
position = [2, 3.6, 0.4]
radius = 0.8
material = "glass"

[[objects]]
name = "block"
type = "cuboid"
position = [-3, 1, 1]
rotation = [0, 25, 0]
size = [1, 2, 1]
material = "glass"
"#;

#[test]
fn mirror_and_glass_cones_deliver_the_uniform_power() {
    let scene = Scene::parse("mirror-and-glass.toml", MIRROR_AND_GLASS).unwrap().1;
    // Floor left and right of the light, the wall, anything else.
    let region = |p: DVec3| {
        Some(if p.x > 5.8 {
            2
        } else if p.y.abs() < 1e-3 {
            usize::from(p.x >= 0.0)
        } else {
            3
        })
    };
    cones_agree_with_uniform(&scene, (40_000, 600_000), 4, &region, &[0, 1, 2], 5.0);
}

/// Where rays `(weight, point at z, slope)` cross the axis (rays from an
/// axial point stay in a plane with the axis): the weighted median of the
/// crossings, which the few weak ghosts (two inner reflections) cannot pull.
fn median_focus(z: f64, rays: impl Iterator<Item = (f64, (f64, f64), (f64, f64))>) -> f64 {
    let mut at: Vec<(f64, f64)> = rays
        .map(|(w, p, v)| (z - (p.0 * v.0 + p.1 * v.1) / (v.0 * v.0 + v.1 * v.1), w))
        .collect();
    at.sort_by(|a, b| a.0.total_cmp(&b.0));
    let half = 0.5 * at.iter().map(|a| a.1).sum::<f64>();
    let mut acc = 0.0;
    at.iter()
        .find(|a| {
            acc += a.1;
            acc >= half
        })
        .unwrap()
        .0
}

/// With dispersive glass each photon carries one channel, traced at that
/// channel's wavelength (the camera's C, d and F lines): a lens focuses red
/// farther than green and green farther than blue (normal dispersion: the
/// index falls with the wavelength), where an independent count of rays
/// through the lens at each line focuses; each channel carries a third of
/// the photons at three times the power, so the same power as one colour;
/// the same photons on any thread count.
#[test]
fn a_dispersive_lens_focuses_red_farther_than_blue() {
    use lensview::geometry::LensTraceStatus;
    use lensview::optics::{RGB_WAVELENGTHS_UM, fresnel_at};
    use lensview::sampling::Sampler;
    use std::f64::consts::PI;
    let (a, b, d, r, light_z, screen_z) = (1.5, 0.012, 1.2, 8.0, -60.0, 5.0);
    let text = format!(
        r#"
[camera]
position = [6, 0, 0]
look_at = [0, 0, 3]
[[lights]]
type = "point"
position = [0, 0, {light_z}]
intensity = 1000
[[lenses]]
center = [0, 0, 0]
axis = [0, 0, 1]
d = {d}
r1 = {r}
r2 = {r}
n = {{ cauchy = [{a}, {b}] }}
[materials.screen]
diffuse = 1.0
[[objects]]
type = "cuboid"
position = [0, 0, {z}]
size = [10, 10, 0.2]
material = "screen"
"#,
        z = screen_z + 0.1
    );
    let scene = Scene::parse("dispersive.toml", &text).unwrap().1;
    assert!(scene.features.dispersion);
    // The same photons, channels and all, on one thread and on three.
    let on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| photon_pass(&scene, &Targets::of(&scene), 1, 90_000, 3))
    };
    let photons = on(3);
    assert!(photons == on(1), "the photons differ between 1 and 3 threads");
    let lens = scene.objects.iter().find_map(|o| o.lens()).unwrap();
    let light = DVec3::new(0.0, 0.0, light_z);
    // The rim's cone from the light (the rim lies in the plane z = 0).
    let cos_max = -light_z / light_z.hypot(0.5 * d);
    let (mut focus, mut count, mut power) = ([0.0; 3], [0.0; 3], [0.0; 3]);
    for c in 0..3 {
        let mine = photons.iter().filter(|ph| ph.power[c] > 0.0).map(|ph| {
            assert!((ph.p.z - screen_z).abs() < 1e-6, "{:?}", ph.p);
            power[c] += ph.power[c] as f64;
            let [dx, dy, dz] = ph.dir.map(f64::from);
            (ph.power[c] as f64, (ph.p.x, ph.p.y), (dx / dz, dy / dz))
        });
        focus[c] = median_focus(screen_z, mine);
        // The independent count: rays over the rim's cone through the
        // exact tracer at this channel's index, weighted by the Fresnel
        // transmission of their two crossings.
        let n = a + b / RGB_WAVELENGTHS_UM[c].powi(2);
        let rays = (0..200_000).filter_map(|i| {
            let (u, v) = Sampler::new(99, i, 7).next_2d();
            let cos = 1.0 - u * (1.0 - cos_max);
            let sin = (1.0 - cos * cos).sqrt();
            let dir = DVec3::new(sin * (2.0 * PI * v).cos(), sin * (2.0 * PI * v).sin(), cos);
            let path = lens.trace(light, dir, n);
            if path.status != LensTraceStatus::Transmitted || path.internal_reflections > 0 {
                return None;
            }
            let (s1, x1, inside) = path.entry.unwrap();
            let (_, x2, out) = path.exit.unwrap();
            let t_in = 1.0 - fresnel_at(dir, lens.normal(x1, s1 as u8), 1.0, n);
            let t_out = 1.0 - fresnel_at(inside, -path.exit_crossing.unwrap().normal, n, 1.0);
            let p = x2 + out * ((screen_z - x2.z) / out.z);
            Some((t_in * t_out, (p.x, p.y), (out.x / out.z, out.y / out.z)))
        });
        count[c] = median_focus(screen_z, rays);
    }
    eprintln!("photons focus {focus:?}, ray count {count:?}, power {power:?}");
    assert!(focus[0] > focus[1] && focus[1] > focus[2], "{focus:?}");
    for c in 0..3 {
        assert!(
            (focus[c] - count[c]).abs() < 0.05 * (count[0] - count[2]),
            "{focus:?} vs {count:?}"
        );
        assert!((power[c] / power[1] - 1.0).abs() < 0.03, "{power:?}");
    }
}
