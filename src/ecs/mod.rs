//! The bevy_ecs layer (cargo feature `ecs`, on by default): the Rapier world as a resource, rigid
//! bodies, hinges and drives as components, and the per-step systems in a fixed order.
//!
//! A thin layer: the physics is the core's
//! ([`ClearanceJointSet`](crate::rapier::joint::ClearanceJointSet),
//! [`DriveSet`](crate::rapier::sources::drive::DriveSet), the conversions of
//! [`convert`](crate::rapier::hinge::convert)). The systems reconcile the Rapier world with the components
//! every step: spawning, changing or removing a component is all a user does.
//!
//! - [`Physics`] (resource): the Rapier `PhysicsWorld`, the clearance joints and the drives;
//!   [`Physics::new`] makes a new world, [`Physics::from_world`] wraps yours.
//! - [`Body`]: a rigid body, from a Rapier description (`RigidBodyBuilder`) or an existing handle.
//! - [`Hinge`]: which two bodies a hinge joins, its anchors and axes; with a mode component:
//!   [`IdealHinge`] (Rapier's revolute joint) or [`ClearanceHinge`] (radial clearance, contact and
//!   friction laws). A hinge with neither joins nothing. When both are present, the clearance wins.
//! - [`Drive`]: a torsion spring `T = T0 - k theta` on a hinge (on the hinge's entity).
//! - [`UserHooks`] (resource, optional): a force source of your own
//!   ([`StepHooks`](crate::rapier::pipeline::step_hooks::StepHooks)) stepped with the world's.
//! - [`HingeState`] and [`BodyState`] (added automatically): what the last step did (a hinge's
//!   force, eccentricity and `|e|/c`, contact, impulse, the substeps of a large-step hinge;
//!   the counts of onsets and impacts, see the
//!   [definitions](crate::rapier::observers::metrics#onsets-impacts-and-chatter); the force averaged over
//!   the last frame and its peak: [`run_frame`] runs one frame of a game loop).
//!
//! A `ClearanceHinge` builds the compliant model unless its
//! [`HingeDesign::model`](crate::rapier::hinge::design::HingeDesign::model) is
//! [`ClearanceModel::LargeStep`](crate::rapier::hinge::design::ClearanceModel::LargeStep): the one-line
//! choice of the large-step model (see [`large_step`](crate::rapier::large_step)), stepped by the
//! same schedule.
//!
//! Swapping an entity's `IdealHinge` for a `ClearanceHinge` is the whole change, at spawn or
//! while running: the sync system converts the Rapier revolute joint into a clearance joint with
//! [`ConvertRevolute::convert_revolute`](crate::rapier::hinge::convert::ConvertRevolute::convert_revolute)
//! (and back with
//! [`revert_to_revolute`](crate::rapier::hinge::convert::ConvertRevolute::revert_to_revolute)
//! when the `ClearanceHinge` is removed again).
//!
//! # The world's settings are yours
//!
//! The layer never changes the Rapier world's settings ([`Physics::new`] keeps Rapier's
//! defaults but `dt` and gravity; [`Physics::from_world`] keeps the world as it comes). A
//! compliant hinge sub-cycles its contact by default (integrated inside each step,
//! [`ContactIntegration`](crate::rapier::joint::ContactIntegration)) and takes any number of
//! solver iterations. The explicit one (`ContactIntegration::Explicit`) needs one thing of them:
//! `integration_parameters.num_solver_iterations = 1`. Its contact force is evaluated once per
//! step and held over the step; Rapier's substeps would make every impact gain energy. The
//! setting is the whole world's: every other body then gets
//! one solver iteration too, and stacks of resting bodies lose the stiffness Rapier's default
//! iterations give them (a stack of eight 0.5 m boxes at 60 Hz stands with Rapier's 4 and has
//! fallen within 10 s with one). An explicit compliant [`ClearanceHinge`] in a world with more
//! iterations is refused with an error that says so; nothing is changed. A game world that keeps
//! its iterations keeps its hinges sub-cycled, or gives them the large-step model, which works
//! with any number. One substep is also one
//! Gauss-Seidel sweep over the ideal joints a step: a chain with a light body between stiff joints
//! (a motor-driven crank carrying a heavier coupler) wants more sweeps,
//! `integration_parameters.num_internal_pgs_iterations` (see
//! [`ClearanceWorld`](crate::rapier::pipeline::world)'s docs), which keeps the one substep.
//!
//! ```
//! use bevy_ecs::prelude::*;
//! use clearance_joint::rapier::hinge::design::HingeDesign;
//! use clearance_joint::ecs::*;
//! use rapier3d_f64::math::Vector;
//! use rapier3d_f64::prelude::{MassProperties, RigidBodyBuilder};
//!
//! let mut world = World::new();
//! let mut physics = Physics::new(1e-5, Vector::new(0.0, -9.81, 0.0));
//! // One substep a step, as the scenes run (the explicit model's need; the sub-cycled
//! // default takes any number, see above).
//! physics.world.rapier.integration_parameters.num_solver_iterations = 1;
//! world.insert_resource(physics);
//! let base = world.spawn(Body::new(RigidBodyBuilder::fixed())).id();
//! let arm = world
//!     .spawn(Body::new(
//!         RigidBodyBuilder::dynamic()
//!             .translation(Vector::new(0.0, -0.3, 0.0))
//!             .additional_mass_properties(MassProperties::new(Vector::ZERO, 2.0, Vector::splat(0.02)))
//!             .can_sleep(false),
//!     ))
//!     .id();
//! let pivot = world
//!     .spawn((
//!         Hinge::new(base, arm, Vector::Z).local_anchor2(Vector::new(0.0, 0.3, 0.0)),
//!         // In place of: IdealHinge,
//!         ClearanceHinge(HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016)?),
//!     ))
//!     .id();
//! let mut schedule = physics_schedule();
//! for _ in 0..20_000 {
//!     run_step(&mut world, &mut schedule)?;
//! }
//! let state = world.get::<HingeState>(pivot).unwrap();
//! assert_eq!(state.mode, HingeMode::Clearance);
//! assert!((state.force - 19.62).abs() < 0.05, "the journal carries the arm: {} N", state.force);
//! assert!(state.eccentricity_ratio > 1.0, "resting on the wall: |e|/c = {}", state.eccentricity_ratio);
//! # Ok::<(), clearance_joint::Error>(())
//! ```
//!
//! # Your own Rapier world
//!
//! [`Physics::from_world`] wraps a `PhysicsWorld` you built: its settings, bodies, colliders and
//! joints stay, and [`Body::from_handle`] makes one of its bodies an entity's. Here a game world
//! at 60 Hz with Rapier's 4 solver iterations (its stacks stay stiff) hangs a sign on a
//! large-step clearance hinge; the same hinge with the explicit compliant model is refused (the
//! sub-cycled one, the default, would step it).
//!
//! ```
//! use bevy_ecs::prelude::*;
//! use clearance_joint::rapier::hinge::design::{HingeDesign, ClearanceModel};
//! use clearance_joint::rapier::joint::ContactIntegration;
//! use clearance_joint::ecs::*;
//! use rapier3d_f64::math::Vector;
//! use rapier3d_f64::prelude::{MassProperties, PhysicsWorld, RigidBodyBuilder};
//!
//! let mut rapier = PhysicsWorld::new(); // 1/60 s, 4 solver iterations, gravity -9.81 along y
//! let post = rapier.bodies.insert(RigidBodyBuilder::fixed());
//! let sign = rapier.bodies.insert(
//!     RigidBodyBuilder::dynamic()
//!         .translation(Vector::new(0.0, -0.3, 0.0))
//!         .additional_mass_properties(MassProperties::new(Vector::ZERO, 2.0, Vector::splat(0.02))),
//! );
//! let mut world = World::new();
//! world.insert_resource(Physics::from_world(rapier));
//! let (post, sign) = (
//!     world.spawn(Body::from_handle(post)).id(),
//!     world.spawn(Body::from_handle(sign)).id(),
//! );
//! let clearance = HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016)?;
//! let hinge = world
//!     .spawn((
//!         Hinge::new(post, sign, Vector::Z).local_anchor2(Vector::new(0.0, 0.3, 0.0)),
//!         ClearanceHinge(clearance.clone().integration(ContactIntegration::Explicit)),
//!     ))
//!     .id();
//! let mut schedule = physics_schedule();
//! // The explicit compliant model needs one solver iteration; the world is left as it is.
//! let refused = run_step(&mut world, &mut schedule).unwrap_err().to_string();
//! assert!(refused.contains("num_solver_iterations") && refused.contains("LargeStep"), "{refused}");
//! assert_eq!(world.resource::<Physics>().world.rapier.integration_parameters.num_solver_iterations, 4);
//! // The large-step model steps the world as it is.
//! world
//!     .entity_mut(hinge)
//!     .insert(ClearanceHinge(clearance.model(ClearanceModel::LargeStep)));
//! for _ in 0..120 {
//!     run_step(&mut world, &mut schedule)?;
//! }
//! let state = world.get::<HingeState>(hinge).unwrap();
//! assert_eq!(state.mode, HingeMode::LargeStep);
//! assert!((state.force - 19.62).abs() < 1e-3, "the journal carries the sign: {} N", state.force);
//! assert!(state.substeps >= 4, "{} substeps", state.substeps);
//! # Ok::<(), clearance_joint::Error>(())
//! ```

// One concept a file. The physics core (`crate::rapier`) knows nothing of these.
// - components: what a user spawns, and the states the systems write back;
// - physics: the `Physics` resource, the Rapier side of every entity and the work of the systems;
// - systems: the per-step systems, components to Rapier and back;
// - schedule: their order (`PhysicsSet`) and the schedule that runs one step.
mod components;
mod physics;
mod schedule;
mod systems;
#[cfg(test)]
mod tests;

pub use components::{
    Body, BodyState, ClearanceHinge, Drive, Hinge, HingeMode, HingeState, IdealHinge,
};
pub use physics::{HingeJoint, Physics};
pub use schedule::{PhysicsSet, add_physics_systems, physics_schedule, run_frame, run_step};
pub use systems::{UserHooks, apply_forces, record, step_physics, sync_bodies, sync_hinges};
