//! The changes the viewer's panel and keys make to a [`Document`], other
//! than adding and removing items: camera, lens, light, material and render
//! settings, and the key edits of [`Edit`]. Each is one method, validated
//! and undoable like any [`Document::edit`]; the viewer only calls them.
//!
//! Setters of a whole record (`set_lens`, `set_light`, …) are merged edits
//! keyed by the record's path, so dragging a value is one undo step.
//! Methods that return `Option` answer `None` when there is nothing to do
//! (no such item, or a direction that does not exist).

use super::{Change, Document, Item, Rejected};
use crate::color::blackbody;
use crate::edit::Edit;
use crate::math::{angles_looking_along, rotation_from_degrees};
use crate::optics::{Index, WAVELENGTH_D_UM};
use crate::scene::SceneFile;
use crate::scene::file::{AmbientFile, IndexFile, LensFile, LightFile, LightKind, MaterialFile, ObjectFile, V3};
use glam::DVec3;

/// Cauchy's B (µm²) given to a lens or material switched to dispersion: a
/// crown glass's.
pub const CROWN_B: f64 = 0.0042;

impl Document {
    /// Applies a key edit: clamped to valid values (see [`crate::edit::apply`]),
    /// validated and one undo step labelled with what it did. Returns that
    /// line and what changed.
    pub fn apply_edit(&mut self, edit: Edit) -> Result<(String, Change), Rejected> {
        let mut next = self.scene.clone();
        let msg = crate::edit::apply(&mut next, edit);
        let change = self.edit(&msg, |sf| *sf = next)?;
        Ok((msg, change))
    }

    /// Flight and mouse-look: one undo step per gesture (merged until
    /// [`Self::seal`]).
    pub fn fly_camera(&mut self, position: DVec3, rotation_deg: DVec3) -> Result<Change, Rejected> {
        self.edit_merged("fly", "move the camera", |sf| {
            set_camera_pose(sf, position, rotation_deg)
        })
    }

    /// Puts the camera back where it was when the document was opened.
    pub fn reset_view(&mut self) -> Result<Change, Rejected> {
        let (p, r) = self.home;
        self.edit("reset the view", |sf| set_camera_pose(sf, p, r))
    }

    /// The *Camera* fields: pose and vertical field of view (degrees).
    pub fn set_camera(&mut self, position: DVec3, rotation_deg: DVec3, fov_deg: f64) -> Result<Change, Rejected> {
        self.edit_merged("camera", "edit the camera", |sf| {
            set_camera_pose(sf, position, rotation_deg);
            sf.camera.fov = fov_deg;
        })
    }

    /// Turns the camera toward lens `i`'s centre (no roll).
    pub fn look_at_lens(&mut self, i: usize) -> Option<Result<Change, Rejected>> {
        let c = DVec3::from(self.scene.lenses.get(i)?.center);
        let pos = self.camera_pose().0;
        if (c - pos).length() <= 0.0 {
            return None;
        }
        let rot = angles_looking_along(c - pos);
        Some(self.edit("look at the lens", |sf| set_camera_pose(sf, pos, rot)))
    }

    /// The *Lens* fields of lens `i`, as one record.
    pub fn set_lens(&mut self, i: usize, lens: LensFile) -> Result<Change, Rejected> {
        let label = format!("edit {}", self.item_name(Item::Lens(i)));
        self.edit_merged(&format!("lenses[{i}]"), &label, |sf| {
            if let Some(l) = sf.lenses.get_mut(i) {
                *l = lens;
            }
        })
    }

    /// Turns lens `i`'s axis (S1) toward the camera, in place.
    pub fn point_lens_at_camera(&mut self, i: usize) -> Option<Result<Change, Rejected>> {
        let c = DVec3::from(self.scene.lenses.get(i)?.center);
        let pos = self.camera_pose().0;
        if (pos - c).length() <= 0.0 {
            return None;
        }
        let a = (pos - c).normalize().to_array();
        Some(self.edit("point the lens at the camera", |sf| sf.lenses[i].axis = a))
    }

    /// Moves lens `i` to `distance` in front of the camera, facing it.
    pub fn put_lens_in_front(&mut self, i: usize, distance: f64) -> Result<Change, Rejected> {
        let f = self.built.camera.forward();
        let pos = self.camera_pose().0;
        let (c, a) = ((pos + f * distance).to_array(), (-f).to_array());
        self.edit("put the lens in front of the camera", |sf| {
            if let Some(l) = sf.lenses.get_mut(i) {
                l.center = c;
                l.axis = a;
            }
        })
    }

