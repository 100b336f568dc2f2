//! One point of a sweep: its job, its folder's manifest, and running it.

use super::*;

/// One point ready to run: its scene and its folder.
#[derive(Clone, Debug)]
pub struct Job {
    /// The grid point.
    pub point: Point,
    /// The scene with the base and point overrides applied, checked once (it carries the
    /// hinges' built `HingeDesign`s the run uses).
    pub scene: ValidatedScene,
    /// The point's folder.
    pub dir: PathBuf,
    /// The sweep's fixed overrides (recorded in the manifest).
    pub base_overrides: Vec<String>,
}

/// A size-checked file of a finished point.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct FileEntry {
    /// File name inside the point's folder.
    pub name: String,
    /// Its size, bytes.
    pub bytes: u64,
}

/// `point.json`: what a finished point holds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// [`FORMAT_VERSION`].
    pub format: u32,
    /// The grid point.
    pub point: Point,
    /// The fixed overrides of the sweep.
    pub base_overrides: Vec<String>,
    /// The scene that ran, as RON: a rerun reuses the point only if its scene is identical.
    pub scene_ron: String,
    /// The result files and their sizes.
    pub files: Vec<FileEntry>,
    /// The run's metrics.
    pub metrics: RunMetrics,
}

/// A finished point, just run or reused.
#[derive(Clone, Debug)]
pub struct PointOutcome {
    /// Its manifest.
    pub manifest: Manifest,
    /// Its folder.
    pub dir: PathBuf,
    /// True when an earlier run's complete files were reused.
    pub reused: bool,
}

impl Job {
    /// The point's manifest if the point is finished: manifest readable, same format and scene,
    /// and every listed file present with its recorded size. Anything else means unfinished.
    pub fn finished(&self) -> Option<Manifest> {
        let text = std::fs::read_to_string(self.dir.join(MANIFEST)).ok()?;
        let m: Manifest = serde_json::from_str(&text).ok()?;
        if m.format != FORMAT_VERSION || m.scene_ron != self.scene.to_ron() {
            return None;
        }
        for f in &m.files {
            let meta = std::fs::metadata(self.dir.join(&f.name)).ok()?;
            if !meta.is_file() || meta.len() != f.bytes {
                return None;
            }
        }
        Some(m)
    }

    /// Runs the point and writes its files as one set, the manifest last (see
    /// [`run_point`](Self::run_point)).
    pub fn run(&self) -> Result<Manifest> {
        self.run_replay(false)
    }

    /// As [`run`](Self::run), also writing the point's replay (`replay.html`) when `replay`.
    pub fn run_replay(&self, replay: bool) -> Result<Manifest> {
        self.run_point(replay, false)
    }

    /// As [`run_replay`](Self::run_replay), also checking the point's convergence when `check`
    /// ([`ExecOptions::check`]). A check whose own run fails does not fail the point: its
    /// verdict says so. The point's files (CSVs, summary, replay, manifest) are one result set
    /// ([`ResultSet`]): written into `points/.<dir>.new-<pid>` and renamed into place whole, so
    /// a kill leaves the old set or the new one, never a mix; its claim (`points/.<dir>.lock`)
    /// refuses a second sweep running the same point.
    pub fn run_point(&self, replay: bool, check: bool) -> Result<Manifest> {
        let set = ResultSet::begin(&self.dir, &[])?;
        let adaptive = self.scene.run.step == clearance_joint::scene::StepMode::Adaptive;
        let (mut result, recording) = crate::replay::run_recorded(&self.scene, |_| {}, replay)
            .map_err(|e| e.with_step_mode(adaptive))?;
        // A point the step control stalled is an error of the sweep, not a result.
        if let Some(e) = result.stopped.take() {
            return Err(e.with_step_mode(adaptive));
        }
        let convergence = if check {
            match convergence::check(&self.scene, &result, |_| {}) {
                Ok(c) => c.verdict(),
                Err(e) => ConvergenceVerdict::Failed {
                    error: e.to_string(),
                },
            }
        } else {
            ConvergenceVerdict::NotChecked {
                reason: "not asked for".into(),
            }
        };
        let mut metrics = RunMetrics::of(&result)?;
        metrics.convergence = convergence.clone();
        let dir = set.dir();
        crate::summary::write_run(&result, dir, &convergence)?;
        pause_at("point-summary");
        if let Some(recording) = &recording {
            crate::replay::write_run_replay(&self.scene, &result, recording, dir)?;
        }
        pause_at("point-replay");
        let manifest = self.manifest(&result, dir, metrics)?;
        write_atomic(&dir.join(MANIFEST), &json_bytes(&manifest, "manifest")?)?;
        pause_at("point-manifest");
        set.commit()?;
        Ok(manifest)
    }

    /// The manifest of the point's files written into `dir`.
    fn manifest(
        &self,
        result: &clearance_joint::scene::runner::RunResult,
        dir: &Path,
        metrics: RunMetrics,
    ) -> Result<Manifest> {
        let mut names: Vec<String> = result
            .twins
            .iter()
            .map(|t| format!("{}.csv", t.kind.name()))
            .collect();
        names.push("summary.json".into());
        let files = names
            .into_iter()
            .map(|name| {
                let path = dir.join(&name);
                let bytes = std::fs::metadata(&path)
                    .map_err(|source| Error::Io {
                        action: "cannot read the size of",
                        path,
                        source,
                    })?
                    .len();
                Ok(FileEntry { name, bytes })
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Manifest {
            format: FORMAT_VERSION,
            point: self.point.clone(),
            base_overrides: self.base_overrides.clone(),
            scene_ron: self.scene.to_ron(),
            files,
            metrics,
        })
    }
}

pub(super) fn remove_if_present(path: &Path) -> Result<()> {
    match std::fs::remove_file(path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(Error::Io {
            action: "cannot remove",
            path: path.to_path_buf(),
            source: e,
        }),
        _ => Ok(()),
    }
}

/// Pretty JSON of a serialisable value (refusing non-finite numbers, which JSON cannot hold).
pub(crate) fn json_bytes<T: Serialize>(value: &T, what: &str) -> Result<Vec<u8>> {
    let v = serde_json::to_value(value).map_err(|e| Error::invalid(what, e.to_string()))?;
    serde_json::to_vec_pretty(&v).map_err(|e| Error::invalid(what, e.to_string()))
}
