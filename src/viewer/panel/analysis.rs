//! The optics switches (in the *Lens* section: the overlay in the picture,
//! F6; the analysis window, F7) and the *Lens analysis* window: the
//! cross-section to scale with the ray fan and F, F′, H, H′ and the real
//! marginal focus M; the longitudinal spherical aberration; the spot
//! diagram for the C, d and F lines at a chosen image plane; distortion
//! against field angle (for a selected lens system: `system_analysis.rs`).
//! Everything is computed by `lensview::lens_tools::analysis` (every ray
//! by `Lens::trace` or `LensSystem::trace`; the web page's analysis panel
//! shows the same figures) from the lens as it is in this very UI pass, so
//! an edit by key, panel or undo shows in the same frame; this draws them.

use super::Ctx;
use super::plots::{Series, plot, sketch};
use egui::{Color32, Vec2};
use egui_plot::MarkerShape;
use lensview::lens_tools::analysis::{FieldSpot, Figures, Settings, lens_figures, plane_words, system_figures};

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

    /// The library's settings of the figures.
    pub fn settings(&self) -> Settings {
        Settings {
            object_distance: self.object(),
            field_deg: self.field_deg,
            defocus: self.defocus,
            rings: self.rings,
        }
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
                if system.is_none() && lens.is_none() {
                    ui.label("No lens in this scene.");
                    return;
                }
                controls(ui, &mut cx.ui.analysis);
                let a = cx.ui.analysis.settings();
                let figures = match (&system, &lens) {
                    (Some(sys), _) => system_figures(sys, &a),
                    (None, Some(lens)) => lens_figures(lens, &a),
                    (None, None) => return,
                };
                match figures {
                    Ok(f) => placed = self::figures(ui, &f),
                    Err(e) => {
                        ui.colored_label(super::ERROR, e);
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

/// The figures of a lens or a system; returns where they are (for
/// `--ui-log`).
fn figures(ui: &mut egui::Ui, f: &Figures) -> super::system_analysis::Placed {
    let width = ui.available_width().max(150.0);
    let plots = if f.axial_colour.is_some() { 5 } else { 3 };
    let (sketch_h, size) = figure_sizes(width, plots);
    let mut placed = Vec::new();
    ui.label(f.header.as_str());
    placed.push(("analysis sketch", sketch(ui, &f.sketch, width, sketch_h)));
    // Three plots, for a dispersive system five with the axial and lateral
    // colour: all in a row if they fit, wrapped (and scrolled) if not.
    ui.with_layout(figure_row(), |ui| {
        placed.push(("analysis LSA", lsa_plot(ui, size, f.lsa.clone())));
        placed.extend(spot_figure(ui, size, f.spots.as_deref(), f.last).map(|r| ("analysis spot", r)));
        placed.extend(distortion_curve(ui, size, f.distortion.clone()).map(|r| ("analysis distortion", r)));
        placed.extend(super::system_analysis::colour_plots(ui, f, size));
    });
    placed
}

/// The spot plots of `diagrams` (each: field angle, image plane from the
/// last vertex `last`, lines) side by side, each with its lines' RMS
/// radius and centroid below, or why there are none; returns where they
/// are together.
fn spot_figure(ui: &mut egui::Ui, size: Vec2, diagrams: Option<&[FieldSpot]>, last: &str) -> Option<egui::Rect> {
    let Some(diagrams) = diagrams else {
        ui.allocate_ui(size, |ui| {
            ui.label(format!(
                "Spot: no image plane here (give the image a plane after {last})."
            ));
        });
        return None;
    };
    let mut all: Option<egui::Rect> = None;
    for FieldSpot {
        field_deg,
        plane_from_last: plane,
        lines,
    } in diagrams
    {
        // Its size with the lines below, so that a wrapping row wraps before it.
        let tall = size + Vec2::new(0.0, 80.0);
        let r = ui.allocate_ui_with_layout(tall, egui::Layout::top_down(egui::Align::Min), |ui| {
            let series = spot_series(lines.iter().map(|l| l.points.iter().copied()));
            let title = format!("Spot, field {field_deg}°");
            let rect = plot(ui, size, &title, ("x (units)", "y (units)"), &series, true);
            ui.small(plane_words(*plane, last));
            for (l, colour) in lines.iter().zip(LINES) {
                let c = l
                    .centroid
                    .map_or("—".into(), |c| lensview::lens_tools::spot::centroid_text(c, 2));
                let r = l.rms.map_or("—".into(), |r| format!("{r:.3e}"));
                ui.colored_label(colour, format!("{}: RMS {r}  centroid {c}", l.line));
            }
            rect
        });
        all = Some(all.map_or(r.inner, |a| a.union(r.inner)));
    }
    all
}

/// The plots' row: left to right, wrapped, their tops aligned.
fn figure_row() -> egui::Layout {
    egui::Layout::left_to_right(egui::Align::Min).with_main_wrap(true)
}

/// The longitudinal spherical aberration (the lens's and a system's).
fn lsa_plot(ui: &mut egui::Ui, size: Vec2, points: Vec<[f64; 2]>) -> egui::Rect {
    let series = [Series {
        colour: LINES[1],
        points,
        dots: None,
        name: "",
    }];
    let axes = ("focus − paraxial focus (units)", "pupil height (units)");
    plot(
        ui,
        size,
        "Longitudinal spherical aberration (d line)",
        axes,
        &series,
        false,
    )
}

/// The spot plot's series (the lens's and a system's): where each line's
/// rays meet the image plane, as dots in the line's colour (C, d, F).
fn spot_series<I>(lines: impl IntoIterator<Item = I>) -> Vec<Series>
where
    I: IntoIterator<Item = Option<[f64; 3]>>,
{
    (lines.into_iter().zip(LINES).zip(SPOT_MARKS))
        .map(|((hits, colour), (name, shape))| Series {
            colour,
            points: hits.into_iter().flatten().map(|p| [p[0], p[1]]).collect(),
            dots: Some(shape),
            name,
        })
        .collect()
}

/// The C, d and F lines' names and markers (dots that coincide stay
/// distinguishable: a hollow circle, a cross, a hollow triangle).
const SPOT_MARKS: [(&str, MarkerShape); 3] = [
    ("C", MarkerShape::Circle),
    ("d", MarkerShape::Cross),
    ("F", MarkerShape::Up),
];

/// The distortion plot of `points` (field °, %) from the axis, or why
/// there is none (no real paraxial image): the lens's and a system's.
/// Returns where the plot is on screen.
fn distortion_curve(ui: &mut egui::Ui, size: Vec2, points: Option<Vec<[f64; 2]>>) -> Option<egui::Rect> {
    let Some(points) = points else {
        ui.allocate_ui(size, |ui| {
            ui.label("Distortion: no real paraxial image.");
        });
        return None;
    };
    let mut pts = vec![[0.0, 0.0]];
    pts.extend(points);
    let marks: Vec<[f64; 2]> = pts.iter().skip(1).step_by(5).copied().collect();
    let series = [
        Series {
            colour: LINES[2],
            points: pts,
            dots: None,
            name: "",
        },
        Series {
            colour: LINES[2],
            points: marks,
            dots: Some(MarkerShape::Circle),
            name: "",
        },
    ];
    Some(plot(
        ui,
        size,
        "Distortion",
        ("field angle (°)", "distortion (%)"),
        &series,
        false,
    ))
}
