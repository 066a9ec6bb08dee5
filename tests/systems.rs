//! Lens systems in scenes (`[[systems]]`): every kind builds, every refusal
//! names its key and line, extreme values never panic, and a biconvex
//! system renders what the biconvex `[[lenses]]` renders.

use lensview::render::{RenderSettings, render};
use lensview::scene::Scene;

const HEAD: &str = r#"
[render]
background = [0.1, 0.1, 0.1]
caustics = false

[camera]
position = [0, 0, 8]
look_at = [0, 0, 0]
fov = 40

[ambient]
intensity = 0.3

[[lights]]
position = [2, 3, 8]
intensity = 400

[materials.white]
color = [0.9, 0.9, 0.9]
diffuse = 0.9

[materials.black]
color = [0.05, 0.05, 0.05]
diffuse = 0.9

[[objects]]
type = "cuboid"
position = [0, 0, -0.1]
size = [8, 6, 0.2]
material = "white"

[[objects]]
type = "cuboid"
position = [0.4, 0.3, 0.01]
size = [0.6, 0.6, 0.02]
material = "black"

[[objects]]
type = "cuboid"
position = [-0.7, -0.5, 0.01]
size = [0.4, 0.8, 0.02]
material = "black"
"#;

fn scene(system: &str) -> Result<Scene, String> {
    Scene::parse("t.toml", &format!("{HEAD}\n{system}"))
        .map(|s| s.1)
        .map_err(|e| e.to_string())
}

#[test]
fn every_kind_builds_a_system() {
    let kinds = [
        "kind = \"plano-convex\"\ncenter = [0, 0, 2]\nd = 2\nr = 3\nthickness = 0.4\nn = 1.5",
        "kind = \"plano-convex\"\ncenter = [0, 0, 2]\nd = 2\nr = 3\nthickness = 0.4\nn = 1.5\nflat = \"front\"",
        "kind = \"plano-concave\"\ncenter = [0, 0, 2]\nd = 2\nr = 3\nthickness = 0.2\nn = \"N-BK7\"",
        "kind = \"biconvex\"\nvertex = [0, 0, 2]\nd = 2\nr1 = 3\nr2 = 4\nthickness = 0.5\nn = 1.6",
        "kind = \"biconcave\"\ncenter = [0, 0, 2]\nd = 2\nr1 = 3\nr2 = 4\nthickness = 0.1\nn = 1.6",
        "kind = \"meniscus\"\ncenter = [0, 0, 2]\nd = 2\nr1 = 2\nr2 = 4\nthickness = 0.4\nn = 1.6",
        "kind = \"doublet\"\ncenter = [0, 0, 2]\nd = 2\nr1 = 5\nr2 = -3.6\nr3 = -10\nthickness = 0.4\nthickness2 = 0.2\nn = \"N-BK7\"\nn2 = \"SF5\"",
        "kind = \"surfaces\"\ncenter = [0, 0, 2]\nsurfaces = [{ radius = 3, thickness = 0.5, n = 1.5, semi_aperture = 1 }, { radius = 0, semi_aperture = 1 }]",
        "kind = \"preset\"\npreset = \"double-gauss-50mm\"\nscale = 0.05\ncenter = [0, 0, 2]",
        "kind = \"prescription\"\nscale = 0.05\ncenter = [0, 0, 2]\nprescription = \"\"\"\n# r t n a\n40 6 1.5168 30\n-40 0 1 30\n\"\"\"",
    ];
    for k in kinds {
        let s = scene(&format!("[[systems]]\n{k}\n")).unwrap_or_else(|e| panic!("{k}: {e}"));
        let sys = s.objects.iter().find_map(|o| o.system()).expect("a system");
        assert!(sys.len() >= 2);
        // Rendered: finite everywhere, and the lens changes the picture.
        let img = render(
            &s,
            &RenderSettings {
                width: 24,
                height: 18,
                spp: 1,
                seed: 1,
            },
            None,
        );
        assert!(img.pixels.iter().all(|p| p.is_finite()), "{k}");
    }
}

