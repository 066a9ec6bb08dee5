//! Scenes: the file model ([`file`]), its validation into the render model
//! ([`Scene`]), errors that name file, line and field ([`error`]), and
//! reading a file with a size cap ([`read_capped`]).
//!
//! [`Scene::build`] is the only way from a [`SceneFile`] to a [`Scene`]; a
//! file loaded from disk, the embedded default and (later) an edit made in
//! the window all pass through it.

mod camera_lens;
mod change;
pub mod error;
pub mod file;
mod input;
mod stream;
mod systems;
mod validate;

pub use camera_lens::lens_camera_of;
pub use change::Change;
pub use error::{FieldPath, Problem, SceneError, escape_controls};
pub use file::SceneFile;
pub use input::{SCENE_FILE_CAP, check_scene_bytes, read_capped};
pub use systems::KINDS as SYSTEM_KINDS;

use crate::camera::{Camera, LensCamera};
use crate::color::Rgb;
use crate::geometry::{Aabb, Lens, LensSystem, Shape};
use crate::light::Light;
use crate::material::Material;
use crate::math::{renormalize, rotation_from_degrees};
use crate::optics::Index;
use error::Located;
use glam::{DMat3, DVec3};
use validate::Validator;

/// The scene compiled in for `lensview` without a scene argument: the
/// benchmark scene `scenes/cubes.toml`.
pub const DEFAULT_SCENE: &str = include_str!("../../../scenes/cubes.toml");
/// The name under which the embedded scene reports errors.
pub const DEFAULT_SCENE_NAME: &str = "<default scene>";

/// An object: a shape, its material and its placement.
#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    pub name: String,
    pub shape: Shape,
    pub material: Material,
    /// Rotation part of `world_from_object` (its inverse is its transpose,
    /// [`Object::object_from_world`]).
    pub world_from_object: DMat3,
    /// Translation part of `world_from_object` (the object's position).
    pub position: DVec3,
    /// True when the transform is the identity (lenses), so no ray is moved.
    pub identity: bool,
    /// True when there is no rotation: object space is world space shifted.
    pub translation_only: bool,
    pub world_bounds: Aabb,
    /// Characteristic size of the shape (for ray offsets), cached.
    pub scale: f64,
    /// The smallest `r·v` whose Phong lobe `(r·v)^shininess` shading adds:
    /// [`Material::lobe_cos_min`], cached.
    pub lobe_cos_min: f64,
    /// For a rotated shape of flat faces (cuboid, prism, pyramid), the
    /// world normal of each face, exactly what [`Object::world_normal`]
    /// would compute at any point of it: a hit looks its normal up instead
    /// of transforming the point and the normal and normalising. Boxed, and
    /// only when rotated (unrotated, the shape's own normal is a lookup):
    /// inline it would be a fifth of every object.
    face_normals: Option<Box<[DVec3; 6]>>,
}

impl Object {
    pub fn new(name: String, shape: Shape, material: Material, position: DVec3, rotation_deg: DVec3) -> Self {
        let identity = position == DVec3::ZERO && rotation_deg == DVec3::ZERO;
        let translation_only = rotation_deg == DVec3::ZERO;
        let rot = rotation_from_degrees(rotation_deg);
        let world_bounds = shape.bounds().transformed(rot, position);
        let scale = shape.scale();
        let lobe_cos_min = material.lobe_cos_min();
        let mut o = Object {
            name,
            shape,
            material,
            world_from_object: rot,
            position,
            identity,
            translation_only,
            world_bounds,
            scale,
            face_normals: None,
            lobe_cos_min,
        };
        if let Some(faces) = o.shape.flat_faces().filter(|_| !translation_only) {
            // A flat face's normal does not depend on the point: any point
            // (the centre) gives the same bits as the hit point would.
            let mut n = [DVec3::ZERO; 6];
            for (part, n) in n.iter_mut().enumerate().take(faces) {
                *n = o.transformed_normal(o.position, part as u8);
            }
            o.face_normals = Some(Box::new(n));
        }
        o
    }

