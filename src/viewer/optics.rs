//! Optics over the picture (F6, or *Show optics* in the Lens section): for
//! the lens the panel shows, the optical axis, the vertices V1 and V2, the
//! focal points F and F′ as markers, the principal planes H and H′ as thin
//! rings of diameter d, and a fan of 7 real meridional rays — parallel to
//! the axis, or from the object point the analysis window sets — traced by
//! `Lens::trace` (whose inside pass is `Lens::propagate_inside`'s, the
//! renderer's), entering through S1 as in `lens info`. Labels say F' and
//! H' (egui's font has no ′). The figure and its projection are the
//! library's (`lens_tools::overlay`, which the web page draws too); this
//! paints them.
//!
//! Drawn with egui on a background layer (under the windows), clipped to the picture, with the
//! camera's own projection (the inverse of `Camera::ray`): **on top, not
//! depth-tested**, lines half transparent so the picture shows through.
//! It is display only: toggling it or moving it never restarts refinement.

use lensview::camera::Camera;
pub use lensview::lens_tools::overlay::project;
use lensview::lens_tools::overlay::{Figure, Projected, Role, scene_figure};
use lensview::scene::Scene;

use super::screen::{Display, Screen};
use super::session::Session;

/// Where the picture lies in the window: its first framebuffer column, its
/// render size, and the window's size (physical pixels); the framebuffer is
/// scaled up by a whole factor and centred, as `pixels` draws it.
#[derive(Clone, Copy, Debug)]
pub struct Picture {
    pub x0: u32,
    pub size: (u32, u32),
    pub window: (u32, u32),
}

impl Picture {
    /// The whole factor the framebuffer is scaled up by, and the window
    /// position (physical pixels) of its corner.
    fn layout(&self) -> (f64, [f64; 2]) {
        let (bw, bh) = (self.x0 + self.size.0, self.size.1);
        let s = (f64::from(self.window.0) / f64::from(bw))
            .min(f64::from(self.window.1) / f64::from(bh))
            .floor()
            .max(1.0);
        let off = [
            0.5 * (f64::from(self.window.0) - s * f64::from(bw)),
            0.5 * (f64::from(self.window.1) - s * f64::from(bh)),
        ];
        (s, off)
    }

    /// A continuous picture position in window pixels (physical).
    pub fn window_point(&self, p: [f64; 2]) -> [f64; 2] {
        let (s, off) = self.layout();
        [off[0] + s * (f64::from(self.x0) + p[0]), off[1] + s * p[1]]
    }

    /// The picture position under window pixel `w` (physical), if it is
    /// on the picture: the inverse of [`Self::window_point`].
    pub fn picture_point(&self, w: [f64; 2]) -> Option<[f64; 2]> {
        let (s, off) = self.layout();
        let p = [(w[0] - off[0]) / s - f64::from(self.x0), (w[1] - off[1]) / s];
        let inside = p[0] >= 0.0 && p[1] >= 0.0 && p[0] < f64::from(self.size.0) && p[1] < f64::from(self.size.1);
        inside.then_some(p)
    }

    /// Window pixels (physical) per picture pixel.
    pub fn scale(&self) -> f64 {
        self.layout().0
    }
}

/// A painter over the picture, clipped to it, on its own background layer
/// `id`, and the map from picture positions to its points.
pub struct Canvas {
    pub painter: egui::Painter,
    pic: Picture,
    ppp: f64,
}

impl Canvas {
    pub fn new(ctx: &egui::Context, pic: Picture, id: &'static str) -> Canvas {
        let ppp = f64::from(ctx.pixels_per_point());
        let painter = ctx.layer_painter(egui::LayerId::new(egui::Order::Background, egui::Id::new(id)));
        let mut canvas = Canvas { painter, pic, ppp };
        let size = [f64::from(pic.size.0), f64::from(pic.size.1)];
        let clip = egui::Rect::from_min_max(canvas.pt([0.0, 0.0]), canvas.pt(size));
        canvas.painter.set_clip_rect(clip);
        canvas
    }

