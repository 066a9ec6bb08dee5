//! Whitted radiance: ambient + Lambert diffuse + Phong specular for each
//! light, hard shadows, mirror reflection and Snell refraction with total
//! internal reflection, to a maximum depth.
//!
//! Light through a lens follows the lens's own exact tracer
//! ([`Lens::propagate_inside`]): the same code `lensview lens trace` reports.

use crate::accel::packet::{
    LANES, Lanes, NO_OBJECT, Packet, PacketHits, closest_hits, live_lanes, transmittances, with_avx2,
};
use crate::color::Rgb;
use crate::geometry::{ExitCrossing, Hit, Lens, LensTraceStatus};
use crate::light::{Light, LightSample};
use crate::math::{Ray, surface_offset};
use crate::optics::{self, fresnel_at};
use crate::scene::{Object, Scene};
use glam::DVec3;

/// Below this path weight a branch is not traced further.
const MIN_WEIGHT: f64 = 1e-4;

/// The closest hit: object index and the shape's hit record. Walks the
/// scene's BVH when it has one, else tests every object's box.
#[inline]
pub fn closest_hit(scene: &Scene, ray: &Ray, t_max: f64) -> Option<(usize, Hit)> {
    closest_hit_skip(scene, ray, t_max, usize::MAX)
}

/// [`closest_hit`] without testing object `skip` (one the ray is leaving:
/// see [`Surface::leaving`]).
#[inline]
pub fn closest_hit_skip(scene: &Scene, ray: &Ray, t_max: f64, skip: usize) -> Option<(usize, Hit)> {
    let mut best: Option<(usize, Hit)> = None;
    let mut test = |i: usize, t_max: f64| {
        if i == skip {
            return None;
        }
        let o = &scene.objects[i];
        o.shape.intersect(&o.to_object(ray), 0.0, t_max).map(|h| {
            best = Some((i, h));
            h.t
        })
    };
    match &scene.bvh {
        Some(bvh) => bvh.traverse(ray, t_max, |i, t_max| Ok(test(i as usize, t_max))),
        None => {
            let inv = ray.dir.recip();
            let mut t_max = t_max;
            for (i, o) in scene.objects.iter().enumerate() {
                if o.world_bounds.hit(ray, inv, 0.0, t_max)
                    && let Some(t) = test(i, t_max)
                {
                    t_max = t;
                }
            }
        }
    }
    best
}

/// Light that reaches from `p` to a light `dist` away along `dir`: zero
/// behind an opaque object (the search stops at the first), filtered by each
/// transparent object crossed.
pub fn transmittance(scene: &Scene, p: DVec3, dir: DVec3, dist: f64) -> Rgb {
    transmittance_skip(scene, &Ray { origin: p, dir }, dist, usize::MAX)
}

/// [`transmittance`] along `ray` without testing object `skip`.
pub fn transmittance_skip(scene: &Scene, ray: &Ray, dist: f64, skip: usize) -> Rgb {
    let mut t = Rgb::ONE;
    let mut test = |i: usize| {
        let o = &scene.objects[i];
        if i != skip && o.shape.intersect(&o.to_object(ray), 0.0, dist).is_some() {
            t *= o.material.shadow_transmittance();
        }
        t != Rgb::ZERO
    };
    match &scene.bvh {
        Some(bvh) => bvh.traverse(ray, dist, |i, _| if test(i as usize) { Ok(None) } else { Err(()) }),
        None => {
            let inv = ray.dir.recip();
            for (i, o) in scene.objects.iter().enumerate() {
                if o.world_bounds.hit(ray, inv, 0.0, dist) && !test(i) {
                    break;
                }
            }
        }
    }
    t
}

/// Where a ray leaves a surface: pushed off by a few rounding errors of the
/// point's coordinates, on the side it travels to.
#[inline]
pub fn spawn_ray(p: DVec3, normal: DVec3, dir: DVec3, scale: f64) -> Ray {
    spawn_ray_by(p, normal, dir, surface_offset(p, scale))
}

/// [`spawn_ray`] with the offset given.
#[inline(always)]
fn spawn_ray_by(p: DVec3, normal: DVec3, dir: DVec3, offset: f64) -> Ray {
    let side = if dir.dot(normal) >= 0.0 { normal } else { -normal };
    Ray {
        origin: p + side * offset,
        dir,
    }
}

