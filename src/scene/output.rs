//! Result files written whole or not at all.
//!
//! A set of files is written to temporary names (`.<name>.tmp-<pid>`, `pid` this process's id)
//! in its folder, then renamed into place, its last file (the summary or manifest) last: a set
//! without its last file is incomplete, and a failed rename removes the whole set
//! ([`write_set`]). The temporaries are recorded in a [`Staging`] while they exist, which the
//! caller owns: an application that removes its temporaries on an interrupt keeps one for the
//! whole process and calls [`Staging::remove_all`] from its handler.

use crate::error::{Error, Result};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

/// The temporaries (and any other files the caller [`track`](Self::track)s) of the sets being
/// written, removed at once by [`remove_all`](Self::remove_all). Creating a temporary and
/// renaming a set into place happen under its lock, so `remove_all` waits for a set being
/// committed and no temporary is created after it.
#[derive(Debug, Default)]
pub struct Staging {
    files: Mutex<Vec<PathBuf>>,
    on_folder: Option<fn(&Path)>,
}

impl Staging {
    /// An empty record.
    pub const fn new() -> Staging {
        Staging {
            files: Mutex::new(Vec::new()),
            on_folder: None,
        }
    }

    /// An empty record that calls `hook` on each folder [`write_set`] writes into, once per set
    /// and before its first temporary there (an application removes the temporaries of dead
    /// processes with it).
    pub const fn with_folder_hook(hook: fn(&Path)) -> Staging {
        Staging {
            files: Mutex::new(Vec::new()),
            on_folder: Some(hook),
        }
    }

    fn lock(&self) -> MutexGuard<'_, Vec<PathBuf>> {
        self.files.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Records `path` (a lock file, a probe) for [`remove_all`](Self::remove_all).
    pub fn track(&self, path: &Path) {
        self.lock().push(path.to_path_buf());
    }

    /// Forgets `path`, recorded by [`track`](Self::track).
    pub fn untrack(&self, path: &Path) {
        forget(&mut self.lock(), path);
    }

    /// Removes every recorded file, and keeps any new temporary from being created until the
    /// process exits: for a SIGINT/SIGTERM handler, which then exits. A set being renamed into
    /// place is finished first. Returns the number of files removed.
    pub fn remove_all(&self) -> usize {
        let mut list = self.lock();
        let n = list
            .iter()
            .filter(|p| std::fs::remove_file(p).is_ok())
            .count();
        list.clear();
        // Keep the lock: writers block at their next temporary until the handler exits.
        std::mem::forget(list);
        n
    }
}

fn forget(list: &mut Vec<PathBuf>, path: &Path) {
    if let Some(i) = list.iter().position(|p| p == path) {
        list.swap_remove(i);
    }
}

/// Creates the folder of `path` and calls the staging's folder hook there (once per folder).
fn create_parent(path: &Path, staging: &Staging, cleaned: &mut Vec<PathBuf>) -> Result<()> {
    let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) else {
        return Ok(());
    };
    std::fs::create_dir_all(dir).map_err(|source| Error::Io {
        action: "cannot create the folder of",
        path: path.to_path_buf(),
        source,
    })?;
    if !cleaned.iter().any(|d| d == dir) {
        if let Some(hook) = staging.on_folder {
            hook(dir);
        }
        cleaned.push(dir.to_path_buf());
    }
    Ok(())
}

/// Writes the content of one file into a writer (streamed: a large table is never held as text).
pub type Render<'a> = Box<dyn Fn(&mut dyn Write) -> Result<()> + 'a>;

/// Writes several files as one set: every file goes to a temporary name in its folder first,
/// recorded in `staging` while it exists. When all are written, the old last
/// file is removed, the others are renamed into place, and the last file (the set's summary or
/// manifest) is renamed last. A failure before the renames leaves the previous files untouched;
/// a failed rename removes every file of the set, old or new, so no set is ever mixed.
pub fn write_set(files: &[(&Path, Render)], staging: &Staging) -> Result<()> {
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
        let mut list = staging.lock();
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
            let mut list = staging.lock();
            let made = create_parent(path, staging, &mut cleaned)
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
    let mut list = staging.lock();
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
