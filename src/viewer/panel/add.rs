//! The *Add* section: a form per kind of item (its sizes kept per kind),
//! where to put it, and the button. The new item itself is the library's
//! (`NewItem::of`, its sizes then set from the form) and added by
//! `Document::add_new`, as the page's *Add* menu does.

use super::Ctx;
use super::widgets::{Field, positive, vec3};
use lensview::edit::Placement;
use lensview::edit::document::{NEW_COLOUR, NEW_DISTANCE, NewItem};
use lensview::prescription::PRESETS;
use lensview::scene::SYSTEM_KINDS;
use lensview::scene::file::{IndexFile, ShapeKind, V3};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum AddKind {
    Cuboid,
    Prism,
    Sphere,
    Pyramid,
    Lens,
    System,
}

impl AddKind {
    const ALL: [AddKind; 6] = [
        AddKind::Cuboid,
        AddKind::Prism,
        AddKind::Sphere,
        AddKind::Pyramid,
        AddKind::Lens,
        AddKind::System,
    ];

    fn name(self) -> &'static str {
        match self {
            AddKind::Cuboid => "cuboid",
            AddKind::Prism => "prism",
            AddKind::Sphere => "sphere",
            AddKind::Pyramid => "pyramid",
            AddKind::Lens => "lens",
            AddKind::System => "system",
        }
    }
}

/// The *Add* form: parameters kept per kind.
pub struct AddForm {
    kind: AddKind,
    size: [f64; 3],
    radius: f64,
    prism: [f64; 2],
    pyramid: [f64; 2],
    /// d, r1, r2, n.
    lens: [f64; 4],
    /// The system's kind (one of `SYSTEM_KINDS`) and, for `preset`, which.
    system: &'static str,
    preset: &'static str,
    color: [f32; 3],
    in_front: bool,
    distance: f64,
    position: [f64; 3],
}

impl Default for AddForm {
    fn default() -> Self {
        AddForm {
            kind: AddKind::Sphere,
            size: [1.0; 3],
            radius: 0.5,
            prism: [1.0, 1.0],
            pyramid: [1.0, 1.0],
            lens: [2.0, 5.0, 5.0, 1.5],
            system: "biconvex",
            preset: PRESETS[0].0,
            color: NEW_COLOUR.map(|x| x as f32),
            in_front: true,
            distance: NEW_DISTANCE,
            position: [0.0, 0.5, 0.0],
        }
    }
}

impl AddForm {
    fn placement(&self) -> Placement {
        if self.in_front {
            Placement::InFrontOfCamera(self.distance)
        } else {
            Placement::At(self.position)
        }
    }

    /// The size rows of the form's kind.
    fn size_rows(&mut self, ui: &mut egui::Ui) {
        match self.kind {
            AddKind::Cuboid => {
                ui.label("size");
                ui.horizontal(|ui| {
                    for (x, p) in self.size.iter_mut().zip(["x ", "y ", "z "]) {
                        ui.add(positive(x).prefix(p));
                    }
                });
                ui.end_row();
            }
            AddKind::Sphere => {
                ui.label("radius");
                ui.add(positive(&mut self.radius));
                ui.end_row();
            }
            AddKind::Prism | AddKind::Pyramid => {
                let sh = if self.kind == AddKind::Prism {
                    &mut self.prism
                } else {
                    &mut self.pyramid
                };
                ui.label("base side");
                ui.add(positive(&mut sh[0]));
                ui.end_row();
                ui.label("height");
                ui.add(positive(&mut sh[1]));
                ui.end_row();
            }
            AddKind::Lens => {
                for (i, name) in ["d", "r1", "r2", "n"].iter().enumerate() {
                    ui.label(*name);
                    ui.add(positive(&mut self.lens[i]));
                    ui.end_row();
                }
            }
            AddKind::System => self.system_rows(ui),
        }
    }

