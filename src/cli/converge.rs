//! `lensview converge`: error against run time of the progressive
//! schedule, as a table (CSV) and a log–log plot (PNG).

use super::load_scene;
use super::table::{Column, Plot, Table, num};
use crate::plot::Series;
use anyhow::Result;
use clap::Args;
use lensview::bench::convergence::{converge as converge_rows, reference};
use lensview::{limits, output};
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
    // The schedule renders about 2 × max-spp samples a pixel in all.
    let spp = a.reference_spp as u64 + 2 * a.max_spp as u64 + 1;
    limits::check_work("the reference and the schedule", a.width, a.height, spp, 1)?;
    output::check_target(&a.csv)?;
    output::check_target(&a.plot)?;
    let (_, scene) = load_scene(a.scene.as_deref())?;
    eprintln!("rendering the reference at {} spp…", a.reference_spp);
    let t = Instant::now();
    let reference = reference(&scene, a.width, a.height, a.reference_spp, 1);
    eprintln!("reference done in {:.1} s", t.elapsed().as_secs_f64());
    let rows = converge_rows(&scene, &reference, a.max_spp);
    let name = a
        .scene
        .as_deref()
        .map_or("default scene".to_string(), |p| p.display().to_string());
    let title = format!("{name}, {}×{}: error against run time", a.width, a.height);
    let mut t = Table::new(
        title.clone(),
        vec![
            Column::new("stage", "stage"),
            Column::new("spp", "spp"),
            Column::new("stage_ms", "stage ms"),
            Column::new("elapsed_ms", "elapsed ms"),
            Column::new("rmse", "RMSE"),
            Column::new("psnr_db", "PSNR dB"),
        ],
    );
    for r in &rows {
        t.row(vec![
            r.stage.clone(),
            r.spp.to_string(),
            num(r.stage_ms, 3),
            num(r.elapsed_ms, 3),
            num(r.rmse, 6),
            num(r.psnr_db, 3),
        ]);
    }
    t.plot = Some(Plot {
        title,
        x_label: "time since refinement started (ms)".into(),
        y_label: format!("RMSE against {} spp reference", a.reference_spp),
        series: vec![Series {
            name: "progressive schedule".into(),
            points: rows.iter().map(|r| (r.elapsed_ms, r.rmse)).collect(),
            labels: rows.iter().map(|r| format!(" {}", r.stage)).collect(),
        }],
    });
    t.emit(&a.csv, &a.plot)?;
    println!("wrote {} and {}", a.csv.display(), a.plot.display());
    Ok(())
}
