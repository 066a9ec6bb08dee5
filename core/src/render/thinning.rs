//! Fewer gathers where the caustic is smooth at the scale of a pixel:
//! where the photons' gather radius spans half a pixel's footprint or
//! more ([`THIN_FROM`]), the estimate changes little across a pixel, so
//! its camera samples gather the same light over and over. There one sample in `P` of each stage
//! gathers, counting `P` times ([`crate::integrator::Lit::for_sample`]):
//! a stage's mean has the caustic's full weight (an unbiased estimate of
//! the same image), with fewer gathers (with `P` = 4, 6 samples of 16 and
//! 18 of 64 gather), which were most of what caustics cost where the
//! caustic covers the floor (rim-lens: 29 % of a frame, `perf`). The gathers saved buy more photons
//! ([`THINNED_PHOTONS`]): with them the caustic's error is what it was
//! (docs/performance.md, round 24).
//!
//! `P` depends on the camera, never the photon map's contents: the map is
//! the same for every camera; only how often it is read changes.

use crate::integrator::Lit;
use crate::photon::PhotonMap;
use crate::scene::Scene;

/// The most samples one gather stands for.
pub const MOST_THINNING: u32 = 4;
/// The gather radius, in pixel footprints, from which one sample in 2,
/// then one sample in 4, gathers. One in 2 from half a footprint (round
/// 27; two footprints before): since the photons leave their lights evenly
/// spread (`integrator::emission::emission_point`), the quarter more
/// photons a thinned frame traces ([`THINNED_PHOTONS`]) buy more than
/// the gathers it drops lose, down to radii of half a pixel: against
/// 256-spp references the caustic pixels' error at 16 and 64 spp is below
/// the unthinned frame's of round 26 in every shipped scene, in less time
/// (docs/performance.md, round 27). One in 4 still from four footprints:
/// from one footprint it raised lens-family's error at 64 spp by a third
/// (likely because its caustic is seen through other lenses, where a
/// pixel's footprint is smaller than the pinhole's this measures; not
/// checked pixel by pixel). One entry per doubling up to
/// [`MOST_THINNING`].
pub const THIN_FROM: [f64; MOST_THINNING.trailing_zeros() as usize] = [0.5, 4.0];

/// The share of the photons (of `PhotonMap::spread`) that must lie in the
/// camera's field of view for its gathers to be thinned.
pub const IN_VIEW: f64 = 0.125;

/// Photons traced where gathers are thinned, for each photon the frame
/// affords without thinning.
pub const THINNED_PHOTONS: f64 = 1.25;

/// The same for the viewer's adaptive waves ([`wave_photon_factor`]): a
/// wave spends its samples where pixels are noisy, so its thinned pixels
/// gather fewer times for their samples than a stage's do, and more
/// photons keep the caustic's error (docs/performance.md, round 25).
pub const WAVE_THINNED_PHOTONS: f64 = 1.5;

/// One sample in how many gathers in a frame of `scene` (its camera)
/// `width`×`height` pixels, for photons spread as `map`'s
/// (`PhotonMap::spread`) gathered within `radius`: the largest power of two
/// `P` up to [`MOST_THINNING`] whose [`THIN_FROM`] the radius reaches, in
/// pixel footprints where the camera sees the photons (the median
/// distance from the camera of those in its field of view, times the
/// angle of a pixel).
/// 1 with a lens camera (whose pixels' footprints are not a pinhole's), or
/// where fewer than [`IN_VIEW`] of the photons lie in the field of view:
/// there few samples gather near photons, so thinning saves little, while
/// the photons it buys ([`THINNED_PHOTONS`]) cost their whole price
/// (cubes, whose caustic lies mostly out of view: round 25).
pub fn gather_thinning(scene: &Scene, map: &PhotonMap, radius: f64, (width, height): (u32, u32)) -> u32 {
    if scene.lens.is_some() || height == 0 || width == 0 {
        return 1;
    }
    let cam = &scene.camera;
    let (forward, right, up) = (cam.forward(), cam.right(), cam.up());
    let tan_y = cam.tan_half_fov();
    let tan_x = tan_y * width as f64 / height as f64;
    let mut far: Vec<f64> = map
        .spread()
        .iter()
        .map(|&p| p - cam.position)
        .filter(|v| {
            let z = v.dot(forward);
            z > 0.0 && v.dot(right).abs() <= z * tan_x && v.dot(up).abs() <= z * tan_y
        })
        .map(|v| v.length())
        .collect();
    if far.is_empty() || (far.len() as f64) < IN_VIEW * map.spread().len() as f64 {
        return 1;
    }
    let mid = far.len() / 2;
    let (_, &mut median, _) = far.select_nth_unstable_by(mid, f64::total_cmp);
    let pixel = 2.0 * tan_y / height as f64;
    let footprints = radius / (median * pixel);
    let mut p = 1;
    // NaN or infinite ratios (a degenerate camera) leave it at 1.
    while p < MOST_THINNING && footprints.is_finite() && footprints >= THIN_FROM[p.trailing_zeros() as usize] {
        p *= 2;
    }
    p
}

