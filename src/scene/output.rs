//! Result files written whole or not at all, folders claimed before any work, and the memory a
//! run will hold, estimated before it starts.
//!
//! - A set of files is written to temporary names (`.<name>.tmp-<pid>`) in its folder, then
//!   renamed into place, its last file (the summary or manifest) last: a set without its last
//!   file is incomplete, and a failed rename removes the whole set.
//! - [`DirLock`] claims a result folder for one process (an OS lock on `<folder>/.lock`), so
//!   two runs into one folder cannot mix their files; a second run is refused at once.
//! - Temporaries of processes that no longer exist are removed by the next write into their
//!   folder, and an interrupted process removes its own ([`remove_inflight`], called from the
//!   CLI's SIGINT/SIGTERM handler).

use crate::error::{Error, Result, sig4};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Temporaries and lock files this process has open, removed on an interrupt. The renames of a
/// set happen under this lock, so an interrupt waits for a set being committed.
static INFLIGHT: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn inflight() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    INFLIGHT.lock().unwrap_or_else(|e| e.into_inner())
}

fn forget(list: &mut Vec<PathBuf>, path: &Path) {
    if let Some(i) = list.iter().position(|p| p == path) {
        list.swap_remove(i);
    }
}

/// Removes every temporary and lock file this process holds, and keeps any new one from being
/// created until the process exits: for a SIGINT/SIGTERM handler, which then exits. A set being
/// renamed into place is finished first. Returns the number of files removed.
pub fn remove_inflight() -> usize {
    let mut list = inflight();
    let n = list
        .iter()
        .filter(|p| std::fs::remove_file(p).is_ok())
        .count();
    list.clear();
    // Keep the lock: writers block at their next temporary until the handler exits.
    std::mem::forget(list);
    n
}

/// Whether process `pid` exists (Linux: `/proc/<pid>`; elsewhere assumed alive, so nothing of
/// another process is ever removed by mistake).
pub fn process_alive(pid: u32) -> bool {
    if pid == std::process::id() {
        return true;
    }
    let proc_root = Path::new("/proc");
    if !proc_root.join("self").exists() {
        return true;
    }
    proc_root.join(pid.to_string()).exists()
}

/// The pid of a temporary `.<name>.tmp-<pid>` written by [`write_all_atomic`].
fn temp_owner(file_name: &str) -> Option<u32> {
    let (_, pid) = file_name.strip_prefix('.')?.rsplit_once(".tmp-")?;
    pid.parse().ok()
}

/// Removes the temporaries left in `dir` by processes that no longer exist (a run killed while
/// writing). Returns how many were removed.
pub fn clean_stale_temps(dir: &Path) -> usize {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return 0;
    };
    entries
        .filter_map(|e| e.ok())
        .filter(|e| {
            e.file_name()
                .to_str()
                .and_then(temp_owner)
                .is_some_and(|pid| !process_alive(pid))
        })
        .filter(|e| e.file_type().is_ok_and(|t| t.is_file()))
        .filter(|e| std::fs::remove_file(e.path()).is_ok())
        .count()
}

/// The `field` of the [`Error::Invalid`] this module returns for a result folder that cannot be
/// used (not a folder, claimed by another run): an application names its own option for it.
pub const OUTPUT_FOLDER: &str = "output folder";

/// Creates `dir` (and its parents) and checks that it is a writable folder, before any work is
/// done for it; removes stale temporaries found there.
pub fn prepare_dir(dir: &Path) -> Result<()> {
    if dir.exists() && !dir.is_dir() {
        return Err(Error::invalid(
            OUTPUT_FOLDER,
            format!("`{}` exists and is not a folder", dir.display()),
        ));
    }
    std::fs::create_dir_all(dir).map_err(|source| Error::Io {
        action: "cannot create the output folder",
        path: dir.to_path_buf(),
        source,
    })?;
    let probe = dir.join(format!(".probe.tmp-{}", std::process::id()));
    inflight().push(probe.clone());
    let written = std::fs::File::create(&probe).and_then(|mut f| f.write_all(b"probe"));
    let _ = std::fs::remove_file(&probe);
    forget(&mut inflight(), &probe);
    written.map_err(|source| Error::Io {
        action: "cannot write into the output folder",
        path: dir.to_path_buf(),
        source,
    })?;
    clean_stale_temps(dir);
    Ok(())
}

