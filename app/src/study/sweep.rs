//! Running a grid of scenes: one ideal-vs-clearance run per point in its own folder, in
//! parallel (rayon), resumable, shardable, and summarised in one metrics table.
//!
//! Layout of a sweep folder `OUT`:
//! - `OUT/points/<dir>/{ideal.csv, clearance.csv, summary.json, point.json}` per point.
//!   `point.json` (the manifest: the point, its scene, its metrics and the sizes of the other
//!   files) is written last, atomically: a point is finished exactly when its manifest exists,
//!   describes the same scene, and every file it lists has the size it records.
//! - `OUT/metrics.csv` and `OUT/metrics.json` (whole grid), or
//!   `OUT/metrics.shard-K-of-N.{csv,json}` for a shard; `merge` gathers shard tables.

use super::grid::{Axis, Grid, Point, Shard};
use super::metrics::RunMetrics;
use crate::advice::memory_options;
use crate::process::files::{write_all_atomic, write_atomic};
use crate::process::memory::bytes_text;
use crate::resultset::{ResultSet, pause_at};
use clearance_joint::error::{Divergence, Error, Result};
use clearance_joint::scene::runner::convergence::{self, ConvergenceVerdict};
use clearance_joint::scene::{Scene, ValidatedScene, field_within};
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;

mod compare;
mod execute;
mod points;
mod table;
pub use compare::*;
pub use execute::*;
pub use points::*;
pub use table::*;

/// Version of the point folders' files (the manifest, `summary.json` with its effective scene)
/// and of the table format: a point written under another version is not finished (it runs
/// again), and tables of another version do not merge.
pub const FORMAT_VERSION: u32 = 2;
/// Name of a point's manifest, written last.
pub const MANIFEST: &str = "point.json";

/// A grid of scenes: a base scene with fixed overrides, and the swept axes.
#[derive(Clone, Debug)]
pub struct Sweep {
    /// Name of the sweep (table header, progress messages).
    pub name: String,
    /// The scene before any override, without study presets: they are not part of a run, so a
    /// point's scene and manifest hold only what ran (and editing a preset reuses finished points).
    pub base: Scene,
    /// Overrides applied to every point before the point's own.
    pub base_overrides: Vec<String>,
    /// The swept axes.
    pub grid: Grid,
}

impl Sweep {
    /// A sweep of `grid` over `base` (its study presets dropped) with fixed `base_overrides`.
    pub fn new(
        name: impl Into<String>,
        mut base: Scene,
        base_overrides: Vec<String>,
        grid: Grid,
    ) -> Sweep {
        base.studies.clear();
        Sweep {
            name: name.into(),
            base,
            base_overrides,
            grid,
        }
    }

    /// The jobs of `shard` with folders under `out/points/`. Every point's scene is built and
    /// validated first, so a bad value fails before anything runs, naming the point (for a
    /// study's few cases; a sweep builds its points one by one, see [`Sweep::run`]).
    pub fn jobs(&self, out: &Path, shard: Shard) -> Result<Vec<Job>> {
        let base = self.check()?;
        shard
            .points(&self.grid)
            .map(|point| self.job(&base, out, point))
            .collect()
    }

    /// The job of `point`, from the base scene with the fixed overrides applied.
    fn job(&self, base: &ValidatedScene, out: &Path, point: Point) -> Result<Job> {
        let scene = base
            .with_overrides(&point.overrides())
            .map_err(|e| in_point(e, &point))?;
        Ok(Job {
            dir: out.join("points").join(&point.dir),
            base_overrides: self.base_overrides.clone(),
            point,
            scene,
        })
    }

    /// Checks the sweep before any point runs, and returns the base scene with the fixed
    /// overrides applied: two axes naming one field by different paths, or nested ones (one sets
    /// a field inside the other's value), are refused (one would silently overwrite the other),
    /// and every value of every axis is applied once, the other axes at their first value, so a
    /// bad value fails naming its point without building the whole grid.
    pub fn check(&self) -> Result<ValidatedScene> {
        let base = self
            .base
            .with_overrides(&self.base_overrides)?
            .validated()?;
        let points = self.axis_value_points();
        for &index in &points {
            self.check_axis_fields(&base, index)?;
            self.check_fixed_fields(index)?;
        }
        for index in points {
            self.job(&base, Path::new(""), self.grid.point(index))?;
        }
        Ok(base)
    }

