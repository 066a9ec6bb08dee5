//! What the lanes of a packet that enter a lens together send on
//! ([`send_through_lens`]): [`shade_onward`]'s steps for a lane entering a
//! lens, over all lanes at once where the lanes' pass ([`LensPasses`])
//! ends the lane's tree at its first two exits (nearly every lane), else
//! lane by lane with the scalar walk and chain.
//!
//! [`shade_onward`]: super::shade::shade_onward

// Lane loops index several arrays by the lane: the form the vectoriser wants.
#![allow(clippy::needless_range_loop)]

use super::Lit;
use super::PacketPaths;
use super::lens_pass::{LensPasses, Transmitted, chain};
use super::packet::{Extra, Gather, Onward, further};
use super::shade::{
    Secondary, Tracer, carried_on, followed, glass_shares, lens_pruning, reflected, refracted, within_depth,
};
use super::surface::Surface;
use crate::color::Rgb;
use crate::geometry::{Inside, Lens, Pruning};
use crate::scene::{Object, Scene};
use crate::simd::{LANES, Lanes, lane, live_lanes, mask, with_avx2};

/// [`send_onward`](super::packet) for the lanes whose passes through a lens
/// `passes` traced together: [`shade_onward`](super::shade::shade_onward)'s
/// steps for a lane entering a lens ([`glass_shares`], [`lens_pruning`],
/// [`refracted`], [`reflected`]). The rays out at the first two exits and
/// the reflected rays of all lanes are written into the packets as lane
/// arrays ([`lens_onward`]); a lane whose tree goes on past the lanes' exits
/// takes [`LensPasses::walk`] and the scalar [`chain`] ([`chain_on`], out of
/// line). Out of line, so that the common path stays small. The lanes'
/// colours take nothing until the rays come back.
#[inline(never)]
pub(super) fn send_through_lens<const SHADOWS: bool, const GLASS: bool, const MIRROR: bool, const SPECULAR: bool>(
    scene: Lit,
    paths: &PacketPaths,
    surfaces: &[Option<Surface>; LANES],
    passes: &LensPasses,
    lambda_um: f64,
    onward: &mut [Onward; 3],
    extra: &mut Vec<Extra>,
) {
    // Every traced lane is on the same lens (`lens_passes`).
    let Some(first) = &surfaces[passes.lanes.trailing_zeros() as usize % LANES] else {
        return;
    };
    let m = &first.object.material;
    let mut shares = [[0.0; LANES]; 2];
    for l in 0..LANES {
        (shares[0][l], shares[1][l]) = glass_shares::<MIRROR>(m, passes.pass.entry_fresnel[l]);
    }
    let left = lens_onward(scene.scene, (first.index, first.object), passes, paths, &shares, onward);
    for l in live_lanes(left) {
        let Some(s) = &surfaces[l] else { continue };
        let Some(lens) = s.object.lens() else { continue };
        let (depth, weight, kt) = (paths.depth[l], paths.weight[l], shares[1][l]);
        let prune = lens_pruning(scene.scene, depth, weight, kt);
        let lane = LensLane {
            scene,
            s,
            depth,
            weight,
            kt,
            l,
        };
        // A lane's rays out of a lens take the refracted slots in order
        // (`Gather` would find them free: the lane sent nothing yet).
        let mut slot = 0;
        let mut send = |tr: Transmitted| {
            if let Some(sec) = lane.refracted(tr) {
                if slot < 2 {
                    onward[slot].push(l, &sec);
                } else {
                    extra.push(further::<SHADOWS, GLASS, MIRROR, SPECULAR>(scene, l, &sec, lambda_um));
                }
                slot += 1;
            }
        };
        if let Some(on) = passes.walk(l, lens, s.p, &prune, &mut send) {
            chain_on::<SHADOWS, GLASS, MIRROR, SPECULAR>(&lane, lambda_um, (lens, on, &prune), onward, extra);
        }
    }
}

