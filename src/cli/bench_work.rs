//! What each report of `bench`'s study measures (its sizes and sweeps), in
//! one place, so that the work a run will do is counted from the same lists
//! before anything is measured ([`work`]), and every mode's work counts the
//! scene's lights as `render`'s does.

use super::bench::{BenchArgs, BenchMode};
use lensview::limits::Work;

/// The image sizes of the size sweep.
pub fn sizes(quick: bool) -> &'static [(u32, u32)] {
    if quick {
        &[(32, 32), (64, 64), (64, 36)]
    } else {
        &[
            (100, 100),
            (200, 200),
            (400, 400),
            (800, 800),
            (1600, 1600),
            (1280, 720),
        ]
    }
}

/// The object-count sweep: its image size, the numbers of the scene's cubes
/// kept, and the sides of the grids of cubes.
pub fn objects(quick: bool) -> ((u32, u32), Vec<usize>, &'static [usize]) {
    if quick {
        ((48, 48), vec![0, 5, 25], &[2, 5, 10])
    } else {
        ((400, 400), (0..=25).collect(), &[5, 10, 20, 30, 40, 50])
    }
}

/// The size the throughput report measures at.
pub fn throughput_size(quick: bool) -> (u32, u32) {
    if quick { (64, 36) } else { (1280, 720) }
}

/// The size the feature costs are measured at.
pub fn features_size(quick: bool) -> (u32, u32) {
    if quick { (48, 48) } else { (400, 400) }
}

/// Frames a feature variant is timed for, in units of one timing (`runs`
/// frames after a warm-up): with and without it, and the unused feature
/// three times each way (`lensview::bench::feature_costs`).
const TIMINGS_PER_FEATURE: u64 = 2 + 2 * 3;

/// Pixels of `(w, h)`.
fn px((w, h): (u32, u32)) -> u64 {
    w as u64 * h as u64
}

/// The camera samples one bench run renders (every timing counted with its
/// warm-up), of a scene with `lights` lights and `variants` feature
/// variants; photons are never shot by `bench`.
pub fn work(a: &BenchArgs, lights: usize, variants: usize) -> Work {
    let timing = a.runs.max(1) as u64 + 1;
    let samples = match a.mode() {
        BenchMode::UnusedFeature { frames, .. } => px((a.width, a.height)) * frames as u64,
        // Three ways of casting.
        BenchMode::PrimaryOnly => 3 * timing * px((a.width, a.height)),
        BenchMode::FrameOnly => timing * (px((400, 400)) + px((a.width, a.height))),
        BenchMode::Study => study_samples(a.quick, timing, variants),
    };
    Work {
        samples: samples as f64,
        lights,
        photons: 0.0,
    }
}

/// The study's camera samples, report by report, with `timing` frames a
/// timing.
fn study_samples(quick: bool, timing: u64, variants: usize) -> u64 {
    let sizes: u64 = sizes(quick).iter().map(|&s| px(s)).sum();
    let (size, counts, sides) = objects(quick);
    let objects = px(size) * (counts.len() + sides.len()) as u64;
    let t = px(throughput_size(quick));
    // Three primary-ray rates, the frame (at most 3 runs), 400×400 and
    // the first 8×8 level (counted as a frame).
    let throughput = 3 * t + t + px((400, 400)) + t;
    let features = px(features_size(quick)) * TIMINGS_PER_FEATURE * variants as u64;
    timing * (sizes + objects + throughput + features)
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    fn args(list: &[&str]) -> BenchArgs {
        let cli = super::super::Cli::try_parse_from([&["lensview", "bench"], list].concat()).unwrap();
        match cli.command {
            Some(super::super::Command::Bench(a)) => a,
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn the_study_counts_every_report_and_its_runs() {
        let one = study_samples(false, 2, 5) as f64;
        // Sizes alone: 4.33 M pixels a timing.
        assert!(one > 2.0 * 4.33e6, "{one}");
        assert_eq!(study_samples(false, 4, 5), 2 * study_samples(false, 2, 5));
        // `--quick` still times one 400×400 frame: about a 36th of the study.
        assert!(study_samples(true, 2, 5) < study_samples(false, 2, 5) / 30);
        // The default study fits; a thousand runs of it do not.
        let default = work(&args(&[]), 1, 5).total();
        assert!(default < lensview::limits::MAX_SAMPLES as f64, "{default:e}");
        let many = work(&args(&["--runs", "1000"]), 1, 5).total();
        assert!(many > lensview::limits::MAX_SAMPLES as f64, "{many:e}");
        // Lights count as in `render`.
        let lit = work(&args(&["--frame-only"]), 101, 5).total();
        assert_eq!(lit, 26.0 * work(&args(&["--frame-only"]), 1, 5).total());
    }
}
