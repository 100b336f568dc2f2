//! A result set (data, figures, report, and whatever else a command writes beside them) made
//! one unit: every writer of a set (`run`, each study) builds it in a staging folder beside its
//! target, `.<name>.new-<pid>`, and [`ResultSet::commit`] renames it into place, the old set
//! moved aside (`.<name>.old-<pid>`) and removed. So no member of an older set ever sits beside
//! a newer one: after a kill the target holds the old set whole, or (for a few instructions of
//! the commit) nothing while the new set waits in its staging folder.
//!
//! - The target is claimed by an OS lock on `.<name>.lock` beside it (a [`DirLock`] on the parent
//!   folder), so the lock outlives the renames and a second run is refused at once.
//! - A set may carry entries over from the old one (`keep`: a study's resumable `points`): the
//!   old set is then taken apart when the new one begins (its other members removed), and the
//!   staging folder of a run killed mid-way is adopted by the next, so finished points are reused.
//! - Files in the target that no writer makes (anything not `.csv`, `.json`, `.png`, `.svg`,
//!   `.html` or `.md`, hidden files included) are the user's: they are carried into the new set.
//! - A set that fails before its commit is dropped: the old set stays as it was (with `keep`,
//!   the carried entries go back into the target). [`abandon_all`] does the same on an interrupt.

use crate::process::files::{clean_stale_temps, process_alive};
use crate::process::lock::DirLock;
use clearance_joint::error::{Error, Result};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Staging folders of this process: (staging folder, target, carries entries over).
static OPEN: Mutex<Vec<(PathBuf, PathBuf, bool)>> = Mutex::new(Vec::new());

fn open_sets() -> std::sync::MutexGuard<'static, Vec<(PathBuf, PathBuf, bool)>> {
    OPEN.lock().unwrap_or_else(|e| e.into_inner())
}

/// A result set being built; see the module docs.
#[derive(Debug)]
pub struct ResultSet {
    target: PathBuf,
    stage: PathBuf,
    keep: Vec<String>,
    committed: bool,
    _lock: DirLock,
}

/// Whether a file name is one a writer of result sets makes (so an old one is a member of the
/// old set, not the user's).
pub fn is_member(name: &str) -> bool {
    !name.starts_with('.')
        && Path::new(name)
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| ["csv", "json", "png", "svg", "html", "md"].contains(&e))
}

fn io(action: &'static str, path: &Path) -> impl FnOnce(std::io::Error) -> Error {
    let path = path.to_path_buf();
    move |source| Error::Io {
        action,
        path,
        source,
    }
}

fn remove_any(path: &Path) -> std::io::Result<()> {
    match std::fs::symlink_metadata(path) {
        Ok(m) if m.is_dir() => std::fs::remove_dir_all(path),
        Ok(_) => std::fs::remove_file(path),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(e),
    }
}

fn entries(dir: &Path) -> Vec<(String, PathBuf)> {
    std::fs::read_dir(dir)
        .map(|rd| {
            rd.filter_map(|e| e.ok())
                .filter_map(|e| Some((e.file_name().into_string().ok()?, e.path())))
                .collect()
        })
        .unwrap_or_default()
}

impl ResultSet {
    /// Claims `target` and opens the staging folder of its next set. `keep` names entries of
    /// the current set carried into the new one (see the module docs); with `keep`, the target
    /// is moved to the staging folder now and is absent until the commit.
    pub fn begin(target: &Path, keep: &[&str]) -> Result<ResultSet> {
        let name = target
            .file_name()
            .and_then(|n| n.to_str())
            .filter(|n| *n != "." && *n != "..")
            .ok_or_else(|| {
                Error::invalid(
                    "--out",
                    format!("`{}` does not end in a folder name", target.display()),
                )
            })?
            .to_string();
        let parent = match target.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        if target.exists() && !target.is_dir() {
            return Err(Error::invalid(
                "--out",
                format!("`{}` exists and is not a folder", target.display()),
            ));
        }
        std::fs::create_dir_all(&parent).map_err(io("cannot create the output folder", target))?;
        let lock = DirLock::acquire_named(&parent, &format!(".{name}.lock"))?;
        // Under the registry's lock from the first rename to the registration: an interrupt
        // waits, then finds the staging folder registered and drops it (an unregistered one
        // would stay behind, or hold the old set with the target gone).
        let mut open = open_sets();
        clean_stale_temps(target);
        let stage = parent.join(format!(".{name}.new-{}", std::process::id()));
        let keep: Vec<String> = keep.iter().map(|k| k.to_string()).collect();
        // Leftovers of runs killed mid-way: we hold the lock, so nobody else is writing them.
        let mut adopted = false;
        for (n, path) in entries(&parent) {
            let new = n.starts_with(&format!(".{name}.new-"));
            if !(new || n.starts_with(&format!(".{name}.old-"))) {
                continue;
            }
            if new && !keep.is_empty() && !adopted && !target.exists() {
                std::fs::rename(&path, &stage).map_err(io("cannot adopt", &path))?;
                adopted = true;
            } else {
                remove_any(&path).map_err(io("cannot remove", &path))?;
            }
        }
        if !keep.is_empty() && target.exists() {
            std::fs::rename(target, &stage).map_err(io("cannot move aside", target))?;
        }
        std::fs::create_dir_all(&stage).map_err(io("cannot create", &stage))?;
        clean_stale_temps(&stage);
        if !keep.is_empty() {
            for (n, path) in entries(&stage) {
                if is_member(&n) && !keep.contains(&n) {
                    remove_any(&path).map_err(io("cannot remove", &path))?;
                }
            }
        }
        open.push((stage.clone(), target.to_path_buf(), !keep.is_empty()));
        drop(open);
        Ok(ResultSet {
            target: target.to_path_buf(),
            stage,
            keep,
            committed: false,
            _lock: lock,
        })
    }

