//! Rendering an image from a scene: pixel sampling, parallel rows, and the
//! linear image buffer with its PNG output.
//!
//! Each pixel depends only on (scene, camera, pixel, sample index, seed), so
//! the image is bit-identical on any number of threads.

mod adaptive;
pub mod caustics;
pub mod edges;
pub mod exr;
pub mod first_frame;
mod image;
pub mod progressive;
pub mod reproject;
mod sparse;
pub mod steps;
pub mod thinning;
pub mod upsample;
pub mod worker;

pub use adaptive::Adaptive;
pub use image::{Image, ImageFormat};
pub use sparse::{FirstHit, Seen};

use crate::camera::LensCamera;
use crate::color::Rgb;
use crate::integrator::Lit;
use crate::integrator::{PacketPaths, PacketScratch, radiance, radiance_packet, radiance_packet_into};
use crate::optics::WAVELENGTH_D_UM;
use crate::sampling::{Pattern, lens_point, pixel_offset};
use crate::scene::Scene;
use crate::simd::{LANES, Lanes};
use crate::trace::{CameraTile, Packet, PacketHits, TILE, camera_hits, camera_tile_hits};
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

pub use crate::optics::RGB_WAVELENGTHS_UM;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub seed: u64,
}

/// Radiance of one camera sample at continuous pixel position `(x, y)`.
#[inline]
pub fn sample<'a>(scene: impl Into<Lit<'a>>, x: f64, y: f64, width: u32, height: u32) -> Rgb {
    let lit = scene.into();
    let scene = &lit;
    let ray = scene.camera.ray(x, y, width, height);
    if scene.features.dispersion {
        let mut c = Rgb::ZERO;
        for (ch, &l) in RGB_WAVELENGTHS_UM.iter().enumerate() {
            c[ch] = radiance(scene, &ray, 0, l)[ch];
        }
        c
    } else {
        radiance(scene, &ray, 0, WAVELENGTH_D_UM)
    }
}

/// Radiance of the lens camera's sample at continuous pixel position
/// `(x, y)` through the exit pupil's point `u` ([`LensCamera::ray`]), its
/// weight applied; a ray the lens stops gives black. Three wavelengths
/// when the scene or the lens disperses (each its own ray through the lens).
pub fn lens_sample(scene: &Lit, lens: &LensCamera, at: (f64, f64), size: (u32, u32), u: (f64, f64)) -> Rgb {
    let trace = |channel: usize, lambda: f64| {
        lens.ray(&scene.camera, at, size, u, channel)
            .map_or(Rgb::ZERO, |(ray, weight)| radiance(scene, &ray, 0, lambda) * weight)
    };
    if scene.features.dispersion || lens.is_dispersive() {
        let mut c = Rgb::ZERO;
        for (ch, &lambda) in RGB_WAVELENGTHS_UM.iter().enumerate() {
            c[ch] = trace(ch, lambda)[ch];
        }
        c
    } else {
        trace(1, WAVELENGTH_D_UM)
    }
}

/// Sample `i` of pixel `(px, py)` at [`pixel_offset`] of `pattern`: the
/// pinhole's [`sample`], or through the scene's lens camera at its pupil
/// point [`lens_point`] (both keyed by the seed, the pixel and `i` alone).
pub fn pixel_sample(scene: &Lit, (px, py): (u32, u32), (i, pattern): (u32, Pattern), s: &RenderSettings) -> Rgb {
    let (at, u) = sample_point((px, py), (i, pattern), s);
    match &scene.lens {
        Some(lens) => lens_sample(scene, lens, at, (s.width, s.height), u),
        None => sample(scene, at.0, at.1, s.width, s.height),
    }
}

/// Sample `i` of pixel `(px, py)`: its continuous position and its pupil
/// point ([`pixel_sample`]).
#[inline]
fn sample_point((px, py): (u32, u32), (i, pattern): (u32, Pattern), s: &RenderSettings) -> ((f64, f64), (f64, f64)) {
    let pixel = py as u64 * s.width as u64 + px as u64;
    let (jx, jy) = pixel_offset(pattern, s.seed, pixel, i);
    ((px as f64 + jx, py as f64 + jy), lens_point(s.seed, pixel, i))
}

/// Sensor positions (or pupil points) of a packet's lanes.
type Points = Lanes<(f64, f64)>;

/// Lens-camera samples gathered eight at a time ([`lens_samples`]), each
/// with where it goes: what a band's sample, and an adaptive wave, cast
/// through a lens camera.
#[derive(Default)]
pub(crate) struct LensBatch {
    at: Points,
    u: Points,
    dst: [u32; LANES],
    n: usize,
}

