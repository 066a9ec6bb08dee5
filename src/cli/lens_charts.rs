//! `lens spot -o` and `lens distortion -o`: the figures as optics plots,
//! drawn with plotters' charts (axes with ticks, units and titles, a
//! legend) into a PNG or an SVG by the file's extension.
//!
//! The spot: one panel per field angle, all at one scale, each about its
//! own d-line centroid; C, d and F as a hollow circle, a cross and a hollow
//! triangle, so dots that coincide stay distinguishable. The distortion: the
//! curve over the field with a marker at each field angle listed.

use anyhow::{Result, anyhow, bail};
use lensview::lens_tools::chart::{line_colour, range, tick};
use lensview::output::write_file;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// One wavelength's dots: its line (`C`, `d`, `F`) and image points.
pub struct LineDots {
    pub line: &'static str,
    pub points: Vec<[f64; 2]>,
}

/// One field angle's spot.
pub struct FieldSpot {
    pub field_deg: f64,
    pub lines: Vec<LineDots>,
}

/// A chart file's format, by its extension.
enum Format {
    Png,
    Svg,
}

fn format(path: &Path) -> Result<Format> {
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("png") => Ok(Format::Png),
        Some("svg") => Ok(Format::Svg),
        _ => bail!("-o {}: the plot is written as .png or .svg", path.display()),
    }
}

/// Draws with `draw` onto a `size` canvas of the file's format and writes it
/// atomically.
fn write_chart(
    path: &Path,
    size: (u32, u32),
    draw_png: impl FnOnce(DrawingArea<BitMapBackend, Shift>) -> Result<()>,
    draw_svg: impl FnOnce(DrawingArea<SVGBackend, Shift>) -> Result<()>,
) -> Result<()> {
    crate::plot::register_font();
    match format(path)? {
        Format::Png => {
            let mut rgb = vec![255u8; size.0 as usize * size.1 as usize * 3];
            draw_png(BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area())?;
            crate::plot::write_png(path, size, &rgb)
        }
        Format::Svg => {
            let mut text = String::new();
            draw_svg(SVGBackend::with_string(&mut text, size).into_drawing_area())?;
            write_file(path, text.as_bytes())?;
            Ok(())
        }
    }
}

fn err<E: std::fmt::Debug>(path: &Path) -> impl Fn(E) -> anyhow::Error + '_ {
    move |e| anyhow!("cannot draw {}: {e:?}", path.display())
}

/// The colour of a line's dots (the page's analysis uses the same).
fn colour(line: &str) -> RGBColor {
    let [r, g, b] = line_colour(line);
    RGBColor(r, g, b)
}

/// A line's marker, in pixels about its point: C a hollow circle, d a
/// cross, F a hollow triangle (dots of coinciding lines stay apart to the eye).
fn marker(line: &str, style: ShapeStyle) -> PathElement<(i32, i32)> {
    let pts: Vec<(i32, i32)> = match line {
        "C" => (0..=16)
            .map(|k| f64::from(k) * std::f64::consts::TAU / 16.0)
            .map(|a| ((4.5 * a.cos()).round() as i32, (4.5 * a.sin()).round() as i32))
            .collect(),
        "d" => vec![(-3, -3), (3, 3), (0, 0), (-3, 3), (3, -3)],
        _ => vec![(0, -5), (4, 3), (-4, 3), (0, -5)],
    };
    PathElement::new(pts, style)
}

/// The spot diagrams of `fields` side by side, `title` above them.
pub fn spot_chart(path: &Path, title: &str, fields: &[FieldSpot]) -> Result<()> {
    let panels = fields.len().max(1) as u32;
    let size = (40 + 420 * panels, 520);
    write_chart(
        path,
        size,
        |root| draw_spots(root, path, title, fields),
        |root| draw_spots(root, path, title, fields),
    )
}

