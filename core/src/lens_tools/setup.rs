//! The optical bench behind the fan, spot and distortion figures: a lens on
//! the z axis, an object at infinity or at a distance, a field angle, and
//! how a pupil point becomes a real ray.
//!
//! Frame: the lens's centre C at the origin, its axis +z. Light enters
//! through S1 (which faces +z) and travels toward −z; the meridional plane
//! is x–z. V1 = (0, 0, sag1), V2 = (0, 0, −sag2). Distances "along the
//! light" grow toward −z.
//!
//! The aperture stop is the lens itself: its rim circle (radius d/2 in the
//! plane through C), taken on the incoming rays (the entrance pupil is the
//! rim circle). A pupil point (px, py) in the unit disc is aimed at
//! C + PUPIL_FILL·(d/2)·(px, py, 0) before refraction; the chief ray
//! (0, 0) is aimed at C. The field angle A is the chief ray's angle to the
//! axis, tilted toward +x at the object: from infinity every ray has the
//! direction (−sin A, 0, −cos A) and starts in the plane d beyond V1; from
//! an object at distance D before V1 every ray starts at the object point
//! ((D + sag1)·tan A, 0, sag1 + D) ([`Setup::object_point`]).

use super::bench::{self, Bench, Names};
use crate::geometry::{Lens, LensError, LensPath, LensSurface, LensTraceStatus};
use crate::optics::{Index, ThickLens, WAVELENGTH_D_UM};
use crate::render::RGB_WAVELENGTHS_UM;
use glam::DVec3;
use serde::Serialize;

/// Share of the aperture radius d/2 the pupil fills (the marginal ray of
/// `lens info` is at 0.9·d/2 too): rays at the very rim, where S1 and S2
/// meet at an edge, are left out.
pub const PUPIL_FILL: f64 = 0.9;

/// The C, d and F lines (656.3, 587.6, 486.1 nm) the spot diagram uses, the
/// renderer's three wavelengths.
pub const SPOT_WAVELENGTHS_UM: [(&str, f64); 3] = [
    ("C", RGB_WAVELENGTHS_UM[0]),
    ("d", WAVELENGTH_D_UM),
    ("F", RGB_WAVELENGTHS_UM[2]),
];

/// A bad value, named by the option it came from (`d`, `r1`, `r2`, `n`,
/// `object-distance`, `field-deg`, `image-plane`, `rings`, `rays`).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("--{field}: {message}")]
pub struct SetupError {
    pub field: &'static str,
    pub message: String,
}

/// The lens bench's words in its refusals.
const NAMES: Names = Names {
    who: "lens",
    field: "n",
    last: "V2",
    after: "the rear vertex V2",
    where_: ", inside or in front of the glass",
};

pub(super) fn bad(field: &'static str, message: String) -> SetupError {
    SetupError { field, message }
}

/// The paraxial image of an object at infinity (`None`) or `dist` before
/// the first vertex, through a lens or system of focal length `efl`, back
/// focal distance `bfd` and principal planes `h` (H from the first vertex,
/// H′ from the last, both along the light): the image from the last
/// vertex along the light and the lateral magnification (`None` from
/// infinity); `None` for an object inside F (a virtual image).
pub(super) fn image_of(object_distance: Option<f64>, efl: f64, bfd: f64, h: [f64; 2]) -> Option<(f64, Option<f64>)> {
    match object_distance {
        None => Some((bfd, None)),
        Some(dist) => {
            if !(dist + h[0] > efl) {
                return None;
            }
            let p = paraxial_image(dist, efl, h)?;
            Some((p.from_last_vertex, Some(p.magnification)))
        }
    }
}

/// The paraxial image of an object `dist` before the first vertex (real
/// or virtual), through focal length `efl` and principal planes `h` (H
/// from the first vertex, H′ from the last, along the light).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ParaxialImage {
    /// From the last vertex along the light: negative before it, against
    /// the light (a virtual image lies on the object's side).
    pub from_last_vertex: f64,
    /// Lateral magnification: negative for a real, inverted image; above
    /// 1 for a magnifier's virtual, upright one.
    pub magnification: f64,
    /// Whether the rays leave diverging, as from a point before H′: the
    /// object inside F (a magnifier).
    #[serde(rename = "virtual")]
    pub is_virtual: bool,
}

