//! The lens's hit test and its exit from inside the glass for `N` rays at
//! once ([`Lens::intersect_lanes`], [`Lens::exit_lanes`]): the scalar
//! steps (`near_point`, [`span`], `pick`, `exit_step`) called lane by lane,
//! with no branch on a lane's value, so that the lanes run side by side in
//! SIMD registers and each gets the scalar answer bit for bit.

// Lane loops index several arrays by the lane: the form the vectoriser wants.
#![allow(clippy::needless_range_loop)]

use super::cap::span;
use super::{Lens, near_point};
use crate::optics::Crossing;
use crate::simd::{lane, set_lane};

/// Hits of a packet's lanes ([`Lens::intersect_lanes`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct LaneHits<const N: usize> {
    pub t: [f64; N],
    pub part: [u8; N],
    pub hit: [bool; N],
    /// Lanes that the scalar test must take.
    pub slow: [bool; N],
}

/// Exits of a packet's lanes from inside the glass
/// ([`Lens::exit_lanes`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct LaneExits<const N: usize> {
    /// The exit point, world coordinates, and local ones (from the centre:
    /// where a reflection on inside starts, [`Lens::reflect_inside`]).
    pub y: [[f64; N]; 3],
    pub local: [[f64; N]; 3],
    /// The refracted direction out of the glass (unit).
    pub out: [[f64; N]; 3],
    /// The face left through (0: S1, 1: S2).
    pub part: [u64; N],
    /// [`super::ExitCrossing::normal`] and [`super::ExitCrossing::reflectance`].
    pub normal: [[f64; N]; 3],
    pub reflectance: [f64; N],
    /// Lanes that leave by refraction at their first exit; the others (a
    /// total internal reflection, or a start outside the glass) need the
    /// scalar [`Lens::propagate_inside`].
    pub ok: [bool; N],
}

/// `put` of `(l, step)` for every lane `l < N`: one loop over all lanes
/// (`WHOLE`), which the AVX-512 build runs in one 64-byte register a
/// step, or the two halves side by side, the lanes `l` and `l + N/2`
/// together, which gives the AVX2 build two 32-byte registers' long chains
/// of square roots and divisions at once. The AVX-512 build ran the halves
/// as 32-byte registers too: the whole loop made its Whitted frame of
/// `cubes.toml` 7 % faster, and the AVX2 build 2.5 % slower (round 20).
/// Each lane's arithmetic is the same either way. A macro, not a function
/// taking closures: a closure is compiled without its caller's target
/// features, so it would not be inlined into the AVX builds.
macro_rules! each_lane {
    ($whole:expr, $n:expr, $l:ident => $step:expr, ($pl:ident, $pv:pat) => $put:block) => {
        if $whole {
            for $l in 0..$n {
                let v = $step;
                let ($pl, $pv) = ($l, v);
                $put
            }
        } else {
            for i in 0..$n / 2 {
                let (a, b) = (
                    {
                        let $l = i;
                        $step
                    },
                    {
                        let $l = i + $n / 2;
                        $step
                    },
                );
                {
                    let ($pl, $pv) = (i, a);
                    $put
                }
                {
                    let ($pl, $pv) = (i + $n / 2, b);
                    $put
                }
            }
        }
    };
}

impl Lens {
    /// [`Lens::intersect`] on `(0, t_max[l])` for every lane `l` of a packet
    /// (origins `o`, unit directions `d`, structure of arrays). Lanes whose
    /// origin lies beyond the fast radius need the double-double start
    /// point: they are flagged `slow` and left for the scalar test.
    #[inline(always)]
    pub(crate) fn intersect_lanes<const N: usize>(
        &self,
        o: &[[f64; N]; 3],
        d: &[[f64; N]; 3],
        t_max: &[f64; N],
    ) -> LaneHits<N> {
        let mut out = LaneHits {
            t: [0.0; N],
            part: [0; N],
            hit: [false; N],
            slow: [false; N],
        };
        let start = |l: usize| {
            let rel = lane(o, l) - self.center;
            (rel, rel.dot(lane(d, l)), rel.length_squared())
        };
        // The cheap rejection of `intersect` first: a packet whose rays all
        // pass clear of the lens (its box is larger than it) stops here.
        let mut any_near = false;
        for l in 0..N {
            let (_, along, rel2) = start(l);
            any_near |= !self.clear_of(rel2, along);
        }
        if !any_near {
            return out;
        }
        for l in 0..N {
            let (rel, along, rel2) = start(l);
            let near = !self.clear_of(rel2, along);
            let fast = rel2 <= self.fast_radius2;
            let (p, u, t0) = near_point(rel, along, lane(d, l));
            let (met, hit) = self.pick(&span(&self.caps, p, u), p, u, t0, 0.0, t_max[l]);
            out.part[l] = hit.part;
            out.t[l] = hit.t;
            out.hit[l] = near & fast & met;
            out.slow[l] = near & !fast;
        }
        out
    }

