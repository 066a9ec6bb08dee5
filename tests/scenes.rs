//! Every shipped scene loads and renders; bad scene files are rejected with
//! one line naming file, line and field.

use lensview::render::{RenderSettings, render};
use lensview::scene::{Scene, SceneError};
use std::path::PathBuf;

fn scene_files() -> Vec<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    v.sort();
    v
}

#[test]
fn every_scene_loads_and_renders() {
    let files = scene_files();
    assert!(files.len() >= 3, "{files:?}");
    for f in files {
        let (_, scene) = Scene::load(&f).unwrap_or_else(|e| panic!("{e}"));
        let img = render(
            &scene,
            &RenderSettings {
                width: 48,
                height: 32,
                spp: 1,
                seed: 0,
            },
            None,
        );
        let lum: f64 = img.pixels.iter().map(|c| c.element_sum()).sum::<f64>() / img.pixels.len() as f64;
        assert!(lum > 0.02, "{}: image is black", f.display());
        assert!(
            img.pixels.iter().all(|c| c.is_finite()),
            "{}: non-finite pixel",
            f.display()
        );
        // Not a flat colour: there is a picture.
        let first = img.pixels[0];
        assert!(
            img.pixels.iter().any(|c| (*c - first).abs().max_element() > 0.05),
            "{}: flat image",
            f.display()
        );
    }
}

#[test]
fn embedded_default_scene_is_valid_and_has_a_lens() {
    let (_, scene) = Scene::default_scene();
    assert!(scene.objects.iter().any(|o| o.lens().is_some()));
}

#[test]
fn cubes_scene_is_laid_out_as_specified() {
    let (_, s) = Scene::load(&PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/cubes.toml")).unwrap();
    let cubes: Vec<_> = s.objects.iter().filter(|o| o.name.starts_with("cube")).collect();
    assert_eq!(cubes.len(), 25);
    let grid = [-3.2, -1.6, 0.0, 1.6, 3.2];
    for o in &cubes {
        assert!(grid.contains(&o.position.x) && grid.contains(&o.position.z) && o.position.y == 0.5);
        assert_eq!(o.material.shininess, 48.0);
    }
    let lens = s.objects.iter().find_map(|o| o.lens()).unwrap();
    assert_eq!((lens.d, lens.r1, lens.r2, lens.index.nominal()), (2.0, 5.0, 5.0, 1.5));
    // The camera looks at (0, 0.5, 0) through the lens centre.
    let to_target = (glam::DVec3::new(0.0, 0.5, 0.0) - s.camera.position).normalize();
    assert!((s.camera.forward() - to_target).length() < 1e-6);
    let to_lens = (lens.center - s.camera.position).normalize();
    assert!((to_lens - to_target).length() < 1e-6);
    assert!((lens.axis + to_target).length() < 1e-6);
    assert_eq!(s.camera.fov_y_deg, 45.0);
}

const BASE: &str = r#"
[camera]
position = [0, 1, 5]
look_at = [0, 0, 0]

[[lights]]
position = [1, 4, 2]
intensity = 100

[materials.red]
color = [0.8, 0.1, 0.1]

[[objects]]
type = "sphere"
radius = 1
material = "red"

[[lenses]]
center = [0, 0, 3]
d = 1
r1 = 2
r2 = 2
n = 1.5
"#;

/// Parses `BASE` with `from` replaced by `to`; returns (line, column, field, message).
fn error_of(from: &str, to: &str) -> (usize, String, String) {
    assert!(BASE.contains(from), "{from}");
    let text = BASE.replacen(from, to, 1);
    match Scene::parse("bad.toml", &text) {
        Ok(_) => panic!("accepted {to}"),
        Err(SceneError::Invalid {
            file,
            line,
            field,
            message,
            ..
        }) => {
            assert_eq!(file, "bad.toml");
            let shown = Scene::parse("bad.toml", &text).unwrap_err().to_string();
            assert!(!shown.contains('\n'), "not one line: {shown}");
            assert!(shown.starts_with(&format!("bad.toml:{line}:")), "{shown}");
            (line, field, message)
        }
        Err(e) => panic!("{e}"),
    }
}

#[test]
fn valid_base_scene() {
    Scene::parse("ok.toml", BASE).unwrap();
}

#[test]
fn typo_key_is_rejected_with_line_and_field() {
    let (line, field, msg) = error_of("radius = 1", "raduis = 1");
    assert_eq!(line, 15);
    assert_eq!(field, "objects[0].raduis");
    assert!(msg.contains("unknown field `raduis`"), "{msg}");
}

#[test]
fn radius_below_half_diameter_is_rejected() {
    let (line, field, msg) = error_of("r1 = 2", "r1 = 0.4");
    assert_eq!(line, 21);
    assert_eq!(field, "lenses[0].r1");
    assert!(msg.contains("smaller than d/2"), "{msg}");
}

#[test]
fn nan_and_infinity_are_rejected() {
    let (line, field, _) = error_of("intensity = 100", "intensity = nan");
    assert_eq!((line, field.as_str()), (8, "lights[0].intensity"));
    let (line, field, _) = error_of("position = [0, 1, 5]", "position = [0, inf, 5]");
    assert_eq!((line, field.as_str()), (3, "camera.position[1]"));
}

#[test]
fn impossible_values_are_rejected() {
    assert_eq!(error_of("radius = 1", "radius = -1").1, "objects[0].radius");
    assert_eq!(error_of("d = 1", "d = 0").1, "lenses[0].d");
    assert_eq!(error_of("n = 1.5", "n = 0.5").1, "lenses[0].n");
    assert_eq!(error_of("radius = 1", "radius = 1\nside = 2").1, "objects[0].side");
    assert_eq!(
        error_of("material = \"red\"", "material = \"blue\"").1,
        "objects[0].material"
    );
    assert_eq!(
        error_of("color = [0.8, 0.1, 0.1]", "color = [0.8, -0.1, 0.1]").1,
        "materials.red.color[1]"
    );
    let (_, field, msg) = error_of("d = 1", "d = \"one\"");
    assert_eq!(field, "lenses[0].d");
    assert!(msg.contains("invalid type"), "{msg}");
}

#[test]
fn missing_file_names_the_file() {
    let e = Scene::load(std::path::Path::new("no/such/scene.toml")).unwrap_err();
    assert!(e.to_string().starts_with("no/such/scene.toml: cannot read"), "{e}");
}

#[test]
fn scene_file_round_trips_through_toml() {
    let (sf, scene) = Scene::parse("ok.toml", BASE).unwrap();
    let text = toml::to_string(&sf).unwrap();
    let (sf2, scene2) = Scene::parse("again.toml", &text).unwrap();
    assert_eq!(sf, sf2);
    assert_eq!(scene, scene2);
}