/// A result folder claimed by this process: an OS lock on `<folder>/.lock` (released by the OS
/// if the process dies, so a killed run never blocks the next one). Dropping it removes the
/// lock file. Two runs into one folder: the second is refused at once, naming the first's pid.
#[derive(Debug)]
pub struct DirLock {
    path: PathBuf,
    _file: std::fs::File,
}

impl DirLock {
    /// Name of the lock file inside a claimed folder.
    pub const FILE: &'static str = ".lock";

    /// Prepares `dir` ([`prepare_dir`]) and claims it (lock file [`DirLock::FILE`]).
    pub fn acquire(dir: &Path) -> Result<DirLock> {
        Self::acquire_named(dir, Self::FILE)
    }

    /// Prepares `dir` and claims the part of it that lock file `name` stands for (a sweep
    /// shard's table: shards of one sweep share its folder).
    pub fn acquire_named(dir: &Path, name: &str) -> Result<DirLock> {
        prepare_dir(dir)?;
        let path = dir.join(name);
        let io = |action, source| Error::Io {
            action,
            path: path.clone(),
            source,
        };
        // A holder that just released the lock unlinks its file: lock the file that is still at
        // `path`, retrying if it was replaced between opening and locking.
        for _ in 0..100 {
            let mut file = std::fs::OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(&path)
                .map_err(|e| io("cannot create the lock file", e))?;
            match file.try_lock() {
                Ok(()) => {}
                Err(std::fs::TryLockError::WouldBlock) => {
                    let holder = std::fs::read_to_string(&path).unwrap_or_default();
                    let holder = holder.trim();
                    return Err(Error::invalid(
                        OUTPUT_FOLDER,
                        format!(
                            "`{}` is being written by another run{}: wait for it to finish or choose another \
                             folder (two runs into one folder would mix their files)",
                            dir.display(),
                            if holder.is_empty() {
                                String::new()
                            } else {
                                format!(" (process {holder})")
                            }
                        ),
                    ));
                }
                Err(std::fs::TryLockError::Error(e)) => return Err(io("cannot lock", e)),
            }
            if !same_file(&file, &path) {
                continue;
            }
            file.set_len(0)
                .and_then(|_| file.write_all(std::process::id().to_string().as_bytes()))
                .map_err(|e| io("cannot write", e))?;
            inflight().push(path.clone());
            return Ok(DirLock { path, _file: file });
        }
        Err(Error::invalid(
            OUTPUT_FOLDER,
            format!(
                "the lock file of `{}` keeps changing: another process is claiming it",
                dir.display()
            ),
        ))
    }
}

impl Drop for DirLock {
    fn drop(&mut self) {
        let mut list = inflight();
        forget(&mut list, &self.path);
        // Unlink while still holding the lock: a waiter that opened this file retries.
        let _ = std::fs::remove_file(&self.path);
    }
}

#[cfg(unix)]
fn same_file(file: &std::fs::File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

#[cfg(not(unix))]
fn same_file(_: &std::fs::File, path: &Path) -> bool {
    path.exists()
}

/// Writes `bytes` to `path` atomically (temporary file + rename), creating the folder.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    write_all_atomic(&[(path, bytes)])
}

/// Writes several files as a set (see [`write_set`]).
pub fn write_all_atomic(files: &[(&Path, &[u8])]) -> Result<()> {
    let renders: Vec<(&Path, Render)> = files
        .iter()
        .map(|(p, bytes)| {
            let r: Render = Box::new(move |w: &mut dyn Write| {
                w.write_all(bytes).map_err(|e| Error::Io {
                    action: "cannot write",
                    path: p.to_path_buf(),
                    source: e,
                })
            });
            (*p, r)
        })
        .collect();
    write_set(&renders)
}

