//! The command line: parses arguments, calls the app library (`clearance_joint_app::cli` and
//! `study`), prints what it returns, and sets the exit code.

use clap::{Args, Parser, Subcommand};
use clearance_joint::scene::report::comparison_table;
use clearance_joint::scene::runner::convergence::{self, Convergence, ConvergenceVerdict};
use clearance_joint::scene::{Scene, ValidatedScene};
use clearance_joint_app::cli::{self, merge::Merged, run::SceneRun, sweep::SweepJob};
use clearance_joint_app::figures::run::{can_draw, draw_run_figures};
use clearance_joint_app::progress::RunProgress;
use clearance_joint_app::study::report::Verdict;
use clearance_joint_app::study::sweep::{ExecOptions, MetricsTable, Progress};
use clearance_joint_app::study::{StudyOptions, run_studies, select};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

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

/// Parallelism and progress, shared by `sweep` and `study`.
#[derive(Args, Debug, Clone, Default)]
struct ExecArgs {
    /// Worker threads; default one per core (or RAYON_NUM_THREADS), at most one per core.
    #[arg(long, allow_hyphen_values = true)]
    jobs: Option<i64>,
    #[command(flatten)]
    memory: MemoryArgs,
    /// Recompute every point, even those finished by an earlier run.
    #[arg(long)]
    rerun: bool,
    /// Progress: auto (a bar on a terminal, lines otherwise), bar, lines or quiet.
    #[arg(long, default_value = "auto", value_parser = ["auto", "bar", "lines", "quiet"])]
    progress: String,
}

