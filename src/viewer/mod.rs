//! The window: a `winit` event loop over a `pixels` framebuffer, with an
//! egui side panel for editing the scene. The render thread
//! (`lensview::render::worker`) refines the picture and wakes the loop for
//! every frame; the window drops frames of an older generation, draws the
//! newest with the overlay and the panel when `pacing` says so, and never
//! waits for the renderer.
//!
//! This file is the shell: the [`ApplicationHandler`] that hands events to
//! the parts and carries out what they ask.
//! - `screen`: window, framebuffer, egui surface, sizes, presenting.
//! - `input`: keys and mouse → flight, key edits, commands.
//! - `keys`: the key-binding tables and the help printed from them.
//! - `flight`: camera flight and mouse-look (a pure step, tested).
//! - `refine`: the link to the render thread: generations, pause.
//! - `stats`: frame timings, the frame log, the overlay's lines.
//! - `session`: the document, the panel's state and the message line,
//!   with the commands keys and panel share (undo, save, open, quit…).
//! - `panel`: the egui panel, one file per section.
//! - `gui`, `overlay`: egui on `pixels`; the overlay box and key help.
//! - `pacing`: when to present (nothing twice, one per refresh, refining
//!   frames paced on a CPU rasterizer).
//! - `platform`: the environment set before any thread (X11 without
//!   `XDG_RUNTIME_DIR`).
//!
//! The scene lives in a `Document` (library, `lensview::edit`): every change
//! is one of its methods, which validates with `Scene::build`, keeps the
//! undo history and says whether the picture changed; only then is
//! refinement restarted.

mod flight;
mod gui;
mod heap;
mod input;
mod keys;
mod optics;
mod overlay;
mod pacing;
mod panel;
mod pick;
mod platform;
mod recorder;
mod refine;
mod screen;
mod session;
mod settle;
mod stats;
mod watchdog;

use anyhow::{Context, Result, anyhow};
use lensview::edit::{Document, Source};
use lensview::render::worker::Worker;
use lensview::scene::SceneFile;
use pacing::{Decision, Pacer};
pub use platform::quiet_wayland_probe;
use refine::Refine;
use screen::{Display, Screen, Shown};
use session::{Command, Outcome, Session};
use stats::{Presented, Stats};
use std::path::PathBuf;
use std::time::{Duration, Instant};
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::ModifiersState;
use winit::window::WindowId;

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
    /// Where screenshots (P) go.
    pub screenshots: PathBuf,
    /// A flight to play back from the start.
    pub play: Option<lensview::flight::Flight>,
}

#[derive(Debug)]
enum UserEvent {
    FrameReady,
    /// A line for the message bar from a thread of the window's (a
    /// screenshot saved, or not).
    Notice(String),
}

struct Viewer {
    opts: ViewOptions,
    /// The window and its surface, once the event loop has resumed.
    screen: Option<Screen>,
    session: Session,
    display: Display,
    flight: flight::Flight,
    /// When the last flight step went (see [`flight::step_due`]).
    last_step: Option<Instant>,
    /// A flight being recorded (F8) or played (`--play`).
    recorder: Option<recorder::Recorder>,
    player: Option<recorder::Player>,
    modifiers: ModifiersState,
    refine: Refine,
    stats: Stats,
    minimised: bool,
    /// When egui asked to run again (animations, tooltips).
    repaint_at: Option<Instant>,
    /// When presents happen (see `pacing`).
    pacer: Pacer,
    /// A present the pacer put off, and when to try again.
    present_at: Option<Instant>,
    /// A redraw was asked for by the viewer itself (else the system asked:
    /// the window must be drawn again).
    asked: bool,
    /// The system asked for a redraw (exposed, mapped): present even if
    /// nothing changed.
    exposed: bool,
    /// Set when the window should close (after any question was answered).
    quit: bool,
    /// Where the left button went down over the picture (a click picks).
    press_at: Option<(f64, f64)>,
    /// What a left-button drag is moving (else it looks around).
    grab: Option<pick::Grab>,
    error: Option<anyhow::Error>,
    /// For threads of the window's to send it events.
    proxy: winit::event_loop::EventLoopProxy<UserEvent>,
}

