//! The scalar tracer inside the glass: a real ray through the lens
//! ([`Lens::trace`], behind `lensview lens trace`) and the pass from an
//! entry point to the exit that the renderer follows
//! ([`Lens::propagate_inside`]), with total internal reflections. The
//! entry step ([`Lens::entry`]) is the renderer's too
//! ([`Lens::entry_of_hit`]), and the exit step ([`Lens::exit_step`]) is
//! shared with the lanes ([`Lens::exit_lanes`]).

use super::cap::{Cap, Span, span};
use super::{Lens, LensSurface};
use crate::math::{Ray, max_abs, rescale_pow2};
use crate::optics::{self, Crossing};
use glam::DVec3;

/// The most total internal reflections followed inside the glass before a
/// ray is reported as trapped.
pub const MAX_INTERNAL_REFLECTIONS: u32 = 64;
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LensTraceStatus {
    /// The ray entered (or started inside) and left the glass.
    Transmitted,
    /// The ray does not meet the glass.
    Miss,
    /// More than [`MAX_INTERNAL_REFLECTIONS`] total internal reflections.
    Trapped,
}

/// A real ray through the lens.
#[derive(Clone, Debug, PartialEq)]
pub struct LensPath {
    pub status: LensTraceStatus,
    /// Entry face, point, and unit direction inside the glass after the first
    /// refraction; `None` for a miss or a ray that starts inside the glass.
    pub entry: Option<(LensSurface, DVec3, DVec3)>,
    /// Exit face, point, and unit direction in air after the last refraction.
    pub exit: Option<(LensSurface, DVec3, DVec3)>,
    /// The crossing at the exit: `None` without an exit.
    pub exit_crossing: Option<ExitCrossing>,
    pub internal_reflections: u32,
}

/// How a path crosses the exit face, beyond the point and direction of
/// [`LensPath::exit`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExitCrossing {
    /// The face's outward unit normal at the exit point.
    pub normal: DVec3,
    /// The Fresnel reflectance of the crossing from glass into air
    /// ([`optics::fresnel_at`], from the cosines of the refraction itself):
    /// the share of the light that stays inside.
    pub reflectance: f64,
}

/// Where a ray enters the glass ([`Lens::entry`]), in lens-local
/// coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LensEntry {
    /// The entry point, relative to the centre.
    pub local: DVec3,
    /// The face's outward unit normal there.
    pub normal: DVec3,
    /// The ray's unit direction, to refract.
    pub dir: DVec3,
}

/// A ray in lens-local coordinates ([`Lens::localize`]: its point `p`
/// nearest the centre, the unit direction `u`, the distance `t0` from the
/// origin to `p`) with both faces' roots along it.
pub(super) struct LocalRay {
    pub(super) p: DVec3,
    pub(super) u: DVec3,
    pub(super) t0: f64,
    pub(super) sp: Span,
}

/// The first exit of a ray inside the glass ([`Lens::exit_step`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct ExitStep {
    /// The ray meets a face ahead (else nothing below is a number to use).
    pub(super) found: bool,
    /// The exit point, local coordinates.
    pub(super) y: DVec3,
    /// The face (0: S1, 1: S2) and its outward unit normal at `y`.
    pub(super) face: usize,
    pub(super) normal: DVec3,
    /// The crossing out, from glass of index `n` into air.
    pub(super) crossing: Crossing,
}

impl Lens {
    /// Snell's law at entry, total internal reflections inside (counted, at
    /// most [`MAX_INTERNAL_REFLECTIONS`]), refraction at exit. A ray whose
    /// origin lies inside the glass starts there without an entry; one whose
    /// origin lies on a face (within 1e-10·d) and points inward enters there.
    pub fn trace(&self, origin: DVec3, dir: DVec3, n: f64) -> LensPath {
        let miss = LensPath {
            status: LensTraceStatus::Miss,
            entry: None,
            exit: None,
            exit_crossing: None,
            internal_reflections: 0,
        };
        let r = self.local_ray(origin, dir);
        let LocalRay { p, u, t0, sp } = r;
        if !sp.real {
            return miss;
        }
        let tol = 1e-10 * self.d;
        // Distances from the ray's origin.
        let (o_in, o_out) = (sp.t_in + t0, sp.t_out + t0);
        if sp.t_in >= sp.t_out || o_out <= tol {
            return miss;
        }
        let mut path = if o_in >= -tol {
            let (s, e) = self.entry_on(&r);
            // From air into glass (n ≥ 1) there is no total reflection.
            let Some(inside) = optics::refract(e.dir, e.normal, 1.0, n) else {
                return miss;
            };
            let mut path = self.propagate_local(e.local, inside, n);
            path.entry = Some((LensSurface::from_part(s as u8), e.local, inside));
            path
        } else {
            // Starts inside the glass: from the origin, in local coordinates.
            self.propagate_local(p - t0 * u, u, n)
        };
        // Back to world coordinates for the caller.
        let world = |e: Option<(LensSurface, DVec3, DVec3)>| e.map(|(s, x, d)| (s, self.center + x, d));
        path.entry = world(path.entry);
        path.exit = world(path.exit);
        path
    }

