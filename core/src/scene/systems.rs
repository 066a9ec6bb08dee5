//! `[[systems]]`: lens systems from their kinds (a table of surfaces, a
//! prescription in pbrt-v4's form, a preset, or a shorthand: plano-convex,
//! plano-concave, biconvex, biconcave, meniscus, doublet) to
//! [`LensSystem`] objects, each refusal naming its key.

use super::Object;
use super::error::FieldPath;
use super::file::{IndexFile, SystemFile};
use super::validate::Validator;
use crate::geometry::{LensSystem, Shape, SurfaceSpec, SystemError};
use crate::material::Material;
use crate::optics::Index;
use crate::prescription;
use glam::DVec3;

/// The kinds a `[[systems]]` entry may have.
pub const KINDS: &[&str] = &[
    "surfaces",
    "prescription",
    "preset",
    "plano-convex",
    "plano-concave",
    "biconvex",
    "biconcave",
    "meniscus",
    "doublet",
];

/// The keys each shorthand kind reads (besides name, kind, the pose and
/// the tint), and which key names each surface's radius.
struct Shorthand {
    keys: &'static [&'static str],
    radii: &'static [&'static str],
}

fn shorthand(kind: &str) -> Option<Shorthand> {
    let (keys, radii): (&[&str], &[&str]) = match kind {
        "plano-convex" | "plano-concave" => (&["d", "r", "thickness", "n", "flat"], &["r"]),
        "biconvex" | "biconcave" | "meniscus" => (&["d", "r1", "r2", "thickness", "n"], &["r1", "r2"]),
        "doublet" => (
            &["d", "r1", "r2", "r3", "thickness", "thickness2", "n", "n2"],
            &["r1", "r2", "r3"],
        ),
        _ => return None,
    };
    Some(Shorthand { keys, radii })
}

/// The keys of a `[[systems]]` entry that are set, by name.
fn keys_set(s: &SystemFile) -> Vec<&'static str> {
    let set = [
        ("d", s.d.is_some()),
        ("r", s.r.is_some()),
        ("r1", s.r1.is_some()),
        ("r2", s.r2.is_some()),
        ("r3", s.r3.is_some()),
        ("thickness", s.thickness.is_some()),
        ("thickness2", s.thickness2.is_some()),
        ("n", s.n.is_some()),
        ("n2", s.n2.is_some()),
        ("flat", s.flat.is_some()),
        ("surfaces", s.surfaces.is_some()),
        ("prescription", s.prescription.is_some()),
        ("preset", s.preset.is_some()),
        ("scale", s.scale.is_some()),
    ];
    set.into_iter().filter(|(_, on)| *on).map(|(k, _)| k).collect()
}

impl Validator {
    /// `[[systems]]`, as glass objects.
    pub(super) fn systems(&mut self, sf: &super::SceneFile) -> Vec<Object> {
        let mut objects = Vec::new();
        for (i, s) in sf.systems.iter().enumerate() {
            let p = FieldPath::root("systems").index(i);
            let tint = self.colour(&p.key("tint"), s.tint);
            let Some((surfaces, fields)) = self.system_surfaces(&p, s) else {
                continue;
            };
            let length: f64 = surfaces.iter().rev().skip(1).map(|f| f.thickness).sum();
            let axis = DVec3::from(s.axis);
            let vertex = match (s.vertex, s.center) {
                (Some(v), None) => DVec3::from(v),
                (None, Some(c)) => DVec3::from(c) + axis.normalize_or_zero() * (0.5 * length),
                _ => {
                    self.problem(
                        p.key("vertex"),
                        "give one of `vertex` (the first surface's) or `center`",
                    );
                    continue;
                }
            };
            match LensSystem::new(vertex, axis, surfaces) {
                Ok(sys) => {
                    let material = Material::glass_of_shape(tint);
                    let name = s.name.clone().unwrap_or_default();
                    objects.push(Object::new(
                        name,
                        Shape::System(Box::new(sys)),
                        material,
                        DVec3::ZERO,
                        DVec3::ZERO,
                    ));
                }
                Err(e) => {
                    let at = fields(&e);
                    let (path, message) = (p.key(&at), e.message);
                    self.problem(path, message);
                }
            }
        }
        objects
    }

