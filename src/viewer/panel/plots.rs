//! The analysis window's plots (egui_plot: axes with ticks, names and
//! units, a legend) and the cross-section sketch (egui's painter).

use egui::{Color32, Pos2, Rect, Stroke, Vec2};
use egui_plot::{Legend, Line, MarkerShape, Plot, Points};
use lensview::lens_tools::sketch::{Sketch, place_label};

pub struct Series {
    pub colour: Color32,
    pub points: Vec<[f64; 2]>,
    /// Dots of this shape instead of a line.
    pub dots: Option<MarkerShape>,
    /// Its name in the legend (none: no legend entry).
    pub name: &'static str,
}

const TEXT: Color32 = Color32::from_gray(210);

/// A plot `size` points large, drawn by egui_plot: `title` above, axes
/// with ticks and their names (with units), the series (with `equal`, one
/// scale on both axes), a legend when a series is named. Returns where it
/// is on screen.
pub fn plot(ui: &mut egui::Ui, size: Vec2, title: &str, axes: (&str, &str), series: &[Series], equal: bool) -> Rect {
    // Allocated at its size first, so that a wrapping row wraps before it.
    let layout = egui::Layout::top_down(egui::Align::Center);
    ui.allocate_ui_with_layout(size, layout, |ui| {
        ui.set_width(size.x);
        ui.label(egui::RichText::new(title).color(TEXT).size(13.0));
        let finite = |p: &&[f64; 2]| p[0].is_finite() && p[1].is_finite();
        if !series.iter().any(|s| s.points.iter().any(|p| finite(&p))) {
            let (rect, _) = ui.allocate_exact_size(size - Vec2::new(0.0, 18.0), egui::Sense::hover());
            ui.painter_at(rect).text(
                rect.center(),
                egui::Align2::CENTER_CENTER,
                "nothing to show",
                egui::FontId::proportional(13.0),
                TEXT,
            );
            return;
        }
        let mut p = Plot::new(("analysis plot", title))
            .width(size.x)
            .height(size.y - 18.0)
            .x_axis_label(axes.0)
            .y_axis_label(axes.1)
            .allow_scroll(false)
            .allow_zoom(false)
            .allow_drag(false)
            .allow_boxed_zoom(false)
            .show_x(false)
            .show_y(false)
            .set_margin_fraction(Vec2::splat(0.08));
        if equal {
            p = p.data_aspect(1.0);
        }
        if series.iter().any(|s| !s.name.is_empty()) {
            p = p.legend(Legend::default().position(egui_plot::Corner::RightTop));
        }
        p.show(ui, |plot| {
            for s in series {
                let pts: Vec<[f64; 2]> = s.points.iter().filter(finite).copied().collect();
                match s.dots {
                    Some(shape) => plot.points(
                        Points::new(s.name, pts)
                            .shape(shape)
                            .color(s.colour)
                            .filled(shape == MarkerShape::Cross)
                            .radius(2.5),
                    ),
                    None => plot.line(Line::new(s.name, pts).color(s.colour).width(1.5)),
                }
            }
        });
    })
    .response
    .rect
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
        let [tx, ty] = place_label(rel, &text, 13.0, 4.0, &mut placed);
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
