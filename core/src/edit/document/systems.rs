//! Lens systems (`[[systems]]`, docs/lens-systems.md) in a [`Document`]:
//! new ones of each kind or from a preset, sized for a scene (about 2
//! units across); the fields of one as a record; its table of surfaces
//! (insert, remove, move); its key edits. Each is validated and undoable
//! like any [`Document::edit`]; a refusal leaves the document as it was.

use super::{Change, Document, Item, Rejected};
use crate::edit::Edit;
use crate::geometry::LensSystem;
use crate::glass;
use crate::optics::Index;
use crate::prescription;
use crate::scene::file::{IndexFile, SurfaceFile, SystemFile, V3};
use crate::scene::{Scene, SceneFile};

/// The diameter new systems are given (scene units).
pub const NEW_DIAMETER: f64 = 2.0;

impl Document {
    /// Adds a lens system (named after its kind when it has no name);
    /// returns the new item.
    pub fn add_system(&mut self, mut system: SystemFile) -> Result<Item, Rejected> {
        if system.name.is_none() {
            system.name = Some(self.unique_name(&system_kind_label(&system)));
        }
        let label = format!("add {}", system_kind_label(&system));
        let index = self.scene.systems.len();
        self.edit(&label, |sf| sf.systems.push(system))?;
        Ok(Item::System(index))
    }

    /// Adds `system` turned to face the camera (its first surface toward
    /// it); returns the new item.
    pub fn add_system_facing_camera(&mut self, mut system: SystemFile) -> Result<Item, Rejected> {
        system.axis = (-self.built.camera.forward()).to_array();
        self.add_system(system)
    }

    /// The *System* fields of system `i`, as one record (merged while
    /// dragging: one undo step per gesture).
    pub fn set_system(&mut self, i: usize, system: SystemFile) -> Result<Change, Rejected> {
        let label = format!("edit {}", self.item_name(Item::System(i)));
        self.edit_merged(&format!("systems[{i}]"), &label, |sf| {
            if let Some(s) = sf.systems.get_mut(i) {
                *s = system;
            }
        })
    }

    /// The built lens system of `[[systems]]` entry `i`.
    pub fn built_system(&self, i: usize) -> Option<&LensSystem> {
        built_system(&self.built, i)
    }

    /// Inserts a surface after surface `k` of system `i` (kind `surfaces`):
    /// a plane in the same medium halfway through the gap after `k` (after
    /// the last, a plane in air behind it), so the optics do not change
    /// until it is edited.
    pub fn insert_surface(&mut self, i: usize, k: usize) -> Result<Change, Rejected> {
        let Some(list) = self.surfaces(i) else {
            return Ok(Change::None);
        };
        let Some(after) = list.get(k).cloned() else {
            return Ok(Change::None);
        };
        let last = k + 1 == list.len();
        // After the last: clear of its sag at the aperture.
        let a = after.semi_aperture;
        let c = if after.radius == 0.0 { 0.0 } else { 1.0 / after.radius };
        let sag = c * a * a / (1.0 + (1.0 - c * c * a * a).max(0.0).sqrt());
        let half = if last {
            sag.max(0.0) + 0.1 * a
        } else {
            0.5 * after.thickness
        };
        let new = SurfaceFile {
            radius: 0.0,
            thickness: if last { 0.0 } else { half },
            n: after.n,
            semi_aperture: after.semi_aperture,
            stop: false,
        };
        let label = format!(
            "insert a surface after surface {} of {}",
            k + 1,
            self.item_name(Item::System(i))
        );
        self.edit(&label, |sf| {
            let list = table_mut(sf, i);
            list[k].thickness = half;
            list.insert(k + 1, new);
        })
    }

    /// Removes surface `k` of system `i` (kind `surfaces`); the thickness
    /// after it joins the one before, so what follows stays in place.
    pub fn remove_surface(&mut self, i: usize, k: usize) -> Result<Change, Rejected> {
        let Some(list) = self.surfaces(i) else {
            return Ok(Change::None);
        };
        if k >= list.len() {
            return Ok(Change::None);
        }
        let label = format!("remove surface {} of {}", k + 1, self.item_name(Item::System(i)));
        self.edit(&label, |sf| {
            let list = table_mut(sf, i);
            let gone = list.remove(k);
            if k > 0 && k < list.len() {
                list[k - 1].thickness += gone.thickness;
            }
        })
    }

    /// Swaps surface `k` of system `i` with the one before it (`up`) or
    /// after it.
    pub fn move_surface(&mut self, i: usize, k: usize, up: bool) -> Result<Change, Rejected> {
        let Some(list) = self.surfaces(i) else {
            return Ok(Change::None);
        };
        let other = if up { k.checked_sub(1) } else { Some(k + 1) };
        let Some(j) = other.filter(|&j| j < list.len() && k < list.len()) else {
            return Ok(Change::None);
        };
        let dir = if up { "up" } else { "down" };
        let label = format!("move surface {} of {} {dir}", k + 1, self.item_name(Item::System(i)));
        self.edit(&label, |sf| table_mut(sf, i).swap(k, j))
    }

