//! The window: a `winit` event loop over a `pixels` framebuffer, with an
//! egui side panel for editing the scene. The render thread
//! (`lensview::render::worker`) refines the picture and wakes the loop for
//! every frame; the window drops frames of an older generation, draws the
//! newest with the overlay and the panel, and never waits for the renderer.
//!
//! The scene lives in a [`Document`] (library, `lensview::edit`): keys,
//! flight and panel edits all change it through `Document::edit`, which
//! validates with `Scene::build`, keeps the undo history and says whether
//! the picture changed; only then is refinement restarted.

mod gui;
mod keys;
mod overlay;
mod panel;

use anyhow::{Context, Result, anyhow};
use glam::DVec3;
use keys::{Action, help_lines};
use lensview::edit::document::set_camera_pose;
use lensview::edit::{self, Change, Document, Edit, Source};
use lensview::render::progressive::{Progressive, Stage};
use lensview::render::worker::{Frame, Job, Worker};
use lensview::scene::{Scene, SceneFile};
use pixels::{Pixels, SurfaceTexture};
use std::collections::HashSet;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::window::{Window, WindowId};

/// Options of `lensview view`.
pub struct ViewOptions {
    pub scene_path: Option<PathBuf>,
    pub scene_file: SceneFile,
    pub frame_log: Option<PathBuf>,
    pub exit_after: Option<f64>,
    pub max_spp: u32,
    pub width: u32,
    pub height: u32,
    /// Start with the editing panel shown.
    pub panel: bool,
    /// Write the screen rectangles of the panel's main buttons here (JSON),
    /// so scripted tests can click them.
    pub ui_log: Option<PathBuf>,
}

#[derive(Debug)]
enum UserEvent {
    FrameReady,
}

/// Degrees per second of arrow-key turning; degrees per pixel of dragging.
const TURN_RATE: f64 = 60.0;
const DRAG_RATE: f64 = 0.15;

struct Viewer {
    opts: ViewOptions,
    /// The scene being edited, with its undo history and file.
    doc: Document,
    /// The camera pose that R returns to (as opened).
    home: (DVec3, DVec3),
    speed: f64,
    window: Option<Arc<Window>>,
    pixels: Option<Pixels<'static>>,
    gui: Option<gui::Gui>,
    worker: Worker,
    generation: u64,
    /// Frames of this generation are dropped (the job that stops the render
    /// thread when refinement is paused).
    ignore_generation: u64,
    input_time: Instant,
    /// Newest frame of the current generation.
    frame: Option<Frame>,
    held: HashSet<KeyCode>,
    shift: bool,
    ctrl: bool,
    dragging: Option<(f64, f64)>,
    cursor: (f64, f64),
    last_step: Instant,
    overlay: bool,
    help: bool,
    /// Render at 1/res_div of the window's resolution (F3: 2).
    res_div: u32,
    /// The editing panel is shown (F4).
    panel: bool,
    paused: bool,
    max_spp: u32,
    message: String,
    minimised: bool,
    started: Instant,
    frame_times: f64,
    last_present: Option<Instant>,
    log: Option<std::fs::File>,
    error: Option<anyhow::Error>,
    screenshot_n: u32,
    preset: usize,
    temperature: f64,
    present_ms: f64,
    ui: panel::UiState,
    title: String,
    /// When egui asked to run again (animations, tooltips).
    repaint_at: Option<Instant>,
    /// Set when the window should close (after any question was answered).
    quit: bool,
}