/// Radiance arriving along `ray` at wavelength `lambda_um` (used only by
/// dispersive glass), `depth` bounces deep.
///
/// The kernel is chosen once per call from the scene's [`Features`]: each
/// combination is its own monomorphised function, so a scene pays nothing for
/// what it does not use — no shadow rays, no refraction or mirror branch, no
/// specular term — not even a test per hit.
///
/// [`Features`]: crate::scene::Features
pub fn radiance(scene: &Scene, ray: &Ray, depth: u32, lambda_um: f64) -> Rgb {
    let f = scene.features;
    with_features!(f, kernel, (scene, ray, usize::MAX, depth, lambda_um, 1.0))
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
pub fn radiance_packet(
    scene: &Scene,
    paths: &PacketPaths,
    lambda_um: f64,
    scratch: &mut PacketScratch,
) -> [Rgb; LANES] {
    let mut out = [Rgb::ZERO; LANES];
    radiance_packet_into(scene, paths, lambda_um, scratch, &mut out);
    out
}

/// [`radiance_packet`] written into `out` (every lane: zero where not live).
#[inline]
pub fn radiance_packet_into(
    scene: &Scene,
    paths: &PacketPaths,
    lambda_um: f64,
    scratch: &mut PacketScratch,
    out: &mut Lanes<Rgb>,
) {
    let f = scene.features;
    with_features!(f, packet_kernel, (scene, paths, lambda_um, scratch, out));
}

/// [`radiance_packet`] with every feature compiled in: what a renderer that
/// does not specialise would run. For benchmarks of the savings.
pub fn radiance_packet_unspecialised(
    scene: &Scene,
    paths: &PacketPaths,
    lambda_um: f64,
    scratch: &mut PacketScratch,
) -> [Rgb; LANES] {
    let mut out = [Rgb::ZERO; LANES];
    packet_kernel::<true, true, true, true>(scene, paths, lambda_um, scratch, &mut out);
    out
}

/// The signature of [`radiance_packet`] and [`radiance_packet_unspecialised`].
pub type PacketKernel = fn(&Scene, &PacketPaths, f64, &mut PacketScratch) -> [Rgb; LANES];

/// The packet kernel's working memory for one depth of its recursion, and
/// (made when first needed) for the depths below: the shadow packet, the
/// gathered refracted and reflected rays and what they bring back. Kept
/// from packet to packet, so that these arrays (about 3 KB a depth) are
/// neither built nor copied per packet; every lane read is written first.
pub struct PacketScratch {
    shadow: Packet,
    lens: LensPasses,
    onward: [Onward; 2],
    back: [Lanes<Rgb>; 2],
    deeper: Option<Box<PacketScratch>>,
}

impl Default for PacketScratch {
    fn default() -> Self {
        PacketScratch {
            shadow: Packet::EMPTY,
            lens: LensPasses::EMPTY,
            onward: [Onward::EMPTY, Onward::EMPTY],
            back: [[Rgb::ZERO; LANES]; 2],
            deeper: None,
        }
    }
}

/// Below this many rays, secondary rays are traced one by one.
const MIN_PACKET: u32 = 3;

/// The refracted (kind 0) or reflected (kind 1) rays a packet's lanes send
/// on, gathered as a packet, with what [`Secondary`] holds for each lane.
struct Onward {
    rays: Packet,
    live: u32,
    skip: [u32; LANES],
    depth: [u32; LANES],
    weight: [f64; LANES],
    tint: [Option<Rgb>; LANES],
    factor: [f64; LANES],
}

impl Onward {
    const EMPTY: Onward = Onward {
        rays: Packet::EMPTY,
        live: 0,
        skip: [NO_OBJECT; LANES],
        depth: [0; LANES],
        weight: [0.0; LANES],
        tint: [None; LANES],
        factor: [0.0; LANES],
    };

    #[inline(always)]
    fn push(&mut self, l: usize, sec: &Secondary) {
        self.rays.set(l, &sec.ray, f64::INFINITY);
        self.live |= 1 << l;
        self.skip[l] = u32::try_from(sec.skip).unwrap_or(NO_OBJECT);
        self.depth[l] = sec.depth;
        self.weight[l] = sec.weight;
        self.tint[l] = sec.tint;
        self.factor[l] = sec.factor;
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
            tint: self.tint[l],
            factor: self.factor[l],
        }
    }

    /// The radiance each live lane's ray brings back, written to `back`: a
    /// packet (with `scratch` for the next depth), or one ray at a time
    /// below [`MIN_PACKET`] rays.
    #[inline(always)]
    fn trace<const SHADOWS: bool, const GLASS: bool, const MIRROR: bool, const SPECULAR: bool>(
        &mut self,
        scene: &Scene,
        lambda_um: f64,
        scratch: &mut PacketScratch,
        back: &mut Lanes<Rgb>,
    ) {
        if self.live.count_ones() < MIN_PACKET {
            for l in live_lanes(self.live) {
                let sec = self.secondary(l);
                back[l] = kernel::<SHADOWS, GLASS, MIRROR, SPECULAR>(
                    scene, &sec.ray, sec.skip, sec.depth, lambda_um, sec.weight,
                );
            }
            return;
        }
        if self.all_escape(scene) {
            for l in live_lanes(self.live) {
                back[l] = scene.background;
            }
            return;
        }
        self.rays.fill_unused(self.live);
        // Lanes that sent nothing hold what an earlier packet left; they
        // never hit (`fill_unused`), and skip nothing.
        for l in 0..LANES {
            if self.live >> l & 1 == 0 {
                self.skip[l] = NO_OBJECT;
            }
        }
        let hits = closest_hits(scene, &self.rays, &self.skip);
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
    fn all_escape(&self, scene: &Scene) -> bool {
        for l in live_lanes(self.live) {
            let Some(bounds) = scene.others_bounds.get(self.skip[l] as usize) else {
                return false;
            };
            if let Some(b) = bounds {
                let ray = self.rays.ray(l);
                if b.hit(&ray, ray.dir.recip(), 0.0, f64::INFINITY) {
                    return false;
                }
            }
        }
        true
    }

    /// Adds what lane `l`'s ray brought back (`back`) to `color`, as
    /// [`Secondary::join`] does.
    #[inline(always)]
    fn join(&self, l: usize, color: &mut Rgb, back: Rgb) {
        join(color, self.tint[l], self.factor[l], back);
    }
}

/// The packet form of the scalar [`kernel`]: every step of [`shade`] over
/// the lanes, in the same order and with the same arithmetic per lane
/// ([`ambient`], [`add_light`], [`shade_onward`]), so that each lane gets
/// the scalar radiance bit for bit. Each light's shadow rays are one
/// packet; the refracted and the reflected rays of the lanes are a packet
/// each, traced after the local shading of every lane. The radiance of
/// each live lane is written to `out` (the others are zero).
fn packet_kernel<const SHADOWS: bool, const GLASS: bool, const MIRROR: bool, const SPECULAR: bool>(
    scene: &Scene,
    paths: &PacketPaths,
    lambda_um: f64,
    scratch: &mut PacketScratch,
    out: &mut Lanes<Rgb>,
) {
    let PacketPaths {
        rays: p,
        hits,
        active,
        ref depth,
        ref weight,
    } = *paths;
    let mut surfaces: [Option<Surface>; LANES] = [None; LANES];
    *out = [Rgb::ZERO; LANES];
    let mut any = false;
    for l in 0..LANES {
        if active >> l & 1 == 0 {
            continue;
        }
        match hits.get(l) {
            Some((i, h)) => {
                let s = surface(scene, &p.ray(l), i, h);
                out[l] = ambient::<GLASS>(scene, &s);
                surfaces[l] = Some(s);
                any = true;
            }
            None => out[l] = scene.background,
        }
    }
    if !any {
        // Every ray escaped (the rays a lens reflects, mostly).
        return;
    }
    // Each light at every lane's surface, its shadow rays a packet.
    for light in &scene.lights {
        let mut samples: [Option<LightSample>; LANES] = [None; LANES];
        for l in 0..LANES {
            samples[l] = surfaces[l].as_ref().and_then(|s| light_at(s, light));
        }
        let mut vis = [Rgb::ONE; LANES];
        if SHADOWS && scene.shadows {
            let shadow = &mut scratch.shadow;
            let mut live = 0u32;
            let mut skip = [NO_OBJECT; LANES];
            for l in 0..LANES {
                if let (Some(s), Some(ls)) = (&surfaces[l], &samples[l])
                    && visibility_matters::<GLASS, SPECULAR>(s, ls, p.dir(l))
                {
                    let (r, t_max) = shadow_ray(s, ls);
                    shadow.set(l, &r, t_max);
                    live |= 1 << l;
                    skip[l] = u32::try_from(s.leaving(ls.to_light)).unwrap_or(NO_OBJECT);
                }
            }
            if live != 0 {
                shadow.fill_unused(live);
                vis = transmittances(scene, shadow, &skip);
            }
        }
        for l in 0..LANES {
            if let (Some(s), Some(ls)) = (&surfaces[l], &samples[l]) {
                add_light::<SHADOWS, GLASS, SPECULAR>(scene, s, p.dir(l), ls, vis[l], &mut out[l]);
            }
        }
    }
    if !(GLASS || MIRROR) {
        return;
    }
    // Refracted (0) and reflected (1) rays, gathered and traced afterwards
    // (most packets send none).
    let PacketScratch {
        onward,
        back,
        deeper,
        lens,
        ..
    } = scratch;
    // The passes through a lens of the lanes that enter one, traced together.
    let passes = GLASS && lens_passes(p, &surfaces, lambda_um, lens);
    let lens = &*lens;
    let traced = |l: usize| (passes && lens.lanes >> l & 1 != 0).then_some(lens);
    for o in onward.iter_mut() {
        o.live = 0;
    }
    for l in 0..LANES {
        let Some(s) = &surfaces[l] else { continue };
        let dir = p.dir(l);
        shade_onward::<GLASS, MIRROR>(
            scene,
            dir,
            s,
            depth[l],
            lambda_um,
            weight[l],
            &mut |dir, nf, n1, n2| match traced(l) {
                Some(ps) => ps.pass.entry_fresnel[l],
                None => fresnel_at(dir, nf, n1, n2),
            },
            &mut |s, ior| match traced(l) {
                Some(ps) => ps.transmitted(l),
                None => transmitted_ray(s.object, s.p, s.nf, s.entering, dir, ior),
            },
            &mut |sec, _| onward[usize::from(sec.tint.is_none())].push(l, &sec),
            &mut out[l],
        );
    }
    if onward.iter().all(|o| o.live == 0) {
        return;
    }
    let deeper = deeper.get_or_insert_with(Box::default);
    for (o, back) in onward.iter_mut().zip(back.iter_mut()) {
        if o.live != 0 {
            o.trace::<SHADOWS, GLASS, MIRROR, SPECULAR>(scene, lambda_um, deeper, back);
        }
    }
    // In the order `shade` adds them: refracted, then reflected.
    for l in 0..LANES {
        for (o, back) in onward.iter().zip(back.iter()) {
            if o.live >> l & 1 != 0 {
                o.join(l, &mut out[l], back[l]);
            }
        }
    }
}

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
use with_features;

fn kernel<const SHADOWS: bool, const GLASS: bool, const MIRROR: bool, const SPECULAR: bool>(
    scene: &Scene,
    ray: &Ray,
    skip: usize,
    depth: u32,
    lambda_um: f64,
    weight: f64,
) -> Rgb {
    let hit = closest_hit_skip(scene, ray, f64::INFINITY, skip);
    let hit = hit.map(|(i, h)| surface(scene, ray, i, h));
    shade::<SHADOWS, GLASS, MIRROR, SPECULAR>(scene, ray, hit.as_ref(), depth, lambda_um, weight)
}

/// A ray that shading sends on (refracted or reflected), and how its
/// radiance `L` joins the colour: `colour += tint · L · factor`.
#[derive(Clone, Copy, Debug)]
pub struct Secondary {
    pub ray: Ray,
    /// The object the ray leaves ([`Surface::leaving`]), or `usize::MAX`.
    pub skip: usize,
    pub depth: u32,
    /// Path weight after this ray.
    pub weight: f64,
    pub tint: Option<Rgb>,
    pub factor: f64,
}

impl Secondary {
    /// Adds the radiance `l` that came back along the ray.
    #[inline]
    pub fn join(&self, color: &mut Rgb, l: Rgb) {
        join(color, self.tint, self.factor, l);
    }
}

/// How the radiance `l` a secondary ray brought back joins the colour:
/// `colour += tint · l · factor` (without a tint, `l · factor`).
#[inline(always)]
fn join(color: &mut Rgb, tint: Option<Rgb>, factor: f64, l: Rgb) {
    *color += match tint {
        Some(t) => t * l * factor,
        None => l * factor,
    };
}

/// A hit with what shading needs of it.
#[derive(Clone, Copy, Debug)]
pub struct Surface<'a> {
    pub index: usize,
    pub object: &'a Object,
    pub p: DVec3,
    /// The unit normal on the side the ray came from: the outward normal
    /// when `entering`, else its opposite.
    pub nf: DVec3,
    /// Whether the ray arrived from outside the solid.
    pub entering: bool,
}

