//! A chain of slender bodies under adaptive steps (issue 16): the benchmark set's double
//! pendulum, two 0.5 m steel bars of 16 mm square section (out-of-plane moment of inertia 490
//! times below the in-plane one) with a clearance elbow, released from horizontal. Rapier
//! corrects its joints' drift within each step; when the step drops near a contact that
//! multiplies the correcting velocity and the locked tilt of the bars grows at each change of
//! the step until the run diverges. The stepper's joint correction spreads the correction over
//! the longest recent step (`rapier::pipeline::joint_correction`): the same run then ends clean.

use clearance_joint::model::laws::{
    Ambrosio, BearingGeometry, FrictionModel, LankaraniNikravesh, Material, NormalModel,
};
use clearance_joint::rapier::hinge::design::HingeDesign;
use clearance_joint::rapier::joint::{ClearanceJointSet, ContactIntegration};
use clearance_joint::rapier::pipeline::stepper::StepControl;
use clearance_joint::rapier::pipeline::world::ClearanceWorld;
use clearance_joint::{Error, Result};
use rapier3d_f64::prelude::*;

/// The double pendulum of `assets/double_pendulum.ron` (plain API), its elbow's contact
/// integrated as `integration` says: the world, the elbow's clearance set, and the lower bar.
fn double_pendulum(
    integration: ContactIntegration,
) -> (PhysicsWorld, ClearanceJointSet, RigidBodyHandle) {
    let mut world = PhysicsWorld::new();
    world.gravity = Vector::new(0.0, -9.81, 0.0);
    world.integration_parameters.num_solver_iterations = 1;
    let bar = |x: f64| {
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(x, 0.0, 0.0))
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                1.0,
                Vector::new(4.267e-5, 0.020854, 0.020854),
            ))
            .can_sleep(false)
    };
    let ground = world.bodies.insert(RigidBodyBuilder::fixed());
    let link1 = world.bodies.insert(bar(0.25));
    let link2 = world.bodies.insert(bar(0.75));
    let shoulder = RevoluteJointBuilder::new(Vector::Z).local_anchor2(Vector::new(-0.25, 0.0, 0.0));
    world.impulse_joints.insert(ground, link1, shoulder, true);
    let geometry = BearingGeometry::from_clearance(0.010, 0.5e-3, 0.020).unwrap();
    let k =
        LankaraniNikravesh::stiffness_from_geometry(&geometry, &Material::STEEL, &Material::STEEL);
    let law = LankaraniNikravesh::new(k, LankaraniNikravesh::EXPONENT, 0.9).unwrap();
    let elbow = HingeDesign::new(geometry, NormalModel::LankaraniNikravesh(law))
        .integration(integration)
        .friction(FrictionModel::Ambrosio(
            Ambrosio::new(0.01, 1e-4, 1e-2).unwrap(),
        ))
        .joint(
            Vector::new(0.25, 0.0, 0.0),
            Vector::new(-0.25, 0.0, 0.0),
            Vector::Z,
            Vector::Z,
        )
        .unwrap();
    let mut joints = ClearanceJointSet::new();
    joints
        .insert(
            link1,
            link2,
            elbow,
            &world.bodies,
            &mut world.impulse_joints,
        )
        .unwrap();
    (world, joints, link2)
}

/// Runs the pendulum to `end` s at the library's defaults (adaptive, tolerance 0.0075, largest
/// step 1e-3 s) with the joint correction on or off: the largest out-of-plane angular velocity
/// of the lower bar, or the error that stopped the run.
fn run(correction: bool, end: f64) -> Result<f64> {
    run_at(0.0075, correction, end, ContactIntegration::default())
}

/// [`run`] at adaptive tolerance `tol`, the contact integrated as `integration` says.
fn run_at(tol: f64, correction: bool, end: f64, integration: ContactIntegration) -> Result<f64> {
    let (rapier, joints, link2) = double_pendulum(integration);
    let control = StepControl {
        joint_correction: correction,
        ..StepControl::adaptive(1e-3, tol)
    };
    let mut world = ClearanceWorld::new(rapier, control);
    world.clearance = joints;
    let mut tilt_rate: f64 = 0.0;
    while world.time() < end {
        world.step(end)?;
        let w = world.rapier.bodies[link2].angvel();
        tilt_rate = tilt_rate.max(w.x.hypot(w.y));
    }
    assert!(world.guards().is_clean(), "{:?}", world.guards());
    Ok(tilt_rate)
}

#[test]
fn a_slender_double_pendulum_stays_planar_at_the_defaults() {
    let end = 0.3;
    let tilt_rate = run(true, end).expect("the run ends");
    assert!(tilt_rate < 1e-6, "out-of-plane rate {tilt_rate} rad/s");
}

/// The failure the correction removes, shown on purpose with Rapier's own correction and the
/// explicit joint, whose steps drop near each contact: the locked tilt grows at each change of
/// the step (sub-cycled, the default, the world step does not drop). Measured over 0.3 s: the lower bar's out-of-plane rate
/// reaches 0.055 rad/s at the defaults and 0.73 rad/s at twice the default tolerance while the
/// contact laws read the bodies' stored rate, and 0.009 and 0.0055 rad/s since they read
/// the rate the positions moved at (below 1e-6 with the correction at both; the growth is
/// chaotic, so the figures move with any change of the step sequence). Before the contact step was doubled (issue 16) the run at the
/// defaults diverged (200 m/s at t = 0.15 s); a run that diverges must name the switch.
#[test]
fn without_the_joint_correction_the_same_run_leaves_its_plane() {
    for (tol, at_least) in [(0.0075, 1e-4), (0.015, 1e-3)] {
        let result = run_at(tol, false, 0.3, ContactIntegration::Explicit);
        match result {
            Ok(rate) => assert!(
                rate > at_least,
                "tolerance {tol}: out-of-plane rate {rate} rad/s"
            ),
            Err(e @ Error::Diverged { .. }) => {
                assert!(e.to_string().contains("joint_correction"), "{e}");
            }
            Err(e) => panic!("tolerance {tol}: {e}"),
        }
        let with = run_at(tol, true, 0.3, ContactIntegration::Explicit).expect("the run ends");
        assert!(
            with < 1e-6,
            "tolerance {tol}: out-of-plane rate {with} rad/s with the correction"
        );
    }
}
