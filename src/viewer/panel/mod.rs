//! The editing panel (egui): the menu bar and status lines (`menu`), the
//! sections *Add* (`add`), *Objects* (`objects`, with the material
//! editor in `material`), *Camera* (`camera`), *Lens* (`lens`),
//! *System* (`system`: the selected lens system), *Light* (`light`) and *Render* (`render`), the file dialog
//! (`file_dialog`) and the unsaved-changes question (`confirm`).
//!
//! A section gets a [`Ctx`]: the editing session (document, the panel's
//! state in [`UiState`], the message line) and the few display settings it
//! shows — never the window. Scene changes are `Document` methods; what
//! only the window can do (pause, resize, quit) is asked for with a
//! `Command`.
//!
//! Every value the panel changes goes through a merged `Document` edit
//! (one undo step per field gesture), validated with `Scene::build`. A value
//! that does not validate is kept as a *draft* ([`drafted`]): the fields
//! show what was typed, an error under them says why it is impossible, and
//! the scene keeps its last valid state until the draft becomes valid or is
//! reverted.

mod add;
mod analysis;
mod camera;
mod camera_lens;
mod confirm;
mod file_dialog;
mod lens;
mod light;
mod material;
mod menu;
mod objects;
mod plots;
mod render;
mod system;
mod system_analysis;
mod widgets;

pub use analysis::AnalysisState;
pub use confirm::{Answer, Pending};
pub use file_dialog::{DialogMode, FileDialog};

use super::screen::{Display, PanelShape};
use super::session::Command;
use super::session::Session;
use egui::Color32;
use lensview::edit::{Change, Document, Item, Rejected, Source};
use lensview::render::worker::Frame;
use std::any::Any;
use std::collections::{BTreeMap, HashMap};
use std::ops::{Deref, DerefMut};
use std::path::{Path, PathBuf};

/// Width of the panel in points (logical pixels), margins included.
pub const PANEL_WIDTH: f32 = 340.0;
/// Below this window width (points) the panel collapses to a strip, so the
/// picture keeps most of the width.
pub const NARROW: f32 = 900.0;
/// Width of the collapsed panel: the button that opens it.
pub const STRIP_WIDTH: f32 = 30.0;

const ERROR: Color32 = Color32::from_rgb(255, 110, 100);
const WARN: Color32 = Color32::from_rgb(255, 190, 90);

/// What a section may touch: the editing session (through `Deref`: `cx.doc`,
/// `cx.ui`, `cx.message`), the display switches, the flight speed, and
/// what the render thread is doing (read only).
pub struct Ctx<'a> {
    pub session: &'a mut Session,
    pub display: &'a mut Display,
    pub speed: &'a mut f64,
    pub render: RenderState<'a>,
}

/// The refinement as the *Render* section shows it.
#[derive(Clone, Copy)]
pub struct RenderState<'a> {
    pub paused: bool,
    pub max_spp: u32,
    pub frame: Option<&'a Frame>,
}

impl Deref for Ctx<'_> {
    type Target = Session;
    fn deref(&self) -> &Session {
        self.session
    }
}

impl DerefMut for Ctx<'_> {
    fn deref_mut(&mut self) -> &mut Session {
        self.session
    }
}

/// Values typed that did not validate, by field key, with the reason; all
/// are forgotten when the document changes by other means (undo, a key).
#[derive(Default)]
struct Drafts {
    values: HashMap<String, (Box<dyn Any>, String)>,
    /// The document revision the drafts were made against.
    revision: u64,
}

/// Screen rectangles of the named buttons, for scripted tests (`--ui-log`).
#[derive(Default)]
struct Rects {
    rects: BTreeMap<String, [f32; 4]>,
    written: String,
}

impl Rects {
    fn insert(&mut self, name: &str, r: egui::Rect, pixels_per_point: f32) {
        let s = pixels_per_point;
        self.rects
            .insert(name.to_string(), [r.min.x * s, r.min.y * s, r.max.x * s, r.max.y * s]);
    }
}