    /// Turns system `i` into kind `surfaces`: its table as built (lengths
    /// in scene units, a preset's scale applied), same pose and optics.
    pub fn system_to_surfaces(&mut self, i: usize) -> Result<Change, Rejected> {
        let Some(sys) = self.built_system(i) else {
            return Ok(Change::None);
        };
        let Some(s) = self.scene.systems.get(i) else {
            return Ok(Change::None);
        };
        let mut t = SystemFile {
            name: s.name.clone(),
            kind: "surfaces".into(),
            vertex: Some(sys.vertex.to_array()),
            center: None,
            axis: s.axis,
            tint: s.tint,
            ..empty_system("surfaces")
        };
        t.surfaces = Some(
            sys.surfaces
                .iter()
                .map(|f| SurfaceFile {
                    radius: if f.radius.is_infinite() { 0.0 } else { f.radius },
                    thickness: f.thickness,
                    n: index_file(f.n),
                    semi_aperture: f.semi_aperture,
                    stop: f.stop,
                })
                .collect(),
        );
        let label = format!("{} as a table of surfaces", self.item_name(Item::System(i)));
        self.edit(&label, |sf| sf.systems[i] = t)
    }

    /// Places system `i` by its first vertex (`by_vertex`) or by its
    /// centre (the middle of its axial length), the one point converted to
    /// the other from the system as built, so nothing moves.
    pub fn place_system(&mut self, i: usize, by_vertex: bool) -> Result<Change, Rejected> {
        let (Some(sys), Some(s)) = (self.built_system(i), self.scene.systems.get(i)) else {
            return Ok(Change::None);
        };
        if s.vertex.is_some() == by_vertex {
            return Ok(Change::None);
        }
        let vertex = sys.vertex;
        let centre = vertex - glam::DVec3::from(s.axis).normalize_or_zero() * (0.5 * sys.length());
        let (point, label) = if by_vertex {
            (vertex, "its first vertex")
        } else {
            (centre, "its centre")
        };
        let label = format!("place {} by {label}", self.item_name(Item::System(i)));
        self.edit(&label, |sf| {
            let s = &mut sf.systems[i];
            (s.vertex, s.center) = if by_vertex {
                (Some(point.to_array()), None)
            } else {
                (None, Some(point.to_array()))
            };
        })
    }

    /// Applies a lens key edit to system `i` (see
    /// [`crate::edit::apply_system`]); a light edit goes to the light as
    /// usual. A result that does not validate is refused, nothing changed.
    pub fn apply_system_edit(&mut self, i: usize, edit: Edit) -> Result<(String, Change), Rejected> {
        if !edit.is_lens() || i >= self.scene.systems.len() {
            return self.apply_edit(edit);
        }
        let mut next = self.scene.systems[i].clone();
        let what = crate::edit::apply_system(&mut next, edit);
        let msg = format!("{}: {what}", self.item_name(Item::System(i)));
        let change = self.edit(&msg, |sf| sf.systems[i] = next)?;
        Ok((msg, change))
    }

    /// The table of system `i` when its kind is `surfaces`.
    fn surfaces(&self, i: usize) -> Option<&Vec<SurfaceFile>> {
        let s = self.scene.systems.get(i)?;
        if s.kind != "surfaces" {
            return None;
        }
        s.surfaces.as_ref()
    }
}

/// The table of system `i` (present: checked by the caller).
fn table_mut(sf: &mut SceneFile, i: usize) -> &mut Vec<SurfaceFile> {
    sf.systems[i].surfaces.get_or_insert_with(Vec::new)
}

/// The `i`-th lens system of a built scene (they follow the objects and
/// lenses).
pub fn built_system(scene: &Scene, i: usize) -> Option<&LensSystem> {
    scene.objects.iter().filter_map(|o| o.system()).nth(i)
}

/// How wide system `i` is (its largest diameter), when built.
pub(super) fn system_width(scene: &Scene, i: usize) -> Option<f64> {
    built_system(scene, i).map(|s| 2.0 * s.radius())
}

/// The kind of a system as the *Objects* list says it: the preset's name
/// for a preset, else the kind.
pub fn system_kind_label(s: &SystemFile) -> String {
    match (s.kind.as_str(), &s.preset) {
        ("preset", Some(p)) => p.clone(),
        (k, _) => k.to_string(),
    }
}

