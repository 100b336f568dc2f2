//! The metrics table of a sweep: its rows and failures, its CSV and JSON, and merging shards.

use super::*;

/// A point that failed, with the reason.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Failure {
    /// The grid point.
    pub point: Point,
    /// The error message.
    pub error: String,
}

/// One row of the metrics table: a finished point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TableRow {
    /// The grid point.
    pub point: Point,
    /// Its folder, relative to the sweep folder (`points/<dir>`).
    pub dir: String,
    /// Its metrics.
    pub metrics: RunMetrics,
}

impl TableRow {
    pub(super) fn of(manifest: &Manifest, dir: &Path, out: &Path) -> TableRow {
        TableRow {
            point: manifest.point.clone(),
            dir: dir
                .strip_prefix(out)
                .unwrap_or(dir)
                .to_string_lossy()
                .replace('\\', "/"),
            metrics: manifest.metrics.clone(),
        }
    }
}

/// The per-run metrics of a sweep (or of one shard of it).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MetricsTable {
    /// The sweep.
    pub sweep: SweepInfo,
    /// The shard this table covers (`None`: the whole grid or a merge).
    pub shard: Option<Shard>,
    /// Finished points, in grid order.
    pub rows: Vec<TableRow>,
    /// Points that failed.
    pub failures: Vec<Failure>,
    /// Indices of grid points with neither a row nor a failure (after a merge of incomplete shards).
    #[serde(default)]
    pub missing: Vec<usize>,
}

impl MetricsTable {
    /// File stem of this table: `metrics` or `metrics.shard-K-of-N`.
    pub fn stem(&self) -> String {
        match self.shard {
            Some(s) => format!("metrics.shard-{}-of-{}", s.index(), s.count()),
            None => "metrics".into(),
        }
    }

    /// CSV text: `index, dir`, one column per axis (its value as written), then the metrics
    /// columns of [`RunMetrics::columns`]; an optional metric without value is an empty cell.
    pub fn to_csv(&self) -> Result<String> {
        let mut header: Vec<String> = vec!["index".into(), "dir".into()];
        header.extend(self.sweep.axes.iter().map(|a| csv_cell(&a.path)));
        let metric_names: Vec<String> = self
            .rows
            .first()
            .map(|r| r.metrics.columns().into_iter().map(|c| c.0).collect())
            .unwrap_or_default();
        header.extend(metric_names.iter().cloned());
        let mut s = header.join(",");
        s.push('\n');
        for r in &self.rows {
            let cols = r.metrics.columns();
            if cols.len() != metric_names.len()
                || cols.iter().zip(&metric_names).any(|(c, n)| &c.0 != n)
            {
                return Err(Error::invalid(
                    "metrics table",
                    format!(
                        "point `{}` has other metric columns than the first point (different bodies or hinges)",
                        r.point.dir
                    ),
                ));
            }
            let mut cells = vec![r.point.index.to_string(), csv_cell(&r.dir)];
            cells.extend(r.point.assignments.iter().map(|(_, v)| csv_cell(v)));
            for (name, v) in cols {
                cells.push(match v {
                    Some(x) if x.is_finite() => format!("{x}"),
                    Some(x) => {
                        return Err(Error::Diverged {
                            t: r.metrics.end_s,
                            what: Box::new(Divergence::NonFinite {
                                name: name.clone(),
                                place: format!("among the metrics of point `{}`", r.point.dir),
                                value: Some(x),
                            }),
                        });
                    }
                    None => String::new(),
                });
            }
            s.push_str(&cells.join(","));
            s.push('\n');
        }
        Ok(s)
    }

    /// Writes `<stem>.csv` and `<stem>.json` into `out` as one set (see [`MetricsTable::stem`]).
    pub fn write(&self, out: &Path) -> Result<()> {
        self.write_named(out, &self.stem())
    }

    /// Writes `<stem>.csv` and `<stem>.json` into `out` as one set, the JSON last.
    pub fn write_named(&self, out: &Path, stem: &str) -> Result<()> {
        for r in &self.rows {
            r.metrics.check_finite()?;
        }
        let csv = self.to_csv()?;
        let json = json_bytes(self, "metrics table")?;
        // One set, the JSON (which `merge` reads) last.
        write_all_atomic(&[
            (&out.join(format!("{stem}.csv")), csv.as_bytes()),
            (&out.join(format!("{stem}.json")), &json),
        ])
    }

