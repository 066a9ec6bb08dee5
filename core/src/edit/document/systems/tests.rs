//! Lens systems in a document, without a window: the *Objects* list of
//! scenes/lens-family.toml, select/delete/duplicate with undo, a new
//! system of every kind and preset, the fields, the table of surfaces and
//! the lens keys on a system.

use super::super::{Change, Document, Item};
use super::*;
use crate::edit::Edit;
use crate::scene::SYSTEM_KINDS;
use glam::DVec3;

fn family() -> Document {
    Document::preset("lens family").unwrap()
}

fn cubes() -> Document {
    Document::preset("cubes").unwrap()
}

#[test]
fn the_lens_family_lists_its_systems_and_they_delete_duplicate_and_undo() {
    let mut doc = family();
    let items = doc.items();
    let systems: Vec<_> = items.iter().filter(|(i, _)| matches!(i, Item::System(_))).collect();
    assert_eq!(systems.len(), 3);
    assert_eq!(systems[0], &(Item::System(0), "plano-convex condenser".to_string()));
    assert_eq!(doc.item_name(Item::System(2)), "meniscus");
    assert!(doc.contains(Item::System(2)) && !doc.contains(Item::System(3)));
    assert_eq!(doc.item_name(Item::System(3)), "");
    assert!(doc.built_system(2).is_some() && doc.built_system(3).is_none());

    let before = doc.scene().clone();
    let n = doc.built().objects.len();
    assert_eq!(doc.delete(Item::System(1)).unwrap(), Change::Picture);
    assert_eq!(doc.undo_label(), Some("delete biconcave diverger"));
    assert_eq!(doc.item_name(Item::System(1)), "meniscus");
    assert_eq!(doc.built().objects.len(), n - 1);
    let copy = doc.duplicate(Item::System(1)).unwrap().unwrap();
    assert_eq!(copy, Item::System(2));
    assert_eq!(doc.item_name(copy), "meniscus copy");
    let (a, b) = (&doc.scene().systems[1], &doc.scene().systems[2]);
    assert!(
        b.center.unwrap()[0] > a.center.unwrap()[0] + 2.2,
        "moved aside by its width"
    );
    assert_eq!((a.r1, a.r2, a.thickness), (b.r1, b.r2, b.thickness));
    assert_eq!(doc.delete(Item::System(7)).unwrap(), Change::None);
    assert_eq!(doc.duplicate(Item::System(7)).unwrap(), None);
    while doc.undo().is_some() {}
    assert_eq!(doc.scene(), &before);
    assert!(!doc.is_dirty());
}

#[test]
fn a_new_system_of_every_kind_and_preset_is_valid_and_about_two_across() {
    let mut doc = cubes();
    for kind in SYSTEM_KINDS {
        let s = new_system(kind, [0.0, 3.0, 2.0], [0.0, 0.0, 1.0]).unwrap();
        let item = doc.add_system(s).unwrap_or_else(|e| panic!("{kind}: {e}"));
        let Item::System(i) = item else { panic!("{item:?}") };
        let width = 2.0 * doc.built_system(i).unwrap().radius();
        assert!((1.5..=2.5).contains(&width), "{kind}: {width}");
        assert!(!doc.item_name(item).is_empty());
    }
    assert!(new_system("no such kind", [0.0; 3], [0.0, 0.0, 1.0]).is_none());
    for (name, _) in crate::prescription::PRESETS {
        let s = new_preset_system(name, [0.0, -3.0, 2.0], [0.0, 0.0, 1.0]).unwrap();
        let item = doc
            .add_system_facing_camera(s)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(doc.item_name(item).starts_with(name), "named after its preset");
        let Item::System(i) = item else { panic!() };
        let sys = doc.built_system(i).unwrap();
        assert!(
            (2.0 * sys.radius() - 2.0).abs() < 0.05,
            "{name}: {}",
            2.0 * sys.radius()
        );
        let facing = DVec3::from(doc.scene().systems[i].axis).dot(-doc.built().camera.forward());
        assert!((facing - 1.0).abs() < 1e-9);
    }
    assert!(new_preset_system("no-such-preset", [0.0; 3], [0.0, 0.0, 1.0]).is_none());
    let added = SYSTEM_KINDS.len() + crate::prescription::PRESETS.len();
    assert_eq!(doc.scene().systems.len(), added);
    assert_eq!(doc.undo_depth(), added);
    // Saved and read back, the systems are the same.
    let text = crate::edit::document::to_toml(doc.scene()).unwrap();
    assert!(text.contains("[[systems]]"));
    let (back, _) = crate::scene::Scene::parse("t.toml", &text).unwrap();
    assert_eq!(back.systems, doc.scene().systems);
}

