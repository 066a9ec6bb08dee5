//! The scene being edited: its file model, where it came from, whether it
//! has unsaved changes, and its undo history. Knows nothing of windows: the
//! viewer's panels and keys call it, and the tests drive it directly.
//!
//! Every change is a function on a copy of the [`SceneFile`], validated by
//! [`Scene::build`] — the same code path as a file loaded from disk — and
//! kept only when it passes; a rejected change leaves the document as it
//! was and returns the problems. The document therefore always holds a
//! valid scene, so it can always be rendered and saved.

use crate::math::angles_looking_along;
use crate::scene::file::{IndexFile, LensFile, LightFile, MaterialFile, ObjectFile, ShapeKind, V3};
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

/// What an accepted edit did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Change {
    /// Nothing changed (no undo step was made).
    None,
    /// The file changed but not the picture (a name, `render.spp`, an unused
    /// material): no need to restart refinement.
    File,
    /// The picture changed: restart refinement.
    Picture,
}

impl Change {
    pub fn restarts(self) -> bool {
        self == Change::Picture
    }
}

/// One item of the *Objects* list: a primitive or a lens.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Item {
    Object(usize),
    Lens(usize),
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
}

impl Document {
    /// A document over a scene that passes validation.
    pub fn new(scene: SceneFile, source: Source) -> Result<Self, Rejected> {
        let built = Scene::build(&scene).map_err(Rejected)?;
        Ok(Document {
            saved: scene.clone(),
            scene,
            built: Arc::new(built),
            source,
            undo: Vec::new(),
            redo: Vec::new(),
            merge: None,
            revision: 0,
        })
    }

