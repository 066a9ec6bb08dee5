//! The computations behind `lensview lens trace` and `lensview lens info`:
//! real rays through a lens described in JSON, and a lens's paraxial data
//! with its real marginal-ray focus and axial colour.

use crate::geometry::{Lens, LensError, LensSurface, LensTraceStatus, MAX_INTERNAL_REFLECTIONS};
use crate::optics::{Index, ThickLens, WAVELENGTH_D_UM};
use crate::render::RGB_WAVELENGTHS_UM;
use crate::scene::file::IndexFile;
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// `{ "cases": [ … ] }`. Unknown keys are ignored (files may carry notes).
#[derive(Clone, Debug, Deserialize)]
pub struct TraceInput {
    pub cases: Vec<TraceCase>,
}

#[derive(Clone, Debug, Deserialize)]
pub struct TraceCase {
    #[serde(default)]
    pub id: serde_json::Value,
    pub lens: LensSpec,
    pub rays: Vec<RaySpec>,
}

#[derive(Clone, Debug, Deserialize)]
pub struct LensSpec {
    pub center: [f64; 3],
    pub axis: [f64; 3],
    pub d: f64,
    #[serde(alias = "r1")]
    #[serde(rename = "R1")]
    pub r1: f64,
    #[serde(alias = "r2")]
    #[serde(rename = "R2")]
    pub r2: f64,
    pub n: IndexFile,
}

#[derive(Clone, Debug, Deserialize)]
pub struct RaySpec {
    #[serde(default)]
    pub id: serde_json::Value,
    pub origin: [f64; 3],
    pub direction: [f64; 3],
    #[serde(default)]
    pub wavelength_um: Option<f64>,
}

#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct TraceOutput {
    pub cases: Vec<CaseOutput>,
}

#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct CaseOutput {
    pub id: serde_json::Value,
    pub rays: Vec<RayOutput>,
}

#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct RayOutput {
    pub id: serde_json::Value,
    /// "transmitted", "miss", or "trapped" (more than
    /// [`MAX_INTERNAL_REFLECTIONS`] total internal reflections).
    pub status: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub entry_surface: Option<&'static str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub entry_point: Option<[f64; 3]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub entry_direction: Option<[f64; 3]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exit_surface: Option<&'static str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exit_point: Option<[f64; 3]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exit_direction: Option<[f64; 3]>,
    pub n_internal_reflections: u32,
    /// Index used for this ray (after the wavelength, for Cauchy glass).
    pub n: f64,
}

/// A problem with one case or ray, named by its position and id.
#[derive(Debug, thiserror::Error)]
#[error("{place}: {message}")]
pub struct TraceError {
    pub place: String,
    pub message: String,
}

pub fn index_of(n: IndexFile) -> Index {
    match n {
        IndexFile::Constant(n) => Index::Constant(n),
        IndexFile::Cauchy([a, b]) => Index::Cauchy { a, b },
    }
}

fn lens_field(e: &LensError) -> &'static str {
    match e.field() {
        "r1" => "R1",
        "r2" => "R2",
        f => f,
    }
}

