//! `merge`: the metrics tables of a sharded sweep gathered into one.

use crate::sweep::fail_on_failures;
use clap::Args;
use clearance_joint_app::cli::{self, merge::Merged};
use std::path::PathBuf;

/// `merge`: shard tables in, one table out.
#[derive(Args, Debug, Clone)]
pub(crate) struct MergeArgs {
    /// Sweep folders (their `metrics.shard-*.json` are read) or shard table files.
    #[arg(required = true)]
    pub(crate) inputs: Vec<PathBuf>,
    /// Folder for the merged `metrics.csv` and `metrics.json`; default: the first input folder.
    #[arg(long)]
    pub(crate) out: Option<PathBuf>,
    /// With points missing (a shard not run), write `metrics.incomplete.{csv,json}` listing
    /// them instead of refusing; `metrics.csv` is only ever written for a whole grid.
    #[arg(long)]
    pub(crate) incomplete: bool,
}

/// Merges the tables `args` name.
pub(crate) fn merge(args: &MergeArgs) -> clearance_joint::Result<()> {
    let Merged {
        table,
        inputs,
        out,
        stem,
    } = cli::merge::merge(&args.inputs, args.out.as_deref(), args.incomplete)?;
    println!(
        "merged {inputs} table(s): {} of {} points, {} failed, {} missing -> {}",
        table.rows.len(),
        table.sweep.points,
        table.failures.len(),
        table.missing.len(),
        out.join(format!("{stem}.csv")).display()
    );
    cli::merge::check_missing(&table)?;
    fail_on_failures(&table)
}
