use super::*;
use lensview::render::render;

fn finish(v: &mut View) {
    while v.step(3) {}
    assert!(v.done());
}

/// `render`'s picture of `scene` with its caustics, converted as the
/// PNG is (RGB).
fn renders(scene: &Scene, (width, height): (u32, u32), spp: u32, seed: u64) -> Vec<u8> {
    let s = RenderSettings {
        width,
        height,
        spp,
        seed,
    };
    let photons = CausticSettings {
        seed,
        ..CausticSettings::default()
    };
    let map = still_map(scene, (width, height), spp, photons);
    render(lit_of(scene, &map), &s, None).to_srgb8_toned(scene.tone)
}

fn rgb(v: &View) -> Vec<u8> {
    v.rgba().chunks(4).flat_map(|p| [p[0], p[1], p[2]]).collect()
}

/// The page's scene now, as `lensview render` would read its file.
fn scene_of(v: &View) -> Scene {
    Scene::parse("page.toml", &v.scene_toml().unwrap()).unwrap().1
}

/// The finished picture is `render`'s at the same size, spp and seed,
/// converted as the PNG is; it starts with the block previews.
#[test]
fn the_picture_is_renders() {
    let mut v = View::new(Some("cubes"), (24, 20), 2, 3).unwrap();
    assert_eq!(v.stage(), "0 spp");
    assert!(v.step(1));
    assert_eq!(v.stage(), "8×8 blocks");
    // Blended between the 3 × 3 block centres, not one colour a block.
    let colours: std::collections::HashSet<&[u8]> = v.rgba().chunks(4).collect();
    assert!(colours.len() > 9, "{} colours", colours.len());
    finish(&mut v);
    assert_eq!((v.samples(), v.stage().as_str()), ((2, 2), "2 spp"));
    assert_eq!(rgb(&v), renders(&Scene::default_scene().1, (24, 20), 2, 3));
}

/// W keeps the photon map (it does not depend on the camera): the new
/// picture is still `render`'s of the moved scene.
#[test]
fn w_moves_the_camera_and_restarts() {
    let mut v = View::new(None, (16, 12), 2, 1).unwrap();
    finish(&mut v);
    let before = v.rgba().to_vec();
    assert!(v.key("KeyW"));
    assert!(!v.done());
    finish(&mut v);
    assert_ne!(v.rgba(), &before[..]);
    assert_eq!(rgb(&v), renders(&scene_of(&v), (16, 12), 2, 1));
    assert!(!v.key("KeyG"));
    assert!(v.scene_toml().unwrap().contains("[camera]"));
    // Q and E fly down and up, as on the desktop.
    let y = v.doc.camera_pose().0.y;
    assert!(v.key("KeyQ"));
    assert!(v.doc.camera_pose().0.y < y);
    assert!(v.key("KeyE"));
    assert!(v.key("KeyE"));
    assert!(v.doc.camera_pose().0.y > y);
}

/// The mean absolute difference of two RGB(A) pictures, per channel.
fn mean_diff(a: &[u8], b: &[u8]) -> f64 {
    let sum: u64 = a.iter().zip(b).map(|(&x, &y)| u64::from(x.abs_diff(y))).sum();
    sum as f64 / a.len() as f64
}

/// A move with a picture at full resolution shows it moved into the
/// new view (the desktop's reprojection), far nearer the moved scene's
/// picture than the block preview a fresh start shows, and again after
/// a second move (a reprojection of the reprojection); the finished
/// picture is still `render`'s. With only blocks shown, a move starts
/// over with blocks.
#[test]
fn a_move_shows_the_picture_moved_then_renders() {
    let (size, spp, seed) = ((64, 48), 2, 4);
    let mut v = View::new(Some("cubes"), size, spp, seed).unwrap();
    finish(&mut v);
    for key in ["ArrowLeft", "ArrowUp", "KeyW"] {
        let stale = rgb(&v);
        assert!(v.key(key));
        assert_eq!(v.stage(), "reprojected");
        let moved = rgb(&v);
        let want = renders(&scene_of(&v), size, spp, seed);
        let mut fresh = View::new(Some("cubes"), size, spp, seed).unwrap();
        assert!(
            fresh
                .doc
                .fly_camera(v.doc.camera_pose().0, v.doc.camera_pose().1)
                .is_ok()
        );
        fresh.restart(false);
        assert!(fresh.step(1));
        assert_eq!(fresh.stage(), "8×8 blocks");
        let (d_moved, d_blocks) = (mean_diff(&moved, &want), mean_diff(&rgb(&fresh), &want));
        let d_stale = mean_diff(&stale, &want);
        eprintln!("{key}: {d_moved} against blocks {d_blocks}, unmoved {d_stale}");
        assert!(d_moved < 0.5 * d_blocks, "{key}: {d_moved} against blocks {d_blocks}");
        // A turn moves the whole picture; a step forward of this size
        // hardly changes it (the unmoved picture is then no measure).
        if key != "KeyW" {
            assert!(d_moved < 0.5 * d_stale, "{key}: {d_moved} against unmoved {d_stale}");
        }
    }
    finish(&mut v);
    assert_eq!(rgb(&v), renders(&scene_of(&v), size, spp, seed));
    // Blocks only: a move starts over.
    let mut w = View::new(Some("cubes"), size, spp, seed).unwrap();
    assert!(w.step(1) && w.key("KeyW") && w.step(1));
    assert_eq!(w.stage(), "8×8 blocks");
    // A lens camera's picture is not moved.
    let mut c = View::new(Some("camera-dgauss"), (24, 16), 1, seed).unwrap();
    finish(&mut c);
    assert!(c.key("KeyW") && c.step(1));
    assert_eq!(c.stage(), "8×8 blocks");
}