#[test]
fn system_fields_are_one_merged_step_and_an_impossible_one_is_refused() {
    let mut doc = family();
    let mut s = doc.scene().systems[0].clone();
    s.d = Some(2.0);
    assert_eq!(doc.set_system(0, s.clone()).unwrap(), Change::Picture);
    s.n = Some(IndexFile::Glass(crate::glass::lookup("N-SF11").unwrap()));
    doc.set_system(0, s.clone()).unwrap();
    assert_eq!(doc.undo_depth(), 1, "merged while dragging");
    assert_eq!(doc.undo_label(), Some("edit plano-convex condenser"));
    let good = doc.scene().clone();
    // A diameter larger than the curved face's sphere: refused, named.
    s.d = Some(6.0);
    let e = doc.set_system(0, s).unwrap_err();
    assert!(e.concerns("systems[0]"), "{e}");
    assert_eq!(doc.scene(), &good);
    doc.undo().unwrap();
    assert_eq!(doc.scene(), family().scene());
}

#[test]
fn the_table_of_surfaces_inserts_removes_and_moves_rows_with_undo() {
    let mut doc = family();
    assert_eq!(doc.insert_surface(0, 0).unwrap(), Change::None, "not a table yet");
    let efl = |d: &Document| d.built_system(1).unwrap().paraxial(crate::optics::WAVELENGTH_D_UM).efl;
    let before = efl(&doc);
    assert_eq!(doc.system_to_surfaces(1).unwrap(), Change::Picture);
    let s = &doc.scene().systems[1];
    assert_eq!((s.kind.as_str(), s.surfaces.as_ref().unwrap().len()), ("surfaces", 2));
    assert!((efl(&doc) - before).abs() < 1e-9 * before.abs(), "same optics");
    // A plane inside the glass changes nothing optical.
    doc.insert_surface(1, 0).unwrap();
    let table = doc.scene().systems[1].surfaces.clone().unwrap();
    assert_eq!(table.len(), 3);
    assert_eq!((table[1].radius, table[1].n), (0.0, table[0].n));
    assert!((table[0].thickness + table[1].thickness - 0.15).abs() < 1e-12);
    assert!((efl(&doc) - before).abs() < 1e-9 * before.abs());
    // Behind the last surface: a plane in air.
    doc.insert_surface(1, 2).unwrap();
    assert_eq!(doc.scene().systems[1].surfaces.as_ref().unwrap().len(), 4);
    doc.remove_surface(1, 3).unwrap();
    doc.remove_surface(1, 1).unwrap();
    assert_eq!(doc.scene().systems[1].surfaces.as_ref().unwrap()[0].thickness, 0.15);
    // Moving the glass face last leaves glass after the last surface: refused.
    let e = doc.move_surface(1, 0, false).unwrap_err();
    assert!(e.concerns("systems[1]"), "{e}");
    assert_eq!(
        doc.move_surface(1, 0, true).unwrap(),
        Change::None,
        "nothing above the first"
    );
    assert_eq!(doc.move_surface(1, 9, false).unwrap(), Change::None);
    assert_eq!(doc.remove_surface(1, 9).unwrap(), Change::None);
    while doc.undo().is_some() {}
    assert_eq!(doc.scene(), family().scene());
}

