//! A meridional drawing to scale — polylines and labelled marks in (s, x),
//! s along the light — and its SVG. The PNG of `lens fan` and the viewer's
//! analysis window draw the same [`Sketch`] through [`Sketch::frame`].

use std::fmt::Write;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Axis,
    Lens,
    Ray,
    Plane,
    Principal,
    /// A system's aperture stop (the diaphragm).
    Stop,
    /// A ray's backward extension to a virtual image (a magnifier's),
    /// drawn dashed as Ray Optics Simulation draws it.
    Virtual,
}

impl Kind {
    /// Stroke colour (sRGB) and width in pixels.
    pub fn style(self) -> ([u8; 3], f64) {
        match self {
            Kind::Axis => ([120, 120, 120], 1.0),
            Kind::Lens => ([20, 90, 200], 2.0),
            Kind::Ray => ([220, 60, 20], 1.2),
            Kind::Plane => ([40, 150, 60], 1.0),
            Kind::Principal => ([150, 80, 180], 1.0),
            Kind::Stop => ([0, 0, 0], 3.0),
            Kind::Virtual => ([220, 60, 20], 1.0),
        }
    }

    /// Dash and gap lengths in pixels for a dashed stroke.
    pub fn dashes(self) -> Option<(f64, f64)> {
        (self == Kind::Virtual).then_some((6.0, 4.0))
    }
}

/// A mark's label, as the drawings place it: its text box's left and
/// baseline in pixels, `gap` from the mark at `at` (pixels), given the
/// boxes of the labels already placed (left, top, right, bottom). The first of four
/// places (above right, above left, below right, below left) whose box
/// clears them, so close marks (V1 and V2 of a thin lens) do not print one
/// label over the other; above right when none does.
pub fn place_label(at: [f64; 2], text: &str, font_px: f64, gap: f64, placed: &mut Vec<[f64; 4]>) -> [f64; 2] {
    let w = 0.62 * font_px * text.chars().count() as f64;
    let spots = [
        [at[0] + gap, at[1] - gap],
        [at[0] - gap - w, at[1] - gap],
        [at[0] + gap, at[1] + gap + font_px],
        [at[0] - gap - w, at[1] + gap + font_px],
    ];
    let boxed = |p: [f64; 2]| [p[0], p[1] - font_px, p[0] + w, p[1]];
    let clear = |b: [f64; 4]| {
        placed
            .iter()
            .all(|q| b[2] <= q[0] || q[2] <= b[0] || b[3] <= q[1] || q[3] <= b[1])
    };
    let p = spots.into_iter().find(|p| clear(boxed(*p))).unwrap_or(spots[0]);
    placed.push(boxed(p));
    p
}

#[derive(Clone, Debug, Default)]
pub struct Sketch {
    pub lines: Vec<(Kind, Vec<[f64; 2]>)>,
    pub marks: Vec<(&'static str, [f64; 2])>,
    /// The s range shown.
    pub view: [f64; 2],
}

/// World (s, x) to pixels: equal scale on both axes, x up.
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    pub width: f64,
    pub height: f64,
    scale: f64,
    s0: f64,
    x0: f64,
}

impl Frame {
    pub fn px(&self, p: [f64; 2]) -> [f64; 2] {
        [
            (p[0] - self.s0) * self.scale,
            self.height - (p[1] - self.x0) * self.scale,
        ]
    }
}

const MARGIN: f64 = 24.0;

impl Sketch {
    pub fn line(&mut self, kind: Kind, pts: Vec<[f64; 2]>) {
        self.lines.push((kind, pts));
    }

    pub fn mark(&mut self, label: &'static str, at: [f64; 2]) {
        self.marks.push((label, at));
    }

    /// The frame fitting the view into `width` × at most `max_height`
    /// pixels at equal scale; the x range is what the lines reach inside
    /// the view, at least a tenth of its length.
    pub fn frame(&self, width: f64, max_height: f64) -> Frame {
        let [s0, s1] = self.view;
        let inside = |p: &[f64; 2]| p[0] >= s0 && p[0] <= s1 && p[1].is_finite();
        let reach = (self.lines.iter().flat_map(|l| l.1.iter()))
            .chain(self.marks.iter().map(|m| &m.1))
            .filter(|p| inside(p))
            .fold(0.0f64, |a, p| a.max(p[1].abs()));
        let half = (1.1 * reach).max(0.05 * (s1 - s0));
        let scale = ((width - 2.0 * MARGIN) / (s1 - s0)).min((max_height - 2.0 * MARGIN) / (2.0 * half));
        let height = 2.0 * half * scale + 2.0 * MARGIN;
        let used = (s1 - s0) * scale;
        Frame {
            width,
            height,
            scale,
            s0: s0 - (width - used) / (2.0 * scale),
            x0: -half - MARGIN / scale,
        }
    }

    /// An SVG `width` pixels wide (at most as high).
    pub fn svg(&self, width: f64) -> String {
        let f = self.frame(width, width);
        let mut out = String::new();
        let _ = writeln!(
            out,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w:.0}" height="{h:.0}" viewBox="0 0 {w:.0} {h:.0}">"#,
            w = f.width,
            h = f.height
        );
        let _ = writeln!(out, r#"<rect width="100%" height="100%" fill="white"/>"#);
        for (kind, pts) in &self.lines {
            let ([r, g, b], w) = kind.style();
            let d: Vec<String> = pts
                .iter()
                .map(|&p| f.px(p))
                .map(|[x, y]| format!("{x:.2},{y:.2}"))
                .collect();
            let dash = kind
                .dashes()
                .map_or(String::new(), |(on, off)| format!(r#" stroke-dasharray="{on} {off}""#));
            let _ = writeln!(
                out,
                r#"<polyline fill="none" stroke="rgb({r},{g},{b})" stroke-width="{w}"{dash} points="{}"/>"#,
                d.join(" ")
            );
        }
        let mut placed = Vec::new();
        for (label, p) in &self.marks {
            let [x, y] = f.px(*p);
            let _ = writeln!(out, r#"<circle cx="{x:.2}" cy="{y:.2}" r="3" fill="black"/>"#);
            let [tx, ty] = place_label([x, y], label, 14.0, 4.0, &mut placed);
            let _ = writeln!(
                out,
                r#"<text x="{tx:.2}" y="{ty:.2}" font-family="sans-serif" font-size="14">{label}</text>"#,
            );
        }
        out.push_str("</svg>\n");
        out
    }
}
