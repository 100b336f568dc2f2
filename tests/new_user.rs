//! A new user's sub-cycled pin at game rate (1/60 s, Rapier's four solver iterations) in a loop
//! of their own: what they get wrong is refused naming what they gave, before the step.

use clearance_joint::error::Error;
use clearance_joint::prelude::*;
use rapier3d_f64::prelude::*;

/// A 2 kg arm on a sub-cycled steel pin with 0.2 mm of play, released horizontal, in a world at
/// Rapier's defaults (four solver iterations) stepped at a fixed 1/60 s.
fn game_pendulum() -> (ClearanceWorld, RigidBodyHandle) {
    let mut world = ClearanceWorld::new(PhysicsWorld::new(), StepControl::fixed(1.0 / 60.0));
    assert_eq!(world.rapier.integration_parameters.num_solver_iterations, 4);
    let base = world.rapier.bodies.insert(RigidBodyBuilder::fixed());
    let arm = world.rapier.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.3, 0.0, 0.0))
            .additional_mass_properties(MassProperties::new(Vector::ZERO, 2.0, Vector::splat(0.02)))
            .can_sleep(false),
    );
    let pin = HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016)
        .unwrap()
        .integration(ContactIntegration::SubCycled)
        .joint(
            Vector::ZERO,
            Vector::new(-0.3, 0.0, 0.0),
            Vector::Z,
            Vector::Z,
        )
        .unwrap();
    world.insert_clearance(base, arm, pin).unwrap();
    (world, arm)
}

/// A controller's NaN or infinite torque, a NaN force or a NaN mass on a body is refused before
/// the step, naming the field and the body, and the world is left where it was: not a
/// divergence a step later whose message can only list causes.
#[test]
fn a_non_finite_user_force_or_mass_is_named_before_the_step() {
    type Spoil = fn(&mut RigidBody);
    let cases: [(&str, Spoil); 4] = [
        ("user_force", |rb| {
            rb.add_force(Vector::new(f64::NAN, 0.0, 0.0), true)
        }),
        ("user_torque", |rb| {
            rb.add_torque(Vector::new(0.0, 0.0, f64::NAN), true)
        }),
        ("user_torque", |rb| {
            rb.add_torque(Vector::new(0.0, 0.0, f64::INFINITY), true)
        }),
        ("mass", |rb| {
            rb.set_additional_mass_properties(
                MassProperties::new(Vector::ZERO, f64::NAN, Vector::splat(0.02)),
                true,
            )
        }),
    ];
    for (field, spoil) in cases {
        let (mut world, arm) = game_pendulum();
        world.step_to(0.1).unwrap();
        let (t, position) = (world.time(), world.rapier.bodies[arm].translation());
        spoil(&mut world.rapier.bodies[arm]);
        let e = world.step(0.2).unwrap_err();
        let m = e.to_string();
        assert!(
            matches!(&e, Error::Invalid { field: f, .. } if f == field)
                && m.contains("non-finite")
                && m.contains(&format!("{:?}", arm.into_raw_parts())),
            "{field}: {m}"
        );
        assert_eq!(world.time(), t, "{field}");
        assert_eq!(world.rapier.bodies[arm].translation(), position, "{field}");
    }
}

/// A finite user force goes through the check: the user's own torque on the sub-cycled arm
/// still steps.
#[test]
fn a_finite_user_torque_steps() {
    let (mut world, arm) = game_pendulum();
    for frame in 1..=30 {
        let rb = &mut world.rapier.bodies[arm];
        rb.reset_torques(false);
        rb.add_torque(Vector::new(0.0, 0.0, 0.5), true);
        world.step(frame as f64 / 60.0).unwrap();
    }
    assert!(world.guards().is_clean());
}

