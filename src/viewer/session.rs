//! The editing session the keys and the panel share: the document, the
//! panel's own state and the message line, with the commands both give
//! (undo, redo, save, open, reload, delete, the unsaved-changes question).
//!
//! Nothing here knows the window. What a command needs of it — restart
//! refinement, drop the old picture, resize, pause, quit — is gathered in an
//! [`Outcome`], which the shell takes and carries out after each key or UI
//! pass.

use super::panel::{Answer, DialogMode, Pending, UiState};
use lensview::edit::{Change, Document, Edit, Item, Rejected};
use std::path::Path;

/// What only the window can do, asked for by a key or the panel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Command {
    Quit,
    ShowPanel(bool),
    /// In a narrow window: open the panel from its strip, or fold it back.
    ExpandPanel(bool),
    /// Render at 1/n of the window's resolution.
    Resolution(u32),
    SampleCap(u32),
    TogglePause,
    /// Save the picture at full resolution in this format.
    Screenshot,
    /// Start or stop recording a flight.
    ToggleRecording,
}

/// What the keys and clicks since the last [`Session::take_outcome`] did.
#[derive(Debug, Default, PartialEq)]
pub struct Outcome {
    /// The largest change an accepted edit made, if any edit was made.
    pub change: Option<Change>,
    /// The document was replaced (open, preset): the old picture goes.
    pub new_document: bool,
    /// Something on screen changed (title, panel, a question).
    pub redraw: bool,
    pub commands: Vec<Command>,
}

pub struct Session {
    pub doc: Document,
    pub ui: UiState,
    /// The line under the panel's buttons and at the foot of the overlay.
    pub message: String,
    out: Outcome,
    /// When Escape last asked to be pressed again to quit (nothing to lose).
    quit_armed: Option<std::time::Instant>,
}

/// How long a second Escape has to quit a session with nothing unsaved.
pub const QUIT_AGAIN: std::time::Duration = std::time::Duration::from_secs(3);

impl Session {
    pub fn new(doc: Document, ui: UiState) -> Self {
        Session {
            doc,
            ui,
            message: "F2: help  F4: panel".into(),
            out: Outcome::default(),
            quit_armed: None,
        }
    }

    pub fn take_outcome(&mut self) -> Outcome {
        std::mem::take(&mut self.out)
    }

    pub fn ask(&mut self, c: Command) {
        self.out.commands.push(c);
        self.out.redraw = true;
    }

    pub fn redraw(&mut self) {
        self.out.redraw = true;
    }

    /// After an accepted edit: refinement restarts when the picture
    /// changed; the title and panel are redrawn either way.
    pub fn changed(&mut self, c: Change) {
        self.out.change = Some(self.out.change.map_or(c, |old| old.max(c)));
        self.out.redraw = true;
    }

    /// Turns caustics off when the scene computes them, else on (a scene
    /// without lit glass or mirror then computes nothing still).
    pub fn toggle_caustics(&mut self) {
        let on = !self.doc.built().features.caustics;
        let r = self.doc.set_caustics(on);
        self.apply_result(if on { "caustics on" } else { "caustics off" }, r);
    }

    /// Shows `what` for an accepted edit, or why it was refused.
    pub fn apply_result(&mut self, what: &str, r: Result<Change, Rejected>) {
        match r {
            Ok(c) => {
                self.message = what.to_string();
                self.changed(c);
            }
            Err(e) => self.refuse(format!("not applied: {e}")),
        }
    }

    /// A failure: on the message line and in red at the top of the panel.
    fn refuse(&mut self, msg: String) {
        self.ui.error = Some(msg.clone());
        self.message = msg;
    }

    /// A key edit: its line, or why it was refused, on the message line.
    /// With a lens system selected, the lens keys act on it.
    pub fn apply_edit(&mut self, e: Edit) {
        let r = match self.ui.selected {
            Some(Item::System(i)) if e.is_lens() => self.doc.apply_system_edit(i, e),
            _ => self.doc.apply_edit(e),
        };
        self.key_outcome(r.map_err(lensview::edit::KeyRefused::Rejected));
    }

    /// What a key edit did, or why not, on the message line.
    pub fn key_outcome(&mut self, r: lensview::edit::KeyOutcome) {
        match r {
            Ok((msg, c)) => {
                self.message = msg;
                self.changed(c);
            }
            Err(e) => self.message = e.to_string(),
        }
    }

