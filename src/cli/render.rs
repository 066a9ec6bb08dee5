//! `lensview render`: one image, headless, to a PNG or OpenEXR file.

use super::load_scene;
use anyhow::Result;
use clap::Args;
use lensview::color::{Tone, ToneCurve};
use lensview::integrator::Lit;
use lensview::photon::PhotonMap;
use lensview::render::caustics::{CausticSettings, render_photons, still_map};
use lensview::render::{Image, ImageFormat, RenderSettings, render};
use lensview::scene::Scene;
use lensview::{files, limits, output};
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// Scene file (TOML); the embedded default scene when omitted.
    pub scene: Option<PathBuf>,
    /// Output file: .png (8-bit sRGB) or .exr (linear RGB, 32-bit float, unclamped).
    #[arg(short, long, default_value = "lensview.png")]
    pub output: PathBuf,
    /// Image width in pixels.
    #[arg(long, default_value_t = 800)]
    pub width: u32,
    /// Image height in pixels.
    #[arg(long, default_value_t = 600)]
    pub height: u32,
    /// Samples per pixel, 1..=65536 (default: the scene's `render.spp`).
    #[arg(long)]
    pub spp: Option<u32>,
    /// Seed of the sample pattern.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Exposure of the PNG in stops (default: the scene's `[display] exposure`, 0).
    #[arg(long, allow_negative_numbers = true, value_name = "STOPS")]
    pub exposure: Option<f64>,
    /// Tone curve of the PNG: clamp, reinhard or aces (default: the scene's `[display] tone`, clamp).
    #[arg(long, value_name = "CURVE", value_parser = tone_curve)]
    pub tone: Option<ToneCurve>,
}

fn tone_curve(s: &str) -> Result<ToneCurve, String> {
    ToneCurve::parse(s).ok_or_else(|| format!("unknown tone curve '{s}' (use clamp, reinhard or aces)"))
}

/// The PNG's tone: the scene's, with the flags given over it; a refusal for
/// an EXR (linear radiance, never toned) or an exposure out of range.
fn tone_of(a: &RenderArgs, format: ImageFormat, scene: Tone) -> Result<Tone> {
    if format == ImageFormat::Exr && (a.exposure.is_some() || a.tone.is_some()) {
        anyhow::bail!("--exposure and --tone apply to PNG output; an EXR is linear radiance, never toned");
    }
    let exposure = a.exposure.unwrap_or(scene.exposure);
    if !Tone::accepts(exposure) {
        anyhow::bail!("--exposure {exposure}: not in -{m}..={m} stops", m = Tone::MAX_STOPS);
    }
    Ok(Tone {
        exposure,
        curve: a.tone.unwrap_or(scene.curve),
    })
}

