//! The fidelity ladder: the same three scenes with the compliant model at a converged step (the
//! reference) and with the large-step model at 1/60, 1/240, 1e-3 and 1e-4 s.
//! `cargo bench --bench fidelity` prints one Markdown table (and writes it to
//! `bench_out/fidelity.md`).
//!
//! Scenes (every joint built from one `HingeDesign` with `HingeDesign::joint` or
//! `HingeDesign::large_step_joint`: same geometry, the law's own restitution, Bai dry friction's
//! sliding coefficient):
//! - `solar panel`: the paper's satellite and panel, free-floating, torsion-spring drive, 0.5 mm,
//!   5 s. Observed: the deployment angle.
//! - `drop-in arm`: the two-link arm of `examples/drop_in.rs` released at 30 deg under gravity,
//!   0.1 mm play in the elbow, 1 s. Observed: the lower link's angle.
//! - `driven crank`: a crank turned at 0.5 rev/s by a velocity motor, a bar hanging from its pin
//!   with 0.2 mm play, under gravity, 2 s. Observed: the bar's angle.
//!
//! A second table, "resolution", shows what the large-step model's substeps buy: a 2 kg rod
//! (0.6 m) pinned 0.3 m from its centre, released horizontal, 20 s at 1/60 s with Rapier's defaults,
//! for clearances 0.05 to 2 mm and `max_substeps` 4 to 64; beside it, how far Rapier's revolute
//! joint's anchors drift apart in the same swing (in units of each clearance).
//!
//! Errors are against the compliant model at the finest step (`dt_ref`); the row "compliant at
//! 2 dt_ref" is that reference's own error estimate by step doubling. Angles and rates are
//! compared every 50 ms. The column "ideal revolute's RMS angle error" runs the same scene with
//! Rapier's revolute joint in place of the clearance at that step, against the same at `dt_ref`:
//! the part of the error that is Rapier's integration at that step, whatever the joint. The peak force of the large-step model is its largest per-step normal
//! force (the limit's impulse over the substep), which measures an impact's impulse over one
//! substep, not the contact's force history.

use clearance_joint::model::angle::HingeAngle;
use clearance_joint::model::laws::{Bai, FrictionModel};
use clearance_joint::rapier::hinge::design::HingeDesign;
use clearance_joint::rapier::joint::ClearanceJointSet;
use clearance_joint::rapier::large_step::LargeStepJointSet;
use clearance_joint::rapier::sources::drive::{DriveSet, TorsionSpring};
use rapier3d_f64::math::{Pose, Rotation, Vector};
use rapier3d_f64::prelude::{
    IntegrationParameters, MassProperties, PhysicsWorld, RevoluteJointBuilder, RigidBodyBuilder,
    RigidBodyHandle,
};
use std::fmt::Write as _;
use std::time::Instant;

/// Sampling interval of angles and rates, s (a multiple of every step in the ladder).
const SAMPLE: f64 = 0.05;

#[derive(Clone, Copy, PartialEq, Eq)]
enum Model {
    Compliant,
    LargeStep,
    /// Rapier's revolute joint in place of the clearance: the floor of each step's error.
    Ideal,
}

/// A built scene: the world, the joint sets, drives, and what to observe.
struct Built {
    world: PhysicsWorld,
    compliant: ClearanceJointSet,
    play: LargeStepJointSet,
    drives: DriveSet,
    /// Observed angle: body `observed.1` relative to `observed.0` about `axis` (body 0's frame).
    observed: (RigidBodyHandle, RigidBodyHandle),
    axis: Vector,
}

struct Scene {
    name: &'static str,
    end: f64,
    dt_ref: f64,
    build: fn(Model, bool) -> Built,
    /// Dry friction (Bai) in the clearance; `false`: frictionless in both models.
    friction: bool,
}

/// The scenes' clearance: steel, the paper's law, Bai dry friction or none.
fn steel(radius: f64, c: f64, width: f64, friction: bool) -> HingeDesign {
    let law = if friction {
        FrictionModel::Bai(Bai::DRY)
    } else {
        FrictionModel::None
    };
    HingeDesign::steel_improved_liu(radius, c, width)
        .unwrap()
        .friction(law)
}

