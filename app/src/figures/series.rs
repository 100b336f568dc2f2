//! The time series of one study case, read back from a point's `ideal.csv` and `clearance.csv`
//! (so finished points reused from an earlier run plot exactly like fresh ones).

use clearance_joint::error::{Error, Result};
use clearance_joint::scene::{HingeSpec, Scene};
use clearance_joint::table::Table;
use std::path::Path;

mod tables;

/// Angle and rate of one body in both twins.
#[derive(Clone, Debug, Default)]
pub struct BodySeries {
    /// Body name.
    pub name: String,
    /// Angle, clearance twin, deg.
    pub angle_deg: Vec<f64>,
    /// Rate, clearance twin, deg/s.
    pub rate_deg_s: Vec<f64>,
    /// Angle, ideal twin, deg.
    pub angle_ideal_deg: Vec<f64>,
    /// Rate, ideal twin, deg/s.
    pub rate_ideal_deg_s: Vec<f64>,
}

/// Everything the figures of one case need.
#[derive(Clone, Debug, Default)]
pub struct CaseSeries {
    /// Legend label, e.g. `c = 0.10 mm`.
    pub label: String,
    /// Name of the hinge shown (a study's, or the first hinge with clearance).
    pub hinge: String,
    /// Its radial clearance, mm.
    pub clearance_mm: f64,
    /// Row times, s.
    pub t_s: Vec<f64>,
    /// Movable bodies, the hinge's journal body first (the paper's panel, then satellite).
    pub bodies: Vec<BodySeries>,
    /// Joint force magnitude, clearance twin, N.
    pub force_n: Vec<f64>,
    /// Joint force magnitude, ideal twin, N.
    pub force_ideal_n: Vec<f64>,
    /// Journal-centre eccentricity along u, mm.
    pub ecc_u_mm: Vec<f64>,
    /// Journal-centre eccentricity along v, mm.
    pub ecc_v_mm: Vec<f64>,
    /// 1 in contact, 0 in free flight.
    pub contact: Vec<f64>,
    /// Each contact's largest force, clearance twin, from every step of the run, not the rows:
    /// `(time s, force N)` in time order ([`Impact::peak_t_s`]). The force plot passes through
    /// them ([`force_with_peaks`](Self::force_with_peaks)), so it never shows less than the
    /// run's peak. Empty when unknown (a point saved without its `peak_t_s` column).
    ///
    /// [`Impact::peak_t_s`]: clearance_joint::rapier::observers::metrics::Impact::peak_t_s
    pub peaks: Vec<(f64, f64)>,
}

impl CaseSeries {
    /// The clearance twin's force against time, the rows with each contact's peak
    /// ([`peaks`](Self::peaks)) merged in time order.
    pub fn force_with_peaks(&self) -> (Vec<f64>, Vec<f64>) {
        merge_points(&self.t_s, &self.force_n, &self.peaks)
    }

    /// The case with `peaks` set from a contact list ([`Impact::peak_t_s`],
    /// [`Impact::peak_force_n`]).
    ///
    /// [`Impact::peak_t_s`]: clearance_joint::rapier::observers::metrics::Impact::peak_t_s
    /// [`Impact::peak_force_n`]: clearance_joint::rapier::observers::metrics::Impact::peak_force_n
    pub fn with_contacts(
        mut self,
        contacts: &[clearance_joint::rapier::observers::metrics::Impact],
    ) -> Self {
        self.peaks = peaks_of(contacts);
        self
    }

    /// Reads a point folder's `ideal.csv` and `clearance.csv` (the first clearance hinge).
    pub fn load(label: impl Into<String>, scene: &Scene, dir: &Path) -> Result<CaseSeries> {
        let ideal = read_csv(&dir.join("ideal.csv"))?;
        let clear = read_csv(&dir.join("clearance.csv"))?;
        Self::from_tables(label, scene, &ideal, &clear)
    }

