//! The meridional ray fan and the longitudinal spherical aberration curve,
//! and the cross-section they are drawn on ([`super::sketch`]).

use super::setup::{ListedRay, Setup, SetupError, bad, exit_axis_crossing};
use super::sketch::{Kind, Sketch};
use super::{LensInfo, lens_info};
use crate::optics::{WAVELENGTH_D_UM, sagitta};
use glam::DVec3;
use serde::Serialize;

/// The most rays in a fan.
pub const MAX_FAN_RAYS: u32 = 1001;
/// Heights on the LSA curve.
pub const LSA_STEPS: u32 = 32;

/// One fan ray: as listed, with where it enters and leaves the glass.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct FanRay {
    #[serde(flatten)]
    pub ray: ListedRay,
    pub entry_point: Option<[f64; 3]>,
    pub exit_point: Option<[f64; 3]>,
    pub exit_direction: Option<[f64; 3]>,
}

/// One point of the LSA curve: a ray from the axial object point at pupil
/// height `height` (in the rim plane), where its exit line crosses the
/// axis, and that minus the paraxial image.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct LsaPoint {
    pub height: f64,
    pub ray: ListedRay,
    pub focus_from_v2: Option<f64>,
    pub lsa: Option<f64>,
}

/// Where the figures' marks lie: what `lens info` prints (at the d line),
/// and the paraxial image and real marginal focus of this object.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Cardinal {
    #[serde(flatten)]
    pub info: LensInfo,
    /// The paraxial image of the object, from V2 (the paraxial focus).
    pub paraxial_image_from_v2: Option<f64>,
    /// Where the real ray from the axial object point through the pupil
    /// edge crosses the axis, from V2 (from infinity: `marginal_focus_from_v2`).
    pub object_marginal_focus_from_v2: Option<f64>,
}

#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Fan {
    pub d: f64,
    pub r1: f64,
    pub r2: f64,
    pub n: f64,
    pub object_distance: Option<f64>,
    pub field_deg: f64,
    /// The plane the rays are followed to (their `image_point`), from V2.
    pub image_plane_from_v2: f64,
    /// That plane is a magnifier's virtual image, before V2: the image
    /// points are the rays' backward extensions. Absent when real.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub virtual_image: bool,
    pub cardinal: Cardinal,
    pub rays: Vec<FanRay>,
    pub lsa: Vec<LsaPoint>,
}

fn fan_ray(setup: &Setup, px: f64, n: f64, plane_z: f64) -> FanRay {
    let (ray, path) = ListedRay::traced(setup, px, 0.0, n, plane_z);
    FanRay {
        ray,
        entry_point: path.entry.map(|e| e.1.to_array()),
        exit_point: path.exit.map(|e| e.1.to_array()),
        exit_direction: path.exit.map(|e| e.2.to_array()),
    }
}

/// The cardinal points at the d line, and the object's real marginal focus.
pub fn cardinal(setup: &Setup) -> Result<Cardinal, SetupError> {
    let l = &setup.lens;
    let info = lens_info(l.d, l.r1, l.r2, setup.index, WAVELENGTH_D_UM).map_err(|e| bad("n", e.to_string()))?;
    let n = info.n;
    let axial = Setup {
        field_deg: 0.0,
        ..setup.clone()
    };
    let power = info.efl.is_some();
    let (o, u) = axial.ray(1.0, 0.0);
    let marginal = exit_axis_crossing(&axial.lens, o, u, n).filter(|_| power);
    Ok(Cardinal {
        info,
        paraxial_image_from_v2: setup.paraxial_image(n).map(|p| p.0),
        object_marginal_focus_from_v2: marginal,
    })
}

/// The LSA curve at the d line: heights PUPIL_FILL·(d/2)·k/steps.
pub fn lsa_curve(setup: &Setup, steps: u32) -> Vec<LsaPoint> {
    (super::bench::lsa(setup, steps).into_iter())
        .map(|p| LsaPoint {
            height: p.height,
            ray: p.ray,
            focus_from_v2: p.focus,
            lsa: p.lsa,
        })
        .collect()
}

/// `rays` meridional rays (pupil x from −1 to 1) at the d line, followed to
/// `image_plane` (default: the paraxial image, real or a magnifier's virtual
/// one, refused without either as `spot` and `distortion` refuse:
/// [`Setup::figure_image`]).
pub fn fan(setup: &Setup, rays: u32, image_plane: Option<f64>) -> Result<Fan, SetupError> {
    let pupil = super::bench::fan_pupil(rays)?;
    let n = setup.index.nominal();
    let from_v2 = setup.image_plane(image_plane)?;
    let plane_z = setup.plane_z(from_v2);
    Ok(Fan {
        d: setup.lens.d,
        r1: setup.lens.r1,
        r2: setup.lens.r2,
        n,
        object_distance: setup.object_distance,
        field_deg: setup.field_deg,
        image_plane_from_v2: from_v2,
        virtual_image: from_v2 < 0.0,
        cardinal: cardinal(setup)?,
        rays: pupil.iter().map(|&px| fan_ray(setup, px, n, plane_z)).collect(),
        lsa: lsa_curve(setup, LSA_STEPS),
    })
}

