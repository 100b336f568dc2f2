//! Every invalid input named in DEVELOPERS.md gets a clear error naming the field, never a panic,
//! and a failed run leaves no result file behind.

use clearance_joint::Error;
use clearance_joint::scene::runner::{RunOptions, Simulation};
use clearance_joint::scene::{SOLAR_PANEL_RON, Scene};
use std::process::Command;

fn override_err(set: &[&str]) -> String {
    Scene::solar_panel()
        .with_overrides(set)
        .expect_err("must be refused")
        .to_string()
}

#[test]
fn non_positive_clearance() {
    for c in ["0", "-0.1"] {
        let e = override_err(&[&format!("hinge.clearance_mm={c}")]);
        assert!(
            e.contains("hinges[hinge].clearance.clearance_mm") && e.contains("> 0"),
            "{e}"
        );
    }
}

#[test]
fn journal_larger_than_bearing() {
    let e = override_err(&["hinge.clearance_mm=12"]);
    assert!(
        e.contains("clearance_mm") && e.contains("bearing radius"),
        "{e}"
    );
}

#[test]
fn nan_in_a_scene_file() {
    let text = SOLAR_PANEL_RON.replace("mass_kg: 7.68", "mass_kg: NaN");
    let e = Scene::from_ron(&text, "nan.ron").unwrap_err().to_string();
    assert!(
        e.contains("bodies[panel].mass_kg") && e.contains("NaN"),
        "{e}"
    );
}

#[test]
fn unknown_model_name() {
    let text = SOLAR_PANEL_RON.replace("contact: ImprovedLiu(", "contact: Improved(");
    let e = Scene::from_ron(&text, "bad.ron").unwrap_err().to_string();
    assert!(
        e.contains("bad.ron") && e.contains("Improved") && e.contains("ImprovedLiu"),
        "{e}"
    );
    let e = override_err(&["hinge.friction=Sticky"]);
    assert!(e.contains("Sticky") && e.contains("Lubricated"), "{e}");
}

#[test]
fn malformed_scene_file_names_the_position() {
    let text = SOLAR_PANEL_RON.replace("bodies: [", "bodies: [[");
    let e = Scene::from_ron(&text, "broken.ron").unwrap_err();
    assert!(matches!(e, Error::Parse { .. }));
    let e = e.to_string();
    assert!(
        e.contains("broken.ron") && e.chars().any(|c| c.is_ascii_digit()),
        "{e}"
    );
}

#[test]
fn unknown_override_path() {
    let e = override_err(&["hinge.clearence_mm=0.2"]);
    assert!(e.contains("clearence_mm"), "{e}");
    let e = override_err(&["wing.clearance_mm=0.2"]);
    assert!(e.contains("wing"), "{e}");
}

