//! A recorded flight: camera poses with their times, and the scene edits
//! made meanwhile, as a TOML file beside the scene (README, "Films"). The
//! viewer writes it; `lensview film` renders it frame by frame.
//!
//! Between poses the position follows a cubic Hermite curve whose tangents
//! are the finite differences of the neighbouring poses over their times
//! (Catmull–Rom on non-uniform times: it passes every recorded pose and
//! has no kink there), the orientation a quaternion slerp on the shorter
//! arc, the field of view a straight line. An edit holds the whole scene
//! after it (a scene file as text): at time `t` the scene is the one of the
//! last edit at or before `t`, the film's scene before the first.

use crate::math::rotation_from_degrees;
use crate::scene::SceneError;
use crate::scene::error::line_col;
use glam::{DQuat, DVec3, EulerRot};
use serde::{Deserialize, Serialize};
use toml::Spanned;

/// The format this build writes and reads.
pub const FLIGHT_VERSION: u32 = 1;

/// Poses a flight may hold (an hour at 60 a second, with room).
pub const MAX_POSES: usize = 1 << 18;

/// The file as written.
#[derive(Clone, Debug, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct FlightFile {
    pub version: u32,
    /// The scene it was recorded on, as the viewer knew it (informative).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scene: Option<String>,
    #[serde(default)]
    pub poses: Vec<PoseKey>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub edits: Vec<EditKey>,
}

/// The camera at a time.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PoseKey {
    /// Seconds from the start of the flight.
    pub t: f64,
    pub position: [f64; 3],
    /// Degrees about x, y and z, as the scene's `[camera] rotation`.
    pub rotation: [f64; 3],
    /// Vertical field of view in degrees; the scene's when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fov: Option<f64>,
}

/// The whole scene after an edit, from its time on.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct EditKey {
    pub t: f64,
    pub scene: String,
}

/// The camera between keys.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    pub position: DVec3,
    pub rotation_deg: DVec3,
    pub fov: Option<f64>,
}

/// A checked flight.
#[derive(Clone, Debug, PartialEq)]
pub struct Flight {
    pub file: FlightFile,
}

/// Spanned twins of the file's keys, to place a refusal at its line.
#[derive(Deserialize)]
struct Placed {
    #[serde(default)]
    poses: Vec<Spanned<Keys>>,
    #[serde(default)]
    edits: Vec<Spanned<Keys>>,
}

type Keys = std::collections::BTreeMap<String, Spanned<toml::Value>>;

/// Where key `field` of table `i` of `list` starts: the field's value, else
/// the table.
fn place(list: &[Spanned<Keys>], i: usize, field: &str) -> usize {
    list.get(i)
        .map_or(0, |s| s.get_ref().get(field).map_or(s.span().start, |v| v.span().start))
}

impl Flight {
    /// Reads and checks a flight; `file` names it in errors, which are one
    /// line: `file:line:column: field: message`.
    pub fn parse(file: &str, text: &str) -> Result<Flight, SceneError> {
        let at = |offset: usize, field: String, message: String| {
            let (line, column) = line_col(text, offset);
            SceneError::Invalid {
                file: file.to_string(),
                line,
                column,
                field,
                message,
            }
        };
        let flight: FlightFile = toml::from_str(text).map_err(|e| {
            let span = e.span().unwrap_or(0..0);
            at(span.start, "flight".into(), e.message().replace('\n', " "))
        })?;
        let problem = match check(&flight) {
            Ok(()) => return Ok(Flight { file: flight }),
            Err(p) => p,
        };
        // Only a refusal reads the text again, keeping the keys' places.
        let placed: Placed =
            toml::from_str(text).map_err(|e| at(0, "flight".into(), e.message().replace('\n', " ")))?;
        match problem {
            Problem::File(field, message) => Err(at(0, field.into(), message)),
            Problem::Pose(i, field, message) => Err(at(
                place(&placed.poses, i, field),
                format!("poses[{i}].{field}"),
                message,
            )),
            Problem::Edit(i, field, message) => Err(at(
                place(&placed.edits, i, field),
                format!("edits[{i}].{field}"),
                message,
            )),
        }
    }

    /// The flight's length in seconds: its last pose's time.
    pub fn duration(&self) -> f64 {
        self.file.poses.last().map_or(0.0, |p| p.t)
    }

