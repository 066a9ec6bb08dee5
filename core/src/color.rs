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
    let x = unit(x);
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * libm::pow(x, 1.0 / 2.4) - 0.055
    }
}

/// A linear channel as the output reads it: clamped to [0, 1], NaN as 0.
#[inline(always)]
fn unit(x: f64) -> f64 {
    if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) }
}

/// Inverse of [`linear_to_srgb`].
pub fn srgb_to_linear(x: f64) -> f64 {
    if x <= 0.040_45 {
        x / 12.92
    } else {
        libm::pow((x + 0.055) / 1.055, 2.4)
    }
}

/// One linear colour to an 8-bit sRGB triple (rounded to nearest): each
/// channel exactly [`srgb8_level`], found without a `powf` a channel.
pub fn to_srgb8(c: Rgb) -> [u8; 3] {
    let (table, steps) = (Srgb8::table(), srgb8_steps());
    [c.x, c.y, c.z].map(|x| {
        let x = unit(x);
        // The table's level is within one of the exact one (tested); the
        // levels' lowest values then decide.
        let mut level = table.channel(x) as usize;
        while level < 255 && x >= steps[level + 1] {
            level += 1;
        }
        while level > 0 && x < steps[level] {
            level -= 1;
        }
        level as u8
    })
}

/// The 8-bit level of one linear channel by definition: [`linear_to_srgb`]
/// scaled to 255 and rounded to nearest. [`to_srgb8`] gives the same
/// without computing it (`powf` was 7 % of a 640×360 focal-spot render,
/// all in writing the PNG).
pub fn srgb8_level(x: f64) -> u8 {
    (linear_to_srgb(x) * 255.0 + 0.5).floor() as u8
}

/// For each level `k` in 1..=255 the lowest `x` in [0, 1] whose
/// [`srgb8_level`] is at least `k` (found by bisection on the bits of
/// `x`, with the function itself, so the boundaries are its own); entry 0
/// is 0. The level rises with `x`, so a value's level is the number of
/// entries past 0 at most it.
fn srgb8_steps() -> &'static [f64; 256] {
    static STEPS: std::sync::OnceLock<[f64; 256]> = std::sync::OnceLock::new();
    STEPS.get_or_init(|| {
        std::array::from_fn(|k| {
            // Non-negative doubles are ordered as their bits.
            let (mut lo, mut hi) = (0u64, 1f64.to_bits());
            while lo < hi {
                let mid = lo + (hi - lo) / 2;
                if (srgb8_level(f64::from_bits(mid)) as usize) < k {
                    lo = mid + 1;
                } else {
                    hi = mid;
                }
            }
            f64::from_bits(lo)
        })
    })
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
        Srgb8(LUT.get_or_init(|| Box::new(std::array::from_fn(|i| srgb8_level(i as f64 / 65535.0)))))
    }

    /// One channel ([`to_srgb8_fast`]): NaN is 0, [0, 1] clamped. The
    /// index, at most 65535.5 before the cast, fits `u16` (no bounds check).
    #[inline]
    pub fn channel(self, x: f64) -> u8 {
        let x = unit(x);
        self.0[(x * 65535.0 + 0.5) as u16 as usize]
    }

    /// An opaque RGBA pixel.
    #[inline]
    pub fn rgba(self, c: Rgb) -> [u8; 4] {
        [self.channel(c.x), self.channel(c.y), self.channel(c.z), 255]
    }
}

/// How the picture's linear radiance becomes what is shown and written as
/// PNG: scaled by `2^exposure` (stops), then through `curve`, then sRGB
/// encoded (which clamps to [0, 1]). EXR output stays linear: no tone.
/// The default (0 stops, [`ToneCurve::Clamp`]) leaves every value as it is.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Tone {
    pub exposure: f64,
    pub curve: ToneCurve,
}

/// The tone curve of [`Tone`], applied per channel after the exposure.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ToneCurve {
    /// Values over 1 clip to white (the picture as it always was).
    #[default]
    Clamp,
    /// `x / (1 + x)`: never clips, compresses the highlights (and darkens
    /// mid-tones a little: 0.18 becomes 0.153).
    Reinhard,
    /// Narkowicz's fit of the ACES filmic curve: a toe and a shoulder,
    /// reaching white at about 7.2 (the fit, which overshoots 1, is cut there).
    Aces,
}

impl ToneCurve {
    pub const ALL: [ToneCurve; 3] = [ToneCurve::Clamp, ToneCurve::Reinhard, ToneCurve::Aces];

    /// The name used in scene files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            ToneCurve::Clamp => "clamp",
            ToneCurve::Reinhard => "reinhard",
            ToneCurve::Aces => "aces",
        }
    }

    /// The curve named `s` (as [`Self::name`] writes it).
    pub fn parse(s: &str) -> Option<ToneCurve> {
        ToneCurve::ALL.into_iter().find(|c| c.name() == s)
    }

    /// The next curve (the viewer's key cycles through them).
    pub fn next(self) -> ToneCurve {
        let i = ToneCurve::ALL.iter().position(|&c| c == self).unwrap_or(0);
        ToneCurve::ALL[(i + 1) % ToneCurve::ALL.len()]
    }

    /// One channel through the curve (NaN and negatives left to the sRGB
    /// encoding, which makes them 0).
    #[inline]
    pub fn map(self, x: f64) -> f64 {
        match self {
            ToneCurve::Clamp => x,
            ToneCurve::Reinhard => x.max(0.0) / (1.0 + x.max(0.0)),
            ToneCurve::Aces => {
                let x = x.max(0.0);
                ((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)).min(1.0)
            }
        }
    }
}

