//! The `run` command (and the default job): one scene's ideal and clearance twins, run into a
//! result set (data and figures, one unit: see [`crate::resultset`]) for a folder claimed for it.

use crate::resultset::ResultSet;
use clearance_joint::error::Result;
use clearance_joint::scene::output::{MemoryEstimate, available_memory, write_atomic};
use clearance_joint::scene::runner::convergence::{self, ConvergenceCheck};
use clearance_joint::scene::runner::{Progress, RunOptions, RunResult, Simulation, Twins};
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
    /// Before any work: the run fits `max_memory` (default: what the system has available), and
    /// the folder is ours alone until the set is in place, its staging folder writable.
    pub fn prepare(
        scene: ValidatedScene,
        out: PathBuf,
        max_memory: Option<u64>,
    ) -> Result<SceneRun> {
        if let Some(budget) = max_memory.or_else(available_memory) {
            let estimate = MemoryEstimate::of(&scene);
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
    ) -> Result<(
        RunResult,
        Option<clearance_joint::rapier::replay::Recording>,
    )> {
        crate::replay::run_recorded(&self.scene, progress, replay)
            .map_err(|e| e.with_step_mode(self.scene.run.step == StepMode::Adaptive))
    }

    /// The convergence check (`--check`): the scene again at half its tolerance (half its fixed
    /// step), the clearance twin only, compared with `result`'s
    /// ([`clearance_joint::scene::runner::convergence`]).
    pub fn check_convergence(
        &self,
        result: &RunResult,
        progress: impl FnMut(&Progress),
    ) -> Result<ConvergenceCheck> {
        let tighter = convergence::tightened(&self.scene)?;
        let options = RunOptions {
            twins: Twins::ClearanceOnly,
            skip_rows: true,
        };
        let finer = Simulation::from_validated(&tighter, options)?
            .run_with_progress(progress)
            .map_err(|e| e.with_step_mode(tighter.run.step == StepMode::Adaptive))?;
        Ok(ConvergenceCheck::compare(result, &finer))
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

/// What the console says of a run without `--check`: its numbers are one run's, not shown to
/// converge, and how to find out.
pub const UNCHECKED: &str = "convergence: not checked. `--check` runs the scene again at half \
the tolerance (about twice the time) and flags every metric that moves beyond its bound; a \
chaotic rattle's later statistics are compared over several runs, not read from one";

/// The convergence check for the console: one line per metric (flagged ones marked), then the
/// verdict naming the worst.
pub fn convergence_lines(check: &ConvergenceCheck) -> String {
    let mut out = format!(
        "convergence check against {} ({} steps against {}):\n",
        check.tighter, check.steps[1], check.steps[0]
    );
    for m in &check.metrics {
        let mark = if m.flagged { "NOT CONVERGED" } else { "ok" };
        out.push_str(&format!("  {mark:>13}  {}\n", m.describe()));
    }
    match check.worst() {
        None => out.push_str("every metric within its bound at this step control"),
        Some(w) => out.push_str(&format!(
            "WARNING: {} metric(s) not converged at this step control; the worst: {}. A tighter \
             step control (`--set run.tolerance=...`, `--dt`) converges what converges; what \
             keeps moving (the onsets of a chaotic rattle) is a statistic to compare over several \
             runs, not a number to trust from one",
            check.flagged().count(),
            w.describe()
        )),
    }
    out
}
