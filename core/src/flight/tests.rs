use super::*;
use crate::sampling::{mix64, unit_f64};

fn pose(t: f64, position: [f64; 3], rotation: [f64; 3]) -> PoseKey {
    PoseKey {
        t,
        position,
        rotation,
        fov: None,
    }
}

fn flight(poses: Vec<PoseKey>) -> Flight {
    Flight {
        file: FlightFile {
            version: FLIGHT_VERSION,
            scene: None,
            poses,
            edits: vec![],
        },
    }
}

/// The quaternion of the camera's angles is the camera's rotation, and
/// back: angles from all over the sphere (pitch within ±89°, as flown).
#[test]
fn angles_quaternions_and_matrices_agree() {
    for i in 0..2000u64 {
        let r = |k: u64| unit_f64(mix64(i * 3 + k));
        let a = [178.0 * r(0) - 89.0, 720.0 * r(1) - 360.0, 360.0 * r(2) - 180.0];
        let m = rotation_from_degrees(v(a));
        let q = glam::DMat3::from_quat(quat(a));
        assert!((m - q).abs_diff_eq(glam::DMat3::ZERO, 1e-13), "{a:?}");
        let back = rotation_from_degrees(degrees(quat(a)));
        assert!((m - back).abs_diff_eq(glam::DMat3::ZERO, 1e-12), "{a:?}");
    }
}

/// Every recorded pose is passed exactly; a straight flight at constant
/// speed stays straight and keeps its speed between keys (the tangents are
/// the neighbours' differences over time, whatever the spacing).
#[test]
fn the_path_passes_the_keys_and_keeps_a_line_straight() {
    let times = [0.0, 0.1, 0.35, 0.4, 1.0, 2.5];
    let f = flight(
        times
            .iter()
            .map(|&t| pose(t, [2.0 * t, 1.0, -3.0 * t], [0.0, 0.0, 0.0]))
            .collect(),
    );
    for k in &f.file.poses {
        assert_eq!(f.pose_at(k.t).position, v(k.position));
    }
    for i in 0..=250 {
        let t = 0.01 * i as f64;
        let p = f.pose_at(t).position;
        let want = DVec3::new(2.0 * t, 1.0, -3.0 * t);
        assert!((p - want).length() < 1e-12, "t {t}: {p} against {want}");
    }
    assert_eq!(f.pose_at(-1.0).position, v(f.file.poses[0].position));
    assert_eq!(f.pose_at(9.0).position, DVec3::new(5.0, 1.0, -7.5));
}

/// Turning from yaw 0 to yaw 90 passes yaw 45 half way, at constant
/// angular speed, and never by the long way round (350 to 10 goes through
/// 0).
#[test]
fn the_turn_is_a_slerp_on_the_shorter_arc() {
    let f = flight(vec![
        pose(0.0, [0.0; 3], [0.0, 0.0, 0.0]),
        pose(1.0, [0.0; 3], [0.0, 90.0, 0.0]),
    ]);
    for i in 0..=10 {
        let s = i as f64 / 10.0;
        let r = f.pose_at(s).rotation_deg;
        assert!((r - DVec3::new(0.0, 90.0 * s, 0.0)).length() < 1e-9, "{s}: {r}");
    }
    let f = flight(vec![
        pose(0.0, [0.0; 3], [0.0, 350.0, 0.0]),
        pose(1.0, [0.0; 3], [0.0, 10.0, 0.0]),
    ]);
    let mid = f.pose_at(0.5).rotation_deg;
    assert!(mid.y.abs() < 1e-9 && mid.x.abs() < 1e-9, "{mid}");
}

#[test]
fn the_scene_in_force_is_the_last_edit_before() {
    let (sf, _) = crate::scene::Scene::default_scene();
    let text = crate::edit::document::to_toml(&sf).unwrap();
    let mut f = flight(vec![pose(0.0, [0.0; 3], [0.0; 3]), pose(2.0, [0.0; 3], [0.0; 3])]);
    f.file.edits = vec![
        EditKey {
            t: 0.5,
            scene: text.clone(),
        },
        EditKey { t: 1.5, scene: text },
    ];
    assert_eq!(f.edit_at(0.2), None);
    assert_eq!(f.edit_at(0.5).map(|e| e.0), Some(0));
    assert_eq!(f.edit_at(1.49).map(|e| e.0), Some(0));
    assert_eq!(f.edit_at(1.5).map(|e| e.0), Some(1));
    let back = Flight::parse("f.toml", &f.to_toml().unwrap()).expect("reads back");
    assert_eq!(back, f);
}

