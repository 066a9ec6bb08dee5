//! The page's editing panel without the browser: the scene's items (the
//! camera, the render settings, the lights, the primitives, the lenses and
//! the lens systems) and the fields of the selected one, as plain rows
//! that `www/panel.js` turns into inputs (`panel/rows.rs` has the lens
//! camera's, the render settings' and a material's). Values go back as
//! text to [`set`] (`panel/edit.rs`, `panel/settings.rs`), which parses
//! them and makes the desktop panel's edit through the library's
//! `edit::Document` (`set_lens`, `set_system`, `set_light`, …); buttons
//! (the *Add* menu, *Delete*, *Duplicate*) go to [`act`] (`panel/act.rs`).
//! Each is validated by the scene's own checks and is one undo step.
//! Nothing here knows optics; the readouts (EFL, f-number) are the
//! library's.

mod act;
mod edit;
mod rows;
mod settings;
#[cfg(test)]
mod tests;

pub use act::{act, adds};
pub use edit::set;

use lensview::edit::document::system_kind_label;
use lensview::edit::{Document, Item};
use lensview::glass::CATALOGUE;
use lensview::optics::{Index, ThickLens, WAVELENGTH_D_UM};
use lensview::prescription::PRESETS;
use lensview::scene::SYSTEM_KINDS;
use lensview::scene::file::{IndexFile, LensFile, LightKind, ObjectFile, ShapeKind, SystemFile, V3};
use serde::Serialize;

/// One row of the panel.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Field {
    /// What [`set`] takes: `"r1"`, `"center"`, `"surface.2.radius"`.
    pub key: String,
    pub label: String,
    /// `"number"`, `"vec3"` (three numbers, comma separated), `"choice"`
    /// (one of `options`), `"text"` (a line: a name), `"lines"` (a
    /// prescription's table) or `"readout"` (shown, not edited).
    pub kind: &'static str,
    pub value: String,
    /// A choice's values and what the list shows for each.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub options: Vec<(String, String)>,
}

/// What the page shows: the items (id, label), the selected one's fields,
/// the buttons of what can be done to it (action, label: [`act`]), what
/// the *Add* menu adds (action, label), and what Undo and Redo would undo
/// and redo.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Panel {
    pub items: Vec<(String, String)>,
    pub selected: String,
    pub fields: Vec<Field>,
    pub actions: Vec<(String, String)>,
    pub adds: Vec<(String, String)>,
    pub undo: Option<String>,
    pub redo: Option<String>,
}

/// An item of the panel's list, by its id: `camera`, `render` (the
/// scene's render settings and ambient light), `light:K`, `object:I`,
/// `lens:I`, `system:I`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    Camera,
    Render,
    Light(usize),
    Item(Item),
}

impl Target {
    pub fn parse(id: &str) -> Option<Target> {
        match id {
            "camera" => return Some(Target::Camera),
            "render" => return Some(Target::Render),
            _ => {}
        }
        let (kind, i) = id.split_once(':')?;
        let i: usize = i.parse().ok()?;
        Some(match kind {
            "light" => Target::Light(i),
            "object" => Target::Item(Item::Object(i)),
            "lens" => Target::Item(Item::Lens(i)),
            "system" => Target::Item(Item::System(i)),
            _ => return None,
        })
    }

    pub fn id(self) -> String {
        match self {
            Target::Camera => "camera".into(),
            Target::Render => "render".into(),
            Target::Light(k) => format!("light:{k}"),
            Target::Item(Item::Object(i)) => format!("object:{i}"),
            Target::Item(Item::Lens(i)) => format!("lens:{i}"),
            Target::Item(Item::System(i)) => format!("system:{i}"),
        }
    }

    /// Whether the document has it.
    fn exists(self, doc: &Document) -> bool {
        match self {
            Target::Camera | Target::Render => true,
            Target::Light(k) => k < doc.scene().lights.len(),
            Target::Item(item) => doc.contains(item),
        }
    }

    /// The scene file's path of the item, for error lines (`lenses[0]`).
    pub fn path(self) -> String {
        match self {
            Target::Camera => "camera".into(),
            Target::Render => "render".into(),
            Target::Light(k) => format!("lights[{k}]"),
            Target::Item(Item::Object(i)) => format!("objects[{i}]"),
            Target::Item(Item::Lens(i)) => format!("lenses[{i}]"),
            Target::Item(Item::System(i)) => format!("systems[{i}]"),
        }
    }
}

