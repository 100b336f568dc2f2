//! `sweep`: a grid of scene runs and its metrics table.

use crate::args::{ExecArgs, TimeArgs, warn};
use clap::Args;
use clearance_joint_app::cli::{self, sweep::SweepJob};
use clearance_joint_app::study::sweep::MetricsTable;
use std::path::PathBuf;
use std::time::Instant;

/// `sweep`: every `--set` is an axis of the grid.
#[derive(Args, Debug, Clone)]
pub(crate) struct SweepArgs {
    /// Scene file (RON); default: the paper's solar-panel scene.
    #[arg(long)]
    pub(crate) scene: Option<PathBuf>,
    /// A swept parameter and its values: `--set hinge.clearance_mm=0.1,0.25,0.5` (repeatable;
    /// the grid is the product, the first `--set` varying slowest). One value fixes a parameter.
    #[arg(long = "set", value_name = "PATH=V1,V2,...")]
    pub(crate) axes: Vec<String>,
    #[command(flatten)]
    pub(crate) time: TimeArgs,
    /// Output folder; default `out/sweep`.
    #[arg(long)]
    pub(crate) out: Option<PathBuf>,
    /// Run only the points with index % N == K (K from 0): `--shard 0/4` ... `--shard 3/4`.
    #[arg(long, value_name = "K/N")]
    pub(crate) shard: Option<String>,
    /// Write each point's replay (`points/<dir>/replay.html`, the table's `dir`); off by default.
    #[arg(long)]
    pub(crate) replay: bool,
    /// Check each point's convergence (off by default for a sweep, whose points are many): the
    /// point again at half its tolerance, the clearance twin only; the verdict in the point's
    /// `summary.json`, the table's `convergence` (JSON) and `not_converged` (CSV).
    #[arg(long)]
    pub(crate) check: bool,
    #[command(flatten)]
    pub(crate) exec: ExecArgs,
}

/// Runs the sweep of `args`.
pub(crate) fn sweep(args: &SweepArgs) -> clearance_joint::Result<()> {
    let base = cli::load_scene(args.scene.as_deref())?;
    warn(&base);
    let mut exec = args.exec.options()?;
    exec.replay = args.replay;
    exec.check = args.check;
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out/sweep"));
    let job = SweepJob::prepare(
        base,
        &args.axes,
        args.time.overrides(),
        args.shard.as_deref(),
        out,
    )?;
    let (dt, max_dt) = (args.time.dt.is_some(), args.time.max_dt.is_some());
    if let Some(note) = job.unused_step_note(dt, max_dt) {
        eprintln!("note: {note}");
    }
    eprintln!(
        "sweep of {} points{}: {} to run or reuse, into {}",
        job.sweep.grid.len(),
        if job.shard.is_all() {
            String::new()
        } else {
            format!(" (shard {})", job.shard)
        },
        job.points(),
        job.out.display()
    );
    let start = Instant::now();
    let outcome = job.run(exec)?;
    let reused = outcome.points.iter().filter(|p| p.reused).count();
    let flagged = outcome
        .points
        .iter()
        .filter(|p| !p.manifest.metrics.guard_violations.is_empty())
        .count();
    if flagged > 0 {
        eprintln!(
            "WARNING: {flagged} point(s) left the model's validity (run-time guards; column \
             `guard_violations`, and each point's summary.json); `--strict` makes them failures"
        );
    }
    println!(
        "{} points finished ({} run, {reused} reused), {} failed, in {:.2} s; table {}",
        outcome.points.len(),
        outcome.points.len() - reused,
        outcome.table.failures.len(),
        start.elapsed().as_secs_f64(),
        job.out
            .join(format!("{}.csv", outcome.table.stem()))
            .display()
    );
    fail_on_failures(&outcome.table)
}

pub(crate) fn fail_on_failures(table: &MetricsTable) -> clearance_joint::Result<()> {
    for f in &table.failures {
        eprintln!("point `{}` failed: {}", f.point.dir, f.error);
    }
    cli::sweep::check_failures(table)
}
