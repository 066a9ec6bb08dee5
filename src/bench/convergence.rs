//! Error against run time of the progressive schedule (`lensview
//! converge`): each stage run headless, timed, and compared with a
//! converged reference rendered with another sample pattern.

use crate::color::Rgb;
use crate::render::Image;
use crate::render::progressive::{Progressive, Stage, schedule};
use crate::scene::Scene;
use rayon::prelude::*;

/// One row of [`converge`]: a stage, when it finished and how far from the
/// reference the picture then was.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ConvergeRow {
    pub stage: String,
    pub spp: u32,
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
    let sum: f64 = a
        .pixels
        .par_iter()
        .zip(&b.pixels)
        .map(|(x, y)| {
            let d = x.clamp(Rgb::ZERO, Rgb::ONE) - y.clamp(Rgb::ZERO, Rgb::ONE);
            d.length_squared()
        })
        .sum();
    (sum / n).sqrt()
}

/// A converged reference: `spp` samples per pixel with a sample pattern
/// (seed) other than the one being measured, so its own noise is
/// independent of the stages' noise.
pub fn reference(scene: &Scene, width: u32, height: u32, spp: u32, seed: u64) -> Image {
    let mut p = Progressive::new(width, height, seed);
    p.run(scene, Stage::Samples(spp.max(1)), &|| false);
    p.image()
}

/// Runs the progressive schedule headless and measures each stage's time
/// and its error against `reference`.
pub fn converge(scene: &Scene, reference: &Image, max_spp: u32) -> Vec<ConvergeRow> {
    let mut p = Progressive::new(reference.width, reference.height, 0);
    // Elapsed time counts rendering only, not the error measurement.
    let mut elapsed_ms = 0.0;
    let mut rows = Vec::new();
    for stage in schedule(max_spp) {
        let t0 = std::time::Instant::now();
        p.run(scene, stage, &|| false);
        let stage_ms = t0.elapsed().as_secs_f64() * 1e3;
        elapsed_ms += stage_ms;
        let e = rmse(&p.image(), reference);
        rows.push(ConvergeRow {
            stage: stage.label(),
            spp: p.spp,
            stage_ms,
            elapsed_ms,
            rmse: e,
            psnr_db: if e > 0.0 { -20.0 * e.log10() } else { f64::INFINITY },
        });
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn error_falls_as_refinement_proceeds() {
        let s = Scene::default_scene().1;
        let r = reference(&s, 48, 36, 64, 1);
        let rows = converge(&s, &r, 16);
        assert_eq!(rows.len(), schedule(16).len());
        // Each row is its stage of the schedule, with the samples it leaves.
        for (row, stage) in rows.iter().zip(schedule(16)) {
            assert_eq!(row.stage, stage.label());
            let spp = match stage {
                Stage::Blocks(_) => 0,
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
        let mut p = Progressive::new(48, 36, 0);
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