    /// The inverse rotation, `world_from_object`ᵀ: made when used (a
    /// transpose moves numbers and rounds none), not kept in every object.
    #[inline(always)]
    pub fn object_from_world(&self) -> DMat3 {
        self.world_from_object.transpose()
    }

    /// A ray in object space (the same `t` as in world space: rigid motion).
    #[inline]
    pub fn to_object(&self, ray: &crate::math::Ray) -> crate::math::Ray {
        if self.identity {
            *ray
        } else if self.translation_only {
            crate::math::Ray {
                origin: ray.origin - self.position,
                dir: ray.dir,
            }
        } else {
            crate::math::Ray {
                origin: self.object_from_world() * (ray.origin - self.position),
                dir: self.object_from_world() * ray.dir,
            }
        }
    }

    /// World-space outward normal at the world point `p` of part `part`.
    #[inline]
    pub fn world_normal(&self, p: DVec3, part: u8) -> DVec3 {
        match &self.face_normals {
            Some(n) => n[part as usize],
            None => self.transformed_normal(p, part),
        }
    }

    /// The shape's normal at the object-space image of `p`, in world space.
    #[inline(always)]
    fn transformed_normal(&self, p: DVec3, part: u8) -> DVec3 {
        if self.identity {
            self.shape.normal(p, part)
        } else if self.translation_only {
            self.shape.normal(p - self.position, part)
        } else {
            let po = self.object_from_world() * (p - self.position);
            // A rotated unit normal: unit up to rounding.
            renormalize(self.world_from_object * self.shape.normal(po, part))
        }
    }

    pub fn lens(&self) -> Option<&Lens> {
        match &self.shape {
            Shape::Lens(l) => Some(l),
            _ => None,
        }
    }

    pub fn system(&self) -> Option<&LensSystem> {
        match &self.shape {
            Shape::System(s) => Some(s),
            _ => None,
        }
    }

    /// The refractive index of the object's glass, which has one owner: a
    /// lens's is its own ([`Lens::index`]), a system's first glass is its
    /// surfaces' (each surface's medium: `LensSystem::media`), any other
    /// object's is its material's `ior` (a lens's or system's material
    /// holds none: [`Material::glass_of_shape`]).
    #[inline]
    pub fn ior(&self) -> Index {
        match &self.shape {
            Shape::Lens(l) => l.index,
            Shape::System(s) => s.first_glass(),
            _ => self.material.ior,
        }
    }

    /// Whether the object's glass bends colours apart (its index depends on
    /// the wavelength, at any of a system's surfaces).
    pub fn is_dispersive(&self) -> bool {
        match &self.shape {
            Shape::System(s) => s.is_dispersive(),
            _ => self.ior().is_dispersive(),
        }
    }
}

/// What a scene uses, decided once when it is built, so that rendering
/// leaves out the rest (see `integrator::radiance`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Features {
    /// Shadow rays: shadows on, a light, and more than one object (a convex
    /// object cannot shadow itself where a light faces it).
    pub shadows: bool,
    /// Some material is transparent: the refraction path.
    pub glass: bool,
    /// Some material is a mirror (glass reflects too): the reflection path.
    pub mirror: bool,
    /// Some material has a specular coefficient: the Phong term.
    pub specular: bool,
    /// Some transparent material has a wavelength-dependent index: three
    /// wavelengths a sample instead of one.
    pub dispersion: bool,
    /// Caustics by photon mapping: on by `[render] caustics`, or by default
    /// when glass or a mirror and a light are present. Shadow rays then stop
    /// at glass ([`Scene::shadow_filter`]): light through it arrives as
    /// photons (the map the kernels get beside the scene: `integrator::Lit`).
    pub caustics: bool,
}

impl Features {
    pub const ALL: Features = Features {
        shadows: true,
        glass: true,
        mirror: true,
        specular: true,
        dispersion: true,
        caustics: true,
    };
}

/// Below this many objects a ray tests every object's box: a hierarchy
/// would cost more than it saves.
pub const BVH_MIN_OBJECTS: usize = 8;

