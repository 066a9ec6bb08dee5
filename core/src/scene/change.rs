//! What an edit of a scene changed, as the render thread needs to know it:
//! the editor says so ([`Change::between`], from the two scene files), so
//! the render thread never compares scenes to find out.

use super::SceneFile;
use super::file::{AmbientFile, LightFile, RenderFile, V3};

/// What changed between two versions of a scene, ordered from least to
/// most, each level allowing less than the one below it to be kept, so the
/// effect of several edits is the largest of theirs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Change {
    /// Nothing changed.
    None,
    /// The file changed but not the picture (a name, `render.spp`, an unused
    /// material): no need to restart refinement.
    File,
    /// Only how the picture is shown (`[display]`: exposure, tone curve):
    /// the samples are kept and shown again with the new tone.
    Display,
    /// Only the camera: the picture may be reprojected into the new view,
    /// and the caustic photons (world-space) kept.
    Camera,
    /// The shading but not the light paths (the ambient light, the
    /// background; the camera too, perhaps): the picture starts again, the
    /// caustic photons are kept.
    Shading,
    /// The light paths (objects, lenses, systems, lights, used materials,
    /// the depth, shadows, caustics): everything starts again.
    Picture,
}

impl Change {
    /// Whether refinement restarts.
    pub fn restarts(self) -> bool {
        self >= Change::Camera
    }

    /// Whether a picture of the scene before may be reprojected into the
    /// scene after (the same size given).
    pub fn reprojects(self) -> bool {
        self <= Change::Camera
    }

    /// Whether the render thread needs a new job: a restart, or the kept
    /// samples shown with a new tone ([`Change::Display`]).
    pub fn resubmits(self) -> bool {
        self >= Change::Display
    }

    /// Whether the caustic photons of the scene before serve the scene after.
    pub fn keeps_photons(self) -> bool {
        self <= Change::Shading
    }

    /// What changed from `a` to `b`. Names, `render.spp` and the unused
    /// materials do not change the picture (a [`Change::File`]).
    pub fn between(a: &SceneFile, b: &SceneFile) -> Change {
        if a == b {
            return Change::None;
        }
        let (paths_a, shading_a) = parts(a);
        let (paths_b, shading_b) = parts(b);
        if paths_a != paths_b || !same_solids(a, b) {
            return Change::Picture;
        }
        match (shading_a != shading_b, a.camera != b.camera) {
            (true, _) => Change::Shading,
            (false, true) => Change::Camera,
            (false, false) if a.display != b.display => Change::Display,
            (false, false) => Change::File,
        }
    }
}

/// What of a scene file sets the light paths (beside its solids:
/// [`same_solids`]) and what sets only the shading. Every field is named,
/// so a new one cannot be forgotten.
#[allow(clippy::type_complexity)]
fn parts(sf: &SceneFile) -> ((u32, bool, Option<bool>, &[LightFile]), (&V3, &AmbientFile)) {
    let SceneFile {
        render,
        camera: _,
        ambient,
        lights,
        materials: _,
        objects: _,
        lenses: _,
        systems: _,
        display: _,
    } = sf;
    let RenderFile {
        background,
        max_depth,
        shadows,
        spp: _,
        caustics,
    } = render;
    ((*max_depth, *shadows, *caustics, lights), (background, ambient))
}

/// Whether `a` and `b` hold the same objects, lenses and systems with the
/// same materials, names and unused materials aside.
fn same_solids(a: &SceneFile, b: &SceneFile) -> bool {
    let unnamed = |sf: &SceneFile| {
        let mut objects = sf.objects.clone();
        for o in &mut objects {
            o.name = None;
            o.material = None;
        }
        let mut lenses = sf.lenses.clone();
        for l in &mut lenses {
            l.name = None;
        }
        let mut systems = sf.systems.clone();
        for s in &mut systems {
            s.name = None;
        }
        (objects, lenses, systems)
    };
    let materials = |sf: &SceneFile| -> Vec<Option<_>> {
        sf.objects
            .iter()
            .map(|o| o.material.as_ref().and_then(|m| sf.materials.get(m)).cloned())
            .collect()
    };
    a.objects.len() == b.objects.len() && materials(a) == materials(b) && unnamed(a) == unnamed(b)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cubes() -> SceneFile {
        toml::from_str(include_str!("../../../scenes/cubes.toml")).unwrap()
    }

    /// Each kind of edit is named for what it touched, and several edits
    /// are the largest of theirs.
    #[test]
    fn each_edit_says_what_it_touched() {
        let a = cubes();
        let edit = |f: &dyn Fn(&mut SceneFile)| {
            let mut b = a.clone();
            f(&mut b);
            Change::between(&a, &b)
        };
        assert_eq!(edit(&|_| {}), Change::None);
        assert_eq!(edit(&|b| b.render.spp += 1), Change::File);
        assert_eq!(edit(&|b| b.display.exposure = 1.5), Change::Display);
        assert_eq!(
            edit(&|b| {
                b.display.tone = crate::color::ToneCurve::Aces;
                b.camera.fov += 1.0;
            }),
            Change::Camera
        );
        assert_eq!(edit(&|b| b.objects[0].name = Some("renamed".into())), Change::File);
        assert_eq!(
            edit(&|b| {
                b.materials
                    .insert("unused".into(), b.materials.values().next().unwrap().clone());
            }),
            Change::File
        );
        assert_eq!(edit(&|b| b.camera.position[0] += 0.1), Change::Camera);
        assert_eq!(edit(&|b| b.render.background[1] *= 0.5), Change::Shading);
        assert_eq!(
            edit(&|b| {
                b.ambient.intensity *= 0.5;
                b.camera.position[0] += 0.1;
            }),
            Change::Shading
        );
        assert_eq!(edit(&|b| b.lights[0].intensity *= 2.0), Change::Picture);
        assert_eq!(edit(&|b| b.render.shadows = !b.render.shadows), Change::Picture);
        assert_eq!(edit(&|b| b.render.max_depth += 1), Change::Picture);
        assert_eq!(edit(&|b| b.objects[0].position[0] += 1.0), Change::Picture);
        assert_eq!(edit(&|b| b.lenses[0].d *= 0.9), Change::Picture);
        assert_eq!(
            edit(&|b| {
                let used = b.objects[0].material.clone().unwrap();
                b.materials.get_mut(&used).unwrap().diffuse *= 0.5;
            }),
            Change::Picture
        );
        assert_eq!(edit(&|b| b.objects.truncate(1)), Change::Picture);
        assert!(Change::Camera.reprojects() && !Change::Shading.reprojects());
        assert!(Change::Shading.keeps_photons() && !Change::Picture.keeps_photons());
        assert!(!Change::File.restarts() && Change::Camera.restarts());
    }
}
