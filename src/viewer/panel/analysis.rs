//! The optics switches (in the *Lens* section: the overlay in the picture,
//! F6; the analysis window, F7) and the *Lens analysis* window: the
//! cross-section to scale with the ray fan and F, F′, H, H′ and the real
//! marginal focus M; the longitudinal spherical aberration; the spot
//! diagram for the C, d and F lines at a chosen image plane; distortion
//! against field angle (for a selected lens system: `system_analysis.rs`).
//! Everything is computed by `lensview::lens_tools`
//! (every ray by `Lens::trace`) from the lens as it is in this very UI pass,
//! so an edit by key, panel or undo shows in the same frame.

use super::Ctx;
use super::plots::{Series, plot, sketch};
use egui::{Color32, Vec2};
use lensview::lens_tools::{Setup, distortion, fan, spot_diagram};

/// The optics display state (not part of the scene).
pub struct AnalysisState {
    /// The optics overlay over the picture (F6).
    pub optics: bool,
    /// The analysis window (F7).
    pub window: bool,
    /// Object at infinity, else at `object_distance` before V1.
    pub infinity: bool,
    pub object_distance: f64,
    pub field_deg: f64,
    /// The image plane's distance from the paraxial image (defocus).
    pub defocus: f64,
    pub rings: u32,
}

impl Default for AnalysisState {
    fn default() -> Self {
        AnalysisState {
            optics: false,
            window: false,
            infinity: true,
            object_distance: 20.0,
            field_deg: 0.0,
            defocus: 0.0,
            rings: 6,
        }
    }
}

impl AnalysisState {
    /// The object distance the figures use (`None`: at infinity).
    pub fn object(&self) -> Option<f64> {
        (!self.infinity).then_some(self.object_distance)
    }
}

/// The two switches, for the *Lens* section.
pub fn toggles(ui: &mut egui::Ui, cx: &mut Ctx) {
    let a = &mut cx.ui.analysis;
    ui.horizontal(|ui| {
        ui.checkbox(&mut a.optics, "Show optics (F6)")
            .on_hover_text("axis, F, F′, H, H′ and a real ray fan over the picture");
        ui.checkbox(&mut a.window, "Analysis (F7)");
    });
}

pub(super) const LINES: [Color32; 3] = [
    Color32::from_rgb(235, 70, 60),
    Color32::from_rgb(90, 210, 90),
    Color32::from_rgb(90, 140, 255),
];

/// The *Lens analysis* window, when open.
pub fn window(ctx: &egui::Context, cx: &mut Ctx) {
    if !cx.ui.analysis.window {
        return;
    }
    let mut open = true;
    // A selected lens system is analysed; else the lens of the *Lens*
    // section; in a scene without one, its first system.
    let lens = (cx.doc.built().objects.iter().filter_map(|o| o.lens()))
        .nth(cx.ui.lens)
        .cloned();
    let system = match cx.ui.selected {
        Some(lensview::edit::Item::System(i)) => cx.doc.built_system(i).cloned(),
        _ if lens.is_none() => cx.doc.built_system(0).cloned(),
        _ => None,
    };
    let mut placed = Vec::new();
    let area = free_area(ctx, cx.display.panel_width(ctx.content_rect().width()));
    let shown = egui::Window::new("Lens analysis")
        .open(&mut open)
        .default_rect(area.shrink(MARGIN))
        .max_size(area.size())
        .constrain_to(area)
        .show(ctx, |ui| {
            // Whatever the window's height, every figure and line can be
            // scrolled to (at 640×480 the spot's RMS lines and the
            // distortion are below the fold).
            let scroll = egui::ScrollArea::vertical().auto_shrink([false, false]);
            scroll.show(ui, |ui| {
                if let Some(sys) = &system {
                    controls(ui, &mut cx.ui.analysis);
                    placed = super::system_analysis::figures(ui, sys, &cx.ui.analysis);
                    return;
                }
                let Some(lens) = lens else {
                    ui.label("No lens in this scene.");
                    return;
                };
                controls(ui, &mut cx.ui.analysis);
                let a = &cx.ui.analysis;
                match Setup::new(lens.d, lens.r1, lens.r2, lens.index, a.object(), a.field_deg) {
                    Ok(s) => placed = figures(ui, &s, a),
                    Err(e) => {
                        ui.colored_label(super::ERROR, e.to_string());
                    }
                }
            });
        });
    let ppp = ctx.pixels_per_point();
    if let Some(r) = shown {
        cx.ui.rects.insert("Lens analysis", r.response.rect, ppp);
    }
    for (name, r) in placed {
        cx.ui.rects.insert(name, r, ppp);
    }
    cx.ui.analysis.window &= open;
}

/// Space between the analysis window and the edges of the free area.
const MARGIN: f32 = 8.0;

/// The screen right of the panel (`panel` points wide): where the analysis
/// window opens, filling it, and stays.
fn free_area(ctx: &egui::Context, panel: f32) -> egui::Rect {
    let screen = ctx.content_rect();
    egui::Rect::from_min_max(egui::pos2(screen.min.x + panel, screen.min.y), screen.max)
}

/// The figures' sizes in a window `width` points wide with `plots` plots:
/// the sketch's height and each plot's size, as many plots a row as fit at
/// 220 points (all of them, or fewer), every figure growing with the window
/// (the lens's and a system's).
pub(super) fn figure_sizes(width: f32, plots: usize) -> (f32, Vec2) {
    let per_row = (width / 220.0).floor().clamp(1.0, plots.max(1) as f32);
    let w = (width / per_row - 8.0).max(140.0);
    let h = (w * 0.8).clamp(180.0, 360.0);
    ((width * 0.25).clamp(180.0, 360.0), Vec2::new(w, h))
}

