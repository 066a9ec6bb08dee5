//! `lensview converge`: error against run time of the progressive
//! schedule, as a table (CSV) and a log–log plot (PNG).

use super::load_scene;
use super::table::{Column, Plot, Table, num, write_files};
use crate::plot::Series;
use anyhow::Result;
use clap::Args;
use lensview::bench::convergence::{
    ConvergeRow, Work, at_multiple, converge as converge_rows, converge_step, reference, step_camera,
};
use lensview::render::Adaptive;
use lensview::render::Image;
use lensview::render::progressive::Sampling;
use lensview::sampling::Pattern;
use lensview::scene::Scene;
use lensview::{files, limits, output};
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args, Debug)]
pub struct ConvergeArgs {
    /// Scene file (TOML); the embedded default scene when omitted.
    pub scene: Option<PathBuf>,
    #[arg(long, default_value_t = 400)]
    pub width: u32,
    #[arg(long, default_value_t = 300)]
    pub height: u32,
    /// Samples per pixel the schedule refines to.
    #[arg(long, default_value_t = 64)]
    pub max_spp: u32,
    /// Samples per pixel of the reference (rendered with another sample pattern).
    #[arg(long, default_value_t = 256)]
    pub reference_spp: u32,
    /// Uniform waves (every pixel gets every sample) instead of adaptive ones.
    #[arg(long)]
    pub uniform_waves: bool,
    /// Sample points after the centre: `r2` (low discrepancy) or `uniform`
    /// (hashed jitter, as before issue #21).
    #[arg(long, default_value = "r2", value_parser = ["r2", "uniform"])]
    pub pattern: String,
    /// Also run the other three combinations of pattern and waves, each a
    /// series of the table and the plot.
    #[arg(long)]
    pub compare: bool,
    /// Measure after a camera step instead: right, up, forward (scene
    /// units), then yaw and pitch (degrees); `0,0,0.1` is W held for 1/30 s
    /// at the default flight speed. The previous view is refined to
    /// --max-spp first; the reference is of the new view.
    #[arg(long, value_name = "DX,DY,DZ[,YAW,PITCH]", value_parser = parse_step)]
    pub camera_step: Option<[f64; 5]>,
    /// Block size at which a reprojection traces what it cannot move
    /// (1: each such pixel's centre).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub step_block: u32,
    /// CSV table to write.
    #[arg(long, default_value = "converge.csv")]
    pub csv: PathBuf,
    /// PNG plot to write (error against time, log scales).
    #[arg(long, default_value = "converge.png")]
    pub plot: PathBuf,
}

/// Renders the reference, runs the schedule against it, and reports one
/// table (printed, `--csv`, plotted to `--plot`).
pub fn converge(a: &ConvergeArgs) -> Result<()> {
    // The reference's image and the schedule's planes and stage images.
    let bpp = limits::PROGRESSIVE_BYTES_PER_PIXEL + 2 * 24;
    limits::check_image("--width × --height", a.width, a.height, bpp)?;
    limits::check_spp("--max-spp", a.max_spp)?;
    limits::check_spp("--reference-spp", a.reference_spp)?;
    let scene_input = a.scene.as_deref().map(|p| ("the scene", p));
    files::check_distinct(
        scene_input.as_slice(),
        &[("--csv", a.csv.as_path()), ("--plot", a.plot.as_path())],
    )?;
    output::check_target(&a.csv)?;
    output::check_target(&a.plot)?;
    let (_, before) = load_scene(a.scene.as_deref())?;
    // Each schedule renders about 2 × max-spp samples a pixel in all, each
    // sample shading every light.
    let spp = a.reference_spp as u64 + 8 * a.max_spp as u64 + 1;
    let work = limits::Work::samples(a.width, a.height, spp, 1).with_lights(before.lights.len());
    limits::check_total("the reference and the schedule", work)?;
    let scene = match a.camera_step {
        Some(step) => step_camera(&before, step),
        None => before.clone(),
    };
    eprintln!("rendering the reference at {} spp…", a.reference_spp);
    let t = Instant::now();
    let reference = reference(&scene, a.width, a.height, a.reference_spp, 1);
    eprintln!("reference done in {:.1} s", t.elapsed().as_secs_f64());
    let runs = runs(a, (&before, &scene), &reference);
    let name = a
        .scene
        .as_deref()
        .map_or("default scene".to_string(), |p| p.display().to_string());
    let title = format!("{name}, {}×{}: error against run time", a.width, a.height);
    let mut t = table(title.clone(), &runs);
    t.plot = Some(Plot {
        title,
        x_label: "time since refinement started (ms)".into(),
        y_label: format!("RMSE against {} spp reference", a.reference_spp),
        series: runs
            .iter()
            .enumerate()
            .map(|(i, (name, rows))| Series {
                name: name.clone(),
                points: rows.iter().map(|r| (r.elapsed_ms, r.rmse)).collect(),
                // Stage labels on the first series only (the others would
                // print over it).
                labels: rows
                    .iter()
                    .filter(|_| i == 0)
                    .map(|r| format!(" {}", r.stage))
                    .collect(),
            })
            .collect(),
    });
    // The CSV and the plot both ready before either is written.
    write_files(&t.emit(&a.csv, &a.plot)?)?;
    println!("wrote {} and {}", a.csv.display(), a.plot.display());
    Ok(())
}

