//! Issue 30, parts 2–4: the files a command reads and writes, as a user runs
//! it. Only regular files are read (a FIFO never blocks); photons and
//! lights count in the work budget; no output is an input or another
//! output; a file with other hard links is not replaced; SIGTERM and SIGHUP
//! clean up as Ctrl-C does; a failed command leaves nothing behind; every
//! output is checked before any work; an exact result is plotted.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_lensview"))
}

fn scene(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes").join(name)
}

fn fresh_dir(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("cli-files").join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The names in `d`, sorted.
fn listing(d: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Runs `lensview args`, killed after `secs` (a hang fails the test).
fn run_within(secs: u64, args: &[&str]) -> Output {
    let mut child = bin()
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > Duration::from_secs(secs) {
            child.kill().unwrap();
            panic!("lensview {args:?} still running after {secs} s");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    child.wait_with_output().unwrap()
}

/// One line on stderr, exit status 1, and the line contains each of `words`.
fn refused(o: &Output, words: &[&str]) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    for w in words {
        assert!(err.contains(w), "{w:?} not in {err}");
    }
}

fn mkfifo(p: &Path) {
    assert!(Command::new("mkfifo").arg(p).status().unwrap().success());
}

/// 30.2: a FIFO or a device given as an input is refused at once, by every
/// command that reads a file; before, `render FIFO` blocked in open(2).
#[test]
fn a_fifo_or_device_as_input_is_refused_without_blocking() {
    let d = fresh_dir("fifo-input");
    let fifo = d.join("scene.toml");
    mkfifo(&fifo);
    let out = d.join("o.png");
    let csv = d.join("c.csv");
    let plot = d.join("c.png");
    let cases: [Vec<&str>; 5] = [
        vec!["render", s(&fifo), "-o", s(&out), "--width", "4", "--height", "4"],
        vec!["converge", s(&fifo), "--csv", s(&csv), "--plot", s(&plot)],
        vec!["lens", "trace", s(&fifo)],
        vec!["view", s(&fifo)],
        vec!["render", "/dev/zero", "-o", s(&out), "--width", "4", "--height", "4"],
    ];
    for args in &cases {
        let o = run_within(20, args);
        let what = if args.contains(&"/dev/zero") {
            "it is a character device, not a regular file"
        } else {
            "it is a FIFO, not a regular file"
        };
        refused(
            &o,
            &[
                what,
                if args.contains(&"/dev/zero") {
                    "/dev/zero"
                } else {
                    s(&fifo)
                },
            ],
        );
    }
    assert_eq!(listing(&d), ["scene.toml"]);
}

/// A scene of `n` point lights around the cubes scene's lens (caustics on
/// or off).
fn many_lights(d: &Path, n: usize, caustics: bool) -> PathBuf {
    let mut text = std::fs::read_to_string(scene("cubes.toml")).unwrap().replacen(
        "[render]",
        &format!("[render]\ncaustics = {caustics}"),
        1,
    );
    for i in 1..n {
        text += &format!(
            "\n[[lights]]\ntype = \"point\"\nposition = [{}, 10, {}]\nintensity = 5\n",
            i % 40,
            i / 40
        );
    }
    let p = d.join(format!("lights-{n}-{caustics}.toml"));
    std::fs::write(&p, text).unwrap();
    p
}

/// 30.2: photons (passes × photons a pass × lights) and the lights a sample
/// shades count in the work budget, and a render's photon passes are cut to
/// 2^28 photons: 1 pixel at 65536 spp (2^32 photons asked for) finishes
/// within the cap; what would trace too many photons in one pass, or shade
/// too many lights, is refused at once.
#[test]
fn photon_and_light_work_is_in_the_budget() {
    let d = fresh_dir("photon-work");
    let out = d.join("o.png");
    let one_pixel = ["--width", "1", "--height", "1"];
    let o = run_within(
        120,
        &[
            &["render", s(&scene("cubes.toml")), "-o", s(&out), "--spp", "65536"][..],
            &one_pixel,
        ]
        .concat(),
    );
    let said = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let passes: u32 = said
        .split("caustics: ")
        .nth(1)
        .unwrap()
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(passes <= 8192, "{said}");
    // 40 000 lights: one pass alone is 1.3e9 photons (5.2e9 samples of work).
    let lights = many_lights(&d, 40_000, true);
    let o = run_within(
        20,
        &[&["render", s(&lights), "-o", s(&out), "--spp", "1"][..], &one_pixel].concat(),
    );
    refused(
        &o,
        &[
            "the render is",
            "shading 40000 lights",
            "1.31e9 photons",
            "the limit is 4.29e9 (2^32)",
        ],
    );
    // Without caustics, 10 000 lights make each sample 2500 times the work.
    let lights = many_lights(&d, 10_000, false);
    let o = run_within(
        20,
        &[
            "render",
            s(&lights),
            "-o",
            s(&out),
            "--width",
            "400",
            "--height",
            "300",
            "--spp",
            "16",
        ],
    );
    refused(&o, &["shading 10000 lights", "0.00e0 photons"]);
    // The same scene at one sample of a few pixels is accepted.
    let o = run_within(
        120,
        &[
            "render",
            s(&lights),
            "-o",
            s(&out),
            "--width",
            "4",
            "--height",
            "3",
            "--spp",
            "1",
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(listing(&d).len(), 3);
}

/// 30.3: an output that is an input (by any name: itself, a hard link, a
/// symbolic link) or another output is refused before any work, and every
/// file is as it was.
#[test]
fn an_output_that_is_an_input_or_another_output_is_refused() {
    let d = fresh_dir("same-file");
    let sc = d.join("sc.toml");
    std::fs::copy(scene("cubes.toml"), &sc).unwrap();
    let sc_png = d.join("sc.png");
    std::fs::copy(scene("cubes.toml"), &sc_png).unwrap();
    let hard = d.join("hard.toml");
    std::fs::hard_link(&sc, &hard).unwrap();
    let soft = d.join("soft.csv");
    std::os::unix::fs::symlink(&sc, &soft).unwrap();
    let new = d.join("x.out");
    let small = [
        "--width",
        "4",
        "--height",
        "4",
        "--max-spp",
        "1",
        "--reference-spp",
        "1",
    ];
    let cases: Vec<(Vec<&str>, [&str; 2])> = vec![
        (
            vec!["converge", s(&sc), "--csv", s(&sc), "--plot", s(&new)],
            ["--csv", "is the same file as the scene"],
        ),
        (
            vec!["converge", s(&sc), "--csv", s(&new), "--plot", s(&sc)],
            ["--plot", "refusing to write over an input"],
        ),
        (
            vec!["converge", s(&hard), "--csv", s(&soft), "--plot", s(&new)],
            ["soft.csv is the same file as the scene", "hard.toml"],
        ),
        (
            vec!["render", s(&sc_png), "-o", s(&sc_png)],
            ["-o", "sc.png is the same file as the scene"],
        ),
        (
            vec!["converge", s(&sc), "--csv", s(&new), "--plot", s(&new)],
            ["--plot", "is the same file as --csv"],
        ),
        (
            vec!["view", s(&sc), "--frame-log", s(&hard)],
            ["--frame-log", "the same file as the scene"],
        ),
    ];
    for (args, words) in &cases {
        let args = [&args[..], &small[..if args[0] == "converge" { 8 } else { 0 }]].concat();
        refused(&run_within(20, &args), words);
    }
    let text = std::fs::read_to_string(scene("cubes.toml")).unwrap();
    for p in [&sc, &sc_png, &hard, &soft] {
        assert_eq!(std::fs::read_to_string(p).unwrap(), text);
    }
    assert_eq!(listing(&d), ["hard.toml", "sc.png", "sc.toml", "soft.csv"]);
}

/// 30.3: a file with another hard link is not replaced (that would split
/// the link, the other name keeping the old content): refused, both names
/// unchanged; once the other link is gone it is replaced.
#[test]
fn a_hard_linked_output_is_refused() {
    let d = fresh_dir("hard-link");
    let (h1, h2) = (d.join("h1.png"), d.join("h2.png"));
    std::fs::write(&h1, "old").unwrap();
    std::fs::hard_link(&h1, &h2).unwrap();
    let render = |out: &Path| {
        run_within(
            60,
            &["render", "-o", s(out), "--width", "4", "--height", "4", "--spp", "1"],
        )
    };
    refused(&render(&h1), &["h1.png", "it has 2 hard links"]);
    assert_eq!([&h1, &h2].map(|p| std::fs::read_to_string(p).unwrap()), ["old", "old"]);
    std::fs::remove_file(&h2).unwrap();
    assert!(render(&h1).status.success());
    assert_eq!(listing(&d), ["h1.png"]);
}

/// Ctrl-C (SIGINT) and, since 30.3, SIGTERM and SIGHUP during a write
/// remove the temporary file (exit 130); before, the last two left a large
/// `.NAME.XXXXXX.tmp`.
#[test]
fn ctrl_c_sigterm_and_sighup_during_the_write_leave_no_temporary_file() {
    for signal in ["-INT", "-TERM", "-HUP"] {
        let d = fresh_dir(&format!("signal{signal}"));
        let out = d.join("big.png");
        let mut child = bin()
            .env("RAYON_NUM_THREADS", "2")
            .args([
                "render",
                "-o",
                s(&out),
                "--width",
                "4000",
                "--height",
                "3000",
                "--spp",
                "1",
            ])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let start = Instant::now();
        let mut seen = false;
        while start.elapsed() < Duration::from_secs(120) && child.try_wait().unwrap().is_none() {
            if listing(&d).iter().any(|n| n.ends_with(".tmp")) {
                seen = true;
                break;
            }
            std::thread::sleep(Duration::from_millis(1));
        }
        let pid = child.id().to_string();
        assert!(Command::new("kill").args([signal, &pid]).status().unwrap().success() || !seen);
        let status = child.wait().unwrap();
        assert!(seen, "{signal}: the temporary file never appeared");
        match status.code() {
            // The signal may come after the rename: then the whole file is there.
            Some(130) => assert!(
                listing(&d).is_empty() || listing(&d) == ["big.png"],
                "{signal}: {:?}",
                listing(&d)
            ),
            Some(0) => assert_eq!(listing(&d), ["big.png"]),
            other => panic!("{signal}: exit {other:?} ({status})"),
        }
    }
}

/// 30.3 and 30.4: `bench` checks every file it writes before measuring (a
/// directory or a dangling link at the second report's plot is refused at
/// once, nothing written), and a `--out-dir` it made is removed when the
/// run then fails.
#[test]
fn bench_checks_every_output_first_and_leaves_nothing_when_it_fails() {
    let d = fresh_dir("bench-outputs");
    let out_dir = d.join("out");
    std::fs::create_dir(&out_dir).unwrap();
    let objects_png = out_dir.join("bench-objects.png");
    std::fs::create_dir(&objects_png).unwrap();
    let bench =
        |dir: &Path, scene: &Path| run_within(30, &["bench", s(scene), "--quick", "--runs", "1", "--out-dir", s(dir)]);
    let cubes = scene("cubes.toml");
    refused(&bench(&out_dir, &cubes), &["bench-objects.png", "it is a directory"]);
    assert_eq!(listing(&out_dir), ["bench-objects.png"]);
    std::fs::remove_dir(&objects_png).unwrap();
    std::os::unix::fs::symlink(d.join("nowhere"), &objects_png).unwrap();
    refused(
        &bench(&out_dir, &cubes),
        &["bench-objects.png", "a symbolic link to nothing"],
    );
    assert_eq!(listing(&out_dir), ["bench-objects.png"]);
    // A new --out-dir (two levels) and a scene that fails to load.
    let missing = d.join("no-such-scene.toml");
    refused(&bench(&d.join("new/deeper"), &missing), &["no-such-scene.toml"]);
    assert_eq!(listing(&d), ["out"]);
}

/// 30.2: `bench` counts its work as `render` does, before measuring: the
/// whole study's frames (every report, every run, warm-ups included) and
/// the scene's lights. Over the budget it is refused at once and leaves no
/// `--out-dir` behind; before, the study was not counted at all (a
/// `--runs 1000` study ran for hours) and no mode counted lights.
#[test]
fn bench_counts_the_whole_study_and_the_lights_before_measuring() {
    let d = fresh_dir("bench-work");
    let made = d.join("made");
    let o = run_within(20, &["bench", "--runs", "1000", "--out-dir", s(&made)]);
    refused(&o, &["the benchmark", "camera samples", "2^32"]);
    assert!(!made.exists(), "{} left behind", made.display());
    // 2000 lights: 500× the work of one; ten runs at 1280×720 and 400×400
    // are then over the budget.
    let lit = d.join("lit.toml");
    let mut text = std::fs::read_to_string(scene("cubes.toml")).unwrap();
    for i in 0..2000 {
        text.push_str(&format!(
            "\n[[lights]]\ntype = \"point\"\nposition = [{}, 5, 0]\nintensity = 1\n",
            i % 50
        ));
    }
    std::fs::write(&lit, text).unwrap();
    let o = run_within(20, &["bench", s(&lit), "--frame-only", "--runs", "10"]);
    refused(&o, &["the benchmark", "2001 lights"]);
}

/// 30.4: a scene that converges exactly (RMSE 0 at every stage: nothing
/// in view but the background) is a result: the CSV and the plot are
/// written; before, the plot failed with "nothing to plot" after all the
/// work.
#[test]
fn converge_of_an_exact_scene_writes_its_plot() {
    let d = fresh_dir("converge-exact");
    let sc = d.join("empty.toml");
    std::fs::write(
        &sc,
        "[camera]\nposition = [0, 0, 0]\nlook_at = [0, 0, -1]\n\
         [[objects]]\ntype = \"sphere\"\nposition = [0, 0, 50]\nradius = 1\n",
    )
    .unwrap();
    let (csv, plot) = (d.join("c.csv"), d.join("c.png"));
    let o = run_within(
        60,
        &[
            "converge",
            s(&sc),
            "--width",
            "8",
            "--height",
            "6",
            "--max-spp",
            "2",
            "--reference-spp",
            "2",
            "--csv",
            s(&csv),
            "--plot",
            s(&plot),
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let table = std::fs::read_to_string(&csv).unwrap();
    assert!(table.lines().skip(1).all(|l| l.contains(",0.000000,")), "{table}");
    assert_eq!(lensview::render::Image::read_png(&plot).unwrap().width, 960);
}
