//! The scene keys the desktop viewer and the web page share, named by
//! their `KeyboardEvent.code` (the names of winit's `KeyCode` too): the
//! lens keys ([`super::LENS_KEYS`]), the light keys and the lens camera's
//! keys, each applied to a [`Document`] as one undo step by
//! [`Document::scene_key`]. The step sizes are here once; the front ends
//! only map their key events to these codes.

use super::{Change, Document, Edit, LIGHT_PRESETS, Rejected, lens_key};
use glam::DVec3;

/// What a scene key does besides a plain [`Edit`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SceneKey {
    /// A key edit of the scene file.
    Edit(Edit),
    /// The first light's colour: the next of [`LIGHT_PRESETS`].
    LightPreset,
    /// The first light's colour temperature stepped by this many kelvin
    /// (within [`TEMPERATURE_RANGE`]).
    LightTemperature(f64),
    /// The view the scene opened with (`Document::reset_view`).
    ResetView,
    /// Pinhole ↔ lens camera (`Document::toggle_lens_camera`).
    LensCamera,
    /// The lens camera's focus distance times this factor.
    Focus(f64),
    /// The lens camera's f-number stepped by this many stops.
    FNumber(f64),
}

/// The colour temperatures the temperature keys stay within, in kelvin.
pub const TEMPERATURE_RANGE: (f64, f64) = (1000.0, 40000.0);

/// The reset, light and lens camera keys (the lens keys are
/// [`super::LENS_KEYS`]).
pub const SCENE_KEYS: &[(&str, SceneKey)] = &[
    ("KeyR", SceneKey::ResetView),
    ("KeyJ", SceneKey::Edit(Edit::LightMove(DVec3::new(-0.5, 0.0, 0.0)))),
    ("KeyL", SceneKey::Edit(Edit::LightMove(DVec3::new(0.5, 0.0, 0.0)))),
    ("KeyU", SceneKey::Edit(Edit::LightMove(DVec3::new(0.0, 0.5, 0.0)))),
    ("KeyO", SceneKey::Edit(Edit::LightMove(DVec3::new(0.0, -0.5, 0.0)))),
    ("KeyI", SceneKey::Edit(Edit::LightMove(DVec3::new(0.0, 0.0, -0.5)))),
    ("KeyK", SceneKey::Edit(Edit::LightMove(DVec3::new(0.0, 0.0, 0.5)))),
    ("BracketLeft", SceneKey::Edit(Edit::LightIntensity(0.8))),
    ("BracketRight", SceneKey::Edit(Edit::LightIntensity(1.25))),
    ("KeyT", SceneKey::LightPreset),
    ("Comma", SceneKey::LightTemperature(-500.0)),
    ("Period", SceneKey::LightTemperature(500.0)),
    ("F9", SceneKey::LensCamera),
    ("Semicolon", SceneKey::Focus(0.8)),
    ("Quote", SceneKey::Focus(1.25)),
    ("PageUp", SceneKey::FNumber(-1.0)),
    ("PageDown", SceneKey::FNumber(1.0)),
];

/// What scene key `code` does: a lens key's edit, or one of
/// [`SCENE_KEYS`]; `None` for any other key.
pub fn scene_key(code: &str) -> Option<SceneKey> {
    lens_key(code)
        .map(SceneKey::Edit)
        .or_else(|| SCENE_KEYS.iter().find(|k| k.0 == code).map(|k| k.1))
}

/// What the light's colour keys step from: the preset shown last and the
/// temperature (the desktop panel's colour controls share them).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KeyState {
    pub preset: usize,
    pub temperature: f64,
}

impl Default for KeyState {
    fn default() -> Self {
        KeyState {
            preset: 0,
            temperature: 6500.0,
        }
    }
}

impl KeyState {
    /// The edit of `key`, stepping the preset or the temperature it keeps;
    /// `None` for the view and lens camera keys (not key edits of the file).
    pub fn edit(&mut self, key: SceneKey) -> Option<Edit> {
        match key {
            SceneKey::Edit(e) => Some(e),
            SceneKey::LightPreset => {
                self.preset = (self.preset + 1) % LIGHT_PRESETS.len();
                Some(Edit::LightPreset(self.preset))
            }
            SceneKey::LightTemperature(dk) => {
                self.temperature = (self.temperature + dk).clamp(TEMPERATURE_RANGE.0, TEMPERATURE_RANGE.1);
                Some(Edit::LightTemperature(self.temperature))
            }
            SceneKey::ResetView | SceneKey::LensCamera | SceneKey::Focus(_) | SceneKey::FNumber(_) => None,
        }
    }
}

