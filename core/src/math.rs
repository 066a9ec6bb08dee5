//! Rays and small numerical helpers on `glam`'s double-precision types.
//!
//! Everything in the tracer is `f64`: the lens must be exact to 1e-9 of its
//! diameter even when it is tiny and far from the origin, and `f32` cannot
//! hold that. There is no vector type of our own; `DVec3` is the vector.

use glam::{DMat3, DVec3};

/// A ray `origin + t·dir`. `dir` is kept unit length by every constructor in
/// the crate, so `t` is a distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: DVec3,
    pub dir: DVec3,
}

impl Ray {
    /// A ray with a normalised direction.
    pub fn new(origin: DVec3, dir: DVec3) -> Self {
        Ray {
            origin,
            dir: dir.normalize(),
        }
    }

    pub fn at(&self, t: f64) -> DVec3 {
        self.origin + self.dir * t
    }
}

/// The supported domain of a scene and of a lens (README, "Scene file
/// format"): inside it the exact-lens arithmetic and the shading give
/// correct answers; the validators refuse anything outside.
///
/// - Coordinates `|x| ≤ 1e9`: squares stay ≤ 1e18 and products of two
///   squares ≤ 1e36, far from overflow, and points are spaced ≤ 2.2e-7.
/// - Lengths (sizes, radii, lens diameter and face radii) in `[1e-9, 1e9]`,
///   and at least 1e-7 of the object's distance from the origin: there
///   points are spaced ≤ 2.2e-9 of the size and a spawned ray is pushed off
///   by ≤ 2.3e-3 of it ([`surface_offset`]); a lens face of radius up to 1e9
///   is a plano-like face that the vertex form solves without overflow.
/// - Index of refraction in `[1, 10]` (real glass stays below 4.1).
/// - Colour components ≤ 1e3, intensities ≤ 1e12, material coefficients
///   ≤ 1e3: light times the coefficients and 65 bounces of colour stay below
///   1e230, so no product reaches ∞ (and no ∞·0 makes a NaN).
pub mod domain {
    pub const MAX_COORDINATE: f64 = 1e9;
    pub const MIN_LENGTH: f64 = 1e-9;
    pub const MAX_LENGTH: f64 = 1e9;
    /// A length must be at least this fraction of its object's distance
    /// (largest coordinate) from the origin.
    pub const MIN_LENGTH_PER_DISTANCE: f64 = 1e-7;
    pub const MAX_INDEX: f64 = 10.0;
    pub const MAX_COLOUR: f64 = 1e3;
    pub const MAX_INTENSITY: f64 = 1e12;
    pub const MAX_COEFFICIENT: f64 = 1e3;

    /// Why a coordinate is outside the domain (`None` inside).
    pub fn coordinate(x: f64) -> Option<String> {
        (!(x.abs() <= MAX_COORDINATE)).then(|| format!("{x:e} is outside the supported range ±{MAX_COORDINATE:e}"))
    }

    /// Why a length is outside the domain for an object whose largest
    /// coordinate is `distance` (`None` inside).
    pub fn length(x: f64, distance: f64) -> Option<String> {
        let least = MIN_LENGTH.max(MIN_LENGTH_PER_DISTANCE * distance);
        if !(MIN_LENGTH..=MAX_LENGTH).contains(&x) {
            Some(format!(
                "{x:e} is outside the supported lengths [{MIN_LENGTH:e}, {MAX_LENGTH:e}]"
            ))
        } else if !(x >= least) {
            Some(format!(
                "{x:e} is smaller than {MIN_LENGTH_PER_DISTANCE:e} of the distance {distance:e} from the origin \
                 (below {least:e} the spacing of coordinates there is too coarse)"
            ))
        } else {
            None
        }
    }

    /// Why an index of refraction is outside the domain (`None` inside).
    pub fn index(n: f64) -> Option<String> {
        (!(1.0..=MAX_INDEX).contains(&n))
            .then(|| format!("index {n:e} is outside the supported range [1, {MAX_INDEX}]"))
    }
}

