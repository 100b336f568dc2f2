//! Issue 18, item 5: the library's errors speak to the library's caller. A plain-API caller (its
//! own Rapier world, loop and `Stepper`) reads the API's names, never an option of the app
//! (`--dt`) nor a path of the scene format (`run.dt_s`, `hinges[NAME]...`); the same errors
//! through the scene runner name the scene's fields (the app's options are added by the app:
//! `app/tests/reliability.rs`).

use clearance_joint::error::Error;
use clearance_joint::model::laws::{BearingGeometry, Hertz, KelvinVoigt, NormalModel};
use clearance_joint::prelude::*;
use clearance_joint::rapier::stepper::{StepControl, Stepper};
use clearance_joint::scene::Scene;
use clearance_joint::scene::runner::{RunOptions, Simulation};
use rapier3d_f64::prelude::*;

/// Words of the app and of the scene format that no plain-API message may hold.
fn assert_plain(message: &str) {
    for word in ["--", "run.", "hinges[", "`run", "scene"] {
        assert!(
            !message.contains(word),
            "{word:?} in a plain-API message: {message}"
        );
    }
}

/// A 2 kg arm on a steel pin with radial play, released with the journal centred (it falls
/// across the gap and hits the bearing after about 6 ms), in a world with `iterations` solver
/// iterations.
fn pendulum(clearance: Clearance, iterations: usize) -> (PhysicsWorld, ClearanceJointSet) {
    let mut world = PhysicsWorld::new();
    world.integration_parameters.num_solver_iterations = iterations;
    let base = world.bodies.insert(RigidBodyBuilder::fixed());
    let arm = world.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.3, 0.0, 0.0))
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                2.0,
                Vector::splat(0.02),
            )),
    );
    let revolute = RevoluteJointBuilder::new(Vector::Z).local_anchor2(Vector::new(-0.3, 0.0, 0.0));
    let hinge = world.impulse_joints.insert(base, arm, revolute, true);
    let mut set = ClearanceJointSet::new();
    set.convert_revolute(
        hinge,
        BearingSide::Body1,
        clearance.name("pin"),
        &mut world.impulse_joints,
    )
    .unwrap();
    (world, set)
}

fn steel() -> Clearance {
    Clearance::steel_improved_liu(0.010, 0.2e-3, 0.016).unwrap()
}

/// Steps `set`'s world with `control` until an error (or `end` s, then panics).
fn run_until_error(
    world: &mut PhysicsWorld,
    set: &mut ClearanceJointSet,
    control: StepControl,
    end: f64,
) -> Error {
    let mut stepper = Stepper::new(control);
    loop {
        match stepper.step(world, &mut [set], end) {
            Ok(_) => assert!(stepper.time() < end, "no error by t = {end} s"),
            Err(e) => return e,
        }
    }
}

#[test]
fn a_fixed_step_too_large_names_the_api() {
    let (mut world, mut set) = pendulum(steel(), 1);
    let e = run_until_error(&mut world, &mut set, StepControl::fixed(1e-3), 1.0);
    let m = e.to_string();
    assert!(
        matches!(&e, Error::StepTooLarge { field, joint, adaptive: Some(false), t: Some(_), .. }
            if field == "StepControl::max_dt" && joint == "pin"),
        "{m}"
    );
    for part in [
        "`StepControl::max_dt` = 0.001 s",
        "joint `pin`",
        "adaptive stepping (`StepControl::adaptive`)",
        // Over-damped at that penetration: the improved law's damping.
        "soften the contact: `MaxDamping::Eta` (or `MaxDamping::Explicit`)",
    ] {
        assert!(m.contains(part), "{part:?} not in {m}");
    }
    assert!(e.suggested_step().is_some_and(|dt| dt < 1e-3), "{m}");
    assert_plain(&m);

    // The same through a `ClearanceWorld`, the plain API's world.
    let mut rapier = PhysicsWorld::new();
    rapier.integration_parameters.num_solver_iterations = 1;
    let mut world = ClearanceWorld::new(rapier, StepControl::fixed(1e-3));
    let base = world.rapier.bodies.insert(RigidBodyBuilder::fixed());
    let arm = world.rapier.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.3, 0.0, 0.0))
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                2.0,
                Vector::splat(0.02),
            )),
    );
    let pin = steel()
        .name("pin")
        .joint(
            Vector::ZERO,
            Vector::new(-0.3, 0.0, 0.0),
            Vector::Z,
            Vector::Z,
        )
        .unwrap();
    world.insert_clearance(base, arm, pin).unwrap();
    let e = loop {
        match world.step(1.0) {
            Ok(_) => assert!(world.time() < 1.0, "never refused"),
            Err(e) => break e,
        }
    };
    let m2 = e.to_string();
    assert!(
        matches!(&e, Error::StepTooLarge { field, .. } if field == "StepControl::max_dt"),
        "{m2}"
    );
    assert_plain(&m2);
}

