//! The *Camera* section: pose and field of view, the pinhole/lens switch
//! with the lens camera's focus and f-number, the flight speed, *Reset
//! the view* and *Look at the lens*.

use super::widgets::{Field, vec3};
use super::{Ctx, drafted};
use glam::DVec3;

pub fn section(ui: &mut egui::Ui, cx: &mut Ctx) {
    let header = egui::CollapsingHeader::new("Camera");
    super::section(ui, cx, header, "Camera", |ui, cx| {
        let (p, r) = cx.doc.camera_pose();
        let current = (p.to_array(), r.to_array(), cx.doc.scene().camera.fov);
        drafted(
            ui,
            cx,
            "camera",
            current,
            |ui, (pos, rot, fov)| {
                egui::Grid::new("camera-grid").num_columns(2).show(ui, |ui| {
                    ui.label("position");
                    vec3(ui, pos, 0.02, Field::Coordinate);
                    ui.end_row();
                    ui.label("rotation °");
                    vec3(ui, rot, 0.5, Field::Angle);
                    ui.end_row();
                    ui.label("field of view °");
                    ui.add(egui::DragValue::new(fov).speed(0.2).max_decimals(3));
                    ui.end_row();
                });
            },
            |doc, (pos, rot, fov)| doc.set_camera(DVec3::from(pos), DVec3::from(rot), fov),
        );
        super::camera_lens::controls(ui, cx);
        ui.horizontal(|ui| {
            ui.label("movement speed");
            ui.add(
                egui::DragValue::new(cx.speed)
                    .speed(0.05)
                    .range(0.05..=500.0)
                    .max_decimals(2),
            )
            .on_hover_text("units per second (mouse wheel over the picture; Shift flies 4× faster)");
        });
        ui.horizontal(|ui| {
            if ui.button("Reset the view").on_hover_text("R").clicked() {
                cx.reset_view();
            }
            let lens = cx.ui.lens;
            let has_lens = lens < cx.doc.scene().lenses.len();
            if ui
                .add_enabled(has_lens, egui::Button::new("Look at the lens"))
                .clicked()
                && let Some(r) = cx.doc.look_at_lens(lens)
            {
                cx.apply_result("looking at the lens", r);
            }
        });
    });
}
