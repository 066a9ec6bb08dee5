//! The lens analysis (the desktop viewer's F7 window and the web page's
//! panel): for a lens or a lens system at the window's settings, the
//! cross-section to scale with the ray fan and F, F′, H, H′ and the real
//! marginal focus M; the longitudinal spherical aberration; the spot
//! diagram for the C, d and F lines at the paraxial focus plus a defocus;
//! distortion against field angle; and, for a system of dispersive glass,
//! its axial colour (the paraxial focus from 400 to 700 nm against the d
//! line's) and its lateral colour (the F line's chief ray height minus the
//! C line's in the d line's paraxial image plane, out to the usable field).
//! Every number comes from the figures of `lens fan`, `lens spot` and
//! `lens distortion` (every ray by `Lens::trace` or `LensSystem::trace`);
//! this only gathers them. The desktop draws [`Figures`] with egui,
//! [`super::chart`] writes them as SVG for the page.

use super::bench::Bench;
use super::sketch::Sketch;
use super::system_bench::SystemBench;
use super::system_colour::usable_curve;
use super::system_fan::system_fan;
use super::system_spot::{system_distortion, system_spot};
use super::{Setup, distortion, fan, spot_diagram};
use crate::geometry::{Lens, LensSystem};
use crate::optics::WAVELENGTH_D_UM;

/// The analysis window's settings (not part of the scene).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// The object's distance before the first vertex (`None`: at infinity).
    pub object_distance: Option<f64>,
    pub field_deg: f64,
    /// The image plane's distance from the paraxial image (defocus).
    pub defocus: f64,
    /// The spot's hexapolar rings.
    pub rings: u32,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            object_distance: None,
            field_deg: 0.0,
            defocus: 0.0,
            rings: 6,
        }
    }
}

/// One wavelength's spot as the window shows it.
#[derive(Clone, Debug, PartialEq)]
pub struct SpotLine {
    pub line: &'static str,
    pub points: Vec<Option<[f64; 3]>>,
    pub rms: Option<f64>,
    pub centroid: Option<[f64; 2]>,
}

impl SpotLine {
    /// A line's spot from its listed rays (the lens's or a system's).
    pub fn of<B: Bench>(line: &'static str, rays: &[B::Ray], rms: Option<f64>, centroid: Option<[f64; 2]>) -> SpotLine {
        SpotLine {
            line,
            points: rays.iter().map(B::image_point).collect(),
            rms,
            centroid,
        }
    }
}

/// One field angle's spot: the angle, its image plane from the last
/// vertex, and the C, d and F lines.
#[derive(Clone, Debug, PartialEq)]
pub struct FieldSpot {
    pub field_deg: f64,
    pub plane_from_last: f64,
    pub lines: Vec<SpotLine>,
}

/// The analysis of one lens or system.
#[derive(Clone, Debug)]
pub struct Figures {
    /// The first-order data in one line.
    pub header: String,
    pub sketch: Sketch,
    /// (LSA, pupil height) points.
    pub lsa: Vec<[f64; 2]>,
    /// The spots on the axis and at the field angle (`None`: no image plane).
    pub spots: Option<Vec<FieldSpot>>,
    /// (field °, distortion %) from the axis (`None`: no real paraxial image).
    pub distortion: Option<Vec<[f64; 2]>>,
    /// A dispersive system's axial colour: (focus − focus at d, nm).
    pub axial_colour: Option<Vec<[f64; 2]>>,
    /// Its lateral colour: (field °, F − C height); `None` inside
    /// `Some` without a real paraxial image.
    pub lateral_colour: Option<Option<Vec<[f64; 2]>>>,
    /// The last vertex in words (`V2`, `the last vertex`).
    pub last: &'static str,
}

/// The plane the window's spot is traced to, from the paraxial image
/// `paraxial` (from the last vertex): a real one moved by the defocus (the
/// spot refuses it at or before the last vertex), a magnifier's virtual
/// image as it is (`None`: the figures' own image).
pub fn spot_plane(paraxial: f64, defocus: f64) -> Option<f64> {
    (paraxial > 0.0).then_some(paraxial + defocus)
}

/// The field angles the window's spot shows: the axis, and the chosen
/// field beside it when it is off the axis.
pub fn spot_fields(field_deg: f64) -> Vec<f64> {
    if field_deg == 0.0 {
        vec![0.0]
    } else {
        vec![0.0, field_deg]
    }
}

/// An image plane from the last vertex `last`, in words, rounded.
pub fn plane_words(from_last: f64, last: &str) -> String {
    if from_last < 0.0 {
        format!("virtual image {:.4} before {last}", -from_last)
    } else {
        format!("plane {from_last:.4} after {last}")
    }
}

/// A number of the header (`—` when there is none).
fn opt(x: Option<f64>) -> String {
    x.map_or("—".into(), |x| format!("{x:.5}"))
}