/// Where the camera sees the caustic over several pixels (rim-lens),
/// the page thins its gathers as `render` does; a step back that ends
/// the thinning traces the photons again (`render` traces fewer
/// there), and the picture is `render`'s before and after.
#[test]
fn thinned_gathers_follow_the_camera_as_render_does() {
    let (size, spp, seed) = ((160, 90), 4, 2);
    let mut v = View::new(Some("rim-lens"), size, spp, seed).unwrap();
    finish(&mut v);
    let thin = |v: &View| v.map.as_ref().map(|m| m.1);
    assert_eq!(thin(&v), Some(2));
    assert_eq!(rgb(&v), renders(&scene_of(&v), size, spp, seed));
    let passes = v.map.as_ref().map(|m| m.0.passes());
    // Steps back until the radius is under half a pixel's footprint
    // (`thinning::THIN_FROM`).
    let mut steps = 0;
    for _ in 0..200 {
        assert!(v.key("KeyS"));
        steps += 1;
        if thin(&v) == Some(1) {
            break;
        }
        assert_eq!(
            v.map.as_ref().map(|m| m.0.passes()),
            passes,
            "the same photons while thinned"
        );
    }
    finish(&mut v);
    assert_eq!(thin(&v), Some(1), "{steps} steps back");
    assert!(v.map.as_ref().map(|m| m.0.passes()) < passes, "fewer photons unthinned");
    assert_eq!(rgb(&v), renders(&scene_of(&v), size, spp, seed));
}

/// Mouse-look turns the camera as the desktop's drag does
/// (`flight::look`), shows the picture moved, and finishes as `render`'s
/// picture of the turned scene; no movement changes nothing.
#[test]
fn mouse_look_turns_as_the_desktop_and_renders() {
    let mut v = View::new(Some("cubes"), (32, 24), 1, 6).unwrap();
    finish(&mut v);
    let before = v.doc.camera_pose();
    assert!(!v.look(0.0, 0.0));
    assert!(v.look(40.0, -10.0));
    assert_eq!(v.doc.camera_pose(), look(before, 40.0, -10.0));
    assert_eq!(v.stage(), "reprojected");
    finish(&mut v);
    assert_eq!(rgb(&v), renders(&scene_of(&v), (32, 24), 1, 6));
    // One gesture is one undo step, until sealed.
    assert!(v.look(5.0, 0.0));
    v.seal();
    assert!(v.look(5.0, 0.0));
    assert!(v.undo());
    assert_eq!(v.doc.camera_pose(), look(look(before, 40.0, -10.0), 5.0, 0.0));
    assert!(v.undo());
    assert_eq!(v.doc.camera_pose(), before);
}

/// A lens key makes the desktop's edit (`edit::apply` of its
/// `LENS_KEYS` entry) on the first lens, and the picture is `render`'s
/// of the edited scene.
#[test]
fn a_lens_key_edits_the_first_lens_as_the_desktop_does() {
    let mut v = View::new(Some("cubes"), (16, 12), 1, 2).unwrap();
    let mut want = v.doc.scene().clone();
    lensview::edit::apply(&mut want, lens_key("Digit2").unwrap());
    assert!(v.key("Digit2"));
    assert!(v.message().starts_with("lens d = "), "{}", v.message());
    assert_eq!(v.doc.scene().lenses[0].d, want.lenses[0].d);
    assert_ne!(v.doc.scene().lenses[0].d, Scene::default_scene().0.lenses[0].d);
    finish(&mut v);
    assert_eq!(rgb(&v), renders(&scene_of(&v), (16, 12), 1, 2));
}

