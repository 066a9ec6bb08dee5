//! The window's surface: the `winit` window, the `pixels` framebuffer at
//! 1/`res_div` of its size, egui on top, and the title. The picture is
//! copied in right of the panel's columns, then egui (panel, overlay,
//! dialogs) painted over it.

use super::gui::Gui;
use super::overlay::OverlayMode;
use super::panel::{NARROW, PANEL_WIDTH, STRIP_WIDTH};
use super::settle::{Gate, SurfaceGate, Try, acquire};
use anyhow::{Result, anyhow};
use lensview::render::worker::Frame;
use pixels::{Pixels, SurfaceTexture};
use std::sync::Arc;
use std::time::Instant;
use winit::dpi::PhysicalSize;
use winit::event_loop::ActiveEventLoop;
use winit::window::Window;

/// What is shown, as opposed to what is rendered.
pub struct Display {
    /// The figures and message drawn over the picture (F1 cycles).
    pub overlay: OverlayMode,
    /// The key help window (F2).
    pub help: bool,
    /// The editing panel (F4).
    pub panel: bool,
    /// In a window narrower than [`NARROW`] the panel is a strip with a
    /// button that opens it; true once the user opened it there.
    pub panel_expanded: bool,
    /// Render at 1/res_div of the window's resolution (F3: 2).
    pub res_div: u32,
}

/// How the panel is shown.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PanelShape {
    Hidden,
    /// A strip with the button that opens the panel (narrow windows).
    Strip,
    Full,
}

impl Display {
    /// The panel's shape in a window `width` points wide.
    pub fn panel_shape(&self, width: f32) -> PanelShape {
        if !self.panel {
            PanelShape::Hidden
        } else if width < NARROW && !self.panel_expanded {
            PanelShape::Strip
        } else {
            PanelShape::Full
        }
    }

    /// The panel's width in points in a window `width` points wide.
    pub fn panel_width(&self, width: f32) -> f32 {
        match self.panel_shape(width) {
            PanelShape::Hidden => 0.0,
            PanelShape::Strip => STRIP_WIDTH,
            PanelShape::Full => PANEL_WIDTH,
        }
    }
}

pub struct Screen {
    pub window: Arc<Window>,
    pixels: Pixels<'static>,
    pub gui: Gui,
    title: String,
    /// The size the surface was last configured at.
    surface: (u32, u32),
    /// When a new window size reaches the surface.
    gate: SurfaceGate,
}

/// How soon a present that got no surface texture is tried again.
const RETRY: std::time::Duration = std::time::Duration::from_millis(50);

/// What [`Screen::present`] did.
pub enum Shown {
    /// Nothing to draw into.
    Nothing,
    /// Not presented: the surface waits for the window's size to settle
    /// (ask again at the instant; `None`: at the next resize).
    Settling(Option<Instant>),
    /// Presented: the picture's first column and whether presenting worked.
    Presented(u32, Result<(), String>),
}

impl Screen {
    /// Opens the window (`width`×`height` pixels) and its surface.
    pub fn open(event_loop: &ActiveEventLoop, (width, height): (u32, u32), title: String) -> Result<Screen> {
        let attrs = Window::default_attributes()
            .with_title(&title)
            .with_inner_size(PhysicalSize::new(width, height))
            .with_min_inner_size(PhysicalSize::new(1, 1));
        let window = Arc::new(
            event_loop
                .create_window(attrs)
                .map_err(|e| anyhow!("cannot create a window: {e}"))?,
        );
        let size = window.inner_size();
        let (w, h) = (size.width.max(1), size.height.max(1));
        // No vsync: a frame is presented as soon as it is rendered; waiting
        // for a vertical blank would add up to a refresh period of latency.
        let pixels = pixels::PixelsBuilder::new(w, h, SurfaceTexture::new(w, h, window.clone()))
            .enable_vsync(false)
            .build()
            .map_err(|e| {
                anyhow!("cannot draw into the window ({e}); render headless instead: lensview render -o out.png")
            })?;
        let gui = Gui::new(&window, &pixels);
        Ok(Screen {
            window,
            pixels,
            gui,
            title,
            surface: (w, h),
            gate: SurfaceGate::default(),
        })
    }

    /// Whether the adapter is a CPU rasterizer (lavapipe, llvmpipe): its
    /// presents take cores from the tracer.
    pub fn cpu_adapter(&self) -> bool {
        self.pixels.adapter().get_info().device_type == pixels::wgpu::DeviceType::Cpu
    }

    /// The refresh rate of the window's monitor, if it says.
    pub fn refresh_millihertz(&self) -> Option<u32> {
        self.window.current_monitor()?.refresh_rate_millihertz()
    }

    pub fn set_title(&mut self, title: String) {
        if title != self.title {
            self.window.set_title(&title);
            self.title = title;
        }
    }

    pub fn is_minimised(&self) -> bool {
        let s = self.window.inner_size();
        s.width == 0 || s.height == 0
    }