impl LensBatch {
    /// Adds sample `i` of pixel `px` (going to `dst`); a full batch is
    /// traced and handed to `sink` in the order pushed.
    pub(crate) fn push(
        &mut self,
        scene: &Lit,
        lens: &LensCamera,
        (px, i, pattern): ((u32, u32), u32, Pattern),
        s: &RenderSettings,
        dst: u32,
        sink: &mut impl FnMut(u32, Rgb),
    ) {
        (self.at[self.n], self.u[self.n]) = sample_point(px, (i, pattern), s);
        self.dst[self.n] = dst;
        self.n += 1;
        if self.n == LANES {
            self.flush(scene, lens, (s.width, s.height), sink);
        }
    }

    /// Traces what is gathered and hands it to `sink`.
    pub(crate) fn flush(&mut self, scene: &Lit, lens: &LensCamera, size: (u32, u32), sink: &mut impl FnMut(u32, Rgb)) {
        if self.n > 0 {
            let c = lens_samples(scene, lens, (&self.at, &self.u), self.n, size);
            for (&d, c) in self.dst.iter().zip(c).take(self.n) {
                sink(d, c);
            }
            self.n = 0;
        }
    }
}

/// [`lens_sample`] of the lanes `l < n` (others: black), at the sensor
/// positions `at[l]` and pupil points `u[l]`: their sensor rays cross the
/// lens together ([`LensCamera::rays`]), each then traced alone; lane for
/// lane the same bits.
fn lens_samples(
    scene: &Lit,
    lens: &LensCamera,
    (at, u): (&Points, &Points),
    n: usize,
    size: (u32, u32),
) -> [Rgb; LANES] {
    let trace = |channel: usize, lambda: f64| {
        lens.rays(&scene.camera, at, size, u, n, channel)
            .map(|r| r.map_or(Rgb::ZERO, |(ray, weight)| radiance(scene, &ray, 0, lambda) * weight))
    };
    if scene.features.dispersion || lens.is_dispersive() {
        let mut c = [Rgb::ZERO; LANES];
        for (ch, &lambda) in RGB_WAVELENGTHS_UM.iter().enumerate() {
            for (c, v) in c.iter_mut().zip(trace(ch, lambda)) {
                c[ch] = v[ch];
            }
        }
        c
    } else {
        trace(1, WAVELENGTH_D_UM)
    }
}

/// Camera samples at the continuous pixel positions `(xs[l], ys[l])` for
/// `l < n` (1 ..= [`LANES`]), traced as one packet: lane `l` is exactly
/// [`sample`] at its position (through a lens camera, [`lens_sample`]; their
/// sensor rays cross the lens together). `scratch` is working memory, kept from
/// call to call.
#[inline]
pub fn sample_packet(
    scene: &Lit,
    xs: &[f64; LANES],
    ys: &[f64; LANES],
    n: usize,
    width: u32,
    height: u32,
    scratch: &mut PacketScratch,
) -> [Rgb; LANES] {
    if let Some(lens) = &scene.lens {
        // Through a lens camera, at each position's pixel's first pupil
        // point (a block preview's or an adaptive sample's).
        let (mut at, mut u) = ([(0.0, 0.0); LANES], [(0.0, 0.0); LANES]);
        for l in 0..n {
            let pixel = ys[l] as u64 * width as u64 + xs[l] as u64;
            (at[l], u[l]) = ((xs[l], ys[l]), lens_point(0, pixel, 0));
        }
        return lens_samples(scene, lens, (&at, &u), n, (width, height));
    }
    let (p, hits) = camera_hits(scene, xs, ys, n, width, height);
    let mut out = [Rgb::ZERO; LANES];
    shade_camera_packet(scene, &p, &hits, n, scratch, &mut out);
    out
}

/// The radiance of each camera ray of `p` (lanes `l < n`) from its hit,
/// written into `out` (lanes from `n` on: zero).
#[inline]
fn shade_camera_packet(
    scene: &Lit,
    p: &Packet,
    hits: &PacketHits,
    n: usize,
    scratch: &mut PacketScratch,
    out: &mut [Rgb; LANES],
) {
    let paths = PacketPaths::camera(p, hits, n);
    if scene.features.dispersion {
        *out = [Rgb::ZERO; LANES];
        for (ch, &lambda) in RGB_WAVELENGTHS_UM.iter().enumerate() {
            let c = radiance_packet(scene, &paths, lambda, scratch);
            for l in 0..n {
                out[l][ch] = c[l][ch];
            }
        }
    } else {
        radiance_packet_into(scene, &paths, WAVELENGTH_D_UM, scratch, out);
    }
}

