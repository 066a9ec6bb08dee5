//! Validation of the file model: each part of a scene file checked and
//! turned into its render-model value, every problem recorded with its field
//! path so that one pass reports them all.

use super::Object;
use super::error::{FieldPath, Problem};
use super::file::{IndexFile, LightKind, MaterialFile, ObjectFile, SceneFile, ShapeKind, V3};
use crate::camera::Camera;
use crate::color::{Rgb, Tone};
use crate::geometry::{Cuboid, Lens, Prism, Pyramid, Shape, Sphere};
use crate::light::Light;
use crate::material::Material;
use crate::math::{angles_looking_along, domain, max_abs, rescale_pow2, surface_offset};
use crate::optics::Index;
use glam::DVec3;

#[derive(Default)]
pub(super) struct Validator {
    pub(super) problems: Vec<Problem>,
}

impl Validator {
    /// `[render]`: background, max_depth, shadows, spp.
    pub(super) fn render_settings(&mut self, sf: &SceneFile) -> (Rgb, u32, bool, u32) {
        let r = &sf.render;
        let background = self.colour(&FieldPath::root("render").key("background"), r.background);
        if r.max_depth > 64 {
            self.problem(
                FieldPath::root("render").key("max_depth"),
                format!("{} is more than 64", r.max_depth),
            );
        }
        if r.spp == 0 || r.spp > crate::limits::MAX_SPP {
            self.problem(
                FieldPath::root("render").key("spp"),
                format!("{} is not in 1..={}", r.spp, crate::limits::MAX_SPP),
            );
        }
        (background, r.max_depth, r.shadows, r.spp)
    }

    /// `[display]`: the exposure (finite, within ±[`Tone::MAX_STOPS`]) and
    /// the tone curve.
    pub(super) fn display(&mut self, sf: &SceneFile) -> Tone {
        let d = &sf.display;
        if !Tone::accepts(d.exposure) {
            self.problem(
                FieldPath::root("display").key("exposure"),
                format!("{} stops is not in -{m}..={m}", d.exposure, m = Tone::MAX_STOPS),
            );
        }
        Tone {
            exposure: d.exposure,
            curve: d.tone,
        }
    }

    /// `[ambient]`: its colour times its intensity.
    pub(super) fn ambient(&mut self, sf: &SceneFile) -> Rgb {
        let ap = FieldPath::root("ambient");
        self.colour(&ap.key("color"), sf.ambient.color)
            * self.bounded(&ap.key("intensity"), sf.ambient.intensity, domain::MAX_INTENSITY)
    }

    /// `[camera]`, with `rotation` or `look_at`.
    pub(super) fn camera(&mut self, sf: &SceneFile) -> Camera {
        let cp = FieldPath::root("camera");
        let c = &sf.camera;
        let position = self.vec(&cp.key("position"), c.position);
        if !(c.fov > 0.0 && c.fov < 180.0) {
            self.problem(
                cp.key("fov"),
                format!("field of view {} must be in (0, 180) degrees", c.fov),
            );
        }
        let rotation = match (c.rotation, c.look_at) {
            (Some(_), Some(_)) => {
                self.problem(cp.key("look_at"), "give either rotation or look_at, not both");
                DVec3::ZERO
            }
            (Some(r), None) => self.vec(&cp.key("rotation"), r),
            (None, Some(t)) => {
                let dir = self.vec(&cp.key("look_at"), t) - position;
                if dir.length() > 0.0 {
                    angles_looking_along(dir)
                } else {
                    self.problem(cp.key("look_at"), "look_at equals the camera position");
                    DVec3::ZERO
                }
            }
            (None, None) => DVec3::ZERO,
        };
        Camera::new(position, rotation, c.fov)
    }

