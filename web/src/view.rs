//! The page's state without the browser: a scene document, the picture
//! being rendered step by step and its RGBA pixels, and the keys that fly
//! the camera and edit the lens. A new picture starts with the desktop
//! viewer's block previews ([`schedule`]'s block stages, drawn by
//! [`Progressive`]), then adds full samples band by band ([`Steps`]: the
//! finished picture is `render`'s). Plain Rust, tested natively below;
//! `lib.rs` only hands it to JavaScript.

use crate::panel::{self, Panel};
use glam::DVec3;
use lensview::camera::Camera;
use lensview::color::to_srgb8_toned;
use lensview::edit::document::{Document, Source, to_toml};
#[cfg(test)]
use lensview::edit::lens_key;
use lensview::edit::{Change, KeyState, scene_key};
use lensview::flight::look;
use lensview::integrator::Lit;
use lensview::photon::PhotonMap;
use lensview::render::RenderSettings;
use lensview::render::caustics::{CausticSettings, render_photons, still_map, still_thinning};
use lensview::render::first_frame::hole_level;
use lensview::render::progressive::{Progressive, Sampling, Stage, schedule};
use lensview::render::steps::Steps;
use lensview::render::thinning::photon_factor;
use lensview::scene::{SCENE_FILE_CAP, Scene, SceneError, escape_controls};
use std::sync::Arc;

/// Units a flight key moves the camera per press (the desktop viewer's
/// 3 units a second for a twelfth of a second); degrees a turn key turns.
pub const MOVE_STEP: f64 = 0.25;
pub const TURN_STEP: f64 = 5.0;

/// What the page shades `scene` with: the still's caustics, thinned.
fn lit_of<'a>(scene: &'a Scene, map: &'a Option<(PhotonMap, u32)>) -> Lit<'a> {
    let thin = map.as_ref().map_or(1, |m| m.1);
    Lit::new(scene, map.as_ref().map(|m| &m.0)).thinned(thin)
}