/// Each refusal is one line naming the file, the line of the key at fault
/// and its field.
#[test]
fn bad_flights_are_refused_at_their_line() {
    let head = "version = 1\n\n[[poses]]\nt = 0\nposition = [0, 0, 0]\nrotation = [0, 0, 0]\n\n";
    let cases = [
        (
            "[[poses]]\nt = 0\nposition = [0, 0, 1]\nrotation = [0, 0, 0]\n",
            9,
            "poses[1].t",
        ),
        (
            "[[poses]]\nt = 1\nposition = [0, 0, 1e300]\nrotation = [0, 0, 0]\n",
            10,
            "poses[1].position",
        ),
        (
            "[[poses]]\nt = 1\nposition = [0, 0, 1]\nrotation = [0, 0, 0]\nfov = 180\n",
            12,
            "poses[1].fov",
        ),
        (
            "[[poses]]\nt = 1\nposition = [0, 0, 1]\nrotation = [0, 0, nan]\n",
            11,
            "poses[1].rotation",
        ),
        ("[[poses]]\nposition = [0, 0, 1]\nrotation = [0, 0, 0]\n", 8, "flight"),
        (
            "[[poses]]\nt = 1\nposition = [0, 0]\nrotation = [0, 0, 0]\n",
            10,
            "flight",
        ),
        (
            "[[poses]]\nt = 1\nposition = [0, 0, 1]\nrotation = [0, 0, 0]\nspeed = 3\n",
            12,
            "flight",
        ),
        ("[[edits]]\nt = 1\nscene = \"not a scene\"\n", 10, "edits[0].scene"),
    ];
    for (tail, line, field) in cases {
        let text = format!("{head}{tail}");
        let e = Flight::parse("f.toml", &text).expect_err(tail).to_string();
        assert!(e.starts_with(&format!("f.toml:{line}:")), "{tail}: {e}");
        assert!(e.contains(&format!(": {field}: ")), "{tail}: {e}");
        assert!(!e.contains('\n'), "{e}");
    }
    let e = Flight::parse("f.toml", "version = 2\n").unwrap_err().to_string();
    assert!(e.contains("version"), "{e}");
    let e = Flight::parse("f.toml", "version = 1\n").unwrap_err().to_string();
    assert!(e.contains("at least one pose"), "{e}");
}

/// A trimmed, retimed flight flies the same path: at its own time `τ` it is
/// where the original was at `from + τ·speed` (exactly at the original's
/// keys and on a straight flight), and the edit in force at the cut is
/// in force from its start.
#[test]
fn a_trim_and_a_retime_fly_the_same_path() {
    let times = [0.0, 0.5, 1.0, 1.7, 3.0];
    let mut f = flight(
        times
            .iter()
            .map(|&t| pose(t, [t, 2.0 * t, -t], [0.0, 30.0 * t, 0.0]))
            .collect(),
    );
    let (sf, _) = crate::scene::Scene::default_scene();
    let text = crate::edit::document::to_toml(&sf).unwrap();
    f.file.edits = vec![
        EditKey {
            t: 0.2,
            scene: text.clone(),
        },
        EditKey { t: 2.0, scene: text },
    ];
    let (from, to, speed) = (0.75, 2.5, 2.0);
    let g = f.retimed(from, to, speed).expect("a valid trim");
    assert_eq!(g.duration(), (to - from) / speed);
    for i in 0..=40 {
        let tau = g.duration() * i as f64 / 40.0;
        let (a, b) = (g.pose_at(tau), f.pose_at(from + tau * speed));
        assert!((a.position - b.position).length() < 1e-12, "{tau}");
        assert!((a.rotation_deg - b.rotation_deg).length() < 1e-9, "{tau}");
    }
    assert_eq!(g.file.poses[1].t, (1.0 - from) / speed);
    assert_eq!(g.file.poses[1].position, f.file.poses[2].position);
    assert_eq!(g.edit_at(0.0).map(|e| e.0), Some(0));
    assert_eq!(g.file.edits[1].t, (2.0 - from) / speed);
    let back = Flight::parse("g.toml", &g.to_toml().unwrap()).expect("a retimed flight is valid");
    assert_eq!(back, g);
    for (from, to, speed) in [(1.0, 1.0, 1.0), (-0.1, 1.0, 1.0), (0.0, 3.5, 1.0), (0.0, 1.0, 0.0)] {
        assert!(f.retimed(from, to, speed).is_none(), "{from} {to} {speed}");
    }
}

#[test]
fn mouse_look_turns_and_clamps_pitch() {
    let start = (DVec3::new(1.0, 2.0, 3.0), DVec3::ZERO);
    let (p, r) = look(start, 100.0, -20.0);
    assert_eq!((p, r), (start.0, DVec3::new(3.0, -15.0, 0.0)));
    assert_eq!(look(start, 0.0, 1e6).1.x, -MAX_PITCH);
    assert_eq!(look(start, 0.0, -1e6).1.x, MAX_PITCH);
}
