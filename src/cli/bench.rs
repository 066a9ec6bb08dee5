//! `lensview bench`: the flags, the [`BenchMode`] they pick, and the four
//! reports of the full study (image size, object count, throughput, feature
//! costs), each one [`Table`] that is printed, written as CSV and plotted
//! into `--out-dir` (docs/bench/ holds a run of it). The measuring itself
//! is the library's (`lensview::bench`).

use super::table::{Column, Plot, Table, num, write_files};
use super::{bench_work, load_scene};
use crate::plot::Series;
use anyhow::{Context, Result, bail};
use clap::Args;
use lensview::bench::{
    FEATURES, cubes_grid, cubes_subset, feature_costs, frame_time, interleaved_frame_samples, interleaved_frame_times,
    median_time, primary_rays_per_second, primary_rays_per_second_scalar, unused_feature_frame,
};
use lensview::scene::{Scene, SceneFile};
use lensview::{files, limits, output};
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Scene file (TOML) in the layout of scenes/cubes.toml; the embedded cubes scene when omitted.
    pub scene: Option<PathBuf>,
    /// Directory for the CSV tables and PNG plots.
    #[arg(long, default_value = "bench")]
    pub out_dir: PathBuf,
    /// Timed runs per point (the median is reported).
    #[arg(long, default_value_t = 5)]
    pub runs: usize,
    /// Small sizes and few points: a smoke test of the command.
    #[arg(long)]
    pub quick: bool,
    #[command(flatten)]
    pub mode: ModeFlags,
    #[arg(long, default_value_t = 1280)]
    pub width: u32,
    #[arg(long, default_value_t = 720)]
    pub height: u32,
    /// With --unused-feature: through the kernel that has every feature compiled in.
    #[arg(long, requires = "unused_feature")]
    pub unspecialised: bool,
    /// With --unused-feature: how many frames.
    #[arg(long, default_value_t = 1, requires = "unused_feature")]
    pub frames: u32,
}

/// The flags that pick a [`BenchMode`] other than the full study: at most
/// one of them.
#[derive(Args, Debug)]
#[group(multiple = false)]
pub struct ModeFlags {
    /// Only measure closest-hit primary rays per second at WIDTH×HEIGHT and print it.
    #[arg(long)]
    pub primary_only: bool,
    /// Only time full Whitted frames (1 sample per pixel) at 400×400 and at
    /// WIDTH×HEIGHT, round-robin, and print the fastest and the median.
    #[arg(long)]
    pub frame_only: bool,
    /// Render FRAMES frames at WIDTH×HEIGHT of the cubes scene without this
    /// feature (shadows, glass, mirror, specular, dispersion) and exit: for
    /// counting instructions (benches/feature-instructions.sh).
    #[arg(long, value_name = "FEATURE")]
    pub unused_feature: Option<String>,
}

/// What one `lensview bench` run measures.
#[derive(Debug, PartialEq)]
pub enum BenchMode<'a> {
    /// The full study: four tables (CSV) and two plots (PNG) in `--out-dir`.
    Study,
    /// Primary rays per second, three ways, as `name value` lines
    /// (benches/embree_compare.py reads them) and a summary.
    PrimaryOnly,
    /// Full frames at 400×400 and WIDTH×HEIGHT: the fastest and the median.
    FrameOnly,
    /// Frames without a feature and nothing printed, for an instruction
    /// counter (benches/feature-instructions.sh).
    UnusedFeature {
        feature: &'a str,
        unspecialised: bool,
        frames: u32,
    },
}

impl BenchArgs {
    pub fn mode(&self) -> BenchMode<'_> {
        let m = &self.mode;
        match (&m.unused_feature, m.primary_only, m.frame_only) {
            (Some(feature), ..) => BenchMode::UnusedFeature {
                feature,
                unspecialised: self.unspecialised,
                frames: self.frames,
            },
            (None, true, _) => BenchMode::PrimaryOnly,
            (None, false, true) => BenchMode::FrameOnly,
            (None, false, false) => BenchMode::Study,
        }
    }
}

