//! `lensview view` (and `lensview` alone): checks the flags and opens the
//! window (the binary's `viewer` module).

use super::load_scene;
use anyhow::{Result, bail};
use clap::Args;
use lensview::limits;
use std::path::PathBuf;

#[derive(Args, Debug, Default)]
pub struct ViewArgs {
    /// Scene file (TOML); the embedded default scene when omitted.
    pub scene: Option<PathBuf>,
    /// Append one JSON line per presented frame to this file.
    #[arg(long)]
    pub frame_log: Option<PathBuf>,
    /// Close the window cleanly after this many seconds.
    #[arg(long)]
    pub exit_after: Option<f64>,
    /// Samples per pixel to refine to.
    #[arg(long, default_value_t = 64)]
    pub max_spp: u32,
    /// Initial window width.
    #[arg(long, default_value_t = 1280)]
    pub width: u32,
    /// Initial window height.
    #[arg(long, default_value_t = 720)]
    pub height: u32,
    /// Start with the editing panel hidden (F4 shows it).
    #[arg(long)]
    pub no_panel: bool,
    /// Write the screen rectangles of the panel's buttons to this file (JSON), for scripted tests.
    #[arg(long, hide = true)]
    pub ui_log: Option<PathBuf>,
    /// Folder for screenshots (P: the picture on screen as PNG and linear EXR); made when needed.
    #[arg(long, value_name = "DIR", default_value = "lensview-screenshots")]
    pub screenshots: PathBuf,
    /// Play a recorded flight (F8 records one) from the start.
    #[arg(long, value_name = "FLIGHT")]
    pub play: Option<PathBuf>,
    /// With --play: only seconds A to B of the flight (`A..B`).
    #[arg(long, value_name = "A..B", requires = "play")]
    pub play_trim: Option<String>,
    /// With --play: this many times as fast.
    #[arg(long, value_name = "S", default_value_t = 1.0, requires = "play")]
    pub play_speed: f64,
}

pub fn view(a: ViewArgs) -> Result<()> {
    // The logs are written to, the scene only read (saving it is the
    // editor's business): a log must not be the scene, nor the other log.
    let scene_input = a.scene.as_deref().map(|p| ("the scene", p));
    let logs: Vec<(&str, &std::path::Path)> = [("--frame-log", &a.frame_log), ("--ui-log", &a.ui_log)]
        .into_iter()
        .filter_map(|(flag, p)| p.as_deref().map(|p| (flag, p)))
        .collect();
    lensview::files::check_distinct(scene_input.as_slice(), &logs)?;
    let (scene_file, _) = load_scene(a.scene.as_deref())?;
    let play = match a.play.as_deref() {
        Some(p) => Some(super::film::retimed(
            super::film::read_flight(p)?,
            a.play_trim.as_deref(),
            a.play_speed,
        )?),
        None => None,
    };
    // The window's own buffers: the progressive planes and the RGBA frame.
    limits::check_image(
        "window --width × --height",
        a.width,
        a.height,
        limits::PROGRESSIVE_BYTES_PER_PIXEL + 4,
    )?;
    limits::check_spp("--max-spp", a.max_spp)?;
    if let Some(t) = a.exit_after
        && !(t >= 0.0 && t.is_finite())
    {
        bail!("--exit-after must be a number of seconds ≥ 0, got {t}");
    }
    crate::viewer::run(crate::viewer::ViewOptions {
        scene_path: a.scene,
        scene_file,
        frame_log: a.frame_log,
        exit_after: a.exit_after,
        max_spp: a.max_spp,
        width: a.width,
        height: a.height,
        panel: !a.no_panel,
        ui_log: a.ui_log,
        screenshots: a.screenshots,
        play,
    })
}
