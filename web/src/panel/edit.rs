//! The panel's edits: a field's text parsed (a number, three numbers, a
//! choice) and set on a copy of the item's record, which goes to the
//! document's setter of that record as the desktop panel's does
//! (`Document::set_lens`, `set_system`, `set_light`, `set_object`,
//! `set_material`, `set_camera`), then sealed: one undo step per field
//! committed. A value the scene's checks refuse leaves the document as it
//! was and comes back as the one-line error the page shows.

use super::{Target, settings};
use glam::DVec3;
use lensview::edit::document::{new_preset_system, new_system, switch_light_kind};
use lensview::edit::{Change, Document, Item};
use lensview::glass;
use lensview::scene::escape_controls;
use lensview::scene::file::{IndexFile, LensFile, LightFile, LightKind, ObjectFile, SystemFile, V3};

/// Sets field `key` of item `id` to `value` (text, as typed). Returns what
/// was done and what changed, or the one line (`error: …`) saying why not.
pub fn set(doc: &mut Document, id: &str, key: &str, value: &str) -> Result<(String, Change), String> {
    let target = Target::parse(id)
        .filter(|t| t.exists(doc))
        .ok_or_else(|| format!("error: no item \"{}\" in the scene", shown(id)))?;
    let path = format!("{}.{key}", target.path());
    let r = match target {
        Target::Camera => set_camera(doc, key, value, &path)?,
        Target::Render => settings::render(doc, key, value, &path)?,
        Target::Light(k) => {
            let mut l = doc.scene().lights[k].clone();
            light_field(&mut l, key, value, &path)?;
            doc.set_light(k, l)
        }
        Target::Item(Item::Object(i)) if settings::MATERIAL_KEYS.contains(&key) => {
            settings::material(doc, i, key, value, &path)?
        }
        Target::Item(Item::Object(i)) => {
            let mut o = doc.scene().objects[i].clone();
            object_field(&mut o, key, value, &path)?;
            doc.set_object(i, o)
        }
        Target::Item(Item::Lens(i)) => {
            let mut l = doc.scene().lenses[i].clone();
            lens_field(&mut l, key, value, &path)?;
            doc.set_lens(i, l)
        }
        Target::Item(Item::System(i)) => {
            let s = system_field(doc.scene().systems[i].clone(), key, value, &path)?;
            doc.set_system(i, s)
        }
    };
    doc.seal();
    let change = r.map_err(|e| format!("error: {}", escape_controls(&e.to_string())))?;
    Ok((format!("{path} = {}", shown(value.trim())), change))
}

/// `value` for an error line: controls escaped, at most 40 characters.
pub(super) fn shown(value: &str) -> String {
    let cut: String = value.chars().take(40).collect();
    escape_controls(&cut).into_owned()
}

pub(super) fn unknown(path: &str) -> String {
    format!("error: {path}: no such field")
}

/// A finite number.
pub fn parse_num(path: &str, value: &str) -> Result<f64, String> {
    match value.trim().parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(x),
        _ => Err(format!("error: {path}: not a number: \"{}\"", shown(value.trim()))),
    }
}

/// Three finite numbers, separated by commas or spaces.
pub fn parse_v3(path: &str, value: &str) -> Result<V3, String> {
    let parts: Vec<&str> = value.split([',', ' ']).filter(|s| !s.trim().is_empty()).collect();
    let bad = || format!("error: {path}: not three numbers: \"{}\"", shown(value.trim()));
    if parts.len() != 3 {
        return Err(bad());
    }
    let mut v = [0.0; 3];
    for (x, p) in v.iter_mut().zip(parts) {
        *x = parse_num(path, p).map_err(|_| bad())?;
    }
    Ok(v)
}

/// The camera's pose and field of view.
fn set_camera(
    doc: &mut Document,
    key: &str,
    value: &str,
    path: &str,
) -> Result<Result<Change, lensview::edit::Rejected>, String> {
    let (mut pos, mut rot) = doc.camera_pose();
    let mut fov = doc.scene().camera.fov;
    match key {
        "position" => pos = DVec3::from(parse_v3(path, value)?),
        "rotation" => rot = DVec3::from(parse_v3(path, value)?),
        "fov" => fov = parse_num(path, value)?,
        _ => return settings::camera_lens(doc, key, value, path),
    }
    Ok(doc.set_camera(pos, rot, fov))
}

fn light_field(l: &mut LightFile, key: &str, value: &str, path: &str) -> Result<(), String> {
    match key {
        "kind" => match value {
            "point" => switch_light_kind(l, LightKind::Point),
            "directional" => switch_light_kind(l, LightKind::Directional),
            _ => return Err(format!("error: {path}: not a light type: \"{}\"", shown(value))),
        },
        "position" => l.position = Some(parse_v3(path, value)?),
        "direction" => l.direction = Some(parse_v3(path, value)?),
        "color" => l.color = parse_v3(path, value)?,
        "intensity" => l.intensity = parse_num(path, value)?,
        _ => return Err(unknown(path)),
    }
    Ok(())
}

/// A name as typed; blank: none (the renderer's own).
fn named(value: &str) -> Option<String> {
    (!value.trim().is_empty()).then(|| value.to_string())
}

