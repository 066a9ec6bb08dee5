//! The page's state without the browser: a scene document, the picture
//! being rendered step by step ([`Steps`]) and its RGBA pixels, and the
//! keys that fly the camera. Plain Rust, tested natively below;
//! `lib.rs` only hands it to JavaScript.

use glam::DVec3;
use lensview::camera::Camera;
use lensview::color::to_srgb8_toned;
use lensview::edit::document::{Document, Source, to_toml};
use lensview::integrator::Lit;
use lensview::photon::PhotonMap;
use lensview::render::RenderSettings;
use lensview::render::caustics::{CausticSettings, caustic_map, render_photons};
use lensview::render::steps::Steps;
use lensview::scene::{Scene, escape_controls};

/// Units a flight key moves the camera per press (the desktop viewer's
/// 3 units a second for a twelfth of a second); degrees a turn key turns.
pub const MOVE_STEP: f64 = 0.25;
pub const TURN_STEP: f64 = 5.0;

pub struct View {
    doc: Document,
    /// Picture size, seed; `spp`: 0 takes the scene's `render.spp`, as
    /// `lensview render` does without `--spp`.
    size: (u32, u32),
    spp: u32,
    seed: u64,
    map: Option<PhotonMap>,
    steps: Steps,
    rgba: Vec<u8>,
}

/// A scene that parsed but failed validation as a document (not expected:
/// the same checks passed a moment before).
fn rejected(e: &lensview::edit::document::Rejected) -> String {
    let why = e.0.first().map_or("invalid scene", |p| p.message.as_str());
    format!("error: {}", escape_controls(why))
}

/// A refusal as `lensview render` prints it: one line, `error: ` first.
pub fn error_line(e: &impl std::fmt::Display) -> String {
    format!("error: {}", escape_controls(&e.to_string()))
}

impl View {
    /// The preset `scene` (a name or file name of `scenes/`), or the
    /// embedded default scene when `None`.
    pub fn new(scene: Option<&str>, size: (u32, u32), spp: u32, seed: u64) -> Result<View, String> {
        let doc = match scene {
            Some(name) => Document::preset(name).map_err(|e| error_line(&e))?,
            None => {
                let (sf, _) = Scene::default_scene();
                Document::new(sf, Source::Default).map_err(|e| rejected(&e))?
            }
        };
        let settings = RenderSettings {
            width: size.0,
            height: size.1,
            spp: 1,
            seed,
        };
        let mut view = View {
            doc,
            size,
            spp,
            seed,
            map: None,
            steps: Steps::new(settings),
            rgba: vec![0; size.0 as usize * size.1 as usize * 4],
        };
        view.restart();
        Ok(view)
    }

    /// Starts the picture over for the document's scene: the caustics'
    /// photons as `lensview render` traces them, then sample by sample.
    fn restart(&mut self) {
        let scene = self.doc.built();
        let spp = if self.spp == 0 { scene.spp } else { self.spp };
        let photons = CausticSettings {
            seed: self.seed,
            ..CausticSettings::default()
        };
        let (passes, _) = render_photons(scene, self.size, spp, photons);
        self.map = caustic_map(scene, passes, photons);
        self.steps = Steps::new(RenderSettings {
            width: self.size.0,
            height: self.size.1,
            spp,
            seed: self.seed,
        });
    }

    /// Renders the next band of the next sample into the RGBA pixels;
    /// `false` when the picture was already finished.
    pub fn step(&mut self) -> bool {
        let scene = self.doc.built();
        let lit = Lit::new(scene, self.map.as_ref());
        let Some((y0, y1)) = self.steps.step(&lit) else {
            return false;
        };
        let tone = scene.tone;
        let w = self.size.0;
        for y in y0..y1 {
            for x in 0..w {
                let Some(c) = self.steps.pixel(x, y) else { continue };
                let [r, g, b] = to_srgb8_toned(c, tone);
                let i = 4 * (y as usize * w as usize + x as usize);
                self.rgba[i..i + 4].copy_from_slice(&[r, g, b, 255]);
            }
        }
        true
    }

    pub fn done(&self) -> bool {
        self.steps.done()
    }

    /// Samples every pixel has; of how many.
    pub fn samples(&self) -> (u32, u32) {
        (self.steps.samples_done(), self.steps.settings().spp)
    }

