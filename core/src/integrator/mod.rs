//! Whitted radiance: ambient + Lambert diffuse + Phong specular for each
//! light, hard shadows, mirror reflection and Snell refraction with total
//! internal reflection, to a maximum depth.
//!
//! Light through a lens follows the lens's own exact tracer, the full
//! Whitted tree inside ([`crate::geometry::Lens::branches_inside`]: at each
//! inner crossing the refracted and the reflected share, by Fresnel, each
//! branch pruned below [`LENS_MIN_WEIGHT`] or at `max_depth`): the same code
//! `lensview lens trace --branches` reports.
//!
//! Where things live:
//! - `mod.rs`: the entry points ([`radiance`], [`radiance_packet`] and
//!   its forms) and `with_features!`, which picks the kernel compiled for
//!   the scene's [`Features`];
//! - `surface.rs`: a hit with what shading needs ([`Surface`]), and the
//!   one place rays are spawned off a surface ([`spawn_ray`],
//!   [`shadow_ray`]);
//! - `shade.rs`: the shading both kernels share, step by step (ambient,
//!   each light, the refracted and reflected rays sent on);
//! - `scalar.rs`: the kernel for one ray;
//! - `packet.rs`: the kernel for a packet of rays, lane by lane the scalar
//!   one's arithmetic, and its working memory ([`PacketScratch`]);
//! - `lens_pass.rs`: the pass through a lens of one ray
//!   ([`transmitted_rays`]: every ray out of the lens's Whitted tree) or of
//!   a packet's lanes at once, from the same per-ray steps;
//! - `lens_send.rs`: what the lanes entering a lens together send on (the
//!   rays out at the first two exits and the reflected rays), written into
//!   the packets as lane arrays;
//! - `emission.rs`: where caustic photons start: the targets worth a
//!   photon ([`Targets`]), each light's emitter and each photon's first ray,
//!   at evenly spread points;
//! - `photons.rs`: caustic photons from the lights through the glass and
//!   off the mirrors to the diffuse surfaces ([`photon_pass`]).
//!
//! [`Features`]: crate::scene::Features

/// Calls `$f::<SHADOWS, GLASS, MIRROR, SPECULAR>$args` with the const
/// parameters read from a `Features` value.
macro_rules! with_features {
    ($feat:expr, $f:ident, $args:tt) => {
        with_features!(@ $f, $args, [], [$feat.shadows, $feat.glass, $feat.mirror, $feat.specular])
    };
    (@ $f:ident, $args:tt, [$($acc:tt)*], []) => { $f::<$($acc)*> $args };
    (@ $f:ident, $args:tt, [$($acc:tt)*], [$b:expr $(, $rest:expr)*]) => {
        if $b {
            with_features!(@ $f, $args, [$($acc)* true,], [$($rest),*])
        } else {
            with_features!(@ $f, $args, [$($acc)* false,], [$($rest),*])
        }
    };
}