impl Surface<'_> {
    /// Whether `dir` points out of the solid: `dir · n > 0` for the outward
    /// normal `n`, evaluated as `±(dir · nf)` (negation is exact, so this is
    /// the same test to the bit).
    #[inline(always)]
    pub fn outward(&self, dir: DVec3) -> bool {
        let d = dir.dot(self.nf);
        if self.entering { d > 0.0 } else { d < 0.0 }
    }

    /// The object a ray leaving this point along `dir` cannot meet again,
    /// or `usize::MAX`. Every shape is convex, so a ray that starts on the
    /// surface and heads outward never returns to it: its test is skipped
    /// (it could only find the point itself, which the start offset is
    /// there to avoid).
    #[inline]
    pub fn leaving(&self, dir: DVec3) -> usize {
        if self.outward(dir) { self.index } else { usize::MAX }
    }
}

/// The shading data of hit `hit` of object `index` along `ray`.
#[inline(always)]
pub fn surface<'a>(scene: &'a Scene, ray: &Ray, index: usize, hit: Hit) -> Surface<'a> {
    let object = &scene.objects[index];
    let p = ray.at(hit.t);
    let n = object.world_normal(p, hit.part);
    let entering = ray.dir.dot(n) < 0.0;
    Surface {
        index,
        object,
        p,
        nf: if entering { n } else { -n },
        entering,
    }
}

