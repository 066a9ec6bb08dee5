//! Small egui widgets the sections share: rows of numbers, colours, the
//! index (constant or Cauchy) and the red frame of a draft. Every number
//! of a scene is dragged or typed within its [`Field`]'s range: the
//! supported domain that the scene validator enforces
//! ([`lensview::math::domain`]), so a panel edit is clamped to what a
//! scene file may hold.

use super::ERROR;
use lensview::edit::document::{axis_angles, axis_from_angles, index_with_dispersion};
use lensview::math::domain;
use lensview::scene::file::IndexFile;
use std::ops::RangeInclusive;

/// What a number of the scene is, and so the range a panel field keeps it
/// in (within [`domain`], the one source of these limits).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Field {
    /// A coordinate of a position, or a component of a direction.
    Coordinate,
    /// A rotation angle in degrees (only kept finite).
    Angle,
    /// A size, a radius, a lens diameter or face radius.
    Length,
    /// A colour component.
    Colour,
    /// A light's intensity.
    Intensity,
    /// A material's ambient, diffuse or specular coefficient.
    Coefficient,
    /// A material's reflectivity or transparency.
    Fraction,
    /// A Phong exponent (only kept finite).
    Exponent,
    /// An index of refraction, or Cauchy's A.
    Index,
    /// Cauchy's B (µm²): with A = 1, the index at 0.38 µm stays in the domain.
    Dispersion,
}

impl Field {
    #[cfg(test)]
    pub const ALL: [Field; 10] = [
        Field::Coordinate,
        Field::Angle,
        Field::Length,
        Field::Colour,
        Field::Intensity,
        Field::Coefficient,
        Field::Fraction,
        Field::Exponent,
        Field::Index,
        Field::Dispersion,
    ];

    /// The values a panel field of this kind may take.
    pub fn range(self) -> RangeInclusive<f64> {
        let b = (domain::MAX_INDEX - 1.0) * 0.38 * 0.38;
        match self {
            Field::Coordinate | Field::Angle => -domain::MAX_COORDINATE..=domain::MAX_COORDINATE,
            Field::Length => domain::MIN_LENGTH..=domain::MAX_LENGTH,
            Field::Colour => 0.0..=domain::MAX_COLOUR,
            Field::Intensity => 0.0..=domain::MAX_INTENSITY,
            Field::Coefficient => 0.0..=domain::MAX_COEFFICIENT,
            Field::Fraction => 0.0..=1.0,
            Field::Exponent => 0.0..=f64::MAX,
            Field::Index => 1.0..=domain::MAX_INDEX,
            Field::Dispersion => -b..=b,
        }
    }

    /// A drag value over `x` kept in this field's range.
    pub fn drag(self, x: &mut f64) -> egui::DragValue<'_> {
        egui::DragValue::new(x).range(self.range())
    }
}

/// Three drag values in a row of kind `field`; true when one changed.
pub fn vec3(ui: &mut egui::Ui, v: &mut [f64; 3], speed: f64, field: Field) -> bool {
    ui.horizontal(|ui| {
        let mut changed = false;
        for (x, p) in v.iter_mut().zip(["x ", "y ", "z "]) {
            changed |= ui.add(field.drag(x).speed(speed).max_decimals(4).prefix(p)).changed();
        }
        changed
    })
    .inner
}

/// A positive size in the *Add* form.
pub fn positive(x: &mut f64) -> egui::DragValue<'_> {
    Field::Length.drag(x).speed(0.01).max_decimals(4)
}

