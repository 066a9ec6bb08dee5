//! The pass through a lens: one ray's (`refraction::transmitted_rays`: refraction
//! in, the lens's Whitted tree inside, [`Lens::branches_inside`], every ray
//! out weighted by Fresnel) and that of the lanes of a packet that enter a
//! lens together (`lens_passes`), which runs the first two exits of all
//! lanes at once (`optics::crossing` in, `Lens::exit_lanes` through,
//! `leaving` out, the reflection on and the second exit) and goes on from
//! there lane by lane with the scalar steps ([`Lens::reflect_inside`],
//! [`Lens::branch_chain`]); a lane that reflects totally goes on with the
//! scalar chain from there.

// Lane loops index several arrays by the lane: the form the vectoriser wants.
#![allow(clippy::needless_range_loop)]

#[cfg(test)]
use super::refraction::transmitted_rays;
use super::surface::{Surface, spawn_ray};
use crate::geometry::{Inside, LaneExits, Lens, LensBranch, Pruning};
use crate::math::Ray;
use crate::optics;
use crate::simd::{LANES, Lanes, lane, set_lane, with_avx2};
use crate::trace::Packet;
use glam::DVec3;

/// A ray that carries on after refraction at a hit.
#[derive(Clone, Copy, Debug)]
pub struct Transmitted {
    /// The continuing ray: inside the glass for ordinary solids, already out
    /// of an exit face for a lens.
    pub ray: Ray,
    /// Depth it used: 1 for a refraction, 1 + reflections inside + 1 for a
    /// ray out of a lens.
    pub bounces: u32,
    /// Extra transmission factor: for a ray out of a lens, its branch's
    /// weight ([`LensBranch::weight`]: the Fresnel factors inside).
    pub factor: f64,
}

/// The ray of a branch out of `lens`.
#[inline(always)]
pub(super) fn out_of(lens: &Lens, b: &LensBranch) -> Transmitted {
    Transmitted {
        ray: leaving(lens, b.point, b.dir, b.normal),
        bounces: 2 + b.reflections,
        factor: b.weight,
    }
}

/// The passes through a lens of the lanes of a packet whose surface is the
/// entry into it ([`lens_passes`]).
pub(super) struct LensPasses {
    /// The lanes traced.
    pub(super) lanes: u32,
    /// The first two exits of each traced lane.
    pub(super) pass: LensLanes,
    /// Each lane's entry point, facing normal and direction there (lanes
    /// not traced repeat a traced one).
    pub(super) x: [Lanes<f64>; 3],
    pub(super) nf: [Lanes<f64>; 3],
    pub(super) dir: [Lanes<f64>; 3],
}

/// What a pass's first two exits do with traced lane `l`'s light, from the
/// lanes ([`LensPasses::finished`]).
pub(super) struct Finished {
    /// The lanes end the lane's tree: no reflection at the entry, the first
    /// exit a refraction, and the light reflected on there either dropped
    /// or leaving by refraction at the second exit and dropped after it.
    /// Where not, [`LensPasses::walk`] and the scalar [`chain`] take it.
    pub(super) done: bool,
    /// The weight of the ray out at each exit.
    pub(super) out: [f64; 2],
    /// Whether it is kept (the second: the light reflected on to it too).
    pub(super) kept: [bool; 2],
}

impl LensPasses {
    pub(super) const EMPTY: LensPasses = LensPasses {
        lanes: 0,
        pass: LensLanes {
            reflected: [false; LANES],
            entry_fresnel: [0.0; LANES],
            inside: [[0.0; LANES]; 3],
            on: [[0.0; LANES]; 3],
            exits: [LaneExit::EMPTY; 2],
        },
        x: [[0.0; LANES]; 3],
        nf: [[0.0; LANES]; 3],
        dir: [[0.0; LANES]; 3],
    };

