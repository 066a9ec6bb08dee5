//! Each change the panel and keys make, driven without a window: what it
//! does to the file model, its undo label, and that undo restores the scene.

use super::super::{Change, Document, Item, Placement, new_lens, new_object};
use super::*;
use crate::scene::file::ShapeKind;

fn cubes() -> Document {
    Document::preset("cubes").unwrap()
}

fn close(a: DVec3, b: DVec3) -> bool {
    (a - b).length() < 1e-9
}

/// Undoes the newest step and checks that it was `label` and that the scene
/// is back to `before`.
fn undo_to(doc: &mut Document, label: &str, before: &SceneFile) {
    assert_eq!(doc.undo().map(|(l, _)| l).as_deref(), Some(label));
    assert_eq!(doc.scene(), before, "undo of {label} did not restore the scene");
}

#[test]
fn a_key_edit_is_clamped_validated_and_one_undo_step() {
    let mut doc = cubes();
    let before = doc.scene().clone();
    let (msg, change) = doc.apply_edit(Edit::LightIntensity(2.0)).unwrap();
    assert_eq!(change, Change::Picture);
    assert_eq!(doc.scene().lights[0].intensity, 1000.0);
    assert!(msg.contains("light intensity 1000"), "{msg}");
    assert_eq!(doc.undo_label(), Some(msg.as_str()));
    undo_to(&mut doc, &msg, &before);
    let (msg, _) = doc.apply_edit(Edit::LensR1(-100.0)).unwrap();
    assert!(msg.contains("clamped to d/2"), "{msg}");
    assert_eq!(doc.scene().lenses[0].r1, 1.0);
}

#[test]
fn flight_is_one_step_per_gesture_and_reset_returns_to_the_opened_view() {
    let mut doc = cubes();
    let before = doc.scene().clone();
    let home = doc.camera_pose();
    assert_eq!(doc.home(), home);
    for k in 1..=3 {
        let p = home.0 + DVec3::X * k as f64;
        assert_eq!(doc.fly_camera(p, home.1 + DVec3::Y).unwrap(), Change::Camera);
    }
    assert_eq!(doc.undo_depth(), 1);
    assert!(close(doc.camera_pose().0, home.0 + DVec3::X * 3.0));
    doc.seal();
    doc.reset_view().unwrap();
    assert_eq!(doc.undo_label(), Some("reset the view"));
    assert!(close(doc.camera_pose().0, home.0) && close(doc.camera_pose().1, home.1));
    assert_eq!(doc.scene().camera.look_at, None);
    doc.undo();
    undo_to(&mut doc, "move the camera", &before);
}

#[test]
fn the_camera_fields_set_pose_and_field_of_view() {
    let mut doc = cubes();
    let before = doc.scene().clone();
    let (p, r) = (DVec3::new(1.0, 2.0, 9.0), DVec3::new(-10.0, 5.0, 0.0));
    doc.set_camera(p, r, 60.0).unwrap();
    doc.set_camera(p, r, 50.0).unwrap();
    assert_eq!(doc.undo_depth(), 1, "field edits merge until sealed");
    assert_eq!(doc.scene().camera.fov, 50.0);
    assert!(close(doc.camera_pose().0, p) && close(doc.camera_pose().1, r));
    assert!(
        doc.set_camera(p, r, 180.0).is_err(),
        "a field of view of 180° is impossible"
    );
    undo_to(&mut doc, "edit the camera", &before);
}

