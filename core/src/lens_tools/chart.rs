//! The analysis as SVG (the web page's analysis panel): plots with a
//! title, axes with ticks and their names, lines and markers (C, d and F
//! as a hollow circle, a cross and a hollow triangle, as `lens spot -o`
//! draws them), and [`figures_html`], the whole [`Figures`] as one HTML
//! fragment: the header line, the cross-section ([`super::sketch::Sketch::svg`])
//! and the plots. The tick labels and axis ranges are also `lens spot -o`'s
//! and `lens distortion -o`'s ([`tick`], [`range`]).

use super::analysis::{Figures, plane_words};
use super::spot::centroid_text;
use std::fmt::Write;

/// The colour of a line's dots and of its text (on white).
pub fn line_colour(line: &str) -> [u8; 3] {
    match line {
        "C" => [214, 39, 40],
        "d" => [44, 160, 44],
        _ => [31, 119, 180],
    }
}

/// A tick label: short, and 0 for rounding noise about zero.
pub fn tick(v: f64) -> String {
    if v.abs() < 1e-15 {
        "0".into()
    } else if v.abs() >= 1e-3 && v.abs() < 1e4 {
        format!("{}", (v * 1e6).round() / 1e6)
    } else {
        format!("{v:.2e}")
    }
}

/// An axis range over `v` with a margin; a unit span about a lone value.
pub fn range(v: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = v.fold((f64::INFINITY, f64::NEG_INFINITY), |a, x| (a.0.min(x), a.1.max(x)));
    if !(lo.is_finite() && hi.is_finite()) {
        return (-1.0, 1.0);
    }
    let span = (hi - lo).max(1e-9 * hi.abs().max(lo.abs())).max(1e-12);
    (lo - 0.06 * span, hi + 0.06 * span)
}

