//! The ECS layer's own behaviour: conversions in place, removals, errors, the large-step model.
//! The comparison with the scene runner (a sibling layer) is the integration test `tests/ecs.rs`.

use super::*;
use crate::error::{Error, Result};
use crate::model::kinematics::ContactMode;
use crate::model::laws::{Bai, FrictionModel};
use crate::rapier::hinge::design::{ClearanceModel, HingeDesign};
use crate::rapier::observers::metrics::{ContactObservation, ImpactRecorder};
use crate::rapier::pipeline::stepper::StepControl;
use bevy_ecs::prelude::*;
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::{MassProperties, PhysicsWorld, RigidBodyBuilder};

/// The compliant hinge with explicit contact: the tests below read its per-step forces, limits
/// and refusals (the sub-cycled default's are `sub_cycled_compliant_hinge_at_game_rate`'s).
fn clearance() -> HingeDesign {
    default_clearance().integration(crate::rapier::joint::ContactIntegration::Explicit)
}

/// The same hinge at the library's defaults (sub-cycled contact).
fn default_clearance() -> HingeDesign {
    HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016)
        .unwrap()
        .friction(FrictionModel::Bai(Bai::DRY))
}

/// A 2 kg arm whose centre of mass hangs 0.3 m below `(x, 0, 0)`.
fn arm_at(x: f64) -> Body {
    arm_with_centre(Vector::new(x, -0.3, 0.0))
}

/// A 2 kg arm with its centre of mass at `centre`.
fn arm_with_centre(centre: Vector) -> Body {
    Body::new(
        RigidBodyBuilder::dynamic()
            .translation(centre)
            .additional_mass_properties(MassProperties::new(Vector::ZERO, 2.0, Vector::splat(0.02)))
            .can_sleep(false),
    )
}

/// A world with gravity along -y, one solver iteration (ready for the compliant model) and
/// steps of `dt`, with a fixed base: `(world, base)`.
fn compliant_world(dt: f64) -> (World, Entity) {
    let mut world = World::new();
    let mut physics = Physics::new(dt, Vector::new(0.0, -9.81, 0.0));
    physics
        .world
        .rapier
        .integration_parameters
        .num_solver_iterations = 1;
    world.insert_resource(physics);
    let base = world.spawn(Body::new(RigidBodyBuilder::fixed())).id();
    (world, base)
}

/// A 2 kg arm hanging 0.3 m below a fixed base on an ideal hinge about z, in a world with one
/// solver iteration (ready for the compliant model).
fn pendulum(dt: f64) -> (World, Schedule, Entity, Entity) {
    let (mut world, base) = compliant_world(dt);
    let arm = world.spawn(arm_at(0.0)).id();
    let hinge = world
        .spawn((
            Hinge::new(base, arm, Vector::Z).local_anchor2(Vector::new(0.0, 0.3, 0.0)),
            IdealHinge,
        ))
        .id();
    (world, physics_schedule(), arm, hinge)
}

fn steps(world: &mut World, schedule: &mut Schedule, n: usize) -> Result<()> {
    for _ in 0..n {
        run_step(world, schedule)?;
    }
    Ok(())
}

#[test]
fn swapping_the_mode_converts_the_rapier_joint_both_ways() {
    let (mut world, mut schedule, arm, hinge) = pendulum(1e-5);
    steps(&mut world, &mut schedule, 10).unwrap();
    let p = world.resource::<Physics>();
    assert!(matches!(p.joint(hinge), Some(HingeJoint::Ideal(_))));
    assert_eq!(p.world.rapier.impulse_joints.len(), 1);
    assert_eq!(
        world.get::<HingeState>(hinge).unwrap().mode,
        HingeMode::Ideal
    );

    // Swap in place: the revolute becomes a clearance joint (plus its out-of-plane lock).
    world
        .entity_mut(hinge)
        .remove::<IdealHinge>()
        .insert(ClearanceHinge(clearance()));
    steps(&mut world, &mut schedule, 20_000).unwrap();
    let p = world.resource::<Physics>();
    let j = p.clearance_joint(hinge).expect("converted");
    assert_eq!(j.local_anchor2(), Vector::new(0.0, 0.3, 0.0));
    assert_eq!(p.clearance().len(), 1);
    assert_eq!(p.world.rapier.impulse_joints.len(), 1, "only the lock");
    let s = world.get::<HingeState>(hinge).unwrap();
    assert_eq!(s.mode, HingeMode::Clearance);
    assert!(s.onsets > 0);
    assert!((s.force - 19.62).abs() < 0.02, "{}", s.force);
    assert!(s.penetration > 0.0);

    // And back: ideal again, and the contact force taken off the arm.
    world
        .entity_mut(hinge)
        .remove::<ClearanceHinge>()
        .insert(IdealHinge);
    steps(&mut world, &mut schedule, 1).unwrap();
    let p = world.resource::<Physics>();
    assert!(p.clearance().is_empty());
    assert!(matches!(p.joint(hinge), Some(HingeJoint::Ideal(_))));
    let rb = &p.world.rapier.bodies[p.body(arm).unwrap()];
    assert_eq!(rb.user_force(), Vector::ZERO);
    assert_eq!(rb.user_torque(), Vector::ZERO);

    // Neither mode: no joint at all; the arm falls.
    world.entity_mut(hinge).remove::<IdealHinge>();
    steps(&mut world, &mut schedule, 100).unwrap();
    let p = world.resource::<Physics>();
    assert_eq!(p.joint(hinge), None);
    assert_eq!(p.world.rapier.impulse_joints.len(), 0);
    assert_eq!(
        world.get::<HingeState>(hinge).unwrap().mode,
        HingeMode::None
    );
    assert!(world.get::<BodyState>(arm).unwrap().linvel.y < -0.005);
}

