//! Changes a user makes to a scene, applied to the file model so that what
//! is edited can be saved as it is.
//!
//! - [`document`]: the scene being edited — validation of every change
//!   through `Scene::build`, undo/redo, unsaved-changes state, save and
//!   open, add/delete/duplicate, and one method for each change the
//!   viewer's panel and keys make. The viewer only calls them.
//! - [`presets`]: the scenes of `scenes/`, compiled in.
//! - This module: the viewer's key edits ([`Edit`], [`apply`]), each clamped
//!   to valid values and saying what it did, clamp included, instead of
//!   failing (applied to a document by `Document::apply_edit`).

pub mod document;
pub mod presets;
mod scene_keys;
mod system_keys;

pub use scene_keys::{KeyOutcome, KeyRefused, KeyState, SCENE_KEYS, SceneKey, TEMPERATURE_RANGE, scene_key};
pub use system_keys::apply_system;

pub use document::{Change, Document, Item, Placement, Rejected, Source, Unsaved};

use crate::color::{Rgb, blackbody};
use crate::math::{domain, rotation_from_degrees};
use crate::scene::file::{IndexFile, LensFile, LightFile, LightKind, SceneFile, V3};
use glam::DVec3;

/// Smallest lens diameter the keys go down to.
pub const MIN_DIAMETER: f64 = 0.05;
/// Index range offered by the keys.
pub const INDEX_RANGE: (f64, f64) = (1.0, 4.0);

/// Named light colours offered by the colour key.
pub const LIGHT_PRESETS: [(&str, [f64; 3]); 6] = [
    ("white", [1.0, 1.0, 1.0]),
    ("warm 2700 K", [0.0, 0.0, 0.0]),
    ("daylight 6500 K", [0.0, 0.0, 0.0]),
    ("red", [1.0, 0.25, 0.2]),
    ("green", [0.3, 1.0, 0.3]),
    ("blue", [0.3, 0.45, 1.0]),
];

