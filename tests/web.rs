//! Issue #34: lensview in the browser. Builds the page (web/build.sh: the
//! library for wasm32 with threads, and wasm-bindgen), serves it on
//! 127.0.0.1 and opens it in headless Chromium (tools/web_page_test.py,
//! which stops both), then, cross-origin isolated (threads): the page's
//! picture of cubes is the native renderer's bit for bit at the same size,
//! spp, seed and the portable kernel; W moves the camera and the lens key 2
//! edits the lens as the desktop does, and each new picture is again the
//! native one of the page's own scene file; the editing panel sets the
//! lens's r1 (the native picture again), refuses a bad r1 in one line,
//! Ctrl+Z and Redo bring back each picture bit for bit, and a glass picked
//! from its catalogue list is the native picture again; Save scene and
//! Save PNG download the edited scene and the canvas; a sphere from the
//! panel's Add menu is the desktop's new sphere and the native picture,
//! its Delete button the native picture again, and Undo brings it back; a bad scene file, opened or dropped,
//! gets the command line's one-line error in the page, and a good one
//! dropped is rendered as natively; every preset is the
//! native picture; no console error. The same in headless Firefox (over
//! WebDriver BiDi) and in WebKitGTK's MiniBrowser, Safari's engine (over
//! WebDriver, under Xvfb): the first picture, W, the lens key, the dropped
//! files and the presets, bit for bit (their drivers have no file-input or
//! download commands, and the panel is Chromium's part; WebKitGTK gives
//! WebDriver no console, so there the page's error line stands for it). Then not isolated, in
//! each of the three (WebKitGTK also without SharedArrayBuffer): the page's
//! one-thread build (no shared memory), a note that says so, and the same picture. Needs Debian's rustc-web,
//! rust-web-src, rust-web-llvm, lld, chromium, firefox-esr, webkit2gtk-driver,
//! xvfb-run, wasm-bindgen-cli and
//! Python's websocket-client (`.ci/run` installs them); fails, naming what
//! is missing, without them.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Size, spp and seed of the cubes page; of each preset's page.
const CUBES: Shot = Shot {
    size: (160, 120),
    spp: 4,
    seed: 7,
};
const PRESETS: Shot = Shot {
    size: (64, 48),
    spp: 2,
    seed: 3,
};

#[derive(Clone, Copy)]
struct Shot {
    size: (u32, u32),
    spp: u32,
    seed: u64,
}

impl Shot {
    fn query(&self) -> String {
        let Shot {
            size: (w, h),
            spp,
            seed,
        } = self;
        format!("w={w}&h={h}&spp={spp}&seed={seed}")
    }
}

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
    if !has("firefox-esr", &["--version"]) {
        missing.push("firefox (apt-get install firefox-esr)");
    }
    if !Path::new("/usr/bin/WebKitWebDriver").exists() || !has("xvfb-run", &["--help"]) {
        missing.push("WebKit's driver and xvfb-run (apt-get install webkit2gtk-driver xvfb xauth)");
    }
    if !has("python3", &["-c", "import websocket"]) {
        missing.push("Python's websocket-client (python3 -m pip install websocket-client)");
    }
    missing
}

/// Runs `cmd` to the end or for `limit`, killing its whole process group
/// then (the page driver's browser and server with it). Its output is read
/// as it comes (threads), so a child that writes more than a pipe holds
/// never blocks on it.
fn run_bounded(cmd: &mut Command, limit: Duration, what: &str) -> (String, String) {
    use std::io::Read;
    use std::os::unix::process::CommandExt;
    let out = cmd
        .process_group(0)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn();
    let mut child = out.unwrap_or_else(|e| panic!("{what}: cannot start: {e}"));
    let drain = |mut pipe: Box<dyn Read + Send>| {
        std::thread::spawn(move || {
            let mut bytes = Vec::new();
            let _ = pipe.read_to_end(&mut bytes);
            String::from_utf8_lossy(&bytes).into_owned()
        })
    };
    let stdout = drain(Box::new(child.stdout.take().unwrap()));
    let stderr = drain(Box::new(child.stderr.take().unwrap()));
    let pid = child.id() as i32;
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if start.elapsed() > limit {
            // SAFETY: kill(2) on the process group this test created for
            // the child (negative pid); no memory is involved.
            unsafe { libc::kill(-pid, libc::SIGKILL) };
            let _ = child.wait();
            panic!("{what}: still running after {limit:?}; killed");
        }
        std::thread::sleep(Duration::from_millis(100));
    };
    // Whatever the child left running in its group (a browser's helper
    // process) goes too, and with it the last holder of its pipes.
    // SAFETY: as above.
    unsafe { libc::kill(-pid, libc::SIGKILL) };
    let (stdout, stderr) = (stdout.join().unwrap(), stderr.join().unwrap());
    assert!(status.success(), "{what} failed ({status}):\n{stdout}\n{stderr}");
    (stdout, stderr)
}