    /// The camera at time `t` (clamped to the flight).
    pub fn pose_at(&self, t: f64) -> Pose {
        let p = &self.file.poses;
        let t = t.clamp(0.0, self.duration());
        // The last key at or before t (the first when t precedes it).
        let i = p.partition_point(|k| k.t <= t).saturating_sub(1);
        let Some(b) = p.get(i + 1) else {
            return key_pose(&p[i]);
        };
        let a = &p[i];
        let h = b.t - a.t;
        let s = ((t - a.t) / h).clamp(0.0, 1.0);
        if s == 0.0 {
            // The recorded pose itself, not its round trip through a
            // quaternion: a frame at a key is the still of that camera.
            return key_pose(a);
        }
        let tangent = |k: usize| {
            let (lo, hi) = (k.saturating_sub(1), (k + 1).min(p.len() - 1));
            (v(p[hi].position) - v(p[lo].position)) / (p[hi].t - p[lo].t)
        };
        let position = hermite(v(a.position), v(b.position), tangent(i) * h, tangent(i + 1) * h, s);
        let (qa, qb) = (quat(a.rotation), quat(b.rotation));
        let qb = if qa.dot(qb) < 0.0 { -qb } else { qb };
        let fov = match (a.fov, b.fov) {
            (Some(fa), Some(fb)) => Some(fa + (fb - fa) * s),
            (fa, fb) => fa.or(fb),
        };
        Pose {
            position,
            rotation_deg: degrees(qa.slerp(qb, s)),
            fov,
        }
    }

    /// The scene text in force at time `t`: the last edit's at or before
    /// it, `None` before the first edit (the film's own scene).
    pub fn edit_at(&self, t: f64) -> Option<(usize, &str)> {
        let e = &self.file.edits;
        let i = e.partition_point(|k| k.t <= t).checked_sub(1)?;
        Some((i, e[i].scene.as_str()))
    }

    /// The part of the flight from `from` to `to` seconds, played `speed`
    /// times as fast (a trim and a retime): poses inside kept at their new
    /// times, the poses at the cut points added, the edit in force at
    /// `from` moved to its start. `None` unless `0 ≤ from < to ≤ duration`
    /// and `speed` is positive and finite.
    pub fn retimed(&self, from: f64, to: f64, speed: f64) -> Option<Flight> {
        let ok = from >= 0.0 && from < to && to <= self.duration() && speed > 0.0 && speed.is_finite();
        if !ok {
            return None;
        }
        let at = |t: f64| (t - from) / speed;
        let key = |t: f64| {
            let p = self.pose_at(t);
            PoseKey {
                t: at(t),
                position: p.position.to_array(),
                rotation: p.rotation_deg.to_array(),
                fov: p.fov,
            }
        };
        let inner = self.file.poses.iter().filter(|k| k.t > from && k.t < to);
        let mut poses = vec![key(from)];
        poses.extend(inner.map(|k| PoseKey { t: at(k.t), ..*k }));
        poses.push(key(to));
        let mut edits: Vec<EditKey> = self.edit_at(from).map_or(vec![], |(i, _)| {
            vec![EditKey {
                t: 0.0,
                scene: self.file.edits[i].scene.clone(),
            }]
        });
        edits.extend(
            self.file
                .edits
                .iter()
                .filter(|e| e.t > from && e.t <= to)
                .map(|e| EditKey {
                    t: at(e.t),
                    scene: e.scene.clone(),
                }),
        );
        // Times that rounding made equal (keys closer than an ulp) are one.
        poses.dedup_by(|b, a| b.t <= a.t);
        let file = FlightFile {
            poses,
            edits,
            ..self.file.clone()
        };
        Some(Flight { file })
    }

    /// The flight as TOML text that reads back to the same flight.
    pub fn to_toml(&self) -> Result<String, String> {
        let body = toml::to_string(&self.file).map_err(|e| e.to_string())?;
        Ok(format!(
            "# lensview flight (recorded by lensview {}): camera poses and scene edits in time\n\n{body}",
            env!("CARGO_PKG_VERSION")
        ))
    }
}

fn v(a: [f64; 3]) -> DVec3 {
    DVec3::from_array(a)
}

fn key_pose(k: &PoseKey) -> Pose {
    Pose {
        position: v(k.position),
        rotation_deg: v(k.rotation),
        fov: k.fov,
    }
}