/// [`ParaxialImage`] of an object `dist` before the first vertex; `None`
/// for an object at F (the image at infinity) or a lens without power.
pub fn paraxial_image(dist: f64, efl: f64, h: [f64; 2]) -> Option<ParaxialImage> {
    // From H to the object.
    let so = dist + h[0];
    if so == efl || !efl.is_finite() {
        return None;
    }
    let si = so * efl / (so - efl);
    Some(ParaxialImage {
        from_last_vertex: h[1] + si,
        magnification: -si / so,
        is_virtual: si < 0.0,
    })
}

/// The object of a bench (the lens's and a system's): at infinity or a
/// positive distance (at most 1e9) before `first`, at a field angle
/// strictly inside (−90, 90)°.
pub fn check_object(object_distance: Option<f64>, field_deg: f64, first: &str) -> Result<(), SetupError> {
    if let Some(dist) = object_distance
        && !(dist > 0.0 && dist <= crate::math::domain::MAX_LENGTH)
    {
        return Err(bad(
            "object-distance",
            format!("{dist} must be positive (from {first}, against the light) and at most 1e9"),
        ));
    }
    if !(field_deg.abs() < 90.0) {
        return Err(bad(
            "field-deg",
            format!("{field_deg} must lie strictly between −90 and 90"),
        ));
    }
    Ok(())
}

/// The lens on the z axis, where the light comes from, and the field angle.
#[derive(Clone, Debug)]
pub struct Setup {
    pub lens: Lens,
    pub index: Index,
    /// Object distance from V1 (against the light); `None`: at infinity.
    pub object_distance: Option<f64>,
    /// Field angle in degrees, in (−90, 90).
    pub field_deg: f64,
}

impl Setup {
    pub fn new(
        d: f64,
        r1: f64,
        r2: f64,
        index: Index,
        object_distance: Option<f64>,
        field_deg: f64,
    ) -> Result<Setup, SetupError> {
        let lens = Lens::new(DVec3::ZERO, DVec3::Z, d, r1, r2, index).map_err(|e: LensError| {
            let field = match e.field() {
                "d" => "d",
                "r1" => "r1",
                "r2" => "r2",
                _ => "n",
            };
            bad(field, e.to_string())
        })?;
        for (_, l) in SPOT_WAVELENGTHS_UM {
            let n = index.at(l);
            if !(n >= 1.0 && n.is_finite()) {
                return Err(bad("n", format!("index {n} at {l} µm must be ≥ 1")));
            }
        }
        check_object(object_distance, field_deg, "V1")?;
        Ok(Setup {
            lens,
            index,
            object_distance,
            field_deg,
        })
    }

    pub fn sag1(&self) -> f64 {
        self.lens.vertex(LensSurface::S1).z
    }

    pub fn sag2(&self) -> f64 {
        -self.lens.vertex(LensSurface::S2).z
    }

    /// The object point for a finite object distance: where the chief ray,
    /// aimed at C at the field angle, starts.
    pub fn object_point(&self, distance: f64) -> DVec3 {
        let z = self.sag1() + distance;
        bench::object_point(z, z, self.field_deg)
    }

    /// The real ray for the pupil point (px, py): its origin and unit
    /// direction, exactly as traced (and as listed in the JSON).
    pub fn ray(&self, px: f64, py: f64) -> (DVec3, DVec3) {
        let rho = PUPIL_FILL * 0.5 * self.lens.d;
        let aim = DVec3::new(px * rho, py * rho, 0.0);
        let object = self.object_distance.map(|dist| self.object_point(dist));
        // From infinity: back along the ray to the plane d beyond V1.
        bench::pupil_ray(aim, object, self.field_deg, -1.0, self.sag1() + self.lens.d)
    }