/// A file index of a built one.
fn index_file(n: Index) -> IndexFile {
    match n {
        Index::Constant(v) => IndexFile::Constant(v),
        Index::Cauchy { a, b } => IndexFile::Cauchy([a, b]),
        Index::Glass(g) => IndexFile::Glass(g),
    }
}

/// A system of `kind` with nothing but its kind set (pose at the origin).
fn empty_system(kind: &str) -> SystemFile {
    SystemFile {
        name: None,
        kind: kind.to_string(),
        vertex: None,
        center: Some([0.0; 3]),
        axis: [0.0, 0.0, 1.0],
        tint: [1.0; 3],
        d: None,
        r: None,
        r1: None,
        r2: None,
        r3: None,
        thickness: None,
        thickness2: None,
        n: None,
        n2: None,
        flat: None,
        surfaces: None,
        prescription: None,
        preset: None,
        scale: None,
    }
}

fn glass_or(name: &str, n: f64) -> IndexFile {
    glass::lookup(name).map_or(IndexFile::Constant(n), IndexFile::Glass)
}

/// A new system of `kind` (one of [`crate::scene::SYSTEM_KINDS`]) centred
/// at `center`, facing `axis`, 2 units across: crown glass (N-BK7) singlets
/// of moderate power, a cemented N-BK7/N-SF5 doublet, a singlet as a
/// table of surfaces, the AC254-100-A achromat as a prescription. `None`
/// for an unknown kind.
pub fn new_system(kind: &str, center: V3, axis: V3) -> Option<SystemFile> {
    let mut s = empty_system(kind);
    s.center = Some(center);
    s.axis = axis;
    let crown = glass_or("N-BK7", 1.5168);
    s.d = Some(NEW_DIAMETER);
    s.n = Some(crown);
    match kind {
        "plano-convex" => (s.r, s.thickness) = (Some(2.5), Some(0.45)),
        "plano-concave" => (s.r, s.thickness) = (Some(2.5), Some(0.15)),
        "biconvex" => (s.r1, s.r2, s.thickness) = (Some(4.0), Some(4.0), Some(0.4)),
        "biconcave" => (s.r1, s.r2, s.thickness) = (Some(4.0), Some(4.0), Some(0.15)),
        "meniscus" => (s.r1, s.r2, s.thickness) = (Some(2.0), Some(4.0), Some(0.4)),
        "doublet" => {
            (s.r1, s.r2, s.r3) = (Some(3.0), Some(-2.5), Some(-10.0));
            (s.thickness, s.thickness2) = (Some(0.5), Some(0.2));
            s.n2 = Some(glass_or("N-SF5", 1.6727));
        }
        "surfaces" | "prescription" | "preset" => {
            (s.d, s.n) = (None, None);
            match kind {
                "surfaces" => s.surfaces = Some(singlet_table()),
                "prescription" => {
                    let name = "achromat-AC254-100-A";
                    s.prescription = prescription::preset(name).map(str::to_string);
                    s.scale = preset_scale(name);
                }
                _ => return new_preset_system(prescription::PRESETS[0].0, center, axis),
            }
        }
        _ => return None,
    }
    Some(s)
}

/// A biconvex N-BK7 singlet as a table: R = ±4, 0.4 thick, 2 across.
fn singlet_table() -> Vec<SurfaceFile> {
    let a = 0.5 * NEW_DIAMETER;
    vec![
        SurfaceFile {
            radius: 4.0,
            thickness: 0.4,
            n: glass_or("N-BK7", 1.5168),
            semi_aperture: a,
            stop: false,
        },
        SurfaceFile {
            radius: -4.0,
            thickness: 0.0,
            n: IndexFile::Constant(1.0),
            semi_aperture: a,
            stop: false,
        },
    ]
}

/// A new system of preset `name` (see [`prescription::PRESETS`]) at
/// `center` facing `axis`, scaled to be 2 units across.
pub fn new_preset_system(name: &str, center: V3, axis: V3) -> Option<SystemFile> {
    let scale = preset_scale(name)?;
    let mut s = empty_system("preset");
    s.center = Some(center);
    s.axis = axis;
    s.preset = Some(name.to_string());
    s.scale = Some(scale);
    Some(s)
}

/// The scale that makes preset (or prescription) `name` 2 units across:
/// its widest clear aperture, rounded to 4 significant digits.
pub fn preset_scale(name: &str) -> Option<f64> {
    let rows = prescription::parse(name, prescription::preset(name)?).ok()?;
    let widest = rows.iter().map(|r| r.aperture_diameter).fold(0.0, f64::max);
    if widest <= 0.0 {
        return None;
    }
    let s = NEW_DIAMETER / widest;
    let digits = 10f64.powi(3 - libm::log10(s).floor() as i32);
    Some((s * digits).round() / digits)
}

#[cfg(test)]
mod tests;
