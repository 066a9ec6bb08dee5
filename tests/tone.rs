//! Exposure and tone curve (`[display]`, `render --exposure/--tone`): the
//! PNG is toned, the EXR stays linear, the default changes nothing, and bad
//! values are refused with a line naming the file, line and field.

use lensview::render::Image;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn tmp(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("tone");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn scene(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes").join(name)
}

/// `lensview render SCENE -o OUT` at 40×30, 2 spp, with `extra` flags.
fn render(scene: &Path, out: &Path, extra: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lensview"))
        .arg("render")
        .arg(scene)
        .arg("-o")
        .arg(out)
        .args(["--width", "40", "--height", "30", "--spp", "2"])
        .args(extra)
        .output()
        .unwrap()
}

fn ok(o: &Output) {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

fn refused(o: &Output, want: &str) {
    assert!(!o.status.success(), "succeeded");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(err.trim_end().lines().count(), 1, "not one line: {err}");
    assert!(err.contains(want), "{err} lacks {want}");
}

fn bytes(p: &Path) -> Vec<u8> {
    std::fs::read(p).unwrap()
}

/// The focal spot clips to white two stops up, a tone curve brings it
/// back under white, three stops down darken it, and the scene's
/// `[display]` keys do what the flags do.
#[test]
fn exposure_and_tone_change_the_png_and_the_default_changes_nothing() {
    let spot = scene("focal-spot.toml");
    let plain = tmp("plain.png");
    ok(&render(&spot, &plain, &[]));
    let same = tmp("same.png");
    ok(&render(&spot, &same, &["--exposure", "0", "--tone", "clamp"]));
    assert_eq!(bytes(&plain), bytes(&same), "the default tone is not the identity");

    let white = |p: &Path| {
        let img = Image::read_png(p).unwrap();
        img.to_srgb8().chunks(3).filter(|c| c.iter().all(|&v| v == 255)).count()
    };
    let brightest = |p: &Path| Image::read_png(p).unwrap().to_srgb8().into_iter().max().unwrap();
    // Two stops up, the focal spot clips to white; Reinhard rolls it off.
    let up = tmp("up.png");
    ok(&render(&spot, &up, &["--exposure", "2"]));
    assert!(white(&up) > white(&plain), "{} ≤ {}", white(&up), white(&plain));
    let reinhard = tmp("reinhard.png");
    ok(&render(&spot, &reinhard, &["--exposure", "2", "--tone", "reinhard"]));
    assert_eq!(white(&reinhard), 0);
    let aces = tmp("aces.png");
    ok(&render(&spot, &aces, &["--exposure", "2", "--tone", "aces"]));
    assert!(white(&aces) < white(&up), "{} ≥ {}", white(&aces), white(&up));
    let down = tmp("down.png");
    ok(&render(&spot, &down, &["--exposure", "-3"]));
    assert!(brightest(&down) < brightest(&plain));

    // The scene's keys do what the flags do.
    let text = std::fs::read_to_string(&spot).unwrap();
    let keyed = tmp("keyed.toml");
    std::fs::write(&keyed, format!("{text}\n[display]\nexposure = -3.0\n")).unwrap();
    let by_key = tmp("by-key.png");
    ok(&render(&keyed, &by_key, &[]));
    assert_eq!(bytes(&by_key), bytes(&down));
    // A flag overrides the scene.
    let back = tmp("back.png");
    ok(&render(&keyed, &back, &["--exposure", "0"]));
    assert_eq!(bytes(&back), bytes(&plain));
}

/// The EXR is the radiance, whatever the scene's tone; tone flags with an
/// EXR are refused rather than ignored.
#[test]
fn the_exr_stays_linear() {
    let spot = scene("focal-spot.toml");
    let text = std::fs::read_to_string(&spot).unwrap();
    let keyed = tmp("toned.toml");
    std::fs::write(&keyed, format!("{text}\n[display]\nexposure = 2.5\ntone = \"aces\"\n")).unwrap();
    let (a, b) = (tmp("plain.exr"), tmp("toned.exr"));
    ok(&render(&spot, &a, &[]));
    ok(&render(&keyed, &b, &[]));
    assert_eq!(bytes(&a), bytes(&b));
    refused(&render(&spot, &a, &["--exposure", "1"]), "an EXR is linear radiance");
}

#[test]
fn bad_tone_values_are_refused_with_file_line_and_field() {
    let text = std::fs::read_to_string(scene("cubes.toml")).unwrap();
    let bad = tmp("bad-exposure.toml");
    let line = text.lines().count() + 3;
    std::fs::write(&bad, format!("{text}\n[display]\nexposure = 99.0\n")).unwrap();
    refused(
        &render(&bad, &tmp("x.png"), &[]),
        &format!("bad-exposure.toml:{line}:1: display.exposure: 99 stops is not in -20..=20"),
    );
    let bad = tmp("bad-tone.toml");
    std::fs::write(&bad, format!("{text}\n[display]\ntone = \"sepia\"\n")).unwrap();
    refused(&render(&bad, &tmp("x.png"), &[]), &format!("bad-tone.toml:{line}:"));
    refused(&render(&bad, &tmp("x.png"), &[]), "display.tone");
    refused(
        &render(&scene("cubes.toml"), &tmp("x.png"), &["--tone", "sepia"]),
        "unknown tone curve 'sepia'",
    );
    refused(
        &render(&scene("cubes.toml"), &tmp("x.png"), &["--exposure", "-21"]),
        "--exposure -21: not in -20..=20 stops",
    );
}
