//! Optics over the picture (F6, or *Show optics* in the Lens section): for
//! the lens the panel shows, the optical axis, the vertices V1 and V2, the
//! focal points F and F′ as markers, the principal planes H and H′ as thin
//! rings of diameter d, and a fan of 7 real meridional rays — parallel to
//! the axis, or from the object point the analysis window sets — traced by
//! `Lens::trace` (whose inside pass is `Lens::propagate_inside`'s, the
//! renderer's), entering through S1 as in `lens info`. Labels say F' and
//! H' (egui's font has no ′).
//!
//! Drawn with egui on a background layer (under the windows), clipped to the picture, with the
//! camera's own projection (the inverse of `Camera::ray`): **on top, not
//! depth-tested**, lines half transparent so the picture shows through.
//! It is display only: toggling it or moving it never restarts refinement.

use glam::DVec3;
use lensview::camera::Camera;
use lensview::geometry::{Lens, LensSurface, LensSystem};
use lensview::lens_tools::sketch::place_label;
use lensview::optics::WAVELENGTH_D_UM;
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

/// F′'s marker colour (also what tests/window.rs looks for).
pub const F_BACK: egui::Color32 = egui::Color32::from_rgb(255, 0, 255);
const F_FRONT: egui::Color32 = egui::Color32::from_rgb(0, 230, 255);
const VERTEX: egui::Color32 = egui::Color32::from_rgb(255, 255, 255);
const AXIS: egui::Color32 = egui::Color32::from_rgba_premultiplied(150, 150, 150, 170);
const RAY: egui::Color32 = egui::Color32::from_rgba_premultiplied(230, 180, 40, 220);
const PRINCIPAL: egui::Color32 = egui::Color32::from_rgba_premultiplied(150, 90, 200, 200);

/// The camera's projection of a world point to continuous pixel
/// coordinates of a `w × h` render (y down), the inverse of
/// [`Camera::ray`]; `None` behind the near plane.
pub fn project(cam: &Camera, p: DVec3, (w, h): (u32, u32)) -> Option<[f64; 2]> {
    let d = p - cam.position;
    let z = d.dot(cam.forward());
    if z.is_nan() || z <= NEAR {
        return None;
    }
    let tan = (0.5 * cam.fov_y_deg.to_radians()).tan();
    let aspect = f64::from(w) / f64::from(h);
    let (sx, sy) = (d.dot(cam.right()) / z, d.dot(cam.up()) / z);
    Some([
        (sx / (tan * aspect) + 1.0) * 0.5 * f64::from(w),
        (1.0 - sy / tan) * 0.5 * f64::from(h),
    ])
}

const NEAR: f64 = 1e-3;

/// The segment `a`–`b` cut to the part in front of the camera's near plane.
fn clip(cam: &Camera, a: DVec3, b: DVec3) -> Option<(DVec3, DVec3)> {
    let f = cam.forward();
    let (za, zb) = ((a - cam.position).dot(f), (b - cam.position).dot(f));
    let near = 2.0 * NEAR;
    if za < near && zb < near {
        return None;
    }
    let cut = |p: DVec3, q: DVec3, zp: f64, zq: f64| p + (q - p) * ((near - zp) / (zq - zp));
    Some(match (za < near, zb < near) {
        (true, _) => (cut(a, b, za, zb), b),
        (_, true) => (a, cut(b, a, zb, za)),
        _ => (a, b),
    })
}

