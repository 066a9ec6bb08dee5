//! Tests of the progressive schedule, adaptive waves and cancellation.

use super::*;
use crate::render::edges::{self, EDGE_SHARE};
use crate::render::{RenderSettings, Seen, render};

fn scene() -> Scene {
    Scene::default_scene().1
}

fn direct_settings() -> RenderSettings {
    RenderSettings {
        width: 40,
        height: 30,
        spp: 1,
        seed: 3,
    }
}

/// Adaptive waves refine the pixels at edges to the cap and leave flat
/// ones early; a pixel that got every sample is bit for bit the
/// uniform picture's, and the rest stay close to it.
#[test]
fn adaptive_waves_refine_edges_and_stop_on_flat_pixels() {
    let s = scene();
    let (w, h) = (64, 48);
    let run = |sampling| {
        let mut p = Progressive::new(w, h, 2).with_sampling(sampling);
        for st in schedule(16) {
            assert!(p.run(&s, st, &|| false));
        }
        p
    };
    let (adaptive, uniform) = (run(Sampling::default()), run(Sampling::UNIFORM));
    assert_eq!((adaptive.spp, uniform.spp), (16, 16));
    let (a, u) = (adaptive.image(), uniform.image());
    let counts = adaptive.counts();
    let full = counts.iter().filter(|&&n| n == 16).count();
    let stopped = counts.iter().filter(|&&n| n < 16).count();
    assert!(
        full > 50 && stopped > counts.len() / 3,
        "{full} at the cap, {stopped} stopped"
    );
    let mut worst: f64 = 0.0;
    for (i, &n) in counts.iter().enumerate() {
        assert!(n >= 1);
        if n == 16 {
            assert_eq!(a.pixels[i], u.pixels[i], "pixel {i}");
        }
        worst = worst.max((a.pixels[i] - u.pixels[i]).abs().max_element());
    }
    assert!(worst < 0.05, "{worst}");
    // Samples cast: far fewer than the uniform picture's.
    assert!(adaptive.samples_cast * 4 < uniform.samples_cast * 3);
    // Pixels that differ from a neighbour by more than four times the
    // threshold in the uniform picture (edges) reached the cap, but for
    // a few whose edge no centre sample around them met (a feature
    // thinner than a pixel: contrast cannot see it).
    let t = Adaptive::default().contrast;
    let (mut edges, mut at_cap) = (0, 0);
    for y in 1..h as usize - 1 {
        for x in 1..w as usize - 1 {
            let c = |x: usize, y: usize| u.pixels[y * w as usize + x].clamp(Rgb::ZERO, Rgb::ONE);
            let edge = (-1..=1i64).any(|dy| {
                (-1..=1i64).any(|dx| {
                    let q = c((x as i64 + dx) as usize, (y as i64 + dy) as usize);
                    (q - c(x, y)).abs().max_element() > 4.0 * t
                })
            });
            if edge {
                edges += 1;
                at_cap += usize::from(counts[y * w as usize + x] == 16);
            }
        }
    }
    assert!(
        edges > 100 && at_cap * 100 >= edges * 95,
        "{at_cap} of {edges} edge pixels at the cap"
    );
}

#[test]
fn schedule_goes_coarse_to_fine_and_stops_at_the_cap() {
    assert_eq!(
        schedule(16),
        vec![
            Stage::Blocks(8),
            Stage::Blocks(4),
            Stage::Blocks(2),
            Stage::Samples(1),
            Stage::Samples(2),
            Stage::Samples(4),
            Stage::Samples(8),
            Stage::Samples(16)
        ]
    );
    assert_eq!(*schedule(1).last().unwrap(), Stage::Samples(1));
    assert_eq!(*schedule(48).last().unwrap(), Stage::Samples(48));
}

