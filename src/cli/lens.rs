//! `lensview lens`: real rays through lenses (`trace`, JSON in and out)
//! and a lens's paraxial data (`info`).

use anyhow::{Context, Result, bail};
use clap::{Args, Subcommand};
use std::path::{Path, PathBuf};

#[derive(Subcommand, Debug)]
pub enum LensCommand {
    /// Trace real rays through lenses given in a JSON file; JSON on stdout.
    Trace {
        /// The cases file: { "cases": [ { "id", "lens": {center, axis, d, R1, R2, n}, "rays": [...] } ] }.
        cases: PathBuf,
        /// Also list each ray's weighted branches: every ray out of the lens's
        /// Whitted tree (Fresnel-weighted, those above 1e-12) and the weight left out.
        #[arg(long)]
        branches: bool,
    },
    /// Paraxial data of a lens (light entering through S1), its real marginal focus and axial colour.
    Info(LensInfoArgs),
    /// A meridional ray fan through the lens, drawn to scale (SVG or PNG) or as JSON with the LSA curve.
    Fan(super::lens_figures::FanArgs),
    /// Spot diagram (hexapolar pupil, C, d and F lines) at an image plane.
    Spot(super::lens_figures::SpotArgs),
    /// Distortion (%) of the real chief ray against the paraxial image height, by field angle.
    Distortion(super::lens_figures::DistortionArgs),
    /// First-order data of a lens system (EFL, BFD, FFD, H, H', pupils, f-number, axial colour)
    /// from a JSON system, a prescription file or a preset.
    System(super::lens_system::LensSystemArgs),
}

#[derive(Args, Debug)]
pub struct LensInfoArgs {
    #[command(flatten)]
    pub shape: LensShape,
    /// Wavelength in µm (default: the helium d line, 0.5875618).
    #[arg(long, default_value_t = lensview::optics::WAVELENGTH_D_UM)]
    pub wavelength_um: f64,
    /// An object this far before V1: its paraxial image, real or virtual (a magnifier's), and
    /// the magnification.
    #[arg(long)]
    pub object_distance: Option<f64>,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Every digit in the table (the shortest text that reads back to the
    /// same number), not rounded to 9 decimals.
    #[arg(long)]
    pub exact: bool,
}

/// The lens: diameter, radii and index.
#[derive(Args, Debug)]
pub struct LensShape {
    /// Diameter.
    #[arg(long)]
    pub d: f64,
    /// Radius of curvature of S1 (magnitude, ≥ d/2).
    #[arg(long)]
    pub r1: f64,
    /// Radius of curvature of S2 (magnitude, ≥ d/2).
    #[arg(long)]
    pub r2: f64,
    /// Refractive index (a number), Cauchy coefficients as A,B (n = A + B/λ², λ in µm), or a catalogue
    /// glass's name (N-BK7, N-SF5, F2, …: Sellmeier dispersion).
    #[arg(long, value_parser = parse_index)]
    pub n: lensview::optics::Index,
}

pub(super) fn parse_index(s: &str) -> Result<lensview::optics::Index, String> {
    let num = |t: &str| {
        t.trim()
            .parse::<f64>()
            .map_err(|e| format!("`{t}` is not a number: {e}"))
    };
    let s = s.trim().trim_start_matches("cauchy:");
    match s.split_once(',') {
        Some((a, b)) => Ok(lensview::optics::Index::Cauchy { a: num(a)?, b: num(b)? }),
        None if s.parse::<f64>().is_err() && s.chars().any(|c| c.is_ascii_alphabetic()) => {
            match lensview::glass::lookup(s) {
                Some(g) => Ok(lensview::optics::Index::Glass(g)),
                None => Err(format!(
                    "`{s}` is neither a number nor a known glass (known: {})",
                    lensview::glass::names()
                )),
            }
        }
        None => Ok(lensview::optics::Index::Constant(num(s)?)),
    }
}

fn lens_trace(path: &Path, branches: bool) -> Result<()> {
    use lensview::lens_tools::{TraceInput, check_cases, write_trace_json};
    use std::io::Write;
    let name = path.display();
    let bytes = lensview::scene::read_capped(path, lensview::limits::TRACE_INPUT_CAP)?;
    let mut input: TraceInput =
        serde_json::from_slice(&bytes).map_err(|e| anyhow::anyhow!("{name}:{}:{}: {e}", e.line(), e.column()))?;
    drop(bytes);
    input.branches = branches;
    // Every case and ray is checked before anything is written (a refusal
    // writes nothing); then each ray is traced as its JSON is written, so
    // the output is never held whole (10^6 rays would take over 1 GB).
    check_cases(&input).map_err(|e| anyhow::anyhow!("{name}: {e}"))?;
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    write_trace_json(&input, &mut out).map_err(|e| anyhow::anyhow!("{name}: {e}"))?;
    writeln!(out)
        .and_then(|()| out.flush())
        .context("writing the traced rays to stdout")?;
    Ok(())
}

fn lens_info(a: &LensInfoArgs) -> Result<()> {
    if !(a.wavelength_um > 0.0 && a.wavelength_um.is_finite()) {
        bail!("--wavelength-um must be a positive number, got {}", a.wavelength_um);
    }
    // Each refusal names the flag the user typed (`--r1`), not only the
    // lens's own name for the value (`radius r1`).
    let sh = &a.shape;
    for (flag, v) in [("--d", sh.d), ("--r1", sh.r1), ("--r2", sh.r2)] {
        if !v.is_finite() {
            bail!("impossible lens: {flag} must be a finite number, got {v}");
        }
    }
    if let Some(dist) = a.object_distance {
        lensview::lens_tools::setup::check_object(Some(dist), 0.0, "V1")?;
    }
    let mut info = lensview::lens_tools::lens_info(sh.d, sh.r1, sh.r2, sh.n, a.wavelength_um)
        .map_err(|e| anyhow::anyhow!("impossible lens: --{}: {e}", e.field()))?;
    if let Some(dist) = a.object_distance {
        info = info.with_object(dist);
    }
    if a.json {
        println!("{}", serde_json::to_string_pretty(&info)?);
    } else if a.exact {
        print!("{info:#}");
    } else {
        print!("{info}");
    }
    Ok(())
}

pub fn lens(c: LensCommand) -> Result<()> {
    match c {
        LensCommand::Trace { cases, branches } => lens_trace(&cases, branches),
        LensCommand::Info(a) => lens_info(&a),
        LensCommand::System(a) => super::lens_system::lens_system(&a),
        LensCommand::Fan(a) => super::lens_figures::fan(&a),
        LensCommand::Spot(a) => super::lens_figures::spot(&a),
        LensCommand::Distortion(a) => super::lens_figures::distortion(&a),
    }
}
