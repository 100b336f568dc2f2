//! Issue 18, item 5: the library's errors speak to the library's caller. A plain-API caller (its
//! own Rapier world and loop, stepped by a `ClearanceWorld`) reads the API's names, never an option of the app
//! (`--dt`) nor a path of the scene format (`run.dt_s`, `hinges[NAME]...`); the same errors
//! through the scene runner name the scene's fields (the app's options are added by the app:
//! `app/tests/reliability.rs`).

use clearance_joint::error::Error;
use clearance_joint::model::laws::{BearingGeometry, Hertz, KelvinVoigt, NormalModel};
use clearance_joint::prelude::*;
use clearance_joint::rapier::pipeline::stepper::StepControl;
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
fn pendulum(clearance: HingeDesign, iterations: usize) -> (PhysicsWorld, ClearanceJointSet) {
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

/// Runs `scene` through the scene runner with the default options.
fn run_scene(
    scene: &Scene,
) -> clearance_joint::error::Result<clearance_joint::scene::runner::RunResult> {
    Simulation::new(scene, RunOptions::default())?.run()
}

/// The pin with explicit contact: the step refusals below are the explicit joint's (a
/// sub-cycled joint, the default, adds no stability limit in a `ClearanceWorld`).
fn steel() -> HingeDesign {
    HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016)
        .unwrap()
        .integration(ContactIntegration::Explicit)
}

/// `world` with the joints of `set`, stepped with `control`.
fn world_of(world: PhysicsWorld, set: ClearanceJointSet, control: StepControl) -> ClearanceWorld {
    let mut world = ClearanceWorld::new(world, control);
    world.clearance = set;
    world
}

/// Steps `set`'s world with `control` until an error (or `end` s, then panics).
fn run_until_error(
    world: PhysicsWorld,
    set: ClearanceJointSet,
    control: StepControl,
    end: f64,
) -> Error {
    let mut world = world_of(world, set, control);
    loop {
        match world.step(end) {
            Ok(_) => assert!(world.time() < end, "no error by t = {end} s"),
            Err(e) => return e,
        }
    }
}

#[test]
fn a_fixed_step_too_large_names_the_api() {
    let (world, set) = pendulum(steel(), 1);
    let e = run_until_error(world, set, StepControl::fixed(1e-3), 1.0);
    let m = e.to_string();
    assert!(
        matches!(&e, Error::StepTooLarge(l) if l.field() == "StepControl::max_dt"
            && l.joint() == "pin" && l.adaptive() == Some(false) && l.t().is_some()),
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
        matches!(&e, Error::StepTooLarge(l) if l.field() == "StepControl::max_dt"),
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
        matches!(&e, Error::StepTooLarge(l) if l.field() == "dt" && l.adaptive().is_none()),
        "{m}"
    );
    assert!(m.contains("smaller `dt`"), "{m}");
    assert_plain(&m);
}

#[test]
fn a_users_own_loop_steps_the_default_joint_as_the_explicit_one() {
    // The default joint is sub-cycled, which needs the ClearanceWorld's two passes a step. A loop
    // of the user's own holds `apply`'s forces over Rapier's step: the joint is the explicit one
    // there, its states and its refusals included, never a sub-cycled joint stepped blind.
    let default = || HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016).unwrap();
    let run = |design: HingeDesign, iterations: usize, dt: f64, steps: usize| {
        let (mut world, mut set) = pendulum(design, iterations);
        world.integration_parameters.dt = dt;
        let (mut states, mut deepest) = (Vec::new(), 0.0_f64);
        for _ in 0..steps {
            set.apply(
                &mut world.bodies,
                &world.impulse_joints,
                &world.integration_parameters,
            )?;
            world.step();
            let (_, joint) = set.iter().next().unwrap();
            assert_eq!(joint.integration(), ContactIntegration::Explicit);
            deepest = deepest.max(joint.report().state.penetration);
            let arm = world.bodies.iter().find(|(_, b)| b.is_dynamic()).unwrap().1;
            states.push((*arm.position(), arm.linvel(), arm.angvel()));
        }
        Ok::<_, Error>((states, deepest))
    };
    let (_, set) = pendulum(default(), 1);
    let (_, joint) = set.iter().next().unwrap();
    assert_eq!(joint.integration(), ContactIntegration::SubCycled);
    // 20 ms at 2 us: the journal crosses the gap and strikes (after about 6 ms).
    let (states, deepest) = run(default(), 1, 2e-6, 10_000).unwrap();
    assert!(deepest > 1e-7, "no contact: deepest {deepest} m");
    assert!(states == run(steel(), 1, 2e-6, 10_000).unwrap().0);
    // Rapier's four iterations and a step beyond the contact's limit are refused as for `steel()`.
    for (iterations, dt) in [(4, 2e-6), (1, 1e-3)] {
        let e = run(default(), iterations, dt, 1000).expect_err("refused");
        let explicit = run(steel(), iterations, dt, 1000).expect_err("refused");
        assert_eq!(e.to_string(), explicit.to_string());
        assert_plain(&e.to_string());
    }
}

