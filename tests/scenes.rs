//! Every shipped scene loads and renders; bad scene files are rejected with
//! one line naming file, line and field. Input hardening (issue 19): exact
//! array lengths, duplicate keys and tables named with their line, invalid
//! UTF-8 placed, control characters escaped in every message, and input
//! files read with a size cap.

use lensview::render::{RenderSettings, render};
use lensview::scene::{SCENE_FILE_CAP, Scene, SceneError, read_capped};
use std::path::{Path, PathBuf};

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

/// Parses `BASE` with `from` replaced by `to`; returns (line, field,
/// message) of the one-line error ([`placed_error_of`]).
fn error_of(from: &str, to: &str) -> (usize, String, String) {
    let (line, _, field, message) = placed_error_of(from, to);
    (line, field, message)
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

/// A material no object uses is validated all the same (the panel offers
/// every material the file defines), each impossible value named.
#[test]
fn an_unused_material_with_impossible_values_is_refused() {
    let cases = [
        ("reflectivity = 2", "materials.spare.reflectivity"),
        ("ior = 0.9", "materials.spare.ior"),
        ("color = [0.5, nan, 0.5]", "materials.spare.color[1]"),
        ("diffuse = -1", "materials.spare.diffuse"),
        ("reflectivity = 0.7\ntransparency = 0.7", "materials.spare.transparency"),
    ];
    for (body, want) in cases {
        let to = format!("[materials.red]\ncolor = [0.8, 0.1, 0.1]\n\n[materials.spare]\n{body}\n");
        let (line, _, field, _) = placed_error_of("[materials.red]\ncolor = [0.8, 0.1, 0.1]\n", &to);
        assert_eq!(field, want, "{body}");
        assert!(line >= 13, "{body}: line {line}");
    }
}

/// A number out of its type's range (which leaves no document to find the
/// field in) names its field, not `(document)`; a missing `[camera]` is
/// named, not the table that starts the file.
#[test]
fn overflowing_values_and_missing_tables_name_their_fields() {
    let cases = [
        (
            "[camera]",
            "[render]\nspp = 99999999999999999999\n[camera]",
            "render.spp",
        ),
        ("radius = 1", "radius = 1e400", "objects[0].radius"),
        ("position = [0, 1, 5]", "position = [0, 1e999, 5]", "camera.position[1]"),
        (
            "intensity = 100",
            "intensity = 99999999999999999999999",
            "lights[0].intensity",
        ),
        ("d = 1", "d = -1e309", "lenses[0].d"),
    ];
    for (from, to, want) in cases {
        let (_, _, field, message) = placed_error_of(from, to);
        assert_eq!(field, want, "{to}: {message}");
    }
    let no_camera = BASE.replacen(
        "[camera]\nposition = [0, 1, 5]\nlook_at = [0, 0, 0]\n",
        "[render]\nspp = 4\n",
        1,
    );
    assert!(!no_camera.contains("[camera]"), "{no_camera}");
    let (_, _, field, message) = invalid(Scene::parse("bad.toml", &no_camera));
    assert_eq!((field.as_str(), message.as_str()), ("camera", "missing table [camera]"));
}

/// Several numbers out of range in one file (each leaves `toml_edit` no
/// document), integers and floats, decimal and hexadecimal, in tables,
/// arrays and inline objects, beside a key made of digits: the error names
/// the field of the one reported, never `(document)`.
#[test]
fn several_numbers_out_of_range_still_name_their_field() {
    let huge = "99999999999999999999999";
    let cases: [(&str, String, &[&str]); 4] = [
        (
            "intensity = 100",
            format!("intensity = {huge}\ncolor = [1, -{huge}, 1e999]"),
            &["lights[0].intensity", "lights[0].color[1]", "lights[0].color[2]"],
        ),
        (
            "[camera]",
            "[render]\nspp = 0x1_0000_0000_0000_0000\nbackground = [0, 0, 1e400]\n[camera]".to_string(),
            &["render.spp", "render.background[2]"],
        ),
        (
            "[materials.red]",
            format!("[materials.12345678901234567890123]\nshininess = {huge}\nspecular = {huge}\n[materials.red]"),
            &[
                "materials.12345678901234567890123.shininess",
                "materials.12345678901234567890123.specular",
            ],
        ),
        (
            "[[objects]]",
            format!(
                "objects = [{{type = \"sphere\", radius = {huge}}}, {{type = \"sphere\", radius = {huge}}}]\n[[objects]]"
            ),
            &["objects[0].radius", "objects[1].radius"],
        ),
    ];
    for (from, to, want) in cases {
        // The inline objects go first: a root key cannot follow a table.
        let text = match to.strip_suffix("[[objects]]") {
            Some(inline) if to.starts_with("objects") => format!(
                "{inline}{}",
                BASE.replacen(
                    "[[objects]]\ntype = \"sphere\"\nradius = 1\nmaterial = \"red\"\n",
                    "",
                    1
                )
            ),
            _ => BASE.replacen(from, &to, 1),
        };
        assert_ne!(text, BASE, "{from}");
        let (_, _, field, message) = invalid(Scene::parse("bad.toml", &text));
        assert!(want.contains(&field.as_str()), "{to}: {field}: {message}");
    }
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

/// The error for `BASE` with `from` replaced by `to`: (line, column,
/// field, message), after checking that its text is one line that starts
/// with `bad.toml:line:column: field: `.
fn placed_error_of(from: &str, to: &str) -> (usize, usize, String, String) {
    assert!(BASE.contains(from), "{from}");
    invalid(Scene::parse("bad.toml", &BASE.replacen(from, to, 1)))
}

fn invalid<T>(r: Result<T, SceneError>) -> (usize, usize, String, String) {
    let e = match r {
        Ok(_) => panic!("accepted a bad scene"),
        Err(e) => e,
    };
    let shown = e.to_string();
    assert!(!shown.contains('\n'), "not one line: {shown}");
    match e {
        SceneError::Invalid {
            line,
            column,
            field,
            message,
            ..
        } => {
            let head = format!("bad.toml:{line}:{column}: {field}: ");
            assert!(shown.starts_with(&head), "{shown}");
            (line, column, field, message)
        }
        e => panic!("{e}"),
    }
}

#[test]
fn arrays_of_the_wrong_length_are_refused() {
    Scene::parse("ok.toml", BASE).unwrap();
    let (line, _, field, msg) = placed_error_of("position = [0, 1, 5]", "position = [0, 1, 6, 7]");
    assert_eq!((line, field.as_str()), (3, "camera.position"));
    assert_eq!(msg, "invalid length 4, expected an array of 3 numbers");
    let (_, _, field, msg) = placed_error_of("position = [0, 1, 5]", "position = [0, 1]");
    assert_eq!(field, "camera.position");
    assert_eq!(msg, "invalid length 2, expected an array of 3 numbers");
    let (line, _, field, msg) = placed_error_of("color = [0.8, 0.1, 0.1]", "color = [0.8, 0.1, 0.1, 1]");
    assert_eq!((line, field.as_str()), (11, "materials.red.color"));
    assert!(msg.contains("invalid length 4"), "{msg}");
    let (line, _, field, msg) = placed_error_of("n = 1.5", "n = { cauchy = [1.5, 0.004, 7] }");
    assert_eq!((line, field.as_str()), (23, "lenses[0].n.cauchy"));
    assert_eq!(msg, "invalid length 3, expected an array of 2 numbers");
    Scene::parse("ok.toml", &BASE.replacen("n = 1.5", "n = { cauchy = [1.5, 0.004] }", 1)).unwrap();
    // Every array of three: an optional one, one with a default, a lens's.
    for (from, to, at) in [
        ("look_at = [0, 0, 0]", "look_at = [0, 0, 0, 0]", "camera.look_at"),
        (
            "radius = 1",
            "radius = 1\nrotation = [1, 2, 3, 4]",
            "objects[0].rotation",
        ),
        ("center = [0, 0, 3]", "center = [0, 0, 3, 0]", "lenses[0].center"),
        ("d = 1", "d = 1\ntint = [1, 1, 1, 1]", "lenses[0].tint"),
        (
            "intensity = 100",
            "intensity = 100\ncolor = [1, 1, 1, 1, 1]",
            "lights[0].color",
        ),
    ] {
        assert_eq!(placed_error_of(from, to).2, at, "{to}");
    }
}

#[test]
fn duplicate_keys_and_tables_are_named_with_their_lines() {
    let (line, col, field, msg) = placed_error_of("radius = 1", "radius = 1\nradius = 2");
    assert_eq!((line, col, field.as_str()), (16, 1, "objects[0].radius"));
    assert_eq!(msg, "duplicate key `radius`, first given on line 15");
    let (line, _, field, msg) = placed_error_of("[[lenses]]", "[camera]\nfov = 30\n\n[[lenses]]");
    assert_eq!((line, field.as_str()), (18, "camera"));
    assert_eq!(msg, "duplicate table `camera`, first given on line 2");
    let (line, _, field, msg) = placed_error_of("[[objects]]", "[materials.red]\n\n[[objects]]");
    assert_eq!((line, field.as_str()), (13, "materials.red"));
    assert!(msg.starts_with("duplicate table `red`"), "{msg}");
    // In the second of two [[lenses]], and in an inline table.
    let two = "[[lenses]]\ncenter = [0, 0, 9]\nd = 1\nr1 = 2\nr2 = 2\nn = 1.5\nd = 3\n\n[[lenses]]";
    let (line, _, field, _) = placed_error_of("[[lenses]]", two);
    assert_eq!((line, field.as_str()), (24, "lenses[0].d"));
    let (_, _, field, _) = placed_error_of("n = 1.5", "n = { cauchy = [1.5, 0], cauchy = [1.6, 0] }");
    assert_eq!(field, "lenses[0].n.cauchy");
}

#[test]
fn invalid_utf8_is_placed_at_its_first_bad_byte() {
    let mut bytes = BASE.replacen("material = \"red\"", "name = \"caf\u{e9}!\"\nmaterial = \"red\"", 1);
    bytes.insert_str(0, "# comment\n");
    let mut bytes = bytes.into_bytes();
    // "é" is 0xc3 0xa9; 0xe9 alone (Latin-1) is not UTF-8.
    let at = bytes.windows(2).position(|w| w == [0xc3, 0xa9]).unwrap();
    bytes.splice(at..at + 2, [0xe9]);
    let (line, col, field, msg) = invalid(Scene::from_bytes("bad.toml", &bytes));
    assert_eq!((line, col), (17, 12));
    assert_eq!(field, "objects[0].name");
    assert!(msg.starts_with("invalid UTF-8 (byte 0xe9)"), "{msg}");
    // A truncated sequence at the very end.
    let mut cut = BASE.as_bytes().to_vec();
    cut.push(0xc3);
    let (line, col, _, msg) = invalid(Scene::from_bytes("bad.toml", &cut));
    assert_eq!((line, col), (24, 1));
    assert!(msg.contains("0xc3"), "{msg}");
}

#[test]
fn control_characters_are_escaped_in_every_message() {
    let esc = |s: &str| {
        assert!(!s.chars().any(|c| c.is_control()), "raw control character in {s:?}");
        assert!(s.contains("\\u{1b}"), "{s}");
    };
    // A validation message quoting a name.
    let r = Scene::parse("bad.toml", &BASE.replacen("\"red\"\n", "\"\\u001b[2J\"\n", 1));
    esc(&r.unwrap_err().to_string());
    // A field path with a quoted key, from the parser.
    let r = Scene::parse(
        "bad.toml",
        &BASE.replacen("color = [0.8", "\"\\u001b]0;x\\u0007\" = 1\ncolor = [0.8", 1),
    );
    let e = r.unwrap_err().to_string();
    esc(&e);
    assert!(e.contains("\\u{7}"), "{e}");
    // A C1 control and DEL in a duplicate key, and the file's own name.
    let text = BASE.replacen("radius = 1", "\"a\\u009b\\u007f\" = 1\n\"a\\u009b\\u007f\" = 2", 1);
    let e = Scene::parse("bad\u{1b}[2J.toml", &text).unwrap_err().to_string();
    esc(&e);
    assert!(e.contains("\\u{9b}\\u{7f}"), "{e}");
    let e = Scene::load(Path::new("no/such/\u{1b}[2J.toml"))
        .unwrap_err()
        .to_string();
    esc(&e);
}

fn scratch(name: &str) -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("scenes-{name}"))
}