/// The rays the traced lanes of `passes` send on, written into `onward`
/// lane by lane with no branch on a lane's values, so that the lanes run
/// side by side in SIMD registers: each lane's reflected ray
/// ([`reflected`], slot 2), and where the lanes end its tree
/// ([`LensPasses::finished`]) its rays out at the first two exits in the
/// order [`LensPasses::walk`] emits them ([`carried_on`] within the depth,
/// slots 0 and 1). Every lane of the three packets is written, and a lane
/// made live where it sends a ray (nothing was gathered before). The lanes
/// enter the lens `object` (of index `index`); `shares` are each lane's
/// reflected and transmitted shares ([`glass_shares`]). Returns the traced
/// lanes whose refracted rays are left to the scalar steps.
#[inline(always)]
fn lens_onward_impl(
    scene: &Scene,
    (index, object): (usize, &Object),
    passes: &LensPasses,
    paths: &PacketPaths,
    shares: &[Lanes<f64>; 2],
    onward: &mut [Onward; 3],
) -> u32 {
    let [kr, kt] = shares;
    let mut sent = [[false; LANES]; 3];
    let mut left = [false; LANES];
    let [out0, out1, mirror] = &mut *onward;
    for l in 0..LANES {
        let traced = passes.lanes >> l & 1 != 0;
        // Lanes not traced hold what an earlier packet left: numbers too.
        let (depth, weight) = (paths.depth[l], paths.weight[l]);
        let live = traced & (depth < scene.max_depth);
        let at = Surface {
            index,
            object,
            p: lane(&passes.x, l),
            nf: lane(&passes.nf, l),
            entering: true,
        };
        mirror.write(l, &reflected(&at, lane(&passes.dir, l), depth, weight, kr[l]));
        sent[2][l] = live & followed(kr[l], weight);
        let through = live & followed(kt[l], weight);
        let f = passes.finished(l, &lens_pruning(scene, depth, weight, kt[l]));
        let done = through & f.done;
        let a = done & f.kept[0] & within_depth(scene, depth, 2);
        let b = done & f.kept[1] & within_depth(scene, depth, 3);
        let (first, second) = (passes.ray_out(0, l, f.out[0]), passes.ray_out(1, l, f.out[1]));
        let firsts = if a { first } else { second };
        out0.write(l, &carried_on(&at, depth, weight, kt[l], firsts));
        out1.write(l, &carried_on(&at, depth, weight, kt[l], second));
        sent[0][l] = a | b;
        sent[1][l] = a & b;
        left[l] = through & !f.done;
    }
    for (o, sent) in onward.iter_mut().zip(&sent) {
        o.live |= mask(sent);
    }
    mask(&left)
}

with_avx2! {
    /// [`lens_onward_impl`], built for AVX2 where the CPU has it.
    fn lens_onward / lens_onward_avx2 => lens_onward_impl(
        scene: &Scene,
        lens: (usize, &Object),
        passes: &LensPasses,
        paths: &PacketPaths,
        shares: &[Lanes<f64>; 2],
        onward: &mut [Onward; 3]
    ) -> u32
}

/// A lane of [`send_through_lens`] entering a lens at its surface `s`
/// (transmitted share `kt`).
struct LensLane<'a, 's> {
    scene: Lit<'a>,
    s: &'a Surface<'s>,
    depth: u32,
    weight: f64,
    kt: f64,
    l: usize,
}

impl LensLane<'_, '_> {
    /// [`refracted`] for a ray out of the lens.
    #[inline(always)]
    fn refracted(&self, tr: Transmitted) -> Option<Secondary> {
        refracted(self.scene.scene, self.s, self.depth, self.weight, self.kt, tr)
    }
}

kernel_builds! {
    /// The rays out of a lens past the first two exits of lane `lane` (the
    /// light inside `on` in `lens`, pruned by `prune`), by the scalar
    /// [`chain`], gathered as [`Gather`] does. Out of line, so that the
    /// lanes' common path keeps its values in registers; in the best build
    /// this CPU runs, as the kernels are: compiled for the baseline x86-64
    /// alone (SSE2), it was 39 % of rim-lens's frame (`perf`, round 30),
    /// where a lens seen near its rim sends many rays on past the first two.
    #[inline(always)]
    fn chain_on => chain_on_impl(
        lane: &LensLane,
        lambda_um: f64,
        within: (&Lens, Inside, &Pruning),
        onward: &mut [Onward; 3],
        extra: &mut Vec<Extra>,
    )
}