pub struct View {
    doc: Document,
    /// Picture size, seed; `spp`: 0 takes the scene's `render.spp`, as
    /// `lensview render` does without `--spp`.
    size: (u32, u32),
    spp: u32,
    seed: u64,
    /// The still's photon map and the thinning of its gathers
    /// (`still_map`).
    map: Option<(PhotonMap, u32)>,
    /// The block previews left to draw (the last first), and what draws
    /// them.
    previews: Vec<Stage>,
    progressive: Progressive,
    /// The block preview drawn last, until the first band of samples.
    shown: Option<Stage>,
    steps: Steps,
    /// The scene of the picture shown (its camera), for the next move to
    /// reproject it from.
    pictured: Arc<Scene>,
    rgba: Vec<u8>,
    /// What the last key did, for the page's message line.
    message: String,
    /// What the light's colour keys step from.
    keys: KeyState,
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
    /// The preset `scene` (a name or file name of `scenes/`, with or
    /// without `.toml`), or the
    /// embedded default scene when `None`.
    pub fn new(scene: Option<&str>, size: (u32, u32), spp: u32, seed: u64) -> Result<View, String> {
        let doc = match scene {
            // A preset's menu name, file name, or file name without
            // `.toml` (`?scene=focal-spot`).
            Some(name) => Document::preset(name)
                .or_else(|e| Document::preset(&format!("{name}.toml")).map_err(|_| e))
                .map_err(|e| error_line(&e))?,
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
        let pictured = doc.built().clone();
        let mut view = View {
            doc,
            size,
            spp,
            seed,
            map: None,
            previews: Vec::new(),
            progressive: Progressive::new(size.0, size.1, seed).with_sampling(Sampling::UNIFORM),
            shown: None,
            steps: Steps::new(settings),
            pictured,
            rgba: vec![0; size.0 as usize * size.1 as usize * 4],
            message: String::new(),
            keys: KeyState::default(),
        };
        view.restart(true);
        Ok(view)
    }

    /// Starts the picture over for the document's scene: the caustics'
    /// photons as `lensview render` traces them (`light`: when anything but
    /// the camera changed; the photon map does not depend on the camera),
    /// the block previews, then sample by sample.
    fn restart(&mut self, light: bool) {
        self.trace_photons(light);
        let spp = self.target_spp();
        self.previews = schedule(spp)
            .into_iter()
            .take_while(|s| matches!(s, Stage::Blocks(_)))
            .collect();
        self.previews.reverse();
        self.shown = None;
        self.progressive.reset(self.size.0, self.size.1, self.seed);
        self.new_samples();
    }

    /// The caustics' photons as `lensview render` traces them for the
    /// document's scene: traced again when anything but the camera
    /// changed (`light`), else kept, as long as the camera's thinning of
    /// the gathers (`still_thinning`) leaves the photons `render` traces
    /// the same (more where the gathers are thinned).
    fn trace_photons(&mut self, light: bool) {
        let (scene, spp) = (self.doc.built(), self.target_spp());
        let photons = CausticSettings {
            seed: self.seed,
            ..CausticSettings::default()
        };
        let thinning = |(map, _): &(PhotonMap, u32)| {
            let (passes, _) = render_photons(scene, self.size, spp, photons);
            still_thinning(scene, map, passes, self.size)
        };
        match self.map.as_ref().map(|m| (thinning(m), m.1)) {
            Some((now, was)) if !light && photon_factor(now) == photon_factor(was) => {
                if let Some(m) = &mut self.map {
                    m.1 = now;
                }
            }
            _ if light || self.map.is_some() => self.map = still_map(scene, self.size, spp, photons),
            _ => {}
        }
    }

    /// The samples a pixel gets: the page's, or (0) the scene's own.
    fn target_spp(&self) -> u32 {
        if self.spp == 0 { self.doc.built().spp } else { self.spp }
    }

    /// Full samples start over (the picture shown stays until their bands
    /// replace it).
    fn new_samples(&mut self) {
        self.steps = Steps::new(RenderSettings {
            width: self.size.0,
            height: self.size.1,
            spp: self.target_spp(),
            seed: self.seed,
        });
        self.pictured = self.doc.built().clone();
    }

    /// A camera move: the picture shown, moved into the new view as the
    /// desktop viewer moves it (`Progressive::reproject`: what was seen
    /// stays sharp, what was hidden or is seen through glass is traced at
    /// 2×2 blocks), then full samples from the start; the block previews
    /// again while nothing at full resolution is shown (or through a lens
    /// camera, whose pixels a warp cannot move).
    fn moved(&mut self) {
        if !self.reproject() {
            self.restart(false);
        }
    }

    fn reproject(&mut self) -> bool {
        let w = self.size.0 as usize;
        let steps = &self.steps;
        if w == 0 || !self.progressive.hold(|i| steps.pixel((i % w) as u32, (i / w) as u32)) {
            return false;
        }
        self.trace_photons(false);
        let scene = self.doc.built().clone();
        let lit = lit_of(&scene, &self.map);
        if !self
            .progressive
            .reproject(lit, &self.pictured, |holes| hole_level(holes, None))
        {
            return false;
        }
        self.progressive.write_rgba8(&mut self.rgba, scene.tone);
        self.previews.clear();
        self.shown = Some(Stage::Reprojected);
        self.new_samples();
        true
    }

    /// Draws the next block preview, or renders the next `bands` bands of
    /// the next sample (in parallel where the page has threads) into the
    /// RGBA pixels; `false` when the picture was already finished.
    pub fn step(&mut self, bands: usize) -> bool {
        let scene = self.doc.built();
        let lit = lit_of(scene, &self.map);
        if let Some(stage) = self.previews.pop() {
            self.progressive.run(lit, stage, &|| false);
            self.progressive.write_rgba8(&mut self.rgba, scene.tone);
            self.shown = Some(stage);
            return true;
        }
        let Some((y0, y1)) = self.steps.step_bands(&lit, bands) else {
            return false;
        };
        self.shown = None;
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

    /// What the picture shows now: a block preview, or full samples.
    pub fn stage(&self) -> String {
        match self.shown {
            Some(stage) => stage.label(),
            None => format!("{} spp", self.steps.samples_done()),
        }
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

    /// The scene as the document built it (the optics overlay's and the
    /// analysis's).
    pub fn scene(&self) -> &Scene {
        self.doc.built()
    }

    pub fn size(&self) -> (u32, u32) {
        self.size
    }

    /// A key (a DOM `KeyboardEvent.code`): a flight key ([`Self::fly`]) or
    /// a scene key of the desktop viewer (R, the lens, light and lens
    /// camera keys of `edit::scene_key`, applied by the document's
    /// `scene_key` as the desktop applies them). Returns whether it
    /// changed the scene (the picture starts over); [`Self::message`] says
    /// what it did.
    pub fn key(&mut self, code: &str) -> bool {
        let Some(key) = scene_key(code) else {
            return self.fly(code);
        };
        match self.doc.scene_key(key, &mut self.keys) {
            Ok((msg, change)) => {
                self.message = msg;
                self.changed(change)
            }
            Err(e) => {
                self.message = e.to_string();
                false
            }
        }
    }

    /// The panel with item `selected` (an id, see [`panel::Target`]).
    pub fn panel(&self, selected: &str) -> Panel {
        panel::panel(&self.doc, selected)
    }

    /// A panel edit: field `key` of item `id` set to `value` as typed
    /// ([`panel::set`]); whether the picture starts over. A refusal is one
    /// line, and the scene stays.
    pub fn set(&mut self, id: &str, key: &str, value: &str) -> Result<bool, String> {
        let (msg, change) = panel::set(&mut self.doc, id, key, value)?;
        self.message = msg;
        Ok(self.changed(change))
    }

    /// A panel button ([`panel::act`]: the *Add* menu's items, *Delete*,
    /// *Duplicate*, a material of its own) with item `id` selected;
    /// whether the picture starts over, and the item to select then. A
    /// refusal is one line, and the scene stays.
    pub fn act(&mut self, id: &str, action: &str) -> Result<(bool, String), String> {
        let (msg, selected, change) = panel::act(&mut self.doc, id, action)?;
        self.message = msg;
        Ok((self.changed(change), selected))
    }

    /// Undoes the newest edit (a panel field, a key, a flight); whether
    /// the picture starts over.
    pub fn undo(&mut self) -> bool {
        let step = self.doc.undo();
        self.stepped(step, "undone", "nothing to undo")
    }

    pub fn redo(&mut self) -> bool {
        let step = self.doc.redo();
        self.stepped(step, "redone", "nothing to redo")
    }

    fn stepped(&mut self, step: Option<(String, Change)>, done: &str, none: &str) -> bool {
        let Some((label, change)) = step else {
            self.message = none.into();
            return false;
        };
        self.message = format!("{done}: {label}");
        self.changed(change)
    }

    /// Starts the picture over for a change of the document: keeping the
    /// photon map when only the camera moved, not at all when the picture
    /// does not change (a name).
    fn changed(&mut self, change: Change) -> bool {
        match change {
            Change::None | Change::File => false,
            Change::Camera => {
                self.moved();
                true
            }
            _ => {
                self.restart(true);
                true
            }
        }
    }

    /// The line the last key left: what the edit did, or why not.
    pub fn message(&self) -> &str {
        &self.message
    }

    /// W/S forward and back, A/D left and right, Q/E down and up (the
    /// desktop's keys), the arrows turn; whether it moved the camera.
    fn fly(&mut self, code: &str) -> bool {
        let (mut pos, mut rot) = self.doc.camera_pose();
        let cam = Camera::new(pos, rot, 45.0);
        let (f, r) = (cam.forward(), cam.right());
        match code {
            "KeyW" => pos += f * MOVE_STEP,
            "KeyS" => pos -= f * MOVE_STEP,
            "KeyA" => pos -= r * MOVE_STEP,
            "KeyD" => pos += r * MOVE_STEP,
            "KeyE" => pos += DVec3::Y * MOVE_STEP,
            "KeyQ" => pos -= DVec3::Y * MOVE_STEP,
            "ArrowLeft" => rot.y += TURN_STEP,
            "ArrowRight" => rot.y -= TURN_STEP,
            "ArrowUp" => rot.x = (rot.x + TURN_STEP).min(89.0),
            "ArrowDown" => rot.x = (rot.x - TURN_STEP).max(-89.0),
            _ => return false,
        }
        if self.doc.fly_camera(pos, rot).is_err() {
            return false;
        }
        self.moved();
        true
    }

    /// Mouse-look (the pointer locked on the picture): the camera turned by
    /// a movement of (`dx`, `dy`) pixels as the desktop's drag turns it
    /// (`flight::look`); whether it turned.
    pub fn look(&mut self, dx: f64, dy: f64) -> bool {
        let (pos, rot) = look(self.doc.camera_pose(), dx, dy);
        if (pos, rot) == self.doc.camera_pose() || self.doc.fly_camera(pos, rot).is_err() {
            return false;
        }
        self.message = format!("camera pitch {:.1}°, yaw {:.1}°", rot.x, rot.y);
        self.moved();
        true
    }

    /// Ends the camera's flight gesture: the next flight or look is a new
    /// undo step.
    pub fn seal(&mut self) {
        self.doc.seal();
    }

    /// Opens scene file bytes (`name`: the file's name, for errors). A
    /// refusal is the one line `lensview render` prints for the same file,
    /// and the scene shown stays; so is a file over `Scene::load`'s cap
    /// ([`SCENE_FILE_CAP`]), refused before it is parsed.
    pub fn open(&mut self, name: &str, bytes: &[u8]) -> Result<(), String> {
        if bytes.len() as u64 > SCENE_FILE_CAP {
            let file = name.to_string();
            return Err(error_line(&SceneError::TooLarge {
                file,
                cap: SCENE_FILE_CAP,
            }));
        }
        let (sf, _) = Scene::from_bytes(name, bytes).map_err(|e| error_line(&e))?;
        self.doc = Document::new(sf, Source::File(name.into())).map_err(|e| rejected(&e))?;
        self.restart(true);
        Ok(())
    }

    /// The scene now (camera moves included) as a scene file.
    pub fn scene_toml(&self) -> Result<String, String> {
        to_toml(self.doc.scene())
    }
}

#[cfg(test)]
mod tests;
