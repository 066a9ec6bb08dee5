//! The meridional ray fan through a lens system and its longitudinal
//! spherical aberration curve (at the d line), and the system's
//! cross-section they are drawn on ([`super::sketch`]).

use super::bench::Bench;
use super::fan::LSA_STEPS;
use super::setup::SetupError;
use super::sketch::{Kind, Sketch};
use super::system_bench::{Aim, SystemBench, SystemRay};
use super::system_info::{SystemInfo, system_info};
use crate::geometry::{LensSystem, RayStatus, is_air};
use crate::optics::WAVELENGTH_D_UM;
use serde::Serialize;

/// One fan ray: as listed, and the local points of its path (origin,
/// every event, and its end: the image plane, or where it was absorbed).
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct SystemFanRay {
    #[serde(flatten)]
    pub ray: SystemRay,
    pub path: Vec<[f64; 3]>,
}

/// One point of the LSA curve: the axial object point's ray at pupil
/// height `height` (in the entrance pupil), where its exit line crosses
/// the axis (from the last vertex), and that minus the paraxial image.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct SystemLsaPoint {
    pub height: f64,
    pub ray: SystemRay,
    pub focus_from_last_vertex: Option<f64>,
    pub lsa: Option<f64>,
}

/// What `lens system` prints, and the marks of the drawing.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct SystemCardinal {
    #[serde(flatten)]
    pub info: SystemInfo,
    /// The stop's vertex, from the first vertex.
    pub stop_z: f64,
    /// The paraxial image of the object, from the last vertex.
    pub paraxial_image_from_last_vertex: Option<f64>,
    /// Where the real ray from the axial object point through the pupil
    /// edge crosses the axis, from the last vertex.
    pub marginal_focus_from_last_vertex: Option<f64>,
}

#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct SystemFan {
    pub surfaces: usize,
    pub length: f64,
    /// Object distance before the first vertex; `null`: at infinity.
    pub object_distance: Option<f64>,
    pub field_deg: f64,
    pub wavelength_um: f64,
    /// The pupil the rays fill (local z along the light, radius).
    pub pupil: Aim,
    /// The pupil's centre (x, in units of its radius): 0, or the real
    /// chief ray's with `--aim-chief`.
    pub pupil_centre: f64,
    /// The plane the rays are followed to (their `image_point`), from the
    /// last vertex.
    pub image_plane_from_last_vertex: f64,
    pub cardinal: SystemCardinal,
    pub rays: Vec<SystemFanRay>,
    pub lsa: Vec<SystemLsaPoint>,
}

/// The first-order data and the object's real marginal focus.
pub fn system_cardinal(bench: &SystemBench) -> SystemCardinal {
    let axial = bench.axial();
    let (_, _, ray) = axial.trace(1.0, 0.0, WAVELENGTH_D_UM);
    SystemCardinal {
        info: system_info(&bench.system, WAVELENGTH_D_UM),
        stop_z: bench.system.vertex_z(bench.paraxial.stop),
        paraxial_image_from_last_vertex: bench.paraxial_image().map(|p| p.0),
        marginal_focus_from_last_vertex: axial.axis_crossing(&ray).filter(|_| bench.paraxial.efl.is_finite()),
    }
}

/// The LSA curve: pupil heights radius·k/steps, k = 1..steps, at the d line.
pub fn system_lsa(bench: &SystemBench, steps: u32) -> Vec<SystemLsaPoint> {
    (super::bench::lsa(bench, steps).into_iter())
        .map(|p| SystemLsaPoint {
            height: p.height,
            ray: p.ray,
            focus_from_last_vertex: p.focus,
            lsa: p.lsa,
        })
        .collect()
}

/// `rays` meridional rays (pupil x from −1 to 1) at the d line, followed to
/// `image_plane` (default: the paraxial image).
pub fn system_fan(bench: &SystemBench, rays: u32, image_plane: Option<f64>) -> Result<SystemFan, SetupError> {
    let pupil = super::bench::fan_pupil(rays)?;
    let from_last = bench.image_plane(image_plane)?;
    let plane_z = bench.plane_z(from_last);
    let fan_ray = |px: f64| {
        let (ray, real) = SystemRay::traced(bench, px, 0.0, WAVELENGTH_D_UM, plane_z);
        let mut path: Vec<[f64; 3]> = bench
            .path(ray.origin.into(), &real)
            .iter()
            .map(|p| p.to_array())
            .collect();
        if real.status == RayStatus::Transmitted {
            let (x, u) = real.local;
            // Off to the image plane, or a while along the way it leaves.
            let end = ray
                .image_point
                .unwrap_or_else(|| (x + u * bench.system.radius()).to_array());
            path.push(end);
        }
        SystemFanRay { ray, path }
    };
    Ok(SystemFan {
        surfaces: bench.system.len(),
        length: bench.system.length(),
        object_distance: bench.object_distance,
        field_deg: bench.field_deg,
        wavelength_um: WAVELENGTH_D_UM,
        pupil: bench.aim,
        pupil_centre: bench.centre,
        image_plane_from_last_vertex: from_last,
        cardinal: system_cardinal(bench),
        rays: pupil.iter().map(|&px| fan_ray(px)).collect(),
        lsa: system_lsa(bench, LSA_STEPS),
    })
}

