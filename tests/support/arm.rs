//! The plain-API arm on one clearance pin, shared by `tests/spatial.rs` and
//! `benches/step_cost.rs` (each includes this file).

use clearance_joint::prelude::*;
use rapier3d_f64::prelude::{MassProperties, PhysicsWorld, RigidBodyBuilder, RigidBodyHandle};

/// A 2 kg arm (0.02 kg m^2 about each axis) whose centre of mass sits 0.3 m from a fixed base at
/// the origin, `offset` m along the hinge's axis (z) from the pin's mid-plane, on the pin
/// `clearance`, released horizontal under gravity (-9.81 m/s^2 along y) in a world of one solver
/// iteration (the compliant joints need it) stepped by `control`. Returns the world, the arm and
/// the pin.
pub fn arm(
    clearance: HingeDesign,
    offset: f64,
    control: StepControl,
) -> (ClearanceWorld, RigidBodyHandle, ClearanceJointHandle) {
    let mut rapier = PhysicsWorld::new();
    rapier.gravity = Vector::new(0.0, -9.81, 0.0);
    rapier.integration_parameters.num_solver_iterations = 1;
    let mut world = ClearanceWorld::new(rapier, control);
    let base = world.rapier.bodies.insert(RigidBodyBuilder::fixed());
    let arm = world.rapier.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.3, 0.0, offset))
            .additional_mass_properties(MassProperties::new(Vector::ZERO, 2.0, Vector::splat(0.02)))
            .can_sleep(false),
    );
    let joint = clearance
        .joint(
            Vector::ZERO,
            Vector::new(-0.3, 0.0, -offset),
            Vector::Z,
            Vector::Z,
        )
        .expect("the arm's pin is a valid joint");
    let pin = world.insert_clearance(base, arm, joint).unwrap();
    (world, arm, pin)
}
