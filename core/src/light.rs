//! Lights: ambient, point (inverse-square) and directional.

use crate::color::Rgb;
use crate::simd::{LANES, Lanes, lane, set_lane};
use glam::DVec3;

/// A light that can cast shadows.
#[derive(Clone, Debug, PartialEq)]
pub enum Light {
    /// An isotropic point light of total power `intensity` (scene units):
    /// its radiant intensity is `intensity / 4π` per steradian, so the
    /// irradiance on a surface at distance `r` tilted by θ is
    /// `E = (intensity/4π)·cos θ / r²`.
    Point {
        position: DVec3,
        color: Rgb,
        intensity: f64,
    },
    /// Parallel light travelling along the unit vector `direction`, giving
    /// irradiance `intensity·cos θ` everywhere.
    Directional {
        direction: DVec3,
        color: Rgb,
        intensity: f64,
    },
}

/// What a light delivers at a point.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Unit vector from the point toward the light.
    pub to_light: DVec3,
    /// Distance to the light (∞ for a directional light).
    pub distance: f64,
    /// Coloured irradiance on a surface facing the light (before cos θ).
    pub irradiance: Rgb,
}

impl Light {
    pub fn sample(&self, p: DVec3) -> LightSample {
        match *self {
            Light::Point {
                position,
                color,
                intensity,
            } => point_sample(position, color, intensity, p),
            Light::Directional {
                direction,
                color,
                intensity,
            } => directional_sample(direction, color, intensity),
        }
    }

    /// [`Light::sample`] at each lane's point `p` (structure of arrays),
    /// the same arithmetic lane by lane, as a lane loop (the form the
    /// vectoriser wants).
    #[inline(always)]
    pub fn sample_lanes(&self, p: &[Lanes<f64>; 3], out: &mut LightLanes) {
        match *self {
            Light::Point {
                position,
                color,
                intensity,
            } => {
                for l in 0..LANES {
                    out.set(l, &point_sample(position, color, intensity, lane(p, l)));
                }
            }
            Light::Directional {
                direction,
                color,
                intensity,
            } => {
                let s = directional_sample(direction, color, intensity);
                for l in 0..LANES {
                    out.set(l, &s);
                }
            }
        }
    }
}

/// A point light's sample at `p`.
#[inline(always)]
fn point_sample(position: DVec3, color: Rgb, intensity: f64, p: DVec3) -> LightSample {
    let v = position - p;
    let r2 = v.length_squared();
    let r = r2.sqrt();
    LightSample {
        to_light: v * (1.0 / r),
        distance: r,
        irradiance: color * (intensity / (4.0 * std::f64::consts::PI * r2)),
    }
}

/// A directional light's sample (the same everywhere).
#[inline(always)]
fn directional_sample(direction: DVec3, color: Rgb, intensity: f64) -> LightSample {
    LightSample {
        to_light: -direction,
        distance: f64::INFINITY,
        irradiance: color * intensity,
    }
}

/// One light's samples at [`LANES`] points, structure of arrays
/// ([`Light::sample_lanes`]).
#[derive(Clone, Copy, Debug)]
pub struct LightLanes {
    to_light: [Lanes<f64>; 3],
    distance: Lanes<f64>,
    irradiance: [Lanes<f64>; 3],
}

impl LightLanes {
    pub const EMPTY: LightLanes = LightLanes {
        to_light: [[0.0; LANES]; 3],
        distance: [0.0; LANES],
        irradiance: [[0.0; LANES]; 3],
    };

    #[inline(always)]
    fn set(&mut self, l: usize, s: &LightSample) {
        set_lane(&mut self.to_light, l, s.to_light);
        self.distance[l] = s.distance;
        set_lane(&mut self.irradiance, l, s.irradiance);
    }

    /// Lane `l`'s sample.
    #[inline(always)]
    pub fn get(&self, l: usize) -> LightSample {
        LightSample {
            to_light: lane(&self.to_light, l),
            distance: self.distance[l],
            irradiance: lane(&self.irradiance, l),
        }
    }
}
