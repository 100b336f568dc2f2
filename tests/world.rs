//! `ClearanceWorld`: the one world type. Its step runs every set's hooks (the large-step joints'
//! included, which a bare `world.step()` loop can forget), it steps to the bit like the `Stepper`
//! with the same sets, and it notices a compliant joint added through its public field.

use clearance_joint::model::laws::BearingGeometry;
use clearance_joint::prelude::*;
use clearance_joint::rapier::large_step::LargeStepJointBuilder;
use rapier3d_f64::prelude::*;

/// A 2 kg arm whose centre of mass hangs 0.3 m below a fixed base at the origin.
fn arm_world(iterations: usize) -> (PhysicsWorld, RigidBodyHandle, RigidBodyHandle) {
    let mut rapier = PhysicsWorld::new();
    rapier.gravity = Vector::new(0.0, -9.81, 0.0);
    rapier.integration_parameters.num_solver_iterations = iterations;
    let base = rapier.bodies.insert(RigidBodyBuilder::fixed());
    let arm = rapier.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.3, 0.0, 0.0))
            .additional_mass_properties(MassProperties::new(Vector::ZERO, 2.0, Vector::splat(0.02)))
            .can_sleep(false),
    );
    (rapier, base, arm)
}

/// The arm's compliant pin: steel, bearing radius 10 mm, clearance 0.2 mm, width 16 mm.
fn compliant_pin() -> ClearanceJoint {
    Clearance::steel_improved_liu(0.010, 0.2e-3, 0.016)
        .unwrap()
        .joint(
            Vector::ZERO,
            Vector::new(-0.3, 0.0, 0.0),
            Vector::Z,
            Vector::Z,
        )
        .unwrap()
}

fn large_step_pin() -> LargeStepJoint {
    let geometry = BearingGeometry::from_clearance(0.010, 1e-3, 0.016).unwrap();
    LargeStepJointBuilder::new(Vector::Z, geometry)
        .local_anchor2(Vector::new(-0.3, 0.0, 0.0))
        .restitution(0.3)
        .build()
        .unwrap()
}

/// The trap of a bare loop: the large-step joint's hooks forgotten. Inside the world's step they
/// cannot be: the journal stays in its bearing at 60 Hz with Rapier's 4 iterations, and the
/// report reads the weight the pin carries once the arm hangs still.
#[test]
fn large_step_hooks_run_inside_the_world_step() {
    let (rapier, base, arm) = arm_world(4);
    let mut world = ClearanceWorld::new(rapier, StepControl::fixed(1.0 / 60.0));
    let pin = world.insert_large_step(base, arm, large_step_pin());
    let mut worst: f64 = 0.0;
    while world.time() < 20.0 {
        world.step(20.0).unwrap();
        let r = world.large_step.get(pin).unwrap().report();
        worst = worst.max(r.eccentricity_ratio);
    }
    assert!(worst < 1.1, "the journal left its bearing: |e|/c = {worst}");
    let r = *world.large_step.get(pin).unwrap().report();
    // Swinging down from horizontal and damped by the bounces' restitution and Rapier's joint
    // damping, the arm ends hanging: the pin carries at least its weight, 2 kg x 9.81 m/s^2,
    // plus what its swing still adds.
    assert!(
        r.normal_force > 19.0,
        "the readout is zero or low: {}",
        r.normal_force
    );
    assert!(world.large_step.get(pin).unwrap().impacts() > 0);
    assert!(world.guards().is_clean(), "{:?}", world.guards());
}

/// The world's step is the `Stepper`'s with the same sets, to the bit.
#[test]
fn the_world_steps_like_the_stepper_with_the_same_sets() {
    let control = StepControl::adaptive(1e-3, 0.0075);
    let (rapier, base, arm) = arm_world(1);
    let mut world = ClearanceWorld::new(rapier, control);
    world.insert_clearance(base, arm, compliant_pin());
    world.step_to(0.05).unwrap();

    let (mut rapier, base2, arm2) = arm_world(1);
    let mut joints = ClearanceJointSet::new();
    joints.insert(base2, arm2, compliant_pin(), &mut rapier.impulse_joints);
    let mut stepper = Stepper::new(control);
    while stepper.time() < 0.05 {
        stepper.step(&mut rapier, &mut [&mut joints], 0.05).unwrap();
    }
    assert_eq!(world.steps(), stepper.steps());
    let (a, b) = (&world.rapier.bodies[arm], &rapier.bodies[arm2]);
    assert_eq!(a.translation(), b.translation());
    assert_eq!(a.linvel(), b.linvel());
    assert_eq!(a.angvel(), b.angvel());
}