/// The native picture of `scene` (portable kernel) as RGB bytes.
fn native_rgb(scene: &Path, png: &Path, shot: Shot) -> Vec<u8> {
    let o = Command::new(env!("CARGO_BIN_EXE_lensview"))
        .env("LENSVIEW_ISA", "portable")
        .arg("render")
        .arg(scene)
        .args([
            "--width",
            &shot.size.0.to_string(),
            "--height",
            &shot.size.1.to_string(),
        ])
        .args(["--spp", &shot.spp.to_string(), "--seed", &shot.seed.to_string(), "-o"])
        .arg(png)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (size, colour, pixels) = read_png(png);
    assert_eq!((size, colour), (shot.size, png::ColorType::Rgb));
    pixels
}

/// A PNG's size, colour type and pixels.
fn read_png(path: &Path) -> ((u32, u32), png::ColorType, Vec<u8>) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    buf.truncate(info.buffer_size());
    ((info.width, info.height), info.color_type, buf)
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

/// Runs the page driver with `args` into `out`; its report (JSON text),
/// checked for console errors.
fn drive(root: &Path, dist: &Path, out: &Path, args: &[&str]) -> String {
    let t = Instant::now();
    // WebKitGTK needs an X display: its own Xvfb, stopped with it.
    let mut driver = if args.contains(&"webkit") {
        let mut c = Command::new("xvfb-run");
        c.args(["-a", "python3"]);
        c
    } else {
        Command::new("python3")
    };
    driver.arg(root.join("tools/web_page_test.py")).arg("--dist").arg(dist);
    driver.arg("--out").arg(out).args(args);
    run_bounded(
        &mut driver,
        Duration::from_secs(300),
        "the page test (tools/web_page_test.py)",
    );
    let report = std::fs::read_to_string(out.join("report.json")).unwrap();
    eprintln!("the page test {args:?}: {:.1} s; {report}", t.elapsed().as_secs_f64());
    assert!(
        report.contains("\"console_errors\": []"),
        "the page logged errors: {report}"
    );
    report
}

/// The names of the presets (`scenes/*.toml`), sorted.
fn presets(root: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(root.join("scenes"))
        .unwrap()
        .filter_map(|e| {
            let name = e.unwrap().file_name().into_string().unwrap();
            name.strip_suffix(".toml").map(str::to_string)
        })
        .collect();
    v.sort();
    v
}

/// The threads the page reported, from the report's JSON.
fn page_threads(report: &str) -> u32 {
    report_number(report, "threads")
}

/// The first number named `key` in the report's JSON.
fn report_number(report: &str, key: &str) -> u32 {
    let name = format!("\"{key}\": ");
    let at = report.find(&name).unwrap_or_else(|| panic!("the report has no {key}")) + name.len();
    let digits: String = report[at..].chars().take_while(char::is_ascii_digit).collect();
    digits.parse().unwrap()
}

/// The command line's refusal of `bad.toml` in `work`.
fn cli_error(work: &Path) -> String {
    let o = Command::new(env!("CARGO_BIN_EXE_lensview"))
        .current_dir(work)
        .args(["render", "bad.toml", "-o", "bad.png"])
        .output()
        .unwrap();
    assert!(!o.status.success());
    String::from_utf8_lossy(&o.stderr).trim_end().to_string()
}