/// The validated render model.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// The pose, and the pinhole's field of view (with a lens camera, the
    /// lens's equivalent: [`LensCamera::fov_y_deg`]).
    pub camera: Camera,
    /// A lens system and sensor the camera rays come through (`[camera]
    /// lens`); `None`: the pinhole (also with a `lens` and `pinhole = true`).
    pub lens: Option<std::sync::Arc<LensCamera>>,
    /// Ambient light: colour × intensity.
    pub ambient: Rgb,
    pub lights: Vec<Light>,
    pub objects: Vec<Object>,
    pub background: Rgb,
    pub max_depth: u32,
    pub shadows: bool,
    pub spp: u32,
    /// `[render] caustics` as written (`None`: the default, see
    /// [`Features::caustics`]).
    pub caustics: Option<bool>,
    /// `[display]`: how the picture is shown and written as PNG.
    pub tone: crate::color::Tone,
    /// What the scene uses ([`Scene::compile`]).
    pub features: Features,
    /// A BVH over `objects` when there are at least [`BVH_MIN_OBJECTS`].
    pub bvh: Option<crate::accel::Bvh>,
    /// For each object, a box around every other object, enlarged by a
    /// millionth of its size (`None`: no other object): a ray that cannot
    /// meet object `i` and misses box `i` meets nothing ([`Scene::compile`]).
    pub others_bounds: Vec<Option<Aabb>>,
}

/// [`Scene::others_bounds`]: unions of the objects' world boxes before and
/// after each one, enlarged so that rounding in a box test can never make a
/// ray that meets an object miss the box.
fn others_bounds(objects: &[Object]) -> Vec<Option<Aabb>> {
    let join = |a: Option<Aabb>, b: Option<Aabb>| match (a, b) {
        (Some(a), Some(b)) => Some(a.union(&b)),
        (a, b) => a.or(b),
    };
    // First the union of the boxes before each object, then, from the end,
    // joined with the union after it (one vector: no copy of the first).
    let mut out = Vec::with_capacity(objects.len());
    let mut acc = None;
    for o in objects {
        out.push(acc);
        acc = join(acc, Some(o.world_bounds));
    }
    let mut after = None;
    for (i, o) in objects.iter().enumerate().rev() {
        out[i] = join(out[i], after).map(|b| {
            let pad = (b.max - b.min).max_element() * 1e-6 + (b.min.abs().max(b.max.abs())).max_element() * 1e-12;
            Aabb::new(b.min - pad, b.max + pad)
        });
        after = join(after, Some(o.world_bounds));
    }
    out
}

impl Scene {
    /// Decides [`Features`] and builds the BVH; call again after changing
    /// `objects`, `lights` or `shadows` directly.
    pub fn compile(&mut self) {
        let mats = || self.objects.iter().map(|o| &o.material);
        let glass = mats().any(|m| m.transparency > 0.0);
        let glass_or_mirror = glass || mats().any(|m| m.reflectivity > 0.0);
        self.features = Features {
            shadows: self.shadows && !self.lights.is_empty() && self.objects.len() > 1,
            glass,
            mirror: glass || mats().any(|m| m.reflectivity > 0.0),
            specular: mats().any(|m| m.specular > 0.0),
            dispersion: self
                .objects
                .iter()
                .any(|o| o.material.transparency > 0.0 && o.is_dispersive()),
            caustics: self.caustics.unwrap_or(true) && glass_or_mirror && !self.lights.is_empty(),
        };
        self.bvh = (self.objects.len() >= BVH_MIN_OBJECTS).then(|| {
            let bounds: Vec<Aabb> = self.objects.iter().map(|o| o.world_bounds).collect();
            crate::accel::Bvh::build(&bounds)
        });
        self.others_bounds = others_bounds(&self.objects);
    }

    /// The embedded default scene.
    pub fn default_scene() -> (SceneFile, Scene) {
        Self::parse(DEFAULT_SCENE_NAME, DEFAULT_SCENE).expect("embedded default scene is valid") // ok: a test fixture (tests/scenes.rs)
    }