    /// The *Objects* fields of primitive `i`, as one record.
    pub fn set_object(&mut self, i: usize, object: ObjectFile) -> Result<Change, Rejected> {
        let label = format!("edit {}", self.item_name(Item::Object(i)));
        self.edit_merged(&format!("objects[{i}]"), &label, |sf| {
            if let Some(o) = sf.objects.get_mut(i) {
                *o = object;
            }
        })
    }

    /// The fields of material `name` (added if missing).
    pub fn set_material(&mut self, name: &str, material: MaterialFile) -> Result<Change, Rejected> {
        let label = format!("edit material {name}");
        self.edit_merged(&format!("materials.{name}"), &label, |sf| {
            sf.materials.insert(name.to_string(), material);
        })
    }

    /// How many primitives use material `name`.
    pub fn material_users(&self, name: &str) -> usize {
        self.scene
            .objects
            .iter()
            .filter(|o| o.material.as_deref() == Some(name))
            .count()
    }

    /// Gives primitive `i` a material of its own, named after it: a copy of
    /// its material when others share it, the default material when it has
    /// none (or names one that does not exist). Nothing changes when it is
    /// already the only user of its material.
    pub fn give_own_material(&mut self, i: usize) -> Result<Change, Rejected> {
        let Some(o) = self.scene.objects.get(i) else {
            return Ok(Change::None);
        };
        let current = o
            .material
            .as_ref()
            .and_then(|m| Some((m, self.scene.materials.get(m)?)));
        let material = match current {
            Some((m, _)) if self.material_users(m) <= 1 => return Ok(Change::None),
            Some((_, mat)) => mat.clone(),
            None => MaterialFile::default(),
        };
        let obj_name = self.item_name(Item::Object(i));
        self.edit("own material", |sf| {
            let name = super::unique_key(&sf.materials, &obj_name);
            sf.materials.insert(name.clone(), material);
            sf.objects[i].material = Some(name);
        })
    }

    /// The *Light* fields of light `k`, as one record.
    pub fn set_light(&mut self, k: usize, light: LightFile) -> Result<Change, Rejected> {
        self.edit_merged(&format!("lights[{k}]"), "edit the light", |sf| {
            if let Some(l) = sf.lights.get_mut(k) {
                *l = light;
            }
        })
    }

    /// Adds a point light 2 units above the camera; returns its index.
    pub fn add_point_light(&mut self) -> Result<usize, Rejected> {
        let p = (self.camera_pose().0 + DVec3::Y * 2.0).to_array();
        let k = self.scene.lights.len();
        self.edit("add a light", |sf| sf.lights.push(new_point_light(p)))?;
        Ok(k)
    }

    pub fn delete_light(&mut self, k: usize) -> Result<Change, Rejected> {
        if k >= self.scene.lights.len() {
            return Ok(Change::None);
        }
        self.edit("delete a light", |sf| {
            sf.lights.remove(k);
        })
    }

    /// Colours light `k` as a black body at `kelvin` (merged while the
    /// slider is dragged).
    pub fn set_light_temperature(&mut self, k: usize, kelvin: f64) -> Result<Change, Rejected> {
        let c = blackbody(kelvin).to_array();
        self.edit_merged(&format!("lights[{k}].temperature"), "light colour", |sf| {
            if let Some(l) = sf.lights.get_mut(k) {
                l.color = c;
            }
        })
    }

    pub fn set_ambient(&mut self, ambient: AmbientFile) -> Result<Change, Rejected> {
        self.edit_merged("ambient", "edit the ambient light", |sf| sf.ambient = ambient)
    }

    /// Caustics by photon mapping on or off (written as `[render] caustics`).
    pub fn set_caustics(&mut self, on: bool) -> Result<Change, Rejected> {
        self.edit("caustics on/off", |sf| sf.render.caustics = Some(on))
    }

    pub fn set_shadows(&mut self, on: bool) -> Result<Change, Rejected> {
        self.edit("shadows on/off", |sf| sf.render.shadows = on)
    }

    /// The longest chain of reflections and refractions.
    pub fn set_max_depth(&mut self, depth: u32) -> Result<Change, Rejected> {
        self.edit_merged("render.max_depth", "max depth", |sf| sf.render.max_depth = depth)
    }

    pub fn set_background(&mut self, colour: V3) -> Result<Change, Rejected> {
        self.edit_merged("render.background", "background", |sf| sf.render.background = colour)
    }

