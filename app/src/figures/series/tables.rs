//! A case's series taken from a run's two tables (in memory, or read back from its CSVs).

use super::{BodySeries, CaseSeries, clearance_hinge};
use clearance_joint::error::{Error, Result};
use clearance_joint::scene::Scene;
use clearance_joint::table::Table;

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
        let hinge = clearance_hinge(scene, hinge)?;
        let h = |s: &str| format!("{}_{s}", hinge.name);
        let mut order: Vec<&clearance_joint::scene::BodySpec> =
            scene.bodies.iter().filter(|b| !b.fixed).collect();
        order.sort_by_key(|b| b.name != hinge.journal);
        // Each table's columns in one pass (a table is a run's megabytes of rows): every
        // body's angle and rate, then the hinge's columns.
        let mut names: Vec<String> = order
            .iter()
            .flat_map(|b| {
                [
                    format!("{}_angle_deg", b.name),
                    format!("{}_rate_deg_s", b.name),
                ]
            })
            .collect();
        let ideal_names = [&names[..], &[h("force_n")]].concat();
        names.extend([
            "t_s".into(),
            h("force_n"),
            h("ecc_u_mm"),
            h("ecc_v_mm"),
            h("contact"),
        ]);
        let cols = |t: &Table, names: &[String]| {
            let names: Vec<&str> = names.iter().map(String::as_str).collect();
            t.columns(&names).ok_or_else(|| {
                let missing = names.iter().find(|n| t.column_index(n).is_none());
                let missing = missing.copied().unwrap_or_default();
                Error::invalid("output table", format!("has no column `{missing}`"))
            })
        };
        let (mut c, mut i) = (
            cols(clear, &names)?.into_iter(),
            cols(ideal, &ideal_names)?.into_iter(),
        );
        let bodies = order
            .into_iter()
            .map(|b| BodySeries {
                name: b.name.clone(),
                angle_deg: c.next().unwrap_or_default(),
                rate_deg_s: c.next().unwrap_or_default(),
                angle_ideal_deg: i.next().unwrap_or_default(),
                rate_ideal_deg_s: i.next().unwrap_or_default(),
            })
            .collect();
        let mut c = || c.next().unwrap_or_default();
        let (t_s, force_n, ecc_u_mm, ecc_v_mm, contact) = (c(), c(), c(), c(), c());
        let force_ideal_n = i.next().unwrap_or_default();
        Ok(CaseSeries {
            label: label.into(),
            hinge: hinge.name.clone(),
            clearance_mm: hinge.clearance.as_ref().map_or(0.0, |c| c.clearance_mm),
            t_s,
            bodies,
            force_n,
            force_ideal_n,
            ecc_u_mm,
            ecc_v_mm,
            contact,
            peaks: Vec::new(),
        })
    }
}
