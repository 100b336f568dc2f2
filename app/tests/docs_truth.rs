//! The docs' quoted figures against the commands that produce them: each documented command whose
//! output the README or a guide quotes is run here, and every quoted figure must be found both in
//! the doc and in the output (or the files the run wrote). A figure that moves fails this test
//! until the doc is re-measured; a doc edited away from its command fails it too.
//!
//! Timings (wall time, us per step) are not checked here: they are machine figures, measured by
//! the benchmarks.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The repository's root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// A doc's text with every run of whitespace made one space (docs wrap their lines anywhere).
fn flat(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

fn doc(path: &str) -> String {
    let p = root().join(path);
    flat(&std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display())))
}

/// Runs the app with `args` from the repository's root (so `assets/...` resolve), writing into
/// `out` unless `args` name an output folder; returns standard output and error, flattened.
fn run(args: &[&str], out: &Path) -> String {
    let mut c = Command::new(env!("CARGO_BIN_EXE_clearance_joint"));
    c.current_dir(root()).args(args);
    if !args.contains(&"--out") {
        c.arg("--out").arg(out);
    }
    let o = c.args(["--progress", "quiet"]).output().unwrap();
    flat(&format!(
        "{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    ))
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cj-docs-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// Asserts `quote` is in the doc `path` and `found` in `output` (the same figure as each writes
/// it: the doc may group digits, the console does not).
fn assert_quoted(path: &str, quote: &str, output: &str, found: &str) {
    assert!(
        doc(path).contains(&flat(quote)),
        "{path} no longer quotes `{quote}`: re-measure it and update this test"
    );
    assert!(
        output.contains(&flat(found)),
        "{path} quotes `{quote}`, but the command now gives:\n{output}"
    );
}

/// A quote that both the doc and the output write the same way.
fn assert_same(path: &str, quote: &str, output: &str) {
    assert_quoted(path, quote, output, quote);
}

/// The cells of the markdown table row whose first cell is `label`, in `path`.
fn table_row(path: &str, label: &str) -> Vec<String> {
    let text = std::fs::read_to_string(root().join(path)).unwrap();
    let line = text
        .lines()
        .find(|l| l.starts_with(&format!("| {label} |")))
        .unwrap_or_else(|| panic!("{path} has no table row `{label}`"));
    line.trim_matches('|')
        .split('|')
        .map(|c| c.trim().to_string())
        .collect()
}

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// The README's results of the default run (`cargo run --release`): its table against
/// `summary.json`, its step count against the console, and the replay's frames and size in the
/// guide's table against the page the same run wrote.
#[test]
fn the_default_run_is_as_the_readme_says() {
    let out = scratch("default");
    let console = run(&["--no-check"], &out);
    let summary: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let twin = |k: &str| &summary["twins"][k];
    let hinge = |k: &str| &summary["twins"][k]["hinges"]["hinge"];
    let angle = |k: &str, b: &str| format!("{:.4}", num(&twin(k)["final_angles_deg"][b]));
    let both = |label: &str, ideal: String, clear: String| {
        let row = table_row("README.md", label);
        assert_eq!(
            (row[1].as_str(), row[2].as_str()),
            (ideal.as_str(), clear.as_str()),
            "README's `{label}`: the run gives {ideal} | {clear}"
        );
    };
    both(
        "final deployment (hinge) angle, deg",
        angle("ideal", "hinge"),
        angle("clearance", "hinge"),
    );
    both(
        "final panel angle, deg",
        angle("ideal", "panel"),
        angle("clearance", "panel"),
    );
    both(
        "final satellite angle, deg",
        angle("ideal", "satellite"),
        angle("clearance", "satellite"),
    );
    both(
        "peak joint force, N",
        format!("{:.4}", num(&hinge("ideal")["peak_force_n"])),
        format!("{:.2}", num(&hinge("clearance")["peak_force_n"])),
    );
    both(
        "RMS joint force, N",
        format!("{:.4}", num(&hinge("ideal")["rms_force_n"])),
        format!("{:.3}", num(&hinge("clearance")["rms_force_n"])),
    );
    both(
        "onsets (contacts, chatter included)",
        "0".into(),
        hinge("clearance")["onsets"].to_string(),
    );
    both(
        "impacts (onsets after a free flight of at least 0.1 um)",
        "0".into(),
        hinge("clearance")["separated_impacts"].to_string(),
    );
    both(
        "first impact: time, peak force",
        "-".into(),
        format!(
            "{:.4} s, {:.2} N",
            num(&hinge("clearance")["first_impact_t_s"]),
            num(&hinge("clearance")["first_impact_peak_n"])
        ),
    );
    both(
        "max penetration, um",
        "0".into(),
        format!("{:.3}", num(&hinge("clearance")["max_penetration_um"])),
    );
    both(
        "time in contact",
        "-".into(),
        format!(
            "{:.2} %",
            100.0 * num(&hinge("clearance")["contact_fraction"])
        ),
    );
    let panel = &summary["comparison"]["bodies"]["panel"];
    both(
        "panel rate deviation from ideal, RMS / max, deg/s",
        "-".into(),
        format!(
            "{:.3} / {:.3}",
            num(&panel["rms_deg_s"]),
            num(&panel["max_deg_s"])
        ),
    );
    let drift = |k: &str| {
        format!(
            "{:.1e} / {:.1e}",
            num(&twin(k)["linear_momentum_drift"]),
            num(&twin(k)["angular_momentum_drift"])
        )
    };
    both(
        "linear / angular momentum drift",
        drift("ideal"),
        drift("clearance"),
    );
    let steps = twin("clearance")["steps"].as_u64().unwrap();
    let grouped = format!("{},{:03} steps", steps / 1000, steps % 1000);
    assert_quoted("README.md", &grouped, &console, &format!("{steps} steps"));

    // The guide's replay table, from the page this run wrote.
    let html = std::fs::read_to_string(out.join("replay.html")).unwrap();
    let data = &html[html.find("{\"title\"").unwrap()..];
    let data: Value = serde_json::Deserializer::from_str(data)
        .into_iter::<Value>()
        .next()
        .unwrap()
        .unwrap();
    let row = table_row(
        "docs/guide-scenes-and-app.md",
        "default run (`cargo run --release`, 5 s)",
    );
    let frames = data["t"].as_array().unwrap().len();
    assert_eq!(
        row[1..],
        [
            hinge("clearance")["onsets"].to_string(),
            frames.to_string(),
            format!("{:.2} MB", html.len() as f64 / 1e6),
        ],
        "the guide's replay row"
    );
    let _ = std::fs::remove_dir_all(&out);
}

/// Messages the docs quote, each with the command that gives it.
#[test]
fn quoted_messages_are_what_the_commands_print() {
    let out = scratch("messages");
    // The explicit joint's refusals and guards (a sub-cycled contact has no step limit and an
    // implicit friction), as the docs' commands say.
    let explicit = ["--set", "run.contact_integration=Explicit"];
    let refused = run(
        &[
            &explicit[..],
            &["--set", "run.step=Fixed", "--dt", "1e-3", "--end", "0.2"],
        ]
        .concat(),
        &out,
    );
    for quote in [
        "error: `run.dt_s` = 0.001 s is too large for the contact of joint `hinge` at t = 0.088 s: the explicit
step is stable only below 1.634e-4 s there (penetration 1.648 um, natural frequency 9486 rad/s,
damping ratio 0.2573). Use `run.dt_s` below 1.308e-4 s",
        "On the command line: `--dt 1.308e-4` (or smaller), or `--set run.step=Adaptive`.",
    ] {
        assert_same("docs/reliability.md", quote, &refused);
    }
    let negative = run(&["--dt", "-1e-4"], &out);
    assert_same(
        "docs/reliability.md",
        "invalid `run.dt_s`: must be > 0 (got -1e-4)",
        &negative,
    );
    let memory = run(&["--max-memory", "80M"], &out);
    for quote in [
        "50002 rows of 24 values and the replay (about 53.29 MB) would need about 139.6 MB",
        "`--no-replay` drops the replay",
    ] {
        assert_same("docs/reliability.md", quote, &memory);
    }
    let pendulum = run(
        &[
            &explicit[..],
            &["--scene", "assets/pendulum.ron", "--end", "0.3"],
        ]
        .concat(),
        &out,
    );
    assert_same(
        "docs/stepper-and-accuracy.md",
        "WARNING: joint `pivot`: the fixed step is longer than friction's limit near zero slip, worst \
         182.3 times it at t = 0.00644 s (step 2e-5 s, friction's limit 1.097e-7 s; 13516 states, \
         the first at t = 0.0064 s): stiction is a numerical chatter there; adaptive steps resolve it",
        &pendulum,
    );
    let _ = std::fs::remove_dir_all(&out);
}