    /// Scene key `key` applied to the document, the light's colour keys
    /// stepping the preset and temperature the panel shares.
    pub fn scene_key(&mut self, key: lensview::edit::SceneKey) {
        let mut state = lensview::edit::KeyState {
            preset: self.ui.preset,
            temperature: self.ui.temperature,
        };
        let r = self.doc.scene_key(key, &mut state);
        (self.ui.preset, self.ui.temperature) = (state.preset, state.temperature);
        self.key_outcome(r);
    }

    pub fn reset_view(&mut self) {
        self.scene_key(lensview::edit::SceneKey::ResetView);
    }

    pub fn undo(&mut self) {
        match self.doc.undo() {
            Some((label, c)) => {
                self.message = format!("undone: {label}");
                self.changed(c);
            }
            None => self.message = "nothing to undo".into(),
        }
    }

    pub fn redo(&mut self) {
        match self.doc.redo() {
            Some((label, c)) => {
                self.message = format!("redone: {label}");
                self.changed(c);
            }
            None => self.message = "nothing to redo".into(),
        }
    }

    /// Ctrl+S: to the document's file, or ask for one. True when saved.
    pub fn save(&mut self) -> bool {
        match self.doc.save() {
            Ok(Some(p)) => {
                self.message = format!("saved {}", p.display());
                self.ui.error = None;
                self.redraw();
                true
            }
            Ok(None) => {
                self.ui.open_file_dialog(DialogMode::SaveAs, self.doc.source());
                false
            }
            Err(e) => {
                self.refuse(format!("not saved: {e}"));
                false
            }
        }
    }

    pub fn save_as(&mut self, path: &Path) -> Result<(), String> {
        let p = self.doc.save_as(path).map_err(|e| e.to_string())?;
        self.message = format!("saved {}", p.display());
        self.ui.error = None;
        self.redraw();
        Ok(())
    }

    pub fn reload(&mut self) {
        match self.doc.reload(true) {
            Ok(c) => {
                self.message = format!("reloaded {} (Ctrl+Z undoes)", self.doc.source());
                self.ui.error = None;
                self.changed(c);
            }
            // Nothing the user made is lost: the current scene stays.
            Err(e) => self.refuse(format!("reload failed, scene kept: {e}")),
        }
    }

    /// Replaces the document (open, preset); the view goes to its camera.
    fn replace_document(&mut self, doc: Document, what: String) {
        self.doc = doc;
        self.ui.reset_for_new_document();
        self.message = what;
        self.ui.error = None;
        self.out.new_document = true;
        self.changed(Change::Picture);
    }

    /// Opens a file, keeping the current scene when it does not load.
    fn open_path(&mut self, path: &Path) -> Result<(), String> {
        match Document::open(path) {
            Ok(doc) => {
                self.replace_document(doc, format!("opened {}", path.display()));
                Ok(())
            }
            Err(e) => {
                let msg = format!("not opened, the current scene is kept: {e}");
                self.refuse(msg.clone());
                Err(msg)
            }
        }
    }

    fn open_preset(&mut self, name: &str) {
        match Document::preset(name) {
            Ok(doc) => self.replace_document(doc, format!("preset {name}")),
            Err(e) => self.refuse(format!("preset not opened: {e}")),
        }
    }

    /// Does what was asked, or asks first when it would lose unsaved
    /// edits (a camera moved by flying alone is not worth the question).
    pub fn perform(&mut self, p: Pending, ask: bool) {
        self.redraw();
        if ask && self.doc.has_unsaved_content() {
            self.ui.confirm = Some(p);
            return;
        }
        self.ui.confirm = None;
        match p {
            Pending::Quit => self.ask(Command::Quit),
            Pending::Open(path) => {
                if self.open_path(&path).is_ok() {
                    self.ui.file_dialog = None;
                }
            }
            Pending::Preset(name) => self.open_preset(&name),
        }
    }

    /// Escape: closes what is open first (answers "cancel" to a question,
    /// closes the file dialog, then the analysis window); otherwise quits:
    /// with unsaved changes it asks, with none it asks for a second Escape
    /// within [`QUIT_AGAIN`] (a stray key must not end the session
    /// without a word).
    pub fn request_quit(&mut self) {
        self.redraw();
        if self.ui.confirm.take().is_some() {
            self.message = "cancelled".into();
            return;
        }
        if self.ui.file_dialog.take().is_some() {
            self.message = "closed the file dialog".into();
            self.quit_armed = None;
            return;
        }
        if std::mem::take(&mut self.ui.analysis.window) {
            self.message = "closed the analysis window".into();
            self.quit_armed = None;
            return;
        }
        if self.doc.has_unsaved_content() {
            return self.perform(Pending::Quit, true);
        }
        match self.quit_armed.take() {
            Some(t) if t.elapsed() <= QUIT_AGAIN => self.perform(Pending::Quit, false),
            _ => {
                self.quit_armed = Some(std::time::Instant::now());
                self.message = format!("press Esc again to quit (within {} s)", QUIT_AGAIN.as_secs());
            }
        }
    }

