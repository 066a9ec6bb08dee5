//! `lensview film` (issue #35): a flight rendered into frames, each the
//! still `render` makes of the scene at that camera; resumable; split into
//! ranges that join to the whole; bad input refused in one line.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_lensview"))
}

fn tmp(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("film").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn scene() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/cubes.toml")
}

const FLIGHT: &str = "version = 1

[[poses]]
t = 0
position = [0, 1.2, 6]
rotation = [-5, 0, 0]

[[poses]]
t = 1.0
position = [1.5, 1.2, 4]
rotation = [-5, 20, 0]

[[poses]]
t = 2.0
position = [2.5, 1.5, 2]
rotation = [-10, 40, 0]
fov = 50
";

fn film(dir: &Path, flight: &Path, extra: &[&str]) -> Output {
    bin()
        .arg("film")
        .arg(scene())
        .arg(flight)
        .arg("-o")
        .arg(dir)
        .args(
            [
                ("--fps", "4"),
                ("--width", "48"),
                ("--height", "32"),
                ("--spp", "2"),
                ("--encode", "none"),
            ]
            .into_iter()
            .filter(|(flag, _)| !extra.contains(flag))
            .flat_map(|(flag, v)| [flag, v]),
        )
        .args(extra)
        .output()
        .unwrap()
}

fn ok(o: &Output) -> String {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn frames(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "png"))
        .map(|p| {
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                std::fs::read(&p).unwrap(),
            )
        })
        .collect();
    v.sort();
    v
}

/// A frame at a recorded pose is, byte for byte, the still `render` makes
/// with that camera in the scene file.
#[test]
fn a_frame_at_a_pose_is_the_still_of_that_camera() {
    let dir = tmp("still");
    let flight = dir.join("flight.toml");
    std::fs::write(&flight, FLIGHT).unwrap();
    let frames_dir = dir.join("frames");
    let out = ok(&film(&frames_dir, &flight, &[]));
    assert!(
        out.contains("filmed frames 0..9 of 9 (9 rendered, 0 already there)"),
        "{out}"
    );
    let text = std::fs::read_to_string(scene()).unwrap();
    for (frame, position, rotation, fov) in [
        (4, "[1.5, 1.2, 4]", "[-5, 20, 0]", None),
        (8, "[2.5, 1.5, 2]", "[-10, 40, 0]", Some(50)),
    ] {
        // The scene with its camera replaced by the pose's.
        let start = text.find("[camera]").unwrap();
        let end = text[start + 1..].find("\n[").map_or(text.len(), |e| start + 1 + e);
        let fov = fov.map_or(String::new(), |f| format!("fov = {f}\n"));
        let camera = format!("[camera]\nposition = {position}\nrotation = {rotation}\n{fov}");
        let old_fov = text[start..end].lines().find(|l| l.starts_with("fov")).unwrap_or("");
        let camera = if fov.is_empty() {
            format!("{camera}{old_fov}\n")
        } else {
            camera
        };
        let still_scene = dir.join(format!("still-{frame}.toml"));
        std::fs::write(&still_scene, format!("{}{camera}{}", &text[..start], &text[end..])).unwrap();
        let still = dir.join(format!("still-{frame}.png"));
        let o = bin()
            .arg("render")
            .arg(&still_scene)
            .args(["--width", "48", "--height", "32", "--spp", "2", "-o"])
            .arg(&still)
            .output()
            .unwrap();
        ok(&o);
        let got = std::fs::read(frames_dir.join(format!("frame-{frame:06}.png"))).unwrap();
        assert!(
            got == std::fs::read(&still).unwrap(),
            "frame {frame} differs from the still"
        );
    }
    // Frames between poses differ from their neighbours (the camera moves).
    let f = frames(&frames_dir);
    assert_eq!(f.len(), 9);
    assert!(f.windows(2).all(|w| w[0].1 != w[1].1));
}

/// A film stopped half way resumes: frames on disk are kept, the missing
/// ones rendered, and the result is the film made in one go; ranges made
/// apart join to the whole.
#[test]
fn films_resume_and_ranges_join() {
    let dir = tmp("resume");
    let flight = dir.join("flight.toml");
    std::fs::write(&flight, FLIGHT).unwrap();
    let whole = dir.join("whole");
    ok(&film(&whole, &flight, &[]));
    let reference = frames(&whole);
    std::fs::remove_file(whole.join("frame-000003.png")).unwrap();
    std::fs::remove_file(whole.join("frame-000007.png")).unwrap();
    let out = ok(&film(&whole, &flight, &[]));
    assert!(out.contains("(2 rendered, 7 already there)"), "{out}");
    assert_eq!(frames(&whole), reference);
    let split = dir.join("split");
    for r in ["0..3", "6..9", "3..6"] {
        ok(&film(&split, &flight, &["--frames", r]));
    }
    assert_eq!(frames(&split), reference);
}

