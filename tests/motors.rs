//! Joint motors on ideal joints, from scene files: each kind against an independent value (a
//! closed form), the solver's motor torque or force against the impulse Rapier's solver
//! applied, the energy balance with the motors' work, the motor fields' validation, and the
//! motor-driven four-bar under adaptive steps against a fine fixed-step run.

use clearance_joint::rapier::pipeline::protocol::GuardKind;
use clearance_joint::rapier::pipeline::protocol::Violation;
use clearance_joint::scene::Scene;
use clearance_joint::scene::runner::{RunOptions, Simulation, TwinKind, Twins};
use rapier3d_f64::prelude::{JointAxesMask, JointAxis};

/// A scene of one body (`mass` kg, centre of mass at `com`) on the ground by one joint at the
/// origin (`kind` and `motor` in RON), gravity -9.81 along y, run as `run`.
fn one_joint_scene(mass: f64, com: [f64; 3], kind: &str, motor: &str, run: &str) -> Scene {
    one_joint(mass, com, kind, motor, run).unwrap()
}

/// [`one_joint_scene`] as parsed and validated.
fn one_joint(
    mass: f64,
    com: [f64; 3],
    kind: &str,
    motor: &str,
    run: &str,
) -> clearance_joint::Result<Scene> {
    let text = format!(
        r#"Scene(
            name: "motor",
            gravity: (0.0, -9.81, 0.0),
            reference_axis: (0.0, 0.0, 1.0),
            bodies: [
                (name: "ground", mass_kg: 0.0, inertia_kg_m2: (0.0, 0.0, 0.0), center_of_mass_m: (0.0, 0.0, 0.0), fixed: true),
                (name: "body", mass_kg: {mass}, inertia_kg_m2: (0.01, 0.01, 0.01), center_of_mass_m: ({}, {}, {})),
            ],
            hinges: [],
            joints: [
                (name: "m", body1: "ground", body2: "body", point_m: (0.0, 0.0, 0.0), kind: {kind}, motor: Some({motor})),
            ],
            run: ({run}, body_motion: true),
        )"#,
        com[0], com[1], com[2]
    );
    Scene::from_ron(&text, "test")
}

/// Runs the ideal twin to the end, collecting after every step the motor's torque or force by
/// Rapier's impulse (`-impulse / dt`, the force on body 2). Returns the run and those values
/// with the step's start time.
fn run_with_impulses(
    scene: &Scene,
) -> (clearance_joint::scene::runner::RunResult, Vec<(f64, f64)>) {
    let mut sim = Simulation::new(
        scene,
        RunOptions {
            twins: Twins::IdealOnly,
            skip_rows: false,
        },
    )
    .unwrap();
    let (handle, axis) = sim
        .world
        .rapier
        .impulse_joints
        .iter()
        .find(|(_, j)| !j.data.motor_axes.is_empty())
        .map(|(h, j)| {
            let axis = if j.data.motor_axes.contains(JointAxesMask::ANG_X) {
                JointAxis::AngX
            } else {
                JointAxis::LinX
            };
            (h, axis)
        })
        .unwrap();
    let mut impulses = Vec::new();
    while sim.time() < scene.run.end_s * (1.0 - 1e-12) {
        let t0 = sim.time();
        sim.step().unwrap();
        let dt = sim.world.rapier.integration_parameters.dt;
        let j = sim.world.rapier.impulse_joints.get(handle).unwrap();
        impulses.push((t0, -j.data.motors[axis as usize].impulse / dt));
    }
    (sim.run().unwrap(), impulses)
}

fn column(result: &clearance_joint::scene::runner::RunResult, name: &str) -> Vec<f64> {
    result
        .twin(TwinKind::Ideal)
        .unwrap()
        .table
        .column(name)
        .unwrap()
}

/// The root of `k (target - theta) = m g l sin(theta)` by bisection on `[0, target]`.
fn static_angle(k: f64, target: f64, mgl: f64) -> f64 {
    let f = |th: f64| k * (target - th) - mgl * th.sin();
    let (mut lo, mut hi) = (0.0, target);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(mid) > 0.0 { lo = mid } else { hi = mid }
    }
    0.5 * (lo + hi)
}