/// One number of kind `field`; true when it changed.
pub fn number(ui: &mut egui::Ui, x: &mut f64, speed: f64, field: Field) -> bool {
    ui.add(field.drag(x).speed(speed).max_decimals(6)).changed()
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
            changed |= ui.add(Field::Colour.drag(x).speed(0.01).max_decimals(3)).changed();
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

/// The *orientation* (yaw and pitch, degrees) and *axis* rows of a grid
/// over one axis (a lens's or a system's): turning either writes the axis.
pub fn axis_rows(ui: &mut egui::Ui, axis: &mut [f64; 3], hover: Option<&str>) {
    ui.label("orientation");
    let (mut yaw, mut pitch) = axis_angles(*axis);
    let changed = ui
        .horizontal(|ui| {
            let a = ui.add(egui::DragValue::new(&mut yaw).speed(0.5).max_decimals(2).prefix("yaw "));
            let b = ui.add(
                egui::DragValue::new(&mut pitch)
                    .speed(0.5)
                    .range(-90.0..=90.0)
                    .max_decimals(2)
                    .prefix("pitch "),
            );
            a.changed() || b.changed()
        })
        .inner;
    if changed {
        *axis = axis_from_angles(yaw, pitch);
    }
    ui.end_row();
    let label = ui.label("axis");
    if let Some(h) = hover {
        label.on_hover_text(h);
    }
    vec3(ui, axis, 0.01, Field::Coordinate);
    ui.end_row();
}

/// A grid of read-only numbers (first-order data), each with `decimals`
/// digits after the point, `per_row` name–value pairs a row.
pub fn readout_grid(
    ui: &mut egui::Ui,
    id: impl std::hash::Hash + std::fmt::Debug,
    rows: &[(&str, f64)],
    decimals: usize,
    per_row: usize,
) {
    egui::Grid::new(id).num_columns(2 * per_row).show(ui, |ui| {
        for row in rows.chunks(per_row.max(1)) {
            for (k, v) in row {
                ui.label(*k);
                ui.monospace(format!("{v:.decimals$}"));
            }
            ui.end_row();
        }
    });
}

/// A refractive index: a constant, or Cauchy's A and B; a catalogue glass
/// (from the file) is shown by name and kept until another kind is chosen.
pub fn index(ui: &mut egui::Ui, n: &mut IndexFile) {
    ui.horizontal(|ui| {
        let cauchy = matches!(n, IndexFile::Cauchy(_));
        let constant = matches!(n, IndexFile::Constant(_));
        if let IndexFile::Glass(g) = n {
            let _ = ui.radio(true, format!("glass {}", g.name));
        }
        if ui.radio(constant, "n").clicked() {
            *n = index_with_dispersion(*n, false);
        }
        if ui.radio(cauchy, "Cauchy A + B/λ²").clicked() {
            *n = index_with_dispersion(*n, true);
        }
    });
    match n {
        IndexFile::Constant(v) => {
            ui.add(Field::Index.drag(v).speed(0.002).max_decimals(5).prefix("n "));
        }
        IndexFile::Cauchy([a, b]) => {
            ui.horizontal(|ui| {
                ui.add(Field::Index.drag(a).speed(0.002).max_decimals(5).prefix("A "));
                ui.add(Field::Dispersion.drag(b).speed(0.0002).max_decimals(6).prefix("B "))
                    .on_hover_text("µm²");
            });
        }
        IndexFile::Glass(g) => {
            ui.label(format!("nd {:.5}, Abbe number vd {:.2}", g.nd(), g.abbe()))
                .on_hover_text("Sellmeier dispersion from the glass catalogue");
        }
    }
}

/// [`index`], and a choice of a catalogue glass ([`lensview::glass`]);
/// `id` tells the choices of several apart.
pub fn index_or_glass(ui: &mut egui::Ui, id: impl std::hash::Hash + std::fmt::Debug, n: &mut IndexFile) {
    index(ui, n);
    glass_choice(ui, id, n);
}

/// A menu of the catalogue's glasses; choosing one makes `n` that glass.
pub fn glass_choice(ui: &mut egui::Ui, id: impl std::hash::Hash + std::fmt::Debug, n: &mut IndexFile) {
    let shown = match n {
        IndexFile::Glass(g) => g.name.to_string(),
        _ => "catalogue glass…".to_string(),
    };
    egui::ComboBox::from_id_salt(("glass", id))
        .selected_text(shown)
        .show_ui(ui, |ui| {
            for g in lensview::glass::CATALOGUE {
                let on = matches!(n, IndexFile::Glass(h) if h.name == g.name);
                let text = format!("{}  (nd {:.4}, vd {:.1})", g.name, g.nd(), g.abbe());
                if ui.selectable_label(on, text).clicked() {
                    *n = IndexFile::Glass(g);
                }
            }
        });
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

#[cfg(test)]
mod tests {
    use super::*;

    /// No panel field reaches outside the supported domain: both ends of
    /// every field's range pass the domain's own checks (the ones the
    /// scene validator makes), and a field that must be positive starts
    /// above zero.
    #[test]
    fn every_field_stays_inside_the_domain() {
        for f in Field::ALL {
            let r = f.range();
            let (lo, hi) = (*r.start(), *r.end());
            assert!(lo <= hi && lo.is_finite() && hi.is_finite(), "{f:?}");
            for x in [lo, hi] {
                let inside = match f {
                    Field::Coordinate | Field::Angle => domain::coordinate(x).is_none(),
                    Field::Length => domain::length(x, 0.0).is_none(),
                    Field::Colour => (0.0..=domain::MAX_COLOUR).contains(&x),
                    Field::Intensity => (0.0..=domain::MAX_INTENSITY).contains(&x),
                    Field::Coefficient => (0.0..=domain::MAX_COEFFICIENT).contains(&x),
                    Field::Fraction => (0.0..=1.0).contains(&x),
                    Field::Exponent => x >= 0.0,
                    Field::Index => domain::index(x).is_none(),
                    // Cauchy's n = A + B/λ² at A = 1 over the visible range.
                    Field::Dispersion => [0.38f64, 0.78]
                        .iter()
                        .all(|l| x.abs() / (l * l) <= domain::MAX_INDEX - 1.0 + 1e-12),
                };
                assert!(inside, "{f:?}: {x:e} is outside the supported domain");
            }
        }
    }
}
