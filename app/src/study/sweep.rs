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
use clearance_joint::error::{Error, Result};
use clearance_joint::scene::runner::convergence::{self, ConvergenceVerdict};
use clearance_joint::scene::{Scene, ValidatedScene, field_within};
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;

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

/// One point ready to run: its scene and its folder.
#[derive(Clone, Debug)]
pub struct Job {
    /// The grid point.
    pub point: Point,
    /// The scene with the base and point overrides applied, checked once (it carries the
    /// hinges' built `HingeDesign`s the run uses).
    pub scene: ValidatedScene,
    /// The point's folder.
    pub dir: PathBuf,
    /// The sweep's fixed overrides (recorded in the manifest).
    pub base_overrides: Vec<String>,
}

/// A size-checked file of a finished point.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct FileEntry {
    /// File name inside the point's folder.
    pub name: String,
    /// Its size, bytes.
    pub bytes: u64,
}

/// `point.json`: what a finished point holds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// [`FORMAT_VERSION`].
    pub format: u32,
    /// The grid point.
    pub point: Point,
    /// The fixed overrides of the sweep.
    pub base_overrides: Vec<String>,
    /// The scene that ran, as RON: a rerun reuses the point only if its scene is identical.
    pub scene_ron: String,
    /// The result files and their sizes.
    pub files: Vec<FileEntry>,
    /// The run's metrics.
    pub metrics: RunMetrics,
}

/// A finished point, just run or reused.
#[derive(Clone, Debug)]
pub struct PointOutcome {
    /// Its manifest.
    pub manifest: Manifest,
    /// Its folder.
    pub dir: PathBuf,
    /// True when an earlier run's complete files were reused.
    pub reused: bool,
}

/// How to show progress.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Progress {
    /// A bar when standard error is a terminal, plain lines otherwise.
    #[default]
    Auto,
    /// Always a bar.
    Bar,
    /// One line per finished point.
    Lines,
    /// Nothing.
    Quiet,
}

/// Execution options of a sweep.
#[derive(Clone, Copy, Debug, Default)]
pub struct ExecOptions {
    /// Progress display.
    pub progress: Progress,
    /// Worker threads (`None`: one per core).
    pub threads: Option<usize>,
    /// Recompute finished points instead of reusing them.
    pub rerun: bool,
    /// Memory the parallel runs may hold, bytes (`None`: 80 % of what the system reports
    /// available, see [`crate::process::memory::available_memory`]).
    pub max_memory: Option<u64>,
    /// Write each point's replay (`replay.html`, see [`crate::replay`]); a finished point
    /// without one is run again.
    pub replay: bool,
    /// Check each point's convergence ([`clearance_joint::scene::runner::convergence::check`]:
    /// the point again at half its tolerance, the clearance twin only), its verdict in the
    /// point's `summary.json` and metrics ([`RunMetrics::convergence`]); a finished point
    /// without a verdict is run again.
    pub check: bool,
}

/// The number of worker threads for `requested` (`None`: one per core), at most one per core:
/// more threads than cores only add memory and switching. Returns the count and, when the
/// request was cut, a message saying so.
pub fn thread_count(requested: Option<usize>) -> Result<(usize, Option<String>)> {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    match requested {
        Some(0) => Err(Error::invalid("--jobs", "must be at least 1 (got 0)")),
        Some(n) if n > cores => Ok((
            cores,
            Some(format!(
                "--jobs {n} capped at {cores}: this machine has {cores} core(s)"
            )),
        )),
        Some(n) => Ok((n, None)),
        None => Ok((cores, None)),
    }
}

/// A point that failed, with the reason.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Failure {
    /// The grid point.
    pub point: Point,
    /// The error message.
    pub error: String,
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

/// What a sweep run produced.
#[derive(Clone, Debug)]
pub struct SweepOutcome {
    /// Finished points, in grid order.
    pub points: Vec<PointOutcome>,
    /// The table written (with the failures).
    pub table: MetricsTable,
}

impl Job {
    /// The point's manifest if the point is finished: manifest readable, same format and scene,
    /// and every listed file present with its recorded size. Anything else means unfinished.
    pub fn finished(&self) -> Option<Manifest> {
        let text = std::fs::read_to_string(self.dir.join(MANIFEST)).ok()?;
        let m: Manifest = serde_json::from_str(&text).ok()?;
        if m.format != FORMAT_VERSION || m.scene_ron != self.scene.to_ron() {
            return None;
        }
        for f in &m.files {
            let meta = std::fs::metadata(self.dir.join(&f.name)).ok()?;
            if !meta.is_file() || meta.len() != f.bytes {
                return None;
            }
        }
        Some(m)
    }

