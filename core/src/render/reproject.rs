//! Reprojection (issue #21): after a camera move, the previous picture
//! moved into the new view, so the first frame is sharp instead of blocky.
//!
//! Every pixel of a picture keeps what its centre ray met first
//! ([`FirstHit`]: the point, or a direction for the background, and
//! whether it was glass or a mirror). A move then takes three steps:
//!
//! 1. **Splat** each old pixel's point into the new view, keeping the
//!    nearest per new pixel (depth and source packed in one `u64`, so the
//!    parallel `fetch_min` gives the same winner on any thread count).
//! 2. **Look back**: each new pixel takes the depth splatted on it (or on
//!    a neighbour, for the gaps a forward move opens), puts that point on
//!    its own centre ray, projects it into the old view and interpolates
//!    the old colours bilinearly from the taps that saw the same surface
//!    (point within [`DEPTH_TOLERANCE`] of the old view's distance).
//! 3. **Trace** what is left — disoccluded pixels, pixels seen through
//!    glass or in a mirror (their picture moves differently), pixels no
//!    tap fits — at their centres, or per block of a coarser level when
//!    the caller's budget says so.

mod fill;

pub use fill::fill;

use super::sparse::{FirstHit, Seen};
use crate::camera::Camera;
use crate::color::Rgb;
use crate::scene::Scene;
use crate::simd::LANES;
use glam::Vec3;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU32, Ordering};

/// Relative difference of depth (along the old view's axis) under which
/// an old pixel's point counts as the same surface as a new pixel's.
pub const DEPTH_TOLERANCE: f32 = 0.03;

/// Whether `a` and `b` differ only by their cameras: then a picture of one
/// may be reprojected into the other.
pub fn same_but_camera(a: &Scene, b: &Scene) -> bool {
    a.ambient == b.ambient
        && a.background == b.background
        && a.max_depth == b.max_depth
        && a.shadows == b.shadows
        && a.features == b.features
        && a.lights == b.lights
        && a.objects == b.objects
}

/// A view's projection, its constants worked out once, in `f32` (a
/// pixel's position to a thousandth of a pixel is plenty for a warp).
#[derive(Clone, Copy, Debug)]
pub struct Projector {
    right: Vec3,
    up: Vec3,
    forward: Vec3,
    /// Pixels per unit of screen coordinate, and the centre.
    sx: f32,
    sy: f32,
    cx: f32,
    cy: f32,
    /// Their inverses, for [`Self::direction`].
    isx: f32,
    isy: f32,
}

impl Projector {
    pub fn new(cam: &Camera, (w, h): (u32, u32)) -> Projector {
        let tan = cam.tan_half_fov();
        let (cx, cy) = (0.5 * w as f64, 0.5 * h as f64);
        let (sx, sy) = (cx / (tan * w as f64 / h as f64), cy / tan);
        Projector {
            right: cam.right().as_vec3(),
            up: cam.up().as_vec3(),
            forward: cam.forward().as_vec3(),
            sx: sx as f32,
            sy: sy as f32,
            cx: cx as f32,
            cy: cy as f32,
            isx: (1.0 / sx) as f32,
            isy: (1.0 / sy) as f32,
        }
    }

    /// The continuous pixel position and depth (along the view's axis) of
    /// `v`, a point less the camera position or a direction (a point at
    /// infinity): the inverse of [`Camera::ray`]; `None` behind the camera.
    #[inline]
    pub fn project(&self, v: Vec3) -> Option<(f32, f32, f32)> {
        let p = self.project_any(v);
        (p.2 > 0.0).then_some(p)
    }

    /// [`Self::project`] without the test (behind the camera, the depth is
    /// not positive and the position means nothing): no branch, so that a
    /// loop over lanes of it runs in SIMD registers.
    #[inline(always)]
    fn project_any(&self, v: Vec3) -> (f32, f32, f32) {
        let z = v.dot(self.forward);
        let iz = 1.0 / z;
        (
            self.cx + v.dot(self.right) * iz * self.sx,
            self.cy - v.dot(self.up) * iz * self.sy,
            z,
        )
    }

    /// The direction through the continuous pixel position `(x, y)`, scaled
    /// to depth 1 along the view's axis (the inverse of [`Self::project`]).
    #[inline(always)]
    fn direction(&self, x: f32, y: f32) -> Vec3 {
        self.forward + self.right * ((x - self.cx) * self.isx) - self.up * ((y - self.cy) * self.isy)
    }

