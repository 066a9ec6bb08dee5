//! The optical bench behind the figures of a lens system (`lens fan`,
//! `spot`, `distortion` with `--preset`, `--prescription` or `--system`):
//! the system, an object at infinity or at a distance, a field angle, and
//! how a pupil point becomes a real ray ([`LensSystem::trace`]).
//!
//! Everything is in the system's local frame (docs/lens-systems.md): `z`
//! along the light from the first vertex, the meridional plane `x–z`.
//! Pupil rays are aimed at the paraxial entrance pupil at the d line: the
//! pupil point (px, py) in the unit disc at `(px·ρ, py·ρ, z_p)`, with `z_p`
//! the pupil's position and `ρ` its semi-diameter ([`Aim`]). The field
//! angle A tilts the chief ray toward +x at the object: from infinity every
//! ray has the direction `(−sin A, 0, cos A)` and starts in a plane before
//! every piece of the system; from an object at distance D before the
//! first vertex every ray starts at the object point
//! `((D + z_p)·tan A, 0, −D)`. This is the biconvex bench
//! ([`super::setup`]) with its pupil plane (through the lens's centre C) and
//! radius replaced by the entrance pupil's.

use super::bench::{self, Bench, Names};
use super::setup::{SPOT_WAVELENGTHS_UM, SetupError, bad};
use crate::geometry::{EventKind, LensSystem, Paraxial, PieceKind, RayStatus, RealRay};
use crate::optics::WAVELENGTH_D_UM;
use glam::DVec3;
use serde::Serialize;

/// Where pupil rays are aimed: the plane `z` (local, along the light from
/// the first vertex) and the radius there that the unit pupil fills.
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
pub struct Aim {
    pub z: f64,
    pub radius: f64,
}

/// The share of the paraxial entrance pupil's radius the unit pupil
/// fills: its edge a hair inside, so that where the stop is a lens's own
/// aperture (the achromat's first face) the rim rays meet the cap, not the
/// edge it ends on, by a rounding.
pub const PUPIL_EDGE: f64 = 1.0 - 1e-9;

/// A system bench's words in its refusals.
const NAMES: Names = Names {
    who: "system",
    field: "system",
    last: "the last vertex",
    after: "the last vertex",
    where_: "",
};

/// A system, where the light comes from, and the field angle.
#[derive(Clone, Debug)]
pub struct SystemBench {
    pub system: LensSystem,
    /// Object distance before the first vertex; `None`: at infinity.
    pub object_distance: Option<f64>,
    /// Field angle in degrees, in (−90, 90).
    pub field_deg: f64,
    /// The pupil the rays fill (default: the paraxial entrance pupil).
    pub aim: Aim,
    /// First-order data at the d line.
    pub paraxial: Paraxial,
    /// The pupil's centre, x in units of the aim radius: 0 (the paraxial
    /// chief ray), or the real chief ray's ([`SystemBench::aimed`]).
    pub centre: f64,
}

impl SystemBench {
    /// The bench for `system` (its pose is irrelevant: everything is local),
    /// checked as the biconvex bench checks its values.
    pub fn new(system: LensSystem, object_distance: Option<f64>, field_deg: f64) -> Result<SystemBench, SetupError> {
        for (_, l) in SPOT_WAVELENGTHS_UM {
            for (k, s) in system.surfaces.iter().enumerate() {
                let n = s.n.at(l);
                if !(n >= 1.0 && n.is_finite()) {
                    return Err(bad("n", format!("index {n} after surface {k} at {l} µm must be ≥ 1")));
                }
            }
        }
        super::setup::check_object(object_distance, field_deg, "the first vertex")?;
        let paraxial = system.paraxial(WAVELENGTH_D_UM);
        let ep = paraxial.entrance_pupil;
        if !(ep.position.is_finite() && ep.semi_diameter > 0.0 && ep.semi_diameter.is_finite()) {
            return Err(bad(
                "system",
                format!(
                    "the paraxial entrance pupil (at {}, semi-diameter {}) is not a finite disc: no pupil to fill",
                    ep.position, ep.semi_diameter
                ),
            ));
        }
        let bench = SystemBench {
            system,
            object_distance,
            field_deg,
            aim: Aim {
                z: ep.position,
                radius: ep.semi_diameter * PUPIL_EDGE,
            },
            paraxial,
            centre: 0.0,
        };
        if let Some(dist) = object_distance {
            let o = bench.object_point(dist);
            if bench.system.contains(bench.system.world_point(o)) {
                return Err(bad(
                    "object-distance",
                    format!("{dist}: the object point lies inside the glass"),
                ));
            }
        }
        Ok(bench)
    }

