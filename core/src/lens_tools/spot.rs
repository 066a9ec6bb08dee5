//! The spot diagram: hexapolar pupil rays for the C, d and F lines, where
//! each crosses the image plane, and their RMS radius about the centroid.

use super::setup::{ListedRay, Setup, SetupError, bad};
use serde::Serialize;

/// The most hexapolar rings (1 + 3·K·(K+1) rays per wavelength: 12 481 at 64).
pub const MAX_RINGS: u32 = 64;

/// Hexapolar sampling of the unit pupil with `rings` rings: the centre, then
/// ring k = 1..K at radius k/K with 6k points at angles 2πj/(6k), j = 0..6k.
pub fn hexapolar(rings: u32) -> Vec<[f64; 2]> {
    let mut pts = vec![[0.0, 0.0]];
    for k in 1..=rings {
        let r = f64::from(k) / f64::from(rings);
        let m = 6 * k;
        for j in 0..m {
            let a = std::f64::consts::TAU * f64::from(j) / f64::from(m);
            pts.push([r * a.cos(), r * a.sin()]);
        }
    }
    pts
}

/// One wavelength's spot: a system's ([`super::bench::LineSpot`]) with
/// the lens's index.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Spot {
    /// `C`, `d` or `F`.
    pub line: &'static str,
    pub wavelength_um: f64,
    pub n: f64,
    /// Rays that reach the image plane (those with an `image_point`).
    pub ray_count: usize,
    /// Mean of the image points' x and y over those rays.
    pub centroid: Option<[f64; 2]>,
    /// √(mean of |p − centroid|²) over those rays, in the plane.
    pub rms_radius: Option<f64>,
    pub rays: Vec<ListedRay>,
}

/// `lens spot`: the bench, the image plane, and one spot per wavelength.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct SpotDiagram {
    pub d: f64,
    pub r1: f64,
    pub r2: f64,
    /// Object distance from V1; `null`: at infinity.
    pub object_distance: Option<f64>,
    pub field_deg: f64,
    /// `hexapolar`, with `rings` rings, over PUPIL_FILL·d/2.
    pub sampling: &'static str,
    pub rings: u32,
    pub pupil_radius: f64,
    /// The image plane's distance from V2 along the light, and its world z.
    pub image_plane_from_v2: f64,
    pub image_plane_z: f64,
    /// The paraxial image (d line) from V2, when it is real.
    pub paraxial_image_from_v2: Option<f64>,
    /// The plane is a magnifier's virtual image, before V2: the image
    /// points are the rays' backward extensions. Absent when real.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub virtual_image: bool,
    pub spots: Vec<Spot>,
}

/// Centroid and RMS radius of points in the plane (`None` for none).
pub fn rms_and_centroid(points: &[[f64; 2]]) -> Option<([f64; 2], f64)> {
    if points.is_empty() {
        return None;
    }
    let k = points.len() as f64;
    let c = points.iter().fold([0.0, 0.0], |a, p| [a[0] + p[0], a[1] + p[1]]);
    let c = [c[0] / k, c[1] / k];
    let s: f64 = points
        .iter()
        .map(|p| (p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2))
        .sum();
    // The centroid printed: a coordinate below 1e-12 of the spot's reach
    // from the axis is rounding noise (an axial spot's 4e-18), shown as 0.
    let reach = points.iter().fold(0.0_f64, |m, p| m.max(p[0].abs()).max(p[1].abs()));
    let clean = |x: f64| if x.abs() < CENTROID_NOISE * reach { 0.0 } else { x };
    Some(([clean(c[0]), clean(c[1])], (s / k).sqrt()))
}

/// A centroid as printed: `(x, y)` in `digits`-digit scientific notation,
/// an exact 0 as `0` (the text of `lens spot` and the analysis window).
pub fn centroid_text(c: [f64; 2], digits: usize) -> String {
    let f = |x: f64| {
        if x == 0.0 {
            "0".to_string()
        } else {
            format!("{x:.digits$e}")
        }
    };
    format!("({}, {})", f(c[0]), f(c[1]))
}

/// Below this share of a spot's reach from the axis, a centroid coordinate
/// is rounding noise and is given as 0 ([`rms_and_centroid`]).
pub const CENTROID_NOISE: f64 = 1e-12;

/// A spot's rays that reach the image plane (those with an image point):
/// their count, and the centroid and RMS radius of their points.
pub fn spot_stats(image_points: impl IntoIterator<Item = Option<[f64; 3]>>) -> (usize, Option<([f64; 2], f64)>) {
    let hits: Vec<[f64; 2]> = image_points.into_iter().flatten().map(|p| [p[0], p[1]]).collect();
    (hits.len(), rms_and_centroid(&hits))
}

/// Rings of a hexapolar pupil (the lens's spot and a system's): 1 to
/// [`MAX_RINGS`].
pub(super) fn check_rings(rings: u32) -> Result<(), SetupError> {
    if !(1..=MAX_RINGS).contains(&rings) {
        return Err(bad("rings", format!("{rings} must be between 1 and {MAX_RINGS}")));
    }
    Ok(())
}

pub fn spot_diagram(setup: &Setup, image_plane: Option<f64>, rings: u32) -> Result<SpotDiagram, SetupError> {
    let traced = super::bench::spots(setup, image_plane, rings)?;
    let (from_v2, plane_z) = (traced.from_last, traced.plane_z);
    let spots = (traced.spots.into_iter())
        .map(|s| Spot {
            line: s.line,
            wavelength_um: s.wavelength_um,
            n: setup.index.at(s.wavelength_um),
            ray_count: s.ray_count,
            centroid: s.centroid,
            rms_radius: s.rms_radius,
            rays: s.rays,
        })
        .collect();
    Ok(SpotDiagram {
        d: setup.lens.d,
        r1: setup.lens.r1,
        r2: setup.lens.r2,
        object_distance: setup.object_distance,
        field_deg: setup.field_deg,
        sampling: "hexapolar",
        rings,
        pupil_radius: super::setup::PUPIL_FILL * 0.5 * setup.lens.d,
        image_plane_from_v2: from_v2,
        image_plane_z: plane_z,
        paraxial_image_from_v2: setup.paraxial_image(setup.index.nominal()).map(|p| p.0),
        virtual_image: from_v2 < 0.0,
        spots,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_centroid_of_rounding_noise_is_zero() {
        // Symmetric about the axis but for 4e-18 of rounding: 0, not 4e-18.
        let pts = [[0.03 + 4e-18, 1e-18], [-0.03, -0.02], [0.0, 0.02]];
        let (c, rms) = rms_and_centroid(&pts).unwrap();
        assert_eq!(c, [0.0, 0.0]);
        assert!(rms > 0.02);
        // A real offset is kept.
        let (c, _) = rms_and_centroid(&[[1.0, 1e-9], [1.0, 0.0]]).unwrap();
        assert_eq!(c, [1.0, 5e-10]);
        assert_eq!(centroid_text([0.0, -4.5e-1], 2), "(0, -4.50e-1)");
    }
}
