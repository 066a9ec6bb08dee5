//! Rendering an image from a scene: pixel sampling, parallel rows, and the
//! linear image buffer with its PNG output.
//!
//! Each pixel depends only on (scene, camera, pixel, sample index, seed), so
//! the image is bit-identical on any number of threads.

mod image;
pub mod progressive;
pub mod worker;

pub use image::Image;

use crate::color::Rgb;
use crate::integrator::radiance;
use crate::optics::WAVELENGTH_D_UM;
use crate::sampling::Sampler;
use crate::scene::Scene;
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Wavelengths (µm) at which dispersive glass is traced for the red, green
/// and blue channels: the Fraunhofer C (hydrogen, 656.3 nm), d (helium,
/// 587.6 nm) and F (hydrogen, 486.1 nm) lines, the lines an optician quotes
/// dispersion at.
pub const RGB_WAVELENGTHS_UM: [f64; 3] = [0.656_281_6, WAVELENGTH_D_UM, 0.486_132_7];

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub seed: u64,
}

/// Whether any glass in the scene has a wavelength-dependent index.
pub fn is_dispersive(scene: &Scene) -> bool {
    scene
        .objects
        .iter()
        .any(|o| o.material.transparency > 0.0 && o.material.ior.is_dispersive())
}

/// Radiance of one camera sample at continuous pixel position `(x, y)`.
#[inline]
pub fn sample(scene: &Scene, dispersive: bool, x: f64, y: f64, width: u32, height: u32) -> Rgb {
    let ray = scene.camera.ray(x, y, width, height);
    if dispersive {
        let mut c = Rgb::ZERO;
        for (ch, &l) in RGB_WAVELENGTHS_UM.iter().enumerate() {
            c[ch] = radiance(scene, &ray, 0, l)[ch];
        }
        c
    } else {
        radiance(scene, &ray, 0, WAVELENGTH_D_UM)
    }
}

/// The mean of `spp` samples of pixel `(px, py)`: the pixel centre for one
/// sample, otherwise stratified jitter keyed by (seed, pixel, sample).
pub fn render_pixel(scene: &Scene, dispersive: bool, px: u32, py: u32, s: &RenderSettings) -> Rgb {
    if s.spp <= 1 {
        return sample(scene, dispersive, px as f64 + 0.5, py as f64 + 0.5, s.width, s.height);
    }
    let pixel = py as u64 * s.width as u64 + px as u64;
    let mut sum = Rgb::ZERO;
    for i in 0..s.spp {
        let mut rng = Sampler::new(s.seed, pixel, i as u64);
        let (jx, jy) = rng.next_2d();
        sum += sample(scene, dispersive, px as f64 + jx, py as f64 + jy, s.width, s.height);
    }
    sum / s.spp as f64
}

/// Renders the whole image in parallel rows. `progress` is called with the
/// fraction of rows done (from worker threads, at most about 100 times).
pub fn render(scene: &Scene, s: &RenderSettings, progress: Option<&(dyn Fn(f64) + Sync)>) -> Image {
    let mut img = Image::new(s.width, s.height);
    if s.width == 0 || s.height == 0 {
        return img;
    }
    let dispersive = is_dispersive(scene);
    let done = AtomicUsize::new(0);
    let step = (s.height as usize / 100).max(1);
    img.pixels
        .par_chunks_mut(s.width as usize)
        .enumerate()
        .for_each(|(y, row)| {
            for (x, px) in row.iter_mut().enumerate() {
                *px = render_pixel(scene, dispersive, x as u32, y as u32, s);
            }
            let n = done.fetch_add(1, Ordering::Relaxed) + 1;
            if let Some(p) = progress
                && n % step == 0
            {
                p(n as f64 / s.height as f64);
            }
        });
    img
}