    /// The system's kind and preset (sized 2 units across; edited under
    /// *System* once added).
    fn system_rows(&mut self, ui: &mut egui::Ui) {
        ui.label("kind");
        egui::ComboBox::from_id_salt("add-system-kind")
            .selected_text(self.system)
            .show_ui(ui, |ui| {
                for k in SYSTEM_KINDS {
                    ui.selectable_value(&mut self.system, *k, *k);
                }
            });
        ui.end_row();
        if self.system == "preset" {
            ui.label("preset");
            egui::ComboBox::from_id_salt("add-system-preset")
                .selected_text(self.preset)
                .show_ui(ui, |ui| {
                    for (p, _) in PRESETS {
                        ui.selectable_value(&mut self.preset, *p, *p);
                    }
                });
            ui.end_row();
        }
    }

    /// The colour and placement rows.
    fn where_rows(&mut self, ui: &mut egui::Ui) {
        if !matches!(self.kind, AddKind::Lens | AddKind::System) {
            ui.label("colour");
            ui.color_edit_button_rgb(&mut self.color);
            ui.end_row();
        }
        ui.label("where");
        ui.checkbox(&mut self.in_front, "in front of the camera");
        ui.end_row();
        if self.in_front {
            ui.label("distance");
            ui.add(positive(&mut self.distance));
            ui.end_row();
        } else {
            ui.label("position");
            vec3(ui, &mut self.position, 0.05, Field::Coordinate);
            ui.end_row();
        }
    }
}

pub fn section(ui: &mut egui::Ui, cx: &mut Ctx) {
    let header = egui::CollapsingHeader::new("Add").default_open(true);
    super::section(ui, cx, header, "Add", |ui, cx| {
        let f = &mut cx.session.ui.add;
        let kinds: Vec<(String, egui::Response)> = ui
            .horizontal_wrapped(|ui| {
                AddKind::ALL
                    .iter()
                    .map(|k| {
                        (
                            format!("kind {}", k.name()),
                            ui.selectable_value(&mut f.kind, *k, k.name()),
                        )
                    })
                    .collect()
            })
            .inner;
        egui::Grid::new("add-form").num_columns(2).show(ui, |ui| {
            f.size_rows(ui);
            f.where_rows(ui);
        });
        let label = format!("Add {}", f.kind.name());
        for (name, r) in &kinds {
            cx.session.ui.rect(ui, name, r);
        }
        let r = ui.button(&label);
        cx.ui.rect(ui, &label, &r);
        if r.clicked() {
            add_from_form(cx);
        }
    });
}

fn add_from_form(cx: &mut Ctx) {
    let s = &mut *cx.session;
    let f = &s.ui.add;
    let position: V3 = s.doc.place(f.placement());
    let what = if f.kind == AddKind::System {
        f.system
    } else {
        f.kind.name()
    };
    let Some(mut new) = NewItem::of(what, f.preset, position) else {
        return;
    };
    match &mut new {
        NewItem::Primitive(o, colour) => {
            match o.kind {
                ShapeKind::Cuboid => o.size = Some(f.size),
                ShapeKind::Sphere => o.radius = Some(f.radius),
                ShapeKind::Prism => (o.side, o.height) = (Some(f.prism[0]), Some(f.prism[1])),
                ShapeKind::Pyramid => (o.side, o.height) = (Some(f.pyramid[0]), Some(f.pyramid[1])),
            }
            *colour = f.color.map(|x| x as f64);
        }
        NewItem::Lens(l) => {
            (l.d, l.r1, l.r2, l.n) = (f.lens[0], f.lens[1], f.lens[2], IndexFile::Constant(f.lens[3]));
        }
        NewItem::System(_) => {}
    }
    let result = s.doc.add_new(new);
    match result {
        Ok(item) => {
            s.select(item);
            let p = position;
            s.message = format!(
                "added {} at ({:.2}, {:.2}, {:.2})",
                s.doc.item_name(item),
                p[0],
                p[1],
                p[2]
            );
            s.ui.error = None;
            s.changed(lensview::edit::Change::Picture);
        }
        Err(e) => {
            s.message = format!("not added: {e}");
            s.ui.error = Some(s.message.clone());
        }
    }
}
