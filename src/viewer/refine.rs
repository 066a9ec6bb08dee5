//! The link to the render thread: every change to what is drawn starts a
//! new generation of refinement; the newest frame of the current one is
//! kept for drawing. Pausing cancels the running job
//! (`Worker::cancel`); while paused an edit is still shown, refined to one
//! sample per pixel. A screenshot takes the render thread's picture and
//! writes it on a thread of its own.

use lensview::color::Tone;
use lensview::render::ImageFormat;
use lensview::render::worker::{Frame, Job, Snapshot, Worker};
use lensview::scene::Change;
use lensview::scene::Scene;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// A stage the render thread finished: its generation, level and time.
#[derive(Clone, Debug, PartialEq)]
pub struct StageTime {
    pub generation: u64,
    pub level: String,
    pub render_ms: f64,
}

/// The longest the render thread waits for the first frame of a
/// generation to be shown (a present on lavapipe at 1280×720 takes 12–45 ms,
/// and waits up to a display refresh for its turn).
pub const HOLD_LIMIT: Duration = Duration::from_millis(60);

/// Stages kept for the frame log while nothing is presented (a hidden
/// window): the oldest go first.
pub const MAX_STAGES: usize = 256;

pub struct Refine {
    worker: Worker,
    generation: u64,
    /// When the input behind the current generation happened.
    input_time: Instant,
    /// Newest frame of the current generation.
    frame: Option<Frame>,
    /// Every stage received since the frame log last took them
    /// ([`Self::take_stages`]), presented or not: at most [`MAX_STAGES`].
    stages: Vec<StageTime>,
    paused: bool,
    max_spp: u32,
    screenshots: u32,
    /// What the edits since the last job changed ([`Self::changed`]).
    unsent: Change,
}

impl Refine {
    pub fn new(worker: Worker, max_spp: u32) -> Self {
        Refine {
            worker,
            generation: 0,
            input_time: Instant::now(),
            frame: None,
            stages: Vec::new(),
            paused: false,
            max_spp,
            screenshots: 0,
            unsent: Change::Picture,
        }
    }

    /// Notes what an accepted edit changed, for the next job: the render
    /// thread keeps the picture or the photons by it, never by comparing
    /// scenes.
    pub fn changed(&mut self, c: Change) {
        self.unsent = self.unsent.max(c);
    }

    /// Starts a new generation: `scene` at `width`×`height`, for a window
    /// whose presents take `present_s`.
    pub fn submit(&mut self, scene: Arc<Scene>, (width, height): (u32, u32), present_s: f64) {
        self.generation += 1;
        self.input_time = Instant::now();
        self.worker.submit(Job {
            generation: self.generation,
            change: std::mem::replace(&mut self.unsent, Change::None),
            scene,
            width,
            height,
            // Paused: an edit still shows, refined to one sample per pixel.
            max_spp: if self.paused { 1 } else { self.max_spp },
            seed: 0,
            input_time: self.input_time,
            present_s,
        });
    }

    /// Pauses (stops the render thread; the picture stays) or resumes
    /// (the caller submits again). Returns whether it is paused now.
    pub fn toggle_pause(&mut self) -> bool {
        self.paused = !self.paused;
        if self.paused {
            self.worker.cancel();
        }
        self.paused
    }

    pub fn paused(&self) -> bool {
        self.paused
    }

    pub fn max_spp(&self) -> u32 {
        self.max_spp
    }

    /// Sets the sample cap (clamped to 1..=65536); true when it changed
    /// (the caller submits again).
    pub fn set_max_spp(&mut self, spp: u32) -> bool {
        let spp = spp.clamp(1, 65536);
        let changed = spp != self.max_spp;
        self.max_spp = spp;
        changed
    }

    /// Has the render thread wait, after the first frame of each
    /// generation, until [`Self::shown`] reports it on screen (at most
    /// [`HOLD_LIMIT`]): for a CPU rasterizer, whose presents take the
    /// tracer's cores.
    pub fn hold_first_frames(&self) {
        self.worker.hold_first_frames(HOLD_LIMIT);
    }

    /// Tells the render thread that the newest frame is on screen.
    pub fn shown(&self) {
        if let Some(f) = &self.frame {
            self.worker.shown(f.generation);
        }
    }

    /// Takes the frames the render thread sent; true when a newer frame of
    /// the current generation arrived (draw it).
    pub fn receive(&mut self) -> bool {
        let mut frames = self.worker.frames();
        self.stages.extend(frames.iter().map(|f| StageTime {
            generation: f.generation,
            level: f.stage.label(),
            render_ms: f.render_ms,
        }));
        let over = self.stages.len().saturating_sub(MAX_STAGES);
        self.stages.drain(..over);
        let newest = frames.pop();
        // The buffers of frames replaced go back to the render thread.
        for f in frames {
            self.worker.recycle(f.rgba);
        }
        match newest {
            Some(f) => {
                if let Some(old) = self.frame.replace(f) {
                    self.worker.recycle(old.rgba);
                }
                true
            }
            None => false,
        }
    }

    /// The stages received since the last call, oldest first (the frame
    /// log's `stages`: the render thread's work, whether presented or not).
    pub fn take_stages(&mut self) -> Vec<StageTime> {
        std::mem::take(&mut self.stages)
    }

    /// Whether a frame of the newest generation has arrived.
    pub fn answered(&self) -> bool {
        self.frame.as_ref().is_some_and(|f| f.generation == self.generation)
    }

    pub fn frame(&self) -> Option<&Frame> {
        self.frame.as_ref()
    }

    /// Forgets the picture (a new size or a new document).
    pub fn clear_frame(&mut self) {
        self.frame = None;
    }

