//! What a replay of a run needs, recorded from any Rapier loop: the tracked bodies' shapes and
//! poses, and each tracked clearance joint's journal in its bearing (eccentricity, contact
//! force, penetration, contact and impact flags), thinned by time.
//!
//! The recorder only reads the world (after each step, with the force sources evaluated at the
//! new state as [`ClearanceWorld::step`](crate::rapier::pipeline::world::ClearanceWorld::step) leaves them), so the
//! same piece serves a plain-Rapier loop and the scene runner. Its [`Recording`] is plain data
//! (serde); the app turns it into a self-contained `replay.html`.
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
//! use clearance_joint::rapier::observers::replay::{ReplayRecorder, ReplayShape};
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

use crate::error::{Error, Result};
use crate::model::spatial::SpatialPose;
use crate::rapier::joint::{
    ClearanceJoint, ClearanceJointHandle, ClearanceJointSet, SpatialReport, SubStep,
};
use rapier3d_f64::math::{Rotation, Vector};
use rapier3d_f64::prelude::*;
use serde::{Deserialize, Serialize};

mod frames;
mod recorder;
pub(crate) use frames::in_plane_u;

/// Frames of a contact kept at `contact_interval` after its onset (see the module docs).
pub const DENSE_FRAMES: f64 = 100.0;

/// A shape drawn for a body, in the body's frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum ReplayShape {
    /// A box.
    Box {
        /// Half extents along the box's axes, m.
        half_extents_m: [f64; 3],
        /// Centre in the body's frame, m.
        center_m: [f64; 3],
        /// Rotation from the box's axes to the body's frame (quaternion x, y, z, w).
        rotation: [f64; 4],
    },
    /// A cylinder along its own y axis.
    Cylinder {
        /// Radius, m.
        radius_m: f64,
        /// Half height, m.
        half_height_m: f64,
        /// Centre in the body's frame, m.
        center_m: [f64; 3],
        /// Rotation from the cylinder's axes to the body's frame (quaternion x, y, z, w).
        rotation: [f64; 4],
    },
    /// A ball.
    Ball {
        /// Radius, m.
        radius_m: f64,
        /// Centre in the body's frame, m.
        center_m: [f64; 3],
    },
}

/// A tracked body.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReplayBody {
    /// Name shown.
    pub name: String,
    /// Group (e.g. the twin: `ideal`, `clearance`); groups are drawn side by side.
    pub group: String,
    /// Its shapes: its colliders' (boxes, cylinders, balls), else the box with its mass and
    /// principal inertia (a uniform box's `a_x^2 = 6 (J_y + J_z - J_x) / m`), else none (a fixed
    /// body without colliders: the viewer sizes it from the joint points).
    pub shapes: Vec<ReplayShape>,
}

/// A tracked clearance joint: where its bearing and journal are on their bodies.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReplayJournal {
    /// Name shown.
    pub name: String,
    /// Group, as the bodies'.
    pub group: String,
    /// Index (in [`Recording::bodies`]) of the body carrying the bearing.
    pub bearing: usize,
    /// Index of the body carrying the journal.
    pub journal: usize,
    /// Bearing centre in the bearing body's frame, m.
    pub anchor1_m: [f64; 3],
    /// Journal centre in the journal body's frame, m.
    pub anchor2_m: [f64; 3],
    /// Axis in the bearing body's frame (unit).
    pub axis1: [f64; 3],
    /// In-plane direction `u` of the inset (bearing frame, unit; `v = axis x u`).
    pub u1: [f64; 3],
    /// Radial clearance `c`, m.
    pub clearance_m: f64,
    /// Bearing radius, m.
    pub bearing_radius_m: f64,
    /// Bearing width, m.
    pub width_m: f64,
    /// A spatial joint's axial play (its journal's free axial travel when centred), m; `None`
    /// (and absent from the serialized journal) for a planar joint.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axial_play_m: Option<f64>,
}

/// An ideal hinge drawn as a pin (not sampled: its bodies' poses say all).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReplayPin {
    /// Name shown.
    pub name: String,
    /// Group, as the bodies'.
    pub group: String,
    /// Index of the first body.
    pub body1: usize,
    /// Index of the second body.
    pub body2: usize,
    /// Pin centre in the first body's frame, m.
    pub anchor1_m: [f64; 3],
    /// Axis in the first body's frame (unit).
    pub axis1: [f64; 3],
}

/// One journal at one state.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct JournalFrame {
    /// Eccentricity along the bearing's `u`, m.
    pub ecc_u_m: f64,
    /// Eccentricity along the bearing's `v`, m.
    pub ecc_v_m: f64,
    /// Contact force on the journal along `u`, N.
    pub force_u_n: f64,
    /// Contact force on the journal along `v`, N.
    pub force_v_n: f64,
    /// Contact force magnitude, N.
    pub force_n: f64,
    /// Penetration (0 when apart), m.
    pub penetration_m: f64,
    /// In contact at this state.
    pub contact: bool,
    /// A contact began at this state with an impact (approach speed above the joint's floor).
    pub impact: bool,
    /// A spatial joint's tilt, axial offset and edge and face forces (`None` for a planar
    /// joint, and then absent from the serialized frame).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spatial: Option<SpatialFrame>,
}

/// A spatial journal at one state, in the bearing's frame: `u`, `v` (as [`JournalFrame`]'s
/// eccentricity) and the axis `a`, from the bearing's centre.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SpatialFrame {
    /// The journal axis's tilt about `u` and about `v`, rad (the scene runner's
    /// `tilt_u_deg`/`tilt_v_deg` columns, in rad).
    pub tilt_rad: [f64; 2],
    /// The journal's axial offset along `a`, m.
    pub axial_m: f64,
    /// Normal resultant of the bore at its lower (`-L/2`) and upper (`+L/2`) end, N.
    pub edge_force_n: [f64; 2],
    /// Where each edge resultant acts, `[u, v, a]` from the bearing's centre, m (the centre
    /// while it carries nothing).
    pub edge_at_m: [[f64; 3]; 2],
    /// Normal resultant of the lower and upper shoulder face, N.
    pub face_force_n: [f64; 2],
    /// Where each face resultant acts, `[u, v, a]` from the bearing's centre, m.
    pub face_at_m: [[f64; 3]; 2],
}

/// One kept state.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReplayFrame {
    /// Time, s.
    pub t: f64,
    /// Pose of every tracked body: position (m) and rotation quaternion, `[x, y, z, qx, qy, qz, qw]`.
    pub poses: Vec<[f64; 7]>,
    /// Every tracked journal, in tracking order.
    pub journals: Vec<JournalFrame>,
}

/// What a [`ReplayRecorder`] recorded.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Recording {
    /// Tracked bodies.
    pub bodies: Vec<ReplayBody>,
    /// Tracked clearance joints.
    pub journals: Vec<ReplayJournal>,
    /// Ideal hinges drawn as pins.
    pub pins: Vec<ReplayPin>,
    /// Kept states, in time order.
    pub frames: Vec<ReplayFrame>,
    /// Free-flight frame interval, s.
    pub interval_s: f64,
    /// In-contact frame interval, s.
    pub contact_interval_s: f64,
}

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
}

#[cfg(test)]
mod tests;