    /// The ray `origin + s·dir` in lens-local coordinates with both faces'
    /// roots along it. `dir` is scaled by a power of two first: [1e200, 0,
    /// −1e201] squares to ∞, [1e-200, 0, −1e-199] to 0; the line is the same.
    pub(super) fn local_ray(&self, origin: DVec3, dir: DVec3) -> LocalRay {
        let (p, u, t0) = self.localize(origin, rescale_pow2(dir));
        LocalRay {
            p,
            u,
            t0,
            sp: span(&self.caps, p, u),
        }
    }

    /// Where the local ray `r` enters the glass (at its origin itself if
    /// that lies on a face, `t_in + t0 ≤ 0`): the face (0: S1, 1: S2) and
    /// the entry. Nothing here is a number to use if `r` misses.
    pub(super) fn entry_on(&self, r: &LocalRay) -> (usize, LensEntry) {
        let (p, u, t0) = (r.p, r.u, r.t0);
        let x = if r.sp.t_in + t0 > 0.0 {
            p + r.sp.t_in * u
        } else {
            p - t0 * u
        };
        let s = self.face(x, r.sp.face_in);
        let e = LensEntry {
            local: x,
            normal: self.caps[s].normal(x),
            dir: u,
        };
        (s, e)
    }

    /// Where the ray `origin + s·dir` enters the glass, in lens-local
    /// arithmetic throughout: [`Lens::trace`]'s entry. The ray must meet the
    /// lens (else nothing here is a number to use).
    pub fn entry(&self, origin: DVec3, dir: DVec3) -> LensEntry {
        self.entry_on(&self.local_ray(origin, dir)).1
    }

    /// Whether a ray from `origin` finds its entry point well enough from
    /// the world hit point: when the origin's and the centre's coordinates
    /// are at most 10⁴·d, that point's rounding, a few ε·10⁴·d, tilts the
    /// normal by ≲ 10⁻¹¹, as in [`Lens::localize`]'s fast path.
    #[inline(always)]
    pub fn world_is_exact(&self, origin: DVec3) -> bool {
        max_abs(origin) <= self.world_exact
    }

    /// The entry of the renderer's hit along `ray` at the world point `p`
    /// (outward unit normal `normal` there, computed from `p`): `p` itself
    /// where [`Lens::world_is_exact`], else [`Lens::entry`] from the ray, the
    /// very entry of [`Lens::trace`]. A rounded world point `p` at 10⁴ from
    /// the origin would tilt the normal of a 10⁻³ lens by 10⁻⁹.
    #[inline(always)]
    pub fn entry_of_hit(&self, ray: &Ray, p: DVec3, normal: DVec3) -> LensEntry {
        if self.world_is_exact(ray.origin) {
            LensEntry {
                local: p - self.center,
                normal,
                dir: ray.dir,
            }
        } else {
            self.entry(ray.origin, ray.dir)
        }
    }

    /// Follows a ray inside the glass from the world point `x` in the unit
    /// direction `u` until it leaves (the renderer calls this after its own
    /// entry refraction). Points in the result are in world coordinates.
    pub fn propagate_inside(&self, x: DVec3, u: DVec3, n: f64) -> LensPath {
        let mut path = self.propagate_local(x - self.center, u, n);
        path.exit = path.exit.map(|(s, y, d)| (s, self.center + y, d));
        path
    }

    /// The exit from inside the glass: the nearer of the two far roots, from
    /// the local point `x` (inside or on the surface) along the unit `u`,
    /// and the crossing there from index `n` into air. Inside the glass only
    /// the far roots are used, which needs no epsilon. No branch: lanes run
    /// it side by side.
    ///
    /// `caps` are this lens's faces, passed in by value so that a lane loop
    /// holds them in registers: picked out of memory by each lane's face,
    /// they would be gathered lane by lane.
    #[inline(always)]
    pub(super) fn exit_step(&self, caps: [Cap; 2], x: DVec3, u: DVec3, n: f64) -> ExitStep {
        let (found, y, face, normal) = self.exit_point(caps, x, u);
        ExitStep {
            found,
            y,
            face,
            normal,
            crossing: Self::exit_crossing(u, normal, n),
        }
    }

    /// [`Lens::exit_step`]'s exit point: whether it is found, the point, the
    /// face and its outward unit normal there. Apart from the crossing, so
    /// that the lanes can go on from the normal (the reflection on inside)
    /// while the crossing's square roots run.
    #[inline(always)]
    pub(super) fn exit_point(&self, caps: [Cap; 2], x: DVec3, u: DVec3) -> (bool, DVec3, usize, DVec3) {
        let sp = span(&caps, x, u);
        let t = sp.t_out;
        let y = x + t * u;
        let face = self.face(y, sp.face_out);
        let [c0, c1] = caps;
        let normal = if face == 0 { c0 } else { c1 }.normal(y);
        (sp.real & (t >= 0.0), y, face, normal)
    }

