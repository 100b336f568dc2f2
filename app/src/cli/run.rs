//! The `run` command (and the default job): one scene's ideal and clearance twins, run into a
//! result set (data and figures, one unit: see [`crate::resultset`]) for a folder claimed for it.

use crate::process::files::write_atomic;
use crate::process::memory::available_memory;
use crate::resultset::ResultSet;
use clearance_joint::error::Result;
use clearance_joint::scene::runner::convergence::{self, Convergence, ConvergenceCheck};
use clearance_joint::scene::runner::{Progress, RunOptions, RunResult, Simulation};
use clearance_joint::scene::{StepMode, ValidatedScene};
use std::path::PathBuf;

/// A run ready to go: its memory checked and its output folder claimed (until dropped).
#[derive(Debug)]
pub struct SceneRun {
    /// The scene, overrides applied, checked.
    pub scene: ValidatedScene,
    /// The output folder.
    pub out: PathBuf,
    /// The result set: every file of the run goes into [`ResultSet::dir`], and
    /// [`SceneRun::commit`] puts them in `out` together.
    pub set: ResultSet,
}

impl SceneRun {
    /// Before any work: the run, with its replay when `replay`, fits `max_memory` (default:
    /// what the system has available), and the folder is ours alone until the set is in place,
    /// its staging folder writable.
    pub fn prepare(
        scene: ValidatedScene,
        out: PathBuf,
        max_memory: Option<u64>,
        replay: bool,
    ) -> Result<SceneRun> {
        if let Some(budget) = max_memory.or_else(available_memory) {
            let estimate = crate::replay::estimate(&scene, replay);
            estimate
                .check(&scene, 1, budget)
                .map_err(|e| crate::advice::memory_options(e, &estimate, &scene, 1, budget))?;
        }
        let set = ResultSet::begin(&out, &[])?;
        Ok(SceneRun { scene, out, set })
    }

    /// Puts the set written into [`ResultSet::dir`] in place in `out`, replacing the old one whole.
    pub fn commit(self) -> Result<PathBuf> {
        self.set.commit()
    }

    /// Runs both twins, calling `progress` after every step; a step-size error advises for the
    /// scene's step mode. A run the step control stalls returns what it computed up to the
    /// stall ([`RunResult::stopped`] holds the error): write it, then fail.
    pub fn execute(&self, progress: impl FnMut(&Progress)) -> Result<RunResult> {
        Simulation::from_validated(&self.scene, RunOptions::default())?
            .run_keeping_partial(progress)
            .map_err(|e| e.with_step_mode(self.scene.run.step == StepMode::Adaptive))
    }

    /// As [`execute`](Self::execute), also recording the replay when `replay` (see
    /// [`crate::replay`]).
    pub fn execute_recorded(
        &self,
        progress: impl FnMut(&Progress),
        replay: bool,
    ) -> Result<(RunResult, Option<crate::replay::record::Recording>)> {
        crate::replay::run_recorded(&self.scene, progress, replay)
            .map_err(|e| e.with_step_mode(self.scene.run.step == StepMode::Adaptive))
    }

    /// The convergence check (the default; `--no-check` skips it): the library's
    /// [`convergence::check`], the scene again at half its tolerance (half its fixed step), the
    /// clearance twin only, compared with `result`'s; nothing to check, and no second run, for
    /// a scene without a clearance hinge.
    pub fn check_convergence(
        &self,
        result: &RunResult,
        progress: impl FnMut(&Progress),
    ) -> Result<Convergence> {
        convergence::check(&self.scene, result, progress)
    }

    /// Writes `check` as `convergence.json` into the result set.
    pub fn write_convergence(&self, check: &ConvergenceCheck) -> Result<()> {
        let json = serde_json::to_string_pretty(check)
            .map_err(|e| clearance_joint::Error::invalid("convergence", e.to_string()))?;
        write_atomic(&self.set.dir().join("convergence.json"), json.as_bytes())
    }

    /// The files `result` writes (see [`RunResult::write`]), in the order they are listed.
    pub fn files(&self, result: &RunResult) -> Vec<String> {
        let mut files = vec!["ideal.csv".to_string(), "clearance.csv".to_string()];
        for t in &result.twins {
            for h in t.clearance_hinges() {
                files.push(format!("{}_{h}_impacts.csv", t.kind.name()));
                if self.scene.drive_period().is_some() {
                    files.push(format!("{}_{h}_turns.csv", t.kind.name()));
                }
            }
        }
        files.push("summary.json".into());
        files
    }
}

/// What the console says of a run with `--no-check`: its numbers are one run's, not shown to
/// converge, and how to find out.
pub const UNCHECKED: &str = "convergence: not checked (`--no-check`). Without it the run is \
checked against the scene at half the tolerance (about twice the run's time again) and every \
metric that moves beyond its bound is flagged; a chaotic rattle's later statistics are compared \
over several runs, not read from one";

/// What the console says of a scene with nothing to check (`reason`: no clearance hinge).
pub fn nothing_to_check(reason: &str) -> String {
    format!(
        "convergence: nothing to check ({reason}): the check compares clearance hinges' metrics, \
         so no metric is checked and no second run is made"
    )
}

/// The convergence check for the console: one line per metric (flagged ones marked), the
/// verdict naming the worst, then what the check cost against the run.
pub fn convergence_lines(check: &ConvergenceCheck) -> String {
    let mut out = format!("convergence check against {}:\n", check.tighter);
    for m in &check.metrics {
        let mark = if m.flagged { "NOT CONVERGED" } else { "ok" };
        out.push_str(&format!("  {mark:>13}  {}\n", m.describe()));
    }
    match check.worst() {
        None => out.push_str(&format!(
            "converged: every metric ({}) within its bound at this step control\n",
            check.metrics.len()
        )),
        Some(w) => {
            let flagged = check.flagged().count();
            out.push_str(&format!(
                "WARNING: {flagged} of {} metric(s) not converged at this step control (the other {} \
                 converged); the worst: {}. A tighter step control (`--set run.tolerance=...`, \
                 `--dt`) converges what converges; what keeps moving (the onsets of a chaotic \
                 rattle) is a statistic to compare over several runs, not a number to trust from \
                 one\n",
                check.metrics.len(),
                check.metrics.len() - flagged,
                w.describe()
            ))
        }
    }
    out.push_str(&format!(
        "check: {}; `--no-check` skips it",
        check.cost().describe()
    ));
    out
}
