//! The window's optics under Xvfb (as `tests/window.rs`): the optics
//! overlay (F6) draws F′ where `lens info` puts it, for the biconvex lens
//! and a lens system; the lens family's systems follow the lens keys; the
//! analysis window (F7) draws every figure of a system.

use lensview::render::Image;
use lensview::scene::Scene;
use std::path::PathBuf;
use std::process::Command;
use std::time::Duration;

mod window_support;
use window_support::*;

#[test]
fn optics_overlay_draws_f_prime_where_lens_info_puts_it_without_restarting() {
    let _one = one_at_a_time();
    let x = Xvfb::start();
    let dir = dir();
    // cubes.toml seen from the side, where the fan and F′ are spread out.
    let text = std::fs::read_to_string(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/cubes.toml")).unwrap();
    let text = text
        .replace("position = [0, 6, 10]", "position = [7.5, 4.2, 4.4]")
        .replace("rotation = [-28.810794, 0, 0]", "rotation = [-10, 90, 0]");
    let scene = dir.join("cubes-side.toml");
    std::fs::write(&scene, text).unwrap();
    let line = format!("--width {W} --height {H} --max-spp 2 --exit-after 600 --no-panel");
    let args: Vec<&str> = line.split(' ').collect();
    let s = Session::launch(&x, &dir, &scene, &args, dir.join("frames.jsonl"));
    let g1 = s.wait_frame_where(0, 2, "start", |f| f["width"] == W && f["x0"] == 0);
    // F′ from `lens info` (BFD from V2) and the scene's lens pose.
    let (sf, sc) = Scene::load(&scene).unwrap();
    let l = &sf.lenses[0];
    let out = Command::new(env!("CARGO_BIN_EXE_lensview"))
        .args(["lens", "info", "--d", &l.d.to_string(), "--r1", &l.r1.to_string()])
        .args(["--r2", &l.r2.to_string(), "--n", "1.5", "--json"])
        .output()
        .unwrap();
    let info: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let a = glam::DVec3::from(l.axis).normalize();
    let v2 = glam::DVec3::from(l.center) - a * info["sag2"].as_f64().unwrap();
    let f_back = v2 - a * info["bfd"].as_f64().unwrap();
    let (px, py) = project(&sc.camera, f_back);
    assert!(
        px > 10.0 && px < W as f64 - 10.0 && py > 10.0 && py < H as f64 - 10.0,
        "F′ off screen"
    );
    // The marker: a magenta disc (radius 5) centred within a pixel of the
    // projection.
    let magenta_near = |img: &Image| {
        let (n, c) = magenta_around(img, px, py);
        n >= 40 && (c[0] - px).hypot(c[1] - py) < 1.0
    };
    // The text overlay off; then the optics on.
    s.overlay_to("full");
    s.overlay_to("off");
    assert!(
        !magenta_near(&s.screenshot("before.png")),
        "magenta at F′ before the overlay"
    );
    let n = s.frames().len();
    s.key("F6");
    s.wait_screenshot("optics.png", "F′ at its projected pixel", magenta_near);
    s.wait_present(n, "F6");
    s.key("F6");
    s.wait_screenshot("no-optics.png", "the optics switched off", |img| !magenta_near(img));
    let gens: Vec<_> = s.frames()[n..].iter().map(|f| f["generation"].clone()).collect();
    assert!(
        gens.iter().all(|g| g == g1),
        "toggling the optics restarted refinement: {gens:?} after {g1}"
    );
}

/// The lens family (three `[[systems]]`): the window shows it; *Add
/// system* puts a biconvex system in front of the camera and selects it;
/// the lens key X moves it (a new frame each); Ctrl+Z twice undoes both.
#[test]
fn the_lens_family_shows_and_an_added_system_moves_with_the_lens_keys() {
    let _one = one_at_a_time();
    let x = Xvfb::start();
    let (dir, ui_log) = test_dir("lens-family");
    let scene = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/lens-family.toml");
    let args = ui_args(W + 340, H, 240, &ui_log);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let mut s = Session::launch(&x, &dir, &scene, &args, dir.join("frames.jsonl"));
    let g1 = s.wait_frame(0, 1, "start");
    let shot = s.screenshot("start.png");
    assert!(spread(&shot) > 20.0, "the window is blank");
    s.click(&ui_log, "kind system");
    s.click(&ui_log, "Add system");
    let g2 = s.wait_frame(g1, 1, "Add system");
    assert!(s.title().ends_with('*'), "no unsaved mark: {}", s.title());
    s.key("x");
    let g3 = s.wait_frame(g2, 1, "the lens key on the selected system");
    s.chord("ctrl+z");
    let g4 = s.wait_frame(g3, 1, "undo the move");
    s.chord("ctrl+z");
    s.wait_frame(g4, 1, "undo the add");
    assert!(
        wait_until(Duration::from_secs(30), || !s.title().ends_with('*')),
        "{}",
        s.title()
    );
    let (status, err) = s.escape_out(3);
    assert!(status.success(), "exit status {status:?}; stderr: {err}");
}

/// In a scene of lens systems only (scenes/achromat.toml), the optics
/// overlay (F6) draws the first system: its F′ marker lies where the
/// system's paraxial data put it.
#[test]
fn optics_overlay_draws_a_lens_systems_f_prime() {
    let _one = one_at_a_time();
    let x = Xvfb::start();
    let dir = dir();
    let scene = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/achromat.toml");
    let line = format!("--width {W} --height {H} --max-spp 1 --exit-after 600 --no-panel");
    let args: Vec<&str> = line.split(' ').collect();
    let mut s = Session::launch(&x, &dir, &scene, &args, dir.join("frames.jsonl"));
    s.wait_frame_where(0, 1, "start", |f| f["width"] == W && f["x0"] == 0);
    let (_, sc) = Scene::load(&scene).unwrap();
    let sys = sc.objects.iter().find_map(|o| o.system()).expect("a lens system");
    let bfd = sys.paraxial(lensview::optics::WAVELENGTH_D_UM).bfd;
    let f_back = sys.world_point(glam::DVec3::new(0.0, 0.0, sys.length() + bfd));
    let (px, py) = project(&sc.camera, f_back);
    assert!(
        px > 10.0 && px < W as f64 - 10.0 && py > 10.0 && py < H as f64 - 10.0,
        "F′ off screen"
    );
    let magenta_near = |img: &Image| magenta_around(img, px, py).0 >= 40;
    s.overlay_to("full");
    s.overlay_to("off");
    assert!(
        !magenta_near(&s.screenshot("before.png")),
        "magenta at F′ before the overlay"
    );
    s.key("F6");
    s.wait_screenshot("optics.png", "the system's F′ at its projected pixel", magenta_near);
    let (status, err) = s.escape_out(3);
    assert!(status.success(), "exit status {status:?}; stderr: {err}");
}

/// The analysis window (F7) on scenes/achromat.toml analyses its first
/// system (the AC254-100-A achromat, dispersive): every figure is where
/// the window says (`--ui-log`) and drawn in its colour — the fan's rays in
/// the cross-section, the LSA curve, the C, d and F spots, the distortion,
/// the axial colour and, across most of the plot's width (out to the
/// usable field), the lateral colour. F7 again closes it.
#[test]
fn the_analysis_window_draws_every_figure_of_a_lens_system() {
    let _one = one_at_a_time();
    let x = Xvfb::start();
    let (dir, ui_log) = test_dir("system-analysis");
    let scene = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/achromat.toml");
    let mut args = ui_args(1400, 980, 600, &ui_log);
    args.push("--no-panel".into());
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let mut s = Session::launch(&x, &dir, &scene, &args, dir.join("frames.jsonl"));
    s.wait_frame(0, 1, "start");
    assert!(!s.rects(&ui_log).contains_key("Lens analysis"), "open before F7");
    s.key("F7");
    let figures: [(&str, &[[u8; 3]], usize); 6] = [
        ("analysis sketch", &[[220, 60, 20]], 100),
        ("analysis LSA", &[[90, 210, 90]], 30),
        ("analysis spot", &[[235, 70, 60], [90, 210, 90], [90, 140, 255]], 5),
        ("analysis distortion", &[[90, 140, 255]], 30),
        ("analysis axial colour", &[[235, 70, 60]], 30),
        ("analysis lateral colour", &[[220, 80, 220]], 30),
    ];
    let mut rects = serde_json::Map::new();
    assert!(
        wait_until(Duration::from_secs(60), || {
            rects = s.rects(&ui_log);
            figures.iter().all(|f| rects.contains_key(f.0))
        }),
        "the window never placed every figure: {rects:?}"
    );
    let rect = |name: &str| -> Vec<f64> {
        (rects[name].as_array().unwrap().iter())
            .map(|v| v.as_f64().unwrap())
            .collect()
    };
    let drawn = |img: &Image| {
        figures
            .iter()
            .all(|(name, colours, least)| (colours.iter()).all(|c| colour_in(img, &rect(name), *c, 24).0 >= *least))
    };
    let shot = s.wait_screenshot("analysis.png", "every figure in its colour", drawn);
    let r = rect("analysis lateral colour");
    let (n, span) = colour_in(&shot, &r, [220, 80, 220], 24);
    eprintln!(
        "lateral colour curve: {n} pixels over {span} of {} columns",
        r[2] - r[0]
    );
    assert!(span > 0.5 * (r[2] - r[0]), "the curve stops short: {span}");
    s.key("F7");
    assert!(
        wait_until(Duration::from_secs(30), || !s
            .rects(&ui_log)
            .contains_key("Lens analysis")),
        "F7 did not close the window"
    );
    let (status, err) = s.escape_out(3);
    assert!(status.success(), "exit status {status:?}; stderr: {err}");
}

/// The rectangle `name` in the ui log (window pixels), waited for.
fn rect_of(s: &Session, ui_log: &std::path::Path, name: &str) -> [f64; 4] {
    let mut r = None;
    let found = wait_until(Duration::from_secs(60), || {
        r = s.rects(ui_log).get(name).and_then(|v| {
            let v: Vec<f64> = v.as_array()?.iter().filter_map(|x| x.as_f64()).collect();
            Some([v[0], v[1], v[2], v[3]])
        });
        r.is_some()
    });
    assert!(found, "no `{name}` on screen: {:?}", s.rects(ui_log));
    r.unwrap()
}

/// Issue 33.8: the analysis window (the magnifier of the default scene)
/// fits a 640×480 window, every figure as wide as it and the distortion
/// beside or below the others, not cut off; in a large window it fills the
/// room right of the panel. The *Lens* section, opened at 1280×720, fits
/// the panel: the last section's header stays on screen.
#[test]
fn the_analysis_window_and_the_lens_section_fit_small_and_fill_large_windows() {
    let _one = one_at_a_time();
    let x = Xvfb::start();
    let scene = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/cubes.toml");
    for (w, h, panel) in [(640u32, 480u32, false), (1600, 980, true), (1280, 720, true)] {
        let (dir, ui_log) = test_dir(&format!("analysis-{w}"));
        let _ = std::fs::remove_file(&ui_log);
        let mut args = ui_args(w, h, 600, &ui_log);
        if !panel {
            args.push("--no-panel".into());
        }
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let mut s = Session::launch(&x, &dir, &scene, &args, dir.join("frames.jsonl"));
        s.wait_frame(0, 1, "start");
        if h == 720 {
            s.click(&ui_log, "section Lens");
            // Opened, and the others closed at the next frame.
            std::thread::sleep(Duration::from_millis(1500));
            let render = rect_of(&s, &ui_log, "section Render");
            assert!(
                render[3] <= h as f64,
                "the Lens section pushes Render off screen: {render:?}"
            );
        } else {
            s.key("F7");
            let win = rect_of(&s, &ui_log, "Lens analysis");
            let dist = rect_of(&s, &ui_log, "analysis distortion");
            let spot = rect_of(&s, &ui_log, "analysis spot");
            assert!(win[0] >= 0.0 && win[2] <= w as f64 && win[3] <= h as f64, "{win:?}");
            for r in [dist, spot] {
                assert!(r[0] >= win[0] && r[2] <= win[2], "a plot is cut off: {r:?} in {win:?}");
            }
            if w > 1000 {
                let room = w as f64 - 340.0;
                assert!(win[2] - win[0] > 0.9 * room, "the window does not fill: {win:?}");
                assert!(dist[2] - dist[0] > 400.0, "the plots do not grow: {dist:?}");
            }
        }
        let (status, err) = s.escape_out(3);
        assert!(status.success(), "{err}");
    }
}