    /// `[[lights]]`: point and directional.
    pub(super) fn lights(&mut self, sf: &SceneFile) -> Vec<Light> {
        let mut lights = Vec::new();
        for (i, l) in sf.lights.iter().enumerate() {
            let p = FieldPath::root("lights").index(i);
            let color = self.colour(&p.key("color"), l.color);
            let intensity = self.bounded(&p.key("intensity"), l.intensity, domain::MAX_INTENSITY);
            match l.kind {
                LightKind::Point => {
                    if l.direction.is_some() {
                        self.problem(p.key("direction"), "a point light has a position, not a direction");
                    }
                    match l.position {
                        Some(pos) => lights.push(Light::Point {
                            position: self.vec(&p.key("position"), pos),
                            color,
                            intensity,
                        }),
                        None => self.problem(p.clone(), "a point light needs `position`"),
                    }
                }
                LightKind::Directional => {
                    if l.position.is_some() {
                        self.problem(p.key("position"), "a directional light has a direction, not a position");
                    }
                    // Scaled first: [1e200, 0, 1e201] squares to ∞.
                    match l.direction.map(|d| rescale_pow2(DVec3::from(d))) {
                        Some(d) if d.length() > 0.0 => lights.push(Light::Directional {
                            direction: d.normalize(),
                            color,
                            intensity,
                        }),
                        Some(_) => self.problem(p.key("direction"), "direction must not be zero"),
                        None => self.problem(p.clone(), "a directional light needs `direction`"),
                    }
                }
            }
        }
        lights
    }

    /// `[[objects]]` with their materials.
    pub(super) fn objects(&mut self, sf: &SceneFile) -> Vec<Object> {
        // The lenses are added after them (tests/memory.rs: no regrowth).
        let mut objects = Vec::with_capacity(sf.objects.len() + sf.lenses.len());
        for (i, o) in sf.objects.iter().enumerate() {
            let p = FieldPath::root("objects").index(i);
            let material = match &o.material {
                None => self.material(&FieldPath::root("materials"), &MaterialFile::default()),
                Some(name) => match sf.materials.get(name) {
                    Some(m) => self.material(&FieldPath::root("materials").key(name), m),
                    None => {
                        self.problem(p.key("material"), format!("no material named `{name}` in [materials]"));
                        self.material(&FieldPath::root("materials"), &MaterialFile::default())
                    }
                },
            };
            // Unnamed, no name is kept (an allocation an object); messages
            // call it by its kind and number ([`label`]).
            let name = o.name.clone().unwrap_or_default();
            if let Some(shape) = self.shape(&p, o) {
                objects.push(Object::new(
                    name,
                    shape,
                    material,
                    DVec3::from(o.position),
                    DVec3::from(o.rotation),
                ));
            }
        }
        // Every material, used or not: one the file defines is one the
        // panel offers (each reports its problems once).
        for (name, m) in &sf.materials {
            self.material(&FieldPath::root("materials").key(name), m);
        }
        objects
    }

    /// `[[lenses]]`, as glass objects.
    pub(super) fn lenses(&mut self, sf: &SceneFile) -> Vec<Object> {
        let mut objects = Vec::new();
        for (i, l) in sf.lenses.iter().enumerate() {
            let p = FieldPath::root("lenses").index(i);
            let tint = self.colour(&p.key("tint"), l.tint);
            let index = self.index(&p.key("n"), l.n);
            match Lens::new(DVec3::from(l.center), DVec3::from(l.axis), l.d, l.r1, l.r2, index) {
                Ok(lens) => {
                    let name = l.name.clone().unwrap_or_default();
                    objects.push(Object::new(
                        name,
                        Shape::Lens(Box::new(lens)),
                        Material::glass_of_shape(tint),
                        DVec3::ZERO,
                        DVec3::ZERO,
                    ));
                }
                Err(e) => {
                    self.problem(p.key(e.field()), e.to_string());
                }
            }
        }
        objects
    }

    /// The camera must not lie on a surface: every camera ray would start
    /// on the solid, where its roots near 0 are rounding noise (speckled
    /// false hits). "On" is within 4 ray offsets ([`surface_offset`]): the
    /// solid's inside changes under a nudge that small along an axis.
    pub(super) fn camera_off_surfaces(&mut self, sf: &SceneFile, camera: DVec3, objects: &[Object]) {
        for (i, o) in objects.iter().enumerate() {
            let delta = 4.0 * surface_offset(camera, o.scale);
            let b = &o.world_bounds;
            if (camera - b.min).min_element() < -delta || (b.max - camera).min_element() < -delta {
                continue;
            }
            let at = o.object_from_world() * (camera - o.position);
            let inside = o.shape.contains(at);
            let nudged = |k: usize, s: f64| {
                let mut e = DVec3::ZERO;
                e[k] = s * delta;
                o.shape.contains(at + e) != inside
            };
            if (0..3).any(|k| nudged(k, -1.0) || nudged(k, 1.0)) {
                self.problem(
                    FieldPath::root("camera").key("position"),
                    format!(
                        "lies on the surface of `{}` (within {delta:.1e}): camera rays would start on it; move the camera off",
                        label(sf, i)
                    ),
                );
                return;
            }
        }
    }

