//! Small plots drawn with egui's painter for the analysis window: axes
//! with their ranges, lines or dots, and the cross-section sketch.

use egui::{Color32, Pos2, Rect, Stroke, Vec2, pos2};
use lensview::lens_tools::sketch::{Sketch, place_label};

pub struct Series {
    pub colour: Color32,
    pub points: Vec<[f64; 2]>,
    /// Dots instead of a line.
    pub dots: bool,
}

const TEXT: Color32 = Color32::from_gray(210);
const FRAME: Color32 = Color32::from_gray(90);

fn short(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else if x.abs() >= 1e-3 && x.abs() < 1e4 {
        format!("{x:.4}")
    } else {
        format!("{x:.2e}")
    }
}

/// A plot `size` points large: `title`, axis names, and the series in a
/// range fitted to them (with `equal`, one scale on both axes). Returns
/// where it is on screen.
pub fn plot(ui: &mut egui::Ui, size: Vec2, title: &str, axes: (&str, &str), series: &[Series], equal: bool) -> Rect {
    let (rect, _) = ui.allocate_exact_size(size, egui::Sense::hover());
    let painter = ui.painter_at(rect);
    let font = egui::FontId::proportional(13.0);
    painter.text(rect.center_top(), egui::Align2::CENTER_TOP, title, font.clone(), TEXT);
    let area = Rect::from_min_max(rect.min + Vec2::new(52.0, 20.0), rect.max - Vec2::new(8.0, 30.0));
    painter.rect_stroke(area, 0.0, Stroke::new(1.0, FRAME), egui::StrokeKind::Inside);
    let (w, h) = (f64::from(area.width()), f64::from(area.height()));
    let Some((lo, hi)) = fit(series, equal, w, h) else {
        painter.text(
            area.center(),
            egui::Align2::CENTER_CENTER,
            "nothing to show",
            font,
            TEXT,
        );
        return rect;
    };
    let at = |p: &[f64; 2]| -> Pos2 {
        pos2(
            area.min.x + ((p[0] - lo[0]) / (hi[0] - lo[0]) * w) as f32,
            area.max.y - ((p[1] - lo[1]) / (hi[1] - lo[1]) * h) as f32,
        )
    };
    let small = egui::FontId::proportional(11.0);
    let corner = |p: Pos2, a: egui::Align2, s: String| painter.text(p, a, s, small.clone(), TEXT);
    corner(
        area.left_bottom() + Vec2::new(0.0, 2.0),
        egui::Align2::LEFT_TOP,
        short(lo[0]),
    );
    corner(
        area.right_bottom() + Vec2::new(0.0, 2.0),
        egui::Align2::RIGHT_TOP,
        short(hi[0]),
    );
    corner(
        area.left_bottom() - Vec2::new(3.0, 0.0),
        egui::Align2::RIGHT_BOTTOM,
        short(lo[1]),
    );
    corner(
        area.left_top() - Vec2::new(3.0, 0.0),
        egui::Align2::RIGHT_TOP,
        short(hi[1]),
    );
    corner(
        area.center_bottom() + Vec2::new(0.0, 14.0),
        egui::Align2::CENTER_TOP,
        axes.0.into(),
    );
    corner(
        area.left_center() - Vec2::new(3.0, 0.0),
        egui::Align2::RIGHT_CENTER,
        axes.1.into(),
    );
    if lo[0] < 0.0 && hi[0] > 0.0 {
        painter.line_segment([at(&[0.0, lo[1]]), at(&[0.0, hi[1]])], Stroke::new(1.0, FRAME));
    }
    if lo[1] < 0.0 && hi[1] > 0.0 {
        painter.line_segment([at(&[lo[0], 0.0]), at(&[hi[0], 0.0])], Stroke::new(1.0, FRAME));
    }
    for s in series {
        let p: Vec<Pos2> = s
            .points
            .iter()
            .filter(|p| p[0].is_finite() && p[1].is_finite())
            .map(at)
            .collect();
        if s.dots {
            for q in p {
                painter.circle_filled(q, 1.6, s.colour);
            }
        } else {
            painter.add(egui::Shape::line(p, Stroke::new(1.5, s.colour)));
        }
    }
    rect
}

/// The plotted range: the series' extent with a margin (one scale for both
/// axes with `equal`, in a `w` × `h` area); `None` without a finite point.
fn fit(series: &[Series], equal: bool, w: f64, h: f64) -> Option<([f64; 2], [f64; 2])> {
    let pts = series
        .iter()
        .flat_map(|s| s.points.iter())
        .filter(|p| p[0].is_finite() && p[1].is_finite());
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in pts {
        for i in 0..2 {
            lo[i] = lo[i].min(p[i]);
            hi[i] = hi[i].max(p[i]);
        }
    }
    if !(lo[0].is_finite() && lo[1].is_finite()) {
        return None;
    }
    for i in 0..2 {
        let span = (hi[i] - lo[i]).max(1e-12 * hi[i].abs().max(lo[i].abs())).max(1e-300);
        let mid = 0.5 * (hi[i] + lo[i]);
        lo[i] = mid - 0.55 * span;
        hi[i] = mid + 0.55 * span;
    }
    if equal {
        let k = ((hi[0] - lo[0]) / w).max((hi[1] - lo[1]) / h);
        for (i, len) in [(0, w), (1, h)] {
            let mid = 0.5 * (hi[i] + lo[i]);
            lo[i] = mid - 0.5 * k * len;
            hi[i] = mid + 0.5 * k * len;
        }
    }
    Some((lo, hi))
}

/// The cross-section sketch to scale, `width` points wide; returns where
/// it is on screen.
pub fn sketch(ui: &mut egui::Ui, sk: &Sketch, width: f32, max_height: f32) -> Rect {
    let f = sk.frame(f64::from(width), f64::from(max_height));
    let (rect, _) = ui.allocate_exact_size(Vec2::new(f.width as f32, f.height as f32), egui::Sense::hover());
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 0.0, Color32::from_gray(250));
    let at = |p: [f64; 2]| {
        let [x, y] = f.px(p);
        rect.min + Vec2::new(x as f32, y as f32)
    };
    for (kind, pts) in &sk.lines {
        let ([r, g, b], w) = kind.style();
        let line: Vec<Pos2> = pts.iter().map(|&p| at(p)).collect();
        let stroke = Stroke::new(w as f32, Color32::from_rgb(r, g, b));
        match kind.dashes() {
            Some((on, off)) => {
                painter.extend(egui::Shape::dashed_line(&line, stroke, on as f32, off as f32));
            }
            None => {
                painter.add(egui::Shape::line(line, stroke));
            }
        }
    }
    let mut placed = Vec::new();
    for (label, p) in &sk.marks {
        let q = at(*p);
        painter.circle_filled(q, 3.0, Color32::BLACK);
        let font = egui::FontId::proportional(13.0);
        // egui's font has no ′.
        let text = label.replace('′', "'");
        let rel = [f64::from(q.x - rect.min.x), f64::from(q.y - rect.min.y)];
        let [tx, ty] = place_label(rel, &text, 13.0, &mut placed);
        painter.text(
            rect.min + Vec2::new(tx as f32, ty as f32),
            egui::Align2::LEFT_BOTTOM,
            text,
            font,
            Color32::BLACK,
        );
    }
    rect
}
