//! Bounds of the exit pupil as the sensor sees it, as pbrt-v4's
//! `RealisticCamera::BoundExitPupil` finds them: for each interval of
//! sensor radius, the box on the rear vertex's plane that holds every
//! point through which a ray from the interval's sensor points (on the
//! `+x` axis) passes the whole system. Rays from a sensor point at angle
//! φ use the box turned by φ (the system is round).
//!
//! Each box is found by tracing a low-discrepancy set of rays (sensor
//! point stratified over the interval, rear point a Halton (2, 3) point)
//! over an area, then again over the box found, grown by two sample
//! spacings; the result is grown by two of the second pass's spacings
//! (pbrt grows its one pass the same way). The first area is where the
//! paraxial exit pupil's cone from the interval meets the rear plane,
//! its radius doubled: a stopped-down lens's pupil is too small a part of
//! pbrt's square (1.5 × the rear aperture) for its samples to find. Where
//! the box found there is empty or reaches the area's border (pupil
//! aberration, vignetting), the radius is tripled (twice), then the
//! square is searched.

use crate::geometry::LensSystem;
use crate::sampling::radical_inverse;
use glam::DVec3;

/// Intervals of sensor radius, from the centre to the half diagonal.
pub const INTERVALS: usize = 64;

/// Rays traced per pass of one interval.
const SAMPLES: u32 = 4096;

/// An axis-aligned box on the rear plane; empty when `lo > hi`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PupilBox {
    pub lo: [f64; 2],
    pub hi: [f64; 2],
}

impl PupilBox {
    pub const EMPTY: PupilBox = PupilBox {
        lo: [f64::INFINITY; 2],
        hi: [f64::NEG_INFINITY; 2],
    };

    pub fn square(half: f64) -> PupilBox {
        PupilBox {
            lo: [-half; 2],
            hi: [half; 2],
        }
    }

    pub fn is_empty(&self) -> bool {
        !(self.lo[0] <= self.hi[0] && self.lo[1] <= self.hi[1])
    }

    pub fn area(&self) -> f64 {
        if self.is_empty() {
            0.0
        } else {
            (self.hi[0] - self.lo[0]) * (self.hi[1] - self.lo[1])
        }
    }

    fn diagonal(&self) -> f64 {
        libm::hypot(self.hi[0] - self.lo[0], self.hi[1] - self.lo[1])
    }

    /// The point at `(u, v)` ∈ [0, 1)² of the box.
    #[inline]
    pub fn lerp(&self, (u, v): (f64, f64)) -> (f64, f64) {
        (
            self.lo[0] + u * (self.hi[0] - self.lo[0]),
            self.lo[1] + v * (self.hi[1] - self.lo[1]),
        )
    }

    fn contains(&self, (x, y): (f64, f64)) -> bool {
        x >= self.lo[0] && x <= self.hi[0] && y >= self.lo[1] && y <= self.hi[1]
    }

    fn add(&mut self, (x, y): (f64, f64)) {
        self.lo = [self.lo[0].min(x), self.lo[1].min(y)];
        self.hi = [self.hi[0].max(x), self.hi[1].max(y)];
    }

    fn grown(&self, by: f64) -> PupilBox {
        PupilBox {
            lo: [self.lo[0] - by, self.lo[1] - by],
            hi: [self.hi[0] + by, self.hi[1] + by],
        }
    }
}

/// The sensor and rear planes a search traces between (camera space: the
/// system's axis along `−z`, light along `+z`).
pub struct Planes<'a> {
    pub system: &'a LensSystem,
    /// The d line's media ([`LensSystem::media`]).
    pub media: &'a [f64],
    pub sensor_z: f64,
    pub rear_z: f64,
    /// The paraxial exit pupil: its camera-space `z` and semi-diameter.
    pub exit_pupil: (f64, f64),
}

impl Planes<'_> {
    /// Whether the ray from the sensor point `(x, y)` to the rear plane's
    /// point `p` passes the system.
    pub fn passes(&self, (x, y): (f64, f64), p: (f64, f64)) -> bool {
        let film = DVec3::new(x, y, self.sensor_z);
        let d = DVec3::new(p.0, p.1, self.rear_z) - film;
        self.system.pass(film, d, self.media).is_some_and(|(_, u)| u.z < 0.0)
    }

    /// One pass over `area` for sensor points on `[r0, r1]` of the `+x` axis.
    fn scan(&self, area: &PupilBox, (r0, r1): (f64, f64)) -> PupilBox {
        let mut found = PupilBox::EMPTY;
        for i in 0..SAMPLES {
            let x = r0 + (i as f64 + 0.5) / SAMPLES as f64 * (r1 - r0);
            let p = area.lerp((radical_inverse(i, 2), radical_inverse(i, 3)));
            if !found.contains(p) && self.passes((x, 0.0), p) {
                found.add(p);
            }
        }
        found
    }

    /// Where the paraxial exit pupil's cone from sensor points on `[r0,
    /// r1]` of the `+x` axis meets the rear plane, its radius times `grow`.
    fn predicted(&self, (r0, r1): (f64, f64), grow: f64) -> PupilBox {
        let (z, a) = self.exit_pupil;
        // A point at `x` sees the pupil's disc at `x·(1 − t)`, radius `a·t`.
        let t = (self.sensor_z - self.rear_z) / (self.sensor_z - z);
        let (c0, c1) = (r0 * (1.0 - t), r1 * (1.0 - t));
        let r = grow * a * t.abs();
        PupilBox {
            lo: [c0.min(c1) - r, -r],
            hi: [c0.max(c1) + r, r],
        }
    }

    /// The exit pupil's box for sensor radii `[r0, r1]`, searched first
    /// over the predicted area, else over the square of half side `half`
    /// (empty: no ray passes).
    pub fn bound(&self, half: f64, radii: (f64, f64)) -> PupilBox {
        let spacing = |b: &PupilBox| 2.0 * b.diagonal() / (SAMPLES as f64).sqrt();
        let near = [2.0, 6.0, 18.0].into_iter().find_map(|grow| {
            let predicted = self.predicted(radii, grow);
            let near = self.scan(&predicted, radii).grown(spacing(&predicted));
            let inside = !near.is_empty()
                && near.lo[0] > predicted.lo[0]
                && near.lo[1] > predicted.lo[1]
                && near.hi[0] < predicted.hi[0]
                && near.hi[1] < predicted.hi[1];
            inside.then_some(near)
        });
        let area = match near {
            Some(near) => near,
            None => {
                let square = PupilBox::square(half);
                let first = self.scan(&square, radii);
                if first.is_empty() {
                    return first;
                }
                first.grown(spacing(&square))
            }
        };
        let second = self.scan(&area, radii);
        if second.is_empty() {
            // Too thin a sliver to meet twice: the first pass's box.
            return area;
        }
        second.grown(spacing(&area))
    }
}
