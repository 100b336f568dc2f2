//! Drop-in, plain Rapier: a two-link arm hangs from a fixed base on two ideal revolute joints and
//! swings down from 30 degrees under gravity. The same Rapier code runs twice; the second time,
//! one call turns the elbow's revolute joint into a clearance joint (0.1 mm of radial play in a
//! 10 mm steel bearing, dry friction). Everything else, including the step loop (a
//! `ClearanceWorld`, whose `step` takes the place of `world.step()`), is identical.
//!
//! `cargo run --release --example drop_in`

use clearance_joint::Result;
use clearance_joint::model::angle::{UnwrappedAngle, twist_angle};
use clearance_joint::model::laws::{Bai, FrictionModel};
use clearance_joint::rapier::hinge::convert::{BearingSide, ConvertRevolute};
use clearance_joint::rapier::hinge::design::HingeDesign;
use clearance_joint::rapier::pipeline::stepper::StepControl;
use clearance_joint::rapier::pipeline::world::ClearanceWorld;
use rapier3d_f64::math::{Rotation, Vector};
use rapier3d_f64::prelude::{
    ImpulseJointHandle, MassProperties, PhysicsWorld, RevoluteJointBuilder, RigidBodyBuilder,
    RigidBodyHandle,
};
use std::process::ExitCode;

/// Step, s. The elbow's steel contact under the swinging arm's load is stable only below about
/// 3.8e-5 s: the hook refuses 5e-5 s with an error naming the limit.
pub const DT: f64 = 2e-5;
/// Simulated time, s.
pub const END: f64 = 1.0;
/// Initial angle of the straight arm from the downward vertical, deg.
pub const START_DEG: f64 = 30.0;
const GRAVITY: f64 = 9.81;
const UPPER: (f64, f64) = (1.0, 0.4); // mass kg, length m
const LOWER: (f64, f64) = (0.5, 0.3);

/// The bodies and joints of one arm.
pub struct Arm {
    /// The upper link (shoulder to elbow).
    pub upper: RigidBodyHandle,
    /// The lower link (hangs from the elbow).
    pub lower: RigidBodyHandle,
    /// The shoulder: base to upper link.
    pub shoulder: ImpulseJointHandle,
    /// The elbow: upper link (bearing) to lower link (journal).
    pub elbow: ImpulseJointHandle,
}

fn link(
    world: &mut PhysicsWorld,
    (mass, length): (f64, f64),
    center: Vector,
    rotation: Rotation,
) -> RigidBodyHandle {
    let j = mass * length * length / 12.0;
    world.bodies.insert(
        RigidBodyBuilder::dynamic()
            .pose(rapier3d_f64::math::Pose::from_parts(center, rotation))
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                mass,
                Vector::new(j, 1e-3 * j, j),
            ))
            .can_sleep(false),
    )
}

/// The arm on two ideal revolute joints about z, gravity along -y, in a `ClearanceWorld` at
/// fixed steps of [`DT`].
pub fn build() -> (ClearanceWorld, Arm) {
    let mut world = PhysicsWorld::new();
    world.gravity = Vector::new(0.0, -GRAVITY, 0.0);
    world.integration_parameters.dt = DT;
    world.integration_parameters.num_solver_iterations = 1; // as the scenes run (sub-cycled, the default, takes any)
    let base = world.bodies.insert(RigidBodyBuilder::fixed());
    let r = Rotation::from_rotation_z(START_DEG.to_radians());
    let down = r * Vector::NEG_Y;
    let upper = link(&mut world, UPPER, 0.5 * UPPER.1 * down, r);
    let lower = link(&mut world, LOWER, (UPPER.1 + 0.5 * LOWER.1) * down, r);
    let shoulder = world.impulse_joints.insert(
        base,
        upper,
        RevoluteJointBuilder::new(Vector::Z)
            .local_anchor2(Vector::new(0.0, 0.5 * UPPER.1, 0.0))
            .contacts_enabled(false),
        true,
    );
    let elbow = world.impulse_joints.insert(
        upper,
        lower,
        RevoluteJointBuilder::new(Vector::Z)
            .local_anchor1(Vector::new(0.0, -0.5 * UPPER.1, 0.0))
            .local_anchor2(Vector::new(0.0, 0.5 * LOWER.1, 0.0))
            .contacts_enabled(false),
        true,
    );
    (
        ClearanceWorld::new(world, StepControl::fixed(DT)),
        Arm {
            upper,
            lower,
            shoulder,
            elbow,
        },
    )
}

/// What one run measured.
#[derive(Clone, Debug, Default)]
pub struct Run {
    /// Final shoulder angle (upper link from its start), deg.
    pub shoulder_deg: f64,
    /// Final elbow angle (lower link relative to the upper), deg.
    pub elbow_deg: f64,
    /// Largest elbow force, from the lower link's momentum balance `m dv/dt - m g`, N.
    pub peak_elbow_force_n: f64,
    /// Root-mean-square elbow force, N.
    pub rms_elbow_force_n: f64,
    /// Largest contact force of the elbow's clearance joint, N (clearance only; the same force
    /// as the momentum balance sees, from the joint's own report).
    pub peak_contact_force_n: f64,
    /// Contact onsets in the elbow, chatter included (clearance only).
    pub onsets: u64,
    /// Largest penetration in the elbow, um (clearance only).
    pub max_penetration_um: f64,
}