#[test]
fn look_at_the_lens_turns_the_camera_toward_its_centre() {
    let mut doc = cubes();
    let before = doc.scene().clone();
    doc.fly_camera(DVec3::new(3.0, 1.0, 12.0), DVec3::ZERO).unwrap();
    doc.seal();
    let after_fly = doc.scene().clone();
    doc.look_at_lens(0).unwrap().unwrap();
    let c = DVec3::from(doc.scene().lenses[0].center);
    let (pos, _) = doc.camera_pose();
    assert!(
        close(pos, DVec3::new(3.0, 1.0, 12.0)),
        "the camera turns, it does not move"
    );
    assert!(close(doc.built().camera.forward(), (c - pos).normalize()));
    assert!(doc.look_at_lens(5).is_none(), "there is no lens 6");
    undo_to(&mut doc, "look at the lens", &after_fly);
    // Standing in the lens's centre there is no direction to look along.
    doc.fly_camera(c, DVec3::ZERO).unwrap();
    assert!(doc.look_at_lens(0).is_none());
    while doc.undo().is_some() {}
    assert_eq!(doc.scene(), &before);
}

#[test]
fn a_lens_can_face_the_camera_or_be_put_in_front_of_it() {
    let mut doc = cubes();
    let before = doc.scene().clone();
    let (pos, _) = doc.camera_pose();
    doc.point_lens_at_camera(0).unwrap().unwrap();
    let l = &doc.scene().lenses[0];
    assert!(close(DVec3::from(l.axis), (pos - DVec3::from(l.center)).normalize()));
    assert_eq!(
        DVec3::from(l.center),
        DVec3::from(before.lenses[0].center),
        "it turns in place"
    );
    undo_to(&mut doc, "point the lens at the camera", &before);
    assert!(doc.point_lens_at_camera(1).is_none());

    doc.put_lens_in_front(0, 3.5).unwrap();
    let f = doc.built().camera.forward();
    let l = &doc.scene().lenses[0];
    assert!(close(DVec3::from(l.center), pos + f * 3.5));
    assert!(close(DVec3::from(l.axis), -f));
    undo_to(&mut doc, "put the lens in front of the camera", &before);
    assert_eq!(doc.put_lens_in_front(7, 3.5).unwrap(), Change::None);
}

#[test]
fn record_setters_merge_per_record_and_reject_impossible_values() {
    let mut doc = cubes();
    let before = doc.scene().clone();
    let mut lens = doc.scene().lenses[0].clone();
    lens.r1 = 6.0;
    doc.set_lens(0, lens.clone()).unwrap();
    lens.r1 = 7.0;
    doc.set_lens(0, lens.clone()).unwrap();
    assert_eq!((doc.undo_depth(), doc.undo_label()), (1, Some("edit lens")));
    assert_eq!(doc.scene().lenses[0].r1, 7.0);
    lens.r1 = 0.5;
    assert!(doc.set_lens(0, lens).unwrap_err().concerns("lenses[0].r1"));

    let name = doc.item_name(Item::Object(3));
    let mut o = doc.scene().objects[3].clone();
    o.position[1] += 1.0;
    assert_eq!(doc.set_object(3, o.clone()).unwrap(), Change::Picture);
    assert_eq!(doc.undo_depth(), 2, "another record is another step");
    assert_eq!(doc.undo_label(), Some(format!("edit {name}").as_str()));
    assert_eq!(doc.set_object(99, o).unwrap(), Change::None);

    let mut light = doc.scene().lights[0].clone();
    light.intensity = 42.0;
    doc.set_light(0, light).unwrap();
    assert_eq!(doc.scene().lights[0].intensity, 42.0);
    let mut m = doc.scene().materials["cube1"].clone();
    m.reflectivity = 0.5;
    doc.set_material("cube1", m).unwrap();
    assert_eq!(doc.scene().materials["cube1"].reflectivity, 0.5);
    assert_eq!(doc.undo_label(), Some("edit material cube1"));
    while doc.undo().is_some() {}
    assert_eq!(doc.scene(), &before);
}

