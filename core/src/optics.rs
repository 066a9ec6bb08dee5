//! Optics in the optician's words: reflection, Snell refraction, Fresnel
//! reflectance, refractive index models and thick-lens paraxial data.
//!
//! Conventions: a surface normal `n` passed here is unit length and faces the
//! side the incident ray comes from (`dot(i, n) < 0`); directions are unit.

use crate::glass::Glass;
use crate::math::renormalize;
use glam::DVec3;

/// The d line of helium (587.5618 nm), where a single "n" is quoted.
pub const WAVELENGTH_D_UM: f64 = 0.587_561_8;

/// Wavelengths (µm) at which dispersive glass is traced for the red, green
/// and blue channels: the Fraunhofer C (hydrogen, 656.3 nm), d (helium,
/// 587.6 nm) and F (hydrogen, 486.1 nm) lines, the lines an optician quotes
/// dispersion at. Camera samples and caustic photons both use them.
pub const RGB_WAVELENGTHS_UM: [f64; 3] = [0.656_281_6, WAVELENGTH_D_UM, 0.486_132_7];

/// Mirror reflection of the unit direction `i` about the unit normal `n`:
/// `r = i − 2(i·n)n`.
#[inline]
pub fn reflect(i: DVec3, n: DVec3) -> DVec3 {
    i - 2.0 * i.dot(n) * n
}

/// Snell refraction of the unit direction `i` at a surface with unit normal `n`
/// facing the incident side, going from index `n1` to `n2`.
///
/// With `η = n1/n2`, `cos θi = −i·n` and `sin² θt = η²(1 − cos² θi)`, the
/// refracted direction is `t = η·i + (η·cos θi − cos θt)·n` (Hecht, *Optics*,
/// §4.4; Glassner, *An Introduction to Ray Tracing*, ch. 6). `1 − cos² θi` is
/// computed as `|i × n|²`, which keeps its relative precision near normal
/// incidence. Returns `None` for total internal reflection.
#[inline]
pub fn refract(i: DVec3, n: DVec3, n1: f64, n2: f64) -> Option<DVec3> {
    let (eta, cos_i, sin2_t) = snell(i, n, n1, n2);
    if sin2_t > 1.0 {
        return None;
    }
    Some(refracted(i, n, eta, cos_i, sin2_t).0)
}

/// What [`refract`], [`crossing`] and [`fresnel_at`] share: `η = n1/n2`,
/// `cos θi = −i·n` and `sin² θt = η²·|i × n|²`.
#[inline(always)]
fn snell(i: DVec3, n: DVec3, n1: f64, n2: f64) -> (f64, f64, f64) {
    let eta = n1 / n2;
    let cos_i = -i.dot(n);
    let sin2_i = i.cross(n).length_squared();
    (eta, cos_i, eta * eta * sin2_i)
}

/// The refracted unit direction and `cos θt` from [`snell`]'s numbers (not
/// numbers under total internal reflection, `sin² θt > 1`).
#[inline(always)]
fn refracted(i: DVec3, n: DVec3, eta: f64, cos_i: f64, sin2_t: f64) -> (DVec3, f64) {
    let cos_t = (1.0 - sin2_t).sqrt();
    // Unit up to rounding: `renormalize` (no square root, no division).
    (renormalize(eta * i + (eta * cos_i - cos_t) * n), cos_t)
}

/// How much [`refract`] turns a ray: the refracted direction `t` minus the
/// incident one, for the incident direction `i + di` (`i` unit, `di` a
/// small earlier deviation, zero at a first refraction) at a surface of
/// unit normal `n` facing it, from index `n1` into `n2`. `None` under total
/// internal reflection (or at grazing incidence).
///
/// With `η = n1/n2`, `t − v = (η − 1)·[n × (v × n) + (η + 1)·sin²θi /
/// (cos θi + cos θt)·n]` for the incident `v`: the tangential part is
/// Snell's `(η − 1)·v_t` and the normal part `cos θi − cos θt` written as
/// `(η² − 1)·sin²θi/(cos θi + cos θt)`. `η − 1 = (n1 − n2)/n2` is a
/// factor, so the deviation keeps its relative precision as the indices
/// meet (at n − 1 = 10⁻¹³, `refract(…) − i`, the difference of two nearly
/// equal unit vectors, keeps only ε/10⁻¹³ of its digits); `v × n` is taken
/// as `i × n + di × n`, so `di` loses nothing to being added to `i`.
pub fn refraction_deviation(i: DVec3, di: DVec3, n: DVec3, n1: f64, n2: f64) -> Option<DVec3> {
    let eta = n1 / n2;
    let eta_m1 = (n1 - n2) / n2;
    let cos_i = -(i.dot(n) + di.dot(n));
    let w = i.cross(n) + di.cross(n);
    let sin2_i = w.length_squared();
    let sin2_t = eta * eta * sin2_i;
    let cos_sum = cos_i + (1.0 - sin2_t).sqrt();
    if !(sin2_t <= 1.0 && cos_sum > 0.0) {
        return None;
    }
    Some(eta_m1 * (n.cross(w) + ((eta + 1.0) * sin2_i / cos_sum) * n))
}

