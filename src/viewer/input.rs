//! Keys and mouse: which key events count (not those typed into a field,
//! not auto-repeated toggles), what a pressed key does (flight, a key edit
//! of the document, a session command, a display switch), and mouse-look
//! and the flight-speed wheel.

use super::Viewer;
use super::keys::{self, Action};
use super::panel::{Answer, DialogMode};
use super::session::Command;
use lensview::edit::{Edit, SceneKey};
use winit::event::{ElementState, KeyEvent, MouseButton, MouseScrollDelta};
use winit::keyboard::{KeyCode, PhysicalKey};

/// How far (window pixels) the cursor may move between a press and its
/// release for the two to be a click rather than a mouse-look drag.
const CLICK_SLOP: f64 = 4.0;

impl Viewer {
    pub(super) fn keyboard_input(&mut self, event: &KeyEvent, is_synthetic: bool, consumed: bool) {
        // winit fakes presses for keys held when focus arrives.
        if is_synthetic {
            return;
        }
        let PhysicalKey::Code(code) = event.physical_key else {
            return;
        };
        let (ctrl, shift) = (self.modifiers.control_key(), self.modifiers.shift_key());
        // Keys typed into a field are the field's (Ctrl+Z there is the
        // field's own undo); releases always stop flight. Save and open,
        // which no field uses, work while typing too.
        let typing = self.screen.as_ref().is_some_and(|s| s.gui.typing());
        let file_chord = ctrl
            && matches!(
                keys::action_for(code, true, shift),
                Some(Action::Save | Action::SaveAs | Action::Open)
            );
        if consumed && typing && event.state == ElementState::Pressed && !file_chord {
            return;
        }
        // Auto-repeat steps scene edits and undo/redo, never toggles.
        let repeats = keys::action_for(code, ctrl, shift).is_some_and(|a| {
            !a.is_held() && (a.restarts() || matches!(a, Action::Undo | Action::Redo | Action::Exposure(_)))
        });
        if event.repeat && !repeats {
            return;
        }
        self.key_event(code, event.state);
    }

    fn key_event(&mut self, code: KeyCode, state: ElementState) {
        let (ctrl, shift) = (self.modifiers.control_key(), self.modifiers.shift_key());
        // While the unsaved-changes question is up, keys answer it.
        if self.session.ui.confirm.is_some() {
            if state == ElementState::Pressed {
                match code {
                    KeyCode::KeyS | KeyCode::Enter if !ctrl => self.session.answer(Answer::Save),
                    KeyCode::KeyD | KeyCode::KeyN => self.session.answer(Answer::Discard),
                    KeyCode::Escape => self.session.answer(Answer::Cancel),
                    _ => {}
                }
                self.settle();
            }
            self.flight.release_keys();
            return;
        }
        let Some(action) = keys::action_for(code, ctrl, shift) else {
            // A flight key released while Ctrl is down still stops flying.
            if state == ElementState::Released {
                self.flight.key(code, false);
            }
            return;
        };
        match state {
            ElementState::Pressed if action.is_held() => self.flight.key(code, true),
            ElementState::Released if action.is_held() => self.flight.key(code, false),
            ElementState::Pressed => self.press(action),
            ElementState::Released => {}
        }
    }

    /// A pressed key's action (all but flight).
    fn press(&mut self, a: Action) {
        match self.key_edit(a) {
            // The key edits clamp to valid values; they still pass through
            // the document's validation and undo history like any edit.
            Some(e) => self.session.apply_edit(e),
            None => self.command_key(a),
        }
        self.session.redraw();
        self.settle();
    }

    /// The document edit of a lens key.
    fn key_edit(&mut self, a: Action) -> Option<Edit> {
        match a {
            Action::LensKey(code) => lensview::edit::lens_key(code),
            _ => None,
        }
    }

