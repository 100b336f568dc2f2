//! `run` (the default command): one scene, its result set, figures, replay and convergence
//! check.

use crate::args::{MemoryArgs, TimeArgs, progress_mode, warn};
use clap::Args;
use clearance_joint::scene::ValidatedScene;
use clearance_joint::scene::report::comparison_table;
use clearance_joint::scene::runner::RunResult;
use clearance_joint::scene::runner::convergence::{self, Convergence, ConvergenceVerdict};
use clearance_joint_app::cli::{self, run::SceneRun};
use clearance_joint_app::figures::run::{can_draw, draw_run_figures};
use clearance_joint_app::progress::RunProgress;
use clearance_joint_app::replay::record::Recording;
use std::path::PathBuf;

/// Scene selection and overrides shared by the commands.
#[derive(Args, Debug, Clone, Default)]
pub(crate) struct RunArgs {
    /// Scene file (RON); default: the paper's solar-panel scene.
    #[arg(long)]
    pub(crate) scene: Option<PathBuf>,
    /// Override a parameter: `--set hinge.clearance_mm=0.25` (repeatable).
    #[arg(long = "set", value_name = "PATH=VALUE")]
    pub(crate) overrides: Vec<String>,
    #[command(flatten)]
    pub(crate) time: TimeArgs,
    /// Output folder; default `out/<scene name>`.
    #[arg(long)]
    pub(crate) out: Option<PathBuf>,
    /// Progress of a long run: auto (a bar on a terminal once the run has taken 2 s, nothing
    /// otherwise), bar, lines or quiet.
    #[arg(long, default_value = "auto", value_parser = ["auto", "bar", "lines", "quiet"])]
    pub(crate) progress: String,
    #[command(flatten)]
    pub(crate) memory: MemoryArgs,
    /// Draw the figures (the default): angles and rates, joint force, journal orbit of the first
    /// clearance hinge, PNG and SVG, into the output folder after the result set. With this flag a
    /// scene that cannot have them is an error; without it such a scene just has none.
    #[arg(long, conflicts_with = "no_figures")]
    pub(crate) figures: bool,
    /// Skip the figures.
    #[arg(long)]
    pub(crate) no_figures: bool,
    /// Skip the replay (`replay.html`: the run in 3D with the journal magnified in its bearing,
    /// written beside the CSVs by default).
    #[arg(long)]
    pub(crate) no_replay: bool,
    /// Check convergence (the default). The check runs the scene again at half its tolerance
    /// (half its fixed step), the clearance twin only, and compares every clearance hinge's first
    /// impact, largest force and penetration, onsets and impacts after a separation, contact
    /// fraction and final angle. A metric whose estimated error exceeds its bound is flagged on
    /// the console, in `summary.json`'s `convergence` and in `convergence.json`, and fails the
    /// run (exit code 1, the set written) under `--strict`. About the run's own time again on
    /// the paper's scene. The flag itself changes two things: a check whose own run fails fails
    /// the command (it warns otherwise), and with `--strict` a scene with nothing to check (no
    /// clearance hinge) is refused before it runs.
    #[arg(long, conflicts_with = "no_check")]
    pub(crate) check: bool,
    /// Skip the convergence check (on the paper's scene the command then takes about 2/3 of the
    /// time); the summary says the run was not checked.
    #[arg(long)]
    pub(crate) no_check: bool,
}

impl RunArgs {
    pub(crate) fn scene(&self) -> clearance_joint::Result<ValidatedScene> {
        let mut overrides = self.overrides.clone();
        overrides.extend(self.time.overrides());
        let scene = cli::load_validated(self.scene.as_deref())?;
        // Given together, an override a later one replaces whole would be lost unsaid.
        scene.refuse_lost_overrides::<&str, _>(&[], &overrides)?;
        scene.with_overrides(&overrides)
    }
}

/// What the convergence check gave: its result, or the error of its own run.
type Check = (Option<Convergence>, Option<clearance_joint::Error>);

/// Runs the scene of `args` (see [`RunArgs`]): the run, its convergence check, the result set
/// written whole, the comparison printed.
pub(crate) fn run(args: &RunArgs) -> clearance_joint::Result<()> {
    let scene = args.scene()?;
    warn(&scene);
    let (dt, max_dt) = (args.time.dt.is_some(), args.time.max_dt.is_some());
    if let Some(note) = cli::unused_step_note(&scene.run, dt, max_dt) {
        eprintln!("note: {note}");
    }
    refuse_nothing_to_check(args, &scene)?;
    let figures = figures_wanted(args, &scene)?;
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out").join(&scene.name));
    let job = SceneRun::prepare(scene, out, args.memory.budget()?, !args.no_replay)?;
    let scene = &job.scene;
    eprintln!(
        "running `{}`: {}, {} s simulated, contact {:?} (`run.contact_integration`), ideal and clearance twins",
        scene.name,
        scene.run.stepping(),
        clearance_joint::error::sig4(scene.run.end_s),
        scene.run.contact_integration
    );
    let mut progress = RunProgress::new(progress_mode(&args.progress));
    let result = job.execute_recorded(|p| progress.update(p), !args.no_replay);
    progress.finish();
    let (mut result, recording) = result?;
    // The convergence check, before the set is written (its summary records the verdict). A
    // check that fails loses nothing: the set is written, then the command fails when the
    // check was asked for (`--check`) or under `--strict`, and warns otherwise.
    let check = check_convergence(args, &job, &result);
    let verdict = verdict(args, &check);
    let (comparison, files, drawn) =
        write_set(&job, &result, recording.as_ref(), figures, &check, &verdict)?;
    let strict = scene.run.strict;
    let out = job.commit()?;
    println!("{comparison}");
    print_convergence(args, &check, &verdict);
    println!(
        "{} steps in {:.2} s wall; wrote {}/{{{}}}",
        result.steps,
        result.wall_s,
        out.display(),
        files.join(", ")
    );
    for p in drawn {
        println!("wrote {}", p.display());
    }
    // A stalled run: its set is written (marked incomplete) and the command fails.
    if let Some(e) = result.stopped.take() {
        return Err(e);
    }
    outcome(args, strict, check)
}