    /// The point (logical) of continuous picture position `p`.
    pub fn pt(&self, p: [f64; 2]) -> egui::Pos2 {
        let w = self.pic.window_point(p);
        egui::pos2((w[0] / self.ppp) as f32, (w[1] / self.ppp) as f32)
    }
}

/// A role's colour in egui.
const fn colour(role: Role) -> egui::Color32 {
    let [r, g, b, a] = role.premultiplied();
    egui::Color32::from_rgba_premultiplied(r, g, b, a)
}

/// F′'s marker colour (also what tests/window.rs looks for).
pub const F_BACK: egui::Color32 = colour(Role::BackFocus);

/// Paints `fig` over the picture: [`Projected`]'s segments and labels.
pub fn paint(ctx: &egui::Context, cam: &Camera, pic: Picture, fig: &Figure) {
    let canvas = Canvas::new(ctx, pic, "lensview-optics");
    let (painter, to_pt) = (&canvas.painter, |p| canvas.pt(p));
    let proj = Projected::new(cam, pic.size, fig);
    for (role, a, b) in &proj.segments {
        painter.line_segment(
            [to_pt(*a), to_pt(*b)],
            egui::Stroke::new(role.width() as f32, colour(*role)),
        );
    }
    let font = egui::FontId::proportional(15.0);
    let height = painter.layout_no_wrap("F".into(), font.clone(), F_BACK).size().y;
    // Label spots in points from the picture's corner (placement only
    // compares labels with each other, so the corner's offset is added after).
    let scale = pic.scale() / f64::from(ctx.pixels_per_point());
    let corner = to_pt([0.0, 0.0]);
    for (l, [x, y]) in proj.labels.iter().zip(proj.label_spots(scale, f64::from(height))) {
        let c = colour(l.role);
        if l.disc {
            painter.circle_filled(to_pt(l.at), 5.0, c);
        }
        let g = painter.layout_no_wrap(l.text.to_string(), font.clone(), c);
        let at = corner + egui::vec2(x as f32, y as f32 - g.size().y);
        let r = egui::Rect::from_min_size(at, g.size()).expand(2.0);
        painter.rect_filled(r, 2.0, egui::Color32::from_black_alpha(170));
        painter.galley(r.min + egui::vec2(2.0, 2.0), g, c);
    }
}

/// The figure for lens `index` of `scene` (if it has one), painted; for
/// lens system `system` instead when given.
pub fn show(
    ctx: &egui::Context,
    scene: &Scene,
    (index, system): (usize, Option<usize>),
    pic: Picture,
    object_distance: Option<f64>,
) {
    if let Some(fig) = scene_figure(scene, index, system, object_distance) {
        paint(ctx, &scene.camera, pic, &fig);
    }
}

/// Where the picture is now (`None` while the window has no size).
pub fn picture(screen: &Screen, d: &Display) -> Option<Picture> {
    let size = screen.render_size(d)?;
    let w = screen.window.inner_size();
    Some(Picture {
        x0: screen.panel_columns(d),
        size,
        window: (w.width, w.height),
    })
}

/// The overlay, when switched on, for the lens the panel shows, from the
/// document as this UI pass left it.
pub fn overlay(ctx: &egui::Context, s: &Session, pic: Option<Picture>) {
    let a = &s.ui.analysis;
    if let (true, Some(pic)) = (a.optics, pic) {
        // A selected lens system; else the panel's lens; in a scene
        // without one, the first system.
        let scene = s.doc.built();
        let system = match s.ui.selected {
            Some(lensview::edit::Item::System(i)) => Some(i),
            _ if !scene.objects.iter().any(|o| o.lens().is_some()) => Some(0),
            _ => None,
        };
        show(ctx, scene, (s.ui.lens, system), pic, a.object());
    }
}
