//! The lens camera's depth of field, from its paraxial (thick-lens) data.
//!
//! A point at distance `D` from the entrance pupil (the camera) sends a
//! cone filling the entrance pupil (radius `a`); where the cone crosses
//! the plane in focus (distance `D_s`) it is a disc of diameter
//! `2a·|1 − D_s/D|`, and that plane is imaged on the sensor at the
//! magnification `m`: paraxial imaging takes the cone to the one through
//! the exit pupil, so the blur on the sensor is
//! `b = 2a·g·|1/D_s − 1/D|` with `g = |m|·D_s` (`= f·D_s/(D_s + e − h − f)`
//! through the principal plane H and the entrance pupil's position `e`;
//! `f` focused at infinity). The depth of field is where `b ≤ c`:
//! `1/D = 1/D_s ± c/(2a·g)`, near and far.

use super::LensCamera;

impl LensCamera {
    /// The circle of confusion the focus readout uses: the sensor's
    /// diagonal over 1500 (a full frame's 0.029 mm).
    pub fn circle_of_confusion(&self) -> f64 {
        libm::hypot(self.sensor[0], self.sensor[1]) / 1500.0
    }

    /// The nearest and farthest distances from the camera whose blur on
    /// the sensor is at most `c` (far: infinite beyond the hyperfocal
    /// distance), paraxial at the d line.
    pub fn depth_of_field(&self, c: f64) -> (f64, f64) {
        let p = &self.paraxial;
        let d = self.focus_distance;
        let g = if d.is_finite() {
            self.magnification.abs() * d
        } else {
            p.efl
        };
        let k = c / (2.0 * p.entrance_pupil.semi_diameter * g);
        let (near, far) = (1.0 / d + k, 1.0 / d - k);
        (1.0 / near, if far > 0.0 { 1.0 / far } else { f64::INFINITY })
    }
}

#[cfg(test)]
mod tests {
    use crate::camera::LensCamera;
    use crate::optics::WAVELENGTH_D_UM;
    use std::sync::Arc;

    /// The double Gauss at a hundredth of its size (a 36 × 24 sensor at
    /// the same scale), focused at `focus` (infinite: at infinity).
    fn camera(focus: f64, f_number: f64) -> Arc<LensCamera> {
        let focus = if focus.is_finite() {
            format!("focus_distance = {focus}\n")
        } else {
            String::new()
        };
        let text = format!(
            "[camera]\nposition = [0, 0, 0]\nlens = {{ preset = \"double-gauss-50mm\", scale = 0.01 }}\n\
             {focus}f_number = {f_number}\n"
        );
        let (_, scene) = crate::scene::Scene::parse("test", &text).unwrap();
        scene.lens.unwrap()
    }

    /// The blur on the sensor of a point at `d` from the camera, on the
    /// image side: its image by the thick-lens equation through H and H′,
    /// the cone from the exit pupil's rim to it, cut by the sensor.
    fn blur(cam: &LensCamera, d: f64) -> f64 {
        let p = cam.system.paraxial(WAVELENGTH_D_UM);
        let so = d + p.front_principal - p.entrance_pupil.position;
        let image = p.rear_principal + p.efl * so / (so - p.efl);
        let (xp, a) = (p.exit_pupil.position, p.exit_pupil.semi_diameter);
        2.0 * a * (cam.sensor_distance - image).abs() / (image - xp).abs()
    }

    /// Where [`blur`] is `c` between `lo` and `hi` (it grows from one
    /// end), by bisection.
    fn solve(cam: &LensCamera, c: f64, (mut lo, mut hi): (f64, f64)) -> f64 {
        let grows_up = blur(cam, hi) > blur(cam, lo);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if (blur(cam, mid) > c) == grows_up {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        0.5 * (lo + hi)
    }

    #[test]
    fn depth_of_field_is_where_the_image_side_blur_is_the_circle_of_confusion() {
        for (focus, n) in [(11.4, 2.8), (11.4, 11.0), (3.0, 2.1), (40.0, 5.6)] {
            let cam = camera(focus, n);
            let c = cam.circle_of_confusion();
            assert!((c - 0.36f64.hypot(0.24) / 1500.0).abs() < 1e-15);
            let (near, far) = cam.depth_of_field(c);
            let near_b = solve(&cam, c, (0.6, focus));
            assert!(
                (near - near_b).abs() < 1e-9 * focus,
                "f/{n} at {focus}: near {near} vs {near_b}"
            );
            assert!(near < focus && far > focus);
            if far.is_finite() {
                let far_b = solve(&cam, c, (focus, 1e9));
                assert!(
                    (far - far_b).abs() < 1e-8 * far,
                    "f/{n} at {focus}: far {far} vs {far_b}"
                );
            } else {
                // Beyond the hyperfocal distance: even infinity is sharp enough.
                assert!(blur(&cam, 1e12) <= c * (1.0 + 1e-9), "f/{n} at {focus}");
            }
        }
        // Stopping down deepens the field.
        let (a, b) = (camera(11.4, 2.8), camera(11.4, 11.0));
        let c = a.circle_of_confusion();
        assert!(b.depth_of_field(c).0 < a.depth_of_field(c).0);
    }

    #[test]
    fn focused_at_infinity_the_near_limit_is_the_hyperfocal_distance() {
        let cam = camera(f64::INFINITY, 4.0);
        let c = cam.circle_of_confusion();
        let (near, far) = cam.depth_of_field(c);
        assert!(far.is_infinite());
        // Hand formula: H ≈ f²/(N·c) from the entrance pupil (the pupil
        // diameter f/N).
        let f = cam.paraxial.efl;
        let h = f * f / (cam.f_number * c);
        assert!((near - h).abs() < 1e-9 * h, "{near} vs {h}");
        assert!((blur(&cam, near) - c).abs() < 1e-9 * c);
    }
}