/// The panel's own state (not part of the scene).
pub struct UiState {
    pub selected: Option<Item>,
    add: add::AddForm,
    drafts: Drafts,
    /// The lens the *Lens* section shows, and whether to open it.
    pub lens: usize,
    open_lens: bool,
    /// Whether to open the *System* section (a system was selected).
    open_system: bool,
    /// Whether to open the *Light* section (a light was picked).
    open_light: bool,
    /// The section opened last (by its header or a pick): the others are
    /// closed ([`section`]).
    opened: Option<&'static str>,
    /// The light the *Light* section shows.
    light: usize,
    /// The last black-body colour chosen (slider, or the , and . keys).
    pub temperature: f64,
    /// The last light-colour preset the T key chose.
    pub preset: usize,
    pub file_dialog: Option<FileDialog>,
    pub confirm: Option<Pending>,
    /// What to do once *Save as* has succeeded (asked from the question).
    pub after_save: Option<Pending>,
    /// The last failure (open, save, reload, add), shown in red at the top.
    pub error: Option<String>,
    rects: Rects,
    start_dir: PathBuf,
    /// The optics overlay and analysis window (`analysis`).
    pub analysis: AnalysisState,
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
            add: add::AddForm::default(),
            drafts: Drafts::default(),
            lens: 0,
            open_lens: false,
            open_light: false,
            open_system: false,
            opened: None,
            light: 0,
            temperature: 6500.0,
            preset: 0,
            file_dialog: None,
            confirm: None,
            after_save: None,
            error: None,
            rects: Rects::default(),
            start_dir,
            analysis: AnalysisState::default(),
        }
    }

    pub fn reset_for_new_document(&mut self) {
        self.selected = None;
        self.drafts.values.clear();
        self.lens = 0;
        self.light = 0;
    }

    /// Opens the *System* section at the next frame.
    pub fn open_system(&mut self) {
        self.open_system = true;
        self.opened = Some("System");
    }

    /// Shows light `i` in the *Light* section, opened at the next frame.
    pub fn show_light(&mut self, i: usize) {
        self.light = i;
        self.open_light = true;
        self.opened = Some("Light");
    }

    /// Opens the *Lens* section at the next frame.
    pub fn open_lens(&mut self) {
        self.open_lens = true;
        self.opened = Some("Lens");
    }

    pub fn open_file_dialog(&mut self, mode: DialogMode, source: &Source) {
        self.file_dialog = Some(FileDialog::for_source(mode, source, &self.start_dir));
    }

    /// Records where `r` is on screen under `name`, if it is visible.
    fn rect(&mut self, ui: &egui::Ui, name: &str, r: &egui::Response) {
        if ui.clip_rect().contains_rect(r.rect) {
            self.rects.insert(name, r.rect, ui.ctx().pixels_per_point());
        }
    }

    /// Records a rectangle drawn over the picture (a selection's outline)
    /// under `name`, for the `--ui-log` file.
    pub fn note_rect(&mut self, name: &str, r: egui::Rect, pixels_per_point: f32) {
        self.rects.insert(name, r, pixels_per_point);
    }

    /// Writes the rectangles of the named buttons (physical pixels, window
    /// coordinates) when they changed: `{"Add sphere": [x0, y0, x1, y1], …}`.
    pub fn write_rects(&mut self, path: Option<&Path>) {
        let Some(path) = path else { return };
        let text = serde_json::to_string(&self.rects.rects).unwrap_or_default();
        if text != self.rects.written && lensview::output::write_file(path, text.as_bytes()).is_ok() {
            self.rects.written = text;
        }
    }
}