/// The light's sample at the surface when the light is on the side the ray
/// came from (`None` when it lights the other side).
#[inline]
pub fn light_at(s: &Surface, light: &Light) -> Option<LightSample> {
    let ls = light.sample(s.p);
    (s.nf.dot(ls.to_light) > 0.0).then_some(ls)
}

/// `rv` to the power `shininess`: by repeated squaring for a whole
/// exponent (the usual case, within a few ulp of `powf` and several times
/// cheaper), by `powf` otherwise.
#[inline]
fn phong_lobe(rv: f64, shininess: f64) -> f64 {
    if shininess.fract() == 0.0 && shininess <= 4096.0 {
        rv.powi(shininess as i32)
    } else {
        rv.powf(shininess)
    }
}

/// Whether the light of sample `ls` can change what [`shade`] adds at the
/// surface for a ray along `dir`: a diffuse term (zero for clear glass, whose
/// opacity is zero) or a specular one (left out where `r·v` is at most the
/// object's [`Object::lobe_cos_min`], below which the lobe is under
/// [`crate::material::LOBE_FLOOR`] of its peak). Where neither is, the shadow ray
/// would not change a bit of the pixel, and a packet does not trace it (the
/// scalar kernel still does: the tests compare the two paths bit for bit).
/// The expressions are `shade`'s own.
#[inline(always)]
fn visibility_matters<const GLASS: bool, const SPECULAR: bool>(s: &Surface, ls: &LightSample, dir: DVec3) -> bool {
    let m = &s.object.material;
    let opacity = if GLASS { 1.0 - m.transparency } else { 1.0 };
    let cos = s.nf.dot(ls.to_light);
    if m.diffuse * opacity * cos != 0.0 || !ls.irradiance.is_finite() {
        return true;
    }
    SPECULAR && m.specular > 0.0 && optics::reflect(-ls.to_light, s.nf).dot(-dir) > s.object.lobe_cos_min
}

/// Light `j`'s sample at the surface and, with shadows, the transmittance
/// of the shadow ray toward it, traced alone (one without shadows).
#[inline]
fn lit_by<const SHADOWS: bool>(scene: &Scene, j: usize, s: &Surface) -> Option<(LightSample, Rgb)> {
    let ls = light_at(s, &scene.lights[j])?;
    if !(SHADOWS && scene.shadows) {
        return Some((ls, Rgb::ONE));
    }
    let (sr, dist) = shadow_ray(s, &ls);
    Some((ls, transmittance_skip(scene, &sr, dist, s.leaving(ls.to_light))))
}

