//! Issue 33, item 5: a sweep point's files (CSVs, `summary.json`, `replay.html`, `point.json`)
//! are one set. A `sweep --replay` rerun into a finished folder is stopped between every two
//! writes of a point (the `CLEARANCE_JOINT_PAUSE_AT` hook) and killed there by SIGKILL, SIGTERM
//! or SIGINT: every point folder then holds the old set whole or the new set whole, an
//! interrupt leaves no staging folder, and the next run removes what a SIGKILL left.

use clearance_joint_app::resultset::PAUSE_ENV;
use std::io::BufRead;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, SystemTime};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cj-sets-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn sweep(out: &Path, end: &str) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_clearance_joint"));
    c.args([
        "sweep",
        "--set",
        "hinge.clearance_mm=0.1,0.25",
        "--end",
        end,
    ])
    .args(["--jobs", "1", "--replay", "--progress", "quiet", "--out"])
    .arg(out);
    c
}

/// Non-hidden files of `dir` with their modification times.
fn members(dir: &Path) -> Vec<(String, SystemTime)> {
    let mut v: Vec<(String, SystemTime)> = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .flatten()
        .filter_map(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            let m = e.metadata().ok()?;
            (!name.starts_with('.')).then_some((name, m.modified().ok()?))
        })
        .collect();
    v.sort();
    v
}

/// Staging folders (`.<name>.new-*`, `.<name>.old-*`) in `points`.
fn stages(points: &Path) -> Vec<String> {
    std::fs::read_dir(points)
        .into_iter()
        .flatten()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('.') && (n.contains(".new-") || n.contains(".old-")))
        .collect()
}

/// Every point folder under `points` is one whole set: its five files at least (an impacts
/// table may join them), all older than
/// `rerun` or all newer.
fn assert_whole_points(points: &Path, rerun: SystemTime, what: &str) {
    let want = [
        "clearance.csv",
        "ideal.csv",
        "point.json",
        "replay.html",
        "summary.json",
    ];
    for dir in std::fs::read_dir(points).unwrap().flatten() {
        let name = dir.file_name().to_string_lossy().into_owned();
        if name.starts_with('.') || !dir.path().is_dir() {
            continue;
        }
        let m = members(&dir.path());
        let names: Vec<&str> = m.iter().map(|(n, _)| n.as_str()).collect();
        let missing: Vec<&&str> = want.iter().filter(|w| !names.contains(w)).collect();
        assert!(
            missing.is_empty(),
            "{what}: point `{name}` is not a whole set, it lacks {missing:?}: {names:?}"
        );
        let old = m.iter().filter(|(_, t)| *t < rerun).count();
        assert!(
            old == 0 || old == m.len(),
            "{what}: point `{name}` mixes {old} old files with {} new: {m:?}",
            m.len() - old
        );
    }
}

/// The files of the first point folder (by name) under `points`.
fn first_point(points: &Path) -> Vec<(String, SystemTime)> {
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(points)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.is_dir() && !p.file_name().unwrap().to_string_lossy().starts_with('.'))
        .collect();
    dirs.sort();
    members(&dirs[0])
}

/// Runs the rerun until it pauses at `step`, then sends `signal`.
fn kill_at(out: &Path, end: &str, step: &str, signal: &str) {
    let mut child = sweep(out, end)
        .env(PAUSE_ENV, step)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Standard error stays open (read to its end) after the pause: the interrupt handler
    // writes to it.
    let mut lines = std::io::BufReader::new(child.stderr.take().unwrap()).lines();
    let name = step.split('#').next().unwrap_or(step);
    let paused = lines.any(|l| l.unwrap_or_default().contains(&format!("paused at {name}")));
    let drain = std::thread::spawn(move || lines.for_each(drop));
    assert!(paused, "the rerun never reached `{step}`");
    let sent = Command::new("kill")
        .args(["-s", signal, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(sent.success());
    let status = child.wait().unwrap();
    let _ = drain.join();
    assert!(!status.success(), "{step}, {signal}: {status:?}");
}

#[test]
fn killed_replay_reruns_leave_whole_point_sets() {
    let out = scratch("replay-rerun");
    let points = out.join("points");
    assert!(sweep(&out, "0.02").status().unwrap().success());
    let mut trial = 0;
    for step in ["point-summary", "point-replay", "point-manifest"] {
        for signal in ["KILL", "TERM", "INT"] {
            trial += 1;
            std::thread::sleep(Duration::from_millis(20));
            let rerun = SystemTime::now();
            std::thread::sleep(Duration::from_millis(20));
            // Another end each time: the rerun's points differ from the folder's. Every other
            // trial stops at the second point, after the first committed its new set.
            let at = format!("{step}#{}", 1 + trial % 2);
            kill_at(&out, &format!("0.0{trial}1"), &at, signal);
            let what = format!("killed by SIG{signal} at {at}");
            assert_whole_points(&points, rerun, &what);
            if at.ends_with("#2") {
                assert!(
                    first_point(&points).iter().all(|(_, t)| *t > rerun),
                    "{what}: the first point's new set is not in place"
                );
            }
            if signal != "KILL" {
                assert!(stages(&points).is_empty(), "{what}: {:?}", stages(&points));
            }
        }
    }
    // The next run completes every point and removes what the SIGKILLs left.
    let rerun = SystemTime::now();
    std::thread::sleep(Duration::from_millis(20));
    assert!(sweep(&out, "0.02").status().unwrap().success());
    assert_whole_points(&points, rerun, "the run after");
    assert!(stages(&points).is_empty(), "{:?}", stages(&points));
    let _ = std::fs::remove_dir_all(&out);
}
