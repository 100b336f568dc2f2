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
    /// One accepted step of the [`ClearanceWorld`](crate::rapier::pipeline::world::ClearanceWorld).
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

/// Runs `schedule` (one physics step, a frame of its own: see
/// [`HingeState::frame_mean_force`](super::HingeState::frame_mean_force)) and returns the error
/// it met, if any (taken out of [`Physics`]).
pub fn run_step(world: &mut World, schedule: &mut Schedule) -> Result<()> {
    physics_of(world)?.begin_frame();
    run_once(world, schedule)
}

/// Runs `schedule` until [`Physics::time`] reaches `duration` (s) later: one frame of a game
/// loop, whatever steps the step control takes (the last lands on the frame's end). The hinges'
/// frame figures ([`HingeState::frame_mean_force`](super::HingeState::frame_mean_force),
/// [`frame_peak_force`](super::HingeState::frame_peak_force)) cover its steps. Returns the
/// steps taken, or the first error (taken out of [`Physics`]; the frame stops there).
pub fn run_frame(world: &mut World, schedule: &mut Schedule, duration: f64) -> Result<u64> {
    if !(duration > 0.0 && duration.is_finite()) {
        return Err(Error::invalid(
            "duration",
            format!("must be a positive, finite time in seconds (got {duration})"),
        ));
    }
    let mut physics = physics_of(world)?;
    physics.begin_frame();
    let end = physics.time() + duration;
    physics.set_frame_end(Some(end));
    let mut taken = 0;
    let result = loop {
        if world.resource::<Physics>().time() >= end {
            break Ok(taken);
        }
        if let Err(e) = run_once(world, schedule) {
            break Err(e);
        }
        taken += 1;
    };
    world.resource_mut::<Physics>().set_frame_end(None);
    result
}

/// The [`Physics`] resource of `world`, or the error that names it missing.
fn physics_of(world: &mut World) -> Result<Mut<'_, Physics>> {
    world.get_resource_mut::<Physics>().ok_or_else(|| {
        Error::invalid(
            "Physics",
            "no such resource in the world: insert one with `world.insert_resource(Physics::new(dt, gravity))` \
             (or `Physics::from_world(your_rapier_world)`)",
        )
    })
}

/// Runs `schedule` once and takes its error out of [`Physics`].
fn run_once(world: &mut World, schedule: &mut Schedule) -> Result<()> {
    schedule.run(world);
    world.clear_trackers();
    match world.resource_mut::<Physics>().take_error() {
        Some(e) => Err(e),
        None => Ok(()),
    }
}