    /// The real ray traced by [`Lens::trace`] at index `n`.
    pub fn trace(&self, px: f64, py: f64, n: f64) -> (DVec3, DVec3, LensPath) {
        let (o, u) = self.ray(px, py);
        (o, u, self.lens.trace(o, u, n))
    }

    /// Paraxial data at index `n`.
    pub fn paraxial(&self, n: f64) -> ThickLens {
        self.lens.paraxial(n)
    }

    /// The paraxial image of the object, from V2 along the light, and the
    /// lateral magnification (`None` for an object at infinity); `None` when
    /// the lens has no power or the image is virtual (object inside F).
    pub fn paraxial_image(&self, n: f64) -> Option<(f64, Option<f64>)> {
        let px = self.paraxial(n);
        if !px.has_power() {
            return None;
        }
        image_of(self.object_distance, px.efl, px.bfd, [px.h1, px.h2])
    }

    /// The real paraxial image at index `n`, from V2 along the light, and
    /// the lateral magnification: the one rule `fan`, `spot` and
    /// `distortion` share. Refused, naming what was given that makes it
    /// so: no power (`n`: n = 1, or faces that cancel), the object inside
    /// the front focal point (`object-distance`, only when one was given),
    /// or an image that is not after V2 (`n`: the focus falls inside the
    /// glass or before it, where only the backward extension of the rays
    /// would meet; the lens's shape and index put it there).
    pub fn real_image(&self, n: f64) -> Result<(f64, Option<f64>), SetupError> {
        if !self.paraxial(n).has_power() {
            return Err(bad(
                "n",
                format!("the lens has no power at n = {n} (n = 1, or faces that cancel): it forms no image"),
            ));
        }
        bench::real_image(&NAMES, self.paraxial_image(n))
    }

    /// The image the figures (fan, spot, distortion) measure in, from V2
    /// along the light, its magnification, and whether it is virtual: the
    /// real paraxial image, or for an object inside F (a magnifier) the
    /// virtual one, before V2 on the object's side, where the rays'
    /// backward extensions are taken ([`bench::figure_image`]). Refused as
    /// [`Self::real_image`] otherwise.
    pub fn figure_image(&self, n: f64) -> Result<(f64, Option<f64>, bool), SetupError> {
        let px = self.paraxial(n);
        bench::figure_image(self.real_image(n), || {
            let dist = self.object_distance.filter(|_| px.has_power())?;
            paraxial_image(dist, px.efl, [px.h1, px.h2])
        })
    }

    /// World z of the plane `from_v2` beyond V2 along the light.
    pub fn plane_z(&self, from_v2: f64) -> f64 {
        -self.sag2() - from_v2
    }

    /// The image plane: `image_plane` if given (checked: after V2), else the
    /// paraxial image at the d line.
    pub fn image_plane(&self, image_plane: Option<f64>) -> Result<f64, SetupError> {
        bench::image_plane(&NAMES, image_plane, || self.figure_image(self.index.nominal()))
    }
}

/// Where a traced path crosses the plane z = `plane_z`: `None` unless it
/// was transmitted through S2 and travels toward −z.
pub fn plane_crossing(path: &LensPath, plane_z: f64) -> Option<DVec3> {
    let (s, x, u) = path.exit?;
    if path.status != LensTraceStatus::Transmitted || s != LensSurface::S2 || !(u.z < 0.0) {
        return None;
    }
    let t = (plane_z - x.z) / u.z;
    Some(DVec3::new(x.x + t * u.x, x.y + t * u.y, plane_z))
}

