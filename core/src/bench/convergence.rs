//! Error against run time of the progressive schedule (`lensview
//! converge`): each stage run headless, timed, and compared with a
//! converged reference rendered with another sample pattern.

use crate::color::Rgb;
use crate::render::Image;
use crate::render::edges::{EDGE_BLOCK, EDGE_SHARE};
use crate::render::progressive::{Progressive, Sampling, Stage, schedule};
use crate::scene::Scene;
use rayon::prelude::*;

/// One row of [`converge`]: a stage, when it finished and how far from the
/// reference the picture then was.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ConvergeRow {
    pub stage: String,
    pub spp: u32,
    /// Camera samples cast so far per pixel (block levels included): the
    /// machine-independent measure of work.
    pub samples_per_pixel: f64,
    /// Time this stage took.
    pub stage_ms: f64,
    /// Rendering time since refinement started (stages only).
    pub elapsed_ms: f64,
    /// Root-mean-square error over all pixels and channels, in linear light
    /// clamped to [0, 1].
    pub rmse: f64,
    /// Peak signal-to-noise ratio, 10·log10(1 / MSE), in dB.
    pub psnr_db: f64,
}

/// RMSE between two images (linear light, each channel clamped to [0, 1]).
pub fn rmse(a: &Image, b: &Image) -> f64 {
    assert_eq!((a.width, a.height), (b.width, b.height));
    let n = a.pixels.len() as f64 * 3.0;
    // Summed in fixed chunks, in order: a parallel `sum()` adds in an
    // order that depends on how the work was stolen, so the same images
    // gave RMSEs an ulp apart from run to run.
    const CHUNK: usize = 4096;
    let partial: Vec<f64> = (a.pixels.par_chunks(CHUNK))
        .zip(b.pixels.par_chunks(CHUNK))
        .map(|(xs, ys)| {
            let d =
                |(x, y): (&Rgb, &Rgb)| (x.clamp(Rgb::ZERO, Rgb::ONE) - y.clamp(Rgb::ZERO, Rgb::ONE)).length_squared();
            xs.iter().zip(ys).map(d).sum::<f64>()
        })
        .collect();
    (partial.iter().sum::<f64>() / n).sqrt()
}

/// A converged reference: `spp` samples in every pixel with a sample
/// pattern (seed) other than the one being measured, so its own noise is
/// independent of the stages' noise.
pub fn reference(scene: &Scene, width: u32, height: u32, spp: u32, seed: u64) -> Image {
    let mut p = Progressive::new(width, height, seed).with_sampling(Sampling::UNIFORM);
    p.run(scene, Stage::Samples(spp.max(1)), &|| false);
    p.image()
}

/// PSNR in dB of an RMSE.
pub fn psnr(rmse: f64) -> f64 {
    if rmse > 0.0 {
        -20.0 * rmse.log10()
    } else {
        f64::INFINITY
    }
}

/// The row of `p`'s picture after `stage`: its error against `reference`.
fn row(p: &Progressive, stage: Stage, (stage_ms, elapsed_ms): (f64, f64), reference: &Image) -> ConvergeRow {
    let pixels = (reference.width as f64 * reference.height as f64).max(1.0);
    let e = rmse(&p.image(), reference);
    ConvergeRow {
        stage: stage.label(),
        spp: p.spp,
        samples_per_pixel: p.samples_cast as f64 / pixels,
        stage_ms,
        elapsed_ms,
        rmse: e,
        psnr_db: psnr(e),
    }
}

/// Runs the progressive schedule headless with `sampling` and measures
/// each stage's time and its error against `reference`.
pub fn converge(scene: &Scene, reference: &Image, max_spp: u32, sampling: Sampling) -> Vec<ConvergeRow> {
    let mut p = Progressive::new(reference.width, reference.height, 0).with_sampling(sampling);
    // Elapsed time counts rendering only, not the error measurement.
    let mut elapsed_ms = 0.0;
    let mut rows = Vec::new();
    for stage in schedule(max_spp) {
        let t0 = web_time::Instant::now();
        p.run(scene, stage, &|| false);
        let stage_ms = t0.elapsed().as_secs_f64() * 1e3;
        elapsed_ms += stage_ms;
        rows.push(row(&p, stage, (stage_ms, elapsed_ms), reference));
    }
    rows
}