#[test]
fn clearance_takes_precedence_and_handles_follow_removals() {
    // Two pendulums; removing the first clearance joint leaves the second's handle as it was.
    let (mut world, mut schedule, _, first) = pendulum(1e-5);
    let base = world.spawn(Body::new(RigidBodyBuilder::fixed())).id();
    let arm = world.spawn(arm_at(1.0)).id();
    let second = world
        .spawn((
            Hinge::new(base, arm, Vector::Z)
                .local_anchor1(Vector::new(1.0, 0.0, 0.0))
                .local_anchor2(Vector::new(0.0, 0.3, 0.0)),
            ClearanceHinge(clearance().name("second")),
        ))
        .id();
    // Both components: the clearance wins.
    world
        .entity_mut(first)
        .insert(ClearanceHinge(clearance().name("first")));
    steps(&mut world, &mut schedule, 2).unwrap();
    let p = world.resource::<Physics>();
    assert_eq!(p.clearance().len(), 2);
    let Some(HingeJoint::Clearance(was_first)) = p.joint(first) else {
        panic!("first is a clearance joint")
    };
    let second_handle = p.joint(second);
    world.entity_mut(first).remove::<ClearanceHinge>();
    steps(&mut world, &mut schedule, 2).unwrap();
    let p = world.resource::<Physics>();
    assert_eq!(p.clearance().len(), 1);
    assert!(matches!(p.joint(first), Some(HingeJoint::Ideal(_))));
    assert_eq!(p.joint(second), second_handle);
    assert_eq!(p.clearance_joint(second).unwrap().name(), "second");
    assert!(
        p.clearance().get(was_first).is_none(),
        "a stale handle finds nothing"
    );
}

#[test]
fn bodies_of_an_existing_rapier_world_by_handle() {
    let mut rapier = PhysicsWorld::new();
    rapier.integration_parameters.num_solver_iterations = 1;
    rapier.integration_parameters.dt = 1e-5;
    let base = rapier.bodies.insert(RigidBodyBuilder::fixed());
    let arm = rapier.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.0, -0.3, 0.0))
            .additional_mass_properties(MassProperties::new(Vector::ZERO, 2.0, Vector::splat(0.02)))
            .can_sleep(false),
    );
    let mut world = World::new();
    world.insert_resource(Physics::from_world(rapier));
    let (b, a) = (
        world.spawn(Body::from_handle(base)).id(),
        world.spawn(Body::from_handle(arm)).id(),
    );
    let hinge = world
        .spawn((
            Hinge::new(b, a, Vector::Z).local_anchor2(Vector::new(0.0, 0.3, 0.0)),
            ClearanceHinge(clearance()),
        ))
        .id();
    let mut schedule = physics_schedule();
    steps(&mut world, &mut schedule, 20_000).unwrap();
    let p = world.resource::<Physics>();
    assert_eq!(p.body(a), Some(arm));
    assert_eq!(p.world.rapier.bodies.len(), 2);
    // PhysicsWorld::new() has Rapier's default gravity, -9.81 along y.
    let s = world.get::<HingeState>(hinge).unwrap();
    assert!((s.force - 19.62).abs() < 0.02, "{}", s.force);

    // A handle that is not in the world is refused.
    let mut other = PhysicsWorld::new();
    for _ in 0..5 {
        other.bodies.insert(RigidBodyBuilder::fixed());
    }
    let stale = other.bodies.insert(RigidBodyBuilder::fixed());
    world.spawn(Body::from_handle(stale));
    let msg = run_step(&mut world, &mut schedule).unwrap_err().to_string();
    assert!(msg.contains("no rigid body with handle"), "{msg}");
}

#[test]
fn despawning_a_hinge_with_its_body_removes_them_from_rapier() {
    let (mut world, mut schedule, arm, hinge) = pendulum(1e-5);
    world
        .entity_mut(hinge)
        .insert((ClearanceHinge(clearance()), Drive::torsion_spring(0.1, 0.0)));
    steps(&mut world, &mut schedule, 10).unwrap();
    world.despawn(hinge);
    world.despawn(arm);
    steps(&mut world, &mut schedule, 10).unwrap();
    let p = world.resource::<Physics>();
    assert_eq!(p.world.rapier.bodies.len(), 1, "the base is left");
    assert_eq!(p.world.rapier.impulse_joints.len(), 0);
    assert!(p.clearance().is_empty());
    assert!(p.drive(hinge).is_none());
}