    /// The centre rays of row `y`'s pixels, as [`Self::direction`] scales
    /// them: pixel `x`'s is `start + step * x` (a pass over a row adds
    /// instead of working each one out: measured, the splat took three
    /// times as long with a [`Self::direction`] per pixel).
    #[inline]
    fn row_rays(&self, y: usize) -> (Vec3, Vec3) {
        (self.direction(0.5, y as f32 + 0.5), self.right * self.isx)
    }
}

/// The picture before the move: its camera, colours and first hits. With
/// `count`, a pixel's colour is `colour / count` (running sums).
pub struct Source<'a> {
    pub camera: &'a Camera,
    pub size: (u32, u32),
    pub colour: &'a [Rgb],
    pub count: Option<&'a [u32]>,
    pub first: &'a [FirstHit],
}

impl Source<'_> {
    /// The mean colour of old pixels `taps` weighted `wt` (their sum
    /// `weight`): each tap's colour times its weight over the weights'
    /// sum and, with running sums, over its count, the four quotients in
    /// one division (per tap, an f64 mean and then the division by the
    /// weights' sum cost about a third of the look back).
    #[inline(always)]
    fn blend(&self, taps: [usize; 4], wt: [f32; 4], weight: f32) -> Rgb {
        let n = match self.count {
            Some(count) => taps.map(|i| count[i].max(1) as f32 * weight),
            None => [weight; 4],
        };
        let mut sum = Rgb::ZERO;
        for (i, (wt, n)) in taps.into_iter().zip(wt.into_iter().zip(n)) {
            if wt > 0.0 {
                sum += self.colour[i] * (wt / n) as f64;
            }
        }
        sum
    }
}

/// Working memory of [`warp`], kept from call to call.
#[derive(Debug, Default)]
pub struct Scratch {
    /// Per new pixel, the nearest point splatted on it: [`key`].
    /// Plain integers outside step 1 (so that step 2's reads of three rows
    /// at a time run in SIMD registers: atomic loads do not).
    splat: Vec<u32>,
    /// Seconds the last warp's step 1 took (of its whole time, which the
    /// caller measures).
    pub splat_s: f64,
}

/// What a splat key says besides depth (its two low bits): the classes of
/// [`FirstHit`]'s own two low bits, so the two packings stay one (a
/// surface's is 0; an unknown first hit is splatted nowhere).
const UNKNOWN: u32 = Seen::Unknown as u32;
const SKY: u32 = Seen::Sky as u32;
const SPECULAR: u32 = Seen::Specular as u32;
/// No splat.
const EMPTY: u32 = u32::MAX;

/// A splat key: the depth's bits (positive, so ordered as integers) with
/// the class in the two low bits: the minimum is the nearest point
/// whatever order the splats come in.
#[inline]
fn key(z: f32, class: u32) -> u32 {
    (z.to_bits() & !3) | class
}

/// Rows of new pixels per parallel task of step 2.
const ROWS: usize = 8;

/// Steps 1 and 2: the old picture in the new view `cam` (`w × h`, the same
/// size), into `out` and `out_first`; pixels left for step 3 get
/// [`Seen::Unknown`]. Returns how many.
pub fn warp(
    src: &Source,
    cam: &Camera,
    (w, h): (u32, u32),
    scratch: &mut Scratch,
    out: &mut [Rgb],
    out_first: &mut [FirstHit],
) -> usize {
    let (wu, hu) = (w as usize, h as usize);
    let t = web_time::Instant::now();
    splat(src, cam, (w, h), scratch);
    scratch.splat_s = t.elapsed().as_secs_f64();
    let splat = &scratch.splat[..wu * hu];
    let back = Back {
        splat,
        src,
        size: (wu, hu),
        to_new: Projector::new(cam, (w, h)),
        to_old: Projector::new(src.camera, src.size),
        shift: (cam.position - src.camera.position).as_vec3(),
    };
    out.par_chunks_mut(wu * ROWS)
        .zip(out_first.par_chunks_mut(wu * ROWS))
        .enumerate()
        .map(|(band, (rows, firsts))| {
            // Per column, the least key of the three rows around, and the
            // least of them that is glass or a mirror.
            let (mut near, mut spec) = (vec![EMPTY; wu + 2], vec![EMPTY; wu + 2]);
            let mut holes = 0;
            for (r, (row, first)) in rows.chunks_mut(wu).zip(firsts.chunks_mut(wu)).enumerate() {
                let y = band * ROWS + r;
                column_minima(splat, (wu, hu), y, &mut near, &mut spec);
                holes += back.row(y, (&near, &spec), row, first);
            }
            holes
        })
        .sum()
}