#[test]
fn refusals_name_the_key_and_its_line() {
    let cases = [
        ("kind = \"lens\"\ncenter = [0, 0, 2]", "systems[0].kind"),
        (
            "kind = \"biconvex\"\ncenter = [0, 0, 2]\nd = 2\nr1 = 3\nr2 = 3\nn = 1.5",
            "systems[0].thickness",
        ),
        (
            "kind = \"biconvex\"\ncenter = [0, 0, 2]\nd = 2\nr1 = 0.5\nr2 = 3\nthickness = 1\nn = 1.5",
            "systems[0].r1",
        ),
        (
            "kind = \"biconvex\"\ncenter = [0, 0, 2]\nd = 2\nr1 = 3\nr2 = 3\nthickness = 0.1\nn = 1.5",
            "systems[0].thickness",
        ),
        (
            "kind = \"biconvex\"\ncenter = [0, 0, 2]\nd = 2\nr = 3\nr2 = 3\nthickness = 1\nn = 1.5",
            "systems[0].r",
        ),
        (
            "kind = \"biconvex\"\nd = 2\nr1 = 3\nr2 = 3\nthickness = 1\nn = 1.5",
            "systems[0].vertex",
        ),
        (
            "kind = \"biconvex\"\ncenter = [0, 0, 2]\nd = 2\nr1 = 3\nr2 = 3\nthickness = 1\nn = 0.5",
            "systems[0].n",
        ),
        (
            "kind = \"doublet\"\ncenter = [0, 0, 2]\nd = 2\nr1 = 5\nr2 = -3.6\nr3 = -10\nthickness = 0.4\nthickness2 = 0.2\nn = 1.5\nn2 = 0.9",
            "systems[0].n2",
        ),
        (
            "kind = \"preset\"\npreset = \"nope\"\ncenter = [0, 0, 2]",
            "systems[0].preset",
        ),
        (
            "kind = \"prescription\"\ncenter = [0, 0, 2]\nprescription = \"40 6 1.5\"",
            "systems[0].prescription",
        ),
        (
            "kind = \"prescription\"\ncenter = [0, 0, 2]\nprescription = \"40 6 1.5 100\\n-40 0 1 100\"",
            "systems[0].prescription: line 1: radius",
        ),
        (
            "kind = \"surfaces\"\ncenter = [0, 0, 2]\nsurfaces = [{ radius = 3, thickness = 0.5, n = 1.5, semi_aperture = 4 }, { semi_aperture = 1 }]",
            "systems[0].surfaces[0].radius",
        ),
        (
            "kind = \"surfaces\"\ncenter = [0, 0, 2]\nsurfaces = [{ radius = 3, thickness = 0.5, n = 1.5, semi_aperture = 1 }]",
            "systems[0].surfaces[0].n",
        ),
        (
            "kind = \"surfaces\"\ncenter = [0, 0, 2]\nsurfaces = [{ radius = 3, thickness = 0.5, n = \"XYZ\", semi_aperture = 1 }, { semi_aperture = 1 }]",
            "systems[0].surfaces[0].n",
        ),
        (
            "kind = \"plano-convex\"\ncenter = [0, 0, 2]\nd = 2\nr = 3\nthickness = 0.4\nn = 1.5\nflat = \"left\"",
            "systems[0].flat",
        ),
        (
            "kind = \"preset\"\npreset = \"double-gauss-50mm\"\nscale = -1\ncenter = [0, 0, 2]",
            "systems[0].scale",
        ),
    ];
    for (body, field) in cases {
        let text = format!("{HEAD}\n[[systems]]\n{body}\n");
        let e = Scene::parse("t.toml", &text).map(|_| ()).unwrap_err().to_string();
        assert!(e.contains(field), "{body}\n→ {e}\n(wanted {field})");
        assert!(e.starts_with("t.toml:"), "no line: {e}");
        assert_eq!(e.lines().count(), 1, "{e}");
    }
}

/// A tiny deterministic generator (xorshift) for the sweep below.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn pick<'a>(&mut self, xs: &[&'a str]) -> &'a str {
        xs[(self.next() % xs.len() as u64) as usize]
    }
}

