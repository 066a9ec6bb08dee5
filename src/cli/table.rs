//! The one shape every measurement command reports in: a [`Table`] of
//! formatted cells that [`Table::emit`] prints aligned on stdout, makes into
//! CSV and, when it carries a [`Plot`], draws as a log–log PNG, written by
//! [`write_files`] all at once. The CSV
//! files are read by the docs (docs/bench/, docs/converge-*.csv), so a
//! table's CSV columns are a contract; printed-only columns are not.

use crate::plot::{Series, log_log};
use anyhow::Result;
use lensview::output::write_all;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// One column: its CSV header, or `None` for a figure derived for the
/// reader and only printed, and its printed label.
pub struct Column {
    pub csv: Option<&'static str>,
    pub label: &'static str,
}

impl Column {
    /// A column written to the CSV file as `csv` and printed as `label`.
    pub const fn new(csv: &'static str, label: &'static str) -> Self {
        Column { csv: Some(csv), label }
    }

    /// A column only printed.
    pub const fn shown(label: &'static str) -> Self {
        Column { csv: None, label }
    }
}

/// A log–log plot of a table's figures.
pub struct Plot {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
}

/// A titled table of cells, formatted once so that the printed figures and
/// the CSV figures are the same strings; `notes` are printed after it.
pub struct Table {
    pub title: String,
    pub columns: Vec<Column>,
    pub rows: Vec<Vec<String>>,
    pub notes: Vec<String>,
    pub plot: Option<Plot>,
}

impl Table {
    pub fn new(title: impl Into<String>, columns: Vec<Column>) -> Self {
        Table {
            title: title.into(),
            columns,
            rows: Vec::new(),
            notes: Vec::new(),
            plot: None,
        }
    }

    /// Adds a row: one cell for each column, in order.
    pub fn row(&mut self, cells: Vec<String>) {
        debug_assert_eq!(cells.len(), self.columns.len(), "{}", self.title);
        self.rows.push(cells);
    }

    /// A first line of `header`, then the rows, as string slices.
    fn lines<'a>(&'a self, header: impl Iterator<Item = &'a str>) -> Vec<Vec<&'a str>> {
        std::iter::once(header.collect())
            .chain(self.rows.iter().map(|r| r.iter().map(String::as_str).collect()))
            .collect()
    }

    /// The CSV text: the header of the CSV columns, then one line a row.
    /// Cells are written as they are (the figures and labels of the
    /// measurements hold no commas or quotes).
    pub fn csv(&self) -> String {
        let header = self.columns.iter().map(|c| c.csv.unwrap_or_default());
        let written = |i: &usize| self.columns[*i].csv.is_some();
        self.lines(header)
            .iter()
            .map(|cells| {
                let kept: Vec<&str> = (0..cells.len()).filter(written).map(|i| cells[i]).collect();
                kept.join(",") + "\n"
            })
            .collect()
    }

    /// The printed text: a blank line, the title, the labels and the rows
    /// in columns (numbers right-aligned, text left-aligned), then the
    /// notes.
    pub fn text(&self) -> String {
        let len = |s: &str| s.chars().count();
        let is_number = |s: &str| s.trim_end_matches('%').parse::<f64>().is_ok();
        let lines = self.lines(self.columns.iter().map(|c| c.label));
        let widths: Vec<usize> = (0..self.columns.len())
            .map(|i| lines.iter().map(|cells| len(cells[i])).max().unwrap_or(0))
            .collect();
        let left: Vec<bool> = (0..self.columns.len())
            .map(|i| !self.rows.iter().all(|r| is_number(&r[i])))
            .collect();
        let mut out = format!("\n{}:\n", self.title);
        for cells in &lines {
            let mut line = String::new();
            for ((cell, w), left) in cells.iter().zip(&widths).zip(&left) {
                let pad = " ".repeat(w - len(cell));
                line += &if *left {
                    format!("  {cell}{pad}")
                } else {
                    format!("  {pad}{cell}")
                };
            }
            let _ = writeln!(out, "{}", line.trim_end());
        }
        for n in &self.notes {
            let _ = writeln!(out, "{n}");
        }
        out
    }

    /// Prints the table and returns its files: the CSV text for `csv` and,
    /// if it has a plot, the PNG drawn for `png`. Nothing is written here:
    /// the caller writes them all as one (`output::write_all`), once every
    /// file is ready, so a failure leaves none behind.
    pub fn emit(&self, csv: &Path, png: &Path) -> Result<Vec<(PathBuf, Vec<u8>)>> {
        print!("{}", self.text());
        let mut files = vec![(csv.to_path_buf(), self.csv().into_bytes())];
        if let Some(p) = &self.plot {
            files.push((
                png.to_path_buf(),
                log_log(png, &p.title, &p.x_label, &p.y_label, &p.series)?,
            ));
        }
        Ok(files)
    }
}

/// Writes `files` as one ([`lensview::output::write_all`]).
pub fn write_files(files: &[(PathBuf, Vec<u8>)]) -> Result<()> {
    let refs: Vec<(&Path, &[u8])> = files.iter().map(|(p, b)| (p.as_path(), b.as_slice())).collect();
    write_all(&refs)?;
    Ok(())
}

/// `v` with `decimals` digits after the point, as the CSV files hold it.
pub fn num(v: f64, decimals: usize) -> String {
    format!("{v:.decimals$}")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table() -> Table {
        let mut t = Table::new(
            "sizes",
            vec![
                Column::new("width", "w"),
                Column::shown("rate"),
                Column::new("median_ms", "median ms"),
            ],
        );
        t.row(vec!["100".into(), "13.76".into(), num(0.7271, 3)]);
        t.row(vec!["1600".into(), "1.5".into(), num(143.0, 3)]);
        t
    }

    #[test]
    fn csv_holds_the_csv_columns_only() {
        assert_eq!(table().csv(), "width,median_ms\n100,0.727\n1600,143.000\n");
    }

    #[test]
    fn text_aligns_numbers_right_and_words_left() {
        let mut t = table();
        t.notes.push("a note".into());
        assert_eq!(
            t.text(),
            "\nsizes:\n     w   rate  median ms\n   100  13.76      0.727\n  1600    1.5    143.000\na note\n"
        );
        let mut words = Table::new("words", vec![Column::new("feature", "feature"), Column::shown("cost")]);
        words.row(vec!["glass (the lens)".into(), "2.6%".into()]);
        words.row(vec!["shadows".into(), "-0.3%".into()]);
        assert_eq!(
            words.text(),
            "\nwords:\n  feature            cost\n  glass (the lens)   2.6%\n  shadows           -0.3%\n"
        );
    }
}
