//! The `lensview` binary as a user runs it.

use std::path::PathBuf;
use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_lensview"))
}

fn tmp(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("cli");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn scene(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes").join(name)
}

#[test]
fn render_writes_a_png_of_the_requested_size() {
    let out = tmp("cubes.png");
    let _ = std::fs::remove_file(&out);
    let o = bin()
        .args([
            "render",
            scene("cubes.toml").to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--width",
            "40",
            "--height",
            "30",
            "--spp",
            "1",
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("rendered 40×30"));
    let img = lensview::render::Image::read_png(&out).unwrap();
    assert_eq!((img.width, img.height), (40, 30));
}

#[test]
fn render_without_a_scene_uses_the_embedded_default() {
    let out = tmp("default.png");
    let o = bin()
        .args(["render", "-o", out.to_str().unwrap(), "--width", "16", "--height", "12"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.exists());
}

#[test]
fn same_image_with_one_and_two_threads() {
    let mut bytes = Vec::new();
    for threads in ["1", "2"] {
        let out = tmp(&format!("threads-{threads}.png"));
        let o = bin()
            .env("RAYON_NUM_THREADS", threads)
            .args([
                "render",
                scene("primitives.toml").to_str().unwrap(),
                "-o",
                out.to_str().unwrap(),
                "--width",
                "64",
                "--height",
                "48",
                "--spp",
                "2",
            ])
            .output()
            .unwrap();
        assert!(o.status.success());
        assert!(String::from_utf8_lossy(&o.stdout).contains(&format!("{threads} threads")));
        bytes.push(std::fs::read(&out).unwrap());
    }
    assert_eq!(bytes[0], bytes[1]);
}

fn fails_with(args: &[&str], want: &str) {
    let o = bin().args(args).output().unwrap();
    assert!(!o.status.success(), "{args:?} succeeded");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(err.trim_end().lines().count(), 1, "not one line: {err}");
    assert!(err.contains(want), "{err} lacks {want}");
}

#[test]
fn bad_input_gives_one_line_and_a_failure_code() {
    let bad = tmp("typo.toml");
    let text = std::fs::read_to_string(scene("cubes.toml")).unwrap();
    std::fs::write(&bad, text.replacen("fov = 45", "fvo = 45", 1)).unwrap();
    let line = text.lines().position(|l| l == "fov = 45").unwrap() + 1;
    fails_with(
        &["render", bad.to_str().unwrap(), "-o", tmp("x.png").to_str().unwrap()],
        &format!("typo.toml:{line}:1: camera.fvo: unknown field `fvo`"),
    );

    std::fs::write(&bad, text.replacen("r1 = 5", "r1 = 0.5", 1)).unwrap();
    fails_with(
        &["render", bad.to_str().unwrap()],
        "lenses[0].r1: radius r1 = 0.5 is smaller than d/2 = 1",
    );

    std::fs::write(&bad, text.replacen("intensity = 500", "intensity = nan", 1)).unwrap();
    fails_with(
        &["render", bad.to_str().unwrap()],
        "lights[0].intensity: NaN is not a finite number",
    );

    fails_with(&["render", "--width", "0"], "--width and --height must be at least 1");
    fails_with(&["render", "no-such-file.toml"], "no-such-file.toml: cannot read");
}

#[test]
fn a_failed_render_leaves_no_file() {
    let out = tmp("not-written.png");
    let _ = std::fs::remove_file(&out);
    let o = bin()
        .args(["render", "missing.toml", "-o", out.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert!(!out.exists());
}
