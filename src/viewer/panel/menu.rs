//! The top of the panel: the menu bar (File, Edit, View, Presets) and the
//! status lines (the document, undo/redo/save/open/pause buttons, the
//! message line and the last error).

use super::{Ctx, DialogMode, ERROR, Pending, WARN};
use crate::viewer::keys::{Action, label_of};
use crate::viewer::overlay::OverlayMode;
use crate::viewer::session::Command;
use egui::RichText;
use lensview::edit::presets::PRESETS;

/// A menu entry with its key shown; true when clicked.
fn entry(ui: &mut egui::Ui, text: &str, action: Action) -> bool {
    ui.add(egui::Button::new(text).shortcut_text(label_of(action)))
        .clicked()
}

pub fn menu_bar(ui: &mut egui::Ui, cx: &mut Ctx) {
    egui::MenuBar::new().ui(ui, |ui| {
        // In a narrow window the panel folds back to its strip.
        if ui.ctx().content_rect().width() < super::NARROW {
            let r = ui.button("«").on_hover_text("fold the panel to a strip");
            cx.ui.rect(ui, "fold panel", &r);
            if r.clicked() {
                cx.ask(Command::ExpandPanel(false));
            }
        }
        ui.menu_button("File", |ui| file_menu(ui, cx));
        ui.menu_button("Edit", |ui| edit_menu(ui, cx));
        ui.menu_button("View", |ui| view_menu(ui, cx));
        ui.menu_button("Presets", |ui| {
            for p in PRESETS {
                if ui.button(p.name).on_hover_text(p.about).clicked() {
                    cx.perform(Pending::Preset(p.name.to_string()), true);
                    ui.close();
                }
            }
        });
    });
}

fn file_menu(ui: &mut egui::Ui, cx: &mut Ctx) {
    if entry(ui, "Open…", Action::Open) {
        let s = &mut *cx.session;
        s.ui.open_file_dialog(DialogMode::Open, s.doc.source());
        ui.close();
    }
    if entry(ui, "Save", Action::Save) {
        cx.save();
        ui.close();
    }
    if entry(ui, "Save as…", Action::SaveAs) {
        let s = &mut *cx.session;
        s.ui.open_file_dialog(DialogMode::SaveAs, s.doc.source());
        ui.close();
    }
    let has_file = cx.doc.source().path().is_some();
    if ui
        .add_enabled(
            has_file,
            egui::Button::new("Reload from disk").shortcut_text(label_of(Action::Reload)),
        )
        .on_hover_text("read the file again, keeping the camera (undoable)")
        .clicked()
    {
        cx.reload();
        ui.close();
    }
    ui.separator();
    if entry(ui, "Quit", Action::Quit) {
        cx.perform(Pending::Quit, true);
        ui.close();
    }
}

fn edit_menu(ui: &mut egui::Ui, cx: &mut Ctx) {
    if history_entry(ui, "Undo", cx.doc.undo_label(), "Ctrl+Z") {
        cx.undo();
    }
    if history_entry(ui, "Redo", cx.doc.redo_label(), "Ctrl+Shift+Z") {
        cx.redo();
    }
}

/// *Undo …* / *Redo …* naming the step, greyed out without one.
fn history_entry(ui: &mut egui::Ui, verb: &str, step: Option<&str>, keys: &str) -> bool {
    let text = step.map_or_else(|| verb.to_string(), |l| format!("{verb} {l}"));
    ui.add_enabled(step.is_some(), egui::Button::new(text).shortcut_text(keys))
        .clicked()
}

fn view_menu(ui: &mut egui::Ui, cx: &mut Ctx) {
    ui.horizontal(|ui| {
        ui.label("Overlay (F1)");
        for m in [OverlayMode::Off, OverlayMode::Compact, OverlayMode::Full] {
            ui.selectable_value(&mut cx.display.overlay, m, m.label());
        }
    });
    ui.checkbox(&mut cx.display.help, "Key help (F2)");
    if entry(ui, "Hide this panel", Action::TogglePanel) {
        cx.ask(Command::ShowPanel(false));
        ui.close();
    }
    if entry(ui, "Reset the view", Action::ResetView) {
        cx.reset_view();
    }
    if entry(ui, "Screenshot (PNG and EXR)", Action::Screenshot) {
        cx.ask(Command::Screenshot);
    }
    if entry(ui, "Record a flight on/off", Action::ToggleRecording) {
        cx.ask(Command::ToggleRecording);
    }
}

/// The document's name and state, the main buttons, the message line and
/// the last error.
pub fn status(ui: &mut egui::Ui, cx: &mut Ctx) {
    ui.horizontal_wrapped(|ui| {
        // A file by its name on one line (the whole path on hover): a long
        // path must not wrap and push the sections down.
        let source = cx.doc.source();
        let shown = match source {
            lensview::edit::Source::File(p) => p.file_name().map_or(source.to_string(), |n| n.to_string_lossy().into()),
            _ => source.to_string(),
        };
        let label = egui::Label::new(RichText::new(shown).strong()).truncate();
        ui.add(label).on_hover_text(source.to_string());
        let u = cx.doc.unsaved();
        if u.content {
            ui.colored_label(WARN, "* unsaved changes");
        } else if u.view {
            ui.weak("camera moved (Save keeps it)");
        }
    });
    ui.horizontal(|ui| buttons(ui, cx));
    ui.label(RichText::new(format!("> {}", cx.message)).small().weak());
    if let Some(e) = cx.ui.error.clone() {
        ui.horizontal_wrapped(|ui| {
            ui.colored_label(ERROR, e);
            if ui.small_button("ok").clicked() {
                cx.ui.error = None;
            }
        });
    }
}

fn buttons(ui: &mut egui::Ui, cx: &mut Ctx) {
    let r = ui.add_enabled(cx.doc.undo_label().is_some(), egui::Button::new("Undo"));
    let r = match cx.doc.undo_label() {
        Some(l) => r.on_hover_text(format!("undo {l} (Ctrl+Z)")),
        None => r,
    };
    if r.clicked() {
        cx.undo();
    }
    cx.ui.rect(ui, "Undo", &r);
    let r = ui.add_enabled(cx.doc.redo_label().is_some(), egui::Button::new("Redo"));
    if r.clicked() {
        cx.redo();
    }
    let r = ui.button("Save").on_hover_text("Ctrl+S");
    if r.clicked() {
        cx.save();
    }
    cx.ui.rect(ui, "Save", &r);
    if ui.button("Open…").on_hover_text("Ctrl+O").clicked() {
        let s = &mut *cx.session;
        s.ui.open_file_dialog(DialogMode::Open, s.doc.source());
    }
    let pause = if cx.render.paused { "Resume" } else { "Pause" };
    if ui.button(pause).on_hover_text("refinement (Space)").clicked() {
        cx.ask(Command::TogglePause);
    }
}
