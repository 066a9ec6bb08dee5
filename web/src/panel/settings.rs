//! The panel's edits of what is not one record of an item: the lens
//! camera (the *Camera* section's `toggle_lens_camera`,
//! `set_focus_distance`, `set_f_number`), the render settings and ambient
//! light (the *Render* and *Light* sections' `set_max_depth`,
//! `set_background`, `set_caustics`, `set_shadows`, `set_ambient`,
//! `set_exposure`, `set_tone`) and a primitive's material (the material
//! editor's `set_material`; a primitive with the built-in grey gets a
//! material of its own in the same undo step, as a colour did).

use super::edit::{index_field, parse_num, parse_v3, shown, unknown};
use lensview::color::ToneCurve;
use lensview::edit::document::{Rejected, unique_key};
use lensview::edit::{Change, Document, Item};
use lensview::scene::file::MaterialFile;

type Edited = Result<Result<Change, Rejected>, String>;

/// `on` or `off`.
fn on_off(path: &str, value: &str) -> Result<bool, String> {
    match value.trim() {
        "on" => Ok(true),
        "off" => Ok(false),
        v => Err(format!("error: {path}: not on or off: \"{}\"", shown(v))),
    }
}

/// The lens camera: `lens_camera` (`pinhole` or `lens`), `focus` (a
/// distance; empty or `infinity`: at infinity) and `f_number`.
pub fn camera_lens(doc: &mut Document, key: &str, value: &str, path: &str) -> Edited {
    match key {
        "lens_camera" => {
            let on = match value.trim() {
                "lens" => true,
                "pinhole" => false,
                v => return Err(format!("error: {path}: not pinhole or lens: \"{}\"", shown(v))),
            };
            if on == doc.lens_camera_on() {
                return Ok(Ok(Change::None));
            }
            Ok(doc.toggle_lens_camera().map(|(_, change)| change))
        }
        "focus" => {
            let d = match value.trim() {
                "" | "infinity" | "inf" => None,
                v => Some(parse_num(path, v)?),
            };
            Ok(doc.set_focus_distance(d))
        }
        "f_number" => Ok(doc.set_f_number(Some(parse_num(path, value)?))),
        _ => Err(unknown(path)),
    }
}

/// The render settings, the ambient light and the display's exposure and
/// tone curve.
pub fn render(doc: &mut Document, key: &str, value: &str, path: &str) -> Edited {
    let mut ambient = doc.scene().ambient.clone();
    Ok(match key {
        "max_depth" => {
            let d = value.trim().parse::<u32>();
            let d = d.map_err(|_| format!("error: {path}: not a whole number: \"{}\"", shown(value.trim())))?;
            doc.set_max_depth(d)
        }
        "background" => doc.set_background(parse_v3(path, value)?),
        "caustics" => doc.set_caustics(on_off(path, value)?),
        "shadows" => doc.set_shadows(on_off(path, value)?),
        "ambient" | "ambient_color" => {
            if key == "ambient" {
                ambient.intensity = parse_num(path, value)?;
            } else {
                ambient.color = parse_v3(path, value)?;
            }
            doc.set_ambient(ambient)
        }
        "exposure" => doc.set_exposure(parse_num(path, value)?),
        "tone" => {
            let curve = ToneCurve::parse(value.trim())
                .ok_or_else(|| format!("error: {path}: not a tone curve: \"{}\"", shown(value.trim())))?;
            doc.set_tone(curve)
        }
        _ => return Err(unknown(path)),
    })
}

/// The material fields of a primitive, as [`material`] takes them.
pub const MATERIAL_KEYS: [&str; 9] = [
    "color",
    "ambient",
    "diffuse",
    "specular",
    "shininess",
    "reflectivity",
    "transparency",
    "ior",
    "ior.glass",
];

/// Field `key` (one of [`MATERIAL_KEYS`]) of primitive `i`'s material:
/// every primitive sharing it changes too, as on the desktop.
pub fn material(doc: &mut Document, i: usize, key: &str, value: &str, path: &str) -> Edited {
    let named = doc.scene().objects[i].material.clone();
    let named = named.filter(|m| doc.scene().materials.contains_key(m));
    let mut m = named
        .as_ref()
        .map_or_else(MaterialFile::default, |n| doc.scene().materials[n].clone());
    match key {
        "color" => m.color = parse_v3(path, value)?,
        "ambient" => m.ambient = parse_num(path, value)?,
        "diffuse" => m.diffuse = parse_num(path, value)?,
        "specular" => m.specular = parse_num(path, value)?,
        "shininess" => m.shininess = parse_num(path, value)?,
        "reflectivity" => m.reflectivity = parse_num(path, value)?,
        "transparency" => m.transparency = parse_num(path, value)?,
        "ior" | "ior.glass" => index_field(&mut m.ior, key == "ior.glass", value, path)?,
        _ => return Err(unknown(path)),
    }
    if let Some(name) = named {
        return Ok(doc.set_material(&name, m));
    }
    let base = doc.item_name(Item::Object(i));
    Ok(doc.edit("material", |sf| {
        let name = unique_key(&sf.materials, &base);
        sf.materials.insert(name.clone(), m);
        sf.objects[i].material = Some(name);
    }))
}