#[test]
fn lens_keys_move_turn_and_reshape_the_selected_system() {
    let mut doc = family();
    let c0 = DVec3::from(doc.scene().systems[1].center.unwrap());
    let a = DVec3::from(doc.scene().systems[1].axis).normalize();
    let (msg, change) = doc.apply_system_edit(1, Edit::LensAlongAxis(0.5)).unwrap();
    assert_eq!(change, Change::Picture);
    assert!(msg.starts_with("biconcave diverger: centre"), "{msg}");
    let c1 = DVec3::from(doc.scene().systems[1].center.unwrap());
    assert!((c1 - (c0 + 0.5 * a)).length() < 1e-12);
    doc.apply_system_edit(1, Edit::LensMove(DVec3::X)).unwrap();
    assert_eq!(doc.scene().systems[1].center.unwrap()[0], c1.x + 1.0);
    doc.apply_system_edit(1, Edit::LensTurn { yaw: 20.0, pitch: 0.0 })
        .unwrap();
    let turned = DVec3::from(doc.scene().systems[1].axis);
    assert!((turned.length() - 1.0).abs() < 1e-12 && turned.dot(a) < 0.99);
    // r1 grows in magnitude; n steps; d steps.
    doc.apply_system_edit(1, Edit::LensR1(0.5)).unwrap();
    assert_eq!(doc.scene().systems[1].r1, Some(3.5));
    let (msg, _) = doc.apply_system_edit(1, Edit::LensIndex(0.1)).unwrap();
    assert!(msg.contains("n = 1.6168"), "{msg}");
    doc.apply_system_edit(1, Edit::LensDiameter(-0.2)).unwrap();
    assert_eq!(doc.scene().systems[1].d, Some(2.0));
    // Too wide for r1 = 3.5: refused, nothing changed.
    let before = doc.scene().clone();
    assert!(doc.apply_system_edit(1, Edit::LensDiameter(10.0)).is_err());
    assert_eq!(doc.scene(), &before);
    // The lens keys leave the other systems and the light alone; a light
    // key still moves the light.
    assert_eq!(doc.scene().systems[0], family().scene().systems[0]);
    doc.apply_system_edit(1, Edit::LightMove(DVec3::Y)).unwrap();
    assert_eq!(doc.scene().lights[0].position.unwrap()[1], 4.0);
}

#[test]
fn keys_on_a_preset_step_its_scale_and_say_what_has_no_key() {
    let mut doc = cubes();
    let s = new_preset_system("cooke-triplet-100mm", [0.0, 3.0, 2.0], [0.0, 0.0, 1.0]).unwrap();
    let Item::System(i) = doc.add_system(s).unwrap() else {
        panic!()
    };
    let scale = doc.scene().systems[i].scale.unwrap();
    doc.apply_system_edit(i, Edit::LensDiameter(0.2)).unwrap();
    let grown = doc.scene().systems[i].scale.unwrap();
    assert!((grown / scale - 1.1).abs() < 1e-12);
    let depth = doc.undo_depth();
    let (msg, change) = doc.apply_system_edit(i, Edit::LensIndex(0.1)).unwrap();
    assert!(msg.contains("has no `n`"), "{msg}");
    assert_eq!((change, doc.undo_depth()), (Change::None, depth));
    let (msg, _) = doc.apply_system_edit(i, Edit::LensR2(0.1)).unwrap();
    assert!(msg.contains("no radius key"), "{msg}");
    // Moving a vertex-placed system moves its vertex.
    doc.system_to_surfaces(i).unwrap();
    let v = doc.scene().systems[i].vertex.unwrap();
    doc.apply_system_edit(i, Edit::LensMove(DVec3::Y)).unwrap();
    assert_eq!(doc.scene().systems[i].vertex.unwrap()[1], v[1] + 1.0);
}