/// One crossing of an interface ([`crossing`]).
#[derive(Clone, Copy, Debug)]
pub struct Crossing {
    /// [`refract`]'s direction.
    pub dir: DVec3,
    /// [`fresnel_at`]'s reflectance.
    pub reflectance: f64,
    /// Total internal reflection: `dir` and `reflectance` are then not
    /// numbers to use.
    pub total: bool,
}

/// [`refract`] and [`fresnel_at`] of one crossing from one set of cosines
/// (one square root for `cos θt`), bit for bit what each gives alone, and
/// written without branches so that packet lanes can run it side by side.
#[inline(always)]
pub fn crossing(i: DVec3, n: DVec3, n1: f64, n2: f64) -> Crossing {
    let (eta, cos_i, sin2_t) = snell(i, n, n1, n2);
    let (dir, cos_t) = refracted(i, n, eta, cos_i, sin2_t);
    Crossing {
        dir,
        reflectance: fresnel_cosines(cos_i, cos_t, n1, n2),
        total: sin2_t > 1.0,
    }
}

/// The Fresnel reflectance where the unit direction `i` meets a surface of
/// unit normal `n` (facing it) from index `n1` into `n2`, from the very
/// cosines [`refract`] computes: the reflectance and the refracted ray of
/// one crossing agree to the last bit, and a caller that needs both takes
/// them from [`crossing`] with one square root. 1 under total internal
/// reflection.
#[inline]
pub fn fresnel_at(i: DVec3, n: DVec3, n1: f64, n2: f64) -> f64 {
    let (_, cos_i, sin2_t) = snell(i, n, n1, n2);
    if sin2_t > 1.0 {
        return 1.0;
    }
    fresnel_cosines(cos_i, (1.0 - sin2_t).sqrt(), n1, n2)
}

/// Unpolarised Fresnel reflectance of a dielectric interface (the mean of the
/// s and p reflectances, Hecht eq. 4.34/4.40); 1 under total internal
/// reflection. `cos_i` is the cosine of the incidence angle (≥ 0): for a
/// caller that has only that cosine (the renderer, which has the
/// directions, uses [`fresnel_at`] and [`crossing`]).
#[inline]
pub fn fresnel_dielectric(cos_i: f64, n1: f64, n2: f64) -> f64 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let eta = n1 / n2;
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    let total = sin2_t >= 1.0;
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let r = fresnel_cosines(cos_i, cos_t, n1, n2);
    if total { 1.0 } else { r }
}

/// The unpolarised Fresnel reflectance from both cosines, `cos θi` (clamped
/// to [0, 1]) and `cos θt`, below the critical angle: the mean of
/// `rs = (n1·cos θi − n2·cos θt)/(n1·cos θi + n2·cos θt)` and
/// `rp = (n1·cos θt − n2·cos θi)/(n1·cos θt + n2·cos θi)` squared. No branch
/// and no square root.
#[inline]
pub fn fresnel_cosines(cos_i: f64, cos_t: f64, n1: f64, n2: f64) -> f64 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    // rs and rp squared and summed over one common denominator: one
    // division instead of two.
    let (a, b) = (n1 * cos_i, n2 * cos_t);
    let (c, d) = (n1 * cos_t, n2 * cos_i);
    let (s_num, s_den) = ((a - b) * (a - b), (a + b) * (a + b));
    let (p_num, p_den) = ((c - d) * (c - d), (c + d) * (c + d));
    0.5 * (s_num * p_den + p_num * s_den) / (s_den * p_den)
}

/// A refractive index: a constant, Cauchy's law `n(λ) = A + B/λ²` with λ in
/// micrometres, or a catalogue glass (Sellmeier, `crate::glass`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Index {
    Constant(f64),
    Cauchy { a: f64, b: f64 },
    Glass(&'static Glass),
}