    /// [`LensPasses::walk`]'s weights for traced lane `l` where the lanes
    /// end its tree (`done`), with no branch on the lane's values: the
    /// steps of the walk ([`Inside::out_weight`], [`Pruning::keeps`],
    /// [`Inside::on_weight`], [`Pruning::keeps_on`]) at both exits.
    #[inline(always)]
    pub(super) fn finished(&self, l: usize, prune: &Pruning) -> Finished {
        let [first, second] = &self.pass.exits;
        let start = Inside {
            x: DVec3::ZERO,
            u: DVec3::ZERO,
            weight: 1.0,
            reflections: 0,
        };
        let r = [first.exit.reflectance[l], second.exit.reflectance[l]];
        let on = Inside {
            weight: start.on_weight(r[0]),
            reflections: 1,
            ..start
        };
        let on_kept = prune.keeps_on(on.weight, start.reflections);
        let beyond = prune.keeps_on(on.on_weight(r[1]), on.reflections);
        let out = [start.out_weight(r[0]), on.out_weight(r[1])];
        // `ok` at the first exit holds no reflection at the entry; at the
        // second, the first's `ok`.
        Finished {
            done: first.exit.ok[l] & (!on_kept | (second.exit.ok[l] & !beyond)),
            out,
            kept: [prune.keeps(out[0]), on_kept & prune.keeps(out[1])],
        }
    }

    /// Traced lane `l`'s ray out at exit `k` (0 or 1), and the bounces it
    /// uses ([`Transmitted::bounces`]: `k` reflections inside).
    #[inline(always)]
    pub(super) fn ray_out(&self, k: usize, l: usize, factor: f64) -> Transmitted {
        let ex = &self.pass.exits[k];
        Transmitted {
            ray: Ray {
                origin: lane(&ex.origin, l),
                dir: lane(&ex.dir, l),
            },
            bounces: 2 + k as u32,
            factor,
        }
    }

    /// `transmitted_rays` for traced lane `l` (into `lens` at `p`, index
    /// `ior`): [`Lens::branches_inside`]'s loop, its first two exits taken
    /// from the lanes where they leave by refraction ([`LensPasses::walk`]),
    /// the rest (and a lane that reflects totally) from the scalar chain.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)] // the lane, its entry, the bound and the sink
    #[cfg(test)]
    pub(super) fn transmitted(
        &self,
        l: usize,
        lens: &Lens,
        p: DVec3,
        ior: f64,
        prune: &Pruning,
        mut emit: impl FnMut(Transmitted),
    ) {
        if let Some(on) = self.walk(l, lens, p, prune, &mut emit) {
            chain(lens, on, ior, prune, emit);
        }
    }

    /// The rays out of traced lane `l` (into `lens` at `p`) at its first
    /// two exits, taken from the lanes, handed to `emit` in order; where the
    /// tree goes on past them (or the lane reflects totally at one), the
    /// light inside there, for [`chain`].
    #[inline(always)]
    pub(super) fn walk(
        &self,
        l: usize,
        lens: &Lens,
        p: DVec3,
        prune: &Pruning,
        emit: &mut impl Sink,
    ) -> Option<Inside> {
        let pass = &self.pass;
        if pass.reflected[l] {
            return None;
        }
        let mut on = Inside {
            x: p - lens.center,
            u: lane(&pass.inside, l),
            weight: 1.0,
            reflections: 0,
        };
        for (k, ex) in pass.exits.iter().enumerate() {
            if !ex.exit.ok[l] {
                return Some(on);
            }
            let out = on.out_weight(ex.exit.reflectance[l]);
            if prune.keeps(out) {
                emit.send(self.ray_out(k, l, out));
            }
            // After the first exit, the direction on is the lanes' own.
            let (y, u) = (lane(&ex.exit.local, l), on.u);
            let dir = || match k {
                0 => lane(&pass.on, l),
                _ => Lens::reflected_inside(u, lane(&ex.exit.normal, l)),
            };
            Lens::reflect_on(&mut on, y, ex.exit.reflectance[l], prune, dir).ok()?;
        }
        Some(on)
    }
}

/// Where a pass hands its rays out ([`LensPasses::walk`]): any closure, or
/// a kernel's own sink whose `send` is compiled into the walk.
pub(super) trait Sink {
    fn send(&mut self, tr: Transmitted);
}

impl<F: FnMut(Transmitted)> Sink for F {
    #[inline(always)]
    fn send(&mut self, tr: Transmitted) {
        self(tr)
    }
}