#[test]
fn position_motor_pendulum_rests_at_the_closed_form_angle() {
    // A 1 kg pendulum hanging 0.5 m below its pivot, a force-based position motor towards
    // 0.8 rad (k = 20 N m/rad, c = 2 N m s/rad): at rest k (0.8 - theta) = m g l sin(theta).
    // Rapier solves the motor's row with the body's own inertia, apart from the joint's other
    // rows, so its discrete rest angle departs from that by O(dt^2) (measured 3.6e-3 rad at
    // steps of 1e-3 s, 4.8e-5 at 1e-4 s, 5.0e-7 at 1e-5 s).
    let mgl = 9.81 * 0.5;
    let expected = static_angle(20.0, 0.8, mgl);
    let (mut errors, mut energy) = (Vec::new(), Vec::new());
    for max_dt in [2e-4, 1e-4] {
        let scene = one_joint_scene(
            1.0,
            [0.0, -0.5, 0.0],
            "Revolute(axis: (0.0, 0.0, 1.0))",
            "Position(target_rad: 0.8, stiffness_nm_per_rad: 20.0, damping_nm_s_per_rad: 2.0)",
            &format!("max_dt_s: {max_dt}, end_s: 6.0, output_interval_s: 0.01, step: Adaptive"),
        );
        let result = Simulation::new(&scene, RunOptions::default())
            .unwrap()
            .run()
            .unwrap();
        assert!(result.guards.is_clean(), "{:?}", result.guards.violations);
        let theta = column(&result, "body_angle_deg")
            .last()
            .unwrap()
            .to_radians();
        let tau = *column(&result, "m_motor_nm").last().unwrap();
        let f = *column(&result, "m_force_n").last().unwrap();
        let ay = *column(&result, "body_ay_m_s2").last().unwrap();
        println!(
            "max_dt {max_dt}: rest angle {theta} against {expected}; motor {tau} N m against \
             {}, pivot {f} N",
            mgl * expected.sin()
        );
        errors.push((theta - expected).abs());
        // The motor carries the weight's moment, the pivot the weight; nothing accelerates (to
        // the departure of Rapier's rest state from the continuous one, which the solve at that
        // state shows).
        assert!((tau - mgl * expected.sin()).abs() < 1e-3 * mgl, "{tau}");
        assert!((f - 9.81).abs() < 1e-3 * 9.81, "{f}");
        assert!(ay.abs() < 2e-3 * 9.81, "{ay}");
        // The energy balance counts the motor's work (its damper dissipates): it closes.
        let inv = &result.twin(TwinKind::Ideal).unwrap().invariants;
        println!(
            "energy error {:?}, motor work {} J",
            inv.energy_error, inv.motor_work_j
        );
        energy.push(inv.energy_error.unwrap());
        // Lifted by 0.65 rad: the motor did m g l (1 - cos) = 1.0 J net.
        let lift = mgl * (1.0 - theta.cos());
        assert!(
            (inv.motor_work_j / lift - 1.0).abs() < 0.02,
            "{}",
            inv.motor_work_j
        );
    }
    assert!(
        errors[1] < 1e-4 && errors[1] < errors[0] / 3.0,
        "{errors:?}"
    );
    println!("energy errors {energy:?}");
    assert!(
        energy[1] < 1e-3 && energy[1] < energy[0] / 1.5,
        "{energy:?}"
    );
}

