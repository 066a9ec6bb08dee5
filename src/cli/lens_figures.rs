//! `lensview lens fan | spot | distortion`: the lens's figures, computed by
//! `lensview::lens_tools` (every ray by `Lens::trace`), written as JSON on
//! stdout, a table, or a drawing (`lens fan -o fan.svg|fan.png`). A lens
//! system (`--preset`, `--prescription`, `--system`) is handed to
//! `lens_system_figures.rs`.

use super::lens_system_figures::{FigureLens, Which};
use anyhow::{Result, anyhow, bail};
use clap::Args;
use lensview::lens_tools::sketch::Sketch;
use lensview::lens_tools::{Setup, SetupError};
use lensview::output::write_file;
use std::path::{Path, PathBuf};

/// Where the light comes from.
#[derive(Args, Debug)]
pub struct Bench {
    #[command(flatten)]
    pub shape: FigureLens,
    /// Object distance before the vertex V1, or a system's first vertex (default: at infinity).
    #[arg(long, allow_negative_numbers = true)]
    pub object_distance: Option<f64>,
    /// Field angle in degrees: the chief ray's angle to the axis (aimed at the lens centre).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub field_deg: f64,
}

#[derive(Args, Debug)]
pub struct FanArgs {
    #[command(flatten)]
    pub bench: Bench,
    /// Number of meridional rays across the pupil.
    #[arg(long, default_value_t = 7)]
    pub rays: u32,
    /// Image plane, distance after V2 along the light (default: the paraxial image).
    #[arg(long, allow_negative_numbers = true)]
    pub image_plane: Option<f64>,
    /// Draw the fan to scale into this file (.svg or .png).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Print the rays, cardinal points and LSA curve as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

#[derive(Args, Debug)]
pub struct SpotArgs {
    #[command(flatten)]
    pub bench: Bench,
    /// Image plane, distance after V2 along the light (default: the paraxial image at the d line).
    #[arg(long, allow_negative_numbers = true)]
    pub image_plane: Option<f64>,
    /// Hexapolar rings (1 + 3K(K+1) rays per wavelength).
    #[arg(long, default_value_t = 6)]
    pub rings: u32,
    /// Print JSON (every ray) instead of a table.
    #[arg(long)]
    pub json: bool,
}

#[derive(Args, Debug)]
pub struct DistortionArgs {
    #[command(flatten)]
    pub shape: FigureLens,
    /// Object distance before the vertex V1, or a system's first vertex (default: at infinity).
    #[arg(long, allow_negative_numbers = true)]
    pub object_distance: Option<f64>,
    /// Largest field angle, degrees.
    #[arg(long, default_value_t = 20.0, allow_negative_numbers = true)]
    pub max_field_deg: f64,
    /// Field angles sampled, evenly up to the largest.
    #[arg(long, default_value_t = 10)]
    pub steps: u32,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// A bad value: one line naming the option.
pub(super) fn refuse(e: SetupError) -> anyhow::Error {
    anyhow!("{e}")
}

fn setup(l: (f64, f64, f64, lensview::optics::Index), object_distance: Option<f64>, field_deg: f64) -> Result<Setup> {
    Setup::new(l.0, l.1, l.2, l.3, object_distance, field_deg).map_err(refuse)
}

pub(super) fn print_json<T: serde::Serialize>(value: &T) -> Result<()> {
    use std::io::Write;
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    serde_json::to_writer_pretty(&mut out, value)?;
    writeln!(out)?;
    out.flush()?;
    Ok(())
}

pub fn fan(a: &FanArgs) -> Result<()> {
    let b = &a.bench;
    let l = match b.shape.which()? {
        Which::Lens(l) => l,
        Which::System(sys) => return super::lens_system_figures::fan(a, sys),
    };
    let s = setup(l, b.object_distance, b.field_deg)?;
    if a.output.is_none() && !a.json {
        bail!("give -o fan.svg|fan.png, --json, or both");
    }
    let fan = lensview::lens_tools::fan(&s, a.rays, a.image_plane).map_err(refuse)?;
    if let Some(path) = &a.output {
        write_sketch(path, &fan.sketch(&s))?;
    }
    if a.json {
        print_json(&fan)?;
    }
    Ok(())
}

/// The drawing as .svg or .png, by the file's extension.
pub(super) fn write_sketch(path: &Path, sketch: &Sketch) -> Result<()> {
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("svg") => write_file(path, sketch.svg(1200.0).as_bytes())?,
        Some("png") => sketch_png(path, sketch)?,
        _ => bail!("-o {}: the drawing is written as .svg or .png", path.display()),
    }
    Ok(())
}

pub fn spot(a: &SpotArgs) -> Result<()> {
    let b = &a.bench;
    let l = match b.shape.which()? {
        Which::Lens(l) => l,
        Which::System(sys) => return super::lens_system_figures::spot(a, sys),
    };
    let s = setup(l, b.object_distance, b.field_deg)?;
    let spot = lensview::lens_tools::spot_diagram(&s, a.image_plane, a.rings).map_err(refuse)?;
    if a.json {
        return print_json(&spot);
    }
    println!(
        "spot diagram: hexapolar, {} rings over {} (0.9·d/2); image plane {} after V2; field {}°",
        spot.rings, spot.pupil_radius, spot.image_plane_from_v2, spot.field_deg
    );
    for sp in &spot.spots {
        let rays = (sp.ray_count, sp.rays.len());
        let stats = (sp.centroid, sp.rms_radius);
        println!("{}", spot_row(sp.line, sp.wavelength_um, Some(sp.n), rays, stats));
    }
    Ok(())
}

/// One line of a spot's table (the lens's, with its index, and a
/// system's): the line, its wavelength, the rays that reached the plane of
/// those traced, the centroid and the RMS radius.
pub(super) fn spot_row(
    line: &str,
    wavelength_um: f64,
    n: Option<f64>,
    rays: (usize, usize),
    (centroid, rms): (Option<[f64; 2]>, Option<f64>),
) -> String {
    let c = centroid.map_or("—".into(), |c| lensview::lens_tools::spot::centroid_text(c, 6));
    let r = rms.map_or("—".into(), |r| format!("{r:.9e}"));
    let n = n.map_or(String::new(), |n| format!("n {n}  "));
    format!(
        "  {line} {wavelength_um:.4} µm  {n}rays {}/{}  centroid {c}  RMS radius {r}",
        rays.0, rays.1
    )
}

pub fn distortion(a: &DistortionArgs) -> Result<()> {
    let l = match a.shape.which()? {
        Which::Lens(l) => l,
        Which::System(sys) => return super::lens_system_figures::distortion(a, sys),
    };
    let s = setup(l, a.object_distance, 0.0)?;
    let dist = lensview::lens_tools::distortion(&s, a.max_field_deg, a.steps).map_err(refuse)?;
    if a.json {
        return print_json(&dist);
    }
    print!("{dist}");
    Ok(())
}

/// The sketch as a PNG 1200 pixels wide, through plotters.
fn sketch_png(path: &Path, sketch: &Sketch) -> Result<()> {
    use plotters::prelude::*;
    crate::plot::register_font();
    let f = sketch.frame(1200.0, 900.0);
    let (w, h) = (f.width.round() as u32, f.height.round() as u32);
    let mut rgb = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area();
        let e = |e: DrawingAreaErrorKind<_>| anyhow!("cannot draw {}: {e:?}", path.display());
        let pix = |p: [f64; 2]| {
            let [x, y] = f.px(p);
            (x.clamp(-1e6, 1e6) as i32, y.clamp(-1e6, 1e6) as i32)
        };
        for (kind, pts) in &sketch.lines {
            let ([r, g, b], width) = kind.style();
            let style = RGBColor(r, g, b).stroke_width(width.round().max(1.0) as u32);
            root.draw(&PathElement::new(
                pts.iter().map(|&p| pix(p)).collect::<Vec<_>>(),
                style,
            ))
            .map_err(e)?;
        }
        for (label, p) in &sketch.marks {
            let (x, y) = pix(*p);
            root.draw(&Circle::new((x, y), 3, BLACK.filled())).map_err(e)?;
            root.draw(&Text::new(*label, (x + 4, y - 20), ("sans-serif", 16).into_font()))
                .map_err(e)?;
        }
        root.present().map_err(e)?;
    }
    crate::plot::write_png(path, (w, h), &rgb)
}
