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

use super::sparse::{Batch, FirstHit, Seen};
use crate::camera::Camera;
use crate::color::Rgb;
use crate::scene::Scene;
use crate::simd::LANES;
use crate::trace::TILE;
use glam::DVec3;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};

/// Relative difference of distance (from the old camera) under which an
/// old pixel's point counts as the same surface as a new pixel's.
pub const DEPTH_TOLERANCE: f64 = 0.03;

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

/// A view's projection, its constants worked out once.
#[derive(Clone, Copy, Debug)]
pub struct Projector {
    position: DVec3,
    right: DVec3,
    up: DVec3,
    forward: DVec3,
    /// Pixels per unit of screen coordinate, and the centre.
    sx: f64,
    sy: f64,
    cx: f64,
    cy: f64,
}

impl Projector {
    pub fn new(cam: &Camera, (w, h): (u32, u32)) -> Projector {
        let tan = (0.5 * cam.fov_y_deg.to_radians()).tan();
        let (cx, cy) = (0.5 * w as f64, 0.5 * h as f64);
        Projector {
            position: cam.position,
            right: cam.right(),
            up: cam.up(),
            forward: cam.forward(),
            sx: cx / (tan * w as f64 / h as f64),
            sy: cy / tan,
            cx,
            cy,
        }
    }

    /// The continuous pixel position of world point `p` (or of direction
    /// `p` when `at_infinity`): the inverse of [`Camera::ray`]; `None`
    /// behind the camera.
    #[inline]
    pub fn project(&self, p: DVec3, at_infinity: bool) -> Option<(f64, f64)> {
        let v = if at_infinity { p } else { p - self.position };
        let z = v.dot(self.forward);
        if !(z > 0.0) {
            return None;
        }
        let iz = 1.0 / z;
        Some((
            self.cx + v.dot(self.right) * iz * self.sx,
            self.cy - v.dot(self.up) * iz * self.sy,
        ))
    }
}

/// The picture before the move: its camera, colours and first hits.
pub struct Source<'a> {
    pub camera: &'a Camera,
    pub size: (u32, u32),
    pub colour: &'a [Rgb],
    pub first: &'a [FirstHit],
}

/// A first hit's world point (or direction, for the background).
fn point(cam: &Camera, f: &FirstHit) -> DVec3 {
    let o = DVec3::from(f.offset.map(f64::from));
    if f.seen == Seen::Sky { o } else { cam.position + o }
}

/// Steps 1 and 2: the old picture in the new view `cam` (`w × h`, the same
/// size), into `out` and `out_first`; pixels left for step 3 get
/// [`Seen::Unknown`]. Returns how many.
/// `splat` is working memory, kept from call to call.
pub fn warp(
    src: &Source,
    cam: &Camera,
    (w, h): (u32, u32),
    splat: &mut Vec<AtomicU64>,
    out: &mut [Rgb],
    out_first: &mut [FirstHit],
) -> usize {
    let (wu, hu) = (w as usize, h as usize);
    let n = wu * hu;
    // Step 1: the nearest splat per pixel, as (distance bits << 32) | source.
    // Glass and mirrors take part, so that they hide what is behind them.
    splat.resize_with(n, || AtomicU64::new(u64::MAX));
    splat
        .par_iter_mut()
        .with_min_len(4096)
        .for_each(|s| *s.get_mut() = u64::MAX);
    let splat = &splat[..n];
    let to_new = Projector::new(cam, (w, h));
    src.first.par_iter().enumerate().with_min_len(1024).for_each(|(i, f)| {
        if f.seen == Seen::Unknown {
            return;
        }
        let sky = f.seen == Seen::Sky;
        let p = point(src.camera, f);
        let Some((x, y)) = to_new.project(p, sky) else { return };
        if !(x >= 0.0 && y >= 0.0 && x < w as f64 && y < h as f64) {
            return;
        }
        let d = if sky {
            f32::MAX
        } else {
            (p - cam.position).length() as f32
        };
        let key = ((d.to_bits() as u64) << 32) | i as u64;
        splat[y as usize * wu + x as usize].fetch_min(key, Ordering::Relaxed);
    });
    // Step 2.
    let to_old = Projector::new(src.camera, src.size);
    out.par_chunks_mut(wu)
        .zip(out_first.par_chunks_mut(wu))
        .enumerate()
        .map(|(y, (row, first))| {
            let mut holes = 0;
            for x in 0..wu {
                match look_back(src, &to_old, cam, (w, h), splat, (x, y)) {
                    Some((c, f)) => (row[x], first[x]) = (c, f),
                    None => {
                        first[x] = FirstHit::default();
                        holes += 1;
                    }
                }
            }
            holes
        })
        .sum()
}

