//! Recording a flight (F8) and playing one back (`--play FLIGHT`): the
//! camera's poses in time and every scene edit made meanwhile, as the
//! flight file `lensview film` renders ([`lensview::flight`]).

use glam::DVec3;
use lensview::edit::Document;
use lensview::edit::document::to_toml;
use lensview::flight::{EditKey, FLIGHT_VERSION, Flight, FlightFile, PoseKey};
use lensview::scene::{Scene, SceneFile};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// A still camera is recorded this often (a moving one at every frame).
const STILL_EVERY: f64 = 0.25;
/// Poses closer in time than this are one (a burst of events in a frame).
const MIN_GAP: f64 = 1.0 / 240.0;

pub struct Recorder {
    start: Instant,
    file: FlightFile,
    /// The scene as last recorded, its camera left out.
    scene: SceneFile,
    revision: u64,
}

/// The scene without its camera (what an edit is compared by).
fn without_camera(sf: &SceneFile, camera: &SceneFile) -> SceneFile {
    let mut s = sf.clone();
    s.camera = camera.camera.clone();
    s
}

impl Recorder {
    pub fn start(doc: &Document) -> Recorder {
        let mut r = Recorder {
            start: Instant::now(),
            file: FlightFile {
                version: FLIGHT_VERSION,
                scene: doc.source().path().map(|p| p.display().to_string()),
                poses: Vec::new(),
                edits: Vec::new(),
            },
            scene: doc.scene().clone(),
            revision: doc.revision(),
        };
        r.pose(0.0, doc);
        r
    }

    fn pose(&mut self, t: f64, doc: &Document) {
        let (p, r) = doc.camera_pose();
        self.file.poses.push(PoseKey {
            t,
            position: p.to_array(),
            rotation: r.to_array(),
            fov: Some(doc.built().camera.fov_y_deg),
        });
    }

    /// Records the document now: a pose when the camera moved (or a still
    /// one now and then), the whole scene when something but the camera
    /// changed.
    pub fn sample(&mut self, doc: &Document) {
        let t = self.start.elapsed().as_secs_f64();
        let last = *self.file.poses.last().expect("a recording starts with a pose"); // ok: Recorder::start pushes one
        if t - last.t < MIN_GAP {
            return;
        }
        let (p, r) = doc.camera_pose();
        let fov = doc.built().camera.fov_y_deg;
        let moved =
            DVec3::from_array(last.position) != p || DVec3::from_array(last.rotation) != r || last.fov != Some(fov);
        if moved || t - last.t >= STILL_EVERY {
            self.pose(t, doc);
        }
        if doc.revision() != self.revision {
            self.revision = doc.revision();
            let now = doc.scene();
            if without_camera(now, &self.scene) != self.scene
                && let Ok(text) = to_toml(now)
            {
                self.file.edits.push(EditKey { t, scene: text });
                self.scene = now.clone();
            }
        }
    }

    /// Ends the recording: the flight written beside the scene (or in the
    /// working folder for a preset), under the first free name.
    pub fn finish(mut self, doc: &Document) -> Result<(PathBuf, usize, f64), String> {
        self.sample(doc);
        let t = self.start.elapsed().as_secs_f64();
        if self.file.poses.last().is_some_and(|k| k.t < t) {
            self.pose(t, doc);
        }
        let flight = Flight { file: self.file };
        let text = flight.to_toml()?;
        let path = free_name(doc.source().path());
        lensview::output::write_file(&path, text.as_bytes()).map_err(|e| e.to_string())?;
        Ok((path, flight.file.poses.len(), flight.duration()))
    }
}

/// `NAME-flight-N.toml` beside the scene `NAME.toml`, N the first free.
fn free_name(scene: Option<&Path>) -> PathBuf {
    let (dir, stem) = match scene {
        Some(p) => (
            p.parent().map(Path::to_path_buf).unwrap_or_default(),
            p.file_stem()
                .map_or("lensview".into(), |s| s.to_string_lossy().into_owned()),
        ),
        None => (PathBuf::new(), "lensview".to_string()),
    };
    (1..)
        .map(|n| dir.join(format!("{stem}-flight-{n}.toml")))
        .find(|p| std::fs::symlink_metadata(p).is_err())
        .expect("a free name") // ok: the names are endless
}

/// A flight being played back.
pub struct Player {
    /// When the flight started: at the first step (the window's first
    /// picture), not when the viewer did.
    start: Option<Instant>,
    flight: Flight,
    /// The edit in force (its index), applied once.
    edit: Option<usize>,
}

impl Player {
    pub fn new(flight: Flight) -> Player {
        Player {
            start: None,
            flight,
            edit: None,
        }
    }

    /// What to show now: the scene of an edit that came into force (its
    /// camera aside), and the pose; `None` when the flight is over.
    pub fn step(&mut self) -> Option<(Option<SceneFile>, lensview::flight::Pose)> {
        let t = self.start.get_or_insert_with(Instant::now).elapsed().as_secs_f64();
        if t > self.flight.duration() {
            return None;
        }
        let mut scene = None;
        if let Some((i, text)) = self.flight.edit_at(t)
            && self.edit != Some(i)
        {
            self.edit = Some(i);
            scene = Scene::parse("the flight's edit", text).ok().map(|(sf, _)| sf);
        }
        Some((scene, self.flight.pose_at(t)))
    }
}