    /// Reads a point folder's `ideal.csv` and `clearance.csv` for the clearance hinge `hinge`.
    pub fn load_hinge(
        label: impl Into<String>,
        scene: &Scene,
        hinge: &str,
        dir: &Path,
    ) -> Result<CaseSeries> {
        let ideal = read_csv(&dir.join("ideal.csv"))?;
        let clear = read_csv(&dir.join("clearance.csv"))?;
        Self::from_hinge_tables(label, scene, hinge, &ideal, &clear)
    }
}

/// A study case's series read back in one pass over its point's CSV files, holding a bounded
/// amount of it whatever the run's length: what the figures draw of it (see [`CaseSeries::stream`]).
#[derive(Clone, Debug, Default)]
pub struct StreamedCase {
    /// The series, reduced.
    pub series: CaseSeries,
    /// Every contact onset of the full series (see [`crate::study::metrics::onset_times`]), s.
    pub onsets_s: Vec<f64>,
    /// Rows read per twin.
    pub rows: usize,
}

/// Time bins of [`CaseSeries::stream`] over the run: a few per pixel column of a figure.
pub const STREAM_BINS: usize = 2048;

impl CaseSeries {
    /// Reads a point folder's `ideal.csv` and `clearance.csv` row by row (never the whole files)
    /// for the clearance hinge `hinge`, keeping of the time series, in each of [`STREAM_BINS`]
    /// equal bins over `[0, run.end_s]`, the rows holding any column's minimum or maximum (so the
    /// figures' envelopes and every peak survive), the first and the last row; and of the
    /// journal path (`ecc_u_mm`, `ecc_v_mm`, which then need not align with `t_s`) the points
    /// farther than `c / 800` from the last kept one (under a quarter pixel of the trajectory
    /// figure). Contact onsets are counted on every row. Memory: at most a few rows per bin per
    /// column, and the kept path.
    pub fn stream(
        label: impl Into<String>,
        scene: &Scene,
        hinge: &str,
        dir: &Path,
    ) -> Result<StreamedCase> {
        let spec = clearance_hinge(scene, hinge)?;
        let c = spec.clearance.as_ref().map_or(0.0, |c| c.clearance_mm);
        let mut ideal = CsvRows::open(&dir.join("ideal.csv"))?;
        let mut clear = CsvRows::open(&dir.join("clearance.csv"))?;
        let mut order: Vec<&clearance_joint::scene::BodySpec> =
            scene.bodies.iter().filter(|b| !b.fixed).collect();
        order.sort_by_key(|b| b.name != spec.journal);
        let h = |s: &str| format!("{}_{s}", spec.name);
        // Columns kept, in CaseSeries order: t, per body 4, force, force ideal, contact.
        let mut picks: Vec<(bool, usize)> = vec![(false, clear.index("t_s")?)];
        for b in &order {
            let c = |s: &str| format!("{}_{s}", b.name);
            picks.push((false, clear.index(&c("angle_deg"))?));
            picks.push((false, clear.index(&c("rate_deg_s"))?));
            picks.push((true, ideal.index(&c("angle_deg"))?));
            picks.push((true, ideal.index(&c("rate_deg_s"))?));
        }
        picks.push((false, clear.index(&h("force_n"))?));
        picks.push((true, ideal.index(&h("force_n"))?));
        picks.push((false, clear.index(&h("contact"))?));
        let (iu, iv) = (clear.index(&h("ecc_u_mm"))?, clear.index(&h("ecc_v_mm"))?);
        let contact_col = picks.len() - 1;
        let end = scene.run.end_s;
        let mut bins = BinExtremes::new(picks.len());
        let mut path: Vec<(f64, f64)> = Vec::new();
        let min_step = if c > 0.0 { c / 800.0 } else { 0.0 };
        let mut onsets = Vec::new();
        let mut in_contact = false;
        let (mut ri, mut rc) = (Vec::new(), Vec::new());
        let mut row = vec![0.0; picks.len()];
        let mut rows = 0usize;
        let mut last_uv = None;
        loop {
            let (a, b) = (ideal.next_into(&mut ri)?, clear.next_into(&mut rc)?);
            if a != b {
                return Err(Error::Parse {
                    what: dir.display().to_string(),
                    reason: "ideal.csv and clearance.csv have different numbers of rows".into(),
                });
            }
            if !a {
                break;
            }
            for (slot, &(from_ideal, k)) in row.iter_mut().zip(&picks) {
                *slot = if from_ideal { ri[k] } else { rc[k] };
            }
            let t = row[0];
            let now = row[contact_col] > 0.5;
            if now && !in_contact {
                onsets.push(t);
            }
            in_contact = now;
            let bin = if end > 0.0 {
                ((t / end * STREAM_BINS as f64).max(0.0) as usize).min(STREAM_BINS - 1)
            } else {
                0
            };
            bins.push(bin, rows, &row);
            let p = (rc[iu], rc[iv]);
            match path.last() {
                Some(&(u, v)) if (p.0 - u).hypot(p.1 - v) < min_step => last_uv = Some(p),
                _ => {
                    path.push(p);
                    last_uv = None;
                }
            }
            rows += 1;
        }
        path.extend(last_uv);
        let kept = bins.finish();
        let column = |k: usize| kept.iter().map(|r| r[k]).collect::<Vec<f64>>();
        let bodies = order
            .iter()
            .enumerate()
            .map(|(i, b)| BodySeries {
                name: b.name.clone(),
                angle_deg: column(1 + 4 * i),
                rate_deg_s: column(2 + 4 * i),
                angle_ideal_deg: column(3 + 4 * i),
                rate_ideal_deg_s: column(4 + 4 * i),
            })
            .collect();
        let n = picks.len();
        let (ecc_u_mm, ecc_v_mm) = path.into_iter().unzip();
        Ok(StreamedCase {
            series: CaseSeries {
                label: label.into(),
                hinge: spec.name.clone(),
                clearance_mm: c,
                t_s: column(0),
                bodies,
                force_n: column(n - 3),
                force_ideal_n: column(n - 2),
                ecc_u_mm,
                ecc_v_mm,
                contact: column(n - 1),
                peaks: read_peaks(&dir.join(format!("clearance_{}_impacts.csv", spec.name)))?,
            },
            onsets_s: onsets,
            rows,
        })
    }
}