#[test]
fn the_force_hook_in_a_users_own_loop_names_rapiers_dt() {
    // No stepper: the user's loop calls the hook before `PhysicsPipeline::step`.
    let (mut world, mut set) = pendulum(steel(), 1);
    world.integration_parameters.dt = 1e-3;
    let e = (0..1000)
        .find_map(|_| {
            let r = set.apply(
                &mut world.bodies,
                &world.impulse_joints,
                &world.integration_parameters,
            );
            world.step();
            r.err()
        })
        .expect("the contact refuses a 1 ms step");
    let m = e.to_string();
    assert!(
        matches!(&e, Error::StepTooLarge { field, adaptive: None, .. } if field == "dt"),
        "{m}"
    );
    assert!(m.contains("smaller `dt`"), "{m}");
    assert_plain(&m);
}

#[test]
fn invalid_clearance_parameters_name_the_api_parameter() {
    let bad = [
        Clearance::steel_improved_liu(0.010, -0.2e-3, 0.016).unwrap_err(),
        Clearance::steel_improved_liu(0.010, 0.2e-3, f64::NAN).unwrap_err(),
        KelvinVoigt::new(-1.0, 10.0).unwrap_err(),
        Hertz::new(1e10, 0.5).unwrap_err(),
        BearingGeometry::from_clearance(0.010, 0.020, 0.016).unwrap_err(),
        steel()
            .max_valid_penetration(-1.0)
            .joint(Vector::ZERO, Vector::ZERO, Vector::Z, Vector::Z)
            .unwrap_err(),
        steel()
            .model(ClearanceModel::LargeStep)
            .joint(Vector::ZERO, Vector::ZERO, Vector::Z, Vector::Z)
            .unwrap_err(),
    ];
    for e in bad {
        let m = e.to_string();
        assert!(
            matches!(e, Error::Invalid { .. }) && m.starts_with("invalid `"),
            "{m}"
        );
        assert_plain(&m);
    }
}

/// The spatial model's own values, and a spatial joint asked of the large-step model, are refused
/// naming the API's field.
#[test]
fn invalid_spatial_values_name_the_spatial_field() {
    use clearance_joint::model::spatial::{FaceLaw, SpatialModel};
    let joint = |model: SpatialModel| {
        steel()
            .model(ClearanceModel::Spatial(model))
            .joint(Vector::ZERO, Vector::ZERO, Vector::Z, Vector::Z)
            .unwrap_err()
    };
    let good = SpatialModel::steel(0.3e-3, 0.015);
    let cases = [
        (
            joint(SpatialModel::steel(0.3e-3, 0.009)),
            "spatial.collar_radius",
        ),
        (
            joint(SpatialModel::steel(-0.3e-3, 0.015)),
            "spatial.axial_play",
        ),
        (
            joint(good.face(FaceLaw {
                stiffness: 1e9,
                restitution: 1.5,
            })),
            "spatial.face.restitution",
        ),
        // The journal radius is 10 mm - 0.2 mm: a collar of that radius is no ring.
        (
            joint(SpatialModel::steel(0.3e-3, 0.0098)),
            "spatial.collar_radius",
        ),
        (
            joint(SpatialModel::steel(0.3e-3, f64::NAN)),
            "spatial.collar_radius",
        ),
        (joint(SpatialModel::steel(0.0, 0.015)), "spatial.axial_play"),
        (
            joint(SpatialModel::steel(f64::NAN, 0.015)),
            "spatial.axial_play",
        ),
        (
            joint(good.face(FaceLaw {
                stiffness: -1e9,
                restitution: 0.9,
            })),
            "spatial.face.stiffness",
        ),
        (
            joint(good.face(FaceLaw {
                stiffness: f64::INFINITY,
                restitution: 0.9,
            })),
            "spatial.face.stiffness",
        ),
        (
            joint(good.face(FaceLaw {
                stiffness: 1e9,
                restitution: 0.0,
            })),
            "spatial.face.restitution",
        ),
        (
            joint(good.face(FaceLaw {
                stiffness: 1e9,
                restitution: f64::NAN,
            })),
            "spatial.face.restitution",
        ),
        (
            steel()
                .model(ClearanceModel::Spatial(good))
                .large_step_joint(Vector::ZERO, Vector::ZERO, Vector::Z, Vector::Z)
                .unwrap_err(),
            "model",
        ),
    ];
    for (e, field) in cases {
        let m = e.to_string();
        assert!(
            matches!(&e, Error::Invalid { field: f, .. } if f == field),
            "expected `{field}`: {m}"
        );
        assert_plain(&m);
    }
}

