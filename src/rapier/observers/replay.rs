//! What a replay of a run needs, recorded from any Rapier loop: the tracked bodies' shapes and
//! poses, and each tracked clearance joint's journal in its bearing (eccentricity, contact
//! force, penetration, contact and impact flags), thinned by time.
//!
//! The recorder only reads the world (after each step, with the force sources evaluated at the
//! new state as [`Stepper::step`](crate::rapier::pipeline::stepper::Stepper::step) leaves them), so the
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
//! let mut stepper = Stepper::new(StepControl::adaptive(1e-3, 0.0075));
//! stepper.prepare(&mut world, &mut [&mut clearance])?;
//! recorder.record(0.0, &world.bodies, &[&clearance]);
//! while stepper.time() < 0.05 {
//!     stepper.step(&mut world, &mut [&mut clearance], 0.05)?;
//!     recorder.record(stepper.time(), &world.bodies, &[&clearance]);
//! }
//! let recording = recorder.finish();
//! assert_eq!(recording.frames.last().unwrap().t, stepper.time());
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

impl ReplayRecorder {
    /// A recorder keeping a state per `interval` s in free flight and per `contact_interval`
    /// s while a journal is in contact (`0 < contact_interval <= interval`).
    pub fn new(interval: f64, contact_interval: f64) -> Result<Self> {
        if !(interval.is_finite() && interval > 0.0) {
            return Err(Error::invalid("interval", "must be a positive time, s"));
        }
        if !(contact_interval.is_finite() && contact_interval > 0.0 && contact_interval <= interval)
        {
            return Err(Error::invalid(
                "contact_interval",
                "must be a positive time no longer than `interval`, s",
            ));
        }
        Ok(ReplayRecorder {
            recording: Recording {
                interval_s: interval,
                contact_interval_s: contact_interval,
                ..Recording::default()
            },
            handles: Vec::new(),
            joints: Vec::new(),
            pending: None,
            peak: None,
            in_contact: false,
            onset: f64::NEG_INFINITY,
            last_kept: f64::NEG_INFINITY,
            max_frames: usize::MAX,
        })
    }

    /// The recorder keeping at most `max_frames` frames (at least 4), halving its frames and
    /// doubling its intervals whenever it reaches them (see the module docs' cap).
    pub fn with_max_frames(mut self, max_frames: usize) -> Self {
        self.max_frames = max_frames.max(4);
        self
    }

    /// Tracks a body (in group `group`), its shapes from its colliders or its mass properties
    /// (see [`ReplayBody::shapes`]; call after the mass properties are known: Rapier computes
    /// them in the first step,
    /// [`prepare_mass_properties`](crate::rapier::observers::reaction::prepare_mass_properties) before it).
    /// Returns its index.
    pub fn track_body(
        &mut self,
        name: &str,
        group: &str,
        handle: RigidBodyHandle,
        bodies: &RigidBodySet,
        colliders: &ColliderSet,
    ) -> usize {
        let shapes = bodies
            .get(handle)
            .map(|rb| body_shapes(rb, colliders))
            .unwrap_or_default();
        self.recording.bodies.push(ReplayBody {
            name: name.into(),
            group: group.into(),
            shapes,
        });
        self.handles.push(handle);
        self.handles.len() - 1
    }

    /// The index of a tracked body, by handle.
    fn body_index(&self, handle: RigidBodyHandle, field: &str) -> Result<usize> {
        self.handles
            .iter()
            .position(|&h| h == handle)
            .ok_or_else(|| Error::invalid(field, "its body is not tracked: track it first"))
    }