    /// [`Lens::propagate_inside`] for `N` rays at once, for rays that leave
    /// at their first exit: lane `l` starts at the world point `x[l]` inside
    /// (or on) the glass along the unit `u[l]`. A lane flagged `ok` gets
    /// exactly the scalar exit; the others are left to the scalar code.
    #[cfg(test)]
    pub(crate) fn exit_lanes<const N: usize>(&self, x: &[[f64; N]; 3], u: &[[f64; N]; 3], n: f64) -> LaneExits<N> {
        let mut out = LaneExits::EMPTY;
        self.exit_lanes_into(x, u, n, &mut out);
        out
    }

    /// [`Lens::exit_lanes`] written into `out` (every field of every lane:
    /// working memory kept by the caller, with nothing to clear first).
    #[cfg(test)]
    #[inline(always)]
    pub(crate) fn exit_lanes_into<const N: usize>(
        &self,
        x: &[[f64; N]; 3],
        u: &[[f64; N]; 3],
        n: f64,
        out: &mut LaneExits<N>,
    ) {
        let mut local = [[0.0; N]; 3];
        for l in 0..N {
            set_lane(&mut local, l, lane(x, l) - self.center);
        }
        self.exit_lanes_local_into(&local, u, n, out)
    }

    /// [`Lens::exit_lanes_into`] from local points `x` (from the centre), as
    /// [`Lens::branch_chain`] goes on from one exit to the next.
    #[cfg(test)]
    #[inline(always)]
    pub(crate) fn exit_lanes_local_into<const N: usize>(
        &self,
        x: &[[f64; N]; 3],
        u: &[[f64; N]; 3],
        n: f64,
        out: &mut LaneExits<N>,
    ) {
        self.exit_points_local_into::<N, false>(x, u, out);
        Self::exit_crossings_into::<N, false>(u, n, out);
    }

    /// [`Lens::exit_lanes_local_into`]'s exit points ([`Lens::exit_point`]):
    /// `y`, `local`, `part` and `normal`, with `ok` holding whether the
    /// point is found until [`Lens::exit_crossings_into`]. `WHOLE`: one
    /// lane loop over all `N` lanes, else two halves side by side
    /// (`each_lane!`).
    #[inline(always)]
    pub(crate) fn exit_points_local_into<const N: usize, const WHOLE: bool>(
        &self,
        x: &[[f64; N]; 3],
        u: &[[f64; N]; 3],
        out: &mut LaneExits<N>,
    ) {
        let caps = self.caps;
        each_lane!(WHOLE, N, l => self.exit_point(caps, lane(x, l), lane(u, l)), (l, (found, y, face, normal)) => {
            set_lane(&mut out.y, l, self.center + y);
            set_lane(&mut out.local, l, y);
            set_lane(&mut out.normal, l, normal);
            out.part[l] = face as u64;
            out.ok[l] = found;
        });
    }

    /// [`Lens::exit_lanes_local_into`]'s crossings out ([`Lens::exit_crossing`])
    /// along `u` (index `n`) at the points [`Lens::exit_points_local_into`]
    /// wrote: `out` and `reflectance`, and `ok` where the point was found
    /// and the lane leaves by refraction. `WHOLE` as in
    /// [`Lens::exit_points_local_into`].
    #[inline(always)]
    pub(crate) fn exit_crossings_into<const N: usize, const WHOLE: bool>(
        u: &[[f64; N]; 3],
        n: f64,
        out: &mut LaneExits<N>,
    ) {
        each_lane!(WHOLE, N, l => Self::exit_crossing(lane(u, l), lane(&out.normal, l), n), (l, c) => {
            let c: Crossing = c;
            set_lane(&mut out.out, l, c.dir);
            out.reflectance[l] = c.reflectance;
            out.ok[l] &= !c.total;
        });
    }
}