    /// Refuses two axes that write one field, or nested fields, at point `index`: each axis's
    /// field is found as the point's overrides apply (in axis order, each in the scene the
    /// earlier left), so `hinge.exponent` after a `hinge.contact` axis is found inside the law
    /// that axis sets. A point whose overrides do not apply is left to the point's own check.
    fn check_axis_fields(&self, base: &ValidatedScene, index: usize) -> Result<()> {
        let Ok(fields) = base.override_fields(&self.grid.point(index).overrides()) else {
            return Ok(());
        };
        let axes = &self.grid.axes;
        for (i, (a, fa)) in axes.iter().zip(&fields).enumerate() {
            for (b, fb) in axes[i + 1..].iter().zip(&fields[i + 1..]) {
                if fa == fb {
                    return Err(Error::invalid(
                        format!("sweep axis `{}`", b.path),
                        format!(
                            "names the same field as axis `{}` ({fa}): put all its values in one \
                             `--set {fa}=v1,v2,...`",
                            a.path
                        ),
                    ));
                }
                if field_within(fb, fa) {
                    return Err(nested_axes(a, fa, b, fb));
                }
                if field_within(fa, fb) {
                    return Err(nested_axes(b, fb, a, fa));
                }
            }
        }
        Ok(())
    }

    /// Refuses a fixed override the point's axes overwrite (an axis sets its field, or an object
    /// holding it): it would be ignored at every point (`study torque --set
    /// drive.torque_scale=2`). A field set inside a fixed override's value is well-defined.
    fn check_fixed_fields(&self, index: usize) -> Result<()> {
        let mut all = self.base_overrides.clone();
        all.extend(self.grid.point(index).overrides());
        let Ok(fields) = self.base.override_fields(&all) else {
            return Ok(());
        };
        let (fixed, swept) = fields.split_at(self.base_overrides.len());
        for (o, f) in self.base_overrides.iter().zip(fixed) {
            let over = self.grid.axes.iter().zip(swept);
            if let Some((a, af)) = over.clone().find(|(_, af)| *af == f || field_within(f, af)) {
                return Err(Error::invalid(
                    o,
                    format!(
                        "this fixed setting is overwritten at every point of `{}` by the swept `{}` (which sets \
                         `{af}`), so it would be ignored: drop it, or put what it sets in the \
                         swept values",
                        self.name, a.path
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Indices of the points that set each value of each axis once, the other axes at their
    /// first value (the first point included once).
    fn axis_value_points(&self) -> Vec<usize> {
        let mut indices = vec![0];
        let mut stride = 1usize;
        for a in self.grid.axes.iter().rev() {
            indices.extend((1..a.values.len()).map(|j| j * stride));
            stride = stride.saturating_mul(a.values.len());
        }
        indices
    }

    /// Refuses, before any point runs, a shard of `points` points that cannot fit `budget`
    /// (default: what the system has available): the rows the table keeps per point, plus the
    /// parallel runs (the largest estimate among the points of [`Sweep::check`]). Returns the
    /// budget left for the runs.
    fn check_memory(
        &self,
        base: &ValidatedScene,
        points: usize,
        threads: usize,
        budget: Option<u64>,
        replay: bool,
    ) -> Result<Option<u64>> {
        let Some(budget) = budget.or_else(crate::process::memory::available_memory) else {
            return Ok(None);
        };
        let per_point = self.kept_bytes_per_point(base)?;
        let kept = per_point.saturating_mul(points as u64);
        if kept >= budget / 2 {
            return Err(Error::invalid(
                "sweep grid",
                format!(
                    "{points} points would keep about {} in memory for the table (about {} each), more than \
                     half the {} budget (--max-memory, default 80 % of the available memory): sweep fewer \
                     values, or split the grid with --shard K/N (each shard keeps its share) and `merge`",
                    bytes_text(kept),
                    bytes_text(per_point),
                    bytes_text(budget)
                ),
            ));
        }
        let left = budget - kept;
        let samples = self
            .axis_value_points()
            .into_iter()
            .map(|i| self.job(base, Path::new(""), self.grid.point(i)))
            .collect::<Result<Vec<_>>>()?;
        check_memory(&samples, threads.min(points.max(1)), Some(left), replay)?;
        Ok(Some(left))
    }

    /// Memory the sweep keeps per finished point until its table is written: the row and the
    /// outcome, and the table's CSV and JSON forms, allowed as eight times the point's row in JSON.
    fn kept_bytes_per_point(&self, base: &Scene) -> Result<u64> {
        let mut metrics = RunMetrics::default();
        for b in base.bodies.iter().filter(|b| !b.fixed) {
            metrics.bodies.insert(b.name.clone(), Default::default());
        }
        for h in &base.hinges {
            metrics.hinges.insert(h.name.clone(), Default::default());
        }
        metrics.guard_violations = vec!["x".repeat(200)];
        // A check's verdict names 8 metrics per hinge and describes the worst.
        metrics.convergence = ConvergenceVerdict::Checked {
            converged: vec!["x".repeat(40); 8 * base.hinges.len()],
            not_converged: Vec::new(),
            worst: Some("x".repeat(200)),
            cost: Default::default(),
        };
        let point = self.grid.point(self.grid.len() - 1);
        let row = TableRow {
            dir: format!("points/{}", point.dir),
            point,
            metrics,
        };
        Ok(8 * json_bytes(&row, "metrics table")?.len() as u64)
    }

    /// The table header describing this sweep.
    pub fn info(&self) -> SweepInfo {
        SweepInfo {
            format: FORMAT_VERSION,
            name: self.name.clone(),
            scene: self.base.name.clone(),
            base_overrides: self.base_overrides.clone(),
            axes: self.grid.axes.clone(),
            points: self.grid.len(),
        }
    }

    /// Runs `shard` of the sweep into `out` and writes its table (see the module docs). Points
    /// that fail are listed in the table's `failures` and returned with the outcome; the error
    /// is only for problems that stop the whole sweep (bad overrides, unwritable folder).
    pub fn run(&self, out: &Path, shard: Shard, options: ExecOptions) -> Result<SweepOutcome> {
        let base = self.check()?;
        let (threads, _) = thread_count(options.threads)?;
        let count = shard.len(&self.grid);
        let run_budget =
            self.check_memory(&base, count, threads, options.max_memory, options.replay)?;
        // The table of an earlier run must not pass for this one's while the points change.
        remove_tables(out, shard)?;
        crate::resultset::clean_stale(&out.join("points"));
        let index = |k: usize| shard.index() + k * shard.count();
        let results = execute_with(
            count,
            |k| self.job(&base, out, self.grid.point(index(k))),
            options,
            run_budget,
        )?;
        let mut rows = Vec::new();
        let mut failures = Vec::new();
        let mut outcomes = Vec::new();
        for (k, r) in results.into_iter().enumerate() {
            match r {
                Ok(o) => {
                    rows.push(TableRow::of(&o.manifest, &o.dir, out));
                    outcomes.push(o);
                }
                Err(e) => failures.push(Failure {
                    point: self.grid.point(index(k)),
                    error: e.to_string(),
                }),
            }
        }
        let table = MetricsTable {
            sweep: self.info(),
            shard: (!shard.is_all()).then_some(shard),
            rows,
            failures,
            missing: Vec::new(),
        };
        table.write(out)?;
        Ok(SweepOutcome {
            points: outcomes,
            table,
        })
    }
}

/// Removes the tables a run of `shard` into `out` replaces: its own, and the merged table of
/// the whole grid (a shard's new points make it stale).
fn remove_tables(out: &Path, shard: Shard) -> Result<()> {
    let mut stems = vec!["metrics".to_string()];
    if !shard.is_all() {
        stems.push(format!(
            "metrics.shard-{}-of-{}",
            shard.index(),
            shard.count()
        ));
    }
    for stem in stems {
        // The JSON (which `merge` reads) first: a table without it is no table.
        for ext in ["json", "csv"] {
            remove_if_present(&out.join(format!("{stem}.{ext}")))?;
        }
    }
    Ok(())
}

/// An error of building `point`'s scene, naming the point.
fn in_point(e: Error, point: &Point) -> Error {
    match e {
        Error::Invalid { field, reason } => Error::Invalid {
            field,
            reason: format!("{reason} (sweep point `{}`)", point.dir),
        },
        Error::Parse { what, reason } => Error::Parse {
            what: format!("{what} (sweep point `{}`)", point.dir),
            reason,
        },
        other => other,
    }
}