/// Adds sample `i` of every pixel of the rows `y0 ..` held in `rows` (up
/// to [`TILE`] whole rows of the image, one after another) to them; sample
/// 0 is the first of a sum, so it is written over whatever `rows` held
/// (no clearing pass, and no read of the old value). Sample
/// `i` lies at [`pixel_offset`] of `pattern` (sample 0: the pixel centre).
/// The camera rays are cast in tiles
/// of eight pixels by the band's rows ([`camera_tile_hits`]), each row of
/// a tile a packet; every pixel gets exactly what [`sample`] gives it.
pub fn add_band_samples(
    scene: &Lit,
    y0: u32,
    (i, pattern): (u32, Pattern),
    s: &RenderSettings,
    memory: &mut BandMemory,
    rows: &mut [Rgb],
) {
    let BandMemory { tile, scratch } = memory;
    let Some((w, count)) = band_shape(rows.len(), s) else {
        return;
    };
    if let Some(lens) = &scene.lens {
        // A lens camera's rays start apart: eight at a time through the
        // lens, then each alone into the scene.
        let mut batch = LensBatch::default();
        let mut add = |k: u32, v: Rgb| {
            let px = &mut rows[k as usize];
            *px = if i == 0 { v } else { *px + v };
        };
        for k in 0..(w * count) as u32 {
            let pixel = (k % w as u32, y0 + k / w as u32);
            batch.push(scene, lens, (pixel, i, pattern), s, k, &mut add);
        }
        batch.flush(scene, lens, (s.width, s.height), &mut add);
        return;
    }
    for x0 in (0..w).step_by(LANES) {
        let n = cast_band_tile(scene, (x0, y0, count), (i, pattern), s, tile);
        for r in 0..count {
            let row = &mut rows[r * w + x0..r * w + x0 + n];
            // A whole packet's first sample is written in place.
            if i == 0
                && let Ok(row) = <&mut [Rgb; LANES]>::try_from(&mut *row)
            {
                shade_camera_packet(scene, &tile.packets[r], &tile.hits[r], n, scratch, row);
                continue;
            }
            let mut v = [Rgb::ZERO; LANES];
            shade_camera_packet(scene, &tile.packets[r], &tile.hits[r], n, scratch, &mut v);
            for (px, v) in row.iter_mut().zip(v) {
                if i == 0 {
                    *px = v;
                } else {
                    *px += v;
                }
            }
        }
    }
}

/// What the centre rays of the rows `y0 ..` held in `first` (up to
/// [`TILE`] whole rows) meet first: sample 0's camera rays of
/// [`add_band_samples`], cast the same way but not shaded.
pub fn band_first_hits(scene: &Scene, y0: u32, s: &RenderSettings, memory: &mut BandMemory, first: &mut [FirstHit]) {
    let Some((w, count)) = band_shape(first.len(), s) else {
        return;
    };
    for x0 in (0..w).step_by(LANES) {
        let n = cast_band_tile(scene, (x0, y0, count), (0, Pattern::R2), s, &mut memory.tile);
        for r in 0..count {
            let (p, hits) = (&memory.tile.packets[r], &memory.tile.hits[r]);
            FirstHit::lanes(scene, p, hits, &mut first[r * w + x0..r * w + x0 + n]);
        }
    }
}

/// The image's width and the rows a band's buffer of `len` pixels holds
/// (whole rows, at most [`TILE`]); `None` for an empty image.
fn band_shape(len: usize, s: &RenderSettings) -> Option<(usize, usize)> {
    let w = s.width as usize;
    (w > 0).then(|| {
        let count = len / w;
        debug_assert!(count <= TILE && count * w == len);
        (w, count)
    })
}

/// Casts sample `i` of the pixels `x0 ..` (a packet's width) of `count`
/// rows from `y0`, each row a packet of `tile`; returns the pixels per row.
fn cast_band_tile(
    scene: &Scene,
    (x0, y0, count): (usize, u32, usize),
    (i, pattern): (u32, Pattern),
    s: &RenderSettings,
    tile: &mut CameraTile,
) -> usize {
    let w = s.width as usize;
    let n = (w - x0).min(LANES);
    let mut xs = [[0.0; LANES]; TILE];
    let mut ys = [[0.0; LANES]; TILE];
    sample_positions((x0, y0, count), (i, pattern), s.seed, s.width, &mut xs, &mut ys);
    camera_tile_hits(
        scene,
        &xs[..count],
        &ys[..count],
        &[n; TILE][..count],
        s.width,
        s.height,
        tile,
    );
    n
}

