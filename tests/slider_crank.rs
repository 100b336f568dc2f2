//! The slider-crank of `examples/slider_crank.rs` (plain API: kinematic crank at 5000 rpm,
//! ideal crank pin, prismatic guide, clearance at the rod-slider pin, gravity, the `Stepper`):
//! the ideal slider's acceleration against the closed form, the ideal pin force against a hand
//! value, and the first impact's convergence under halving fixed steps.

#[allow(dead_code)]
#[path = "../examples/slider_crank.rs"]
mod slider_crank;

use slider_crank::*;
use std::f64::consts::TAU;

/// The extremes of the closed form over a turn, sampled finely.
fn closed_form_extremes() -> (f64, f64) {
    extremes((0..20_000).map(|k| closed_form_acceleration(k as f64 * TAU / 20_000.0)))
}

#[test]
fn ideal_slider_acceleration_matches_the_closed_form() {
    let turn = TAU / OMEGA;
    let dt = 1.25e-7;
    let run = simulate(None, dt, 2.0 * turn).unwrap();
    // Over the second turn (the first begins with the start's transient).
    let acc: Vec<(usize, f64)> = run
        .acceleration()
        .into_iter()
        .filter(|&(n, _)| run.t[n] >= turn)
        .collect();
    let (hi, lo) = extremes(acc.iter().map(|&(_, a)| a));
    let (c_hi, c_lo) = closed_form_extremes();
    // Top dead centre: -omega^2 L1 (1 + L1/L2); bottom dead centre: omega^2 L1 (1 - L1/L2).
    assert!((c_lo / (-OMEGA * OMEGA * CRANK * (1.0 + CRANK / ROD)) - 1.0).abs() < 1e-12);
    assert!((c_hi / (OMEGA * OMEGA * CRANK * (1.0 - CRANK / ROD)) - 1.0).abs() < 1e-9);
    assert!((hi / c_hi - 1.0).abs() < 1e-3, "max {hi} against {c_hi}");
    assert!((lo / c_lo - 1.0).abs() < 1e-3, "min {lo} against {c_lo}");
    // Everywhere, at the crank angle of the state, within 0.1 % of the largest acceleration.
    let worst = acc
        .iter()
        .map(|&(n, a)| (a - closed_form_acceleration(run.theta[n])).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-3 * c_lo.abs(), "worst {worst} m/s^2");
    // The crank turned at the prescribed speed.
    let last = run.t.len() - 1;
    assert!((run.theta[last] / (OMEGA * run.t[last]) - 1.0).abs() < 1e-9);
    // At top dead centre the pin pushes the slider along x alone (the rod is along x): the
    // pin force is m_slider |a| there, the largest over the turn; gravity adds ~2.5 N across.
    let peak = run.metrics().peak_force_n;
    assert!(
        (peak / (SLIDER_MASS * c_lo.abs()) - 1.0).abs() < 1e-4,
        "peak {peak} N against {}",
        SLIDER_MASS * c_lo.abs()
    );
    assert!(run.recorder.contacts().is_empty());
}

#[test]
fn clearance_pin_impacts_and_its_first_impact_converges() {
    let ideal = simulate(None, 1.25e-7, FIRST_IMPACT_END).unwrap();
    let runs: Vec<Run> = [2.5e-7, 1.25e-7, 6.25e-8]
        .iter()
        .map(|&dt| simulate(Some(pin_clearance().unwrap()), dt, FIRST_IMPACT_END).unwrap())
        .collect();
    let peaks: Vec<f64> = runs
        .iter()
        .map(|r| r.metrics().first_impact_peak_n.unwrap())
        .collect();
    // Halving the step shrinks the change of the peak.
    let (d1, d2) = (peaks[1] - peaks[0], peaks[2] - peaks[1]);
    assert!(d2.abs() < d1.abs(), "{peaks:?}");
    assert!((d2 / peaks[2]).abs() < 0.02, "{peaks:?}");
    // Onset and approach speed are resolved to 1e-3 relative.
    let first: Vec<_> = runs.iter().map(|r| r.recorder.contacts()[0]).collect();
    for w in first.windows(2) {
        assert!((w[1].onset_t_s / w[0].onset_t_s - 1.0).abs() < 1e-3);
        assert!((w[1].approach_speed_m_s / w[0].approach_speed_m_s - 1.0).abs() < 1e-3);
    }
    // The journal crosses the clearance fast: the impact is far above the ideal pin force.
    assert!(first[2].approach_speed_m_s > 1.0);
    assert!(peaks[2] > 10.0 * ideal.metrics().peak_force_n);
}

