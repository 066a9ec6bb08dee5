//! The *Lens analysis* window's two more plots for a lens system of
//! dispersive glass: its axial colour (the paraxial focus from 400 to 700
//! nm against the d line's) and its lateral colour (the F line's chief ray
//! height minus the C line's in the d line's paraxial image plane, out to
//! the usable field). The numbers are `lensview::lens_tools::analysis`'s
//! (as `lens distortion` computes them); the rest of a system's window is
//! the lens's (`analysis.rs`).

use super::analysis::LINES;
use super::plots::{Series, plot};
use egui::{Color32, Rect, Vec2};
use lensview::lens_tools::analysis::Figures;

/// Where each figure is on screen, by name (for `--ui-log`).
pub type Placed = Vec<(&'static str, Rect)>;

/// The axial and lateral colour of `f`, when it has them (a dispersive
/// system's); returns where they are.
pub fn colour_plots(ui: &mut egui::Ui, f: &Figures, size: Vec2) -> Placed {
    let mut placed = Placed::new();
    if let Some(points) = &f.axial_colour {
        placed.push(("analysis axial colour", focal_shift(ui, points.clone(), size)));
    }
    if let Some(lateral) = &f.lateral_colour {
        placed.extend(lateral_colour(ui, lateral.clone(), size).map(|r| ("analysis lateral colour", r)));
    }
    placed
}

/// Axial colour: (BFD(λ) − BFD(d), nm) points.
fn focal_shift(ui: &mut egui::Ui, points: Vec<[f64; 2]>, size: Vec2) -> Rect {
    let series = [Series {
        colour: LINES[0],
        points,
        dots: None,
        name: "",
    }];
    let axes = ("focus − focus at d (units)", "wavelength (nm)");
    plot(ui, size, "Axial colour", axes, &series, false)
}

/// Lateral colour: the F chief ray's height minus the C chief ray's, from
/// the axis to the usable field, or why there is none.
fn lateral_colour(ui: &mut egui::Ui, points: Option<Vec<[f64; 2]>>, size: Vec2) -> Option<Rect> {
    let Some(points) = points else {
        ui.allocate_ui(size, |ui| {
            ui.label("Lateral colour: no real paraxial image.");
        });
        return None;
    };
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
