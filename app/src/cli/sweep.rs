//! The `sweep` command: a grid of ideal-vs-clearance runs over a base scene, or one shard of
//! it, into a folder whose table it claims.

use crate::process::lock::DirLock;
use crate::study::grid::{Axis, Grid, Shard};
use crate::study::sweep::{ExecOptions, MetricsTable, Sweep, SweepOutcome};
use clearance_joint::error::{Error, Result};
use clearance_joint::scene::Scene;
use std::path::PathBuf;

/// A sweep ready to run: its grid built and checked, and its table claimed (until dropped).
#[derive(Debug)]
pub struct SweepJob {
    /// The sweep.
    pub sweep: Sweep,
    /// The share of the grid this run covers.
    pub shard: Shard,
    /// The sweep folder.
    pub out: PathBuf,
    _lock: DirLock,
}

impl SweepJob {
    /// Parses the axes (`path=v1,v2,...`) and the shard (`K/N`), then claims this shard's table
    /// in `out` (and checks the folder) before any point runs; the points claim their own
    /// folders, so shards of one sweep can share it. `fixed` overrides hold for every point.
    pub fn prepare(
        base: Scene,
        axes: &[String],
        fixed: Vec<String>,
        shard: Option<&str>,
        out: PathBuf,
    ) -> Result<SweepJob> {
        let axes = axes
            .iter()
            .map(|a| Axis::parse(a))
            .collect::<Result<Vec<_>>>()?;
        let shard = match shard {
            Some(s) => Shard::parse(s)?,
            None => Shard::ALL,
        };
        let sweep = Sweep::new("sweep", base, fixed, Grid::new(axes)?);
        // Bad values and two axes naming one field are refused before the folder is touched.
        sweep.check()?;
        let stem = if shard.is_all() {
            "metrics".to_string()
        } else {
            format!("metrics.shard-{}-of-{}", shard.index(), shard.count())
        };
        let lock = DirLock::acquire_named(&out, &format!(".{stem}.lock"))?;
        Ok(SweepJob {
            sweep,
            shard,
            out,
            _lock: lock,
        })
    }

    /// Points this run covers (run or reused).
    pub fn points(&self) -> usize {
        self.shard.len(&self.sweep.grid)
    }

    /// The note for a step flag no point uses ([`super::unused_step_note`]), or `None`: none
    /// when an axis sets the step mode (each point uses what its mode uses).
    pub fn unused_step_note(&self, dt: bool, max_dt: bool) -> Option<String> {
        let base = self
            .sweep
            .base
            .with_overrides(&self.sweep.base_overrides)
            .ok()?;
        let sets_mode = self.sweep.grid.axes.iter().any(|a| {
            base.override_field(&a.path)
                .is_ok_and(|f| f == "run" || f == "run.step")
        });
        if sets_mode {
            return None;
        }
        super::unused_step_note(&base.run, dt, max_dt)
    }

    /// Runs the points and writes the table.
    pub fn run(&self, exec: ExecOptions) -> Result<SweepOutcome> {
        self.sweep.run(&self.out, self.shard, exec)
    }
}

/// The error of a table with failed points (the caller lists them first), or `Ok`.
pub fn check_failures(table: &MetricsTable) -> Result<()> {
    match table.failures.len() {
        0 => Ok(()),
        n => Err(Error::invalid(
            "sweep",
            format!(
                "{n} point(s) failed (listed above and in the table's `failures`); fix the cause and run again: finished points are reused"
            ),
        )),
    }
}