#[test]
fn input_files_are_read_with_a_size_cap() {
    let path = scratch("cap.toml");
    std::fs::write(&path, b"12345").unwrap();
    assert_eq!(read_capped(&path, 5).unwrap(), b"12345");
    let e = read_capped(&path, 4).unwrap_err();
    assert!(matches!(e, SceneError::TooLarge { cap: 4, .. }), "{e}");
    assert_eq!(
        e.to_string(),
        format!(
            "{}: not read: larger than the 4 bytes limit for this input",
            path.display()
        )
    );
    // A scene file over 128 MiB is refused before it is read.
    let big = scratch("big.toml");
    let f = std::fs::File::create(&big).unwrap();
    f.set_len(SCENE_FILE_CAP + 1).unwrap();
    let e = Scene::load(&big).unwrap_err().to_string();
    assert!(
        e.starts_with(&big.display().to_string()) && e.ends_with("larger than the 128 MiB limit for this input"),
        "{e}"
    );
    std::fs::remove_file(&big).unwrap();
    // A device is not read at all (issue 30.2: only regular files).
    if Path::new("/dev/zero").exists() {
        let t = std::time::Instant::now();
        let e = Scene::load(Path::new("/dev/zero")).unwrap_err().to_string();
        assert_eq!(
            e,
            "/dev/zero: cannot read: it is a character device, not a regular file (only regular files are read)"
        );
        assert!(t.elapsed().as_secs() < 10, "{:?}", t.elapsed());
    }
    // A directory is an I/O error naming it.
    let e = Scene::load(Path::new(env!("CARGO_TARGET_TMPDIR")))
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with(&format!("{}: cannot read", env!("CARGO_TARGET_TMPDIR"))),
        "{e}"
    );
}

