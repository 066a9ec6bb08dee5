//! The render thread: takes jobs (scene, size, generation), refines them
//! through the progressive schedule and sends a frame after every stage over
//! a `crossbeam-channel`, then calls a wake-up function so an event loop can
//! draw it. A newer job cancels the current one between row bands, and
//! [`Worker::cancel`] stops it without starting another (the viewer's
//! pause). [`Worker::frames`] hands out only frames of the job that
//! is still wanted. Where presenting takes the tracer's cores, the thread
//! can hold after the first frame of each job until the window reports it
//! on screen ([`Worker::hold_first_frames`]).

use super::caustics::{CausticStats, Interleaved, stage_work};
use super::first_frame::{Costs, First};
use super::progressive::{Progressive, ReprojectTimes, Stage, schedule};
use super::reproject::same_but_camera;
use crate::scene::{Change, Scene};
use crossbeam_channel::{Receiver, Sender, unbounded};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

pub use super::first_frame::{FIRST_FRAME_BUDGET_S, hole_level};

#[derive(Clone, Debug)]
pub struct Job {
    /// Strictly increasing; every change to what is drawn bumps it.
    pub generation: u64,
    /// What changed in the scene since the job before (the largest change
    /// of the edits between; `Change::None` for a new size or sample cap),
    /// as the editor reports it: the render thread reprojects the picture or
    /// keeps the photons by it, and never compares scenes.
    pub change: Change,
    pub scene: Arc<Scene>,
    pub width: u32,
    pub height: u32,
    pub max_spp: u32,
    pub seed: u64,
    /// When the input that caused this job happened.
    pub input_time: Instant,
    /// What showing a frame costs the window (its smoothed present time;
    /// 0 headless): the first picture after a move gets what is left of
    /// a flight frame ([`super::first_frame::Costs::move_budget`]).
    pub present_s: f64,
}

/// One refined picture.
#[derive(Clone, Debug)]
pub struct Frame {
    pub generation: u64,
    pub stage: Stage,
    /// Samples per pixel (0 for a block preview).
    pub spp: u32,
    pub width: u32,
    pub height: u32,
    /// 8-bit sRGB RGBA, row-major.
    pub rgba: Vec<u8>,
    /// Time spent rendering this stage.
    pub render_ms: f64,
    /// Time from the job's input until the render thread started on it.
    pub queued_ms: f64,
    /// Time from the job's input to this frame leaving the render thread.
    pub since_input_ms: f64,
    /// Camera samples per second measured on this stage.
    pub samples_per_s: f64,
    /// True for the last stage of the schedule.
    pub last: bool,
    /// The caustics: the map so far, this stage's photon and gather times.
    pub caustics: CausticStats,
    /// The camera's position and rotation (degrees) in this picture.
    pub camera: (glam::DVec3, glam::DVec3),
    /// Where a [`Stage::Reprojected`] frame's time went.
    pub reprojection: Option<ReprojectTimes>,
}

/// The value of `Worker::wanted` that no job has: nothing is to be rendered.
const NOTHING: u64 = u64::MAX;

pub struct Worker {
    jobs: Option<Sender<Job>>,
    frames: Receiver<Frame>,
    /// The generation the render thread may work on: the newest submitted,
    /// or [`NOTHING`] after [`Worker::cancel`]. The thread polls it between
    /// row bands, so one atomic both cancels and tells frames apart.
    wanted: Arc<AtomicU64>,
    shown: Arc<Shown>,
    /// Pixel buffers of frames the window is done with, for the render
    /// thread to write the next frames into (a frame's buffer is megabytes,
    /// mapped afresh and faulted in page by page when allocated).
    spare: Sender<Vec<u8>>,
    handle: Option<JoinHandle<()>>,
}

/// Buffers kept for reuse at most: the frame being drawn, one on its way.
const SPARE_BUFFERS: usize = 2;

/// What the window has on screen, for the render thread's hold after the
/// first frame of a job: the newest generation shown, and how long to wait
/// for it (0: never).
#[derive(Default)]
struct Shown {
    generation: Mutex<u64>,
    changed: Condvar,
    hold_ms: AtomicU64,
}

