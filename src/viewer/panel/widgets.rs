//! Small egui widgets the sections share: rows of numbers, colours, the
//! index (constant or Cauchy) and the red frame of a draft.

use super::ERROR;
use lensview::edit::document::index_with_dispersion;
use lensview::scene::file::IndexFile;

/// Three drag values in a row; true when one changed.
pub fn vec3(ui: &mut egui::Ui, v: &mut [f64; 3], speed: f64) -> bool {
    ui.horizontal(|ui| {
        let mut changed = false;
        for (x, p) in v.iter_mut().zip(["x ", "y ", "z "]) {
            changed |= ui
                .add(egui::DragValue::new(x).speed(speed).max_decimals(4).prefix(p))
                .changed();
        }
        changed
    })
    .inner
}

/// A positive size in the *Add* form.
pub fn positive(x: &mut f64) -> egui::DragValue<'_> {
    egui::DragValue::new(x).speed(0.01).range(0.001..=1e6).max_decimals(4)
}

pub fn number(ui: &mut egui::Ui, x: &mut f64, speed: f64) -> bool {
    ui.add(egui::DragValue::new(x).speed(speed).max_decimals(6)).changed()
}

/// A colour picker (linear RGB, as in the scene file) and its numbers.
pub fn colour(ui: &mut egui::Ui, c: &mut [f64; 3]) -> bool {
    ui.horizontal(|ui| {
        let mut f = c.map(|x| x.clamp(0.0, 1.0) as f32);
        let mut changed = false;
        if ui.color_edit_button_rgb(&mut f).changed() {
            *c = f.map(|x| x as f64);
            changed = true;
        }
        for x in c.iter_mut() {
            changed |= ui.add(egui::DragValue::new(x).speed(0.01).max_decimals(3)).changed();
        }
        changed
    })
    .inner
}

/// An optional name: empty text means none.
pub fn name(ui: &mut egui::Ui, name: &mut Option<String>) {
    let mut n = name.clone().unwrap_or_default();
    if ui.text_edit_singleline(&mut n).changed() {
        *name = if n.trim().is_empty() { None } else { Some(n) };
    }
}

/// A refractive index: a constant, or Cauchy's A and B.
pub fn index(ui: &mut egui::Ui, n: &mut IndexFile) {
    ui.horizontal(|ui| {
        let cauchy = matches!(n, IndexFile::Cauchy(_));
        if ui.radio(!cauchy, "n").clicked() {
            *n = index_with_dispersion(*n, false);
        }
        if ui.radio(cauchy, "Cauchy A + B/λ²").clicked() {
            *n = index_with_dispersion(*n, true);
        }
    });
    match n {
        IndexFile::Constant(v) => {
            ui.add(egui::DragValue::new(v).speed(0.002).max_decimals(5).prefix("n "));
        }
        IndexFile::Cauchy([a, b]) => {
            ui.horizontal(|ui| {
                ui.add(egui::DragValue::new(a).speed(0.002).max_decimals(5).prefix("A "));
                ui.add(egui::DragValue::new(b).speed(0.0002).max_decimals(6).prefix("B "))
                    .on_hover_text("µm²");
            });
        }
    }
}

/// A frame around `add`, red when it shows a draft that did not validate.
pub fn draft_frame<R>(ui: &mut egui::Ui, is_draft: bool, add: impl FnOnce(&mut egui::Ui) -> R) -> R {
    let stroke = if is_draft {
        egui::Stroke::new(1.5, ERROR)
    } else {
        egui::Stroke::NONE
    };
    egui::Frame::new().stroke(stroke).inner_margin(2.0).show(ui, add).inner
}
