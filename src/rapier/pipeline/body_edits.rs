//! Edits of the dynamic bodies between two steps, noticed: a body moved or a velocity set by
//! hand between [`ClearanceWorld`](super::world::ClearanceWorld)'s steps makes the next step
//! evaluate the forces again, and a velocity set by hand restarts the kick as
//! [`invalidate(true)`](super::world::ClearanceWorld::invalidate) does.
//!
//! Rapier flags a pose set through its setters but not a velocity, and clears its flags inside
//! its own step: the world keeps each dynamic body's pose and velocities as its last step left
//! them and compares them at the next step's start (a copy of 13 numbers a body a step, small
//! against the step itself).

use rapier3d_f64::math::{Pose, Vector};
use rapier3d_f64::prelude::{RigidBodyHandle, RigidBodySet};

/// What changed in the dynamic bodies since the last record.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum BodyEdit {
    /// Nothing (or nothing recorded yet).
    None,
    /// A pose: the forces must be evaluated at the new state.
    Moved,
    /// A velocity: the forces evaluated again, and the kick restarted from the new velocities
    /// (the rate the contact laws carried across the step no longer holds).
    Velocity,
}

/// The dynamic bodies' state as the last step left it.
#[derive(Clone, Debug, Default)]
pub(crate) struct BodyEdits {
    after: Vec<(RigidBodyHandle, Pose, Vector, Vector)>,
    recorded: bool,
}

impl BodyEdits {
    /// Records every dynamic body's pose and velocities.
    pub(crate) fn record(&mut self, bodies: &RigidBodySet) {
        self.after.clear();
        self.after.extend(
            bodies
                .iter()
                .filter(|(_, rb)| rb.is_dynamic())
                .map(|(h, rb)| (h, *rb.position(), rb.linvel(), rb.angvel())),
        );
        self.recorded = true;
    }

    /// The largest edit of a recorded body since the record (bit for bit: the world alone
    /// moves the bodies between records). A body removed since is not an edit of the others;
    /// one added is none of a recorded body's.
    pub(crate) fn since(&self, bodies: &RigidBodySet) -> BodyEdit {
        if !self.recorded {
            return BodyEdit::None;
        }
        let mut edit = BodyEdit::None;
        for (h, pose, linvel, angvel) in &self.after {
            let Some(rb) = bodies.get(*h) else { continue };
            if rb.linvel() != *linvel || rb.angvel() != *angvel {
                return BodyEdit::Velocity;
            }
            if rb.position() != pose {
                edit = BodyEdit::Moved;
            }
        }
        edit
    }
}