pub fn bench(a: &BenchArgs) -> Result<()> {
    // Dropped on an error: `--out-dir`, if this run made it, is removed.
    let new_dirs = check_limits(a)?;
    let (sf, scene) = load_scene(a.scene.as_deref())?;
    let variants = lensview::bench::feature_variants(&sf).len();
    limits::check_total("the benchmark", bench_work::work(a, scene.lights.len(), variants))?;
    run_mode(a, &sf, &scene)?;
    if let Some(d) = new_dirs {
        d.keep();
    }
    Ok(())
}

fn run_mode(a: &BenchArgs, sf: &SceneFile, scene: &Scene) -> Result<()> {
    match a.mode() {
        BenchMode::UnusedFeature {
            feature,
            unspecialised,
            frames,
        } => {
            for _ in 0..frames {
                if unused_feature_frame(sf, feature, unspecialised, a.width, a.height).is_none() {
                    bail!(
                        "--unused-feature: unknown feature {feature:?}; one of {}",
                        FEATURES.join(", ")
                    );
                }
            }
            Ok(())
        }
        BenchMode::PrimaryOnly => {
            primary_only(scene, a.width, a.height, a.runs);
            Ok(())
        }
        BenchMode::FrameOnly => {
            frame_only(scene, a.width, a.height, a.runs);
            Ok(())
        }
        BenchMode::Study => study(
            &Study {
                sf,
                scene,
                runs: a.runs,
                quick: a.quick,
            },
            &a.out_dir,
        ),
    }
}

/// The shared limits ([`limits`]) for this run's size, runs and frames,
/// and for the study a `--out-dir` where every file it writes can be
/// written, checked before the scene is read (its work is checked after:
/// [`bench_work::work`]). Returns the directories made for `--out-dir`
/// (removed again if the run fails).
fn check_limits(a: &BenchArgs) -> Result<Option<output::NewDirs>> {
    limits::check_image("--width × --height", a.width, a.height, limits::IMAGE_BYTES_PER_PIXEL)?;
    limits::check_count("--runs", a.runs as u64, limits::MAX_RUNS as u64)?;
    match a.mode() {
        BenchMode::UnusedFeature { frames, .. } => {
            limits::check_count("--frames", frames as u64, limits::MAX_RUNS as u64)?;
            Ok(None)
        }
        BenchMode::Study => check_outputs(a).map(Some),
        BenchMode::PrimaryOnly | BenchMode::FrameOnly => Ok(None),
    }
}

/// Makes `--out-dir` and checks every file the study writes there
/// ([`study_files`]): each writable, none the scene.
fn check_outputs(a: &BenchArgs) -> Result<output::NewDirs> {
    let made = output::create_dirs(&a.out_dir).with_context(|| format!("cannot create {}", a.out_dir.display()))?;
    let outputs = study_files(&a.out_dir);
    let named: Vec<(&str, &Path)> = outputs.iter().map(|p| ("output", p.as_path())).collect();
    let scene_input = a.scene.as_deref().map(|p| ("the scene", p));
    files::check_distinct(scene_input.as_slice(), &named)?;
    for p in &outputs {
        output::check_target(p)?;
    }
    Ok(made)
}

/// Every file the study writes in `out_dir`: each report's CSV and, for
/// those plotted, its PNG.
fn study_files(out_dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for (name, _, plotted) in REPORTS {
        files.push(out_dir.join(format!("{name}.csv")));
        if plotted {
            files.push(out_dir.join(format!("{name}.png")));
        }
    }
    files
}

/// Closest-hit primary rays per second at one size, cast three ways.
struct PrimaryRates {
    /// In tiles of camera packets, as the renderer casts them.
    tiles: f64,
    /// Each packet walking the BVH alone.
    packets: f64,
    /// One ray at a time.
    one_by_one: f64,
}

