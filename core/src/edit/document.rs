//! The scene being edited: its file model, where it came from, whether it
//! has unsaved changes, and its undo history. Knows nothing of windows: the
//! viewer's panels and keys call it, and the tests drive it directly.
//!
//! Every change is a function on a copy of the [`SceneFile`], validated by
//! [`Scene::build`] — the same code path as a file loaded from disk — and
//! kept only when it passes; a rejected change leaves the document as it
//! was and returns the problems. The document therefore always holds a
//! valid scene, so it can always be rendered and saved.
//!
//! - This file: the document, its undo history and what a change did.
//! - `items`: the *Objects* list — add, delete, duplicate, names.
//! - `systems`: lens systems (`[[systems]]`): new ones of each kind or
//!   preset, their fields, their table of surfaces and their key edits.
//! - `scene_edits`: every other change the panel and keys make (camera,
//!   lens, light, material, render settings, the key edits of
//!   [`super::Edit`]), each one method.
//! - `camera_lens`: the lens camera's switch, focus and f-number.
//! - `files`: save, save as, reload, and the TOML text.

mod camera_lens;
mod files;
mod items;
mod scene_edits;
mod systems;
mod unsaved;

pub use camera_lens::DEFAULT_CAMERA_LENS;
pub use unsaved::Unsaved;

pub use files::{ReloadError, SaveError, to_toml};
pub use items::{
    NEW_COLOUR, NEW_DISTANCE, NewItem, Placement, free_name, in_front_of_camera, new_lens, new_material, new_object,
    unique_key,
};
pub use scene_edits::{
    axis_angles, axis_from_angles, index_with_dispersion, new_point_light, set_camera_pose, switch_light_kind,
};
pub use systems::{new_preset_system, new_system, preset_scale, system_kind_label};

use crate::scene::{Problem, Scene, SceneError, SceneFile};
use glam::DVec3;
use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Undo steps kept (the oldest are forgotten first).
pub const UNDO_LIMIT: usize = 200;

/// Where the document's scene came from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Source {
    /// A file on disk: *Save* writes back to it.
    File(PathBuf),
    /// A preset compiled into the program (see [`super::presets`]): *Save*
    /// must ask for a file name.
    Preset(String),
    /// The embedded default scene.
    Default,
}

impl Source {
    pub fn path(&self) -> Option<&Path> {
        match self {
            Source::File(p) => Some(p),
            _ => None,
        }
    }
}

impl fmt::Display for Source {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            Source::File(p) => write!(f, "{}", p.display()),
            Source::Preset(n) => write!(f, "preset {n} (not saved)"),
            Source::Default => f.write_str("default scene (not saved)"),
        }
    }
}

/// An edit that did not pass validation; the document is unchanged.
#[derive(Clone, Debug, PartialEq)]
pub struct Rejected(pub Vec<Problem>);

impl Rejected {
    /// Whether some problem concerns `path` or a field below it
    /// (`"lenses[0]"` matches `lenses[0].r1`).
    pub fn concerns(&self, path: &str) -> bool {
        self.0.iter().any(|p| {
            let s = p.path.to_string();
            s == path || s.starts_with(&format!("{path}.")) || s.starts_with(&format!("{path}["))
        })
    }
}

impl fmt::Display for Rejected {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        for (i, p) in self.0.iter().enumerate() {
            if i > 0 {
                f.write_str("; ")?;
            }
            write!(f, "{}: {}", p.path, p.message)?;
        }
        Ok(())
    }
}

impl std::error::Error for Rejected {}

/// What an accepted edit did, for the render thread: the scene's own
/// [`Change`] (`Change::between` the files before and after).
pub use crate::scene::Change;

/// One item of the *Objects* list: a primitive, a lens (`[[lenses]]`) or
/// a lens system (`[[systems]]`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Item {
    Object(usize),
    Lens(usize),
    System(usize),
}

#[derive(Clone, Debug)]
struct Step {
    scene: SceneFile,
    label: String,
}

/// A scene being edited.
#[derive(Clone, Debug)]
pub struct Document {
    scene: SceneFile,
    built: Arc<Scene>,
    source: Source,
    /// The scene as last opened or saved: the document is dirty when it differs.
    saved: SceneFile,
    undo: Vec<Step>,
    redo: Vec<Step>,
    /// The merge key of the newest undo step while it is still open.
    merge: Option<String>,
    revision: u64,
    /// The camera pose as opened: what *Reset the view* returns to.
    home: (DVec3, DVec3),
}

impl Document {
    /// A document over a scene that passes validation.
    pub fn new(scene: SceneFile, source: Source) -> Result<Self, Rejected> {
        let built = Scene::build(&scene).map_err(Rejected)?;
        Ok(Self::from_parts(scene, built, source))
    }

    /// Opens a scene file.
    pub fn open(path: &Path) -> Result<Self, SceneError> {
        let (sf, scene) = Scene::load(path)?;
        Ok(Self::from_parts(sf, scene, Source::File(path.to_path_buf())))
    }