pub fn run(opts: ViewOptions) -> Result<()> {
    let event_loop = EventLoop::<UserEvent>::with_user_event().build().map_err(|e| {
        anyhow!(
            "cannot open a window: no display available ({e}); render headless instead: lensview render {} -o out.png",
            opts.scene_path
                .as_deref()
                .map_or(String::new(), |p| p.display().to_string())
        )
    })?;
    let proxy = event_loop.create_proxy();
    let worker = Worker::spawn(move || {
        let _ = proxy.send_event(UserEvent::FrameReady);
    });
    let source = match &opts.scene_path {
        Some(p) => Source::File(p.clone()),
        None => Source::Default,
    };
    let doc = Document::new(opts.scene_file.clone(), source).map_err(|e| anyhow!("invalid scene: {e}"))?;
    let home = doc.camera_pose();
    let log = match &opts.frame_log {
        Some(p) => Some(
            std::fs::OpenOptions::new()
                .create(true)
                .append(true)
                .open(p)
                .with_context(|| format!("cannot open frame log {}", p.display()))?,
        ),
        None => None,
    };
    let mut app = Viewer {
        max_spp: opts.max_spp,
        panel: opts.panel,
        ui: panel::UiState::new(opts.scene_path.as_deref()),
        opts,
        doc,
        home,
        speed: 3.0,
        window: None,
        pixels: None,
        gui: None,
        worker,
        generation: 0,
        ignore_generation: 0,
        input_time: Instant::now(),
        frame: None,
        held: HashSet::new(),
        shift: false,
        ctrl: false,
        dragging: None,
        cursor: (0.0, 0.0),
        last_step: Instant::now(),
        overlay: true,
        help: false,
        res_div: 1,
        paused: false,
        message: "F2: help  F4: panel".into(),
        minimised: false,
        started: Instant::now(),
        frame_times: 0.0,
        last_present: None,
        log,
        error: None,
        screenshot_n: 0,
        preset: 0,
        temperature: 6500.0,
        present_ms: 0.0,
        title: String::new(),
        repaint_at: None,
        quit: false,
    };
    event_loop.run_app(&mut app).context("event loop failed")?;
    match app.error.take() {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

impl Viewer {
    /// `lensview - scenes/cubes.toml *`: the file and an unsaved-changes mark.
    fn title(&self) -> String {
        format!("lensview - {}", self.doc.title())
    }

    fn update_title(&mut self) {
        let t = self.title();
        if t != self.title {
            if let Some(w) = &self.window {
                w.set_title(&t);
            }
            self.title = t;
        }
    }

    fn request_redraw(&self) {
        if let Some(w) = &self.window {
            w.request_redraw();
        }
    }

    /// The framebuffer: the window at 1/res_div.
    fn buffer_size(&self) -> Option<(u32, u32)> {
        let w = self.window.as_ref()?;
        let s = w.inner_size();
        if s.width == 0 || s.height == 0 {
            return None;
        }
        Some(((s.width / self.res_div).max(1), (s.height / self.res_div).max(1)))
    }

    /// Columns of the framebuffer under the panel; the picture starts there.
    fn panel_columns(&self) -> u32 {
        let (Some(w), Some((bw, _))) = (&self.window, self.buffer_size()) else {
            return 0;
        };
        if !self.panel {
            return 0;
        }
        let px = (panel::PANEL_WIDTH as f64 * w.scale_factor()).ceil() as u32;
        px.div_ceil(self.res_div).min(bw.saturating_sub(1))
    }

    /// The size the picture is rendered at: the framebuffer right of the panel.
    fn render_size(&self) -> Option<(u32, u32)> {
        let (bw, bh) = self.buffer_size()?;
        Some(((bw - self.panel_columns()).max(1), bh))
    }

    /// Starts a new generation of refinement of the document's scene.
    fn submit(&mut self) {
        let Some((w, h)) = self.render_size() else { return };
        self.generation += 1;
        self.input_time = Instant::now();
        self.worker.submit(Job {
            generation: self.generation,
            scene: self.doc.built().clone(),
            width: w,
            height: h,
            // Paused: an edit still shows, refined to one sample per pixel.
            max_spp: if self.paused { 1 } else { self.max_spp },
            seed: 0,
            input_time: self.input_time,
        });
    }

    /// What to do after the document changed: restart refinement only when
    /// the picture changed; always redraw (title, panel).
    fn changed(&mut self, change: Change) {
        if change.restarts() {
            self.submit();
        }
        self.update_title();
        self.request_redraw();
    }

    fn toggle_pause(&mut self) {
        self.paused = !self.paused;
        if self.paused {
            // Stop the render thread: a tiny job of a new generation cancels
            // the current one, and its frame is dropped; the picture stays.
            self.generation += 1;
            self.ignore_generation = self.generation;
            self.worker.submit(Job {
                generation: self.generation,
                scene: self.doc.built().clone(),
                width: 1,
                height: 1,
                max_spp: 1,
                seed: 0,
                input_time: Instant::now(),
            });
            self.message = "refinement paused (Space resumes)".into();
        } else {
            self.message = "refinement resumed".into();
            self.submit();
        }
        self.request_redraw();
    }

    fn set_resolution_divisor(&mut self, div: u32) {
        let div = div.clamp(1, 8);
        if div != self.res_div {
            self.res_div = div;
            self.message = format!("resolution {}%", 100 / div);
            self.resize_buffers();
        }
    }

    fn set_max_spp(&mut self, spp: u32) {
        let spp = spp.clamp(1, 65536);
        if spp != self.max_spp {
            self.max_spp = spp;
            self.message = format!("sample cap {spp} per pixel");
            self.submit();
        }
    }

    fn set_panel(&mut self, shown: bool) {
        if shown != self.panel {
            self.panel = shown;
            self.dragging = None;
            self.resize_buffers();
        }
    }

    /// One flight step for the held keys; false when none is held.
    fn fly(&mut self) -> bool {
        let now = Instant::now();
        let dt = (now - self.last_step).as_secs_f64().min(0.1);
        self.last_step = now;
        let held: Vec<Action> = self
            .held
            .iter()
            .filter_map(|k| keys::action_for(*k, false, false))
            .filter(|a| a.is_held())
            .collect();
        if held.is_empty() {
            return false;
        }
        let (mut pos, mut rot) = self.doc.camera_pose();
        let cam = lensview::camera::Camera::new(pos, rot, 45.0);
        let (f, r) = (cam.forward(), cam.right());
        let step = self.speed * if self.shift { 4.0 } else { 1.0 } * dt;
        let turn = TURN_RATE * dt;
        for a in held {
            match a {
                Action::Forward => pos += f * step,
                Action::Back => pos -= f * step,
                Action::Left => pos -= r * step,
                Action::Right => pos += r * step,
                Action::Up => pos += DVec3::Y * step,
                Action::Down => pos -= DVec3::Y * step,
                Action::LookLeft => rot.y += turn,
                Action::LookRight => rot.y -= turn,
                Action::LookUp => rot.x = (rot.x + turn).min(89.0),
                Action::LookDown => rot.x = (rot.x - turn).max(-89.0),
                _ => {}
            }
        }
        self.move_camera(pos, rot);
        true
    }

    /// Flight and mouse-look: one undo step per gesture (merged until the
    /// keys and the button are released).
    fn move_camera(&mut self, pos: DVec3, rot: DVec3) {
        match self
            .doc
            .edit_merged("fly", "move the camera", |sf| set_camera_pose(sf, pos, rot))
        {
            Ok(c) => self.changed(c),
            Err(e) => self.message = format!("not applied: {e}"),
        }
    }

    fn press(&mut self, a: Action) {
        let e = match a {
            Action::LightX(d) => Some(Edit::LightMove(DVec3::X * d)),
            Action::LightY(d) => Some(Edit::LightMove(DVec3::Y * d)),
            Action::LightZ(d) => Some(Edit::LightMove(DVec3::Z * d)),
            Action::LightIntensity(f) => Some(Edit::LightIntensity(f)),
            Action::LightPreset => {
                self.preset = (self.preset + 1) % edit::LIGHT_PRESETS.len();
                Some(Edit::LightPreset(self.preset))
            }
            Action::LightWarmer | Action::LightCooler => {
                let k = self.temperature + if a == Action::LightWarmer { -500.0 } else { 500.0 };
                self.temperature = k.clamp(1000.0, 40000.0);
                Some(Edit::LightTemperature(self.temperature))
            }
            Action::LensAlongAxis(d) => Some(Edit::LensAlongAxis(d)),
            Action::LensSideways(d) => Some(Edit::LensMove(DVec3::X * d)),
            Action::LensVertical(d) => Some(Edit::LensMove(DVec3::Y * d)),
            Action::LensYaw(d) => Some(Edit::LensTurn { yaw: d, pitch: 0.0 }),
            Action::LensPitch(d) => Some(Edit::LensTurn { yaw: 0.0, pitch: d }),
            Action::LensD(d) => Some(Edit::LensDiameter(d)),
            Action::LensR1(d) => Some(Edit::LensR1(d)),
            Action::LensR2(d) => Some(Edit::LensR2(d)),
            Action::LensN(d) => Some(Edit::LensIndex(d)),
            _ => None,
        };
        if let Some(e) = e {
            // The key edits clamp to valid values; they still pass through
            // the document's validation and undo history like any edit.
            let mut next = self.doc.scene().clone();
            let msg = edit::apply(&mut next, e);
            match self.doc.edit(&msg, |sf| *sf = next) {
                Ok(c) => {
                    self.message = msg;
                    self.changed(c);
                }
                Err(err) => self.message = format!("not applied: {err}"),
            }
            return;
        }
        match a {
            Action::ResetView => {
                let (p, r) = self.home;
                match self.doc.edit("reset the view", |sf| set_camera_pose(sf, p, r)) {
                    Ok(c) => {
                        self.message = "view reset".into();
                        self.changed(c);
                    }
                    Err(e) => self.message = format!("not applied: {e}"),
                }
            }
            Action::Reload => self.reload(),
            Action::HalfResolution => self.set_resolution_divisor(if self.res_div == 1 { 2 } else { 1 }),
            Action::Screenshot => self.screenshot(),
            Action::ToggleOverlay => self.overlay = !self.overlay,
            Action::ToggleHelp => self.help = !self.help,
            Action::Undo => self.undo(),
            Action::Redo => self.redo(),
            Action::Save => {
                self.save();
            }
            Action::SaveAs => self.ui.open_file_dialog(panel::DialogMode::SaveAs, self.doc.source()),
            Action::Open => self.ui.open_file_dialog(panel::DialogMode::Open, self.doc.source()),
            Action::TogglePanel => self.set_panel(!self.panel),
            Action::Pause => self.toggle_pause(),
            Action::DeleteSelected => self.delete_selected(),
            Action::DuplicateSelected => self.duplicate_selected(),
            Action::Quit => self.request_quit(),
            _ => {}
        }
        self.request_redraw();
    }

    fn undo(&mut self) {
        match self.doc.undo() {
            Some((label, c)) => {
                self.message = format!("undone: {label}");
                self.changed(c);
            }
            None => self.message = "nothing to undo".into(),
        }
    }

    fn redo(&mut self) {
        match self.doc.redo() {
            Some((label, c)) => {
                self.message = format!("redone: {label}");
                self.changed(c);
            }
            None => self.message = "nothing to redo".into(),
        }
    }

    /// Ctrl+S: to the document's file, or ask for one.
    fn save(&mut self) -> bool {
        match self.doc.save() {
            Ok(Some(p)) => {
                self.message = format!("saved {}", p.display());
                self.ui.error = None;
                self.update_title();
                true
            }
            Ok(None) => {
                self.ui.open_file_dialog(panel::DialogMode::SaveAs, self.doc.source());
                false
            }
            Err(e) => {
                self.message = format!("not saved: {e}");
                self.ui.error = Some(self.message.clone());
                false
            }
        }
    }

    fn save_as(&mut self, path: &Path) -> Result<(), String> {
        match self.doc.save_as(path) {
            Ok(p) => {
                self.message = format!("saved {}", p.display());
                self.ui.error = None;
                self.opts.scene_path = Some(p);
                self.update_title();
                Ok(())
            }
            Err(e) => Err(e.to_string()),
        }
    }

    /// Replaces the document (open, preset); the view goes to its camera.
    fn replace_document(&mut self, doc: Document, what: String) {
        self.doc = doc;
        self.home = self.doc.camera_pose();
        self.opts.scene_path = self.doc.source().path().map(Path::to_path_buf);
        self.ui.reset_for_new_document();
        self.message = what;
        self.ui.error = None;
        self.frame = None;
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
                self.message = msg.clone();
                self.ui.error = Some(msg.clone());
                Err(msg)
            }
        }
    }

    fn open_preset(&mut self, name: &str) {
        match Document::preset(name) {
            Ok(doc) => self.replace_document(doc, format!("preset {name}")),
            Err(e) => {
                self.message = format!("preset not opened: {e}");
                self.ui.error = Some(self.message.clone());
            }
        }
    }

    /// Does what was asked, or asks first when it would lose unsaved changes.
    fn perform(&mut self, p: panel::Pending, ask: bool) {
        if ask && self.doc.is_dirty() {
            self.ui.confirm = Some(p);
            self.request_redraw();
            return;
        }
        self.ui.confirm = None;
        match p {
            panel::Pending::Quit => self.quit = true,
            panel::Pending::Open(path) => {
                if self.open_path(&path).is_ok() {
                    self.ui.file_dialog = None;
                }
            }
            panel::Pending::Preset(name) => self.open_preset(&name),
        }
        self.request_redraw();
    }

    fn request_quit(&mut self) {
        // A question already on screen: Escape answers "cancel".
        if self.ui.confirm.take().is_some() {
            self.message = "cancelled".into();
            return;
        }
        if self.ui.file_dialog.take().is_some() {
            return;
        }
        self.perform(panel::Pending::Quit, true);
    }

    fn reload(&mut self) {
        match self.doc.reload(true) {
            Ok(c) => {
                self.message = format!("reloaded {} (Ctrl+Z undoes)", self.doc.source());
                self.ui.error = None;
                self.changed(c);
            }
            // Nothing the user made is lost: the current scene stays.
            Err(e) => {
                self.message = format!("reload failed, scene kept: {e}");
                self.ui.error = Some(self.message.clone());
            }
        }
    }

    /// Saves the full-resolution image at the samples refined so far (at
    /// least one), rendered on its own thread so the window stays live.
    fn screenshot(&mut self) {
        let Some((w, h)) = self.render_size() else { return };
        let (w, h) = (w * self.res_div, h * self.res_div);
        let spp = self.frame.as_ref().map_or(1, |f| f.spp.max(1));
        self.screenshot_n += 1;
        let name = PathBuf::from(format!(
            "lensview-{}-{}.png",
            std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_secs()),
            self.screenshot_n
        ));
        let scene: Arc<Scene> = self.doc.built().clone();
        self.message = format!("saving {} ({w}×{h}, {spp} spp)…", name.display());
        std::thread::spawn(move || {
            let mut p = Progressive::new(w, h, 0);
            p.run(&scene, Stage::Samples(spp), &|| false);
            match p.image().write_png(&name) {
                Ok(()) => eprintln!("saved {}", name.display()),
                Err(e) => eprintln!("error: cannot write {}: {e}", name.display()),
            }
        });
    }

    fn resize_buffers(&mut self) {
        let Some(window) = &self.window else { return };
        let size = window.inner_size();
        self.minimised = size.width == 0 || size.height == 0;
        if self.minimised {
            return;
        }
        let Some((bw, bh)) = self.buffer_size() else { return };
        if let Some(p) = &mut self.pixels {
            if let Err(e) = p.resize_surface(size.width, size.height) {
                self.message = format!("resize failed: {e}");
                return;
            }
            if let Err(e) = p.resize_buffer(bw, bh) {
                self.message = format!("resize failed: {e}");
                return;
            }
        }
        self.frame = None;
        // (Paused, the new size is shown at one sample per pixel.)
        self.submit();
        self.request_redraw();
    }

    fn overlay_lines(&self) -> Vec<String> {
        let mut v = vec![self.title()];
        let fps = if self.frame_times > 0.0 {
            1000.0 / self.frame_times
        } else {
            0.0
        };
        // Lines of at most ~55 characters: at 16 px a character they fit
        // the picture beside the panel in a 1280-pixel-wide window.
        match &self.frame {
            Some(f) => {
                v.push(format!(
                    "{}{}{} in {:.0} ms, {:.2} M rays/s",
                    f.stage.label(),
                    if f.last { " (done)" } else { "" },
                    if self.paused { " (paused)" } else { "" },
                    f.render_ms,
                    f.samples_per_s / 1e6,
                ));
                v.push(format!(
                    "frame {:.1} ms ({:.0} fps), present {:.1} ms",
                    self.frame_times, fps, self.present_ms
                ));
            }
            None => v.push("rendering…".into()),
        }
        let scene = self.doc.built();
        let (p, r) = (scene.camera.position, scene.camera.rotation_deg);
        v.push(format!(
            "camera ({:.2}, {:.2}, {:.2})  speed {:.1}",
            p.x, p.y, p.z, self.speed
        ));
        v.push(format!(
            "  rot x {:.1} y {:.1} z {:.1}  fov {:.0}",
            r.x, r.y, r.z, scene.camera.fov_y_deg
        ));
        if let Some(l) = self.doc.scene().lights.first() {
            let p = l.position.or(l.direction).unwrap_or_default();
            v.push(format!(
                "light ({:.2}, {:.2}, {:.2})  intensity {:.1}",
                p[0], p[1], p[2], l.intensity
            ));
            v.push(format!(
                "  colour ({:.2}, {:.2}, {:.2})",
                l.color[0], l.color[1], l.color[2]
            ));
        }
        if let Some(lens) = scene.objects.iter().find_map(|o| o.lens()) {
            let n = lens.index.nominal();
            let px = lens.paraxial(n);
            v.push(format!(
                "lens d {:.3}  r1 {:.3}  r2 {:.3}  n {:.4}",
                lens.d, lens.r1, lens.r2, n
            ));
            v.push(format!("  EFL {:.4}  BFD {:.4}", px.efl, px.bfd));
        }
        v.push(format!("> {}", self.message));
        if self.help {
            v.extend(help_lines());
        }
        v
    }

    /// Runs the panel's UI pass (also when the panel is hidden: the
    /// questions and file dialogs still show).
    fn run_ui(&mut self) {
        let (Some(window), Some(mut gui)) = (self.window.clone(), self.gui.take()) else {
            return;
        };
        let delay = gui.run(&window, |ui| self.ui(ui));
        self.gui = Some(gui);
        self.repaint_at = delay.map(|d| Instant::now() + d);
        if delay == Some(Duration::ZERO) {
            window.request_redraw();
        }
        self.ui.write_rects(self.opts.ui_log.as_deref());
        self.update_title();
    }

    fn draw(&mut self) {
        if self.minimised {
            return;
        }
        self.run_ui();
        let Some((bw, bh)) = self.buffer_size() else { return };
        let x0 = self.panel_columns();
        let (w, h) = ((bw - x0).max(1), bh);
        let lines = if self.overlay { Some(self.overlay_lines()) } else { None };
        let Some(pixels) = &mut self.pixels else { return };
        let t0 = Instant::now();
        let buf = pixels.frame_mut();
        if buf.len() != (bw * bh * 4) as usize {
            return;
        }
        let (row, fw) = (bw as usize * 4, w as usize * 4);
        match &self.frame {
            Some(f) if f.width == w && f.height == h && f.rgba.len() == fw * h as usize => {
                for (y, src) in f.rgba.chunks_exact(fw).enumerate() {
                    let start = y * row + x0 as usize * 4;
                    buf[start..start + fw].copy_from_slice(src);
                }
                for y in 0..h as usize {
                    buf[y * row..y * row + x0 as usize * 4].fill(0);
                }
            }
            _ => buf.fill(0),
        }
        if let Some(lines) = lines {
            overlay::draw_lines(buf, bw as usize, bh as usize, x0 as usize, &lines);
        }
        let gui = &mut self.gui;
        let result = pixels.render_with(|encoder, target, context| {
            context.scaling_renderer.render(encoder, target);
            if let Some(g) = gui.as_mut() {
                g.paint(encoder, target, context);
            }
            Ok(())
        });
        if let Err(e) = result {
            self.message = format!("present failed: {e}");
        }
        let now = Instant::now();
        let present_ms = (now - t0).as_secs_f64() * 1e3;
        self.present_ms = present_ms;
        if let Some(prev) = self.last_present {
            let dt = (now - prev).as_secs_f64() * 1e3;
            self.frame_times = if self.frame_times == 0.0 {
                dt
            } else {
                0.9 * self.frame_times + 0.1 * dt
            };
        }
        self.last_present = Some(now);
        if let (Some(log), Some(f)) = (&mut self.log, &self.frame) {
            let line = serde_json::json!({
                "generation": f.generation,
                "level": f.stage.label(),
                "spp": f.spp,
                "width": f.width,
                "height": f.height,
                "x0": x0,
                "ms_since_input": (now - self.input_time).as_secs_f64() * 1e3,
                "render_ms": f.render_ms,
                "queued_ms": f.queued_ms,
                "sent_ms_since_input": f.since_input_ms,
                "present_ms": present_ms,
                "t": (now - self.started).as_secs_f64(),
            });
            let _ = writeln!(log, "{line}");
        }
    }

    fn key_event(&mut self, code: KeyCode, state: ElementState) {
        // While the unsaved-changes question is up, keys answer it.
        if self.ui.confirm.is_some() {
            if state == ElementState::Pressed {
                match code {
                    KeyCode::KeyS | KeyCode::Enter if !self.ctrl => self.answer(panel::Answer::Save),
                    KeyCode::KeyD | KeyCode::KeyN => self.answer(panel::Answer::Discard),
                    KeyCode::Escape => self.answer(panel::Answer::Cancel),
                    _ => {}
                }
            }
            self.held.clear();
            return;
        }
        let Some(action) = keys::action_for(code, self.ctrl, self.shift) else {
            // A flight key released while Ctrl is down still stops flying.
            if state == ElementState::Released {
                self.held.remove(&code);
            }
            return;
        };
        match state {
            ElementState::Pressed if action.is_held() => {
                if self.held.insert(code) {
                    self.last_step = Instant::now();
                }
            }
            ElementState::Released if action.is_held() => {
                self.held.remove(&code);
            }
            ElementState::Pressed => self.press(action),
            ElementState::Released => {}
        }
    }
}