    /// `[display] exposure` in stops, clamped to ±[`Tone::MAX_STOPS`] (one
    /// undo step per gesture: merged until [`Self::seal`]).
    pub fn set_exposure(&mut self, stops: f64) -> Result<Change, Rejected> {
        let m = crate::color::Tone::MAX_STOPS;
        let stops = if stops.is_nan() { 0.0 } else { stops.clamp(-m, m) };
        self.edit_merged("display.exposure", "exposure", |sf| sf.display.exposure = stops)
    }

    /// `[display] tone`: the tone curve.
    pub fn set_tone(&mut self, curve: crate::color::ToneCurve) -> Result<Change, Rejected> {
        self.edit("tone curve", |sf| sf.display.tone = curve)
    }
}

/// Sets the camera's pose as `position` and `rotation` (dropping `look_at`).
pub fn set_camera_pose(sf: &mut SceneFile, position: DVec3, rotation_deg: DVec3) {
    sf.camera.position = position.to_array();
    sf.camera.rotation = Some(rotation_deg.to_array());
    sf.camera.look_at = None;
}

/// Yaw and pitch (degrees) of a lens axis: the angles that turn +z onto it,
/// in the camera's convention (`R = Ry·Rx`, no roll).
pub fn axis_angles(axis: V3) -> (f64, f64) {
    // The camera convention turns −z; a lens axis is turned from +z, which
    // is −z turned by 180° of yaw.
    let a = DVec3::from(axis).normalize_or(DVec3::Z);
    let r = angles_looking_along(-a);
    (r.y, -r.x)
}

/// The lens axis for yaw and pitch in degrees (inverse of [`axis_angles`]).
pub fn axis_from_angles(yaw_deg: f64, pitch_deg: f64) -> V3 {
    let r = rotation_from_degrees(DVec3::new(-pitch_deg, yaw_deg, 0.0));
    let a = -(r * DVec3::NEG_Z);
    clean(a).to_array()
}

/// Rounds away the last-ulp noise of trigonometry (1e-15) so saved axes read well.
fn clean(v: DVec3) -> DVec3 {
    let f = |x: f64| {
        let r = (x * 1e12).round() / 1e12;
        if r == 0.0 { 0.0 } else { r }
    };
    DVec3::new(f(v.x), f(v.y), f(v.z))
}

/// A point light at `position`: white, power 300.
pub fn new_point_light(position: V3) -> LightFile {
    LightFile {
        kind: LightKind::Point,
        position: Some(position),
        direction: None,
        color: [1.0; 3],
        intensity: 300.0,
    }
}

/// Makes `light` a light of `kind`, with that kind's default placement: a
/// point light at (0, 8, 4); a directional light along (0.3, −1, −0.4) with
/// irradiance 1 (a point light's power would blind the scene).
pub fn switch_light_kind(light: &mut LightFile, kind: LightKind) {
    if light.kind == kind {
        return;
    }
    light.kind = kind;
    match kind {
        LightKind::Point => {
            light.position = Some([0.0, 8.0, 4.0]);
            light.direction = None;
        }
        LightKind::Directional => {
            light.direction = Some([0.3, -1.0, -0.4]);
            light.position = None;
            light.intensity = 1.0;
        }
    }
}

/// An index with or without dispersion, keeping its value at the d line:
/// a constant becomes Cauchy's `A + B/λ²` with a crown glass's B
/// ([`CROWN_B`]); a Cauchy pair becomes its d-line value. A catalogue
/// glass becomes its `nd`, or the Cauchy pair through its `nd` with its
/// `nF − nC` (so the Abbe number is kept).
pub fn index_with_dispersion(n: IndexFile, dispersive: bool) -> IndexFile {
    match (n, dispersive) {
        (IndexFile::Cauchy([a, b]), false) => IndexFile::Constant(Index::Cauchy { a, b }.nominal()),
        (IndexFile::Glass(g), false) => IndexFile::Constant(g.nd()),
        (IndexFile::Glass(g), true) => {
            use crate::glass::{C_UM, F_UM};
            let b = (g.n(F_UM) - g.n(C_UM)) / (F_UM.powi(-2) - C_UM.powi(-2));
            IndexFile::Cauchy([g.nd() - b / WAVELENGTH_D_UM.powi(2), b])
        }
        (IndexFile::Constant(v), true) => IndexFile::Cauchy([v - CROWN_B / WAVELENGTH_D_UM.powi(2), CROWN_B]),
        _ => n,
    }
}

#[cfg(test)]
mod tests;
