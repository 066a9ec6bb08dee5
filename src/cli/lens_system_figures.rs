//! `lensview lens fan | spot | distortion` for a lens system: which lens
//! the flags name (the biconvex lens of `--d --r1 --r2 --n`, or a system
//! from `--system`, `--prescription` or `--preset`, never both), and the
//! system's figures ([`lensview::lens_tools::system_fan`],
//! [`lensview::lens_tools::system_spot`]).

use super::lens_figures::{
    DistortionArgs, FanArgs, SpotArgs, field_spot, plane_words, print_json, refuse, rounded, spot_outputs, spot_row,
    write_sketch,
};
use anyhow::{Result, bail};
use clap::Args;
use glam::DVec3;
use lensview::geometry::{LensSystem, SurfaceSpec};
use lensview::lens_tools::system_bench::SystemBench;
use lensview::lens_tools::system_fan::system_fan;
use lensview::lens_tools::system_spot::{system_distortion, system_spot};
use lensview::optics::Index;
use std::path::PathBuf;

/// The lens of a figure: a biconvex lens, or a lens system.
#[derive(Args, Debug)]
pub struct FigureLens {
    /// Diameter of the biconvex lens.
    #[arg(long)]
    pub d: Option<f64>,
    /// Radius of curvature of S1 (magnitude, ≥ d/2).
    #[arg(long)]
    pub r1: Option<f64>,
    /// Radius of curvature of S2 (magnitude, ≥ d/2).
    #[arg(long)]
    pub r2: Option<f64>,
    /// Refractive index (a number), Cauchy coefficients as A,B (n = A + B/λ², λ in µm), or a catalogue
    /// glass's name (N-BK7, N-SF5, F2, …: Sellmeier dispersion).
    #[arg(long, value_parser = super::lens::parse_index)]
    pub n: Option<Index>,
    /// A lens system as JSON, or a scene file's (as `lens system --system` reads them) instead of the
    /// biconvex lens.
    #[arg(long, value_name = "FILE")]
    pub system: Option<PathBuf>,
    /// Which of a scene's [[systems]] --system reads (from 0).
    #[arg(long, default_value_t = 0)]
    pub system_index: usize,
    /// With a scene file at --system: its camera's lens ([camera] lens) instead of a [[systems]] entry.
    #[arg(long, requires = "system")]
    pub camera: bool,
    /// A prescription file (pbrt-v4 lens format) instead of the biconvex lens.
    #[arg(long, value_name = "FILE")]
    pub prescription: Option<PathBuf>,
    /// A built-in prescription (as `lens system --preset`) instead of the biconvex lens.
    #[arg(long)]
    pub preset: Option<String>,
    /// Lengths of the system multiplied by this.
    #[arg(long)]
    pub scale: Option<f64>,
    /// Centre a system's pupil rays on the real chief ray (through the stop's centre) instead of the
    /// paraxial entrance pupil's centre.
    #[arg(long)]
    pub aim_chief: bool,
}

/// What the flags name.
pub enum Which {
    Lens((f64, f64, f64, Index)),
    System(Box<LensSystem>),
}

impl FigureLens {
    /// The lens the flags name, or a one-line refusal.
    pub fn which(&self) -> Result<Which> {
        let lens: Vec<&str> = [
            ("--d", self.d.is_some()),
            ("--r1", self.r1.is_some()),
            ("--r2", self.r2.is_some()),
            ("--n", self.n.is_some()),
        ]
        .into_iter()
        .filter_map(|(f, given)| given.then_some(f))
        .collect();
        let system: Vec<&str> = [
            ("--system", self.system.is_some()),
            ("--prescription", self.prescription.is_some()),
            ("--preset", self.preset.is_some()),
        ]
        .into_iter()
        .filter_map(|(f, given)| given.then_some(f))
        .collect();
        let both = "give the biconvex lens (--d --r1 --r2 --n) or one system (--system, --prescription or --preset)";
        if !lens.is_empty() && !system.is_empty() {
            bail!("{} with {}: {both}, not both", lens.join(" "), system.join(" "));
        }
        if system.len() > 1 {
            bail!("{}: {both}, only one", system.join(" and "));
        }
        if system.is_empty() {
            for (flag, given) in [("--scale", self.scale.is_some()), ("--aim-chief", self.aim_chief)] {
                if given {
                    bail!(
                        "{flag}: applies to a system (--system, --prescription or --preset), not to the biconvex lens"
                    );
                }
            }
            return match (self.d, self.r1, self.r2, self.n) {
                (Some(d), Some(r1), Some(r2), Some(n)) => Ok(Which::Lens((d, r1, r2, n))),
                _ => {
                    let missing: Vec<&str> = ["--d", "--r1", "--r2", "--n"]
                        .into_iter()
                        .filter(|f| !lens.contains(f))
                        .collect();
                    bail!("{} missing: {both}", missing.join(" "))
                }
            };
        }
        let scale = self.scale.unwrap_or(1.0);
        let sys = super::lens_system::load_system(
            self.system
                .as_deref()
                .map(|p| (p, (!self.camera).then_some(self.system_index))),
            self.prescription.as_deref(),
            self.preset.as_deref(),
            scale,
        )?;
        // The figures measure in the system's own frame; a JSON system's
        // lengths are scaled here (a prescription's were as it was read).
        let s = if self.system.is_some() { scale } else { 1.0 };
        let surfaces = (sys.surfaces.iter())
            .map(|f| SurfaceSpec {
                radius: f.radius * s,
                thickness: f.thickness * s,
                semi_aperture: f.semi_aperture * s,
                ..*f
            })
            .collect();
        let sys = LensSystem::new(DVec3::ZERO, DVec3::Z, surfaces).map_err(|e| anyhow::anyhow!("--scale: {e}"))?;
        Ok(Which::System(Box::new(sys)))
    }
}