    /// Answers the unsaved-changes question (buttons, or keys S, D, Esc).
    pub fn answer(&mut self, a: Answer) {
        self.redraw();
        let Some(p) = self.ui.confirm.clone() else { return };
        match a {
            Answer::Save if self.doc.source().path().is_some() => {
                if self.save() {
                    self.perform(p, false);
                }
            }
            Answer::Save => {
                self.ui.after_save = Some(p);
                self.ui.confirm = None;
                self.ui.open_file_dialog(DialogMode::SaveAs, self.doc.source());
            }
            Answer::Discard => self.perform(p, false),
            Answer::Cancel => {
                self.ui.confirm = None;
                self.message = "cancelled".into();
            }
        }
    }

    /// Duplicates the selected item and selects the copy (button, Ctrl+D).
    pub fn duplicate_selected(&mut self) {
        let Some(item) = self.ui.selected else {
            self.message = "select an object first (Objects)".into();
            return;
        };
        match self.doc.duplicate(item) {
            Ok(Some(copy)) => {
                self.select(copy);
                self.message = format!("duplicated as {}", self.doc.item_name(copy));
                self.changed(Change::Picture);
            }
            Ok(None) => {}
            Err(e) => self.ui.error = Some(format!("not duplicated: {e}")),
        }
    }

    /// Deletes the selected item (button, Delete key); Ctrl+Z brings it back.
    pub fn delete_selected(&mut self) {
        let Some(item) = self.ui.selected else {
            self.message = "select an object first (Objects)".into();
            return;
        };
        let name = self.doc.item_name(item);
        let r = self.doc.delete(item);
        self.ui.selected = None;
        self.apply_result(&format!("deleted {name} (Ctrl+Z undoes)"), r);
    }

    /// Selects a new item; a lens is also the one the *Lens* section shows.
    pub fn select(&mut self, item: Item) {
        self.ui.selected = Some(item);
        match item {
            Item::Lens(i) => self.ui.lens = i,
            Item::System(_) => self.ui.open_system(),
            Item::Object(_) => {}
        }
    }

    /// A drag moved what was picked by `by` (world units): one undo step
    /// per drag, ended by [`Self::end_drag`].
    pub fn drag(&mut self, what: super::pick::Picked, by: glam::DVec3) {
        use super::pick::Picked;
        if by == glam::DVec3::ZERO {
            return;
        }
        let (moved, name) = match what {
            Picked::Item(item) => (self.doc.move_item(item, by), self.doc.item_name(item)),
            Picked::Light(k) => (self.doc.move_light(k, by), format!("light {}", k + 1)),
        };
        match moved {
            Ok(c) => {
                self.message = format!("moving {name} (Ctrl+Z undoes the whole drag)");
                self.changed(c);
            }
            Err(e) => self.message = format!("{name} not moved: {e}"),
        }
    }

    /// The drag ended: the next one is its own undo step.
    pub fn end_drag(&mut self) {
        self.doc.seal();
    }

