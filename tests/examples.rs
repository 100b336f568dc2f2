//! The examples (examples/*.rs) run as tests two ways: their `run` functions are compiled into
//! this test and their numbers checked, and their binaries are run as a user would run them.

use clearance_joint::scene::Scene;
use clearance_joint::scene::runner::{RunOptions, Simulation, TwinKind, Twins};
use std::path::PathBuf;
use std::process::Command;

#[allow(dead_code)]
#[path = "../examples/door_hinge.rs"]
mod door_hinge;
#[allow(dead_code)]
#[path = "../examples/drop_in.rs"]
mod drop_in;
#[cfg(feature = "ecs")]
#[allow(dead_code)]
#[path = "../examples/ecs.rs"]
mod ecs;
#[allow(dead_code)]
#[path = "../examples/game_rate.rs"]
mod game_rate;
#[allow(dead_code)]
#[path = "../examples/robot_backlash.rs"]
mod robot_backlash;
#[allow(dead_code)]
#[path = "../examples/solar_panel.rs"]
mod solar_panel;

#[test]
fn drop_in_converts_the_elbow_and_the_arm_rattles() {
    let runs = drop_in::run().unwrap();
    let (ideal, clear) = &runs;
    assert_eq!(ideal.onsets, 0);
    assert_eq!(ideal.max_penetration_um, 0.0);
    assert!(clear.onsets > 10, "{} onsets", clear.onsets);
    // The swing barely changes; the joint force becomes impulsive.
    assert!(
        (ideal.shoulder_deg - clear.shoulder_deg).abs() < 1.0,
        "{} vs {}",
        ideal.shoulder_deg,
        clear.shoulder_deg
    );
    assert!(
        ideal.shoulder_deg < -20.0,
        "the arm swung through the vertical"
    );
    assert!(
        clear.peak_elbow_force_n > 10.0 * ideal.peak_elbow_force_n,
        "{} vs {}",
        clear.peak_elbow_force_n,
        ideal.peak_elbow_force_n
    );
    // The lower link (0.5 kg) swinging: its ideal elbow load is a few times its weight.
    assert!(ideal.peak_elbow_force_n > 4.9 && ideal.peak_elbow_force_n < 20.0);
    // The lower link's momentum balance sees exactly the contact force the joint reports.
    assert!(
        (clear.peak_elbow_force_n - clear.peak_contact_force_n).abs()
            < 1e-6 * clear.peak_contact_force_n,
        "{} vs {}",
        clear.peak_elbow_force_n,
        clear.peak_contact_force_n
    );
    assert_eq!(ideal.peak_contact_force_n, 0.0);
    let text = drop_in::report(&runs);
    for needle in ["ideal", "clearance", "peak elbow force (N)", "elbow onsets"] {
        assert!(text.contains(needle), "{text}");
    }
}

#[cfg(feature = "ecs")]
#[test]
fn ecs_swap_is_the_plain_api_run() {
    // The ECS layer is thin: the arm with a ClearanceHinge steps exactly like drop_in's arm
    // converted with the plain API (same Rapier calls in the same order).
    let runs = ecs::run().unwrap();
    let plain = drop_in::clearance_run().unwrap();
    let [ideal, clear, swapped] = &runs;
    use clearance_joint::ecs::HingeMode;
    assert_eq!(ideal.elbow.mode, HingeMode::Ideal);
    assert_eq!(clear.elbow.mode, HingeMode::Clearance);
    assert_eq!(swapped.elbow.mode, HingeMode::Clearance);
    assert_eq!(ideal.shoulder.mode, HingeMode::Ideal);
    assert_eq!(ideal.elbow.onsets, 0);
    assert_eq!(clear.elbow.onsets, plain.onsets);
    assert!(clear.elbow.impacts > 0 && clear.elbow.impacts <= clear.elbow.onsets);
    assert_eq!(clear.elbow.peak_force, plain.peak_contact_force_n);
    assert!((clear.shoulder.angle.to_degrees() - plain.shoulder_deg).abs() < 1e-9);
    assert!((clear.elbow.angle.to_degrees() - plain.elbow_deg).abs() < 1e-9);
    // Swapped while running: ideal until half time, then rattling.
    assert!(swapped.elbow.onsets > 0);
    let text = ecs::report(&runs);
    assert!(
        text.contains("swapped@0.5s") && text.contains("Clearance"),
        "{text}"
    );
}

