//! lensview in the browser: [`App`] hands the page's [`view::View`] to
//! JavaScript (`www/main.js` draws its pixels on a canvas and feeds it keys
//! and files). One thread: the page calls [`App::step`] in small slices
//! between frames.

pub mod view;

use wasm_bindgen::prelude::*;

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

    /// Renders up to `bands` bands; returns whether any work was done.
    pub fn step(&mut self, bands: u32) -> bool {
        let mut any = false;
        for _ in 0..bands {
            if !self.0.step() {
                break;
            }
            any = true;
        }
        any
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

    /// A `KeyboardEvent.code`; whether it moved the camera.
    pub fn key(&mut self, code: &str) -> bool {
        self.0.key(code)
    }

    /// Opens a scene file's bytes; throws the CLI's one-line error.
    pub fn open(&mut self, name: &str, bytes: &[u8]) -> Result<(), JsValue> {
        self.0.open(name, bytes).map_err(|e| JsValue::from_str(&e))
    }

    #[wasm_bindgen(js_name = sceneToml)]
    pub fn scene_toml(&self) -> Result<String, JsValue> {
        self.0.scene_toml().map_err(|e| JsValue::from_str(&e))
    }
}