/// Traces every ray of every case.
pub fn trace_cases(input: &TraceInput) -> Result<TraceOutput, TraceError> {
    let mut cases = Vec::with_capacity(input.cases.len());
    for (ci, case) in input.cases.iter().enumerate() {
        let place = format!("cases[{ci}] (id {})", case.id);
        let l = &case.lens;
        let index = index_of(l.n);
        let lens =
            Lens::new(DVec3::from(l.center), DVec3::from(l.axis), l.d, l.r1, l.r2, index).map_err(|e| TraceError {
                place: format!("{place}.lens.{}", lens_field(&e)),
                message: e.to_string(),
            })?;
        let mut rays = Vec::with_capacity(case.rays.len());
        for (ri, r) in case.rays.iter().enumerate() {
            let rplace = || format!("{place}.rays[{ri}] (id {})", r.id);
            let origin = DVec3::from(r.origin);
            let dir = DVec3::from(r.direction);
            if !origin.is_finite() {
                return Err(TraceError {
                    place: rplace() + ".origin",
                    message: "must be finite".into(),
                });
            }
            if !(dir.is_finite() && dir.length() > 0.0) {
                return Err(TraceError {
                    place: rplace() + ".direction",
                    message: "must be a finite non-zero vector".into(),
                });
            }
            let lambda = r.wavelength_um.unwrap_or(WAVELENGTH_D_UM);
            if !(lambda > 0.0 && lambda.is_finite()) {
                return Err(TraceError {
                    place: rplace() + ".wavelength_um",
                    message: format!("{lambda} must be positive"),
                });
            }
            let n = index.at(lambda);
            if !(n >= 1.0 && n.is_finite()) {
                return Err(TraceError {
                    place: rplace() + ".wavelength_um",
                    message: format!("index {n} at {lambda} µm is below 1"),
                });
            }
            let p = lens.trace(origin, dir, n);
            let side =
                |x: Option<(LensSurface, DVec3, DVec3)>| x.map(|(s, p, d)| (s.name(), p.to_array(), d.to_array()));
            let entry = side(p.entry);
            let exit = side(p.exit);
            rays.push(RayOutput {
                id: r.id.clone(),
                status: match p.status {
                    LensTraceStatus::Transmitted => "transmitted",
                    LensTraceStatus::Miss => "miss",
                    LensTraceStatus::Trapped => "trapped",
                },
                entry_surface: entry.map(|e| e.0),
                entry_point: entry.map(|e| e.1),
                entry_direction: entry.map(|e| e.2),
                exit_surface: exit.map(|e| e.0),
                exit_point: exit.map(|e| e.1),
                exit_direction: exit.map(|e| e.2),
                n_internal_reflections: p.internal_reflections,
                n,
            });
        }
        cases.push(CaseOutput {
            id: case.id.clone(),
            rays,
        });
    }
    Ok(TraceOutput { cases })
}

/// `lens info`: paraxial data, the real marginal-ray focus, axial colour.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct LensInfo {
    pub d: f64,
    pub r1: f64,
    pub r2: f64,
    pub wavelength_um: f64,
    pub n: f64,
    pub thickness: f64,
    pub sag1: f64,
    pub sag2: f64,
    /// Effective focal length; `None` (JSON `null`) when the lens has no
    /// power, as are the four below: see [`LensInfo::no_power`].
    pub efl: Option<f64>,
    /// Back focal distance, from the vertex of S2 (light enters through S1).
    pub bfd: Option<f64>,
    /// Front focal distance, before the vertex of S1.
    pub ffd: Option<f64>,
    /// Front principal plane H, from V1, positive in the direction of travel.
    pub principal_front_from_v1: Option<f64>,
    /// Rear principal plane H', from V2, positive in the direction of travel.
    pub principal_rear_from_v2: Option<f64>,
    /// Why the focal data are `null`: at n = 1 the lens bends no ray and its
    /// focal lengths are infinite (JSON has no ∞). Absent for a lens with power.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub no_power: Option<&'static str>,
    /// Height of the real marginal ray, 0.9·d/2.
    pub marginal_height: f64,
    /// Where the real marginal ray (or its backward extension) crosses the
    /// axis, from V2 (`null` if it does not leave through S2).
    pub marginal_focus_from_v2: Option<f64>,
    /// Longitudinal spherical aberration: marginal focus − BFD.
    pub spherical_aberration: Option<f64>,
    /// For Cauchy glass: back focal distance at F (486.1 nm) minus at C
    /// (656.3 nm); negative when blue focuses closer, as in every simple lens.
    pub axial_colour: Option<f64>,
    pub max_internal_reflections: u32,
}

/// [`LensInfo::no_power`]'s reason.
pub const NO_POWER: &str =
    "n = 1: the lens bends no ray; its focal lengths are infinite and it has no principal planes";

/// The real ray parallel to the axis at height `h` through a lens on the z
/// axis: where it crosses the axis, measured from V2 along the direction of
/// travel.
pub fn real_focus(lens: &Lens, h: f64, n: f64) -> Option<f64> {
    let start = lens.vertex(LensSurface::S1) + lens.axis * lens.d + DVec3::X * h;
    let p = lens.trace(start, -lens.axis, n);
    let (s, x, u) = p.exit?;
    // The crossing of the exit ray's line with the axis; for a strongly
    // aberrated lens (a ball lens at 0.9 of its aperture) it lies before V2.
    if p.status != LensTraceStatus::Transmitted || s != LensSurface::S2 || u.x == 0.0 {
        return None;
    }
    let t = -x.x / u.x;
    let cross = x + t * u;
    Some((lens.vertex(LensSurface::S2) - cross).dot(lens.axis))
}

