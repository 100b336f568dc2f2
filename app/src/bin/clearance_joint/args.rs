//! The options several commands share: parallelism and progress, the memory budget, the
//! run-settings shortcuts.

use clap::Args;
use clearance_joint::scene::Scene;
use clearance_joint_app::cli;
use clearance_joint_app::study::sweep::{ExecOptions, Progress};

/// Parallelism and progress, shared by `sweep` and `study`.
#[derive(Args, Debug, Clone, Default)]
pub(crate) struct ExecArgs {
    /// Worker threads; default one per core (or RAYON_NUM_THREADS), at most one per core.
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) jobs: Option<i64>,
    #[command(flatten)]
    pub(crate) memory: MemoryArgs,
    /// Recompute every point, even those finished by an earlier run.
    #[arg(long)]
    pub(crate) rerun: bool,
    /// Progress: auto (a bar on a terminal, lines otherwise), bar, lines or quiet.
    #[arg(long, default_value = "auto", value_parser = ["auto", "bar", "lines", "quiet"])]
    pub(crate) progress: String,
}

impl ExecArgs {
    /// The options (saying so when the thread count was capped at the cores).
    pub(crate) fn options(&self) -> clearance_joint::Result<ExecOptions> {
        let (options, note) = cli::exec_options(
            cli::jobs(self.jobs)?,
            progress_mode(&self.progress),
            self.rerun,
            self.memory.max_memory.as_deref(),
        )?;
        if let Some(note) = note {
            eprintln!("note: {note}");
        }
        Ok(options)
    }
}

pub(crate) fn progress_mode(name: &str) -> Progress {
    match name {
        "bar" => Progress::Bar,
        "lines" => Progress::Lines,
        "quiet" => Progress::Quiet,
        _ => Progress::Auto,
    }
}

/// The memory budget, shared by every command that runs.
#[derive(Args, Debug, Clone, Default)]
pub(crate) struct MemoryArgs {
    /// Memory the runs may hold (e.g. 4G, 512M, 2GiB); default 80 % of what the system has
    /// available. A run that would need more is refused before it starts.
    #[arg(long, value_name = "SIZE", allow_hyphen_values = true)]
    pub(crate) max_memory: Option<String>,
}

impl MemoryArgs {
    pub(crate) fn budget(&self) -> clearance_joint::Result<Option<u64>> {
        cli::memory_budget(self.max_memory.as_deref())
    }
}

/// The run-settings shortcuts shared by `run` and `sweep` (for a sweep, they hold for every point).
#[derive(Args, Debug, Clone, Default)]
pub(crate) struct TimeArgs {
    /// Fixed step, s (same as `--set run.dt_s=...`).
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) dt: Option<f64>,
    /// Adaptive steps: the largest step, s (`run.max_dt_s`).
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) max_dt: Option<f64>,
    /// Fail the run (exit code 1) when a run-time guard is violated: a penetration beyond the
    /// contact law's validity, energy gained, steps at the floor, a fixed step longer than
    /// friction's limit (`run.strict`). Without it they are warnings on the console and in
    /// `summary.json`'s `guards`.
    #[arg(long)]
    pub(crate) strict: bool,
    /// Simulated time, s.
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) end: Option<f64>,
    /// Interval between CSV rows, s.
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) output_interval: Option<f64>,
}

impl TimeArgs {
    /// The options as `--set` overrides.
    pub(crate) fn overrides(&self) -> Vec<String> {
        [
            ("run.dt_s", self.dt),
            ("run.max_dt_s", self.max_dt),
            ("run.end_s", self.end),
            ("run.output_interval_s", self.output_interval),
        ]
        .into_iter()
        .filter_map(|(key, v)| v.map(|v| format!("{key}={v:e}")))
        .chain(self.strict.then(|| "run.strict=true".to_string()))
        .collect()
    }
}

/// Prints a scene's warnings.
pub(crate) fn warn(scene: &Scene) {
    for w in scene.warnings() {
        eprintln!("warning: {w}");
    }
}
