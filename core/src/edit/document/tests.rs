//! The edit model without a window: add, delete, duplicate, change, undo and
//! redo, merged steps, rejected edits, dirty state, save and load.

use super::*;
use crate::edit::presets::PRESETS;
use crate::scene::file::{IndexFile, LightKind, MaterialFile, ShapeKind};

fn cubes() -> Document {
    Document::preset("cubes").unwrap()
}

/// `name` in a folder of its own, removed when the folder is dropped.
fn tmp(name: &str) -> (tempfile::TempDir, PathBuf) {
    let d = tempfile::Builder::new().prefix("lensview-doc-").tempdir().unwrap();
    let path = d.path().join(name);
    (d, path)
}

#[test]
fn add_sphere_changes_the_picture_and_undo_redo_restore_it() {
    let mut doc = cubes();
    let before = doc.scene().clone();
    let n = doc.built().objects.len();
    assert!(!doc.is_dirty());
    let pos = in_front_of_camera(doc.built(), 5.0);
    let item = doc
        .add_object(
            new_object(ShapeKind::Sphere, pos),
            Some(("sphere".into(), new_material([0.9, 0.2, 0.1]))),
        )
        .unwrap();
    assert_eq!(item, Item::Object(26));
    assert_eq!(doc.built().objects.len(), n + 1);
    assert!(doc.is_dirty());
    assert_eq!(doc.item_name(item), "sphere");
    let o = &doc.scene().objects[26];
    assert_eq!(o.radius, Some(0.5));
    assert_eq!(o.material.as_deref(), Some("sphere"));
    assert_eq!(doc.scene().materials["sphere"].color, [0.9, 0.2, 0.1]);
    assert_eq!(doc.undo_label(), Some("add sphere"));
    assert!(doc.title().ends_with(" *"));

    let (label, change) = doc.undo().unwrap();
    assert_eq!((label.as_str(), change), ("add sphere", Change::Picture));
    assert_eq!(doc.scene(), &before);
    assert!(!doc.is_dirty(), "undoing back to the opened scene is clean");
    assert!(doc.undo().is_none());
    let (_, change) = doc.redo().unwrap();
    assert_eq!(change, Change::Picture);
    assert_eq!(doc.built().objects.len(), n + 1);
    assert!(doc.redo().is_none());
}

#[test]
fn every_primitive_and_a_lens_can_be_added_deleted_and_duplicated() {
    let mut doc = cubes();
    for kind in [
        ShapeKind::Cuboid,
        ShapeKind::Prism,
        ShapeKind::Sphere,
        ShapeKind::Pyramid,
    ] {
        let item = doc.add_object(new_object(kind, [0.0, 3.0, 0.0]), None).unwrap();
        assert_eq!(doc.item_name(item), kind.name());
        let copy = doc.duplicate(item).unwrap().unwrap();
        assert_eq!(doc.item_name(copy), format!("{} copy", kind.name()));
        let (Item::Object(a), Item::Object(b)) = (item, copy) else {
            panic!()
        };
        let (oa, ob) = (&doc.scene().objects[a], &doc.scene().objects[b]);
        assert!(ob.position[0] > oa.position[0], "the copy is moved aside");
        assert_eq!(
            (oa.size, oa.radius, oa.side, oa.height),
            (ob.size, ob.radius, ob.side, ob.height)
        );
    }
    let lens = doc.add_lens(new_lens([0.0, 2.0, 3.0], [0.0, 0.0, 1.0])).unwrap();
    assert_eq!(lens, Item::Lens(1));
    assert_eq!(doc.item_name(lens), "lens 2", "the cubes lens is called `lens`");
    assert_eq!(doc.built().objects.iter().filter(|o| o.lens().is_some()).count(), 2);
    let copy = doc.duplicate(lens).unwrap().unwrap();
    assert_eq!(copy, Item::Lens(2));
    assert_eq!(doc.undo_depth(), 10);

    // Delete the first cube: the rest shift down, names stay.
    let name = doc.item_name(Item::Object(1));
    let third = doc.item_name(Item::Object(2));
    assert_eq!(doc.delete(Item::Object(1)).unwrap(), Change::Picture);
    assert_eq!(doc.undo_label(), Some(format!("delete {name}").as_str()));
    assert_eq!(doc.item_name(Item::Object(1)), third);
    assert_eq!(doc.delete(Item::Lens(0)).unwrap(), Change::Picture);
    assert_eq!(doc.scene().lenses.len(), 2);
    // Deleting what is not there does nothing.
    assert_eq!(doc.delete(Item::Lens(9)).unwrap(), Change::None);
    assert_eq!(doc.duplicate(Item::Object(99)).unwrap(), None);
    // All of it undoes back to the preset.
    while doc.undo().is_some() {}
    assert_eq!(doc.scene(), &cubes().scene().clone());
    assert!(!doc.is_dirty());
    assert_eq!(doc.items().len(), 27);
}