/// Step 2 for new pixel `(x, y)`: its colour and first hit, or `None`.
fn look_back(
    src: &Source,
    to_old: &Projector,
    cam: &Camera,
    (w, h): (u32, u32),
    splat: &[AtomicU64],
    (x, y): (usize, usize),
) -> Option<(Rgb, FirstHit)> {
    let wu = w as usize;
    let at = |i: usize| splat[i].load(Ordering::Relaxed);
    let source = |key: u64| &src.first[(key & 0xffff_ffff) as usize];
    // The splat on the pixel, else the nearest on a neighbour. Glass or a
    // mirror splatted nearer on a neighbour may cover this pixel now (its
    // silhouette moved): left to step 3.
    let own = at(y * wu + x);
    let mut nearest = u64::MAX;
    for y2 in y.saturating_sub(1)..(y + 2).min(h as usize) {
        for x2 in x.saturating_sub(1)..(x + 2).min(wu) {
            let k = at(y2 * wu + x2);
            if k < own && source(k).seen == Seen::Specular {
                return None;
            }
            nearest = nearest.min(k);
        }
    }
    let key = if own == u64::MAX { nearest } else { own };
    if key == u64::MAX || source(key).seen == Seen::Specular {
        return None;
    }
    let from = source(key);
    let sky = from.seen == Seen::Sky;
    let dir = cam.ray(x as f64 + 0.5, y as f64 + 0.5, w, h).dir;
    let (p, first) = if sky {
        (
            dir,
            FirstHit {
                offset: dir.as_vec3().to_array(),
                seen: Seen::Sky,
            },
        )
    } else {
        let d = f32::from_bits((key >> 32) as u32) as f64;
        let p = cam.position + dir * d;
        (
            p,
            FirstHit {
                offset: (dir * d).as_vec3().to_array(),
                seen: Seen::Surface,
            },
        )
    };
    let (u, v) = to_old.project(p, sky)?;
    taps(src, (w, h), (u, v), p, sky).map(|c| (c, first))
}

/// The old picture's colour at continuous position `(u, v)`, bilinear over
/// the taps that saw `p` (the background when `sky`); `None` if none did.
fn taps(src: &Source, (w, h): (u32, u32), (u, v): (f64, f64), p: DVec3, sky: bool) -> Option<Rgb> {
    let wu = w as usize;
    let (u, v) = (u - 0.5, v - 0.5);
    let (u0, v0) = (u.floor(), v.floor());
    let (fu, fv) = (u - u0, v - v0);
    let old_d = (p - src.camera.position).length();
    let (mut sum, mut weight) = (Rgb::ZERO, 0.0);
    let corners = [
        (0, 0, (1.0 - fu) * (1.0 - fv)),
        (1, 0, fu * (1.0 - fv)),
        (0, 1, (1.0 - fu) * fv),
        (1, 1, fu * fv),
    ];
    for (dx, dy, wt) in corners {
        let (tx, ty) = (u0 as i64 + dx, v0 as i64 + dy);
        if tx < 0 || ty < 0 || tx >= w as i64 || ty >= h as i64 || wt <= 0.0 {
            continue;
        }
        let k = ty as usize * wu + tx as usize;
        let t = &src.first[k];
        let same = match t.seen {
            Seen::Sky => sky,
            Seen::Surface if !sky => {
                let td = glam::Vec3::from(t.offset).length() as f64;
                (td - old_d).abs() <= DEPTH_TOLERANCE * old_d
            }
            _ => false,
        };
        if same {
            sum += src.colour[k] * wt;
            weight += wt;
        }
    }
    (weight > 1e-3).then(|| sum / weight)
}

