//! This process's files in flight: the [`Staging`] its result files are written through
//! (removed by the interrupt handler, [`remove_inflight`]), and the temporaries of dead
//! processes, removed by the next write into their folder.

use clearance_joint::error::Result;
use clearance_joint::scene::output::{Render, Staging, write_set};
use std::io::Write;
use std::path::Path;

/// The temporaries and lock files of this process, removed on an interrupt; each folder written
/// into is first cleared of the temporaries of dead processes ([`clean_stale_temps`]).
pub static STAGING: Staging = Staging::with_folder_hook(clean_stale_in);

fn clean_stale_in(dir: &Path) {
    clean_stale_temps(dir);
}

/// Removes every temporary and lock file this process holds, and keeps any new one from being
/// created until the process exits: for a SIGINT/SIGTERM handler, which then exits. A set being
/// renamed into place is finished first. Returns the number of files removed.
pub fn remove_inflight() -> usize {
    STAGING.remove_all()
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

/// The pid of a temporary `.<name>.tmp-<pid>` (the library's [`write_set`] names them so).
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

/// Writes `bytes` to `path` atomically (temporary file + rename), creating the folder.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    write_all_atomic(&[(path, bytes)])
}

/// Writes the file `path` atomically as [`write_atomic`] does, its bytes streamed into it by
/// `render` (no copy of them is held).
pub fn write_atomic_with(path: &Path, render: impl Fn(&mut dyn Write) -> Result<()>) -> Result<()> {
    let render: Render = Box::new(render);
    write_set(&[(path, render)], &STAGING)
}

/// Writes several files as one set ([`write_set`], through [`STAGING`]).
pub fn write_all_atomic(files: &[(&Path, &[u8])]) -> Result<()> {
    let renders: Vec<(&Path, Render)> = files
        .iter()
        .map(|(p, bytes)| {
            let r: Render = Box::new(move |w: &mut dyn Write| {
                w.write_all(bytes)
                    .map_err(|e| clearance_joint::error::Error::Io {
                        action: "cannot write",
                        path: p.to_path_buf(),
                        source: e,
                    })
            });
            (*p, r)
        })
        .collect();
    write_set(&renders, &STAGING)
}
