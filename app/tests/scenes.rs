//! Scenes beyond the paper's (assets/): a pendulum resting on its journal under gravity, a
//! deployable array of four rattling clearance hinges, and what the planar model handles or
//! refuses (gravity, several joints, out-of-plane loads).

use clearance_joint::Error;
use clearance_joint::model::kinematics::ContactMode;
use clearance_joint::model::laws::NormalForceLaw;
use clearance_joint::rapier::joint::ClearanceJoint;
use clearance_joint::scene::runner::{RunOptions, Simulation, TwinKind, Twins};
use clearance_joint::scene::{BodySpec, HingeSpec, Scene};
use rapier3d_f64::math::Vector;
use std::path::{Path, PathBuf};
use std::process::Command;

fn asset_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../assets")
        .join(name)
}

fn asset(name: &str) -> Scene {
    Scene::load(&asset_path(name)).expect("the asset is a valid scene")
}

fn options(twins: Twins) -> RunOptions {
    RunOptions {
        twins,
        skip_rows: true,
    }
}

/// Builds `scene` with only the clearance twin and steps it to `run.end_s` by hand, so that the
/// world (bodies, joints) can be inspected at the end.
fn settle(scene: &Scene) -> Simulation {
    let mut sim = Simulation::new(scene, options(Twins::ClearanceOnly)).unwrap();
    let n = (scene.run.end_s / scene.run.dt_s).round() as u64;
    for _ in 0..n {
        sim.step().unwrap();
    }
    sim
}

/// The clearance joint called `name` in the (only) twin of `sim`.
fn joint<'a>(sim: &'a Simulation, name: &str) -> &'a ClearanceJoint {
    sim.world
        .clearance
        .iter()
        .map(|(_, j)| j)
        .find(|j| j.name() == name)
        .unwrap_or_else(|| panic!("no clearance joint `{name}`"))
}

