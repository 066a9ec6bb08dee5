//! [`render`](super::render) in small steps, one band of one sample at a
//! time, on the calling thread: for a front end that must give control
//! back between steps (a web page's main thread draws nothing while Rust
//! runs). Each pixel adds its samples in the order `render` does and the
//! last step divides as it does, so the finished image is `render`'s, bit
//! for bit (tested below).

use super::{BandMemory, Image, RenderSettings, add_band_samples};
use crate::color::Rgb;
use crate::integrator::Lit;
use crate::sampling::Pattern;
use crate::trace::TILE;
use rayon::prelude::*;

/// An image being rendered step by step ([`Steps::step`]).
pub struct Steps {
    settings: RenderSettings,
    /// Per pixel: the sum of the samples so far; the mean once done.
    sums: Image,
    memory: BandMemory,
    /// The sample being added now, and the band that takes it next.
    sample: u32,
    band: usize,
}

impl Steps {
    pub fn new(settings: RenderSettings) -> Self {
        Steps {
            settings,
            sums: Image::new(settings.width, settings.height),
            memory: BandMemory::default(),
            sample: 0,
            band: 0,
        }
    }

    pub fn settings(&self) -> &RenderSettings {
        &self.settings
    }

    fn bands(&self) -> usize {
        (self.settings.height as usize).div_ceil(TILE)
    }

    /// Whether every sample of every pixel has been added.
    pub fn done(&self) -> bool {
        self.sample >= self.settings.spp.max(1) || self.bands() == 0 || self.settings.width == 0
    }

    /// Samples every pixel of the rows done so far holds (the rows after
    /// them hold one fewer).
    pub fn samples_done(&self) -> u32 {
        self.sample
    }

    /// Adds the next band's next sample; returns the rows it wrote (as
    /// `first..end`), or `None` when the image was already done.
    pub fn step(&mut self, scene: &Lit) -> Option<(u32, u32)> {
        self.step_bands(scene, 1)
    }

    /// [`Steps::step`] for up to `bands` bands at once (the next ones of
    /// the same sample), in parallel with rayon: each pixel gets the same
    /// samples in the same order whatever `bands` and the thread count, so
    /// the same bits. Returns the rows written.
    pub fn step_bands(&mut self, scene: &Lit, bands: usize) -> Option<(u32, u32)> {
        if self.done() {
            return None;
        }
        let (w, h) = (self.settings.width as usize, self.settings.height as usize);
        let end = (self.band + bands.max(1)).min(self.bands());
        let y0 = self.band * TILE;
        let y1 = (end * TILE).min(h);
        let rows = &mut self.sums.pixels[y0 * w..y1 * w];
        let (i, s) = (self.sample, &self.settings);
        let last = i + 1 == s.spp.max(1) && s.spp > 1;
        let band = |memory: &mut BandMemory, (k, rows): (usize, &mut [Rgb])| {
            add_band_samples(scene, (y0 + k * TILE) as u32, (i, Pattern::R2), s, memory, rows);
            if last {
                // `render`'s division, as it does it.
                for px in rows.iter_mut() {
                    *px /= s.spp as f64;
                }
            }
        };
        if end - self.band == 1 {
            band(&mut self.memory, (0, rows));
        } else {
            rows.par_chunks_mut(w * TILE)
                .enumerate()
                .for_each_init(BandMemory::default, band);
        }
        self.band = end;
        if self.band == self.bands() {
            self.band = 0;
            self.sample += 1;
        }
        Some((y0 as u32, y1 as u32))
    }

    /// Pixel `(x, y)` as shown now: the mean of its samples so far
    /// (`None` before its first). Once [`Steps::done`], `render`'s value.
    pub fn pixel(&self, x: u32, y: u32) -> Option<Rgb> {
        let n = self.samples_of_row(y);
        let v = self.sums.get(x, y);
        match n {
            0 => None,
            n if n == self.settings.spp.max(1) => Some(v),
            n => Some(v / n as f64),
        }
    }

    /// The samples the pixels of row `y` hold now.
    fn samples_of_row(&self, y: u32) -> u32 {
        let band = y as usize / TILE;
        self.sample + u32::from(band < self.band)
    }

    /// The finished image (`render`'s), once [`Steps::done`].
    pub fn image(&self) -> Option<&Image> {
        self.done().then_some(&self.sums)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::caustics::{CausticSettings, caustic_map, render_photons};
    use crate::render::render;
    use crate::scene::Scene;

    /// Step by step, with the caustics' photons, the image is `render`'s
    /// bit for bit; a row shows the mean of the samples it holds.
    #[test]
    fn steps_give_renders_image() {
        let scene = Scene::default_scene().1;
        for spp in [1, 3] {
            let s = RenderSettings {
                width: 37,
                height: 40,
                spp,
                seed: 5,
            };
            let photons = CausticSettings {
                seed: s.seed,
                ..CausticSettings::default()
            };
            let (passes, _) = render_photons(&scene, (s.width, s.height), spp, photons);
            let map = caustic_map(&scene, passes, photons);
            assert!(map.is_some(), "the default scene has caustics");
            let lit = Lit::new(&scene, map.as_ref());
            let mut steps = Steps::new(s);
            assert_eq!(steps.pixel(0, 0), None);
            let mut n = 0;
            while let Some((y0, y1)) = steps.step(&lit) {
                assert!(y0 < y1 && y1 <= s.height);
                assert!(steps.pixel(0, y0).is_some());
                n += 1;
            }
            assert_eq!(n, 3 * spp, "three bands a sample");
            let direct = render(Lit::new(&scene, map.as_ref()), &s, None);
            assert_eq!(steps.image(), Some(&direct));
            assert_eq!(steps.pixel(3, 37), Some(direct.get(3, 37)));
            let mut par = Steps::new(s);
            while par.step_bands(&lit, 2).is_some() {}
            assert_eq!(par.image(), Some(&direct), "two bands at a time");
        }
    }
}
