//! Stability at the extremes (issue 4): every run either completes with finite output, conserved
//! momentum and energy that never grows beyond a stated tolerance, or is refused with a clear
//! error naming the field, never a silent blow-up. Rapier clamps speeds instead of producing NaN,
//! so energy and momentum are what is checked.

use clearance_joint::Error;
use clearance_joint::scene::Scene;
use clearance_joint::scene::report::TwinSummary;
use clearance_joint::scene::runner::{RunOptions, Simulation, Twins};

/// The energy balance may not grow by more than this fraction of the energy scale (the
/// integrator's own error, first order in the contact step).
const ENERGY_GROWTH_TOLERANCE: f64 = 5e-3;
/// Relative drift of total linear and angular momentum of the free-floating system.
const MOMENTUM_TOLERANCE: f64 = 1e-9;

fn run(overrides: &[&str]) -> Result<TwinSummary, Error> {
    let mut set = vec!["run.end_s=2", "run.output_interval_s=1e-2"];
    set.extend_from_slice(overrides);
    let scene = Scene::solar_panel().with_overrides(&set)?;
    let r = Simulation::new(
        &scene,
        RunOptions {
            twins: Twins::ClearanceOnly,
            skip_rows: false,
        },
    )?
    .run()?;
    // Rendering checks every output value is finite.
    r.twins[0].table.to_csv()?;
    Ok(r.summary().twins["clearance"].clone())
}

fn assert_healthy(case: &str, s: &TwinSummary) {
    assert!(s.onsets > 0, "{case}: no contact, nothing tested");
    assert!(
        s.peak_joint_force_n.is_finite() && s.final_angles_deg.values().all(|a| a.is_finite()),
        "{case}: non-finite"
    );
    assert!(
        s.linear_momentum_drift.expect("free-floating") < MOMENTUM_TOLERANCE,
        "{case}: linear momentum drift {:?}",
        s.linear_momentum_drift
    );
    assert!(
        s.angular_momentum_drift.expect("free-floating") < MOMENTUM_TOLERANCE,
        "{case}: angular momentum drift {:?}",
        s.angular_momentum_drift
    );
    assert!(
        s.invariants.energy_growth.unwrap() < ENERGY_GROWTH_TOLERANCE,
        "{case}: energy grew by {:?} of the energy scale",
        s.invariants.energy_growth
    );
}