#[test]
fn bad_laws_parameters_are_named() {
    let e = override_err(&[r#"hinge.contact={"HuntCrossley":{"restitution":1.5}}"#]);
    assert!(
        e.contains("hinges[hinge].clearance.contact.restitution"),
        "{e}"
    );
    let e = override_err(&[
        r#"hinge.friction={"Bai":{"mu_s":0.3,"mu_d":0.25,"v_s_mm_s":10,"v_d_mm_s":0.1}}"#,
    ]);
    // The scene's field and unit, not the law's `v_d` in m/s.
    assert!(
        e.contains("hinges[hinge].clearance.friction.v_d_mm_s")
            && e.contains("`v_s_mm_s` = 10 mm/s"),
        "{e}"
    );
    let e = override_err(&["run.dt_s=-1e-4"]);
    assert!(e.contains("run.dt_s"), "{e}");
}

/// A shipped scene's text (`assets/<name>.ron`).
fn asset(name: &str) -> String {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../assets")
        .join(format!("{name}.ron"));
    std::fs::read_to_string(path).unwrap()
}

/// The slider-crank's crank, driven by `motion` instead of its spin.
fn slider_crank_driven_by(motion: &str) -> String {
    let spin =
        "Spin(axis: (0.0, 0.0, 1.0), point_m: (0.0, 0.0, 0.0), rate_rad_s: 523.5987755982989)";
    let text = asset("slider_crank");
    assert!(text.contains(spin));
    text.replace(spin, motion)
}

#[test]
fn motions_beyond_the_speed_guard_are_refused_at_load() {
    // Each moves the crank faster than the speed range (100 m/s, half the run-time guard's
    // 200 m/s): refused at load, naming the field, not a divergence blaming another body.
    for (motion, field) in [
        (
            "TableAngle(axis: (0.0, 0.0, 1.0), point_m: (0.0, 0.0, 0.0), t_s: [0.0, 1.0], angle_rad: [0.0, 1e300])",
            "bodies[crank].motion.angle_rad",
        ),
        (
            // 2e4 rad/s at 0.025 m is 500 m/s of the crank's centre of mass.
            "TableAngle(axis: (0.0, 0.0, 1.0), point_m: (0.0, 0.0, 0.0), t_s: [0.0, 1.0], angle_rad: [0.0, 9000.0])",
            "bodies[crank].motion.angle_rad",
        ),
        (
            "TablePosition(direction: (1.0, 0.0, 0.0), t_s: [0.0, 1.0], position_m: [0.0, 1e300])",
            "bodies[crank].motion.position_m",
        ),
        (
            "TablePosition(direction: (1.0, 0.0, 0.0), t_s: [0.0, 1.0], position_m: [-1e308, 1e308])",
            "bodies[crank].motion.position_m",
        ),
        (
            "Translate(velocity_m_s: (200.0, 0.0, 0.0))",
            "bodies[crank].motion.velocity_m_s",
        ),
        (
            // Each component in range, the speed (113 m/s) not.
            "Translate(velocity_m_s: (80.0, 80.0, 0.0))",
            "bodies[crank].motion.velocity_m_s",
        ),
        (
            // 1e4 rad/s is in range, but turns the centre of mass at 250 m/s.
            "Spin(axis: (0.0, 0.0, 1.0), point_m: (0.0, 0.0, 0.0), rate_rad_s: 1e4)",
            "bodies[crank].motion.rate_rad_s",
        ),
    ] {
        let e = Scene::from_ron(&slider_crank_driven_by(motion), "s.ron")
            .expect_err(motion)
            .to_string();
        assert!(e.contains(field), "{motion}: {e}");
    }
}

#[test]
fn the_largest_speeds_in_range_run() {
    // The largest `Translate` velocity and `LinearVelocity` target run without the speed guard
    // taking them for a blow-up (at 200 m/s, the old limit, both failed at once).
    let text = |kind_motor: &str, slider: &str| {
        format!(
            r#"Scene(name: "fast", gravity: (0.0, 0.0, 0.0), reference_axis: (0.0, 0.0, 1.0),
            bodies: [
                (name: "ground", mass_kg: 0.0, inertia_kg_m2: (0.0, 0.0, 0.0), center_of_mass_m: (0.0, 0.0, 0.0), fixed: true),
                (name: "slider", mass_kg: 1.0, inertia_kg_m2: (0.01, 0.01, 0.01), center_of_mass_m: (0.0, 0.0, 0.0){slider}),
                (name: "arm", mass_kg: 1.0, inertia_kg_m2: (0.01, 0.01, 0.01), center_of_mass_m: (0.0, -0.2, 0.0), velocity_m_s: (100.0, 0.0, 0.0)),
            ],
            hinges: [(name: "pin", bearing: "slider", journal: "arm", point_m: (0.0, 0.0, 0.0), axis: (0.0, 0.0, 1.0))],
            joints: [{kind_motor}],
            run: (dt_s: 1e-4, end_s: 0.01, output_interval_s: 1e-3, step: Fixed))"#
        )
    };
    let translate = text(
        "",
        ", motion: Some(Translate(velocity_m_s: (100.0, 0.0, 0.0)))",
    );
    let motor = text(
        r#"(name: "guide", body1: "ground", body2: "slider", point_m: (0.0, 0.0, 0.0),
            kind: Prismatic(axis: (1.0, 0.0, 0.0)),
            motor: Some(LinearVelocity(target_m_s: 100.0, factor: 1e8)))"#,
        ", velocity_m_s: (100.0, 0.0, 0.0)",
    );
    for (case, text) in [("Translate", translate), ("LinearVelocity", motor)] {
        let scene = Scene::from_ron(&text, "fast.ron").unwrap_or_else(|e| panic!("{case}: {e}"));
        let r = Simulation::new(&scene, RunOptions::default())
            .unwrap()
            .run()
            .unwrap_or_else(|e| panic!("{case}: {e}"));
        assert!(r.guards.is_clean(), "{case}: {:?}", r.guards.violations);
    }
}

