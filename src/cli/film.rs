//! `lensview film`: a recorded flight ([`lensview::flight`]) rendered
//! frame by frame into numbered images, then encoded with `ffmpeg` where
//! it is installed. Frames are written atomically and a frame already on
//! disk is kept, so a film stopped half way resumes where it stopped, and
//! ranges of frames (`--frames A..B`) can be rendered apart, on several
//! machines (tools/ray_film.py), into one folder.

use super::load_scene;
use super::render::Still;
use anyhow::{Context, Result, bail};
use clap::Args;
use lensview::flight::Flight;
use lensview::render::ImageFormat;
use lensview::scene::{Scene, SceneFile};
use lensview::{files, limits, output};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

#[derive(Args, Debug)]
pub struct FilmArgs {
    /// Scene file (TOML): the scene before the flight's first edit.
    pub scene: PathBuf,
    /// Flight file (TOML) recorded by the viewer (F8).
    pub flight: PathBuf,
    /// Folder for the frames (`frame-000000.png` …) and the film.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Frames a second.
    #[arg(long, default_value_t = 30.0)]
    pub fps: f64,
    #[arg(long, default_value_t = 1280)]
    pub width: u32,
    #[arg(long, default_value_t = 720)]
    pub height: u32,
    /// Samples per pixel, 1..=65536 (default: the scene's `render.spp`).
    #[arg(long)]
    pub spp: Option<u32>,
    /// Only frames A to B−1 (`A..B`, numbered from 0), for splitting a film.
    #[arg(long)]
    pub frames: Option<String>,
    /// Frame files: png (8-bit sRGB) or exr (linear, unclamped).
    #[arg(long, default_value = "png")]
    pub format: String,
    /// Seed of the sample pattern (every frame uses the same one, as a
    /// still does, so a frame is the same image whatever machine made it).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Encode the frames into `film.mp4` (or `film.webm`) with ffmpeg when
    /// the whole film is on disk: mp4, webm or none.
    #[arg(long, default_value = "mp4")]
    pub encode: String,
    /// Only the part of the flight from A to B seconds (`A..B`).
    #[arg(long, value_name = "A..B")]
    pub trim: Option<String>,
    /// Play the flight this many times as fast (0.5: at half speed).
    #[arg(long, default_value_t = 1.0)]
    pub speed: f64,
    /// Render nothing: print, as JSON, the film's frame count and the
    /// frames of the range still missing in the folder (what
    /// tools/ray_film.py splits into tasks).
    #[arg(long)]
    pub plan: bool,
}

/// `A..B` as two numbers.
fn span<T: std::str::FromStr>(text: &str) -> Option<(T, T)> {
    let (lo, hi) = text.split_once("..")?;
    Some((lo.trim().parse().ok()?, hi.trim().parse().ok()?))
}

/// The film's frames: how many, and the range asked for.
fn frame_range(a: &FilmArgs, duration: f64) -> Result<(u64, std::ops::Range<u64>)> {
    if !(a.fps.is_finite() && a.fps > 0.0 && a.fps <= 1000.0) {
        bail!("--fps {}: must be in (0, 1000]", a.fps);
    }
    let total = (duration * a.fps + 1e-9).floor() as u64 + 1;
    if total > limits::MAX_FILM_FRAMES {
        bail!(
            "the flight is {total} frames at {} fps; the limit is {}",
            a.fps,
            limits::MAX_FILM_FRAMES
        );
    }
    let range = match &a.frames {
        None => 0..total,
        Some(r) => {
            let (lo, hi) =
                span::<u64>(r).with_context(|| format!("--frames {r}: expected A..B, frame numbers from 0"))?;
            if lo >= hi || hi > total {
                bail!("--frames {r}: the film has frames 0..{total}; A..B must lie within, A < B");
            }
            lo..hi
        }
    };
    Ok((total, range))
}

