//! Whole-process CPU time of the paper's scene, side by side in one run: the app at its
//! default (sub-cycled contact), explicit, and at the paper's fixed 1e-4 s, each a separate
//! process writing its whole result set (`--no-check`), plus the independent scipy RK45 model
//! (`benches/reference/solar_panel_rk45.py`, rtol 1e-4) when Python has scipy.
//! `cargo bench --bench paper_cost [-- RUNS]` writes `bench_out/paper_cost.md`.
//!
//! CPU is user plus system time of the child process (`getrusage(RUSAGE_CHILDREN)` around each
//! run), the median of `RUNS` (default 5) runs taken in turn, so that a load on the machine
//! falls on every configuration alike.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// One configuration: a name and the command that runs it.
struct Config {
    name: &'static str,
    program: PathBuf,
    args: Vec<String>,
}

/// User plus system CPU time of the process's waited-for children so far, s.
#[cfg(unix)]
fn children_cpu_s() -> f64 {
    // SAFETY: `getrusage` fills the zeroed struct it is given and reads nothing else.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    unsafe { libc::getrusage(libc::RUSAGE_CHILDREN, &mut u) };
    let s = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    s(u.ru_utime) + s(u.ru_stime)
}

#[cfg(not(unix))]
fn children_cpu_s() -> f64 {
    f64::NAN
}

/// Runs `c` once; its CPU time, s, or why it failed.
fn run_once(c: &Config) -> Result<f64, String> {
    let before = children_cpu_s();
    let status = Command::new(&c.program)
        .args(&c.args)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .map_err(|e| format!("{}: {e}", c.program.display()))?;
    if !status.success() {
        return Err(format!("{} exited with {status}", c.name));
    }
    Ok(children_cpu_s() - before)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Whether `python3` can import scipy (the reference model's only need beyond numpy).
fn has_scipy() -> bool {
    Command::new("python3")
        .args(["-c", "import numpy, scipy"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// World steps of the clearance twin in a result set's `summary.json`.
fn steps(out: &Path) -> Option<u64> {
    let text = std::fs::read_to_string(out.join("summary.json")).ok()?;
    let v: serde_json::Value = serde_json::from_str(&text).ok()?;
    v["twins"]["clearance"]["steps"].as_u64()
}

fn main() {
    let runs: usize = std::env::args()
        .skip(1)
        .find_map(|a| a.parse().ok())
        .unwrap_or(5)
        .max(1);
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let scratch = std::env::temp_dir().join(format!("paper_cost_{}", std::process::id()));
    let app = PathBuf::from(env!("CARGO_BIN_EXE_clearance_joint"));
    let app_config = |name, extra: &[&str]| {
        let out = scratch.join(name);
        let mut args: Vec<String> = extra.iter().map(|s| s.to_string()).collect();
        args.extend([
            "--no-check".into(),
            "--out".into(),
            out.display().to_string(),
        ]);
        Config {
            name,
            program: app.clone(),
            args,
        }
    };
    let mut configs = vec![
        app_config("sub-cycled (default)", &[]),
        app_config("explicit", &["--set", "run.contact_integration=Explicit"]),
        app_config(
            "fixed 1e-4 s, explicit",
            &[
                "--set",
                "run.step=Fixed",
                "--set",
                "run.dt_s=1e-4",
                "--set",
                "run.contact_integration=Explicit",
            ],
        ),
    ];
    let script = root.join("benches/reference/solar_panel_rk45.py");
    if has_scipy() {
        configs.push(Config {
            name: "scipy RK45, rtol 1e-4",
            program: "python3".into(),
            args: vec![script.display().to_string()],
        });
    } else {
        eprintln!(
            "python3 with numpy and scipy not found: the RK45 row is skipped (pip install numpy scipy)"
        );
    }
    let mut cpu: Vec<Vec<f64>> = vec![Vec::new(); configs.len()];
    for k in 0..runs {
        for (c, samples) in configs.iter().zip(&mut cpu) {
            eprintln!("run {}/{runs}: {}", k + 1, c.name);
            match run_once(c) {
                Ok(t) => samples.push(t),
                Err(e) => eprintln!("  failed: {e}"),
            }
        }
    }
    let median_of = |name: &str| {
        configs
            .iter()
            .zip(&cpu)
            .find(|(c, s)| c.name == name && !s.is_empty())
            .map(|(_, s)| median(s.clone()))
    };
    let fixed = median_of("fixed 1e-4 s, explicit");
    let scipy = median_of("scipy RK45, rtol 1e-4");
    let ratio = |t: f64, of: Option<f64>| of.map_or("-".to_string(), |r| format!("{:.2}", t / r));
    let mut md = format!(
        "| configuration | world steps | CPU, whole process (s, median of {runs}) | of the fixed 1e-4 s run's | of the RK45 script's |\n|---|---|---|---|---|\n"
    );
    for (c, s) in configs.iter().zip(&cpu) {
        if s.is_empty() {
            md.push_str(&format!("| {} | failed | | | |\n", c.name));
            continue;
        }
        let t = median(s.clone());
        let n = steps(&scratch.join(c.name)).map_or("-".to_string(), |n| n.to_string());
        md.push_str(&format!(
            "| {} | {n} | {t:.3} | {} | {} |\n",
            c.name,
            ratio(t, fixed),
            ratio(t, scipy)
        ));
    }
    let _ = std::fs::remove_dir_all(&scratch);
    let dir = root.join("bench_out");
    if let Err(e) =
        std::fs::create_dir_all(&dir).and_then(|_| std::fs::write(dir.join("paper_cost.md"), &md))
    {
        eprintln!("cannot write bench_out/paper_cost.md: {e}");
    }
    println!("{md}");
}