/// Penetration at which the elastic part of hinge `hinge`'s law carries `load`, by bisection.
fn static_penetration(scene: &Scene, hinge: &str, load: f64) -> f64 {
    let spec = scene.hinges[scene.hinge_index(hinge).unwrap()]
        .clearance
        .as_ref()
        .unwrap();
    let p = spec.clearance().unwrap();
    let (mut lo, mut hi) = (0.0, p.geometry.clearance());
    assert!(p.normal.elastic_force(hi) > load);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if p.normal.elastic_force(mid) < load {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

fn mass(scene: &Scene, body: &str) -> f64 {
    scene.bodies[scene.body_index(body).unwrap()].mass_kg
}

fn weight(scene: &Scene, bodies: &[&str]) -> f64 {
    let g = Vector::from(scene.gravity).length();
    bodies.iter().map(|b| mass(scene, b) * g).sum()
}

/// Checks that `j` rests in continuous contact at the bottom of its bearing carrying `load`:
/// force within 0.1 %, penetration within 0.1 % of the law's static penetration.
fn assert_resting(scene: &Scene, j: &ClearanceJoint, load: f64) {
    let r = j.report();
    let force = r.force.on_journal.length();
    assert!(
        ((force - load) / load).abs() < 1e-3,
        "`{}`: resting force {force} N, static load {load} N",
        j.name()
    );
    let delta_s = static_penetration(scene, j.name(), load);
    let delta = r.state.penetration;
    assert!(
        ((delta - delta_s) / delta_s).abs() < 1e-3,
        "`{}`: rest penetration {delta:e} m, static penetration of the law {delta_s:e} m",
        j.name()
    );
    assert_eq!(r.mode, ContactMode::Continuous, "`{}`", j.name());
    // At the bottom: the journal sits below the bearing centre, along gravity.
    let down = Vector::from(scene.gravity).normalize();
    assert!(
        r.state.normal.dot(down) > 1.0 - 1e-6,
        "`{}`: contact normal {:?}",
        j.name(),
        r.state.normal
    );
    assert!(r.state.slip.length() < 1e-6, "`{}`: slipping", j.name());
}

#[test]
fn pendulum_settles_onto_its_journal_carrying_the_static_load() {
    let scene = asset("pendulum.ron");
    let sim = settle(&scene);
    let j = joint(&sim, "pivot");
    let load = weight(&scene, &["arm"]);
    assert_resting(&scene, j, load);
    // It got there by bouncing: the drop through the clearance is an impact, not a touch-down.
    let r = j.report();
    assert!(r.state.penetration > 0.0);
    let metrics = &sim.twins[0].hinge_metrics()["pivot"];
    assert!(metrics.onsets > 1, "{} onsets", metrics.onsets);
    assert!(
        metrics.peak_force_n > 10.0 * load,
        "first impact {} N",
        metrics.peak_force_n
    );
}

#[test]
fn pendulum_ideal_twin_carries_the_static_load_exactly() {
    let scene = asset("pendulum.ron")
        .with_overrides(&["run.end_s=0.05"])
        .unwrap();
    let r = Simulation::new(&scene, options(Twins::IdealOnly))
        .unwrap()
        .run()
        .unwrap();
    let ideal = r.twin(TwinKind::Ideal).unwrap();
    let m = &ideal.hinge_metrics()["pivot"];
    let load = weight(&scene, &["arm"]);
    assert!(
        ((m.peak_force_n - load) / load).abs() < 1e-3,
        "ideal reaction {} N, load {load} N",
        m.peak_force_n
    );
    assert_eq!(m.onsets, 0);
}

/// The pendulum with a second link hanging from the first: two clearance hinges in series
/// under gravity.
fn double_pendulum() -> Scene {
    let mut scene = asset("pendulum.ron");
    scene.name = "double_pendulum".into();
    scene.bodies.push(BodySpec {
        name: "lower".into(),
        mass_kg: 1.0,
        inertia_kg_m2: [0.0133, 0.001, 0.0133],
        center_of_mass_m: [0.0, -0.8, 0.0],
        fixed: false,
        motion: None,
        velocity_m_s: [0.0; 3],
        angular_velocity_rad_s: [0.0; 3],
    });
    let pivot = scene.hinges[0].clone();
    scene.hinges.push(HingeSpec {
        name: "knee".into(),
        bearing: "arm".into(),
        journal: "lower".into(),
        point_m: [0.0, -0.6, 0.0],
        ..pivot
    });
    scene.validate().unwrap();
    scene
}

#[test]
fn double_pendulum_hinges_each_carry_the_weight_below_them() {
    let scene = double_pendulum();
    let sim = settle(&scene);
    assert_resting(
        &scene,
        joint(&sim, "pivot"),
        weight(&scene, &["arm", "lower"]),
    );
    assert_resting(&scene, joint(&sim, "knee"), weight(&scene, &["lower"]));
}

#[test]
fn out_of_plane_moment_is_carried_by_the_lock() {
    // The arm's centre of mass 50 mm along the hinge axis from the bearing: its weight tilts the
    // arm about a horizontal axis normal to the hinge. The planar contact cannot carry that moment;
    // the out-of-plane lock (a Rapier joint on the axial translation and the tilts) does, and the
    // contact still carries exactly the weight.
    let mut scene = asset("pendulum.ron");
    scene.bodies[1].center_of_mass_m = [0.0, -0.3, 0.05];
    let sim = settle(&scene);
    let j = joint(&sim, "pivot");
    assert_resting(&scene, j, weight(&scene, &["arm"]));
    let arm = &sim.world.rapier.bodies[j.body2()];
    let tilt = (*arm.rotation() * Vector::Z).angle_between(Vector::Z);
    assert!(tilt < 1e-6, "the arm tilted by {tilt} rad");
}

#[test]
fn deployable_array_rattles_in_all_four_hinges_and_conserves_momentum() {
    let scene = asset("deployable_array.ron")
        .with_overrides(&["run.end_s=0.5"])
        .unwrap();
    assert_eq!(scene.hinges.len(), 4);
    assert_eq!(scene.drives.len(), 4);
    assert!(scene.hinges.iter().all(|h| h.clearance.is_some()));
    // Rows on (one per ms): the hinge angles are measured at rows.
    let with_rows = RunOptions {
        twins: Twins::ClearanceOnly,
        skip_rows: false,
    };
    let r = Simulation::new(&scene, with_rows).unwrap().run().unwrap();
    let s = r.summary().twins["clearance"].clone();
    for (name, m) in &s.hinges {
        assert!(m.onsets > 0, "hinge `{name}` never touched");
        assert!(
            m.peak_force_n > 10.0,
            "hinge `{name}`: {} N",
            m.peak_force_n
        );
    }
    assert!(
        s.linear_momentum_drift.expect("free-floating") < 1e-9,
        "linear momentum drift {:?}",
        s.linear_momentum_drift
    );
    assert!(
        s.angular_momentum_drift.expect("free-floating") < 1e-9,
        "angular momentum drift {:?}",
        s.angular_momentum_drift
    );
    // Every hinge moved (the chain's inertia makes some relative angles go negative first).
    for (name, m) in &s.hinges {
        assert!(m.final_angle_deg.abs() > 0.1, "`{name}` did not move");
    }
}

fn refusal(scene: Result<Scene, Error>) -> String {
    let e = scene
        .and_then(|s| Simulation::new(&s, RunOptions::default()).map(|_| ()))
        .expect_err("the scene must be refused");
    let msg = e.to_string();
    assert!(matches!(e, Error::Invalid { .. }), "{msg}");
    msg
}

#[test]
fn a_door_on_a_vertical_clearance_hinge_is_refused() {
    // Gravity along the hinge axis is an axial load: the planar contact cannot carry it.
    let door = asset("pendulum.ron").with_overrides(&[
        "pivot.axis=[0,1,0]",
        "reference_axis=[0,1,0]",
        "arm.center_of_mass_m=[0.4,0,0]",
    ]);
    let msg = refusal(door);
    assert!(msg.contains("`gravity`"), "{msg}");
    assert!(
        msg.contains("along the axis of clearance hinge `pivot`"),
        "{msg}"
    );
    assert!(msg.contains("axial"), "{msg}");
    // Tilted gravity is refused too: any axial component.
    let msg = refusal(asset("pendulum.ron").with_overrides(&["gravity=[0,-9.81,0.1]"]));
    assert!(msg.contains("axial"), "{msg}");
}

#[test]
fn a_door_on_an_ideal_vertical_hinge_is_handled() {
    // The same door with an ideal hinge: Rapier's revolute joint carries the axial load.
    let scene = asset("pendulum.ron")
        .with_overrides(&[
            "pivot.axis=[0,1,0]",
            "reference_axis=[0,1,0]",
            "arm.center_of_mass_m=[0.4,0,0]",
            "pivot.clearance=null",
            "run.end_s=0.01",
        ])
        .unwrap();
    let r = Simulation::new(&scene, options(Twins::Both))
        .unwrap()
        .run()
        .unwrap();
    // The ideal hinge carries the whole weight axially (2 kg x 9.81 m/s^2) and the door stays put.
    let s = r.summary();
    for twin in ["ideal", "clearance"] {
        let t = &s.twins[twin];
        let load = t.hinges["pivot"].peak_force_n;
        assert!(
            (load - 19.62).abs() < 0.01 * 19.62,
            "{twin}: axial load {load} N"
        );
        assert!(
            t.final_angles_deg["pivot"].abs() < 1e-6,
            "{twin}: the door turned"
        );
    }
}

#[test]
fn an_array_hinge_out_of_the_deployment_plane_is_refused() {
    let msg =
        refusal(asset("deployable_array.ron").with_overrides(&["panel1_panel2.axis=[0,0,1]"]));
    assert!(msg.contains("hinges[panel1_panel2].axis"), "{msg}");
    assert!(
        msg.contains("parallel to the scene's reference_axis"),
        "{msg}"
    );
    assert!(msg.contains("out-of-plane"), "{msg}");
    // Hinges alternately along +y and -y are parallel: the asset itself is accepted.
    asset("deployable_array.ron").validate().unwrap();
}

#[test]
fn cli_runs_the_new_scenes() {
    for (name, end) in [("pendulum.ron", "0.02"), ("deployable_array.ron", "0.02")] {
        let dir = std::env::temp_dir().join(format!(
            "cj-scenes-{}-{}",
            name.trim_end_matches(".ron"),
            std::process::id()
        ));
        let out = Command::new(env!("CARGO_BIN_EXE_clearance_joint"))
            .arg("--scene")
            .arg(asset_path(name))
            .args(["--end", end, "--no-check", "--out"])
            .arg(&dir)
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(stdout.contains("onsets"), "{stdout}");
        for file in ["ideal.csv", "clearance.csv", "summary.json"] {
            assert!(dir.join(file).is_file(), "{name}: no {file}");
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}

/// Issue 10 item 2: the runner writes each clearance joint's impact list, and it agrees with
/// the joint's summary figures (same recorder).
#[test]
fn the_impact_list_is_written_and_matches_the_summary() {
    let mut scene = asset("pendulum.ron");
    scene.run.end_s = 0.3;
    let result = Simulation::new(&scene, RunOptions::default())
        .unwrap()
        .run()
        .unwrap();
    let dir = std::env::temp_dir().join(format!("cj_impacts_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let summary = result.write(&dir).unwrap();
    let csv = std::fs::read_to_string(dir.join("clearance_pivot_impacts.csv")).unwrap();
    assert!(!dir.join("ideal_pivot_impacts.csv").exists());
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        "onset_t_s,approach_speed_mm_s,peak_force_n,peak_t_s,max_penetration_um,duration_s,separated"
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    let m = &summary.twins["clearance"].hinges["pivot"];
    assert_eq!(rows.len() as u64, m.onsets);
    assert!(m.onsets > 1);
    let separated = rows.iter().filter(|r| r[6] == 1.0).count();
    assert_eq!(separated as u64, m.impacts);
    assert_eq!(Some(rows[0][0]), m.first_impact_t_s);
    assert_eq!(Some(rows[0][2]), m.first_impact_peak_n);
    let peak = rows.iter().map(|r| r[2]).fold(0.0, f64::max);
    assert_eq!(peak, m.peak_force_n);
    // Each peak inside its contact.
    for r in &rows {
        assert!(
            r[3] >= r[0] && r[3] <= r[0] + r[5] + 1e-12,
            "peak at {} s: {r:?}",
            r[3]
        );
    }
    let pen = rows.iter().map(|r| r[4]).fold(0.0, f64::max);
    assert_eq!(pen, m.max_penetration_um);
    let contact: f64 = rows.iter().map(|r| r[5]).sum();
    assert!((contact / scene.run.end_s - m.contact_fraction).abs() < 1e-12);
    // Released centred, the journal falls freely through the clearance: it arrives at
    // sqrt(2 g c) = 62.6 mm/s for 0.2 mm.
    let free_fall = (2.0 * 9.81 * 0.2e-3f64).sqrt() * 1e3;
    assert!(
        (rows[0][1] / free_fall - 1.0).abs() < 2e-3,
        "approach {} mm/s, free fall {free_fall}",
        rows[0][1]
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 10: the four-bar linkage scene (a crank on a velocity motor, a closed loop of ideal
/// revolutes, one clearance joint) runs clean; the motor holds the crank's speed; the ideal twin returns to its start after two crank turns and
/// its closed-loop reactions stay at the mechanism's scale; the clearance joint rattles.
#[test]
fn four_bar_linkage_runs_with_a_clearance_joint() {
    let scene = asset("four_bar.ron");
    // `--set` reaches a joint's fields by the joint's name.
    let faster = scene.with_overrides(&["motor.factor=1e7"]).unwrap();
    assert!(matches!(
        faster.joints[0].motor,
        Some(clearance_joint::scene::MotorSpec::Velocity { factor, .. }) if factor == 1e7
    ));
    let result = Simulation::new(&scene, RunOptions::default())
        .unwrap()
        .run()
        .unwrap();
    assert!(result.guards.is_clean(), "{:?}", result.guards.violations);
    let ideal = result.twin(TwinKind::Ideal).unwrap();
    let angles = ideal.final_angles_deg();
    // With the scene's 32 sweeps over the joints the motor holds the crank's speed: 720.0008 deg
    // after two turns (720.027 with one sweep, which solved the crank between its motor and the
    // coupler only in part).
    assert!(
        (angles["crank"] - 720.0).abs() < 0.005,
        "{}",
        angles["crank"]
    );
    // The loop closes where the crank ends: the rocker and the coupler are back within 0.0004 deg
    // (measured; -0.0136 deg each with one sweep).
    assert!(
        angles["rocker"].abs() < 0.003 && angles["coupler"].abs() < 0.003,
        "{angles:?}"
    );
    let m = ideal.hinge_metrics();
    // Inertia and weight of a 0.5 kg linkage at 600 rpm: about a hundred newtons.
    for (name, h) in &m {
        assert!(
            h.peak_force_n > 10.0 && h.peak_force_n < 200.0,
            "{name}: {}",
            h.peak_force_n
        );
    }
    // The motor's pivot carries the crank: its reaction column is at the same scale.
    let motor = ideal.table.column("motor_force_n").unwrap();
    let peak = motor.iter().fold(0.0f64, |m, v| m.max(*v));
    assert!(peak > 10.0 && peak < 300.0, "{peak}");
    let clear = &result.twin(TwinKind::Clearance).unwrap().hinge_metrics()["rocker_pin"];
    assert!(clear.onsets > 2 && clear.peak_force_n > 10.0 * m["rocker_pin"].peak_force_n);
    assert!(clear.contact_fraction > 0.5 && clear.contact_fraction < 1.0);
}

/// Issue 10: fixed and spherical joints in a scene: a bob hanging at rest from a ball joint with
/// a weight welded below it. The ball carries both weights, the weld the lower one, exactly
/// (the reactions are solved, not read from Rapier's impulses).
#[test]
fn ball_joint_and_weld_carry_their_weights() {
    let text = r#"Scene(
        name: "ball",
        gravity: (0.0, -9.81, 0.0),
        reference_axis: (0.0, 0.0, 1.0),
        bodies: [
            (name: "ground", mass_kg: 0.0, inertia_kg_m2: (0.0, 0.0, 0.0), center_of_mass_m: (0.0, 0.0, 0.0), fixed: true),
            (name: "bob", mass_kg: 2.0, inertia_kg_m2: (0.01, 0.01, 0.01), center_of_mass_m: (0.0, -0.5, 0.0)),
            (name: "weight", mass_kg: 1.0, inertia_kg_m2: (0.01, 0.01, 0.01), center_of_mass_m: (0.0, -0.7, 0.0)),
        ],
        hinges: [],
        joints: [
            (name: "ball", body1: "ground", body2: "bob", point_m: (0.0, 0.0, 0.0), kind: Spherical),
            (name: "weld", body1: "bob", body2: "weight", point_m: (0.0, -0.6, 0.0), kind: Fixed),
        ],
        run: (dt_s: 1e-3, end_s: 0.1, output_interval_s: 0.01, step: Fixed, body_motion: true),
    )"#;
    let scene = Scene::from_ron(text, "test").unwrap();
    let result = Simulation::new(&scene, RunOptions::default())
        .unwrap()
        .run()
        .unwrap();
    let table = &result.twin(TwinKind::Ideal).unwrap().table;
    let (ball, weld) = (
        table.column("ball_force_n").unwrap(),
        table.column("weld_force_n").unwrap(),
    );
    for (b, w) in ball.iter().zip(&weld) {
        assert!((b - 3.0 * 9.81).abs() < 1e-6, "ball {b}");
        assert!((w - 9.81).abs() < 1e-6, "weld {w}");
    }
    // At rest: the rows' accelerations, solved at each state, are zero from the first state on
    // (Rapier's one solver iteration, not yet warm-started, leaves the chain sagging for a step:
    // a difference of velocities would show it), the positions the start's.
    let ay = table.column("weight_ay_m_s2").unwrap();
    assert!(ay.iter().all(|a| a.abs() < 1e-6), "{ay:?}");
    // Rapier's joints, solved with one iteration, sag 14.7 um under the two weights.
    let y = table.column("weight_y_m").unwrap();
    assert!(y.iter().all(|v| (v + 0.7).abs() < 2e-5), "{y:?}");
}

/// Issue 10: a tabulated drive. A cart follows `x = t^2` from a position table (sampled every
/// 10 ms, interpolated smoothly); a 1 kg block welded to it is pushed with m a = 2 N, and the
/// rows give the cart's position and acceleration from the table.
#[test]
fn tabulated_position_drives_a_cart() {
    let times: Vec<f64> = (0..=30).map(|i| i as f64 * 0.01).collect();
    let xs: Vec<f64> = times.iter().map(|t| t * t).collect();
    let text = format!(
        r#"Scene(
        name: "cart",
        reference_axis: (0.0, 0.0, 1.0),
        bodies: [
            (name: "cart", mass_kg: 0.0, inertia_kg_m2: (0.0, 0.0, 0.0), center_of_mass_m: (0.0, 0.0, 0.0),
             motion: Some(TablePosition(direction: (1.0, 0.0, 0.0), t_s: {times:?}, position_m: {xs:?}))),
            (name: "block", mass_kg: 1.0, inertia_kg_m2: (0.01, 0.01, 0.01), center_of_mass_m: (0.0, 0.1, 0.0)),
        ],
        hinges: [],
        joints: [(name: "weld", body1: "cart", body2: "block", point_m: (0.0, 0.1, 0.0), kind: Fixed)],
        run: (dt_s: 1e-4, end_s: 0.2, output_interval_s: 0.01, step: Fixed, body_motion: true),
    )"#
    );
    let scene = Scene::from_ron(&text, "test").unwrap();
    let result = Simulation::new(&scene, RunOptions::default())
        .unwrap()
        .run()
        .unwrap();
    let table = &result.twin(TwinKind::Ideal).unwrap().table;
    let (t, x, ax, weld) = (
        table.column("t_s").unwrap(),
        table.column("cart_x_m").unwrap(),
        table.column("cart_ax_m_s2").unwrap(),
        table.column("weld_force_n").unwrap(),
    );
    // From the second table segment on (the first has the table's one-sided end slope, 0.01
    // instead of 0, so it is not the parabola there).
    for i in 2..t.len() {
        assert!((x[i] - t[i] * t[i]).abs() < 1e-12, "x({}) = {}", t[i], x[i]);
        assert!((ax[i] - 2.0).abs() < 1e-9, "a({}) = {}", t[i], ax[i]);
        assert!((weld[i] - 2.0).abs() < 1e-9, "weld({}) = {}", t[i], weld[i]);
    }
    // The welded block follows (Rapier's weld, one iteration, lags by far less than a mm).
    let bx = table.column("block_x_m").unwrap();
    assert!((bx[t.len() - 1] - 0.04).abs() < 1e-3, "{}", bx[t.len() - 1]);
}

/// The scene runs from the command line with `--scene`, writing the result set, the impact and
/// per-turn lists, and with `--figures` the joint-force and journal-orbit figures.
#[test]
fn the_scene_runs_from_the_command_line_with_figures() {
    let dir = std::env::temp_dir().join(format!("cj_sc_cli_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let scene = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/slider_crank.ron");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_clearance_joint"))
        .arg("--scene")
        .arg(&scene)
        .args([
            "--set",
            "run.end_s=0.013",
            "--figures",
            "--no-check",
            "--progress",
            "quiet",
            "--out",
        ])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for f in [
        "ideal.csv",
        "clearance.csv",
        "clearance_slider_pin_impacts.csv",
        "clearance_slider_pin_turns.csv",
        "summary.json",
        "joint_force.png",
        "trajectory.png",
        "slider_acceleration.png",
        "angles_rates.svg",
    ] {
        assert!(dir.join(f).is_file(), "no {f}");
    }
    // The force figure shows the run's peak from every step, not the rows' lower maximum.
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    let peak = summary["twins"]["clearance"]["hinges"]["slider_pin"]["peak_force_n"]
        .as_f64()
        .unwrap();
    let rows = clearance_joint_app::figures::series::read_csv(&dir.join("clearance.csv")).unwrap();
    let rows_max = rows
        .column("slider_pin_force_n")
        .unwrap()
        .into_iter()
        .fold(0.0, f64::max);
    assert!(rows_max < peak * (1.0 - 1e-3), "rows {rows_max} vs {peak}");
    let svg = std::fs::read_to_string(dir.join("joint_force.svg")).unwrap();
    let legend = format!("clearance joint, peak {peak:.4} N");
    assert!(svg.contains(&legend), "no `{legend}` in joint_force.svg");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 10 item 5: sweeps take the mechanism scenes and any of their fields as an axis: the
/// run settings, a clearance joint's clearance, and an ideal joint's motor. Each point runs with
/// its values (read back from the table and the manifests).
#[test]
fn sweeps_take_mechanism_scenes_and_any_field() {
    use clearance_joint_app::study::sweep::{MANIFEST, Manifest, MetricsTable};
    type Field = fn(&Scene) -> f64;
    let cases: [(&str, [&str; 2], &[&str], Field); 2] = [
        (
            "slider_crank.ron",
            ["run.end_s=0.001,0.002", "slider_pin.clearance_mm=0.25,0.5"],
            &[],
            |s| s.run.end_s,
        ),
        (
            "four_bar.ron",
            ["motor.factor=1e5,1e6", "rocker_pin.clearance_mm=0.1,0.2"],
            &["--end", "0.004"],
            |s| match s.joints[0].motor {
                Some(clearance_joint::scene::MotorSpec::Velocity { factor, .. }) => factor,
                _ => f64::NAN,
            },
        ),
    ];
    for (file, [first, clearance], extra, first_field) in cases {
        let dir = std::env::temp_dir().join(format!(
            "cj-sweep-{}-{}",
            file.trim_end_matches(".ron"),
            std::process::id()
        ));
        let _ = std::fs::remove_dir_all(&dir);
        let out = Command::new(env!("CARGO_BIN_EXE_clearance_joint"))
            .args(["sweep", "--scene"])
            .arg(asset_path(file))
            .args(["--set", first, "--set", clearance])
            .args(extra)
            .args(["--progress", "quiet", "--out"])
            .arg(&dir)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{file}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let table = MetricsTable::load(&dir.join("metrics.json")).unwrap();
        assert_eq!(table.rows.len(), 4, "{file}");
        let hinge = clearance.split('.').next().unwrap();
        let values = |axis: &str| -> Vec<f64> {
            let v: Vec<f64> = axis
                .split_once('=')
                .unwrap()
                .1
                .split(',')
                .map(|x| x.parse().unwrap())
                .collect();
            v
        };
        let (firsts, clearances) = (values(first), values(clearance));
        for (i, row) in table.rows.iter().enumerate() {
            // The first axis varies slowest.
            assert_eq!(
                row.metrics.hinges[hinge].clearance_mm,
                clearances[i % 2],
                "{file} point {i}"
            );
            let m: Manifest = serde_json::from_str(
                &std::fs::read_to_string(dir.join(&row.dir).join(MANIFEST)).unwrap(),
            )
            .unwrap();
            let scene = Scene::from_ron(&m.scene_ron, "manifest").unwrap();
            assert_eq!(first_field(&scene), firsts[i / 2], "{file} point {i}");
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}