    /// The same bench aiming at another pupil.
    pub fn with_aim(self, aim: Aim) -> SystemBench {
        SystemBench { aim, ..self }
    }

    /// The same bench with its pupil centred on the real chief ray at the
    /// d line (ray aiming: at wide fields pupil aberration moves the beam
    /// through the stop's centre far from the paraxial one); unchanged when
    /// no chief ray is found.
    pub fn aimed(self) -> SystemBench {
        match self.chief_ray(WAVELENGTH_D_UM) {
            Some(c) => SystemBench { centre: c.px, ..self },
            None => self,
        }
    }

    /// The smallest `z` any piece of the system reaches (a concave first
    /// face, a ring before the first vertex).
    pub fn front_z(&self) -> f64 {
        let s = &self.system;
        (0..s.len())
            .map(|k| s.front(k, s.surfaces[k].semi_aperture).min(s.vertex_z(k)))
            .fold(0.0, f64::min)
    }

    /// The plane rays from infinity start in: before every piece and the pupil.
    pub fn start_z(&self) -> f64 {
        let s = &self.system;
        self.front_z().min(self.aim.z) - 0.3 * s.length().max(s.radius())
    }

    /// The object point for a finite object distance.
    pub fn object_point(&self, distance: f64) -> DVec3 {
        bench::object_point(distance + self.aim.z, -distance, self.field_deg)
    }

    /// The local ray for the pupil point (px, py): origin and unit direction.
    pub fn ray(&self, px: f64, py: f64) -> (DVec3, DVec3) {
        let rho = self.aim.radius;
        let aim = DVec3::new((self.centre + px) * rho, py * rho, self.aim.z);
        let object = self.object_distance.map(|dist| self.object_point(dist));
        bench::pupil_ray(aim, object, self.field_deg, 1.0, aim.z - self.start_z())
    }

    /// The pupil ray (px, py) traced at `lambda_um`: its local origin and
    /// direction, and the real ray.
    pub fn trace(&self, px: f64, py: f64, lambda_um: f64) -> (DVec3, DVec3, RealRay) {
        let (o, u) = self.ray(px, py);
        let s = &self.system;
        (o, u, s.trace(s.world_point(o), s.world_dir(u), lambda_um))
    }

    /// A world point in local coordinates.
    pub fn local(&self, p: DVec3) -> DVec3 {
        self.system.local_dir(p - self.system.vertex)
    }

    /// The local points of a traced ray: its origin and every event.
    pub fn path(&self, origin: DVec3, ray: &RealRay) -> Vec<DVec3> {
        let mut pts = vec![origin];
        pts.extend(ray.events.iter().map(|e| self.local(e.point)));
        pts
    }

    /// Where a ray that passed every cap in order ([`Self::sequential`])
    /// and left forward crosses the plane `z = plane_z` (`None` for any
    /// other ray).
    pub fn image_crossing(&self, ray: &RealRay, plane_z: f64) -> Option<DVec3> {
        let (x, u) = ray.local;
        if !self.sequential(ray) || !(u.z > 0.0) {
            return None;
        }
        let t = (plane_z - x.z) / u.z;
        Some(x + t * u)
    }

    /// Whether a ray was transmitted through every optical cap of the
    /// system once, in order, refracting at each (the path a design
    /// program follows): not one that went past an element, reflected, or
    /// left through the side of an air gap.
    pub fn sequential(&self, ray: &RealRay) -> bool {
        let s = &self.system;
        let caps = (0..s.len()).filter(|&k| s.cap_is_boundary(k)).count();
        ray.status == RayStatus::Transmitted
            && ray.events.len() == caps
            && ray
                .events
                .iter()
                .all(|e| e.piece.kind == PieceKind::Cap && e.kind == EventKind::Refract)
            && ray.events.windows(2).all(|w| w[0].piece.surface < w[1].piece.surface)
    }

    /// Where such a ray's exit line crosses the axis (meridional rays),
    /// from the last vertex along the light.
    pub fn axis_crossing(&self, ray: &RealRay) -> Option<f64> {
        let (x, u) = ray.local;
        self.image_crossing(ray, x.z)?;
        let t = -x.x / u.x;
        (u.x != 0.0).then(|| x.z + t * u.z - self.system.length())
    }

