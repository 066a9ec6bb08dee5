//! The *Objects* list of a [`Document`]: primitives, lenses and lens
//! systems, their
//! displayed names, and adding, deleting and duplicating them; the default
//! new items of the *Add* form.

use super::{Change, Document, Item, Rejected};
use crate::scene::Scene;
use crate::scene::file::{IndexFile, LensFile, MaterialFile, ObjectFile, ShapeKind, SystemFile, V3};

/// Where the *Add* form puts a new item.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Placement {
    /// This far in front of the camera, so it is seen at once.
    InFrontOfCamera(f64),
    /// At this point.
    At(V3),
}

/// How far in front of the camera the *Add* form puts a new item unless
/// told otherwise.
pub const NEW_DISTANCE: f64 = 6.0;

/// The *Add* form's colour of a new primitive.
pub const NEW_COLOUR: V3 = [0.8, 0.25, 0.15];

/// What the *Add* form adds ([`Document::add_new`]).
#[derive(Clone, Debug, PartialEq)]
pub enum NewItem {
    /// A primitive and the colour of its own new material.
    Primitive(ObjectFile, V3),
    Lens(LensFile),
    /// Boxed: a system's record is several times a lens's.
    System(Box<SystemFile>),
}

impl NewItem {
    /// The *Add* form's item named `what` at `position`, of the form's
    /// default sizes ([`new_object`], [`new_lens`], [`new_system`]): a
    /// primitive's kind (of [`NEW_COLOUR`]), `lens`, a system kind, or
    /// `preset` (the system preset `preset`). `None`: no such kind or
    /// preset.
    pub fn of(what: &str, preset: &str, position: V3) -> Option<NewItem> {
        let shapes = [
            ShapeKind::Cuboid,
            ShapeKind::Prism,
            ShapeKind::Sphere,
            ShapeKind::Pyramid,
        ];
        if let Some(kind) = shapes.into_iter().find(|k| k.name() == what) {
            return Some(NewItem::Primitive(new_object(kind, position), NEW_COLOUR));
        }
        let axis = [0.0, 0.0, 1.0];
        match what {
            "lens" => Some(NewItem::Lens(new_lens(position, axis))),
            "preset" => super::new_preset_system(preset, position, axis).map(|s| NewItem::System(Box::new(s))),
            _ => super::new_system(what, position, axis).map(|s| NewItem::System(Box::new(s))),
        }
    }
}

impl Document {
    /// Adds the *Add* form's item: a primitive named after its kind with a
    /// material of its own ([`Document::add_primitive`]), a lens or a
    /// system turned to face the camera. Returns the new item.
    pub fn add_new(&mut self, new: NewItem) -> Result<Item, Rejected> {
        match new {
            NewItem::Primitive(o, colour) => self.add_primitive(o, colour),
            NewItem::Lens(l) => self.add_lens_facing_camera(l),
            NewItem::System(s) => self.add_system_facing_camera(*s),
        }
    }

    /// The items of the *Objects* list: primitives, then lenses, then lens
    /// systems, with the names the renderer uses.
    pub fn items(&self) -> Vec<(Item, String)> {
        let mut v: Vec<(Item, String)> = (0..self.scene.objects.len())
            .map(|i| (Item::Object(i), self.item_name(Item::Object(i))))
            .collect();
        v.extend((0..self.scene.lenses.len()).map(|i| (Item::Lens(i), self.item_name(Item::Lens(i)))));
        v.extend((0..self.scene.systems.len()).map(|i| (Item::System(i), self.item_name(Item::System(i)))));
        v
    }

    /// The item built object `o` (an index into [`Self::built`]'s objects)
    /// comes from: the scene builds primitives, then lenses, then systems,
    /// one object each.
    pub fn item_of_object(&self, o: usize) -> Option<Item> {
        let (n, l, s) = (
            self.scene.objects.len(),
            self.scene.lenses.len(),
            self.scene.systems.len(),
        );
        debug_assert_eq!(self.built().objects.len(), n + l + s);
        match o {
            _ if o < n => Some(Item::Object(o)),
            _ if o < n + l => Some(Item::Lens(o - n)),
            _ if o < n + l + s => Some(Item::System(o - n - l)),
            _ => None,
        }
    }

    /// The built object of `item` (the inverse of [`Self::item_of_object`]).
    pub fn object_of_item(&self, item: Item) -> usize {
        let (n, l) = (self.scene.objects.len(), self.scene.lenses.len());
        match item {
            Item::Object(i) => i,
            Item::Lens(i) => n + i,
            Item::System(i) => n + l + i,
        }
    }

