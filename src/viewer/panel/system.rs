//! The *System* section: the lens system (`[[systems]]`) selected in
//! *Objects* — its kind, pose (centre or vertex, orientation, axis), tint,
//! the keys of its kind (d, radii, thicknesses, glasses, flat face; a
//! preset and its scale; a prescription's table and scale; or the table of
//! surfaces with insert, remove and move buttons), its first-order data
//! as built, and *As a table of surfaces*. Every change is a `Document`
//! edit; one that does not validate is kept as a draft with its reason.

use super::widgets::{Field, axis_rows, colour, glass_choice, index_or_glass, name, number, readout_grid, vec3};
use super::{Ctx, drafted};
use lensview::edit::Item;
use lensview::edit::document::system_kind_label;
use lensview::optics::WAVELENGTH_D_UM;
use lensview::prescription::PRESETS;
use lensview::scene::file::{IndexFile, SurfaceFile, SystemFile};

/// A change applied after the fields are shown: the table's rows, or the
/// placement (by the first vertex: `true`; by the centre: `false`).
#[derive(Clone, Copy)]
enum RowOp {
    Insert(usize),
    Remove(usize),
    Move(usize, bool),
    Place(bool),
}

pub fn section(ui: &mut egui::Ui, cx: &mut Ctx) {
    let count = cx.doc.scene().systems.len();
    let open = std::mem::take(&mut cx.session.ui.open_system).then_some(true);
    let header = egui::CollapsingHeader::new(format!("System ({count})")).open(open);
    super::section(ui, cx, header, "System", |ui, cx| {
        let Some(Item::System(i)) = cx.ui.selected else {
            ui.weak("Select a lens system in Objects to edit it; Add → system puts one in front of the camera.");
            return;
        };
        let Some(current) = cx.doc.scene().systems.get(i).cloned() else {
            return;
        };
        let mut op = None;
        drafted(
            ui,
            cx,
            &format!("systems[{i}]"),
            current,
            |ui, s: &mut SystemFile| {
                egui::Grid::new(("system-grid", i))
                    .num_columns(2)
                    .show(ui, |ui| pose_rows(ui, s, &mut op));
                kind_rows(ui, s, i, &mut op);
            },
            move |doc, v| doc.set_system(i, v),
        );
        if let Some(op) = op {
            let r = match op {
                RowOp::Insert(k) => cx.doc.insert_surface(i, k),
                RowOp::Remove(k) => cx.doc.remove_surface(i, k),
                RowOp::Move(k, up) => cx.doc.move_surface(i, k, up),
                RowOp::Place(by_vertex) => cx.doc.place_system(i, by_vertex),
            };
            let what = match op {
                RowOp::Place(true) => "placed by its first vertex",
                RowOp::Place(false) => "placed by its centre",
                _ => "the table of surfaces changed",
            };
            cx.apply_result(what, r);
        }
        readout(ui, cx, i);
        if cx.doc.scene().systems[i].kind != "surfaces" && ui.button("As a table of surfaces").clicked() {
            let r = cx.doc.system_to_surfaces(i);
            cx.apply_result("the system is now a table of surfaces (Ctrl+Z undoes)", r);
        }
    });
}

/// Name, kind, position (centre or first vertex, and a switch between
/// them), orientation, axis, tint.
fn pose_rows(ui: &mut egui::Ui, s: &mut SystemFile, op: &mut Option<RowOp>) {
    ui.label("name");
    name(ui, &mut s.name);
    ui.end_row();
    ui.label("kind");
    ui.label(system_kind_label(s));
    ui.end_row();
    ui.label("placed by")
        .on_hover_text("which point the position gives; switching keeps the system where it is");
    let by_vertex = s.vertex.is_some();
    let mut want = by_vertex;
    ui.horizontal(|ui| {
        ui.radio_value(&mut want, false, "centre");
        ui.radio_value(&mut want, true, "vertex");
    });
    if want != by_vertex {
        *op = Some(RowOp::Place(want));
    }
    ui.end_row();
    let (key, hover) = if s.center.is_some() {
        ("centre", "the middle of the axial length")
    } else {
        ("vertex", "the first surface's vertex")
    };
    if let Some(p) = s.center.as_mut().or(s.vertex.as_mut()) {
        ui.label(key).on_hover_text(hover);
        vec3(ui, p, 0.01, Field::Coordinate);
        ui.end_row();
    }
    axis_rows(ui, &mut s.axis, Some("the direction the first surface faces"));
    ui.label("tint");
    colour(ui, &mut s.tint);
    ui.end_row();
}