/// The shadow ray from the surface toward a light, and the distance to the
/// light along it.
#[inline]
pub fn shadow_ray(s: &Surface, ls: &LightSample) -> (Ray, f64) {
    let offset = surface_offset(s.p, s.object.scale);
    let sr = spawn_ray_by(s.p, s.nf, ls.to_light, offset);
    // The origin is `offset` from the surface along a unit normal.
    let dist = if ls.distance.is_finite() {
        (ls.distance - offset).max(0.0)
    } else {
        f64::INFINITY
    };
    (sr, dist)
}

/// The radiance along `ray` given its closest hit, one ray alone: light
/// by light with a shadow ray each, then the refracted and reflected rays
/// traced at once. [`packet_kernel`] runs the same three steps over a
/// packet.
#[inline(always)]
fn shade<const SHADOWS: bool, const GLASS: bool, const MIRROR: bool, const SPECULAR: bool>(
    scene: &Scene,
    ray: &Ray,
    hit: Option<&Surface>,
    depth: u32,
    lambda_um: f64,
    weight: f64,
) -> Rgb {
    let Some(s) = hit else {
        return scene.background;
    };
    let mut color = ambient::<GLASS>(scene, s);
    for j in 0..scene.lights.len() {
        if let Some((ls, visible)) = lit_by::<SHADOWS>(scene, j, s) {
            add_light::<SHADOWS, GLASS, SPECULAR>(scene, s, ray.dir, &ls, visible, &mut color);
        }
    }
    if GLASS || MIRROR {
        shade_onward::<GLASS, MIRROR>(
            scene,
            ray.dir,
            s,
            depth,
            lambda_um,
            weight,
            &mut fresnel_at,
            &mut |s, ior| transmitted_ray(s.object, s.p, s.nf, s.entering, ray.dir, ior),
            &mut |sec, color| {
                sec.join(
                    color,
                    kernel::<SHADOWS, GLASS, MIRROR, SPECULAR>(
                        scene, &sec.ray, sec.skip, sec.depth, lambda_um, sec.weight,
                    ),
                )
            },
            &mut color,
        );
    }
    color
}

/// The ambient term at the surface: where local shading starts.
#[inline(always)]
fn ambient<const GLASS: bool>(scene: &Scene, s: &Surface) -> Rgb {
    let m = &s.object.material;
    let opacity = if GLASS { 1.0 - m.transparency } else { 1.0 };
    let mut color = Rgb::ZERO;
    color += m.color * scene.ambient * (m.ambient * opacity);
    color
}

/// Adds the Lambert and Phong terms of one light's sample `ls` at the
/// surface, for a ray along `dir`, dimmed by the transmittance `visible` of
/// its shadow ray (ignored without shadows).
#[inline(always)]
fn add_light<const SHADOWS: bool, const GLASS: bool, const SPECULAR: bool>(
    scene: &Scene,
    s: &Surface,
    dir: DVec3,
    ls: &LightSample,
    visible: Rgb,
    color: &mut Rgb,
) {
    let m = &s.object.material;
    let opacity = if GLASS { 1.0 - m.transparency } else { 1.0 };
    let cos = s.nf.dot(ls.to_light);
    let mut e = ls.irradiance;
    if SHADOWS && scene.shadows {
        e *= visible;
        if e == Rgb::ZERO {
            return;
        }
    }
    *color += m.color * e * (m.diffuse * opacity * cos);
    if SPECULAR && m.specular > 0.0 {
        let r = optics::reflect(-ls.to_light, s.nf);
        let rv = r.dot(-dir);
        if rv > s.object.lobe_cos_min {
            *color += e * (m.specular * phong_lobe(rv, m.shininess));
        }
    }
}