/// Creates the folder of `path` and removes the stale temporaries there (once per folder).
fn create_parent(path: &Path, cleaned: &mut Vec<PathBuf>) -> Result<()> {
    let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) else {
        return Ok(());
    };
    std::fs::create_dir_all(dir).map_err(|source| Error::Io {
        action: "cannot create the folder of",
        path: path.to_path_buf(),
        source,
    })?;
    if !cleaned.iter().any(|d| d == dir) {
        clean_stale_temps(dir);
        cleaned.push(dir.to_path_buf());
    }
    Ok(())
}

/// Writes the content of one file into a writer (streamed: a large table is never held as text).
pub type Render<'a> = Box<dyn Fn(&mut dyn Write) -> Result<()> + 'a>;

/// Writes several files as one set: every file goes to a temporary name in its folder first
/// (stale temporaries of dead processes there are removed). When all are written, the old last
/// file is removed, the others are renamed into place, and the last file (the set's summary or
/// manifest) is renamed last. A failure before the renames leaves the previous files untouched;
/// a failed rename removes every file of the set, old or new, so no set is ever mixed.
pub fn write_set(files: &[(&Path, Render)]) -> Result<()> {
    let io = |action, path: &Path, source| Error::Io {
        action,
        path: path.to_path_buf(),
        source,
    };
    let temp = |path: &Path| {
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        path.with_file_name(format!(".{name}.tmp-{}", std::process::id()))
    };
    let mut staged: Vec<PathBuf> = Vec::with_capacity(files.len());
    let discard = |staged: &[PathBuf]| {
        let mut list = inflight();
        for t in staged {
            let _ = std::fs::remove_file(t);
            forget(&mut list, t);
        }
    };
    let mut cleaned: Vec<PathBuf> = Vec::new();
    for (path, render) in files {
        let tmp = temp(path);
        // Folder and temporary made under the in-flight lock: an interrupt either finds the
        // temporary registered (and removes it) or stops us before we create anything, so no
        // folder (a result set's staging folder) is made again after the interrupt removed it.
        let created = {
            let mut list = inflight();
            let made = create_parent(path, &mut cleaned)
                .and_then(|_| std::fs::File::create(&tmp).map_err(|e| io("cannot write", path, e)));
            if made.is_ok() {
                list.push(tmp.clone());
            }
            made
        };
        let f = match created {
            Ok(f) => f,
            Err(e) => {
                discard(&staged);
                return Err(e);
            }
        };
        staged.push(tmp.clone());
        let written = (|| -> Result<()> {
            let mut w = std::io::BufWriter::with_capacity(1 << 16, f);
            render(&mut w)?;
            let f = w
                .into_inner()
                .map_err(|e| io("cannot write", path, e.into_error()))?;
            f.sync_all().map_err(|e| io("cannot write", path, e))
        })();
        if let Err(e) = written {
            discard(&staged);
            return Err(e);
        }
    }
    // Commit under the in-flight lock: an interrupt waits for the renames.
    let mut list = inflight();
    let n = files.len();
    let last_old = files.last().map(|(p, _)| *p);
    let mut result = Ok(());
    if let Some(last) = last_old
        && n > 1
        && let Err(e) = std::fs::remove_file(last)
        && e.kind() != std::io::ErrorKind::NotFound
    {
        result = Err(io("cannot replace", last, e));
    }
    if result.is_ok() {
        for ((path, _), tmp) in files.iter().zip(&staged) {
            if let Err(e) = std::fs::rename(tmp, path) {
                result = Err(io("cannot write", path, e));
                break;
            }
            forget(&mut list, tmp);
        }
    }
    if result.is_err() {
        for ((path, _), tmp) in files.iter().zip(&staged) {
            let _ = std::fs::remove_file(tmp);
            forget(&mut list, tmp);
            if n > 1 {
                let _ = std::fs::remove_file(path);
            }
        }
    }
    result
}