/// The whole UI pass: the panel (when shown), then the dialogs (also when
/// the panel is hidden).
pub fn show(ui: &mut egui::Ui, cx: &mut Ctx) {
    cx.ui.rects.rects.clear();
    if cx.ui.drafts.revision != cx.doc.revision() {
        cx.session.ui.drafts.values.clear();
        cx.session.ui.drafts.revision = cx.session.doc.revision();
    }
    if let Some(item) = cx.ui.selected
        && !cx.doc.contains(item)
    {
        cx.ui.selected = None;
    }
    let width = ui.ctx().content_rect().width();
    let shape = cx.display.panel_shape(width);
    if shape == PanelShape::Strip {
        strip(ui, cx);
    }
    if shape == PanelShape::Full {
        let r = egui::Panel::left("lensview-panel")
            .exact_size(PANEL_WIDTH)
            .resizable(false)
            .show(ui, |ui| {
                menu::menu_bar(ui, cx);
                menu::status(ui, cx);
                ui.separator();
                egui::ScrollArea::vertical().auto_shrink([false, false]).show(ui, |ui| {
                    add::section(ui, cx);
                    objects::section(ui, cx);
                    camera::section(ui, cx);
                    lens::section(ui, cx);
                    system::section(ui, cx);
                    light::section(ui, cx);
                    render::section(ui, cx);
                });
            });
        let ppp = ui.ctx().pixels_per_point();
        cx.ui.rects.insert("panel", r.response.rect, ppp);
    }
    let ctx = ui.ctx().clone();
    analysis::window(&ctx, cx);
    file_dialog::window(&ctx, cx);
    confirm::modal(&ctx, cx);
}

/// The collapsed panel of a narrow window: a strip with the button that
/// opens it.
fn strip(ui: &mut egui::Ui, cx: &mut Ctx) {
    egui::Panel::left("lensview-strip")
        .exact_size(STRIP_WIDTH)
        .resizable(false)
        .show(ui, |ui| {
            let r = ui
                .add(egui::Button::new(egui::RichText::new("»").strong()).min_size(egui::vec2(20.0, 28.0)))
                .on_hover_text("open the editing panel (F4 hides it)");
            cx.ui.rect(ui, "open panel", &r);
            if r.clicked() {
                cx.ask(Command::ExpandPanel(true));
            }
        });
}

/// A collapsing section whose header is recorded as `section NAME`.
/// The sections close one another (an accordion), so the one opened
/// fits the panel without scrolling in a window 720 pixels tall: opening
/// one, by its header or by a pick, closes the others at the next frame,
/// but for *Objects*, the list that selects what they show.
fn section(
    ui: &mut egui::Ui,
    cx: &mut Ctx,
    header: egui::CollapsingHeader,
    name: &'static str,
    body: impl FnOnce(&mut egui::Ui, &mut Ctx),
) {
    let header = match cx.ui.opened {
        Some(o) if o != name && name != "Objects" => header.open(Some(false)),
        _ => header,
    };
    let r = header.show(ui, |ui| body(ui, cx));
    cx.ui.rect(ui, &format!("section {name}"), &r.header_response);
    if r.header_response.clicked() {
        let state = egui::collapsing_header::CollapsingState::load(ui.ctx(), r.header_response.id);
        if state.is_some_and(|s| s.is_open()) {
            cx.ui.opened = Some(name);
            ui.ctx().request_repaint();
        }
    }
}

/// Shows `current` (or the pending draft) through `widgets`; a change is
/// applied with `apply` (a merged `Document` edit), or kept as a draft under
/// `key` with its error. Returns the value shown.
fn drafted<T: Clone + PartialEq + 'static>(
    ui: &mut egui::Ui,
    s: &mut Session,
    key: &str,
    current: T,
    widgets: impl FnOnce(&mut egui::Ui, &mut T),
    apply: impl FnOnce(&mut Document, T) -> Result<Change, Rejected>,
) -> T {
    let drafts = &mut s.ui.drafts.values;
    let mut v = drafts
        .get(key)
        .and_then(|(b, _)| b.downcast_ref::<T>())
        .cloned()
        .unwrap_or(current);
    let before = v.clone();
    widgets::draft_frame(ui, drafts.contains_key(key), |ui| widgets(ui, &mut v));
    if v != before {
        match apply(&mut s.doc, v.clone()) {
            Ok(c) => {
                s.ui.drafts.values.remove(key);
                s.ui.drafts.revision = s.doc.revision();
                s.changed(c);
            }
            Err(e) => {
                s.ui.drafts
                    .values
                    .insert(key.to_string(), (Box::new(v.clone()), e.to_string()));
            }
        }
    }
    if let Some((_, err)) = s.ui.drafts.values.get(key) {
        let err = err.clone();
        ui.horizontal_wrapped(|ui| {
            ui.colored_label(ERROR, format!("Not applied: {err}"));
            if ui.small_button("revert").clicked() {
                s.ui.drafts.values.remove(key);
            }
        });
    }
    v
}