    /// The folder to write the set into (the staging folder).
    pub fn dir(&self) -> &Path {
        &self.stage
    }

    /// The folder the set will be in once committed.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// Where `path`, inside the staging folder, will be once committed.
    pub fn final_path(&self, path: &Path) -> PathBuf {
        path.strip_prefix(&self.stage)
            .map_or_else(|_| path.to_path_buf(), |rest| self.target.join(rest))
    }

    /// Puts the set in place: the user's files of the old set are carried over, the old set is
    /// moved aside, the new one renamed into place, and the old one removed. Returns the target.
    pub fn commit(mut self) -> Result<PathBuf> {
        let old = self.stage.with_file_name(
            self.stage
                .file_name()
                .and_then(|n| n.to_str())
                .unwrap_or_default()
                .replacen(".new-", ".old-", 1),
        );
        // Under the registry's lock: an interrupt waits for the renames.
        let mut open = open_sets();
        if self.target.exists() {
            for (n, path) in entries(&self.target) {
                let into = self.stage.join(&n);
                if !is_member(&n) && !into.exists() && n != DirLock::FILE {
                    std::fs::rename(&path, &into).map_err(io("cannot carry over", &path))?;
                }
            }
            std::fs::rename(&self.target, &old).map_err(io("cannot move aside", &self.target))?;
        }
        if let Err(e) = std::fs::rename(&self.stage, &self.target) {
            let _ = std::fs::rename(&old, &self.target);
            return Err(io("cannot put in place", &self.target)(e));
        }
        self.committed = true;
        open.retain(|(s, _, _)| *s != self.stage);
        drop(open);
        let _ = remove_any(&old);
        Ok(self.target.clone())
    }
}

/// Drops a staging folder: removed, or with entries carried over, put back as the target
/// (only the carried entries and the user's files) unless a target exists.
fn abandon(stage: &Path, target: &Path, keeps: bool) {
    if keeps && !target.exists() {
        for (n, path) in entries(stage) {
            if is_member(&n) {
                let _ = remove_any(&path);
            }
        }
        if std::fs::rename(stage, target).is_ok() {
            return;
        }
    }
    let _ = remove_any(stage);
}

impl Drop for ResultSet {
    fn drop(&mut self) {
        if !self.committed {
            // Under the registry's lock: an interrupt waits until the set is dropped whole.
            let mut open = open_sets();
            open.retain(|(s, _, _)| *s != self.stage);
            // A kept entry of the new set (a finished point) stays; the rest goes.
            let keeps = !self.keep.is_empty();
            abandon(&self.stage, &self.target, keeps);
        }
    }
}

/// Drops every set this process has open (see [`ResultSet`]'s drop): for a SIGINT/SIGTERM
/// handler, before it exits. Returns the number of sets dropped.
pub fn abandon_all() -> usize {
    let mut open = open_sets();
    let n = open.len();
    // Newest first: a sweep point's set inside a study's staging folder goes before the study's
    // is put back (else it would be carried along and stay).
    for (stage, target, keeps) in open.drain(..).rev() {
        abandon(&stage, &target, keeps);
    }
    // Keep the registry locked: a set committing now waits until the process exits.
    std::mem::forget(open);
    n
}

/// Removes from `dir` the staging folders (`.<name>.new-<pid>`, `.<name>.old-<pid>`) of
/// processes that no longer exist: what a SIGKILL left (an interrupt leaves none). Their
/// targets hold the old set whole (or, killed inside a commit, nothing: the point runs again).
/// Returns how many were removed.
pub fn clean_stale(dir: &Path) -> usize {
    entries(dir)
        .into_iter()
        .filter(|(n, _)| n.starts_with('.'))
        .filter(|(n, _)| {
            let pid = n.rsplit_once(".new-").or_else(|| n.rsplit_once(".old-"));
            pid.and_then(|(_, p)| p.parse::<u32>().ok())
                .is_some_and(|p| !process_alive(p))
        })
        .filter(|(_, path)| remove_any(path).is_ok())
        .count()
}

/// Environment variable of [`pause_at`]: `STEP` or `STEP#K` (the K-th time, from 1).
pub const PAUSE_ENV: &str = "CLEARANCE_JOINT_PAUSE_AT";

/// A test hook between two writes of a result set: when [`PAUSE_ENV`] names `step` (and this
/// is its K-th passage), prints `paused at STEP` on standard error and waits for ever, so a
/// test can kill the process at that exact point. Does nothing otherwise.
pub fn pause_at(step: &str) {
    static PASSED: Mutex<Vec<String>> = Mutex::new(Vec::new());
    let Ok(wanted) = std::env::var(PAUSE_ENV) else {
        return;
    };
    let (name, k) = wanted
        .split_once('#')
        .map_or((wanted.as_str(), 1), |(n, k)| (n, k.parse().unwrap_or(1)));
    if name != step {
        return;
    }
    let mut passed = PASSED.lock().unwrap_or_else(|e| e.into_inner());
    passed.push(step.to_string());
    if passed.iter().filter(|s| *s == step).count() == k {
        let _ = writeln!(std::io::stderr(), "paused at {step}");
        drop(passed);
        loop {
            std::thread::sleep(std::time::Duration::from_secs(3600));
        }
    }
}
