//! Paraxial (first-order) data of a system from a y–nu trace of its
//! surfaces: refraction `n'u' = nu − y·φ` with `φ = (n' − n)·c`, transfer
//! `y' = y + t·u'` (Smith, *Modern Optical Engineering*, §2.6; Kingslake,
//! *Lens Design Fundamentals*, ch. 3). As matrices on `(y, nu)`:
//! refraction `[[1, 0], [−φ, 1]]`, transfer `[[1, t/n], [0, 1]]`; the
//! system from just before the first vertex to just after the last is
//! `[[A, B], [C, D]]` with `AD − BC = 1` (air on both sides).
//!
//! Distances are along the light: `bfd` from the last vertex to F′,
//! `ffd` from F to the first vertex (positive when F lies before it),
//! `front_principal` from the first vertex to H, `rear_principal` from the
//! last vertex to H′. With the power `φ = −C`: `efl = 1/φ`, `bfd = A/φ`,
//! `ffd = D/φ`, `front_principal = (1 − D)/φ`, `rear_principal =
//! (A − 1)/φ` (a ray `(1, 0)` leaves as `(A, C)`; one that leaves parallel
//! entered with `nu = −C·y/D`).

use super::LensSystem;

/// A 2×2 matrix on `(y, nu)`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct M([[f64; 2]; 2]);

impl M {
    const ONE: M = M([[1.0, 0.0], [0.0, 1.0]]);
    fn then(self, next: M) -> M {
        let (a, b) = (next.0, self.0);
        M([
            [
                a[0][0] * b[0][0] + a[0][1] * b[1][0],
                a[0][0] * b[0][1] + a[0][1] * b[1][1],
            ],
            [
                a[1][0] * b[0][0] + a[1][1] * b[1][0],
                a[1][0] * b[0][1] + a[1][1] * b[1][1],
            ],
        ])
    }
    fn apply(self, y: f64, nu: f64) -> (f64, f64) {
        let m = self.0;
        (m[0][0] * y + m[0][1] * nu, m[1][0] * y + m[1][1] * nu)
    }
    /// The inverse of a matrix of determinant 1.
    fn inverse(self) -> M {
        let m = self.0;
        M([[m[1][1], -m[0][1]], [-m[1][0], m[0][0]]])
    }
}

/// A pupil: its position along the light (from the first vertex for the
/// entrance pupil, from the last for the exit pupil) and semi-diameter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pupil {
    pub position: f64,
    pub semi_diameter: f64,
}

/// First-order data at one wavelength. Without power (`efl` infinite),
/// the focal distances are infinite and the principal planes NaN.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Paraxial {
    pub efl: f64,
    pub bfd: f64,
    pub ffd: f64,
    pub front_principal: f64,
    pub rear_principal: f64,
    /// The stop surface (the one flagged, else the one that limits an
    /// axial beam from infinity).
    pub stop: usize,
    pub entrance_pupil: Pupil,
    pub exit_pupil: Pupil,
    /// `efl / (2 · entrance pupil semi-diameter)`.
    pub f_number: f64,
}

impl LensSystem {
    /// The matrix of surfaces `from..to` (refraction at each, transfer to
    /// the next vertex between them), at `lambda_um`.
    fn matrix(&self, from: usize, to: usize, lambda_um: f64) -> M {
        let mut m = M::ONE;
        for k in from..to {
            let (n, n2) = (self.before(k).at(lambda_um), self.surfaces[k].n.at(lambda_um));
            m = m.then(M([[1.0, 0.0], [-(n2 - n) * self.c[k], 1.0]]));
            if k + 1 < to {
                m = m.then(M([[1.0, self.surfaces[k].thickness / n2], [0.0, 1.0]]));
            }
        }
        m
    }

    /// The axial distance from surface `from`'s vertex to surface `to`'s.
    fn span(&self, from: usize, to: usize) -> f64 {
        self.z[to] - self.z[from]
    }

    /// Paraxial data at `lambda_um`.
    pub fn paraxial(&self, lambda_um: f64) -> Paraxial {
        let [[a, _], [c, d]] = self.matrix(0, self.len(), lambda_um).0;
        let power = -c;
        let (efl, bfd, ffd, h, h2) = if power != 0.0 {
            (1.0 / power, a / power, d / power, (1.0 - d) / power, (a - 1.0) / power)
        } else {
            (f64::INFINITY, f64::INFINITY, f64::INFINITY, f64::NAN, f64::NAN)
        };
        let stop = self.stop_surface(lambda_um);
        let a_stop = self.surfaces[stop].semi_aperture;
        // The entrance pupil: the stop seen through the surfaces before it.
        // Rays from the stop's centre and its edge, traced back to object
        // space: the centre ray crosses the axis at the pupil, the edge ray
        // passes its edge there.
        let back = self.to_stop(stop, lambda_um).inverse();
        let entrance = pupil(back, a_stop);
        // The exit pupil: through the stop's surface and those after it.
        let ahead = self.matrix(stop, self.len(), lambda_um);
        let exit = pupil(ahead, a_stop);
        Paraxial {
            efl,
            bfd,
            ffd,
            front_principal: h,
            rear_principal: h2,
            stop,
            entrance_pupil: entrance,
            exit_pupil: exit,
            f_number: efl / (2.0 * entrance.semi_diameter),
        }
    }

    /// From just before the first vertex to the plane of surface `stop`
    /// (before refracting there), in the medium before it.
    fn to_stop(&self, stop: usize, lambda_um: f64) -> M {
        let m = self.matrix(0, stop, lambda_um);
        if stop == 0 {
            return m;
        }
        let n = self.before(stop).at(lambda_um);
        m.then(M([[1.0, self.span(stop - 1, stop) / n], [0.0, 1.0]]))
    }

    /// The flagged stop, or the surface whose aperture a paraxial beam from
    /// infinity fills first (largest `y/a`).
    fn stop_surface(&self, lambda_um: f64) -> usize {
        if let Some(k) = self.surfaces.iter().position(|s| s.stop) {
            return k;
        }
        let mut best = (0, 0.0);
        for k in 0..self.len() {
            let (y, _) = self.to_stop(k, lambda_um).apply(1.0, 0.0);
            let ratio = y.abs() / self.surfaces[k].semi_aperture;
            if ratio > best.1 {
                best = (k, ratio);
            }
        }
        best.0
    }
}

/// The image of a stop of semi-aperture `a` through `m` (from the stop's
/// plane to the reference plane, air after): where a ray from the stop's
/// centre crosses the axis (from the reference plane, along the light) and
/// how high a ray from its edge passes there.
fn pupil(m: M, a: f64) -> Pupil {
    let (y, u) = m.apply(0.0, 1.0);
    let position = -y / u;
    let (ye, ue) = m.apply(a, 0.0);
    Pupil {
        position,
        semi_diameter: (ye + ue * position).abs(),
    }
}
