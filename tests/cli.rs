//! The `lensview` binary as a user runs it.

use std::path::PathBuf;
use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_lensview"))
}

fn tmp(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("cli");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn scene(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes").join(name)
}

#[test]
fn render_writes_a_png_of_the_requested_size() {
    let out = tmp("cubes.png");
    let _ = std::fs::remove_file(&out);
    let o = bin()
        .args([
            "render",
            scene("cubes.toml").to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--width",
            "40",
            "--height",
            "30",
            "--spp",
            "1",
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("rendered 40×30"));
    let img = lensview::render::Image::read_png(&out).unwrap();
    assert_eq!((img.width, img.height), (40, 30));
}

#[test]
fn render_without_a_scene_uses_the_embedded_default() {
    let out = tmp("default.png");
    let _ = std::fs::remove_file(&out);
    let o = bin()
        .args(["render", "-o", out.to_str().unwrap(), "--width", "16", "--height", "12"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // The embedded default is the cubes scene: the same picture as rendering
    // scenes/cubes.toml by name (caustics, photon budget and all).
    let img = lensview::render::Image::read_png(&out).unwrap();
    assert_eq!((img.width, img.height), (16, 12));
    let named = tmp("default-by-name.png");
    let o = bin()
        .args([
            "render",
            scene("cubes.toml").to_str().unwrap(),
            "-o",
            named.to_str().unwrap(),
        ])
        .args(["--width", "16", "--height", "12"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let want = lensview::render::Image::read_png(&named).unwrap();
    assert_eq!(img.to_srgb8(), want.to_srgb8());
}

#[test]
fn same_image_with_one_and_two_threads() {
    let mut bytes = Vec::new();
    for threads in ["1", "2"] {
        let out = tmp(&format!("threads-{threads}.png"));
        let o = bin()
            .env("RAYON_NUM_THREADS", threads)
            .args([
                "render",
                scene("primitives.toml").to_str().unwrap(),
                "-o",
                out.to_str().unwrap(),
                "--width",
                "64",
                "--height",
                "48",
                "--spp",
                "2",
            ])
            .output()
            .unwrap();
        assert!(o.status.success());
        assert!(String::from_utf8_lossy(&o.stdout).contains(&format!("{threads} threads")));
        bytes.push(std::fs::read(&out).unwrap());
    }
    assert_eq!(bytes[0], bytes[1]);
}

fn fails_with(args: &[&str], want: &str) {
    let o = bin().args(args).output().unwrap();
    assert!(!o.status.success(), "{args:?} succeeded");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(err.trim_end().lines().count(), 1, "not one line: {err}");
    assert!(err.contains(want), "{err} lacks {want}");
}

#[test]
fn bad_input_gives_one_line_and_a_failure_code() {
    let bad = tmp("typo.toml");
    let text = std::fs::read_to_string(scene("cubes.toml")).unwrap();
    std::fs::write(&bad, text.replacen("fov = 45", "fvo = 45", 1)).unwrap();
    let line = text.lines().position(|l| l == "fov = 45").unwrap() + 1;
    fails_with(
        &["render", bad.to_str().unwrap(), "-o", tmp("x.png").to_str().unwrap()],
        &format!("typo.toml:{line}:1: camera.fvo: unknown field `fvo`"),
    );

    std::fs::write(&bad, text.replacen("r1 = 5", "r1 = 0.5", 1)).unwrap();
    fails_with(
        &["render", bad.to_str().unwrap()],
        "lenses[0].r1: radius r1 = 0.5 is smaller than d/2 = 1",
    );

    std::fs::write(&bad, text.replacen("intensity = 500", "intensity = nan", 1)).unwrap();
    fails_with(
        &["render", bad.to_str().unwrap()],
        "lights[0].intensity: NaN is not a finite number",
    );

    fails_with(&["render", "--width", "0"], "--width × --height 0×600 is out of range");
    fails_with(&["render", "no-such-file.toml"], "no-such-file.toml: cannot read");
}

#[test]
fn a_failed_render_leaves_no_file() {
    let out = tmp("not-written.png");
    let _ = std::fs::remove_file(&out);
    let o = bin()
        .args(["render", "missing.toml", "-o", out.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert!(!out.exists());
}

#[test]
fn lens_trace_reads_cases_and_writes_json() {
    let cases = tmp("cases.json");
    std::fs::write(
        &cases,
        r#"{ "note": "unknown keys are ignored",
             "cases": [ { "id": "std", "lens": { "center": [0,0,0], "axis": [0,0,1], "d": 20.0, "R1": 50.0, "R2": 50.0, "n": 1.5 },
               "rays": [ { "id": "axial", "origin": [0,0,30], "direction": [0,0,-2] },
                         { "id": "blue", "origin": [3,0,30], "direction": [0,0,-1], "wavelength_um": 0.4861 },
                         { "id": "wide", "origin": [30,0,30], "direction": [0,0,-1] } ] },
               { "id": 7, "lens": { "center": [0,0,0], "axis": [0,0,1], "d": 20.0, "R1": 50.0, "R2": 50.0, "n": { "cauchy": [1.5046, 0.0042] } },
               "rays": [ { "id": "blue", "origin": [3,0,30], "direction": [0,0,-1], "wavelength_um": 0.4861 } ] } ] }"#,
    )
    .unwrap();
    let o = bin().args(["lens", "trace", cases.to_str().unwrap()]).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let rays = &v["cases"][0]["rays"];
    assert_eq!(v["cases"][0]["id"], "std");
    assert_eq!(rays[0]["status"], "transmitted");
    assert_eq!(rays[0]["entry_surface"], "S1");
    assert_eq!(rays[0]["exit_surface"], "S2");
    let sag = 50.0 - (2400.0f64).sqrt();
    assert!((rays[0]["entry_point"][2].as_f64().unwrap() - sag).abs() < 1e-14);
    assert_eq!(rays[0]["exit_direction"], serde_json::json!([0.0, 0.0, -1.0]));
    assert_eq!(rays[0]["n_internal_reflections"], 0);
    // The off-axis ray is bent toward the axis and its direction is unit.
    let d: Vec<f64> = rays[1]["exit_direction"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert!(d[0] < 0.0 && ((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() - 1.0).abs() < 1e-15);
    assert_eq!(rays[2]["status"], "miss");
    assert!(rays[2].get("exit_point").is_none());
    // Cauchy glass at 486.1 nm: n = A + B/λ².
    let n = v["cases"][1]["rays"][0]["n"].as_f64().unwrap();
    assert!((n - (1.5046 + 0.0042 / (0.4861f64 * 0.4861))).abs() < 1e-15);
}

#[test]
fn lens_trace_rejects_impossible_lenses_and_broken_json() {
    let cases = tmp("bad-cases.json");
    std::fs::write(&cases, r#"{ "cases": [ { "id": "x", "lens": { "center": [0,0,0], "axis": [0,0,1], "d": 2, "R1": 0.5, "R2": 5, "n": 1.5 }, "rays": [] } ] }"#).unwrap();
    fails_with(
        &["lens", "trace", cases.to_str().unwrap()],
        "cases[0] (id \"x\").lens.R1: radius r1 = 0.5 is smaller than d/2 = 1",
    );
    std::fs::write(&cases, "{ \"cases\": [\n  { \"id\": 1, ").unwrap();
    fails_with(&["lens", "trace", cases.to_str().unwrap()], "bad-cases.json:2:");
}

#[test]
fn lens_info_prints_paraxial_data_as_text_and_json() {
    let o = bin()
        .args([
            "lens", "info", "--d", "2", "--r1", "1", "--r2", "1", "--n", "1.5", "--json",
        ])
        .output()
        .unwrap();
    assert!(o.status.success());
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    // Ball lens: EFL = nD / (4(n − 1)) = 1.5, BFD = EFL − D/2.
    assert!((v["efl"].as_f64().unwrap() - 1.5).abs() < 1e-15);
    assert!((v["bfd"].as_f64().unwrap() - 0.5).abs() < 1e-15);
    assert_eq!(v["thickness"].as_f64().unwrap(), 2.0);
    let o = bin()
        .args([
            "lens",
            "info",
            "--d",
            "2",
            "--r1",
            "5",
            "--r2",
            "5",
            "--n",
            "1.5046,0.0042",
        ])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("effective focal length") && text.contains("axial colour"),
        "{text}"
    );
    // Each refusal names the flag typed (d, r1, r2, n).
    for (d, r1, r2, n, want) in [
        (
            "2",
            "0.9",
            "5",
            "1.5",
            "impossible lens: --r1: radius r1 = 0.9 is smaller than d/2 = 1",
        ),
        ("2", "5", "0.5", "1.5", "impossible lens: --r2: radius r2 = 0.5"),
        ("2", "5", "5", "0.5", "impossible lens: --n: index 0.5 must be ≥ 1"),
        ("2", "5", "5", "1.5,1e9", "impossible lens: --n: index"),
        (
            "1e300",
            "5",
            "5",
            "1.5",
            "impossible lens: --d: diameter 1e300 is outside the supported lengths",
        ),
        (
            "2",
            "1e309",
            "5",
            "1.5",
            "impossible lens: --r1 must be a finite number, got inf",
        ),
        (
            "2",
            "5",
            "5e300",
            "1.5",
            "impossible lens: --r2: radius r2 = 5e300 is above the supported",
        ),
    ] {
        fails_with(&["lens", "info", "--d", d, "--r1", r1, "--r2", r2, "--n", n], want);
    }
}

/// `bench --quick` writes every table and plot with numbers in them, and its
/// side modes answer as the benchmark scripts expect.
/// `--n` takes a catalogue glass (issue 31): its nd and Abbe number are
/// printed, and an unknown name is one line listing the known ones.
#[test]
fn lens_info_takes_a_glass_name() {
    let args = ["lens", "info", "--d", "20", "--r1", "50", "--r2", "50", "--n", "N-BK7"];
    let o = bin().args(args).output().unwrap();
    assert!(o.status.success());
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("glass N-BK7: nd = 1.51680, Abbe number vd = 64.17"),
        "{text}"
    );
    assert!(text.contains("axial colour"), "{text}");
    let o = bin().args(args).arg("--json").output().unwrap();
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["glass"]["name"], "N-BK7");
    assert!((v["glass"]["nd"].as_f64().unwrap() - 1.5168).abs() < 2e-5);
    assert!((v["glass"]["abbe"].as_f64().unwrap() - 64.17).abs() < 0.05);
    assert!((v["n"].as_f64().unwrap() - 1.5168).abs() < 2e-5);
    let o = bin()
        .args([
            "lens", "info", "--d", "2", "--r1", "5", "--r2", "5", "--n", "1.5", "--json",
        ])
        .output()
        .unwrap();
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(v.get("glass").is_none());
    fails_with(
        &["lens", "info", "--d", "2", "--r1", "5", "--r2", "5", "--n", "XYZ"],
        "`XYZ` is neither a number nor a known glass (known: N-BK7,",
    );
}

#[test]
fn bench_writes_its_tables_and_plots() {
    let dir = tmp("bench");
    let _ = std::fs::remove_dir_all(&dir);
    let o = bin()
        .args(["bench", "--quick", "--runs", "1", "--out-dir", dir.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in ["bench-size.png", "bench-objects.png"] {
        assert!(std::fs::metadata(dir.join(f)).unwrap().len() > 1000, "{f}");
    }
    for f in [
        "bench-size.csv",
        "bench-objects.csv",
        "bench-throughput.csv",
        "bench-features.csv",
    ] {
        let text = std::fs::read_to_string(dir.join(f)).unwrap();
        // The columns of the tables the docs show.
        let docs =
            std::fs::read_to_string(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("docs/bench").join(f)).unwrap();
        assert_eq!(text.lines().next(), docs.lines().next(), "{f}");
        let rows: Vec<&str> = text.lines().skip(1).collect();
        assert!(rows.len() >= 3, "{f}: {text}");
        for r in rows {
            let last = r.rsplit(',').next().unwrap();
            assert!(last.parse::<f64>().is_ok_and(|v| v > 0.0), "{f}: {r}");
        }
    }
    // `lensview bench FLAG --runs RUNS` at 64×36.
    let bench_small = |flag: &str, runs: &str| {
        bin()
            .args(["bench", flag, "--runs", runs, "--width", "64", "--height", "36"])
            .output()
            .unwrap()
    };
    let o = bench_small("--primary-only", "1");
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.lines().any(|l| l.starts_with("primary_rays_per_s ")), "{out}");
    assert!(
        out.lines().any(|l| l.starts_with("primary_rays_per_s_scalar ")),
        "{out}"
    );
    let o = bench_small("--frame-only", "3");
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for size in ["400x400", "64x36"] {
        let line = out
            .lines()
            .find(|l| l.starts_with(&format!("frame {size} ")))
            .unwrap_or_else(|| panic!("no {size} line: {out}"));
        // "fastest A ms, median B ms" with 0 < A <= B.
        let (_, times) = line.split_once("fastest").unwrap_or_else(|| panic!("{line}"));
        let ms: Vec<f64> = times
            .split_whitespace()
            .filter_map(|w| w.trim_end_matches(',').parse().ok())
            .collect();
        assert!(ms.len() == 2 && 0.0 < ms[0] && ms[0] <= ms[1], "{line}");
    }
    let o = bin()
        .args([
            "bench",
            "--unused-feature",
            "glass",
            "--unspecialised",
            "--width",
            "16",
            "--height",
            "16",
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = bin().args(["bench", "--unused-feature", "fog"]).output().unwrap();
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("unknown feature \"fog\""));
}

/// `lensview converge` of the default scene at 32×24.
fn converge_32x24(max_spp: &str, reference_spp: &str) -> Command {
    let mut c = bin();
    c.args(["converge", "--width", "32", "--height", "24"]).args([
        "--max-spp",
        max_spp,
        "--reference-spp",
        reference_spp,
    ]);
    c
}

/// `converge` writes its table and plot, one row a stage of the schedule,
/// the error falling as the samples add up.
#[test]
fn converge_writes_its_table_and_plot() {
    let (csv, png) = (tmp("converge.csv"), tmp("converge.png"));
    let _ = std::fs::remove_file(&csv);
    let _ = std::fs::remove_file(&png);
    let o = converge_32x24("4", "32")
        .args(["--csv", csv.to_str().unwrap(), "--plot", png.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(std::fs::metadata(&png).unwrap().len() > 1000);
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("sampling,stage,spp,samples_per_pixel,stage_ms,elapsed_ms,rmse,psnr_db")
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    // 8×8, 4×4 and 2×2 blocks, then 1, 2 and 4 samples a pixel.
    let spp: Vec<&str> = rows.iter().map(|r| r[2]).collect();
    assert_eq!(spp, ["0", "0", "0", "1", "2", "4"], "{text}");
    assert!(rows.iter().all(|r| r[0] == "R2 points + adaptive waves"), "{text}");
    let rmse = |r: &Vec<&str>| r[6].parse::<f64>().unwrap();
    assert!(rmse(&rows[5]) < rmse(&rows[0]), "{text}");
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("PSNR dB") && stdout.contains("PSNR at multiples of the 1-spp samples"));
    // After a camera step the first row is the reprojected picture; a
    // malformed step is refused with a message naming the option.
    let step = |s: &str| {
        converge_32x24("2", "4")
            .args([
                "--camera-step",
                s,
                "--csv",
                csv.to_str().unwrap(),
                "--plot",
                png.to_str().unwrap(),
            ])
            .output()
            .unwrap()
    };
    let o = step("0,0,0.1");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(text.lines().nth(1).unwrap().contains(",reprojected,0,"), "{text}");
    let o = step("0,0");
    assert!(!o.status.success() && String::from_utf8_lossy(&o.stderr).contains("--camera-step"));
}

// ---- Atomic, safe writes (lensview::output) and the shared limits ----

/// A fresh, empty directory for one test.
fn fresh_dir(name: &str) -> PathBuf {
    let d = tmp(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The names in `d`, sorted.
fn listing(d: &std::path::Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

fn render_to(out: &std::path::Path, size: &str) -> std::process::Output {
    let (w, h) = size.split_once('x').unwrap();
    bin()
        .args([
            "render",
            "-o",
            out.to_str().unwrap(),
            "--width",
            w,
            "--height",
            h,
            "--spp",
            "1",
        ])
        .output()
        .unwrap()
}

/// One line on stderr, exit status 1, and the line contains each of `words`.
fn refused(o: &std::process::Output, words: &[&str]) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    for w in words {
        assert!(err.contains(w), "{w:?} not in {err}");
    }
}

#[test]
fn old_temporary_names_are_neither_followed_nor_clobbered() {
    let d = fresh_dir("old-tmp-names");
    let victim = d.join("victim.txt");
    std::fs::write(&victim, "precious").unwrap();
    // The old fixed names: OUT.png.tmp and OUT.tmp, as links to the victim.
    std::os::unix::fs::symlink(&victim, d.join("out.png.tmp")).unwrap();
    std::os::unix::fs::symlink(&victim, d.join("out.tmp")).unwrap();
    // An unrelated file of the user's at the old name of another output.
    std::fs::write(d.join("mine.png.tmp"), "mine").unwrap();
    for out in ["out.png", "mine.png"] {
        let o = render_to(&d.join(out), "8x6");
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert_eq!(lensview::render::Image::read_png(&d.join(out)).unwrap().width, 8);
    }
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious");
    assert_eq!(std::fs::read_to_string(d.join("mine.png.tmp")).unwrap(), "mine");
    assert!(
        std::fs::symlink_metadata(d.join("out.png.tmp"))
            .unwrap()
            .file_type()
            .is_symlink()
    );
    assert_eq!(
        listing(&d),
        [
            "mine.png",
            "mine.png.tmp",
            "out.png",
            "out.png.tmp",
            "out.tmp",
            "victim.txt"
        ]
    );
}

#[test]
fn only_a_regular_file_is_replaced() {
    let d = fresh_dir("non-regular");
    let sub = d.join("a-directory");
    std::fs::create_dir(&sub).unwrap();
    refused(
        &render_to(&sub, "4x4"),
        &["a-directory", "it is a directory, not a regular file"],
    );
    assert!(listing(&sub).is_empty());
    let fifo = d.join("a-fifo");
    assert!(Command::new("mkfifo").arg(&fifo).status().unwrap().success());
    refused(&render_to(&fifo, "4x4"), &["a-fifo", "it is a FIFO"]);
    let link = d.join("to-dev-null");
    std::os::unix::fs::symlink("/dev/null", &link).unwrap();
    refused(
        &render_to(&link, "4x4"),
        &["to-dev-null", "a symbolic link to a character device"],
    );
    let missing = d.join("no-such-dir").join("x.png");
    refused(
        &render_to(&missing, "4x4"),
        &["no-such-dir", "cannot create a temporary file"],
    );
    // Nothing replaced, nothing left behind.
    assert_eq!(listing(&d), ["a-directory", "a-fifo", "to-dev-null"]);
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
    // A link to a regular file writes its target and stays a link.
    let real = d.join("real.png");
    std::fs::write(&real, "old").unwrap();
    let link = d.join("link.png");
    std::os::unix::fs::symlink(&real, &link).unwrap();
    assert!(render_to(&link, "4x4").status.success());
    assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
    assert_eq!(lensview::render::Image::read_png(&real).unwrap().width, 4);
}

use std::os::unix::fs::FileTypeExt as _;

#[test]
fn every_command_obeys_the_same_limits_at_once() {
    let d = fresh_dir("limits");
    let px = d.join("px.png");
    let p = px.to_str().unwrap();
    let cases: &[(&[&str], &[&str])] = &[
        (
            &["converge", "--width", "100000", "--height", "100000"],
            &["100000×100000", "1..=16384"],
        ),
        (
            &["converge", "--max-spp", "4294967295"],
            &["--max-spp is 4294967295", "1..=65536"],
        ),
        (&["converge", "--reference-spp", "4294967295"], &["--reference-spp"]),
        // Legal values, absurd work: 400×300 × 65536 reference samples.
        (
            &["converge", "--reference-spp", "65536"],
            &["camera samples; the limit is"],
        ),
        (
            &["bench", "--primary-only", "--width", "100000", "--height", "100000"],
            &["100000×100000"],
        ),
        (
            &["bench", "--primary-only", "--runs", "1000000"],
            &["--runs is 1000000"],
        ),
        (
            &[
                "render",
                "--spp",
                "4294967295",
                "--width",
                "1",
                "--height",
                "1",
                "-o",
                p,
            ],
            &["--spp is 4294967295"],
        ),
        (
            &["render", "--spp", "65537", "--width", "1", "--height", "1", "-o", p],
            &["1..=65536"],
        ),
        (
            &["render", "--width", "16384", "--height", "16384", "-o", p],
            &["needs 6.8 GiB", "the limit is 4.0 GiB"],
        ),
        (&["view", "--width", "20000"], &["window --width × --height 20000×720"]),
        (&["view", "--max-spp", "70000"], &["--max-spp is 70000"]),
    ];
    for (args, words) in cases {
        let start = std::time::Instant::now();
        let o = bin().current_dir(&d).args(*args).output().unwrap();
        refused(&o, words);
        assert!(start.elapsed().as_secs() < 5, "{args:?} took {:?}", start.elapsed());
    }
    assert!(listing(&d).is_empty(), "{:?}", listing(&d));
}

#[test]
fn bench_refuses_an_unwritable_out_dir_before_measuring() {
    let d = fresh_dir("bench-out");
    std::fs::create_dir(d.join("bench-size.csv")).unwrap();
    let start = std::time::Instant::now();
    let o = bin()
        .args(["bench", "--quick", "--out-dir", d.to_str().unwrap()])
        .output()
        .unwrap();
    refused(&o, &["bench-size.csv", "it is a directory"]);
    assert!(start.elapsed().as_secs() < 5);
    let file = d.join("a-file");
    std::fs::write(&file, "").unwrap();
    let o = bin()
        .args(["bench", "--quick", "--out-dir", file.to_str().unwrap()])
        .output()
        .unwrap();
    refused(&o, &["cannot create", "a-file"]);
}

/// `render` with standard error piped (CI, a log file): no progress bar,
/// no carriage return, nothing at all on standard error.
#[test]
fn render_piped_prints_no_progress_bar() {
    let out = tmp("piped.png");
    let o = bin()
        .args([
            "render",
            "-o",
            out.to_str().unwrap(),
            "--width",
            "160",
            "--height",
            "120",
            "--spp",
            "2",
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(o.stderr.is_empty(), "{:?}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(!stdout.contains('\r') && !stdout.contains("ETA"), "{stdout}");
}

/// On a terminal (a pseudo-terminal made by `script`, where installed) the
/// bar shows with its percentage and ETA.
#[test]
fn render_on_a_terminal_shows_a_progress_bar_with_an_eta() {
    if Command::new("script").arg("--version").output().is_err() {
        eprintln!("skipped: `script` (util-linux) is not installed");
        return;
    }
    let out = tmp("tty.png");
    let cmd = format!(
        "{} render -o {} --width 320 --height 240 --spp 16",
        env!("CARGO_BIN_EXE_lensview"),
        out.display()
    );
    let o = Command::new("script")
        .args(["-qec", &cmd, "/dev/null"])
        .env("TERM", "xterm")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("rendering [") && text.contains("ETA"), "{text:?}");
    assert!(text.contains("rendered 320×240"), "{text:?}");
}