#[test]
fn removing_a_drive_takes_back_its_torque_exactly() {
    let mut world = World::new();
    world.insert_resource(Physics::new(1e-3, Vector::ZERO));
    let body = |x: f64| {
        Body::new(
            RigidBodyBuilder::dynamic()
                .translation(Vector::new(x, 0.0, 0.0))
                .additional_mass_properties(MassProperties::new(
                    Vector::ZERO,
                    1.0,
                    Vector::new(0.1, 0.2, 0.3),
                ))
                .can_sleep(false),
        )
    };
    let (a, b) = (world.spawn(body(0.0)).id(), world.spawn(body(1.0)).id());
    let axis = Vector::new(0.3, -1.0, 0.2);
    let hinge = world
        .spawn((
            Hinge::new(a, b, axis).local_anchor1(Vector::new(0.5, 0.0, 0.0)),
            Drive::per_degree(0.5, 0.01),
        ))
        .id();
    let mut schedule = physics_schedule();
    steps(&mut world, &mut schedule, 50).unwrap();
    let p = world.resource::<Physics>();
    assert!(
        p.drive(hinge).unwrap().angle() > 0.0,
        "the spring turned body b"
    );
    assert!(p.joint(hinge).is_none(), "no mode component: no joint");
    world.entity_mut(hinge).remove::<Drive>();
    steps(&mut world, &mut schedule, 1).unwrap();
    let p = world.resource::<Physics>();
    for e in [a, b] {
        let rb = &p.world.rapier.bodies[p.body(e).unwrap()];
        assert_eq!(rb.user_torque(), Vector::ZERO, "torque left on {e}");
    }
}

#[test]
fn errors_are_values_and_stop_the_systems() {
    // No resource.
    let mut empty = World::new();
    let e = run_step(&mut empty, &mut physics_schedule()).unwrap_err();
    assert!(e.to_string().contains("Physics"), "{e}");

    // A hinge to an entity without a body.
    let (mut world, mut schedule, _, _) = pendulum(1e-5);
    let ghost = world.spawn_empty().id();
    let base = world.spawn(Body::new(RigidBodyBuilder::fixed())).id();
    let bad = world
        .spawn((Hinge::new(base, ghost, Vector::Z), IdealHinge))
        .id();
    let e = run_step(&mut world, &mut schedule).unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.contains(&format!("hinge {bad}.body2")) && msg.contains("has no Body"),
        "{msg}"
    );
    world.despawn(bad);
    run_step(&mut world, &mut schedule).unwrap();

    // A step too large for the contact: refused when the journal hits the bearing, and the
    // world does not move on until the error is taken.
    let (mut world, mut schedule, _, hinge) = pendulum(1e-4);
    world.entity_mut(hinge).insert(ClearanceHinge(clearance()));
    let e = steps(&mut world, &mut schedule, 2_000).unwrap_err();
    match &e {
        Error::StepTooLarge(l) => {
            assert_eq!(l.field(), "Physics::world.rapier.integration_parameters.dt");
            assert!(l.t().is_some_and(|t| t.is_finite() && t > 0.0));
            // The ECS's names, never the app's options or the scene's paths.
            let msg = e.to_string();
            assert!(
                msg.contains("`Physics::world.rapier.integration_parameters.dt` =")
                    && msg.contains("Physics::set_step_control(StepControl::adaptive(..))"),
                "{msg}"
            );
            for word in ["--", "run.", "hinges["] {
                assert!(!msg.contains(word), "{word:?} in {msg}");
            }
        }
        other => panic!("expected StepTooLarge, got {other}"),
    }
    let t = world.resource::<Physics>().time();
    world
        .resource_mut::<Physics>()
        .fail(Error::invalid("x", "y"));
    schedule.run(&mut world);
    assert_eq!(
        world.resource::<Physics>().time(),
        t,
        "halted while an error is set"
    );

    // An invalid frame is named, for ideal hinges too.
    let (mut world, mut schedule, _, hinge) = pendulum(1e-5);
    world.get_mut::<Hinge>(hinge).unwrap().local_axis2 = Vector::ZERO;
    let msg = run_step(&mut world, &mut schedule).unwrap_err().to_string();
    assert!(msg.contains(&format!("hinge {hinge}.local_axis2")), "{msg}");
    world.get_mut::<Hinge>(hinge).unwrap().local_anchor1 = Vector::new(f64::NAN, 0.0, 0.0);
    world.get_mut::<Hinge>(hinge).unwrap().local_axis2 = Vector::Z;
    let msg = run_step(&mut world, &mut schedule).unwrap_err().to_string();
    assert!(
        msg.contains(&format!("hinge {hinge}.local_anchor1")),
        "{msg}"
    );

    // An invalid clearance is named.
    let (mut world, mut schedule, _, hinge) = pendulum(1e-5);
    let mut c = clearance();
    c.min_impact_speed = -1.0;
    world.entity_mut(hinge).insert(ClearanceHinge(c));
    let msg = run_step(&mut world, &mut schedule).unwrap_err().to_string();
    assert!(
        msg.contains(&format!("hinge {hinge}.min_impact_speed")),
        "{msg}"
    );
}

#[test]
fn an_unnamed_clearance_hinge_is_realised_once() {
    // The joint is named after its entity; the component is not. Comparing the two rebuilt
    // the joint (and reset its contact history) at every step: 17,659 onsets in 20,000
    // steps instead of the pendulum's 18.
    let (mut world, mut schedule, _, hinge) = pendulum(1e-5);
    world.entity_mut(hinge).insert(ClearanceHinge(clearance()));
    steps(&mut world, &mut schedule, 20_000).unwrap();
    let s = world.get::<HingeState>(hinge).unwrap();
    assert!(s.onsets > 0 && s.onsets < 100, "{} onsets", s.onsets);
    let p = world.resource::<Physics>();
    assert_eq!(
        p.clearance_joint(hinge).unwrap().name(),
        format!("hinge {hinge}")
    );
}

