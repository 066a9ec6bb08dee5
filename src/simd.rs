//! Lanes for SIMD code written as plain arrays: [`LANES`] values side by
//! side ([`Lanes`]), bit masks over them ([`mask`], [`live_lanes`]), the
//! comparisons glam's vectors use ([`gmin`], [`gmax`]), and
//! `with_avx2!`, which compiles a lane function a second time for AVX2
//! and picks the build at run time.
//!
//! Lane loops here are `for l in 0..LANES` over `f64` arrays, without
//! branches or lookups by index, which LLVM turns into AVX2 instructions
//! (four `f64` to a register) in the AVX2 build and into SSE2 otherwise.
//! This module knows nothing of scenes or shapes: it sits beside `math` at
//! the bottom of the crate, so that the geometry's lane tests (the lens,
//! the cuboid) can use it as well as the packet walks of `trace`.

use glam::DVec3;

/// Rays in a packet.
pub const LANES: usize = 8;

/// One value per lane.
pub type Lanes<T> = [T; LANES];

/// glam's `DVec3::min` on one component (NaN in `a` or `b` gives `b`).
#[inline(always)]
pub fn gmin(a: f64, b: f64) -> f64 {
    if a < b { a } else { b }
}

/// glam's `DVec3::max` on one component.
#[inline(always)]
pub fn gmax(a: f64, b: f64) -> f64 {
    if a > b { a } else { b }
}

/// Lane `l` of a vector held as structure of arrays.
#[inline(always)]
pub fn lane<const N: usize>(v: &[[f64; N]; 3], l: usize) -> DVec3 {
    DVec3::new(v[0][l], v[1][l], v[2][l])
}

/// Writes `x` into lane `l` of a vector held as structure of arrays.
#[inline(always)]
pub fn set_lane<const N: usize>(v: &mut [[f64; N]; 3], l: usize, x: DVec3) {
    for k in 0..3 {
        v[k][l] = x[k];
    }
}

const _: () = assert!(LANES == 8, "`mask` packs eight lanes");

/// Bit `l` set where `b[l]`: the eight flags as bytes of one word, gathered
/// into its top byte by one multiplication (each byte's bit lands 7 places
/// apart from the next; no two products meet in the top byte).
#[inline(always)]
pub fn mask(b: &Lanes<bool>) -> u32 {
    let word = u64::from_le_bytes(b.map(u8::from));
    (word.wrapping_mul(0x0102_0408_1020_4080) >> 56) as u32
}

/// The lanes whose bit is set in `mask`, lowest first.
#[inline(always)]
pub fn live_lanes(mask: u32) -> LiveLanes {
    LiveLanes(mask)
}

/// [`live_lanes`]: the bits left to visit.
pub struct LiveLanes(u32);

impl Iterator for LiveLanes {
    type Item = usize;

    #[inline(always)]
    fn next(&mut self) -> Option<usize> {
        if self.0 == 0 {
            return None;
        }
        let l = self.0.trailing_zeros() as usize;
        self.0 &= self.0 - 1;
        Some(l)
    }
}

/// Compiles each `*_impl` function a second time with AVX2 enabled, and
/// defines the public function that picks the build at run time.
macro_rules! with_avx2 {
    ($(#[$doc:meta])* $vis:vis fn $name:ident / $avx2:ident => $imp:ident ($($arg:ident: $ty:ty),*) -> $ret:ty) => {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2")]
        fn $avx2($($arg: $ty),*) -> $ret {
            $imp($($arg),*)
        }

        $(#[$doc])*
        $vis fn $name($($arg: $ty),*) -> $ret {
            #[cfg(target_arch = "x86_64")]
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: the AVX2 build differs from the portable one only
                // in being compiled with AVX2 instructions, and the line
                // above has just checked that this CPU has them. Calling a
                // `target_feature` function needs `unsafe` in Rust; nothing
                // else here is unchecked.
                return unsafe { $avx2($($arg),*) };
            }
            $imp($($arg),*)
        }
    };
}

pub(crate) use with_avx2;

/// Whether this CPU runs the AVX2 builds of [`with_avx2!`].
pub fn uses_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mask_sets_bit_l_for_lane_l() {
        for m in 0u32..256 {
            let b: Lanes<bool> = std::array::from_fn(|l| m >> l & 1 != 0);
            assert_eq!(mask(&b), m);
        }
    }

    #[test]
    fn live_lanes_lists_the_set_bits() {
        assert_eq!(live_lanes(0).count(), 0);
        assert_eq!(live_lanes(0b1010_0101).collect::<Vec<_>>(), [0, 2, 5, 7]);
    }
}