    /// The first point where the path (origin, events, and on past the last
    /// event unless absorbed) crosses the plane `z`.
    pub fn plane_crossing(&self, origin: DVec3, ray: &RealRay, z: f64) -> Option<DVec3> {
        let pts = self.path(origin, ray);
        for w in pts.windows(2) {
            let (a, b) = (w[0], w[1]);
            if (a.z - z) * (b.z - z) <= 0.0 && a.z != b.z {
                return Some(a + (b - a) * ((z - a.z) / (b.z - a.z)));
            }
        }
        if ray.status == RayStatus::Absorbed || ray.status == RayStatus::Trapped {
            return None;
        }
        let (x, u) = ray.local;
        let t = (z - x.z) / u.z;
        (t > 0.0 && t.is_finite()).then(|| x + t * u)
    }

    /// The paraxial image of the object at the d line, from the last
    /// vertex along the light, and the lateral magnification (`None` from
    /// infinity); `None` without power or for an object inside F.
    pub fn paraxial_image(&self) -> Option<(f64, Option<f64>)> {
        let p = &self.paraxial;
        if !p.efl.is_finite() {
            return None;
        }
        let h = [p.front_principal, p.rear_principal];
        super::setup::image_of(self.object_distance, p.efl, p.bfd, h)
    }

    /// The real paraxial image (refused as the biconvex bench refuses:
    /// no power, object inside F, image not after the last vertex).
    pub fn real_image(&self) -> Result<(f64, Option<f64>), SetupError> {
        if !self.paraxial.efl.is_finite() {
            return Err(bad("system", "the system has no power: it forms no image".into()));
        }
        bench::real_image(&NAMES, self.paraxial_image())
    }

    /// The image the figures measure in (from the last vertex, the
    /// magnification, virtual or not): the real paraxial image, or a
    /// magnifier's virtual one ([`bench::figure_image`]).
    pub fn figure_image(&self) -> Result<(f64, Option<f64>, bool), SetupError> {
        let p = &self.paraxial;
        bench::figure_image(self.real_image(), || {
            let dist = self.object_distance.filter(|_| p.efl.is_finite())?;
            super::setup::paraxial_image(dist, p.efl, [p.front_principal, p.rear_principal])
        })
    }

    /// The image plane from the last vertex: `image_plane` if given
    /// (checked), else the figures' image at the d line ([`Self::figure_image`]).
    pub fn image_plane(&self, image_plane: Option<f64>) -> Result<f64, SetupError> {
        bench::image_plane(&NAMES, image_plane, || self.figure_image())
    }

    /// Local `z` of the plane `from_last` after the last vertex.
    pub fn plane_z(&self, from_last: f64) -> f64 {
        self.system.length() + from_last
    }

    /// The real chief ray at `lambda_um`: the pupil x (in units of the
    /// aim radius) whose ray crosses the stop's vertex plane on the axis,
    /// found by secant steps from the paraxial chief ray (px = 0); with the
    /// ray's origin, direction and trace, and the height it crosses the
    /// stop plane at. `None` if the ray is lost (absorbed before the stop)
    /// or the steps do not settle.
    pub fn chief_ray(&self, lambda_um: f64) -> Option<ChiefRay> {
        let z_stop = self.system.vertex_z(self.paraxial.stop);
        let probe = SystemBench {
            centre: 0.0,
            ..self.clone()
        };
        let at = |px: f64| {
            let (o, u, ray) = probe.trace(px, 0.0, lambda_um);
            let h = probe.plane_crossing(o, &ray, z_stop)?.x;
            Some(ChiefRay {
                px,
                origin: o,
                dir: u,
                ray,
                stop_height: h,
            })
        };
        let tol = 1e-13 * self.system.radius().max(self.aim.radius);
        let (mut a, mut b) = match at(0.0) {
            Some(a) if a.stop_height.abs() <= tol => return Some(a),
            Some(a) => {
                let b = at(0.01_f64.copysign(-a.stop_height))?;
                (a, b)
            }
            // Lost on the way (wide fields): a bracket from a scan of the
            // pupil plane, 8 radii each side.
            None => {
                let found: Vec<ChiefRay> = (-80..=80).filter_map(|i| at(f64::from(i) / 10.0)).collect();
                let pair = found.windows(2).find(|w| w[0].stop_height * w[1].stop_height <= 0.0)?;
                (pair[0].clone(), pair[1].clone())
            }
        };
        for _ in 0..60 {
            if b.stop_height.abs() <= tol {
                return Some(b);
            }
            let slope = (b.stop_height - a.stop_height) / (b.px - a.px);
            if !(slope.is_finite() && slope != 0.0) {
                break;
            }
            let next = b.px - b.stop_height / slope;
            if !(next.abs() < 10.0) {
                return None;
            }
            if next == b.px {
                return Some(b);
            }
            (a, b) = (b, at(next)?);
        }
        (b.stop_height.abs() <= 1e-9 * self.system.radius()).then_some(b)
    }
}

