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
        if input.is_dir() {
            let found = sweep::shard_tables_in(input)?;
            if found.is_empty() {
                return Err(Error::invalid(
                    format!("merge input `{}`", input.display()),
                    "holds no shard table (metrics.shard-K-of-N.json)",
                ));
            }
            files.extend(found);
        } else {
            files.push(input.clone());
        }
    }
    let tables = files
        .iter()
        .map(|f| MetricsTable::load(f))
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
                first.parent().unwrap_or(Path::new(".")).to_path_buf()
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