pub fn film(a: FilmArgs) -> Result<()> {
    limits::check_image("--width × --height", a.width, a.height, limits::IMAGE_BYTES_PER_PIXEL)?;
    if let Some(spp) = a.spp {
        limits::check_spp("--spp", spp)?;
    }
    let format = match a.format.as_str() {
        "png" => ImageFormat::Png,
        "exr" => ImageFormat::Exr,
        f => bail!("--format {f}: png or exr"),
    };
    if !matches!(a.encode.as_str(), "mp4" | "webm" | "none") {
        bail!("--encode {}: mp4, webm or none", a.encode);
    }
    files::check_distinct(
        &[("the scene", a.scene.as_path()), ("the flight", a.flight.as_path())],
        &[("-o", a.output.as_path())],
    )?;
    let (base, built) = load_scene(Some(&a.scene))?;
    let flight = retimed(read_flight(&a.flight)?, a.trim.as_deref(), a.speed)?;
    let (total, range) = frame_range(&a, flight.duration())?;
    let ext = if format == ImageFormat::Png { "png" } else { "exr" };
    let path_of = |i: u64| a.output.join(format!("frame-{i:06}.{ext}"));
    if a.plan {
        let missing: Vec<u64> = range.filter(|&i| !path_of(i).is_file()).collect();
        println!("{}", serde_json::json!({ "frames": total, "missing": missing }));
        return Ok(());
    }
    let spp = a.spp.unwrap_or(built.spp);
    prepare_folder(&a.output)?;
    check_settings(&a, spp)?;
    let todo: Vec<u64> = range.clone().filter(|&i| !path_of(i).is_file()).collect();
    let start = Instant::now();
    shoot(&a, (&base, &flight), &todo, spp, (format, &path_of))?;
    let secs = start.elapsed().as_secs_f64();
    println!(
        "filmed frames {}..{} of {total} ({} rendered, {} already there) at {}×{}, {spp} spp in {secs:.1} s → {}",
        range.start,
        range.end,
        todo.len(),
        (range.end - range.start) as usize - todo.len(),
        a.width,
        a.height,
        a.output.display()
    );
    if a.encode != "none" && range == (0..total) {
        encode(&a, ext)?;
    }
    Ok(())
}

/// Renders and writes the frames `todo`, with a progress bar on a
/// terminal and a line a frame otherwise.
fn shoot(
    a: &FilmArgs,
    (base, flight): (&SceneFile, &Flight),
    todo: &[u64],
    spp: u32,
    (format, path_of): (ImageFormat, &dyn Fn(u64) -> PathBuf),
) -> Result<()> {
    let start = Instant::now();
    let progress = super::progress::Progress::on_stderr("filming");
    let quiet_bar = !std::io::stderr().is_terminal();
    let mut scenes = SceneCache::default();
    for (done, &i) in todo.iter().enumerate() {
        let t = i as f64 / a.fps;
        let scene = scenes.frame_scene(base, flight, t)?;
        let img = Still::plan(&scene, (a.width, a.height), spp, a.seed, "a frame")?.render(&scene);
        img.write_as(&path_of(i), format, scene.tone)?;
        let f = (done + 1) as f64 / todo.len() as f64;
        if let Some(cb) = progress.callback() {
            cb(f);
        }
        if quiet_bar {
            let spent = start.elapsed().as_secs_f64();
            eprintln!(
                "frame {i} ({}/{}) at t = {t:.3} s; {spent:.1} s so far, ETA {:.1} s",
                done + 1,
                todo.len(),
                spent / f - spent
            );
        }
    }
    progress.finish();
    Ok(())
}

/// The flight trimmed (`--trim`) and retimed (`--speed`).
pub fn retimed(flight: Flight, trim: Option<&str>, speed: f64) -> Result<Flight> {
    if trim.is_none() && speed == 1.0 {
        return Ok(flight);
    }
    let d = flight.duration();
    let (from, to) = match trim {
        None => (0.0, d),
        Some(r) => span::<f64>(r).with_context(|| format!("--trim {r}: expected A..B, seconds of the flight"))?,
    };
    flight.retimed(from, to, speed).with_context(|| {
        format!("--trim {from}..{to} --speed {speed}: the flight is 0..{d} s; A < B within it and a speed > 0")
    })
}

pub fn read_flight(path: &Path) -> Result<Flight> {
    let bytes = lensview::scene::read_capped(path, limits::SCENE_FILE_CAP)?;
    let text = String::from_utf8(bytes).map_err(|_| anyhow::anyhow!("{}: not UTF-8 text", path.display()))?;
    Ok(Flight::parse(&path.display().to_string(), &text)?)
}

/// The output folder: made if missing; anything else there is refused.
fn prepare_folder(dir: &Path) -> Result<()> {
    match std::fs::symlink_metadata(dir) {
        Ok(m) if m.is_dir() => Ok(()),
        Ok(_) => bail!("-o {}: exists and is not a folder", dir.display()),
        Err(_) => {
            output::create_dirs(dir)
                .with_context(|| format!("-o {}: cannot make the folder", dir.display()))?
                .keep();
            Ok(())
        }
    }
}

