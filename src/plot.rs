//! PNG plots with `plotters` for the `converge` (and `bench`) commands. Text
//! uses the DejaVu Sans font embedded in the binary (assets/fonts), so no
//! system font library is needed.

use anyhow::{Result, anyhow};
use lensview::output::write_with;
use plotters::prelude::*;
use std::path::Path;

static FONT: &[u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");

pub fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        // A font that fails to load only leaves the plot without text.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// One labelled series of (x, y) points.
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
    /// Optional label drawn beside each point.
    pub labels: Vec<String>,
}

/// The plot's size in pixels.
const SIZE: (u32, u32) = (960, 640);

/// A log–log line plot with points, as the bytes of a PNG (for
/// `output::write_all`, so that a table and its plot are written as one;
/// `path` names the file in errors).
pub fn log_log(path: &Path, title: &str, x_label: &str, y_label: &str, series: &[Series]) -> Result<Vec<u8>> {
    let mut rgb = vec![255u8; SIZE.0 as usize * SIZE.1 as usize * 3];
    draw(&mut rgb, title, x_label, y_label, series)
        .map_err(|e| anyhow!("cannot draw the plot for {}: {e}", path.display()))?;
    let mut bytes = Vec::new();
    encode_png(&mut bytes, SIZE, &rgb).map_err(|e| anyhow!("cannot encode the plot for {}: {e}", path.display()))?;
    Ok(bytes)
}

/// 8-bit RGB pixels written as a PNG atomically.
pub fn write_png(path: &Path, size: (u32, u32), rgb: &[u8]) -> Result<()> {
    write_with(path, |out| encode_png(out, size, rgb))?;
    Ok(())
}

fn encode_png(out: &mut dyn std::io::Write, (w, h): (u32, u32), rgb: &[u8]) -> std::io::Result<()> {
    let mut enc = png::Encoder::new(out, w, h);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let mut w = enc.write_header().map_err(std::io::Error::other)?;
    w.write_image_data(rgb).map_err(std::io::Error::other)?;
    w.finish().map_err(std::io::Error::other)
}

/// The axis range `(low, high)` of the positive values of `v`, padded and
/// holding two powers of ten; `(1e-3, 1)` when none is positive (every
/// value exact zero: drawn on the floor).
fn log_range(v: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = v
        .filter(|x| *x > 0.0 && x.is_finite())
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), x| (lo.min(x), hi.max(x)));
    if !lo.is_finite() {
        return (1e-3, 1.0);
    }
    // Log axes are labelled at powers of ten: make each range hold two.
    let decade_below = |v: f64| 10f64.powf(v.log10().floor());
    let decade_above = |v: f64| 10f64.powf(v.log10().ceil());
    ((lo / 1.5).min(decade_below(lo)), (hi * 1.5).max(decade_above(hi)))
}

/// Draws the plot into `rgb` (8-bit RGB, [`SIZE`]).
fn draw(rgb: &mut [u8], title: &str, x_label: &str, y_label: &str, series: &[Series]) -> Result<()> {
    register_font();
    let all = || series.iter().flat_map(|s| s.points.iter().copied());
    if !all().any(|(x, y)| x.is_finite() && y.is_finite()) {
        return Err(anyhow!("nothing to plot"));
    }
    let (x0, x1) = log_range(all().map(|p| p.0));
    let (y0, y1) = log_range(all().map(|p| p.1));
    // A value of 0 (an exact result: RMSE 0 against the reference) has no
    // place on a log axis: it is drawn on the axis's floor, not left out.
    let place = |(x, y): (f64, f64)| (x.max(x0), y.max(y0));
    let root = BitMapBackend::with_buffer(rgb, SIZE).into_drawing_area();
    let e = |e: DrawingAreaErrorKind<_>| anyhow!("{e:?}");
    root.fill(&WHITE).map_err(e)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 24))
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc(y_label)
        .x_label_formatter(&|v| format!("{v}"))
        .y_label_formatter(&|v| format!("{v:.1e}"))
        .y_labels(12)
        .label_style(("sans-serif", 15))
        .draw()
        .map_err(e)?;
    let colours = [
        RGBColor(31, 119, 180),
        RGBColor(214, 39, 40),
        RGBColor(44, 160, 44),
        RGBColor(148, 103, 189),
    ];
    for (i, s) in series.iter().enumerate() {
        let c = colours[i % colours.len()];
        let pts: Vec<(f64, f64)> = s
            .points
            .iter()
            .filter(|(x, y)| x.is_finite() && y.is_finite())
            .map(|&p| place(p))
            .collect();
        chart
            .draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))
            .map_err(e)?
            .label(if s.points.iter().any(|&(x, y)| x <= 0.0 || y <= 0.0) {
                format!("{} (values of 0 drawn on the axis)", s.name)
            } else {
                s.name.clone()
            })
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
        chart
            .draw_series(pts.iter().map(|&p| Circle::new(p, 4, c.filled())))
            .map_err(e)?;
        for (p, l) in pts.iter().zip(&s.labels) {
            chart
                .draw_series(std::iter::once(Text::new(
                    l.clone(),
                    *p,
                    ("sans-serif", 13).into_font(),
                )))
                .map_err(e)?;
        }
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .label_font(("sans-serif", 15))
        .draw()
        .map_err(e)?;
    root.present().map_err(e)?;
    Ok(())
}