    /// Runs the point and writes its files as one set, the manifest last (see
    /// [`run_point`](Self::run_point)).
    pub fn run(&self) -> Result<Manifest> {
        self.run_replay(false)
    }

    /// As [`run`](Self::run), also writing the point's replay (`replay.html`) when `replay`.
    pub fn run_replay(&self, replay: bool) -> Result<Manifest> {
        self.run_point(replay, false)
    }

    /// As [`run_replay`](Self::run_replay), also checking the point's convergence when `check`
    /// ([`ExecOptions::check`]). A check whose own run fails does not fail the point: its
    /// verdict says so. The point's files (CSVs, summary, replay, manifest) are one result set
    /// ([`ResultSet`]): written into `points/.<dir>.new-<pid>` and renamed into place whole, so
    /// a kill leaves the old set or the new one, never a mix; its claim (`points/.<dir>.lock`)
    /// refuses a second sweep running the same point.
    pub fn run_point(&self, replay: bool, check: bool) -> Result<Manifest> {
        let set = ResultSet::begin(&self.dir, &[])?;
        let adaptive = self.scene.run.step == clearance_joint::scene::StepMode::Adaptive;
        let (mut result, recording) = crate::replay::run_recorded(&self.scene, |_| {}, replay)
            .map_err(|e| e.with_step_mode(adaptive))?;
        // A point the step control stalled is an error of the sweep, not a result.
        if let Some(e) = result.stopped.take() {
            return Err(e.with_step_mode(adaptive));
        }
        let convergence = if check {
            match convergence::check(&self.scene, &result, |_| {}) {
                Ok(c) => c.verdict(),
                Err(e) => ConvergenceVerdict::Failed {
                    error: e.to_string(),
                },
            }
        } else {
            ConvergenceVerdict::NotChecked {
                reason: "not asked for".into(),
            }
        };
        let mut metrics = RunMetrics::of(&result)?;
        metrics.convergence = convergence.clone();
        let dir = set.dir();
        crate::summary::write_run(&result, dir, &convergence)?;
        pause_at("point-summary");
        if let Some(recording) = &recording {
            crate::replay::write_run_replay(&self.scene, &result, recording, dir)?;
        }
        pause_at("point-replay");
        let manifest = self.manifest(&result, dir, metrics)?;
        write_atomic(&dir.join(MANIFEST), &json_bytes(&manifest, "manifest")?)?;
        pause_at("point-manifest");
        set.commit()?;
        Ok(manifest)
    }