/// The keys of the system's kind.
fn kind_rows(ui: &mut egui::Ui, s: &mut SystemFile, i: usize, op: &mut Option<RowOp>) {
    match s.kind.as_str() {
        "surfaces" => table(ui, s.surfaces.get_or_insert_with(Vec::new), i, op),
        "preset" => {
            egui::Grid::new(("system-preset", i)).num_columns(2).show(ui, |ui| {
                ui.label("preset");
                let shown = s.preset.clone().unwrap_or_default();
                egui::ComboBox::from_id_salt(("preset", i))
                    .selected_text(shown)
                    .show_ui(ui, |ui| {
                        for (p, _) in PRESETS {
                            ui.selectable_value(&mut s.preset, Some(p.to_string()), *p);
                        }
                    });
                ui.end_row();
                scale_row(ui, s);
            });
        }
        "prescription" => {
            egui::Grid::new(("system-prescription", i))
                .num_columns(2)
                .show(ui, |ui| scale_row(ui, s));
            ui.label("prescription (radius, thickness, n, aperture diameter per line)");
            let text = s.prescription.get_or_insert_with(String::new);
            ui.add(egui::TextEdit::multiline(text).code_editor().desired_rows(6));
        }
        _ => {
            egui::Grid::new(("system-shorthand", i))
                .num_columns(2)
                .show(ui, |ui| shorthand_rows(ui, s, i));
        }
    }
}

fn scale_row(ui: &mut egui::Ui, s: &mut SystemFile) {
    ui.label("scale")
        .on_hover_text("the table's lengths (mm) are multiplied by it");
    let mut v = s.scale.unwrap_or(1.0);
    if ui
        .add(Field::Length.drag(&mut v).speed(0.0005).max_decimals(6))
        .changed()
    {
        s.scale = Some(v);
    }
    ui.end_row();
}

/// d, radii, thicknesses, glasses and the flat face of a shorthand kind
/// (the keys it has set).
fn shorthand_rows(ui: &mut egui::Ui, s: &mut SystemFile, i: usize) {
    let hover = |k: &str| match k {
        "d" => "diameter",
        "r" => "radius of the curved face (its magnitude)",
        "r1" => "radius of the front face (facing +axis)",
        "r2" => "radius of the back face (a doublet's cemented face)",
        "r3" => "radius of a doublet's back face",
        "thickness" => "centre thickness",
        _ => "centre thickness of a doublet's second element",
    };
    for (k, v) in [
        ("d", &mut s.d),
        ("r", &mut s.r),
        ("r1", &mut s.r1),
        ("r2", &mut s.r2),
        ("r3", &mut s.r3),
        ("thickness", &mut s.thickness),
        ("thickness2", &mut s.thickness2),
    ] {
        if let Some(x) = v {
            ui.label(k).on_hover_text(hover(k));
            // Signed radii (meniscus, doublet) may be negative.
            let field = if k.starts_with('r') {
                Field::Coordinate
            } else {
                Field::Length
            };
            number(ui, x, 0.01, field);
            ui.end_row();
        }
    }
    for (k, n) in [("n", &mut s.n), ("n2", &mut s.n2)] {
        if let Some(n) = n {
            ui.label(k)
                .on_hover_text("the glass: an index, Cauchy's A and B, or a catalogue glass");
            ui.vertical(|ui| index_or_glass(ui, (i, k), n));
            ui.end_row();
        }
    }
    if s.kind.starts_with("plano") {
        ui.label("flat face");
        let was_front = s.flat.as_deref() == Some("front");
        let mut front = was_front;
        ui.horizontal(|ui| {
            ui.radio_value(&mut front, false, "back");
            ui.radio_value(&mut front, true, "front");
        });
        if front != was_front {
            s.flat = front.then(|| "front".to_string());
        }
        ui.end_row();
    }
}