    /// Tracks clearance joint `handle` of `set`, the set passed `set_index`-th to
    /// [`record`](Self::record). Its two bodies must be tracked already.
    pub fn track_journal(
        &mut self,
        name: &str,
        group: &str,
        set_index: usize,
        handle: ClearanceJointHandle,
        set: &ClearanceJointSet,
    ) -> Result<()> {
        let joint = set
            .get(handle)
            .ok_or_else(|| Error::invalid(name, "no such clearance joint in this set"))?;
        let g = joint.geometry();
        let axis1 = joint.local_axis1();
        let u1 = in_plane_u(axis1);
        self.recording.journals.push(ReplayJournal {
            name: name.into(),
            group: group.into(),
            bearing: self.body_index(joint.body1(), name)?,
            journal: self.body_index(joint.body2(), name)?,
            anchor1_m: joint.local_anchor1().to_array(),
            anchor2_m: joint.local_anchor2().to_array(),
            axis1: axis1.to_array(),
            u1: u1.to_array(),
            clearance_m: g.clearance(),
            bearing_radius_m: g.bearing_radius(),
            width_m: g.length(),
            axial_play_m: joint.spatial_model().map(|m| m.geometry.axial_play),
        });
        self.joints.push((set_index, handle));
        Ok(())
    }

    /// Tracks an ideal hinge between two tracked bodies, drawn as a pin.
    pub fn track_pin(
        &mut self,
        name: &str,
        group: &str,
        body1: RigidBodyHandle,
        body2: RigidBodyHandle,
        anchor1: Vector,
        axis1: Vector,
    ) -> Result<()> {
        let pin = ReplayPin {
            name: name.into(),
            group: group.into(),
            body1: self.body_index(body1, name)?,
            body2: self.body_index(body2, name)?,
            anchor1_m: anchor1.to_array(),
            axis1: axis1.normalize_or_zero().to_array(),
        };
        self.recording.pins.push(pin);
        Ok(())
    }

    /// Records the state at time `t` (call after each step; `sets` as given to
    /// [`track_journal`](Self::track_journal)). Keeps it or not by the thinning rule.
    pub fn record(&mut self, t: f64, bodies: &RigidBodySet, sets: &[&ClearanceJointSet]) {
        let frame = self.frame(t, bodies, sets);
        for inside in self.inside_frames(&frame, bodies, sets) {
            self.record_frame(inside);
        }
        self.record_frame(frame);
    }

    /// Records one state (thinned as [`record`](Self::record) says).
    fn record_frame(&mut self, frame: ReplayFrame) {
        let t = frame.t;
        let contact = frame.journals.iter().any(|j| j.contact);
        let onset = contact && !self.in_contact;
        if onset {
            self.onset = t;
        }
        let dense = t - self.onset <= DENSE_FRAMES * self.recording.contact_interval_s;
        let spacing = if (contact || self.in_contact) && dense {
            self.recording.contact_interval_s
        } else {
            self.recording.interval_s
        };
        let keep = onset || t - self.last_kept >= spacing * (1.0 - 1e-9);
        if onset && let Some(before) = self.pending.take() {
            self.push_after_peak(before);
        }
        self.in_contact = contact;
        if keep {
            self.pending = None;
            self.push_after_peak(frame);
        } else {
            if self.peak.as_ref().is_none_or(|p| force(&frame) > force(p)) {
                self.peak = Some(frame.clone());
            }
            self.pending = Some(frame);
        }
    }

    /// Keeps `frame`, after the state of largest force skipped since the last kept one when
    /// that force exceeds both neighbours' (a peak between kept states: so the recording's
    /// largest force is the run's, whatever the thinning).
    fn push_after_peak(&mut self, frame: ReplayFrame) {
        if let Some(peak) = self.peak.take() {
            let before = self.recording.frames.last().map_or(0.0, force);
            if peak.t < frame.t && force(&peak) > before.max(force(&frame)) {
                self.push(peak);
            }
        }
        self.push(frame);
    }

    fn push(&mut self, frame: ReplayFrame) {
        self.last_kept = frame.t;
        self.recording.frames.push(frame);
        if self.recording.frames.len() > self.max_frames {
            self.halve();
        }
    }