    /// Parses and validates scene text; `file` names it in errors.
    ///
    /// A valid scene is read without a tree of the whole document (its
    /// objects one at a time, [`stream`]). Only a refusal makes the
    /// span-keeping `toml_edit` parse that [`Located`] needs (about 4 KB an
    /// object), and of a text in which every object that cannot be at fault
    /// is replaced by a short stub in the same place, so that a refusal of
    /// a large file costs little more than loading it; the refusal is
    /// decided as before: a non-finite number first, then the parse error,
    /// then the first validation problem, each at its line.
    pub fn parse(file: &str, text: &str) -> Result<(SceneFile, Scene), SceneError> {
        let read = match stream::scene_file(text) {
            stream::Read::Scene(sf) => Some(sf),
            stream::Read::Invalid => None,
            stream::Read::OtherForm => stream::whole_document(text),
        };
        let Some(sf) = read else {
            return Self::refusal(file, text, true);
        };
        match Scene::build(&sf) {
            Ok(scene) => Ok((sf, scene)),
            Err(problems) => {
                // Every object but the one at fault (if any) as a stub.
                let at = problems[0].path.object_index();
                let stubbed = stream::stubbed(text, stream::Stub::Place, &mut |i, _| Some(i) != at);
                Err(Located::new(file, stubbed.as_deref().unwrap_or(text)).error(&problems[0]))
            }
        }
    }

    /// Why `text`, which does not read as a scene file, is refused: the
    /// first non-finite number, else the parse error, else the first
    /// validation problem. With `stub`, found in the text with each object
    /// that parses on its own as a stub (the same error, at the same
    /// place: tests/fuzz_corpus.rs compares both on every input).
    #[doc(hidden)]
    pub fn refusal(file: &str, text: &str, stub: bool) -> Result<(SceneFile, Scene), SceneError> {
        // The error is decided on the text with readable stubs, and placed
        // in the one with the cheapest (the same objects replaced).
        let stubs = |kind| stub.then(|| stream::stubbed(text, kind, &mut |_, piece| stream::parses(piece)));
        let (decided, placed) = (
            stubs(stream::Stub::Object).flatten(),
            stubs(stream::Stub::Place).flatten(),
        );
        let stubbed = decided.is_some() && placed.is_some();
        let (decided, placed) = match (&decided, &placed) {
            (Some(d), Some(p)) => (d.as_str(), p.as_str()),
            _ => (text, text),
        };
        let located = Located::new(file, placed);
        if let Some(p) = located.non_finite().first() {
            return Err(located.error(p));
        }
        let sf: SceneFile = match toml::from_str(decided) {
            Ok(sf) => sf,
            Err(e) => {
                return Err(located.error_at(e.span().unwrap_or(0..0), e.message()));
            }
        };
        match Scene::build(&sf) {
            // Not reached with stubs (the fault is outside them); else the
            // scene as the whole-document parse reads it.
            Ok(_) if stubbed => Self::refusal(file, text, false),
            Ok(scene) => Ok((sf, scene)),
            Err(problems) => Err(located.error(&problems[0])),
        }
    }

    /// Validates the file model and precomputes the render model. Returns
    /// every problem found, each with its field path.
    pub fn build(sf: &SceneFile) -> Result<Scene, Vec<Problem>> {
        let mut v = Validator::default();
        let (background, max_depth, shadows, spp) = v.render_settings(sf);
        let caustics = sf.render.caustics;
        let tone = v.display(sf);
        let camera = v.camera(sf);
        let lens = v.lens_camera(sf).map(std::sync::Arc::new);
        let camera = match &lens {
            Some(l) => Camera::new(camera.position, camera.rotation_deg, l.fov_y_deg()),
            None => camera,
        };
        // `pinhole = true`: the lens checked and its field of view kept,
        // the picture the pinhole's.
        let lens = lens.filter(|_| sf.camera.pinhole != Some(true));
        let ambient = v.ambient(sf);
        let lights = v.lights(sf);
        let mut objects = v.objects(sf);
        objects.extend(v.lenses(sf));
        objects.extend(v.systems(sf));
        v.camera_off_surfaces(sf, camera.position, &objects);
        // Pushed one by one, the vector may have room for nearly as many
        // again (760 bytes each): give it back (tests/memory.rs).
        objects.shrink_to_fit();
        if !v.problems.is_empty() {
            return Err(v.problems);
        }
        let mut scene = Scene {
            camera,
            lens,
            ambient,
            lights,
            objects,
            background,
            max_depth,
            shadows,
            spp,
            caustics,
            tone,
            features: Features::ALL,
            bvh: None,
            others_bounds: Vec::new(),
        };
        scene.compile();
        Ok(scene)
    }

