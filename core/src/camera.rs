//! A pinhole camera: position, rotation about x, y and z (degrees, applied as
//! `Ry·Rx·Rz`, see [`crate::math::rotation_from_degrees`]) and a vertical
//! field of view. With no rotation it looks along −z with +y up.

mod depth;
mod lens;
pub mod pupil;

pub use lens::{Focus, LensCamera, LensCameraError, LensCameraSpec, LocalRay, nearest_focus};

use crate::math::{Ray, rotation_from_degrees};
use glam::{DMat3, DVec3};

#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    pub position: DVec3,
    pub rotation_deg: DVec3,
    pub fov_y_deg: f64,
    basis: DMat3,
    tan_half_fov: f64,
}

impl Camera {
    pub fn new(position: DVec3, rotation_deg: DVec3, fov_y_deg: f64) -> Self {
        Camera {
            position,
            rotation_deg,
            fov_y_deg,
            basis: rotation_from_degrees(rotation_deg),
            tan_half_fov: libm::tan(0.5 * fov_y_deg.to_radians()),
        }
    }

    /// `tan(fov/2)`, as the camera's rays use it (`libm`'s: the same bits
    /// on every platform).
    pub fn tan_half_fov(&self) -> f64 {
        self.tan_half_fov
    }

    pub fn forward(&self) -> DVec3 {
        self.basis * DVec3::NEG_Z
    }
    pub fn right(&self) -> DVec3 {
        self.basis * DVec3::X
    }
    pub fn up(&self) -> DVec3 {
        self.basis * DVec3::Y
    }
    /// The world vector of a camera-space one (rotation only).
    #[inline]
    pub fn to_world(&self, v: DVec3) -> DVec3 {
        self.basis * v
    }

    /// The primary ray through the continuous pixel position `(x, y)` of a
    /// `width × height` image (y down, pixel centres at half-integers).
    #[inline]
    pub fn ray(&self, x: f64, y: f64, width: u32, height: u32) -> Ray {
        let (kx, ky, ax, ay) = self.screen(width, height);
        let sx = (x * kx - 1.0) * ax;
        let sy = (1.0 - y * ky) * ay;
        let dir = self.basis * DVec3::new(sx, sy, -1.0);
        Ray::new(self.position, dir)
    }
}

impl Camera {
    /// The screen mapping of a `width × height` image: pixel position
    /// `(x, y)` lies at `((x·kx − 1)·ax, (1 − y·ky)·ay, −1)` in camera space
    /// (a product for each lane, no division).
    #[inline(always)]
    fn screen(&self, width: u32, height: u32) -> (f64, f64, f64, f64) {
        let tan = self.tan_half_fov;
        let aspect = width as f64 / height as f64;
        (2.0 / width as f64, 2.0 / height as f64, tan * aspect, tan)
    }

    /// Unit directions of the primary rays through `(xs[l], ys[l])` for each
    /// lane `l` (structure of arrays): exactly the arithmetic of
    /// [`Camera::ray`], lane by lane, so the same directions bit for bit,
    /// in a form that runs in SIMD registers.
    #[inline(always)]
    pub fn directions<const N: usize>(&self, xs: &[f64; N], ys: &[f64; N], width: u32, height: u32) -> [[f64; N]; 3] {
        let (kx, ky, ax, ay) = self.screen(width, height);
        let b = self.basis;
        let mut d = [[0.0; N]; 3];
        for l in 0..N {
            let sx = (xs[l] * kx - 1.0) * ax;
            let sy = (1.0 - ys[l] * ky) * ay;
            // `DMat3 * DVec3(sx, sy, −1)`, column by column, then `normalize`.
            let x = b.x_axis.x * sx + b.y_axis.x * sy - b.z_axis.x;
            let y = b.x_axis.y * sx + b.y_axis.y * sy - b.z_axis.y;
            let z = b.x_axis.z * sx + b.y_axis.z * sy - b.z_axis.z;
            let r = 1.0 / ((x * x) + (y * y) + (z * z)).sqrt();
            d[0][l] = x * r;
            d[1][l] = y * r;
            d[2][l] = z * r;
        }
        d
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_pixel_looks_forward_and_fov_is_vertical() {
        let c = Camera::new(DVec3::ZERO, DVec3::new(0.0, 90.0, 0.0), 90.0);
        let r = c.ray(50.0, 50.0, 100, 100);
        assert!((r.dir - DVec3::NEG_X).length() < 1e-12, "{}", r.dir);
        // The top edge of a 90° view is 45° up.
        let top = c.ray(50.0, 0.0, 100, 100);
        assert!((top.dir.y - std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-12);
    }

    #[test]
    fn lane_directions_are_the_scalar_rays_bit_for_bit() {
        let c = Camera::new(DVec3::new(1.0, 2.0, 3.0), DVec3::new(-28.8, 17.0, 3.0), 45.0);
        let xs = [0.0, 0.5, 17.25, 99.9, 640.0, 1279.5, 3.0, 1e-9];
        let ys = [0.0, 719.5, 360.0, 1.0, 2.5, 700.0, 33.3, 0.5];
        let d = c.directions(&xs, &ys, 1280, 720);
        for l in 0..8 {
            let r = c.ray(xs[l], ys[l], 1280, 720);
            assert_eq!(DVec3::new(d[0][l], d[1][l], d[2][l]), r.dir, "lane {l}");
        }
    }
}
