//! The serde mirror of a scene file (TOML). Every struct rejects unknown
//! keys; every default lives here, in one place. See README.md, "Scene file
//! format", for the meaning of each key.

use crate::glass::{self, Glass};
use serde::de::{self, IgnoredAny, MapAccess, SeqAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::collections::BTreeMap;
use std::fmt;

pub type V3 = [f64; 3];

#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    #[serde(default)]
    pub render: RenderFile,
    pub camera: CameraFile,
    #[serde(default)]
    pub ambient: AmbientFile,
    #[serde(default)]
    pub lights: Vec<LightFile>,
    #[serde(default)]
    pub materials: BTreeMap<String, MaterialFile>,
    #[serde(default)]
    pub objects: Vec<ObjectFile>,
    #[serde(default)]
    pub lenses: Vec<LensFile>,
    /// Lens systems: every lens that is not the biconvex `[[lenses]]`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub systems: Vec<SystemFile>,
    /// How the picture is shown and written as PNG (exposure, tone curve);
    /// left out of a saved file while it is the default.
    #[serde(default, skip_serializing_if = "DisplayFile::is_default")]
    pub display: DisplayFile,
}

/// `[display]`: the exposure in stops and the tone curve of the window and
/// of `render`'s PNG (never of its EXR, which stays linear radiance).
#[derive(Clone, Copy, Debug, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct DisplayFile {
    #[serde(default)]
    pub exposure: f64,
    #[serde(default)]
    pub tone: crate::color::ToneCurve,
}

impl DisplayFile {
    pub fn is_default(&self) -> bool {
        *self == DisplayFile::default()
    }
}

#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RenderFile {
    #[serde(default = "default_background", deserialize_with = "exact3")]
    pub background: V3,
    #[serde(default = "default_max_depth")]
    pub max_depth: u32,
    #[serde(default = "default_true")]
    pub shadows: bool,
    /// Samples per pixel for `lensview render` when `--spp` is not given.
    #[serde(default = "default_spp")]
    pub spp: u32,
    /// Caustics by photon mapping; `None`: on when glass or a mirror and a
    /// light are present.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub caustics: Option<bool>,
}

impl Default for RenderFile {
    fn default() -> Self {
        RenderFile {
            background: default_background(),
            max_depth: default_max_depth(),
            shadows: true,
            spp: default_spp(),
            caustics: None,
        }
    }
}

#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct CameraFile {
    #[serde(deserialize_with = "exact3")]
    pub position: V3,
    /// Degrees about x, y, z. Exclusive with `look_at`.
    #[serde(default, skip_serializing_if = "Option::is_none", deserialize_with = "opt_exact3")]
    pub rotation: Option<V3>,
    /// A point to look at (no roll). Exclusive with `rotation`.
    #[serde(default, skip_serializing_if = "Option::is_none", deserialize_with = "opt_exact3")]
    pub look_at: Option<V3>,
    /// Vertical field of view in degrees (with a `lens`, replaced by the
    /// lens's equivalent).
    #[serde(default = "default_fov")]
    pub fov: f64,
    /// A lens system in front of a sensor: a preset's name or a table
    /// (`preset`, `prescription` or `surfaces`, and `scale`).
    #[serde(default, skip_serializing_if = "Option::is_none", deserialize_with = "camera_lens")]
    pub lens: Option<CameraLensFile>,
    /// Sensor width and height, in the lens's units (times its `scale`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sensor: Option<[f64; 2]>,
    /// Distance from the camera to the plane in focus (default: infinity).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub focus_distance: Option<f64>,
    /// Or the sensor's distance behind the rear vertex.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sensor_distance: Option<f64>,
    /// The aperture stop's f-number (default: wide open).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub f_number: Option<f64>,
    /// With a `lens`, `true`: look through the pinhole of the lens's field
    /// of view instead, the lens, focus and f-number kept (the viewer's
    /// pinhole/lens switch).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pinhole: Option<bool>,
}

/// `[camera] lens`: `"PRESET"` or `{ preset | prescription | surfaces, scale }`.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct CameraLensFile {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preset: Option<String>,
    /// A table in pbrt-v4's realistic-camera form, as text.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub prescription: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub surfaces: Option<Vec<SurfaceFile>>,
    /// Presets and prescriptions: lengths (and the sensor) are multiplied by it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<f64>,
}

/// The `[camera] lens` key: a string names a preset.
fn camera_lens<'de, D: Deserializer<'de>>(d: D) -> Result<Option<CameraLensFile>, D::Error> {
    struct V;
    impl<'de> Visitor<'de> for V {
        type Value = CameraLensFile;
        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            f.write_str("a preset's name or a table { preset | prescription | surfaces, scale }")
        }
        fn visit_str<E: de::Error>(self, v: &str) -> Result<CameraLensFile, E> {
            Ok(CameraLensFile {
                preset: Some(v.to_string()),
                ..CameraLensFile::default()
            })
        }
        fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<CameraLensFile, A::Error> {
            CameraLensFile::deserialize(de::value::MapAccessDeserializer::new(map))
        }
    }
    d.deserialize_any(V).map(Some)
}