/// The memory a run will hold for its output rows, estimated from the scene before it starts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MemoryEstimate {
    /// Output rows per twin.
    pub rows: u64,
    /// Values per row, over both twins.
    pub values_per_row: u64,
    /// Bytes: the rows' values (8 bytes each) held twice, for a table's growth by doubling,
    /// plus a fixed allowance for the world and the program, plus [`replay_bytes`](Self::replay_bytes).
    pub bytes: u64,
    /// Bytes of the run's replay, when one is recorded (0 otherwise): what its recorder and
    /// page hold at their peak, as the application that builds them states
    /// ([`with_replay`](Self::with_replay)).
    pub replay_bytes: u64,
}

/// Fixed allowance of a run beyond its rows (program, Rapier world, buffers), bytes.
const BASE_BYTES: u64 = 64 << 20;

impl MemoryEstimate {
    /// The estimate for one run of `scene` with both twins: rows from `run.end_s` and
    /// `run.output_interval_s` (fixed steps: the interval rounded to whole steps), one time
    /// column, two per body and seven per hinge, per twin.
    pub fn of(scene: &crate::scene::Scene) -> MemoryEstimate {
        let r = &scene.run;
        let rows = match r.step {
            crate::scene::StepMode::Fixed => {
                let steps = (r.end_s / r.dt_s).round().max(1.0);
                let stride = (r.output_interval_s / r.dt_s).round().max(1.0);
                (steps / stride + 1e-9).floor() + 2.0
            }
            crate::scene::StepMode::Adaptive => {
                (r.end_s / r.output_interval_s + 1e-9).floor() + 2.0
            }
        };
        let rows = if rows.is_finite() {
            rows.min(u64::MAX as f64 / 1e3) as u64
        } else {
            u64::MAX / 1000
        };
        let motion = if scene.run.body_motion { 9 } else { 0 };
        let per_twin = 1
            + (2 + motion) * scene.bodies.len() as u64
            + 7 * scene.hinges.len() as u64
            + scene.joints.len() as u64;
        let values_per_row = 2 * per_twin;
        let bytes = rows
            .saturating_mul(values_per_row)
            .saturating_mul(16)
            .saturating_add(BASE_BYTES);
        MemoryEstimate {
            rows,
            values_per_row,
            bytes,
            replay_bytes: 0,
        }
    }

    /// The estimate with a replay of `replay_bytes` recorded beside the rows (replacing any
    /// replay counted before).
    pub fn with_replay(self, replay_bytes: u64) -> MemoryEstimate {
        MemoryEstimate {
            bytes: self
                .bytes
                .saturating_sub(self.replay_bytes)
                .saturating_add(replay_bytes),
            replay_bytes,
            ..self
        }
    }

    /// Refuses the run when `concurrent` such runs would need more than `budget` bytes, with the
    /// numbers and the fields to change (a larger `run.output_interval_s`, the smallest that
    /// fits: [`fitting_interval`](Self::fitting_interval)).
    pub fn check(&self, scene: &crate::scene::Scene, concurrent: u64, budget: u64) -> Result<()> {
        let need = self.bytes.saturating_mul(concurrent.max(1));
        if need <= budget {
            return Ok(());
        }
        let advice = match self.fitting_interval(scene, concurrent, budget) {
            Some(interval) => format!(
                "use `run.output_interval_s` = {} or larger (or a shorter `run.end_s`, or a larger \
                 memory budget)",
                sig4(interval)
            ),
            None => format!(
                "that is less than the {} a run needs beyond its rows: raise the memory budget{}",
                bytes_text(BASE_BYTES.saturating_add(self.replay_bytes)),
                if concurrent > 1 {
                    " or run fewer in parallel"
                } else {
                    ""
                }
            ),
        };
        Err(Error::invalid(
            "run.output_interval_s",
            format!(
                "{} rows of {} values{}{} would need about {} of memory, more than the {} available: {advice}",
                sig4(self.rows as f64),
                self.values_per_row,
                if self.replay_bytes > 0 {
                    format!(" and the replay (about {})", bytes_text(self.replay_bytes))
                } else {
                    String::new()
                },
                if concurrent > 1 {
                    format!(" in each of {concurrent} parallel runs")
                } else {
                    String::new()
                },
                bytes_text(need),
                bytes_text(budget),
            ),
        ))
    }

