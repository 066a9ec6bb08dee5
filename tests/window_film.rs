//! Issue #35, item 1, in the real window under Xvfb: F8 records the flight
//! (the camera's poses and an edit made meanwhile) into a file beside the
//! scene; `--play` flies it again; `lensview film` renders it. Needs what
//! tests/window.rs needs (`.ci/run` installs it).

use lensview::flight::Flight;
use std::path::PathBuf;
use std::process::Command;
use std::time::Duration;

mod window_support;
use window_support::*;

fn position(f: &serde_json::Value) -> [f64; 3] {
    [0, 1, 2].map(|i| f["camera"][0][i].as_f64().unwrap())
}

#[test]
fn f8_records_a_flight_that_plays_back_and_films() {
    let _one = one_at_a_time();
    let x = Xvfb::start();
    let (dir, _) = test_dir("record-flight");
    // The scene in the test's folder: the flight is written beside it.
    let scene = dir.join("cubes.toml");
    let original =
        std::fs::read_to_string(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/cubes.toml")).unwrap();
    std::fs::write(&scene, &original).unwrap();
    let flight_path = dir.join("cubes-flight-1.toml");
    let _ = std::fs::remove_file(&flight_path);
    let args = [
        "--no-panel",
        "--width",
        "480",
        "--height",
        "270",
        "--max-spp",
        "2",
        "--exit-after",
        "600",
    ];
    {
        let s = Session::launch(&x, &dir, &scene, &args, dir.join("record.jsonl"));
        s.wait_frame(0, 2, "start");
        s.xdotool(&["windowfocus", "--sync", &s.window]);
        s.key("F8");
        std::thread::sleep(Duration::from_millis(300));
        s.hold("w", 1200);
        s.key("l");
        std::thread::sleep(Duration::from_millis(500));
        s.key("F8");
        assert!(
            wait_until(Duration::from_secs(30), || flight_path.is_file()),
            "F8 wrote no flight beside the scene"
        );
    }
    let text = std::fs::read_to_string(&flight_path).unwrap();
    let flight = Flight::parse("flight", &text).expect("the recorded flight reads back");
    let poses = &flight.file.poses;
    assert!(poses.len() >= 5, "{} poses", poses.len());
    let (first, last) = (poses[0].position, poses[poses.len() - 1].position);
    assert!(last[2] < first[2] - 0.5, "W flew forward (−z): {first:?} → {last:?}");
    assert!(flight.duration() > 1.5, "{}", flight.duration());
    assert_eq!(flight.file.edits.len(), 1, "the light's move is one edit");
    let (edited, _) = lensview::scene::Scene::parse("edit", &flight.file.edits[0].scene).unwrap();
    let (before, _) = lensview::scene::Scene::parse("scene", &original).unwrap();
    assert_ne!(edited.lights, before.lights, "the edit holds the moved light");

    // Played back, the camera flies to the flight's last pose.
    {
        let play = ["--play", flight_path.to_str().unwrap()];
        let all: Vec<&str> = args.iter().copied().chain(play).collect();
        let s = Session::launch(&x, &dir, &scene, &all, dir.join("play.jsonl"));
        let reached = wait_until(Duration::from_secs(60), || {
            s.frames().iter().any(|f| {
                let p = position(f);
                (0..3).all(|i| (p[i] - last[i]).abs() < 1e-9)
            })
        });
        let seen: Vec<[f64; 3]> = s.frames().iter().map(position).collect();
        assert!(reached, "playback never showed the last pose {last:?}: {seen:?}");
        let distinct: std::collections::BTreeSet<String> = seen.iter().map(|p| format!("{p:?}")).collect();
        assert!(distinct.len() >= 3, "playback showed {} poses", distinct.len());
    }

    // And it films.
    let frames = dir.join("frames");
    let o = Command::new(env!("CARGO_BIN_EXE_lensview"))
        .arg("film")
        .arg(&scene)
        .arg(&flight_path)
        .arg("-o")
        .arg(&frames)
        .args([
            "--fps", "5", "--width", "32", "--height", "18", "--spp", "1", "--encode", "none",
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let n = std::fs::read_dir(&frames)
        .unwrap()
        .filter(|e| e.as_ref().unwrap().file_name().to_string_lossy().starts_with("frame-"))
        .count();
    assert_eq!(n as u64, (flight.duration() * 5.0 + 1e-9).floor() as u64 + 1);
}