    /// Halves the frames kept (see the module docs' cap): the first and last stay, each pair
    /// between keeps its frame of larger force, with the other's impact flags.
    fn halve(&mut self) {
        let frames = std::mem::take(&mut self.recording.frames);
        let n = frames.len();
        let mut kept = Vec::with_capacity(n / 2 + 2);
        let mut it = frames.into_iter();
        kept.extend(it.next());
        let last = it.next_back();
        while let Some(a) = it.next() {
            kept.push(match it.next() {
                Some(b) => merge_pair(a, b),
                None => a,
            });
        }
        kept.extend(last);
        self.recording.frames = kept;
        self.recording.interval_s *= 2.0;
        self.recording.contact_interval_s *= 2.0;
    }

    fn frame(&self, t: f64, bodies: &RigidBodySet, sets: &[&ClearanceJointSet]) -> ReplayFrame {
        let poses = self
            .handles
            .iter()
            .map(|&h| match bodies.get(h) {
                Some(rb) => {
                    let (p, q) = (rb.translation(), *rb.rotation());
                    [p.x, p.y, p.z, q.x, q.y, q.z, q.w]
                }
                None => [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0],
            })
            .collect();
        let journals = self
            .joints
            .iter()
            .zip(&self.recording.journals)
            .map(|(&(set, h), track)| {
                let Some(joint) = sets.get(set).and_then(|s| s.get(h)) else {
                    return JournalFrame::default();
                };
                journal_frame(joint, bodies, track)
            })
            .collect();
        ReplayFrame { t, poses, journals }
    }

    /// The states inside the step that led to `end` of the sub-cycled joints
    /// ([`ClearanceJoint::substeps`]), in time order: each such joint at its sub-step, the other
    /// journals as at the step's end (or at their own latest sub-step before), the bodies drawn
    /// at the step's end (they move little within a step against the journal in its play).
    fn inside_frames(
        &self,
        end: &ReplayFrame,
        bodies: &RigidBodySet,
        sets: &[&ClearanceJointSet],
    ) -> Vec<ReplayFrame> {
        let joint = |&(set, h): &(usize, ClearanceJointHandle)| sets.get(set)?.get(h);
        let mut times: Vec<f64> = Vec::new();
        for j in self.joints.iter().filter_map(joint) {
            if let Some((last, inside)) = j.substeps().split_last() {
                let start = end.t - last.t;
                times.extend(inside.iter().map(|s| start + s.t));
            }
        }
        if times.is_empty() {
            return Vec::new();
        }
        times.sort_by(f64::total_cmp);
        times.dedup();
        let rotation = |j: &ClearanceJoint| -> Rotation {
            bodies
                .get(j.body1())
                .map(|rb| *rb.rotation())
                .unwrap_or_default()
        };
        times
            .into_iter()
            .map(|t| {
                let mut frame = ReplayFrame {
                    t,
                    poses: end.poses.clone(),
                    journals: end.journals.clone(),
                };
                for ((k, id), track) in self.joints.iter().enumerate().zip(&self.recording.journals)
                {
                    let Some(j) = joint(id) else { continue };
                    let Some(last) = j.substeps().last() else {
                        continue;
                    };
                    let start = end.t - last.t;
                    if let Some(s) = j.substeps().iter().rev().find(|s| start + s.t <= t) {
                        frame.journals[k] = substep_frame(s, rotation(j), track);
                    }
                }
                frame
            })
            .collect()
    }

    /// The frames kept so far.
    pub fn frames(&self) -> &[ReplayFrame] {
        &self.recording.frames
    }

    /// The recording, with the last state recorded kept.
    pub fn finish(mut self) -> Recording {
        if let Some(last) = self.pending.take() {
            self.push_after_peak(last);
        }
        self.recording
    }
}

