//! The window: a `winit` event loop over a `pixels` framebuffer. The render
//! thread (`lensview::render::worker`) refines the picture and wakes the loop
//! for every frame; the window drops frames of an older generation, draws the
//! newest with the overlay, and never waits for the renderer.

mod keys;
mod overlay;

use anyhow::{Context, Result, anyhow};
use glam::DVec3;
use keys::{Action, help_lines};
use lensview::edit::{self, Edit};
use lensview::render::progressive::{Progressive, Stage};
use lensview::render::worker::{Frame, Job, Worker};
use lensview::scene::{Scene, SceneFile};
use pixels::{Pixels, SurfaceTexture};
use std::collections::HashSet;
use std::io::Write;
use std::path::PathBuf;
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
    /// The scene as a file model (what edits change) and the camera, which
    /// the viewer owns while flying.
    scene_file: SceneFile,
    scene: Arc<Scene>,
    home: (DVec3, DVec3),
    cam_pos: DVec3,
    cam_rot: DVec3,
    speed: f64,
    window: Option<Arc<Window>>,
    pixels: Option<Pixels<'static>>,
    worker: Worker,
    generation: u64,
    input_time: Instant,
    /// Newest frame of the current generation.
    frame: Option<Frame>,
    held: HashSet<KeyCode>,
    shift: bool,
    dragging: Option<(f64, f64)>,
    cursor: (f64, f64),
    last_step: Instant,
    overlay: bool,
    help: bool,
    half_res: bool,
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
    let scene =
        Scene::build(&opts.scene_file).map_err(|p| anyhow!("invalid scene: {}: {}", p[0].path, p[0].message))?;
    let home = (scene.camera.position, scene.camera.rotation_deg);
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
        scene_file: opts.scene_file.clone(),
        opts,
        scene: Arc::new(scene),
        home,
        cam_pos: home.0,
        cam_rot: home.1,
        speed: 3.0,
        window: None,
        pixels: None,
        worker,
        generation: 0,
        input_time: Instant::now(),
        frame: None,
        held: HashSet::new(),
        shift: false,
        dragging: None,
        cursor: (0.0, 0.0),
        last_step: Instant::now(),
        overlay: true,
        help: false,
        half_res: false,
        message: "F2: help".into(),
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
    };
    event_loop.run_app(&mut app).context("event loop failed")?;
    match app.error.take() {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

impl Viewer {
    fn title(&self) -> String {
        let name = self
            .opts
            .scene_path
            .as_ref()
            .map_or("default scene".to_string(), |p| p.display().to_string());
        format!("lensview - {name}")
    }

    fn render_size(&self) -> Option<(u32, u32)> {
        let w = self.window.as_ref()?;
        let s = w.inner_size();
        if s.width == 0 || s.height == 0 {
            return None;
        }
        let div = if self.half_res { 2 } else { 1 };
        Some(((s.width / div).max(1), (s.height / div).max(1)))
    }

    /// Rebuilds the render model from the file model and the flying camera,
    /// and starts a new generation.
    fn restart(&mut self) {
        let mut sf = self.scene_file.clone();
        sf.camera.position = self.cam_pos.to_array();
        sf.camera.rotation = Some(self.cam_rot.to_array());
        sf.camera.look_at = None;
        match Scene::build(&sf) {
            Ok(s) => self.scene = Arc::new(s),
            Err(p) => self.message = format!("not applied: {}: {}", p[0].path, p[0].message),
        }
        self.submit();
    }

    fn submit(&mut self) {
        let Some((w, h)) = self.render_size() else { return };
        self.generation += 1;
        self.input_time = Instant::now();
        self.worker.submit(Job {
            generation: self.generation,
            scene: self.scene.clone(),
            width: w,
            height: h,
            max_spp: self.opts.max_spp,
            seed: 0,
            input_time: self.input_time,
        });
    }

    fn fly(&mut self) -> bool {
        let now = Instant::now();
        let dt = (now - self.last_step).as_secs_f64().min(0.1);
        self.last_step = now;
        let held: Vec<Action> = self
            .held
            .iter()
            .filter_map(|k| keys::action_for(*k))
            .filter(|a| a.is_held())
            .collect();
        if held.is_empty() {
            return false;
        }
        let cam = lensview::camera::Camera::new(self.cam_pos, self.cam_rot, 45.0);
        let (f, r) = (cam.forward(), cam.right());
        let step = self.speed * if self.shift { 4.0 } else { 1.0 } * dt;
        let turn = TURN_RATE * dt;
        for a in held {
            match a {
                Action::Forward => self.cam_pos += f * step,
                Action::Back => self.cam_pos -= f * step,
                Action::Left => self.cam_pos -= r * step,
                Action::Right => self.cam_pos += r * step,
                Action::Up => self.cam_pos += DVec3::Y * step,
                Action::Down => self.cam_pos -= DVec3::Y * step,
                Action::LookLeft => self.cam_rot.y += turn,
                Action::LookRight => self.cam_rot.y -= turn,
                Action::LookUp => self.cam_rot.x = (self.cam_rot.x + turn).min(89.0),
                Action::LookDown => self.cam_rot.x = (self.cam_rot.x - turn).max(-89.0),
                _ => {}
            }
        }
        true
    }

    fn press(&mut self, a: Action, event_loop: &ActiveEventLoop) {
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
            self.message = edit::apply(&mut self.scene_file, e);
        }
        match a {
            Action::ResetView => {
                (self.cam_pos, self.cam_rot) = self.home;
                self.message = "view reset".into();
            }
            // These restart (or not) by themselves: a failed reload keeps
            // the picture, a resolution change resizes first.
            Action::Reload => return self.reload(),
            Action::HalfResolution => {
                self.half_res = !self.half_res;
                self.message = if self.half_res {
                    "half resolution"
                } else {
                    "full resolution"
                }
                .into();
                return self.resize_buffers();
            }
            Action::Screenshot => self.screenshot(),
            Action::ToggleOverlay => self.overlay = !self.overlay,
            Action::ToggleHelp => self.help = !self.help,
            Action::Quit => event_loop.exit(),
            _ => {}
        }
        if a.restarts() {
            self.restart();
        } else if let Some(w) = &self.window {
            w.request_redraw();
        }
    }
}

