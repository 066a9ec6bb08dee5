//! The command line: `render`, `lens` (later `view`, `bench`, `converge`).
//! Each command parses its arguments, calls the library and reports; errors
//! travel up as `anyhow` chains and are printed by `main`.

use anyhow::{Context, Result, bail};
use clap::{Args, Parser, Subcommand};
use lensview::render::{RenderSettings, render};
use lensview::scene::{Scene, SceneFile};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(Parser, Debug)]
#[command(
    name = "lensview",
    version,
    about = "A ray tracer that shows how a thick biconvex glass lens distorts a 3D scene"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Open the interactive viewer on SCENE (the embedded default without one).
    View(ViewArgs),
    /// Render a scene to a PNG file without a window.
    Render(RenderArgs),
    /// Error against run time: the progressive schedule, headless, against a converged reference.
    Converge(ConvergeArgs),
    /// Performance: time against image size and object count, ray throughput, feature costs.
    Bench(BenchArgs),
    /// Exact lens optics: real rays (`trace`) and paraxial data (`info`).
    #[command(subcommand)]
    Lens(LensCommand),
}

#[derive(Args, Debug)]
pub struct ConvergeArgs {
    /// Scene file (TOML); the embedded default scene when omitted.
    pub scene: Option<PathBuf>,
    #[arg(long, default_value_t = 400)]
    pub width: u32,
    #[arg(long, default_value_t = 300)]
    pub height: u32,
    /// Samples per pixel the schedule refines to.
    #[arg(long, default_value_t = 64)]
    pub max_spp: u32,
    /// Samples per pixel of the reference (rendered with another sample pattern).
    #[arg(long, default_value_t = 256)]
    pub reference_spp: u32,
    /// CSV table to write.
    #[arg(long, default_value = "converge.csv")]
    pub csv: PathBuf,
    /// PNG plot to write (error against time, log scales).
    #[arg(long, default_value = "converge.png")]
    pub plot: PathBuf,
}

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Scene file (TOML) in the layout of scenes/cubes.toml; the embedded cubes scene when omitted.
    pub scene: Option<PathBuf>,
    /// Directory for the CSV tables and PNG plots.
    #[arg(long, default_value = "bench")]
    pub out_dir: PathBuf,
    /// Timed runs per point (the median is reported).
    #[arg(long, default_value_t = 5)]
    pub runs: usize,
    /// Small sizes and few points: a smoke test of the command.
    #[arg(long)]
    pub quick: bool,
    /// Only measure closest-hit primary rays per second at WIDTH×HEIGHT and print it.
    #[arg(long)]
    pub primary_only: bool,
    /// Only time full Whitted frames (1 sample per pixel) at 400×400 and at
    /// WIDTH×HEIGHT, round-robin, and print the fastest and the median.
    #[arg(long, conflicts_with = "primary_only")]
    pub frame_only: bool,
    #[arg(long, default_value_t = 1280)]
    pub width: u32,
    #[arg(long, default_value_t = 720)]
    pub height: u32,
    /// Render FRAMES frames at WIDTH×HEIGHT of the cubes scene without this
    /// feature (shadows, glass, mirror, specular, dispersion) and exit: for
    /// counting instructions (benches/feature-instructions.sh).
    #[arg(long, value_name = "FEATURE")]
    pub unused_feature: Option<String>,
    /// With --unused-feature: through the kernel that has every feature compiled in.
    #[arg(long, requires = "unused_feature")]
    pub unspecialised: bool,
    /// With --unused-feature: how many frames.
    #[arg(long, default_value_t = 1, requires = "unused_feature")]
    pub frames: u32,
}

#[derive(Subcommand, Debug)]
pub enum LensCommand {
    /// Trace real rays through lenses given in a JSON file; JSON on stdout.
    Trace {
        /// The cases file: { "cases": [ { "id", "lens": {center, axis, d, R1, R2, n}, "rays": [...] } ] }.
        cases: PathBuf,
    },
    /// Paraxial data of a lens (light entering through S1), its real marginal focus and axial colour.
    Info(LensInfoArgs),
}