/// Asked to confirm convergence strictly, a scene with nothing to check fails before any run:
/// it could only pass by checking nothing.
fn refuse_nothing_to_check(args: &RunArgs, scene: &ValidatedScene) -> clearance_joint::Result<()> {
    let (true, true, Some(reason)) = (
        args.check,
        scene.run.strict,
        convergence::nothing_to_check(scene),
    ) else {
        return Ok(());
    };
    Err(clearance_joint::Error::invalid(
        "--check",
        format!(
            "nothing to check ({reason}) in scene `{}`: the convergence check compares \
             clearance hinges' metrics at two step controls, so with `--strict` it could only \
             pass by checking nothing; give a hinge a clearance, or drop `--check` (the run \
             then says there is nothing to check) or `--strict`",
            scene.name
        ),
    ))
}

/// Whether to draw the figures (known before the run): an error when asked for (`--figures`)
/// and the scene cannot have them.
fn figures_wanted(args: &RunArgs, scene: &ValidatedScene) -> clearance_joint::Result<bool> {
    match can_draw(scene) {
        Ok(()) => Ok(!args.no_figures),
        Err(e) if args.figures => Err(e),
        Err(e) => {
            if !args.no_figures {
                eprintln!("no figures: {e}");
            }
            Ok(false)
        }
    }
}

/// The convergence check of a complete run, unless `--no-check`.
fn check_convergence(args: &RunArgs, job: &SceneRun, result: &RunResult) -> Check {
    if args.no_check || !result.is_complete() {
        return (None, None);
    }
    let mut progress = RunProgress::new(progress_mode(&args.progress));
    let check = job.check_convergence(result, |p| progress.update(p));
    progress.finish();
    match check {
        Ok(c) => (Some(c), None),
        Err(e) => (None, Some(e)),
    }
}

/// The verdict the summary records.
fn verdict(args: &RunArgs, check: &Check) -> ConvergenceVerdict {
    match check {
        (Some(c), _) => c.verdict(),
        (None, Some(e)) => ConvergenceVerdict::Failed {
            error: e.to_string(),
        },
        (None, None) if args.no_check => ConvergenceVerdict::NotChecked {
            reason: "`--no-check`".into(),
        },
        (None, None) => ConvergenceVerdict::NotChecked {
            reason: "the run did not reach its end".into(),
        },
    }
}

/// Writes the whole set (tables, summary, figures, replay, convergence) to the staging folder;
/// returns the comparison table to print, the data files' names and the figures' and replay's
/// final paths. A figure that cannot be written fails the command; the old set stays whole.
fn write_set(
    job: &SceneRun,
    result: &RunResult,
    recording: Option<&Recording>,
    figures: bool,
    check: &Check,
    verdict: &ConvergenceVerdict,
) -> clearance_joint::Result<(String, Vec<String>, Vec<PathBuf>)> {
    let (scene, dir) = (&job.scene, job.set.dir());
    let summary = clearance_joint_app::summary::write_run(result, dir, verdict)?;
    let mut drawn = Vec::new();
    if figures {
        draw_run_figures(scene, result, dir, |p| drawn.push(job.set.final_path(p)))?;
    }
    if let Some(recording) = recording {
        let path = clearance_joint_app::replay::write_run_replay(scene, result, recording, dir)?;
        drawn.push(job.set.final_path(&path));
    }
    let mut files = job.files(result);
    if let Some(c) = check.0.as_ref().and_then(Convergence::checked) {
        job.write_convergence(c)?;
        files.push("convergence.json".into());
    }
    Ok((comparison_table(&summary), files, drawn))
}

/// Prints the convergence verdict's lines.
fn print_convergence(args: &RunArgs, check: &Check, verdict: &ConvergenceVerdict) {
    match check {
        (Some(Convergence::Checked(c)), _) => println!("{}", cli::run::convergence_lines(c)),
        (Some(Convergence::NothingToCheck { reason }), _) => {
            println!("{}", cli::run::nothing_to_check(reason))
        }
        (None, Some(_)) => println!("convergence: {}", verdict.describe()),
        (None, None) if args.no_check => println!("{}", cli::run::UNCHECKED),
        (None, None) => println!(
            "convergence: not checked: the run did not reach its end, so there is no end to compare"
        ),
    }
}

/// The command's outcome once the set is written: a failed check's run fails it when the check
/// was asked for or under `--strict` (it warns otherwise); under `--strict` a metric beyond its
/// bound fails it.
fn outcome(args: &RunArgs, strict: bool, check: Check) -> clearance_joint::Result<()> {
    let (check, check_failed) = check;
    if let Some(e) = check_failed {
        if args.check || strict {
            eprintln!("the convergence check's run at the tighter step control failed");
            return Err(e);
        }
        eprintln!(
            "WARNING: the convergence check's run at the tighter step control failed, so this \
             run's numbers are unchecked (`--check` or `--strict` make that an error): {e}"
        );
    }
    match &check {
        Some(check) if strict => check.strict(),
        _ => Ok(()),
    }
}