/// What step 2 reads.
struct Back<'a> {
    splat: &'a [u32],
    src: &'a Source<'a>,
    size: (usize, usize),
    to_new: Projector,
    to_old: Projector,
    /// The new camera's position less the old one's.
    shift: Vec3,
}

impl Back<'_> {
    /// Step 2 for row `y` (`near`, `spec`: [`column_minima`]), [`LANES`]
    /// pixels at a time: each takes a splat's depth, puts that point on its
    /// own centre ray, projects it into the old view and interpolates the
    /// old colours there ([`taps`]). Returns the pixels left.
    fn row(&self, y: usize, (near, spec): (&[u32], &[u32]), row: &mut [Rgb], first: &mut [FirstHit]) -> usize {
        let w = self.size.0;
        let mut holes = 0;
        let (row0, dx) = self.to_new.row_rays(y);
        for x0 in (0..w).step_by(LANES) {
            let m = (w - x0).min(LANES);
            let mut k = [SPECULAR; LANES];
            for (l, k) in k.iter_mut().enumerate().take(m) {
                let x = x0 + l;
                *k = pick(self.splat[y * w + x], &near[x..x + 3], &spec[x..x + 3]);
            }
            // The points (less the new camera position) and where they lie
            // in the old view, lane by lane without branches.
            let (mut rel, mut at) = ([Vec3::ZERO; LANES], [(0.0, 0.0, 0.0); LANES]);
            for l in 0..LANES {
                let sky = k[l] & 3 == SKY;
                let d = row0 + dx * (x0 + l) as f32;
                rel[l] = d * if sky { 1.0 } else { f32::from_bits(k[l] & !3) };
                at[l] = self.to_old.project_any(if sky { d } else { self.shift + rel[l] });
            }
            for l in 0..m {
                let (class, (u, v, z)) = (k[l] & 3, at[l]);
                let taken = (class != SPECULAR && z > 0.0)
                    .then(|| taps(self.src, (u, v), (class != SKY).then_some(z)))
                    .flatten();
                let x = x0 + l;
                first[x] = match taken {
                    Some(c) => {
                        row[x] = c;
                        match class {
                            SKY => FirstHit::new(Seen::Sky, 0.0),
                            _ => FirstHit::new(Seen::Surface, f32::from_bits(k[l] & !3)),
                        }
                    }
                    None => {
                        holes += 1;
                        FirstHit::UNKNOWN
                    }
                };
            }
        }
        holes
    }
}

/// Step 1: every old pixel's point splatted on the new view, keeping the
/// nearest per new pixel (glass and mirrors too, so that they hide what is
/// behind them). It reads only the old first hits (their colours are read
/// by [`taps`], where they are taken: a pass that copied them into a
/// buffer of its own cost more than the look back's reads).
fn splat(src: &Source, cam: &Camera, (w, h): (u32, u32), scratch: &mut Scratch) {
    let n = w as usize * h as usize;
    // The cells as atomics for the parallel splat, cleared, and back to
    // plain integers after it (both in place: the allocation is kept).
    let mut cells: Vec<AtomicU32> = std::mem::take(&mut scratch.splat)
        .into_iter()
        .map(|_| AtomicU32::new(EMPTY))
        .collect();
    cells.resize_with(n, || AtomicU32::new(EMPTY));
    splat_into(src, cam, (w, h), &cells);
    scratch.splat = cells.into_iter().map(AtomicU32::into_inner).collect();
}