#[test]
fn initial_velocities_of_bodies_that_do_not_move_by_themselves() {
    // A fixed body's or a driven body's velocity would be ignored: refused, naming the field.
    let text = asset("pendulum").replace(
        "center_of_mass_m: (0.0, 0.0, 0.0), fixed: true)",
        "center_of_mass_m: (0.0, 0.0, 0.0), fixed: true, velocity_m_s: (1.0, 0.0, 0.0))",
    );
    let e = Scene::from_ron(&text, "p.ron").unwrap_err().to_string();
    assert!(
        e.contains("bodies[ground].velocity_m_s") && e.contains("ignored"),
        "{e}"
    );
    let text = asset("slider_crank").replace(
        "rate_rad_s: 523.5987755982989)))",
        "rate_rad_s: 523.5987755982989)), angular_velocity_rad_s: (0.0, 0.0, 1.0))",
    );
    let e = Scene::from_ron(&text, "s.ron").unwrap_err().to_string();
    assert!(
        e.contains("bodies[crank].angular_velocity_rad_s") && e.contains("motion"),
        "{e}"
    );
}

#[test]
fn a_drive_spring_too_stiff_for_the_step() {
    let e = override_err(&["drive.stiffness_nm_per_deg=1e6"]);
    assert!(
        e.contains("drives[drive].stiffness_nm_per_deg")
            && e.contains("too stiff for the step")
            && e.contains("run.max_dt_s"),
        "{e}"
    );
    // The shipped springs are far from it.
    for name in ["solar_panel", "deployable_array"] {
        Scene::from_ron(&asset(name), "a.ron").unwrap();
    }
}

#[test]
fn a_divergence_names_the_body_as_the_scene_does() {
    // A free stone thrown down at 99 m/s (in range) under 100 g passes the guard's 200 m/s
    // after 0.1 s: the error names it as the scene does, not by its Rapier handle.
    let text = asset("pendulum")
        .replace("gravity: (0.0, -9.81, 0.0)", "gravity: (0.0, -1000.0, 0.0)")
        .replace(
            "    ],\n    hinges:",
            "        (name: \"stone\", mass_kg: 1.0, inertia_kg_m2: (0.01, 0.01, 0.01), center_of_mass_m: (1.0, 0.0, 0.0), velocity_m_s: (0.0, -99.0, 0.0)),\n    ],\n    hinges:",
        );
    assert!(text.contains("stone"));
    let scene = Scene::from_ron(&text, "p.ron")
        .unwrap()
        .with_overrides(&[
            "pivot.clearance=null",
            "run.end_s=0.2",
            "run.output_interval_s=0.01",
        ])
        .unwrap();
    match Simulation::new(&scene, RunOptions::default())
        .unwrap()
        .run()
    {
        Err(Error::Diverged { what, .. }) => {
            let reason = what.to_string();
            assert!(
                reason.contains("body `stone`")
                    && reason.contains("likely cause")
                    && !reason.contains("body ("),
                "{reason}"
            );
        }
        other => panic!("expected a divergence, got {:?}", other.map(|r| r.guards)),
    }
}

#[test]
fn step_too_large_for_the_contact_stiffness() {
    // The explicit joint's stability limit (a sub-cycled contact has none).
    let scene = Scene::solar_panel()
        .with_overrides(&[
            "run.contact_integration=Explicit",
            "run.step=Fixed",
            "run.dt_s=5e-4",
        ])
        .unwrap();
    let e = Simulation::new(&scene, RunOptions::default())
        .unwrap()
        .run()
        .unwrap_err();
    match &e {
        Error::StepTooLarge(l) => {
            assert_eq!(l.field(), "run.dt_s");
            assert!(l.dt_max() < 5e-4 && l.dt_max() > 1e-5, "{}", l.dt_max());
        }
        other => panic!("expected StepTooLarge, got {other}"),
    }
}

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_clearance_joint"))
}

#[test]
fn cli_refuses_without_writing_anything() {
    let dir = std::env::temp_dir().join(format!("cj-refused-{}", std::process::id()));
    // The explicit joint's step limit refuses the run.
    let out = bin()
        .args([
            "--set",
            "run.contact_integration=Explicit",
            "--set",
            "run.step=Fixed",
            "--dt",
            "1e-3",
            "--out",
        ])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("run.dt_s") && err.contains("too large"),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    assert!(
        !dir.exists() || std::fs::read_dir(&dir).unwrap().next().is_none(),
        "files left in {}",
        dir.display()
    );
}