#[test]
fn refinement_converges_to_the_same_image_as_a_direct_render() {
    let s = scene();
    let mut p = Progressive::new(40, 30, 3);
    for st in schedule(4) {
        assert!(p.run(&s, st, &|| false));
    }
    assert_eq!(p.spp, 4);
    let direct = render(&s, &direct_settings(), None);
    let mut one = Progressive::new(40, 30, 3);
    one.run(&s, Stage::Samples(1), &|| false);
    // Sample 0 is the pixel centre, as in a 1-spp render.
    assert_eq!(one.image(), direct);
    // After a reset the kept buffers hold old sums; they never leak in.
    one.run(&s, Stage::Samples(3), &|| false);
    one.reset(40, 30, 3);
    one.run(&s, Stage::Samples(1), &|| false);
    assert_eq!(one.image(), direct);
    // Four samples in uniform waves equal four samples at once.
    let mut waves = Progressive::new(40, 30, 3).with_sampling(Sampling::UNIFORM);
    for st in schedule(4) {
        assert!(waves.run(&s, st, &|| false));
    }
    let mut once = Progressive::new(40, 30, 3);
    once.run(&s, Stage::Samples(4), &|| false);
    assert_eq!(once.image(), waves.image());
    // And equal a direct render at four samples.
    let four = RenderSettings {
        spp: 4,
        ..direct_settings()
    };
    let direct4 = render(&s, &four, None);
    for (a, b) in once.image().pixels.iter().zip(&direct4.pixels) {
        assert!((*a - *b).abs().max_element() < 1e-12);
    }
}

/// The sums of squares after a wave are those of the samples each pixel
/// holds, although the first sample stage leaves them unwritten (the wave
/// computes them from the sums as it copies): pixel for pixel, against
/// each sample traced alone.
#[test]
fn squares_after_a_wave_are_the_squares_of_the_samples() {
    use super::super::adaptive::square;
    use crate::sampling::pixel_offset;
    let s = scene();
    let (w, h, seed) = (40, 30, 3);
    let mut p = Progressive::new(w, h, seed);
    // Squares of another picture: a wave that copied them would show it.
    assert!(p.run(&s, Stage::Samples(3), &|| false));
    p.reset(w, h, seed);
    assert!(p.run(&s, Stage::Samples(1), &|| false));
    assert!(p.sq_of_sum, "the first sample stage stored squares");
    assert!(p.run(&s, Stage::Samples(2), &|| false));
    let mut refined = 0;
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let mut q = [0.0f32; 3];
            for k in 0..p.count[i] {
                let (jx, jy) = pixel_offset(Pattern::R2, seed, i as u64, k);
                let c = square(crate::render::sample(&s, x as f64 + jx, y as f64 + jy, w, h));
                q = [q[0] + c[0], q[1] + c[1], q[2] + c[2]];
            }
            assert_eq!(p.sq[i], q, "pixel {x},{y} with {} samples", p.count[i]);
            refined += usize::from(p.count[i] == 2);
        }
    }
    assert!(refined > 0 && refined < (w * h) as usize, "{refined} refined");
}

#[test]
fn cancellation_stops_a_stage_and_keeps_the_previous_image() {
    let s = scene();
    let mut p = Progressive::new(64, 16 * BAND as u32, 0);
    p.run(&s, Stage::Samples(1), &|| false);
    let before = p.image();
    let calls = std::sync::atomic::AtomicUsize::new(0);
    let ok = p.run(&s, Stage::Samples(8), &|| {
        calls.fetch_add(1, std::sync::atomic::Ordering::Relaxed) >= 2
    });
    assert!(!ok);
    assert_eq!(p.spp, 1);
    assert_eq!(p.image(), before);
    // Bands after the cancellation were skipped, not rendered: of the
    // 16 bands, the two that saw no cancellation and the few already
    // started beside the third asked.
    assert!(calls.load(std::sync::atomic::Ordering::Relaxed) <= 8);
}

#[test]
fn the_schedule_gives_the_same_bits_on_one_two_and_three_threads() {
    let s = Scene::load(
        &std::path::PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/..")).join("scenes/primitives.toml"),
    )
    .unwrap()
    .1;
    // Taller than one band per thread, and not a whole number of bands.
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| {
                let mut p = Progressive::new(45, 7 * BAND as u32 + 3, 11);
                let mut frames = Vec::new();
                for st in schedule(6) {
                    assert!(p.run(&s, st, &|| false));
                    let mut rgba = Vec::new();
                    p.write_rgba8(&mut rgba, Default::default());
                    frames.push((p.image(), rgba));
                }
                frames
            })
    };
    let bits = |frames: &[(crate::render::Image, Vec<u8>)]| -> Vec<(Vec<u64>, Vec<u8>)> {
        frames
            .iter()
            .map(|(img, rgba)| {
                (
                    img.pixels.iter().flat_map(|c| c.to_array().map(f64::to_bits)).collect(),
                    rgba.clone(),
                )
            })
            .collect()
    };
    let one = bits(&run(1));
    assert_eq!(one.len(), schedule(6).len());
    // Every stage changed the picture (the comparison is not of blanks).
    assert!(one.windows(2).all(|w| w[0].0 != w[1].0));
    assert_eq!(one, bits(&run(2)));
    assert_eq!(one, bits(&run(3)));
}