/// The cubes page after W and the lens key 2: each picture is the native
/// one of the page's scene file, and the key made the desktop's edit
/// (`edit::apply` of the library's lens key table) of the scene before.
fn assert_keys_give_native(out: &Path) -> Vec<u8> {
    let first = std::fs::read(out.join("first.rgba")).unwrap();
    let moved = std::fs::read(out.join("moved.rgba")).unwrap();
    assert_ne!(first, moved, "W changed nothing on the page");
    let native_moved = native_rgb(&out.join("moved.toml"), &out.join("moved.png"), CUBES);
    assert_same_picture(&moved, &native_moved, "cubes after W");
    let lens = std::fs::read(out.join("lens.rgba")).unwrap();
    assert_ne!(moved, lens, "the lens key changed nothing on the page");
    let native_lens = native_rgb(&out.join("lens.toml"), &out.join("lens.png"), CUBES);
    assert_same_picture(&lens, &native_lens, "cubes after the lens key 2");
    let text = |name: &str| std::fs::read_to_string(out.join(name)).unwrap();
    let (mut want, _) = lensview::scene::Scene::parse("moved", &text("moved.toml")).unwrap();
    let edit = lensview::edit::lens_key("Digit2").unwrap();
    lensview::edit::apply(&mut want, edit);
    let (got, _) = lensview::scene::Scene::parse("lens", &text("lens.toml")).unwrap();
    assert!(
        got == want,
        "the page's lens key is not the desktop's edit: lenses {:?}, want {:?}",
        got.lenses,
        want.lenses
    );
    // Mouse-look turns the camera as the desktop's drag (flight::look).
    let looked = std::fs::read(out.join("looked.rgba")).unwrap();
    assert_ne!(looked, lens, "mouse-look changed nothing on the page");
    let native_looked = native_rgb(&out.join("looked.toml"), &out.join("looked.png"), CUBES);
    assert_same_picture(&looked, &native_looked, "cubes after mouse-look");
    let (turned, _) = lensview::scene::Scene::parse("looked", &text("looked.toml")).unwrap();
    use lensview::edit::{Document, Source};
    let pose = |s| Document::new(s, Source::Default).unwrap().camera_pose();
    assert_eq!(pose(turned), lensview::flight::look(pose(got), 40.0, -10.0));
    lens
}

/// The light key L on the page: the desktop's edit (the library's scene
/// key, through a document) of the scene before, and its native picture.
fn assert_light_key(out: &Path) {
    use lensview::edit::{Document, KeyState, Source, scene_key};
    let text = |name: &str| std::fs::read_to_string(out.join(name)).unwrap();
    let (before, _) = lensview::scene::Scene::parse("unlit", &text("unlit.toml")).unwrap();
    let mut doc = Document::new(before, Source::Default).unwrap();
    doc.scene_key(scene_key("KeyL").unwrap(), &mut KeyState::default())
        .unwrap();
    let (got, _) = lensview::scene::Scene::parse("light", &text("light.toml")).unwrap();
    assert!(
        got.lights == doc.scene().lights,
        "the page's light key is not the desktop's: {:?}, want {:?}",
        got.lights,
        doc.scene().lights
    );
    let light = std::fs::read(out.join("light.rgba")).unwrap();
    let native = native_rgb(&out.join("light.toml"), &out.join("light.png"), CUBES);
    assert_same_picture(&light, &native, "cubes after the light key L");
}

/// The r1 the page's panel test types, and the one it must refuse
/// (tools/web_page_test.py's defaults).
const PANEL_R1: f64 = 3.5;
const PANEL_BAD: f64 = 0.1;
const PANEL_GLASS: &str = "N-SF5";

