//! The pass through a lens: one ray's ([`transmitted_ray`]: refraction
//! in, the lens's exact tracer inside, the ray out) and that of the lanes
//! of a packet that enter a lens together (`lens_passes`), which runs the
//! same steps over all lanes at once (`optics::crossing` in,
//! `Lens::exit_lanes` through, `leaving` out) and hands the few lanes
//! that reflect inside to the scalar pass.

// Lane loops index several arrays by the lane: the form the vectoriser wants.
#![allow(clippy::needless_range_loop)]

use super::surface::{Surface, spawn_ray};
use crate::geometry::{ExitCrossing, Lens, LensTraceStatus};
use crate::math::Ray;
use crate::optics;
use crate::scene::Object;
use crate::simd::{LANES, Lanes, lane, live_lanes, set_lane, with_avx2};
use crate::trace::Packet;
use glam::DVec3;

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
pub(super) struct LensPasses {
    /// The lanes traced.
    pub(super) lanes: u32,
    /// The traced lanes that send no ray on: totally reflected at the entry
    /// (never from air into glass), or trapped inside.
    stopped: u32,
    /// [`through_lens`]'s ray, depth used and Fresnel factor for the
    /// other traced lanes.
    pub(super) pass: LensLanes,
    bounces: Lanes<u32>,
}

impl LensPasses {
    pub(super) const EMPTY: LensPasses = LensPasses {
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
    pub(super) fn transmitted(&self, l: usize) -> Option<Transmitted> {
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
/// Fresnel reflectance at each traced lane's entry (what `shade_onward`
/// weighs the pass with). The whole pass runs over the lanes at once
/// ([`lens_lanes`]); a lane that reflects inside is traced by the scalar
/// [`through_lens`]. The passes are written to `out` (working memory kept
/// from packet to packet); `false` when no lane enters a lens.
#[inline(always)]
pub(super) fn lens_passes(
    rays: &Packet,
    surfaces: &[Option<Surface>; LANES],
    lambda_um: f64,
    out: &mut LensPasses,
) -> bool {
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
pub(super) struct LensLanes {
    /// Totally reflected at the entry.
    reflected: Lanes<bool>,
    /// The Fresnel reflectance at the entry.
    pub(super) entry_fresnel: Lanes<f64>,
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
    let mut reflected = [false; LANES];
    let mut inside = [[0.0; LANES]; 3];
    let mut entry_fresnel = [0.0; LANES];
    // `optics::refract(dir, nf, 1.0, ior)`, and `shade_onward`'s Fresnel
    // reflectance (`optics::fresnel_at`), from one crossing.
    for l in 0..LANES {
        let c = optics::crossing(lane(dir, l), lane(nf, l), 1.0, ior);
        reflected[l] = c.total;
        entry_fresnel[l] = c.reflectance;
        set_lane(&mut inside, l, c.dir);
    }
    let e = lens.exit_lanes(x, &inside, ior);
    let mut origin = [[0.0; LANES]; 3];
    let mut out_dir = [[0.0; LANES]; 3];
    let mut factor = [0.0; LANES];
    for l in 0..LANES {
        let (ray, f) = leaving(
            lens,
            lane(&e.y, l),
            lane(&e.out, l),
            lane(&e.normal, l),
            e.reflectance[l],
        );
        set_lane(&mut origin, l, ray.origin);
        set_lane(&mut out_dir, l, ray.dir);
        factor[l] = f;
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
    let (ray, factor) = leaving(lens, y, out, c.normal, c.reflectance);
    Transmitted {
        ray,
        bounces: 2 + reflections,
        factor,
    }
}

/// The exit step of a pass, one ray's or one lane's: the ray out of `lens`
/// from the exit point `y` along `out`, spawned off the face of outward
/// normal `normal`, and the share of the light the crossing lets through
/// (the Fresnel loss at the exit face, of reflectance `reflectance`).
#[inline(always)]
fn leaving(lens: &Lens, y: DVec3, out: DVec3, normal: DVec3, reflectance: f64) -> (Ray, f64) {
    (spawn_ray(y, normal, out, lens.d), 1.0 - reflectance)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::surface;
    use crate::optics::fresnel_at;
    use crate::sampling::Sampler;
    use crate::scene::Scene;

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