    pub(super) fn problem(&mut self, path: FieldPath, msg: impl Into<String>) {
        self.problems.push(Problem::new(path, msg));
    }

    fn vec(&mut self, path: &FieldPath, v: V3) -> DVec3 {
        for (i, x) in v.iter().enumerate() {
            if !x.is_finite() {
                self.problem(path.index(i), format!("{x} is not a finite number"));
            } else if let Some(why) = domain::coordinate(*x) {
                self.problem(path.index(i), why);
            }
        }
        DVec3::from(v)
    }

    pub(super) fn colour(&mut self, path: &FieldPath, v: V3) -> Rgb {
        for (i, x) in v.iter().enumerate() {
            if !(x.is_finite() && *x >= 0.0) {
                self.problem(
                    path.index(i),
                    format!("colour component {x} must be a finite number ≥ 0"),
                );
            } else if *x > domain::MAX_COLOUR {
                self.problem(
                    path.index(i),
                    format!("colour component {x:e} is above the supported {:e}", domain::MAX_COLOUR),
                );
            }
        }
        DVec3::from(v)
    }

    fn non_negative(&mut self, path: &FieldPath, x: f64) -> f64 {
        if !(x.is_finite() && x >= 0.0) {
            self.problem(path.clone(), format!("{x} must be a finite number ≥ 0"));
        }
        x
    }

    /// A number in `[0, max]` (the supported domain, [`domain`]).
    fn bounded(&mut self, path: &FieldPath, x: f64, max: f64) -> f64 {
        let x = self.non_negative(path, x);
        if x > max {
            self.problem(path.clone(), format!("{x:e} is above the supported {max:e}"));
        }
        x
    }

    fn unit(&mut self, path: &FieldPath, x: f64) -> f64 {
        if !(0.0..=1.0).contains(&x) {
            self.problem(path.clone(), format!("{x} must lie in [0, 1]"));
        }
        x
    }

    /// A length of an object whose position is `at` (the domain, [`domain::length`]).
    fn length(&mut self, path: FieldPath, x: f64, at: DVec3) {
        if let Some(why) = domain::length(x, max_abs(at)) {
            self.problem(path, why);
        }
    }

    fn positive(&mut self, path: &FieldPath, x: Option<f64>, kind: &str, key: &str, at: DVec3) -> f64 {
        match x {
            None => {
                self.problem(path.clone(), format!("a {kind} needs `{key}`"));
                1.0
            }
            Some(x) if !(x > 0.0 && x.is_finite()) => {
                self.problem(path.key(key), format!("size {x} must be positive"));
                1.0
            }
            Some(x) => {
                self.length(path.key(key), x, at);
                x
            }
        }
    }

    pub(super) fn index(&mut self, path: &FieldPath, n: IndexFile) -> Index {
        match n {
            IndexFile::Constant(n) => {
                if !(n >= 1.0) {
                    self.problem(path.clone(), format!("refractive index {n} must be ≥ 1"));
                } else if let Some(why) = domain::index(n) {
                    self.problem(path.clone(), why);
                }
                Index::Constant(n)
            }
            IndexFile::Cauchy([a, b]) => {
                let idx = Index::Cauchy { a, b };
                if !(idx.at(0.38) >= 1.0 && idx.at(0.78) >= 1.0) {
                    self.problem(
                        path.key("cauchy"),
                        format!("Cauchy index A + B/λ² = {a} + {b}/λ² falls below 1 in the visible range"),
                    );
                } else if let Some(why) = domain::index(idx.at(0.38)).or(domain::index(idx.at(0.78))) {
                    self.problem(
                        path.key("cauchy"),
                        format!("Cauchy index A + B/λ² = {a} + {b}/λ²: {why}"),
                    );
                }
                idx
            }
            // A catalogue glass is physical everywhere in the visible.
            IndexFile::Glass(g) => Index::Glass(g),
        }
    }