#[test]
fn soft_motor_torque_is_rapiers_impulse_in_the_limit() {
    // The pendulum swinging from rest at its start (0 rad) towards 0.8 rad: the solver's torque
    // at each state against Rapier's motor impulse over the step from it (Rapier evaluates the
    // law implicitly, at the step's end: a first-order difference).
    let mut errors = Vec::new();
    for dt in [2e-4, 1e-4, 5e-5] {
        let scene = one_joint_scene(
            1.0,
            [0.0, -0.5, 0.0],
            "Revolute(axis: (0.0, 0.0, 1.0))",
            "Position(target_rad: 0.8, stiffness_nm_per_rad: 20.0, damping_nm_s_per_rad: 0.5)",
            &format!("dt_s: {dt}, end_s: 1.0, output_interval_s: {dt}, step: Fixed"),
        );
        let (result, impulses) = run_with_impulses(&scene);
        let torque = column(&result, "m_motor_nm");
        let peak = torque.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let worst = impulses
            .iter()
            .zip(&torque)
            .map(|(&(_, r), s)| (r - s).abs())
            .fold(0.0, f64::max);
        println!(
            "dt {dt}: peak {peak} N m, worst |solver - Rapier| {worst} ({})",
            worst / peak
        );
        errors.push(worst / peak);
    }
    assert!(errors[0] < 0.02, "{errors:?}");
    for w in errors.windows(2) {
        let ratio = w[1] / w[0];
        assert!(ratio > 0.4 && ratio < 0.6, "first order: {errors:?}");
    }
}

#[test]
fn held_velocity_motor_turns_an_arm_against_gravity() {
    // A 1 kg arm, centre of mass 0.2 m out along x, driven about z at 2 pi rad/s by a stiff
    // velocity motor: holding the speed, the motor balances the weight's moment,
    // tau = m g l cos(theta), at each state (exact in the held model), and Rapier's impulse
    // follows it within its servo's lag.
    let w = std::f64::consts::TAU;
    let text = format!(
        r#"Scene(
            name: "arm",
            gravity: (0.0, -9.81, 0.0),
            reference_axis: (0.0, 0.0, 1.0),
            bodies: [
                (name: "ground", mass_kg: 0.0, inertia_kg_m2: (0.0, 0.0, 0.0), center_of_mass_m: (0.0, 0.0, 0.0), fixed: true),
                (name: "body", mass_kg: 1.0, inertia_kg_m2: (0.001, 0.004, 0.004), center_of_mass_m: (0.2, 0.0, 0.0),
                 velocity_m_s: (0.0, {}, 0.0), angular_velocity_rad_s: (0.0, 0.0, {w})),
            ],
            hinges: [],
            joints: [
                (name: "m", body1: "ground", body2: "body", point_m: (0.0, 0.0, 0.0), kind: Revolute(axis: (0.0, 0.0, 1.0)),
                 motor: Some(Velocity(target_rad_s: {w}, factor: 1e6))),
            ],
            run: (dt_s: 1e-5, end_s: 1.0, output_interval_s: 1e-5, step: Fixed, body_motion: true),
        )"#,
        0.2 * w
    );
    let scene = Scene::from_ron(&text, "test").unwrap();
    let (result, impulses) = run_with_impulses(&scene);
    let (angle, torque) = (
        column(&result, "body_angle_deg"),
        column(&result, "m_motor_nm"),
    );
    let mgl = 9.81 * 0.2;
    let worst = angle
        .iter()
        .zip(&torque)
        .map(|(a, t)| (t - mgl * a.to_radians().cos()).abs())
        .fold(0.0, f64::max);
    let worst_rapier = impulses
        .iter()
        .zip(&angle)
        .skip(1000) // Rapier's servo takes hold over the first steps
        .map(|(&(_, r), a)| (r - mgl * a.to_radians().cos()).abs())
        .fold(0.0, f64::max);
    println!("held: worst {worst} N m; Rapier's impulse: worst {worst_rapier} N m of {mgl}");
    assert!(worst < 1e-9 * mgl, "{worst}");
    assert!(worst_rapier < 2e-3 * mgl, "{worst_rapier}");
    // One turn a second: a turn after 1 s (Rapier's servo holds the speed to 1e-5).
    let last = *angle.last().unwrap();
    assert!((last - 360.0).abs() < 0.5, "{last}");
    // The motor's work is the weight's potential energy change: the balance closes.
    let inv = &result.twin(TwinKind::Ideal).unwrap().invariants;
    println!(
        "energy error {:?}, motor work {} J",
        inv.energy_error, inv.motor_work_j
    );
    assert!(inv.energy_error.unwrap() < 1e-3, "{:?}", inv.energy_error);
}