#[derive(Args, Debug)]
pub struct LensInfoArgs {
    /// Diameter.
    #[arg(long)]
    pub d: f64,
    /// Radius of curvature of S1 (magnitude, ≥ d/2).
    #[arg(long)]
    pub r1: f64,
    /// Radius of curvature of S2 (magnitude, ≥ d/2).
    #[arg(long)]
    pub r2: f64,
    /// Refractive index (a number), or Cauchy coefficients as A,B (n = A + B/λ², λ in µm).
    #[arg(long, value_parser = parse_index)]
    pub n: lensview::optics::Index,
    /// Wavelength in µm (default: the helium d line, 0.5875618).
    #[arg(long, default_value_t = lensview::optics::WAVELENGTH_D_UM)]
    pub wavelength_um: f64,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

fn parse_index(s: &str) -> Result<lensview::optics::Index, String> {
    let num = |t: &str| {
        t.trim()
            .parse::<f64>()
            .map_err(|e| format!("`{t}` is not a number: {e}"))
    };
    let s = s.trim().trim_start_matches("cauchy:");
    match s.split_once(',') {
        Some((a, b)) => Ok(lensview::optics::Index::Cauchy { a: num(a)?, b: num(b)? }),
        None => Ok(lensview::optics::Index::Constant(num(s)?)),
    }
}

#[derive(Args, Debug, Default)]
pub struct ViewArgs {
    /// Scene file (TOML); the embedded default scene when omitted.
    pub scene: Option<PathBuf>,
    /// Append one JSON line per presented frame to this file.
    #[arg(long)]
    pub frame_log: Option<PathBuf>,
    /// Close the window cleanly after this many seconds.
    #[arg(long)]
    pub exit_after: Option<f64>,
    /// Samples per pixel to refine to.
    #[arg(long, default_value_t = 64)]
    pub max_spp: u32,
    /// Initial window width.
    #[arg(long, default_value_t = 1280)]
    pub width: u32,
    /// Initial window height.
    #[arg(long, default_value_t = 720)]
    pub height: u32,
    /// Start with the editing panel hidden (F4 shows it).
    #[arg(long)]
    pub no_panel: bool,
    /// Write the screen rectangles of the panel's buttons to this file (JSON), for scripted tests.
    #[arg(long, hide = true)]
    pub ui_log: Option<PathBuf>,
}

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// Scene file (TOML); the embedded default scene when omitted.
    pub scene: Option<PathBuf>,
    /// Output PNG file.
    #[arg(short, long, default_value = "lensview.png")]
    pub output: PathBuf,
    /// Image width in pixels.
    #[arg(long, default_value_t = 800)]
    pub width: u32,
    /// Image height in pixels.
    #[arg(long, default_value_t = 600)]
    pub height: u32,
    /// Samples per pixel (default: the scene's `render.spp`).
    #[arg(long)]
    pub spp: Option<u32>,
    /// Seed of the sample pattern.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
}

/// Loads `path`, or the embedded default scene.
pub fn load_scene(path: Option<&Path>) -> Result<(SceneFile, Scene)> {
    match path {
        Some(p) => Ok(Scene::load(p)?),
        None => Ok(Scene::default_scene()),
    }
}

pub fn run(cli: Cli) -> Result<()> {
    match cli.command {
        None => view(ViewArgs {
            max_spp: 64,
            width: 1280,
            height: 720,
            ..Default::default()
        }),
        Some(Command::View(a)) => view(a),
        Some(Command::Render(a)) => render_cmd(a),
        Some(Command::Converge(a)) => converge(&a),
        Some(Command::Bench(a)) => bench(&a),
        Some(Command::Lens(LensCommand::Trace { cases })) => lens_trace(&cases),
        Some(Command::Lens(LensCommand::Info(a))) => lens_info(&a),
    }
}