/// The same sub-cycled pin through bevy_ecs at 1/60 s and four iterations: `HingeState` holds
/// what the plain world's sub-steps hold (onsets, impacts, the largest force inside the steps).
/// A bevy_ecs world at 1/60 s with gravity, a fixed base and a 2 kg arm 0.3 m from it (the
/// guide's), not yet hinged.
#[cfg(feature = "ecs")]
fn ecs_arm() -> (
    bevy_ecs::world::World,
    bevy_ecs::entity::Entity,
    bevy_ecs::entity::Entity,
) {
    use clearance_joint::ecs::*;
    let mut world = bevy_ecs::world::World::new();
    world.insert_resource(Physics::new(1.0 / 60.0, Vector::new(0.0, -9.81, 0.0)));
    let base = world.spawn(Body::new(RigidBodyBuilder::fixed())).id();
    let arm = world
        .spawn(Body::new(
            RigidBodyBuilder::dynamic()
                .translation(Vector::new(0.3, 0.0, 0.0))
                .additional_mass_properties(MassProperties::new(
                    Vector::ZERO,
                    2.0,
                    Vector::splat(0.02),
                ))
                .can_sleep(false),
        ))
        .id();
    (world, base, arm)
}

#[cfg(feature = "ecs")]
#[test]
fn a_sub_cycled_hinge_in_bevy_ecs_reports_its_sub_steps() {
    use clearance_joint::ecs::*;
    let (mut plain, _) = game_pendulum();
    let (mut peak, mut onsets, mut impacts, mut last) = (0.0f64, 0u64, 0u64, 0usize);
    let pin = plain.clearance.iter().next().unwrap().0;
    for frame in 1..=60 {
        plain.step(frame as f64 / 60.0).unwrap();
        let s = plain.clearance.get(pin).unwrap().substeps();
        last = s.len();
        for s in s {
            peak = peak.max(s.force.normal_force);
            onsets += s.onset as u64;
            impacts += s.impact as u64;
        }
    }
    let (mut world, base, arm) = ecs_arm();
    let design = HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016)
        .unwrap()
        .integration(ContactIntegration::SubCycled);
    let hinge = world
        .spawn((
            Hinge::new(base, arm, Vector::Z).local_anchor2(Vector::new(-0.3, 0.0, 0.0)),
            ClearanceHinge(design),
        ))
        .id();
    let mut schedule = physics_schedule();
    for _ in 0..60 {
        run_step(&mut world, &mut schedule).unwrap();
    }
    let state = world.get::<HingeState>(hinge).unwrap();
    assert_eq!(state.mode, HingeMode::Clearance);
    assert_eq!((state.onsets, state.impacts), (onsets, impacts));
    assert_eq!(state.peak_force, peak);
    // The last step's sub-steps, as the plain joint's `substeps()` (more than one: the contact
    // is resolved inside the 1/60 s step).
    assert!(last > 1, "{last}");
    assert_eq!(state.substeps, last);
}

/// Switching a live bevy_ecs hinge from sub-cycled to explicit in a world at Rapier's four
/// iterations is refused naming the setting and both ways out; switching back steps on.
#[cfg(feature = "ecs")]
#[test]
fn switching_a_live_hinge_off_sub_cycling_at_four_iterations_is_refused() {
    use clearance_joint::ecs::*;
    let (mut world, base, arm) = ecs_arm();
    let design = HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016).unwrap();
    let sub_cycled = design.clone().integration(ContactIntegration::SubCycled);
    let hinge = world
        .spawn((
            Hinge::new(base, arm, Vector::Z).local_anchor2(Vector::new(-0.3, 0.0, 0.0)),
            ClearanceHinge(sub_cycled.clone()),
        ))
        .id();
    let mut schedule = physics_schedule();
    for _ in 0..10 {
        run_step(&mut world, &mut schedule).unwrap();
    }
    world.get_mut::<ClearanceHinge>(hinge).unwrap().0 =
        design.integration(ContactIntegration::Explicit);
    let m = run_step(&mut world, &mut schedule).unwrap_err().to_string();
    assert!(
        m.contains("num_solver_iterations")
            && m.contains("ContactIntegration::SubCycled")
            && m.contains("ClearanceModel::LargeStep"),
        "{m}"
    );
    world.get_mut::<ClearanceHinge>(hinge).unwrap().0 = sub_cycled;
    for _ in 0..10 {
        run_step(&mut world, &mut schedule).unwrap();
    }
    let physics = world.resource::<Physics>();
    assert!(
        (physics.world.time() - 20.0 / 60.0).abs() < 1e-12,
        "{}",
        physics.world.time()
    );
    assert!(physics.guards().is_clean());
    let state = world.get::<HingeState>(hinge).unwrap();
    assert_eq!(state.mode, HingeMode::Clearance);
    assert!(state.substeps > 1, "{}", state.substeps);
}