impl Shown {
    /// Wakes a hold to look again (at `wanted`, or at what is shown). The
    /// lock is taken first, so a hold that is about to wait cannot miss it.
    fn wake(&self) {
        drop(self.generation.lock());
        self.changed.notify_all();
    }

    /// Records that `generation` is on screen, and wakes a hold.
    fn show(&self, generation: u64) {
        let mut g = self.generation.lock().unwrap_or_else(|e| e.into_inner());
        *g = (*g).max(generation);
        drop(g);
        self.changed.notify_all();
    }

    /// After the first frame of job `generation`: waits until the window
    /// shows it, the job is no longer wanted, or the hold's limit passed.
    fn hold(&self, generation: u64, cancelled: &dyn Fn() -> bool) {
        let ms = self.hold_ms.load(Ordering::Relaxed);
        if ms == 0 {
            return;
        }
        let shown = self.generation.lock().unwrap_or_else(|e| e.into_inner());
        let wait = |g: &mut u64| *g < generation && !cancelled();
        let _ = self.changed.wait_timeout_while(shown, Duration::from_millis(ms), wait);
    }
}

impl Worker {
    /// Starts the render thread; `wake` is called after each frame is sent.
    pub fn spawn(wake: impl Fn() + Send + 'static) -> Self {
        let (job_tx, job_rx) = unbounded::<Job>();
        let (frame_tx, frame_rx) = unbounded::<Frame>();
        let wanted = Arc::new(AtomicU64::new(NOTHING));
        let shown = Arc::new(Shown::default());
        let (spare, spare_rx) = crossbeam_channel::bounded(SPARE_BUFFERS);
        let (w, s) = (wanted.clone(), shown.clone());
        let handle = std::thread::Builder::new()
            .name("lensview-render".into())
            .spawn(move || run(job_rx, frame_tx, (w, s, spare_rx), wake))
            .ok();
        Worker {
            jobs: Some(job_tx),
            frames: frame_rx,
            wanted,
            shown,
            spare,
            handle,
        }
    }

    /// From now on, after sending the first frame of a job, the render
    /// thread waits until [`Self::shown`] reports that frame on screen (or
    /// a newer job comes, or `max` passed) before it renders the next
    /// stage. For a window whose presents take the tracer's cores (a CPU
    /// rasterizer): the frame that answers an input is presented with the
    /// whole machine, and the stages after it are traced without a present
    /// in their midst. Zero: no hold (the default).
    pub fn hold_first_frames(&self, max: Duration) {
        let ms = max.as_millis().min(u64::MAX as u128) as u64;
        self.shown.hold_ms.store(ms, Ordering::Relaxed);
        self.shown.wake();
    }

    /// Hands back the pixels of a frame no longer needed: the render thread
    /// writes a later frame into them (dropped when enough are kept).
    pub fn recycle(&self, rgba: Vec<u8>) {
        let _ = self.spare.try_send(rgba);
    }

    /// Reports that the frames of `generation` sent so far are on screen.
    pub fn shown(&self, generation: u64) {
        self.shown.show(generation);
    }

    /// Replaces whatever is being rendered by `job`. Generations must grow
    /// and stay below `u64::MAX`.
    pub fn submit(&self, job: Job) {
        debug_assert!(job.generation != NOTHING);
        self.wanted.store(job.generation, Ordering::SeqCst);
        self.shown.wake();
        if let Some(tx) = &self.jobs {
            let _ = tx.send(job);
        }
    }

    /// Stops the current job between row bands and starts none: the thread
    /// waits for the next [`Self::submit`]. Frames the job already sent are
    /// dropped by [`Self::frames`].
    pub fn cancel(&self) {
        self.wanted.store(NOTHING, Ordering::SeqCst);
        self.shown.wake();
    }

    /// Takes every frame sent so far and returns those of the job still
    /// wanted, oldest first; frames of older or cancelled jobs are dropped.
    /// Never waits.
    pub fn frames(&self) -> Vec<Frame> {
        let wanted = self.wanted.load(Ordering::SeqCst);
        self.frames.try_iter().filter(|f| f.generation == wanted).collect()
    }
}