#[test]
fn a_rejected_edit_changes_nothing_and_says_why() {
    let mut doc = cubes();
    let rev = doc.revision();
    let err = doc.edit("r1", |sf| sf.lenses[0].r1 = 0.5).unwrap_err();
    assert!(err.concerns("lenses[0]") && err.concerns("lenses[0].r1"), "{err}");
    assert!(!err.concerns("lenses[1]"));
    assert!(err.to_string().contains("lenses[0].r1"), "{err}");
    assert_eq!(doc.scene().lenses[0].r1, 5.0);
    assert_eq!(doc.revision(), rev);
    assert!(!doc.is_dirty());
    assert_eq!(doc.undo_depth(), 0);
    // Other impossible values, one per panel.
    type Breaks = fn(&mut SceneFile);
    let bad: [(&str, Breaks); 7] = [
        ("camera.fov", |sf| sf.camera.fov = 180.0),
        ("objects[1].size[0]", |sf| sf.objects[1].size = Some([0.0, 1.0, 1.0])),
        ("lights[0].intensity", |sf| sf.lights[0].intensity = -1.0),
        ("lenses[0].n", |sf| sf.lenses[0].n = IndexFile::Constant(0.9)),
        ("render.max_depth", |sf| sf.render.max_depth = 65),
        ("lenses[0].axis", |sf| sf.lenses[0].axis = [0.0; 3]),
        ("ambient.intensity", |sf| sf.ambient.intensity = f64::NAN),
    ];
    for (path, f) in bad {
        let e = doc.edit("bad", f).unwrap_err();
        assert!(e.concerns(path), "{path}: {e}");
    }
    assert_eq!(doc.revision(), rev);
}

#[test]
fn changes_that_do_not_change_the_picture_do_not_restart() {
    let mut doc = cubes();
    assert_eq!(doc.edit("same", |_| {}).unwrap(), Change::None);
    assert_eq!(doc.undo_depth(), 0, "a no-op is not an undo step");
    assert_eq!(
        doc.edit("rename", |sf| sf.objects[3].name = Some("hero".into()))
            .unwrap(),
        Change::File
    );
    assert!(doc.is_dirty(), "a rename is still an unsaved change");
    assert_eq!(doc.edit("spp", |sf| sf.render.spp = 16).unwrap(), Change::File);
    assert_eq!(
        doc.edit("unused material", |sf| {
            sf.materials.insert("spare".into(), MaterialFile::default());
        })
        .unwrap(),
        Change::File
    );
    assert_eq!(
        doc.edit("used material", |sf| sf.materials.get_mut("cube1").unwrap().color =
            [1.0; 3])
            .unwrap(),
        Change::Picture
    );
    // The camera alone: the picture restarts (reprojected, photons kept).
    assert_eq!(doc.edit("fov", |sf| sf.camera.fov = 50.0).unwrap(), Change::Camera);
    assert_eq!(doc.undo().unwrap().1, Change::Camera);
    assert_eq!(doc.undo().unwrap().1, Change::Picture);
    assert_eq!(doc.undo().unwrap().1, Change::File);
}

#[test]
fn merged_edits_are_one_step_until_sealed_and_history_keeps_at_least_50() {
    let mut doc = cubes();
    for i in 0..30 {
        doc.edit_merged("light.x", "move light", |sf| {
            sf.lights[0].position = Some([i as f64, 10.0, 6.0])
        })
        .unwrap();
    }
    assert_eq!(doc.undo_depth(), 1);
    doc.seal();
    doc.edit_merged("light.x", "move light", |sf| {
        sf.lights[0].position = Some([-1.0, 10.0, 6.0])
    })
    .unwrap();
    // Another key opens a new step too.
    doc.edit_merged("fov", "fov", |sf| sf.camera.fov = 40.0).unwrap();
    assert_eq!(doc.undo_depth(), 3);
    doc.undo();
    doc.undo();
    assert_eq!(doc.scene().lights[0].position, Some([29.0, 10.0, 6.0]));
    doc.undo();
    assert_eq!(doc.scene().lights[0].position, Some([5.0, 10.0, 6.0]));

    // A new edit clears the redo stack.
    doc.redo();
    doc.edit("fov", |sf| sf.camera.fov = 30.0).unwrap();
    assert!(doc.redo().is_none());

    // Deep history: 300 single steps keep the newest UNDO_LIMIT (≥ 50).
    let mut doc = cubes();
    for i in 0..300 {
        doc.edit("fov", |sf| sf.camera.fov = 20.0 + i as f64 * 0.1).unwrap();
    }
    const { assert!(UNDO_LIMIT >= 50) };
    assert_eq!(doc.undo_depth(), UNDO_LIMIT);
    for _ in 0..UNDO_LIMIT {
        doc.undo().unwrap();
    }
    assert!((doc.scene().camera.fov - (20.0 + (300 - UNDO_LIMIT - 1) as f64 * 0.1)).abs() < 1e-9);
    for _ in 0..UNDO_LIMIT {
        doc.redo().unwrap();
    }
    assert!((doc.scene().camera.fov - 49.9).abs() < 1e-9);
}