    /// Reads a table written by [`MetricsTable::write`] (its JSON file).
    pub fn load(path: &Path) -> Result<MetricsTable> {
        let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
            action: "cannot read metrics table",
            path: path.to_path_buf(),
            source,
        })?;
        serde_json::from_str(&text).map_err(|e| Error::Parse {
            what: path.display().to_string(),
            reason: e.to_string(),
        })
    }
}

/// A CSV cell: quoted when it holds a comma, quote or newline.
pub(super) fn csv_cell(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// The shard tables (`metrics.shard-*.json`) in `dir`, sorted by name.
pub fn shard_tables_in(dir: &Path) -> Result<Vec<PathBuf>> {
    let entries = std::fs::read_dir(dir).map_err(|source| Error::Io {
        action: "cannot list",
        path: dir.to_path_buf(),
        source,
    })?;
    let mut found: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("metrics.shard-") && n.ends_with(".json"))
        })
        .collect();
    found.sort();
    Ok(found)
}

/// Gathers shard tables of one sweep into one table for the whole grid. Every table must
/// describe the same sweep; a point in two tables must have identical metrics. A point failed
/// in one shard but finished in another counts as finished. Grid points in no table are listed
/// in `missing` (the caller decides whether that is an error).
pub fn merge(tables: &[MetricsTable]) -> Result<MetricsTable> {
    let first = tables
        .first()
        .ok_or_else(|| Error::invalid("merge", "no shard table given"))?;
    let info = first.sweep.clone();
    let mut rows: std::collections::BTreeMap<usize, TableRow> = Default::default();
    let mut failures: std::collections::BTreeMap<usize, Failure> = Default::default();
    for (i, t) in tables.iter().enumerate() {
        if t.sweep != info {
            return Err(Error::invalid(
                format!("merge: table {}", i + 1),
                format!(
                    "belongs to another sweep than table 1: {}",
                    info.differences(&t.sweep).join("; ")
                ),
            ));
        }
        for r in &t.rows {
            if r.point.index >= info.points {
                return Err(Error::invalid(
                    format!("merge: table {}", i + 1),
                    format!(
                        "has point {} outside the grid of {}",
                        r.point.index, info.points
                    ),
                ));
            }
            match rows.get(&r.point.index) {
                // Wall time is a measurement of the machine, not of the physics: a point
                // recomputed in two shards agrees in everything else.
                Some(old) if !same_physics(&old.metrics, &r.metrics) => {
                    return Err(Error::invalid(
                        format!("merge: point `{}`", r.point.dir),
                        "appears in two tables with different metrics",
                    ));
                }
                Some(_) => {}
                None => {
                    rows.insert(r.point.index, r.clone());
                }
            }
        }
        for f in &t.failures {
            failures.entry(f.point.index).or_insert_with(|| f.clone());
        }
    }
    failures.retain(|k, _| !rows.contains_key(k));
    let missing = (0..info.points)
        .filter(|i| !rows.contains_key(i) && !failures.contains_key(i))
        .collect();
    Ok(MetricsTable {
        sweep: info,
        shard: None,
        rows: rows.into_values().collect(),
        failures: failures.into_values().collect(),
        missing,
    })
}

/// The refusal of two nested axes: `inner` (writing `inner_field`) sets a field inside the value
/// of `outer` (writing `outer_field`), so whichever applies later overwrites the other at every
/// point.
pub(super) fn nested_axes(
    outer: &Axis,
    outer_field: &str,
    inner: &Axis,
    inner_field: &str,
) -> Error {
    Error::invalid(
        "sweep",
        format!(
            "axes `{op}` and `{ip}` are nested: `{ip}` sets `{inner_field}`, a field inside `{op}`'s value \
             (`{outer_field}`), so one would overwrite the other at every point. Sweep one of \
             them, or give the field inside each value of `{op}`",
            ip = inner.path,
            op = outer.path,
        ),
    )
}