    /// The keys of session commands and display switches.
    fn command_key(&mut self, a: Action) {
        let s = &mut self.session;
        match a {
            Action::ResetView => s.reset_view(),
            Action::Reload => s.reload(),
            Action::HalfResolution => s.ask(Command::Resolution(if self.display.res_div == 1 { 2 } else { 1 })),
            Action::Screenshot | Action::ScreenshotExr => s.ask(Command::Screenshot),
            Action::ToggleRecording => s.ask(Command::ToggleRecording),
            Action::ToggleOverlay => self.display.overlay = self.display.overlay.next(),
            Action::ToggleHelp => self.display.help = !self.display.help,
            Action::ToggleOptics => s.ui.analysis.optics ^= true,
            Action::ToggleAnalysis => s.ui.analysis.window ^= true,
            Action::Undo => s.undo(),
            Action::Redo => s.redo(),
            Action::Save => {
                s.save();
            }
            Action::SaveAs => s.ui.open_file_dialog(DialogMode::SaveAs, s.doc.source()),
            Action::Open => s.ui.open_file_dialog(DialogMode::Open, s.doc.source()),
            Action::TogglePanel => s.ask(Command::ShowPanel(!self.display.panel)),
            Action::Pause => s.ask(Command::TogglePause),
            Action::ToggleCaustics => s.toggle_caustics(),
            Action::ToggleLensCamera => s.scene_key(SceneKey::LensCamera),
            Action::SceneKey(code) => {
                if let Some(k) = lensview::edit::scene_key(code) {
                    s.scene_key(k);
                }
            }
            Action::Exposure(d) => {
                let stops = s.doc.scene().display.exposure + d;
                let r = s.doc.set_exposure(stops);
                s.doc.seal();
                let what = format!("exposure {:+.1} stops", s.doc.scene().display.exposure);
                s.apply_result(&what, r);
            }
            Action::ToneNext => {
                let curve = s.doc.scene().display.tone.next();
                let r = s.doc.set_tone(curve);
                s.apply_result(&format!("tone curve {}", curve.name()), r);
            }
            Action::DeleteSelected => s.delete_selected(),
            Action::DuplicateSelected => s.duplicate_selected(),
            // An open menu closes first (egui does it), then the help
            // window, as the panel's windows do.
            Action::Quit if self.screen.as_ref().is_some_and(|s| s.gui.menu_open()) => {}
            Action::Quit if self.display.help => self.display.help = false,
            Action::Quit => s.request_quit(),
            _ => {}
        }
    }

    /// The left button: pressed over the picture (not the panel) starts
    /// mouse-look; released ends it.
    pub(super) fn mouse_button(&mut self, state: ElementState, button: MouseButton, consumed: bool) {
        if button != MouseButton::Left {
            return;
        }
        if state == ElementState::Released {
            self.flight.end_drag();
            if self.grab.take().is_some() {
                self.session.end_drag();
            }
            // A press and release in one place (within a few pixels) is a
            // click: it picks what is under the cursor.
            let at = self.flight.cursor();
            if let Some(p) = self.press_at.take()
                && (p.0 - at.0).hypot(p.1 - at.1) <= CLICK_SLOP
                && let Some(screen) = &self.screen
                && let Some(pic) = super::optics::picture(screen, &self.display)
            {
                let ppp = screen.window.scale_factor();
                let picked = super::pick::pick(&self.session.doc, &pic, at, ppp);
                self.session.picked(picked);
                self.settle();
            }
            return;
        }
        let columns = self.screen.as_ref().map_or(0, |s| s.panel_columns(&self.display));
        let over_panel = self.display.panel && self.flight.cursor().0 < columns as f64 * self.display.res_div as f64;
        if !consumed && !over_panel {
            let at = self.flight.cursor();
            self.press_at = Some(at);
            // On a light's marker or on the selected item, a drag moves it;
            // anywhere else it looks around.
            self.grab = self.grab_at(at);
            if self.grab.is_none() {
                self.flight.start_drag();
            }
        }
    }

    /// What a press at `at` grabs: a light's marker, or the item selected.
    fn grab_at(&self, at: (f64, f64)) -> Option<super::pick::Grab> {
        use super::pick::{Grab, Picked, pick};
        let screen = self.screen.as_ref()?;
        let pic = super::optics::picture(screen, &self.display)?;
        let doc = &self.session.doc;
        match pick(doc, &pic, at, screen.window.scale_factor())? {
            Picked::Item(item) if self.session.ui.selected != Some(item) => None,
            what => Grab::new(doc, what, at),
        }
    }

    /// A look-around drag is applied by the next flight step (once per
    /// frame shown); a grab moves what it holds at once.
    pub(super) fn cursor_moved(&mut self, x: f64, y: f64) {
        self.flight.cursor_moved((x, y));
        let along = self.modifiers.shift_key();
        if let Some(mut grab) = self.grab
            && let Some(screen) = &self.screen
            && let Some(pic) = super::optics::picture(screen, &self.display)
        {
            let by = grab.step(&self.session.doc, &pic, (x, y), along);
            self.grab = Some(grab);
            self.session.drag(grab.what, by);
            self.settle();
        }
    }

    /// The wheel (over the picture) changes the flight speed.
    pub(super) fn wheel(&mut self, delta: MouseScrollDelta) {
        let steps = match delta {
            MouseScrollDelta::LineDelta(_, y) => y as f64,
            MouseScrollDelta::PixelDelta(p) => p.y / 40.0,
        };
        let speed = self.flight.wheel(steps);
        self.session.message = format!("flight speed {speed:.2}");
        self.request_redraw();
    }
}
