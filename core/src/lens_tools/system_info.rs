//! `lens system`: the first-order data of a lens system at the d line
//! (EFL, BFD, FFD, principal planes, pupils, f-number) and its axial colour
//! from the C and F lines, from the y–nu trace ([`LensSystem::paraxial`]).

use crate::geometry::{LensSystem, Paraxial, Pupil};
use crate::glass::{C_UM as WAVELENGTH_C_UM, F_UM as WAVELENGTH_F_UM};
use crate::optics::WAVELENGTH_D_UM;
use serde::Serialize;
use std::fmt;

/// A pupil as printed.
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
pub struct PupilOutput {
    /// Along the light: the entrance pupil from the first vertex, the exit
    /// pupil from the last.
    pub position: f64,
    pub semi_diameter: f64,
}

/// What `lens system` prints. Lengths along the light; `null` (JSON) for a
/// system without power.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct SystemInfo {
    pub surfaces: usize,
    /// First vertex to last.
    pub length: f64,
    pub wavelength_um: f64,
    pub efl: Option<f64>,
    /// From the last vertex to F′.
    pub bfd: Option<f64>,
    /// From F to the first vertex.
    pub ffd: Option<f64>,
    /// H from the first vertex.
    pub front_principal: Option<f64>,
    /// H′ from the last vertex.
    pub rear_principal: Option<f64>,
    /// The stop surface (0-based): the one flagged, else the one an axial
    /// beam fills first.
    pub stop: usize,
    pub entrance_pupil: PupilOutput,
    pub exit_pupil: PupilOutput,
    pub f_number: Option<f64>,
    /// BFD at the F line minus BFD at the C line (486.1 − 656.3 nm).
    pub axial_colour: Option<f64>,
}

fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
}

fn pupil(p: Pupil) -> PupilOutput {
    // + 0.0: a pupil on the vertex is printed 0, not −0.
    PupilOutput {
        position: p.position + 0.0,
        semi_diameter: p.semi_diameter,
    }
}

/// The first-order data of `sys` at `wavelength_um`.
pub fn system_info(sys: &LensSystem, wavelength_um: f64) -> SystemInfo {
    let p: Paraxial = sys.paraxial(wavelength_um);
    let colour = sys.paraxial(WAVELENGTH_F_UM).bfd - sys.paraxial(WAVELENGTH_C_UM).bfd;
    SystemInfo {
        surfaces: sys.len(),
        length: sys.length(),
        wavelength_um,
        efl: finite(p.efl),
        bfd: finite(p.bfd),
        ffd: finite(p.ffd),
        front_principal: finite(p.front_principal),
        rear_principal: finite(p.rear_principal),
        stop: p.stop,
        entrance_pupil: pupil(p.entrance_pupil),
        exit_pupil: pupil(p.exit_pupil),
        f_number: finite(p.f_number),
        axial_colour: finite(colour).filter(|_| sys.is_dispersive()),
    }
}

/// The d line, as `lens info` defaults to.
pub const DEFAULT_WAVELENGTH_UM: f64 = WAVELENGTH_D_UM;

impl fmt::Display for SystemInfo {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        use super::table_row as row;
        writeln!(
            f,
            "lens system: {} surfaces, length {:.9}, at {} µm",
            self.surfaces, self.length, self.wavelength_um
        )?;
        let rows = [
            ("EFL", self.efl, ""),
            ("BFD", self.bfd, "(last vertex to F′)"),
            ("FFD", self.ffd, "(F to first vertex)"),
            ("principal plane H", self.front_principal, "(from the first vertex)"),
            ("principal plane H′", self.rear_principal, "(from the last vertex)"),
        ];
        for (label, x, note) in rows {
            match x {
                Some(x) => row(f, label, &[x], note)?,
                None => writeln!(f, "  {label:<30}{:>18}   (no power)", "∞")?,
            }
        }
        writeln!(f, "  {:<30}{:>18}", "stop", format!("surface {}", self.stop))?;
        let (e, x) = (self.entrance_pupil, self.exit_pupil);
        let pupil = "(position, semi-diameter)";
        row(
            f,
            "entrance pupil",
            &[e.position, e.semi_diameter],
            &format!("{pupil} from the first vertex"),
        )?;
        row(
            f,
            "exit pupil",
            &[x.position, x.semi_diameter],
            &format!("{pupil} from the last vertex"),
        )?;
        match self.f_number {
            Some(n) => row(f, "f-number", &[n], "")?,
            None => writeln!(f, "  {:<30}{:>18}   (no power)", "f-number", "∞")?,
        }
        if let Some(c) = self.axial_colour {
            row(f, "axial colour BFD(F) − BFD(C)", &[c], "")?;
        }
        Ok(())
    }
}