/// [`gather_thinning`] of the map `lit` shades with, at its latest radius
/// (what the viewer thins its stages by), for a `width`×`height` frame.
pub fn thinning_of(lit: &Lit, size: (u32, u32)) -> u32 {
    lit.caustics
        .map_or(1, |map| gather_thinning(lit.scene, map, map.radius(), size))
}

/// The thinning a stage of samples `from..to` of every pixel uses for a
/// frame's thinning `p`: the largest power of two up to `p` that divides
/// both `from` and the stage's samples (so that the samples that gather,
/// `from, from + q, …`, each stand for exactly `q` of the stage's). The
/// viewer's stages double (1, 2, 4, … samples), so a stage of `m` samples
/// is thinned by up to `m`.
pub fn stage_thinning(p: u32, from: u32, to: u32) -> u32 {
    let n = to.saturating_sub(from);
    let mut q = p.clamp(1, MOST_THINNING).next_power_of_two();
    while q > 1 && (from % q != 0 || n % q != 0 || q > p) {
        q /= 2;
    }
    q
}

/// The stage of samples `from..to` that sample `i` of `spp` belongs to
/// in `render`: the viewer's doubling stages (`0..1`, `1..2`, `2..4`,
/// `4..8`, …, the last cut at `spp`), so that a picture of any power of
/// two samples (and the finished one) has each stage's full caustic, and
/// a still has the gathers of the viewer's stages.
pub fn sample_stage(i: u32, spp: u32) -> (u32, u32) {
    if i == 0 {
        return (0, 1);
    }
    let from = 1 << (31 - i.leading_zeros());
    (from, from.saturating_mul(2).min(spp.max(i + 1)))
}

/// What sample `i` of `spp` gathers in `render` ([`sample_stage`]),
/// thinned as `lit` says (`Lit::thinned`).
pub fn lit_for_sample<'a>(lit: &Lit<'a>, i: u32, spp: u32) -> Lit<'a> {
    let (from, to) = sample_stage(i, spp);
    lit.for_sample(i, from, stage_thinning(lit.thin(), from, to))
}

/// What camera sample `i` of `spp` gathers counts for where one sample in
/// `thin` gathers ([`lit_for_sample`]'s thinning, as a number: 0 where
/// it gathers nothing), and the thinning `q` of its stage
/// ([`stage_thinning`] of [`sample_stage`]): for samples cast one by one
/// in a batch of many pixels' (the viewer's adaptive waves,
/// `Lit::with_lane_weights`).
pub fn sample_weight(thin: u32, i: u32, spp: u32) -> (u32, u32) {
    let (from, to) = sample_stage(i, spp);
    let q = stage_thinning(thin, from, to);
    (Lit::sample_counts(i, from, q), q)
}

/// The observations a pixel's first `n` samples make where the stages
/// of samples are thinned by `thin` ([`sample_stage`], [`stage_thinning`]):
/// each unthinned sample one, each group of `q` samples of a stage thinned
/// by `q` (one gathers for all) one. With `thin` = 1, `n`. What the
/// standard error of an adaptive wave divides by (`render::adaptive`).
pub fn observations(thin: u32, n: u32) -> u32 {
    if thin <= 1 {
        return n;
    }
    let (mut from, mut m) = (0, 0);
    while from < n {
        let (_, to) = sample_stage(from, n);
        m += (to - from) / stage_thinning(thin, from, to);
        from = to;
    }
    m
}

/// The photons a frame traces for each it affords unthinned.
pub fn photon_factor(thin: u32) -> f64 {
    if thin > 1 { THINNED_PHOTONS } else { 1.0 }
}

