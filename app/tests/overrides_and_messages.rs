//! Issue 33 (faults and bad input, third round): overrides that would overwrite one another are
//! refused naming both, and refusals and notes say what to change: a negative torque scale, CSV
//! tables given to `merge`, `--dt` under adaptive steps.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cj-issue33-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// The binary with `args`, its output in `out`.
fn app(args: &[&str], out: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_clearance_joint"))
        .args(args)
        .args(["--progress", "quiet", "--out"])
        .arg(out)
        .output()
        .unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Refused with a message holding every one of `parts`, before anything is written to `out`.
fn assert_refused(o: &Output, out: &Path, parts: &[&str]) {
    let e = stderr(o);
    assert!(!o.status.success(), "must be refused: {e}");
    assert!(!e.contains("panicked"), "{e}");
    for p in parts {
        assert!(e.contains(p), "`{p}` missing from: {e}");
    }
    assert!(!out.exists(), "{} written", out.display());
}

fn asset(name: &str) -> String {
    format!("{}/../assets/{name}", env!("CARGO_MANIFEST_DIR"))
}

const LAWS: &str =
    r#"hinge.contact={"ImprovedLiu":{"exponent":1.0}},{"ImprovedLiu":{"exponent":1.5}}"#;

/// A law axis and an axis of a field inside the law, in either order: the later would overwrite
/// the earlier at every point (the points labelled 1.0 and 1.5 ran identical), so the sweep is
/// refused naming both paths and what to do.
#[test]
fn nested_sweep_axes_are_refused_naming_both() {
    let out = scratch("nested-law");
    for axes in [
        ["--set", LAWS, "--set", "hinge.exponent=2,2.5"],
        ["--set", "hinge.exponent=2,2.5", "--set", LAWS],
    ] {
        let mut args = vec!["sweep"];
        args.extend(axes);
        args.extend(["--end", "0.2"]);
        let o = app(&args, &out);
        assert_refused(
            &o,
            &out,
            &[
                "axes `hinge.",
                "are nested",
                "`hinge.exponent` sets `hinges[hinge].clearance.contact.ImprovedLiu.exponent`",
                "inside `hinge.contact`'s value",
                "Sweep one of them, or give the field inside each value of `hinge.contact`",
            ],
        );
    }
}

/// A model axis beside an axis of the axial play inside the spatial model, even when only some
/// of the model's values hold that field.
#[test]
fn a_model_axis_beside_its_axial_play_is_refused() {
    let out = scratch("nested-model");
    let scene = asset("solar_panel_spatial.ron");
    let spatial = r#"{"Spatial":{"geometry":{"axial_play":0.2e-3,"collar_radius":0.015}}}"#;
    let wider = r#"{"Spatial":{"geometry":{"axial_play":0.1e-3,"collar_radius":0.02}}}"#;
    for models in [
        format!("hinge.model={spatial},{wider}"),
        format!("hinge.model=Compliant,{spatial}"),
    ] {
        let args = [
            "sweep",
            "--scene",
            &scene,
            "--set",
            &models,
            "--set",
            "hinge.axial_play=1e-4,3e-4",
            "--end",
            "0.05",
        ];
        let o = app(&args, &out);
        assert_refused(
            &o,
            &out,
            &[
                "axes `hinge.model` and `hinge.axial_play` are nested",
                "hinges[hinge].clearance.model.Spatial.geometry.axial_play",
                "give the field inside each value of `hinge.model`",
            ],
        );
    }
}

/// `run --set hinge.exponent=1.5 --set hinge.contact=...`: the law replaces the exponent whole,
/// so the first override would be lost; refused naming both and the order that works (a field
/// after its law is set inside it, and the same field twice is the later value: the library's
/// unit tests).
#[test]
fn run_refuses_an_override_a_later_one_replaces() {
    let out = scratch("run-lost");
    let law = r#"hinge.contact={"ImprovedLiu":{"exponent":1.0,"delta_max_mm":0.1,"eta_s":0.01}}"#;
    let args = ["--set", "hinge.exponent=1.5", "--set", law, "--end", "0.01"];
    let o = app(&args, &out);
    assert_refused(
        &o,
        &out,
        &[
            "invalid `hinge.exponent`: its value would be lost",
            "the later override of `hinge.contact` replaces whole",
            "Give `hinge.contact` first and `hinge.exponent` after it",
        ],
    );
    // A study's `--set`s alike (they replace the study's own settings freely).
    let out = scratch("study-lost");
    let study = [
        "study",
        "clearance",
        "--set",
        "hinge.exponent=1.5",
        "--set",
        law,
        "--no-figures",
    ];
    let o = app(&study, &out);
    assert_refused(
        &o,
        &out,
        &["invalid `hinge.exponent`: its value would be lost"],
    );
}

/// A study's `--set` of the field its cases sweep was ignored at every case; now refused.
#[test]
fn a_study_setting_its_swept_field_is_refused() {
    let out = scratch("study-swept");
    let args = [
        "study",
        "torque",
        "--set",
        "drive.torque_scale=2",
        "--set",
        "run.end_s=0.01",
        "--no-figures",
        "--no-replay",
        "--no-check",
    ];
    let o = app(&args, &out);
    assert_refused(
        &o,
        &out,
        &[
            "invalid `drive.torque_scale=2`: this fixed setting",
            "overwritten at every point of `torque` by the swept `drive.torque_scale`",
        ],
    );
}

/// A negative torque scale is refused naming `torque_scale` (the field given) and its range, not
/// the stiffness it scales.
#[test]
fn a_negative_torque_scale_names_torque_scale() {
    let out = scratch("torque-scale");
    let o = app(&["--set", "drive.torque_scale=-5", "--end", "0.01"], &out);
    assert_refused(
        &o,
        &out,
        &[
            "invalid `drives[drive].torque_scale`",
            "must be 0 to 1000",
            "got -5",
        ],
    );
    assert!(!stderr(&o).contains("`drives[drive].stiffness_nm_per_deg`"));
}

/// `merge` given a shard's CSV table says it reads the JSON, and names the file and folder to
/// pass instead.
#[test]
fn merge_of_a_csv_table_says_what_to_pass() {
    let dir = scratch("merge-csv");
    let args = [
        "sweep",
        "--set",
        "hinge.clearance_mm=0.25,0.5",
        "--end",
        "0.01",
        "--shard",
        "0/2",
    ];
    let o = app(&args, &dir);
    assert!(o.status.success(), "{}", stderr(&o));
    let csv = dir.join("metrics.shard-0-of-2.csv");
    let o = Command::new(env!("CARGO_BIN_EXE_clearance_joint"))
        .arg("merge")
        .arg(&csv)
        .output()
        .unwrap();
    let e = stderr(&o);
    assert!(!o.status.success());
    let json = dir.join("metrics.shard-0-of-2.json");
    for part in [
        format!("`{}`", csv.display()),
        "is a CSV table".into(),
        format!("pass `{}` instead", json.display()),
        format!("the sweep folder `{}`", dir.display()),
    ] {
        assert!(e.contains(&part), "`{part}` missing from: {e}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--dt` under adaptive steps is noted as unused with the flags that act instead; under fixed
/// steps it is used and not noted (and `--max-dt` under fixed steps is noted alike).
#[test]
fn dt_under_adaptive_steps_is_noted() {
    let quick = ["--end", "0.01", "--no-figures", "--no-replay", "--no-check"];
    let run = |args: &[&str], name: &str| {
        let out = scratch(name);
        let o = app(&[args, &quick[..]].concat(), &out);
        assert!(o.status.success(), "{}", stderr(&o));
        let _ = std::fs::remove_dir_all(&out);
        stderr(&o)
    };
    let e = run(&["--dt", "5e-5"], "dt-adaptive");
    assert!(
        e.contains("note: `--dt` sets the fixed step (`run.dt_s`)")
            && e.contains("steps adaptively")
            && e.contains("not used")
            && e.contains("--set run.tolerance=")
            && e.contains("--max-dt")
            && e.contains("--set run.step=Fixed"),
        "{e}"
    );
    let e = run(&["--set", "run.step=Fixed", "--dt", "5e-5"], "dt-fixed");
    assert!(!e.contains("note: `--dt`"), "{e}");
    let e = run(
        &["--set", "run.step=Fixed", "--max-dt", "1e-3"],
        "max-dt-fixed",
    );
    assert!(
        e.contains("note: `--max-dt` caps adaptive steps") && e.contains("--set run.step=Adaptive"),
        "{e}"
    );
    // A sweep says it once, and not when an axis sets the step mode.
    let sweep = |extra: &[&str], name: &str| {
        let out = scratch(name);
        let mut args = vec!["sweep", "--set", "hinge.clearance_mm=0.25", "--dt", "5e-5"];
        args.extend(extra);
        args.extend(["--end", "0.01"]);
        let o = app(&args, &out);
        assert!(o.status.success(), "{}", stderr(&o));
        let _ = std::fs::remove_dir_all(&out);
        stderr(&o)
    };
    assert_eq!(sweep(&[], "dt-sweep").matches("note: `--dt`").count(), 1);
    let e = sweep(&["--set", "run.step=Fixed,Adaptive"], "dt-sweep-modes");
    assert!(!e.contains("note: `--dt`"), "{e}");
}