impl Viewer {
    fn reload(&mut self) {
        let Some(path) = self.opts.scene_path.clone() else {
            self.message = "the embedded scene has no file to reload".into();
            return;
        };
        match Scene::load(&path) {
            Ok((sf, _)) => {
                self.scene_file = sf;
                self.message = format!("reloaded {}", path.display());
                self.restart();
            }
            // Nothing the user made is lost: the current scene stays.
            Err(e) => self.message = format!("reload failed, scene kept: {e}"),
        }
    }

    /// Saves the full-resolution image at the samples refined so far (at
    /// least one), rendered on its own thread so the window stays live.
    fn screenshot(&mut self) {
        let Some((w, h)) = self.render_size() else { return };
        let spp = self.frame.as_ref().map_or(1, |f| f.spp.max(1));
        self.screenshot_n += 1;
        let name = PathBuf::from(format!(
            "lensview-{}-{}.png",
            std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_secs()),
            self.screenshot_n
        ));
        let scene = self.scene.clone();
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
        let Some((w, h)) = self.render_size() else { return };
        if let Some(p) = &mut self.pixels {
            if let Err(e) = p.resize_surface(size.width, size.height) {
                self.message = format!("resize failed: {e}");
                return;
            }
            if let Err(e) = p.resize_buffer(w, h) {
                self.message = format!("resize failed: {e}");
                return;
            }
        }
        self.frame = None;
        self.submit();
    }

    fn overlay_lines(&self) -> Vec<String> {
        let mut v = vec![self.title()];
        let fps = if self.frame_times > 0.0 {
            1000.0 / self.frame_times
        } else {
            0.0
        };
        match &self.frame {
            Some(f) => v.push(format!(
                "{}{} in {:.0} ms  {:.2} M rays/s  frame {:.1} ms ({:.0} fps)  present {:.1} ms",
                f.stage.label(),
                if f.last { " (done)" } else { "" },
                f.render_ms,
                f.samples_per_s / 1e6,
                self.frame_times,
                fps,
                self.present_ms
            )),
            None => v.push("rendering…".into()),
        }
        let r = self.cam_rot;
        v.push(format!(
            "camera ({:.2}, {:.2}, {:.2})  rot x {:.1} y {:.1} z {:.1}  fov {:.0}  speed {:.1}",
            self.cam_pos.x, self.cam_pos.y, self.cam_pos.z, r.x, r.y, r.z, self.scene.camera.fov_y_deg, self.speed
        ));
        if let Some(l) = self.scene_file.lights.first() {
            let p = l.position.or(l.direction).unwrap_or_default();
            v.push(format!(
                "light ({:.2}, {:.2}, {:.2})  intensity {:.1}  colour ({:.2}, {:.2}, {:.2})",
                p[0], p[1], p[2], l.intensity, l.color[0], l.color[1], l.color[2]
            ));
        }
        if let Some(lens) = self.scene.objects.iter().find_map(|o| o.lens()) {
            let n = lens.index.nominal();
            let px = lens.paraxial(n);
            v.push(format!(
                "lens d {:.3}  r1 {:.3}  r2 {:.3}  n {:.4}  EFL {:.4}  BFD {:.4}",
                lens.d, lens.r1, lens.r2, n, px.efl, px.bfd
            ));
        }
        v.push(format!("> {}", self.message));
        if self.help {
            v.extend(help_lines());
        }
        v
    }

    fn draw(&mut self) {
        if self.minimised {
            return;
        }
        let Some((w, h)) = self.render_size() else { return };
        let lines = if self.overlay { Some(self.overlay_lines()) } else { None };
        let Some(pixels) = &mut self.pixels else { return };
        let t0 = Instant::now();
        let buf = pixels.frame_mut();
        match &self.frame {
            Some(f) if f.width == w && f.height == h && buf.len() == f.rgba.len() => buf.copy_from_slice(&f.rgba),
            _ => buf.fill(0),
        }
        if let Some(lines) = lines {
            overlay::draw_lines(buf, w as usize, h as usize, &lines);
        }
        if let Err(e) = pixels.render() {
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
        self.window = Some(window);
        self.pixels = Some(pixels);
        self.resize_buffers();
    }

    fn user_event(&mut self, _: &ActiveEventLoop, event: UserEvent) {
        match event {
            UserEvent::FrameReady => {
                let mut newest = None;
                while let Ok(f) = self.worker.frames.try_recv() {
                    // Frames of an older generation are dropped.
                    if f.generation == self.generation {
                        newest = Some(f);
                    }
                }
                if let Some(f) = newest {
                    self.frame = Some(f);
                    if let Some(w) = &self.window {
                        w.request_redraw();
                    }
                }
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(_) => self.resize_buffers(),
            WindowEvent::RedrawRequested => self.draw(),
            WindowEvent::ModifiersChanged(m) => self.shift = m.state().shift_key(),
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
                let Some(action) = keys::action_for(code) else { return };
                match event.state {
                    ElementState::Pressed if action.is_held() => {
                        if self.held.insert(code) {
                            self.last_step = Instant::now();
                        }
                    }
                    ElementState::Released if action.is_held() => {
                        self.held.remove(&code);
                    }
                    ElementState::Pressed => self.press(action, event_loop),
                    ElementState::Released => {}
                }
            }
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Left,
                ..
            } => {
                self.dragging = (state == ElementState::Pressed).then_some(self.cursor);
            }
            WindowEvent::CursorMoved { position, .. } => {
                self.cursor = (position.x, position.y);
                if let Some((x0, y0)) = self.dragging {
                    let (dx, dy) = (position.x - x0, position.y - y0);
                    self.dragging = Some(self.cursor);
                    self.cam_rot.y -= dx * DRAG_RATE;
                    self.cam_rot.x = (self.cam_rot.x - dy * DRAG_RATE).clamp(-89.0, 89.0);
                    self.restart();
                }
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let steps = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y as f64,
                    MouseScrollDelta::PixelDelta(p) => p.y / 40.0,
                };
                self.speed = (self.speed * 1.2f64.powf(steps)).clamp(0.05, 500.0);
                self.message = format!("flight speed {:.2}", self.speed);
                if let Some(w) = &self.window {
                    w.request_redraw();
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        if let Some(limit) = self.opts.exit_after
            && self.started.elapsed().as_secs_f64() >= limit
        {
            event_loop.exit();
            return;
        }
        if self.fly() {
            self.restart();
            // Keep stepping while a key is held: about one 60 Hz frame.
            event_loop.set_control_flow(ControlFlow::WaitUntil(Instant::now() + Duration::from_millis(16)));
        } else if let Some(limit) = self.opts.exit_after {
            let left = (limit - self.started.elapsed().as_secs_f64()).max(0.0);
            event_loop.set_control_flow(ControlFlow::WaitUntil(
                Instant::now() + Duration::from_secs_f64(left.min(0.25)),
            ));
        } else {
            event_loop.set_control_flow(ControlFlow::Wait);
        }
    }
}
