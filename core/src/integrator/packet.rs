//! The kernel for a packet of rays ([`packet_kernel`]): every step of the
//! scalar kernel (`scalar.rs`) over the lanes, in the same order and with
//! the same arithmetic per lane (the steps of `shade.rs`), so that each lane
//! gets the scalar radiance bit for bit. Each light's shadow rays are one
//! packet; the refracted and the reflected rays of the lanes are a packet
//! each ([`Onward`]; the second rays out of a lens one more, and a lane's
//! further ones go to the scalar kernel), traced after the local shading of
//! every lane.

// Lane loops index several arrays by the lane: the form the vectoriser wants.
#![allow(clippy::needless_range_loop)]

use super::Lit;
use super::PacketPaths;
use super::lens_pass::{LensPasses, lens_passes};
use super::local::{SurfaceLanes, add_light_lanes, local_shading};
use super::scalar::kernel;
use super::shade::{Secondary, Tracer, join, shade_onward};
use super::surface::Surface;
use super::system_pass::{SystemTrees, system_trees};
use crate::color::Rgb;

use crate::simd::{LANES, Lanes, lane, live_lanes, set_lane};
use crate::trace::{NO_OBJECT, Packet, closest_hits, lane_object, slab};

/// The packet kernel's working memory for one depth of its recursion, and
/// (made when first needed) for the depths below: the shadow packet, the
/// lanes' surfaces as structure of arrays, the gathered refracted and
/// reflected rays and what they bring back. Kept from packet to packet, so
/// that these arrays (about 4 KB a depth) are neither built nor copied per
/// packet; every lane read is written first, but for the lanes without a
/// surface in `surfaces`, whose numbers the lane loops run on and the
/// masks drop.
pub struct PacketScratch {
    shadow: Packet,
    surfaces: SurfaceLanes,
    lens: LensPasses,
    onward: [Onward; 3],
    back: [Lanes<Rgb>; 3],
    extra: Vec<Extra>,
    systems: SystemTrees,
    deeper: Option<Box<PacketScratch>>,
}

/// A lane's further ray out of a lens (after its first two, which go in
/// the refracted packets), traced at once by the scalar kernel: what it brought
/// back and how it joins.
pub(super) struct Extra {
    lane: usize,
    tint: Option<Rgb>,
    factor: f64,
    back: Rgb,
}

impl Default for PacketScratch {
    fn default() -> Self {
        PacketScratch {
            shadow: Packet::EMPTY,
            surfaces: SurfaceLanes::EMPTY,
            lens: LensPasses::EMPTY,
            onward: [Onward::REFRACTED, Onward::REFRACTED, Onward::REFLECTED],
            back: [[Rgb::ZERO; LANES]; 3],
            extra: Vec::new(),
            systems: SystemTrees::default(),
            deeper: None,
        }
    }
}

/// Below this many rays, secondary rays are traced one by one.
const MIN_PACKET: u32 = 3;

/// The refracted (slots 0 and 1) or reflected (slot 2) rays a packet's lanes send
/// on, gathered as a packet, with what [`Secondary`] holds for each lane.
pub(super) struct Onward {
    rays: Packet,
    pub(super) live: u32,
    skip: [u32; LANES],
    depth: [u32; LANES],
    weight: [f64; LANES],
    /// Whether the rays have a tint (the refracted ones), and each lane's
    /// (structure of arrays).
    tinted: bool,
    tint: [Lanes<f64>; 3],
    factor: [f64; LANES],
}

impl Onward {
    const REFRACTED: Onward = Onward::empty(true);
    const REFLECTED: Onward = Onward::empty(false);

    const fn empty(tinted: bool) -> Onward {
        Onward {
            rays: Packet::EMPTY,
            live: 0,
            skip: [NO_OBJECT; LANES],
            depth: [0; LANES],
            weight: [0.0; LANES],
            tinted,
            tint: [[0.0; LANES]; 3],
            factor: [0.0; LANES],
        }
    }

