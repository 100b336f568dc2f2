//! A table of numbers with named columns, written as CSV: the one form of every time series,
//! impact list and metrics table the crate produces.

use crate::error::{Error, Result};
use std::io::Write;
use std::path::PathBuf;

/// A table of `f64` columns rendered as CSV with the shortest round-trip representation
/// (bit-identical text for bit-identical numbers).
#[derive(Clone, Debug, Default)]
pub struct Table {
    /// Column names.
    pub columns: Vec<String>,
    /// Row-major values, `columns.len()` per row.
    pub values: Vec<f64>,
}

impl Table {
    /// An empty table with these columns.
    pub fn new(columns: Vec<String>) -> Self {
        Table {
            columns,
            values: Vec::new(),
        }
    }

    /// Number of rows.
    pub fn rows(&self) -> usize {
        if self.columns.is_empty() {
            0
        } else {
            self.values.len() / self.columns.len()
        }
    }

    /// Row `i`.
    pub fn row(&self, i: usize) -> &[f64] {
        let n = self.columns.len();
        &self.values[i * n..(i + 1) * n]
    }

    /// Index of the column called `name`.
    pub fn column_index(&self, name: &str) -> Option<usize> {
        self.columns.iter().position(|c| c == name)
    }

    /// All values of column `name`.
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let j = self.column_index(name)?;
        Some((0..self.rows()).map(|i| self.row(i)[j]).collect())
    }

    /// CSV text; fails on a non-finite value, naming its row and column.
    pub fn to_csv(&self) -> Result<String> {
        let mut out = Vec::with_capacity(self.values.len() * 12 + 256);
        self.write_csv(&mut out)?;
        String::from_utf8(out).map_err(|e| Error::invalid("table", e.to_string()))
    }

    /// Streams the CSV text into `w` (no copy of the table is held); fails on a non-finite
    /// value, naming its row and column.
    pub fn write_csv(&self, w: &mut dyn Write) -> Result<()> {
        let io = |e| Error::Io {
            action: "cannot write CSV",
            path: PathBuf::new(),
            source: e,
        };
        writeln!(w, "{}", self.columns.join(",")).map_err(io)?;
        let mut line = String::with_capacity(32 * self.columns.len() + 1);
        for i in 0..self.rows() {
            line.clear();
            for (j, v) in self.row(i).iter().enumerate() {
                if !v.is_finite() {
                    return Err(Error::diverged(
                        self.row(i)[0],
                        crate::error::Divergence::NonFinite {
                            name: self.columns[j].clone(),
                            place: format!("in output row {i}"),
                            value: Some(*v),
                        },
                    ));
                }
                if j > 0 {
                    line.push(',');
                }
                use std::fmt::Write as _;
                let _ = write!(line, "{v}");
            }
            line.push('\n');
            w.write_all(line.as_bytes()).map_err(io)?;
        }
        Ok(())
    }
}
