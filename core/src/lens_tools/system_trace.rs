//! `lens trace` for a lens system: a case with `"system"` instead of
//! `"lens"` (docs/lens-systems.md), each ray followed surface by surface
//! ([`LensSystem::trace`]) and every event listed.

use super::{RaySpec, TraceCase, TraceError, case_place, index_of};
use crate::geometry::{LensSystem, SurfaceSpec};
use crate::optics::WAVELENGTH_D_UM;
use crate::scene::file::IndexFile;
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// A system as a case gives it.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SystemSpec {
    pub vertex: [f64; 3],
    #[serde(default = "z_axis")]
    pub axis: [f64; 3],
    pub surfaces: Vec<SurfaceJson>,
}

fn z_axis() -> [f64; 3] {
    [0.0, 0.0, 1.0]
}

/// One surface of a [`SystemSpec`].
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SurfaceJson {
    #[serde(default)]
    pub radius: f64,
    #[serde(default)]
    pub thickness: f64,
    #[serde(default = "air")]
    pub n: IndexFile,
    pub semi_aperture: f64,
    #[serde(default)]
    pub stop: bool,
}

fn air() -> IndexFile {
    IndexFile::Constant(1.0)
}

/// One event of a ray: the piece, what happened, the point and the
/// direction after.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct EventOutput {
    pub surface: usize,
    pub piece: &'static str,
    pub kind: &'static str,
    pub point: [f64; 3],
    pub direction: [f64; 3],
}

/// A ray through a system as `lens trace` prints it.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct SystemRayOutput {
    pub id: serde_json::Value,
    /// "transmitted", "miss", "absorbed" or "trapped".
    pub status: &'static str,
    pub n_internal_reflections: u32,
    pub events: Vec<EventOutput>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exit_surface: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exit_point: Option<[f64; 3]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exit_direction: Option<[f64; 3]>,
}

impl SystemSpec {
    /// The system, or what is wrong with it (`surfaces[k].field: message`).
    pub fn build(&self) -> Result<LensSystem, String> {
        let surfaces = self
            .surfaces
            .iter()
            .map(|s| SurfaceSpec {
                radius: s.radius,
                thickness: s.thickness,
                n: index_of(s.n),
                semi_aperture: s.semi_aperture,
                stop: s.stop,
            })
            .collect();
        LensSystem::new(DVec3::from(self.vertex), DVec3::from(self.axis), surfaces).map_err(|e| match e.surface {
            Some(k) => format!("surfaces[{k}].{}: {}", e.field, e.message),
            None => format!("{}: {}", e.field, e.message),
        })
    }
}

/// The system of case `ci`, or what is wrong with it.
pub(super) fn case_system(ci: usize, case: &TraceCase) -> Result<LensSystem, TraceError> {
    let place = case_place(ci, case);
    let Some(spec) = &case.system else {
        return Err(TraceError {
            place,
            message: "needs `system`".into(),
        });
    };
    if case.lens.is_some() {
        return Err(TraceError {
            place,
            message: "gives both `lens` and `system`: one of the two".into(),
        });
    }
    spec.build().map_err(|message| TraceError {
        place: format!("{place}.system"),
        message,
    })
}

/// Checks ray `ri` of case `ci`: a finite origin outside the glass, a
/// finite non-zero direction, a positive wavelength at which every medium
/// has an index of at least 1. Returns the wavelength.
pub(super) fn check_ray(
    sys: &LensSystem,
    ci: usize,
    case: &TraceCase,
    ri: usize,
    r: &RaySpec,
) -> Result<f64, TraceError> {
    let place = || format!("{}.rays[{ri}] (id {})", case_place(ci, case), r.id);
    let fail = |field: &str, message: String| {
        Err(TraceError {
            place: place() + field,
            message,
        })
    };
    let origin = DVec3::from(r.origin);
    let dir = DVec3::from(r.direction);
    if !origin.is_finite() {
        return fail(".origin", "must be finite".into());
    }
    if sys.contains(origin) {
        return fail(".origin", "lies inside the glass: a ray starts in air".into());
    }
    if !(dir.is_finite() && dir.length() > 0.0) {
        return fail(".direction", "must be a finite non-zero vector".into());
    }
    let lambda = r.wavelength_um.unwrap_or(WAVELENGTH_D_UM);
    if !(lambda > 0.0 && lambda.is_finite()) {
        return fail(".wavelength_um", format!("{lambda} must be positive"));
    }
    for (k, s) in sys.surfaces.iter().enumerate() {
        let n = s.n.at(lambda);
        if !(n >= 1.0 && n.is_finite()) {
            return fail(
                ".wavelength_um",
                format!("index {n} after surface {k} at {lambda} µm is below 1"),
            );
        }
    }
    Ok(lambda)
}

/// Ray `ri` of case `ci` traced through `sys`.
pub(super) fn trace_ray(
    sys: &LensSystem,
    ci: usize,
    case: &TraceCase,
    ri: usize,
    r: &RaySpec,
) -> Result<SystemRayOutput, TraceError> {
    let lambda = check_ray(sys, ci, case, ri, r)?;
    let real = sys.trace(DVec3::from(r.origin), DVec3::from(r.direction), lambda);
    let events = real
        .events
        .iter()
        .map(|e| EventOutput {
            surface: e.piece.surface,
            piece: sys.piece_name(e.piece),
            kind: e.kind.name(),
            point: e.point.to_array(),
            direction: e.dir.to_array(),
        })
        .collect();
    Ok(SystemRayOutput {
        id: r.id.clone(),
        status: real.status.name(),
        n_internal_reflections: real.reflections,
        events,
        exit_surface: real.exit.map(|e| e.0.surface),
        exit_point: real.exit.map(|e| e.1.to_array()),
        exit_direction: real.exit.map(|e| e.2.to_array()),
    })
}
