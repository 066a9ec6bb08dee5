//! The scenes of `scenes/`, compiled into the binary so the viewer's
//! *Presets* menu works from any directory. `tests` below checks that every
//! file in `scenes/` is listed here.

/// One shipped scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Preset {
    /// Name shown in the menu.
    pub name: &'static str,
    /// File name in `scenes/`.
    pub file: &'static str,
    /// What it shows, for the menu's tooltip.
    pub about: &'static str,
    /// The TOML text.
    pub text: &'static str,
}

pub const PRESETS: &[Preset] = &[
    Preset {
        name: "cubes",
        file: "cubes.toml",
        about: "25 cubes on a slab, one light, the lens in front of the camera (the benchmark scene)",
        text: include_str!("../../../scenes/cubes.toml"),
    },
    Preset {
        name: "primitives",
        file: "primitives.toml",
        about: "one of each primitive, a mirror ball, a glass ball and a dispersive lens",
        text: include_str!("../../../scenes/primitives.toml"),
    },
    Preset {
        name: "optical bench",
        file: "optical-bench.toml",
        about: "a checkerboard wall behind the lens: magnification and distortion",
        text: include_str!("../../../scenes/optical-bench.toml"),
    },
    Preset {
        name: "rim lens",
        file: "rim-lens.toml",
        about: "a strong lens seen obliquely: the rim ring and the ghosts of reflections inside",
        text: include_str!("../../../scenes/rim-lens.toml"),
    },
    Preset {
        name: "focal spot",
        file: "focal-spot.toml",
        about: "a point light above a lens: the focal spot and its caustic ring on the floor",
        text: include_str!("../../../scenes/focal-spot.toml"),
    },
    Preset {
        name: "lens family",
        file: "lens-family.toml",
        about: "a checkerboard behind a plano-convex condenser, a biconcave diverger and a meniscus (lens systems)",
        text: include_str!("../../../scenes/lens-family.toml"),
    },
    Preset {
        name: "achromat",
        file: "achromat.toml",
        about: "a cemented achromat (AC254-100-A) beside an N-BK7 singlet of the same focal length: the singlet's colour fringes",
        text: include_str!("../../../scenes/achromat.toml"),
    },
    Preset {
        name: "lens camera",
        file: "camera-dgauss.toml",
        about: "the cubes photographed through a double Gauss at f/2.8 and a 36 × 24 sensor: depth of field and vignetting (a lens camera)",
        text: include_str!("../../../scenes/camera-dgauss.toml"),
    },
];

/// The preset called `name` (menu name or file name).
pub fn find(name: &str) -> Option<&'static Preset> {
    PRESETS.iter().find(|p| p.name == name || p.file == name)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;

    #[test]
    fn every_scene_file_is_a_preset_and_every_preset_is_valid() {
        let dir = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/..")).join("scenes");
        let mut files: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .filter_map(|e| e.ok())
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".toml"))
            .collect();
        files.sort();
        let mut listed: Vec<String> = PRESETS.iter().map(|p| p.file.to_string()).collect();
        listed.sort();
        assert_eq!(files, listed, "scenes/ and PRESETS differ");
        for p in PRESETS {
            Scene::parse(p.file, p.text).unwrap_or_else(|e| panic!("{e}"));
        }
        let cubes = Scene::parse("cubes", find("cubes").unwrap().text).unwrap().0;
        assert_eq!(cubes.objects.iter().filter(|o| o.name.is_none()).count(), 0);
        assert_eq!(cubes.objects.len(), 26, "the cubes preset is 25 cubes and a slab");
    }
}