/// The supported domain (`lensview::math::domain`, README "Scene file
/// format"): just outside each bound a one-line refusal naming the field;
/// at the bound itself an accepted scene that renders a correct picture.
#[test]
fn values_outside_the_supported_domain_are_refused() {
    for (from, to, field, says) in [
        (
            "n = 1.5",
            "n = 1e78",
            "lenses[0].n",
            "outside the supported range [1, 10]",
        ),
        (
            "n = 1.5",
            "n = 10.001",
            "lenses[0].n",
            "outside the supported range [1, 10]",
        ),
        (
            "d = 1\nr1 = 2\nr2 = 2",
            "d = 1e300\nr1 = 1e300\nr2 = 1e300",
            "lenses[0].d",
            "outside the supported lengths",
        ),
        ("r1 = 2", "r1 = 1e308", "lenses[0].r1", "above the supported 1e9"),
        (
            "center = [0, 0, 3]",
            "center = [0, 0, 1.1e9]",
            "lenses[0].center",
            "outside the supported range",
        ),
        (
            "radius = 1",
            "radius = 1e155",
            "objects[0].radius",
            "outside the supported lengths",
        ),
        (
            "radius = 1",
            "radius = 1e-10",
            "objects[0].radius",
            "outside the supported lengths",
        ),
        (
            "radius = 1",
            "radius = 1e-3\nposition = [0, 0, 1e5]",
            "objects[0].radius",
            "smaller than 1e-7 of the distance",
        ),
        (
            "position = [0, 1, 5]",
            "position = [0, 1, -2e9]",
            "camera.position[2]",
            "outside the supported range",
        ),
        (
            "position = [1, 4, 2]",
            "position = [1, 4e9, 2]",
            "lights[0].position[1]",
            "outside the supported range",
        ),
        (
            "intensity = 100",
            "intensity = 1e308",
            "lights[0].intensity",
            "1e308 is above the supported 1e12",
        ),
        (
            "intensity = 100",
            "intensity = 1\ncolor = [1e300, 1, 1]",
            "lights[0].color[0]",
            "1e300 is above the supported 1e3",
        ),
        (
            "color = [0.8, 0.1, 0.1]",
            "color = [0.8, 1001, 0.1]",
            "materials.red.color[1]",
            "above the supported 1e3",
        ),
        (
            "color = [0.8, 0.1, 0.1]",
            "color = [0.8, 0.1, 0.1]\ndiffuse = 1e4",
            "materials.red.diffuse",
            "above the supported 1e3",
        ),
        (
            "position = [0, 1, 5]",
            "position = [0, 1, 0]",
            "camera.position",
            "lies on the surface of `sphere 1`",
        ),
    ] {
        let (_, got_field, msg) = error_of(from, to);
        assert_eq!(got_field, field, "{to}: {msg}");
        assert!(msg.contains(says) && !msg.contains('\n'), "{to}: {msg}");
    }
}