/// A compliant joint inserted through the public field between steps gets its forces evaluated
/// before the next step (as through `insert_clearance`), and in a world the compliant model
/// cannot step (4 solver iterations) it is refused at that step, naming the setting.
#[test]
fn a_joint_added_through_the_field_is_noticed() {
    let (rapier, base, arm) = arm_world(4);
    let mut world = ClearanceWorld::new(rapier, StepControl::fixed(1e-4));
    world.step(1e-4).unwrap();
    let w = &mut world;
    w.clearance
        .insert(base, arm, compliant_pin(), &mut w.rapier.impulse_joints);
    let e = world.step(2e-4).unwrap_err().to_string();
    assert!(e.contains("num_solver_iterations"), "{e}");
}

/// The reaction solve knows the large-step joints through their constraint forces: a link hanging
/// from a large-step pin carries a second link on an ideal revolute, and the revolute's exact
/// reaction is the lower link's weight (a solve blind to the pin would let the upper link fall
/// freely and find no reaction).
#[test]
fn reactions_see_the_large_step_joints() {
    let mut rapier = PhysicsWorld::new();
    rapier.gravity = Vector::new(0.0, -9.81, 0.0);
    let base = rapier.bodies.insert(RigidBodyBuilder::fixed());
    let link = |y: f64, m: f64| {
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.0, y, 0.0))
            .additional_mass_properties(MassProperties::new(Vector::ZERO, m, Vector::splat(0.01)))
            .can_sleep(false)
    };
    let upper = rapier.bodies.insert(link(-0.2, 1.0));
    let lower = rapier.bodies.insert(link(-0.6, 3.0));
    let elbow = RevoluteJointBuilder::new(Vector::Z)
        .local_anchor1(Vector::new(0.0, -0.2, 0.0))
        .local_anchor2(Vector::new(0.0, 0.2, 0.0))
        .contacts_enabled(false);
    rapier.impulse_joints.insert(upper, lower, elbow, true);
    let mut world = ClearanceWorld::new(rapier, StepControl::fixed(1.0 / 60.0));
    let geometry = BearingGeometry::from_clearance(0.010, 1e-3, 0.016).unwrap();
    let pin = LargeStepJointBuilder::new(Vector::Z, geometry)
        .local_anchor2(Vector::new(0.0, 0.2, 0.0))
        .restitution(0.3)
        .build()
        .unwrap();
    world.insert_large_step(base, upper, pin);
    world.step_to(5.0).unwrap();
    let joints = [IdealJoint::Revolute(IdealRevolute {
        body1: upper,
        body2: lower,
        local_anchor1: Vector::new(0.0, -0.2, 0.0),
        local_anchor2: Vector::new(0.0, 0.2, 0.0),
        local_axis1: Vector::Z,
    })];
    let mut solver = ReactionSolver::default();
    let f = world.solve_reactions(&mut solver, &joints).unwrap()[0];
    let weight = 3.0 * 9.81;
    assert!(
        (f.length() - weight).abs() < 0.02 * weight,
        "elbow reaction {f:?}, the lower link weighs {weight} N"
    );
}

/// `step_to` refuses a time it could never reach (no endless loop), naming the argument.
#[test]
fn step_to_refuses_an_unreachable_time() {
    let (rapier, _, _) = arm_world(1);
    let mut world = ClearanceWorld::new(rapier, StepControl::fixed(1e-3));
    for until in [f64::INFINITY, f64::NAN] {
        let e = world.step_to(until).unwrap_err().to_string();
        assert!(e.contains("`until`") && e.contains("finite"), "{e}");
    }
    assert_eq!(world.step_to(0.01).unwrap(), 10);
    assert_eq!(world.step_to(0.005).unwrap(), 0);
}