#[test]
fn extreme_values_are_refused_or_rendered_never_a_panic() {
    let numbers = [
        "0", "-0", "1e-12", "1e-9", "0.5", "1", "2", "3", "-3", "1e3", "1e9", "1e12", "1e308", "nan", "inf", "-inf",
    ];
    let mut rng = Rng(0x5eed_1234_abcd);
    let (mut built, mut refused) = (0, 0);
    for i in 0..400 {
        let mut n = || rng.pick(&numbers);
        let body = match i % 4 {
            0 => format!(
                "kind = \"biconvex\"\ncenter = [0, 0, {}]\nd = {}\nr1 = {}\nr2 = {}\nthickness = {}\nn = 1.5",
                n(),
                n(),
                n(),
                n(),
                n()
            ),
            1 => format!(
                "kind = \"surfaces\"\nvertex = [0, 0, 2]\naxis = [{}, 0, 1]\nsurfaces = [{{ radius = {}, thickness = {}, n = 1.5, semi_aperture = {} }}, {{ radius = {}, semi_aperture = {}, stop = true }}]",
                n(),
                n(),
                n(),
                n(),
                n(),
                n()
            ),
            2 => format!(
                "kind = \"doublet\"\ncenter = [{}, 0, 2]\nd = {}\nr1 = {}\nr2 = {}\nr3 = {}\nthickness = {}\nthickness2 = {}\nn = 1.5\nn2 = 1.7",
                n(),
                n(),
                n(),
                n(),
                n(),
                n(),
                n()
            ),
            _ => format!(
                "kind = \"preset\"\npreset = \"cooke-triplet-100mm\"\nscale = {}\ncenter = [0, {}, 2]",
                n(),
                n()
            ),
        };
        match scene(&format!("[[systems]]\n{body}\n")) {
            Ok(s) => {
                built += 1;
                let img = render(
                    &s,
                    &RenderSettings {
                        width: 8,
                        height: 6,
                        spp: 1,
                        seed: 3,
                    },
                    None,
                );
                assert!(img.pixels.iter().all(|p| p.is_finite()), "{body}");
            }
            Err(e) => {
                refused += 1;
                assert!(e.contains("systems[0]"), "{body}\n→ {e}");
                assert_eq!(e.lines().count(), 1, "{e}");
            }
        }
    }
    eprintln!("400 extreme systems: {built} built and rendered, {refused} refused");
    assert!(built > 10 && refused > 100, "built {built}, refused {refused}");
}

#[test]
fn a_biconvex_system_renders_as_the_biconvex_lens() {
    // d 2, R 3, 3, n 1.5: the knife-edge thickness is 2·sag.
    let sag = 3.0 - (9.0f64 - 1.0).sqrt();
    let lens = "[[lenses]]\ncenter = [0, 0, 2]\nd = 2\nr1 = 3\nr2 = 3\nn = 1.5\n";
    let system = format!(
        "[[systems]]\nkind = \"biconvex\"\ncenter = [0, 0, 2]\nd = 2\nr1 = 3\nr2 = 3\nthickness = {}\nn = 1.5\n",
        2.0 * sag
    );
    let s = RenderSettings {
        width: 64,
        height: 48,
        spp: 2,
        seed: 5,
    };
    let a = render(&scene(lens).unwrap(), &s, None);
    let b = render(&scene(&system).unwrap(), &s, None);
    let mut worst: f64 = 0.0;
    let mut sum = 0.0;
    for (x, y) in a.pixels.iter().zip(&b.pixels) {
        let d = (*x - *y).abs().max_element();
        worst = worst.max(d);
        sum += d;
    }
    let mean = sum / a.pixels.len() as f64;
    eprintln!("biconvex system against the lens: mean {mean:.3e}, worst {worst:.3e} (linear RGB)");
    // The same light paths: only the order of additions and the branches
    // pruned near the weight bound differ.
    assert!(mean < 1e-10 && worst < 1e-8, "mean {mean}, worst {worst}");
    // And the lens is seen: a different picture without it.
    let none = render(&scene("").unwrap(), &s, None);
    let moved: f64 = a
        .pixels
        .iter()
        .zip(&none.pixels)
        .map(|(x, y)| (*x - *y).abs().max_element())
        .sum();
    assert!(moved / a.pixels.len() as f64 > 1e-2);
}

