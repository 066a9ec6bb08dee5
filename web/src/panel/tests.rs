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
    assert_eq!(&ids[..3], ["camera", "light:0", "object:0"]);
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