/// Steps `world` to [`END`] with `ClearanceWorld::step` in place of `world.step()`: it applies
/// the clearance forces, keeps the kicks consistent and refuses an unstable step. The same loop
/// for both runs.
fn simulate(mut world: ClearanceWorld, arm: &Arm) -> Result<Run> {
    world.prepare()?; // the joints' forces at the start
    let mut run = Run::default();
    let (mut shoulder, mut elbow) = (UnwrappedAngle::default(), UnwrappedAngle::default());
    let start = *world.rapier.bodies[arm.upper].rotation();
    let (mut sum_sq, mut steps) = (0.0, 0u64);
    while world.time() < END {
        let v_before = world.rapier.bodies[arm.lower].linvel();
        // The joint's contact over the coming step (evaluated at its start).
        for (_, j) in world.clearance.iter() {
            let r = j.report();
            run.onsets += u64::from(r.onset);
            run.peak_contact_force_n = run.peak_contact_force_n.max(r.force.on_journal.length());
            run.max_penetration_um = run.max_penetration_um.max(r.state.penetration * 1e6);
        }
        let step = world.step(END)?; // was: world.step()
        // The lower link's momentum balance: applied forces act for the step's kick.
        let bodies = &world.rapier.bodies;
        let lower = &bodies[arm.lower];
        let gravity = world.rapier.gravity;
        let force =
            (LOWER.0 * (lower.linvel() - v_before) / step.kick - LOWER.0 * gravity).length();
        run.peak_elbow_force_n = run.peak_elbow_force_n.max(force);
        sum_sq += force * force;
        steps += 1;
        let (q1, q2) = (*bodies[arm.upper].rotation(), *lower.rotation());
        shoulder.update(twist_angle(&(q1 * start.inverse()), Vector::Z));
        elbow.update(twist_angle(&(q1.inverse() * q2), Vector::Z));
    }
    run.shoulder_deg = shoulder.value().to_degrees();
    run.elbow_deg = elbow.value().to_degrees();
    run.rms_elbow_force_n = (sum_sq / steps as f64).sqrt();
    Ok(run)
}

/// The elbow's clearance: a 10 mm steel bearing, 8 mm wide, 0.1 mm radial play, dry friction.
/// Explicit contact: the run's fixed steps resolve every contact, and the lower link's momentum
/// balance over a step then reads the contact force the joint reports at the step's start (a
/// sub-cycled joint, the default, delivers a step's contact impulse spread over the step).
pub fn elbow_clearance() -> Result<HingeDesign> {
    Ok(HingeDesign::steel_improved_liu(0.005, 0.1e-3, 0.008)?
        .friction(FrictionModel::Bai(Bai::DRY))
        .integration(clearance_joint::rapier::joint::ContactIntegration::Explicit)
        .name("elbow"))
}

/// The arm with ideal hinges.
pub fn ideal_run() -> Result<Run> {
    let (world, arm) = build();
    simulate(world, &arm)
}

/// The same arm with the elbow converted into a clearance joint.
pub fn clearance_run() -> Result<Run> {
    let (mut world, arm) = build();
    // The whole change: the elbow's revolute joint becomes a clearance joint.
    world.clearance.convert_revolute(
        arm.elbow,
        BearingSide::Body1,
        elbow_clearance()?,
        &mut world.rapier.impulse_joints,
    )?;
    simulate(world, &arm)
}

/// Both runs: ideal, then with the elbow converted.
pub fn run() -> Result<(Run, Run)> {
    Ok((ideal_run()?, clearance_run()?))
}

/// The printed comparison.
pub fn report((ideal, clear): &(Run, Run)) -> String {
    let mut s = format!(
        "drop_in: two-link arm released at {START_DEG} deg under gravity, {END} s, dt = {DT:e} s\n\
         elbow: Rapier revolute vs clearance joint (0.1 mm radial play, steel, dry friction)\n\n\
         {:<28}{:>14}{:>14}\n",
        "", "ideal", "clearance"
    );
    let mut row =
        |label: &str, a: String, b: String| s.push_str(&format!("{label:<28}{a:>14}{b:>14}\n"));
    row(
        "final shoulder angle (deg)",
        format!("{:.4}", ideal.shoulder_deg),
        format!("{:.4}", clear.shoulder_deg),
    );
    row(
        "final elbow angle (deg)",
        format!("{:.4}", ideal.elbow_deg),
        format!("{:.4}", clear.elbow_deg),
    );
    row(
        "peak elbow force (N)",
        format!("{:.3}", ideal.peak_elbow_force_n),
        format!("{:.3}", clear.peak_elbow_force_n),
    );
    row(
        "rms elbow force (N)",
        format!("{:.3}", ideal.rms_elbow_force_n),
        format!("{:.3}", clear.rms_elbow_force_n),
    );
    row(
        "elbow onsets",
        ideal.onsets.to_string(),
        clear.onsets.to_string(),
    );
    row(
        "max penetration (um)",
        "-".into(),
        format!("{:.3}", clear.max_penetration_um),
    );
    s
}

fn main() -> ExitCode {
    match run() {
        Ok(runs) => {
            print!("{}", report(&runs));
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