    /// Opens a preset (see [`super::presets::PRESETS`]).
    pub fn preset(name: &str) -> Result<Self, SceneError> {
        let p = super::presets::find(name).ok_or_else(|| SceneError::Invalid {
            file: name.to_string(),
            line: 1,
            column: 1,
            field: "(document)".into(),
            message: "no such preset".into(),
        })?;
        let (sf, scene) = Scene::parse(p.file, p.text)?;
        Ok(Self::from_parts(sf, scene, Source::Preset(p.name.to_string())))
    }

    fn from_parts(scene: SceneFile, built: Scene, source: Source) -> Self {
        Document {
            home: (built.camera.position, built.camera.rotation_deg),
            saved: scene.clone(),
            scene,
            built: Arc::new(built),
            source,
            undo: Vec::new(),
            redo: Vec::new(),
            merge: None,
            revision: 0,
        }
    }

    pub fn scene(&self) -> &SceneFile {
        &self.scene
    }

    /// The validated render model of [`Self::scene`].
    pub fn built(&self) -> &Arc<Scene> {
        &self.built
    }

    pub fn source(&self) -> &Source {
        &self.source
    }

    /// Whether the scene differs from the file as last opened or saved.
    pub fn is_dirty(&self) -> bool {
        self.scene != self.saved
    }

    /// Bumped by every change of the scene (edit, undo, redo, reload).
    pub fn revision(&self) -> u64 {
        self.revision
    }

    /// `"scenes/cubes.toml *"`: the source and an unsaved-changes mark;
    /// `"… (camera moved)"` when only the view is unsaved.
    pub fn title(&self) -> String {
        let u = self.unsaved();
        let mark = if u.content {
            " *"
        } else if u.view {
            " (camera moved)"
        } else {
            ""
        };
        format!("{}{mark}", self.source)
    }

    /// Applies `f` to a copy of the scene; keeps it if it validates. One
    /// undo step per call.
    pub fn edit(&mut self, label: &str, f: impl FnOnce(&mut SceneFile)) -> Result<Change, Rejected> {
        self.merge = None;
        self.commit(label, None, f)
    }

    /// Like [`Self::edit`], but successive calls with the same `key` make
    /// one undo step until [`Self::seal`] (or an edit with another key):
    /// dragging a value or flying the camera is one step, not hundreds.
    pub fn edit_merged(&mut self, key: &str, label: &str, f: impl FnOnce(&mut SceneFile)) -> Result<Change, Rejected> {
        self.commit(label, Some(key), f)
    }

    /// Ends the open merged step, so the next merged edit starts a new one.
    pub fn seal(&mut self) {
        self.merge = None;
    }

    fn commit(&mut self, label: &str, key: Option<&str>, f: impl FnOnce(&mut SceneFile)) -> Result<Change, Rejected> {
        let mut next = self.scene.clone();
        f(&mut next);
        if next == self.scene {
            return Ok(Change::None);
        }
        let built = Scene::build(&next).map_err(Rejected)?;
        let change = Change::between(&self.scene, &next);
        let merging = key.is_some() && self.merge.as_deref() == key && !self.undo.is_empty();
        if !merging {
            self.undo.push(Step {
                scene: std::mem::replace(&mut self.scene, next),
                label: label.to_string(),
            });
            if self.undo.len() > UNDO_LIMIT {
                self.undo.remove(0);
            }
        } else {
            self.scene = next;
        }
        self.merge = key.map(str::to_string);
        self.redo.clear();
        self.built = Arc::new(built);
        self.revision += 1;
        Ok(change)
    }

    /// Undoes the newest step; returns its label and what changed.
    pub fn undo(&mut self) -> Option<(String, Change)> {
        let step = self.undo.pop()?;
        Some(self.swap(step, true))
    }

    /// Redoes the newest undone step.
    pub fn redo(&mut self) -> Option<(String, Change)> {
        let step = self.redo.pop()?;
        Some(self.swap(step, false))
    }

    fn swap(&mut self, step: Step, undoing: bool) -> (String, Change) {
        self.merge = None;
        let change = Change::between(&self.scene, &step.scene);
        // Every scene on the stacks was valid when it was pushed, and
        // validation depends on nothing but the scene; should that ever
        // change, the step is dropped rather than shown half-valid.
        let Ok(built) = Scene::build(&step.scene) else {
            return (step.label, Change::None);
        };
        let back = Step {
            scene: std::mem::replace(&mut self.scene, step.scene),
            label: step.label.clone(),
        };
        if undoing {
            self.redo.push(back);
        } else {
            self.undo.push(back);
        }
        self.built = Arc::new(built);
        self.revision += 1;
        (step.label, change)
    }

    /// Label of the step [`Self::undo`] would undo.
    pub fn undo_label(&self) -> Option<&str> {
        self.undo.last().map(|s| s.label.as_str())
    }

    pub fn redo_label(&self) -> Option<&str> {
        self.redo.last().map(|s| s.label.as_str())
    }

    /// Number of steps that can be undone.
    pub fn undo_depth(&self) -> usize {
        self.undo.len()
    }

    /// The camera's position and rotation (degrees), whether the file gives
    /// `rotation` or `look_at`.
    pub fn camera_pose(&self) -> (DVec3, DVec3) {
        (self.built.camera.position, self.built.camera.rotation_deg)
    }

    /// The camera pose as opened (position, rotation in degrees).
    pub fn home(&self) -> (DVec3, DVec3) {
        self.home
    }
}

#[cfg(test)]
mod tests;
