//! The unsaved-changes question: shown before quitting or opening another
//! scene would drop edits. Its keys (S, D, Esc) are handled by the shell;
//! both end in `Session::answer`.

use super::Ctx;
use std::path::PathBuf;

/// Something that would drop unsaved changes, waiting for an answer.
#[derive(Clone, Debug, PartialEq)]
pub enum Pending {
    Quit,
    Open(PathBuf),
    Preset(String),
}

/// An answer to the unsaved-changes question.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Answer {
    Save,
    Discard,
    Cancel,
}

/// The question as a modal window, while one is pending.
pub fn modal(ctx: &egui::Context, cx: &mut Ctx) {
    let Some(p) = cx.ui.confirm.clone() else { return };
    let (what, go) = match &p {
        Pending::Quit => ("Quit anyway?".to_string(), "Quit without saving (D)"),
        Pending::Open(path) => (format!("Open {} anyway?", path.display()), "Discard and open (D)"),
        Pending::Preset(n) => (format!("Open the preset {n} anyway?"), "Discard and open (D)"),
    };
    let save = if cx.doc.source().path().is_some() {
        "Save first (S)"
    } else {
        "Save as… (S)"
    };
    let width = 440.0f32.min(ctx.content_rect().width() - 40.0).max(120.0);
    egui::Modal::new(egui::Id::new("unsaved-changes")).show(ctx, |ui| {
        ui.set_max_width(width);
        ui.heading("Unsaved changes");
        ui.label(format!(
            "{} has changes that are not saved: {}. {what}",
            cx.doc.source(),
            cx.doc.unsaved_summary()
        ));
        ui.add_space(8.0);
        ui.horizontal_wrapped(|ui| {
            for (label, name, answer) in [
                (save, "confirm save", Answer::Save),
                (go, "confirm discard", Answer::Discard),
                ("Cancel (Esc)", "confirm cancel", Answer::Cancel),
            ] {
                let r = ui.button(label);
                cx.ui.rect(ui, name, &r);
                if r.clicked() {
                    cx.answer(answer);
                }
            }
        });
    });
}
