//! Running a sweep's jobs in parallel: options, thread count, memory check and progress.

use super::*;

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

/// What a sweep run produced.
#[derive(Clone, Debug)]
pub struct SweepOutcome {
    /// Finished points, in grid order.
    pub points: Vec<PointOutcome>,
    /// The table written (with the failures).
    pub table: MetricsTable,
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
pub(super) fn execute_with(
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
pub(super) struct Reporter {
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
