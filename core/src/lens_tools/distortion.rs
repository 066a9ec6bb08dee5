//! Distortion against field angle: the real chief ray (aimed at the centre
//! of the stop, the lens's centre C) against the thick-lens paraxial image
//! height, in the paraxial image plane at the d line; for a magnifier (the
//! object inside F) in its virtual image plane, before V2, with the chief
//! rays extended backwards (as Ray Optics Simulation draws them).

use super::bench::{distortion_percent, field_sweep};
use super::setup::{ListedRay, Setup, SetupError, bad};
use serde::Serialize;

/// The most field angles one curve samples.
pub const MAX_STEPS: u32 = 10_000;

#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct DistortionPoint {
    pub field_deg: f64,
    /// The chief ray, traced; its `image_point` is in the paraxial image plane.
    pub chief_ray: ListedRay,
    /// The chief ray's height (x) in that plane; `null` if it does not get there.
    pub real_height: Option<f64>,
    /// −EFL·tan A from infinity, m·(D + sag1)·tan A from an object at D.
    pub paraxial_height: f64,
    /// 100·(real − paraxial)/paraxial.
    pub distortion_percent: Option<f64>,
}

#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Distortion {
    pub d: f64,
    pub r1: f64,
    pub r2: f64,
    pub n: f64,
    pub object_distance: Option<f64>,
    pub efl: f64,
    /// The paraxial image plane, from V2 along the light.
    pub image_plane_from_v2: f64,
    /// Lateral magnification (`null` for an object at infinity).
    pub magnification: Option<f64>,
    /// The image is virtual (a magnifier: the object inside F): the plane
    /// lies before V2 (`image_plane_from_v2` < 0) and the chief rays'
    /// heights are those of their backward extensions. Absent when real.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub virtual_image: bool,
    pub points: Vec<DistortionPoint>,
}

/// Field angles max·k/steps, k = 1..steps, for the setup's object (its own
/// field angle is ignored).
pub fn distortion(setup: &Setup, max_field_deg: f64, steps: u32) -> Result<Distortion, SetupError> {
    check_fields(max_field_deg, steps)?;
    let n = setup.index.nominal();
    let (from_v2, m, virtual_image) = setup.figure_image(n)?;
    let efl = setup.paraxial(n).efl;
    let plane_z = setup.plane_z(from_v2);
    let sweep = field_sweep(
        setup,
        setup.object_distance,
        (efl, m, setup.sag1()),
        (max_field_deg, steps),
    );
    let points = sweep
        .into_iter()
        .map(|f| {
            let (chief_ray, _) = ListedRay::traced(&f.bench, 0.0, 0.0, n, plane_z);
            let real_height = chief_ray.image_point.map(|p| p[0]);
            DistortionPoint {
                field_deg: f.field_deg,
                chief_ray,
                real_height,
                paraxial_height: f.paraxial_height,
                distortion_percent: distortion_percent(real_height, f.paraxial_height),
            }
        })
        .collect();
    Ok(Distortion {
        d: setup.lens.d,
        r1: setup.lens.r1,
        r2: setup.lens.r2,
        n,
        object_distance: setup.object_distance,
        efl,
        image_plane_from_v2: from_v2,
        magnification: m,
        virtual_image,
        points,
    })
}

impl std::fmt::Display for Distortion {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        let obj = self
            .object_distance
            .map_or("infinity".to_string(), |d| format!("{d} before V1"));
        writeln!(
            f,
            "distortion: lens d = {}, R1 = {}, R2 = {}, n = {}; object at {obj}",
            self.d, self.r1, self.r2, self.n
        )?;
        if self.virtual_image {
            writeln!(
                f,
                "  chief ray aimed at the lens centre; virtual image {} before V2 (heights of the chief rays extended backwards), magnification {}; EFL {}",
                -self.image_plane_from_v2,
                self.magnification.unwrap_or(f64::NAN),
                self.efl
            )?;
        } else {
            writeln!(
                f,
                "  chief ray aimed at the lens centre; paraxial image plane {} after V2; EFL {}",
                self.image_plane_from_v2, self.efl
            )?;
        }
        writeln!(
            f,
            "  {:>10}  {:>24}  {:>24}  {:>14}",
            "field °", "real height", "paraxial height", "distortion %"
        )?;
        for p in &self.points {
            let opt = |x: Option<f64>| x.map_or("—".to_string(), |x| format!("{x}"));
            writeln!(
                f,
                "  {:>10}  {:>24}  {:>24}  {:>14}",
                p.field_deg,
                opt(p.real_height),
                p.paraxial_height,
                opt(p.distortion_percent.map(|x| (x * 1e6).round() / 1e6))
            )?;
        }
        Ok(())
    }
}

/// The field angles of a distortion sweep (the lens's and a system's): the
/// largest strictly inside (0, 90)°, 1 to [`MAX_STEPS`] steps.
pub(super) fn check_fields(max_field_deg: f64, steps: u32) -> Result<(), SetupError> {
    if !(max_field_deg > 0.0 && max_field_deg < 90.0) {
        return Err(bad(
            "max-field-deg",
            format!("{max_field_deg} must lie strictly between 0 and 90"),
        ));
    }
    if !(1..=MAX_STEPS).contains(&steps) {
        return Err(bad("steps", format!("{steps} must be between 1 and {MAX_STEPS}")));
    }
    Ok(())
}