#[test]
fn extreme_parameters_complete_healthy() {
    let cases: &[(&str, &[&str])] = &[
        ("clearance 1 um", &["hinge.clearance_mm=0.001"]),
        ("clearance 5 mm", &["hinge.clearance_mm=5"]),
        ("torque x50", &["drive.torque_scale=50"]),
        (
            "E = 1e12 Pa",
            &[
                "hinge.bearing_material.youngs_modulus_pa=1e12",
                "hinge.journal_material.youngs_modulus_pa=1e12",
            ],
        ),
        (
            "E = 1e7 Pa",
            &[
                "hinge.bearing_material.youngs_modulus_pa=1e7",
                "hinge.journal_material.youngs_modulus_pa=1e7",
            ],
        ),
        (
            "restitution 0.1",
            &[r#"hinge.contact={"LankaraniNikravesh":{"restitution":0.1}}"#],
        ),
        (
            "restitution 1.0, frictionless",
            &[
                r#"hinge.contact={"LankaraniNikravesh":{"restitution":1.0}}"#,
                "hinge.friction=None",
            ],
        ),
        ("friction 0", &["hinge.friction=None"]),
        (
            "friction 1",
            &[r#"hinge.friction={"Coulomb":{"mu_d":1.0,"v_eps_mm_s":0.1}}"#],
        ),
    ];
    for (case, set) in cases {
        let s = run(set).unwrap_or_else(|e| panic!("{case}: {e}"));
        assert_healthy(case, &s);
    }
}

#[test]
fn one_hundred_seconds() {
    let scene = Scene::solar_panel()
        .with_overrides(&["run.end_s=100", "run.output_interval_s=0.1"])
        .unwrap();
    let r = Simulation::new(
        &scene,
        RunOptions {
            twins: Twins::ClearanceOnly,
            skip_rows: false,
        },
    )
    .unwrap()
    .run()
    .unwrap();
    r.twins[0].table.to_csv().unwrap();
    let s = &r.summary().twins["clearance"];
    assert_healthy("100 s", s);
    // The spring's equilibrium is T0/k = 90 deg: by 100 s the panel oscillates about it.
    assert!(
        (s.final_angles_deg["hinge"] - 90.0).abs() < 20.0,
        "{}",
        s.final_angles_deg["hinge"]
    );
}

#[test]
fn fixed_steps_across_the_stability_limit() {
    // The guard checks every step against the linearised limit of the contact as it is then
    // (stiffness, damping and effective mass): across the limit each run either completes healthy
    // or is refused naming `run.dt_s`, and both happen.
    let (mut passed, mut refused) = (Vec::new(), Vec::new());
    for dt in [1e-4, 1.25e-4, 2e-4, 2.5e-4, 5e-4, 1e-3] {
        let set = format!("run.dt_s={dt:e}");
        // The explicit joint's guard (a sub-cycled contact has no step limit).
        match run(&["run.contact_integration=Explicit", "run.step=Fixed", &set]) {
            Ok(s) => {
                assert_healthy(&set, &s);
                passed.push(dt);
            }
            Err(Error::StepTooLarge(l)) => {
                assert_eq!(l.field(), "run.dt_s");
                assert!(l.dt_max() < dt, "{} vs {dt}", l.dt_max());
                refused.push(dt);
            }
            Err(other) => panic!("{set}: unexpected error {other}"),
        }
    }
    assert!(
        !passed.is_empty() && !refused.is_empty(),
        "passed {passed:?}, refused {refused:?}"
    );
    // Monotone: no step passes above a refused one.
    assert!(
        passed.iter().all(|p| refused.iter().all(|r| p < r)),
        "passed {passed:?}, refused {refused:?}"
    );
}

#[test]
fn a_stability_limit_below_the_smallest_step_is_out_of_reach() {
    // Issue 17: a contact damped at 1e12 N s/m (the documented maximum) is stable only below
    // a step far under the smallest any run takes (1e-10 s); the advice used to be "use
    // `run.dt_s` below 6.633e-19 s". It says no step resolves it and names the parameter.
    let contact = r#"hinge.contact={"KelvinVoigt":{"stiffness":1e8,"damping":1e12}}"#;
    // The explicit joint's limit (a sub-cycled contact has none).
    let explicit = "run.contact_integration=Explicit";
    match run(&[explicit, "run.step=Fixed", "run.dt_s=1e-5", contact]) {
        Err(e @ Error::StepTooLarge(_)) => {
            let Error::StepTooLarge(l) = &e else {
                unreachable!()
            };
            let dt_max = l.dt_max();
            let msg = e.to_string();
            println!("{msg}");
            assert!(0.8 * dt_max < 1e-10, "{msg}");
            assert!(
                msg.contains("No step resolves this contact")
                    && msg.contains("out of reach")
                    && msg.contains("hinges[hinge].clearance.contact.damping")
                    && !msg.contains("Use `run.dt_s` below"),
                "{msg}"
            );
        }
        other => panic!("expected StepTooLarge, got {:?}", other.map(|s| s.onsets)),
    }
}

/// The same contact sub-cycled at a fixed step: no sub-step the cap allows resolves it, and
/// every world step ends at the sub-cycle's cap. Ten such steps in a row stop the run with the
/// contact's diagnosis (its damped stability limit, the parameter to change) instead of
/// crawling on at the cap's cost a step.
#[test]
fn a_sub_cycle_at_its_cap_step_after_step_stalls_with_the_contacts_cause() {
    let contact = r#"hinge.contact={"KelvinVoigt":{"stiffness":1e8,"damping":1e12}}"#;
    match run(&["run.step=Fixed", "run.dt_s=1e-5", contact]) {
        Err(e @ Error::Stalled { .. }) => {
            let msg = e.to_string();
            println!("{msg}");
            for words in [
                "10 world steps in a row at the sub-cycle's cap of 100000 sub-steps",
                "over-damped",
                "stable only below 4.1",
                "`damping`",
            ] {
                assert!(msg.contains(words), "{words}: {msg}");
            }
        }
        other => panic!("expected Stalled, got {:?}", other.map(|s| s.onsets)),
    }
}

/// The same contact sub-cycled at the default adaptive steps: the sub-steps resolve it but
/// follow its damped limit (4.1e-12 s), so it asks for world steps (ten sub-steps) below the
/// floor (1e-10 s), the world's step sits there and the run would crawl. Ten world steps ending
/// in it stop the run at its first contact, as the explicit joint stops at it, with the same
/// diagnosis.
#[test]
fn a_sub_cycled_contact_stable_only_below_the_floor_stalls_at_its_first_contact() {
    // The first contact of the default law: the free flight before it is the same.
    let first = run(&["run.end_s=0.1"])
        .unwrap()
        .first_impact_t_s
        .expect("a contact before 0.1 s");
    let contact = r#"hinge.contact={"KelvinVoigt":{"stiffness":1e8,"damping":1e12}}"#;
    // An end 20 us after the contact: a run that crawled would reach it (in tens of seconds).
    let end = format!("run.end_s={}", first + 2e-5);
    match run(&[contact, &end]) {
        Err(e @ Error::Stalled { .. }) => {
            let Error::Stalled { t, .. } = &e else {
                unreachable!()
            };
            let msg = e.to_string();
            println!("first contact at {first} s, stalled at {t} s: {msg}");
            for words in [
                "10 world steps ended in a sub-cycled contact that asks for world steps of 3.1",
                "under the floor",
                "stable only below 4.1",
                "joint `hinge`",
                "over-damped",
                "`damping`",
            ] {
                assert!(msg.contains(words), "{words}: {msg}");
            }
            // Ten world steps at the floor after the first contact, not a crawl through it.
            assert!(
                *t >= first - 1e-9 && *t - first < 1e-8,
                "stalled at {t} s, first contact at {first} s"
            );
        }
        other => panic!("expected Stalled, got {:?}", other.map(|s| s.onsets)),
    }
}

/// A 2 kg arm on a clearance joint (steel, 0.2 mm play) under a fixed pivot, in a plain Rapier
/// world: the world, the joints, the arm.
fn api_pendulum() -> (
    rapier3d_f64::prelude::PhysicsWorld,
    clearance_joint::rapier::joint::ClearanceJointSet,
    rapier3d_f64::prelude::RigidBodyHandle,
) {
    use rapier3d_f64::math::Vector;
    use rapier3d_f64::prelude::*;
    let mut world = PhysicsWorld::new();
    world.integration_parameters.num_solver_iterations = 1;
    let ground = world.bodies.insert(RigidBodyBuilder::fixed());
    let arm = world.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.0, -0.3, 0.0))
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                2.0,
                Vector::splat(0.02),
            )),
    );
    let joint =
        clearance_joint::rapier::hinge::design::HingeDesign::steel_improved_liu(0.01, 2e-4, 0.016)
            .unwrap()
            .joint(
                Vector::ZERO,
                Vector::new(0.0, 0.3, 0.0),
                Vector::Z,
                Vector::Z,
            )
            .unwrap();
    let mut joints = clearance_joint::rapier::joint::ClearanceJointSet::new();
    joints
        .insert(ground, arm, joint, &world.bodies, &mut world.impulse_joints)
        .unwrap();
    (world, joints, arm)
}