/// The cubic Hermite curve from `a` to `b` with end tangents `ta`, `tb`
/// (per unit of `s`), at `s` in `[0, 1]`.
fn hermite(a: DVec3, b: DVec3, ta: DVec3, tb: DVec3, s: f64) -> DVec3 {
    let (s2, s3) = (s * s, s * s * s);
    a * (2.0 * s3 - 3.0 * s2 + 1.0) + ta * (s3 - 2.0 * s2 + s) + b * (-2.0 * s3 + 3.0 * s2) + tb * (s3 - s2)
}

/// Degrees per pixel of mouse-look (a drag on the desktop, pointer-locked
/// movement on the web page).
pub const DRAG_RATE: f64 = 0.15;
/// Pitch stops short of straight up and down, where yaw is undefined.
pub const MAX_PITCH: f64 = 89.0;

/// The camera pose (position, rotation in degrees) turned by a mouse
/// movement of (`dx`, `dy`) pixels: right turns right, down looks down.
pub fn look((pos, mut rot): (DVec3, DVec3), dx: f64, dy: f64) -> (DVec3, DVec3) {
    rot.y -= dx * DRAG_RATE;
    rot.x = (rot.x - dy * DRAG_RATE).clamp(-MAX_PITCH, MAX_PITCH);
    (pos, rot)
}

/// The rotation of the camera's angles ([`rotation_from_degrees`]:
/// `Ry·Rx·Rz`) as a quaternion.
pub fn quat(deg: [f64; 3]) -> DQuat {
    let r = v(deg) * (std::f64::consts::PI / 180.0);
    DQuat::from_euler(EulerRot::YXZ, r.y, r.x, r.z)
}

/// The camera's angles of a rotation.
pub fn degrees(q: DQuat) -> DVec3 {
    let (y, x, z) = q.to_euler(EulerRot::YXZ);
    DVec3::new(x, y, z) * (180.0 / std::f64::consts::PI)
}

/// What is wrong with a flight, and where.
enum Problem {
    File(&'static str, String),
    Pose(usize, &'static str, String),
    Edit(usize, &'static str, String),
}

fn check(f: &FlightFile) -> Result<(), Problem> {
    if f.version != FLIGHT_VERSION {
        return Err(Problem::File(
            "version",
            format!(
                "version {} is not {FLIGHT_VERSION}, the one this lensview reads",
                f.version
            ),
        ));
    }
    if f.poses.is_empty() {
        return Err(Problem::File("poses", "a flight needs at least one pose".into()));
    }
    if f.poses.len() > MAX_POSES {
        return Err(Problem::File(
            "poses",
            format!("{} poses: at most {MAX_POSES}", f.poses.len()),
        ));
    }
    let mut last = -f64::INFINITY;
    for (i, p) in f.poses.iter().enumerate() {
        let bad = |field, m: String| Err(Problem::Pose(i, field, m));
        if !(p.t.is_finite() && p.t >= 0.0 && p.t <= crate::limits::MAX_FLIGHT_SECONDS) {
            return bad(
                "t",
                format!(
                    "time {} must be in [0, {}] seconds",
                    p.t,
                    crate::limits::MAX_FLIGHT_SECONDS
                ),
            );
        }
        if p.t <= last {
            return bad("t", format!("time {} does not follow the pose before ({last})", p.t));
        }
        last = p.t;
        if let Some(why) = p.position.iter().find_map(|&x| crate::math::domain::coordinate(x)) {
            return bad("position", why);
        }
        if !p.rotation.iter().all(|a| a.is_finite() && a.abs() <= 1e6) {
            return bad("rotation", "angles must be finite degrees (|a| ≤ 1e6)".into());
        }
        if let Some(fov) = p.fov
            && !(fov > 0.0 && fov < 180.0)
        {
            return bad("fov", format!("field of view {fov} must be in (0, 180) degrees"));
        }
        // The basis must be a rotation (no NaN from huge angles).
        if !rotation_from_degrees(v(p.rotation)).is_finite() {
            return bad("rotation", "angles give no rotation".into());
        }
    }
    let mut last = -f64::INFINITY;
    for (i, e) in f.edits.iter().enumerate() {
        if !(e.t.is_finite() && e.t >= 0.0) || e.t < last {
            return Err(Problem::Edit(
                i,
                "t",
                format!("time {} must be finite, ≥ 0 and not before the edit before", e.t),
            ));
        }
        last = e.t;
        if let Err(err) = crate::scene::Scene::parse("scene", &e.scene) {
            return Err(Problem::Edit(i, "scene", format!("the scene does not load: {err}")));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests;