fn world(model: Model, gravity: Vector, dt: f64) -> PhysicsWorld {
    let mut w = PhysicsWorld::new();
    w.gravity = gravity;
    w.integration_parameters = IntegrationParameters {
        dt,
        // The compliant hook holds its force over the step: one substep (substeps make every impact gain energy).
        num_solver_iterations: if model == Model::Compliant { 1 } else { 4 },
        ..IntegrationParameters::default()
    };
    w
}

fn body(w: &mut PhysicsWorld, mass: f64, inertia: Vector, pose: Pose) -> RigidBodyHandle {
    w.bodies.insert(
        RigidBodyBuilder::dynamic()
            .pose(pose)
            .additional_mass_properties(MassProperties::new(Vector::ZERO, mass, inertia))
            .can_sleep(false),
    )
}

/// Adds the clearance joint of `c` between `b1` and `b2` in the model's set.
#[allow(clippy::too_many_arguments)]
fn joint(
    built: &mut Built,
    model: Model,
    c: &HingeDesign,
    b1: RigidBodyHandle,
    b2: RigidBodyHandle,
    a1: Vector,
    a2: Vector,
    axis: Vector,
) {
    match model {
        Model::Compliant => {
            let j = c.joint(a1, a2, axis, axis).expect("valid clearance");
            built
                .compliant
                .insert(
                    b1,
                    b2,
                    j,
                    &built.world.bodies,
                    &mut built.world.impulse_joints,
                )
                .unwrap();
        }
        Model::LargeStep => {
            let j = c
                .large_step_joint(a1, a2, axis, axis)
                .expect("valid clearance");
            built
                .play
                .insert(
                    b1,
                    b2,
                    j,
                    &built.world.bodies,
                    &mut built.world.impulse_joints,
                )
                .unwrap();
        }
        Model::Ideal => {
            built.world.impulse_joints.insert(
                b1,
                b2,
                RevoluteJointBuilder::new(axis)
                    .local_anchor1(a1)
                    .local_anchor2(a2)
                    .contacts_enabled(false),
                true,
            );
        }
    }
}

fn empty(w: PhysicsWorld, observed: (RigidBodyHandle, RigidBodyHandle), axis: Vector) -> Built {
    Built {
        world: w,
        compliant: ClearanceJointSet::new(),
        play: LargeStepJointSet::new(),
        drives: DriveSet::new(),
        observed,
        axis,
    }
}

/// The paper's satellite and panel (MODEL.md §4), c = 0.5 mm, dry.
fn solar_panel(model: Model, friction: bool) -> Built {
    let mut w = world(model, Vector::ZERO, 0.0);
    let sat = body(
        &mut w,
        768.0,
        Vector::new(104.96, 81.92, 104.96),
        Pose::IDENTITY,
    );
    let panel = body(
        &mut w,
        7.68,
        Vector::new(1.6137, 0.4156, 2.0293),
        Pose::from_translation(Vector::new(0.4, 0.0, 0.0)),
    );
    let axis = Vector::NEG_Y;
    let mut b = empty(w, (sat, panel), axis);
    let c = steel(0.010, 0.5e-3, 0.016, friction);
    let h = Vector::new(0.4, 0.0, 0.4);
    joint(
        &mut b,
        model,
        &c,
        sat,
        panel,
        h,
        h - Vector::new(0.4, 0.0, 0.0),
        axis,
    );
    b.drives.insert(
        TorsionSpring::new(sat, panel, axis, 0.135, 0.0015f64.to_degrees()).expect("valid drive"),
    );
    b
}

/// `examples/drop_in.rs`'s arm with the elbow's 0.1 mm play.
fn drop_in(model: Model, friction: bool) -> Built {
    let mut w = world(model, Vector::new(0.0, -9.81, 0.0), 0.0);
    let base = w.bodies.insert(RigidBodyBuilder::fixed());
    let r = Rotation::from_rotation_z(30f64.to_radians());
    let down = r * Vector::NEG_Y;
    let link = |w: &mut PhysicsWorld, (m, l): (f64, f64), centre: Vector| {
        let j = m * l * l / 12.0;
        body(
            w,
            m,
            Vector::new(j, 1e-3 * j, j),
            Pose::from_parts(centre, r),
        )
    };
    let upper = link(&mut w, (1.0, 0.4), 0.2 * down);
    let lower = link(&mut w, (0.5, 0.3), 0.55 * down);
    w.impulse_joints.insert(
        base,
        upper,
        RevoluteJointBuilder::new(Vector::Z)
            .local_anchor2(Vector::new(0.0, 0.2, 0.0))
            .contacts_enabled(false),
        true,
    );
    let mut b = empty(w, (base, lower), Vector::Z);
    let c = steel(0.005, 0.1e-3, 0.008, friction);
    joint(
        &mut b,
        model,
        &c,
        upper,
        lower,
        Vector::new(0.0, -0.2, 0.0),
        Vector::new(0.0, 0.15, 0.0),
        Vector::Z,
    );
    b
}