#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct AmbientFile {
    #[serde(default = "default_white", deserialize_with = "exact3")]
    pub color: V3,
    #[serde(default = "default_ambient")]
    pub intensity: f64,
}

impl Default for AmbientFile {
    fn default() -> Self {
        AmbientFile {
            color: default_white(),
            intensity: default_ambient(),
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum LightKind {
    Point,
    Directional,
}

#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LightFile {
    #[serde(rename = "type", default = "default_light_kind")]
    pub kind: LightKind,
    #[serde(default, skip_serializing_if = "Option::is_none", deserialize_with = "opt_exact3")]
    pub position: Option<V3>,
    #[serde(default, skip_serializing_if = "Option::is_none", deserialize_with = "opt_exact3")]
    pub direction: Option<V3>,
    #[serde(default = "default_white", deserialize_with = "exact3")]
    pub color: V3,
    pub intensity: f64,
}

#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialFile {
    #[serde(default = "default_grey", deserialize_with = "exact3")]
    pub color: V3,
    #[serde(default = "default_one")]
    pub ambient: f64,
    #[serde(default = "default_diffuse")]
    pub diffuse: f64,
    #[serde(default)]
    pub specular: f64,
    #[serde(default = "default_shininess")]
    pub shininess: f64,
    #[serde(default)]
    pub reflectivity: f64,
    #[serde(default)]
    pub transparency: f64,
    #[serde(default = "default_ior")]
    pub ior: IndexFile,
}

impl Default for MaterialFile {
    fn default() -> Self {
        MaterialFile {
            color: default_grey(),
            ambient: 1.0,
            diffuse: default_diffuse(),
            specular: 0.0,
            shininess: default_shininess(),
            reflectivity: 0.0,
            transparency: 0.0,
            ior: default_ior(),
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ShapeKind {
    Cuboid,
    Prism,
    Sphere,
    Pyramid,
}

impl ShapeKind {
    pub fn name(self) -> &'static str {
        match self {
            ShapeKind::Cuboid => "cuboid",
            ShapeKind::Prism => "prism",
            ShapeKind::Sphere => "sphere",
            ShapeKind::Pyramid => "pyramid",
        }
    }
}

/// A primitive. Which size keys apply depends on `type`: a cuboid takes
/// `size = [x, y, z]`, a sphere `radius`, a prism and a pyramid `side` (of
/// the base) and `height`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectFile {
    #[serde(rename = "type")]
    pub kind: ShapeKind,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    #[serde(default, deserialize_with = "exact3")]
    pub position: V3,
    #[serde(default, deserialize_with = "exact3")]
    pub rotation: V3,
    #[serde(default, skip_serializing_if = "Option::is_none", deserialize_with = "opt_exact3")]
    pub size: Option<V3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub side: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height: Option<f64>,
    /// Name of a `[materials.NAME]` table; the built-in grey when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<String>,
}

#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LensFile {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    #[serde(deserialize_with = "exact3")]
    pub center: V3,
    #[serde(default = "default_axis", deserialize_with = "exact3")]
    pub axis: V3,
    pub d: f64,
    pub r1: f64,
    pub r2: f64,
    pub n: IndexFile,
    /// Colour of the glass (1 = clear).
    #[serde(default = "default_white", deserialize_with = "exact3")]
    pub tint: V3,
}

/// `[[systems]]`: a lens system (README, "Lens systems"). `kind` says
/// which of the other keys it reads; the rest must be absent.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SystemFile {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// `surfaces`, `prescription`, `preset`, `plano-convex`,
    /// `plano-concave`, `biconvex`, `biconcave`, `meniscus` or `doublet`.
    pub kind: String,
    /// The first surface's vertex; or `center`, the middle of the axial
    /// length (one of the two).
    #[serde(default, skip_serializing_if = "Option::is_none", deserialize_with = "opt_exact3")]
    pub vertex: Option<V3>,
    #[serde(default, skip_serializing_if = "Option::is_none", deserialize_with = "opt_exact3")]
    pub center: Option<V3>,
    #[serde(default = "default_axis", deserialize_with = "exact3")]
    pub axis: V3,
    #[serde(default = "default_white", deserialize_with = "exact3")]
    pub tint: V3,
    /// Shorthand kinds: diameter, radii, centre thickness(es), glass(es).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub d: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub r: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub r1: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub r2: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub r3: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thickness: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thickness2: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub n: Option<IndexFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub n2: Option<IndexFile>,
    /// Plano kinds: which face is flat, `"front"` or `"back"` (default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub flat: Option<String>,
    /// `kind = "surfaces"`: the surfaces in the order the light meets them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub surfaces: Option<Vec<SurfaceFile>>,
    /// `kind = "prescription"`: a table in pbrt-v4's realistic-camera form.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub prescription: Option<String>,
    /// `kind = "preset"`: a built-in system's name.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preset: Option<String>,
    /// Prescriptions and presets: lengths are multiplied by it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<f64>,
}