impl ApplicationHandler<UserEvent> for Viewer {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_some() {
            return;
        }
        let attrs = Window::default_attributes()
            .with_title(self.title())
            .with_inner_size(PhysicalSize::new(self.opts.width, self.opts.height))
            .with_min_inner_size(PhysicalSize::new(1, 1));
        let window = match event_loop.create_window(attrs) {
            Ok(w) => Arc::new(w),
            Err(e) => {
                self.error = Some(anyhow!("cannot create a window: {e}"));
                event_loop.exit();
                return;
            }
        };
        let size = window.inner_size();
        let (w, h) = (size.width.max(1), size.height.max(1));
        // No vsync: a frame is presented as soon as it is rendered; waiting
        // for a vertical blank would add up to a refresh period of latency.
        let built = pixels::PixelsBuilder::new(w, h, SurfaceTexture::new(w, h, window.clone()))
            .enable_vsync(false)
            .build();
        let pixels = match built {
            Ok(p) => p,
            Err(e) => {
                self.error = Some(anyhow!(
                    "cannot draw into the window ({e}); render headless instead: lensview render -o out.png"
                ));
                event_loop.exit();
                return;
            }
        };
        self.gui = Some(gui::Gui::new(&window, &pixels));
        self.title = self.title();
        self.window = Some(window);
        self.pixels = Some(pixels);
        self.resize_buffers();
    }

    fn user_event(&mut self, _: &ActiveEventLoop, event: UserEvent) {
        match event {
            UserEvent::FrameReady => {
                let mut newest = None;
                while let Ok(f) = self.worker.frames.try_recv() {
                    // Frames of an older generation are dropped, and so is
                    // the pause job's.
                    if f.generation == self.generation && f.generation != self.ignore_generation {
                        newest = Some(f);
                    }
                }
                if let Some(f) = newest {
                    self.frame = Some(f);
                    self.request_redraw();
                }
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        // egui sees every event but the redraw; what it consumes (a click on
        // the panel, typing in a field) does not also fly the camera.
        let mut consumed = false;
        if !matches!(event, WindowEvent::RedrawRequested)
            && let (Some(g), Some(w)) = (self.gui.as_mut(), self.window.as_ref())
        {
            let r = g.on_event(w, &event);
            if r.repaint {
                w.request_redraw();
            }
            consumed = r.consumed;
        }
        let typing = self.gui.as_ref().is_some_and(|g| g.typing());
        match event {
            WindowEvent::CloseRequested => {
                self.ui.file_dialog = None;
                self.perform(panel::Pending::Quit, true);
            }
            WindowEvent::Resized(_) => self.resize_buffers(),
            WindowEvent::RedrawRequested => self.draw(),
            WindowEvent::ModifiersChanged(m) => {
                self.shift = m.state().shift_key();
                self.ctrl = m.state().control_key();
            }
            WindowEvent::Focused(false) => self.held.clear(),
            WindowEvent::KeyboardInput {
                event, is_synthetic, ..
            } => {
                // winit fakes presses for keys held when focus arrives.
                if is_synthetic {
                    return;
                }
                let PhysicalKey::Code(code) = event.physical_key else {
                    return;
                };
                // Keys typed into a field are the field's (Ctrl+Z there is
                // the field's own undo); releases always stop flight. Save
                // and open, which no field uses, work while typing too.
                let file_chord = self.ctrl
                    && matches!(
                        keys::action_for(code, true, self.shift),
                        Some(Action::Save | Action::SaveAs | Action::Open)
                    );
                if consumed && typing && event.state == ElementState::Pressed && !file_chord {
                    return;
                }
                // Auto-repeat steps scene edits and undo/redo, never toggles.
                let repeats = keys::action_for(code, self.ctrl, self.shift)
                    .is_some_and(|a| !a.is_held() && (a.restarts() || matches!(a, Action::Undo | Action::Redo)));
                if event.repeat && !repeats {
                    return;
                }
                self.key_event(code, event.state);
            }
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Left,
                ..
            } => {
                let over_panel = self.panel && self.cursor.0 < self.panel_columns() as f64 * self.res_div as f64;
                if state == ElementState::Pressed {
                    if !consumed && !over_panel {
                        self.dragging = Some(self.cursor);
                    }
                } else {
                    self.dragging = None;
                }
            }
            WindowEvent::CursorMoved { position, .. } => {
                self.cursor = (position.x, position.y);
                if let Some((x0, y0)) = self.dragging {
                    let (dx, dy) = (position.x - x0, position.y - y0);
                    self.dragging = Some(self.cursor);
                    let (pos, mut rot) = self.doc.camera_pose();
                    rot.y -= dx * DRAG_RATE;
                    rot.x = (rot.x - dy * DRAG_RATE).clamp(-89.0, 89.0);
                    self.move_camera(pos, rot);
                }
            }
            WindowEvent::MouseWheel { delta, .. } if !consumed => {
                let steps = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y as f64,
                    MouseScrollDelta::PixelDelta(p) => p.y / 40.0,
                };
                self.speed = (self.speed * 1.2f64.powf(steps)).clamp(0.05, 500.0);
                self.message = format!("flight speed {:.2}", self.speed);
                self.request_redraw();
            }
            _ => {}
        }
        if self.quit {
            event_loop.exit();
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        if self.quit {
            event_loop.exit();
            return;
        }
        if let Some(limit) = self.opts.exit_after
            && self.started.elapsed().as_secs_f64() >= limit
        {
            event_loop.exit();
            return;
        }
        let flying = self.fly();
        // A gesture ends when nothing is held, dragged or typed: the next
        // edit is a new undo step.
        let ui_busy = self
            .gui
            .as_ref()
            .is_some_and(|g| g.typing() || g.ctx.egui_is_using_pointer());
        if !flying && self.dragging.is_none() && !ui_busy {
            self.doc.seal();
        }
        let mut wake: Option<Instant> = None;
        if flying {
            // Keep stepping while a key is held: about one 60 Hz frame.
            wake = Some(Instant::now() + Duration::from_millis(16));
        }
        if let Some(t) = self.repaint_at {
            if t <= Instant::now() {
                self.repaint_at = None;
                self.request_redraw();
            } else {
                wake = Some(wake.map_or(t, |w| w.min(t)));
            }
        }
        if let Some(limit) = self.opts.exit_after {
            let left = (limit - self.started.elapsed().as_secs_f64()).max(0.0);
            let t = Instant::now() + Duration::from_secs_f64(left.min(0.25));
            wake = Some(wake.map_or(t, |w| w.min(t)));
        }
        event_loop.set_control_flow(match wake {
            Some(t) => ControlFlow::WaitUntil(t),
            None => ControlFlow::Wait,
        });
    }
}