    /// What a shadow ray keeps crossing object `i`: its material's
    /// [`Material::shadow_transmittance`] at its index ([`Object::ior`]), or
    /// nothing with caustics on (the light through glass arrives as photons
    /// instead, not twice).
    #[inline]
    pub fn shadow_filter(&self, i: usize) -> Rgb {
        if self.features.caustics {
            Rgb::ZERO
        } else {
            let o = &self.objects[i];
            o.material.shadow_transmittance(o.ior().nominal())
        }
    }

    pub fn has_transparency(&self) -> bool {
        self.objects.iter().any(|o| o.material.is_transparent())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Cuboid, Prism, Pyramid, Sphere};
    use crate::optics::Index;

    /// A valid scene skips the span-keeping parse only when every float is
    /// finite, however deeply it is nested; anything else takes the careful
    /// path, which refuses it with its line.
    #[test]
    fn only_finite_floats_skip_the_careful_path() {
        let finite = |t: &str| stream::all_finite(toml::de::DeTable::parse(t).unwrap().get_ref());
        assert!(finite("a = 1.5\nb = [1, 2.0e300, { c = -0.0 }]\n[t]\nd = 1_000.5"));
        for t in [
            "a = inf",
            "a = -nan",
            "a = [1, [2, +inf]]",
            "a = { b = { c = nan } }",
            "[t]\nd = 1e400",
        ] {
            assert!(!finite(t), "{t}");
        }
    }

    /// The face normals looked up for flat shapes are, bit for bit, the
    /// normal transformed from object space at points on each face, for
    /// rotated and shifted cuboids, prisms and pyramids.
    #[test]
    fn face_normals_are_the_transformed_normals() {
        let shapes = [
            Shape::Cuboid(Cuboid::new(DVec3::new(1.0, 2.5, 0.7))),
            Shape::Prism(Prism::new(1.3, 2.0)),
            Shape::Pyramid(Pyramid::new(1.7, 0.9)),
        ];
        let placements = [
            (DVec3::ZERO, DVec3::ZERO),
            (DVec3::new(3.0, -1.0, 2.0), DVec3::ZERO),
            (DVec3::new(-4.0, 0.5, 7.0), DVec3::new(17.0, -33.0, 71.5)),
        ];
        for shape in &shapes {
            let faces = shape.flat_faces().expect("flat shape");
            for &(pos, rot) in &placements {
                let glass = Material::glass(Rgb::ONE, Index::Constant(1.5));
                let o = Object::new("o".into(), shape.clone(), glass, pos, rot);
                assert_eq!(o.face_normals.is_some(), rot != DVec3::ZERO);
                for part in 0..faces as u8 {
                    for p in [pos, pos + DVec3::new(0.3, -0.2, 0.1), DVec3::new(100.0, 3.0, -50.0)] {
                        assert_eq!(o.world_normal(p, part), o.transformed_normal(p, part), "part {part}");
                    }
                    assert!((o.world_normal(pos, part).length() - 1.0).abs() < 1e-15);
                }
            }
        }
        let sphere = Object::new(
            "s".into(),
            Shape::Sphere(Sphere::new(2.0)),
            Material::glass(Rgb::ONE, Index::Constant(1.5)),
            DVec3::X,
            DVec3::ZERO,
        );
        assert!(sphere.face_normals.is_none());
    }
}
