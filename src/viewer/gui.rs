//! egui on the `pixels` surface: `egui-winit` turns window events into egui
//! input, `egui-wgpu` draws the tessellated UI with the device and queue
//! `pixels` already has. Inside `Pixels::render_with` the scaling renderer
//! draws the picture first and egui follows in a second render pass that
//! loads (does not clear) the target, so the panel lies over the picture.

use pixels::wgpu;
use pixels::{Pixels, PixelsContext};
use std::time::Duration;
use winit::event::WindowEvent;
use winit::window::Window;

pub struct Gui {
    pub ctx: egui::Context,
    state: egui_winit::State,
    renderer: egui_wgpu::Renderer,
    paint: Option<Paint>,
    /// The shapes and window size of the last pass, to tell whether a new
    /// pass looks any different.
    shown: (Vec<egui::epaint::ClippedShape>, [u32; 2]),
}

struct Paint {
    jobs: Vec<egui::ClippedPrimitive>,
    textures: egui::TexturesDelta,
    screen: egui_wgpu::ScreenDescriptor,
}

impl Gui {
    pub fn new(window: &Window, pixels: &Pixels<'_>) -> Self {
        let ctx = egui::Context::default();
        let max_texture_side = pixels.device().limits().max_texture_dimension_2d as usize;
        let state = egui_winit::State::new(
            ctx.clone(),
            egui::ViewportId::ROOT,
            window,
            Some(window.scale_factor() as f32),
            window.theme(),
            Some(max_texture_side),
        );
        let renderer = egui_wgpu::Renderer::new(
            pixels.device(),
            pixels.render_texture_format(),
            egui_wgpu::RendererOptions::default(),
        );
        Gui {
            ctx,
            state,
            renderer,
            paint: None,
            shown: (Vec::new(), [0, 0]),
        }
    }

    /// Hands a window event to egui. Never pass `RedrawRequested`: egui
    /// answers it with "repaint" and the window would redraw forever.
    pub fn on_event(&mut self, window: &Window, event: &WindowEvent) -> egui_winit::EventResponse {
        self.state.on_window_event(window, event)
    }

    /// Whether a text field has the keyboard (then keys are typing, not flying).
    pub fn typing(&self) -> bool {
        self.ctx.text_edit_focused()
    }

    /// Whether a menu or popup is open (Escape is then egui's: it closes it).
    pub fn menu_open(&self) -> bool {
        self.ctx.any_popup_open()
    }

    /// Runs one UI pass and tessellates it for [`Self::paint`]. Returns how
    /// soon egui wants to run again (animations, tooltips), if at all, and
    /// whether the pass looks different from the one before.
    pub fn run(&mut self, window: &Window, ui: impl FnMut(&mut egui::Ui)) -> (Option<Duration>, bool) {
        let raw = self.state.take_egui_input(window);
        let out = self.ctx.run_ui(raw, ui);
        self.state.handle_platform_output(window, out.platform_output);
        let size = window.inner_size();
        let looks = (out.shapes, [size.width, size.height]);
        let changed = looks != self.shown || !out.textures_delta.is_empty();
        self.shown = looks;
        let jobs = self.ctx.tessellate(self.shown.0.clone(), out.pixels_per_point);
        let mut textures = out.textures_delta;
        // Textures not yet uploaded (a frame that was never painted) are kept.
        if let Some(old) = self.paint.take() {
            let mut set = old.textures.set;
            set.extend(textures.set);
            textures.set = set;
            let mut free = old.textures.free;
            free.extend(textures.free);
            textures.free = free;
        }
        self.paint = Some(Paint {
            jobs,
            textures,
            screen: egui_wgpu::ScreenDescriptor {
                size_in_pixels: [size.width, size.height],
                pixels_per_point: out.pixels_per_point,
            },
        });
        let delay = out
            .viewport_output
            .get(&egui::ViewportId::ROOT)
            .map(|v| v.repaint_delay)
            .filter(|d| *d < Duration::from_secs(3600));
        (delay, changed)
    }

    /// Draws the last UI pass over `target` (after the picture).
    pub fn paint(&mut self, encoder: &mut wgpu::CommandEncoder, target: &wgpu::TextureView, context: &PixelsContext) {
        let Some(p) = self.paint.take() else { return };
        for (id, delta) in &p.textures.set {
            self.renderer
                .update_texture(&context.device, &context.queue, *id, delta);
        }
        // Only paint callbacks make command buffers; this UI has none.
        let _ = self
            .renderer
            .update_buffers(&context.device, &context.queue, encoder, &p.jobs, &p.screen);
        {
            let mut pass = encoder
                .begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("egui"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: target,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Load,
                            store: wgpu::StoreOp::Store,
                        },
                        depth_slice: None,
                    })],
                    depth_stencil_attachment: None,
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                })
                .forget_lifetime();
            self.renderer.render(&mut pass, &p.jobs, &p.screen);
        }
        for id in &p.textures.free {
            self.renderer.free_texture(id);
        }
    }
}
