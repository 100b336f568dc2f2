//! The replay page in a real browser: a short run of the paper's scene writes `replay.html`;
//! headless Chromium opens it at the time of a row inside the first impact (`#t=...`), and the
//! page must raise no error, report that time and the eccentricity of the CSV row, and draw a
//! screenshot that is not blank; the same page with a script error must fail the error checks.

use std::path::{Path, PathBuf};
use std::process::Command;

const INSTALL: &str = "apt-get update && apt-get install -y chromium";

/// The browser: `$CHROMIUM`, else `chromium`, `chromium-browser` or `google-chrome` on the PATH.
/// `None` when none runs: the replay test is then skipped, with its reason written to the
/// console, so that `cargo test --release` passes on a machine without a browser; under CI
/// (`CI` set and not empty, `0` or `false`; `.ci/run` sets it and installs Chromium) a missing
/// browser fails the test instead.
fn chromium() -> Option<PathBuf> {
    let candidates: Vec<String> = std::env::var("CHROMIUM")
        .into_iter()
        .chain(["chromium", "chromium-browser", "google-chrome"].map(String::from))
        .collect();
    for c in &candidates {
        if let Ok(out) = Command::new(c).arg("--version").output()
            && out.status.success()
        {
            return Some(PathBuf::from(c));
        }
    }
    let reason = format!(
        "no Chromium found (tried {candidates:?}): the replay test needs a real browser; install \
         it with `{INSTALL}` (or set CHROMIUM to a Chromium/Chrome binary)"
    );
    let ci = std::env::var("CI").is_ok_and(|v| !matches!(v.trim(), "" | "0" | "false"));
    assert!(
        !ci,
        "{reason}; CI is set, so the replay must be checked in a browser"
    );
    // Written to the console itself, past the test harness's capture, so that a plain
    // `cargo test` shows why the test passed without a browser.
    use std::io::Write;
    let _ = writeln!(
        std::io::stderr(),
        "replay_opens_in_chromium_at_an_impact_and_matches_the_csv skipped: {reason}; with CI \
         set a missing browser fails it"
    );
    None
}

/// Runs headless Chromium on `url` with `args`; returns (stdout, stderr).
fn headless(browser: &Path, url: &str, args: &[&str], profile: &Path) -> (String, String) {
    let out = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--no-first-run",
            "--disable-extensions",
            "--hide-scrollbars",
            "--enable-logging=stderr",
            "--v=0",
            "--window-size=1400,1150",
            "--virtual-time-budget=20000",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .args(args)
        .arg(url)
        .output()
        .expect("chromium runs");
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    );
    assert!(out.status.success(), "chromium failed: {stderr}");
    (stdout, stderr)
}

/// Console messages in Chromium's log (`...:INFO:CONSOLE:...`, whatever the level, uncaught
/// exceptions included): the page writes none, so any is an error.
fn console_errors(stderr: &str) -> Vec<&str> {
    stderr
        .lines()
        .filter(|l| l.contains(":CONSOLE") || l.contains("Uncaught"))
        .collect()
}

fn csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

/// The page's status element (JSON), from the dumped DOM.
fn status_of(dom: &str) -> serde_json::Value {
    let start = dom.find("<pre id=\"status\">").expect("status element") + 17;
    let end = start + dom[start..].find("</pre>").unwrap();
    let text = dom[start..end]
        .replace("&quot;", "\"")
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&amp;", "&");
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("status is JSON ({e}): {text}"))
}

/// No two label boxes of one canvas (the page's `labels`, CSS pixels) intersect.
fn assert_labels_apart(status: &serde_json::Value) {
    let canvases = status["labels"].as_object().expect("labels in the status");
    assert!(
        canvases.contains_key("scene3d") && canvases.contains_key("inset0"),
        "{status}"
    );
    for (canvas, boxes) in canvases {
        let boxes = boxes.as_array().unwrap();
        let r = |b: &serde_json::Value, k: &str| b[k].as_f64().unwrap();
        for (i, a) in boxes.iter().enumerate() {
            for b in &boxes[i + 1..] {
                let overlap_x = r(a, "x") + r(a, "w") - r(b, "x") > 0.01
                    && r(b, "x") + r(b, "w") - r(a, "x") > 0.01;
                let overlap_y = r(a, "y") + r(a, "h") - r(b, "y") > 0.01
                    && r(b, "y") + r(b, "h") - r(a, "y") > 0.01;
                assert!(
                    !(overlap_x && overlap_y),
                    "labels overlap in {canvas}: {a} and {b}"
                );
            }
        }
    }
}

