//! Revolute hinges with **radial clearance** for [Rapier](https://rapier.rs) (`rapier3d-f64`).
//!
//! The journal rattles inside its bearing: contact and friction forces come from published
//! compliant contact laws (Hertz, Kelvin-Voigt, Hunt-Crossley, Lankarani-Nikravesh, Flores,
//! Gonthier, Liu, and the improved law of Wang & Liu), evaluated from the two bodies' poses in place
//! of Rapier's ideal revolute constraint. The equations, conventions and parameters are in
//! [`model`] (the project's `docs/MODEL.md`).
//!
//! This guide goes from one hinge in your own Rapier loop to driven mechanisms, scene files,
//! studies and the choice of model. The repository's README has the measured results, the
//! command-line app and every option.
//!
//! # 1. One hinge in your Rapier loop
//!
//! Keep your world and your loop. One change makes a loop clearance-ready: a
//! [`ClearanceWorld`](rapier::pipeline::world::ClearanceWorld) around your `PhysicsWorld`,
//! whose [`step`](rapier::pipeline::world::ClearanceWorld::step) takes the place of `world.step()`: it
//! evaluates the joints' and drives' forces, chooses the step (adaptive by default, or fixed with
//! a stability check), takes it with every joint set's hooks, judges it and retries it if a
//! contact was entered blindly, and keeps the run's guards. The joint sub-cycles its contact
//! inside each step (the default) and takes any number of solver iterations; the explicit joint
//! (`ContactIntegration::Explicit`) needs one. Then one call turns a revolute joint you already
//! have into a clearance joint:
//!
//! ```
//! use clearance_joint::prelude::*;
//! use rapier3d_f64::prelude::*;
//!
//! let mut rapier = PhysicsWorld::new(); // gravity -9.81 m/s^2 along y
//! rapier.integration_parameters.num_solver_iterations = 1; // as the scenes run (any works)
//! let base = rapier.bodies.insert(RigidBodyBuilder::fixed());
//! let arm = rapier.bodies.insert(
//!     RigidBodyBuilder::dynamic()
//!         .translation(Vector::new(0.0, -0.3, 0.0))
//!         .additional_mass_properties(MassProperties::new(Vector::ZERO, 2.0, Vector::splat(0.02))),
//! );
//! let hinge = RevoluteJointBuilder::new(Vector::Z).local_anchor2(Vector::new(0.0, 0.3, 0.0));
//! let hinge = rapier.impulse_joints.insert(base, arm, hinge, true);
//! // Adaptive steps of at most 1 ms, 1.5 % of a contact period inside contacts.
//! let mut world = ClearanceWorld::new(rapier, StepControl::adaptive(1e-3, 0.0075));
//!
//! // 0.2 mm of play in a 20 mm steel bearing, 16 mm wide; the base carries the bearing.
//! let play = HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016)?;
//! let hinge = world.clearance.convert_revolute(hinge, BearingSide::Body1, play, &mut world.rapier.impulse_joints)?;
//!
//! world.step_to(0.1)?;
//! let report = world.clearance.get(hinge).unwrap().report(); // force, eccentricity, penetration, ...
//! assert!(report.state.penetration >= 0.0 && world.guards().is_clean());
//! # Ok::<(), clearance_joint::Error>(())
//! ```
//!
//! The pieces: [`HingeDesign`](rapier::hinge::design::HingeDesign) (geometry and laws, any law of
//! [`model::laws`]), [`ClearanceJointSet`](rapier::joint::ClearanceJointSet) (the joints and their
//! force hook), [`LargeStepJointSet`](rapier::large_step::LargeStepJointSet) (the play as a
//! constraint, for game and robot rates), [`StepControl`](rapier::pipeline::stepper::StepControl)
//! (step choice, acceptance, [`GuardReport`](rapier::pipeline::protocol::GuardReport)), the step
//! protocol every set implements ([`StepHooks`](rapier::pipeline::step_hooks::StepHooks)), and
//! [`HingeDesign::joint`](rapier::hinge::design::HingeDesign::joint) for a joint built from scratch.
//! [`ClearanceWorld`](rapier::pipeline::world::ClearanceWorld) bundles them and takes every step;
//! the scene runner and the bevy_ecs layer are built on it.
//!
//! # 2. A driven mechanism, with its metrics
//!
//! Any Rapier mechanism works: prismatic guides, kinematic bodies with a prescribed motion
//! ([`rapier::sources::prescribed`]), torsion springs and torques ([`rapier::sources::drive`]). Around the loop, the
//! same public pieces the scene runner uses:
//! - [`ImpactRecorder`](rapier::observers::metrics::ImpactRecorder): the impact list (onset, approach speed,
//!   peak force, deepest penetration, duration), contact fraction, peak and first-impact figures;
//! - [`ReactionSolver`](rapier::observers::reaction::ReactionSolver): the exact reactions of the ideal joints
//!   at a state, from the constrained equations (no difference quotients);
//! - [`StepInfo`](rapier::pipeline::stepper::StepInfo) of every step and the world's guards (penetration
//!   beyond the law's validity, energy gained, steps at the floor).
//!
//! The README's "A driven mechanism" builds a slider-crank with a clearance pin this way in under
//! 40 lines; `examples/slider_crank.rs` compares it with its ideal twin.
//!
//! # 3. Scenes and the runner
//!
//! A mechanism can instead be described in a RON scene file ([`scene::Scene`]: bodies, ideal
//! joints, hinges with or without clearance, drives, prescribed motions, run settings), validated
//! with errors that name the field. [`scene::runner::Simulation`] builds an ideal and a clearance
//! twin in one [`ClearanceWorld`](rapier::pipeline::world::ClearanceWorld), steps them with the same step control, and returns
//! their time series, impact lists, reactions, energy and momentum checks and guards;
//! [`RunResult::write`](scene::runner::RunResult::write) writes the result set whole or not at
//! all:
//!
//! ```
//! use clearance_joint::scene::Scene;
//! use clearance_joint::scene::runner::{RunOptions, Simulation};
//!
//! // The paper's solar panel, shortened to its first impact.
//! let scene = Scene::solar_panel().with_overrides(&["run.end_s=0.1"])?;
//! let result = Simulation::new(&scene, RunOptions::default())?.run()?;
//! let summary = result.summary();
//! assert!(result.guards.is_clean() && summary.twins.len() == 2);
//! # Ok::<(), clearance_joint::Error>(())
//! ```
//!
//! # 4. Studies, sweeps and figures
//!
//! The command-line app of the repository (package `clearance_joint_app`, not a dependency of
//! this library) runs scenes, sweeps any scene field (`sweep --set path=v1,v2`), the paper's
//! studies of clearance size, driving torque and friction (`study all`), and draws the figures.
//! It is built on section 3's runner; nothing in it is needed to use the library.
//!
//! # 5. Which model: compliant or large-step
//!
//! - The **compliant** clearance joint ([`rapier::joint`]) resolves each impact: peak and fatigue
//!   loads, impact counts and timing, penetration, stick-slip with a specific friction law. Its
//!   contact is stiff: by default the joint sub-cycles it inside each world step
//!   ([`ContactIntegration`](rapier::joint::ContactIntegration)), with any number of solver
//!   iterations; the explicit joint needs short steps (chosen by the stepper) and one iteration.
//! - The **large-step** model ([`rapier::large_step`]) solves the play as a constraint inside
//!   Rapier's solver, for worlds stepped at 1/60 s or 1 kHz with the default four iterations:
//!   angles, orbits, backlash, settling and sustained loads, not peak forces. One setter chooses
//!   it: `HingeDesign::model(ClearanceModel::LargeStep)`.
//!
//! The README's fidelity ladder measures both against a converged reference.
//!
//! # 6. bevy_ecs
//!
//! With the `ecs` feature (on by default), [`ecs`] is a thin layer of components and systems over
//! the same pieces: a hinge is a component, and its mode (`IdealHinge` or `ClearanceHinge`) is
//! another component you swap.
//!
//! # Layers
//!
//! | module | layer | depends on |
//! |---|---|---|
//! | [`model`] | contact and friction laws, bearing kinematics, hinge angles: pure numbers | - |
//! | [`rapier`] | the joints, step control, conversions, drives, prescribed motion, reactions, metrics | `model`, Rapier |
//! | `ecs` | bevy_ecs components and systems | `rapier`, `model` |
//! | [`scene`] | scene files, the runner, result sets and summaries | `rapier`, `model` |
//! | [`error`], [`table`] | errors with the field and the reason; CSV tables | - |
#![warn(missing_docs)]
// `!(x > 0.0)` is how this crate rejects NaN along with non-positive values: intended.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

