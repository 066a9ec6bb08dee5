//! The key-binding tables: every key the viewer answers, the action it
//! triggers, and its help text. The help overlay is printed from these
//! tables. Plain keys are in [`BINDINGS`] (Shift only speeds up flight);
//! Ctrl chords, where Shift matters, in [`CTRL_BINDINGS`].

use winit::keyboard::KeyCode;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Action {
    // Held: camera flight.
    Forward,
    Back,
    Left,
    Right,
    Down,
    Up,
    LookLeft,
    LookRight,
    LookUp,
    LookDown,
    // Pressed: scene edits (restart refinement).
    /// A light or lens camera key: its code in the library's table
    /// (`edit::SCENE_KEYS`), which holds what it does.
    SceneKey(&'static str),
    /// A lens key: its code in the library's table (`edit::LENS_KEYS`),
    /// which holds the edit.
    LensKey(&'static str),
    ResetView,
    Reload,
    // Pressed: the lens camera (issue #32).
    ToggleLensCamera,
    // Pressed: editing (undo history, files, the panel); each restarts
    // refinement by itself when, and only when, the picture changes.
    Undo,
    Redo,
    Save,
    SaveAs,
    Open,
    TogglePanel,
    Pause,
    DeleteSelected,
    DuplicateSelected,
    // Pressed: display only (no restart).
    Exposure(f64),
    ToneNext,
    Screenshot,
    ScreenshotExr,
    ToggleRecording,
    ToggleOverlay,
    ToggleHelp,
    ToggleOptics,
    ToggleAnalysis,
    HalfResolution,
    ToggleCaustics,
    Quit,
}

impl Action {
    /// Held actions move the camera every frame while the key is down.
    pub fn is_held(self) -> bool {
        matches!(
            self,
            Action::Forward
                | Action::Back
                | Action::Left
                | Action::Right
                | Action::Down
                | Action::Up
                | Action::LookLeft
                | Action::LookRight
                | Action::LookUp
                | Action::LookDown
        )
    }

    /// Whether the action always changes the picture (and so restarts
    /// refinement). The editing actions decide by themselves.
    pub fn restarts(self) -> bool {
        !matches!(
            self,
            Action::Screenshot
                | Action::Exposure(_)
                | Action::ToneNext
                | Action::ScreenshotExr
                | Action::ToggleRecording
                | Action::ToggleOverlay
                | Action::ToggleHelp
                | Action::ToggleOptics
                | Action::ToggleAnalysis
                | Action::Quit
                | Action::Undo
                | Action::Redo
                | Action::Save
                | Action::SaveAs
                | Action::Open
                | Action::TogglePanel
                | Action::Pause
                | Action::ToggleCaustics
                | Action::ToggleLensCamera
                | Action::DeleteSelected
                | Action::DuplicateSelected
        )
    }
}

/// (key, label shown in help, action, help text)
pub const BINDINGS: &[(KeyCode, &str, Action, &str)] = &[
    (KeyCode::KeyW, "W", Action::Forward, "fly forward"),
    (KeyCode::KeyS, "S", Action::Back, "fly back"),
    (KeyCode::KeyA, "A", Action::Left, "fly left"),
    (KeyCode::KeyD, "D", Action::Right, "fly right"),
    (KeyCode::KeyQ, "Q", Action::Down, "fly down"),
    (KeyCode::KeyE, "E", Action::Up, "fly up"),
    (
        KeyCode::ArrowLeft,
        "Left",
        Action::LookLeft,
        "turn left (or drag with the mouse)",
    ),
    (KeyCode::ArrowRight, "Right", Action::LookRight, "turn right"),
    (KeyCode::ArrowUp, "Up", Action::LookUp, "look up"),
    (KeyCode::ArrowDown, "Down", Action::LookDown, "look down"),
    (KeyCode::KeyJ, "J/L", Action::SceneKey("KeyJ"), "light x -/+"),
    (KeyCode::KeyL, "", Action::SceneKey("KeyL"), ""),
    (KeyCode::KeyU, "U/O", Action::SceneKey("KeyU"), "light y +/-"),
    (KeyCode::KeyO, "", Action::SceneKey("KeyO"), ""),
    (KeyCode::KeyI, "I/K", Action::SceneKey("KeyI"), "light z -/+"),
    (KeyCode::KeyK, "", Action::SceneKey("KeyK"), ""),
    (
        KeyCode::BracketLeft,
        "[ / ]",
        Action::SceneKey("BracketLeft"),
        "light intensity -/+",
    ),
    (KeyCode::BracketRight, "", Action::SceneKey("BracketRight"), ""),
    (
        KeyCode::KeyT,
        "T",
        Action::SceneKey("KeyT"),
        "light colour: next preset",
    ),
    (
        KeyCode::Comma,
        ", / .",
        Action::SceneKey("Comma"),
        "light colour temperature -/+ 500 K",
    ),
    (KeyCode::Period, "", Action::SceneKey("Period"), ""),
    (
        KeyCode::KeyZ,
        "Z/X",
        Action::LensKey("KeyZ"),
        "lens (or selected system) along its axis -/+",
    ),
    (KeyCode::KeyX, "", Action::LensKey("KeyX"), ""),
    (KeyCode::KeyV, "V/B", Action::LensKey("KeyV"), "lens x -/+"),
    (KeyCode::KeyB, "", Action::LensKey("KeyB"), ""),
    (KeyCode::KeyN, "N/M", Action::LensKey("KeyN"), "lens y -/+"),
    (KeyCode::KeyM, "", Action::LensKey("KeyM"), ""),
    (KeyCode::Digit9, "9/0", Action::LensKey("Digit9"), "lens yaw -/+ 5 deg"),
    (KeyCode::Digit0, "", Action::LensKey("Digit0"), ""),
    (
        KeyCode::Minus,
        "- / =",
        Action::LensKey("Minus"),
        "lens pitch -/+ 5 deg",
    ),
    (KeyCode::Equal, "", Action::LensKey("Equal"), ""),
    (KeyCode::Digit1, "1/2", Action::LensKey("Digit1"), "lens diameter d -/+"),
    (KeyCode::Digit2, "", Action::LensKey("Digit2"), ""),
    (KeyCode::Digit3, "3/4", Action::LensKey("Digit3"), "lens r1 -/+"),
    (KeyCode::Digit4, "", Action::LensKey("Digit4"), ""),
    (KeyCode::Digit5, "5/6", Action::LensKey("Digit5"), "lens r2 -/+"),
    (KeyCode::Digit6, "", Action::LensKey("Digit6"), ""),
    (KeyCode::Digit7, "7/8", Action::LensKey("Digit7"), "lens index n -/+"),
    (KeyCode::Digit8, "", Action::LensKey("Digit8"), ""),
    (
        KeyCode::F9,
        "F9",
        Action::ToggleLensCamera,
        "camera: pinhole / lens (a scene with no lens gets the double Gauss)",
    ),
    (
        KeyCode::Semicolon,
        "; / '",
        Action::SceneKey("Semicolon"),
        "lens camera: focus nearer / farther (×0.8, ×1.25)",
    ),
    (KeyCode::Quote, "", Action::SceneKey("Quote"), ""),
    (
        KeyCode::PageUp,
        "PgUp/PgDn",
        Action::SceneKey("PageUp"),
        "lens camera: f-number -/+ one stop (open / stop down)",
    ),
    (KeyCode::PageDown, "", Action::SceneKey("PageDown"), ""),
    (KeyCode::KeyR, "R", Action::ResetView, "reset the view"),
    (
        KeyCode::F5,
        "F5",
        Action::Reload,
        "reload the scene file (keeps the camera)",
    ),
    (
        KeyCode::KeyG,
        "G/H",
        Action::Exposure(-0.5),
        "exposure -/+ half a stop (display and PNG; the samples are kept)",
    ),
    (KeyCode::KeyH, "", Action::Exposure(0.5), ""),
    (
        KeyCode::KeyY,
        "Y",
        Action::ToneNext,
        "tone curve: clamp / reinhard / aces",
    ),
    (
        KeyCode::KeyP,
        "P",
        Action::Screenshot,
        "save the picture on screen: PNG as shown and linear EXR, in the screenshot folder",
    ),
    (
        KeyCode::F1,
        "F1",
        Action::ToggleOverlay,
        "overlay: off / compact / full",
    ),
    (KeyCode::F2, "F2", Action::ToggleHelp, "this help on/off"),
    (KeyCode::F3, "F3", Action::HalfResolution, "half resolution on/off"),
    (KeyCode::F4, "F4", Action::TogglePanel, "editing panel on/off"),
    (
        KeyCode::F6,
        "F6",
        Action::ToggleOptics,
        "optics over the picture on/off (axis, F, F', H, H', ray fan)",
    ),
    (KeyCode::F7, "F7", Action::ToggleAnalysis, "lens analysis window on/off"),
    (
        KeyCode::F8,
        "F8",
        Action::ToggleRecording,
        "record a flight on/off (for lensview film)",
    ),
    (
        KeyCode::KeyC,
        "C",
        Action::ToggleCaustics,
        "caustics (photon mapping) on/off",
    ),
    (KeyCode::Space, "Space", Action::Pause, "pause/resume refinement"),
    (
        KeyCode::Delete,
        "Del",
        Action::DeleteSelected,
        "delete the object selected in the panel",
    ),
    (
        KeyCode::Escape,
        "Esc",
        Action::Quit,
        "close the open window or question; else quit (asks if there are unsaved changes, else wants a second Esc)",
    ),
];

/// Ctrl chords: (key, with Shift, label shown in help, action, help text).
pub const CTRL_BINDINGS: &[(KeyCode, bool, &str, Action, &str)] = &[
    (KeyCode::KeyZ, false, "Ctrl+Z", Action::Undo, "undo"),
    (KeyCode::KeyZ, true, "Ctrl+Shift+Z", Action::Redo, "redo (also Ctrl+Y)"),
    (KeyCode::KeyY, false, "", Action::Redo, ""),
    (KeyCode::KeyS, false, "Ctrl+S", Action::Save, "save the scene"),
    (
        KeyCode::KeyS,
        true,
        "Ctrl+Shift+S",
        Action::SaveAs,
        "save the scene as…",
    ),
    (KeyCode::KeyO, false, "Ctrl+O", Action::Open, "open a scene file"),
    (KeyCode::KeyP, false, "Ctrl+P", Action::ScreenshotExr, "the same as P"),
    (
        KeyCode::KeyD,
        false,
        "Ctrl+D",
        Action::DuplicateSelected,
        "duplicate the object selected in the panel",
    ),
];

/// The action of `key` with the modifiers held (Shift matters only with Ctrl).
pub fn action_for(key: KeyCode, ctrl: bool, shift: bool) -> Option<Action> {
    if ctrl {
        CTRL_BINDINGS.iter().find(|b| b.0 == key && b.1 == shift).map(|b| b.3)
    } else {
        BINDINGS.iter().find(|b| b.0 == key).map(|b| b.2)
    }
}

/// The label of the key bound to `action` (for menus): "Ctrl+S", "F4".
pub fn label_of(action: Action) -> &'static str {
    CTRL_BINDINGS
        .iter()
        .find(|b| b.3 == action && !b.2.is_empty())
        .map(|b| b.2)
        .or_else(|| BINDINGS.iter().find(|b| b.2 == action && !b.1.is_empty()).map(|b| b.1))
        .unwrap_or("")
}

/// The key help, (keys, what they do): one row per labelled binding, plus
/// the mouse and modifiers.
pub fn help_rows() -> Vec<(&'static str, &'static str)> {
    let mut v: Vec<_> = BINDINGS
        .iter()
        .filter(|b| !b.1.is_empty())
        .map(|b| (b.1, b.3))
        .collect();
    v.extend(CTRL_BINDINGS.iter().filter(|b| !b.2.is_empty()).map(|b| (b.2, b.4)));
    v.push(("Shift", "fly faster;  wheel: flight speed"));
    v.push(("Mouse", "drag with the left button to look around"));
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_key_is_bound_once_and_every_help_line_has_text() {
        for (i, a) in BINDINGS.iter().enumerate() {
            assert!(BINDINGS[i + 1..].iter().all(|b| b.0 != a.0), "{:?} bound twice", a.0);
            assert!(a.1.is_empty() == a.3.is_empty());
        }
        assert!(help_rows().len() > 20);
        for (i, a) in CTRL_BINDINGS.iter().enumerate() {
            assert!(
                CTRL_BINDINGS[i + 1..].iter().all(|b| (b.0, b.1) != (a.0, a.1)),
                "{:?} bound twice",
                a.0
            );
        }
        assert_eq!(action_for(KeyCode::KeyW, false, false), Some(Action::Forward));
        assert_eq!(action_for(KeyCode::KeyW, false, true), Some(Action::Forward));
        assert_eq!(action_for(KeyCode::KeyS, true, false), Some(Action::Save));
        assert_eq!(action_for(KeyCode::KeyZ, false, false), Some(Action::LensKey("KeyZ")));
        assert_eq!(action_for(KeyCode::KeyZ, true, false), Some(Action::Undo));
        assert_eq!(action_for(KeyCode::KeyZ, true, true), Some(Action::Redo));
        assert_eq!(action_for(KeyCode::KeyW, true, false), None);
        assert_eq!(label_of(Action::Redo), "Ctrl+Shift+Z");
        assert_eq!(label_of(Action::TogglePanel), "F4");
        assert!(help_rows().iter().any(|r| r.0 == "Ctrl+Z" && r.1 == "undo"));
        assert!(!Action::ToggleOverlay.restarts() && Action::LensKey("Digit2").restarts());
        assert_eq!(action_for(KeyCode::F9, false, false), Some(Action::ToggleLensCamera));
        assert!(!Action::ToggleLensCamera.restarts() && Action::SceneKey("PageDown").restarts());
    }

    /// Every lens key's row names its own key in the library's table, and
    /// every key of the table has its row.
    #[test]
    fn lens_keys_are_the_librarys() {
        let rows: Vec<_> = BINDINGS
            .iter()
            .filter_map(|b| match b.2 {
                Action::LensKey(code) => Some((format!("{:?}", b.0), code)),
                _ => None,
            })
            .collect();
        for (key, code) in &rows {
            assert_eq!(key, code);
            assert!(lensview::edit::lens_key(code).is_some(), "{code}");
        }
        assert_eq!(rows.len(), lensview::edit::LENS_KEYS.len());
    }
}
