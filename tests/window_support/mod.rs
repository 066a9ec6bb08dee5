//! What the window tests share: an Xvfb server of their own (stopped when
//! dropped), the viewer session on it (launched, driven by `xdotool`,
//! screenshot by ImageMagick's `import`, killed when dropped), polling with
//! generous time-outs, and the picture comparisons. Included by
//! `tests/window.rs` and `tests/window_optics.rs`.

#![allow(dead_code)] // each test binary uses its own part

use lensview::render::Image;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

pub const W: u32 = 640;
pub const H: u32 = 480;

pub struct Xvfb {
    pub child: Child,
    pub display: String,
}

impl Xvfb {
    /// Starts a server on a display number of its own choosing: with
    /// `-displayfd` Xvfb picks a free number (clearing stale locks) and
    /// writes it to our pipe only once it accepts connections, so there is
    /// neither a race for the number nor a guess at when it is ready.
    pub fn start() -> Xvfb {
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
pub static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

pub fn one_at_a_time() -> std::sync::MutexGuard<'static, ()> {
    // A test that failed holding it poisons it; the next still runs alone.
    ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner())
}

pub fn wait_until(limit: Duration, mut f: impl FnMut() -> bool) -> bool {
    let end = Instant::now() + limit;
    while Instant::now() < end {
        if f() {
            return true;
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    false
}

pub fn dir() -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("window-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A fresh folder NAME for a test and the path of its `--ui-log` file.
pub fn test_dir(name: &str) -> (PathBuf, PathBuf) {
    let dir = dir().join(name);
    std::fs::create_dir_all(&dir).unwrap();
    let ui_log = dir.join("ui.json");
    let _ = std::fs::remove_file(&ui_log);
    (dir, ui_log)
}

/// `--width W --height H --max-spp 1 --exit-after SECONDS --ui-log LOG`.
pub fn ui_args(w: u32, h: u32, exit_after: u32, ui_log: &Path) -> Vec<String> {
    let mut v: Vec<String> = ["--width", &w.to_string(), "--height", &h.to_string(), "--max-spp", "1"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    v.extend(["--exit-after".into(), exit_after.to_string()]);
    v.extend(["--ui-log".into(), ui_log.display().to_string()]);
    v
}

pub struct Session<'a> {
    pub x: &'a Xvfb,
    pub app: Child,
    pub window: String,
    pub log: PathBuf,
    pub dir: PathBuf,
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
    pub fn launch(x: &'a Xvfb, dir: &Path, scene: &Path, args: &[&str], log: PathBuf) -> Session<'a> {
        let runtime = dir.join("xdg");
        std::fs::create_dir_all(&runtime).unwrap();
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_lensview"));
        cmd.env("XDG_RUNTIME_DIR", &runtime);
        Self::launch_with(cmd, x, dir, scene, args, log)
    }

    /// Like `launch`, with `cmd` (the binary, its environment) given.
    pub fn launch_with(
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

    pub fn xdotool(&self, args: &[&str]) -> String {
        let o = Command::new("xdotool")
            .env("DISPLAY", &self.x.display)
            .args(args)
            .output()
            .expect("xdotool is not installed");
        String::from_utf8_lossy(&o.stdout).trim().to_string()
    }

    /// Frame-log lines as JSON values.
    pub fn frames(&self) -> Vec<serde_json::Value> {
        std::fs::read_to_string(&self.log)
            .unwrap_or_default()
            .lines()
            .filter_map(|l| serde_json::from_str(l).ok())
            .collect()
    }

    /// Waits until a frame of a generation above `after`, refined to at
    /// least `spp`, has been presented; returns its generation.
    pub fn wait_frame(&self, after: u64, spp: u64, what: &str) -> u64 {
        self.wait_frame_where(after, spp, what, |_| true)
    }

    /// Like `wait_frame`, for a frame that also passes `pred`.
    pub fn wait_frame_where(&self, after: u64, spp: u64, what: &str, pred: impl Fn(&serde_json::Value) -> bool) -> u64 {
        let mut found = 0;
        let ok = wait_until(Duration::from_secs(120), || {
            found = self.latest_frame(after, spp, &pred);
            found > 0
        });
        assert!(ok, "no refined frame after {what}; frames: {:?}", self.frames().last());
        // Let the window draw it (the log is written right after presenting).
        std::thread::sleep(Duration::from_millis(300));
        found
    }

    /// The latest generation after `after` with at least `spp` samples
    /// whose frame passes `pred` (0: none yet).
    fn latest_frame(&self, after: u64, spp: u64, pred: &impl Fn(&serde_json::Value) -> bool) -> u64 {
        self.frames()
            .iter()
            .filter(|f| f["generation"].as_u64().unwrap_or(0) > after && f["spp"].as_u64().unwrap_or(0) >= spp)
            .filter(|f| pred(f))
            .map(|f| f["generation"].as_u64().unwrap())
            .max()
            .unwrap_or(0)
    }

    /// Clicks the button `name`, which goes away when it is taken (the
    /// panel's open and fold buttons), and waits for a frame after `after`
    /// that passes `pred` (`wait_frame_where`). A click can be lost on a
    /// loaded machine, and a converged viewer then presents nothing more:
    /// so where no such frame has come 20 s after a click (40 s after the
    /// second, 60 s after the third) and the button is still on screen,
    /// it clicks again, 3 clicks at most. A click that is taken hides the
    /// button at once (the UI log is rewritten by the UI pass that takes
    /// it), so a slow frame is never clicked twice.
    pub fn click_away(
        &self,
        ui_log: &Path,
        name: &str,
        after: u64,
        what: &str,
        pred: impl Fn(&serde_json::Value) -> bool,
    ) -> u64 {
        for attempt in 1..=3u64 {
            self.click(ui_log, name);
            let waited = Duration::from_secs(20 * attempt);
            let came = wait_until(waited, || self.latest_frame(after, 1, &pred) > 0);
            if came || !self.rects(ui_log).contains_key(name) {
                return self.wait_frame_where(after, 1, what, pred);
            }
            eprintln!("no frame {waited:?} after clicking `{name}`, and it is still on screen: clicking again");
        }
        panic!(
            "no refined frame after {what} (clicked `{name}` 3 times); frames: {:?}",
            self.frames().last()
        );
    }

    /// Waits (up to 30 s) until more than `n` frames are in the log: the
    /// window presented again after whatever was done since `n` was read.
    pub fn wait_present(&self, n: usize, what: &str) {
        assert!(
            wait_until(Duration::from_secs(30), || self.frames().len() > n),
            "nothing presented after {what}"
        );
    }

    /// Screenshots until `pred` holds (up to 30 s); returns the last one.
    pub fn wait_screenshot(&self, name: &str, what: &str, pred: impl Fn(&Image) -> bool) -> Image {
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

    pub fn last_generation(&self) -> u64 {
        self.frames()
            .iter()
            .filter_map(|f| f["generation"].as_u64())
            .max()
            .unwrap_or(0)
    }

    pub fn screenshot(&self, name: &str) -> Image {
        let path = self.dir.join(name);
        let st = Command::new("import")
            .env("DISPLAY", &self.x.display)
            .args(["-window", &self.window, &format!("png24:{}", path.display())])
            .status()
            .expect("ImageMagick import is not installed");
        assert!(st.success(), "import failed");
        Image::read_png(&path).unwrap()
    }

    pub fn key(&self, key: &str) {
        self.xdotool(&["key", "--window", &self.window, key]);
    }

    /// Types a key chord through the X server's input (XTEST), as a user
    /// would: modifiers reach the window's keyboard state. The window must
    /// have the focus.
    pub fn chord(&self, keys: &str) {
        self.xdotool(&["key", "--clearmodifiers", keys]);
    }

    pub fn title(&self) -> String {
        self.xdotool(&["getwindowname", &self.window])
    }

    /// The panel's named buttons and their rectangles (`--ui-log`).
    pub fn rects(&self, ui_log: &Path) -> serde_json::Map<String, serde_json::Value> {
        std::fs::read_to_string(ui_log)
            .ok()
            .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
            .and_then(|v| v.as_object().cloned())
            .unwrap_or_default()
    }

    /// Clicks the left button at window pixel `(x, y)`.
    pub fn click_at(&self, (x, y): (i64, i64)) {
        self.xdotool(&["mousemove", "--window", &self.window, &x.to_string(), &y.to_string()]);
        std::thread::sleep(Duration::from_millis(300));
        self.xdotool(&["mousedown", "1"]);
        std::thread::sleep(Duration::from_millis(150));
        self.xdotool(&["mouseup", "1"]);
        std::thread::sleep(Duration::from_millis(300));
    }

    /// Clicks the middle of the button called `name` once it is on screen.
    pub fn click(&self, ui_log: &Path, name: &str) {
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
        self.click_at(at.unwrap());
    }

    pub fn hold(&self, key: &str, ms: u64) {
        self.xdotool(&["keydown", "--window", &self.window, key]);
        std::thread::sleep(Duration::from_millis(ms));
        self.xdotool(&["keyup", "--window", &self.window, key]);
    }
}

/// Mean absolute difference of two images in 8-bit levels, over rows y0..y1.
pub fn diff(a: &Image, b: &Image, y0: u32, y1: u32) -> f64 {
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
pub fn diff_right_of(a: &Image, b: &Image, x0: u32) -> f64 {
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

pub fn spread(img: &Image) -> f64 {
    let b = img.to_srgb8();
    let mean = b.iter().map(|&x| x as f64).sum::<f64>() / b.len() as f64;
    (b.iter().map(|&x| (x as f64 - mean).powi(2)).sum::<f64>() / b.len() as f64).sqrt()
}

/// The bounding box (x0, y0, x1, y1, inclusive) of the pixels where `a` and
/// `b` differ by more than `level` in some channel (8-bit).
pub fn changed_box(a: &Image, b: &Image, level: u8) -> Option<(u32, u32, u32, u32)> {
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
    /// Presses Escape until the viewer exits, at most `presses` times (it
    /// closes what is open first, and with nothing unsaved wants a second
    /// press within `QUIT_AGAIN`, 3 s); its status and stderr.
    pub fn escape_out(&mut self, presses: usize) -> (std::process::ExitStatus, String) {
        for _ in 0..presses {
            self.key("Escape");
            if wait_until(Duration::from_secs(1), || self.app.try_wait().unwrap().is_some()) {
                break;
            }
        }
        self.wait_exit("Escape")
    }

    pub fn wait_exit(&mut self, what: &str) -> (std::process::ExitStatus, String) {
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
    pub fn overlay_to(&self, mode: &str) {
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

/// The camera's projection of a world point to pixel coordinates of a
/// `W × H` picture (y down): `Camera::ray` inverted, written here again.
/// The magenta pixels (F′'s marker, `viewer::optics::F_BACK`) within 7
/// of `(px, py)`: their count and centroid (pixel centres at
/// half-integers).
pub fn magenta_around(img: &Image, px: f64, py: f64) -> (usize, [f64; 2]) {
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

pub fn project(cam: &lensview::camera::Camera, p: glam::DVec3) -> (f64, f64) {
    let d = p - cam.position;
    let z = d.dot(cam.forward());
    assert!(z > 0.0, "behind the camera");
    let tan = (cam.fov_y_deg.to_radians() / 2.0).tan();
    let aspect = W as f64 / H as f64;
    let (sx, sy) = (d.dot(cam.right()) / z / (tan * aspect), d.dot(cam.up()) / z / tan);
    ((sx + 1.0) * W as f64 / 2.0, (1.0 - sy) * H as f64 / 2.0)
}

/// Pixels within `tol` levels of `colour` in the window rectangle `r`
/// (`--ui-log`'s physical pixels): their count and the span of their x.
pub fn colour_in(img: &Image, r: &[f64], colour: [u8; 3], tol: i32) -> (usize, f64) {
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
