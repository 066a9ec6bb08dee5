//! A real ray's pass through the lens with its turn kept apart from its
//! direction ([`Lens::trace_fine`]): what a focus is measured from as the
//! index goes to 1, where the exit direction of [`Lens::trace`], a unit
//! vector rounded to ε, holds only ε/(n − 1) of the turn.

use super::trace::LocalRay;
use super::{Lens, LensSurface};
use crate::optics;
use glam::DVec3;

/// A ray that enters the glass and leaves at the first face it meets
/// inside (no internal reflection): the path of [`Lens::trace`] with the
/// exit direction split into the incoming direction and the deviation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FinePass {
    pub entry_face: LensSurface,
    pub exit_face: LensSurface,
    /// The exit point, relative to the centre (the point [`Lens::trace`]
    /// gives, less `center`).
    pub exit_local: DVec3,
    /// The incoming unit direction, as traced.
    pub dir: DVec3,
    /// The exit direction minus `dir`: both refractions' turns by
    /// [`optics::refraction_deviation`], so it keeps its relative precision
    /// however close n is to 1 (n − 1 is a factor of it). `dir + deviation`
    /// is the exit direction (unit to a few ε).
    pub deviation: DVec3,
}

impl Lens {
    /// The pass of the ray `origin + s·dir` at index `n` when it enters the
    /// glass and leaves at the next face without a total internal
    /// reflection — entry, exit point and faces those of [`Lens::trace`] —
    /// with its deviation computed apart ([`FinePass`]); `None` for any
    /// other path (a miss, a start inside the glass, a reflection inside).
    pub fn trace_fine(&self, origin: DVec3, dir: DVec3, n: f64) -> Option<FinePass> {
        let r: LocalRay = self.local_ray(origin, dir);
        let tol = 1e-10 * self.d;
        let sp = r.sp;
        if !sp.real || sp.t_in >= sp.t_out || sp.t_out + r.t0 <= tol || sp.t_in + r.t0 < -tol {
            return None;
        }
        let (s, e) = self.entry_on(&r);
        let inside = optics::refract(e.dir, e.normal, 1.0, n)?;
        let x = self.exit_step(self.caps, e.local, inside, n);
        if !x.found || x.crossing.total {
            return None;
        }
        let d1 = optics::refraction_deviation(e.dir, DVec3::ZERO, e.normal, 1.0, n)?;
        // Inside, the exit face's outward normal points away from the ray.
        let d2 = optics::refraction_deviation(e.dir, d1, -x.normal, n, 1.0)?;
        Some(FinePass {
            entry_face: LensSurface::from_part(s as u8),
            exit_face: LensSurface::from_part(x.face as u8),
            exit_local: x.y,
            dir: e.dir,
            deviation: d1 + d2,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::Index;

    #[test]
    fn the_fine_pass_is_the_traced_path() {
        let l = Lens::new(
            DVec3::new(1.0, -2.0, 3.0),
            DVec3::Z,
            2.0,
            5.0,
            3.0,
            Index::Constant(1.5),
        )
        .unwrap();
        for k in -8..=8 {
            let o = DVec3::new(1.0 + 0.1 * f64::from(k), -2.0, 9.0);
            let dir = DVec3::new(0.01, 0.02, -1.0);
            let p = l.trace(o, dir, 1.5);
            let f = l.trace_fine(o, dir, 1.5).expect("through");
            let (s, x, u) = p.exit.unwrap();
            assert_eq!((f.entry_face, f.exit_face), (LensSurface::S1, s));
            assert_eq!(l.center + f.exit_local, x);
            assert!(((f.dir + f.deviation) - u).length() < 1e-15, "{k}");
        }
        assert!(l.trace_fine(DVec3::new(5.0, 0.0, 9.0), DVec3::NEG_Z, 1.5).is_none());
    }
}
