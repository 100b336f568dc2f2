//! The order of a physics step ([`PhysicsSet`]) and the schedule that runs it.

use super::physics::Physics;
use super::systems::{apply_forces, record, step_physics, sync_bodies, sync_hinges};
use crate::error::{Error, Result};
use bevy_ecs::prelude::*;

/// The stages of a physics step, in this order.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PhysicsSet {
    /// Components to Rapier: bodies, hinges (with conversions), drives.
    Sync,
    /// Torsion-spring torques and clearance contact and friction forces at the current state,
    /// when the stepper has not evaluated them yet ([`apply_forces`]).
    Forces,
    /// One accepted step of the [`Stepper`](crate::rapier::stepper::Stepper).
    Step,
    /// Rapier to [`HingeState`](super::HingeState) and [`BodyState`](super::BodyState).
    Record,
}

/// Adds the physics systems to `schedule`, in [`PhysicsSet`] order.
pub fn add_physics_systems(schedule: &mut Schedule) {
    schedule.configure_sets(
        (
            PhysicsSet::Sync,
            PhysicsSet::Forces,
            PhysicsSet::Step,
            PhysicsSet::Record,
        )
            .chain(),
    );
    schedule.add_systems((
        (sync_bodies, sync_hinges).chain().in_set(PhysicsSet::Sync),
        apply_forces.in_set(PhysicsSet::Forces),
        step_physics.in_set(PhysicsSet::Step),
        record.in_set(PhysicsSet::Record),
    ));
}

/// A schedule with the physics systems: one run is one physics step.
pub fn physics_schedule() -> Schedule {
    let mut schedule = Schedule::default();
    add_physics_systems(&mut schedule);
    schedule
}

/// Runs `schedule` (one physics step) and returns the error it met, if any (taken out of
/// [`Physics`]).
pub fn run_step(world: &mut World, schedule: &mut Schedule) -> Result<()> {
    if !world.contains_resource::<Physics>() {
        return Err(Error::invalid(
            "Physics",
            "no such resource in the world: insert one with `world.insert_resource(Physics::new(dt, gravity))` \
             (or `Physics::from_world(your_rapier_world)`)",
        ));
    }
    schedule.run(world);
    world.clear_trackers();
    match world.resource_mut::<Physics>().take_error() {
        Some(e) => Err(e),
        None => Ok(()),
    }
}