impl<const N: usize> LaneExits<N> {
    /// Zeros, to be written over ([`Lens::exit_lanes_into`]).
    pub(crate) const EMPTY: LaneExits<N> = LaneExits {
        y: [[0.0; N]; 3],
        local: [[0.0; N]; 3],
        out: [[0.0; N]; 3],
        part: [0; N],
        normal: [[0.0; N]; 3],
        reflectance: [0.0; N],
        ok: [false; N],
    };
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{ExitCrossing, Hit, LensSurface, LensTraceStatus};
    use crate::math::Ray;
    use crate::optics::{self, Index};
    use glam::DVec3;

    /// Lenses for the lane tests: the benchmark scene's, a ball, a
    /// meniscus-like pair of radii, a nearly flat one and a tiny one far
    /// from the origin.
    fn lane_test_lenses() -> Vec<Lens> {
        [
            Lens::new(
                DVec3::new(0.0, 4.3, 6.9),
                DVec3::new(0.0, 0.48, 0.88),
                2.0,
                5.0,
                5.0,
                Index::Constant(1.5),
            ),
            Lens::new(DVec3::ZERO, DVec3::Z, 2.0, 1.0, 1.0, Index::Constant(1.5)),
            Lens::new(DVec3::ONE, DVec3::X, 2.0, 1.0, 3.0, Index::Constant(1.5)),
            Lens::new(DVec3::ZERO, DVec3::Y, 2.0, 2e6, 2e7, Index::Constant(1.5)),
            Lens::new(DVec3::splat(1e4), DVec3::ONE, 1e-3, 0.7e-3, 5e-3, Index::Constant(1.5)),
        ]
        .into_iter()
        .map(|l| l.unwrap())
        .collect()
    }

    /// The lane exits are the scalar `propagate_inside` exits to the bit,
    /// for rays refracted in at real entry points (thick, ball, meniscus-
    /// like, nearly flat and tiny far-off lenses), and every lane that
    /// reflects inside is left to the scalar code.
    #[test]
    fn lane_exits_are_the_scalar_exits_bit_for_bit() {
        use crate::sampling::Sampler;
        let mut s = Sampler::new(5, 0, 0);
        let (mut exact, mut scalar) = (0, 0);
        for (c, l) in lane_test_lenses().into_iter().enumerate() {
            let n = 1.5;
            for _ in 0..3000 {
                let mut x = [[0.0; 8]; 3];
                let mut u = [[0.0; 8]; 3];
                for lane in 0..8 {
                    // A ray from outside toward the lens, refracted in where
                    // it enters.
                    let org = l.center + (DVec3::new(s.next_f64(), s.next_f64(), s.next_f64()) - 0.5) * 6.0 * l.d;
                    let aim = l.center + (DVec3::new(s.next_f64(), s.next_f64(), s.next_f64()) - 0.5) * l.d;
                    let ray = Ray::new(org, aim - org);
                    let (p, dir) = match l.intersect(&ray, 0.0, f64::INFINITY) {
                        Some(h) => {
                            let p = ray.at(h.t);
                            let nrm = l.normal(p, h.part);
                            let nf = if ray.dir.dot(nrm) < 0.0 { nrm } else { -nrm };
                            (p, optics::refract(ray.dir, nf, 1.0, n).unwrap_or(ray.dir))
                        }
                        // A start inside the glass in a random direction.
                        None => (l.center, ray.dir),
                    };
                    for k in 0..3 {
                        x[k][lane] = p[k];
                        u[k][lane] = dir[k];
                    }
                }
                let got = l.exit_lanes(&x, &u, n);
                // The whole-lane loops (the AVX-512 build's) give the bits
                // of the halves side by side.
                let mut local = [[0.0; 8]; 3];
                for lane in 0..8 {
                    set_lane(&mut local, lane, super::lane(&x, lane) - l.center);
                }
                let mut whole = LaneExits::EMPTY;
                l.exit_points_local_into::<8, true>(&local, &u, &mut whole);
                Lens::exit_crossings_into::<8, true>(&u, n, &mut whole);
                let bits = |e: &LaneExits<8>| {
                    let f = |v: &[[f64; 8]; 3]| v.map(|a| a.map(f64::to_bits));
                    (
                        f(&e.y),
                        f(&e.local),
                        f(&e.out),
                        e.part,
                        f(&e.normal),
                        e.reflectance.map(f64::to_bits),
                        e.ok,
                    )
                };
                assert_eq!(bits(&whole), bits(&got), "case {c}: whole-lane loops");
                for lane in 0..8 {
                    let p = DVec3::new(x[0][lane], x[1][lane], x[2][lane]);
                    let dir = DVec3::new(u[0][lane], u[1][lane], u[2][lane]);
                    let want = l.propagate_inside(p, dir, n);
                    if !got.ok[lane] {
                        scalar += 1;
                        assert!(
                            want.internal_reflections > 0 || want.status != LensTraceStatus::Transmitted,
                            "case {c}: a plain pass left to the scalar code"
                        );
                        continue;
                    }
                    exact += 1;
                    let y = DVec3::new(got.y[0][lane], got.y[1][lane], got.y[2][lane]);
                    let out = DVec3::new(got.out[0][lane], got.out[1][lane], got.out[2][lane]);
                    let part = LensSurface::from_part(got.part[lane] as u8);
                    assert_eq!(want.status, LensTraceStatus::Transmitted, "case {c}");
                    assert_eq!(want.internal_reflections, 0, "case {c}");
                    assert_eq!(want.exit, Some((part, y, out)), "case {c}");
                    let crossing = ExitCrossing {
                        normal: DVec3::new(got.normal[0][lane], got.normal[1][lane], got.normal[2][lane]),
                        reflectance: got.reflectance[lane],
                    };
                    assert_eq!(want.exit_crossing, Some(crossing), "case {c}");
                }
            }
        }
        assert!(
            exact > 50_000 && scalar > 500,
            "{exact} exact lanes, {scalar} left to the scalar code"
        );
    }