fn preset_colour(i: usize) -> Rgb {
    match i {
        1 => blackbody(2700.0),
        2 => blackbody(6500.0),
        _ => DVec3::from(LIGHT_PRESETS[i].1),
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Edit {
    /// Move the first point light by a world-space offset.
    LightMove(DVec3),
    /// Multiply the first light's intensity.
    LightIntensity(f64),
    /// Set the first light's colour to preset `i` (see [`LIGHT_PRESETS`]).
    LightPreset(usize),
    /// Set the first light's colour to a black body at this temperature.
    LightTemperature(f64),
    /// Move the first lens by a world-space offset.
    LensMove(DVec3),
    /// Move the first lens along its own axis.
    LensAlongAxis(f64),
    /// Turn the first lens's axis by yaw (about world y) and pitch (degrees).
    LensTurn {
        yaw: f64,
        pitch: f64,
    },
    LensDiameter(f64),
    LensR1(f64),
    LensR2(f64),
    LensIndex(f64),
}

impl Edit {
    /// Whether the edit changes a lens (the lens keys), rather than the
    /// light: with a lens system selected, these act on it.
    pub fn is_lens(&self) -> bool {
        !matches!(
            self,
            Edit::LightMove(_) | Edit::LightIntensity(_) | Edit::LightPreset(_) | Edit::LightTemperature(_)
        )
    }
}

/// The lens keys, the desktop viewer's and the web page's: each key's
/// code (the name of winit's `KeyCode`, which is also the DOM's
/// `KeyboardEvent.code`) and the edit it makes to the first lens (or the
/// selected system) through [`apply`].
pub const LENS_KEYS: [(&str, Edit); 18] = [
    ("KeyZ", Edit::LensAlongAxis(-0.1)),
    ("KeyX", Edit::LensAlongAxis(0.1)),
    ("KeyV", Edit::LensMove(DVec3::new(-0.1, 0.0, 0.0))),
    ("KeyB", Edit::LensMove(DVec3::new(0.1, 0.0, 0.0))),
    ("KeyN", Edit::LensMove(DVec3::new(0.0, -0.1, 0.0))),
    ("KeyM", Edit::LensMove(DVec3::new(0.0, 0.1, 0.0))),
    ("Digit9", Edit::LensTurn { yaw: -5.0, pitch: 0.0 }),
    ("Digit0", Edit::LensTurn { yaw: 5.0, pitch: 0.0 }),
    ("Minus", Edit::LensTurn { yaw: 0.0, pitch: -5.0 }),
    ("Equal", Edit::LensTurn { yaw: 0.0, pitch: 5.0 }),
    ("Digit1", Edit::LensDiameter(-0.1)),
    ("Digit2", Edit::LensDiameter(0.1)),
    ("Digit3", Edit::LensR1(-0.25)),
    ("Digit4", Edit::LensR1(0.25)),
    ("Digit5", Edit::LensR2(-0.25)),
    ("Digit6", Edit::LensR2(0.25)),
    ("Digit7", Edit::LensIndex(-0.02)),
    ("Digit8", Edit::LensIndex(0.02)),
];

/// The edit of lens key `code` ([`LENS_KEYS`]).
pub fn lens_key(code: &str) -> Option<Edit> {
    LENS_KEYS.iter().find(|k| k.0 == code).map(|k| k.1)
}

fn first_light(sf: &mut SceneFile) -> Option<&mut LightFile> {
    let i = sf.lights.iter().position(|l| l.kind == LightKind::Point).unwrap_or(0);
    sf.lights.get_mut(i)
}

/// A point kept within the supported coordinates ([`domain`]): each
/// coordinate clamped to ±`MAX_COORDINATE`; true when one was.
fn clamp_point(p: DVec3) -> (DVec3, bool) {
    let m = domain::MAX_COORDINATE;
    let c = p.clamp(DVec3::splat(-m), DVec3::splat(m));
    (c, c != p)
}

/// `message`, and when `clamped` that the value stopped at the edge of the
/// supported domain.
fn said(message: String, clamped: bool) -> String {
    if clamped {
        format!("{message} (clamped to the supported domain)")
    } else {
        message
    }
}

fn fmt3(v: [f64; 3]) -> String {
    format!("({:.2}, {:.2}, {:.2})", v[0], v[1], v[2])
}

/// Applies `edit` to the scene file; returns a line saying what changed.
pub fn apply(sf: &mut SceneFile, edit: Edit) -> String {
    match edit {
        Edit::LightMove(d) => match first_light(sf) {
            Some(l) if l.kind == LightKind::Point => {
                let (p, clamped) = clamp_point(DVec3::from(l.position.unwrap_or_default()) + d);
                l.position = Some(p.to_array());
                said(format!("light moved to {}", fmt3(p.to_array())), clamped)
            }
            Some(l) => {
                let dir = (DVec3::from(l.direction.unwrap_or([0.0, -1.0, 0.0])) + d * 0.1).normalize_or(DVec3::NEG_Y);
                l.direction = Some(dir.to_array());
                format!("light direction {}", fmt3(dir.to_array()))
            }
            None => "the scene has no light".into(),
        },
        Edit::LightIntensity(f) => match first_light(sf) {
            Some(l) => {
                let want = l.intensity * f;
                l.intensity = want.clamp(0.0, domain::MAX_INTENSITY);
                let clamped = want != l.intensity;
                said(format!("light intensity {:.3}", l.intensity), clamped)
            }
            None => "the scene has no light".into(),
        },
        Edit::LightPreset(i) => match first_light(sf) {
            Some(l) => {
                let i = i % LIGHT_PRESETS.len();
                l.color = preset_colour(i).to_array();
                format!("light colour: {} {}", LIGHT_PRESETS[i].0, fmt3(l.color))
            }
            None => "the scene has no light".into(),
        },
        Edit::LightTemperature(k) => match first_light(sf) {
            Some(l) => {
                let k = k.clamp(1000.0, 40000.0);
                l.color = blackbody(k).to_array();
                format!("light colour: black body {k:.0} K {}", fmt3(l.color))
            }
            None => "the scene has no light".into(),
        },
        _ => match sf.lenses.first_mut() {
            Some(lens) => edit_lens(lens, edit),
            None => "the scene has no lens".into(),
        },
    }
}

fn edit_lens(l: &mut LensFile, edit: Edit) -> String {
    let half_max = 0.5 * l.d;
    match edit {
        Edit::LensMove(_) | Edit::LensAlongAxis(_) => {
            let step = match edit {
                Edit::LensMove(d) => d,
                Edit::LensAlongAxis(s) => DVec3::from(l.axis).normalize_or(DVec3::Z) * s,
                _ => DVec3::ZERO,
            };
            let (c, clamped) = clamp_point(DVec3::from(l.center) + step);
            l.center = c.to_array();
            said(format!("lens centre {}", fmt3(l.center)), clamped)
        }
        Edit::LensTurn { yaw, pitch } => {
            l.axis = turn_axis(l.axis, yaw, pitch);
            format!("lens axis {}", fmt3(l.axis))
        }
        Edit::LensDiameter(delta) => {
            let max = (2.0 * l.r1.min(l.r2)).min(domain::MAX_LENGTH);
            let want = l.d + delta;
            l.d = want.clamp(MIN_DIAMETER, max);
            if want > max {
                format!("lens d clamped to 2·min(r1, r2) = {:.4}", l.d)
            } else if want < MIN_DIAMETER {
                format!("lens d clamped to its minimum {MIN_DIAMETER}")
            } else {
                format!("lens d = {:.4}", l.d)
            }
        }
        Edit::LensR1(delta) | Edit::LensR2(delta) => {
            let (name, r) = if matches!(edit, Edit::LensR1(_)) {
                ("r1", &mut l.r1)
            } else {
                ("r2", &mut l.r2)
            };
            let want = *r + delta;
            *r = want.max(half_max).min(domain::MAX_LENGTH);
            if want < half_max {
                format!("lens {name} clamped to d/2 = {:.4} (a hemisphere)", *r)
            } else {
                said(format!("lens {name} = {:.4}", *r), want > *r)
            }
        }
        Edit::LensIndex(delta) => edit_index(&mut l.n, delta),
        _ => String::new(),
    }
}

/// `axis` turned by yaw (about world y) and then pitch (about the
/// horizontal perpendicular to it), degrees; a unit vector.
fn turn_axis(axis: V3, yaw: f64, pitch: f64) -> V3 {
    let a = DVec3::from(axis).normalize_or(DVec3::Z);
    let turned = rotation_from_degrees(DVec3::new(0.0, yaw, 0.0)) * a;
    let side = turned.cross(DVec3::Y).normalize_or(DVec3::X);
    // glam's `DQuat::from_axis_angle`, from `libm`'s sine and cosine (the
    // same bits in the browser as on the desktop: ARCHITECTURE.md).
    let (s, c) = libm::sincos(pitch.to_radians() * 0.5);
    let v = side * s;
    let turned = glam::DQuat::from_xyzw(v.x, v.y, v.z, c) * turned;
    turned.normalize().to_array()
}

/// The lens index changed by `delta` (its Cauchy A for a Cauchy pair),
/// clamped to [`INDEX_RANGE`]; a catalogue glass is left as it is.
fn edit_index(n: &mut IndexFile, delta: f64) -> String {
    let (lo, hi) = INDEX_RANGE;
    match n {
        IndexFile::Constant(n) => {
            let want = *n + delta;
            *n = want.clamp(lo, hi);
            if want != *n {
                format!("lens n clamped to {:.4}", *n)
            } else {
                format!("lens n = {:.4}", *n)
            }
        }
        IndexFile::Cauchy([a, b]) => {
            // Shift A; keep n(λ) within range over the visible band.
            let n_blue = |a: f64| a + *b / (0.38 * 0.38);
            let want = *a + delta;
            let a_max = hi - (n_blue(0.0)).max(0.0);
            let a_min = lo - (*b / (0.78 * 0.78)).min(0.0);
            *a = want.clamp(a_min, a_max.max(a_min));
            if want != *a {
                format!("lens Cauchy A clamped to {:.4}", *a)
            } else {
                format!("lens Cauchy A = {:.4} (B = {:.5})", *a, *b)
            }
        }
        // A catalogue glass is kept: its index is the glass's own.
        IndexFile::Glass(g) => format!(
            "lens n is the glass {} (nd = {:.5}): choose n or Cauchy in the panel to change it",
            g.name,
            g.nd()
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;

    fn sf() -> SceneFile {
        Scene::default_scene().0
    }

    #[test]
    fn a_glass_lens_keeps_its_glass_under_the_index_key() {
        let mut s = sf();
        let g = crate::glass::lookup("N-BK7").unwrap();
        s.lenses[0].n = IndexFile::Glass(g);
        let msg = apply(&mut s, Edit::LensIndex(0.3));
        assert!(msg.contains("the glass N-BK7 (nd = 1.51680)"), "{msg}");
        assert_eq!(s.lenses[0].n, IndexFile::Glass(g));
        Scene::build(&s).unwrap();
    }

    #[test]
    fn lens_edits_are_clamped_and_the_scene_stays_valid() {
        let mut s = sf();
        for _ in 0..100 {
            apply(&mut s, Edit::LensR1(-0.5));
            apply(&mut s, Edit::LensDiameter(0.7));
            apply(&mut s, Edit::LensIndex(0.3));
            Scene::build(&s).unwrap();
        }
        let msg = apply(&mut s, Edit::LensR1(-0.5));
        assert!(msg.contains("clamped to d/2"), "{msg}");
        assert_eq!(s.lenses[0].r1, 0.5 * s.lenses[0].d);
        let msg = apply(&mut s, Edit::LensDiameter(100.0));
        assert!(msg.contains("clamped"), "{msg}");
        assert!(s.lenses[0].d <= 2.0 * s.lenses[0].r1.min(s.lenses[0].r2));
        assert_eq!(s.lenses[0].n, IndexFile::Constant(4.0));
        for _ in 0..100 {
            apply(&mut s, Edit::LensIndex(-0.3));
            apply(&mut s, Edit::LensDiameter(-0.3));
        }
        assert_eq!(s.lenses[0].n, IndexFile::Constant(1.0));
        assert_eq!(s.lenses[0].d, MIN_DIAMETER);
        Scene::build(&s).unwrap();
    }

    #[test]
    fn lens_turns_keep_a_unit_axis_and_moves_follow_the_axis() {
        let mut s = sf();
        let c0 = DVec3::from(s.lenses[0].center);
        let a0 = DVec3::from(s.lenses[0].axis).normalize();
        apply(&mut s, Edit::LensAlongAxis(1.0));
        assert!((DVec3::from(s.lenses[0].center) - (c0 + a0)).length() < 1e-12);
        apply(&mut s, Edit::LensTurn { yaw: 30.0, pitch: 10.0 });
        let a = DVec3::from(s.lenses[0].axis);
        assert!((a.length() - 1.0).abs() < 1e-12 && a.dot(a0) < 0.99);
    }

    /// No key step leaves the supported domain: each stops at its edge and
    /// says so, and the scene still builds.
    #[test]
    fn key_steps_stop_at_the_edge_of_the_domain() {
        let mut s = sf();
        s.lights[0].intensity = 0.9 * domain::MAX_INTENSITY;
        let msg = apply(&mut s, Edit::LightIntensity(1.25));
        assert_eq!(s.lights[0].intensity, domain::MAX_INTENSITY);
        assert!(msg.contains("clamped to the supported domain"), "{msg}");
        Scene::build(&s).unwrap();
        // Inside, no clamp is said (and a large value is not pulled down).
        s.lights[0].intensity = 1e10;
        let msg = apply(&mut s, Edit::LightIntensity(1.25));
        assert_eq!((s.lights[0].intensity, msg.contains("clamped")), (1.25e10, false));
        let far = DVec3::splat(2.0 * domain::MAX_COORDINATE);
        let msg = apply(&mut s, Edit::LightMove(far));
        assert!(
            msg.contains("clamped") && s.lights[0].position.unwrap()[1] == domain::MAX_COORDINATE,
            "{msg}"
        );
        let msg = apply(&mut s, Edit::LensMove(-far));
        assert!(
            msg.contains("clamped") && s.lenses[0].center[2] == -domain::MAX_COORDINATE,
            "{msg}"
        );
        let msg = apply(&mut s, Edit::LensAlongAxis(3.0 * domain::MAX_COORDINATE));
        assert!(msg.contains("clamped"), "{msg}");
        assert!(s.lenses[0].center.iter().all(|c| c.abs() <= domain::MAX_COORDINATE));
        let msg = apply(&mut s, Edit::LensR1(2.0 * domain::MAX_LENGTH));
        assert!(msg.contains("clamped") && s.lenses[0].r1 == domain::MAX_LENGTH, "{msg}");
        apply(&mut s, Edit::LensR2(2.0 * domain::MAX_LENGTH));
        apply(&mut s, Edit::LensDiameter(3.0 * domain::MAX_LENGTH));
        assert_eq!(s.lenses[0].d, domain::MAX_LENGTH);
        // Every lens value is back inside the domain's checks.
        for e in [domain::length(s.lenses[0].d, 0.0), domain::length(s.lenses[0].r1, 0.0)] {
            assert_eq!(e, None);
        }
    }

    #[test]
    fn light_edits() {
        let mut s = sf();
        let i0 = s.lights[0].intensity;
        apply(&mut s, Edit::LightIntensity(2.0));
        assert_eq!(s.lights[0].intensity, 2.0 * i0);
        apply(&mut s, Edit::LightMove(DVec3::X));
        assert_eq!(s.lights[0].position.unwrap()[0], 6.0);
        let m = apply(&mut s, Edit::LightTemperature(2700.0));
        assert!(m.contains("2700 K") && s.lights[0].color[0] > s.lights[0].color[2]);
        for i in 0..LIGHT_PRESETS.len() {
            apply(&mut s, Edit::LightPreset(i));
            Scene::build(&s).unwrap();
        }
    }
}
