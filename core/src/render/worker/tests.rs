//! The render thread: order of stages, cancelling, holding, reprojection
//! after a move, and the photon map through a move.

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

/// A new tone keeps the samples: the first frame of the job is the held
/// picture (same samples) in the new tone, and refinement goes on from
/// there to the new cap; the default tone shows what it always did.
#[test]
fn a_new_tone_shows_the_samples_held_again() {
    let w = Worker::spawn(|| {});
    let a = job(1, 48, 32, 2);
    w.submit(a.clone());
    let before = frames_until_last_of(&w, 1).pop().unwrap();
    let mut toned = (*a.scene).clone();
    toned.tone = crate::color::Tone {
        exposure: 1.0,
        curve: crate::color::ToneCurve::Clamp,
    };
    w.submit(Job {
        generation: 2,
        change: Change::Display,
        scene: Arc::new(toned),
        max_spp: 4,
        ..a
    });
    let frames = frames_until_last_of(&w, 2);
    let stages: Vec<Stage> = frames.iter().map(|f| f.stage).collect();
    assert_eq!(stages, [Stage::Samples(2), Stage::Samples(4)]);
    // One stop up: each channel at least as bright, most brighter.
    let (old, new) = (&before.rgba, &frames[0].rgba);
    assert!(old.iter().zip(new).all(|(a, b)| b >= a));
    let brighter = old.iter().zip(new).filter(|(a, b)| b > a).count();
    assert!(brighter > old.len() / 2, "{brighter} of {}", old.len());
}

/// The pixels a reprojection traces afresh see the photon map: turned
/// from the floor behind it to the focal spot, which fills the view,
/// the camera's first (reprojected) frame is as bright as the frames
/// after, not the grey of the lens's shadow.
#[test]
fn reprojected_holes_show_the_caustic() {
    use crate::camera::Camera;
    use glam::DVec3;
    let text = include_str!("../../../../scenes/focal-spot.toml");
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
