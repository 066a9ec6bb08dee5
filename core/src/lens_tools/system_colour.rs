//! Lateral colour of a lens system: the height at which the real chief
//! ray of the F line (486.1 nm) meets the d line's paraxial image plane
//! minus the C line's (656.3 nm), against field angle. Each line's chief
//! ray is its own: the ray of that wavelength through the stop's centre
//! ([`SystemBench::chief_ray`]). Zero on the axis and for glass without
//! dispersion; the chief ray's own refraction sets it, so a stop at the
//! glass of a thin lens nearly cancels it and a stop away from it does not.

use super::setup::SPOT_WAVELENGTHS_UM;
use super::system_bench::SystemBench;
use serde::Serialize;

/// The F and C lines' chief rays at one field angle.
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
pub struct ChiefColour {
    /// The F line's chief ray height (x) in the image plane; `null` when
    /// that ray is not found or does not reach it.
    pub height_f: Option<f64>,
    /// The C line's.
    pub height_c: Option<f64>,
    /// Lateral colour, `height_f − height_c`.
    pub lateral_colour: Option<f64>,
}

/// The F and C chief rays of `bench` (at its field angle) on the plane
/// `plane_z` (local). `lens distortion` lists it beside the d line's chief
/// ray ([`super::system_spot::system_distortion`]).
pub fn lateral_colour_at(bench: &SystemBench, plane_z: f64) -> ChiefColour {
    let height = |lambda_um: f64| {
        let c = bench.chief_ray(lambda_um)?;
        bench.image_crossing(&c.ray, plane_z).map(|p| p.x)
    };
    let (height_c, height_f) = (height(SPOT_WAVELENGTHS_UM[0].1), height(SPOT_WAVELENGTHS_UM[2].1));
    ChiefColour {
        height_f,
        height_c,
        lateral_colour: height_f.zip(height_c).map(|(f, c)| f - c),
    }
}

/// The lateral colour from the axis out to the system's usable field, as
/// (field °, F − C) points: (0, 0), then `points` (field °, lateral
/// colour) up to the first field whose F or C chief ray is lost.
pub fn usable_curve(points: impl IntoIterator<Item = (f64, Option<f64>)>) -> Vec<[f64; 2]> {
    let mut curve = vec![[0.0, 0.0]];
    curve.extend(points.into_iter().map_while(|(a, l)| Some([a, l?])));
    curve
}

#[cfg(test)]
mod tests;
