//! The large-step clearance joint (`clearance_joint::large_step`): bounded eccentricity, no energy
//! gain, stability over clearances and masses at game rate, restitution, friction and the force
//! readout. Release profile (`cargo test --release`); every scene is a few seconds of simulated
//! time or less at 1/60 s.

use clearance_joint::large_step::{LargeStepJointBuilder, LargeStepJointHandle, LargeStepJointSet};
use clearance_joint::laws::BearingGeometry;
use rapier3d_f64::prelude::*;

/// A free body (no gravity) whose journal starts at the bearing centre and moves at `speed` along
/// +x towards the wall; the bearing is fixed.
fn shot(
    speed: f64,
    restitution: f64,
    dt: f64,
) -> (
    PhysicsWorld,
    LargeStepJointSet,
    LargeStepJointHandle,
    RigidBodyHandle,
) {
    let mut world = PhysicsWorld::new();
    world.gravity = Vector::ZERO;
    world.integration_parameters.dt = dt;
    let base = world.bodies.insert(RigidBodyBuilder::fixed());
    let body = world.bodies.insert(
        RigidBodyBuilder::dynamic()
            .linvel(Vector::new(speed, 0.0, 0.0))
            .additional_mass_properties(MassProperties::new(Vector::ZERO, 3.0, Vector::splat(0.05)))
            .can_sleep(false),
    );
    let joint = LargeStepJointBuilder::new(
        Vector::Z,
        BearingGeometry::from_clearance(0.01, 0.5e-3, 0.016).unwrap(),
    )
    .restitution(restitution)
    .build()
    .unwrap();
    let mut play = LargeStepJointSet::new();
    let h = play.insert(base, body, joint, &mut world.impulse_joints);
    (world, play, h, body)
}

fn step(world: &mut PhysicsWorld, play: &mut LargeStepJointSet) {
    play.before_step(
        &mut world.bodies,
        &mut world.impulse_joints,
        &world.integration_parameters,
    );
    world.step();
    play.after_step(&mut world.bodies, &world.impulse_joints);
}

#[test]
fn a_single_impact_rebounds_with_the_coefficient() {
    for e in [0.0, 0.3, 0.7, 1.0] {
        // 20 mm/s across 0.5 mm: the impact comes in the second step at 1/60 s.
        let (mut world, mut play, h, body) = shot(0.02, e, 1.0 / 60.0);
        let mut impact = None;
        for _ in 0..3 {
            step(&mut world, &mut play);
            let r = *play.get(h).unwrap().report();
            if r.impact {
                impact = Some(r);
            }
        }
        let r = impact.expect("one impact");
        let v = world.bodies[body].linvel().x;
        assert!(
            (r.approach_speed - 0.02).abs() < 1e-12,
            "{}",
            r.approach_speed
        );
        assert!((v + e * 0.02).abs() < 1e-9, "e {e}: rebound {v}");
        assert!((r.rebound_speed - e * 0.02).abs() < 1e-12);
        assert!((r.impact_impulse - 3.0 * (1.0 + e) * 0.02).abs() < 1e-9);
    }
}