#[test]
fn linear_velocity_motor_holds_a_slider_up_an_incline() {
    // A 2 kg slider on a guide inclined 30 degrees, held at 0.1 m/s up the guide by a stiff
    // velocity motor: the motor pushes m g sin(30) = 9.81 N, the guide m g cos(30) = 16.99 N.
    let (s, c) = (0.5f64, 0.75f64.sqrt());
    let text = format!(
        r#"Scene(
            name: "incline",
            gravity: (0.0, -9.81, 0.0),
            reference_axis: (0.0, 0.0, 1.0),
            bodies: [
                (name: "ground", mass_kg: 0.0, inertia_kg_m2: (0.0, 0.0, 0.0), center_of_mass_m: (0.0, 0.0, 0.0), fixed: true),
                (name: "body", mass_kg: 2.0, inertia_kg_m2: (0.01, 0.01, 0.01), center_of_mass_m: (0.0, 0.0, 0.0),
                 velocity_m_s: ({}, {}, 0.0)),
            ],
            hinges: [],
            joints: [
                (name: "m", body1: "ground", body2: "body", point_m: (0.0, 0.0, 0.0), kind: Prismatic(axis: ({c}, {s}, 0.0)),
                 motor: Some(LinearVelocity(target_m_s: 0.1, factor: 1e6))),
            ],
            run: (dt_s: 1e-4, end_s: 0.5, output_interval_s: 1e-4, step: Fixed, body_motion: true),
        )"#,
        0.1 * c,
        0.1 * s
    );
    let scene = Scene::from_ron(&text, "test").unwrap();
    let (result, impulses) = run_with_impulses(&scene);
    let (f, guide) = (column(&result, "m_motor_n"), column(&result, "m_force_n"));
    let (vx, vy) = (
        column(&result, "body_vx_m_s"),
        column(&result, "body_vy_m_s"),
    );
    let w = 2.0 * 9.81;
    for k in 0..f.len() {
        assert!((f[k] - w * s).abs() < 1e-9, "motor {}", f[k]);
        assert!((guide[k] - w * c).abs() < 1e-9, "guide {}", guide[k]);
        // Rapier's servo holds the speed within F/(m factor) = 4.9e-6 m/s.
        let v = (vx[k] * vx[k] + vy[k] * vy[k]).sqrt();
        assert!((v - 0.1).abs() < 1e-5, "{v}");
    }
    let worst = impulses
        .iter()
        .skip(10)
        .map(|&(_, r)| (r - w * s).abs())
        .fold(0.0, f64::max);
    println!("Rapier's motor impulse / dt: worst {worst} N off {}", w * s);
    assert!(worst < 1e-6 * w, "{worst}");
    let x = column(&result, "body_x_m");
    assert!((x.last().unwrap() - 0.05 * c).abs() < 1e-5);
}

#[test]
fn linear_position_motor_rests_where_its_spring_carries_the_weight() {
    // A 2 kg slider on a vertical guide, a force-based position motor towards 0 (k = 500 N/m,
    // c = 20 N s/m): at rest x = -m g/k = -39.24 mm, the motor pushing m g.
    let scene = one_joint_scene(
        2.0,
        [0.0, 0.0, 0.0],
        "Prismatic(axis: (0.0, 1.0, 0.0))",
        "LinearPosition(target_m: 0.0, stiffness_n_per_m: 500.0, damping_n_s_per_m: 20.0)",
        "max_dt_s: 1e-3, end_s: 4.0, output_interval_s: 0.01, step: Adaptive",
    );
    let result = Simulation::new(&scene, RunOptions::default())
        .unwrap()
        .run()
        .unwrap();
    let y = *column(&result, "body_y_m").last().unwrap();
    let f = *column(&result, "m_motor_n").last().unwrap();
    println!("rest at {y} m, motor {f} N");
    assert!((y + 2.0 * 9.81 / 500.0).abs() < 1e-8, "{y}");
    assert!((f - 2.0 * 9.81).abs() < 1e-5, "{f}");
    // The first row: released at 0, the spring not yet stretched: free fall.
    let ay = column(&result, "body_ay_m_s2");
    assert!((ay[0] + 9.81).abs() < 1e-9, "{}", ay[0]);
}