    #[test]
    fn lanes_give_the_scalar_hit_bit_for_bit() {
        use crate::sampling::Sampler;
        let mut s = Sampler::new(11, 0, 0);
        for (c, l) in lane_test_lenses().into_iter().enumerate() {
            let mut hits = 0;
            for k in 0..4000 {
                let mut o = [[0.0; 8]; 3];
                let mut d = [[0.0; 8]; 3];
                let mut t_max = [f64::INFINITY; 8];
                for lane in 0..8 {
                    // Origins near the lens (some inside it), on the far side,
                    // and far away for the slow lanes.
                    let spread = [0.2, 3.0, 1e5][(k + lane) % 3] * l.d;
                    let org = l.center + (DVec3::new(s.next_f64(), s.next_f64(), s.next_f64()) - 0.5) * spread;
                    let aim = l.center + (DVec3::new(s.next_f64(), s.next_f64(), s.next_f64()) - 0.5) * l.d;
                    let dir = (aim - org).normalize();
                    if lane == 7 {
                        t_max[lane] = s.next_f64() * spread;
                    }
                    for i in 0..3 {
                        o[i][lane] = org[i];
                        d[i][lane] = dir[i];
                    }
                }
                let got = l.intersect_lanes(&o, &d, &t_max);
                for lane in 0..8 {
                    let ray = Ray {
                        origin: DVec3::new(o[0][lane], o[1][lane], o[2][lane]),
                        dir: DVec3::new(d[0][lane], d[1][lane], d[2][lane]),
                    };
                    let want = l.intersect(&ray, 0.0, t_max[lane]);
                    if got.slow[lane] {
                        assert!((ray.origin - l.center).length_squared() > l.fast_radius2, "case {c}");
                        continue;
                    }
                    let have = got.hit[lane].then_some(Hit {
                        t: got.t[lane],
                        part: got.part[lane],
                    });
                    assert_eq!(have, want, "case {c}, packet {k}, lane {lane}: {ray:?}");
                    hits += usize::from(want.is_some());
                }
            }
            assert!(hits > 2000, "case {c}: only {hits} hits");
        }
    }
}
