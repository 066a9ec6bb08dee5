//! A pinhole camera: position, rotation about x, y and z (degrees, applied as
//! `Ry·Rx·Rz`, see [`crate::math::rotation_from_degrees`]) and a vertical
//! field of view. With no rotation it looks along −z with +y up.

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
            tan_half_fov: (0.5 * fov_y_deg.to_radians()).tan(),
        }
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

    /// The primary ray through the continuous pixel position `(x, y)` of a
    /// `width × height` image (y down, pixel centres at half-integers).
    #[inline]
    pub fn ray(&self, x: f64, y: f64, width: u32, height: u32) -> Ray {
        let tan = self.tan_half_fov;
        let aspect = width as f64 / height as f64;
        let sx = (2.0 * x / width as f64 - 1.0) * tan * aspect;
        let sy = (1.0 - 2.0 * y / height as f64) * tan;
        let dir = self.basis * DVec3::new(sx, sy, -1.0);
        Ray::new(self.position, dir)
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
}
