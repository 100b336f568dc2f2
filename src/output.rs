//! Result files written whole or not at all: to a temporary name in the same folder, then renamed.

use crate::error::{Error, Result};
use std::io::Write;
use std::path::Path;

/// Writes `bytes` to `path` atomically (temporary file + rename), creating the folder.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    write_all_atomic(&[(path, bytes)])
}

/// Writes several files as a set: every file goes to a temporary name in its folder first, and
/// only when all are written are they renamed into place. A failure before the renames leaves
/// the previous files untouched and no temporary behind.
pub fn write_all_atomic(files: &[(&Path, &[u8])]) -> Result<()> {
    let io = |action, path: &Path, source| Error::Io {
        action,
        path: path.to_path_buf(),
        source,
    };
    let temp = |path: &Path| {
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        path.with_file_name(format!(".{name}.tmp-{}", std::process::id()))
    };
    let mut staged = Vec::with_capacity(files.len());
    for (path, bytes) in files {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|e| io("cannot create the folder of", path, e))?;
        }
        let tmp = temp(path);
        let written = (|| {
            let mut f = std::fs::File::create(&tmp)?;
            f.write_all(bytes)?;
            f.sync_all()
        })();
        staged.push(tmp);
        if let Err(e) = written {
            for t in &staged {
                let _ = std::fs::remove_file(t);
            }
            return Err(io("cannot write", path, e));
        }
    }
    for ((path, _), tmp) in files.iter().zip(&staged) {
        if let Err(e) = std::fs::rename(tmp, path) {
            for t in &staged {
                let _ = std::fs::remove_file(t);
            }
            return Err(io("cannot write", path, e));
        }
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
