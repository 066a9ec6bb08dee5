//! The optics overlay's geometry (the desktop viewer's F6 and the web
//! page's): for a lens, the optical axis, the vertices V1 and V2, the focal
//! points F and F′ as markers, the principal planes H and H′ as thin rings
//! of diameter d, and a fan of 7 real meridional rays — parallel to the
//! axis, or from an axial object point — traced by `Lens::trace` (whose
//! inside pass is the renderer's), entering through S1 as in `lens info`;
//! for a lens system the same through `LensSystem::trace`, with the stop
//! and both pupils. Labels say F' and H' (the viewer's font has no ′).
//!
//! The figure is in world coordinates; [`project`] is the camera's own
//! projection (the inverse of `Camera::ray`) and [`Projected`] the figure
//! cut at the near plane and projected to picture pixels, which the
//! desktop paints with egui and the page on a 2D canvas.

use super::sketch::place_label;
use crate::camera::Camera;
use crate::geometry::{Lens, LensSurface, LensSystem};
use crate::optics::WAVELENGTH_D_UM;
use crate::scene::Scene;
use glam::DVec3;

/// What a line or marker of the figure is, which sets its colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    Axis,
    Ray,
    /// The principal planes, the stop and the pupils (rings).
    Principal,
    Vertex,
    FrontFocus,
    BackFocus,
}

impl Role {
    /// Its colour, RGBA premultiplied by alpha (as egui takes it).
    pub const fn premultiplied(self) -> [u8; 4] {
        match self {
            Role::Axis => [150, 150, 150, 170],
            Role::Ray => [230, 180, 40, 220],
            Role::Principal => [150, 90, 200, 200],
            Role::Vertex => [255, 255, 255, 255],
            Role::FrontFocus => [0, 230, 255, 255],
            Role::BackFocus => [255, 0, 255, 255],
        }
    }

    /// Its colour as CSS `rgba(…)` (straight alpha), for a 2D canvas.
    pub fn css(self) -> String {
        let [r, g, b, a] = self.premultiplied();
        let straight = |c: u8| (f64::from(c) * 255.0 / f64::from(a.max(1))).round().min(255.0);
        format!(
            "rgba({},{},{},{:.3})",
            straight(r),
            straight(g),
            straight(b),
            f64::from(a) / 255.0
        )
    }