/// The panel after the lens key: r1 typed into it is the library's edit
/// of the scene before (`Document::set_lens`), and the picture the native
/// one of the page's scene file; a refused r1 gets the library's one-line
/// error and the field shows the scene's value again; Ctrl+Z brings back
/// the picture before bit for bit, Redo the edited one; a glass picked
/// from the catalogue is the library's and the native picture again; Save
/// scene saves the edited scene and Save PNG the canvas. The overlay shows
/// the stage.
fn assert_panel_edits(work: &Path, out: &Path, lens: &[u8]) {
    use lensview::edit::{Document, Source};
    use lensview::scene::Scene;
    let text = |name: &str| std::fs::read_to_string(out.join(name)).unwrap();
    let (before, _) = Scene::parse("lens", &text("lens.toml")).unwrap();
    let (got, _) = Scene::parse("panel", &text("panel.toml")).unwrap();
    let mut doc = Document::new(before, Source::Default).unwrap();
    let mut l = doc.scene().lenses[0].clone();
    l.r1 = PANEL_R1;
    doc.set_lens(0, l.clone()).unwrap();
    assert!(&got == doc.scene(), "the panel's r1: lenses {:?}", got.lenses);
    let panel = std::fs::read(out.join("panel.rgba")).unwrap();
    assert_ne!(panel, lens, "the panel's r1 changed nothing on the page");
    let native = native_rgb(&out.join("panel.toml"), &work.join("panel.png"), CUBES);
    assert_same_picture(&panel, &native, "cubes after r1 in the panel");
    l.r1 = PANEL_BAD;
    let refused = doc.set_lens(0, l).unwrap_err();
    let want = format!("error: {}", lensview::scene::escape_controls(&refused.to_string()));
    assert_eq!(text("panel-error.txt"), want, "the refused r1's error line");
    let report = text("report.json");
    let field = format!("\"panel_field_after_error\": \"{PANEL_R1}\"");
    assert!(report.contains(&field), "the field after the refusal: {report}");
    assert!(
        report.contains("\"undone_error\": \"\""),
        "undo clears the error: {report}"
    );
    let undone = std::fs::read(out.join("undone.rgba")).unwrap();
    assert_same_picture(&undone, &rgb_of(lens), "Ctrl+Z after the panel's r1");
    let redone = std::fs::read(out.join("redone.rgba")).unwrap();
    assert!(redone == panel, "Redo: not the edited picture");
    // A catalogue glass picked from the list: the library's glass, and the
    // native picture of the page's scene.
    let (got, _) = Scene::parse("glass", &text("glass.toml")).unwrap();
    let mut l = doc.scene().lenses[0].clone();
    l.n = lensview::scene::file::IndexFile::Glass(lensview::glass::lookup(PANEL_GLASS).unwrap());
    doc.set_lens(0, l).unwrap();
    assert!(&got == doc.scene(), "the panel's glass: lenses {:?}", got.lenses);
    let glass = std::fs::read(out.join("glass.rgba")).unwrap();
    assert_ne!(glass, redone, "the panel's glass changed nothing on the page");
    let native = native_rgb(&out.join("glass.toml"), &work.join("glass.png"), CUBES);
    assert_same_picture(&glass, &native, "cubes after the glass N-SF5 in the panel");
    // Save scene and Save PNG: the edited scene's file and the canvas.
    assert_eq!(text("saved.toml"), text("glass.toml"), "Save scene");
    let (size, colour, png) = read_png(&out.join("saved.png"));
    assert_eq!((size, colour), (CUBES.size, png::ColorType::Rgba), "Save PNG");
    assert!(png == glass, "Save PNG: the file is not the canvas");
    let overlay = format!("\"overlay\": \"{0} spp of {0} spp (done), ", CUBES.spp);
    assert!(report.contains(&overlay), "the overlay: {report}");
}

/// F6 and F7 on the page (after the panel's edits): the optics overlay's
/// canvas has drawn pixels, F′ among its labels; the analysis panel shows
/// the library's SVG figures (the cross-section, LSA, spot and distortion;
/// a second spot with the field at 5°); the picture's canvas and its
/// renders are untouched (display only).
fn assert_optics(report: &str) {
    let pixels = report_number(report, "overlay_pixels");
    assert!(pixels > 200, "the optics overlay drew {pixels} pixels: {report}");
    assert!(report.contains("\"F'\""), "no F' label in the overlay: {report}");
    assert_eq!(report_number(report, "svgs"), 4, "the analysis's figures: {report}");
    assert_eq!(report_number(report, "svgs_at_5_deg"), 5, "the spot at 5°: {report}");
    for unchanged in ["renders_unchanged", "canvas_unchanged", "renders_unchanged_at_5_deg"] {
        assert!(
            report.contains(&format!("\"{unchanged}\": true")),
            "{unchanged}: the optics touched the picture: {report}"
        );
    }
    assert!(report.contains("Longitudinal spherical aberration"), "{report}");
}

