//! Runs studies end to end: every case in one parallel batch, then per study its metrics table,
//! figures and report, and the summary of `study all`.

use super::case::StudyCase;
use super::grid::Shard;
use super::preset::Study;
use super::report;
use super::sweep::{ExecOptions, Failure, Job, MetricsTable, Sweep, TableRow, execute};
use crate::figures::series::{CaseSeries, StreamedCase};
use crate::figures::{Figure, FigureKind};
use crate::process::files::write_atomic;
use crate::resultset::ResultSet;
use clearance_joint::error::{Error, Result};
use clearance_joint::scene::Scene;
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// Options of a study run.
#[derive(Clone, Debug, Default)]
pub struct StudyOptions {
    /// Parallelism, progress and reuse of finished points.
    pub exec: ExecOptions,
    /// Overrides applied to every case after the study's own (e.g. `run.end_s=0.3` for a quick look).
    pub extra_overrides: Vec<String>,
    /// Skip the figures (faster; the report then has none).
    pub no_figures: bool,
}

/// A finished study: its cases, table, figures and report.
#[derive(Clone, Debug)]
pub struct StudyOutcome {
    /// Which study.
    pub study: Study,
    /// Its folder.
    pub dir: PathBuf,
    /// Cases in axis order.
    pub cases: Vec<StudyCase>,
    /// The metrics table written to `metrics.csv` / `metrics.json`.
    pub table: MetricsTable,
    /// Figure files written (PNG and SVG).
    pub figures: Vec<PathBuf>,
    /// `report.md`.
    pub report: PathBuf,
    /// The report's verdicts on the paper's conclusions (none unless [`Study::paper`]).
    pub conclusions: Vec<report::Conclusion>,
    /// Settings and names the report states.
    pub setup: report::Setup,
}

/// Runs `studies` (presets of `base`, see [`super::preset::select`]) into `root/<name>/`: all
/// their points in one parallel batch (one progress display), then per study the metrics table,
/// figures and `report.md`; with more than one study, also `root/report.md` gathering their key
/// tables and verdicts. Each study's folder is one result set ([`ResultSet`], its `points`
/// carried over so finished cases are reused): while it runs the folder is absent (its points
/// wait in the staging folder `.<name>.new-<pid>`), and it reappears whole. Studies whose cases
/// all finished are written even if another study failed; then the first failure is returned.
/// Refused before anything runs: a case whose settings leave the study's hinge without
/// clearance (nothing to compare or plot).
pub fn run_studies(
    studies: &[Study],
    base: &Scene,
    root: &Path,
    options: &StudyOptions,
) -> Result<Vec<StudyOutcome>> {
    // Every case is built and checked before any folder is touched.
    let mut checked: Vec<(&Study, Sweep)> = Vec::new();
    for study in studies {
        let sweep = study.sweep(base, &options.extra_overrides);
        check_cases(study, &sweep.jobs(Path::new(""), Shard::ALL)?)?;
        checked.push((study, sweep));
    }
    // The summary of an earlier `study all` must not pass for this run's.
    let index_path = root.join("report.md");
    remove_file(&index_path)?;
    let mut plans: Vec<(&Study, ResultSet, Sweep, Vec<Job>)> = Vec::new();
    for (study, sweep) in checked {
        let set = ResultSet::begin(&root.join(study.name()), &["points"])?;
        let jobs = sweep.jobs(set.dir(), Shard::ALL)?;
        plans.push((study, set, sweep, jobs));
    }
    let all_jobs: Vec<Job> = plans.iter().flat_map(|p| p.3.iter().cloned()).collect();
    let mut results = execute(&all_jobs, options.exec)?.into_iter();
    let mut outcomes = Vec::new();
    let mut first_error: Option<Error> = None;
    for (study, set, sweep, jobs) in plans {
        let mut rows = Vec::new();
        let mut cases = Vec::new();
        let mut failures = Vec::new();
        let labels = study.labels();
        for job in &jobs {
            match results.next() {
                Some(Ok(o)) => {
                    rows.push(TableRow {
                        point: o.manifest.point.clone(),
                        dir: format!("points/{}", job.point.dir),
                        metrics: o.manifest.metrics.clone(),
                    });
                    cases.push(StudyCase {
                        label: labels
                            .get(job.point.index)
                            .cloned()
                            .unwrap_or_else(|| job.point.dir.clone()),
                        value: job.point.assignments[0].1.clone(),
                        scene: job.scene.scene().clone(),
                        metrics: o.manifest.metrics,
                        dir: job.dir.clone(),
                        reused: o.reused,
                    });
                }
                Some(Err(e)) => {
                    failures.push(Failure {
                        point: job.point.clone(),
                        error: e.to_string(),
                    });
                    eprintln!(
                        "study {}: case `{}` failed: {e}",
                        study.name(),
                        job.point.dir
                    );
                    first_error.get_or_insert(e);
                }
                None => {
                    return Err(Error::invalid("study", "a case has no result"));
                }
            }
        }
        let table = MetricsTable {
            sweep: sweep.info(),
            shard: None,
            rows,
            failures,
            missing: Vec::new(),
        };
        table.write(set.dir())?;
        if !table.failures.is_empty() {
            // An incomplete study: its points and the table listing the failures, no report.
            set.commit()?;
            continue;
        }
        outcomes.push(finish_study(study, set, &sweep, cases, table, options)?);
    }
    if outcomes.len() > 1 {
        let entries: Vec<report::IndexEntry> = outcomes
            .iter()
            .map(|o| report::IndexEntry {
                study: &o.study,
                setup: &o.setup,
                cases: &o.cases,
                conclusions: &o.conclusions,
            })
            .collect();
        let index = report::index_report(&entries);
        write_atomic(&index_path, index.as_bytes())?;
    }
    match first_error {
        Some(e) => Err(e),
        None => Ok(outcomes),
    }
}

