//! The time series of one study case, read back from a point's `ideal.csv` and `clearance.csv`
//! (so finished points reused from an earlier run plot exactly like fresh ones).

use clearance_joint::error::{Error, Result};
use clearance_joint::scene::Scene;
use clearance_joint::table::Table;
use std::path::Path;

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
}

impl CaseSeries {
    /// Extracts the series of `scene`'s first clearance hinge from the two twins' tables.
    pub fn from_tables(
        label: impl Into<String>,
        scene: &Scene,
        ideal: &Table,
        clear: &Table,
    ) -> Result<CaseSeries> {
        let hinge = scene
            .hinges
            .iter()
            .find(|h| h.clearance.is_some())
            .ok_or_else(|| Error::invalid("hinges", "no hinge has a clearance: nothing to plot"))?;
        Self::from_hinge_tables(label, scene, &hinge.name, ideal, clear)
    }

    /// Extracts the series of `scene`'s clearance hinge `hinge` from the two twins' tables.
    pub fn from_hinge_tables(
        label: impl Into<String>,
        scene: &Scene,
        hinge: &str,
        ideal: &Table,
        clear: &Table,
    ) -> Result<CaseSeries> {
        let hinge = scene
            .hinges
            .iter()
            .find(|h| h.name == hinge && h.clearance.is_some())
            .ok_or_else(|| {
                Error::invalid(
                    format!("hinges[{hinge}]"),
                    "is not a hinge with clearance: nothing to plot",
                )
            })?;
        let col = |t: &Table, name: &str| {
            t.column(name)
                .ok_or_else(|| Error::invalid("output table", format!("has no column `{name}`")))
        };
        let h = |s: &str| format!("{}_{s}", hinge.name);
        let mut order: Vec<&clearance_joint::scene::BodySpec> =
            scene.bodies.iter().filter(|b| !b.fixed).collect();
        order.sort_by_key(|b| b.name != hinge.journal);
        let bodies = order
            .into_iter()
            .map(|b| {
                let c = |s: &str| format!("{}_{s}", b.name);
                Ok(BodySeries {
                    name: b.name.clone(),
                    angle_deg: col(clear, &c("angle_deg"))?,
                    rate_deg_s: col(clear, &c("rate_deg_s"))?,
                    angle_ideal_deg: col(ideal, &c("angle_deg"))?,
                    rate_ideal_deg_s: col(ideal, &c("rate_deg_s"))?,
                })
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(CaseSeries {
            label: label.into(),
            hinge: hinge.name.clone(),
            clearance_mm: hinge.clearance.as_ref().map_or(0.0, |c| c.clearance_mm),
            t_s: col(clear, "t_s")?,
            bodies,
            force_n: col(clear, &h("force_n"))?,
            force_ideal_n: col(ideal, &h("force_n"))?,
            ecc_u_mm: col(clear, &h("ecc_u_mm"))?,
            ecc_v_mm: col(clear, &h("ecc_v_mm"))?,
            contact: col(clear, &h("contact"))?,
        })
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