/// A crank turned at 0.5 rev/s by a velocity motor, a bar hanging from its pin with 0.2 mm play.
fn crank(model: Model, friction: bool) -> Built {
    let mut w = world(model, Vector::new(0.0, -9.81, 0.0), 0.0);
    let base = w.bodies.insert(RigidBodyBuilder::fixed());
    let crank = body(
        &mut w,
        1.0,
        Vector::splat(1e-3),
        Pose::from_translation(Vector::new(0.05, 0.0, 0.0)),
    );
    let bar = body(
        &mut w,
        0.5,
        Vector::new(3.75e-3, 3.75e-6, 3.75e-3),
        Pose::from_translation(Vector::new(0.1, -0.15, 0.0)),
    );
    w.impulse_joints.insert(
        base,
        crank,
        RevoluteJointBuilder::new(Vector::Z)
            .local_anchor2(Vector::new(-0.05, 0.0, 0.0))
            .motor_velocity(std::f64::consts::PI, 1e9)
            .motor_max_force(1e4)
            .contacts_enabled(false),
        true,
    );
    let mut b = empty(w, (base, bar), Vector::Z);
    let c = steel(0.008, 0.2e-3, 0.012, friction);
    joint(
        &mut b,
        model,
        &c,
        crank,
        bar,
        Vector::new(0.05, 0.0, 0.0),
        Vector::new(0.0, 0.15, 0.0),
        Vector::Z,
    );
    b
}

/// What one run produced.
#[derive(Default)]
struct Trace {
    angles: Vec<f64>, // deg, every SAMPLE
    rates: Vec<f64>,  // deg/s
    first_impact: Option<f64>,
    peak_force: f64,
    impacts: u64,
    steps: u64,
    wall: f64,
    max_substeps: usize,
    under_resolved: u64,
}

fn simulate(scene: &Scene, model: Model, dt: f64) -> Trace {
    let mut b = (scene.build)(model, scene.friction);
    b.world.integration_parameters.dt = dt;
    let steps = (scene.end / dt).round() as u64;
    let every = (SAMPLE / dt).round() as u64;
    let mut angle = HingeAngle::default();
    let mut t = Trace {
        steps,
        ..Trace::default()
    };
    let (o0, o1) = b.observed;
    let sample = |b: &Built, angle: &mut HingeAngle, t: &mut Trace| {
        let (r0, r1) = (&b.world.bodies[o0], &b.world.bodies[o1]);
        let a = angle.update(r0.rotation(), r1.rotation(), b.axis);
        let axis = *r0.rotation() * b.axis;
        t.angles.push(a.to_degrees());
        t.rates
            .push((r1.angvel() - r0.angvel()).dot(axis).to_degrees());
    };
    sample(&b, &mut angle, &mut t);
    let start = Instant::now();
    for k in 1..=steps {
        b.drives.apply(&mut b.world.bodies);
        match model {
            Model::Compliant => {
                b.compliant
                    .apply(
                        &mut b.world.bodies,
                        &b.world.impulse_joints,
                        &b.world.integration_parameters,
                    )
                    .expect("the reference step is stable");
            }
            Model::LargeStep => b.play.before_step(
                &mut b.world.bodies,
                &mut b.world.impulse_joints,
                &b.world.integration_parameters,
            ),
            Model::Ideal => {}
        }
        b.world.step();
        b.play
            .after_step(&mut b.world.bodies, &b.world.impulse_joints);
        let time = k as f64 * dt;
        let (onset, force) = match model {
            Model::Ideal => (false, 0.0),
            Model::Compliant => {
                let r = b.compliant.iter().next().expect("one joint").1.report();
                // The force acting over the step just taken was evaluated before it.
                (r.onset, r.force.normal_force)
            }
            Model::LargeStep => {
                let r = b.play.iter().next().expect("one joint").1.report();
                t.max_substeps = t.max_substeps.max(r.substeps);
                t.under_resolved += u64::from(r.under_resolved);
                (r.onset, r.normal_force)
            }
        };
        if onset {
            t.impacts += 1;
            if t.first_impact.is_none() {
                t.first_impact = Some(time - if model == Model::Compliant { dt } else { 0.0 });
            }
        }
        t.peak_force = t.peak_force.max(force);
        if k % every == 0 {
            sample(&b, &mut angle, &mut t);
        }
    }
    t.wall = start.elapsed().as_secs_f64();
    if model == Model::Compliant {
        t.max_substeps = 1;
    }
    t
}