impl Tone {
    /// The widest exposure accepted, in stops either way.
    pub const MAX_STOPS: f64 = 20.0;

    /// Whether `stops` is an exposure accepted (finite, within ±[`Self::MAX_STOPS`]).
    pub fn accepts(stops: f64) -> bool {
        stops.is_finite() && stops.abs() <= Self::MAX_STOPS
    }

    /// Whether the tone leaves every value as it is (today's pictures).
    pub fn is_identity(self) -> bool {
        self.exposure == 0.0 && self.curve == ToneCurve::Clamp
    }

    /// A linear colour as the display gets it (before sRGB encoding).
    #[inline]
    pub fn apply(self, c: Rgb) -> Rgb {
        let c = c * libm::exp2(self.exposure);
        DVec3::new(self.curve.map(c.x), self.curve.map(c.y), self.curve.map(c.z))
    }

    /// One line saying the tone: "exposure +1.5 stops, reinhard".
    pub fn describe(self) -> String {
        format!("exposure {:+.1} stops, {}", self.exposure, self.curve.name())
    }
}

/// [`to_srgb8`] after `tone`: exactly [`to_srgb8`] for the identity.
pub fn to_srgb8_toned(c: Rgb, tone: Tone) -> [u8; 3] {
    if tone.is_identity() {
        to_srgb8(c)
    } else {
        to_srgb8(tone.apply(c))
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
        329.698_727_446 * libm::pow(t - 60.0, -0.133_204_759_2)
    };
    let g = if t <= 66.0 {
        99.470_802_586_1 * libm::log(t) - 161.119_568_166_1
    } else {
        288.122_169_528_3 * libm::pow(t - 60.0, -0.075_514_849_2)
    };
    let b = if t >= 66.0 {
        255.0
    } else if t <= 19.0 {
        0.0
    } else {
        138.517_731_223_1 * libm::log(t - 10.0) - 305.044_792_730_7
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

    /// `to_srgb8` is `srgb8_level` everywhere: at and around every level's
    /// boundary (the bits on either side), on a fine even grid, on random
    /// bits spread over [0, 1] and past its ends.
    #[test]
    fn srgb8_is_the_level_by_definition() {
        let check = |x: f64| assert_eq!(to_srgb8(DVec3::splat(x))[0], srgb8_level(x), "{x:e}");
        for &step in srgb8_steps() {
            let b = step.to_bits();
            for d in 0..8 {
                check(f64::from_bits(b + d));
                check(f64::from_bits(b.saturating_sub(d)));
            }
        }
        for i in 0..=1_000_000 {
            check(i as f64 / 1_000_000.0);
        }
        let mut seed = 0x853c_49e6_748f_ea9b_u64;
        for _ in 0..1_000_000 {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            check(f64::from_bits(seed % (1f64.to_bits() + 1)));
        }
        for x in [
            -1.0,
            -0.0,
            0.003_130_8,
            1.0,
            1.5,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MIN_POSITIVE,
            5e-324,
        ] {
            check(x);
        }
        assert_eq!(srgb8_steps()[0], 0.0);
        assert!(srgb8_steps().windows(2).all(|w| w[0] < w[1]));
    }

    #[test]
    fn fast_srgb_is_within_one_level() {
        for i in 0..=100_000 {
            let x = i as f64 / 100_000.0;
            let exact = srgb8_level(x) as i32;
            assert!((to_srgb8_fast(x) as i32 - exact).abs() <= 1, "{x}");
        }
        assert_eq!(to_srgb8_fast(f64::NAN), 0);
        assert_eq!(to_srgb8_fast(7.0), 255);
    }

    #[test]
    fn tone_identity_exposure_and_curves() {
        let c = DVec3::new(0.18, 2.0, 40.0);
        // The default changes nothing (pictures stay byte-identical).
        assert_eq!(to_srgb8_toned(c, Tone::default()), to_srgb8(c));
        // One stop doubles; two stops down quarters.
        let up = Tone {
            exposure: 1.0,
            curve: ToneCurve::Clamp,
        };
        assert_eq!(up.apply(c), c * 2.0);
        let down = Tone {
            exposure: -2.0,
            curve: ToneCurve::Clamp,
        };
        assert_eq!(to_srgb8_toned(DVec3::splat(2.0), down), to_srgb8(DVec3::splat(0.5)));
        // Reinhard and ACES never clip what clamp clips, and stay monotone.
        for curve in [ToneCurve::Reinhard, ToneCurve::Aces] {
            let t = Tone { exposure: 0.0, curve };
            let [a, b, _] = to_srgb8_toned(c, t);
            assert!(a < b && b < 255, "{curve:?}: {a} {b}");
            let mut last = -1.0;
            for i in 0..1000 {
                let y = curve.map(i as f64 * 0.05);
                assert!(y >= last && y <= 1.0 + 1e-12, "{curve:?} at {i}");
                last = y;
            }
            assert_eq!(ToneCurve::parse(curve.name()), Some(curve));
        }
        assert!((ToneCurve::Reinhard.map(0.18) - 0.18 / 1.18).abs() < 1e-15);
        assert_eq!(ToneCurve::Aces.next().next().next(), ToneCurve::Aces);
        assert_eq!(
            to_srgb8_toned(
                DVec3::splat(f64::NAN),
                Tone {
                    exposure: 1.0,
                    curve: ToneCurve::Aces
                }
            ),
            [0, 0, 0]
        );
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