#[cfg(feature = "ecs")]
pub mod ecs;
pub mod error;
pub mod model;
pub mod rapier;
pub mod scene;
pub mod table;
pub use error::{Error, Result};

// The README's examples and its chapters' (docs/, except MODEL.md, the `model` module's doc) are
// compiled and run as doctests. `tests/doc_links.rs` checks that every chapter is listed here.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
#[cfg(doctest)]
mod chapter_doctests {
    #[doc = include_str!("../docs/guide-plain-rapier.md")]
    pub struct GuidePlainRapier;
    #[doc = include_str!("../docs/guide-mechanisms.md")]
    pub struct GuideMechanisms;
    #[doc = include_str!("../docs/guide-scenes-and-app.md")]
    pub struct GuideScenesAndApp;
    #[doc = include_str!("../docs/guide-bevy-ecs.md")]
    pub struct GuideBevyEcs;
    #[doc = include_str!("../docs/guide-game-and-robot-rates.md")]
    pub struct GuideGameAndRobotRates;
    #[doc = include_str!("../docs/stepper-and-accuracy.md")]
    pub struct StepperAndAccuracy;
    #[doc = include_str!("../docs/large-step-model.md")]
    pub struct LargeStepModel;
    #[doc = include_str!("../docs/sub-cycled-contact.md")]
    pub struct SubCycledContact;
    #[doc = include_str!("../docs/spatial-joint.md")]
    pub struct SpatialJoint;
    #[doc = include_str!("../docs/scene-format.md")]
    pub struct SceneFormat;
    #[doc = include_str!("../docs/validation.md")]
    pub struct Validation;
    #[doc = include_str!("../docs/reliability.md")]
    pub struct Reliability;
    #[doc = include_str!("../docs/layout-and-dependencies.md")]
    pub struct LayoutAndDependencies;
}

