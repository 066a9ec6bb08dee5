//! A camera made of a lens system and a sensor (pbrt-v4's
//! `RealisticCamera`, with the system's own exact tracer).
//!
//! Camera space is the pinhole's: looking along `−z`, `+y` up. The system
//! faces `−z` (its axis), so light crosses it along `+z` toward the sensor,
//! a plane behind its rear vertex. The **entrance pupil's centre sits at
//! the camera's position**: the perspective centre of a lens, so a lens
//! camera and the pinhole of its equivalent field of view see the same
//! directions ([`LensCamera::fov_y_deg`]).
//!
//! A camera ray starts on the sensor, aims at a point of the exit pupil's
//! bounds on the rear vertex's plane ([`super::pupil`]) and is traced
//! backwards through the system ([`LensSystem::pass`]: the interface step
//! of every lens); a ray that an aperture, ring or edge stops carries no
//! light. The lens turns the image round; the picture is turned back
//! (a pixel's sensor point is opposite its upright position).
//!
//! **Weight** (pbrt-v4): `cos⁴θ · A / z²`, `θ` the ray's angle to the axis
//! at the sensor, `A` the area of the box sampled, `z` the sensor's
//! distance to the rear plane: the irradiance estimate of the sensor point
//! divided by the radiance. We divide it by its value at the sensor's
//! centre (computed once on a 128 × 128 grid), so that the centre of the
//! frame shows the scene's radiance as the pinhole does, and corners fall
//! off by `cos⁴` and vignetting together.

use super::Camera;
use super::pupil::{INTERVALS, Planes, PupilBox};
use crate::geometry::{LensSystem, Paraxial, Passed, SurfaceSpec};
use crate::math::Ray;
use crate::optics::{RGB_WAVELENGTHS_UM, WAVELENGTH_D_UM};
use crate::sampling::radical_inverse;
use crate::simd::{LANES, Lanes, set_lane};
use glam::DVec3;
use rayon::prelude::*;
use std::sync::{Arc, Mutex, OnceLock};

/// What sets the focus.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Focus {
    /// The distance from the camera (the entrance pupil) to the plane in
    /// focus, along the view; infinite: focused at infinity.
    Distance(f64),
    /// The sensor's distance behind the rear vertex.
    Sensor(f64),
}

/// A lens camera as a scene describes it (lengths in scene units).
#[derive(Clone, Debug, PartialEq)]
pub struct LensCameraSpec {
    pub surfaces: Vec<SurfaceSpec>,
    /// Sensor width and height.
    pub sensor: [f64; 2],
    pub focus: Focus,
    /// The stop's f-number; `None`: wide open.
    pub f_number: Option<f64>,
}

/// Why a lens camera is impossible: the `[camera]` key and the reason
/// (`lens` with a surface for a surface's problem).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct LensCameraError {
    pub field: &'static str,
    pub system: Option<crate::geometry::SystemError>,
    pub message: String,
}

fn fail<T>(field: &'static str, message: String) -> Result<T, LensCameraError> {
    Err(LensCameraError {
        field,
        system: None,
        message,
    })
}

#[derive(Clone, Debug, PartialEq)]
pub struct LensCamera {
    /// The system in camera space (axis `−z`).
    pub system: LensSystem,
    /// Paraxial data at the d line, with the stop as set.
    pub paraxial: Paraxial,
    pub sensor: [f64; 2],
    /// The sensor's distance behind the rear vertex.
    pub sensor_distance: f64,
    /// The distance in focus from the camera (infinite: at infinity).
    pub focus_distance: f64,
    /// The stop's paraxial f-number as set, and wide open.
    pub f_number: f64,
    pub open_f_number: f64,
    /// Paraxial lateral magnification of the plane in focus (negative:
    /// the image is inverted).
    pub magnification: f64,
    /// Camera-space `z` of the sensor and of the rear vertex.
    sensor_z: f64,
    rear_z: f64,
    half_diagonal: f64,
    /// The exit pupil's boxes and the exposure, found at the first ray
    /// (half a million rays: a scene is built, and checked, without them),
    /// or taken from [`SAMPLINGS`].
    sampling: OnceLock<Arc<Sampling>>,
    /// The media at the C, d and F lines ([`RGB_WAVELENGTHS_UM`]).
    media: Vec<Vec<f64>>,
}