fn object_field(o: &mut ObjectFile, key: &str, value: &str, path: &str) -> Result<(), String> {
    match key {
        "name" => o.name = named(value),
        "material" => o.material = named(value),
        "position" => o.position = parse_v3(path, value)?,
        "rotation" => o.rotation = parse_v3(path, value)?,
        "size" => o.size = Some(parse_v3(path, value)?),
        "radius" => o.radius = Some(parse_num(path, value)?),
        "side" => o.side = Some(parse_num(path, value)?),
        "height" => o.height = Some(parse_num(path, value)?),
        _ => return Err(unknown(path)),
    }
    Ok(())
}

/// An index's fields: `KEY` (a number: the index becomes that constant)
/// or `KEY.glass` (a catalogue glass; empty: the glass's nd as a number,
/// rounded to 5 decimals as the desktop's *number* button does).
pub(super) fn index_field(n: &mut IndexFile, glass_key: bool, value: &str, path: &str) -> Result<(), String> {
    if !glass_key {
        *n = IndexFile::Constant(parse_num(path, value)?);
    } else if value.trim().is_empty() {
        if let IndexFile::Glass(g) = *n {
            *n = IndexFile::Constant((g.nd() * 1e5).round() / 1e5);
        }
    } else {
        let g = glass::lookup(value).ok_or_else(|| {
            format!(
                "error: {path}: unknown glass \"{}\"; known glasses: {}",
                shown(value),
                glass::names()
            )
        })?;
        *n = IndexFile::Glass(g);
    }
    Ok(())
}

fn lens_field(l: &mut LensFile, key: &str, value: &str, path: &str) -> Result<(), String> {
    match key {
        "name" => l.name = named(value),
        "center" => l.center = parse_v3(path, value)?,
        "axis" => l.axis = parse_v3(path, value)?,
        "tint" => l.tint = parse_v3(path, value)?,
        "d" => l.d = parse_num(path, value)?,
        "r1" => l.r1 = parse_num(path, value)?,
        "r2" => l.r2 = parse_num(path, value)?,
        "n" | "n.glass" => index_field(&mut l.n, key == "n.glass", value, path)?,
        _ => return Err(unknown(path)),
    }
    Ok(())
}

/// A system's field; a new kind or preset is the library's new system of
/// that kind or preset at the same place, facing the same way, named the
/// same.
fn system_field(mut s: SystemFile, key: &str, value: &str, path: &str) -> Result<SystemFile, String> {
    let place = s.center.or(s.vertex).unwrap_or_default();
    let renew = |new: Option<SystemFile>, what: &str| {
        let mut new = new.ok_or_else(|| format!("error: {path}: not a {what}: \"{}\"", shown(value)))?;
        (new.name, new.tint) = (s.name.clone(), s.tint);
        Ok(new)
    };
    match key {
        "kind" if value == s.kind => {}
        "kind" => return renew(new_system(value, place, s.axis), "system kind"),
        "preset" => return renew(new_preset_system(value, place, s.axis), "preset"),
        "name" => s.name = named(value),
        "prescription" => s.prescription = Some(value.to_string()),
        "center" => s.center = Some(parse_v3(path, value)?),
        "vertex" => s.vertex = Some(parse_v3(path, value)?),
        "axis" => s.axis = parse_v3(path, value)?,
        "tint" => s.tint = parse_v3(path, value)?,
        "scale" => s.scale = Some(parse_num(path, value)?),
        "d" => s.d = Some(parse_num(path, value)?),
        "r" => s.r = Some(parse_num(path, value)?),
        "r1" => s.r1 = Some(parse_num(path, value)?),
        "r2" => s.r2 = Some(parse_num(path, value)?),
        "r3" => s.r3 = Some(parse_num(path, value)?),
        "thickness" => s.thickness = Some(parse_num(path, value)?),
        "thickness2" => s.thickness2 = Some(parse_num(path, value)?),
        "flat" => s.flat = (value == "front").then(|| "front".to_string()),
        _ => system_index_or_surface(&mut s, key, value, path)?,
    }
    Ok(s)
}

/// `n`, `n2` (with `.glass`) and the table's `surface.K.FIELD`.
fn system_index_or_surface(s: &mut SystemFile, key: &str, value: &str, path: &str) -> Result<(), String> {
    let (base, glass_key) = match key.strip_suffix(".glass") {
        Some(b) => (b, true),
        None => (key, false),
    };
    let n = match base {
        "n" => s.n.as_mut(),
        "n2" => s.n2.as_mut(),
        _ => None,
    };
    if let Some(n) = n {
        return index_field(n, glass_key, value, path);
    }
    let mut parts = key.splitn(3, '.');
    let (Some("surface"), Some(k), Some(field)) = (parts.next(), parts.next(), parts.next()) else {
        return Err(unknown(path));
    };
    let f = k
        .parse::<usize>()
        .ok()
        .and_then(|k| s.surfaces.as_mut()?.get_mut(k))
        .ok_or_else(|| unknown(path))?;
    match field {
        "radius" => f.radius = parse_num(path, value)?,
        "thickness" => f.thickness = parse_num(path, value)?,
        "semi_aperture" => f.semi_aperture = parse_num(path, value)?,
        "n" | "n.glass" => index_field(&mut f.n, field == "n.glass", value, path)?,
        _ => return Err(unknown(path)),
    }
    Ok(())
}
