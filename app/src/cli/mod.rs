//! What the commands do between parsing their arguments and printing: the binary
//! (`src/bin/clearance_joint/`) parses, calls these, and prints what they return.
//!
//! - [`run`]: one scene's ideal-vs-clearance run into a result set (`run`, the default job).
//! - [`sweep`]: a grid of runs, or a shard of it, into one folder (`sweep`).
//! - [`merge`]: the tables of a sharded sweep gathered into one (`merge`).
//!
//! `study` needs nothing here: it selects and runs presets with [`crate::study`].

pub mod merge;
pub mod run;
pub mod sweep;

use crate::study::sweep::{ExecOptions, Progress, thread_count};
use clearance_joint::error::sig4;
use clearance_joint::error::{Error, Result};
use clearance_joint::scene::{RunSettings, SOLAR_PANEL_RON, Scene, StepMode, ValidatedScene};
use std::path::Path;

/// The scene file at `path`, or without one the paper's solar-panel scene.
pub fn load_scene(path: Option<&Path>) -> Result<Scene> {
    load_validated(path).map(ValidatedScene::into_scene)
}

/// As [`load_scene`], keeping what the scene's check built (the run needs no second check).
pub fn load_validated(path: Option<&Path>) -> Result<ValidatedScene> {
    match path {
        Some(p) => ValidatedScene::load(p),
        None => ValidatedScene::from_ron(SOLAR_PANEL_RON, "assets/solar_panel.ron"),
    }
}

/// The memory budget `--max-memory SIZE` (e.g. `4G`), if given.
pub fn memory_budget(max_memory: Option<&str>) -> Result<Option<u64>> {
    if let Some(m) = max_memory.filter(|m| m.trim_start().starts_with('-')) {
        return Err(Error::invalid(
            "--max-memory",
            format!("must be a positive size such as 4G, 512M or 2GiB (got `{m}`)"),
        ));
    }
    max_memory
        .map(crate::process::memory::parse_bytes)
        .transpose()
        .map_err(|e| crate::advice::from_option(e, "--max-memory"))
}

/// The thread count `--jobs N` as given (possibly negative), refused below 1.
pub fn jobs(jobs: Option<i64>) -> Result<Option<usize>> {
    jobs.map(|n| match usize::try_from(n) {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err(Error::invalid(
            "--jobs",
            format!("must be at least 1 (got {n})"),
        )),
    })
    .transpose()
}

/// Execution options of the parallel commands. The thread count is the request (else
/// `RAYON_NUM_THREADS`, else one per core) capped at the cores, and is used for the global
/// pool too (figures), so no setting spawns thousands of threads. Returns the options and, when
/// the request was cut, a note saying so.
pub fn exec_options(
    jobs: Option<usize>,
    progress: Progress,
    rerun: bool,
    max_memory: Option<&str>,
) -> Result<(ExecOptions, Option<String>)> {
    let requested = jobs.or_else(|| {
        std::env::var("RAYON_NUM_THREADS")
            .ok()
            .and_then(|v| v.trim().parse().ok())
            .filter(|&n: &usize| n > 0)
    });
    let (threads, note) = thread_count(requested)?;
    let _ = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build_global();
    let options = ExecOptions {
        progress,
        threads: Some(threads),
        rerun,
        max_memory: memory_budget(max_memory)?,
        replay: false,
        check: false,
    };
    Ok((options, note))
}

/// The note for a step flag the scene's step mode does not use, or `None`: `--dt` sets the fixed
/// step (`run.dt_s`), which adaptive steps ignore, and `--max-dt` caps adaptive steps
/// (`run.max_dt_s`), which a fixed step ignores. Said rather than refused: the flag is recorded
/// in the scene and holds if the mode is switched, but the run must not look refined by it.
pub fn unused_step_note(run: &RunSettings, dt: bool, max_dt: bool) -> Option<String> {
    match run.step {
        StepMode::Adaptive if dt => Some(format!(
            "`--dt` sets the fixed step (`run.dt_s`), but this scene steps adaptively \
             (`run.step: Adaptive`), so it is not used. For smaller adaptive steps give a smaller \
             `--set run.tolerance=...` (now {}) or cap them with `--max-dt` (now {} s); for fixed \
             steps of `--dt` add `--set run.step=Fixed`",
            sig4(run.tolerance),
            sig4(run.max_dt_s)
        )),
        StepMode::Fixed if max_dt => Some(format!(
            "`--max-dt` caps adaptive steps (`run.max_dt_s`), but this scene steps at a fixed \
             step (`run.step: Fixed`, {} s), so it is not used. Set the fixed step with `--dt`, \
             or step adaptively with `--set run.step=Adaptive`",
            sig4(run.dt_s)
        )),
        _ => None,
    }
}