/// [`splat`] into `splat`, cleared.
fn splat_into(src: &Source, cam: &Camera, (w, h): (u32, u32), splat: &[AtomicU32]) {
    let to_new = Projector::new(cam, (w, h));
    let shift = (src.camera.position - cam.position).as_vec3();
    // The old pixels' centre rays, scaled to depth 1 in the old view.
    let from_old = Projector::new(src.camera, src.size);
    let old_w = src.size.0 as usize;
    let (wf, hf) = (w as f32, h as f32);
    src.first.par_chunks(old_w.max(1)).enumerate().for_each(|(y, firsts)| {
        let (row0, dx) = from_old.row_rays(y);
        for (c, firsts) in firsts.chunks(LANES).enumerate() {
            let x0 = c * LANES;
            // Where the points (the directions, for the background) land,
            // lane by lane without branches (a lane past the row's end
            // projects a point that is not used).
            let (mut xs, mut ys, mut zs) = ([0.0; LANES], [0.0; LANES], [0.0; LANES]);
            for l in 0..LANES {
                let f = firsts.get(l).copied().unwrap_or(FirstHit::UNKNOWN);
                let dir = row0 + dx * (x0 + l) as f32;
                let sky = f.seen() == Seen::Sky;
                (xs[l], ys[l], zs[l]) = to_new.project_any(if sky { dir } else { dir * f.depth() + shift });
            }
            for (l, f) in firsts.iter().enumerate() {
                // The class is the first hit's own two low bits.
                let (class, x, y, z) = (f.seen() as u32, xs[l], ys[l], zs[l]);
                if class == UNKNOWN || !(z > 0.0 && x >= 0.0 && y >= 0.0 && x < wf && y < hf) {
                    continue;
                }
                let k = key(if class == SKY { f32::MAX } else { z }, class);
                let cell = &splat[(y as i32 * w as i32 + x as i32) as usize];
                if k < cell.load(Ordering::Relaxed) {
                    cell.fetch_min(k, Ordering::Relaxed);
                }
            }
        }
    });
}

/// For row `y`: per column `x` (at `x + 1`; the ends stay [`EMPTY`]) the
/// least key of rows `y − 1 ..= y + 1` into `near`, and the least of
/// those that is glass or a mirror into `spec`.
fn column_minima(splat: &[u32], (w, h): (usize, usize), y: usize, near: &mut [u32], spec: &mut [u32]) {
    near[1..=w].fill(EMPTY);
    spec[1..=w].fill(EMPTY);
    for y2 in y.saturating_sub(1)..(y + 2).min(h) {
        let row = &splat[y2 * w..(y2 + 1) * w];
        for ((&k, n), s) in row.iter().zip(&mut near[1..=w]).zip(&mut spec[1..=w]) {
            *n = (*n).min(k);
            *s = (*s).min(if k & 3 == SPECULAR { k } else { EMPTY });
        }
    }
}

/// The key a new pixel takes from its own splat `own` and the column
/// minima around it: its own, else the nearest on a neighbour (for the
/// gaps a forward move opens). Glass or a mirror splatted nearer on a
/// neighbour may cover the pixel now (its silhouette moved): then, as for
/// no splat at all, a key of class [`SPECULAR`], left to step 3.
#[inline]
fn pick(own: u32, near: &[u32], spec: &[u32]) -> u32 {
    let spec = spec[0].min(spec[1]).min(spec[2]);
    let near = near[0].min(near[1]).min(near[2]);
    match own {
        _ if spec < own => spec,
        EMPTY if near == EMPTY => SPECULAR,
        EMPTY => near,
        _ => own,
    }
}