/// The measured series: the camera step (when asked), then the chosen
/// sampling and, with `--compare`, the other three.
fn runs(a: &ConvergeArgs, (before, scene): (&Scene, &Scene), reference: &Image) -> Vec<(String, Vec<ConvergeRow>)> {
    let pattern = |p: &str| if p == "uniform" { Pattern::Uniform } else { Pattern::R2 };
    let adaptive = Some(Adaptive::default());
    let mut runs = vec![(pattern(&a.pattern), if a.uniform_waves { None } else { adaptive })];
    if a.compare {
        for p in [Pattern::R2, Pattern::Uniform] {
            for w in [adaptive, None] {
                if !runs.contains(&(p, w)) {
                    runs.push((p, w));
                }
            }
        }
    }
    let mut step_runs = Vec::new();
    if a.camera_step.is_some() {
        let name = format!(
            "camera step: reprojected (holes at {0}×{0}) + adaptive waves",
            a.step_block
        );
        eprintln!("{name}…");
        let rows = converge_step((before, scene), reference, a.max_spp, Sampling::default(), a.step_block);
        step_runs.push((name, rows));
    }
    step_runs
        .into_iter()
        .chain(runs.into_iter().map(|(pattern, adaptive)| {
            let name = format!(
                "{} points + {} waves",
                if pattern == Pattern::R2 { "R2" } else { "uniform" },
                if adaptive.is_some() { "adaptive" } else { "uniform" }
            );
            eprintln!("{name}…");
            (
                name,
                converge_rows(scene, reference, a.max_spp, Sampling { pattern, adaptive }),
            )
        }))
        .collect()
}

/// One row per stage of every series, and the PSNR at multiples of the
/// 1-spp work as notes.
fn table(title: String, runs: &[(String, Vec<ConvergeRow>)]) -> Table {
    let mut t = Table::new(
        title,
        vec![
            Column::new("sampling", "sampling"),
            Column::new("stage", "stage"),
            Column::new("spp", "spp"),
            Column::new("samples_per_pixel", "samples/px"),
            Column::new("stage_ms", "stage ms"),
            Column::new("elapsed_ms", "elapsed ms"),
            Column::new("rmse", "RMSE"),
            Column::new("psnr_db", "PSNR dB"),
        ],
    );
    for (name, rows) in runs {
        for r in rows {
            t.row(vec![
                name.clone(),
                r.stage.clone(),
                r.spp.to_string(),
                num(r.samples_per_pixel, 3),
                num(r.stage_ms, 3),
                num(r.elapsed_ms, 3),
                num(r.rmse, 6),
                num(r.psnr_db, 3),
            ]);
        }
        for work in [Work::Time, Work::Samples] {
            let at: Vec<String> = [1.0, 2.0, 3.0, 4.0]
                .iter()
                .map(|&k| at_multiple(rows, k, work).map_or("-".into(), |p| format!("{k}× {p:.2} dB")))
                .collect();
            let unit = match work {
                Work::Time => "the 1-spp time",
                Work::Samples => "the 1-spp samples",
            };
            t.notes
                .push(format!("{name}: PSNR at multiples of {unit}: {}", at.join(", ")));
        }
    }
    t
}

/// `DX,DY,DZ[,YAW,PITCH]`: five finite numbers (yaw and pitch default 0).
fn parse_step(s: &str) -> Result<[f64; 5], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>().map_err(|e| format!("{x:?}: {e}")))
        .collect::<Result<_, _>>()?;
    if !(v.len() == 3 || v.len() == 5) || v.iter().any(|x| !x.is_finite() || x.abs() > 1e6) {
        return Err("expected DX,DY,DZ or DX,DY,DZ,YAW,PITCH: finite numbers of magnitude at most 1e6".into());
    }
    Ok([v[0], v[1], v[2], *v.get(3).unwrap_or(&0.0), *v.get(4).unwrap_or(&0.0)])
}

#[cfg(test)]
mod tests {
    use super::parse_step;

    #[test]
    fn camera_steps_parse_and_bad_ones_are_refused() {
        assert_eq!(parse_step("0,0,0.1"), Ok([0.0, 0.0, 0.1, 0.0, 0.0]));
        assert_eq!(parse_step("1, 2,3,4,5"), Ok([1.0, 2.0, 3.0, 4.0, 5.0]));
        for bad in ["", "1,2", "1,2,3,4", "1,2,x", "1,2,NaN", "1,2,inf", "1,2,3,4,5,6"] {
            assert!(parse_step(bad).is_err(), "{bad}");
        }
    }
}
