//! The real window under Xvfb with Mesa's software Vulkan driver (lavapipe):
//! it opens and shows the scene, keys change the picture, the overlay shows,
//! resizing and unmapping do not crash, and Escape exits with status 0.
//!
//! Needs `Xvfb`, `xdotool` and ImageMagick's `import` (`.ci/run` installs
//! them). Every wait polls with a generous time-out; the X server is stopped
//! when the test ends, pass or fail. The server runs with `-noreset`: by
//! default Xvfb resets whenever its last client leaves, and a viewer that
//! connected just as an `xdotool` poll disconnected was refused
//! (intermittently, "Failed to open connection to X server").

use lensview::render::{Image, RenderSettings, render};
use lensview::scene::Scene;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

const W: u32 = 640;
const H: u32 = 480;

struct Xvfb {
    child: Child,
    display: String,
}

impl Xvfb {
    /// Starts a server on a display number of its own choosing: with
    /// `-displayfd` Xvfb picks a free number (clearing stale locks) and
    /// writes it to our pipe only once it accepts connections, so there is
    /// neither a race for the number nor a guess at when it is ready.
    fn start() -> Xvfb {
        use std::io::BufRead;
        let mut child = Command::new("Xvfb")
            .args([
                "-displayfd",
                "1",
                "-screen",
                "0",
                "1600x1000x24",
                "-nolisten",
                "tcp",
                "-noreset",
            ])
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("Xvfb is not installed (apt-get install xvfb)");
        let out = child.stdout.take().unwrap();
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let mut line = String::new();
            let _ = std::io::BufReader::new(out).read_line(&mut line);
            let _ = tx.send(line);
        });
        match rx.recv_timeout(Duration::from_secs(120)) {
            Ok(line) if line.trim().parse::<u32>().is_ok() => Xvfb {
                child,
                display: format!(":{}", line.trim()),
            },
            other => {
                let _ = child.kill();
                let _ = child.wait();
                panic!("Xvfb did not start: {other:?}");
            }
        }
    }
}

impl Drop for Xvfb {
    /// SIGTERM first, so that the server removes its lock file and socket;
    /// SIGKILL if it has not gone within 10 s.
    fn drop(&mut self) {
        // `kill` as the shell's builtin: no package beyond `sh` needed.
        let _ = Command::new("sh")
            .args(["-c", &format!("kill {}", self.child.id())])
            .status();
        if !wait_until(Duration::from_secs(10), || {
            self.child.try_wait().ok().flatten().is_some()
        }) {
            let _ = self.child.kill();
        }
        let _ = self.child.wait();
    }
}

/// The tests that start an X server take this first: one server and one
/// software-rendered viewer at a time (two at once on a 2-core machine
/// starve each other past the time-outs).
static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn one_at_a_time() -> std::sync::MutexGuard<'static, ()> {
    // A test that failed holding it poisons it; the next still runs alone.
    ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner())
}

