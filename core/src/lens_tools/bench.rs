//! What the lens's bench ([`super::Setup`]) and a system's
//! ([`super::system_bench::SystemBench`]) share: how a pupil point becomes a
//! ray, the real image and the image plane with their refusals, and the
//! [`Bench`] trait the figures (fan, LSA, spot, distortion) are computed
//! on once for both.

use super::setup::{ParaxialImage, SPOT_WAVELENGTHS_UM, SetupError, bad};
use super::spot::{check_rings, hexapolar, spot_stats};
use glam::DVec3;
use serde::Serialize;

/// A bench's words in its refusals: where its image must lie and what is
/// blamed when it does not.
pub(super) struct Names {
    /// `lens` or `system`.
    pub who: &'static str,
    /// The option blamed for an image before the last vertex.
    pub field: &'static str,
    /// The last vertex (`V2`).
    pub last: &'static str,
    /// The same in an `--image-plane` refusal.
    pub after: &'static str,
    /// Said after "before V2" of an image that lies there.
    pub where_: &'static str,
}

/// The real paraxial image from the last vertex and the magnification, from
/// `image` (`None`: the object inside F) and refused as the figures refuse
/// it: the object inside the front focal point, or an image not after the
/// last vertex. The bench checks its power first.
pub(super) fn real_image(names: &Names, image: Option<(f64, Option<f64>)>) -> Result<(f64, Option<f64>), SetupError> {
    let Some((from_last, m)) = image else {
        return Err(bad(
            "object-distance",
            format!(
                "the object is inside the front focal point: the {} forms no real image of it",
                names.who
            ),
        ));
    };
    if !(from_last > 0.0) {
        return Err(bad(
            names.field,
            format!(
                "the paraxial image lies {:.6} before {}{}: the {} forms no real image after it",
                -from_last, names.last, names.where_, names.who
            ),
        ));
    }
    Ok((from_last, m))
}

/// The image the figures measure in when no plane is given: from the last
/// vertex, the magnification, and whether it is virtual. The real paraxial
/// image (`real`); or, for an object inside F (a magnifier), its virtual
/// image before the last vertex on the object's side (`virtual_image`),
/// where the rays' backward extensions meet, as Ray Optics Simulation draws
/// them. Refused as `real` is otherwise.
pub(super) fn figure_image(
    real: Result<(f64, Option<f64>), SetupError>,
    virtual_image: impl FnOnce() -> Option<ParaxialImage>,
) -> Result<(f64, Option<f64>, bool), SetupError> {
    let refused = match real {
        Ok((from_last, m)) => return Ok((from_last, m, false)),
        Err(e) => e,
    };
    match virtual_image() {
        Some(p) if p.is_virtual => Ok((p.from_last_vertex, Some(p.magnification), true)),
        _ => Err(refused),
    }
}

/// The image plane from the last vertex: `given` if given (checked: after
/// the last vertex, at most 1e9), else the figures' image `image()` (real,
/// or a magnifier's virtual one: [`figure_image`]).
pub(super) fn image_plane(
    names: &Names,
    given: Option<f64>,
    image: impl FnOnce() -> Result<(f64, Option<f64>, bool), SetupError>,
) -> Result<f64, SetupError> {
    match given {
        Some(z) if z > 0.0 && z <= crate::math::domain::MAX_LENGTH => Ok(z),
        Some(z) => Err(bad(
            "image-plane",
            format!(
                "{z} must be a distance after {} along the light (> 0, at most 1e9)",
                names.after
            ),
        )),
        None => image().map(|(z, _, _)| z).map_err(|e| {
            bad(
                e.field,
                format!("{}; give --image-plane to trace to a plane of your own", e.message),
            )
        }),
    }
}

/// The object point at the field angle `field_deg`: `from_pupil` before
/// the pupil plane (the chief ray's height there is zero), at `z`.
pub(super) fn object_point(from_pupil: f64, z: f64, field_deg: f64) -> DVec3 {
    DVec3::new(from_pupil * field_deg.to_radians().tan(), 0.0, z)
}

/// The ray through the pupil point `aim`: from the object point, or from
/// infinity at `field_deg` (the light along `forward`·z, ±1), starting
/// `back` along the axis before the aim's plane. Its origin and unit
/// direction.
pub(super) fn pupil_ray(aim: DVec3, object: Option<DVec3>, field_deg: f64, forward: f64, back: f64) -> (DVec3, DVec3) {
    match object {
        Some(o) => (o, (aim - o).normalize()),
        None => {
            let a = field_deg.to_radians();
            let dir = DVec3::new(-a.sin(), 0.0, forward * a.cos());
            let t = back / a.cos();
            (aim - t * dir, dir)
        }
    }
}

/// A bench the figures are computed on: the lens's or a system's.
pub trait Bench: Clone {
    /// A ray as the JSON lists it.
    type Ray;
    /// The same bench at another field angle.
    fn at_field(&self, field_deg: f64) -> Self;
    /// The bench for the axial object point.
    fn axial(&self) -> Self;
    /// The paraxial image at the design wavelength, from the last vertex,
    /// and the magnification ([`super::setup::image_of`]).
    fn paraxial_image(&self) -> Option<(f64, Option<f64>)>;
    /// The image plane from the last vertex (`given`, or the real image).
    fn image_plane(&self, given: Option<f64>) -> Result<f64, SetupError>;
    /// The plane `from_last` after the last vertex: its `z`.
    fn plane_z(&self, from_last: f64) -> f64;
    /// A pupil x as a height in the pupil.
    fn pupil_height(&self, px: f64) -> f64;
    /// The pupil ray (px, py) at `lambda_um`, listed with where it crosses
    /// the plane `plane_z`.
    fn listed(&self, px: f64, py: f64, lambda_um: f64, plane_z: f64) -> Self::Ray;
    /// Where a listed ray crosses the image plane.
    fn image_point(ray: &Self::Ray) -> Option<[f64; 3]>;
    /// The meridional ray px at the design wavelength, listed to `plane_z`,
    /// and where its exit line crosses the axis from the last vertex.
    fn focus_ray(&self, px: f64, plane_z: f64) -> (Self::Ray, Option<f64>);
}

