//! `lensview lens fan | spot | distortion`: the lens's figures, computed by
//! `lensview::lens_tools` (every ray by `Lens::trace`), written as JSON on
//! stdout, a table, or a drawing (`lens fan -o fan.svg|fan.png`). A lens
//! system (`--preset`, `--prescription`, `--system`) is handed to
//! `lens_system_figures.rs`.

use super::lens_charts::{FieldSpot, LineDots, distortion_chart, spot_chart};
use super::lens_system_figures::{FigureLens, Which};
use anyhow::{Result, anyhow, bail};
use clap::Args;
use lensview::lens_tools::bench::Bench as FigureBench;
use lensview::lens_tools::sketch::{Sketch, place_label};
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
    /// Several field angles in degrees, comma-separated (`0,10,20`): a spot
    /// diagram at each, drawn side by side at one scale (instead of --field-deg).
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
    pub fields: Vec<f64>,
    /// Draw the spot diagrams into this file (.png or .svg): axes in units,
    /// C, d and F as circle, cross and triangle.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Print JSON (every ray) instead of a table: one diagram, or a list of
    /// them with --fields.
    #[arg(long)]
    pub json: bool,
}

impl SpotArgs {
    /// A refusal, naming --fields for a field angle given there.
    pub fn refuse(&self, e: SetupError) -> anyhow::Error {
        match e.field {
            "field-deg" if !self.fields.is_empty() => refuse(SetupError { field: "fields", ..e }),
            _ => refuse(e),
        }
    }

    /// The field angles asked for: --fields, else --field-deg.
    pub fn field_list(&self) -> Vec<f64> {
        if self.fields.is_empty() {
            vec![self.bench.field_deg]
        } else {
            self.fields.clone()
        }
    }
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
    /// Draw the distortion curve into this file (.png or .svg).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
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
    let mut spots = Vec::new();
    for field in a.field_list() {
        let s = Setup::new(l.0, l.1, l.2, l.3, b.object_distance, field).map_err(|e| a.refuse(e))?;
        spots.push(lensview::lens_tools::spot_diagram(&s, a.image_plane, a.rings).map_err(|e| a.refuse(e))?);
    }
    let chart = || {
        let fields = (spots.iter())
            .map(|d| field_spot::<Setup>(d.field_deg, d.spots.iter().map(|sp| (sp.line, &sp.rays[..]))))
            .collect();
        let plane = plane_words(rounded(spots[0].image_plane_from_v2), "V2");
        let title = format!(
            "Spot diagram: lens d {} R1 {} R2 {}; image plane {plane}",
            l.0, l.1, l.2
        );
        (title, fields)
    };
    spot_outputs(a, &spots, chart, |spot| {
        println!(
            "spot diagram: hexapolar, {} rings over {} (0.9·d/2); image plane {}; field {}°",
            spot.rings,
            spot.pupil_radius,
            plane_words(spot.image_plane_from_v2, "V2"),
            spot.field_deg
        );
        for sp in &spot.spots {
            let rays = (sp.ray_count, sp.rays.len());
            let stats = (sp.centroid, sp.rms_radius);
            println!("{}", spot_row(sp.line, sp.wavelength_um, Some(sp.n), rays, stats));
        }
    })
}

/// `spot`'s outputs, for the lens's diagrams and a system's: the chart of
/// `chart()` (title, fields) with -o, then the JSON (one diagram, or a list
/// with --fields) or each diagram's text (`text`).
pub(super) fn spot_outputs<T: serde::Serialize>(
    a: &SpotArgs,
    spots: &[T],
    chart: impl FnOnce() -> (String, Vec<FieldSpot>),
    text: impl Fn(&T),
) -> Result<()> {
    if let Some(path) = &a.output {
        let (title, fields) = chart();
        spot_chart(path, &title, &fields)?;
    }
    if a.json {
        return match spots {
            [one] => print_json(one),
            many => print_json(&many),
        };
    }
    spots.iter().for_each(text);
    Ok(())
}

/// An image plane `from_last` along the light from the last vertex `last`,
/// in words: after it, or before it for a magnifier's virtual image.
pub(super) fn plane_words(from_last: f64, last: &str) -> String {
    if from_last < 0.0 {
        format!(
            "{} before {last} (the virtual image: rays extended backwards)",
            -from_last
        )
    } else {
        format!("{from_last} after {last}")
    }
}

/// `x` to six decimals, for a chart's title (the tables keep every digit).
pub(super) fn rounded(x: f64) -> f64 {
    (x * 1e6).round() / 1e6
}

/// One field's spot as the chart draws it: each line's image points
/// (the rays listed by the bench `B`, the lens's or a system's).
pub(super) fn field_spot<'a, B: FigureBench>(
    field_deg: f64,
    lines: impl Iterator<Item = (&'static str, &'a [B::Ray])>,
) -> FieldSpot
where
    B::Ray: 'a,
{
    FieldSpot {
        field_deg,
        lines: lines
            .map(|(line, rays)| LineDots {
                line,
                points: rays.iter().filter_map(B::image_point).map(|p| [p[0], p[1]]).collect(),
            })
            .collect(),
    }
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
    if let Some(path) = &a.output {
        let pts: Vec<(f64, f64)> = (dist.points.iter())
            .filter_map(|p| Some((p.field_deg, p.distortion_percent?)))
            .collect();
        let title = format!(
            "Distortion: lens d {} R1 {} R2 {}; image {}",
            l.0,
            l.1,
            l.2,
            plane_words(rounded(dist.image_plane_from_v2), "V2")
        );
        distortion_chart(path, &title, &pts)?;
    }
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
            let pts: Vec<(i32, i32)> = pts.iter().map(|&p| pix(p)).collect();
            match kind.dashes() {
                Some((on, off)) => root.draw(&plotters::element::DashedPathElement::new(
                    pts, on as u32, off as u32, style,
                )),
                None => root.draw(&PathElement::new(pts, style)),
            }
            .map_err(e)?;
        }
        let mut placed = Vec::new();
        for (label, p) in &sketch.marks {
            let (x, y) = pix(*p);
            root.draw(&Circle::new((x, y), 3, BLACK.filled())).map_err(e)?;
            let [tx, ty] = place_label([f64::from(x), f64::from(y)], label, 16.0, 4.0, &mut placed);
            // plotters places text by its top left corner.
            let at = (tx.round() as i32, (ty - 16.0).round() as i32);
            root.draw(&Text::new(*label, at, ("sans-serif", 16).into_font()))
                .map_err(e)?;
        }
        root.present().map_err(e)?;
    }
    crate::plot::write_png(path, (w, h), &rgb)
}