/// Multiplies `v` by a power of two (exactly) so that its largest
/// component lies in [1, 2): a direction that squares to ∞ or to 0 becomes
/// one that normalises, and the line it names is the same.
pub fn rescale_pow2(v: DVec3) -> DVec3 {
    let m = max_abs(v);
    if !(m > 0.0 && m.is_finite()) {
        return v;
    }
    let e = m.log2().floor() as i32;
    // In two steps: 2^−e alone may not be a finite f64.
    let half = e / 2;
    v * 2f64.powi(-half) * 2f64.powi(half - e)
}

/// The two real roots of `t² + 2·b·t + c = 0` in ascending order, computed
/// without catastrophic cancellation (Numerical Recipes §5.6): the root of
/// larger magnitude is `q = −(b + sign(b)·√(b²−c))`, the other is `c / q`.
/// Returns `None` when the discriminant is negative.
pub fn solve_half_b_quadratic(b: f64, c: f64) -> Option<(f64, f64)> {
    solve_with_discriminant(b, c, half_b_discriminant(b, c))
}

/// Same as [`solve_half_b_quadratic`] with a discriminant `b² − c` that the
/// caller computed in a more accurate way (see the sphere intersection).
pub fn solve_with_discriminant(b: f64, c: f64, disc: f64) -> Option<(f64, f64)> {
    if !(disc >= 0.0) {
        return None;
    }
    Some(half_b_roots(b, c, disc))
}

/// The discriminant `b² − c` of `t² + 2·b·t + c = 0`: real roots when it
/// is at least 0.
#[inline(always)]
pub fn half_b_discriminant(b: f64, c: f64) -> f64 {
    b * b - c
}

/// [`solve_half_b_quadratic`]'s roots `(smaller, larger)` from the
/// discriminant `disc` (not numbers when it is negative), written without
/// branches, so that SIMD lanes can run it side by side and a scalar
/// caller gets the same bits.
#[inline(always)]
pub fn half_b_roots(b: f64, c: f64, disc: f64) -> (f64, f64) {
    let s = disc.sqrt();
    let q = if b >= 0.0 { -(b + s) } else { -(b - s) };
    let r2 = c / q;
    let pair = if q <= r2 { (q, r2) } else { (r2, q) };
    // b = 0 and c = 0: a double root at zero (and not 0/0).
    if q == 0.0 { (0.0, 0.0) } else { pair }
}

/// The unit vector along `v`, for a `v` already of unit length up to
/// rounding (`|1 − |v|²| ≤ 2⁻²⁰`): a refraction or reflection of unit
/// vectors, a rotated unit normal. `normalize` takes a square root and a
/// division, which share one unit that is not pipelined (on Zen 4 a
/// 64-byte register's take 16 and 9 cycles, against 2 for a product).
/// Here `1/√(1 + ε)` is its series `1 − ε/2 + 3ε²/8`, with `ε = |v|² − 1`
/// exact (Sterbenz): the series' error `5|ε|³/16` is at most 2.8·10⁻¹⁹,
/// below a unit in the last place of 1, so the result is as near the unit
/// vector along `v` as `normalize`'s (a test holds it to that, against
/// the length in double-double arithmetic), though not always its bits.
/// In the lens pass (six a lane) it made rim-lens.toml's frame 4 %
/// faster (docs/performance.md, round 20).
#[inline(always)]
pub fn renormalize(v: DVec3) -> DVec3 {
    let eps = v.length_squared() - 1.0;
    // Not a number passes: lanes whose numbers are not used hold them.
    debug_assert!(!(eps.abs() > RENORMALIZE_MAX), "{v} is not unit length up to rounding");
    v * (1.0 + eps * (0.375 * eps - 0.5))
}

/// The largest `||v|² − 1|` [`renormalize`] takes.
pub const RENORMALIZE_MAX: f64 = 1.0 / (1u64 << 20) as f64;