/// The film a folder holds: its inputs (by a hash of their bytes) and
/// settings, in `film-settings.txt`. A folder of another film's frames is
/// refused, so a resumed film is never a mix of two.
fn check_settings(a: &FilmArgs, spp: u32) -> Result<()> {
    let hash = |p: &Path| -> Result<u64> {
        let bytes = std::fs::read(p).with_context(|| format!("cannot read {}", p.display()))?;
        Ok(bytes.iter().fold(0x9e37_79b9_7f4a_7c15, |h: u64, &b| {
            lensview::sampling::mix64(h ^ u64::from(b))
        }))
    };
    let settings = format!(
        "lensview film: scene {:016x}, flight {:016x}, {}x{}, {spp} spp, {} fps, seed {}, {}, trim {}, speed {}\n",
        hash(&a.scene)?,
        hash(&a.flight)?,
        a.width,
        a.height,
        a.fps,
        a.seed,
        a.format,
        a.trim.as_deref().unwrap_or("all"),
        a.speed
    );
    let path = a.output.join("film-settings.txt");
    match std::fs::read_to_string(&path) {
        Ok(old) if old == settings => Ok(()),
        Ok(old) => bail!(
            "-o {}: it holds frames of another film ({}), not of this one ({}); use another folder or empty it",
            a.output.display(),
            old.trim().trim_start_matches("lensview film: "),
            settings.trim().trim_start_matches("lensview film: ")
        ),
        Err(_) => Ok(output::write_file(&path, settings.as_bytes())?),
    }
}

/// The scenes of the flight's edits, each read once.
#[derive(Default)]
struct SceneCache {
    edits: std::collections::HashMap<usize, SceneFile>,
}

impl SceneCache {
    /// The scene at time `t` with the flight's camera.
    fn frame_scene(&mut self, base: &SceneFile, flight: &Flight, t: f64) -> Result<Scene> {
        let mut sf = match flight.edit_at(t) {
            None => base.clone(),
            Some((i, text)) => match self.edits.get(&i) {
                Some(sf) => sf.clone(),
                None => {
                    let (sf, _) = Scene::parse(&format!("edit {i} of the flight"), text)?;
                    self.edits.insert(i, sf.clone());
                    sf
                }
            },
        };
        let pose = flight.pose_at(t);
        sf.camera.position = pose.position.to_array();
        sf.camera.rotation = Some(pose.rotation_deg.to_array());
        sf.camera.look_at = None;
        if let Some(fov) = pose.fov {
            sf.camera.fov = fov;
        }
        Scene::build(&sf).map_err(|p| anyhow::anyhow!("the scene at t = {t:.3} s: {}: {}", p[0].path, p[0].message))
    }
}

/// Encodes the frames with ffmpeg into `film.mp4` / `film.webm` (written
/// under a temporary name, then renamed), or says how when it is missing.
fn encode(a: &FilmArgs, ext: &str) -> Result<()> {
    let out = a.output.join(format!("film.{}", a.encode));
    let part = a.output.join(format!("film.part.{}", a.encode));
    let codec: &[&str] = match a.encode.as_str() {
        "webm" => &["-c:v", "libvpx-vp9", "-b:v", "0", "-crf", "30"],
        // 4:2:0 needs even sides: an odd one gets a black line.
        _ => &[
            "-vf",
            "pad=ceil(iw/2)*2:ceil(ih/2)*2",
            "-c:v",
            "libx264",
            "-pix_fmt",
            "yuv420p",
            "-crf",
            "18",
        ],
    };
    let input = a.output.join(format!("frame-%06d.{ext}"));
    let mut args: Vec<String> = ["-y", "-loglevel", "error", "-framerate"].map(String::from).to_vec();
    args.push(format!("{}", a.fps));
    args.extend(["-i".into(), input.display().to_string()]);
    args.extend(codec.iter().map(|s| s.to_string()));
    args.push(part.display().to_string());
    let shown = format!("ffmpeg {}", args.join(" ")).replace(&part.display().to_string(), &out.display().to_string());
    match Command::new("ffmpeg").args(&args).status() {
        Err(_) => {
            eprintln!(
                "ffmpeg is not installed: the frames are in {}; to encode them: {shown}",
                a.output.display()
            );
            Ok(())
        }
        Ok(s) if s.success() => {
            std::fs::rename(&part, &out).with_context(|| format!("cannot rename {}", part.display()))?;
            println!("encoded {} ({shown})", out.display());
            Ok(())
        }
        Ok(s) => {
            let _ = std::fs::remove_file(&part);
            bail!("ffmpeg failed ({s}): {shown}")
        }
    }
}