#[test]
fn rapiers_default_iterations_suggest_the_large_step_model() {
    let (mut world, mut set) = pendulum(steel(), 4);
    let e = run_until_error(&mut world, &mut set, StepControl::fixed(1e-5), 0.01);
    let m = e.to_string();
    assert!(
        matches!(&e, Error::Invalid { field, .. } if field == "num_solver_iterations"),
        "{m}"
    );
    assert!(
        m.contains("is 4")
            && m.contains("num_solver_iterations = 1")
            && m.contains("Clearance::model(ClearanceModel::LargeStep)")
            && m.contains("any number of iterations"),
        "{m}"
    );
    assert!(!m.contains("must be 1"), "{m}");
    assert_plain(&m);
    // The same hinge with the large-step model runs in that world.
    let mut world = PhysicsWorld::new();
    let base = world.bodies.insert(RigidBodyBuilder::fixed());
    let arm = world.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.3, 0.0, 0.0))
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                2.0,
                Vector::splat(0.02),
            )),
    );
    let revolute = RevoluteJointBuilder::new(Vector::Z).local_anchor2(Vector::new(-0.3, 0.0, 0.0));
    let hinge = world.impulse_joints.insert(base, arm, revolute, true);
    let mut play = LargeStepJointSet::new();
    play.convert_revolute(
        hinge,
        BearingSide::Body1,
        steel().model(ClearanceModel::LargeStep),
        &mut world.impulse_joints,
    )
    .unwrap();
    for _ in 0..60 {
        play.before_step(
            &mut world.bodies,
            &mut world.impulse_joints,
            &world.integration_parameters,
        );
        world.step();
        play.after_step(&mut world.bodies, &world.impulse_joints);
    }
    assert!(world.bodies.get(arm).unwrap().translation().is_finite());
}

#[test]
fn a_stall_names_the_api() {
    // The stiffest Hertz contact the ranges accept, with a step floor of 1 us: no step
    // resolves it.
    let geometry = BearingGeometry::from_clearance(0.010, 0.2e-3, 0.016).unwrap();
    let law = NormalModel::Hertz(Hertz::new(1e16, 1.5).unwrap());
    let (mut world, mut set) = pendulum(Clearance::new(geometry, law), 1);
    let control = StepControl::adaptive(1e-3, 0.0075).min_dt(1e-6);
    let e = run_until_error(&mut world, &mut set, control, 0.1);
    let m = e.to_string();
    assert!(matches!(e, Error::Stalled { .. }), "{m}");
    assert!(m.contains("joint `pin`") && m.contains("`min_dt`"), "{m}");
    assert_plain(&m);
}

#[test]
fn a_strict_guard_names_the_joint() {
    // A validity limit of 1 nm: the first contact passes it.
    let clearance = steel().max_valid_penetration(1e-9);
    let (mut world, mut set) = pendulum(clearance, 1);
    let control = StepControl::adaptive(1e-3, 0.0075).strict(true);
    let e = run_until_error(&mut world, &mut set, control, 0.1);
    let m = e.to_string();
    assert!(matches!(e, Error::Guard { .. }), "{m}");
    assert!(
        m.contains("joint `pin` penetrated beyond its law's validity"),
        "{m}"
    );
    assert_plain(&m);
}

#[test]
fn the_scene_layer_names_the_scene_fields() {
    // The same kind of error through the scene runner: the scene's step field and the hinge's
    // clearance fields, but no option of the app.
    let scene = Scene::solar_panel()
        .with_overrides(&["run.step=Fixed", "run.dt_s=1e-3", "run.end_s=0.2"])
        .unwrap();
    let e = Simulation::new(&scene, RunOptions::default())
        .unwrap()
        .run()
        .unwrap_err();
    let m = e.to_string();
    assert!(
        matches!(&e, Error::StepTooLarge { field, .. } if field == "run.dt_s"),
        "{m}"
    );
    for part in [
        "`run.dt_s` = 0.001 s",
        "`run.step = Adaptive`",
        "`hinges[hinge].clearance.contact.eta_s` (or `d_max_n_s_per_m`)",
    ] {
        assert!(m.contains(part), "{part:?} not in {m}");
    }
    assert!(!m.contains("--"), "{m}");
}