/// About five round tick values in `lo..=hi` (steps of 1, 2 or 5 × 10^k,
/// the one nearest five ticks).
pub fn ticks(lo: f64, hi: f64) -> Vec<f64> {
    let span = hi - lo;
    if !(span > 0.0 && span.is_finite()) {
        return vec![lo];
    }
    let p = 10f64.powf((span / 5.0).log10().floor());
    let off = |m: &f64| (span / (m * p) - 5.0).abs();
    let m = [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .min_by(|a, b| off(a).total_cmp(&off(b)))
        .unwrap_or(1.0);
    let step = m * p;
    let (first, last) = ((lo / step).ceil() as i64, (hi / step).floor() as i64);
    (first..=last).map(|k| k as f64 * step).collect()
}

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Marker {
    Line,
    Circle,
    Cross,
    Triangle,
}

/// One series of a plot.
#[derive(Clone, Debug)]
pub struct Series {
    pub colour: [u8; 3],
    pub points: Vec<[f64; 2]>,
    pub marker: Marker,
    /// Its name in the legend (none: no legend entry).
    pub name: &'static str,
}

/// A marker's SVG at pixel `(x, y)`.
fn marker(m: Marker, x: f64, y: f64, stroke: &str) -> String {
    match m {
        Marker::Circle => format!(r#"<circle cx="{x:.1}" cy="{y:.1}" r="3.5" fill="none" {stroke}/>"#),
        Marker::Cross => format!(
            r#"<path d="M{:.1},{:.1}l6,6m0,-6l-6,6" fill="none" {stroke}/>"#,
            x - 3.0,
            y - 3.0
        ),
        Marker::Triangle => format!(r#"<path d="M{x:.1},{:.1}l3.5,6.5h-7z" fill="none" {stroke}/>"#, y - 4.0),
        Marker::Line => String::new(),
    }
}

/// Text with `&`, `<` and `>` escaped.
pub fn escape(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

const LEFT: f64 = 64.0;
const RIGHT: f64 = 12.0;
const TOP: f64 = 26.0;
const BOTTOM: f64 = 42.0;

/// A plot `w × h` pixels as an SVG: `title` above, axes with ticks and
/// their names (with units), the series (with `equal`, one scale on both
/// axes), a legend when a series is named; "nothing to show" without a
/// finite point.
pub fn plot_svg(size: (f64, f64), title: &str, axes: (&str, &str), series: &[Series], equal: bool) -> String {
    let (w, h) = size;
    let mut out = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w:.0}" height="{h:.0}" viewBox="0 0 {w:.0} {h:.0}" font-family="sans-serif" font-size="11"><rect width="100%" height="100%" fill="white"/><text x="{:.1}" y="16" text-anchor="middle" font-size="13">{}</text>"#,
        w / 2.0,
        escape(title)
    );
    let finite = |p: &&[f64; 2]| p[0].is_finite() && p[1].is_finite();
    let all: Vec<[f64; 2]> = series
        .iter()
        .flat_map(|s| s.points.iter().filter(finite).copied())
        .collect();
    if all.is_empty() {
        let _ = write!(
            out,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">nothing to show</text></svg>"#,
            w / 2.0,
            h / 2.0
        );
        return out;
    }
    let (pw, ph) = (w - LEFT - RIGHT, h - TOP - BOTTOM);
    let (mut x, mut y) = (range(all.iter().map(|p| p[0])), range(all.iter().map(|p| p[1])));
    if equal {
        // One scale: widen the narrower range about its middle.
        let s = ((x.1 - x.0) / pw).max((y.1 - y.0) / ph);
        let (cx, cy) = (0.5 * (x.0 + x.1), 0.5 * (y.0 + y.1));
        x = (cx - 0.5 * s * pw, cx + 0.5 * s * pw);
        y = (cy - 0.5 * s * ph, cy + 0.5 * s * ph);
    }
    let px = |p: [f64; 2]| {
        [
            LEFT + (p[0] - x.0) / (x.1 - x.0) * pw,
            TOP + ph - (p[1] - y.0) / (y.1 - y.0) * ph,
        ]
    };
    axes_svg(&mut out, (x, y), (pw, ph), axes, &px);
    for s in series {
        series_svg(&mut out, s, &px);
    }
    legend_svg(&mut out, series, w);
    out.push_str("</svg>");
    out
}

/// The frame, the ticks with their labels, and the axes' names.
fn axes_svg(
    out: &mut String,
    (x, y): ((f64, f64), (f64, f64)),
    (pw, ph): (f64, f64),
    axes: (&str, &str),
    px: &dyn Fn([f64; 2]) -> [f64; 2],
) {
    let _ = write!(
        out,
        r##"<rect x="{LEFT}" y="{TOP}" width="{pw:.1}" height="{ph:.1}" fill="none" stroke="#888"/>"##
    );
    let (base, label_x) = (TOP + ph, LEFT - 7.0);
    for t in ticks(x.0, x.1) {
        let [a, _] = px([t, y.0]);
        let (end, text_y, label) = (base + 5.0, base + 16.0, tick(t));
        let _ = write!(
            out,
            r##"<line x1="{a:.1}" y1="{base:.1}" x2="{a:.1}" y2="{end:.1}" stroke="#888"/><text x="{a:.1}" y="{text_y:.1}" text-anchor="middle">{label}</text>"##
        );
    }
    for t in ticks(y.0, y.1) {
        let [_, b] = px([x.0, t]);
        let (start, text_y, label) = (LEFT - 5.0, b + 4.0, tick(t));
        let _ = write!(
            out,
            r##"<line x1="{start:.1}" y1="{b:.1}" x2="{LEFT}" y2="{b:.1}" stroke="#888"/><text x="{label_x:.1}" y="{text_y:.1}" text-anchor="end">{label}</text>"##
        );
    }
    let _ = write!(
        out,
        r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">{}</text><text transform="translate(12,{:.1}) rotate(-90)" text-anchor="middle">{}</text>"#,
        LEFT + pw / 2.0,
        TOP + ph + 34.0,
        escape(axes.0),
        TOP + ph / 2.0,
        escape(axes.1)
    );
}

/// A series: a polyline, or its markers.
fn series_svg(out: &mut String, s: &Series, px: &dyn Fn([f64; 2]) -> [f64; 2]) {
    let [r, g, b] = s.colour;
    let stroke = format!(r#"stroke="rgb({r},{g},{b})""#);
    let pts = s
        .points
        .iter()
        .filter(|p| p[0].is_finite() && p[1].is_finite())
        .map(|&p| px(p));
    if s.marker == Marker::Line {
        let d: Vec<String> = pts.map(|[x, y]| format!("{x:.1},{y:.1}")).collect();
        let _ = write!(
            out,
            r#"<polyline fill="none" stroke-width="1.5" {stroke} points="{}"/>"#,
            d.join(" ")
        );
    } else {
        for [x, y] in pts {
            out.push_str(&marker(s.marker, x, y, &stroke));
        }
    }
}

/// The named series' markers and names in the top right corner.
fn legend_svg(out: &mut String, series: &[Series], w: f64) {
    let named = series.iter().filter(|s| !s.name.is_empty());
    for (k, s) in named.enumerate() {
        let [r, g, b] = s.colour;
        let y = TOP + 12.0 + 14.0 * k as f64;
        let stroke = format!(r#"stroke="rgb({r},{g},{b})""#);
        out.push_str(&marker(s.marker, w - RIGHT - 28.0, y - 4.0, &stroke));
        let _ = write!(
            out,
            r#"<text x="{:.1}" y="{y:.1}">{}</text>"#,
            w - RIGHT - 20.0,
            escape(s.name)
        );
    }
}

/// One curve in the d line's colour.
fn curve(points: Vec<[f64; 2]>, colour: [u8; 3]) -> Vec<Series> {
    vec![Series {
        colour,
        points,
        marker: Marker::Line,
        name: "",
    }]
}

/// The C, d and F markers of the spot's lines.
fn spot_series(lines: &[super::analysis::SpotLine]) -> Vec<Series> {
    let marks = [Marker::Circle, Marker::Cross, Marker::Triangle];
    (lines.iter().zip(marks))
        .map(|(l, marker)| Series {
            colour: line_colour(l.line),
            points: l.points.iter().flatten().map(|p| [p[0], p[1]]).collect(),
            marker,
            name: l.line,
        })
        .collect()
}

/// A `<p>` of `text` (escaped) with the class `class`.
fn para(out: &mut String, class: &str, text: &str) {
    let _ = write!(out, r#"<p class="{class}">{}</p>"#, escape(text));
}

/// The spots (or why there are none), each with its plane and its lines'
/// RMS radius and centroid below.
fn spots_html(out: &mut String, f: &Figures, size: (f64, f64)) {
    let Some(spots) = &f.spots else {
        para(
            out,
            "figure",
            &format!("Spot: no image plane here (give the image a plane after {}).", f.last),
        );
        return;
    };
    for s in spots {
        out.push_str(r#"<div class="figure">"#);
        let title = format!("Spot, field {}°", s.field_deg);
        out.push_str(&plot_svg(
            size,
            &title,
            ("x (units)", "y (units)"),
            &spot_series(&s.lines),
            true,
        ));
        para(out, "plane", &plane_words(s.plane_from_last, f.last));
        for l in &s.lines {
            let c = l.centroid.map_or("—".into(), |c| centroid_text(c, 2));
            let r = l.rms.map_or("—".into(), |r| format!("{r:.3e}"));
            let [cr, cg, cb] = line_colour(l.line);
            let _ = write!(
                out,
                r#"<p class="rms" style="color:rgb({cr},{cg},{cb})">{}: RMS {r}  centroid {}</p>"#,
                l.line,
                escape(&c)
            );
        }
        out.push_str("</div>");
    }
}

/// The whole analysis as one HTML fragment for a panel `width` pixels
/// wide: the header, the cross-section, the LSA, the spots, the distortion
/// and a dispersive system's axial and lateral colour.
pub fn figures_html(f: &Figures, width: f64) -> String {
    let mut out = String::new();
    para(&mut out, "header", &f.header);
    out.push_str(&f.sketch.svg(width));
    let size = (((width - 16.0) / 2.0).max(200.0), 260.0);
    let green = line_colour("d");
    let blue = line_colour("F");
    out.push_str(r#"<div class="plots">"#);
    let lsa = curve(f.lsa.clone(), green);
    let axes = ("focus − paraxial focus (units)", "pupil height (units)");
    out.push_str(&plot_svg(
        size,
        "Longitudinal spherical aberration (d line)",
        axes,
        &lsa,
        false,
    ));
    spots_html(&mut out, f, size);
    let field = "field angle (°)";
    match &f.distortion {
        Some(d) => {
            let mut pts = vec![[0.0, 0.0]];
            pts.extend(d);
            let marks: Vec<[f64; 2]> = pts.iter().skip(1).step_by(5).copied().collect();
            let mut s = curve(pts, blue);
            s.push(Series {
                colour: blue,
                points: marks,
                marker: Marker::Circle,
                name: "",
            });
            out.push_str(&plot_svg(size, "Distortion", (field, "distortion (%)"), &s, false));
        }
        None => para(&mut out, "figure", "Distortion: no real paraxial image."),
    }
    if let Some(axial) = &f.axial_colour {
        let s = curve(axial.clone(), line_colour("C"));
        out.push_str(&plot_svg(
            size,
            "Axial colour",
            ("focus − focus at d (units)", "wavelength (nm)"),
            &s,
            false,
        ));
    }
    match &f.lateral_colour {
        Some(Some(l)) => {
            let s = curve(l.clone(), [200, 60, 200]);
            out.push_str(&plot_svg(
                size,
                "Lateral colour",
                (field, "F − C height (units)"),
                &s,
                false,
            ));
        }
        Some(None) => para(&mut out, "figure", "Lateral colour: no real paraxial image."),
        None => {}
    }
    out.push_str("</div>");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_round_and_inside() {
        let labels: Vec<String> = ticks(-0.06, 1.06).into_iter().map(tick).collect();
        assert_eq!(labels, ["0", "0.2", "0.4", "0.6", "0.8", "1"]);
        assert!(ticks(3.0, 3.0).len() == 1);
        let t = ticks(-2.3e-5, 4.1e-5);
        assert!(
            t.iter().all(|v| (-2.3e-5..=4.1e-5).contains(v)) && t.len() >= 4,
            "{t:?}"
        );
    }

    #[test]
    fn a_plot_has_its_title_axes_and_markers() {
        let s = [Series {
            colour: [1, 2, 3],
            points: vec![[0.0, 0.0], [1.0, 2.0]],
            marker: Marker::Triangle,
            name: "F",
        }];
        let svg = plot_svg((300.0, 200.0), "Spot <1>", ("x", "y"), &s, true);
        assert!(svg.starts_with("<svg") && svg.ends_with("</svg>"));
        assert!(svg.contains("Spot &lt;1&gt;") && svg.contains(">F</text>"));
        assert_eq!(svg.matches("l3.5,6.5h-7z").count(), 3, "two points and the legend's");
        let empty = plot_svg((300.0, 200.0), "t", ("x", "y"), &[], false);
        assert!(empty.contains("nothing to show"));
    }
}
