//! The in-window file dialog for *Open* and *Save as* (no system dialog:
//! nothing beyond X11 needed). It lists folders and `.toml` files; saving
//! over an existing file takes a second click.

use super::{Ctx, ERROR, Pending, WARN};
use lensview::edit::Source;
use std::path::{Path, PathBuf};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DialogMode {
    Open,
    SaveAs,
}

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

    /// A dialog in the folder of the document's file (or `start_dir`);
    /// saving proposes the file's name, or one made from the preset's.
    pub fn for_source(mode: DialogMode, source: &Source, start_dir: &Path) -> Self {
        let (dir, name) = match source.path() {
            Some(p) => (
                p.parent()
                    .filter(|d| !d.as_os_str().is_empty())
                    .map_or_else(|| start_dir.to_path_buf(), Path::to_path_buf),
                p.file_name()
                    .map_or(String::new(), |n| n.to_string_lossy().into_owned()),
            ),
            None => (
                start_dir.to_path_buf(),
                match source {
                    Source::Preset(n) => format!("{}.toml", n.replace(' ', "-")),
                    _ => "scene.toml".into(),
                },
            ),
        };
        let name = if mode == DialogMode::Open { String::new() } else { name };
        FileDialog::new(mode, dir, name)
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

    /// The folder line: typed, or one up.
    fn folder_row(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            ui.label("folder");
            let r = ui.add(egui::TextEdit::singleline(&mut self.dir_text).desired_width(300.0));
            if r.lost_focus() {
                let p = PathBuf::from(self.dir_text.trim());
                if p.is_dir() {
                    self.enter(p);
                } else {
                    self.error = Some(format!("{} is not a folder", p.display()));
                }
            }
            if ui.button("up").clicked()
                && let Some(parent) = self
                    .dir
                    .canonicalize()
                    .ok()
                    .and_then(|p| p.parent().map(Path::to_path_buf))
            {
                self.enter(parent);
            }
        });
    }

    /// The folders and scenes here; a double click chooses a file.
    fn entry_list(&mut self, ui: &mut egui::Ui) -> Option<PathBuf> {
        let mut chosen = None;
        egui::ScrollArea::vertical()
            .id_salt("file-list")
            .max_height(220.0)
            .auto_shrink([false, true])
            .show(ui, |ui| {
                let entries = self.entries.clone();
                for (name, is_dir) in entries {
                    if is_dir {
                        if ui.selectable_label(false, format!("📁 {name}/")).clicked() {
                            self.enter(self.dir.join(&name));
                        }
                    } else {
                        let r = ui.selectable_label(self.name == name, &name);
                        if r.clicked() {
                            self.name = name.clone();
                            self.overwrite = None;
                        }
                        if r.double_clicked() {
                            chosen = self.path();
                        }
                    }
                }
                if self.entries.is_empty() {
                    ui.weak("(no folders or .toml files here)");
                }
            });
        chosen
    }

    /// The file name line; Enter in it chooses.
    fn name_row(&mut self, ui: &mut egui::Ui) -> Option<PathBuf> {
        ui.horizontal(|ui| {
            ui.label("file");
            let r = ui.add(egui::TextEdit::singleline(&mut self.name).desired_width(300.0));
            if r.changed() {
                self.overwrite = None;
            }
            if r.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter)) {
                return self.path();
            }
            None
        })
        .inner
    }
}

/// What the dialog's window was answered.
enum Choice {
    Nothing,
    Path(PathBuf),
    Cancel,
}

/// The dialog's window (while one is open), and what a choice leads to.
pub fn window(ctx: &egui::Context, cx: &mut Ctx) {
    let Some(mut d) = cx.ui.file_dialog.take() else {
        return;
    };
    let title = match d.mode {
        DialogMode::Open => "Open a scene",
        DialogMode::SaveAs => "Save the scene as",
    };
    let mut choice = Choice::Nothing;
    // Never larger than the window: its buttons stay reachable at any size.
    let screen = ctx.content_rect();
    egui::Window::new(title)
        .collapsible(false)
        .resizable(true)
        .constrain_to(screen)
        .default_width(480.0f32.min(screen.width() - 24.0))
        .max_width((screen.width() - 24.0).max(120.0))
        .max_height((screen.height() - 24.0).max(120.0))
        .anchor(egui::Align2::CENTER_CENTER, [0.0, 0.0])
        .show(ctx, |ui| choice = contents(ui, cx, &mut d));
    match choice {
        Choice::Path(path) => choose(cx, d, path),
        Choice::Nothing => cx.ui.file_dialog = Some(d),
        Choice::Cancel => cx.ui.after_save = None,
    }
}

fn contents(ui: &mut egui::Ui, cx: &mut Ctx, d: &mut FileDialog) -> Choice {
    d.folder_row(ui);
    let mut chosen = d.entry_list(ui);
    chosen = d.name_row(ui).or(chosen);
    if let Some(e) = &d.error {
        ui.colored_label(ERROR, e);
    }
    if let Some(p) = &d.overwrite {
        ui.colored_label(WARN, format!("{} exists: Save again replaces it.", p.display()));
    }
    let mut cancel = false;
    ui.horizontal(|ui| {
        let ok = match d.mode {
            DialogMode::Open => "Open",
            DialogMode::SaveAs => "Save",
        };
        let r = ui.add_enabled(!d.name.trim().is_empty(), egui::Button::new(ok));
        cx.ui.rect(ui, &format!("dialog {ok}"), &r);
        if r.clicked() {
            chosen = d.path();
        }
        cancel = ui.button("Cancel").clicked();
    });
    match chosen {
        Some(p) => Choice::Path(p),
        None if cancel => Choice::Cancel,
        None => Choice::Nothing,
    }
}

/// Opens or saves `path`; the dialog stays open with the reason when that
/// fails (or to confirm replacing a file).
fn choose(cx: &mut Ctx, mut d: FileDialog, path: PathBuf) {
    match d.mode {
        DialogMode::Open => {
            cx.ui.file_dialog = Some(d);
            cx.perform(Pending::Open(path), true);
            // A failed open keeps the dialog and shows why in it.
            let ui = &mut cx.session.ui;
            if let (Some(d), Some(e)) = (&mut ui.file_dialog, &ui.error) {
                d.error = Some(e.clone());
            }
        }
        DialogMode::SaveAs if path.exists() && d.overwrite.as_ref() != Some(&path) => {
            d.overwrite = Some(path);
            cx.ui.file_dialog = Some(d);
        }
        DialogMode::SaveAs => match cx.save_as(&path) {
            Ok(()) => {
                if let Some(p) = cx.ui.after_save.take() {
                    cx.perform(p, false);
                }
            }
            Err(e) => {
                d.error = Some(format!("not saved: {e}"));
                cx.ui.file_dialog = Some(d);
            }
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn the_dialog_starts_beside_the_file_or_proposes_a_name() {
        let start = std::env::temp_dir();
        let d = FileDialog::for_source(DialogMode::SaveAs, &Source::Preset("optical bench".into()), &start);
        assert_eq!(
            (d.dir.as_path(), d.name.as_str()),
            (start.as_path(), "optical-bench.toml")
        );
        let d = FileDialog::for_source(DialogMode::SaveAs, &Source::File(start.join("x.toml")), Path::new("/"));
        assert_eq!((d.dir.as_path(), d.name.as_str()), (start.as_path(), "x.toml"));
        let d = FileDialog::for_source(DialogMode::Open, &Source::Default, &start);
        assert_eq!(d.name, "");
    }
}
