//! The packet kernel's local shading ([`local_shading`], [`add_light_lanes`]):
//! the lanes' surfaces kept as structure of arrays as well
//! ([`SurfaceLanes`]), so that the steps of `shade.rs` that read only
//! numbers (a light's sample, whether a shadow ray matters, the ray, the
//! Lambert term, the cosine of the Phong lobe) run as lane loops, which
//! the AVX2 build of the kernel turns into vector instructions. Each lane
//! gets the scalar kernel's arithmetic, in its order.

// Lane loops index several arrays by the lane: the form the vectoriser wants.
#![allow(clippy::needless_range_loop)]

use super::Lit;
use super::PacketPaths;
#[cfg(doc)]
use super::shade::ambient;
use super::shade::{
    ambient_light, arriving, caustic_term, diffuse_share, faces, gathers_caustics, lambert, light_matters, lobe_cos,
    phong, reads_surface,
};
use super::surface::{Surface, outward, shadow_ray_from, surface};
use crate::color::Rgb;
use crate::light::{Light, LightLanes};
use crate::photon::{PhotonMap, Queries};

use crate::simd::{LANES, Lanes, lane, live_lanes, mask, set_lane};
use crate::trace::{NO_OBJECT, Packet, lane_object, transmittances};

/// The lanes' surfaces as structure of arrays, for the lane loops of
/// [`add_light_lanes`]: which lanes hit (`hit`, a bit mask), and each one's
/// point and normal ([`Surface::p`], [`Surface::nf`]), side and object
/// ([`Surface::entering`], [`Surface::index`]) and what shading reads of
/// its object: `kd_ks_lobe` ([`diffuse_share`], `specular`,
/// `lobe_cos_min`), `color`, `shininess`, `scale`. Kept in the packet
/// kernel's scratch: a lane without a surface holds what an earlier
/// packet left there, which the lane loops compute on and the masks drop.
pub(super) struct SurfaceLanes {
    hit: u32,
    p: [Lanes<f64>; 3],
    nf: [Lanes<f64>; 3],
    entering: Lanes<bool>,
    index: Lanes<u32>,
    kd_ks_lobe: [Lanes<f64>; 3],
    color: [Lanes<f64>; 3],
    shininess: Lanes<f64>,
    scale: Lanes<f64>,
}

impl SurfaceLanes {
    pub(super) const EMPTY: SurfaceLanes = SurfaceLanes {
        hit: 0,
        p: [[0.0; LANES]; 3],
        nf: [[0.0; LANES]; 3],
        entering: [false; LANES],
        index: [0; LANES],
        kd_ks_lobe: [[0.0; LANES]; 3],
        color: [[0.0; LANES]; 3],
        shininess: [0.0; LANES],
        scale: [0.0; LANES],
    };

    /// Sets lane `l` to the surface `s`.
    #[inline(always)]
    fn set<const GLASS: bool>(&mut self, l: usize, s: &Surface) {
        let (m, o) = (&s.object.material, s.object);
        set_lane(&mut self.p, l, s.p);
        set_lane(&mut self.nf, l, s.nf);
        self.entering[l] = s.entering;
        self.index[l] = lane_object(s.index);
        self.kd_ks_lobe[0][l] = diffuse_share::<GLASS>(m);
        self.kd_ks_lobe[1][l] = m.specular;
        self.kd_ks_lobe[2][l] = o.lobe_cos_min;
        set_lane(&mut self.color, l, m.color);
        self.shininess[l] = m.shininess;
        self.scale[l] = o.scale;
        self.hit |= 1 << l;
    }
}

/// Each live lane's surface (in `surfaces`, and in `at`) and [`ambient`]
/// term, or the background where its ray escapes (in `out`); whether any
/// lane has a surface (in a scene without lights or caustic photons, a
/// lane whose shading is its ambient light alone, [`reads_surface`], gets
/// none: its radiance is complete).
#[inline(always)]
pub(super) fn local_shading<'s, const GLASS: bool, const MIRROR: bool>(
    scene: Lit<'s>,
    paths: &PacketPaths,
    surfaces: &mut [Option<Surface<'s>>; LANES],
    at: &mut SurfaceLanes,
    out: &mut Lanes<Rgb>,
) -> bool {
    // Two builds of the loop, so that a lit scene's is the loop without
    // the tests for ambient light alone.
    if scene.lights.is_empty() && scene.caustics.is_none() {
        local_lanes::<GLASS, MIRROR, true>(scene, paths, surfaces, at, out)
    } else {
        local_lanes::<GLASS, MIRROR, false>(scene, paths, surfaces, at, out)
    }
}

/// [`local_shading`] in a scene with no lights and no caustic photons
/// (`BARE`) or with some.
#[inline(always)]
fn local_lanes<'s, const GLASS: bool, const MIRROR: bool, const BARE: bool>(
    scene: Lit<'s>,
    paths: &PacketPaths,
    surfaces: &mut [Option<Surface<'s>>; LANES],
    at: &mut SurfaceLanes,
    out: &mut Lanes<Rgb>,
) -> bool {
    *out = [Rgb::ZERO; LANES];
    at.hit = 0;
    for l in 0..LANES {
        if paths.active >> l & 1 == 0 {
            continue;
        }
        match paths.hits.get(l) {
            // A surface whose shading is its ambient light alone needs no
            // point, normal or side: it gets no `Surface`, so nothing after
            // looks at the lane.
            Some((i, _)) if BARE && !reads_surface::<GLASS, MIRROR>(scene, &scene.objects[i].material) => {
                out[l] = ambient_light::<GLASS>(scene, &scene.objects[i].material);
            }
            Some((i, h)) => {
                let s = surface(scene.scene, &paths.rays.ray(l), i, h);
                // [`ambient`] less its caustic term (none when `BARE`),
                // which [`add_caustics_lanes`] adds to the lanes at once.
                out[l] = ambient_light::<GLASS>(scene, &s.object.material);
                if BARE {
                    // Only [`add_light_lanes`] reads the lane arrays:
                    // without lights, the bit mask is all that is kept.
                    at.hit |= 1 << l;
                } else {
                    at.set::<GLASS>(l, &s);
                }
                surfaces[l] = Some(s);
            }
            None => out[l] = scene.background,
        }
    }
    if !BARE && let Some(map) = scene.caustics {
        add_caustics_lanes(&scene, map, at, out);
    }
    at.hit != 0
}