    /// Moves `item` by `by` (world units), one undo step per drag (merged
    /// until [`Self::seal`]): a primitive's position, a lens's centre, a
    /// system's vertex or centre (whichever places it).
    pub fn move_item(&mut self, item: Item, by: glam::DVec3) -> Result<Change, Rejected> {
        let shift = |p: &mut V3| *p = (glam::DVec3::from(*p) + by).to_array();
        let name = self.item_name(item);
        self.edit_merged(&format!("drag {name}"), &format!("move {name}"), |sf| match item {
            Item::Object(i) => sf.objects.get_mut(i).into_iter().for_each(|o| shift(&mut o.position)),
            Item::Lens(i) => sf.lenses.get_mut(i).into_iter().for_each(|l| shift(&mut l.center)),
            Item::System(i) => {
                if let Some(s) = sf.systems.get_mut(i) {
                    s.vertex.iter_mut().chain(s.center.iter_mut()).for_each(shift);
                }
            }
        })
    }

    /// Moves point light `k` by `by`, one undo step per drag.
    pub fn move_light(&mut self, k: usize, by: glam::DVec3) -> Result<Change, Rejected> {
        self.edit_merged(&format!("drag light {k}"), &format!("move light {}", k + 1), |sf| {
            if let Some(p) = sf.lights.get_mut(k).and_then(|l| l.position.as_mut()) {
                *p = (glam::DVec3::from(*p) + by).to_array();
            }
        })
    }

    /// The displayed name of an item (its `name`, or the default the
    /// renderer gives it).
    pub fn item_name(&self, item: Item) -> String {
        match item {
            Item::Object(i) => self.scene.objects.get(i).map_or_else(String::new, |o| {
                o.name.clone().unwrap_or_else(|| format!("{} {}", o.kind.name(), i + 1))
            }),
            Item::Lens(i) => self.scene.lenses.get(i).map_or_else(String::new, |l| {
                l.name.clone().unwrap_or_else(|| format!("lens {}", i + 1))
            }),
            Item::System(i) => self.scene.systems.get(i).map_or_else(String::new, |s| {
                s.name.clone().unwrap_or_else(|| format!("system {}", i + 1))
            }),
        }
    }

    pub fn contains(&self, item: Item) -> bool {
        match item {
            Item::Object(i) => i < self.scene.objects.len(),
            Item::Lens(i) => i < self.scene.lenses.len(),
            Item::System(i) => i < self.scene.systems.len(),
        }
    }

    /// Adds a primitive, with a new material of its own when `material` is
    /// given (its name made unique). Returns the new item.
    pub fn add_object(
        &mut self,
        mut object: ObjectFile,
        material: Option<(String, MaterialFile)>,
    ) -> Result<Item, Rejected> {
        if object.name.is_none() {
            object.name = Some(self.unique_name(object.kind.name()));
        }
        let label = format!("add {}", object.kind.name());
        let index = self.scene.objects.len();
        self.edit(&label, |sf| {
            if let Some((name, m)) = material {
                let name = unique_key(&sf.materials, &name);
                sf.materials.insert(name.clone(), m);
                object.material = Some(name);
            }
            sf.objects.push(object);
        })?;
        Ok(Item::Object(index))
    }

    /// Where `at` is: a point in front of the camera, or `at` itself.
    pub fn place(&self, at: Placement) -> V3 {
        match at {
            Placement::InFrontOfCamera(distance) => in_front_of_camera(&self.built, distance),
            Placement::At(p) => p,
        }
    }

    /// The *Add* form's primitive: `object` (its position and sizes set)
    /// named after its kind, with a new plain material of `colour` of the
    /// same name. Returns the new item.
    pub fn add_primitive(&mut self, mut object: ObjectFile, colour: V3) -> Result<Item, Rejected> {
        let name = self.unique_name(object.kind.name());
        object.name = Some(name.clone());
        self.add_object(object, Some((name, new_material(colour))))
    }

    /// The *Add* form's lens: `lens` (its centre and shape set) turned to
    /// face the camera, S1 toward it. Returns the new item.
    pub fn add_lens_facing_camera(&mut self, mut lens: LensFile) -> Result<Item, Rejected> {
        lens.axis = (-self.built.camera.forward()).to_array();
        self.add_lens(lens)
    }

    /// Adds a lens; returns the new item.
    pub fn add_lens(&mut self, mut lens: LensFile) -> Result<Item, Rejected> {
        if lens.name.is_none() {
            lens.name = Some(self.unique_name("lens"));
        }
        let index = self.scene.lenses.len();
        self.edit("add lens", |sf| sf.lenses.push(lens))?;
        Ok(Item::Lens(index))
    }

    /// Deletes an item (its material stays in `[materials]`).
    pub fn delete(&mut self, item: Item) -> Result<Change, Rejected> {
        if !self.contains(item) {
            return Ok(Change::None);
        }
        let label = format!("delete {}", self.item_name(item));
        self.edit(&label, |sf| match item {
            Item::Object(i) => {
                sf.objects.remove(i);
            }
            Item::Lens(i) => {
                sf.lenses.remove(i);
            }
            Item::System(i) => {
                sf.systems.remove(i);
            }
        })
    }