    /// The smallest output interval, s (2 significant digits, rounded up), at which
    /// `concurrent` runs of `scene` fit `budget` bytes; `None` when no interval does (the budget
    /// is below what a run needs beyond its rows).
    pub fn fitting_interval(
        &self,
        scene: &crate::scene::Scene,
        concurrent: u64,
        budget: u64,
    ) -> Option<f64> {
        let per_run = budget / concurrent.max(1);
        let fixed = BASE_BYTES.saturating_add(self.replay_bytes);
        let fit_rows = per_run.saturating_sub(fixed) / (16 * self.values_per_row.max(1));
        (fit_rows > 2).then(|| round_up_sig(scene.run.end_s / (fit_rows - 2) as f64))
    }
}

/// `x` rounded up to 2 significant digits (a suggested option value).
fn round_up_sig(x: f64) -> f64 {
    if !(x.is_finite() && x > 0.0) {
        return x;
    }
    let p = 10f64.powf(x.log10().floor() - 1.0);
    (x / p).ceil() * p
}

/// Bytes as `1.23 GB` (powers of 1000).
pub fn bytes_text(bytes: u64) -> String {
    let b = bytes as f64;
    for (unit, scale) in [("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)] {
        if b >= scale {
            return format!("{} {unit}", sig4(b / scale));
        }
    }
    format!("{bytes} B")
}

/// Parses a memory size: bytes, or a number with `k`, `M`, `G` or `T` (powers of 1024 with
/// `KiB`..`TiB`, of 1000 with `kB`..`TB` or the bare letter).
pub fn parse_bytes(text: &str) -> Result<u64> {
    let t = text.trim();
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.' || c == 'e' || c == 'E'))
        .unwrap_or(t.len());
    let (num, unit) = t.split_at(split);
    let scale = match unit.trim().to_ascii_lowercase().as_str() {
        "" | "b" => 1.0,
        "k" | "kb" => 1e3,
        "m" | "mb" => 1e6,
        "g" | "gb" => 1e9,
        "t" | "tb" => 1e12,
        "kib" => 1024.0,
        "mib" => 1024.0 * 1024.0,
        "gib" => 1024.0 * 1024.0 * 1024.0,
        "tib" => 1024.0f64.powi(4),
        _ => f64::NAN,
    };
    let v: f64 = num.parse().unwrap_or(f64::NAN) * scale;
    if v.is_finite() && v > 0.0 {
        Ok(v as u64)
    } else {
        Err(Error::invalid(
            "size",
            format!(
                "expected a size such as 4G, 512M or 2GiB (got `{}`)",
                crate::error::excerpt(text, 40)
            ),
        ))
    }
}

/// Memory this process may use: 80 % of what the system reports available (Linux
/// `MemAvailable`, and a cgroup limit when there is one); `None` when unknown.
pub fn available_memory() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok()?;
    let avail_kb: u64 = meminfo
        .lines()
        .find_map(|l| l.strip_prefix("MemAvailable:"))?
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    let mut avail = avail_kb.saturating_mul(1024);
    for (limit, usage) in [
        ("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current"),
        (
            "/sys/fs/cgroup/memory/memory.limit_in_bytes",
            "/sys/fs/cgroup/memory/memory.usage_in_bytes",
        ),
    ] {
        let read =
            |p: &str| -> Option<u64> { std::fs::read_to_string(p).ok()?.trim().parse().ok() };
        if let (Some(l), Some(u)) = (read(limit), read(usage)) {
            avail = avail.min(l.saturating_sub(u));
        }
    }
    Some(avail / 5 * 4)
}
