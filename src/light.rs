//! Lights: ambient, point (inverse-square) and directional.

use crate::color::Rgb;
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
            } => {
                let v = position - p;
                let r2 = v.length_squared();
                let r = r2.sqrt();
                LightSample {
                    to_light: v * (1.0 / r),
                    distance: r,
                    irradiance: color * (intensity / (4.0 * std::f64::consts::PI * r2)),
                }
            }
            Light::Directional {
                direction,
                color,
                intensity,
            } => LightSample {
                to_light: -direction,
                distance: f64::INFINITY,
                irradiance: color * intensity,
            },
        }
    }
}