impl Index {
    /// The index at wavelength `lambda_um` (ignored for a constant).
    pub fn at(&self, lambda_um: f64) -> f64 {
        match *self {
            Index::Constant(n) => n,
            Index::Cauchy { a, b } => a + b / (lambda_um * lambda_um),
            Index::Glass(g) => g.n(lambda_um),
        }
    }

    /// The index at the d line.
    pub fn nominal(&self) -> f64 {
        self.at(WAVELENGTH_D_UM)
    }

    pub fn is_dispersive(&self) -> bool {
        matches!(*self, Index::Cauchy { b, .. } if b != 0.0) || matches!(self, Index::Glass(_))
    }
}

/// Sagitta of a spherical cap of radius `r` over a half-aperture `h ≤ r`:
/// `r − √(r² − h²)`, written as `h²/(r + √((r−h)(r+h)))` so that it keeps full
/// precision when `r ≫ h` (nearly flat faces) and when `r = h` (hemisphere).
pub fn sagitta(r: f64, h: f64) -> f64 {
    let root = ((r - h) * (r + h)).max(0.0).sqrt();
    h * h / (r + root)
}

/// Distance from a cap's rim plane to its sphere's centre: `√(r² − h²)`,
/// computed as `√((r−h)(r+h))`.
pub fn centre_offset(r: f64, h: f64) -> f64 {
    ((r - h) * (r + h)).max(0.0).sqrt()
}

/// Paraxial (first-order) data of a thick biconvex lens in air, for light
/// entering through S1.
///
/// In the usual sign convention (light travels left to right, a radius is
/// positive when its centre of curvature lies to the right of the vertex) the
/// biconvex lens has `R1s = +r1` and `R2s = −r2`. With centre thickness `t`
/// and index `n`, the lensmaker's equation for a thick lens is
/// `1/f = (n−1)·(1/R1s − 1/R2s + (n−1)·t/(n·R1s·R2s))`, the principal planes
/// lie at `h1 = −f(n−1)t/(n·R2s)` from V1 and `h2 = −f(n−1)t/(n·R1s)` from
/// V2 (both positive to the right), and the focal distances are
/// `BFD = f + h2` (from V2) and `FFD = f − h1` (before V1). Hecht, *Optics*,
/// 5th ed., §6.1, eqs. 6.1–6.4.
///
/// At `n = 1` the glass is air and the lens has no power
/// ([`ThickLens::has_power`] is false): `efl`, `bfd` and `ffd` are +∞ and
/// there are no principal planes (`h1`, `h2` are NaN).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThickLens {
    pub thickness: f64,
    pub sag1: f64,
    pub sag2: f64,
    pub efl: f64,
    pub bfd: f64,
    pub ffd: f64,
    /// Front principal plane H, from V1, positive in the direction of travel.
    pub h1: f64,
    /// Rear principal plane H', from V2, positive in the direction of travel.
    pub h2: f64,
    pub n: f64,
}

impl ThickLens {
    /// Whether the lens bends light at all (false at `n = 1`).
    pub fn has_power(&self) -> bool {
        self.efl.is_finite()
    }