impl LensCamera {
    pub fn new(spec: &LensCameraSpec) -> Result<LensCamera, LensCameraError> {
        let [sw, sh] = spec.sensor;
        if !(sw > 0.0 && sh > 0.0 && sw.is_finite() && sh.is_finite()) {
            return fail("sensor", format!("sensor {sw} × {sh} must be positive and finite"));
        }
        let (surfaces, open_f_number) = stopped_down(&spec.surfaces, spec.f_number)?;
        let probe = system_at(0.0, surfaces.clone()).map_err(|e| match spec.f_number {
            // The lens as given was built: the stop's new aperture failed.
            Some(n) => LensCameraError {
                field: "f_number",
                system: None,
                message: format!("f/{n} makes an impossible stop: {}", e.message),
            },
            None => e,
        })?;
        let paraxial = probe.paraxial(WAVELENGTH_D_UM);
        if !paraxial.efl.is_finite() || paraxial.efl <= 0.0 {
            return fail(
                "lens",
                format!(
                    "the lens has focal length {}: a camera needs a positive one",
                    paraxial.efl
                ),
            );
        }
        let e = paraxial.entrance_pupil.position;
        let system = system_at(e, surfaces)?;
        let (sensor_distance, focus_distance) = focus(&paraxial, spec.focus)?;
        let rear = system.length();
        let reach = (0..system.len())
            .map(|k| {
                system
                    .vertex_z(k)
                    .max(system.front(k, system.surfaces[k].semi_aperture))
            })
            .fold(f64::NEG_INFINITY, f64::max);
        if !(rear + sensor_distance > reach) {
            let field = match spec.focus {
                Focus::Distance(_) => "focus_distance",
                Focus::Sensor(_) => "sensor_distance",
            };
            return fail(
                field,
                format!(
                    "puts the sensor {sensor_distance:.6} behind the rear vertex, inside the lens (its rear reaches {:.6})",
                    reach - rear
                ),
            );
        }
        let media: Vec<Vec<f64>> = RGB_WAVELENGTHS_UM.iter().map(|&l| system.media(l).to_vec()).collect();
        let (sensor_z, rear_z) = (rear + sensor_distance - e, rear - e);
        let half_diagonal = 0.5 * libm::hypot(sw, sh);
        // The axial ray must pass: else nothing does near the centre.
        let axial = system.pass(DVec3::new(0.0, 0.0, sensor_z), DVec3::NEG_Z, &media[1]);
        if axial.is_none() {
            return fail("lens", "the ray along the axis does not pass the lens".into());
        }
        let f_number = paraxial.f_number;
        let magnification = magnification(&paraxial, sensor_distance);
        Ok(LensCamera {
            system,
            paraxial,
            sensor: spec.sensor,
            sensor_distance,
            focus_distance,
            f_number,
            open_f_number,
            magnification,
            sensor_z,
            rear_z,
            half_diagonal,
            sampling: OnceLock::new(),
            media,
        })
    }
}

/// The system with its first vertex `e` in front of the camera-space
/// origin, facing `−z`.
fn system_at(e: f64, surfaces: Vec<SurfaceSpec>) -> Result<LensSystem, LensCameraError> {
    LensSystem::new(DVec3::new(0.0, 0.0, -e), DVec3::NEG_Z, surfaces).map_err(|s| LensCameraError {
        field: "lens",
        message: s.message.clone(),
        system: Some(s),
    })
}

/// The surfaces with the stop's aperture set for `f_number` (paraxial:
/// the entrance pupil scales with the stop), and the lens's f-number wide
/// open.
fn stopped_down(surfaces: &[SurfaceSpec], f_number: Option<f64>) -> Result<(Vec<SurfaceSpec>, f64), LensCameraError> {
    let mut out = surfaces.to_vec();
    let open = system_at(0.0, out.clone())?.paraxial(WAVELENGTH_D_UM).f_number;
    let Some(n) = f_number else {
        return Ok((out, open));
    };
    if !(n > 0.0 && n.is_finite()) {
        return fail("f_number", format!("f-number {n} must be positive and finite"));
    }
    let Some(stop) = out.iter().position(|s| s.stop) else {
        return fail(
            "f_number",
            "the lens has no stop surface to set (mark one `stop = true`)".into(),
        );
    };
    if n < open * (1.0 - 1e-9) {
        return fail(
            "f_number",
            format!("f/{n} is faster than the lens opens: f/{open:.3} at most"),
        );
    }
    out[stop].semi_aperture *= open / n;
    Ok((out, open))
}

/// The nearest distance from the entrance pupil that a lens of paraxial
/// data `p` can focus on (the object at its front focal point).
pub fn nearest_focus(p: &Paraxial) -> f64 {
    p.efl - p.front_principal + p.entrance_pupil.position
}

