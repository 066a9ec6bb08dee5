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
