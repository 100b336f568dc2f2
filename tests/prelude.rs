//! A downstream crate's imports, as the README writes them: both preludes glob-imported, with
//! warnings as errors. A name exported by both preludes as different items is ambiguous where it
//! is used (the `ambiguous_glob_imports` lint, or error E0659), so this file uses every name of
//! `clearance_joint::prelude` and fails to compile if any of them clashes with Rapier's prelude.
#![deny(warnings)]

use clearance_joint::prelude::*;
use rapier3d_f64::prelude::*;

/// Every name of the prelude, used once (types by name, traits as bounds).
#[test]
fn every_prelude_name_resolves_next_to_rapiers_prelude() {
    fn step_hooks<T: StepHooks>() -> &'static str {
        std::any::type_name::<T>()
    }
    fn converts<T: ConvertRevolute>() -> &'static str {
        std::any::type_name::<T>()
    }
    let names = [
        std::any::type_name::<BearingSide>(),
        std::any::type_name::<HingeDesign>(),
        std::any::type_name::<ClearanceModel>(),
        converts::<ClearanceJointSet>(),
        converts::<LargeStepJointSet>(),
        step_hooks::<DriveSet>(),
        std::any::type_name::<DriveHandle>(),
        std::any::type_name::<ClearanceWorld>(),
        std::any::type_name::<TorsionSpring>(),
        std::any::type_name::<GuardReport>(),
        std::any::type_name::<GuardKind>(),
        std::any::type_name::<Violation>(),
        std::any::type_name::<Wrench>(),
        std::any::type_name::<EvaluateContext>(),
        std::any::type_name::<StepContext>(),
        std::any::type_name::<ClearanceJoint>(),
        std::any::type_name::<ClearanceJointHandle>(),
        std::any::type_name::<OutOfPlaneLock>(),
        std::any::type_name::<ContactIntegration>(),
        std::any::type_name::<SubCycleTechniques>(),
        std::any::type_name::<LargeStepJoint>(),
        std::any::type_name::<LargeStepJointBuilder>(),
        std::any::type_name::<LargeStepJointHandle>(),
        std::any::type_name::<Restitution>(),
        std::any::type_name::<ContactObservation>(),
        std::any::type_name::<ImpactRecorder>(),
        std::any::type_name::<IdealJoint>(),
        std::any::type_name::<KinematicState>(),
        std::any::type_name::<ReactionSolver>(),
        step_hooks::<LargeStepJointSet>(),
        std::any::type_name::<StepControl>(),
        std::any::type_name::<StepInfo>(),
        std::any::type_name::<Vector>(),
    ];
    // Each resolved to this crate's item (Vector to Rapier's own, which the prelude re-exports).
    for name in names {
        assert!(
            name.starts_with("clearance_joint::") || name.contains("glam"),
            "{name}"
        );
    }
    // The name the laws share with Rapier's prelude resolves to Rapier's, unambiguously.
    assert!(std::any::type_name::<FrictionModel>().starts_with("rapier3d_f64::"));
    // And the list above is complete: a name added to the prelude must be used there.
    let this_test = include_str!("prelude.rs");
    for name in prelude_names() {
        assert!(
            this_test.contains(&format!("::<{name}>()"))
                || this_test.contains(&format!("<T: {name}>")),
            "the prelude's `{name}` is not used by this test"
        );
    }
}

/// The names `pub mod prelude` exports, read from its source (which must hold no glob).
fn prelude_names() -> Vec<String> {
    let source = include_str!("../src/lib.rs");
    let start = source
        .find("pub mod prelude {")
        .expect("the prelude module");
    let body = &source[start..];
    let body = &body[..body.find("\n}").expect("the end of the prelude")];
    let mut names = Vec::new();
    for item in body.split("pub use ").skip(1) {
        let item = &item[..item.find(';').expect("a use item ends")];
        assert!(!item.contains('*'), "a glob in the prelude: {item}");
        let list = match item.find('{') {
            Some(open) => &item[open + 1..item.rfind('}').expect("a closed list")],
            None => item.rsplit("::").next().expect("a path"),
        };
        for name in list.split(',').map(str::trim).filter(|n| !n.is_empty()) {
            names.push(name.rsplit(" as ").next().expect("a name").to_string());
        }
    }
    names
}

/// The README's first loop, written against both preludes, with a law imported by name (which
/// shadows Rapier's own `FrictionModel`).
#[test]
fn a_hinge_in_a_rapier_loop_with_both_preludes() -> Result<(), clearance_joint::Error> {
    use clearance_joint::model::laws::{Bai, FrictionModel};
    let mut world = PhysicsWorld::new();
    world.integration_parameters.num_solver_iterations = 1;
    let base = world.bodies.insert(RigidBodyBuilder::fixed());
    let arm = world.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.0, -0.3, 0.0))
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                2.0,
                Vector::splat(0.02),
            )),
    );
    let revolute = RevoluteJointBuilder::new(Vector::Z).local_anchor2(Vector::new(0.0, 0.3, 0.0));
    let hinge = world.impulse_joints.insert(base, arm, revolute, true);
    let mut clearance = ClearanceJointSet::new();
    let play = HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016)?
        .friction(FrictionModel::Bai(Bai::DRY));
    let hinge =
        clearance.convert_revolute(hinge, BearingSide::Body1, play, &mut world.impulse_joints)?;
    let mut world = ClearanceWorld::new(world, StepControl::adaptive(1e-3, 0.0075));
    world.clearance = clearance;
    world.step_to(0.1)?;
    let report = world
        .clearance
        .get(hinge)
        .expect("the hinge is in the set")
        .report();
    assert!(report.state.penetration >= 0.0, "{report:?}");
    assert!(world.guards().is_clean(), "{:?}", world.guards());
    Ok(())
}
