//! `[camera] lens`, `sensor`, `focus_distance` | `sensor_distance`,
//! `f_number` and `pinhole`: the lens camera ([`LensCamera`]), its surfaces
//! read as a `[[systems]]` entry's are (a preset, a prescription or a
//! table), each refusal naming its key.

use super::error::FieldPath;
use super::file::{CameraLensFile, SceneFile, SystemFile};
use super::validate::Validator;
use crate::camera::{Focus, LensCamera, LensCameraSpec};

/// The sensor when none is given: 36 × 24 (a full frame in millimetres),
/// times the lens's scale.
pub const DEFAULT_SENSOR: [f64; 2] = [36.0, 24.0];

/// The `[[systems]]` entry a camera lens stands for: its kind is the one
/// key of `preset`, `prescription` and `surfaces` it sets.
fn as_system(lens: &CameraLensFile) -> Result<SystemFile, String> {
    let set = [
        ("preset", lens.preset.is_some()),
        ("prescription", lens.prescription.is_some()),
        ("surfaces", lens.surfaces.is_some()),
    ];
    let kinds: Vec<&str> = set.iter().filter(|(_, on)| *on).map(|(k, _)| *k).collect();
    let [kind] = kinds[..] else {
        return Err(format!(
            "give exactly one of `preset`, `prescription` or `surfaces` (found {})",
            if kinds.is_empty() {
                "none".to_string()
            } else {
                kinds.join(", ")
            }
        ));
    };
    let file = format!("kind = {kind:?}\n{}", toml::to_string(lens).map_err(|e| e.to_string())?);
    toml::from_str(&file).map_err(|e| e.to_string())
}

/// The lens camera `sf`'s `[camera]` describes, shown or not (`pinhole =
/// true` keeps it): `None` without a `lens`, or when it is refused.
pub fn lens_camera_of(sf: &SceneFile) -> Option<LensCamera> {
    Validator::default().lens_camera(sf)
}

impl Validator {
    /// The lens camera of `[camera]`, if it has a `lens` (`None`, with the
    /// problem noted, when it is impossible).
    pub(super) fn lens_camera(&mut self, sf: &SceneFile) -> Option<LensCamera> {
        let cp = FieldPath::root("camera");
        let c = &sf.camera;
        let Some(lens) = &c.lens else {
            for (key, set) in [
                ("sensor", c.sensor.is_some()),
                ("focus_distance", c.focus_distance.is_some()),
                ("sensor_distance", c.sensor_distance.is_some()),
                ("f_number", c.f_number.is_some()),
                ("pinhole", c.pinhole.is_some()),
            ] {
                if set {
                    self.problem(cp.key(key), format!("`{key}` needs a `lens`"));
                }
            }
            return None;
        };
        let lp = cp.key("lens");
        let system = match as_system(lens) {
            Ok(s) => s,
            Err(why) => {
                self.problem(lp, why);
                return None;
            }
        };
        let (surfaces, fields) = self.system_surfaces(&lp, &system)?;
        let scale = if system.kind == "surfaces" {
            1.0
        } else {
            lens.scale.unwrap_or(1.0)
        };
        let sensor = c.sensor.unwrap_or(DEFAULT_SENSOR).map(|v| v * scale);
        let focus = match (c.focus_distance, c.sensor_distance) {
            (Some(_), Some(_)) => {
                self.problem(
                    cp.key("sensor_distance"),
                    "give either focus_distance or sensor_distance, not both",
                );
                return None;
            }
            (Some(d), None) => Focus::Distance(d),
            (None, Some(s)) => Focus::Sensor(s),
            (None, None) => Focus::Distance(f64::INFINITY),
        };
        let spec = LensCameraSpec {
            surfaces,
            sensor,
            focus,
            f_number: c.f_number,
        };
        match LensCamera::new(&spec) {
            Ok(cam) => Some(cam),
            Err(e) => {
                let path = match &e.system {
                    Some(s) => lp.key(&fields(s)),
                    None => cp.key(e.field),
                };
                self.problem(path, e.message);
                None
            }
        }
    }
}