/// `after`'s camera pose: `before`'s moved by `dx` along its right axis,
/// `dy` along world up and `dz` along its forward axis, then turned by
/// `yaw` and `pitch` degrees (the viewer's flight keys: W for 1/30 s at the
/// default speed is `dz` = 0.1).
pub fn step_camera(before: &Scene, [dx, dy, dz, yaw, pitch]: [f64; 5]) -> Scene {
    let c = &before.camera;
    let pos = c.position + c.right() * dx + glam::DVec3::Y * dy + c.forward() * dz;
    let rot = c.rotation_deg + glam::DVec3::new(pitch, yaw, 0.0);
    Scene {
        camera: crate::camera::Camera::new(pos, rot, c.fov_y_deg),
        ..before.clone()
    }
}

/// A camera step: `before`'s view refined through the schedule to
/// `max_spp` (not timed), then the camera moves to `after`'s and, as the
/// render thread does, the picture is reprojected (pixels it cannot move
/// traced at block size `block`) and refined from one sample per pixel on.
/// Each row is measured against `reference` (of `after`'s view).
pub fn converge_step(
    (before, after): (&Scene, &Scene),
    reference: &Image,
    max_spp: u32,
    sampling: Sampling,
    block: u32,
) -> Vec<ConvergeRow> {
    let (w, h) = (reference.width, reference.height);
    let mut p = Progressive::new(w, h, 0).with_sampling(sampling);
    let refined = |p: &mut Progressive| {
        p.reset(w, h, 0);
        for stage in schedule(max_spp) {
            p.run(before, stage, &|| false);
        }
        // The render thread records a refined picture's first hits while
        // it waits for input (worker.rs), so a move finds them there.
        p.record_first_hits(before, &|| false);
    };
    // A first, cold reprojection: its buffers are touched for the first
    // time (page faults). In a flight every later one finds them warm, so
    // the timed one is the second, from the same refined picture.
    refined(&mut p);
    p.reproject(after, before, |_| block);
    let cold = p.reprojection;
    refined(&mut p);
    let mut rows = Vec::new();
    let t0 = web_time::Instant::now();
    p.reproject(after, before, |_| block);
    let mut elapsed_ms = t0.elapsed().as_secs_f64() * 1e3;
    let r = p.reprojection;
    eprintln!(
        "reprojection: first hits {:.1} ms, warp {:.1} ms (splat {:.1}, look back {:.1}; cold: {:.1} ms), {} pixels left traced at {l}×{l} in {:.1} ms",
        r.first_hits_s * 1e3,
        r.warp_s * 1e3,
        r.splat_s * 1e3,
        (r.warp_s - r.splat_s) * 1e3,
        cold.warp_s * 1e3,
        r.holes,
        r.fill_s * 1e3,
        l = r.level,
    );
    eprintln!(
        "fresh at the new view instead (one block level alone, as the viewer may show it): {}",
        fresh_levels(after, reference, sampling).join(", ")
    );
    let mut push = |p: &Progressive, stage: Stage, stage_ms: f64, elapsed_ms: f64| {
        rows.push(row(p, stage, (stage_ms, elapsed_ms), reference));
    };
    push(&p, Stage::Reprojected, elapsed_ms, elapsed_ms);
    for stage in schedule(max_spp).into_iter().filter(|s| matches!(s, Stage::Samples(_))) {
        let t0 = web_time::Instant::now();
        p.run(after, stage, &|| false);
        let stage_ms = t0.elapsed().as_secs_f64() * 1e3;
        elapsed_ms += stage_ms;
        push(&p, stage, stage_ms, elapsed_ms);
    }
    rows
}