/// One surface of `[[systems]]` `surfaces`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SurfaceFile {
    /// Signed radius (0 = plane).
    #[serde(default)]
    pub radius: f64,
    #[serde(default)]
    pub thickness: f64,
    /// The medium after the surface (1 = air).
    #[serde(default = "default_air")]
    pub n: IndexFile,
    pub semi_aperture: f64,
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub stop: bool,
}

fn default_air() -> IndexFile {
    IndexFile::Constant(1.0)
}

/// A refractive index as written in a file: `1.5`, `{ cauchy = [A, B] }`
/// or a catalogue glass's name, `"N-BK7"` (resolved when read; an unknown
/// name is refused with the list of known ones).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum IndexFile {
    Constant(f64),
    Cauchy([f64; 2]),
    Glass(&'static Glass),
}

impl<'de> Deserialize<'de> for IndexFile {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = IndexFile;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number, a glass name or a table { cauchy = [A, B] }")
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<IndexFile, E> {
                glass::lookup(v).map(IndexFile::Glass).ok_or_else(|| {
                    let shown: String = v.chars().take(40).flat_map(char::escape_default).collect();
                    E::custom(format!("unknown glass \"{shown}\"; known glasses: {}", glass::names()))
                })
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<IndexFile, E> {
                Ok(IndexFile::Constant(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<IndexFile, E> {
                Ok(IndexFile::Constant(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<IndexFile, E> {
                Ok(IndexFile::Constant(v as f64))
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<IndexFile, A::Error> {
                let mut out = None;
                while let Some(key) = map.next_key::<String>()? {
                    if key != "cauchy" {
                        return Err(de::Error::unknown_field(&key, &["cauchy"]));
                    }
                    out = Some(IndexFile::Cauchy(map.next_value::<Exact<2>>()?.0));
                }
                out.ok_or_else(|| de::Error::missing_field("cauchy"))
            }
        }
        d.deserialize_any(V)
    }
}

impl Serialize for IndexFile {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            IndexFile::Constant(n) => s.serialize_f64(*n),
            IndexFile::Glass(g) => s.serialize_str(g.name),
            IndexFile::Cauchy(ab) => {
                use serde::ser::SerializeMap;
                let mut m = s.serialize_map(Some(1))?;
                m.serialize_entry("cauchy", ab)?;
                m.end()
            }
        }
    }
}

/// Exactly `N` numbers. serde's `[f64; N]` stops reading after `N` and the
/// TOML reader does not complain about the rest, so `[0, 1, 6, 7]` would
/// pass as `[0, 1, 6]`; this counts what is left and refuses it.
struct Exact<const N: usize>([f64; N]);

impl<'de, const N: usize> Deserialize<'de> for Exact<N> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V<const N: usize>;
        impl<'de, const N: usize> Visitor<'de> for V<N> {
            type Value = Exact<N>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                write!(f, "an array of {N} numbers")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Exact<N>, A::Error> {
                let mut out = [0.0; N];
                for (i, x) in out.iter_mut().enumerate() {
                    *x = seq.next_element()?.ok_or_else(|| de::Error::invalid_length(i, &self))?;
                }
                let mut len = N;
                while seq.next_element::<IgnoredAny>()?.is_some() {
                    len += 1;
                }
                if len > N {
                    return Err(de::Error::invalid_length(len, &self));
                }
                Ok(Exact(out))
            }
        }
        d.deserialize_seq(V::<N>)
    }
}

fn exact3<'de, D: Deserializer<'de>>(d: D) -> Result<V3, D::Error> {
    Exact::<3>::deserialize(d).map(|e| e.0)
}

fn opt_exact3<'de, D: Deserializer<'de>>(d: D) -> Result<Option<V3>, D::Error> {
    exact3(d).map(Some)
}

fn default_background() -> V3 {
    [0.02, 0.025, 0.035]
}
fn default_max_depth() -> u32 {
    8
}
fn default_true() -> bool {
    true
}
fn default_spp() -> u32 {
    4
}
fn default_fov() -> f64 {
    45.0
}
fn default_white() -> V3 {
    [1.0, 1.0, 1.0]
}
fn default_grey() -> V3 {
    [0.7, 0.7, 0.7]
}
fn default_ambient() -> f64 {
    0.1
}
fn default_one() -> f64 {
    1.0
}
fn default_diffuse() -> f64 {
    0.9
}
fn default_shininess() -> f64 {
    32.0
}
fn default_ior() -> IndexFile {
    IndexFile::Constant(1.5)
}
fn default_light_kind() -> LightKind {
    LightKind::Point
}
fn default_axis() -> V3 {
    [0.0, 0.0, 1.0]
}
