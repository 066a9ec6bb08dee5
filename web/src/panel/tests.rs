//! The panel natively: its rows are the document's, every field edit goes
//! through the document (one undo step each), and a refused value is one
//! line that leaves the scene as it was.

use super::*;
use lensview::edit::Change;
use lensview::scene::file::IndexFile;

fn cubes() -> Document {
    Document::preset("cubes").unwrap()
}

fn field<'a>(p: &'a Panel, key: &str) -> &'a Field {
    p.fields
        .iter()
        .find(|f| f.key == key)
        .unwrap_or_else(|| panic!("no field {key}: {p:?}"))
}

#[test]
fn the_panel_lists_the_items_and_shows_the_lens() {
    let doc = cubes();
    let p = panel(&doc, "");
    assert_eq!(p.selected, "lens:0", "the first lens is selected first");
    let ids: Vec<&str> = p.items.iter().map(|(id, _)| id.as_str()).collect();
    assert_eq!(&ids[..4], ["camera", "render", "light:0", "object:0"]);
    assert!(ids.contains(&"lens:0"));
    assert_eq!(
        (field(&p, "r1").value.as_str(), field(&p, "n").value.as_str()),
        ("5", "1.5")
    );
    assert_eq!(field(&p, "center").value, "0, 4.313284, 6.933244");
    let glass = field(&p, "n.glass");
    assert_eq!((glass.kind, glass.value.as_str()), ("choice", ""));
    let bk7 = glass.options.iter().find(|(v, _)| v == "N-BK7").unwrap();
    assert!(bk7.1.contains("nd 1.5168") && bk7.1.contains("Abbe 64.1"), "{}", bk7.1);
    assert!(p.fields.iter().any(|f| f.label == "EFL (paraxial)"));
    assert_eq!((p.undo.as_deref(), p.redo.as_deref()), (None, None));
    // Gone or unknown selections fall back; other items have their rows.
    assert_eq!(panel(&doc, "lens:7").selected, "lens:0");
    assert_eq!(field(&panel(&doc, "camera"), "fov").value, "45");
    assert_eq!(field(&panel(&doc, "light:0"), "intensity").value, "500");
    assert!(panel(&doc, "object:1").fields.iter().any(|f| f.key == "color"));
    let json = serde_json::to_string(&p).unwrap();
    assert!(json.starts_with("{\"items\":[[\"camera\",\"camera\"]"), "{json}");
}

#[test]
fn each_field_is_one_undo_step_of_the_document() {
    let mut doc = cubes();
    let before = doc.scene().clone();
    let (msg, change) = set(&mut doc, "lens:0", "r1", "3.5").unwrap();
    assert_eq!((msg.as_str(), change), ("lenses[0].r1 = 3.5", Change::Picture));
    let mut want = before.clone();
    want.lenses[0].r1 = 3.5;
    assert!(doc.scene() == &want);
    set(&mut doc, "lens:0", "r2", "4").unwrap();
    set(&mut doc, "lens:0", "n.glass", "n-sf5").unwrap();
    assert!(matches!(doc.scene().lenses[0].n, IndexFile::Glass(g) if g.name == "N-SF5"));
    assert_eq!(doc.undo_depth(), 3, "three fields, three steps");
    assert_eq!(panel(&doc, "lens:0").undo.as_deref(), Some("edit lens"));
    doc.undo();
    doc.undo();
    assert_eq!(doc.scene().lenses[0].r1, 3.5);
    doc.undo();
    assert!(doc.scene() == &before);
    doc.redo();
    assert!(doc.scene() == &want);
    // The glass back to a number: its nd, rounded as the desktop does.
    set(&mut doc, "lens:0", "n.glass", "N-BK7").unwrap();
    set(&mut doc, "lens:0", "n.glass", "").unwrap();
    assert_eq!(doc.scene().lenses[0].n, IndexFile::Constant(1.5168));
    // The camera keeps the photon map; a colour of a shared material.
    assert_eq!(set(&mut doc, "camera", "fov", "50").unwrap().1, Change::Camera);
    set(&mut doc, "object:1", "color", "0.1 0.2 0.3").unwrap();
    let m = doc.scene().objects[1].material.clone().unwrap();
    assert_eq!(doc.scene().materials[&m].color, [0.1, 0.2, 0.3]);
    set(&mut doc, "light:0", "kind", "directional").unwrap();
    assert!(doc.scene().lights[0].position.is_none());
}

