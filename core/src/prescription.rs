//! Lens prescriptions as text: the format of pbrt-v4's realistic camera
//! (`lenses/*.dat`), one surface a line, object side first:
//!
//! ```text
//! # radius  thickness  index-after  aperture-diameter     (millimetres)
//! 29.475    3.76       1.67         25.2
//! 0         4.5        0            17.1                  # the aperture stop
//! ```
//!
//! - `radius`: signed radius of curvature; `0` marks the aperture stop (a
//!   plane).
//! - `thickness`: axial distance to the next surface, ≥ 0.
//! - `index-after`: the medium after the surface: a number ≥ 1, `0` or
//!   `air` for air, or a catalogue glass's name (`N-BK7`, see
//!   [`crate::glass`]), which brings its Sellmeier dispersion.
//! - `aperture-diameter`: the clear diameter, > 0.
//!
//! `#` starts a comment (whole line or trailing); blank lines are skipped.
//! Parsing is pure: the caller reads the file and passes its text and a name
//! for the errors, which read `name:line: field: message`.

use crate::glass;
use crate::optics::Index;
use std::fmt;

/// One surface of a prescription.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrescriptionRow {
    /// 1-based line of the text the row came from.
    pub line: usize,
    /// Signed radius of curvature (mm); 0 for the stop.
    pub radius: f64,
    /// Axial distance to the next surface (mm).
    pub thickness: f64,
    /// The medium after the surface; air is `Index::Constant(1.0)`.
    pub n: Index,
    /// Clear aperture diameter (mm).
    pub aperture_diameter: f64,
    /// The surface is the aperture stop (radius 0 in the file).
    pub stop: bool,
}

impl PrescriptionRow {
    /// The medium after the surface is air.
    pub fn is_air_after(&self) -> bool {
        self.n == AIR
    }
}

/// The index of air in a prescription.
pub const AIR: Index = Index::Constant(1.0);

/// A refusal: `name:line: field: message`.
#[derive(Clone, Debug, PartialEq)]
pub struct PrescriptionError {
    pub name: String,
    /// 1-based line; for an empty text, the number of lines it has (at least 1).
    pub line: usize,
    /// `radius`, `thickness`, `n`, `aperture`, `columns` or `file`.
    pub field: &'static str,
    pub message: String,
}

impl fmt::Display for PrescriptionError {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "{}:{}: {}: {}", self.name, self.line, self.field, self.message)
    }
}

impl std::error::Error for PrescriptionError {}

/// What a text field shows in a message: at most 40 characters, escaped.
fn shown(s: &str) -> String {
    s.chars().take(40).flat_map(char::escape_default).collect()
}

/// A finite number, or why not.
fn number(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(x),
        Ok(x) => Err(format!("{x} is not a finite number")),
        Err(_) => Err(format!("`{}` is not a number", shown(s))),
    }
}

/// The index column: `0`/`air` (air), a number ≥ 1, or a glass name.
fn index(s: &str) -> Result<Index, String> {
    if s.eq_ignore_ascii_case("air") {
        return Ok(AIR);
    }
    if let Ok(x) = s.parse::<f64>() {
        return match x {
            0.0 => Ok(AIR),
            x if x >= 1.0 && x.is_finite() => Ok(Index::Constant(x)),
            x => Err(format!("index {x} must be 0 (air) or a finite number ≥ 1")),
        };
    }
    glass::lookup(s).map(Index::Glass).ok_or_else(|| {
        format!(
            "`{}` is neither a number nor a known glass (known: {})",
            shown(s),
            glass::names()
        )
    })
}

/// One line's four columns as a row.
fn row(line: usize, cols: &[&str]) -> Result<PrescriptionRow, (&'static str, String)> {
    let radius = number(cols[0]).map_err(|m| ("radius", m))?;
    let thickness = number(cols[1]).map_err(|m| ("thickness", m))?;
    if thickness < 0.0 {
        return Err(("thickness", format!("thickness {thickness} must not be negative")));
    }
    let n = index(cols[2]).map_err(|m| ("n", m))?;
    let aperture_diameter = number(cols[3]).map_err(|m| ("aperture", m))?;
    if !(aperture_diameter > 0.0) {
        return Err((
            "aperture",
            format!("aperture diameter {aperture_diameter} must be positive"),
        ));
    }
    let stop = radius == 0.0;
    if stop && n != AIR {
        return Err((
            "n",
            "the aperture stop (radius 0) must have air after it (0, 1 or air)".to_string(),
        ));
    }
    Ok(PrescriptionRow {
        line,
        radius,
        thickness,
        n,
        aperture_diameter,
        stop,
    })
}

/// The rows of a prescription `text`; `name` (a file name) heads every error.
pub fn parse(name: &str, text: &str) -> Result<Vec<PrescriptionRow>, PrescriptionError> {
    let err = |line: usize, field: &'static str, message: String| PrescriptionError {
        name: name.to_string(),
        line,
        field,
        message,
    };
    let mut rows = Vec::new();
    let mut lines = 0;
    for (i, raw) in text.lines().enumerate() {
        lines = i + 1;
        let code = raw.split('#').next().unwrap_or("");
        let cols: Vec<&str> = code.split_whitespace().collect();
        match cols.len() {
            0 => continue,
            4 => rows.push(row(i + 1, &cols).map_err(|(field, m)| err(i + 1, field, m))?),
            k => {
                let what = if k < 4 { "too few" } else { "too many" };
                let message =
                    format!("{what} columns: {k}, expected 4 (radius, thickness, index after, aperture diameter)");
                return Err(err(i + 1, "columns", message));
            }
        }
    }
    if rows.is_empty() {
        return Err(err(
            lines.max(1),
            "file",
            "no surfaces (only comments and blank lines)".to_string(),
        ));
    }
    Ok(rows)
}