    /// [`Lens::exit_step`]'s crossing out along `u` through a face of outward
    /// unit `normal`, from glass of index `n` into air.
    #[inline(always)]
    pub(super) fn exit_crossing(u: DVec3, normal: DVec3, n: f64) -> Crossing {
        // Inside, the face's outward normal points away from the incident
        // side, so Snell's law takes −normal.
        optics::crossing(u, -normal, n, 1.0)
    }

    /// [`Lens::propagate_inside`] in local coordinates.
    fn propagate_local(&self, mut x: DVec3, mut u: DVec3, n: f64) -> LensPath {
        let mut reflections = 0;
        let stop = |status, reflections| LensPath {
            status,
            entry: None,
            exit: None,
            exit_crossing: None,
            internal_reflections: reflections,
        };
        loop {
            let e = self.exit_step(self.caps, x, u, n);
            if !e.found {
                return stop(LensTraceStatus::Miss, reflections);
            }
            let c = e.crossing;
            if !c.total {
                return LensPath {
                    status: LensTraceStatus::Transmitted,
                    entry: None,
                    exit: Some((LensSurface::from_part(e.face as u8), e.y, c.dir)),
                    exit_crossing: Some(ExitCrossing {
                        normal: e.normal,
                        reflectance: c.reflectance,
                    }),
                    internal_reflections: reflections,
                };
            }
            if reflections >= MAX_INTERNAL_REFLECTIONS {
                return stop(LensTraceStatus::Trapped, reflections);
            }
            reflections += 1;
            u = Lens::reflected_inside(u, e.normal);
            x = e.y;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::Index;
    use approx::assert_relative_eq;

    fn lens(d: f64, r1: f64, r2: f64, n: f64) -> Lens {
        Lens::new(DVec3::ZERO, DVec3::Z, d, r1, r2, Index::Constant(n)).unwrap()
    }

    #[test]
    fn axial_ray_passes_undeviated() {
        let l = lens(20.0, 50.0, 50.0, 1.5);
        let p = l.trace(DVec3::new(0.0, 0.0, 30.0), DVec3::NEG_Z, 1.5);
        assert_eq!(p.status, LensTraceStatus::Transmitted);
        let (s, x, u) = p.entry.unwrap();
        assert_eq!(s, LensSurface::S1);
        assert_relative_eq!(x.z, optics::sagitta(50.0, 10.0), epsilon = 1e-15);
        assert_eq!(u, DVec3::NEG_Z);
        let (s, x, u) = p.exit.unwrap();
        assert_eq!(s, LensSurface::S2);
        assert_relative_eq!(x.z, -optics::sagitta(50.0, 10.0), epsilon = 1e-15);
        assert_eq!(u, DVec3::NEG_Z);
    }

    #[test]
    fn paraxial_ray_focuses_near_back_focal_distance() {
        let l = lens(20.0, 50.0, 50.0, 1.5);
        let px = l.paraxial(1.5);
        let h = 1e-4;
        let p = l.trace(DVec3::new(h, 0.0, 30.0), DVec3::NEG_Z, 1.5);
        let (_, x, u) = p.exit.unwrap();
        // Where the exiting ray crosses the axis, measured from V2.
        let t = -x.x / u.x;
        let z = x.z + t * u.z;
        let bfd = l.vertex(LensSurface::S2).z - z;
        assert_relative_eq!(bfd, px.bfd, max_relative = 1e-7);
    }

    #[test]
    fn misses_and_rays_from_inside() {
        let l = lens(2.0, 5.0, 5.0, 1.5);
        assert_eq!(
            l.trace(DVec3::new(1.01, 0.0, 5.0), DVec3::NEG_Z, 1.5).status,
            LensTraceStatus::Miss
        );
        assert_eq!(
            l.trace(DVec3::new(0.0, 0.0, -5.0), DVec3::NEG_Z, 1.5).status,
            LensTraceStatus::Miss
        );
        // From the centre toward S1 (not toward the rim, where the faces meet).
        let p = l.trace(DVec3::ZERO, DVec3::new(0.3, 0.0, 1.0), 1.5);
        assert!(p.entry.is_none());
        assert_eq!(p.exit.unwrap().0, LensSurface::S1);
        assert_eq!(p.status, LensTraceStatus::Transmitted);
    }

    #[test]
    fn ball_lens_traps_nothing_and_index_four_reflects() {
        // A ball lens: both faces hemispheres.
        let ball = lens(2.0, 1.0, 1.0, 1.5);
        let p = ball.trace(DVec3::new(0.5, 0.0, 5.0), DVec3::NEG_Z, 1.5);
        assert_eq!(p.status, LensTraceStatus::Transmitted);
        assert_eq!(p.internal_reflections, 0);
        let (_, x, _) = p.exit.unwrap();
        assert_relative_eq!(x.length(), 1.0, epsilon = 1e-15);
        // A ray inside a ball is never trapped by TIR (the chord angle is
        // preserved), but inside a thin lens at n = 4 a ray is.
        let l = lens(2.0, 5.0, 5.0, 4.0);
        let p = l.trace(DVec3::ZERO, DVec3::new(1.0, 0.0, 0.05), 4.0);
        assert!(p.internal_reflections >= 1, "{p:?}");
    }
}