/// A kernel step generic over the four shading switches (`SHADOWS`,
/// `GLASS`, `MIRROR`, `SPECULAR`), compiled three times (portable, AVX2,
/// AVX-512: `simd::with_avx2!`, which takes no generics, does the same for
/// plain functions) and picked at run time by [`crate::simd::isa`]: `$name`
/// calls the build of `$imp` (its steps, `#[inline(always)]`) for this CPU.
/// The builds stay out of line, so that the dispatcher is a few
/// instructions; each gives the same bits (no fused operations).
macro_rules! kernel_builds {
    ($(#[$attr:meta])* $vis:vis fn $name:ident => $imp:ident ($($arg:ident: $ty:ty),* $(,)?)) => {
        $(#[$attr])*
        $vis fn $name<const SHADOWS: bool, const GLASS: bool, const MIRROR: bool, const SPECULAR: bool>(
            $($arg: $ty),*
        ) {
            /// The portable build.
            #[inline(never)]
            fn portable<const SHADOWS: bool, const GLASS: bool, const MIRROR: bool, const SPECULAR: bool>(
                $($arg: $ty),*
            ) {
                $imp::<SHADOWS, GLASS, MIRROR, SPECULAR>($($arg),*)
            }
            /// The AVX2 build.
            #[cfg(target_arch = "x86_64")]
            #[target_feature(enable = "avx2")]
            #[inline(never)]
            fn avx2<const SHADOWS: bool, const GLASS: bool, const MIRROR: bool, const SPECULAR: bool>(
                $($arg: $ty),*
            ) {
                $imp::<SHADOWS, GLASS, MIRROR, SPECULAR>($($arg),*)
            }
            /// The AVX-512 build.
            #[cfg(target_arch = "x86_64")]
            #[target_feature(enable = "avx512f,avx512vl,avx512dq,avx512bw,avx2")]
            #[inline(never)]
            fn avx512<const SHADOWS: bool, const GLASS: bool, const MIRROR: bool, const SPECULAR: bool>(
                $($arg: $ty),*
            ) {
                $imp::<SHADOWS, GLASS, MIRROR, SPECULAR>($($arg),*)
            }
            #[cfg(target_arch = "x86_64")]
            match crate::simd::isa() {
                // SAFETY: each build differs from the portable one only in
                // being compiled with more instructions, and `isa` picks
                // only a build whose instructions this CPU has
                // (`Isa::detected`). Calling a `target_feature` function
                // needs `unsafe` in Rust; nothing else here is unchecked.
                crate::simd::Isa::Avx512 => return unsafe { avx512::<SHADOWS, GLASS, MIRROR, SPECULAR>($($arg),*) },
                // SAFETY: as above.
                crate::simd::Isa::Avx2 => return unsafe { avx2::<SHADOWS, GLASS, MIRROR, SPECULAR>($($arg),*) },
                crate::simd::Isa::Portable => {}
            }
            portable::<SHADOWS, GLASS, MIRROR, SPECULAR>($($arg),*)
        }
    };
}

mod emission;
mod lens_pass;
mod lens_send;
mod lit;
mod local;
mod packet;
mod photons;
mod refraction;
mod scalar;
mod shade;
mod surface;
mod system_pass;

pub use emission::{Targets, photons_per_light};
pub use lens_pass::Transmitted;
pub use lit::Lit;
pub use packet::PacketScratch;
pub use photons::{Sent, family_source, photon_pass};
pub use refraction::{transmitted_ray, transmitted_rays};
pub use shade::{GHOST_ROULETTE, LENS_MIN_WEIGHT, MIN_WEIGHT, Secondary, light_at};
pub use surface::{Surface, shadow_ray, spawn_ray, surface};

use crate::color::Rgb;
use crate::math::Ray;
use crate::simd::{LANES, Lanes};
use crate::trace::{Packet, PacketHits};
use packet::packet_kernel;
use scalar::kernel;

/// Radiance arriving along `ray` at wavelength `lambda_um` (used only by
/// dispersive glass), `depth` bounces deep.
///
/// The kernel is chosen once per call from the scene's [`Features`]: each
/// combination is its own monomorphised function, so a scene pays nothing for
/// what it does not use — no shadow rays, no refraction or mirror branch, no
/// specular term — not even a test per hit.
///
/// [`Features`]: crate::scene::Features
pub fn radiance<'a>(scene: impl Into<Lit<'a>>, ray: &Ray, depth: u32, lambda_um: f64) -> Rgb {
    let lit = scene.into();
    let scene = &lit;
    let f = scene.features;
    with_features!(f, kernel, (*scene, ray, usize::MAX, depth, lambda_um, 1.0))
}

/// The rays of a packet in flight: their closest hits, which lanes are live
/// (`active`, a bit mask), and each lane's path depth and weight.
#[derive(Clone, Copy, Debug)]
pub struct PacketPaths<'a> {
    pub rays: &'a Packet,
    pub hits: &'a PacketHits,
    pub active: u32,
    pub depth: [u32; LANES],
    pub weight: [f64; LANES],
}

impl<'a> PacketPaths<'a> {
    /// Camera rays: the first `n` lanes live, at depth 0 and weight 1.
    pub fn camera(rays: &'a Packet, hits: &'a PacketHits, n: usize) -> Self {
        PacketPaths {
            rays,
            hits,
            active: (1u32 << n) - 1,
            depth: [0; LANES],
            weight: [1.0; LANES],
        }
    }
}

/// [`radiance`] of every live ray of a packet whose closest hits are known:
/// the same values, lane by lane, with the shadow rays and the refracted and
/// reflected rays of the lanes traced as packets too.
/// `scratch` is working memory kept from packet to packet (one per thread
/// of work): it holds no result between calls.
pub fn radiance_packet(scene: &Lit, paths: &PacketPaths, lambda_um: f64, scratch: &mut PacketScratch) -> [Rgb; LANES] {
    let mut out = [Rgb::ZERO; LANES];
    radiance_packet_into(scene, paths, lambda_um, scratch, &mut out);
    out
}

/// [`radiance_packet`] written into `out` (every lane: zero where not live).
#[inline]
pub fn radiance_packet_into(
    scene: &Lit,
    paths: &PacketPaths,
    lambda_um: f64,
    scratch: &mut PacketScratch,
    out: &mut Lanes<Rgb>,
) {
    let f = scene.features;
    with_features!(f, packet_kernel, (*scene, paths, lambda_um, scratch, out));
}

/// [`radiance_packet`] with every feature compiled in: what a renderer that
/// does not specialise would run. For benchmarks of the savings.
pub fn radiance_packet_unspecialised(
    scene: &Lit,
    paths: &PacketPaths,
    lambda_um: f64,
    scratch: &mut PacketScratch,
) -> [Rgb; LANES] {
    let mut out = [Rgb::ZERO; LANES];
    packet_kernel::<true, true, true, true>(*scene, paths, lambda_um, scratch, &mut out);
    out
}

/// The signature of [`radiance_packet`] and [`radiance_packet_unspecialised`].
pub type PacketKernel = fn(&Lit, &PacketPaths, f64, &mut PacketScratch) -> [Rgb; LANES];