/// The rays out of `lens` (index `ior`) from the light inside `on` on, by
/// the scalar chain ([`Lens::branch_chain`]), handed to `emit` in order.
/// Inlined, so that it is compiled into the build of its caller
/// (`lens_send::chain_on`'s).
#[inline(always)]
pub(super) fn chain(lens: &Lens, on: Inside, ior: f64, prune: &Pruning, mut emit: impl FnMut(Transmitted)) {
    lens.branch_chain(on, ior, prune, &mut |b| emit(out_of(lens, &b)));
}

/// The first exits from a lens of the lanes whose surface is the entry into
/// it (the first such lens; lanes on another take the scalar path), with
/// the Fresnel reflectance at each traced lane's entry (what `shade_onward`
/// weighs the pass with), all lanes at once ([`lens_lanes`]). The passes
/// are written to `out` (working memory kept from packet to packet);
/// `false` when no lane enters a lens.
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
    let LensPasses { x, nf, dir, .. } = out;
    for l in 0..LANES {
        let Some(s) = &surfaces[l] else { continue };
        let Some(lens) = s.object.lens() else { continue };
        // A lane whose entry needs the lens-local arithmetic
        // (`Lens::entry_of_hit`) takes the scalar path.
        if !s.entering
            || s.object.material.transparency <= 0.0
            || which.is_some_and(|(i, ..)| i != s.index)
            || !lens.world_is_exact(rays.ray(l).origin)
        {
            continue;
        }
        which.get_or_insert((s.index, lens, lens.index.at(lambda_um)));
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
    *dir = *rays.dirs();
    for l in 0..LANES {
        if lanes >> l & 1 == 0 {
            for k in 0..3 {
                x[k][l] = x[k][first];
                nf[k][l] = nf[k][first];
                dir[k][l] = dir[k][first];
            }
        }
    }
    lens_lanes(lens, ior, x, dir, nf, &mut out.pass);
    out.lanes = lanes;
    true
}

/// `transmitted_rays` at lane `l`'s surface `s` (index `ior`) of the
/// packet `rays`: from the lanes' passes (`passes`, where [`lens_passes`]
/// traced the lane), else the scalar pass: the steps the packet kernel
/// takes (`send_through_lens` walks the lanes' exits, then [`chain`]).
#[inline(always)]
#[allow(clippy::too_many_arguments)] // the lane, its surface, the bound and the sink
#[cfg(test)]
pub(super) fn lane_transmitted(
    passes: Option<&LensPasses>,
    rays: &Packet,
    l: usize,
    s: &Surface,
    ior: f64,
    prune: &Pruning,
    emit: &mut dyn FnMut(Transmitted),
) {
    match (passes, s.object.lens()) {
        (Some(ps), Some(lens)) => ps.transmitted(l, lens, s.p, ior, prune, emit),
        _ => transmitted_rays(s.object, s.p, s.nf, s.entering, &rays.ray(l), ior, prune, emit),
    }
}

/// First exits from a lens of a packet's lanes ([`lens_lanes`]).
pub(super) struct LensLanes {
    /// Totally reflected at the entry.
    reflected: Lanes<bool>,
    /// The Fresnel reflectance at the entry.
    pub(super) entry_fresnel: Lanes<f64>,
    /// The direction inside after the entry refraction.
    inside: [Lanes<f64>; 3],
    /// The direction on inside after a reflection at the first exit.
    on: [Lanes<f64>; 3],
    /// The first exit, and the second after a reflection at the first.
    exits: [LaneExit; 2],
}

/// One exit of a packet's lanes from inside a lens ([`Lens::exit_lanes`]:
/// where `ok`, the lane meets a face and leaves by refraction; the rest
/// reflects on from `local` off the face of outward normal `normal` with
/// reflectance `reflectance`), and the rays out along `origin`, `dir`.
#[derive(Clone, Copy)]
struct LaneExit {
    exit: LaneExits<LANES>,
    origin: [Lanes<f64>; 3],
    dir: [Lanes<f64>; 3],
}

impl LaneExit {
    const EMPTY: LaneExit = LaneExit {
        exit: LaneExits::EMPTY,
        origin: [[0.0; LANES]; 3],
        dir: [[0.0; LANES]; 3],
    };