/// [`pendulum`] at 1/60 s with Rapier's four solver iterations (a game world's).
fn game_rate_pendulum() -> (World, Schedule, Entity, Entity) {
    let (mut world, schedule, arm, hinge) = pendulum(1.0 / 60.0);
    world
        .resource_mut::<Physics>()
        .world
        .rapier
        .integration_parameters
        .num_solver_iterations = 4;
    (world, schedule, arm, hinge)
}

#[test]
fn large_step_hinge_at_game_rate_with_rapiers_defaults() {
    // 1/60 s and Rapier's four solver iterations: the explicit compliant model refuses both.
    let (mut world, mut schedule, arm, hinge) = game_rate_pendulum();
    let large = clearance()
        .model(ClearanceModel::LargeStep)
        .restitution(0.5);
    world
        .entity_mut(hinge)
        .insert(ClearanceHinge(large.clone()));
    steps(&mut world, &mut schedule, 120).unwrap();
    let p = world.resource::<Physics>();
    assert!(matches!(p.joint(hinge), Some(HingeJoint::LargeStep(_))));
    assert!(p.clearance().is_empty());
    assert_eq!(p.large_step().len(), 1);
    assert_eq!(
        p.world.rapier.impulse_joints.len(),
        1,
        "the revolute became the play joint"
    );
    let j = p.large_step_joint(hinge).unwrap();
    assert_eq!(j.friction(), 0.25, "Bai DRY's sliding coefficient");
    let s = world.get::<HingeState>(hinge).unwrap();
    assert_eq!(s.mode, HingeMode::LargeStep);
    // Hanging at rest on the wall: the journal at the clearance, the force the weight.
    assert!((s.force - 19.62).abs() < 1e-6, "{}", s.force);
    assert!(s.penetration.abs() < 0.05 * 0.2e-3, "{}", s.penetration);
    assert_eq!(s.contact, ContactMode::Continuous);

    // Back to ideal and to large-step again, in place.
    world
        .entity_mut(hinge)
        .remove::<ClearanceHinge>()
        .insert(IdealHinge);
    steps(&mut world, &mut schedule, 2).unwrap();
    let p = world.resource::<Physics>();
    assert!(p.large_step().is_empty());
    assert!(matches!(p.joint(hinge), Some(HingeJoint::Ideal(_))));
    let rb = &p.world.rapier.bodies[p.body(arm).unwrap()];
    assert_eq!(rb.additional_solver_iterations(), 0, "substeps handed back");
    world.entity_mut(hinge).insert(ClearanceHinge(large));
    steps(&mut world, &mut schedule, 2).unwrap();
    assert_eq!(
        world.get::<HingeState>(hinge).unwrap().mode,
        HingeMode::LargeStep
    );
    // Compliant <-> large step: the model change rebuilds the joint.
    world.entity_mut(hinge).insert(ClearanceHinge(clearance()));
    world
        .resource_mut::<Physics>()
        .world
        .rapier
        .integration_parameters = {
        let mut p = world
            .resource::<Physics>()
            .world
            .rapier
            .integration_parameters;
        p.num_solver_iterations = 1;
        p.dt = 1e-5;
        p
    };
    steps(&mut world, &mut schedule, 2).unwrap();
    let p = world.resource::<Physics>();
    assert!(p.large_step().is_empty());
    assert_eq!(p.clearance().len(), 1);
    assert_eq!(
        world.get::<HingeState>(hinge).unwrap().mode,
        HingeMode::Clearance
    );
}

/// A compliant hinge at the defaults (sub-cycled) at 1/60 s with Rapier's four iterations (the
/// explicit one refuses both): its first impact, inside one frame, is in the hinge state (onset,
/// a peak over the static load), and the arm comes to hang on the wall with the weight as its
/// force.
#[test]
fn sub_cycled_compliant_hinge_at_game_rate() {
    let (mut world, mut schedule, _, hinge) = game_rate_pendulum();
    world
        .entity_mut(hinge)
        .insert(ClearanceHinge(default_clearance()));
    steps(&mut world, &mut schedule, 3).unwrap();
    let s = *world.get::<HingeState>(hinge).unwrap();
    assert_eq!(s.mode, HingeMode::Clearance);
    assert!(s.onsets >= 1 && s.impacts >= 1, "{s:?}");
    assert!(s.peak_force > 100.0, "the drop's impact: {}", s.peak_force);
    steps(&mut world, &mut schedule, 300).unwrap();
    let s = world.get::<HingeState>(hinge).unwrap();
    assert!((s.force - 19.62).abs() < 0.02, "{}", s.force);
    assert_eq!(s.contact, ContactMode::Continuous);
    assert!(world.resource::<Physics>().guards().is_clean());
}

