//! The panel's buttons: the *Add* menu (the desktop *Add* form's items at
//! its default sizes and place, `NewItem::of` and `Document::add_new`; a
//! point light as the light section's `add_point_light`), and what can be
//! done to the selected item (*Duplicate*, *Delete*, *Give it a material
//! of its own*), each the desktop's `Document` call and one undo step.

use super::Target;
use super::edit::shown;
use lensview::edit::document::{NEW_DISTANCE, NewItem, Rejected};
use lensview::edit::{Change, Document, Item, Placement};
use lensview::prescription::PRESETS;
use lensview::scene::SYSTEM_KINDS;
use lensview::scene::escape_controls;

/// What the *Add* menu offers: (action, label). `add:KIND` for the
/// primitives, a lens and each system kind, `add:preset:NAME` for each
/// system preset, `add:light` for a point light.
pub fn adds() -> Vec<(String, String)> {
    let mut v: Vec<(String, String)> = ["cuboid", "prism", "sphere", "pyramid", "lens"]
        .iter()
        .map(|k| (format!("add:{k}"), k.to_string()))
        .collect();
    v.push(("add:light".into(), "point light".into()));
    for k in SYSTEM_KINDS.iter().filter(|k| **k != "preset") {
        v.push((format!("add:{k}"), format!("system: {k}")));
    }
    for (p, _) in PRESETS {
        v.push((format!("add:preset:{p}"), format!("system preset: {p}")));
    }
    v
}

/// The buttons of the selected item: (action, label).
pub fn actions(doc: &Document, target: Target) -> Vec<(String, String)> {
    let pair = |a: &str, l: &str| (a.to_string(), l.to_string());
    match target {
        Target::Camera | Target::Render => Vec::new(),
        Target::Light(_) => vec![pair("delete", "Delete")],
        Target::Item(item) => {
            let mut v = vec![pair("duplicate", "Duplicate"), pair("delete", "Delete")];
            if let Item::Object(i) = item {
                let own = match &doc.scene().objects[i].material {
                    Some(m) if doc.scene().materials.contains_key(m) => doc.material_users(m) > 1,
                    _ => true,
                };
                if own {
                    v.push(pair("own-material", "Give it a material of its own"));
                }
            }
            v
        }
    }
}

/// Does `action` (one of [`adds`] or [`actions`]) with item `id` selected.
/// Returns what was done, the item to select then (`""`: the panel's
/// first), and what changed; or the one line (`error: …`) saying why not.
pub fn act(doc: &mut Document, id: &str, action: &str) -> Result<(String, String, Change), String> {
    let target = Target::parse(id).filter(|t| t.exists(doc));
    let r = match (action.strip_prefix("add:"), target) {
        (Some(what), _) => add(doc, what),
        (None, Some(target)) => on_item(doc, target, action),
        (None, None) => return Err(format!("error: no item \"{}\" in the scene", shown(id))),
    };
    doc.seal();
    let (msg, selected, change) = r?;
    Ok((msg, selected.map_or_else(String::new, Target::id), change))
}

type Done = Result<(String, Option<Target>, Change), String>;

/// The library's refusal as the page's one line.
fn refused(e: Rejected) -> String {
    format!("error: {}", escape_controls(&e.to_string()))
}

/// The *Add* menu's `what`, in front of the camera.
fn add(doc: &mut Document, what: &str) -> Done {
    if what == "light" {
        let k = doc.add_point_light().map_err(refused)?;
        return Ok((
            "added a point light above the camera".into(),
            Some(Target::Light(k)),
            Change::Picture,
        ));
    }
    let position = doc.place(Placement::InFrontOfCamera(NEW_DISTANCE));
    let (kind, preset) = what.split_once(':').unwrap_or((what, ""));
    let Some(new) = NewItem::of(kind, preset, position) else {
        return Err(format!("error: nothing to add called \"{}\"", shown(what)));
    };
    let item = doc.add_new(new).map_err(refused)?;
    let p = position;
    let msg = format!(
        "added {} at ({:.2}, {:.2}, {:.2})",
        doc.item_name(item),
        p[0],
        p[1],
        p[2]
    );
    Ok((msg, Some(Target::Item(item)), Change::Picture))
}

/// *Delete*, *Duplicate* or *Give it a material of its own* on `target`.
fn on_item(doc: &mut Document, target: Target, action: &str) -> Done {
    match (action, target) {
        ("delete", Target::Light(k)) => {
            let change = doc.delete_light(k).map_err(refused)?;
            Ok((format!("deleted light {}", k + 1), None, change))
        }
        ("delete", Target::Item(item)) => {
            let name = doc.item_name(item);
            let change = doc.delete(item).map_err(refused)?;
            Ok((format!("deleted {name}"), None, change))
        }
        ("duplicate", Target::Item(item)) => {
            let copy = doc.duplicate(item).map_err(refused)?;
            let msg = copy.map_or_else(String::new, |c| format!("added {}", doc.item_name(c)));
            Ok((msg, copy.map(Target::Item).or(Some(target)), Change::Picture))
        }
        ("own-material", Target::Item(Item::Object(i))) => {
            let change = doc.give_own_material(i).map_err(refused)?;
            Ok(("the object has its own material now".into(), Some(target), change))
        }
        _ => Err(format!("error: {}: no action \"{}\"", target.path(), shown(action))),
    }
}