/// The lens's meridional outline as (s, x) points, s = −z along the light.
pub fn outline(setup: &Setup, points_per_face: u32) -> Vec<[f64; 2]> {
    let h = 0.5 * setup.lens.d;
    let (s1, s2) = (setup.sag1(), setup.sag2());
    let (r1, r2) = (setup.lens.r1, setup.lens.r2);
    let m = points_per_face.max(2);
    let at = |k: u32| -h + 2.0 * h * f64::from(k) / f64::from(m - 1);
    let mut pts: Vec<[f64; 2]> = (0..m).map(|k| [-(s1 - sagitta(r1, at(k).abs())), at(k)]).collect();
    pts.extend((0..m).rev().map(|k| [s2 - sagitta(r2, at(k).abs()), at(k)]));
    pts.push(pts[0]);
    pts
}

/// (s, x) of a world point in the meridional plane.
fn sx(p: [f64; 3]) -> [f64; 2] {
    [-p[2], p[0]]
}

impl Fan {
    /// The fan drawn to scale over the lens's cross-section: axis, rays,
    /// image plane, and F, F′, H, H′, V1, V2 and the real marginal focus M.
    pub fn sketch(&self, setup: &Setup) -> Sketch {
        let (c, m) = (&self.cardinal.info, self.cardinal.object_marginal_focus_from_v2);
        let mut sk = Sketch::default();
        let image = c.sag2 + self.image_plane_from_v2;
        // A magnifier's rays diverge after the lens: drawn on a while, their
        // backward extensions dashed to the virtual image before it.
        let end = match self.virtual_image {
            true => c.sag2 + (0.5 * -self.image_plane_from_v2).max(self.d),
            false => image,
        };
        let far = self.object_distance.unwrap_or(self.d).min(1.5 * end.max(self.d));
        let front = c.ffd.filter(|f| *f < 1.5 * end.max(self.d)).unwrap_or(0.0);
        let start = (-c.sag1 - far.max(1.1 * front)).min(image - 0.05 * (end - image));
        sk.line(Kind::Axis, vec![[start, 0.0], [end * 1.05 + 0.05 * self.d, 0.0]]);
        sk.line(Kind::Lens, outline(setup, 64));
        for r in &self.rays {
            let mut pts = vec![sx(r.ray.origin)];
            pts.extend(r.entry_point.map(sx));
            pts.extend(r.exit_point.map(sx));
            let ahead = |t: f64| {
                let (x, u) = (DVec3::from(r.exit_point?), DVec3::from(r.exit_direction?));
                Some(sx((x + u * t).to_array()))
            };
            match (self.virtual_image, r.ray.image_point, r.exit_point, r.exit_direction) {
                (true, Some(back), Some(x), Some(u)) => {
                    // On to s = end (s = −z along the light).
                    let t = if u[2] < 0.0 { (end + x[2]) / -u[2] } else { self.d };
                    pts.extend(ahead(t.max(0.0)));
                    sk.line(Kind::Virtual, vec![sx(x), sx(back)]);
                }
                (_, tail, _, _) => pts.extend(tail.map(sx).or_else(|| ahead(self.d))),
            }
            sk.line(Kind::Ray, pts);
        }
        let half = 0.6 * self.d;
        sk.line(Kind::Plane, vec![[image, -half], [image, half]]);
        let s2 = |from_v2: Option<f64>| from_v2.map(|x| c.sag2 + x);
        let marks = [
            ("V1", Some(-c.sag1)),
            ("V2", Some(c.sag2)),
            ("F", c.ffd.map(|f| -c.sag1 - f)),
            ("F′", s2(c.bfd)),
            ("M", s2(m)),
        ];
        for (label, s) in marks {
            if let Some(s) = s {
                sk.mark(label, [s, 0.0]);
            }
        }
        for (label, s) in [
            ("H", c.principal_front_from_v1.map(|h| -c.sag1 + h)),
            ("H′", s2(c.principal_rear_from_v2)),
        ] {
            if let Some(s) = s {
                sk.line(Kind::Principal, vec![[s, -half], [s, half]]);
                sk.mark(label, [s, if label == "H" { half } else { -half }]);
            }
        }
        sk.view = [start, end * 1.05 + 0.05 * self.d];
        sk
    }
}