/// The refracted and reflected rays at the surface for a ray along `dir`,
/// `depth` bounces deep with path weight `weight`: `trace(secondary,
/// colour)` follows each and adds what it brings (the scalar kernel at
/// once, a packet after the local shading of all its lanes: the additions
/// come in the same order either way). `fresnel(dir, nf, n1, n2)` is
/// [`fresnel_at`] and `transmit(s, ior)` is [`transmitted_ray`] at
/// the surface for this ray: a packet traces the passes through a lens of
/// all its lanes together beforehand, the entry's reflectance with them.
#[inline(always)]
#[allow(clippy::too_many_arguments)] // the three callbacks are what differ between the scalar and packet kernels
fn shade_onward<const GLASS: bool, const MIRROR: bool>(
    scene: &Scene,
    dir: DVec3,
    s: &Surface,
    depth: u32,
    lambda_um: f64,
    weight: f64,
    fresnel: &mut impl FnMut(DVec3, DVec3, f64, f64) -> f64,
    transmit: &mut impl FnMut(&Surface, f64) -> Option<Transmitted>,
    trace: &mut impl FnMut(Secondary, &mut Rgb),
    color: &mut Rgb,
) {
    if depth >= scene.max_depth {
        return;
    }
    let (obj, p, nf, entering) = (s.object, s.p, s.nf, s.entering);
    let m = &obj.material;
    let mut kr = if MIRROR { m.reflectivity } else { 0.0 };
    if GLASS && m.transparency > 0.0 {
        let ior = m.ior.at(lambda_um);
        let (n1, n2) = if entering { (1.0, ior) } else { (ior, 1.0) };
        let f = fresnel(dir, nf, n1, n2);
        kr += m.transparency * f;
        let kt = m.transparency * (1.0 - f);
        if kt * weight > MIN_WEIGHT
            && let Some(tr) = transmit(s, ior)
            && depth + tr.bounces <= scene.max_depth
        {
            let w = kt * tr.factor;
            // Out of a lens, or out of a solid: the ray has left the object.
            let skip = if s.outward(tr.ray.dir) || obj.lens().is_some() {
                s.index
            } else {
                usize::MAX
            };
            trace(
                Secondary {
                    ray: tr.ray,
                    skip,
                    depth: depth + tr.bounces,
                    weight: weight * w,
                    tint: Some(m.color),
                    factor: w,
                },
                color,
            );
        }
    }
    if kr * weight > MIN_WEIGHT {
        let r = optics::reflect(dir, nf);
        trace(
            Secondary {
                ray: spawn_ray(p, nf, r, obj.scale),
                skip: s.leaving(r),
                depth: depth + 1,
                weight: weight * kr,
                tint: None,
                factor: kr,
            },
            color,
        );
    }
}

/// The ray that carries on after refraction at a hit.
#[derive(Clone, Copy, Debug)]
pub struct Transmitted {
    /// The continuing ray: inside the glass for ordinary solids, already out
    /// of the exit face for a lens.
    pub ray: Ray,
    /// Depth it used: 1 for a refraction, 1 + internal reflections + 1 for a
    /// pass through a lens.
    pub bounces: u32,
    /// Extra transmission factor (the Fresnel loss at a lens's exit face).
    pub factor: f64,
}

/// Refraction at the hit point `p` of `obj` (normal `nf` facing the incoming
/// ray of direction `dir`, index `ior`). A ray entering a lens is carried
/// through it by the lens's exact tracer ([`Lens::propagate_inside`], the
/// code behind `lensview lens trace`); other solids return the ray inside.
/// `None` under total internal reflection, or when the lens traps the ray.
pub fn transmitted_ray(obj: &Object, p: DVec3, nf: DVec3, entering: bool, dir: DVec3, ior: f64) -> Option<Transmitted> {
    let (n1, n2) = if entering { (1.0, ior) } else { (ior, 1.0) };
    let t = optics::refract(dir, nf, n1, n2)?;
    match obj.lens() {
        Some(lens) if entering => through_lens(lens, p, t, ior),
        _ => Some(Transmitted {
            ray: spawn_ray(p, nf, t, obj.scale),
            bounces: 1,
            factor: 1.0,
        }),
    }
}

/// The passes through a lens of the lanes of a packet whose surface is the
/// entry into it ([`lens_passes`]).
struct LensPasses {
    /// The lanes traced.
    lanes: u32,
    /// The traced lanes that send no ray on: totally reflected at the entry
    /// (never from air into glass), or trapped inside.
    stopped: u32,
    /// [`through_lens`]'s ray, depth used and Fresnel factor for the
    /// other traced lanes.
    pass: LensLanes,
    bounces: Lanes<u32>,
}

impl LensPasses {
    const EMPTY: LensPasses = LensPasses {
        lanes: 0,
        stopped: 0,
        pass: LensLanes {
            reflected: [false; LANES],
            entry_fresnel: [0.0; LANES],
            ok: [false; LANES],
            inside: [[0.0; LANES]; 3],
            origin: [[0.0; LANES]; 3],
            dir: [[0.0; LANES]; 3],
            factor: [0.0; LANES],
        },
        bounces: [0; LANES],
    };

    /// [`transmitted_ray`] for traced lane `l`.
    #[inline(always)]
    fn transmitted(&self, l: usize) -> Option<Transmitted> {
        let pass = &self.pass;
        (self.stopped >> l & 1 == 0).then(|| Transmitted {
            ray: Ray {
                origin: DVec3::new(pass.origin[0][l], pass.origin[1][l], pass.origin[2][l]),
                dir: DVec3::new(pass.dir[0][l], pass.dir[1][l], pass.dir[2][l]),
            },
            bounces: self.bounces[l],
            factor: pass.factor[l],
        })
    }
}