    /// `d` diameter, `r1`, `r2` radius magnitudes, `n` index.
    pub fn new(d: f64, r1: f64, r2: f64, n: f64) -> Self {
        let h = 0.5 * d;
        let sag1 = sagitta(r1, h);
        let sag2 = sagitta(r2, h);
        let t = sag1 + sag2;
        let (r1s, r2s) = (r1, -r2);
        let power = (n - 1.0) * (1.0 / r1s - 1.0 / r2s + (n - 1.0) * t / (n * r1s * r2s));
        if !(power > 0.0) {
            // n = 1 (the only zero: t < r1 + r2 makes the bracket positive).
            return ThickLens {
                thickness: t,
                sag1,
                sag2,
                efl: f64::INFINITY,
                bfd: f64::INFINITY,
                ffd: f64::INFINITY,
                h1: f64::NAN,
                h2: f64::NAN,
                n,
            };
        }
        let efl = 1.0 / power;
        let h1 = -efl * (n - 1.0) * t / (n * r2s);
        let h2 = -efl * (n - 1.0) * t / (n * r1s);
        ThickLens {
            thickness: t,
            sag1,
            sag2,
            efl,
            bfd: efl + h2,
            ffd: efl - h1,
            h1,
            h2,
            n,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn snell_law_holds() {
        let n = DVec3::Z;
        for deg in [0.0f64, 10.0, 30.0, 60.0, 80.0, 89.9] {
            let th = deg.to_radians();
            let i = DVec3::new(th.sin(), 0.0, -th.cos());
            let t = refract(i, n, 1.0, 1.5).unwrap();
            assert_relative_eq!(t.length(), 1.0, epsilon = 1e-15);
            // n1 sin θi = n2 sin θt, and the ray stays in the plane of incidence.
            assert_relative_eq!(th.sin(), 1.5 * t.x, epsilon = 1e-15);
            assert!(t.y.abs() < 1e-16 && t.z < 0.0);
        }
    }

    #[test]
    fn refraction_deviation_is_refract_less_the_incident_ray() {
        let nrm = DVec3::new(0.1, -0.2, 1.0).normalize();
        for deg in [0.0f64, 10.0, 30.0, 60.0, 80.0] {
            let th = deg.to_radians();
            let i = DVec3::new(th.sin(), 0.0, -th.cos());
            for (n1, n2) in [(1.0, 1.5), (1.5, 1.0), (1.0, 4.0)] {
                let Some(t) = refract(i, nrm, n1, n2) else { continue };
                let dev = refraction_deviation(i, DVec3::ZERO, nrm, n1, n2).unwrap();
                assert!((i + dev - t).length() < 4e-16, "{deg}° {n1} → {n2}");
                // The incident direction split in two gives the same turn.
                let half = 0.5 * (t - i);
                let split = refraction_deviation(i + half, -half, nrm, n1, n2).unwrap();
                assert!((split - dev).length() < 1e-15);
            }
            assert_eq!(refraction_deviation(i, DVec3::ZERO, nrm, 1.0, 1.0), Some(DVec3::ZERO));
        }
        let past = 60f64.to_radians();
        let i = DVec3::new(past.sin(), 0.0, -past.cos());
        assert_eq!(refraction_deviation(i, DVec3::ZERO, DVec3::Z, 1.5, 1.0), None);
    }

    #[test]
    fn total_internal_reflection_beyond_critical_angle() {
        let crit = (1.0f64 / 1.5).asin();
        let n = DVec3::Z;
        let below = crit - 1e-6;
        let above = crit + 1e-6;
        assert!(refract(DVec3::new(below.sin(), 0.0, -below.cos()), n, 1.5, 1.0).is_some());
        assert!(refract(DVec3::new(above.sin(), 0.0, -above.cos()), n, 1.5, 1.0).is_none());
        assert_eq!(fresnel_dielectric(above.cos(), 1.5, 1.0), 1.0);
    }

    #[test]
    fn fresnel_matches_the_two_ratio_form() {
        // Hecht's rs and rp, each its own ratio, at angles from normal to
        // grazing, into and out of glass (below the critical angle).
        for (n1, n2) in [(1.0, 1.5), (1.5, 1.0), (1.0, 2.4), (1.33, 1.0)] {
            for k in 0..=1000 {
                let cos_i = k as f64 / 1000.0;
                let sin2_t = (n1 / n2) * (n1 / n2) * (1.0 - cos_i * cos_i);
                if sin2_t >= 1.0 {
                    continue;
                }
                let cos_t = (1.0f64 - sin2_t).sqrt();
                let rs = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t);
                let rp = (n1 * cos_t - n2 * cos_i) / (n1 * cos_t + n2 * cos_i);
                let want = 0.5 * (rs * rs + rp * rp);
                let got = fresnel_dielectric(cos_i, n1, n2);
                assert!(
                    (got - want).abs() <= 4.0 * f64::EPSILON * want,
                    "{n1} → {n2}, cos {cos_i}: {got} vs {want}"
                );
            }
        }
    }

    /// `fresnel_at` (cosines from the directions, as `refract` computes
    /// them) agrees with `fresnel_dielectric` (from `cos θi` alone) to a few
    /// ulp of the reflectance wherever the light gets through, and is 1
    /// beyond the critical angle.
    #[test]
    fn fresnel_at_agrees_with_fresnel_dielectric() {
        for (n1, n2) in [(1.0, 1.5), (1.5, 1.0), (1.0, 2.4), (1.33, 1.0)] {
            for k in 0..=2000 {
                let th = std::f64::consts::FRAC_PI_2 * k as f64 / 2000.0;
                let i = DVec3::new(th.sin(), 0.0, -th.cos());
                let cos_i = -i.dot(DVec3::Z);
                let want = fresnel_dielectric(cos_i, n1, n2);
                let got = fresnel_at(i, DVec3::Z, n1, n2);
                if want == 1.0 {
                    assert!(
                        got == 1.0 || (n1 / n2 * th.sin() - 1.0).abs() < 1e-12,
                        "{n1} → {n2} at {th}: {got}"
                    );
                } else {
                    // Near grazing and near the critical angle the reflectance
                    // is ill-conditioned in cos θt: an error of ε in sin² θt
                    // moves it by about ε / cos θt.
                    let sin2_t = (n1 / n2 * th.sin()).powi(2);
                    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
                    let tol = if k < 2000 {
                        64.0 * f64::EPSILON / cos_t.max(1e-6)
                    } else {
                        1e-7
                    };
                    assert!(
                        (got - want).abs() <= tol * want.max(1e-3),
                        "{n1} → {n2} at {th}: {got} vs {want}"
                    );
                }
            }
        }
        // 0.04 straight on, 1 past the critical angle of glass into air.
        assert_relative_eq!(fresnel_at(-DVec3::Z, DVec3::Z, 1.0, 1.5), 0.04, epsilon = 1e-15);
        let crit = (1.0f64 / 1.5).asin() + 1e-6;
        assert_eq!(
            fresnel_at(DVec3::new(crit.sin(), 0.0, -crit.cos()), DVec3::Z, 1.5, 1.0),
            1.0
        );
    }

    #[test]
    fn fresnel_at_normal_incidence() {
        // ((n−1)/(n+1))² = 0.04 for n = 1.5.
        assert_relative_eq!(fresnel_dielectric(1.0, 1.0, 1.5), 0.04, epsilon = 1e-15);
        assert_relative_eq!(fresnel_dielectric(1.0, 1.5, 1.0), 0.04, epsilon = 1e-15);
        assert_relative_eq!(fresnel_dielectric(0.0, 1.0, 1.5), 1.0, epsilon = 1e-12);
    }

    #[test]
    fn reflection_preserves_angle() {
        let i = DVec3::new(1.0, -1.0, 0.0).normalize();
        let r = reflect(i, DVec3::Y);
        assert_relative_eq!(r.x, i.x);
        assert_relative_eq!(r.y, -i.y);
    }

    #[test]
    fn sagitta_is_stable() {
        // Flat limit: sag → h²/(2r).
        let s = sagitta(1e7, 1.0);
        assert_relative_eq!(s, 1.0 / 2e7, max_relative = 1e-12);
        assert_eq!(sagitta(1.0, 1.0), 1.0);
        assert_eq!(centre_offset(1.0, 1.0), 0.0);
    }

    #[test]
    fn thin_lens_limit_and_symmetry() {
        // Biconvex symmetric, very large radii: thin-lens f = R/(2(n−1)).
        let l = ThickLens::new(1.0, 1e6, 1e6, 1.5);
        assert_relative_eq!(l.efl, 1e6, max_relative = 1e-9);
        // Symmetric lens: BFD = FFD, H and H' symmetric.
        let l = ThickLens::new(2.0, 5.0, 5.0, 1.5);
        assert_relative_eq!(l.bfd, l.ffd, max_relative = 1e-14);
        assert_relative_eq!(l.h1, -l.h2, max_relative = 1e-14);
        // Ball lens (two hemispheres): EFL = nD/(4(n−1)) from the centre.
        let ball = ThickLens::new(2.0, 1.0, 1.0, 1.5);
        assert_relative_eq!(ball.thickness, 2.0, max_relative = 1e-15);
        assert_relative_eq!(ball.efl, 1.5 * 2.0 / (4.0 * 0.5), max_relative = 1e-14);
        assert_relative_eq!(ball.bfd, ball.efl - 1.0, max_relative = 1e-14);
    }

    #[test]
    fn cauchy_index() {
        let idx = Index::Cauchy { a: 1.5, b: 0.004 };
        assert_relative_eq!(idx.at(0.5), 1.516, epsilon = 1e-15);
        assert!(idx.is_dispersive() && !Index::Constant(1.5).is_dispersive());
    }

    #[test]
    fn glass_index() {
        let g = crate::glass::lookup("N-BK7").unwrap();
        let idx = Index::Glass(g);
        assert_eq!(idx.at(0.5), g.n(0.5));
        assert!((idx.nominal() - 1.5168).abs() < 2e-5);
        assert!(idx.is_dispersive() && idx == Index::Glass(g));
    }
}
