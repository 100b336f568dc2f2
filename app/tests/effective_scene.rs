//! `summary.json` records the effective scene (`effective_scene`): the scene after every `--set`
//! override, defaults filled in, for `run` and for every point of a sweep and case of a study;
//! the recorded scene, run again from a scene file, gives the same run.

use clearance_joint::scene::Scene;
use clearance_joint_app::summary::{EFFECTIVE_SCENE, recorded_scene};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cj-effective-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// Runs the binary with `args` (quiet, and for `run` and `study` no figures, replay or check)
/// into `out`; must succeed.
fn app(args: &[&str], out: &Path) {
    let skip: &[&str] = match args.first() {
        Some(&"sweep") => &[],
        _ => &["--no-figures", "--no-replay", "--no-check"],
    };
    let o = Command::new(env!("CARGO_BIN_EXE_clearance_joint"))
        .args(args)
        .args(skip)
        .args(["--progress", "quiet", "--out"])
        .arg(out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

fn summary(dir: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap()
}

/// The summary without what differs between two identical runs (wall times) and without the
/// recorded scene itself.
fn results(mut s: Value) -> Value {
    let o = s.as_object_mut().unwrap();
    o.remove(EFFECTIVE_SCENE);
    for twin in o["twins"].as_object_mut().unwrap().values_mut() {
        twin["wall_s"] = Value::Null;
    }
    s
}

/// `run --set run.tolerance=0.002 --set hinge.friction=Lubricated --set hinge.clearance_mm=0.25`:
/// the summary's scene holds the overridden values, the `--end` and the defaults of fields the
/// scene file leaves out; that scene written as a scene file and run with no override gives
/// the same rows and the same summary.
#[test]
fn a_run_records_its_effective_scene_and_reruns_the_same() {
    let dir = scratch("run");
    let sets = [
        "--set",
        "run.tolerance=0.002",
        "--set",
        "hinge.friction=Lubricated",
        "--set",
        "hinge.clearance_mm=0.25",
    ];
    app(&[&["--end", "0.1"], &sets[..]].concat(), &dir.join("set"));
    let first = summary(&dir.join("set"));
    let scene = &first[EFFECTIVE_SCENE];
    assert_eq!(scene["run"]["tolerance"], 0.002);
    assert_eq!(scene["run"]["end_s"], 0.1);
    assert_eq!(scene["run"]["step"], "Adaptive");
    let clearance = &scene["hinges"][0]["clearance"];
    assert_eq!(clearance["friction"], "Lubricated");
    assert_eq!(clearance["clearance_mm"], 0.25);
    assert_eq!(clearance["model"], "Compliant");
    assert_eq!(
        scene["hinges"][0]["journal_offset_mm"],
        serde_json::json!([0.0, 0.0, 0.0])
    );
    assert!(first["twins"]["clearance"]["onsets"].as_u64().unwrap() > 0);

    let text = std::fs::read_to_string(dir.join("set/summary.json")).unwrap();
    let recorded = recorded_scene(&text, "summary.json").unwrap();
    let file = dir.join("recorded.ron");
    std::fs::write(&file, recorded.to_ron()).unwrap();
    app(&["--scene", file.to_str().unwrap()], &dir.join("file"));
    let second = summary(&dir.join("file"));
    assert_eq!(second[EFFECTIVE_SCENE], first[EFFECTIVE_SCENE]);
    assert_eq!(results(second), results(first));
    let rows = |d: &str| std::fs::read(dir.join(d).join("clearance.csv")).unwrap();
    assert_eq!(rows("file"), rows("set"), "the same rows");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A spatial hinge set on the command line is recorded with its whole model: the geometry
/// given and every field it defaults to, as the scene the same override builds; it reads back as
/// that scene.
#[test]
fn a_spatial_hinge_is_recorded_with_its_geometry() {
    let dir = scratch("spatial");
    let model = r#"hinge.model={"Spatial":{"geometry":{"axial_play":1e-4,"collar_radius":0.015}}}"#;
    app(&["--end", "0.01", "--set", model], &dir);
    let text = std::fs::read_to_string(dir.join("summary.json")).unwrap();
    let s: Value = serde_json::from_str(&text).unwrap();
    let recorded_model = &s[EFFECTIVE_SCENE]["hinges"][0]["clearance"]["model"];
    let geometry = &recorded_model["Spatial"]["geometry"];
    assert_eq!(geometry["axial_play"], 1e-4);
    assert_eq!(geometry["collar_radius"], 0.015);
    let expected = Scene::solar_panel()
        .with_overrides(&[model, "run.end_s=0.01"])
        .unwrap();
    let spec = expected.hinges[0].clearance.as_ref().unwrap().model;
    assert_eq!(*recorded_model, serde_json::to_value(spec).unwrap());
    let recorded = recorded_scene(&text, "summary.json").unwrap();
    assert_eq!(*recorded, expected);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Every point of a sweep records its own scene: the swept value and the fixed overrides.
#[test]
fn each_sweep_point_records_its_scene() {
    let dir = scratch("sweep");
    app(
        &[
            "sweep",
            "--set",
            "hinge.clearance_mm=0.25,0.5",
            "--set",
            "run.tolerance=0.002",
            "--end",
            "0.02",
        ],
        &dir,
    );
    for (point, c) in [
        ("000-hinge.clearance_mm=0.25", 0.25),
        ("001-hinge.clearance_mm=0.5", 0.5),
    ] {
        let scene = &summary(&dir.join("points").join(point))[EFFECTIVE_SCENE];
        assert_eq!(
            scene["hinges"][0]["clearance"]["clearance_mm"], c,
            "{point}"
        );
        assert_eq!(scene["run"]["tolerance"], 0.002, "{point}");
        assert_eq!(scene["run"]["end_s"], 0.02, "{point}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Every case of a study records its scene: the study's own setting per case, and `--set`.
#[test]
fn each_study_case_records_its_scene() {
    let dir = scratch("study");
    app(&["study", "friction", "--set", "run.end_s=0.02"], &dir);
    let points = dir.join("friction").join("points");
    let mut frictions: Vec<Value> = std::fs::read_dir(&points)
        .unwrap()
        .map(|case| {
            let scene = summary(&case.unwrap().path())[EFFECTIVE_SCENE].clone();
            assert_eq!(scene["run"]["end_s"], 0.02);
            scene["hinges"][0]["clearance"]["friction"].clone()
        })
        .collect();
    frictions.sort_by_key(|f| f.to_string());
    assert_eq!(frictions, ["Dry", "Lubricated"]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// A summary without a recorded scene is refused, naming the field.
#[test]
fn a_summary_without_a_scene_is_refused() {
    let e = recorded_scene(r#"{"scene": "solar_panel"}"#, "old/summary.json").unwrap_err();
    let message = e.to_string();
    assert!(
        message.contains("old/summary.json") && message.contains(EFFECTIVE_SCENE),
        "{message}"
    );
}