    /// The stroke width of its lines, in logical pixels.
    pub fn width(self) -> f64 {
        if self == Role::Ray { 1.5 } else { 1.0 }
    }
}

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
pub fn clip(cam: &Camera, a: DVec3, b: DVec3) -> Option<(DVec3, DVec3)> {
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
    pub marks: Vec<(&'static str, DVec3, Role)>,
}

/// A unit vector across `axis`, as near `up_hint` as it can be: the
/// meridional plane holds the axis and the camera's up, so the fan faces
/// the camera.
fn across(axis: DVec3, up_hint: DVec3) -> DVec3 {
    let e1 = up_hint - axis * up_hint.dot(axis);
    if e1.length() < 1e-6 {
        axis.any_orthonormal_vector()
    } else {
        e1.normalize()
    }
}

/// A ring of 49 points (closed) about `c` across `axis`.
fn ring(c: DVec3, (e1, e2): (DVec3, DVec3), radius: f64) -> Vec<DVec3> {
    (0..=48)
        .map(|k| {
            let t = std::f64::consts::TAU * f64::from(k) / 48.0;
            c + (e1 * t.cos() + e2 * t.sin()) * radius
        })
        .collect()
}

/// The figure of `lens` at its d-line index: from infinity, or from the
/// axial object point `object_distance` before V1.
pub fn figure(lens: &Lens, up_hint: DVec3, object_distance: Option<f64>) -> Figure {
    let n = lens.index.nominal();
    let px = lens.paraxial(n);
    let a = lens.axis;
    let (v1, v2) = (lens.vertex(LensSurface::S1), lens.vertex(LensSurface::S2));
    let e1 = across(a, up_hint);
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
    fig.marks.push(("V1", v1, Role::Vertex));
    fig.marks.push(("V2", v2, Role::Vertex));
    if power {
        fig.marks.push(("F", v1 + a * px.ffd, Role::FrontFocus));
        fig.marks.push(("F'", v2 - a * px.bfd, Role::BackFocus));
        let e = (e1, a.cross(e1));
        fig.rings.push(("H", ring(v1 - a * px.h1, e, 0.5 * d)));
        fig.rings.push(("H'", ring(v2 - a * px.h2, e, 0.5 * d)));
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
    let e1 = across(a, up_hint);
    let e = (e1, a.cross(e1));
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
        let (o, u) = match object_distance {
            Some(dist) => (v1 + a * dist, (aim - (v1 + a * dist)).normalize()),
            None => (aim + a * (ep.position + size), -a),
        };
        let r = sys.trace(o, u, WAVELENGTH_D_UM);
        let mut pts = vec![o];
        pts.extend(r.events.iter().map(|e| e.point));
        if let Some((_, x, dir)) = r.exit {
            pts.push(x + dir * (1.3 * reach));
        }
        fig.rays.push(pts);
    }
    let stop = sys.world_point(DVec3::new(0.0, 0.0, sys.vertex_z(px.stop)));
    fig.rings
        .push(("stop", ring(stop, e, sys.surfaces[px.stop].semi_aperture)));
    fig.rings.push(("EP", ring(v1 - a * ep.position, e, ep.semi_diameter)));
    let xp = px.exit_pupil;
    fig.rings.push(("XP", ring(vn - a * xp.position, e, xp.semi_diameter)));
    fig.marks.push(("V1", v1, Role::Vertex));
    fig.marks.push(("Vn", vn, Role::Vertex));
    if power {
        fig.marks.push(("F", v1 + a * px.ffd, Role::FrontFocus));
        fig.marks.push(("F'", vn - a * px.bfd, Role::BackFocus));
        fig.rings
            .push(("H", ring(v1 - a * px.front_principal, e, sys.radius())));
        fig.rings
            .push(("H'", ring(vn - a * px.rear_principal, e, sys.radius())));
    }
    fig
}

/// The figure for `scene`'s lens system `system` when given, else for its
/// lens `lens`; `None` when there is no such one.
pub fn scene_figure(scene: &Scene, lens: usize, system: Option<usize>, object_distance: Option<f64>) -> Option<Figure> {
    let up = scene.camera.up();
    Some(match system {
        Some(i) => system_figure(
            scene.objects.iter().filter_map(|o| o.system()).nth(i)?,
            up,
            object_distance,
        ),
        None => figure(
            scene.objects.iter().filter_map(|o| o.lens()).nth(lens)?,
            up,
            object_distance,
        ),
    })
}

/// A label of the projected figure: its text, where its point is, its
/// role, and whether the point gets a marker's disc (the marks do, the
/// rings' names do not).
#[derive(Clone, Debug, PartialEq)]
pub struct Label {
    pub text: &'static str,
    pub at: [f64; 2],
    pub role: Role,
    pub disc: bool,
}

/// The figure seen by a camera: line segments and labels in continuous
/// picture pixels (y down), in the order they are painted (the axis, the
/// rings, the rays; the rings' labels, then the marks).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Projected {
    pub segments: Vec<(Role, [f64; 2], [f64; 2])>,
    pub labels: Vec<Label>,
}

impl Projected {
    /// `fig` seen by `cam` in a `size` picture: each polyline cut at the
    /// near plane, each point projected; a label whose point is behind
    /// the camera is left out.
    pub fn new(cam: &Camera, size: (u32, u32), fig: &Figure) -> Projected {
        let mut out = Projected::default();
        let mut line = |pts: &[DVec3], role: Role| {
            for w in pts.windows(2) {
                if let Some((a, b)) = clip(cam, w[0], w[1])
                    && let (Some(pa), Some(pb)) = (project(cam, a, size), project(cam, b, size))
                {
                    out.segments.push((role, pa, pb));
                }
            }
        };
        line(&fig.axis, Role::Axis);
        for (_, ring) in &fig.rings {
            line(ring, Role::Principal);
        }
        for r in &fig.rays {
            line(r, Role::Ray);
        }
        // H at the top of its ring, H' at the bottom of its own: apart.
        for (k, (name, ring)) in fig.rings.iter().enumerate() {
            if let Some(at) = ring.get(k * ring.len() / 2).and_then(|&p| project(cam, p, size)) {
                let (text, role, disc) = (*name, Role::Principal, false);
                out.labels.push(Label { text, at, role, disc });
            }
        }
        for (text, p, role) in &fig.marks {
            if let Some(at) = project(cam, *p, size) {
                let (text, role, disc) = (*text, *role, true);
                out.labels.push(Label { text, at, role, disc });
            }
        }
        out
    }

    /// Where each label's text goes (its left and baseline), `scale` pixels
    /// of the painter a picture pixel, for text `font_px` high: up and
    /// right of its point, clear of a marker's disc (radius 5), or on
    /// another side when a label is already there (V1 and Vn of a thin
    /// lens), as [`place_label`] places them.
    pub fn label_spots(&self, scale: f64, font_px: f64) -> Vec<[f64; 2]> {
        let mut placed = Vec::new();
        (self.labels.iter())
            .map(|l| place_label([l.at[0] * scale, l.at[1] * scale], l.text, font_px, 9.0, &mut placed))
            .collect()
    }
}

#[cfg(test)]
mod tests;