#[test]
fn block_preview_fills_every_pixel() {
    let s = scene();
    let mut p = Progressive::new(37, 23, 0);
    assert!(p.run(&s, Stage::Blocks(8), &|| false));
    let img = p.image();
    // Each block's centre pixel is the sample cast there (in a tile of
    // packets, as `sample` gives it), the pixels between centres blend
    // them, and the last partial block is filled too.
    let at = |x: u32, y: u32| crate::render::sample(&s, x as f64 + 0.5, y as f64 + 0.5, 37, 23);
    for (x, y) in [(4, 4), (12, 12), (28, 12), (36, 20)] {
        assert_eq!(img.get(x, y), at(x, y), "({x}, {y})");
    }
    let mut differ = 0;
    for y in [4, 12, 20] {
        for x in [8, 16, 24, 32] {
            let (a, b) = (at(x - 4, y), at(x + 4, y));
            assert_eq!(img.get(x, y), a * 0.5 + b * 0.5, "({x}, {y})");
            differ += usize::from(a != b);
        }
    }
    assert!(differ > 0, "every centre the same colour");
    assert_ne!(img.get(36, 22), Rgb::ZERO);
    let mut rgba = Vec::new();
    p.write_rgba8(&mut rgba, Default::default());
    assert_eq!(rgba.len(), 37 * 23 * 4);
    // The per-block conversion gives the same bytes as per pixel.
    let per_pixel: Vec<u8> = img
        .pixels
        .iter()
        .flat_map(|c| {
            [
                crate::color::to_srgb8_fast(c.x),
                crate::color::to_srgb8_fast(c.y),
                crate::color::to_srgb8_fast(c.z),
                255,
            ]
        })
        .collect();
    assert_eq!(rgba, per_pixel);
}

/// A sample stage records no first hits; a reprojection records the ones
/// it needs first, so what it shows does not depend on whether the render
/// thread had the time to record them (the same picture, bit for bit); a
/// cancelled recording leaves them unrecorded.
#[test]
fn a_reprojection_records_the_first_hits_it_needs() {
    use crate::camera::Camera;
    let a = scene();
    let c = &a.camera;
    let b = Scene {
        camera: Camera::new(c.position + c.forward() * 0.1, c.rotation_deg, c.fov_y_deg),
        ..a.clone()
    };
    let (w, h) = (48, 32);
    let mut late = Progressive::new(w, h, 0);
    assert!(late.run(&a, Stage::Samples(1), &|| false));
    assert!(late.first_hits().is_none());
    assert!(!late.record_first_hits(&a, &|| true));
    assert!(late.first_hits().is_none());
    let mut early = Progressive::new(w, h, 0);
    assert!(early.run(&a, Stage::Samples(1), &|| false));
    assert!(early.record_first_hits(&a, &|| false));
    let first = early.first_hits().expect("recorded");
    assert!(first.iter().any(|f| f.seen() == Seen::Surface) && first.iter().any(|f| f.seen() == Seen::Specular));
    assert!(late.reproject(&b, &a, |_| 1));
    assert!(early.reproject(&b, &a, |_| 1));
    assert_eq!(late.image().pixels, early.image().pixels);
    assert_eq!(late.first_hits(), early.first_hits());
}

/// A sphere seen through a lens camera (a small double Gauss).
fn lens_camera_scene() -> Scene {
    let text = "[camera]\nposition = [0, 0.5, 4]\nlens = { preset = \"double-gauss-50mm\", scale = 0.01 }\n\
                focus_distance = 4\n[ambient]\ncolor = [1, 1, 1]\nintensity = 1\n\
                [[objects]]\ntype = \"sphere\"\nposition = [0, 0.5, 0]\nradius = 0.5\n";
    Scene::parse("lens", text).unwrap().1
}

