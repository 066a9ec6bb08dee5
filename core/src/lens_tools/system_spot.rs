//! The spot diagram (C, d and F lines, hexapolar pupil) and the distortion
//! of the real chief ray for a lens system, on [`SystemBench`].

use super::bench::{LineSpot, distortion_percent, field_sweep};
use super::setup::SetupError;
use super::system_bench::{Aim, SystemBench, SystemRay};
use super::system_colour::{ChiefColour, lateral_colour_at};
use crate::optics::WAVELENGTH_D_UM;
use serde::Serialize;
use std::fmt;

/// One wavelength's spot.
pub type SystemSpot = LineSpot<SystemRay>;

#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct SystemSpotDiagram {
    pub surfaces: usize,
    pub object_distance: Option<f64>,
    pub field_deg: f64,
    /// `hexapolar`, with `rings` rings, over the pupil.
    pub sampling: &'static str,
    pub rings: u32,
    pub pupil: Aim,
    /// The pupil's centre (x, in units of its radius): 0, or the real
    /// chief ray's with `--aim-chief`.
    pub pupil_centre: f64,
    /// The image plane from the last vertex, and its local z.
    pub image_plane_from_last_vertex: f64,
    pub image_plane_z: f64,
    pub paraxial_image_from_last_vertex: Option<f64>,
    /// The plane is a magnifier's virtual image, before the last vertex:
    /// the image points are the rays' backward extensions. Absent when real.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub virtual_image: bool,
    pub spots: Vec<SystemSpot>,
}

pub fn system_spot(bench: &SystemBench, image_plane: Option<f64>, rings: u32) -> Result<SystemSpotDiagram, SetupError> {
    let traced = super::bench::spots(bench, image_plane, rings)?;
    Ok(SystemSpotDiagram {
        surfaces: bench.system.len(),
        object_distance: bench.object_distance,
        field_deg: bench.field_deg,
        sampling: "hexapolar",
        rings,
        pupil: bench.aim,
        pupil_centre: bench.centre,
        image_plane_from_last_vertex: traced.from_last,
        image_plane_z: traced.plane_z,
        paraxial_image_from_last_vertex: bench.paraxial_image().map(|p| p.0),
        virtual_image: traced.from_last < 0.0,
        spots: traced.spots,
    })
}

#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct SystemDistortionPoint {
    pub field_deg: f64,
    /// The real chief ray (aimed through the stop's centre), traced; its
    /// `image_point` is in the paraxial image plane. `null` when no ray
    /// through the stop's centre was found.
    pub chief_ray: Option<SystemRay>,
    /// Where that ray crosses the stop's vertex plane (≈ 0).
    pub stop_height: Option<f64>,
    /// The chief ray's height (x) in the image plane.
    pub real_height: Option<f64>,
    /// −EFL·tan A from infinity, m·(D + entrance pupil)·tan A from an object at D.
    pub paraxial_height: f64,
    /// 100·(real − paraxial)/paraxial.
    pub distortion_percent: Option<f64>,
    /// The F and C lines' chief rays in the same plane: lateral colour.
    #[serde(flatten)]
    pub colour: ChiefColour,
}

#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct SystemDistortion {
    pub surfaces: usize,
    pub object_distance: Option<f64>,
    pub efl: f64,
    /// The stop surface and its vertex from the first vertex.
    pub stop: usize,
    pub stop_z: f64,
    /// The paraxial image plane, from the last vertex along the light.
    pub image_plane_from_last_vertex: f64,
    pub magnification: Option<f64>,
    /// The image is virtual (a magnifier): the plane lies before the last
    /// vertex and the heights are the chief rays' backward extensions'.
    /// Absent when real.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub virtual_image: bool,
    pub points: Vec<SystemDistortionPoint>,
}

/// Field angles max·k/steps, k = 1..steps, at the d line; with the
/// lateral colour of the F and C lines in the same plane.
pub fn system_distortion(bench: &SystemBench, max_field_deg: f64, steps: u32) -> Result<SystemDistortion, SetupError> {
    super::distortion::check_fields(max_field_deg, steps)?;
    let (from_last, m, virtual_image) = bench.figure_image()?;
    let efl = bench.paraxial.efl;
    let plane_z = bench.plane_z(from_last);
    let sweep = field_sweep(
        bench,
        bench.object_distance,
        (efl, m, bench.aim.z),
        (max_field_deg, steps),
    );
    let points = sweep
        .into_iter()
        .map(|f| {
            let s = f.bench;
            let chief = s.chief_ray(WAVELENGTH_D_UM);
            let chief_ray = chief
                .as_ref()
                .map(|c| SystemRay::listed([c.px, 0.0], c.origin, c.dir, &c.ray, &s, WAVELENGTH_D_UM, plane_z));
            let real_height = chief_ray.as_ref().and_then(|r| r.image_point).map(|p| p[0]);
            SystemDistortionPoint {
                field_deg: f.field_deg,
                chief_ray,
                stop_height: chief.map(|c| c.stop_height),
                real_height,
                paraxial_height: f.paraxial_height,
                distortion_percent: distortion_percent(real_height, f.paraxial_height),
                colour: lateral_colour_at(&s, plane_z),
            }
        })
        .collect();
    Ok(SystemDistortion {
        surfaces: bench.system.len(),
        object_distance: bench.object_distance,
        efl,
        stop: bench.paraxial.stop,
        stop_z: bench.system.vertex_z(bench.paraxial.stop),
        image_plane_from_last_vertex: from_last,
        magnification: m,
        virtual_image,
        points,
    })
}

impl fmt::Display for SystemDistortion {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        let obj = self
            .object_distance
            .map_or("infinity".to_string(), |d| format!("{d} before the first vertex"));
        writeln!(
            f,
            "distortion: lens system of {} surfaces; object at {obj}",
            self.surfaces
        )?;
        writeln!(
            f,
            "  chief ray through the centre of the stop (surface {}); paraxial image plane {} after the last vertex; EFL {}",
            self.stop, self.image_plane_from_last_vertex, self.efl
        )?;
        writeln!(
            f,
            "  {:>10}  {:>24}  {:>24}  {:>14}  {:>24}",
            "field °", "real height", "paraxial height", "distortion %", "lateral colour F−C"
        )?;
        for p in &self.points {
            let opt = |x: Option<f64>| x.map_or("—".to_string(), |x| format!("{x}"));
            writeln!(
                f,
                "  {:>10}  {:>24}  {:>24}  {:>14}  {:>24}",
                p.field_deg,
                opt(p.real_height),
                p.paraxial_height,
                opt(p.distortion_percent.map(|x| (x * 1e6).round() / 1e6)),
                opt(p.colour.lateral_colour)
            )?;
        }
        Ok(())
    }
}