    /// Writes the rays out of the exits of `lens` held.
    #[inline(always)]
    fn rays(&mut self, lens: &Lens) {
        let e = &self.exit;
        for l in 0..LANES {
            let ray = leaving(lens, lane(&e.y, l), lane(&e.out, l), lane(&e.normal, l));
            set_lane(&mut self.origin, l, ray.origin);
            set_lane(&mut self.dir, l, ray.dir);
        }
    }
}

/// The first two exits from `lens` (index `ior`) of rays entering at the
/// points `x` (normals `nf`, facing the rays of directions `dir`) for every
/// lane at once, step by step over all lanes so that they run side by side
/// in SIMD registers: the entry refraction ([`optics::refract`]), the pass
/// to the exit ([`Lens::exit_lanes`]), the ray out ([`leaving`]), the
/// reflection on inside and the second exit, each lane with exactly the
/// scalar arithmetic of [`Lens::branches_inside`], so that it gets the
/// scalar rays bit for bit. Written into `out` in place (it is large).
#[inline(always)]
fn lens_lanes_impl<const WHOLE: bool>(
    lens: &Lens,
    ior: f64,
    x: &[Lanes<f64>; 3],
    dir: &[Lanes<f64>; 3],
    nf: &[Lanes<f64>; 3],
    out: &mut LensLanes,
) {
    // `optics::refract(dir, nf, 1.0, ior)`, and `shade_onward`'s Fresnel
    // reflectance (`optics::fresnel_at`), from one crossing.
    for l in 0..LANES {
        let c = optics::crossing(lane(dir, l), lane(nf, l), 1.0, ior);
        out.reflected[l] = c.total;
        out.entry_fresnel[l] = c.reflectance;
        set_lane(&mut out.inside, l, c.dir);
    }
    let LensLanes {
        reflected,
        inside,
        on,
        exits: [first, second],
        ..
    } = out;
    let mut local = [[0.0; LANES]; 3];
    for l in 0..LANES {
        set_lane(&mut local, l, lane(x, l) - lens.center);
    }
    // The first exit's point, then the reflection on from its normal, so
    // that the second exit runs beside the first exit's crossing (the two
    // longest chains of square roots side by side).
    lens.exit_points_local_into::<LANES, WHOLE>(&local, inside, &mut first.exit);
    // `Lens::reflect_inside`'s new direction.
    for l in 0..LANES {
        set_lane(
            on,
            l,
            Lens::reflected_inside(lane(inside, l), lane(&first.exit.normal, l)),
        );
    }
    Lens::exit_crossings_into::<LANES, WHOLE>(inside, ior, &mut first.exit);
    lens.exit_points_local_into::<LANES, WHOLE>(&first.exit.local, on, &mut second.exit);
    Lens::exit_crossings_into::<LANES, WHOLE>(on, ior, &mut second.exit);
    first.rays(lens);
    second.rays(lens);
    for l in 0..LANES {
        first.exit.ok[l] &= !reflected[l];
        second.exit.ok[l] &= first.exit.ok[l];
    }
}

with_avx2! {
    /// [`lens_lanes_impl`] in the best build this CPU runs: in the AVX-512
    /// build each lane loop runs over all lanes at once (one 64-byte
    /// register), in the others over two halves side by side
    /// (`geometry::lens::lanes`' `each_lane!`). The same bits in each.
    fn lens_lanes / lens_lanes_avx2 => {lens_lanes_impl::<false>}, avx512 => {lens_lanes_impl::<true>} (
        lens: &Lens,
        ior: f64,
        x: &[Lanes<f64>; 3],
        dir: &[Lanes<f64>; 3],
        nf: &[Lanes<f64>; 3],
        out: &mut LensLanes
    ) -> ()
}

/// The first lens of `scene` and its object's index (for tests).
#[cfg(test)]
pub(super) fn first_lens(scene: &crate::scene::Scene) -> (usize, &Lens) {
    scene
        .objects
        .iter()
        .enumerate()
        .find_map(|(i, o)| o.lens().map(|l| (i, l)))
        .expect("the scene has a lens")
}