/// [`transmitted_ray`] for the lanes whose surface is the entry into a lens
/// (the first such lens; lanes on another take the scalar path), with the
/// Fresnel reflectance at each traced lane's entry (what [`shade_onward`]
/// weighs the pass with). The whole pass runs over the lanes at once
/// ([`lens_lanes`]); a lane that reflects inside is traced by the scalar
/// [`through_lens`]. The passes are written to `out` (working memory kept
/// from packet to packet); `false` when no lane enters a lens.
#[inline(always)]
fn lens_passes(rays: &Packet, surfaces: &[Option<Surface>; LANES], lambda_um: f64, out: &mut LensPasses) -> bool {
    // The lens (its object index, shape and index of refraction there).
    let mut which: Option<(usize, &Lens, f64)> = None;
    let mut lanes = 0u32;
    let mut x = [[0.0; LANES]; 3];
    let mut nf = [[0.0; LANES]; 3];
    for l in 0..LANES {
        let Some(s) = &surfaces[l] else { continue };
        let Some(lens) = s.object.lens() else { continue };
        if !s.entering || s.object.material.transparency <= 0.0 || which.is_some_and(|(i, ..)| i != s.index) {
            continue;
        }
        which.get_or_insert((s.index, lens, s.object.material.ior.at(lambda_um)));
        lanes |= 1 << l;
        for k in 0..3 {
            x[k][l] = s.p[k];
            nf[k][l] = s.nf[k];
        }
    }
    let Some((_, lens, ior)) = which else {
        return false;
    };
    // Lanes outside `lanes` repeat a traced lane, so that every lane holds
    // numbers (their results are not read).
    let first = lanes.trailing_zeros() as usize;
    let mut dir = *rays.dirs();
    for l in 0..LANES {
        if lanes >> l & 1 == 0 {
            for k in 0..3 {
                x[k][l] = x[k][first];
                nf[k][l] = nf[k][first];
                dir[k][l] = dir[k][first];
            }
        }
    }
    out.pass = lens_lanes(lens, ior, &x, &dir, &nf);
    let LensPasses {
        pass, stopped, bounces, ..
    } = out;
    *stopped = 0;
    *bounces = [2; LANES];
    for l in live_lanes(lanes) {
        if pass.reflected[l] {
            *stopped |= 1 << l;
        } else if !pass.ok[l] {
            let p = DVec3::new(x[0][l], x[1][l], x[2][l]);
            let t = DVec3::new(pass.inside[0][l], pass.inside[1][l], pass.inside[2][l]);
            match through_lens(lens, p, t, ior) {
                Some(tr) => {
                    for k in 0..3 {
                        pass.origin[k][l] = tr.ray.origin[k];
                        pass.dir[k][l] = tr.ray.dir[k];
                    }
                    pass.factor[l] = tr.factor;
                    bounces[l] = tr.bounces;
                }
                None => *stopped |= 1 << l,
            }
        }
    }
    out.lanes = lanes;
    true
}

/// Passes through a lens of a packet's lanes ([`lens_lanes`]).
struct LensLanes {
    /// Totally reflected at the entry.
    reflected: Lanes<bool>,
    /// The Fresnel reflectance at the entry.
    entry_fresnel: Lanes<f64>,
    /// Refracted in, and out at the first exit: `origin`, `dir` and
    /// `factor` are [`through_lens`]'s ray and Fresnel factor.
    ok: Lanes<bool>,
    /// The direction inside after the entry refraction.
    inside: [Lanes<f64>; 3],
    origin: [Lanes<f64>; 3],
    dir: [Lanes<f64>; 3],
    factor: Lanes<f64>,
}

/// [`transmitted_ray`] into `lens` (index `ior`) at the entry points `x`
/// (normals `nf`, facing the rays of directions `dir`) for every lane at
/// once, step by step over all lanes so that they run side by side in SIMD
/// registers: the entry refraction ([`optics::refract`]), the pass to the
/// exit ([`Lens::exit_lanes`]) and the ray out with its Fresnel factor
/// ([`leaving_lens`]), each lane with exactly the scalar arithmetic, so
/// that it gets the scalar ray bit for bit.
#[inline(always)]
fn lens_lanes_impl(
    lens: &Lens,
    ior: f64,
    x: &[Lanes<f64>; 3],
    dir: &[Lanes<f64>; 3],
    nf: &[Lanes<f64>; 3],
) -> LensLanes {
    let lane = |v: &[Lanes<f64>; 3], l: usize| DVec3::new(v[0][l], v[1][l], v[2][l]);
    let mut reflected = [false; LANES];
    let mut inside = [[0.0; LANES]; 3];
    let mut entry_fresnel = [0.0; LANES];
    // `optics::refract(dir, nf, 1.0, ior)`, and `shade_onward`'s Fresnel
    // reflectance (`optics::fresnel_at`), from one crossing.
    for l in 0..LANES {
        let c = optics::crossing(lane(dir, l), lane(nf, l), 1.0, ior);
        reflected[l] = c.total;
        entry_fresnel[l] = c.reflectance;
        for (k, inside) in inside.iter_mut().enumerate() {
            inside[l] = c.dir[k];
        }
    }
    let e = lens.exit_lanes(x, &inside, ior);
    let mut origin = [[0.0; LANES]; 3];
    let mut out_dir = [[0.0; LANES]; 3];
    let mut factor = [0.0; LANES];
    // `leaving_lens` of the exit.
    for l in 0..LANES {
        let (y, out, n) = (lane(&e.y, l), lane(&e.out, l), lane(&e.normal, l));
        let ray = spawn_ray(y, n, out, lens.d);
        factor[l] = 1.0 - e.reflectance[l];
        for k in 0..3 {
            origin[k][l] = ray.origin[k];
            out_dir[k][l] = ray.dir[k];
        }
    }
    let mut ok = e.ok;
    for l in 0..LANES {
        ok[l] &= !reflected[l];
    }
    LensLanes {
        reflected,
        entry_fresnel,
        ok,
        inside,
        origin,
        dir: out_dir,
        factor,
    }
}

with_avx2! {
    /// [`lens_lanes_impl`], built for AVX2 where the CPU has it.
    fn lens_lanes / lens_lanes_avx2 => lens_lanes_impl(
        lens: &Lens,
        ior: f64,
        x: &[Lanes<f64>; 3],
        dir: &[Lanes<f64>; 3],
        nf: &[Lanes<f64>; 3]
    ) -> LensLanes
}