/// A scene key's outcome: what changed and the line saying so, or why
/// nothing did.
pub type KeyOutcome = Result<(String, Change), KeyRefused>;

/// Why a scene key changed nothing.
#[derive(Debug)]
pub enum KeyRefused {
    /// The document refused the result.
    Rejected(Rejected),
    /// A lens camera key without a lens camera.
    NoLensCamera,
}

impl std::fmt::Display for KeyRefused {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            KeyRefused::Rejected(r) => write!(f, "not applied: {r}"),
            KeyRefused::NoLensCamera => f.write_str("no lens camera: F9 switches to one"),
        }
    }
}

impl Document {
    /// Scene key `key` ([`scene_key`]) applied as one undo step, `state`
    /// stepped by the colour keys.
    pub fn scene_key(&mut self, key: SceneKey, state: &mut KeyState) -> KeyOutcome {
        let done = match (state.edit(key), key) {
            (Some(e), _) => Some(self.apply_edit(e)),
            (None, SceneKey::ResetView) => Some(self.reset_view().map(|c| ("view reset".to_string(), c))),
            (None, SceneKey::LensCamera) => Some(self.toggle_lens_camera()),
            (None, SceneKey::Focus(f)) => self.step_focus(f),
            (None, SceneKey::FNumber(stops)) => self.step_f_number(stops),
            (None, _) => None,
        };
        done.ok_or(KeyRefused::NoLensCamera)?.map_err(KeyRefused::Rejected)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every key the table names is found, lens keys included, and the
    /// colour keys step the state they keep.
    #[test]
    fn the_keys_are_found_and_the_colour_keys_step_their_state() {
        assert_eq!(scene_key("KeyZ"), lens_key("KeyZ").map(SceneKey::Edit));
        assert_eq!(scene_key("F9"), Some(SceneKey::LensCamera));
        assert_eq!(scene_key("KeyW"), None);
        for (code, key) in SCENE_KEYS {
            assert_eq!(scene_key(code), Some(*key), "{code}");
        }
        let mut s = KeyState::default();
        assert_eq!(s.edit(SceneKey::LightPreset), Some(Edit::LightPreset(1)));
        assert_eq!(
            s.edit(SceneKey::LightTemperature(-500.0)),
            Some(Edit::LightTemperature(6000.0))
        );
        for _ in 0..100 {
            s.edit(SceneKey::LightTemperature(-500.0));
        }
        assert_eq!(s.temperature, TEMPERATURE_RANGE.0);
        assert_eq!(s.edit(SceneKey::Focus(0.8)), None);
    }

    /// A light key is one undo step; the lens camera's keys need one
    /// (F9 switches to it, then focus works).
    #[test]
    fn light_and_camera_keys_edit_the_document() {
        let (sf, _) = crate::scene::Scene::default_scene();
        let mut d = Document::new(sf, crate::edit::Source::Default).unwrap();
        let mut s = KeyState::default();
        let before = d.scene().lights[0].clone();
        let (msg, change) = d.scene_key(scene_key("KeyL").unwrap(), &mut s).unwrap();
        assert!(msg.contains("light moved"), "{msg}");
        assert_ne!(change, Change::None);
        assert_ne!(d.scene().lights[0], before);
        assert!(d.undo().is_some());
        assert_eq!(d.scene().lights[0], before);
        let err = d.scene_key(SceneKey::Focus(0.8), &mut s).unwrap_err();
        assert_eq!(err.to_string(), "no lens camera: F9 switches to one");
        d.scene_key(SceneKey::LensCamera, &mut s).unwrap();
        assert!(d.scene().camera.lens.is_some());
        d.scene_key(SceneKey::Focus(0.8), &mut s).unwrap();
        // R brings back the view the scene opened with.
        let home = d.camera_pose();
        d.fly_camera(home.0 + DVec3::X, home.1).unwrap();
        let (msg, _) = d.scene_key(scene_key("KeyR").unwrap(), &mut s).unwrap();
        assert_eq!((msg.as_str(), d.camera_pose()), ("view reset", home));
    }
}