/// Each contact's peak `(peak_t_s, peak_force_n)` of a contact list, in time order: the points
/// a force plot of thinned rows must pass through.
pub fn peaks_of(
    contacts: &[clearance_joint::rapier::observers::metrics::Impact],
) -> Vec<(f64, f64)> {
    contacts
        .iter()
        .map(|i| (i.peak_t_s, i.peak_force_n))
        .collect()
}

/// `(t, v)` with `points` (`(t, v)` pairs in time order) merged in time order: the series a
/// plot draws so that it passes through values the rows skipped.
pub fn merge_points(t: &[f64], v: &[f64], points: &[(f64, f64)]) -> (Vec<f64>, Vec<f64>) {
    let n = t.len().min(v.len());
    let (mut mt, mut mv) = (
        Vec::with_capacity(n + points.len()),
        Vec::with_capacity(n + points.len()),
    );
    let mut p = points.iter().peekable();
    for i in 0..n {
        while let Some(&&(pt, pv)) = p.peek().filter(|q| q.0 < t[i]) {
            mt.push(pt);
            mv.push(pv);
            p.next();
        }
        mt.push(t[i]);
        mv.push(v[i]);
    }
    for &(pt, pv) in p {
        mt.push(pt);
        mv.push(pv);
    }
    (mt, mv)
}