    #[inline(always)]
    pub(super) fn push(&mut self, l: usize, sec: &Secondary) {
        self.write(l, sec);
        self.live |= 1 << l;
    }

    /// Writes `sec` into lane `l`, which stays as live as it was: the
    /// lane loops of `send_through_lens` write every lane and set `live`
    /// after.
    #[inline(always)]
    pub(super) fn write(&mut self, l: usize, sec: &Secondary) {
        debug_assert_eq!(sec.tint.is_some(), self.tinted);
        self.rays.set(l, &sec.ray, f64::INFINITY);
        self.skip[l] = lane_object(sec.skip);
        self.depth[l] = sec.depth;
        self.weight[l] = sec.weight;
        // Untinted rays (the reflected packet's) leave the tints unread.
        if let Some(t) = sec.tint {
            set_lane(&mut self.tint, l, t);
        }
        self.factor[l] = sec.factor;
    }

    /// Lane `l`'s tint.
    #[inline(always)]
    fn tint(&self, l: usize) -> Option<Rgb> {
        self.tinted.then(|| lane(&self.tint, l))
    }

    /// Lane `l`'s ray as shading sent it.
    #[inline(always)]
    fn secondary(&self, l: usize) -> Secondary {
        Secondary {
            ray: self.rays.ray(l),
            skip: if self.skip[l] == NO_OBJECT {
                usize::MAX
            } else {
                self.skip[l] as usize
            },
            depth: self.depth[l],
            weight: self.weight[l],
            tint: self.tint(l),
            factor: self.factor[l],
        }
    }

    /// The radiance each live lane's ray brings back, written to `back`: a
    /// packet (with `scratch` for the next depth), or one ray at a time
    /// below [`MIN_PACKET`] rays.
    #[inline(always)]
    fn trace<const SHADOWS: bool, const GLASS: bool, const MIRROR: bool, const SPECULAR: bool>(
        &mut self,
        scene: Lit,
        lambda_um: f64,
        scratch: &mut PacketScratch,
        back: &mut Lanes<Rgb>,
    ) {
        if self.live.count_ones() < MIN_PACKET {
            for l in live_lanes(self.live) {
                let sec = self.secondary(l);
                back[l] = kernel::<SHADOWS, GLASS, MIRROR, SPECULAR>(
                    scene.lane(l),
                    &sec.ray,
                    sec.skip,
                    sec.depth,
                    lambda_um,
                    sec.weight,
                );
            }
            return;
        }
        // Every lane's inverse direction first (all lanes at once): the
        // escape test takes them too.
        self.rays.fill_unused(self.live);
        if self.all_escape(scene) {
            for l in live_lanes(self.live) {
                back[l] = scene.background;
            }
            return;
        }
        // Lanes that sent nothing hold what an earlier packet left; they
        // never hit (`fill_unused`), and skip nothing.
        for l in 0..LANES {
            if self.live >> l & 1 == 0 {
                self.skip[l] = NO_OBJECT;
            }
        }
        let hits = closest_hits(scene.scene, &self.rays, &self.skip);
        let paths = PacketPaths {
            rays: &self.rays,
            hits: &hits,
            active: self.live,
            depth: self.depth,
            weight: self.weight,
        };
        packet_kernel::<SHADOWS, GLASS, MIRROR, SPECULAR>(scene, &paths, lambda_um, scratch, back);
    }

    /// Whether every live lane's ray leaves its object (`skip`) and misses
    /// the box around all the others ([`Scene::others_bounds`]): then it
    /// meets nothing and brings back the background, which is what tracing
    /// it would give (the rays a lens reflects away from the scene, mostly).
    #[inline(always)]
    fn all_escape(&self, scene: Lit) -> bool {
        // The lanes grouped by the object they leave, one box test in lanes
        // for each group (`slab` is `slab_hit` a lane): most packets leave
        // one object (a lens's rays out, or those it reflects), so one test.
        // Plain loops, no closures: a closure is compiled without the
        // target features of the build that calls it.
        let mut left = self.live;
        while left != 0 {
            let skip = self.skip[left.trailing_zeros() as usize];
            let mut group = 0;
            for l in live_lanes(left) {
                group |= u32::from(self.skip[l] == skip) << l;
            }
            match scene.others_bounds.get(skip as usize) {
                None => return false,
                Some(Some(b)) if slab(b.min, b.max, &self.rays, &[f64::INFINITY; LANES]) & group != 0 => return false,
                _ => {}
            }
            left &= !group;
        }
        true
    }