pub fn run(opts: ViewOptions) -> Result<()> {
    heap::return_large_blocks();
    let event_loop = EventLoop::<UserEvent>::with_user_event().build().map_err(|e| {
        anyhow!(
            "cannot open a window: no display available ({e}); render headless instead: lensview render {} -o out.png",
            opts.scene_path
                .as_deref()
                .map_or(String::new(), |p| p.display().to_string())
        )
    })?;
    watchdog::arm(opts.exit_after);
    let proxy = event_loop.create_proxy();
    let wake = proxy.clone();
    let worker = Worker::spawn(move || {
        let _ = wake.send_event(UserEvent::FrameReady);
    });
    let source = match &opts.scene_path {
        Some(p) => Source::File(p.clone()),
        None => Source::Default,
    };
    let doc = Document::new(opts.scene_file.clone(), source).map_err(|e| anyhow!("invalid scene: {e}"))?;
    let log = match &opts.frame_log {
        Some(p) => Some({
            // Appended to, not replaced: still never a device, FIFO or
            // directory, and a FIFO swapped in cannot block the open.
            lensview::output::check_regular(p).context("--frame-log")?;
            lensview::files::open_append(p).with_context(|| format!("cannot open frame log {}", p.display()))?
        }),
        None => None,
    };
    let player = opts.play.clone().map(recorder::Player::new);
    let mut app = Viewer {
        session: Session::new(doc, panel::UiState::new(opts.scene_path.as_deref())),
        display: Display {
            overlay: overlay::OverlayMode::Compact,
            help: false,
            panel: opts.panel,
            panel_expanded: false,
            res_div: 1,
        },
        refine: Refine::new(worker, opts.max_spp),
        opts,
        screen: None,
        flight: flight::Flight::new(),
        last_step: None,
        recorder: None,
        player,
        modifiers: ModifiersState::empty(),
        stats: Stats::new(log),
        minimised: false,
        repaint_at: None,
        pacer: Pacer::new(false, Pacer::refresh_period(None), 1),
        present_at: None,
        asked: false,
        exposed: false,
        quit: false,
        error: None,
        press_at: None,
        grab: None,
        proxy,
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
        format!("lensview - {}", self.session.doc.title())
    }

    fn update_title(&mut self) {
        let t = self.title();
        if let Some(s) = &mut self.screen {
            s.set_title(t);
        }
    }

    /// Something on screen besides the picture changed: draw again.
    fn request_redraw(&mut self) {
        self.pacer.ui_changed();
        self.ask_redraw();
    }

    fn ask_redraw(&mut self) {
        if let Some(s) = &self.screen {
            self.asked = true;
            s.window.request_redraw();
        }
    }

    /// Starts a new generation of refinement of the document's scene.
    fn submit(&mut self) {
        let Some(size) = self.screen.as_ref().and_then(|s| s.render_size(&self.display)) else {
            return;
        };
        let present_s = self.pacer.present_cost().as_secs_f64();
        self.refine.submit(self.session.doc.built().clone(), size, present_s);
        self.pacer.submitted(Instant::now());
    }

    /// Carries out what the keys or the panel asked: restart refinement
    /// when the picture changed, drop the picture of a replaced document,
    /// the window's own commands, the title, a redraw.
    fn settle(&mut self) {
        let Outcome {
            change,
            new_document,
            redraw,
            commands,
        } = self.session.take_outcome();
        if new_document {
            self.refine.clear_frame();
        }
        if let Some(c) = change {
            self.refine.changed(c);
        }
        if change.is_some_and(|c| c.resubmits()) {
            self.submit();
        }
        for c in commands {
            self.command(c);
        }
        self.update_title();
        if redraw {
            self.request_redraw();
        }
    }

    fn command(&mut self, c: Command) {
        match c {
            Command::Quit => self.quit = true,
            Command::ShowPanel(shown) => {
                if shown != self.display.panel {
                    self.display.panel = shown;
                    // Asked for by name: shown whole, even in a narrow window.
                    self.display.panel_expanded = shown;
                    self.flight.end_drag();
                    self.resize_buffers();
                }
            }
            Command::ExpandPanel(open) => {
                if open != self.display.panel_expanded {
                    self.display.panel_expanded = open;
                    self.flight.end_drag();
                    self.resize_buffers();
                }
            }
            Command::Resolution(div) => {
                let div = div.clamp(1, 8);
                if div != self.display.res_div {
                    self.display.res_div = div;
                    self.session.message = format!("resolution {}%", 100 / div);
                    self.resize_buffers();
                }
            }
            Command::SampleCap(spp) => {
                if self.refine.set_max_spp(spp) {
                    self.session.message = format!("sample cap {} per pixel", self.refine.max_spp());
                    self.submit();
                }
            }
            Command::TogglePause => {
                if self.refine.toggle_pause() {
                    self.session.message = "refinement paused (Space resumes)".into();
                } else {
                    self.session.message = "refinement resumed".into();
                    self.submit();
                }
            }
            Command::ToggleRecording => self.toggle_recording(),
            Command::Screenshot => {
                let proxy = self.proxy.clone();
                let notify = move |line| {
                    let _ = proxy.send_event(UserEvent::Notice(line));
                };
                let tone = self.session.doc.built().tone;
                self.session.message = self.refine.screenshot(self.opts.screenshots.clone(), tone, notify);
            }
        }
    }

    /// Fits the framebuffer to the window and restarts refinement at the
    /// new size (paused, the new size is shown at one sample per pixel).
    fn resize_buffers(&mut self) {
        let Some(screen) = &mut self.screen else { return };
        self.minimised = screen.is_minimised();
        if self.minimised {
            return;
        }
        if let Err(e) = screen.resize(&self.display) {
            self.session.message = format!("resize failed: {e}");
            return;
        }
        self.refine.clear_frame();
        self.submit();
        self.request_redraw();
    }

    /// The overlay's lines for the frame being drawn.
    fn overlay_lines(&self) -> Vec<String> {
        let timing = self.stats.timing_lines(self.refine.frame(), self.refine.paused());
        let s = &self.session;
        stats::overlay_lines(
            self.display.overlay,
            self.title(),
            timing,
            &s.doc,
            self.flight.speed,
            &s.message,
        )
    }

    /// Runs the UI pass: the panel (also when hidden, the questions and
    /// file dialogs still show), the overlay `lines` and the key help; then
    /// carries out what it asked. Returns whether the UI looks different.
    fn run_ui(&mut self, lines: &[String]) -> bool {
        let Some(screen) = &mut self.screen else { return false };
        let picture = screen.picture_rect(&self.display);
        let pic = optics::picture(screen, &self.display);
        let mut cx = panel::Ctx {
            session: &mut self.session,
            display: &mut self.display,
            speed: &mut self.flight.speed,
            render: panel::RenderState {
                paused: self.refine.paused(),
                max_spp: self.refine.max_spp(),
                frame: self.refine.frame(),
            },
        };
        let (delay, changed) = screen.gui.run(&screen.window, |ui| {
            overlay::show(ui.ctx(), picture, lines);
            panel::show(ui, &mut cx);
            optics::overlay(ui.ctx(), cx.session, pic);
            // Markers and the selection's outline are overlay: F1's "off"
            // leaves the bare picture.
            if let Some(pic) = pic.filter(|_| cx.display.overlay != overlay::OverlayMode::Off) {
                let selected = cx.session.ui.selected;
                if let Some(r) = pick::paint(ui.ctx(), &cx.session.doc, pic, selected)
                    && let Some(item) = selected
                {
                    let name = format!("selected {}", cx.session.doc.item_name(item));
                    cx.session.ui.note_rect(&name, r, ui.ctx().pixels_per_point());
                }
            }
            overlay::help_window(ui.ctx(), &mut cx.display.help);
        });
        self.repaint_at = delay.map(|d| Instant::now() + d);
        if delay == Some(Duration::ZERO) {
            self.request_redraw();
        }
        self.session.ui.write_rects(self.opts.ui_log.as_deref());
        self.settle();
        changed
    }

    fn draw(&mut self) {
        if self.minimised {
            return;
        }
        match self.pacer.decide(Instant::now()) {
            Decision::Skip => return,
            Decision::At(t) => {
                self.present_at = Some(t);
                return;
            }
            Decision::Now => self.present_at = None,
        }
        let lines = self.overlay_lines();
        let changed = self.run_ui(&lines);
        if !changed && !self.pacer.has_new_frame() && !std::mem::take(&mut self.exposed) {
            self.pacer.unchanged();
            return;
        }
        let Some(screen) = &mut self.screen else { return };
        let t0 = Instant::now();
        let (x0, result) = match screen.present(&self.display, self.refine.frame()) {
            Shown::Nothing => return,
            Shown::Settling(t) => {
                // Presented when the size has settled, changed or not.
                self.present_at = t;
                self.exposed = true;
                return;
            }
            Shown::Presented(x0, result) => (x0, result),
        };
        if let Err(e) = result {
            self.session.message = format!("present failed: {e}");
        }
        self.pacer.presented(Instant::now(), t0.elapsed());
        self.refine.shown();
        // Taken only with a frame to log: a line without one is not written.
        let stages = match self.refine.frame() {
            Some(_) => self.refine.take_stages(),
            None => Vec::new(),
        };
        let p = Presented {
            frame: self.refine.frame(),
            x0,
            input_time: self.refine.input_time(),
            stages: &stages,
            overlay: self.display.overlay.label(),
        };
        self.stats.presented(t0, p);
    }

    /// One flight step for the held keys and the drag, once per frame
    /// shown (the frame of the last step has arrived: [`flight::step_due`]);
    /// false when nothing is held or dragged.
    fn fly(&mut self) -> bool {
        if !self.flight.wants_step() {
            return false;
        }
        let now = Instant::now();
        if !flight::step_due(now, self.last_step, self.refine.answered(), self.pacer.refresh()) {
            return true;
        }
        let pose = self.session.doc.camera_pose();
        if let Some((pos, rot)) = self.flight.tick(self.modifiers.shift_key(), pose) {
            self.last_step = Some(now);
            self.move_camera(pos, rot);
        }
        true
    }

    /// Flight and mouse-look: one undo step per gesture.
    fn move_camera(&mut self, pos: glam::DVec3, rot: glam::DVec3) {
        match self.session.doc.fly_camera(pos, rot) {
            Ok(c) => self.session.changed(c),
            Err(e) => self.session.message = format!("not applied: {e}"),
        }
        self.settle();
    }

    /// When the loop should wake next, if not for an event: while flying,
    /// at egui's request, and to check `--exit-after`.
    fn next_wake(&mut self, flying: bool) -> Option<Instant> {
        let mut wake: Option<Instant> = None;
        if flying {
            // Keep stepping while a key is held: the frame of the last step
            // wakes the loop when it comes; this, a refresh after it.
            wake = Some(Instant::now() + self.pacer.refresh().min(Duration::from_millis(16)));
        }
        if due(&mut self.repaint_at, &mut wake) {
            self.request_redraw();
        }
        if due(&mut self.present_at, &mut wake) {
            self.ask_redraw();
        }
        if let Some(limit) = self.opts.exit_after {
            let left = (limit - self.stats.started.elapsed().as_secs_f64()).max(0.0);
            let t = Instant::now() + Duration::from_secs_f64(left.min(0.25));
            wake = Some(wake.map_or(t, |w| w.min(t)));
        }
        wake
    }
}