fn converge(a: &ConvergeArgs) -> Result<()> {
    use lensview::render::progressive::{converge, reference};
    let (_, scene) = load_scene(a.scene.as_deref())?;
    if a.width == 0 || a.height == 0 || a.max_spp == 0 || a.reference_spp == 0 {
        bail!("--width, --height, --max-spp and --reference-spp must be at least 1");
    }
    eprintln!("rendering the reference at {} spp…", a.reference_spp);
    let t = Instant::now();
    let reference = reference(&scene, a.width, a.height, a.reference_spp, 1);
    eprintln!("reference done in {:.1} s", t.elapsed().as_secs_f64());
    let rows = converge(&scene, &reference, a.max_spp);
    let mut csv = String::from("stage,spp,stage_ms,elapsed_ms,rmse,psnr_db\n");
    println!(
        "{:<14} {:>5} {:>10} {:>11} {:>10} {:>8}",
        "stage", "spp", "stage ms", "elapsed ms", "RMSE", "PSNR dB"
    );
    for r in &rows {
        println!(
            "{:<14} {:>5} {:>10.1} {:>11.1} {:>10.5} {:>8.2}",
            r.stage, r.spp, r.stage_ms, r.elapsed_ms, r.rmse, r.psnr_db
        );
        csv.push_str(&format!(
            "{},{},{:.3},{:.3},{:.6},{:.3}\n",
            r.stage, r.spp, r.stage_ms, r.elapsed_ms, r.rmse, r.psnr_db
        ));
    }
    std::fs::write(&a.csv, csv).with_context(|| format!("cannot write {}", a.csv.display()))?;
    let name = a
        .scene
        .as_deref()
        .map_or("default scene".to_string(), |p| p.display().to_string());
    crate::plot::log_log(
        &a.plot,
        &format!("{name}, {}×{}: error against run time", a.width, a.height),
        "time since refinement started (ms)",
        &format!("RMSE against {} spp reference", a.reference_spp),
        &[crate::plot::Series {
            name: "progressive schedule".into(),
            points: rows.iter().map(|r| (r.elapsed_ms, r.rmse)).collect(),
            labels: rows.iter().map(|r| format!(" {}", r.stage)).collect(),
        }],
    )?;
    println!("wrote {} and {}", a.csv.display(), a.plot.display());
    Ok(())
}