/// The table of surfaces: per surface its radius, thickness, semi-aperture,
/// medium after it and stop flag, and buttons to move, insert after and
/// remove it.
fn table(ui: &mut egui::Ui, list: &mut [SurfaceFile], i: usize, op: &mut Option<RowOp>) {
    let last = list.len().saturating_sub(1);
    for (k, f) in list.iter_mut().enumerate() {
        ui.separator();
        ui.horizontal(|ui| {
            ui.strong(format!("surface {}", k + 1));
            if ui.small_button("↑").on_hover_text("move up").clicked() && k > 0 {
                *op = Some(RowOp::Move(k, true));
            }
            if ui.small_button("↓").on_hover_text("move down").clicked() && k < last {
                *op = Some(RowOp::Move(k, false));
            }
            if ui.small_button("+").on_hover_text("insert a plane after it").clicked() {
                *op = Some(RowOp::Insert(k));
            }
            if ui.small_button("×").on_hover_text("remove it").clicked() {
                *op = Some(RowOp::Remove(k));
            }
            ui.checkbox(&mut f.stop, "stop");
        });
        ui.horizontal(|ui| {
            ui.add(
                Field::Coordinate
                    .drag(&mut f.radius)
                    .speed(0.01)
                    .max_decimals(5)
                    .prefix("R "),
            )
            .on_hover_text("signed radius, 0 for a plane");
            ui.add(
                Field::Coordinate
                    .drag(&mut f.thickness)
                    .speed(0.005)
                    .max_decimals(5)
                    .prefix("t "),
            )
            .on_hover_text("to the next surface");
            ui.add(
                Field::Length
                    .drag(&mut f.semi_aperture)
                    .speed(0.005)
                    .max_decimals(5)
                    .prefix("a "),
            )
            .on_hover_text("clear semi-aperture");
        });
        ui.horizontal(|ui| {
            ui.label("n after");
            surface_index(ui, (i, k), &mut f.n);
        });
    }
}

/// A compact index for a table row: a number (Cauchy's A), or a glass.
fn surface_index(ui: &mut egui::Ui, id: (usize, usize), n: &mut IndexFile) {
    match n {
        IndexFile::Constant(v) => {
            ui.add(Field::Index.drag(v).speed(0.002).max_decimals(5));
        }
        IndexFile::Cauchy([a, _]) => {
            ui.add(Field::Index.drag(a).speed(0.002).max_decimals(5).prefix("A "));
        }
        IndexFile::Glass(_) => {
            if ui
                .small_button("number")
                .on_hover_text("use its nd as a number")
                .clicked()
                && let IndexFile::Glass(g) = n
            {
                *n = IndexFile::Constant((g.nd() * 1e5).round() / 1e5);
            }
        }
    }
    glass_choice(ui, id, n);
}

/// The system as built: surfaces, length, diameter and first-order data.
fn readout(ui: &mut egui::Ui, cx: &Ctx, i: usize) {
    let Some(sys) = cx.doc.built_system(i) else {
        return;
    };
    let p = sys.paraxial(WAVELENGTH_D_UM);
    let rows = [
        ("surfaces", sys.len() as f64),
        ("length", sys.length()),
        ("diameter", 2.0 * sys.radius()),
        ("EFL", p.efl),
        ("BFD", p.bfd),
        ("f-number", p.f_number),
    ];
    readout_grid(ui, ("system-readout", i), &rows, 5, 2);
    ui.weak("paraxial, d line; lens keys move and reshape the selected system");
}