/// The prescriptions of `lenses/`, compiled in: `[[systems]]` with
/// `kind = "preset"` and `lens … --preset` name them.
pub const PRESETS: &[(&str, &str)] = &[
    ("double-gauss-50mm", include_str!("../../lenses/dgauss.50mm.dat")),
    (
        "cooke-triplet-100mm",
        include_str!("../../lenses/cooke-triplet.100mm.dat"),
    ),
    (
        "achromat-AC254-100-A",
        include_str!("../../lenses/achromat.AC254-100-A.dat"),
    ),
    ("wide-22mm", include_str!("../../lenses/wide.22mm.dat")),
    ("telephoto-250mm", include_str!("../../lenses/telephoto.250mm.dat")),
    ("fisheye-10mm", include_str!("../../lenses/fisheye.10mm.dat")),
];

/// The preset called `name`.
pub fn preset(name: &str) -> Option<&'static str> {
    PRESETS.iter().find(|(n, _)| *n == name).map(|(_, t)| *t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_numbers_stops_comments_and_blank_lines() {
        let text = "# a comment\n\n 29.475\t3.76\t1.67\t25.2\n0 4.5 0 17.1  # stop\n-39.73 0 1 20\n";
        let rows = parse("t.dat", text).unwrap();
        assert_eq!(rows.len(), 3);
        assert_eq!(
            rows[0],
            PrescriptionRow {
                line: 3,
                radius: 29.475,
                thickness: 3.76,
                n: Index::Constant(1.67),
                aperture_diameter: 25.2,
                stop: false
            }
        );
        assert!(rows[1].stop && rows[1].is_air_after() && rows[1].line == 4);
        assert!(!rows[2].stop && rows[2].is_air_after() && rows[2].radius == -39.73);
    }

    #[test]
    fn the_index_column_takes_glass_names_and_air() {
        let rows = parse(
            "g.dat",
            "62.75 4 N-BK7 25.4\n-45.71 2.5 sf5 25.4\n-128.23 97 air 25.4\n",
        )
        .unwrap();
        assert_eq!(rows[0].n, Index::Glass(glass::lookup("N-BK7").unwrap()));
        assert_eq!(rows[1].n, Index::Glass(glass::lookup("SF5").unwrap()));
        assert!(rows[2].is_air_after());
    }

    #[test]
    fn every_refusal_names_the_line_and_field() {
        let cases: &[(&str, &str)] = &[
            ("1 2 1.5\n", "x:1: columns: too few columns: 3"),
            ("# c\n1 2 1.5 4 5\n", "x:2: columns: too many columns: 5"),
            ("abc 2 1.5 4\n", "x:1: radius: `abc` is not a number"),
            ("1 nan 1.5 4\n", "x:1: thickness: NaN is not a finite number"),
            ("1 -2 1.5 4\n", "x:1: thickness: thickness -2 must not be negative"),
            ("1 2 0.5 4\n", "x:1: n: index 0.5 must be 0 (air)"),
            (
                "1 2 XYZ 4\n",
                "x:1: n: `XYZ` is neither a number nor a known glass (known: N-BK7",
            ),
            ("1 2 1.5 -4\n", "x:1: aperture: aperture diameter -4 must be positive"),
            ("1 2 1.5 0\n", "x:1: aperture: aperture diameter 0 must be positive"),
            ("1 2 1.5 inf\n", "x:1: aperture: inf is not a finite number"),
            (
                "0 2 1.5 4\n",
                "x:1: n: the aperture stop (radius 0) must have air after it",
            ),
            ("# only\n\n", "x:2: file: no surfaces"),
            ("", "x:1: file: no surfaces"),
        ];
        for (text, want) in cases {
            let e = parse("x", text).unwrap_err().to_string();
            assert!(e.starts_with(want), "{text:?}: {e}");
            assert!(!e.contains('\n'), "{e}");
        }
        // Text from the file is escaped and cut in messages.
        let e = parse("x", &format!("1 2 \u{1b}[31m{} 4", "a".repeat(100)))
            .unwrap_err()
            .to_string();
        assert!(!e.contains('\u{1b}') && e.len() < 400, "{e}");
    }

    /// Every prescription shipped in `lenses/` reads.
    #[test]
    fn every_file_in_lenses_parses() {
        let dir = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/..")).join("lenses");
        let mut seen = 0;
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_none_or(|e| e != "dat") {
                continue;
            }
            let text = std::fs::read_to_string(&path).unwrap();
            let rows = parse(&path.display().to_string(), &text).unwrap_or_else(|e| panic!("{e}"));
            assert!(
                rows.iter().filter(|r| r.stop).count() <= 1,
                "{}: one stop at most",
                path.display()
            );
            assert!(
                rows.last().unwrap().is_air_after(),
                "{}: air after the last surface",
                path.display()
            );
            seen += 1;
        }
        assert!(seen >= 6, "found {seen} prescriptions");
        let dgauss = parse("dgauss", &std::fs::read_to_string(dir.join("dgauss.50mm.dat")).unwrap()).unwrap();
        assert_eq!(dgauss.len(), 11);
        assert!(dgauss[5].stop && dgauss[5].aperture_diameter == 17.1);
    }
}