/// [`chain_on`]'s steps, compiled into each build.
#[inline(always)]
fn chain_on_impl<const SHADOWS: bool, const GLASS: bool, const MIRROR: bool, const SPECULAR: bool>(
    lane: &LensLane,
    lambda_um: f64,
    (lens, on, prune): (&Lens, Inside, &Pruning),
    onward: &mut [Onward; 3],
    extra: &mut Vec<Extra>,
) {
    let mut gather = Gather::<SHADOWS, GLASS, MIRROR, SPECULAR> {
        scene: lane.scene,
        lambda_um,
        l: lane.l,
        onward,
        extra,
    };
    let ior = lens.index.at(lambda_um);
    chain(lens, on, ior, prune, |tr| {
        if let Some(sec) = lane.refracted(tr) {
            gather.trace(sec, &mut Rgb::default());
        }
    });
}

#[cfg(test)]
mod tests {
    use super::super::scalar::kernel;
    use super::super::{PacketScratch, radiance_packet};
    use super::*;
    use crate::math::Ray;
    use crate::optics::WAVELENGTH_D_UM;
    use crate::sampling::Sampler;
    use crate::scene::Scene;
    use crate::trace::{NO_OBJECT, Packet, closest_hits};
    use glam::DVec3;

    /// Packets whose lanes enter the lens of cubes.toml, or of a steep
    /// version of it (index 3: many exits near the critical angle, where
    /// the first ray out can be dropped and the second kept), at depths from
    /// 0 to past `max_depth` (1 to 8) and with path weights from 1 down to
    /// below the pruning bounds, so that the lanes send two rays out, one
    /// (either) or none: every lane's radiance from the packet kernel is the
    /// scalar kernel's, bit for bit.
    #[test]
    fn lens_lanes_send_what_the_scalar_kernel_follows() {
        let cubes = include_str!("../../../scenes/cubes.toml");
        let steep = cubes.replace("r1 = 5\nr2 = 5\nn = 1.5", "r1 = 1.05\nr2 = 8\nn = 3");
        assert!(steep.contains("n = 3"));
        let mut s = Sampler::new(13, 0, 0);
        let mut entered = 0;
        for (text, max_depth) in [1, 2, 3, 4, 8].into_iter().flat_map(|m| [(cubes, m), (&steep, m)]) {
            let mut scene = Scene::parse("cubes", text).expect("a valid scene").1;
            scene.max_depth = max_depth;
            let (index, lens) = super::super::lens_pass::first_lens(&scene);
            let (center, axis, d) = (lens.center, lens.axis, lens.d);
            let mut scratch = PacketScratch::default();
            for _ in 0..200 {
                let mut v = || DVec3::new(s.next_f64(), s.next_f64(), s.next_f64()) - 0.5;
                let rays: Vec<Ray> = (0..LANES)
                    .map(|_| {
                        let org = center + axis * 3.0 * d + v() * 2.0 * d;
                        Ray::new(org, center + v() * 1.2 * d - org)
                    })
                    .collect();
                let depth: Lanes<u32> = std::array::from_fn(|_| (s.next_f64() * f64::from(max_depth + 2)) as u32);
                let weight: Lanes<f64> = std::array::from_fn(|_| 10f64.powf(-5.0 * s.next_f64()));
                let packet = Packet::new(&rays, f64::INFINITY);
                let hits = closest_hits(&scene, &packet, &[NO_OBJECT; LANES]);
                let paths = PacketPaths {
                    rays: &packet,
                    hits: &hits,
                    active: 0xff,
                    depth,
                    weight,
                };
                let got = radiance_packet(&(&scene).into(), &paths, WAVELENGTH_D_UM, &mut scratch);
                for (l, ray) in rays.iter().enumerate() {
                    let (f, w) = (scene.features, weight[l]);
                    let want = with_features!(
                        f,
                        kernel,
                        ((&scene).into(), ray, usize::MAX, depth[l], WAVELENGTH_D_UM, w)
                    );
                    assert_eq!(got[l].to_array().map(f64::to_bits), want.to_array().map(f64::to_bits));
                    entered += usize::from(hits.object[l] as usize == index);
                }
            }
        }
        assert!(entered > 8000, "{entered} lanes entered the lens");
    }
}