    /// The surfaces an entry describes, and how a [`SystemError`] names its
    /// key; `None` (with the problem noted) when the entry is malformed.
    #[allow(clippy::type_complexity)]
    pub(super) fn system_surfaces(
        &mut self,
        p: &FieldPath,
        s: &SystemFile,
    ) -> Option<(Vec<SurfaceSpec>, Box<dyn Fn(&SystemError) -> String>)> {
        let set = keys_set(s);
        let allowed: Vec<&str> = match s.kind.as_str() {
            "surfaces" => vec!["surfaces"],
            "prescription" => vec!["prescription", "scale"],
            "preset" => vec!["preset", "scale"],
            k => match shorthand(k) {
                Some(sh) => sh.keys.to_vec(),
                None => {
                    self.problem(
                        p.key("kind"),
                        format!("unknown kind `{}`; one of {}", s.kind, KINDS.join(", ")),
                    );
                    return None;
                }
            },
        };
        if let Some(extra) = set.iter().find(|k| !allowed.contains(k)) {
            let why = format!(
                "`{extra}` is not read by kind `{}` (it reads {})",
                s.kind,
                allowed.join(", ")
            );
            self.problem(p.key(extra), why);
            return None;
        }
        match s.kind.as_str() {
            "surfaces" => self.table(p, s),
            "prescription" | "preset" => self.prescribed(p, s),
            k => self.shorthand_surfaces(p, s, k),
        }
    }

    /// `kind = "surfaces"`.
    #[allow(clippy::type_complexity)]
    fn table(
        &mut self,
        p: &FieldPath,
        s: &SystemFile,
    ) -> Option<(Vec<SurfaceSpec>, Box<dyn Fn(&SystemError) -> String>)> {
        let Some(list) = &s.surfaces else {
            self.problem(
                p.key("surfaces"),
                "kind `surfaces` needs `surfaces = [{ radius, thickness, n, semi_aperture }, …]`",
            );
            return None;
        };
        let mut out = Vec::with_capacity(list.len());
        for (k, f) in list.iter().enumerate() {
            let n = self.index(&p.key("surfaces").index(k).key("n"), f.n);
            out.push(SurfaceSpec {
                radius: f.radius,
                thickness: f.thickness,
                n,
                semi_aperture: f.semi_aperture,
                stop: f.stop,
            });
        }
        let fields = |e: &SystemError| match e.surface {
            Some(k) => format!("surfaces[{k}].{}", e.field),
            None => e.field.to_string(),
        };
        Some((out, Box::new(fields)))
    }

    /// The shorthand kinds: the surfaces they stand for.
    #[allow(clippy::type_complexity)]
    fn shorthand_surfaces(
        &mut self,
        p: &FieldPath,
        s: &SystemFile,
        kind: &str,
    ) -> Option<(Vec<SurfaceSpec>, Box<dyn Fn(&SystemError) -> String>)> {
        let sh = shorthand(kind)?;
        let missing = |key: &str, v: Option<f64>, this: &mut Self| {
            if v.is_none() {
                this.problem(p.key(key), format!("kind `{kind}` needs `{key}`"));
            }
            v.unwrap_or(f64::NAN)
        };
        let d = missing("d", s.d, self);
        let t = missing("thickness", s.thickness, self);
        let n_file = s.n.unwrap_or(IndexFile::Constant(f64::NAN));
        if s.n.is_none() {
            self.problem(p.key("n"), format!("kind `{kind}` needs `n`"));
        }
        let n = self.index(&p.key("n"), n_file);
        let a = 0.5 * d;
        let face = |radius: f64, thickness: f64, n: Index| SurfaceSpec {
            radius,
            thickness,
            n,
            semi_aperture: a,
            stop: false,
        };
        let surfaces = self.shorthand_faces(p, s, kind, (t, n), &face, &missing)?;
        if [d, t].iter().any(|v| v.is_nan()) {
            return None;
        }
        let radii = sh.radii;
        let fields = move |e: &SystemError| {
            let k = e.surface.unwrap_or(0);
            match e.field {
                "radius" => radii.get(k).or(radii.last()).copied().unwrap_or("r").to_string(),
                "thickness" if k == 1 => "thickness2".into(),
                "thickness" => "thickness".into(),
                "n" if k == 1 => "n2".into(),
                "semi_aperture" => "d".into(),
                f => f.to_string(),
            }
        };
        Some((surfaces, Box::new(fields)))
    }