/// The light and lens camera keys are the desktop's (the library's
/// `SCENE_KEYS`, through the document): L moves the first light as the
/// desktop's L does, one undo step, and the picture is `render`'s; F9
/// switches to a lens camera and ; focuses it; R resets the view.
#[test]
fn the_light_camera_and_reset_keys_are_the_desktops() {
    let mut v = View::new(Some("cubes"), (16, 12), 1, 2).unwrap();
    let mut want = v.doc.scene().clone();
    lensview::edit::apply(
        &mut want,
        lensview::edit::Edit::LightMove(glam::DVec3::new(0.5, 0.0, 0.0)),
    );
    assert!(v.key("KeyL"));
    assert!(v.message().starts_with("light moved to"), "{}", v.message());
    assert_eq!(v.doc.scene().lights[0].position, want.lights[0].position);
    finish(&mut v);
    assert_eq!(rgb(&v), renders(&scene_of(&v), (16, 12), 1, 2));
    assert!(v.undo());
    assert_eq!(
        v.doc.scene().lights[0].position,
        Scene::default_scene().0.lights[0].position
    );
    assert!(!v.key("Semicolon"), "no lens camera yet");
    assert_eq!(v.message(), "no lens camera: F9 switches to one");
    assert!(v.key("F9"));
    assert!(v.doc.built().lens.is_some());
    assert!(v.key("Semicolon"));
    assert!(v.key("KeyW"));
    assert!(v.key("KeyR"));
    assert_eq!(v.message(), "view reset");
    assert_eq!(
        v.doc.camera_pose().0,
        View::new(Some("cubes"), (16, 12), 1, 2).unwrap().doc.camera_pose().0
    );
}

/// A panel edit is `render`'s picture of the edited scene; a refused
/// value changes nothing; undo brings back the first picture bit for
/// bit, redo the edited one.
#[test]
fn a_panel_edit_renders_and_undo_brings_the_picture_back() {
    let mut v = View::new(Some("cubes"), (16, 12), 1, 5).unwrap();
    finish(&mut v);
    let first = v.rgba().to_vec();
    assert!(v.set("lens:0", "r1", "2.5").unwrap());
    assert_eq!(v.message(), "lenses[0].r1 = 2.5");
    finish(&mut v);
    let edited = v.rgba().to_vec();
    assert_ne!(edited, first);
    assert_eq!(rgb(&v), renders(&scene_of(&v), (16, 12), 1, 5));
    assert!(v.set("lens:0", "r1", "x").is_err());
    assert!(v.done(), "a refused value does not restart");
    assert!(v.undo());
    finish(&mut v);
    assert_eq!(v.rgba(), &first[..]);
    assert!(v.redo());
    finish(&mut v);
    assert_eq!(v.rgba(), &edited[..]);
    assert!(!v.redo());
    assert_eq!(v.message(), "nothing to redo");
    assert!(v.panel("lens:0").undo.is_some());
}

#[test]
fn a_bad_file_is_refused_in_one_line_and_the_scene_stays() {
    let mut v = View::new(None, (16, 12), 1, 0).unwrap();
    let e = v.open("bad.toml", b"[camera]\nfov = \"wide\"\n").unwrap_err();
    assert!(e.starts_with("error: bad.toml"), "{e}");
    assert!(!e.contains('\n'));
    assert!(v.done() || v.step(1));
    let e = View::new(Some("no such"), (4, 4), 1, 0).err().unwrap();
    assert_eq!(e, "error: no such:1:1: (document): no such preset");
    for p in lensview::edit::presets::PRESETS {
        for name in [p.name, p.file, p.file.trim_end_matches(".toml")] {
            assert!(View::new(Some(name), (4, 4), 1, 0).is_ok(), "{name}");
        }
    }
}

/// A file over `Scene::load`'s cap gets its line (as `lensview render`
/// prints for such a file) and the scene stays; one at the cap is parsed.
#[test]
fn a_file_over_the_scene_cap_is_refused_as_scene_load_does() {
    let mut v = View::new(None, (16, 12), 1, 0).unwrap();
    let before = v.scene_toml().unwrap();
    let big = vec![b' '; SCENE_FILE_CAP as usize + 1];
    let e = v.open("big.toml", &big).unwrap_err();
    assert_eq!(
        e,
        "error: big.toml: not read: larger than the 128 MiB limit for this input"
    );
    assert_eq!(v.scene_toml().unwrap(), before);
    let e = v.open("big.toml", &big[1..]).unwrap_err();
    assert!(!e.contains("limit"), "{e}");
}
