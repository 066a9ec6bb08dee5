//! Surface materials: Phong coefficients, mirror reflectivity and
//! transparency with a refractive index.

use crate::color::Rgb;
use crate::optics::Index;

/// The smallest part of its peak a Phong lobe keeps: a highlight's tail
/// below a millionth of its peak is left out (at most 1e-6 of the light's
/// specular peak per light, far under one 8-bit step of the image unless
/// the highlight is already saturated about a thousandfold). For the lens's
/// glass (shininess 300) this drops the lobe where `r·v < 0.955`, and with
/// it most of the shadow rays from the lens's surface, which only the
/// highlight needs.
pub const LOBE_FLOOR: f64 = 1e-6;

#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Base colour (linear RGB); for transparent materials also the tint of
    /// transmitted light.
    pub color: Rgb,
    /// Ambient coefficient `ka`.
    pub ambient: f64,
    /// Lambert coefficient `kd`.
    pub diffuse: f64,
    /// Phong specular coefficient `ks`.
    pub specular: f64,
    /// Phong exponent.
    pub shininess: f64,
    /// Mirror reflectivity `kr` in [0, 1].
    pub reflectivity: f64,
    /// Transparency `kt` in [0, 1]: the part of light that is refracted
    /// (before Fresnel reflection takes its share).
    pub transparency: f64,
    /// Refractive index of a transparent material.
    pub ior: Index,
}

impl Material {
    /// A clear glass with a faint highlight, used for lenses.
    /// Clear glass of index `ior` and colour `tint`, for an object that is
    /// not a lens or a system.
    pub fn glass(tint: Rgb, ior: Index) -> Self {
        Material {
            color: tint,
            ambient: 0.0,
            diffuse: 0.0,
            specular: 0.6,
            shininess: 300.0,
            reflectivity: 0.0,
            transparency: 1.0,
            ior,
        }
    }

    /// The glass of a lens or a lens system of colour `tint`: the index is
    /// the shape's (`Object::ior`), so `ior` here is air and never read.
    pub fn glass_of_shape(tint: Rgb) -> Self {
        Material::glass(tint, Index::Constant(1.0))
    }

    /// The cosine `r·v` (mirrored light direction against the view
    /// direction) below which the Phong lobe `(r·v)^shininess` is under
    /// [`LOBE_FLOOR`] of its peak: shading leaves such a lobe out, and does
    /// not trace the shadow ray it alone would need. 0 for a shininess of 0
    /// (a lobe of 1 wherever `r·v > 0`).
    pub fn lobe_cos_min(&self) -> f64 {
        if self.shininess > 0.0 {
            libm::pow(LOBE_FLOOR, 1.0 / self.shininess).clamp(0.0, 1.0)
        } else {
            0.0
        }
    }

    pub fn is_transparent(&self) -> bool {
        self.transparency > 0.0
    }

    /// Fraction of light a shadow ray lets through this material, of index
    /// `n` (the object's: `Object::ior`): its transparency and tint, less the
    /// Fresnel reflection at normal incidence at the two faces it crosses,
    /// `(1 − R0)²` with `R0 = ((n−1)/(n+1))²`. Refraction of the shadow ray
    /// itself is ignored (see README, "Shadows of glass").
    pub fn shadow_transmittance(&self, n: f64) -> Rgb {
        if self.transparency <= 0.0 {
            return Rgb::ZERO;
        }
        let r0 = ((n - 1.0) / (n + 1.0)).powi(2);
        self.color * (self.transparency * (1.0 - r0) * (1.0 - r0))
    }
}