/// Adds [`ambient`]'s caustic term ([`caustic_term`]) to the lanes of
/// `at` where [`ambient`] gathers ([`gathers_caustics`]), their
/// irradiance gathered as one packet
/// (`PhotonMap::irradiance_lanes`). Out of line, and after the lane loop
/// rather than in it: a gather called in the loop slowed the kernel's
/// frames without caustics by 6 % (cubes, task-clock of 8 paired runs).
#[inline(never)]
fn add_caustics_lanes(scene: &Lit, map: &PhotonMap, at: &SurfaceLanes, out: &mut Lanes<Rgb>) {
    let kd = &at.kd_ks_lobe[0];
    let diffuse: Lanes<bool> = std::array::from_fn(|l| gathers_caustics(kd[l]) && scene.gathers(l));
    let gather = at.hit & mask(&diffuse);
    if gather == 0 {
        return;
    }
    let e = map.irradiance_lanes(Queries {
        x: &at.p,
        n: &at.nf,
        live: gather,
    });
    for l in live_lanes(gather) {
        out[l] += caustic_term(lane(&at.color, l), scene.counted_lane(e[l], l), kd[l]);
    }
}

/// [`super::shade::add_light`] of `light` at every lane's surface (`at`),
/// its shadow rays a packet (`shadow`, working memory), as lane loops: the
/// light's samples ([`super::shade::light_at`]), the shadow rays that
/// matter ([`light_matters`], [`shadow_ray_from`]), the Lambert terms and
/// the lobe cosines; the Phong terms lane by lane where the lobe is on.
#[inline(always)]
pub(super) fn add_light_lanes<const SHADOWS: bool, const GLASS: bool, const SPECULAR: bool>(
    scene: Lit,
    p: &Packet,
    at: &SurfaceLanes,
    light: &Light,
    shadow: &mut Packet,
    out: &mut Lanes<Rgb>,
) {
    let mut samples = LightLanes::EMPTY;
    light.sample_lanes(&at.p, &mut samples);
    let mut facing = [false; LANES];
    for l in 0..LANES {
        facing[l] = faces(lane(&at.nf, l), &samples.get(l));
    }
    // The lanes lit: those that hit a surface on the light's side.
    let lit = mask(&facing) & at.hit;
    if lit == 0 {
        // No lane gets anything of this light.
        return;
    }
    let shadows = SHADOWS && scene.shadows;
    let mut vis = [Rgb::ONE; LANES];
    if shadows {
        // The lanes that trace their shadow ray are those lit where it
        // matters (`fill_unused` sets the others).
        let mut matters = [false; LANES];
        let mut skip = [NO_OBJECT; LANES];
        for l in 0..LANES {
            let (ls, nf) = (samples.get(l), lane(&at.nf, l));
            let kd_ks_lobe = [at.kd_ks_lobe[0][l], at.kd_ks_lobe[1][l], at.kd_ks_lobe[2][l]];
            matters[l] = light_matters::<SPECULAR>(kd_ks_lobe, nf, &ls, p.dir(l));
            let (r, t_max) = shadow_ray_from(lane(&at.p, l), nf, at.scale[l], &ls);
            shadow.set(l, &r, t_max);
            // [`Surface::leaving`].
            skip[l] = if outward(at.entering[l], nf, ls.to_light) {
                at.index[l]
            } else {
                NO_OBJECT
            };
        }
        let live = mask(&matters) & lit;
        if live != 0 {
            shadow.fill_unused(live);
            vis = transmittances(scene.scene, shadow, &skip);
        }
    }
    // [`super::shade::add_light`]'s steps: the light that arrives (none
    // where the shadow ray found nothing), the Lambert term, then the
    // Phong term where the lobe is on.
    let mut e = [Rgb::ZERO; LANES];
    let mut on = [false; LANES];
    let mut rv = [0.0; LANES];
    let mut lobe = [false; LANES];
    for l in 0..LANES {
        let (ls, nf) = (samples.get(l), lane(&at.nf, l));
        let (arrived, arrives) = arriving(shadows, &ls, vis[l]);
        on[l] = lit >> l & 1 != 0 && arrives;
        e[l] = arrived;
        let term = lambert(lane(&at.color, l), e[l], at.kd_ks_lobe[0][l], nf, &ls);
        out[l] = if on[l] { out[l] + term } else { out[l] };
        rv[l] = lobe_cos(nf, &ls, p.dir(l));
        lobe[l] = at.kd_ks_lobe[1][l] > 0.0 && rv[l] > at.kd_ks_lobe[2][l];
    }
    if SPECULAR {
        for l in live_lanes(mask(&on) & mask(&lobe)) {
            out[l] += phong(e[l], at.kd_ks_lobe[1][l], rv[l], at.shininess[l]);
        }
    }
}