/// The photons an adaptive wave thinned by `thin` traces for each it
/// affords unthinned.
pub fn wave_photon_factor(thin: u32) -> f64 {
    if thin > 1 { WAVE_THINNED_PHOTONS } else { 1.0 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::color::Rgb;
    use crate::render::caustics::{CausticSettings, caustic_map};
    use crate::render::{RenderSettings, render, render_pixel};

    fn rim_lens() -> Scene {
        Scene::parse("rim-lens", include_str!("../../../scenes/rim-lens.toml"))
            .unwrap()
            .1
    }

    /// Thinned, `render`'s packets and the scalar path (`render_pixel`)
    /// still agree bit for bit; the picture differs from the unthinned one
    /// only by noise: the caustic's light over the picture is the same
    /// within 3 %, and it is there (thinned samples gather).
    #[test]
    fn thinned_renders_agree_and_keep_the_caustics_light() {
        let scene = rim_lens();
        let map = caustic_map(&scene, 2, CausticSettings::default()).unwrap();
        let s = RenderSettings {
            width: 64,
            height: 36,
            spp: 16,
            seed: 3,
        };
        let total = |lit: Lit| render(lit, &s, None).pixels.iter().fold(Rgb::ZERO, |a, &p| a + p);
        let (thin, full) = (Lit::new(&scene, Some(&map)).thinned(4), Lit::new(&scene, Some(&map)));
        let img = render(thin, &s, None);
        for y in (0..s.height).step_by(3) {
            for x in 0..s.width {
                assert_eq!(img.get(x, y), render_pixel(thin, x, y, &s), "pixel {x},{y}");
            }
        }
        assert_ne!(img, render(full, &s, None), "thinning changes which samples gather");
        let none = total(Lit::new(&scene, None));
        let (a, b) = (total(thin) - none, total(full) - none);
        for c in 0..3 {
            assert!(
                b[c] > 0.01 * none[c],
                "channel {c}: the caustic is a visible share: {b:?} of {none:?}"
            );
            assert!(
                (a[c] / b[c] - 1.0).abs() < 0.03,
                "channel {c}: thinned {a:?}, every sample {b:?}"
            );
        }
    }

    /// Where the caustic's radius spans pixels (rim-lens at 640×360) one
    /// sample in four gathers; where it is under a pixel (a 32nd of the
    /// pixels a side), every sample; every sample where no photon lies in
    /// front of the camera, where they all lie far from it, or where few
    /// lie in its field of view.
    #[test]
    fn the_thinning_follows_the_pixels_footprint() {
        let scene = rim_lens();
        let map = caustic_map(&scene, 3, CausticSettings::default()).unwrap();
        let lit = Lit::new(&scene, Some(&map));
        assert_eq!(thinning_of(&lit, (640, 360)), 4);
        // About a footprint (an eighth of the pixels a side): one in two
        // (round 27; two footprints were needed before).
        assert_eq!(thinning_of(&lit, (80, 45)), 2);
        assert_eq!(thinning_of(&lit, (20, 360 / 32)), 1);
        assert_eq!(thinning_of(&Lit::new(&scene, None), (640, 360)), 1);
        let away = glam::DVec3::new(0.0, 0.0, 1e3);
        let mut behind = scene.clone();
        behind.camera = crate::camera::Camera::new(away, glam::DVec3::new(0.0, 180.0, 0.0), 38.0);
        assert_eq!(
            thinning_of(&Lit::new(&behind, Some(&map)), (640, 360)),
            1,
            "no photon in front of the camera"
        );
        behind.camera = crate::camera::Camera::new(away, glam::DVec3::ZERO, 38.0);
        assert_eq!(thinning_of(&Lit::new(&behind, Some(&map)), (640, 360)), 1, "far away");
        // Cubes: a radius of about ten footprints, but the caustic lies
        // mostly out of view (under a twelfth of the photons in it).
        let cubes = Scene::default_scene().1;
        let map = caustic_map(&cubes, 3, CausticSettings::default()).unwrap();
        let all = gather_thinning(&cubes, &map, map.radius(), (640, 360));
        assert_eq!(all, 1, "cubes: few photons in view");
        // The same camera turned toward the photons' middle: thinned.
        let mut facing = cubes.clone();
        let n = map.spread().len() as f64;
        let middle = map.spread().iter().fold(glam::DVec3::ZERO, |a, &p| a + p) / n;
        let turn = crate::math::angles_looking_along(middle - cubes.camera.position);
        facing.camera = crate::camera::Camera::new(cubes.camera.position, turn, cubes.camera.fov_y_deg);
        assert!(
            gather_thinning(&facing, &map, map.radius(), (640, 360)) > 1,
            "cubes facing its caustic"
        );
    }

    /// Each stage's gathering samples weigh as much as its samples: the
    /// estimate of every stage is unbiased, whatever the stage.
    #[test]
    fn the_gathers_of_a_stage_weigh_its_samples() {
        for p in 1..=8 {
            for from in 0..40 {
                for to in from..80 {
                    let q = stage_thinning(p, from, to);
                    assert!(
                        q.is_power_of_two() && q <= p.min(MOST_THINNING),
                        "{p} {from}..{to}: {q}"
                    );
                    let gathered: u32 = (from..to).filter(|i| (i - from) % q == 0).map(|_| q).sum();
                    assert_eq!(gathered, to - from, "{p} {from}..{to}");
                }
            }
        }
        // The viewer's doubling stages, thinned as far as the frame allows.
        assert_eq!(stage_thinning(4, 0, 1), 1);
        assert_eq!(stage_thinning(4, 1, 2), 1);
        assert_eq!(stage_thinning(4, 2, 4), 2);
        assert_eq!(stage_thinning(4, 4, 8), 4);
        assert_eq!(stage_thinning(4, 32, 64), 4);
        assert_eq!(stage_thinning(2, 32, 64), 2);
        assert_eq!(stage_thinning(4, 0, 16), 4);
        assert_eq!(stage_thinning(4, 0, 6), 2);
        assert_eq!(stage_thinning(4, 8, 9), 1);
    }

    /// A sample's weight alone (`sample_weight`, the adaptive waves') is
    /// what `lit_for_sample` gives it, and the samples up to any count
    /// whose stages are whole weigh that count; the observations are the
    /// gathering samples (6 of 16 and 18 of 64 thinned by 4), each sample
    /// unthinned.
    #[test]
    fn sample_weights_are_the_samples_thinning() {
        let scene = rim_lens();
        let map = caustic_map(&scene, 1, CausticSettings::default()).unwrap();
        for thin in [1, 2, 4] {
            let lit = Lit::new(&scene, Some(&map)).thinned(thin);
            for spp in [1, 5, 16, 48, 64] {
                let mut total = 0;
                for i in 0..spp {
                    let (w, _) = sample_weight(thin, i, spp);
                    let alone = lit_for_sample(&lit, i, spp);
                    let e = Rgb::ONE;
                    let want = if alone.caustics.is_some() {
                        alone.counted(e).x as u32
                    } else {
                        0
                    };
                    assert_eq!(w, want, "thin {thin}, sample {i} of {spp}");
                    total += w;
                }
                assert_eq!(total, spp, "thin {thin}, {spp} samples");
                let gathering = (0..spp).filter(|&i| sample_weight(thin, i, spp).0 > 0).count() as u32;
                assert_eq!(observations(thin, spp), gathering, "thin {thin}, {spp} samples");
            }
            assert_eq!(observations(thin, 64), [64, 33, 18][thin.trailing_zeros() as usize]);
        }
        assert_eq!(observations(4, 16), 6);
    }

    /// `render`'s stages are the viewer's: doubling, the last cut at the
    /// samples asked for; every sample in one.
    #[test]
    fn renders_stages_double() {
        let stages: Vec<_> = (0..12).map(|i| sample_stage(i, 12)).collect();
        let want = [(0, 1), (1, 2), (2, 4), (2, 4), (4, 8), (4, 8), (4, 8), (4, 8)];
        assert_eq!(stages[..8], want);
        assert!(stages[8..].iter().all(|&s| s == (8, 12)));
        for spp in 1..70 {
            for i in 0..spp {
                let (from, to) = sample_stage(i, spp);
                assert!(from <= i && i < to && to <= spp, "{i} of {spp}: {from}..{to}");
            }
        }
        assert_eq!(sample_stage(u32::MAX - 1, u32::MAX), (1 << 31, u32::MAX));
    }
}