/// One journal's state in its bearing's `u`/`v` directions (a spatial joint's eccentricity at
/// the bearing's mid-plane, as the scene runner's CSV rows: its report's state is its deepest
/// station's, which may be a face's).
fn journal_frame(
    joint: &ClearanceJoint,
    bodies: &RigidBodySet,
    track: &ReplayJournal,
) -> JournalFrame {
    let r = joint.report();
    let (rb1, rb2) = (bodies.get(joint.body1()), bodies.get(joint.body2()));
    let rotation: Rotation = rb1.map(|rb| *rb.rotation()).unwrap_or_default();
    let (u, v) = bearing_directions(rotation, track);
    let pose = match (r.spatial, rb1, rb2) {
        (Some(_), Some(rb1), Some(rb2)) => Some(joint.spatial_pose(rb1, rb2, u)),
        _ => None,
    };
    let e = pose.map_or(r.state.eccentricity, |p| p.mid_plane_eccentricity());
    JournalFrame {
        spatial: pose
            .zip(r.spatial)
            .map(|(p, s)| spatial_frame(&p, &s, u, v)),
        ..planar_frame(e, &r.state, &r.force, r.impact, (u, v))
    }
}

/// A planar joint's frame at one of its sub-steps, in the bearing's directions (its body's
/// `rotation` at the step's end).
fn substep_frame(s: &SubStep, rotation: Rotation, track: &ReplayJournal) -> JournalFrame {
    let uv = bearing_directions(rotation, track);
    planar_frame(s.state.eccentricity, &s.state, &s.force, s.impact, uv)
}

/// The bearing's in-plane directions `u`, `v` (world) for its body's `rotation`.
fn bearing_directions(rotation: Rotation, track: &ReplayJournal) -> (Vector, Vector) {
    let u1 = Vector::from(track.u1);
    (
        rotation * u1,
        rotation * Vector::from(track.axis1).cross(u1),
    )
}

/// A journal's frame from its eccentricity `e`, its state's penetration and its force, along
/// the bearing's `u` and `v` (no spatial part).
fn planar_frame(
    e: Vector,
    state: &crate::model::kinematics::JournalState,
    force: &crate::model::kinematics::ForcePair,
    impact: bool,
    (u, v): (Vector, Vector),
) -> JournalFrame {
    let f = force.on_journal;
    JournalFrame {
        ecc_u_m: e.dot(u),
        ecc_v_m: e.dot(v),
        force_u_n: f.dot(u),
        force_v_n: f.dot(v),
        force_n: f.length(),
        penetration_m: state.penetration.max(0.0),
        contact: state.penetration > 0.0,
        impact,
        spatial: None,
    }
}

/// A spatial joint's frame values from its pose and report (`u`, `v`: the bearing's
/// directions, world).
fn spatial_frame(pose: &SpatialPose, s: &SpatialReport, u: Vector, v: Vector) -> SpatialFrame {
    let local = |at: Vector| {
        let d = at - pose.bearing_center;
        [d.dot(u), d.dot(v), d.dot(pose.bearing_axis)]
    };
    SpatialFrame {
        tilt_rad: pose.tilt(),
        axial_m: pose.axial_offset(),
        edge_force_n: s.edge_force,
        edge_at_m: s.edge_point.map(local),
        face_force_n: s.face_force,
        face_at_m: s.face_point.map(local),
    }
}

/// The largest contact force of a frame's journals, N.
fn force(f: &ReplayFrame) -> f64 {
    f.journals.iter().map(|j| j.force_n).fold(0.0, f64::max)
}

/// The frame of `a` and `b` with the larger contact force, carrying the other's impact flags
/// (an impact's frame dropped still shows on the timeline).
fn merge_pair(a: ReplayFrame, b: ReplayFrame) -> ReplayFrame {
    let (mut keep, drop) = if force(&b) > force(&a) {
        (b, a)
    } else {
        (a, b)
    };
    for (k, d) in keep.journals.iter_mut().zip(&drop.journals) {
        k.impact |= d.impact;
    }
    keep
}