#[test]
fn solar_panel_in_code_is_the_scene_file() {
    let outcomes = solar_panel::run().unwrap();
    let (ideal, clear) = &outcomes;
    // The same scene through the runner, at the same fixed step.
    let scene = Scene::solar_panel()
        .with_overrides(&["run.step=Fixed", "run.dt_s=1e-4", "run.end_s=5"])
        .unwrap();
    let r = Simulation::new(
        &scene,
        RunOptions {
            twins: Twins::Both,
            skip_rows: false,
        },
    )
    .unwrap()
    .run()
    .unwrap();
    for (kind, o) in [(TwinKind::Ideal, ideal), (TwinKind::Clearance, clear)] {
        let twin = r.twin(kind).unwrap();
        let angles = twin.final_angles_deg();
        let m = &twin.hinge_metrics()["hinge"];
        let close = |a: f64, b: f64, what: &str| {
            assert!(
                (a - b).abs() <= 1e-9 * b.abs().max(1.0),
                "{kind:?} {what}: {a} vs {b}"
            )
        };
        close(o.deployment_deg, angles["hinge"], "deployment");
        close(o.panel_deg, angles["panel"], "panel angle");
        close(o.satellite_deg, angles["satellite"], "satellite angle");
        close(o.peak_force_n, m.peak_force_n, "peak force");
        assert_eq!(o.onsets, m.onsets, "{kind:?} onsets");
    }
    // The paper's conclusion 1: angles barely change, the joint force becomes impulsive.
    assert!((ideal.deployment_deg - clear.deployment_deg).abs() < 0.5);
    assert!(clear.peak_force_n > 100.0 * ideal.peak_force_n);
    assert!(clear.onsets > 100);
    assert!(clear.linear_momentum_drift < 1e-9 && clear.angular_momentum_drift < 1e-9);
    let text = solar_panel::report(&outcomes);
    assert!(text.contains("final deployment angle (deg)"), "{text}");
}

#[test]
fn game_rate_sign_rattles_within_its_play_at_60_hz() {
    let runs = game_rate::run().unwrap();
    let game_rate::Runs {
        ideal,
        play,
        capped,
    } = &runs;
    // Rapier's defaults: 1/60 s and four solver iterations.
    assert_eq!(play.dt, 1.0 / 60.0);
    assert_eq!(play.iterations, 4);
    // The play holds: the pin stays within 10 % of its clearance at every step's end.
    assert!(
        play.max_eccentricity_ratio > 1.0 && play.max_eccentricity_ratio < 1.1,
        "{}",
        play.max_eccentricity_ratio
    );
    // It rattles on the cobbles and rests once the cart stops, carrying the sign's weight.
    assert!(play.bounces_rolling > 10, "{}", play.bounces_rolling);
    assert_eq!(play.bounces_stopped, 0);
    assert!(
        (play.final_force_n - 2.0 * 9.81).abs() < 1e-6,
        "{}",
        play.final_force_n
    );
    // Nothing drives the sign after the stop: its energy never rises (1e-9 J tolerance on a
    // swing of about 0.08 J), and friction takes the swing.
    for r in [ideal, play, capped] {
        assert!(r.max_energy_rise_j < 1e-9, "{}", r.max_energy_rise_j);
    }
    assert!(play.energy_at_stop_j > 0.01);
    assert!(play.final_swing_deg < 0.1 * play.max_swing_deg);
    // The swing itself barely changes.
    assert!((play.max_swing_deg - ideal.max_swing_deg).abs() < 2.0);
    // Capped at Rapier's four substeps it is cheaper and says it is under-resolved.
    assert_eq!(capped.max_substeps, 4);
    assert!(capped.under_resolved > 0);
    assert!(play.mean_substeps > capped.mean_substeps);
    // What the README quotes of this run.
    readme_quotes(&format!(
        "rattles ({} bounces while rolling)",
        play.bounces_rolling
    ));
    readme_quotes(&format!(
        "stays within {:.1} % of its clearance and carries {:.4} N once at rest",
        100.0 * (play.max_eccentricity_ratio - 1.0),
        play.final_force_n
    ));
    let text = game_rate::report(&runs);
    assert!(
        text.contains("largest |e|/c") && text.contains("play@4"),
        "{text}"
    );
}