fn render_small(text: &str) -> Vec<glam::DVec3> {
    let (_, scene) = Scene::parse("edge.toml", text).unwrap_or_else(|e| panic!("{e}"));
    let settings = RenderSettings {
        width: 16,
        height: 12,
        spp: 1,
        seed: 0,
    };
    render(&scene, &settings, None).pixels
}

#[test]
fn scenes_at_the_edges_of_the_supported_domain_render_correctly() {
    // A sphere of the largest radius around the camera is seen in every
    // pixel (at 1e155 it used to vanish), lit by its ambient term.
    let inside = BASE.replace("radius = 1", "radius = 1e9");
    let px = render_small(&inside);
    assert!(
        px.iter().all(|c| c.is_finite() && c.x > 0.0 && c.x > 4.0 * c.y),
        "{px:?}"
    );
    // The brightest light on a material with diffuse 0: finite, not black
    // (colour 1e300 × intensity 1e308 gave ∞·0 = NaN, a black object).
    let bright = BASE
        .replace("intensity = 100", "intensity = 1e12\ncolor = [1e3, 1e3, 1e3]")
        .replace(
            "color = [0.8, 0.1, 0.1]",
            "color = [0.8, 0.1, 0.1]\ndiffuse = 0\nspecular = 1e3",
        );
    let px = render_small(&bright);
    assert!(px.iter().all(|c| c.is_finite()), "{px:?}");
    let centre = px[6 * 16 + 8];
    assert!(centre.x > 0.0, "{centre}");
    // The camera just off the sphere (5 offsets) is accepted and sees the
    // same inside everywhere: no speckle of false hits.
    let off = BASE.replace("position = [0, 1, 5]", "position = [0, 0.999999, 0]");
    let px = render_small(&off);
    assert!(
        px.iter()
            .all(|c| (*c - px[0]).abs().max_element() < 0.5 * px[0].max_element()),
        "{px:?}"
    );
}