/// Refuses a study one of whose cases has no clearance at the hinge it shows (its `set`, a
/// `--set` or its own value made the hinge ideal): there is nothing to compare or plot.
fn check_cases(study: &Study, jobs: &[Job]) -> Result<()> {
    for job in jobs {
        let hinge = job.scene.hinges.iter().find(|h| h.name == study.hinge);
        if hinge.is_none_or(|h| h.clearance.is_none()) {
            return Err(Error::invalid(
                format!("study {}", study.name()),
                format!(
                    "case `{}` leaves hinge `{}` without clearance ({}): a study compares a clearance hinge \
                     with its ideal twin, so it would have nothing to compare or plot; drop the setting that \
                     makes it ideal (`clearance=null` in the preset's `set` or a `--set`)",
                    job.point.dir,
                    study.hinge,
                    if hinge.is_none() {
                        "no such hinge"
                    } else {
                        "an ideal hinge"
                    }
                ),
            ));
        }
    }
    Ok(())
}

fn remove_file(path: &Path) -> Result<()> {
    match std::fs::remove_file(path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(Error::Io {
            action: "cannot remove",
            path: path.to_path_buf(),
            source: e,
        }),
        _ => Ok(()),
    }
}

/// Figures and report of a study whose cases all finished, written into its set, which is
/// then put in place.
fn finish_study(
    study: &Study,
    set: ResultSet,
    sweep: &Sweep,
    mut cases: Vec<StudyCase>,
    table: MetricsTable,
    options: &StudyOptions,
) -> Result<StudyOutcome> {
    let dir = set.dir().to_path_buf();
    let mut figures = Vec::new();
    let mut figure_stems = Vec::new();
    // One case at a time per worker, each read in one pass and kept reduced: the memory of this
    // step stays below that of the runs, whatever the number of cases.
    let streamed: Vec<StreamedCase> = cases
        .par_iter()
        .map(|c| CaseSeries::stream(c.label.clone(), &c.scene, &study.hinge, &c.dir))
        .collect::<Result<_>>()?;
    let timeline = report::Timeline::of_onsets(
        &streamed
            .iter()
            .map(|c| {
                (
                    c.onsets_s.clone(),
                    c.series.t_s.last().copied().unwrap_or(0.0),
                )
            })
            .collect::<Vec<_>>(),
    );
    let series: Vec<CaseSeries> = streamed.into_iter().map(|c| c.series).collect();
    if !options.no_figures {
        let nums = study.paper_figures();
        let titles: Vec<String> = FigureKind::ALL
            .iter()
            .enumerate()
            .map(|(i, f)| {
                let what = match f {
                    FigureKind::AnglesRates => "angles and angular rates, clearance vs ideal joint",
                    FigureKind::Force => "joint reaction force, ideal vs clearance joint",
                    FigureKind::Trajectory => {
                        "journal-centre trajectory inside the clearance circle"
                    }
                };
                match nums {
                    Some(n) => format!("{} study: {what} (paper fig. {})", study.name(), n[i]),
                    None => format!("{} study: {what}", study.name()),
                }
            })
            .collect();
        // A figure that cannot be written fails the study; its old set stays as it was.
        let written: Vec<[PathBuf; 2]> = FigureKind::ALL
            .par_iter()
            .zip(titles.par_iter())
            .map(|(&f, title)| {
                Figure {
                    kind: f,
                    title,
                    cases: &series,
                }
                .write(&dir, f.stem())
            })
            .collect::<Result<_>>()?;
        for (f, paths) in FigureKind::ALL.iter().zip(written) {
            figure_stems.push((*f, f.stem().to_string()));
            figures.extend(paths.iter().map(|p| set.final_path(p)));
        }
    }
    let setup = report::Setup::of(study, sweep, &cases);
    // The paper's conclusions are about its scene and its three studies only.
    let conclusions = if study.paper {
        report::conclusions(study, &cases, Some(&timeline))
    } else {
        Vec::new()
    };
    let text = report::study_report(
        study,
        &setup,
        &cases,
        &figure_stems,
        &conclusions,
        Some(&timeline),
    );
    let text = text + &crate::replay::report_section(&dir, &cases);
    write_atomic(&dir.join("report.md"), text.as_bytes())?;
    for c in &mut cases {
        c.dir = set.final_path(&c.dir);
    }
    let dir = set.commit()?;
    let report_path = dir.join("report.md");
    Ok(StudyOutcome {
        study: study.clone(),
        dir,
        cases,
        table,
        figures,
        report: report_path,
        conclusions,
        setup,
    })
}