/// The velocity motor guard's violation of a one-arm scene (1 kg, centre of mass 0.2 m out
/// along x, about z) run with its ideal twin, fixed steps of 1e-5 s.
fn motor_guard(motor: &str, body: &str, end_s: f64) -> Option<Violation> {
    let text = format!(
        r#"Scene(
            name: "arm",
            gravity: (0.0, -9.81, 0.0),
            reference_axis: (0.0, 0.0, 1.0),
            bodies: [
                (name: "ground", mass_kg: 0.0, inertia_kg_m2: (0.0, 0.0, 0.0), center_of_mass_m: (0.0, 0.0, 0.0), fixed: true),
                (name: "body", mass_kg: 1.0, inertia_kg_m2: (0.001, 0.004, 0.004), center_of_mass_m: (0.2, 0.0, 0.0){body}),
            ],
            hinges: [],
            joints: [
                (name: "m", body1: "ground", body2: "body", point_m: (0.0, 0.0, 0.0), kind: Revolute(axis: (0.0, 0.0, 1.0)),
                 motor: Some({motor})),
            ],
            run: (dt_s: 1e-5, end_s: {end_s}, output_interval_s: 1e-3, step: Fixed, body_motion: true),
        )"#
    );
    let scene = Scene::from_ron(&text, "test").unwrap();
    let result = Simulation::new(&scene, RunOptions::default())
        .unwrap()
        .run()
        .unwrap();
    result.guards.worst(GuardKind::MotorSpeed).cloned()
}

#[test]
fn velocity_motor_with_a_zero_target_reports_its_miss_in_its_unit() {
    // Issue 17: a weak motor (factor 1/s) told to hold the arm still lets the weight swing it;
    // relative to a zero target (floored at 1e-3) the miss read "26.75 of its target". It is
    // reported as it is, in rad/s, against the limit times that floor (the same ratio).
    let v = motor_guard("Velocity(target_rad_s: 0.0, factor: 1.0)", "", 0.05)
        .expect("the motor guard fires");
    let msg = v.to_string();
    println!("{msg}");
    assert_eq!(v.unit, Some("rad/s"), "{msg}");
    assert!(v.worst > v.limit, "{} against {}", v.worst, v.limit);
    // The arm falls away from zero speed at once: the first violating state is within the first
    // milliseconds, the worst at the end (the first time was once reported as the worst's).
    assert!(
        v.first_t_s < 1e-3 && v.t_s > 0.04,
        "first {} s, worst {} s",
        v.first_t_s,
        v.t_s
    );
    // Free fall of the arm's weight over 0.05 s bounds the miss: m g l t / (I + m l^2).
    assert!(
        v.worst > 1e-3 && v.worst < 9.81 * 0.2 * 0.05 / 0.044,
        "{msg}"
    );
    assert!(
        msg.contains(" rad/s (its target is 0; limit 1e-5 rad/s)")
            && !msg.contains("of its target"),
        "{msg}"
    );
    // The arm started at its target: the advice is the motor's own.
    assert!(msg.contains("raise its `factor`"), "{msg}");
}

#[test]
fn velocity_motor_started_from_rest_blames_the_initial_velocities() {
    // Issue 17: the arm starts at rest, its stiff motor at one turn a second: Rapier jumps it to
    // speed in the first steps. The guard used to say "raise its factor"; the cause is the
    // initial velocities, which do not match the motor.
    let w = std::f64::consts::TAU;
    let motor = format!("Velocity(target_rad_s: {w}, factor: 1e6)");
    let v = motor_guard(&motor, "", 0.01).expect("the motor guard fires");
    let msg = v.to_string();
    println!("{msg}");
    assert_eq!(v.t_s, 0.0, "{msg}");
    assert!(
        msg.contains("the velocity motor `m` starts at 0 rad/s against its target 6.283 rad/s")
            && msg.contains("the bodies' initial velocities do not match the motor")
            && !msg.contains("raise its `factor`"),
        "{msg}"
    );
    // Started at the motor's speed, the same arm holds it: no violation.
    let body = format!(
        ", velocity_m_s: (0.0, {}, 0.0), angular_velocity_rad_s: (0.0, 0.0, {w})",
        0.2 * w
    );
    let held = motor_guard(&motor, &body, 0.01);
    assert!(held.is_none(), "{:?}", held.map(|v| v.to_string()));
}

