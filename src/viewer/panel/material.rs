//! The material editor under a selected primitive: the fields of its
//! material (shared materials say by how many), or a button to give it one
//! of its own (`Document::give_own_material`).

use super::widgets::{Field, colour, index, number};
use super::{Ctx, drafted};
use lensview::scene::file::{MaterialFile, ObjectFile};

/// The editor of primitive `i`'s material, `o` being the primitive as shown.
pub fn editor(ui: &mut egui::Ui, cx: &mut Ctx, i: usize, o: &ObjectFile) {
    match o.material.clone() {
        Some(m) if cx.doc.scene().materials.contains_key(&m) => {
            let users = cx.doc.material_users(&m);
            let title = if users > 1 {
                format!("Material {m} (shared by {users} objects)")
            } else {
                format!("Material {m}")
            };
            egui::CollapsingHeader::new(title)
                .id_salt(("material-editor", i))
                .show(ui, |ui| {
                    fields(ui, cx, i, &m);
                    if users > 1 && ui.button("Give this object its own copy").clicked() {
                        own_material(cx, i);
                    }
                });
        }
        _ => {
            if ui.button("Give it a material of its own").clicked() {
                own_material(cx, i);
            }
        }
    }
}

fn own_material(cx: &mut Ctx, i: usize) {
    let r = cx.doc.give_own_material(i);
    cx.apply_result("the object has its own material now", r);
}

/// The fields of material `m` (of primitive `i`'s editor).
fn fields(ui: &mut egui::Ui, cx: &mut Ctx, i: usize, m: &str) {
    let current = cx.doc.scene().materials[m].clone();
    drafted(
        ui,
        cx,
        &format!("materials.{m}"),
        current,
        |ui, mat: &mut MaterialFile| {
            egui::Grid::new(("material-grid", i)).num_columns(2).show(ui, |ui| {
                ui.label("colour");
                colour(ui, &mut mat.color);
                ui.end_row();
                for (label, x, speed, field) in [
                    ("ambient", &mut mat.ambient, 0.01, Field::Coefficient),
                    ("diffuse", &mut mat.diffuse, 0.01, Field::Coefficient),
                    ("specular", &mut mat.specular, 0.01, Field::Coefficient),
                    ("shininess", &mut mat.shininess, 0.5, Field::Exponent),
                    ("reflectivity", &mut mat.reflectivity, 0.005, Field::Fraction),
                    ("transparency", &mut mat.transparency, 0.005, Field::Fraction),
                ] {
                    ui.label(label);
                    number(ui, x, speed, field);
                    ui.end_row();
                }
                ui.label("index (ior)");
                ui.vertical(|ui| index(ui, &mut mat.ior));
                ui.end_row();
            });
        },
        |doc, v| doc.set_material(m, v),
    );
}