/// Runs the app with `args` and `--out dir`; panics with its stderr on failure.
fn run_app(args: &[&str], dir: &Path) {
    let out = Command::new(env!("CARGO_BIN_EXE_clearance_joint"))
        .args(args)
        .args(["--no-figures", "--no-check", "--progress", "quiet", "--out"])
        .arg(dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A spatial replay (the spatial panel's first impact): the page shows, at a CSV row's time in
/// contact, the row's tilt, axial offset, edge forces and mid-plane eccentricity; it plots the
/// tilt, and its labels do not overlap.
#[test]
fn spatial_replay_shows_the_csv_tilt_and_edge_forces() {
    let Some(browser) = chromium() else {
        return;
    };
    let dir = std::env::temp_dir().join(format!("cj-sreplay-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/solar_panel_spatial.ron");
    run_app(&["--scene", scene.to_str().unwrap(), "--end", "0.12"], &dir);
    let page = dir.join("replay.html");
    let (header, rows) = csv(&dir.join("clearance.csv"));
    let col = |name: &str| {
        header
            .iter()
            .position(|c| c == name)
            .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
    };
    let (tc, contact) = (col("t_s"), col("hinge_contact"));
    let edges = [
        col("hinge_edge_lower_force_n"),
        col("hinge_edge_upper_force_n"),
    ];
    // A row in contact with an edge loaded.
    let row = rows
        .iter()
        .find(|r| r[contact] == 1.0 && (r[edges[0]] > 1.0 || r[edges[1]] > 1.0))
        .expect("a row in edge contact");
    let t = row[tc];
    let url = format!("file://{}#t={t}", page.display());
    let (dom, log) = headless(&browser, &url, &["--dump-dom"], &dir.join("profile"));
    let errors = console_errors(&log);
    assert!(errors.is_empty(), "console errors: {errors:?}");
    let status = status_of(&dom);
    assert_eq!(
        status["errors"].as_array().map(Vec::len),
        Some(0),
        "{status}"
    );
    assert!(
        (status["t"].as_f64().unwrap() - t).abs() < 1e-12,
        "{status}"
    );
    let j = &status["clearance.hinge"];
    // The page's numbers carry 7 digits.
    let close = |page: f64, csv: f64, what: &str, abs: f64| {
        assert!(
            (page - csv).abs() <= 1e-5 * csv.abs() + abs,
            "{what}: page {page} vs CSV {csv} at t = {t}: {j}"
        );
    };
    let num = |v: &serde_json::Value| v.as_f64().unwrap_or_else(|| panic!("{v} in {j}"));
    close(
        num(&j["tilt_u_deg"]),
        row[col("hinge_tilt_u_deg")],
        "tilt u",
        1e-12,
    );
    close(
        num(&j["tilt_v_deg"]),
        row[col("hinge_tilt_v_deg")],
        "tilt v",
        1e-12,
    );
    close(
        num(&j["axial_mm"]),
        row[col("hinge_axial_mm")],
        "axial offset",
        1e-9,
    );
    for (k, c) in edges.iter().enumerate() {
        close(num(&j["edge_force_n"][k]), row[*c], "edge force", 1e-6);
    }
    close(
        num(&j["ecc_u_mm"]),
        row[col("hinge_ecc_u_mm")],
        "eccentricity u",
        1e-9,
    );
    close(
        num(&j["ecc_v_mm"]),
        row[col("hinge_ecc_v_mm")],
        "eccentricity v",
        1e-9,
    );
    assert!(
        status["labels"]["side0"]
            .as_array()
            .is_some_and(|l| !l.is_empty()),
        "{status}"
    );
    let plots = status["plots"].as_array().unwrap();
    assert!(
        plots
            .iter()
            .any(|p| p["title"].as_str().unwrap().contains("tilt")),
        "no tilt plot: {status}"
    );
    assert_labels_apart(&status);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn replay_opens_in_chromium_at_an_impact_and_matches_the_csv() {
    let Some(browser) = chromium() else {
        return;
    };
    let dir = std::env::temp_dir().join(format!("cj-replay-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    // The sub-cycled joint (the default): its frames and the CSV rows inside a world step read the
    // same sub-steps.
    let status = Command::new(env!("CARGO_BIN_EXE_clearance_joint"))
        .args([
            "--end",
            "0.12",
            "--no-figures",
            "--no-check",
            "--progress",
            "quiet",
            "--out",
        ])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    let page = dir.join("replay.html");
    let html = std::fs::read_to_string(&page).expect("replay.html written beside the CSVs");
    assert!(
        !html.contains("http://") && !html.contains("https://") && !html.contains(" src="),
        "the page must load nothing from outside"
    );

    // A row inside the first impact: the first row after its onset.
    let (ih, impacts) = csv(&dir.join("clearance_hinge_impacts.csv"));
    let onset_col = ih.iter().position(|c| c == "onset_t_s").unwrap();
    let onset = impacts[0][onset_col];
    let (header, rows) = csv(&dir.join("clearance.csv"));
    let col = |name: &str| header.iter().position(|c| c == name).unwrap();
    let (tc, eu, ev, contact) = (
        col("t_s"),
        col("hinge_ecc_u_mm"),
        col("hinge_ecc_v_mm"),
        col("hinge_contact"),
    );
    let row = rows
        .iter()
        .find(|r| r[tc] > onset && r[contact] == 1.0)
        .expect("a row in contact after the first onset");
    let t = row[tc];
    let url = format!("file://{}#t={t}", page.display());
    let profile = dir.join("profile");

    let (dom, log) = headless(&browser, &url, &["--dump-dom"], &profile);
    let errors = console_errors(&log);
    assert!(errors.is_empty(), "console errors: {errors:?}");
    let status = status_of(&dom);
    assert_eq!(status["ready"], true, "{status}");
    assert_eq!(
        status["errors"].as_array().map(Vec::len),
        Some(0),
        "{status}"
    );
    assert!(status["impacts"].as_u64().unwrap() >= 1, "{status}");
    let shown_t = status["t"].as_f64().unwrap();
    assert!((shown_t - t).abs() < 1e-12, "page time {shown_t} vs {t}");
    let j = &status["clearance.hinge"];
    let (pu, pv) = (
        j["ecc_u_mm"].as_f64().unwrap(),
        j["ecc_v_mm"].as_f64().unwrap(),
    );
    // Same states, same linear interpolation (1.8e-8 mm apart here); the page's numbers carry 7
    // digits.
    for (page_mm, csv_mm, what) in [(pu, row[eu], "u"), (pv, row[ev], "v")] {
        assert!(
            (page_mm - csv_mm).abs() < 1e-5,
            "eccentricity {what}: page {page_mm} mm vs CSV {csv_mm} mm at t = {t}"
        );
    }
    assert_eq!(j["contact"], true, "{j}");
    assert!(
        j.get("tilt_u_deg").is_none(),
        "a planar journal shows no tilt: {j}"
    );
    assert_labels_apart(&status);
    // The run's peak (every step) is the page's: the inset's largest force and the force
    // plot's top, to the page's 7 digits; neither is the rows' lower maximum.
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    let peak = summary["twins"]["clearance"]["hinges"]["hinge"]["peak_force_n"]
        .as_f64()
        .unwrap();
    let rows_max = rows
        .iter()
        .map(|r| r[col("hinge_force_n")])
        .fold(0.0, f64::max);
    assert!(rows_max < peak * (1.0 - 1e-4), "rows {rows_max} vs {peak}");
    let largest = j["largest_force_n"].as_f64().unwrap();
    assert!(
        (largest / peak - 1.0).abs() < 1e-6,
        "inset {largest} N vs summary {peak} N"
    );
    let plots = status["plots"].as_array().unwrap();
    let force_plot = plots
        .iter()
        .find(|p| p["title"].as_str().unwrap().contains("joint force"))
        .expect("a force plot");
    let plotted = force_plot["lines"]
        .as_array()
        .unwrap()
        .iter()
        .find(|l| l["group"] == "clearance")
        .unwrap()["max"]
        .as_f64()
        .unwrap();
    assert!(
        (plotted / peak - 1.0).abs() < 1e-6,
        "plot {plotted} N vs summary {peak} N"
    );

    // A screenshot that is not blank: many distinct colours and a real spread of brightness.
    let shot = dir.join("replay.png");
    let (_, log) = headless(
        &browser,
        &url,
        &[&format!("--screenshot={}", shot.display())],
        &profile,
    );
    assert!(console_errors(&log).is_empty(), "console errors: {log}");
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&shot).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    let channels = info.color_type.samples();
    let pixels: Vec<&[u8]> = buf[..info.buffer_size()].chunks(channels).collect();
    let luma: Vec<f64> = pixels
        .iter()
        .map(|p| 0.299 * p[0] as f64 + 0.587 * p[1] as f64 + 0.114 * p[2] as f64)
        .collect();
    let mean = luma.iter().sum::<f64>() / luma.len() as f64;
    let var = luma.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / luma.len() as f64;
    let colours: std::collections::HashSet<&[u8]> = pixels.iter().copied().collect();
    assert!(
        var > 100.0 && colours.len() > 200,
        "blank screenshot? luma variance {var}, {} colours",
        colours.len()
    );
    // The error checks fire: the same page with a script error.
    let broken = dir.join("broken.html");
    std::fs::write(
        &broken,
        html.replacen("</body>", "<script>null.boom();</script></body>", 1),
    )
    .unwrap();
    let (dom, log) = headless(
        &browser,
        &format!("file://{}#t={t}", broken.display()),
        &["--dump-dom"],
        &profile,
    );
    assert!(
        !console_errors(&log).is_empty(),
        "no console error seen: {log}"
    );
    let status = status_of(&dom);
    assert!(
        status["errors"].as_array().is_some_and(|e| !e.is_empty()),
        "the page's error list misses it: {status}"
    );
    // Recording changes nothing in the run; without it no replay is left behind.
    let clear = std::fs::read(dir.join("clearance.csv")).unwrap();
    let run = Command::new(env!("CARGO_BIN_EXE_clearance_joint"))
        .args([
            "--end",
            "0.12",
            "--no-figures",
            "--no-replay",
            "--no-check",
            "--progress",
            "quiet",
            "--out",
        ])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert_eq!(std::fs::read(dir.join("clearance.csv")).unwrap(), clear);
    assert!(!page.exists(), "a stale replay.html stayed");
    // Kept for a look (target/replay-test.png).
    let keep = Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/replay-test.png");
    let _ = std::fs::copy(&shot, keep);
    let _ = std::fs::remove_dir_all(&dir);
}

/// A study writes each case's replay in its folder and links it from its report; a rerun
/// without replays removes them and the links.
#[test]
fn study_cases_have_replays_linked_from_the_report() {
    use clearance_joint::scene::Scene;
    use clearance_joint_app::study::sweep::{ExecOptions, Progress};
    use clearance_joint_app::study::{StudyOptions, run_studies, select};
    let root = std::env::temp_dir().join(format!("cj-replay-study-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    let paper = Scene::solar_panel();
    let run = |replay: bool| {
        let options = StudyOptions {
            exec: ExecOptions {
                progress: Progress::Quiet,
                replay,
                rerun: true,
                ..Default::default()
            },
            extra_overrides: vec!["run.end_s=0.1".into()],
            no_figures: true,
        };
        run_studies(
            &select(&paper, "friction").unwrap(),
            &paper,
            &root,
            &options,
        )
        .unwrap()
    };
    let outcomes = run(true);
    let report = std::fs::read_to_string(&outcomes[0].report).unwrap();
    assert!(report.contains("## Replays"), "{report}");
    for case in &outcomes[0].cases {
        assert!(case.dir.join("replay.html").is_file(), "{:?}", case.dir);
        let link = case
            .dir
            .strip_prefix(&outcomes[0].dir)
            .unwrap()
            .join("replay.html");
        assert!(report.contains(&*link.to_string_lossy()), "{report}");
    }
    let outcomes = run(false);
    let report = std::fs::read_to_string(&outcomes[0].report).unwrap();
    assert!(!report.contains("## Replays"), "{report}");
    assert!(
        outcomes[0]
            .cases
            .iter()
            .all(|c| !c.dir.join("replay.html").exists())
    );
    let _ = std::fs::remove_dir_all(&root);
}

/// Without a browser the replay test is skipped with its reason printed, unless `CI` is set:
/// there it fails. Runs this test binary's replay test with no browser to find (`CHROMIUM` a
/// missing file, an empty `PATH`), once without `CI` and once with `CI=true`.
#[test]
fn without_chromium_the_replay_test_is_skipped_except_under_ci() {
    let empty = std::env::temp_dir().join(format!("cj-no-chromium-{}", std::process::id()));
    std::fs::create_dir_all(&empty).unwrap();
    let run = |ci: Option<&str>| {
        let mut cmd = Command::new(std::env::current_exe().unwrap());
        cmd.args([
            "replay_opens_in_chromium_at_an_impact_and_matches_the_csv",
            "--exact",
            "--nocapture",
        ])
        .env("CHROMIUM", empty.join("chromium"))
        .env("PATH", &empty)
        .env_remove("CI");
        if let Some(ci) = ci {
            cmd.env("CI", ci);
        }
        let out = cmd.output().unwrap();
        let text = format!(
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        (out.status.success(), text)
    };
    let (ok, text) = run(None);
    assert!(
        ok && text.contains("1 passed") && text.contains("skipped: no Chromium found"),
        "without CI a missing browser skips the test, saying why: {text}"
    );
    for ci in ["true", "1"] {
        let (ok, text) = run(Some(ci));
        assert!(
            !ok && text.contains("no Chromium found") && text.contains("CI is set"),
            "under CI={ci} a missing browser fails the test: {text}"
        );
    }
    let (ok, _) = run(Some("false"));
    assert!(ok, "CI=false is not CI");
    let _ = std::fs::remove_dir_all(&empty);
}
