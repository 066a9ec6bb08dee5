//! The *Lens analysis* window for a selected lens system: the
//! cross-section of every element with the ray fan, the stop, H, H′ and
//! F′; the LSA curve; the spot diagram for the C, d and F lines (at the
//! paraxial focus plus the defocus, from the last vertex); the distortion
//! of the real chief ray; the axial colour of dispersive glass (the
//! paraxial focus from 400 to 700 nm against the d line's) and its
//! lateral colour (the F line's chief ray height minus the C line's in the
//! d line's paraxial image plane, out to the usable field). All from
//! `lensview::lens_tools`' system figures (every ray by
//! `LensSystem::trace`), as `lens fan`, `lens spot` and `lens distortion`
//! compute them.

use super::analysis::{AnalysisState, LINES, SpotLine, distortion_curve, spot_fields, spot_figure, spot_plane};
use super::plots::{Series, plot, sketch};
use egui::{Color32, Rect, Vec2};
use lensview::geometry::LensSystem;
use lensview::lens_tools::bench::Bench;
use lensview::lens_tools::system_bench::SystemBench;
use lensview::lens_tools::system_colour::usable_curve;
use lensview::lens_tools::system_fan::system_fan;
use lensview::lens_tools::system_spot::{SystemDistortion, system_distortion, system_spot};

/// Where each figure is on screen, by name (for `--ui-log`).
pub type Placed = Vec<(&'static str, Rect)>;

/// The figures of `sys` for the window's settings; returns where they are.
pub fn figures(ui: &mut egui::Ui, sys: &LensSystem, a: &AnalysisState) -> Placed {
    let mut placed = Placed::new();
    let bench = match SystemBench::new(sys.clone(), a.object(), a.field_deg) {
        Ok(b) => b,
        Err(e) => {
            ui.colored_label(super::ERROR, e.to_string());
            return placed;
        }
    };
    let width = ui.available_width().max(150.0);
    let plots = if sys.is_dispersive() { 5 } else { 3 };
    let (sketch_h, size) = super::analysis::figure_sizes(width, plots);
    let f = match system_fan(&bench, 7, None) {
        Ok(f) => f,
        Err(e) => {
            ui.colored_label(super::ERROR, e.to_string());
            return placed;
        }
    };
    let c = &f.cardinal.info;
    let opt = |x: Option<f64>| x.map_or("—".into(), |x| format!("{x:.5}"));
    ui.label(format!(
        "{} surfaces   EFL {}   BFD {}   FFD {}   f/{}   stop: surface {}",
        c.surfaces,
        opt(c.efl),
        opt(c.bfd),
        opt(c.ffd),
        opt(c.f_number),
        c.stop
    ));
    placed.push(("analysis sketch", sketch(ui, &f.sketch(&bench), width, sketch_h)));
    // Three plots, for dispersive glass five with the axial and lateral
    // colour: all in a row if they fit, wrapped (and scrolled) if not.
    let dist = system_distortion(&bench, 30.0, 30).ok();
    ui.with_layout(super::analysis::figure_row(), |ui| {
        let lsa: Vec<[f64; 2]> = f.lsa.iter().filter_map(|p| Some([p.lsa?, p.height])).collect();
        let r = super::analysis::lsa_plot(ui, size, lsa);
        placed.push(("analysis LSA", r));
        placed.extend(spot(ui, &bench, a, f.image_plane_from_last_vertex, size).map(|r| ("analysis spot", r)));
        placed.extend(distortion_plot(ui, dist.as_ref(), size).map(|r| ("analysis distortion", r)));
        if sys.is_dispersive() {
            placed.push(("analysis axial colour", focal_shift(ui, sys, size)));
            placed.extend(lateral_colour(ui, dist.as_ref(), size).map(|r| ("analysis lateral colour", r)));
        }
    });
    placed
}

/// Axial colour: the paraxial focus at each wavelength from 400 to 700 nm
/// against the d line's (BFD(λ) − BFD(d), from the y–nu trace).
fn focal_shift(ui: &mut egui::Ui, sys: &LensSystem, size: Vec2) -> Rect {
    let d = sys.paraxial(lensview::optics::WAVELENGTH_D_UM).bfd;
    let points: Vec<[f64; 2]> = (0..=60)
        .map(|k| 0.40 + 0.005 * f64::from(k))
        .filter_map(|l| {
            let shift = sys.paraxial(l).bfd - d;
            shift.is_finite().then_some([shift, l * 1e3])
        })
        .collect();
    let series = [Series {
        colour: LINES[0],
        points,
        dots: None,
        name: "",
    }];
    let axes = ("focus − focus at d (units)", "wavelength (nm)");
    plot(ui, size, "Axial colour", axes, &series, false)
}

fn spot(ui: &mut egui::Ui, bench: &SystemBench, a: &AnalysisState, paraxial: f64, size: Vec2) -> Option<Rect> {
    let plane = spot_plane(paraxial, a.defocus);
    let diagrams = (spot_fields(a.field_deg).into_iter())
        .map(|f| {
            let d = system_spot(&bench.at_field(f), plane, a.rings).ok()?;
            let lines =
                (d.spots.iter()).map(|sp| SpotLine::of::<SystemBench>(sp.line, &sp.rays, sp.rms_radius, sp.centroid));
            Some((d.field_deg, d.image_plane_from_last_vertex, lines.collect()))
        })
        .collect();
    spot_figure(ui, size, diagrams, "the last vertex")
}

fn distortion_plot(ui: &mut egui::Ui, dist: Option<&SystemDistortion>, size: Vec2) -> Option<Rect> {
    let points = dist.map(|d| {
        (d.points.iter())
            .filter_map(|p| Some([p.field_deg, p.distortion_percent?]))
            .collect()
    });
    distortion_curve(ui, size, points)
}

/// Lateral colour: the F chief ray's height minus the C chief ray's in the
/// d line's paraxial image plane, from the axis to the usable field
/// (where either chief ray is first lost), with the distortion's fields.
fn lateral_colour(ui: &mut egui::Ui, dist: Option<&SystemDistortion>, size: Vec2) -> Option<Rect> {
    let Some(d) = dist else {
        ui.allocate_ui(size, |ui| {
            ui.label("Lateral colour: no real paraxial image.");
        });
        return None;
    };
    let points = usable_curve(d.points.iter().map(|p| (p.field_deg, p.colour.lateral_colour)));
    let series = [Series {
        colour: LATERAL,
        points,
        dots: None,
        name: "",
    }];
    let axes = ("field angle (°)", "F − C height (units)");
    Some(plot(ui, size, "Lateral colour", axes, &series, false))
}

/// The lateral colour curve's colour: a magenta no other plot uses.
pub(super) const LATERAL: Color32 = Color32::from_rgb(220, 80, 220);
