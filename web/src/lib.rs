//! lensview in the browser: [`App`] hands the page's [`view::View`] to
//! JavaScript. `www/worker.js` holds it in a Web Worker, calls
//! [`App::step`] in slices and posts the pixels to `www/main.js`, which
//! draws them on a canvas and forwards keys and files. Threads: the
//! worker calls `initThreadPool` (wasm-bindgen-rayon) when the page is
//! cross-origin isolated, and rayon's loops of the library run on them;
//! otherwise rayon runs on the worker's own thread. The editing panel
//! (`www/panel.js`) shows [`App::panel`]'s rows and sends their values to
//! [`App::set`]; [`App::undo`] and [`App::redo`] step the document's
//! history (`panel.rs`).

pub mod optics;
pub mod panel;
pub mod view;

use wasm_bindgen::prelude::*;
#[cfg(feature = "threads")]
pub use wasm_bindgen_rayon::init_thread_pool;

#[wasm_bindgen]
pub struct App(view::View);

#[wasm_bindgen]
impl App {
    /// `scene`: a preset's name (`None`: the default scene); `spp` 0: the
    /// scene's own. Throws the one-line error for an unknown preset.
    #[wasm_bindgen(constructor)]
    pub fn new(scene: Option<String>, width: u32, height: u32, spp: u32, seed: u32) -> Result<App, JsValue> {
        view::View::new(scene.as_deref(), (width, height), spp, seed as u64)
            .map(App)
            .map_err(|e| JsValue::from_str(&e))
    }

    /// Draws the next block preview, or renders up to `bands` bands of
    /// the next sample (in parallel on the pool's threads); returns
    /// whether any work was done.
    pub fn step(&mut self, bands: u32) -> bool {
        self.0.step(bands as usize)
    }

    /// The threads rayon runs on (1 without a pool).
    pub fn threads() -> u32 {
        rayon::current_num_threads() as u32
    }

    /// The shipped scenes for the page's *Presets* menu, as JSON: `[[what
    /// ?scene= takes, the menu's name, what it shows], …]` (the desktop
    /// *Presets* menu's list).
    pub fn presets() -> String {
        let list: Vec<[&str; 3]> = lensview::edit::presets::PRESETS
            .iter()
            .map(|p| [p.file.trim_end_matches(".toml"), p.name, p.about])
            .collect();
        serde_json::to_string(&list).unwrap_or_default()
    }

    /// What the picture shows: "8×8 blocks", "3 spp".
    pub fn stage(&self) -> String {
        self.0.stage()
    }

    /// What the last key did.
    pub fn message(&self) -> String {
        self.0.message().into()
    }

    pub fn done(&self) -> bool {
        self.0.done()
    }

    #[wasm_bindgen(js_name = samplesDone)]
    pub fn samples_done(&self) -> u32 {
        self.0.samples().0
    }

    pub fn spp(&self) -> u32 {
        self.0.samples().1
    }

    pub fn width(&self) -> u32 {
        self.0.size().0
    }

    pub fn height(&self) -> u32 {
        self.0.size().1
    }

    /// The picture: RGBA bytes, row by row (a copy, for `ImageData`).
    pub fn rgba(&self) -> Vec<u8> {
        self.0.rgba().to_vec()
    }

    /// A `KeyboardEvent.code`; whether it changed the scene (the camera
    /// or the lens).
    pub fn key(&mut self, code: &str) -> bool {
        self.0.key(code)
    }

    /// Mouse-look by (`dx`, `dy`) pixels of pointer-locked movement, as the
    /// desktop's drag; whether the camera turned.
    pub fn look(&mut self, dx: f64, dy: f64) -> bool {
        self.0.look(dx, dy)
    }

    /// Ends a flight gesture (the pointer released): the next is a new
    /// undo step.
    pub fn seal(&mut self) {
        self.0.seal()
    }

    /// Opens a scene file's bytes; throws the CLI's one-line error.
    pub fn open(&mut self, name: &str, bytes: &[u8]) -> Result<(), JsValue> {
        self.0.open(name, bytes).map_err(|e| JsValue::from_str(&e))
    }

    #[wasm_bindgen(js_name = sceneToml)]
    pub fn scene_toml(&self) -> Result<String, JsValue> {
        self.0.scene_toml().map_err(|e| JsValue::from_str(&e))
    }

    /// The panel as JSON: the items, the fields of `selected` (an item id:
    /// `camera`, `light:0`, `lens:0`, …; another when it is gone), and the
    /// labels of Undo and Redo.
    pub fn panel(&self, selected: &str) -> String {
        serde_json::to_string(&self.0.panel(selected)).unwrap_or_default()
    }

    /// Sets field `key` of item `id` to the text `value`; whether the
    /// picture starts over. Throws the one-line error of a value the scene
    /// refuses (the scene stays).
    pub fn set(&mut self, id: &str, key: &str, value: &str) -> Result<bool, JsValue> {
        self.0.set(id, key, value).map_err(|e| JsValue::from_str(&e))
    }

    /// Does a panel button's `action` (the *Add* menu's `add:…`,
    /// `delete`, `duplicate`, `own-material`) with item `id` selected.
    /// Returns JSON: whether the picture starts over (`changed`) and the
    /// item to select now (`selected`). Throws the library's one-line
    /// refusal (the scene stays).
    pub fn act(&mut self, id: &str, action: &str) -> Result<String, JsValue> {
        let (changed, selected) = self.0.act(id, action).map_err(|e| JsValue::from_str(&e))?;
        Ok(serde_json::json!({ "changed": changed, "selected": selected }).to_string())
    }

    /// Undoes the newest edit; whether the picture starts over.
    pub fn undo(&mut self) -> bool {
        self.0.undo()
    }

    pub fn redo(&mut self) -> bool {
        self.0.redo()
    }
}

// The optics overlay (F6) and the analysis panel (F7): `optics.rs`; the
// page's `www/main.js` draws them (its optics block). Display only.
#[wasm_bindgen]
impl App {
    /// The overlay of the selected lens or system (`selected`: the panel's
    /// item id) as JSON segments and labels in picture pixels; the object
    /// `object_distance` before the first vertex (NaN: at infinity).
    pub fn optics(&self, selected: &str, object_distance: f64) -> String {
        let object = (!object_distance.is_nan()).then_some(object_distance);
        let o = optics::overlay(self.0.scene(), selected, self.0.size(), object);
        serde_json::to_string(&o).unwrap_or_default()
    }

    /// The analysis of the selected lens or system as HTML with SVG
    /// figures, `width` pixels wide (`object_distance` NaN: at infinity).
    pub fn analysis(
        &self,
        selected: &str,
        object_distance: f64,
        field_deg: f64,
        defocus: f64,
        rings: u32,
        width: f64,
    ) -> String {
        let settings = lensview::lens_tools::analysis::Settings {
            object_distance: (!object_distance.is_nan()).then_some(object_distance),
            field_deg,
            defocus,
            rings: rings.clamp(1, 16),
        };
        optics::analysis(self.0.scene(), selected, &settings, width)
    }
}