fn bench(a: &BenchArgs) -> Result<()> {
    use lensview::bench::*;
    use std::fmt::Write as _;
    let (sf, scene) = load_scene(a.scene.as_deref())?;
    if a.width == 0 || a.height == 0 || a.runs == 0 {
        bail!("--width, --height and --runs must be at least 1");
    }
    let threads = rayon::current_num_threads();
    if let Some(f) = &a.unused_feature {
        for _ in 0..a.frames {
            if unused_feature_frame(&sf, f, a.unspecialised, a.width, a.height).is_none() {
                bail!(
                    "--unused-feature: unknown feature {f:?}; one of {}",
                    FEATURES.join(", ")
                );
            }
        }
        return Ok(());
    }
    if a.primary_only {
        let rps = primary_rays_per_second(&scene, a.width, a.height, a.runs, true);
        let packets = primary_rays_per_second(&scene, a.width, a.height, a.runs, false);
        let scalar = primary_rays_per_second_scalar(&scene, a.width, a.height, a.runs);
        println!("primary_rays_per_s {rps:.0}");
        println!("primary_rays_per_s_packets_alone {packets:.0}");
        println!("primary_rays_per_s_scalar {scalar:.0}");
        println!(
            "lensview: closest-hit primary rays at {}×{} ({threads} threads): {}",
            a.width,
            a.height,
            primary_summary(rps, packets, scalar)
        );
        return Ok(());
    }
    if a.frame_only {
        let sizes = [(400, 400), (a.width, a.height)];
        let items: Vec<_> = sizes.iter().map(|&(w, h)| (&scene, w, h)).collect();
        let times = interleaved_frame_samples(&items, a.runs);
        for ((w, h), v) in sizes.iter().zip(&times) {
            println!(
                "frame {w}x{h} ({threads} threads, {} runs): fastest {:.2} ms, median {:.2} ms",
                v.len(),
                v[0] * 1e3,
                v[v.len() / 2] * 1e3
            );
        }
        return Ok(());
    }
    std::fs::create_dir_all(&a.out_dir).with_context(|| format!("cannot create {}", a.out_dir.display()))?;
    let out = |name: &str| a.out_dir.join(name);
    let runs = a.runs;
    println!(
        "lensview bench: median of {runs} runs (the points of a sweep timed round-robin), {threads} threads, \
         1 sample per pixel, full Whitted shading"
    );

    // 1. Render time against image size.
    let sizes: Vec<(u32, u32)> = if a.quick {
        vec![(32, 32), (64, 64), (64, 36)]
    } else {
        vec![
            (100, 100),
            (200, 200),
            (400, 400),
            (800, 800),
            (1600, 1600),
            (1280, 720),
        ]
    };
    let mut csv = String::from("width,height,pixels,median_ms\n");
    let mut pts = Vec::new();
    println!("\nimage size      median ms    M samples/s");
    let items: Vec<(&Scene, u32, u32)> = sizes.iter().map(|&(w, h)| (&scene, w, h)).collect();
    let times = interleaved_frame_times(&items, runs);
    for (&(w, h), t) in sizes.iter().zip(times) {
        let ms = t * 1e3;
        let px = (w * h) as f64;
        println!("{:>5}×{:<5} {:>12.2} {:>14.2}", w, h, ms, px / ms / 1e3);
        let _ = writeln!(csv, "{w},{h},{px},{ms:.3}");
        if w == h {
            pts.push((px, ms));
        }
    }
    std::fs::write(out("bench-size.csv"), &csv)?;
    crate::plot::log_log(
        &out("bench-size.png"),
        "render time against image size (cubes scene, 1 spp)",
        "pixels",
        "median frame time (ms)",
        &[crate::plot::Series {
            name: "lensview".into(),
            labels: sizes
                .iter()
                .filter(|(w, h)| w == h)
                .map(|(w, _)| format!(" {w}²"))
                .collect(),
            points: pts,
        }],
    )?;

    // 2. Render time against object count.
    let (w, h) = if a.quick { (48, 48) } else { (400, 400) };
    let mut csv = String::from("series,objects,median_ms\n");
    let counts: Vec<usize> = if a.quick { vec![0, 5, 25] } else { (0..=25).collect() };
    let mut removal = Vec::new();
    println!("\ncubes (of 25) at {w}×{h}: median ms");
    let subsets: Vec<Scene> = counts.iter().map(|&n| cubes_subset(&sf, n)).collect();
    let sides: Vec<usize> = if a.quick {
        vec![2, 5, 10]
    } else {
        vec![5, 10, 20, 30, 40, 50]
    };
    let grids: Vec<Scene> = sides.iter().map(|&side| cubes_grid(&sf, side)).collect();
    // Both series in one round-robin.
    let items: Vec<(&Scene, u32, u32)> = subsets.iter().chain(&grids).map(|s| (s, w, h)).collect();
    let times = interleaved_frame_times(&items, runs);
    let (removal_times, grid_times) = times.split_at(counts.len());
    for (&n, t) in counts.iter().zip(removal_times) {
        let ms = t * 1e3;
        print!("{n}:{ms:.2}  ");
        let _ = writeln!(csv, "cubes scene,{n},{ms:.3}");
        removal.push((n.max(1) as f64, ms));
    }
    println!();
    let mut grid = Vec::new();
    println!("grid of cubes at {w}×{h}:");
    for (&side, t) in sides.iter().zip(grid_times) {
        let ms = t * 1e3;
        let n = side * side;
        println!("  {n:>5} cubes {ms:>10.2} ms");
        let _ = writeln!(csv, "grid,{n},{ms:.3}");
        grid.push((n as f64, ms));
    }
    std::fs::write(out("bench-objects.csv"), &csv)?;
    if let (Some(g25), Some(glast)) = (grid.iter().find(|p| p.0 == 25.0), grid.last()) {
        println!("  {} cubes cost {:.2}× the time of 25", glast.0, glast.1 / g25.1);
    }
    crate::plot::log_log(
        &out("bench-objects.png"),
        &format!("render time against object count ({w}×{h}, 1 spp)"),
        "cubes",
        "median frame time (ms)",
        &[
            crate::plot::Series {
                name: "cubes scene, cubes removed one by one".into(),
                points: removal,
                labels: vec![],
            },
            crate::plot::Series {
                name: "grid of N cubes over the same area".into(),
                points: grid,
                labels: vec![],
            },
        ],
    )?;

    // 3. Throughput and frame rate.
    let (tw, th) = if a.quick { (64, 36) } else { (1280, 720) };
    let rps = primary_rays_per_second(&scene, tw, th, runs, true);
    let rps_packets = primary_rays_per_second(&scene, tw, th, runs, false);
    let rps_scalar = primary_rays_per_second_scalar(&scene, tw, th, runs);
    let frame = frame_time(&scene, tw, th, runs.min(3));
    let small = frame_time(&scene, 400, 400, runs);
    println!(
        "\nprimary rays (closest hit, no shading) at {tw}×{th}: {}",
        primary_summary(rps, rps_packets, rps_scalar)
    );
    println!(
        "full Whitted frame at {tw}×{th}: {:.1} ms ({:.1} fps); at 400×400: {:.1} ms",
        frame * 1e3,
        1.0 / frame,
        small * 1e3
    );
    let first = {
        use lensview::render::progressive::{Progressive, Stage};
        let mut p = Progressive::new(tw, th, 0);
        median_time(runs, || {
            p.reset(tw, th, 0);
            p.run(&scene, Stage::Blocks(8), &|| false);
        })
    };
    println!(
        "first progressive level (8×8 blocks) at {tw}×{th}: {:.2} ms",
        first * 1e3
    );
    std::fs::write(
        out("bench-throughput.csv"),
        format!(
            "measure,value\nprimary_rays_per_s_tiles,{rps:.0}\nprimary_rays_per_s_packets_alone,{rps_packets:.0}\n\
             primary_rays_per_s_one_by_one,{rps_scalar:.0}\n\
             frame_ms_{tw}x{th},{:.3}\nframe_ms_400x400,{:.3}\nfirst_level_8x8_ms_{tw}x{th},{:.3}\n",
            frame * 1e3,
            small * 1e3,
            first * 1e3
        ),
    )?;

    // 4. What features cost.
    let (fw, fh) = if a.quick { (48, 48) } else { (400, 400) };
    let costs = feature_costs(&sf, fw, fh, runs);
    let mut csv = String::from("feature,with_ms,without_ms,unused_specialised_ms,unused_unspecialised_ms\n");
    println!("\nfeature costs at {fw}×{fh} (ms):");
    println!(
        "  {:<18} {:>9} {:>9}   {:>22} {:>14} {:>9}",
        "feature", "with", "without", "unused: left out", "compiled in", "overhead"
    );
    for c in &costs {
        println!(
            "  {:<18} {:>9.2} {:>9.2}   {:>22.2} {:>14.2} {:>8.1}%",
            c.feature,
            c.with_ms,
            c.without_ms,
            c.unused_specialised_ms,
            c.unused_unspecialised_ms,
            100.0 * c.unused_overhead()
        );
        let _ = writeln!(
            csv,
            "{},{:.3},{:.3},{:.3},{:.3}",
            c.feature, c.with_ms, c.without_ms, c.unused_specialised_ms, c.unused_unspecialised_ms
        );
    }
    std::fs::write(out("bench-features.csv"), &csv)?;
    println!(
        "\nwrote bench-size.csv/png, bench-objects.csv/png, bench-throughput.csv, bench-features.csv in {}",
        a.out_dir.display()
    );
    Ok(())
}