    pub fn input_time(&self) -> Instant {
        self.input_time
    }

    /// Saves the picture on screen, as refined so far (caustics and all),
    /// into `dir` (made if missing): a PNG as shown and an EXR of the same
    /// picture in linear light, `lensview-SECONDS-N.png|exr`. The render
    /// thread hands the picture over between stages and a thread of its
    /// own writes it, so the window stays live; `notify` gets the line
    /// that says where the files went (or why not). Returns the line for
    /// the message bar meanwhile.
    pub fn screenshot(&mut self, dir: PathBuf, tone: Tone, notify: impl Fn(String) + Send + 'static) -> String {
        self.screenshots += 1;
        let stem = format!(
            "lensview-{}-{}",
            std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_secs()),
            self.screenshots
        );
        let picture = self.worker.snapshot();
        let saving = format!("saving the picture on screen into {}…", dir.display());
        std::thread::spawn(move || {
            let line = match picture.recv_timeout(SNAPSHOT_WAIT) {
                Ok(Some(snap)) => match save_snapshot(&snap, &dir, &stem, tone) {
                    Ok(png) => format!(
                        "saved {} and .exr ({}×{}, {} spp)",
                        png.display(),
                        snap.image.width,
                        snap.image.height,
                        snap.spp
                    ),
                    Err(e) => format!("screenshot not saved: {e}"),
                },
                Ok(None) => "screenshot not saved: no picture yet".into(),
                Err(_) => "screenshot not saved: the render thread did not answer".into(),
            };
            eprintln!("{line}");
            notify(line);
        });
        saving
    }
}

/// How long a screenshot waits for the render thread to hand over its
/// picture (it answers between stages: a stage at 64 spp of a large
/// window can take seconds).
const SNAPSHOT_WAIT: Duration = Duration::from_secs(120);

/// Writes `snap` as `dir/stem.png` (after `tone`, as shown) and
/// `dir/stem.exr` (linear); the PNG's path.
fn save_snapshot(snap: &Snapshot, dir: &Path, stem: &str, tone: Tone) -> Result<PathBuf, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let png = dir.join(format!("{stem}.png"));
    let full = std::path::absolute(&png).unwrap_or(png);
    snap.image
        .write_as(&full, ImageFormat::Png, tone)
        .map_err(|e| e.to_string())?;
    let exr = full.with_extension("exr");
    snap.image
        .write_as(&exr, ImageFormat::Exr, tone)
        .map_err(|e| e.to_string())?;
    Ok(full)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Waits up to 30 s for `refine` to receive a frame that passes `pred`.
    fn wait(refine: &mut Refine, pred: impl Fn(&Frame) -> bool) -> bool {
        let end = Instant::now() + Duration::from_secs(30);
        while Instant::now() < end {
            if refine.receive() && refine.frame().is_some_and(&pred) {
                return true;
            }
            std::thread::sleep(Duration::from_millis(2));
        }
        false
    }

    #[test]
    fn paused_the_picture_stays_and_an_edit_refines_to_one_sample() {
        let scene = Arc::new(Scene::default_scene().1);
        let mut r = Refine::new(Worker::spawn(|| {}), 1 << 16);
        r.submit(scene.clone(), (48, 32), 0.0);
        assert!(wait(&mut r, |f| f.generation == 1));
        assert!(r.toggle_pause());
        let kept = r.frame().map(|f| (f.generation, f.spp));
        std::thread::sleep(Duration::from_millis(300));
        assert!(!r.receive(), "a frame arrived while paused");
        assert_eq!(r.frame().map(|f| (f.generation, f.spp)), kept);
        // An edit while paused: shown, but only to one sample per pixel.
        r.submit(scene.clone(), (48, 32), 0.0);
        assert!(wait(&mut r, |f| f.generation == 2 && f.last));
        assert_eq!(r.frame().map(|f| f.spp), Some(1));
        // Resumed: refinement goes on to the cap.
        assert!(!r.toggle_pause());
        assert!(r.set_max_spp(4) && !r.set_max_spp(4));
        r.submit(scene, (48, 32), 0.0);
        assert!(wait(&mut r, |f| f.generation == 3 && f.last));
        assert_eq!(r.frame().map(|f| f.spp), Some(4));
        r.clear_frame();
        assert!(r.frame().is_none());
    }

    /// Every stage the render thread sends reaches the stage record once,
    /// in order, also those never drawn because a newer one came with them.
    #[test]
    fn every_stage_is_recorded_once_whether_drawn_or_not() {
        let scene = Arc::new(Scene::default_scene().1);
        let mut r = Refine::new(Worker::spawn(|| {}), 4);
        r.take_stages();
        r.submit(scene, (48, 32), 0.0);
        let g = r.generation;
        // Let every stage arrive before taking them: most are never drawn.
        let end = Instant::now() + Duration::from_secs(30);
        let mut seen = Vec::new();
        while Instant::now() < end && !seen.iter().any(|s: &StageTime| s.level == "4 spp") {
            std::thread::sleep(Duration::from_millis(200));
            r.receive();
            seen.extend(r.take_stages());
        }
        let levels: Vec<&str> = seen.iter().map(|s| s.level.as_str()).collect();
        assert!(seen.iter().all(|s| s.generation == g && s.render_ms >= 0.0), "{seen:?}");
        assert_eq!(levels.iter().filter(|l| **l == "1 spp").count(), 1, "{levels:?}");
        let pos = |l: &str| levels.iter().position(|x| *x == l);
        assert!(pos("1 spp") < pos("2 spp") && pos("2 spp") < pos("4 spp"), "{levels:?}");
        assert!(r.take_stages().is_empty());
    }
}
