//! The lens camera's edits (issue #32): the pinhole/lens switch, the focus
//! distance and the f-number, from the panel's sliders (merged while
//! dragged) and the keys (one step a press, clamped to what the lens can
//! do and saying so). Each is validated and undoable like any edit.

use super::{Change, Document, Rejected};
use crate::camera::{LensCamera, nearest_focus};
use crate::math::Ray;
use crate::scene::SceneFile;
use crate::scene::file::CameraLensFile;
use crate::trace::closest_hit_skip;

/// The lens a pinhole scene is given when switched to the lens camera:
/// the double Gauss 50 mm at a hundredth of its size (as
/// `scenes/camera-dgauss.toml`), at f/2.8.
pub const DEFAULT_CAMERA_LENS: (&str, f64, f64) = ("double-gauss-50mm", 0.01, 2.8);

/// Beyond this many focal lengths the focus keys go to infinity.
const FAR_FOCUS: f64 = 1000.0;

impl Document {
    /// The lens camera of the scene, switched on or not (`pinhole`).
    pub fn lens_camera(&self) -> Option<LensCamera> {
        crate::scene::lens_camera_of(&self.scene)
    }

    /// Whether the picture is the lens camera's.
    pub fn lens_camera_on(&self) -> bool {
        self.built.lens.is_some()
    }

    /// Switches between the pinhole and the lens camera. A scene with no
    /// `lens` gets [`DEFAULT_CAMERA_LENS`], focused on what the centre of
    /// the picture sees (at infinity when nothing). Returns what it did.
    pub fn toggle_lens_camera(&mut self) -> Result<(String, Change), Rejected> {
        if self.scene.camera.lens.is_none() {
            let focus = self.centre_distance();
            let (preset, scale, n) = DEFAULT_CAMERA_LENS;
            let change = self.edit("lens camera", |sf| {
                let c = &mut sf.camera;
                c.lens = Some(CameraLensFile {
                    preset: Some(preset.into()),
                    scale: Some(scale),
                    ..CameraLensFile::default()
                });
                (c.focus_distance, c.sensor_distance, c.f_number, c.pinhole) = (focus, None, Some(n), None);
            })?;
            return Ok((format!("lens camera: {preset} at f/{n}"), change));
        }
        let on = !self.lens_camera_on();
        let change = self.edit(if on { "lens camera" } else { "pinhole camera" }, |sf| {
            sf.camera.pinhole = (!on).then_some(true);
        })?;
        let what = if on {
            "lens camera".to_string()
        } else {
            "pinhole camera (the lens's field of view)".to_string()
        };
        Ok((what, change))
    }

    /// How far along the view's centre the first surface that is not a
    /// lens's or a lens system's lies (`None`: nothing): what the camera
    /// is pointed at, glass aside.
    pub fn centre_distance(&self) -> Option<f64> {
        let scene = &self.built;
        let cam = &scene.camera;
        let (mut ray, mut skip, mut t) = (Ray::new(cam.position, cam.forward()), usize::MAX, 0.0);
        for _ in 0..64 {
            let (o, hit) = closest_hit_skip(scene, &ray, f64::INFINITY, skip)?;
            t += hit.t;
            let glass = &scene.objects[o];
            if glass.lens().is_none() && glass.system().is_none() {
                return Some(t);
            }
            (ray, skip) = (Ray::new(ray.origin + ray.dir * hit.t, ray.dir), o);
        }
        None
    }

    /// The focus distance from the camera (`None`: infinity); a slider's
    /// drag is one undo step.
    pub fn set_focus_distance(&mut self, d: Option<f64>) -> Result<Change, Rejected> {
        self.edit_merged("camera.focus_distance", "focus", |sf| set_focus(sf, d))
    }

    /// The f-number (`None`: wide open); a slider's drag is one undo step.
    pub fn set_f_number(&mut self, n: Option<f64>) -> Result<Change, Rejected> {
        self.edit_merged("camera.f_number", "f-number", |sf| sf.camera.f_number = n)
    }

    /// The focus key: the distance in focus times `factor`, kept beyond
    /// the nearest the lens focuses on; from infinity, nearer starts at
    /// [`FAR_FOCUS`] focal lengths, and farther than that is infinity.
    /// `None` without a lens.
    pub fn step_focus(&mut self, factor: f64) -> Option<Result<(String, Change), Rejected>> {
        let lens = self.lens_camera()?;
        let far = FAR_FOCUS * lens.paraxial.efl;
        let near = nearest_focus(&lens.paraxial) * 1.001;
        let now = lens.focus_distance;
        let want = if now.is_finite() { now * factor } else { far };
        let (d, what) = if want > far && factor > 1.0 {
            (None, "focus at infinity".to_string())
        } else if want < near {
            (Some(near), format!("focus {near:.4}: the nearest the lens focuses on"))
        } else {
            (Some(want), format!("focus {want:.4}"))
        };
        let r = self.edit("focus", |sf| set_focus(sf, d));
        Some(r.map(|c| (what, c)))
    }