/// A catalogue glass by name (issue 31): a lens and a material take
/// `"N-BK7"`, render with its dispersion and write the name back; an
/// unknown name is one line naming the field and the known glasses.
#[test]
fn glass_names_are_read_rendered_and_refused_by_field() {
    let text = BASE.replace("n = 1.5", "n = \"N-BK7\"").replace(
        "color = [0.8, 0.1, 0.1]",
        "color = [0.8, 0.1, 0.1]\ntransparency = 0.5\nior = \"n-sf11\"",
    );
    let (sf, scene) = Scene::parse("glass.toml", &text).unwrap_or_else(|e| panic!("{e}"));
    let bk7 = lensview::glass::lookup("N-BK7").unwrap();
    assert_eq!(sf.lenses[0].n, lensview::scene::file::IndexFile::Glass(bk7));
    let saved = toml::to_string(&sf).unwrap();
    assert!(
        saved.contains("n = \"N-BK7\"") && saved.contains("ior = \"N-SF11\""),
        "{saved}"
    );
    assert_eq!(Scene::parse("again.toml", &saved).unwrap().1, scene);
    let px = render_small(&text);
    assert!(px.iter().all(|c| c.is_finite()) && px.iter().any(|c| c.x > 0.0));

    let (line, field, msg) = error_of("n = 1.5", "n = \"XYZ\"");
    assert_eq!((line, field.as_str()), (23, "lenses[0].n"));
    assert!(
        msg.contains("unknown glass \"XYZ\"") && msg.contains("N-BK7, ") && msg.contains("F_SILICA"),
        "{msg}"
    );
    // BK7 (the old melt) is not N-BK7.
    assert_eq!(error_of("n = 1.5", "n = \"BK7\"").1, "lenses[0].n");
    let (_, field, msg) = error_of("color = [0.8, 0.1, 0.1]", "color = [0.8, 0.1, 0.1]\nior = \"XYZ\"");
    assert_eq!(field, "materials.red.ior");
    assert!(msg.contains("unknown glass"), "{msg}");
}