#[test]
fn robot_backlash_shows_the_tracking_error_of_the_play() {
    let o = robot_backlash::run().unwrap();
    // The pins rattle at every load turn-over and stay in their play.
    assert!(o.bounces[0] > 5 && o.bounces[1] > 5, "{:?}", o.bounces);
    for r in o.max_eccentricity_ratio {
        assert!(r > 0.99 && r < 1.1, "{r}");
    }
    // The play moves the hand off the ideal arm's by about the play of two pins (0.1 mm each,
    // levered by the links) and more in the rattle.
    assert!(
        o.play_effect_mm.0 > 0.05 && o.play_effect_mm.1 < 2.0,
        "{:?}",
        o.play_effect_mm
    );
    readme_quotes(&format!(
        "the play moves the hand {:.3} mm RMS and {:.3} mm at most off the ideal arm's",
        o.play_effect_mm.0, o.play_effect_mm.1
    ));
    assert!(o.play_effect_mm.1 > 0.2, "{:?}", o.play_effect_mm);
    assert_eq!(o.under_resolved, 0);
    let text = robot_backlash::report(&o);
    assert!(text.contains("hand off the ideal arm's"), "{text}");
}

/// The gate on one pin: the planar joint's lock holds the weight's moment, so the panel swings on
/// freely; the spatial joint tilts until the bore's edges hold the moment, sags, knocks the face,
/// and its edge friction stops the swing. Once the swing has died down, the moments of the bore's
/// and the faces' contact forces hold the weight's moment (a static balance).
#[test]
fn door_hinge_sags_edge_loads_and_knocks_only_in_space() {
    let runs = door_hinge::run().unwrap();
    let (planar, spatial) = &runs;
    assert!(planar.clean && spatial.clean, "{runs:?}");
    assert_eq!(planar.max_tilt, 0.0);
    assert_eq!(planar.face_knocks, 0);
    // Rounding only (1.4e-9 mm measured; 4-5 mm in space).
    assert!(planar.sag_mm.abs() < 1e-8, "{}", planar.sag_mm);
    // Diagonal edge contact: tilt at least 2c/L = 10 mrad.
    assert!(spatial.max_tilt > 0.0099, "{}", spatial.max_tilt);
    // Sag of the free edge: 0.4 m x the tilt, plus the 0.15 mm axial drop.
    assert!(
        spatial.sag_mm > 4.0 && spatial.sag_mm < 5.0,
        "{}",
        spatial.sag_mm
    );
    // Both edges loaded about equally, less than M/L (the face takes a share of the moment).
    let moment = door_hinge::MASS * 9.81 * door_hinge::ARM;
    let moment_over_width = moment / door_hinge::WIDTH;
    for f in spatial.late_edge_force {
        assert!(
            f > 0.9 * moment_over_width && f < moment_over_width,
            "{f} against M/L = {moment_over_width}"
        );
    }
    let [a, b] = spatial.late_edge_force;
    assert!((a - b).abs() < 0.01 * a, "{a} {b}");
    // Quasi-static: the shoulder rests on the face with the weight, less what the loaded edges'
    // friction holds axially (up to mu x 2 x 190 N, so the share is friction-indeterminate:
    // 89 % on the face measured once the axial slip's friction is resolved by the step control),
    // and the edges' couple plus the face force's moment make the weight's moment.
    let weight = door_hinge::MASS * 9.81;
    assert!(
        spatial.late_face_force > 0.5 * weight && spatial.late_face_force < 1.02 * weight,
        "{} against m g = {weight}",
        spatial.late_face_force
    );
    let [edges, face] = door_hinge::holding_moments(spatial);
    assert!(
        ((edges + face) / moment - 1.0).abs() < 0.005,
        "edges {edges} + face {face} against m g x = {moment}"
    );
    assert!(
        spatial.face_knocks >= 1 && spatial.max_face_force > 100.0,
        "{spatial:?}"
    );
    // The edges' friction stops the swing the planar joint lets run on (1 rad/s for 1 s: 57 deg).
    assert!(
        planar.swing_deg > 45.0 && spatial.swing_deg < 15.0,
        "{runs:?}"
    );
    readme_quotes(&format!(
        "swings on ({:.0}° in 1 s) on the planar joint; on the spatial one it tilts {:.1} mrad, \
         sags {:.1} mm at its free edge, knocks the top face ({:.1} kN peak), and its edge \
         friction stops the swing at {:.1}°; at rest the edges' couple ({:.0} and {:.0} N)",
        planar.swing_deg,
        1e3 * spatial.max_tilt,
        spatial.sag_mm,
        1e-3 * spatial.max_face_force,
        spatial.swing_deg,
        spatial.late_edge_force[0],
        spatial.late_edge_force[1]
    ));
    let text = door_hinge::report(&runs).unwrap();
    assert!(text.contains("M/L") && text.contains("m g x"), "{text}");
}

