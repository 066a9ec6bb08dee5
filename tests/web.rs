//! Issue #34: lensview in the browser. Builds the page (web/build.sh: the
//! library for wasm32 and wasm-bindgen), serves it on 127.0.0.1 and opens it
//! in headless Chromium (tools/web_page_test.py, which stops both), then:
//! the page's picture of cubes is the native renderer's bit for bit at the
//! same size, spp, seed and the portable kernel; W moves the camera and the
//! new picture is again the native one of the page's own scene file; a bad
//! scene file gets the command line's one-line error in the page; no
//! console error; two more presets (dispersion, a lens camera) are the
//! native pictures too. Needs Debian's rustc-web, rust-web-src, rust-web-llvm,
//! lld, chromium, wasm-bindgen-cli and Python's websocket-client (`.ci/run`
//! installs them); fails, naming what is missing, without them.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const SIZE: (u32, u32) = (160, 120);
const SPP: u32 = 4;
const SEED: u64 = 7;

/// The tools the test needs, each with how to get it.
fn missing_tools() -> Vec<&'static str> {
    let has = |cmd: &str, args: &[&str]| {
        Command::new(cmd)
            .args(args)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success())
    };
    let mut missing = Vec::new();
    if !has("/usr/bin/cargo", &["--version"]) || !Path::new("/usr/lib/rustlib/src/rust/library/std").is_dir() {
        missing.push("Debian's wasm32 Rust (apt-get install rustc-web cargo-web rust-web-src rust-web-llvm lld-22)");
    }
    if !has("wasm-bindgen", &["--version"]) {
        missing.push("wasm-bindgen (cargo install wasm-bindgen-cli --version <Cargo.lock's wasm-bindgen>)");
    }
    if !has("chromium", &["--version"]) {
        missing.push("chromium (apt-get install chromium)");
    }
    if !has("python3", &["-c", "import websocket"]) {
        missing.push("Python's websocket-client (python3 -m pip install websocket-client)");
    }
    missing
}

