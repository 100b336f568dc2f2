//! `study NAME`: a scene's study presets with their figures and reports.

use crate::args::{ExecArgs, warn};
use clap::Args;
use clearance_joint_app::cli;
use clearance_joint_app::study::report::Verdict;
use clearance_joint_app::study::{StudyOptions, run_studies, select};
use std::path::PathBuf;
use std::time::Instant;

/// `study NAME`.
#[derive(Args, Debug, Clone)]
pub(crate) struct StudyArgs {
    /// The preset's name, as the scene's `studies` declare it (the paper's scene: clearance,
    /// torque, friction), or all.
    pub(crate) name: String,
    /// Scene file (RON); default: the paper's solar-panel scene. Its `studies` declare the
    /// presets; a scene declaring none gets the paper's, which set `hinge.*` and `drive.*` and so
    /// need a clearance hinge named `hinge` and a drive named `drive`.
    #[arg(long)]
    pub(crate) scene: Option<PathBuf>,
    /// Override a parameter in every case, after the study's own settings (repeatable),
    /// e.g. `--set run.end_s=1` for a quick look.
    #[arg(long = "set", value_name = "PATH=VALUE")]
    pub(crate) overrides: Vec<String>,
    /// Root folder; each study writes into `<out>/<name>/`. Default `out/studies`.
    #[arg(long)]
    pub(crate) out: Option<PathBuf>,
    /// Skip the figures.
    #[arg(long)]
    pub(crate) no_figures: bool,
    /// Fail (exit code 1) when a case leaves the model's validity (a run-time guard; same as
    /// `--set run.strict=true`): the case fails and the study writes no report. Without it
    /// they are warnings in each case's `summary.json` and in the metrics table.
    #[arg(long)]
    pub(crate) strict: bool,
    /// Skip the replays (each case's `replay.html`, linked from the report; written by default).
    #[arg(long)]
    pub(crate) no_replay: bool,
    /// Skip the convergence check of each case (by default each case runs again at half its
    /// tolerance, the clearance twin only, and the report says per case which metrics
    /// converged; on `study all` the checks take about as long as the runs).
    #[arg(long)]
    pub(crate) no_check: bool,
    #[command(flatten)]
    pub(crate) exec: ExecArgs,
}

/// Runs the studies `args` name.
pub(crate) fn study(args: &StudyArgs) -> clearance_joint::Result<()> {
    let base = cli::load_scene(args.scene.as_deref())?;
    let studies = select(&base, &args.name)?;
    warn(&base);
    let root = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out/studies"));
    let mut exec = args.exec.options()?;
    exec.replay = !args.no_replay;
    exec.check = !args.no_check;
    let options = StudyOptions {
        exec,
        extra_overrides: args
            .overrides
            .iter()
            .cloned()
            .chain(args.strict.then(|| "run.strict=true".to_string()))
            .collect(),
        no_figures: args.no_figures,
    };
    // The `--set`s replace the study's own settings freely, but not one another unsaid.
    for s in &studies {
        base.refuse_lost_overrides(&s.spec.set, &options.extra_overrides)?;
    }
    let start = Instant::now();
    let outcomes = run_studies(&studies, &base, &root, &options)?;
    for o in &outcomes {
        println!("{} study -> {}", o.study.name(), o.report.display());
        for c in &o.cases {
            if let Some(h) = c.metrics.hinges.get(&o.study.hinge) {
                println!(
                    "  {:<22} onsets {:>5}  impacts {:>5}  peak force {:>9.3} N  RMS force {:>7.3} N  final hinge angle {:>8.3} deg (ideal {:>8.3}){}",
                    c.label,
                    h.onsets,
                    h.impacts,
                    h.peak_force_n,
                    h.rms_force_n,
                    h.final_angle_deg,
                    h.final_angle_ideal_deg,
                    if c.reused { "  [reused]" } else { "" }
                );
                println!(
                    "  {:<22} convergence: {}",
                    "",
                    c.metrics.convergence.describe()
                );
            }
        }
        for c in &o.conclusions {
            if c.verdict != Verdict::NotTested {
                println!("  paper conclusion {}: {}", c.number, c.verdict.text());
            }
        }
    }
    if outcomes.len() > 1 {
        println!("summary -> {}", root.join("report.md").display());
    }
    println!("done in {:.2} s", start.elapsed().as_secs_f64());
    Ok(())
}