#[test]
fn motor_fields_are_validated_with_their_paths() {
    let hinge = "Revolute(axis: (0.0, 0.0, 1.0))";
    let slide = "Prismatic(axis: (0.0, 1.0, 0.0))";
    let cases = [
        (
            hinge,
            "Position(target_rad: 3.5, stiffness_nm_per_rad: 1.0, damping_nm_s_per_rad: 0.0)",
            "joints[m].motor.target_rad",
        ),
        (
            hinge,
            "Position(target_rad: 0.5, stiffness_nm_per_rad: -1.0, damping_nm_s_per_rad: 0.0)",
            "joints[m].motor.stiffness_nm_per_rad",
        ),
        (
            hinge,
            "Position(target_rad: 0.5, stiffness_nm_per_rad: 1.0, damping_nm_s_per_rad: 1e10)",
            "joints[m].motor.damping_nm_s_per_rad",
        ),
        (
            hinge,
            "Position(target_rad: 0.5, stiffness_nm_per_rad: 0.0, damping_nm_s_per_rad: 0.0)",
            "the motor does nothing",
        ),
        (
            hinge,
            "Position(target_rad: 0.5, stiffness_nm_per_rad: 1.0, damping_nm_s_per_rad: 0.0, target_rad_s: 1e5)",
            "joints[m].motor.target_rad_s",
        ),
        (
            hinge,
            "Velocity(target_rad_s: 1.0, factor: 0.0)",
            "joints[m].motor.factor",
        ),
        (
            hinge,
            "LinearVelocity(target_m_s: 1.0, factor: 1e6)",
            "a `LinearVelocity` motor needs a `Prismatic` joint",
        ),
        (
            slide,
            "Position(target_rad: 0.5, stiffness_nm_per_rad: 1.0, damping_nm_s_per_rad: 0.0)",
            "`LinearPosition`",
        ),
        (
            slide,
            "Velocity(target_rad_s: 1.0, factor: 1e6)",
            "`LinearVelocity`",
        ),
        (
            slide,
            "LinearVelocity(target_m_s: 1e3, factor: 1e6)",
            "joints[m].motor.target_m_s",
        ),
        (
            slide,
            "LinearVelocity(target_m_s: 1.0, factor: 1e13)",
            "joints[m].motor.factor",
        ),
        (
            slide,
            "LinearPosition(target_m: 1e5, stiffness_n_per_m: 1.0, damping_n_s_per_m: 0.0)",
            "joints[m].motor.target_m",
        ),
        (
            slide,
            "LinearPosition(target_m: 0.0, stiffness_n_per_m: NaN, damping_n_s_per_m: 0.0)",
            "joints[m].motor.stiffness_n_per_m",
        ),
        (
            slide,
            "LinearPosition(target_m: 0.0, stiffness_n_per_m: 1.0, damping_n_s_per_m: -2.0)",
            "joints[m].motor.damping_n_s_per_m",
        ),
        (
            slide,
            "LinearPosition(target_m: 0.0, stiffness_n_per_m: 1.0, damping_n_s_per_m: 0.0, target_m_s: -1e3)",
            "joints[m].motor.target_m_s",
        ),
        (
            "Prismatic(axis: (0.0, 1.0, 0.0), limits_m: Some((-0.1, 0.1)))",
            "LinearVelocity(target_m_s: 0.1, factor: 1e6)",
            "`limits_m` is not supported",
        ),
    ];
    for (kind, motor, needle) in cases {
        let e = one_joint(1.0, [0.0, -0.5, 0.0], kind, motor, "end_s: 1.0")
            .unwrap_err()
            .to_string();
        assert!(e.contains(needle), "{motor}: {e} (wanted {needle})");
    }
    // Every kind in its valid form (the README's examples).
    for (kind, motor) in [
        (hinge, "Velocity(target_rad_s: 6.28, factor: 1e6)"),
        (
            hinge,
            "Position(target_rad: 0.8, stiffness_nm_per_rad: 20.0, damping_nm_s_per_rad: 2.0)",
        ),
        (
            hinge,
            "Position(target_rad: 0.0, stiffness_nm_per_rad: 0.0, damping_nm_s_per_rad: 0.05, target_rad_s: 100.0)",
        ),
        (slide, "LinearVelocity(target_m_s: 0.1, factor: 1e6)"),
        (
            slide,
            "LinearPosition(target_m: 0.02, stiffness_n_per_m: 500.0, damping_n_s_per_m: 20.0)",
        ),
    ] {
        one_joint(1.0, [0.0, -0.5, 0.0], kind, motor, "end_s: 1.0").unwrap();
    }
}