/// The scene file `assets/slider_crank.ron` builds the same mechanism through the runner: its
/// impact list and pin metrics are the plain-API example's, bit for bit.
#[test]
fn the_scene_run_is_the_plain_api_run_bit_for_bit() {
    use clearance_joint::scene::Scene;
    use clearance_joint::scene::runner::{RunOptions, Simulation, TwinKind};
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/slider_crank.ron");
    let mut scene = Scene::load(&path).unwrap();
    let end = 0.004;
    scene.run.end_s = end;
    let result = Simulation::new(&scene, RunOptions::default())
        .unwrap()
        .run()
        .unwrap();
    let twin = |k: TwinKind| result.twin(k).unwrap();
    let clear = simulate(Some(pin_clearance().unwrap()), scene.run.dt_s, end).unwrap();
    let ideal = simulate(None, scene.run.dt_s, end).unwrap();
    let recorders = twin(TwinKind::Clearance).hinge_recorders();
    let scene_pin = recorders["slider_pin"];
    assert!(!clear.recorder.contacts().is_empty());
    assert_eq!(scene_pin.contacts(), clear.recorder.contacts());
    let (a, b) = (scene_pin.metrics(), clear.metrics());
    assert_eq!(
        (
            a.peak_force_n,
            a.rms_force_n,
            a.contact_fraction,
            a.first_impact_peak_n
        ),
        (
            b.peak_force_n,
            b.rms_force_n,
            b.contact_fraction,
            b.first_impact_peak_n
        )
    );
    let ideal_pin = &twin(TwinKind::Ideal).hinge_metrics()["slider_pin"];
    assert_eq!(
        (ideal_pin.peak_force_n, ideal_pin.rms_force_n),
        (ideal.metrics().peak_force_n, ideal.metrics().rms_force_n)
    );
}