#[test]
fn the_worlds_settings_stay_the_users() {
    // `new` keeps Rapier's defaults but dt and gravity.
    let p = Physics::new(1e-3, Vector::new(0.0, -1.0, 0.0));
    let defaults = PhysicsWorld::new().integration_parameters;
    let mut expected = defaults;
    expected.dt = 1e-3;
    assert_eq!(p.world.rapier.integration_parameters, expected);
    assert_eq!(
        p.world.rapier.integration_parameters.num_solver_iterations,
        4
    );

    // A compliant hinge in a world with 4 iterations is refused, naming the setting, why and
    // the way out; the world and the hinge stay as they were.
    let (mut world, mut schedule, _, hinge) = pendulum(1e-5);
    steps(&mut world, &mut schedule, 2).unwrap();
    world
        .resource_mut::<Physics>()
        .world
        .rapier
        .integration_parameters
        .num_solver_iterations = 4;
    world.entity_mut(hinge).insert(ClearanceHinge(clearance()));
    let msg = run_step(&mut world, &mut schedule).unwrap_err().to_string();
    for needle in [
        "Physics::world.rapier.integration_parameters.num_solver_iterations",
        &format!("hinge {hinge} needs 1 (the world has 4)"),
        "gain energy",
        "ClearanceModel::LargeStep",
    ] {
        assert!(msg.contains(needle), "{needle:?} not in: {msg}");
    }
    let p = world.resource::<Physics>();
    assert_eq!(
        p.world.rapier.integration_parameters.num_solver_iterations,
        4
    );
    assert!(matches!(p.joint(hinge), Some(HingeJoint::Ideal(_))));
    assert!(p.clearance().is_empty());
    // Set up by the user, the same hinge is realised.
    world
        .resource_mut::<Physics>()
        .world
        .rapier
        .integration_parameters
        .num_solver_iterations = 1;
    steps(&mut world, &mut schedule, 2).unwrap();
    let p = world.resource::<Physics>();
    assert!(matches!(p.joint(hinge), Some(HingeJoint::Clearance(_))));

    // A spatial hinge is refused the same way, naming its model, and is told that the way out
    // is planar.
    let (mut world, mut schedule, _, hinge) = pendulum(1e-5);
    world
        .resource_mut::<Physics>()
        .world
        .rapier
        .integration_parameters
        .num_solver_iterations = 4;
    let spatial = clearance().model(ClearanceModel::Spatial(
        crate::model::spatial::SpatialModel::steel(0.2e-3, 0.015),
    ));
    world.entity_mut(hinge).insert(ClearanceHinge(spatial));
    let msg = run_step(&mut world, &mut schedule).unwrap_err().to_string();
    for needle in [
        "num_solver_iterations",
        "the spatial clearance model",
        "planar: it cannot tilt",
    ] {
        assert!(msg.contains(needle), "{needle:?} not in: {msg}");
    }
    assert!(world.resource::<Physics>().clearance().is_empty());
}

#[test]
fn hinge_state_carries_the_readouts() {
    // Compliant: |e|/c above 1 when resting on the wall, no impulse, no substeps.
    let (mut world, mut schedule, _, hinge) = pendulum(1e-5);
    world.entity_mut(hinge).insert(ClearanceHinge(clearance()));
    steps(&mut world, &mut schedule, 20_000).unwrap();
    let s = *world.get::<HingeState>(hinge).unwrap();
    let p = world.resource::<Physics>();
    let j = p.clearance_joint(hinge).unwrap();
    let e = j.report().state.eccentricity.length();
    assert_eq!(s.eccentricity_ratio, e / j.geometry().clearance());
    assert!(s.eccentricity_ratio > 1.0 && s.eccentricity_ratio < 1.01);
    assert_eq!((s.impulse, s.substeps, s.under_resolved), (0.0, 0, false));

    // Large step at 1/60 s, without gravity: the journal crosses the play at 2 mm/s and hits
    // the wall after a few steps, an impact with its impulse.
    let mut world = World::new();
    world.insert_resource(Physics::new(1.0 / 60.0, Vector::ZERO));
    let base = world.spawn(Body::new(RigidBodyBuilder::fixed())).id();
    let arm = world
        .spawn(Body::new(
            RigidBodyBuilder::dynamic()
                .translation(Vector::new(0.0, -0.3, 0.0))
                .linvel(Vector::new(2e-3, 0.0, 0.0))
                .additional_mass_properties(MassProperties::new(
                    Vector::ZERO,
                    2.0,
                    Vector::splat(0.02),
                ))
                .can_sleep(false),
        ))
        .id();
    let hinge = world
        .spawn((
            Hinge::new(base, arm, Vector::Z).local_anchor2(Vector::new(0.0, 0.3, 0.0)),
            ClearanceHinge(clearance().model(ClearanceModel::LargeStep)),
        ))
        .id();
    let mut schedule = physics_schedule();
    let mut impulses = Vec::new();
    for _ in 0..120 {
        run_step(&mut world, &mut schedule).unwrap();
        let s = *world.get::<HingeState>(hinge).unwrap();
        let r = *world
            .resource::<Physics>()
            .large_step_joint(hinge)
            .unwrap()
            .report();
        assert_eq!(s.eccentricity_ratio, r.eccentricity_ratio);
        assert_eq!(s.impulse, r.impact_impulse);
        assert_eq!(
            (s.substeps, s.under_resolved),
            (r.substeps, r.under_resolved)
        );
        assert!(s.substeps >= 4, "{} substeps", s.substeps);
        if s.impulse > 0.0 {
            impulses.push(s.impulse);
        }
        // A one-step frame: the step's normal force plus its bounce's impulse over the step.
        let mean = r.normal_force + r.impact_impulse * 60.0;
        assert!((s.frame_mean_force - mean).abs() <= 1e-12 * mean.max(1.0));
        let j = world.resource::<Physics>().large_step_joint(hinge).unwrap();
        assert_eq!((s.onsets, s.impacts), (j.onsets(), j.bounces()));
    }
    assert!(!impulses.is_empty(), "the journal hit the wall");
}