fn rms_diff(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    (a.iter()
        .zip(b)
        .take(n)
        .map(|(x, y)| (x - y).powi(2))
        .sum::<f64>()
        / n as f64)
        .sqrt()
}

fn row(out: &mut String, scene: &str, label: &str, t: &Trace, r: &Trace, floor: &str) {
    let final_err = (t.angles.last().unwrap() - r.angles.last().unwrap()).abs();
    let impact = match (t.first_impact, r.first_impact) {
        (Some(a), Some(b)) => format!("{:+.4}", a - b),
        (None, None) => "-".into(),
        (a, _) => format!("{a:?}"),
    };
    let peak = if r.peak_force > 0.0 {
        format!("{:+.1} %", (t.peak_force / r.peak_force - 1.0) * 100.0)
    } else {
        "-".into()
    };
    let _ = writeln!(
        out,
        "| {scene} | {label} | {:.4} | {:.4} | {floor} | {:.3} | {impact} | {:.1} ({peak}) | {} | {} | {:.2} | {:.3} |",
        final_err,
        rms_diff(&t.angles, &r.angles),
        rms_diff(&t.rates, &r.rates),
        t.peak_force,
        t.impacts,
        t.max_substeps,
        t.wall / t.steps as f64 * 1e6,
        t.wall,
    );
}

/// Largest `|e|/c`, mean substeps and under-resolved steps of the rod pendulum at 1/60 s, or
/// (`cap = None`) the largest anchor separation of Rapier's revolute in its place, over `c`.
fn resolution(clearance: f64, cap: Option<usize>) -> (f64, f64, u64) {
    let mut w = world(Model::LargeStep, Vector::new(0.0, -9.81, 0.0), 1.0 / 60.0);
    let base = w.bodies.insert(RigidBodyBuilder::fixed());
    let rod = body(
        &mut w,
        2.0,
        Vector::splat(2.0 * 0.36 / 12.0),
        Pose::from_translation(Vector::new(0.3, 0.0, 0.0)),
    );
    let anchor = Vector::new(-0.3, 0.0, 0.0);
    let mut play = LargeStepJointSet::new();
    let pin = cap.map(|cap| {
        let joint = clearance_joint::rapier::large_step::LargeStepJointBuilder::new(
            Vector::Z,
            clearance_joint::model::laws::BearingGeometry::from_clearance(0.010, clearance, 0.016)
                .expect("valid geometry"),
        )
        .local_anchor2(anchor)
        .max_substeps(cap)
        .build()
        .expect("valid joint");
        play.insert(base, rod, joint, &w.bodies, &mut w.impulse_joints)
            .unwrap()
    });
    if pin.is_none() {
        w.impulse_joints.insert(
            base,
            rod,
            RevoluteJointBuilder::new(Vector::Z).local_anchor2(anchor),
            true,
        );
    }
    let (mut worst, mut substeps, mut flagged) = (0.0f64, 0usize, 0u64);
    let steps = 1200;
    for _ in 0..steps {
        play.before_step(
            &mut w.bodies,
            &mut w.impulse_joints,
            &w.integration_parameters,
        );
        w.step();
        play.after_step(&mut w.bodies, &w.impulse_joints);
        match pin {
            Some(pin) => {
                let r = play.get(pin).expect("inserted").report();
                worst = worst.max(r.eccentricity_ratio);
                substeps += r.substeps;
                flagged += u64::from(r.under_resolved);
            }
            None => {
                let p = *w.bodies[rod].position() * anchor;
                worst = worst.max(p.length() / clearance);
                substeps += 4;
            }
        }
    }
    (worst, substeps as f64 / steps as f64, flagged)
}