fn lens_trace(path: &Path) -> Result<()> {
    use lensview::lens_tools::{TraceInput, trace_cases};
    let name = path.display();
    let text = std::fs::read_to_string(path).with_context(|| format!("{name}: cannot read"))?;
    let input: TraceInput =
        serde_json::from_str(&text).map_err(|e| anyhow::anyhow!("{name}:{}:{}: {e}", e.line(), e.column()))?;
    let out = trace_cases(&input).map_err(|e| anyhow::anyhow!("{name}: {e}"))?;
    println!("{}", serde_json::to_string_pretty(&out)?);
    Ok(())
}

fn lens_info(a: &LensInfoArgs) -> Result<()> {
    if !(a.wavelength_um > 0.0 && a.wavelength_um.is_finite()) {
        bail!("--wavelength-um must be a positive number, got {}", a.wavelength_um);
    }
    let info = lensview::lens_tools::lens_info(a.d, a.r1, a.r2, a.n, a.wavelength_um).context("impossible lens")?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&info)?);
    } else {
        print!("{info}");
    }
    Ok(())
}

fn view(a: ViewArgs) -> Result<()> {
    let (scene_file, _) = load_scene(a.scene.as_deref())?;
    if a.width == 0 || a.height == 0 {
        bail!("--width and --height must be at least 1 (got {}×{})", a.width, a.height);
    }
    if a.max_spp == 0 {
        bail!("--max-spp must be at least 1");
    }
    if let Some(t) = a.exit_after
        && !(t >= 0.0 && t.is_finite())
    {
        bail!("--exit-after must be a number of seconds ≥ 0, got {t}");
    }
    crate::viewer::run(crate::viewer::ViewOptions {
        scene_path: a.scene,
        scene_file,
        frame_log: a.frame_log,
        exit_after: a.exit_after,
        max_spp: a.max_spp,
        width: a.width,
        height: a.height,
        panel: !a.no_panel,
        ui_log: a.ui_log,
    })
}