/// Each contact's peak `(peak_t_s, peak_force_n)` from a contact list written by the run
/// (`<twin>_<hinge>_impacts.csv`), read row by row; empty when the file or its `peak_t_s`
/// column is absent (a point saved without that column draws its rows alone).
fn read_peaks(path: &Path) -> Result<Vec<(f64, f64)>> {
    if !path.is_file() {
        return Ok(Vec::new());
    }
    let mut rows = CsvRows::open(path)?;
    let (Ok(t), Ok(f)) = (rows.index("peak_t_s"), rows.index("peak_force_n")) else {
        return Ok(Vec::new());
    };
    let mut peaks = Vec::new();
    let mut row = Vec::new();
    while rows.next_into(&mut row)? {
        peaks.push((row[t], row[f]));
    }
    Ok(peaks)
}

/// Per time bin, the rows holding each column's minimum and maximum (plus the first and the
/// last row of all), kept in row order.
struct BinExtremes {
    columns: usize,
    bin: Option<usize>,
    /// Candidate rows of the current bin: (row number, values).
    rows: Vec<(usize, Vec<f64>)>,
    lo: Vec<usize>,
    hi: Vec<usize>,
    out: Vec<Vec<f64>>,
    last: Option<(usize, Vec<f64>)>,
    last_out: Option<usize>,
}

impl BinExtremes {
    fn new(columns: usize) -> Self {
        BinExtremes {
            columns,
            bin: None,
            rows: Vec::new(),
            lo: vec![0; columns],
            hi: vec![0; columns],
            out: Vec::new(),
            last: None,
            last_out: None,
        }
    }

    fn push(&mut self, bin: usize, index: usize, row: &[f64]) {
        if self.bin != Some(bin) {
            self.flush();
            self.bin = Some(bin);
            self.rows.push((index, row.to_vec()));
            self.lo.fill(0);
            self.hi.fill(0);
        } else {
            let at = self.rows.len();
            let mut wins = false;
            for (k, &x) in row.iter().enumerate() {
                if x < self.rows[self.lo[k]].1[k] {
                    self.lo[k] = at;
                    wins = true;
                }
                if x > self.rows[self.hi[k]].1[k] {
                    self.hi[k] = at;
                    wins = true;
                }
            }
            if wins {
                self.rows.push((index, row.to_vec()));
                if self.rows.len() > 4 * self.columns + 8 {
                    self.compact();
                }
            }
        }
        if index == 0 {
            self.out.push(row.to_vec());
            self.last_out = Some(0);
        }
        match &mut self.last {
            Some((i, r)) => {
                *i = index;
                r.copy_from_slice(row);
            }
            None => self.last = Some((index, row.to_vec())),
        }
    }

    /// Keeps only the candidate rows that hold an extreme.
    fn compact(&mut self) {
        let mut keep: Vec<usize> = self.lo.iter().chain(&self.hi).copied().collect();
        keep.sort_unstable();
        keep.dedup();
        let remap = |old: usize| keep.binary_search(&old).unwrap_or(0);
        for k in 0..self.columns {
            self.lo[k] = remap(self.lo[k]);
            self.hi[k] = remap(self.hi[k]);
        }
        let rows = std::mem::take(&mut self.rows);
        self.rows = rows
            .into_iter()
            .enumerate()
            .filter(|(i, _)| keep.binary_search(i).is_ok())
            .map(|(_, r)| r)
            .collect();
    }

    fn flush(&mut self) {
        if self.bin.is_none() {
            return;
        }
        let mut keep: Vec<usize> = self.lo.iter().chain(&self.hi).copied().collect();
        keep.sort_unstable();
        keep.dedup();
        let rows = std::mem::take(&mut self.rows);
        for (i, (index, values)) in rows.into_iter().enumerate() {
            if keep.binary_search(&i).is_ok() && self.last_out.is_none_or(|l| index > l) {
                self.out.push(values);
                self.last_out = Some(index);
            }
        }
    }

    fn finish(mut self) -> Vec<Vec<f64>> {
        self.flush();
        if let Some((index, values)) = self.last.take()
            && self.last_out.is_none_or(|l| index > l)
        {
            self.out.push(values);
        }
        self.out
    }
}