#[test]
fn save_and_load_round_trip_every_preset_and_an_edited_scene() {
    for p in PRESETS {
        let mut doc = Document::preset(p.name).unwrap();
        assert_eq!(doc.save().unwrap(), None, "a preset has no file: Save must ask for one");
        let (_path_dir, path) = tmp(p.file);
        doc.save_as(&path).unwrap();
        assert!(!doc.is_dirty());
        assert_eq!(doc.source(), &Source::File(path.clone()));
        let back = Document::open(&path).unwrap();
        assert_eq!(back.scene(), doc.scene(), "{}", p.name);
        assert_eq!(**back.built(), **doc.built(), "{}", p.name);
    }

    // An edited scene with every kind of thing in it: Cauchy glass, a
    // directional light, rotations, a duplicated lens, odd numbers.
    let mut doc = Document::preset("primitives").unwrap();
    doc.add_object(
        new_object(ShapeKind::Pyramid, [0.1, 0.2, 0.3]),
        Some(("gold".into(), new_material([0.3; 3]))),
    )
    .unwrap();
    doc.duplicate(Item::Lens(0)).unwrap();
    doc.edit("many", |sf| {
        sf.objects[0].rotation = [1.0 / 3.0, -45.0, 1e-7];
        sf.lenses[1].n = IndexFile::Constant(1.5168);
        sf.lenses[0].axis = axis_from_angles(12.5, -7.0);
        sf.camera.fov = 37.123456789;
        sf.render.shadows = false;
        sf.lights.push(new_point_light([0.0, 5.0, 0.0]));
        sf.lights[1].kind = LightKind::Directional;
        set_camera_pose(sf, DVec3::new(0.5, 2.0, 8.0), DVec3::new(-10.0, 5.0, 1.0));
    })
    .unwrap();
    assert_eq!(
        doc.scene().materials["gold 2"].color,
        [0.3; 3],
        "a taken material name gets a suffix"
    );
    let (_path_dir, path) = tmp("edited.toml");
    let saved = doc.save_as(&path).unwrap();
    assert_eq!(saved, path);
    assert!(!doc.is_dirty());
    assert!(doc.title().ends_with("edited.toml"), "{}", doc.title());
    let back = Document::open(&path).unwrap();
    assert_eq!(back.scene(), doc.scene());
    assert_eq!(**back.built(), **doc.built());
    // Saving again to its own file (Ctrl+S).
    doc.edit("fov", |sf| sf.camera.fov = 40.0).unwrap();
    assert!(doc.is_dirty());
    assert_eq!(doc.save().unwrap(), Some(path.clone()));
    assert_eq!(Document::open(&path).unwrap().scene().camera.fov, 40.0);
    assert!(!doc.is_dirty());
    // Undo after a save makes it dirty again.
    doc.undo();
    assert!(doc.is_dirty());
}

#[test]
fn failed_open_and_save_keep_everything() {
    let (_missing_dir, missing) = tmp("does-not-exist.toml");
    let e = Document::open(&missing).unwrap_err();
    assert!(e.to_string().contains("cannot read"), "{e}");
    let (_bad_dir, bad) = tmp("bad.toml");
    std::fs::write(&bad, "[camera]\nposition = [0, 0, 0]\nfov = 0\n").unwrap();
    let e = Document::open(&bad).unwrap_err();
    assert!(e.to_string().contains("camera.fov"), "{e}");
    assert!(Document::preset("no such").is_err());

    let mut doc = cubes();
    doc.edit("fov", |sf| sf.camera.fov = 40.0).unwrap();
    let (_dir_dir, dir) = tmp("a-directory");
    std::fs::create_dir_all(&dir).unwrap();
    assert!(doc.save_as(&dir).is_err());
    assert!(doc.save_as(&tmp("no-such-dir").1.join("x.toml")).is_err());
    assert!(doc.is_dirty(), "a failed save leaves the changes unsaved");
    assert!(matches!(doc.source(), Source::Preset(_)));
}