/// The sensor's distance behind the rear vertex and the distance in focus
/// from the entrance pupil, by the thick-lens equation through the
/// principal planes (pbrt-v4's `FocusThickLens`, from the y–nu trace).
fn focus(p: &Paraxial, f: Focus) -> Result<(f64, f64), LensCameraError> {
    let efl = p.efl;
    let (h, h2, e) = (p.front_principal, p.rear_principal, p.entrance_pupil.position);
    match f {
        Focus::Distance(d) => {
            if d.is_infinite() && d > 0.0 {
                return Ok((h2 + efl, d));
            }
            // The object's distance before H.
            let so = h - e + d;
            if !(d > 0.0 && so > efl) {
                return fail(
                    "focus_distance",
                    format!(
                        "focus distance {d} is nearer than the lens can focus: it must exceed {:.6}",
                        nearest_focus(p)
                    ),
                );
            }
            Ok((h2 + efl * so / (so - efl), d))
        }
        Focus::Sensor(s) => {
            if !s.is_finite() {
                return fail("sensor_distance", format!("sensor distance {s} must be finite"));
            }
            let si = s - h2;
            // At F′ or nearer the lens: focused at infinity (or beyond).
            let d = if si <= efl {
                f64::INFINITY
            } else {
                efl * si / (si - efl) - h + e
            };
            Ok((s, d))
        }
    }
}

/// The paraxial lateral magnification of the plane the sensor sees sharp.
fn magnification(p: &Paraxial, sensor_distance: f64) -> f64 {
    let si = sensor_distance - p.rear_principal;
    // 1/si + 1/so = 1/f: m = −si/so = 1 − si/f.
    1.0 - si / p.efl
}

/// The weight's integral over the exit pupil at the sensor's centre
/// (cos⁴θ / z² over the points of `b` that pass, a 128 × 128 grid).
fn centre_weight(planes: &Planes, b: &PupilBox) -> f64 {
    const N: usize = 128;
    if b.is_empty() {
        return 0.0;
    }
    let z = planes.sensor_z - planes.rear_z;
    let sum: f64 = (0..N * N)
        .into_par_iter()
        .map(|i| {
            let p = b.lerp((((i % N) as f64 + 0.5) / N as f64, ((i / N) as f64 + 0.5) / N as f64));
            if planes.passes((0.0, 0.0), p) {
                cos4(libm::hypot(p.0, p.1), z)
            } else {
                0.0
            }
        })
        .sum();
    sum / (N * N) as f64 * b.area() / (z * z)
}

/// `cos⁴θ` of a ray that moves `r` across while it moves `z` along.
#[inline]
fn cos4(r: f64, z: f64) -> f64 {
    let c2 = z * z / (z * z + r * r);
    c2 * c2
}

/// What the camera samples by: the exit pupil's box for each interval of
/// sensor radius, and one over the weight's mean at the sensor's centre.
#[derive(Clone, Debug, PartialEq)]
struct Sampling {
    pupil: Vec<PupilBox>,
    exposure: f64,
}

/// What the pupil boxes and the exposure depend on: the system (its
/// surfaces and stop, in camera space), the sensor and its distance (the
/// focus); not the camera's pose nor the scene.
#[derive(PartialEq)]
struct SamplingKey {
    system: LensSystem,
    sensor: [f64; 2],
    sensor_distance: f64,
}

/// Samplings kept, the newest last: an edit of the scene or a move of the
/// camera builds a new [`LensCamera`], which finds its sampling here
/// instead of searching again (0.3–0.6 s); a few, so that stepping the
/// focus or f-number back and forth, or undoing, finds them too.
const SAMPLINGS_KEPT: usize = 8;
static SAMPLINGS: Mutex<Vec<(SamplingKey, Arc<Sampling>)>> = Mutex::new(Vec::new());

/// The kept sampling of `key`, if any.
fn cached(key: &SamplingKey) -> Option<Arc<Sampling>> {
    let cache = SAMPLINGS.lock().unwrap_or_else(|e| e.into_inner());
    cache.iter().find(|(k, _)| k == key).map(|(_, s)| s.clone())
}

/// A camera ray in camera space: origin, direction and weight.
pub struct LocalRay {
    pub origin: DVec3,
    pub dir: DVec3,
    pub weight: f64,
}

impl LocalRay {
    /// The ray in the world of the pinhole `cam`'s pose, and its weight.
    fn to_world(&self, cam: &Camera) -> (Ray, f64) {
        (
            Ray::new(cam.position + cam.to_world(self.origin), cam.to_world(self.dir)),
            self.weight,
        )
    }
}

/// A sensor ray before the system: the sensor point, the direction to the
/// pupil point (not unit) and the area of the pupil's box.
#[derive(Clone, Copy)]
struct Aim {
    film: DVec3,
    d: DVec3,
    area: f64,
}