    /// Duplicates an item beside the original (moved along +x by its width
    /// and a little more, so the copy is seen); returns the copy.
    pub fn duplicate(&mut self, item: Item) -> Result<Option<Item>, Rejected> {
        if !self.contains(item) {
            return Ok(None);
        }
        let base = self.item_name(item);
        let name = self.unique_name(&format!("{base} copy"));
        let label = format!("duplicate {base}");
        match item {
            Item::Object(i) => {
                let mut o = self.scene.objects[i].clone();
                o.name = Some(name);
                o.position[0] += object_width(&o) + 0.25;
                let at = self.scene.objects.len();
                self.edit(&label, |sf| sf.objects.push(o))?;
                Ok(Some(Item::Object(at)))
            }
            Item::Lens(i) => {
                let mut l = self.scene.lenses[i].clone();
                l.name = Some(name);
                l.center[0] += l.d + 0.25;
                let at = self.scene.lenses.len();
                self.edit(&label, |sf| sf.lenses.push(l))?;
                Ok(Some(Item::Lens(at)))
            }
            Item::System(i) => {
                let mut s = self.scene.systems[i].clone();
                s.name = Some(name);
                let width = super::systems::system_width(&self.built, i).unwrap_or(2.0);
                for p in [&mut s.vertex, &mut s.center].into_iter().flatten() {
                    p[0] += width + 0.25;
                }
                let at = self.scene.systems.len();
                self.edit(&label, |sf| sf.systems.push(s))?;
                Ok(Some(Item::System(at)))
            }
        }
    }

    /// A name no item has yet: `base`, or `base 2`, `base 3`, …
    pub fn unique_name(&self, base: &str) -> String {
        let taken: Vec<String> = self.items().into_iter().map(|(_, n)| n).collect();
        free_name(base, |n| taken.iter().any(|t| t == n))
    }
}

/// The first of `base`, `base 2`, `base 3`, … that `taken` refuses.
pub fn free_name(base: &str, taken: impl Fn(&str) -> bool) -> String {
    (1..)
        .map(|k| {
            if k == 1 {
                base.to_string()
            } else {
                format!("{base} {k}")
            }
        })
        .find(|n| !taken(n))
        .unwrap_or_else(|| base.to_string()) // ok: the range is endless
}

/// A key not yet in `map`: see [`free_name`].
pub fn unique_key<V>(map: &std::collections::BTreeMap<String, V>, base: &str) -> String {
    free_name(base, |n| map.contains_key(n))
}

fn object_width(o: &ObjectFile) -> f64 {
    match o.kind {
        ShapeKind::Cuboid => o.size.map_or(1.0, |s| s[0]),
        ShapeKind::Sphere => 2.0 * o.radius.unwrap_or(0.5),
        ShapeKind::Prism | ShapeKind::Pyramid => o.side.unwrap_or(1.0),
    }
}

/// A new primitive of `kind` at `position` with the default sizes of the
/// *Add* form: a unit cube, a sphere of radius 0.5, prism and pyramid of
/// side 1 and height 1.
pub fn new_object(kind: ShapeKind, position: V3) -> ObjectFile {
    let mut o = ObjectFile {
        kind,
        name: None,
        position,
        rotation: [0.0; 3],
        size: None,
        radius: None,
        side: None,
        height: None,
        material: None,
    };
    match kind {
        ShapeKind::Cuboid => o.size = Some([1.0; 3]),
        ShapeKind::Sphere => o.radius = Some(0.5),
        ShapeKind::Prism | ShapeKind::Pyramid => {
            o.side = Some(1.0);
            o.height = Some(1.0);
        }
    }
    o
}

/// A new lens at `center` facing `axis`: d = 2, r1 = r2 = 5, n = 1.5 (the
/// cubes scene's lens).
pub fn new_lens(center: V3, axis: V3) -> LensFile {
    LensFile {
        name: None,
        center,
        axis,
        d: 2.0,
        r1: 5.0,
        r2: 5.0,
        n: IndexFile::Constant(1.5),
        tint: [1.0; 3],
    }
}

/// A plain coloured material for a new object.
pub fn new_material(color: V3) -> MaterialFile {
    MaterialFile {
        color,
        specular: 0.3,
        ..MaterialFile::default()
    }
}

/// A point `distance` in front of the camera: where the *Add* form puts new
/// things so they are seen at once.
pub fn in_front_of_camera(scene: &Scene, distance: f64) -> V3 {
    (scene.camera.position + scene.camera.forward() * distance).to_array()
}