/// The panel's Add menu, a sphere: the desktop's *Add* form's (the
/// library's `NewItem::of` and `Document::add_new`) in the scene the page
/// had, and the native picture of the page's scene; its Delete button
/// removes it (`Document::delete`, the native picture again), and Undo
/// brings the sphere's picture back bit for bit.
fn assert_panel_adds(work: &Path, out: &Path) {
    use lensview::edit::document::{NEW_DISTANCE, NewItem};
    use lensview::edit::{Document, Placement, Source};
    use lensview::scene::Scene;
    let text = |name: &str| std::fs::read_to_string(out.join(name)).unwrap();
    let (before, _) = Scene::parse("glass", &text("glass.toml")).unwrap();
    let mut doc = Document::new(before, Source::Default).unwrap();
    let at = doc.place(Placement::InFrontOfCamera(NEW_DISTANCE));
    let sphere = doc.add_new(NewItem::of("sphere", "", at).unwrap()).unwrap();
    let (got, _) = Scene::parse("added", &text("added.toml")).unwrap();
    assert!(&got == doc.scene(), "the panel's sphere: objects {:?}", got.objects);
    let report = text("report.json");
    let lensview::edit::Item::Object(i) = sphere else {
        unreachable!()
    };
    assert!(
        report.contains(&format!("\"added_selected\": \"object:{i}\"")),
        "the new sphere is selected: {report}"
    );
    let added = std::fs::read(out.join("added.rgba")).unwrap();
    let native = native_rgb(&out.join("added.toml"), &work.join("added.png"), CUBES);
    assert_same_picture(&added, &native, "cubes after adding a sphere in the panel");
    doc.delete(sphere).unwrap();
    let (got, _) = Scene::parse("deleted", &text("deleted.toml")).unwrap();
    assert!(&got == doc.scene(), "the panel's Delete: objects {:?}", got.objects);
    let deleted = std::fs::read(out.join("deleted.rgba")).unwrap();
    assert_ne!(deleted, added, "Delete changed nothing on the page");
    let native = native_rgb(&out.join("deleted.toml"), &work.join("deleted.png"), CUBES);
    assert_same_picture(&deleted, &native, "cubes after deleting the sphere in the panel");
    let undeleted = std::fs::read(out.join("undeleted.rgba")).unwrap();
    assert!(undeleted == added, "Undo after Delete: not the sphere's picture");
}

/// RGBA bytes as RGB (for [`assert_same_picture`]'s native side).
fn rgb_of(rgba: &[u8]) -> Vec<u8> {
    rgba.chunks(4).flat_map(|p| [p[0], p[1], p[2]]).collect()
}