    /// Adds what lane `l`'s ray brought back (`back`) to `color`, as
    /// [`Secondary::join`] does.
    #[inline(always)]
    fn join(&self, l: usize, color: &mut Rgb, back: Rgb) {
        join(color, self.tint(l), self.factor[l], back);
    }
}

kernel_builds! {
    /// The radiance of each live lane of `paths` (the others are zero), written
    /// to `out`: the local shading of every lane, each light's shadow rays as
    /// one packet, then the refracted and reflected rays as a packet each.
    ///
    /// Compiled three times, like the walks of `crate::trace` ([`crate::simd`]'s
    /// `with_avx2!`; `kernel_builds!` for the const parameters): the AVX-512 or AVX2
    /// build runs where the CPU has it ([`crate::simd::isa`]). The lanes' shading is scalar arithmetic either
    /// way (no FMA is enabled, and Rust never contracts a multiply and an add),
    /// so both builds give the same bits; AVX2's three-operand instructions
    /// save the register copies of the SSE2 build, and the lane loops run four
    /// lanes to an instruction instead of two.
    pub(super) fn packet_kernel => packet_kernel_impl(
        scene: Lit,
        paths: &PacketPaths,
        lambda_um: f64,
        scratch: &mut PacketScratch,
        out: &mut Lanes<Rgb>,
    )
}

/// [`packet_kernel`]'s steps, compiled into each build.
#[inline(always)]
fn packet_kernel_impl<const SHADOWS: bool, const GLASS: bool, const MIRROR: bool, const SPECULAR: bool>(
    scene: Lit,
    paths: &PacketPaths,
    lambda_um: f64,
    scratch: &mut PacketScratch,
    out: &mut Lanes<Rgb>,
) {
    let mut surfaces: [Option<Surface>; LANES] = [None; LANES];
    let at = &mut scratch.surfaces;
    if !local_shading::<GLASS, MIRROR>(scene, paths, &mut surfaces, at, out) {
        // Every ray escaped (the rays a lens reflects, mostly), or met
        // only what ambient light alone shades.
        return;
    }
    for light in &scene.lights {
        add_light_lanes::<SHADOWS, GLASS, SPECULAR>(
            scene,
            paths.rays,
            &scratch.surfaces,
            light,
            &mut scratch.shadow,
            out,
        );
    }
    if !(GLASS || MIRROR) {
        return;
    }
    let PacketScratch {
        onward,
        back,
        extra,
        deeper,
        lens,
        systems,
        ..
    } = scratch;
    let sent = Sent {
        lens,
        systems,
        onward,
        extra,
    };
    if !send_onward::<SHADOWS, GLASS, MIRROR, SPECULAR>(scene, paths, &surfaces, lambda_um, sent, out) {
        return;
    }
    let deeper = deeper.get_or_insert_with(Box::default);
    for (o, back) in onward.iter_mut().zip(back.iter_mut()) {
        if o.live != 0 {
            o.trace::<SHADOWS, GLASS, MIRROR, SPECULAR>(scene, lambda_um, deeper, back);
        }
    }
    // In the order `shade` adds them: refracted (the first two rays out of a
    // lens, then the others), then reflected. Each lane's sum is its own, so
    // the lanes can go slot by slot.
    for (k, (o, back)) in onward.iter().zip(back.iter()).enumerate() {
        for l in live_lanes(o.live) {
            o.join(l, &mut out[l], back[l]);
        }
        if k == 1 {
            for e in extra.iter() {
                join(&mut out[e.lane], e.tint, e.factor, e.back);
            }
        }
    }
}