impl Drop for Worker {
    fn drop(&mut self) {
        // Cancel the current job and close the channel: the thread ends.
        self.cancel();
        self.jobs.take();
        if let Some(h) = self.handle.take() {
            let _ = h.join();
        }
    }
}

/// How a job starts: with the reprojected picture (after this many
/// seconds), or afresh at this stage of the schedule.
enum Start {
    Moved(f64),
    At(usize),
}

/// A camera move with a picture to move: the previous picture reprojected
/// into the new view (refinement then goes on from the first
/// full-resolution sample) where [`Costs::choose`] finds that sharper
/// within the budget; otherwise a fresh start at the first stage that fits
/// the budget. `shown` is the scene whose picture `prog` holds; the holes
/// are traced in `traced` (the job's scene with its photon map).
fn start(
    prog: &mut Progressive,
    shown: &mut Held,
    job: &Job,
    traced: &Scene,
    stages: &[Stage],
    costs: &mut Costs,
) -> Start {
    let t0 = Instant::now();
    let size = (job.width, job.height);
    let moved = shown
        .scene
        .as_ref()
        .filter(|s| (prog.width, prog.height) == size && s.camera != job.scene.camera && shown.since.reprojects());
    debug_assert!(
        moved.is_none_or(|s| same_but_camera(s, &job.scene)),
        "{:?}",
        shown.since
    );
    // A move (even with no picture to move: a flight's fresh previews)
    // gets what a flight frame leaves; an edit or a new size, a tap's.
    let budget = match moved {
        Some(_) => costs.move_budget(size, job.present_s),
        None => FIRST_FRAME_BUDGET_S,
    };
    let chosen = match moved {
        Some(_) => costs.choose(stages, size, budget),
        None => First::Fresh(costs.first_stage(stages, size, budget)),
    };
    if let Some(old) = moved
        && chosen == First::Reproject
        && prog.reproject(traced, old, |holes| {
            costs.hole_level(holes, budget - t0.elapsed().as_secs_f64())
        })
    {
        costs.reprojected(&prog.reprojection, size.0 as usize * size.1 as usize);
        prog.seed = job.seed;
        shown.set(&job.scene);
        return Start::Moved(t0.elapsed().as_secs_f64());
    }
    prog.reset(job.width, job.height, job.seed);
    Start::At(match chosen {
        First::Fresh(i) => i,
        // Nothing to reproject (only block levels drawn so far).
        First::Reproject => costs.first_stage(stages, size, budget),
    })
}

/// A stage's time, the camera samples it cast, and its job's wait.
struct Timing {
    dt: f64,
    cast: u64,
    queued_ms: f64,
}

impl Frame {
    /// The frame showing `prog` after `stage` of `job`.
    /// `rgba`: a buffer to write the pixels into (a recycled one, or empty).
    fn of(
        prog: &Progressive,
        job: &Job,
        (stage, mut rgba): (Stage, Vec<u8>),
        t: Timing,
        last: bool,
        caustics: CausticStats,
    ) -> Frame {
        prog.write_rgba8(&mut rgba);
        Frame {
            generation: job.generation,
            stage,
            spp: prog.spp,
            width: job.width,
            height: job.height,
            rgba,
            render_ms: t.dt * 1e3,
            queued_ms: t.queued_ms,
            since_input_ms: job.input_time.elapsed().as_secs_f64() * 1e3,
            samples_per_s: if t.dt > 0.0 { t.cast as f64 / t.dt } else { 0.0 },
            last,
            caustics,
            camera: (job.scene.camera.position, job.scene.camera.rotation_deg),
            reprojection: (stage == Stage::Reprojected).then_some(prog.reprojection),
        }
    }
}

