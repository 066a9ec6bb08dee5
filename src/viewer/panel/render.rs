//! The *Render* section: the window's resolution and sample cap (display
//! settings, carried out by the shell), the scene's max depth and
//! background, pause, and what the render thread last delivered.

use super::{Ctx, drafted, widgets::colour};
use crate::viewer::session::Command;
use crate::viewer::stats::{caustics_text, stage_text};
use lensview::color::ToneCurve;

pub fn section(ui: &mut egui::Ui, cx: &mut Ctx) {
    let header = egui::CollapsingHeader::new("Render");
    super::section(ui, cx, header, "Render", |ui, cx| {
        egui::Grid::new("render-grid")
            .num_columns(2)
            .show(ui, |ui| resolution_and_cap(ui, cx));
        scene_settings(ui, cx);
        display_settings(ui, cx);
        let mut caustics = cx.doc.built().features.caustics;
        if ui
            .checkbox(&mut caustics, "caustics")
            .on_hover_text("light through glass and off mirrors by photon mapping (C)")
            .changed()
        {
            let r = cx.doc.set_caustics(caustics);
            cx.apply_result(if caustics { "caustics on" } else { "caustics off" }, r);
        }
        ui.horizontal(|ui| {
            let label = if cx.render.paused {
                "Resume refinement"
            } else {
                "Pause refinement"
            };
            if ui.button(label).on_hover_text("Space").clicked() {
                cx.ask(Command::TogglePause);
            }
        });
        if let Some(f) = cx.render.frame {
            ui.weak(format!(
                "{}: {}×{}, {:.0} ms, {:.2} M samples/s",
                stage_text(f, cx.render.paused),
                f.width,
                f.height,
                f.render_ms,
                f.samples_per_s / 1e6
            ));
            if f.caustics.passes > 0 {
                ui.weak(caustics_text(f));
            }
        }
    });
}

fn resolution_and_cap(ui: &mut egui::Ui, cx: &mut Ctx) {
    ui.label("resolution");
    let mut div = cx.display.res_div;
    egui::ComboBox::from_id_salt("resolution")
        .selected_text(format!("{}%", 100 / div))
        .show_ui(ui, |ui| {
            for d in [1, 2, 3, 4] {
                ui.selectable_value(&mut div, d, format!("{}%", 100 / d));
            }
        });
    if div != cx.display.res_div {
        cx.ask(Command::Resolution(div));
    }
    ui.end_row();
    ui.label("sample cap");
    let mut cap = cx.render.max_spp;
    egui::ComboBox::from_id_salt("sample-cap")
        .selected_text(format!("{cap} per pixel"))
        .show_ui(ui, |ui| {
            for k in 0..=12 {
                ui.selectable_value(&mut cap, 1 << k, format!("{} per pixel", 1 << k));
            }
        });
    if cap != cx.render.max_spp {
        cx.ask(Command::SampleCap(cap));
    }
    ui.end_row();
}

/// The scene's own render settings: max depth and background.
fn scene_settings(ui: &mut egui::Ui, cx: &mut Ctx) {
    let depth = cx.doc.scene().render.max_depth;
    drafted(
        ui,
        cx,
        "render.max_depth",
        depth,
        |ui, d: &mut u32| {
            ui.horizontal(|ui| {
                ui.label("max depth");
                ui.add(egui::DragValue::new(d).speed(0.1))
                    .on_hover_text("longest chain of reflections and refractions (0–64)");
            });
        },
        |doc, d| doc.set_max_depth(d),
    );
    let bg = cx.doc.scene().render.background;
    drafted(
        ui,
        cx,
        "render.background",
        bg,
        |ui, c: &mut [f64; 3]| {
            ui.horizontal(|ui| {
                ui.label("background");
                colour(ui, c);
            });
        },
        |doc, c| doc.set_background(c),
    );
}

/// `[display]`: the exposure (stops) and the tone curve of the picture
/// shown and of its PNG (the EXR stays linear). Changing them keeps the
/// samples: the render thread shows them again.
fn display_settings(ui: &mut egui::Ui, cx: &mut Ctx) {
    let d = cx.doc.scene().display;
    let mut stops = d.exposure;
    ui.horizontal(|ui| {
        ui.label("exposure");
        let r = ui
            .add(egui::Slider::new(&mut stops, -8.0..=8.0).step_by(0.1).suffix(" EV"))
            .on_hover_text("stops: each one doubles the light shown (G/H); the EXR stays linear");
        if r.changed() {
            let res = cx.doc.set_exposure(stops);
            cx.apply_result(&format!("exposure {stops:+.1} stops"), res);
        }
        if r.drag_stopped() || r.lost_focus() {
            cx.doc.seal();
        }
    });
    ui.horizontal(|ui| {
        ui.label("tone curve");
        let mut curve = d.tone;
        egui::ComboBox::from_id_salt("tone-curve")
            .selected_text(curve.name())
            .show_ui(ui, |ui| {
                for c in ToneCurve::ALL {
                    ui.selectable_value(&mut curve, c, c.name());
                }
            })
            .response
            .on_hover_text("clamp clips to white; reinhard and aces roll the highlights off (Y)");
        if curve != d.tone {
            let res = cx.doc.set_tone(curve);
            cx.apply_result(&format!("tone curve {}", curve.name()), res);
        }
    });
}
