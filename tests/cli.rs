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
    // scenes/cubes.toml by name.
    let img = lensview::render::Image::read_png(&out).unwrap();
    assert_eq!((img.width, img.height), (16, 12));
    let (_, cubes) = lensview::scene::Scene::load(&scene("cubes.toml")).unwrap();
    let want = lensview::render::render(
        &cubes,
        &lensview::render::RenderSettings {
            width: 16,
            height: 12,
            spp: cubes.spp,
            seed: 0,
        },
        None,
    );
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

    fails_with(&["render", "--width", "0"], "--width and --height must be at least 1");
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
    fails_with(
        &["lens", "info", "--d", "2", "--r1", "0.9", "--r2", "5", "--n", "1.5"],
        "radius r1 = 0.9 is smaller than d/2 = 1",
    );
    fails_with(
        &["lens", "info", "--d", "2", "--r1", "5", "--r2", "5", "--n", "0.5"],
        "index 0.5 must be ≥ 1",
    );
}

/// `bench --quick` writes every table and plot with numbers in them, and its
/// side modes answer as the benchmark scripts expect.
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

/// `converge` writes its table and plot, one row a stage of the schedule,
/// the error falling as the samples add up.
#[test]
fn converge_writes_its_table_and_plot() {
    let (csv, png) = (tmp("converge.csv"), tmp("converge.png"));
    let _ = std::fs::remove_file(&csv);
    let _ = std::fs::remove_file(&png);
    let o = bin()
        .args([
            "converge",
            "--width",
            "32",
            "--height",
            "24",
            "--max-spp",
            "4",
            "--reference-spp",
            "32",
        ])
        .args(["--csv", csv.to_str().unwrap(), "--plot", png.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(std::fs::metadata(&png).unwrap().len() > 1000);
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("stage,spp,stage_ms,elapsed_ms,rmse,psnr_db"));
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    // 8×8, 4×4 and 2×2 blocks, then 1, 2 and 4 samples a pixel.
    let spp: Vec<&str> = rows.iter().map(|r| r[1]).collect();
    assert_eq!(spp, ["0", "0", "0", "1", "2", "4"], "{text}");
    let rmse = |r: &Vec<&str>| r[4].parse::<f64>().unwrap();
    assert!(rmse(&rows[5]) < rmse(&rows[0]), "{text}");
    assert!(String::from_utf8_lossy(&o.stdout).contains("PSNR dB"));
}