#[test]
fn cli_writes_the_specified_files() {
    let dir = std::env::temp_dir().join(format!("cj-ok-{}", std::process::id()));
    let out = bin()
        .args(["--end", "0.2", "--out"])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let header = "t_s,satellite_angle_deg,satellite_rate_deg_s,panel_angle_deg,panel_rate_deg_s,hinge_angle_deg,\
                  hinge_rate_deg_s,hinge_force_n,hinge_ecc_u_mm,hinge_ecc_v_mm,hinge_penetration_um,hinge_contact";
    for twin in ["ideal", "clearance"] {
        let csv = std::fs::read_to_string(dir.join(format!("{twin}.csv"))).unwrap();
        let mut lines = csv.lines();
        assert_eq!(lines.next().unwrap(), header);
        let rows: Vec<&str> = lines.collect();
        assert_eq!(rows.len(), 2001, "one row per 0.1 ms from 0 to 0.2 s");
        assert!(!csv.contains("NaN") && !csv.contains("inf"));
    }
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    for key in [
        "steps",
        "wall_s",
        "final_angles_deg",
        "peak_joint_force_n",
        "onsets",
        "first_impact_t_s",
        "first_impact_peak_n",
        "max_penetration_um",
        "linear_momentum_drift",
        "angular_momentum_drift",
    ] {
        let v = &summary["twins"]["clearance"][key];
        assert!(v.is_number() || v.is_object(), "`{key}` is {v}");
    }
    // The first impact of the paper's scene comes at 0.0875 s, within the 0.2 s run.
    let t = summary["twins"]["clearance"]["first_impact_t_s"]
        .as_f64()
        .unwrap();
    assert!((t - 0.0875).abs() < 1e-3, "{t}");
    assert!(summary["twins"]["ideal"]["first_impact_t_s"].is_null());
    // No temporary files left behind.
    assert!(
        std::fs::read_dir(&dir).unwrap().all(|e| !e
            .unwrap()
            .file_name()
            .to_string_lossy()
            .starts_with('.'))
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn names_that_would_break_outputs() {
    let text = SOLAR_PANEL_RON.replace("name: \"hinge\"", "name: \"hin,ge\"");
    let e = Scene::from_ron(&text, "names.ron").unwrap_err().to_string();
    assert!(e.contains("hinges[hin,ge]") && e.contains("letters"), "{e}");
    let e = override_err(&["name=\"..\""]);
    assert!(e.contains("`name`"), "{e}");
}

#[test]
fn too_many_rows() {
    let e = override_err(&["run.end_s=1e4", "run.output_interval_s=1e-6"]);
    assert!(
        e.contains("run.output_interval_s") && e.contains("rows"),
        "{e}"
    );
}

#[test]
fn geometric_stiffness_only_for_exponent_one_and_a_half() {
    let e = override_err(&[r#"hinge.contact={"HuntCrossley":{"restitution":0.8,"exponent":1.0}}"#]);
    assert!(
        e.contains("hinges[hinge].clearance.contact.stiffness") && e.contains("1.5"),
        "{e}"
    );
    // With n = 1.5 the default applies; with an explicit stiffness any n is fine.
    Scene::solar_panel()
        .with_overrides(&[r#"hinge.contact={"HuntCrossley":{"restitution":0.8}}"#])
        .unwrap();
    Scene::solar_panel()
        .with_overrides(&[
            r#"hinge.contact={"HuntCrossley":{"restitution":0.8,"exponent":1.0,"stiffness":1e9}}"#,
        ])
        .unwrap();
}

#[test]
fn unlocked_out_of_plane_motion_in_a_scene() {
    let e = override_err(&["hinge.lock=None"]);
    assert!(e.contains("hinges[hinge].clearance.lock"), "{e}");
}

/// Issue 17, item 8: `merge` of two sweeps that differ only in `--end` says which setting
/// differs, not two identical dumps of the axes.
#[test]
fn merge_names_the_setting_that_differs() {
    let dir = std::env::temp_dir().join(format!("cj-merge-diff-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    for (shard, end) in [("0/2", "0.01"), ("1/2", "0.02")] {
        let o = bin()
            .args([
                "sweep",
                "--set",
                "hinge.clearance_mm=0.25,0.5",
                "--end",
                end,
            ])
            .args(["--shard", shard, "--progress", "quiet", "--out"])
            .arg(&dir)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let o = bin().arg("merge").arg(&dir).output().unwrap();
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(
        e.contains("fixed settings")
            && e.contains("run.end_s=1e-2")
            && e.contains("run.end_s=2e-2"),
        "{e}"
    );
    assert!(!e.contains("Axis {"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}