/// One wavelength's spot (a system's as it is listed; the lens's adds its
/// index).
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct LineSpot<R> {
    /// `C`, `d` or `F`.
    pub line: &'static str,
    pub wavelength_um: f64,
    /// Rays that reach the image plane (those with an `image_point`).
    pub ray_count: usize,
    /// Mean of the image points' x and y over those rays.
    pub centroid: Option<[f64; 2]>,
    /// √(mean of |p − centroid|²) over those rays, in the plane.
    pub rms_radius: Option<f64>,
    pub rays: Vec<R>,
}

/// The spots of the C, d and F lines in an image plane.
pub(super) struct Spots<R> {
    /// The plane's distance from the last vertex, and its `z`.
    pub from_last: f64,
    pub plane_z: f64,
    pub spots: Vec<LineSpot<R>>,
}

/// The spots of the C, d and F lines with `rings` hexapolar rings in the
/// image plane (`image_plane` or the real image).
pub(super) fn spots<B: Bench>(bench: &B, image_plane: Option<f64>, rings: u32) -> Result<Spots<B::Ray>, SetupError> {
    check_rings(rings)?;
    let from_last = bench.image_plane(image_plane)?;
    let plane_z = bench.plane_z(from_last);
    let pupil = hexapolar(rings);
    let spots = SPOT_WAVELENGTHS_UM
        .iter()
        .map(|&(line, l)| {
            let rays: Vec<B::Ray> = (pupil.iter()).map(|p| bench.listed(p[0], p[1], l, plane_z)).collect();
            let (ray_count, stats) = spot_stats(rays.iter().map(B::image_point));
            LineSpot {
                line,
                wavelength_um: l,
                ray_count,
                centroid: stats.map(|s| s.0),
                rms_radius: stats.map(|s| s.1),
                rays,
            }
        })
        .collect();
    Ok(Spots {
        from_last,
        plane_z,
        spots,
    })
}

/// The pupil x of each of `rays` meridional fan rays, from −1 to 1 (0 for
/// one ray); refused beyond [`super::fan::MAX_FAN_RAYS`].
pub(super) fn fan_pupil(rays: u32) -> Result<Vec<f64>, SetupError> {
    let most = super::fan::MAX_FAN_RAYS;
    if !(1..=most).contains(&rays) {
        return Err(bad("rays", format!("{rays} must be between 1 and {most}")));
    }
    let px = |k: u32| {
        if rays == 1 {
            0.0
        } else {
            -1.0 + 2.0 * f64::from(k) / f64::from(rays - 1)
        }
    };
    Ok((0..rays).map(px).collect())
}

/// One point of an LSA curve: the pupil height, the ray, where its exit
/// line crosses the axis (from the last vertex) and that minus the
/// paraxial image.
pub(super) struct Lsa<R> {
    pub height: f64,
    pub ray: R,
    pub focus: Option<f64>,
    pub lsa: Option<f64>,
}

/// The LSA curve of the axial object point: pupil heights k/steps of the
/// pupil, k = 1..steps, at the design wavelength.
pub(super) fn lsa<B: Bench>(bench: &B, steps: u32) -> Vec<Lsa<B::Ray>> {
    let axial = bench.axial();
    let paraxial = axial.paraxial_image().map(|p| p.0);
    let plane_z = axial.plane_z(paraxial.unwrap_or(0.0));
    (1..=steps)
        .map(|k| {
            let px = f64::from(k) / f64::from(steps);
            let (ray, focus) = axial.focus_ray(px, plane_z);
            let focus = focus.filter(|_| paraxial.is_some());
            Lsa {
                height: bench.pupil_height(px),
                ray,
                focus,
                lsa: focus.zip(paraxial).map(|(f, p)| f - p),
            }
        })
        .collect()
}

/// A distortion sweep's point: the field angle, the bench there, and the
/// paraxial height in the image plane.
pub(super) struct Field<B> {
    pub field_deg: f64,
    pub bench: B,
    pub paraxial_height: f64,
}

/// Field angles max·k/steps, k = 1..steps: the bench at each and the
/// paraxial chief ray's height: −EFL·tan A from infinity, m·(D + p)·tan A
/// from an object at D, with the pupil `p` after the first vertex.
pub(super) fn field_sweep<B: Bench>(
    bench: &B,
    object_distance: Option<f64>,
    (efl, m, p): (f64, Option<f64>, f64),
    (max_field_deg, steps): (f64, u32),
) -> Vec<Field<B>> {
    (1..=steps)
        .map(|k| {
            let a = max_field_deg * f64::from(k) / f64::from(steps);
            let t = a.to_radians().tan();
            let paraxial_height = match (object_distance, m) {
                (Some(dist), Some(m)) => m * (dist + p) * t,
                _ => -efl * t,
            };
            Field {
                field_deg: a,
                bench: bench.at_field(a),
                paraxial_height,
            }
        })
        .collect()
}

/// The distortion in percent of a real height against the paraxial one.
pub(super) fn distortion_percent(real: Option<f64>, paraxial: f64) -> Option<f64> {
    real.map(|h| 100.0 * (h - paraxial) / paraxial)
}
