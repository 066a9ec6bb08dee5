//! What is unsaved, told apart: the scene's content (objects, lenses,
//! lights, materials, the camera's field of view, render settings) or only
//! the view (the camera's position and direction, which flying changes).
//! Losing a flight is no reason to stop the user at quit; losing an edit
//! is. Save writes both.

use super::Document;
use crate::scene::SceneFile;

/// Which kinds of change are not saved.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Unsaved {
    /// Anything but the camera's pose differs from the file.
    pub content: bool,
    /// The camera's position or direction differs from the file.
    pub view: bool,
}

/// The camera's pose: position, and `rotation` or `look_at`.
fn same_view(a: &SceneFile, b: &SceneFile) -> bool {
    let (a, b) = (&a.camera, &b.camera);
    (a.position, a.rotation, a.look_at) == (b.position, b.rotation, b.look_at)
}

/// `a` and `b` equal but for the camera's pose.
fn same_content(a: &SceneFile, b: &SceneFile) -> bool {
    let mut b = b.clone();
    b.camera.position = a.camera.position;
    b.camera.rotation = a.camera.rotation;
    b.camera.look_at = a.camera.look_at;
    *a == b
}

/// The top-level parts of the file that differ, as the question names them.
fn changed_parts(a: &SceneFile, b: &SceneFile) -> Vec<&'static str> {
    let mut v = Vec::new();
    let mut push = |differs: bool, name| {
        if differs {
            v.push(name);
        }
    };
    push(a.objects != b.objects, "objects");
    push(a.lenses != b.lenses, "lenses");
    push(a.lights != b.lights, "lights");
    push(a.materials != b.materials, "materials");
    push(a.ambient != b.ambient, "ambient light");
    push(a.camera.fov != b.camera.fov, "field of view");
    push(a.render != b.render, "render settings");
    v
}

impl Document {
    /// What differs from the file as last opened or saved.
    pub fn unsaved(&self) -> Unsaved {
        Unsaved {
            content: !same_content(&self.scene, &self.saved),
            view: !same_view(&self.scene, &self.saved),
        }
    }

    /// Whether closing the document would lose an edit (not just a flight).
    pub fn has_unsaved_content(&self) -> bool {
        self.unsaved().content
    }

    /// What is unsaved, in words: `"objects and lights (and the camera)"`;
    /// empty when nothing is.
    pub fn unsaved_summary(&self) -> String {
        let parts = changed_parts(&self.scene, &self.saved);
        let mut s = match parts.as_slice() {
            [] => String::new(),
            [one] => one.to_string(),
            [init @ .., last] => format!("{} and {last}", init.join(", ")),
        };
        if self.unsaved().view {
            s = if s.is_empty() {
                "the camera".into()
            } else {
                format!("{s} (and the camera)")
            };
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edit::Edit;
    use glam::DVec3;

    #[test]
    fn a_flight_alone_is_a_view_change_and_an_edit_is_content() {
        let mut doc = Document::preset("cubes").unwrap();
        assert_eq!(doc.unsaved(), Unsaved::default());
        assert_eq!(doc.unsaved_summary(), "");
        let (p, r) = doc.camera_pose();
        doc.fly_camera(p + DVec3::new(0.0, 0.0, -1.0), r).unwrap();
        assert_eq!(
            doc.unsaved(),
            Unsaved {
                content: false,
                view: true
            }
        );
        assert!(doc.is_dirty() && !doc.has_unsaved_content());
        assert_eq!(doc.unsaved_summary(), "the camera");
        assert_eq!(doc.title(), "preset cubes (not saved) (camera moved)");
        doc.apply_edit(Edit::LightIntensity(2.0)).unwrap();
        assert_eq!(
            doc.unsaved(),
            Unsaved {
                content: true,
                view: true
            }
        );
        assert_eq!(doc.unsaved_summary(), "lights (and the camera)");
        assert!(doc.title().ends_with(" *"), "{}", doc.title());
        doc.apply_edit(Edit::LensDiameter(0.1)).unwrap();
        assert_eq!(doc.unsaved_summary(), "lenses and lights (and the camera)");
        // Back where it was opened: only the edits are left.
        doc.reset_view().unwrap();
        assert_eq!(
            doc.unsaved(),
            Unsaved {
                content: true,
                view: false
            }
        );
        assert_eq!(doc.unsaved_summary(), "lenses and lights");
    }

    #[test]
    fn the_field_of_view_is_content_and_save_clears_both() {
        let mut doc = Document::preset("cubes").unwrap();
        let (p, r) = doc.camera_pose();
        doc.set_camera(p, r, 40.0).unwrap();
        // The same pose, a narrower field: content only.
        assert_eq!(
            doc.unsaved(),
            Unsaved {
                content: true,
                view: false
            }
        );
        assert_eq!(doc.unsaved_summary(), "field of view");
        let path = std::env::temp_dir().join(format!("lensview-unsaved-{}.toml", std::process::id()));
        doc.save_as(&path).unwrap();
        let _ = std::fs::remove_file(&path);
        assert_eq!(doc.unsaved(), Unsaved::default());
    }
}