/// Whether the instant in `slot` has come (then it is taken); if not, the
/// loop's next `wake` is brought forward to it.
fn due(slot: &mut Option<Instant>, wake: &mut Option<Instant>) -> bool {
    let Some(t) = *slot else { return false };
    if t <= Instant::now() {
        *slot = None;
        return true;
    }
    *wake = Some(wake.map_or(t, |w| w.min(t)));
    false
}

impl ApplicationHandler<UserEvent> for Viewer {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.screen.is_some() {
            return;
        }
        match Screen::open(event_loop, (self.opts.width, self.opts.height), self.title()) {
            Ok(s) => {
                let cores = std::thread::available_parallelism().map_or(1, |n| n.get() as u32);
                self.pacer = Pacer::new(s.cpu_adapter(), Pacer::refresh_period(s.refresh_millihertz()), cores);
                if s.cpu_adapter() {
                    self.refine.hold_first_frames();
                }
                self.screen = Some(s);
            }
            Err(e) => {
                self.error = Some(e);
                event_loop.exit();
                return;
            }
        }
        self.resize_buffers();
    }

    fn user_event(&mut self, _: &ActiveEventLoop, event: UserEvent) {
        match event {
            UserEvent::FrameReady => {
                if self.refine.receive()
                    && let Some(f) = self.refine.frame()
                {
                    self.pacer.frame_arrived(f.generation);
                    self.ask_redraw();
                }
            }
            UserEvent::Notice(line) => {
                self.session.message = line;
                self.ask_redraw();
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        // egui sees every event but the redraw; what it consumes (a click on
        // the panel, typing in a field) does not also fly the camera.
        let mut consumed = false;
        if !matches!(event, WindowEvent::RedrawRequested)
            && let Some(s) = &mut self.screen
        {
            let r = s.gui.on_event(&s.window, &event);
            consumed = r.consumed;
            if r.repaint {
                self.request_redraw();
            }
        }
        match event {
            WindowEvent::CloseRequested => {
                self.session.ui.file_dialog = None;
                self.session.perform(panel::Pending::Quit, true);
                self.settle();
            }
            WindowEvent::Resized(_) => self.resize_buffers(),
            WindowEvent::RedrawRequested => {
                // Not asked for by the viewer: the system needs the window
                // drawn again (exposed, mapped).
                if !std::mem::take(&mut self.asked) {
                    self.pacer.ui_changed();
                    self.exposed = true;
                }
                self.draw();
            }
            WindowEvent::ModifiersChanged(m) => self.modifiers = m.state(),
            WindowEvent::Focused(false) => self.flight.release_keys(),
            WindowEvent::KeyboardInput {
                event, is_synthetic, ..
            } => self.keyboard_input(&event, is_synthetic, consumed),
            WindowEvent::MouseInput { state, button, .. } => self.mouse_button(state, button, consumed),
            WindowEvent::CursorMoved { position, .. } => self.cursor_moved(position.x, position.y),
            WindowEvent::MouseWheel { delta, .. } if !consumed => self.wheel(delta),
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
            && self.stats.started.elapsed().as_secs_f64() >= limit
        {
            event_loop.exit();
            return;
        }
        let flying = self.fly() | self.play();
        if let Some(r) = &mut self.recorder {
            r.sample(&self.session.doc);
        }
        // A gesture ends when nothing is held, dragged or typed: the next
        // edit is a new undo step.
        let ui_busy = self
            .screen
            .as_ref()
            .is_some_and(|s| s.gui.typing() || s.gui.ctx.egui_is_using_pointer());
        if !flying && !self.flight.is_dragging() && self.grab.is_none() && !ui_busy {
            self.session.doc.seal();
        }
        event_loop.set_control_flow(match self.next_wake(flying) {
            Some(t) => ControlFlow::WaitUntil(t),
            None => ControlFlow::Wait,
        });
    }
}

impl Viewer {
    /// F8: starts recording a flight, or ends it and writes the file.
    fn toggle_recording(&mut self) {
        self.session.message = match self.recorder.take() {
            None => {
                self.recorder = Some(recorder::Recorder::start(&self.session.doc));
                "recording the flight (F8 stops)".into()
            }
            Some(r) => match r.finish(&self.session.doc) {
                Ok((path, poses, secs)) => format!(
                    "flight saved: {} ({poses} poses, {secs:.1} s); render it with lensview film",
                    path.display()
                ),
                Err(e) => format!("the flight was not saved: {e}"),
            },
        };
        self.request_redraw();
    }

    /// One step of the flight played back (`--play`): false when none is.
    fn play(&mut self) -> bool {
        let Some(player) = &mut self.player else {
            return false;
        };
        // As the keys fly: from the first picture on, one step per frame
        // shown (a step per event cancelled every picture before it came).
        let now = Instant::now();
        if self.refine.frame().is_none()
            || !flight::step_due(now, self.last_step, self.refine.answered(), self.pacer.refresh())
        {
            return true;
        }
        self.last_step = Some(now);
        let Some((scene, pose)) = player.step() else {
            self.player = None;
            self.session.message = "the flight is over".into();
            return false;
        };
        if let Some(sf) = scene {
            let applied = self.session.doc.edit("the flight's edit", |s| {
                let camera = s.camera.clone();
                *s = sf;
                s.camera = camera;
            });
            if let Ok(c) = applied {
                self.session.changed(c);
            }
        }
        match pose.fov {
            Some(fov) if fov != self.session.doc.built().camera.fov_y_deg => {
                if let Ok(c) = self.session.doc.set_camera(pose.position, pose.rotation_deg, fov) {
                    self.session.changed(c);
                }
                self.settle();
            }
            _ => self.move_camera(pose.position, pose.rotation_deg),
        }
        true
    }
}