/// The in-plane `u` direction of a hinge: the axis of the frame least aligned with `axis`,
/// made orthogonal to it (x for an axis along y; then `v = axis x u` is z). The scene runner's
/// CSV columns `*_ecc_u_mm`/`*_ecc_v_mm` use the same directions.
pub fn in_plane_u(axis: Vector) -> Vector {
    let candidates = [Vector::X, Vector::Y, Vector::Z];
    let mut best = candidates[0];
    for c in candidates {
        if c.dot(axis).abs() < best.dot(axis).abs() - 1e-12 {
            best = c;
        }
    }
    (best - best.dot(axis) * axis).normalize()
}

/// A body's shapes: its colliders' (boxes, cylinders, balls; capsules as cylinders), else the
/// box with its mass and principal inertia.
fn body_shapes(rb: &RigidBody, colliders: &ColliderSet) -> Vec<ReplayShape> {
    let mut shapes = Vec::new();
    for &c in rb.colliders() {
        let Some(col) = colliders.get(c) else {
            continue;
        };
        let pose = col.position_wrt_parent().copied().unwrap_or_default();
        let center_m = pose.translation.to_array();
        let q = pose.rotation;
        let rotation = [q.x, q.y, q.z, q.w];
        let shape = col.shape();
        if let Some(b) = shape.as_cuboid() {
            shapes.push(ReplayShape::Box {
                half_extents_m: b.half_extents.to_array(),
                center_m,
                rotation,
            });
        } else if let Some(cy) = shape.as_cylinder() {
            shapes.push(ReplayShape::Cylinder {
                radius_m: cy.radius,
                half_height_m: cy.half_height,
                center_m,
                rotation,
            });
        } else if let Some(b) = shape.as_ball() {
            shapes.push(ReplayShape::Ball {
                radius_m: b.radius,
                center_m,
            });
        } else if let Some(cap) = shape.as_capsule() {
            shapes.push(ReplayShape::Cylinder {
                radius_m: cap.radius,
                half_height_m: cap.half_height() + cap.radius,
                center_m,
                rotation,
            });
        }
    }
    if shapes.is_empty() {
        let m = &rb.mass_properties().local_mprops;
        let mass = m.mass();
        let j = m.principal_inertia();
        if mass > 0.0 && mass.is_finite() {
            // A uniform box: J_x = m (a_y^2 + a_z^2) / 12 with full extents a, so
            // a_x^2 = 6 (J_y + J_z - J_x) / m.
            let full = |a: f64, b: f64, c: f64| (6.0 * (b + c - a) / mass).max(0.0).sqrt();
            let half = [
                0.5 * full(j.x, j.y, j.z),
                0.5 * full(j.y, j.z, j.x),
                0.5 * full(j.z, j.x, j.y),
            ];
            let q = m.principal_inertia_local_frame;
            shapes.push(ReplayShape::Box {
                half_extents_m: half,
                center_m: m.local_com.to_array(),
                rotation: [q.x, q.y, q.z, q.w],
            });
        }
    }
    shapes
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equivalent_box_of_a_uniform_box_is_the_box() {
        // A 2 x 3 x 4 m box of 12 kg: J = m/12 (b^2 + c^2), ...
        let m: f64 = 12.0;
        let (a, b, c): (f64, f64, f64) = (2.0, 3.0, 4.0);
        let j = Vector::new(
            m / 12.0 * (b * b + c * c),
            m / 12.0 * (a * a + c * c),
            m / 12.0 * (a * a + b * b),
        );
        let mut bodies = RigidBodySet::new();
        let h = bodies.insert(
            RigidBodyBuilder::dynamic().additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                m,
                j,
            )),
        );
        crate::rapier::observers::reaction::prepare_mass_properties(&mut bodies);
        let shapes = body_shapes(&bodies[h], &ColliderSet::new());
        let ReplayShape::Box { half_extents_m, .. } = shapes[0] else {
            panic!("expected a box, got {shapes:?}");
        };
        for (got, want) in half_extents_m.iter().zip([1.0, 1.5, 2.0]) {
            assert!((got - want).abs() < 1e-9, "{half_extents_m:?}");
        }
    }

    #[test]
    fn thinning_keeps_contacts_and_the_last_state() {
        let mut r = ReplayRecorder::new(0.1, 0.01).unwrap();
        let bodies = RigidBodySet::new();
        for k in 0..=150 {
            r.record(k as f64 * 1e-3, &bodies, &[]);
        }
        let rec = r.finish();
        let t: Vec<f64> = rec.frames.iter().map(|f| f.t).collect();
        // Every 0.1 s, and the last state.
        assert_eq!(t.len(), 3, "{t:?}");
        assert_eq!(t[0], 0.0);
        assert!((t[1] - 0.1).abs() < 1e-12 && t[2] == 0.15, "{t:?}");
        assert!(ReplayRecorder::new(0.1, 0.2).is_err());
    }

    #[test]
    fn the_cap_halves_frames_and_keeps_the_first_and_last() {
        let mut r = ReplayRecorder::new(1e-3, 1e-3).unwrap().with_max_frames(10);
        let bodies = RigidBodySet::new();
        for k in 0..=100 {
            r.record(k as f64 * 1e-3, &bodies, &[]);
        }
        let rec = r.finish();
        assert!(rec.frames.len() <= 10, "{}", rec.frames.len());
        assert_eq!(rec.frames[0].t, 0.0);
        assert_eq!(rec.frames.last().unwrap().t, 0.1);
        assert!(rec.interval_s > 1e-3 && rec.contact_interval_s > 1e-3);
        assert!(ReplayRecorder::new(f64::NAN, 0.1).is_err());
    }

    /// A sub-cycled joint's impact inside one 1/60 s step is in the recording at its sub-steps:
    /// the recording's largest force is the largest sub-step force, at that sub-step's time,
    /// where the steps' own states see nothing of the impact.
    #[test]
    fn a_sub_cycled_impact_inside_a_step_is_recorded_at_its_sub_steps() {
        use crate::prelude::*;
        let mut rapier = PhysicsWorld::new();
        rapier.gravity = Vector::new(0.0, -9.81, 0.0);
        let base = rapier.bodies.insert(RigidBodyBuilder::fixed());
        let arm = rapier.bodies.insert(
            RigidBodyBuilder::dynamic()
                .translation(Vector::new(0.0, -0.3, 0.0))
                .additional_mass_properties(MassProperties::new(
                    Vector::ZERO,
                    2.0,
                    Vector::splat(0.02),
                ))
                .can_sleep(false),
        );
        let pin = HingeDesign::steel_improved_liu(0.010, 0.2e-3, 0.016)
            .unwrap()
            .integration(ContactIntegration::SubCycled)
            .joint(
                Vector::ZERO,
                Vector::new(0.0, 0.3, 0.0),
                Vector::Z,
                Vector::Z,
            )
            .unwrap();
        let mut world = ClearanceWorld::new(rapier, StepControl::fixed(1.0 / 60.0));
        let hinge = world.insert_clearance(base, arm, pin).unwrap();
        let mut r = ReplayRecorder::new(1.0 / 60.0, 1e-5).unwrap();
        let (b, c) = (&world.rapier.bodies, &world.rapier.colliders);
        r.track_body("base", "clearance", base, b, c);
        r.track_body("arm", "clearance", arm, b, c);
        r.track_journal("pin", "clearance", 0, hinge, &world.clearance)
            .unwrap();
        let (mut peak, mut peak_t, mut at_steps) = (0.0_f64, 0.0, 0.0_f64);
        while world.time() < 0.1 {
            let t0 = world.time();
            world.step(0.1).unwrap();
            r.record(world.time(), &world.rapier.bodies, &[&world.clearance]);
            let j = world.clearance.get(hinge).unwrap();
            at_steps = at_steps.max(j.report().force.normal_force);
            for s in j.substeps() {
                if s.force.on_journal.length() > peak {
                    (peak, peak_t) = (s.force.on_journal.length(), t0 + s.t);
                }
            }
        }
        let recording = r.finish();
        let kept = recording
            .frames
            .iter()
            .max_by(|a, b| force(a).total_cmp(&force(b)))
            .unwrap();
        assert!(
            peak > 5.0 * at_steps.max(19.62),
            "{peak} N inside, {at_steps} N at the steps"
        );
        assert_eq!(force(kept), peak);
        assert!(
            (kept.t - peak_t).abs() < 1e-12,
            "{} against {peak_t}",
            kept.t
        );
    }

    #[test]
    fn a_spatial_frame_carries_the_joints_tilt_and_edge_forces() {
        use crate::model::spatial::SpatialModel;
        use crate::prelude::*;
        // The library's spatial example: an arm 0.2 m out from a vertical pin tilts its journal
        // onto both edges of the bore.
        let mut rapier = PhysicsWorld::new();
        rapier.gravity = Vector::new(0.0, -9.81, 0.0);
        rapier.integration_parameters.num_solver_iterations = 1;
        let post = rapier.bodies.insert(RigidBodyBuilder::fixed());
        let arm = rapier.bodies.insert(
            RigidBodyBuilder::dynamic()
                .translation(Vector::new(0.2, 0.0, 0.0))
                .additional_mass_properties(MassProperties::new(
                    Vector::ZERO,
                    2.0,
                    Vector::splat(0.02),
                )),
        );
        let pin = HingeDesign::steel_improved_liu(0.006, 0.1e-3, 0.020)
            .unwrap()
            .model(ClearanceModel::Spatial(SpatialModel::steel(0.3e-3, 0.010)))
            .joint(
                Vector::ZERO,
                Vector::new(-0.2, 0.0, 0.0),
                Vector::Y,
                Vector::Y,
            )
            .unwrap();
        let mut world = ClearanceWorld::new(rapier, StepControl::adaptive(1e-3, 0.0075));
        let hinge = world.insert_clearance(post, arm, pin).unwrap();
        let mut r = ReplayRecorder::new(1e-3, 1e-5).unwrap();
        let (b, c) = (&world.rapier.bodies, &world.rapier.colliders);
        r.track_body("post", "clearance", post, b, c);
        r.track_body("arm", "clearance", arm, b, c);
        r.track_journal("pin", "clearance", 0, hinge, &world.clearance)
            .unwrap();
        let mut seen = false;
        while world.time() < 0.03 {
            world.step(0.03).unwrap();
            r.record(world.time(), &world.rapier.bodies, &[&world.clearance]);
            let joint = world.clearance.get(hinge).unwrap();
            let s = joint.report().spatial.unwrap();
            let last = r.frames().last().unwrap();
            if last.t != world.time() || s.edge_force[0] <= 0.0 || s.edge_force[1] <= 0.0 {
                continue;
            }
            // A kept frame in edge contact: its values are the joint's report's.
            seen = true;
            let f = last.journals[0].spatial.expect("a spatial frame");
            assert_eq!(f.edge_force_n, s.edge_force);
            assert_eq!(f.face_force_n, s.face_force);
            // Tilt in the recorder's u/v is the report's (the joint's transverse axis is u).
            assert!(
                (f.tilt_rad[0].hypot(f.tilt_rad[1]) - s.tilt[0].hypot(s.tilt[1])).abs() < 1e-12
            );
            assert!((f.axial_m - s.axial_offset).abs() < 1e-12);
            // Each edge acts at its end of the width, on the bore's wall.
            let w = 0.020;
            let [lo, hi] = f.edge_at_m;
            assert!(lo[2] < 0.0 && lo[2] >= -0.5 * w - 1e-9, "{lo:?}");
            assert!(hi[2] > 0.0 && hi[2] <= 0.5 * w + 1e-9, "{hi:?}");
            assert!((lo[0].hypot(lo[1]) - 0.006).abs() < 0.2e-3, "{lo:?}");
        }
        assert!(seen, "no kept frame with both edges in contact");
        // A planar joint's frame serializes without the spatial part.
        let planar = serde_json::to_string(&JournalFrame::default()).unwrap();
        assert!(!planar.contains("spatial"), "{planar}");
    }
}