/// A 2 kg arm hanging 0.3 m below a fixed base, its centre of mass 30 mm along the hinge's axis
/// (z) from the pin's mid-plane (its weight makes a moment across the axis), in a compliant-ready
/// world at 1e-5 s steps: `(world, base, arm)`.
fn offset_arm() -> (World, Entity, Entity) {
    let (mut world, base) = compliant_world(1e-5);
    let arm = world
        .spawn(arm_with_centre(Vector::new(0.0, -0.3, 0.03)))
        .id();
    (world, base, arm)
}

/// The spatial model through the ECS: the same `ClearanceHinge` with `ClearanceModel::Spatial`
/// converts the revolute without any lock, and an arm whose centre of mass sits 30 mm along the
/// axis from the pin's mid-plane tilts the journal until the bore's edges carry its moment.
#[test]
fn a_spatial_hinge_tilts_under_a_moment_across_its_axis() {
    use crate::model::spatial::SpatialModel;
    let (mut world, base, arm) = offset_arm();
    let spatial = clearance().model(ClearanceModel::Spatial(SpatialModel::steel(0.2e-3, 0.015)));
    let hinge = world
        .spawn((
            Hinge::new(base, arm, Vector::Z).local_anchor2(Vector::new(0.0, 0.3, -0.03)),
            ClearanceHinge(spatial),
        ))
        .id();
    let mut schedule = physics_schedule();
    steps(&mut world, &mut schedule, 20_000).unwrap();
    let p = world.resource::<Physics>();
    assert_eq!(p.world.rapier.impulse_joints.len(), 0, "nothing locked");
    let j = p.clearance_joint(hinge).expect("converted");
    assert!(j.spatial_model().is_some());
    let r = j.report().spatial.expect("a spatial report");
    // The weight's moment across the axis, 2 kg x 9.81 x 0.03 m = 0.59 N m, tilts the journal
    // about x (the arm hangs along -y, its weight offset along z).
    let tilt = r.tilt[0].hypot(r.tilt[1]);
    assert!(tilt > 1e-3, "{r:?}");
    assert!(r.edge_force[0] + r.edge_force[1] > 19.0, "{r:?}");
    let s = *world.get::<HingeState>(hinge).unwrap();
    assert_eq!(s.mode, HingeMode::Clearance);
    assert_eq!(s.penetration, j.report().state.penetration);
    assert_eq!(s.spatial, Some(r), "HingeState carries the spatial report");
}

/// A hinge swapped in place between the planar model, the spatial one and an ideal revolute: the
/// lock comes and goes with the planar model, the spatial report with the spatial one, and the
/// arm's off-plane weight tilts the journal only while it is spatial.
#[test]
fn a_hinge_swaps_between_planar_spatial_and_ideal() {
    use crate::model::spatial::SpatialModel;
    let (mut world, base, arm) = offset_arm();
    let hinge = world
        .spawn((
            Hinge::new(base, arm, Vector::Z).local_anchor2(Vector::new(0.0, 0.3, -0.03)),
            IdealHinge,
        ))
        .id();
    let mut schedule = physics_schedule();
    let planar = clearance();
    let spatial = planar
        .clone()
        .model(ClearanceModel::Spatial(SpatialModel::steel(0.2e-3, 0.015)));
    let tilt = |world: &World| {
        world
            .get::<HingeState>(hinge)
            .unwrap()
            .spatial
            .map(|r| r.tilt[0].hypot(r.tilt[1]))
    };
    world
        .entity_mut(hinge)
        .remove::<IdealHinge>()
        .insert(ClearanceHinge(planar));
    steps(&mut world, &mut schedule, 5_000).unwrap();
    assert_eq!(
        world
            .resource::<Physics>()
            .world
            .rapier
            .impulse_joints
            .len(),
        1,
        "the lock"
    );
    assert_eq!(tilt(&world), None);

    world.entity_mut(hinge).insert(ClearanceHinge(spatial));
    steps(&mut world, &mut schedule, 20_000).unwrap();
    let p = world.resource::<Physics>();
    assert_eq!(p.world.rapier.impulse_joints.len(), 0, "no lock");
    assert_eq!(p.clearance().len(), 1);
    let t = tilt(&world).expect("a spatial report");
    assert!(t > 1e-3, "{t}");
    assert_eq!(
        world.get::<HingeState>(hinge).unwrap().mode,
        HingeMode::Clearance
    );

    world
        .entity_mut(hinge)
        .remove::<ClearanceHinge>()
        .insert(IdealHinge);
    steps(&mut world, &mut schedule, 10).unwrap();
    let p = world.resource::<Physics>();
    assert!(p.clearance().is_empty());
    assert!(matches!(p.joint(hinge), Some(HingeJoint::Ideal(_))));
    assert_eq!(p.world.rapier.impulse_joints.len(), 1, "the revolute alone");
    assert_eq!(tilt(&world), None);
}