/// Step 3: traces the pixels [`warp`] left ([`Seen::Unknown`]): at their
/// centres when `block` is 1 (they get their first hits too), else one
/// sample at the centre of each `block × block` block holding some (the
/// point a block level samples), which fills them. Returns the samples
/// cast.
pub fn fill(scene: &Scene, (w, h): (u32, u32), block: u32, out: &mut [Rgb], first: &mut [FirstHit]) -> u64 {
    let (wu, n) = (w as usize, block.max(1) as usize);
    // Bands of block rows, or for single pixels of a tile's height.
    let band = if n == 1 { TILE } else { n };
    out.par_chunks_mut(wu * band)
        .zip(first.par_chunks_mut(wu * band))
        .enumerate()
        .map(|(by, (rows, first))| {
            let rows_here = rows.len() / wu;
            let is_hole = |i: usize| first[i].seen == Seen::Unknown;
            // The holes (n = 1) or the blocks holding some, as destinations.
            let dst: Vec<u32> = if n == 1 {
                // By columns of a packet's width, as the tiles go.
                let per_column =
                    |x0: usize| (0..rows_here).flat_map(move |r| (x0..(x0 + LANES).min(wu)).map(move |x| r * wu + x));
                (0..wu)
                    .step_by(LANES)
                    .flat_map(per_column)
                    .filter(|&i| is_hole(i))
                    .map(|i| i as u32)
                    .collect()
            } else {
                (0..wu.div_ceil(n))
                    .filter(|&bx| (0..rows_here).any(|r| (bx * n..((bx + 1) * n).min(wu)).any(|x| is_hole(r * wu + x))))
                    .map(|bx| bx as u32)
                    .collect()
            };
            let mut colours = vec![Rgb::ZERO; if n == 1 { 0 } else { wu.div_ceil(n) }];
            let mut batch = Batch::default();
            {
                let mut sink = |d: u32, c: Rgb, f: &dyn Fn() -> FirstHit| {
                    if n == 1 {
                        (rows[d as usize], first[d as usize]) = (c, f());
                    } else {
                        colours[d as usize] = c;
                    }
                };
                let cy = (by * n + n / 2).min(h as usize - 1);
                for &d in &dst {
                    let (x, y) = if n == 1 {
                        (d as usize % wu, by * band + d as usize / wu)
                    } else {
                        ((d as usize * n + n / 2).min(wu - 1), cy)
                    };
                    batch.push(scene, (w, h), (x as f64 + 0.5, y as f64 + 0.5), d, &mut sink);
                }
                batch.flush(scene, (w, h), &mut sink);
            }
            if n > 1 {
                for r in 0..rows_here {
                    for x in 0..wu {
                        if first[r * wu + x].seen == Seen::Unknown {
                            rows[r * wu + x] = colours[x / n];
                        }
                    }
                }
            }
            dst.len() as u64
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::progressive::{Progressive, Sampling, Stage};

    /// `scene` with its camera moved by `by` (world units).
    fn moved(scene: &Scene, by: DVec3) -> Scene {
        let c = &scene.camera;
        Scene {
            camera: Camera::new(c.position + by, c.rotation_deg, c.fov_y_deg),
            ..scene.clone()
        }
    }

    fn one_sample(scene: &Scene, (w, h): (u32, u32)) -> Progressive {
        let mut p = Progressive::new(w, h, 0).with_sampling(Sampling::UNIFORM);
        assert!(p.run(scene, Stage::Samples(1), &|| false));
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
        let src = Source {
            camera: &a.camera,
            size,
            colour: &old_img.pixels,
            first: old.first_hits(),
        };
        let mut out = vec![Rgb::ZERO; w * h];
        let mut first = vec![FirstHit::default(); w * h];
        let holes = warp(&src, &b.camera, size, &mut Vec::new(), &mut out, &mut first);
        let left: Vec<bool> = first.iter().map(|f| f.seen == Seen::Unknown).collect();
        assert_eq!(left.iter().filter(|&&l| l).count(), holes);
        assert_eq!(fill(&b, size, 1, &mut out, &mut first) as usize, holes);
        let (mut moved, mut compared, mut traced) = (0, 0, 0);
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                let want = new_img.pixels[i];
                if fresh.first_hits()[i].seen == Seen::Specular {
                    assert!(left[i], "pixel {x},{y} seen through glass was moved");
                }
                if left[i] {
                    assert_eq!(out[i], want, "traced pixel {x},{y}");
                    assert_eq!(first[i], fresh.first_hits()[i]);
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

    /// Projecting a camera ray's point gives back its pixel position.
    #[test]
    fn projection_inverts_the_camera_ray() {
        let cam = Camera::new(DVec3::new(1.0, 2.0, 3.0), DVec3::new(-20.0, 30.0, 0.0), 50.0);
        let p = Projector::new(&cam, (320, 200));
        for (x, y) in [(0.5, 0.5), (160.0, 100.0), (319.5, 7.25), (3.0, 199.0)] {
            let r = cam.ray(x, y, 320, 200);
            for (q, inf) in [(r.origin + r.dir * 7.0, false), (r.dir, true)] {
                let (u, v) = p.project(q, inf).unwrap();
                assert!((u - x).abs() < 1e-9 && (v - y).abs() < 1e-9, "{x},{y} → {u},{v}");
            }
        }
        assert!(p.project(cam.position - cam.forward(), false).is_none());
    }
}
