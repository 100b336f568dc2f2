//! The turning arm the sub-cycling tests share: a pin on a link that a torque turns.

use clearance_joint::model::laws::{BearingGeometry, NormalModel};
use clearance_joint::prelude::*;
use rapier3d_f64::prelude::*;

/// An upper link (2 kg x 0.4 m) turned about a fixed pivot by 2 N m without gravity, a lower
/// link (1 kg x 0.3 m) hung at its tip on a sub-cycled pin (`law`, radius 6 mm, clearance
/// 0.1 mm, 12 mm wide); the pivot a Rapier revolute, or with `both` a second sub-cycled pin.
pub fn turning_arm(
    law: NormalModel,
    dt: f64,
    iterations: usize,
    techniques: SubCycleTechniques,
    both: bool,
) -> (ClearanceWorld, [RigidBodyHandle; 2], ClearanceJointHandle) {
    let mut rapier = PhysicsWorld::new();
    rapier.gravity = Vector::ZERO;
    rapier.integration_parameters.num_solver_iterations = iterations;
    let mut world = ClearanceWorld::new(rapier, StepControl::fixed(dt));
    let base = world.rapier.bodies.insert(RigidBodyBuilder::fixed());
    let upper = link(&mut world, 2.0, 0.4, 0.0, 0.1);
    let lower = link(&mut world, 1.0, 0.3, 0.4, 0.1);
    let geometry = BearingGeometry::new(0.006, 0.006 - 0.1e-3, 0.012).unwrap();
    let design = HingeDesign::new(geometry, law)
        .integration(ContactIntegration::SubCycled)
        .sub_cycle_techniques(techniques);
    if both {
        let shoulder = design
            .clone()
            .joint(
                Vector::ZERO,
                Vector::new(-0.2, 0.0, 0.0),
                Vector::Z,
                Vector::Z,
            )
            .unwrap();
        world.insert_clearance(base, upper, shoulder).unwrap();
    } else {
        let pivot = RevoluteJointBuilder::new(Vector::Z)
            .local_anchor2(Vector::new(-0.2, 0.0, 0.0))
            .contacts_enabled(false);
        world.rapier.impulse_joints.insert(base, upper, pivot, true);
    }
    let pin = design
        .joint(
            Vector::new(0.2, 0.0, 0.0),
            Vector::new(-0.15, 0.0, 0.0),
            Vector::Z,
            Vector::Z,
        )
        .unwrap();
    let pin = world.insert_clearance(upper, lower, pin).unwrap();
    world.rapier.bodies[upper].add_torque(Vector::new(0.0, 0.0, 2.0), true);
    (world, [upper, lower], pin)
}

/// A slender link along x from `start` (m): `mass` (kg), `length` (m), the transverse inertia
/// of a rod, `axial` of it about its length.
pub fn link(
    world: &mut ClearanceWorld,
    mass: f64,
    length: f64,
    start: f64,
    axial: f64,
) -> RigidBodyHandle {
    let j = mass * length * length / 12.0;
    world.rapier.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(start + 0.5 * length, 0.0, 0.0))
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                mass,
                Vector::new(axial * j, j, j),
            ))
            .can_sleep(false),
    )
}

/// The pin's penetration as its last sub-step reported it, and at Rapier's poses of `bodies`
/// (bearing side first) at the step's end, m.
pub fn penetrations(
    world: &ClearanceWorld,
    bodies: [RigidBodyHandle; 2],
    pin: ClearanceJointHandle,
) -> (f64, f64) {
    let j = world.clearance.get(pin).unwrap();
    let reported = j.report().state.penetration;
    let (b1, b2) = (
        &world.rapier.bodies[bodies[0]],
        &world.rapier.bodies[bodies[1]],
    );
    let d = *b2.position() * j.local_anchor2() - *b1.position() * j.local_anchor1();
    let axis = *b1.rotation() * j.local_axis1();
    let posed = (d - d.dot(axis) * axis).length() - j.geometry().clearance();
    (reported, posed)
}
