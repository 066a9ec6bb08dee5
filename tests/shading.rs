//! The shading terms of the README against values computed here by hand:
//! ambient, Lambert under a directional light (and its shadow), Phong
//! specular, mirror reflection, and the order of the dispersion channels.

use glam::DVec3;
use lensview::render::{RGB_WAVELENGTHS_UM, RenderSettings, render, render_pixel};
use lensview::scene::Scene;

/// A 1×1 image: its one sample (spp 1 is the pixel centre) looks exactly
/// along the camera's view direction.
fn one_pixel(text: &str) -> DVec3 {
    let (_, scene) = Scene::parse("t.toml", text).unwrap();
    render_pixel(&scene, 0, 0, &one_sample(1, 1))
}

/// One sample a pixel, at its centre.
fn one_sample(width: u32, height: u32) -> RenderSettings {
    RenderSettings {
        width,
        height,
        spp: 1,
        seed: 0,
    }
}

fn close(got: DVec3, want: DVec3) {
    assert!(
        (got - want).abs().max_element() <= 1e-12 * want.max_element().max(1e-3),
        "got {got}, want {want}"
    );
}

/// Looking straight down at the floor y = 0 (its top face) from above.
const FLOOR: &str = r#"
[render]
background = [0, 0, 0]
[camera]
position = [0, 3, 0]
rotation = [-90, 0, 0]
[materials.m]
color = [0.8, 0.5, 0.3]
ambient = 0.5
diffuse = 0.9
specular = 0
[[objects]]
type = "cuboid"
position = [0, -0.5, 0]
size = [40, 1, 40]
material = "m"
"#;

const C: DVec3 = DVec3::new(0.8, 0.5, 0.3);

#[test]
fn ambient_and_a_directional_light_give_ka_c_a_plus_kd_c_e_cos() {
    let dir = DVec3::new(1.0, -2.0, 0.5);
    let text = format!(
        "{FLOOR}[ambient]\ncolor = [0.2, 0.4, 1.0]\nintensity = 0.3\n\
         [[lights]]\ntype = \"directional\"\ndirection = [1, -2, 0.5]\ncolor = [1, 0.5, 0.25]\nintensity = 2\n"
    );
    let ambient = 0.5 * C * DVec3::new(0.2, 0.4, 1.0) * 0.3;
    let cos = -dir.normalize().y;
    let lambert = 0.9 * C * DVec3::new(1.0, 0.5, 0.25) * 2.0 * cos;
    close(one_pixel(&text), ambient + lambert);
    // A box up the light's way shadows the point: the ambient term remains.
    let up = -dir.normalize() * 2.0;
    let shadowed = format!(
        "{text}[[objects]]\ntype = \"cuboid\"\nposition = [{}, {}, {}]\nsize = [0.5, 0.1, 0.5]\n",
        up.x, up.y, up.z
    );
    close(one_pixel(&shadowed), ambient);
    // Shadows off: the light gets through the box again.
    close(
        one_pixel(&shadowed.replace("[render]", "[render]\nshadows = false")),
        ambient + lambert,
    );
}

#[test]
fn phong_specular_is_ks_times_cos_alpha_to_the_shininess() {
    // The light travels 20° off the mirror direction that would reach the
    // eye: the angle between R and V is then 20°.
    let a = 35f64.to_radians();
    let off = 20f64.to_radians();
    let dir = DVec3::new((a + off).sin(), -(a + off).cos(), 0.0);
    let text = FLOOR
        .replace(
            "diffuse = 0.9\nspecular = 0",
            "diffuse = 0\nspecular = 0.7\nshininess = 10",
        )
        .replace("ambient = 0.5", "ambient = 0")
        + &format!(
            "[[lights]]\ntype = \"directional\"\ndirection = [{}, {}, 0]\ncolor = [1, 0.5, 0.25]\nintensity = 3\n",
            dir.x, dir.y
        );
    let l = -dir;
    let n = DVec3::Y;
    let r = 2.0 * n.dot(l) * n - l;
    let v = DVec3::Y;
    assert!((r.dot(v) - (a + off).cos()).abs() < 1e-15);
    let want = 0.7 * r.dot(v).powi(10) * 3.0 * DVec3::new(1.0, 0.5, 0.25);
    close(one_pixel(&text), want);
}

#[test]
fn a_mirror_returns_kr_times_what_it_reflects() {
    // The camera looks down at 45° onto a mirror floor; the reflected ray
    // goes up at 45° into a wall lit by ambient light only.
    let text = r#"
[render]
background = [0, 0, 0]
[camera]
position = [0, 2, 2]
rotation = [-45, 0, 0]
[ambient]
color = [1, 0.5, 0.5]
intensity = 0.8
[materials.mirror]
ambient = 0
diffuse = 0
reflectivity = 0.6
[materials.wall]
color = [0.3, 0.9, 0.6]
ambient = 1
diffuse = 0
[[objects]]
type = "cuboid"
position = [0, -0.5, 0]
size = [40, 1, 40]
material = "mirror"
[[objects]]
type = "cuboid"
position = [0, 0, -6]
size = [40, 40, 1]
material = "wall"
"#;
    let wall = DVec3::new(0.3, 0.9, 0.6) * DVec3::new(1.0, 0.5, 0.5) * 0.8;
    close(one_pixel(text), 0.6 * wall);
    // Without the mirror term the floor is black.
    close(
        one_pixel(&text.replace("reflectivity = 0.6", "reflectivity = 0")),
        DVec3::ZERO,
    );
}

#[test]
fn dispersion_channels_are_c_d_f_and_red_focuses_farther() {
    // The Fraunhofer lines, from the literature: C (H-alpha), d (He), F (H-beta).
    let cdf = [0.656_281_6, 0.587_561_8, 0.486_132_7];
    for (got, want) in RGB_WAVELENGTHS_UM.iter().zip(cdf) {
        assert!((got - want).abs() < 1e-7, "{RGB_WAVELENGTHS_UM:?}");
    }
    // A white bar seen through a magnifier (object inside the focal length):
    // magnification f/(f − u) falls as f grows, and normal dispersion
    // (n falls with wavelength) gives red the longest focal length, so the
    // bar looks narrowest in red and widest in blue.
    let text = r#"
[render]
background = [0, 0, 0]
[camera]
position = [0, 0, 3]
fov = 6
[ambient]
intensity = 1
[materials.white]
color = [1, 1, 1]
ambient = 1
diffuse = 0
[[objects]]
type = "cuboid"
position = [0, 0, -2.5]
size = [0.5, 8, 0.05]
material = "white"
[[lenses]]
center = [0, 0, 0]
d = 2
r1 = 4
r2 = 4
n = { cauchy = [1.5, 0.05] }
"#;
    let (_, scene) = Scene::parse("d.toml", text).unwrap();
    let (w, h) = (801, 81);
    let img = render(&scene, &one_sample(w, h), None);
    let row = h / 2;
    let width_in = |ch: usize| (0..w).filter(|&x| img.get(x, row)[ch] > 0.5).count();
    let (r, g, b) = (width_in(0), width_in(1), width_in(2));
    assert!(
        r > 10 && r < g && g < b,
        "bar widths in pixels: red {r}, green {g}, blue {b}"
    );
}