/// The old picture's colour at continuous position `(u, v)`, bilinear over
/// the taps that saw a surface within [`DEPTH_TOLERANCE`] of depth `z`
/// (the background, when `z` is `None`); `None` if none did.
#[inline]
fn taps(src: &Source, (u, v): (f32, f32), z: Option<f32>) -> Option<Rgb> {
    let (w, h) = (src.size.0 as i32, src.size.1 as i32);
    let (u, v) = (u - 0.5, v - 0.5);
    if !(u > -1.0 && v > -1.0 && u < w as f32 && v < h as f32) {
        return None;
    }
    // Floor, for positions above −1.
    let (u0, v0) = ((u + 1.0) as i32 - 1, (v + 1.0) as i32 - 1);
    let (fu, fv) = (u - u0 as f32, v - v0 as f32);
    // Taps off the picture weigh nothing (their indices are clamped).
    let wx = [if u0 >= 0 { 1.0 - fu } else { 0.0 }, if u0 + 1 < w { fu } else { 0.0 }];
    let wy = [if v0 >= 0 { 1.0 - fv } else { 0.0 }, if v0 + 1 < h { fv } else { 0.0 }];
    let xs = [u0.max(0), (u0 + 1).min(w - 1)];
    let ys = [v0.max(0), (v0 + 1).min(h - 1)];
    let at = [(0, 0), (0, 1), (1, 0), (1, 1)];
    let taps = at.map(|(j, i)| (ys[j] * w + xs[i]) as usize);
    let mut wt = at.map(|(j, i)| wy[j] * wx[i]);
    for (wt, i) in wt.iter_mut().zip(taps) {
        let t = src.first[i];
        let same = match z {
            None => t.seen() == Seen::Sky,
            Some(z) => t.seen() == Seen::Surface && (t.depth() - z).abs() <= DEPTH_TOLERANCE * z,
        };
        if !same {
            *wt = 0.0;
        }
    }
    let weight: f32 = wt.iter().sum();
    (weight > 1e-3).then(|| src.blend(taps, wt, weight))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::progressive::{Progressive, Sampling, Stage};
    use glam::DVec3;

    /// `scene` with its camera moved by `by` (world units).
    fn moved(scene: &Scene, by: DVec3) -> Scene {
        let c = &scene.camera;
        Scene {
            camera: Camera::new(c.position + by, c.rotation_deg, c.fov_y_deg),
            ..scene.clone()
        }
    }

    /// `old`'s picture (`img`) seen from `camera`, as a warp's source.
    fn source<'a>(
        camera: &'a Camera,
        size: (u32, u32),
        img: &'a crate::render::Image,
        old: &'a Progressive,
    ) -> Source<'a> {
        Source {
            camera,
            size,
            colour: &img.pixels,
            count: None,
            first: old.first_hits().expect("first hits recorded"),
        }
    }

    fn one_sample(scene: &Scene, (w, h): (u32, u32)) -> Progressive {
        let mut p = Progressive::new(w, h, 0).with_sampling(Sampling::UNIFORM);
        assert!(p.run(scene, Stage::Samples(1), &|| false));
        assert!(p.first_hits().is_none(), "a sample stage recorded first hits");
        assert!(p.record_first_hits(scene, &|| false));
        p
    }

    /// A pure camera translation of the default scene (cubes, a lens):
    /// pixels moved from the old picture match a fresh render of the new
    /// view wherever that render is flat around them; pixels left to step
    /// 3 — disocclusions, everything seen through the lens — are the fresh
    /// render's bit for bit; no pixel seen through glass is moved.
    #[test]
    fn a_translated_view_matches_a_fresh_render_outside_disocclusions() {
        let a = Scene::default_scene().1;
        let b = moved(&a, DVec3::new(0.12, 0.05, -0.2));
        assert!(same_but_camera(&a, &b) && a.camera != b.camera);
        let size = (96, 64);
        let (w, h) = (size.0 as usize, size.1 as usize);
        let old = one_sample(&a, size);
        let fresh = one_sample(&b, size);
        let (old_img, new_img) = (old.image(), fresh.image());
        let fresh_first = fresh.first_hits().expect("first hits recorded");
        let src = source(&a.camera, size, &old_img, &old);
        let mut out = vec![Rgb::ZERO; w * h];
        let mut first = vec![FirstHit::default(); w * h];
        let holes = warp(&src, &b.camera, size, &mut Scratch::default(), &mut out, &mut first);
        let left: Vec<bool> = first.iter().map(|f| f.seen() == Seen::Unknown).collect();
        assert_eq!(left.iter().filter(|&&l| l).count(), holes);
        assert_eq!(fill(&b, size, 1, &mut out, &mut first) as usize, holes);
        let (mut moved, mut compared, mut traced) = (0, 0, 0);
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                let want = new_img.pixels[i];
                if fresh_first[i].seen() == Seen::Specular {
                    assert!(left[i], "pixel {x},{y} seen through glass was moved");
                }
                if left[i] {
                    assert_eq!(out[i], want, "traced pixel {x},{y}");
                    assert_eq!(first[i], fresh_first[i]);
                    traced += 1;
                    continue;
                }
                moved += 1;
                let flat = (y.saturating_sub(1)..(y + 2).min(h)).all(|y2| {
                    (x.saturating_sub(1)..(x + 2).min(w))
                        .all(|x2| (new_img.pixels[y2 * w + x2] - want).abs().max_element() < 0.01)
                });
                if flat {
                    let d = (out[i] - want).abs().max_element();
                    assert!(d < 0.01, "moved pixel {x},{y}: {:?} against {want:?}", out[i]);
                    compared += 1;
                }
            }
        }
        assert!(
            moved > w * h / 2 && compared > w * h / 3 && traced > 100,
            "{moved} moved, {compared} compared, {traced} traced"
        );
    }

    /// Warp and fill give the same picture, first hits and hole count on
    /// one thread as on several (the nearest splat wins whatever order the
    /// threads splat in), for a move and a turn.
    #[test]
    fn reprojection_is_the_same_on_any_thread_count() {
        let a = Scene::default_scene().1;
        let size = (80, 56);
        let n = (size.0 * size.1) as usize;
        let old = one_sample(&a, size);
        let old_img = old.image();
        let c = &a.camera;
        let turned = Camera::new(
            c.position + c.right() * 0.05,
            c.rotation_deg + DVec3::new(1.0, 2.0, 0.0),
            c.fov_y_deg,
        );
        for cam in [moved(&a, DVec3::new(0.0, 0.0, -0.3)).camera, turned] {
            let b = Scene {
                camera: cam,
                ..a.clone()
            };
            let on = |threads: usize| {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
                pool.install(|| {
                    let src = source(&a.camera, size, &old_img, &old);
                    let mut out = vec![Rgb::ZERO; n];
                    let mut first = vec![FirstHit::default(); n];
                    let holes = warp(&src, &b.camera, size, &mut Scratch::default(), &mut out, &mut first);
                    fill(&b, size, 2, &mut out, &mut first);
                    (holes, out, first)
                })
            };
            let one = on(1);
            assert!(one.0 > 0 && one.0 < n / 2, "{} holes", one.0);
            for threads in [2, 3] {
                assert!(on(threads) == one, "{threads} threads differ from one");
            }
        }
    }

    /// Of two points splatted on one pixel the nearer wins, though it comes
    /// first: after a step to the left, old pixel `a` (near, red) and its
    /// right neighbour `b` (far, blue) land on the same new pixel `p`,
    /// which shows `a` (a plain store would keep `b`, splatted after it).
    #[test]
    fn the_nearest_splat_wins_whatever_comes_first() {
        let cam = Scene::default_scene().1.camera;
        let size = (8, 8);
        // Pixels per unit of screen coordinate (Projector::new's `sy`).
        let s = 4.0 / (0.5 * cam.fov_y_deg.to_radians()).tan();
        let (a, b) = (4 * 8 + 3, 4 * 8 + 4);
        let mut first = vec![FirstHit::new(Seen::Surface, 5.0); 64];
        first[a] = FirstHit::new(Seen::Surface, 2.0);
        first[b] = FirstHit::new(Seen::Surface, 1000.0);
        let mut colour = vec![Rgb::splat(0.5); 64];
        colour[a] = Rgb::new(1.0, 0.0, 0.0);
        colour[b] = Rgb::new(0.0, 0.0, 1.0);
        let src = Source {
            camera: &cam,
            size,
            colour: &colour,
            count: None,
            first: &first,
        };
        // Two pixels' parallax at depth 2 moves `a` one pixel right, onto
        // `b`'s place; `b`, far, stays.
        let to = Camera::new(cam.position - cam.right() * (2.0 / s), cam.rotation_deg, cam.fov_y_deg);
        let (mut out, mut got) = (vec![Rgb::ZERO; 64], vec![FirstHit::default(); 64]);
        warp(&src, &to, size, &mut Scratch::default(), &mut out, &mut got);
        let p = b;
        assert_eq!(got[p].seen(), Seen::Surface);
        assert!((got[p].depth() - 2.0).abs() < 1e-3, "depth {}", got[p].depth());
        assert!((out[p] - colour[a]).abs().max_element() < 1e-6, "{:?}", out[p]);
    }

    /// Projecting a camera ray's point gives back its pixel position, and
    /// the direction through a position is the camera ray's.
    #[test]
    fn projection_inverts_the_camera_ray() {
        let cam = Camera::new(DVec3::new(1.0, 2.0, 3.0), DVec3::new(-20.0, 30.0, 0.0), 50.0);
        let p = Projector::new(&cam, (320, 200));
        for (x, y) in [(0.5, 0.5), (160.0, 100.0), (319.5, 7.25), (3.0, 199.0)] {
            let r = cam.ray(x, y, 320, 200);
            for v in [r.dir * 7.0, r.dir] {
                let (u, v, _) = p.project(v.as_vec3()).unwrap();
                let (u, v) = (u as f64, v as f64);
                assert!((u - x).abs() < 1e-3 && (v - y).abs() < 1e-3, "{x},{y} → {u},{v}");
            }
            let d = p.direction(x as f32, y as f32).normalize().as_dvec3();
            assert!((d - r.dir).length() < 1e-5, "{d} against {}", r.dir);
        }
        assert!(p.project(-cam.forward().as_vec3()).is_none());
    }
}
