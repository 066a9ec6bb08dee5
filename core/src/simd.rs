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

/// The instruction sets a lane function is built for; [`isa`] picks one
/// at run time. Every build performs the same `f64` operations in the same
/// order (no FMA is enabled in any, and Rust never contracts a multiply
/// and an add), so all give the same bits (`tests/isa.rs`); they differ in
/// how many lanes one instruction carries: two (SSE2), four (AVX2) or all
/// eight (AVX-512, one `zmm` register a lane array).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Isa {
    Portable = 1,
    Avx2 = 2,
    Avx512 = 3,
}

impl Isa {
    pub fn name(self) -> &'static str {
        match self {
            Isa::Portable => "SSE2",
            Isa::Avx2 => "AVX2",
            Isa::Avx512 => "AVX-512",
        }
    }

    /// The best build this CPU runs.
    pub fn detected() -> Isa {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::is_x86_feature_detected as has;
            if has!("avx512f") && has!("avx512vl") && has!("avx512dq") && has!("avx512bw") && has!("avx2") {
                return Isa::Avx512;
            }
            if has!("avx2") {
                return Isa::Avx2;
            }
        }
        Isa::Portable
    }

    /// An ISA by name (`sse2`/`portable`, `avx2`, `avx512`), if this CPU
    /// runs it.
    pub fn parse(name: &str) -> Option<Isa> {
        let isa = match name.to_ascii_lowercase().as_str() {
            "sse2" | "portable" => Isa::Portable,
            "avx2" => Isa::Avx2,
            "avx512" | "avx-512" => Isa::Avx512,
            _ => return None,
        };
        (isa as u8 <= Isa::detected() as u8).then_some(isa)
    }
}

/// The build forced by [`force_isa`] or `LENSVIEW_ISA` (0: none yet read).
static CHOSEN: std::sync::atomic::AtomicU8 = std::sync::atomic::AtomicU8::new(0);

/// The build the lane functions run: the best this CPU has, unless
/// `LENSVIEW_ISA` (`sse2`, `avx2`, `avx512`; one this CPU runs) or
/// [`force_isa`] asked for a lesser one (to compare them).
///
/// Inlined into every dispatcher (one load and a compare before the jump
/// to the build), the first call's look-up out of line.
#[inline(always)]
pub fn isa() -> Isa {
    use std::sync::atomic::Ordering;
    match CHOSEN.load(Ordering::Relaxed) {
        1 => Isa::Portable,
        2 => Isa::Avx2,
        3 => Isa::Avx512,
        _ => choose_isa(),
    }
}

/// [`isa`]'s first call: reads `LENSVIEW_ISA` and keeps the choice.
#[cold]
#[inline(never)]
fn choose_isa() -> Isa {
    let isa = std::env::var("LENSVIEW_ISA")
        .ok()
        .and_then(|v| Isa::parse(&v))
        .unwrap_or_else(Isa::detected);
    CHOSEN.store(isa as u8, std::sync::atomic::Ordering::Relaxed);
    isa
}

/// Runs the lane functions on `isa` from now on (`None`: the best this CPU
/// has); an ISA this CPU lacks is refused (false).
pub fn force_isa(isa: Option<Isa>) -> bool {
    let isa = isa.unwrap_or_else(Isa::detected);
    if isa as u8 > Isa::detected() as u8 {
        return false;
    }
    CHOSEN.store(isa as u8, std::sync::atomic::Ordering::Relaxed);
    true
}

/// Compiles each `*_impl` function again with AVX2 and with AVX-512
/// enabled, and defines the public function that picks the build [`isa`]
/// says. In the form `=> {IMPL}, avx512 => {OTHER}` the AVX-512 build
/// runs `OTHER` instead (a form of the function for eight lanes in one
/// register, same bits; either may name generic arguments).
macro_rules! with_avx2 {
    ($(#[$doc:meta])* $vis:vis fn $name:ident / $avx2:ident => $imp:ident ($($arg:ident: $ty:ty),*) -> $ret:ty) => {
        $crate::simd::with_avx2! {
            $(#[$doc])* $vis fn $name / $avx2 => {$imp}, avx512 => {$imp} ($($arg: $ty),*) -> $ret
        }
    };
    ($(#[$doc:meta])* $vis:vis fn $name:ident / $avx2:ident => {$($imp:tt)*}, avx512 => {$($imp512:tt)*} ($($arg:ident: $ty:ty),*) -> $ret:ty) => {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2")]
        fn $avx2($($arg: $ty),*) -> $ret {
            $($imp)*($($arg),*)
        }

        $(#[$doc])*
        $vis fn $name($($arg: $ty),*) -> $ret {
            #[cfg(target_arch = "x86_64")]
            {
                /// The AVX-512 build.
                #[target_feature(enable = "avx512f,avx512vl,avx512dq,avx512bw,avx2")]
                fn avx512($($arg: $ty),*) -> $ret {
                    $($imp512)*($($arg),*)
                }
                match $crate::simd::isa() {
                    // SAFETY: each build differs from the portable one only
                    // in being compiled with more instructions, and `isa`
                    // picks only a build whose instructions this CPU has
                    // (`Isa::detected`). Calling a `target_feature`
                    // function needs `unsafe` in Rust; nothing else here
                    // is unchecked.
                    $crate::simd::Isa::Avx512 => return unsafe { avx512($($arg),*) },
                    // SAFETY: as above.
                    $crate::simd::Isa::Avx2 => return unsafe { $avx2($($arg),*) },
                    $crate::simd::Isa::Portable => {}
                }
            }
            /// The portable build, out of line: the dispatcher stays a
            /// few instructions, with no stack frame of the build's size.
            #[inline(never)]
            fn portable($($arg: $ty),*) -> $ret {
                $($imp)*($($arg),*)
            }
            portable($($arg),*)
        }
    };
}

pub(crate) use with_avx2;

/// Whether this CPU runs the AVX2 builds of [`with_avx2!`] (or better).
pub fn uses_avx2() -> bool {
    isa() != Isa::Portable
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