impl LensCamera {
    /// The pupil boxes and the exposure, found once for each lens, sensor
    /// and focus ([`SAMPLINGS`]; [`super::pupil`]).
    fn sampling(&self) -> &Sampling {
        self.sampling.get_or_init(|| {
            let key = SamplingKey {
                system: self.system.clone(),
                sensor: self.sensor,
                sensor_distance: self.sensor_distance,
            };
            if let Some(s) = cached(&key) {
                return s;
            }
            let s = Arc::new(self.search());
            let mut cache = SAMPLINGS.lock().unwrap_or_else(|e| e.into_inner());
            if cache.len() == SAMPLINGS_KEPT {
                cache.remove(0);
            }
            cache.push((key, s.clone()));
            s
        })
    }

    /// Searches the pupil boxes and the exposure.
    fn search(&self) -> Sampling {
        let planes = Planes {
            system: &self.system,
            media: &self.media[1],
            sensor_z: self.sensor_z,
            rear_z: self.rear_z,
            exit_pupil: (
                self.rear_z + self.paraxial.exit_pupil.position,
                self.paraxial.exit_pupil.semi_diameter,
            ),
        };
        let half = 1.5 * self.system.surfaces[self.system.len() - 1].semi_aperture;
        let pupil: Vec<PupilBox> = (0..INTERVALS)
            .into_par_iter()
            .map(|i| {
                let r = |i: usize| i as f64 / INTERVALS as f64 * self.half_diagonal;
                planes.bound(half, (r(i), r(i + 1)))
            })
            .collect();
        // Not zero: the axial ray passes ([`LensCamera::new`]).
        let centre = centre_weight(&planes, &pupil[0]);
        Sampling {
            exposure: if centre > 0.0 { 1.0 / centre } else { 0.0 },
            pupil,
        }
    }

    /// The picture's width and height on the sensor for a `width × height`
    /// image: the largest centred rectangle of its aspect.
    pub fn picture(&self, width: u32, height: u32) -> (f64, f64) {
        let [sw, sh] = self.sensor;
        let a = width as f64 / height as f64;
        if a <= sw / sh { (sh * a, sh) } else { (sw, sw / a) }
    }

    /// The vertical field of view (degrees) of the pinhole at the camera
    /// that sees what the picture's full sensor height sees, to first
    /// order: chief rays through the entrance pupil's centre leave through
    /// the exit pupil's, their angle scaled by the pupils' ratio.
    pub fn fov_y_deg(&self) -> f64 {
        let (ep, xp) = (self.paraxial.entrance_pupil, self.paraxial.exit_pupil);
        let g = (self.sensor_distance - xp.position) * ep.semi_diameter / xp.semi_diameter;
        2.0 * libm::atan(0.5 * self.sensor[1] / g).to_degrees()
    }

    /// The exit pupil's box of each interval of sensor radius, from the
    /// centre to the sensor's half diagonal ([`super::pupil::INTERVALS`]).
    pub fn pupil_boxes(&self) -> &[PupilBox] {
        &self.sampling().pupil
    }

    /// Whether the lens's glass is dispersive (three wavelengths a sample).
    pub fn is_dispersive(&self) -> bool {
        self.system.is_dispersive()
    }

    /// The interval of sensor radius `r` (pbrt clamps the last).
    fn interval(&self, r: f64) -> usize {
        ((r / self.half_diagonal * INTERVALS as f64) as usize).min(INTERVALS - 1)
    }

    /// The sensor ray of continuous pixel position `(x, y)` of a `width ×
    /// height` picture toward the exit pupil's point `u` ∈ [0, 1)² of its
    /// box, in camera space: before the system ([`LensCamera::local_ray`]).
    /// `None` where the box is empty.
    fn aim(&self, (x, y): (f64, f64), (width, height): (u32, u32), u: (f64, f64)) -> Option<Aim> {
        let (pw, ph) = self.picture(width, height);
        let sx = (x / width as f64 - 0.5) * pw;
        let sy = (0.5 - y / height as f64) * ph;
        // The sensor point opposite the upright one: the lens inverts.
        let film = DVec3::new(-sx, -sy, self.sensor_z);
        let r = libm::hypot(sx, sy);
        let b = &self.sampling().pupil[self.interval(r)];
        if b.is_empty() {
            return None;
        }
        let (px, py) = b.lerp(u);
        let (c, s) = if r > 0.0 { (film.x / r, film.y / r) } else { (1.0, 0.0) };
        let rear = DVec3::new(c * px - s * py, s * px + c * py, self.rear_z);
        Some(Aim {
            film,
            d: rear - film,
            area: b.area(),
        })
    }