/// Through a lens camera a block level samples each block's centre at its
/// pixel's first pupil point, as the sample stages' first sample does.
#[test]
fn a_lens_cameras_block_centres_are_its_first_samples() {
    let s = lens_camera_scene();
    let mut p = Progressive::new(24, 16, 0);
    assert!(p.run(&s, Stage::Blocks(4), &|| false));
    let lit = crate::integrator::Lit::from(&s);
    let lens = s.lens.as_ref().unwrap();
    for (x, y) in [(2, 2), (10, 6), (22, 14)] {
        let pixel = y as u64 * 24 + x as u64;
        let want = crate::render::lens_sample(
            &lit,
            lens,
            (x as f64 + 0.5, y as f64 + 0.5),
            (24, 16),
            crate::sampling::lens_point(0, pixel, 0),
        );
        assert_eq!(p.image().get(x, y), want, "({x}, {y})");
    }
}

/// A lens camera's picture is never warped (the warp assumes a pinhole):
/// moved, or moved into, it is refused and the picture left as it was.
#[test]
fn a_lens_camera_is_never_reprojected() {
    use crate::camera::Camera;
    let lens = lens_camera_scene();
    let c = &lens.camera;
    let moved = Scene {
        camera: Camera::new(c.position + c.forward() * 0.1, c.rotation_deg, c.fov_y_deg),
        ..lens.clone()
    };
    let pinhole = Scene {
        lens: None,
        ..moved.clone()
    };
    let (w, h) = (24, 16);
    let mut p = Progressive::new(w, h, 0);
    assert!(p.run(&lens, Stage::Samples(1), &|| false));
    let before = p.image().pixels;
    assert!(!p.reproject(&moved, &lens, |_| 1));
    assert!(!p.reproject(&lens, &pinhole, |_| 1));
    assert!(!p.reproject(&pinhole, &lens, |_| 1));
    assert_eq!(p.image().pixels, before);
    // The pinhole of the same pose reprojects.
    let mut q = Progressive::new(w, h, 0);
    assert!(q.run(&pinhole, Stage::Samples(1), &|| false));
    assert!(q.reproject(
        &Scene {
            lens: None,
            ..lens.clone()
        },
        &pinhole,
        |_| 1
    ));
}

/// Adaptive waves through a lens camera cast the lens camera's samples
/// (each pixel's sum is its samples `0 .. count` of the whole-picture
/// path), not the pinhole's: a defocused picture stays defocused.
#[test]
fn adaptive_waves_sample_through_the_lens_camera() {
    use crate::render::pixel_sample;
    let text = "[camera]\nposition = [0, 0.5, 4]\nlens = { preset = \"double-gauss-50mm\", scale = 0.01 }\n\
                focus_distance = 1.5\nf_number = 2.8\n[ambient]\ncolor = [1, 1, 1]\nintensity = 1\n\
                [[objects]]\ntype = \"cuboid\"\nposition = [0, 0.5, 0]\nsize = [1, 1, 1]\n";
    let (_, s) = Scene::parse("lens", text).unwrap();
    let (w, h) = (24u32, 16u32);
    let mut p = Progressive::new(w, h, 5).with_sampling(Sampling::default());
    for st in schedule(8) {
        assert!(p.run(&s, st, &|| false));
    }
    let counts = p.counts().to_vec();
    assert!(counts.iter().any(|&n| n > 1), "no wave refined anything");
    let img = p.image();
    let settings = RenderSettings {
        width: w,
        height: h,
        spp: 8,
        seed: 5,
    };
    let lit = crate::integrator::Lit::from(&s);
    for y in 0..h {
        for x in 0..w {
            let n = counts[(y * w + x) as usize];
            let sum = (0..n).fold(Rgb::ZERO, |a, i| {
                a + pixel_sample(&lit, (x, y), (i, p.sampling.pattern), &settings)
            });
            let want = sum / n as f64;
            assert!((img.get(x, y) - want).abs().max_element() < 1e-5, "pixel ({x}, {y})");
        }
    }
}

