//! Linear RGB colour and its conversion to 8-bit sRGB at output.
//!
//! Colours are `DVec3` in linear light; nothing is gamma-encoded until
//! [`to_srgb8`] writes a pixel.

use glam::DVec3;

/// Linear RGB.
pub type Rgb = DVec3;

/// The sRGB transfer function (IEC 61966-2-1) of one linear channel, clamped
/// to [0, 1].
pub fn linear_to_srgb(x: f64) -> f64 {
    let x = if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// Inverse of [`linear_to_srgb`].
pub fn srgb_to_linear(x: f64) -> f64 {
    if x <= 0.040_45 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    }
}

/// One linear colour to an 8-bit sRGB triple (rounded to nearest).
pub fn to_srgb8(c: Rgb) -> [u8; 3] {
    let f = |x: f64| (linear_to_srgb(x) * 255.0 + 0.5).floor() as u8;
    [f(c.x), f(c.y), f(c.z)]
}

/// [`linear_to_srgb`] as 8 bits through a table of 2¹⁶ entries over [0, 1]:
/// about 5× faster, for the viewer's frames; within one level of
/// [`to_srgb8`] (tested).
#[inline]
pub fn to_srgb8_fast(x: f64) -> u8 {
    Srgb8::table().channel(x)
}

/// The table of [`to_srgb8_fast`], fetched once for a whole frame.
#[derive(Clone, Copy)]
pub struct Srgb8(&'static [u8; 1 << 16]);

impl Srgb8 {
    pub fn table() -> Srgb8 {
        static LUT: std::sync::OnceLock<Box<[u8; 1 << 16]>> = std::sync::OnceLock::new();
        Srgb8(LUT.get_or_init(|| {
            Box::new(std::array::from_fn(|i| {
                (linear_to_srgb(i as f64 / 65535.0) * 255.0 + 0.5).floor() as u8
            }))
        }))
    }

    /// One channel ([`to_srgb8_fast`]): NaN is 0, [0, 1] clamped. The
    /// index, at most 65535.5 before the cast, fits `u16` (no bounds check).
    #[inline]
    pub fn channel(self, x: f64) -> u8 {
        let x = if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
        self.0[(x * 65535.0 + 0.5) as u16 as usize]
    }

    /// An opaque RGBA pixel.
    #[inline]
    pub fn rgba(self, c: Rgb) -> [u8; 4] {
        [self.channel(c.x), self.channel(c.y), self.channel(c.z), 255]
    }
}

/// Approximate linear RGB of a black body at `kelvin` (1000–40000 K),
/// normalised so the brightest channel is 1. Tanner Helland's fit of the CIE
/// data, converted from sRGB to linear.
pub fn blackbody(kelvin: f64) -> Rgb {
    let t = kelvin.clamp(1000.0, 40000.0) / 100.0;
    let r = if t <= 66.0 {
        255.0
    } else {
        329.698_727_446 * (t - 60.0).powf(-0.133_204_759_2)
    };
    let g = if t <= 66.0 {
        99.470_802_586_1 * t.ln() - 161.119_568_166_1
    } else {
        288.122_169_528_3 * (t - 60.0).powf(-0.075_514_849_2)
    };
    let b = if t >= 66.0 {
        255.0
    } else if t <= 19.0 {
        0.0
    } else {
        138.517_731_223_1 * (t - 10.0).ln() - 305.044_792_730_7
    };
    let c = DVec3::new(r, g, b).clamp(DVec3::ZERO, DVec3::splat(255.0)) / 255.0;
    let lin = DVec3::new(srgb_to_linear(c.x), srgb_to_linear(c.y), srgb_to_linear(c.z));
    lin / lin.max_element().max(1e-12)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_endpoints_and_midpoint() {
        assert_eq!(to_srgb8(DVec3::ZERO), [0, 0, 0]);
        assert_eq!(to_srgb8(DVec3::ONE), [255, 255, 255]);
        // 18% grey is sRGB 118.
        assert_eq!(to_srgb8(DVec3::splat(0.18))[0], 118);
        assert_eq!(to_srgb8(DVec3::splat(f64::NAN)), [0, 0, 0]);
        for i in 0..=100 {
            let x = i as f64 / 100.0;
            assert!((srgb_to_linear(linear_to_srgb(x)) - x).abs() < 1e-12);
        }
    }

    #[test]
    fn fast_srgb_is_within_one_level() {
        for i in 0..=100_000 {
            let x = i as f64 / 100_000.0;
            let exact = to_srgb8(DVec3::splat(x))[0] as i32;
            assert!((to_srgb8_fast(x) as i32 - exact).abs() <= 1, "{x}");
        }
        assert_eq!(to_srgb8_fast(f64::NAN), 0);
        assert_eq!(to_srgb8_fast(7.0), 255);
    }

    #[test]
    fn blackbody_is_warm_when_cool() {
        let warm = blackbody(2700.0);
        let cold = blackbody(10000.0);
        assert!(warm.x > warm.z && cold.z > cold.x);
        let d65 = blackbody(6600.0);
        assert!((d65 - DVec3::ONE).abs().max_element() < 0.05, "{d65}");
    }
}