    /// The camera ray of `aim` after the system ([`LensSystem::pass`]
    /// gave `passed`), with its weight.
    fn finish(&self, aim: &Aim, passed: Option<(DVec3, DVec3)>) -> Option<LocalRay> {
        let (origin, dir) = passed?;
        if dir.z >= 0.0 {
            return None;
        }
        let (d, z) = (aim.d, self.sensor_z - self.rear_z);
        let weight = cos4(libm::hypot(d.x, d.y), z) * aim.area / (z * z) * self.sampling().exposure;
        Some(LocalRay { origin, dir, weight })
    }

    /// The camera ray of continuous pixel position `(x, y)` of a `width ×
    /// height` picture through the exit pupil's point `u` ∈ [0, 1)² of its
    /// box, at the wavelength `channel` of [`RGB_WAVELENGTHS_UM`] (1: the d
    /// line), in camera space; `None` where the system stops it.
    pub fn local_ray(&self, at: (f64, f64), size: (u32, u32), u: (f64, f64), channel: usize) -> Option<LocalRay> {
        let aim = self.aim(at, size, u)?;
        let passed = self.system.pass(aim.film, aim.d, &self.media[channel]);
        self.finish(&aim, passed)
    }

    /// [`LensCamera::local_ray`] of the lanes `l < n` (others: `None`),
    /// their sensor rays through the system together
    /// ([`LensSystem::pass_lanes`]): lane for lane the same bits.
    pub fn local_rays(
        &self,
        at: &Lanes<(f64, f64)>,
        size: (u32, u32),
        u: &Lanes<(f64, f64)>,
        n: usize,
        channel: usize,
    ) -> Lanes<Option<LocalRay>> {
        let aims: Lanes<Option<Aim>> = std::array::from_fn(|l| if l < n { self.aim(at[l], size, u[l]) } else { None });
        let (mut film, mut d) = ([[0.0; LANES]; 3], [[0.0; LANES]; 3]);
        for (l, a) in aims.iter().enumerate() {
            if let Some(a) = a {
                set_lane(&mut film, l, a.film);
                set_lane(&mut d, l, a.d);
            }
        }
        let live = aims.map(|a| a.is_some());
        let passed: Lanes<Passed> = self.system.pass_lanes(&film, &d, live, &self.media[channel]);
        std::array::from_fn(|l| aims[l].as_ref().and_then(|a| self.finish(a, passed[l])))
    }

    /// [`LensCamera::local_ray`] in the world of the pinhole `cam`'s pose.
    pub fn ray(
        &self,
        cam: &Camera,
        at: (f64, f64),
        size: (u32, u32),
        u: (f64, f64),
        channel: usize,
    ) -> Option<(Ray, f64)> {
        self.local_ray(at, size, u, channel).map(|r| r.to_world(cam))
    }

    /// [`LensCamera::ray`] of the lanes `l < n` ([`LensCamera::local_rays`]).
    pub fn rays(
        &self,
        cam: &Camera,
        at: &Lanes<(f64, f64)>,
        size: (u32, u32),
        u: &Lanes<(f64, f64)>,
        n: usize,
        channel: usize,
    ) -> Lanes<Option<(Ray, f64)>> {
        self.local_rays(at, size, u, n, channel)
            .map(|r| r.map(|r| r.to_world(cam)))
    }

    /// The share of camera rays that pass the system over a `width ×
    /// height` picture: a 64 × 48 grid of pixel positions, 16 pupil points
    /// each (Halton), at the d line.
    pub fn pass_share(&self, width: u32, height: u32) -> f64 {
        let (gx, gy, k) = (64u32, 48u32, 16u32);
        let passed: u32 = (0..gx * gy)
            .into_par_iter()
            .map(|i| {
                let at = (
                    ((i % gx) as f64 + 0.5) / gx as f64 * width as f64,
                    ((i / gx) as f64 + 0.5) / gy as f64 * height as f64,
                );
                (0..k)
                    .step_by(LANES)
                    .map(|j0| {
                        let u = std::array::from_fn(|l| {
                            let j = j0 + l as u32;
                            (radical_inverse(j, 2), radical_inverse(j, 3))
                        });
                        let n = (k - j0).min(LANES as u32) as usize;
                        let rays = self.local_rays(&[at; LANES], (width, height), &u, n, 1);
                        rays.iter().filter(|r| r.is_some()).count() as u32
                    })
                    .sum::<u32>()
            })
            .sum();
        passed as f64 / (gx * gy * k) as f64
    }
}