    /// The manifest of the point's files written into `dir`.
    fn manifest(
        &self,
        result: &clearance_joint::scene::runner::RunResult,
        dir: &Path,
        metrics: RunMetrics,
    ) -> Result<Manifest> {
        let mut names: Vec<String> = result
            .twins
            .iter()
            .map(|t| format!("{}.csv", t.kind.name()))
            .collect();
        names.push("summary.json".into());
        let files = names
            .into_iter()
            .map(|name| {
                let path = dir.join(&name);
                let bytes = std::fs::metadata(&path)
                    .map_err(|source| Error::Io {
                        action: "cannot read the size of",
                        path,
                        source,
                    })?
                    .len();
                Ok(FileEntry { name, bytes })
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Manifest {
            format: FORMAT_VERSION,
            point: self.point.clone(),
            base_overrides: self.base_overrides.clone(),
            scene_ron: self.scene.to_ron(),
            files,
            metrics,
        })
    }
}

fn remove_if_present(path: &Path) -> Result<()> {
    match std::fs::remove_file(path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(Error::Io {
            action: "cannot remove",
            path: path.to_path_buf(),
            source: e,
        }),
        _ => Ok(()),
    }
}

/// Pretty JSON of a serialisable value (refusing non-finite numbers, which JSON cannot hold).
pub(crate) fn json_bytes<T: Serialize>(value: &T, what: &str) -> Result<Vec<u8>> {
    let v = serde_json::to_value(value).map_err(|e| Error::invalid(what, e.to_string()))?;
    serde_json::to_vec_pretty(&v).map_err(|e| Error::invalid(what, e.to_string()))
}

/// Runs `jobs` (reusing finished ones unless `rerun`) in parallel; results in job order.
/// Fails only if the batch cannot fit the memory budget or the thread pool cannot be built;
/// each job has its own result.
pub fn execute(jobs: &[Job], options: ExecOptions) -> Result<Vec<Result<PointOutcome>>> {
    let (threads, _) = thread_count(options.threads)?;
    check_memory(jobs, threads, options.max_memory, options.replay)?;
    let mut parents: Vec<&Path> = jobs.iter().filter_map(|j| j.dir.parent()).collect();
    parents.dedup();
    for p in parents {
        crate::resultset::clean_stale(p);
    }
    execute_with(jobs.len(), |k| Ok(jobs[k].clone()), options, None)
}

/// Runs `count` jobs, job `k` built by `job_at(k)` when a worker takes it (a large grid is
/// never held whole), in parallel; results in job order. With `run_budget`, a point whose runs
/// in parallel would exceed it fails before it starts. The outcomes keep no scene text.
fn execute_with(
    count: usize,
    job_at: impl Fn(usize) -> Result<Job> + Sync,
    options: ExecOptions,
    run_budget: Option<u64>,
) -> Result<Vec<Result<PointOutcome>>> {
    let (threads, _) = thread_count(options.threads)?;
    let concurrent = threads.min(count).max(1) as u64;
    let progress = Reporter::new(count, options.progress);
    let run = |job: &Job| -> Result<PointOutcome> {
        if let Some(budget) = run_budget {
            let estimate = crate::replay::estimate(&job.scene, options.replay);
            estimate
                .check(&job.scene, concurrent, budget)
                .map_err(|e| memory_options(e, &estimate, &job.scene, concurrent, budget))
                .map_err(|e| in_point(e, &job.point))?;
        }
        // A finished point is reused unless a replay or a check is asked for and it has none.
        let finished = (!options.rerun)
            .then(|| job.finished())
            .flatten()
            .filter(|_| !options.replay || job.dir.join(crate::replay::FILE).is_file())
            .filter(|m| !options.check || m.metrics.convergence.is_answered());
        let (manifest, reused) = match finished {
            Some(manifest) => (manifest, true),
            None => (job.run_point(options.replay, options.check)?, false),
        };
        Ok(PointOutcome {
            manifest: Manifest {
                scene_ron: String::new(),
                ..manifest
            },
            dir: job.dir.clone(),
            reused,
        })
    };
    let work = || -> Vec<Result<PointOutcome>> {
        (0..count)
            .into_par_iter()
            .map(|k| {
                let start = Instant::now();
                let (name, outcome) = match job_at(k) {
                    Ok(job) => (job.point.dir.clone(), run(&job)),
                    Err(e) => (format!("point {k}"), Err(e)),
                };
                progress.done(&name, &outcome, start.elapsed().as_secs_f64());
                outcome
            })
            .collect()
    };
    let results = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Error::invalid("--jobs", e.to_string()))?
        .install(work);
    progress.finish();
    Ok(results)
}

/// Refuses, before any point runs, a batch whose parallel runs would hold more memory than
/// `budget` (default: what the system has available): the largest point's estimate times the
/// runs in flight at once.
pub fn check_memory(jobs: &[Job], threads: usize, budget: Option<u64>, replay: bool) -> Result<()> {
    let Some(budget) = budget.or_else(crate::process::memory::available_memory) else {
        return Ok(());
    };
    let Some((job, estimate)) = jobs
        .iter()
        .map(|j| (j, crate::replay::estimate(&j.scene, replay)))
        .max_by_key(|(_, e)| e.bytes)
    else {
        return Ok(());
    };
    let concurrent = threads.min(jobs.len()).max(1) as u64;
    estimate
        .check(&job.scene, concurrent, budget)
        .map_err(|e| memory_options(e, &estimate, &job.scene, concurrent, budget))
        .map_err(|e| match e {
            Error::Invalid { field, reason } => Error::Invalid {
                field,
                reason: format!("{reason} (sweep point `{}`)", job.point.dir),
            },
            other => other,
        })
}

/// Progress display: an indicatif bar or plain lines on standard error.
struct Reporter {
    bar: Option<ProgressBar>,
    lines: bool,
    total: usize,
    done: std::sync::atomic::AtomicUsize,
}

impl Reporter {
    fn new(total: usize, mode: Progress) -> Reporter {
        let mode = match mode {
            Progress::Auto if std::io::stderr().is_terminal() => Progress::Bar,
            Progress::Auto => Progress::Lines,
            m => m,
        };
        let bar = (mode == Progress::Bar).then(|| {
            let b = ProgressBar::new(total as u64);
            if let Ok(style) = ProgressStyle::with_template(
                "{elapsed_precise} [{bar:30}] {pos}/{len} points {msg}",
            ) {
                b.set_style(style.progress_chars("=> "));
            }
            b
        });
        Reporter {
            bar,
            lines: mode == Progress::Lines,
            total,
            done: std::sync::atomic::AtomicUsize::new(0),
        }
    }