impl PrimaryRates {
    fn measure(scene: &Scene, width: u32, height: u32, runs: usize) -> Self {
        PrimaryRates {
            tiles: primary_rays_per_second(scene, width, height, runs, true),
            packets: primary_rays_per_second(scene, width, height, runs, false),
            one_by_one: primary_rays_per_second_scalar(scene, width, height, runs),
        }
    }

    /// The three rates in words.
    fn summary(&self) -> String {
        use lensview::simd::{LANES, isa};
        use lensview::trace::TILE;
        format!(
            "{:.2} M rays/s in tiles of {TILE} packets of {LANES} ({}), {:.2} M rays/s in packets walking alone, \
             {:.2} M rays/s one by one (tiles {:.2}× one by one)",
            self.tiles / 1e6,
            isa().name(),
            self.packets / 1e6,
            self.one_by_one / 1e6,
            self.tiles / self.one_by_one
        )
    }
}

fn primary_only(scene: &Scene, width: u32, height: u32, runs: usize) {
    let r = PrimaryRates::measure(scene, width, height, runs);
    println!("primary_rays_per_s {:.0}", r.tiles);
    println!("primary_rays_per_s_packets_alone {:.0}", r.packets);
    println!("primary_rays_per_s_scalar {:.0}", r.one_by_one);
    println!(
        "lensview: closest-hit primary rays at {width}×{height} ({} threads): {}",
        rayon::current_num_threads(),
        r.summary()
    );
}

/// The sizes `--frame-only` times: 400×400, then WIDTH×HEIGHT unless it
/// is 400×400 too (benches/mitsuba_speed.py times that size alone).
fn frame_sizes(width: u32, height: u32) -> Vec<(u32, u32)> {
    let mut sizes = vec![(400, 400), (width, height)];
    sizes.dedup();
    sizes
}

fn frame_only(scene: &Scene, width: u32, height: u32, runs: usize) {
    let sizes = frame_sizes(width, height);
    let items: Vec<_> = sizes.iter().map(|&(w, h)| (scene, w, h)).collect();
    let times = interleaved_frame_samples(&items, runs);
    for ((w, h), v) in sizes.iter().zip(&times) {
        println!(
            "frame {w}x{h} ({} threads, {} runs): fastest {:.2} ms, median {:.2} ms ({} lanes)",
            rayon::current_num_threads(),
            v.len(),
            v[0] * 1e3,
            v[v.len() / 2] * 1e3,
            lensview::simd::isa().name()
        );
    }
}

/// What the reports of the full study share.
struct Study<'a> {
    sf: &'a SceneFile,
    scene: &'a Scene,
    runs: usize,
    /// Small sizes and few points (`--quick`).
    quick: bool,
}

/// A report of the full study: it measures and returns its table.
type Report = fn(&Study) -> Table;

/// The reports of the full study, the names of their files and whether
/// each is plotted, in the order they run.
const REPORTS: [(&str, Report, bool); 4] = [
    ("bench-size", report_sizes, true),
    ("bench-objects", report_objects, true),
    ("bench-throughput", report_throughput, false),
    ("bench-features", report_features, false),
];

fn study(s: &Study, out_dir: &Path) -> Result<()> {
    println!(
        "lensview bench: median of {} runs (the points of a sweep timed round-robin), {} threads, \
         1 sample per pixel, full Whitted shading",
        s.runs,
        rayon::current_num_threads()
    );
    let (mut written, mut files) = (Vec::new(), Vec::new());
    for (name, report, plotted) in REPORTS {
        let table = report(s);
        debug_assert_eq!(table.plot.is_some(), plotted, "{name}");
        files.extend(table.emit(
            &out_dir.join(format!("{name}.csv")),
            &out_dir.join(format!("{name}.png")),
        )?);
        written.push(if plotted {
            format!("{name}.csv/png")
        } else {
            format!("{name}.csv")
        });
    }
    // All files at once, at the end: a run that fails writes none.
    write_files(&files)?;
    println!("\nwrote {} in {}", written.join(", "), out_dir.display());
    Ok(())
}