pub fn render_cmd(a: RenderArgs) -> Result<()> {
    limits::check_image("--width × --height", a.width, a.height, limits::IMAGE_BYTES_PER_PIXEL)?;
    if let Some(spp) = a.spp {
        limits::check_spp("--spp", spp)?;
    }
    // The scene itself, a directory, device or FIFO at -o, or an unknown
    // extension, is refused before rendering.
    let scene_input = a.scene.as_deref().map(|p| ("the scene", p));
    files::check_distinct(scene_input.as_slice(), &[("-o", a.output.as_path())])?;
    output::check_target(&a.output)?;
    let format = ImageFormat::of(&a.output).map_err(anyhow::Error::msg)?;
    let (_, scene) = load_scene(a.scene.as_deref())?;
    let tone = tone_of(&a, format, scene.tone)?;
    if let Some(lens) = &scene.lens {
        println!("{}", lens_summary(lens, a.width, a.height));
    }
    let spp = a.spp.unwrap_or(scene.spp);
    let still = Still::plan(&scene, (a.width, a.height), spp, a.seed, "the render")?;
    let progress = super::progress::Progress::on_stderr("rendering");
    let callback = progress.callback();
    let start = Instant::now();
    let caustics = still.caustics(&scene);
    let photon_secs = start.elapsed().as_secs_f64();
    let img = render(
        still.lit(&scene, caustics.as_ref()),
        &still.settings,
        callback.as_ref().map(|c| c as &(dyn Fn(f64) + Sync)),
    );
    let secs = start.elapsed().as_secs_f64();
    progress.finish();
    img.write_as(&a.output, format, tone)?;
    let samples = a.width as f64 * a.height as f64 * spp as f64;
    let photons = match &caustics {
        Some((m, thin)) => format!(
            ", caustics: {} photon passes in {photon_secs:.3} s, {} photons{}",
            m.passes(),
            m.photons(),
            if *thin > 1 {
                format!(", gathered by 1 sample in {thin}")
            } else {
                String::new()
            }
        ),
        None => String::new(),
    };
    println!(
        "rendered {}×{} at {} spp in {:.3} s ({:.2} M camera samples/s, {} threads{photons}) → {}",
        a.width,
        a.height,
        spp,
        secs,
        samples / secs / 1e6,
        rayon::current_num_threads(),
        a.output.display()
    );
    Ok(())
}

/// A still as `render` makes it (and `film` makes each frame): the camera
/// samples, the lights they shade and the caustics' photons in one work
/// budget, all from one seed.
pub struct Still {
    pub settings: RenderSettings,
    photons: CausticSettings,
}

impl Still {
    /// The still of `scene` at `size` and `spp` from `seed`, its work
    /// checked against the limit (`what` names it in the refusal).
    pub fn plan(scene: &Scene, (width, height): (u32, u32), spp: u32, seed: u64, what: &str) -> Result<Still> {
        let photons = CausticSettings {
            seed,
            ..CausticSettings::default()
        };
        // (`still_map` traces more photons where its gathers are thinned
        // only if that work fits as well.)
        let (_, n) = render_photons(scene, (width, height), spp, photons);
        let work = limits::Work::samples(width, height, spp as u64, 1)
            .with_lights(scene.lights.len())
            .with_photons(n);
        limits::check_total(what, work)?;
        let settings = RenderSettings {
            width,
            height,
            spp,
            seed,
        };
        Ok(Still { settings, photons })
    }

    /// The caustics' photon map and the thinning of its gathers (`None`:
    /// the scene has none).
    pub fn caustics(&self, scene: &Scene) -> Option<(PhotonMap, u32)> {
        let s = &self.settings;
        still_map(scene, (s.width, s.height), s.spp, self.photons)
    }

    /// The image, with no progress report.
    pub fn render(&self, scene: &Scene) -> Image {
        let caustics = self.caustics(scene);
        render(self.lit(scene, caustics.as_ref()), &self.settings, None)
    }

    /// What the still shades `scene` with: its caustics, thinned.
    fn lit<'a>(&self, scene: &'a Scene, caustics: Option<&'a (PhotonMap, u32)>) -> Lit<'a> {
        let thin = caustics.map_or(1, |c| c.1);
        Lit::new(scene, caustics.map(|c| &c.0)).thinned(thin)
    }
}

/// One line on a lens camera: its f-number, focus, field of view, and the
/// share of camera rays that pass it for this picture.
fn lens_summary(lens: &lensview::camera::LensCamera, width: u32, height: u32) -> String {
    let focus = if lens.focus_distance.is_finite() {
        format!("{:.6}", lens.focus_distance)
    } else {
        "infinity".into()
    };
    format!(
        "lens camera: f/{:.3}, efl {:.6}, in focus at {focus} (sensor {:.6} behind the rear vertex), {:.2}° high; {:.1} % of camera rays pass the lens",
        lens.f_number,
        lens.paraxial.efl,
        lens.sensor_distance,
        lens.fov_y_deg(),
        100.0 * lens.pass_share(width, height)
    )
}