/// `assets/four_bar.ron` over its first `end` seconds with `overrides`, run with `twins`.
fn run_four_bar(
    end: f64,
    overrides: &[&str],
    twins: Twins,
    skip_rows: bool,
) -> clearance_joint::scene::runner::RunResult {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/four_bar.ron");
    let mut scene = Scene::load(&path)
        .unwrap()
        .with_overrides(overrides)
        .unwrap();
    scene.run.end_s = end;
    Simulation::new(&scene, RunOptions { twins, skip_rows })
        .unwrap()
        .run()
        .unwrap()
}

/// The ideal twin's rows of `assets/four_bar.ron` (the crank on a held velocity motor, a
/// closed loop of ideal revolutes) over its first `end` seconds, with `overrides`; only the
/// ideal twin when `alone`. With the run's guard violations.
fn four_bar(
    end: f64,
    overrides: &[&str],
    alone: bool,
) -> (clearance_joint::table::Table, Vec<String>) {
    let twins = if alone { Twins::IdealOnly } else { Twins::Both };
    let result = run_four_bar(end, overrides, twins, false);
    (
        result.twin(TwinKind::Ideal).unwrap().table.clone(),
        result.guards.messages(),
    )
}

/// The largest difference of column `name` between two tables with the same rows, over the
/// largest magnitude in `reference`.
fn worst_relative(
    a: &clearance_joint::table::Table,
    reference: &clearance_joint::table::Table,
    name: &str,
) -> f64 {
    let (x, y) = (a.column(name).unwrap(), reference.column(name).unwrap());
    assert_eq!(x.len(), y.len());
    let peak = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    x.iter()
        .zip(&y)
        .map(|(p, q)| (p - q).abs())
        .fold(0.0, f64::max)
        / peak
}

#[test]
fn four_bar_reactions_under_adaptive_steps_match_a_fine_fixed_run() {
    // Half a turn, through the clearance twin's first impacts (1.3 ms), where its contacts cut
    // the shared steps from the bound to a fraction of a microsecond and back.
    let end = 0.05;
    let (fine, guards) = four_bar(end, &["run.step=Fixed", "run.dt_s=1e-6"], true);
    assert!(guards.is_empty(), "{guards:?}");
    let (adaptive, guards) = four_bar(end, &[], false);
    assert!(guards.is_empty(), "{guards:?}");
    // Steps up to 1e-4 s with the weaker motor the scene had before (factor 1e6): the first
    // impact slows the clearance twin's crank by 2.3 %, and a guard says so. (With one sweep over
    // the joints the ideal twin's motor missed its speed too; before the free-flight step bound,
    // the steps that the first impact cut abruptly let the crank speed jump by a third.)
    let (coarse, guards) = four_bar(end, &["run.max_dt_s=1e-4", "motor.factor=1e6"], false);
    assert!(
        guards
            .iter()
            .any(|g| g.contains("clearance twin's velocity motor `motor` missed its speed")),
        "{guards:?}"
    );
    let columns = [
        "crank_pin_force_n",
        "rocker_pin_force_n",
        "rocker_pivot_force_n",
        "motor_force_n",
        "motor_motor_nm",
        "coupler_ax_m_s2",
        "rocker_ay_m_s2",
    ];
    for name in columns {
        let (w, c) = (
            worst_relative(&adaptive, &fine, name),
            worst_relative(&coarse, &fine, name),
        );
        println!("{name}: steps <= 5e-6 s {w:.2e}, <= 1e-4 s {c:.2e} of the peak");
        // The scene's bound on the step (5e-6 s) with its 32 sweeps over the joints: measured
        // 7.4e-5 at worst (with one sweep, 2.7e-3: the loop's constraints were not solved).
        assert!(w < 5e-4, "{name}: {w}");
        // There the reactions follow that motion, but do not spike (solved from the half-step
        // velocities, the crank pin's peak was 3.2 times the fine run's).
        assert!(c < 0.1, "{name}: {c}");
    }
    let peak = |t: &clearance_joint::table::Table| {
        t.column("crank_pin_force_n")
            .unwrap()
            .iter()
            .fold(0.0f64, |m, v| m.max(*v))
    };
    println!(
        "crank pin peaks: {} {} {}",
        peak(&fine),
        peak(&adaptive),
        peak(&coarse)
    );
    assert!((peak(&coarse) / peak(&fine) - 1.0).abs() < 0.02);
}