/// Runs `cmd` to the end or for `limit`, killing its whole process group
/// then (the page driver's Chromium and server with it).
fn run_bounded(cmd: &mut Command, limit: Duration, what: &str) -> (String, String) {
    use std::os::unix::process::CommandExt;
    let out = cmd
        .process_group(0)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn();
    let mut child = out.unwrap_or_else(|e| panic!("{what}: cannot start: {e}"));
    let pid = child.id() as i32;
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > limit {
            // SAFETY: kill(2) on the process group this test created for
            // the child (negative pid); no memory is involved.
            unsafe { libc::kill(-pid, libc::SIGKILL) };
            let _ = child.wait();
            panic!("{what}: still running after {limit:?}; killed");
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    let o = child.wait_with_output().unwrap();
    let (stdout, stderr) = (
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    );
    assert!(o.status.success(), "{what} failed ({}):\n{stdout}\n{stderr}", o.status);
    (stdout, stderr)
}

/// The native picture of `scene` (portable kernel) as RGB bytes.
fn native_rgb(scene: &Path, png: &Path) -> Vec<u8> {
    let o = Command::new(env!("CARGO_BIN_EXE_lensview"))
        .env("LENSVIEW_ISA", "portable")
        .arg("render")
        .arg(scene)
        .args(["--width", &SIZE.0.to_string(), "--height", &SIZE.1.to_string()])
        .args(["--spp", &SPP.to_string(), "--seed", &SEED.to_string(), "-o"])
        .arg(png)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(png).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(
        (info.width, info.height, info.color_type),
        (SIZE.0, SIZE.1, png::ColorType::Rgb)
    );
    buf.truncate(info.buffer_size());
    buf
}

/// The canvas's RGBA against the native RGB: every byte, alpha opaque.
fn assert_same_picture(canvas: &[u8], native: &[u8], what: &str) {
    assert_eq!(canvas.len(), native.len() / 3 * 4, "{what}: canvas size");
    let mut differ = 0;
    let mut first = None;
    let mut worst = 0;
    for (i, (c, n)) in canvas.chunks(4).zip(native.chunks(3)).enumerate() {
        assert_eq!(c[3], 255, "{what}: pixel {i} is not opaque");
        if c[..3] != *n {
            differ += 1;
            first.get_or_insert((i, [c[0], c[1], c[2]], [n[0], n[1], n[2]]));
            worst = worst.max((0..3).map(|k| c[k].abs_diff(n[k])).max().unwrap());
        }
    }
    assert!(
        differ == 0,
        "{what}: {differ} of {} pixels differ from the native picture (largest step {worst}; first (pixel, page, native): {first:?})",
        canvas.len() / 4
    );
}

/// The page's picture of preset `scene` (as `scenes/SCENE.toml`) is the
/// native one.
fn assert_preset_is_native(root: &Path, work: &Path, scene: &str) {
    let out = work.join(scene);
    let query = format!("scene={scene}.toml&w={}&h={}&spp={SPP}&seed={SEED}", SIZE.0, SIZE.1);
    let mut driver = Command::new("python3");
    driver
        .arg(root.join("tools/web_page_test.py"))
        .arg("--dist")
        .arg(work.join("dist"));
    driver.arg("--out").arg(&out).args(["--query", &query, "--measure"]);
    run_bounded(&mut driver, Duration::from_secs(300), scene);
    let report = std::fs::read_to_string(out.join("report.json")).unwrap();
    assert!(
        report.contains("\"console_errors\": []"),
        "{scene}: the page logged errors: {report}"
    );
    let page = std::fs::read(out.join("first.rgba")).unwrap();
    let scene_file = root.join("scenes").join(format!("{scene}.toml"));
    assert_same_picture(
        &page,
        &native_rgb(&scene_file, &work.join(format!("{scene}.png"))),
        scene,
    );
}

#[test]
fn the_page_renders_what_the_native_renderer_renders() {
    let missing = missing_tools();
    assert!(
        missing.is_empty(),
        "the web test needs: {}. .ci/run installs them.",
        missing.join("; ")
    );
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let work = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("web");
    let _ = std::fs::remove_dir_all(&work);
    std::fs::create_dir_all(&work).unwrap();
    let dist = work.join("dist");
    let t = Instant::now();
    run_bounded(
        Command::new("bash").arg(root.join("web/build.sh")).arg(&dist),
        Duration::from_secs(1800),
        "web/build.sh",
    );
    eprintln!("web/build.sh: {:.1} s", t.elapsed().as_secs_f64());

    let bad = work.join("bad.toml");
    std::fs::write(&bad, "[camera]\nposition = [0, 1, 5]\nfov = \"wide\"\n").unwrap();
    let out = work.join("page");
    let query = format!("scene=cubes&w={}&h={}&spp={SPP}&seed={SEED}", SIZE.0, SIZE.1);
    let t = Instant::now();
    let mut driver = Command::new("python3");
    driver
        .arg(root.join("tools/web_page_test.py"))
        .arg("--dist")
        .arg(&dist)
        .arg("--out")
        .arg(&out);
    driver.args(["--query", &query]).arg("--bad").arg(&bad);
    let (report, _) = run_bounded(
        &mut driver,
        Duration::from_secs(300),
        "the page test (tools/web_page_test.py)",
    );
    eprintln!("the page in Chromium: {:.1} s; {report}", t.elapsed().as_secs_f64());
    let report: String = std::fs::read_to_string(out.join("report.json")).unwrap();
    assert!(
        report.contains("\"console_errors\": []"),
        "the page logged errors: {report}"
    );

    let first = std::fs::read(out.join("first.rgba")).unwrap();
    assert_same_picture(
        &first,
        &native_rgb(&root.join("scenes/cubes.toml"), &work.join("first.png")),
        "cubes",
    );
    let moved = std::fs::read(out.join("moved.rgba")).unwrap();
    assert_ne!(first, moved, "W changed nothing on the page");
    let native_moved = native_rgb(&out.join("moved.toml"), &work.join("moved.png"));
    assert_same_picture(&moved, &native_moved, "cubes after W");

    // Two more presets, each by another path: dispersion (primitives) and a
    // lens camera, whose rays are traced one by one (camera-dgauss).
    for scene in ["primitives", "camera-dgauss"] {
        assert_preset_is_native(&root, &work, scene);
    }

    // The command line's refusal of the same file, named the same way.
    let o = Command::new(env!("CARGO_BIN_EXE_lensview"))
        .current_dir(&work)
        .args(["render", "bad.toml", "-o", "bad.png"])
        .output()
        .unwrap();
    assert!(!o.status.success());
    let cli = String::from_utf8_lossy(&o.stderr);
    let page = std::fs::read_to_string(out.join("error.txt")).unwrap();
    assert!(page.starts_with("error: bad.toml:"), "{page}");
    assert_eq!(
        page.trim_end(),
        cli.trim_end(),
        "the page's error line is not the command line's"
    );
}
