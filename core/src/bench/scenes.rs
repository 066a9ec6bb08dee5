//! Benchmark scenes: variants of the cubes scene (scenes/cubes.toml, the
//! embedded default) built for timing, namely fewer cubes, a denser grid of
//! cubes over the same area, and each feature switched on or off. Tests may
//! use them as fixtures, but they exist for `lensview bench`; a scene that
//! lacks the cubes' naming (`cube …`) simply yields fewer cubes.

use crate::scene::Scene;
use crate::scene::file::{ObjectFile, SceneFile, ShapeKind};

fn is_cube(o: &ObjectFile) -> bool {
    o.name.as_deref().is_some_and(|n| n.starts_with("cube"))
}

/// The cubes scene with only its first `n` cubes (ground and lens kept).
pub fn cubes_subset(base: &SceneFile, n: usize) -> Scene {
    let mut sf = base.clone();
    let mut kept = 0;
    sf.objects.retain(|o| {
        if !is_cube(o) {
            return true;
        }
        kept += 1;
        kept <= n
    });
    Scene::build(&sf).expect("subset of a valid scene") // ok: a subset of a valid scene is valid
}

/// The cubes scene with its 5×5 grid replaced by `side × side` cubes over
/// the same area (−3.2 … 3.2), each scaled so the gaps keep their ratio.
pub fn cubes_grid(base: &SceneFile, side: usize) -> Scene {
    let mut sf = base.clone();
    let template = sf.objects.iter().find(|o| is_cube(o)).cloned();
    let materials: Vec<Option<String>> = sf
        .objects
        .iter()
        .filter(|o| is_cube(o))
        .map(|o| o.material.clone())
        .collect();
    sf.objects.retain(|o| !is_cube(o));
    if let Some(t) = template {
        let spacing = if side > 1 { 6.4 / (side - 1) as f64 } else { 1.6 };
        let size = 0.625 * spacing;
        for i in 0..side * side {
            let (ix, iz) = (i % side, i / side);
            let (x, z) = if side > 1 {
                (-3.2 + ix as f64 * spacing, -3.2 + iz as f64 * spacing)
            } else {
                (0.0, 0.0)
            };
            sf.objects.push(ObjectFile {
                kind: ShapeKind::Cuboid,
                name: Some(format!("cube {}", i + 1)),
                position: [x, 0.5 * size, z],
                size: Some([size; 3]),
                material: materials[i % materials.len().max(1)].clone(),
                ..t.clone()
            });
        }
    }
    Scene::build(&sf).expect("grid of a valid scene") // ok: the same objects at other sizes
}

/// The features [`feature_variants`] measures, by the names the command
/// line takes.
pub const FEATURES: [&str; 5] = ["shadows", "glass", "mirror", "specular", "dispersion"];

/// For each feature of [`FEATURES`]: its label, the cubes scene using it and
/// the same scene without it.
pub fn feature_variants(base: &SceneFile) -> Vec<(&'static str, Scene, Scene)> {
    let build = |f: &dyn Fn(&mut SceneFile)| {
        let mut sf = base.clone();
        f(&mut sf);
        Scene::build(&sf).expect("variant of a valid scene") // ok: the variants only switch valid settings
    };
    let no_lens = |sf: &mut SceneFile| sf.lenses.clear();
    let no_spec = |sf: &mut SceneFile| sf.materials.values_mut().for_each(|m| m.specular = 0.0);
    let mirror = |sf: &mut SceneFile| {
        if let Some(m) = sf.materials.get_mut("ground") {
            m.reflectivity = 0.5;
        }
    };
    let dispersive = |sf: &mut SceneFile| {
        if let Some(l) = sf.lenses.first_mut() {
            l.n = crate::scene::file::IndexFile::Cauchy([1.4846, 0.0042]);
        }
    };
    vec![
        ("shadows", build(&|_| {}), build(&|sf| sf.render.shadows = false)),
        ("glass (the lens)", build(&|_| {}), build(&no_lens)),
        // Glass reflects too: the mirror path is unused only without the lens.
        (
            "mirror",
            build(&|sf| {
                no_lens(sf);
                mirror(sf)
            }),
            build(&no_lens),
        ),
        // The lens glass has a highlight of its own: measured without it.
        (
            "specular",
            build(&no_lens),
            build(&|sf| {
                no_lens(sf);
                no_spec(sf)
            }),
        ),
        ("dispersion", build(&dispersive), build(&|_| {})),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Features;

    #[test]
    fn variants_have_the_objects_asked_for() {
        let (sf, _) = Scene::default_scene();
        let s = cubes_subset(&sf, 7);
        assert_eq!(s.objects.iter().filter(|o| o.name.starts_with("cube")).count(), 7);
        let g = cubes_grid(&sf, 10);
        assert_eq!(g.objects.iter().filter(|o| o.name.starts_with("cube")).count(), 100);
        assert!(g.bvh.is_some());
        let g5 = cubes_grid(&sf, 5);
        let orig = Scene::default_scene().1;
        // A 5×5 grid is the original layout.
        let pos = |s: &Scene| {
            s.objects
                .iter()
                .filter(|o| o.name.starts_with("cube"))
                .map(|o| o.position)
                .collect::<Vec<_>>()
        };
        for (a, b) in pos(&g5).iter().zip(pos(&orig)) {
            assert!((*a - b).length() < 1e-12);
        }
    }

    #[test]
    fn each_variant_pair_differs_in_its_feature_only_being_used() {
        let (sf, _) = Scene::default_scene();
        for ((label, with, without), name) in feature_variants(&sf).into_iter().zip(FEATURES) {
            let pick = |f: Features| match name {
                "shadows" => f.shadows,
                "glass" => f.glass,
                "mirror" => f.mirror,
                "specular" => f.specular,
                _ => f.dispersion,
            };
            assert!(pick(with.features) && !pick(without.features), "{label}");
        }
    }
}