/// Where sample `i` of each pixel of a tile's rows lies ([`pixel_offset`]):
/// the continuous positions `xs[r][l]`, `ys[r][l]` of pixel `(x0 + l, y0 +
/// r)`, `r < count`, in every lane (lanes past the image's right edge get
/// numbers that are not used). A lane loop: the hashes and conversions of
/// eight pixels side by side (one by one they were a tenth of a focal-spot
/// frame at 64 spp, `perf`).
#[inline(always)]
fn sample_positions_impl(
    (x0, y0, count): (usize, u32, usize),
    (i, pattern): (u32, Pattern),
    seed: u64,
    width: u32,
    xs: &mut [Lanes<f64>; TILE],
    ys: &mut [Lanes<f64>; TILE],
) {
    for r in 0..count.min(TILE) {
        let y = y0 + r as u32;
        for l in 0..LANES {
            let px = (x0 + l) as u64;
            let (jx, jy) = pixel_offset(pattern, seed, y as u64 * width as u64 + px, i);
            xs[r][l] = px as f64 + jx;
            ys[r][l] = y as f64 + jy;
        }
    }
}

crate::simd::with_avx2! {
    /// [`sample_positions_impl`] in the best build this CPU runs (the same
    /// numbers in each).
    fn sample_positions / sample_positions_avx2 => sample_positions_impl(
        rows: (usize, u32, usize),
        sample: (u32, Pattern),
        seed: u64,
        width: u32,
        xs: &mut [Lanes<f64>; TILE],
        ys: &mut [Lanes<f64>; TILE]
    ) -> ()
}

/// The working memory of [`add_band_samples`], kept from call to call by
/// whoever samples a band: the camera tile and the packet kernel's memory.
#[derive(Default)]
pub struct BandMemory {
    tile: CameraTile,
    scratch: PacketScratch,
}

/// The mean of `spp` samples of pixel `(px, py)` at the points of
/// [`Pattern::R2`] (sample 0: the pixel centre), traced one by one.
pub fn render_pixel<'a>(scene: impl Into<Lit<'a>>, px: u32, py: u32, s: &RenderSettings) -> Rgb {
    let lit = scene.into();
    let spp = s.spp.max(1);
    let mut sum = Rgb::ZERO;
    for i in 0..spp {
        let lit = thinning::lit_for_sample(&lit, i, spp);
        sum += pixel_sample(&lit, (px, py), (i, Pattern::R2), s);
    }
    if s.spp <= 1 {
        return sum;
    }
    sum / s.spp as f64
}

/// Renders the whole image in parallel bands of [`TILE`] rows. `progress` is called with the
/// fraction of rows done (from worker threads, at most about 100 times).
pub fn render<'a>(scene: impl Into<Lit<'a>>, s: &RenderSettings, progress: Option<&(dyn Fn(f64) + Sync)>) -> Image {
    let mut img = Image::new(0, 0);
    render_into(scene, s, progress, &mut img);
    img
}