/// A spot's dots about its d-line centroid (the first line's without d).
fn about_centroid(spot: &FieldSpot) -> Vec<(&'static str, Vec<(f64, f64)>)> {
    let reference = (spot.lines.iter().find(|l| l.line == "d"))
        .or(spot.lines.first())
        .map(|l| l.points.as_slice())
        .unwrap_or(&[]);
    let k = reference.len().max(1) as f64;
    let c = reference
        .iter()
        .fold([0.0, 0.0], |a, p| [a[0] + p[0] / k, a[1] + p[1] / k]);
    (spot.lines.iter())
        .map(|l| (l.line, l.points.iter().map(|p| (p[0] - c[0], p[1] - c[1])).collect()))
        .collect()
}

fn draw_spots<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    path: &Path,
    title: &str,
    fields: &[FieldSpot],
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let e = err(path);
    root.fill(&WHITE).map_err(&e)?;
    let root = root.titled(title, ("sans-serif", 20)).map_err(&e)?;
    let dots: Vec<_> = fields.iter().map(about_centroid).collect();
    // One scale for every panel: the farthest dot from its centroid.
    let reach = (dots.iter().flatten().flat_map(|l| l.1.iter()))
        .filter(|p| p.0.is_finite() && p.1.is_finite())
        .fold(0.0f64, |m, p| m.max(p.0.abs()).max(p.1.abs()));
    let r = if reach > 0.0 { 1.1 * reach } else { 1.0 };
    let panels = root.split_evenly((1, fields.len().max(1)));
    for ((panel, spot), lines) in panels.iter().zip(fields).zip(&dots) {
        let mut chart = ChartBuilder::on(panel)
            .caption(format!("field {}°", spot.field_deg), ("sans-serif", 16))
            .margin(12)
            .x_label_area_size(44)
            .y_label_area_size(64)
            .build_cartesian_2d(-r..r, -r..r)
            .map_err(&e)?;
        chart
            .configure_mesh()
            .x_desc("x − centroid (units)")
            .y_desc("y − centroid (units)")
            .x_labels(5)
            .y_labels(5)
            .x_label_formatter(&|v| tick(*v))
            .y_label_formatter(&|v| tick(*v))
            .draw()
            .map_err(&e)?;
        for (line, pts) in lines {
            let style = colour(line).stroke_width(1);
            let pts = pts.iter().copied().filter(|p| p.0.is_finite() && p.1.is_finite());
            let series = chart
                .draw_series(pts.map(|p| EmptyElement::at(p) + marker(line, style)))
                .map_err(&e)?;
            series
                .label(*line)
                .legend(move |(x, y)| EmptyElement::at((x, y)) + marker(line, style));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(&e)?;
    }
    root.present().map_err(&e)?;
    Ok(())
}

/// The distortion curve (field °, %) with its points marked, `title` above.
pub fn distortion_chart(path: &Path, title: &str, points: &[(f64, f64)]) -> Result<()> {
    write_chart(
        path,
        (900, 600),
        |root| draw_distortion(root, path, title, points),
        |root| draw_distortion(root, path, title, points),
    )
}

fn draw_distortion<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    path: &Path,
    title: &str,
    points: &[(f64, f64)],
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let e = err(path);
    root.fill(&WHITE).map_err(&e)?;
    let mut pts = vec![(0.0, 0.0)];
    pts.extend(points.iter().copied().filter(|p| p.0.is_finite() && p.1.is_finite()));
    let (x_lo, x_hi) = range(pts.iter().map(|p| p.0));
    let (y_lo, y_hi) = range(pts.iter().map(|p| p.1));
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 20))
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(72)
        .build_cartesian_2d(x_lo..x_hi, y_lo..y_hi)
        .map_err(&e)?;
    chart
        .configure_mesh()
        .x_desc("field angle (°)")
        .y_desc("distortion (%)")
        .x_label_formatter(&|v| tick(*v))
        .y_label_formatter(&|v| tick(*v))
        .draw()
        .map_err(&e)?;
    let blue = colour("F");
    chart
        .draw_series(LineSeries::new(pts.iter().copied(), blue.stroke_width(2)))
        .map_err(&e)?;
    chart
        .draw_series(pts.iter().skip(1).map(|p| Circle::new(*p, 4, blue.filled())))
        .map_err(&e)?;
    root.present().map_err(&e)?;
    Ok(())
}