/// Follows a ray that has just refracted into `lens` at `p` to its exit.
fn through_lens(lens: &Lens, p: DVec3, inside: DVec3, ior: f64) -> Option<Transmitted> {
    let path = lens.propagate_inside(p, inside, ior);
    match (path.status, path.exit, path.exit_crossing) {
        (LensTraceStatus::Transmitted, Some((_, y, out)), Some(c)) => {
            Some(leaving_lens(lens, y, out, c, path.internal_reflections))
        }
        _ => None,
    }
}

/// The ray out of `lens` from the exit point `y` along `out`, and what its
/// exit crossing `c` lets through.
fn leaving_lens(lens: &Lens, y: DVec3, out: DVec3, c: ExitCrossing, reflections: u32) -> Transmitted {
    Transmitted {
        ray: spawn_ray(y, c.normal, out, lens.d),
        bounces: 2 + reflections,
        // The Fresnel loss at the exit face.
        factor: 1.0 - c.reflectance,
    }
}

/// The shading point data of the closest hit, for tools and tests.
pub fn hit_point<'a>(scene: &'a Scene, ray: &Ray) -> Option<(&'a Object, DVec3, DVec3)> {
    let (i, h) = closest_hit(scene, ray, f64::INFINITY)?;
    let o = &scene.objects[i];
    let p = ray.at(h.t);
    Some((o, p, o.world_normal(p, h.part)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Sampler;

    /// Eight vectors, structure of arrays.
    type V = [Lanes<f64>; 3];

    /// Lanes of rays that enter the default scene's lens at random points
    /// from random directions: entry points, facing normals, directions.
    fn entries(scene: &Scene, seed: u64) -> Vec<(V, V, V)> {
        let (index, lens) = scene
            .objects
            .iter()
            .enumerate()
            .find_map(|(i, o)| o.lens().map(|l| (i, l)))
            .expect("the default scene has a lens");
        let mut s = Sampler::new(seed, 0, 0);
        let mut out = Vec::new();
        let mut lanes = ([[0.0; LANES]; 3], [[0.0; LANES]; 3], [[0.0; LANES]; 3]);
        let mut l = 0;
        while out.len() < 2000 {
            let mut v = || DVec3::new(s.next_f64(), s.next_f64(), s.next_f64()) - 0.5;
            let org = lens.center + v() * 8.0 * lens.d;
            let aim = lens.center + v() * 1.2 * lens.d;
            let ray = Ray::new(org, aim - org);
            let Some(h) = lens.intersect(&ray, 0.0, f64::INFINITY) else {
                continue;
            };
            let srf = surface(scene, &ray, index, h);
            if !srf.entering {
                continue;
            }
            for k in 0..3 {
                lanes.0[k][l] = srf.p[k];
                lanes.1[k][l] = srf.nf[k];
                lanes.2[k][l] = ray.dir[k];
            }
            l += 1;
            if l == LANES {
                out.push(lanes);
                l = 0;
            }
        }
        out
    }

    /// Both builds of the lane pass (AVX2 where the CPU has it, and the
    /// portable one) give every lane the scalar `transmitted_ray`, bit for
    /// bit, and leave to the scalar code only the lanes that reflect inside.
    #[test]
    fn lens_lanes_give_the_scalar_pass() {
        let scene = Scene::default_scene().1;
        let obj = scene.objects.iter().find(|o| o.lens().is_some()).expect("a lens");
        let lens = obj.lens().expect("a lens");
        let ior = obj.material.ior.at(crate::optics::WAVELENGTH_D_UM);
        let (mut exact, mut scalar) = (0, 0);
        for (x, nf, dir) in entries(&scene, 3) {
            for pass in [
                lens_lanes(lens, ior, &x, &dir, &nf),
                lens_lanes_impl(lens, ior, &x, &dir, &nf),
            ] {
                for l in 0..LANES {
                    let at = |v: &V| DVec3::new(v[0][l], v[1][l], v[2][l]);
                    let want = transmitted_ray(obj, at(&x), at(&nf), true, at(&dir), ior);
                    assert!(!pass.reflected[l], "air to glass never reflects totally");
                    let f = fresnel_at(at(&dir), at(&nf), 1.0, ior);
                    assert_eq!(pass.entry_fresnel[l], f, "shade_onward's reflectance");
                    if !pass.ok[l] {
                        scalar += 1;
                        let t = optics::refract(at(&dir), at(&nf), 1.0, ior).expect("refracts");
                        assert_eq!(t, at(&pass.inside));
                        let path = lens.propagate_inside(at(&x), t, ior);
                        assert!(path.internal_reflections > 0 || path.status != LensTraceStatus::Transmitted);
                        continue;
                    }
                    exact += 1;
                    let want = want.expect("a plain pass leaves the lens");
                    assert_eq!(want.ray.origin, at(&pass.origin));
                    assert_eq!(want.ray.dir, at(&pass.dir));
                    assert_eq!(want.factor, pass.factor[l]);
                    assert_eq!(want.bounces, 2);
                }
            }
        }
        assert!(
            exact > 20_000 && scalar > 50,
            "{exact} exact lanes, {scalar} left to the scalar code"
        );
    }
}
