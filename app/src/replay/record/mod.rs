//! What a replay of a run needs, recorded from any Rapier loop: the tracked bodies' shapes and
//! poses, and each tracked clearance joint's journal in its bearing (eccentricity, contact
//! force, penetration, contact and impact flags), thinned by time.
//!
//! The recorder only reads the world (after each step, with the force sources evaluated at the
//! new state as [`ClearanceWorld::step`](clearance_joint::rapier::pipeline::world::ClearanceWorld::step)
//! leaves them), so the same piece serves a plain-Rapier loop and the library's scene runner
//! ([`ReplayRecorder::for_simulation`]). Its [`Recording`] is plain data (serde);
//! [`ReplayPage`](super::ReplayPage) writes it as a self-contained `replay.html`.
//!
//! **Thinning rule.** A state is kept when at least `interval` has passed since the last kept
//! state; during the first [`DENSE_FRAMES`] `contact_interval`s after a contact's onset (while
//! in contact, and at the state where that contact ends), when at least `contact_interval` has
//! passed; always at a contact's onset and at the state just before it, and the last state
//! recorded; and between two kept states, the skipped state of largest contact force when that
//! force exceeds both of theirs, so the recording's largest force is the largest of every state
//! recorded (a summary's peak), whatever the intervals. So every impact is kept at the contact's
//! own resolution while free flight and sustained contact (a journal sliding along the wall)
//! cost one frame per `interval`: at most `2 (duration / interval + impacts x (DENSE_FRAMES +
//! 2))` frames.
//!
//! **Cap.** A recorder built [`with_max_frames`](ReplayRecorder::with_max_frames) never holds
//! more: on reaching the cap it halves its frames (the first and last stay; of each pair between,
//! the frame of larger contact force, carrying the other's impact flags) and doubles both
//! intervals, so a long or rattling run's recording stays bounded in memory and every kept
//! stretch keeps its largest force.
//!
//! ```
//! use clearance_joint::prelude::*;
//! use clearance_joint_app::replay::record::{ReplayRecorder, ReplayShape};
//! use rapier3d_f64::prelude::*;
//!
//! let mut world = PhysicsWorld::new();
//! world.integration_parameters.num_solver_iterations = 1;
//! let base = world.bodies.insert(RigidBodyBuilder::fixed());
//! let arm = world.bodies.insert(
//!     RigidBodyBuilder::dynamic()
//!         .translation(Vector::new(0.0, -0.3, 0.0))
//!         .additional_mass_properties(MassProperties::new(Vector::ZERO, 2.0, Vector::splat(0.02))),
//! );
//! let hinge = RevoluteJointBuilder::new(Vector::Z).local_anchor2(Vector::new(0.0, 0.3, 0.0));
//! let hinge = world.impulse_joints.insert(base, arm, hinge, true);
//! let mut clearance = ClearanceJointSet::new();
//! let play = HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016)?;
//! let hinge = clearance.convert_revolute(hinge, BearingSide::Body1, play, &mut world.impulse_joints)?;
//!
//! // Mass properties now (Rapier computes them in the first step): the arm's box comes from them.
//! clearance_joint::rapier::observers::reaction::prepare_mass_properties(&mut world.bodies);
//! // One frame per ms in free flight, one per 10 us in contact.
//! let mut recorder = ReplayRecorder::new(1e-3, 1e-5)?;
//! recorder.track_body("base", "clearance", base, &world.bodies, &world.colliders);
//! recorder.track_body("arm", "clearance", arm, &world.bodies, &world.colliders);
//! recorder.track_journal("hinge", "clearance", 0, hinge, &clearance)?;
//! let mut world = ClearanceWorld::new(world, StepControl::adaptive(1e-3, 0.0075));
//! world.clearance = clearance;
//! world.prepare()?;
//! recorder.record(0.0, &world.rapier.bodies, &[&world.clearance]);
//! while world.time() < 0.05 {
//!     world.step(0.05)?;
//!     recorder.record(world.time(), &world.rapier.bodies, &[&world.clearance]);
//! }
//! let recording = recorder.finish();
//! assert_eq!(recording.frames.last().unwrap().t, world.time());
//! assert!(matches!(recording.bodies[1].shapes[0], ReplayShape::Box { .. }));
//! # Ok::<(), clearance_joint::Error>(())
//! ```

use clearance_joint::error::{Error, Result};
use clearance_joint::model::spatial::SpatialPose;
use clearance_joint::rapier::joint::{
    ClearanceJoint, ClearanceJointHandle, ClearanceJointSet, SpatialReport, SubStep,
};
use rapier3d_f64::math::{Rotation, Vector};
use rapier3d_f64::prelude::*;

mod frame;
mod journal;
mod recorder;
mod recording;
mod shapes;
mod simulation;
mod thinning;

pub use frame::{JournalFrame, ReplayFrame, SpatialFrame};
pub use recording::{Recording, ReplayBody, ReplayJournal, ReplayPin, ReplayShape};

/// Frames of a contact kept at `contact_interval` after its onset (see the module docs).
pub const DENSE_FRAMES: f64 = 100.0;

/// Records a replay from a Rapier loop (see the module docs for the thinning rule).
#[derive(Clone, Debug)]
pub struct ReplayRecorder {
    recording: Recording,
    handles: Vec<RigidBodyHandle>,
    /// Per tracked journal: index of its set in `record`'s `sets`, and its handle.
    joints: Vec<(usize, ClearanceJointHandle)>,
    /// The last state recorded, when not kept (kept if a contact starts next).
    pending: Option<ReplayFrame>,
    /// The state of largest contact force since the last kept one, when not kept (kept before
    /// the next kept state when its force exceeds both neighbours').
    peak: Option<ReplayFrame>,
    in_contact: bool,
    /// Time of the last contact onset.
    onset: f64,
    last_kept: f64,
    /// Frames kept at most (see the module docs' cap).
    max_frames: usize,
    /// Frames no longer held (a replaced pending or peak state), whose vectors the next states
    /// reuse: recording a state allocates only when the state is kept.
    spare: Vec<ReplayFrame>,
    /// The state at a step's end and a state inside the step, reused from step to step.
    scratch: [ReplayFrame; 2],
    /// The sub-step times of the step being recorded, reused from step to step.
    times: Vec<f64>,
}

#[cfg(test)]
mod tests;