    /// The f-number key: `stops` stops slower (negative: faster), kept
    /// between wide open and f/64. `None` without a lens.
    pub fn step_f_number(&mut self, stops: f64) -> Option<Result<(String, Change), Rejected>> {
        let lens = self.lens_camera()?;
        let open = lens.open_f_number;
        let want = lens.f_number * libm::pow(2f64.sqrt(), stops);
        let (n, what) = if want <= open * (1.0 + 1e-9) {
            (None, format!("f/{open:.2}: wide open"))
        } else if want > 64.0 {
            (Some(64.0), "f/64: the slowest the keys go".to_string())
        } else {
            (Some(want), format!("f/{want:.2}"))
        };
        let r = self.edit("f-number", |sf| sf.camera.f_number = n);
        Some(r.map(|c| (what, c)))
    }
}

/// `[camera] focus_distance` set (the sensor's distance then follows).
fn set_focus(sf: &mut SceneFile, d: Option<f64>) {
    sf.camera.focus_distance = d;
    sf.camera.sensor_distance = None;
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// F9 on a pinhole scene adds the double Gauss focused on what the
    /// centre of the view meets; again, the pinhole of the lens's field of
    /// view; again, the lens; undo goes back step by step.
    #[test]
    fn the_switch_adds_a_lens_then_toggles_and_undoes() {
        let mut doc = Document::preset("cubes").unwrap();
        let original = doc.scene().clone();
        let (what, change) = doc.toggle_lens_camera().unwrap();
        assert_eq!(what, "lens camera: double-gauss-50mm at f/2.8");
        assert!(change.restarts());
        let lens = doc.built().lens.clone().expect("a lens camera");
        // cubes.toml looks through its lens at the middle cube, from
        // (0, 6, 10) along (0, −5.5, −10): its front face (z = 0.5).
        let top = 0.95 * 5.5f64.hypot(10.0);
        assert!((lens.focus_distance - top).abs() < 1e-4, "{}", lens.focus_distance);
        assert!((lens.f_number - 2.8).abs() < 1e-9);
        let fov = doc.built().camera.fov_y_deg;
        assert!((fov - lens.fov_y_deg()).abs() < 1e-12);

        let (what, _) = doc.toggle_lens_camera().unwrap();
        assert!(what.starts_with("pinhole camera"), "{what}");
        assert!(doc.built().lens.is_none() && !doc.lens_camera_on());
        assert_eq!(doc.scene().camera.pinhole, Some(true));
        assert_eq!(doc.built().camera.fov_y_deg, fov, "the same framing");
        assert!(doc.lens_camera().is_some(), "the lens is kept");
        doc.toggle_lens_camera().unwrap();
        assert!(doc.lens_camera_on());
        assert_eq!(doc.scene().camera.pinhole, None);
        for _ in 0..3 {
            doc.undo().unwrap();
        }
        assert_eq!(doc.scene(), &original);
    }

    /// The keys step the f-number by stops, to wide open and no further;
    /// the focus by a factor, to the nearest the lens focuses on.
    #[test]
    fn the_keys_step_and_clamp_focus_and_f_number() {
        let mut doc = Document::preset("lens camera").unwrap();
        let (what, _) = doc.step_f_number(1.0).unwrap().unwrap();
        let n = 2.8 * 2f64.sqrt();
        assert_eq!(what, format!("f/{n:.2}"));
        assert!((doc.built().lens.as_ref().unwrap().f_number - n).abs() < 1e-9);
        let (what, _) = doc.step_f_number(-3.0).unwrap().unwrap();
        assert!(what.ends_with("wide open"), "{what}");
        assert_eq!(doc.scene().camera.f_number, None);
        let lens = doc.built().lens.clone().unwrap();
        assert_eq!(lens.f_number, lens.open_f_number);
        let (what, _) = doc.step_focus(0.8).unwrap().unwrap();
        assert_eq!(what, format!("focus {:.4}", 11.4 * 0.8));
        for _ in 0..40 {
            doc.step_focus(0.8).unwrap().unwrap();
        }
        let near = nearest_focus(&lens.paraxial) * 1.001;
        assert_eq!(doc.scene().camera.focus_distance, Some(near));
        for _ in 0..60 {
            doc.step_focus(1.25).unwrap().unwrap();
        }
        assert_eq!(doc.scene().camera.focus_distance, None, "at infinity");
        assert!(Document::preset("cubes").unwrap().step_focus(0.8).is_none());
    }

    /// The pupil boxes are searched once for a lens, sensor and focus: a
    /// camera move or a cube's edit finds them again; a new f-number does
    /// not.
    #[test]
    fn pupil_boxes_outlive_moves_and_scene_edits() {
        let mut doc = Document::preset("lens camera").unwrap();
        let boxes = |doc: &Document| doc.built().lens.clone().unwrap().pupil_boxes().as_ptr();
        let first = boxes(&doc);
        doc.fly_camera(DVec3::new(1.0, 5.0, 9.0), DVec3::new(-20.0, 5.0, 0.0))
            .unwrap();
        assert_eq!(boxes(&doc), first, "searched again after a move");
        doc.edit("move a cube", |sf| sf.objects[1].position[0] += 0.5).unwrap();
        assert_eq!(boxes(&doc), first, "searched again after a cube's edit");
        doc.set_f_number(Some(5.6)).unwrap();
        assert_ne!(boxes(&doc), first, "an f-number's boxes are its own");
    }
}