/// The types most users need to put clearance hinges in their own Rapier loop.
///
/// An explicit list, made to be glob-imported next to `rapier3d_f64::prelude::*`: no name here
/// is also a different item of Rapier's prelude (a test compiles both globs with
/// `#![deny(warnings)]`). The contact and friction laws are not in it: Rapier's prelude has its
/// own `FrictionModel`, so import the laws by name from [`model::laws`], which also shadows
/// Rapier's name:
///
/// ```
/// use clearance_joint::model::laws::{Bai, FrictionModel};
/// use clearance_joint::prelude::*;
/// use rapier3d_f64::prelude::*;
///
/// let play = HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016)?.friction(FrictionModel::Bai(Bai::DRY));
/// # let _ = (play, PhysicsWorld::new());
/// # Ok::<(), clearance_joint::Error>(())
/// ```
pub mod prelude {
    pub use crate::rapier::hinge::convert::{BearingSide, ConvertRevolute};
    pub use crate::rapier::hinge::design::{ClearanceModel, HingeDesign};
    pub use crate::rapier::joint::{
        ClearanceJoint, ClearanceJointHandle, ClearanceJointSet, ContactIntegration,
        OutOfPlaneLock, SubCycleTechniques,
    };
    pub use crate::rapier::large_step::{
        LargeStepJoint, LargeStepJointBuilder, LargeStepJointHandle, LargeStepJointSet, Restitution,
    };
    pub use crate::rapier::observers::metrics::{ContactObservation, ImpactRecorder};
    pub use crate::rapier::observers::reaction::{IdealJoint, KinematicState, ReactionSolver};
    pub use crate::rapier::pipeline::protocol::{GuardKind, GuardReport, Violation, Wrench};
    pub use crate::rapier::pipeline::step_hooks::{EvaluateContext, StepContext, StepHooks};
    pub use crate::rapier::pipeline::stepper::{StepControl, StepInfo};
    pub use crate::rapier::pipeline::world::ClearanceWorld;
    pub use crate::rapier::sources::drive::{DriveHandle, DriveSet, TorsionSpring};
    /// The same item as Rapier's (`rapier3d_f64::math::Vector`), so no clash with its prelude.
    pub use rapier3d_f64::math::Vector;
}