/// [`render`] into `img`, whose buffer is kept when it is large enough (as
/// a viewer keeps its frame from frame to frame): every pixel is written,
/// so nothing is cleared first.
pub fn render_into<'a>(
    scene: impl Into<Lit<'a>>,
    s: &RenderSettings,
    progress: Option<&(dyn Fn(f64) + Sync)>,
    img: &mut Image,
) {
    let lit = scene.into();
    let scene = &lit;
    (img.width, img.height) = (s.width, s.height);
    img.pixels.resize(s.width as usize * s.height as usize, Rgb::ZERO);
    if s.width == 0 || s.height == 0 {
        return;
    }
    let spp = s.spp.max(1);
    let done = AtomicUsize::new(0);
    let step = (s.height as usize / 100).max(1);
    let w = s.width as usize;
    img.pixels
        .par_chunks_mut(w * TILE)
        .enumerate()
        .for_each(|(band, rows)| {
            // Sample by sample over the band, in tiles of packets; each
            // pixel adds its samples in the order `render_pixel` does.
            let mut memory = BandMemory::default();
            for i in 0..spp {
                // Where one sample in several gathers (`thinning`), its own.
                let lit = thinning::lit_for_sample(scene, i, spp);
                add_band_samples(&lit, (band * TILE) as u32, (i, Pattern::R2), s, &mut memory, rows);
            }
            if s.spp > 1 {
                for px in rows.iter_mut() {
                    *px /= s.spp as f64;
                }
            }
            let before = done.fetch_add(rows.len() / w, Ordering::Relaxed);
            let n = before + rows.len() / w;
            if let Some(p) = progress
                && n / step > before / step
            {
                p(n as f64 / s.height as f64);
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A block preview's packet through a lens camera (its sensor rays
    /// crossing the lens together) is, lane for lane and bit for bit, each
    /// position's [`lens_sample`] at its pixel's first pupil point; lanes
    /// past `n` are black. Dispersive glass too (a sample per channel).
    #[test]
    fn a_lens_cameras_packet_is_its_samples_one_by_one() {
        let text = |f: &str| {
            format!(
                "[camera]\nposition = [0, 0.5, 4]\nlens = {{ preset = \"{f}\", scale = 0.01 }}\n\
                 focus_distance = 1.5\nf_number = 4\n[ambient]\ncolor = [1, 1, 1]\nintensity = 1\n\
                 [[objects]]\ntype = \"cuboid\"\nposition = [0, 0.5, 0]\nsize = [1, 1, 1]\n"
            )
        };
        let (w, h) = (37u32, 23u32);
        for preset in ["double-gauss-50mm", "cooke-triplet-100mm"] {
            let (_, s) = Scene::parse("lens", &text(preset)).unwrap();
            let lit = Lit::from(&s);
            let lens = s.lens.as_deref().unwrap();
            let mut scratch = PacketScratch::default();
            let mut k = 0.0;
            for n in [LANES, 5, 1] {
                for _ in 0..12 {
                    let (mut xs, mut ys) = ([0.0; LANES], [0.0; LANES]);
                    for l in 0..n {
                        k += 1.0;
                        (xs[l], ys[l]) = ((k * 7.31) % w as f64, (k * 3.17) % h as f64);
                    }
                    let got = sample_packet(&lit, &xs, &ys, n, w, h, &mut scratch);
                    for l in 0..LANES {
                        let want = if l < n {
                            let pixel = ys[l] as u64 * w as u64 + xs[l] as u64;
                            lens_sample(&lit, lens, (xs[l], ys[l]), (w, h), lens_point(0, pixel, 0))
                        } else {
                            Rgb::ZERO
                        };
                        let bits = |c: Rgb| c.to_array().map(f64::to_bits);
                        assert_eq!(
                            bits(got[l]),
                            bits(want),
                            "{preset}: lane {l} of {n} at {}, {}",
                            xs[l],
                            ys[l]
                        );
                    }
                }
            }
        }
    }

    /// A kept buffer's old contents (here NaN, from a larger frame) never
    /// reach the image: `render_into` writes every pixel.
    #[test]
    fn render_into_a_used_buffer_gives_a_fresh_render() {
        let scene = Scene::default_scene().1;
        for spp in [1, 2] {
            let s = RenderSettings {
                width: 29,
                height: 19,
                spp,
                seed: 1,
            };
            let mut img = Image {
                width: 40,
                height: 40,
                pixels: vec![Rgb::splat(f64::NAN); 1600],
            };
            render_into(&scene, &s, None, &mut img);
            assert_eq!(img, render(&scene, &s, None));
        }
    }

    /// The packet path of `render` gives, pixel for pixel and bit for bit,
    /// what tracing each camera sample alone (`render_pixel`) gives, on the
    /// default scene, on one with dispersive glass and on a steep lens.
    #[test]
    fn packets_render_what_single_rays_render() {
        // A steep lens of index 3: many rays reflect inside it, and the
        // packet path hands those to the scalar lens tracer.
        let steep =
            include_str!("../../../scenes/cubes.toml").replace("r1 = 5\nr2 = 5\nn = 1.5", "r1 = 1.05\nr2 = 8\nn = 3");
        assert!(steep.contains("n = 3"));
        let scenes = [
            Scene::default_scene().1,
            Scene::parse("primitives", include_str!("../../../scenes/primitives.toml"))
                .unwrap()
                .1,
            Scene::parse("steep", &steep).unwrap().1,
        ];
        for scene in &scenes {
            for spp in [1, 3] {
                let s = RenderSettings {
                    width: 37,
                    height: 23,
                    spp,
                    seed: 5,
                };
                let img = render(scene, &s, None);
                for y in 0..s.height {
                    for x in 0..s.width {
                        assert_eq!(img.get(x, y), render_pixel(scene, x, y, &s), "pixel {x},{y}");
                    }
                }
            }
        }
    }
}
