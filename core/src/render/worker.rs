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
use super::thinning::thinning_of;
use crate::integrator::Lit;
use crate::scene::{Change, Scene};
use crossbeam_channel::{Receiver, Sender, unbounded};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;
use web_time::Instant;

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

/// The picture the render thread holds, in linear light: what the window
/// shows (the newest stage sent), for a screenshot ([`Worker::snapshot`]).
#[derive(Clone, Debug)]
pub struct Snapshot {
    pub image: super::Image,
    /// Samples per pixel (0 for a block preview or a reprojection).
    pub spp: u32,
    /// The job it belongs to.
    pub generation: u64,
}

/// Where a snapshot goes: `None` when there is no picture yet.
type SnapshotReply = Sender<Option<Snapshot>>;

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
    /// Requests for the picture held ([`Self::snapshot`]).
    snapshots: Sender<SnapshotReply>,
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
        let (snapshots, snap_rx) = unbounded::<SnapshotReply>();
        let (w, s) = (wanted.clone(), shown.clone());
        let handle = std::thread::Builder::new()
            .name("lensview-render".into())
            .spawn(move || run((job_rx, snap_rx), frame_tx, (w, s, spare_rx), wake))
            .ok();
        Worker {
            jobs: Some(job_tx),
            frames: frame_rx,
            wanted,
            shown,
            spare,
            snapshots,
            handle,
        }
    }

    /// Asks for the picture the render thread holds, in linear light (the
    /// newest stage it sent): answered between stages, or at once when it
    /// is idle. `None` comes back when there is no picture yet.
    pub fn snapshot(&self) -> Receiver<Option<Snapshot>> {
        let (tx, rx) = crossbeam_channel::bounded(1);
        let _ = self.snapshots.send(tx);
        rx
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

/// How a job starts: with a picture to send at once (the reprojected one,
/// or the samples held shown in a new tone), going on at stage `first`;
/// or afresh at this stage of the schedule.
enum Start {
    Shown {
        stage: Stage,
        dt: f64,
        cast: u64,
        first: usize,
    },
    At(usize),
}

/// Only the display changed ([`Change::Display`]) and `prog` holds samples
/// of this size: the stage to go on at (past the samples it has).
fn kept(prog: &Progressive, shown: &Held, job: &Job, stages: &[Stage]) -> Option<usize> {
    let same = shown.scene.is_some() && (prog.width, prog.height) == (job.width, job.height);
    (same && shown.since == Change::Display && prog.spp > 0).then(|| {
        stages
            .iter()
            .position(|s| matches!(*s, Stage::Samples(n) if n > prog.spp))
            .unwrap_or(stages.len())
    })
}

/// A camera move with a picture to move: the previous picture reprojected
/// into the new view (refinement then goes on from the first
/// full-resolution sample) where [`Costs::choose`] finds that sharper
/// within the budget; otherwise a fresh start at the first stage that fits
/// the budget. `shown` is the scene whose picture `prog` holds; the holes
/// are traced in `traced` (the job's scene with its photon map beside it).
fn start(
    prog: &mut Progressive,
    shown: &mut Held,
    job: &Job,
    traced: Lit,
    stages: &[Stage],
    costs: &mut Costs,
) -> Start {
    if let Some(first) = kept(prog, shown, job, stages) {
        shown.set(&job.scene);
        let stage = Stage::Samples(prog.spp);
        return Start::Shown {
            stage,
            dt: 0.0,
            cast: 0,
            first,
        };
    }
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
        let first = stages.iter().position(|s| matches!(s, Stage::Samples(_))).unwrap_or(0);
        let (dt, cast) = (t0.elapsed().as_secs_f64(), prog.samples_cast);
        return Start::Shown {
            stage: Stage::Reprojected,
            dt,
            cast,
            first,
        };
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
        prog.write_rgba8(&mut rgba, job.scene.tone);
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

/// Waits for the next job, answering snapshot requests meanwhile with
/// `prog`'s picture (of job `pictured`); `None` once the worker is gone.
fn next_job(
    jobs: &Receiver<Job>,
    snapshots: &Receiver<SnapshotReply>,
    prog: &Progressive,
    pictured: Option<u64>,
) -> Option<Job> {
    loop {
        crossbeam_channel::select! {
            recv(jobs) -> j => return j.ok(),
            recv(snapshots) -> r => {
                let _ = r.ok()?.send(snapshot_of(prog, pictured));
            }
        }
    }
}

/// `prog`'s picture, of job `generation` (`None`: none sent yet).
fn snapshot_of(prog: &Progressive, generation: Option<u64>) -> Option<Snapshot> {
    generation
        .filter(|_| prog.width > 0 && prog.height > 0)
        .map(|g| Snapshot {
            image: prog.image(),
            spp: prog.spp,
            generation: g,
        })
}

/// Answers the snapshot requests waiting.
fn answer_snapshots(requests: &Receiver<SnapshotReply>, prog: &Progressive, generation: Option<u64>) {
    for reply in requests.try_iter() {
        let _ = reply.send(snapshot_of(prog, generation));
    }
}

fn run(
    (jobs, snapshots): (Receiver<Job>, Receiver<SnapshotReply>),
    frames: Sender<Frame>,
    (wanted, screen, spare): (Arc<AtomicU64>, Arc<Shown>, Receiver<Vec<u8>>),
    wake: impl Fn(),
) {
    let mut costs = Costs::default();
    // Reused across jobs of one size: zeroing two full-size buffers a keypress costs ms.
    let mut prog = Progressive::new(0, 0, 0);
    // The photon map, kept across jobs that change only the camera.
    let mut caustics = Interleaved::default();
    // The scene whose picture `prog` holds (for reprojection).
    let mut shown = Held::default();
    // What changed since the scene `caustics` last followed.
    let mut since_followed = Change::Picture;
    // The job whose stage `prog` holds last sent (for snapshots).
    let pictured = std::cell::Cell::new(None);
    while let Some(job) = next_job(&jobs, &snapshots, &prog, pictured.get()) {
        let (job, change) = newest(job, &jobs);
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
            pictured.set(Some(generation));
            answer_snapshots(&snapshots, prog, pictured.get());
            if ok && !last && !first_sent.replace(true) {
                screen.hold(generation, &cancelled);
            }
            ok
        };
        let traced = thinned(Lit::new(&job.scene, caustics.map()), (job.width, job.height));
        let first = match start(&mut prog, &mut shown, &job, traced, &stages, &mut costs) {
            Start::Shown { stage, dt, cast, first } => {
                if !send(&prog, stage, dt, cast, first == stages.len(), caustics.stats()) {
                    return;
                }
                first
            }
            Start::At(first) => {
                // The picture was started afresh: none to hand out until a stage is sent.
                pictured.set(None);
                first
            }
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
        record_first_hits(&mut prog, &job.scene, &mut costs, &cancelled);
    }
}

/// Refined (or cancelled): with nothing else to do, records the picture's
/// first hits for the next move's reprojection (which otherwise records
/// them itself, on the input's time).
fn record_first_hits(prog: &mut Progressive, scene: &Scene, costs: &mut Costs, cancelled: &(dyn Fn() -> bool + Sync)) {
    // A lens camera's picture is never reprojected ([`Progressive::reproject`]).
    if scene.lens.is_none()
        && prog.record_first_hits(scene, cancelled)
        && let Some(share) = prog.specular_share()
    {
        // What the next move's reprojection will have to trace, at least.
        costs.holes = share;
    }
}

/// The newest of `job` and the jobs waiting behind it, and the largest
/// change of them all (each says what changed since the one before).
fn newest(mut job: Job, jobs: &Receiver<Job>) -> (Job, Change) {
    let mut change = job.change;
    while let Ok(newer) = jobs.try_recv() {
        job = newer;
        change = change.max(job.change);
    }
    (job, change)
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
    // The stage's thinning of its gathers, and the photons that buys.
    let thin = thinning_of(&Lit::new(scene, caustics.map()), (prog.width, prog.height));
    let work = stage_work(stage, (prog.width, prog.height, prog.spp), scene.lights.len());
    caustics.refine((work, prog.stage_photons(stage, thin)), cancelled);
    let traced = Instant::now();
    caustics.gather_clock(false);
    if !prog.run(Lit::new(scene, caustics.map()).thinned(thin), stage, cancelled) {
        return None;
    }
    caustics.gather_clock(true);
    let cost = prog.samples_cast - before;
    costs.sampled(stage, traced.elapsed().as_secs_f64(), cost);
    Some((t0.elapsed().as_secs_f64(), cost))
}

/// `lit` with its sample stages' gathers thinned as its map and camera
/// allow in a frame of `size` pixels (`thinning::thinning_of`).
fn thinned(lit: Lit, size: (u32, u32)) -> Lit {
    lit.thinned(thinning_of(&lit, size))
}

#[cfg(test)]
mod tests;