#[test]
fn a_refused_value_is_one_line_and_the_scene_stays() {
    let mut doc = cubes();
    let before = doc.scene().clone();
    let cases = [
        ("lens:0", "r1", "abc", "error: lenses[0].r1: not a number: \"abc\""),
        ("lens:0", "r1", "nan", "error: lenses[0].r1: not a number: \"nan\""),
        (
            "lens:0",
            "center",
            "1, 2",
            "error: lenses[0].center: not three numbers: \"1, 2\"",
        ),
        ("lens:0", "bogus", "1", "error: lenses[0].bogus: no such field"),
        ("lens:9", "r1", "1", "error: no item \"lens:9\" in the scene"),
    ];
    for (id, key, value, want) in cases {
        assert_eq!(set(&mut doc, id, key, value).unwrap_err(), want);
    }
    // The library's own checks: a radius under d/2, an unknown glass.
    let e = set(&mut doc, "lens:0", "r1", "0.5").unwrap_err();
    assert!(e.starts_with("error: lenses[0]") && !e.contains('\n'), "{e}");
    let e = set(&mut doc, "lens:0", "n.glass", "unobtainium").unwrap_err();
    assert!(
        e.starts_with("error: lenses[0].n.glass: unknown glass \"unobtainium\"; known glasses: N-BK7"),
        "{e}"
    );
    let e = set(&mut doc, "lens:0", "d", "-1\n").unwrap_err();
    assert!(e.starts_with("error: lenses[0]") && !e.contains('\n'), "{e}");
    assert!(doc.scene() == &before);
    assert_eq!(doc.undo_depth(), 0);
}

#[test]
fn a_system_takes_the_librarys_kinds_presets_and_glasses() {
    let mut doc = Document::preset("achromat").unwrap();
    let p = panel(&doc, "system:0");
    assert_eq!(field(&p, "kind").value, "preset");
    assert!(field(&p, "kind").options.iter().any(|(k, _)| k == "doublet"));
    assert_eq!(field(&p, "preset").value, "achromat-AC254-100-A");
    assert!(p.fields.iter().any(|f| f.label == "f-number"));
    let name = doc.scene().systems[0].name.clone();
    set(&mut doc, "system:0", "preset", "cooke-triplet-100mm").unwrap();
    let s = &doc.scene().systems[0];
    assert_eq!((s.preset.as_deref(), &s.name), (Some("cooke-triplet-100mm"), &name));
    set(&mut doc, "system:0", "kind", "surfaces").unwrap();
    let p = panel(&doc, "system:0");
    assert!(field(&p, "surface.0.semi_aperture").value.parse::<f64>().unwrap() > 0.0);
    set(&mut doc, "system:0", "surface.0.radius", "3.9").unwrap();
    assert_eq!(doc.scene().systems[0].surfaces.as_ref().unwrap()[0].radius, 3.9);
    set(&mut doc, "system:0", "surface.0.n.glass", "N-SF5").unwrap();
    set(&mut doc, "system:0", "kind", "doublet").unwrap();
    set(&mut doc, "system:0", "n2", "1.7").unwrap();
    assert_eq!(doc.scene().systems[0].n2, Some(IndexFile::Constant(1.7)));
    assert!(
        set(&mut doc, "system:0", "kind", "blimp")
            .unwrap_err()
            .contains("not a system kind")
    );
    assert_eq!(doc.undo_depth(), 6);
}

/// `act`'s selection and change, unwrapped.
fn act_ok(doc: &mut Document, id: &str, action: &str) -> (String, Change) {
    let (_, selected, change) = act(doc, id, action).unwrap_or_else(|e| panic!("{action}: {e}"));
    (selected, change)
}