/// Rotation matrix from angles in degrees about x, y and z, applied in the
/// order z (roll) then x (pitch) then y (yaw): `R = Ry · Rx · Rz`. This is the
/// convention of a fly camera: yaw turns about the world's up axis.
pub fn rotation_from_degrees(deg: DVec3) -> DMat3 {
    let r = deg * (std::f64::consts::PI / 180.0);
    // glam's `from_rotation_y`, `_x` and `_z`, from `libm`'s sine and
    // cosine (glam's call the platform's, whose last bit differs between
    // a native build and the browser's: ARCHITECTURE.md, "Determinism").
    let ((sy, cy), (sx, cx), (sz, cz)) = (libm::sincos(r.y), libm::sincos(r.x), libm::sincos(r.z));
    let y = DMat3::from_cols(DVec3::new(cy, 0.0, -sy), DVec3::Y, DVec3::new(sy, 0.0, cy));
    let x = DMat3::from_cols(DVec3::X, DVec3::new(0.0, cx, sx), DVec3::new(0.0, -sx, cx));
    let z = DMat3::from_cols(DVec3::new(cz, sz, 0.0), DVec3::new(-sz, cz, 0.0), DVec3::Z);
    y * x * z
}

/// Angles (degrees, the convention of [`rotation_from_degrees`], no roll) that
/// turn the default view direction −z toward `dir`.
pub fn angles_looking_along(dir: DVec3) -> DVec3 {
    let d = dir.normalize();
    let pitch = libm::asin(d.y.clamp(-1.0, 1.0));
    let yaw = libm::atan2(-d.x, -d.z);
    DVec3::new(pitch.to_degrees(), yaw.to_degrees(), 0.0)
}

/// Largest absolute coordinate: the scale of rounding errors at `p`.
pub fn max_abs(p: DVec3) -> f64 {
    p.abs().max_element()
}

/// The distance by which a spawned ray's origin is pushed off a surface:
/// a fixed multiple of the rounding error of coordinates of size `max_abs(p)`
/// (2⁻³² relative), with a floor for points near the origin.
pub fn surface_offset(p: DVec3, shape_scale: f64) -> f64 {
    (max_abs(p) + shape_scale) * (1.0 / 4_294_967_296.0)
}