/// The ray out of `lens` from the exit point `y` along `out`, spawned off
/// the face of outward normal `normal`: one ray's or one lane's.
#[inline(always)]
fn leaving(lens: &Lens, y: DVec3, out: DVec3, normal: DVec3) -> Ray {
    spawn_ray(y, normal, out, lens.d)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::surface;
    use crate::optics::{WAVELENGTH_D_UM, fresnel_at};
    use crate::sampling::Sampler;
    use crate::scene::Scene;

    /// Eight vectors, structure of arrays.
    type V = [Lanes<f64>; 3];

    /// Lanes of rays that enter the default scene's lens at random points
    /// from random directions: entry points, facing normals, directions.
    fn entries(scene: &Scene, seed: u64) -> Vec<(V, V, V)> {
        let (index, lens) = first_lens(scene);
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
    /// portable one) give every lane the scalar `transmitted_rays`, every
    /// ray out in order, bit for bit, pruned or not; most lanes take their
    /// first exit from the lanes.
    #[test]
    fn lens_lanes_give_the_scalar_pass() {
        let scene = Scene::default_scene().1;
        let obj = scene.objects.iter().find(|o| o.lens().is_some()).expect("a lens");
        let lens = obj.lens().expect("a lens");
        let ior = lens.index.at(crate::optics::WAVELENGTH_D_UM);
        let (mut exact, mut scalar, mut rays) = (0, 0, 0);
        let prunes = [
            Pruning::NONE,
            Pruning {
                scale: 0.7,
                min: 1e-3,
                max_reflections: 3,
                roulette: 0.0,
            },
        ];
        let key = |t: &Transmitted| (t.ray.origin, t.ray.dir, t.bounces, t.factor.to_bits());
        for (i, (x, nf, dir)) in entries(&scene, 3).into_iter().enumerate() {
            let prune = &prunes[i % 2];
            // The build this CPU runs, and the portable arithmetic with
            // either shape of lane loop (`tests/isa.rs` runs every build).
            for build in 0..3 {
                let mut passes = LensPasses {
                    lanes: 0xff,
                    ..LensPasses::EMPTY
                };
                let pass = &mut passes.pass;
                match build {
                    0 => lens_lanes(lens, ior, &x, &dir, &nf, pass),
                    1 => lens_lanes_impl::<true>(lens, ior, &x, &dir, &nf, pass),
                    _ => lens_lanes_impl::<false>(lens, ior, &x, &dir, &nf, pass),
                }
                for l in 0..LANES {
                    let at = |v: &V| DVec3::new(v[0][l], v[1][l], v[2][l]);
                    let mut want = Vec::new();
                    let ray = Ray {
                        origin: at(&x) - at(&dir),
                        dir: at(&dir),
                    };
                    transmitted_rays(obj, at(&x), at(&nf), true, &ray, ior, prune, &mut |t| {
                        want.push(key(&t))
                    });
                    let mut got = Vec::new();
                    passes.transmitted(l, lens, at(&x), ior, prune, &mut |t| got.push(key(&t)));
                    assert_eq!(got, want);
                    assert!(!passes.pass.reflected[l], "air to glass never reflects totally");
                    let f = fresnel_at(at(&dir), at(&nf), 1.0, ior);
                    assert_eq!(passes.pass.entry_fresnel[l], f, "shade_onward's reflectance");
                    if passes.pass.exits[1].exit.ok[l] {
                        exact += 1
                    } else {
                        scalar += 1
                    }
                    rays += got.len();
                }
            }
        }
        assert!(
            exact > 20_000 && scalar > 50 && rays > 2 * exact,
            "{exact} exact lanes, {scalar} left to the scalar code, {rays} rays out"
        );
    }

    /// Rays that start near a tiny lens (d = 1e-3) far from the origin
    /// (~1e4, where world coordinates are spaced 2e-9·d), and near one at
    /// the origin: on the axis, parallel to it at 0.5 h and 0.99 h, at 80°
    /// to it and skew. The renderer's pass into the lens, as the packet
    /// kernel takes it (`lens_passes`, then `lane_transmitted`: the lanes
    /// or the scalar `transmitted_rays`), leaves along `Lens::trace`'s exit:
    /// the direction within 1e-9 and the point (spawned off the face as the
    /// renderer does) within 1e-9·d + 64 ε·|x|. From the world hit point
    /// alone the far lens's exits are off by several 1e-9.
    #[test]
    fn rays_near_a_tiny_far_lens_leave_as_lens_trace_says() {
        use crate::math::{max_abs, orthonormal_basis};
        use crate::trace::closest_hit;
        let (mut compared, mut traced, mut worst) = (0, 0, 0.0f64);
        for center in ["[7000, -5000, 5000]", "[-9999.5, 3.25, 8000.125]", "[0.3, -0.2, 0.5]"] {
            let text = format!(
                "[camera]\nposition = [0, 0, 10]\nlook_at = [0, 0, 0]\n\n[[lenses]]\ncenter = {center}\n\
                 axis = [-0.6, 0.7, -0.4]\nd = 0.001\nr1 = 0.0012\nr2 = 0.003\nn = 1.5\n"
            );
            let scene = Scene::parse("tiny.toml", &text).expect("a valid scene").1;
            let lens = scene.objects[0].lens().expect("a lens");
            let (a, d) = (lens.axis, lens.d);
            let h = 0.5 * d;
            let (e1, e2) = orthonormal_basis(a);
            let mut s = Sampler::new(7, 0, 0);
            let rays: Vec<Ray> = (0..400)
                .map(|i| {
                    let phi = std::f64::consts::TAU * s.next_f64();
                    let radial = e1 * phi.cos() + e2 * phi.sin();
                    let across = radial.cross(a);
                    let dist = [1.5, 3.0, 7.0][i % 3] * d;
                    let (target, dir) = match i % 5 {
                        k @ 0..=2 => (lens.center + [0.0, 0.5, 0.99][k] * h * radial, -a),
                        3 => {
                            let th = 80f64.to_radians();
                            (lens.center + 0.3 * h * radial, -th.cos() * a + th.sin() * across)
                        }
                        _ => (
                            lens.center + 0.9 * h * s.next_f64().sqrt() * radial,
                            (-a + (0.05 + 0.55 * s.next_f64()) * across).normalize(),
                        ),
                    };
                    Ray::new(target - dist * dir, dir)
                })
                .collect();
            for chunk in rays.chunks(LANES) {
                let packet = Packet::new(chunk, f64::INFINITY);
                let surfaces: [Option<Surface>; LANES] = std::array::from_fn(|l| {
                    let ray = chunk.get(l)?;
                    closest_hit(&scene, ray, f64::INFINITY).map(|(i, hit)| surface(&scene, ray, i, hit))
                });
                let mut passes = LensPasses::EMPTY;
                let any = lens_passes(&packet, &surfaces, WAVELENGTH_D_UM, &mut passes);
                for (l, ray) in chunk.iter().enumerate() {
                    let want = lens.trace(ray.origin, ray.dir, 1.5);
                    let (Some(srf), Some((_, x, u)), Some(c)) = (&surfaces[l], want.exit, want.exit_crossing) else {
                        continue;
                    };
                    let lanes = (any && passes.lanes >> l & 1 != 0).then_some(&passes);
                    traced += usize::from(lanes.is_some());
                    let mut first = None;
                    lane_transmitted(lanes, &packet, l, srf, 1.5, &Pruning::NONE, &mut |t| {
                        first.get_or_insert(t);
                    });
                    let got = first.expect("a ray out");
                    assert_eq!(got.bounces, 2 + want.internal_reflections, "{ray:?}");
                    let spawned = leaving(lens, x, u, c.normal).origin;
                    let pos = (got.ray.origin - spawned).length() / (1e-9 * d + 64.0 * f64::EPSILON * max_abs(x));
                    let dir = (got.ray.dir - u).length() / 1e-9;
                    assert!(pos <= 1.0 && dir <= 1.0, "{center}: {ray:?}: {got:?}, want {x} {u}");
                    worst = worst.max(pos).max(dir);
                    compared += 1;
                }
            }
        }
        println!("{compared} rays compared, {traced} of them by the lanes; worst error {worst:.3e} of tolerance");
        assert!(
            compared > 1000 && traced > 300,
            "{compared} compared, {traced} by the lanes"
        );
    }
}