/// The 4×4 and 2×2 block levels of `scene` each run alone on a fresh
/// picture (the second of two runs, so its buffers are warm as the
/// reprojection's are), as "N×N blocks T ms at P dB" against
/// `reference`, and for a level refined at edges (2×2) also so refined:
/// ", refined at edges (S % of blocks) T ms at P dB".
fn fresh_levels(scene: &Scene, reference: &Image, sampling: Sampling) -> Vec<String> {
    let (w, h) = (reference.width, reference.height);
    let mut p = Progressive::new(w, h, 0).with_sampling(sampling);
    let mut level = |n: u32, share: f64| {
        p.edge_share = share;
        let mut ms = 0.0;
        for _ in 0..2 {
            p.reset(w, h, 0);
            let t0 = web_time::Instant::now();
            p.run(scene, Stage::Blocks(n), &|| false);
            ms = t0.elapsed().as_secs_f64() * 1e3;
        }
        let blocks = (w.div_ceil(n) * h.div_ceil(n)).max(1) as f64;
        (ms, psnr(rmse(&p.image(), reference)), p.edge_blocks() as f64 / blocks)
    };
    [4, 2]
        .into_iter()
        .map(|n| {
            let (plain_ms, plain_db, _) = level(n, 0.0);
            let plain = format!("{n}×{n} blocks {plain_ms:.1} ms at {plain_db:.2} dB");
            if n as usize > EDGE_BLOCK {
                return plain;
            }
            let (ms, db, share) = level(n, EDGE_SHARE);
            format!(
                "{plain}, refined at edges ({:.1} % of blocks) {ms:.1} ms at {db:.2} dB",
                share * 100.0
            )
        })
        .collect()
}

/// What [`at_multiple`] counts work in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Work {
    /// Rendering time (noisy on a shared machine).
    Time,
    /// Camera samples cast (the same on any machine).
    Samples,
}

/// The PSNR of the picture on screen once `k` times the work of the first
/// full-resolution sample (the `1 spp` row, block levels included) has
/// been done: the last stage finished by then. `None` without a 1-spp row.
pub fn at_multiple(rows: &[ConvergeRow], k: f64, work: Work) -> Option<f64> {
    let of = |r: &ConvergeRow| match work {
        Work::Time => r.elapsed_ms,
        Work::Samples => r.samples_per_pixel,
    };
    let one = of(rows.iter().find(|r| r.spp == 1)?);
    // A hair of slack so that "1×" includes the 1-spp row itself.
    let limit = k * one * (1.0 + 1e-12);
    rows.iter().take_while(|r| of(r) <= limit).last().map(|r| r.psnr_db)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn error_falls_as_refinement_proceeds() {
        let s = Scene::default_scene().1;
        let r = reference(&s, 48, 36, 64, 1);
        let rows = converge(&s, &r, 16, Sampling::UNIFORM);
        assert_eq!(rows.len(), schedule(16).len());
        // Each row is its stage of the schedule, with the samples it leaves.
        for (row, stage) in rows.iter().zip(schedule(16)) {
            assert_eq!(row.stage, stage.label());
            let spp = match stage {
                Stage::Blocks(_) | Stage::Reprojected => 0,
                Stage::Samples(s) => s,
            };
            assert_eq!(row.spp, spp);
        }
        // Elapsed time is the running sum of the stages' times, each spent.
        let mut sum = 0.0;
        for row in &rows {
            sum += row.stage_ms;
            assert!(row.stage_ms > 0.0, "{row:?}");
            assert_eq!(row.elapsed_ms, sum, "{row:?}");
        }
        // The error is the RMSE of that stage's picture, and PSNR follows it.
        let mut p = Progressive::new(48, 36, 0).with_sampling(Sampling::UNIFORM);
        for (row, stage) in rows.iter().zip(schedule(16)) {
            p.run(&s, stage, &|| false);
            assert_eq!(row.rmse, rmse(&p.image(), &r));
            assert!((row.psnr_db - 10.0 * (1.0 / (row.rmse * row.rmse)).log10()).abs() < 1e-9);
        }
        let first = rows[0].rmse;
        let last = rows.last().unwrap().rmse;
        assert!(last < 0.5 * first, "{first} → {last}");
        assert_eq!(rmse(&r, &r), 0.0);
        // RMSE by hand on two 1×2 images: channel errors 0.5 and 0 (clamped).
        let img = |a: Rgb, b: Rgb| Image {
            width: 2,
            height: 1,
            pixels: vec![a, b],
        };
        let e = rmse(&img(Rgb::splat(0.5), Rgb::splat(2.0)), &img(Rgb::ZERO, Rgb::ONE));
        assert!((e - (0.25f64 * 3.0 / 6.0).sqrt()).abs() < 1e-15, "{e}");
    }
}