#[test]
fn own_material_copies_a_shared_one_or_makes_a_default() {
    let mut doc = cubes();
    let before = doc.scene().clone();
    assert_eq!(doc.material_users("cube1"), 1);
    assert_eq!(doc.give_own_material(1).unwrap(), Change::None, "it is the only user");
    // Share cube1 with the second cube, then give the second its own copy.
    let mut o = doc.scene().objects[2].clone();
    o.material = Some("cube1".into());
    doc.set_object(2, o).unwrap();
    doc.seal();
    assert_eq!(doc.material_users("cube1"), 2);
    let shared = doc.scene().clone();
    doc.give_own_material(2).unwrap();
    let name = doc.item_name(Item::Object(2));
    assert_eq!(doc.scene().objects[2].material.as_deref(), Some(name.as_str()));
    assert_eq!(doc.scene().materials[&name], doc.scene().materials["cube1"]);
    assert_eq!(doc.material_users("cube1"), 1);
    undo_to(&mut doc, "own material", &shared);
    // Without a material: the default one.
    let mut o = doc.scene().objects[2].clone();
    o.material = None;
    doc.set_object(2, o).unwrap();
    doc.give_own_material(2).unwrap();
    assert_eq!(doc.scene().materials[&name], MaterialFile::default());
    assert_eq!(doc.give_own_material(99).unwrap(), Change::None);
    while doc.undo().is_some() {}
    assert_eq!(doc.scene(), &before);
}

#[test]
fn lights_are_added_above_the_camera_coloured_and_deleted() {
    let mut doc = cubes();
    let before = doc.scene().clone();
    let k = doc.add_point_light().unwrap();
    assert_eq!(k, 1);
    let l = &doc.scene().lights[1];
    assert_eq!(l.kind, LightKind::Point);
    assert!(close(
        DVec3::from(l.position.unwrap()),
        doc.camera_pose().0 + DVec3::Y * 2.0
    ));
    assert_eq!(doc.undo_label(), Some("add a light"));
    doc.set_light_temperature(1, 3000.0).unwrap();
    doc.set_light_temperature(1, 2500.0).unwrap();
    assert_eq!(doc.undo_label(), Some("light colour"));
    assert_eq!(doc.undo_depth(), 2, "one step while the slider moves");
    assert_eq!(doc.scene().lights[1].color, blackbody(2500.0).to_array());
    assert_eq!(doc.scene().lights[0].color, [1.0; 3], "only the chosen light");
    doc.seal();
    let two = doc.scene().clone();
    assert_eq!(doc.delete_light(0).unwrap(), Change::Picture);
    assert_eq!(doc.scene().lights.len(), 1);
    assert_eq!(doc.delete_light(4).unwrap(), Change::None);
    undo_to(&mut doc, "delete a light", &two);
    while doc.undo().is_some() {}
    assert_eq!(doc.scene(), &before);
}

#[test]
fn render_settings_and_the_ambient_light() {
    let mut doc = cubes();
    let before = doc.scene().clone();
    assert_eq!(doc.set_shadows(false).unwrap(), Change::Picture);
    assert!(!doc.scene().render.shadows);
    assert_eq!(doc.undo_label(), Some("shadows on/off"));
    // Caustics: on by default in cubes (a lit lens), off by the key, and
    // the file says so when saved.
    assert!(doc.built().features.caustics);
    assert_eq!(doc.set_caustics(false).unwrap(), Change::Picture);
    assert!(!doc.built().features.caustics);
    assert_eq!(doc.scene().render.caustics, Some(false));
    doc.set_max_depth(3).unwrap();
    assert_eq!(doc.scene().render.max_depth, 3);
    assert!(doc.set_max_depth(1000).is_err(), "beyond the depth limit");
    doc.set_background([0.5, 0.1, 0.1]).unwrap();
    assert_eq!(doc.scene().render.background, [0.5, 0.1, 0.1]);
    let mut a = doc.scene().ambient.clone();
    a.intensity = 0.3;
    doc.set_ambient(a).unwrap();
    assert_eq!(doc.scene().ambient.intensity, 0.3);
    assert_eq!(doc.undo_label(), Some("edit the ambient light"));
    while doc.undo().is_some() {}
    assert_eq!(doc.scene(), &before);
}