    /// Opens a scene file.
    pub fn open(path: &Path) -> Result<Self, SceneError> {
        let (sf, scene) = Scene::load(path)?;
        Ok(Document {
            saved: sf.clone(),
            scene: sf,
            built: Arc::new(scene),
            source: Source::File(path.to_path_buf()),
            undo: Vec::new(),
            redo: Vec::new(),
            merge: None,
            revision: 0,
        })
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
        Ok(Document {
            saved: sf.clone(),
            scene: sf,
            built: Arc::new(scene),
            source: Source::Preset(p.name.to_string()),
            undo: Vec::new(),
            redo: Vec::new(),
            merge: None,
            revision: 0,
        })
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

    /// `"scenes/cubes.toml *"`: the source and an unsaved-changes mark.
    pub fn title(&self) -> String {
        format!("{}{}", self.source, if self.is_dirty() { " *" } else { "" })
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
        let change = if same_picture(&self.scene, &next) {
            Change::File
        } else {
            Change::Picture
        };
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
        let change = if same_picture(&self.scene, &step.scene) {
            Change::File
        } else {
            Change::Picture
        };
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

    /// Saves to the document's own file. `Ok(None)` when it has none (a
    /// preset or the default scene): ask for a name and use [`Self::save_as`].
    pub fn save(&mut self) -> Result<Option<PathBuf>, SaveError> {
        match self.source.path().map(Path::to_path_buf) {
            Some(p) => self.save_as(&p).map(Some),
            None => Ok(None),
        }
    }

    /// Writes the scene as TOML to `path` (through a temporary file and a
    /// rename, so a failed save never leaves half a file), checks that the
    /// text reads back to the identical scene, and makes `path` the
    /// document's file.
    pub fn save_as(&mut self, path: &Path) -> Result<PathBuf, SaveError> {
        let text = to_toml(&self.scene).map_err(SaveError::Serialize)?;
        write_atomically(path, &text).map_err(|err| SaveError::Io {
            path: path.to_path_buf(),
            err,
        })?;
        self.source = Source::File(path.to_path_buf());
        self.saved = self.scene.clone();
        Ok(path.to_path_buf())
    }

    /// Reads the document's file again as one undoable step. With
    /// `keep_camera` the camera stays where it is. A file that does not load
    /// changes nothing.
    pub fn reload(&mut self, keep_camera: bool) -> Result<Change, ReloadError> {
        let path = self.source.path().ok_or(ReloadError::NoFile)?.to_path_buf();
        let (mut sf, _) = Scene::load(&path).map_err(ReloadError::Scene)?;
        let on_disk = sf.clone();
        if keep_camera {
            sf.camera = self.scene.camera.clone();
        }
        let change = self.edit("reload", |s| *s = sf).map_err(ReloadError::Rejected)?;
        self.saved = on_disk;
        Ok(change)
    }

    /// The items of the *Objects* list: primitives, then lenses, with the
    /// names the renderer uses.
    pub fn items(&self) -> Vec<(Item, String)> {
        let mut v: Vec<(Item, String)> = (0..self.scene.objects.len())
            .map(|i| (Item::Object(i), self.item_name(Item::Object(i))))
            .collect();
        v.extend((0..self.scene.lenses.len()).map(|i| (Item::Lens(i), self.item_name(Item::Lens(i)))));
        v
    }

    /// The displayed name of an item (its `name`, or the default the
    /// renderer gives it).
    pub fn item_name(&self, item: Item) -> String {
        match item {
            Item::Object(i) => self.scene.objects.get(i).map_or_else(String::new, |o| {
                o.name.clone().unwrap_or_else(|| format!("{} {}", o.kind.name(), i + 1))
            }),
            Item::Lens(i) => self.scene.lenses.get(i).map_or_else(String::new, |l| {
                l.name.clone().unwrap_or_else(|| format!("lens {}", i + 1))
            }),
        }
    }

    pub fn contains(&self, item: Item) -> bool {
        match item {
            Item::Object(i) => i < self.scene.objects.len(),
            Item::Lens(i) => i < self.scene.lenses.len(),
        }
    }

    /// Adds a primitive, with a new material of its own when `material` is
    /// given (its name made unique). Returns the new item.
    pub fn add_object(
        &mut self,
        mut object: ObjectFile,
        material: Option<(String, MaterialFile)>,
    ) -> Result<Item, Rejected> {
        if object.name.is_none() {
            object.name = Some(self.unique_name(object.kind.name()));
        }
        let label = format!("add {}", object.kind.name());
        let index = self.scene.objects.len();
        self.edit(&label, |sf| {
            if let Some((name, m)) = material {
                let name = unique_key(&sf.materials, &name);
                sf.materials.insert(name.clone(), m);
                object.material = Some(name);
            }
            sf.objects.push(object);
        })?;
        Ok(Item::Object(index))
    }

    /// Adds a lens; returns the new item.
    pub fn add_lens(&mut self, mut lens: LensFile) -> Result<Item, Rejected> {
        if lens.name.is_none() {
            lens.name = Some(self.unique_name("lens"));
        }
        let index = self.scene.lenses.len();
        self.edit("add lens", |sf| sf.lenses.push(lens))?;
        Ok(Item::Lens(index))
    }

    /// Deletes an item (its material stays in `[materials]`).
    pub fn delete(&mut self, item: Item) -> Result<Change, Rejected> {
        if !self.contains(item) {
            return Ok(Change::None);
        }
        let label = format!("delete {}", self.item_name(item));
        self.edit(&label, |sf| match item {
            Item::Object(i) => {
                sf.objects.remove(i);
            }
            Item::Lens(i) => {
                sf.lenses.remove(i);
            }
        })
    }

    /// Duplicates an item beside the original (moved along +x by its width
    /// and a little more, so the copy is seen); returns the copy.
    pub fn duplicate(&mut self, item: Item) -> Result<Option<Item>, Rejected> {
        if !self.contains(item) {
            return Ok(None);
        }
        let base = self.item_name(item);
        let name = self.unique_name(&format!("{base} copy"));
        let label = format!("duplicate {base}");
        match item {
            Item::Object(i) => {
                let mut o = self.scene.objects[i].clone();
                o.name = Some(name);
                o.position[0] += object_width(&o) + 0.25;
                let at = self.scene.objects.len();
                self.edit(&label, |sf| sf.objects.push(o))?;
                Ok(Some(Item::Object(at)))
            }
            Item::Lens(i) => {
                let mut l = self.scene.lenses[i].clone();
                l.name = Some(name);
                l.center[0] += l.d + 0.25;
                let at = self.scene.lenses.len();
                self.edit(&label, |sf| sf.lenses.push(l))?;
                Ok(Some(Item::Lens(at)))
            }
        }
    }

    /// A name no item has yet: `base`, or `base 2`, `base 3`, …
    pub fn unique_name(&self, base: &str) -> String {
        let taken: Vec<String> = self.items().into_iter().map(|(_, n)| n).collect();
        free_name(base, |n| taken.iter().any(|t| t == n))
    }

    /// The camera's position and rotation (degrees), whether the file gives
    /// `rotation` or `look_at`.
    pub fn camera_pose(&self) -> (DVec3, DVec3) {
        (self.built.camera.position, self.built.camera.rotation_deg)
    }
}

/// Sets the camera's pose as `position` and `rotation` (dropping `look_at`).
pub fn set_camera_pose(sf: &mut SceneFile, position: DVec3, rotation_deg: DVec3) {
    sf.camera.position = position.to_array();
    sf.camera.rotation = Some(rotation_deg.to_array());
    sf.camera.look_at = None;
}

/// Whether two valid scenes render the same picture in the viewer: equal
/// but for names, `render.spp` (used only by `lensview render`) and
/// materials no object uses. Camera `look_at` and the equivalent `rotation`
/// count as different (a harmless extra restart).
pub fn same_picture(a: &SceneFile, b: &SceneFile) -> bool {
    fn key(sf: &SceneFile) -> (SceneFile, Vec<Option<MaterialFile>>) {
        let mut k = sf.clone();
        k.render.spp = 0;
        k.materials.clear();
        let mats = sf
            .objects
            .iter()
            .map(|o| o.material.as_ref().and_then(|m| sf.materials.get(m)).cloned())
            .collect();
        for o in &mut k.objects {
            o.name = None;
            o.material = None;
        }
        for l in &mut k.lenses {
            l.name = None;
        }
        (k, mats)
    }
    key(a) == key(b)
}

/// The scene as TOML text that reads back to the identical [`SceneFile`].
pub fn to_toml(sf: &SceneFile) -> Result<String, String> {
    let body = toml::to_string(sf).map_err(|e| e.to_string())?;
    let text = format!(
        "# lensview scene (saved by lensview {})\n\n{body}",
        env!("CARGO_PKG_VERSION")
    );
    // The promise is that saving loses nothing: check it before writing.
    let back: SceneFile = toml::from_str(&text).map_err(|e| format!("the saved text does not read back: {e}"))?;
    if &back != sf {
        return Err("the saved text reads back to a different scene".into());
    }
    Ok(text)
}

fn write_atomically(path: &Path, text: &str) -> std::io::Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let name = path
        .file_name()
        .ok_or_else(|| std::io::Error::new(std::io::ErrorKind::InvalidInput, "not a file name"))?;
    let tmp = dir.join(format!(".{}.{}.tmp", name.to_string_lossy(), std::process::id()));
    std::fs::write(&tmp, text)?;
    std::fs::rename(&tmp, path).inspect_err(|_| {
        let _ = std::fs::remove_file(&tmp);
    })
}

/// Why a save failed (the document is unchanged and still dirty).
#[derive(Debug, thiserror::Error)]
pub enum SaveError {
    #[error("cannot write {}: {err}", path.display())]
    Io { path: PathBuf, err: std::io::Error },
    #[error("cannot write the scene as TOML: {0}")]
    Serialize(String),
}

/// Why a reload failed (the document is unchanged).
#[derive(Debug, thiserror::Error)]
pub enum ReloadError {
    #[error("this scene has no file to reload (it is a preset or the default scene)")]
    NoFile,
    #[error("{0}")]
    Scene(SceneError),
    #[error("{0}")]
    Rejected(Rejected),
}

/// The first of `base`, `base 2`, `base 3`, … that `taken` refuses.
pub fn free_name(base: &str, taken: impl Fn(&str) -> bool) -> String {
    (1..)
        .map(|k| {
            if k == 1 {
                base.to_string()
            } else {
                format!("{base} {k}")
            }
        })
        .find(|n| !taken(n))
        .unwrap_or_else(|| base.to_string()) // ok: the range is endless
}

/// A key not yet in `map`: see [`free_name`].
pub fn unique_key<V>(map: &std::collections::BTreeMap<String, V>, base: &str) -> String {
    free_name(base, |n| map.contains_key(n))
}

fn object_width(o: &ObjectFile) -> f64 {
    match o.kind {
        ShapeKind::Cuboid => o.size.map_or(1.0, |s| s[0]),
        ShapeKind::Sphere => 2.0 * o.radius.unwrap_or(0.5),
        ShapeKind::Prism | ShapeKind::Pyramid => o.side.unwrap_or(1.0),
    }
}

/// A new primitive of `kind` at `position` with the default sizes of the
/// *Add* form: a unit cube, a sphere of radius 0.5, prism and pyramid of
/// side 1 and height 1.
pub fn new_object(kind: ShapeKind, position: V3) -> ObjectFile {
    let mut o = ObjectFile {
        kind,
        name: None,
        position,
        rotation: [0.0; 3],
        size: None,
        radius: None,
        side: None,
        height: None,
        material: None,
    };
    match kind {
        ShapeKind::Cuboid => o.size = Some([1.0; 3]),
        ShapeKind::Sphere => o.radius = Some(0.5),
        ShapeKind::Prism | ShapeKind::Pyramid => {
            o.side = Some(1.0);
            o.height = Some(1.0);
        }
    }
    o
}

/// A new lens at `center` facing `axis`: d = 2, r1 = r2 = 5, n = 1.5 (the
/// cubes scene's lens).
pub fn new_lens(center: V3, axis: V3) -> LensFile {
    LensFile {
        name: None,
        center,
        axis,
        d: 2.0,
        r1: 5.0,
        r2: 5.0,
        n: IndexFile::Constant(1.5),
        tint: [1.0; 3],
    }
}

/// A plain coloured material for a new object.
pub fn new_material(color: V3) -> MaterialFile {
    MaterialFile {
        color,
        specular: 0.3,
        ..MaterialFile::default()
    }
}

/// A point `distance` in front of the camera: where the *Add* form puts new
/// things so they are seen at once.
pub fn in_front_of_camera(scene: &Scene, distance: f64) -> V3 {
    (scene.camera.position + scene.camera.forward() * distance).to_array()
}

/// Yaw and pitch (degrees) of a lens axis: the angles that turn +z onto it,
/// in the camera's convention (`R = Ry·Rx`, no roll).
pub fn axis_angles(axis: V3) -> (f64, f64) {
    // The camera convention turns −z; a lens axis is turned from +z, which
    // is −z turned by 180° of yaw.
    let a = DVec3::from(axis).normalize_or(DVec3::Z);
    let r = angles_looking_along(-a);
    (r.y, -r.x)
}

/// The lens axis for yaw and pitch in degrees (inverse of [`axis_angles`]).
pub fn axis_from_angles(yaw_deg: f64, pitch_deg: f64) -> V3 {
    let r = crate::math::rotation_from_degrees(DVec3::new(-pitch_deg, yaw_deg, 0.0));
    let a = -(r * DVec3::NEG_Z);
    clean(a).to_array()
}

/// Rounds away the last-ulp noise of trigonometry (1e-15) so saved axes read well.
fn clean(v: DVec3) -> DVec3 {
    let f = |x: f64| {
        let r = (x * 1e12).round() / 1e12;
        if r == 0.0 { 0.0 } else { r }
    };
    DVec3::new(f(v.x), f(v.y), f(v.z))
}

/// Fills in `light` as a point light at `position` (the *Add light* form).
pub fn new_point_light(position: V3) -> LightFile {
    LightFile {
        kind: crate::scene::file::LightKind::Point,
        position: Some(position),
        direction: None,
        color: [1.0; 3],
        intensity: 300.0,
    }
}

#[cfg(test)]
mod tests;