fn run(
    jobs: Receiver<Job>,
    frames: Sender<Frame>,
    (wanted, screen, spare): (Arc<AtomicU64>, Arc<Shown>, Receiver<Vec<u8>>),
    wake: impl Fn(),
) {
    let mut costs = Costs::default();
    // Reused across jobs of the same size: allocating and zeroing two
    // full-resolution buffers per keypress costs milliseconds.
    let mut prog = Progressive::new(0, 0, 0);
    // The photon map, kept across jobs that change only the camera.
    let mut caustics = Interleaved::default();
    // The scene whose picture `prog` holds (for reprojection).
    let mut shown = Held::default();
    // What changed since the scene `caustics` last followed.
    let mut since_followed = Change::Picture;
    while let Ok(mut job) = jobs.recv() {
        let mut change = job.change;
        while let Ok(newer) = jobs.try_recv() {
            job = newer;
            change = change.max(job.change);
        }
        shown.since = shown.since.max(change);
        since_followed = since_followed.max(change);
        if job.generation != wanted.load(Ordering::SeqCst) {
            continue;
        }
        let stages = schedule(job.max_spp.max(1));
        let queued_ms = job.input_time.elapsed().as_secs_f64() * 1e3;
        let generation = job.generation;
        let cancelled = || wanted.load(Ordering::Relaxed) != generation;
        caustics.follow(&job.scene, since_followed.keeps_photons());
        since_followed = Change::None;
        let first_sent = std::cell::Cell::new(false);
        let send = |prog: &Progressive, stage: Stage, dt: f64, cast: u64, last: bool, c: CausticStats| {
            let rgba = spare.try_recv().unwrap_or_default();
            let frame = Frame::of(prog, &job, (stage, rgba), Timing { dt, cast, queued_ms }, last, c);
            let ok = frames.send(frame).is_ok();
            wake();
            if ok && !last && !first_sent.replace(true) {
                screen.hold(generation, &cancelled);
            }
            ok
        };
        let traced = caustics.scene(&job.scene);
        let first = match start(&mut prog, &mut shown, &job, traced, &stages, &mut costs) {
            Start::Moved(dt) => {
                if !send(
                    &prog,
                    Stage::Reprojected,
                    dt,
                    prog.samples_cast,
                    false,
                    caustics.stats(),
                ) {
                    return;
                }
                stages.iter().position(|s| matches!(s, Stage::Samples(_))).unwrap_or(0)
            }
            Start::At(first) => first,
        };
        for (i, &stage) in stages.iter().enumerate().skip(first) {
            if cancelled() {
                break;
            }
            let Some((dt, cost)) = run_stage(&mut prog, &mut caustics, &job.scene, stage, &mut costs, &cancelled)
            else {
                break;
            };
            shown.set(&job.scene);
            if !send(&prog, stage, dt, cost, i + 1 == stages.len(), caustics.stats()) {
                return;
            }
        }
        // Refined (or cancelled): with nothing else to do, record the
        // picture's first hits for the next move's reprojection (which
        // otherwise records them itself, on the input's time).
        if prog.record_first_hits(&job.scene, &cancelled)
            && let Some(share) = prog.specular_share()
        {
            // What the next move's reprojection will have to trace, at least.
            costs.holes = share;
        }
    }
}

/// The scene whose picture the render thread holds, and what the jobs
/// since changed (the editor's [`Change`], never found by comparing).
struct Held {
    scene: Option<Arc<Scene>>,
    since: Change,
}

impl Default for Held {
    fn default() -> Self {
        Held {
            scene: None,
            since: Change::Picture,
        }
    }
}

impl Held {
    fn set(&mut self, scene: &Arc<Scene>) {
        self.scene = Some(scene.clone());
        self.since = Change::None;
    }
}

