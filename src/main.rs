//! Command-line front end: parses arguments, runs, prints. The work is in the library.

use clap::{Args, Parser, Subcommand};
use clearance_joint::report::comparison_table;
use clearance_joint::scene::Scene;
use clearance_joint::sim::{RunOptions, Simulation};
use std::path::PathBuf;
use std::process::ExitCode;

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
}

/// Scene selection and overrides shared by the commands.
#[derive(Args, Debug, Clone, Default)]
struct RunArgs {
    /// Scene file (RON); default: the paper's solar-panel scene.
    #[arg(long)]
    scene: Option<PathBuf>,
    /// Override a parameter: `--set hinge.clearance_mm=0.25` (repeatable).
    #[arg(long = "set", value_name = "PATH=VALUE")]
    overrides: Vec<String>,
    /// Step size, s (same as `--set run.dt_s=...`).
    #[arg(long)]
    dt: Option<f64>,
    /// Simulated time, s.
    #[arg(long)]
    end: Option<f64>,
    /// Interval between CSV rows, s.
    #[arg(long)]
    output_interval: Option<f64>,
    /// Output folder; default `out/<scene name>`.
    #[arg(long)]
    out: Option<PathBuf>,
}

impl RunArgs {
    fn scene(&self) -> clearance_joint::Result<Scene> {
        let base = match &self.scene {
            Some(p) => Scene::load(p)?,
            None => Scene::solar_panel(),
        };
        let mut overrides = self.overrides.clone();
        for (key, v) in [
            ("run.dt_s", self.dt),
            ("run.end_s", self.end),
            ("run.output_interval_s", self.output_interval),
        ] {
            if let Some(v) = v {
                overrides.push(format!("{key}={v:e}"));
            }
        }
        base.with_overrides(&overrides)
    }
}

fn run(args: &RunArgs) -> clearance_joint::Result<()> {
    let scene = args.scene()?;
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out").join(&scene.name));
    eprintln!(
        "running `{}`: dt = {:e} s, {} s simulated, ideal and clearance twins",
        scene.name, scene.run.dt_s, scene.run.end_s
    );
    let result = Simulation::new(&scene, RunOptions::default())?.run()?;
    let summary = result.write(&out)?;
    println!("{}", comparison_table(&summary));
    println!(
        "{} steps in {:.2} s wall; wrote {}/{{ideal.csv, clearance.csv, summary.json}}",
        result.steps,
        result.wall_s,
        out.display()
    );
    Ok(())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let outcome = match &cli.command {
        Some(Command::Run(a)) => run(a),
        None => run(&cli.run),
    };
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