/// Where the exit line of the ray `origin + s·dir` at index `n` crosses the
/// axis of `lens` (placed on the z axis as the bench and `lens info` place
/// it; the ray in the meridional plane x–z), from V2 along the light;
/// `None` unless it leaves through S2, not parallel to the axis. A ray that
/// passes without a reflection inside (every ray as n → 1) is taken from
/// [`Lens::trace_fine`]: its exit slope is the incoming one plus a
/// deviation computed with n − 1 as a factor, so the focus keeps its
/// relative precision (from [`Lens::trace`]'s rounded exit direction it
/// would keep only ε/(n − 1): 2·10⁻³ of the focus at n − 1 = 10⁻¹³).
/// Any other path is taken from [`Lens::trace`].
pub fn exit_axis_crossing(lens: &Lens, origin: DVec3, dir: DVec3, n: f64) -> Option<f64> {
    let v2 = lens.vertex(LensSurface::S2) - lens.center;
    let crossing = |x: DVec3, u: DVec3| {
        let t = -x.x / u.x;
        (u.x != 0.0).then(|| (v2 - (x + t * u)).dot(lens.axis))
    };
    if let Some(f) = lens.trace_fine(origin, dir, n) {
        return crossing(f.exit_local, f.dir + f.deviation).filter(|_| f.exit_face == LensSurface::S2);
    }
    let path = lens.trace(origin, dir, n);
    let (s, x, u) = path.exit?;
    if path.status != LensTraceStatus::Transmitted || s != LensSurface::S2 {
        return None;
    }
    crossing(x - lens.center, u)
}

/// A ray as the JSON lists it: enough to trace it again.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct ListedRay {
    /// Pupil coordinates in the unit disc ([`PUPIL_FILL`]·d/2 at 1).
    pub pupil: [f64; 2],
    pub origin: [f64; 3],
    pub direction: [f64; 3],
    /// `transmitted`, `miss` or `trapped`, as `lens trace` says.
    pub status: &'static str,
    pub n_internal_reflections: u32,
    /// Where it crosses the image plane (`null` if it does not leave
    /// through S2 toward it).
    pub image_point: Option<[f64; 3]>,
}

pub(super) fn status_name(s: LensTraceStatus) -> &'static str {
    match s {
        LensTraceStatus::Transmitted => "transmitted",
        LensTraceStatus::Miss => "miss",
        LensTraceStatus::Trapped => "trapped",
    }
}

impl ListedRay {
    pub fn traced(setup: &Setup, px: f64, py: f64, n: f64, plane_z: f64) -> (ListedRay, LensPath) {
        let (o, u, path) = setup.trace(px, py, n);
        let ray = ListedRay {
            pupil: [px, py],
            origin: o.to_array(),
            direction: u.to_array(),
            status: status_name(path.status),
            n_internal_reflections: path.internal_reflections,
            image_point: plane_crossing(&path, plane_z).map(|p| p.to_array()),
        };
        (ray, path)
    }
}

impl Bench for Setup {
    type Ray = ListedRay;

    fn at_field(&self, field_deg: f64) -> Setup {
        Setup {
            field_deg,
            ..self.clone()
        }
    }

    fn axial(&self) -> Setup {
        self.at_field(0.0)
    }

    fn paraxial_image(&self) -> Option<(f64, Option<f64>)> {
        Setup::paraxial_image(self, self.index.nominal())
    }

    fn image_plane(&self, given: Option<f64>) -> Result<f64, SetupError> {
        Setup::image_plane(self, given)
    }

    fn plane_z(&self, from_last: f64) -> f64 {
        Setup::plane_z(self, from_last)
    }

    fn pupil_height(&self, px: f64) -> f64 {
        px * PUPIL_FILL * 0.5 * self.lens.d
    }

    fn listed(&self, px: f64, py: f64, lambda_um: f64, plane_z: f64) -> ListedRay {
        ListedRay::traced(self, px, py, self.index.at(lambda_um), plane_z).0
    }

    fn image_point(ray: &ListedRay) -> Option<[f64; 3]> {
        ray.image_point
    }

    fn focus_ray(&self, px: f64, plane_z: f64) -> (ListedRay, Option<f64>) {
        let n = self.index.nominal();
        let (ray, _) = ListedRay::traced(self, px, 0.0, n, plane_z);
        let (o, u) = self.ray(px, 0.0);
        (ray, exit_axis_crossing(&self.lens, o, u, n))
    }
}