/// Asserts the README quotes `figure` (whitespace-insensitive: it wraps its lines), as the
/// example computes it: a figure that moves fails here until the README is re-measured.
fn readme_quotes(figure: &str) {
    let readme =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/README.md")).unwrap();
    let flat = |t: &str| t.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(
        flat(&readme).contains(&flat(figure)),
        "the README does not quote `{figure}`, which the example now gives: re-measure it"
    );
}

/// `target/<profile>/examples`, next to this test's `deps` folder.
fn examples_dir() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    exe.parent().unwrap().parent().unwrap().join("examples")
}

#[test]
fn example_binaries_run_headless_and_print_the_comparison() {
    // `cargo test` builds the examples; build them here too (a no-op then) for `--test examples`.
    let dir = examples_dir();
    let profile = dir
        .parent()
        .and_then(|p| p.file_name())
        .and_then(|p| p.to_str())
        .unwrap()
        .to_string();
    let mut build = Command::new(env!("CARGO"));
    build.current_dir(env!("CARGO_MANIFEST_DIR")).arg("build");
    // `cargo test` builds examples with the `test` profile into `target/debug`, and with
    // `--release` with the `release` profile into `target/release`: the same profile here makes
    // this build a no-op after `cargo test`.
    match profile.as_str() {
        "debug" => {
            build.args(["--profile", "test"]);
        }
        "release" => {
            build.arg("--release");
        }
        other => {
            build.args(["--profile", other]);
        }
    }
    // The `ecs` example needs the feature of the same name.
    if cfg!(feature = "ecs") {
        build.args(["--example", "ecs"]);
    }
    let out = build
        .args([
            "--example",
            "door_hinge",
            "--example",
            "drop_in",
            "--example",
            "solar_panel",
            "--example",
            "game_rate",
            "--example",
            "robot_backlash",
            "--example",
            "slider_crank",
            "--example",
            "user_force_source",
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for (name, needles) in [
        ("door_hinge", &["planar", "spatial", "M/L", "bore"][..]),
        ("drop_in", &["ideal", "clearance", "elbow onsets"][..]),
        ("ecs", &["ideal", "clearance", "swapped@0.5s"][..]),
        (
            "solar_panel",
            &["ideal", "clearance", "final deployment angle"][..],
        ),
        ("game_rate", &["ideal", "play", "largest |e|/c"][..]),
        (
            "robot_backlash",
            &["ideal", "play", "hand off the ideal arm's"][..],
        ),
        (
            "slider_crank",
            &["ideal slider acceleration", "closed form", "first impact"][..],
        ),
        (
            "user_force_source",
            &["steps", "closed form", "guard: the spring"][..],
        ),
    ] {
        if name == "ecs" && !cfg!(feature = "ecs") {
            continue;
        }
        let exe = dir.join(format!("{name}{}", std::env::consts::EXE_SUFFIX));
        let out = Command::new(&exe)
            .output()
            .unwrap_or_else(|e| panic!("{}: {e}", exe.display()));
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        for n in needles {
            assert!(stdout.contains(n), "{name}: no `{n}` in\n{stdout}");
        }
    }
}