    fn done(&self, name: &str, outcome: &Result<PointOutcome>, seconds: f64) {
        let n = self.done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
        let what = match outcome {
            Ok(o) if o.reused => "reused (finished earlier)".to_string(),
            Ok(o) => {
                let mut what = format!("done in {seconds:.2} s");
                let m = &o.manifest.metrics;
                if !m.guard_violations.is_empty() {
                    what += &format!(
                        "; WARNING, outside the model's validity: {}",
                        m.guard_violations.join("; ")
                    );
                }
                if !m.convergence.not_converged().is_empty() {
                    what += &format!(
                        "; not converged: {}",
                        m.convergence.not_converged().join(", ")
                    );
                }
                what
            }
            Err(e) => format!("FAILED: {e}"),
        };
        let line = format!("[{n}/{}] {name}: {what}", self.total);
        if let Some(bar) = &self.bar {
            let warned =
                matches!(outcome, Ok(o) if !o.manifest.metrics.guard_violations.is_empty());
            if outcome.is_err() || warned {
                bar.println(&line);
            }
            bar.set_message(name.to_string());
            bar.inc(1);
        } else if self.lines {
            eprintln!("{line}");
        }
    }

    fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

/// Header of a metrics table: which sweep it belongs to.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct SweepInfo {
    /// [`FORMAT_VERSION`].
    pub format: u32,
    /// Sweep name.
    pub name: String,
    /// Base scene name.
    pub scene: String,
    /// Fixed overrides.
    pub base_overrides: Vec<String>,
    /// Swept axes.
    pub axes: Vec<Axis>,
    /// Number of points of the whole grid.
    pub points: usize,
}

impl SweepInfo {
    /// What differs between this sweep and `other`, a phrase per setting (empty when equal),
    /// e.g. ``fixed settings: `run.end_s=1e0` in table 1, `run.end_s=2e0` here``.
    pub fn differences(&self, other: &SweepInfo) -> Vec<String> {
        let mut d = Vec::new();
        let mut differ = |what: &str, a: String, b: String| {
            if a != b {
                d.push(format!("{what}: {a} in table 1, {b} here"));
            }
        };
        differ("format", self.format.to_string(), other.format.to_string());
        differ(
            "name",
            format!("`{}`", self.name),
            format!("`{}`", other.name),
        );
        differ(
            "scene",
            format!("`{}`", self.scene),
            format!("`{}`", other.scene),
        );
        let only = |a: &[String], b: &[String]| -> String {
            let v: Vec<String> = a
                .iter()
                .filter(|x| !b.contains(x))
                .map(|x| format!("`{x}`"))
                .collect();
            if v.is_empty() {
                "nothing else".into()
            } else {
                v.join(", ")
            }
        };
        if self.base_overrides != other.base_overrides {
            differ(
                "fixed settings (--set, --end, --dt, ...)",
                only(&self.base_overrides, &other.base_overrides),
                only(&other.base_overrides, &self.base_overrides),
            );
        }
        let axes = |v: &[Axis]| -> Vec<String> {
            v.iter()
                .map(|a| format!("{}={}", a.path, a.values.join(",")))
                .collect()
        };
        if self.axes != other.axes {
            differ(
                "axes",
                only(&axes(&self.axes), &axes(&other.axes)),
                only(&axes(&other.axes), &axes(&self.axes)),
            );
        }
        differ("points", self.points.to_string(), other.points.to_string());
        d
    }
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
    fn of(manifest: &Manifest, dir: &Path, out: &Path) -> TableRow {
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
                            reason: format!("metric `{name}` of `{}` is {x}", r.point.dir),
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
fn csv_cell(s: &str) -> String {
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
fn nested_axes(outer: &Axis, outer_field: &str, inner: &Axis, inner_field: &str) -> Error {
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

/// Two runs' metrics equal in everything but the wall times (the run's, and its check's).
fn same_physics(a: &super::metrics::RunMetrics, b: &super::metrics::RunMetrics) -> bool {
    let mut b = b.clone();
    b.wall_s = a.wall_s;
    if let (
        ConvergenceVerdict::Checked { cost: ca, .. },
        ConvergenceVerdict::Checked { cost: cb, .. },
    ) = (&a.convergence, &mut b.convergence)
    {
        cb.wall_s = ca.wall_s;
        cb.run_wall_s = ca.run_wall_s;
    }
    *a == b
}
