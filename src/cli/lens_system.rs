//! `lensview lens system`: first-order data of a lens system given as a
//! JSON system (as `lens trace` reads it), a prescription file in
//! pbrt-v4's form, or a built-in preset.

use anyhow::{Context, Result, bail};
use clap::Args;
use glam::DVec3;
use lensview::geometry::{LensSystem, SurfaceSpec};
use lensview::lens_tools::system_info::{DEFAULT_WAVELENGTH_UM, system_info};
use lensview::prescription;
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct LensSystemArgs {
    /// A system as JSON: {"vertex", "axis", "surfaces": [{radius, thickness, n, semi_aperture, stop}]};
    /// or a scene file (.toml): its lens system number --system-index (from 0) of its [[systems]].
    #[arg(long, value_name = "FILE", conflicts_with_all = ["prescription", "preset"])]
    pub system: Option<PathBuf>,
    /// Which of a scene's [[systems]] --system reads (from 0).
    #[arg(long, default_value_t = 0)]
    pub system_index: usize,
    /// With a scene file at --system: its camera's lens ([camera] lens) instead of a [[systems]] entry.
    #[arg(long, requires = "system")]
    pub camera: bool,
    /// A prescription file (pbrt-v4 lens format: radius, thickness, index after, aperture diameter).
    #[arg(long, value_name = "FILE", conflicts_with = "preset")]
    pub prescription: Option<PathBuf>,
    /// A built-in prescription: double-gauss-50mm, cooke-triplet-100mm, achromat-AC254-100-A, wide-22mm,
    /// telephoto-250mm, fisheye-10mm.
    #[arg(long)]
    pub preset: Option<String>,
    /// Lengths of a prescription or preset multiplied by this.
    #[arg(long, default_value_t = 1.0)]
    pub scale: f64,
    /// Wavelength in µm (default: the helium d line, 0.5875618).
    #[arg(long, default_value_t = DEFAULT_WAVELENGTH_UM)]
    pub wavelength_um: f64,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// The system the arguments name.
fn load(a: &LensSystemArgs) -> Result<LensSystem> {
    load_system(
        a.system.as_deref().map(|p| (p, (!a.camera).then_some(a.system_index))),
        a.prescription.as_deref(),
        a.preset.as_deref(),
        a.scale,
    )
}

/// The system of exactly one of a JSON file (or a scene file's lens
/// system of that index; `None`: its camera's lens), a prescription file
/// or a preset; `scale` multiplies the lengths of a prescription or preset.
pub(super) fn load_system(
    system: Option<(&Path, Option<usize>)>,
    prescription: Option<&Path>,
    preset: Option<&str>,
    scale: f64,
) -> Result<LensSystem> {
    if !(scale > 0.0 && scale.is_finite()) {
        bail!("--scale must be a positive number, got {scale}");
    }
    let from_rows = |name: &str, text: &str| -> Result<LensSystem> {
        let rows = prescription::parse(name, text).map_err(|e| anyhow::anyhow!("{e}"))?;
        LensSystem::new(DVec3::ZERO, DVec3::Z, SurfaceSpec::from_rows(&rows, scale)).map_err(|e| match e.surface {
            Some(k) => anyhow::anyhow!("{name}:{}: {}: {}", rows[k].line, e.field, e.message),
            None => anyhow::anyhow!("{name}: {}: {}", e.field, e.message),
        })
    };
    match (system, prescription, preset) {
        (Some((path, None)), None, None) if path.extension().is_some_and(|e| e == "toml") => {
            // The camera's lens whether shown or not (`pinhole = true`).
            let (sf, _) = lensview::scene::Scene::load(path)?;
            match lensview::scene::lens_camera_of(&sf) {
                Some(lens) => Ok(lens.system),
                None => bail!("{}: --camera: the scene's [camera] has no lens", path.display()),
            }
        }
        (Some((path, Some(index))), None, None) if path.extension().is_some_and(|e| e == "toml") => {
            let (_, scene) = lensview::scene::Scene::load(path)?;
            let count = scene.objects.iter().filter(|o| o.system().is_some()).count();
            match scene.objects.iter().filter_map(|o| o.system()).nth(index) {
                Some(sys) => Ok(sys.clone()),
                None => bail!(
                    "{}: --system-index {index}: the scene has {count} lens system{} ([[systems]])",
                    path.display(),
                    if count == 1 { "" } else { "s" }
                ),
            }
        }
        (Some((path, _)), None, None) => {
            let name = path.display().to_string();
            let bytes = lensview::scene::read_capped(path, lensview::limits::TRACE_INPUT_CAP)?;
            let spec: lensview::lens_tools::system_trace::SystemSpec = serde_json::from_slice(&bytes)
                .map_err(|e| anyhow::anyhow!("{name}:{}:{}: {e}", e.line(), e.column()))?;
            spec.build().map_err(|e| anyhow::anyhow!("{name}: {e}"))
        }
        (None, Some(path), None) => {
            let name = path.display().to_string();
            let bytes = lensview::scene::read_capped(path, lensview::limits::TRACE_INPUT_CAP)?;
            let text = String::from_utf8(bytes).with_context(|| format!("{name}: not UTF-8 text"))?;
            from_rows(&name, &text)
        }
        (None, None, Some(p)) => match prescription::preset(p) {
            Some(text) => from_rows(p, text),
            None => {
                let names: Vec<&str> = prescription::PRESETS.iter().map(|(n, _)| *n).collect();
                bail!("--preset: no preset `{p}`: one of {}", names.join(", "))
            }
        },
        _ => bail!("give one of --system, --prescription or --preset"),
    }
}

pub fn lens_system(a: &LensSystemArgs) -> Result<()> {
    if !(a.wavelength_um > 0.0 && a.wavelength_um.is_finite()) {
        bail!("--wavelength-um must be a positive number, got {}", a.wavelength_um);
    }
    let sys = load(a)?;
    let info = system_info(&sys, a.wavelength_um);
    if a.json {
        println!("{}", serde_json::to_string_pretty(&info)?);
    } else {
        print!("{info}");
    }
    Ok(())
}