    fn material(&mut self, path: &FieldPath, m: &MaterialFile) -> Material {
        let before = self.problems.len();
        let color = self.colour(&path.key("color"), m.color);
        let ambient = self.bounded(&path.key("ambient"), m.ambient, domain::MAX_COEFFICIENT);
        let diffuse = self.bounded(&path.key("diffuse"), m.diffuse, domain::MAX_COEFFICIENT);
        let specular = self.bounded(&path.key("specular"), m.specular, domain::MAX_COEFFICIENT);
        let shininess = self.non_negative(&path.key("shininess"), m.shininess);
        let reflectivity = self.unit(&path.key("reflectivity"), m.reflectivity);
        let transparency = self.unit(&path.key("transparency"), m.transparency);
        if reflectivity + transparency > 1.0 {
            self.problem(
                path.key("transparency"),
                "reflectivity + transparency must not exceed 1",
            );
        }
        let ior = self.index(&path.key("ior"), m.ior);
        // A material used by several objects reports its problems once.
        let new: Vec<Problem> = self.problems.drain(before..).collect();
        for p in new {
            if !self.problems.contains(&p) {
                self.problems.push(p);
            }
        }
        Material {
            color,
            ambient,
            diffuse,
            specular,
            shininess,
            reflectivity,
            transparency,
            ior,
        }
    }

    fn shape(&mut self, p: &FieldPath, o: &ObjectFile) -> Option<Shape> {
        let before = self.problems.len();
        let at = self.vec(&p.key("position"), o.position);
        self.vec(&p.key("rotation"), o.rotation);
        let kind = o.kind.name();
        let allowed: &[&str] = match o.kind {
            ShapeKind::Cuboid => &["size"],
            ShapeKind::Sphere => &["radius"],
            ShapeKind::Prism | ShapeKind::Pyramid => &["side", "height"],
        };
        let given = [
            ("size", o.size.is_some()),
            ("radius", o.radius.is_some()),
            ("side", o.side.is_some()),
            ("height", o.height.is_some()),
        ];
        for (key, present) in given {
            if present && !allowed.contains(&key) {
                self.problem(
                    p.key(key),
                    format!("a {kind} has no `{key}` (it takes {})", allowed.join(", ")),
                );
            }
        }
        let shape = match o.kind {
            ShapeKind::Cuboid => match o.size {
                None => {
                    self.problem(p.clone(), "a cuboid needs `size = [x, y, z]`");
                    None
                }
                Some(s) => {
                    for (i, x) in s.iter().enumerate() {
                        if !(*x > 0.0 && x.is_finite()) {
                            self.problem(p.key("size").index(i), format!("side length {x} must be positive"));
                        } else {
                            self.length(p.key("size").index(i), *x, at);
                        }
                    }
                    Some(Shape::Cuboid(Cuboid::new(DVec3::from(s))))
                }
            },
            ShapeKind::Sphere => Some(Shape::Sphere(Sphere::new(
                self.positive(p, o.radius, kind, "radius", at),
            ))),
            ShapeKind::Prism => Some(Shape::Prism(Prism::new(
                self.positive(p, o.side, kind, "side", at),
                self.positive(p, o.height, kind, "height", at),
            ))),
            ShapeKind::Pyramid => Some(Shape::Pyramid(Pyramid::new(
                self.positive(p, o.side, kind, "side", at),
                self.positive(p, o.height, kind, "height", at),
            ))),
        };
        if self.problems.len() > before { None } else { shape }
    }
}

/// What messages call the `i`-th object of the render model (the file's
/// objects, then its lenses, then its systems, when none was refused): its
/// name, else its kind and number in its list (`cuboid 3`, `lens 1`,
/// `system 2`).
pub(super) fn label(sf: &SceneFile, i: usize) -> String {
    let (n, m) = (sf.objects.len(), sf.lenses.len());
    let (name, kind, k) = if let Some(o) = sf.objects.get(i) {
        (&o.name, o.kind.name(), i)
    } else if i < n + m {
        (&sf.lenses[i - n].name, "lens", i - n)
    } else {
        let k = i - n - m;
        (sf.systems.get(k).map_or(&None, |s| &s.name), "system", k)
    };
    name.clone().unwrap_or_else(|| format!("{kind} {}", k + 1))
}