    /// The picture as shown: 8-bit sRGB RGBA, row by row from the top.
    pub fn rgba(&self) -> &[u8] {
        &self.rgba
    }

    pub fn size(&self) -> (u32, u32) {
        self.size
    }

    /// A key (a DOM `KeyboardEvent.code`): W/S forward and back, A/D left
    /// and right, R/F up and down, the arrows turn. Returns whether it
    /// moved the camera (the picture starts over).
    pub fn key(&mut self, code: &str) -> bool {
        let (mut pos, mut rot) = self.doc.camera_pose();
        let cam = Camera::new(pos, rot, 45.0);
        let (f, r) = (cam.forward(), cam.right());
        match code {
            "KeyW" => pos += f * MOVE_STEP,
            "KeyS" => pos -= f * MOVE_STEP,
            "KeyA" => pos -= r * MOVE_STEP,
            "KeyD" => pos += r * MOVE_STEP,
            "KeyR" => pos += DVec3::Y * MOVE_STEP,
            "KeyF" => pos -= DVec3::Y * MOVE_STEP,
            "ArrowLeft" => rot.y += TURN_STEP,
            "ArrowRight" => rot.y -= TURN_STEP,
            "ArrowUp" => rot.x = (rot.x + TURN_STEP).min(89.0),
            "ArrowDown" => rot.x = (rot.x - TURN_STEP).max(-89.0),
            _ => return false,
        }
        if self.doc.fly_camera(pos, rot).is_err() {
            return false;
        }
        self.restart();
        true
    }

    /// Opens scene file bytes (`name`: the file's name, for errors). A
    /// refusal is the one line `lensview render` prints for the same file,
    /// and the scene shown stays.
    pub fn open(&mut self, name: &str, bytes: &[u8]) -> Result<(), String> {
        let (sf, _) = Scene::from_bytes(name, bytes).map_err(|e| error_line(&e))?;
        self.doc = Document::new(sf, Source::File(name.into())).map_err(|e| rejected(&e))?;
        self.restart();
        Ok(())
    }

    /// The scene now (camera moves included) as a scene file.
    pub fn scene_toml(&self) -> Result<String, String> {
        to_toml(self.doc.scene())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lensview::render::render;

    fn finish(v: &mut View) {
        while v.step() {}
        assert!(v.done());
    }

    /// The finished picture is `render`'s at the same size, spp and seed,
    /// converted as the PNG is.
    #[test]
    fn the_picture_is_renders() {
        let mut v = View::new(Some("cubes"), (24, 20), 2, 3).unwrap();
        finish(&mut v);
        assert_eq!(v.samples(), (2, 2));
        let (_, scene) = Scene::default_scene();
        let s = RenderSettings {
            width: 24,
            height: 20,
            spp: 2,
            seed: 3,
        };
        let photons = CausticSettings {
            seed: 3,
            ..CausticSettings::default()
        };
        let (passes, _) = render_photons(&scene, (24, 20), 2, photons);
        let map = caustic_map(&scene, passes, photons);
        let img = render(Lit::new(&scene, map.as_ref()), &s, None);
        let png: Vec<u8> = img.to_srgb8_toned(scene.tone);
        let rgb: Vec<u8> = v.rgba().chunks(4).flat_map(|p| [p[0], p[1], p[2]]).collect();
        assert_eq!(rgb, png);
    }

    #[test]
    fn w_moves_the_camera_and_restarts() {
        let mut v = View::new(None, (16, 12), 1, 0).unwrap();
        finish(&mut v);
        let before = v.rgba().to_vec();
        assert!(v.key("KeyW"));
        assert!(!v.done());
        finish(&mut v);
        assert_ne!(v.rgba(), &before[..]);
        assert!(!v.key("KeyQ"));
        assert!(v.scene_toml().unwrap().contains("[camera]"));
    }

    #[test]
    fn a_bad_file_is_refused_in_one_line_and_the_scene_stays() {
        let mut v = View::new(None, (16, 12), 1, 0).unwrap();
        let e = v.open("bad.toml", b"[camera]\nfov = \"wide\"\n").unwrap_err();
        assert!(e.starts_with("error: bad.toml"), "{e}");
        assert!(!e.contains('\n'));
        assert!(v.done() || v.step());
        assert!(View::new(Some("no such"), (4, 4), 1, 0).is_err());
    }
}
