//! The command line: parses arguments, calls the app library (`clearance_joint_app::cli` and
//! `study`), prints what it returns, and sets the exit code. One file per command (`run.rs`,
//! `sweep.rs`, `study.rs`, `merge.rs`: its options and its work); `args.rs` the options they
//! share.

mod args;
mod merge;
mod run;
mod study;
mod sweep;

use clap::{Parser, Subcommand};
use merge::MergeArgs;
use run::RunArgs;
use std::process::ExitCode;
use study::StudyArgs;
use sweep::SweepArgs;

/// Revolute hinges with clearance in Rapier: runs a scene with an ideal and a clearance twin.
#[derive(Parser, Debug)]
#[command(version, about, args_conflicts_with_subcommands = true)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    #[command(flatten)]
    run: RunArgs,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Run a scene (the default command): ideal vs clearance, CSV + summary.json.
    Run(RunArgs),
    /// Run a grid of scenes, one ideal-vs-clearance run per point, plus a metrics table.
    Sweep(SweepArgs),
    /// Run a study preset of the scene with figures and reports (the paper's scene: clearance,
    /// torque, friction), or all of them.
    Study(StudyArgs),
    /// Gather the metrics tables of a sharded sweep into one.
    Merge(MergeArgs),
}

fn main() -> ExitCode {
    // Ctrl-C (or a kill with SIGTERM/SIGHUP): remove our temporaries and lock files, then exit.
    // A set being renamed into place is finished first; finished points of a sweep or study stay.
    if let Err(e) = ctrlc::set_handler(|| {
        clearance_joint_app::process::files::remove_inflight();
        clearance_joint_app::resultset::abandon_all();
        // Not `eprintln!`: it panics on a closed standard error, and the process would not exit.
        let _ = std::io::Write::write_all(
            &mut std::io::stderr(),
            b"\ninterrupted: temporary files removed\n",
        );
        std::process::exit(130);
    }) {
        eprintln!(
            "warning: no interrupt handler ({e}): an interrupted run may leave temporary files"
        );
    }
    let cli = Cli::parse();
    let outcome = match &cli.command {
        Some(Command::Run(a)) => run::run(a),
        Some(Command::Sweep(a)) => sweep::sweep(a),
        Some(Command::Study(a)) => study::study(a),
        Some(Command::Merge(a)) => merge::merge(a),
        None => run::run(&cli.run),
    };
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", clearance_joint_app::advice::describe(&e));
            ExitCode::FAILURE
        }
    }
}