/// What is drawn, in world coordinates.
#[derive(Clone, Debug, Default)]
pub struct Figure {
    pub axis: Vec<DVec3>,
    pub rays: Vec<Vec<DVec3>>,
    pub rings: Vec<(&'static str, Vec<DVec3>)>,
    pub marks: Vec<(&'static str, DVec3, egui::Color32)>,
}

/// The figure of `lens` at its d-line index: from infinity, or from the
/// axial object point `object_distance` before V1.
pub fn figure(lens: &Lens, up_hint: DVec3, object_distance: Option<f64>) -> Figure {
    let n = lens.index.nominal();
    let px = lens.paraxial(n);
    let a = lens.axis;
    let (v1, v2) = (lens.vertex(LensSurface::S1), lens.vertex(LensSurface::S2));
    // The meridional plane holds the axis and (as nearly as it can) the
    // camera's up, so the fan faces the camera.
    let mut e1 = up_hint - a * up_hint.dot(a);
    if e1.length() < 1e-6 {
        e1 = a.any_orthonormal_vector();
    }
    let e1 = e1.normalize();
    let d = lens.d;
    let power = px.has_power();
    let reach = if power { px.bfd.abs().max(d) } else { 3.0 * d };
    let before = if power { px.ffd.abs().max(d) } else { 3.0 * d };
    let mut fig = Figure {
        axis: vec![v1 + a * (1.2 * before), v2 - a * (1.3 * reach)],
        ..Figure::default()
    };
    for k in 0..7 {
        let h = (-1.0 + f64::from(k) / 3.0) * 0.9 * 0.5 * d;
        let aim = lens.center + e1 * h;
        let (o, u) = match object_distance {
            Some(dist) => {
                let o = v1 + a * dist;
                (o, (aim - o).normalize())
            }
            None => (aim + a * (v1 - lens.center).dot(a) + a * d, -a),
        };
        let p = lens.trace(o, u, n);
        let mut pts = vec![o];
        pts.extend(p.entry.map(|e| e.1));
        if let Some((_, x, dir)) = p.exit {
            pts.push(x);
            pts.push(x + dir * (1.3 * reach));
        }
        fig.rays.push(pts);
    }
    let mut mark = |label, p: DVec3, c| fig.marks.push((label, p, c));
    mark("V1", v1, VERTEX);
    mark("V2", v2, VERTEX);
    if power {
        mark("F", v1 + a * px.ffd, F_FRONT);
        mark("F'", v2 - a * px.bfd, F_BACK);
        let e2 = a.cross(e1);
        let ring = |c: DVec3| {
            (0..=48)
                .map(|k| {
                    let t = std::f64::consts::TAU * f64::from(k) / 48.0;
                    c + (e1 * t.cos() + e2 * t.sin()) * (0.5 * d)
                })
                .collect()
        };
        fig.rings.push(("H", ring(v1 - a * px.h1)));
        fig.rings.push(("H'", ring(v2 - a * px.h2)));
    }
    fig
}

/// The figure of a lens system at the d line, as [`figure`] draws the
/// lens: its axis, the vertices of its first and last surfaces, F and F′,
/// the principal planes, the stop and both pupils as rings, and 7 real
/// meridional rays through `LensSystem::trace` (ending where an edge, ring
/// or the diaphragm absorbs them).
pub fn system_figure(sys: &LensSystem, up_hint: DVec3, object_distance: Option<f64>) -> Figure {
    let px = sys.paraxial(WAVELENGTH_D_UM);
    let a = sys.axis;
    let v1 = sys.vertex;
    let vn = sys.world_point(DVec3::new(0.0, 0.0, sys.length()));
    let mut e1 = up_hint - a * up_hint.dot(a);
    if e1.length() < 1e-6 {
        e1 = a.any_orthonormal_vector();
    }
    let e1 = e1.normalize();
    let e2 = a.cross(e1);
    let size = sys.radius().max(sys.length());
    let power = px.efl.is_finite();
    let reach = if power { px.bfd.abs().max(size) } else { 3.0 * size };
    let before = if power { px.ffd.abs().max(size) } else { 3.0 * size };
    let mut fig = Figure {
        axis: vec![v1 + a * (1.2 * before), vn - a * (1.3 * reach)],
        ..Figure::default()
    };
    let ep = px.entrance_pupil;
    for k in 0..7 {
        let h = (-1.0 + f64::from(k) / 3.0) * 0.9 * ep.semi_diameter;
        let aim = v1 - a * ep.position + e1 * h;
        let o = match object_distance {
            Some(dist) => v1 + a * dist,
            None => aim + a * (ep.position + size),
        };
        let u = if object_distance.is_some() {
            (aim - o).normalize()
        } else {
            -a
        };
        let r = sys.trace(o, u, WAVELENGTH_D_UM);
        let mut pts = vec![o];
        pts.extend(r.events.iter().map(|e| e.point));
        if let Some((_, x, dir)) = r.exit {
            pts.push(x + dir * (1.3 * reach));
        }
        fig.rays.push(pts);
    }
    let ring = |c: DVec3, radius: f64| -> Vec<DVec3> {
        (0..=48)
            .map(|k| {
                let t = std::f64::consts::TAU * f64::from(k) / 48.0;
                c + (e1 * t.cos() + e2 * t.sin()) * radius
            })
            .collect()
    };
    let stop = sys.world_point(DVec3::new(0.0, 0.0, sys.vertex_z(px.stop)));
    fig.rings
        .push(("stop", ring(stop, sys.surfaces[px.stop].semi_aperture)));
    fig.rings.push(("EP", ring(v1 - a * ep.position, ep.semi_diameter)));
    let xp = px.exit_pupil;
    fig.rings.push(("XP", ring(vn - a * xp.position, xp.semi_diameter)));
    fig.marks.push(("V1", v1, VERTEX));
    fig.marks.push(("Vn", vn, VERTEX));
    if power {
        fig.marks.push(("F", v1 + a * px.ffd, F_FRONT));
        fig.marks.push(("F'", vn - a * px.bfd, F_BACK));
        fig.rings.push(("H", ring(v1 - a * px.front_principal, sys.radius())));
        fig.rings.push(("H'", ring(vn - a * px.rear_principal, sys.radius())));
    }
    fig
}

/// Paints `fig` over the picture.
pub fn paint(ctx: &egui::Context, cam: &Camera, pic: Picture, fig: &Figure) {
    let canvas = Canvas::new(ctx, pic, "lensview-optics");
    let (painter, to_pt) = (&canvas.painter, |p| canvas.pt(p));
    let line = |pts: &[DVec3], stroke: egui::Stroke| {
        for w in pts.windows(2) {
            if let Some((a, b)) = clip(cam, w[0], w[1])
                && let (Some(pa), Some(pb)) = (project(cam, a, pic.size), project(cam, b, pic.size))
            {
                painter.line_segment([to_pt(pa), to_pt(pb)], stroke);
            }
        }
    };
    line(&fig.axis, egui::Stroke::new(1.0, AXIS));
    for (_, ring) in &fig.rings {
        line(ring, egui::Stroke::new(1.0, PRINCIPAL));
    }
    for r in &fig.rays {
        line(r, egui::Stroke::new(1.5, RAY));
    }
    let font = egui::FontId::proportional(15.0);
    let mut placed = Vec::new();
    let mut label = |at: egui::Pos2, text: &str, colour: egui::Color32| {
        let g = painter.layout_no_wrap(text.to_string(), font.clone(), colour);
        // Up and right, clear of a marker's disc (radius 5), or on another
        // side when a label is already there (V1 and Vn of a thin lens).
        let spot = [f64::from(at.x), f64::from(at.y)];
        let [x, y] = place_label(spot, text, f64::from(g.size().y), 9.0, &mut placed);
        let r = egui::Rect::from_min_size(egui::pos2(x as f32, y as f32 - g.size().y), g.size()).expand(2.0);
        painter.rect_filled(r, 2.0, egui::Color32::from_black_alpha(170));
        painter.galley(r.min + egui::vec2(2.0, 2.0), g, colour);
    };
    // H at the top of its ring, H' at the bottom of its own: apart.
    for (k, (name, ring)) in fig.rings.iter().enumerate() {
        if let Some(p) = ring.get(k * ring.len() / 2).and_then(|&p| project(cam, p, pic.size)) {
            label(to_pt(p), name, PRINCIPAL);
        }
    }
    for (name, p, colour) in &fig.marks {
        if let Some(q) = project(cam, *p, pic.size) {
            let at = to_pt(q);
            painter.circle_filled(at, 5.0, *colour);
            label(at, name, *colour);
        }
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
    let fig = match system {
        Some(i) => {
            let Some(sys) = scene.objects.iter().filter_map(|o| o.system()).nth(i) else {
                return;
            };
            system_figure(sys, scene.camera.up(), object_distance)
        }
        None => {
            let Some(lens) = scene.objects.iter().filter_map(|o| o.lens()).nth(index) else {
                return;
            };
            figure(lens, scene.camera.up(), object_distance)
        }
    };
    paint(ctx, &scene.camera, pic, &fig);
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

#[cfg(test)]
mod tests {
    use super::*;
    use lensview::optics::Index;

    #[test]
    fn projection_inverts_the_camera_ray() {
        let cam = Camera::new(DVec3::new(1.0, 6.0, 10.0), DVec3::new(-28.8, 12.0, 3.0), 45.0);
        for (x, y) in [(10.5, 20.5), (319.5, 239.5), (600.25, 7.75)] {
            let r = cam.ray(x, y, 640, 480);
            let p = project(&cam, r.origin + r.dir * 7.0, (640, 480)).unwrap();
            assert!((p[0] - x).abs() < 1e-9 && (p[1] - y).abs() < 1e-9, "{p:?} vs {x}, {y}");
        }
        assert!(project(&cam, cam.position - cam.forward(), (640, 480)).is_none());
    }

    #[test]
    fn fan_from_infinity_meets_near_the_back_focal_point() {
        let lens = Lens::new(
            DVec3::new(0.0, 4.3, 6.9),
            DVec3::new(0.0, 0.48, 0.876),
            2.0,
            5.0,
            5.0,
            Index::Constant(1.5),
        )
        .unwrap();
        let fig = figure(&lens, DVec3::Y, None);
        let f_back = fig.marks.iter().find(|m| m.0 == "F'").unwrap().1;
        // The innermost rays (h = ±0.3) cross the axis within the LSA of F′.
        for r in [&fig.rays[2], &fig.rays[4]] {
            let (x, u) = (r[2], (r[3] - r[2]).normalize());
            let closest = x + u * (f_back - x).dot(u);
            assert!((closest - f_back).length() < 0.05, "{closest} vs {f_back}");
        }
        assert_eq!(fig.rays.len(), 7);
        assert_eq!(fig.rings.len(), 2);
    }

    #[test]
    fn a_system_fan_from_infinity_meets_near_its_back_focal_point() {
        // The double Gauss at 1/20 scale, tilted: its inner rays cross the
        // axis within its LSA of F′, and the stop, pupils and principal
        // planes are drawn.
        let text = lensview::prescription::preset("double-gauss-50mm").unwrap();
        let rows = lensview::prescription::parse("dg", text).unwrap();
        let surfaces = lensview::geometry::SurfaceSpec::from_rows(&rows, 0.05);
        let sys = LensSystem::new(DVec3::new(0.5, 1.0, 3.0), DVec3::new(0.0, 0.3, 1.0), surfaces).unwrap();
        let fig = system_figure(&sys, DVec3::Y, None);
        let f_back = fig.marks.iter().find(|m| m.0 == "F'").unwrap().1;
        for r in [&fig.rays[2], &fig.rays[4]] {
            let n = r.len();
            let (x, u) = (r[n - 2], (r[n - 1] - r[n - 2]).normalize());
            let closest = x + u * (f_back - x).dot(u);
            assert!((closest - f_back).length() < 0.02, "{closest} vs {f_back}");
        }
        let names: Vec<&str> = fig.rings.iter().map(|r| r.0).collect();
        assert_eq!(names, ["stop", "EP", "XP", "H", "H'"]);
    }
}
