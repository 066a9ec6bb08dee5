//! The editing panel (egui): menus, *Add*, *Objects*, *Camera*, *Lens*,
//! *Light* and *Render* sections, the file dialog and the unsaved-changes
//! question.
//!
//! Every value the panel changes goes to `Document::edit_merged` (one undo
//! step per field gesture), which validates it with `Scene::build`. A value
//! that does not validate is kept as a *draft*: the fields show what was
//! typed, an error under them says why it is impossible, and the scene keeps
//! its last valid state until the draft becomes valid or is reverted.

use super::Viewer;
use egui::{Color32, RichText};
use glam::DVec3;
use lensview::color::blackbody;
use lensview::edit::document::{
    axis_angles, axis_from_angles, in_front_of_camera, new_lens, new_material, new_object, new_point_light,
    set_camera_pose, unique_key,
};
use lensview::edit::presets::PRESETS;
use lensview::edit::{Change, Item, Source};
use lensview::math::angles_looking_along;
use lensview::optics::{Index, ThickLens};
use lensview::scene::SceneFile;
use lensview::scene::file::{
    AmbientFile, IndexFile, LensFile, LightFile, LightKind, MaterialFile, ObjectFile, ShapeKind,
};
use std::any::Any;
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

/// Width of the panel in points (logical pixels), margins included.
pub const PANEL_WIDTH: f32 = 340.0;

const ERROR: Color32 = Color32::from_rgb(255, 110, 100);
const WARN: Color32 = Color32::from_rgb(255, 190, 90);

/// Something that would drop unsaved changes, waiting for an answer.
#[derive(Clone, Debug, PartialEq)]
pub enum Pending {
    Quit,
    Open(PathBuf),
    Preset(String),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DialogMode {
    Open,
    SaveAs,
}

/// The in-window file dialog (no system dialog: nothing beyond X11 needed).
pub struct FileDialog {
    mode: DialogMode,
    dir: PathBuf,
    dir_text: String,
    name: String,
    entries: Vec<(String, bool)>,
    pub error: Option<String>,
    /// A file that exists and was chosen once: choosing it again replaces it.
    overwrite: Option<PathBuf>,
}

impl FileDialog {
    fn new(mode: DialogMode, dir: PathBuf, name: String) -> Self {
        let mut d = FileDialog {
            mode,
            dir_text: dir.display().to_string(),
            dir,
            name,
            entries: Vec::new(),
            error: None,
            overwrite: None,
        };
        d.list();
        d
    }

    fn list(&mut self) {
        self.entries.clear();
        match std::fs::read_dir(&self.dir) {
            Ok(rd) => {
                for e in rd.flatten() {
                    let name = e.file_name().to_string_lossy().into_owned();
                    if name.starts_with('.') {
                        continue;
                    }
                    let is_dir = e.path().is_dir();
                    if is_dir || name.ends_with(".toml") {
                        self.entries.push((name, is_dir));
                    }
                }
                self.entries.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
                self.error = None;
            }
            Err(e) => self.error = Some(format!("cannot read the folder {}: {e}", self.dir.display())),
        }
    }

    fn enter(&mut self, dir: PathBuf) {
        self.dir = dir;
        self.dir_text = self.dir.display().to_string();
        self.overwrite = None;
        self.list();
    }

    /// The chosen path (`.toml` added when saving a name without extension).
    fn path(&self) -> Option<PathBuf> {
        let name = self.name.trim();
        if name.is_empty() {
            return None;
        }
        let mut p = self.dir.join(name);
        if self.mode == DialogMode::SaveAs && p.extension().is_none() {
            p.set_extension("toml");
        }
        Some(p)
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum AddKind {
    Cuboid,
    Prism,
    Sphere,
    Pyramid,
    Lens,
}

impl AddKind {
    const ALL: [AddKind; 5] = [
        AddKind::Cuboid,
        AddKind::Prism,
        AddKind::Sphere,
        AddKind::Pyramid,
        AddKind::Lens,
    ];
    fn name(self) -> &'static str {
        match self {
            AddKind::Cuboid => "cuboid",
            AddKind::Prism => "prism",
            AddKind::Sphere => "sphere",
            AddKind::Pyramid => "pyramid",
            AddKind::Lens => "lens",
        }
    }
    fn shape(self) -> Option<ShapeKind> {
        match self {
            AddKind::Cuboid => Some(ShapeKind::Cuboid),
            AddKind::Prism => Some(ShapeKind::Prism),
            AddKind::Sphere => Some(ShapeKind::Sphere),
            AddKind::Pyramid => Some(ShapeKind::Pyramid),
            AddKind::Lens => None,
        }
    }
}

/// The *Add* form: parameters kept per kind.
struct AddForm {
    kind: AddKind,
    size: [f64; 3],
    radius: f64,
    prism: [f64; 2],
    pyramid: [f64; 2],
    lens: [f64; 4],
    color: [f32; 3],
    in_front: bool,
    distance: f64,
    position: [f64; 3],
}

impl Default for AddForm {
    fn default() -> Self {
        AddForm {
            kind: AddKind::Sphere,
            size: [1.0; 3],
            radius: 0.5,
            prism: [1.0, 1.0],
            pyramid: [1.0, 1.0],
            lens: [2.0, 5.0, 5.0, 1.5],
            color: [0.8, 0.25, 0.15],
            in_front: true,
            distance: 6.0,
            position: [0.0, 0.5, 0.0],
        }
    }
}

type Drafts = HashMap<String, (Box<dyn Any>, String)>;

/// The panel's own state (not part of the scene).
pub struct UiState {
    pub selected: Option<Item>,
    add: AddForm,
    drafts: Drafts,
    drafts_rev: u64,
    lens: usize,
    open_lens: bool,
    light: usize,
    temperature: f64,
    pub file_dialog: Option<FileDialog>,
    pub confirm: Option<Pending>,
    /// What to do once *Save as* has succeeded (asked from the question).
    after_save: Option<Pending>,
    /// The last failure (open, save, reload, add), shown in red at the top.
    pub error: Option<String>,
    rects: BTreeMap<String, [f32; 4]>,
    rects_written: String,
    start_dir: PathBuf,
}

impl UiState {
    pub fn new(scene_path: Option<&Path>) -> Self {
        let start_dir = scene_path
            .and_then(Path::parent)
            .filter(|p| !p.as_os_str().is_empty())
            .map(Path::to_path_buf)
            .or_else(|| std::env::current_dir().ok())
            .unwrap_or_else(|| PathBuf::from("."));
        UiState {
            selected: None,
            add: AddForm::default(),
            drafts: HashMap::new(),
            drafts_rev: 0,
            lens: 0,
            open_lens: false,
            light: 0,
            temperature: 6500.0,
            file_dialog: None,
            confirm: None,
            after_save: None,
            error: None,
            rects: BTreeMap::new(),
            rects_written: String::new(),
            start_dir,
        }
    }

    pub fn reset_for_new_document(&mut self) {
        self.selected = None;
        self.drafts.clear();
        self.lens = 0;
        self.light = 0;
    }