fn controls(ui: &mut egui::Ui, a: &mut AnalysisState) {
    ui.horizontal(|ui| {
        ui.checkbox(&mut a.infinity, "object at infinity");
        ui.add_enabled(
            !a.infinity,
            egui::DragValue::new(&mut a.object_distance)
                .range(1e-3..=1e6)
                .speed(0.1)
                .prefix("distance before V1 "),
        );
        ui.add(
            egui::Slider::new(&mut a.field_deg, -60.0..=60.0)
                .text("field °")
                .step_by(0.5),
        );
    });
    ui.horizontal(|ui| {
        ui.add(
            egui::DragValue::new(&mut a.defocus)
                .speed(0.01)
                .prefix("image plane: paraxial focus + "),
        );
        ui.add(egui::Slider::new(&mut a.rings, 1..=16).text("spot rings"));
    });
}

/// The lens's figures; returns where they are (for `--ui-log`).
fn figures(ui: &mut egui::Ui, s: &Setup, a: &AnalysisState) -> super::system_analysis::Placed {
    let width = ui.available_width().max(150.0);
    let (sketch_h, size) = figure_sizes(width, 3);
    let mut placed = Vec::new();
    match fan(s, 7, None) {
        Ok(f) => {
            let c = &f.cardinal.info;
            let opt = |x: Option<f64>| x.map_or("—".into(), |x| format!("{x:.5}"));
            ui.label(format!(
                "EFL {}   BFD {}   FFD {}   marginal focus M {} from V2",
                opt(c.efl),
                opt(c.bfd),
                opt(c.ffd),
                opt(f.cardinal.object_marginal_focus_from_v2)
            ));
            placed.push(("analysis sketch", sketch(ui, &f.sketch(s), width, sketch_h)));
            ui.horizontal_wrapped(|ui| {
                let lsa: Vec<[f64; 2]> = f.lsa.iter().filter_map(|p| Some([p.lsa?, p.height])).collect();
                let series = [Series {
                    colour: LINES[1],
                    points: lsa,
                    dots: false,
                }];
                let r = plot(ui, size, "LSA (d line)", ("focus − paraxial", "height"), &series, false);
                placed.push(("analysis LSA", r));
                placed.extend(spot(ui, s, a, size).map(|r| ("analysis spot", r)));
                placed.extend(distortion_plot(ui, s, size).map(|r| ("analysis distortion", r)));
            });
        }
        Err(e) => {
            ui.colored_label(super::ERROR, e.to_string());
        }
    }
    placed
}

fn spot(ui: &mut egui::Ui, s: &Setup, a: &AnalysisState, size: Vec2) -> Option<egui::Rect> {
    let paraxial = s.image_plane(None).ok();
    let plane = paraxial.map(|p| p + a.defocus).filter(|p| *p > 0.0);
    let Some(Ok(sd)) = plane.map(|p| spot_diagram(s, Some(p), a.rings)) else {
        ui.allocate_ui(size, |ui| {
            ui.label("Spot: no real image plane after V2 here.");
        });
        return None;
    };
    ui.vertical(|ui| {
        let series = spot_series(sd.spots.iter().map(|sp| sp.rays.iter().map(|r| r.image_point)));
        let title = format!("Spot at {:.4} after V2", sd.image_plane_from_v2);
        let rect = plot(ui, size, &title, ("x", "y"), &series, true);
        for (sp, colour) in sd.spots.iter().zip(LINES) {
            let c = sp
                .centroid
                .map_or("—".into(), |c| lensview::lens_tools::spot::centroid_text(c, 2));
            let r = sp.rms_radius.map_or("—".into(), |r| format!("{r:.3e}"));
            ui.colored_label(colour, format!("{}: RMS {r}  centroid {c}", sp.line));
        }
        rect
    })
    .inner
    .into()
}

fn distortion_plot(ui: &mut egui::Ui, s: &Setup, size: Vec2) -> Option<egui::Rect> {
    let points = distortion(s, 30.0, 30).ok().map(|d| {
        (d.points.iter())
            .filter_map(|p| Some([p.field_deg, p.distortion_percent?]))
            .collect()
    });
    distortion_curve(ui, size, points)
}

/// The spot plot's series (the lens's and a system's): where each line's
/// rays meet the image plane, as dots in the line's colour (C, d, F).
pub(super) fn spot_series<I>(lines: impl IntoIterator<Item = I>) -> Vec<Series>
where
    I: IntoIterator<Item = Option<[f64; 3]>>,
{
    (lines.into_iter().zip(LINES))
        .map(|(hits, colour)| Series {
            colour,
            points: hits.into_iter().flatten().map(|p| [p[0], p[1]]).collect(),
            dots: true,
        })
        .collect()
}

/// The distortion plot of `points` (field °, %) from the axis, or why
/// there is none (no real paraxial image): the lens's and a system's.
/// Returns where the plot is on screen.
pub(super) fn distortion_curve(ui: &mut egui::Ui, size: Vec2, points: Option<Vec<[f64; 2]>>) -> Option<egui::Rect> {
    let Some(points) = points else {
        ui.allocate_ui(size, |ui| {
            ui.label("Distortion: no real paraxial image.");
        });
        return None;
    };
    let mut pts = vec![[0.0, 0.0]];
    pts.extend(points);
    let series = [Series {
        colour: LINES[2],
        points: pts,
        dots: false,
    }];
    Some(plot(ui, size, "Distortion", ("field °", "%"), &series, false))
}