/// Builds an orthonormal basis `(u, v)` perpendicular to the unit vector `n`
/// (Duff et al., "Building an Orthonormal Basis, Revisited", JCGT 2017).
pub fn orthonormal_basis(n: DVec3) -> (DVec3, DVec3) {
    let sign = 1.0f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        DVec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

/// `(sin t, cos t)` for `|t| ≤ π/4`, from the polynomials of FreeBSD's
/// `k_sin.c` and `k_cos.c` (what musl and Rust's `libm` evaluate there,
/// within one unit in the last place of the true values; the same
/// doubles, written as their shortest decimals), with `+`, `−` and `×`
/// alone: `libm`'s `sin` and `cos` bit for bit over the quarter turn.
/// The platform's `sin` and `cos` are not the same function everywhere:
/// glibc's (native builds) and `libm`'s (wasm32) gave other last bits for
/// 3.1 % of angles (10⁷ uniform in [−π, π), glibc 2.36 against `libm`
/// 0.2.16: `examples/libm_differ`), so a photon emitted through them left
/// in another direction in the browser.
/// IEEE arithmetic without fused operations (Rust never contracts) gives
/// these the same bits on every platform, without a call
/// (`sampling::concentric_disc`, one per photon).
#[inline]
pub fn sin_cos_quarter(t: f64) -> (f64, f64) {
    debug_assert!(t.abs() <= std::f64::consts::FRAC_PI_4 * (1.0 + 1e-15), "{t}");
    const S: [f64; 6] = [
        -0.16666666666666632,
        0.00833333333332249,
        -0.0001984126982985795,
        2.7557313707070068e-06,
        -2.5050760253406863e-08,
        1.58969099521155e-10,
    ];
    const C: [f64; 6] = [
        0.0416666666666666,
        -0.001388888888887411,
        2.480158728947673e-05,
        -2.7557314351390663e-07,
        2.087572321298175e-09,
        -1.1359647557788195e-11,
    ];
    let z = t * t;
    let w = z * z;
    let r = S[1] + z * (S[2] + z * S[3]) + z * w * (S[4] + z * S[5]);
    let sin = t + z * t * (S[0] + z * r);
    let r = z * (C[0] + z * (C[1] + z * C[2])) + w * w * (C[3] + z * (C[4] + z * C[5]));
    let hz = 0.5 * z;
    let one_less = 1.0 - hz;
    let cos = one_less + (((1.0 - one_less) - hz) + z * r);
    (sin, cos)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quadratic_roots_are_accurate_when_b_dominates() {
        // t² + 2·1e8·t + 1 = 0: the small root is −5e-9 to full precision.
        let (a, b) = solve_half_b_quadratic(1e8, 1.0).unwrap();
        assert!((b - (-5e-9)).abs() / 5e-9 < 1e-15, "{b}");
        assert!((a + 2e8).abs() / 2e8 < 1e-15);
        // The naive formula loses the small root completely.
        let naive = -1e8 + (1e16f64 - 1.0).sqrt();
        assert!((naive - (-5e-9)).abs() / 5e-9 > 0.1);
    }

    #[test]
    fn quadratic_without_real_roots() {
        assert!(solve_half_b_quadratic(0.0, 1.0).is_none());
        assert_eq!(solve_half_b_quadratic(0.0, 0.0), Some((0.0, 0.0)));
    }

    #[test]
    fn look_angles_round_trip() {
        for dir in [
            DVec3::new(0.0, -5.5, -10.0),
            DVec3::new(1.0, 0.3, 0.2),
            DVec3::new(-0.2, 0.1, 1.0),
        ] {
            let m = rotation_from_degrees(angles_looking_along(dir));
            let got = m * DVec3::NEG_Z;
            assert!((got - dir.normalize()).length() < 1e-12, "{got} {dir}");
        }
    }

    #[test]
    fn basis_is_orthonormal() {
        for n in [DVec3::X, DVec3::NEG_Z, DVec3::new(0.3, -0.4, 0.5).normalize()] {
            let (u, v) = orthonormal_basis(n);
            assert!(u.dot(v).abs() < 1e-15 && u.dot(n).abs() < 1e-15 && v.dot(n).abs() < 1e-15);
            assert!((u.length() - 1.0).abs() < 1e-15 && (v.length() - 1.0).abs() < 1e-15);
        }
    }

    /// `|w|² − 1` in double-double arithmetic (products split exactly by
    /// `mul_add`): the length's error without the rounding of measuring it.
    fn unit_error(w: DVec3) -> f64 {
        let (mut hi, mut lo) = (-1.0f64, 0.0f64);
        for c in w.to_array() {
            let p = c * c;
            let e = c.mul_add(c, -p);
            let s = hi + p;
            let z = s - hi;
            lo += (hi - (s - z)) + (p - z) + e;
            hi = s;
        }
        hi + lo
    }

    /// [`renormalize`] gives vectors as near unit length as `normalize`
    /// does, along the same line, from vectors of unit length up to a few
    /// roundings and up to [`RENORMALIZE_MAX`], in every direction.
    #[test]
    fn renormalized_vectors_are_unit_to_the_last_place() {
        let mut s = crate::sampling::Sampler::new(7, 0, 0);
        let ulp = f64::EPSILON;
        let (mut worst_new, mut worst_old) = (0.0f64, 0.0f64);
        for i in 0..200_000 {
            let u = DVec3::new(s.next_f64(), s.next_f64(), s.next_f64()) * 2.0 - 1.0;
            let Some(u) = u.try_normalize() else { continue };
            // Off unit length by a few roundings, or (one in four) by up
            // to the most `renormalize` takes.
            let off = if i % 4 == 0 { RENORMALIZE_MAX } else { 8.0 * ulp };
            let v = u * (1.0 + off * (2.0 * s.next_f64() - 1.0) / 2.0);
            let (new, old) = (renormalize(v), v.normalize());
            worst_new = worst_new.max(unit_error(new).abs());
            worst_old = worst_old.max(unit_error(old).abs());
            // Along `v`: the same line to the last place.
            assert!(new.cross(v).length() <= 2.0 * ulp * v.length(), "{v}: {new}");
            assert!((new - old).abs().max_element() <= 2.0 * ulp, "{v}: {new} against {old}");
        }
        assert!(worst_new <= 2.5 * ulp, "renormalize: |w|² − 1 up to {worst_new:e}");
        assert!(
            worst_new <= 1.5 * worst_old,
            "{worst_new:e} against normalize's {worst_old:e}"
        );
    }
    /// [`sin_cos_quarter`] is `libm`'s `sin` and `cos` bit for bit over
    /// the quarter turn (the functions wasm32's std links), within one unit
    /// in the last place of the platform's (glibc's here), exact at 0, odd
    /// and even, and keeps `sin² + cos² = 1` to rounding.
    #[test]
    fn quarter_sine_and_cosine_match_the_platform() {
        let ulp = |a: f64, b: f64| (a.to_bits() as i64 - b.to_bits() as i64).unsigned_abs();
        let quarter = std::f64::consts::FRAC_PI_4;
        let mut rng = crate::sampling::Sampler::new(11, 0, 0);
        let (mut worst, mut differ) = (0, 0);
        for i in 0..200_000 {
            let u = rng.next_f64();
            // Uniform over the quarter turn, and a few near 0 and its ends.
            let t = match i % 4 {
                0 => (2.0 * u - 1.0) * 1e-6,
                1 => quarter * (1.0 - 1e-3 * u),
                _ => (2.0 * u - 1.0) * quarter,
            };
            let (s, c) = sin_cos_quarter(t);
            assert_eq!(
                (s.to_bits(), c.to_bits()),
                (libm::sin(t).to_bits(), libm::cos(t).to_bits()),
                "{t}"
            );
            for (got, want) in [(s, t.sin()), (c, t.cos())] {
                let d = ulp(got, want);
                worst = worst.max(d);
                differ += usize::from(d != 0);
            }
            assert_eq!(sin_cos_quarter(-t), (-s, c), "odd sine, even cosine at {t}");
            assert!((s * s + c * c - 1.0).abs() <= 4.0 * f64::EPSILON, "{t}");
        }
        assert!(worst <= 1, "{worst} units in the last place");
        assert!(differ < 20_000, "{differ} of 400 000 differ by one unit");
        assert_eq!(sin_cos_quarter(0.0), (0.0, 1.0));
        assert_eq!(sin_cos_quarter(quarter).0, libm::sin(quarter));
    }

    /// The camera's rotation from `libm`'s sines is glam's from the
    /// platform's to rounding, and a rotation.
    #[test]
    fn the_rotation_is_glams() {
        for deg in [
            DVec3::ZERO,
            DVec3::new(-12.5, 33.0, 4.0),
            DVec3::new(89.0, -170.0, -30.0),
        ] {
            let r = deg * (std::f64::consts::PI / 180.0);
            let glam = DMat3::from_rotation_y(r.y) * DMat3::from_rotation_x(r.x) * DMat3::from_rotation_z(r.z);
            let ours = rotation_from_degrees(deg);
            assert!(ours.abs_diff_eq(glam, 1e-15), "{deg}: {ours} against {glam}");
            assert!((ours * ours.transpose()).abs_diff_eq(DMat3::IDENTITY, 1e-15), "{deg}");
        }
    }
}