/// A numeric CSV written by [`Table::to_csv`], read one row at a time.
struct CsvRows {
    path: std::path::PathBuf,
    columns: Vec<String>,
    lines: std::io::Lines<std::io::BufReader<std::fs::File>>,
    line: usize,
}

impl CsvRows {
    fn open(path: &Path) -> Result<CsvRows> {
        use std::io::BufRead;
        let file = std::fs::File::open(path).map_err(|source| Error::Io {
            action: "cannot read",
            path: path.to_path_buf(),
            source,
        })?;
        let mut lines = std::io::BufReader::new(file).lines();
        let header = lines
            .next()
            .transpose()
            .map_err(|source| Error::Io {
                action: "cannot read",
                path: path.to_path_buf(),
                source,
            })?
            .ok_or_else(|| Error::Parse {
                what: path.display().to_string(),
                reason: "empty file".into(),
            })?;
        Ok(CsvRows {
            path: path.to_path_buf(),
            columns: header.split(',').map(str::to_string).collect(),
            lines,
            line: 1,
        })
    }

    fn index(&self, name: &str) -> Result<usize> {
        self.columns.iter().position(|c| c == name).ok_or_else(|| {
            Error::invalid(
                format!("output table {}", self.path.display()),
                format!("has no column `{name}`"),
            )
        })
    }

    /// Reads the next row into `row`; false at the end.
    fn next_into(&mut self, row: &mut Vec<f64>) -> Result<bool> {
        loop {
            let Some(line) = self.lines.next() else {
                return Ok(false);
            };
            self.line += 1;
            let line = line.map_err(|source| Error::Io {
                action: "cannot read",
                path: self.path.clone(),
                source,
            })?;
            if line.is_empty() {
                continue;
            }
            row.clear();
            for cell in line.split(',') {
                row.push(cell.parse().map_err(|e| Error::Parse {
                    what: self.path.display().to_string(),
                    reason: format!("line {}: `{cell}`: {e}", self.line),
                })?);
            }
            if row.len() != self.columns.len() {
                return Err(Error::Parse {
                    what: self.path.display().to_string(),
                    reason: format!(
                        "line {} has {} cells, the header {}",
                        self.line,
                        row.len(),
                        self.columns.len()
                    ),
                });
            }
            return Ok(true);
        }
    }
}

/// Reads a numeric CSV written by [`Table::to_csv`] (header line, then numbers).
pub fn read_csv(path: &Path) -> Result<Table> {
    let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
        action: "cannot read",
        path: path.to_path_buf(),
        source,
    })?;
    let mut lines = text.lines();
    let columns: Vec<String> = lines
        .next()
        .ok_or_else(|| Error::Parse {
            what: path.display().to_string(),
            reason: "empty file".into(),
        })?
        .split(',')
        .map(str::to_string)
        .collect();
    let mut table = Table::new(columns);
    let n = table.columns.len();
    for (i, line) in lines.enumerate() {
        if line.is_empty() {
            continue;
        }
        let before = table.values.len();
        for cell in line.split(',') {
            let v: f64 = cell.parse().map_err(|e| Error::Parse {
                what: path.display().to_string(),
                reason: format!("line {}: `{cell}`: {e}", i + 2),
            })?;
            table.values.push(v);
        }
        if table.values.len() - before != n {
            return Err(Error::Parse {
                what: path.display().to_string(),
                reason: format!(
                    "line {} has {} cells, the header {n}",
                    i + 2,
                    table.values.len() - before
                ),
            });
        }
    }
    Ok(table)
}

/// `scene`'s hinge named `hinge`, which must have a clearance (the figures plot its journal).
fn clearance_hinge<'a>(scene: &'a Scene, hinge: &str) -> Result<&'a HingeSpec> {
    scene
        .hinges
        .iter()
        .find(|h| h.name == hinge && h.clearance.is_some())
        .ok_or_else(|| {
            Error::invalid(
                format!("hinges[{hinge}]"),
                "is not a hinge with clearance: nothing to plot",
            )
        })
}