/// A picture refined elsewhere is held only where it covers what would
/// otherwise be a block preview or nothing; held, it is the picture a
/// reprojection moves (a turn of the camera by nothing moves nothing).
#[test]
fn a_held_picture_is_what_a_reprojection_moves() {
    let scene = scene();
    let mut p = Progressive::new(48, 36, 1);
    let n = 48 * 36;
    let colour = |i: usize| Rgb::splat(i as f64 / n as f64);
    assert!(!p.hold(|_| None), "nothing drawn yet");
    p.run(&scene, Stage::Blocks(4), &|| false);
    assert!(!p.hold(|i| (i > 0).then(|| colour(i))), "a pixel left to a block");
    assert!(p.hold(|i| Some(colour(i))));
    assert!(p.hold(|_| None), "a held picture is at full resolution");
    assert!(p.reproject(&scene, &scene, |_| 1));
    let img = p.image();
    // Pixels seen on a surface keep their colour (to the rounding of the
    // projection), but for those beside glass or a mirror, which are
    // traced again with those seen through them.
    let first = p.first_hits().unwrap();
    let surface: Vec<usize> = (0..n).filter(|&i| first[i].seen() == Seen::Surface).collect();
    let kept = surface
        .iter()
        .filter(|&&i| (img.pixels[i] - colour(i)).abs().max_element() < 1e-4)
        .count();
    assert!(surface.len() >= n / 4, "{} of {n} on a surface", surface.len());
    assert!(kept * 4 >= surface.len() * 3, "{kept} of {} kept", surface.len());
}

/// A 2×2 level refined at its edges: in the blocks refined every pixel
/// is a 1-spp stage's, bit for bit (through a pinhole and through a lens
/// camera, whose block levels take seed 0's pupil points), the rest is the plain level's blend; no more blocks than the
/// cap, each refined pixel counted once; the same bits on one and two
/// threads; a refinement cancelled leaves the plain level.
#[test]
fn a_block_level_refined_at_edges_shows_the_first_samples_there() {
    let (w, h) = (61u32, 43u32);
    let (bw, bh) = (31usize, 22usize);
    let bits = |img: &crate::render::Image| -> Vec<u64> {
        img.pixels.iter().flat_map(|c| c.to_array().map(f64::to_bits)).collect()
    };
    for s in [scene(), lens_camera_scene()] {
        let level = |threads: usize, share: f64| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let mut p = Progressive::new(w, h, 0);
                p.edge_share = share;
                assert!(p.run(&s, Stage::Blocks(2), &|| false));
                let mut rgba = Vec::new();
                p.write_rgba8(&mut rgba, Default::default());
                (p.image(), rgba, p.edges.clone(), p.samples_cast)
            })
        };
        let (img, rgba, refined, cast) = level(1, EDGE_SHARE);
        let (plain, _, none, plain_cast) = level(2, 0.0);
        assert!(none.is_empty() && plain_cast == (bw * bh) as u64);
        assert!(!refined.is_empty(), "no edges");
        assert!(refined.len() <= edges::cap(bw * bh, 2, EDGE_SHARE), "{}", refined.len());
        let mut one = Progressive::new(w, h, 0);
        assert!(one.run(&s, Stage::Samples(1), &|| false));
        let one = one.image();
        let mut exact = vec![false; (w * h) as usize];
        for &b in &refined {
            let (bx, by) = (b as usize % bw, b as usize / bw);
            for y in 2 * by..(2 * by + 2).min(h as usize) {
                for x in 2 * bx..(2 * bx + 2).min(w as usize) {
                    exact[y * w as usize + x] = true;
                }
            }
        }
        // Each refined pixel cast once: the block's centre was already.
        let centres = refined.len() as u64;
        assert_eq!(cast, plain_cast + exact.iter().filter(|&&e| e).count() as u64 - centres);
        for (i, &e) in exact.iter().enumerate() {
            let want = if e { one.pixels[i] } else { plain.pixels[i] };
            assert_eq!(
                img.pixels[i].to_array().map(f64::to_bits),
                want.to_array().map(f64::to_bits),
                "{i}"
            );
        }
        // The 8-bit frame shows the same picture.
        let per_pixel: Vec<u8> = img
            .pixels
            .iter()
            .flat_map(|c| {
                [c.x, c.y, c.z]
                    .map(crate::color::to_srgb8_fast)
                    .into_iter()
                    .chain([255])
            })
            .collect();
        assert_eq!(rgba, per_pixel);
        let (img2, rgba2, refined2, _) = level(2, EDGE_SHARE);
        assert_eq!((bits(&img), rgba, refined), (bits(&img2), rgba2, refined2));
        // Cancelled after the centres (bands of rows of blocks, through a
        // pinhole or a lens), in the refinement.
        let bands = bh.div_ceil(BAND);
        let asked = std::sync::atomic::AtomicUsize::new(0);
        let mut p = Progressive::new(w, h, 0);
        let late = || asked.fetch_add(1, std::sync::atomic::Ordering::Relaxed) >= bands;
        assert!(
            !rayon::ThreadPoolBuilder::new()
                .num_threads(1)
                .build()
                .unwrap()
                .install(|| p.run(&s, Stage::Blocks(2), &late))
        );
        assert_eq!(p.edge_blocks(), 0);
        assert_eq!(bits(&p.image()), bits(&plain));
    }
}