impl ExecArgs {
    /// The options (saying so when the thread count was capped at the cores).
    fn options(&self) -> clearance_joint::Result<ExecOptions> {
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

fn progress_mode(name: &str) -> Progress {
    match name {
        "bar" => Progress::Bar,
        "lines" => Progress::Lines,
        "quiet" => Progress::Quiet,
        _ => Progress::Auto,
    }
}

/// The memory budget, shared by every command that runs.
#[derive(Args, Debug, Clone, Default)]
struct MemoryArgs {
    /// Memory the runs may hold (e.g. 4G, 512M, 2GiB); default 80 % of what the system has
    /// available. A run that would need more is refused before it starts.
    #[arg(long, value_name = "SIZE", allow_hyphen_values = true)]
    max_memory: Option<String>,
}

impl MemoryArgs {
    fn budget(&self) -> clearance_joint::Result<Option<u64>> {
        cli::memory_budget(self.max_memory.as_deref())
    }
}

/// `sweep`: every `--set` is an axis of the grid.
#[derive(Args, Debug, Clone)]
struct SweepArgs {
    /// Scene file (RON); default: the paper's solar-panel scene.
    #[arg(long)]
    scene: Option<PathBuf>,
    /// A swept parameter and its values: `--set hinge.clearance_mm=0.1,0.25,0.5` (repeatable;
    /// the grid is the product, the first `--set` varying slowest). One value fixes a parameter.
    #[arg(long = "set", value_name = "PATH=V1,V2,...")]
    axes: Vec<String>,
    #[command(flatten)]
    time: TimeArgs,
    /// Output folder; default `out/sweep`.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Run only the points with index % N == K (K from 0): `--shard 0/4` ... `--shard 3/4`.
    #[arg(long, value_name = "K/N")]
    shard: Option<String>,
    /// Write each point's replay (`points/<dir>/replay.html`, the table's `dir`); off by default.
    #[arg(long)]
    replay: bool,
    /// Check each point's convergence (off by default for a sweep, whose points are many): the
    /// point again at half its tolerance, the clearance twin only; the verdict in the point's
    /// `summary.json`, the table's `convergence` (JSON) and `not_converged` (CSV).
    #[arg(long)]
    check: bool,
    #[command(flatten)]
    exec: ExecArgs,
}

/// `study NAME`.
#[derive(Args, Debug, Clone)]
struct StudyArgs {
    /// The preset's name, as the scene's `studies` declare it (the paper's scene: clearance,
    /// torque, friction), or all.
    name: String,
    /// Scene file (RON); default: the paper's solar-panel scene. Its `studies` declare the
    /// presets; a scene declaring none gets the paper's, which set `hinge.*` and `drive.*` and so
    /// need a clearance hinge named `hinge` and a drive named `drive`.
    #[arg(long)]
    scene: Option<PathBuf>,
    /// Override a parameter in every case, after the study's own settings (repeatable),
    /// e.g. `--set run.end_s=1` for a quick look.
    #[arg(long = "set", value_name = "PATH=VALUE")]
    overrides: Vec<String>,
    /// Root folder; each study writes into `<out>/<name>/`. Default `out/studies`.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Skip the figures.
    #[arg(long)]
    no_figures: bool,
    /// Fail (exit code 1) when a case leaves the model's validity (a run-time guard; same as
    /// `--set run.strict=true`): the case fails and the study writes no report. Without it
    /// they are warnings in each case's `summary.json` and in the metrics table.
    #[arg(long)]
    strict: bool,
    /// Skip the replays (each case's `replay.html`, linked from the report; written by default).
    #[arg(long)]
    no_replay: bool,
    /// Skip the convergence check of each case (by default each case runs again at half its
    /// tolerance, the clearance twin only, and the report says per case which metrics
    /// converged; on `study all` the checks take about as long as the runs).
    #[arg(long)]
    no_check: bool,
    #[command(flatten)]
    exec: ExecArgs,
}

/// `merge`: shard tables in, one table out.
#[derive(Args, Debug, Clone)]
struct MergeArgs {
    /// Sweep folders (their `metrics.shard-*.json` are read) or shard table files.
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    /// Folder for the merged `metrics.csv` and `metrics.json`; default: the first input folder.
    #[arg(long)]
    out: Option<PathBuf>,
    /// With points missing (a shard not run), write `metrics.incomplete.{csv,json}` listing
    /// them instead of refusing; `metrics.csv` is only ever written for a whole grid.
    #[arg(long)]
    incomplete: bool,
}

/// The run-settings shortcuts shared by `run` and `sweep` (for a sweep, they hold for every point).
#[derive(Args, Debug, Clone, Default)]
struct TimeArgs {
    /// Fixed step, s (same as `--set run.dt_s=...`).
    #[arg(long, allow_hyphen_values = true)]
    dt: Option<f64>,
    /// Adaptive steps: the largest step, s (`run.max_dt_s`).
    #[arg(long, allow_hyphen_values = true)]
    max_dt: Option<f64>,
    /// Fail the run (exit code 1) when a run-time guard is violated: a penetration beyond the
    /// contact law's validity, energy gained, steps at the floor, a fixed step longer than
    /// friction's limit (`run.strict`). Without it they are warnings on the console and in
    /// `summary.json`'s `guards`.
    #[arg(long)]
    strict: bool,
    /// Simulated time, s.
    #[arg(long, allow_hyphen_values = true)]
    end: Option<f64>,
    /// Interval between CSV rows, s.
    #[arg(long, allow_hyphen_values = true)]
    output_interval: Option<f64>,
}

impl TimeArgs {
    /// The options as `--set` overrides.
    fn overrides(&self) -> Vec<String> {
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

/// Scene selection and overrides shared by the commands.
#[derive(Args, Debug, Clone, Default)]
struct RunArgs {
    /// Scene file (RON); default: the paper's solar-panel scene.
    #[arg(long)]
    scene: Option<PathBuf>,
    /// Override a parameter: `--set hinge.clearance_mm=0.25` (repeatable).
    #[arg(long = "set", value_name = "PATH=VALUE")]
    overrides: Vec<String>,
    #[command(flatten)]
    time: TimeArgs,
    /// Output folder; default `out/<scene name>`.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Progress of a long run: auto (a bar on a terminal once the run has taken 2 s, nothing
    /// otherwise), bar, lines or quiet.
    #[arg(long, default_value = "auto", value_parser = ["auto", "bar", "lines", "quiet"])]
    progress: String,
    #[command(flatten)]
    memory: MemoryArgs,
    /// Draw the figures (the default): angles and rates, joint force, journal orbit of the first
    /// clearance hinge, PNG and SVG, into the output folder after the result set. With this flag a
    /// scene that cannot have them is an error; without it such a scene just has none.
    #[arg(long, conflicts_with = "no_figures")]
    figures: bool,
    /// Skip the figures.
    #[arg(long)]
    no_figures: bool,
    /// Skip the replay (`replay.html`: the run in 3D with the journal magnified in its bearing,
    /// written beside the CSVs by default).
    #[arg(long)]
    no_replay: bool,
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
    check: bool,
    /// Skip the convergence check (on the paper's scene the command then takes about 2/3 of the
    /// time); the summary says the run was not checked.
    #[arg(long)]
    no_check: bool,
}

impl RunArgs {
    fn scene(&self) -> clearance_joint::Result<ValidatedScene> {
        let mut overrides = self.overrides.clone();
        overrides.extend(self.time.overrides());
        let scene = cli::load_validated(self.scene.as_deref())?;
        // Given together, an override a later one replaces whole would be lost unsaid.
        scene.refuse_lost_overrides::<&str, _>(&[], &overrides)?;
        scene.with_overrides(&overrides)
    }
}

fn warn(scene: &Scene) {
    for w in scene.warnings() {
        eprintln!("warning: {w}");
    }
}

fn run(args: &RunArgs) -> clearance_joint::Result<()> {
    let scene = args.scene()?;
    warn(&scene);
    let (dt, max_dt) = (args.time.dt.is_some(), args.time.max_dt.is_some());
    if let Some(note) = cli::unused_step_note(&scene.run, dt, max_dt) {
        eprintln!("note: {note}");
    }
    // Asked to confirm convergence strictly, a scene with nothing to check fails before any
    // run: it could only pass by checking nothing.
    if let (true, true, Some(reason)) = (
        args.check,
        scene.run.strict,
        convergence::nothing_to_check(&scene),
    ) {
        return Err(clearance_joint::Error::invalid(
            "--check",
            format!(
                "nothing to check ({reason}) in scene `{}`: the convergence check compares \
                 clearance hinges' metrics at two step controls, so with `--strict` it could only \
                 pass by checking nothing; give a hinge a clearance, or drop `--check` (the run \
                 then says there is nothing to check) or `--strict`",
                scene.name
            ),
        ));
    }
    // Whether the figures can be drawn is known before the run.
    let figures = match can_draw(&scene) {
        Ok(()) => !args.no_figures,
        Err(e) if args.figures => return Err(e),
        Err(e) => {
            if !args.no_figures {
                eprintln!("no figures: {e}");
            }
            false
        }
    };
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out").join(&scene.name));
    let job = SceneRun::prepare(scene, out, args.memory.budget()?, !args.no_replay)?;
    let scene = &job.scene;
    eprintln!(
        "running `{}`: {}, {} s simulated, ideal and clearance twins",
        scene.name,
        scene.run.stepping(),
        clearance_joint::error::sig4(scene.run.end_s)
    );
    let mut progress = RunProgress::new(progress_mode(&args.progress));
    let result = job.execute_recorded(|p| progress.update(p), !args.no_replay);
    progress.finish();
    let (mut result, recording) = result?;
    // The convergence check, before the set is written (its summary records the verdict). A
    // check that fails loses nothing: the set is written, then the command fails when the
    // check was asked for (`--check`) or under `--strict`, and warns otherwise.
    let (check, check_failed) = match (args.no_check, result.is_complete()) {
        (true, _) => (None, None),
        (false, true) => {
            let mut progress = RunProgress::new(progress_mode(&args.progress));
            let check = job.check_convergence(&result, |p| progress.update(p));
            progress.finish();
            match check {
                Ok(c) => (Some(c), None),
                Err(e) => (None, Some(e)),
            }
        }
        (false, false) => (None, None),
    };
    let verdict = match (&check, &check_failed) {
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
    };
    // The whole set (tables, summary, figures, replay) goes to the staging folder, then into
    // place.
    let summary = clearance_joint_app::summary::write_run(&result, job.set.dir(), &verdict)?;
    let mut drawn = Vec::new();
    if figures {
        // A figure that cannot be written fails the command; the old set stays whole.
        draw_run_figures(scene, &result, job.set.dir(), |p| {
            drawn.push(job.set.final_path(p))
        })?;
    }
    if let Some(recording) = &recording {
        let path = clearance_joint_app::replay::write_run_replay(
            scene,
            &result,
            recording,
            job.set.dir(),
        )?;
        drawn.push(job.set.final_path(&path));
    }
    let mut files = job.files(&result);
    if let Some(c) = check.as_ref().and_then(Convergence::checked) {
        job.write_convergence(c)?;
        files.push("convergence.json".into());
    }
    let strict = scene.run.strict;
    let out = job.commit()?;
    println!("{}", comparison_table(&summary));
    match (&check, &check_failed) {
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

fn sweep(args: &SweepArgs) -> clearance_joint::Result<()> {
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

fn fail_on_failures(table: &MetricsTable) -> clearance_joint::Result<()> {
    for f in &table.failures {
        eprintln!("point `{}` failed: {}", f.point.dir, f.error);
    }
    cli::sweep::check_failures(table)
}

fn study(args: &StudyArgs) -> clearance_joint::Result<()> {
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

fn merge(args: &MergeArgs) -> clearance_joint::Result<()> {
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
        Some(Command::Run(a)) => run(a),
        Some(Command::Sweep(a)) => sweep(a),
        Some(Command::Study(a)) => study(a),
        Some(Command::Merge(a)) => merge(a),
        None => run(&cli.run),
    };
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", clearance_joint_app::advice::describe(&e));
            ExitCode::FAILURE
        }
    }
}