/// (field °, value) points of the points that have a value.
fn curve<P>(points: &[P], f: impl Fn(&P) -> (f64, Option<f64>)) -> Vec<[f64; 2]> {
    points.iter().filter_map(|p| Some([f(p).0, f(p).1?])).collect()
}

/// The figures of `lens` (its shape and d-line index) at `a`.
pub fn lens_figures(lens: &Lens, a: &Settings) -> Result<Figures, String> {
    let s =
        Setup::new(lens.d, lens.r1, lens.r2, lens.index, a.object_distance, a.field_deg).map_err(|e| e.to_string())?;
    let f = fan(&s, 7, None).map_err(|e| e.to_string())?;
    let c = &f.cardinal.info;
    let header = format!(
        "EFL {}   BFD {}   FFD {}   marginal focus M {} from V2",
        opt(c.efl),
        opt(c.bfd),
        opt(c.ffd),
        opt(f.cardinal.object_marginal_focus_from_v2)
    );
    let spots = s.image_plane(None).ok().and_then(|paraxial| {
        let plane = spot_plane(paraxial, a.defocus);
        (spot_fields(a.field_deg).into_iter())
            .map(|field| {
                let d = spot_diagram(&s.at_field(field), plane, a.rings).ok()?;
                let lines = d
                    .spots
                    .iter()
                    .map(|sp| SpotLine::of::<Setup>(sp.line, &sp.rays, sp.rms_radius, sp.centroid));
                let (field_deg, plane_from_last) = (d.field_deg, d.image_plane_from_v2);
                Some(FieldSpot {
                    field_deg,
                    plane_from_last,
                    lines: lines.collect(),
                })
            })
            .collect()
    });
    let dist = distortion(&s, 30.0, 30).ok();
    Ok(Figures {
        header,
        sketch: f.sketch(&s),
        lsa: f.lsa.iter().filter_map(|p| Some([p.lsa?, p.height])).collect(),
        spots,
        distortion: dist.map(|d| curve(&d.points, |p| (p.field_deg, p.distortion_percent))),
        axial_colour: None,
        lateral_colour: None,
        last: "V2",
    })
}

/// The figures of the lens system `sys` at `a`.
pub fn system_figures(sys: &LensSystem, a: &Settings) -> Result<Figures, String> {
    let bench = SystemBench::new(sys.clone(), a.object_distance, a.field_deg).map_err(|e| e.to_string())?;
    let f = system_fan(&bench, 7, None).map_err(|e| e.to_string())?;
    let c = &f.cardinal.info;
    let header = format!(
        "{} surfaces   EFL {}   BFD {}   FFD {}   f/{}   stop: surface {}",
        c.surfaces,
        opt(c.efl),
        opt(c.bfd),
        opt(c.ffd),
        opt(c.f_number),
        c.stop
    );
    let plane = spot_plane(f.image_plane_from_last_vertex, a.defocus);
    let spots = (spot_fields(a.field_deg).into_iter())
        .map(|field| {
            let d = system_spot(&bench.at_field(field), plane, a.rings).ok()?;
            let lines =
                (d.spots.iter()).map(|sp| SpotLine::of::<SystemBench>(sp.line, &sp.rays, sp.rms_radius, sp.centroid));
            let (field_deg, plane_from_last) = (d.field_deg, d.image_plane_from_last_vertex);
            Some(FieldSpot {
                field_deg,
                plane_from_last,
                lines: lines.collect(),
            })
        })
        .collect();
    let dist = system_distortion(&bench, 30.0, 30).ok();
    let dispersive = sys.is_dispersive();
    let lateral =
        (dist.as_ref()).map(|d| usable_curve(d.points.iter().map(|p| (p.field_deg, p.colour.lateral_colour))));
    Ok(Figures {
        header,
        sketch: f.sketch(&bench),
        lsa: f.lsa.iter().filter_map(|p| Some([p.lsa?, p.height])).collect(),
        spots,
        distortion: dist.map(|d| curve(&d.points, |p| (p.field_deg, p.distortion_percent))),
        axial_colour: dispersive.then(|| focal_shift(sys)),
        lateral_colour: dispersive.then_some(lateral),
        last: "the last vertex",
    })
}

/// Axial colour: the paraxial focus at each wavelength from 400 to 700 nm
/// against the d line's (BFD(λ) − BFD(d), from the y–nu trace), as
/// (shift, nm) points.
pub fn focal_shift(sys: &LensSystem) -> Vec<[f64; 2]> {
    let d = sys.paraxial(WAVELENGTH_D_UM).bfd;
    (0..=60)
        .map(|k| 0.40 + 0.005 * f64::from(k))
        .filter_map(|l| {
            let shift = sys.paraxial(l).bfd - d;
            shift.is_finite().then_some([shift, l * 1e3])
        })
        .collect()
}