#[test]
fn invalid_clearance_parameters_name_the_api_parameter() {
    let bad = [
        HingeDesign::steel_improved_liu(0.010, -0.2e-3, 0.016).unwrap_err(),
        HingeDesign::steel_improved_liu(0.010, 0.2e-3, f64::NAN).unwrap_err(),
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
        // The given field, not the face stiffness a huge collar makes.
        (
            joint(SpatialModel::steel(1e-4, 1e300)),
            "spatial.collar_radius",
        ),
        // A play lost in the rounding of the journal's position, one wider than the bearing.
        (
            joint(SpatialModel::steel(1e-300, 0.015)),
            "spatial.axial_play",
        ),
        (
            joint(SpatialModel::steel(0.017, 0.015)),
            "spatial.axial_play",
        ),
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

/// A restitution set on the compliant or spatial model, which take theirs from the normal law, is
/// refused naming `restitution` (unchecked, `joint()` ignored it); the large-step model takes it.
#[test]
fn a_restitution_the_model_ignores_is_refused() {
    use clearance_joint::model::spatial::SpatialModel;
    let spatial = ClearanceModel::Spatial(SpatialModel::steel(0.3e-3, 0.015));
    for model in [ClearanceModel::Compliant, spatial] {
        let e = steel()
            .model(model)
            .restitution(0.5)
            .joint(Vector::ZERO, Vector::ZERO, Vector::Z, Vector::Z)
            .unwrap_err();
        let m = e.to_string();
        assert!(
            matches!(&e, Error::Invalid { field, .. } if field == "restitution"),
            "{m}"
        );
        assert!(m.contains("LargeStep"), "{m}");
        assert_plain(&m);
    }
    let large = steel().model(ClearanceModel::LargeStep).restitution(0.5);
    let j = large.large_step_joint(Vector::ZERO, Vector::ZERO, Vector::Z, Vector::Z);
    assert!(j.is_ok());
}

#[test]
fn rapiers_default_iterations_suggest_the_large_step_model() {
    let (world, set) = pendulum(steel(), 4);
    let e = run_until_error(world, set, StepControl::fixed(1e-5), 0.01);
    let m = e.to_string();
    assert!(
        matches!(&e, Error::Invalid { field, .. } if field == "num_solver_iterations"),
        "{m}"
    );
    assert!(
        m.contains("is 4")
            && m.contains("num_solver_iterations = 1")
            && m.contains("HingeDesign::model(ClearanceModel::LargeStep)")
            && m.contains("HingeDesign::integration(ContactIntegration::SubCycled)")
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
    // The stiffest Hertz contact the ranges accept, with a step floor of 1 us: no explicit step
    // resolves it.
    let geometry = BearingGeometry::from_clearance(0.010, 0.2e-3, 0.016).unwrap();
    let law = NormalModel::Hertz(Hertz::new(1e16, 1.5).unwrap());
    let design = HingeDesign::new(geometry, law).integration(ContactIntegration::Explicit);
    let (world, set) = pendulum(design, 1);
    let control = StepControl {
        min_dt: 1e-6,
        ..StepControl::adaptive(1e-3, 0.0075)
    };
    let e = run_until_error(world, set, control, 0.1);
    let m = e.to_string();
    assert!(matches!(e, Error::Stalled { .. }), "{m}");
    assert!(m.contains("joint `pin`") && m.contains("`min_dt`"), "{m}");
    assert_plain(&m);
}

#[test]
fn a_strict_guard_names_the_joint() {
    // A validity limit of 1 nm: the first contact passes it.
    let clearance = steel().max_valid_penetration(1e-9);
    let (world, set) = pendulum(clearance, 1);
    let control = StepControl {
        strict: true,
        ..StepControl::adaptive(1e-3, 0.0075)
    };
    let e = run_until_error(world, set, control, 0.1);
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
    // clearance fields, but no option of the app (the explicit joint's step limit).
    let scene = Scene::solar_panel()
        .with_overrides(&[
            "run.contact_integration=Explicit",
            "run.step=Fixed",
            "run.dt_s=1e-3",
            "run.end_s=0.2",
        ])
        .unwrap();
    let e = run_scene(&scene).unwrap_err();
    let m = e.to_string();
    assert!(
        matches!(&e, Error::StepTooLarge(l) if l.field() == "run.dt_s"),
        "{m}"
    );
    for part in [
        "`run.dt_s` = 0.001 s",
        "`run.step = Adaptive`",
        // The impact it meets is under-damped (damping ratio 0.25): its stiffness, the
        // materials' moduli and the width, is what to soften.
        "`hinges[hinge].clearance.bearing_material.youngs_modulus_pa`",
        "`hinges[hinge].clearance.width_mm` (the law's stiffness is (pi/2) E* L)",
    ] {
        assert!(m.contains(part), "{part:?} not in {m}");
    }
    assert!(!m.contains("--"), "{m}");
}

/// A face law whose restitution is tiny stalls the explicit joint at the door's first face knock:
/// its hysteresis damping, growing with the penetration, stiffens the contact 10^6 times past its
/// spring (the sub-cycled default integrates that damping implicitly). The
/// stall names the face and its restitution, not the stiffness (unchecked, it read "too stiff
/// ... check the law's stiffness").
#[test]
fn a_face_restitution_that_stalls_is_named() {
    for restitution in ["1e-6", "1e-300"] {
        let face = format!(
            r#"hinge.model={{"Spatial":{{"geometry":{{"axial_play":3e-4,"collar_radius":0.010}},"face":{{"stiffness":3e9,"restitution":{restitution}}}}}}}"#
        );
        let scene = Scene::load(std::path::Path::new("assets/door_hinge.ron"))
            .unwrap()
            .with_overrides(&[
                "run.contact_integration=Explicit",
                "run.end_s=0.02",
                face.as_str(),
            ])
            .unwrap();
        let e = run_scene(&scene).unwrap_err();
        let m = e.to_string();
        assert!(matches!(e, Error::Stalled { .. }), "{m}");
        for part in [
            "a shoulder on a bearing face",
            "lower the face law's damping",
            "`spatial.face.restitution`",
        ] {
            assert!(m.contains(part), "{restitution}: {part:?} not in {m}");
        }
        assert!(!m.contains("stiffness"), "{m}");
    }
}

/// Steps, tolerances and drive torques the solver cannot take are refused naming the plain API's
/// field, before anything moves; a body whose state is not finite before a step is refused
/// naming the state (unchecked, each left the physical range as "speed 0 m/s").
#[test]
fn steps_torques_and_states_the_solver_cannot_take_are_named() {
    for (control, field) in [
        (StepControl::fixed(1e-300), "dt"),
        (StepControl::adaptive(1e-300, 0.0075), "max_dt"),
        (StepControl::adaptive(1e-3, 1e-300), "tolerance"),
    ] {
        let (world, set) = pendulum(steel(), 1);
        let e = world_of(world, set, control).step(0.1).unwrap_err();
        let m = e.to_string();
        assert!(
            matches!(&e, Error::Invalid { field: f, .. } if f == field),
            "{field}: {m}"
        );
        assert_plain(&m);
    }
    let arm = RigidBodyHandle::from_raw_parts(1, 0);
    let spring = |t0: f64, k: f64| {
        TorsionSpring::new(RigidBodyHandle::from_raw_parts(0, 0), arm, Vector::Z, t0, k)
    };
    for (e, field) in [
        (spring(1e300, 0.0), "torque0"),
        (spring(0.1, 1e300), "stiffness"),
    ] {
        let e = e.unwrap_err();
        assert!(
            matches!(&e, Error::Invalid { field: f, .. } if f == field),
            "{e}"
        );
    }
    for (field, set_bad) in [
        (
            "linvel",
            (|rb: &mut RigidBody| rb.set_linvel(Vector::new(f64::NAN, 0.0, 0.0), true))
                as fn(&mut RigidBody),
        ),
        ("angvel", |rb| {
            rb.set_angvel(Vector::new(0.0, 0.0, f64::INFINITY), true)
        }),
        ("position", |rb| {
            rb.set_translation(Vector::new(f64::NAN, 0.0, 0.0), true)
        }),
    ] {
        let (world, set) = pendulum(steel(), 1);
        let mut world = world_of(world, set, StepControl::adaptive(1e-3, 0.0075));
        set_bad(&mut world.rapier.bodies[arm]);
        let e = world.step(0.1).unwrap_err();
        let m = e.to_string();
        assert!(
            matches!(&e, Error::Invalid { field: f, .. } if f == field) && m.contains("non-finite"),
            "{field}: {m}"
        );
        assert_eq!(world.time(), 0.0);
    }
}

/// `model: Spatial` without its settings, in a scene file or an override, says how the spatial
/// model is written (unchecked: "invalid type: unit variant, expected newtype variant").
#[test]
fn a_spatial_model_without_its_settings_says_how_it_is_written() {
    let text = std::fs::read_to_string("assets/solar_panel_spatial.ron").unwrap();
    let start = text.find("model: Spatial(").unwrap();
    let end = start + text[start..].find("\n").unwrap();
    let bare = format!("{}model: Spatial,{}", &text[..start], &text[end..]);
    let e = Scene::from_ron(&bare, "bare.ron").unwrap_err().to_string();
    assert!(
        e.contains("`Spatial` is written Spatial((geometry: (axial_play"),
        "{e}"
    );
    let e = Scene::solar_panel()
        .with_overrides(&["hinge.model=Spatial"])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("`Spatial` is written Spatial((geometry:") && e.contains("as JSON"),
        "{e}"
    );
}

/// The same face sub-cycled (the default) runs to its end: a spatial joint's sub-steps
/// integrate the damping implicitly under error control, and its world step follows the
/// regions' paths, not the contact, so the stall guard on a sub-cycled contact that asks for
/// world steps below the floor leaves it alone (the face is stable only below 4.2e-11 s).
#[test]
fn a_face_restitution_that_stalls_the_explicit_joint_runs_sub_cycled() {
    let face = r#"hinge.model={"Spatial":{"geometry":{"axial_play":3e-4,"collar_radius":0.010},"face":{"stiffness":3e9,"restitution":1e-6}}}"#;
    let scene = Scene::load(std::path::Path::new("assets/door_hinge.ron"))
        .unwrap()
        .with_overrides(&["run.end_s=0.02", face])
        .unwrap();
    let r = run_scene(&scene).unwrap();
    let s = r.summary();
    assert!(
        s.complete && s.twins["clearance"].onsets > 0,
        "{:?}",
        s.error
    );
}

/// A stall that the turn bound causes (a body spinning so fast that `tolerance/8` rad a step needs
/// steps at the floor) says so and names `tolerance`, not "a body moved by hand".
#[test]
fn a_stall_of_the_turn_bound_names_the_tolerance() {
    let mut world = PhysicsWorld::new();
    world.bodies.insert(
        RigidBodyBuilder::dynamic()
            .angvel(Vector::new(0.0, 0.0, 2e4))
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                1.0,
                Vector::splat(0.01),
            )),
    );
    let mut world = ClearanceWorld::new(world, StepControl::adaptive(1e-3, 1e-6));
    let e = loop {
        match world.step(1.0) {
            Ok(_) => assert!(world.steps() < 1_000_000, "no stall"),
            Err(e) => break e,
        }
    };
    let m = e.to_string();
    assert!(matches!(e, Error::Stalled { .. }), "{m}");
    assert!(
        m.contains("the turn bound") && m.contains("raise `tolerance`"),
        "{m}"
    );
    assert!(!m.contains("moved by hand"), "{m}");
    assert_plain(&m);
}

/// A fixed step refused at an impact advises from the impact as a short enough step resolves it
/// (the approach speed at the crossing, its kinetic energy stored in the law's spring), not from
/// the depth the step too long pressed to: the step it suggests runs through the impact, and one
/// twice as long is refused again (the explicit joint: a sub-cycled one has no step limit). (From
/// the pressed depth, the paper's scene at 1 ms suggested 2.6e-5 s, five times shorter than
/// needed.)
#[test]
fn a_refused_fixed_step_suggests_the_step_the_impact_needs() {
    let run = |dt: f64| {
        let scene = Scene::solar_panel()
            .with_overrides(&[
                "run.contact_integration=Explicit".to_string(),
                "run.step=Fixed".to_string(),
                format!("run.dt_s={dt}"),
                "run.end_s=0.2".to_string(),
            ])
            .unwrap();
        run_scene(&scene)
    };
    let e = run(1e-3).unwrap_err();
    let suggested = e.suggested_step().expect("a fixed step to suggest");
    assert!(suggested > 1e-4, "{e}");
    assert!(run(suggested).is_ok(), "the suggested {suggested} s");
    let e = run(2.0 * suggested).unwrap_err();
    assert!(matches!(e, Error::StepTooLarge(_)), "{e}");
}
