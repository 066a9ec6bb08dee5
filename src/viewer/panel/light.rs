//! The *Light* section: which light, add and delete, its fields (type,
//! position or direction, intensity, colour), a colour-temperature slider,
//! then the ambient light and shadows.

use super::widgets::{Field, colour, number, vec3};
use super::{Ctx, drafted};
use lensview::edit::Change;
use lensview::edit::document::switch_light_kind;
use lensview::scene::file::{AmbientFile, LightFile, LightKind};

pub fn section(ui: &mut egui::Ui, cx: &mut Ctx) {
    let open = std::mem::take(&mut cx.ui.open_light).then_some(true);
    let header = egui::CollapsingHeader::new("Light").open(open);
    super::section(ui, cx, header, "Light", |ui, cx| {
        ui.horizontal(|ui| choose_add_delete(ui, cx));
        let count = cx.doc.scene().lights.len();
        if count == 0 {
            ui.weak("No light: only the ambient level lights the scene.");
        } else {
            let k = cx.ui.light.min(count - 1);
            cx.ui.light = k;
            let current = cx.doc.scene().lights[k].clone();
            drafted(
                ui,
                cx,
                &format!("lights[{k}]"),
                current,
                |ui, l: &mut LightFile| {
                    egui::Grid::new(("light-grid", k))
                        .num_columns(2)
                        .show(ui, |ui| light_rows(ui, l));
                },
                move |doc, v| doc.set_light(k, v),
            );
            ui.horizontal(|ui| temperature(ui, cx, k));
        }
        ui.separator();
        ambient_and_shadows(ui, cx);
    });
}

/// Which light (when there are several), *Add a point light*, *Delete*.
fn choose_add_delete(ui: &mut egui::Ui, cx: &mut Ctx) {
    let count = cx.doc.scene().lights.len();
    if count > 1 {
        let kinds: Vec<String> = cx
            .doc
            .scene()
            .lights
            .iter()
            .enumerate()
            .map(|(k, l)| format!("light {} ({})", k + 1, kind_name(l.kind)))
            .collect();
        cx.ui.light = cx.ui.light.min(count - 1);
        egui::ComboBox::from_id_salt("light-choice")
            .selected_text(kinds[cx.ui.light].clone())
            .show_ui(ui, |ui| {
                for (k, n) in kinds.iter().enumerate() {
                    ui.selectable_value(&mut cx.session.ui.light, k, n);
                }
            });
    }
    if ui.button("Add a point light").clicked() {
        let r = cx.doc.add_point_light();
        if let Ok(k) = r {
            cx.ui.light = k;
        }
        cx.apply_result("added a point light above the camera", r.map(|_| Change::Picture));
    }
    if count > 0 && ui.button("Delete").clicked() {
        let k = cx.ui.light.min(count - 1);
        let r = cx.doc.delete_light(k);
        cx.ui.light = 0;
        cx.apply_result("deleted the light (Ctrl+Z undoes)", r);
    }
}

fn light_rows(ui: &mut egui::Ui, l: &mut LightFile) {
    ui.label("type");
    ui.horizontal(|ui| {
        for (kind, text) in [(LightKind::Point, "point"), (LightKind::Directional, "directional")] {
            if ui.radio(l.kind == kind, text).clicked() {
                switch_light_kind(l, kind);
            }
        }
    });
    ui.end_row();
    if l.kind == LightKind::Point {
        ui.label("position");
        let mut p = l.position.unwrap_or_default();
        if vec3(ui, &mut p, 0.05, Field::Coordinate) {
            l.position = Some(p);
        }
    } else {
        ui.label("direction");
        let mut d = l.direction.unwrap_or([0.0, -1.0, 0.0]);
        if vec3(ui, &mut d, 0.01, Field::Coordinate) {
            l.direction = Some(d);
        }
    }
    ui.end_row();
    ui.label("intensity").on_hover_text(if l.kind == LightKind::Point {
        "power Φ: a surface r away receives Φ·cosθ/(4πr²)"
    } else {
        "irradiance at normal incidence"
    });
    let speed = (l.intensity.abs() * 0.005).max(0.01);
    number(ui, &mut l.intensity, speed, Field::Intensity);
    ui.end_row();
    ui.label("colour");
    colour(ui, &mut l.color);
    ui.end_row();
}

/// Light `k`'s colour as a black body (the temperature is shared with the
/// , and . keys).
fn temperature(ui: &mut egui::Ui, cx: &mut Ctx, k: usize) {
    ui.label("colour temperature");
    let r = ui.add(
        egui::Slider::new(&mut cx.session.ui.temperature, 1000.0..=12000.0)
            .suffix(" K")
            .step_by(50.0),
    );
    if r.changed() {
        let t = cx.ui.temperature;
        let r = cx.doc.set_light_temperature(k, t);
        cx.apply_result(&format!("light colour: black body {t:.0} K"), r);
    }
}

fn ambient_and_shadows(ui: &mut egui::Ui, cx: &mut Ctx) {
    let current = cx.doc.scene().ambient.clone();
    drafted(
        ui,
        cx,
        "ambient",
        current,
        |ui, a: &mut AmbientFile| {
            egui::Grid::new("ambient-grid").num_columns(2).show(ui, |ui| {
                ui.label("ambient level");
                number(ui, &mut a.intensity, 0.002, Field::Intensity);
                ui.end_row();
                ui.label("ambient colour");
                colour(ui, &mut a.color);
                ui.end_row();
            });
        },
        |doc, v| doc.set_ambient(v),
    );
    let mut shadows = cx.doc.scene().render.shadows;
    if ui.checkbox(&mut shadows, "shadows").changed() {
        let r = cx.doc.set_shadows(shadows);
        cx.apply_result(if shadows { "shadows on" } else { "shadows off" }, r);
    }
}

fn kind_name(k: LightKind) -> &'static str {
    match k {
        LightKind::Point => "point",
        LightKind::Directional => "directional",
    }
}