pub fn lens_info(d: f64, r1: f64, r2: f64, index: Index, wavelength_um: f64) -> Result<LensInfo, LensError> {
    let lens = Lens::new(DVec3::ZERO, DVec3::Z, d, r1, r2, index)?;
    let n = index.at(wavelength_um);
    if !(n >= 1.0 && n.is_finite()) {
        return Err(LensError::Index(n));
    }
    let px = ThickLens::new(d, r1, r2, n);
    let h = 0.9 * 0.5 * d;
    // Without power a ray leaves parallel: it has no focus.
    let power = px.has_power();
    let marginal = real_focus(&lens, h, n).filter(|_| power);
    let focal = |x: f64| Some(x).filter(|_| power);
    let axial_colour = index.is_dispersive().then(|| {
        let bfd = |l: f64| ThickLens::new(d, r1, r2, index.at(l)).bfd;
        bfd(RGB_WAVELENGTHS_UM[2]) - bfd(RGB_WAVELENGTHS_UM[0])
    });
    Ok(LensInfo {
        d,
        r1,
        r2,
        wavelength_um,
        n,
        thickness: px.thickness,
        sag1: px.sag1,
        sag2: px.sag2,
        efl: focal(px.efl),
        bfd: focal(px.bfd),
        ffd: focal(px.ffd),
        principal_front_from_v1: focal(px.h1),
        principal_rear_from_v2: focal(px.h2),
        no_power: (!power).then_some(NO_POWER),
        marginal_height: h,
        marginal_focus_from_v2: marginal,
        spherical_aberration: marginal.map(|m| m - px.bfd),
        axial_colour,
        max_internal_reflections: MAX_INTERNAL_REFLECTIONS,
    })
}

impl std::fmt::Display for LensInfo {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        // Shortest representation that reads back to the same f64: every digit shown is meant.
        let g = |x: f64| format!("{x:<24}");
        writeln!(
            f,
            "lens d = {}, R1 = {}, R2 = {}, n = {} at λ = {} µm",
            self.d, self.r1, self.r2, self.n, self.wavelength_um
        )?;
        writeln!(f, "  centre thickness           {}", g(self.thickness))?;
        writeln!(f, "  sagitta S1, S2             {}, {}", g(self.sag1), g(self.sag2))?;
        if let Some(why) = self.no_power {
            writeln!(f, "  no power ({why})")?;
            writeln!(f, "  effective focal length     ∞")?;
            writeln!(f, "  back focal distance        ∞")?;
            writeln!(f, "  front focal distance       ∞")?;
            writeln!(f, "  principal planes H, H'     none")?;
            writeln!(
                f,
                "  real ray at 0.9·d/2 = {} leaves parallel: no focus",
                self.marginal_height
            )?;
            return Ok(());
        }
        let g = |x: Option<f64>| format!("{:<24}", x.unwrap_or(f64::NAN));
        writeln!(f, "  effective focal length     {}", g(self.efl))?;
        writeln!(f, "  back focal distance        {}   (from V2)", g(self.bfd))?;
        writeln!(f, "  front focal distance       {}   (before V1)", g(self.ffd))?;
        writeln!(
            f,
            "  principal plane H          {}   (from V1, + along the light)",
            g(self.principal_front_from_v1)
        )?;
        writeln!(
            f,
            "  principal plane H'         {}   (from V2, + along the light)",
            g(self.principal_rear_from_v2)
        )?;
        let g = |x: f64| format!("{x:<24}");
        match (self.marginal_focus_from_v2, self.spherical_aberration) {
            (Some(m), Some(sa)) => {
                writeln!(
                    f,
                    "  real focus of ray at 0.9·d/2 {}   (from V2; h = {})",
                    g(m),
                    self.marginal_height
                )?;
                writeln!(f, "  longitudinal sph. aberr.   {}   (real − paraxial)", g(sa))?;
            }
            _ => writeln!(
                f,
                "  real ray at 0.9·d/2 = {} does not leave through S2",
                self.marginal_height
            )?,
        }
        if let Some(c) = self.axial_colour {
            writeln!(f, "  axial colour BFD(F) − BFD(C) {}   (486.1 nm − 656.3 nm)", g(c))?;
        }
        Ok(())
    }
}
