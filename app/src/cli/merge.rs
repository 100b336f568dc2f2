//! The `merge` command: the metrics tables of a sharded sweep gathered into one, refused
//! while points are missing unless an incomplete table is asked for.

use crate::study::sweep::{self, MetricsTable};
use clearance_joint::error::{Error, Result};
use std::path::{Path, PathBuf};

/// A merged table, written.
#[derive(Clone, Debug)]
pub struct Merged {
    /// The merged table.
    pub table: MetricsTable,
    /// Shard tables read.
    pub inputs: usize,
    /// Folder written to.
    pub out: PathBuf,
    /// File stem written: `metrics`, or `metrics.incomplete` with points missing.
    pub stem: &'static str,
}

/// Reads the shard tables of `inputs` (sweep folders, whose `metrics.shard-*.json` are read, or
/// table files), merges them and writes `metrics.{csv,json}` into `out` (default: the first
/// input folder). With points missing nothing is written unless `incomplete`, which writes
/// `metrics.incomplete.{csv,json}` listing them.
pub fn merge(inputs: &[PathBuf], out: Option<&Path>, incomplete: bool) -> Result<Merged> {
    let mut files = Vec::new();
    for input in inputs {
        files.extend(tables_of(input)?);
    }
    let tables = files
        .iter()
        .map(|f| MetricsTable::load(f).map_err(not_a_table))
        .collect::<Result<Vec<_>>>()?;
    let merged = sweep::merge(&tables)?;
    if !merged.missing.is_empty() && !incomplete {
        return Err(Error::invalid(
            "merge",
            format!(
                "points {:?} are in no table, so nothing was written: run their shards (point i belongs to \
                 shard i % N), or pass --incomplete to write metrics.incomplete.{{csv,json}} listing them",
                merged.missing
            ),
        ));
    }
    let out = match out {
        Some(o) => o.to_path_buf(),
        None => {
            let first = &inputs[0];
            if first.is_dir() {
                first.clone()
            } else {
                folder_of(first).to_path_buf()
            }
        }
    };
    let stem = if merged.missing.is_empty() {
        "metrics"
    } else {
        "metrics.incomplete"
    };
    merged.write_named(&out, stem)?;
    Ok(Merged {
        table: merged,
        inputs: tables.len(),
        out,
        stem,
    })
}

/// The table files an input names: a sweep folder's shard tables (`metrics.shard-*.json`), or
/// the file itself. A CSV table is refused naming the JSON to pass instead: only the JSON
/// describes the sweep (its axes and fixed settings), which merging checks.
fn tables_of(input: &Path) -> Result<Vec<PathBuf>> {
    let what = || format!("merge input `{}`", input.display());
    if input.is_dir() {
        let found = sweep::shard_tables_in(input)?;
        if found.is_empty() {
            return Err(Error::invalid(
                what(),
                "holds no shard table (metrics.shard-K-of-N.json)",
            ));
        }
        return Ok(found);
    }
    let is_csv = input
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("csv"));
    if is_csv {
        return Err(Error::invalid(
            what(),
            format!(
                "is a CSV table, and merge reads the JSON tables (only they describe the sweep, \
                 which merging checks): pass `{}` instead, or the sweep folder `{}` to merge \
                 all its metrics.shard-K-of-N.json",
                input.with_extension("json").display(),
                folder_of(input).display()
            ),
        ));
    }
    Ok(vec![input.to_path_buf()])
}

/// The folder holding `file` (`.` for a bare file name).
fn folder_of(file: &Path) -> &Path {
    file.parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

/// A file that does not read as a metrics table, said so with what merge takes.
fn not_a_table(e: Error) -> Error {
    match e {
        Error::Parse { what, reason } => Error::Parse {
            what,
            reason: format!(
                "{reason}: not a metrics table; merge takes sweep folders or their \
                 metrics.shard-K-of-N.json files"
            ),
        },
        other => other,
    }
}

/// The error of a merged table with points missing (written as incomplete), or `Ok`.
pub fn check_missing(table: &MetricsTable) -> Result<()> {
    if table.missing.is_empty() {
        return Ok(());
    }
    Err(Error::invalid(
        "merge",
        format!(
            "points {:?} are in no table: run their shards (a point i belongs to shard i % N)",
            table.missing
        ),
    ))
}