#[test]
fn api_refuses_a_gravity_that_is_not_finite() {
    use clearance_joint::rapier::pipeline::{stepper::StepControl, world::ClearanceWorld};
    let (world, joints, _) = api_pendulum();
    let mut world = ClearanceWorld::new(world, StepControl::fixed(1e-5));
    world.clearance = joints;
    world.rapier.gravity = rapier3d_f64::math::Vector::new(0.0, f64::NAN, 0.0);
    let e = world.step(0.01).unwrap_err();
    assert!(
        matches!(&e, Error::Invalid { field, .. } if field == "gravity"),
        "{e}"
    );
}

#[test]
fn api_names_a_journal_body_removed_after_the_joint() {
    // The step check used to read "stable only below 0 s ... use `dt` below 0 s".
    use clearance_joint::rapier::pipeline::{stepper::StepControl, world::ClearanceWorld};
    let (world, joints, arm) = api_pendulum();
    let mut world = ClearanceWorld::new(world, StepControl::fixed(1e-5));
    world.clearance = joints;
    world.step(1e-3).unwrap();
    let rapier = &mut world.rapier;
    rapier.bodies.remove(
        arm,
        &mut rapier.islands,
        &mut rapier.colliders,
        &mut rapier.impulse_joints,
        &mut rapier.multibody_joints,
        &mut rapier.soft_bodies,
        true,
    );
    let e = loop {
        match world.step(1e-2) {
            Ok(_) => assert!(world.time() < 1e-2, "the missing body went unnoticed"),
            Err(e) => break e.to_string(),
        }
    };
    assert!(
        e.contains("`body2`") && e.contains("not in the world's bodies") && !e.contains(" 0 s"),
        "{e}"
    );
}

#[test]
fn api_divergence_names_the_handle_and_the_likely_cause() {
    // A stone flung at 300 m/s beside the pendulum leaves the physical range at once.
    use clearance_joint::rapier::pipeline::{stepper::StepControl, world::ClearanceWorld};
    use rapier3d_f64::prelude::{MassProperties, RigidBodyBuilder};
    let (mut world, joints, _) = api_pendulum();
    let stone = world.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(rapier3d_f64::math::Vector::new(1.0, 0.0, 0.0))
            .linvel(rapier3d_f64::math::Vector::new(300.0, 0.0, 0.0))
            .additional_mass_properties(MassProperties::new(
                rapier3d_f64::math::Vector::ZERO,
                1.0,
                rapier3d_f64::math::Vector::splat(0.01),
            )),
    );
    let mut world = ClearanceWorld::new(world, StepControl::fixed(1e-6));
    world.clearance = joints;
    let e = loop {
        match world.step(1e-2) {
            Ok(_) => assert!(world.time() < 1e-2, "never diverged"),
            Err(e) => break e,
        }
    };
    let s = e.to_string();
    assert!(matches!(e, Error::Diverged { .. }), "{s}");
    let handle = format!("{:?}", stone.into_raw_parts());
    assert!(
        s.contains(&handle) && s.contains("likely cause") && s.contains("speed 300"),
        "{s}"
    );
}