    pub fn open_file_dialog(&mut self, mode: DialogMode, source: &Source) {
        let (dir, name) = match source.path() {
            Some(p) => (
                p.parent()
                    .filter(|d| !d.as_os_str().is_empty())
                    .map_or_else(|| self.start_dir.clone(), Path::to_path_buf),
                p.file_name()
                    .map_or(String::new(), |n| n.to_string_lossy().into_owned()),
            ),
            None => (
                self.start_dir.clone(),
                match source {
                    Source::Preset(n) => format!("{}.toml", n.replace(' ', "-")),
                    _ => "scene.toml".into(),
                },
            ),
        };
        let name = if mode == DialogMode::Open { String::new() } else { name };
        self.file_dialog = Some(FileDialog::new(mode, dir, name));
    }

    fn rect(&mut self, ui: &egui::Ui, name: &str, r: &egui::Response) {
        if ui.clip_rect().contains_rect(r.rect) {
            let s = ui.ctx().pixels_per_point();
            self.rects.insert(
                name.to_string(),
                [r.rect.min.x * s, r.rect.min.y * s, r.rect.max.x * s, r.rect.max.y * s],
            );
        }
    }

    /// Writes the rectangles of the named buttons (physical pixels, window
    /// coordinates) when they changed: `{"Add sphere": [x0, y0, x1, y1], …}`.
    pub fn write_rects(&mut self, path: Option<&Path>) {
        let Some(path) = path else { return };
        let text = serde_json::to_string(&self.rects).unwrap_or_default();
        if text != self.rects_written {
            let tmp = path.with_extension("tmp");
            if std::fs::write(&tmp, &text).is_ok() && std::fs::rename(&tmp, path).is_ok() {
                self.rects_written = text;
            }
        }
    }
}

/// Three drag values in a row; true when one changed.
fn vec3(ui: &mut egui::Ui, v: &mut [f64; 3], speed: f64) -> bool {
    ui.horizontal(|ui| {
        let mut changed = false;
        for (x, p) in v.iter_mut().zip(["x ", "y ", "z "]) {
            changed |= ui
                .add(egui::DragValue::new(x).speed(speed).max_decimals(4).prefix(p))
                .changed();
        }
        changed
    })
    .inner
}

/// A positive size in the *Add* form.
fn pos(x: &mut f64) -> egui::DragValue<'_> {
    egui::DragValue::new(x).speed(0.01).range(0.001..=1e6).max_decimals(4)
}

fn number(ui: &mut egui::Ui, x: &mut f64, speed: f64) -> bool {
    ui.add(egui::DragValue::new(x).speed(speed).max_decimals(6)).changed()
}

/// A colour picker (linear RGB, as in the scene file) and its numbers.
fn colour(ui: &mut egui::Ui, c: &mut [f64; 3]) -> bool {
    ui.horizontal(|ui| {
        let mut f = c.map(|x| x.clamp(0.0, 1.0) as f32);
        let mut changed = false;
        if ui.color_edit_button_rgb(&mut f).changed() {
            *c = f.map(|x| x as f64);
            changed = true;
        }
        for x in c.iter_mut() {
            changed |= ui.add(egui::DragValue::new(x).speed(0.01).max_decimals(3)).changed();
        }
        changed
    })
    .inner
}

fn index_ui(ui: &mut egui::Ui, n: &mut IndexFile) {
    ui.horizontal(|ui| {
        let cauchy = matches!(n, IndexFile::Cauchy(_));
        if ui.radio(!cauchy, "n").clicked() && cauchy {
            *n = IndexFile::Constant(to_index(*n).nominal());
        }
        if ui.radio(cauchy, "Cauchy A + B/λ²").clicked() && !cauchy {
            let IndexFile::Constant(v) = *n else { return };
            *n = IndexFile::Cauchy([v - 0.0042 / 0.5875618f64.powi(2), 0.0042]);
        }
    });
    match n {
        IndexFile::Constant(v) => {
            ui.add(egui::DragValue::new(v).speed(0.002).max_decimals(5).prefix("n "));
        }
        IndexFile::Cauchy([a, b]) => {
            ui.horizontal(|ui| {
                ui.add(egui::DragValue::new(a).speed(0.002).max_decimals(5).prefix("A "));
                ui.add(egui::DragValue::new(b).speed(0.0002).max_decimals(6).prefix("B "))
                    .on_hover_text("µm²");
            });
        }
    }
}

fn to_index(n: IndexFile) -> Index {
    match n {
        IndexFile::Constant(v) => Index::Constant(v),
        IndexFile::Cauchy([a, b]) => Index::Cauchy { a, b },
    }
}

/// The paraxial data of a lens as typed, or why there are none.
fn paraxial(l: &LensFile) -> Result<ThickLens, &'static str> {
    let n = to_index(l.n).nominal();
    // Written so that a NaN fails every test.
    if l.d.is_nan() || l.d <= 0.0 || l.d.is_infinite() {
        Err("d must be positive")
    } else if l.r1.is_nan() || l.r2.is_nan() || l.r1 < 0.5 * l.d || l.r2 < 0.5 * l.d {
        Err("r1 and r2 must be at least d/2")
    } else if n.is_nan() || n < 1.0 {
        Err("n must be at least 1")
    } else {
        Ok(ThickLens::new(l.d, l.r1, l.r2, n))
    }
}

impl Viewer {
    /// The whole UI pass: the panel (when shown), then the dialogs.
    pub(super) fn ui(&mut self, ui: &mut egui::Ui) {
        self.ui.rects.clear();
        if self.ui.drafts_rev != self.doc.revision() {
            self.ui.drafts.clear();
            self.ui.drafts_rev = self.doc.revision();
        }
        if let Some(item) = self.ui.selected
            && !self.doc.contains(item)
        {
            self.ui.selected = None;
        }
        if self.panel {
            let r = egui::Panel::left("lensview-panel")
                .exact_size(PANEL_WIDTH)
                .resizable(false)
                .show(ui, |ui| {
                    self.menu_bar(ui);
                    self.status(ui);
                    ui.separator();
                    egui::ScrollArea::vertical().auto_shrink([false, false]).show(ui, |ui| {
                        self.add_section(ui);
                        self.objects_section(ui);
                        self.camera_section(ui);
                        self.lens_section(ui);
                        self.light_section(ui);
                        self.render_section(ui);
                    });
                });
            let s = ui.ctx().pixels_per_point();
            let rr = r.response.rect;
            self.ui
                .rects
                .insert("panel".into(), [rr.min.x * s, rr.min.y * s, rr.max.x * s, rr.max.y * s]);
        }
        let ctx = ui.ctx().clone();
        self.file_dialog_ui(&ctx);
        self.confirm_ui(&ctx);
    }