/// Where [`send_onward`] puts the rays the lanes send on: the first
/// exits from a lens (`lens`, traced first), the refracted and reflected
/// packets, and the further rays out of a lens, traced at once.
struct Sent<'a> {
    lens: &'a mut LensPasses,
    systems: &'a mut SystemTrees,
    onward: &'a mut [Onward; 3],
    extra: &'a mut Vec<Extra>,
}

/// [`shade_onward`] at every lane's surface: the refracted (0; a second ray
/// out of a lens, 1) and reflected (2) rays gathered into `onward`, to be
/// traced afterwards (most packets send none), with the first exits from a
/// lens of the lanes that enter one traced together first (`lens`, working
/// memory); a lane's further rays out of a lens are traced at once by the
/// scalar kernel (into `extra`). Whether any lane sends a ray on.
#[inline(always)]
fn send_onward<const SHADOWS: bool, const GLASS: bool, const MIRROR: bool, const SPECULAR: bool>(
    scene: Lit,
    paths: &PacketPaths,
    surfaces: &[Option<Surface>; LANES],
    lambda_um: f64,
    sent: Sent,
    out: &mut Lanes<Rgb>,
) -> bool {
    let Sent {
        lens,
        systems,
        onward,
        extra,
    } = sent;
    let p = paths.rays;
    for o in onward.iter_mut() {
        o.live = 0;
    }
    extra.clear();
    let mut traced = 0;
    if GLASS && lens_passes(p, surfaces, lambda_um, lens) {
        traced = lens.lanes;
        super::lens_send::send_through_lens::<SHADOWS, GLASS, MIRROR, SPECULAR>(
            scene, paths, surfaces, lens, lambda_um, onward, extra,
        );
    }
    if GLASS {
        system_trees(scene.scene, paths, surfaces, lambda_um, systems);
    }
    // One sink for every lane, moved from lane to lane.
    let mut gather = Gather::<SHADOWS, GLASS, MIRROR, SPECULAR> {
        scene,
        lambda_um,
        l: 0,
        onward,
        extra,
    };
    for l in 0..LANES {
        let Some(s) = &surfaces[l] else { continue };
        if traced >> l & 1 != 0 {
            continue;
        }
        gather.l = l;
        let dir = p.dir(l);
        shade_onward::<GLASS, MIRROR>(
            scene.scene,
            dir,
            s,
            paths.depth[l],
            lambda_um,
            paths.weight[l],
            &systems.lane(l, p.ray(l)),
            &mut gather,
            &mut out[l],
        );
    }
    gather.onward.iter().any(|o| o.live != 0)
}

/// A lane's further ray out of a lens, traced at once by the scalar
/// kernel (rare: out of line, so that the common path stays small).
#[inline(never)]
pub(super) fn further<const SHADOWS: bool, const GLASS: bool, const MIRROR: bool, const SPECULAR: bool>(
    scene: Lit,
    lane: usize,
    sec: &Secondary,
    lambda_um: f64,
) -> Extra {
    Extra {
        lane,
        tint: sec.tint,
        factor: sec.factor,
        back: kernel::<SHADOWS, GLASS, MIRROR, SPECULAR>(
            scene.lane(lane),
            &sec.ray,
            sec.skip,
            sec.depth,
            lambda_um,
            sec.weight,
        ),
    }
}

/// Lane `l`'s [`Tracer`]: a refracted ray goes in the first of the
/// refracted packets (`onward` 0 and 1) where the lane is free, a reflected
/// one in the reflected packet (2), to be traced after the local shading of
/// every lane; a third refracted ray (out of a lens) is traced at once by
/// the scalar kernel (into `extra`).
pub(super) struct Gather<'a, const SHADOWS: bool, const GLASS: bool, const MIRROR: bool, const SPECULAR: bool> {
    pub(super) scene: Lit<'a>,
    pub(super) lambda_um: f64,
    pub(super) l: usize,
    pub(super) onward: &'a mut [Onward; 3],
    pub(super) extra: &'a mut Vec<Extra>,
}