/// The meridional section of glass element `k` (the cell after surface
/// `k`) as a closed (s, x) polyline: the front face across, the edge, the
/// back face back, the other edge. Each face is sampled evenly and at its
/// aperture, where the sphere gives way to the flat ring.
pub fn element_outline(sys: &LensSystem, k: usize, points_per_face: u32) -> Vec<[f64; 2]> {
    let a = [sys.surfaces[k].semi_aperture, sys.surfaces[k + 1].semi_aperture];
    let rim = a[0].max(a[1]);
    let m = points_per_face.max(2);
    let mut xs: Vec<f64> = (0..m)
        .map(|i| -rim + 2.0 * rim * f64::from(i) / f64::from(m - 1))
        .collect();
    xs.extend([-a[0], a[0], -a[1], a[1]]);
    xs.sort_by(f64::total_cmp);
    xs.dedup();
    let mut pts: Vec<[f64; 2]> = xs.iter().map(|&x| [sys.front(k, x.abs()), x]).collect();
    pts.extend(xs.iter().rev().map(|&x| [sys.back(k, x.abs()), x]));
    pts.push(pts[0]);
    pts
}

impl SystemFan {
    /// The s range drawn: from where the rays start (or a little before
    /// the system for a far object) to a little past the image plane.
    fn view(&self, bench: &SystemBench) -> [f64; 2] {
        let end = self.length + self.image_plane_from_last_vertex;
        let span = end - bench.front_z();
        let start = match self.object_distance {
            Some(d) => -d.min(0.5 * span + bench.front_z().abs()),
            None => bench.start_z(),
        };
        [start, end + 0.05 * (end - start)]
    }

    /// The fan drawn to scale over the system's cross-section: axis,
    /// elements, the stop's diaphragm, rays, image plane, F, F′, H, H′.
    pub fn sketch(&self, bench: &SystemBench) -> Sketch {
        let sys = &bench.system;
        let mut sk = Sketch::default();
        let view = self.view(bench);
        sk.line(Kind::Axis, vec![[view[0], 0.0], [view[1], 0.0]]);
        for k in 0..sys.len().saturating_sub(1) {
            if !is_air(&sys.surfaces[k].n) {
                sk.line(Kind::Lens, element_outline(sys, k, 64));
            }
        }
        let stop = self.cardinal.info.stop;
        let z_stop = sys.vertex_z(stop);
        let a_stop = sys.surfaces[stop].semi_aperture;
        if sys.surfaces[stop].stop {
            let outer = sys.radius().max(1.15 * a_stop);
            sk.line(Kind::Stop, vec![[z_stop, a_stop], [z_stop, outer]]);
            sk.line(Kind::Stop, vec![[z_stop, -a_stop], [z_stop, -outer]]);
        }
        sk.mark("stop", [z_stop, a_stop]);
        for r in &self.rays {
            let pts = r.path.iter().map(|p| [p[2], p[0]]).collect();
            sk.line(Kind::Ray, pts);
        }
        let end = self.length + self.image_plane_from_last_vertex;
        let half = 1.1 * sys.radius();
        sk.line(Kind::Plane, vec![[end, -half], [end, half]]);
        let c = &self.cardinal.info;
        let inside = |s: f64| s >= view[0] && s <= view[1];
        let marks = [("F", c.ffd.map(|f| -f)), ("F′", c.bfd.map(|b| self.length + b))];
        for (label, s) in marks {
            if let Some(s) = s.filter(|s| inside(*s)) {
                sk.mark(label, [s, 0.0]);
            }
        }
        for (label, s, x) in [
            ("H", c.front_principal, half),
            ("H′", c.rear_principal.map(|h| self.length + h), -half),
        ] {
            if let Some(s) = s.filter(|s| inside(*s)) {
                sk.line(Kind::Principal, vec![[s, -half], [s, half]]);
                sk.mark(label, [s, x]);
            }
        }
        sk.view = view;
        sk
    }
}
