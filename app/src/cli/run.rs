//! The `run` command (and the default job): one scene's ideal and clearance twins, run into a
//! result set in a folder claimed for it.

use clearance_joint::error::Result;
use clearance_joint::scene::output::{DirLock, MemoryEstimate, available_memory};
use clearance_joint::scene::runner::{Progress, RunOptions, RunResult, Simulation};
use clearance_joint::scene::{Scene, StepMode};
use std::path::PathBuf;

/// A run ready to go: its memory checked and its output folder claimed (until dropped).
#[derive(Debug)]
pub struct SceneRun {
    /// The scene, overrides applied.
    pub scene: Scene,
    /// The output folder.
    pub out: PathBuf,
    _lock: DirLock,
}

impl SceneRun {
    /// Before any work: the run fits `max_memory` (default: what the system has available), and
    /// the folder exists, is writable and is ours alone until the set is written.
    pub fn prepare(scene: Scene, out: PathBuf, max_memory: Option<u64>) -> Result<SceneRun> {
        if let Some(budget) = max_memory.or_else(available_memory) {
            MemoryEstimate::of(&scene).check(&scene, 1, budget)?;
        }
        let lock = DirLock::acquire(&out)?;
        Ok(SceneRun {
            scene,
            out,
            _lock: lock,
        })
    }

    /// Runs both twins, calling `progress` after every step; a step-size error advises for the
    /// scene's step mode.
    pub fn execute(&self, progress: impl FnMut(&Progress)) -> Result<RunResult> {
        Simulation::new(&self.scene, RunOptions::default())?
            .run_with_progress(progress)
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
