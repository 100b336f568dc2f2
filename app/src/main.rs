//! Command-line front end: parses arguments, runs, prints. The work is in the library.

use clap::{Args, Parser, Subcommand};
use clearance_joint::scene::output::{DirLock, MemoryEstimate};
use clearance_joint::scene::report::comparison_table;
use clearance_joint::scene::runner::{RunOptions, Simulation};
use clearance_joint::scene::{Scene, StepMode};
use clearance_joint_app::progress::RunProgress;
use clearance_joint_app::study::sweep::{self, ExecOptions, MetricsTable, Progress, Sweep};
use clearance_joint_app::study::{Axis, Grid, Shard, StudyKind, StudyOptions, run_studies};
use std::path::{Path, PathBuf};
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
    /// Run the paper's studies with figures and reports: clearance, torque, friction or all.
    Study(StudyArgs),
    /// Gather the metrics tables of a sharded sweep into one.
    Merge(MergeArgs),
}

/// Parallelism and progress, shared by `sweep` and `study`.
#[derive(Args, Debug, Clone, Default)]
struct ExecArgs {
    /// Worker threads; default one per core (or RAYON_NUM_THREADS), at most one per core.
    #[arg(long)]
    jobs: Option<usize>,
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
    /// The options, with the thread count capped at the cores (saying so) and used for the
    /// global pool too (figures), so no setting spawns thousands of threads.
    fn options(&self) -> clearance_joint::Result<ExecOptions> {
        let requested = self.jobs.or_else(|| {
            std::env::var("RAYON_NUM_THREADS")
                .ok()
                .and_then(|v| v.trim().parse().ok())
                .filter(|&n: &usize| n > 0)
        });
        let (threads, note) = sweep::thread_count(requested)?;
        if let Some(note) = note {
            eprintln!("note: {note}");
        }
        let _ = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build_global();
        Ok(ExecOptions {
            progress: progress_mode(&self.progress),
            threads: Some(threads),
            rerun: self.rerun,
            max_memory: self.memory.budget()?,
        })
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
    #[arg(long, value_name = "SIZE")]
    max_memory: Option<String>,
}

impl MemoryArgs {
    fn budget(&self) -> clearance_joint::Result<Option<u64>> {
        self.max_memory
            .as_deref()
            .map(clearance_joint::scene::output::parse_bytes)
            .transpose()
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
    #[command(flatten)]
    exec: ExecArgs,
}

/// `study NAME`.
#[derive(Args, Debug, Clone)]
struct StudyArgs {
    /// clearance, torque, friction or all.
    #[arg(value_parser = ["clearance", "torque", "friction", "all"])]
    name: String,
    /// Scene file (RON); default: the paper's solar-panel scene. The presets set
    /// `hinge.*` and `drive.*`: the scene must name its clearance hinge `hinge` and its drive `drive`.
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
}

impl RunArgs {
    fn scene(&self) -> clearance_joint::Result<Scene> {
        let mut overrides = self.overrides.clone();
        overrides.extend(self.time.overrides());
        base_scene(&self.scene)?.with_overrides(&overrides)
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
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out").join(&scene.name));
    if let Some(budget) = args
        .memory
        .budget()?
        .or_else(clearance_joint::scene::output::available_memory)
    {
        MemoryEstimate::of(&scene).check(&scene, 1, budget)?;
    }
    // Before any work: the folder exists, is writable and is ours alone until the set is written.
    let _lock = DirLock::acquire(&out)?;
    eprintln!(
        "running `{}`: {}, {} s simulated, ideal and clearance twins",
        scene.name,
        scene.run.stepping(),
        clearance_joint::error::sig4(scene.run.end_s)
    );
    let mut progress = RunProgress::new(progress_mode(&args.progress));
    let result = Simulation::new(&scene, RunOptions::default())?
        .run_with_progress(|p| progress.update(p))
        .map_err(|e| e.with_step_mode(scene.run.step == StepMode::Adaptive));
    progress.finish();
    let result = result?;
    let summary = result.write(&out)?;
    println!("{}", comparison_table(&summary));
    let mut files = vec!["ideal.csv".to_string(), "clearance.csv".to_string()];
    for t in &result.twins {
        for h in t.clearance_hinges() {
            files.push(format!("{}_{h}_impacts.csv", t.kind.name()));
            if scene.drive_period().is_some() {
                files.push(format!("{}_{h}_turns.csv", t.kind.name()));
            }
        }
    }
    files.push("summary.json".into());
    println!(
        "{} steps in {:.2} s wall; wrote {}/{{{}}}",
        result.steps,
        result.wall_s,
        out.display(),
        files.join(", ")
    );
    if !args.no_figures {
        let drawn = (|| -> clearance_joint::Result<()> {
            use clearance_joint::scene::runner::TwinKind;
            use clearance_joint_app::figures::series::CaseSeries;
            use clearance_joint_app::figures::{Figure, FigureKind};
            let (Some(ideal), Some(clear)) = (
                result.twin(TwinKind::Ideal),
                result.twin(TwinKind::Clearance),
            ) else {
                return Err(clearance_joint::Error::invalid(
                    "--figures",
                    "needs both twins",
                ));
            };
            let series = [CaseSeries::from_tables(
                scene.name.clone(),
                &scene,
                &ideal.table,
                &clear.table,
            )?];
            // Driven mechanisms: each moving body's x acceleration against the driver's angle over
            // the last turn, ideal against clearance.
            if let (Some(period), true) = (scene.drive_period(), scene.run.body_motion) {
                use clearance_joint::scene::MotionSpec;
                let driver = scene
                    .bodies
                    .iter()
                    .find(|b| matches!(b.motion, Some(MotionSpec::Spin { .. })))
                    .map(|b| b.name.clone())
                    .or_else(|| {
                        scene
                            .joints
                            .iter()
                            .find(|j| j.motor.is_some())
                            .map(|j| j.body2.clone())
                    });
                let end = scene.run.end_s;
                for b in scene
                    .bodies
                    .iter()
                    .filter(|b| !b.fixed && b.motion.is_none())
                {
                    let (Some(driver), true) = (&driver, end >= period * (1.0 - 1e-9)) else {
                        continue;
                    };
                    let column = format!("{}_ax_m_s2", b.name);
                    let curve = |label: &str, t: &clearance_joint::table::Table| {
                        let (Some(ts), Some(angle), Some(a)) = (
                            t.column("t_s"),
                            t.column(&format!("{driver}_angle_deg")),
                            t.column(&column),
                        ) else {
                            return None;
                        };
                        let first = ts.iter().position(|&x| x >= end - period)?;
                        let points = (first..ts.len())
                            .map(|i| (angle[i] - angle[first], a[i]))
                            .collect();
                        Some((label.to_string(), points))
                    };
                    let curves: Vec<(String, Vec<(f64, f64)>)> = [
                        curve("ideal", &ideal.table),
                        curve("clearance", &clear.table),
                    ]
                    .into_iter()
                    .flatten()
                    .collect();
                    if curves.is_empty() {
                        continue;
                    }
                    let title = format!(
                        "{}: {} acceleration along x over the last turn of {driver}",
                        scene.name, b.name
                    );
                    let x_label = format!("{driver} angle from the turn's start (deg)");
                    let paths = clearance_joint_app::figures::XyFigure {
                        title: &title,
                        x_label: &x_label,
                        y_label: "acceleration along x (m/s^2)",
                        curves: &curves,
                    }
                    .write(&out, &format!("{}_acceleration", b.name))?;
                    for p in paths {
                        println!("wrote {}", p.display());
                    }
                }
            }
            for kind in FigureKind::ALL {
                let title = format!("{}: {}", scene.name, kind.stem().replace('_', " "));
                let paths = Figure {
                    kind,
                    title: &title,
                    cases: &series,
                }
                .write(&out, kind.stem())?;
                for p in paths {
                    println!("wrote {}", p.display());
                }
            }
            Ok(())
        })();
        match drawn {
            Err(e) if !args.figures => eprintln!("no figures: {e}"),
            other => other?,
        }
    }
    Ok(())
}

fn base_scene(path: &Option<PathBuf>) -> clearance_joint::Result<Scene> {
    match path {
        Some(p) => Scene::load(p),
        None => Ok(Scene::solar_panel()),
    }
}

fn sweep(args: &SweepArgs) -> clearance_joint::Result<()> {
    let base = base_scene(&args.scene)?;
    warn(&base);
    let exec = args.exec.options()?;
    let axes = args
        .axes
        .iter()
        .map(|a| Axis::parse(a))
        .collect::<clearance_joint::Result<Vec<_>>>()?;
    let fixed = args.time.overrides();
    let shard = match &args.shard {
        Some(s) => Shard::parse(s)?,
        None => Shard::ALL,
    };
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out/sweep"));
    let sweep = Sweep::new("sweep", base, fixed, Grid::new(axes)?);
    // Claim this shard's table (and check the folder) before any point runs; the points claim
    // their own folders, so shards of one sweep can share it.
    let stem = if shard.is_all() {
        "metrics".to_string()
    } else {
        format!("metrics.shard-{}-of-{}", shard.index(), shard.count())
    };
    let _lock = DirLock::acquire_named(&out, &format!(".{stem}.lock"))?;
    let n = shard.points(&sweep.grid).len();
    eprintln!(
        "sweep of {} points{}: {n} to run or reuse, into {}",
        sweep.grid.len(),
        if shard.is_all() {
            String::new()
        } else {
            format!(" (shard {shard})")
        },
        out.display()
    );
    let start = Instant::now();
    let outcome = sweep.run(&out, shard, exec)?;
    let reused = outcome.points.iter().filter(|p| p.reused).count();
    println!(
        "{} points finished ({} run, {reused} reused), {} failed, in {:.2} s; table {}",
        outcome.points.len(),
        outcome.points.len() - reused,
        outcome.table.failures.len(),
        start.elapsed().as_secs_f64(),
        out.join(format!("{}.csv", outcome.table.stem())).display()
    );
    fail_on_failures(&outcome.table)
}

fn fail_on_failures(table: &MetricsTable) -> clearance_joint::Result<()> {
    for f in &table.failures {
        eprintln!("point `{}` failed: {}", f.point.dir, f.error);
    }
    match table.failures.len() {
        0 => Ok(()),
        n => Err(clearance_joint::Error::invalid(
            "sweep",
            format!(
                "{n} point(s) failed (listed above and in the table's `failures`); fix the cause and run again: finished points are reused"
            ),
        )),
    }
}

fn study(args: &StudyArgs) -> clearance_joint::Result<()> {
    let base = base_scene(&args.scene)?;
    clearance_joint_app::study::preset::check_names(&base)?;
    warn(&base);
    let kinds: Vec<StudyKind> = if args.name == "all" {
        StudyKind::ALL.to_vec()
    } else {
        vec![StudyKind::parse(&args.name)?]
    };
    let root = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out/studies"));
    let options = StudyOptions {
        exec: args.exec.options()?,
        extra_overrides: args.overrides.clone(),
        no_figures: args.no_figures,
    };
    let start = Instant::now();
    let outcomes = run_studies(&kinds, &base, &root, &options)?;
    for o in &outcomes {
        println!("{} study -> {}", o.kind.name(), o.report.display());
        for c in &o.cases {
            let h = c.metrics.hinges.values().find(|h| h.clearance_mm > 0.0);
            if let Some(h) = h {
                println!(
                    "  {:<22} impacts {:>5}  peak force {:>9.3} N  RMS force {:>7.3} N  final hinge angle {:>8.3} deg (ideal {:>8.3}){}",
                    c.label,
                    h.impacts,
                    h.peak_force_n,
                    h.rms_force_n,
                    h.final_angle_deg,
                    h.final_angle_ideal_deg,
                    if c.reused { "  [reused]" } else { "" }
                );
            }
        }
        for c in &o.conclusions {
            if c.verdict != clearance_joint_app::study::report::Verdict::NotTested {
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
    let mut files = Vec::new();
    for input in &args.inputs {
        if input.is_dir() {
            let found = sweep::shard_tables_in(input)?;
            if found.is_empty() {
                return Err(clearance_joint::Error::invalid(
                    format!("merge input `{}`", input.display()),
                    "holds no shard table (metrics.shard-K-of-N.json)",
                ));
            }
            files.extend(found);
        } else {
            files.push(input.clone());
        }
    }
    let tables = files
        .iter()
        .map(|f| MetricsTable::load(f))
        .collect::<clearance_joint::Result<Vec<_>>>()?;
    let merged = sweep::merge(&tables)?;
    if !merged.missing.is_empty() && !args.incomplete {
        return Err(clearance_joint::Error::invalid(
            "merge",
            format!(
                "points {:?} are in no table, so nothing was written: run their shards (point i belongs to \
                 shard i % N), or pass --incomplete to write metrics.incomplete.{{csv,json}} listing them",
                merged.missing
            ),
        ));
    }
    let out = match &args.out {
        Some(o) => o.clone(),
        None => {
            let first = &args.inputs[0];
            if first.is_dir() {
                first.clone()
            } else {
                first.parent().unwrap_or(Path::new(".")).to_path_buf()
            }
        }
    };
    let stem = if merged.missing.is_empty() {
        "metrics"
    } else {
        "metrics.incomplete"
    };
    merged.write_named(&out, stem)?;
    println!(
        "merged {} table(s): {} of {} points, {} failed, {} missing -> {}",
        tables.len(),
        merged.rows.len(),
        merged.sweep.points,
        merged.failures.len(),
        merged.missing.len(),
        out.join(format!("{stem}.csv")).display()
    );
    if !merged.missing.is_empty() {
        return Err(clearance_joint::Error::invalid(
            "merge",
            format!(
                "points {:?} are in no table: run their shards (a point i belongs to shard i % N)",
                merged.missing
            ),
        ));
    }
    fail_on_failures(&merged)
}

fn main() -> ExitCode {
    // Ctrl-C (or a kill with SIGTERM/SIGHUP): remove our temporaries and lock files, then exit.
    // A set being renamed into place is finished first; finished points of a sweep stay.
    if let Err(e) = ctrlc::set_handler(|| {
        clearance_joint::scene::output::remove_inflight();
        eprintln!("\ninterrupted: temporary files removed");
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
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