/// Render time against image size; the square sizes plotted.
fn report_sizes(s: &Study) -> Table {
    let sizes = bench_work::sizes(s.quick);
    let items: Vec<(&Scene, u32, u32)> = sizes.iter().map(|&(w, h)| (s.scene, w, h)).collect();
    let times = interleaved_frame_times(&items, s.runs);
    let title = "render time against image size (cubes scene, 1 spp)";
    let mut t = Table::new(
        title,
        vec![
            Column::new("width", "width"),
            Column::new("height", "height"),
            Column::new("pixels", "pixels"),
            Column::new("median_ms", "median ms"),
            Column::shown("M samples/s"),
        ],
    );
    let mut square = series("lensview");
    for (&(w, h), secs) in sizes.iter().zip(times) {
        let (ms, px) = (secs * 1e3, (w * h) as f64);
        t.row(vec![
            w.to_string(),
            h.to_string(),
            px.to_string(),
            num(ms, 3),
            num(px / ms / 1e3, 2),
        ]);
        if w == h {
            square.points.push((px, ms));
            square.labels.push(format!(" {w}²"));
        }
    }
    t.plot = Some(Plot {
        title: title.into(),
        x_label: "pixels".into(),
        y_label: "median frame time (ms)".into(),
        series: vec![square],
    });
    t
}

/// Render time against object count: the cubes scene with its cubes
/// removed one by one, and grids of more cubes over the same area, timed
/// in one round-robin.
fn report_objects(s: &Study) -> Table {
    let ((w, h), counts, sides) = bench_work::objects(s.quick);
    let subsets = counts.iter().map(|&n| cubes_subset(s.sf, n));
    let grids = sides.iter().map(|&side| cubes_grid(s.sf, side));
    let scenes: Vec<Scene> = subsets.chain(grids).collect();
    let items: Vec<(&Scene, u32, u32)> = scenes.iter().map(|sc| (sc, w, h)).collect();
    let times = interleaved_frame_times(&items, s.runs);
    let title = format!("render time against object count ({w}×{h}, 1 spp)");
    let mut t = Table::new(
        title.clone(),
        vec![
            Column::new("series", "series"),
            Column::new("objects", "objects"),
            Column::new("median_ms", "median ms"),
        ],
    );
    let mut removal = series("cubes scene, cubes removed one by one");
    let mut grid = series("grid of N cubes over the same area");
    let objects = counts.iter().copied().chain(sides.iter().map(|side| side * side));
    for (i, (n, secs)) in objects.zip(times).enumerate() {
        let ms = secs * 1e3;
        let (label, points, x) = if i < counts.len() {
            // A log axis has no 0: the scene without cubes is drawn at 1.
            ("cubes scene", &mut removal.points, n.max(1))
        } else {
            ("grid", &mut grid.points, n)
        };
        t.row(vec![label.into(), n.to_string(), num(ms, 3)]);
        points.push((x as f64, ms));
    }
    if let (Some(g25), Some(last)) = (grid.points.iter().find(|p| p.0 == 25.0), grid.points.last()) {
        t.notes
            .push(format!("{} cubes cost {:.2}× the time of 25", last.0, last.1 / g25.1));
    }
    t.plot = Some(Plot {
        title,
        x_label: "cubes".into(),
        y_label: "median frame time (ms)".into(),
        series: vec![removal, grid],
    });
    t
}