    /// The faces of a shorthand kind: centre thickness `t` and glass `n`
    /// given, `face` making a surface of the kind's diameter, `missing`
    /// reading a key that must be there.
    #[allow(clippy::type_complexity)]
    fn shorthand_faces(
        &mut self,
        p: &FieldPath,
        s: &SystemFile,
        kind: &str,
        (t, n): (f64, Index),
        face: &dyn Fn(f64, f64, Index) -> SurfaceSpec,
        missing: &dyn Fn(&str, Option<f64>, &mut Self) -> f64,
    ) -> Option<Vec<SurfaceSpec>> {
        let air = Index::Constant(1.0);
        Some(match kind {
            "plano-convex" | "plano-concave" => {
                let r = missing("r", s.r, self).abs();
                let flat_front = match s.flat.as_deref() {
                    None | Some("back") => false,
                    Some("front") => true,
                    Some(other) => {
                        self.problem(p.key("flat"), format!("flat = `{other}`: `front` or `back`"));
                        return None;
                    }
                };
                // Convex: the curved face bulges out of the glass.
                let r = if kind == "plano-convex" { r } else { -r };
                if flat_front {
                    vec![face(0.0, t, n), face(-r, 0.0, air)]
                } else {
                    vec![face(r, t, n), face(0.0, 0.0, air)]
                }
            }
            "biconvex" | "biconcave" | "meniscus" => {
                let (r1, r2) = (missing("r1", s.r1, self), missing("r2", s.r2, self));
                let (r1, r2) = match kind {
                    "biconvex" => (r1.abs(), -r2.abs()),
                    "biconcave" => (-r1.abs(), r2.abs()),
                    _ => (r1, r2),
                };
                vec![face(r1, t, n), face(r2, 0.0, air)]
            }
            _ => {
                let (r1, r2, r3) = (
                    missing("r1", s.r1, self),
                    missing("r2", s.r2, self),
                    missing("r3", s.r3, self),
                );
                let t2 = missing("thickness2", s.thickness2, self);
                let n2_file = s.n2.unwrap_or(IndexFile::Constant(f64::NAN));
                if s.n2.is_none() {
                    self.problem(p.key("n2"), "kind `doublet` needs `n2`");
                }
                let n2 = self.index(&p.key("n2"), n2_file);
                vec![face(r1, t, n), face(r2, t2, n2), face(r3, 0.0, air)]
            }
        })
    }

    /// `kind = "prescription"` and `"preset"`.
    #[allow(clippy::type_complexity)]
    fn prescribed(
        &mut self,
        p: &FieldPath,
        s: &SystemFile,
    ) -> Option<(Vec<SurfaceSpec>, Box<dyn Fn(&SystemError) -> String>)> {
        let (key, text) = if s.kind == "preset" {
            let Some(name) = &s.preset else {
                self.problem(
                    p.key("preset"),
                    format!("kind `preset` needs `preset`: one of {}", preset_names()),
                );
                return None;
            };
            let Some(text) = prescription::preset(name) else {
                self.problem(
                    p.key("preset"),
                    format!("no preset `{name}`: one of {}", preset_names()),
                );
                return None;
            };
            ("preset", text)
        } else {
            let Some(text) = &s.prescription else {
                self.problem(
                    p.key("prescription"),
                    "kind `prescription` needs `prescription`, the table as text",
                );
                return None;
            };
            ("prescription", text.as_str())
        };
        let scale = s.scale.unwrap_or(1.0);
        if !(scale > 0.0 && scale.is_finite()) {
            self.problem(p.key("scale"), format!("scale {scale} must be positive and finite"));
            return None;
        }
        let rows = match prescription::parse(key, text) {
            Ok(rows) => rows,
            Err(e) => {
                self.problem(p.key(key), e.to_string());
                return None;
            }
        };
        let lines: Vec<usize> = rows.iter().map(|r| r.line).collect();
        let fields = move |e: &SystemError| match e.surface {
            Some(k) => format!("{key}: line {}: {}", lines.get(k).copied().unwrap_or(0), e.field),
            None => format!("{key}: {}", e.field),
        };
        Some((SurfaceSpec::from_rows(&rows, scale), Box::new(fields)))
    }
}

/// The names of the built-in prescriptions.
fn preset_names() -> String {
    prescription::PRESETS
        .iter()
        .map(|(n, _)| *n)
        .collect::<Vec<_>>()
        .join(", ")
}
