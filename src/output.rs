//! Result files written whole or not at all: to a temporary name in the same folder, then renamed.

use crate::error::{Error, Result};
use std::io::Write;
use std::path::Path;

/// Writes `bytes` to `path` atomically (temporary file + rename), creating the folder.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let io = |action, source| Error::Io {
        action,
        path: path.to_path_buf(),
        source,
    };
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| io("cannot create the folder of", e))?;
    }
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = path.with_file_name(format!(".{name}.tmp-{}", std::process::id()));
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(io("cannot write", e));
    }
    Ok(())
}

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
        let mut s = String::with_capacity(self.values.len() * 12 + 256);
        s.push_str(&self.columns.join(","));
        s.push('\n');
        for i in 0..self.rows() {
            for (j, v) in self.row(i).iter().enumerate() {
                if !v.is_finite() {
                    return Err(Error::Diverged {
                        t: self.row(i)[0],
                        reason: format!("non-finite `{}` in output row {i}", self.columns[j]),
                    });
                }
                if j > 0 {
                    s.push(',');
                }
                use std::fmt::Write as _;
                let _ = write!(s, "{v}");
            }
            s.push('\n');
        }
        Ok(s)
    }
}
