//! `lens info --object-distance`: the paraxial image of an object before
//! V1, real or virtual (a magnifier's), with its magnification.

use super::setup;
use super::{LensInfo, table_number, table_row};
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
    table_row(f, "object distance", &[im.object_distance], "(before V1)")?;
    let Some(p) = im.paraxial else {
        return writeln!(f, "  {:<30}at infinity (the object is at F)", "image");
    };
    let z = p.from_last_vertex;
    if p.is_virtual {
        let before = table_number(-z, f.alternate());
        let note = format!("(from V2: {} before it, on the object's side)", before.trim());
        table_row(f, "virtual image", &[z], &note)?;
        table_row(f, "magnification", &[p.magnification], "(upright)")
    } else {
        table_row(f, "real image", &[z], "(from V2)")?;
        table_row(f, "magnification", &[p.magnification], "(inverted)")
    }
}