#[test]
fn a_velocity_motor_that_misses_its_speed_is_flagged() {
    // The first impact (1.3 ms) slows a crank on a softer motor by 2.2 %: its torque and the
    // reactions, solved as if it held its speed, are off by that much, and the run says so.
    let (_, guards) = four_bar(0.003, &["motor.factor=1e6"], false);
    assert!(
        guards
            .iter()
            .any(|g| g.contains("velocity motor `motor` missed its speed")),
        "{guards:?}"
    );
    // The scene's own motor holds it within the limit.
    let (_, guards) = four_bar(0.003, &[], false);
    assert!(guards.is_empty(), "{guards:?}");
}

/// The clearance twin's first impact onset (s) of `assets/four_bar.ron` over its first 1.5 ms,
/// with `overrides`.
fn four_bar_first_onset(overrides: &[&str]) -> f64 {
    let result = run_four_bar(0.0015, overrides, Twins::ClearanceOnly, true);
    let twin = result.twin(TwinKind::Clearance).unwrap();
    twin.hinge_recorders()["rocker_pin"].contacts()[0].onset_t_s
}

#[test]
fn the_four_bars_joint_sweeps_bring_its_first_impact_to_the_fine_run() {
    // The light crank sits between its stiff motor and a coupler 4.5 times its inertia about the
    // pivot: one Gauss-Seidel sweep over the joints a step leaves part of their constraints
    // unsolved, and at the library's default steps (up to 1e-3 s, tolerance 0.0075) the first
    // impact came 19.7 us late (measured); the scene's 32 sweeps bring it within 0.7 us.
    let fine = four_bar_first_onset(&["run.step=Fixed", "run.dt_s=1e-6"]);
    let defaults = ["run.max_dt_s=1e-3", "run.tolerance=0.0075"];
    let swept = four_bar_first_onset(&defaults);
    let one = four_bar_first_onset(&[defaults[0], defaults[1], "run.solver_sweeps=1"]);
    println!(
        "first onset: fixed 1e-6 s {fine:.9} s; defaults {:+.3} us, with one sweep {:+.3} us",
        (swept - fine) * 1e6,
        (one - fine) * 1e6
    );
    assert!((swept - fine).abs() < 1e-6, "{swept} against {fine}");
    assert!(one - fine > 1e-5, "one sweep: {one} against {fine}");
}

#[test]
fn solver_sweeps_out_of_range_are_refused_by_name() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/four_bar.ron");
    for sweeps in ["0", "1001"] {
        let e = Scene::load(&path)
            .unwrap()
            .with_overrides(&[format!("run.solver_sweeps={sweeps}")])
            .and_then(|s| s.validated().map(|_| ()))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("run.solver_sweeps") && e.contains("1 to 1000"),
            "{sweeps}: {e}"
        );
    }
}
