//! The *Lens* section: which lens, its fields (centre, orientation as yaw
//! and pitch or as an axis, d, r1, r2, index, tint), the paraxial readout
//! of the values as typed, and *Point at the camera* / *Put in front of the
//! camera*.

use super::widgets::{Field, axis_rows, colour, index, name, number, readout_grid, vec3};
use super::{Ctx, ERROR, drafted};
use lensview::edit::Item;
use lensview::optics::{Index, ThickLens};
use lensview::scene::file::{IndexFile, LensFile};

/// How far in front of the camera *Put in front of the camera* puts it.
const IN_FRONT: f64 = 3.5;

pub fn section(ui: &mut egui::Ui, cx: &mut Ctx) {
    let open = std::mem::take(&mut cx.ui.open_lens).then_some(true);
    let header = egui::CollapsingHeader::new("Lens").open(open);
    super::section(ui, cx, header, "Lens", |ui, cx| {
        let count = cx.doc.scene().lenses.len();
        super::analysis::toggles(ui, cx);
        if count == 0 {
            ui.weak("No lens in this scene: Add → lens puts one in front of the camera.");
            return;
        }
        cx.ui.lens = cx.ui.lens.min(count - 1);
        if count > 1 {
            chooser(ui, cx, count);
        }
        let i = cx.ui.lens;
        let current = cx.doc.scene().lenses[i].clone();
        let shown = drafted(
            ui,
            cx,
            &format!("lenses[{i}]"),
            current,
            |ui, l: &mut LensFile| {
                egui::Grid::new(("lens-grid", i))
                    .num_columns(2)
                    .show(ui, |ui| lens_rows(ui, l));
            },
            move |doc, v| doc.set_lens(i, v),
        );
        readout(ui, &shown, i);
        ui.horizontal(|ui| {
            if ui.button("Point at the camera").clicked()
                && let Some(r) = cx.doc.point_lens_at_camera(i)
            {
                cx.apply_result("the lens faces the camera", r);
            }
            if ui.button("Put in front of the camera").clicked() {
                let r = cx.doc.put_lens_in_front(i, IN_FRONT);
                cx.apply_result(&format!("the lens is {IN_FRONT} in front of the camera"), r);
            }
        });
    });
}

/// Which lens the section shows (when there are several).
fn chooser(ui: &mut egui::Ui, cx: &mut Ctx, count: usize) {
    let names: Vec<String> = (0..count).map(|i| cx.doc.item_name(Item::Lens(i))).collect();
    egui::ComboBox::from_id_salt("lens-choice")
        .selected_text(names[cx.ui.lens].clone())
        .show_ui(ui, |ui| {
            for (i, n) in names.iter().enumerate() {
                ui.selectable_value(&mut cx.session.ui.lens, i, n);
            }
        });
}

fn lens_rows(ui: &mut egui::Ui, l: &mut LensFile) {
    ui.label("name");
    name(ui, &mut l.name);
    ui.end_row();
    ui.label("centre");
    vec3(ui, &mut l.center, 0.01, Field::Coordinate);
    ui.end_row();
    axis_rows(ui, &mut l.axis, None);
    // One row for the three lengths: the section fits a 720-pixel window.
    ui.label("d, r1, r2")
        .on_hover_text("diameter; radius of S1 (faces +axis) and of S2 (faces −axis), each at least d/2");
    ui.horizontal(|ui| {
        for x in [&mut l.d, &mut l.r1, &mut l.r2] {
            number(ui, x, 0.01, Field::Length);
        }
    });
    ui.end_row();
    ui.label("index");
    ui.vertical(|ui| index(ui, &mut l.n));
    ui.end_row();
    ui.label("tint");
    colour(ui, &mut l.tint);
    ui.end_row();
}

/// Thickness, EFL, BFD and FFD of the lens as shown, or why it is impossible.
fn readout(ui: &mut egui::Ui, l: &LensFile, i: usize) {
    match paraxial(l) {
        Ok(p) => {
            let rows = [
                ("thickness", p.thickness),
                ("EFL", p.efl),
                ("BFD", p.bfd),
                ("FFD", p.ffd),
            ];
            readout_grid(ui, ("lens-readout", i), &rows, 6, 2);
            ui.weak(format!("paraxial, at n = {:.5} (d line)", p.n));
        }
        Err(why) => {
            ui.colored_label(ERROR, format!("Impossible lens: {why}."));
        }
    }
}

fn to_index(n: IndexFile) -> Index {
    match n {
        IndexFile::Constant(v) => Index::Constant(v),
        IndexFile::Cauchy([a, b]) => Index::Cauchy { a, b },
        IndexFile::Glass(g) => Index::Glass(g),
    }
}

/// The paraxial data of a lens as typed, or why there are none.
fn paraxial(l: &LensFile) -> Result<ThickLens, &'static str> {
    let n = to_index(l.n).nominal();
    // Written so that a NaN fails every test.
    if l.d.is_nan() || l.d <= 0.0 || l.d.is_infinite() {
        Err("d must be positive")
    } else if l.r1.is_nan() || l.r2.is_nan() || l.r1 < 0.5 * l.d || l.r2 < 0.5 * l.d {
        Err("r1 and r2 must be at least d/2")
    } else if n.is_nan() || n < 1.0 {
        Err("n must be at least 1")
    } else {
        Ok(ThickLens::new(l.d, l.r1, l.r2, n))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lensview::edit::document::new_lens;

    #[test]
    fn the_lens_readout_is_the_paraxial_data_or_says_why_not() {
        let mut l = new_lens([0.0; 3], [0.0, 0.0, 1.0]);
        let p = paraxial(&l).unwrap();
        assert!((p.efl - 5.03390182).abs() < 1e-7 && (p.thickness - 0.202041029).abs() < 1e-8);
        l.r1 = 0.5;
        assert_eq!(paraxial(&l).unwrap_err(), "r1 and r2 must be at least d/2");
        l.r1 = 5.0;
        l.n = IndexFile::Constant(0.9);
        assert!(paraxial(&l).is_err());
        l.n = IndexFile::Cauchy([1.5046, 0.0042]);
        assert!((paraxial(&l).unwrap().efl - 4.87131316).abs() < 1e-7);
        l.d = f64::NAN;
        assert!(paraxial(&l).is_err());
    }
}