#[test]
fn the_add_form_names_colours_places_and_turns_new_items() {
    let mut doc = cubes();
    let ahead = doc.place(Placement::InFrontOfCamera(6.0));
    let cam = &doc.built().camera;
    assert!(close(DVec3::from(ahead), cam.position + cam.forward() * 6.0));
    assert_eq!(doc.place(Placement::At([1.0, 2.0, 3.0])), [1.0, 2.0, 3.0]);
    let item = doc
        .add_primitive(new_object(ShapeKind::Sphere, ahead), [0.8, 0.25, 0.15])
        .unwrap();
    assert_eq!(doc.item_name(item), "sphere");
    let Item::Object(i) = item else { panic!("{item:?}") };
    assert_eq!(doc.scene().objects[i].material.as_deref(), Some("sphere"));
    assert_eq!(doc.scene().materials["sphere"].color, [0.8, 0.25, 0.15]);
    let again = doc
        .add_primitive(new_object(ShapeKind::Sphere, ahead), [0.1; 3])
        .unwrap();
    assert_eq!(doc.item_name(again), "sphere 2");

    let lens = doc.add_lens_facing_camera(new_lens(ahead, [1.0, 0.0, 0.0])).unwrap();
    let Item::Lens(j) = lens else { panic!("{lens:?}") };
    let axis = DVec3::from(doc.scene().lenses[j].axis);
    assert!(close(axis, -doc.built().camera.forward()), "S1 faces the camera");
    assert_eq!(doc.undo_label(), Some("add lens"));
}

#[test]
fn switching_a_light_kind_gives_that_kinds_defaults() {
    let mut l = new_point_light([1.0, 2.0, 3.0]);
    switch_light_kind(&mut l, LightKind::Point);
    assert_eq!(l.position, Some([1.0, 2.0, 3.0]), "the same kind keeps everything");
    switch_light_kind(&mut l, LightKind::Directional);
    assert_eq!(
        (l.direction, l.position, l.intensity),
        (Some([0.3, -1.0, -0.4]), None, 1.0)
    );
    switch_light_kind(&mut l, LightKind::Point);
    assert_eq!((l.position, l.direction), (Some([0.0, 8.0, 4.0]), None));
    let mut sf = Document::preset("cubes").unwrap().scene().clone();
    sf.lights.push(l);
    crate::scene::Scene::build(&sf).unwrap();
}

#[test]
fn dispersion_on_and_off_keeps_the_index_at_the_d_line() {
    let n = IndexFile::Constant(1.5);
    assert_eq!(index_with_dispersion(n, false), n);
    let c = index_with_dispersion(n, true);
    let IndexFile::Cauchy([a, b]) = c else { panic!("{c:?}") };
    assert_eq!(b, CROWN_B);
    assert!((Index::Cauchy { a, b }.nominal() - 1.5).abs() < 1e-12);
    assert_eq!(index_with_dispersion(c, true), c);
    let IndexFile::Constant(back) = index_with_dispersion(c, false) else {
        panic!()
    };
    assert!((back - 1.5).abs() < 1e-12);
}

#[test]
fn a_glass_turns_into_its_nd_or_a_cauchy_pair_with_its_dispersion() {
    use crate::glass::{C_UM, F_UM};
    let g = crate::glass::lookup("N-SF5").unwrap();
    let n = IndexFile::Glass(g);
    let IndexFile::Constant(nd) = index_with_dispersion(n, false) else {
        panic!()
    };
    assert_eq!(nd, g.nd());
    let IndexFile::Cauchy([a, b]) = index_with_dispersion(n, true) else {
        panic!()
    };
    let c = Index::Cauchy { a, b };
    assert!((c.nominal() - g.nd()).abs() < 1e-12);
    let dispersion = g.n(F_UM) - g.n(C_UM);
    assert!((c.at(F_UM) - c.at(C_UM) - dispersion).abs() < 1e-12);
}