#[test]
fn the_add_menu_adds_the_desktops_items_each_one_undo_step() {
    use lensview::edit::document::{NEW_DISTANCE, NewItem};
    use lensview::edit::{Item, Placement};
    let mut doc = cubes();
    let before = doc.scene().clone();
    let adds: Vec<String> = panel(&doc, "").adds.into_iter().map(|(a, _)| a).collect();
    let kinds = [
        "cuboid",
        "prism",
        "sphere",
        "pyramid",
        "lens",
        "biconvex",
        "preset:cooke-triplet-100mm",
    ];
    for (n, what) in kinds.iter().enumerate() {
        let action = format!("add:{what}");
        assert!(adds.contains(&action), "{action} not in the menu: {adds:?}");
        // What the desktop's Add form makes of the same kind at its defaults.
        let mut want = Document::new(doc.scene().clone(), lensview::edit::Source::Default).unwrap();
        let at = want.place(Placement::InFrontOfCamera(NEW_DISTANCE));
        let (kind, preset) = what.split_once(':').unwrap_or((what, ""));
        let item = want.add_new(NewItem::of(kind, preset, at).unwrap()).unwrap();
        let (selected, change) = act_ok(&mut doc, "lens:0", &action);
        assert_eq!((selected, change), (Target::Item(item).id(), Change::Picture));
        assert!(doc.scene() == want.scene(), "{what}");
        assert_eq!(doc.undo_depth(), n + 1, "{what}: one step");
        assert_eq!(panel(&doc, &Target::Item(item).id()).selected, Target::Item(item).id());
    }
    let s = doc.scene();
    let shapes: Vec<&str> = s.objects[before.objects.len()..]
        .iter()
        .map(|o| o.kind.name())
        .collect();
    assert_eq!(shapes, ["cuboid", "prism", "sphere", "pyramid"]);
    assert!(
        s.objects
            .last()
            .unwrap()
            .name
            .as_deref()
            .unwrap()
            .starts_with("pyramid")
    );
    assert_eq!(s.systems.len(), before.systems.len() + 2);
    assert!(doc.contains(Item::Lens(before.lenses.len())));
    let (selected, _) = act_ok(&mut doc, "camera", "add:light");
    assert_eq!(selected, format!("light:{}", before.lights.len()));
    while doc.undo().is_some() {}
    assert!(doc.scene() == &before, "undo restores the scene exactly");
}

#[test]
fn delete_duplicate_and_own_material_are_the_documents() {
    let mut doc = cubes();
    let before = doc.scene().clone();
    assert_eq!(
        panel(&doc, "object:0")
            .actions
            .iter()
            .map(|(a, _)| a.as_str())
            .take(2)
            .collect::<Vec<_>>(),
        ["duplicate", "delete"]
    );
    let (selected, change) = act_ok(&mut doc, "object:0", "delete");
    assert_eq!((selected.as_str(), change), ("", Change::Picture));
    assert_eq!(doc.scene().objects.len(), before.objects.len() - 1);
    assert_eq!(&doc.scene().objects[..], &before.objects[1..]);
    assert!(
        doc.undo_label().unwrap().starts_with("delete "),
        "{:?}",
        doc.undo_label()
    );
    doc.undo();
    assert!(doc.scene() == &before, "undo brings the deleted item back exactly");
    let (selected, _) = act_ok(&mut doc, "lens:0", "duplicate");
    assert_eq!(selected, format!("lens:{}", before.lenses.len()));
    let copy = doc.scene().lenses.last().unwrap();
    assert!(copy.name.as_deref().unwrap().ends_with("copy"), "{copy:?}");
    act_ok(&mut doc, "light:0", "delete");
    assert_eq!(doc.scene().lights.len(), before.lights.len() - 1);
    assert_eq!(doc.undo_depth(), 2);
    doc.undo();
    doc.undo();
    assert!(doc.scene() == &before);
}

#[test]
fn names_materials_and_prescriptions_are_fields() {
    let mut doc = cubes();
    let before = doc.scene().clone();
    set(&mut doc, "object:0", "name", "plinth").unwrap();
    assert_eq!(doc.scene().objects[0].name.as_deref(), Some("plinth"));
    assert!(
        items(&doc)
            .iter()
            .any(|(id, l)| id == "object:0" && l.starts_with("plinth ("))
    );
    set(&mut doc, "lens:0", "name", "loupe").unwrap();
    assert_eq!(doc.scene().lenses[0].name.as_deref(), Some("loupe"));
    // Every field the desktop's material editor shows.
    let p = panel(&doc, "object:1");
    for key in [
        "material",
        "color",
        "ambient",
        "diffuse",
        "specular",
        "shininess",
        "reflectivity",
        "transparency",
        "ior",
        "ior.glass",
    ] {
        field(&p, key);
    }
    set(&mut doc, "object:1", "diffuse", "0.25").unwrap();
    set(&mut doc, "object:1", "shininess", "64").unwrap();
    set(&mut doc, "object:1", "ior.glass", "N-BK7").unwrap();
    let m = &doc.scene().materials[doc.scene().objects[1].material.as_ref().unwrap()];
    assert_eq!((m.diffuse, m.shininess), (0.25, 64.0));
    assert!(matches!(m.ior, IndexFile::Glass(g) if g.name == "N-BK7"));
    assert_eq!(field(&panel(&doc, "object:1"), "diffuse").value, "0.25");
    assert_eq!(doc.undo_depth(), 5, "one step a field");
    while doc.undo().is_some() {}
    assert!(doc.scene() == &before);
    // A prescription's table, as the desktop's text box edits it.
    let mut doc = Document::preset("achromat").unwrap();
    set(&mut doc, "system:0", "kind", "prescription").unwrap();
    let p = panel(&doc, "system:0");
    assert_eq!(field(&p, "prescription").kind, "lines");
    let table = "50 4 1.5168 25\n-50 10 1 25\n";
    set(&mut doc, "system:0", "prescription", table).unwrap();
    assert_eq!(doc.scene().systems[0].prescription.as_deref(), Some(table));
    assert_eq!(field(&panel(&doc, "system:0"), "prescription").value, table);
}