#[test]
fn unchanged_hinges_are_not_reconciled_again_but_changes_are_seen() {
    let (mut world, mut schedule, arm, hinge) = pendulum(1e-5);
    steps(&mut world, &mut schedule, 3).unwrap();
    let passes = |w: &World| w.resource::<Physics>().hinge_passes;
    assert_eq!(
        passes(&world),
        1,
        "the first step realises the hinge, the others skip"
    );

    // A changed frame is seen and rebuilds the joint where it now is.
    let before = world.resource::<Physics>().joint(hinge);
    world.get_mut::<Hinge>(hinge).unwrap().local_anchor2 = Vector::new(0.0, 0.31, 0.0);
    steps(&mut world, &mut schedule, 2).unwrap();
    assert_eq!(passes(&world), 2);
    assert_ne!(world.resource::<Physics>().joint(hinge), before);

    // An added drive, and its removal.
    world
        .entity_mut(hinge)
        .insert(Drive::torsion_spring(0.1, 0.0));
    steps(&mut world, &mut schedule, 2).unwrap();
    assert!(world.resource::<Physics>().drive(hinge).is_some());
    world.entity_mut(hinge).remove::<Drive>();
    steps(&mut world, &mut schedule, 2).unwrap();
    assert!(world.resource::<Physics>().drive(hinge).is_none());
    assert_eq!(passes(&world), 4);

    // A removed mode component.
    world.entity_mut(hinge).remove::<IdealHinge>();
    steps(&mut world, &mut schedule, 2).unwrap();
    assert_eq!(world.resource::<Physics>().joint(hinge), None);
    world.entity_mut(hinge).insert(IdealHinge);
    steps(&mut world, &mut schedule, 1).unwrap();
    assert!(matches!(
        world.resource::<Physics>().joint(hinge),
        Some(HingeJoint::Ideal(_))
    ));

    // A body removed without touching the hinge: the hinge is checked again and refused.
    world.entity_mut(arm).remove::<Body>();
    let msg = run_step(&mut world, &mut schedule).unwrap_err().to_string();
    assert!(msg.contains("has no Body"), "{msg}");
    // The error was taken: the next step checks again (and refuses again).
    let msg = run_step(&mut world, &mut schedule).unwrap_err().to_string();
    assert!(msg.contains("has no Body"), "{msg}");
}

/// The top box of an 8-box stack (0.5 m boxes on the ground) after 10 s at 60 Hz beside a sign on
/// a large-step hinge, in a world of `iterations` solver iterations wrapped as it is.
fn stack_beside_a_sign(iterations: usize) -> Vector {
    use rapier3d_f64::prelude::ColliderBuilder;
    let mut rapier = PhysicsWorld::new();
    rapier.integration_parameters.num_solver_iterations = iterations;
    let ground = rapier.bodies.insert(RigidBodyBuilder::fixed());
    let ground_shape =
        ColliderBuilder::cuboid(10.0, 0.1, 10.0).translation(Vector::new(0.0, -0.1, 0.0));
    rapier
        .colliders
        .insert_with_parent(ground_shape, ground, &mut rapier.bodies);
    let mut top = ground;
    for i in 0..8 {
        let y = 0.25 + 0.5 * i as f64;
        top = rapier
            .bodies
            .insert(RigidBodyBuilder::dynamic().translation(Vector::new(0.0, y, 0.0)));
        let shape = ColliderBuilder::cuboid(0.25, 0.25, 0.25);
        rapier
            .colliders
            .insert_with_parent(shape, top, &mut rapier.bodies);
    }
    let mut world = World::new();
    world.insert_resource(Physics::from_world(rapier));
    let post = world
        .spawn(Body::new(
            RigidBodyBuilder::fixed().translation(Vector::new(3.0, 2.0, 0.0)),
        ))
        .id();
    let sign = world
        .spawn(Body::new(
            RigidBodyBuilder::dynamic()
                .translation(Vector::new(3.0, 1.7, 0.0))
                .additional_mass_properties(MassProperties::new(
                    Vector::ZERO,
                    2.0,
                    Vector::splat(0.02),
                ))
                .can_sleep(false),
        ))
        .id();
    let hinge = world
        .spawn((
            Hinge::new(post, sign, Vector::Z).local_anchor2(Vector::new(0.0, 0.3, 0.0)),
            ClearanceHinge(clearance().model(ClearanceModel::LargeStep)),
        ))
        .id();
    let mut schedule = physics_schedule();
    steps(&mut world, &mut schedule, 600).unwrap();
    assert_eq!(
        world.get::<HingeState>(hinge).unwrap().mode,
        HingeMode::LargeStep
    );
    let s = world.get::<HingeState>(hinge).unwrap();
    assert!(
        (s.force - 19.62).abs() < 0.01,
        "the sign hangs: {} N",
        s.force
    );
    let p = world.resource::<Physics>();
    assert_eq!(
        p.world.rapier.integration_parameters.num_solver_iterations, iterations,
        "the layer left the setting as it was"
    );
    p.world.rapier.bodies[top].translation()
}

#[test]
fn a_game_worlds_stack_stands_because_its_iterations_are_left_alone() {
    // Rapier's 4 iterations: the stack stands (its top box started at 3.75 m).
    let top = stack_beside_a_sign(4);
    assert!(top.y > 3.7 && top.x.abs() < 0.05, "{top:?}");
    // One iteration, as the compliant model needs, for the whole world: the stack falls.
    let top = stack_beside_a_sign(1);
    assert!(top.y < 1.0, "{top:?}");
}