/// The panel with `selected` (an id) selected; a selection the document
/// lacks (another file was opened) falls back to the first lens or system,
/// else the camera.
pub fn panel(doc: &Document, selected: &str) -> Panel {
    let target = Target::parse(selected)
        .filter(|t| t.exists(doc))
        .or_else(|| {
            let s = doc.scene();
            let first = [
                (!s.lenses.is_empty(), Item::Lens(0)),
                (!s.systems.is_empty(), Item::System(0)),
            ];
            first.into_iter().find(|(has, _)| *has).map(|(_, i)| Target::Item(i))
        })
        .unwrap_or(Target::Camera);
    Panel {
        items: items(doc),
        selected: target.id(),
        fields: fields(doc, target),
        actions: act::actions(doc, target),
        adds: adds(),
        undo: doc.undo_label().map(str::to_string),
        redo: doc.redo_label().map(str::to_string),
    }
}

/// The list: the camera, the lights, then the document's own items (as the
/// desktop's *Objects* list names them), each with its kind.
pub fn items(doc: &Document) -> Vec<(String, String)> {
    let s = doc.scene();
    let mut v = vec![
        ("camera".to_string(), "camera".to_string()),
        ("render".to_string(), "render settings".to_string()),
    ];
    for (k, l) in s.lights.iter().enumerate() {
        let kind = if l.kind == LightKind::Point {
            "point"
        } else {
            "directional"
        };
        v.push((Target::Light(k).id(), format!("light {} ({kind})", k + 1)));
    }
    for (item, name) in doc.items() {
        let kind = match item {
            Item::Object(i) => s.objects[i].kind.name().to_string(),
            Item::Lens(_) => "lens".to_string(),
            Item::System(i) => format!("system: {}", system_kind_label(&s.systems[i])),
        };
        v.push((Target::Item(item).id(), format!("{name} ({kind})")));
    }
    v
}

/// A number as the panel shows it: the shortest text that reads back the
/// same.
pub fn num(x: f64) -> String {
    format!("{x}")
}

fn v3(v: V3) -> String {
    format!("{}, {}, {}", num(v[0]), num(v[1]), num(v[2]))
}

fn number(key: &str, label: &str, x: f64) -> Field {
    row(key, label, "number", num(x))
}

fn vec3(key: &str, label: &str, v: V3) -> Field {
    row(key, label, "vec3", v3(v))
}

fn text(key: &str, label: &str, value: &str) -> Field {
    row(key, label, "text", value.into())
}

fn readout(label: &str, value: String) -> Field {
    row("", label, "readout", value)
}

fn row(key: &str, label: &str, kind: &'static str, value: String) -> Field {
    Field {
        key: key.into(),
        label: label.into(),
        kind,
        value,
        options: Vec::new(),
    }
}

fn choice(key: &str, label: &str, value: &str, options: Vec<(String, String)>) -> Field {
    Field {
        options,
        ..row(key, label, "choice", value.into())
    }
}

/// The rows of the selected item.
pub fn fields(doc: &Document, target: Target) -> Vec<Field> {
    let s = doc.scene();
    match target {
        Target::Camera => {
            let (p, r) = doc.camera_pose();
            vec![
                vec3("position", "position", p.to_array()),
                vec3("rotation", "rotation °", r.to_array()),
                number("fov", "fov °", s.camera.fov),
            ]
            .into_iter()
            .chain(rows::camera_lens(doc))
            .collect()
        }
        Target::Render => rows::render(doc),
        Target::Light(k) => {
            let l = &s.lights[k];
            let kinds = [("point", "point"), ("directional", "directional")];
            let kind = if l.kind == LightKind::Point {
                "point"
            } else {
                "directional"
            };
            let mut v = vec![choice("kind", "type", kind, pairs(&kinds))];
            v.extend(l.position.map(|p| vec3("position", "position", p)));
            v.extend(l.direction.map(|d| vec3("direction", "direction", d)));
            v.push(vec3("color", "colour", l.color));
            v.push(number("intensity", "intensity", l.intensity));
            v
        }
        Target::Item(Item::Object(i)) => object_fields(doc, &s.objects[i]),
        Target::Item(Item::Lens(i)) => lens_fields(&s.lenses[i]),
        Target::Item(Item::System(i)) => system_fields(doc, i, &s.systems[i]),
    }
}

fn pairs(v: &[(&str, &str)]) -> Vec<(String, String)> {
    v.iter().map(|(a, b)| (a.to_string(), b.to_string())).collect()
}

fn object_fields(doc: &Document, o: &ObjectFile) -> Vec<Field> {
    let mut v = vec![
        text("name", "name", o.name.as_deref().unwrap_or_default()),
        readout("type", o.kind.name().into()),
        vec3("position", "position", o.position),
        vec3("rotation", "rotation °", o.rotation),
    ];
    match o.kind {
        ShapeKind::Cuboid => v.push(vec3("size", "size", o.size.unwrap_or([1.0; 3]))),
        ShapeKind::Sphere => v.push(number("radius", "radius", o.radius.unwrap_or(0.5))),
        ShapeKind::Prism | ShapeKind::Pyramid => {
            v.push(number("side", "base side", o.side.unwrap_or(1.0)));
            v.push(number("height", "height", o.height.unwrap_or(1.0)));
        }
    }
    v.extend(rows::material(doc, o));
    v
}