/// `stage` of `scene` on `prog`, a sample stage's photon passes first:
/// its time and the camera samples it cast (`None`: cancelled). The
/// samples' own time (photon passes left out) goes to `costs`.
fn run_stage(
    prog: &mut Progressive,
    caustics: &mut Interleaved,
    scene: &Arc<Scene>,
    stage: Stage,
    costs: &mut Costs,
    cancelled: &(dyn Fn() -> bool + Sync),
) -> Option<(f64, u64)> {
    let before = prog.samples_cast;
    let t0 = Instant::now();
    caustics.refine(
        stage_work(stage, (prog.width, prog.height, prog.spp), scene.lights.len()),
        cancelled,
    );
    let traced = Instant::now();
    caustics.gather_clock(false);
    if !prog.run(caustics.scene(scene), stage, cancelled) {
        return None;
    }
    caustics.gather_clock(true);
    let cost = prog.samples_cast - before;
    costs.sampled(stage, traced.elapsed().as_secs_f64(), cost);
    Some((t0.elapsed().as_secs_f64(), cost))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    fn job(generation: u64, w: u32, h: u32, spp: u32) -> Job {
        Job {
            generation,
            change: Change::Picture,
            scene: Arc::new(Scene::default_scene().1),
            width: w,
            height: h,
            max_spp: spp,
            seed: 0,
            input_time: Instant::now(),
            present_s: 0.0,
        }
    }

    #[test]
    fn a_job_refines_to_its_sample_cap_in_order() {
        let w = Worker::spawn(|| {});
        w.submit(job(1, 32, 24, 4));
        let mut spp = Vec::new();
        loop {
            let f = w.frames.recv_timeout(Duration::from_secs(30)).unwrap();
            assert_eq!(f.generation, 1);
            assert_eq!(f.rgba.len(), 32 * 24 * 4);
            spp.push(f.spp);
            if f.last {
                break;
            }
        }
        assert_eq!(*spp.last().unwrap(), 4);
        assert!(spp.windows(2).all(|p| p[0] <= p[1]), "{spp:?}");
    }

    /// A worker whose wake-up waits for the test: after sending each frame
    /// the render thread reports on `sent` and then blocks until a token
    /// arrives on `gate` (or `gate` is dropped). A job whose frame was
    /// reported is therefore provably running, between two stages.
    fn gated() -> (Worker, Receiver<()>, Sender<()>) {
        let (sent_tx, sent_rx) = unbounded();
        let (gate_tx, gate_rx) = unbounded::<()>();
        let w = Worker::spawn(move || {
            let _ = sent_tx.send(());
            let _ = gate_rx.recv();
        });
        (w, sent_rx, gate_tx)
    }

    /// Collects frames until generation `g` sends its last one (30 s at most).
    fn frames_until_last_of(w: &Worker, g: u64) -> Vec<Frame> {
        let deadline = Instant::now() + Duration::from_secs(30);
        let mut got = Vec::new();
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            let f = w.frames.recv_timeout(left).expect("generation never finished");
            let done = f.generation == g && f.last;
            got.push(f);
            if done {
                return got;
            }
        }
    }

    #[test]
    fn a_newer_job_cancels_the_older_one() {
        let (w, sent, gate) = gated();
        // A job far too long to finish: 4096 samples at 320×240.
        w.submit(job(1, 320, 240, 4096));
        sent.recv_timeout(Duration::from_secs(30)).unwrap();
        let first = w.frames.try_recv().unwrap();
        assert_eq!((first.generation, first.last), (1, false));
        // Job 1 is running (its thread waits in the wake-up); replace it.
        w.submit(job(2, 16, 16, 2));
        drop(gate);
        let after = frames_until_last_of(&w, 2);
        let gens: Vec<u64> = after.iter().map(|f| f.generation).collect();
        assert!(gens.iter().all(|&g| g == 2), "job 1 went on after job 2 came: {gens:?}");
        assert_eq!(after.last().map(|f| f.spp), Some(2));
    }

    /// Waits (up to 30 s) until the render thread has sent something.
    fn wait_for_a_frame(w: &Worker) {
        let deadline = Instant::now() + Duration::from_secs(30);
        while w.frames.is_empty() {
            assert!(Instant::now() < deadline, "no frame");
            std::thread::sleep(Duration::from_millis(2));
        }
    }

    #[test]
    fn cancel_stops_the_job_and_drops_what_it_sent() {
        let (w, sent, gate) = gated();
        w.submit(job(1, 64, 48, 1 << 16));
        sent.recv_timeout(Duration::from_secs(30)).unwrap();
        // Job 1 is running and its first frame waits in the channel.
        w.cancel();
        assert!(
            w.frames().pop().is_none(),
            "a frame of the cancelled job was handed out"
        );
        drop(gate);
        // The thread takes the next job, and nothing of job 1 comes between:
        // frames arrive in order, so a job that went on would show here.
        w.submit(job(2, 16, 16, 2));
        let after = frames_until_last_of(&w, 2);
        let gens: Vec<u64> = after.iter().map(|f| f.generation).collect();
        assert!(
            gens.iter().all(|&g| g == 2),
            "the cancelled job kept rendering: {gens:?}"
        );
        assert_eq!(after.last().map(|f| f.spp), Some(2));
    }

    #[test]
    fn frames_drops_frames_of_older_jobs() {
        let w = Worker::spawn(|| {});
        w.submit(job(1, 16, 16, 2));
        wait_for_a_frame(&w);
        // Frames of job 1 wait in the channel; job 2 replaces it.
        w.submit(job(2, 16, 16, 2));
        let f = w.frames().pop();
        assert!(
            f.as_ref().is_none_or(|f| f.generation == 2),
            "{:?}",
            f.map(|f| f.generation)
        );
    }

    /// After a camera move the first frame is the reprojected picture,
    /// then refinement goes on from one sample per pixel; an edit (not only
    /// the camera) starts as before, from the level that fits the budget.
    #[test]
    fn a_camera_move_shows_the_reprojected_picture_first() {
        let w = Worker::spawn(|| {});
        let a = job(1, 48, 32, 2);
        w.submit(a.clone());
        frames_until_last_of(&w, 1);
        let mut moved = (*a.scene).clone();
        let c = &moved.camera;
        moved.camera = crate::camera::Camera::new(c.position + c.forward() * 0.1, c.rotation_deg, c.fov_y_deg);
        w.submit(Job {
            generation: 2,
            change: Change::Camera,
            scene: Arc::new(moved.clone()),
            ..a.clone()
        });
        let stages: Vec<Stage> = frames_until_last_of(&w, 2).iter().map(|f| f.stage).collect();
        assert_eq!(stages, [Stage::Reprojected, Stage::Samples(1), Stage::Samples(2)]);
        let mut edited = moved;
        edited.background *= 0.5;
        w.submit(Job {
            generation: 3,
            change: Change::Shading,
            scene: Arc::new(edited),
            ..a
        });
        let first = frames_until_last_of(&w, 3)[0].stage;
        assert!(matches!(first, Stage::Blocks(_) | Stage::Samples(1)), "{first:?}");
        assert_eq!(hole_level(1000, None), 2);
        assert_eq!(hole_level(1000, Some(1e-6)), 1);
        assert_eq!(hole_level(100_000, Some(1e-7)), 2);
        assert_eq!(hole_level(100_000, Some(1e-6)), 8);
    }

    /// The pixels a reprojection traces afresh see the photon map: turned
    /// from the floor behind it to the focal spot, which fills the view,
    /// the camera's first (reprojected) frame is as bright as the frames
    /// after, not the grey of the lens's shadow.
    #[test]
    fn reprojected_holes_show_the_caustic() {
        use crate::camera::Camera;
        use glam::DVec3;
        let text = include_str!("../../scenes/focal-spot.toml");
        let mut scene = Scene::parse("focal-spot.toml", text).unwrap().1;
        let eye = DVec3::new(0.0, 1.2, 0.8);
        scene.camera = Camera::new(eye, DVec3::new(-55.0, 180.0, 0.0), 40.0);
        let w = Worker::spawn(|| {});
        let a = Job {
            scene: Arc::new(scene.clone()),
            ..job(1, 48, 32, 2)
        };
        w.submit(a.clone());
        frames_until_last_of(&w, 1);
        scene.camera = Camera::new(eye, DVec3::new(-55.0, 0.0, 0.0), 40.0);
        w.submit(Job {
            generation: 2,
            change: Change::Camera,
            scene: Arc::new(scene.clone()),
            ..a
        });
        let frames = frames_until_last_of(&w, 2);
        assert_eq!(frames[0].stage, Stage::Reprojected);
        // The middle of the view, inside the spot.
        let mean = |f: &Frame| {
            let px = |(x, y): (usize, usize)| f.rgba[4 * (y * 48 + x)] as f64;
            (10..22)
                .flat_map(|y| (16..32).map(move |x| (x, y)))
                .map(px)
                .sum::<f64>()
                / 192.0
        };
        let (first, last) = (mean(&frames[0]), mean(frames.last().unwrap()));
        // The same view without caustics: the lens's shadow.
        scene.caustics = Some(false);
        scene.compile();
        let w = Worker::spawn(|| {});
        w.submit(Job {
            generation: 3,
            scene: Arc::new(scene),
            ..job(3, 48, 32, 1)
        });
        let shadow = mean(frames_until_last_of(&w, 3).last().unwrap());
        assert!(last > 1.3 * shadow, "no spot to see: {last} vs the shadow's {shadow}");
        assert!(first > 0.8 * last, "reprojected {first}, then {last} (shadow {shadow})");
    }

    /// Holding: after the first frame of a job nothing more comes until
    /// the window reports it shown (the limit here is far longer than the
    /// test), then the job refines to its cap; a newer job ends a hold.
    #[test]
    fn a_held_job_goes_on_once_its_first_frame_is_shown() {
        let w = Worker::spawn(|| {});
        w.hold_first_frames(Duration::from_secs(600));
        w.submit(job(1, 32, 24, 4));
        let first = w.frames.recv_timeout(Duration::from_secs(30)).unwrap();
        assert!(!first.last);
        // Without the hold the whole job (a few milliseconds) would be here.
        std::thread::sleep(Duration::from_millis(300));
        assert!(w.frames.is_empty(), "frames came before the first was shown");
        w.shown(1);
        let rest = frames_until_last_of(&w, 1);
        assert_eq!(rest.last().map(|f| f.spp), Some(4));
        // Job 2 is held after its first frame; job 3 replaces it unshown.
        w.submit(job(2, 32, 24, 4));
        assert_eq!(w.frames.recv_timeout(Duration::from_secs(30)).unwrap().generation, 2);
        w.submit(job(3, 32, 24, 1));
        w.shown(3);
        let after = frames_until_last_of(&w, 3);
        assert!(after.iter().all(|f| f.generation == 3), "job 2 went on");
        // Off again: a job runs through unshown.
        w.hold_first_frames(Duration::ZERO);
        w.submit(job(4, 32, 24, 4));
        assert_eq!(frames_until_last_of(&w, 4).last().map(|f| f.spp), Some(4));
    }

    /// A frame's buffer handed back is written again: the next frame's
    /// pixels are in it (the same allocation), and they are what a worker
    /// given no buffers sends for the same jobs.
    #[test]
    fn recycled_buffers_carry_the_next_frames() {
        let (w, plain) = (Worker::spawn(|| {}), Worker::spawn(|| {}));
        for x in [&w, &plain] {
            x.submit(job(1, 32, 24, 2));
            frames_until_last_of(x, 1);
        }
        let mut old = vec![7u8; 32 * 24 * 4];
        old.reserve(100);
        let ptr = old.as_ptr();
        w.recycle(old);
        w.submit(job(2, 32, 24, 2));
        plain.submit(job(2, 32, 24, 2));
        let (got, want) = (frames_until_last_of(&w, 2), frames_until_last_of(&plain, 2));
        assert_eq!(got[0].rgba.as_ptr(), ptr, "the buffer was not reused");
        assert_eq!(got.len(), want.len());
        for (i, (a, b)) in got.iter().zip(&want).enumerate() {
            assert!(a.rgba == b.rgba, "frame {i} ({}) differs", b.stage.label());
        }
    }

    #[test]
    fn dropping_the_worker_stops_the_thread() {
        let w = Worker::spawn(|| {});
        w.submit(job(1, 640, 480, 4096));
        std::thread::sleep(Duration::from_millis(50));
        let t = Instant::now();
        drop(w);
        assert!(t.elapsed() < Duration::from_secs(20));
    }
}
