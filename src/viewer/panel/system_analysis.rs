//! The *Lens analysis* window for a selected lens system: the
//! cross-section of every element with the ray fan, the stop, H, H′ and
//! F′; the LSA curve; the spot diagram for the C, d and F lines (at the
//! paraxial focus plus the defocus, from the last vertex); the distortion
//! of the real chief ray; the axial colour of dispersive glass (the
//! paraxial focus from 400 to 700 nm against the d line's). All from
//! `lensview::lens_tools`' system figures (every ray by
//! `LensSystem::trace`), as `lens fan`, `lens spot` and `lens distortion`
//! compute them.

use super::analysis::{AnalysisState, LINES, distortion_curve};
use super::plots::{Series, plot, sketch};
use egui::Vec2;
use lensview::geometry::LensSystem;
use lensview::lens_tools::system_bench::SystemBench;
use lensview::lens_tools::system_fan::system_fan;
use lensview::lens_tools::system_spot::{system_distortion, system_spot};

/// The figures of `sys` for the window's settings.
pub fn figures(ui: &mut egui::Ui, sys: &LensSystem, a: &AnalysisState) {
    let bench = match SystemBench::new(sys.clone(), a.object(), a.field_deg) {
        Ok(b) => b,
        Err(e) => {
            ui.colored_label(super::ERROR, e.to_string());
            return;
        }
    };
    let width = ui.available_width().max(300.0);
    let f = match system_fan(&bench, 7, None) {
        Ok(f) => f,
        Err(e) => {
            ui.colored_label(super::ERROR, e.to_string());
            return;
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
    sketch(ui, &f.sketch(&bench), width, 240.0);
    // Three plots a row, four with the axial colour of dispersive glass.
    let plots = if sys.is_dispersive() { 4.0 } else { 3.0 };
    ui.horizontal(|ui| {
        let size = Vec2::new((width / plots - 8.0).max(140.0), 230.0);
        let lsa: Vec<[f64; 2]> = f.lsa.iter().filter_map(|p| Some([p.lsa?, p.height])).collect();
        let series = [Series {
            colour: LINES[1],
            points: lsa,
            dots: false,
        }];
        plot(ui, size, "LSA (d line)", ("focus − paraxial", "height"), &series, false);
        spot(ui, &bench, a, f.image_plane_from_last_vertex, size);
        distortion_plot(ui, &bench, size);
        if sys.is_dispersive() {
            focal_shift(ui, sys, size);
        }
    });
}

/// Axial colour: the paraxial focus at each wavelength from 400 to 700 nm
/// against the d line's (BFD(λ) − BFD(d), from the y–nu trace).
fn focal_shift(ui: &mut egui::Ui, sys: &LensSystem, size: Vec2) {
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
        dots: false,
    }];
    plot(ui, size, "Axial colour", ("focus − focus(d)", "nm"), &series, false);
}

fn spot(ui: &mut egui::Ui, bench: &SystemBench, a: &AnalysisState, paraxial: f64, size: Vec2) {
    let Ok(sd) = system_spot(bench, Some(paraxial + a.defocus), a.rings) else {
        ui.allocate_ui(size, |ui| {
            ui.label("Spot: no real image plane after the last vertex here.");
        });
        return;
    };
    ui.vertical(|ui| {
        let series: Vec<Series> = (sd.spots.iter().zip(LINES))
            .map(|(sp, colour)| Series {
                colour,
                points: sp
                    .rays
                    .iter()
                    .filter_map(|r| r.image_point.map(|p| [p[0], p[1]]))
                    .collect(),
                dots: true,
            })
            .collect();
        let title = format!("Spot at {:.4}", sd.image_plane_from_last_vertex);
        plot(ui, size, &title, ("x", "y"), &series, true);
        for (sp, colour) in sd.spots.iter().zip(LINES) {
            let r = sp.rms_radius.map_or("—".into(), |r| format!("{r:.3e}"));
            ui.colored_label(colour, format!("{}: RMS {r}  rays {}", sp.line, sp.ray_count));
        }
    });
}

fn distortion_plot(ui: &mut egui::Ui, bench: &SystemBench, size: Vec2) {
    let points = system_distortion(bench, 30.0, 30).ok().map(|d| {
        (d.points.iter())
            .filter_map(|p| Some([p.field_deg, p.distortion_percent?]))
            .collect()
    });
    distortion_curve(ui, size, points);
}