fn main() {
    let scenes = [
        Scene {
            name: "solar panel",
            end: 5.0,
            dt_ref: 5e-6,
            build: solar_panel,
            friction: true,
        },
        Scene {
            name: "drop-in arm",
            end: 1.0,
            dt_ref: 2.5e-6,
            build: drop_in,
            friction: true,
        },
        Scene {
            name: "drop-in arm, frictionless",
            end: 1.0,
            dt_ref: 2.5e-6,
            build: drop_in,
            friction: false,
        },
        Scene {
            name: "driven crank",
            end: 2.0,
            dt_ref: 1.25e-6,
            build: crank,
            friction: true,
        },
    ];
    let mut out = String::new();
    let _ = writeln!(
        out,
        "| scene | model, step | final angle error (deg) | RMS angle error (deg) | ideal revolute's RMS angle error at this step (deg) | RMS rate error (deg/s) | first impact time error (s) | peak force, N (error) | contact onsets | substeps (max) | us/step | wall (s) |"
    );
    let _ = writeln!(out, "|---|---|---|---|---|---|---|---|---|---|---|---|");
    for scene in &scenes {
        eprintln!("{}: reference ...", scene.name);
        let reference = simulate(scene, Model::Compliant, scene.dt_ref);
        let coarse = simulate(scene, Model::Compliant, 2.0 * scene.dt_ref);
        let ideal_reference = simulate(scene, Model::Ideal, scene.dt_ref);
        let _ = writeln!(
            out,
            "| {} | compliant, dt_ref = {:e} s (reference) | 0 | 0 | - | 0 | {} | {:.1} | {} | 1 | {:.2} | {:.3} |",
            scene.name,
            scene.dt_ref,
            reference
                .first_impact
                .map_or("-".into(), |t| format!("at {t:.4}")),
            reference.peak_force,
            reference.impacts,
            reference.wall / reference.steps as f64 * 1e6,
            reference.wall,
        );
        row(
            &mut out,
            scene.name,
            &format!("compliant, 2 dt_ref = {:e} s", 2.0 * scene.dt_ref),
            &coarse,
            &reference,
            "-",
        );
        for (label, dt) in [
            ("1/60 s", 1.0 / 60.0),
            ("1/240 s", 1.0 / 240.0),
            ("1e-3 s", 1e-3),
            ("1e-4 s", 1e-4),
        ] {
            eprintln!("{}: large step {label} ...", scene.name);
            let t = simulate(scene, Model::LargeStep, dt);
            let ideal = simulate(scene, Model::Ideal, dt);
            let floor = format!("{:.4}", rms_diff(&ideal.angles, &ideal_reference.angles));
            row(
                &mut out,
                scene.name,
                &format!("large step, {label}"),
                &t,
                &reference,
                &floor,
            );
        }
    }
    let _ = writeln!(
        out,
        "\nResolution: rod pendulum released horizontal, 20 s at 1/60 s, Rapier's defaults. Largest |e|/c \
         (mean substeps; steps flagged under-resolved) by max_substeps, and Rapier's revolute's largest \
         anchor separation over c.\n"
    );
    let caps = [4, 8, 16, 32, 64];
    let _ = writeln!(
        out,
        "| c (mm) | revolute's anchors apart / c | {} |",
        caps.map(|c| format!("max_substeps {c}")).join(" | ")
    );
    let _ = writeln!(out, "|---|---|{}", "---|".repeat(caps.len()));
    for c in [0.05e-3, 0.2e-3, 0.5e-3, 2e-3] {
        let cells: Vec<String> = caps
            .iter()
            .map(|&cap| {
                let (worst, mean, flagged) = resolution(c, Some(cap));
                format!("{worst:.3} ({mean:.1}; {flagged})")
            })
            .collect();
        let _ = writeln!(
            out,
            "| {} | {:.3} | {} |",
            c * 1e3,
            resolution(c, None).0,
            cells.join(" | ")
        );
    }
    print!("{out}");
    let _ = std::fs::create_dir_all("bench_out");
    if let Err(e) = std::fs::write("bench_out/fidelity.md", &out) {
        eprintln!("cannot write bench_out/fidelity.md: {e}");
    }
}