#[test]
fn reload_is_one_undoable_step_and_keeps_the_camera() {
    let (_path_dir, path) = tmp("reload.toml");
    let mut doc = cubes();
    doc.save_as(&path).unwrap();
    doc.edit("fly", |sf| {
        set_camera_pose(sf, DVec3::new(1.0, 2.0, 3.0), DVec3::new(0.0, 10.0, 0.0))
    })
    .unwrap();
    // Someone else edits the file.
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace("intensity = 500.0", "intensity = 250.0");
    std::fs::write(&path, text).unwrap();
    assert_eq!(doc.reload(true).unwrap(), Change::Picture);
    assert_eq!(doc.scene().lights[0].intensity, 250.0);
    assert_eq!(doc.camera_pose().0, DVec3::new(1.0, 2.0, 3.0));
    assert!(doc.is_dirty(), "the camera differs from the file");
    doc.undo();
    assert_eq!(doc.scene().lights[0].intensity, 500.0);
    // A broken file changes nothing.
    std::fs::write(&path, "garbage = [").unwrap();
    let before = doc.scene().clone();
    assert!(doc.reload(true).is_err());
    assert_eq!(doc.scene(), &before);
    assert!(matches!(cubes().reload(true), Err(ReloadError::NoFile)));
}

/// Issue 30.2: F5 when the scene's path has become a FIFO (or a device)
/// is refused at once, naming it, and the document stays; before, the open
/// blocked the window's thread until a writer came.
#[test]
fn reload_of_a_path_that_became_a_fifo_does_not_block() {
    let (_path_dir, path) = tmp("reload-fifo.toml");
    let mut doc = cubes();
    doc.save_as(&path).unwrap();
    std::fs::remove_file(&path).unwrap();
    assert!(
        std::process::Command::new("mkfifo")
            .arg(&path)
            .status()
            .unwrap()
            .success()
    );
    let before = doc.scene().clone();
    // On another thread, so that a regression fails instead of hanging.
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let e = doc.reload(true).unwrap_err().to_string();
        let _ = tx.send((e, doc.scene() == &before));
    });
    let (e, kept) = rx
        .recv_timeout(std::time::Duration::from_secs(10))
        .expect("reload blocked on a FIFO");
    assert!(e.contains("it is a FIFO, not a regular file"), "{e}");
    assert!(e.contains(&*path.to_string_lossy()), "{e}");
    assert!(kept);
    std::fs::remove_file(&path).unwrap();
}

#[test]
fn lens_axis_angles_round_trip() {
    for (yaw, pitch) in [(0.0, 0.0), (30.0, 10.0), (-120.0, -45.0), (179.0, 80.0)] {
        let a = axis_from_angles(yaw, pitch);
        assert!((DVec3::from(a).length() - 1.0).abs() < 1e-9);
        let (y, p) = axis_angles(a);
        assert!(
            (y - yaw).abs() < 1e-6 && (p - pitch).abs() < 1e-6,
            "{yaw} {pitch} -> {y} {p}"
        );
    }
    assert_eq!(axis_from_angles(0.0, 0.0), [0.0, 0.0, 1.0]);
    // Positive pitch tilts the axis up.
    assert!(axis_from_angles(0.0, 20.0)[1] > 0.0);
    let unique = cubes().unique_name("cube 1");
    assert_eq!(unique, "cube 1 2");
}