    /// A click on the picture picked `p` (`None`: the background, which
    /// clears the selection): the panel shows it.
    pub fn picked(&mut self, p: Option<super::pick::Picked>) {
        use super::pick::Picked;
        self.redraw();
        match p {
            Some(Picked::Item(item)) => {
                self.select(item);
                if matches!(item, Item::Lens(_)) {
                    self.ui.open_lens();
                }
                self.message = format!("selected {}", self.doc.item_name(item));
            }
            Some(Picked::Light(i)) => {
                self.ui.show_light(i);
                self.message = format!("light {} (the Light section shows it)", i + 1);
            }
            None => {
                self.ui.selected = None;
                self.message = "nothing selected".into();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn session() -> Session {
        Session::new(Document::preset("cubes").unwrap(), UiState::new(None))
    }

    #[test]
    fn edits_undo_and_redo_say_what_they_did_and_ask_for_a_restart() {
        let mut s = session();
        s.apply_edit(Edit::LightIntensity(2.0));
        assert!(s.message.starts_with("light intensity"), "{}", s.message);
        let out = s.take_outcome();
        assert_eq!((out.change, out.redraw), (Some(Change::Picture), true));
        assert_eq!(s.take_outcome(), Outcome::default(), "taken once");
        s.undo();
        assert!(s.message.starts_with("undone: light intensity"), "{}", s.message);
        s.undo();
        assert_eq!(s.message, "nothing to undo");
        s.redo();
        assert_eq!(s.take_outcome().change, Some(Change::Picture));
    }

    #[test]
    fn quitting_with_unsaved_changes_asks_first_and_escape_cancels() {
        let mut s = session();
        s.request_quit();
        assert!(s.take_outcome().commands.is_empty(), "a stray Escape quit");
        assert!(s.message.starts_with("press Esc again"), "{}", s.message);
        s.request_quit();
        assert_eq!(
            s.take_outcome().commands,
            [Command::Quit],
            "nothing to lose: the second Escape quits"
        );
        // Flying alone: no question (Save would keep the view), two presses.
        let (p, r) = s.doc.camera_pose();
        s.doc.fly_camera(p + glam::DVec3::X, r).unwrap();
        s.request_quit();
        s.request_quit();
        assert_eq!(s.ui.confirm, None);
        assert_eq!(s.take_outcome().commands, [Command::Quit], "a flight alone: quits");
        // A press long ago does not count.
        s.request_quit();
        s.quit_armed = Some(std::time::Instant::now() - QUIT_AGAIN * 2);
        s.request_quit();
        assert!(s.take_outcome().commands.is_empty(), "an old Escape counted");
        // Escape closes the analysis window before anything else.
        s.ui.analysis.window = true;
        s.request_quit();
        s.request_quit();
        assert!(!s.ui.analysis.window);
        assert!(
            s.take_outcome().commands.is_empty(),
            "quit with the analysis window open"
        );
        s.apply_edit(Edit::LensDiameter(0.1));
        s.request_quit();
        assert_eq!(s.ui.confirm, Some(Pending::Quit));
        assert!(s.take_outcome().commands.is_empty());
        s.request_quit();
        assert_eq!((s.ui.confirm.clone(), s.message.as_str()), (None, "cancelled"));
        s.perform(Pending::Quit, true);
        s.answer(Answer::Discard);
        assert_eq!(s.take_outcome().commands, [Command::Quit]);
    }

    #[test]
    fn a_preset_replaces_the_document_and_a_failed_open_keeps_it() {
        let mut s = session();
        s.ui.selected = Some(Item::Object(3));
        s.perform(Pending::Preset("primitives".into()), true);
        let out = s.take_outcome();
        assert!(out.new_document && out.change == Some(Change::Picture));
        assert_eq!(s.ui.selected, None);
        assert_eq!(s.doc.source().to_string(), "preset primitives (not saved)");
        s.perform(Pending::Open("/no/such/scene.toml".into()), false);
        assert!(s.ui.error.as_deref().unwrap_or("").contains("not opened"));
        assert!(!s.take_outcome().new_document);
        assert_eq!(s.doc.source().to_string(), "preset primitives (not saved)");
        // Saving a preset asks for a file name.
        assert!(!s.save());
        assert!(s.ui.file_dialog.is_some());
    }

    #[test]
    fn duplicate_and_delete_act_on_the_selection() {
        let mut s = session();
        s.delete_selected();
        assert_eq!(s.message, "select an object first (Objects)");
        s.select(Item::Lens(0));
        s.duplicate_selected();
        assert_eq!(s.ui.selected, Some(Item::Lens(1)));
        assert_eq!(s.ui.lens, 1);
        s.delete_selected();
        assert_eq!(s.ui.selected, None);
        assert_eq!(s.doc.scene().lenses.len(), 1);
        assert!(s.message.starts_with("deleted lens copy"), "{}", s.message);
    }

    /// With a lens system selected the lens keys move it; without, they
    /// look for a `[[lenses]]` lens (the lens family has none).
    #[test]
    fn lens_keys_act_on_a_selected_system() {
        let mut s = Session::new(Document::preset("lens family").unwrap(), UiState::new(None));
        s.apply_edit(Edit::LensAlongAxis(0.5));
        assert_eq!(s.message, "the scene has no lens");
        s.select(Item::System(2));
        let z = s.doc.scene().systems[2].center.unwrap()[2];
        s.apply_edit(Edit::LensAlongAxis(0.5));
        assert!(s.message.starts_with("meniscus: centre"), "{}", s.message);
        assert_eq!(s.doc.scene().systems[2].center.unwrap()[2], z + 0.5);
        s.apply_edit(Edit::LensDiameter(10.0));
        assert!(s.message.starts_with("not applied: systems[2]"), "{}", s.message);
        s.duplicate_selected();
        assert_eq!(s.ui.selected, Some(Item::System(3)));
        s.delete_selected();
        assert_eq!(s.doc.scene().systems.len(), 3);
    }
}