pub fn fan(a: &FanArgs, sys: Box<LensSystem>) -> Result<()> {
    let b = &a.bench;
    let bench = SystemBench::new(*sys, b.object_distance, b.field_deg).map_err(refuse)?;
    let bench = if b.shape.aim_chief { bench.aimed() } else { bench };
    if a.output.is_none() && !a.json {
        bail!("give -o fan.svg|fan.png, --json, or both");
    }
    let fan = system_fan(&bench, a.rays, a.image_plane).map_err(refuse)?;
    if let Some(path) = &a.output {
        write_sketch(path, &fan.sketch(&bench))?;
    }
    if a.json {
        print_json(&fan)?;
    }
    Ok(())
}

pub fn spot(a: &SpotArgs, sys: Box<LensSystem>) -> Result<()> {
    let b = &a.bench;
    let mut spots = Vec::new();
    for field in a.field_list() {
        let bench = SystemBench::new((*sys).clone(), b.object_distance, field).map_err(|e| a.refuse(e))?;
        let bench = if b.shape.aim_chief { bench.aimed() } else { bench };
        spots.push(system_spot(&bench, a.image_plane, a.rings).map_err(|e| a.refuse(e))?);
    }
    let chart = || {
        let fields = (spots.iter())
            .map(|d| field_spot::<SystemBench>(d.field_deg, d.spots.iter().map(|sp| (sp.line, &sp.rays[..]))))
            .collect();
        let plane = plane_words(rounded(spots[0].image_plane_from_last_vertex), "the last vertex");
        (
            format!("Spot diagram: {} surfaces; image plane {plane}", sys.len()),
            fields,
        )
    };
    spot_outputs(a, &spots, chart, |spot| {
        println!(
            "spot diagram: hexapolar, {} rings over the entrance pupil (radius {} at {} from the first vertex); image plane {}; field {}°",
            spot.rings,
            spot.pupil.radius,
            spot.pupil.z,
            plane_words(spot.image_plane_from_last_vertex, "the last vertex"),
            spot.field_deg
        );
        for sp in &spot.spots {
            let rays = (sp.ray_count, sp.rays.len());
            let stats = (sp.centroid, sp.rms_radius);
            println!("{}", spot_row(sp.line, sp.wavelength_um, None, rays, stats));
        }
    })
}

pub fn distortion(a: &DistortionArgs, sys: Box<LensSystem>) -> Result<()> {
    let bench = SystemBench::new(*sys, a.object_distance, 0.0).map_err(refuse)?;
    let dist = system_distortion(&bench, a.max_field_deg, a.steps).map_err(refuse)?;
    if let Some(path) = &a.output {
        let pts: Vec<(f64, f64)> = (dist.points.iter())
            .filter_map(|p| Some((p.field_deg, p.distortion_percent?)))
            .collect();
        let plane = plane_words(rounded(dist.image_plane_from_last_vertex), "the last vertex");
        let title = format!("Distortion: {} surfaces; image {plane}", dist.surfaces);
        super::lens_charts::distortion_chart(path, &title, &pts)?;
    }
    if a.json {
        return print_json(&dist);
    }
    print!("{dist}");
    Ok(())
}