/// Mechanism fields are checked at load, each error naming its field.
#[test]
fn mechanism_fields_are_validated_with_their_paths() {
    use clearance_joint::scene::{JointKindSpec, MotionSpec, Scene};
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/slider_crank.ron");
    let base = Scene::load(&path).unwrap();
    let check = |edit: &dyn Fn(&mut Scene), needle: &str| {
        let mut s = base.clone();
        edit(&mut s);
        let e = s.validate().unwrap_err().to_string();
        assert!(e.contains(needle), "{e} (wanted {needle})");
    };
    check(
        &|s| s.joints[0].body1 = "nowhere".into(),
        "joints[guide].body1",
    );
    check(
        &|s| s.joints[0].body2 = "ground".into(),
        "joints[guide].body2",
    );
    check(
        &|s| {
            s.joints[0].kind = JointKindSpec::Prismatic {
                axis: [1.0, 0.0, 0.0],
                limits_m: Some([0.1, 0.2]),
            }
        },
        "joints[guide].kind.limits_m",
    );
    check(
        &|s| {
            s.joints[0].kind = JointKindSpec::Prismatic {
                axis: [0.0, 0.0, 0.0],
                limits_m: None,
            }
        },
        "joints[guide].kind.axis",
    );
    check(&|s| s.joints[0].name = "rod".into(), "duplicate name");
    check(
        &|s| {
            s.joints[0].motor = Some(clearance_joint::scene::MotorSpec::Velocity {
                target_rad_s: 1.0,
                factor: 1e6,
            })
        },
        "joints[guide].motor",
    );
    check(&|s| s.bodies[1].fixed = true, "bodies[crank].motion");
    check(
        &|s| {
            s.bodies[1].motion = Some(MotionSpec::Spin {
                axis: [0.0, 0.0, 1.0],
                point_m: [0.0; 3],
                rate_rad_s: f64::NAN,
            })
        },
        "bodies[crank].motion.rate_rad_s",
    );
    check(
        &|s| s.bodies[2].velocity_m_s[1] = 1e6,
        "bodies[rod].velocity_m_s[1]",
    );
    check(
        &|s| {
            s.bodies[1].motion = Some(MotionSpec::TableAngle {
                axis: [0.0, 0.0, 1.0],
                point_m: [0.0; 3],
                t_s: vec![0.0, 0.0],
                angle_rad: vec![0.0, 1.0],
            })
        },
        "bodies[crank].motion.t_s[1]",
    );
    check(
        &|s| {
            s.bodies[1].motion = Some(MotionSpec::TablePosition {
                direction: [1.0, 0.0, 0.0],
                t_s: vec![0.0, 1.0],
                position_m: vec![0.0],
            })
        },
        "bodies[crank].motion.position_m",
    );
    // The scene format stays backward compatible: no `joints`, no motion, no velocities.
    assert!(
        Scene::load(&std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/pendulum.ron"))
            .is_ok()
    );
}

/// The ideal twin's rows of `assets/slider_crank.ron` run with `overrides`, against the closed
/// form at each row's crank angle, over every row (the first included): the worst acceleration
/// and velocity errors (m/s^2, m/s), the extremes of the acceleration, and the first row's
/// acceleration.
fn scene_rows_against_the_closed_form(overrides: &[&str]) -> (f64, f64, f64, f64, f64) {
    use clearance_joint::scene::Scene;
    use clearance_joint::scene::runner::{RunOptions, Simulation, TwinKind};
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/slider_crank.ron");
    let scene = Scene::load(&path)
        .unwrap()
        .with_overrides(overrides)
        .unwrap();
    let result = Simulation::new(&scene, RunOptions::default())
        .unwrap()
        .run()
        .unwrap();
    assert!(result.guards.is_clean(), "{:?}", result.guards.violations);
    let table = &result.twin(TwinKind::Ideal).unwrap().table;
    let (theta, a, v) = (
        table.column("crank_angle_deg").unwrap(),
        table.column("slider_ax_m_s2").unwrap(),
        table.column("slider_vx_m_s").unwrap(),
    );
    let mut worst = 0.0f64;
    let (mut hi, mut lo) = (f64::NEG_INFINITY, f64::INFINITY);
    let mut worst_v = 0.0f64;
    for i in 0..a.len() {
        let th = theta[i].to_radians();
        worst = worst.max((a[i] - closed_form_acceleration(th)).abs());
        (hi, lo) = (hi.max(a[i]), lo.min(a[i]));
        // The velocity: -omega (L1 sin + L1^2 sin cos / S).
        let s = (ROD * ROD - (CRANK * th.sin()).powi(2)).sqrt();
        let v_exact = -OMEGA * (CRANK * th.sin() + CRANK * CRANK * th.sin() * th.cos() / s);
        worst_v = worst_v.max((v[i] - v_exact).abs());
    }
    (worst, worst_v, hi, lo, a[0])
}

/// The scene's rows carry the slider's velocity and acceleration (`slider_vx_m_s`,
/// `slider_ax_m_s2`), solved at each state from the constrained equations: with the crank
/// prescribed the ideal mechanism has no freedom left, so they are exact at the row's
/// position, from the first row (at rest, where a difference of Rapier's velocities would show
/// its first-step position correction) to the last.
#[test]
fn scene_rows_carry_the_exact_slider_acceleration() {
    let (c_hi, c_lo) = closed_form_extremes();
    let (worst, worst_v, hi, lo, first) = scene_rows_against_the_closed_form(&[]);
    assert!(worst < 1e-6 * c_lo.abs(), "worst {worst} m/s^2");
    assert!(
        (hi / c_hi - 1.0).abs() < 1e-6 && (lo / c_lo - 1.0).abs() < 1e-6,
        "{hi} {lo}"
    );
    assert!(
        worst_v < 1e-6 * OMEGA * CRANK,
        "worst velocity error {worst_v} m/s"
    );
    // Top dead centre at the start: -omega^2 L1 (1 + L1/L2).
    assert!((first / c_lo - 1.0).abs() < 1e-6, "{first} against {c_lo}");
}

/// The same under the default adaptive steps (up to 1 ms in free flight, down to the contact's
/// resolution in the clearance twin, whose steps the ideal twin shares: abrupt step changes):
/// the rows, interpolated between states of varying spacing, hold the closed form to 0.1 % of
/// the peak, the first row and the extremes to 1e-6.
#[test]
fn adaptive_steps_keep_the_slider_acceleration_exact() {
    let (c_hi, c_lo) = closed_form_extremes();
    let (worst, worst_v, hi, lo, first) =
        scene_rows_against_the_closed_form(&["run.step=Adaptive"]);
    assert!(worst < 1e-3 * c_lo.abs(), "worst {worst} m/s^2");
    assert!(
        (hi / c_hi - 1.0).abs() < 1e-6 && (lo / c_lo - 1.0).abs() < 1e-6,
        "{hi} {lo}"
    );
    assert!(
        worst_v < 1e-3 * OMEGA * CRANK,
        "worst velocity error {worst_v} m/s"
    );
    assert!((first / c_lo - 1.0).abs() < 1e-6, "{first} against {c_lo}");
}

/// A scene with a spinning body writes per-turn statistics of each clearance joint, which add up
/// to the joint's totals.
#[test]
fn per_turn_statistics_add_up() {
    use clearance_joint::scene::Scene;
    use clearance_joint::scene::runner::{RunOptions, Simulation};
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/slider_crank.ron");
    let mut scene = Scene::load(&path).unwrap();
    scene.run.end_s = 0.018; // a turn and a half
    let result = Simulation::new(&scene, RunOptions::default())
        .unwrap()
        .run()
        .unwrap();
    let dir = std::env::temp_dir().join(format!("cj_turns_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let summary = result.write(&dir).unwrap();
    let csv = std::fs::read_to_string(dir.join("clearance_slider_pin_turns.csv")).unwrap();
    let rows: Vec<Vec<f64>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 2);
    let turn = TAU / OMEGA;
    assert!((rows[1][1] - turn).abs() < 1e-15);
    let m = &summary.twins["clearance"].hinges["slider_pin"];
    assert_eq!(rows.iter().map(|r| r[2]).sum::<f64>() as u64, m.onsets);
    assert_eq!(
        rows.iter().map(|r| r[4]).fold(0.0, f64::max),
        m.peak_force_n
    );
    let contact = rows[0][5] * turn + rows[1][5] * (0.018 - turn);
    assert!((contact / 0.018 - m.contact_fraction).abs() < 1e-9);
    assert!(!dir.join("ideal_slider_pin_turns.csv").exists());
    let _ = std::fs::remove_dir_all(&dir);
}