#[test]
fn bad_input_is_refused_in_one_line() {
    let dir = tmp("bad");
    let flight = dir.join("flight.toml");
    std::fs::write(&flight, FLIGHT).unwrap();
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, FLIGHT.replace("t = 1.0", "t = 3.0")).unwrap();
    let file = dir.join("a-file");
    std::fs::write(&file, "x").unwrap();
    let cases: Vec<(PathBuf, PathBuf, Vec<&str>, &str)> = vec![
        (
            bad.clone(),
            dir.join("o1"),
            vec![],
            "bad.toml:14:5: poses[2].t: time 2 does not follow",
        ),
        (
            flight.clone(),
            dir.join("o2"),
            vec!["--frames", "5..3"],
            "--frames 5..3",
        ),
        (flight.clone(), dir.join("o3"), vec!["--frames", "0..10"], "frames 0..9"),
        (flight.clone(), dir.join("o4"), vec!["--fps", "0"], "--fps 0: must be"),
        (flight.clone(), file.clone(), vec![], "is not a folder"),
        (dir.join("missing.toml"), dir.join("o5"), vec![], "missing.toml"),
        (flight.clone(), dir.join("o6"), vec!["--encode", "avi"], "--encode avi"),
    ];
    for (fl, out, extra, want) in cases {
        let o = film(&out, &fl, &extra);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{want}: {err}");
        assert!(err.contains(want), "{want}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    }
    assert_eq!(std::fs::read(&file).unwrap(), b"x");
}

/// `--trim A..B --speed S` films the part of the flight from A to B at S
/// times the speed: its first and last frames are the frames of the whole
/// film at A and B, byte for byte.
#[test]
fn a_trimmed_film_is_the_part_of_the_whole() {
    let dir = tmp("trim");
    let flight = dir.join("flight.toml");
    std::fs::write(&flight, FLIGHT).unwrap();
    let whole = dir.join("whole");
    ok(&film(&whole, &flight, &[]));
    let part = dir.join("part");
    let out = ok(&film(&part, &flight, &["--trim", "0.5..1.5", "--speed", "0.5"]));
    assert!(out.contains("filmed frames 0..9 of 9"), "{out}");
    let (w, p) = (frames(&whole), frames(&part));
    assert_eq!(p[0].1, w[2].1, "the first frame is the whole film's at 0.5 s");
    assert_eq!(p[8].1, w[6].1, "the last frame is the whole film's at 1.5 s");
    let o = film(&dir.join("bad"), &flight, &["--trim", "1..5"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("the flight is 0..2 s"));
}

/// With ffmpeg installed (`.ci/run` installs it), a whole film is encoded
/// into `film.mp4` with one picture a frame, odd sizes included; a partial
/// range is not encoded.
#[test]
fn a_whole_film_is_encoded_with_ffmpeg() {
    let dir = tmp("encode");
    let flight = dir.join("flight.toml");
    std::fs::write(&flight, FLIGHT).unwrap();
    let out = dir.join("film");
    ok(&film(&out, &flight, &["--frames", "0..4", "--encode", "mp4"]));
    assert!(!out.join("film.mp4").exists(), "a part is not encoded");
    let said = ok(&film(&out, &flight, &["--encode", "mp4"]));
    assert!(said.contains("encoded"), "{said}");
    // Another film's settings in the same folder are refused.
    let o = film(&out, &flight, &["--width", "47"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("holds frames of another film") && err.contains("48x32"),
        "{err}"
    );
    // An odd width is padded for 4:2:0.
    let odd = dir.join("odd");
    ok(&film(&odd, &flight, &["--width", "47", "--encode", "mp4"]));
    let probe = Command::new("ffprobe")
        .args([
            "-v",
            "error",
            "-count_frames",
            "-show_entries",
            "stream=codec_name,nb_read_frames,width",
        ])
        .args(["-of", "csv=p=0"])
        .arg(odd.join("film.mp4"))
        .output()
        .expect("ffprobe (ffmpeg) is installed");
    let text = String::from_utf8_lossy(&probe.stdout);
    assert_eq!(text.trim(), "h264,48,9", "{text}");
    assert!(out.join("film.mp4").is_file());
    assert!(!out.join("film.part.mp4").exists());
}