/// F5 on a file that was broken on disk (bad TOML, then a valid TOML with an
/// impossible lens): an error naming the file, line and field, and the
/// document, its dirty state and its undo history exactly as they were;
/// once the file is fixed, the reload goes through.
#[test]
fn reload_of_a_broken_file_says_where_and_keeps_everything() {
    let (_path_dir, path) = tmp("reload-broken.toml");
    let mut doc = cubes();
    doc.save_as(&path).unwrap();
    let home = doc.camera_pose();
    doc.edit("fly", |sf| set_camera_pose(sf, DVec3::new(1.0, 2.0, 3.0), DVec3::ZERO))
        .unwrap();
    let good = std::fs::read_to_string(&path).unwrap();
    let r1 = good.lines().position(|l| l.trim_start().starts_with("r1 =")).unwrap() + 1;
    let bad_lens = good
        .lines()
        .map(|l| {
            if l.trim_start().starts_with("r1 =") {
                "r1 = 0.5"
            } else {
                l
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    let bad_toml = format!("{good}\n[camera\n");
    let bad_toml_line = good.lines().count() + 2;
    for (text, line, field) in [(bad_toml, bad_toml_line, ""), (bad_lens, r1, "lenses[0].r1")] {
        std::fs::write(&path, &text).unwrap();
        let before = (doc.scene().clone(), doc.is_dirty(), doc.camera_pose());
        let msg = doc.reload(true).unwrap_err().to_string();
        let at = format!("{}:{line}:", path.display());
        assert!(
            msg.contains(&at) && msg.contains(field),
            "{msg} (want {at} and {field})"
        );
        assert_eq!(msg.lines().count(), 1, "{msg}");
        assert_eq!((doc.scene().clone(), doc.is_dirty(), doc.camera_pose()), before);
    }
    // The history holds the flight and nothing from the failed reloads.
    doc.undo();
    assert_eq!(doc.camera_pose(), home);
    assert!(!doc.is_dirty());
    doc.redo();
    std::fs::write(&path, good.replace("intensity = 500.0", "intensity = 250.0")).unwrap();
    assert_eq!(doc.reload(true).unwrap(), Change::Picture);
    assert_eq!(doc.scene().lights[0].intensity, 250.0);
}

/// Issue 33.1: a drag moves a primitive, a lens, a lens system (by the
/// key that places it) or a point light; a drag's moves are one undo step,
/// and the built objects map back to their items.
#[test]
fn drags_move_items_and_lights_in_one_undo_step_each() {
    let mut doc = Document::preset("lens family").unwrap();
    let before = doc.scene().clone();
    let by = glam::DVec3::new(0.1, -0.2, 0.3);
    let items = doc.items();
    for (k, &(item, _)) in items.iter().enumerate() {
        assert_eq!(doc.item_of_object(doc.object_of_item(item)), Some(item));
        let o = doc.object_of_item(item);
        let b0 = doc.built().objects[o].world_bounds;
        doc.move_item(item, by).unwrap();
        doc.move_item(item, by).unwrap();
        let b1 = doc.built().objects[o].world_bounds;
        let moved = 0.5 * (b1.min + b1.max) - 0.5 * (b0.min + b0.max);
        assert!((moved - 2.0 * by).length() < 1e-9, "{item:?} moved by {moved}");
        doc.seal();
        assert_eq!(doc.undo_depth(), k + 1, "one step per drag");
    }
    assert_eq!(doc.item_of_object(items.len()), None);
    let light = doc
        .scene()
        .lights
        .iter()
        .position(|l| l.kind == LightKind::Point)
        .unwrap();
    let p0 = doc.scene().lights[light].position.unwrap();
    doc.move_light(light, by).unwrap();
    let p1 = doc.scene().lights[light].position.unwrap();
    assert!((glam::DVec3::from(p1) - glam::DVec3::from(p0) - by).length() < 1e-12);
    for _ in 0..=items.len() {
        doc.undo();
    }
    assert_eq!(*doc.scene(), before);
}

#[test]
fn the_add_forms_new_items_are_named_kinds_at_the_forms_defaults() {
    let at = [1.0, 2.0, 3.0];
    for kind in [
        ShapeKind::Cuboid,
        ShapeKind::Prism,
        ShapeKind::Sphere,
        ShapeKind::Pyramid,
    ] {
        let want = NewItem::Primitive(new_object(kind, at), NEW_COLOUR);
        assert_eq!(NewItem::of(kind.name(), "", at), Some(want));
    }
    assert_eq!(
        NewItem::of("lens", "", at),
        Some(NewItem::Lens(new_lens(at, [0.0, 0.0, 1.0])))
    );
    assert!(matches!(NewItem::of("doublet", "", at), Some(NewItem::System(s)) if s.kind == "doublet"));
    let preset = NewItem::of("preset", "cooke-triplet-100mm", at);
    assert!(matches!(preset, Some(NewItem::System(ref s)) if s.preset.as_deref() == Some("cooke-triplet-100mm")));
    assert_eq!(NewItem::of("blimp", "", at), None);
    assert_eq!(NewItem::of("preset", "no-such-lens", at), None);
    // Added: the system faces the camera, as the desktop's form adds it.
    let mut doc = cubes();
    let item = doc.add_new(preset.unwrap()).unwrap();
    let Item::System(i) = item else { panic!("{item:?}") };
    let facing = (-doc.built().camera.forward()).to_array();
    assert_eq!(doc.scene().systems[i].axis, facing);
    assert_eq!(doc.undo_depth(), 1);
}
