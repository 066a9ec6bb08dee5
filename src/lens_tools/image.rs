//! `lens info --object-distance`: the paraxial image of an object before
//! V1, real or virtual (a magnifier's), with its magnification.

use super::LensInfo;
use super::setup;
use serde::Serialize;

/// [`LensInfo::image`]: the object's distance before V1 and its paraxial
/// image (`null` when the object is at F: the image is at infinity).
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct ImageInfo {
    pub object_distance: f64,
    pub paraxial: Option<setup::ParaxialImage>,
}

impl LensInfo {
    /// The info with the paraxial image of an object `dist` before V1
    /// (`null` image for a lens without power or an object at F).
    pub fn with_object(mut self, dist: f64) -> LensInfo {
        let paraxial = match (self.efl, self.principal_front_from_v1, self.principal_rear_from_v2) {
            (Some(efl), Some(h1), Some(h2)) => setup::paraxial_image(dist, efl, [h1, h2]),
            _ => None,
        };
        self.image = Some(ImageInfo {
            object_distance: dist,
            paraxial,
        });
        self
    }
}

/// The image lines of `lens info --object-distance`.
pub(super) fn write_image(f: &mut std::fmt::Formatter, im: &ImageInfo) -> std::fmt::Result {
    let g = |x: f64| format!("{x:<24}");
    writeln!(
        f,
        "  object distance            {}   (before V1)",
        g(im.object_distance)
    )?;
    let Some(p) = im.paraxial else {
        return writeln!(f, "  image                      at infinity (the object is at F)");
    };
    if p.is_virtual {
        writeln!(
            f,
            "  virtual image              {}   (from V2: {} before it, on the object's side)",
            g(p.from_last_vertex),
            -p.from_last_vertex
        )?;
        writeln!(f, "  magnification              {}   (upright)", g(p.magnification))
    } else {
        writeln!(f, "  real image                 {}   (from V2)", g(p.from_last_vertex))?;
        writeln!(f, "  magnification              {}   (inverted)", g(p.magnification))
    }
}
