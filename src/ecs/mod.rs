//! The bevy_ecs layer (cargo feature `ecs`, on by default): the Rapier world as a resource, rigid
//! bodies, hinges and drives as components, and the per-step systems in a fixed order.
//!
//! A thin layer: the physics is the core's
//! ([`ClearanceJointSet`](crate::rapier::joint::ClearanceJointSet),
//! [`DriveSet`](crate::rapier::drive::DriveSet), the conversions of
//! [`convert`](crate::rapier::convert)). The systems reconcile the Rapier world with the components
//! every step: spawning, changing or removing a component is all a user does.
//!
//! - [`Physics`] (resource): the Rapier `PhysicsWorld`, the clearance joints and the drives.
//! - [`Body`]: a rigid body, from a Rapier description (`RigidBodyBuilder`) or an existing handle.
//! - [`Hinge`]: which two bodies a hinge joins, its anchors and axes; with a mode component:
//!   [`IdealHinge`] (Rapier's revolute joint) or [`ClearanceHinge`] (radial clearance, contact and
//!   friction laws). A hinge with neither joins nothing. When both are present, the clearance wins.
//! - [`Drive`]: a torsion spring `T = T0 - k theta` on a hinge (on the hinge's entity).
//! - [`HingeState`] and [`BodyState`] (added automatically): what the last step did.
//!
//! A `ClearanceHinge` builds the compliant model unless its
//! [`Clearance::model`](crate::rapier::convert::Clearance::model) is
//! [`ClearanceModel::LargeStep`](crate::rapier::convert::ClearanceModel::LargeStep): the one-line
//! choice of the large-step model (see [`large_step`](crate::rapier::large_step)), stepped by the
//! same schedule.
//!
//! Swapping an entity's `IdealHinge` for a `ClearanceHinge` is the whole change, at spawn or
//! while running: the sync system converts the Rapier revolute joint into a clearance joint with
//! [`revolute_to_clearance`](crate::rapier::convert::revolute_to_clearance) (and back with
//! [`clearance_to_revolute`](crate::rapier::convert::clearance_to_revolute) when the `ClearanceHinge`
//! is removed again).
//!
//! ```
//! use bevy_ecs::prelude::*;
//! use clearance_joint::rapier::convert::Clearance;
//! use clearance_joint::ecs::*;
//! use rapier3d_f64::math::Vector;
//! use rapier3d_f64::prelude::{MassProperties, RigidBodyBuilder};
//!
//! let mut world = World::new();
//! world.insert_resource(Physics::new(1e-5, Vector::new(0.0, -9.81, 0.0)));
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
//!         // Was: IdealHinge,
//!         ClearanceHinge(Clearance::steel_improved_liu(0.010, 0.2e-3, 0.016)?),
//!     ))
//!     .id();
//! let mut schedule = physics_schedule();
//! for _ in 0..20_000 {
//!     run_step(&mut world, &mut schedule)?;
//! }
//! let state = world.get::<HingeState>(pivot).unwrap();
//! assert_eq!(state.mode, HingeMode::Clearance);
//! assert!((state.force - 19.62).abs() < 0.05, "the journal carries the arm: {} N", state.force);
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
pub use schedule::{PhysicsSet, add_physics_systems, physics_schedule, run_step};
pub use systems::{
    apply_forces, finish_large_step, prepare_large_step, record, step_physics, sync_bodies,
    sync_hinges,
};