/// A 2 kg arm released horizontal on a clearance hinge (0.2 mm of play, dry friction), stepped
/// adaptively (at most 1 ms a run): its journal rattles in the bearing as it swings.
fn rattling_pendulum() -> (World, Schedule, Entity) {
    let (mut world, base) = compliant_world(1e-3);
    world
        .resource_mut::<Physics>()
        .set_step_control(StepControl::adaptive(1e-3, 0.02));
    let arm = world
        .spawn(arm_with_centre(Vector::new(0.3, 0.0, 0.0)))
        .id();
    let hinge = world
        .spawn((
            Hinge::new(base, arm, Vector::Z).local_anchor2(Vector::new(-0.3, 0.0, 0.0)),
            ClearanceHinge(clearance()),
        ))
        .id();
    (world, physics_schedule(), hinge)
}

/// One run of `schedule` inside the current frame (`run_step` would begin a new one).
fn step_in_frame(world: &mut World, schedule: &mut Schedule) {
    schedule.run(world);
    world.clear_trackers();
    assert!(world.resource::<Physics>().error().is_none());
}

#[test]
fn the_frame_mean_is_the_step_weighted_force_and_the_peak_bounds_every_sample() {
    let (mut world, mut schedule, hinge) = rattling_pendulum();
    run_frame(&mut world, &mut schedule, 0.1).unwrap();
    let time = |w: &World| w.resource::<Physics>().time();
    // One 1/60 s frame by hand: each state's force held over the step that followed it.
    let mut samples = vec![world.get::<HingeState>(hinge).unwrap().force];
    let (mut impulse, t0) = (0.0, time(&world));
    world.resource_mut::<Physics>().begin_frame();
    while time(&world) < t0 + 1.0 / 60.0 {
        let t = time(&world);
        step_in_frame(&mut world, &mut schedule);
        impulse += samples.last().unwrap() * (time(&world) - t);
        samples.push(world.get::<HingeState>(hinge).unwrap().force);
    }
    let s = *world.get::<HingeState>(hinge).unwrap();
    let mean = impulse / (time(&world) - t0);
    let (min, max) = samples
        .iter()
        .fold((f64::INFINITY, 0.0_f64), |(a, b), f| (a.min(*f), b.max(*f)));
    eprintln!(
        "frame of {} steps: samples {min:.3}..{max:.3} N, last {:.3} N, mean {:.3} N, peak {:.3} N",
        samples.len() - 1,
        s.force,
        s.frame_mean_force,
        s.frame_peak_force
    );
    // A rattle: the samples jump between free flight and contact.
    assert!(min < 0.5 * mean && max > 2.0 * mean, "{samples:?}");
    assert!((s.frame_mean_force - mean).abs() <= 1e-12 * mean);
    assert!(min <= s.frame_mean_force && s.frame_mean_force <= max);
    assert_eq!(s.frame_peak_force, max);
}

#[test]
fn run_frame_lands_on_the_frames_end_and_covers_its_steps() {
    let (mut world, mut schedule, hinge) = rattling_pendulum();
    run_frame(&mut world, &mut schedule, 0.1).unwrap();
    let t0 = world.resource::<Physics>().time();
    let steps = run_frame(&mut world, &mut schedule, 1.0 / 60.0).unwrap();
    let t1 = world.resource::<Physics>().time();
    assert!((t1 - t0 - 1.0 / 60.0).abs() < 1e-12, "{t0} -> {t1}");
    assert!(steps > 1, "{steps} steps");
    let s = *world.get::<HingeState>(hinge).unwrap();
    assert!(s.frame_mean_force > 0.0 && s.frame_mean_force <= s.frame_peak_force);
    assert!(s.frame_peak_force <= s.peak_force && s.force <= s.frame_peak_force);
    // A step is a frame of its own: its mean is the force its start state held.
    let start = s.force;
    run_step(&mut world, &mut schedule).unwrap();
    let s = *world.get::<HingeState>(hinge).unwrap();
    assert_eq!(s.frame_mean_force, start);
    assert_eq!(s.frame_peak_force, start.max(s.force));
    let e = run_frame(&mut world, &mut schedule, 0.0).unwrap_err();
    assert!(e.to_string().contains("duration"), "{e}");
}

#[test]
fn onsets_and_impacts_are_the_metrics_of_the_same_states() {
    // 2 s of the rattling pendulum, every state also recorded by the library's recorder.
    let (mut world, mut schedule, hinge) = rattling_pendulum();
    let mut recorder = ImpactRecorder::new();
    let observe =
        |w: &World| ContactObservation::of(w.resource::<Physics>().clearance_joint(hinge).unwrap());
    while world.resource::<Physics>().time() < 2.0 {
        let t = world.resource::<Physics>().time();
        let before = if t > 0.0 {
            observe(&world)
        } else {
            ContactObservation::default()
        };
        run_step(&mut world, &mut schedule).unwrap();
        recorder.record(t, world.resource::<Physics>().time() - t, &before);
    }
    recorder.finish(world.resource::<Physics>().time(), &observe(&world));
    let s = world.get::<HingeState>(hinge).unwrap();
    let m = recorder.metrics();
    eprintln!(
        "2 s: {} onsets, {} impacts, {} chatter",
        s.onsets,
        s.impacts,
        s.onsets - s.impacts
    );
    assert_eq!((s.onsets, s.impacts), (m.onsets, m.impacts));
    // Chatter: one counter could not be both.
    assert!(s.impacts > 0 && s.onsets > s.impacts);
}