fn wait_until(limit: Duration, mut f: impl FnMut() -> bool) -> bool {
    let end = Instant::now() + limit;
    while Instant::now() < end {
        if f() {
            return true;
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    false
}

fn dir() -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("window-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A fresh folder NAME for a test and the path of its `--ui-log` file.
fn test_dir(name: &str) -> (PathBuf, PathBuf) {
    let dir = dir().join(name);
    std::fs::create_dir_all(&dir).unwrap();
    let ui_log = dir.join("ui.json");
    let _ = std::fs::remove_file(&ui_log);
    (dir, ui_log)
}

/// `--width W --height H --max-spp 1 --exit-after SECONDS --ui-log LOG`.
fn ui_args(w: u32, h: u32, exit_after: u32, ui_log: &Path) -> Vec<String> {
    let mut v: Vec<String> = ["--width", &w.to_string(), "--height", &h.to_string(), "--max-spp", "1"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    v.extend(["--exit-after".into(), exit_after.to_string()]);
    v.extend(["--ui-log".into(), ui_log.display().to_string()]);
    v
}

struct Session<'a> {
    x: &'a Xvfb,
    app: Child,
    window: String,
    log: PathBuf,
    dir: PathBuf,
}

impl Drop for Session<'_> {
    fn drop(&mut self) {
        let _ = self.app.kill();
        let _ = self.app.wait();
    }
}

impl<'a> Session<'a> {
    /// Starts `lensview view SCENE ARGS… --frame-log LOG` on `x`, in `dir`,
    /// waits (up to 120 s) for its window and focuses it. If the viewer exits
    /// first, fails with what it printed.
    fn launch(x: &'a Xvfb, dir: &Path, scene: &Path, args: &[&str], log: PathBuf) -> Session<'a> {
        let runtime = dir.join("xdg");
        std::fs::create_dir_all(&runtime).unwrap();
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_lensview"));
        cmd.env("XDG_RUNTIME_DIR", &runtime);
        Self::launch_with(cmd, x, dir, scene, args, log)
    }

    /// Like `launch`, with `cmd` (the binary, its environment) given.
    fn launch_with(
        mut cmd: Command,
        x: &'a Xvfb,
        dir: &Path,
        scene: &Path,
        args: &[&str],
        log: PathBuf,
    ) -> Session<'a> {
        let _ = std::fs::remove_file(&log);
        let app = cmd
            .env("DISPLAY", &x.display)
            .env_remove("WAYLAND_DISPLAY")
            .current_dir(dir)
            .args(["view", scene.to_str().unwrap()])
            .args(args)
            .args(["--frame-log", log.to_str().unwrap()])
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let mut s = Session {
            x,
            app,
            window: String::new(),
            log,
            dir: dir.to_path_buf(),
        };
        let mut id = String::new();
        let mut exited = None;
        wait_until(Duration::from_secs(120), || {
            id = s
                .xdotool(&["search", "--name", "^lensview"])
                .lines()
                .next()
                .unwrap_or("")
                .to_string();
            exited = s.app.try_wait().ok().flatten();
            !id.is_empty() || exited.is_some()
        });
        if id.is_empty() {
            let _ = s.app.kill();
            let mut err = String::new();
            if let Some(mut e) = s.app.stderr.take() {
                use std::io::Read;
                let _ = e.read_to_string(&mut err);
            }
            let probe = Command::new("xdpyinfo").args(["-display", &x.display]).output();
            let alive = probe.map(|o| o.status.success());
            panic!(
                "the window never appeared on {} (server answers: {alive:?}; viewer exit: {exited:?}); stderr: {err}",
                x.display
            );
        }
        s.window = id;
        s.xdotool(&["windowfocus", "--sync", &s.window]);
        s
    }

    fn xdotool(&self, args: &[&str]) -> String {
        let o = Command::new("xdotool")
            .env("DISPLAY", &self.x.display)
            .args(args)
            .output()
            .expect("xdotool is not installed");
        String::from_utf8_lossy(&o.stdout).trim().to_string()
    }

    /// Frame-log lines as JSON values.
    fn frames(&self) -> Vec<serde_json::Value> {
        std::fs::read_to_string(&self.log)
            .unwrap_or_default()
            .lines()
            .filter_map(|l| serde_json::from_str(l).ok())
            .collect()
    }

    /// Waits until a frame of a generation above `after`, refined to at
    /// least `spp`, has been presented; returns its generation.
    fn wait_frame(&self, after: u64, spp: u64, what: &str) -> u64 {
        self.wait_frame_where(after, spp, what, |_| true)
    }

    /// Like `wait_frame`, for a frame that also passes `pred`.
    fn wait_frame_where(&self, after: u64, spp: u64, what: &str, pred: impl Fn(&serde_json::Value) -> bool) -> u64 {
        let mut found = 0;
        let ok = wait_until(Duration::from_secs(120), || {
            found = self
                .frames()
                .iter()
                .filter(|f| f["generation"].as_u64().unwrap_or(0) > after && f["spp"].as_u64().unwrap_or(0) >= spp)
                .filter(|f| pred(f))
                .map(|f| f["generation"].as_u64().unwrap())
                .max()
                .unwrap_or(0);
            found > 0
        });
        assert!(ok, "no refined frame after {what}; frames: {:?}", self.frames().last());
        // Let the window draw it (the log is written right after presenting).
        std::thread::sleep(Duration::from_millis(300));
        found
    }

    /// Waits (up to 30 s) until more than `n` frames are in the log: the
    /// window presented again after whatever was done since `n` was read.
    fn wait_present(&self, n: usize, what: &str) {
        assert!(
            wait_until(Duration::from_secs(30), || self.frames().len() > n),
            "nothing presented after {what}"
        );
    }

    /// Screenshots until `pred` holds (up to 30 s); returns the last one.
    fn wait_screenshot(&self, name: &str, what: &str, pred: impl Fn(&Image) -> bool) -> Image {
        let mut shot = None;
        let ok = wait_until(Duration::from_secs(30), || {
            let s = self.screenshot(name);
            let good = pred(&s);
            shot = Some(s);
            good
        });
        assert!(ok, "the window never showed {what}");
        shot.unwrap()
    }

    fn last_generation(&self) -> u64 {
        self.frames()
            .iter()
            .filter_map(|f| f["generation"].as_u64())
            .max()
            .unwrap_or(0)
    }

    fn screenshot(&self, name: &str) -> Image {
        let path = self.dir.join(name);
        let st = Command::new("import")
            .env("DISPLAY", &self.x.display)
            .args(["-window", &self.window, &format!("png24:{}", path.display())])
            .status()
            .expect("ImageMagick import is not installed");
        assert!(st.success(), "import failed");
        Image::read_png(&path).unwrap()
    }

    fn key(&self, key: &str) {
        self.xdotool(&["key", "--window", &self.window, key]);
    }

    /// Types a key chord through the X server's input (XTEST), as a user
    /// would: modifiers reach the window's keyboard state. The window must
    /// have the focus.
    fn chord(&self, keys: &str) {
        self.xdotool(&["key", "--clearmodifiers", keys]);
    }

    fn title(&self) -> String {
        self.xdotool(&["getwindowname", &self.window])
    }

    /// The panel's named buttons and their rectangles (`--ui-log`).
    fn rects(&self, ui_log: &Path) -> serde_json::Map<String, serde_json::Value> {
        std::fs::read_to_string(ui_log)
            .ok()
            .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
            .and_then(|v| v.as_object().cloned())
            .unwrap_or_default()
    }

    /// Clicks the middle of the button called `name` once it is on screen.
    fn click(&self, ui_log: &Path, name: &str) {
        let mut at = None;
        assert!(
            wait_until(Duration::from_secs(60), || {
                at = self.rects(ui_log).get(name).and_then(|r| {
                    let r: Vec<f64> = r.as_array()?.iter().filter_map(|x| x.as_f64()).collect();
                    Some((((r[0] + r[2]) / 2.0) as i64, ((r[1] + r[3]) / 2.0) as i64))
                });
                at.is_some()
            }),
            "no button `{name}` on screen: {:?}",
            self.rects(ui_log)
        );
        let (x, y) = at.unwrap();
        self.xdotool(&["mousemove", "--window", &self.window, &x.to_string(), &y.to_string()]);
        std::thread::sleep(Duration::from_millis(300));
        self.xdotool(&["mousedown", "1"]);
        std::thread::sleep(Duration::from_millis(150));
        self.xdotool(&["mouseup", "1"]);
        std::thread::sleep(Duration::from_millis(300));
    }

    fn hold(&self, key: &str, ms: u64) {
        self.xdotool(&["keydown", "--window", &self.window, key]);
        std::thread::sleep(Duration::from_millis(ms));
        self.xdotool(&["keyup", "--window", &self.window, key]);
    }
}

/// Mean absolute difference of two images in 8-bit levels, over rows y0..y1.
fn diff(a: &Image, b: &Image, y0: u32, y1: u32) -> f64 {
    assert_eq!((a.width, a.height), (b.width, b.height));
    let (a8, b8) = (a.to_srgb8(), b.to_srgb8());
    let row = a.width as usize * 3;
    let (s, e) = (y0 as usize * row, y1 as usize * row);
    a8[s..e]
        .iter()
        .zip(&b8[s..e])
        .map(|(x, y)| (*x as f64 - *y as f64).abs())
        .sum::<f64>()
        / (e - s) as f64
}

/// Mean absolute difference in 8-bit levels over columns x0.. (the picture
/// right of the panel), all rows.
fn diff_right_of(a: &Image, b: &Image, x0: u32) -> f64 {
    assert_eq!((a.width, a.height), (b.width, b.height));
    let (a8, b8) = (a.to_srgb8(), b.to_srgb8());
    let mut sum = 0.0;
    let mut n = 0usize;
    for y in 0..a.height as usize {
        let s = (y * a.width as usize + x0 as usize) * 3;
        let e = (y + 1) * a.width as usize * 3;
        sum += a8[s..e]
            .iter()
            .zip(&b8[s..e])
            .map(|(x, y)| (*x as f64 - *y as f64).abs())
            .sum::<f64>();
        n += e - s;
    }
    sum / n as f64
}

fn spread(img: &Image) -> f64 {
    let b = img.to_srgb8();
    let mean = b.iter().map(|&x| x as f64).sum::<f64>() / b.len() as f64;
    (b.iter().map(|&x| (x as f64 - mean).powi(2)).sum::<f64>() / b.len() as f64).sqrt()
}

#[test]
fn the_window_shows_the_scene_answers_keys_and_exits_cleanly() {
    let _one = one_at_a_time();
    let x = Xvfb::start();
    let dir = dir();
    let scene = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/cubes.toml");
    let (w, h) = (W.to_string(), H.to_string());
    let args = ["--width", &w, "--height", &h, "--max-spp", "2", "--exit-after", "600"];
    let mut s = Session::launch(&x, &dir, &scene, &args, dir.join("frames.jsonl"));

    // F4 hides the editing panel, so the picture fills the window.
    s.key("F4");
    // It shows the scene: not blank, and like the headless render (overlay off).
    // Refined to the cap (2 spp): no more frames of this generation follow.
    let g1 = s.wait_frame_where(0, 2, "start", |f| f["width"] == W && f["x0"] == 0);
    let (_, sc) = Scene::load(&scene).unwrap();
    let headless = render(
        &sc,
        &RenderSettings {
            width: W,
            height: H,
            spp: 1,
            seed: 0,
        },
        None,
    );
    // F1 twice: the overlay from compact (the default) to full to off.
    s.overlay_to("full");
    s.overlay_to("off");
    let shot = s.screenshot("start.png");
    assert_eq!((shot.width, shot.height), (W, H), "window size");
    assert!(spread(&shot) > 20.0, "the window is blank");
    let d = diff(&shot, &headless, 0, H);
    assert!(
        d < 6.0,
        "window differs from the headless render by {d:.2} levels on average"
    );

    // The overlay is visible when on: the top-left corner changes.
    let n = s.frames().len();
    s.key("F1");
    let with_overlay = s.wait_screenshot("overlay.png", "the overlay", |img| diff(img, &shot, 0, 60) > 5.0);
    // The redraw with the overlay was presented (and logged) with the same
    // generation: nothing restarted refinement.
    s.wait_present(n, "the overlay toggle");
    let gens: Vec<_> = s.frames()[n..].iter().map(|f| f["generation"].clone()).collect();
    assert!(
        gens.iter().all(|g| g == g1),
        "toggling the overlay restarted refinement: {gens:?} after {g1}"
    );
    // Below the compact overlay (three lines) the picture is untouched.
    assert!(
        diff(&with_overlay, &shot, 120, H) < 1.0,
        "the overlay toggle re-rendered the picture"
    );
    // Full, then off again.
    s.key("F1");
    s.key("F1");

    // Pressing W moves the camera: a new generation and a different picture.
    s.hold("w", 400);
    let g2 = s.wait_frame(g1, 1, "W");
    let moved = s.screenshot("moved.png");
    assert!(diff(&moved, &shot, 0, H) > 2.0, "W did not change the picture");

    // A lens key (2: diameter +) changes the picture.
    s.key("2");
    let g3 = s.wait_frame(g2, 1, "lens key");
    let lens = s.screenshot("lens.png");
    assert!(
        diff(&lens, &moved, 0, H) > 0.5,
        "the lens key did not change the picture"
    );

    // Resizing re-renders at the new size; unmapping and mapping survive.
    s.xdotool(&["windowsize", "--sync", &s.window, "800", "560"]);
    assert!(
        wait_until(Duration::from_secs(60), || s
            .frames()
            .iter()
            .any(|f| f["width"] == 800 && f["height"] == 560)),
        "no frame at the new size"
    );
    s.xdotool(&["windowunmap", "--sync", &s.window]);
    s.xdotool(&["windowmap", "--sync", &s.window]);
    // Alive and answering: a lens key after mapping gives a new frame.
    s.xdotool(&["windowfocus", "--sync", &s.window]);
    let g4 = s.last_generation();
    assert!(g4 > g3);
    s.key("2");
    s.wait_frame(g4, 1, "a key after unmap and map");
    assert!(
        s.app.try_wait().unwrap().is_none(),
        "the viewer died after resize/unmap"
    );

    // Escape exits with status 0 (after asking, as the lens was changed:
    // D answers "quit without saving").
    s.xdotool(&["windowfocus", "--sync", &s.window]);
    s.key("Escape");
    assert!(
        !wait_until(Duration::from_secs(2), || s.app.try_wait().unwrap().is_some()),
        "quit with unsaved changes without asking"
    );
    s.key("d");
    let mut status = None;
    wait_until(Duration::from_secs(30), || {
        status = s.app.try_wait().unwrap();
        status.is_some()
    });
    let status = status.expect("Escape did not close the viewer");
    let mut err = String::new();
    if let Some(mut e) = s.app.stderr.take() {
        use std::io::Read;
        let _ = e.read_to_string(&mut err);
    }
    assert!(status.success(), "exit status {status:?}; stderr: {err}");
}

#[test]
fn without_a_display_the_viewer_says_how_to_render_headless() {
    let o = Command::new(env!("CARGO_BIN_EXE_lensview"))
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .args(["view"])
        .output()
        .unwrap();
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("lensview render"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
}

/// The editing panel: *Add sphere* is clicked and the picture changes; undo,
/// redo and save (Ctrl+Z, Ctrl+Shift+Z, Ctrl+S); flight keys still fly with
/// the panel shown; Escape with unsaved changes asks instead of quitting.
#[test]
fn the_panel_adds_a_sphere_undoes_saves_and_asks_before_quitting() {
    let (ew, eh) = (1100u32, 760u32);
    let _one = one_at_a_time();
    let x = Xvfb::start();
    let (dir, ui_log) = test_dir("editor");
    let scene = dir.join("cubes.toml");
    std::fs::copy(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/cubes.toml"),
        &scene,
    )
    .unwrap();
    let original = std::fs::read_to_string(&scene).unwrap();
    let args = ui_args(ew, eh, 600, &ui_log);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let mut s = Session::launch(&x, &dir, &scene, &args, dir.join("frames.jsonl"));

    // The panel is shown by default; the picture is rendered right of it.
    let g1 = s.wait_frame(0, 1, "start");
    let first = s.frames().into_iter().find(|f| f["generation"] == g1).unwrap();
    let x0 = first["x0"].as_u64().unwrap() as u32;
    assert!(x0 >= 300, "no room left for the panel: {first}");
    assert_eq!(first["width"].as_u64().unwrap() as u32, ew - x0);
    let title = s.title();
    assert!(title.contains("cubes.toml") && !title.ends_with('*'), "{title}");
    // Overlay off (compact → full → off), so pictures compare exactly.
    s.overlay_to("full");
    s.overlay_to("off");
    let before = s.screenshot("editor-start.png");
    assert_eq!((before.width, before.height), (ew, eh));
    assert!(spread(&before) > 20.0, "the window is blank");

    // Click "Add sphere": a new generation, a different picture, a dirty title.
    s.click(&ui_log, "Add sphere");
    let g2 = s.wait_frame(g1, 1, "Add sphere");
    let added = s.screenshot("editor-added.png");
    let d = diff_right_of(&added, &before, x0);
    assert!(d > 0.3, "Add sphere did not change the picture ({d:.3} levels)");
    assert!(s.title().ends_with('*'), "no unsaved mark: {}", s.title());
    assert_eq!(
        std::fs::read_to_string(&scene).unwrap(),
        original,
        "nothing is saved before Ctrl+S"
    );

    // Ctrl+Z undoes it: the very same picture, and the mark goes.
    s.chord("ctrl+z");
    let g3 = s.wait_frame(g2, 1, "Ctrl+Z");
    let undone = s.screenshot("editor-undone.png");
    let d = diff_right_of(&undone, &before, x0);
    assert!(d < 0.05, "undo did not restore the picture ({d:.3} levels)");
    assert!(!s.title().ends_with('*'), "{}", s.title());
    // Ctrl+Shift+Z redoes it.
    s.chord("ctrl+shift+z");
    let g4 = s.wait_frame(g3, 1, "Ctrl+Shift+Z");
    let redone = s.screenshot("editor-redone.png");
    assert!(
        diff_right_of(&redone, &added, x0) < 0.05,
        "redo did not bring the sphere back"
    );

    // Ctrl+S writes the file, which loads back with the sphere.
    s.chord("ctrl+s");
    assert!(
        wait_until(Duration::from_secs(30), || !s.title().ends_with('*')),
        "Ctrl+S did not save: {}",
        s.title()
    );
    let (saved, _) = Scene::load(&scene).unwrap();
    assert_eq!(saved.objects.len(), 27);
    assert_eq!(saved.objects[26].kind.name(), "sphere");
    assert_eq!(s.last_generation(), g4, "saving restarted refinement");

    // Keyboard flight still works with the panel shown (it has no focus);
    // the title says the camera moved (not an unsaved edit).
    s.hold("w", 400);
    let g5 = s.wait_frame(g4, 1, "W with the panel shown");
    assert!(s.title().ends_with("(camera moved)"), "{}", s.title());
    // A lens key (2) after it: an unsaved edit, the question at quit.
    s.chord("2");
    s.wait_frame(g5, 1, "the lens key");
    assert!(s.title().ends_with('*'), "{}", s.title());

    // Escape with unsaved changes asks; Escape again cancels the question.
    s.chord("Escape");
    assert!(
        wait_until(Duration::from_secs(30), || s
            .rects(&ui_log)
            .contains_key("confirm discard")),
        "Escape did not ask about the unsaved changes"
    );
    assert!(s.app.try_wait().unwrap().is_none(), "quit without asking");
    s.chord("Escape");
    assert!(
        wait_until(Duration::from_secs(30), || !s
            .rects(&ui_log)
            .contains_key("confirm discard")),
        "Escape did not cancel the question"
    );
    // (The viewer still answering below shows that it did not quit.)
    assert!(s.app.try_wait().unwrap().is_none(), "the viewer quit on cancel");

    // Escape, then "Quit without saving": exits 0 and the file keeps the save.
    s.chord("Escape");
    s.click(&ui_log, "confirm discard");
    let mut status = None;
    wait_until(Duration::from_secs(30), || {
        status = s.app.try_wait().unwrap();
        status.is_some()
    });
    let status = status.expect("Quit without saving did not close the viewer");
    let mut err = String::new();
    if let Some(mut e) = s.app.stderr.take() {
        use std::io::Read;
        let _ = e.read_to_string(&mut err);
    }
    assert!(status.success(), "exit status {status:?}; stderr: {err}");
    let (after, _) = Scene::load(&scene).unwrap();
    assert_eq!(after, saved, "the flight and edit after the save were not written");
}

/// The bounding box (x0, y0, x1, y1, inclusive) of the pixels where `a` and
/// `b` differ by more than `level` in some channel (8-bit).
fn changed_box(a: &Image, b: &Image, level: u8) -> Option<(u32, u32, u32, u32)> {
    assert_eq!((a.width, a.height), (b.width, b.height));
    let (a8, b8) = (a.to_srgb8(), b.to_srgb8());
    let mut bx: Option<(u32, u32, u32, u32)> = None;
    for y in 0..a.height {
        for x in 0..a.width {
            let i = ((y * a.width + x) * 3) as usize;
            if (0..3).any(|c| a8[i + c].abs_diff(b8[i + c]) > level) {
                bx = Some(bx.map_or((x, y, x, y), |(x0, y0, x1, y1)| {
                    (x0.min(x), y0.min(y), x1.max(x), y1.max(y))
                }));
            }
        }
    }
    bx
}

impl Session<'_> {
    /// Waits (up to 60 s) for the viewer to exit; its status and stderr.
    fn wait_exit(&mut self, what: &str) -> (std::process::ExitStatus, String) {
        let mut status = None;
        wait_until(Duration::from_secs(60), || {
            status = self.app.try_wait().unwrap();
            status.is_some()
        });
        let status = status.unwrap_or_else(|| panic!("the viewer did not exit after {what}"));
        let mut err = String::new();
        if let Some(mut e) = self.app.stderr.take() {
            use std::io::Read;
            let _ = e.read_to_string(&mut err);
        }
        (status, err)
    }

    /// Presses `key` and waits until the window presented again.
    /// Presses F1 until a frame presented after the press shows the
    /// overlay in form `mode` (the frame log's `overlay`): a present that
    /// was already due before the key (a repaint, a refinement) is not
    /// taken for the key's.
    fn overlay_to(&self, mode: &str) {
        let n = self.frames().len();
        self.key("F1");
        let shows = |f: &serde_json::Value| f["overlay"] == mode;
        assert!(
            wait_until(Duration::from_secs(30), || self.frames()[n..].iter().any(shows)),
            "F1 never brought the overlay to {mode}"
        );
        // The newest line is what is on screen.
        assert!(
            wait_until(Duration::from_secs(10), || self.frames().last().is_some_and(shows)),
            "the overlay left {mode} by itself"
        );
    }
}

/// At 640×480 (started without XDG_RUNTIME_DIR, as on a bare X11 session):
/// the panel is a strip and opens and folds back; the overlay sits at the
/// picture's top-left, inside it, in compact and full form, and F1 cycles
/// compact → full → off → compact; after flying alone Escape quits at once;
/// nothing on stderr mentions XDG_RUNTIME_DIR.
#[test]
fn a_small_window_folds_the_panel_fits_the_overlay_and_quits_after_flying() {
    let _one = one_at_a_time();
    let x = Xvfb::start();
    let (dir, ui_log) = test_dir("small");
    let scene = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/cubes.toml");
    let args = ui_args(W, H, 600, &ui_log);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_lensview"));
    cmd.env_remove("XDG_RUNTIME_DIR");
    let mut s = Session::launch_with(cmd, &x, &dir, &scene, &args, dir.join("frames.jsonl"));

    // The panel is a strip: the picture keeps most of the width.
    let g1 = s.wait_frame(0, 1, "start");
    let first = s.frames().into_iter().find(|f| f["generation"] == g1).unwrap();
    let x0 = first["x0"].as_u64().unwrap() as u32;
    assert!(x0 > 0 && x0 <= 48, "the panel did not fold to a strip: {first}");
    assert_eq!(first["width"].as_u64().unwrap() as u32, W - x0);

    // The overlay: compact (the default), full, off.
    let compact = s.screenshot("small-compact.png");
    s.overlay_to("full");
    let full = s.screenshot("small-full.png");
    s.overlay_to("off");
    let off = s.screenshot("small-off.png");
    let cb = changed_box(&compact, &off, 40).expect("no compact overlay");
    let fb = changed_box(&full, &off, 40).expect("no full overlay");
    for (name, b) in [("compact", cb), ("full", fb)] {
        // At the picture's top-left (right of the strip), and inside it:
        // not cut off at the right or the bottom.
        assert!(b.0 >= x0 && b.0 < x0 + 24 && b.1 < 24, "{name} overlay at {b:?}");
        assert!(b.2 < W - 4 && b.3 < H - 4, "{name} overlay clipped: {b:?}");
    }
    assert!(fb.3 > cb.3 + 40, "full {fb:?} is not taller than compact {cb:?}");
    s.overlay_to("compact");
    let again = changed_box(&s.screenshot("small-again.png"), &off, 40).expect("F1 did not come back to compact");
    assert!(again.3.abs_diff(cb.3) <= 4, "compact again {again:?}, first {cb:?}");

    // The strip's button opens the panel; « folds it back.
    let g = s.last_generation();
    s.click(&ui_log, "open panel");
    let g = s.wait_frame_where(g, 1, "opening the panel", |f| f["x0"].as_u64().unwrap_or(0) >= 300);
    s.click(&ui_log, "fold panel");
    let g = s.wait_frame_where(g, 1, "folding the panel", |f| f["x0"].as_u64() == Some(x0 as u64));

    // Flying alone: the title says so, and Escape quits without a question.
    s.xdotool(&["windowfocus", "--sync", &s.window]);
    s.hold("w", 400);
    s.wait_frame(g, 1, "W");
    assert!(s.title().ends_with("(camera moved)"), "{}", s.title());
    s.key("Escape");
    let (status, err) = s.wait_exit("Escape after flying alone");
    assert!(status.success(), "exit status {status:?}; stderr: {err}");
    assert!(!err.contains("XDG_RUNTIME_DIR"), "stderr: {err}");
}

/// `--exit-after` closes the window while the unsaved-changes question is
/// up, with status 0.
#[test]
fn exit_after_closes_the_window_with_a_question_open() {
    let _one = one_at_a_time();
    let x = Xvfb::start();
    let (dir, ui_log) = test_dir("exit-after");
    let scene = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/cubes.toml");
    let args = ui_args(W, H, 45, &ui_log);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let mut s = Session::launch(&x, &dir, &scene, &args, dir.join("frames.jsonl"));
    let g1 = s.wait_frame(0, 1, "start");
    s.key("2");
    s.wait_frame(g1, 1, "the lens key");
    s.key("Escape");
    assert!(
        wait_until(Duration::from_secs(30), || s
            .rects(&ui_log)
            .contains_key("confirm discard")),
        "Escape after an edit did not ask (or the viewer had exited already)"
    );
    assert!(s.app.try_wait().unwrap().is_none(), "quit without asking");
    let (status, err) = s.wait_exit("--exit-after with the question open");
    assert!(status.success(), "exit status {status:?}; stderr: {err}");
}

/// The camera's projection of a world point to pixel coordinates of a
/// `W × H` picture (y down): `Camera::ray` inverted, written here again.
/// The magenta pixels (F′'s marker, `viewer::optics::F_BACK`) within 7
/// of `(px, py)`: their count and centroid (pixel centres at
/// half-integers).
fn magenta_around(img: &Image, px: f64, py: f64) -> (usize, [f64; 2]) {
    let rgb = img.to_srgb8();
    let (mut n, mut sx, mut sy) = (0, 0.0, 0.0);
    for y in (py as i64 - 7)..=(py as i64 + 7) {
        for x in (px as i64 - 7)..=(px as i64 + 7) {
            let p = &rgb[(y as usize * img.width as usize + x as usize) * 3..][..3];
            if p[0] > 200 && p[1] < 80 && p[2] > 200 {
                n += 1;
                sx += x as f64 + 0.5;
                sy += y as f64 + 0.5;
            }
        }
    }
    (n, [sx / n.max(1) as f64, sy / n.max(1) as f64])
}

fn project(cam: &lensview::camera::Camera, p: glam::DVec3) -> (f64, f64) {
    let d = p - cam.position;
    let z = d.dot(cam.forward());
    assert!(z > 0.0, "behind the camera");
    let tan = (cam.fov_y_deg.to_radians() / 2.0).tan();
    let aspect = W as f64 / H as f64;
    let (sx, sy) = (d.dot(cam.right()) / z / (tan * aspect), d.dot(cam.up()) / z / tan);
    ((sx + 1.0) * W as f64 / 2.0, (1.0 - sy) * H as f64 / 2.0)
}

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

/// Holding W for 2 s at 1280×720 shows the flight: the window presents
/// new pictures during the hold (steps coalesced, one per frame shown, not
/// one per event, which cancelled every picture before it was drawn), each
/// further along the way than the last; after the release the last pose
/// refines to the sample cap. The rate this reaches is measured by
/// `benches/viewer-flight.sh`, not asserted here.
#[test]
fn holding_a_key_shows_the_flight_and_converges_after_it() {
    let _one = one_at_a_time();
    let x = Xvfb::start();
    let (dir, _) = test_dir("held-key");
    let scene = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/cubes.toml");
    let args = [
        "--no-panel",
        "--width",
        "1280",
        "--height",
        "720",
        "--max-spp",
        "4",
        "--exit-after",
        "600",
    ];
    let s = Session::launch(&x, &dir, &scene, &args, dir.join("frames.jsonl"));
    let g0 = s.wait_frame(0, 4, "start");
    let start = s.frames().last().unwrap()["camera"][0].clone();
    let pos = |f: &serde_json::Value| -> [f64; 3] {
        let p = &f["camera"][0];
        [0, 1, 2].map(|i| p[i].as_f64().unwrap())
    };
    let p0 = [0, 1, 2].map(|i| start[i].as_f64().unwrap());
    let dist = |p: [f64; 3]| ((p[0] - p0[0]).powi(2) + (p[1] - p0[1]).powi(2) + (p[2] - p0[2]).powi(2)).sqrt();

    s.xdotool(&["windowfocus", "--sync", &s.window]);
    let before = s.frames().len();
    s.hold("w", 2000);
    let during: Vec<serde_json::Value> = s.frames()[before..].to_vec();
    let moved: Vec<&serde_json::Value> = during
        .iter()
        .filter(|f| f["generation"].as_u64().unwrap() > g0)
        .collect();
    let gens: std::collections::BTreeSet<u64> = moved.iter().map(|f| f["generation"].as_u64().unwrap()).collect();
    eprintln!(
        "held W 2 s: {} presents, {} generations shown, levels {:?}",
        during.len(),
        gens.len(),
        moved
            .iter()
            .map(|f| f["level"].as_str().unwrap_or(""))
            .collect::<Vec<_>>()
    );
    assert!(
        gens.len() >= 4,
        "holding W for 2 s showed {} pictures of the flight: {during:?}",
        gens.len()
    );
    // Each picture shown is further along the flight than the one before.
    let ds: Vec<f64> = moved.iter().map(|f| dist(pos(f))).collect();
    assert!(ds[0] > 0.0 && ds.windows(2).all(|w| w[1] >= w[0]), "{ds:?}");

    // Released: the last pose refines to the cap.
    let g = gens.iter().max().copied().unwrap();
    let last = s.wait_frame(g - 1, 4, "releasing W");
    let end = s.frames().into_iter().rev().find(|f| f["generation"] == last).unwrap();
    assert!(dist(pos(&end)) >= *ds.last().unwrap(), "{end}");
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
    s.key("Escape");
    let (status, err) = s.wait_exit("Escape");
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
    s.key("Escape");
    let (status, err) = s.wait_exit("Escape");
    assert!(status.success(), "exit status {status:?}; stderr: {err}");
}

/// Pixels within `tol` levels of `colour` in the window rectangle `r`
/// (`--ui-log`'s physical pixels): their count and the span of their x.
fn colour_in(img: &Image, r: &[f64], colour: [u8; 3], tol: i32) -> (usize, f64) {
    let rgb = img.to_srgb8();
    let (mut n, mut lo, mut hi) = (0, f64::INFINITY, f64::NEG_INFINITY);
    let clamp = |v: f64, max: u32| (v.max(0.0) as u32).min(max);
    for y in clamp(r[1], img.height)..clamp(r[3], img.height) {
        for x in clamp(r[0], img.width)..clamp(r[2], img.width) {
            let p = &rgb[(y as usize * img.width as usize + x as usize) * 3..][..3];
            if (0..3).all(|i| (i32::from(p[i]) - i32::from(colour[i])).abs() <= tol) {
                n += 1;
                lo = lo.min(f64::from(x));
                hi = hi.max(f64::from(x));
            }
        }
    }
    (n, if n > 0 { hi - lo + 1.0 } else { 0.0 })
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
    s.key("Escape");
    let (status, err) = s.wait_exit("Escape");
    assert!(status.success(), "exit status {status:?}; stderr: {err}");
}