    /// The framebuffer: the window at 1/res_div.
    pub fn buffer_size(&self, d: &Display) -> Option<(u32, u32)> {
        let s = self.window.inner_size();
        if s.width == 0 || s.height == 0 {
            return None;
        }
        Some(((s.width / d.res_div).max(1), (s.height / d.res_div).max(1)))
    }

    /// Columns of the framebuffer under the panel; the picture starts there.
    pub fn panel_columns(&self, d: &Display) -> u32 {
        let Some((bw, _)) = self.buffer_size(d) else {
            return 0;
        };
        let scale = self.window.scale_factor();
        let points = (self.window.inner_size().width as f64 / scale) as f32;
        let px = (d.panel_width(points) as f64 * scale).ceil() as u32;
        px.div_ceil(d.res_div).min(bw.saturating_sub(1))
    }

    /// The size the picture is rendered at: the framebuffer right of the panel.
    pub fn render_size(&self, d: &Display) -> Option<(u32, u32)> {
        let (bw, bh) = self.buffer_size(d)?;
        Some(((bw - self.panel_columns(d)).max(1), bh))
    }

    /// Fits the framebuffer to `d` (the surface follows in
    /// [`Screen::present`], once the window's size has settled).
    pub fn resize(&mut self, d: &Display) -> Result<(), String> {
        let Some((bw, bh)) = self.buffer_size(d) else {
            return Ok(());
        };
        self.pixels.resize_buffer(bw, bh).map_err(|e| e.to_string())
    }

    /// Whether the surface may be presented to now, configured at the
    /// window's size first when that differs from the last one and has
    /// settled ([`SurfaceGate`]). pixels' `render_with` retries an
    /// out-of-date surface at its stored size without bound: presenting
    /// after the window was resized, before the `Resized` event, spun there
    /// for ever (found by `benches/soak.sh`), so the size is checked before
    /// every present.
    fn fit_surface(&mut self, width: u32, height: u32) -> Result<Gate, String> {
        let gate = self.gate.check(self.surface, (width, height), Instant::now());
        if gate == Gate::Configure {
            self.pixels.resize_surface(width, height).map_err(|e| e.to_string())?;
            self.surface = (width, height);
        }
        Ok(gate)
    }

    /// Where the picture is, in egui's points: right of the panel.
    pub fn picture_rect(&self, d: &Display) -> egui::Rect {
        let s = self.window.inner_size();
        let ppp = self.window.scale_factor() as f32;
        let x0 = (self.panel_columns(d) * d.res_div) as f32 / ppp;
        egui::Rect::from_min_max(
            egui::pos2(x0, 0.0),
            egui::pos2(s.width as f32 / ppp, s.height as f32 / ppp),
        )
    }

    /// Draws `frame` right of the panel and the last UI pass (panel,
    /// overlay, dialogs) over it, and presents (see [`Shown`]).
    pub fn present(&mut self, d: &Display, frame: Option<&Frame>) -> Shown {
        let Some((bw, bh)) = self.buffer_size(d) else {
            return Shown::Nothing;
        };
        let x0 = self.panel_columns(d);
        let (w, h) = ((bw - x0).max(1), bh);
        let buf = self.pixels.frame_mut();
        if buf.len() != (bw * bh * 4) as usize {
            return Shown::Nothing;
        }
        let (row, fw) = (bw as usize * 4, w as usize * 4);
        match frame {
            Some(f) if f.width == w && f.height == h && f.rgba.len() == fw * h as usize => {
                // (Columns 0..x0 lie under the panel or its strip.)
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
        let size = self.window.inner_size();
        // A window with no area (minimised) or a new size not settled yet:
        // skip the frame (pixels would retry an out-of-date surface without
        // bound); the redraw at the instant, or after the next resize,
        // presents.
        match self.fit_surface(size.width, size.height) {
            Err(e) => return Shown::Presented(x0, Err(e)),
            Ok(Gate::Wait(t)) => return Shown::Settling(t),
            Ok(Gate::Ready | Gate::Configure) => {}
        }
        use pixels::wgpu::CurrentSurfaceTexture as C;
        let pixels = &self.pixels;
        let texture = acquire(
            || match pixels.current_texture() {
                C::Success(t) => Try::Got(t),
                C::Suboptimal(t) => Try::Stale(Some(t)),
                C::Outdated | C::Lost => Try::Stale(None),
                C::Occluded | C::Timeout => Try::Skip,
                C::Validation => Try::Fail("wgpu validation error".into()),
            },
            || pixels.reconfigure(),
        );
        let texture = match texture {
            Ok(Some(t)) => t,
            // No texture now: the next present tries again shortly.
            Ok(None) => return Shown::Settling(Some(Instant::now() + RETRY)),
            Err(e) => return Shown::Presented(x0, Err(e)),
        };
        let gui = &mut self.gui;
        let result = pixels.render_to(texture, |encoder, target, context| {
            context.scaling_renderer.render(encoder, target);
            gui.paint(encoder, target, context);
            Ok(())
        });
        Shown::Presented(x0, result.map_err(|e| e.to_string()))
    }
}
