//! Result folders claimed before any work: [`DirLock`] claims a folder for one process (an OS
//! lock on `<folder>/.lock`), so two runs into one folder cannot mix their files; a second run
//! is refused at once ([`Error::OutputFolder`], which [`crate::advice`] phrases as `--out`).

use crate::process::files::{STAGING, clean_stale_temps};
use clearance_joint::error::{Error, Result};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Creates `dir` (and its parents) and checks that it is a writable folder, before any work is
/// done for it; removes stale temporaries found there.
pub fn prepare_dir(dir: &Path) -> Result<()> {
    if dir.exists() && !dir.is_dir() {
        return Err(Error::OutputFolder {
            folder: dir.to_path_buf(),
            reason: format!("`{}` exists and is not a folder", dir.display()),
        });
    }
    std::fs::create_dir_all(dir).map_err(|source| Error::Io {
        action: "cannot create the output folder",
        path: dir.to_path_buf(),
        source,
    })?;
    let probe = dir.join(format!(".probe.tmp-{}", std::process::id()));
    STAGING.track(&probe);
    let written = std::fs::File::create(&probe).and_then(|mut f| f.write_all(b"probe"));
    let _ = std::fs::remove_file(&probe);
    STAGING.untrack(&probe);
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
                    return Err(Error::OutputFolder {
                        folder: dir.to_path_buf(),
                        reason: format!(
                            "`{}` is being written by another run{}: wait for it to finish or choose another \
                             folder (two runs into one folder would mix their files)",
                            dir.display(),
                            if holder.is_empty() {
                                String::new()
                            } else {
                                format!(" (process {holder})")
                            }
                        ),
                    });
                }
                Err(std::fs::TryLockError::Error(e)) => return Err(io("cannot lock", e)),
            }
            if !same_file(&file, &path) {
                continue;
            }
            file.set_len(0)
                .and_then(|_| file.write_all(std::process::id().to_string().as_bytes()))
                .map_err(|e| io("cannot write", e))?;
            STAGING.track(&path);
            return Ok(DirLock { path, _file: file });
        }
        Err(Error::OutputFolder {
            folder: dir.to_path_buf(),
            reason: format!(
                "the lock file of `{}` keeps changing: another process is claiming it",
                dir.display()
            ),
        })
    }
}

impl Drop for DirLock {
    fn drop(&mut self) {
        STAGING.untrack(&self.path);
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