impl<const SHADOWS: bool, const GLASS: bool, const MIRROR: bool, const SPECULAR: bool> Tracer
    for Gather<'_, SHADOWS, GLASS, MIRROR, SPECULAR>
{
    #[inline(always)]
    fn trace(&mut self, sec: Secondary, _: &mut Rgb) {
        let l = self.l;
        let free = |o: &Onward| o.live >> l & 1 == 0;
        let slot = match sec.tint {
            None => Some(2),
            Some(_) => (0..2).find(|&k| free(&self.onward[k])),
        };
        match slot {
            Some(k) => self.onward[k].push(l, &sec),
            None => self.extra.push(further::<SHADOWS, GLASS, MIRROR, SPECULAR>(
                self.scene,
                l,
                &sec,
                self.lambda_um,
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::radiance;
    use crate::optics::WAVELENGTH_D_UM;
    use crate::scene::Scene;
    use crate::trace::camera_hits;

    /// The portable build of the packet kernel (its first depth; the
    /// depths below go through [`packet_kernel`], the AVX2 build where the
    /// CPU has it) gives every lane the scalar kernel's radiance bit for
    /// bit, as the AVX2 build does (`render`'s tests compare that one),
    /// without and with each scene's caustic photons (gathered a packet at
    /// a time, `PhotonMap::irradiance_lanes`).
    #[test]
    fn the_portable_packet_kernel_gives_the_scalar_radiance() {
        let parse = |name, text| Scene::parse(name, text).unwrap().1;
        let scenes = [
            ("cubes", Scene::default_scene().1),
            (
                "primitives",
                parse("primitives", include_str!("../../../scenes/primitives.toml")),
            ),
            (
                "optical bench",
                parse("optical bench", include_str!("../../../scenes/optical-bench.toml")),
            ),
            (
                "rim lens",
                parse("rim lens", include_str!("../../../scenes/rim-lens.toml")),
            ),
        ];
        let (w, h) = (48u32, 36u32);
        let mut scratch = PacketScratch::default();
        let mut gathered = 0;
        for (name, scene) in &scenes {
            let map = crate::render::caustics::caustic_map(scene, 3, Default::default());
            assert!(map.is_some(), "{name} has caustics");
            for map in [None, map.as_ref()] {
                let lit = Lit::new(scene, map);
                let (mut seen, mut caustic) = (0, 0);
                for y in 0..h {
                    for x0 in (0..w).step_by(LANES) {
                        let xs: Lanes<f64> = std::array::from_fn(|l| (x0 as usize + l) as f64 + 0.5);
                        let ys = [y as f64 + 0.5; LANES];
                        let (p, hits) = camera_hits(scene, &xs, &ys, LANES, w, h);
                        let paths = PacketPaths::camera(&p, &hits, LANES);
                        let mut out = [Rgb::ZERO; LANES];
                        let f = scene.features;
                        with_features!(
                            f,
                            packet_kernel_impl,
                            (lit, &paths, WAVELENGTH_D_UM, &mut scratch, &mut out)
                        );
                        for l in 0..LANES {
                            let want = radiance(lit, &p.ray(l), 0, WAVELENGTH_D_UM);
                            assert_eq!(out[l], want, "{name}: pixel {}, {y}", x0 as usize + l);
                            seen += usize::from(want != scene.background);
                            if map.is_some() {
                                caustic += usize::from(want != radiance(scene, &p.ray(l), 0, WAVELENGTH_D_UM));
                            }
                        }
                    }
                }
                assert!(seen > (w * h) as usize / 2, "only {seen} pixels lit");
                gathered += caustic;
            }
        }
        assert!(gathered > 100, "{gathered} pixels show caustics");
    }
}