/// Cross-origin isolated (`work/dist` served with COOP/COEP): one thread a
/// core; cubes, W, the lens key, saving; the bad file opened and dropped,
/// a good one dropped; every preset; each picture the native one.
fn assert_isolated_page(root: &Path, work: &Path, query: &str, browser: &str) {
    let bad = work.join("bad.toml");
    std::fs::write(&bad, "[camera]\nposition = [0, 1, 5]\nfov = \"wide\"\n").unwrap();
    let (out, names) = (work.join(format!("page-{browser}")), presets(root));
    let good = root.join("scenes/focal-spot.toml");
    let (bad_arg, good_arg) = (bad.to_str().unwrap(), good.to_str().unwrap());
    let presets = (names.join(","), PRESETS.query());
    let args = [
        "--query",
        query,
        "--bad",
        bad_arg,
        "--good",
        good_arg,
        "--browser",
        browser,
    ];
    let more = ["--presets", &presets.0, "--preset-query", &presets.1];
    let report = drive(root, &work.join("dist"), &out, &[&args[..], &more[..]].concat());
    assert!(
        report.contains("\"cross_origin_isolated\": true"),
        "{browser}: {report}"
    );
    if browser == "chromium" {
        assert_optics(&report);
    }
    // One thread a core as the browser counts them (WebKit rounds the
    // count it gives pages: 4 on this 2-core machine).
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get()) as u32;
    let counted = report_number(&report, "hardware_concurrency");
    // The page falls back to one thread (and says so) when its thread pool
    // twice did not start (main.js, `stuckStarting`).
    let fell_back = report.contains("the thread pool did not start");
    let want = if fell_back { 1 } else { counted };
    assert_eq!(page_threads(&report), want, "{browser}: threads: one a core");
    if browser != "webkit" {
        assert_eq!(counted, cores, "{browser}: hardwareConcurrency");
    }
    let cubes = root.join("scenes/cubes.toml");
    let first = std::fs::read(out.join("first.rgba")).unwrap();
    let what = format!("cubes in {browser}");
    assert_same_picture(&first, &native_rgb(&cubes, &out.join("first.png"), CUBES), &what);
    let lens = assert_keys_give_native(&out);
    if browser == "chromium" {
        assert_panel_edits(work, &out, &lens);
        assert_panel_adds(work, &out);
        assert_light_key(&out);
    }
    for name in &names {
        let page = std::fs::read(out.join(format!("preset-{name}.rgba"))).unwrap();
        let scene = root.join("scenes").join(format!("{name}.toml"));
        let native = native_rgb(&scene, &out.join(format!("{name}.png")), PRESETS);
        assert_same_picture(&page, &native, &format!("{name} in {browser}"));
    }
    if browser == "chromium" {
        // The Presets menu lists every shipped scene and opens the one picked.
        assert_eq!(
            report_number(&report, "menu_options") as usize,
            names.len() + 1,
            "{report}"
        );
        let page = std::fs::read(out.join("menu-focal-spot.rgba")).unwrap();
        let scene = root.join("scenes/focal-spot.toml");
        let native = native_rgb(&scene, &out.join("menu-focal-spot.png"), PRESETS);
        assert_same_picture(&page, &native, "focal-spot picked from the Presets menu");
    }
    let dropped = std::fs::read(out.join("good.rgba")).unwrap();
    let native = native_rgb(&good, &out.join("good.png"), CUBES);
    assert_same_picture(&dropped, &native, "focal-spot.toml dropped on the page");
    let cli = cli_error(work);
    // Firefox's BiDi cannot fill a file input: the file is dropped there.
    let files: &[&str] = if browser == "chromium" {
        &["error.txt", "dropped.txt"]
    } else {
        &["dropped.txt"]
    };
    for file in files {
        let page = std::fs::read_to_string(out.join(file)).unwrap();
        assert!(page.starts_with("error: bad.toml:"), "{browser} {file}: {page}");
        let why = format!("{browser} {file}: the page's error line is not the command line's");
        assert_eq!(page.trim_end(), cli, "{why}");
    }
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

    let query = format!("scene=cubes&{}", CUBES.query());
    assert_isolated_page(&root, &work, &query, "chromium");
    assert_isolated_page(&root, &work, &query, "firefox");
    assert_isolated_page(&root, &work, &query, "webkit");

    for browser in ["chromium", "firefox", "webkit"] {
        assert_plain_page(&root, &work, &query, browser);
    }
}

/// Not isolated (`work/dist` served without COOP/COEP; WebKitGTK without
/// `JSC_useSharedArrayBuffer` too): the worker loads the one-thread build
/// (`pkg-st`, no shared memory), which Firefox and WebKit run where they
/// refuse the threaded one; the note says so; cubes is native's picture;
/// no console error (`drive`).
fn assert_plain_page(root: &Path, work: &Path, query: &str, browser: &str) {
    let out = work.join(format!("plain-{browser}"));
    let args = ["--query", query, "--measure", "--no-isolation", "--browser", browser];
    let report = drive(root, &work.join("dist"), &out, &args);
    assert!(
        report.contains("\"cross_origin_isolated\": false"),
        "{browser}: {report}"
    );
    assert_eq!(page_threads(&report), 1, "{browser}: {report}");
    assert!(
        report.contains("\"note\": \"one thread: serve with COOP/COEP for threads\""),
        "{browser}: {report}"
    );
    let cubes = root.join("scenes/cubes.toml");
    let plain = std::fs::read(out.join("first.rgba")).unwrap();
    let native = native_rgb(&cubes, &out.join("first.png"), CUBES);
    assert_same_picture(&plain, &native, &format!("cubes, one thread, {browser}"));
}