/// Primary-ray throughput, full frame times and the first progressive level.
fn report_throughput(s: &Study) -> Table {
    use lensview::render::progressive::{Progressive, Stage};
    let (w, h) = bench_work::throughput_size(s.quick);
    let rates = PrimaryRates::measure(s.scene, w, h, s.runs);
    let frame = frame_time(s.scene, w, h, s.runs.min(3));
    let small = frame_time(s.scene, 400, 400, s.runs);
    let mut p = Progressive::new(w, h, 0);
    let first = median_time(s.runs, || {
        p.reset(w, h, 0);
        p.run(s.scene, Stage::Blocks(8), &|| false);
    });
    let mut t = Table::new(
        format!("throughput at {w}×{h}"),
        vec![Column::new("measure", "measure"), Column::new("value", "value")],
    );
    for (measure, value) in [
        ("primary_rays_per_s_tiles".into(), num(rates.tiles, 0)),
        ("primary_rays_per_s_packets_alone".into(), num(rates.packets, 0)),
        ("primary_rays_per_s_one_by_one".into(), num(rates.one_by_one, 0)),
        (format!("frame_ms_{w}x{h}"), num(frame * 1e3, 3)),
        ("frame_ms_400x400".into(), num(small * 1e3, 3)),
        (format!("first_level_8x8_ms_{w}x{h}"), num(first * 1e3, 3)),
    ] {
        t.row(vec![measure, value]);
    }
    t.notes = vec![
        format!("primary rays (closest hit, no shading): {}", rates.summary()),
        format!(
            "full Whitted frame at {w}×{h}: {:.1} ms ({:.1} fps); at 400×400: {:.1} ms",
            frame * 1e3,
            1.0 / frame,
            small * 1e3
        ),
    ];
    t
}

/// What each feature costs, in milliseconds a frame, and what carrying it
/// unused would cost.
fn report_features(s: &Study) -> Table {
    let (w, h) = bench_work::features_size(s.quick);
    let mut t = Table::new(
        format!("feature costs at {w}×{h} (ms)"),
        vec![
            Column::new("feature", "feature"),
            Column::new("with_ms", "with"),
            Column::new("without_ms", "without"),
            Column::new("unused_specialised_ms", "unused: left out"),
            Column::new("unused_unspecialised_ms", "compiled in"),
            Column::shown("overhead"),
        ],
    );
    for c in feature_costs(s.sf, w, h, s.runs) {
        t.row(vec![
            c.feature.into(),
            num(c.with_ms, 3),
            num(c.without_ms, 3),
            num(c.unused_specialised_ms, 3),
            num(c.unused_unspecialised_ms, 3),
            format!("{:.1}%", 100.0 * c.unused_overhead()),
        ]);
    }
    t
}

fn series(name: &str) -> Series {
    Series {
        name: name.into(),
        points: Vec::new(),
        labels: Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    fn mode_of(args: &[&str]) -> Result<String, clap::Error> {
        let cli = super::super::Cli::try_parse_from([&["lensview", "bench"], args].concat())?;
        match cli.command {
            Some(super::super::Command::Bench(a)) => Ok(format!("{:?}", a.mode())),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn flags_pick_one_mode() {
        assert_eq!(mode_of(&[]).unwrap(), "Study");
        assert_eq!(mode_of(&["--quick", "--runs", "1"]).unwrap(), "Study");
        assert_eq!(mode_of(&["--primary-only"]).unwrap(), "PrimaryOnly");
        assert_eq!(mode_of(&["--frame-only", "--width", "64"]).unwrap(), "FrameOnly");
        assert_eq!(
            mode_of(&["--unused-feature", "glass", "--unspecialised", "--frames", "2"]).unwrap(),
            r#"UnusedFeature { feature: "glass", unspecialised: true, frames: 2 }"#
        );
        assert!(mode_of(&["--primary-only", "--frame-only"]).is_err());
        assert!(mode_of(&["--frame-only", "--unused-feature", "glass"]).is_err());
        assert!(mode_of(&["--unspecialised"]).is_err());
    }

    #[test]
    fn frame_only_times_400_by_400_once() {
        assert_eq!(frame_sizes(64, 36), [(400, 400), (64, 36)]);
        assert_eq!(frame_sizes(400, 400), [(400, 400)]);
    }
}
