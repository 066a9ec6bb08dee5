//! Deterministic random numbers: every sample derives from
//! (seed, pixel, sample index) through a hash, never from a generator whose
//! state depends on which thread ran first. The same scene, camera and sample
//! count therefore give the same image on any number of threads.

/// SplitMix64's finaliser: a bijective 64-bit mix with good avalanche.
#[inline(always)]
pub fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A hash's top 53 bits as a uniform number in [0, 1).
#[inline(always)]
pub fn unit_f64(bits: u64) -> f64 {
    (bits >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// A tiny counter-based generator keyed by (seed, pixel, sample).
#[derive(Clone, Debug)]
pub struct Sampler {
    key: u64,
    counter: u64,
}

impl Sampler {
    #[inline(always)]
    pub fn new(seed: u64, pixel: u64, sample: u64) -> Self {
        let key = mix64(
            seed ^ mix64(pixel.wrapping_add(0x9e37_79b9_7f4a_7c15)) ^ mix64(sample.wrapping_mul(0xd1b5_4a32_d192_ed03)),
        );
        Sampler { key, counter: 0 }
    }

    /// A uniform number in [0, 1) with 53 random bits.
    #[inline(always)]
    pub fn next_f64(&mut self) -> f64 {
        self.counter += 1;
        unit_f64(mix64(
            self.key.wrapping_add(self.counter.wrapping_mul(0x9e37_79b9_7f4a_7c15)),
        ))
    }

    /// A 2D point in [0, 1)².
    #[inline(always)]
    pub fn next_2d(&mut self) -> (f64, f64) {
        (self.next_f64(), self.next_f64())
    }
}

/// Where in a pixel its camera samples lie.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Pattern {
    /// Sample `i ≥ 1` at an independent uniform point, hashed from
    /// (seed, pixel, `i`): the pattern before issue #21, kept for
    /// comparison and for references whose noise must be independent.
    Uniform,
    /// Sample `i ≥ 1` at point `i` of the R2 sequence (Roberts 2018, the
    /// plastic-number lattice `frac(i·α)`), shifted per pixel by a hashed
    /// Cranley–Patterson rotation: low discrepancy within a pixel, each
    /// sample still uniform over the pixel, and pixels decorrelated.
    #[default]
    R2,
}

/// The fractional part of `v ≥ 0` (below 2⁵²): `v − ⌊v⌋` to the bit.
/// `⌊v⌋` is the nearest integer (adding and taking away 2⁵², whose unit in
/// the last place is 1: both exact but the rounding to an integer), less
/// one where that rounded up: plain arithmetic that lane loops run side by
/// side in every build, where `f64::floor` is a library call without
/// SSE4.1 (5 % of a focal-spot frame, `perf`) and a cast to an integer is
/// one lane at a time.
#[inline(always)]
fn frac(v: f64) -> f64 {
    const TWO_52: f64 = 4_503_599_627_370_496.0;
    debug_assert!((0.0..TWO_52).contains(&v), "{v}");
    let nearest = (v + TWO_52) - TWO_52;
    v - (nearest - if nearest > v { 1.0 } else { 0.0 })
}

/// The R2 sequence's steps: 1/g and 1/g², g the plastic number (the real
/// root of x³ = x + 1).
const R2_ALPHA: (f64, f64) = (0.754_877_666_246_692_7, 0.569_840_290_998_053_3);

/// The position in pixel `pixel` (row-major index) of its sample `i`, in
/// [0, 1)²: sample 0 is the pixel centre whatever the pattern (so a
/// one-sample image is the same with any pattern and seed); the others
/// follow `pattern`, keyed by (seed, pixel, `i`) alone, so any thread
/// count and any order of waves give the same points.
#[inline(always)]
pub fn pixel_offset(pattern: Pattern, seed: u64, pixel: u64, i: u32) -> (f64, f64) {
    if i == 0 {
        return (0.5, 0.5);
    }
    match pattern {
        Pattern::Uniform => Sampler::new(seed, pixel, i as u64).next_2d(),
        Pattern::R2 => {
            // Sample index 0 keys the rotation: no uniform sample uses it.
            let (rx, ry) = Sampler::new(seed, pixel, 0).next_2d();
            (frac(rx + i as f64 * R2_ALPHA.0), frac(ry + i as f64 * R2_ALPHA.1))
        }
    }
}

/// The radical inverse of `i` in base `b` (Halton's sequence).
pub fn radical_inverse(mut i: u32, b: u32) -> f64 {
    let (mut f, mut out) = (1.0, 0.0);
    while i > 0 {
        f /= b as f64;
        out += f * (i % b) as f64;
        i /= b;
    }
    out
}

/// The lens camera's point of sample `i` of `pixel` on the exit pupil's
/// box, in [0, 1)²: the Halton (2, 3) point `i`, shifted (mod 1) by a
/// hash of the seed and the pixel. Stratified, so that the share of a
/// pixel's samples that pass the lens varies little; not the pixel
/// offset's R2 pattern, which it would follow in lockstep.
#[inline]
pub fn lens_point(seed: u64, pixel: u64, i: u32) -> (f64, f64) {
    let (rx, ry) = Sampler::new(seed ^ 0x6c65_6e73_6361_6d31, pixel, 0).next_2d();
    (frac(rx + radical_inverse(i, 2)), frac(ry + radical_inverse(i, 3)))
}

/// Sobol's dimension 1 of each byte of an index, by the byte's place:
/// the xor of the direction numbers of its set bits (1, 3, 5, 15, 17, …,
/// Pascal's triangle mod 2: each the last xor itself shifted right once).
/// Four loads a point, where a loop over the index's bits cost a
/// mispredicted branch for about every other bit.
const SOBOL_1: [[u32; 256]; 4] = {
    let mut dir = [0u32; 32];
    let mut v = 1u32 << 31;
    let mut b = 0;
    while b < 32 {
        dir[b] = v;
        v ^= v >> 1;
        b += 1;
    }
    let mut t = [[0u32; 256]; 4];
    let mut place = 0;
    while place < 4 {
        let mut byte = 0;
        while byte < 256 {
            let (mut y, mut bit) = (0u32, 0);
            while bit < 8 {
                if byte >> bit & 1 == 1 {
                    y ^= dir[place * 8 + bit];
                }
                bit += 1;
            }
            t[place][byte] = y;
            byte += 1;
        }
        place += 1;
    }
    t
};

/// Point `index` of the first two dimensions of Sobol's sequence, each
/// Owen-scrambled with its own key from `seed` (nested uniform
/// scrambling by hashing: Burley 2020, "Practical Hash-based Owen
/// Scrambling", whose Laine–Karras permutation this is), in [0, 1)² to
/// 32 bits. Still a (0, 2)-sequence: each run of 2^m points from a
/// multiple of 2^m has one point in each of the 2^m boxes of any shape
/// 2^-a × 2^-(m-a) on the grid, so any prefix spreads evenly, and each
/// point alone is uniform (the scrambling's keys are random), so
/// estimates over the points stay unbiased.
pub fn sobol_owen_2d(index: u32, seed: u64) -> (f64, f64) {
    let y = SOBOL_1[0][(index & 255) as usize]
        ^ SOBOL_1[1][(index >> 8 & 255) as usize]
        ^ SOBOL_1[2][(index >> 16 & 255) as usize]
        ^ SOBOL_1[3][(index >> 24) as usize];
    let key = mix64(seed ^ 0x736f_626f_6c32_6421);
    let scramble = |x: u32, k: u32| {
        let mut x = x.reverse_bits().wrapping_add(k);
        x ^= x.wrapping_mul(0x6c50_b47c);
        x ^= x.wrapping_mul(0xb82f_1e52);
        x ^= x.wrapping_mul(0xc7af_e638);
        x ^= x.wrapping_mul(0x8d22_f6e6);
        x.reverse_bits()
    };
    const UNIT: f64 = 1.0 / 4_294_967_296.0;
    (
        scramble(index.reverse_bits(), key as u32) as f64 * UNIT,
        scramble(y, (key >> 32) as u32) as f64 * UNIT,
    )
}

/// The point of the unit disc that `u` in [0, 1)² maps to by Shirley and
/// Chiu's concentric map: area for area, and squares to nearly square
/// patches (a polar map stretches them into slivers at the centre), so
/// that evenly spread points stay evenly spread on the disc. As
/// `(r, (cos φ, sin φ))`, the point `r·(cos φ, sin φ)` with `r` in
/// [−1, 1] (negative on half the square: the angle is then φ + π), so that
/// a caller needs neither the radius's square root nor a division by it.
pub fn concentric_disc((u1, u2): (f64, f64)) -> (f64, (f64, f64)) {
    use crate::math::sin_cos_quarter;
    use std::f64::consts::FRAC_PI_4;
    let (a, b) = (2.0 * u1 - 1.0, 2.0 * u2 - 1.0);
    if a == 0.0 && b == 0.0 {
        return (0.0, (1.0, 0.0));
    }
    // φ = π/4·(b/a), or π/2 − π/4·(a/b), whose cosine and sine are the
    // sine and cosine of π/4·(a/b): a quarter turn at most either way
    // (`math::sin_cos_quarter`, the same bits on every platform).
    if a * a > b * b {
        let (sin, cos) = sin_cos_quarter(FRAC_PI_4 * (b / a));
        (a, (cos, sin))
    } else {
        (b, sin_cos_quarter(FRAC_PI_4 * (a / b)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `frac` is `v − ⌊v⌋` to the bit: integers, halves (the rounding's
    /// ties), the numbers next to them and random ones up to 2⁵².
    #[test]
    fn frac_is_v_less_its_floor_to_the_bit() {
        let mut s = Sampler::new(3, 1, 4);
        let mut values = vec![
            0.0,
            0.5,
            1.0,
            1.5,
            2.5,
            4_503_599_627_370_495.5,
            4_503_599_627_370_495.0,
        ];
        for k in 0..2000 {
            let base = [k as f64, k as f64 + 0.5, (k as f64) * 1e9, (1u64 << (k % 52)) as f64];
            for b in base {
                values.extend([b, b.next_up(), b.next_down().max(0.0)]);
            }
            values.push(s.next_f64() * (1u64 << (k % 53)) as f64);
        }
        for v in values.into_iter().filter(|v| *v < 4_503_599_627_370_496.0) {
            assert_eq!(frac(v).to_bits(), (v - v.floor()).to_bits(), "{v}");
        }
    }

    /// The R2 points of a pixel fill it more evenly than uniform points:
    /// 15 samples (after the centre) leave fewer than half as many cells of
    /// a 4×4 grid empty as uniform points leave (about 6 a pixel).
    /// Both start at the centre and stay in [0, 1)².
    #[test]
    fn r2_points_spread_over_the_pixel() {
        let empty_cells = |pattern, pixel| {
            let mut cells = [false; 16];
            for i in 1..16 {
                let (x, y) = pixel_offset(pattern, 3, pixel, i);
                assert!((0.0..1.0).contains(&x) && (0.0..1.0).contains(&y));
                cells[(x * 4.0) as usize * 4 + (y * 4.0) as usize] = true;
            }
            cells.iter().filter(|c| !**c).count()
        };
        let (mut r2, mut uniform) = (0, 0);
        for pixel in 0..200 {
            r2 += empty_cells(Pattern::R2, pixel);
            uniform += empty_cells(Pattern::Uniform, pixel);
            for p in [Pattern::R2, Pattern::Uniform] {
                assert_eq!(pixel_offset(p, 3, pixel, 0), (0.5, 0.5));
            }
        }
        assert!(
            uniform > 2 * r2 && uniform > 1000,
            "R2 {r2} empty cells, uniform {uniform}"
        );
        // Pixels get different points (the rotation is per pixel and seed).
        assert_ne!(pixel_offset(Pattern::R2, 3, 1, 1), pixel_offset(Pattern::R2, 3, 2, 1));
        assert_ne!(pixel_offset(Pattern::R2, 3, 1, 1), pixel_offset(Pattern::R2, 4, 1, 1));
    }

    #[test]
    fn same_key_same_numbers() {
        let mut a = Sampler::new(1, 2, 3);
        let mut b = Sampler::new(1, 2, 3);
        for _ in 0..10 {
            assert_eq!(a.next_f64().to_bits(), b.next_f64().to_bits());
        }
        let mut c = Sampler::new(1, 2, 4);
        assert_ne!(Sampler::new(1, 2, 3).next_f64(), c.next_f64());
    }

    #[test]
    fn roughly_uniform() {
        let mut s = Sampler::new(7, 0, 0);
        let n = 100_000;
        let mut bins = [0u32; 10];
        let mut sum = 0.0;
        for _ in 0..n {
            let x = s.next_f64();
            assert!((0.0..1.0).contains(&x));
            sum += x;
            bins[(x * 10.0) as usize] += 1;
        }
        assert!((sum / n as f64 - 0.5).abs() < 0.01);
        for b in bins {
            assert!((b as f64 - 10_000.0).abs() < 500.0, "{bins:?}");
        }
    }

    /// Scrambled Sobol points keep the (0, 2)-sequence's property: every
    /// aligned run of 2^m points (m up to 10, from several places in the
    /// sequence, several keys) has one point in each 2^-a × 2^-(m-a) box;
    /// and over many keys a point is uniform (its mean and its share in
    /// a quadrant).
    #[test]
    fn scrambled_sobol_points_are_a_0_2_sequence() {
        for seed in [0u64, 7, 123_456_789] {
            for m in 0..=10u32 {
                for start in [0u32, 1 << 12, 5 << 20] {
                    let pts: Vec<(f64, f64)> = (0..1u32 << m).map(|i| sobol_owen_2d(start + i, seed)).collect();
                    for a in 0..=m {
                        let mut seen = vec![false; 1 << m];
                        for &(x, y) in &pts {
                            assert!((0.0..1.0).contains(&x) && (0.0..1.0).contains(&y));
                            let cell = ((x * (1u64 << a) as f64) as usize) << (m - a)
                                | (y * (1u64 << (m - a)) as f64) as usize;
                            assert!(!seen[cell], "seed {seed} m {m} a {a} start {start}");
                            seen[cell] = true;
                        }
                    }
                }
            }
        }
        let (mut sum, mut low) = ((0.0, 0.0), 0);
        let n = 20_000;
        for seed in 0..n {
            let (x, y) = sobol_owen_2d(3, seed);
            sum = (sum.0 + x, sum.1 + y);
            low += usize::from(x < 0.5 && y < 0.5);
        }
        assert!(
            (sum.0 / n as f64 - 0.5).abs() < 0.01 && (sum.1 / n as f64 - 0.5).abs() < 0.01,
            "{sum:?}"
        );
        assert!((low as f64 / n as f64 - 0.25).abs() < 0.015, "{low}");
    }

    /// The concentric map keeps area: a quarter of uniform points fall
    /// within radius 1/2, points stay in the disc, and the four quadrants
    /// of the square's centre region go to the disc's centre.
    #[test]
    fn the_concentric_map_keeps_area() {
        let mut s = Sampler::new(5, 0, 0);
        let n = 40_000;
        let mut inner = 0;
        for _ in 0..n {
            let (r, (c, s)) = concentric_disc(s.next_2d());
            assert!(((c * c + s * s) - 1.0).abs() < 1e-12);
            let r2 = r * r;
            assert!(r2 <= 1.0 + 1e-12);
            inner += usize::from(r2 < 0.25);
        }
        assert!((inner as f64 / n as f64 - 0.25).abs() < 0.01, "{inner}");
        assert_eq!(concentric_disc((0.5, 0.5)).0, 0.0);
        let (r, (c, s)) = concentric_disc((1.0, 0.5));
        assert!((r * c - 1.0).abs() < 1e-15 && (r * s).abs() < 1e-15);
    }
}