#[test]
fn preset_scales_make_two_units_and_kind_labels_name_presets() {
    for (name, _) in crate::prescription::PRESETS {
        let s = preset_scale(name).unwrap();
        assert!(s > 0.0 && s < 1.0, "{name}: {s}");
    }
    assert_eq!(preset_scale("nothing"), None);
    let s = new_system("doublet", [0.0; 3], [0.0, 0.0, 1.0]).unwrap();
    assert_eq!(system_kind_label(&s), "doublet");
}

/// The panel's *flat face* switch (a record edit, as the other fields):
/// the plano-convex condenser turned the other way round keeps its centre
/// and focal length; an unknown side is refused; undo restores it.
#[test]
fn the_flat_face_of_a_plano_kind_switches_sides_with_undo() {
    let mut doc = family();
    let built = |d: &Document| d.built_system(0).unwrap().clone();
    let before = built(&doc);
    let efl = |s: &crate::geometry::LensSystem| s.paraxial(crate::optics::WAVELENGTH_D_UM).efl;
    assert_eq!(doc.scene().systems[0].flat, None, "the flat face at the back");
    assert!(before.surfaces[0].curvature() > 0.0 && before.surfaces[1].curvature() == 0.0);
    let mut s = doc.scene().systems[0].clone();
    s.flat = Some("front".into());
    assert_eq!(doc.set_system(0, s.clone()).unwrap(), Change::Picture);
    let front = built(&doc);
    assert!(front.surfaces[0].curvature() == 0.0 && front.surfaces[1].curvature() < 0.0);
    assert_eq!(front.length(), before.length());
    assert!((front.vertex - before.vertex).length() < 1e-12, "the centre stays");
    assert!((efl(&front) - efl(&before)).abs() < 1e-12 * efl(&before));
    s.flat = Some("back".into());
    doc.set_system(0, s.clone()).unwrap();
    assert_eq!(built(&doc).surfaces, before.surfaces);
    s.flat = Some("side".into());
    let e = doc.set_system(0, s).unwrap_err();
    assert!(
        e.concerns("systems[0]") && e.to_string().contains("`front` or `back`"),
        "{e}"
    );
    assert_eq!(doc.undo_depth(), 1, "one merged step");
    doc.undo().unwrap();
    assert_eq!(doc.scene(), family().scene());
}

/// Placing a system by its first vertex or by its centre converts the one
/// point to the other: the system as built does not move; saved, the file
/// has the key chosen; undo restores it.
#[test]
fn placing_by_vertex_or_centre_keeps_the_system_where_it_is() {
    let mut doc = family();
    let vertex = |d: &Document| d.built_system(2).unwrap().vertex;
    let (v0, c0) = (vertex(&doc), DVec3::from(doc.scene().systems[2].center.unwrap()));
    assert_eq!(
        doc.place_system(2, false).unwrap(),
        Change::None,
        "already by its centre"
    );
    assert_ne!(doc.place_system(2, true).unwrap(), Change::None);
    assert_eq!(doc.undo_label(), Some("place meniscus by its first vertex"));
    let s = &doc.scene().systems[2];
    assert!(s.center.is_none());
    assert!((DVec3::from(s.vertex.unwrap()) - v0).length() < 1e-12);
    assert!((vertex(&doc) - v0).length() < 1e-12, "it did not move");
    let text = crate::edit::document::to_toml(doc.scene()).unwrap();
    let (back, _) = crate::scene::Scene::parse("t.toml", &text).unwrap();
    assert_eq!(back.systems[2].vertex, doc.scene().systems[2].vertex);
    doc.place_system(2, false).unwrap();
    assert_eq!(doc.undo_label(), Some("place meniscus by its centre"));
    let c = DVec3::from(doc.scene().systems[2].center.unwrap());
    assert!((c - c0).length() < 1e-12, "{c} {c0}");
    assert!(doc.scene().systems[2].vertex.is_none());
    assert_eq!(doc.place_system(9, true).unwrap(), Change::None);
    while doc.undo().is_some() {}
    assert_eq!(doc.scene(), family().scene());
}