fn render_cmd(a: RenderArgs) -> Result<()> {
    let (_, scene) = load_scene(a.scene.as_deref())?;
    if a.width == 0 || a.height == 0 {
        bail!("--width and --height must be at least 1 (got {}×{})", a.width, a.height);
    }
    if a.width > 16384 || a.height > 16384 {
        bail!(
            "--width and --height must be at most 16384 (got {}×{})",
            a.width,
            a.height
        );
    }
    let spp = a.spp.unwrap_or(scene.spp);
    if spp == 0 {
        bail!("--spp must be at least 1");
    }
    let settings = RenderSettings {
        width: a.width,
        height: a.height,
        spp,
        seed: a.seed,
    };
    let tty = std::io::stderr().is_terminal();
    let show = |f: f64| eprint!("\rrendering {:3.0}%", f * 100.0);
    let start = Instant::now();
    let img = render(&scene, &settings, if tty { Some(&show) } else { None });
    let secs = start.elapsed().as_secs_f64();
    if tty {
        eprint!("\r");
    }
    img.write_png(&a.output)
        .with_context(|| format!("cannot write {}", a.output.display()))?;
    let samples = a.width as f64 * a.height as f64 * spp as f64;
    println!(
        "rendered {}×{} at {} spp in {:.3} s ({:.2} M camera samples/s, {} threads) → {}",
        a.width,
        a.height,
        spp,
        secs,
        samples / secs / 1e6,
        rayon::current_num_threads(),
        a.output.display()
    );
    Ok(())
}

/// The three primary-ray rates (rays/s) in words: in tiles (what the
/// renderer casts), in packets walking alone, one by one.
fn primary_summary(tiles: f64, packets: f64, one_by_one: f64) -> String {
    use lensview::simd::{LANES, uses_avx2};
    use lensview::trace::TILE;
    format!(
        "{:.2} M rays/s in tiles of {TILE} packets of {LANES} ({}), {:.2} M rays/s in packets walking alone, \
         {:.2} M rays/s one by one (tiles {:.2}× one by one)",
        tiles / 1e6,
        if uses_avx2() { "AVX2" } else { "SSE2" },
        packets / 1e6,
        one_by_one / 1e6,
        tiles / one_by_one
    )
}