/// An index's two rows: the catalogue glass (or none: a number), and the
/// index at the d line (editing it makes the index that number).
fn index_fields(key: &str, label: &str, n: IndexFile) -> [Field; 2] {
    let mut options = vec![(String::new(), "(a number)".to_string())];
    options.extend(CATALOGUE.iter().map(|g| {
        let shown = format!("{}  (nd {:.5}, Abbe {:.2})", g.name, g.nd(), g.abbe());
        (g.name.to_string(), shown)
    }));
    let glass = match n {
        IndexFile::Glass(g) => g.name,
        _ => "",
    };
    [
        choice(&format!("{key}.glass"), &format!("{label} glass"), glass, options),
        number(key, &format!("{label} (d line)"), nominal(n)),
    ]
}

/// The index at the d line.
pub fn nominal(n: IndexFile) -> f64 {
    match n {
        IndexFile::Constant(v) => v,
        IndexFile::Cauchy([a, b]) => Index::Cauchy { a, b }.nominal(),
        IndexFile::Glass(g) => g.nd(),
    }
}

fn lens_fields(l: &LensFile) -> Vec<Field> {
    let mut v = vec![
        text("name", "name", l.name.as_deref().unwrap_or_default()),
        vec3("center", "centre", l.center),
        vec3("axis", "axis", l.axis),
        number("d", "diameter d", l.d),
        number("r1", "r1 (faces +axis)", l.r1),
        number("r2", "r2 (faces −axis)", l.r2),
    ];
    v.extend(index_fields("n", "n", l.n));
    v.push(vec3("tint", "tint", l.tint));
    let n = nominal(l.n);
    let sound = l.d > 0.0 && l.r1 >= 0.5 * l.d && l.r2 >= 0.5 * l.d && n >= 1.0;
    if sound {
        let p = ThickLens::new(l.d, l.r1, l.r2, n);
        v.push(readout("thickness", format!("{:.6}", p.thickness)));
        v.push(readout("EFL (paraxial)", format!("{:.6}", p.efl)));
    }
    v
}

fn system_fields(doc: &Document, i: usize, s: &SystemFile) -> Vec<Field> {
    let kinds: Vec<(String, String)> = SYSTEM_KINDS.iter().map(|k| (k.to_string(), k.to_string())).collect();
    let name = s.name.as_deref().unwrap_or_default();
    let mut v = vec![text("name", "name", name), choice("kind", "kind", &s.kind, kinds)];
    if s.kind == "preset" {
        let presets = PRESETS.iter().map(|(p, _)| (p.to_string(), p.to_string())).collect();
        v.push(choice("preset", "preset", s.preset.as_deref().unwrap_or(""), presets));
    }
    v.extend(s.scale.map(|x| number("scale", "scale", x)));
    if s.kind == "prescription" {
        let table = s.prescription.as_deref().unwrap_or_default();
        let label = "prescription (radius, thickness, n, aperture diameter per line)";
        v.push(row("prescription", label, "lines", table.into()));
    }
    v.extend(s.center.map(|p| vec3("center", "centre", p)));
    v.extend(s.vertex.map(|p| vec3("vertex", "first vertex", p)));
    v.push(vec3("axis", "axis", s.axis));
    let lengths = [
        ("d", s.d),
        ("r", s.r),
        ("r1", s.r1),
        ("r2", s.r2),
        ("r3", s.r3),
        ("thickness", s.thickness),
        ("thickness2", s.thickness2),
    ];
    for (k, x) in lengths {
        v.extend(x.map(|x| number(k, k, x)));
    }
    for (k, n) in [("n", s.n), ("n2", s.n2)] {
        v.extend(n.into_iter().flat_map(|n| index_fields(k, k, n)));
    }
    if s.kind.starts_with("plano") {
        let faces = pairs(&[("back", "back"), ("front", "front")]);
        v.push(choice("flat", "flat face", s.flat.as_deref().unwrap_or("back"), faces));
    }
    for (k, f) in s.surfaces.iter().flatten().enumerate() {
        let key = |x: &str| format!("surface.{k}.{x}");
        let label = |x: &str| format!("surface {} {x}", k + 1);
        v.push(number(&key("radius"), &label("radius"), f.radius));
        v.push(number(&key("thickness"), &label("thickness"), f.thickness));
        v.push(number(&key("semi_aperture"), &label("semi-aperture"), f.semi_aperture));
        v.extend(index_fields(&key("n"), &label("n after"), f.n));
    }
    v.push(vec3("tint", "tint", s.tint));
    if let Some(sys) = doc.built_system(i) {
        let p = sys.paraxial(WAVELENGTH_D_UM);
        v.push(readout("EFL (paraxial)", format!("{:.6}", p.efl)));
        v.push(readout("f-number", format!("{:.3}", p.f_number)));
    }
    v
}
