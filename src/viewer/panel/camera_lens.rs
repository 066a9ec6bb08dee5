//! The *Camera* section's lens camera (issue #32): the pinhole/lens switch
//! (F9), and with the lens on, its focus distance (`;` / `'`) and f-number
//! (PgUp/PgDn) on sliders, each drag one undo step.

use super::Ctx;
use lensview::camera::nearest_focus;

pub fn controls(ui: &mut egui::Ui, cx: &mut Ctx) {
    let on = cx.doc.lens_camera_on();
    ui.horizontal(|ui| {
        ui.label("camera");
        let mut want = on;
        ui.radio_value(&mut want, false, "pinhole")
            .on_hover_text("F9: a pinhole (with a lens in the scene file, of its field of view)");
        ui.radio_value(&mut want, true, "lens")
            .on_hover_text("F9: a sensor behind the camera's lens system (a scene with none gets the double Gauss)");
        if want != on {
            cx.scene_key(lensview::edit::SceneKey::LensCamera);
        }
    });
    let Some(lens) = cx.doc.built().lens.clone() else {
        return;
    };
    let p = &lens.paraxial;
    let (near, far) = (nearest_focus(p) * 1.001, 1000.0 * p.efl);
    let mut infinite = !lens.focus_distance.is_finite();
    let mut d = lens.focus_distance.clamp(near, far);
    ui.horizontal(|ui| {
        ui.label("focus");
        let r = ui
            .add_enabled(
                !infinite,
                egui::Slider::new(&mut d, near..=far).logarithmic(true).max_decimals(3),
            )
            .on_hover_text("distance from the camera to the plane in focus (; nearer, ' farther)");
        if r.changed() {
            let res = cx.doc.set_focus_distance(Some(d));
            cx.apply_result(&format!("focus {d:.3}"), res);
        }
        if r.drag_stopped() || r.lost_focus() {
            cx.doc.seal();
        }
        if ui.checkbox(&mut infinite, "infinity").changed() {
            let res = cx.doc.set_focus_distance((!infinite).then_some(d));
            cx.doc.seal();
            cx.apply_result(if infinite { "focus at infinity" } else { "focus" }, res);
        }
    });
    let mut n = lens.f_number;
    ui.horizontal(|ui| {
        ui.label("f-number");
        let r = ui
            .add(
                egui::Slider::new(&mut n, lens.open_f_number..=64.0)
                    .logarithmic(true)
                    .max_decimals(2)
                    .prefix("f/"),
            )
            .on_hover_text("the aperture stop (PgUp opens a stop, PgDn stops down)");
        if r.changed() {
            let res = cx.doc.set_f_number(Some(n));
            cx.apply_result(&format!("f/{n:.2}"), res);
        }
        if r.drag_stopped() || r.lost_focus() {
            cx.doc.seal();
        }
    });
    if let Some(line) = crate::viewer::stats::focus_line(&cx.doc) {
        ui.weak(line);
    }
}