/// Thinned gathers (`Lit::thinned`): stages of every pixel thin as
/// `render` does, so uniform stages to 8 samples give a thinned render's
/// picture; adaptive waves thin as much (sample by sample).
#[test]
fn stages_of_every_pixel_thin_as_render_does() {
    let text = include_str!("../../../../scenes/rim-lens.toml");
    let s = Scene::parse("rim-lens", text).unwrap().1;
    let settings = crate::render::caustics::CausticSettings::default();
    let map = crate::render::caustics::caustic_map(&s, 2, settings).unwrap();
    let lit = Lit::new(&s, Some(&map)).thinned(4);
    let mut waves = Progressive::new(32, 18, 3).with_sampling(Sampling::UNIFORM);
    let mut adaptive = Progressive::new(32, 18, 3);
    for st in schedule(8) {
        let want = match st {
            Stage::Samples(1) => 1,
            Stage::Samples(2) => 1,
            Stage::Samples(4) => 2,
            Stage::Samples(8) => 4,
            _ => 1,
        };
        assert_eq!(waves.stage_thinning(st, 4), want, "{st:?}");
        assert_eq!(adaptive.stage_thinning(st, 4), want, "{st:?}");
        assert!(waves.run(lit, st, &|| false));
        assert!(adaptive.run(lit, st, &|| false));
    }
    let eight = RenderSettings {
        width: 32,
        height: 18,
        spp: 8,
        seed: 3,
    };
    let direct = render(lit, &eight, None);
    assert_ne!(direct, render(Lit::new(&s, Some(&map)), &eight, None), "thinned");
    for (a, b) in waves.image().pixels.iter().zip(&direct.pixels) {
        assert!((*a - *b).abs().max_element() < 1e-12);
    }
}

/// Adaptive waves thinned sample by sample (`thinning::sample_weight`):
/// the same bits on one and two threads; the caustic's light over the
/// picture within 3 % of unthinned waves' (each gathering sample counts
/// for its group); and no more samples cast than unthinned waves cast
/// (a wave reads the variance of groups, `adaptive::GroupSquares`).
#[test]
fn thinned_waves_keep_the_caustics_light_and_refine_no_more() {
    let text = include_str!("../../../../scenes/rim-lens.toml");
    let s = Scene::parse("rim-lens", text).unwrap().1;
    let settings = crate::render::caustics::CausticSettings::default();
    let map = crate::render::caustics::caustic_map(&s, 4, settings).unwrap();
    let run = |lit: Lit, threads| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            // Loose enough that many pixels stop early.
            let adaptive = Some(Adaptive {
                contrast: 0.05,
                error: 0.01,
            });
            let sampling = Sampling {
                pattern: Pattern::R2,
                adaptive,
            };
            let mut p = Progressive::new(96, 54, 5).with_sampling(sampling);
            for st in schedule(32) {
                assert!(p.run(lit, st, &|| false));
            }
            (p.image(), p.samples_cast)
        })
    };
    let thinned = Lit::new(&s, Some(&map)).thinned(4);
    let (img, cast) = run(thinned, 1);
    assert_eq!(img, run(thinned, 2).0, "the same on two threads");
    let (full, cast_full) = run(Lit::new(&s, Some(&map)), 1);
    assert_ne!(img, full, "thinned waves gather fewer samples");
    let total = |img: &crate::render::Image| img.pixels.iter().fold(Rgb::ZERO, |a, &p| a + p);
    let none = total(&run(Lit::new(&s, None), 1).0);
    let (a, b) = (total(&img) - none, total(&full) - none);
    for c in 0..3 {
        assert!(b[c] > 0.01 * none[c], "channel {c}: the caustic is a visible share");
        assert!(
            (a[c] / b[c] - 1.0).abs() < 0.03,
            "channel {c}: thinned {a:?}, unthinned {b:?}"
        );
    }
    assert!(
        (cast as f64) < 1.05 * cast_full as f64,
        "thinned waves cast {cast} samples, unthinned {cast_full}"
    );
}