#[test]
fn lens_commands_read_a_scene_files_system() {
    let run = |args: &[&str]| {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_lensview"))
            .args(args)
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .output()
            .unwrap();
        (
            o.status.code(),
            String::from_utf8_lossy(&o.stdout).into_owned(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    // The achromat and the singlet of scenes/achromat.toml: the same focal
    // length, as the scene says.
    let efl = |index: &str| {
        let (code, out, err) = run(&[
            "lens",
            "system",
            "--system",
            "scenes/achromat.toml",
            "--system-index",
            index,
            "--json",
        ]);
        assert_eq!(code, Some(0), "{err}");
        let v: serde_json::Value = serde_json::from_str(&out).unwrap();
        v["efl"].as_f64().unwrap()
    };
    let (a, s) = (efl("0"), efl("1"));
    assert!((a - 8.0).abs() < 0.01 && (s - 8.0).abs() < 0.01, "{a} {s}");
    let (code, _, err) = run(&[
        "lens",
        "system",
        "--system",
        "scenes/achromat.toml",
        "--system-index",
        "2",
    ]);
    assert_eq!(code, Some(1));
    assert!(err.contains("has 2 lens systems") && err.lines().count() == 1, "{err}");
    let (code, out, err) = run(&[
        "lens",
        "fan",
        "--system",
        "scenes/lens-family.toml",
        "--system-index",
        "0",
        "--json",
    ]);
    assert_eq!(code, Some(0), "{err}");
    assert!(out.contains("\"surfaces\": 2"), "{out}");
}

/// The index has one owner: a lens's and a system's are their shapes'
/// (`Object::ior`), a glass sphere's its material's. A lens's or system's
/// material holds none: changing it changes no pixel, with shadows through
/// glass (caustics off) and dispersion, where every path reads an index.
#[test]
fn a_lens_index_has_one_owner() {
    let body = "[[lenses]]\ncenter = [-1.5, 0, 2]\nd = 2\nr1 = 3\nr2 = 3\nn = \"N-SF11\"\n\
                [[systems]]\nkind = \"doublet\"\ncenter = [1.5, 0, 2]\nd = 2\nr1 = 6\nr2 = -4\nr3 = -20\n\
                thickness = 0.6\nthickness2 = 0.3\nn = \"N-BK7\"\nn2 = \"SF5\"\n\
                [materials.glassy]\ncolor = [1, 1, 1]\ntransparency = 0.9\nior = 1.3\n\
                [[objects]]\ntype = \"sphere\"\nposition = [0, 1.8, 1]\nradius = 0.5\nmaterial = \"glassy\"\n";
    let s = scene(body).unwrap();
    let find = |f: &dyn Fn(&lensview::scene::Object) -> bool| s.objects.iter().find(|o| f(o)).unwrap();
    let lens = find(&|o| o.lens().is_some());
    let system = find(&|o| o.system().is_some());
    let sphere = find(&|o| o.lens().is_none() && o.system().is_none() && o.material.transparency > 0.0);
    let d = lensview::optics::WAVELENGTH_D_UM;
    assert_eq!(lens.ior(), lens.lens().unwrap().index);
    assert!((lens.ior().at(d) - 1.78472).abs() < 1e-4, "{}", lens.ior().at(d));
    assert_eq!(system.ior(), system.system().unwrap().first_glass());
    assert_eq!(sphere.ior().at(d), 1.3);
    assert!(s.features.dispersion);
    let settings = RenderSettings {
        width: 48,
        height: 36,
        spp: 1,
        seed: 2,
    };
    let before = render(&s, &settings, None);
    let mut changed = s.clone();
    for o in &mut changed.objects {
        if o.lens().is_some() || o.system().is_some() {
            o.material.ior = lensview::optics::Index::Constant(2.9);
        }
    }
    changed.compile();
    let after = render(&changed, &settings, None);
    assert!(before.pixels == after.pixels, "a lens's material index was read");
}
