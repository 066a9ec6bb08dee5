//! The *Objects* section: the list of primitives, lenses and lens
//! systems, the editor of
//! the selected primitive (its material below it, see `material.rs`),
//! and *Duplicate* / *Delete*.

use super::widgets::{Field, name, number, vec3};
use super::{Ctx, drafted, material};
use lensview::edit::Item;
use lensview::edit::document::system_kind_label;
use lensview::scene::file::{ObjectFile, ShapeKind};

pub fn section(ui: &mut egui::Ui, cx: &mut Ctx) {
    let items = cx.doc.items();
    let header = egui::CollapsingHeader::new(format!("Objects ({})", items.len()))
        .id_salt("objects")
        .default_open(true);
    super::section(ui, cx, header, "Objects", |ui, cx| {
        egui::ScrollArea::vertical()
            .id_salt("object-list")
            .max_height(150.0)
            .auto_shrink([false, true])
            .show(ui, |ui| list(ui, cx, &items));
        ui.separator();
        match cx.ui.selected {
            None => {
                ui.weak("Select an object to edit, duplicate or delete it.");
            }
            Some(Item::Object(i)) => object_editor(ui, cx, i),
            Some(Item::Lens(i)) => {
                ui.label(format!(
                    "{}: its shape and glass are under Lens.",
                    cx.doc.item_name(Item::Lens(i))
                ));
            }
            Some(Item::System(i)) => {
                ui.label(format!(
                    "{}: its pose, shape and glasses are under System; the lens keys move and reshape it.",
                    cx.doc.item_name(Item::System(i))
                ));
            }
        }
        if cx.ui.selected.is_some() {
            ui.horizontal(|ui| {
                if ui.button("Duplicate").on_hover_text("Ctrl+D").clicked() {
                    cx.duplicate_selected();
                }
                if ui.button("Delete").on_hover_text("Delete key").clicked() {
                    cx.delete_selected();
                }
            });
        }
    });
}

/// The items, one selectable line each; a lens also opens *Lens*, a
/// system *System*.
fn list(ui: &mut egui::Ui, cx: &mut Ctx, items: &[(Item, String)]) {
    for (item, name) in items {
        let kind = match item {
            Item::Object(i) => cx.doc.scene().objects.get(*i).map_or("", |o| o.kind.name()).to_string(),
            Item::Lens(_) => "lens".to_string(),
            Item::System(i) => cx
                .doc
                .scene()
                .systems
                .get(*i)
                .map_or_else(String::new, system_kind_label),
        };
        let sel = cx.ui.selected == Some(*item);
        let r = ui.selectable_label(sel, format!("{name}   ({kind})"));
        cx.ui.rect(ui, &format!("item {name}"), &r);
        if r.clicked() {
            cx.ui.selected = if sel { None } else { Some(*item) };
            match item {
                Item::Lens(i) => {
                    cx.ui.lens = *i;
                    cx.ui.open_lens();
                }
                Item::System(_) => cx.ui.open_system(),
                Item::Object(_) => {}
            }
        }
    }
}

fn object_editor(ui: &mut egui::Ui, cx: &mut Ctx, i: usize) {
    let Some(current) = cx.doc.scene().objects.get(i).cloned() else {
        return;
    };
    let materials: Vec<String> = cx.doc.scene().materials.keys().cloned().collect();
    let shown = drafted(
        ui,
        cx,
        &format!("objects[{i}]"),
        current,
        |ui, o| {
            egui::Grid::new(("object", i))
                .num_columns(2)
                .show(ui, |ui| object_rows(ui, o, i, &materials));
        },
        move |doc, v| doc.set_object(i, v),
    );
    material::editor(ui, cx, i, &shown);
}

/// The rows of one primitive: name, type, placement, sizes, material.
fn object_rows(ui: &mut egui::Ui, o: &mut ObjectFile, i: usize, materials: &[String]) {
    ui.label("name");
    name(ui, &mut o.name);
    ui.end_row();
    ui.label("type");
    ui.label(o.kind.name());
    ui.end_row();
    ui.label("position");
    vec3(ui, &mut o.position, 0.02, Field::Coordinate);
    ui.end_row();
    ui.label("rotation °");
    vec3(ui, &mut o.rotation, 0.5, Field::Angle);
    ui.end_row();
    size_rows(ui, o);
    ui.label("material");
    let text = o.material.clone().unwrap_or_else(|| "built-in grey".into());
    egui::ComboBox::from_id_salt(("material", i))
        .selected_text(text)
        .show_ui(ui, |ui| {
            ui.selectable_value(&mut o.material, None, "built-in grey");
            for m in materials {
                ui.selectable_value(&mut o.material, Some(m.clone()), m);
            }
        });
    ui.end_row();
}

/// The size rows of the primitive's kind (defaults shown when unset).
fn size_rows(ui: &mut egui::Ui, o: &mut ObjectFile) {
    match o.kind {
        ShapeKind::Cuboid => {
            ui.label("size");
            let mut s = o.size.unwrap_or([1.0; 3]);
            if vec3(ui, &mut s, 0.01, Field::Length) {
                o.size = Some(s);
            }
            ui.end_row();
        }
        ShapeKind::Sphere => {
            ui.label("radius");
            let mut r = o.radius.unwrap_or(0.5);
            if number(ui, &mut r, 0.01, Field::Length) {
                o.radius = Some(r);
            }
            ui.end_row();
        }
        ShapeKind::Prism | ShapeKind::Pyramid => {
            ui.label("base side");
            let mut s = o.side.unwrap_or(1.0);
            if number(ui, &mut s, 0.01, Field::Length) {
                o.side = Some(s);
            }
            ui.end_row();
            ui.label("height");
            let mut h = o.height.unwrap_or(1.0);
            if number(ui, &mut h, 0.01, Field::Length) {
                o.height = Some(h);
            }
            ui.end_row();
        }
    }
}
