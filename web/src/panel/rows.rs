//! The rows the desktop shows in its *Camera*, *Render* and *Light*
//! sections and its material editor: the lens camera, the render settings
//! and ambient light, and a primitive's material. `settings.rs` sets them.

use super::{Field, choice, index_fields, num, number, pairs, readout, row, vec3};
use lensview::color::ToneCurve;
use lensview::edit::Document;
use lensview::scene::file::{MaterialFile, ObjectFile};

/// The pinhole/lens switch and, with the lens camera on, its focus
/// distance (empty: infinity) and f-number.
pub fn camera_lens(doc: &Document) -> Vec<Field> {
    let kinds = pairs(&[("pinhole", "pinhole"), ("lens", "lens")]);
    let on = if doc.lens_camera_on() { "lens" } else { "pinhole" };
    let mut v = vec![choice("lens_camera", "camera", on, kinds)];
    if let Some(lens) = &doc.built().lens {
        let d = lens.focus_distance;
        let focus = if d.is_finite() { num(d) } else { String::new() };
        v.push(row("focus", "focus distance (empty: infinity)", "number", focus));
        // The file's f-number as written (the built one is its product).
        let n = doc.scene().camera.f_number.unwrap_or(lens.f_number);
        v.push(number("f_number", "f-number", n));
        v.push(readout("widest f-number", format!("{:.2}", lens.open_f_number)));
    }
    v
}

/// `[render]` (max depth, background, caustics, shadows), `[ambient]` and
/// `[display]` (exposure, tone curve).
pub fn render(doc: &Document) -> Vec<Field> {
    let s = doc.scene();
    let on_off = |b: bool| if b { "on" } else { "off" };
    let both = pairs(&[("on", "on"), ("off", "off")]);
    let curves = ToneCurve::ALL
        .iter()
        .map(|c| (c.name().to_string(), c.name().to_string()));
    vec![
        row("max_depth", "max depth", "number", s.render.max_depth.to_string()),
        vec3("background", "background", s.render.background),
        choice(
            "caustics",
            "caustics",
            on_off(doc.built().features.caustics),
            both.clone(),
        ),
        choice("shadows", "shadows", on_off(s.render.shadows), both),
        number("ambient", "ambient level", s.ambient.intensity),
        vec3("ambient_color", "ambient colour", s.ambient.color),
        number("exposure", "exposure (stops)", s.display.exposure),
        choice("tone", "tone curve", s.display.tone.name(), curves.collect()),
    ]
}

/// Which material primitive `o` has (shared ones say by how many), and
/// its fields: those of the built-in grey when it has none (editing one
/// gives it a material of its own).
pub fn material(doc: &Document, o: &ObjectFile) -> Vec<Field> {
    let materials = &doc.scene().materials;
    let name = o.material.as_deref().filter(|m| materials.contains_key(*m));
    let mut options = vec![(String::new(), "built-in grey".to_string())];
    options.extend(materials.keys().map(|m| (m.clone(), m.clone())));
    let label = match name {
        Some(m) if doc.material_users(m) > 1 => format!("material (shared by {})", doc.material_users(m)),
        _ => "material".to_string(),
    };
    let m = name.map_or_else(MaterialFile::default, |n| materials[n].clone());
    let mut v = vec![
        choice("material", &label, name.unwrap_or_default(), options),
        vec3("color", "colour", m.color),
    ];
    for (key, x) in [
        ("ambient", m.ambient),
        ("diffuse", m.diffuse),
        ("specular", m.specular),
        ("shininess", m.shininess),
        ("reflectivity", m.reflectivity),
        ("transparency", m.transparency),
    ] {
        v.push(number(key, key, x));
    }
    v.extend(index_fields("ior", "ior", m.ior));
    v
}
