//! [`render`](super::render) in small steps, one band of one sample at a
//! time, on the calling thread: for a front end that must give control
//! back between steps (a web page's main thread draws nothing while Rust
//! runs). Each pixel adds its samples in the order `render` does and the
//! last step divides as it does, so the finished image is `render`'s, bit
//! for bit (tested below).

use super::thinning::{lit_for_sample, sample_stage};
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
    /// Where gathers are thinned: each pixel's sum at the end of the
    /// last stage of samples its row finished ([`settled`]), what
    /// [`Steps::pixel`] shows until the next (within a stage the samples
    /// that gather count for those still to come).
    settled: Vec<Rgb>,
}

/// The samples a row shows when it holds `n` of `spp` and gathers are
/// thinned: the end of the last stage it finished
/// (`thinning::sample_stage`: a power of two, or all of them).
fn settled(n: u32, spp: u32) -> u32 {
    if n >= spp || n == 0 { n } else { sample_stage(n, spp).0 }
}

impl Steps {
    pub fn new(settings: RenderSettings) -> Self {
        Steps {
            settings,
            sums: Image::new(settings.width, settings.height),
            memory: BandMemory::default(),
            sample: 0,
            band: 0,
            settled: Vec::new(),
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
        let (i, s) = (self.sample, &self.settings);
        let last = i + 1 == s.spp.max(1) && s.spp > 1;
        let thin = scene.thin();
        if thin > 1 && self.settled.is_empty() {
            self.settled = vec![Rgb::ZERO; w * h];
        }
        let rows = &mut self.sums.pixels[y0 * w..y1 * w];
        let scene = &lit_for_sample(scene, i, s.spp.max(1));
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
        if thin > 1 && settled(i + 1, s.spp.max(1)) == i + 1 {
            self.settled[y0 * w..y1 * w].copy_from_slice(rows);
        }
        self.band = end;
        if self.band == self.bands() {
            self.band = 0;
            self.sample += 1;
        }
        Some((y0 as u32, y1 as u32))
    }

    /// Pixel `(x, y)` as shown now: the mean of its samples so far
    /// (`None` before its first), or where gathers are thinned of those
    /// up to the end of the last stage its row finished. Once
    /// [`Steps::done`], `render`'s value.
    pub fn pixel(&self, x: u32, y: u32) -> Option<Rgb> {
        let mut n = self.samples_of_row(y);
        let mut v = self.sums.get(x, y);
        let spp = self.settings.spp.max(1);
        if !self.settled.is_empty() && settled(n, spp) < n {
            n = settled(n, spp);
            v = self.settled[y as usize * self.settings.width as usize + x as usize];
        }
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

    /// With thinned gathers too, the finished image is `render`'s; while a
    /// stage of samples is under way, a row shows the mean up to the end
    /// of the last stage it finished (`settled`), where the samples that
    /// gather stand for those still to come.
    #[test]
    fn thinned_steps_give_renders_image_and_show_whole_stages() {
        let scene = Scene::default_scene().1;
        let s = RenderSettings {
            width: 21,
            height: 17,
            spp: 8,
            seed: 2,
        };
        let map = caustic_map(&scene, 2, CausticSettings::default());
        let lit = Lit::new(&scene, map.as_ref()).thinned(4);
        let mut steps = Steps::new(s);
        let (mut shown, mut at_four) = (Vec::new(), None);
        while let Some((y0, _)) = steps.step(&lit) {
            if y0 == 0 {
                // Band 0 now holds `samples_done() + 1` samples.
                let n = steps.samples_done() + 1;
                let v = steps.pixel(5, 3);
                if n == 4 {
                    at_four = v;
                }
                shown.push((n, v));
            }
        }
        assert_eq!(steps.image(), Some(&render(lit, &s, None)));
        let at_four = at_four.expect("band 0 reached 4 samples");
        for (n, v) in shown {
            if (5..8).contains(&n) {
                assert_eq!(v, Some(at_four), "{n} samples show the first 4");
            }
        }
    }

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