    /// Shows `current` (or the pending draft) through `widgets`; a change is
    /// applied with `apply` as one merged undo step, or kept as a draft with
    /// its error. Returns the value shown.
    fn drafted<T: Clone + PartialEq + 'static>(
        &mut self,
        ui: &mut egui::Ui,
        key: &str,
        label: &str,
        current: T,
        widgets: impl FnOnce(&mut egui::Ui, &mut T),
        apply: impl FnOnce(&mut SceneFile, T),
    ) -> T {
        let mut v = self
            .ui
            .drafts
            .get(key)
            .and_then(|(b, _)| b.downcast_ref::<T>())
            .cloned()
            .unwrap_or(current);
        let before = v.clone();
        // A draft that does not validate is framed in red.
        let stroke = if self.ui.drafts.contains_key(key) {
            egui::Stroke::new(1.5, ERROR)
        } else {
            egui::Stroke::NONE
        };
        egui::Frame::new()
            .stroke(stroke)
            .inner_margin(2.0)
            .show(ui, |ui| widgets(ui, &mut v));
        if v != before {
            let value = v.clone();
            match self.doc.edit_merged(key, label, move |sf| apply(sf, value)) {
                Ok(c) => {
                    self.ui.drafts.remove(key);
                    self.ui.drafts_rev = self.doc.revision();
                    self.changed(c);
                }
                Err(e) => {
                    self.ui
                        .drafts
                        .insert(key.to_string(), (Box::new(v.clone()), e.to_string()));
                }
            }
        }
        if let Some((_, err)) = self.ui.drafts.get(key) {
            let err = err.clone();
            ui.horizontal_wrapped(|ui| {
                ui.colored_label(ERROR, format!("Not applied: {err}"));
                if ui.small_button("revert").clicked() {
                    self.ui.drafts.remove(key);
                }
            });
        }
        v
    }

    fn apply_result(&mut self, what: &str, r: Result<Change, lensview::edit::Rejected>) {
        match r {
            Ok(c) => {
                self.message = what.to_string();
                self.changed(c);
            }
            Err(e) => {
                self.message = format!("not applied: {e}");
                self.ui.error = Some(self.message.clone());
            }
        }
    }

    fn menu_bar(&mut self, ui: &mut egui::Ui) {
        use super::keys::{Action, label_of};
        egui::MenuBar::new().ui(ui, |ui| {
            ui.menu_button("File", |ui| {
                if ui
                    .add(egui::Button::new("Open…").shortcut_text(label_of(Action::Open)))
                    .clicked()
                {
                    self.ui.open_file_dialog(DialogMode::Open, self.doc.source());
                    ui.close();
                }
                if ui
                    .add(egui::Button::new("Save").shortcut_text(label_of(Action::Save)))
                    .clicked()
                {
                    self.save();
                    ui.close();
                }
                if ui
                    .add(egui::Button::new("Save as…").shortcut_text(label_of(Action::SaveAs)))
                    .clicked()
                {
                    self.ui.open_file_dialog(DialogMode::SaveAs, self.doc.source());
                    ui.close();
                }
                let has_file = self.doc.source().path().is_some();
                if ui
                    .add_enabled(
                        has_file,
                        egui::Button::new("Reload from disk").shortcut_text(label_of(Action::Reload)),
                    )
                    .on_hover_text("read the file again, keeping the camera (undoable)")
                    .clicked()
                {
                    self.reload();
                    ui.close();
                }
                ui.separator();
                if ui
                    .add(egui::Button::new("Quit").shortcut_text(label_of(Action::Quit)))
                    .clicked()
                {
                    self.perform(Pending::Quit, true);
                    ui.close();
                }
            });
            ui.menu_button("Edit", |ui| {
                let undo = self.doc.undo_label().map(|l| format!("Undo {l}"));
                if ui
                    .add_enabled(
                        undo.is_some(),
                        egui::Button::new(undo.unwrap_or_else(|| "Undo".into())).shortcut_text("Ctrl+Z"),
                    )
                    .clicked()
                {
                    self.undo();
                }
                let redo = self.doc.redo_label().map(|l| format!("Redo {l}"));
                if ui
                    .add_enabled(
                        redo.is_some(),
                        egui::Button::new(redo.unwrap_or_else(|| "Redo".into())).shortcut_text("Ctrl+Shift+Z"),
                    )
                    .clicked()
                {
                    self.redo();
                }
            });
            ui.menu_button("View", |ui| {
                ui.checkbox(&mut self.overlay, "Overlay (F1)");
                ui.checkbox(&mut self.help, "Key help (F2)");
                if ui
                    .add(egui::Button::new("Hide this panel").shortcut_text(label_of(Action::TogglePanel)))
                    .clicked()
                {
                    self.set_panel(false);
                    ui.close();
                }
                if ui
                    .add(egui::Button::new("Reset the view").shortcut_text(label_of(Action::ResetView)))
                    .clicked()
                {
                    self.press(Action::ResetView);
                }
                if ui
                    .add(egui::Button::new("Screenshot PNG").shortcut_text(label_of(Action::Screenshot)))
                    .clicked()
                {
                    self.screenshot();
                }
            });
            ui.menu_button("Presets", |ui| {
                for p in PRESETS {
                    if ui.button(p.name).on_hover_text(p.about).clicked() {
                        self.perform(Pending::Preset(p.name.to_string()), true);
                        ui.close();
                    }
                }
            });
        });
    }

    fn status(&mut self, ui: &mut egui::Ui) {
        ui.horizontal_wrapped(|ui| {
            ui.strong(self.doc.source().to_string());
            if self.doc.is_dirty() {
                ui.colored_label(WARN, "* unsaved changes");
            }
        });
        ui.horizontal(|ui| {
            let r = ui.add_enabled(self.doc.undo_label().is_some(), egui::Button::new("Undo"));
            let r = match self.doc.undo_label() {
                Some(l) => r.on_hover_text(format!("undo {l} (Ctrl+Z)")),
                None => r,
            };
            if r.clicked() {
                self.undo();
            }
            self.ui.rect(ui, "Undo", &r);
            let r = ui.add_enabled(self.doc.redo_label().is_some(), egui::Button::new("Redo"));
            if r.clicked() {
                self.redo();
            }
            let r = ui.button("Save").on_hover_text("Ctrl+S");
            if r.clicked() {
                self.save();
            }
            self.ui.rect(ui, "Save", &r);
            if ui.button("Open…").on_hover_text("Ctrl+O").clicked() {
                self.ui.open_file_dialog(DialogMode::Open, self.doc.source());
            }
            let pause = if self.paused { "Resume" } else { "Pause" };
            if ui.button(pause).on_hover_text("refinement (Space)").clicked() {
                self.toggle_pause();
            }
        });
        ui.label(RichText::new(format!("> {}", self.message)).small().weak());
        if let Some(e) = self.ui.error.clone() {
            ui.horizontal_wrapped(|ui| {
                ui.colored_label(ERROR, e);
                if ui.small_button("ok").clicked() {
                    self.ui.error = None;
                }
            });
        }
    }

    fn add_section(&mut self, ui: &mut egui::Ui) {
        let r = egui::CollapsingHeader::new("Add").default_open(true).show(ui, |ui| {
            ui.horizontal_wrapped(|ui| {
                for k in AddKind::ALL {
                    ui.selectable_value(&mut self.ui.add.kind, k, k.name());
                }
            });
            let f = &mut self.ui.add;
            egui::Grid::new("add-form").num_columns(2).show(ui, |ui| {
                match f.kind {
                    AddKind::Cuboid => {
                        ui.label("size");
                        ui.horizontal(|ui| {
                            for (x, p) in f.size.iter_mut().zip(["x ", "y ", "z "]) {
                                ui.add(pos(x).prefix(p));
                            }
                        });
                        ui.end_row();
                    }
                    AddKind::Sphere => {
                        ui.label("radius");
                        ui.add(pos(&mut f.radius));
                        ui.end_row();
                    }
                    AddKind::Prism | AddKind::Pyramid => {
                        let sh = if f.kind == AddKind::Prism {
                            &mut f.prism
                        } else {
                            &mut f.pyramid
                        };
                        ui.label("base side");
                        ui.add(pos(&mut sh[0]));
                        ui.end_row();
                        ui.label("height");
                        ui.add(pos(&mut sh[1]));
                        ui.end_row();
                    }
                    AddKind::Lens => {
                        for (i, name) in ["d", "r1", "r2", "n"].iter().enumerate() {
                            ui.label(*name);
                            ui.add(pos(&mut f.lens[i]));
                            ui.end_row();
                        }
                    }
                }
                if f.kind != AddKind::Lens {
                    ui.label("colour");
                    ui.color_edit_button_rgb(&mut f.color);
                    ui.end_row();
                }
                ui.label("where");
                ui.checkbox(&mut f.in_front, "in front of the camera");
                ui.end_row();
                if f.in_front {
                    ui.label("distance");
                    ui.add(pos(&mut f.distance));
                    ui.end_row();
                } else {
                    ui.label("position");
                    vec3(ui, &mut f.position, 0.05);
                    ui.end_row();
                }
            });
            let label = format!("Add {}", self.ui.add.kind.name());
            let r = ui.button(&label);
            self.ui.rect(ui, &label, &r);
            if r.clicked() {
                self.add_from_form();
            }
        });
        self.ui.rect(ui, "section Add", &r.header_response);
    }

    fn add_from_form(&mut self) {
        let f = &self.ui.add;
        let scene = self.doc.built().clone();
        let position = if f.in_front {
            in_front_of_camera(&scene, f.distance)
        } else {
            f.position
        };
        let result = match f.kind.shape() {
            Some(kind) => {
                let mut o = new_object(kind, position);
                match kind {
                    ShapeKind::Cuboid => o.size = Some(f.size),
                    ShapeKind::Sphere => o.radius = Some(f.radius),
                    ShapeKind::Prism => (o.side, o.height) = (Some(f.prism[0]), Some(f.prism[1])),
                    ShapeKind::Pyramid => (o.side, o.height) = (Some(f.pyramid[0]), Some(f.pyramid[1])),
                }
                let name = self.doc.unique_name(kind.name());
                o.name = Some(name.clone());
                let mat = new_material(f.color.map(|x| x as f64));
                self.doc.add_object(o, Some((name, mat)))
            }
            None => {
                // Facing the camera: S1 toward it.
                let axis = (-scene.camera.forward()).to_array();
                let mut l = new_lens(position, axis);
                (l.d, l.r1, l.r2, l.n) = (f.lens[0], f.lens[1], f.lens[2], IndexFile::Constant(f.lens[3]));
                self.doc.add_lens(l)
            }
        };
        match result {
            Ok(item) => {
                self.ui.selected = Some(item);
                if let Item::Lens(i) = item {
                    self.ui.lens = i;
                }
                let p = position;
                self.message = format!(
                    "added {} at ({:.2}, {:.2}, {:.2})",
                    self.doc.item_name(item),
                    p[0],
                    p[1],
                    p[2]
                );
                self.ui.error = None;
                self.changed(Change::Picture);
            }
            Err(e) => {
                self.message = format!("not added: {e}");
                self.ui.error = Some(self.message.clone());
            }
        }
    }

    fn objects_section(&mut self, ui: &mut egui::Ui) {
        let items = self.doc.items();
        let r = egui::CollapsingHeader::new(format!("Objects ({})", items.len()))
            .id_salt("objects")
            .default_open(true)
            .show(ui, |ui| {
                egui::ScrollArea::vertical()
                    .id_salt("object-list")
                    .max_height(150.0)
                    .auto_shrink([false, true])
                    .show(ui, |ui| {
                        for (item, name) in &items {
                            let kind = match item {
                                Item::Object(i) => self.doc.scene().objects[*i].kind.name(),
                                Item::Lens(_) => "lens",
                            };
                            let sel = self.ui.selected == Some(*item);
                            if ui.selectable_label(sel, format!("{name}   ({kind})")).clicked() {
                                self.ui.selected = if sel { None } else { Some(*item) };
                                if let Item::Lens(i) = item {
                                    self.ui.lens = *i;
                                    self.ui.open_lens = true;
                                }
                            }
                        }
                    });
                ui.separator();
                match self.ui.selected {
                    None => {
                        ui.weak("Select an object to edit, duplicate or delete it.");
                    }
                    Some(Item::Object(i)) => self.object_editor(ui, i),
                    Some(Item::Lens(i)) => {
                        ui.label(format!(
                            "{}: its shape and glass are under Lens.",
                            self.doc.item_name(Item::Lens(i))
                        ));
                    }
                }
                if self.ui.selected.is_some() {
                    ui.horizontal(|ui| {
                        if ui.button("Duplicate").on_hover_text("Ctrl+D").clicked() {
                            self.duplicate_selected();
                        }
                        if ui.button("Delete").on_hover_text("Delete key").clicked() {
                            self.delete_selected();
                        }
                    });
                }
            });
        self.ui.rect(ui, "section Objects", &r.header_response);
    }

    /// Duplicates the selected item and selects the copy (button, Ctrl+D).
    pub(super) fn duplicate_selected(&mut self) {
        let Some(item) = self.ui.selected else {
            self.message = "select an object first (Objects)".into();
            return;
        };
        match self.doc.duplicate(item) {
            Ok(Some(copy)) => {
                self.ui.selected = Some(copy);
                if let Item::Lens(i) = copy {
                    self.ui.lens = i;
                }
                self.message = format!("duplicated as {}", self.doc.item_name(copy));
                self.changed(Change::Picture);
            }
            Ok(None) => {}
            Err(e) => self.ui.error = Some(format!("not duplicated: {e}")),
        }
    }

    /// Deletes the selected item (button, Delete key); Ctrl+Z brings it back.
    pub(super) fn delete_selected(&mut self) {
        let Some(item) = self.ui.selected else {
            self.message = "select an object first (Objects)".into();
            return;
        };
        let name = self.doc.item_name(item);
        let r = self.doc.delete(item);
        self.ui.selected = None;
        self.apply_result(&format!("deleted {name} (Ctrl+Z undoes)"), r);
    }

    fn object_editor(&mut self, ui: &mut egui::Ui, i: usize) {
        let Some(current) = self.doc.scene().objects.get(i).cloned() else {
            return;
        };
        let materials: Vec<String> = self.doc.scene().materials.keys().cloned().collect();
        let name = self.doc.item_name(Item::Object(i));
        let key = format!("objects[{i}]");
        let shown = self.drafted(
            ui,
            &key,
            &format!("edit {name}"),
            current,
            |ui, o| {
                egui::Grid::new(("object", i)).num_columns(2).show(ui, |ui| {
                    ui.label("name");
                    let mut n = o.name.clone().unwrap_or_default();
                    if ui.text_edit_singleline(&mut n).changed() {
                        o.name = if n.trim().is_empty() { None } else { Some(n) };
                    }
                    ui.end_row();
                    ui.label("type");
                    ui.label(o.kind.name());
                    ui.end_row();
                    ui.label("position");
                    vec3(ui, &mut o.position, 0.02);
                    ui.end_row();
                    ui.label("rotation °");
                    vec3(ui, &mut o.rotation, 0.5);
                    ui.end_row();
                    match o.kind {
                        ShapeKind::Cuboid => {
                            ui.label("size");
                            let mut s = o.size.unwrap_or([1.0; 3]);
                            if vec3(ui, &mut s, 0.01) {
                                o.size = Some(s);
                            }
                            ui.end_row();
                        }
                        ShapeKind::Sphere => {
                            ui.label("radius");
                            let mut r = o.radius.unwrap_or(0.5);
                            if number(ui, &mut r, 0.01) {
                                o.radius = Some(r);
                            }
                            ui.end_row();
                        }
                        ShapeKind::Prism | ShapeKind::Pyramid => {
                            ui.label("base side");
                            let mut s = o.side.unwrap_or(1.0);
                            if number(ui, &mut s, 0.01) {
                                o.side = Some(s);
                            }
                            ui.end_row();
                            ui.label("height");
                            let mut h = o.height.unwrap_or(1.0);
                            if number(ui, &mut h, 0.01) {
                                o.height = Some(h);
                            }
                            ui.end_row();
                        }
                    }
                    ui.label("material");
                    let text = o.material.clone().unwrap_or_else(|| "built-in grey".into());
                    egui::ComboBox::from_id_salt(("material", i))
                        .selected_text(text)
                        .show_ui(ui, |ui| {
                            ui.selectable_value(&mut o.material, None, "built-in grey");
                            for m in &materials {
                                ui.selectable_value(&mut o.material, Some(m.clone()), m);
                            }
                        });
                    ui.end_row();
                });
            },
            move |sf, v| {
                if let Some(o) = sf.objects.get_mut(i) {
                    *o = v;
                }
            },
        );
        self.material_editor(ui, i, &shown);
    }

    fn material_editor(&mut self, ui: &mut egui::Ui, i: usize, o: &ObjectFile) {
        let obj_name = self.doc.item_name(Item::Object(i));
        match o.material.clone() {
            Some(m) if self.doc.scene().materials.contains_key(&m) => {
                let users = self
                    .doc
                    .scene()
                    .objects
                    .iter()
                    .filter(|x| x.material.as_ref() == Some(&m))
                    .count();
                let title = if users > 1 {
                    format!("Material {m} (shared by {users} objects)")
                } else {
                    format!("Material {m}")
                };
                egui::CollapsingHeader::new(title)
                    .id_salt(("material-editor", i))
                    .show(ui, |ui| {
                        let current = self.doc.scene().materials[&m].clone();
                        let key = format!("materials.{m}");
                        let mm = m.clone();
                        self.drafted(
                            ui,
                            &key,
                            &format!("edit material {m}"),
                            current,
                            |ui, mat: &mut MaterialFile| {
                                egui::Grid::new(("material-grid", i)).num_columns(2).show(ui, |ui| {
                                    ui.label("colour");
                                    colour(ui, &mut mat.color);
                                    ui.end_row();
                                    for (label, x, speed) in [
                                        ("ambient", &mut mat.ambient, 0.01),
                                        ("diffuse", &mut mat.diffuse, 0.01),
                                        ("specular", &mut mat.specular, 0.01),
                                        ("shininess", &mut mat.shininess, 0.5),
                                        ("reflectivity", &mut mat.reflectivity, 0.005),
                                        ("transparency", &mut mat.transparency, 0.005),
                                    ] {
                                        ui.label(label);
                                        number(ui, x, speed);
                                        ui.end_row();
                                    }
                                    ui.label("index (ior)");
                                    ui.vertical(|ui| index_ui(ui, &mut mat.ior));
                                    ui.end_row();
                                });
                            },
                            move |sf, v| {
                                sf.materials.insert(mm, v);
                            },
                        );
                        if users > 1 && ui.button("Give this object its own copy").clicked() {
                            let mat = self.doc.scene().materials[&m].clone();
                            let r = self.doc.edit("own material", |sf| {
                                let name = unique_key(&sf.materials, &obj_name);
                                sf.materials.insert(name.clone(), mat);
                                sf.objects[i].material = Some(name);
                            });
                            self.apply_result("the object has its own material now", r);
                        }
                    });
            }
            _ => {
                if ui.button("Give it a material of its own").clicked() {
                    let r = self.doc.edit("own material", |sf| {
                        let name = unique_key(&sf.materials, &obj_name);
                        sf.materials.insert(name.clone(), MaterialFile::default());
                        sf.objects[i].material = Some(name);
                    });
                    self.apply_result("the object has its own material now", r);
                }
            }
        }
    }

    fn camera_section(&mut self, ui: &mut egui::Ui) {
        let r = egui::CollapsingHeader::new("Camera").show(ui, |ui| {
            let (p, r) = self.doc.camera_pose();
            let current = (p.to_array(), r.to_array(), self.doc.scene().camera.fov);
            self.drafted(
                ui,
                "camera",
                "edit the camera",
                current,
                |ui, (pos, rot, fov)| {
                    egui::Grid::new("camera-grid").num_columns(2).show(ui, |ui| {
                        ui.label("position");
                        vec3(ui, pos, 0.02);
                        ui.end_row();
                        ui.label("rotation °");
                        vec3(ui, rot, 0.5);
                        ui.end_row();
                        ui.label("field of view °");
                        ui.add(egui::DragValue::new(fov).speed(0.2).max_decimals(3));
                        ui.end_row();
                    });
                },
                |sf, (pos, rot, fov)| {
                    set_camera_pose(sf, DVec3::from(pos), DVec3::from(rot));
                    sf.camera.fov = fov;
                },
            );
            ui.horizontal(|ui| {
                ui.label("movement speed");
                ui.add(
                    egui::DragValue::new(&mut self.speed)
                        .speed(0.05)
                        .range(0.05..=500.0)
                        .max_decimals(2),
                )
                .on_hover_text("units per second (mouse wheel over the picture; Shift flies 4× faster)");
            });
            ui.horizontal(|ui| {
                if ui.button("Reset the view").on_hover_text("R").clicked() {
                    self.press(super::keys::Action::ResetView);
                }
                let lens = self.doc.scene().lenses.get(self.ui.lens).map(|l| DVec3::from(l.center));
                if ui
                    .add_enabled(lens.is_some(), egui::Button::new("Look at the lens"))
                    .clicked()
                    && let Some(c) = lens
                {
                    let pos = self.doc.camera_pose().0;
                    if (c - pos).length() > 0.0 {
                        let rot = angles_looking_along(c - pos);
                        let r = self.doc.edit("look at the lens", |sf| set_camera_pose(sf, pos, rot));
                        self.apply_result("looking at the lens", r);
                    }
                }
            });
        });
        self.ui.rect(ui, "section Camera", &r.header_response);
    }

    fn lens_section(&mut self, ui: &mut egui::Ui) {
        let open = std::mem::take(&mut self.ui.open_lens).then_some(true);
        let r = egui::CollapsingHeader::new("Lens").open(open).show(ui, |ui| {
            let count = self.doc.scene().lenses.len();
            if count == 0 {
                ui.weak("No lens in this scene: Add → lens puts one in front of the camera.");
                return;
            }
            self.ui.lens = self.ui.lens.min(count - 1);
            if count > 1 {
                let names: Vec<String> = (0..count).map(|i| self.doc.item_name(Item::Lens(i))).collect();
                egui::ComboBox::from_id_salt("lens-choice")
                    .selected_text(names[self.ui.lens].clone())
                    .show_ui(ui, |ui| {
                        for (i, n) in names.iter().enumerate() {
                            ui.selectable_value(&mut self.ui.lens, i, n);
                        }
                    });
            }
            let i = self.ui.lens;
            let current = self.doc.scene().lenses[i].clone();
            let name = self.doc.item_name(Item::Lens(i));
            let shown = self.drafted(
                ui,
                &format!("lenses[{i}]"),
                &format!("edit {name}"),
                current,
                |ui, l: &mut LensFile| {
                    egui::Grid::new(("lens-grid", i)).num_columns(2).show(ui, |ui| {
                        ui.label("name");
                        let mut n = l.name.clone().unwrap_or_default();
                        if ui.text_edit_singleline(&mut n).changed() {
                            l.name = if n.trim().is_empty() { None } else { Some(n) };
                        }
                        ui.end_row();
                        ui.label("centre");
                        vec3(ui, &mut l.center, 0.01);
                        ui.end_row();
                        ui.label("orientation");
                        let (mut yaw, mut pitch) = axis_angles(l.axis);
                        let changed = ui
                            .horizontal(|ui| {
                                let a =
                                    ui.add(egui::DragValue::new(&mut yaw).speed(0.5).max_decimals(2).prefix("yaw "));
                                let b = ui.add(
                                    egui::DragValue::new(&mut pitch)
                                        .speed(0.5)
                                        .range(-90.0..=90.0)
                                        .max_decimals(2)
                                        .prefix("pitch "),
                                );
                                a.changed() || b.changed()
                            })
                            .inner;
                        if changed {
                            l.axis = axis_from_angles(yaw, pitch);
                        }
                        ui.end_row();
                        ui.label("axis");
                        vec3(ui, &mut l.axis, 0.01);
                        ui.end_row();
                        for (label, x, hover) in [
                            ("d", &mut l.d, "diameter"),
                            ("r1", &mut l.r1, "radius of S1 (faces +axis), at least d/2"),
                            ("r2", &mut l.r2, "radius of S2 (faces −axis), at least d/2"),
                        ] {
                            ui.label(label).on_hover_text(hover);
                            number(ui, x, 0.01);
                            ui.end_row();
                        }
                        ui.label("index");
                        ui.vertical(|ui| index_ui(ui, &mut l.n));
                        ui.end_row();
                        ui.label("tint");
                        colour(ui, &mut l.tint);
                        ui.end_row();
                    });
                },
                move |sf, v| {
                    if let Some(l) = sf.lenses.get_mut(i) {
                        *l = v;
                    }
                },
            );
            match paraxial(&shown) {
                Ok(p) => {
                    egui::Grid::new(("lens-readout", i)).num_columns(2).show(ui, |ui| {
                        for (k, v) in [
                            ("thickness", p.thickness),
                            ("EFL", p.efl),
                            ("BFD", p.bfd),
                            ("FFD", p.ffd),
                        ] {
                            ui.label(k);
                            ui.monospace(format!("{v:.6}"));
                            ui.end_row();
                        }
                    });
                    ui.weak(format!("paraxial, at n = {:.5} (d line)", p.n));
                }
                Err(why) => {
                    ui.colored_label(ERROR, format!("Impossible lens: {why}."));
                }
            }
            ui.horizontal(|ui| {
                let (pos, _) = self.doc.camera_pose();
                if ui.button("Point at the camera").clicked() {
                    let c = DVec3::from(shown.center);
                    if (pos - c).length() > 0.0 {
                        let a = (pos - c).normalize().to_array();
                        let r = self
                            .doc
                            .edit("point the lens at the camera", |sf| sf.lenses[i].axis = a);
                        self.apply_result("the lens faces the camera", r);
                    }
                }
                if ui.button("Put in front of the camera").clicked() {
                    let f = self.doc.built().camera.forward();
                    let (c, a) = ((pos + f * 3.5).to_array(), (-f).to_array());
                    let r = self.doc.edit("put the lens in front of the camera", |sf| {
                        sf.lenses[i].center = c;
                        sf.lenses[i].axis = a;
                    });
                    self.apply_result("the lens is 3.5 in front of the camera", r);
                }
            });
        });
        self.ui.rect(ui, "section Lens", &r.header_response);
    }

    fn light_section(&mut self, ui: &mut egui::Ui) {
        let r = egui::CollapsingHeader::new("Light").show(ui, |ui| {
            let count = self.doc.scene().lights.len();
            ui.horizontal(|ui| {
                if count > 1 {
                    let kinds: Vec<String> = self
                        .doc
                        .scene()
                        .lights
                        .iter()
                        .enumerate()
                        .map(|(k, l)| format!("light {} ({})", k + 1, kind_name(l.kind)))
                        .collect();
                    self.ui.light = self.ui.light.min(count - 1);
                    egui::ComboBox::from_id_salt("light-choice")
                        .selected_text(kinds[self.ui.light].clone())
                        .show_ui(ui, |ui| {
                            for (k, n) in kinds.iter().enumerate() {
                                ui.selectable_value(&mut self.ui.light, k, n);
                            }
                        });
                }
                if ui.button("Add a point light").clicked() {
                    let p = (self.doc.camera_pose().0 + DVec3::Y * 2.0).to_array();
                    let r = self.doc.edit("add a light", |sf| sf.lights.push(new_point_light(p)));
                    self.ui.light = count;
                    self.apply_result("added a point light above the camera", r);
                }
                if count > 0 && ui.button("Delete").clicked() {
                    let k = self.ui.light.min(count - 1);
                    let r = self.doc.edit("delete a light", |sf| {
                        sf.lights.remove(k);
                    });
                    self.ui.light = 0;
                    self.apply_result("deleted the light (Ctrl+Z undoes)", r);
                }
            });
            let count = self.doc.scene().lights.len();
            if count == 0 {
                ui.weak("No light: only the ambient level lights the scene.");
            } else {
                let k = self.ui.light.min(count - 1);
                self.ui.light = k;
                let current = self.doc.scene().lights[k].clone();
                self.drafted(
                    ui,
                    &format!("lights[{k}]"),
                    "edit the light",
                    current,
                    |ui, l: &mut LightFile| {
                        egui::Grid::new(("light-grid", k)).num_columns(2).show(ui, |ui| {
                            ui.label("type");
                            ui.horizontal(|ui| {
                                if ui.radio(l.kind == LightKind::Point, "point").clicked() && l.kind != LightKind::Point
                                {
                                    l.kind = LightKind::Point;
                                    l.position = Some([0.0, 8.0, 4.0]);
                                    l.direction = None;
                                }
                                if ui.radio(l.kind == LightKind::Directional, "directional").clicked()
                                    && l.kind != LightKind::Directional
                                {
                                    l.kind = LightKind::Directional;
                                    l.direction = Some([0.3, -1.0, -0.4]);
                                    l.position = None;
                                    l.intensity = 1.0;
                                }
                            });
                            ui.end_row();
                            if l.kind == LightKind::Point {
                                ui.label("position");
                                let mut p = l.position.unwrap_or_default();
                                if vec3(ui, &mut p, 0.05) {
                                    l.position = Some(p);
                                }
                            } else {
                                ui.label("direction");
                                let mut d = l.direction.unwrap_or([0.0, -1.0, 0.0]);
                                if vec3(ui, &mut d, 0.01) {
                                    l.direction = Some(d);
                                }
                            }
                            ui.end_row();
                            ui.label("intensity").on_hover_text(if l.kind == LightKind::Point {
                                "power Φ: a surface r away receives Φ·cosθ/(4πr²)"
                            } else {
                                "irradiance at normal incidence"
                            });
                            let speed = (l.intensity.abs() * 0.005).max(0.01);
                            number(ui, &mut l.intensity, speed);
                            ui.end_row();
                            ui.label("colour");
                            colour(ui, &mut l.color);
                            ui.end_row();
                        });
                    },
                    move |sf, v| {
                        if let Some(l) = sf.lights.get_mut(k) {
                            *l = v;
                        }
                    },
                );
                ui.horizontal(|ui| {
                    ui.label("colour temperature");
                    let r = ui.add(
                        egui::Slider::new(&mut self.ui.temperature, 1000.0..=12000.0)
                            .suffix(" K")
                            .step_by(50.0),
                    );
                    if r.changed() {
                        let c = blackbody(self.ui.temperature).to_array();
                        let t = self.ui.temperature;
                        let r = self
                            .doc
                            .edit_merged(&format!("lights[{k}].temperature"), "light colour", |sf| {
                                sf.lights[k].color = c
                            });
                        self.apply_result(&format!("light colour: black body {t:.0} K"), r);
                    }
                });
            }
            ui.separator();
            let current = self.doc.scene().ambient.clone();
            self.drafted(
                ui,
                "ambient",
                "edit the ambient light",
                current,
                |ui, a: &mut AmbientFile| {
                    egui::Grid::new("ambient-grid").num_columns(2).show(ui, |ui| {
                        ui.label("ambient level");
                        number(ui, &mut a.intensity, 0.002);
                        ui.end_row();
                        ui.label("ambient colour");
                        colour(ui, &mut a.color);
                        ui.end_row();
                    });
                },
                |sf, v| sf.ambient = v,
            );
            let mut shadows = self.doc.scene().render.shadows;
            if ui.checkbox(&mut shadows, "shadows").changed() {
                let r = self.doc.edit("shadows on/off", |sf| sf.render.shadows = shadows);
                self.apply_result(if shadows { "shadows on" } else { "shadows off" }, r);
            }
        });
        self.ui.rect(ui, "section Light", &r.header_response);
    }

    fn render_section(&mut self, ui: &mut egui::Ui) {
        let r = egui::CollapsingHeader::new("Render").show(ui, |ui| {
            egui::Grid::new("render-grid").num_columns(2).show(ui, |ui| {
                ui.label("resolution");
                let mut div = self.res_div;
                egui::ComboBox::from_id_salt("resolution")
                    .selected_text(format!("{}%", 100 / div))
                    .show_ui(ui, |ui| {
                        for d in [1, 2, 3, 4] {
                            ui.selectable_value(&mut div, d, format!("{}%", 100 / d));
                        }
                    });
                if div != self.res_div {
                    self.set_resolution_divisor(div);
                }
                ui.end_row();
                ui.label("sample cap");
                let mut cap = self.max_spp;
                egui::ComboBox::from_id_salt("sample-cap")
                    .selected_text(format!("{cap} per pixel"))
                    .show_ui(ui, |ui| {
                        for k in 0..=12 {
                            ui.selectable_value(&mut cap, 1 << k, format!("{} per pixel", 1 << k));
                        }
                    });
                if cap != self.max_spp {
                    self.set_max_spp(cap);
                }
                ui.end_row();
            });
            let depth = self.doc.scene().render.max_depth;
            self.drafted(
                ui,
                "render.max_depth",
                "max depth",
                depth,
                |ui, d: &mut u32| {
                    ui.horizontal(|ui| {
                        ui.label("max depth");
                        ui.add(egui::DragValue::new(d).speed(0.1))
                            .on_hover_text("longest chain of reflections and refractions (0–64)");
                    });
                },
                |sf, d| sf.render.max_depth = d,
            );
            let bg = self.doc.scene().render.background;
            self.drafted(
                ui,
                "render.background",
                "background",
                bg,
                |ui, c: &mut [f64; 3]| {
                    ui.horizontal(|ui| {
                        ui.label("background");
                        colour(ui, c);
                    });
                },
                |sf, c| sf.render.background = c,
            );
            ui.horizontal(|ui| {
                let label = if self.paused {
                    "Resume refinement"
                } else {
                    "Pause refinement"
                };
                if ui.button(label).on_hover_text("Space").clicked() {
                    self.toggle_pause();
                }
            });
            if let Some(f) = &self.frame {
                ui.weak(format!(
                    "{}{}{}: {}×{}, {:.0} ms, {:.2} M samples/s",
                    f.stage.label(),
                    if f.last { " (done)" } else { "" },
                    if self.paused { " (paused)" } else { "" },
                    f.width,
                    f.height,
                    f.render_ms,
                    f.samples_per_s / 1e6
                ));
            }
        });
        self.ui.rect(ui, "section Render", &r.header_response);
    }

    fn file_dialog_ui(&mut self, ctx: &egui::Context) {
        let Some(mut d) = self.ui.file_dialog.take() else {
            return;
        };
        let title = match d.mode {
            DialogMode::Open => "Open a scene",
            DialogMode::SaveAs => "Save the scene as",
        };
        let mut keep = true;
        let mut chosen: Option<PathBuf> = None;
        egui::Window::new(title)
            .collapsible(false)
            .resizable(true)
            .default_width(480.0)
            .anchor(egui::Align2::CENTER_CENTER, [0.0, 0.0])
            .show(ctx, |ui| {
                ui.horizontal(|ui| {
                    ui.label("folder");
                    let r = ui.add(egui::TextEdit::singleline(&mut d.dir_text).desired_width(300.0));
                    if r.lost_focus() {
                        let p = PathBuf::from(d.dir_text.trim());
                        if p.is_dir() {
                            d.enter(p);
                        } else {
                            d.error = Some(format!("{} is not a folder", p.display()));
                        }
                    }
                    if ui.button("up").clicked()
                        && let Some(parent) = d
                            .dir
                            .canonicalize()
                            .ok()
                            .and_then(|p| p.parent().map(Path::to_path_buf))
                    {
                        d.enter(parent);
                    }
                });
                egui::ScrollArea::vertical()
                    .id_salt("file-list")
                    .max_height(220.0)
                    .auto_shrink([false, true])
                    .show(ui, |ui| {
                        let entries = d.entries.clone();
                        for (name, is_dir) in entries {
                            if is_dir {
                                if ui.selectable_label(false, format!("📁 {name}/")).clicked() {
                                    d.enter(d.dir.join(&name));
                                }
                            } else {
                                let r = ui.selectable_label(d.name == name, &name);
                                if r.clicked() {
                                    d.name = name.clone();
                                    d.overwrite = None;
                                }
                                if r.double_clicked() {
                                    chosen = d.path();
                                }
                            }
                        }
                        if d.entries.is_empty() {
                            ui.weak("(no folders or .toml files here)");
                        }
                    });
                ui.horizontal(|ui| {
                    ui.label("file");
                    let r = ui.add(egui::TextEdit::singleline(&mut d.name).desired_width(300.0));
                    if r.changed() {
                        d.overwrite = None;
                    }
                    if r.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter)) {
                        chosen = d.path();
                    }
                });
                if let Some(e) = &d.error {
                    ui.colored_label(ERROR, e);
                }
                if let Some(p) = &d.overwrite {
                    ui.colored_label(WARN, format!("{} exists: Save again replaces it.", p.display()));
                }
                ui.horizontal(|ui| {
                    let ok = match d.mode {
                        DialogMode::Open => "Open",
                        DialogMode::SaveAs => "Save",
                    };
                    let r = ui.add_enabled(!d.name.trim().is_empty(), egui::Button::new(ok));
                    self.ui.rect(ui, &format!("dialog {ok}"), &r);
                    if r.clicked() {
                        chosen = d.path();
                    }
                    if ui.button("Cancel").clicked() {
                        keep = false;
                    }
                });
            });
        if let Some(path) = chosen {
            match d.mode {
                DialogMode::Open => {
                    self.ui.file_dialog = Some(d);
                    self.perform(Pending::Open(path), true);
                    // A failed open keeps the dialog and shows why in it.
                    if let (Some(d), Some(e)) = (&mut self.ui.file_dialog, &self.ui.error) {
                        d.error = Some(e.clone());
                    }
                    return;
                }
                DialogMode::SaveAs => {
                    if path.exists() && d.overwrite.as_ref() != Some(&path) {
                        d.overwrite = Some(path);
                    } else {
                        match self.save_as(&path) {
                            Ok(()) => {
                                if let Some(p) = self.ui.after_save.take() {
                                    self.perform(p, false);
                                }
                                return;
                            }
                            Err(e) => d.error = Some(format!("not saved: {e}")),
                        }
                    }
                }
            }
        }
        if keep {
            self.ui.file_dialog = Some(d);
        } else {
            self.ui.after_save = None;
        }
    }

    fn confirm_ui(&mut self, ctx: &egui::Context) {
        let Some(p) = self.ui.confirm.clone() else { return };
        let (what, go) = match &p {
            Pending::Quit => ("Quit anyway?".to_string(), "Quit without saving (D)"),
            Pending::Open(path) => (format!("Open {} anyway?", path.display()), "Discard and open (D)"),
            Pending::Preset(n) => (format!("Open the preset {n} anyway?"), "Discard and open (D)"),
        };
        let save = if self.doc.source().path().is_some() {
            "Save first (S)"
        } else {
            "Save as… (S)"
        };
        egui::Modal::new(egui::Id::new("unsaved-changes")).show(ctx, |ui| {
            ui.set_max_width(440.0);
            ui.heading("Unsaved changes");
            ui.label(format!("{} has changes that are not saved. {what}", self.doc.source()));
            ui.add_space(8.0);
            ui.horizontal(|ui| {
                for (label, name, answer) in [
                    (save, "confirm save", Answer::Save),
                    (go, "confirm discard", Answer::Discard),
                    ("Cancel (Esc)", "confirm cancel", Answer::Cancel),
                ] {
                    let r = ui.button(label);
                    self.ui.rect(ui, name, &r);
                    if r.clicked() {
                        self.answer(answer);
                    }
                }
            });
        });
    }

    /// Answers the unsaved-changes question (buttons, or keys S, D, Esc).
    pub(super) fn answer(&mut self, a: Answer) {
        let Some(p) = self.ui.confirm.clone() else { return };
        match a {
            Answer::Save => {
                if self.doc.source().path().is_some() {
                    if self.save() {
                        self.perform(p, false);
                    }
                } else {
                    self.ui.after_save = Some(p);
                    self.ui.confirm = None;
                    self.ui.open_file_dialog(DialogMode::SaveAs, self.doc.source());
                }
            }
            Answer::Discard => self.perform(p, false),
            Answer::Cancel => {
                self.ui.confirm = None;
                self.message = "cancelled".into();
            }
        }
        self.request_redraw();
    }
}