#[test]
fn render_settings_and_the_lens_camera_are_the_documents() {
    let mut doc = cubes();
    let before = doc.scene().clone();
    assert!(items(&doc).iter().any(|(id, _)| id == "render"));
    set(&mut doc, "render", "max_depth", "3").unwrap();
    set(&mut doc, "render", "shadows", "off").unwrap();
    set(&mut doc, "render", "caustics", "off").unwrap();
    set(&mut doc, "render", "tone", "aces").unwrap();
    set(&mut doc, "render", "ambient", "0.2").unwrap();
    let s = doc.scene();
    assert_eq!(
        (s.render.max_depth, s.render.shadows, s.render.caustics),
        (3, false, Some(false))
    );
    assert_eq!((s.display.tone.name(), s.ambient.intensity), ("aces", 0.2));
    assert_eq!(field(&panel(&doc, "render"), "caustics").value, "off");
    assert_eq!(doc.undo_depth(), 5);
    // The lens camera: on, focused, stopped down; each one step.
    assert_eq!(field(&panel(&doc, "camera"), "lens_camera").value, "pinhole");
    let (_, change) = set(&mut doc, "camera", "lens_camera", "lens").unwrap();
    assert_ne!(change, Change::None);
    assert!(doc.lens_camera_on());
    set(&mut doc, "camera", "focus", "5").unwrap();
    set(&mut doc, "camera", "f_number", "8").unwrap();
    let lens = doc.built().lens.clone().unwrap();
    assert_eq!((lens.focus_distance, doc.scene().camera.f_number), (5.0, Some(8.0)));
    assert!((lens.f_number - 8.0).abs() < 1e-9, "{}", lens.f_number);
    let p = panel(&doc, "camera");
    assert_eq!(
        (field(&p, "focus").value.as_str(), field(&p, "f_number").value.as_str()),
        ("5", "8")
    );
    set(&mut doc, "camera", "focus", "").unwrap();
    assert!(!doc.built().lens.as_ref().unwrap().focus_distance.is_finite());
    assert_eq!(doc.undo_depth(), 9);
    while doc.undo().is_some() {}
    assert!(doc.scene() == &before);
}

#[test]
fn a_refused_edit_or_action_is_one_line_and_changes_nothing() {
    let mut doc = cubes();
    let before = doc.scene().clone();
    let sets = [
        (
            "render",
            "max_depth",
            "2.5",
            "error: render.max_depth: not a whole number: \"2.5\"",
        ),
        (
            "render",
            "caustics",
            "maybe",
            "error: render.caustics: not on or off: \"maybe\"",
        ),
        (
            "render",
            "tone",
            "sepia",
            "error: render.tone: not a tone curve: \"sepia\"",
        ),
        (
            "camera",
            "lens_camera",
            "eye",
            "error: camera.lens_camera: not pinhole or lens: \"eye\"",
        ),
        (
            "object:1",
            "diffuse",
            "x",
            "error: objects[1].diffuse: not a number: \"x\"",
        ),
    ];
    for (id, key, value, want) in sets {
        assert_eq!(set(&mut doc, id, key, value).unwrap_err(), want);
    }
    let acts = [
        ("object:99", "delete", "error: no item \"object:99\" in the scene"),
        ("camera", "delete", "error: camera: no action \"delete\""),
        ("camera", "add:blimp", "error: nothing to add called \"blimp\""),
    ];
    for (id, action, want) in acts {
        assert_eq!(act(&mut doc, id, action).unwrap_err(), want);
    }
    // The library's own checks.
    let e = set(&mut doc, "render", "max_depth", "65").unwrap_err();
    assert!(e.starts_with("error: render.max_depth") && !e.contains('\n'), "{e}");
    assert!(doc.scene() == &before);
    assert_eq!(doc.undo_depth(), 0);
    set(&mut doc, "object:1", "reflectivity", "0.9").unwrap();
    let e = set(&mut doc, "object:1", "transparency", "0.9").unwrap_err();
    assert!(e.contains("reflectivity + transparency") && !e.contains('\n'), "{e}");
    assert_eq!(doc.undo_depth(), 1, "the refusal made no step");
    doc.undo();
    assert!(doc.scene() == &before);
}