/// The real chief ray ([`SystemBench::chief_ray`]).
#[derive(Clone, Debug)]
pub struct ChiefRay {
    /// Pupil x of its aim, in units of the aim radius.
    pub px: f64,
    pub origin: DVec3,
    pub dir: DVec3,
    pub ray: RealRay,
    /// Where it crosses the stop's vertex plane (x, local).
    pub stop_height: f64,
}

/// A ray as the JSON lists it: enough to trace it again (local frame).
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct SystemRay {
    /// Pupil coordinates in the unit disc (the aim radius at 1).
    pub pupil: [f64; 2],
    pub origin: [f64; 3],
    pub direction: [f64; 3],
    pub wavelength_um: f64,
    /// `transmitted`, `miss`, `absorbed` or `trapped`, as `lens trace` says.
    pub status: &'static str,
    pub n_internal_reflections: u32,
    /// Where it crosses the image plane (`null` unless it passed every
    /// surface in order and left through the last toward it).
    pub image_point: Option<[f64; 3]>,
    /// Where it was absorbed, and the surface of the piece.
    pub absorbed_at: Option<[f64; 3]>,
    pub absorbed_surface: Option<usize>,
}

impl SystemRay {
    /// The pupil ray (px, py) at `lambda_um`, followed to the plane `plane_z`.
    pub fn traced(bench: &SystemBench, px: f64, py: f64, lambda_um: f64, plane_z: f64) -> (SystemRay, RealRay) {
        let (o, u, ray) = bench.trace(px, py, lambda_um);
        (SystemRay::listed([px, py], o, u, &ray, bench, lambda_um, plane_z), ray)
    }

    /// The listing of a ray already traced.
    pub fn listed(
        pupil: [f64; 2],
        o: DVec3,
        u: DVec3,
        ray: &RealRay,
        bench: &SystemBench,
        lambda_um: f64,
        plane_z: f64,
    ) -> SystemRay {
        let absorbed = (ray.status == RayStatus::Absorbed).then(|| ray.events.last()).flatten();
        SystemRay {
            pupil,
            origin: o.to_array(),
            direction: u.to_array(),
            wavelength_um: lambda_um,
            status: ray.status.name(),
            n_internal_reflections: ray.reflections,
            image_point: bench.image_crossing(ray, plane_z).map(|p| p.to_array()),
            absorbed_at: absorbed.map(|e| bench.local(e.point).to_array()),
            absorbed_surface: absorbed.map(|e| e.piece.surface),
        }
    }
}

impl Bench for SystemBench {
    type Ray = SystemRay;

    fn at_field(&self, field_deg: f64) -> SystemBench {
        SystemBench {
            field_deg,
            ..self.clone()
        }
    }

    fn axial(&self) -> SystemBench {
        SystemBench {
            field_deg: 0.0,
            centre: 0.0,
            ..self.clone()
        }
    }

    fn paraxial_image(&self) -> Option<(f64, Option<f64>)> {
        SystemBench::paraxial_image(self)
    }

    fn image_plane(&self, given: Option<f64>) -> Result<f64, SetupError> {
        SystemBench::image_plane(self, given)
    }

    fn plane_z(&self, from_last: f64) -> f64 {
        SystemBench::plane_z(self, from_last)
    }

    fn pupil_height(&self, px: f64) -> f64 {
        px * self.aim.radius
    }

    fn listed(&self, px: f64, py: f64, lambda_um: f64, plane_z: f64) -> SystemRay {
        SystemRay::traced(self, px, py, lambda_um, plane_z).0
    }

    fn image_point(ray: &SystemRay) -> Option<[f64; 3]> {
        ray.image_point
    }

    fn focus_ray(&self, px: f64, plane_z: f64) -> (SystemRay, Option<f64>) {
        let (ray, real) = SystemRay::traced(self, px, 0.0, WAVELENGTH_D_UM, plane_z);
        (ray, self.axis_crossing(&real))
    }
}