/// An answer to the unsaved-changes question.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Answer {
    Save,
    Discard,
    Cancel,
}

fn kind_name(k: LightKind) -> &'static str {
    match k {
        LightKind::Point => "point",
        LightKind::Directional => "directional",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_lens_readout_is_the_paraxial_data_or_says_why_not() {
        let mut l = new_lens([0.0; 3], [0.0, 0.0, 1.0]);
        let p = paraxial(&l).unwrap();
        assert!((p.efl - 5.03390182).abs() < 1e-7 && (p.thickness - 0.202041029).abs() < 1e-8);
        l.r1 = 0.5;
        assert_eq!(paraxial(&l).unwrap_err(), "r1 and r2 must be at least d/2");
        l.r1 = 5.0;
        l.n = IndexFile::Constant(0.9);
        assert!(paraxial(&l).is_err());
        l.n = IndexFile::Cauchy([1.5046, 0.0042]);
        assert!((paraxial(&l).unwrap().efl - 4.87131316).abs() < 1e-7);
        l.d = f64::NAN;
        assert!(paraxial(&l).is_err());
    }

    #[test]
    fn the_file_dialog_lists_folders_then_scenes_and_adds_toml_when_saving() {
        let dir = std::env::temp_dir().join(format!("lensview-dialog-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        for f in ["b.toml", "a.toml", "notes.txt", ".hidden.toml"] {
            std::fs::write(dir.join(f), "").unwrap();
        }
        let mut d = FileDialog::new(DialogMode::SaveAs, dir.clone(), "scene".into());
        let names: Vec<&str> = d.entries.iter().map(|e| e.0.as_str()).collect();
        assert_eq!(names, ["sub", "a.toml", "b.toml"]);
        assert!(d.error.is_none());
        assert_eq!(d.path(), Some(dir.join("scene.toml")));
        d.mode = DialogMode::Open;
        assert_eq!(d.path(), Some(dir.join("scene")));
        d.name = "  ".into();
        assert_eq!(d.path(), None);
        d.enter(dir.join("no-such-folder"));
        assert!(d.error.as_deref().unwrap_or("").contains("cannot read the folder"));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
