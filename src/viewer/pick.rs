//! Picking in the picture (issue 33.1): a click on the picture selects
//! what is under the cursor — a point light's marker, else the object,
//! lens or lens system the pixel's centre ray meets first — and the panel
//! shows it. Every point light has a marker; the selection is outlined
//! (its box, projected).

use super::optics::{Canvas, Picture, project};
use glam::DVec3;
use lensview::edit::{Document, Item};
use lensview::light::Light;
use lensview::math::Ray;
use lensview::scene::Scene;

/// What a click picked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Picked {
    Item(Item),
    /// Light `i` of the scene (its marker).
    Light(usize),
}

/// A light marker's radius, and how near (window pixels, logical) a click
/// must be to pick it.
const MARKER_RADIUS: f32 = 7.0;
const MARKER_PICK: f64 = 12.0;
const LIGHT_MARK: egui::Color32 = egui::Color32::from_rgb(255, 220, 60);
const SELECTED: egui::Color32 = egui::Color32::from_rgb(80, 200, 255);

/// Point light `i`'s position in the picture (continuous pixels).
fn light_at(scene: &Scene, i: usize, pic: &Picture) -> Option<[f64; 2]> {
    match scene.lights.get(i)? {
        Light::Point { position, .. } => project(&scene.camera, *position, pic.size),
        _ => None,
    }
}

/// What lies under window pixel `cursor` (physical), at `ppp` physical
/// pixels a logical one: the nearest light marker within reach, else what
/// the centre ray of the pixel meets first; `None` off the picture or
/// over the background.
pub fn pick(doc: &Document, pic: &Picture, cursor: (f64, f64), ppp: f64) -> Option<Picked> {
    let scene = doc.built();
    let p = pic.picture_point([cursor.0, cursor.1])?;
    let reach = MARKER_PICK * ppp;
    let near = (0..scene.lights.len())
        .filter_map(|i| {
            let q = pic.window_point(light_at(scene, i, pic)?);
            let d = (q[0] - cursor.0).hypot(q[1] - cursor.1);
            (d <= reach).then_some((d, i))
        })
        .min_by(|a, b| a.0.total_cmp(&b.0));
    if let Some((_, i)) = near {
        return Some(Picked::Light(i));
    }
    let (w, h) = pic.size;
    // Through a lens camera, the ray the lens sends out for the pixel's
    // centre through the middle of its pupil box (the picture is made of
    // such rays, not the pinhole's); the pinhole's where the lens stops it.
    let through_lens = (scene.lens.as_ref())
        .and_then(|l| l.ray(&scene.camera, (p[0], p[1]), (w, h), (0.5, 0.5), 1))
        .map(|r| r.0);
    let ray: Ray = through_lens.unwrap_or_else(|| scene.camera.ray(p[0], p[1], w, h));
    let (o, _) = lensview::trace::closest_hit(scene, &ray, f64::INFINITY)?;
    doc.item_of_object(o).map(Picked::Item)
}

/// The light markers and the selection's outline over the picture;
/// returns the outline (logical points), if drawn.
pub fn paint(ctx: &egui::Context, doc: &Document, pic: Picture, selected: Option<Item>) -> Option<egui::Rect> {
    let scene = doc.built();
    let canvas = Canvas::new(ctx, pic, "lensview-pick");
    let (painter, to_pt) = (&canvas.painter, |p| canvas.pt(p));
    let clip = painter.clip_rect();
    let dark = egui::Stroke::new(3.0, egui::Color32::from_black_alpha(200));
    for i in 0..scene.lights.len() {
        if let Some(p) = light_at(scene, i, &pic) {
            let at = to_pt(p);
            painter.circle_stroke(at, MARKER_RADIUS, dark);
            painter.circle_stroke(at, MARKER_RADIUS, egui::Stroke::new(1.5, LIGHT_MARK));
            painter.circle_filled(at, 2.0, LIGHT_MARK);
        }
    }
    let obj = selected.and_then(|item| scene.objects.get(doc.object_of_item(item)))?;
    // The box's corners in front of the camera, projected: their extent.
    let (lo, hi) = (obj.world_bounds.min, obj.world_bounds.max);
    let corners = (0..8).filter_map(|k| {
        let c = glam::DVec3::new(
            if k & 1 == 0 { lo.x } else { hi.x },
            if k & 2 == 0 { lo.y } else { hi.y },
            if k & 4 == 0 { lo.z } else { hi.z },
        );
        project(&scene.camera, c, pic.size).map(to_pt)
    });
    let mut r = egui::Rect::NOTHING;
    for c in corners {
        r.extend_with(c);
    }
    let r = r.intersect(clip);
    r.is_positive().then(|| {
        painter.rect_stroke(r, 2.0, dark, egui::StrokeKind::Outside);
        painter.rect_stroke(r, 2.0, egui::Stroke::new(1.5, SELECTED), egui::StrokeKind::Outside);
        r
    })
}

/// A drag of a picked thing (the selected item, or a light's marker):
/// moved in the plane through its point facing the camera, or with Shift
/// along the view.
#[derive(Clone, Copy, Debug)]
pub struct Grab {
    pub what: Picked,
    /// The world point that follows the cursor.
    anchor: DVec3,
    /// The cursor's last window position (physical pixels).
    last: (f64, f64),
}

/// The world point a picked thing is dragged by: a light's position, an
/// item's box centre.
fn anchor_of(doc: &Document, what: Picked) -> Option<DVec3> {
    let scene = doc.built();
    match what {
        Picked::Light(i) => match scene.lights.get(i)? {
            Light::Point { position, .. } => Some(*position),
            _ => None,
        },
        Picked::Item(item) => {
            let b = scene.objects.get(doc.object_of_item(item))?.world_bounds;
            Some(0.5 * (b.min + b.max))
        }
    }
}

impl Grab {
    /// A grab of `what` with the cursor at `cursor`.
    pub fn new(doc: &Document, what: Picked, cursor: (f64, f64)) -> Option<Grab> {
        Some(Grab {
            what,
            anchor: anchor_of(doc, what)?,
            last: cursor,
        })
    }

    /// The move that takes the grabbed point under the cursor at `to`
    /// (in its plane facing the camera), or along the view by the
    /// cursor's vertical travel with `along` (Shift: up moves away); zero
    /// where the cursor is off the picture or the plane is edge-on.
    pub fn step(&mut self, doc: &Document, pic: &Picture, to: (f64, f64), along: bool) -> DVec3 {
        let cam = &doc.built().camera;
        let f = cam.forward();
        let depth = (self.anchor - cam.position).dot(f);
        let by = if along {
            let dy = (to.1 - self.last.1) / f64::from(pic.size.1.max(1)) / pic.scale();
            f * (-2.0 * dy * depth.abs().max(1e-3))
        } else {
            let Some(p) = pic.picture_point([to.0, to.1]) else {
                return DVec3::ZERO;
            };
            let ray = cam.ray(p[0], p[1], pic.size.0, pic.size.1);
            let along_f = ray.dir.dot(f);
            if along_f.abs() < 1e-9 || depth <= 0.0 {
                return DVec3::ZERO;
            }
            let t = (self.anchor - ray.origin).dot(f) / along_f;
            ray.origin + ray.dir * t - self.anchor
        };
        self.last = to;
        if by.is_finite() {
            self.anchor += by;
            by
        } else {
            DVec3::ZERO
        }
    }
}
